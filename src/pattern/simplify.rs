//! Simplified seams for pieces laid out from D-Charts (issue 7, thesis §5.3 "Simplifying
//! boundaries"): chart boundaries follow mesh edges, so in 2D they zig-zag in many tiny
//! segments that a drag knife cuts badly and a person sews badly. The boundary between two
//! charts is simplified by collapsing vertices.
//!
//! **From the thesis.** The cost of collapsing a vertex is the sum of the areas of the two
//! triangles it makes with its neighbours on the boundary, one on each side of the seam (each
//! piece has its own copy of the vertex in 2D); when a vertex is collapsed, half its cost is
//! added to each of its two neighbours. Vertices are collapsed cheapest first.
//!
//! **Choices where the thesis is silent.**
//! - *What is simplified:* only the interior vertices of seam chains (`super::marks::find`):
//!   a chain of border vertices shared by two pieces, or by the two sides of a cut inside one
//!   chart. Chain ends (where three or more sides meet, or a seam meets the free boundary) stay,
//!   and so does every border vertex where a fold line ends. The free boundary (the mesh's own
//!   edge) is left as modelled: it is not a product of the segmentation and does not zig-zag.
//! - *Both sides together:* a collapse removes the same 3D vertex from both sides of its seam,
//!   so the two sides keep the same number of vertices and correspond vertex for vertex.
//!   Every vertex left is an original vertex; nothing moves.
//! - *Stopping rule:* the thesis orders collapses but does not say when to stop. A collapse is
//!   made only if, on both sides, every original vertex between the two neighbours lies within
//!   `tolerance` mm of the new segment (the deviation of the simplified chain from the original,
//!   measured exactly; the distance between a polyline and a chord through its ends is largest
//!   at a vertex), and if the two sides' lengths then differ by at most [`MISMATCH_MM`] and
//!   [`MISMATCH_REL`] of the seam's length (or by no more than they already did before
//!   simplifying), so that the seam still meets when sewn, well within the strictest material's
//!   seam tolerance (metal, 0.1 %).
//!   A collapse refused waits until one of its neighbours is collapsed (its cost and geometry
//!   change); simplification ends when no vertex can go. Default tolerances: see
//!   [`super::PatternOptions::for_material`]; 0 turns simplification off.
//! - *Geometry:* a collapse is refused when the new segment would touch another segment of
//!   the piece's border, or come closer to it than `2 CLEAN_MM` (0.1 mm, what a knife can
//!   separate) and closer than the two segments it replaces were, when it would cross a fold
//!   line, when it would make a corner sharper than 3° (and sharper than before) with the
//!   border next to it, or when the triangle it cuts off or adds contains another border
//!   vertex (a hole, another part of the outline) or a fold line's end; a ring keeps at least
//!   three vertices. The outline therefore stays simple and clear of its holes and folds.
//! - *Marks:* seam ids, notches and registration marks are placed after simplification, on
//!   the simplified chains, side B's notches at the same fractions of its length as side A's
//!   (`super::marks::place`).
//! - *Bookkeeping:* a simplified border segment stands for a run of mesh edges;
//!   `border_edges` and `border_faces` keep those of the first. A seam side's `length` becomes
//!   the length of its simplified chain (what is cut and sewn).
//! - Ties in cost break on the order of seams and of vertices along side A: deterministic.

use super::{Piece, SeamSide};
use crate::geom::heap::Lowest;
use crate::geom::polygon;
use glam::DVec2;
use std::collections::BinaryHeap;

/// Largest difference (mm) simplification may bring between the lengths of a seam's two sides,
/// unless they already differed by more.
pub const MISMATCH_MM: f64 = 0.1;

/// Largest relative difference simplification may bring between a seam's two sides (of the
/// longer side), unless they already differed by more.
pub const MISMATCH_REL: f64 = 5e-4;

/// Least distance (mm) between a new segment and the rest of the piece's border.
const CLEARANCE_MM: f64 = 2.0 * super::allowance::CLEAN_MM;

