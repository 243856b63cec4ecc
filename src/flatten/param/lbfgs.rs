//! L2 stretch minimised over the whole chart at once: the energy of [`super::stretch`]
//! (Sander, Snyder, Gortler, Hoppe 2001 §4: E = (Σ A₃·f) · (Σ A₂), f = ‖J‖²_F with J the linear
//! map from a flat triangle to its 3D shape) by limited-memory BFGS (Liu and Nocedal 1989,
//! two-loop recursion), every vertex moving in each step. The paper moves one vertex at a
//! time; on a chart of a thousand vertices that leaves the smooth part of the error to
//! hundreds of sweeps, where a quasi-Newton step with a Laplacian preconditioner carries it
//! in tens of steps.
//!
//! Choices where the papers are silent:
//! - **Preconditioner**: the chart's cotangent Laplacian (the Dirichlet energy of its 3D
//!   triangles, which the stretch energy's Hessian resembles near an isometry), softly pinned
//!   at one vertex (translation costs nothing in E), factored once per call by sparse
//!   Cholesky; the initial inverse Hessian is it scaled by sᵀy / yᵀL⁻¹y of the last step
//!   (by 1 / (4 Σ A₂) before the first). Memory: [`MEMORY`] pairs.
//! - **Steps**: backtracking from the full quasi-Newton step (halved at most 30 times) until
//!   E decreases by the Armijo condition and no triangle flips or collapses, so the layout
//!   stays flip-free and E never increases. A pair whose curvature sᵀy is not positive is not
//!   kept; a direction that is not one of descent restarts from the preconditioned gradient.
//! - **Stopping**: after `max_iter` steps, or when a step lowers E by less than `rel` of it.
//! - **Seam lengths** ([`match_lengths`]): a penalty k Σ ((|uᵢ − uⱼ| − ℓ)/ℓ)² on the given
//!   edges, k = μ E₀ with μ rising through [`PENALTIES`], each stage started where the last
//!   ended: the boundary is brought to its 3D lengths while every vertex, the boundary's
//!   included, still moves to lower the stretch, and nothing flips on the way. Used where
//!   the as-rigid-as-possible matching of [`super::seams`] cannot reach the lengths without
//!   a flip.

use super::solve::{half_cotangents, push_cotangent_laplacian};
use super::{shapes_from_3d, Chart};
use crate::geom::sparse::{Cholesky, Pattern};
use faer::sparse::Triplet;
use glam::{DMat2, DVec2};
use std::collections::VecDeque;

/// Pairs (s, y) the quasi-Newton approximation keeps.
const MEMORY: usize = 6;
/// Halvings of a step at most.
const HALVINGS: usize = 30;
/// Armijo's sufficient decrease.
const ARMIJO: f64 = 1e-4;
/// Weights of the length penalty of [`match_lengths`], in turn, relative to E at the start.
pub(crate) const PENALTIES: [f64; 3] = [1e3, 1e5, 1e7];
/// Steps at most per weight of [`match_lengths`].
const MATCH_STEPS: usize = 100;

/// The stretch energy of a chart and its length penalty, with their gradients.
struct Energy<'a> {
    tris: &'a [[usize; 3]],
    /// Each triangle's 3D shape as the columns (corner 1 − corner 0, corner 2 − corner 0).
    q: Vec<DMat2>,
    /// 3D areas.
    a3: Vec<f64>,
    /// Penalised edges (local vertices, 3D length) and the penalty's weight k.
    edges: &'a [(usize, usize, f64)],
    k: f64,
}

