//! Bent sheets: a flat sheet bent so that a line or curve drawn on it follows a 3D
//! control curve — the geodesic-controlled developables of Bo & Wang 2007 (seed 004), with
//! their extension to non-geodesic control curves (§5).
//!
//! The sheet is given flat (an outline, holes allowed) with one curve on it per curved piece —
//! a straight line, or a planar curve ([`FlatPath`]: a circular arc or a Bézier / B-spline) —
//! and for each a 3D control curve (Bézier or B-spline control points, or two handles: end
//! points with surface normals). For a line the surface is the rectifying developable of the
//! control curve, `X(s, t) = p(s) + t·r(s)` with `r` along the Darboux vector `τT + κB`
//! (eq. 1, §3.1), mapped onto the flat outline by the isometry of §3.3 (steps 1–4: arc length
//! along the line, ruling angle kept, rulings cut by the outline, distances measured along the
//! ruling).
//!
//! For a curve on the sheet (§5, "non-geodesic control curves") the flat curve's signed
//! curvature `c(s)` is the geodesic curvature the control curve keeps on the bent sheet: with
//! the surface normal `n ⟂ T` and `b = n × T`, `p'' = κN = c·b + κ_n·n`, so
//! `n = σ(κ_n/κ) N + (c/κ) B` with `κ_n = √(κ² − c²)` (writing `n = cos θ N + sin θ B`,
//! `sin θ = c/κ`). The developable is the envelope of the tangent planes along `p`: its rulings
//! follow the tangent-plane part of the Darboux vector of the frame `(T, b, n)`,
//! `τ_g T − κ_n b`, with the geodesic torsion `τ_g = τ + θ'` (for `c = 0` this is eq. 1). The
//! part `c·n` of the Darboux vector turns the curve inside the sheet, which the flat curve does
//! by itself. The sign of `c` (the flat curve turning left, seen from the printed side, is
//! `c > 0`) fixes which side of the control curve the sheet's printed side faces.
//!
//! # Files
//!
//! - `path`: the curve on the flat sheet ([`FlatPath`]: line, arc, spline) by arc length.
//! - `spline`: control curves with three derivatives ([`Param`], [`Spline`]) and arc length
//!   ([`ArcLength`], §4.1.3).
//! - `control`: a piece's control curve from the spec, and control handles (§4.1.2, eq. 7).
//! - `folds`: the folds of one piece: rulings from the Darboux vector (eq. 1, §5).
//! - `sheet`: the flat outline and holes, the curves on it, where rulings cross it (§3.3).
//! - `admissible`: the curve of regression and crossing rulings (§3.2, eq. 2–6, §4.3).
//! - `mesh`: the sheet cut along the rulings, each region moved rigidly (§3.3, §3.4, §4.2).
//! - `bends`: which rulings become bend lines, with their signed angles.

mod admissible;
mod bends;
mod control;
mod folds;
mod mesh;
mod path;
mod sheet;
mod spline;

pub use control::handles_curve;
pub use folds::Ruling;
pub use path::FlatPath;
pub use spline::{ArcLength, Param, Spline};

use crate::geom::curve::Curve;
use crate::geom::mesh::Mesh;
use crate::surface::strip::BendLines;
use crate::surface::Bend;
use admissible::check_rulings;
use bends::pick_bends;
use control::control_param;
use folds::{fold_pieces, Folds};
use glam::{DVec2, DVec3};
use mesh::{compact, fold_triangles, forward_left_of, place_faces, subdivide};
use path::Flat;
use sheet::{check_paths, cut_holes, ruling_chains, sheet_rings};

/// A bent sheet as the spec describes it (`kind = "bent-sheet"`).
#[derive(Debug, Clone, PartialEq)]
pub struct BentSpec {
    /// Outer outline of the flat sheet (mm), either orientation.
    pub outline: Vec<DVec2>,
    /// Holes in the sheet.
    pub holes: Vec<Vec<DVec2>>,
    /// The curved pieces: one straight line on the sheet and its control curve each.
    pub pieces: Vec<PieceSpec>,
    /// Sampling tolerance (mm): sagitta of one fold step.
    pub tolerance: f64,
    pub bend_lines: BendLines,
}

/// One curved piece: the curve on the flat sheet (a straight line, or a planar curve whose
/// geodesic curvature is kept, §5) and the 3D curve it must follow.
#[derive(Debug, Clone, PartialEq)]
pub struct PieceSpec {
    /// The curve on the flat sheet (mm), from its start to its end.
    pub path: FlatPath,
    pub control: Control,
    pub fit: LengthFit,
}

/// How the 3D curve is given.
#[derive(Debug, Clone, PartialEq)]
pub enum Control {
    /// A Bézier or (open) B-spline curve (`geom::curve`).
    Curve(Curve),
    /// Two control handles (§4.1.2): end points and the surface normals there.
    Handles {
        start: DVec3,
        start_normal: DVec3,
        end: DVec3,
        end_normal: DVec3,
    },
}

/// How the control curve is brought to the length of the flat line (§4.1.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthFit {
    /// Scale about the curve's first point.
    #[default]
    Scale,
    /// Cut at the line's length from the start.
    Trim,
}

