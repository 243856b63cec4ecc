//! Spline developables (Tang, Bo, Wallner, Pottmann 2016, *Interactive design of developable
//! surfaces*, §2 and §3.2; issue 24): the ruled surface s(u, v) = (1 − v) a(u) + v b(u)
//! between B-spline curves of one degree and control-point count (or a cone: one curve and an
//! apex), made developable by guided projection ([`solve`]; its rows and sparse solve in
//! `system`), then sampled into a triangle mesh whose rulings are exact edges, for the exact
//! unfolder. Besides developability and creases the solve can approximate a target (§4.2,
//! [`target`]), keep the surface isometric to a flat outline (§5, eq. 12, `develop`) and drag
//! points by handles.
//!
//! Several curves make a chain of strips, curve k to curve k + 1, each with its own normals;
//! each shared (interior) curve is a crease with a condition (§3.3): `fold` (eq. 7), `geodesic`
//! (eq. 8), `smooth` (equal normals) or `free` (none). The normals of every strip are oriented
//! as e × a′ with e the ruling from curve k to curve k + 1, so both sides of a crease have
//! their normals on one side of the sheet (the paper leaves this unstated; with it, a flat
//! sheet satisfies eq. 7 and a fold by reflection in a plane satisfies eq. 7 but not eq. 8).
//! The mesh keeps the strips joined along their creases, whose edges are fold lines with
//! their dihedral angles whatever `bend_lines` says (it picks among the rulings only).
//!
//! Choices where the paper is silent:
//!
//! - A run of equal control points stays one point (one unknown in the solve): the curve
//!   stands still there. A strip whose one curve stands still is a cone with its apex on that
//!   curve (a fan from a corner of the sheet); where both stand still the strip pauses on one
//!   ruling. The sampled mesh has one vertex for such a run and leaves out the triangles it
//!   would flatten, and the apex may be where the rulings meet (not a striction).
//! - `folds` states which way a crease folds (mountain or valley seen from the printed side,
//!   the side the mesh's faces face) and optionally its mean angle; see [`solve`].
//! - Output sampling: each span is cut into N equal parameter steps with N the smallest that
//!   keeps the chordal error `max|a″| h²/8` (of both curves) within `tolerance`, at least 2
//!   and at most 512 per span. Each quad a_i a_i+1 b_i+1 b_i becomes the triangles
//!   (a_i, a_i+1, b_i+1) and (a_i, b_i+1, b_i), so that rulings a_i b_i are edges; a cone's
//!   triangles share one apex vertex. A closed surface is welded around and its ruling at
//!   u = 0 is a cut ([`Solved::seam`], the surface's `cuts`): the unfolder opens it there and
//!   the pattern stage sees a seam (glue tab, matched marks) instead of two loose ends.
//! - A striction point (where rulings cross, the curve of regression) at a parameter v in
//!   [0, 1] of a sampled ruling is refused, naming u (0-based span parameter) and v; a cone's
//!   apex (v = 1) and the end of a ruling on a curve that stands still are allowed.
//! - Figures (report.json): `iterations`, `largest_sine` (the intrinsic developability sine at
//!   64 parameters per span after the solve), `solver_sine` (at the solver's samples),
//!   `flatness_delta` (Fig. 17's δ: distance of the diagonals of each sampled quad over the
//!   mean of its two ruling-free edges, largest), `isometry_error` (largest relative
//!   difference between a quad's second diagonal in 3D and in its two triangles unfolded),
//!   `control_points_moved_mm`, `crease_sine` (the largest intrinsic crease sine at 64
//!   parameters per span, [`solve::crease_sine`]) and `crease_angle_defect` (Fig. 17's crease
//!   flatness |K|: the largest |angle sum − 2π| at the sampled mesh's vertices on creases);
//!   with creases `fold_angle_mean_deg` (weighted by length) and `fold_angle_max_deg` of the
//!   sampled crease edges; with a target `approximation_rms_mm`, `approximation_max_mm`,
//!   `coverage` (the share of
//!   target points within [`COVERAGE_MM`]) and `target_points`; with handles
//!   `handle_distance_mm`; with an outline `outline_isometry_error` (eq. 12's largest relative
//!   length error). Seconds per iteration are not written there (the report must be
//!   byte-identical between runs); `benches/spline.rs` measures them.
//! - A final sine above 1e-6 is a warning.

mod develop;
pub mod solve;
mod system;
pub mod target;

use super::strip::BendLines;
use super::Bend;
use crate::geom::bspline::BSpline;
use crate::geom::mesh::{Face, Mesh};
use glam::DVec3;
pub use solve::{Crease, FoldGoal, Model, Report, SolveError, SolveOptions};

