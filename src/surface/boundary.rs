//! Developable surfaces from a closed 3D boundary (Rose, Sheffer, Wither, Cani, Thibert 2007,
//! seed 000): a *boundary triangulation* of the input polyline — triangles over its vertices
//! only, no interior vertices, manifold, its boundary exactly the polyline — chosen so that
//! most interior edges are locally convex (it approximates a smooth developable), every
//! dihedral angle is below a threshold (smooth), with few interior triangles (predictable) and
//! a small sum of squared dihedral angles (fair). Being a boundary triangulation, it unfolds
//! exactly (the flatten stage keeps every edge length).
//!
//! # What follows the paper
//!
//! - §3 charts: on the convex hull ([`crate::geom::hull`]) of a (sub)loop, a chart is a
//!   connected set of hull triangles that (1) share edges with each other, (2) each have an
//!   edge on the loop, (3) all run the same way as the loop. Subtracting charts from the loop
//!   leaves subloops; a subloop that lies on its hull splits it into two *envelopes*.
//! - §4/§5.1 metrics: smoothness (largest dihedral angle below `max_dihedral`), predictability
//!   (interior triangles: no edge on the input polyline), fairness (sum of squared dihedral
//!   angles over interior edges). Triangulations and covers compare predictability first, then
//!   fairness. A cover's quality is a lower bound: its own interior triangles plus one per
//!   subloop touching more than two of its charts; its own squared angles plus, per subloop
//!   touching two or more charts, `(α₁ + α₂)² / (n − 1)` with αᵢ the angle between the
//!   subloop's plane and the nearest triangle of the first two charts (by id: the paper's
//!   "random pair", made deterministic).
//! - §5 branch-and-bound, Fig. 9: a priority queue of covers ordered by potential (§5.1.2:
//!   fewer charts first, then the larger largest chart), seeded with the empty cover; pop,
//!   discard when the best triangulation is at least as good as the cover's bound, subtract,
//!   take the best smooth choice of envelopes when every subloop has them, extend the cover by
//!   every valid chart of every subloop hull (refusing charts whose angle with the cover is
//!   over the threshold), and queue it unless a queued subset is at least as good (a better
//!   superset replaces the subset). Charts must be smooth inside, smooth against the
//!   neighbouring interior hull triangles, and at least `min_chart_area` of their hull's area.
//!   Stop when the best is good enough (`good_interior`, `good_fairness`), the queue is empty,
//!   or after `max_iterations` (the paper: "less than a thousand for all the models").
//!   A hull without any valid chart makes each of its triangles a chart (the pathological case).
//! - §6 darts, several loops (connecting charts first, else the shortest tree), rulings,
//!   alternatives; §7 B-spline smoothing and radial offset.
//!
//! # Choices where the paper is silent
//!
//! - Orientation: every triangle is wound in the loop's cyclic order of its three vertices
//!   (in a boundary triangulation of a disk that is the only consistent winding), so a hull
//!   triangle is "oriented consistently" when its outward winding is that order, or all of the
//!   chart's are the reverse. Subloops are computed combinatorially (the chords of a convex
//!   polygon), so they are always simple.
//! - §7 radial offset: hulls and charts are computed on points moved `offset` (default 0.1) ×
//!   their mean distance from the centre of mass C, radially away from C; the triangulation is
//!   then built on the input points, and all angles are measured there. The boundary stays
//!   exactly the input. Smoothing (`smooth = true` in the spec) resamples a closed cubic
//!   B-spline through the points instead, and then the boundary is the resampled curve.
//! - Chart area threshold: relative to the hull of the subloop being split (deeper subloops
//!   are small; against the top hull they would never have charts).
//! - Subloop plane for the fairness bound: Newell's normal through the centroid.
//! - Darts (§6.1): a dart is a polyline from a loop point (of any loop) to its tip, inserted
//!   twice with reversed orientation into its loop: the loop point and the dart's points are
//!   duplicated (left copy, tip once, right copy), and the two copies *coincide* in 3D — the
//!   sewn dart. The triangulation treats them as two boundary sections, so the flat piece
//!   opens them into the V that a pattern cuts out. Coinciding points break hulls and local
//!   convexity predicates, so, as the §7 radial offset does, hulls are computed on perturbed
//!   points only: the copies opened into a narrow V (at the mouth `width`, default 2 % of the
//!   dart's length, along the boundary, narrowing to the tip); triangles and all angles use
//!   the real points. A triangle with two copies of one point, a triangle without area, or
//!   an edge in space used by more than two triangles (the surface folded onto itself around
//!   the tip) is refused in charts, envelopes, covers and results. Should the coinciding
//!   sides give no valid triangulation, or only one over the limits while the V gives one
//!   within them, the darts are opened into that V for real and a warning says so (the old
//!   behaviour, kept only as this fallback; with neither valid the result is an error). A
//!   dart tip that lies off the surface the rest of the boundary asks for (the dart takes
//!   fabric in) is what makes the flat V open; a tip barely off it can need the fallback.
//! - Several loops (§6): the first loop is the outer one, the others holes (reversed if their
//!   Newell normal agrees with the outer's, so that the surface lies left of every loop).
//!   First, charts that connect loops: on the hull of all the loops' points (radial offset
//!   applied) charts are found as in §3 — triangles with an input edge, all wound like the
//!   loops, joined across edges that are not loop edges — and a chart is *connecting* when it
//!   touches two loops or more. The validity conditions are those of single charts (smooth
//!   inside and against the neighbouring interior hull triangles, at least `min_chart_area`
//!   of the hull), plus, adapted to several loops: its subtraction must leave simple loops
//!   with each touched loop entered once (so they merge into one loop, or vanish when the
//!   chart covers the band between them, as on a lamp collar), and keep every ruling
//!   possible. The largest valid one is taken (the paper does not say which: the largest is
//!   the §5.1.2 potential's choice), subtracted, and the search for connecting charts is
//!   repeated on the loops left; its triangles are part of the result. Then the user's
//!   rulings between loops join them, then the *shortest tree* of connecting edges: Kruskal
//!   over all vertex pairs of different loops by length, skipping an edge that comes within
//!   1e-9 × the size of a loop edge, a chart edge, a ruling or an earlier tree edge (in
//!   space; this is exact for planar panels), or that shares an end with another joining
//!   edge or a ruling. A joining edge `a b` is walked both ways (… a, b, around the hole, b,
//!   a, …): the search sees `a` and `b` twice, as two copies nudged apart for the hulls only
//!   (1 % of the shorter of the joining edge and their loop edge, along the loop edge), and
//!   the same validity test refuses triangles that would use the edge or a vertex twice. In
//!   the result both copies are one vertex, so the joining edge is an ordinary interior edge
//!   with a triangle on each side: the mesh is a disk with holes (Euler characteristic
//!   1 − holes), its boundary exactly the input loops. Joining edges and chart rims are
//!   treated as interior edges for chart extraction (§6.1). The dihedral angles across a
//!   connecting chart's rim are measured in the figures but not bounded by the search of the
//!   region next to it.
//! - Rulings (§6.1) name points of any loop. Between two loops a ruling is a joining edge
//!   (taken before the shortest tree); within the joined loop it is a constraint edge that
//!   splits it into regions searched separately.
//! - The flat piece of a surface with holes: the flatten stage unfolds it face by face. If a
//!   hole's loop closes up in the plane (a planar panel, or any panel whose surface around
//!   the hole is developable as a disk) the piece is one piece with the hole cut out, which
//!   is what a cutter user wants (no slit to tape). A band around a hole that cannot lie flat
//!   closed (a lamp collar: a cone-like band) is cut open along one edge by the unfolder
//!   (where joining is cheapest) into one piece with a slit there, the seam the user glues:
//!   that is unavoidable, since no flat piece without a cut has that shape.
//! - Alternatives: every distinct complete triangulation met is kept; the N best are returned.
//! - The radial offset is skipped when it leaves fewer loop edges on the hull than the input
//!   points do (a scalloped edge near the centre of mass sinks inside its hull when pushed).
//! - When no smooth triangulation exists within the limits, the search is run again with the
//!   thresholds relaxed (180°, no area limit) and a warning says so; if even that finds
//!   nothing in `max_iterations`, the cover is completed depth first (the largest chart of
//!   each subloop without envelopes, at most n steps), with a warning; a fan from the first
//!   vertex is the last resort (a subloop whose hull is flat but folded over itself).

use crate::geom::hull::{self, segment_on_hull};
use crate::geom::mesh::{Face, Mesh};
use glam::{DVec2, DVec3};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::rc::Rc;
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
pub struct Quality {
    pub interior: usize,
    pub fairness: f64,
}

