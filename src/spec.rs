//! The job spec: a TOML file (`patterns/*.toml`) naming the surfaces to cut and the material,
//! sheet and pattern settings to cut them with.
//!
//! ```toml
//! name = "cube"            # optional; default: the spec file's stem
//! device = "hpgl-pens"     # optional device profile name
//!
//! [[surface]]              # one or more
//! kind = "mesh"            # required: "mesh", "strip" or "bent-sheet" (see below)
//! path = "cube.obj"        # required for mesh; relative to the spec file's directory
//! scale = 1.0              # optional, > 0, finite; default 1
//! units = "mm"             # optional: "mm" | "cm" | "m" | "in"; default "mm"
//! name = "box"             # optional; default: the mesh file stem
//! segment = "dcharts"      # optional: "faces" | "dcharts" (smooth meshes, issue 7); see
//!                          # `SegmentSpec` for this and `charts`, `f_max`, `approximate`,
//!                          # `simplify`
//!
//! [material]               # optional table
//! kind = "paper"           # "paper" | "fabric" | "metal"; default paper
//! thickness = 0.25         # mm, > 0, finite; default by kind: paper 0.25, fabric 0.5, metal 1.0
//!
//! [sheet]                  # optional table
//! width = 210              # mm > 0; default 210 (A4 portrait)
//! height = 297             # mm > 0; default 297; not allowed together with roll = true
//! roll = false             # true: a roll of `width`, unlimited length
//! margin = 5               # mm >= 0; default 5
//! spacing = 3              # mm >= 0; default 3
//!
//! [pattern]                # optional table
//! fold_threshold = 1.0     # degrees, >= 0 and < 180; default 1: joined edges bending more
//!                          # than this become fold lines
//! tabs = "one-side"        # glue tabs: "none" | "one-side" | "both"; default: paper one-side
//! tab_height = 5           # mm > 0; default 5
//! allowance = 10           # seam allowance, mm >= 0; default: fabric 10, else 0
//! notches = 50             # notch spacing along seams, mm >= 0 (0: none); default: fabric 50
//! kerf = 0.2               # cut width, mm >= 0; default 0 (or the device's cut tool `kerf`)
//! bend_notches = false     # V notches where bend lines meet the outline; default false
//! ```
//!
//! [`load`] reads a spec file; a `.obj` file (any letter case) given instead stands for a
//! spec with that one mesh and every default ([`Spec::from_mesh`]). Every other extension is
//! read as TOML.
//!
//! # Precedence
//!
//! Settings come from three places, each overriding the one before: the spec file, then the
//! device profile it names (or the CLI picks), then command-line flags. This module only reads
//! the spec and fills in its own defaults; the CLI applies the profile and the flags on top.
//!
//! # Choices
//!
//! - Unknown keys, in any table, are errors rather than ignored, so a typo (`colour`,
//!   `widht`) never silently falls back to a default.
//! - Every error is one line, `FILE:LINE: ...`, naming the key as a dotted path
//!   (`sheet.width`, `surface[2].scale`) and saying what is expected. Lines are 1-based and
//!   point at the offending value (or, for a missing key, at its table's header).
//!   `[[surface]]` entries are counted from 1 in keys: the second one is `surface[2]`.
//! - A value of the wrong type (`width = "wide"`, `surface = "cube.obj"`) is reported as an
//!   invalid value of that key, not as a bare TOML type error.
//! - Numbers may be written as integers or floats (`width = 210` or `210.0`); `nan` and
//!   `inf` are never accepted.
//! - Enumerated values (`kind`, `units`) are matched ignoring ASCII case; an unknown one lists
//!   the allowed values.
//! - `name` (spec and surface), `device` and `path` must not be empty strings.
//! - `margin`: twice the margin must be less than the sheet width and, for a sheet (not a
//!   roll), the sheet height, so some area is left to cut in.
//! - [`SurfaceSpec::line`] is the line of the surface's `path` value (where to look when its
//!   mesh cannot be read), or 0 for a spec made from a mesh file by [`Spec::from_mesh`].
//! - Surface paths are resolved against the spec file's directory as written (no
//!   canonicalising, no `~` expansion); an absolute path stays as it is.
//!
//! # Strips (issue 4)
//!
//! A `kind = "strip"` surface is a developable strip between two boundary curves (see
//! `surface::strip`), with keys `p` and `q` (required), `method` ("godt+gmbt" default,
//! "godt", "gmbt", "gmat", "local"), `bend_lines` ("all" default, "none", or a spacing in mm)
//! and `tolerance` (chordal, mm, default 0.05), besides `name`. A curve is an inline list of
//! points (`p = [[0, 0, 0], [100, 0, 0]]`, open) or a table with a `kind`:
//!
//! ```toml
//! p = { kind = "points", points = [[0, 0], [100, 0, 5]], closed = false }
//! p = { kind = "csv", path = "edge.csv", closed = true }   # relative to the spec's folder
//! p = { kind = "circle", center = [0, 0, 0], radius = 100 }  # or diameter = 200
//! p = { kind = "ellipse", center = [0, 0, 150], rx = 80, ry = 50 }
//! p = { kind = "rect", center = [0, 0, 0], width = 400, height = 300, corner_radius = 0 }
//! p = { kind = "bezier", control = [[0, 0, 0], [50, 80, 0], [100, 0, 20]] }
//! p = { kind = "bspline", control = [...], degree = 3, closed = false }
//! ```
//!
//! Points have 2 or 3 coordinates (z = 0 when left out). A curve's keys are checked when the
//! spec is read (errors name `surface[k].p.radius` and the line of `p`), the curves are
//! sampled there too, and `q` equal to `p` is an error.
//!
//! Sheet thickness: in `[material] kind = "metal"` a strip is developed on the neutral surface
//! of the sheet, K·t from the inside, like the `fitting` command's blanks: `side` says which
//! surface the curves describe ("outside" default: the neutral surface is (1 − K)·t inside
//! them; "inside": K·t outside; "neutral": as given) and `k_factor` is K (0 to 1, default 0.4,
//! FreeCAD SheetMetal's). Paper and fabric strips are developed as given.
//!
//! # Bent sheets (issue 5)
//!
//! A `kind = "bent-sheet"` surface is a flat sheet bent along a control curve (see
//! `surface::geodesic`): `outline` (required: `[width, height]` from the origin, or a list of
//! `[x, y]` points), `holes` (optional list of point lists), exactly one of `line` (two points on
//! the sheet: the control curve is a geodesic), `arc` (`{ center = [x, y], radius, start_deg,
//! end_deg }`, degrees from +x, counter-clockwise when `end_deg > start_deg`) and `flat_curve`
//! (Bézier control points `[[x, y], ...]` on the sheet, or `{ kind = "bspline", control,
//! degree }`): a curve on the sheet whose curvature the bent sheet keeps as geodesic curvature
//! (§5), then exactly one of `control_points` (a list of `[x, y, z]` Bézier control points, or a
//! curve table of kind `bezier` or `bspline`) and `handles` (`{ start, start_normal, end,
//! end_normal }`), `length_fit` ("scale" default, "trim"), `tolerance` (mm, default 0.05),
//! `bend_lines` (as strips) and `name`. Several curved pieces: `pieces = [{ line, control_points
//! | handles, length_fit }, ...]` (with `arc` or `flat_curve` in place of `line` as above)
//! instead of the top-level keys. Errors about the geometry (a point off the sheet, the curve of
//! regression on the sheet, a control curve curving less than the curve on the sheet) name the
//! line of `line`, `arc` or `flat_curve` (or of `pieces`).
//!
//! # Boundaries (issue 6)
//!
//! A `kind = "boundary"` surface is the developable boundary triangulation of a closed 3D
//! polyline (see `surface::boundary`, Rose et al.). Exactly one of: `loop` (an inline list of
//! points, closed by itself, or a closed curve table as above), `loop_csv` (a CSV file of
//! points) or `loops` (a list of loops, the first the outer one, the others holes). Optional:
//! `darts = [{ at = 12, points = [[x, y, z], ...], loop = 1, width = 2 }]` (from point `at` of
//! loop `loop` (default 1), counted from 1, to the tip, the last point; the dart's two sides
//! coincide in 3D; `width` is the opening at the mouth in mm used only if they cannot be
//! triangulated so), `rulings = [[i, j], ...]` (edges between points of the first loop,
//! counted from 1, that the surface must contain) or `[[[l, i], [m, j]], ...]` (point `i` of
//! loop `l` to point `j` of loop `m`: within a loop a ruling splits the surface, between loops
//! it joins them), `max_dihedral` (degrees, default 60), `min_chart_area` (percent of the hull,
//! default 2), `max_iterations` (default 1000), `good_interior` and `good_fairness` (stop as
//! soon as a triangulation has at most that many interior triangles and that sum of squared
//! dihedral angles in radians²; default 0 and 0), `smooth` (resample a B-spline through the
//! points, default false) and `tolerance` (chordal, for curves and smoothing, default 0.5 mm).
//! Open polylines, fewer than three points, repeated consecutive points and loops that cross
//! themselves are errors naming the loop and point.

use serde::de::{self, Deserialize, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use std::fmt;
use std::marker::PhantomData;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use toml::Spanned;

// ---------------------------------------------------------------------------------------------
// Public data types
// ---------------------------------------------------------------------------------------------

/// A whole job: what to cut and how.
#[derive(Debug, Clone, PartialEq)]
pub struct Spec {
    /// Job name, used in output file names and labels.
    pub name: String,
    /// The file the spec came from (a `.toml` spec or, via [`Spec::from_mesh`], a mesh).
    pub path: PathBuf,
    /// Device profile named by the spec, if any.
    pub device: Option<String>,
    /// One or more surfaces to flatten, in file order.
    pub surfaces: Vec<SurfaceSpec>,
    pub material: Material,
    pub sheet: SheetSpec,
    pub pattern: PatternSpec,
}

/// One `[[surface]]` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSpec {
    pub kind: SurfaceKind,
    /// Source file, resolved against the spec file's directory.
    pub path: PathBuf,
    /// Factor applied to the coordinates, on top of [`SurfaceSpec::units`].
    pub scale: f64,
    /// Units the file's coordinates are in.
    pub units: Units,
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
    /// How a mesh is cut into pieces (issue 7); default: decided from the mesh.
    pub segment: SegmentSpec,
}

/// A developable from a closed 3D boundary (`kind = "boundary"`, Rose et al.): the loops as
/// sampled (and smoothed when asked), darts, rulings and the search settings.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundarySpec {
    pub input: crate::surface::boundary::Input,
    pub options: crate::surface::boundary::Options,
}

/// A bent sheet (`kind = "bent-sheet"`), see `surface::geodesic`.
pub use crate::surface::geodesic::BentSpec;

/// A strip between two boundary curves (`kind = "strip"`, or built by `flatcut fitting`).
#[derive(Debug, Clone, PartialEq)]
pub struct StripSpec {
    pub p: crate::geom::curve::Curve,
    pub q: crate::geom::curve::Curve,
    pub method: crate::surface::strip::Method,
    pub bend_lines: crate::surface::strip::BendLines,
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
    pub const NAMES: [(&'static str, SheetSide); 3] = [
        ("outside", SheetSide::Outside),
        ("inside", SheetSide::Inside),
        ("neutral", SheetSide::Neutral),
    ];

    /// How far inside the given surface the neutral surface lies (negative: outside) for a
    /// sheet `t` mm thick with K factor `k`.
    pub fn neutral_offset(self, k: f64, t: f64) -> f64 {
        match self {
            SheetSide::Outside => (1.0 - k) * t,
            SheetSide::Inside => -k * t,
            SheetSide::Neutral => 0.0,
        }
    }
}

impl SurfaceSpec {
    /// This surface as it is developed in `material`: a strip from a spec file in metal moves
    /// to its neutral surface (see [`StripSpec::sheet`]); paper and fabric are thin enough to
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

/// The sheet (or roll) the pieces are nested on, in millimetres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetSpec {
    pub width: f64,
    /// Sheet height; `None` for a roll of unlimited length.
    pub height: Option<f64>,
    /// Blank border kept on every side.
    pub margin: f64,
    /// Minimum gap between pieces.
    pub spacing: f64,
}

/// Settings for turning a flattened surface into a pattern.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternSpec {
    /// Joined edges whose faces bend by more than this many degrees become fold lines.
    pub fold_threshold_deg: f64,
    /// The rest: `None` leaves the material's default (see `PatternOptions::for_material`).
    pub tabs: Option<crate::pattern::Tabs>,
    pub tab_height: Option<f64>,
    pub allowance: Option<f64>,
    /// Notch spacing in mm; `Some(0)` for none.
    pub notches: Option<f64>,
    pub kerf: Option<f64>,
    pub bend_notches: Option<bool>,
}

/// Everything that can be wrong with a spec. Each message is one line starting with the file.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    #[error("{}: cannot read spec: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}:{line}: {message}", path.display())]
    Syntax {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{}:{line}: `{key}`: {message}", path.display())]
    Invalid {
        path: PathBuf,
        line: usize,
        key: String,
        message: String,
    },
}

// ---------------------------------------------------------------------------------------------
// Enum names, defaults, conversions
// ---------------------------------------------------------------------------------------------

/// "one of a, b, c"
fn one_of(names: &[&str]) -> String {
    format!("one of {}", names.join(", "))
}

/// Finds `s` among `(name, value)` pairs, ignoring ASCII case; the error lists the names.
fn pick<T: Copy>(s: &str, table: &[(&str, T)]) -> Result<T, String> {
    table
        .iter()
        .find(|(name, _)| name.eq_ignore_ascii_case(s.trim()))
        .map(|&(_, v)| v)
        .ok_or_else(|| {
            let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
            format!("expected {}, got {s:?}", one_of(&names))
        })
}

impl SurfaceKind {
    const NAMES: [(&'static str, SurfaceKind); 4] = [
        ("mesh", SurfaceKind::Mesh),
        ("strip", SurfaceKind::Strip),
        ("bent-sheet", SurfaceKind::BentSheet),
        ("boundary", SurfaceKind::Boundary),
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            SurfaceKind::Mesh => "mesh",
            SurfaceKind::Strip => "strip",
            SurfaceKind::BentSheet => "bent-sheet",
            SurfaceKind::Boundary => "boundary",
        }
    }
}