/// A spline surface as the spec describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct SplineSpec {
    /// Control points of each curve, all of one count.
    pub curves: Vec<Vec<DVec3>>,
    /// A cone's apex (with exactly one curve).
    pub apex: Option<DVec3>,
    pub degree: usize,
    pub closed: bool,
    /// Fixed control points (curve, index), 0-based; curve `curves.len()` is the apex.
    pub fixed: Vec<(usize, usize)>,
    /// The condition on each interior curve (entry k for curve k + 1); empty: all `free`.
    pub creases: Vec<Crease>,
    /// The stated fold of each interior curve (entry k for curve k + 1); empty: none.
    pub folds: Vec<Option<FoldGoal>>,
    /// A shape to approximate (eq. 9–11); without `curves` the start is its principal
    /// rectangle.
    pub target: Option<target::Target>,
    /// Handles (at, to): a point of the surface as given dragged towards a 3D position (mm).
    pub handles: Vec<(DVec3, DVec3)>,
    /// A flat domain the surface stays isometric to (eq. 12), in the plane z = 0 where the
    /// curves start.
    pub outline: Option<Vec<glam::DVec2>>,
    pub options: SolveOptions,
    /// Which surface of a metal sheet the curves describe and the K factor (`side`,
    /// `k_factor`), from which [`crate::surface::SurfaceSpec::for_material`] sets
    /// `neutral_offset`.
    pub sheet: (super::SheetSide, f64),
    /// How far (mm) the developed (neutral) surface lies inside the designed one, against the
    /// mesh's face normals; 0 develops the design as it is.
    pub neutral_offset: f64,
    /// Chordal tolerance of the output sampling (mm).
    pub tolerance: f64,
    pub bend_lines: BendLines,
}

/// A solved design as the output keeps it (`--spline-json`): the model and where its curves
/// are in the sampled mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    pub model: Model,
    /// The output parameters (the sampled rulings), over `[0, spans]`.
    pub params: Vec<f64>,
    /// For each curve (then the apex, for a cone), its mesh vertices at `params` (the apex:
    /// one vertex).
    pub curve_verts: Vec<Vec<usize>>,
}

/// The solved surface, sampled.
#[derive(Debug, Clone, PartialEq)]
pub struct Solved {
    pub model: Model,
    /// The output parameters and each curve's vertices in `mesh`.
    pub params: Vec<f64>,
    pub curve_verts: Vec<Vec<usize>>,
    /// A closed surface's seam: the rulings at u = 0 (their two vertices, smaller first),
    /// where the mesh, welded around, is cut open.
    pub seam: Vec<[usize; 2]>,
    pub report: Report,
    pub mesh: Mesh,
    pub bends: Vec<Bend>,
    pub figures: Vec<(&'static str, f64)>,
    pub warnings: Vec<String>,
}

/// What can go wrong making a spline surface.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SplineError {
    /// A shape the spec cannot have; `key` is the spec key concerned, relative to the surface
    /// (`curves[2]`, `creases[1]`, `degree`, `apex`).
    #[error("`{key}`: {message}")]
    Shape { key: String, message: String },
    #[error(transparent)]
    Solve(#[from] SolveError),
    #[error("the rulings cross inside the strip (a striction point, the curve of regression) at u = {u:.4}, v = {v:.4} of strip {strip}: the sheet would fold over itself there; move the curves apart or reduce the twist")]
    Striction { u: f64, v: f64, strip: usize },
}

impl SplineError {
    /// "`KEY`: " for errors about the design as a whole (they concern `curves`), nothing for
    /// shape errors, whose message names their key.
    pub fn key_prefix(&self) -> &'static str {
        match self {
            SplineError::Shape { .. } => "",
            _ => "`curves`: ",
        }
    }
}

