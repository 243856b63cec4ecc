//! B-spline curves as linear maps of their control points (issue 24; Tang, Bo, Wallner,
//! Pottmann 2016, §2.1 eq. 5): for a parameter `u` the point `a(u)` and its derivatives are
//! returned as sparse rows of weights, one weight per control point that the span touches, so
//! that a solver can use `a(u)`, `a′(u)` and `a″(u)` as linear expressions in the control
//! points (the paper's de Boor auxiliary points `a₀⁽¹⁾, a₁⁽¹⁾` span the same tangent line:
//! `a₁⁽¹⁾ − a₀⁽¹⁾` is `a′` times a positive factor, so `n ⟂ a′` is the same condition).
//!
//! Choices where the paper is silent:
//!
//! - Knots are uniform, one span per unit of parameter: a clamped curve with `count` control
//!   points has `count − degree` spans on `[0, count − degree]` and starts and ends at its first
//!   and last control point (the knots of [`super::curve::clamped_knots`]); a periodic (closed)
//!   one has `count` spans on `[0, count]`, control point indices wrap around, and it is
//!   `C^(degree−1)` across `u = 0`.
//! - Degrees 1 to 5 are accepted here (the spline surfaces use 2 to 5); a curve needs at least
//!   `degree + 1` control points.
//! - Basis values by the Cox–de Boor recursion (Piegl & Tiller A2.2), derivatives from the
//!   basis of the degrees below (the derivative formula of the B-spline basis).

use glam::DVec3;

/// A B-spline's parameter space: degree, number of control points, closed or clamped.
#[derive(Debug, Clone, PartialEq)]
pub struct BSpline {
    degree: usize,
    count: usize,
    closed: bool,
    knots: Vec<f64>,
}

/// Sparse rows of one parameter: (control point index, weight) for the point and its first
/// and second derivatives with respect to `u`.
#[derive(Debug, Clone, PartialEq)]
pub struct Rows {
    pub point: Vec<(usize, f64)>,
    pub d1: Vec<(usize, f64)>,
    pub d2: Vec<(usize, f64)>,
}

/// A B-spline that cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BSplineError {
    #[error("degree {0} is not supported (1 to 5)")]
    Degree(usize),
    #[error("{count} control points are too few for degree {degree} (at least {})", degree + 1)]
    TooFew { count: usize, degree: usize },
}

impl BSpline {
    /// The uniform B-spline space of `degree` with `count` control points.
    pub fn new(degree: usize, count: usize, closed: bool) -> Result<BSpline, BSplineError> {
        if !(1..=5).contains(&degree) {
            return Err(BSplineError::Degree(degree));
        }
        if count < degree + 1 {
            return Err(BSplineError::TooFew { count, degree });
        }
        let knots = if closed {
            // Basis i lives on [i − p, i + 1]; indices i ≥ count wrap to i − count.
            (0..count + 2 * degree + 1)
                .map(|i| i as f64 - degree as f64)
                .collect()
        } else {
            super::curve::clamped_knots(count, degree).1
        };
        Ok(BSpline {
            degree,
            count,
            closed,
            knots,
        })
    }

    pub fn degree(&self) -> usize {
        self.degree
    }
    pub fn count(&self) -> usize {
        self.count
    }
    pub fn closed(&self) -> bool {
        self.closed
    }
    /// Number of spans; the parameter runs over `[0, spans]`.
    pub fn spans(&self) -> usize {
        if self.closed {
            self.count
        } else {
            self.count - self.degree
        }
    }
    /// The knot vector (uniform; clamped ends repeated `degree + 1` times).
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Index `k` of the knot interval `[t_k, t_k+1)` holding `u` (the last span at the end).
    fn knot_span(&self, u: f64) -> usize {
        let p = self.degree;
        let s = self.spans();
        let span = if u.is_finite() {
            (u.floor().max(0.0) as usize).min(s - 1)
        } else {
            0
        };
        span + p
    }

