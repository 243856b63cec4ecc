//! Isometry to a prescribed flat domain (Tang et al. 2016, §5, eq. 12): a development V̄ of a
//! mesh V sampled on the curves is kept as unknowns beside the control points, with
//! ‖vᵢ − vⱼ‖² = ‖v̄ᵢ − v̄ⱼ‖² for the four edges and two diagonals of every quad, the
//! development's boundary vertices kept on the outline (linearised on the tangent at their
//! footpoint, updated every iteration), its corners fixed in the outline's corners, and the
//! vertices of every crease with a condition kept on that crease as drawn on the flat sheet.
//!
//! Choices where the paper is silent:
//!
//! - The sheet starts flat: the curves as given lie in the plane z = 0 of the outline's
//!   coordinates, and V̄ starts as V's (x, y). The flat creases are the creases as given.
//! - V samples every curve at 4 parameters per span (ends included); a vertex is a linear
//!   expression in the control points (the paper's relation (5)).
//! - Eq. 12 is divided by 2‖vᵢ − vⱼ‖ at the current iterate, so its residual is a length
//!   difference; the outline and crease rows are distances; all weigh 1.
//! - Boundary vertices: all of the first and last curve and the ends of every curve (an open
//!   sheet); a vertex that starts within 1e-9 (scaled) of an outline corner stays in it.
//! - The fairness against overfolding is the second differences of V̄ along each curve, held
//!   at their start values with ε₁ (like the control polygons' fairness).

use super::system::{eval, Expr, Row};
use crate::geom::bspline::BSpline;
use glam::{DVec2, DVec3};

/// Parameters per span of the development mesh.
const PER_SPAN: usize = 4;

/// The development's unknowns and conditions (in the solver's scaled frame).
pub(super) struct Dev {
    /// Each mesh vertex as an expression over the model's points.
    verts: Vec<Expr>,
    /// Offset of v̄₀ in the unknowns (two per vertex).
    base: usize,
    /// Vertex pairs of eq. 12.
    pairs: Vec<(usize, usize)>,
    /// Vertices kept on the outline, and those fixed in a corner.
    on_boundary: Vec<usize>,
    corners: Vec<(usize, DVec2)>,
    /// Vertices kept on a flat crease (vertex, crease).
    on_crease: Vec<(usize, usize)>,
    outline: Vec<DVec2>,
    creases: Vec<Vec<DVec2>>,
    /// Second differences of V̄ along the curves and their start values.
    fair: Vec<[usize; 3]>,
    fair_s: Vec<DVec2>,
    /// V̄ at the start.
    start: Vec<DVec2>,
    /// Vertices per curve (V samples every curve at the same parameters).
    per_curve: usize,
}

