//! Flatten stage: lays a [`Surface`]'s panels into the plane as [`Flat`] islands, keeping the
//! 3D↔2D correspondence (every face keeps its mesh index; every edge knows whether its two
//! faces stay joined in the plane and by how much the surface bends there).
//!
//! [`unfold`](mod@unfold) is the exact unfolding of polyhedral (developable) meshes. [`param`] flattens
//! nearly developable disk-topology charts (LSCM / ABF++) and [`distortion`] measures any flat
//! layout against its mesh (L2 / L∞ stretch, shear, angle defect).

pub mod charts;
pub mod distortion;
pub mod param;
pub mod unfold;

pub use distortion::Stretch;
pub use param::{parameterize, ChartParam, ParamError, ParamMethod};

pub use unfold::{unfold, UnfoldOptions};

use crate::geom::mesh::Topology;
use crate::surface::Surface;
use glam::DVec2;

/// A surface laid flat: islands of faces, each face placed by a rigid motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Flat {
    /// The surface it came from (3D positions, names, source file).
    pub surface: Surface,
    pub topology: Topology,
    /// For each face, its corner positions in its island's plane (mm), in the face's order;
    /// counter-clockwise, i.e. seen from the printed side.
    pub face_2d: Vec<Vec<DVec2>>,
    /// For each face, its island.
    pub face_island: Vec<usize>,
    /// Faces of each island, in the order they were joined.
    pub islands: Vec<Vec<usize>>,
    /// For each edge: its two faces stay joined in the plane (a fold, or flat).
    pub joined: Vec<bool>,
    /// For each edge: signed bend angle between its faces in radians; positive where the
    /// surface is convex (a mountain fold seen from the printed side), 0 on the boundary.
    pub dihedral: Vec<f64>,
    /// Overlap depth and coincidence distance (mm) the unfolding was built with: faces may
    /// overlap by less than this, and cut edges whose copies lie closer are joined.
    pub tolerance: f64,
}

impl Flat {
    /// 2D positions of the directed edge at corner `i` of face `f`.
    pub fn corner_edge(&self, f: usize, i: usize) -> (DVec2, DVec2) {
        let p = &self.face_2d[f];
        (p[i], p[(i + 1) % p.len()])
    }
}

/// Errors of the flatten stage, naming the surface and the face concerned.
#[derive(Debug, thiserror::Error)]
pub enum FlattenError {
    #[error("surface `{surface}`: face {face}{} is too degenerate to lay flat", line.map(|l| format!(" (line {l})")).unwrap_or_default())]
    Degenerate {
        surface: String,
        face: usize,
        line: Option<usize>,
    },
    /// Two faces of one piece overlap when laid flat: the stage's own fault, never output.
    #[error("surface `{surface}`, piece {piece}: faces {a} and {b} overlap when laid flat (flatcut bug)")]
    Overlap {
        surface: String,
        piece: usize,
        a: usize,
        b: usize,
    },
}
