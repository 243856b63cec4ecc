//! Mesh files of every format flatcut reads, chosen by extension (any letter case) and, for a
//! file with another extension, by its first bytes: Wavefront OBJ ([`super::obj`]), STL binary
//! and ASCII ([`super::stl`]), PLY ASCII and binary ([`super::ply`]) and OFF ([`super::off`]).
//! Each reader gives the same [`RawMesh`] as the OBJ reader (file units, faces with the line
//! they are on in a text file, none in a binary one, vertices with identical coordinates
//! welded), so that [`super::obj::validate`] checks and repairs them all the same way.
//!
//! Why hand-written readers: the formats are small, and the crates (stl_io, ply-rs) report
//! errors without a line or record, read coordinates into f32 only, or are unmaintained;
//! flatcut's messages name the file and the line (text) or the triangle, vertex or face
//! (binary) that is wrong.
//!
//! Choices: a binary STL is recognised by its size (84 bytes + 50 per triangle as its header
//! says), whatever its first bytes are (many binary STLs begin with `solid`); a file with an
//! unknown extension is PLY when it begins with `ply`, OFF with `OFF`, STL when it begins with
//! `solid` or has a binary STL's size, else OBJ.

use super::obj::RawMesh;
use super::SurfaceError;
use crate::geom::mesh::{Face, Mesh};
use glam::DVec3;
use std::collections::HashMap;
use std::path::Path;

/// The extensions of the mesh files flatcut reads (lower case).
pub const EXTENSIONS: [&str; 4] = ["obj", "stl", "ply", "off"];

/// Whether `path` names a mesh file by its extension (any letter case).
pub fn is_mesh_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| {
        let e = e.to_string_lossy().to_ascii_lowercase();
        EXTENSIONS.contains(&e.as_str())
    })
}

/// Formats of mesh files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Obj,
    Stl,
    Ply,
    Off,
}

/// The format of a file, by extension, else by its first bytes.
pub fn format(path: &Path, bytes: &[u8]) -> Format {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "obj" => return Format::Obj,
        "stl" => return Format::Stl,
        "ply" => return Format::Ply,
        "off" => return Format::Off,
        _ => {}
    }
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(64)]).to_ascii_lowercase();
    let head = head.trim_start();
    if head.starts_with("ply") {
        Format::Ply
    } else if head.starts_with("off") || head.starts_with("coff") || head.starts_with("noff") {
        Format::Off
    } else if head.starts_with("solid") || super::stl::is_binary(bytes) {
        Format::Stl
    } else {
        Format::Obj
    }
}

/// Read a mesh file of any format.
pub fn read(path: &Path) -> Result<RawMesh, SurfaceError> {
    let bytes = std::fs::read(path).map_err(|source| SurfaceError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    match format(path, &bytes) {
        Format::Obj => super::obj::read(path),
        Format::Stl => super::stl::parse(&bytes, path),
        Format::Ply => super::ply::parse(&bytes, path),
        Format::Off => super::off::parse(&bytes, path),
    }
}

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
