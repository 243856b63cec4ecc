//! The DCS approximation (Julius 2006, thesis chapter 6, eq. 6.1–6.3): moves a mesh towards a
//! developable one ([`approximate`]) made of pieces of developable surfaces of constant slope
//! (DCS), each fitted with the proxy of [`crate::geom::proxy`] (axis `N`, `c = cos θ`,
//! eq. 4.1 and 5.4).
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
use crate::geom::proxy::{fit_local, Moments};
use glam::{DMat3, DVec3};

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
    let rows = gluing_rows(mesh, targets);
    let ne = NormalEquations::new(mesh, &rows, &var, nfree, original, ell);
    let x0: Vec<DVec3> = (0..nv)
        .filter(|&v| var[v] != usize::MAX)
        .map(|v| mesh.vertices[v])
        .collect();
    let x = ne.solve(x0);
    for v in 0..nv {
        if var[v] != usize::MAX && x[var[v]].is_finite() {
            mesh.vertices[v] = x[var[v]];
        }
    }
}

/// One row of the gluing problem: Σ_k coef_k · x_{vk} = rhs (per coordinate), weight w.
struct Row {
    coef: [(usize, f64); 3],
    rhs: DVec3,
    w: f64,
}

/// The rows of eq. 6.3: three per target triangle (one per column of `(Ṽ − V) W`), weighted
/// by the triangle's area over the mean area.
fn gluing_rows(mesh: &Mesh, targets: &[(usize, [DVec3; 3], DVec3, f64)]) -> Vec<Row> {
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

/// The normal equations `A x = b` of the gluing rows over the free vertices, `A` as its
/// diagonal and its off-diagonal entries row by row.
struct NormalEquations {
    nfree: usize,
    diag: Vec<f64>,
    b: Vec<DVec3>,
    /// Row `i`'s entries are `cols[start[i]..start[i + 1]]`, `vals[..]`.
    start: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
}

impl NormalEquations {
    /// `A = Σ w aᵀa + μ I`, `b = Σ w aᵀ rhs + μ v⁰`, fixed vertices moved to the right.
    fn new(
        mesh: &Mesh,
        rows: &[Row],
        var: &[usize],
        nfree: usize,
        original: &[DVec3],
        ell: f64,
    ) -> Self {
        let nv = mesh.vertices.len();
        let mu = 1e-3 / (ell * ell);
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
        NormalEquations {
            nfree,
            diag,
            b,
            start,
            cols,
            vals,
        }
    }

    /// Jacobi-preconditioned conjugate gradients from `x`, the three coordinates at once.
    fn solve(&self, mut x: Vec<DVec3>) -> Vec<DVec3> {
        let (nfree, diag, b) = (self.nfree, &self.diag, &self.b);
        let (start, cols, vals) = (&self.start, &self.cols, &self.vals);
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
}
