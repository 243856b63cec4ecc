//! Distortion of a flat layout against its 3D surface: L2 and L∞ stretch (Sander, Snyder,
//! Gortler, Hoppe 2001, §3 "texture stretch metric"), L2 shear, and the angle defect (discrete
//! Gaussian curvature) of a mesh. These are the figures the thesis (seed 001, §2.5) reports for
//! every chart: 1.0 stretch and 0 shear for a perfect (isometric) flattening.
//!
//! Per triangle, with 3D corners q₁ q₂ q₃ and flat corners (s,t)ᵢ, the affine map from the flat
//! triangle onto the 3D one has partial derivatives S_s, S_t (Sander eq. 2); with a = S_s·S_s,
//! b = S_s·S_t, c = S_t·S_t its singular values are Γ, γ = √(½(a + c ± √((a − c)² + 4b²))).
//! The triangle's L2 stretch is √(½(a + c)) = √(½(Γ² + γ²)), its L∞ stretch Γ.
//!
//! Choices (where the papers leave them open):
//! - The flat layout is first scaled uniformly so that its area equals the 3D area (Sander
//!   §3: "we normalise"), so 1.0 means isometric whatever the layout's units.
//! - Whole-chart figures are weighted by 3D triangle area: L2 = √(Σ A·L2(T)² / Σ A), L∞ = max
//!   Γ; `combine` does the same across charts (L2 in quadrature, L∞ the maximum).
//! - Shear per triangle is (Γ − γ)/(Γ + γ): 0 for a conformal (angle-keeping) map, towards 1 for
//!   a triangle squashed flat; it does not depend on how the layout is rotated. L2 shear is its
//!   area-weighted root mean square. (ABF++ reports an L2 shear without restating the formula;
//!   this is the frame-independent form of it.)
//! - A flipped triangle (negative flat area) is measured through its mirror image and counted
//!   in [`Stretch::flipped`]; a flat triangle of zero area makes L2 and L∞ infinite (never NaN).
//!   A face whose `uv` does not have one point per corner, or whose index is out of range, is
//!   not measured and is counted as flipped, so a broken layout can never pass as isometric.
//! - Polygon faces are measured through the triangles of `face_triangles` (ear clipping in
//!   the face's plane), the same triangles `param` flattens.

use crate::geom::mesh::Mesh;
use crate::geom::polygon;
use glam::{DVec2, DVec3};
use std::borrow::Cow;
use std::f64::consts::PI;

/// Distortion figures of a flat layout (one chart, or a whole surface via `combine`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stretch {
    /// Area-weighted L2 stretch (1.0 = isometric).
    pub l2: f64,
    /// Worst triangle stretch Γ (1.0 = isometric).
    pub linf: f64,
    /// Area-weighted RMS shear (0.0 = conformal).
    pub shear_l2: f64,
    /// Triangles whose flat image is mirrored or collapsed (plus faces that could not be
    /// measured).
    pub flipped: usize,
    /// 3D area (mm²).
    pub area_3d: f64,
    /// Flat area before scaling to the 3D area (mm², in the layout's units).
    pub area_2d: f64,
}

/// Triangles of a face as corner-index triples (indices into `mesh.faces[f].verts`), in the
/// face's winding: a triangle is itself; a polygon is ear-clipped in its best-fit plane (Newell
/// normal). Fewer than three corners: none.
pub(crate) fn face_triangles(mesh: &Mesh, f: usize) -> Cow<'static, [[usize; 3]]> {
    let Some(face) = mesh.faces.get(f) else {
        return Cow::Borrowed(&[]);
    };
    let n = face.verts.len();
    if n < 3 {
        return Cow::Borrowed(&[]);
    }
    if n == 3 {
        return Cow::Borrowed(polygon::ONE_TRIANGLE);
    }
    let normal = mesh.newell(f).normalize_or_zero();
    if normal == DVec3::ZERO || !normal.is_finite() {
        return Cow::Owned((1..n - 1).map(|k| [0, k, k + 1]).collect());
    }
    let e1 = normal.any_orthonormal_vector();
    let e2 = normal.cross(e1);
    let flat: Vec<DVec2> = face
        .verts
        .iter()
        .map(|&v| {
            let p = mesh.vertices.get(v).copied().unwrap_or(DVec3::ZERO);
            DVec2::new(p.dot(e1), p.dot(e2))
        })
        .collect();
    polygon::triangulate(&flat)
}

