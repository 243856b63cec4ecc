//! The material a pattern is cut from: its kind (paper, fabric, metal), thickness and, for
//! metal, how it bends (K factor and inside bend radius). The surface stage reads it first (a
//! metal strip is developed on its neutral surface, see
//! [`super::source::SurfaceSpec::for_material`]); flatten and pattern take their defaults
//! from the kind, and the pattern stage develops the folds of metal meshes with its bend
//! settings ([`Material::sheet_bend`], `pattern::develop`).
//!
//! Choices: a thickness left out defaults by kind (paper 0.25 mm, fabric 0.5, metal 1.0),
//! also when the command line changes the kind; K
//! defaults to 0.4 (as the fittings' and FreeCAD SheetMetal's tables for steel in air
//! bending) and the inside bend radius to the thickness (a common punch for mild steel).

use std::fmt;

/// The material the pattern is cut from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub kind: MaterialKind,
    /// Thickness in millimetres.
    pub thickness: f64,
    /// K factor of the folds of metal meshes: the neutral surface's depth below the inside
    /// face over the thickness (0..1; default 0.4).
    pub k_factor: f64,
    /// Inside bend radius (mm) of the folds of metal meshes; `None`: the thickness.
    pub bend_radius: Option<f64>,
    /// Whether the thickness was stated (in the spec or by a flag), not the kind's default.
    pub thickness_given: bool,
}

impl Material {
    /// The K factor used when none is given.
    pub const DEFAULT_K_FACTOR: f64 = 0.4;

    /// Make the material `kind` (`--material`): a thickness that was only the old kind's
    /// default becomes the new kind's (a spec without `[material]` cut as metal is 1 mm
    /// sheet, not paper's 0.25 mm); a stated one stays.
    pub fn set_kind(&mut self, kind: MaterialKind) {
        self.kind = kind;
        if !self.thickness_given {
            self.thickness = kind.default_thickness();
        }
    }

    /// How this material's sheet bends: thickness, K factor and inside radius (the thickness
    /// unless given).
    pub fn sheet_bend(&self) -> crate::geom::bend::SheetBend {
        crate::geom::bend::SheetBend {
            thickness: self.thickness,
            k_factor: self.k_factor,
            inside_radius: self.bend_radius.unwrap_or(self.thickness),
        }
    }
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
            k_factor: Material::DEFAULT_K_FACTOR,
            bend_radius: None,
            thickness_given: false,
        }
    }
}
