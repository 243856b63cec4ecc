//! Guided projection (Tang et al. 2016, §3.2 eq. 6) for spline developables: the unknowns are
//! the free control points of the curves (and of a cone's apex) and one normal per sample
//! parameter (3m − 2 per span, §2.1); the constraints are eq. 4 — ⟨n, b − a⟩ = ⟨n, a′⟩ =
//! ⟨n, b′⟩ = 0 — and ⟨n, n⟩ = 1. Every iteration linearises them at the current point and
//! solves (HᵀW²H + ε₁²KᵀK + ε₂²I) x = HᵀW²r + ε₁²Kᵀs + ε₂²xₖ by a sparse Cholesky (faer),
//! whose symbolic factorisation is computed once: the pattern of the system never changes.
//!
//! Choices where the paper is silent (or mangled in the text):
//!
//! - `a′` stands for the paper's `a₁⁽¹⁾ − a₀⁽¹⁾` (the same direction, a positive multiple).
//! - Each constraint ⟨n, d⟩ is divided by |d| at the current iterate, so that its residual is a
//!   sine and the three kinds weigh alike; all weights are 1 (Fig. 17's).
//! - Fixed control points are not unknowns (exactly fixed, not weighted).
//! - Sample parameters are `s + (i + ½)/(3m − 2)` in span `s`.
//! - Fairness K: second differences of each control polygon (cyclic when closed), with s their
//!   values in the input, not 0: the paper's Σ‖aᵢ₊₁ − 2aᵢ + aᵢ₋₁‖² pulls a closed polygon
//!   towards one point, where every ruled surface is trivially "developable" (a loft between
//!   two rims can collapse to a double cone); measured against the input it keeps the
//!   designed shape without shrinking it. Schedule ε₁ = `epsilon1`·0.9ⁱ for the first
//!   `iterations` rounds (at least [`HANDLE_RAMP`] with handles) and 0 after (Fig. 17's);
//!   ε₂ = `epsilon2` while the fairness acts, then divided by 10 per round down to 1e-4 (held
//!   at ε₂ it damps the last rounds into linear convergence; much below 1e-4 the normal
//!   equations lose the digits the last rounds need).
//! - Goals besides the constraints — a target (eq. 9–11, rows in this file, footpoints from
//!   `target`), handles (weight 1, their goal moved there over [`HANDLE_RAMP`] rounds; with an
//!   outline a handle holds a point of the flat sheet, found on the surface again every
//!   iteration through the development's triangle that holds it, u and v interpolated there)
//!   and an outline (eq. 12, `develop`) — keep the solve going past the sine test until their
//!   measure stops changing; a deterministic work budget bounds the rounds of any design.
//! - The model is moved to its bounding box centre and scaled to diameter 1 inside.
//! - A step whose squared constraint residual is larger than the current one is halved, up to
//!   8 times (then taken as it is).
//! - The stop test is the largest *intrinsic* developability sine at the samples: the sine of
//!   the angle between the tangent planes at `a(u)` and `b(u)`,
//!   |det(e, a′, b′)|·|e| / (|e × a′|·|e × b′|) with e = b − a, which does not depend on the
//!   auxiliary normals. It is tested before the first iteration too, so an exact developable is
//!   returned untouched; so is the largest intrinsic crease sine ([`crease::crease_sine`]).
//! - Creases (§3.3): eq. 7–8 and the smooth condition, in [`crease`].
//! - A curve that stands still (a tangent shorter than [`STILL`] in the diameter-1 frame: a
//!   run of equal control points, which share one unknown) has no tangent: its conditions are
//!   left out there, a normal is oriented by the other curve's tangent, and where both stand
//!   still it takes the nearest sample's plane of its strip to start from.
//! - A stated fold (`folds`, §3.3 leaves the direction of a fold to the start) is one more
//!   goal row: the length-weighted mean over the crease's samples of the fold angle, the signed angle from the
//!   left strip's normal to the right one's about c′ (atan2, linearised in the normals), at
//!   the stated angle (its goal moved there from the start over [`HANDLE_RAMP`] rounds, like a
//!   handle) or, for a direction alone, at least [`FOLD_MIN`]. The fold angle of a curved
//!   crease varies along it (it follows the sides' bending); the mean is what a user sets.

mod crease;
mod goals;

