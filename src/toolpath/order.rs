//! Travel optimisation inside one group of strokes: the pen-up moves between strokes made short.
//!
//! A group is a set of strokes whose order is free (the groups themselves follow the order rules
//! of [`super`]). The pen starts at a given point and the route ends anywhere (an open path,
//! not a tour). An open stroke may be cut in either direction; a closed one may start at any of
//! its vertices and ends where it started.
//!
//! 1. **Nearest neighbour**: from the pen, the nearest free entry point (either end of an open
//!    stroke, any vertex of a closed one), over a uniform grid so that thousands of strokes
//!    stay near O(n log n). This is vpype's `linesort` greedy sort, with reversal.
//! 2. **2-opt** (Johnson and McGeoch, "The traveling salesman problem: a case study in local
//!    optimization", 1997, §3: 2-opt with neighbour lists and don't-look bits left out): reversing
//!    the run of strokes at positions `i..=j` reverses each open stroke in it and replaces the
//!    travel edges `(exit[i-1], entry[i])` and `(exit[j], entry[j+1])` by `(exit[i-1], exit[j])`
//!    and `(entry[i], entry[j+1])`; the travel inside the run is unchanged. Candidate moves come
//!    from the `NEIGHBOURS` nearest stroke ends of each end (an improving move shortens at
//!    least one of its two edges, so one of its new edges joins two near neighbours), and a run
//!    is at most `WINDOW` strokes long, so a move costs O(WINDOW) at most.
//! 3. **Closed strokes re-pick their entry vertex**: the vertex that minimises the travel in and
//!    out, with the neighbours fixed. Steps 2 and 3 alternate for at most `ROUNDS` rounds.
//!
//! Choices where the sources are silent: the bounds are counts (`PASSES` sweeps of 2-opt per
//! round, `ROUNDS` rounds), never time, so that the result never depends on the machine's
//! load; a move must gain more than `EPS` mm; ties go to the lower index. The caller keeps the
//! group's original order when that travels less ([`order`] does).

use super::Stroke;
use glam::DVec2;

/// Nearest stroke ends considered per end.
pub(crate) const NEIGHBOURS: usize = 8;
/// Longest run of strokes one 2-opt move reverses.
pub(crate) const WINDOW: usize = 1000;
/// Sweeps over the sequence per round of 2-opt.
pub(crate) const PASSES: usize = 30;
/// Rounds of 2-opt + entry re-picking.
pub(crate) const ROUNDS: usize = 4;
/// Smallest gain (mm) a move must make.
pub(crate) const EPS: f64 = 1e-9;

/// Order `strokes` for short pen-up travel from `pen`; `pen` ends at the last stroke's end.
/// Returns the original order (untouched) when the optimised one is not shorter.
pub fn order(strokes: Vec<Stroke>, pen: &mut DVec2) -> Vec<Stroke> {
    order_with(strokes, pen, ROUNDS)
}

/// [`order`] with at most `rounds` rounds of 2-opt and entry re-picking (0: nearest neighbour
/// alone), for comparisons.
pub fn order_with(strokes: Vec<Stroke>, pen: &mut DVec2, rounds: usize) -> Vec<Stroke> {
    if strokes.is_empty() {
        return strokes;
    }
    let start = *pen;
    let original = travel_from(start, &strokes);
    let mut nodes = nearest_neighbour(&strokes, start);
    for _ in 0..rounds {
        let before = nodes_travel(&strokes, &nodes, start);
        two_opt(&strokes, &mut nodes, start);
        repick_entries(&strokes, &mut nodes, start);
        if nodes_travel(&strokes, &nodes, start) >= before - EPS {
            break;
        }
    }
    let optimised = nodes_travel(&strokes, &nodes, start);
    let out = if optimised < original {
        materialise(strokes, &nodes)
    } else {
        strokes
    };
    if let Some(last) = out.last().and_then(|s| s.points.last()) {
        *pen = *last;
    }
    out
}

