//! Flattening of a segmented smooth surface: every chart of [`Surface::charts`] becomes one
//! island, laid flat by [`super::param::parameterize`] (LSCM / ABF++, scaled so that its 2D
//! area equals its 3D area), and [`flatten`] picks between that and the exact polyhedral
//! [`super::unfold()`] for the CLI.
//!
//! **Cuts inside a chart** ([`Surface::cuts`], thesis §5.2.3): a chart is opened along its cut
//! edges before it is parameterised: [`crate::geom::cut::open`] gives one vertex per
//! wedge of faces around each mesh vertex, so the vertices along a seam are split, and the
//! opened chart is laid flat as a mesh of its own. A chart that is still not a disk gets the
//! cuts of [`crate::geom::cut::disk_cuts`] (a tube the shortest seam between its rims,
//! a chart with handles its shortest system of loops as well);
//! cuts a split leaves useless are dropped and found again. A cut edge is never `joined`, so
//! the pattern stage draws it as a cut line with seam marks on both sides, like a seam
//! between two pieces; [`Surface::cuts`] of the result lists the cuts that stayed inside a
//! piece.
//!
//! The [`Flat`] it builds is the one the pattern stage already reads: `face_2d` per face
//! corner, counter-clockwise (a chart laid out mirrored is mirrored back); `joined` for the
//! edges inside a chart (their two copies coincide, the layout being per opened vertex);
//! `dihedral` the signed bend of every interior edge, as [`super::unfold()`] computes it.
//!
//! After the thesis' §5.3 ("overlaps cut away", "darts shortened", "a piece over the
//! material's tolerance"), a chart
//! - whose layout overlaps itself deeper than the unfolder's tolerance (a global overlap) has
//!   the overlapping region cut off (`cut_off`, after Lévy et al. 2002, the thesis' ref. 22:
//!   the overlapping faces are sorted to the nearer of the two first found overlapping, the
//!   side with less overlapping area is cut off, again while the rest still overlaps) when
//!   that part has at most `CUT_OFF_AREA` of the chart's area; the part cut off is a chart
//!   of its own, re-attached at the end to a neighbour where it fits (`reattach`). A larger
//!   overlap splits the chart between the two overlapping faces
//!   (`split_between` of [`crate::geom::cut`]: each face goes with the nearer of the two,
//!   through the chart); a chart that needed seams to be a disk (a tube whose layout
//!   spirals over itself) is halved along the bisector instead, unless it lies flat with
//!   next to no stretch (`TUBE_CUT_OFF`): such a band overlaps where flanges standing at a
//!   crease fold over one another, and has them cut off like any chart;
//! - whose L2 stretch is over [`FlattenOptions::tolerance`] first gets darts (`darts`: up
//!   to [`FlattenOptions::darts`] partial cuts from its boundary toward its most curved
//!   region, then shortened while it stays within the tolerance), then gussets where the
//!   surface is saddle-shaped (`gussets`: a slit toward the most negative angle defect
//!   overlaps instead of opening; the overlapping region is cut off as a small piece of its
//!   own, sewn into the gap the slit leaves, and re-attached to a neighbour when it fits;
//!   tried on a chart that can still be split only within `GUSSET_REACH` of the tolerance);
//!
//! and is split along the bisector of its two most distant faces
//! (`bisect` of [`crate::geom::cut`]) when
//! - it has a flipped triangle,
//! - the parameteriser refuses it (no cut makes it a disk),
//! - or its L2 stretch is still over the tolerance — at most [`FlattenOptions::max_splits`]
//!   times per chart (its darts dropped, each half gets its own); what is still over it then
//!   is laid out exactly, as the polyhedral unfolder does (`exact`: stretch 1, its bends fold
//!   lines, slits where it needs them, several pieces where it would overlap itself), unless
//!   [`FlattenOptions::exact`] is off; then it is reported (a warning on the surface, and the
//!   stretch of every piece in `report.json`).
//!
//! Material tolerances on the L2 stretch of a piece (`material_tolerance`), chosen here:
//! paper 1.003 (paper does not stretch; 0.3 % is taken up by folding and gluing without a
//! visible wrinkle), metal 1.001 (a blank must develop, 0.1 % is within a plotter's accuracy
//! on a 1 m piece), fabric 1.03 (woven cloth gives a few percent on the bias, and stuffing
//! takes up more). L∞ is reported but not used: one sliver triangle makes it large without a
//! visible fault.
//!
//! The charts are laid on the machine's cores ([`crate::geom::par`]): each chart, then the
//! parts it is split or cut into (forked in turn), the results put back in the order one core
//! would make them, so the output does not depend on the number of cores. A layout made to
//! decide (a part cut off, a dart tried) is kept, up to a bound, and not made again when that
//! chart's turn comes.
//!
//! **Parts start from the whole** (`lay_from`, [`param::relax_from`]): a half of a chart split
//! for stretch or a flip, a part of one split or cut off where it overlaps itself, and two
//! pieces merged into one are not laid anew: they start from the layout they had within the
//! whole (the two pieces: one moved onto the other along their common boundary) and are only
//! relaxed by the stretch minimisation, which stops early from there. The halves of a tube and
//! the rest of a chart after a gusset start anew (their layout within the whole, spiralled or
//! with the slit's sides overlapping, is a poor start), and so do darts (a dart closed in the
//! start opens too slowly). A part the whole's layout does not fit (its corners at one vertex
//! apart, a triangle flipped) is laid anew.
//!
//! **Pieces that fit the sheet** (`room`): once every chart is laid, a piece that does not fit
//! the sheet ([`FlattenOptions::sheet`]) is halved and each half laid again from the whole, in
//! rounds until its parts fit [`FlattenOptions::room`]; the pattern stage would cut it as it
//! lies, and a part of a layout can stretch more than the whole or be a small tip. The sheet
//! does not scale with the model: these halves are the only pieces that depend on its size.
//!
//! **Few pieces** (issue 20): then a piece under 1 % of the area is
//! merged into a neighbour where the two laid out as one stay within the tolerance, flip-free,
//! without overlap and with their seams matched (`merge`), else grafted onto its neighbours as
//! they lie: its faces unfolded exactly onto their layouts (`exact::graft`). Then neighbouring
//! pieces of any size are joined where they lie flat as one well within the tolerance
//! (`merge`). Last, a piece still small is hinged onto a neighbour as it lies, by one edge of
//! their common boundary, the rest of it a slit (`hinge`), where it fits beside it.
//!
//! **Seams that match** (issue 20): every layout within the tolerance has its boundary edges
//! brought to their 3D lengths by [`param::match_seams`] before it is judged (overlap, flips,
//! stretch), so both sides of every seam between charts, and of every cut inside one, are as
//! long flat as in 3D and the stretch a non-developable chart needs is taken up inside it.
//! Matching raises L2 a little (the inside absorbs what the boundary gave up), so a chart near
//! the tolerance may be cut further. Layouts over the tolerance are not matched while they are
//! still to be cut or split; a chart left over it at the end is matched then, or halved when
//! its matched layout would overlap or flip (`MATCH_ROUNDS` rounds). So is a chart whose border
//! edges are still further from their 3D lengths than [`FlattenOptions::seam_tolerance`] (its
//! matching could not be had without a flip). Before those rounds every piece is checked to
//! lie in one part (`Charts::flat_parts`): one whose faces are joined only through its cuts,
//! or through edges whose two copies lie apart, would be cut and nested as two outlines in
//! one, so it is taken apart into the pieces it lies in (a guard; the stages above do not
//! make such pieces).

