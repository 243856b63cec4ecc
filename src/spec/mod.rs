//! The job spec: a TOML file (`patterns/*.toml`) naming the surfaces to cut and the material,
//! sheet and pattern settings to cut them with.
//!
//! ```toml
//! name = "cube"            # optional; default: the spec file's stem
//! device = "hpgl-pens"     # optional device profile name
//! size = 200               # optional, mm > 0: the whole job's largest dimension (all
//!                          # surfaces together, aspect kept; `--size` wins)
//!
//! [[surface]]              # one or more
//! kind = "mesh"            # required: "mesh", "strip", "bent-sheet", "boundary" or "spline"
//! path = "cube.obj"        # required for mesh; relative to the spec file's directory
//! scale = 1.0              # optional, > 0, finite; default 1
//! units = "mm"             # optional: "mm" | "cm" | "m" | "in"; default "mm"
//! name = "box"             # optional; default: the mesh file stem
//! size = 150               # optional, mm > 0: the surface's largest dimension (any kind),
//!                          # aspect kept; replaces scale and units
//! segment = "dcharts"      # optional: "faces" | "dcharts" (smooth meshes, issue 7); see
//!                          # `spec::mesh` for this and `charts`, `f_max`, `approximate`,
//!                          # `simplify`
//!
//! [material]               # optional table
//! kind = "paper"           # "paper" | "fabric" | "metal"; default paper
//! thickness = 0.25         # mm, > 0, finite; default by kind: paper 0.25, fabric 0.5, metal 1.0
//! k_factor = 0.4           # metal meshes: K, the neutral surface's depth below the inside
//!                          # face over the thickness, 0 to 1; default 0.4
//! bend_radius = 2          # metal meshes: inside bend radius of the folds, mm >= 0;
//!                          # default: the thickness (see `pattern::develop`)
//!
//! [sheet]                  # optional table; without it a roll-fed device's roll is used
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
//! [`load`] reads a spec file; a mesh file (`.obj`, `.stl`, `.ply` or `.off`, any letter case)
//! given instead stands for a spec with that one mesh and every default ([`Spec::from_mesh`]).
//! Every other extension is read as TOML.
//!
//! # Layout
//!
//! The spec produces the stages' own option types ([`SurfaceSpec`] and the kinds' settings,
//! [`Material`] from `surface`; [`crate::pattern::PatternOptions`] through
//! [`Spec::pattern_options`]); no stage imports this module. This file holds the schema
//! ([`Spec`] and its tables), [`load`] and [`parse`] and the top-level tables' readers;
//! `spanned` the serde form in which every value keeps its span; `context` the `FILE:LINE`
//! and dotted-key messages ([`SpecError`]); `names` the names of the enums; `curves` the
//! curve and point readers several kinds share; `mesh`, `strip`, `bent` and `boundary` one
//! reader per surface kind.
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
//!
//! # Spline surfaces (issue 24)
//!
//! A `kind = "spline"` surface is a ruled surface between B-spline curves, made developable by
//! guided projection (see `surface::spline`, Tang et al. 2016): `curves` (two or more curves,
//! each an inline list of control points `[[x, y, z], ...]`, all of one count; or one curve
//! and `apex = [x, y, z]` for a cone), `degree` (2 to 5, default 3), `closed` (periodic
//! curves, default false; the surface is opened along its first ruling, a seam with a tab),
//! `creases` (one per interior curve of a chain of three or more: "fold" (the sheet folds
//! along it), "geodesic" (a geodesic of both sides: it unfolds to a straight line), "smooth"
//! (no crease) or "free" (no condition: the sides may not unfold in one piece); default all
//! "free"), `folds` (per interior curve "mountain", "valley", "none" or `{ kind, angle_deg }`:
//! which way a `fold` or `geodesic` crease folds, seen from the printed side, and the mean
//! angle along it; a direction alone folds it by at least 1°), `fixed` (control points the
//! solve keeps: curve numbers for whole curves,
//! `[curve, point]` counted from 1, or "apex"), `target` (a shape to approximate: a mesh file
//! or a CSV point cloud, as a path or `{ path, scale, units }`; without `curves` the start is
//! the target's principal rectangle), `handles` (`[{ at = [x, y, z], to = [x, y, z] }]`: the
//! surface's point nearest `at` dragged to `to`; `lift = H` instead of `to` raises it by H
//! only), `outline` (the flat sheet the surface stays isometric to: `[width, height]` from the
//! origin or a list of `[x, y]` points; the curves must start flat in it, z = 0), `iterations`
//! (rounds with the fairness energy, default 5), `max_iterations` (default 50, 150 with a
//! target), `epsilon1` (fairness weight, default 0.1), `epsilon2` (step damping, default
//! 0.01), `tolerance` (chordal tolerance of the output sampling, mm, default 0.05),
//! `bend_lines` (which rulings are scored, as strips; creases are folds whatever it says),
//! `side` and `k_factor` (metal: developed on the neutral surface, as strips) and `name`.
//! Unequal control-point counts, a wrong number of `creases` or `folds`, a "fold" or
//! "geodesic" crease on a straight curve, a stated fold on a crease that does not fold, a control point that does not exist, an unreadable target and
//! a curve off the outline are errors at the line of the key concerned; rulings that cross
//! inside the surface (a curve of regression) and a solve that breaks down name `curves`.