impl Quality {
    /// Strictly better: fewer interior triangles, or as many and less fairness (1e-12 slack).
    pub fn better(&self, o: &Quality) -> bool {
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

/// What is wrong with a boundary; loops and points counted from 1 as users count them.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BoundaryError {
    #[error("no boundary loop given")]
    NoLoop,
    #[error("loop {looop}: needs at least 3 points, got {got}")]
    TooFew { looop: usize, got: usize },
    #[error("loop {looop}: point {point} has a coordinate that is not a finite number")]
    NonFinite { looop: usize, point: usize },
    #[error("loop {looop}: point {point} repeats point {prev} (consecutive points must differ)")]
    Repeated {
        looop: usize,
        point: usize,
        prev: usize,
    },
    #[error("loop {looop}: the polyline is open; a boundary must be a closed loop")]
    Open { looop: usize },
    #[error("the boundary crosses itself: segment {a} (points {a}–{a1} of loop {la}) meets segment {b} (points {b}–{b1} of loop {lb}) near ({x:.3}, {y:.3}, {z:.3})")]
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
    #[error("ruling {index}: {message}")]
    Ruling { index: usize, message: String },
    #[error("dart {index}: {message}")]
    Dart { index: usize, message: String },
    #[error("several loops: {0}")]
    Loops(String),
    #[error("no valid boundary triangulation found (a dart or a joining edge folds the surface onto itself); raise max_dihedral, lower min_chart_area, or add rulings")]
    NoTriangulation,
}

// ---------------------------------------------------------------------------------------------
// Checks and preparation
// ---------------------------------------------------------------------------------------------

/// Check loops: at least three finite points, no repeated consecutive points (the last one
/// against the first included).
pub fn check_loops(loops: &[Vec<DVec3>]) -> Result<(), BoundaryError> {
    if loops.is_empty() {
        return Err(BoundaryError::NoLoop);
    }
    for (l, pts) in loops.iter().enumerate() {
        if let Some(i) = pts.iter().position(|p| !p.is_finite()) {
            return Err(BoundaryError::NonFinite {
                looop: l + 1,
                point: i + 1,
            });
        }
        if pts.len() < 3 {
            return Err(BoundaryError::TooFew {
                looop: l + 1,
                got: pts.len(),
            });
        }
        let scale = size(pts);
        for i in 0..pts.len() {
            let j = (i + 1) % pts.len();
            if pts[i].distance(pts[j]) <= 1e-9 * scale.max(1e-300) {
                return Err(BoundaryError::Repeated {
                    looop: l + 1,
                    point: j + 1,
                    prev: i + 1,
                });
            }
        }
    }
    Ok(())
}

fn size(p: &[DVec3]) -> f64 {
    let Some(first) = p.first() else { return 0.0 };
    let (lo, hi) = p
        .iter()
        .fold((*first, *first), |(lo, hi), q| (lo.min(*q), hi.max(*q)));
    (hi - lo).length()
}

/// Distance between segments `p0 p1` and `q0 q1`, and the midpoint of the closest pair.
fn segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> (f64, DVec3) {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let (s, t);
    if a <= 1e-300 && e <= 1e-300 {
        return (p0.distance(q0), 0.5 * (p0 + q0));
    }
    if a <= 1e-300 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= 1e-300 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 1e-12 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    let cp = p0 + d1 * s;
    let cq = q0 + d2 * t;
    (cp.distance(cq), 0.5 * (cp + cq))
}

/// Check that no two non-adjacent segments of the loops come closer than 1e-9 × the size.
/// `labels[l][i]` is the user's (loop, point) name of point `i` of loop `l`.
fn check_crossings(
    loops: &[Vec<DVec3>],
    labels: &[Vec<(usize, usize)>],
) -> Result<(), BoundaryError> {
    let all: Vec<DVec3> = loops.iter().flatten().copied().collect();
    let tol = 1e-9 * size(&all);
    let segs: Vec<(usize, usize, DVec3, DVec3)> = loops
        .iter()
        .enumerate()
        .flat_map(|(l, p)| (0..p.len()).map(move |i| (l, i, p[i], p[(i + 1) % p.len()])))
        .collect();
    // Bounding boxes to skip far pairs cheaply.
    let boxes: Vec<(DVec3, DVec3)> = segs
        .iter()
        .map(|s| {
            (
                s.2.min(s.3) - DVec3::splat(tol),
                s.2.max(s.3) + DVec3::splat(tol),
            )
        })
        .collect();
    for x in 0..segs.len() {
        for y in x + 1..segs.len() {
            let (la, i, a0, a1) = segs[x];
            let (lb, j, b0, b1) = segs[y];
            if la == lb {
                let n = loops[la].len();
                if j == i + 1 || (i == 0 && j == n - 1) {
                    continue; // adjacent: they share a point
                }
            }
            let (bx, by) = (boxes[x], boxes[y]);
            if bx.0.cmpgt(by.1).any() || by.0.cmpgt(bx.1).any() {
                continue;
            }
            let (d, at) = segment_distance(a0, a1, b0, b1);
            if d <= tol {
                let na = loops[la].len();
                let nb = loops[lb].len();
                let (ul, ua) = labels[la][i];
                let (_, ua1) = labels[la][(i + 1) % na];
                let (vl, vb) = labels[lb][j];
                let (_, vb1) = labels[lb][(j + 1) % nb];
                return Err(BoundaryError::SelfIntersecting {
                    la: ul,
                    a: ua,
                    a1: ua1,
                    lb: vl,
                    b: vb,
                    b1: vb1,
                    x: at.x,
                    y: at.y,
                    z: at.z,
                });
            }
        }
    }
    Ok(())
}

fn newell(p: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for i in 0..p.len() {
        n += p[i].cross(p[(i + 1) % p.len()]);
    }
    n
}

/// One loop with its darts inserted (see the module doc).
struct Darted {
    /// The points; a dart's two copies coincide (or form the opened V with `open`).
    pts: Vec<DVec3>,
    /// The points for hulls and the crossing check: the copies always opened into a V.
    hull: Vec<DVec3>,
    /// For each point, the point it coincides with: the left copy for a right copy, else itself.
    twin: Vec<usize>,
    /// Old point index → new.
    map: Vec<usize>,
    /// The user's (loop, point) name of each new point, from 1.
    labels: Vec<(usize, usize)>,
}

/// Insert the darts `(index, dart)` of loop `l` into its points (see the module doc).
fn insert_darts(
    pts: &[DVec3],
    l: usize,
    darts: &[(usize, &Dart)],
    open: bool,
) -> Result<Darted, BoundaryError> {
    let n = pts.len();
    let mut by_at: Vec<Option<usize>> = vec![None; n];
    for (di, &(k, d)) in darts.iter().enumerate() {
        let err = |message: String| BoundaryError::Dart {
            index: k + 1,
            message,
        };
        if d.at >= n {
            return Err(err(format!(
                "starts at point {} but loop {} has {n} points",
                d.at + 1,
                l + 1
            )));
        }
        if by_at[d.at].is_some() {
            return Err(err(format!(
                "point {} of loop {} already starts a dart",
                d.at + 1,
                l + 1
            )));
        }
        if d.points.is_empty() {
            return Err(err("needs at least one point (the tip)".into()));
        }
        if d.points.iter().any(|p| !p.is_finite()) {
            return Err(err("a point is not finite".into()));
        }
        let mut prev = pts[d.at];
        for (i, p) in d.points.iter().enumerate() {
            if p.distance(prev) <= 1e-9 * size(pts) {
                return Err(err(format!("point {} repeats the point before it", i + 1)));
            }
            prev = *p;
        }
        if let Some(w) = d.width {
            if !(w.is_finite() && w > 0.0) {
                return Err(err(format!(
                    "width must be a positive number of mm, got {w}"
                )));
            }
        }
        by_at[d.at] = Some(di);
    }
    let mut out = Darted {
        pts: Vec::new(),
        hull: Vec::new(),
        twin: Vec::new(),
        map: vec![0; n],
        labels: Vec::new(),
    };
    for i in 0..n {
        let Some(di) = by_at[i] else {
            out.map[i] = out.pts.len();
            out.twin.push(out.pts.len());
            out.pts.push(pts[i]);
            out.hull.push(pts[i]);
            out.labels.push((l + 1, i + 1));
            continue;
        };
        let d = darts[di].1;
        let a = pts[i];
        let t = (pts[(i + 1) % n] - pts[(i + n - 1) % n]).normalize_or_zero();
        let mut chain = vec![a];
        chain.extend_from_slice(&d.points);
        let mut cum = vec![0.0];
        for w in chain.windows(2) {
            cum.push(cum.last().copied().unwrap_or(0.0) + w[0].distance(w[1]));
        }
        let len = cum.last().copied().unwrap_or(0.0);
        let half = 0.5 * d.width.unwrap_or(0.02 * len);
        let m = chain.len();
        // Left copy (mouth to tip, on the side of the previous point), tip, right copy back.
        out.map[i] = out.pts.len();
        let left = out.pts.len();
        for j in 0..m - 1 {
            let v = chain[j] - t * half * (1.0 - cum[j] / len);
            out.twin.push(out.pts.len());
            out.pts.push(if open { v } else { chain[j] });
            out.hull.push(v);
            out.labels.push((l + 1, i + 1));
        }
        out.twin.push(out.pts.len());
        out.pts.push(chain[m - 1]);
        out.hull.push(chain[m - 1]);
        out.labels.push((l + 1, i + 1));
        for j in (0..m - 1).rev() {
            let v = chain[j] + t * half * (1.0 - cum[j] / len);
            out.twin.push(if open { out.pts.len() } else { left + j });
            out.pts.push(if open { v } else { chain[j] });
            out.hull.push(v);
            out.labels.push((l + 1, i + 1));
        }
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// The whole boundary: loops joined by connecting charts and the shortest tree, regions split by
// rulings, each searched on its own
// ---------------------------------------------------------------------------------------------

/// The boundary ready to search.
struct Prepared {
    /// All vertices (dart copies coincide unless opened).
    verts: Vec<DVec3>,
    /// The vertices for hulls (dart copies opened into a V).
    hverts: Vec<DVec3>,
    /// Site of each vertex: the vertex it coincides with (a dart's left copy), else itself.
    site: Vec<usize>,
    /// The loops as vertex ids, holes reversed when needed.
    loop_ids: Vec<Vec<usize>>,
    /// The input's directed edges.
    input_edges: HashSet<(usize, usize)>,
    /// Triangles of the charts that connect loops, wound like the loops.
    fixed: Vec<[usize; 3]>,
    /// Loops joining edges (user rulings between loops and the shortest tree), undirected.
    joins: HashSet<(usize, usize)>,
    /// The simple-or-seamed loops left to search (a join's ends appear twice).
    regions: Vec<Vec<usize>>,
    connecting_charts: usize,
}

/// Check a boundary without searching: loops, darts, crossings, rulings.
pub fn check(input: &Input) -> Result<(), BoundaryError> {
    prepare(input, &Options::default(), false).map(|_| ())
}

/// Triangulate a boundary (see the module doc).
pub fn triangulate(input: &Input, opts: &Options) -> Result<Output, BoundaryError> {
    let t0 = Instant::now();
    let prep = prepare(input, opts, false)?;
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

fn prepare(input: &Input, opts: &Options, open: bool) -> Result<Prepared, BoundaryError> {
    check_loops(&input.loops)?;
    let nl = input.loops.len();
    for (k, d) in input.darts.iter().enumerate() {
        if d.looop >= nl {
            return Err(BoundaryError::Dart {
                index: k + 1,
                message: format!("is on loop {} but there are {nl} loops", d.looop + 1),
            });
        }
    }
    let mut darted = Vec::new();
    for (l, p) in input.loops.iter().enumerate() {
        let mine: Vec<(usize, &Dart)> = input
            .darts
            .iter()
            .enumerate()
            .filter(|(_, d)| d.looop == l)
            .collect();
        darted.push(insert_darts(p, l, &mine, open)?);
    }
    let hull_loops: Vec<Vec<DVec3>> = darted.iter().map(|d| d.hull.clone()).collect();
    let labels: Vec<Vec<(usize, usize)>> = darted.iter().map(|d| d.labels.clone()).collect();
    check_crossings(&hull_loops, &labels)?;
    // Global vertices and the input's directed edges.
    let mut verts: Vec<DVec3> = Vec::new();
    let mut hverts: Vec<DVec3> = Vec::new();
    let mut site: Vec<usize> = Vec::new();
    let mut starts = Vec::new();
    for d in &darted {
        let s = verts.len();
        starts.push(s);
        verts.extend_from_slice(&d.pts);
        hverts.extend_from_slice(&d.hull);
        site.extend(d.twin.iter().map(|t| s + t));
    }
    let outer_normal = newell(&darted[0].hull);
    let mut loop_ids: Vec<Vec<usize>> = Vec::new();
    for (l, d) in darted.iter().enumerate() {
        let mut ids: Vec<usize> = (starts[l]..starts[l] + d.pts.len()).collect();
        if l > 0 && newell(&d.hull).dot(outer_normal) > 0.0 {
            ids.reverse();
        }
        loop_ids.push(ids);
    }
    let mut input_edges: HashSet<(usize, usize)> = HashSet::new();
    for ids in &loop_ids {
        for k in 0..ids.len() {
            input_edges.insert((ids[k], ids[(k + 1) % ids.len()]));
        }
    }
    // Rulings as global vertex pairs.
    let mut rulings: Vec<(usize, [usize; 2])> = Vec::new();
    for (r, ru) in input.rulings.iter().enumerate() {
        let err = |message: String| BoundaryError::Ruling {
            index: r + 1,
            message,
        };
        let mut ends = [0; 2];
        for (e, &(l, i)) in ru.iter().enumerate() {
            if l >= nl {
                return Err(err(format!(
                    "names loop {} but there are {nl} loops",
                    l + 1
                )));
            }
            let n = input.loops[l].len();
            if i >= n {
                return Err(err(format!(
                    "point {} of loop {}: the loop has {n} points",
                    i + 1,
                    l + 1
                )));
            }
            ends[e] = starts[l] + darted[l].map[i];
        }
        if ends[0] == ends[1] {
            return Err(err("joins a point to itself".into()));
        }
        rulings.push((r, ends));
    }
    // §6: charts connecting loops first.
    let mut cycles = loop_ids.clone();
    let mut fixed: Vec<[usize; 3]> = Vec::new();
    let mut pending = rulings.clone();
    let mut connecting_charts = 0;
    while cycles.len() > 1 {
        let Some((tris, next)) = connecting_chart(
            &verts,
            &hverts,
            &site,
            &cycles,
            &input_edges,
            &pending,
            opts,
        ) else {
            break;
        };
        pending.retain(|(_, [a, b])| !tris.iter().any(|t| t.contains(a) && t.contains(b)));
        fixed.extend(tris);
        cycles = next;
        connecting_charts += 1;
    }
    // Then the user's rulings between loops, then the shortest tree of connecting edges.
    let cycle_of = |cycles: &[Vec<usize>], v: usize| cycles.iter().position(|c| c.contains(&v));
    let mut joins: HashSet<(usize, usize)> = HashSet::new();
    let mut used: HashSet<usize> = HashSet::new();
    let mut chords: Vec<(usize, [usize; 2])> = Vec::new();
    for &(r, [a, b]) in &pending {
        let err = |message: String| BoundaryError::Ruling {
            index: r + 1,
            message,
        };
        match (cycle_of(&cycles, a), cycle_of(&cycles, b)) {
            (Some(x), Some(y)) if x != y => {
                if used.contains(&a) || used.contains(&b) {
                    return Err(err(
                        "an end already joins two loops (rulings between loops must not share points)".into(),
                    ));
                }
                join(&mut cycles, x, a, y, b);
                used.extend([a, b]);
                joins.insert((a.min(b), a.max(b)));
            }
            (Some(_), Some(_)) => chords.push((r, [a, b])),
            _ => {
                return Err(err(
                    "an end lies inside a chart that connects the loops; choose other points"
                        .into(),
                ))
            }
        }
    }
    if cycles.len() > 1 {
        let avoid: HashSet<usize> = chords.iter().flat_map(|(_, e)| *e).collect();
        let mut cand: Vec<(f64, usize, usize)> = Vec::new();
        for (i, ci) in cycles.iter().enumerate() {
            for cj in &cycles[i + 1..] {
                for &a in ci {
                    for &b in cj {
                        if !used.contains(&a)
                            && !used.contains(&b)
                            && !avoid.contains(&a)
                            && !avoid.contains(&b)
                        {
                            cand.push((verts[a].distance(verts[b]), a.min(b), a.max(b)));
                        }
                    }
                }
            }
        }
        cand.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        let tol = 1e-9 * size(&verts);
        for (_, a, b) in cand {
            if cycles.len() == 1 {
                break;
            }
            let (Some(x), Some(y)) = (cycle_of(&cycles, a), cycle_of(&cycles, b)) else {
                continue;
            };
            if x == y || used.contains(&a) || used.contains(&b) {
                continue;
            }
            // No crossing with the loops, the charts, the rulings or the tree so far.
            let mut segs: Vec<(usize, usize)> = Vec::new();
            for c in &cycles {
                segs.extend((0..c.len()).map(|k| (c[k], c[(k + 1) % c.len()])));
            }
            for t in &fixed {
                segs.extend((0..3).map(|k| (t[k], t[(k + 1) % 3])));
            }
            segs.extend(chords.iter().map(|(_, e)| (e[0], e[1])));
            segs.extend(joins.iter().copied());
            let crosses = segs.iter().any(|&(p, q)| {
                if p == a || p == b || q == a || q == b {
                    return false;
                }
                segment_distance(verts[a], verts[b], verts[p], verts[q]).0 <= tol
            });
            if crosses {
                continue;
            }
            join(&mut cycles, x, a, y, b);
            used.extend([a, b]);
            joins.insert((a, b));
        }
        if cycles.len() > 1 {
            return Err(BoundaryError::Loops(
                "the loops cannot be joined by edges that cross neither the loops nor each other"
                    .into(),
            ));
        }
    }
    // Rulings within a loop split the region.
    let mut regions: Vec<Vec<usize>> = cycles;
    for (r, [a, b]) in chords {
        let err = |message: String| BoundaryError::Ruling {
            index: r + 1,
            message,
        };
        let found = regions.iter().position(|g| {
            let pa = g.iter().position(|&v| v == a);
            let pb = g.iter().position(|&v| v == b);
            match (pa, pb) {
                (Some(x), Some(y)) => {
                    let d = (x + g.len() - y) % g.len();
                    d != 0 && d != 1 && d != g.len() - 1
                }
                _ => false,
            }
        });
        let Some(gi) = found else {
            return Err(err(
                "its points are neighbours, or on different sides of another ruling (rulings must not cross)".into(),
            ));
        };
        if regions[gi].iter().filter(|&&v| v == a || v == b).count() > 2 {
            return Err(err(
                "an end is also the end of a ruling between loops; choose other points".into(),
            ));
        }
        let g = regions.swap_remove(gi);
        let (x, y) = split_at(&g, a, b);
        regions.push(x);
        regions.push(y);
    }
    Ok(Prepared {
        verts,
        hverts,
        site,
        loop_ids,
        input_edges,
        fixed,
        joins,
        regions,
        connecting_charts,
    })
}

/// Join cycle `y` into cycle `x` by the edge `a b` (`a` on `x`, `b` on `y`), walked both
/// ways: … a, b, (y around), b, a, … .
fn join(cycles: &mut Vec<Vec<usize>>, x: usize, a: usize, y: usize, b: usize) {
    let cx = &cycles[x];
    let cy = &cycles[y];
    let i = cx.iter().position(|&v| v == a).unwrap_or(0);
    let j = cy.iter().position(|&v| v == b).unwrap_or(0);
    let mut merged: Vec<usize> = cx[..=i].to_vec();
    merged.extend_from_slice(&cy[j..]);
    merged.extend_from_slice(&cy[..=j]);
    merged.extend_from_slice(&cx[i..]);
    cycles[x] = merged;
    cycles.remove(y);
}

/// §6 "charts which connect separate loops": on the hull of all the loops' points (the §7
/// radial offset applied), charts as in §3 — hull triangles joined across edges that are not
/// loop edges, each with an input edge, all wound like the loops — that touch two loops or
/// more, smooth inside and against the neighbouring interior hull triangles, at least
/// `min_chart_area` of the hull, whose subtraction leaves simple loops (each touched loop
/// entered once, so they merge into one, or none when the chart covers them) and keeps every
/// pending ruling possible. The largest such chart, wound like the loops, and the loops left.
#[allow(clippy::type_complexity)]
fn connecting_chart(
    verts: &[DVec3],
    hverts: &[DVec3],
    site: &[usize],
    cycles: &[Vec<usize>],
    input_edges: &HashSet<(usize, usize)>,
    pending: &[(usize, [usize; 2])],
    opts: &Options,
) -> Option<(Vec<[usize; 3]>, Vec<Vec<usize>>)> {
    let ids: Vec<usize> = cycles.iter().flatten().copied().collect();
    let m = ids.len();
    let c = ids.iter().map(|&v| hverts[v]).sum::<DVec3>() / m as f64;
    let mean = ids.iter().map(|&v| hverts[v].distance(c)).sum::<f64>() / m as f64;
    let hp: Vec<DVec3> = ids
        .iter()
        .map(|&v| hverts[v] + (hverts[v] - c).normalize_or_zero() * opts.offset * mean)
        .collect();
    let hull = hull::hull(&hp)?;
    if hull.planar.is_some() {
        return None;
    }
    let mut edge_cycle: HashMap<(usize, usize), usize> = HashMap::new();
    for (ci, cy) in cycles.iter().enumerate() {
        for k in 0..cy.len() {
            edge_cycle.insert((cy[k], cy[(k + 1) % cy.len()]), ci);
        }
    }
    let nf = hull.faces.len();
    let face = |f: usize| hull.faces[f].map(|x| ids[x]);
    let on_loop =
        |a: usize, b: usize| edge_cycle.contains_key(&(a, b)) || edge_cycle.contains_key(&(b, a));
    let mut sense: Vec<Option<bool>> = vec![None; nf];
    let mut has_edge = vec![false; nf];
    for f in 0..nf {
        let t = face(f);
        let mut vote: Option<bool> = None;
        let mut mixed = false;
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let v = if edge_cycle.contains_key(&(a, b)) {
                has_edge[f] = true;
                input_edges.contains(&(a, b)).then_some(true)
            } else if edge_cycle.contains_key(&(b, a)) {
                has_edge[f] = true;
                input_edges.contains(&(b, a)).then_some(false)
            } else {
                None
            };
            if let Some(v) = v {
                mixed |= vote.is_some_and(|w| w != v);
                vote = Some(v);
            }
        }
        let wound = if vote == Some(false) {
            [t[0], t[2], t[1]]
        } else {
            t
        };
        if !mixed && sites_valid(verts, site, &[wound]) {
            sense[f] = vote;
        }
    }
    let thr = opts.max_dihedral_deg.to_radians();
    let hull_area = hull.area(&hp);
    let mut comp = vec![usize::MAX; nf];
    let mut best: Option<(f64, Vec<[usize; 3]>, Vec<Vec<usize>>)> = None;
    for f0 in 0..nf {
        let Some(s0) = sense[f0] else { continue };
        if comp[f0] != usize::MAX {
            continue;
        }
        comp[f0] = f0;
        let mut part = vec![f0];
        let mut k = 0;
        while k < part.len() {
            let f = part[k];
            k += 1;
            let t = face(f);
            for e in 0..3 {
                let g = hull.neighbours[f][e];
                if g == usize::MAX
                    || comp[g] != usize::MAX
                    || sense[g] != Some(s0)
                    || on_loop(t[e], t[(e + 1) % 3])
                {
                    continue;
                }
                comp[g] = f0;
                part.push(g);
            }
        }
        let tris: Vec<[usize; 3]> = part
            .iter()
            .map(|&f| {
                let t = face(f);
                if s0 {
                    t
                } else {
                    [t[0], t[2], t[1]]
                }
            })
            .collect();
        let mut touched: BTreeSet<usize> = BTreeSet::new();
        for t in &tris {
            for k in 0..3 {
                if let Some(&ci) = edge_cycle.get(&(t[k], t[(k + 1) % 3])) {
                    touched.insert(ci);
                }
            }
        }
        if touched.len() < 2 {
            continue;
        }
        let area: f64 = part
            .iter()
            .map(|&f| {
                let t = hull.faces[f];
                0.5 * (hp[t[1]] - hp[t[0]]).cross(hp[t[2]] - hp[t[0]]).length()
            })
            .sum();
        if area < opts.min_chart_area * hull_area || best.as_ref().is_some_and(|b| b.0 >= area) {
            continue;
        }
        let smooth = part.iter().all(|&f| {
            (0..3).all(|e| {
                let g = hull.neighbours[f][e];
                g == usize::MAX
                    || (comp[g] != f0 && has_edge[g])
                    || angle(unit_normal(verts, face(f)), unit_normal(verts, face(g))) < thr
            })
        });
        if !smooth || !sites_valid(verts, site, &tris) {
            continue;
        }
        // Subtract: the loops' edges, less the chart's, plus the chart's rim reversed.
        let mut rem: BTreeSet<(usize, usize)> = edge_cycle.keys().copied().collect();
        let mut ok = true;
        for t in &tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if !rem.remove(&(a, b)) {
                    ok &= rem.insert((b, a));
                }
            }
        }
        let mut next: BTreeMap<usize, usize> = BTreeMap::new();
        let mut into: HashSet<usize> = HashSet::new();
        for &(a, b) in &rem {
            ok &= next.insert(a, b).is_none() && into.insert(b);
        }
        if !ok {
            continue;
        }
        let mut left: Vec<Vec<usize>> = Vec::new();
        let mut seen: HashSet<usize> = HashSet::new();
        for &start in next.keys() {
            if seen.contains(&start) {
                continue;
            }
            let mut cy = vec![start];
            seen.insert(start);
            let mut v = next[&start];
            while v != start && ok {
                ok = seen.insert(v);
                cy.push(v);
                v = next.get(&v).copied().unwrap_or(start);
            }
            ok &= cy.len() >= 3;
            left.push(cy);
        }
        let merged = cycles.len() + 1 - touched.len();
        if !ok || !(left.len() == merged || left.len() + 1 == merged) {
            continue;
        }
        let feasible = pending.iter().all(|(_, [a, b])| {
            tris.iter().any(|t| t.contains(a) && t.contains(b))
                || (left.iter().any(|c| c.contains(a)) && left.iter().any(|c| c.contains(b)))
        });
        if feasible {
            best = Some((area, tris, left));
        }
    }
    best.map(|(_, t, l)| (t, l))
}

/// Whether triangles over vertices with sites are valid pieces of a boundary triangulation:
/// no triangle with two vertices at one site or with no area, no site pair (edge in space) in
/// more than two triangles.
fn sites_valid(p: &[DVec3], site: &[usize], tris: &[[usize; 3]]) -> bool {
    let mut count: HashMap<(usize, usize), u8> = HashMap::new();
    for t in tris {
        let s = t.map(|x| site[x]);
        if s[0] == s[1] || s[1] == s[2] || s[0] == s[2] {
            return false;
        }
        let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
        let longest = a
            .distance_squared(b)
            .max(b.distance_squared(c))
            .max(c.distance_squared(a));
        if (b - a).cross(c - a).length() <= 1e-9 * longest {
            return false;
        }
        for k in 0..3 {
            let (x, y) = (s[k], s[(k + 1) % 3]);
            let n = count.entry((x.min(y), x.max(y))).or_default();
            *n += 1;
            if *n > 2 {
                return false;
            }
        }
    }
    true
}

/// Search every region; `false` when a region with copies got no valid triangulation.
fn search(prep: Prepared, opts: &Options, t0: Instant) -> (Output, bool) {
    let Prepared {
        verts,
        hverts,
        site,
        loop_ids,
        input_edges,
        fixed,
        joins,
        regions,
        connecting_charts,
    } = prep;
    let mut best: Vec<Vec<[usize; 3]>> = vec![fixed.clone()];
    let mut warnings = Vec::new();
    let mut iterations = 0;
    let mut alts: Vec<Vec<Vec<[usize; 3]>>> = vec![Vec::new()];
    let mut all_ok = true;
    for g in &regions {
        let q = g.len();
        let pts: Vec<DVec3> = g.iter().map(|&v| verts[v]).collect();
        // Hull points: a join's two copies of an end are nudged apart, each along its loop
        // edge (1 % of the shorter of that edge and the join), for the hulls only.
        let mut times: HashMap<usize, usize> = HashMap::new();
        for &v in g {
            *times.entry(v).or_default() += 1;
        }
        let hp: Vec<DVec3> = (0..q)
            .map(|k| {
                let v = g[k];
                if times[&v] < 2 {
                    return hverts[v];
                }
                let (a, b) = (g[(k + q - 1) % q], g[(k + 1) % q]);
                let (nb, partner) = if joins.contains(&(v.min(b), v.max(b))) {
                    (a, b)
                } else {
                    (b, a)
                };
                let d = verts[nb] - verts[v];
                let eps = 0.01 * d.length().min(verts[partner].distance(verts[v]));
                hverts[v] + d.normalize_or_zero() * eps
            })
            .collect();
        let lsite: Vec<usize> = g.iter().map(|&v| site[v]).collect();
        let mut sorted = lsite.clone();
        sorted.sort_unstable();
        sorted.dedup();
        let copies = sorted.len() < q;
        let orig: Vec<bool> = (0..q)
            .map(|k| input_edges.contains(&(g[k], g[(k + 1) % q])))
            .collect();
        let res = solve(&pts, &hp, &orig, &lsite, copies, opts, &mut warnings);
        all_ok &= res.valid;
        iterations += res.iterations;
        let to_global = |t: &Vec<[usize; 3]>| -> Vec<[usize; 3]> {
            t.iter().map(|f| f.map(|x| g[x])).collect()
        };
        best.push(to_global(&res.best));
        alts.push(res.alternatives.iter().map(to_global).collect());
    }
    let faces: Vec<[usize; 3]> = best.iter().flatten().copied().collect();
    all_ok &= sites_valid(&verts, &site, &faces);
    let mesh = to_mesh(&verts, &faces);
    let mut figures = figures(&verts, &faces, &input_edges, &loop_ids);
    figures.iterations = iterations;
    figures.seconds = t0.elapsed().as_secs_f64();
    figures.connecting_charts = connecting_charts;
    figures.joining_edges = joins.len();
    // Alternatives: one region's next best with the other regions' best, region by region.
    let mut alternatives = Vec::new();
    'regions: for (r, list) in alts.iter().enumerate() {
        for alt in list {
            if alternatives.len() + 1 >= opts.alternatives {
                break 'regions;
            }
            let mut all: Vec<[usize; 3]> = Vec::new();
            for (s, b) in best.iter().enumerate() {
                all.extend_from_slice(if s == r { alt } else { b });
            }
            alternatives.push(to_mesh(&verts, &all));
        }
    }
    (
        Output {
            mesh,
            figures,
            alternatives,
            warnings,
        },
        all_ok,
    )
}

