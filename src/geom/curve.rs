//! Boundary curves for strips (issue 4, item 2): inline point lists, CSV files, circles,
//! ellipses, rectangles with optional corner radius, Bézier and B-spline curves, each sampled
//! into a [`Polyline`] whose chords stay within a chordal tolerance (default
//! [`DEFAULT_TOLERANCE`], 0.05 mm) of the curve.
//!
//! Wang & Tang (seed 003, §4) only say that P and Q are "uniformly distributed or sampled
//! adaptively according to a user specified approximation tolerance"; the choices here:
//!
//! - Circles, ellipses and rectangles lie in the plane `z = center.z`, run counter-clockwise seen
//!   from +z and start on the +x axis (a rectangle at the middle of its +x side). Every quadrant
//!   point (angles 0°, 90°, 180°, 270°) is a sample, so that the flat triangles of a
//!   square-to-round end exactly on the circle's tangent points; a circle has a multiple of four
//!   samples, equally spaced (`N = ⌈π / acos(1 − tol/r)⌉`, rounded up to a multiple of 4, at
//!   least 8). A rectangle keeps the midpoints of its four sides as samples (the seam of a duct
//!   is usually put there); its corner arcs are sampled like circles.
//! - Ellipses, Bézier and B-spline curves are subdivided recursively in their parameter until the
//!   distance of the parameter midpoint and of the two quarter points from the chord is within
//!   the tolerance (quarter points too, so that an S-shaped span is not mistaken for a straight
//!   one); at most 2^20 spans per starting interval.
//! - A Bézier curve is one curve of degree `len − 1` through its first and last control point
//!   (de Casteljau). A B-spline is uniform, of degree `degree` (default 3, lowered to
//!   `len − 1` when there are fewer control points); open ones are clamped (they start and end
//!   at the first and last control point), closed ones are periodic. Samples are evaluated by
//!   de Boor's algorithm; [`bspline_derivatives`] gives position and three derivatives of an
//!   open one on the same knots ([`clamped_knots`], Piegl & Tiller A2.3) for the control curves
//!   of bent sheets.
//! - Point lists and CSV files are taken as given, except that consecutive duplicates (closer
//!   than 1e-9 mm) are dropped, and for a closed curve a last point equal to the first.
//! - CSV: one point per line, `x,y` or `x,y,z` (commas, semicolons, tabs or spaces between
//!   numbers); blank lines and lines starting with `#` are skipped, and so is a first line that
//!   is not numeric (a header). Errors name the file and line.

use glam::DVec3;
use std::path::{Path, PathBuf};

/// Default chordal tolerance (mm).
pub const DEFAULT_TOLERANCE: f64 = 0.05;

/// A curve as described in a spec or built by a fitting.
#[derive(Debug, Clone, PartialEq)]
pub enum Curve {
    /// Points as given.
    Points {
        points: Vec<DVec3>,
        closed: bool,
    },
    /// Points read from a CSV file.
    Csv {
        path: PathBuf,
        closed: bool,
    },
    Circle {
        center: DVec3,
        radius: f64,
    },
    /// Axis-aligned ellipse: semi-axes along x and y.
    Ellipse {
        center: DVec3,
        rx: f64,
        ry: f64,
    },
    /// Axis-aligned rectangle, `width` along x, `height` along y.
    Rect {
        center: DVec3,
        width: f64,
        height: f64,
        corner_radius: f64,
    },
    /// One Bézier curve through its first and last control points.
    Bezier {
        control: Vec<DVec3>,
    },
    BSpline {
        control: Vec<DVec3>,
        degree: usize,
        closed: bool,
    },
}

/// A sampled curve; a closed one does not repeat its first point.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    pub points: Vec<DVec3>,
    pub closed: bool,
}

/// What can be wrong with a curve. The caller adds which curve (spec key or flag).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CurveError {
    #[error("needs at least {need} distinct points, got {got}")]
    TooFewPoints { need: usize, got: usize },
    #[error("`{what}` must be a positive finite number of millimetres, got {value}")]
    NotPositive { what: &'static str, value: f64 },
    #[error("a point has a coordinate that is not a finite number")]
    NonFinite,
    #[error(
        "corner radius {radius} mm is more than half the rectangle's shorter side ({half} mm)"
    )]
    CornerRadius { radius: f64, half: f64 },
    #[error("{}: cannot read: {message}", path.display())]
    Io { path: PathBuf, message: String },
    #[error("{}:{line}: {message}", path.display())]
    Csv {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("chordal tolerance must be a positive number of millimetres, got {0}")]
    Tolerance(f64),
}