/// Check the spec's shapes and build the model.
pub fn model(spec: &SplineSpec) -> Result<Model, SplineError> {
    let shape = |key: String, message: String| SplineError::Shape { key, message };
    let started;
    let spec = match (&spec.target, spec.curves.is_empty()) {
        (Some(t), true) => {
            if spec.closed {
                return Err(shape(
                    "closed".into(),
                    "a start from the target's principal rectangle is open; give `curves` for a closed surface".into(),
                ));
            }
            let curves = t.principal_rectangle(RECTANGLE_POINTS).ok_or_else(|| {
                shape(
                    "target".into(),
                    "has no extent in two directions: no rectangle to start from; give `curves`"
                        .into(),
                )
            })?;
            started = SplineSpec {
                curves,
                ..spec.clone()
            };
            &started
        }
        _ => spec,
    };
    let count = spec.curves.first().map_or(0, Vec::len);
    if !(2..=5).contains(&spec.degree) {
        return Err(shape(
            "degree".into(),
            format!("must be 2, 3, 4 or 5, got {}", spec.degree),
        ));
    }
    let basis = BSpline::new(spec.degree, count, spec.closed)
        .map_err(|e| shape("curves[1]".into(), e.to_string()))?;
    if let Some(k) = spec.curves.iter().position(|c| c.len() != count) {
        return Err(shape(
            format!("curves[{}]", k + 1),
            format!(
                "has {} control points, curve 1 has {count}: all curves need the same count",
                spec.curves[k].len()
            ),
        ));
    }
    match (spec.apex, spec.curves.len()) {
        (Some(_), 1) | (None, 2..) => {}
        (Some(_), n) => {
            return Err(shape(
                "apex".into(),
                format!("a cone takes one curve and `apex`, got {n} curves"),
            ))
        }
        (None, n) => {
            return Err(shape(
                "curves".into(),
                format!("a spline surface needs two or more curves (or one and `apex`), got {n}"),
            ))
        }
    }
    let interior = spec.curves.len().saturating_sub(2);
    per_interior("creases", spec.creases.len(), interior)?;
    check_folds(spec, interior)?;
    let total = count.saturating_mul(spec.curves.len() + 1);
    if total > MAX_CONTROL_POINTS {
        return Err(shape(
            "curves".into(),
            format!("{total} control points in all is over {MAX_CONTROL_POINTS}: a design of that size is not interactive; split it into several surfaces"),
        ));
    }
    if let Some(&(c, i)) = spec.fixed.iter().find(|&&(c, i)| {
        !(c < spec.curves.len() && i < count
            || c == spec.curves.len() && i == 0 && spec.apex.is_some())
    }) {
        return Err(shape(
            "fixed".into(),
            format!(
                "control point {} of curve {} does not exist ({} curves of {count} points)",
                i + 1,
                c + 1,
                spec.curves.len()
            ),
        ));
    }
    let m = Model {
        basis,
        curves: spec.curves.clone(),
        apex: spec.apex,
        fixed: spec.fixed.clone(),
        creases: spec.creases.clone(),
        folds: spec.folds.clone(),
        target: spec.target.clone(),
        handles: spec.handles.clone(),
        outline: spec.outline.clone(),
    };
    let straight = solve::STRAIGHT / diameter(&m);
    for (k, &kind) in spec.creases.iter().enumerate() {
        if !matches!(kind, Crease::Fold | Crease::Geodesic) {
            continue;
        }
        let curved = (0..=m.basis.spans() * 16).any(|i| {
            let r = m.basis.rows(i as f64 / 16.0);
            let c = &m.curves[k + 1];
            let (t, d2) = (
                crate::geom::bspline::apply(&r.d1, c),
                crate::geom::bspline::apply(&r.d2, c),
            );
            t.cross(d2).length() > straight * t.length().powi(3)
        });
        if !curved {
            return Err(shape(
                format!("creases[{}]", k + 1),
                format!(
                    "curve {} is straight: a `{}` condition says nothing on a straight crease; make it `free` or `smooth`, or bend the curve",
                    k + 2,
                    if kind == Crease::Fold { "fold" } else { "geodesic" }
                ),
            ));
        }
    }
    Ok(m)
}

/// A list with one entry per interior curve (`creases`, `folds`) has `len` entries: none (all
/// defaults) or one per interior curve of the chain.
fn per_interior(key: &str, len: usize, interior: usize) -> Result<(), SplineError> {
    if len == 0 || len == interior {
        return Ok(());
    }
    Err(SplineError::Shape {
        key: key.into(),
        message: format!(
            "has {len} entries, the chain has {interior} interior curves (one per curve between the first and the last)"
        ),
    })
}

/// `folds`: one entry per interior curve, a stated fold only on a crease that folds.
fn check_folds(spec: &SplineSpec, interior: usize) -> Result<(), SplineError> {
    let shape = |key: String, message: String| SplineError::Shape { key, message };
    per_interior("folds", spec.folds.len(), interior)?;
    for (k, f) in spec.folds.iter().enumerate() {
        let kind = spec.creases.get(k).copied().unwrap_or_default();
        if f.is_some() && !matches!(kind, Crease::Fold | Crease::Geodesic) {
            let name = Crease::NAMES
                .iter()
                .find(|(_, c)| *c == kind)
                .map_or("free", |n| n.0);
            return Err(shape(
                format!("folds[{}]", k + 1),
                format!(
                    "curve {} is a `{name}` crease, which does not fold; make it `fold` (or `geodesic`) in `creases`, or say \"none\" here",
                    k + 2
                ),
            ));
        }
    }
    Ok(())
}

/// A target point within this distance (mm) of the surface counts as covered (`coverage`).
pub const COVERAGE_MM: f64 = 0.5;

/// Control points per curve of a start from a target's principal rectangle.
pub const RECTANGLE_POINTS: usize = 8;

/// Consecutive samples of a curve closer than this (relative to the model's diameter) are one
/// vertex: the curve stands still there, a cone's apex.
const WELD: f64 = 1e-12;

/// A curve whose tangent is at most this share of the other curve's stands still there.
const APEX: f64 = 1e-6;