/// Split loop `g` along the chord `a b`: (a … b) and (b … a).
fn split_at(g: &[usize], a: usize, b: usize) -> (Vec<usize>, Vec<usize>) {
    let pa = g.iter().position(|&v| v == a).unwrap_or(0);
    let pb = g.iter().position(|&v| v == b).unwrap_or(0);
    let walk = |from: usize, to: usize| {
        let mut out = vec![g[from]];
        let mut i = from;
        while i != to {
            i = (i + 1) % g.len();
            out.push(g[i]);
        }
        out
    };
    (walk(pa, pb), walk(pb, pa))
}

fn to_mesh(verts: &[DVec3], faces: &[[usize; 3]]) -> Mesh {
    Mesh {
        vertices: verts.to_vec(),
        faces: faces
            .iter()
            .map(|f| Face {
                verts: f.to_vec(),
                line: None,
            })
            .collect(),
    }
}

fn unit_normal(p: &[DVec3], t: [usize; 3]) -> DVec3 {
    (p[t[1]] - p[t[0]])
        .cross(p[t[2]] - p[t[0]])
        .normalize_or_zero()
}

fn angle(n1: DVec3, n2: DVec3) -> f64 {
    n1.cross(n2).length().atan2(n1.dot(n2))
}

/// Report figures of a finished triangulation (global vertex ids).
fn figures(
    verts: &[DVec3],
    faces: &[[usize; 3]],
    input_edges: &HashSet<(usize, usize)>,
    loops: &[Vec<usize>],
) -> Figures {
    let mut nb: HashMap<usize, (usize, usize)> = HashMap::new();
    for ids in loops {
        let n = ids.len();
        for k in 0..n {
            nb.insert(ids[k], (ids[(k + n - 1) % n], ids[(k + 1) % n]));
        }
    }
    let mut edges: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (f, t) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut fig = Figures {
        triangles: faces.len(),
        ..Default::default()
    };
    fig.interior_triangles = faces
        .iter()
        .filter(|t| {
            (0..3).all(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                !input_edges.contains(&(a, b)) && !input_edges.contains(&(b, a))
            })
        })
        .count();
    let mut keys: Vec<_> = edges.keys().copied().collect();
    keys.sort_unstable();
    for e in keys {
        let fs = &edges[&e];
        if fs.len() != 2 {
            continue;
        }
        fig.interior_edges += 1;
        let th = angle(
            unit_normal(verts, faces[fs[0]]),
            unit_normal(verts, faces[fs[1]]),
        );
        fig.largest_dihedral_deg = fig.largest_dihedral_deg.max(th.to_degrees());
        fig.fairness += th * th;
        let (a, b) = e;
        let mut others = Vec::new();
        for v in [a, b] {
            if let Some(&(p, q)) = nb.get(&v) {
                others.push(verts[p]);
                others.push(verts[q]);
            }
        }
        if segment_on_hull(verts[a], verts[b], &others) {
            fig.convex_edges += 1;
        }
    }
    fig
}