impl Energy<'_> {
    /// (Σ A₃·f, Σ A₂) at `uv`, and where asked their gradients (added into `gs`, `ga`);
    /// `None` when a triangle is flipped or collapsed.
    fn sums(
        &self,
        uv: &[DVec2],
        mut grads: Option<(&mut [DVec2], &mut [DVec2])>,
    ) -> Option<(f64, f64)> {
        let (mut s, mut a) = (0.0, 0.0);
        for ((t, q), &a3) in self.tris.iter().zip(&self.q).zip(&self.a3) {
            let p = DMat2::from_cols(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]);
            let d = p.determinant();
            if !(d > 0.0 && d.is_finite()) {
                return None;
            }
            let pi = p.inverse();
            let j = *q * pi;
            s += a3 * (j.x_axis.length_squared() + j.y_axis.length_squared());
            a += 0.5 * d;
            if let Some((gs, ga)) = grads.as_mut() {
                // ∂‖Q P⁻¹‖²/∂P = −2 JᵀJ P⁻ᵀ; ∂(det P / 2)/∂P = det P · P⁻ᵀ / 2.
                let pit = pi.transpose();
                let g = (j.transpose() * j * pit) * (-2.0 * a3);
                gs[t[1]] += g.x_axis;
                gs[t[2]] += g.y_axis;
                gs[t[0]] -= g.x_axis + g.y_axis;
                let h = pit * (0.5 * d);
                ga[t[1]] += h.x_axis;
                ga[t[2]] += h.y_axis;
                ga[t[0]] -= h.x_axis + h.y_axis;
            }
        }
        Some((s, a))
    }

    /// The penalty at `uv`, its gradient added into `g` where given.
    fn penalty(&self, uv: &[DVec2], mut g: Option<&mut [DVec2]>) -> f64 {
        let mut total = 0.0;
        for &(a, b, l) in self.edges {
            let d = uv[a] - uv[b];
            let len = d.length();
            let r = (len - l) / l;
            total += r * r;
            if let Some(g) = g.as_mut() {
                if len > 0.0 {
                    let gr = d * (2.0 * self.k * r / (l * len));
                    g[a] += gr;
                    g[b] -= gr;
                }
            }
        }
        self.k * total
    }

    /// E plus the penalty at `uv`; `None` when a triangle is flipped or collapsed.
    fn value(&self, uv: &[DVec2]) -> Option<f64> {
        let (s, a) = self.sums(uv, None)?;
        Some(s * a + self.penalty(uv, None))
    }

    /// [`Energy::value`] and its gradient (into `g`, zero at the `fixed` vertices), with
    /// `work` as scratch of the same length.
    fn gradient(&self, uv: &[DVec2], g: &mut [DVec2], work: &mut [DVec2]) -> Option<f64> {
        g.fill(DVec2::ZERO);
        work.fill(DVec2::ZERO);
        let (s, a) = self.sums(uv, Some((&mut *g, &mut *work)))?;
        for (gi, wi) in g.iter_mut().zip(work.iter()) {
            *gi = *gi * a + *wi * s;
        }
        Some(s * a + self.penalty(uv, Some(g)))
    }
}

fn dot(a: &[DVec2], b: &[DVec2]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

/// The chart's cotangent Laplacian (3D shapes), softly pinned at vertex 0, factored.
fn laplacian(chart: &Chart, shapes: &[[DVec2; 3]]) -> Option<Cholesky> {
    let n = chart.pos.len();
    let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(chart.tris.len() * 9 + 1);
    push_cotangent_laplacian(&mut trip, &chart.tris, &half_cotangents(shapes));
    trip.push(Triplet::new(0, 0, 1.0));
    let pattern = Pattern::new(n, &trip)?;
    let mut chol = chart.vertex_cholesky(&pattern)?;
    chol.factor(&pattern.matrix(&trip)).then_some(chol)
}

/// The preconditioner applied to `g` (both coordinates), into `out`.
fn precondition(chol: &mut Cholesky, g: &[DVec2], buf: &mut [f64], out: &mut [DVec2]) {
    let n = g.len();
    for (i, p) in g.iter().enumerate() {
        buf[i] = p.x;
        buf[n + i] = p.y;
    }
    chol.solve(buf, 2);
    for (i, o) in out.iter_mut().enumerate() {
        *o = DVec2::new(buf[i], buf[n + i]);
    }
}

/// Free-boundary L2 stretch minimisation of the flip-free layout `uv` (per local vertex), at
/// most `max_iter` steps, stopping when a step gains less than `rel` of E (see the module
/// doc); `None` when `uv` has a flipped or collapsed triangle or the Laplacian cannot be
/// factored.
pub(super) fn minimise(
    chart: &Chart,
    uv: Vec<DVec2>,
    max_iter: usize,
    rel: f64,
) -> Option<Vec<DVec2>> {
    let shapes = shapes_from_3d(chart);
    let mut chol = laplacian(chart, &shapes)?;
    let mut energy = energy(chart, &shapes, &[]);
    descend(&mut energy, &mut chol, uv, max_iter, rel, 0.0)
}

/// The flip-free layout `uv` with the `edges` (local vertices, 3D length) brought to their
/// lengths by the rising penalty of the module doc while the stretch is minimised; `None`
/// when `uv` has a flipped or collapsed triangle or the Laplacian cannot be factored.
pub(super) fn match_lengths(
    chart: &Chart,
    mut uv: Vec<DVec2>,
    edges: &[(usize, usize, f64)],
) -> Option<Vec<DVec2>> {
    let shapes = shapes_from_3d(chart);
    let mut chol = laplacian(chart, &shapes)?;
    let mut energy = energy(chart, &shapes, edges);
    let (s, a) = energy.sums(&uv, None)?;
    let e0 = s * a;
    for mu in PENALTIES {
        energy.k = mu * e0;
        uv = descend(&mut energy, &mut chol, uv, MATCH_STEPS, 1e-9, mu)?;
    }
    Some(uv)
}

fn energy<'a>(
    chart: &'a Chart,
    shapes: &[[DVec2; 3]],
    edges: &'a [(usize, usize, f64)],
) -> Energy<'a> {
    let q: Vec<DMat2> = shapes
        .iter()
        .map(|s| DMat2::from_cols(s[1] - s[0], s[2] - s[0]))
        .collect();
    let a3 = q.iter().map(|m| 0.5 * m.determinant()).collect();
    Energy {
        tris: &chart.tris,
        q,
        a3,
        edges,
        k: 0.0,
    }
}

