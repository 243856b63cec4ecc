//! Bent sheets (issue 5): a flat sheet bent so that a line or curve drawn on it follows a 3D
//! control curve — the geodesic-controlled developables of Bo & Wang 2007 (seed 004), with
//! their extension to non-geodesic control curves (§5).
//!
//! The sheet is given flat (an outline, holes allowed) with one curve on it per curved piece —
//! a straight line, or a planar curve ([`FlatPath`]: a circular arc or a Bézier / B-spline) —
//! and for each a 3D control curve (Bézier or B-spline control points, or two handles: end
//! points with surface normals). For a line the surface is the rectifying developable of the
//! control curve, `X(s, t) = p(s) + t·r(s)` with `r` along the Darboux vector `τT + κB`
//! (eq. 1, §3.1), mapped onto the flat outline by the isometry of §3.3 (steps 1–4: arc length
//! along the line, ruling angle kept, rulings cut by the outline, distances measured along the
//! ruling).
//!
//! For a curve on the sheet (§5, "non-geodesic control curves") the flat curve's signed
//! curvature `c(s)` is the geodesic curvature the control curve keeps on the bent sheet: with
//! the surface normal `n ⟂ T` and `b = n × T`, `p'' = κN = c·b + κ_n·n`, so
//! `n = σ(κ_n/κ) N + (c/κ) B` with `κ_n = √(κ² − c²)` (writing `n = cos θ N + sin θ B`,
//! `sin θ = c/κ`). The developable is the envelope of the tangent planes along `p`: its rulings
//! follow the tangent-plane part of the Darboux vector of the frame `(T, b, n)`,
//! `τ_g T − κ_n b`, with the geodesic torsion `τ_g = τ + θ'` (for `c = 0` this is eq. 1). The
//! part `c·n` of the Darboux vector turns the curve inside the sheet, which the flat curve does
//! by itself. The sign of `c` (the flat curve turning left, seen from the printed side, is
//! `c > 0`) fixes which side of the control curve the sheet's printed side faces.
//!
//! # How it is computed
//!
//! The smooth surface is replaced by a *folded* one that is exactly developable: the flat sheet
//! is folded along straight ruling lines, `s_k = k·h` apart along the line (`h = L / n`), each
//! fold turning the sheet beyond it about the ruling by `|ω(s_k)|·h`, where `ω = τ_g T − κ_n b`
//! is the folding part of the Darboux vector of the arc-length parameterised control curve at
//! `s_k`, expressed in the curve's own frame (tangent `T`, surface normal `n` (`±N` for a
//! line), `b = n × T`): the flat ruling runs through the flat curve's point at `s_k` in the
//! direction `(ω·T) d + (ω·b) d⊥`, `d` the flat curve's unit tangent there. This is the
//! midpoint rule for the frame's rotation about the Darboux vector (the "instantaneous rotation
//! axis" of §3.1; for a curve on the sheet a Strang splitting: the in-sheet turn is exact
//! between folds), so the folded curve follows the control curve to O(h²), while every face
//! is a piece of the flat sheet moved rigidly: the mesh is isometric to the outline to
//! rounding, the curve's folded length is the flat curve's exactly, and the flatten stage gets
//! back the outline. `n` is chosen so that the sheet is bent by `h` steps with a sagitta
//! `h²|ω|/8` within the sampling tolerance; the folded curve's largest distance from the
//! control curve (at the folds) is measured and reported in a warning when it exceeds the
//! tolerance.
//!
//! Regions the rulings do not reach (corners beyond the first and last ruling, the sheet beyond
//! the line's ends, the sheet between several curved pieces) are simply not folded: they stay
//! planar and join the curved part tangentially along its end ruling (§3.4, §4.2). Several
//! curved pieces are folds along their own lines; the first piece is placed where its control
//! curve is, the others follow rigidly through the sheet (§4.2: "wield the polygon B to its
//! shared edge with A using a rigid transformation"), so only their shape, not their position,
//! is taken from their control curves.
//!
//! # Admissibility (§3.2, §3.3, §4.3)
//!
//! Two neighbouring rulings meet at the discrete curve of regression (eq. 2–5: the limit of this
//! intersection is `l(s) = sin α / α'` along the ruling). A sheet is refused when that point
//! lies on the sheet (eq. 6), with the arc length along the line (mm), its distance from the
//! line and how deep inside the sheet it is. Rulings of different pieces may not cross on the
//! sheet either (checked between every pair, not only end rulings). A control curve that
//! curves less than the curve on the sheet somewhere (`|p''| < |c|`, §5 last paragraph: no
//! surface gives it that geodesic curvature) is refused with the arc length (mm) of the largest
//! shortfall and the shortfall (1/mm), probed at 513 points along the curve.
//!
//! # Choices where the paper is silent
//!
//! - Length (§4.1.3): the control curve is re-parameterised by arc length (Gauss–Legendre) and
//!   fitted to the flat line's length `L`: `length_fit = "scale"` (default) scales it about its
//!   first point (as the paper's tube example, §5, "preserved by scaling"); `"trim"` cuts it at
//!   length `L` from its start (§4.1.3) and refuses a curve shorter than the line.
//! - Which side of the sheet faces where: the sheet's printed side (+z of the flat outline)
//!   faces the surface normal `n`, chosen at the first curved point of the control curve: the
//!   given start normal for handles, else the side with `n·z > 0` (then `n·y > 0`, `n·x > 0`
//!   when `n` is horizontal; for a curve on the sheet, of its two normals the one with the
//!   larger `n·z`, then `n·y`, then `n·x`). Bending a sheet that lies printed side up keeps it
//!   up at the start. Where the curve is straight (an inflection, κ = 0) the normal is carried
//!   over unchanged.
//! - Folds turning by less than 1e-9 rad are left out (straight stretches stay planar).
//! - Curves on the sheet (§5): `κ_n` is taken as 0 where `κ_n² < 1e-10 κ²` (the control curve
//!   lies flat on the sheet there to 1e-5 of its curvature: an exact circle fitted to length
//!   lands here, not on rounding noise), and a curvature short of `|c|` by 1e-9 relative is
//!   rounding, not a refusal. Of the two normals (branches σ = ±1) the first curved point takes
//!   the one by the sign rule above, later points the one nearer the previous normal. `θ'` is
//!   a central difference over ±1 µm of arc length (one-sided at the ends), on the point's
//!   branch. The flat curve must lie on the sheet (256 samples); rulings are drawn through its
//!   points at the folds, so a flat curve's own curvature needs no sampling.
//! - Rulings continue across holes (a ruling of a developable is a straight line through all of
//!   it); beyond the first boundary on each side they stop (§3.3). A hole that no ruling crosses
//!   gets a straight cut line of zero angle through it so that every face of the mesh is a
//!   simple polygon; it is not a bend line.
//! - Handles (§4.1.2, eq. 7): a quartic Bézier through the two end points whose end principal
//!   normals are fitted to the given ones by Levenberg–Marquardt on
//!   `|N0/|N0| − N̄0|² + |N1/|N1| − N̄1|² + (len/L − 1)² + 0.1·|ΔX/L|²` from a start polygon
//!   with end tangents perpendicular to the normals (the length term is ours: it keeps the
//!   re-parameterisation small). A normal missed by more than 1° is a warning, and so is an end
//!   that the length fit moves more than the tolerance away from its handle (handles whose
//!   normals do not suit the sheet's length cannot all be met).
//! - Bend lines: every fold is a ruling and a bend line with its angle (`bend_lines = "all"`),
//!   none, or one every `spacing` mm along each line carrying the angle accumulated since the
//!   previous one, as strips do.

use crate::geom::curve::Curve;
use crate::geom::mesh::{Face, Mesh};
use crate::geom::polygon;
use crate::surface::strip::BendLines;
use crate::surface::Bend;
use glam::{DAffine3, DVec2, DVec3};
use std::collections::{HashMap, VecDeque};

// ---------------------------------------------------------------------------------------------
// Input
// ---------------------------------------------------------------------------------------------

/// A bent sheet as the spec describes it (`kind = "bent-sheet"`).
#[derive(Debug, Clone, PartialEq)]
pub struct BentSpec {
    /// Outer outline of the flat sheet (mm), either orientation.
    pub outline: Vec<DVec2>,
    /// Holes in the sheet.
    pub holes: Vec<Vec<DVec2>>,
    /// The curved pieces: one straight line on the sheet and its control curve each.
    pub pieces: Vec<PieceSpec>,
    /// Sampling tolerance (mm): sagitta of one fold step.
    pub tolerance: f64,
    pub bend_lines: BendLines,
}

/// One curved piece: the curve on the flat sheet (a straight line, or a planar curve whose
/// geodesic curvature is kept, §5) and the 3D curve it must follow.
#[derive(Debug, Clone, PartialEq)]
pub struct PieceSpec {
    /// The curve on the flat sheet (mm), from its start to its end.
    pub path: FlatPath,
    pub control: Control,
    pub fit: LengthFit,
}

/// The curve drawn on the flat sheet that a control curve bends.
#[derive(Debug, Clone, PartialEq)]
pub enum FlatPath {
    /// A straight line from the first point to the second: the control curve is a geodesic
    /// (eq. 1).
    Line([DVec2; 2]),
    /// A circular arc about `center` from the angle `start_deg` to `end_deg` (degrees from +x;
    /// counter-clockwise when `end_deg > start_deg`, clockwise otherwise), at most one turn.
    Arc {
        center: DVec2,
        radius: f64,
        start_deg: f64,
        end_deg: f64,
    },
    /// A Bézier or B-spline curve on the sheet (its control points' z is 0).
    Curve(Spline),
}