use super::develop::Dev;
use super::system::{eval, normal_equations, sparse_solve, Expr, Pattern, Row};
use super::target::Target;
use crate::geom::bspline::BSpline;
use crease::{crease_residual, crease_rows, CreaseSample};
pub use crease::{crease_sine, Crease, STRAIGHT};
use glam::DVec3;
use goals::{
    feet, fold_mean, fold_merit, fold_rows, foot_exprs, grids, handle_merit, handle_rows,
    nearest_foot, target_merit, target_rows, FoldGoalRows, Foot,
};
pub use goals::{FOLD_MIN, HANDLE_RAMP};

/// The solver's settings (spec keys of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// Rounds in which the fairness energy acts (ε₁ decays by 0.9 per round, then is 0).
    pub iterations: usize,
    /// Most iterations in all.
    pub max_iterations: usize,
    /// ε₁, the weight of the fairness energy at the start.
    pub epsilon1: f64,
    /// ε₂, the weight of the distance to the previous iterate.
    pub epsilon2: f64,
    /// Stop when the largest developability sine is at most this.
    pub stop_sine: f64,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            iterations: 5,
            max_iterations: 50,
            epsilon1: 0.1,
            epsilon2: 0.01,
            stop_sine: 1e-10,
        }
    }
}

/// A crease's stated fold (spec `folds`): which way it folds and, optionally, by how much.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FoldGoal {
    /// A valley seen from the front (the side the sampled mesh's faces face, where the
    /// pattern is printed), else a mountain.
    pub valley: bool,
    /// The mean fold angle along the crease (radians, in (0, π)); `None`: at least
    /// [`FOLD_MIN`], the direction alone.
    pub angle: Option<f64>,
}

/// A spline developable's unknowns before and after the solve, in millimetres.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub basis: BSpline,
    /// Control points of each curve (all [`BSpline::count`] long).
    pub curves: Vec<Vec<DVec3>>,
    /// A cone's apex (then `curves` has one curve).
    pub apex: Option<DVec3>,
    /// Fixed control points: (curve, index); curve `curves.len()` is the apex.
    pub fixed: Vec<(usize, usize)>,
    /// The condition on each interior curve (curve k + 1 for entry k); shorter means `Free`.
    pub creases: Vec<Crease>,
    /// The stated fold of each interior curve (entry k for curve k + 1); shorter means none.
    pub folds: Vec<Option<FoldGoal>>,
    /// A shape to approximate (eq. 9–11); `None` for none.
    pub target: Option<Target>,
    /// Handles: a point on the surface as given (`at`; with an outline, the point of the flat
    /// sheet there) dragged towards a 3D position (`to`), as (at, to), in millimetres; a
    /// coordinate of `to` that is NaN is left free.
    pub handles: Vec<(DVec3, DVec3)>,
    /// A flat domain (mm, in the plane z = 0 of the curves as given, which lie in it) that the
    /// surface stays isometric to (eq. 12); `None` for none.
    pub outline: Option<Vec<glam::DVec2>>,
}

impl Model {
    /// The condition on curve `c` (0-based): `Free` on the first and last.
    pub fn crease(&self, c: usize) -> Crease {
        match c.checked_sub(1) {
            Some(k) if c + 1 < self.curves.len() => {
                self.creases.get(k).copied().unwrap_or_default()
            }
            _ => Crease::Free,
        }
    }
}

/// What the solve did.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    pub iterations: usize,
    /// Largest intrinsic developability sine at the samples, after each iteration (the first
    /// entry before any).
    pub sines: Vec<f64>,
    /// Largest distance a control point moved (mm).
    pub moved: f64,
    /// Largest distance of a handle from its goal at the end (mm); 0 without handles.
    pub handle_distance: f64,
    /// Largest relative length error of the development (eq. 12); 0 without an outline.
    pub outline_isometry: f64,
    /// The iterations the work budget allowed, when fewer than `max_iterations`.
    pub budget: Option<usize>,
}

/// A solve that failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    #[error("the model has no extent (all control points coincide)")]
    Degenerate,
    #[error("at u = {u:.4} the ruling and the tangent of curve {curve} are parallel: no tangent plane (move the control points apart)")]
    NoPlane { u: f64, curve: usize },
    #[error("iteration {iteration}: the solve gave a number that is not finite")]
    NonFinite { iteration: usize },
    #[error("the sparse solve failed: {0}")]
    Sparse(String),
}