mod bent;
mod boundary;
mod context;
mod curves;
mod mesh;
mod names;
mod spanned;
mod spline;
mod strip;

// The stage types a spec is made of, defined by the stages that read them (mostly `surface`),
// re-exported here beside the schema that holds them.
pub use crate::surface::geodesic::BentSpec;
pub use crate::surface::{
    ApproximateSpec, BoundarySpec, Fixed, Material, MaterialKind, Segment, SegmentSpec, SheetSide,
    StripSpec, SurfaceKind, SurfaceSpec, Units,
};
pub use context::SpecError;

use crate::pattern::PatternOptions;
use context::{Ctx, Opt, MM_NON_NEGATIVE, MM_POSITIVE};
use names::one_of;
use spanned::{fmt_num, List, RawMaterial, RawPattern, RawSheet, RawSpec, RawSurface, Tab};
use std::path::{Path, PathBuf};
use toml::Spanned;

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
    /// The size (mm) of the whole job's largest dimension, all surfaces together, aspect kept
    /// (top-level `size`, `--size`); `None`: the surfaces as their own settings make them.
    pub size: Option<f64>,
    /// Whether the spec file has a `[sheet]` table; without one a device profile's media
    /// (a roll cutter's roll) is the sheet.
    pub sheet_given: bool,
    pub material: Material,
    pub sheet: SheetSpec,
    pub pattern: PatternSpec,
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
    /// Split pieces too large for the sheet (`--split`; `None`: auto).
    pub split: Option<crate::pattern::split::Split>,
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
            split: None,
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
    /// Which rulings every strip, bent sheet and spline surface scores (`--bend-lines`, over
    /// their own `bend_lines`).
    pub fn set_bend_lines(&mut self, lines: crate::surface::strip::BendLines) {
        for s in &mut self.surfaces {
            if let Some(st) = &mut s.strip {
                st.bend_lines = lines;
            }
            if let Some(b) = &mut s.bent {
                b.bend_lines = lines;
            }
            if let Some(sp) = &mut s.spline {
                sp.bend_lines = lines;
            }
        }
    }

    /// A spec for a single mesh file with every default: paper, A4 portrait, 5 mm margin,
    /// 3 mm spacing, scale 1 in millimetres, named after the file's stem.
    pub fn from_mesh(path: &Path) -> Spec {
        let name = stem_or(path, "mesh");
        Spec {
            name: name.clone(),
            path: path.to_path_buf(),
            device: None,
            size: None,
            sheet_given: false,
            surfaces: vec![SurfaceSpec {
                kind: SurfaceKind::Mesh,
                path: path.to_path_buf(),
                scale: 1.0,
                units: Units::Mm,
                size: None,
                name,
                line: 0,
                strip: None,
                bent: None,
                boundary: None,
                spline: None,
                segment: SegmentSpec::default(),
            }],
            material: Material::default(),
            sheet: SheetSpec::default(),
            pattern: PatternSpec::default(),
        }
    }

    /// The pattern stage's options: the material's defaults with the spec's `[pattern]`
    /// settings on top, each mesh surface's `simplify` and, in metal, the mesh surfaces to
    /// develop with the material's bend settings.
    pub fn pattern_options(&self) -> PatternOptions {
        let spec = self;
        let p = &spec.pattern;
        let mut o = PatternOptions::for_material(spec.material.kind);
        o.fold_threshold_deg = p.fold_threshold_deg;
        if let Some(t) = p.tabs {
            o.tabs = t;
        }
        if let Some(h) = p.tab_height {
            o.tab_height = h;
        }
        if let Some(a) = p.allowance {
            o.allowance = a;
        }
        if let Some(n) = p.notches {
            o.notches = (n > 0.0).then_some(n);
        }
        if let Some(k) = p.kerf {
            o.kerf = k;
        }
        if let Some(b) = p.bend_notches {
            o.bend_notches = b;
        }
        o.simplify_surfaces = spec
            .surfaces
            .iter()
            .filter_map(|s| s.segment.simplify.map(|t| (s.name.clone(), t)))
            .collect();
        // Metal meshes are developed as a brake bends them (`pattern::develop`); strips and
        // splines are developed on their neutral surface already.
        if spec.material.kind == MaterialKind::Metal {
            o.develop = spec
                .surfaces
                .iter()
                .filter(|s| s.kind == SurfaceKind::Mesh)
                .map(|s| (s.name.clone(), spec.material.sheet_bend()))
                .collect();
        }
        o
    }
}

