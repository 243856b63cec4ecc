//! Approximation of a target shape (Tang et al. 2016, §4.2, eq. 9–11): the target as points
//! with unit normals, thinned; the start from the target's principal rectangle; and the
//! closest-point projection (footpoint) of a target point onto a strip, which the solver
//! redoes every iteration to linearise eq. 9 (s(u, v) = q), eq. 10 (⟨m, a − b⟩ = ⟨m, a′⟩ = 0)
//! and eq. 11 (⟨s(u, v) − q, n⟩ = 0).
//!
//! Choices where the paper is silent:
//!
//! - Normals: a mesh target's vertex normals are the area-weighted normals of its faces; a
//!   point cloud's are the least-variance direction of its 12 nearest points (the paper fits
//!   a plane to a ball). Their sign does not matter to eq. 10–11.
//! - Thinning: a target of more than [`MAX_TARGET_POINTS`] points keeps the first point per
//!   cell of a cubic grid whose cell doubles until few enough remain (the paper's Poisson-like
//!   thinning, deterministic).
//! - Principal rectangle: the plane through the centroid spanned by the two largest principal
//!   axes; in it, the rulings run along the direction of least curvature of a quadratic height
//!   fit (so a cylinder's rulings start along its axis), the curves across them at the
//!   extremes of the points' projections, each with evenly spaced control points lifted onto
//!   the fit's profile across the middle ruling: both curves are that profile translated along
//!   the rulings, so the start is a general cylinder, developable and already bent like the
//!   target (the paper starts from the flat rectangle, which guided projection bends only
//!   slowly: the developability rows see bending at second order).
//! - Footpoints: the nearest of a grid of 8 parameters per span by 9 across the strip, then
//!   Gauss–Newton steps on |s(u, v) − q|², with u and v clamped to the strip (a point beyond
//!   its edge is pulled by eq. 9 towards that edge: the strip grows to cover the target).

use crate::geom::bspline::BSpline;
use crate::geom::mesh::{bounds3, Mesh};
use glam::{DMat3, DVec3};

/// Most target points kept after thinning.
pub const MAX_TARGET_POINTS: usize = 4000;

/// A target shape: points with unit normals, in millimetres.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Target {
    pub points: Vec<DVec3>,
    pub normals: Vec<DVec3>,
}

impl Target {
    /// A mesh's vertices with their area-weighted normals (isolated vertices left out).
    pub fn from_mesh(mesh: &Mesh) -> Target {
        let mut normals = vec![DVec3::ZERO; mesh.vertices.len()];
        for (f, face) in mesh.faces.iter().enumerate() {
            let n = mesh.newell(f); // length: twice the area
            for &v in &face.verts {
                normals[v] += n;
            }
        }
        let mut t = Target::default();
        for (p, n) in mesh.vertices.iter().zip(normals) {
            if let Some(n) = n.try_normalize() {
                t.points.push(*p);
                t.normals.push(n);
            }
        }
        t.thinned()
    }

    /// A point cloud, its normals estimated from the 12 nearest points.
    pub fn from_points(points: Vec<DVec3>) -> Target {
        let t = Target {
            normals: vec![DVec3::Z; points.len()],
            points,
        }
        .thinned();
        let normals = cloud_normals(&t.points);
        Target { normals, ..t }
    }

    /// At most [`MAX_TARGET_POINTS`]: the first point per grid cell, the cell doubling.
    fn thinned(self) -> Target {
        if self.points.len() <= MAX_TARGET_POINTS {
            return self;
        }
        let (lo, hi) = bounds3(&self.points).unwrap_or_default();
        let mut cell = (hi - lo).max_element().max(1e-300) / 64.0;
        loop {
            let mut seen = std::collections::HashSet::new();
            let keep: Vec<usize> = (0..self.points.len())
                .filter(|&i| {
                    let c = ((self.points[i] - lo) / cell).floor();
                    seen.insert((c.x as i64, c.y as i64, c.z as i64))
                })
                .collect();
            if keep.len() <= MAX_TARGET_POINTS {
                return Target {
                    points: keep.iter().map(|&i| self.points[i]).collect(),
                    normals: keep.iter().map(|&i| self.normals[i]).collect(),
                };
            }
            cell *= 2.0;
        }
    }

