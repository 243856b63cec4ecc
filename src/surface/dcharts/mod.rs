//! D-Charts: segmentation of a smooth mesh into nearly developable charts (Julius 2006, thesis
//! chapter 5; Julius, Kraevoy, Sheffer 2005).
//!
//! Each chart is grown around a DCS proxy (axis and angle, [`crate::geom::proxy`]) and a seed
//! face. [`segment`] runs the thesis' steps in order, one file each:
//!
//! - `grow`: the modified Lloyd iterations of §5.2.1 with the cost of eq. 5.1–5.3
//!   (`Cost = F^α · C^β · P^γ`, α = 1, β = 0.7, γ = 0.5), farthest-point seeds, one priority
//!   queue per chart, proxy refit (eq. 5.4) and reseeding;
//! - `holes`: hole filling (§5.2.2);
//! - `straighten`: boundary straightening through fuzzy areas (§5.2.3, first step);
//! - `disks`: charts made disks (§5.2.3, "cuts connecting the boundary loops"), cut open along
//!   seams by [`crate::geom::cut`] (shared with the flatten stage), split only where cutting
//!   cannot help;
//! - `merge`: merging adjacent charts whose common boundary fits a cylinder (§5.2.3, `η`);
//! - `creases`: which meshes are segmented at all ([`is_smooth`]) and the creases inside a
//!   chart that a pattern scores (`creases`).
//!
//! [`apply`] reads a mesh surface's spec settings (the DCS approximation of chapter 6 first,
//! [`super::dcs`]) and stores the charts, their cuts and creases on the [`super::Surface`].
//! When the spec leaves `segment` out, the mesh decides ([`is_smooth`]) and the surface's
//! `figures` (report.json) say how: `bent_edges`, `gentle_bend_share` (of those, the share
//! bending under 10°) and `segmented` (1: charts, 0: face by face). [`resegment`] segments
//! such a surface again into another count of charts, at the size [`apply`] segmented it at
//! (the pipeline does when the default count leaves pieces under 1 % of the area; report.json
//! then gives `dcharts_charts` and `dcharts_segmentations`).
//!
//! Choices where the thesis is silent: the default initial chart count is 8 (the thesis gives
//! a rough estimate per model, 6 for the fandisk); `η` defaults to 10⁻³, between the thesis'
//! 10⁻⁵ (mechanical parts) and 10⁻² (free forms); faces across a non-manifold edge (three or
//! more faces) or a degenerate face (zero normal: it fits every proxy) are handled:
//! non-manifold edges simply do not join charts. Several connected components each get their
//! own charts. The result is deterministic: ties break on face index, charts are numbered by
//! their smallest face.
//!
//! Not done: the min-cut straightening of closed boundary loops.

mod creases;
mod disks;
mod grow;
mod holes;
mod merge;
mod straighten;

pub use creases::{bends, is_smooth, Bends};
use creases::{creases, CREASE_DEG};
pub use straighten::boundary_length;

use super::dcs;
use crate::geom::cut::Graph;
use crate::geom::mesh::Mesh;

/// No chart (a face not yet reached).
const NONE: usize = usize::MAX;

/// Settings of the segmentation (thesis defaults).
#[derive(Debug, Clone, PartialEq)]
pub struct DChartsOptions {
    /// Initial estimate of the number of charts (the algorithm adds and removes charts).
    pub charts: usize,
    /// Fitting threshold `F_max` (eq. 4.1 units; default 0.2).
    pub f_max: f64,
    pub alpha: f64,
    pub beta: f64,
    pub gamma: f64,
    /// Bound on Lloyd iterations (default 50).
    pub max_iterations: usize,
    /// Lloyd stops when fewer than this fraction of faces change chart (default 0.05).
    pub stop_fraction: f64,
    /// Best-fitting faces examined when choosing a new seed (default 10).
    pub seed_candidates: usize,
    /// Holes with less than this fraction of the total area are filled by their neighbours
    /// (default 0.002); larger ones get new charts.
    pub small_hole: f64,
    /// Merging threshold `η` on the mean cylinder fitting error (default 1e-3).
    pub eta: f64,
    /// Face rings on each side of a common boundary tested for merging (default 2).
    pub merge_rings: usize,
    /// Straighten the boundaries between charts through their fuzzy areas (§5.2.3; default
    /// on).
    pub straighten: bool,
    /// Fuzzy areas take the faces fitting the other chart's proxy below this fraction of
    /// `F_max` (default 0.1).
    pub fuzzy: f64,
}

impl Default for DChartsOptions {
    fn default() -> Self {
        DChartsOptions {
            charts: 8,
            f_max: 0.2,
            alpha: 1.0,
            beta: 0.7,
            gamma: 0.5,
            max_iterations: 50,
            stop_fraction: 0.05,
            seed_candidates: 10,
            small_hole: 0.002,
            eta: 1e-3,
            merge_rings: 2,
            straighten: true,
            fuzzy: 0.1,
        }
    }
}