use super::distortion::{self, Stretch};
use super::param::{self, ParamMethod};
use super::{unfold, Flat, FlattenError, UnfoldOptions};
use crate::geom::cut::{bisect, disk_cuts, open, split_between, Graph};
use crate::geom::mesh::{Face, Mesh, Topology};
use crate::geom::polygon;
use crate::surface::MaterialKind;
use crate::surface::Surface;
use glam::DVec2;
use std::collections::HashMap;
use std::sync::Arc;

mod assemble;
mod darts;
mod exact;
mod hinge;
mod join;
mod merge;
mod overlap;
mod room;
mod slit;

pub use assemble::small_islands;
use assemble::{assemble, edge_ids};
use darts::{darts, gussets, DART_MIN_FACES, GUSSET_REACH};
use overlap::{cut_off, overlaps, reattach, self_overlap, OVERLAP_PAIRS};

/// How a surface is laid flat.
#[derive(Debug, Clone, PartialEq)]
pub struct FlattenOptions {
    /// The exact unfolding's options (surfaces without charts).
    pub unfold: UnfoldOptions,
    /// Parameterisation of charts.
    pub method: ParamMethod,
    /// Largest L2 stretch of a piece before it is split (see `material_tolerance`).
    pub tolerance: f64,
    /// Times a chart may be split for being over the tolerance (overlaps and flips are always
    /// split, down to single faces).
    pub max_splits: usize,
    /// Most darts cut into a chart over the tolerance before it is split (see the module doc); 0
    /// for none.
    pub darts: usize,
    /// Most gussets cut into a chart still over the tolerance after its darts (see
    /// `gussets`); 0 for none (default 2).
    pub gussets: usize,
    /// A chart still over the tolerance once it may be split no further is laid out exactly,
    /// as the polyhedral unfolder does (`exact`); false leaves it as the parameteriser laid
    /// it, with a warning (default true).
    pub exact: bool,
    /// Merging threshold `η` for re-attaching a cut-off gusset to an adjacent piece: the mean
    /// cylinder fitting error of the gusset and two face rings of the piece around their common
    /// boundary ([`crate::geom::proxy::cylinder_error`], §5.2.3); default 1e-3, the segmentation's
    /// `η` (`surface::dcharts::DChartsOptions::eta`).
    pub reattach_eta: f64,
    /// Largest difference between a border edge of a piece laid flat and in 3D, over its 3D
    /// length (see the module doc's "Seams that match"): half the material's seam tolerance
    /// (issue 20: paper 0.2 %, metal 0.1 %, fabric 1 %), so that the two sides of a seam
    /// differ by at most that (default paper's, 0.001).
    pub seam_tolerance: f64,
    /// The box (width, height in mm; the height infinite on a roll) a piece may take before
    /// the pattern stage splits it to fit the sheet (the sheet less what the material adds
    /// round a piece): the parts of a piece halved for the sheet are halved until they fit it
    /// (see the module doc), and two pieces that each fit it are not merged into one that does
    /// not (at a quarter turn of its minimum-area rectangle, as the nest
    /// places it). `None` (default): no limit.
    pub room: Option<[f64; 2]>,
    /// The sheet inside its margins (width, height in mm; the height infinite on a roll): a
    /// piece that does not fit it is halved here until its parts fit [`FlattenOptions::room`]
    /// (see the module doc); one that fits it but not the room is left to the pattern stage,
    /// which knows what it adds round it. `None` (default): nothing is halved.
    pub sheet: Option<[f64; 2]>,
}

impl Default for FlattenOptions {
    fn default() -> Self {
        FlattenOptions {
            unfold: UnfoldOptions::default(),
            method: ParamMethod::default(),
            tolerance: material_tolerance(MaterialKind::Paper),
            max_splits: 3,
            darts: 4,
            gussets: 2,
            exact: true,
            reattach_eta: 1e-3,
            seam_tolerance: seam_tolerance(MaterialKind::Paper),
            room: None,
            sheet: None,
        }
    }
}

impl FlattenOptions {
    /// Defaults for a material.
    pub fn for_material(kind: MaterialKind) -> Self {
        FlattenOptions {
            tolerance: material_tolerance(kind),
            seam_tolerance: seam_tolerance(kind),
            ..Default::default()
        }
    }
}

/// Half the seam tolerance of a material (see [`FlattenOptions::seam_tolerance`]).
fn seam_tolerance(kind: MaterialKind) -> f64 {
    match kind {
        MaterialKind::Paper => 0.001,
        MaterialKind::Fabric => 0.005,
        MaterialKind::Metal => 0.0005,
    }
}

/// Largest L2 stretch of a piece, by material (see the module doc).
fn material_tolerance(kind: MaterialKind) -> f64 {
    match kind {
        MaterialKind::Paper => 1.003,
        MaterialKind::Fabric => 1.03,
        MaterialKind::Metal => 1.001,
    }
}

/// Lay a surface flat: its charts parameterised when it has them, else unfolded exactly.
/// A mesh with a [`Surface::shape`] is laid out at that shape's size and the layout scaled to
/// the surface's millimetres, so that its pieces do not depend on its size (issue 20, item 5).
pub fn flatten(mut surface: Surface, opts: &FlattenOptions) -> Result<Flat, FlattenError> {
    let shape = surface
        .shape
        .take()
        .filter(|s| s.vertices.len() == surface.mesh.vertices.len() && s.to_mm.is_finite());
    let Some(shape) = shape else {
        return flatten_as_is(surface, opts);
    };
    let k = shape.to_mm;
    let mm = std::mem::replace(&mut surface.mesh.vertices, shape.vertices);
    let mut flat = flatten_as_is(surface, opts)?;
    let vertices = std::mem::replace(&mut flat.surface.mesh.vertices, mm);
    flat.surface.shape = Some(crate::surface::size::Shape { vertices, to_mm: k });
    for c in flat.face_2d.iter_mut().flatten() {
        *c *= k;
    }
    flat.tolerance *= k;
    Ok(flat)
}

