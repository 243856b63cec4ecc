//! Polyhedral meshes from Wavefront OBJ files, read through `tobj`, keeping polygon faces (a
//! planar quad stays one face, one panel of the pattern).
//!
//! [`read`] parses: it scans the text once itself to know the line of every vertex and face (so
//! errors can name it) and to reject what tobj would accept silently (NaN or infinite
//! coordinates, binary files, files without faces), then loads through tobj without
//! triangulation. Vertices with bit-identical coordinates are welded (tobj keeps each `o`/`g`
//! group's vertices apart, and many exporters duplicate vertices along seams).
//!
//! [`validate`] makes the panels flatcut can unfold, with these documented repairs, each
//! reported as a warning:
//! - consecutive repeated vertices in a face are dropped; faces left with fewer than three
//!   vertices, or with (relatively) zero area, are removed: they carry nothing to cut;
//! - non-planar polygons (a vertex off the face plane by more than 1e-6 of the face size) are
//!   split into triangles by ear clipping, since a rigid panel must be flat;
//! - faces wound against their neighbours are flipped; closed shells are wound outwards (positive
//!   signed volume), open ones keep the winding most of their faces had.
//!
//! And these errors: an edge shared by more than two faces (non-manifold), a non-orientable
//! mesh, no faces left.

use super::SurfaceError;
use crate::geom::mesh::{Face, Mesh, Topology};
use crate::geom::polygon;
use glam::{DVec2, DVec3};
use std::collections::{HashMap, VecDeque};
use std::path::{Path, PathBuf};

/// A mesh as read from the file, before validation, in file units.
#[derive(Debug, Clone, PartialEq)]
pub struct RawMesh {
    pub path: PathBuf,
    pub mesh: Mesh,
    /// Vertices welded because they had identical coordinates.
    pub welded: usize,
    /// The model's textures (OBJ `mtllib` / `usemtl` / `vt`), if it has any that could be
    /// read, and what could not be read ([`super::texture`]).
    pub texture: Option<super::texture::Texture>,
    pub texture_warnings: Vec<String>,
}

