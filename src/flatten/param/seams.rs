//! Seam-length matching (issue 20, item 2): a chart laid flat by [`super::parameterize`] is
//! relaxed so that every edge of its boundary is as long flat as in 3D, while the inside stays
//! as close to isometric as it can. Both sides of a seam between two charts (or of a cut inside
//! one) are then as long as the 3D seam, so glue tabs, notches and sewn edges line up; the
//! stretch a non-developable chart needs is taken up inside it instead of along its edges.
//!
//! The energy is the as-rigid-as-possible parameterisation of Liu, Zhang, Xu, Gotsman and
//! Gortler (2008), Σₜ Σₖ ½ cot θₖ |(uᵢ − uⱼ) − Rₜ (xᵢ − xⱼ)|² over each triangle's edges (ij
//! opposite corner k, x the triangle in its own plane), plus W Σ_b |(uᵢ − uⱼ) − d_b|² over the
//! boundary edges, d_b the current flat edge direction scaled to the 3D length ℓ_b. Local step:
//! the best rotation Rₜ per triangle (closed form in 2D) and the target d_b per boundary edge;
//! global step: one sparse solve, whose matrix (the cotangent Laplacian, which is positive
//! semidefinite as a sum of squares, plus W times the boundary's graph Laplacian and a soft pin
//! of one vertex) depends only on W, so it is factored once per weight.
//!
//! Choices where the paper is silent (it has no boundary term):
//! - W rises in [`WEIGHTS`] steps, [`ITERATIONS`] rounds each: a soft weight lets the boundary
//!   turn to where its edges can have their length, a stiff one then makes the lengths exact
//!   (a residual of about the inner force divided by W).
//! - The start is the parameteriser's result (conformal, then stretch-minimised), already close.
//! - A relaxation that flips a triangle (a boundary edge pulled across its neighbours) is
//!   taken only partway, as far as nothing flips (halving from half the way, six times at
//!   most), and relaxed again from there ([`ATTEMPTS`] relaxations at most): the boundary
//!   comes nearer its lengths each time, and a chart whose lengths cannot all be had without a
//!   flip keeps the nearest flip-free layout.
//! - Where the relaxations leave a boundary edge further than [`RESCUE_ABOVE`] from its
//!   length (every attempt flipped), the lengths are reached instead by a rising penalty on
//!   them while the stretch is minimised over every vertex, the boundary's included
//!   ([`super::lbfgs::match_lengths`]): its steps never flip a triangle.
//! - The result is kept only if it flips no triangle the start did not and its boundary is
//!   nearer the 3D lengths; else the start is returned as it was. A chart whose boundary is
//!   within [`EXACT`] of its 3D lengths is returned at once (an exactly developable chart).

use super::solve::{half_cotangents, push_cotangent_laplacian, push_edge};
use super::{build_chart, lbfgs, minimise_stretch, shapes_from_3d, vertex_uv, Chart, ChartParam};
use crate::flatten::distortion;
use crate::geom::mesh::Mesh;
use crate::geom::sparse::{Cholesky, Pattern};
use faer::sparse::Triplet;
use glam::DVec2;

/// Boundary weights, in turn (the cotangent weights are of order 1).
pub(crate) const WEIGHTS: [f64; 3] = [1.0, 100.0, 1e5];
/// Local/global rounds at each weight.
pub(crate) const ITERATIONS: usize = 12;
/// Sweeps of the stretch minimisation inside the matched boundary.
pub(crate) const SWEEPS: usize = 15;
/// Relaxations at most, each from partway to where the last one flipped a triangle.
pub(crate) const ATTEMPTS: usize = 4;
/// Largest relative difference between a boundary edge's flat and 3D length left alone.
pub(crate) const EXACT: f64 = 1e-7;
/// A relaxation that leaves a boundary edge further than this from its 3D length (relative)
/// is matched again by [`lbfgs::match_lengths`]: ten times what the stiffest weight leaves
/// where nothing flipped, under every material's seam tolerance (metal: 5e-4).
pub(crate) const RESCUE_ABOVE: f64 = 1e-4;

/// Largest relative difference between flat and 3D length over the boundary edges.
fn boundary_error(uv: &[DVec2], edges: &[(usize, usize, f64)]) -> f64 {
    edges
        .iter()
        .map(|&(a, b, l)| (uv[a].distance(uv[b]) - l).abs() / l)
        .fold(0.0, f64::max)
}

/// The chart `faces` laid out as `start`, relaxed so that its boundary edges have their 3D
/// lengths (see the module doc); `start` itself when that does not help.
pub fn match_seams(mesh: &Mesh, faces: &[usize], start: &ChartParam) -> ChartParam {
    let Ok(chart) = build_chart(mesh, faces) else {
        return start.clone();
    };
    match_seams_of(mesh, faces, &chart, start)
}