impl Curve {
    /// Whether the curve is a closed loop.
    pub fn is_closed(&self) -> bool {
        match self {
            Curve::Points { closed, .. }
            | Curve::Csv { closed, .. }
            | Curve::BSpline { closed, .. } => *closed,
            Curve::Circle { .. } | Curve::Ellipse { .. } | Curve::Rect { .. } => true,
            Curve::Bezier { .. } => false,
        }
    }

    /// Sample the curve so that every chord is within `tol` mm of it.
    pub fn sample(&self, tol: f64) -> Result<Polyline, CurveError> {
        if !(tol.is_finite() && tol > 0.0) {
            return Err(CurveError::Tolerance(tol));
        }
        let closed = self.is_closed();
        let pts = match self {
            Curve::Points { points, .. } => {
                finite(points)?;
                points.clone()
            }
            Curve::Csv { path, .. } => read_csv(path)?,
            Curve::Circle { center, radius } => {
                positive("radius", *radius)?;
                let n = circle_segments(*radius, tol, 4);
                (0..n)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / n as f64;
                        *center + DVec3::new(radius * a.cos(), radius * a.sin(), 0.0)
                    })
                    .collect()
            }
            Curve::Ellipse { center, rx, ry } => {
                positive("rx", *rx)?;
                positive("ry", *ry)?;
                let c = *center;
                let f = |t: f64| c + DVec3::new(rx * t.cos(), ry * t.sin(), 0.0);
                let q = std::f64::consts::FRAC_PI_2;
                let mut out = Vec::new();
                for k in 0..4 {
                    adaptive(&f, k as f64 * q, (k + 1) as f64 * q, tol, &mut out);
                }
                out
            }
            Curve::Rect {
                center,
                width,
                height,
                corner_radius,
            } => rect(*center, *width, *height, *corner_radius, tol)?,
            Curve::Bezier { control } => {
                finite(control)?;
                if control.len() < 2 {
                    return Err(CurveError::TooFewPoints {
                        need: 2,
                        got: control.len(),
                    });
                }
                let f = |t: f64| de_casteljau(control, t);
                let mut out = Vec::new();
                adaptive(&f, 0.0, 1.0, tol, &mut out);
                out.push(f(1.0));
                out
            }
            Curve::BSpline {
                control,
                degree,
                closed,
            } => {
                finite(control)?;
                let need = if *closed { 3 } else { 2 };
                if control.len() < need {
                    return Err(CurveError::TooFewPoints {
                        need,
                        got: control.len(),
                    });
                }
                bspline(control, *degree, *closed, tol)
            }
        };
        let points = dedup(pts, closed);
        let need = if closed { 3 } else { 2 };
        if points.len() < need {
            return Err(CurveError::TooFewPoints {
                need,
                got: points.len(),
            });
        }
        Ok(Polyline { points, closed })
    }
}

fn positive(what: &'static str, value: f64) -> Result<(), CurveError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(CurveError::NotPositive { what, value })
    }
}

fn finite(points: &[DVec3]) -> Result<(), CurveError> {
    if points.iter().all(|p| p.is_finite()) {
        Ok(())
    } else {
        Err(CurveError::NonFinite)
    }
}

/// Drop consecutive duplicates (and, closed, a last point equal to the first).
fn dedup(pts: Vec<DVec3>, closed: bool) -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::with_capacity(pts.len());
    for p in pts {
        if out.last().is_none_or(|q| q.distance(p) > 1e-9) {
            out.push(p);
        }
    }
    if closed {
        while out.len() > 1 && out[0].distance(out[out.len() - 1]) <= 1e-9 {
            out.pop();
        }
    }
    out
}

/// Segments of a full circle of radius `r` within `tol`, a multiple of `multiple`, at least 8.
pub fn circle_segments(r: f64, tol: f64, multiple: usize) -> usize {
    let c = (1.0 - tol / r).clamp(-1.0, 1.0);
    let n = if c <= -1.0 {
        8.0
    } else {
        (std::f64::consts::PI / c.acos()).ceil()
    };
    let n = (n.min(1e7) as usize).max(8);
    n.div_ceil(multiple) * multiple
}

