//! The sparse solve that LSCM and ABF++ share: a symmetric positive definite system given by
//! its lower-triangle triplets, solved by the Cholesky factorisation of [`crate::geom::sparse`]
//! with its pattern and symbolic factorisation kept for the next system of that pattern, and
//! refined iteratively where asked (LSCM's two steps bring an exactly developable chart to
//! isometry within rounding); and the cotangent Laplacian of a chart's 3D triangles that the
//! seam matching and the stretch minimiser assemble.

use super::{Chart, ParamError};
use crate::geom::sparse::{Cholesky, Pattern};
use faer::sparse::Triplet;
use glam::DVec2;

/// Per triangle corner k of `shapes` (each triangle in its own plane): ½ cot of its angle, the
/// weight of the opposite edge in the cotangent Laplacian.
pub(super) fn half_cotangents(shapes: &[[DVec2; 3]]) -> Vec<[f64; 3]> {
    shapes
        .iter()
        .map(|s| {
            std::array::from_fn(|k| {
                let (p, q, r) = (s[k], s[(k + 1) % 3], s[(k + 2) % 3]);
                let (u, v) = (q - p, r - p);
                0.5 * u.dot(v) / u.perp_dot(v).abs().max(1e-300)
            })
        })
        .collect()
}

/// The lower-triangle triplets of weight `c` on the edge `i j` of a graph Laplacian, pushed
/// onto `trip`.
pub(super) fn push_edge(trip: &mut Vec<Triplet<usize, usize, f64>>, i: usize, j: usize, c: f64) {
    trip.push(Triplet::new(i.max(j), i.min(j), -c));
    trip.push(Triplet::new(i, i, c));
    trip.push(Triplet::new(j, j, c));
}

/// The cotangent Laplacian's triplets of the triangles `tris` (local vertices) with the
/// weights `cots` ([`half_cotangents`]), pushed onto `trip`.
pub(super) fn push_cotangent_laplacian(
    trip: &mut Vec<Triplet<usize, usize, f64>>,
    tris: &[[usize; 3]],
    cots: &[[f64; 3]],
) {
    for (t, c) in tris.iter().zip(cots) {
        for k in 0..3 {
            push_edge(trip, t[(k + 1) % 3], t[(k + 2) % 3], c[k]);
        }
    }
}

/// A system's pattern ([`Pattern`]) with its ordering and symbolic factorisation, which
/// depend on the pattern only: kept by a solver for its next system, used again when that
/// one [`Pattern::fits`] (each Newton step of ABF++, the LSCM solve of a chart laid by LSCM
/// and again from ABF++'s angles).
pub(super) struct Solver {
    pattern: Pattern,
    factor: Cholesky,
}

/// Solve a symmetric positive definite system given by its lower-triangle triplets, with the
/// `solver` kept from the last system where it fits (else made anew and kept).
pub(super) fn spd_solve(
    chart: &Chart,
    method: &'static str,
    n: usize,
    triplets: &[Triplet<usize, usize, f64>],
    rhs: &[f64],
    solver: &mut Option<Solver>,
    refine: usize,
) -> Result<Vec<f64>, ParamError> {
    if n == 0 {
        return Ok(Vec::new());
    }
    let solver = match solver {
        Some(s) if s.pattern.fits(n, triplets) => s,
        _ => {
            let pattern = Pattern::new(n, triplets).ok_or_else(|| {
                chart.solver_error(
                    method,
                    "cannot build the sparse system: an index out of range",
                )
            })?;
            let factor = Cholesky::new(&pattern)
                .ok_or_else(|| chart.solver_error(method, "cannot order the sparse system"))?;
            solver.insert(Solver { pattern, factor })
        }
    };
    let a = solver.pattern.matrix(triplets);
    if !solver.factor.factor(&a) {
        return Err(chart.solver_error(method, "the system is singular"));
    }
    let mut out = rhs.to_vec();
    if !solver.factor.solve(&mut out, 1) {
        return Err(chart.solver_error(method, "the right-hand side has the wrong size"));
    }
    // `refine` steps of iterative refinement: the residual b − A x (A from its lower
    // triangle) solved again and added; LSCM takes two, which brings an exactly developable
    // chart to isometry within rounding (seam sides equal to 1e-9 mm and better).
    for _ in 0..refine {
        let mut r = rhs.to_vec();
        for t in triplets {
            r[t.row] -= t.val * out[t.col];
            if t.row != t.col {
                r[t.col] -= t.val * out[t.row];
            }
        }
        solver.factor.solve(&mut r, 1);
        for (o, d) in out.iter_mut().zip(&r) {
            *o += d;
        }
    }
    if out.iter().any(|v| !v.is_finite()) {
        return Err(chart.solver_error(method, "the solve gave non-finite values"));
    }
    Ok(out)
}
