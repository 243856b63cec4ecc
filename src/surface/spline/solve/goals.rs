//! The goals of a spline solve besides its constraints (Tang et al. 2016): a target's
//! footpoints and eq. 9–11 (§4.2), and handles dragging surface points towards 3D positions;
//! their rows and their share of the merit, over the solver's layout.
//!
//! Choices where the paper is silent are in [`super`]'s doc: footpoints on the nearest strip,
//! the surface normal held fixed within an iteration (as Fig. 16 does), eq. 9 weighted up at
//! the strip's edge so that it grows, handles ramped to their goal.

use super::{normal_of, CreaseSample, Layout, Row, STILL};
use crate::geom::bspline::BSpline;
use crate::surface::spline::system::{eval, Expr};
use crate::surface::spline::target::StripRef;
use glam::DVec3;

/// A target point's footpoint at the current iterate: strip, parameters and the surface's
/// unit normal there (held fixed within the iteration, as Fig. 16 does).
#[derive(Debug, Clone, Copy)]
pub(super) struct Foot {
    pub(super) strip: usize,
    pub(super) u: f64,
    pub(super) v: f64,
    pub(super) n: DVec3,
}

/// Iterations over which a handle's goal moves from where it starts to where it is dragged
/// (a drag in small steps, as in interactive use: one step of the whole way lifts a flat
/// sheet by second-order length changes the isometry rows do not see).
pub const HANDLE_RAMP: usize = 10;

/// The weight of a handle's three rows (Fig. 17: user-defined constraints weigh 1).
const W_HANDLE: f64 = 1.0;

/// Weights of eq. 9, 10 and 11 (Fig. 17's footnote: 1e-3, 1e-4, 1e-2).
const W9: f64 = 1e-3;
const W10: f64 = 1e-4;
const W11: f64 = 1e-2;

/// The handles' rows: the surface point of each towards its goal of this iteration (the
/// coordinates a lift leaves free, NaN, have none).
pub(super) fn handle_rows(l: &Layout, basis: &BSpline, rows: &mut Vec<Row>) {
    for ((f, _), to) in l.handles.iter().zip(&l.handle_now) {
        let (s, _, _) = foot_exprs(l, basis, f);
        for c in (0..3).filter(|&c| to[c].is_finite()) {
            rows.push(dot_row(l, &s, DVec3::AXES[c], to[c], W_HANDLE));
        }
    }
}

/// The strip `k` of the layout's points as the footpoint search sees it.
fn strip_ref<'a>(l: &'a Layout, basis: &'a BSpline, k: usize) -> StripRef<'a> {
    let count = basis.count();
    let (a, b) = l.strips[k];
    let curve = |c: usize| &l.points[c * count..(c + 1) * count];
    StripRef {
        basis,
        a: curve(a),
        b: match b {
            Some(b) => Ok(curve(b)),
            None => Err(l.points[l.points.len() - 1]),
        },
    }
}

/// The footpoint of `q` on its nearest strip (of those whose search `grids` are given), with
/// the surface normal there.
pub(super) fn nearest_foot(
    l: &Layout,
    basis: &BSpline,
    grids: &[Vec<(f64, f64, DVec3)>],
    q: DVec3,
) -> Foot {
    let mut best = (
        f64::INFINITY,
        Foot {
            strip: 0,
            u: 0.0,
            v: 0.0,
            n: DVec3::ZERO,
        },
    );
    for (k, grid) in grids.iter().enumerate() {
        let st = strip_ref(l, basis, k);
        let (u, v, d) = st.footpoint(grid, q);
        if d < best.0 {
            let (_, su, sv) = st.eval(u, v);
            let n = su.cross(sv).normalize_or_zero();
            best = (d, Foot { strip: k, u, v, n });
        }
    }
    best.1
}

/// The search grids of every strip.
pub(super) fn grids(l: &Layout, basis: &BSpline) -> Vec<Vec<(f64, f64, DVec3)>> {
    (0..l.strips.len())
        .map(|k| strip_ref(l, basis, k).grid())
        .collect()
}

/// The footpoint of every target point on its nearest strip, with the surface normal there.
pub(super) fn feet(l: &Layout, basis: &BSpline) -> Vec<Foot> {
    if l.target.is_empty() {
        return Vec::new(); // no grids to build
    }
    let grids = grids(l, basis);
    l.target
        .iter()
        .map(|&(q, _)| nearest_foot(l, basis, &grids, q))
        .collect()
}

