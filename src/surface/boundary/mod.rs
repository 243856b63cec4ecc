//! Developable surfaces from a closed 3D boundary (Rose, Sheffer, Wither, Cani, Thibert 2007,
//! seed 000): a *boundary triangulation* of the input polyline — triangles over its vertices
//! only, no interior vertices, manifold, its boundary exactly the polyline — chosen so that
//! most interior edges are locally convex (it approximates a smooth developable), every
//! dihedral angle is below a threshold (smooth), with few interior triangles (predictable) and
//! a small sum of squared dihedral angles (fair). Being a boundary triangulation, it unfolds
//! exactly (the flatten stage keeps every edge length).
//!
//! The paper's steps, one file each:
//!
//! - `checks`: the input polyline as the paper assumes it (closed, simple, finite).
//! - `darts`: §6.1 darts, inserted into their loop as two coinciding sides.
//! - `loops`: §6 several loops (connecting charts, rulings between loops, the shortest tree)
//!   and §6.1 rulings within a loop, giving the regions to search.
//! - `search`: each region searched (§5) with the §7 radial offset, then relaxed limits and
//!   the fallbacks; the alternatives.
//! - `bnb`: §5 branch-and-bound over covers (Fig. 9), potential §5.1.2.
//! - `charts`: §3 charts, envelopes and subloops of a subloop's hull (cached).
//! - `bounds`: §5.1.1 cover quality, the lower bound that prunes the search.
//! - `figures`: §4 metrics of a finished triangulation and the output mesh.
//! - `planar`: a planar loop, which needs no search (the flat polygon it bounds).
//!
//! # Choices where the paper is silent
//!
//! - Orientation: every triangle is wound in the loop's cyclic order of its three vertices
//!   (in a boundary triangulation of a disk that is the only consistent winding), so a hull
//!   triangle is "oriented consistently" when its outward winding is that order, or all of the
//!   chart's are the reverse. Subloops are computed combinatorially (the chords of a convex
//!   polygon), so they are always simple.
//! - The flat piece of a surface with holes: the flatten stage unfolds it face by face. If a
//!   hole's loop closes up in the plane (a planar panel, or any panel whose surface around
//!   the hole is developable as a disk) the piece is one piece with the hole cut out, which
//!   is what a cutter user wants (no slit to tape). A band around a hole that cannot lie flat
//!   closed (a lamp collar: a cone-like band) is cut open along one edge by the unfolder
//!   (where joining is cheapest) into one piece with a slit there, the seam the user glues:
//!   that is unavoidable, since no flat piece without a cut has that shape.
//! - Alternatives: every distinct complete triangulation met is kept; the N best are returned.

mod bnb;
mod bounds;
mod charts;
mod checks;
mod darts;
mod figures;
mod loops;
mod planar;
mod search;

use crate::geom::mesh::Mesh;
use glam::DVec3;
use loops::prepare;
use search::search;
use std::time::Instant;

/// Search settings; see the module doc.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Largest dihedral angle allowed across an interior edge, degrees.
    pub max_dihedral_deg: f64,
    /// Smallest chart, as a fraction of its hull's area (paper: 0.01–0.03).
    pub min_chart_area: f64,
    /// Good enough: at most this many interior triangles…
    pub good_interior: usize,
    /// …and at most this sum of squared dihedral angles (radians²).
    pub good_fairness: f64,
    /// Branch-and-bound iterations at most (per region split by rulings).
    pub max_iterations: usize,
    /// §7 radial offset, relative to the mean distance from the centre of mass.
    pub offset: f64,
    /// How many best distinct triangulations to return (at least 1).
    pub alternatives: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_dihedral_deg: 60.0,
            min_chart_area: 0.02,
            good_interior: 0,
            good_fairness: 0.0,
            max_iterations: 1000,
            offset: 0.1,
            alternatives: 1,
        }
    }
}

/// A dart: from point `at` of loop `looop` (both 0-based) through `points`, the last one being
/// the tip.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Dart {
    pub looop: usize,
    pub at: usize,
    pub points: Vec<DVec3>,
    /// Opening at the mouth, mm, used only when the coincident sides cannot be triangulated
    /// (and for the hulls); `None`: 2 % of the dart's length.
    pub width: Option<f64>,
}

/// The boundary: closed loops (the first outer), darts and rulings on any loop.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Input {
    pub loops: Vec<Vec<DVec3>>,
    pub darts: Vec<Dart>,
    /// Edges the result must contain: pairs of (loop, point), 0-based, points counted before
    /// darts are inserted. Between two points of one loop a ruling splits the region; between
    /// two loops it joins them.
    pub rulings: Vec<[(usize, usize); 2]>,
}

/// Predictability then fairness; lower is better.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Quality {
    interior: usize,
    fairness: f64,
}

impl Quality {
    /// Strictly better: fewer interior triangles, or as many and less fairness (1e-12 slack).
    fn better(&self, o: &Quality) -> bool {
        self.interior < o.interior
            || (self.interior == o.interior && self.fairness < o.fairness - 1e-12)
    }
}

