//! Partitioning an island that does not fit the sheet into parts that do ([`partition`], for
//! [`super::build_to_fit`]).
//!
//! **How** (the issue asks for few parts, straight and short seams, parts of similar size;
//! the choices below are ours). The faces of the island are put in a sequence, in several
//! ways: by their centroids along each of 12 directions 15° apart and along the axes of the
//! island's minimum-area rectangle (ties broken along the perpendicular, so a sequence sweeps
//! a straight front across the piece), and by their distance through joined edges from one end
//! of the island (on a strip — a path of faces between rulings — that is the order along the
//! strip, and every cut is one ruling). A partition is a cut of the sequence into runs; the
//! parts are the runs' connected pieces. For each sequence the greedy partition (each run as
//! long as fits) gives the fewest runs K that sequence allows; the runs are then balanced to
//! equal areas (each cut moved, within a quarter of a part's area, to where its seam costs
//! least). A part under 1 % of the whole surface's area (issue 20's bound for a piece; the
//! tip of a piece a run ends on, a piece of a run cut off from the rest) then takes faces from
//! the parts beside it while it fits and they stay whole and not small; an island whose parts
//! came out too large once built is partitioned again without this, grown parts being the
//! likelier to. Of all feasible partitions the one with fewest parts wins, then the one with
//! fewest parts over the stretch limit, then with fewest small parts, then the lowest cost:
//! the seams' length over the square root of a part's area (edges where the surface does not
//! bend — the diagonal of a flat quad, of a cone's planar strip between two rulings — and that
//! are no named bend line count double, so seams run along folds and rulings), plus twice the
//! largest part's excess area over the mean. On a large cone this gives what a shop lays out:
//! equal segments joined along rulings, each with its own bend lines.

use super::{rect_angles, rect_size, turned_overflow, Room};
use crate::flatten::Flat;
use crate::geom::polygon;
use crate::pattern::{PatternError, PatternOptions};
use glam::DVec2;
use std::collections::{BTreeSet, HashMap, HashSet};

/// Below this bend (0.01°, as the strips' bend lines) an interior edge is flat: a seam there
/// would cross a panel rather than follow a line of the surface.
const BENDS_RAD: f64 = 0.01 * std::f64::consts::PI / 180.0;

/// How large the parts of an island are made.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sizes {
    /// What the material adds around a part at most (mm): each part's faces must fit the room
    /// shrunk by it on every side (a single face need only fit the room).
    pub(super) grow: f64,
    /// Area (mm²) under which a part is small (`grow_small`).
    pub(super) small: f64,
    /// Whether small parts are grown (`grow_small`).
    pub(super) grow_small: bool,
}

/// One island being split: its faces (local indices), their centroids, areas and corners,
/// and the joined edges between them with their seam cost.
struct Island<'a> {
    flat: &'a Flat,
    faces: &'a [usize],
    centroid: Vec<DVec2>,
    area: Vec<f64>,
    adj: Vec<Vec<usize>>,
    /// (u, v, cost) with u < v: a joined edge, its length doubled where it is not a line of
    /// the surface (where it does not bend and is no named bend line).
    links: Vec<(usize, usize, f64)>,
    grain: bool,
    room: Room,
    sizes: Sizes,
    /// [`PatternOptions::stretch_limit`], for an island laid out from charts.
    limit: Option<f64>,
    /// Every face's corners with the face (local), sorted by x then y: the hull of a large
    /// set of faces is taken from it without sorting again.
    sorted: Vec<(DVec2, usize)>,
}