/// [`match_seams`] with the chart of `faces` already built.
pub(super) fn match_seams_of(
    mesh: &Mesh,
    faces: &[usize],
    chart: &Chart,
    start: &ChartParam,
) -> ChartParam {
    let nv = chart.pos.len();
    let uv = vertex_uv(chart, &start.uv);
    let bl = &chart.boundary_loop;
    let edges: Vec<(usize, usize, f64)> = (0..bl.len())
        .map(|k| {
            let (a, b) = (bl[k], bl[(k + 1) % bl.len()]);
            (a, b, chart.pos[a].distance(chart.pos[b]))
        })
        .filter(|e| e.2 > 0.0 && e.2.is_finite())
        .collect();
    let before = boundary_error(&uv, &edges);
    if before.is_nan() || before <= EXACT || nv < 3 {
        return start.clone();
    }
    let shapes = shapes_from_3d(chart);
    let cots = half_cotangents(&shapes);
    // Where the relaxed layout flips a triangle, the next attempt starts partway there.
    let flips = |uv: &[DVec2]| {
        chart
            .tris
            .iter()
            .filter(|t| (uv[t[1]] - uv[t[0]]).perp_dot(uv[t[2]] - uv[t[0]]) <= 0.0)
            .count()
    };
    let allowed = flips(&uv);
    let mut from = uv.clone();
    for _ in 0..ATTEMPTS {
        let Some(r) = relax(chart, &shapes, &cots, &edges, from.clone()) else {
            break;
        };
        if flips(&r) <= allowed {
            from = r;
            break;
        }
        let partway = (1..=6).map(|j| 0.5f64.powi(j)).find_map(|t| {
            let p: Vec<DVec2> = from
                .iter()
                .zip(&r)
                .map(|(&a, &b)| a + (b - a) * t)
                .collect();
            (flips(&p) <= allowed).then_some(p)
        });
        match partway {
            Some(p) => from = p,
            None => break,
        }
    }
    let relaxed = from;
    // The inside relaxed to the least L2 stretch the matched boundary allows.
    let mut relaxed =
        minimise_stretch(chart, relaxed.clone(), &chart.boundary, SWEEPS).unwrap_or(relaxed);
    // Lengths the rigid matching could not reach without a flip: every vertex moved at once
    // under a rising penalty on them, flip-free throughout.
    if boundary_error(&relaxed, &edges) > RESCUE_ABOVE {
        if let Some(r) = lbfgs::match_lengths(chart, relaxed.clone(), &edges) {
            if boundary_error(&r, &edges) < boundary_error(&relaxed, &edges) {
                relaxed = r;
            }
        }
    }
    let after = boundary_error(&relaxed, &edges);
    if after.is_nan() || after >= before {
        return start.clone();
    }
    let mut lo = DVec2::splat(f64::INFINITY);
    for p in &relaxed {
        lo = lo.min(*p);
    }
    let face_uv: Vec<Vec<DVec2>> = chart
        .corners
        .iter()
        .map(|cs| cs.iter().map(|&v| relaxed[v] - lo).collect())
        .collect();
    let stretch = distortion::stretch(mesh, faces, &face_uv);
    if stretch.flipped > start.stretch.flipped || !stretch.l2.is_finite() {
        return start.clone();
    }
    ChartParam {
        faces: faces.to_vec(),
        uv: face_uv,
        method: start.method,
        stretch,
    }
}