    /// Two straight curves of `count` control points across the principal rectangle, rulings
    /// along the direction of least curvature (see the module doc); `None` when the target
    /// has no extent in two directions.
    pub fn principal_rectangle(&self, count: usize) -> Option<Vec<Vec<DVec3>>> {
        let n = self.points.len();
        if n < 3 {
            return None;
        }
        let c = self.points.iter().sum::<DVec3>() / n as f64;
        let mut cov = DMat3::ZERO;
        for p in &self.points {
            let d = *p - c;
            cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
        }
        let (_, vecs) = crate::geom::proxy::eigen_sym(cov / n as f64);
        let (e1, e2, e3) = (vecs[2], vecs[1], vecs[0]);
        // Quadratic height fit h = αx² + βxy + γy² + δx + εy + ζ over the plane (e1, e2).
        let local: Vec<(f64, f64, f64)> = self
            .points
            .iter()
            .map(|p| {
                let d = *p - c;
                (d.dot(e1), d.dot(e2), d.dot(e3))
            })
            .collect();
        let coef = fit_quadric(&local);
        let ruling = match coef {
            Some([a, b, g, ..]) => {
                // Hessian [[2α, β], [β, 2γ]]: its eigenvector of smaller |eigenvalue|.
                let (h11, h12, h22) = (2.0 * a, b, 2.0 * g);
                let mean = 0.5 * (h11 + h22);
                let disc = (0.25 * (h11 - h22).powi(2) + h12 * h12).sqrt();
                let (l1, l2) = (mean + disc, mean - disc);
                let l = if l1.abs() < l2.abs() { l1 } else { l2 };
                let v = if h12.abs() > 1e-12 * (h11.abs() + h22.abs()).max(1e-300) {
                    (l - h22, h12)
                } else if (h11 - l).abs() <= (h22 - l).abs() {
                    (1.0, 0.0)
                } else {
                    (0.0, 1.0)
                };
                let len = (v.0 * v.0 + v.1 * v.1).sqrt();
                (v.0 / len, v.1 / len)
            }
            None => (1.0, 0.0),
        };
        let r = e1 * ruling.0 + e2 * ruling.1;
        let t = e3.cross(r).normalize_or_zero();
        let (mut r0, mut r1, mut t0, mut t1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in &self.points {
            let d = *p - c;
            r0 = r0.min(d.dot(r));
            r1 = r1.max(d.dot(r));
            t0 = t0.min(d.dot(t));
            t1 = t1.max(d.dot(t));
        }
        if !(r1 - r0 > 0.0 && t1 - t0 > 0.0) {
            return None;
        }
        // The quadric's profile across the rulings, h(t) at the rectangle's middle ruling: the
        // curves are its control polygon, so the start is a general cylinder (developable).
        let mid = 0.5 * (r0 + r1);
        let height = |tv: f64| -> f64 {
            let Some([a, b, g, d, e, z]) = coef else {
                return 0.0;
            };
            // (x, y) in the (e1, e2) frame of the point mid·r + tv·t.
            let p = r * mid + t * tv;
            let (x, y) = (p.dot(e1), p.dot(e2));
            a * x * x + b * x * y + g * y * y + d * x + e * y + z
        };
        let curve = |rv: f64| -> Vec<DVec3> {
            (0..count)
                .map(|j| {
                    let tv = t0 + (t1 - t0) * j as f64 / (count - 1) as f64;
                    c + r * rv + t * tv + e3 * height(tv)
                })
                .collect()
        };
        Some(vec![curve(r0), curve(r1)])
    }
}

/// Least squares h = αx² + βxy + γy² + δx + εy + ζ (normal equations, Gaussian elimination
/// with partial pivoting); `None` when singular.
#[allow(clippy::needless_range_loop)] // rows and columns of one small matrix
fn fit_quadric(pts: &[(f64, f64, f64)]) -> Option<[f64; 6]> {
    let mut a = [[0.0f64; 7]; 6];
    for &(x, y, h) in pts {
        let row = [x * x, x * y, y * y, x, y, 1.0];
        for i in 0..6 {
            for j in 0..6 {
                a[i][j] += row[i] * row[j];
            }
            a[i][6] += row[i] * h;
        }
    }
    for col in 0..6 {
        let piv = (col..6).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, piv);
        for r in 0..6 {
            if r != col {
                let f = a[r][col] / a[col][col];
                for k in col..7 {
                    a[r][k] -= f * a[col][k];
                }
            }
        }
    }
    let out: [f64; 6] = std::array::from_fn(|i| a[i][6] / a[i][i]);
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// Normals of a point cloud: the least-variance direction of each point's 12 nearest
/// neighbours (a uniform grid finds them).
fn cloud_normals(points: &[DVec3]) -> Vec<DVec3> {
    const K: usize = 12;
    let n = points.len();
    if n < 3 {
        return vec![DVec3::Z; n];
    }
    let (lo, hi) = bounds3(points).unwrap_or_default();
    let cell = ((hi - lo).max_element() / (n as f64).cbrt()).max(1e-300);
    let key = |p: DVec3| {
        let c = ((p - lo) / cell).floor();
        (c.x as i64, c.y as i64, c.z as i64)
    };
    let mut grid: std::collections::HashMap<(i64, i64, i64), Vec<usize>> = Default::default();
    for (i, p) in points.iter().enumerate() {
        grid.entry(key(*p)).or_default().push(i);
    }
    points
        .iter()
        .map(|p| {
            let (cx, cy, cz) = key(*p);
            let mut near: Vec<(f64, usize)> = Vec::new();
            let mut ring = 1i64;
            while near.len() < K.min(n - 1) + 1 && ring < 64 {
                near.clear();
                for dx in -ring..=ring {
                    for dy in -ring..=ring {
                        for dz in -ring..=ring {
                            if let Some(v) = grid.get(&(cx + dx, cy + dy, cz + dz)) {
                                near.extend(v.iter().map(|&j| (points[j].distance(*p), j)));
                            }
                        }
                    }
                }
                ring *= 2;
            }
            near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            near.truncate(K + 1);
            let c = near.iter().map(|&(_, j)| points[j]).sum::<DVec3>() / near.len() as f64;
            let mut cov = DMat3::ZERO;
            for &(_, j) in &near {
                let d = points[j] - c;
                cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
            }
            let (_, v) = crate::geom::proxy::eigen_sym(cov);
            v[0].try_normalize().unwrap_or(DVec3::Z)
        })
        .collect()
}

/// A strip as the footpoint search sees it: curve `a` and curve `b` (or the apex).
pub struct StripRef<'a> {
    pub basis: &'a BSpline,
    pub a: &'a [DVec3],
    pub b: Result<&'a [DVec3], DVec3>,
}

