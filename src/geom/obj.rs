//! Wavefront OBJ text of a mesh, optionally with texture coordinates: the one writer behind the
//! example patterns (`surface::solids`) and the `--surface-obj` / `--uv-obj` outputs.
//!
//! Choices: the caller picks how a coordinate is written ([`exact`]: the shortest round-trip
//! representation, so a read-back is exact; [`rounded`]: to 1e-9 mm, for hand-readable
//! generated files); faces keep their vertex order; texture coordinates are shared as every
//! exporter shares them: the corners of one vertex that lie at the same flat point (within
//! [`UV_SAME`]) get one `vt`, so a piece is one UV island, and a vertex on a seam or a slit has
//! one `vt` per side. `vt` are numbered in order of first use (face order, then corner order),
//! which keeps the output deterministic. Indices are written 1-based, as OBJ counts.

use crate::geom::mesh::Mesh;
use glam::DVec2;
use std::fmt::Write as _;

/// Corners of one vertex this close in the flat (mm) share a `vt`: far below any cut
/// tolerance, far above the rounding of laying out one piece's faces one after another.
pub const UV_SAME: f64 = 1e-6;

/// The OBJ text of `mesh`, headed by `# comment` lines (one per line of `comment`), each
/// coordinate written by `coord`. With `uv` (one 2D point per corner of each face, in mm)
/// every face is written `f v/vt …`.
///
/// Returns `None` when `uv` does not have one point per corner of every face.
pub fn write(
    mesh: &Mesh,
    uv: Option<&[Vec<DVec2>]>,
    comment: &str,
    coord: fn(f64) -> String,
) -> Option<String> {
    if let Some(uv) = uv {
        if uv.len() != mesh.faces.len()
            || uv
                .iter()
                .zip(&mesh.faces)
                .any(|(c, f)| c.len() != f.verts.len())
        {
            return None;
        }
    }
    let mut s = String::new();
    for line in comment.lines() {
        let _ = writeln!(s, "# {line}");
    }
    for v in &mesh.vertices {
        let _ = writeln!(s, "v {} {} {}", coord(v.x), coord(v.y), coord(v.z));
    }
    // The `vt` of every corner: a vertex's corners at one flat point share theirs.
    let mut vts: Vec<DVec2> = Vec::new();
    let mut corner_vt: Vec<Vec<usize>> = Vec::new();
    if let Some(uv) = uv {
        let mut of_vertex: Vec<Vec<usize>> = vec![Vec::new(); mesh.vertices.len()];
        for (f, points) in mesh.faces.iter().zip(uv) {
            let mut ids = Vec::with_capacity(points.len());
            for (&v, &p) in f.verts.iter().zip(points) {
                let known = of_vertex.get(v).and_then(|list| {
                    list.iter()
                        .copied()
                        .find(|&t| vts[t].distance(p) <= UV_SAME)
                });
                let id = known.unwrap_or_else(|| {
                    vts.push(p);
                    if let Some(list) = of_vertex.get_mut(v) {
                        list.push(vts.len() - 1);
                    }
                    vts.len() - 1
                });
                ids.push(id);
            }
            corner_vt.push(ids);
        }
    }
    for p in &vts {
        let _ = writeln!(s, "vt {} {}", coord(p.x), coord(p.y));
    }
    for (fi, f) in mesh.faces.iter().enumerate() {
        s.push('f');
        for (i, &v) in f.verts.iter().enumerate() {
            match corner_vt.get(fi) {
                Some(ids) => {
                    let _ = write!(s, " {}/{}", v + 1, ids[i] + 1);
                }
                None => {
                    let _ = write!(s, " {}", v + 1);
                }
            }
        }
        s.push('\n');
    }
    Some(s)
}

/// A coordinate in the shortest representation that reads back exactly (`{}` of an `f64`).
pub fn exact(v: f64) -> String {
    format!("{v}")
}

/// A coordinate rounded to 1e-9 (mm), `0` for zero (no `-0`).
pub fn rounded(v: f64) -> String {
    let r = (v * 1e9).round() / 1e9;
    if r == 0.0 {
        "0".into()
    } else {
        format!("{r}")
    }
}
