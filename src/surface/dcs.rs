//! Developable surfaces of constant slope (DCS): the proxy that D-Charts grows charts around
//! ([`Proxy`], [`fit`], thesis §4.3 and eq. 5.4) and the DCS approximation that moves a mesh
//! towards a developable one ([`approximate`], thesis chapter 6, eq. 6.1–6.3).
//!
//! A DCS proxy is an axis `N` (unit) and the cosine `c = cos θ` of the constant angle between
//! the surface normals and the axis; the fitting error of a face with normal `n` is
//! `F = ((N·n − c)/2)²` (eq. 4.1).
//!
//! # Fitting (eq. 5.4 and 6.1)
//!
//! The thesis solves eq. 5.4 with a general solver (Knitro). It has a closed form: for a fixed
//! axis the best `c` is the area-weighted mean of `N·n`, and what is left is
//! `Nᵀ Σ A_t (n_t − n̄)(n_t − n̄)ᵀ N / 4`, minimised over unit `N` by the eigenvector of the
//! smallest eigenvalue of the weighted covariance of the normals. [`fit`] uses that (a 3×3
//! Jacobi eigen-solver). When the covariance vanishes (a plane) the proxy is the plane's own:
//! `N` = the mean normal, `c` = 1. Fits with a prescribed `c` (the planar test of §6.2.1 with
//! `c = 1`, the `|cos θ| ≤ 0.5` bound of eq. 6.1, the cylinder test of the merging step with
//! `c = 0`) minimise a quadratic on the unit sphere: `(M − λI) N = c b` with `λ` below the
//! smallest eigenvalue of `M`, found by bisection on `|N(λ)| = 1` ([`fit_with_cos`]).
//!
//! Faces with a zero normal (degenerate) weigh nothing in a fit and fit every proxy (F = 0):
//! they carry no direction.
//!
//! # Approximation (chapter 6)
//!
//! For every triangle: the faces within [`ApproximateOptions::rings`] vertex rings are fitted
//! (planar test first: if the plane fits with mean error below
//! [`ApproximateOptions::planar_error`], the plane is used; else eq. 6.1 under `|cos θ| ≤ 0.5`,
//! so no cone apex lands on the surface); the face normal is turned onto the proxy's cone
//! (the nearest direction with `n·N = c`), and the triangle is moved onto the plane with that
//! normal closest to its vertices (eq. 6.2: each vertex projected onto the plane through their
//! mean; fixed vertices leave the sum and stay where they are, the plane goes through the mean
//! of the free ones).
//! Gluing (eq. 6.3) minimises `Σ_j A_j ‖Ṽ_j V_j⁻¹ − I‖²_F` over the new vertex positions, one
//! sparse least-squares problem per coordinate solved by conjugate gradients on the normal
//! equations. Choices where the thesis is silent: the fourth frame point `ṽ4 = ṽ1 + s·m_j`
//! is offset along the triangle's target normal `m_j` (this keeps the problem linear; the
//! edge columns carry the rotation), each triangle is weighted by its area, and a small
//! pull `10⁻³·Σ‖ṽ − v⁰‖²/ℓ²` (ℓ the mean edge length) towards the input keeps the problem
//! well posed without fixed vertices (it removes the free translation). Fixed vertices do not
//! move at all. One call runs [`ApproximateOptions::iterations`] rounds. Only triangles are
//! moved; other polygons keep their vertices unless a triangle moves them.

use crate::geom::mesh::Mesh;
use glam::{DMat3, DVec3};

/// A developable surface of constant slope: normals at a constant angle to `axis`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proxy {
    /// Unit axis `N`.
    pub axis: DVec3,
    /// `cos θ`: 1 for a plane with normal `axis`, 0 for a cylinder along `axis`.
    pub cos: f64,
}