/// The flat point list, the unknowns' layout and the samples.
struct Layout {
    /// Every point: the curves' control points, then the apex.
    points: Vec<DVec3>,
    /// Variable offset (3 coordinates) of each point, `None` when fixed.
    var: Vec<Option<usize>>,
    /// Per sample: e = B − A, tangent of A, tangent of B (None for a cone), normal's offset.
    samples: Vec<Sample>,
    /// Crease conditions, one per sample parameter of each constrained interior curve.
    creases: Vec<CreaseSample>,
    /// Second-difference expressions of the control polygons.
    fair: Vec<Expr>,
    /// Their values in the input (the fairness target s).
    fair_s: Vec<DVec3>,
    /// Target points and unit normals (eq. 9–11), in the scaled frame.
    target: Vec<(DVec3, DVec3)>,
    /// The strips: (curve a, curve b or `None` for the apex).
    strips: Vec<(usize, Option<usize>)>,
    /// Handles: where on the surface (found once, on the start) and the goal, scaled.
    handles: Vec<(Foot, DVec3)>,
    /// Each handle's point at the start and the goal of the current iteration (moved from
    /// the start to the goal over [`HANDLE_RAMP`] iterations).
    handle_start: Vec<DVec3>,
    handle_now: Vec<DVec3>,
    /// Each handle's point of the flat sheet (scaled; used with an outline).
    handle_flat: Vec<glam::DVec2>,
    /// The development kept isometric to the outline (eq. 12).
    dev: Option<Dev>,
    /// The stated folds.
    folds: Vec<FoldGoalRows>,
    /// Number of unknowns.
    n: usize,
}

/// The work budget of one solve: the sum over its iterations of the unknowns plus ten per
/// footpoint search (a 270-control-point chain gets 2,800 iterations, a 4,000-point target on
/// one strip 250).
const WORK_BUDGET: usize = 10_000_000;

/// A target fit or a drag by handles has converged when its goal measure (RMS distance plus
/// the largest handle distance, relative to the model's diameter) changes by less than this
/// in one iteration.
const TARGET_CONVERGED: f64 = 1e-7;

struct Sample {
    u: f64,
    curve: usize,
    e: Expr,
    ta: Expr,
    tb: Option<Expr>,
    normal: usize,
}

/// Intrinsic sine of the angle between the tangent planes at the two ends of a ruling.
pub fn plane_sine(e: DVec3, ta: DVec3, tb: Option<DVec3>) -> f64 {
    let Some(tb) = tb else { return 0.0 };
    let na = e.cross(ta).length();
    let nb = e.cross(tb).length();
    let still = STILL * e.length();
    if ta.length() <= still || tb.length() <= still || nb <= 1e-300 || na <= 1e-300 {
        // a′ or b′ = 0 (a cone point: the curve stands still) or along the ruling: no
        // condition there.
        return 0.0;
    }
    (e.dot(ta.cross(tb)).abs() * e.length() / (na * nb)).min(1.0)
}

/// A tangent (or ruling) at most this long in the diameter-1 frame is zero: the curve stands
/// still there (a run of equal control points, a cone's apex on that curve), and the
/// conditions on it are left out; relative to the other tangent in [`plane_sine`].
pub const STILL: f64 = 1e-9;

/// The smallest ε₂ the schedule decays to once the fairness is off.
const EPS2_FLOOR: f64 = 1e-4;