/// Two 2D copies of one mesh vertex (a fold's end, a border point) closer than this (mm), or
/// than 1e-8 of their distance from the origin on large pieces, are the same point: charts
/// agree on shared vertices to about 1e-9 relative, not exactly.
const SAME_MM: f64 = 1e-6;

/// Whether `x` and `q` are copies of one vertex (see [`SAME_MM`]).
fn same(x: DVec2, q: DVec2) -> bool {
    x.distance(q) < SAME_MM.max(1e-8 * x.length().max(q.length()))
}

/// Sharpest corner (radians) a collapse may make where the chord meets the border next to it.
const SPIKE_RAD: f64 = 0.05;

/// What simplification did to a piece (written under the piece in `report.json`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Simplified {
    /// The tolerance it was asked for (mm).
    pub tolerance: f64,
    /// Border vertices, all rings, before and after.
    pub vertices_before: usize,
    pub vertices_after: usize,
    /// Largest distance (mm) of an original border vertex from the simplified border.
    pub max_deviation: f64,
    /// Largest difference (mm) between the lengths of the two sides of one of its seams.
    pub max_seam_mismatch: f64,
}

/// One border ring of a piece while it is simplified: the original points with a doubly
/// linked list over those still alive.
struct Ring {
    pts: Vec<DVec2>,
    prev: Vec<usize>,
    next: Vec<usize>,
    alive: Vec<bool>,
    count: usize,
}

/// A vertex that may be collapsed: its copy on side A and on side B of one seam.
struct Cand {
    pair: usize,
    /// (piece, ring, index) on each side.
    at: [(usize, usize, usize); 2],
    /// Cost accumulated from collapsed neighbours.
    acc: f64,
    version: u32,
    alive: bool,
}

/// Simplifies the seams of one flat's pieces (whose seams [`super::marks::find`] found, before
/// their marks are placed) within `tolerance` mm, and records [`Simplified`] on each piece.
/// Does nothing for a tolerance that is not a positive number.
pub(super) fn apply(pieces: &mut [Piece], tolerance: f64) {
    if tolerance.is_nan() || tolerance <= 0.0 {
        return;
    }
    let mut rings = rings_of(pieces);
    let before: Vec<usize> = pieces
        .iter()
        .map(|p| p.border.iter().map(|r| r.len()).sum())
        .collect();
    let folds: Vec<Vec<(DVec2, DVec2)>> = pieces
        .iter()
        .map(|p| p.folds.iter().map(|f| (f.a, f.b)).collect())
        .collect();
    let pairs = super::marks::pairs(pieces);
    let mut cs = candidates(pieces, &rings, &folds, &pairs);
    collapse_all(&mut rings, &folds, &mut cs, tolerance);
    rebuild(pieces, &rings, &pairs, &cs.lengths, &before, tolerance);
}

/// The border rings of every piece, all vertices alive.
fn rings_of(pieces: &[Piece]) -> Vec<Vec<Ring>> {
    pieces
        .iter()
        .map(|p| {
            p.border
                .iter()
                .map(|r| {
                    let n = r.len();
                    Ring {
                        pts: r.clone(),
                        prev: (0..n).map(|i| (i + n - 1) % n).collect(),
                        next: (0..n).map(|i| (i + 1) % n).collect(),
                        alive: vec![true; n],
                        count: n,
                    }
                })
                .collect()
        })
        .collect()
}

/// The vertices that may be collapsed, and the seams' lengths.
struct Candidates {
    cands: Vec<Cand>,
    /// Per piece, ring and vertex: its candidate.
    cand_at: Vec<Vec<Vec<Option<usize>>>>,
    /// Per seam pair: the lengths of its two sides.
    lengths: Vec<[f64; 2]>,
    /// Per seam pair: the largest mismatch allowed.
    allowed: Vec<f64>,
}