/// L-BFGS on `energy` from `uv` (see the module doc); `mu` the penalty's relative weight
/// (it scales the first step).
fn descend(
    energy: &mut Energy,
    chol: &mut Cholesky,
    mut uv: Vec<DVec2>,
    max_iter: usize,
    rel: f64,
    mu: f64,
) -> Option<Vec<DVec2>> {
    let n = uv.len();
    let mut buf = vec![0.0; 2 * n];
    let mut work = vec![DVec2::ZERO; n];
    let mut g = vec![DVec2::ZERO; n];
    let mut e = energy.gradient(&uv, &mut g, &mut work)?;
    let (_, a0) = energy.sums(&uv, None)?;
    let mut gamma = 1.0 / (4.0 * a0 * (1.0 + mu));
    let mut pairs: VecDeque<(Vec<DVec2>, Vec<DVec2>, f64)> = VecDeque::with_capacity(MEMORY);
    let (mut d, mut trial, mut g_new) = (vec![DVec2::ZERO; n], uv.clone(), vec![DVec2::ZERO; n]);
    let mut alphas = Vec::with_capacity(MEMORY);
    for _ in 0..max_iter {
        // Two-loop recursion: d = −H g.
        let mut r = g.clone();
        alphas.clear();
        for (s, y, rho) in pairs.iter().rev() {
            let al = rho * dot(s, &r);
            for (ri, yi) in r.iter_mut().zip(y) {
                *ri -= *yi * al;
            }
            alphas.push(al);
        }
        precondition(chol, &r, &mut buf, &mut d);
        for v in d.iter_mut() {
            *v *= gamma;
        }
        for ((s, y, rho), al) in pairs.iter().zip(alphas.iter().rev()) {
            let be = rho * dot(y, &d);
            for (di, si) in d.iter_mut().zip(s) {
                *di += *si * (al - be);
            }
        }
        for v in d.iter_mut() {
            *v = -*v;
        }
        let mut slope = dot(&g, &d);
        if slope.is_nan() || slope >= 0.0 {
            pairs.clear();
            precondition(chol, &g, &mut buf, &mut d);
            for v in d.iter_mut() {
                *v *= -gamma;
            }
            slope = dot(&g, &d);
            if slope.is_nan() || slope >= 0.0 {
                break;
            }
        }
        let mut t = 1.0;
        let mut took = None;
        for _ in 0..HALVINGS {
            for ((o, x), dd) in trial.iter_mut().zip(&uv).zip(&d) {
                *o = *x + *dd * t;
            }
            if let Some(v) = energy.value(&trial) {
                if v <= e + ARMIJO * t * slope {
                    took = Some(v);
                    break;
                }
            }
            t *= 0.5;
        }
        let Some(e_new) = took else { break };
        energy.gradient(&trial, &mut g_new, &mut work)?;
        // The pair of this step, in the storage of the oldest one when memory is full.
        let (mut s, mut y) = match pairs.len() == MEMORY {
            true => pairs.pop_front().map(|(s, y, _)| (s, y))?,
            false => (vec![DVec2::ZERO; n], vec![DVec2::ZERO; n]),
        };
        for (si, di) in s.iter_mut().zip(&d) {
            *si = *di * t;
        }
        for ((yi, a), b) in y.iter_mut().zip(&g_new).zip(&g) {
            *yi = *a - *b;
        }
        let sy = dot(&s, &y);
        if sy > 0.0 {
            precondition(chol, &y, &mut buf, &mut work);
            let ypy = dot(&y, &work);
            if ypy > 0.0 {
                gamma = sy / ypy;
            }
            pairs.push_back((s, y, 1.0 / sy));
        }
        std::mem::swap(&mut uv, &mut trial);
        std::mem::swap(&mut g, &mut g_new);
        let gain = e - e_new;
        e = e_new;
        if gain < rel * e {
            break;
        }
    }
    Some(uv)
}