impl StripRef<'_> {
    /// s(u, v), s_u and s_v.
    pub fn eval(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (pa, ta) = (self.basis.eval(self.a, u), self.basis.deriv(self.a, u));
        let (pb, tb) = match self.b {
            Ok(b) => (self.basis.eval(b, u), self.basis.deriv(b, u)),
            Err(apex) => (apex, DVec3::ZERO),
        };
        (pa * (1.0 - v) + pb * v, ta * (1.0 - v) + tb * v, pb - pa)
    }

    /// The search grid: 8 parameters per span by 9 across, with their points.
    pub fn grid(&self) -> Vec<(f64, f64, DVec3)> {
        let spans = self.basis.spans() as f64;
        let per = 8 * self.basis.spans();
        let mut out = Vec::with_capacity((per + 1) * 9);
        for i in 0..=per {
            let u = spans * i as f64 / per as f64;
            for j in 0..=8 {
                let v = j as f64 / 8.0;
                out.push((u, v, self.eval(u, v).0));
            }
        }
        out
    }

    /// The footpoint (u, v) of `q` on the strip and its squared distance, from the nearest
    /// point of [`StripRef::grid`].
    pub fn footpoint(&self, grid: &[(f64, f64, DVec3)], q: DVec3) -> (f64, f64, f64) {
        let spans = self.basis.spans() as f64;
        let (mut best_u, mut best_v, mut best) = (0.0, 0.0, f64::INFINITY);
        for &(u, v, p) in grid {
            let d = p.distance_squared(q);
            if d < best {
                (best_u, best_v, best) = (u, v, d);
            }
        }
        let (mut u, mut v) = (best_u, best_v);
        for _ in 0..8 {
            let (s, su, sv) = self.eval(u, v);
            let r = s - q;
            let (a11, a12, a22) = (su.dot(su), su.dot(sv), sv.dot(sv));
            let (b1, b2) = (-su.dot(r), -sv.dot(r));
            let det = a11 * a22 - a12 * a12;
            if det.abs() <= 1e-300 {
                break;
            }
            let du = (b1 * a22 - b2 * a12) / det;
            let dv = (a11 * b2 - a12 * b1) / det;
            let (nu, nv) = if self.basis.closed() {
                ((u + du).rem_euclid(spans), (v + dv).clamp(0.0, 1.0))
            } else {
                ((u + du).clamp(0.0, spans), (v + dv).clamp(0.0, 1.0))
            };
            let d = self.eval(nu, nv).0.distance_squared(q);
            if d > best {
                break;
            }
            (u, v, best) = (nu, nv, d);
            if du.abs() + dv.abs() < 1e-12 {
                break;
            }
        }
        (u, v, best)
    }
}