/// Candidates: interior vertices of every chain, side A's index `i` being side B's
/// `count − i`; fixed where a fold line ends.
fn candidates(
    pieces: &[Piece],
    rings: &[Vec<Ring>],
    folds: &[Vec<(DVec2, DVec2)>],
    pairs: &[[(usize, usize); 2]],
) -> Candidates {
    let mut cands: Vec<Cand> = Vec::new();
    let mut cand_at: Vec<Vec<Vec<Option<usize>>>> = rings
        .iter()
        .map(|rs| rs.iter().map(|r| vec![None; r.pts.len()]).collect())
        .collect();
    let mut lengths: Vec<[f64; 2]> = Vec::new();
    let mut allowed: Vec<f64> = Vec::new();
    for (k, &[(pa, ia), (pb, ib)]) in pairs.iter().enumerate() {
        let (sa, sb) = (&pieces[pa].seams[ia], &pieces[pb].seams[ib]);
        let (la, lb) = (
            super::marks::polyline_length(&sa.points),
            super::marks::polyline_length(&sb.points),
        );
        lengths.push([la, lb]);
        allowed.push((MISMATCH_MM.min(MISMATCH_REL * la.max(lb))).max((la - lb).abs()));
        if sa.count != sb.count {
            continue;
        }
        let (na, nb) = (rings[pa][sa.ring].pts.len(), rings[pb][sb.ring].pts.len());
        for i in 1..sa.count {
            let a = (pa, sa.ring, (sa.first + i) % na);
            let b = (pb, sb.ring, (sb.first + sb.count - i) % nb);
            let on_fold = [a, b].iter().any(|&(p, r, j)| {
                let q = rings[p][r].pts[j];
                folds[p].iter().any(|&(u, v)| same(u, q) || same(v, q))
            });
            if on_fold || cand_at[a.0][a.1][a.2].is_some() || cand_at[b.0][b.1][b.2].is_some() {
                continue;
            }
            cand_at[a.0][a.1][a.2] = Some(cands.len());
            cand_at[b.0][b.1][b.2] = Some(cands.len());
            cands.push(Cand {
                pair: k,
                at: [a, b],
                acc: 0.0,
                version: 0,
                alive: true,
            });
        }
    }

    Candidates {
        cands,
        cand_at,
        lengths,
        allowed,
    }
}

/// Collapse vertices cheapest first while they may go (see the module doc).
fn collapse_all(
    rings: &mut [Vec<Ring>],
    folds: &[Vec<(DVec2, DVec2)>],
    cs: &mut Candidates,
    tolerance: f64,
) {
    let Candidates {
        cands,
        cand_at,
        lengths,
        allowed,
    } = cs;
    let area = |rings: &[Vec<Ring>], (p, r, i): (usize, usize, usize)| {
        let ring = &rings[p][r];
        let (a, v, b) = (ring.pts[ring.prev[i]], ring.pts[i], ring.pts[ring.next[i]]);
        0.5 * (v - a).perp_dot(b - a).abs()
    };
    let cost = |rings: &[Vec<Ring>], c: &Cand| area(rings, c.at[0]) + area(rings, c.at[1]) + c.acc;
    let mut heap: BinaryHeap<Lowest<u32>> = cands
        .iter()
        .enumerate()
        .map(|(id, c)| Lowest {
            key: cost(rings, c),
            id,
            data: 0,
        })
        .collect();

    while let Some(e) = heap.pop() {
        let c = &cands[e.id];
        if !c.alive || c.version != e.data {
            continue;
        }
        // The length each side loses, and the mismatch it leaves.
        let loss = |(p, r, i): (usize, usize, usize)| {
            let ring = &rings[p][r];
            let (a, v, b) = (ring.pts[ring.prev[i]], ring.pts[i], ring.pts[ring.next[i]]);
            a.distance(v) + v.distance(b) - a.distance(b)
        };
        let k = c.pair;
        let new_len = [lengths[k][0] - loss(c.at[0]), lengths[k][1] - loss(c.at[1])];
        if (new_len[0] - new_len[1]).abs() > allowed[k] + 1e-12 {
            continue;
        }
        let ok =
            c.at.iter()
                .all(|&at| collapsible(rings, folds, at, tolerance))
                && !crossing_each_other(rings, c.at);
        if !ok {
            continue;
        }
        lengths[k] = new_len;
        let full = e.key;
        let at = c.at;
        cands[e.id].alive = false;
        let mut touched: Vec<usize> = Vec::new();
        for (p, r, i) in at {
            let ring = &mut rings[p][r];
            let (a, b) = (ring.prev[i], ring.next[i]);
            ring.next[a] = b;
            ring.prev[b] = a;
            ring.alive[i] = false;
            ring.count -= 1;
            for j in [a, b] {
                if let Some(n) = cand_at[p][r][j] {
                    if !touched.contains(&n) {
                        touched.push(n);
                    }
                }
            }
        }
        // Half the cost to each neighbour along the chain (the same on both sides).
        for &n in &touched {
            if cands[n].pair == k && cands[n].alive {
                cands[n].acc += 0.5 * full;
            }
        }
        for n in touched {
            if !cands[n].alive {
                continue;
            }
            cands[n].version += 1;
            heap.push(Lowest {
                key: cost(rings, &cands[n]),
                id: n,
                data: cands[n].version,
            });
        }
    }
}