fn parse_err(path: &Path, line: Option<usize>, message: impl Into<String>) -> SurfaceError {
    SurfaceError::Parse {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Parse an OBJ file.
pub fn read(path: &Path) -> Result<RawMesh, SurfaceError> {
    let bytes =
        crate::geom::input::read_bytes(path, crate::geom::input::DATA_LIMIT).map_err(|source| {
            SurfaceError::Io {
                path: path.to_path_buf(),
                source,
            }
        })?;
    let text = String::from_utf8(bytes).map_err(|_| {
        parse_err(
            path,
            None,
            "not an OBJ file: it is not text (binary data); export the model as Wavefront OBJ",
        )
    })?;
    parse(&text, path)
}

/// Parse OBJ text; `path` is only used in messages.
pub fn parse(text: &str, path: &Path) -> Result<RawMesh, SurfaceError> {
    if text.contains('\0') {
        return Err(parse_err(
            path,
            None,
            "not an OBJ file: it contains binary data; export the model as Wavefront OBJ",
        ));
    }
    let face_lines = prescan(text, path)?;
    let opts = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::BufReader::new(text.as_bytes());
    let (models, _materials) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Ok((Vec::new(), Default::default())))
            .map_err(|e| parse_err(path, None, format!("OBJ reader: {e}")))?;

    let (mut mesh, welded) = weld(&models, path)?;
    // tobj keeps faces in file order; name their lines when the counts agree.
    if mesh.faces.len() == face_lines.len() {
        for (f, l) in mesh.faces.iter_mut().zip(&face_lines) {
            f.line = Some(*l);
        }
    }
    let (texture, texture_warnings) = super::texture::read(text, path, &mesh);
    Ok(RawMesh {
        path: path.to_path_buf(),
        mesh,
        welded,
        texture,
        texture_warnings,
    })
}

/// Pre-scan: vertex count, lines of faces, finite coordinates, valid indices; the line
/// (1-based) of each face.
fn prescan(text: &str, path: &Path) -> Result<Vec<usize>, SurfaceError> {
    // Pre-scan: vertex count, lines of faces, finite coordinates, valid indices.
    let mut n_vertices = 0usize;
    let mut face_lines = Vec::new();
    for (k, raw_line) in text.lines().enumerate() {
        let line_no = k + 1;
        let line = raw_line.trim();
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let coords: Vec<&str> = words.collect();
                if coords.len() < 3 {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        format!("vertex needs three coordinates, found `{line}`"),
                    ));
                }
                for c in &coords[..3] {
                    match c.parse::<f64>() {
                        Ok(x) if x.is_finite() => {}
                        Ok(_) => {
                            return Err(SurfaceError::NonFinite {
                                path: path.to_path_buf(),
                                line: line_no,
                                index: n_vertices,
                                text: (*c).to_string(),
                            })
                        }
                        Err(_) => {
                            return Err(parse_err(
                                path,
                                Some(line_no),
                                format!("vertex coordinate `{c}` is not a number"),
                            ))
                        }
                    }
                }
                // tobj takes `x y z`, `x y z w` (w not 0) or `x y z r g b`.
                let extra_ok = coords[3..]
                    .iter()
                    .all(|c| c.parse::<f64>().is_ok_and(f64::is_finite))
                    && (coords.len() != 4 || coords[3].parse::<f64>().is_ok_and(|w| w != 0.0));
                if !matches!(coords.len(), 3 | 4 | 6) || !extra_ok {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        format!(
                            "vertex has {} numbers; a vertex is `v x y z`, `v x y z w` (w not 0) or `v x y z r g b`",
                            coords.len()
                        ),
                    ));
                }
                n_vertices += 1;
            }
            Some(kw @ ("f" | "l")) => {
                let refs: Vec<&str> = words.collect();
                for r in &refs {
                    let first = r.split('/').next().unwrap_or("");
                    let ok = match first.parse::<i64>() {
                        Ok(i) if i > 0 => (i as usize) <= n_vertices,
                        Ok(i) if i < 0 => i.unsigned_abs() as usize <= n_vertices,
                        _ => false,
                    };
                    if !ok {
                        return Err(parse_err(
                            path,
                            Some(line_no),
                            format!(
                                "face refers to vertex `{first}`, but only {n_vertices} vertices are defined before this line"
                            ),
                        ));
                    }
                }
                if refs.len() >= 3 {
                    face_lines.push(line_no);
                } else if kw == "f" {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        format!("face needs at least three vertices, found {}", refs.len()),
                    ));
                }
            }
            Some(w) if w.starts_with('#') => {}
            Some(
                "vt" | "vn" | "vp" | "o" | "g" | "s" | "mtllib" | "usemtl" | "p" | "cstype" | "deg"
                | "curv" | "curv2" | "surf" | "parm" | "trim" | "hole" | "end" | "mg" | "bevel"
                | "c_interp" | "d_interp" | "lod" | "shadow_obj" | "trace_obj",
            )
            | None => {}
            Some(other) => {
                if other.chars().any(|c| c.is_control()) || !other.is_ascii() {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        "not an OBJ file: unexpected characters; export the model as Wavefront OBJ",
                    ));
                }
                // Unknown statements are ignored, as OBJ readers do.
            }
        }
    }
    if face_lines.is_empty() {
        return Err(parse_err(
            path,
            None,
            if n_vertices == 0 {
                "not an OBJ file: no vertices (`v`) and no faces (`f`) found".to_string()
            } else {
                format!("no faces: {n_vertices} vertices but no `f` lines; flatcut needs a surface made of faces")
            },
        ));
    }

    Ok(face_lines)
}