impl<'a> Island<'a> {
    fn new(
        flat: &'a Flat,
        faces: &'a [usize],
        opts: &PatternOptions,
        room: &Room,
        sizes: Sizes,
    ) -> Self {
        let n = faces.len();
        let mut local = HashMap::new();
        for (i, &f) in faces.iter().enumerate() {
            local.insert(f, i);
        }
        // Lines of the surface: where it bends at all, or a bend line it names.
        let named = crate::pattern::bends::fold_angles(flat, opts.fold_threshold_deg.to_radians());
        let mut adj = vec![Vec::new(); n];
        let mut links = Vec::new();
        for (u, &f) in faces.iter().enumerate() {
            for (i, &e) in flat.topology.face_edges[f].iter().enumerate() {
                let edge = &flat.topology.edges[e];
                if !flat.joined[e] || edge.uses.len() != 2 || edge.uses[0] != (f, i) {
                    continue;
                }
                let Some(&v) = local.get(&edge.uses[1].0) else {
                    continue;
                };
                if v == u {
                    continue;
                }
                let (a, b) = flat.corner_edge(f, i);
                let line = named[e].is_some() || flat.dihedral[e].abs() > BENDS_RAD;
                let cost = a.distance(b) * if line { 1.0 } else { 2.0 };
                adj[u].push(v);
                adj[v].push(u);
                links.push((u.min(v), u.max(v), cost));
            }
        }
        let centroid = faces
            .iter()
            .map(|&f| {
                let c = &flat.face_2d[f];
                c.iter().copied().sum::<DVec2>() / c.len().max(1) as f64
            })
            .collect();
        let area = faces
            .iter()
            .map(|&f| flat.surface.mesh.face_area(f))
            .collect();
        let mut sorted: Vec<(DVec2, usize)> = faces
            .iter()
            .enumerate()
            .flat_map(|(u, &f)| flat.face_2d[f].iter().map(move |&p| (p, u)))
            .filter(|(p, _)| p.is_finite())
            .collect();
        sorted.sort_by(|a, b| a.0.x.total_cmp(&b.0.x).then(a.0.y.total_cmp(&b.0.y)));
        Island {
            flat,
            faces,
            centroid,
            area,
            adj,
            links,
            grain: opts.grain,
            room: *room,
            sizes,
            limit: opts.stretch_limit.filter(|_| flat.surface.charts.is_some()),
            sorted,
        }
    }

    /// Whether a part (local faces) stretches by more than [`Island::limit`] as laid.
    fn over_limit(&self, part: &[usize]) -> bool {
        let Some(limit) = self.limit else {
            return false;
        };
        let faces: Vec<usize> = part.iter().map(|&u| self.faces[u]).collect();
        let uv: Vec<Vec<DVec2>> = faces
            .iter()
            .map(|&f| self.flat.face_2d[f].clone())
            .collect();
        crate::flatten::distortion::stretch(&self.flat.surface.mesh, &faces, &uv).l2 > limit
    }

    /// Overflow (mm) of a set of local faces, grown by `self.sizes.grow` unless it is one face.
    fn overflow(&self, set: &[usize]) -> f64 {
        // Its hull: a large set's from the corners sorted once, a small one's by sorting its
        // own. The box of the hull is the box of the set.
        let pts = if set.len() * 8 < self.faces.len() {
            let pts: Vec<DVec2> = set
                .iter()
                .flat_map(|&u| self.flat.face_2d[self.faces[u]].iter().copied())
                .collect();
            polygon::convex_hull(&pts)
        } else {
            let mut inside = vec![false; self.faces.len()];
            for &u in set {
                inside[u] = true;
            }
            let pts = self
                .sorted
                .iter()
                .filter(|(_, u)| inside[*u])
                .map(|(p, _)| *p);
            polygon::hull_of_sorted(pts.collect())
        };
        let grow = if set.len() == 1 { 0.0 } else { self.sizes.grow };
        let angles = rect_angles(polygon::hull_rect_angle(&pts), self.grain);
        let room = Room {
            width: self.room.width - 2.0 * grow,
            height: self.room.height.map(|h| h - 2.0 * grow),
        };
        // A part of several faces fits at the quarter turns the nest packs best; a face on its
        // own, which cannot be split further, may also fit turned between them.
        turned_overflow(&pts, &angles, &room, set.len() == 1 && !self.grain)
    }

    /// Connected pieces (through joined edges) of a set of local faces, each in set order.
    fn components(&self, set: &[usize], stamp: &mut [usize], mark: usize) -> Vec<Vec<usize>> {
        for &u in set {
            stamp[u] = mark;
        }
        let mut out = Vec::new();
        let done = mark + 1;
        for &u0 in set {
            if stamp[u0] != mark {
                continue;
            }
            stamp[u0] = done;
            let mut comp = vec![u0];
            let mut i = 0;
            while i < comp.len() {
                let u = comp[i];
                i += 1;
                for &v in &self.adj[u] {
                    if stamp[v] == mark {
                        stamp[v] = done;
                        comp.push(v);
                    }
                }
            }
            comp.sort_unstable();
            out.push(comp);
        }
        out
    }