/// [`flatten`] at the surface's own size. A layout in which two faces of one piece overlap
/// is refused as the stage's own fault (issue 20, item 1): the unfolder and the chart
/// flattener cut or split where faces would overlap, so one left is a bug, never output.
fn flatten_as_is(surface: Surface, opts: &FlattenOptions) -> Result<Flat, FlattenError> {
    refuse_overlap(if surface.charts.is_some() {
        charts(surface, opts)?
    } else {
        unfold(surface, &opts.unfold)?
    })
}

/// `flat`, or the error naming its first two overlapping faces (see [`flatten_as_is`]).
fn refuse_overlap(flat: Flat) -> Result<Flat, FlattenError> {
    match super::unfold::find_overlap(&flat) {
        Some((f, g)) => Err(FlattenError::Overlap {
            surface: flat.surface.name.clone(),
            piece: flat.face_island[f] + 1,
            a: f + 1,
            b: g + 1,
        }),
        None => Ok(flat),
    }
}

/// A chart laid flat.
#[derive(Clone)]
struct Laid {
    faces: Vec<usize>,
    /// Edges cut open inside the chart (topology ids, sorted).
    cuts: Vec<usize>,
    uv: Vec<Vec<DVec2>>,
    stretch: Stretch,
    /// A gusset cut off a chart ([`gussets`]), to be re-attached to a neighbour if one fits.
    gusset: bool,
}

/// A chart waiting to be laid flat.
struct Todo {
    faces: Vec<usize>,
    /// Times split for stretch.
    splits: usize,
    /// Edges cut open inside it (sorted), inherited from the surface or a larger chart.
    cuts: Vec<usize>,
    /// Cut off a larger chart for overlapping it ([`cut_off`]): to be re-attached to a
    /// neighbour if one fits ([`reattach`]).
    cut_off: bool,
    /// What its layout starts from.
    start: Start,
}

/// What a chart's layout starts from: nothing (laid anew by the parameteriser), the layout of
/// a larger chart it is part of ([`Charts::lay_from`]), or a layout already made (a part cut
/// off: [`cut_off`] lays the parts to decide).
enum Start {
    Anew,
    Within(Arc<Whole>),
    Laid(Vec<Vec<DVec2>>, Stretch),
}

/// A chart's faces and their layout (per face corner), for its parts to start from.
struct Whole {
    /// (face, index into `uv`), sorted by face.
    index: Vec<(usize, usize)>,
    uv: Vec<Vec<DVec2>>,
}

impl Whole {
    fn new(faces: &[usize], uv: &[Vec<DVec2>]) -> Arc<Whole> {
        let mut index: Vec<(usize, usize)> = faces.iter().copied().zip(0..).collect();
        index.sort_unstable();
        Arc::new(Whole {
            index,
            uv: uv.to_vec(),
        })
    }

    /// The layout of `faces` (each one of the whole's), in their order.
    fn restrict(&self, faces: &[usize]) -> Option<Vec<Vec<DVec2>>> {
        faces
            .iter()
            .map(|&f| {
                let k = self.index.binary_search_by_key(&f, |x| x.0).ok()?;
                Some(self.uv[self.index[k].1].clone())
            })
            .collect()
    }
}

/// The error for a face that cannot be laid flat (shared by the threads that lay charts).
type Degenerate<'a> = dyn Fn(usize) -> FlattenError + Sync + 'a;

/// What [`Charts::lay`] made of a chart.
#[derive(Clone)]
enum Layout {
    Laid(Vec<Vec<DVec2>>, Stretch),
    /// The parameteriser refused it (not a disk, solver failure) or gave non-finite points.
    Refused,
}

/// The mesh and what every chart needs.
struct Charts<'a> {
    mesh: &'a Mesh,
    topo: &'a Topology,
    graph: &'a Graph,
    method: ParamMethod,
    /// Seams are matched ([`param::match_seams`]) on layouts whose L2 stretch is at most
    /// this: one over it is cut or split further, which matching would only delay.
    match_below: f64,
    /// Layouts already made, by (faces, cuts, whether seams were matched over the tolerance):
    /// a chart is often laid once to decide (a part cut off, a dart tried) and again when
    /// its turn comes; [`Charts::lay`] is a function of these, so the copy is the same.
    laid: &'a LayCache,
}

/// A mesh with what [`Charts`] borrows, for tests: `Fixture::new(mesh).charts(&opts)`.
#[cfg(test)]
pub(super) struct Fixture {
    pub(super) mesh: Mesh,
    pub(super) topo: Topology,
    pub(super) graph: Graph,
    laid: LayCache,
}

#[cfg(test)]
impl Fixture {
    pub(super) fn new(mesh: Mesh) -> Fixture {
        let topo = mesh.topology();
        let graph = Graph::new(&mesh, &topo);
        Fixture {
            mesh,
            topo,
            graph,
            laid: LayCache::default(),
        }
    }

    /// The charts of the mesh as `opts` lays them.
    fn charts(&self, opts: &FlattenOptions) -> Charts<'_> {
        Charts {
            mesh: &self.mesh,
            topo: &self.topo,
            graph: &self.graph,
            method: opts.method,
            match_below: opts.tolerance,
            laid: &self.laid,
        }
    }
}

#[cfg(test)]
impl Charts<'_> {
    /// `faces` laid out as one piece without cuts, for tests (panics where it cannot be).
    pub(super) fn piece(&self, faces: Vec<usize>) -> Laid {
        let Ok(Layout::Laid(uv, stretch)) = self.lay(&faces, &[]) else {
            panic!("faces {faces:?} not laid out");
        };
        Laid {
            faces,
            cuts: Vec::new(),
            uv,
            stretch,
            gusset: false,
        }
    }
}