fn layout(m: &Model, points: Vec<DVec3>, target: Vec<(DVec3, DVec3)>) -> Layout {
    let count = m.basis.count();
    let nc = m.curves.len();
    let mut var: Vec<Option<usize>> = vec![None; points.len()];
    let mut n = 0;
    for p in 0..points.len() {
        let key = (p / count.max(1), p % count.max(1));
        let key = if p >= nc * count { (nc, 0) } else { key };
        if m.fixed.contains(&key) {
            continue;
        }
        // A run of equal control points is one point: where a curve stands still (a cone's
        // apex on the edge, a pause) it stays still.
        let (c, i) = key;
        if c < nc && i > 0 && m.curves[c][i] == m.curves[c][i - 1] && var[p - 1].is_some() {
            var[p] = var[p - 1];
            continue;
        }
        var[p] = Some(n);
        n += 3;
    }
    let deg = m.basis.degree();
    let per = 3 * deg - 2;
    let mut samples = Vec::new();
    let strips: Vec<(usize, Option<usize>)> = match m.apex {
        Some(_) => vec![(0, None)],
        None => (0..nc - 1).map(|c| (c, Some(c + 1))).collect(),
    };
    for &(a, b) in &strips {
        for s in 0..m.basis.spans() {
            for i in 0..per {
                let u = s as f64 + (i as f64 + 0.5) / per as f64;
                let r = m.basis.rows(u);
                let on = |c: usize, row: &[(usize, f64)]| -> Expr {
                    row.iter().map(|&(j, w)| (c * count + j, w)).collect()
                };
                let (pb, tb) = match b {
                    Some(b) => (on(b, &r.point), Some(on(b, &r.d1))),
                    None => (vec![(nc * count, 1.0)], None),
                };
                let mut e = pb;
                e.extend(on(a, &r.point).into_iter().map(|(j, w)| (j, -w)));
                samples.push(Sample {
                    u,
                    curve: a,
                    e,
                    ta: on(a, &r.d1),
                    tb,
                    normal: n,
                });
                n += 3;
            }
        }
    }
    let per_strip = m.basis.spans() * per;
    let mut creases = Vec::new();
    if m.apex.is_none() {
        for c in 1..nc.saturating_sub(1) {
            let kind = m.crease(c);
            if kind == Crease::Free {
                continue;
            }
            for j in 0..per_strip {
                let left = (c - 1) * per_strip + j;
                let r = m.basis.rows(samples[left].u);
                creases.push(CreaseSample {
                    kind,
                    left,
                    right: c * per_strip + j,
                    d2: r.d2.iter().map(|&(i, w)| (c * count + i, w)).collect(),
                });
            }
        }
    }
    let mut fair = Vec::new();
    for c in 0..nc {
        let range: Vec<usize> = if m.basis.closed() {
            (0..count).collect()
        } else {
            (1..count - 1).collect()
        };
        for j in range {
            let prev = c * count + (j + count - 1) % count;
            let next = c * count + (j + 1) % count;
            fair.push(vec![(prev, 1.0), (c * count + j, -2.0), (next, 1.0)]);
        }
    }
    let fair_s = fair.iter().map(|f| eval(f, &points)).collect();
    Layout {
        points,
        var,
        samples,
        creases,
        fair,
        fair_s,
        target,
        strips,
        handles: Vec::new(),
        handle_start: Vec::new(),
        handle_now: Vec::new(),
        handle_flat: Vec::new(),
        dev: None,
        folds: Vec::new(),
        n,
    }
}

/// The stated folds over the layout's crease samples, their goals starting at the mean
/// angle of the start `x`.
fn fold_goals(m: &Model, l: &Layout, x: &[f64]) -> Vec<FoldGoalRows> {
    let per_strip = l.samples.len() / l.strips.len().max(1);
    let mut out = Vec::new();
    for (k, f) in m.folds.iter().enumerate() {
        let Some(f) = f else { continue };
        // Curve k + 1's samples: those whose left strip is strip k.
        let creases: Vec<usize> = (0..l.creases.len())
            .filter(|&i| l.creases[i].left / per_strip.max(1) == k)
            .collect();
        if creases.is_empty() {
            continue;
        }
        let mut g = FoldGoalRows {
            creases,
            sigma: if f.valley { 1.0 } else { -1.0 },
            angle: f.angle,
            start: 0.0,
            now: 0.0,
        };
        g.start = fold_mean(l, x, &g).0;
        g.now = g.start;
        out.push(g);
    }
    out
}