/// The models' vertices welded where they coincide exactly, and their faces; how many
/// vertices were welded.
fn weld(models: &[tobj::Model], path: &Path) -> Result<(Mesh, usize), SurfaceError> {
    let mut mesh = Mesh::default();
    let mut weld: HashMap<[u64; 3], usize> = HashMap::new();
    let mut welded = 0usize;
    for model in models {
        let m = &model.mesh;
        let mut local = Vec::with_capacity(m.positions.len() / 3);
        for p in m.positions.chunks_exact(3) {
            let v = DVec3::new(p[0], p[1], p[2]);
            // +0.0 and -0.0 are the same point.
            let key = [
                (v.x + 0.0).to_bits(),
                (v.y + 0.0).to_bits(),
                (v.z + 0.0).to_bits(),
            ];
            let id = match weld.get(&key) {
                Some(&id) => {
                    welded += 1;
                    id
                }
                None => {
                    mesh.vertices.push(v);
                    weld.insert(key, mesh.vertices.len() - 1);
                    mesh.vertices.len() - 1
                }
            };
            local.push(id);
        }
        let arities: Vec<usize> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut at = 0usize;
        for a in arities {
            let Some(idx) = m.indices.get(at..at + a) else {
                return Err(parse_err(
                    path,
                    None,
                    "OBJ reader returned a truncated face",
                ));
            };
            let verts = idx
                .iter()
                .map(|&i| local.get(i as usize).copied())
                .collect::<Option<Vec<usize>>>()
                .ok_or_else(|| parse_err(path, None, "face refers to a missing vertex"))?;
            at += a;
            mesh.faces.push(Face { verts, line: None });
        }
    }
    Ok((mesh, welded))
}

fn lines_of(mesh: &Mesh, faces: &[usize], limit: usize) -> String {
    let mut v: Vec<String> = faces
        .iter()
        .take(limit)
        .map(|&f| match mesh.faces[f].line {
            Some(l) => l.to_string(),
            None => format!("face {}", f + 1),
        })
        .collect();
    if faces.len() > limit {
        v.push(format!("… {} more", faces.len() - limit));
    }
    v.join(", ")
}

fn fmt_point(p: DVec3) -> String {
    format!("({:.6}, {:.6}, {:.6})", p.x, p.y, p.z)
}