impl Dev {
    /// The development of `curves` (each `count` points in `points`, scaled) over `outline`
    /// (scaled, counter-clockwise or not), with the crease conditions `constrained` (one flag
    /// per curve); its unknowns start at `base`.
    pub(super) fn new(
        basis: &BSpline,
        points: &[DVec3],
        curves: usize,
        constrained: &[bool],
        outline: Vec<DVec2>,
        base: usize,
    ) -> Dev {
        let count = basis.count();
        let k = basis.spans() * PER_SPAN + 1;
        let params: Vec<f64> = (0..k).map(|i| i as f64 / PER_SPAN as f64).collect();
        let mut verts = Vec::with_capacity(curves * k);
        for c in 0..curves {
            for &u in &params {
                let r = basis.rows(u);
                verts.push(r.point.iter().map(|&(j, w)| (c * count + j, w)).collect());
            }
        }
        let start: Vec<DVec2> = verts.iter().map(|e| eval(e, points).truncate()).collect();
        let id = |c: usize, i: usize| c * k + i;
        let mut pairs = Vec::new();
        for c in 0..curves.saturating_sub(1) {
            for i in 0..k - 1 {
                let (a0, a1, b0, b1) = (id(c, i), id(c, i + 1), id(c + 1, i), id(c + 1, i + 1));
                pairs.extend([(a0, a1), (b0, b1), (a0, b0), (a1, b1), (a0, b1), (a1, b0)]);
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut on_boundary: Vec<usize> = Vec::new();
        for c in 0..curves {
            if c == 0 || c + 1 == curves {
                on_boundary.extend((0..k).map(|i| id(c, i)));
            } else {
                on_boundary.extend([id(c, 0), id(c, k - 1)]);
            }
        }
        let mut corners = Vec::new();
        on_boundary.retain(
            |&v| match outline.iter().find(|q| q.distance(start[v]) <= 1e-9) {
                Some(q) => {
                    corners.push((v, *q));
                    false
                }
                None => true,
            },
        );
        let mut creases = Vec::new();
        let mut on_crease = Vec::new();
        for c in 1..curves.saturating_sub(1) {
            if constrained.get(c).copied().unwrap_or(false) {
                on_crease.extend((1..k - 1).map(|i| (id(c, i), creases.len())));
                creases.push((0..k).map(|i| start[id(c, i)]).collect());
            }
        }
        let mut fair = Vec::new();
        for c in 0..curves {
            for i in 1..k - 1 {
                fair.push([id(c, i - 1), id(c, i), id(c, i + 1)]);
            }
        }
        let fair_s = fair
            .iter()
            .map(|f| start[f[0]] - 2.0 * start[f[1]] + start[f[2]])
            .collect();
        Dev {
            verts,
            base,
            pairs,
            on_boundary,
            corners,
            on_crease,
            outline,
            creases,
            fair,
            fair_s,
            start,
            per_curve: k,
        }
    }

    /// Where the point `q` of the flat sheet is on the surface at the current iterate: the
    /// strip and parameters (u, v) of the development's triangle that holds it (the nearest
    /// one when it holds none), u and v interpolated linearly within that triangle.
    pub(super) fn locate(&self, x: &[f64], q: DVec2) -> Option<(usize, f64, f64)> {
        let k = self.per_curve;
        let curves = self.verts.len() / k.max(1);
        let mut best: Option<(f64, (usize, f64, f64))> = None;
        for c in 0..curves.saturating_sub(1) {
            for i in 0..k.saturating_sub(1) {
                let (u0, u1) = (i as f64 / PER_SPAN as f64, (i + 1) as f64 / PER_SPAN as f64);
                let corner = |cc: usize, ii: usize| self.flat(x, cc * k + ii);
                let (a0, a1, b0, b1) = (
                    corner(c, i),
                    corner(c, i + 1),
                    corner(c + 1, i),
                    corner(c + 1, i + 1),
                );
                // The triangles of the sampled mesh: (a0, a1, b1) and (a0, b1, b0).
                for (t, uv) in [
                    ([a0, a1, b1], [(u0, 0.0), (u1, 0.0), (u1, 1.0)]),
                    ([a0, b1, b0], [(u0, 0.0), (u1, 1.0), (u0, 1.0)]),
                ] {
                    let Some(w) = barycentric(t, q) else { continue };
                    // Outside by the most negative weight (0 inside).
                    let out = -w.iter().copied().fold(0.0, f64::min);
                    if best.is_none_or(|b| out < b.0) {
                        let u = w[0] * uv[0].0 + w[1] * uv[1].0 + w[2] * uv[2].0;
                        let v = w[0] * uv[0].1 + w[1] * uv[1].1 + w[2] * uv[2].1;
                        best = Some((out, (c, u, v.clamp(0.0, 1.0))));
                    }
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Number of unknowns the development adds.
    pub(super) fn unknowns(&self) -> usize {
        2 * self.verts.len()
    }

    /// Put the start into the unknowns.
    pub(super) fn init(&self, x: &mut [f64]) {
        for (i, p) in self.start.iter().enumerate() {
            x[self.base + 2 * i] = p.x;
            x[self.base + 2 * i + 1] = p.y;
        }
    }

    fn flat(&self, x: &[f64], i: usize) -> DVec2 {
        DVec2::new(x[self.base + 2 * i], x[self.base + 2 * i + 1])
    }

    /// The rows of eq. 12, the outline, the corners, the creases and (weighted `eps1`) the
    /// fairness, at the current iterate.
    pub(super) fn rows(
        &self,
        points: &[DVec3],
        var: &[Option<usize>],
        x: &[f64],
        eps1: f64,
        rows: &mut Vec<Row>,
    ) {
        for &(i, j) in &self.pairs {
            let d = eval(&self.verts[i], points) - eval(&self.verts[j], points);
            let e = self.flat(x, i) - self.flat(x, j);
            let len = d.length().max(e.length());
            if len <= 1e-12 {
                continue;
            }
            let mut entries = Vec::new();
            let mut rhs = (d.length_squared() - e.length_squared()) / (2.0 * len);
            for (expr, sign) in [(&self.verts[i], 1.0), (&self.verts[j], -1.0)] {
                for &(p, w) in expr {
                    match var[p] {
                        Some(o) => {
                            for c in 0..3 {
                                entries.push((o + c, sign * w * d[c] / len));
                            }
                        }
                        None => rhs -= sign * w * d.dot(points[p]) / len,
                    }
                }
            }
            for c in 0..2 {
                entries.push((self.base + 2 * i + c, -e[c] / len));
                entries.push((self.base + 2 * j + c, e[c] / len));
            }
            rows.push(Row {
                entries,
                rhs,
                w: 1.0,
            });
        }
        let on_line = |v: usize, poly: &[DVec2], closed: bool, rows: &mut Vec<Row>| {
            if let Some((p, n)) = footpoint(poly, closed, self.flat(x, v)) {
                rows.push(Row {
                    entries: vec![(self.base + 2 * v, n.x), (self.base + 2 * v + 1, n.y)],
                    rhs: n.dot(p),
                    w: 1.0,
                });
            }
        };
        for &v in &self.on_boundary {
            on_line(v, &self.outline, true, rows);
        }
        for &(v, c) in &self.on_crease {
            on_line(v, &self.creases[c], false, rows);
        }
        for &(v, q) in &self.corners {
            for c in 0..2 {
                rows.push(Row {
                    entries: vec![(self.base + 2 * v + c, 1.0)],
                    rhs: q[c],
                    w: 1.0,
                });
            }
        }
        for (f, s) in self.fair.iter().zip(&self.fair_s) {
            for c in 0..2 {
                rows.push(Row {
                    entries: vec![
                        (self.base + 2 * f[0] + c, 1.0),
                        (self.base + 2 * f[1] + c, -2.0),
                        (self.base + 2 * f[2] + c, 1.0),
                    ],
                    rhs: s[c],
                    w: eps1,
                });
            }
        }
    }

    /// The squared residual of eq. 12 and the flat conditions, and the largest relative
    /// length error of eq. 12.
    pub(super) fn merit(&self, points: &[DVec3], x: &[f64]) -> (f64, f64) {
        let (mut sum, mut worst) = (0.0, 0.0f64);
        for &(i, j) in &self.pairs {
            let d = (eval(&self.verts[i], points) - eval(&self.verts[j], points)).length();
            let e = (self.flat(x, i) - self.flat(x, j)).length();
            sum += (d - e).powi(2);
            if d > 1e-12 {
                worst = worst.max((d - e).abs() / d);
            }
        }
        let mut off = |v: usize, poly: &[DVec2], closed: bool| {
            if let Some((p, _)) = footpoint(poly, closed, self.flat(x, v)) {
                sum += p.distance_squared(self.flat(x, v));
            }
        };
        for &v in &self.on_boundary {
            off(v, &self.outline, true);
        }
        for &(v, c) in &self.on_crease {
            off(v, &self.creases[c], false);
        }
        for &(v, q) in &self.corners {
            sum += q.distance_squared(self.flat(x, v));
        }
        (sum, worst)
    }
}

/// The barycentric weights of `q` in the triangle `t`; `None` when it has no area.
fn barycentric(t: [DVec2; 3], q: DVec2) -> Option<[f64; 3]> {
    let d = (t[1] - t[0]).perp_dot(t[2] - t[0]);
    if d.abs() <= 1e-300 {
        return None;
    }
    let w1 = (q - t[0]).perp_dot(t[2] - t[0]) / d;
    let w2 = (t[1] - t[0]).perp_dot(q - t[0]) / d;
    Some([1.0 - w1 - w2, w1, w2])
}

/// The nearest point of a polyline (closed: a polygon) to `q` and the unit normal of the
/// segment it lies on.
fn footpoint(poly: &[DVec2], closed: bool, q: DVec2) -> Option<(DVec2, DVec2)> {
    let n = poly.len();
    let segs = if closed { n } else { n.saturating_sub(1) };
    let mut best: Option<(f64, DVec2, DVec2)> = None;
    for s in 0..segs {
        let (a, b) = (poly[s], poly[(s + 1) % n]);
        let ab = b - a;
        let len2 = ab.length_squared();
        if len2 <= 1e-300 {
            continue;
        }
        let t = ((q - a).dot(ab) / len2).clamp(0.0, 1.0);
        let p = a + ab * t;
        let d = p.distance_squared(q);
        if best.is_none_or(|b| d < b.0) {
            best = Some((d, p, ab.perp() / len2.sqrt()));
        }
    }
    best.map(|(_, p, n)| (p, n))
}