/// Rebuild the pieces from what is left of their rings, and record [`Simplified`].
fn rebuild(
    pieces: &mut [Piece],
    rings: &[Vec<Ring>],
    pairs: &[[(usize, usize); 2]],
    lengths: &[[f64; 2]],
    before: &[usize],
    tolerance: f64,
) {
    let mut mismatch = vec![0.0f64; pieces.len()];
    for (k, &[(pa, _), (pb, _)]) in pairs.iter().enumerate() {
        let d = (lengths[k][0] - lengths[k][1]).abs();
        mismatch[pa] = mismatch[pa].max(d);
        mismatch[pb] = mismatch[pb].max(d);
    }
    for (pi, p) in pieces.iter_mut().enumerate() {
        let mut max_dev = 0.0f64;
        let mut new_index: Vec<Vec<usize>> = Vec::new();
        for (r, ring) in rings[pi].iter().enumerate() {
            let n = ring.pts.len();
            let mut idx = vec![usize::MAX; n];
            let mut pts = Vec::with_capacity(ring.count);
            let mut edges = Vec::with_capacity(ring.count);
            let mut faces = Vec::with_capacity(ring.count);
            for (i, slot) in idx.iter_mut().enumerate() {
                if ring.alive[i] {
                    *slot = pts.len();
                    pts.push(ring.pts[i]);
                    edges.push(p.border_edges[r][i]);
                    faces.push(p.border_faces[r][i]);
                } else {
                    let (a, b) = (
                        ring.pts[alive_before(ring, i)],
                        ring.pts[alive_after(ring, i)],
                    );
                    max_dev = max_dev.max(polygon::segment_distance(ring.pts[i], a, b));
                }
            }
            p.border[r] = pts;
            p.border_edges[r] = edges;
            p.border_faces[r] = faces;
            new_index.push(idx);
        }
        for s in &mut p.seams {
            rebuild_side(s, &rings[pi][s.ring], &new_index[s.ring]);
        }
        p.outline = p.border.clone();
        p.simplified = Some(Simplified {
            tolerance,
            vertices_before: before[pi],
            vertices_after: p.border.iter().map(|r| r.len()).sum(),
            max_deviation: max_dev,
            max_seam_mismatch: mismatch[pi],
        });
    }
}