/// Expressions of s(u, v), e = b(u) − a(u) and a′(u) on strip `k`.
pub(super) fn foot_exprs(l: &Layout, basis: &BSpline, f: &Foot) -> (Expr, Expr, Expr) {
    let count = basis.count();
    let (a, b) = l.strips[f.strip];
    let r = basis.rows(f.u);
    let on = |c: usize, row: &[(usize, f64)], k: f64| -> Expr {
        row.iter().map(|&(j, w)| (c * count + j, k * w)).collect()
    };
    let apex = l.points.len() - 1;
    let (mut s, mut e) = (on(a, &r.point, 1.0 - f.v), on(a, &r.point, -1.0));
    match b {
        Some(b) => {
            s.extend(on(b, &r.point, f.v));
            e.extend(on(b, &r.point, 1.0));
        }
        None => {
            s.push((apex, f.v));
            e.push((apex, 1.0));
        }
    }
    (s, e, on(a, &r.d1, 1.0))
}

/// The row ⟨d, Σ w·P⟩ = rhs with weight `w`, fixed points moved to the right-hand side.
fn dot_row(l: &Layout, expr: &Expr, d: DVec3, rhs: f64, w: f64) -> Row {
    let mut entries = Vec::with_capacity(3 * expr.len());
    let mut rhs = rhs;
    for &(p, k) in expr {
        match l.var[p] {
            Some(o) => {
                for c in 0..3 {
                    if d[c] != 0.0 {
                        entries.push((o + c, k * d[c]));
                    }
                }
            }
            None => rhs -= k * d.dot(l.points[p]),
        }
    }
    Row { entries, rhs, w }
}

/// Eq. 9–11 at the footpoints: s(u, v) = q (three rows), ⟨m, e⟩/|e| = ⟨m, a′⟩/|a′| = 0 and
/// ⟨s(u, v) − q, n⟩ = 0 with n held fixed.
pub(super) fn target_rows(l: &Layout, basis: &BSpline, feet: &[Foot], rows: &mut Vec<Row>) {
    for (f, &(q, m)) in feet.iter().zip(&l.target) {
        let (s, e, ta) = foot_exprs(l, basis, f);
        for c in 0..3 {
            rows.push(dot_row(l, &s, DVec3::AXES[c], q[c], w9(l, basis, f)));
        }
        for d in [&e, &ta] {
            let len = eval(d, &l.points).length();
            if len > 1e-12 {
                rows.push(dot_row(l, d, m / len, 0.0, W10));
            }
        }
        if f.n != DVec3::ZERO {
            rows.push(dot_row(l, &s, f.n, f.n.dot(q), W11));
        }
    }
}

/// The weight of eq. 9 at a footpoint: [`W9`] inside the strip, [`W11`] on its edge (where
/// the target goes on beyond the strip, eq. 9 is what makes it grow).
fn w9(l: &Layout, basis: &BSpline, f: &Foot) -> f64 {
    let spans = basis.spans() as f64;
    let on_end = !basis.closed() && (f.u <= 1e-9 || f.u >= spans - 1e-9);
    let (a, b) = l.strips[f.strip];
    // An edge curve: the first curve of the chain at v = 0, the last at v = 1.
    let first = a == 0 && f.v <= 1e-9;
    let last = b == Some(l.strips.len()) && f.v >= 1.0 - 1e-9;
    if on_end || first || last {
        W11
    } else {
        W9
    }
}

/// The handles' weighted squared residual and their largest distance from the goal.
pub(super) fn handle_merit(l: &Layout, basis: &BSpline, now: bool) -> (f64, f64) {
    let (mut sum, mut worst) = (0.0, 0.0f64);
    for (k, (f, goal)) in l.handles.iter().enumerate() {
        let to = if now { &l.handle_now[k] } else { goal };
        let p = eval(&foot_exprs(l, basis, f).0, &l.points);
        // A coordinate left free (NaN: a lift sets only the height) does not count.
        let d = (0..3)
            .filter(|&c| to[c].is_finite())
            .map(|c| (p[c] - to[c]).powi(2))
            .sum::<f64>()
            .sqrt();
        sum += W_HANDLE * W_HANDLE * d * d;
        worst = worst.max(d);
    }
    (sum, worst)
}

/// The weighted squared residual of eq. 9–11 at `feet` and the mean squared distance.
pub(super) fn target_merit(l: &Layout, basis: &BSpline, feet: &[Foot]) -> (f64, f64) {
    let (mut sum, mut dist) = (0.0, 0.0);
    for (f, &(q, m)) in feet.iter().zip(&l.target) {
        let (s, e, ta) = foot_exprs(l, basis, f);
        let r = eval(&s, &l.points) - q;
        dist += r.length_squared();
        let w = w9(l, basis, f);
        sum += w * w * r.length_squared() + W11 * W11 * r.dot(f.n).powi(2);
        for d in [&e, &ta] {
            let d = eval(d, &l.points);
            let len = d.length();
            if len > 1e-12 {
                sum += W10 * W10 * (m.dot(d) / len).powi(2);
            }
        }
    }
    (sum, dist / feet.len().max(1) as f64)
}