impl Proxy {
    /// Fitting error of a face normal, eq. 4.1; 0 for a zero (degenerate) normal.
    pub fn error(&self, n: DVec3) -> f64 {
        if n == DVec3::ZERO {
            return 0.0;
        }
        let d = (self.axis.dot(n) - self.cos) * 0.5;
        d * d
    }
}

/// Eigenvalues (ascending) and unit eigenvectors of a symmetric 3×3 matrix (Jacobi).
#[allow(clippy::needless_range_loop)] // rows and columns of the same small matrix
pub fn eigen_sym(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    let mut a = m.to_cols_array_2d();
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs() + off;
        if off <= 1e-15 * scale.max(f64::MIN_POSITIVE) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() < 1e-300 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let vp = row[p];
                let vq = row[q];
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let vals = [a[idx[0]][idx[0]], a[idx[1]][idx[1]], a[idx[2]][idx[2]]];
    let col = |j: usize| DVec3::new(v[0][j], v[1][j], v[2][j]).normalize_or(DVec3::Z);
    (vals, [col(idx[0]), col(idx[1]), col(idx[2])])
}

/// Weighted sums of normals: `W = Σw`, `b = Σ w n`, `M = Σ w n nᵀ`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Moments {
    pub w: f64,
    pub b: DVec3,
    pub m: [[f64; 3]; 3],
}

impl Moments {
    /// Add a normal with weight `w` (zero normals and weights are skipped).
    pub fn add(&mut self, n: DVec3, w: f64) {
        if n == DVec3::ZERO || w.is_nan() || w <= 0.0 {
            return;
        }
        self.w += w;
        self.b += w * n;
        let a = n.to_array();
        for (i, row) in self.m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x += w * a[i] * a[j];
            }
        }
    }

    fn mat(&self) -> DMat3 {
        DMat3::from_cols_array_2d(&self.m)
    }
}

/// The DCS proxy minimising the area-weighted fitting error (eq. 5.4), with `cos θ ≥ 0`.
/// `None` when there is no weight (no faces, or only degenerate ones).
pub fn fit(mo: &Moments) -> Option<Proxy> {
    if mo.w <= 0.0 {
        return None;
    }
    let mean = mo.b / mo.w;
    // Covariance Σ w (n − n̄)(n − n̄)ᵀ = M − W n̄ n̄ᵀ.
    let cov = mo.mat() - DMat3::from_cols(mean * mean.x, mean * mean.y, mean * mean.z) * mo.w;
    let (vals, vecs) = eigen_sym(cov);
    let planar = vals[2] <= 1e-14 * mo.w;
    if planar {
        if let Some(n) = mean.try_normalize() {
            return Some(Proxy { axis: n, cos: 1.0 });
        }
    }
    let mut axis = vecs[0];
    let mut cos = axis.dot(mean);
    if cos < 0.0 {
        axis = -axis;
        cos = -cos;
    }
    Some(Proxy {
        axis,
        cos: cos.min(1.0),
    })
}