/// Most vertices of the sampled mesh.
pub const MAX_SAMPLED_VERTICES: usize = 2_000_000;

/// Most control points of one surface (all curves and the apex).
pub const MAX_CONTROL_POINTS: usize = 5_000;

/// The diagonal of the model's control points' bounding box (mm), at least 1e-300.
fn diameter(m: &Model) -> f64 {
    let pts = m.curves.iter().flatten().chain(m.apex.iter());
    crate::geom::mesh::bounds3(pts)
        .map_or(0.0, |(lo, hi)| (hi - lo).length())
        .max(1e-300)
}

/// The largest intrinsic crease sine at `per` parameters per span over the creases with a
/// condition; with `flip`, the right side's normals are turned over (the sign test: a fold
/// then reads as a geodesic crease).
pub fn dense_crease_sine(m: &Model, per: usize, flip: bool) -> f64 {
    let straight = solve::STRAIGHT / diameter(m);
    let mut worst: f64 = 0.0;
    if m.apex.is_some() {
        return 0.0;
    }
    for c in 1..m.curves.len().saturating_sub(1) {
        for k in 0..=m.basis.spans() * per {
            let u = k as f64 / per as f64;
            let r = m.basis.rows(u);
            let p = |j: usize, row: &[(usize, f64)]| crate::geom::bspline::apply(row, &m.curves[j]);
            let here = p(c, &r.point);
            let el = here - p(c - 1, &r.point);
            let er = p(c + 1, &r.point) - here;
            let er = if flip { -er } else { er };
            let t = p(c, &r.d1);
            if t.length() <= solve::STILL * diameter(m) {
                continue; // the crease stands still here
            }
            let s = solve::crease_sine(m.crease(c), el, er, t, p(c, &r.d2), straight);
            worst = worst.max(s);
        }
    }
    worst
}

/// Solve and sample a spline surface.
pub fn build(spec: &SplineSpec) -> Result<Solved, SplineError> {
    let mut m = model(spec)?;
    let report = solve::solve(&mut m, &spec.options)?;
    let params = sample_params(&m, spec.tolerance);
    let verts = params.len().saturating_mul(m.curves.len() + 1);
    if verts > MAX_SAMPLED_VERTICES {
        return Err(SplineError::Shape {
            key: "tolerance".into(),
            message: format!(
                "{} mm samples the surface into {verts} vertices, over {MAX_SAMPLED_VERTICES}; raise it",
                spec.tolerance
            ),
        });
    }
    check_striction(&m, &params)?;
    let sampled = sample_mesh(&m, &params);
    let curve_verts = sampled.curve_verts;
    let mut sampled_mesh = sampled.mesh;
    if spec.neutral_offset != 0.0 {
        offset_mesh(
            &m,
            &params,
            &curve_verts,
            &mut sampled_mesh,
            spec.neutral_offset,
        );
    }
    let seam = if m.basis.closed() {
        let mut s: Vec<[usize; 2]> = curve_verts
            .windows(2)
            .map(|w| [w[0][0].min(w[1][0]), w[0][0].max(w[1][0])])
            .collect();
        s.sort_unstable();
        s
    } else {
        Vec::new()
    };
    let mesh = sampled_mesh;
    let mut bends = bends(&mesh, &sampled.rulings, spec.bend_lines);
    bends.extend(crease_bends(&mesh, &sampled.creases));
    let (fold_mean, fold_max) = fold_angles(&mesh, &sampled.creases);
    let (delta, iso) = quad_figures(&m, &params);
    let defect = angle_defect(&mesh, &sampled.crease_verts);
    let crease_sine = dense_crease_sine(&m, 64, false);
    let sine = dense_sine(&m, 64);
    let mut warnings = Vec::new();
    if let Some(b) = report.budget {
        if report.iterations >= b {
            warnings.push(format!(
                "the design is large: its work budget allowed {b} of `max_iterations` = {} iterations; split it into several surfaces or thin the target",
                spec.options.max_iterations
            ));
        }
    }
    if sine > 1e-6 {
        warnings.push(format!(
            "the solve stopped at a developability sine of {sine:.2e} (above 1e-6) after {} iterations: the blank will need some stretching; raise `max_iterations` or free some control points",
            report.iterations
        ));
    }
    if crease_sine > 1e-6 {
        warnings.push(format!(
            "the solve stopped at a crease sine of {crease_sine:.2e} (above 1e-6) after {} iterations: the sides will not meet exactly along the crease; raise `max_iterations` or free some control points",
            report.iterations
        ));
    }
    let mut figures = vec![
        ("iterations", report.iterations as f64),
        ("largest_sine", sine),
        ("solver_sine", report.sines.last().copied().unwrap_or(0.0)),
        ("flatness_delta", delta),
        ("isometry_error", iso),
        ("control_points_moved_mm", report.moved),
        ("crease_sine", crease_sine),
        ("crease_angle_defect", defect),
    ];
    if !sampled.creases.is_empty() {
        figures.push(("fold_angle_mean_deg", fold_mean));
        figures.push(("fold_angle_max_deg", fold_max));
    }
    if !m.handles.is_empty() {
        figures.push(("handle_distance_mm", report.handle_distance));
    }
    if m.outline.is_some() {
        figures.push(("outline_isometry_error", report.outline_isometry));
    }
    let dist = target_distances(&m);
    if !dist.is_empty() {
        let n = dist.len() as f64;
        let rms = (dist.iter().map(|d| d * d).sum::<f64>() / n).sqrt();
        let covered = dist.iter().filter(|&&d| d <= COVERAGE_MM).count() as f64 / n;
        figures.push(("approximation_rms_mm", rms));
        figures.push((
            "approximation_max_mm",
            dist.iter().copied().fold(0.0, f64::max),
        ));
        figures.push(("coverage", covered));
        figures.push(("target_points", n));
    }
    Ok(Solved {
        model: m,
        params,
        curve_verts,
        seam,
        report,
        mesh,
        bends,
        figures,
        warnings,
    })
}