/// A grid of cells on the plane in pieces, for tests: columns `0..20` of 10 mm (x from 0 to
/// 200 mm), row 0 a strip 1.5 mm high under the x axis, rows `1..11` of 10 mm above it; each
/// block (columns, rows) is a piece of two faces per cell, the pieces' faces numbered in turn
/// (their ranges returned).
#[cfg(test)]
pub(super) fn strip_and_squares(
    blocks: &[(std::ops::Range<usize>, std::ops::Range<usize>)],
) -> (Mesh, Vec<std::ops::Range<usize>>) {
    use glam::DVec3;
    let xs: Vec<f64> = (0..=20).map(|i| 10.0 * i as f64).collect();
    let ys: Vec<f64> = [-1.5]
        .into_iter()
        .chain((0..=10).map(|j| 10.0 * j as f64))
        .collect();
    let vertices: Vec<DVec3> = ys
        .iter()
        .flat_map(|&y| xs.iter().map(move |&x| DVec3::new(x, y, 0.0)))
        .collect();
    let v = |i: usize, j: usize| j * xs.len() + i;
    let (mut faces, mut ranges) = (Vec::new(), Vec::new());
    for (cols, rows) in blocks {
        let first = faces.len();
        for j in rows.clone() {
            for i in cols.clone() {
                let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                for verts in [vec![a, b, c], vec![a, c, d]] {
                    faces.push(Face { verts, line: None });
                }
            }
        }
        ranges.push(first..faces.len());
    }
    (Mesh { vertices, faces }, ranges)
}

/// The pieces of faces `ranges` of a mesh on the plane, laid as they lie, for tests.
#[cfg(test)]
fn as_they_lie(mesh: &Mesh, ranges: &[std::ops::Range<usize>]) -> Vec<Laid> {
    ranges
        .iter()
        .map(|r| {
            let faces: Vec<usize> = r.clone().collect();
            let uv: Vec<Vec<DVec2>> = faces
                .iter()
                .map(|&f| mesh.face_points(f).iter().map(|q| q.truncate()).collect())
                .collect();
            piece_as_laid(mesh, faces, uv)
        })
        .collect()
}

/// `faces` laid out as `uv` without cuts, their stretch measured, for tests.
#[cfg(test)]
fn piece_as_laid(mesh: &Mesh, faces: Vec<usize>, uv: Vec<Vec<DVec2>>) -> Laid {
    Laid {
        stretch: distortion::stretch(mesh, &faces, &uv),
        faces,
        cuts: Vec::new(),
        uv,
        gusset: false,
    }
}

/// A cone over a zigzag, for tests: ten flat sectors round an apex (vertex 0), each of 80°
/// there (800° in all), each an inner triangle (apex, ring 1) and two outer ones (ring 1 to
/// ring 2, twice as far out); faces `3 i .. 3 i + 3` are sector `i`.
#[cfg(test)]
pub(super) fn zigzag_cone() -> Mesh {
    use glam::DVec3;
    let step = std::f64::consts::TAU / 10.0;
    // Unit spokes alternately h above and below, 80° apart.
    let c = 80f64.to_radians().cos();
    let h = ((step.cos() - c) / (1.0 + c)).sqrt();
    let spoke = |i: usize| {
        let a = step * i as f64;
        DVec3::new(a.cos(), a.sin(), if i % 2 == 0 { h } else { -h })
    };
    let mut vertices = vec![DVec3::ZERO];
    for i in 0..10 {
        vertices.push(10.0 * spoke(i));
        vertices.push(20.0 * spoke(i));
    }
    let (r1, r2) = (|i: usize| 1 + 2 * (i % 10), |i: usize| 2 + 2 * (i % 10));
    let mut faces = Vec::new();
    for i in 0..10 {
        for verts in [
            vec![0, r1(i), r1(i + 1)],
            vec![r1(i), r2(i), r2(i + 1)],
            vec![r1(i), r2(i + 1), r1(i + 1)],
        ] {
            faces.push(Face { verts, line: None });
        }
    }
    Mesh { vertices, faces }
}

/// The layouts of [`Charts::laid`] by key, and the faces they hold in all.
type LayCache = std::sync::Mutex<(HashMap<(Vec<usize>, Vec<usize>, u64), Layout>, usize)>;

/// Faces the kept layouts may hold in all (about 80 bytes each); past it layouts are made
/// again instead of kept, so memory stays bounded on any mesh.
const LAY_CACHE_FACES: usize = 2_000_000;