/// The least mean angle (radians, 1°) of a fold stated by its direction alone: enough to
/// leave the flat start on that side.
pub const FOLD_MIN: f64 = std::f64::consts::PI / 180.0;

/// The weight of a stated fold's row (a user-defined goal, like a handle).
const W_FOLD: f64 = 1.0;

/// The fold angle at one crease sample — the signed angle from the left strip's normal to
/// the right one's about the crease tangent, positive for a valley seen from the front (the
/// solver's normals are e × a′, against the sampled mesh's faces a′ × e, which the pattern's
/// mountain and valley see) — and its gradient in the two normals (atan2 of ⟨n_L × n_R, t⟩
/// and ⟨n_L, n_R⟩, t held fixed).
fn fold_at(l: &Layout, x: &[f64], c: &CreaseSample) -> (f64, DVec3, DVec3) {
    let (sl, sr) = (&l.samples[c.left], &l.samples[c.right]);
    let (nl, nr) = (normal_of(x, sl), normal_of(x, sr));
    let t = eval(&sr.ta, &l.points).normalize_or_zero();
    let (s, co) = (nl.cross(nr).dot(t), nl.dot(nr));
    let q = (s * s + co * co).max(1e-300);
    let phi = s.atan2(co);
    let gl = (co * nr.cross(t) - s * nr) / q;
    let gr = (co * t.cross(nl) - s * nl) / q;
    (phi, gl, gr)
}

/// A stated fold's mean angle in its direction (radians; negative when it folds the other
/// way), weighted by length along the crease, and the gradient of that mean in the normals
/// (the weights held at the iterate), as row entries.
pub(super) fn fold_mean(l: &Layout, x: &[f64], f: &FoldGoalRows) -> (f64, Vec<(usize, f64)>) {
    // Each sample weighs its share of the crease's length, |c′| (the samples are equally
    // spaced in u); where the crease stands still it has no angle and no weight.
    let speed = |k: usize| {
        let t = eval(&l.samples[l.creases[k].right].ta, &l.points).length();
        if t > STILL {
            t
        } else {
            0.0
        }
    };
    let total: f64 = f.creases.iter().map(|&k| speed(k)).sum();
    let mut mean = 0.0;
    let mut entries = Vec::with_capacity(6 * f.creases.len());
    if total <= 0.0 {
        return (mean, entries);
    }
    for &k in &f.creases {
        let w = speed(k) / total;
        if w == 0.0 {
            continue;
        }
        let c = &l.creases[k];
        let (phi, gl, gr) = fold_at(l, x, c);
        mean += w * f.sigma * phi;
        for (s, g) in [(&l.samples[c.left], gl), (&l.samples[c.right], gr)] {
            for i in 0..3 {
                entries.push((s.normal + i, w * f.sigma * g[i]));
            }
        }
    }
    (mean, entries)
}

/// The stated folds' rows: the mean angle at this iteration's goal (an angle), or raised to
/// [`FOLD_MIN`] where it is less (a direction alone).
pub(super) fn fold_rows(l: &Layout, x: &[f64], rows: &mut Vec<Row>) {
    for f in &l.folds {
        let (mean, entries) = fold_mean(l, x, f);
        let goal = match f.angle {
            Some(_) => f.now,
            None if mean < FOLD_MIN => FOLD_MIN,
            None => continue,
        };
        // Σ gᵢ xᵢ = goal − mean + Σ gᵢ xᵢ at the iterate.
        let at: f64 = entries.iter().map(|&(i, g)| g * x[i]).sum();
        rows.push(Row {
            entries,
            rhs: goal - mean + at,
            w: W_FOLD,
        });
    }
}

/// The stated folds' weighted squared residual and their largest distance (radians) from
/// the goal (this iteration's with `now`, else the final one).
pub(super) fn fold_merit(l: &Layout, x: &[f64], now: bool) -> (f64, f64) {
    let (mut sum, mut worst) = (0.0, 0.0f64);
    for f in &l.folds {
        let mean = fold_mean(l, x, f).0;
        let d = match f.angle {
            Some(a) => (mean - if now { f.now } else { a }).abs(),
            None => (FOLD_MIN - mean).max(0.0),
        };
        sum += W_FOLD * W_FOLD * d * d;
        worst = worst.max(d);
    }
    (sum, worst)
}

/// A stated fold in the solver: its crease samples (indices into the layout's creases), the
/// direction (1 valley, −1 mountain), the mean angle asked for, and where its goal starts and
/// stands this iteration (moved from the start to the angle over [`HANDLE_RAMP`] iterations).
pub(super) struct FoldGoalRows {
    pub(super) creases: Vec<usize>,
    pub(super) sigma: f64,
    pub(super) angle: Option<f64>,
    pub(super) start: f64,
    pub(super) now: f64,
}