impl FlatPath {
    /// Length on the sheet (mm).
    pub fn length(&self) -> f64 {
        match self {
            FlatPath::Line([a, b]) => a.distance(*b),
            FlatPath::Arc {
                radius,
                start_deg,
                end_deg,
                ..
            } => radius * (end_deg - start_deg).to_radians().abs(),
            FlatPath::Curve(c) => ArcLength::new(c).total(),
        }
    }

    /// Point, unit tangent and signed curvature (1/mm, > 0 turning left) at arc length `s`.
    pub fn at(&self, s: f64) -> (DVec2, DVec2, f64) {
        let f = Flat::new(self);
        let q = f.at(s);
        (q.p, q.t, q.c)
    }
}

/// A [`FlatPath`] ready to be evaluated by arc length.
enum Flat<'a> {
    Line {
        a: DVec2,
        d: DVec2,
        len: f64,
    },
    Arc {
        center: DVec2,
        r: f64,
        phi0: f64,
        sign: f64,
        len: f64,
    },
    Curve {
        curve: &'a Spline,
        arc: ArcLength<'a>,
    },
}

/// A point of the flat curve: position, unit tangent, signed curvature.
struct FlatPoint {
    p: DVec2,
    t: DVec2,
    c: f64,
}

impl<'a> Flat<'a> {
    fn new(path: &'a FlatPath) -> Flat<'a> {
        match path {
            FlatPath::Line([a, b]) => {
                let len = a.distance(*b);
                Flat::Line {
                    a: *a,
                    d: (*b - *a) / len,
                    len,
                }
            }
            FlatPath::Arc {
                center,
                radius,
                start_deg,
                end_deg,
            } => Flat::Arc {
                center: *center,
                r: *radius,
                phi0: start_deg.to_radians(),
                sign: if end_deg >= start_deg { 1.0 } else { -1.0 },
                len: path.length(),
            },
            FlatPath::Curve(curve) => Flat::Curve {
                curve,
                arc: ArcLength::new(curve),
            },
        }
    }

    fn len(&self) -> f64 {
        match self {
            Flat::Line { len, .. } | Flat::Arc { len, .. } => *len,
            Flat::Curve { arc, .. } => arc.total(),
        }
    }

    /// A straight line: no geodesic curvature anywhere.
    fn straight(&self) -> bool {
        matches!(self, Flat::Line { .. })
    }

    fn at(&self, s: f64) -> FlatPoint {
        match self {
            Flat::Line { a, d, .. } => FlatPoint {
                p: *a + *d * s,
                t: *d,
                c: 0.0,
            },
            Flat::Arc {
                center,
                r,
                phi0,
                sign,
                ..
            } => {
                let phi = phi0 + sign * s / r;
                let (sn, cs) = phi.sin_cos();
                FlatPoint {
                    p: *center + DVec2::new(cs, sn) * *r,
                    t: DVec2::new(-sn, cs) * *sign,
                    c: sign / r,
                }
            }
            Flat::Curve { curve, arc } => {
                let [p, d1, d2, _] = curve.eval(arc.param(s));
                let v = DVec2::new(d1.x, d1.y);
                let sp = v.length().max(1e-300);
                FlatPoint {
                    p: DVec2::new(p.x, p.y),
                    t: v / sp,
                    c: v.perp_dot(DVec2::new(d2.x, d2.y)) / (sp * sp * sp),
                }
            }
        }
    }
}

/// How the 3D curve is given.
#[derive(Debug, Clone, PartialEq)]
pub enum Control {
    /// A Bézier or (open) B-spline curve (`geom::curve`).
    Curve(Curve),
    /// Two control handles (§4.1.2): end points and the surface normals there.
    Handles {
        start: DVec3,
        start_normal: DVec3,
        end: DVec3,
        end_normal: DVec3,
    },
}

/// How the control curve is brought to the length of the flat line (§4.1.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthFit {
    /// Scale about the curve's first point.
    #[default]
    Scale,
    /// Cut at the line's length from the start.
    Trim,
}

impl LengthFit {
    pub const NAMES: [(&'static str, LengthFit); 2] =
        [("scale", LengthFit::Scale), ("trim", LengthFit::Trim)];
}

/// What can be wrong with a bent sheet. Positions are on the flat sheet, in mm.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeodesicError {
    #[error("outline: {0}")]
    Outline(String),
    #[error("piece {}: line: {message}", .piece + 1)]
    Line { piece: usize, message: String },
    #[error("piece {}: control curve: {message}", .piece + 1)]
    Control { piece: usize, message: String },
    #[error("piece {piece}: the curve of regression enters the sheet at s = {s:.2} mm along the line (ruling through ({x:.2}, {y:.2})): the singular point lies {dist:.2} mm from the line along the ruling, {depth:.2} mm inside the sheet's edge; bend or twist the control curve less there")]
    Regression {
        piece: usize,
        s: f64,
        x: f64,
        y: f64,
        dist: f64,
        depth: f64,
    },
    #[error("the ruling of piece {a} at s = {sa:.2} mm and the ruling of piece {b} at s = {sb:.2} mm cross on the sheet at ({x:.2}, {y:.2}); move the lines apart or bend less")]
    Crossing {
        a: usize,
        sa: f64,
        b: usize,
        sb: f64,
        x: f64,
        y: f64,
    },
    #[error("piece {piece}: the control curve bends less than the curve drawn on the sheet at s = {s:.2} mm along it: its curvature is {kappa:.6}/mm, the flat curve's {c:.6}/mm (radius {radius:.2} mm), short by {short:.6}/mm; a curve keeps its geodesic curvature when the sheet bends, so in space it must curve at least as much (§5): bend the control curve more there or draw a straighter curve on the sheet")]
    Curvature {
        piece: usize,
        s: f64,
        kappa: f64,
        c: f64,
        radius: f64,
        short: f64,
    },
    #[error("{0}")]
    Mesh(String),
}

// ---------------------------------------------------------------------------------------------
// Control curves: position and three derivatives
// ---------------------------------------------------------------------------------------------

/// A regular parametric 3D curve with three derivatives: what a control geodesic must offer.
pub trait Param {
    /// Parameter interval.
    fn domain(&self) -> (f64, f64);
    /// Position and first, second and third derivatives at `u`.
    fn eval(&self, u: f64) -> [DVec3; 4];
    /// Parameters where the curve is only piecewise polynomial (knots), inside the domain.
    fn breaks(&self) -> Vec<f64> {
        Vec::new()
    }
}

/// A clamped B-spline (a Bézier curve is one with a single span), evaluated with derivatives
/// (Piegl & Tiller A2.3). Knots follow `geom::curve`: uniform, clamped, degree lowered to
/// `len − 1` when there are too few control points.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline {
    control: Vec<DVec3>,
    p: usize,
    knots: Vec<f64>,
}

impl Spline {
    pub fn bezier(control: Vec<DVec3>) -> Spline {
        let p = control.len().saturating_sub(1).max(1);
        let mut knots = vec![0.0; p + 1];
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        Spline { control, p, knots }
    }

    pub fn bspline(control: Vec<DVec3>, degree: usize) -> Spline {
        let n = control.len();
        let p = degree.clamp(1, n.saturating_sub(1).max(1));
        let inner = n.saturating_sub(p).max(1);
        let mut knots = vec![0.0; p + 1];
        knots.extend((1..inner).map(|i| i as f64));
        knots.extend(std::iter::repeat_n(inner as f64, p + 1));
        Spline { control, p, knots }
    }

    pub fn control(&self) -> &[DVec3] {
        &self.control
    }

    fn span(&self, u: f64) -> usize {
        let n = self.control.len() - 1;
        if u >= self.knots[n + 1] {
            return n;
        }
        let mut k = self.p;
        while k < n && u >= self.knots[k + 1] {
            k += 1;
        }
        k
    }
}

impl Param for Spline {
    fn domain(&self) -> (f64, f64) {
        (self.knots[self.p], self.knots[self.control.len()])
    }

    fn breaks(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut out: Vec<f64> = self
            .knots
            .iter()
            .copied()
            .filter(|&k| k > a && k < b)
            .collect();
        out.dedup();
        out
    }

    fn eval(&self, u: f64) -> [DVec3; 4] {
        let p = self.p;
        let k = self.span(u);
        let nd = 3.min(p);
        let ders = ders_basis(k, u, p, nd, &self.knots);
        let mut out = [DVec3::ZERO; 4];
        for (o, row) in out.iter_mut().zip(&ders) {
            for (c, w) in self.control[k - p..=k].iter().zip(row) {
                *o += *c * *w;
            }
        }
        out
    }
}