/// Initial normals: the tangent planes at both ends of each ruling averaged.
fn initial_normals(l: &Layout, x: &mut [f64]) -> Result<(), SolveError> {
    // Where both curves stand still (a pause of the whole strip: the quads are points or
    // rulings) there is no plane; such a sample takes its strip's nearest plane.
    let mut paused = Vec::new();
    for (i, s) in l.samples.iter().enumerate() {
        let e = eval(&s.e, &l.points);
        // A tangent that stands still (a cone's apex) has no plane; e × b′ then orients n.
        let moving = |t: DVec3| if t.length() <= STILL { DVec3::ZERO } else { t };
        let ta = moving(eval(&s.ta, &l.points));
        let tb = s.tb.as_ref().map(|t| moving(eval(t, &l.points)));
        let mut n = e.cross(ta).normalize_or_zero();
        if let Some(tb) = tb {
            let nb = e.cross(tb).normalize_or_zero();
            n += if nb.dot(n) < 0.0 { -nb } else { nb };
        }
        let n = n.normalize_or_zero();
        if n == DVec3::ZERO && ta == DVec3::ZERO && tb.unwrap_or_default() == DVec3::ZERO {
            paused.push(i);
            continue;
        }
        if n == DVec3::ZERO || !n.is_finite() {
            return Err(SolveError::NoPlane {
                u: s.u,
                curve: s.curve + 1,
            });
        }
        x[s.normal..s.normal + 3].copy_from_slice(&n.to_array());
    }
    for &i in &paused {
        let s = &l.samples[i];
        let same = |j: &usize| l.samples[*j].curve == s.curve && !paused.contains(j);
        let near = (0..l.samples.len())
            .filter(same)
            .min_by_key(|&j| j.abs_diff(i))
            .ok_or(SolveError::NoPlane {
                u: s.u,
                curve: s.curve + 1,
            })?;
        let e = eval(&s.e, &l.points).normalize_or_zero();
        let m = normal_of(x, &l.samples[near]);
        let n = (m - e * m.dot(e)).normalize_or_zero();
        if n == DVec3::ZERO {
            return Err(SolveError::NoPlane {
                u: s.u,
                curve: s.curve + 1,
            });
        }
        x[s.normal..s.normal + 3].copy_from_slice(&n.to_array());
    }
    Ok(())
}

fn normal_of(x: &[f64], s: &Sample) -> DVec3 {
    DVec3::new(x[s.normal], x[s.normal + 1], x[s.normal + 2])
}

/// Write the unknowns' point coordinates back into `points`.
fn unpack(l: &mut Layout, x: &[f64]) {
    for (p, v) in l.var.iter().enumerate() {
        if let Some(o) = *v {
            l.points[p] = DVec3::new(x[o], x[o + 1], x[o + 2]);
        }
    }
}

/// The constraints' squared residual sum (sines and norm defects) and the largest intrinsic
/// developability sine.
fn residual(l: &Layout, x: &[f64]) -> (f64, f64) {
    let mut sum = 0.0;
    let mut worst: f64 = 0.0;
    for s in &l.samples {
        let n = normal_of(x, s);
        let e = eval(&s.e, &l.points);
        let ta = eval(&s.ta, &l.points);
        let tb = s.tb.as_ref().map(|t| eval(t, &l.points));
        for d in [Some(e), Some(ta), tb].into_iter().flatten() {
            let len = d.length();
            if len > STILL {
                sum += (n.dot(d) / len).powi(2);
            }
        }
        sum += (n.length_squared() - 1.0).powi(2);
        worst = worst.max(plane_sine(e, ta, tb));
    }
    for c in &l.creases {
        let (r, sine) = crease_residual(l, x, c);
        sum += r;
        worst = worst.max(sine);
    }
    (sum, worst)
}

/// The point part of a bilinear ⟨n, Σ w·P⟩ / `scale` linearised at the iterate (n held at
/// its value there): the entries w·n/scale of the free points, and their value at the iterate
/// added to `rhs`, as first-order linearisation asks.
fn point_part(
    l: &Layout,
    expr: &Expr,
    n: DVec3,
    scale: f64,
    entries: &mut Vec<(usize, f64)>,
    rhs: &mut f64,
) {
    for &(p, w) in expr {
        if let Some(o) = l.var[p] {
            for c in 0..3 {
                entries.push((o + c, w * n[c] / scale));
            }
            *rhs += w * n.dot(l.points[p]) / scale;
        }
    }
}

/// The rows of one bilinear constraint ⟨n, Σ w·P⟩ / |d| at the current iterate.
fn bilinear(l: &Layout, x: &[f64], s: &Sample, expr: &Expr, rows: &mut Vec<Row>) {
    let n = normal_of(x, s);
    let d = eval(expr, &l.points);
    if d.length() <= STILL {
        return; // a curve standing still (a cone's apex): no tangent, no condition
    }
    let len = d.length();
    let mut entries = Vec::with_capacity(3 + 3 * expr.len());
    let mut rhs = 0.0;
    for c in 0..3 {
        entries.push((s.normal + c, d[c] / len));
    }
    point_part(l, expr, n, len, &mut entries, &mut rhs);
    rows.push(Row {
        entries,
        rhs,
        w: 1.0,
    });
}