/// The axis minimising `Σ w (N·n − c)²` over unit `N` for a prescribed `c` (eq. 5.4 with
/// θ fixed). `None` without weight.
pub fn fit_with_cos(mo: &Moments, c: f64) -> Option<Proxy> {
    if mo.w <= 0.0 {
        return None;
    }
    let (mu, e) = eigen_sym(mo.mat());
    let rhs = mo.b * c;
    let coef = [rhs.dot(e[0]), rhs.dot(e[1]), rhs.dot(e[2])];
    let norm2 = |lam: f64| -> f64 {
        (0..3)
            .map(|i| {
                let d = mu[i] - lam;
                if d.abs() < 1e-300 {
                    f64::INFINITY
                } else {
                    (coef[i] / d).powi(2)
                }
            })
            .sum()
    };
    // |N(λ)| grows as λ rises to μ₀; in the "hard case" (b has no part along the smallest
    // eigenvector e₀, e.g. c = 0, or a symmetric patch) it stays finite, and when it stays
    // below 1 the minimiser is N(μ₀) completed by e₀ to unit length.
    let small = coef[0].abs() <= 1e-12 * (mo.w + rhs.length()).max(1e-300);
    let rest = (1..3).fold(DVec3::ZERO, |acc, i| {
        let d = mu[i] - mu[0];
        if d > 1e-12 * mu[2].abs().max(1e-300) {
            acc + e[i] * (coef[i] / d)
        } else {
            acc
        }
    });
    let axis = if small && rest.length_squared() < 1.0 {
        let mut a = rest + e[0] * (1.0 - rest.length_squared()).max(0.0).sqrt();
        if c == 0.0 && a.dot(mo.b) < 0.0 {
            a = -a;
        }
        a.try_normalize()?
    } else {
        let mut hi = mu[0];
        let mut lo = mu[0] - rhs.length() - 1.0;
        while norm2(lo) > 1.0 {
            lo -= (mu[0] - lo).max(1.0);
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if norm2(mid) > 1.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let lam = lo;
        let v = (0..3).fold(DVec3::ZERO, |acc, i| {
            let d = mu[i] - lam;
            if d.abs() < 1e-300 {
                acc
            } else {
                acc + e[i] * (coef[i] / d)
            }
        });
        v.try_normalize()?
    };
    Some(Proxy { axis, cos: c })
}

/// Mean (area-weighted) fitting error of a proxy over weighted normals.
pub fn mean_error(p: &Proxy, mo: &Moments) -> f64 {
    if mo.w <= 0.0 {
        return 0.0;
    }
    // Σ w (N·n − c)² = Nᵀ M N − 2c N·b + c² W.
    let n = p.axis;
    let q = n.dot(mo.mat() * n) - 2.0 * p.cos * n.dot(mo.b) + p.cos * p.cos * mo.w;
    (q.max(0.0) / 4.0) / mo.w
}

/// The DCS fit of eq. 6.1 with `|cos θ| ≤ 0.5`, after the planar test.
pub fn fit_local(mo: &Moments, planar_error: f64) -> Option<Proxy> {
    let plane = fit_with_cos(mo, 1.0)?;
    let plane_err = mean_error(&plane, mo);
    if plane_err <= planar_error {
        return Some(plane);
    }
    let free = fit(mo)?;
    let dcs = if free.cos <= 0.5 {
        free
    } else {
        fit_with_cos(mo, 0.5)?
    };
    let _ = plane_err;
    Some(dcs)
}

/// Settings of the DCS approximation.
#[derive(Debug, Clone, PartialEq)]
pub struct ApproximateOptions {
    /// Rounds of local fit, transform and gluing (default 1).
    pub iterations: usize,
    /// Vertex rings around each triangle in its neighbourhood (default 2).
    pub rings: usize,
    /// Mean fitting error below which a neighbourhood counts as planar (default 1e-6).
    pub planar_error: f64,
    /// Vertices that must not move (mesh indices, 0-based).
    pub fixed: Vec<usize>,
}

impl Default for ApproximateOptions {
    fn default() -> Self {
        ApproximateOptions {
            iterations: 1,
            rings: 2,
            planar_error: 1e-6,
            fixed: Vec::new(),
        }
    }
}

/// What an approximation did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ApproximateStats {
    /// Largest distance a vertex moved from the input (mm).
    pub max_move: f64,
    /// Mean distance vertices moved (mm).
    pub mean_move: f64,
}

/// Why an approximation cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ApproximateError {
    #[error("fixed vertex {0} does not exist (the mesh has {1} vertices)")]
    NoSuchVertex(usize, usize),
    #[error("the mesh has a vertex that is not a finite number")]
    NonFinite,
}