    /// The sequences of faces the partitions cut (see the module docs), without repeats.
    fn orders(&self) -> Vec<Vec<usize>> {
        let n = self.faces.len();
        let (lo, hi) = polygon::bounds(self.centroid.iter().copied()).unwrap_or_default();
        let quantum = 1e-6 * (hi - lo).length().max(1e-9);
        let mut dirs: Vec<DVec2> = (0..12)
            .map(|j| DVec2::from_angle(j as f64 * std::f64::consts::PI / 12.0))
            .collect();
        let a = polygon::min_area_rect_angle(&self.centroid);
        let axis = DVec2::from_angle(-a);
        dirs.push(axis);
        dirs.push(axis.perp());
        let mut out: Vec<Vec<usize>> = Vec::new();
        for d in dirs {
            let mut order: Vec<usize> = (0..n).collect();
            let key = |u: usize| {
                let c = self.centroid[u];
                ((c.dot(d) / quantum).round() as i64, c.perp_dot(d))
            };
            order.sort_by(|&u, &v| {
                let (a, b) = (key(u), key(v));
                a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)).then(u.cmp(&v))
            });
            out.push(order);
        }
        // Through joined edges from one end: the face farthest from face 0, then the order
        // of distance from it (ties along the line between the two ends).
        let far = |s: usize| -> (Vec<usize>, usize) {
            let mut dist = vec![usize::MAX; n];
            dist[s] = 0;
            let mut queue = std::collections::VecDeque::from([s]);
            let mut last = s;
            while let Some(u) = queue.pop_front() {
                last = u;
                for &v in &self.adj[u] {
                    if dist[v] == usize::MAX {
                        dist[v] = dist[u] + 1;
                        queue.push_back(v);
                    }
                }
            }
            (dist, last)
        };
        if n > 0 {
            let (_, end) = far(0);
            let (dist, other) = far(end);
            let d = (self.centroid[other] - self.centroid[end]).normalize_or_zero();
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&u, &v| {
                dist[u]
                    .cmp(&dist[v])
                    .then(self.centroid[u].dot(d).total_cmp(&self.centroid[v].dot(d)))
                    .then(u.cmp(&v))
            });
            out.push(order);
        }
        let mut seen = HashSet::new();
        out.retain(|o| seen.insert(o.clone()));
        out
    }
}

/// Partition of one island into parts (global face ids) that each fit, estimated with
/// `grow`; a single face that does not fit on its own is [`PatternError::TooLarge`].
pub(super) fn partition(
    flat: &Flat,
    faces: &[usize],
    opts: &PatternOptions,
    room: &Room,
    island: usize,
    sizes: Sizes,
) -> Result<Vec<Vec<usize>>, PatternError> {
    let isl = Island::new(flat, faces, opts, room, sizes);
    for u in 0..faces.len() {
        if isl.overflow(&[u]) > 0.0 {
            return Err(face_too_large(&isl, u, island));
        }
    }
    let total: f64 = isl.area.iter().sum();
    let n = faces.len();
    let orders = isl.orders();
    // Each order's greedy partition and its number of runs, then the balanced ones; the
    // orders in parallel, the partitions considered in the orders' order.
    let greedy = crate::geom::par::map(orders.iter().collect(), &[], &|order: &Vec<usize>| {
        greedy(&isl, order)
    });
    let k_min = greedy.iter().map(|g| g.0).min().unwrap_or(1);
    let mut jobs = Vec::new();
    for (order, &(k_own, _)) in orders.iter().zip(&greedy) {
        jobs.push((order, k_min));
        if k_own != k_min {
            jobs.push((order, k_own));
        }
    }
    let mut best: Best = None;
    for parts in greedy.into_iter().filter_map(|g| g.1) {
        consider(&isl, parts, total, &mut best);
    }
    let balanced = crate::geom::par::map(jobs, &[], &|(order, k): (&Vec<usize>, usize)| {
        let cuts = balanced(&isl, order, k, total);
        Runs::new(n)
            .parts(&isl, order, &cuts)
            .map(|parts| grow_small(&isl, merge(&isl, parts)))
    });
    for parts in balanced.into_iter().flatten() {
        consider(&isl, parts, total, &mut best);
    }
    let parts = best
        .map(|(_, p)| p)
        .unwrap_or_else(|| vec![(0..n).collect()]);
    Ok(parts
        .into_iter()
        .map(|p| p.into_iter().map(|u| faces[u]).collect())
        .collect())
}