#[cfg(test)]
mod tests {
    use super::super::tests::bumpy_grid;
    use super::super::{build_chart, parameterize, vertex_uv, ParamMethod, STRETCH_SWEEPS};
    use super::*;
    use crate::flatten::distortion;
    use crate::flatten::param::stretch::minimise_stretch;

    /// The bumpy grid's chart and its LSCM layout (per local vertex).
    fn start() -> (crate::geom::mesh::Mesh, Vec<usize>, Chart, Vec<DVec2>) {
        let m = bumpy_grid();
        let faces: Vec<usize> = (0..m.faces.len()).collect();
        let chart = build_chart(&m, &faces).expect("chart");
        let l = parameterize(&m, &faces, ParamMethod::Lscm).expect("lscm");
        let uv = vertex_uv(&chart, &l.uv);
        (m, faces, chart, uv)
    }

    fn face_uv(chart: &Chart, uv: &[DVec2]) -> Vec<Vec<DVec2>> {
        chart
            .corners
            .iter()
            .map(|cs| cs.iter().map(|&v| uv[v]).collect())
            .collect()
    }

    /// E is the scale-free L2 stretch that `distortion` measures (E = 2 A₃² L2²), and its
    /// gradient, with a length penalty on, agrees with central differences.
    #[test]
    fn energy_is_the_measured_stretch_and_its_gradient_is_exact() {
        let (m, faces, chart, uv) = start();
        let shapes = shapes_from_3d(&chart);
        let edges: Vec<(usize, usize, f64)> = (0..chart.boundary_loop.len())
            .map(|k| {
                let bl = &chart.boundary_loop;
                let (a, b) = (bl[k], bl[(k + 1) % bl.len()]);
                (a, b, chart.pos[a].distance(chart.pos[b]))
            })
            .collect();
        let mut e = energy(&chart, &shapes, &edges);
        let (s, a) = e.sums(&uv, None).expect("flip-free");
        let a3: f64 = e.a3.iter().sum();
        let l2 = distortion::stretch(&m, &faces, &face_uv(&chart, &uv)).l2;
        let from_e = (s * a / (2.0 * a3 * a3)).sqrt();
        assert!((from_e - l2).abs() < 1e-9 * l2, "{from_e} vs {l2}");
        assert!(l2 > 1.001, "the start is stretched: {l2}");
        e.k = 10.0 * s * a;
        let n = uv.len();
        let (mut g, mut work) = (vec![DVec2::ZERO; n], vec![DVec2::ZERO; n]);
        let v0 = e.gradient(&uv, &mut g, &mut work).expect("flip-free");
        assert!((v0 - e.value(&uv).expect("value")).abs() < 1e-12 * v0);
        let h = 1e-6;
        for v in [0, 9, 24, n - 1] {
            for dir in [DVec2::X, DVec2::Y] {
                let (mut p, mut q) = (uv.clone(), uv.clone());
                p[v] += dir * h;
                q[v] -= dir * h;
                let fd = (e.value(&p).unwrap() - e.value(&q).unwrap()) / (2.0 * h);
                let mine = g[v].dot(dir);
                assert!(
                    (mine - fd).abs() < 1e-5 * g.iter().map(|x| x.length()).fold(0.0, f64::max),
                    "vertex {v}: {mine} vs {fd}"
                );
            }
        }
    }