/// Every linearised row at `x`: the constraints (H, r) and the fairness (K, s) weighted ε₁.
fn rows(l: &Layout, x: &[f64], eps1: f64, basis: &BSpline, feet: &[Foot]) -> Vec<Row> {
    let mut rows = Vec::new();
    target_rows(l, basis, feet, &mut rows);
    if let Some(d) = &l.dev {
        d.rows(&l.points, &l.var, x, eps1, &mut rows);
    }
    handle_rows(l, basis, &mut rows);
    fold_rows(l, x, &mut rows);
    for s in &l.samples {
        bilinear(l, x, s, &s.e, &mut rows);
        bilinear(l, x, s, &s.ta, &mut rows);
        if let Some(tb) = &s.tb {
            bilinear(l, x, s, tb, &mut rows);
        }
        let n = normal_of(x, s);
        rows.push(Row {
            entries: (0..3).map(|c| (s.normal + c, 2.0 * n[c])).collect(),
            rhs: n.length_squared() + 1.0,
            w: 1.0,
        });
    }
    for c in &l.creases {
        crease_rows(l, x, c, &mut rows);
    }
    for (f, target) in l.fair.iter().zip(&l.fair_s) {
        for c in 0..3 {
            let mut entries = Vec::new();
            let mut rhs = target[c];
            for &(p, w) in f {
                match l.var[p] {
                    Some(o) => entries.push((o + c, w)),
                    None => rhs -= w * l.points[p][c],
                }
            }
            rows.push(Row {
                entries,
                rhs,
                w: eps1,
            });
        }
    }
    rows
}

/// The model's points in one list (curves, then the apex).
fn flat_points(m: &Model) -> Vec<DVec3> {
    let mut p: Vec<DVec3> = m.curves.iter().flatten().copied().collect();
    p.extend(m.apex);
    p
}

/// One prepared problem, in the scaled frame: for the solver and the benchmark.
pub struct Problem {
    l: Layout,
    basis: BSpline,
    /// The target's footpoints (empty without a target), and whether they are those of the
    /// current iterate.
    feet: Vec<Foot>,
    feet_fresh: bool,
    x: Vec<f64>,
    centre: DVec3,
    diameter: f64,
    pattern: Option<Pattern>,
    merit: f64,
    sine: f64,
}

impl Problem {
    /// Scale the model to diameter 1 and set up the unknowns and the initial normals.
    pub fn new(m: &Model) -> Result<Problem, SolveError> {
        let pts = flat_points(m);
        let target: &[DVec3] = m.target.as_ref().map_or(&[], |t| &t.points);
        // A handle's free coordinates (NaN) count where the handle starts.
        let goals: Vec<DVec3> = m
            .handles
            .iter()
            .map(|&(at, to)| DVec3::select(to.is_finite_mask(), to, at))
            .collect();
        let (lo, hi) = crate::geom::mesh::bounds3(pts.iter().chain(&goals).chain(target))
            .unwrap_or((DVec3::ZERO, DVec3::ZERO));
        let diameter = (hi - lo).length();
        if !(diameter > 0.0 && diameter.is_finite()) {
            return Err(SolveError::Degenerate);
        }
        let centre = 0.5 * (lo + hi);
        let scaled = pts.iter().map(|p| (*p - centre) / diameter).collect();
        let target = m.target.as_ref().map_or(Vec::new(), |t| {
            t.points
                .iter()
                .zip(&t.normals)
                .map(|(p, n)| ((*p - centre) / diameter, *n))
                .collect()
        });
        let mut l = layout(m, scaled, target);
        let basis = m.basis.clone();
        let grids = grids(&l, &basis);
        l.handles = m
            .handles
            .iter()
            .map(|&(at, to)| {
                let q = (at - centre) / diameter;
                (
                    nearest_foot(&l, &basis, &grids, q),
                    (to - centre) / diameter,
                )
            })
            .collect();
        l.handle_start = l
            .handles
            .iter()
            .map(|(f, _)| eval(&foot_exprs(&l, &basis, f).0, &l.points))
            .collect();
        l.handle_now = l.handle_start.clone();
        l.handle_flat = m
            .handles
            .iter()
            .map(|(at, _)| ((*at - centre) / diameter).truncate())
            .collect();
        if let Some(outline) = &m.outline {
            let flat = outline
                .iter()
                .map(|p| (*p - centre.truncate()) / diameter)
                .collect();
            let constrained: Vec<bool> = (0..m.curves.len())
                .map(|c| m.crease(c) != Crease::Free)
                .collect();
            let d = Dev::new(&basis, &l.points, m.curves.len(), &constrained, flat, l.n);
            l.n += d.unknowns();
            l.dev = Some(d);
        }
        let mut x = vec![0.0; l.n];
        if let Some(d) = &l.dev {
            d.init(&mut x);
        }
        for (p, v) in l.var.iter().enumerate() {
            if let Some(o) = *v {
                x[o..o + 3].copy_from_slice(&l.points[p].to_array());
            }
        }
        initial_normals(&l, &mut x)?;
        l.folds = fold_goals(m, &l, &x);
        let (merit, sine) = residual(&l, &x);
        let feet = feet(&l, &basis);
        Ok(Problem {
            l,
            basis,
            feet,
            feet_fresh: true,
            x,
            centre,
            diameter,
            pattern: None,
            merit,
            sine,
        })
    }