impl LengthFit {
    pub const NAMES: [(&'static str, LengthFit); 2] =
        [("scale", LengthFit::Scale), ("trim", LengthFit::Trim)];
}

/// What can be wrong with a bent sheet. Positions are on the flat sheet, in mm; pieces are
/// 0-based here and counted from 1 in the messages.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeodesicError {
    #[error("outline: {0}")]
    Outline(String),
    #[error("piece {}: line: {message}", .piece + 1)]
    Line { piece: usize, message: String },
    #[error("piece {}: control curve: {message}", .piece + 1)]
    Control { piece: usize, message: String },
    #[error("piece {}: the curve of regression enters the sheet at s = {s:.2} mm along the line (ruling through ({x:.2}, {y:.2})): the singular point lies {dist:.2} mm from the line along the ruling, {depth:.2} mm inside the sheet's edge; bend or twist the control curve less there", .piece + 1)]
    Regression {
        piece: usize,
        s: f64,
        x: f64,
        y: f64,
        dist: f64,
        depth: f64,
    },
    #[error("the ruling of piece {} at s = {sa:.2} mm and the ruling of piece {} at s = {sb:.2} mm cross on the sheet at ({x:.2}, {y:.2}); move the lines apart or bend less", .a + 1, .b + 1)]
    Crossing {
        a: usize,
        sa: f64,
        b: usize,
        sb: f64,
        x: f64,
        y: f64,
    },
    #[error("piece {}: the control curve bends less than the curve drawn on the sheet at s = {s:.2} mm along it: its curvature is {kappa:.6}/mm, the flat curve's {c:.6}/mm (radius {radius:.2} mm), short by {short:.6}/mm; a curve keeps its geodesic curvature when the sheet bends, so in space it must curve at least as much (§5): bend the control curve more there or draw a straighter curve on the sheet", .piece + 1)]
    Curvature {
        piece: usize,
        s: f64,
        kappa: f64,
        c: f64,
        radius: f64,
        short: f64,
    },
    #[error("{0}")]
    Mesh(String),
}

/// The result: the bent sheet as a mesh with its flat layout and rulings.
#[derive(Debug, Clone, PartialEq)]
pub struct Bent {
    /// Triangles in mm, counter-clockwise seen from the printed side.
    pub mesh: Mesh,
    /// Flat position of each mesh vertex on the sheet.
    pub flat: Vec<DVec2>,
    /// Rulings (fold lines), piece by piece in order along their lines, then hole cut lines.
    pub rulings: Vec<Ruling>,
    /// Bend lines picked by `bend_lines`.
    pub bends: Vec<Bend>,
    /// Per piece: the fitted control curve's length (mm) and the folded line's largest distance
    /// from it (mm).
    pub lengths: Vec<f64>,
    pub drifts: Vec<f64>,
    pub warnings: Vec<String>,
}

/// Bend the sheet (see the module doc).
pub fn bend(spec: &BentSpec) -> Result<Bent, GeodesicError> {
    let mut params = Vec::new();
    let mut warnings = Vec::new();
    for (i, p) in spec.pieces.iter().enumerate() {
        let (c, up, w) = control_param(i, p)?;
        warnings.extend(w);
        params.push((c, up));
    }
    let refs: Vec<(&dyn Param, Option<DVec3>)> =
        params.iter().map(|(c, up)| (c.as_ref(), *up)).collect();
    let mut out = bend_with(spec, &refs)?;
    warnings.append(&mut out.warnings);
    out.warnings = warnings;
    Ok(out)
}

/// [`bend`] with the control curves given as parametric curves (one per piece, in order), with
/// an optional hint for the surface normal's side at the start.
pub fn bend_with(
    spec: &BentSpec,
    curves: &[(&dyn Param, Option<DVec3>)],
) -> Result<Bent, GeodesicError> {
    let tol = spec.tolerance;
    if !(tol.is_finite() && tol > 0.0) {
        return Err(GeodesicError::Mesh(format!(
            "tolerance must be a positive number of mm, got {tol}"
        )));
    }
    let rings = sheet_rings(spec)?;
    if spec.pieces.is_empty() || curves.len() != spec.pieces.len() {
        return Err(GeodesicError::Mesh(
            "a bent sheet needs at least one line with its control curve".into(),
        ));
    }
    check_paths(spec, &rings)?;
    let flats: Vec<Flat> = spec.pieces.iter().map(|p| Flat::new(&p.path)).collect();
    let Folds {
        mut rulings,
        place,
        warnings,
        lengths,
        drifts,
    } = fold_pieces(spec, curves, &flats, tol)?;
    let mut chains = ruling_chains(&rings, &mut rulings);
    check_rulings(&rulings, spec.pieces.len())?;
    cut_holes(&rings, &mut rulings, &mut chains)?;
    let sub = subdivide(&rings, &chains, &mut rulings)?;
    let forward_left = forward_left_of(&rulings, &flats);
    let xf = place_faces(&sub, &rulings, &flats, &forward_left, place);
    let (vert3, triangles) = fold_triangles(&sub, &xf)?;
    let (mesh, flat) = compact(&sub.pos, &vert3, &triangles, &mut rulings);
    let bends = pick_bends(&rulings, &forward_left, spec.bend_lines);
    Ok(Bent {
        mesh,
        flat,
        rulings,
        bends,
        lengths,
        drifts,
        warnings,
    })
}