/// The nearest alive vertex before (after) the collapsed vertex `i`, in original order.
fn alive_before(ring: &Ring, i: usize) -> usize {
    let n = ring.pts.len();
    let mut j = (i + n - 1) % n;
    while !ring.alive[j] && j != i {
        j = (j + n - 1) % n;
    }
    j
}
fn alive_after(ring: &Ring, i: usize) -> usize {
    let n = ring.pts.len();
    let mut j = (i + 1) % n;
    while !ring.alive[j] && j != i {
        j = (j + 1) % n;
    }
    j
}

/// A seam side on the simplified ring: its alive points, first index and count renumbered.
fn rebuild_side(s: &mut SeamSide, ring: &Ring, idx: &[usize]) {
    let n = ring.pts.len();
    let mut points = Vec::with_capacity(s.points.len());
    for i in 0..=s.count {
        let j = (s.first + i) % n;
        if ring.alive[j] {
            points.push(ring.pts[j]);
        }
    }
    if let Some(&k) = idx.get(s.first).filter(|&&k| k != usize::MAX) {
        s.first = k;
    }
    s.count = points.len().saturating_sub(1);
    s.length = super::marks::polyline_length(&points);
    s.points = points;
}

/// Whether vertex `i` of a ring may go: the chord between its neighbours stays within
/// `tolerance` of the original chain, clear of the rest of the border and of the folds, and the
/// triangle it sweeps holds no other vertex or fold end.
fn collapsible(
    rings: &[Vec<Ring>],
    folds: &[Vec<(DVec2, DVec2)>],
    (p, r, i): (usize, usize, usize),
    tolerance: f64,
) -> bool {
    let ring = &rings[p][r];
    if ring.count <= 3 || !ring.alive[i] {
        return false;
    }
    let n = ring.pts.len();
    let (ia, ib) = (ring.prev[i], ring.next[i]);
    let (a, v, b) = (ring.pts[ia], ring.pts[i], ring.pts[ib]);
    // Deviation: every original vertex strictly between the neighbours.
    let mut j = (ia + 1) % n;
    while j != ib {
        if polygon::segment_distance(ring.pts[j], a, b) > tolerance {
            return false;
        }
        j = (j + 1) % n;
    }
    let (lo, hi) = (a.min(v).min(b), a.max(v).max(b));
    let pad = DVec2::splat(CLEARANCE_MM);
    let inside = |q: DVec2| {
        q.x >= lo.x && q.x <= hi.x && q.y >= lo.y && q.y <= hi.y && in_triangle(q, a, v, b)
    };
    for (r2, other) in rings[p].iter().enumerate() {
        let m = other.pts.len();
        for k in 0..m {
            if !other.alive[k] {
                continue;
            }
            let same = r2 == r;
            let q = other.pts[k];
            if !(same && (k == ia || k == i || k == ib)) && inside(q) {
                return false;
            }
            let k2 = other.next[k];
            if same && (k == i || k2 == i) {
                continue; // the two segments being replaced
            }
            let q2 = other.pts[k2];
            if q.max(q2).x < lo.x - pad.x
                || q.min(q2).x > hi.x + pad.x
                || q.max(q2).y < lo.y - pad.y
                || q.min(q2).y > hi.y + pad.y
            {
                continue;
            }
            if same && (k2 == ia || k == ib) {
                // A neighbouring segment: the chord must not fold back onto it (a spike
                // sharper than SPIKE_RAD, unless the corner there was already as sharp).
                let (far, near) = if k2 == ia { (q, a) } else { (q2, b) };
                let end = if k2 == ia { b } else { a };
                let angle = |x: DVec2, y: DVec2| x.perp_dot(y).abs().atan2(x.dot(y));
                let (u, new, old) = (far - near, end - near, v - near);
                let turn = angle(u, new);
                if turn < SPIKE_RAD && turn < angle(u, old) {
                    return false;
                }
                continue;
            }
            if polygon::segments_intersect(a, b, q, q2) {
                return false;
            }
            // Closer than a knife separates, and closer than the two segments it replaces
            // were (tiny border segments next to the chord's ends are that close anyway).
            let d = polygon::segment_segment_distance(a, b, q, q2);
            if d < CLEARANCE_MM
                && d < polygon::segment_segment_distance(a, v, q, q2)
                    .min(polygon::segment_segment_distance(v, b, q, q2))
            {
                return false;
            }
        }
    }
    for &(u, w) in &folds[p] {
        if inside(u) || inside(w) {
            return false;
        }
        let touches = |x: DVec2| same(x, a) || same(x, b);
        if !touches(u) && !touches(w) && polygon::segments_intersect(a, b, u, w) {
            return false;
        }
    }
    true
}

