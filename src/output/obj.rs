//! Wavefront OBJ writer: a surface mesh in millimetres, optionally with texture coordinates.
//!
//! Used for `--surface-obj` (a bent or generated surface to look at in a 3D viewer) and
//! `--uv-obj` (the mesh with its flat layout as `vt`, in mm, so anyone can measure the pattern
//! against the surface). The text is [`crate::geom::obj::write`]'s with coordinates in their
//! shortest round-trip representation ([`crate::geom::obj::exact`]), so a read-back is exact and
//! the output deterministic; faces keep their vertex order (counter-clockwise seen from the
//! printed side).

use crate::geom::mesh::Mesh;
use crate::geom::obj;
use glam::DVec2;

/// The OBJ text of `mesh`, headed by `# comment` lines (one per line of `comment`). With `uv`
/// (one 2D point per corner of each face, in mm) every face is written `f v/vt …`, the corners
/// of a vertex at one flat point sharing one `vt` (one UV island per piece).
///
/// Returns `None` when `uv` does not have one point per corner of every face.
pub fn write(mesh: &Mesh, uv: Option<&[Vec<DVec2>]>, comment: &str) -> Option<String> {
    obj::write(mesh, uv, comment, obj::exact)
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
    fn obj_lists_vertices_faces_and_shared_uv() {
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
        // The two faces are one piece: vertices 1 and 3 have one `vt` each.
        assert_eq!(with.matches("vt ").count(), 4, "{with}");
        assert!(with.ends_with("f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"), "{with}");
        // Cut apart along the diagonal (the second face moved 30 mm): one `vt` per side.
        let apart: Vec<Vec<DVec2>> = vec![
            uv[0].clone(),
            uv[1].iter().map(|p| *p + DVec2::X * 30.0).collect(),
        ];
        let two = write(&m, Some(&apart), "").unwrap();
        assert_eq!(two.matches("vt ").count(), 6, "{two}");
        assert!(two.ends_with("f 1/1 2/2 3/3\nf 1/4 3/5 4/6\n"), "{two}");
        // One point short for a face: refused.
        let short = vec![uv[0].clone(), uv[1][..2].to_vec()];
        assert!(write(&m, Some(&short), "").is_none());
    }
}
