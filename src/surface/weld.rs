//! What the mesh readers of STL, PLY and OFF share (see `import.rs`): a mesh built from a
//! file's points and faces with the points of identical coordinates welded into one vertex (as
//! the OBJ reader does: `+0.0` and `-0.0` are one point), indexed faces checked against the
//! points they name, and the messages of a coordinate that is not a number or not finite.

use super::obj::RawMesh;
use super::SurfaceError;
use crate::geom::mesh::{Face, Mesh};
use glam::DVec3;
use std::collections::HashMap;
use std::path::Path;

/// A parse error of a mesh file, at a line of a text file (`None`: a binary file or the whole
/// file).
pub(super) fn err(path: &Path, line: Option<usize>, message: impl Into<String>) -> SurfaceError {
    SurfaceError::Parse {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Builds a mesh from points and faces, welding points with identical coordinates (as the
/// OBJ reader does).
#[derive(Debug, Default)]
pub(super) struct Welder {
    pub mesh: Mesh,
    ids: HashMap<[u64; 3], usize>,
    pub welded: usize,
}

impl Welder {
    /// The mesh vertex of a point; `+0.0` and `-0.0` are the same point.
    pub fn vertex(&mut self, p: DVec3) -> usize {
        let key = [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ];
        if let Some(&id) = self.ids.get(&key) {
            self.welded += 1;
            return id;
        }
        self.mesh.vertices.push(p);
        self.ids.insert(key, self.mesh.vertices.len() - 1);
        self.mesh.vertices.len() - 1
    }

    pub fn face(&mut self, verts: Vec<usize>, line: Option<usize>) {
        self.mesh.faces.push(Face { verts, line });
    }

    pub fn finish(self, path: &Path) -> Result<RawMesh, SurfaceError> {
        if self.mesh.faces.is_empty() {
            return Err(err(
                path,
                None,
                "no faces: flatcut needs a surface made of faces",
            ));
        }
        Ok(RawMesh {
            path: path.to_path_buf(),
            mesh: self.mesh,
            welded: self.welded,
            texture: None,
            texture_warnings: Vec::new(),
        })
    }
}

/// Indexed points and faces (PLY, OFF): every point welded, every index checked.
pub(super) fn indexed(
    path: &Path,
    points: &[DVec3],
    faces: Vec<(Vec<i64>, Option<usize>, usize)>,
) -> Result<RawMesh, SurfaceError> {
    let mut w = Welder::default();
    let ids: Vec<usize> = points.iter().map(|p| w.vertex(*p)).collect();
    for (refs, line, k) in faces {
        if refs.len() < 3 {
            return Err(err(
                path,
                line,
                format!(
                    "face {} needs at least three vertices, found {}",
                    k + 1,
                    refs.len()
                ),
            ));
        }
        let mut verts = Vec::with_capacity(refs.len());
        for r in refs {
            let Some(&v) = usize::try_from(r).ok().and_then(|i| ids.get(i)) else {
                return Err(err(
                    path,
                    line,
                    format!(
                        "face {} refers to vertex {r}, but the vertices are numbered 0 to {}",
                        k + 1,
                        points.len() as i64 - 1
                    ),
                ));
            };
            verts.push(v);
        }
        w.face(verts, line);
    }
    w.finish(path)
}

/// A vertex coordinate read as text: a finite number, or an error naming the line and vertex.
pub(super) fn coord(
    path: &Path,
    line: Option<usize>,
    vertex: usize,
    text: &str,
) -> Result<f64, SurfaceError> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(non_finite(path, line, vertex, text)),
        Err(_) => Err(err(
            path,
            line,
            format!("vertex {}: coordinate `{text}` is not a number", vertex + 1),
        )),
    }
}

/// The error of a vertex coordinate that is NaN or infinite.
pub(super) fn non_finite(
    path: &Path,
    line: Option<usize>,
    vertex: usize,
    text: &str,
) -> SurfaceError {
    match line {
        Some(line) => SurfaceError::NonFinite {
            path: path.to_path_buf(),
            line,
            index: vertex,
            text: text.to_string(),
        },
        None => err(
            path,
            None,
            format!(
                "vertex {} has a coordinate that is not a finite number ({text}); fix or remove it",
                vertex + 1
            ),
        ),
    }
}
