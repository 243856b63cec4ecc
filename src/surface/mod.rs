//! Surface stage: where developables come from. Each way of making a developable lives in its
//! own file; all of them produce a [`Surface`]: a polygon mesh in millimetres whose faces are
//! flat panels, with its name and the file it came from.
//!
//! For now the only source is a polyhedral mesh ([`obj`]); strips, fittings, boundary and
//! geodesic developables will add files here (see shared/seeds/README.md).

pub mod obj;
pub mod solids;

use crate::geom::mesh::Mesh;
use crate::spec::{SurfaceKind, SurfaceSpec};
use std::path::PathBuf;

/// A developable surface made of flat polygon panels.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// Name shown in labels and reports.
    pub name: String,
    /// File it was read from.
    pub source: PathBuf,
    /// Panels in millimetres, consistently oriented (counter-clockwise seen from the printed
    /// side, which is the outside of a closed mesh).
    pub mesh: Mesh,
    /// Repairs made on import, one line each, for the user to read.
    pub warnings: Vec<String>,
}

/// Everything that can be wrong with a surface source. Each message is one line that names the
/// file and, where known, the line.
#[derive(Debug, thiserror::Error)]
pub enum SurfaceError {
    #[error("{}: cannot read mesh: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        path: PathBuf,
        line: Option<usize>,
        message: String,
    },
    #[error("{}:{line}: vertex {index} has a coordinate that is not a finite number ({text}); fix or remove it", path.display())]
    NonFinite {
        path: PathBuf,
        line: usize,
        index: usize,
        text: String,
    },
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
    #[error("{}{}: edge from {a} to {b} is shared by {count} faces (lines {lines}); each edge may join at most two faces", path.display(), first_line.map(|l| format!(":{l}")).unwrap_or_default())]
    NonManifold {
        path: PathBuf,
        first_line: Option<usize>,
        a: String,
        b: String,
        count: usize,
        lines: String,
    },
    #[error("{}{}: the mesh is not orientable (a Möbius-like band): its faces cannot all be wound the same way", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    NonOrientable { path: PathBuf, line: Option<usize> },
}

/// Build the surface a spec entry describes.
pub fn build(spec: &SurfaceSpec) -> Result<Surface, SurfaceError> {
    match spec.kind {
        SurfaceKind::Mesh => {
            let scale = spec.scale * spec.units.mm();
            let raw = obj::read(&spec.path)?;
            let (mesh, warnings) = obj::validate(raw, scale)?;
            Ok(Surface {
                name: spec.name.clone(),
                source: spec.path.clone(),
                mesh,
                warnings,
            })
        }
    }
}