impl Charts<'_> {
    /// The chart's faces opened along `cuts` and laid flat: the opened chart becomes a mesh of
    /// its own (vertices split along the cuts), parameterised, then turned counter-clockwise.
    fn lay(&self, faces: &[usize], cuts: &[usize]) -> Result<Layout, param::ParamError> {
        let key = (faces.to_vec(), cuts.to_vec(), self.match_below.to_bits());
        if let Some(l) = self.laid.lock().ok().and_then(|m| m.0.get(&key).cloned()) {
            return Ok(l);
        }
        let l = self.lay_anew(faces, cuts)?;
        if let Ok(mut m) = self.laid.lock() {
            if m.1 + faces.len() <= LAY_CACHE_FACES {
                m.1 += faces.len();
                m.0.insert(key, l.clone());
            }
        }
        Ok(l)
    }

    /// [`Charts::lay`] without the copies.
    fn lay_anew(&self, faces: &[usize], cuts: &[usize]) -> Result<Layout, param::ParamError> {
        let (local, ids) = self.opened(faces, cuts);
        let p = match param::parameterize_matched(&local, &ids, self.method, self.match_below) {
            Ok(p) => p,
            // A sliver triangle cannot be laid flat in any chart: say which (mesh numbering).
            Err(param::ParamError::Degenerate { face, line, angle }) => {
                return Err(param::ParamError::Degenerate {
                    face: faces.get(face).copied().unwrap_or(face),
                    line,
                    angle,
                })
            }
            Err(_) => return Ok(Layout::Refused),
        };
        Ok(self.finish(&local, &ids, p))
    }

    /// Part of a chart laid out from the whole chart's layout (see [`param::relax_from`]): the
    /// whole was laid anew, so its part starts near its own optimum and only needs relaxing.
    /// A part the whole's layout does not fit (corners of one vertex apart where the part has
    /// no cut, a flipped triangle) is laid anew ([`Charts::lay`]).
    pub(super) fn lay_from(
        &self,
        faces: &[usize],
        cuts: &[usize],
        whole: Option<&Whole>,
    ) -> Result<Layout, param::ParamError> {
        if let Some(start) = whole.and_then(|w| w.restrict(faces)) {
            let (local, ids) = self.opened(faces, cuts);
            if let Some(p) =
                param::relax_from_matched(&local, &ids, self.method, &start, self.match_below)
            {
                return Ok(self.finish(&local, &ids, p));
            }
        }
        self.lay(faces, cuts)
    }

    /// The chart's faces opened along `cuts` as a mesh of its own (vertices split along the
    /// cuts), and its faces' indices.
    fn opened(&self, faces: &[usize], cuts: &[usize]) -> (Mesh, Vec<usize>) {
        let op = open(self.mesh, self.topo, faces, &|e| {
            cuts.binary_search(&e).is_ok()
        });
        let local = Mesh {
            vertices: op.vertex.iter().map(|&v| self.mesh.vertices[v]).collect(),
            faces: faces
                .iter()
                .zip(op.corners)
                .map(|(&f, verts)| Face {
                    verts,
                    line: self.mesh.faces[f].line,
                })
                .collect(),
        };
        (local, (0..faces.len()).collect())
    }

    /// A layout as the charts keep it (its seams matched by [`param::parameterize_matched`]
    /// or [`param::relax_from_matched`] when it is within `match_below`): refused when not
    /// finite, counter-clockwise.
    fn finish(&self, local: &Mesh, ids: &[usize], p: param::ChartParam) -> Layout {
        let mut uv = p.uv;
        if uv.iter().any(|c| c.iter().any(|q| !q.is_finite())) {
            return Layout::Refused;
        }
        // Counter-clockwise, as the pattern stage expects.
        let total: f64 = uv.iter().map(|c| polygon::signed_area(c)).sum();
        let stretch = if total < 0.0 {
            for c in uv.iter_mut() {
                for q in c.iter_mut() {
                    q.x = -q.x;
                }
            }
            distortion::stretch(local, ids, &uv)
        } else {
            p.stretch
        };
        Layout::Laid(uv, stretch)
    }

    /// The 3D area of `faces`.
    fn area(&self, faces: &[usize]) -> f64 {
        faces.iter().map(|&f| self.graph.area[f]).sum()
    }

    /// The largest difference between a boundary edge's flat and 3D length, over the 3D
    /// length, in the layout `l` (edges on its border and along its cuts): 1e-5 or less where
    /// its seams were matched ([`param::match_seams`]), 0 where it was laid out exactly.
    fn seam_error(&self, l: &Laid) -> f64 {
        let mut inside = vec![false; self.mesh.faces.len()];
        for &f in &l.faces {
            inside[f] = true;
        }
        let mut worst: f64 = 0.0;
        for (&f, uv) in l.faces.iter().zip(&l.uv) {
            let verts = &self.mesh.faces[f].verts;
            let n = verts.len();
            for (j, &e) in self.topo.face_edges[f].iter().enumerate() {
                let joined = l.cuts.binary_search(&e).is_err()
                    && self.topo.edges[e].uses.len() == 2
                    && self.topo.edges[e].uses.iter().all(|u| inside[u.0]);
                if joined {
                    continue;
                }
                let d3 =
                    self.mesh.vertices[verts[j]].distance(self.mesh.vertices[verts[(j + 1) % n]]);
                if d3 > 0.0 {
                    worst = worst.max((uv[j].distance(uv[(j + 1) % n]) - d3).abs() / d3);
                }
            }
        }
        worst
    }

    /// Cuts that make the chart a disk: `cuts` when they do, else `cuts` with more
    /// ([`disk_cuts`]), else new ones from scratch; `None` when the chart must be split.
    fn disk(&self, faces: &[usize], cuts: &[usize]) -> Option<Vec<usize>> {
        let has = |e: usize| cuts.binary_search(&e).is_ok();
        if let Some(more) = disk_cuts(self.mesh, self.topo, self.graph, faces, &has) {
            let mut all = cuts.to_vec();
            all.extend(more);
            all.sort_unstable();
            all.dedup();
            return Some(all);
        }
        if cuts.is_empty() {
            return None;
        }
        disk_cuts(self.mesh, self.topo, self.graph, faces, &|_| false)
    }

    /// The parts of `l` as it lies: its faces (indices into `l.faces`) joined through edges
    /// that are not cut and whose two copies coincide, one sorted list per part, in the order
    /// of their first faces. One part, unless a layout was put together wrongly.
    fn flat_parts(&self, l: &Laid) -> Vec<Vec<usize>> {
        let mut at: HashMap<usize, usize> = HashMap::with_capacity(l.faces.len());
        for (i, &f) in l.faces.iter().enumerate() {
            at.insert(f, i);
        }
        let mut part = vec![usize::MAX; l.faces.len()];
        let mut parts = Vec::new();
        for first in 0..l.faces.len() {
            if part[first] != usize::MAX {
                continue;
            }
            part[first] = parts.len();
            let mut members = vec![first];
            let mut next = 0;
            while let Some(&a) = members.get(next) {
                next += 1;
                for &e in &self.topo.face_edges[l.faces[a]] {
                    let [(f, i), (g, j)] = self.topo.edges[e].uses[..] else {
                        continue;
                    };
                    let (Some(&x), Some(&y)) = (at.get(&f), at.get(&g)) else {
                        continue;
                    };
                    let b = if x == a { y } else { x };
                    if part[b] == usize::MAX
                        && l.cuts.binary_search(&e).is_err()
                        && coincide(&l.uv[x], i, &l.uv[y], j)
                    {
                        part[b] = parts.len();
                        members.push(b);
                    }
                }
            }
            members.sort_unstable();
            parts.push(members);
        }
        parts
    }

    /// `l` as the pieces it lies in ([`Charts::flat_parts`]): itself when it lies in one,
    /// else each part with its faces, corners and cuts, its stretch measured again.
    fn apart(&self, l: Laid) -> Vec<Laid> {
        let parts = self.flat_parts(&l);
        if parts.len() < 2 {
            return vec![l];
        }
        parts
            .into_iter()
            .map(|idx| {
                let faces: Vec<usize> = idx.iter().map(|&i| l.faces[i]).collect();
                let uv: Vec<Vec<DVec2>> = idx.iter().map(|&i| l.uv[i].clone()).collect();
                Laid {
                    cuts: self.cuts_within(&faces, &l.cuts),
                    stretch: distortion::stretch(self.mesh, &faces, &uv),
                    faces,
                    uv,
                    gusset: l.gusset,
                }
            })
            .collect()
    }

    /// The edges of `cuts` inside `faces` (both faces of the edge in it).
    fn cuts_within(&self, faces: &[usize], cuts: &[usize]) -> Vec<usize> {
        if cuts.is_empty() {
            return Vec::new();
        }
        let mut inside = vec![false; self.mesh.faces.len()];
        for &f in faces {
            inside[f] = true;
        }
        cuts.iter()
            .copied()
            .filter(|&e| self.topo.edges[e].uses.iter().all(|u| inside[u.0]))
            .collect()
    }

    /// The charts of `chart_of` to lay flat, in order, each with the surface's cuts inside it.
    fn initial(&self, chart_of: &[usize], surface_cuts: &[usize]) -> Vec<Todo> {
        let count = chart_of.iter().copied().max().map_or(0, |m| m + 1);
        let mut groups: Vec<Vec<usize>> = vec![Vec::new(); count];
        for (f, &c) in chart_of.iter().enumerate() {
            groups[c].push(f);
        }
        groups
            .into_iter()
            .filter(|g| !g.is_empty())
            .map(|faces| Todo {
                cuts: self.cuts_within(&faces, surface_cuts),
                faces,
                splits: 0,
                cut_off: false,
                start: Start::Anew,
            })
            .collect()
    }

    /// Lay one chart flat (see the module doc): cut into a disk and laid; split or cut where
    /// it overlaps itself or flips; darts, gussets and splits while over the tolerance. Halves
    /// and parts cut off go back onto `todo`, the chart laid and its gussets onto `done`.
    fn lay_one(
        &self,
        opts: &FlattenOptions,
        eps: f64,
        mut t: Todo,
        todo: &mut Vec<Todo>,
        done: &mut Vec<Laid>,
        degenerate: &Degenerate<'_>,
    ) -> Result<(), FlattenError> {
        let layout = match std::mem::replace(&mut t.start, Start::Anew) {
            // Laid to decide, its cuts already those of a disk.
            Start::Laid(uv, s) => Ok(Layout::Laid(uv, s)),
            start => {
                let Some(cuts) = self.disk(&t.faces, &t.cuts) else {
                    return self.split_or_fail(todo, &t, degenerate);
                };
                t.cuts = cuts;
                match start {
                    Start::Within(whole) => self.lay_from(&t.faces, &t.cuts, Some(&whole)),
                    _ => self.lay(&t.faces, &t.cuts),
                }
            }
        };
        let nf = self.mesh.faces.len();
        let layout = layout.map_err(|e| match e {
            param::ParamError::Degenerate { face, .. } => degenerate(face.min(nf - 1)),
            _ => degenerate(t.faces[0]),
        })?;
        let (uv, stretch) = match layout {
            Layout::Laid(uv, s) => (uv, s),
            Layout::Refused => return self.split_or_fail(todo, &t, degenerate),
        };
        if t.faces.len() > 1 {
            // Overlapping parts go to different pieces: split between the two faces.
            if let Some(pair) = self_overlap(&uv, eps) {
                let developable = stretch.l2 - 1.0 <= TUBE_CUT_OFF * (opts.tolerance - 1.0);
                if self.part_overlap(todo, &t, &uv, pair, eps, developable) {
                    return Ok(());
                }
            }
            if stretch.flipped > 0
                && self.split_in_two(todo, &t, t.splits, Some(Whole::new(&t.faces, &uv)))
            {
                return Ok(());
            }
        }
        self.relieve(opts, eps, t, uv, stretch, todo, done)
    }

    /// Each chart of `todo` in turn laid, then what it was split or cut into (in the order
    /// [`Charts::lay_one`] would pop them); what was laid, in that order. The charts are
    /// independent, so they are forked over the machine's cores ([`crate::geom::par`]), the
    /// halves of a split too; the result does not depend on how many cores there are. The
    /// first error in that order is returned.
    fn lay_trees(
        &self,
        opts: &FlattenOptions,
        eps: f64,
        todo: Vec<Todo>,
        degenerate: &Degenerate<'_>,
    ) -> Result<Vec<Laid>, FlattenError> {
        let tree = |t: Todo| -> Result<Vec<Laid>, FlattenError> {
            let (mut parts, mut done) = (Vec::new(), Vec::new());
            self.lay_one(opts, eps, t, &mut parts, &mut done, degenerate)?;
            parts.reverse();
            done.extend(self.lay_trees(opts, eps, parts, degenerate)?);
            Ok(done)
        };
        let sizes: Vec<usize> = todo.iter().map(|t| t.faces.len()).collect();
        let mut done = Vec::new();
        for r in crate::geom::par::map(todo, &sizes, &tree) {
            done.extend(r?);
        }
        Ok(done)
    }

    /// Split a chart that cannot be laid flat in two, or fail on a single face (or a chart
    /// that does not split).
    fn split_or_fail(
        &self,
        todo: &mut Vec<Todo>,
        t: &Todo,
        degenerate: &Degenerate<'_>,
    ) -> Result<(), FlattenError> {
        if t.faces.len() == 1 || !self.split_in_two(todo, t, t.splits, None) {
            return Err(degenerate(t.faces[0]));
        }
        Ok(())
    }

    /// Push the two halves of a chart (cuts kept where they fall inside a half), each to
    /// start from the `whole` chart's layout when there is one.
    fn push_halves(
        &self,
        todo: &mut Vec<Todo>,
        a: Vec<usize>,
        b: Vec<usize>,
        t: &Todo,
        splits: usize,
        whole: Option<Arc<Whole>>,
    ) {
        let (ca, cb) = (self.cuts_within(&a, &t.cuts), self.cuts_within(&b, &t.cuts));
        let start = || whole.clone().map_or(Start::Anew, Start::Within);
        todo.push(Todo {
            faces: b,
            splits,
            cuts: cb,
            cut_off: false,
            start: start(),
        });
        todo.push(Todo {
            faces: a,
            splits,
            cuts: ca,
            cut_off: false,
            start: start(),
        });
    }

    /// Push the halves of a chart split along the bisector of its two most distant faces
    /// (see [`Charts::push_halves`]); false when it does not split.
    fn split_in_two(
        &self,
        todo: &mut Vec<Todo>,
        t: &Todo,
        splits: usize,
        whole: Option<Arc<Whole>>,
    ) -> bool {
        let (a, b) = bisect(self.graph, &t.faces);
        if a.is_empty() || b.is_empty() {
            return false;
        }
        self.push_halves(todo, a, b, t, splits, whole);
        true
    }

    /// A chart whose layout `uv` overlaps itself at faces `(x, y)` (indices into its faces):
    /// halved when it was cut open into a disk (a tube, as a whole) and is not `developable`,
    /// else a small overlapping region cut off (§5.3, to be re-attached elsewhere), else
    /// halved when it is a tube, else split between the two faces. True when the parts went
    /// onto `todo`.
    ///
    /// A tube laid out with next to no stretch (`developable`: within [`TUBE_CUT_OFF`] of the
    /// tolerance) does not overlap because it spirals but because flanges that stand at a
    /// crease from its band fold over one another when laid flat (fandisk's side walls and
    /// the rims along them): cutting those off keeps the band whole, where halving it makes
    /// two pieces whose own flanges overlap again.
    fn part_overlap(
        &self,
        todo: &mut Vec<Todo>,
        t: &Todo,
        uv: &[Vec<DVec2>],
        (x, y): (usize, usize),
        eps: f64,
        developable: bool,
    ) -> bool {
        let tube = !t.cuts.is_empty();
        if tube && !developable && self.split_in_two(todo, t, t.splits, None) {
            return true;
        }
        // A small overlapping region is cut off (§5.3), to be re-attached elsewhere.
        let pairs = overlaps(uv, eps, OVERLAP_PAIRS);
        let (fx, fy) = (t.faces[x], t.faces[y]);
        if let Some((rest, parts)) =
            cut_off(self, &t.faces, &t.cuts, &[fx], &[fy], &pairs, uv, eps, true)
        {
            let off: f64 = parts.iter().map(|p| self.area(&p.faces)).sum();
            if off <= CUT_OFF_AREA * self.area(&t.faces) {
                for p in parts.into_iter().rev() {
                    todo.push(Todo {
                        faces: p.faces,
                        splits: t.splits,
                        cuts: p.cuts,
                        cut_off: true,
                        start: Start::Laid(p.uv, p.stretch),
                    });
                }
                todo.push(Todo {
                    faces: rest.faces,
                    splits: t.splits,
                    cuts: rest.cuts,
                    cut_off: t.cut_off,
                    start: Start::Laid(rest.uv, rest.stretch),
                });
                return true;
            }
        }
        if tube && self.split_in_two(todo, t, t.splits, None) {
            return true;
        }
        let (a, b) = split_between(self.graph, &t.faces, t.faces[x], t.faces[y]);
        if !a.is_empty() && !b.is_empty() {
            self.push_halves(todo, a, b, t, t.splits, Some(Whole::new(&t.faces, uv)));
            return true;
        }
        false
    }

    /// A chart laid flat as `uv` with `stretch`, over the tolerance: darts first, then
    /// gussets (onto `done`), then a split for stretch (its darts dropped: each half gets its
    /// own) while [`FlattenOptions::max_splits`] allows; else it is done as it is.
    #[allow(clippy::too_many_arguments)]
    fn relieve(
        &self,
        opts: &FlattenOptions,
        eps: f64,
        t: Todo,
        uv: Vec<Vec<DVec2>>,
        stretch: Stretch,
        todo: &mut Vec<Todo>,
        done: &mut Vec<Laid>,
    ) -> Result<(), FlattenError> {
        let inherited = t.cuts.clone();
        // The layout the halves of a split start from (before darts: they get their own).
        let first = (stretch.l2 > opts.tolerance).then(|| Whole::new(&t.faces, &uv));
        let mut laid = Laid {
            faces: t.faces,
            cuts: t.cuts,
            uv,
            stretch,
            gusset: t.cut_off,
        };
        if laid.stretch.l2 > opts.tolerance && opts.darts > 0 && laid.faces.len() >= DART_MIN_FACES
        {
            darts(self, &mut laid, opts, eps)?;
        }
        // A chart that can still be halved gets gussets only within their reach.
        let halves = t.splits < opts.max_splits && laid.faces.len() >= 8;
        if laid.stretch.l2 > opts.tolerance
            && opts.gussets > 0
            && laid.faces.len() >= DART_MIN_FACES
            && (!halves || laid.stretch.l2 - 1.0 <= GUSSET_REACH * (opts.tolerance - 1.0))
        {
            let gussets = gussets(self, &mut laid, opts, eps);
            done.extend(gussets);
        }
        if laid.stretch.l2 > opts.tolerance && halves {
            // Darts are dropped: each half gets its own.
            let t = Todo {
                faces: laid.faces,
                splits: t.splits,
                cuts: inherited,
                cut_off: t.cut_off,
                start: Start::Anew,
            };
            if self.split_in_two(todo, &t, t.splits + 1, first) {
                return Ok(());
            }
            laid.faces = t.faces;
        }
        // Too curved for its size: laid out exactly, its islands the pieces.
        if laid.stretch.l2 > opts.tolerance && opts.exact {
            if let Some(islands) = exact::exact(self, &laid.faces, eps) {
                done.extend(islands);
                return Ok(());
            }
        }
        done.push(laid);
        Ok(())
    }
}