/// Distance from `p` to the segment `a b`.
fn seg_dist(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    super::segment::point_segment_dist2(p, a, b).sqrt()
}

/// Samples of `f` on `[t0, t1)` (the end point is left to the next span).
fn adaptive(f: &impl Fn(f64) -> DVec3, t0: f64, t1: f64, tol: f64, out: &mut Vec<DVec3>) {
    #[allow(clippy::too_many_arguments)]
    fn go(
        f: &impl Fn(f64) -> DVec3,
        t0: f64,
        t1: f64,
        a: DVec3,
        b: DVec3,
        tol: f64,
        depth: u32,
        out: &mut Vec<DVec3>,
    ) {
        let tm = 0.5 * (t0 + t1);
        let m = f(tm);
        let ok = depth >= 20
            || (seg_dist(m, a, b) <= tol
                && seg_dist(f(0.5 * (t0 + tm)), a, b) <= tol
                && seg_dist(f(0.5 * (tm + t1)), a, b) <= tol);
        if ok {
            out.push(a);
        } else {
            go(f, t0, tm, a, m, tol, depth + 1, out);
            go(f, tm, t1, m, b, tol, depth + 1, out);
        }
    }
    go(f, t0, t1, f(t0), f(t1), tol, 0, out);
}

fn de_casteljau(control: &[DVec3], t: f64) -> DVec3 {
    let mut pts = control.to_vec();
    let n = pts.len();
    for r in 1..n {
        for i in 0..n - r {
            pts[i] = pts[i].lerp(pts[i + 1], t);
        }
    }
    pts[0]
}

/// de Boor evaluation of a B-spline with knot vector `knots` at `t` in span `k`.
fn de_boor(control: &[DVec3], knots: &[f64], p: usize, k: usize, t: f64) -> DVec3 {
    let mut d: Vec<DVec3> = (0..=p).map(|j| control[j + k - p]).collect();
    for r in 1..=p {
        for j in (r..=p).rev() {
            let i = j + k - p;
            let den = knots[i + 1 + p - r] - knots[i];
            let a = if den.abs() > 0.0 {
                (t - knots[i]) / den
            } else {
                0.0
            };
            d[j] = d[j - 1].lerp(d[j], a);
        }
    }
    d[p]
}

/// Uniform clamped knots of an open B-spline with `n` control points: the degree used
/// (`degree`, lowered to `n − 1` when there are too few points) and the knots `0 … 0, 1, 2, …,
/// n − p … n − p`, each end repeated `p + 1` times.
pub fn clamped_knots(n: usize, degree: usize) -> (usize, Vec<f64>) {
    let p = degree.clamp(1, n.saturating_sub(1).max(1));
    let inner = n.saturating_sub(p).max(1); // number of spans
    let mut knots = vec![0.0; p + 1];
    knots.extend((1..inner).map(|i| i as f64));
    knots.extend(std::iter::repeat_n(inner as f64, p + 1));
    (p, knots)
}

/// Position and first, second and third derivatives of a B-spline of degree `p` with knot
/// vector `knots` at `u` (clamped to its last span at the end): the basis derivatives of
/// Piegl & Tiller's algorithm A2.3 times the control points. Derivatives above `p` are zero.
pub fn bspline_derivatives(control: &[DVec3], p: usize, knots: &[f64], u: f64) -> [DVec3; 4] {
    let k = span(control.len(), p, knots, u);
    let nd = 3.min(p);
    let ders = ders_basis(k, u, p, nd, knots);
    let mut out = [DVec3::ZERO; 4];
    for (o, row) in out.iter_mut().zip(&ders) {
        for (c, w) in control[k - p..=k].iter().zip(row) {
            *o += *c * *w;
        }
    }
    out
}

/// The knot span holding `u` of a B-spline with `len` control points.
fn span(len: usize, p: usize, knots: &[f64], u: f64) -> usize {
    let n = len - 1;
    if u >= knots[n + 1] {
        return n;
    }
    let mut k = p;
    while k < n && u >= knots[k + 1] {
        k += 1;
    }
    k
}