/// Pen-up travel of strokes taken as they are, from `pen`.
pub(crate) fn travel_from(mut pen: DVec2, strokes: &[Stroke]) -> f64 {
    let mut total = 0.0;
    for s in strokes {
        if let (Some(first), Some(last)) = (s.points.first(), s.points.last()) {
            total += pen.distance(*first);
            pen = *last;
        }
    }
    total
}

/// A stroke in the route: which one, and how it is entered.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    stroke: usize,
    /// Open stroke: cut from its last point to its first. Closed: unused.
    rev: bool,
    /// Closed stroke: the vertex it starts and ends at.
    vertex: usize,
}

fn is_closed(s: &Stroke) -> bool {
    s.closed && s.points.len() > 1
}

fn entry(strokes: &[Stroke], n: Node) -> DVec2 {
    let p = &strokes[n.stroke].points;
    if is_closed(&strokes[n.stroke]) {
        p[n.vertex]
    } else if n.rev {
        p[p.len() - 1]
    } else {
        p[0]
    }
}

fn exit(strokes: &[Stroke], n: Node) -> DVec2 {
    let p = &strokes[n.stroke].points;
    if is_closed(&strokes[n.stroke]) {
        p[n.vertex]
    } else if n.rev {
        p[0]
    } else {
        p[p.len() - 1]
    }
}

fn nodes_travel(strokes: &[Stroke], nodes: &[Node], mut pen: DVec2) -> f64 {
    let mut total = 0.0;
    for &n in nodes {
        total += pen.distance(entry(strokes, n));
        pen = exit(strokes, n);
    }
    total
}

/// The strokes in route order, reversed or rotated as the route enters them.
fn materialise(strokes: Vec<Stroke>, nodes: &[Node]) -> Vec<Stroke> {
    let mut slots: Vec<Option<Stroke>> = strokes.into_iter().map(Some).collect();
    let mut out = Vec::with_capacity(nodes.len());
    for n in nodes {
        let Some(mut s) = slots[n.stroke].take() else {
            continue;
        };
        if is_closed(&s) {
            if n.vertex != 0 {
                s.points.pop();
                s.points.rotate_left(n.vertex);
                s.points.push(s.points[0]);
            }
        } else if n.rev {
            s.points.reverse();
        }
        out.push(s);
    }
    out
}

/// A uniform grid over points, for nearest-point queries.
struct Grid {
    lo: DVec2,
    cell: f64,
    nx: i64,
    ny: i64,
    cells: std::collections::HashMap<(i64, i64), Vec<usize>>,
}

impl Grid {
    fn new(points: &[DVec2]) -> Option<Grid> {
        let (lo, hi) = crate::geom::polygon::bounds(points.iter().copied())?;
        let extent = (hi - lo).max_element().max(1e-9);
        let cell = extent / (points.len() as f64).sqrt().max(1.0);
        let mut g = Grid {
            lo,
            cell,
            nx: ((hi.x - lo.x) / cell).floor() as i64,
            ny: ((hi.y - lo.y) / cell).floor() as i64,
            cells: Default::default(),
        };
        for (i, p) in points.iter().enumerate() {
            let k = g.key(*p);
            g.cells.entry(k).or_default().push(i);
        }
        Some(g)
    }

    fn key(&self, p: DVec2) -> (i64, i64) {
        (
            ((p.x - self.lo.x) / self.cell).floor() as i64,
            ((p.y - self.lo.y) / self.cell).floor() as i64,
        )
    }