/// Lay each chart flat as one island (cutting and splitting where needed, see the module
/// doc).
pub fn charts(surface: Surface, opts: &FlattenOptions) -> Result<Flat, FlattenError> {
    crate::geom::par::within(|| charts_in_pool(surface, opts))
}

/// [`charts`] on a thread of the pool ([`crate::geom::par::within`]).
fn charts_in_pool(surface: Surface, opts: &FlattenOptions) -> Result<Flat, FlattenError> {
    let mesh = &surface.mesh;
    let nf = mesh.faces.len();
    let chart_of = match &surface.charts {
        Some(c) if c.len() == nf => c.clone(),
        _ => vec![0; nf],
    };
    let topology = mesh.topology();
    let graph = Graph::new(mesh, &topology);
    let ctx = Charts {
        mesh,
        topo: &topology,
        graph: &graph,
        method: opts.method,
        match_below: opts.tolerance,
        laid: &LayCache::default(),
    };
    let surface_cuts = edge_ids(&topology, &surface.cuts);
    let todo = ctx.initial(&chart_of, &surface_cuts);
    // Overlaps shallower than the unfolder's tolerance count as touching, as in `unfold`.
    let overlap_eps = opts.unfold.tolerance.min(0.01 * mean_edge(mesh, &topology));
    let degenerate = |f: usize| FlattenError::Degenerate {
        surface: surface.name.clone(),
        face: f + 1,
        line: mesh.faces[f].line,
    };
    let mut done = ctx.lay_trees(opts, overlap_eps, todo, &degenerate)?;
    reattach(&ctx, &mut done, opts, overlap_eps);
    room::fit_room(&ctx, &mut done, opts, overlap_eps, &degenerate)?;
    // The trials that failed on pairs of pieces as they are, for every stage below: a trial
    // is a function of the two pieces, so a pair no stage has changed since fails again.
    let failed = overlap::Failed::default();
    merge::merge_small(&ctx, &mut done, opts, overlap_eps, &failed);
    merge::merge_near(&ctx, &mut done, opts, overlap_eps);
    merge::merge_laid(&ctx, &mut done, opts, overlap_eps);
    hinge::hinge_small(&ctx, &mut done, opts, overlap_eps, &failed);
    // Every piece lies in one part: one put together in two would be cut and nested as two
    // outlines in one (a guard, as `refuse_overlap` is).
    done = done.into_iter().flat_map(|l| ctx.apart(l)).collect();
    // A chart left over the tolerance gets its seams matched all the same; one whose matched
    // layout would overlap or flip is halved instead, its halves laid again (a few rounds).
    let all = Charts {
        match_below: f64::INFINITY,
        ..ctx
    };
    for _ in 0..MATCH_ROUNDS {
        let mut todo = Vec::new();
        let mut keep = Vec::with_capacity(done.len());
        for mut l in done.drain(..) {
            if l.stretch.l2 <= opts.tolerance && ctx.seam_error(&l) <= opts.seam_tolerance {
                keep.push(l);
                continue;
            }
            let whole = Whole::new(&l.faces, &l.uv);
            if let Ok(Layout::Laid(uv, s)) = all.lay_from(&l.faces, &l.cuts, Some(&whole)) {
                let was = (std::mem::replace(&mut l.uv, uv), l.stretch);
                l.stretch = s;
                if s.flipped <= was.1.flipped
                    && ctx.seam_error(&l) <= opts.seam_tolerance
                    && self_overlap(&l.uv, overlap_eps).is_none()
                {
                    keep.push(l);
                    continue;
                }
                (l.uv, l.stretch) = was;
            }
            let t = Todo {
                faces: l.faces.clone(),
                splits: opts.max_splits,
                cuts: l.cuts.clone(),
                cut_off: false,
                start: Start::Anew,
            };
            if l.faces.len() < 2 || !ctx.split_in_two(&mut todo, &t, opts.max_splits, Some(whole)) {
                keep.push(l);
            }
        }
        done = keep;
        if todo.is_empty() {
            break;
        }
        // Popped last to first, as the halves were pushed.
        todo.reverse();
        done.extend(ctx.lay_trees(opts, overlap_eps, todo, &degenerate)?);
    }
    Ok(assemble(surface, topology, done, opts))
}

