//! Control curves as something to evaluate: a regular parametric curve with three
//! derivatives ([`Param`], what eq. 1 and the torsion need), the clamped B-spline / Bézier
//! ([`Spline`], evaluated by [`crate::geom::curve::bspline_derivatives`]), a curve scaled or
//! trimmed to the line's length, and arc length ([`ArcLength`]: five-point Gauss–Legendre
//! panels, 32 per polynomial span, inverted by Newton's method).
//!
//! Length (§4.1.3): the control curve is re-parameterised by arc length (Gauss–Legendre) and
//! fitted to the flat line's length `L`: `length_fit = "scale"` (default) scales it about its
//! first point (as the paper's tube example, §5, "preserved by scaling"); `"trim"` cuts it at
//! length `L` from its start (§4.1.3) and refuses a curve shorter than the line.

use crate::geom::curve::{bspline_derivatives, clamped_knots};
use glam::DVec3;

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
/// by [`bspline_derivatives`]. Knots are [`clamped_knots`]: uniform, clamped, degree lowered
/// to `len − 1` when there are too few control points.
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
        let (p, knots) = clamped_knots(control.len(), degree);
        Spline { control, p, knots }
    }

    pub fn control(&self) -> &[DVec3] {
        &self.control
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
        bspline_derivatives(&self.control, self.p, &self.knots, u)
    }
}

/// `inner` scaled about `origin` by `scale` and restricted to `[domain.0, end]`.
pub(super) struct Fitted<'a> {
    pub(super) inner: &'a dyn Param,
    pub(super) origin: DVec3,
    pub(super) scale: f64,
    pub(super) end: f64,
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

pub(super) const GL_X: [f64; 5] = [
    -0.906_179_845_938_664,
    -0.538_469_310_105_683,
    0.0,
    0.538_469_310_105_683,
    0.906_179_845_938_664,
];
pub(super) const GL_W: [f64; 5] = [
    0.236_926_885_056_189,
    0.478_628_670_499_366,
    0.568_888_888_888_889,
    0.478_628_670_499_366,
    0.236_926_885_056_189,
];

pub(super) fn gl(curve: &dyn Param, a: f64, b: f64) -> f64 {
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

    pub(super) fn with_panels(curve: &'a dyn Param, per_span: usize) -> Self {
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