    /// The `k` points nearest `p` that `keep` accepts, nearest first (ties: lower index).
    fn nearest(
        &self,
        points: &[DVec2],
        p: DVec2,
        k: usize,
        mut keep: impl FnMut(usize) -> bool,
    ) -> Vec<(f64, usize)> {
        // Clamped so that ring arithmetic cannot overflow for a far pen; a cell index moved
        // towards the grid only lowers the ring of every point, so the bound below stays true.
        const FAR: i64 = 1 << 40;
        let c = self.key(p);
        let c = (c.0.clamp(-FAR, FAR), c.1.clamp(-FAR, FAR));
        let max_r =
            (c.0.abs().max((c.0 - self.nx).abs())).max(c.1.abs().max((c.1 - self.ny).abs())) + 1;
        let mut best: Vec<(f64, usize)> = Vec::new();
        let mut offer = |i: usize, best: &mut Vec<(f64, usize)>| {
            if !keep(i) {
                return;
            }
            let d = p.distance(points[i]);
            if best.len() < k || (d, i) < best[k - 1] {
                let at = best.partition_point(|&b| b < (d, i));
                best.insert(at, (d, i));
                best.truncate(k);
            }
        };
        // Rings nearer than the grid's own cells are empty: start at the first that meets it.
        let gap = |v: i64, hi: i64| (-v).max(v - hi).max(0);
        let first = gap(c.0, self.nx).max(gap(c.1, self.ny));
        // A bound that does not depend on the coordinates: once the rings have looked at as
        // many cells as there are points, a plain scan of the points is cheaper.
        let mut looked = 0usize;
        for r in first..=max_r {
            if best.len() >= k {
                // Every point in ring r is at least (r - 1) cells away.
                if best[k - 1].0 < (r - 1) as f64 * self.cell {
                    break;
                }
            }
            let cells = self.ring(c, r);
            looked += cells.len();
            if looked > points.len() + 64 {
                best.clear();
                for i in 0..points.len() {
                    offer(i, &mut best);
                }
                return best;
            }
            for key in cells {
                if let Some(list) = self.cells.get(&key) {
                    for &i in list {
                        offer(i, &mut best);
                    }
                }
            }
        }
        best
    }

    /// The cells of ring `r` around `c` (Chebyshev distance `r`) that lie on the grid.
    fn ring(&self, c: (i64, i64), r: i64) -> Vec<(i64, i64)> {
        let (x0, x1) = ((c.0 - r).max(0), (c.0 + r).min(self.nx));
        let (y0, y1) = ((c.1 - r).max(0), (c.1 + r).min(self.ny));
        let mut out = Vec::new();
        if x0 > x1 || y0 > y1 {
            return out;
        }
        for y in [c.1 - r, c.1 + r] {
            if (0..=self.ny).contains(&y) {
                out.extend((x0..=x1).map(|x| (x, y)));
            }
            if r == 0 {
                return out;
            }
        }
        for x in [c.0 - r, c.0 + r] {
            if (0..=self.nx).contains(&x) {
                out.extend(((c.1 - r + 1).max(0)..=(c.1 + r - 1).min(self.ny)).map(|y| (x, y)));
            }
        }
        out
    }
}

/// Entry points of the strokes: (point, stroke, vertex) — both ends of an open stroke, every
/// vertex of a closed one.
pub(super) fn entry_points(strokes: &[Stroke]) -> Vec<(DVec2, usize, usize)> {
    let mut entries = Vec::new();
    for (k, s) in strokes.iter().enumerate() {
        if is_closed(s) {
            for (i, p) in s.points.iter().take(s.points.len() - 1).enumerate() {
                entries.push((*p, k, i));
            }
        } else if let Some(last) = s.points.len().checked_sub(1) {
            entries.push((s.points[0], k, 0));
            if last > 0 {
                entries.push((s.points[last], k, last));
            }
        }
    }
    entries
}

/// Greedy route from `pen`: always the nearest free entry point.
fn nearest_neighbour(strokes: &[Stroke], start: DVec2) -> Vec<Node> {
    let entries = entry_points(strokes);
    let points: Vec<DVec2> = entries.iter().map(|e| e.0).collect();
    let mut nodes = Vec::with_capacity(strokes.len());
    let Some(grid) = Grid::new(&points) else {
        // Strokes without points: keep them, in order.
        return (0..strokes.len())
            .map(|stroke| Node {
                stroke,
                rev: false,
                vertex: 0,
            })
            .collect();
    };
    let mut used = vec![false; strokes.len()];
    let mut pen = start;
    loop {
        let found = grid.nearest(&points, pen, 1, |i| !used[entries[i].1]);
        let Some(&(_, i)) = found.first() else {
            break;
        };
        let (_, k, v) = entries[i];
        used[k] = true;
        let node = if is_closed(&strokes[k]) {
            Node {
                stroke: k,
                rev: false,
                vertex: v,
            }
        } else {
            Node {
                stroke: k,
                rev: v != 0,
                vertex: 0,
            }
        };
        pen = exit(strokes, node);
        nodes.push(node);
    }
    // Strokes without points come last, in their order.
    for (k, u) in used.iter().enumerate() {
        if !u {
            nodes.push(Node {
                stroke: k,
                rev: false,
                vertex: 0,
            });
        }
    }
    nodes
}