/// Reads a spec file. A mesh file (`.obj`, `.stl`, `.ply`, `.off`, any case) gives
/// [`Spec::from_mesh`]; anything else is read as TOML.
pub fn load(path: &Path) -> Result<Spec, SpecError> {
    if crate::surface::import::is_mesh_path(path) {
        return Ok(Spec::from_mesh(path));
    }
    let text =
        crate::geom::input::read_text(path, crate::geom::input::TEXT_LIMIT).map_err(|source| {
            SpecError::Io {
                path: path.to_path_buf(),
                source,
            }
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

impl Ctx<'_> {
    fn build(&self, raw: RawSpec) -> Result<Spec, SpecError> {
        let name = self
            .file_name(&raw.name, "name")?
            .unwrap_or_else(|| stem_or(self.path, "pattern"));
        let device = self.string(&raw.device, "device", "a non-empty device profile name")?;

        let surfaces = self.surfaces(&raw.surface)?;
        let size = self
            .number(&raw.size, "size", MM_POSITIVE, |v| v > 0.0)?
            .map(|(v, _)| v);
        let material = self.material(&raw.material)?;
        let sheet = self.sheet(&raw.sheet)?;
        let pattern = self.pattern(&raw.pattern)?;

        Ok(Spec {
            name,
            path: self.path.to_path_buf(),
            device,
            surfaces,
            size,
            sheet_given: raw.sheet.is_some(),
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
                            one_of(&["mesh", "strip", "bent-sheet", "boundary", "spline"])
                        ),
                    )
                })?;
            if !matches!(kind, SurfaceKind::BentSheet | SurfaceKind::Spline) {
                self.no_bent_keys(s, &key, &[])?;
            }
            if !matches!(kind, SurfaceKind::Boundary | SurfaceKind::Spline) {
                self.no_boundary_keys(s, &key, &[])?;
            }
            if kind != SurfaceKind::Spline {
                self.no_spline_keys(s, &key)?;
            }
            let mut surface = match kind {
                SurfaceKind::BentSheet => self.bent_surface(s, &key, header_line, dir)?,
                SurfaceKind::Strip => self.strip_surface(s, &key, header_line, dir)?,
                SurfaceKind::Boundary => self.boundary_surface(s, &key, header_line, dir)?,
                SurfaceKind::Mesh => self.mesh_surface(s, &key, header_line, dir)?,
                SurfaceKind::Spline => self.spline_surface(s, &key, header_line, dir)?,
            };
            surface.size = self
                .number(&s.size, &format!("{key}.size"), MM_POSITIVE, |v| v > 0.0)?
                .map(|(v, _)| v);
            out.push(surface);
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
        let stated = self.number(&m.thickness, "material.thickness", MM_POSITIVE, |v| v > 0.0)?;
        let thickness = stated.map_or(kind.default_thickness(), |(v, _)| v);
        let k_factor = self
            .number(
                &m.k_factor,
                "material.k_factor",
                "a number from 0 to 1",
                |v| (0.0..=1.0).contains(&v),
            )?
            .map_or(Material::DEFAULT_K_FACTOR, |(v, _)| v);
        let bend_radius = self
            .number(
                &m.bend_radius,
                "material.bend_radius",
                MM_NON_NEGATIVE,
                |v| v >= 0.0,
            )?
            .map(|(v, _)| v);
        Ok(Material {
            kind,
            thickness,
            k_factor,
            bend_radius,
            thickness_given: stated.is_some(),
        })
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
            split: None,
        })
    }
}

#[cfg(test)]
mod tests;