/// Whether the edge at corner `i` of a face laid at `a` and the edge at corner `j` of the face
/// across it, laid at `b` (which runs it the other way round), lie at one place: the two
/// copies of a joined edge (to 1e-9, relative to the distance from the origin).
fn coincide(a: &[DVec2], i: usize, b: &[DVec2], j: usize) -> bool {
    let (p, q) = (a[i], a[(i + 1) % a.len()]);
    let (q0, p0) = (b[j], b[(j + 1) % b.len()]);
    let tol = 1e-9 * (1.0 + p.length().max(q.length()));
    p.distance(p0) <= tol && q.distance(q0) <= tol
}

/// The mean 3D length of a mesh's edges.
fn mean_edge(mesh: &Mesh, topology: &Topology) -> f64 {
    topology
        .edges
        .iter()
        .map(|e| mesh.vertices[e.verts[0]].distance(mesh.vertices[e.verts[1]]))
        .sum::<f64>()
        / topology.edges.len().max(1) as f64
}

/// Stretch of each island of a flat, and of the whole (area-weighted), from its layout.
pub fn stretch(flat: &Flat) -> (Vec<Stretch>, Stretch) {
    let per: Vec<Stretch> = flat
        .islands
        .iter()
        .map(|faces| stretch_of(flat, faces))
        .collect();
    let whole = distortion::combine(&per);
    (per, whole)
}

