//! Mesh files of every format flatcut reads, chosen by extension (any letter case) and, for a
//! file with another extension, by its first bytes: Wavefront OBJ ([`super::obj`]), STL binary
//! and ASCII ([`super::stl`]), PLY ASCII and binary ([`super::ply`]) and OFF ([`super::off`]).
//! Each reader gives the same [`RawMesh`] as the OBJ reader (file units, faces with the line
//! they are on in a text file, none in a binary one, vertices with identical coordinates
//! welded, by `weld.rs`), so that [`super::obj::validate`] checks and repairs them all the same way.
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
    // A regular file under the size limit (`geom::input`): never a device or a FIFO.
    let bytes =
        crate::geom::input::read_bytes(path, crate::geom::input::DATA_LIMIT).map_err(|source| {
            SurfaceError::Io {
                path: path.to_path_buf(),
                source,
            }
        })?;
    match format(path, &bytes) {
        Format::Obj => super::obj::read(path),
        Format::Stl => super::stl::parse(&bytes, path),
        Format::Ply => super::ply::parse(&bytes, path),
        Format::Off => super::off::parse(&bytes, path),
    }
}