/// The strips of a model: (curve a, curve b or None for the apex).
fn strips(m: &Model) -> Vec<(usize, Option<usize>)> {
    match m.apex {
        Some(_) => vec![(0, None)],
        None => (0..m.curves.len() - 1).map(|c| (c, Some(c + 1))).collect(),
    }
}

/// Point and tangent of curve `c` (or the apex) at `u`.
fn at(m: &Model, c: Option<usize>, u: f64) -> (DVec3, Option<DVec3>) {
    match c {
        Some(c) => (
            m.basis.eval(&m.curves[c], u),
            Some(m.basis.deriv(&m.curves[c], u)),
        ),
        None => (m.apex.unwrap_or_default(), None),
    }
}

/// The distance (mm) of each target point from the surface (its footpoint on the nearest
/// strip); empty without a target.
pub fn target_distances(m: &Model) -> Vec<f64> {
    let Some(t) = &m.target else {
        return Vec::new();
    };
    let refs: Vec<target::StripRef> = strips(m)
        .into_iter()
        .map(|(a, b)| target::StripRef {
            basis: &m.basis,
            a: &m.curves[a],
            b: match b {
                Some(b) => Ok(&m.curves[b]),
                None => Err(m.apex.unwrap_or_default()),
            },
        })
        .collect();
    let grids: Vec<_> = refs.iter().map(|r| r.grid()).collect();
    t.points
        .iter()
        .map(|&q| {
            refs.iter()
                .zip(&grids)
                .map(|(r, g)| r.footpoint(g, q).2)
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        })
        .collect()
}

/// The largest intrinsic developability sine at `per` parameters per span.
pub fn dense_sine(m: &Model, per: usize) -> f64 {
    let mut worst: f64 = 0.0;
    for (a, b) in strips(m) {
        for k in 0..=m.basis.spans() * per {
            let u = k as f64 / per as f64;
            let (pa, ta) = at(m, Some(a), u);
            let (pb, tb) = at(m, b, u);
            worst = worst.max(solve::plane_sine(pb - pa, ta.unwrap_or_default(), tb));
        }
    }
    worst
}

/// Output parameters over the whole curve (ends included).
fn sample_params(m: &Model, tol: f64) -> Vec<f64> {
    let mut out = vec![0.0];
    for s in 0..m.basis.spans() {
        let mut m2: f64 = 0.0;
        for c in &m.curves {
            for i in 0..=4 {
                let r = m.basis.rows(s as f64 + i as f64 / 4.0);
                m2 = m2.max(crate::geom::bspline::apply(&r.d2, c).length());
            }
        }
        let n = if m2 > 0.0 {
            (m2 / (8.0 * tol.max(1e-6))).sqrt().ceil() as usize
        } else {
            1
        };
        let n = n.clamp(2, 512);
        out.extend((1..=n).map(|i| s as f64 + i as f64 / n as f64));
    }
    out
}