    /// From the LSCM layout of a non-developable grid: flip-free, a lower L2 than the start
    /// and no higher than 60 vertex-by-vertex sweeps reach; a developable chart stays
    /// isometric.
    #[test]
    fn minimising_lowers_stretch_without_flips_and_keeps_an_isometry() {
        let (m, faces, chart, uv) = start();
        let measure = |uv: &[DVec2]| distortion::stretch(&m, &faces, &face_uv(&chart, uv));
        let before = measure(&uv);
        let sweeps = minimise_stretch(&chart, uv.clone(), &vec![false; uv.len()], STRETCH_SWEEPS)
            .expect("sweeps");
        let lb = minimise(&chart, uv.clone(), 200, 1e-9).expect("lbfgs");
        let (after, by_sweeps) = (measure(&lb), measure(&sweeps));
        assert_eq!(after.flipped, 0);
        assert!(after.l2 < before.l2, "{} vs {}", after.l2, before.l2);
        assert!(
            after.l2 <= by_sweeps.l2 + 1e-9,
            "{} vs {}",
            after.l2,
            by_sweeps.l2
        );
        // Flat: the grid without its bumps is laid out exactly and stays so.
        let mut flat = bumpy_grid();
        for v in &mut flat.vertices {
            v.z = 0.0;
        }
        let chart = build_chart(&flat, &faces).expect("chart");
        let l = parameterize(&flat, &faces, ParamMethod::Lscm).expect("lscm");
        let uv = vertex_uv(&chart, &l.uv);
        let out = minimise(&chart, uv, 200, 1e-9).expect("lbfgs");
        let s = distortion::stretch(&flat, &faces, &face_uv(&chart, &out));
        assert!((s.l2 - 1.0).abs() < 1e-9 && s.flipped == 0, "{s:?}");
        // A flipped start (the layout mirrored) is refused.
        let (_, _, chart, uv) = start();
        let mirrored: Vec<DVec2> = uv.iter().map(|p| DVec2::new(-p.x, p.y)).collect();
        assert_eq!(measure(&mirrored).flipped, chart.tris.len());
        assert!(minimise(&chart, mirrored, 10, 1e-9).is_none());
    }

    /// The boundary brought to its 3D lengths (within 1e-6) from the free layout, flip-free,
    /// the stretch taken up inside (L2 above the free layout's).
    #[test]
    fn matching_lengths_reaches_them_without_flips() {
        let (m, faces, chart, uv) = start();
        let free = minimise(&chart, uv, 200, 1e-9).expect("free");
        let bl = &chart.boundary_loop;
        let edges: Vec<(usize, usize, f64)> = (0..bl.len())
            .map(|k| {
                let (a, b) = (bl[k], bl[(k + 1) % bl.len()]);
                (a, b, chart.pos[a].distance(chart.pos[b]))
            })
            .collect();
        let worst = |uv: &[DVec2]| {
            edges
                .iter()
                .map(|&(a, b, l)| (uv[a].distance(uv[b]) - l).abs() / l)
                .fold(0.0, f64::max)
        };
        assert!(
            worst(&free) > 1e-3,
            "the free layout's lengths differ: {}",
            worst(&free)
        );
        let matched = match_lengths(&chart, free.clone(), &edges).expect("matched");
        assert!(worst(&matched) < 1e-6, "{}", worst(&matched));
        let s = distortion::stretch(&m, &faces, &face_uv(&chart, &matched));
        let f = distortion::stretch(&m, &faces, &face_uv(&chart, &free));
        assert_eq!(s.flipped, 0);
        assert!(s.l2 >= f.l2 && s.l2 < f.l2 + 0.05, "{} vs {}", s.l2, f.l2);
    }
}