/// Move the mesh towards a developable one (thesis chapter 6), in place.
pub fn approximate(
    mesh: &mut Mesh,
    opts: &ApproximateOptions,
) -> Result<ApproximateStats, ApproximateError> {
    let nv = mesh.vertices.len();
    if let Some(&v) = opts.fixed.iter().find(|&&v| v >= nv) {
        return Err(ApproximateError::NoSuchVertex(v + 1, nv));
    }
    if mesh.vertices.iter().any(|p| !p.is_finite()) {
        return Err(ApproximateError::NonFinite);
    }
    let original = mesh.vertices.clone();
    let mut fixed = vec![false; nv];
    for &v in &opts.fixed {
        fixed[v] = true;
    }
    // Vertex → faces.
    let mut vf: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in &face.verts {
            vf[v].push(f);
        }
    }
    let tris: Vec<usize> = (0..mesh.faces.len())
        .filter(|&f| mesh.faces[f].verts.len() == 3)
        .collect();
    let mut edge_sum = 0.0;
    let mut edge_n = 0usize;
    for &f in &tris {
        let v = &mesh.faces[f].verts;
        for i in 0..3 {
            edge_sum += mesh.vertices[v[i]].distance(mesh.vertices[v[(i + 1) % 3]]);
            edge_n += 1;
        }
    }
    let ell = if edge_n > 0 && edge_sum > 0.0 {
        edge_sum / edge_n as f64
    } else {
        return Ok(ApproximateStats::default());
    };
    for _ in 0..opts.iterations {
        let normals: Vec<DVec3> = (0..mesh.faces.len()).map(|f| mesh.face_normal(f)).collect();
        let areas: Vec<f64> = (0..mesh.faces.len()).map(|f| mesh.face_area(f)).collect();
        // Local fit and transform, per triangle.
        let mut stamp = vec![usize::MAX; mesh.faces.len()];
        let mut targets: Vec<(usize, [DVec3; 3], DVec3, f64)> = Vec::with_capacity(tris.len());
        for &f in &tris {
            let mut ring: Vec<usize> = vec![f];
            stamp[f] = f;
            let mut start = 0;
            for _ in 0..opts.rings {
                let end = ring.len();
                for k in start..end {
                    let g = ring[k];
                    for &v in &mesh.faces[g].verts {
                        for &h in &vf[v] {
                            if stamp[h] != f {
                                stamp[h] = f;
                                ring.push(h);
                            }
                        }
                    }
                }
                start = end;
            }
            let mut mo = Moments::default();
            for &g in &ring {
                mo.add(normals[g], areas[g]);
            }
            let n = normals[f];
            let v = &mesh.faces[f].verts;
            let p0 = [
                mesh.vertices[v[0]],
                mesh.vertices[v[1]],
                mesh.vertices[v[2]],
            ];
            let Some(proxy) = fit_local(&mo, opts.planar_error) else {
                continue;
            };
            if n == DVec3::ZERO {
                continue;
            }
            // Nearest direction on the proxy's cone {m : m·N = c}.
            let axis = proxy.axis;
            let m = if proxy.cos >= 1.0 - 1e-15 {
                axis
            } else {
                let side = n - axis * axis.dot(n);
                let side = side
                    .try_normalize()
                    .unwrap_or_else(|| axis.any_orthonormal_vector());
                axis * proxy.cos + side * (1.0 - proxy.cos * proxy.cos).max(0.0).sqrt()
            };
            // Eq. 6.2: the plane with normal m closest to the free vertices.
            // Fixed vertices leave the minimisation (thesis §6.2.2): the plane goes through
            // the free ones' mean.
            let free_here: Vec<usize> = (0..3).filter(|&i| !fixed[v[i]]).collect();
            if free_here.is_empty() {
                continue;
            }
            let d = free_here.iter().map(|&i| p0[i].dot(m)).sum::<f64>() / free_here.len() as f64;
            let mut t = p0;
            for i in 0..3 {
                if !fixed[v[i]] {
                    t[i] = p0[i] - m * (p0[i].dot(m) - d);
                }
            }
            targets.push((f, t, m, areas[f]));
        }
        glue(mesh, &targets, &fixed, &original, ell);
    }
    let moves: Vec<f64> = mesh
        .vertices
        .iter()
        .zip(&original)
        .map(|(a, b)| a.distance(*b))
        .collect();
    Ok(ApproximateStats {
        max_move: moves.iter().copied().fold(0.0, f64::max),
        mean_move: moves.iter().sum::<f64>() / moves.len().max(1) as f64,
    })
}