/// Two sides on one piece (a cut inside a chart): their new chords must keep clear of each
/// other too.
fn crossing_each_other(rings: &[Vec<Ring>], at: [(usize, usize, usize); 2]) -> bool {
    let [(p, r, i), (p2, r2, j)] = at;
    if p != p2 || r != r2 {
        return false;
    }
    let ring = &rings[p][r];
    let (a, b) = (ring.prev[i], ring.next[i]);
    let (c, d) = (ring.prev[j], ring.next[j]);
    if j == a || j == b || i == c || i == d {
        // Adjacent: both go only if the ring keeps three vertices.
        return ring.count <= 4;
    }
    let shared = [a, b].iter().any(|x| *x == c || *x == d);
    if shared {
        return false;
    }
    polygon::segment_segment_distance(ring.pts[a], ring.pts[b], ring.pts[c], ring.pts[d])
        < CLEARANCE_MM
}

/// Strictly inside the triangle `a v b` (either orientation); points on its edges are not.
fn in_triangle(q: DVec2, a: DVec2, v: DVec2, b: DVec2) -> bool {
    let d1 = (v - a).perp_dot(q - a);
    let d2 = (b - v).perp_dot(q - v);
    let d3 = (a - b).perp_dot(q - b);
    (d1 > 0.0 && d2 > 0.0 && d3 > 0.0) || (d1 < 0.0 && d2 < 0.0 && d3 < 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::{Fold, FoldKind};

    /// Two 10 × 10 mm pieces side by side whose shared edge x = 10 runs through `chain`
    /// (bottom to top, ends at (10, 0) and (10, 10)) on the left piece and `chain_b` (same
    /// length) on the right one: one seam, side A on the left.
    fn two(chain: &[DVec2], chain_b: &[DVec2]) -> Vec<Piece> {
        let n = chain.len();
        let mut left = vec![DVec2::new(0.0, 0.0)];
        left.extend_from_slice(chain);
        left.push(DVec2::new(0.0, 10.0));
        let mut right = vec![DVec2::new(20.0, 0.0), DVec2::new(20.0, 10.0)];
        right.extend(chain_b.iter().rev());
        let mut a = Piece::from_outline(1, "1".into(), left.clone());
        let mut b = Piece::from_outline(2, "2".into(), right.clone());
        let side = |is_a: bool, partner: usize, first: usize, points: Vec<DVec2>| SeamSide {
            id: 1,
            is_a,
            partner,
            ring: 0,
            first,
            count: n - 1,
            length: super::super::marks::polyline_length(&points),
            length_3d: super::super::marks::polyline_length(&points),
            points,
            notches: Vec::new(),
            tab: false,
            split: false,
        };
        a.seams.push(side(true, 2, 1, chain.to_vec()));
        b.seams
            .push(side(false, 1, 2, chain_b.iter().rev().copied().collect()));
        vec![a, b]
    }

    fn zigzag(amp: f64) -> Vec<DVec2> {
        (0..=10)
            .map(|i| {
                let x = if i == 0 || i == 10 {
                    10.0
                } else if i % 2 == 1 {
                    10.0 + amp
                } else {
                    10.0 - amp
                };
                DVec2::new(x, i as f64)
            })
            .collect()
    }

    #[test]
    fn zigzag_seam_collapses_to_its_ends_on_both_sides() {
        let z = zigzag(0.1);
        let mut p = two(&z, &z);
        apply(&mut p, 0.5);
        for q in &p {
            let s = q.simplified.unwrap();
            assert_eq!(s.vertices_before, 13);
            assert_eq!(s.vertices_after, 4, "{:?}", q.border);
            assert!(s.max_deviation <= 0.5 && s.max_deviation > 0.09);
            assert!(s.max_seam_mismatch < 1e-12);
            assert_eq!(q.seams[0].count, 1);
            assert!((q.seams[0].length - 10.0).abs() < 1e-12);
            assert!(polygon::is_simple_ring(&q.border[0]));
        }
        assert_eq!(p[0].seams[0].points, vec![z[0], z[10]]);
        assert_eq!(p[1].seams[0].points, vec![z[10], z[0]]);
        // Renumbered: the chain still starts where the ring has its first point.
        assert_eq!(p[0].border[0][p[0].seams[0].first], z[0]);
        assert_eq!(p[1].border[0][p[1].seams[0].first], z[10]);
    }

    #[test]
    fn tolerance_below_the_zigzag_keeps_every_vertex() {
        let z = zigzag(0.1);
        let mut p = two(&z, &z);
        apply(&mut p, 0.05);
        assert_eq!(p[0].border[0].len(), 13);
        assert_eq!(p[1].border[0].len(), 13);
        // Off: nothing recorded, nothing touched.
        let mut q = two(&z, &z);
        apply(&mut q, 0.0);
        assert!(q[0].simplified.is_none());
        assert_eq!(q, two(&z, &z));
    }

    #[test]
    fn sides_stay_equally_long() {
        // Side B straight, side A a zigzag: every collapse shortens A only.
        let z = zigzag(0.3);
        let straight: Vec<DVec2> = (0..=10).map(|i| DVec2::new(10.0, i as f64)).collect();
        let mut p = two(&z, &straight);
        let before = p[0].seams[0].length - p[1].seams[0].length;
        assert!(before > 0.3);
        apply(&mut p, 1.0);
        let after = (p[0].seams[0].length - p[1].seams[0].length).abs();
        assert!(after <= before + 1e-12, "{before} -> {after}");
        assert_eq!(p[0].seams[0].count, p[1].seams[0].count);
        // Both sides lost the same vertices.
        let ys = |s: &SeamSide| {
            let mut v: Vec<i64> = s.points.iter().map(|q| q.y.round() as i64).collect();
            v.sort();
            v
        };
        assert_eq!(ys(&p[0].seams[0]), ys(&p[1].seams[0]));
    }

    #[test]
    fn holes_and_fold_ends_keep_their_vertex() {
        let chain = [
            DVec2::new(10.0, 0.0),
            DVec2::new(10.4, 5.0),
            DVec2::new(10.0, 10.0),
        ];
        let mut free = two(&chain, &chain);
        apply(&mut free, 0.5);
        assert_eq!(free[0].border[0].len(), 4);
        // A small hole in the triangle the collapse would cut off the left piece.
        let mut holed = two(&chain, &chain);
        holed[0].border.push(vec![
            DVec2::new(10.15, 4.8),
            DVec2::new(10.25, 5.0),
            DVec2::new(10.15, 5.2),
        ]);
        holed[0].border_edges.push(vec![9, 9, 9]);
        holed[0].border_faces.push(vec![0, 0, 0]);
        apply(&mut holed, 0.5);
        assert_eq!(holed[0].border[0].len(), 5);
        // A fold line ending at the vertex.
        let mut folded = two(&chain, &chain);
        folded[1].folds.push(Fold {
            a: chain[1],
            b: DVec2::new(15.0, 5.0),
            kind: FoldKind::Mountain,
            angle: 10f64.to_radians(),
            edge: 0,
            tab: false,
        });
        apply(&mut folded, 0.5);
        assert_eq!(folded[0].border[0].len(), 5);
        assert_eq!(folded[1].border[0].len(), 5);
    }
}
