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
//!   two rims collapsed to a double cone in our first trials); measured against the input it
//!   keeps the designed shape without shrinking it. Schedule
//!   ε₁ = `epsilon1`·0.9ⁱ for the first `iterations` rounds and 0 after (Fig. 17's schedule);
//!   ε₂ = `epsilon2` throughout.
//! - The model is moved to its bounding box centre and scaled to diameter 1 inside.
//! - A step whose squared constraint residual is larger than the current one is halved, up to
//!   8 times (then taken as it is).
//! - The stop test is the largest *intrinsic* developability sine at the samples: the sine of
//!   the angle between the tangent planes at `a(u)` and `b(u)`,
//!   |det(e, a′, b′)|·|e| / (|e × a′|·|e × b′|) with e = b − a, which does not depend on the
//!   auxiliary normals. It is tested before the first iteration too, so an exact developable is
//!   returned untouched.

use crate::geom::bspline::{apply, BSpline};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use glam::DVec3;

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

/// A point expression Σ w·P over the model's points (index into the flat point list).
type Expr = Vec<(usize, f64)>;

/// One linearised equation: entries · x ≈ rhs, with weight w.
struct Row {
    entries: Vec<(usize, f64)>,
    rhs: f64,
    w: f64,
}

/// The flat point list, the unknowns' layout and the samples.
struct Layout {
    /// Every point: the curves' control points, then the apex.
    points: Vec<DVec3>,
    /// Variable offset (3 coordinates) of each point, `None` when fixed.
    var: Vec<Option<usize>>,
    /// Per sample: e = B − A, tangent of A, tangent of B (None for a cone), normal's offset.
    samples: Vec<Sample>,
    /// Second-difference expressions of the control polygons.
    fair: Vec<Expr>,
    /// Their values in the input (the fairness target s).
    fair_s: Vec<DVec3>,
    /// Number of unknowns.
    n: usize,
}

struct Sample {
    u: f64,
    curve: usize,
    e: Expr,
    ta: Expr,
    tb: Option<Expr>,
    normal: usize,
}

fn eval(e: &Expr, p: &[DVec3]) -> DVec3 {
    apply(e, p)
}

/// Intrinsic sine of the angle between the tangent planes at the two ends of a ruling.
pub fn plane_sine(e: DVec3, ta: DVec3, tb: Option<DVec3>) -> f64 {
    let Some(tb) = tb else { return 0.0 };
    let na = e.cross(ta).length();
    let nb = e.cross(tb).length();
    if nb <= 1e-300 || na <= 1e-300 {
        // b′ = 0 (a cone point) or along the ruling: no condition there.
        return 0.0;
    }
    (e.dot(ta.cross(tb)).abs() * e.length() / (na * nb)).min(1.0)
}

fn layout(m: &Model, points: Vec<DVec3>) -> Layout {
    let count = m.basis.count();
    let nc = m.curves.len();
    let mut var = vec![None; points.len()];
    let mut n = 0;
    for (p, v) in var.iter_mut().enumerate() {
        let key = (p / count.max(1), p % count.max(1));
        let key = if p >= nc * count { (nc, 0) } else { key };
        if !m.fixed.contains(&key) {
            *v = Some(n);
            n += 3;
        }
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
        fair,
        fair_s,
        n,
    }
}

/// Initial normals: the tangent planes at both ends of each ruling averaged.
fn initial_normals(l: &Layout, x: &mut [f64]) -> Result<(), SolveError> {
    for s in &l.samples {
        let e = eval(&s.e, &l.points);
        let na = e.cross(eval(&s.ta, &l.points));
        let mut n = na.normalize_or_zero();
        if let Some(tb) = &s.tb {
            let nb = e.cross(eval(tb, &l.points)).normalize_or_zero();
            n += if nb.dot(n) < 0.0 { -nb } else { nb };
        }
        let n = n.normalize_or_zero();
        if n == DVec3::ZERO || !n.is_finite() {
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
            if len > 1e-300 {
                sum += (n.dot(d) / len).powi(2);
            }
        }
        sum += (n.length_squared() - 1.0).powi(2);
        worst = worst.max(plane_sine(e, ta, tb));
    }
    (sum, worst)
}

/// The rows of one bilinear constraint ⟨n, Σ w·P⟩ / |d| at the current iterate.
fn bilinear(l: &Layout, x: &[f64], s: &Sample, expr: &Expr, rows: &mut Vec<Row>) {
    let n = normal_of(x, s);
    let d = eval(expr, &l.points);
    let len = d.length().max(1e-12);
    let mut entries = Vec::with_capacity(3 + 3 * expr.len());
    let mut rhs = 0.0;
    for c in 0..3 {
        entries.push((s.normal + c, d[c] / len));
    }
    for &(p, w) in expr {
        if let Some(o) = l.var[p] {
            for c in 0..3 {
                entries.push((o + c, w * n[c] / len));
            }
            rhs += w * n.dot(l.points[p]) / len;
        }
    }
    rows.push(Row {
        entries,
        rhs,
        w: 1.0,
    });
}