/// Per-triangle figures before the area normalisation: (3D area, flat signed area, a, b, c)
/// where a, b, c are built from the flat-to-3D Jacobian of the unscaled layout.
struct TriMeasure {
    area_3d: f64,
    area_2d: f64,
    a: f64,
    b: f64,
    c: f64,
}

fn measure(q: [DVec3; 3], p: [DVec2; 3]) -> TriMeasure {
    let area_3d = 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).length();
    let (s, t) = ([p[0].x, p[1].x, p[2].x], [p[0].y, p[1].y, p[2].y]);
    let area_2d = 0.5 * ((s[1] - s[0]) * (t[2] - t[0]) - (s[2] - s[0]) * (t[1] - t[0]));
    if area_2d == 0.0 || !area_2d.is_finite() {
        return TriMeasure {
            area_3d,
            area_2d: 0.0,
            a: f64::INFINITY,
            b: 0.0,
            c: f64::INFINITY,
        };
    }
    let d = 2.0 * area_2d;
    let ss = (q[0] * (t[1] - t[2]) + q[1] * (t[2] - t[0]) + q[2] * (t[0] - t[1])) / d;
    let st = (q[0] * (s[2] - s[1]) + q[1] * (s[0] - s[2]) + q[2] * (s[1] - s[0])) / d;
    TriMeasure {
        area_3d,
        area_2d,
        a: ss.dot(ss),
        b: ss.dot(st),
        c: st.dot(st),
    }
}

/// Stretch and shear of the flat layout `uv` (per face of `faces`, per corner, any units)
/// against the mesh, after scaling `uv` to the 3D area.
pub fn stretch(mesh: &Mesh, faces: &[usize], uv: &[Vec<DVec2>]) -> Stretch {
    let mut tris: Vec<TriMeasure> = Vec::new();
    let mut unmeasured = 0usize;
    for (k, &f) in faces.iter().enumerate() {
        let (Some(face), Some(p)) = (mesh.faces.get(f), uv.get(k)) else {
            unmeasured += 1;
            continue;
        };
        if p.len() != face.verts.len() || face.verts.iter().any(|&v| v >= mesh.vertices.len()) {
            unmeasured += 1;
            continue;
        }
        for t in face_triangles(mesh, f).iter() {
            let q = t.map(|i| mesh.vertices[face.verts[i]]);
            let pp = t.map(|i| p[i]);
            tris.push(measure(q, pp));
        }
    }
    unmeasured += uv.len().saturating_sub(faces.len());
    let area_3d: f64 = tris.iter().map(|t| t.area_3d).sum();
    let area_2d: f64 = tris.iter().map(|t| t.area_2d.abs()).sum();
    let mut out = Stretch {
        flipped: unmeasured,
        area_3d,
        area_2d,
        ..Default::default()
    };
    if tris.is_empty() {
        return out;
    }
    // Scaling the layout by k divides S_s, S_t by k: a, b, c by k² = area_3d / area_2d.
    let k2 = if area_2d > 0.0 && area_3d > 0.0 {
        area_3d / area_2d
    } else {
        1.0
    };
    let (mut sum_l2, mut sum_shear, mut linf) = (0.0, 0.0, 0.0f64);
    for t in &tris {
        if t.area_2d <= 0.0 {
            out.flipped += 1;
        }
        let (a, b, c) = (t.a / k2, t.b / k2, t.c / k2);
        if !(a.is_finite() && c.is_finite()) {
            sum_l2 = f64::INFINITY;
            linf = f64::INFINITY;
            sum_shear += t.area_3d;
            continue;
        }
        let root = ((a - c) * (a - c) + 4.0 * b * b).sqrt();
        let big = (0.5 * (a + c + root)).max(0.0).sqrt();
        let small = (0.5 * (a + c - root)).max(0.0).sqrt();
        sum_l2 += t.area_3d * 0.5 * (a + c);
        linf = linf.max(big);
        let shear = if big + small > 0.0 {
            (big - small) / (big + small)
        } else {
            0.0
        };
        sum_shear += t.area_3d * shear * shear;
    }
    if area_3d > 0.0 {
        out.l2 = (sum_l2 / area_3d).sqrt();
        out.shear_l2 = (sum_shear / area_3d).sqrt();
    } else {
        // No 3D area at all: nothing to weigh by; report the worst stretch.
        out.l2 = if sum_l2.is_finite() {
            linf
        } else {
            f64::INFINITY
        };
        out.shear_l2 = 0.0;
    }
    out.linf = linf;
    out
}