/// Scale to millimetres, repair what can be repaired (with warnings) and refuse what cannot.
pub fn validate(raw: RawMesh, scale: f64) -> Result<(Mesh, Vec<String>), SurfaceError> {
    let path = raw.path;
    let mut mesh = raw.mesh;
    let mut warnings = Vec::new();
    if raw.welded > 0 {
        warnings.push(format!(
            "{}: welded {} duplicate vertices with identical coordinates",
            path.display(),
            raw.welded
        ));
    }
    for v in &mut mesh.vertices {
        *v *= scale;
    }
    let (lo, hi) = mesh.bounds();
    let size = (hi - lo).length();
    if size.is_nan() || size <= 0.0 || !size.is_finite() {
        return Err(SurfaceError::Invalid {
            path,
            message: "all vertices are at the same point (or the scale makes them so)".into(),
        });
    }

    // 1. Repeated vertices and zero-area faces.
    let mut degenerate = Vec::new();
    let mut kept = Vec::with_capacity(mesh.faces.len());
    let old = std::mem::take(&mut mesh.faces);
    let area_eps = 1e-12 * size * size;
    for face in old {
        let mut verts = face.verts.clone();
        verts.dedup();
        while verts.len() > 1 && verts.first() == verts.last() {
            verts.pop();
        }
        let mut sorted = verts.clone();
        sorted.sort_unstable();
        sorted.dedup();
        let f = Face {
            verts,
            line: face.line,
        };
        let ok = sorted.len() == f.verts.len() && f.verts.len() >= 3 && {
            mesh.faces.push(f.clone());
            let a = mesh.face_area(mesh.faces.len() - 1);
            mesh.faces.pop();
            a > area_eps
        };
        if ok {
            kept.push(f);
        } else {
            degenerate.push(face.line);
        }
    }
    mesh.faces = kept;
    if !degenerate.is_empty() {
        let lines: Vec<String> = degenerate
            .iter()
            .take(8)
            .map(|l| l.map_or("?".into(), |l| l.to_string()))
            .collect();
        warnings.push(format!(
            "{}: removed {} zero-area or degenerate faces (lines {}{})",
            path.display(),
            degenerate.len(),
            lines.join(", "),
            if degenerate.len() > 8 { ", …" } else { "" }
        ));
    }
    if mesh.faces.is_empty() {
        return Err(SurfaceError::Invalid {
            path,
            message: "no faces with an area are left".into(),
        });
    }

    // 2. Non-planar polygons become triangles.
    let mut split = Vec::new();
    let old = std::mem::take(&mut mesh.faces);
    for face in old {
        if face.verts.len() > 3 {
            let pts: Vec<DVec3> = face.verts.iter().map(|&v| mesh.vertices[v]).collect();
            let (planar, flat) = planarity(&pts);
            if !planar || !polygon::is_simple_ring(&flat) {
                split.push(face.line);
                for t in polygon::triangulate(&flat).iter() {
                    mesh.faces.push(Face {
                        verts: t.iter().map(|&k| face.verts[k]).collect(),
                        line: face.line,
                    });
                }
                continue;
            }
        }
        mesh.faces.push(face);
    }
    if !split.is_empty() {
        let lines: Vec<String> = split
            .iter()
            .take(8)
            .map(|l| l.map_or("?".into(), |l| l.to_string()))
            .collect();
        warnings.push(format!(
            "{}: split {} non-planar or self-crossing polygons into triangles (lines {}{})",
            path.display(),
            split.len(),
            lines.join(", "),
            if split.len() > 8 { ", …" } else { "" }
        ));
    }

    // 3. Non-manifold edges.
    let topo = mesh.topology();
    if let Some(e) = topo.edges.iter().find(|e| e.uses.len() > 2) {
        let faces: Vec<usize> = e.uses.iter().map(|u| u.0).collect();
        return Err(SurfaceError::NonManifold {
            path,
            first_line: mesh.faces[faces[0]].line,
            a: fmt_point(mesh.vertices[e.verts[0]]),
            b: fmt_point(mesh.vertices[e.verts[1]]),
            count: e.uses.len(),
            lines: lines_of(&mesh, &faces, 6),
        });
    }

    // 4. Orientation.
    let flipped = orient(&mut mesh, &topo).map_err(|f| SurfaceError::NonOrientable {
        path: path.clone(),
        line: mesh.faces[f].line,
    })?;
    if !flipped.is_empty() {
        warnings.push(format!(
            "{}: reversed the winding of {} faces to match their neighbours (lines {})",
            path.display(),
            flipped.len(),
            lines_of(&mesh, &flipped, 8)
        ));
    }
    Ok((mesh, warnings))
}

/// Whether a polygon is planar (within 1e-6 of its size), and its points in its plane.
fn planarity(pts: &[DVec3]) -> (bool, Vec<DVec2>) {
    let n = pts.len();
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        normal += pts[i].cross(pts[(i + 1) % n]);
    }
    let normal = normal.normalize_or_zero();
    let c = pts.iter().copied().sum::<DVec3>() / n as f64;
    let size = pts.iter().map(|p| p.distance(c)).fold(0.0, f64::max);
    let off = pts
        .iter()
        .map(|p| (*p - c).dot(normal).abs())
        .fold(0.0, f64::max);
    let x = (pts[1] - pts[0]).normalize_or_zero();
    let y = normal.cross(x);
    let flat = pts
        .iter()
        .map(|p| DVec2::new((*p - pts[0]).dot(x), (*p - pts[0]).dot(y)))
        .collect();
    (off <= 1e-6 * size, flat)
}