/// Refuse rulings that cross inside a strip: at each sampled ruling, the parameter v where
/// (1 − v) a′ + v b′ is along the ruling (the surface's singular point on it). Where one
/// curve stands still (its tangent under [`APEX`] times the other's) the rulings meet on it,
/// a cone's apex on the sheet's edge: allowed within 1e-6 of that end.
fn check_striction(m: &Model, params: &[f64]) -> Result<(), SplineError> {
    for (k, (a, b)) in strips(m).into_iter().enumerate() {
        for &u in params {
            let (pa, ta) = at(m, Some(a), u);
            let (pb, tb) = at(m, b, u);
            let e = pb - pa;
            let ta = ta.unwrap_or_default();
            let tb = tb.unwrap_or_default();
            let n = e.cross(ta) + e.cross(tb);
            let t = n.cross(e).normalize_or_zero();
            let (beta, delta) = (ta.dot(t), tb.dot(t));
            let scale = ta.length().max(tb.length()).max(1e-300);
            if (beta - delta).abs() <= 1e-12 * scale {
                continue; // parallel rulings here (a cylinder point)
            }
            if scale <= solve::STILL * e.length() {
                continue; // both curves stand still: the strip pauses on one ruling
            }
            let v = beta / (beta - delta);
            // A curve standing still is a cone's apex: the rulings meet there, on the edge.
            let (bottom, top) = match b {
                None => (-1e-9, 1.0 - 1e-9),
                Some(_) if tb.length() <= APEX * ta.length() => (-1e-9, 1.0 - 1e-6),
                Some(_) if ta.length() <= APEX * tb.length() => (1e-6, 1.0 + 1e-9),
                Some(_) => (-1e-9, 1.0 + 1e-9),
            };
            if v >= bottom && v <= top {
                return Err(SplineError::Striction { u, v, strip: k + 1 });
            }
        }
    }
    Ok(())
}

/// The sampled mesh with its rulings and creases, each edge as (face, corner of the edge in
/// it, the other face).
struct Sampled {
    mesh: Mesh,
    /// Interior rulings, in order along the strips.
    rulings: Vec<(usize, usize, usize)>,
    /// Edges along the interior curves.
    creases: Vec<(usize, usize, usize)>,
    /// Vertices on the interior curves, ends left out.
    crease_verts: Vec<usize>,
    /// Each curve's vertices (then the apex's one).
    curve_verts: Vec<Vec<usize>>,
}

/// Sample the model into triangles whose rulings are edges. Where a curve stands still (a
/// run of equal control points: the strip is a cone with its apex on that curve there), its
/// consecutive samples are one vertex and the quad is one triangle.
fn sample_mesh(m: &Model, params: &[f64]) -> Sampled {
    let mut vertices: Vec<DVec3> = Vec::new();
    let mut faces = Vec::new();
    let mut crease_verts = Vec::new();
    let k = params.len();
    // A closed surface is welded around: the last ruling is the first one.
    let weld = m.basis.closed();
    let still = WELD * diameter(m);
    let row = |c: usize, vertices: &mut Vec<DVec3>| -> Vec<usize> {
        let mut out: Vec<usize> = Vec::with_capacity(k);
        for (i, &u) in params.iter().enumerate() {
            if weld && i + 1 == k {
                out.push(out[0]);
                continue;
            }
            let p = m.basis.eval(&m.curves[c], u);
            match out.last() {
                Some(&v) if vertices[v].distance(p) <= still => out.push(v),
                _ => {
                    out.push(vertices.len());
                    vertices.push(p);
                }
            }
        }
        out
    };
    let first = strips(m).first().map_or(0, |s| s.0);
    let mut rows = vec![row(first, &mut vertices)];
    for (a, b) in strips(m) {
        let row_a = rows[a].clone();
        let row_b = match b {
            None => {
                vertices.push(m.apex.unwrap_or_default());
                vec![vertices.len() - 1; k]
            }
            Some(b) => {
                if a > 0 {
                    crease_verts.extend(row_a[1..k - 1].iter().copied());
                }
                row(b, &mut vertices)
            }
        };
        for i in 0..k - 1 {
            let (a0, a1, b0, b1) = (row_a[i], row_a[i + 1], row_b[i], row_b[i + 1]);
            for f in [[a0, a1, b1], [a0, b1, b0]] {
                if f[0] != f[1] && f[1] != f[2] && f[2] != f[0] {
                    faces.push(Face {
                        verts: f.to_vec(),
                        line: None,
                    });
                }
            }
        }
        rows.push(row_b);
    }
    crease_verts.dedup();
    let mesh = Mesh { vertices, faces };
    // Each edge's faces with its corner in them, to name rulings and creases.
    let topo = mesh.topology();
    let edge: std::collections::HashMap<[usize; 2], usize> = topo
        .edges
        .iter()
        .enumerate()
        .map(|(i, e)| (e.verts, i))
        .collect();
    let shared = |p: usize, q: usize| -> Option<(usize, usize, usize)> {
        match topo.edges[*edge.get(&[p.min(q), p.max(q)])?]
            .uses
            .as_slice()
        {
            &[(f, c), (g, _)] => Some((f, c, g)),
            _ => None,
        }
    };
    let mut rulings = Vec::new();
    let mut creases = Vec::new();
    for (s, _) in strips(m).into_iter().enumerate() {
        let (ra, rb) = (&rows[s], &rows[s + 1]);
        for i in 1..k - 1 {
            if (ra[i], rb[i]) == (ra[i - 1], rb[i - 1]) {
                continue;
            }
            if let Some((f, c, g)) = shared(ra[i], rb[i]) {
                rulings.push((f, g, c));
            }
        }
        if s > 0 {
            for i in 0..k - 1 {
                if ra[i] != ra[i + 1] {
                    if let Some(e) = shared(ra[i], ra[i + 1]) {
                        creases.push(e);
                    }
                }
            }
        }
    }
    if m.apex.is_some() {
        rows[1].truncate(1); // the apex: one vertex
    }
    Sampled {
        mesh,
        rulings,
        creases,
        crease_verts,
        curve_verts: rows,
    }
}