/// Figures of a result, for `report.json`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Figures {
    pub triangles: usize,
    pub interior_triangles: usize,
    pub interior_edges: usize,
    pub convex_edges: usize,
    pub largest_dihedral_deg: f64,
    pub fairness: f64,
    pub iterations: usize,
    pub seconds: f64,
    /// Hull charts that joined loops (§6).
    pub connecting_charts: usize,
    /// Edges that joined loops: rulings between loops and the shortest tree (§6).
    pub joining_edges: usize,
}

impl Figures {
    /// Fraction of interior edges that are locally convex (1 with no interior edge).
    pub fn convex_fraction(&self) -> f64 {
        if self.interior_edges == 0 {
            1.0
        } else {
            self.convex_edges as f64 / self.interior_edges as f64
        }
    }
}

/// The triangulation and what was found on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    pub mesh: Mesh,
    pub figures: Figures,
    /// The next best distinct triangulations (same vertices), best first.
    pub alternatives: Vec<Mesh>,
    pub warnings: Vec<String>,
}

/// What is wrong with a boundary. Loops, points, rulings and darts are 0-based here, as in
/// [`Input`]; the messages count them from 1 as users do.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BoundaryError {
    #[error("no boundary loop given")]
    NoLoop,
    #[error("loop {}: needs at least 3 points, got {got}", .looop + 1)]
    TooFew { looop: usize, got: usize },
    #[error("loop {}: point {} has a coordinate that is not a finite number", .looop + 1, .point + 1)]
    NonFinite { looop: usize, point: usize },
    #[error("loop {}: point {} repeats point {} (consecutive points must differ)", .looop + 1, .point + 1, .prev + 1)]
    Repeated {
        looop: usize,
        point: usize,
        prev: usize,
    },
    #[error("loop {}: the polyline is open; a boundary must be a closed loop", .looop + 1)]
    Open { looop: usize },
    #[error("the boundary crosses itself: segment {} (points {}–{} of loop {}) meets segment {} (points {}–{} of loop {}) near ({x:.3}, {y:.3}, {z:.3})", .a + 1, .a + 1, .a1 + 1, .la + 1, .b + 1, .b + 1, .b1 + 1, .lb + 1)]
    SelfIntersecting {
        la: usize,
        a: usize,
        a1: usize,
        lb: usize,
        b: usize,
        b1: usize,
        x: f64,
        y: f64,
        z: f64,
    },
    #[error("ruling {}: {message}", .index + 1)]
    Ruling { index: usize, message: String },
    #[error("dart {}: {message}", .index + 1)]
    Dart { index: usize, message: String },
    #[error("several loops: {0}")]
    Loops(String),
    #[error("no valid boundary triangulation found (a dart or a joining edge folds the surface onto itself); raise max_dihedral, lower min_chart_area, or add rulings")]
    NoTriangulation,
}

/// Check a boundary without searching: loops, darts, crossings, rulings.
pub fn check(input: &Input) -> Result<(), BoundaryError> {
    prepare(input, &Options::default(), false).map(|_| ())
}

/// Triangulate a boundary (see the module doc).
pub fn triangulate(input: &Input, opts: &Options) -> Result<Output, BoundaryError> {
    let t0 = Instant::now();
    let prep = prepare(input, opts, false)?;
    if let Some(mut out) = planar::planar(input, &prep) {
        out.figures.seconds = t0.elapsed().as_secs_f64();
        return Ok(out);
    }
    let relaxed = |o: &Output| o.warnings.iter().any(|w| w.starts_with(RELAXED));
    let (out, ok) = search(prep, opts, t0);
    if ok && (input.darts.is_empty() || !relaxed(&out)) {
        return Ok(out);
    }
    if !input.darts.is_empty() {
        // The fallback: darts opened into a narrow V, when the coincident sides gave no valid
        // triangulation or only one over the limits and the V gives one within them.
        let prep = prepare(input, opts, true)?;
        let (mut open, open_ok) = search(prep, opts, t0);
        if open_ok && (!ok || !relaxed(&open)) {
            open.warnings.insert(
                0,
                "the darts could not be triangulated within the limits with their two sides coinciding: they were opened into a narrow V (`width`, default 2 % of the dart's length)".into(),
            );
            open.figures.seconds = t0.elapsed().as_secs_f64();
            return Ok(open);
        }
    }
    if ok {
        return Ok(out);
    }
    Err(BoundaryError::NoTriangulation)
}

/// How the warning that the limits were relaxed starts.
const RELAXED: &str = "no triangulation with every dihedral angle under";
/// A chart of a subloop's convex hull (§3): its triangles (indices into the search's points)
/// and its area. Shared by the chart finder ([`charts`]) and the search ([`bnb`]).
struct Chart {
    tris: Vec<[usize; 3]>,
    area: f64,
}

/// What a subloop's hull offers the search: its envelopes and the charts (indices into the
/// search's chart list) found on it.
#[derive(Default)]
struct Sub {
    envelopes: Vec<Vec<[usize; 3]>>,
    charts: Vec<usize>,
}
