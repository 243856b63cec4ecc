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
//! - §6 darts, several loops, rulings, alternatives; §7 B-spline smoothing and radial offset.
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
//! - Darts: the paper duplicates the dart polyline with reversed orientation into one closed
//!   boundary. Two copies of the same points would make a boundary triangulation degenerate,
//!   so the copies are opened into a narrow V: at the mouth by `dart_width` (default 2 % of
//!   the dart's length) along the boundary, narrowing linearly to the single tip vertex. The
//!   flat piece then has the dart cut out, which is what a pattern needs.
//! - Several loops: the first is the outer one, the others are holes (reversed if their
//!   Newell normal agrees with the outer's). Each hole is joined to the region holding the
//!   vertex nearest to it by two edges: the shortest one, and one from the region vertex half
//!   way round to its nearest hole vertex. (The paper's single shortest tree would make a
//!   loop that runs both ways along one edge, which needs duplicate vertices.) Those edges and
//!   the user's rulings are constraints: they split the boundary into subloops solved
//!   separately, and do not count as polyline edges for charts (§6.1). The paper's first
//!   choice, hull charts connecting loops, is not implemented.
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
use std::collections::{BTreeMap, HashMap, HashSet};
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
    /// Branch-and-bound iterations at most (per subloop split by rulings or holes).
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

/// A dart: from loop point `at` (0-based) through `points`, the last one being the tip.
#[derive(Debug, Clone, PartialEq)]
pub struct Dart {
    pub at: usize,
    pub points: Vec<DVec3>,
    /// Opening at the mouth, mm; `None`: 2 % of the dart's length.
    pub width: Option<f64>,
}

/// The boundary: closed loops (the first outer), darts and rulings on the first loop.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Input {
    pub loops: Vec<Vec<DVec3>>,
    pub darts: Vec<Dart>,
    /// Pairs of 0-based point indices of the first loop (before darts are inserted).
    pub rulings: Vec<[usize; 2]>,
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