/// The charts of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Segmentation {
    /// Chart of each face, numbered from 0 by smallest face.
    pub chart: Vec<usize>,
    /// Number of charts.
    pub count: usize,
    /// Lloyd iterations run.
    pub iterations: usize,
    /// Charts added by hole filling.
    pub added: usize,
    /// Merges made.
    pub merged: usize,
    /// Boundary segments re-routed by straightening.
    pub straightened: usize,
    /// Splits made so that every chart is a disk (charts joined through a single vertex or a
    /// non-manifold edge; tubes, closed shells and handles are cut open instead).
    pub split: usize,
    /// Edges cut open inside charts so that every chart is a disk ([`crate::geom::cut::disk_cuts`]), as mesh
    /// vertex pairs (smaller first), sorted: what [`super::Surface::cuts`] takes.
    pub cuts: Vec<[usize; 2]>,
}

impl Segmentation {
    /// Faces of each chart, ascending.
    pub fn charts(&self) -> Vec<Vec<usize>> {
        let mut out = vec![Vec::new(); self.count];
        for (f, &c) in self.chart.iter().enumerate() {
            out[c].push(f);
        }
        out
    }
}

/// Why a mesh cannot be segmented.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DChartsError {
    #[error("the mesh has no faces")]
    Empty,
    #[error("the mesh has a vertex that is not a finite number")]
    NonFinite,
    #[error("{0}")]
    Options(String),
}

/// Segment a mesh into nearly developable charts.
pub fn segment(mesh: &Mesh, o: &DChartsOptions) -> Result<Segmentation, DChartsError> {
    let nf = mesh.faces.len();
    if nf == 0 {
        return Err(DChartsError::Empty);
    }
    if mesh.vertices.iter().any(|v| !v.is_finite()) {
        return Err(DChartsError::NonFinite);
    }
    if !(o.f_max > 0.0 && o.f_max <= 1.0) {
        return Err(DChartsError::Options(format!(
            "f_max must be more than 0 and at most 1, got {}",
            o.f_max
        )));
    }
    if o.charts == 0 {
        return Err(DChartsError::Options("charts must be at least 1".into()));
    }
    if !(o.eta >= 0.0 && o.eta.is_finite()) {
        return Err(DChartsError::Options(format!(
            "eta must be a number, at least 0, got {}",
            o.eta
        )));
    }
    let topo = mesh.topology();
    let g = Graph::new(mesh, &topo);
    let (mut st, iterations) = grow::lloyd(mesh, &g, o);
    let added = holes::fill(&grow::Segmenter { g: &g, o }, &mut st);
    let mut chart = st.assign;
    let mut count = st.proxies.len();
    compact_ids(&mut chart, &mut count);
    let straightened = if o.straighten {
        straighten::straighten(mesh, &topo, &g, o, &mut chart)
    } else {
        0
    };
    compact_ids(&mut chart, &mut count);
    let mut split = disks::make_disks(mesh, &topo, &g, &mut chart, &mut count);
    let merged = merge::merge(mesh, &topo, &g, o, &mut chart, &mut count);
    split += disks::make_disks(mesh, &topo, &g, &mut chart, &mut count);
    compact_ids(&mut chart, &mut count);
    let cuts = disks::chart_cuts(mesh, &topo, &g, &chart, count);
    Ok(Segmentation {
        chart,
        count,
        iterations,
        added,
        merged,
        straightened,
        split,
        cuts,
    })
}

/// Renumber charts 0.. by smallest face, dropping empty ids.
fn compact_ids(chart: &mut [usize], count: &mut usize) {
    let mut map = vec![NONE; (*count).max(chart.iter().copied().max().map_or(0, |m| m + 1))];
    let mut next = 0;
    for c in chart.iter_mut() {
        if map[*c] == NONE {
            map[*c] = next;
            next += 1;
        }
        *c = map[*c];
    }
    *count = next;
}