/// Basis function derivatives (Piegl & Tiller, The NURBS Book, algorithm A2.3).
pub(crate) fn ders_basis(i: usize, u: f64, p: usize, n: usize, knots: &[f64]) -> Vec<Vec<f64>> {
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

fn bspline(control: &[DVec3], degree: usize, closed: bool, tol: f64) -> Vec<DVec3> {
    let mut out = Vec::new();
    if closed {
        // Periodic: wrap the first `p` control points; uniform knots.
        let p = degree.clamp(1, control.len() - 1);
        let mut c = control.to_vec();
        c.extend_from_slice(&control[..p]);
        let knots: Vec<f64> = (0..c.len() + p + 1).map(|i| i as f64).collect();
        for k in p..c.len() {
            let f = |t: f64| de_boor(&c, &knots, p, k, t);
            adaptive(&f, knots[k], knots[k + 1], tol, &mut out);
        }
    } else {
        let n = control.len();
        let (p, knots) = clamped_knots(n, degree);
        for k in p..n {
            let f = |t: f64| de_boor(control, &knots, p, k, t);
            adaptive(&f, knots[k], knots[k + 1], tol, &mut out);
        }
        out.push(control[n - 1]);
    }
    out
}

/// Quarter-arc samples from angle `a0` (radians) counter-clockwise, end excluded.
fn arc(c: DVec3, r: f64, a0: f64, tol: f64, out: &mut Vec<DVec3>) {
    let n = circle_segments(r, tol, 4) / 4;
    for k in 0..n {
        let a = a0 + std::f64::consts::FRAC_PI_2 * k as f64 / n as f64;
        out.push(c + DVec3::new(r * a.cos(), r * a.sin(), 0.0));
    }
}

fn rect(c: DVec3, w: f64, h: f64, r: f64, tol: f64) -> Result<Vec<DVec3>, CurveError> {
    positive("width", w)?;
    positive("height", h)?;
    if !(r.is_finite() && r >= 0.0) {
        return Err(CurveError::NotPositive {
            what: "corner_radius",
            value: r,
        });
    }
    let half = 0.5 * w.min(h);
    if r > half {
        return Err(CurveError::CornerRadius { radius: r, half });
    }
    let (hx, hy) = (0.5 * w, 0.5 * h);
    let mut out = Vec::new();
    // Side midpoints, then each corner (a point, or a quarter arc), counter-clockwise from +x.
    let corners = [(hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy)];
    let mids = [(hx, 0.0), (0.0, hy), (-hx, 0.0), (0.0, -hy)];
    for k in 0..4 {
        out.push(c + DVec3::new(mids[k].0, mids[k].1, 0.0));
        let (x, y) = corners[k];
        if r > 0.0 {
            let cc = c + DVec3::new(x - x.signum() * r, y - y.signum() * r, 0.0);
            arc(cc, r, k as f64 * std::f64::consts::FRAC_PI_2, tol, &mut out);
            let a1 = (k + 1) as f64 * std::f64::consts::FRAC_PI_2;
            out.push(cc + DVec3::new(r * a1.cos(), r * a1.sin(), 0.0));
        } else {
            out.push(c + DVec3::new(x, y, 0.0));
        }
    }
    Ok(out)
}

/// Points of a CSV file (see the module doc for the format).
pub fn read_csv(path: &Path) -> Result<Vec<DVec3>, CurveError> {
    let text =
        super::input::read_text(path, super::input::TEXT_LIMIT).map_err(|e| CurveError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let mut out = Vec::new();
    let mut first = true;
    for (k, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = t
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        let nums: Result<Vec<f64>, _> = fields.iter().map(|s| s.parse::<f64>()).collect();
        let err = |message: String| CurveError::Csv {
            path: path.to_path_buf(),
            line: k + 1,
            message,
        };
        match nums {
            Err(_) if first => {
                first = false;
                continue; // a header
            }
            Err(_) => {
                // Name the field, never echo it: the file may not be a CSV at all.
                let bad = fields
                    .iter()
                    .position(|s| s.parse::<f64>().is_err())
                    .unwrap_or(0);
                return Err(err(format!(
                    "expected numbers `x,y[,z]`; field {} of {} is not a number",
                    bad + 1,
                    fields.len()
                )));
            }
            Ok(v) if v.len() == 2 || v.len() == 3 => {
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(err("a coordinate is not a finite number".into()));
                }
                out.push(DVec3::new(v[0], v[1], v.get(2).copied().unwrap_or(0.0)));
            }
            Ok(v) => {
                return Err(err(format!(
                    "expected 2 or 3 numbers (x,y[,z]), got {}",
                    v.len()
                )))
            }
        }
        first = false;
    }
    Ok(out)
}

/// Length of a polyline (closing segment included when closed).
pub fn length(p: &Polyline) -> f64 {
    let mut l: f64 = p.points.windows(2).map(|w| w[0].distance(w[1])).sum();
    if p.closed && p.points.len() > 2 {
        l += p.points[p.points.len() - 1].distance(p.points[0]);
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    fn max_dev(pl: &Polyline, exact: impl Fn(DVec3) -> f64) -> f64 {
        // Deviation of chord midpoints from the exact curve (implicit distance).
        let n = pl.points.len();
        (0..n)
            .filter(|&i| pl.closed || i + 1 < n)
            .map(|i| exact(0.5 * (pl.points[i] + pl.points[(i + 1) % n])))
            .fold(0.0, f64::max)
    }

    #[test]
    fn strip_curve_circle_is_within_tolerance_with_quadrant_points() {
        let c = Curve::Circle {
            center: DVec3::new(1.0, 2.0, 3.0),
            radius: 125.0,
        };
        let pl = c.sample(0.05).unwrap();
        assert_eq!(pl.points.len() % 4, 0);
        let dev = max_dev(&pl, |p| {
            (125.0 - (p - DVec3::new(1.0, 2.0, 3.0)).length()).abs()
        });
        assert!(dev <= 0.05 && dev > 0.02, "dev {dev}");
        let q = pl.points[pl.points.len() / 4];
        assert!((q - DVec3::new(1.0, 127.0, 3.0)).length() < 1e-9);
    }

    #[test]
    fn strip_curve_ellipse_and_rect_within_tolerance() {
        let e = Curve::Ellipse {
            center: DVec3::ZERO,
            rx: 200.0,
            ry: 50.0,
        }
        .sample(0.05)
        .unwrap();
        // Exact distance is awkward; sample the true ellipse finely and compare.
        let dense: Vec<DVec3> = (0..20000)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 20000.0;
                DVec3::new(200.0 * t.cos(), 50.0 * t.sin(), 0.0)
            })
            .collect();
        let dev = max_dev(&e, |p| {
            dense.iter().map(|q| q.distance(p)).fold(f64::MAX, f64::min)
        });
        assert!(dev <= 0.055, "ellipse dev {dev}");
        let r = Curve::Rect {
            center: DVec3::ZERO,
            width: 400.0,
            height: 300.0,
            corner_radius: 0.0,
        }
        .sample(0.05)
        .unwrap();
        assert_eq!(r.points.len(), 8);
        assert!((length(&r) - 1400.0).abs() < 1e-9);
        let rr = Curve::Rect {
            center: DVec3::ZERO,
            width: 400.0,
            height: 300.0,
            corner_radius: 20.0,
        }
        .sample(0.05)
        .unwrap();
        let exact = 1400.0 - 8.0 * 20.0 + std::f64::consts::TAU * 20.0;
        assert!(
            (length(&rr) - exact).abs() / exact < 1e-4,
            "{}",
            length(&rr)
        );
    }

    #[test]
    fn strip_curve_bezier_and_bspline_end_points_and_errors() {
        let ctl = vec![
            DVec3::ZERO,
            DVec3::new(100.0, 100.0, 0.0),
            DVec3::new(200.0, -100.0, 0.0),
            DVec3::new(300.0, 0.0, 50.0),
        ];
        let b = Curve::Bezier {
            control: ctl.clone(),
        }
        .sample(0.05)
        .unwrap();
        assert_eq!(b.points[0], ctl[0]);
        assert!(b.points.last().unwrap().distance(ctl[3]) < 1e-12);
        let s = Curve::BSpline {
            control: ctl.clone(),
            degree: 3,
            closed: false,
        }
        .sample(0.05)
        .unwrap();
        // Clamped cubic on 4 points is the Bézier curve.
        assert!(
            (length(&s) - length(&b)).abs() < 0.05,
            "{} {}",
            length(&s),
            length(&b)
        );
        assert!(matches!(
            Curve::Points {
                points: vec![DVec3::ZERO],
                closed: false
            }
            .sample(0.05),
            Err(CurveError::TooFewPoints { .. })
        ));
        assert!(matches!(
            Curve::Circle {
                center: DVec3::ZERO,
                radius: 0.0
            }
            .sample(0.05),
            Err(CurveError::NotPositive { .. })
        ));
    }
}