/// Insert the darts into the first loop (see the module doc). Returns the new loop, the map
/// from old point index to new, and the user label of each new point.
#[allow(clippy::type_complexity)]
fn insert_darts(
    pts: &[DVec3],
    darts: &[Dart],
) -> Result<(Vec<DVec3>, Vec<usize>, Vec<(usize, usize)>), BoundaryError> {
    let n = pts.len();
    let mut by_at: Vec<Option<usize>> = vec![None; n];
    for (k, d) in darts.iter().enumerate() {
        let err = |message: String| BoundaryError::Dart {
            index: k + 1,
            message,
        };
        if d.at >= n {
            return Err(err(format!(
                "starts at point {} but the loop has {n} points",
                d.at + 1
            )));
        }
        if by_at[d.at].is_some() {
            return Err(err(format!("point {} already starts a dart", d.at + 1)));
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
        by_at[d.at] = Some(k);
    }
    let mut out = Vec::new();
    let mut labels = Vec::new();
    let mut map = vec![0; n];
    for i in 0..n {
        let Some(k) = by_at[i] else {
            map[i] = out.len();
            out.push(pts[i]);
            labels.push((1, i + 1));
            continue;
        };
        let d = &darts[k];
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
        map[i] = out.len();
        for j in 0..m - 1 {
            out.push(chain[j] - t * half * (1.0 - cum[j] / len));
            labels.push((1, i + 1));
        }
        out.push(chain[m - 1]);
        labels.push((1, i + 1));
        for j in (0..m - 1).rev() {
            out.push(chain[j] + t * half * (1.0 - cum[j] / len));
            labels.push((1, i + 1));
        }
    }
    Ok((out, map, labels))
}

// ---------------------------------------------------------------------------------------------
// The whole boundary: regions split by rulings and hole bridges, each searched on its own
// ---------------------------------------------------------------------------------------------

/// The boundary ready to search: all vertices, the loops as vertex ids (holes reversed when
/// needed), the input's directed edges and the regions split by rulings and hole bridges.
struct Prepared {
    verts: Vec<DVec3>,
    loop_ids: Vec<Vec<usize>>,
    input_edges: HashSet<(usize, usize)>,
    regions: Vec<Vec<usize>>,
}

/// Check a boundary without searching: loops, darts, crossings, rulings.
pub fn check(input: &Input) -> Result<(), BoundaryError> {
    prepare(input).map(|_| ())
}

/// Triangulate a boundary (see the module doc).
pub fn triangulate(input: &Input, opts: &Options) -> Result<Output, BoundaryError> {
    let t0 = Instant::now();
    let Prepared {
        verts,
        loop_ids,
        input_edges,
        regions,
    } = prepare(input)?;
    search(verts, loop_ids, input_edges, regions, opts, t0)
}

fn prepare(input: &Input) -> Result<Prepared, BoundaryError> {
    check_loops(&input.loops)?;
    let (first, map, first_labels) = insert_darts(&input.loops[0], &input.darts)?;
    let mut loops = vec![first];
    let mut labels = vec![first_labels];
    for (l, p) in input.loops.iter().enumerate().skip(1) {
        loops.push(p.clone());
        labels.push((0..p.len()).map(|i| (l + 1, i + 1)).collect());
    }
    check_crossings(&loops, &labels)?;
    // Global vertices and the input's directed edges.
    let mut verts: Vec<DVec3> = Vec::new();
    let mut starts = Vec::new();
    for p in &loops {
        starts.push(verts.len());
        verts.extend_from_slice(p);
    }
    let outer_normal = newell(&loops[0]);
    let mut loop_ids: Vec<Vec<usize>> = Vec::new();
    for (l, p) in loops.iter().enumerate() {
        let mut ids: Vec<usize> = (starts[l]..starts[l] + p.len()).collect();
        if l > 0 && newell(p).dot(outer_normal) > 0.0 {
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
    // Regions: the outer loop, split by rulings, then holes bridged in.
    let mut regions: Vec<Vec<usize>> = vec![loop_ids[0].clone()];
    let n0 = input.loops[0].len();
    for (r, ru) in input.rulings.iter().enumerate() {
        let err = |message: String| BoundaryError::Ruling {
            index: r + 1,
            message,
        };
        if ru[0] >= n0 || ru[1] >= n0 {
            return Err(err(format!(
                "points {} and {}: the loop has {n0} points",
                ru[0] + 1,
                ru[1] + 1
            )));
        }
        let (a, b) = (map[ru[0]], map[ru[1]]);
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
            return Err(err(format!(
                "points {} and {} are neighbours, the same point, or on different sides of another ruling (rulings must not cross)",
                ru[0] + 1,
                ru[1] + 1
            )));
        };
        let g = regions.swap_remove(gi);
        let (x, y) = split_at(&g, a, b);
        regions.push(x);
        regions.push(y);
    }
    for ids in loop_ids.iter().skip(1) {
        // The region and vertex nearest to the hole.
        let mut best = (f64::INFINITY, 0, 0, 0);
        for (gi, g) in regions.iter().enumerate() {
            for (k, &v) in g.iter().enumerate() {
                for (h, &w) in ids.iter().enumerate() {
                    let d = verts[v].distance_squared(verts[w]);
                    if d < best.0 {
                        best = (d, gi, k, h);
                    }
                }
            }
        }
        let (_, gi, k1, h1) = best;
        let g = regions.swap_remove(gi);
        let k2 = (k1 + g.len() / 2) % g.len();
        let mut h2 = (h1 + ids.len() / 2) % ids.len();
        let mut dh = f64::INFINITY;
        for (h, &w) in ids.iter().enumerate() {
            let d = verts[g[k2]].distance_squared(verts[w]);
            if h != h1 && d < dh {
                dh = d;
                h2 = h;
            }
        }
        // Region 1: g[k1..=k2], hole h2..=h1; region 2: g[k2..=k1], hole h1..=h2.
        let arc = |v: &[usize], from: usize, to: usize| -> Vec<usize> {
            let mut out = vec![v[from]];
            let mut i = from;
            while i != to {
                i = (i + 1) % v.len();
                out.push(v[i]);
            }
            out
        };
        let mut r1 = arc(&g, k1, k2);
        r1.extend(arc(ids, h2, h1));
        let mut r2 = arc(&g, k2, k1);
        r2.extend(arc(ids, h1, h2));
        regions.push(r1);
        regions.push(r2);
    }
    Ok(Prepared {
        verts,
        loop_ids,
        input_edges,
        regions,
    })
}

fn search(
    verts: Vec<DVec3>,
    loop_ids: Vec<Vec<usize>>,
    input_edges: HashSet<(usize, usize)>,
    regions: Vec<Vec<usize>>,
    opts: &Options,
    t0: Instant,
) -> Result<Output, BoundaryError> {
    // Search each region.
    let mut best: Vec<Vec<[usize; 3]>> = Vec::new();
    let mut warnings = Vec::new();
    let mut iterations = 0;
    let mut alts: Vec<Vec<Vec<[usize; 3]>>> = Vec::new();
    for g in &regions {
        let pts: Vec<DVec3> = g.iter().map(|&v| verts[v]).collect();
        let orig: Vec<bool> = (0..g.len())
            .map(|k| input_edges.contains(&(g[k], g[(k + 1) % g.len()])))
            .collect();
        let res = solve(&pts, &orig, opts, &mut warnings);
        iterations += res.iterations;
        let to_global = |t: &Vec<[usize; 3]>| -> Vec<[usize; 3]> {
            t.iter().map(|f| f.map(|x| g[x])).collect()
        };
        best.push(to_global(&res.best));
        alts.push(res.alternatives.iter().map(to_global).collect());
    }
    let faces: Vec<[usize; 3]> = best.iter().flatten().copied().collect();
    let mesh = to_mesh(&verts, &faces);
    let mut figures = figures(&verts, &faces, &input_edges, &loop_ids);
    figures.iterations = iterations;
    figures.seconds = t0.elapsed().as_secs_f64();
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
    Ok(Output {
        mesh,
        figures,
        alternatives,
        warnings,
    })
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
}

fn solve(pts: &[DVec3], orig: &[bool], opts: &Options, warnings: &mut Vec<String>) -> Solved {
    let m = pts.len();
    if m == 3 {
        return Solved {
            best: vec![[0, 1, 2]],
            alternatives: vec![],
            iterations: 0,
        };
    }
    // §7 radial offset for the hulls, unless it takes more loop edges off the hull than the
    // points as given (a scalloped edge near the centre of mass can sink inside).
    let c = pts.iter().copied().sum::<DVec3>() / m as f64;
    let mean = pts.iter().map(|p| p.distance(c)).sum::<f64>() / m as f64;
    let mut hpts: Vec<DVec3> = pts
        .iter()
        .map(|p| *p + (*p - c).normalize_or_zero() * opts.offset * mean)
        .collect();
    if opts.offset != 0.0 && loop_edges_on_hull(pts) > loop_edges_on_hull(&hpts) {
        hpts = pts.to_vec();
    }
    let mut s = Search::new(
        pts,
        hpts,
        orig,
        opts.max_dihedral_deg.to_radians(),
        opts.min_chart_area,
    );
    let mut r = s.run(opts);
    let mut relaxed = Search::new(pts, s.h.clone(), orig, std::f64::consts::PI, 0.0);
    if r.best.is_none() {
        let r2 = relaxed.run(opts);
        warnings.push(format!(
            "no triangulation with every dihedral angle under {}° and charts over {} % of their hull: the limits were relaxed",
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
    m: usize,
    thr: f64,
    min_area: f64,
    charts: Vec<Chart>,
    chart_ids: HashMap<Vec<[usize; 3]>, usize>,
    subs: HashMap<Vec<usize>, Rc<Sub>>,
}

/// Edge → triangles; ordered, so that sums of angles come out the same on every run.
type EdgeMap = BTreeMap<(usize, usize), Vec<usize>>;

impl<'a> Search<'a> {
    fn new(p: &'a [DVec3], h: Vec<DVec3>, orig: &'a [bool], thr: f64, min_area: f64) -> Self {
        Search {
            p,
            h,
            orig,
            m: p.len(),
            thr,
            min_area,
            charts: Vec::new(),
            chart_ids: HashMap::new(),
            subs: HashMap::new(),
        }
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
            for pts in [&op, &hp] {
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
                    if tris.len() == q - 2 && Self::non_crossing(&tris) {
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
                    if counts(x, y) {
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
                        if Self::non_crossing(&tris) {
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
            if area < self.min_area * hull_area || !Self::non_crossing(&tris) {
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
                if t[0] != t[1] && t[1] != t[2] {
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
            return (all.len() == self.m - 2).then_some(all);
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
                    if all.len() == self.m - 2 {
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
        let s = Search::new(&p, p.clone(), &orig, 3.0, 0.0);
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