impl fmt::Display for SurfaceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for SurfaceKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        pick(s, &Self::NAMES)
    }
}

impl Units {
    const NAMES: [(&'static str, Units); 4] = [
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

impl FromStr for Units {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        pick(s, &Self::NAMES)
    }
}

impl MaterialKind {
    const NAMES: [(&'static str, MaterialKind); 3] = [
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

/// Parses `paper`, `fabric` or `metal` (any ASCII case); the error lists the allowed values.
impl FromStr for MaterialKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        pick(s, &Self::NAMES)
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

impl Default for SheetSpec {
    /// A4 portrait, 5 mm margin, 3 mm between pieces.
    fn default() -> Self {
        SheetSpec {
            width: 210.0,
            height: Some(297.0),
            margin: 5.0,
            spacing: 3.0,
        }
    }
}

impl SheetSpec {
    /// True for a roll: fixed width, unlimited length.
    pub fn is_roll(&self) -> bool {
        self.height.is_none()
    }
}

impl Default for PatternSpec {
    fn default() -> Self {
        PatternSpec {
            fold_threshold_deg: 1.0,
            tabs: None,
            tab_height: None,
            allowance: None,
            notches: None,
            kerf: None,
            bend_notches: None,
        }
    }
}

/// The file's stem as a string, or `fallback` when it has none.
fn stem_or(path: &Path, fallback: &str) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| fallback.to_string())
}

impl Spec {
    /// A spec for a single mesh file with every default: paper, A4 portrait, 5 mm margin,
    /// 3 mm spacing, scale 1 in millimetres, named after the file's stem.
    pub fn from_mesh(path: &Path) -> Spec {
        let name = stem_or(path, "mesh");
        Spec {
            name: name.clone(),
            path: path.to_path_buf(),
            device: None,
            surfaces: vec![SurfaceSpec {
                kind: SurfaceKind::Mesh,
                path: path.to_path_buf(),
                scale: 1.0,
                units: Units::Mm,
                name,
                line: 0,
                strip: None,
                bent: None,
                boundary: None,
                segment: SegmentSpec::default(),
            }],
            material: Material::default(),
            sheet: SheetSpec::default(),
            pattern: PatternSpec::default(),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Loading and parsing
// ---------------------------------------------------------------------------------------------

/// Reads a spec file. A `.obj` path (any case) gives [`Spec::from_mesh`]; anything else is
/// read as TOML.
pub fn load(path: &Path) -> Result<Spec, SpecError> {
    let is_obj = path
        .extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("obj"));
    if is_obj {
        return Ok(Spec::from_mesh(path));
    }
    let text = std::fs::read_to_string(path).map_err(|source| SpecError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse(&text, path)
}

/// Parses spec text; `path` is the file it came from, used for messages, the default name and
/// resolving surface paths.
pub fn parse(text: &str, path: &Path) -> Result<Spec, SpecError> {
    let ctx = Ctx { text, path };
    let raw: RawSpec = toml::from_str(text).map_err(|e| ctx.syntax(&e))?;
    ctx.build(raw)
}

// ---------------------------------------------------------------------------------------------
// Raw (serde) form: every value spanned, every value of any type accepted so that type
// mistakes are reported with their key.
// ---------------------------------------------------------------------------------------------

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSpec {
    name: Option<Spanned<Val>>,
    device: Option<Spanned<Val>>,
    surface: Option<Spanned<List<Spanned<Tab<RawSurface>>>>>,
    material: Option<Spanned<Tab<RawMaterial>>>,
    sheet: Option<Spanned<Tab<RawSheet>>>,
    pattern: Option<Spanned<Tab<RawPattern>>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSurface {
    kind: Option<Spanned<Val>>,
    path: Option<Spanned<Val>>,
    scale: Option<Spanned<Val>>,
    units: Option<Spanned<Val>>,
    name: Option<Spanned<Val>>,
    p: Option<Spanned<toml::Value>>,
    q: Option<Spanned<toml::Value>>,
    method: Option<Spanned<Val>>,
    bend_lines: Option<Spanned<Val>>,
    tolerance: Option<Spanned<Val>>,
    side: Option<Spanned<Val>>,
    k_factor: Option<Spanned<Val>>,
    outline: Option<Spanned<toml::Value>>,
    holes: Option<Spanned<toml::Value>>,
    line: Option<Spanned<toml::Value>>,
    arc: Option<Spanned<toml::Value>>,
    flat_curve: Option<Spanned<toml::Value>>,
    control_points: Option<Spanned<toml::Value>>,
    handles: Option<Spanned<toml::Value>>,
    length_fit: Option<Spanned<toml::Value>>,
    pieces: Option<Spanned<toml::Value>>,
    #[serde(rename = "loop")]
    loop_: Option<Spanned<toml::Value>>,
    loop_csv: Option<Spanned<Val>>,
    loops: Option<Spanned<toml::Value>>,
    darts: Option<Spanned<toml::Value>>,
    rulings: Option<Spanned<toml::Value>>,
    max_dihedral: Option<Spanned<Val>>,
    min_chart_area: Option<Spanned<Val>>,
    max_iterations: Option<Spanned<Val>>,
    smooth: Option<Spanned<Val>>,
    good_interior: Option<Spanned<Val>>,
    good_fairness: Option<Spanned<Val>>,
    segment: Option<Spanned<Val>>,
    charts: Option<Spanned<Val>>,
    f_max: Option<Spanned<Val>>,
    approximate: Option<Spanned<toml::Value>>,
    simplify: Option<Spanned<Val>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    kind: Option<Spanned<Val>>,
    thickness: Option<Spanned<Val>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSheet {
    width: Option<Spanned<Val>>,
    height: Option<Spanned<Val>>,
    roll: Option<Spanned<Val>>,
    margin: Option<Spanned<Val>>,
    spacing: Option<Spanned<Val>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPattern {
    fold_threshold: Option<Spanned<Val>>,
    tabs: Option<Spanned<Val>>,
    tab_height: Option<Spanned<Val>>,
    allowance: Option<Spanned<Val>>,
    notches: Option<Spanned<Val>>,
    kerf: Option<Spanned<Val>>,
    bend_notches: Option<Spanned<Val>>,
}

/// Any TOML value, reduced to what the checks need. Integers and floats both become `Num`.
#[derive(Debug, Clone, PartialEq)]
enum Val {
    Num(f64),
    Str(String),
    Bool(bool),
    /// A value of another type, described for messages ("a table", "an array", ...).
    Other(&'static str),
}

/// A number as TOML would write it (`nan`, `inf`, `-3`, `0.25`).
fn fmt_num(v: f64) -> String {
    if v.is_nan() {
        "nan".to_string()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.to_string()
    } else {
        format!("{v}")
    }
}

impl fmt::Display for Val {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Val::Num(v) => f.write_str(&fmt_num(*v)),
            Val::Str(s) => write!(f, "{s:?}"),
            Val::Bool(b) => write!(f, "{b}"),
            Val::Other(what) => f.write_str(what),
        }
    }
}

/// Name under which toml hands a date-time to `deserialize_any` (as a one-entry map).
const TOML_DATETIME_KEY: &str = "$__toml_private_datetime";

struct ValVisitor;

impl<'de> Visitor<'de> for ValVisitor {
    type Value = Val;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Val, E> {
        Ok(Val::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Val, E> {
        Ok(Val::Num(v as f64))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Val, E> {
        Ok(Val::Num(v as f64))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Val, E> {
        Ok(Val::Num(v))
    }
    fn visit_str<E>(self, v: &str) -> Result<Val, E> {
        Ok(Val::Str(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> Result<Val, E> {
        Ok(Val::Str(v))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Val, A::Error> {
        while seq.next_element::<IgnoredAny>()?.is_some() {}
        Ok(Val::Other("an array"))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Val, A::Error> {
        let mut what = "a table";
        if let Some(key) = map.next_key::<String>()? {
            if key == TOML_DATETIME_KEY {
                what = "a date-time";
            }
            map.next_value::<IgnoredAny>()?;
            while map.next_entry::<IgnoredAny, IgnoredAny>()?.is_some() {}
        }
        Ok(Val::Other(what))
    }
}

impl<'de> Deserialize<'de> for Val {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ValVisitor)
    }
}

/// Scalar `visit_*` methods that turn the value into `$wrap(Val)`.
macro_rules! wrong_scalars {
    ($wrap:path) => {
        fn visit_bool<E>(self, v: bool) -> Result<Self::Value, E> {
            Ok($wrap(Val::Bool(v)))
        }
        fn visit_i64<E>(self, v: i64) -> Result<Self::Value, E> {
            Ok($wrap(Val::Num(v as f64)))
        }
        fn visit_u64<E>(self, v: u64) -> Result<Self::Value, E> {
            Ok($wrap(Val::Num(v as f64)))
        }
        fn visit_f64<E>(self, v: f64) -> Result<Self::Value, E> {
            Ok($wrap(Val::Num(v)))
        }
        fn visit_str<E>(self, v: &str) -> Result<Self::Value, E> {
            Ok($wrap(Val::Str(v.to_string())))
        }
    };
}

/// A table deserialised as `T`, or a value of another type kept for the message.
enum Tab<T> {
    Table(T),
    Wrong(Val),
}

struct TabVisitor<T>(PhantomData<T>);

impl<'de, T: Deserialize<'de>> Visitor<'de> for TabVisitor<T> {
    type Value = Tab<T>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a table")
    }
    wrong_scalars!(Tab::Wrong);
    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        ValVisitor.visit_seq(seq).map(Tab::Wrong)
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        T::deserialize(de::value::MapAccessDeserializer::new(map)).map(Tab::Table)
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Tab<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TabVisitor(PhantomData))
    }
}

/// An array of `T`, or a value of another type kept for the message.
enum List<T> {
    Items(Vec<T>),
    Wrong(Val),
}

struct ListVisitor<T>(PhantomData<T>);

impl<'de, T: Deserialize<'de>> Visitor<'de> for ListVisitor<T> {
    type Value = List<T>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("an array")
    }
    wrong_scalars!(List::Wrong);
    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        Vec::<T>::deserialize(de::value::SeqAccessDeserializer::new(seq)).map(List::Items)
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        ValVisitor.visit_map(map).map(List::Wrong)
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for List<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ListVisitor(PhantomData))
    }
}

// ---------------------------------------------------------------------------------------------
// Checks
// ---------------------------------------------------------------------------------------------

type Opt = Option<Spanned<Val>>;

const MM_POSITIVE: &str = "a positive number of millimetres";
const MM_NON_NEGATIVE: &str = "a number of millimetres, zero or more";
const NON_EMPTY: &str = "a non-empty string";

struct Ctx<'a> {
    text: &'a str,
    path: &'a Path,
}

impl Ctx<'_> {
    /// 1-based line of a byte offset into the text.
    fn line_at(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        1 + self.text.as_bytes()[..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
    }

    fn line(&self, span: Range<usize>) -> usize {
        self.line_at(span.start)
    }

    fn syntax(&self, err: &toml::de::Error) -> SpecError {
        let span = err.span();
        let line = span.clone().map_or(1, |s| self.line(s));
        let mut message = one_line(err.message());
        // toml says only "duplicate key"; its span covers the key, so name it.
        if message == "duplicate key" {
            if let Some(key) = span.and_then(|s| self.text.get(s)) {
                let key = key.trim();
                if !key.is_empty() && key.len() <= 80 && !key.contains('\n') {
                    message = format!("duplicate key `{key}`");
                }
            }
        }
        // A date-time where a table belongs reaches the table as toml's private key.
        if message.contains(TOML_DATETIME_KEY) {
            message = "expected a table, got a date-time".to_string();
        }
        SpecError::Syntax {
            path: self.path.to_path_buf(),
            line,
            message,
        }
    }

    /// The first of `keys` that is given is an error, `{key}.{k}` with `why`: keys meant for
    /// another kind of surface, or for another place in the file.
    fn refuse(
        &self,
        key: &str,
        keys: &[(&str, Option<Range<usize>>)],
        why: &str,
    ) -> Result<(), SpecError> {
        match keys.iter().find_map(|(k, sp)| sp.clone().map(|sp| (k, sp))) {
            Some((k, sp)) => Err(self.invalid(self.line(sp), &format!("{key}.{k}"), why.into())),
            None => Ok(()),
        }
    }

    fn invalid(&self, line: usize, key: &str, message: String) -> SpecError {
        SpecError::Invalid {
            path: self.path.to_path_buf(),
            line,
            key: key.to_string(),
            message,
        }
    }

    /// "must be EXPECTED, got VALUE" as an `Invalid` error at the value's line.
    fn expected(&self, v: &Spanned<Val>, key: &str, expected: &str) -> SpecError {
        let mut message = format!("must be {expected}, got {}", v.get_ref());
        if matches!(v.get_ref(), Val::Num(n) if !n.is_finite()) {
            message.push_str(" (not a finite number)");
        }
        self.invalid(self.line(v.span()), key, message)
    }

    /// A finite number accepted by `ok`, with its line.
    fn number(
        &self,
        v: &Opt,
        key: &str,
        expected: &str,
        ok: impl Fn(f64) -> bool,
    ) -> Result<Option<(f64, usize)>, SpecError> {
        let Some(v) = v else { return Ok(None) };
        match *v.get_ref() {
            Val::Num(n) if n.is_finite() && ok(n) => Ok(Some((n, self.line(v.span())))),
            _ => Err(self.expected(v, key, expected)),
        }
    }

    fn string(&self, v: &Opt, key: &str, expected: &str) -> Result<Option<String>, SpecError> {
        let Some(v) = v else { return Ok(None) };
        match v.get_ref() {
            Val::Str(s) if !s.trim().is_empty() => Ok(Some(s.clone())),
            _ => Err(self.expected(v, key, expected)),
        }
    }

    fn boolean(&self, v: &Opt, key: &str) -> Result<Option<bool>, SpecError> {
        let Some(v) = v else { return Ok(None) };
        match v.get_ref() {
            Val::Bool(b) => Ok(Some(*b)),
            _ => Err(self.expected(v, key, "true or false")),
        }
    }

    /// One of an enum's names (ASCII case ignored).
    fn choice<T: Copy>(
        &self,
        v: &Opt,
        key: &str,
        table: &[(&str, T)],
    ) -> Result<Option<T>, SpecError> {
        let Some(v) = v else { return Ok(None) };
        let found = match v.get_ref() {
            Val::Str(s) => pick(s, table).ok(),
            _ => None,
        };
        match found {
            Some(t) => Ok(Some(t)),
            None => {
                let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
                Err(self.expected(v, key, &one_of(&names)))
            }
        }
    }

    /// The table, `None` if absent, or an error if the key holds another type.
    fn table<'t, T>(
        &self,
        t: &'t Option<Spanned<Tab<T>>>,
        key: &str,
    ) -> Result<Option<(&'t T, usize)>, SpecError> {
        let Some(t) = t else { return Ok(None) };
        match t.get_ref() {
            Tab::Table(inner) => Ok(Some((inner, self.line(t.span())))),
            Tab::Wrong(v) => Err(self.invalid(
                self.line(t.span()),
                key,
                format!("must be a table ([{key}]), got {v}"),
            )),
        }
    }

    fn build(&self, raw: RawSpec) -> Result<Spec, SpecError> {
        let name = self
            .string(&raw.name, "name", NON_EMPTY)?
            .unwrap_or_else(|| stem_or(self.path, "pattern"));
        let device = self.string(&raw.device, "device", "a non-empty device profile name")?;

        let surfaces = self.surfaces(&raw.surface)?;
        let material = self.material(&raw.material)?;
        let sheet = self.sheet(&raw.sheet)?;
        let pattern = self.pattern(&raw.pattern)?;

        Ok(Spec {
            name,
            path: self.path.to_path_buf(),
            device,
            surfaces,
            material,
            sheet,
            pattern,
        })
    }

    fn surfaces(
        &self,
        raw: &Option<Spanned<List<Spanned<Tab<RawSurface>>>>>,
    ) -> Result<Vec<SurfaceSpec>, SpecError> {
        const ONE_OR_MORE: &str = "one or more [[surface]] tables, each with `kind` and `path`";
        let entries = match raw {
            None => {
                return Err(self.invalid(
                    1,
                    "surface",
                    format!("missing: the spec needs {ONE_OR_MORE}"),
                ))
            }
            Some(list) => match list.get_ref() {
                List::Items(items) if !items.is_empty() => items,
                List::Items(_) => {
                    return Err(self.invalid(
                        self.line(list.span()),
                        "surface",
                        format!("must be {ONE_OR_MORE}, got an empty array"),
                    ))
                }
                List::Wrong(v) => {
                    return Err(self.invalid(
                        self.line(list.span()),
                        "surface",
                        format!("must be {ONE_OR_MORE}, got {v}"),
                    ))
                }
            },
        };
        let dir = self.path.parent().unwrap_or(Path::new(""));
        let mut out = Vec::with_capacity(entries.len());
        for (i, entry) in entries.iter().enumerate() {
            let key = format!("surface[{}]", i + 1);
            let header_line = self.line(entry.span());
            let s = match entry.get_ref() {
                Tab::Table(s) => s,
                Tab::Wrong(v) => {
                    return Err(self.invalid(
                        header_line,
                        &key,
                        format!("must be a table with `kind` and `path`, got {v}"),
                    ))
                }
            };
            let kind_key = format!("{key}.kind");
            let kind = self
                .choice(&s.kind, &kind_key, &SurfaceKind::NAMES)?
                .ok_or_else(|| {
                    self.invalid(
                        header_line,
                        &kind_key,
                        format!(
                            "missing: each [[surface]] needs a `kind`, {}",
                            one_of(&["mesh", "strip", "bent-sheet", "boundary"])
                        ),
                    )
                })?;
            if kind != SurfaceKind::BentSheet {
                self.no_bent_keys(s, &key)?;
            }
            if kind != SurfaceKind::Boundary {
                self.no_boundary_keys(s, &key)?;
            }
            match kind {
                SurfaceKind::BentSheet => out.push(self.bent_surface(s, &key, header_line, dir)?),
                SurfaceKind::Strip => out.push(self.strip_surface(s, &key, header_line, dir)?),
                SurfaceKind::Boundary => {
                    out.push(self.boundary_surface(s, &key, header_line, dir)?)
                }
                SurfaceKind::Mesh => {
                    let path_key = format!("{key}.path");
                    let rel = self.string(
                        &s.path,
                        &path_key,
                        "a non-empty string naming the mesh file, relative to the spec's folder",
                    )?;
                    let (rel, line) = match (rel, &s.path) {
                        (Some(rel), Some(p)) => (rel, self.line(p.span())),
                        _ => {
                            return Err(self.invalid(
                                header_line,
                                &path_key,
                                "missing: a mesh surface needs the path of its .obj file, \
                                 relative to the spec's folder"
                                    .to_string(),
                            ))
                        }
                    };
                    let path = dir.join(&rel);
                    let scale = self
                        .number(
                            &s.scale,
                            &format!("{key}.scale"),
                            "a positive number",
                            |v| v > 0.0,
                        )?
                        .map_or(1.0, |(v, _)| v);
                    let units = self
                        .choice(&s.units, &format!("{key}.units"), &Units::NAMES)?
                        .unwrap_or_default();
                    let name = self
                        .string(&s.name, &format!("{key}.name"), NON_EMPTY)?
                        .unwrap_or_else(|| stem_or(&path, &key));
                    out.push(SurfaceSpec {
                        kind,
                        path,
                        scale,
                        units,
                        name,
                        line,
                        strip: None,
                        bent: None,
                        boundary: None,
                        segment: self.segment(s, &key)?,
                    });
                }
            }
        }
        Ok(out)
    }

    fn material(&self, raw: &Option<Spanned<Tab<RawMaterial>>>) -> Result<Material, SpecError> {
        let Some((m, _)) = self.table(raw, "material")? else {
            return Ok(Material::default());
        };
        let kind = self
            .choice(&m.kind, "material.kind", &MaterialKind::NAMES)?
            .unwrap_or_default();
        let thickness = self
            .number(&m.thickness, "material.thickness", MM_POSITIVE, |v| v > 0.0)?
            .map_or(kind.default_thickness(), |(v, _)| v);
        Ok(Material { kind, thickness })
    }

    fn sheet(&self, raw: &Option<Spanned<Tab<RawSheet>>>) -> Result<SheetSpec, SpecError> {
        let Some((s, header_line)) = self.table(raw, "sheet")? else {
            return Ok(SheetSpec::default());
        };
        let d = SheetSpec::default();
        let positive = |v: f64| v > 0.0;
        let non_negative = |v: f64| v >= 0.0;
        let width = self.number(&s.width, "sheet.width", MM_POSITIVE, positive)?;
        let height = self.number(&s.height, "sheet.height", MM_POSITIVE, positive)?;
        let roll = self.boolean(&s.roll, "sheet.roll")?.unwrap_or(false);
        let margin = self.number(&s.margin, "sheet.margin", MM_NON_NEGATIVE, non_negative)?;
        let spacing = self.number(&s.spacing, "sheet.spacing", MM_NON_NEGATIVE, non_negative)?;

        if let (true, Some((_, line))) = (roll, height) {
            return Err(self.invalid(
                line,
                "sheet.height",
                "not allowed with `roll = true` (a roll has no fixed length); \
                 remove `height` or set `roll = false`"
                    .to_string(),
            ));
        }
        let (width, width_line) = width.unwrap_or((d.width, header_line));
        let height = if roll {
            None
        } else {
            Some(height.unwrap_or((d.height.unwrap_or(297.0), header_line)))
        };
        let margin_given = margin.is_some();
        let (margin, margin_line) = margin.unwrap_or((d.margin, header_line));
        let spacing = spacing.map_or(d.spacing, |(v, _)| v);

        let limits = std::iter::once(("width", width, width_line))
            .chain(height.map(|(h, l)| ("height", h, l)));
        for (what, size, size_line) in limits {
            if 2.0 * margin >= size {
                let (line, default_note) = if margin_given {
                    (margin_line, "")
                } else {
                    (size_line, " (the default)")
                };
                return Err(self.invalid(
                    line,
                    "sheet.margin",
                    format!(
                        "must be less than half the sheet {what} ({} mm), got {}{default_note}",
                        fmt_num(size),
                        fmt_num(margin)
                    ),
                ));
            }
        }
        Ok(SheetSpec {
            width,
            height: height.map(|(h, _)| h),
            margin,
            spacing,
        })
    }

    fn pattern(&self, raw: &Option<Spanned<Tab<RawPattern>>>) -> Result<PatternSpec, SpecError> {
        let Some((p, _)) = self.table(raw, "pattern")? else {
            return Ok(PatternSpec::default());
        };
        let fold_threshold_deg = self
            .number(
                &p.fold_threshold,
                "pattern.fold_threshold",
                "a number of degrees, at least 0 and less than 180",
                |v| (0.0..180.0).contains(&v),
            )?
            .map_or(PatternSpec::default().fold_threshold_deg, |(v, _)| v);
        let tabs = self.choice(
            &p.tabs,
            "pattern.tabs",
            &[
                ("none", crate::pattern::Tabs::None),
                ("one-side", crate::pattern::Tabs::OneSide),
                ("both", crate::pattern::Tabs::Both),
            ],
        )?;
        let mm = |v: &Opt, key: &str, expected: &str, positive: bool| {
            self.number(
                v,
                key,
                expected,
                |x| if positive { x > 0.0 } else { x >= 0.0 },
            )
            .map(|o| o.map(|(v, _)| v))
        };
        Ok(PatternSpec {
            fold_threshold_deg,
            tabs,
            tab_height: mm(
                &p.tab_height,
                "pattern.tab_height",
                "a length in mm, more than 0",
                true,
            )?,
            allowance: mm(
                &p.allowance,
                "pattern.allowance",
                "a length in mm, at least 0",
                false,
            )?,
            notches: mm(
                &p.notches,
                "pattern.notches",
                "a spacing in mm, at least 0 (0: no notches)",
                false,
            )?,
            kerf: mm(&p.kerf, "pattern.kerf", "a width in mm, at least 0", false)?,
            bend_notches: self.boolean(&p.bend_notches, "pattern.bend_notches")?,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Smooth meshes (issue 7): `segment`, `charts`, `f_max`, `approximate`, `simplify` on
// `kind = "mesh"`
// ---------------------------------------------------------------------------------------------

/// How a mesh surface is cut into pieces (`kind = "mesh"` keys, issue 7):
///
/// ```toml
/// segment = "dcharts"      # "faces": exact polyhedral unfolding; "dcharts": nearly developable
///                          # charts (default: dcharts when the mesh is smooth, see
///                          # `surface::dcharts::is_smooth`)
/// charts = 8               # initial estimate of the number of charts, integer >= 1
/// f_max = 0.2              # D-Charts fitting threshold, > 0 and <= 1
/// approximate = { iterations = 1, fixed = ["boundary", 12] }   # DCS approximation first;
///                          # fixed: "boundary" and/or 1-based vertex numbers of the mesh
/// simplify = 0.5           # mm >= 0: largest deviation of a simplified seam between charts
///                          # (thesis §5.3, `pattern::simplify`); 0: off; default by material
///                          # (paper and fabric 0.5, metal 0.1); exact unfoldings never change
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SegmentSpec {
    /// `None`: decided from the mesh.
    pub mode: Option<Segment>,
    pub charts: Option<usize>,
    pub f_max: Option<f64>,
    pub approximate: Option<ApproximateSpec>,
    /// Seam simplification tolerance (mm); `None`: the material's default.
    pub simplify: Option<f64>,
}

/// `segment = "faces" | "dcharts"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Segment {
    /// Every face a rigid panel, unfolded exactly.
    Faces,
    /// D-Charts: nearly developable charts, parameterised.
    Dcharts,
}

impl Segment {
    const NAMES: [(&'static str, Segment); 2] =
        [("faces", Segment::Faces), ("dcharts", Segment::Dcharts)];
}

impl FromStr for Segment {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        pick(s, &Self::NAMES)
    }
}

/// `approximate = { iterations, fixed }`: DCS approximation before segmenting.
#[derive(Debug, Clone, PartialEq)]
pub struct ApproximateSpec {
    /// Rounds (>= 1; default 1).
    pub iterations: usize,
    /// Vertices that stay in place.
    pub fixed: Vec<Fixed>,
}

/// A fixed vertex (or set) of the DCS approximation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fixed {
    /// Every vertex on the mesh boundary.
    Boundary,
    /// A vertex by its 1-based number in the (welded) mesh.
    Vertex(usize),
}

impl Ctx<'_> {
    /// The issue-7 keys of a mesh surface.
    fn segment(&self, s: &RawSurface, key: &str) -> Result<SegmentSpec, SpecError> {
        let mode = self.choice(&s.segment, &format!("{key}.segment"), &Segment::NAMES)?;
        let charts = self
            .number(
                &s.charts,
                &format!("{key}.charts"),
                "a whole number of charts, at least 1",
                |v| v >= 1.0 && v.fract() == 0.0 && v <= 1e6,
            )?
            .map(|(v, _)| v as usize);
        let f_max = self
            .number(
                &s.f_max,
                &format!("{key}.f_max"),
                "a fitting threshold, more than 0 and at most 1",
                |v| v > 0.0 && v <= 1.0,
            )?
            .map(|(v, _)| v);
        let approximate = match &s.approximate {
            None => None,
            Some(v) => Some(self.approximate(v, &format!("{key}.approximate"))?),
        };
        let simplify = self
            .number(
                &s.simplify,
                &format!("{key}.simplify"),
                "a tolerance in mm, at least 0 (0: no simplification)",
                |v| v >= 0.0,
            )?
            .map(|(v, _)| v);
        Ok(SegmentSpec {
            mode,
            charts,
            f_max,
            approximate,
            simplify,
        })
    }

    fn approximate(
        &self,
        v: &Spanned<toml::Value>,
        key: &str,
    ) -> Result<ApproximateSpec, SpecError> {
        let line = self.line(v.span());
        let bad = |k: &str, m: &str| self.invalid(line, k, m.to_string());
        let toml::Value::Table(t) = v.get_ref() else {
            return Err(bad(
                key,
                "must be a table { iterations = N, fixed = [...] }",
            ));
        };
        let mut out = ApproximateSpec {
            iterations: 1,
            fixed: Vec::new(),
        };
        for (k, val) in t {
            match k.as_str() {
                "iterations" => {
                    let n = match val {
                        toml::Value::Integer(n) if (1..=100).contains(n) => *n as usize,
                        _ => {
                            return Err(bad(
                                &format!("{key}.iterations"),
                                &format!("must be a whole number from 1 to 100, got {val}"),
                            ))
                        }
                    };
                    out.iterations = n;
                }
                "fixed" => {
                    let toml::Value::Array(items) = val else {
                        return Err(bad(
                            &format!("{key}.fixed"),
                            "must be an array of \"boundary\" and 1-based vertex numbers",
                        ));
                    };
                    for it in items {
                        let f = match it {
                            toml::Value::String(s) if s.trim().eq_ignore_ascii_case("boundary") => {
                                Fixed::Boundary
                            }
                            toml::Value::Integer(n) if *n >= 1 => Fixed::Vertex(*n as usize),
                            _ => {
                                return Err(bad(
                                    &format!("{key}.fixed"),
                                    &format!(
                                        "entries must be \"boundary\" or a vertex number from 1, got {it}"
                                    ),
                                ))
                            }
                        };
                        out.fixed.push(f);
                    }
                }
                other => {
                    return Err(bad(
                        &format!("{key}.{other}"),
                        "unknown key; expected `iterations` or `fixed`",
                    ))
                }
            }
        }
        Ok(out)
    }
}

// ---------------------------------------------------------------------------------------------
// Strips (issue 4): `kind = "strip"` with curves `p` and `q`
// ---------------------------------------------------------------------------------------------

impl Ctx<'_> {
    /// `bend_lines` of a strip or a bent sheet: "all" (default), "none" or a spacing in mm.
    fn bend_lines(
        &self,
        v: &Option<Spanned<Val>>,
        key: &str,
    ) -> Result<crate::surface::strip::BendLines, SpecError> {
        use crate::surface::strip::BendLines;
        let Some(v) = v else {
            return Ok(BendLines::All);
        };
        match v.get_ref() {
            Val::Str(t) if t.trim().eq_ignore_ascii_case("all") => Ok(BendLines::All),
            Val::Str(t) if t.trim().eq_ignore_ascii_case("none") => Ok(BendLines::None),
            Val::Num(x) if x.is_finite() && *x > 0.0 => Ok(BendLines::Spacing(*x)),
            _ => Err(self.expected(
                v,
                &format!("{key}.bend_lines"),
                "\"all\", \"none\" or a positive spacing in millimetres",
            )),
        }
    }

    /// One `kind = "strip"` entry.
    fn strip_surface(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<SurfaceSpec, SpecError> {
        use crate::surface::strip::Method;
        self.refuse(
            key,
            &[
                ("path", span(&s.path)),
                ("scale", span(&s.scale)),
                ("units", span(&s.units)),
                ("segment", span(&s.segment)),
                ("charts", span(&s.charts)),
                ("f_max", span(&s.f_max)),
                ("approximate", span(&s.approximate)),
                ("simplify", span(&s.simplify)),
            ],
            "is for mesh surfaces; a strip takes the curves `p` and `q`",
        )?;
        let tolerance = self
            .number(
                &s.tolerance,
                &format!("{key}.tolerance"),
                MM_POSITIVE,
                |v| v > 0.0,
            )?
            .map_or(crate::geom::curve::DEFAULT_TOLERANCE, |(v, _)| v);
        let method = self
            .choice(&s.method, &format!("{key}.method"), &Method::NAMES)?
            .unwrap_or_default();
        let side = self
            .choice(&s.side, &format!("{key}.side"), &SheetSide::NAMES)?
            .unwrap_or_default();
        let k_factor = self
            .number(
                &s.k_factor,
                &format!("{key}.k_factor"),
                "a number from 0 to 1",
                |v| (0.0..=1.0).contains(&v),
            )?
            .map_or(0.4, |(v, _)| v);
        let bend_lines = self.bend_lines(&s.bend_lines, key)?;
        let mut curves = Vec::new();
        for (name, v) in [("p", &s.p), ("q", &s.q)] {
            let ck = format!("{key}.{name}");
            let v = v.as_ref().ok_or_else(|| {
                self.invalid(
                    header_line,
                    &ck,
                    "missing: a strip needs two boundary curves `p` and `q`".to_string(),
                )
            })?;
            let line = self.line(v.span());
            let c = self.curve(v.get_ref(), &ck, line, dir)?;
            let sampled = c.sample(tolerance).map_err(|e| {
                use crate::geom::curve::CurveError as E;
                let sub = match &e {
                    E::NotPositive { what, .. } => format!("{ck}.{what}"),
                    E::CornerRadius { .. } => format!("{ck}.corner_radius"),
                    _ => ck.clone(),
                };
                self.invalid(line, &sub, e.to_string())
            })?;
            curves.push((c, sampled, line));
        }
        let (qc, qs, q_line) = curves
            .pop()
            .ok_or_else(|| self.invalid(header_line, key, "no q".into()))?;
        let (pc, ps, p_line) = curves
            .pop()
            .ok_or_else(|| self.invalid(header_line, key, "no p".into()))?;
        if let Err(e) = crate::surface::strip::Strip::new(&ps, &qs) {
            return Err(self.invalid(q_line, &format!("{key}.q"), e.to_string()));
        }
        let name = self
            .string(&s.name, &format!("{key}.name"), NON_EMPTY)?
            .unwrap_or_else(|| format!("strip{}", key.trim_start_matches("surface")));
        Ok(SurfaceSpec {
            kind: SurfaceKind::Strip,
            path: self.path.to_path_buf(),
            scale: 1.0,
            units: Units::Mm,
            name,
            line: p_line,
            strip: Some(StripSpec {
                p: pc,
                q: qc,
                method,
                bend_lines,
                tolerance,
                neutral_offset: 0.0,
                sheet: Some((side, k_factor)),
            }),
            bent: None,
            boundary: None,
            segment: SegmentSpec::default(),
        })
    }

    /// A curve: an inline list of points, or a table with a `kind` (see the module doc).
    fn curve(
        &self,
        v: &toml::Value,
        key: &str,
        line: usize,
        dir: &Path,
    ) -> Result<crate::geom::curve::Curve, SpecError> {
        use crate::geom::curve::Curve;
        use toml::Value;
        let bad = |k: &str, msg: String| self.invalid(line, k, msg);
        let t = match v {
            Value::Array(items) => {
                return Ok(Curve::Points {
                    points: self.points(items, key, line)?,
                    closed: false,
                })
            }
            Value::Table(t) => t,
            other => {
                return Err(bad(
                    key,
                    format!(
                        "must be a list of points [[x, y, z], ...] or a table with `kind`, got {}",
                        other.type_str()
                    ),
                ))
            }
        };
        const KINDS: [&str; 7] = [
            "points", "csv", "circle", "ellipse", "rect", "bezier", "bspline",
        ];
        let kind = match t.get("kind") {
            None if t.contains_key("points") => "points".to_string(),
            None => {
                return Err(bad(
                    &format!("{key}.kind"),
                    format!("missing: a curve table needs `kind`, {}", one_of(&KINDS)),
                ))
            }
            Some(Value::String(k)) if KINDS.iter().any(|x| x.eq_ignore_ascii_case(k.trim())) => {
                k.trim().to_ascii_lowercase()
            }
            Some(other) => {
                return Err(bad(
                    &format!("{key}.kind"),
                    format!("must be {}, got {other}", one_of(&KINDS)),
                ))
            }
        };
        let allowed: &[&str] = match kind.as_str() {
            "points" => &["points", "closed"],
            "csv" => &["path", "closed"],
            "circle" => &["center", "radius", "diameter"],
            "ellipse" => &["center", "rx", "ry"],
            "rect" => &["center", "width", "height", "corner_radius"],
            "bezier" => &["control"],
            _ => &["control", "degree", "closed"],
        };
        for k in t.keys() {
            if k != "kind" && !allowed.contains(&k.as_str()) {
                return Err(bad(
                    &format!("{key}.{k}"),
                    format!(
                        "unknown key for a {kind} curve; expected {}",
                        one_of(allowed)
                    ),
                ));
            }
        }
        let num = |k: &str| -> Result<Option<f64>, SpecError> {
            match t.get(k) {
                None => Ok(None),
                Some(Value::Integer(i)) => Ok(Some(*i as f64)),
                Some(Value::Float(f)) if f.is_finite() => Ok(Some(*f)),
                Some(other) => Err(bad(
                    &format!("{key}.{k}"),
                    format!("must be a finite number, got {other}"),
                )),
            }
        };
        let need = |k: &str| -> Result<f64, SpecError> {
            num(k)?.ok_or_else(|| {
                bad(
                    &format!("{key}.{k}"),
                    format!("missing: a {kind} curve needs `{k}`"),
                )
            })
        };
        let closed = match t.get("closed") {
            None => false,
            Some(Value::Boolean(b)) => *b,
            Some(other) => {
                return Err(bad(
                    &format!("{key}.closed"),
                    format!("must be true or false, got {other}"),
                ))
            }
        };
        let center = match t.get("center") {
            None => glam::DVec3::ZERO,
            Some(Value::Array(a)) => self.point(a, &format!("{key}.center"), line)?,
            Some(other) => {
                return Err(bad(
                    &format!("{key}.center"),
                    format!("must be [x, y] or [x, y, z], got {other}"),
                ))
            }
        };
        let list = |k: &str| -> Result<Vec<glam::DVec3>, SpecError> {
            match t.get(k) {
                Some(Value::Array(items)) => self.points(items, &format!("{key}.{k}"), line),
                Some(other) => Err(bad(
                    &format!("{key}.{k}"),
                    format!("must be a list of points [[x, y, z], ...], got {other}"),
                )),
                None => Err(bad(
                    &format!("{key}.{k}"),
                    format!("missing: a {kind} curve needs `{k}`"),
                )),
            }
        };
        Ok(match kind.as_str() {
            "points" => Curve::Points {
                points: list("points")?,
                closed,
            },
            "csv" => match t.get("path") {
                Some(Value::String(p)) if !p.trim().is_empty() => Curve::Csv {
                    path: dir.join(p),
                    closed,
                },
                _ => return Err(bad(
                    &format!("{key}.path"),
                    "must be a non-empty string naming a CSV file, relative to the spec's folder"
                        .into(),
                )),
            },
            "circle" => {
                let radius = match (num("radius")?, num("diameter")?) {
                    (Some(r), None) => r,
                    (None, Some(d)) => 0.5 * d,
                    _ => {
                        return Err(bad(
                            &format!("{key}.radius"),
                            "a circle needs exactly one of `radius` and `diameter`".into(),
                        ))
                    }
                };
                Curve::Circle { center, radius }
            }
            "ellipse" => Curve::Ellipse {
                center,
                rx: need("rx")?,
                ry: need("ry")?,
            },
            "rect" => Curve::Rect {
                center,
                width: need("width")?,
                height: need("height")?,
                corner_radius: num("corner_radius")?.unwrap_or(0.0),
            },
            "bezier" => Curve::Bezier {
                control: list("control")?,
            },
            _ => {
                let degree = match num("degree")? {
                    None => 3,
                    Some(d) if (1.0..=10.0).contains(&d) && d.fract() == 0.0 => d as usize,
                    Some(d) => {
                        return Err(bad(
                            &format!("{key}.degree"),
                            format!("must be a whole number from 1 to 10, got {d}"),
                        ))
                    }
                };
                Curve::BSpline {
                    control: list("control")?,
                    degree,
                    closed,
                }
            }
        })
    }

    fn points(
        &self,
        items: &[toml::Value],
        key: &str,
        line: usize,
    ) -> Result<Vec<glam::DVec3>, SpecError> {
        items
            .iter()
            .enumerate()
            .map(|(k, it)| match it {
                toml::Value::Array(a) => self.point(a, &format!("{key}[{}]", k + 1), line),
                other => Err(self.invalid(
                    line,
                    &format!("{key}[{}]", k + 1),
                    format!("must be a point [x, y] or [x, y, z], got {other}"),
                )),
            })
            .collect()
    }

    fn point(&self, a: &[toml::Value], key: &str, line: usize) -> Result<glam::DVec3, SpecError> {
        let v: Option<Vec<f64>> = a
            .iter()
            .map(|x| match x {
                toml::Value::Integer(i) => Some(*i as f64),
                toml::Value::Float(f) if f.is_finite() => Some(*f),
                _ => None,
            })
            .collect();
        match v {
            Some(v) if v.len() == 2 || v.len() == 3 => Ok(glam::DVec3::new(
                v[0],
                v[1],
                v.get(2).copied().unwrap_or(0.0),
            )),
            _ => Err(self.invalid(
                line,
                key,
                "must be a point of 2 or 3 finite numbers, [x, y] or [x, y, z]".to_string(),
            )),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Bent sheets (issue 5): `kind = "bent-sheet"`
// ---------------------------------------------------------------------------------------------
//
// ```toml
// [[surface]]
// kind = "bent-sheet"
// outline = [210, 297]              # width × height from (0, 0), or [[x, y], ...]
// holes = [[[80, 120], [130, 120], [130, 170], [80, 170]]]   # optional
// line = [[105, 0], [105, 297]]     # a straight line on the sheet, start to end, or
// arc = { center = [105, 0], radius = 150, start_deg = 60, end_deg = 120 }   # an arc, or
// flat_curve = [[0, 40], [50, 48], [110, 32], [160, 40]]   # a Bézier on the sheet (§5)
// control_points = [[0, 0, 0], [0, 100, 60], [0, 200, -60], [0, 297, 0]]   # a Bézier, or
// control_points = { kind = "bspline", control = [...], degree = 3 }
// handles = { start = [0, 0, 0], start_normal = [0, 0, 1], end = [0, 250, 0], end_normal = [0, 0, 1] }
// length_fit = "scale"              # or "trim" (§4.1.3)
// tolerance = 0.05                  # mm
// bend_lines = "all"                # "none" or a spacing in mm
// pieces = [{ line = ..., control_points = ... }, ...]   # several curved pieces instead
// ```

/// Where a key stands in the file, if it is given.
fn span<T>(v: &Option<Spanned<T>>) -> Option<Range<usize>> {
    v.as_ref().map(|v| v.span())
}

impl Ctx<'_> {
    /// Keys only a bent sheet takes are errors on other kinds.
    fn no_bent_keys(&self, s: &RawSurface, key: &str) -> Result<(), SpecError> {
        self.refuse(
            key,
            &[
                ("outline", span(&s.outline)),
                ("holes", span(&s.holes)),
                ("line", span(&s.line)),
                ("arc", span(&s.arc)),
                ("flat_curve", span(&s.flat_curve)),
                ("control_points", span(&s.control_points)),
                ("handles", span(&s.handles)),
                ("length_fit", span(&s.length_fit)),
                ("pieces", span(&s.pieces)),
            ],
            "is for bent sheets (kind = \"bent-sheet\")",
        )?;
        Ok(())
    }

    /// A 2D point `[x, y]`.
    fn pt2(&self, v: &toml::Value, key: &str, line: usize) -> Result<glam::DVec2, SpecError> {
        let nums: Option<Vec<f64>> = match v {
            toml::Value::Array(a) => a
                .iter()
                .map(|x| match x {
                    toml::Value::Integer(i) => Some(*i as f64),
                    toml::Value::Float(f) if f.is_finite() => Some(*f),
                    _ => None,
                })
                .collect(),
            _ => None,
        };
        match nums {
            Some(n) if n.len() == 2 => Ok(glam::DVec2::new(n[0], n[1])),
            _ => Err(self.invalid(
                line,
                key,
                format!("must be a point on the sheet [x, y] of finite numbers (mm), got {v}"),
            )),
        }
    }

    /// A list of 2D points with at least `min` entries.
    fn pts2(
        &self,
        v: &toml::Value,
        key: &str,
        line: usize,
        min: usize,
    ) -> Result<Vec<glam::DVec2>, SpecError> {
        let toml::Value::Array(items) = v else {
            return Err(self.invalid(
                line,
                key,
                format!(
                    "must be a list of points [[x, y], ...], got {}",
                    v.type_str()
                ),
            ));
        };
        if items.len() < min {
            return Err(self.invalid(
                line,
                key,
                format!("needs at least {min} points, got {}", items.len()),
            ));
        }
        items
            .iter()
            .enumerate()
            .map(|(i, it)| self.pt2(it, &format!("{key}[{}]", i + 1), line))
            .collect()
    }

    /// The curve on the sheet of one bent piece: exactly one of `line` (two points), `arc`
    /// (`{ center, radius, start_deg, end_deg }`) and `flat_curve` (Bézier control points
    /// `[[x, y], ...]` or `{ kind = "bezier" | "bspline", control, degree }`).
    fn flat_path(
        &self,
        pk: &str,
        [line, arc, curve]: [Option<&toml::Value>; 3],
        at: usize,
    ) -> Result<crate::surface::geodesic::FlatPath, SpecError> {
        use crate::surface::geodesic::{FlatPath, Spline};
        let num = |v: Option<&toml::Value>| match v {
            Some(toml::Value::Integer(i)) => Some(*i as f64),
            Some(toml::Value::Float(f)) if f.is_finite() => Some(*f),
            _ => None,
        };
        match (line, arc, curve) {
            (Some(lv), None, None) => {
                let pts = self.pts2(lv, &format!("{pk}line"), at, 2)?;
                if pts.len() != 2 {
                    return Err(self.invalid(
                        at,
                        &format!("{pk}line"),
                        format!(
                            "must be exactly two points [[x0, y0], [x1, y1]], got {}",
                            pts.len()
                        ),
                    ));
                }
                Ok(FlatPath::Line([pts[0], pts[1]]))
            }
            (None, Some(av), None) => {
                let ak = format!("{pk}arc");
                const KEYS: [&str; 4] = ["center", "radius", "start_deg", "end_deg"];
                let toml::Value::Table(t) = av else {
                    return Err(self.invalid(
                        at,
                        &ak,
                        format!(
                            "must be a table {{ center = [x, y], radius, start_deg, end_deg }}, got {}",
                            av.type_str()
                        ),
                    ));
                };
                if let Some(k) = t.keys().find(|k| !KEYS.contains(&k.as_str())) {
                    return Err(self.invalid(
                        at,
                        &format!("{ak}.{k}"),
                        format!("unknown key; expected {}", one_of(&KEYS)),
                    ));
                }
                let center = match t.get("center") {
                    Some(v) => self.pt2(v, &format!("{ak}.center"), at)?,
                    None => {
                        return Err(self.invalid(
                            at,
                            &format!("{ak}.center"),
                            "missing: the arc's centre on the sheet [x, y] (mm)".to_string(),
                        ))
                    }
                };
                let get = |k: &str, what: &str| {
                    num(t.get(k)).ok_or_else(|| {
                        self.invalid(
                            at,
                            &format!("{ak}.{k}"),
                            format!("missing or not a finite number: {what}"),
                        )
                    })
                };
                let radius = get("radius", "the arc's radius (mm)")?;
                let start_deg = get("start_deg", "the angle of the arc's start (degrees from +x)")?;
                let end_deg = get(
                    "end_deg",
                    "the angle of the arc's end (degrees from +x; counter-clockwise when larger than start_deg)",
                )?;
                if radius <= 0.0 {
                    return Err(self.invalid(
                        at,
                        &format!("{ak}.radius"),
                        format!("must be positive (mm), got {radius}"),
                    ));
                }
                let sweep = (end_deg - start_deg).abs();
                if sweep == 0.0 || sweep > 360.0 {
                    return Err(self.invalid(
                        at,
                        &format!("{ak}.end_deg"),
                        format!(
                            "the arc must turn by more than 0° and at most 360°, got start_deg {start_deg}, end_deg {end_deg}"
                        ),
                    ));
                }
                Ok(FlatPath::Arc {
                    center,
                    radius,
                    start_deg,
                    end_deg,
                })
            }
            (None, None, Some(cv)) => {
                let ck = format!("{pk}flat_curve");
                let z = |p: Vec<glam::DVec2>| -> Vec<glam::DVec3> {
                    p.iter().map(|q| glam::DVec3::new(q.x, q.y, 0.0)).collect()
                };
                match cv {
                    toml::Value::Array(_) => {
                        Ok(FlatPath::Curve(Spline::bezier(z(self.pts2(cv, &ck, at, 3)?))))
                    }
                    toml::Value::Table(t) => {
                        const KEYS: [&str; 3] = ["kind", "control", "degree"];
                        if let Some(k) = t.keys().find(|k| !KEYS.contains(&k.as_str())) {
                            return Err(self.invalid(
                                at,
                                &format!("{ck}.{k}"),
                                format!("unknown key; expected {}", one_of(&KEYS)),
                            ));
                        }
                        let control = match t.get("control") {
                            Some(v) => z(self.pts2(v, &format!("{ck}.control"), at, 3)?),
                            None => {
                                return Err(self.invalid(
                                    at,
                                    &format!("{ck}.control"),
                                    "missing: the control points on the sheet [[x, y], ...]"
                                        .to_string(),
                                ))
                            }
                        };
                        match t.get("kind").and_then(|v| v.as_str()) {
                            Some("bezier") | None => Ok(FlatPath::Curve(Spline::bezier(control))),
                            Some("bspline") => {
                                let degree = match t.get("degree") {
                                    None => 3,
                                    Some(toml::Value::Integer(d)) if (2..=9).contains(d) => {
                                        *d as usize
                                    }
                                    Some(v) => {
                                        return Err(self.invalid(
                                            at,
                                            &format!("{ck}.degree"),
                                            format!("must be an integer from 2 to 9, got {v}"),
                                        ))
                                    }
                                };
                                Ok(FlatPath::Curve(Spline::bspline(control, degree)))
                            }
                            Some(k) => Err(self.invalid(
                                at,
                                &format!("{ck}.kind"),
                                format!("must be \"bezier\" or \"bspline\", got \"{k}\""),
                            )),
                        }
                    }
                    v => Err(self.invalid(
                        at,
                        &ck,
                        format!(
                            "must be Bézier control points [[x, y], ...] or a table {{ kind = \"bspline\", control, degree }}, got {}",
                            v.type_str()
                        ),
                    )),
                }
            }
            (None, None, None) => Err(self.invalid(
                at,
                &format!("{pk}line"),
                "missing: the curve on the sheet the control curve bends: `line = [[x0, y0], [x1, y1]]`, `arc = { center = [x, y], radius, start_deg, end_deg }` or `flat_curve = [[x, y], ...]`".to_string(),
            )),
            _ => Err(self.invalid(
                at,
                &format!("{pk}line"),
                "give exactly one of `line`, `arc` and `flat_curve` (the curve on the sheet)"
                    .to_string(),
            )),
        }
    }

    /// One `kind = "bent-sheet"` entry.
    fn bent_surface(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<SurfaceSpec, SpecError> {
        use crate::surface::geodesic::{Control, FlatPath, LengthFit, PieceSpec};
        self.refuse(
            key,
            &[
                ("path", span(&s.path)),
                ("scale", span(&s.scale)),
                ("units", span(&s.units)),
            ],
            "is for mesh surfaces; a bent sheet takes `outline`, `line` (or `arc`, `flat_curve`) and `control_points` or `handles`",
        )?;
        self.refuse(
            key,
            &[("p", span(&s.p)), ("q", span(&s.q))],
            "is for strips; a bent sheet takes `line` (or `arc`, `flat_curve`) and `control_points` or `handles`",
        )?;
        self.refuse(key, &[("method", span(&s.method))], "is for strips")?;
        let tolerance = self
            .number(
                &s.tolerance,
                &format!("{key}.tolerance"),
                MM_POSITIVE,
                |v| v > 0.0,
            )?
            .map_or(crate::geom::curve::DEFAULT_TOLERANCE, |(v, _)| v);
        let bend_lines = self.bend_lines(&s.bend_lines, key)?;
        // Outline: [width, height] or a list of points.
        let ok = format!("{key}.outline");
        let ov = s.outline.as_ref().ok_or_else(|| {
            self.invalid(
                header_line,
                &ok,
                "missing: a bent sheet needs its flat `outline`, [width, height] or [[x, y], ...]"
                    .to_string(),
            )
        })?;
        let oline = self.line(ov.span());
        let outline = match ov.get_ref() {
            toml::Value::Array(a)
                if a.len() == 2 && a.iter().all(|x| x.is_integer() || x.is_float()) =>
            {
                let wh = self.pt2(ov.get_ref(), &ok, oline)?;
                if !(wh.x > 0.0 && wh.y > 0.0) {
                    return Err(self.invalid(
                        oline,
                        &ok,
                        format!(
                            "width and height must be positive, got [{}, {}]",
                            wh.x, wh.y
                        ),
                    ));
                }
                vec![
                    glam::DVec2::ZERO,
                    glam::DVec2::new(wh.x, 0.0),
                    wh,
                    glam::DVec2::new(0.0, wh.y),
                ]
            }
            v => self.pts2(v, &ok, oline, 3)?,
        };
        let mut holes = Vec::new();
        if let Some(hv) = &s.holes {
            let hl = self.line(hv.span());
            let hk = format!("{key}.holes");
            match hv.get_ref() {
                toml::Value::Array(items) => {
                    for (i, it) in items.iter().enumerate() {
                        holes.push(self.pts2(it, &format!("{hk}[{}]", i + 1), hl, 3)?);
                    }
                }
                v => {
                    return Err(self.invalid(
                        hl,
                        &hk,
                        format!(
                            "must be a list of point lists [[[x, y], ...], ...], got {}",
                            v.type_str()
                        ),
                    ))
                }
            }
        }
        // One piece from a table of keys (the surface itself or an entry of `pieces`).
        let piece = |pk: &str,
                     path: FlatPath,
                     control: Option<&toml::Value>,
                     handles: Option<&toml::Value>,
                     fit: Option<&toml::Value>,
                     at: usize|
         -> Result<PieceSpec, SpecError> {
            let control = match (control, handles) {
                (Some(_), Some(_)) | (None, None) => {
                    return Err(self.invalid(
                        at,
                        &format!("{pk}control_points"),
                        "a bent sheet needs exactly one of `control_points` and `handles`"
                            .to_string(),
                    ))
                }
                (Some(cv), None) => {
                    let ck = format!("{pk}control_points");
                    let c = self.curve(cv, &ck, at, dir)?;
                    match c {
                        crate::geom::curve::Curve::Points { points, .. } => {
                            Control::Curve(crate::geom::curve::Curve::Bezier { control: points })
                        }
                        c @ (crate::geom::curve::Curve::Bezier { .. }
                        | crate::geom::curve::Curve::BSpline { .. }) => Control::Curve(c),
                        _ => {
                            return Err(self.invalid(
                                at,
                                &ck,
                                "must be Bézier control points [[x, y, z], ...] or a table with kind = \"bezier\" or \"bspline\"".to_string(),
                            ))
                        }
                    }
                }
                (None, Some(hv)) => {
                    let hk = format!("{pk}handles");
                    let toml::Value::Table(t) = hv else {
                        return Err(self.invalid(
                            at,
                            &hk,
                            "must be a table { start, start_normal, end, end_normal }".to_string(),
                        ));
                    };
                    for k in t.keys() {
                        if !["start", "start_normal", "end", "end_normal"].contains(&k.as_str()) {
                            return Err(self.invalid(
                                at,
                                &format!("{hk}.{k}"),
                                format!(
                                    "unknown key; expected {}",
                                    one_of(&["start", "start_normal", "end", "end_normal"])
                                ),
                            ));
                        }
                    }
                    let get = |k: &str| -> Result<glam::DVec3, SpecError> {
                        match t.get(k) {
                            Some(toml::Value::Array(a)) => self.point(a, &format!("{hk}.{k}"), at),
                            _ => Err(self.invalid(
                                at,
                                &format!("{hk}.{k}"),
                                "missing or not a point [x, y, z]".to_string(),
                            )),
                        }
                    };
                    Control::Handles {
                        start: get("start")?,
                        start_normal: get("start_normal")?,
                        end: get("end")?,
                        end_normal: get("end_normal")?,
                    }
                }
            };
            let fit = match fit {
                None => LengthFit::default(),
                Some(toml::Value::String(f)) => match pick(f, &LengthFit::NAMES) {
                    Ok(f) => f,
                    Err(m) => {
                        return Err(self.invalid(at, &format!("{pk}length_fit"), m));
                    }
                },
                Some(v) => {
                    return Err(self.invalid(
                        at,
                        &format!("{pk}length_fit"),
                        format!("must be \"scale\" or \"trim\", got {v}"),
                    ))
                }
            };
            Ok(PieceSpec { path, control, fit })
        };
        let mut pieces = Vec::new();
        let line_no;
        if let Some(pv) = &s.pieces {
            let pl = self.line(pv.span());
            line_no = pl;
            self.refuse(
                key,
                &[
                    ("line", span(&s.line)),
                    ("arc", span(&s.arc)),
                    ("flat_curve", span(&s.flat_curve)),
                    ("control_points", span(&s.control_points)),
                    ("handles", span(&s.handles)),
                    ("length_fit", span(&s.length_fit)),
                ],
                "goes into each entry of `pieces` when `pieces` is given",
            )?;
            let items = match pv.get_ref() {
                toml::Value::Array(items) if !items.is_empty() => items,
                v => {
                    return Err(self.invalid(
                        pl,
                        &format!("{key}.pieces"),
                        format!(
                        "must be a non-empty list of tables {{ line, control_points }}, got {v}"
                    ),
                    ))
                }
            };
            for (i, it) in items.iter().enumerate() {
                let pk = format!("{key}.pieces[{}].", i + 1);
                let toml::Value::Table(t) = it else {
                    return Err(self.invalid(
                        pl,
                        pk.trim_end_matches('.'),
                        "must be a table { line | arc | flat_curve, control_points | handles }"
                            .to_string(),
                    ));
                };
                const KEYS: [&str; 6] = [
                    "line",
                    "arc",
                    "flat_curve",
                    "control_points",
                    "handles",
                    "length_fit",
                ];
                for k in t.keys() {
                    if !KEYS.contains(&k.as_str()) {
                        return Err(self.invalid(
                            pl,
                            &format!("{pk}{k}"),
                            format!("unknown key; expected {}", one_of(&KEYS)),
                        ));
                    }
                }
                let path =
                    self.flat_path(&pk, [t.get("line"), t.get("arc"), t.get("flat_curve")], pl)?;
                pieces.push(piece(
                    &pk,
                    path,
                    t.get("control_points"),
                    t.get("handles"),
                    t.get("length_fit"),
                    pl,
                )?);
            }
        } else {
            let flat_key = s.line.as_ref().or(s.arc.as_ref()).or(s.flat_curve.as_ref());
            let at = flat_key.map_or(header_line, |v| self.line(v.span()));
            line_no = at;
            let cl = s
                .control_points
                .as_ref()
                .or(s.handles.as_ref())
                .map_or(at, |v| self.line(v.span()));
            let path = self.flat_path(
                &format!("{key}."),
                [
                    s.line.as_ref().map(|v| v.get_ref()),
                    s.arc.as_ref().map(|v| v.get_ref()),
                    s.flat_curve.as_ref().map(|v| v.get_ref()),
                ],
                at,
            )?;
            pieces.push(piece(
                &format!("{key}."),
                path,
                s.control_points.as_ref().map(|v| v.get_ref()),
                s.handles.as_ref().map(|v| v.get_ref()),
                s.length_fit.as_ref().map(|v| v.get_ref()),
                if flat_key.is_some() { cl } else { at },
            )?);
        }
        let name = self
            .string(&s.name, &format!("{key}.name"), NON_EMPTY)?
            .unwrap_or_else(|| format!("sheet{}", key.trim_start_matches("surface")));
        Ok(SurfaceSpec {
            kind: SurfaceKind::BentSheet,
            path: self.path.to_path_buf(),
            scale: 1.0,
            units: Units::Mm,
            name,
            line: line_no,
            strip: None,
            boundary: None,
            segment: SegmentSpec::default(),
            bent: Some(BentSpec {
                outline,
                holes,
                pieces,
                tolerance,
                bend_lines,
            }),
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Boundaries (issue 6): `kind = "boundary"` with `loop`, `loop_csv` or `loops`
// ---------------------------------------------------------------------------------------------

impl Ctx<'_> {
    /// One `kind = "boundary"` entry.
    fn boundary_surface(
        &self,
        s: &RawSurface,
        key: &str,
        header_line: usize,
        dir: &Path,
    ) -> Result<SurfaceSpec, SpecError> {
        use crate::surface::boundary::{self, BoundaryError, Dart, Input, Options};
        use toml::Value;
        let other = [
            ("path", s.path.as_ref().map(|v| v.span())),
            ("scale", s.scale.as_ref().map(|v| v.span())),
            ("units", s.units.as_ref().map(|v| v.span())),
            ("method", s.method.as_ref().map(|v| v.span())),
            ("bend_lines", s.bend_lines.as_ref().map(|v| v.span())),
            ("p", s.p.as_ref().map(|v| v.span())),
            ("q", s.q.as_ref().map(|v| v.span())),
        ];
        for (k, span) in other {
            if let Some(span) = span {
                return Err(self.invalid(
                    self.line(span),
                    &format!("{key}.{k}"),
                    "is not a boundary key; a boundary takes `loop`, `loop_csv` or `loops`"
                        .to_string(),
                ));
            }
        }
        let tolerance = self
            .number(
                &s.tolerance,
                &format!("{key}.tolerance"),
                MM_POSITIVE,
                |v| v > 0.0,
            )?
            .map_or(0.5, |(v, _)| v);
        let smooth = self
            .boolean(&s.smooth, &format!("{key}.smooth"))?
            .unwrap_or(false);
        let mut options = Options::default();
        if let Some((v, _)) = self.number(
            &s.max_dihedral,
            &format!("{key}.max_dihedral"),
            "an angle in degrees, more than 0 and at most 180",
            |v| v > 0.0 && v <= 180.0,
        )? {
            options.max_dihedral_deg = v;
        }
        if let Some((v, _)) = self.number(
            &s.min_chart_area,
            &format!("{key}.min_chart_area"),
            "a percentage of the hull's area, from 0 to less than 100",
            |v| (0.0..100.0).contains(&v),
        )? {
            options.min_chart_area = v / 100.0;
        }
        if let Some((v, _)) = self.number(
            &s.max_iterations,
            &format!("{key}.max_iterations"),
            "a whole number, 1 or more",
            |v| v >= 1.0 && v.fract() == 0.0 && v <= 1e9,
        )? {
            options.max_iterations = v as usize;
        }
        if let Some((v, _)) = self.number(
            &s.good_interior,
            &format!("{key}.good_interior"),
            "a whole number of interior triangles, 0 or more",
            |v| v >= 0.0 && v.fract() == 0.0 && v <= 1e9,
        )? {
            options.good_interior = v as usize;
        }
        if let Some((v, _)) = self.number(
            &s.good_fairness,
            &format!("{key}.good_fairness"),
            "a sum of squared angles in radians², 0 or more",
            |v| v >= 0.0,
        )? {
            options.good_fairness = v;
        }
        // Loops: exactly one of `loop`, `loop_csv`, `loops`.
        let mut raw_loops: Vec<(Value, String, usize)> = Vec::new();
        let given = [s.loop_.is_some(), s.loop_csv.is_some(), s.loops.is_some()];
        if given.iter().filter(|g| **g).count() != 1 {
            return Err(self.invalid(
                header_line,
                &format!("{key}.loop"),
                "a boundary needs exactly one of `loop` (points or a closed curve), `loop_csv` (a CSV file) or `loops` (a list of loops, the first the outer one)".to_string(),
            ));
        }
        if let Some(v) = &s.loop_ {
            raw_loops.push((
                v.get_ref().clone(),
                format!("{key}.loop"),
                self.line(v.span()),
            ));
        }
        if let Some(v) = &s.loop_csv {
            let k = format!("{key}.loop_csv");
            let path = self
                .string(
                    &s.loop_csv,
                    &k,
                    "a non-empty string naming a CSV file of x,y,z points",
                )?
                .unwrap_or_default();
            let mut t = toml::map::Map::new();
            t.insert("kind".into(), Value::String("csv".into()));
            t.insert("path".into(), Value::String(path));
            t.insert("closed".into(), Value::Boolean(true));
            raw_loops.push((Value::Table(t), k, self.line(v.span())));
        }
        if let Some(v) = &s.loops {
            let k = format!("{key}.loops");
            let line = self.line(v.span());
            match v.get_ref() {
                Value::Array(items) if !items.is_empty() => {
                    for (i, it) in items.iter().enumerate() {
                        raw_loops.push((it.clone(), format!("{k}[{}]", i + 1), line));
                    }
                }
                other => {
                    return Err(self.invalid(
                        line,
                        &k,
                        format!("must be a non-empty list of loops, got {other}"),
                    ))
                }
            }
        }
        let mut loops = Vec::new();
        for (v, k, line) in &raw_loops {
            loops.push(self.boundary_loop(v, k, *line, dir, tolerance, smooth)?);
        }
        // Darts and rulings.
        let mut darts = Vec::new();
        let mut darts_line = header_line;
        if let Some(v) = &s.darts {
            darts_line = self.line(v.span());
            let k = format!("{key}.darts");
            let Value::Array(items) = v.get_ref() else {
                return Err(self.invalid(
                    darts_line,
                    &k,
                    "must be a list of tables { at = N, points = [[x, y, z], ...] }".into(),
                ));
            };
            for (i, it) in items.iter().enumerate() {
                let dk = format!("{k}[{}]", i + 1);
                let bad = |m: &str| self.invalid(darts_line, &dk, m.to_string());
                let Value::Table(t) = it else {
                    return Err(bad("must be a table { at = N, points = [[x, y, z], ...] }"));
                };
                for name in t.keys() {
                    if !["at", "points", "width", "loop"].contains(&name.as_str()) {
                        return Err(self.invalid(
                            darts_line,
                            &format!("{dk}.{name}"),
                            "unknown key; expected one of at, points, width, loop".into(),
                        ));
                    }
                }
                let looop = match t.get("loop") {
                    None => 0,
                    Some(Value::Integer(n)) if *n >= 1 && (*n as usize) <= loops.len() => {
                        (*n - 1) as usize
                    }
                    Some(_) => {
                        return Err(bad(&format!(
                        "`loop` must be the number (from 1) of the loop the dart is on, at most {}",
                        loops.len()
                    )))
                    }
                };
                let at =
                    match t.get("at") {
                        Some(Value::Integer(n)) if *n >= 1 => (*n - 1) as usize,
                        _ => return Err(bad(
                            "`at` must be the number (from 1) of the loop point the dart starts at",
                        )),
                    };
                let points = match t.get("points") {
                    Some(Value::Array(p)) => self.points(p, &format!("{dk}.points"), darts_line)?,
                    _ => return Err(bad(
                        "`points` must be the dart's points [[x, y, z], ...], ending at its tip",
                    )),
                };
                let width = match t.get("width") {
                    None => None,
                    Some(Value::Integer(n)) if *n > 0 => Some(*n as f64),
                    Some(Value::Float(f)) if f.is_finite() && *f > 0.0 => Some(*f),
                    Some(_) => return Err(bad("`width` must be a positive number of millimetres")),
                };
                darts.push(Dart {
                    looop,
                    at,
                    points,
                    width,
                });
            }
        }
        let mut rulings = Vec::new();
        let mut rulings_line = header_line;
        if let Some(v) = &s.rulings {
            rulings_line = self.line(v.span());
            let k = format!("{key}.rulings");
            let msg =
                "must be a list of point-number pairs [[i, j], ...] (points of the first loop, from 1) or [[loop, i], [loop, j]] pairs (loops and points from 1)";
            let Value::Array(items) = v.get_ref() else {
                return Err(self.invalid(rulings_line, &k, msg.into()));
            };
            let num = |x: &Value| match x {
                Value::Integer(n) if *n >= 1 => Some((*n - 1) as usize),
                _ => None,
            };
            let end = |x: &Value| match x {
                Value::Integer(_) => num(x).map(|i| (0, i)),
                Value::Array(p) if p.len() == 2 => num(&p[0]).zip(num(&p[1])),
                _ => None,
            };
            for (i, it) in items.iter().enumerate() {
                match it {
                    Value::Array(a)
                        if a.len() == 2
                            && end(&a[0]).is_some()
                            && end(&a[1]).is_some()
                            && matches!(a[0], Value::Integer(_))
                                == matches!(a[1], Value::Integer(_)) =>
                    {
                        if let (Some(x), Some(y)) = (end(&a[0]), end(&a[1])) {
                            rulings.push([x, y]);
                        }
                    }
                    _ => {
                        return Err(self.invalid(
                            rulings_line,
                            &format!("{k}[{}]", i + 1),
                            msg.into(),
                        ))
                    }
                }
            }
        }
        if smooth && (!darts.is_empty() || !rulings.is_empty()) {
            return Err(self.invalid(
                header_line,
                &format!("{key}.smooth"),
                "darts and rulings name points of the loop, which smoothing resamples: use one or the other".into(),
            ));
        }
        let input = Input {
            loops,
            darts,
            rulings,
        };
        if let Err(e) = boundary::check(&input) {
            let at_loop = |l: usize| {
                raw_loops
                    .get(l)
                    .map_or((header_line, key.to_string()), |r| (r.2, r.1.clone()))
            };
            let (line, k) = match &e {
                BoundaryError::Ruling { .. } => (rulings_line, format!("{key}.rulings")),
                BoundaryError::Dart { .. } => (darts_line, format!("{key}.darts")),
                BoundaryError::TooFew { looop, .. }
                | BoundaryError::NonFinite { looop, .. }
                | BoundaryError::Repeated { looop, .. }
                | BoundaryError::Open { looop } => at_loop(*looop),
                BoundaryError::SelfIntersecting { la, .. } => at_loop(*la),
                BoundaryError::NoLoop
                | BoundaryError::Loops(_)
                | BoundaryError::NoTriangulation => (header_line, format!("{key}.loops")),
            };
            return Err(self.invalid(line, &k, e.to_string()));
        }
        let name = self
            .string(&s.name, &format!("{key}.name"), NON_EMPTY)?
            .unwrap_or_else(|| format!("boundary{}", key.trim_start_matches("surface")));
        Ok(SurfaceSpec {
            kind: SurfaceKind::Boundary,
            path: self.path.to_path_buf(),
            scale: 1.0,
            units: Units::Mm,
            name,
            line: raw_loops.first().map_or(header_line, |r| r.2),
            strip: None,
            bent: None,
            boundary: Some(BoundarySpec { input, options }),
            segment: SegmentSpec::default(),
        })
    }

    /// Boundary keys on another kind of surface are mistakes, not silently ignored.
    fn no_boundary_keys(&self, s: &RawSurface, key: &str) -> Result<(), SpecError> {
        self.refuse(
            key,
            &[
                ("loop", span(&s.loop_)),
                ("loop_csv", span(&s.loop_csv)),
                ("loops", span(&s.loops)),
                ("darts", span(&s.darts)),
                ("rulings", span(&s.rulings)),
                ("max_dihedral", span(&s.max_dihedral)),
                ("min_chart_area", span(&s.min_chart_area)),
                ("max_iterations", span(&s.max_iterations)),
                ("smooth", span(&s.smooth)),
                ("good_interior", span(&s.good_interior)),
                ("good_fairness", span(&s.good_fairness)),
            ],
            "is for boundary surfaces (kind = \"boundary\")",
        )
    }

    /// One boundary loop: an inline list of points (closed; a last point equal to the first is
    /// dropped) or a curve table that must be closed. Point lists and CSV files are taken as
    /// given (repeated points are errors, not dropped); other curves are sampled at `tol`;
    /// `smooth` resamples a closed cubic B-spline on the points (§7).
    fn boundary_loop(
        &self,
        v: &toml::Value,
        key: &str,
        line: usize,
        dir: &Path,
        tol: f64,
        smooth: bool,
    ) -> Result<Vec<glam::DVec3>, SpecError> {
        use crate::geom::curve::Curve;
        let c = match (v, self.curve(v, key, line, dir)?) {
            (toml::Value::Array(_), Curve::Points { points, .. }) => Curve::Points {
                points,
                closed: true,
            },
            (_, c) => c,
        };
        if !c.is_closed() {
            return Err(self.invalid(
                line,
                key,
                "is an open polyline: a boundary must be a closed loop (`closed = true`, or an inline list of points, which is closed)".into(),
            ));
        }
        let drop_closing = |mut p: Vec<glam::DVec3>| {
            if p.len() > 3 && p.first() == p.last() {
                p.pop();
            }
            p
        };
        let mut pts = match &c {
            Curve::Points { points, .. } => drop_closing(points.clone()),
            Curve::Csv { path, .. } => drop_closing(
                crate::geom::curve::read_csv(path)
                    .map_err(|e| self.invalid(line, key, e.to_string()))?,
            ),
            other => {
                other
                    .sample(tol)
                    .map_err(|e| self.invalid(line, key, e.to_string()))?
                    .points
            }
        };
        if smooth && pts.len() >= 4 {
            pts = Curve::BSpline {
                control: pts,
                degree: 3,
                closed: true,
            }
            .sample(tol)
            .map_err(|e| self.invalid(line, key, e.to_string()))?
            .points;
        }
        Ok(pts)
    }
}

/// Joins a multi-line message into one line.
fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

// ---------------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------------

#[cfg(test)]
mod tests {
    use super::*;

    const FULL: &str = r#"name = "cube"            # optional; default: the spec file's stem
device = "hpgl-pens"     # optional device profile name

[[surface]]              # one or more
kind = "mesh"
path = "cube.obj"
scale = 1.0
units = "mm"
name = "box"

[material]
kind = "paper"
thickness = 0.25

[sheet]
width = 210
height = 297
roll = false
margin = 5
spacing = 3

[pattern]
fold_threshold = 1.0
"#;

    const MINIMAL: &str = "[[surface]]\nkind = \"mesh\"\npath = \"lamp.obj\"\n";

    fn p(text: &str) -> Result<Spec, SpecError> {
        parse(text, Path::new("patterns/lamp.toml"))
    }

    /// Parses `text`, which must fail; returns (line, key or "", message, Display).
    fn fail(text: &str) -> (SpecError, String) {
        match p(text) {
            Ok(spec) => panic!("expected an error, got {spec:?}"),
            Err(e) => {
                let shown = e.to_string();
                (e, shown)
            }
        }
    }

    fn invalid(text: &str) -> (usize, String, String) {
        match fail(text) {
            (
                SpecError::Invalid {
                    line, key, message, ..
                },
                shown,
            ) => {
                assert_single_line(&shown);
                assert!(shown.starts_with("patterns/lamp.toml:"), "{shown}");
                (line, key, message)
            }
            (other, _) => panic!("expected Invalid, got {other:?}"),
        }
    }

    fn syntax(text: &str) -> (usize, String) {
        match fail(text) {
            (SpecError::Syntax { line, message, .. }, shown) => {
                assert_single_line(&shown);
                assert!(shown.starts_with("patterns/lamp.toml:"), "{shown}");
                (line, message)
            }
            (other, _) => panic!("expected Syntax, got {other:?}"),
        }
    }

    fn assert_single_line(s: &str) {
        assert!(!s.contains('\n') && !s.contains('\r'), "multi-line: {s:?}");
    }

    #[test]
    fn full_example_parses_exactly() {
        let spec = p(FULL).unwrap();
        assert_eq!(
            spec,
            Spec {
                name: "cube".into(),
                path: PathBuf::from("patterns/lamp.toml"),
                device: Some("hpgl-pens".into()),
                surfaces: vec![SurfaceSpec {
                    kind: SurfaceKind::Mesh,
                    path: PathBuf::from("patterns/cube.obj"),
                    scale: 1.0,
                    units: Units::Mm,
                    name: "box".into(),
                    line: 6,
                    strip: None,
                    bent: None,
                    boundary: None,
                    segment: SegmentSpec::default(),
                }],
                material: Material {
                    kind: MaterialKind::Paper,
                    thickness: 0.25
                },
                sheet: SheetSpec {
                    width: 210.0,
                    height: Some(297.0),
                    margin: 5.0,
                    spacing: 3.0
                },
                pattern: PatternSpec::default(),
            }
        );
        assert!(!spec.sheet.is_roll());
    }

    #[test]
    fn full_example_with_other_values() {
        let text = r#"
[[surface]]
kind = "MESH"
path = "a/b.obj"
scale = 2.5
units = "in"

[[surface]]
kind = "mesh"
path = "/abs/c.obj"
units = "cm"

[material]
kind = "metal"

[sheet]
width = 600.5
roll = true
margin = 0
spacing = 1.5

[pattern]
fold_threshold = 179.5
"#;
        let spec = p(text).unwrap();
        assert_eq!(spec.name, "lamp");
        assert_eq!(spec.device, None);
        assert_eq!(spec.surfaces.len(), 2);
        let a = &spec.surfaces[0];
        assert_eq!(a.path, PathBuf::from("patterns/a/b.obj"));
        assert_eq!(
            (a.scale, a.units, a.name.as_str(), a.line),
            (2.5, Units::In, "b", 4)
        );
        let c = &spec.surfaces[1];
        assert_eq!(c.path, PathBuf::from("/abs/c.obj"));
        assert_eq!(
            (c.scale, c.units, c.name.as_str(), c.line),
            (1.0, Units::Cm, "c", 10)
        );
        assert_eq!(
            spec.material,
            Material {
                kind: MaterialKind::Metal,
                thickness: 1.0
            }
        );
        assert_eq!(
            spec.sheet,
            SheetSpec {
                width: 600.5,
                height: None,
                margin: 0.0,
                spacing: 1.5
            }
        );
        assert!(spec.sheet.is_roll());
        assert_eq!(spec.pattern.fold_threshold_deg, 179.5);
    }

    #[test]
    fn minimal_spec_gets_all_defaults() {
        let spec = p(MINIMAL).unwrap();
        assert_eq!(spec.name, "lamp");
        assert_eq!(spec.path, PathBuf::from("patterns/lamp.toml"));
        assert_eq!(spec.device, None);
        assert_eq!(
            spec.surfaces,
            vec![SurfaceSpec {
                kind: SurfaceKind::Mesh,
                path: PathBuf::from("patterns/lamp.obj"),
                scale: 1.0,
                units: Units::Mm,
                name: "lamp".into(),
                line: 3,
                strip: None,
                bent: None,
                boundary: None,
                segment: SegmentSpec::default(),
            }]
        );
        assert_eq!(
            spec.material,
            Material {
                kind: MaterialKind::Paper,
                thickness: 0.25
            }
        );
        assert_eq!(
            spec.sheet,
            SheetSpec {
                width: 210.0,
                height: Some(297.0),
                margin: 5.0,
                spacing: 3.0
            }
        );
        assert_eq!(spec.pattern.fold_threshold_deg, 1.0);
        assert_eq!(spec.material, Material::default());
        assert_eq!(spec.sheet, SheetSpec::default());
        assert_eq!(spec.pattern, PatternSpec::default());
    }

    #[test]
    fn material_thickness_defaults_by_kind() {
        for (kind, t) in [("paper", 0.25), ("fabric", 0.5), ("metal", 1.0)] {
            let text = format!("{MINIMAL}[material]\nkind = \"{kind}\"\n");
            let spec = p(&text).unwrap();
            assert_eq!(spec.material.thickness, t, "{kind}");
            assert_eq!(spec.material.kind.to_string(), kind);
            assert_eq!(spec.material.kind.default_thickness(), t);
        }
        let spec = p(&format!(
            "{MINIMAL}[material]\nkind = \"fabric\"\nthickness = 2\n"
        ))
        .unwrap();
        assert_eq!(spec.material.thickness, 2.0);
    }

    #[test]
    fn relative_path_resolved_against_spec_dir() {
        let text = "[[surface]]\nkind = \"mesh\"\npath = \"../meshes/lamp shade.obj\"\n";
        let spec = parse(text, Path::new("/home/u/patterns/lamp.toml")).unwrap();
        assert_eq!(
            spec.surfaces[0].path,
            PathBuf::from("/home/u/patterns/../meshes/lamp shade.obj")
        );
        assert_eq!(spec.surfaces[0].name, "lamp shade");
        // A spec in the current directory leaves the path as written.
        let spec = parse(text, Path::new("lamp.toml")).unwrap();
        assert_eq!(
            spec.surfaces[0].path,
            PathBuf::from("../meshes/lamp shade.obj")
        );
    }

    #[test]
    fn units_conversions() {
        assert_eq!(Units::Mm.mm(), 1.0);
        assert_eq!(Units::Cm.mm(), 10.0);
        assert_eq!(Units::M.mm(), 1000.0);
        assert_eq!(Units::In.mm(), 25.4);
        for (name, u, mm) in [
            ("mm", Units::Mm, 1.0),
            ("cm", Units::Cm, 10.0),
            ("m", Units::M, 1000.0),
            ("in", Units::In, 25.4),
        ] {
            let spec = p(&format!("{MINIMAL}units = \"{name}\"\n")).unwrap();
            assert_eq!(spec.surfaces[0].units, u);
            assert_eq!(spec.surfaces[0].units.mm(), mm);
            assert_eq!(u.to_string(), name);
            assert_eq!(name.parse::<Units>(), Ok(u));
        }
        let (line, key, message) = invalid(&format!("{MINIMAL}units = \"ft\"\n"));
        assert_eq!((line, key.as_str()), (4, "surface[1].units"));
        assert_eq!(message, "must be one of mm, cm, m, in, got \"ft\"");
    }

    #[test]
    fn integer_and_float_numbers() {
        let ints = p(&format!(
            "{MINIMAL}scale = 2\n[sheet]\nwidth = 300\nheight = 400\nmargin = 0\nspacing = 4\n\
             [material]\nthickness = 1\n[pattern]\nfold_threshold = 5\n"
        ))
        .unwrap();
        let floats = p(&format!(
            "{MINIMAL}scale = 2.0\n[sheet]\nwidth = 300.0\nheight = 4e2\nmargin = 0.0\n\
             spacing = 4.0\n[material]\nthickness = 1.0\n[pattern]\nfold_threshold = 5.0\n"
        ))
        .unwrap();
        assert_eq!(ints, floats);
        assert_eq!(ints.surfaces[0].scale, 2.0);
        assert_eq!(
            ints.sheet,
            SheetSpec {
                width: 300.0,
                height: Some(400.0),
                margin: 0.0,
                spacing: 4.0
            }
        );
        assert_eq!(ints.material.thickness, 1.0);
        assert_eq!(ints.pattern.fold_threshold_deg, 5.0);
    }

    #[test]
    fn unknown_top_level_key() {
        let text = format!("name = \"x\"\n\ncolour = \"red\"\n{MINIMAL}");
        let (line, message) = syntax(&text);
        assert_eq!(line, 3);
        assert!(
            message.starts_with("unknown field `colour`, expected one of"),
            "{message}"
        );
        assert!(message.contains("`surface`"), "{message}");
        let shown = p(&text).unwrap_err().to_string();
        assert!(
            shown.starts_with("patterns/lamp.toml:3: unknown field `colour`"),
            "{shown}"
        );
    }

    #[test]
    fn unknown_key_in_sheet() {
        let (line, message) = syntax(&format!("{MINIMAL}[sheet]\nwidth = 200\nwidht = 300\n"));
        assert_eq!(line, 6);
        assert!(message.starts_with("unknown field `widht`"), "{message}");
        assert!(
            message.contains("`width`") && message.contains("`roll`"),
            "{message}"
        );
    }

    #[test]
    fn unknown_key_in_surface() {
        let text = format!("{MINIMAL}\n[[surface]]\nkind = \"mesh\"\npath = \"b.obj\"\nscal = 2\n");
        let (line, message) = syntax(&text);
        assert_eq!(line, 8);
        assert!(message.starts_with("unknown field `scal`"), "{message}");
        assert!(message.contains("`scale`"), "{message}");
    }

    #[test]
    fn negative_width_is_invalid() {
        let text = format!("{MINIMAL}[sheet]\nheight = 100\nwidth = -3\n");
        let (line, key, message) = invalid(&text);
        assert_eq!((line, key.as_str()), (6, "sheet.width"));
        assert_eq!(message, "must be a positive number of millimetres, got -3");
        assert_eq!(
            p(&text).unwrap_err().to_string(),
            "patterns/lamp.toml:6: `sheet.width`: must be a positive number of millimetres, got -3"
        );
    }

    #[test]
    fn wrong_types_name_the_key() {
        let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nwidth = \"wide\"\n"));
        assert_eq!((line, key.as_str()), (5, "sheet.width"));
        assert_eq!(
            message,
            "must be a positive number of millimetres, got \"wide\""
        );

        let (line, key, message) =
            invalid(&format!("{MINIMAL}[sheet]\nroll = \"yes\"\nheight = 5\n"));
        assert_eq!((line, key.as_str()), (5, "sheet.roll"));
        assert_eq!(message, "must be true or false, got \"yes\"");

        let (line, key, message) = invalid("surface = \"cube.obj\"\n");
        assert_eq!((line, key.as_str()), (1, "surface"));
        assert!(message.ends_with("got \"cube.obj\""), "{message}");

        let (line, key, message) = invalid(&format!("sheet = 5\n{MINIMAL}"));
        assert_eq!((line, key.as_str()), (1, "sheet"));
        assert_eq!(message, "must be a table ([sheet]), got 5");

        let (line, key, message) = invalid(&format!("{MINIMAL}scale = [1, 2]\n"));
        assert_eq!((line, key.as_str()), (4, "surface[1].scale"));
        assert_eq!(message, "must be a positive number, got an array");

        let (line, key, message) = invalid(&format!("name = 1979-05-27\n{MINIMAL}"));
        assert_eq!((line, key.as_str()), (1, "name"));
        assert_eq!(message, "must be a non-empty string, got a date-time");

        let (line, key, _) = invalid(&format!("name = \"\"\n{MINIMAL}"));
        assert_eq!((line, key.as_str()), (1, "name"));
    }

    #[test]
    fn roll_with_height_is_invalid() {
        let (line, key, message) =
            invalid(&format!("{MINIMAL}[sheet]\nroll = true\nheight = 500\n"));
        assert_eq!((line, key.as_str()), (6, "sheet.height"));
        assert!(message.contains("roll = true"), "{message}");
    }

    #[test]
    fn roll_gives_no_height() {
        let spec = p(&format!("{MINIMAL}[sheet]\nwidth = 610\nroll = true\n")).unwrap();
        assert_eq!(spec.sheet.height, None);
        assert_eq!(spec.sheet.width, 610.0);
        assert!(spec.sheet.is_roll());
        let spec = p(&format!("{MINIMAL}[sheet]\nroll = false\n")).unwrap();
        assert_eq!(spec.sheet.height, Some(297.0));
    }

    #[test]
    fn margin_must_leave_room() {
        let (line, key, message) =
            invalid(&format!("{MINIMAL}[sheet]\nwidth = 100\nmargin = 50\n"));
        assert_eq!((line, key.as_str()), (6, "sheet.margin"));
        assert_eq!(
            message,
            "must be less than half the sheet width (100 mm), got 50"
        );

        let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nheight = 8\n"));
        assert_eq!((line, key.as_str()), (5, "sheet.margin"));
        assert_eq!(
            message,
            "must be less than half the sheet height (8 mm), got 5 (the default)"
        );

        // A roll has no height to check against.
        let spec = p(&format!(
            "{MINIMAL}[sheet]\nwidth = 100\nmargin = 49.5\nroll = true\n"
        ))
        .unwrap();
        assert_eq!(spec.sheet.margin, 49.5);
    }

    #[test]
    fn other_range_checks() {
        let (line, key, message) = invalid(&format!("{MINIMAL}[pattern]\nfold_threshold = 180\n"));
        assert_eq!((line, key.as_str()), (5, "pattern.fold_threshold"));
        assert_eq!(
            message,
            "must be a number of degrees, at least 0 and less than 180, got 180"
        );

        let (line, key, _) = invalid(&format!("{MINIMAL}[sheet]\nspacing = -0.5\n"));
        assert_eq!((line, key.as_str()), (5, "sheet.spacing"));

        let (line, key, message) = invalid(&format!("{MINIMAL}[material]\nthickness = 0\n"));
        assert_eq!((line, key.as_str()), (5, "material.thickness"));
        assert_eq!(message, "must be a positive number of millimetres, got 0");

        let (line, key, message) = invalid(&format!("{MINIMAL}[sheet]\nwidth = inf\n"));
        assert_eq!((line, key.as_str()), (5, "sheet.width"));
        assert_eq!(
            message,
            "must be a positive number of millimetres, got inf (not a finite number)"
        );
    }

    #[test]
    fn bad_material_kind_lists_allowed() {
        let (line, key, message) = invalid(&format!("{MINIMAL}[material]\nkind = \"wood\"\n"));
        assert_eq!((line, key.as_str()), (5, "material.kind"));
        assert_eq!(message, "must be one of paper, fabric, metal, got \"wood\"");

        assert_eq!("Fabric".parse::<MaterialKind>(), Ok(MaterialKind::Fabric));
        assert_eq!(
            "wood".parse::<MaterialKind>(),
            Err("expected one of paper, fabric, metal, got \"wood\"".to_string())
        );
        assert_eq!(MaterialKind::Metal.to_string(), "metal");
    }

    #[test]
    fn bad_surface_kind_lists_allowed() {
        let (line, key, message) = invalid("[[surface]]\nkind = \"nurbs\"\npath = \"a.obj\"\n");
        assert_eq!((line, key.as_str()), (2, "surface[1].kind"));
        assert_eq!(
            message,
            "must be one of mesh, strip, bent-sheet, boundary, got \"nurbs\""
        );
    }

    #[test]
    fn missing_surface_keys() {
        let (line, key, message) = invalid(&format!("{MINIMAL}\n[[surface]]\nkind = \"mesh\"\n"));
        assert_eq!((line, key.as_str()), (5, "surface[2].path"));
        assert!(message.starts_with("missing"), "{message}");

        let (line, key, message) = invalid("\n[[surface]]\npath = \"a.obj\"\n");
        assert_eq!((line, key.as_str()), (2, "surface[1].kind"));
        assert!(message.contains("mesh"), "{message}");
    }

    #[test]
    fn no_surfaces_is_an_error() {
        let (line, key, message) = invalid("name = \"x\"\n[sheet]\nwidth = 200\n");
        assert_eq!((line, key.as_str()), (1, "surface"));
        assert!(message.contains("[[surface]]"), "{message}");

        let (line, key, message) = invalid("name = \"x\"\nsurface = []\n");
        assert_eq!((line, key.as_str()), (2, "surface"));
        assert!(message.ends_with("got an empty array"), "{message}");
    }

    #[test]
    fn malformed_toml_is_syntax_error() {
        let (line, message) = syntax(&format!("{MINIMAL}[sheet\nwidth = 1\n"));
        assert_eq!(line, 4);
        assert!(!message.is_empty());

        let (line, message) = syntax(&format!("{MINIMAL}scale = \n"));
        assert_eq!(line, 4);
        assert!(!message.is_empty());

        let (line, message) = syntax(&format!(
            "name = \"a\"\n{MINIMAL}name = \"b\"\nname = \"c\"\n"
        ));
        assert_eq!(line, 6);
        assert_eq!(message, "duplicate key `name`");
    }

    #[test]
    fn nan_is_invalid() {
        let (line, key, message) = invalid(&format!("{MINIMAL}scale = nan\n"));
        assert_eq!((line, key.as_str()), (4, "surface[1].scale"));
        assert_eq!(
            message,
            "must be a positive number, got nan (not a finite number)"
        );
    }

    #[test]
    fn missing_file_is_io() {
        let path = Path::new("/nonexistent/flatcut/spec-test/lamp.toml");
        match load(path) {
            Err(e @ SpecError::Io { .. }) => {
                let shown = e.to_string();
                assert!(
                    shown.starts_with(
                        "/nonexistent/flatcut/spec-test/lamp.toml: cannot read spec: "
                    ),
                    "{shown}"
                );
                assert_single_line(&shown);
            }
            other => panic!("expected Io, got {other:?}"),
        }
    }

    #[test]
    fn load_reads_toml_file() {
        let dir = std::env::temp_dir().join(format!("flatcut-spec-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("job.spec");
        std::fs::write(&file, MINIMAL).unwrap();
        let spec = load(&file);
        let _ = std::fs::remove_dir_all(&dir);
        let spec = spec.unwrap();
        assert_eq!(spec.name, "job");
        assert_eq!(spec.surfaces[0].path, dir.join("lamp.obj"));
    }

    #[test]
    fn obj_path_gives_mesh_defaults() {
        for name in ["models/Cube.obj", "models/Cube.OBJ"] {
            let path = Path::new(name);
            let spec = load(path).unwrap();
            assert_eq!(spec, Spec::from_mesh(path));
            assert_eq!(spec.name, "Cube");
            assert_eq!(spec.path, PathBuf::from(name));
            assert_eq!(spec.device, None);
            assert_eq!(
                spec.surfaces,
                vec![SurfaceSpec {
                    kind: SurfaceKind::Mesh,
                    path: PathBuf::from(name),
                    scale: 1.0,
                    units: Units::Mm,
                    name: "Cube".into(),
                    line: 0,
                    strip: None,
                    bent: None,
                    boundary: None,
                    segment: SegmentSpec::default(),
                }]
            );
            assert_eq!(
                spec.material,
                Material {
                    kind: MaterialKind::Paper,
                    thickness: 0.25
                }
            );
            assert_eq!(
                spec.sheet,
                SheetSpec {
                    width: 210.0,
                    height: Some(297.0),
                    margin: 5.0,
                    spacing: 3.0
                }
            );
            assert_eq!(spec.pattern.fold_threshold_deg, 1.0);
        }
    }

    #[test]
    fn error_display_is_one_line_with_path() {
        let cases = [
            format!("{MINIMAL}colour = 1\n"),
            format!("{MINIMAL}[sheet]\nwidth = -1\n"),
            "[[surface]]\nkind = \"mesh\"\npath = \"a\nb\"\n".to_string(),
            "x = [\n1,\n".to_string(),
            "a = \"\"\"\nmulti\nline\n".to_string(),
            String::new(),
        ];
        for text in cases {
            let shown = p(&text).unwrap_err().to_string();
            assert!(shown.starts_with("patterns/lamp.toml:"), "{shown}");
            assert_single_line(&shown);
        }
    }

    #[test]
    fn boundary_spec_parses_loops_darts_rulings_and_settings() {
        let spec = p(r#"
[[surface]]
kind = "boundary"
name = "panel"
loop = [[0, 0, 0], [100, 0, 0], [100, 80, 10], [50, 100, 5], [0, 80, 10], [0, 0, 0]]
darts = [{ at = 1, points = [[20, 30, 2]], width = 4 }]
rulings = [[2, 5]]
max_dihedral = 45
min_chart_area = 3
max_iterations = 200
good_interior = 2
good_fairness = 0.5
"#)
        .unwrap();
        let s = &spec.surfaces[0];
        assert_eq!(s.kind, SurfaceKind::Boundary);
        assert_eq!(s.name, "panel");
        assert_eq!(s.line, 5);
        let b = s.boundary.as_ref().unwrap();
        assert_eq!(b.input.loops.len(), 1);
        assert_eq!(
            b.input.loops[0].len(),
            5,
            "the repeated closing point is dropped"
        );
        assert_eq!(b.input.darts[0].at, 0);
        assert_eq!(b.input.darts[0].width, Some(4.0));
        assert_eq!(b.input.rulings, vec![[(0, 1), (0, 4)]]);
        assert_eq!(b.options.max_dihedral_deg, 45.0);
        assert!((b.options.min_chart_area - 0.03).abs() < 1e-15);
        assert_eq!(b.options.max_iterations, 200);
        assert_eq!(b.options.good_interior, 2);
        assert_eq!(b.options.good_fairness, 0.5);
        // A closed curve table is sampled; two loops.
        let spec = p(r#"
[[surface]]
kind = "boundary"
loops = [{ kind = "ellipse", center = [0, 0, 0], rx = 100, ry = 60 }, [[-10, -10, 0], [10, -10, 0], [0, 10, 0]]]
darts = [{ loop = 2, at = 3, points = [[0, 0, 0]] }]
rulings = [[[1, 1], [2, 1]]]
"#)
        .unwrap();
        let b = spec.surfaces[0].boundary.as_ref().unwrap();
        assert_eq!(b.input.loops.len(), 2);
        assert_eq!((b.input.darts[0].looop, b.input.darts[0].at), (1, 2));
        assert_eq!(b.input.rulings, vec![[(0, 0), (1, 0)]]);
        assert!(b.input.loops[0].len() > 8);
    }
}