/// Ends of each stroke as the route holds them now: open strokes both ends, closed strokes
/// their entry vertex. Returns their points, their ids (end id = 2 * stroke + (0: first point
/// side, 1: last point side)) and, per stroke, the indices of its (first, last) ends in them
/// (`usize::MAX` for a stroke without ends).
fn route_ends(strokes: &[Stroke], nodes: &[Node]) -> (Vec<DVec2>, Vec<usize>, Vec<(usize, usize)>) {
    let mut end_pts: Vec<DVec2> = Vec::with_capacity(2 * strokes.len());
    let mut end_ids: Vec<usize> = Vec::with_capacity(2 * strokes.len());
    let mut node_of = vec![usize::MAX; strokes.len()];
    for (pos, nd) in nodes.iter().enumerate() {
        node_of[nd.stroke] = pos;
    }
    for (k, s) in strokes.iter().enumerate() {
        if s.points.is_empty() || node_of[k] == usize::MAX {
            continue;
        }
        if is_closed(s) {
            end_pts.push(s.points[nodes[node_of[k]].vertex]);
            end_ids.push(2 * k);
        } else {
            end_pts.push(s.points[0]);
            end_ids.push(2 * k);
            end_pts.push(s.points[s.points.len() - 1]);
            end_ids.push(2 * k + 1);
        }
    }
    // Index into end_pts of a stroke's (first, last) ends.
    let mut ends_of = vec![(usize::MAX, usize::MAX); strokes.len()];
    for (i, &id) in end_ids.iter().enumerate() {
        let e = &mut ends_of[id / 2];
        if id % 2 == 0 {
            e.0 = i;
            if is_closed(&strokes[id / 2]) {
                e.1 = i;
            }
        } else {
            e.1 = i;
        }
    }
    (end_pts, end_ids, ends_of)
}

