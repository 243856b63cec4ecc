//! The material a pattern is cut from: its kind (paper, fabric, metal) and thickness. The
//! surface stage reads it first (a metal strip is developed on its neutral surface, see
//! [`super::source::SurfaceSpec::for_material`]); flatten and pattern take their defaults
//! from the kind.
//!
//! Choices: a thickness left out defaults by kind (paper 0.25 mm, fabric 0.5, metal 1.0).

use std::fmt;

/// The material the pattern is cut from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub kind: MaterialKind,
    /// Thickness in millimetres.
    pub thickness: f64,
}

/// Kinds of sheet material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum MaterialKind {
    #[default]
    Paper,
    Fabric,
    Metal,
}

impl MaterialKind {
    /// The names a spec file and the command line use, in the order messages list them.
    pub(crate) const NAMES: [(&'static str, MaterialKind); 3] = [
        ("paper", MaterialKind::Paper),
        ("fabric", MaterialKind::Fabric),
        ("metal", MaterialKind::Metal),
    ];

    /// Thickness in millimetres assumed when none is given.
    pub fn default_thickness(self) -> f64 {
        match self {
            MaterialKind::Paper => 0.25,
            MaterialKind::Fabric => 0.5,
            MaterialKind::Metal => 1.0,
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            MaterialKind::Paper => "paper",
            MaterialKind::Fabric => "fabric",
            MaterialKind::Metal => "metal",
        }
    }
}

impl fmt::Display for MaterialKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Default for Material {
    fn default() -> Self {
        Material {
            kind: MaterialKind::Paper,
            thickness: MaterialKind::Paper.default_thickness(),
        }
    }
}