    /// The rows of `a(u)`, `a′(u)` and `a″(u)` (clamped to the domain).
    pub fn rows(&self, u: f64) -> Rows {
        let p = self.degree;
        let u = u.clamp(0.0, self.spans() as f64);
        let k = self.knot_span(u);
        // N_{k−p..=k, p}(u) and their first two derivatives (Piegl & Tiller A2.3); above the
        // degree they are zero.
        let ders = super::curve::ders_basis(k, u, p, 2.min(p), &self.knots);
        let zero = vec![0.0; p + 1];
        let (d1, d2) = (&ders[1], ders.get(2).unwrap_or(&zero));
        let index = |j: usize| {
            let i = k + j - p;
            if self.closed {
                i % self.count
            } else {
                i
            }
        };
        let row = |w: &[f64]| -> Vec<(usize, f64)> { (0..=p).map(|j| (index(j), w[j])).collect() };
        Rows {
            point: row(&ders[0]),
            d1: row(d1),
            d2: row(d2),
        }
    }

    /// `a(u)` for control points `ctrl` (which must have [`BSpline::count`] entries).
    pub fn eval(&self, ctrl: &[DVec3], u: f64) -> DVec3 {
        apply(&self.rows(u).point, ctrl)
    }

    /// `a′(u)`.
    pub fn deriv(&self, ctrl: &[DVec3], u: f64) -> DVec3 {
        apply(&self.rows(u).d1, ctrl)
    }
}

/// A row applied to points: `Σ w · p[i]`.
pub fn apply(row: &[(usize, f64)], p: &[DVec3]) -> DVec3 {
    row.iter().map(|&(i, w)| p[i] * w).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctrl(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let t = i as f64;
                DVec3::new(t * 10.0, (t * 1.3).sin() * 20.0, (t * 0.7).cos() * 5.0)
            })
            .collect()
    }

    #[test]
    fn clamped_agrees_with_curve_derivatives() {
        for p in 2..=5 {
            let c = ctrl(9);
            let s = BSpline::new(p, 9, false).unwrap();
            for i in 0..=40 {
                let u = s.spans() as f64 * i as f64 / 40.0;
                let d = crate::geom::curve::bspline_derivatives(&c, p, s.knots(), u);
                let r = s.rows(u);
                assert!((apply(&r.point, &c) - d[0]).length() < 1e-9, "p={p} u={u}");
                assert!((apply(&r.d1, &c) - d[1]).length() < 1e-9, "p={p} u={u}");
                assert!((apply(&r.d2, &c) - d[2]).length() < 1e-8, "p={p} u={u}");
            }
            assert!((s.eval(&c, 0.0) - c[0]).length() < 1e-12);
            assert!((s.eval(&c, s.spans() as f64) - c[8]).length() < 1e-12);
        }
    }

    #[test]
    fn periodic_closes_smoothly_and_derivative_matches_differences() {
        for p in 2..=5 {
            let c = ctrl(8);
            let s = BSpline::new(p, 8, true).unwrap();
            let end = s.spans() as f64;
            assert!((s.eval(&c, 0.0) - s.eval(&c, end)).length() < 1e-9);
            assert!((s.deriv(&c, 0.0) - s.deriv(&c, end)).length() < 1e-9);
            for i in 0..50 {
                let u = end * (i as f64 + 0.37) / 50.0;
                let r = s.rows(u);
                let sum: f64 = r.point.iter().map(|x| x.1).sum();
                assert!((sum - 1.0).abs() < 1e-12, "partition of unity");
                let h = 1e-6;
                let fd = (s.eval(&c, u + h) - s.eval(&c, u - h)) / (2.0 * h);
                assert!((fd - apply(&r.d1, &c)).length() < 1e-5, "p={p} u={u}");
                let fd2 = (s.deriv(&c, u + h) - s.deriv(&c, u - h)) / (2.0 * h);
                assert!((fd2 - apply(&r.d2, &c)).length() < 1e-4, "p={p} u={u}");
            }
        }
    }

    #[test]
    fn refuses_bad_degree_and_count() {
        assert_eq!(BSpline::new(6, 10, false), Err(BSplineError::Degree(6)));
        assert!(matches!(
            BSpline::new(3, 3, true),
            Err(BSplineError::TooFew { .. })
        ));
    }
}