/// One row of eq. 6.3: `Σ_k coef_k · x_{vk} = rhs` (per coordinate), weight `w`.
struct Row {
    coef: [(usize, f64); 3],
    rhs: DVec3,
    w: f64,
}

/// Eq. 6.3: new vertex positions whose triangles' deformation gradients (relative to the
/// moved triangles) are closest to the identity.
fn glue(
    mesh: &mut Mesh,
    targets: &[(usize, [DVec3; 3], DVec3, f64)],
    fixed: &[bool],
    original: &[DVec3],
    ell: f64,
) {
    let nv = mesh.vertices.len();
    // Unknown index of each free vertex.
    let mut var = vec![usize::MAX; nv];
    let mut nfree = 0;
    for v in 0..nv {
        if !fixed[v] {
            var[v] = nfree;
            nfree += 1;
        }
    }
    if nfree == 0 {
        return;
    }
    let rows = gradient_rows(mesh, targets);
    // Normal equations A = Σ w aᵀa + μ I, b = Σ w aᵀ rhs + μ v⁰ (fixed moved to the right).
    let mu = 1e-3 / (ell * ell);
    let (diag, b, trip) = normal_equations(mesh, &rows, &var, original, mu);
    let (start, cols, vals) = compress(trip, nfree);
    let x0: Vec<DVec3> = (0..nv)
        .filter(|&v| var[v] != usize::MAX)
        .map(|v| mesh.vertices[v])
        .collect();
    let x = conjugate_gradients(&diag, (&start, &cols, &vals), &b, x0);
    for v in 0..nv {
        if var[v] != usize::MAX && x[var[v]].is_finite() {
            mesh.vertices[v] = x[var[v]];
        }
    }
}

/// The rows of eq. 6.3, three per target triangle (one per column of its gradient), weighted
/// by the triangle's area relative to the mean.
fn gradient_rows(mesh: &Mesh, targets: &[(usize, [DVec3; 3], DVec3, f64)]) -> Vec<Row> {
    let mut rows: Vec<Row> = Vec::with_capacity(targets.len() * 3);
    let mut total_area = 0.0;
    for (_, _, _, a) in targets {
        total_area += a;
    }
    let area_scale = if total_area > 0.0 {
        targets.len() as f64 / total_area
    } else {
        1.0
    };
    for (f, t, m, a) in targets {
        let v = &mesh.faces[*f].verts;
        let s = ((t[1] - t[0]).cross(t[2] - t[0]).length())
            .sqrt()
            .max(1e-300);
        let t4 = t[0] + *m * s;
        let frame = DMat3::from_cols(t4 - t[0], t4 - t[1], t4 - t[2]);
        if frame.determinant().abs() < 1e-300 || !frame.determinant().is_finite() {
            continue;
        }
        let inv = frame.inverse();
        // (Ṽ − V) W, column c: W[1][c]·((ṽ1 − ṽ2) − (t1 − t2)) + W[2][c]·((ṽ1 − ṽ3) − (t1 − t3)).
        // glam stores columns: inv.col(c)[r] = W[r][c].
        for c in 0..3 {
            let col = inv.col(c);
            let (w1, w2) = (col.y, col.z);
            let rhs = (t[0] - t[1]) * w1 + (t[0] - t[2]) * w2;
            rows.push(Row {
                coef: [(v[0], w1 + w2), (v[1], -w1), (v[2], -w2)],
                rhs,
                w: a * area_scale,
            });
        }
    }
    rows
}