/// Move the sampled mesh `delta` mm against its face normals (onto a metal sheet's neutral
/// surface): each ruling's two ends move by the same vector, delta times the strip's unit
/// normal there (constant along a ruling of a developable, so the moved surface is developable
/// too); a vertex on a crease moves to where the two sides' moved planes meet (the mitre
/// (n₁ + n₂)/(1 + n₁·n₂)), a cone's apex to the least-squares meet of its rulings' planes.
fn offset_mesh(m: &Model, params: &[f64], curve_verts: &[Vec<usize>], mesh: &mut Mesh, delta: f64) {
    let mut normals: Vec<Vec<DVec3>> = vec![Vec::new(); mesh.vertices.len()];
    for (k, (a, b)) in strips(m).into_iter().enumerate() {
        for (i, &u) in params.iter().enumerate() {
            let (pa, ta) = at(m, Some(a), u);
            let (pb, _) = at(m, b, u);
            // Faces (a_i, a_i+1, b_i+1) face a′ × e; inward is e × a′.
            let n = (pb - pa).cross(ta.unwrap_or_default()).normalize_or_zero();
            if n == DVec3::ZERO {
                continue;
            }
            for c in [k, k + 1] {
                if let Some(&v) = curve_verts
                    .get(c)
                    .and_then(|row| row.get(i).or(row.first()))
                {
                    if !normals[v].iter().any(|q| q.dot(n) > 1.0 - 1e-12) {
                        normals[v].push(n);
                    }
                }
            }
        }
    }
    for (v, ns) in normals.iter().enumerate() {
        let shift = match ns.len() {
            0 => continue,
            1 => ns[0],
            2 if ns[0].dot(ns[1]) > -0.9 => (ns[0] + ns[1]) / (1.0 + ns[0].dot(ns[1])),
            _ => {
                // Least squares: ⟨x, nᵢ⟩ = 1 for every normal.
                let a = ns.iter().fold(glam::DMat3::ZERO, |acc, n| {
                    acc + glam::DMat3::from_cols(*n * n.x, *n * n.y, *n * n.z)
                });
                let rhs: DVec3 = ns.iter().copied().sum();
                if a.determinant().abs() > 1e-12 {
                    a.inverse() * rhs
                } else {
                    rhs / ns.len() as f64
                }
            }
        };
        mesh.vertices[v] += shift * delta;
    }
}

/// Fold lines on the crease edges that bend (more than 0.01°), with their dihedral angles.
fn crease_bends(mesh: &Mesh, creases: &[(usize, usize, usize)]) -> Vec<Bend> {
    creases
        .iter()
        .filter_map(|&(f, corner, g)| {
            let (va, vb) = crate::geom::mesh::Topology::corner_verts(mesh, f, corner);
            let deg = mesh.signed_dihedral(f, corner, g)?.to_degrees();
            (deg.abs() > 0.01).then_some(Bend {
                verts: [va.min(vb), va.max(vb)],
                angle_deg: deg,
            })
        })
        .collect()
}

/// The fold angle (degrees, unsigned) along the crease edges: its mean weighted by edge
/// length and its largest.
fn fold_angles(mesh: &Mesh, creases: &[(usize, usize, usize)]) -> (f64, f64) {
    let (mut sum, mut len, mut max) = (0.0, 0.0, 0.0f64);
    for &(f, corner, g) in creases {
        let (va, vb) = crate::geom::mesh::Topology::corner_verts(mesh, f, corner);
        let Some(a) = mesh.signed_dihedral(f, corner, g) else {
            continue;
        };
        let l = mesh.vertices[va].distance(mesh.vertices[vb]);
        let deg = a.to_degrees().abs();
        sum += deg * l;
        len += l;
        max = max.max(deg);
    }
    (if len > 0.0 { sum / len } else { 0.0 }, max)
}

/// The largest |angle sum − 2π| (radians) at `verts` over the faces of `mesh`.
fn angle_defect(mesh: &Mesh, verts: &[usize]) -> f64 {
    let mut sum = vec![0.0; mesh.vertices.len()];
    for f in &mesh.faces {
        let n = f.verts.len();
        for i in 0..n {
            let (p, a, b) = (f.verts[i], f.verts[(i + 1) % n], f.verts[(i + n - 1) % n]);
            let (o, u, w) = (mesh.vertices[p], mesh.vertices[a], mesh.vertices[b]);
            let angle = (u - o).angle_between(w - o);
            if angle.is_finite() {
                sum[p] += angle;
            }
        }
    }
    verts
        .iter()
        .map(|&v| (sum[v] - std::f64::consts::TAU).abs())
        .fold(0.0, f64::max)
}