/// Stretch of some faces of a flat (a piece, or a part of one) as laid out.
pub fn stretch_of(flat: &Flat, faces: &[usize]) -> Stretch {
    let uv: Vec<Vec<DVec2>> = faces.iter().map(|&f| flat.face_2d[f].clone()).collect();
    distortion::stretch(&flat.surface.mesh, faces, &uv)
}

/// A global overlap is cut off ([`overlap::cut_off`]) when the part cut off has at most this fraction
/// of the chart's area; a larger one splits the chart between the two overlapping faces.
const CUT_OFF_AREA: f64 = 0.25;

/// A tube (a chart cut open into a disk) whose layout overlaps itself has the overlapping
/// region cut off like any chart, instead of being halved, when its L2 stretch exceeds 1 by at
/// most this share of the tolerance's (see [`Charts::part_overlap`]).
const TUBE_CUT_OFF: f64 = 0.1;

/// Rounds of matching the seams of charts left over the tolerance (halving those whose
/// matched layout overlaps or flips) after all charts are laid.
const MATCH_ROUNDS: usize = 3;

#[cfg(test)]
mod tests {
    use super::*;

    /// Two faces of one piece laid over each other: refused, naming the surface, the piece and
    /// both faces; laid apart, the flat passes (its exit code: `robust::a_flatten_overlap_is_a_bug`).
    #[test]
    fn an_overlapping_piece_is_refused_as_a_bug() {
        let cube = crate::flatten::unfold::tests::cube(10.0);
        let mut flat = unfold(cube, &crate::flatten::UnfoldOptions::default()).unwrap();
        assert!(refuse_overlap(flat.clone()).is_ok());
        let island = flat.face_island[0];
        let g = (1..flat.face_2d.len())
            .find(|&g| flat.face_island[g] == island)
            .unwrap();
        flat.face_2d[g] = flat.face_2d[0].clone();
        let e = refuse_overlap(flat).unwrap_err();
        let text = e.to_string();
        assert!(text.contains(&format!("faces 1 and {}", g + 1)), "{text}");
        assert!(text.contains(&format!("piece {}", island + 1)), "{text}");
    }

    /// A piece lies in one part; one whose faces are joined only through a cut, or through an
    /// edge whose two copies lie apart, is taken apart into the pieces it lies in, each with
    /// its faces, corners, cuts and stretch.
    #[test]
    fn a_piece_laid_in_two_places_is_taken_apart() {
        let (mesh, blocks) = strip_and_squares(&[(0..2, 1..2)]);
        let fx = Fixture::new(mesh);
        let ctx = fx.charts(&FlattenOptions::default());
        let whole = ctx.piece(blocks[0].clone().collect());
        assert_eq!(ctx.flat_parts(&whole), vec![vec![0, 1, 2, 3]]);
        assert_eq!(ctx.apart(whole.clone()).len(), 1);
        // Cells 0 and 1 meet along one edge: faces 0 (cell 0) and 3 (cell 1).
        let between = fx.topo.face_edges[0]
            .iter()
            .copied()
            .find(|&e| fx.topo.edges[e].uses.iter().any(|u| u.0 == 3))
            .expect("common edge");
        let mut slit = whole.clone();
        slit.cuts = vec![between];
        let mut moved = whole.clone();
        for p in moved.uv[2..].iter_mut().flatten() {
            *p += DVec2::new(0.0, 50.0);
        }
        for l in [slit, moved] {
            assert_eq!(ctx.flat_parts(&l), vec![vec![0, 1], vec![2, 3]]);
            let parts = ctx.apart(l.clone());
            assert_eq!(parts.len(), 2);
            for (part, faces) in parts.iter().zip([[0, 1], [2, 3]]) {
                assert_eq!(part.faces, faces);
                assert_eq!(part.uv, faces.map(|f| l.uv[f].clone()));
                assert!(part.cuts.is_empty());
                assert!((part.stretch.l2 - 1.0).abs() < 1e-9, "{}", part.stretch.l2);
            }
        }
    }
}