    /// The largest intrinsic developability sine now.
    pub fn sine(&self) -> f64 {
        self.sine
    }

    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        self.l.n
    }

    /// Whether a target is approximated.
    pub fn has_target(&self) -> bool {
        !self.l.target.is_empty()
    }

    /// Whether there are goals besides the constraints (a target, handles, an outline, stated
    /// folds): the solve then goes on until they stop improving.
    pub fn has_goals(&self) -> bool {
        self.has_target()
            || !self.l.handles.is_empty()
            || self.l.dev.is_some()
            || !self.l.folds.is_empty()
    }

    /// The development's squared residual and largest relative length error (eq. 12); zero
    /// without an outline.
    fn dev_merit(&self) -> (f64, f64) {
        self.l
            .dev
            .as_ref()
            .map_or((0.0, 0.0), |d| d.merit(&self.l.points, &self.x))
    }

    /// The weighted squared residual of the goals: eq. 9–11 at the footpoints, the handles,
    /// the development.
    fn goals_merit(&self) -> f64 {
        target_merit(&self.l, &self.basis, &self.feet).0
            + handle_merit(&self.l, &self.basis, true).0
            + self.dev_merit().0
            + fold_merit(&self.l, &self.x, true).0
    }

    /// The largest relative length error of the development (eq. 12).
    pub fn outline_isometry_error(&self) -> f64 {
        self.dev_merit().1
    }

    /// The goals' measure of progress: RMS target distance plus the largest handle distance
    /// (scaled).
    fn goal(&self) -> f64 {
        target_merit(&self.l, &self.basis, &self.feet).1.sqrt()
            + handle_merit(&self.l, &self.basis, false).1
            + self.dev_merit().1
            + fold_merit(&self.l, &self.x, false).1
    }

    /// The largest distance (mm) of a handle from its goal.
    pub fn handle_distance_mm(&self) -> f64 {
        handle_merit(&self.l, &self.basis, false).1 * self.diameter
    }

    /// The root mean square distance (mm) of the target points from their footpoints.
    pub fn target_rms_mm(&self) -> f64 {
        target_merit(&self.l, &self.basis, &self.feet).1.sqrt() * self.diameter
    }

    /// One round of guided projection with fairness weight `eps1`.
    pub fn iterate(&mut self, eps1: f64, eps2: f64, iteration: usize) -> Result<(), SolveError> {
        let f = (iteration as f64 / HANDLE_RAMP as f64).min(1.0);
        for (k, (_, goal)) in self.l.handles.iter().enumerate() {
            let start = self.l.handle_start[k];
            self.l.handle_now[k] = start + (*goal - start) * f;
        }
        // With an outline a handle holds a point of the flat sheet: where that point is on
        // the surface is found again through the development every iteration.
        if let Some(d) = &self.l.dev {
            for (k, (foot, _)) in self.l.handles.iter_mut().enumerate() {
                if let Some((strip, u, v)) = d.locate(&self.x, self.l.handle_flat[k]) {
                    *foot = Foot {
                        strip,
                        u,
                        v,
                        ..*foot
                    };
                }
            }
        }
        for g in &mut self.l.folds {
            if let Some(a) = g.angle {
                g.now = g.start + (a - g.start) * f;
            }
        }
        if self.has_goals() {
            // Footpoints found again every iteration (§4.2); the merit counts the goals too.
            if !self.feet_fresh {
                self.feet = feet(&self.l, &self.basis);
            }
            self.feet_fresh = false;
            self.merit = residual(&self.l, &self.x).0 + self.goals_merit();
        }
        let rows = rows(&self.l, &self.x, eps1, &self.basis, &self.feet);
        let (idx, val, b) = normal_equations(self.l.n, &rows, &self.x, eps2);
        let full =
            sparse_solve(self.l.n, idx, &val, &b, &mut self.pattern).map_err(SolveError::Sparse)?;
        if full.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite { iteration });
        }
        let old_x = self.x.clone();
        let old_points = self.l.points.clone();
        let mut step = 1.0;
        for _ in 0..=8 {
            self.x = old_x
                .iter()
                .zip(&full)
                .map(|(a, b)| a + step * (b - a))
                .collect();
            self.l.points.clone_from(&old_points);
            unpack(&mut self.l, &self.x);
            let (merit, sine) = residual(&self.l, &self.x);
            let merit = merit + self.goals_merit();
            if merit <= self.merit || step < 0.01 {
                self.merit = merit;
                self.sine = sine;
                break;
            }
            step *= 0.5;
        }
        Ok(())
    }

    /// The points back in millimetres (curves, then the apex).
    fn points_mm(&self) -> Vec<DVec3> {
        self.l
            .points
            .iter()
            .map(|p| *p * self.diameter + self.centre)
            .collect()
    }
}