// ---------------------------------------------------------------------------------------------
// Branch and bound on one simple loop (local vertex indices 0..m, in loop order)
// ---------------------------------------------------------------------------------------------

struct Solved {
    best: Vec<[usize; 3]>,
    alternatives: Vec<Vec<[usize; 3]>>,
    iterations: usize,
    /// False when the loop has copies (darts, joins) and no valid triangulation was found.
    valid: bool,
}

/// `pts` the points, `base` the points for hulls (copies moved apart), `site` which points
/// coincide, `copies` whether any do.
fn solve(
    pts: &[DVec3],
    base: &[DVec3],
    orig: &[bool],
    site: &[usize],
    copies: bool,
    opts: &Options,
    warnings: &mut Vec<String>,
) -> Solved {
    let m = pts.len();
    if m == 3 {
        return Solved {
            best: vec![[0, 1, 2]],
            alternatives: vec![],
            iterations: 0,
            valid: !copies || sites_valid(pts, site, &[[0, 1, 2]]),
        };
    }
    // §7 radial offset for the hulls, unless it takes more loop edges off the hull than the
    // points as given (a scalloped edge near the centre of mass can sink inside).
    let c = base.iter().copied().sum::<DVec3>() / m as f64;
    let mean = base.iter().map(|p| p.distance(c)).sum::<f64>() / m as f64;
    let mut hpts: Vec<DVec3> = base
        .iter()
        .map(|p| *p + (*p - c).normalize_or_zero() * opts.offset * mean)
        .collect();
    if opts.offset != 0.0 && loop_edges_on_hull(base) > loop_edges_on_hull(&hpts) {
        hpts = base.to_vec();
    }
    let mut s = Search::new(
        pts,
        hpts,
        orig,
        (site, copies),
        opts.max_dihedral_deg.to_radians(),
        opts.min_chart_area,
    );
    s.base = base.to_vec();
    let mut r = s.run(opts);
    let mut relaxed = Search::new(
        pts,
        s.h.clone(),
        orig,
        (site, copies),
        std::f64::consts::PI,
        0.0,
    );
    relaxed.base = base.to_vec();
    if r.best.is_none() {
        let r2 = relaxed.run(opts);
        warnings.push(format!(
            "{RELAXED} {}° and charts over {} % of their hull: the limits were relaxed",
            opts.max_dihedral_deg,
            100.0 * opts.min_chart_area
        ));
        r.iterations += r2.iterations;
        r.best = r2.best;
        r.found = r2.found;
    }
    let best = match r.best {
        Some((t, _)) => t,
        None => match relaxed.dive() {
            Some(t) => {
                warnings.push(
                    "the search ran out of iterations: the triangulation was completed by taking the largest chart of each open subloop".into(),
                );
                t
            }
            None => {
                warnings.push(
                    "no boundary triangulation found: a fan from the first point is used".into(),
                );
                (1..m - 1).map(|k| [0, k, k + 1]).collect()
            }
        },
    };
    let mut found = r.found;
    found.sort_by(|a, b| {
        a.1.interior
            .cmp(&b.1.interior)
            .then(a.1.fairness.total_cmp(&b.1.fairness))
    });
    Solved {
        alternatives: found
            .into_iter()
            .map(|(t, _)| t)
            .filter(|t| *t != best)
            .collect(),
        valid: !copies || sites_valid(pts, site, &best),
        best,
        iterations: r.iterations,
    }
}

