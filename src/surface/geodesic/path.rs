//! The curve drawn on the flat sheet (§5: a line for a geodesic, else a planar curve whose
//! signed curvature is the geodesic curvature to keep): a straight line, a circular arc, or a
//! Bézier / B-spline in the sheet's plane, evaluated by arc length as position, unit tangent and
//! signed curvature (> 0 turning left, seen from the printed side).

use super::spline::{ArcLength, Param, Spline};
use glam::DVec2;

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
pub(super) enum Flat<'a> {
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
pub(super) struct FlatPoint {
    pub(super) p: DVec2,
    pub(super) t: DVec2,
    pub(super) c: f64,
}

impl<'a> Flat<'a> {
    pub(super) fn new(path: &'a FlatPath) -> Flat<'a> {
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

    pub(super) fn len(&self) -> f64 {
        match self {
            Flat::Line { len, .. } | Flat::Arc { len, .. } => *len,
            Flat::Curve { arc, .. } => arc.total(),
        }
    }

    /// A straight line: no geodesic curvature anywhere.
    pub(super) fn straight(&self) -> bool {
        matches!(self, Flat::Line { .. })
    }

    pub(super) fn at(&self, s: f64) -> FlatPoint {
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