/// Apply a mesh surface's issue-7 settings: the DCS approximation when asked, then, for
/// `segment = "dcharts"` (or a smooth mesh without `segment`, see [`is_smooth`]), the charts
/// ([`super::Surface::charts`]) and the creases inside them as the surface's bend lines. Polygons are
/// split into triangles first (by ear clipping in their plane), since charts are
/// parameterised triangle by triangle.
pub fn apply(
    surface: &mut super::Surface,
    seg: &crate::surface::SegmentSpec,
) -> Result<(), super::SurfaceError> {
    use crate::surface::{Fixed, Segment};
    if let Some(ap) = &seg.approximate {
        let nv = surface.mesh.vertices.len();
        let mut fixed = Vec::new();
        for f in &ap.fixed {
            match *f {
                Fixed::Boundary => {
                    let topo = surface.mesh.topology();
                    for e in topo.edges.iter().filter(|e| e.uses.len() == 1) {
                        fixed.extend(e.verts);
                    }
                }
                Fixed::Vertex(v) if v < nv => fixed.push(v),
                Fixed::Vertex(v) => {
                    return Err(invalid(
                        surface,
                        format!(
                            "approximate.fixed names vertex {}, but the mesh has {nv} vertices",
                            v + 1
                        ),
                    ))
                }
            }
        }
        fixed.sort_unstable();
        fixed.dedup();
        let opts = dcs::ApproximateOptions {
            iterations: ap.iterations,
            fixed,
            ..Default::default()
        };
        dcs::approximate(&mut surface.mesh, &opts)
            .map_err(|e| invalid(surface, format!("DCS approximation: {e}")))?;
    }
    let mode = match seg.mode {
        Some(m) => m,
        None => {
            // Decided from the mesh; report.json says so and why (`figures`).
            let b = bends(&surface.mesh);
            surface.figures.push(("bent_edges", b.bent as f64));
            surface
                .figures
                .push(("gentle_bend_share", b.gentle_share()));
            surface
                .figures
                .push(("segmented", f64::from(u8::from(b.smooth()))));
            if b.smooth() {
                Segment::Dcharts
            } else {
                Segment::Faces
            }
        }
    };
    if mode == Segment::Faces {
        return Ok(());
    }
    triangulate(&mut surface.mesh);
    let opts = options(seg, seg.charts);
    let s =
        segment(&surface.mesh, &opts).map_err(|e| invalid(surface, format!("D-Charts: {e}")))?;
    surface.bends = Some(creases(&surface.mesh, CREASE_DEG));
    surface.charts = Some(s.chart);
    surface.cuts = s.cuts;
    Ok(())
}

/// A surface [`apply`] segmented, segmented again into about `charts` charts (the other
/// settings as `seg` gives them): at the size it was first segmented at (its
/// [`super::size::Shape`]), so that its charts do not depend on the size it is made at, as the
/// first segmentation's do not. `Ok(false)`, nothing changed, where the surface has no charts
/// or no shape.
pub fn resegment(
    surface: &mut super::Surface,
    seg: &crate::surface::SegmentSpec,
    charts: usize,
) -> Result<bool, super::SurfaceError> {
    let (Some(_), Some(shape)) = (&surface.charts, &surface.shape) else {
        return Ok(false);
    };
    let at_shape = Mesh {
        vertices: shape.vertices.clone(),
        faces: surface.mesh.faces.clone(),
    };
    let s = segment(&at_shape, &options(seg, Some(charts)))
        .map_err(|e| invalid(surface, format!("D-Charts: {e}")))?;
    surface.charts = Some(s.chart);
    surface.cuts = s.cuts;
    Ok(true)
}

/// The error for `surface`'s settings: its file, its name and `message`.
fn invalid(surface: &super::Surface, message: String) -> super::SurfaceError {
    super::SurfaceError::Invalid {
        path: surface.source.clone(),
        message: format!("surface `{}`: {message}", surface.name),
    }
}

/// D-Charts' options as a spec's `seg` gives them, with `charts` charts (`None`: the
/// default count).
fn options(seg: &crate::surface::SegmentSpec, charts: Option<usize>) -> DChartsOptions {
    let d = DChartsOptions::default();
    DChartsOptions {
        charts: charts.unwrap_or(d.charts),
        f_max: seg.f_max.unwrap_or(d.f_max),
        ..d
    }
}

/// Split every polygon with more than three corners into triangles (ear clipping in the
/// polygon's plane), keeping its source line.
pub fn triangulate(mesh: &mut Mesh) {
    if mesh.faces.iter().all(|f| f.verts.len() == 3) {
        return;
    }
    let mut faces = Vec::with_capacity(mesh.faces.len() * 2);
    for (f, face) in mesh.faces.iter().enumerate() {
        if face.verts.len() <= 3 {
            faces.push(face.clone());
            continue;
        }
        let n = mesh.face_normal(f);
        let x = n.any_orthonormal_vector();
        let y = n.cross(x);
        let pts: Vec<glam::DVec2> = face
            .verts
            .iter()
            .map(|&v| glam::DVec2::new(mesh.vertices[v].dot(x), mesh.vertices[v].dot(y)))
            .collect();
        let tris = crate::geom::polygon::triangulate(&pts);
        if tris.is_empty() {
            faces.push(face.clone());
            continue;
        }
        for t in tris.iter() {
            faces.push(crate::geom::mesh::Face {
                verts: vec![face.verts[t[0]], face.verts[t[1]], face.verts[t[2]]],
                line: face.line,
            });
        }
    }
    mesh.faces = faces;
}