/// Basis function derivatives (Piegl & Tiller, The NURBS Book, algorithm A2.3).
fn ders_basis(i: usize, u: f64, p: usize, n: usize, knots: &[f64]) -> Vec<Vec<f64>> {
    let mut ndu = vec![vec![0.0; p + 1]; p + 1];
    let mut left = vec![0.0; p + 1];
    let mut right = vec![0.0; p + 1];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[i + 1 - j];
        right[j] = knots[i + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = if ndu[j][r] != 0.0 {
                ndu[r][j - 1] / ndu[j][r]
            } else {
                0.0
            };
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = vec![vec![0.0; p + 1]; n + 1];
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let mut a = vec![vec![0.0; p + 1]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=n {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                let den = ndu[pk + 1][rk as usize];
                a[s2][0] = if den != 0.0 { a[s1][0] / den } else { 0.0 };
                d = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if r as isize - 1 <= pk as isize {
                k - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                let den = ndu[pk + 1][idx];
                a[s2][j] = if den != 0.0 {
                    (a[s1][j] - a[s1][j - 1]) / den
                } else {
                    0.0
                };
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                let den = ndu[pk + 1][r];
                a[s2][k] = if den != 0.0 { -a[s1][k - 1] / den } else { 0.0 };
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    // Row k times p!/(p − k)!.
    let mut f = p as f64;
    for (k, row) in ders.iter_mut().enumerate().skip(1) {
        for v in row.iter_mut() {
            *v *= f;
        }
        f *= p.saturating_sub(k) as f64;
    }
    ders
}

/// `inner` scaled about `origin` by `scale` and restricted to `[domain.0, end]`.
struct Fitted<'a> {
    inner: &'a dyn Param,
    origin: DVec3,
    scale: f64,
    end: f64,
}

impl Param for Fitted<'_> {
    fn domain(&self) -> (f64, f64) {
        (self.inner.domain().0, self.end)
    }
    fn eval(&self, u: f64) -> [DVec3; 4] {
        let [p, d1, d2, d3] = self.inner.eval(u);
        let k = self.scale;
        [self.origin + (p - self.origin) * k, d1 * k, d2 * k, d3 * k]
    }
    fn breaks(&self) -> Vec<f64> {
        self.inner
            .breaks()
            .into_iter()
            .filter(|&b| b < self.end)
            .collect()
    }
}

/// Arc length of a parametric curve: a table of (u, s) at Gauss–Legendre panels, inverted by
/// Newton's method.
pub struct ArcLength<'a> {
    curve: &'a dyn Param,
    us: Vec<f64>,
    ss: Vec<f64>,
}

const GL_X: [f64; 5] = [
    -0.906_179_845_938_664,
    -0.538_469_310_105_683,
    0.0,
    0.538_469_310_105_683,
    0.906_179_845_938_664,
];
const GL_W: [f64; 5] = [
    0.236_926_885_056_189,
    0.478_628_670_499_366,
    0.568_888_888_888_889,
    0.478_628_670_499_366,
    0.236_926_885_056_189,
];

fn gl(curve: &dyn Param, a: f64, b: f64) -> f64 {
    let (m, r) = (0.5 * (a + b), 0.5 * (b - a));
    GL_X.iter()
        .zip(GL_W)
        .map(|(x, w)| w * curve.eval(m + r * x)[1].length())
        .sum::<f64>()
        * r
}

impl<'a> ArcLength<'a> {
    pub fn new(curve: &'a dyn Param) -> Self {
        Self::with_panels(curve, 32)
    }

    fn with_panels(curve: &'a dyn Param, per_span: usize) -> Self {
        let (a, b) = curve.domain();
        let mut cuts = vec![a];
        cuts.extend(curve.breaks());
        cuts.push(b);
        let mut us = vec![a];
        let mut ss = vec![0.0];
        for w in cuts.windows(2) {
            for j in 0..per_span {
                let u0 = w[0] + (w[1] - w[0]) * j as f64 / per_span as f64;
                let u1 = w[0] + (w[1] - w[0]) * (j + 1) as f64 / per_span as f64;
                let s = ss[ss.len() - 1] + gl(curve, u0, u1);
                us.push(u1);
                ss.push(s);
            }
        }
        ArcLength { curve, us, ss }
    }

    pub fn total(&self) -> f64 {
        self.ss[self.ss.len() - 1]
    }

    /// The parameter at arc length `s` from the start.
    pub fn param(&self, s: f64) -> f64 {
        let s = s.clamp(0.0, self.total());
        let j = self
            .ss
            .partition_point(|&x| x <= s)
            .clamp(1, self.ss.len() - 1)
            - 1;
        let (u0, u1, s0, s1) = (self.us[j], self.us[j + 1], self.ss[j], self.ss[j + 1]);
        let mut u = if s1 > s0 {
            u0 + (u1 - u0) * (s - s0) / (s1 - s0)
        } else {
            u0
        };
        for _ in 0..8 {
            let f = s0 + gl(self.curve, u0, u) - s;
            let sp = self.curve.eval(u)[1].length();
            if sp <= 0.0 {
                break;
            }
            let du = f / sp;
            u = (u - du).clamp(u0, u1);
            // Converged to a few ulps of the panel (1e-14 of its length in mm at most).
            if du.abs() <= 1e-13 * (u1 - u0) {
                break;
            }
        }
        u
    }
}

/// Frame quantities at one point: unit tangent, curvature vector `dT/ds`, torsion and
/// the Darboux vector `τT + T × K`.
struct Local {
    t: DVec3,
    k: DVec3,
    omega: DVec3,
}

fn local(c: &dyn Param, u: f64) -> Option<Local> {
    let [_, d1, d2, d3] = c.eval(u);
    let sp = d1.length();
    if !(sp.is_finite() && sp > 1e-12) {
        return None;
    }
    let t = d1 / sp;
    let k = (d2 - t * d2.dot(t)) / (sp * sp);
    let cr = d1.cross(d2);
    let c2 = cr.length_squared();
    // τ = det(p', p'', p''') / |p' × p''|², taken as 0 where the curve is straight (κ < 1e-9/mm).
    let tau = if k.length() > 1e-9 && c2 > 0.0 {
        cr.dot(d3) / c2
    } else {
        0.0
    };
    Some(Local {
        t,
        k,
        omega: t * tau + t.cross(k),
    })
}

// ---------------------------------------------------------------------------------------------
// Handles (§4.1.2, eq. 7)
// ---------------------------------------------------------------------------------------------

/// Principal normals at both ends of a Bézier curve from its control points (§4.1.2; the
/// positive factor λ = n³(n − 1) is left out, only directions are used).
fn end_normals(c: &[DVec3]) -> (DVec3, DVec3) {
    let n = c.len() - 1;
    let (t0, a0) = (c[1] - c[0], c[2] - 2.0 * c[1] + c[0]);
    let (t1, a1) = (c[n] - c[n - 1], c[n] - 2.0 * c[n - 1] + c[n - 2]);
    (t0.cross(a0).cross(t0), t1.cross(a1).cross(t1))
}

fn bezier_length(c: &[DVec3]) -> f64 {
    let s = Spline::bezier(c.to_vec());
    let (a, b) = s.domain();
    (0..16)
        .map(|j| {
            let u0 = a + (b - a) * j as f64 / 16.0;
            gl(&s, u0, u0 + (b - a) / 16.0)
        })
        .sum()
}

/// A quartic Bézier through the handles' points whose end principal normals follow the
/// handles' normals (eq. 7 by Levenberg–Marquardt); returns it and the angles (degrees) by
/// which the end normals miss.
pub fn handles_curve(
    start: DVec3,
    n0: DVec3,
    end: DVec3,
    n1: DVec3,
    length: f64,
) -> Result<(Vec<DVec3>, f64, f64), String> {
    let (n0, n1) = (n0.normalize_or_zero(), n1.normalize_or_zero());
    if n0 == DVec3::ZERO || n1 == DVec3::ZERO || !start.is_finite() || !end.is_finite() {
        return Err("the handles' normals must be non-zero finite vectors".into());
    }
    let chord = end - start;
    if chord.length() >= length {
        return Err(format!(
            "the handles are {:.2} mm apart, not less than the line's length {length:.2} mm: paper does not stretch",
            chord.length()
        ));
    }
    let tangent = |n: DVec3| {
        let t = chord - n * chord.dot(n);
        if t.length() > 1e-9 * length {
            Ok(t.normalize())
        } else {
            Err("a handle's normal is along the line between the handles: the curve cannot start or end there with that normal".to_string())
        }
    };
    let (t0, t1) = (tangent(n0)?, tangent(n1)?);
    let q = 0.25 * length;
    let p1 = start + t0 * q;
    let p3 = end - t1 * q;
    let p2 = 0.5 * (p1 + p3);
    let init = [p1, p2, p3];
    let pts = |x: &[f64; 9]| -> Vec<DVec3> {
        vec![
            start,
            DVec3::new(x[0], x[1], x[2]),
            DVec3::new(x[3], x[4], x[5]),
            DVec3::new(x[6], x[7], x[8]),
            end,
        ]
    };
    let mut x = [0.0; 9];
    for j in 0..3 {
        x[3 * j..3 * j + 3].copy_from_slice(&init[j].to_array());
    }
    // The regularisation holds the points near the previous state (§4.1.2: "to ensure a
    // gradual change"); a few passes, each from the last result, as the interactive updates do.
    for _pass in 0..6 {
        let anchor = x;
        let resid = |x: &[f64; 9]| -> [f64; 16] {
            let c = pts(x);
            let (a, b) = end_normals(&c);
            let (a, b) = (a.normalize_or_zero() - n0, b.normalize_or_zero() - n1);
            let len = bezier_length(&c) / length - 1.0;
            let w = 0.1f64.sqrt() / length;
            let mut r = [0.0; 16];
            r[..3].copy_from_slice(&a.to_array());
            r[3..6].copy_from_slice(&b.to_array());
            r[6] = len;
            for j in 0..3 {
                let d = (c[j + 1] - DVec3::from_slice(&anchor[3 * j..3 * j + 3])) * w;
                r[7 + 3 * j..10 + 3 * j].copy_from_slice(&d.to_array());
            }
            r
        };
        let cost = |r: &[f64; 16]| r.iter().map(|v| v * v).sum::<f64>();
        let mut r = resid(&x);
        let mut mu = 1e-3;
        for _ in 0..100 {
            // Numeric Jacobian, 16 × 9, by central differences (so that a symmetric problem, a
            // planar one say, gets no spurious gradient out of its plane).
            let mut jac = [[0.0; 9]; 16];
            for i in 0..9 {
                let e = 1e-5 * length;
                let (mut xp, mut xm) = (x, x);
                xp[i] += e;
                xm[i] -= e;
                let (rp, rm) = (resid(&xp), resid(&xm));
                for (k, row) in jac.iter_mut().enumerate() {
                    row[i] = (rp[k] - rm[k]) / (2.0 * e);
                }
            }
            let mut jtj = [[0.0; 9]; 9];
            let mut jtr = [0.0; 9];
            for row in 0..16 {
                for i in 0..9 {
                    jtr[i] += jac[row][i] * r[row];
                    for j in 0..9 {
                        jtj[i][j] += jac[row][i] * jac[row][j];
                    }
                }
            }
            let mut improved = false;
            for _ in 0..10 {
                let mut a = jtj;
                for (i, row) in a.iter_mut().enumerate() {
                    row[i] += mu * (1.0 + row[i]);
                }
                let Some(dx) = solve9(a, jtr) else {
                    mu *= 10.0;
                    continue;
                };
                let mut xn = x;
                for i in 0..9 {
                    xn[i] -= dx[i];
                }
                let rn = resid(&xn);
                if cost(&rn) < cost(&r) {
                    x = xn;
                    r = rn;
                    mu = (mu * 0.3).max(1e-12);
                    improved = true;
                    break;
                }
                mu *= 10.0;
            }
            if !improved || cost(&r) < 1e-20 {
                break;
            }
        }
    }
    let c = pts(&x);
    let (a, b) = end_normals(&c);
    let miss = |v: DVec3, n: DVec3| v.angle_between(n).to_degrees();
    Ok((c.clone(), miss(a, n0), miss(b, n1)))
}

/// Gaussian elimination with partial pivoting on a 9 × 9 system.
fn solve9(mut a: [[f64; 9]; 9], mut b: [f64; 9]) -> Option<[f64; 9]> {
    for col in 0..9 {
        let piv = (col..9).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let pivot = a[col];
        for row in col + 1..9 {
            let f = a[row][col] / pivot[col];
            for (v, pv) in a[row][col..].iter_mut().zip(&pivot[col..]) {
                *v -= f * pv;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 9];
    for row in (0..9).rev() {
        let s: f64 = (row + 1..9).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

// ---------------------------------------------------------------------------------------------
// Folds of one piece
// ---------------------------------------------------------------------------------------------

/// One ruling of the bent sheet: a fold line on the flat sheet.
#[derive(Debug, Clone, PartialEq)]
pub struct Ruling {
    /// Piece (0-based) it belongs to; `None` for a zero-angle cut line through a hole.
    pub piece: Option<usize>,
    /// Arc length along the piece's line (mm).
    pub s: f64,
    /// Where the ruling crosses the line, on the flat sheet.
    pub point: DVec2,
    /// Unit direction of the ruling on the flat sheet.
    pub dir: DVec2,
    /// Fold angle (radians) about `dir`, right-handed, turning the sheet beyond the ruling
    /// (in the direction of the line) relative to the sheet before it.
    pub angle: f64,
    /// Where the ruling runs on the sheet: `(t0, t1)` along `dir` from `point`.
    pub extent: (f64, f64),
    /// The ruling's segments on the sheet (mesh vertex pairs).
    pub edges: Vec<[usize; 2]>,
    /// 3D direction of the ruling on the bent sheet (unit).
    pub dir_3d: DVec3,
}

/// The folds of one piece and how to place the sheet in space.
struct PieceFolds {
    folds: Vec<Ruling>,
    /// Rigid map from the flat sheet (z = 0) to space for the part before the first fold.
    place: DAffine3,
    /// Largest distance of the folded line's vertices from the control curve (mm).
    drift: f64,
    /// Length of the fitted control curve (mm).
    length: f64,
    warnings: Vec<String>,
}

/// Curvature (1/mm) below which a control curve counts as straight.
const KMIN: f64 = 1e-9;
/// Below this `κ_n² / κ²` counts as zero: the control curve lies flat on the sheet there (its
/// normal curvature is under 1e-5 of its curvature; exact circles fitted to length land here).
const FLAT_KN2: f64 = 1e-10;
/// A control curve's curvature may fall short of the flat curve's by this much (relative)
/// before it is refused: rounding, not geometry.
const SHORT_REL: f64 = 1e-9;

/// |κ_n| = √(κ² − c²) (§5: the normal part of `p''` once the geodesic part `c` is taken).
fn kn_abs(kappa: f64, c: f64) -> f64 {
    let kn2 = kappa * kappa - c * c;
    if kn2 <= FLAT_KN2 * kappa * kappa {
        0.0
    } else {
        kn2.sqrt()
    }
}

/// The two surface normals (branches σ = +1 and −1) along which the control curve has the
/// flat curve's geodesic curvature `c`: `n = σ (κ_n/κ) N + (c/κ) B`, so that
/// `p'' = c (n × T) + σ κ_n n` (§5). `None` where the curve is straight.
fn normals_for(l: &Local, c: f64) -> Option<[DVec3; 2]> {
    let kappa = l.k.length();
    if kappa <= KMIN {
        return None;
    }
    if c == 0.0 {
        let n = l.k.normalize();
        return Some([n, -n]);
    }
    let nn = l.k / kappa;
    let bb = l.t.cross(nn);
    let a = kn_abs(kappa, c) / kappa;
    let beta = (c / kappa).clamp(-1.0, 1.0);
    Some([
        (nn * a + bb * beta).normalize(),
        (nn * -a + bb * beta).normalize(),
    ])
}

/// `θ'` for the surface normal `n = cos θ N + sin θ B` with `tan θ = c / (σ κ_n)` on branch
/// `sigma`: the geodesic torsion is `τ_g = τ + θ'`. Central difference over ±1 µm (one-sided
/// at the ends); zero on a straight flat line.
fn theta_rate(
    curve: &dyn Param,
    arc: &ArcLength,
    flat: &Flat,
    s: f64,
    sigma: f64,
    len: f64,
) -> f64 {
    if flat.straight() {
        return 0.0;
    }
    let delta = 1e-3_f64.min(1e-3 * len);
    let theta = |s: f64| -> Option<f64> {
        let l = local(curve, arc.param(s))?;
        let kappa = l.k.length();
        if kappa <= KMIN {
            return None;
        }
        let c = flat.at(s).c;
        Some(c.atan2(sigma * kn_abs(kappa, c)))
    };
    let (s0, s1) = ((s - delta).max(0.0), (s + delta).min(len));
    match (theta(s0), theta(s1)) {
        (Some(a), Some(b)) if s1 > s0 => {
            let pi = std::f64::consts::PI;
            let mut d = b - a;
            if d > pi {
                d -= 2.0 * pi;
            } else if d < -pi {
                d += 2.0 * pi;
            }
            d / (s1 - s0)
        }
        _ => 0.0,
    }
}

/// Pick the branch of [`normals_for`] by the sign rule at the first curved point (see the
/// module doc): the one further along the hint, then +z, +y, +x. Returns the index.
fn orient_pair(n: &[DVec3; 2], up: Option<DVec3>) -> usize {
    let refs = match up {
        Some(u) => vec![u],
        None => vec![DVec3::Z, DVec3::Y, DVec3::X],
    };
    for r in refs {
        let d = (n[0] - n[1]).dot(r);
        if d.abs() > 2e-6 {
            return if d > 0.0 { 0 } else { 1 };
        }
    }
    0
}

/// Rotation about the line through `q` (z = 0) with unit direction `dir` by `angle`.
fn fold_map(q: DVec2, dir: DVec2, angle: f64) -> DAffine3 {
    let q3 = DVec3::new(q.x, q.y, 0.0);
    DAffine3::from_translation(q3)
        * DAffine3::from_axis_angle(DVec3::new(dir.x, dir.y, 0.0), angle)
        * DAffine3::from_translation(-q3)
}

fn piece_folds(
    piece: usize,
    spec: &PieceSpec,
    flat: &Flat,
    curve: &dyn Param,
    up: Option<DVec3>,
    tol: f64,
) -> Result<PieceFolds, GeodesicError> {
    let cerr = |message: String| GeodesicError::Control { piece, message };
    let len = flat.len();
    let mut warnings = Vec::new();

    // Length (§4.1.3).
    let raw = ArcLength::new(curve);
    let total = raw.total();
    if !(total.is_finite() && total > 1e-9) {
        return Err(cerr("has no length".into()));
    }
    let (dom0, dom1) = curve.domain();
    let origin = curve.eval(dom0)[0];
    let fitted = match spec.fit {
        LengthFit::Scale => {
            let k = len / total;
            if (k - 1.0).abs() > 1e-3 {
                warnings.push(format!(
                    "piece {}: the control curve is {total:.2} mm long and the line {len:.2} mm: curve scaled by {k:.5} about its start",
                    piece + 1
                ));
            }
            Fitted {
                inner: curve,
                origin,
                scale: k,
                end: dom1,
            }
        }
        LengthFit::Trim => {
            if total < len * (1.0 - 1e-12) {
                return Err(cerr(format!(
                    "is {total:.3} mm long, shorter than the line ({len:.3} mm); with length_fit = \"trim\" it must be at least as long"
                )));
            }
            Fitted {
                inner: curve,
                origin,
                scale: 1.0,
                end: raw.param(len),
            }
        }
    };
    let arc = ArcLength::new(&fitted);
    let length = arc.total();

    // Step: sagitta h²|ω|/8 within the tolerance.
    let probes = 256;
    let mut wmax: f64 = 0.0;
    let (f0, f1) = fitted.domain();
    if flat.straight() {
        for j in 0..=probes {
            // |ω| does not depend on the parameterisation: probe evenly in the parameter.
            let u = f0 + (f1 - f0) * j as f64 / probes as f64;
            if let Some(l) = local(&fitted, u) {
                wmax = wmax.max(l.omega.length());
            }
        }
    } else {
        // A curve drawn on the sheet: probe by arc length (the flat curvature is given so),
        // refuse a control curve that curves less than it (§5), and bound the folding part
        // of ω by (|τ| + |θ'|, κ_n).
        let probes = 2 * probes;
        let mut worst: Option<(f64, f64, f64)> = None;
        for j in 0..=probes {
            let s = len * j as f64 / probes as f64;
            let Some(l) = local(&fitted, arc.param(s)) else {
                continue;
            };
            let c = flat.at(s).c;
            let kappa = l.k.length();
            let short = c.abs() - kappa;
            if short > SHORT_REL * c.abs() && worst.is_none_or(|w| short > w.1.abs() - w.2) {
                worst = Some((s, c, kappa));
            }
            let tau = l.omega.dot(l.t);
            let dtheta = theta_rate(&fitted, &arc, flat, s, 1.0, len);
            let tg = tau.abs() + dtheta.abs();
            let kn = kn_abs(kappa, c);
            wmax = wmax.max((tg * tg + kn * kn).sqrt());
        }
        if let Some((s, c, kappa)) = worst {
            return Err(GeodesicError::Curvature {
                piece: piece + 1,
                s,
                kappa,
                c: c.abs(),
                radius: 1.0 / c.abs(),
                short: c.abs() - kappa,
            });
        }
    }
    if !wmax.is_finite() {
        return Err(cerr("its curvature or torsion is not finite".into()));
    }
    let h_max = if wmax > 0.0 {
        (8.0 * tol / wmax).sqrt()
    } else {
        len
    };
    const MAX_STEPS: usize = 200_000;
    let folds_at = |n: usize| folds_at_n(piece, n, &fitted, &arc, flat, up, tol);
    let mut n = ((len / h_max).ceil() as usize).max(2);
    // The folded line strays O(h²) from the curve: refine until it is within the tolerance.
    let mut tries = 0;
    let (folds, place, drift) = loop {
        let (folds, place, drift) = folds_at(n)?;
        tries += 1;
        if drift <= tol || tries >= 4 || n >= MAX_STEPS {
            break (folds, place, drift);
        }
        let grow = ((drift / tol).sqrt() * 1.1).max(1.2);
        n = ((n as f64 * grow).ceil() as usize).min(MAX_STEPS);
    };
    if drift > tol {
        warnings.push(format!(
            "piece {}: the folded sheet strays up to {drift:.3} mm from the control curve (tolerance {tol} mm)",
            piece + 1
        ));
    }
    Ok(PieceFolds {
        folds,
        place,
        drift,
        length,
        warnings,
    })
}

/// [`piece_folds`] at `n` steps: the folds, the placement and the largest distance of the
/// folded flat curve from the control curve.
#[allow(clippy::too_many_arguments)]
fn folds_at_n(
    piece: usize,
    n: usize,
    fitted: &dyn Param,
    arc: &ArcLength,
    flat: &Flat,
    up: Option<DVec3>,
    tol: f64,
) -> Result<(Vec<Ruling>, DAffine3, f64), GeodesicError> {
    let cerr = |message: String| GeodesicError::Control { piece, message };
    let len = flat.len();
    let length = arc.total();
    const MAX_STEPS: usize = 200_000;
    if n > MAX_STEPS {
        return Err(cerr(format!(
            "would need {n} rulings at a tolerance of {tol} mm (over {MAX_STEPS}); raise `tolerance` or bend less sharply"
        )));
    }
    let h = len / n as f64;

    // Frames at s = h/2 (the first segment) and at each fold s_k = k h, with the flat
    // curve's curvature there.
    let mut at: Vec<(f64, Local, f64)> = Vec::with_capacity(n + 1);
    for k in 0..n {
        let s = if k == 0 { 0.5 * h } else { k as f64 * h };
        let l = local(fitted, arc.param(s))
            .ok_or_else(|| cerr(format!("is singular (zero speed) at s = {s:.2} mm")))?;
        if !(l.omega.is_finite() && l.t.is_finite()) {
            return Err(cerr(format!("is not smooth at s = {s:.2} mm")));
        }
        let c = flat.at(s).c;
        at.push((s, l, c));
    }
    // Surface normals (§5; ±K for a line), continuous; carried over where K vanishes. The
    // branch σ (+1: first of `normals_for`) is kept for the geodesic torsion.
    let cands: Vec<Option<[DVec3; 2]>> = at.iter().map(|(_, l, c)| normals_for(l, *c)).collect();
    let first = cands.iter().position(|c| c.is_some());
    let mut normals = vec![DVec3::ZERO; at.len()];
    let mut sigma = vec![1.0; at.len()];
    match first {
        None => {
            let t = at[0].1.t;
            let mut n0 = DVec3::ZERO;
            for r in [up.unwrap_or(DVec3::Z), DVec3::Z, DVec3::Y, DVec3::X] {
                let v = r - t * r.dot(t);
                if v.length() > 1e-6 {
                    n0 = v.normalize();
                    break;
                }
            }
            normals.fill(n0);
        }
        Some(f) => {
            let pair = cands[f].unwrap_or([DVec3::Z, -DVec3::Z]);
            let i0 = orient_pair(&pair, up);
            normals[f] = pair[i0];
            sigma[f] = if i0 == 0 { 1.0 } else { -1.0 };
            for i in (0..f).rev() {
                let t = at[i].1.t;
                let v = normals[i + 1] - t * normals[i + 1].dot(t);
                normals[i] = v.normalize_or(normals[i + 1]);
            }
            for i in f + 1..at.len() {
                let t = at[i].1.t;
                let prev = normals[i - 1];
                normals[i] = match cands[i] {
                    Some(pair) => {
                        if pair[0].dot(prev) >= pair[1].dot(prev) {
                            pair[0]
                        } else {
                            sigma[i] = -1.0;
                            pair[1]
                        }
                    }
                    None => (prev - t * prev.dot(t)).normalize_or(prev),
                };
            }
        }
    }

    // Placement: the flat frame (d, d⊥, z) of the first segment ↦ (T, b, n) there,
    // b = n × T, with the flat curve's start at p(0).
    let (t0, n0) = (at[0].1.t, normals[0]);
    let b0 = n0.cross(t0).normalize();
    let n0 = t0.cross(b0);
    let p0 = fitted.eval(fitted.domain().0)[0];
    let a = flat.at(0.0).p;
    let d = flat.at(at[0].0).t;
    let dp = d.perp();
    let world = glam::DMat3::from_cols(t0, b0, n0);
    let flat_frame = glam::DMat3::from_cols(
        DVec3::new(d.x, d.y, 0.0),
        DVec3::new(dp.x, dp.y, 0.0),
        DVec3::Z,
    );
    let place = DAffine3::from_translation(p0)
        * DAffine3::from_mat3(world * flat_frame.transpose())
        * DAffine3::from_translation(-DVec3::new(a.x, a.y, 0.0));

    let mut folds = Vec::new();
    for k in 1..n {
        let (s, l, _) = &at[k];
        let t = l.t;
        let nn = normals[k];
        let bb = nn.cross(t);
        // The folding part of the Darboux vector: τ_g T − κ_n b (κ_g n turns the curve
        // inside the sheet, which the flat curve does by itself).
        let wt = l.omega.dot(t) + theta_rate(fitted, arc, flat, *s, sigma[k], len);
        let wb = l.omega.dot(bb);
        let mag = (wt * wt + wb * wb).sqrt();
        let angle = mag * h;
        if angle < 1e-9 {
            continue;
        }
        let q = flat.at(*s);
        let dir = (q.t * wt + q.t.perp() * wb) / mag;
        folds.push(Ruling {
            piece: Some(piece),
            s: *s,
            point: q.p,
            dir,
            angle,
            extent: (0.0, 0.0),
            edges: Vec::new(),
            dir_3d: DVec3::ZERO,
        });
    }

    // How far the folded flat curve strays from the control curve.
    let mut m = place;
    let mut drift: f64 = 0.0;
    let mut fi = 0;
    for k in 1..=n {
        let s = k as f64 * h;
        while fi < folds.len() && folds[fi].s < s - 0.5 * h {
            let f = &folds[fi];
            m *= fold_map(f.point, f.dir, f.angle);
            fi += 1;
        }
        let flat_pt = flat.at(s).p;
        let v = m.transform_point3(DVec3::new(flat_pt.x, flat_pt.y, 0.0));
        let target = fitted.eval(arc.param(s.min(length)))[0];
        drift = drift.max(v.distance(target));
    }
    Ok((folds, place, drift))
}

// ---------------------------------------------------------------------------------------------
// The sheet: outline, crossings, faces
// ---------------------------------------------------------------------------------------------

/// Drop repeated and collinear points; orient counter-clockwise (`ccw`) or clockwise.
fn clean_ring(ring: &[DVec2], ccw: bool) -> Vec<DVec2> {
    let mut r: Vec<DVec2> = Vec::with_capacity(ring.len());
    for &p in ring {
        if r.last().is_none_or(|q: &DVec2| q.distance(p) > 1e-9) {
            r.push(p);
        }
    }
    while r.len() > 1 && r[0].distance(r[r.len() - 1]) <= 1e-9 {
        r.pop();
    }
    loop {
        let n = r.len();
        if n < 3 {
            break;
        }
        let drop = (0..n).find(|&i| {
            let (a, b, c) = (r[(i + n - 1) % n], r[i], r[(i + 1) % n]);
            let e = (c - a).length().max(1e-12);
            ((b - a).perp_dot(c - a) / e).abs() < 1e-9
        });
        match drop {
            Some(i) => {
                r.remove(i);
            }
            None => break,
        }
    }
    if (polygon::signed_area(&r) > 0.0) != ccw {
        r.reverse();
    }
    r
}

/// Where a line crosses the sheet's rings.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    t: f64,
    ring: usize,
    edge: usize,
    u: f64,
}

fn crossings(rings: &[Vec<DVec2>], p: DVec2, d: DVec2) -> Vec<Crossing> {
    let mut out = Vec::new();
    for (ri, r) in rings.iter().enumerate() {
        let n = r.len();
        for i in 0..n {
            let (a, b) = (r[i], r[(i + 1) % n]);
            let (sa, sb) = (d.perp_dot(a - p), d.perp_dot(b - p));
            if (sa > 0.0) != (sb > 0.0) {
                let u = sa / (sa - sb);
                out.push(Crossing {
                    t: (a + (b - a) * u - p).dot(d),
                    ring: ri,
                    edge: i,
                    u,
                });
            }
        }
    }
    out.sort_by(|x, y| x.t.total_cmp(&y.t));
    out
}

/// The intervals of a ruling on the sheet: the one through its point (or the two beside it when
/// the point is in a hole), continued across holes to the outer outline.
fn chain(cr: &[Crossing]) -> Vec<(Crossing, Crossing)> {
    let m = cr.len() / 2;
    if m == 0 {
        return Vec::new();
    }
    let idx = cr.partition_point(|c| c.t <= 0.0);
    let (mut i0, mut i1) = if idx % 2 == 1 {
        ((idx - 1) / 2, (idx - 1) / 2)
    } else if idx == 0 {
        (0, 0)
    } else if idx >= 2 * m {
        (m - 1, m - 1)
    } else {
        (idx / 2 - 1, idx / 2)
    };
    while i0 > 0 && cr[2 * i0].ring != 0 {
        i0 -= 1;
    }
    while i1 + 1 < m && cr[2 * i1 + 1].ring != 0 {
        i1 += 1;
    }
    (i0..=i1).map(|i| (cr[2 * i], cr[2 * i + 1])).collect()
}

/// Parameters along two lines where they meet, if they are not parallel.
fn meet(p: DVec2, d: DVec2, q: DVec2, e: DVec2) -> Option<(f64, f64)> {
    let den = d.perp_dot(e);
    if den.abs() < 1e-12 {
        return None;
    }
    let w = q - p;
    Some((w.perp_dot(e) / den, w.perp_dot(d) / den))
}

/// The result: the bent sheet as a mesh with its flat layout and rulings.
#[derive(Debug, Clone, PartialEq)]
pub struct Bent {
    /// Triangles in mm, counter-clockwise seen from the printed side.
    pub mesh: Mesh,
    /// Flat position of each mesh vertex on the sheet.
    pub flat: Vec<DVec2>,
    /// Rulings (fold lines), piece by piece in order along their lines, then hole cut lines.
    pub rulings: Vec<Ruling>,
    /// Bend lines picked by `bend_lines`.
    pub bends: Vec<Bend>,
    /// Per piece: the fitted control curve's length (mm) and the folded line's largest distance
    /// from it (mm).
    pub lengths: Vec<f64>,
    pub drifts: Vec<f64>,
    pub warnings: Vec<String>,
}

/// A piece's control curve to evaluate, the surface normal hint (handles) and warnings.
pub type ControlParam = (Box<dyn Param>, Option<DVec3>, Vec<String>);

/// The control curve of a piece as something to evaluate, and the normal hint for handles.
pub fn control_param(piece: usize, spec: &PieceSpec) -> Result<ControlParam, GeodesicError> {
    let cerr = |message: String| GeodesicError::Control { piece, message };
    let len = spec.path.length();
    let finite = |c: &[DVec3]| c.iter().all(|p| p.is_finite());
    match &spec.control {
        Control::Curve(Curve::Bezier { control }) => {
            if control.len() < 3 || !finite(control) {
                return Err(cerr(format!(
                    "a Bézier control curve needs at least 3 finite control points (it must bend), got {}",
                    control.len()
                )));
            }
            Ok((Box::new(Spline::bezier(control.clone())), None, Vec::new()))
        }
        Control::Curve(Curve::BSpline {
            control,
            degree,
            closed,
        }) => {
            if *closed {
                return Err(cerr("must be an open curve (`closed = false`)".into()));
            }
            if control.len() < 3 || !finite(control) || *degree < 2 {
                return Err(cerr(
                    "a B-spline control curve needs at least 3 finite control points and degree 2 or more"
                        .into(),
                ));
            }
            Ok((
                Box::new(Spline::bspline(control.clone(), *degree)),
                None,
                Vec::new(),
            ))
        }
        Control::Curve(_) => Err(cerr(
            "must be a Bézier or B-spline curve (its rulings need three derivatives)".into(),
        )),
        Control::Handles {
            start,
            start_normal,
            end,
            end_normal,
        } => {
            let (c, m0, m1) =
                handles_curve(*start, *start_normal, *end, *end_normal, len).map_err(cerr)?;
            let mut w = Vec::new();
            let got = ArcLength::new(&Spline::bezier(c.clone())).total();
            let moved = (*end - *start).length() * (len / got - 1.0).abs();
            if moved > 0.05 {
                w.push(format!(
                    "piece {}: the curve through the handles is {got:.1} mm long; fitted to the line's {len:.1} mm its end moves {moved:.1} mm from the end handle (tilt the normals to suit the length)",
                    piece + 1
                ));
            }
            if m0.max(m1) > 1.0 {
                w.push(format!(
                    "piece {}: the handles' normals are met to {m0:.1}° (start) and {m1:.1}° (end)",
                    piece + 1
                ));
            }
            Ok((
                Box::new(Spline::bezier(c)),
                Some(start_normal.normalize_or(DVec3::Z)),
                w,
            ))
        }
    }
}

/// Bend the sheet (see the module doc).
pub fn bend(spec: &BentSpec) -> Result<Bent, GeodesicError> {
    let mut params = Vec::new();
    let mut warnings = Vec::new();
    for (i, p) in spec.pieces.iter().enumerate() {
        let (c, up, w) = control_param(i, p)?;
        warnings.extend(w);
        params.push((c, up));
    }
    let refs: Vec<(&dyn Param, Option<DVec3>)> =
        params.iter().map(|(c, up)| (c.as_ref(), *up)).collect();
    let mut out = bend_with(spec, &refs)?;
    warnings.append(&mut out.warnings);
    out.warnings = warnings;
    Ok(out)
}

/// [`bend`] with the control curves given as parametric curves (one per piece, in order), with
/// an optional hint for the surface normal's side at the start.
pub fn bend_with(
    spec: &BentSpec,
    curves: &[(&dyn Param, Option<DVec3>)],
) -> Result<Bent, GeodesicError> {
    let tol = spec.tolerance;
    if !(tol.is_finite() && tol > 0.0) {
        return Err(GeodesicError::Mesh(format!(
            "tolerance must be a positive number of mm, got {tol}"
        )));
    }
    // Outline and holes.
    let oerr = |m: String| GeodesicError::Outline(m);
    if spec.outline.iter().any(|p| !p.is_finite()) {
        return Err(oerr("a point is not finite".into()));
    }
    let outer = clean_ring(&spec.outline, true);
    if outer.len() >= 3 && !polygon::is_simple_ring(&outer) {
        return Err(oerr("crosses itself".into()));
    }
    if outer.len() < 3 || polygon::signed_area(&outer) < 1e-6 {
        return Err(oerr(
            "needs at least 3 points enclosing an area (rectangle `[width, height]` or a list of points)"
                .into(),
        ));
    }
    if !polygon::is_simple_ring(&outer) {
        return Err(oerr("crosses itself".into()));
    }
    let mut rings = vec![outer];
    for (h, hole) in spec.holes.iter().enumerate() {
        let r = clean_ring(hole, false);
        let herr = |m: &str| oerr(format!("hole {}: {m}", h + 1));
        if hole.iter().any(|p| !p.is_finite()) {
            return Err(herr("a point is not finite"));
        }
        if r.len() < 3 || polygon::signed_area(&r).abs() < 1e-6 {
            return Err(herr("needs at least 3 points enclosing an area"));
        }
        if !polygon::is_simple_ring(&r) {
            return Err(herr("crosses itself"));
        }
        if !r.iter().all(|&p| polygon::contains(&rings[0], p)) {
            return Err(herr("is not inside the outline"));
        }
        for other in &rings {
            let cross = (0..r.len()).any(|i| {
                (0..other.len()).any(|j| {
                    polygon::segments_intersect(
                        r[i],
                        r[(i + 1) % r.len()],
                        other[j],
                        other[(j + 1) % other.len()],
                    )
                })
            });
            if cross || other.iter().any(|&p| polygon::contains(&r, p)) {
                return Err(herr("crosses or contains the outline or another hole"));
            }
        }
        rings.push(r);
    }
    if spec.pieces.is_empty() || curves.len() != spec.pieces.len() {
        return Err(GeodesicError::Mesh(
            "a bent sheet needs at least one line with its control curve".into(),
        ));
    }
    // Lines and curves on the sheet.
    let on_sheet = |q: DVec2| {
        let r = &rings[0];
        (0..r.len()).any(|j| polygon::segment_distance(q, r[j], r[(j + 1) % r.len()]) <= 1e-6)
            || polygon::contains(r, q)
    };
    for (i, p) in spec.pieces.iter().enumerate() {
        let lerr = |message: String| GeodesicError::Line { piece: i, message };
        match &p.path {
            FlatPath::Line([a, b]) => {
                let (a, b) = (*a, *b);
                if !(a.is_finite() && b.is_finite()) {
                    return Err(lerr("a point is not finite".into()));
                }
                if a.distance(b) < 1e-6 {
                    return Err(lerr("its two points are the same".into()));
                }
                for q in [a, b] {
                    if !on_sheet(q) {
                        return Err(lerr(format!(
                            "point ({}, {}) is not on the sheet",
                            q.x, q.y
                        )));
                    }
                }
                continue;
            }
            FlatPath::Arc {
                center,
                radius,
                start_deg,
                end_deg,
            } => {
                if !(center.is_finite() && start_deg.is_finite() && end_deg.is_finite()) {
                    return Err(lerr("the arc's centre and angles must be finite".into()));
                }
                if !(radius.is_finite() && *radius >= 1e-3) {
                    return Err(lerr(format!(
                        "the arc's radius must be at least 0.001 mm, got {radius}"
                    )));
                }
                let sweep = (end_deg - start_deg).abs();
                if !(radius * sweep.to_radians() >= 1e-6 && sweep <= 360.0) {
                    return Err(lerr(format!(
                        "the arc must sweep more than nothing and at most 360°, from start_deg {start_deg} to end_deg {end_deg}"
                    )));
                }
            }
            FlatPath::Curve(c) => {
                if c.control().len() < 2 || c.control().iter().any(|q| !q.is_finite()) {
                    return Err(lerr(
                        "a curve on the sheet needs at least 2 finite control points".into(),
                    ));
                }
                let l = p.path.length();
                if l.is_nan() || l < 1e-6 {
                    return Err(lerr("the curve on the sheet has no length".into()));
                }
            }
        }
        // A curve: every sample on the sheet, and regular.
        let f = Flat::new(&p.path);
        let len = f.len();
        const SAMPLES: usize = 256;
        for j in 0..=SAMPLES {
            let s = len * j as f64 / SAMPLES as f64;
            let q = f.at(s);
            if !(q.p.is_finite() && q.t.is_finite() && q.c.is_finite()) {
                return Err(lerr(format!(
                    "the curve on the sheet is not smooth at s = {s:.2} mm (a cusp or a repeated control point?)"
                )));
            }
            if !on_sheet(q.p) {
                return Err(lerr(format!(
                    "the curve leaves the sheet at s = {s:.2} mm, point ({:.2}, {:.2})",
                    q.p.x, q.p.y
                )));
            }
        }
    }
    let flats: Vec<Flat> = spec.pieces.iter().map(|p| Flat::new(&p.path)).collect();

    // Folds of every piece.
    let mut warnings = Vec::new();
    let mut rulings: Vec<Ruling> = Vec::new();
    let mut place = DAffine3::IDENTITY;
    let mut lengths = Vec::new();
    let mut drifts = Vec::new();
    for (i, (p, (c, up))) in spec.pieces.iter().zip(curves).enumerate() {
        let mut pf = piece_folds(i, p, &flats[i], *c, *up, tol)?;
        if i == 0 {
            place = pf.place;
        }
        warnings.append(&mut pf.warnings);
        lengths.push(pf.length);
        drifts.push(pf.drift);
        rulings.append(&mut pf.folds);
    }
    // Where each ruling lies on the sheet.
    let mut chains: Vec<Vec<(Crossing, Crossing)>> = Vec::with_capacity(rulings.len());
    for r in rulings.iter_mut() {
        let ch = chain(&crossings(&rings, r.point, r.dir));
        r.extent = match (ch.first(), ch.last()) {
            (Some(f), Some(l)) => (f.0.t, l.1.t),
            _ => (0.0, 0.0),
        };
        chains.push(ch);
    }
    // Admissibility: neighbours within a piece, every pair across pieces.
    let inside = |r: &Ruling, t: f64| t > r.extent.0 + 1e-9 && t < r.extent.1 - 1e-9;
    // Pairs to test: each ruling with the next of its piece; across pieces every pair, or
    // only the end rulings (§4.3) when there are very many.
    let mut pairs: Vec<(usize, usize)> = (1..rulings.len())
        .filter(|&j| rulings[j].piece == rulings[j - 1].piece)
        .map(|j| (j - 1, j))
        .collect();
    let groups: Vec<Vec<usize>> = (0..spec.pieces.len())
        .map(|p| {
            (0..rulings.len())
                .filter(|&k| rulings[k].piece == Some(p))
                .collect()
        })
        .collect();
    for (gi, ga) in groups.iter().enumerate() {
        for gb in &groups[gi + 1..] {
            let ends = |g: &Vec<usize>| -> Vec<usize> {
                if ga.len().saturating_mul(gb.len()) <= 4_000_000 {
                    g.clone()
                } else {
                    g.first().into_iter().chain(g.last()).copied().collect()
                }
            };
            for &k in &ends(ga) {
                for &j in &ends(gb) {
                    pairs.push((k, j));
                }
            }
        }
    }
    for (k, j) in pairs {
        {
            let (a, b) = (&rulings[k], &rulings[j]);
            let neighbours = a.piece == b.piece;
            let Some((ta, tb)) = meet(a.point, a.dir, b.point, b.dir) else {
                continue;
            };
            if !(inside(a, ta) && inside(b, tb)) {
                continue;
            }
            let x = a.point + a.dir * ta;
            let (pa, pb) = (a.piece.unwrap_or(0), b.piece.unwrap_or(0));
            return Err(if neighbours {
                GeodesicError::Regression {
                    piece: pa + 1,
                    s: a.s,
                    x: a.point.x,
                    y: a.point.y,
                    dist: ta.abs(),
                    depth: (ta - a.extent.0).min(a.extent.1 - ta),
                }
            } else {
                GeodesicError::Crossing {
                    a: pa + 1,
                    sa: a.s,
                    b: pb + 1,
                    sb: b.s,
                    x: x.x,
                    y: x.y,
                }
            });
        }
    }
    // Holes no ruling crosses get a zero-angle cut line.
    for h in 1..rings.len() {
        if chains
            .iter()
            .flatten()
            .any(|(c0, c1)| c0.ring == h || c1.ring == h)
        {
            continue;
        }
        let hole = &rings[h];
        let centre = hole.iter().copied().sum::<DVec2>() / hole.len() as f64;
        let centre = if polygon::contains(hole, centre) {
            centre
        } else {
            0.5 * (hole[0] + hole[1]) + (hole[1] - hole[0]).perp().normalize() * -1e-3
        };
        let mut dirs: Vec<DVec2> = Vec::new();
        let mut near: Vec<&Ruling> = rulings.iter().collect();
        near.sort_by(|a, b| {
            a.point
                .distance(centre)
                .total_cmp(&b.point.distance(centre))
        });
        dirs.extend(near.iter().take(4).map(|r| r.dir));
        for deg in [0.0f64, 90.0, 45.0, 135.0, 22.5, 67.5, 112.5, 157.5] {
            dirs.push(DVec2::from_angle(deg.to_radians()));
        }
        let mut done = false;
        for dir in dirs {
            let cr = crossings(&rings, centre, dir);
            let ch = chain(&cr);
            let Some(ext) = ch.first().zip(ch.last()).map(|(f, l)| (f.0.t, l.1.t)) else {
                continue;
            };
            let clash = rulings.iter().any(|r| {
                meet(centre, dir, r.point, r.dir)
                    .is_some_and(|(ta, tb)| ta > ext.0 - 1e-6 && ta < ext.1 + 1e-6 && inside(r, tb))
            });
            if clash || !ch.iter().any(|(a, b)| a.ring == h || b.ring == h) {
                continue;
            }
            rulings.push(Ruling {
                piece: None,
                s: 0.0,
                point: centre,
                dir,
                angle: 0.0,
                extent: ext,
                edges: Vec::new(),
                dir_3d: DVec3::ZERO,
            });
            chains.push(ch);
            done = true;
            break;
        }
        if !done {
            return Err(GeodesicError::Mesh(format!(
                "hole {h}: no straight line through it avoids the rulings; move it or the lines"
            )));
        }
    }

    // Nodes: ring vertices, then ruling ends on ring edges.
    let mut pos: Vec<DVec2> = Vec::new();
    let mut ring_node: Vec<Vec<usize>> = Vec::new();
    for r in &rings {
        ring_node.push((pos.len()..pos.len() + r.len()).collect());
        pos.extend_from_slice(r);
    }
    let mut on_edge: HashMap<(usize, usize), Vec<(f64, usize)>> = HashMap::new();
    let mut node_at = |c: &Crossing, pos: &mut Vec<DVec2>| -> usize {
        let r = &rings[c.ring];
        let n = r.len();
        let (a, b) = (r[c.edge], r[(c.edge + 1) % n]);
        let len = a.distance(b);
        if c.u * len <= 1e-9 {
            return ring_node[c.ring][c.edge];
        }
        if (1.0 - c.u) * len <= 1e-9 {
            return ring_node[c.ring][(c.edge + 1) % n];
        }
        let list = on_edge.entry((c.ring, c.edge)).or_default();
        if let Some(&(_, id)) = list.iter().find(|(u, _)| (u - c.u).abs() * len <= 1e-9) {
            return id;
        }
        let id = pos.len();
        pos.push(a + (b - a) * c.u);
        list.push((c.u, id));
        id
    };
    // Undirected edges: (from, to, ruling) — ring edges run with the sheet on their left.
    let mut edges: Vec<(usize, usize, Option<usize>)> = Vec::new();
    for (ri, ch) in chains.iter().enumerate() {
        let mut segs = Vec::new();
        for (c0, c1) in ch {
            let (n0, n1) = (node_at(c0, &mut pos), node_at(c1, &mut pos));
            if n0 != n1 && pos[n0].distance(pos[n1]) > 1e-9 {
                edges.push((n0, n1, Some(ri)));
                segs.push([n0, n1]);
            }
        }
        rulings[ri].edges = segs;
    }
    for (ri, r) in rings.iter().enumerate() {
        for i in 0..r.len() {
            let mut pts = vec![(0.0, ring_node[ri][i])];
            if let Some(list) = on_edge.get(&(ri, i)) {
                let mut l = list.clone();
                l.sort_by(|a, b| a.0.total_cmp(&b.0));
                pts.extend(l);
            }
            pts.push((1.0, ring_node[ri][(i + 1) % r.len()]));
            for w in pts.windows(2) {
                edges.push((w[0].1, w[1].1, None));
            }
        }
    }
    // Half-edges 2e (from → to) and 2e + 1; ring edges' twins face away from the sheet.
    let nh = 2 * edges.len();
    let from = |h: usize| {
        let e = edges[h / 2];
        if h % 2 == 0 {
            e.0
        } else {
            e.1
        }
    };
    let to = |h: usize| from(h ^ 1);
    let mut out: Vec<Vec<usize>> = vec![Vec::new(); pos.len()];
    for h in 0..nh {
        out[from(h)].push(h);
    }
    let ang = |h: usize| {
        let v = pos[to(h)] - pos[from(h)];
        v.y.atan2(v.x)
    };
    for o in out.iter_mut() {
        o.sort_by(|&a, &b| ang(a).total_cmp(&ang(b)));
    }
    let next = |h: usize| -> usize {
        let v = to(h);
        let o = &out[v];
        let twin = h ^ 1;
        let i = o.iter().position(|&x| x == twin).unwrap_or(0);
        o[(i + o.len() - 1) % o.len()]
    };
    let sheet_side = |h: usize| edges[h / 2].2.is_some() || h % 2 == 0;
    let mut face_of = vec![usize::MAX; nh];
    let mut faces: Vec<Vec<usize>> = Vec::new();
    for h0 in 0..nh {
        if face_of[h0] != usize::MAX || !sheet_side(h0) {
            continue;
        }
        let f = faces.len();
        let mut loop_ = Vec::new();
        let mut h = h0;
        let mut guard = 0;
        while face_of[h] == usize::MAX {
            face_of[h] = f;
            loop_.push(h);
            h = next(h);
            guard += 1;
            if guard > nh {
                break;
            }
        }
        if h != h0 {
            return Err(GeodesicError::Mesh(
                "the rulings and the outline do not make a valid subdivision of the sheet (rulings meeting on the outline?)"
                    .into(),
            ));
        }
        faces.push(loop_);
    }
    // Region transforms, breadth first from the face holding the first piece's start.
    let first_fold = rulings
        .iter()
        .filter(|r| r.piece == Some(0))
        .map(|r| r.s)
        .next()
        .unwrap_or(flats[0].len());
    let probe = flats[0]
        .at((0.5 * first_fold).min(1e-3 * first_fold.max(1.0)))
        .p;
    let face_poly = |f: usize| -> Vec<DVec2> { faces[f].iter().map(|&h| pos[from(h)]).collect() };
    let root = (0..faces.len())
        .find(|&f| polygon::contains(&face_poly(f), probe))
        .unwrap_or(0);
    let maps: Vec<DAffine3> = rulings
        .iter()
        .map(|r| fold_map(r.point, r.dir, r.angle))
        .collect();
    let forward_left: Vec<bool> = rulings
        .iter()
        .map(|r| {
            let line_dir = match r.piece {
                Some(p) => flats[p].at(r.s).t,
                None => r.dir.perp(),
            };
            r.dir.perp_dot(line_dir) > 0.0
        })
        .collect();
    let mut xf: Vec<Option<DAffine3>> = vec![None; faces.len()];
    xf[root] = Some(place);
    let mut queue = VecDeque::from([root]);
    while let Some(f) = queue.pop_front() {
        let Some(m) = xf[f] else { continue };
        for &h in &faces[f] {
            let g = face_of[h ^ 1];
            if g == usize::MAX || xf[g].is_some() {
                continue;
            }
            let mg = match edges[h / 2].2 {
                None => m,
                Some(ri) => {
                    let r = &rulings[ri];
                    let along = (pos[to(h)] - pos[from(h)]).dot(r.dir) > 0.0;
                    // Face f lies left of h; f is on the ruling's left iff h runs along it.
                    let f_forward = along == forward_left[ri];
                    if f_forward {
                        m * maps[ri].inverse()
                    } else {
                        m * maps[ri]
                    }
                }
            };
            xf[g] = Some(mg);
            queue.push_back(g);
        }
    }
    // Vertices and triangles.
    let mut vert3 = vec![DVec3::NAN; pos.len()];
    let mut triangles = Vec::new();
    for (f, lp) in faces.iter().enumerate() {
        let m = xf[f].ok_or_else(|| {
            GeodesicError::Mesh("a part of the sheet is not connected to the rest".into())
        })?;
        let ids: Vec<usize> = lp.iter().map(|&h| from(h)).collect();
        for &v in &ids {
            if vert3[v].is_nan() {
                vert3[v] = m.transform_point3(DVec3::new(pos[v].x, pos[v].y, 0.0));
            }
        }
        let poly: Vec<DVec2> = ids.iter().map(|&v| pos[v]).collect();
        if polygon::signed_area(&poly) <= 1e-12 {
            continue;
        }
        for t in polygon::triangulate(&poly) {
            let tri = [ids[t[0]], ids[t[1]], ids[t[2]]];
            let area = (pos[tri[1]] - pos[tri[0]]).perp_dot(pos[tri[2]] - pos[tri[0]]);
            if area > 1e-12 {
                triangles.push(tri);
            }
        }
    }
    // Every triangle must be the flat one moved rigidly; rulings meeting where the checks
    // above do not look (around holes, in concave corners) would break that.
    for t in &triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let (l2, l3) = (pos[a].distance(pos[b]), vert3[a].distance(vert3[b]));
            let err = (l3 - l2).abs();
            if err.is_nan() || err > 1e-7 * l2.max(1.0) {
                return Err(GeodesicError::Mesh(format!(
                    "the rulings cross on the sheet near ({:.2}, {:.2}): the sheet cannot bend this way without creasing; bend less there",
                    pos[a].x, pos[a].y
                )));
            }
        }
    }
    // Keep only used vertices.
    let mut remap = vec![usize::MAX; pos.len()];
    let mut vertices = Vec::new();
    let mut flat = Vec::new();
    for t in &triangles {
        for &v in t {
            if remap[v] == usize::MAX {
                remap[v] = vertices.len();
                vertices.push(vert3[v]);
                flat.push(pos[v]);
            }
        }
    }
    let mesh = Mesh {
        vertices,
        faces: triangles
            .iter()
            .map(|t| Face {
                verts: t.iter().map(|&v| remap[v]).collect(),
                line: None,
            })
            .collect(),
    };
    for r in rulings.iter_mut() {
        r.edges = r
            .edges
            .iter()
            .filter(|e| remap[e[0]] != usize::MAX && remap[e[1]] != usize::MAX)
            .map(|e| [remap[e[0]], remap[e[1]]])
            .collect();
        if let Some(e) = r.edges.first() {
            r.dir_3d = (mesh.vertices[e[1]] - mesh.vertices[e[0]]).normalize_or_zero();
        }
    }
    let bends = pick_bends(&rulings, &forward_left, spec.bend_lines);
    Ok(Bent {
        mesh,
        flat,
        rulings,
        bends,
        lengths,
        drifts,
        warnings,
    })
}

/// Signed fold angle in degrees: positive for a mountain seen from the printed side (+z).
fn signed_deg(r: &Ruling, forward_left: bool) -> f64 {
    // The sheet just beyond the ruling, turned by the fold, goes below the printed side's
    // plane for a mountain.
    let m = if forward_left {
        r.dir.perp()
    } else {
        -r.dir.perp()
    };
    let rot = glam::DQuat::from_axis_angle(DVec3::new(r.dir.x, r.dir.y, 0.0), r.angle);
    let z = (rot * DVec3::new(m.x, m.y, 0.0)).z;
    let deg = r.angle.to_degrees();
    if z < 0.0 {
        deg
    } else {
        -deg
    }
}

/// Bend lines as `lines` asks, from the rulings of the pieces in order along their lines.
fn pick_bends(rulings: &[Ruling], forward_left: &[bool], lines: BendLines) -> Vec<Bend> {
    const EPS_DEG: f64 = 0.01;
    let mut out = Vec::new();
    let mut acc = 0.0;
    let mut last: Option<(usize, f64)> = None;
    let mut pending: Option<usize> = None;
    for (r, &fl) in rulings.iter().zip(forward_left) {
        let Some(piece) = r.piece else { continue };
        let deg = signed_deg(r, fl);
        let push = |out: &mut Vec<Bend>, angle: f64| {
            for e in &r.edges {
                out.push(Bend {
                    verts: *e,
                    angle_deg: angle,
                });
            }
        };
        match lines {
            BendLines::None => {}
            BendLines::All => {
                if deg.abs() > EPS_DEG {
                    push(&mut out, deg);
                }
            }
            BendLines::Spacing(sp) => {
                // A new piece starts its own count.
                if last.is_some_and(|(p, _)| p != piece) {
                    if let Some(i) = pending.take() {
                        add_to_last(&mut out, i, acc);
                    }
                    acc = 0.0;
                    last = None;
                }
                acc += deg;
                let due = last.is_none_or(|(_, s)| r.s - s >= sp);
                if due && deg.abs() > EPS_DEG && !r.edges.is_empty() {
                    pending = Some(out.len());
                    push(&mut out, acc);
                    acc = 0.0;
                    last = Some((piece, r.s));
                }
            }
        }
    }
    if let Some(i) = pending {
        add_to_last(&mut out, i, acc);
    }
    out
}

/// Add `deg` to the bend lines from index `i` on (the segments of one ruling).
fn add_to_last(out: &mut [Bend], i: usize, deg: f64) {
    for b in out.iter_mut().skip(i) {
        b.angle_deg += deg;
    }
}