/// Wind every face consistently with its neighbours; returns the faces flipped, or the face
/// where a non-orientable band closes.
fn orient(mesh: &mut Mesh, topo: &Topology) -> Result<Vec<usize>, usize> {
    let nf = mesh.faces.len();
    let mut flip: Vec<Option<bool>> = vec![None; nf];
    let mut flipped = Vec::new();
    let mut boundary_face = vec![false; nf];
    for e in &topo.edges {
        if e.uses.len() == 1 {
            boundary_face[e.uses[0].0] = true;
        }
    }
    for start in 0..nf {
        if flip[start].is_some() {
            continue;
        }
        let mut component = vec![start];
        flip[start] = Some(false);
        let mut queue = VecDeque::from([start]);
        while let Some(f) = queue.pop_front() {
            let ff = flip[f].unwrap_or(false);
            for (i, &e) in topo.face_edges[f].iter().enumerate() {
                let edge = &topo.edges[e];
                if edge.uses.len() != 2 {
                    continue;
                }
                let &(g, j) = edge.uses.iter().find(|u| **u != (f, i)).unwrap_or(&(f, i));
                if g == f {
                    continue;
                }
                let (a, _) = Topology::corner_verts(mesh, f, i);
                let (c, _) = Topology::corner_verts(mesh, g, j);
                // Consistent neighbours traverse the shared edge in opposite directions.
                let same_dir = a == c;
                let want = ff ^ same_dir;
                match flip[g] {
                    None => {
                        flip[g] = Some(want);
                        component.push(g);
                        queue.push_back(g);
                    }
                    Some(have) if have != want => return Err(g),
                    Some(_) => {}
                }
            }
        }
        // Choose the component's winding.
        let closed = component.iter().all(|&f| !boundary_face[f]);
        let invert = if closed {
            let mut vol = 0.0;
            for &f in &component {
                let p = mesh.face_points(f);
                let s = if flip[f] == Some(true) { -1.0 } else { 1.0 };
                for k in 1..p.len() - 1 {
                    vol += s * p[0].dot(p[k].cross(p[k + 1]));
                }
            }
            vol < 0.0
        } else {
            let flips = component.iter().filter(|&&f| flip[f] == Some(true)).count();
            2 * flips > component.len()
        };
        for &f in &component {
            let fl = flip[f] == Some(true);
            if fl != invert {
                mesh.faces[f].verts.reverse();
                flipped.push(f);
            }
        }
    }
    flipped.sort_unstable();
    Ok(flipped)
}

/// Figures for `flatcut check`, in file units.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MeshStats {
    pub vertices: usize,
    pub faces: usize,
    pub edges: usize,
    pub boundary_loops: usize,
    pub non_manifold_edges: usize,
    /// Largest |2π − Σ angles| over interior vertices, in degrees: 0 for a developable mesh.
    pub max_angle_defect_deg: f64,
    pub non_planar_faces: usize,
    /// The bounding box's sides (x, y, z) in file units.
    pub extent: [f64; 3],
}