/// The normal equations of the rows with the damping `mu` towards the original positions:
/// the diagonal, the right-hand side and the off-diagonal entries as (row, column, value).
#[allow(clippy::type_complexity)]
fn normal_equations(
    mesh: &Mesh,
    rows: &[Row],
    var: &[usize],
    original: &[DVec3],
    mu: f64,
) -> (Vec<f64>, Vec<DVec3>, Vec<(usize, usize, f64)>) {
    let nv = mesh.vertices.len();
    let nfree = var.iter().filter(|&&v| v != usize::MAX).count();
    let mut diag = vec![mu; nfree];
    let mut b = vec![DVec3::ZERO; nfree];
    for v in 0..nv {
        if var[v] != usize::MAX {
            b[var[v]] = original[v] * mu;
        }
    }
    let mut trip: Vec<(usize, usize, f64)> = Vec::new();
    for r in rows {
        let mut rhs = r.rhs;
        for &(v, c) in &r.coef {
            if var[v] == usize::MAX {
                rhs -= mesh.vertices[v] * c;
            }
        }
        for &(vi, ci) in &r.coef {
            let i = var[vi];
            if i == usize::MAX {
                continue;
            }
            b[i] += rhs * (r.w * ci);
            for &(vj, cj) in &r.coef {
                let j = var[vj];
                if j == usize::MAX {
                    continue;
                }
                if i == j {
                    diag[i] += r.w * ci * cj;
                } else {
                    trip.push((i, j, r.w * ci * cj));
                }
            }
        }
    }
    (diag, b, trip)
}

/// Off-diagonal entries summed and compressed by rows: row starts, columns, values.
fn compress(
    mut trip: Vec<(usize, usize, f64)>,
    nfree: usize,
) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    trip.sort_unstable_by_key(|t| (t.0, t.1));
    let mut start = vec![0usize; nfree + 1];
    let mut cols: Vec<usize> = Vec::new();
    let mut vals: Vec<f64> = Vec::new();
    let mut rows_of: Vec<usize> = Vec::new();
    for (i, j, x) in trip {
        if rows_of.last() == Some(&i) && cols.last() == Some(&j) {
            if let Some(last) = vals.last_mut() {
                *last += x;
            }
            continue;
        }
        rows_of.push(i);
        cols.push(j);
        vals.push(x);
    }
    for &i in &rows_of {
        start[i + 1] += 1;
    }
    for i in 0..nfree {
        start[i + 1] += start[i];
    }
    (start, cols, vals)
}

