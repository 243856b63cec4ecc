//! Wavefront OBJ writer: a surface mesh in millimetres, optionally with texture coordinates.
//!
//! Used for `--surface-obj` (a bent or generated surface to look at in a 3D viewer) and
//! `--uv-obj` (the mesh with its flat layout as `vt`, in mm, so anyone can measure the pattern
//! against the surface). The text is [`crate::geom::obj::write`]'s with coordinates in their
//! shortest round-trip representation ([`crate::geom::obj::exact`]), so a read-back is exact and
//! the output deterministic; faces keep their vertex order (counter-clockwise seen from the
//! printed side).
//!
//! With pieces ([`write_pieces`]) the `vt` are shared as every exporter writes them: one per
//! vertex of a piece (the corners of one vertex in one piece whose flat positions coincide
//! within the layout's tolerance), so a vertex on a seam gets one per piece it is in, and a UV
//! tool sees each piece as one island. A vertex on a slit inside a piece (a cut whose two sides
//! lie apart) gets one per side.

use crate::geom::mesh::Mesh;
use crate::geom::obj;
use glam::DVec2;

/// The OBJ text of `mesh`, headed by `# comment` lines (one per line of `comment`). With `uv`
/// (one 2D point per corner of each face, in mm) every face is written `f v/vt …`.
///
/// Returns `None` when `uv` does not have one point per corner of every face.
pub fn write(mesh: &Mesh, uv: Option<&[Vec<DVec2>]>, comment: &str) -> Option<String> {
    obj::write(mesh, uv, comment, obj::exact)
}

/// The OBJ text of `mesh` with its flat layout `uv` (one point per corner of each face, mm) as
/// shared `vt` (see the module doc): `piece[f]` is face `f`'s piece, and corners of one vertex
/// in one piece within `tol` mm of each other share one `vt` (the first one's position).
///
/// Returns `None` when `uv` or `piece` does not have an entry per face, or `uv` not one point
/// per corner.
pub fn write_pieces(
    mesh: &Mesh,
    uv: &[Vec<DVec2>],
    piece: &[usize],
    tol: f64,
    comment: &str,
) -> Option<String> {
    use std::fmt::Write;
    if uv.len() != mesh.faces.len()
        || piece.len() != mesh.faces.len()
        || uv
            .iter()
            .zip(&mesh.faces)
            .any(|(c, f)| c.len() != f.verts.len())
    {
        return None;
    }
    let mut seen: std::collections::HashMap<(usize, usize), Vec<(DVec2, usize)>> =
        Default::default();
    let mut vt: Vec<DVec2> = Vec::new();
    let mut index: Vec<Vec<usize>> = Vec::with_capacity(uv.len());
    for (f, face) in mesh.faces.iter().enumerate() {
        let mut ids = Vec::with_capacity(face.verts.len());
        for (&v, &p) in face.verts.iter().zip(&uv[f]) {
            let list = seen.entry((piece[f], v)).or_default();
            let id = match list.iter().find(|(q, _)| q.distance(p) <= tol) {
                Some(&(_, id)) => id,
                None => {
                    vt.push(p);
                    list.push((p, vt.len() - 1));
                    vt.len() - 1
                }
            };
            ids.push(id);
        }
        index.push(ids);
    }
    let mut s = String::new();
    for line in comment.lines() {
        let _ = writeln!(s, "# {line}");
    }
    for v in &mesh.vertices {
        let _ = writeln!(
            s,
            "v {} {} {}",
            obj::exact(v.x),
            obj::exact(v.y),
            obj::exact(v.z)
        );
    }
    for p in &vt {
        let _ = writeln!(s, "vt {} {}", obj::exact(p.x), obj::exact(p.y));
    }
    for (face, ids) in mesh.faces.iter().zip(&index) {
        s.push('f');
        for (&v, &t) in face.verts.iter().zip(ids) {
            let _ = write!(s, " {}/{}", v + 1, t + 1);
        }
        s.push('\n');
    }
    Some(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::mesh::Face;
    use glam::DVec3;

    fn quad() -> Mesh {
        Mesh {
            vertices: vec![
                DVec3::ZERO,
                DVec3::new(10.0, 0.0, 0.0),
                DVec3::new(10.0, 5.5, 0.0),
                DVec3::new(0.0, 5.5, 1.25),
            ],
            faces: vec![
                Face {
                    verts: vec![0, 1, 2],
                    line: None,
                },
                Face {
                    verts: vec![0, 2, 3],
                    line: None,
                },
            ],
        }
    }

    #[test]
    fn obj_lists_vertices_faces_and_per_corner_uv() {
        let m = quad();
        let plain = write(&m, None, "flatcut").unwrap();
        assert_eq!(
            plain,
            "# flatcut\nv 0 0 0\nv 10 0 0\nv 10 5.5 0\nv 0 5.5 1.25\nf 1 2 3\nf 1 3 4\n"
        );
        let uv: Vec<Vec<DVec2>> = vec![
            vec![DVec2::ZERO, DVec2::X * 10.0, DVec2::new(10.0, 5.5)],
            vec![DVec2::ZERO, DVec2::new(10.0, 5.5), DVec2::new(0.0, 5.64)],
        ];
        let with = write(&m, Some(&uv), "").unwrap();
        assert!(with.contains("vt 0 5.64\n"), "{with}");
        assert!(with.ends_with("f 1/1 2/2 3/3\nf 1/4 3/5 4/6\n"), "{with}");
        // One point short for a face: refused.
        let short = vec![uv[0].clone(), uv[1][..2].to_vec()];
        assert!(write(&m, Some(&short), "").is_none());
    }

    #[test]
    fn vt_are_shared_within_a_piece_and_apart_between_pieces() {
        let m = quad();
        // One piece: the two faces share the diagonal 0–2, so 4 vt (one per vertex).
        let uv: Vec<Vec<DVec2>> = vec![
            vec![DVec2::ZERO, DVec2::X * 10.0, DVec2::new(10.0, 5.5)],
            vec![
                DVec2::ZERO,
                DVec2::new(10.0, 5.5 + 1e-12),
                DVec2::new(0.0, 5.64),
            ],
        ];
        let one = write_pieces(&m, &uv, &[0, 0], 1e-6, "").unwrap();
        assert_eq!(one.matches("\nvt ").count(), 4, "{one}");
        assert!(one.ends_with("f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"), "{one}");
        // Two pieces: the seam's two vertices get one vt per piece.
        let two = write_pieces(&m, &uv, &[0, 1], 1e-6, "").unwrap();
        assert_eq!(two.matches("\nvt ").count(), 6, "{two}");
        // A slit inside a piece (the corners apart): one vt per side.
        let mut apart = uv.clone();
        apart[1][0] = DVec2::new(0.0, -1.0);
        let slit = write_pieces(&m, &apart, &[0, 0], 1e-6, "").unwrap();
        assert_eq!(slit.matches("\nvt ").count(), 5, "{slit}");
        assert!(write_pieces(&m, &uv, &[0], 1e-6, "").is_none());
    }
}
