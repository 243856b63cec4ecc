//! Wavefront OBJ text of a mesh, optionally with texture coordinates: the one writer behind the
//! example patterns (`surface::solids`) and the `--surface-obj` / `--uv-obj` outputs.
//!
//! Choices: the caller picks how a coordinate is written ([`exact`]: the shortest round-trip
//! representation, so a read-back is exact; [`rounded`]: to 1e-9 mm, for hand-readable
//! generated files); faces keep their vertex order; texture coordinates are given per face
//! corner — a vertex on a seam has one `vt` per piece it belongs to — and equal consecutive
//! corners are not merged, so face `f` corner `i` is `vt` number (sum of earlier faces'
//! corners) + i + 1. Indices are written 1-based, as OBJ counts.

use crate::geom::mesh::Mesh;
use glam::DVec2;
use std::fmt::Write as _;

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
    if let Some(uv) = uv {
        for p in uv.iter().flatten() {
            let _ = writeln!(s, "vt {} {}", coord(p.x), coord(p.y));
        }
    }
    let mut t = 0usize;
    for (fi, f) in mesh.faces.iter().enumerate() {
        s.push('f');
        for (i, &v) in f.verts.iter().enumerate() {
            match uv {
                Some(_) => {
                    let _ = write!(s, " {}/{}", v + 1, t + i + 1);
                }
                None => {
                    let _ = write!(s, " {}", v + 1);
                }
            }
        }
        s.push('\n');
        if uv.is_some() {
            t += mesh.faces[fi].verts.len();
        }
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