/// Bend lines on the rulings per `lines` (as strips pick them: all, none, a spacing with the
/// angles in between summed, or a shop's equal shares).
fn bends(mesh: &Mesh, rulings: &[(usize, usize, usize)], lines: BendLines) -> Vec<Bend> {
    const EPS_DEG: f64 = 0.01;
    let mut out: Vec<Bend> = Vec::new();
    let mut acc = 0.0;
    let mut along = 0.0;
    let mut last_pick = 0.0;
    let mut prev_mid: Option<DVec3> = None;
    // Shop: every ruling (vertices, mm along, signed degrees), picked after the walk.
    let mut seen: Vec<([usize; 2], f64, f64)> = Vec::new();
    for &(f, g, corner) in rulings {
        let (va, vb) = crate::geom::mesh::Topology::corner_verts(mesh, f, corner);
        let mid = 0.5 * (mesh.vertices[va] + mesh.vertices[vb]);
        if let Some(p) = prev_mid {
            along += mid.distance(p);
        }
        prev_mid = Some(mid);
        let Some(angle) = mesh.signed_dihedral(f, corner, g) else {
            continue;
        };
        acc += angle;
        let deg = angle.to_degrees();
        let verts = if va < vb { [va, vb] } else { [vb, va] };
        match lines {
            BendLines::None => {}
            BendLines::All => {
                if deg.abs() > EPS_DEG {
                    out.push(Bend {
                        verts,
                        angle_deg: deg,
                    });
                }
            }
            BendLines::Spacing(s) => {
                if along - last_pick >= s && deg.abs() > EPS_DEG {
                    out.push(Bend {
                        verts,
                        angle_deg: f64::to_degrees(acc),
                    });
                    acc = 0.0;
                    last_pick = along;
                }
            }
            BendLines::Shop => seen.push((verts, along, deg)),
        }
    }
    if let (BendLines::Spacing(_), Some(last)) = (lines, out.last_mut()) {
        last.angle_deg += f64::to_degrees(acc);
    }
    if lines == BendLines::Shop {
        let along_deg: Vec<super::strip::shop::Ruling> = seen
            .iter()
            .map(|s| super::strip::shop::Ruling::at(s.1, s.2))
            .collect();
        out = super::strip::shop::picks(&along_deg)
            .into_iter()
            .map(|(k, angle_deg)| Bend {
                verts: seen[k].0,
                angle_deg,
            })
            .collect();
    }
    out
}

/// Fig. 17's face flatness δ (largest) and the largest isometry error of the sampled quads.
fn quad_figures(m: &Model, params: &[f64]) -> (f64, f64) {
    let (mut delta, mut iso): (f64, f64) = (0.0, 0.0);
    for (a, b) in strips(m) {
        let Some(b) = b else { continue };
        for w in params.windows(2) {
            let a0 = m.basis.eval(&m.curves[a], w[0]);
            let a1 = m.basis.eval(&m.curves[a], w[1]);
            let b0 = m.basis.eval(&m.curves[b], w[0]);
            let b1 = m.basis.eval(&m.curves[b], w[1]);
            let short = 0.5 * (a0.distance(a1) + b0.distance(b1));
            if short > 0.0 {
                delta = delta.max(line_distance(a0, b1, a1, b0) / short);
            }
            // Unfold (a0, a1, b1) and (a0, b1, b0) about a0–b1 and compare |a1 − b0|.
            let d3 = a1.distance(b0);
            let d2 = unfolded_distance(a0, b1, a1, b0);
            if d3 > 0.0 {
                iso = iso.max((d2 - d3).abs() / d3);
            }
        }
    }
    (delta, iso)
}

/// Distance between the lines p + s(q − p) and r + t(w − r).
fn line_distance(p: DVec3, q: DVec3, r: DVec3, w: DVec3) -> f64 {
    let n = (q - p).cross(w - r);
    let len = n.length();
    if len <= 1e-300 {
        return 0.0;
    }
    (r - p).dot(n).abs() / len
}

/// Distance of `x` and `y` after the triangles (p, q, x) and (p, q, y) are unfolded into one
/// plane on opposite sides of p–q.
fn unfolded_distance(p: DVec3, q: DVec3, x: DVec3, y: DVec3) -> f64 {
    let axis = (q - p).normalize_or_zero();
    let flat = |v: DVec3| {
        let d = v - p;
        let along = d.dot(axis);
        (along, (d - axis * along).length())
    };
    let (xa, xh) = flat(x);
    let (ya, yh) = flat(y);
    ((xa - ya).powi(2) + (xh + yh).powi(2)).sqrt()
}

#[cfg(test)]
mod tests;