/// Every linearised row at `x`: the constraints (H, r) and the fairness (K, s) weighted ε₁.
fn rows(l: &Layout, x: &[f64], eps1: f64) -> Vec<Row> {
    let mut rows = Vec::new();
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

/// The normal equations' lower triangle and right-hand side.
fn normal_equations(
    n: usize,
    rows: &[Row],
    x: &[f64],
    eps2: f64,
) -> (Vec<Triplet<usize, usize, f64>>, Vec<f64>) {
    let mut t = Vec::new();
    let mut b: Vec<f64> = x.iter().map(|v| eps2 * eps2 * v).collect();
    for i in 0..n {
        t.push(Triplet::new(i, i, eps2 * eps2));
    }
    for r in rows {
        let w2 = r.w * r.w;
        for &(i, vi) in &r.entries {
            b[i] += w2 * vi * r.rhs;
            for &(j, vj) in &r.entries {
                if i >= j {
                    t.push(Triplet::new(i, j, w2 * vi * vj));
                }
            }
        }
    }
    (t, b)
}

fn sparse_solve(
    n: usize,
    t: &[Triplet<usize, usize, f64>],
    b: &[f64],
    symbolic: &mut Option<SymbolicLlt<usize>>,
) -> Result<Vec<f64>, SolveError> {
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, t)
        .map_err(|e| SolveError::Sparse(format!("{e:?}")))?;
    let sym = match symbolic {
        Some(s) => s.clone(),
        None => {
            let s = SymbolicLlt::try_new(a.symbolic(), Side::Lower)
                .map_err(|e| SolveError::Sparse(format!("{e:?}")))?;
            *symbolic = Some(s.clone());
            s
        }
    };
    let llt = Llt::try_new_with_symbolic(sym, a.as_ref(), Side::Lower)
        .map_err(|e| SolveError::Sparse(format!("not positive definite ({e:?})")))?;
    let x = llt.solve(&Mat::<f64>::from_fn(n, 1, |i, _| b[i]));
    Ok((0..n).map(|i| x[(i, 0)]).collect())
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
    x: Vec<f64>,
    centre: DVec3,
    diameter: f64,
    symbolic: Option<SymbolicLlt<usize>>,
    merit: f64,
    sine: f64,
}

impl Problem {
    /// Scale the model to diameter 1 and set up the unknowns and the initial normals.
    pub fn new(m: &Model) -> Result<Problem, SolveError> {
        let pts = flat_points(m);
        let lo = pts
            .iter()
            .fold(DVec3::splat(f64::INFINITY), |a, p| a.min(*p));
        let hi = pts
            .iter()
            .fold(DVec3::splat(f64::NEG_INFINITY), |a, p| a.max(*p));
        let diameter = (hi - lo).length();
        if !(diameter > 0.0 && diameter.is_finite()) {
            return Err(SolveError::Degenerate);
        }
        let centre = 0.5 * (lo + hi);
        let scaled = pts.iter().map(|p| (*p - centre) / diameter).collect();
        let l = layout(m, scaled);
        let mut x = vec![0.0; l.n];
        for (p, v) in l.var.iter().enumerate() {
            if let Some(o) = *v {
                x[o..o + 3].copy_from_slice(&l.points[p].to_array());
            }
        }
        initial_normals(&l, &mut x)?;
        let (merit, sine) = residual(&l, &x);
        Ok(Problem {
            l,
            x,
            centre,
            diameter,
            symbolic: None,
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

    /// One round of guided projection with fairness weight `eps1`.
    pub fn iterate(&mut self, eps1: f64, eps2: f64, iteration: usize) -> Result<(), SolveError> {
        let rows = rows(&self.l, &self.x, eps1);
        let (t, b) = normal_equations(self.l.n, &rows, &self.x, eps2);
        let full = sparse_solve(self.l.n, &t, &b, &mut self.symbolic)?;
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
    while it < o.max_iterations && pr.sine() > o.stop_sine {
        let eps1 = if it < o.iterations {
            o.epsilon1 * 0.9f64.powi(it as i32)
        } else {
            0.0
        };
        pr.iterate(eps1, o.epsilon2, it + 1)?;
        it += 1;
        sines.push(pr.sine());
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
    })
}