/// Neighbour-list 2-opt over the route (see the module documentation).
fn two_opt(strokes: &[Stroke], nodes: &mut [Node], start: DVec2) {
    let n = nodes.len();
    if n < 2 {
        return;
    }
    let (end_pts, end_ids, ends_of) = route_ends(strokes, nodes);
    let Some(grid) = Grid::new(&end_pts) else {
        return;
    };
    // Neighbour lists: the nearest ends of other strokes.
    let neighbours: Vec<Vec<usize>> = (0..end_pts.len())
        .map(|i| {
            let own = end_ids[i] / 2;
            grid.nearest(&end_pts, end_pts[i], NEIGHBOURS, |j| end_ids[j] / 2 != own)
                .into_iter()
                .map(|(_, j)| j)
                .collect()
        })
        .collect();
    let mut pos = vec![usize::MAX; strokes.len()];
    for (p, nd) in nodes.iter().enumerate() {
        pos[nd.stroke] = p;
    }
    // The end index (into end_pts) that is the entry / exit of a node.
    let entry_end = |nd: Node| {
        let (a, b) = ends_of[nd.stroke];
        if nd.rev {
            b
        } else {
            a
        }
    };
    let exit_end = |nd: Node| {
        let (a, b) = ends_of[nd.stroke];
        if nd.rev {
            a
        } else {
            b
        }
    };
    let x = |nodes: &[Node], i: usize| -> DVec2 {
        // exit of position i - 1, or the start for i = 0.
        if i == 0 {
            start
        } else {
            exit(strokes, nodes[i - 1])
        }
    };
    let e =
        |nodes: &[Node], i: usize| -> Option<DVec2> { nodes.get(i).map(|&nd| entry(strokes, nd)) };
    // Gain of reversing positions i..=j (negative: shorter).
    let delta = |nodes: &[Node], i: usize, j: usize| -> f64 {
        let a = x(nodes, i);
        let ei = entry(strokes, nodes[i]);
        let xj = exit(strokes, nodes[j]);
        let mut d = a.distance(xj) - a.distance(ei);
        if let Some(next) = e(nodes, j + 1) {
            d += ei.distance(next) - xj.distance(next);
        }
        d
    };
    let usable = |nd: Node| ends_of[nd.stroke].0 != usize::MAX;
    for _ in 0..PASSES {
        let mut improved = false;
        for i in 0..n {
            if !usable(nodes[i]) {
                continue;
            }
            // Candidate runs (lo, hi) to reverse.
            let mut cands: Vec<(usize, usize)> = Vec::new();
            // From the exit before i: a near exit of a later node j gives the run i..=j; a near
            // exit of an earlier node k gives the run k+1..=i-1.
            if i > 0 && usable(nodes[i - 1]) {
                for &q in &neighbours[exit_end(nodes[i - 1])] {
                    let t = end_ids[q] / 2;
                    let j = pos[t];
                    if exit_end(nodes[j]) != q {
                        continue;
                    }
                    if j >= i {
                        cands.push((i, j));
                    } else if j + 1 < i {
                        cands.push((j + 1, i - 1));
                    }
                }
            }
            // From the entry of i: a near entry of node k.
            for &q in &neighbours[entry_end(nodes[i])] {
                let t = end_ids[q] / 2;
                let k = pos[t];
                if entry_end(nodes[k]) != q {
                    continue;
                }
                if k < i {
                    cands.push((k, i - 1));
                } else if k > i {
                    cands.push((i, k - 1));
                }
            }
            let mut best: Option<(f64, usize, usize)> = None;
            for (lo, hi) in cands {
                if hi < lo || hi - lo + 1 > WINDOW {
                    continue;
                }
                let d = delta(nodes, lo, hi);
                if d < -EPS && best.is_none_or(|b| (d, lo, hi) < b) {
                    best = Some((d, lo, hi));
                }
            }
            if let Some((_, lo, hi)) = best {
                nodes[lo..=hi].reverse();
                for (p, nd) in nodes[lo..=hi].iter_mut().enumerate() {
                    nd.rev = !nd.rev;
                    pos[nd.stroke] = lo + p;
                }
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    // Closed strokes: `rev` means nothing; keep it false.
    for nd in nodes.iter_mut() {
        if is_closed(&strokes[nd.stroke]) {
            nd.rev = false;
        }
    }
}

/// Each closed stroke starts at the vertex nearest the way in and out.
fn repick_entries(strokes: &[Stroke], nodes: &mut [Node], start: DVec2) {
    for i in 0..nodes.len() {
        let s = &strokes[nodes[i].stroke];
        if !is_closed(s) {
            continue;
        }
        let before = if i == 0 {
            start
        } else {
            exit(strokes, nodes[i - 1])
        };
        let after = nodes.get(i + 1).map(|&nd| entry(strokes, nd));
        let cost = |p: DVec2| before.distance(p) + after.map_or(0.0, |a| p.distance(a));
        let mut best = (cost(s.points[nodes[i].vertex]), nodes[i].vertex);
        for (v, p) in s.points.iter().take(s.points.len() - 1).enumerate() {
            let c = cost(*p);
            if c < best.0 - EPS {
                best = (c, v);
            }
        }
        nodes[i].vertex = best.1;
    }
}

#[cfg(test)]
mod tests {
    use super::super::StrokeRole;
    use super::*;

    fn open(a: (f64, f64), b: (f64, f64)) -> Stroke {
        Stroke {
            role: StrokeRole::Mark,
            points: vec![DVec2::new(a.0, a.1), DVec2::new(b.0, b.1)],
            closed: false,
            piece: None,
            outer: false,
        }
    }

    #[test]
    fn nearest_neighbour_chains_and_reverses() {
        let strokes = vec![
            open((100.0, 0.0), (90.0, 0.0)),
            open((12.0, 0.0), (50.0, 0.0)),
            open((1.0, 0.0), (10.0, 0.0)),
        ];
        let before = travel_from(DVec2::ZERO, &strokes);
        let mut pen = DVec2::ZERO;
        let out = order(strokes, &mut pen);
        assert_eq!(out.len(), 3);
        assert_eq!(out[0].points[0], DVec2::new(1.0, 0.0));
        assert_eq!(out[1].points[0], DVec2::new(12.0, 0.0));
        assert_eq!(out[2].points[0], DVec2::new(90.0, 0.0));
        assert!((travel_from(DVec2::ZERO, &out) - (1.0 + 2.0 + 40.0)).abs() < 1e-12);
        assert!(travel_from(DVec2::ZERO, &out) < before);
        assert_eq!(pen, DVec2::new(100.0, 0.0));
    }

    #[test]
    fn closed_stroke_starts_at_nearest_vertex() {
        let ring = Stroke {
            role: StrokeRole::Cut,
            points: [
                (0.0, 0.0),
                (10.0, 0.0),
                (10.0, 10.0),
                (0.0, 10.0),
                (0.0, 0.0),
            ]
            .iter()
            .map(|p| DVec2::new(p.0, p.1))
            .collect(),
            closed: true,
            piece: None,
            outer: false,
        };
        let mut pen = DVec2::new(11.0, 11.0);
        let out = order(vec![ring.clone()], &mut pen);
        assert_eq!(out[0].points[0], DVec2::new(10.0, 10.0));
        assert_eq!(out[0].points.last(), Some(&DVec2::new(10.0, 10.0)));
        assert!((out[0].length() - ring.length()).abs() < 1e-12);
    }

    /// Nearest neighbour on scattered strokes leaves long ways back; 2-opt shortens them.
    #[test]
    fn two_opt_beats_nearest_neighbour_and_keeps_every_stroke() {
        // 300 short strokes scattered over 100 × 100 mm by the seeded generator.
        let mut rng = crate::geom::rng::Rng::new(7);
        let mut next = || rng.f64();
        let strokes: Vec<Stroke> = (0..300)
            .map(|_| {
                let (x, y) = (100.0 * next(), 100.0 * next());
                let (dx, dy) = (4.0 * next() - 2.0, 4.0 * next() - 2.0);
                open((x, y), (x + dx, y + dy))
            })
            .collect();
        let nn = nearest_neighbour(&strokes, DVec2::ZERO);
        let nn_travel = nodes_travel(&strokes, &nn, DVec2::ZERO);
        let mut pen = DVec2::ZERO;
        let out = order(strokes.clone(), &mut pen);
        let opt = travel_from(DVec2::ZERO, &out);
        assert!(opt < 0.95 * nn_travel, "{opt} vs {nn_travel}");
        assert!(opt <= travel_from(DVec2::ZERO, &strokes));
        assert_eq!(out.len(), strokes.len());
        let mut a: Vec<String> = out.iter().map(|s| format!("{:?}", s.length())).collect();
        let mut b: Vec<String> = strokes
            .iter()
            .map(|s| format!("{:?}", s.length()))
            .collect();
        a.sort();
        b.sort();
        assert_eq!(a, b);
        // Same input, same output.
        let mut pen2 = DVec2::ZERO;
        assert_eq!(order(strokes, &mut pen2), out);
    }

    #[test]
    fn keeps_the_original_order_when_shorter() {
        let strokes = vec![open((0.0, 0.0), (1.0, 0.0)), open((1.0, 0.0), (2.0, 0.0))];
        let mut pen = DVec2::ZERO;
        let out = order(strokes.clone(), &mut pen);
        assert_eq!(out, strokes);
    }
}