/// Count what `flatcut check` reports, on a raw (unvalidated) mesh.
pub fn stats(raw: &RawMesh) -> MeshStats {
    let mesh = &raw.mesh;
    let topo = mesh.topology();
    let mut angle_sum = vec![0.0f64; mesh.vertices.len()];
    let mut on_boundary = vec![false; mesh.vertices.len()];
    for e in &topo.edges {
        if e.uses.len() != 2 {
            on_boundary[e.verts[0]] = true;
            on_boundary[e.verts[1]] = true;
        }
    }
    let mut used = vec![false; mesh.vertices.len()];
    let mut non_planar = 0;
    for (f, face) in mesh.faces.iter().enumerate() {
        let n = face.verts.len();
        for i in 0..n {
            let v = face.verts[i];
            used[v] = true;
            let p = mesh.vertices[v];
            let a = mesh.vertices[face.verts[(i + n - 1) % n]] - p;
            let b = mesh.vertices[face.verts[(i + 1) % n]] - p;
            if a.length_squared() > 0.0 && b.length_squared() > 0.0 {
                angle_sum[v] += a.angle_between(b);
            }
        }
        if n > 3 && !planarity(&mesh.face_points(f)).0 {
            non_planar += 1;
        }
    }
    let max_defect = (0..mesh.vertices.len())
        .filter(|&v| used[v] && !on_boundary[v])
        .map(|v| (std::f64::consts::TAU - angle_sum[v]).abs())
        .fold(0.0, f64::max);
    MeshStats {
        vertices: mesh.vertices.len(),
        faces: mesh.faces.len(),
        edges: topo.edges.len(),
        boundary_loops: topo.boundary_loops(mesh),
        non_manifold_edges: topo.edges.iter().filter(|e| e.uses.len() > 2).count(),
        max_angle_defect_deg: max_defect.to_degrees(),
        non_planar_faces: non_planar,
        extent: super::size::extent(mesh).to_array(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

    fn load(text: &str) -> Result<(Mesh, Vec<String>), SurfaceError> {
        validate(parse(text, Path::new("t.obj"))?, 1.0)
    }

    #[test]
    fn cube_keeps_quads_and_is_outward() {
        let (m, w) = load(CUBE).unwrap();
        assert!(w.is_empty(), "{w:?}");
        assert_eq!(m.faces.len(), 6);
        assert!(m.faces.iter().all(|f| f.verts.len() == 4));
        assert_eq!(m.faces[0].line, Some(9));
        // Bottom face normal points down (outwards).
        assert!((m.face_normal(0) - DVec3::NEG_Z).length() < 1e-12);
        let s = stats(&parse(CUBE, Path::new("t.obj")).unwrap());
        assert_eq!(
            (s.vertices, s.faces, s.edges, s.boundary_loops),
            (8, 6, 12, 0)
        );
        assert!((s.max_angle_defect_deg - 90.0).abs() < 1e-9);
    }

    #[test]
    fn inward_cube_is_turned_outward_with_warning() {
        let inv = CUBE
            .lines()
            .map(|l| {
                if let Some(rest) = l.strip_prefix("f ") {
                    let mut v: Vec<&str> = rest.split(' ').collect();
                    v.reverse();
                    format!("f {}", v.join(" "))
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        let (m, w) = load(&inv).unwrap();
        assert!((m.face_normal(0) - DVec3::NEG_Z).length() < 1e-12);
        assert_eq!(w.len(), 1, "{w:?}");
    }

    #[test]
    fn one_flipped_face_is_repaired() {
        let bad = CUBE.replace("f 5 6 7 8", "f 8 7 6 5");
        let (m, w) = load(&bad).unwrap();
        assert!((m.face_normal(1) - DVec3::Z).length() < 1e-12);
        assert!(w[0].contains("reversed the winding of 1 faces"), "{w:?}");
        assert!(w[0].contains("10"), "{w:?}");
    }

    #[test]
    fn nan_names_the_line() {
        let e = load("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n").unwrap_err();
        let s = e.to_string();
        assert!(s.starts_with("t.obj:2:"), "{s}");
        assert!(s.contains("not a finite number"), "{s}");
    }

    #[test]
    fn not_an_obj() {
        let e = load("hello world\nthis is text\n").unwrap_err();
        assert!(e.to_string().contains("not an OBJ file"), "{e}");
        let e = load("v 0 0 0\n").unwrap_err();
        assert!(e.to_string().contains("no faces"), "{e}");
        let e = load("v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap_err();
        assert!(e.to_string().starts_with("t.obj:3:"), "{e}");
    }

    #[test]
    fn non_manifold_edge_is_an_error() {
        let t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
        let e = load(t).unwrap_err();
        let s = e.to_string();
        assert!(s.contains("shared by 3 faces"), "{s}");
        assert!(s.contains("6, 7, 8"), "{s}");
    }

    #[test]
    fn zero_area_faces_are_dropped_with_warning() {
        let t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n";
        let (m, w) = load(t).unwrap();
        assert_eq!(m.faces.len(), 1);
        assert!(w.iter().any(|w| w.contains("lines 6")), "{w:?}");
    }

    #[test]
    fn non_planar_quad_is_split() {
        let t = "v 0 0 0\nv 1 0 0\nv 1 1 0.3\nv 0 1 0\nf 1 2 3 4\n";
        let (m, w) = load(t).unwrap();
        assert_eq!(m.faces.len(), 2);
        assert!(w[0].contains("non-planar"));
    }

    #[test]
    fn groups_are_welded() {
        let t =
            "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 4 6 5\n";
        let (m, _) = load(t).unwrap();
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(
            m.topology()
                .edges
                .iter()
                .filter(|e| e.uses.len() == 2)
                .count(),
            1
        );
        assert_eq!(m.faces[1].line, Some(10));
    }
}
