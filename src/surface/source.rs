//! The description of one surface to build, the input of [`crate::surface::build`]: its
//! kind, source file and units, and the settings of each kind (a strip's curves, a bent
//! sheet, a boundary's loops, how a mesh is segmented). The spec reader (`crate::spec`) fills
//! it from a `[[surface]]` entry; the `fitting` command builds one for a sheet-metal blank.
//!
//! Choices: the names a file uses for the enums (`NAMES`) live with the types, like
//! [`super::strip::Method::NAMES`]; reading them from text is the spec reader's business.
//! [`SurfaceSpec::line`] is kept so that surface errors can point into the spec file.

use super::geodesic::BentSpec;
use super::material::{Material, MaterialKind};
use super::segment::SegmentSpec;
use std::fmt;
use std::path::PathBuf;

/// One surface to build, the input of [`crate::surface::build`]: a `[[surface]]` entry of a
/// spec file, or a blank the `fitting` command makes.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSpec {
    pub kind: SurfaceKind,
    /// Source file, resolved against the spec file's directory.
    pub path: PathBuf,
    /// Factor applied to the coordinates, on top of [`SurfaceSpec::units`].
    pub scale: f64,
    /// Units the file's coordinates are in.
    pub units: Units,
    /// The size (mm) of the surface's largest dimension (its bounding box's longest side),
    /// aspect kept; given, it replaces `scale` and `units`. `None`: as `scale` and `units` say.
    pub size: Option<f64>,
    /// Name shown in labels; default: the source file's stem.
    pub name: String,
    /// 1-based line of this entry's `path` value in the spec; 0 when there is no spec file.
    pub line: usize,
    /// The curves and settings of a [`SurfaceKind::Strip`]; `None` for other kinds.
    pub strip: Option<StripSpec>,
    /// The sheet, lines and control curves of a [`SurfaceKind::BentSheet`]; `None` for others.
    pub bent: Option<BentSpec>,
    /// The loops and settings of a [`SurfaceKind::Boundary`]; `None` for other kinds.
    pub boundary: Option<BoundarySpec>,
    /// The curves and solver settings of a [`SurfaceKind::Spline`]; `None` for other kinds.
    pub spline: Option<super::spline::SplineSpec>,
    /// How a mesh is cut into pieces (issue 7); default: decided from the mesh.
    pub segment: SegmentSpec,
}

/// A developable from a closed 3D boundary (`kind = "boundary"`, Rose et al.): the loops as
/// sampled (and smoothed when asked), darts, rulings and the search settings.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundarySpec {
    pub input: super::boundary::Input,
    pub options: super::boundary::Options,
}

/// A strip between two boundary curves (`kind = "strip"`, or built by `flatcut fitting`).
#[derive(Debug, Clone, PartialEq)]
pub struct StripSpec {
    pub p: crate::geom::curve::Curve,
    pub q: crate::geom::curve::Curve,
    pub method: super::strip::Method,
    pub bend_lines: super::strip::BendLines,
    /// Chordal tolerance for sampling the curves (mm).
    pub tolerance: f64,
    /// How far (mm) the developed surface lies inside the given one: (1 − K)·t for a metal
    /// blank given by its outside, 0 to develop the given surface.
    pub neutral_offset: f64,
    /// For a strip from a spec file: which surface of the sheet the curves describe and the
    /// K factor, from which [`SurfaceSpec::for_material`] sets `neutral_offset` once the
    /// material is known (flags may change it after the spec is read); `None` keeps
    /// `neutral_offset` as it is (the `fitting` command sets it itself).
    pub sheet: Option<(SheetSide, f64)>,
}

/// Which surface of a metal sheet a strip's curves describe (`side`); the blank is developed
/// on the neutral surface, K·t from the inside.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SheetSide {
    /// The outside (as a shop measures a duct): the neutral surface is (1 − K)·t inside.
    #[default]
    Outside,
    /// The inside: the neutral surface is K·t outside.
    Inside,
    /// The curves already describe the neutral surface.
    Neutral,
}

impl SheetSide {
    pub(crate) const NAMES: [(&'static str, SheetSide); 3] = [
        ("outside", SheetSide::Outside),
        ("inside", SheetSide::Inside),
        ("neutral", SheetSide::Neutral),
    ];

    /// How far inside the given surface the neutral surface lies (negative: outside) for a
    /// sheet `t` mm thick with K factor `k`.
    pub fn neutral_offset(self, k: f64, t: f64) -> f64 {
        use crate::geom::bend::{neutral_below_outside, neutral_depth};
        match self {
            SheetSide::Outside => neutral_below_outside(k, t),
            SheetSide::Inside => -neutral_depth(k, t),
            SheetSide::Neutral => 0.0,
        }
    }
}

impl SurfaceSpec {
    /// This surface as it is developed in `material`: a strip or a spline surface from a spec
    /// file in metal moves to its neutral surface (see [`StripSpec::sheet`]); paper and fabric are thin enough to
    /// be developed as given.
    pub fn for_material(&self, material: &Material) -> SurfaceSpec {
        let mut s = self.clone();
        if let Some(st) = &mut s.strip {
            if let Some((side, k)) = st.sheet {
                st.neutral_offset = match material.kind {
                    MaterialKind::Metal => side.neutral_offset(k, material.thickness),
                    _ => 0.0,
                };
            }
        }
        if let Some(sp) = &mut s.spline {
            let (side, k) = sp.sheet;
            sp.neutral_offset = match material.kind {
                MaterialKind::Metal => side.neutral_offset(k, material.thickness),
                _ => 0.0,
            };
        }
        s
    }
}

/// How a surface is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum SurfaceKind {
    /// A polyhedral mesh file (OBJ) whose faces are flat panels.
    #[default]
    Mesh,
    /// A developable strip between two boundary curves.
    Strip,
    /// A flat sheet bent along a control curve (Bo–Wang, `surface::geodesic`).
    BentSheet,
    /// A developable from a closed 3D boundary polyline (Rose et al.).
    Boundary,
    /// A spline developable between B-spline curves (Tang et al., `surface::spline`).
    Spline,
}

/// Length units of a surface's source coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Units {
    #[default]
    Mm,
    Cm,
    M,
    In,
}

impl SurfaceKind {
    /// The names a spec file and the command line use, in the order messages list them.
    pub(crate) const NAMES: [(&'static str, SurfaceKind); 5] = [
        ("mesh", SurfaceKind::Mesh),
        ("strip", SurfaceKind::Strip),
        ("bent-sheet", SurfaceKind::BentSheet),
        ("boundary", SurfaceKind::Boundary),
        ("spline", SurfaceKind::Spline),
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            SurfaceKind::Mesh => "mesh",
            SurfaceKind::Strip => "strip",
            SurfaceKind::BentSheet => "bent-sheet",
            SurfaceKind::Boundary => "boundary",
            SurfaceKind::Spline => "spline",
        }
    }
}

impl fmt::Display for SurfaceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Units {
    /// The names a spec file uses, in the order messages list them.
    pub(crate) const NAMES: [(&'static str, Units); 4] = [
        ("mm", Units::Mm),
        ("cm", Units::Cm),
        ("m", Units::M),
        ("in", Units::In),
    ];

    /// Millimetres in one of these units.
    pub fn mm(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Cm => 10.0,
            Units::M => 1000.0,
            Units::In => 25.4,
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Units::Mm => "mm",
            Units::Cm => "cm",
            Units::M => "m",
            Units::In => "in",
        }
    }
}

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}