/// The parts of runs of an order, as [`partition`] cuts them: stamps for
/// [`Island::components`], fresh for each run.
struct Runs {
    stamp: Vec<usize>,
    mark: usize,
}

impl Runs {
    fn new(n: usize) -> Runs {
        Runs {
            stamp: vec![0; n],
            mark: 1,
        }
    }

    /// The runs [cuts[i], cuts[i + 1]) of `order`, as parts (each run's connected pieces) if
    /// each fits.
    fn parts(&mut self, isl: &Island, order: &[usize], cuts: &[usize]) -> Option<Vec<Vec<usize>>> {
        let mut parts = Vec::new();
        for w in cuts.windows(2) {
            self.mark += 2;
            for comp in isl.components(&order[w[0]..w[1]], &mut self.stamp, self.mark) {
                if isl.overflow(&comp) > 0.0 {
                    return None;
                }
                parts.push(comp);
            }
        }
        Some(parts)
    }
}

/// The greedy partition of an order (each run as long as fits, by binary search on its end):
/// its number of runs, and its parts merged and grown ([`merge`], [`grow_small`]) when they
/// fit.
fn greedy(isl: &Island, order: &[usize]) -> (usize, Option<Vec<Vec<usize>>>) {
    let n = order.len();
    let mut runs = Runs::new(n);
    let mut cuts = vec![0];
    let mut s = 0;
    while s < n {
        let mut ok = |t: usize| runs.parts(isl, order, &[s, t]).is_some();
        let t = if ok(n) {
            n
        } else {
            // ok(lo) holds (every face fits alone, checked before), ok(hi) does not.
            let (mut lo, mut hi) = (s + 1, n);
            while hi - lo > 1 {
                let mid = (lo + hi) / 2;
                if ok(mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        cuts.push(t);
        s = t;
    }
    let parts = runs
        .parts(isl, order, &cuts)
        .map(|parts| grow_small(isl, merge(isl, parts)));
    (cuts.len() - 1, parts)
}

/// Fewer parts: the smallest part that can join a neighbour (through a joined edge) and
/// still fit does, into the neighbour it shares the longest seam with, until none can. A run
/// of a sequence can fall apart into pieces, and a small one is better joined to another.
///
/// A run can fall apart into thousands of pieces (a piece much larger than the sheet), so the
/// parts keep their places (a joined pair in the first one's), the seams between them are
/// summed once and again only round a union (over its links in the island's order, so the
/// sums are those a fresh count gives), and a pair of parts whose union does not fit is not
/// measured again while neither has changed (whether a set fits depends on its faces only).
fn merge(isl: &Island, parts: Vec<Vec<usize>>) -> Vec<Vec<usize>> {
    let n = isl.faces.len();
    let mut links_of: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, &(u, v, _)) in isl.links.iter().enumerate() {
        links_of[u].push(i);
        links_of[v].push(i);
    }
    let mut slot_of = vec![usize::MAX; n];
    for (k, p) in parts.iter().enumerate() {
        for &u in p {
            slot_of[u] = k;
        }
    }
    let sum_area = |p: &[usize]| p.iter().map(|&u| isl.area[u]).sum::<f64>();
    let mut area: Vec<f64> = parts.iter().map(|p| sum_area(p)).collect();
    let mut by_size: BTreeSet<BySize> = (0..parts.len()).map(|k| BySize(area[k], k)).collect();
    // Per part: its neighbours and the seam length shared with each.
    let mut seams: Vec<Vec<(usize, f64)>> = vec![Vec::new(); parts.len()];
    let add = |seams: &mut Vec<(usize, f64)>, other: usize, c: f64| match seams
        .iter_mut()
        .find(|x| x.0 == other)
    {
        Some(x) => x.1 += c,
        None => seams.push((other, c)),
    };
    for &(u, v, c) in &isl.links {
        let (pu, pv) = (slot_of[u], slot_of[v]);
        if pu != pv && pu != usize::MAX && pv != usize::MAX {
            add(&mut seams[pu], pv, c);
            add(&mut seams[pv], pu, c);
        }
    }
    // A part's identity while it is unchanged, and the pairs of them that do not fit.
    let mut ids: Vec<usize> = (0..parts.len()).collect();
    let mut next_id = parts.len();
    let mut too_large: HashSet<(usize, usize)> = HashSet::new();
    let mut parts: Vec<Option<Vec<usize>>> = parts.into_iter().map(Some).collect();
    loop {
        let mut joined = None;
        'parts: for &BySize(_, k) in &by_size {
            // Neighbours by shared seam length, longest first.
            let near = &mut seams[k];
            near.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            for &(j, _) in near.iter() {
                let pair = (ids[k].min(ids[j]), ids[k].max(ids[j]));
                if too_large.contains(&pair) {
                    continue;
                }
                let (Some(pk), Some(pj)) = (&parts[k], &parts[j]) else {
                    continue;
                };
                let mut union = pk.clone();
                union.extend_from_slice(pj);
                if isl.overflow(&union) <= 0.0 {
                    joined = Some((k, j, union));
                    break 'parts;
                }
                too_large.insert(pair);
            }
        }
        let Some((k, j, mut union)) = joined else {
            return parts.into_iter().flatten().collect();
        };
        union.sort_unstable();
        let (keep, drop) = (k.min(j), k.max(j));
        by_size.remove(&BySize(area[k], k));
        by_size.remove(&BySize(area[j], j));
        for &u in &union {
            slot_of[u] = keep;
        }
        // The union's seams over its links in the island's order.
        let mut mine: Vec<usize> = union
            .iter()
            .flat_map(|&u| links_of[u].iter().copied())
            .collect();
        mine.sort_unstable();
        mine.dedup();
        let mut around: Vec<(usize, f64)> = Vec::new();
        for i in mine {
            let (u, v, c) = isl.links[i];
            let (pu, pv) = (slot_of[u], slot_of[v]);
            if pu != pv && pu != usize::MAX && pv != usize::MAX {
                add(&mut around, if pu == keep { pv } else { pu }, c);
            }
        }
        for &(o, c) in &around {
            seams[o].retain(|x| x.0 != k && x.0 != j);
            seams[o].push((keep, c));
        }
        seams[keep] = around;
        seams[drop].clear();
        area[keep] = sum_area(&union);
        parts[keep] = Some(union);
        parts[drop] = None;
        ids[keep] = next_id;
        next_id += 1;
        by_size.insert(BySize(area[keep], keep));
    }
}

/// A part in [`merge`]'s order: by area, then by place.
#[derive(Clone, Copy)]
struct BySize(f64, usize);

impl PartialEq for BySize {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for BySize {}

impl PartialOrd for BySize {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for BySize {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

/// Small parts grown: a part under [`Sizes::small`] (a run of a sequence that ends on a tip
/// of the piece, or a piece of a run cut off from the rest) takes faces from the parts next to
/// it, one at a time, until it is no longer small, as long as it still fits with the growth
/// estimate to spare (a grown part's border is ragged, and the outline built on it reaches
/// further) and the part the face leaves stays connected and not small. The face taken is the
/// one with the most edges on the small part, then the nearest its centroid, so the part grows
/// round rather than along its border; a part that can take none stays as it is.
fn grow_small(isl: &Island, mut parts: Vec<Vec<usize>>) -> Vec<Vec<usize>> {
    let n = isl.faces.len();
    let area = |p: &[usize]| p.iter().map(|&u| isl.area[u]).sum::<f64>();
    let mut small: Vec<usize> = (0..parts.len())
        .filter(|&k| area(&parts[k]) < isl.sizes.small)
        .collect();
    if small.is_empty() || parts.len() < 2 || !isl.sizes.grow_small {
        return parts;
    }
    small.sort_by(|&a, &b| area(&parts[a]).total_cmp(&area(&parts[b])).then(a.cmp(&b)));
    let mut part_of = vec![0; n];
    for (k, p) in parts.iter().enumerate() {
        for &u in p {
            part_of[u] = k;
        }
    }
    let mut stamp = vec![0usize; n];
    let mut mark = 1;
    for k in small {
        let mut have = area(&parts[k]);
        while have < isl.sizes.small {
            let centre = parts[k]
                .iter()
                .map(|&u| isl.centroid[u] * isl.area[u])
                .sum::<DVec2>()
                / have.max(1e-300);
            // Faces next to the part: (face, edges on the part, distance to its centre).
            let mut cands: Vec<(usize, usize, f64)> = Vec::new();
            for &u in &parts[k] {
                for &v in &isl.adj[u] {
                    if part_of[v] == k {
                        continue;
                    }
                    match cands.iter_mut().find(|c| c.0 == v) {
                        Some(c) => c.1 += 1,
                        None => cands.push((v, 1, isl.centroid[v].distance(centre))),
                    }
                }
            }
            cands.sort_by(|a, b| b.1.cmp(&a.1).then(a.2.total_cmp(&b.2)).then(a.0.cmp(&b.0)));
            let mut took = None;
            for &(v, _, _) in &cands {
                let j = part_of[v];
                if area(&parts[j]) - isl.area[v] < isl.sizes.small {
                    continue;
                }
                let mut grown = parts[k].clone();
                grown.push(v);
                if isl.overflow(&grown) > -isl.sizes.grow {
                    continue;
                }
                let rest: Vec<usize> = parts[j].iter().copied().filter(|&u| u != v).collect();
                mark += 2;
                if isl.components(&rest, &mut stamp, mark).len() != 1 {
                    continue;
                }
                took = Some((v, j, grown, rest));
                break;
            }
            let Some((v, j, grown, rest)) = took else {
                break;
            };
            part_of[v] = k;
            have += isl.area[v];
            parts[k] = grown;
            parts[j] = rest;
        }
        parts[k].sort_unstable();
    }
    parts
}

/// The best partition so far: (number of parts, parts over the stretch limit, small parts,
/// cost) and the parts.
type Best = Option<((usize, usize, usize, f64), Vec<Vec<usize>>)>;

/// Keep `parts` if it beats the best so far: fewer parts, then fewer parts over the stretch
/// limit (a part of a layout can stretch more than the whole), then fewer small parts (under
/// [`Sizes::small`]), then a lower cost (seam length over a part's typical size, twice the
/// largest part's excess area over the mean).
fn consider(isl: &Island, parts: Vec<Vec<usize>>, total: f64, best: &mut Best) {
    let mut part_of = vec![0; isl.faces.len()];
    for (k, p) in parts.iter().enumerate() {
        for &u in p {
            part_of[u] = k;
        }
    }
    let mean = total / parts.len() as f64;
    let seam: f64 = isl
        .links
        .iter()
        .filter(|(u, v, _)| part_of[*u] != part_of[*v])
        .map(|l| l.2)
        .sum();
    let largest = parts
        .iter()
        .map(|p| p.iter().map(|&u| isl.area[u]).sum::<f64>())
        .fold(0.0, f64::max);
    let cost = seam / mean.sqrt().max(1e-9) + 2.0 * (largest / mean.max(1e-300) - 1.0);
    let over = parts.iter().filter(|p| isl.over_limit(p)).count();
    let small = parts
        .iter()
        .filter(|p| p.iter().map(|&u| isl.area[u]).sum::<f64>() < isl.sizes.small)
        .count();
    let score = (parts.len(), over, small, cost);
    let better = match best {
        None => true,
        Some((s, _)) => {
            (score.0, score.1, score.2) < (s.0, s.1, s.2)
                || ((score.0, score.1, score.2) == (s.0, s.1, s.2) && score.3 < s.3 - 1e-12)
        }
    };
    if better {
        *best = Some((score, parts));
    }
}

/// Cuts of an order into `k` runs of about equal area, each cut moved within a quarter of a
/// run's area to where the edges it crosses cost least.
fn balanced(isl: &Island, order: &[usize], k: usize, total: f64) -> Vec<usize> {
    let n = order.len();
    let mut rank = vec![0; n];
    for (r, &u) in order.iter().enumerate() {
        rank[u] = r;
    }
    // Area before position q, and the cost of the edges a cut at q crosses.
    let mut before = vec![0.0; n + 1];
    for (r, &u) in order.iter().enumerate() {
        before[r + 1] = before[r] + isl.area[u];
    }
    let mut diff = vec![0.0; n + 2];
    for &(u, v, c) in &isl.links {
        let (a, b) = (rank[u].min(rank[v]), rank[u].max(rank[v]));
        diff[a + 1] += c;
        diff[b + 1] -= c;
    }
    let mut crossing = vec![0.0; n + 1];
    let mut acc = 0.0;
    for q in 0..=n {
        acc += diff[q];
        crossing[q] = acc;
    }
    let share = total / k as f64;
    let size = share.sqrt().max(1e-9);
    let mut cuts = vec![0];
    for j in 1..k {
        let target = share * j as f64;
        let prev = *cuts.last().unwrap_or(&0);
        let q = (prev + 1..n)
            .filter(|&q| (before[q] - target).abs() <= 0.25 * share)
            .min_by(|&a, &b| {
                let f = |q: usize| crossing[q] / size + 2.0 * (before[q] - target).abs() / share;
                f(a).total_cmp(&f(b)).then(a.cmp(&b))
            })
            .unwrap_or_else(|| {
                (prev + 1..n)
                    .min_by(|&a, &b| {
                        (before[a] - target)
                            .abs()
                            .total_cmp(&(before[b] - target).abs())
                    })
                    .unwrap_or(n)
            });
        if q >= n {
            break;
        }
        cuts.push(q);
    }
    cuts.push(n);
    cuts
}

/// The error for face `u` of an island, too large for the room on its own.
fn face_too_large(isl: &Island, u: usize, island: usize) -> PatternError {
    let f = isl.faces[u];
    let size = rect_size(&isl.flat.face_2d[f]);
    PatternError::TooLarge {
        surface: isl.flat.surface.name.clone(),
        piece: format!("{}", island + 1),
        face: f + 1,
        w: size.x.max(size.y),
        h: size.x.min(size.y),
        what: isl.room.what(),
        uw: isl.room.width,
        uh: isl.room.height_text(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::{unfold, UnfoldOptions};
    use crate::pattern::split::tests::row_of_squares;

    /// A row of 40 squares of 10 mm, flat: a part of two squares at its end takes squares from
    /// the part beside it until it has 8 (800 mm², the "small" bound here), the other part
    /// staying one strip; not past what fits the room; and not from a part that would then be
    /// small itself.
    #[test]
    fn a_small_part_grows_from_its_neighbour_while_it_fits() {
        let flat = unfold(row_of_squares(40, 10.0), &UnfoldOptions::default()).unwrap();
        assert_eq!(flat.islands.len(), 1);
        let all = &flat.islands[0];
        // Local faces along the row, by the x of their centroid.
        let opts = PatternOptions::default();
        let grown = |room: f64, parts: Vec<Vec<usize>>| {
            let room = Room {
                width: room,
                height: Some(room),
            };
            let sizes = Sizes {
                grow: 0.0,
                small: 800.0 - 1e-6,
                grow_small: true,
            };
            let isl = Island::new(&flat, all, &opts, &room, sizes);
            let mut by_x: Vec<usize> = (0..all.len()).collect();
            by_x.sort_by(|&a, &b| isl.centroid[a].x.total_cmp(&isl.centroid[b].x));
            let parts: Vec<Vec<usize>> = parts
                .into_iter()
                .map(|p| p.into_iter().map(|k| by_x[k]).collect())
                .collect();
            // Each part as (first x, last x, squares).
            grow_small(&isl, parts)
                .iter()
                .map(|p| {
                    let x = p.iter().map(|&u| isl.centroid[u].x);
                    (
                        x.clone().fold(f64::MAX, f64::min),
                        x.fold(0.0, f64::max),
                        p.len(),
                    )
                })
                .collect::<Vec<(f64, f64, usize)>>()
        };
        let two = |a: usize, b: usize| vec![(0..a).collect(), (a..b).collect::<Vec<usize>>()];
        // Grown to 8 squares, both parts still runs of the row.
        assert_eq!(
            grown(250.0, two(2, 40)),
            [(5.0, 75.0, 8), (85.0, 395.0, 32)]
        );
        // A 55 mm room holds 5 squares: it stops there, still small.
        assert_eq!(grown(55.0, two(2, 40)), [(5.0, 45.0, 5), (55.0, 395.0, 35)]);
        // The part beside it has 8 squares: taking one would make it small.
        let three = vec![(0..2).collect(), (2..10).collect(), (10..40).collect()];
        assert_eq!(
            grown(250.0, three),
            [(5.0, 15.0, 2), (25.0, 95.0, 8), (105.0, 395.0, 30)]
        );
    }
}