/// How many loop edges `k → k+1` are edges of the convex hull of the points (all of them when
/// the points are planar: the loop is then filled in its plane).
fn loop_edges_on_hull(p: &[DVec3]) -> usize {
    let m = p.len();
    let Some(h) = hull::hull(p) else { return 0 };
    if h.planar.is_some() {
        return m;
    }
    let mut edges: HashSet<(usize, usize)> = HashSet::new();
    for f in &h.faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    (0..m)
        .filter(|&k| {
            let (a, b) = (k, (k + 1) % m);
            edges.contains(&(a.min(b), a.max(b)))
        })
        .count()
}

struct Chart {
    tris: Vec<[usize; 3]>,
    area: f64,
}

#[derive(Default)]
struct Sub {
    envelopes: Vec<Vec<[usize; 3]>>,
    charts: Vec<usize>,
}

struct Run {
    best: Option<(Vec<[usize; 3]>, Quality)>,
    found: Vec<(Vec<[usize; 3]>, Quality)>,
    iterations: usize,
}

#[derive(Clone, Copy, PartialEq)]
struct Key {
    charts: usize,
    area: f64,
    seq: u64,
}
impl Eq for Key {}
impl PartialOrd for Key {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Key {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.charts
            .cmp(&o.charts)
            .then(o.area.total_cmp(&self.area))
            .then(self.seq.cmp(&o.seq))
    }
}