/// Whole-surface figures from per-chart figures: L2 stretch and shear combined in quadrature
/// weighted by each chart's 3D area, L∞ the maximum, flips and areas summed. No parts (or no
/// area): all zero but the sums.
pub(crate) fn combine(parts: &[Stretch]) -> Stretch {
    let mut out = Stretch::default();
    let (mut l2, mut shear) = (0.0, 0.0);
    for p in parts {
        out.flipped += p.flipped;
        out.area_3d += p.area_3d;
        out.area_2d += p.area_2d;
        out.linf = out.linf.max(p.linf);
        l2 += p.area_3d * p.l2 * p.l2;
        shear += p.area_3d * p.shear_l2 * p.shear_l2;
    }
    if out.area_3d > 0.0 {
        out.l2 = (l2 / out.area_3d).sqrt();
        out.shear_l2 = (shear / out.area_3d).sqrt();
    }
    out
}

/// Angle at `a` of the triangle (a, b, c), robust for tiny and obtuse angles.
pub(crate) fn corner_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (u, v) = (b - a, c - a);
    u.cross(v).length().atan2(u.dot(v))
}

/// Angle defect per vertex: 2π − Σ corner angles for interior vertices (every edge around
/// them shared by exactly two faces), 0 on the boundary, at non-manifold edges and for unused
/// vertices. Polygon corners are summed over the triangles of `face_triangles`.
pub fn angle_defect(mesh: &Mesh) -> Vec<f64> {
    let nv = mesh.vertices.len();
    let mut sum = vec![0.0; nv];
    let mut used = vec![false; nv];
    let mut interior = vec![true; nv];
    for (f, face) in mesh.faces.iter().enumerate() {
        if face.verts.iter().any(|&v| v >= nv) {
            continue;
        }
        for t in face_triangles(mesh, f).iter() {
            let v = t.map(|i| face.verts[i]);
            let p = v.map(|i| mesh.vertices[i]);
            for k in 0..3 {
                sum[v[k]] += corner_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                used[v[k]] = true;
            }
        }
    }
    let topo = mesh.topology();
    for e in &topo.edges {
        if e.uses.len() != 2 {
            for &v in &e.verts {
                if v < nv {
                    interior[v] = false;
                }
            }
        }
    }
    (0..nv)
        .map(|v| {
            if used[v] && interior[v] && sum[v].is_finite() {
                2.0 * PI - sum[v]
            } else {
                0.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::mesh::Face;

    fn tri_mesh() -> Mesh {
        Mesh {
            vertices: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 1.0),
            ],
            faces: vec![Face {
                verts: vec![0, 1, 2],
                line: Some(3),
            }],
        }
    }

    #[test]
    fn isometric_layout_is_one_and_scale_does_not_matter() {
        let m = tri_mesh();
        let r = 2f64.sqrt();
        for scale in [1.0, 7.5] {
            let uv = vec![vec![
                DVec2::ZERO,
                DVec2::new(2.0, 0.0) * scale,
                DVec2::new(0.0, r) * scale,
            ]];
            let s = stretch(&m, &[0], &uv);
            assert!((s.l2 - 1.0).abs() < 1e-12, "{s:?}");
            assert!((s.linf - 1.0).abs() < 1e-12, "{s:?}");
            assert!(s.shear_l2.abs() < 1e-12);
            assert_eq!(s.flipped, 0);
            assert!((s.area_3d - r).abs() < 1e-12);
        }
    }

    #[test]
    fn anisotropic_layout_has_known_singular_values() {
        // Flat triangle stretched by 2 along x and 1/2 along y: same area, Γ = 2, γ = 1/2 for
        // the flat→3D map (lengths shrink by 2 along x, grow by 2 along y).
        let m = Mesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            faces: vec![Face {
                verts: vec![0, 1, 2],
                line: None,
            }],
        };
        let uv = vec![vec![
            DVec2::ZERO,
            DVec2::new(2.0, 0.0),
            DVec2::new(0.0, 0.5),
        ]];
        let s = stretch(&m, &[0], &uv);
        assert!((s.linf - 2.0).abs() < 1e-12, "{s:?}");
        assert!((s.l2 - (0.5f64 * (4.0 + 0.25)).sqrt()).abs() < 1e-12);
        assert!((s.shear_l2 - 1.5 / 2.5).abs() < 1e-12);
        // Mirrored: same figures, one flip.
        let uv = vec![vec![
            DVec2::ZERO,
            DVec2::new(0.0, 0.5),
            DVec2::new(2.0, 0.0),
        ]];
        let s2 = stretch(&m, &[0], &uv);
        assert_eq!(s2.flipped, 1);
        assert!((s2.linf - 2.0).abs() < 1e-12);
        // Collapsed: infinite, not NaN.
        let uv = vec![vec![DVec2::ZERO, DVec2::X, DVec2::new(2.0, 0.0)]];
        let s3 = stretch(&m, &[0], &uv);
        assert_eq!(s3.flipped, 1);
        assert!(s3.l2.is_infinite() && s3.linf.is_infinite());
        // Wrong corner count: not measured, counted.
        let s4 = stretch(&m, &[0], &[vec![DVec2::ZERO]]);
        assert_eq!(s4.flipped, 1);
    }

    #[test]
    fn combine_weights_by_area() {
        let a = Stretch {
            l2: 1.0,
            linf: 1.0,
            area_3d: 3.0,
            area_2d: 3.0,
            ..Default::default()
        };
        let b = Stretch {
            l2: 2.0,
            linf: 3.0,
            area_3d: 1.0,
            area_2d: 1.0,
            flipped: 2,
            ..Default::default()
        };
        let c = combine(&[a, b]);
        assert!((c.l2 - ((3.0 + 4.0) / 4.0f64).sqrt()).abs() < 1e-12);
        assert_eq!(c.linf, 3.0);
        assert_eq!(c.flipped, 2);
        assert_eq!(c.area_3d, 4.0);
        assert_eq!(combine(&[]), Stretch::default());
    }

    #[test]
    fn angle_defect_of_a_cube_corner_and_a_flat_fan() {
        // Closed cube (quads): every vertex has defect π/2.
        let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let cube = crate::surface::solids::cuboid(1.0, 1.0, 1.0);
        let d = angle_defect(&cube);
        assert_eq!(d.len(), 8);
        for x in d {
            assert!((x - PI / 2.0).abs() < 1e-12, "{x}");
        }
        // Open flat square: boundary vertices are 0.
        let sq = Mesh {
            vertices: vec![v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)],
            faces: vec![Face {
                verts: vec![0, 1, 2, 3],
                line: None,
            }],
        };
        assert_eq!(angle_defect(&sq), vec![0.0; 4]);
    }
}
