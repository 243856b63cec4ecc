//! STL files (binary and ASCII), the triangle soups of 3D printing, welded into an indexed
//! mesh: corners with identical coordinates become one vertex (see `weld.rs`). The
//! format is 3D Systems' *StereoLithography Interface Specification* (1989): binary, an 80-byte
//! header, a little-endian `u32` triangle count, then 50 bytes per triangle (normal, three
//! corners as `f32`, a `u16` attribute); ASCII, `solid name`, then per triangle `facet normal
//! nx ny nz`, `outer loop`, three `vertex x y z`, `endloop`, `endfacet`, and `endsolid`.
//!
//! Choices: the normals are ignored (the mesh's winding is checked and repaired by
//! [`super::obj::validate`] like an OBJ's); a loop of more than three vertices is kept as a
//! polygon (some writers emit them); several `solid` blocks in one file are read as one mesh;
//! the binary file's size must match its triangle count exactly. Errors name the line (ASCII)
//! or the triangle, counted from 1 (binary).

use super::obj::RawMesh;
use super::weld::{coord, err, Welder};
use super::SurfaceError;
use glam::DVec3;
use std::path::Path;

/// Whether `bytes` are a binary STL: 84 bytes of header and count, then exactly 50 bytes per
/// triangle counted.
pub fn is_binary(bytes: &[u8]) -> bool {
    if bytes.len() < 84 {
        return false;
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    bytes.len() as u64 == 84 + 50 * n
}

/// Parse an STL file, binary or ASCII; `path` is used in messages.
pub fn parse(bytes: &[u8], path: &Path) -> Result<RawMesh, SurfaceError> {
    if is_binary(bytes) {
        return binary(bytes, path);
    }
    let text = std::str::from_utf8(bytes)
        .ok()
        .filter(|t| !t.contains('\0'));
    match text {
        Some(t) if t.trim_start().to_ascii_lowercase().starts_with("solid") => ascii(t, path),
        _ if bytes.len() >= 84 => {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
            Err(err(
                path,
                None,
                format!(
                    "broken binary STL: the header counts {n} triangles ({} bytes), but the file has {} bytes",
                    84 + 50 * n,
                    bytes.len()
                ),
            ))
        }
        _ => Err(err(
            path,
            None,
            "not an STL file: neither an ASCII STL (beginning with `solid`) nor a binary one (84 bytes of header and count, 50 per triangle)",
        )),
    }
}

fn binary(bytes: &[u8], path: &Path) -> Result<RawMesh, SurfaceError> {
    let mut w = Welder::default();
    let f32_at =
        |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let n = (bytes.len() - 84) / 50;
    for t in 0..n {
        let base = 84 + 50 * t + 12;
        let mut verts = Vec::with_capacity(3);
        for c in 0..3 {
            let o = base + 12 * c;
            let p = [f32_at(o), f32_at(o + 4), f32_at(o + 8)];
            if let Some(bad) = p.iter().find(|x| !x.is_finite()) {
                return Err(err(
                    path,
                    None,
                    format!(
                        "triangle {}, corner {}: a coordinate is not a finite number ({bad}); fix or remove it",
                        t + 1,
                        c + 1
                    ),
                ));
            }
            verts.push(w.vertex(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)));
        }
        w.face(verts, None);
    }
    w.finish(path)
}

fn ascii(text: &str, path: &Path) -> Result<RawMesh, SurfaceError> {
    let mut w = Welder::default();
    // The loop being read: its corners and the line of `outer loop`.
    let mut open: Option<(Vec<usize>, usize)> = None;
    let mut corners = 0usize;
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let mut words = raw.split_whitespace();
        let Some(word) = words.next() else { continue };
        match word.to_ascii_lowercase().as_str() {
            "solid" | "endsolid" | "facet" | "endfacet" => {}
            "outer" => {
                if open.is_some() {
                    return Err(err(
                        path,
                        Some(line),
                        "`outer loop` inside another loop: a facet is not closed with `endloop`",
                    ));
                }
                open = Some((Vec::new(), line));
            }
            "vertex" => {
                let Some((verts, _)) = open.as_mut() else {
                    return Err(err(
                        path,
                        Some(line),
                        "`vertex` outside `outer loop` … `endloop`",
                    ));
                };
                let c: Vec<&str> = words.collect();
                if c.len() != 3 {
                    return Err(err(
                        path,
                        Some(line),
                        format!("vertex needs three coordinates, found `{}`", raw.trim()),
                    ));
                }
                let mut p = [0.0; 3];
                for (i, t) in c.iter().enumerate() {
                    p[i] = coord(path, Some(line), corners, t)?;
                }
                corners += 1;
                verts.push(w.vertex(DVec3::from_array(p)));
            }
            "endloop" => {
                let Some((verts, at)) = open.take() else {
                    return Err(err(path, Some(line), "`endloop` without `outer loop`"));
                };
                if verts.len() < 3 {
                    return Err(err(
                        path,
                        Some(at),
                        format!("facet needs at least three vertices, found {}", verts.len()),
                    ));
                }
                w.face(verts, Some(at));
            }
            other => {
                return Err(err(
                    path,
                    Some(line),
                    format!("not an ASCII STL line: unexpected `{other}` (expected solid, facet, outer loop, vertex, endloop, endfacet or endsolid)"),
                ));
            }
        }
    }
    if let Some((_, at)) = open {
        return Err(err(
            path,
            Some(at),
            "the file ends inside this facet's loop (no `endloop`)",
        ));
    }
    w.finish(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square as two triangles, ASCII.
    const SQUARE: &str = "solid sq\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid sq\n";

    fn to_binary(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = vec![0u8; 80];
        b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for c in t {
                for x in c {
                    b.extend_from_slice(&x.to_le_bytes());
                }
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    }

    #[test]
    fn ascii_and_binary_weld_to_the_same_mesh() {
        let a = parse(SQUARE.as_bytes(), Path::new("a.stl")).unwrap();
        assert_eq!(
            (a.mesh.vertices.len(), a.mesh.faces.len(), a.welded),
            (4, 2, 2)
        );
        assert_eq!(a.mesh.faces[1].line, Some(10));
        let b = to_binary(&[
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        ]);
        let b = parse(&b, Path::new("b.stl")).unwrap();
        assert_eq!(a.mesh.vertices, b.mesh.vertices);
        assert_eq!(
            a.mesh.faces.iter().map(|f| &f.verts).collect::<Vec<_>>(),
            b.mesh.faces.iter().map(|f| &f.verts).collect::<Vec<_>>()
        );
    }

    #[test]
    fn broken_files_name_the_file_and_place() {
        let mut b = to_binary(&[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]]);
        b.truncate(120);
        let e = parse(&b, Path::new("b.stl")).unwrap_err().to_string();
        assert!(e.starts_with("b.stl: broken binary STL"), "{e}");
        let b = to_binary(&[[[0.0, f32::NAN, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]]);
        let e = parse(&b, Path::new("b.stl")).unwrap_err().to_string();
        assert!(e.contains("triangle 1, corner 1"), "{e}");
        let t = SQUARE.replace(
            "vertex 1 1 0\nendloop\nendfacet\nfacet",
            "vertex 1 x 0\nendloop\nendfacet\nfacet",
        );
        let e = parse(t.as_bytes(), Path::new("a.stl"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("a.stl:6:"), "{e}");
        let e = parse(b"hello", Path::new("a.stl")).unwrap_err().to_string();
        assert!(e.contains("not an STL file"), "{e}");
    }
}