struct Search<'a> {
    p: &'a [DVec3],
    h: Vec<DVec3>,
    orig: &'a [bool],
    /// Which points coincide (dart sides, join ends), and whether any do.
    site: &'a [usize],
    copies: bool,
    m: usize,
    thr: f64,
    min_area: f64,
    /// The hull points before the radial offset (tried for flat subloops).
    base: Vec<DVec3>,
    charts: Vec<Chart>,
    chart_ids: HashMap<Vec<[usize; 3]>, usize>,
    subs: HashMap<Vec<usize>, Rc<Sub>>,
}

/// Edge → triangles; ordered, so that sums of angles come out the same on every run.
type EdgeMap = BTreeMap<(usize, usize), Vec<usize>>;

impl<'a> Search<'a> {
    fn new(
        p: &'a [DVec3],
        h: Vec<DVec3>,
        orig: &'a [bool],
        (site, copies): (&'a [usize], bool),
        thr: f64,
        min_area: f64,
    ) -> Self {
        Search {
            p,
            h,
            orig,
            site,
            copies,
            m: p.len(),
            thr,
            min_area,
            base: Vec::new(),
            charts: Vec::new(),
            chart_ids: HashMap::new(),
            subs: HashMap::new(),
        }
    }

    /// Triangles that can be part of a boundary triangulation once coinciding points are
    /// taken into account (always true without copies).
    fn valid(&self, tris: &[[usize; 3]]) -> bool {
        !self.copies || sites_valid(self.p, self.site, tris)
    }

    fn normal(&self, t: [usize; 3]) -> DVec3 {
        unit_normal(self.p, t)
    }

    fn dihedral(&self, a: [usize; 3], b: [usize; 3]) -> f64 {
        angle(self.normal(a), self.normal(b))
    }

    /// Whether the directed loop edge `a → b` (a, b adjacent in the loop) is an input edge.
    fn is_orig(&self, a: usize, b: usize) -> bool {
        (b == (a + 1) % self.m && self.orig[a]) || (a == (b + 1) % self.m && self.orig[b])
    }

    fn interior(&self, t: [usize; 3]) -> bool {
        !(0..3).any(|k| self.is_orig(t[k], t[(k + 1) % 3]))
    }

    /// Remaining subloops after removing triangles (each sorted, i.e. in loop order).
    fn subtract(&self, tris: &[[usize; 3]]) -> Vec<Vec<usize>> {
        let m = self.m;
        let mut rem: HashSet<(usize, usize)> = (0..m).map(|k| (k, (k + 1) % m)).collect();
        for t in tris {
            for k in 0..3 {
                let e = (t[k], t[(k + 1) % 3]);
                if !rem.remove(&e) {
                    rem.insert((e.1, e.0));
                }
            }
        }
        let mut out: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for &(a, b) in &rem {
            out.entry(a).or_default().push(b);
        }
        let mut loops = Vec::new();
        let off = |x: usize, from: usize| (x + m - from) % m;
        while let Some((&start, _)) = out.iter().find(|(_, v)| !v.is_empty()) {
            let first = out.get_mut(&start).and_then(|v| {
                v.sort_unstable();
                v.pop()
            });
            let Some(mut cur) = first else { break };
            let mut lp = vec![start];
            let mut prev = start;
            let mut guard = 0;
            while cur != start && guard <= m {
                guard += 1;
                lp.push(cur);
                let Some(cands) = out.get_mut(&cur) else {
                    break;
                };
                let lim = off(prev, cur);
                let pick = cands
                    .iter()
                    .enumerate()
                    .filter(|(_, &w)| off(w, cur) < lim || lim == 0)
                    .max_by_key(|(_, &w)| off(w, cur))
                    .map(|(i, _)| i)
                    .or(if cands.is_empty() { None } else { Some(0) });
                let Some(i) = pick else { break };
                let w = cands.swap_remove(i);
                prev = cur;
                cur = w;
            }
            if lp.len() >= 3 {
                let k = lp
                    .iter()
                    .enumerate()
                    .min_by_key(|(_, &v)| v)
                    .map_or(0, |(i, _)| i);
                lp.rotate_left(k);
                loops.push(lp);
            }
        }
        loops.sort();
        loops
    }

    /// Whether triangles (in loop order) have pairwise non-crossing chords.
    fn non_crossing(tris: &[[usize; 3]]) -> bool {
        let mut chords: Vec<(usize, usize)> = Vec::new();
        for t in tris {
            chords.push((t[0], t[1]));
            chords.push((t[1], t[2]));
            chords.push((t[0], t[2]));
        }
        chords.sort_unstable();
        chords.dedup();
        for (i, &(a, b)) in chords.iter().enumerate() {
            for &(c, d) in &chords[i + 1..] {
                if c >= b {
                    break;
                }
                if a < c && c < b && b < d {
                    return false;
                }
            }
        }
        true
    }

    fn chart_id(&mut self, mut tris: Vec<[usize; 3]>) -> usize {
        tris.sort_unstable();
        if let Some(&id) = self.chart_ids.get(&tris) {
            return id;
        }
        let area = tris
            .iter()
            .map(|t| {
                0.5 * (self.p[t[1]] - self.p[t[0]])
                    .cross(self.p[t[2]] - self.p[t[0]])
                    .length()
            })
            .sum();
        let id = self.charts.len();
        self.charts.push(Chart {
            tris: tris.clone(),
            area,
        });
        self.chart_ids.insert(tris, id);
        id
    }

    /// Envelopes and charts of a subloop's hull (cached).
    fn analyse(&mut self, sub: &[usize]) -> Rc<Sub> {
        if let Some(s) = self.subs.get(sub) {
            return s.clone();
        }
        let s = Rc::new(self.analyse_uncached(sub));
        self.subs.insert(sub.to_vec(), s.clone());
        s
    }

    fn analyse_uncached(&mut self, sub: &[usize]) -> Sub {
        let q = sub.len();
        let mut out = Sub::default();
        if q == 3 {
            out.envelopes.push(vec![[sub[0], sub[1], sub[2]]]);
            return out;
        }
        let hp: Vec<DVec3> = sub.iter().map(|&v| self.h[v]).collect();
        let Some(hull) = hull::hull(&hp) else {
            return out;
        };
        let sorted = |t: [usize; 3]| {
            let mut g = t.map(|x| sub[x]);
            g.sort_unstable();
            g
        };
        if hull.planar.is_some() {
            // A flat subloop: ear clipping in its plane, on the input points (the offset ones
            // if those fold over), one envelope since both sides are the same.
            let op: Vec<DVec3> = sub.iter().map(|&v| self.p[v]).collect();
            let bp: Vec<DVec3> = sub
                .iter()
                .filter_map(|&v| self.base.get(v))
                .copied()
                .collect();
            for pts in [&op, &bp, &hp] {
                if pts.len() != q {
                    continue;
                }
                let n = newell(pts).normalize_or_zero();
                if n == DVec3::ZERO {
                    continue;
                }
                let u = n.any_orthonormal_vector();
                let v = n.cross(u);
                let ring: Vec<DVec2> = pts.iter().map(|p| DVec2::new(p.dot(u), p.dot(v))).collect();
                if crate::geom::polygon::is_simple_ring(&ring) {
                    let tris: Vec<[usize; 3]> = crate::geom::polygon::triangulate(&ring)
                        .into_iter()
                        .map(sorted)
                        .collect();
                    if tris.len() == q - 2 && Self::non_crossing(&tris) && self.valid(&tris) {
                        out.envelopes.push(tris);
                        break;
                    }
                }
            }
            return out;
        }
        let nf = hull.faces.len();
        let is_sub_edge = |x: usize, y: usize| y == (x + 1) % q || x == (y + 1) % q;
        // Whether a subloop edge counts as polyline for charts (not a ruling or bridge).
        let counts = |x: usize, y: usize| -> bool {
            let (a, b) = (sub[x], sub[y]);
            if b == (a + 1) % self.m || a == (b + 1) % self.m {
                let k = if b == (a + 1) % self.m { a } else { b };
                self.orig[k]
            } else {
                true
            }
        };
        let mut sense = vec![false; nf];
        let mut has_edge = vec![false; nf];
        let mut eligible = vec![false; nf];
        let mut edge_seen = 0;
        for (f, t) in hull.faces.iter().enumerate() {
            let [i, j, l] = *t;
            sense[f] = u8::from(i < j) + u8::from(j < l) + u8::from(l < i) == 2;
            for k in 0..3 {
                let (x, y) = (t[k], t[(k + 1) % 3]);
                if is_sub_edge(x, y) {
                    has_edge[f] = true;
                    edge_seen += 1;
                    if counts(x, y) && self.valid(&[sorted(*t)]) {
                        eligible[f] = true;
                    }
                }
            }
        }
        // Components across non-subloop edges.
        let comps = |keep: &dyn Fn(usize, usize) -> bool| -> Vec<Vec<usize>> {
            let mut comp = vec![usize::MAX; nf];
            let mut list = Vec::new();
            for f0 in 0..nf {
                if comp[f0] != usize::MAX || !keep(f0, f0) {
                    continue;
                }
                let id = list.len();
                let mut members = vec![f0];
                comp[f0] = id;
                let mut k = 0;
                while k < members.len() {
                    let f = members[k];
                    k += 1;
                    for e in 0..3 {
                        let g = hull.neighbours[f][e];
                        let (x, y) = (hull.faces[f][e], hull.faces[f][(e + 1) % 3]);
                        if g == usize::MAX || comp[g] != usize::MAX || is_sub_edge(x, y) {
                            continue;
                        }
                        if keep(f, g) {
                            comp[g] = id;
                            members.push(g);
                        }
                    }
                }
                list.push(members);
            }
            list
        };
        // Envelopes: every subloop edge on the hull (each seen from both sides) and exactly two
        // components of one sense each.
        if edge_seen == 2 * q {
            let parts = comps(&|_, _| true);
            if parts.len() == 2 {
                for part in &parts {
                    let s0 = sense[part[0]];
                    if part.len() == q - 2 && part.iter().all(|&f| sense[f] == s0) {
                        let tris: Vec<[usize; 3]> =
                            part.iter().map(|&f| sorted(hull.faces[f])).collect();
                        if Self::non_crossing(&tris) && self.valid(&tris) {
                            out.envelopes.push(tris);
                        }
                    }
                }
            }
        }
        // Charts.
        let hull_area = hull.area(&hp);
        let parts = comps(&|f, g| eligible[f] && eligible[g] && sense[f] == sense[g]);
        for part in &parts {
            let tris: Vec<[usize; 3]> = part.iter().map(|&f| sorted(hull.faces[f])).collect();
            let area: f64 = part
                .iter()
                .map(|&f| {
                    0.5 * (hp[hull.faces[f][1]] - hp[hull.faces[f][0]])
                        .cross(hp[hull.faces[f][2]] - hp[hull.faces[f][0]])
                        .length()
                })
                .sum();
            if area < self.min_area * hull_area || !Self::non_crossing(&tris) || !self.valid(&tris)
            {
                continue;
            }
            let mut smooth = true;
            'check: for (k, &f) in part.iter().enumerate() {
                for e in 0..3 {
                    let g = hull.neighbours[f][e];
                    if g == usize::MAX {
                        continue;
                    }
                    let inside = part.contains(&g);
                    let interior_face = !has_edge[g];
                    if (inside || interior_face)
                        && self.dihedral(tris[k], sorted(hull.faces[g])) >= self.thr
                    {
                        smooth = false;
                        break 'check;
                    }
                }
            }
            if smooth {
                let id = self.chart_id(tris);
                out.charts.push(id);
            }
        }
        if out.charts.is_empty() && out.envelopes.is_empty() {
            // The pathological hull: each triangle a chart.
            for f in 0..nf {
                let t = sorted(hull.faces[f]);
                if t[0] != t[1] && t[1] != t[2] && self.valid(&[t]) {
                    let id = self.chart_id(vec![t]);
                    out.charts.push(id);
                }
            }
        }
        out.charts.sort_unstable();
        out.charts.dedup();
        out
    }