/// Jacobi-preconditioned conjugate gradients on `diag + off-diagonal`, the three coordinates
/// at once, from `x`.
fn conjugate_gradients(
    diag: &[f64],
    (start, cols, vals): (&[usize], &[usize], &[f64]),
    b: &[DVec3],
    mut x: Vec<DVec3>,
) -> Vec<DVec3> {
    let nfree = diag.len();
    let apply = |x: &[DVec3], out: &mut [DVec3]| {
        for i in 0..nfree {
            let mut s = x[i] * diag[i];
            for k in start[i]..start[i + 1] {
                s += x[cols[k]] * vals[k];
            }
            out[i] = s;
        }
    };
    let mut ax = vec![DVec3::ZERO; nfree];
    apply(&x, &mut ax);
    let mut r: Vec<DVec3> = b.iter().zip(&ax).map(|(b, a)| *b - *a).collect();
    let z = |r: &[DVec3]| -> Vec<DVec3> { r.iter().zip(diag).map(|(r, d)| *r / *d).collect() };
    let mut zk = z(&r);
    let mut p = zk.clone();
    let dot = |a: &[DVec3], b: &[DVec3]| -> DVec3 {
        a.iter().zip(b).fold(DVec3::ZERO, |s, (x, y)| s + *x * *y)
    };
    let mut rz = dot(&r, &zk);
    let b_norm = dot(b, b).max_element().sqrt().max(1e-300);
    let mut ap = vec![DVec3::ZERO; nfree];
    for _ in 0..(4 * nfree).clamp(100, 5000) {
        apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        let alpha = DVec3::select(pap.cmpgt(DVec3::ZERO), rz / pap, DVec3::ZERO);
        for i in 0..nfree {
            x[i] += p[i] * alpha;
            r[i] -= ap[i] * alpha;
        }
        let rn = dot(&r, &r).max_element().sqrt();
        if rn <= 1e-13 * b_norm {
            break;
        }
        zk = z(&r);
        let rz_new = dot(&r, &zk);
        let beta = DVec3::select(rz.cmpgt(DVec3::ZERO), rz_new / rz, DVec3::ZERO);
        for i in 0..nfree {
            p[i] = zk[i] + p[i] * beta;
        }
        rz = rz_new;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_normals_fit_exactly() {
        let mut mo = Moments::default();
        for k in 0..12 {
            let t = k as f64 * 0.2;
            mo.add(DVec3::new(t.cos(), t.sin(), 0.0), 1.0);
        }
        let p = fit(&mo).unwrap();
        assert!(p.axis.z.abs() > 1.0 - 1e-9, "{p:?}");
        assert!(p.cos.abs() < 1e-9);
        assert!(mean_error(&p, &mo) < 1e-15);
    }

    #[test]
    fn cone_normals_fit_exactly_and_bounded_fit_respects_half() {
        let mut mo = Moments::default();
        let c: f64 = 0.8;
        let s = (1.0 - c * c).sqrt();
        for k in 0..10 {
            let t = k as f64 * 0.3;
            mo.add(DVec3::new(s * t.cos(), s * t.sin(), c), 1.0 + k as f64);
        }
        let p = fit(&mo).unwrap();
        assert!((p.cos - c).abs() < 1e-9, "{p:?}");
        assert!(mean_error(&p, &mo) < 1e-15);
        let q = fit_local(&mo, 1e-9).unwrap();
        assert!((q.cos - 0.5).abs() < 1e-12);
        // The bounded fit is the best with c = 0.5: no nearby axis does better.
        let e = mean_error(&q, &mo);
        for d in [DVec3::X, DVec3::Y, DVec3::Z] {
            let r = Proxy {
                axis: (q.axis + d * 1e-3).normalize(),
                cos: 0.5,
            };
            assert!(mean_error(&r, &mo) >= e - 1e-12);
        }
    }

    #[test]
    fn symmetric_patch_plane_fit_is_its_mean_normal() {
        // Normals spread evenly around z: b lies along z, the smallest eigenvectors across.
        let mut mo = Moments::default();
        mo.add(DVec3::Z, 1.0);
        for k in 0..6 {
            let t = k as f64 * std::f64::consts::PI / 3.0;
            mo.add(
                DVec3::new(0.1 * t.cos(), 0.1 * t.sin(), 1.0).normalize(),
                1.0,
            );
        }
        let p = fit_with_cos(&mo, 1.0).unwrap();
        assert!((p.axis - DVec3::Z).length() < 1e-9, "{p:?}");
        let q = fit_with_cos(&mo, 0.5).unwrap();
        assert!((q.axis.length() - 1.0).abs() < 1e-12);
        assert!(
            mean_error(&q, &mo)
                < mean_error(
                    &Proxy {
                        axis: DVec3::X,
                        cos: 0.5
                    },
                    &mo
                )
        );
    }

    #[test]
    fn plane_fits_as_plane() {
        let mut mo = Moments::default();
        mo.add(DVec3::Y, 2.0);
        mo.add(DVec3::Y, 1.0);
        let p = fit(&mo).unwrap();
        assert_eq!(p.cos, 1.0);
        assert!((p.axis - DVec3::Y).length() < 1e-12);
        assert!(fit(&Moments::default()).is_none());
    }
}