/// The local/global iteration of the module doc from `uv`; `None` when a solve fails.
fn relax(
    chart: &Chart,
    shapes: &[[DVec2; 3]],
    cots: &[[f64; 3]],
    edges: &[(usize, usize, f64)],
    mut uv: Vec<DVec2>,
) -> Option<Vec<DVec2>> {
    let (n, tris) = (uv.len(), &chart.tris);
    // The pinned vertex keeps its place softly: translation is free in the energy.
    let pin = edges.first().map_or(0, |e| e.0);
    let mut solver: Option<(Pattern, Cholesky)> = None;
    for &w in &WEIGHTS {
        let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(tris.len() * 9);
        push_cotangent_laplacian(&mut trip, tris, cots);
        for &(a, b, _) in edges {
            push_edge(&mut trip, a, b, w);
        }
        trip.push(Triplet::new(pin, pin, 1.0));
        // Every weight has the same pattern: one assembly pattern, ordering and symbolic
        // factorisation.
        if !solver.as_ref().is_some_and(|s| s.0.fits(n, &trip)) {
            let pattern = Pattern::new(n, &trip)?;
            let factor = chart.vertex_cholesky(&pattern)?;
            solver = Some((pattern, factor));
        }
        let (pattern, factor) = solver.as_mut()?;
        if !factor.factor(&pattern.matrix(&trip)) {
            return None;
        }
        for _ in 0..ITERATIONS {
            let mut rhs = vec![DVec2::ZERO; n];
            for ((tri, s), c) in tris.iter().zip(shapes).zip(cots) {
                // Best rotation: maximise tr(Rᵀ S), S = Σ cot (uᵢ − uⱼ)(xᵢ − xⱼ)ᵀ.
                let (mut a, mut b, mut cc, mut d) = (0.0, 0.0, 0.0, 0.0);
                for (k, &ck) in c.iter().enumerate() {
                    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                    let du = uv[tri[i]] - uv[tri[j]];
                    let dx = s[i] - s[j];
                    a += ck * du.x * dx.x;
                    b += ck * du.x * dx.y;
                    cc += ck * du.y * dx.x;
                    d += ck * du.y * dx.y;
                }
                // Its angle's cosine and sine, without the angle.
                let r = DVec2::new(a + d, cc - b);
                let len = r.length();
                let r = if len > 0.0 { r / len } else { DVec2::X };
                for (k, &ck) in c.iter().enumerate() {
                    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                    let t = ck * r.rotate(s[i] - s[j]);
                    rhs[tri[i]] += t;
                    rhs[tri[j]] -= t;
                }
            }
            for &(a, b, l) in edges {
                let du = uv[a] - uv[b];
                let len = du.length();
                let t = if len > 0.0 { du * (l / len) } else { du };
                rhs[a] += w * t;
                rhs[b] -= w * t;
            }
            rhs[pin] += uv[pin];
            let mut x: Vec<f64> = rhs
                .iter()
                .map(|r| r.x)
                .chain(rhs.iter().map(|r| r.y))
                .collect();
            if !factor.solve(&mut x, 2) {
                return None;
            }
            for (i, p) in uv.iter_mut().enumerate() {
                *p = DVec2::new(x[i], x[n + i]);
            }
            if uv.iter().any(|p| !p.is_finite()) {
                return None;
            }
        }
    }
    Some(uv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::param::{parameterize, ParamMethod};
    use crate::geom::mesh::Face;
    use glam::DVec3;

    /// A spherical cap of `n` × `rings` quads split in triangles, radius 100 mm.
    fn cap(deg: f64, n: usize, rings: usize) -> Mesh {
        let r = 100.0;
        let mut vertices = vec![DVec3::new(0.0, 0.0, r)];
        for k in 1..=rings {
            let th = (deg.to_radians()) * k as f64 / rings as f64;
            for i in 0..n {
                let ph = std::f64::consts::TAU * i as f64 / n as f64;
                vertices.push(DVec3::new(
                    r * th.sin() * ph.cos(),
                    r * th.sin() * ph.sin(),
                    r * th.cos(),
                ));
            }
        }
        let at = |k: usize, i: usize| 1 + (k - 1) * n + i % n;
        let mut faces = Vec::new();
        let mut push = |verts: Vec<usize>| faces.push(Face { verts, line: None });
        for i in 0..n {
            push(vec![0, at(1, i), at(1, i + 1)]);
        }
        for k in 1..rings {
            for i in 0..n {
                push(vec![at(k, i), at(k + 1, i), at(k + 1, i + 1)]);
                push(vec![at(k, i), at(k + 1, i + 1), at(k, i + 1)]);
            }
        }
        Mesh { vertices, faces }
    }

    #[test]
    fn a_curved_cap_gets_its_boundary_lengths() {
        let mesh = cap(25.0, 24, 6);
        let faces: Vec<usize> = (0..mesh.faces.len()).collect();
        let p = parameterize(&mesh, &faces, ParamMethod::Best).expect("cap");
        let chart = build_chart(&mesh, &faces).expect("chart");
        let rim = |uv: &[Vec<DVec2>]| -> (f64, f64) {
            // Flat and 3D length of the rim (the last ring of faces' outer edges).
            let flat = vertex_uv(&chart, uv);
            let bl = &chart.boundary_loop;
            let (mut a, mut b) = (0.0, 0.0);
            for k in 0..bl.len() {
                let (i, j) = (bl[k], bl[(k + 1) % bl.len()]);
                a += flat[i].distance(flat[j]);
                b += chart.pos[i].distance(chart.pos[j]);
            }
            (a, b)
        };
        let (f0, l3) = rim(&p.uv);
        // The conformal start shortens or stretches the rim by a visible amount.
        assert!((f0 - l3).abs() / l3 > 2e-3, "start {f0} vs {l3}");
        let m = match_seams(&mesh, &faces, &p);
        let (f1, _) = rim(&m.uv);
        assert!((f1 - l3).abs() / l3 < 1e-4, "matched {f1} vs {l3}");
        assert_eq!(m.stretch.flipped, 0);
        // The inside takes the stretch up: L2 stays near the start's.
        assert!(
            m.stretch.l2 < p.stretch.l2 + 0.01,
            "{} vs {}",
            m.stretch.l2,
            p.stretch.l2
        );
    }

    #[test]
    fn a_developable_chart_is_left_as_it_is() {
        // A flat disk: LSCM lays it out isometrically.
        let mut mesh = cap(25.0, 24, 3);
        for v in mesh.vertices.iter_mut() {
            v.z = 0.0;
        }
        let faces: Vec<usize> = (0..mesh.faces.len()).collect();
        let p = parameterize(&mesh, &faces, ParamMethod::Best).expect("cone");
        assert_eq!(match_seams(&mesh, &faces, &p), p);
    }
}