    fn edge_map(tris: &[[usize; 3]]) -> EdgeMap {
        let mut e: EdgeMap = BTreeMap::new();
        for (i, t) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                e.entry((a.min(b), a.max(b))).or_default().push(i);
            }
        }
        e
    }

    fn cover_tris(&self, cover: &[usize]) -> (Vec<[usize; 3]>, Vec<usize>) {
        let mut tris = Vec::new();
        let mut owner = Vec::new();
        for &c in cover {
            for t in &self.charts[c].tris {
                tris.push(*t);
                owner.push(c);
            }
        }
        (tris, owner)
    }

    /// §5.1.1 cover quality: a lower bound for every triangulation containing the cover.
    fn bound(&self, tris: &[[usize; 3]], owner: &[usize], subs: &[Vec<usize>]) -> Quality {
        let em = Self::edge_map(tris);
        let mut q = Quality {
            interior: tris.iter().filter(|t| self.interior(**t)).count(),
            fairness: 0.0,
        };
        for fs in em.values() {
            if fs.len() == 2 {
                let a = self.dihedral(tris[fs[0]], tris[fs[1]]);
                q.fairness += a * a;
            }
        }
        for s in subs {
            let n = s.len();
            // Charts touching the subloop, each with its triangles on it.
            let mut touching: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
            for k in 0..n {
                let (a, b) = (s[k], s[(k + 1) % n]);
                if let Some(fs) = em.get(&(a.min(b), a.max(b))) {
                    for &f in fs {
                        touching.entry(owner[f]).or_default().push(f);
                    }
                }
            }
            if touching.len() > 2 {
                q.interior += 1;
            }
            if touching.len() >= 2 {
                let pts: Vec<DVec3> = s.iter().map(|&v| self.p[v]).collect();
                let pn = newell(&pts).normalize_or_zero();
                let alpha: Vec<f64> = touching
                    .values()
                    .take(2)
                    .map(|fs| {
                        fs.iter()
                            .map(|&f| {
                                let c = pn.dot(self.normal(tris[f])).abs().min(1.0);
                                c.acos()
                            })
                            .fold(f64::INFINITY, f64::min)
                    })
                    .collect();
                let sum = alpha.iter().sum::<f64>();
                q.fairness += sum * sum / (n as f64 - 1.0);
            }
        }
        q
    }

    /// Quality of `add` next to `base` (edges inside `add` and between the two), or `None`
    /// when some of those edges bend more than the threshold.
    fn added(&self, base_em: &EdgeMap, base: &[[usize; 3]], add: &[[usize; 3]]) -> Option<Quality> {
        let em = Self::edge_map(add);
        let mut q = Quality {
            interior: add.iter().filter(|t| self.interior(**t)).count(),
            fairness: 0.0,
        };
        for (e, fs) in &em {
            let mut pair = fs.iter().map(|&f| add[f]).collect::<Vec<_>>();
            if let Some(bs) = base_em.get(e) {
                pair.extend(bs.iter().map(|&f| base[f]));
            }
            if pair.len() == 2 {
                let a = self.dihedral(pair[0], pair[1]);
                if a >= self.thr {
                    return None;
                }
                q.fairness += a * a;
            }
        }
        Some(q)
    }

    /// Depth first, no bounds: while some subloop has no envelopes, add its largest chart;
    /// then take the best envelopes. Ends: each step removes at least one triangle's worth.
    fn dive(&mut self) -> Option<Vec<[usize; 3]>> {
        let mut cover: Vec<usize> = Vec::new();
        for _ in 0..self.m {
            let (tris, _) = self.cover_tris(&cover);
            let subs = self.subtract(&tris);
            let infos: Vec<Rc<Sub>> = subs.iter().map(|s| self.analyse(s)).collect();
            if let Some(k) = infos.iter().position(|i| i.envelopes.is_empty()) {
                let ch = infos[k]
                    .charts
                    .iter()
                    .copied()
                    .max_by(|a, b| self.charts[*a].area.total_cmp(&self.charts[*b].area))?;
                cover.push(ch);
                cover.sort_unstable();
                continue;
            }
            let em = Self::edge_map(&tris);
            let mut all = tris.clone();
            for info in &infos {
                let pick = info
                    .envelopes
                    .iter()
                    .filter_map(|env| self.added(&em, &tris, env).map(|q| (env, q)))
                    .reduce(|a, b| if b.1.better(&a.1) { b } else { a })
                    .map_or(&info.envelopes[0], |(env, _)| env);
                all.extend_from_slice(pick);
            }
            all.sort_unstable();
            return (all.len() == self.m - 2 && self.valid(&all)).then_some(all);
        }
        None
    }

    fn run(&mut self, opts: &Options) -> Run {
        let mut run = Run {
            best: None,
            found: Vec::new(),
            iterations: 0,
        };
        let mut seen_tri: HashSet<Vec<[usize; 3]>> = HashSet::new();
        let mut queue: BTreeMap<Key, (Vec<usize>, Quality)> = BTreeMap::new();
        let mut seen_cover: HashSet<Vec<usize>> = HashSet::new();
        let mut seq = 0u64;
        queue.insert(
            Key {
                charts: 0,
                area: 0.0,
                seq,
            },
            (Vec::new(), Quality::default()),
        );
        seen_cover.insert(Vec::new());
        let good =
            |q: &Quality| q.interior <= opts.good_interior && q.fairness <= opts.good_fairness;
        while let Some((_, (cover, _))) = queue.pop_first() {
            if run.best.as_ref().is_some_and(|b| good(&b.1))
                || run.iterations >= opts.max_iterations
            {
                break;
            }
            run.iterations += 1;
            let (tris, owner) = self.cover_tris(&cover);
            let subs = self.subtract(&tris);
            let bound = self.bound(&tris, &owner, &subs);
            if run.best.as_ref().is_some_and(|b| !bound.better(&b.1)) {
                continue;
            }
            let infos: Vec<Rc<Sub>> = subs.iter().map(|s| self.analyse(s)).collect();
            let em = Self::edge_map(&tris);
            // Stage 2: envelopes.
            if infos.iter().all(|i| !i.envelopes.is_empty()) {
                let own = self.added(&BTreeMap::new(), &[], &tris);
                let mut total = own;
                let mut all = tris.clone();
                for info in &infos {
                    let mut pick: Option<(usize, Quality)> = None;
                    for (k, env) in info.envelopes.iter().enumerate() {
                        if let Some(q) = self.added(&em, &tris, env) {
                            if pick.is_none_or(|(_, b)| q.better(&b)) {
                                pick = Some((k, q));
                            }
                        }
                    }
                    match (pick, total.as_mut()) {
                        (Some((k, q)), Some(t)) => {
                            t.interior += q.interior;
                            t.fairness += q.fairness;
                            all.extend_from_slice(&info.envelopes[k]);
                        }
                        _ => total = None,
                    }
                }
                if let Some(q) = total {
                    if all.len() == self.m - 2 && self.valid(&all) {
                        all.sort_unstable();
                        if seen_tri.insert(all.clone()) {
                            run.found.push((all.clone(), q));
                        }
                        if run.best.as_ref().is_none_or(|b| q.better(&b.1)) {
                            run.best = Some((all, q));
                        }
                    }
                }
            }
            // Stages 3–4: new covers.
            for info in &infos {
                for &ch in &info.charts {
                    let ctris = self.charts[ch].tris.clone();
                    // Smooth against the cover.
                    let mut ok = true;
                    for t in &ctris {
                        for k in 0..3 {
                            let (a, b) = (t[k], t[(k + 1) % 3]);
                            if let Some(fs) = em.get(&(a.min(b), a.max(b))) {
                                if fs.iter().any(|&f| self.dihedral(*t, tris[f]) >= self.thr) {
                                    ok = false;
                                }
                            }
                        }
                    }
                    if !ok {
                        continue;
                    }
                    let mut n = cover.clone();
                    n.push(ch);
                    n.sort_unstable();
                    if !seen_cover.insert(n.clone()) {
                        continue;
                    }
                    let (nt, no) = self.cover_tris(&n);
                    if !self.valid(&nt) {
                        continue;
                    }
                    let nq = self.bound(&nt, &no, &self.subtract(&nt));
                    if run.best.as_ref().is_some_and(|b| !nq.better(&b.1)) {
                        continue;
                    }
                    let subsets: Vec<Key> = queue
                        .iter()
                        .filter(|(_, (r, _))| r.iter().all(|x| n.binary_search(x).is_ok()))
                        .map(|(k, _)| *k)
                        .collect();
                    if !subsets.is_empty() {
                        if subsets.iter().all(|k| nq.better(&queue[k].1)) {
                            for k in &subsets {
                                queue.remove(k);
                            }
                        } else {
                            continue;
                        }
                    }
                    seq += 1;
                    let area = n.iter().map(|&c| self.charts[c].area).fold(0.0, f64::max);
                    queue.insert(
                        Key {
                            charts: n.len(),
                            area,
                            seq,
                        },
                        (n, nq),
                    );
                }
            }
        }
        run
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subtract_gives_simple_subloops() {
        let p: Vec<DVec3> = (0..8)
            .map(|k| {
                let t = k as f64 / 8.0 * std::f64::consts::TAU;
                DVec3::new(t.cos(), t.sin(), 0.3 * (2.0 * t).cos())
            })
            .collect();
        let orig = vec![true; 8];
        let site: Vec<usize> = (0..8).collect();
        let s = Search::new(&p, p.clone(), &orig, (&site, false), 3.0, 0.0);
        // Triangle 1-2-5 leaves 0,1,5,6,7 and 2,3,4,5.
        let subs = s.subtract(&[[1, 2, 5]]);
        assert_eq!(subs, vec![vec![0, 1, 5, 6, 7], vec![2, 3, 4, 5]]);
        // Triangles touching at vertex 4: 2-3-4 and 4-5-6 leave 0,1,2,4,6,7.
        let subs = s.subtract(&[[2, 3, 4], [4, 5, 6]]);
        assert_eq!(subs, vec![vec![0, 1, 2, 4, 6, 7]]);
        // Interior triangle 0-3-6: three subloops.
        let subs = s.subtract(&[[0, 3, 6]]);
        assert_eq!(
            subs,
            vec![vec![0, 1, 2, 3], vec![0, 6, 7], vec![3, 4, 5, 6]]
        );
        assert!(Search::non_crossing(&[[0, 1, 2], [0, 2, 5]]));
        assert!(!Search::non_crossing(&[[0, 1, 3], [2, 3, 5]]));
    }

    #[test]
    fn segment_distance_cases() {
        let (d, _) = segment_distance(
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, -1.0, 1.0),
            DVec3::new(0.5, 1.0, 1.0),
        );
        assert!((d - 1.0).abs() < 1e-12);
        let (d, _) = segment_distance(
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
        );
        assert!((d - 1.0).abs() < 1e-12);
    }
}
