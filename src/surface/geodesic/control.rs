//! A piece's control curve (§4.1): Bézier or B-spline control points from the spec, or two
//! control handles (§4.1.2, eq. 7), checked and made into a [`Param`] with the hint for the
//! surface normal's side; and the frame quantities along it (tangent, curvature vector,
//! torsion, Darboux vector, §3.1).
//!
//! Handles (§4.1.2, eq. 7): a quartic Bézier through the two end points whose end principal
//! normals are fitted to the given ones by Levenberg–Marquardt on
//! `|N0/|N0| − N̄0|² + |N1/|N1| − N̄1|² + (len/L − 1)² + 0.1·|ΔX/L|²` from a start polygon
//! with end tangents perpendicular to the normals (the length term is ours: it keeps the
//! re-parameterisation small). A normal missed by more than 1° is a warning, and so is an end
//! that the length fit moves more than the tolerance away from its handle (handles whose
//! normals do not suit the sheet's length cannot all be met).

use super::spline::{gl, ArcLength, Param, Spline};
use super::{Control, GeodesicError, PieceSpec};
use crate::geom::curve::Curve;
use glam::DVec3;

/// Frame quantities at one point: unit tangent, curvature vector `dT/ds`, torsion and
/// the Darboux vector `τT + T × K`.
pub(super) struct Local {
    pub(super) t: DVec3,
    pub(super) k: DVec3,
    pub(super) omega: DVec3,
}

pub(super) fn local(c: &dyn Param, u: f64) -> Option<Local> {
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

/// Principal normals at both ends of a Bézier curve from its control points (§4.1.2; the
/// positive factor λ = n³(n − 1) is left out, only directions are used).
pub(super) fn end_normals(c: &[DVec3]) -> (DVec3, DVec3) {
    let n = c.len() - 1;
    let (t0, a0) = (c[1] - c[0], c[2] - 2.0 * c[1] + c[0]);
    let (t1, a1) = (c[n] - c[n - 1], c[n] - 2.0 * c[n - 1] + c[n - 2]);
    (t0.cross(a0).cross(t0), t1.cross(a1).cross(t1))
}

pub(super) fn bezier_length(c: &[DVec3]) -> f64 {
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
pub(super) fn solve9(mut a: [[f64; 9]; 9], mut b: [f64; 9]) -> Option<[f64; 9]> {
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

/// A piece's control curve to evaluate, the surface normal hint (handles) and warnings.
pub type ControlParam = (Box<dyn Param>, Option<DVec3>, Vec<String>);

/// The control curve of a piece as something to evaluate, and the normal hint for handles.
pub(super) fn control_param(piece: usize, spec: &PieceSpec) -> Result<ControlParam, GeodesicError> {
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