/// Solve `m` in place by guided projection; returns what the solve did.
pub fn solve(m: &mut Model, o: &SolveOptions) -> Result<Report, SolveError> {
    let before = flat_points(m);
    let mut pr = Problem::new(m)?;
    let mut sines = vec![pr.sine()];
    let mut it = 0;
    // With a target, the solve goes on until the distance stops improving too.
    let mut converged = !pr.has_goals();
    let mut last_goal = f64::INFINITY;
    // A deterministic work budget bounds the time of any design: unknowns plus the footpoint
    // searches (target points × strips) per iteration.
    let per = pr.l.n + 10 * pr.l.target.len() * pr.l.strips.len();
    let budget = (WORK_BUDGET / per.max(1)).max(1);
    let max_iterations = o.max_iterations.min(budget);
    while it < max_iterations && (pr.sine() > o.stop_sine || !converged) {
        let fair_rounds = if m.handles.is_empty() && m.folds.iter().all(Option::is_none) {
            o.iterations
        } else {
            o.iterations.max(HANDLE_RAMP)
        };
        let (eps1, eps2) = if it < fair_rounds {
            (o.epsilon1 * 0.9f64.powi(it as i32), o.epsilon2)
        } else {
            let k = (it + 1 - fair_rounds) as i32;
            (
                0.0,
                (o.epsilon2 * 0.1f64.powi(k)).max(EPS2_FLOOR.min(o.epsilon2)),
            )
        };
        pr.iterate(eps1, eps2, it + 1)?;
        it += 1;
        sines.push(pr.sine());
        if pr.has_goals() {
            if pr.has_target() {
                pr.feet = feet(&pr.l, &pr.basis);
                pr.feet_fresh = true;
            }
            let goal = pr.goal();
            converged = (last_goal - goal).abs() <= TARGET_CONVERGED;
            last_goal = goal;
        }
    }
    let after = pr.points_mm();
    let moved = before
        .iter()
        .zip(&after)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    let mut after = after;
    for (p, v) in pr.l.var.iter().enumerate() {
        if v.is_none() {
            after[p] = before[p]; // fixed points exactly as given, not through the scaling
        }
    }
    let count = m.basis.count();
    for (c, curve) in m.curves.iter_mut().enumerate() {
        curve.copy_from_slice(&after[c * count..(c + 1) * count]);
    }
    if let Some(a) = &mut m.apex {
        *a = after[m.curves.len() * count];
    }
    Ok(Report {
        iterations: it,
        sines,
        moved,
        handle_distance: pr.handle_distance_mm(),
        outline_isometry: pr.outline_isometry_error(),
        budget: (budget < o.max_iterations).then_some(budget),
    })
}
