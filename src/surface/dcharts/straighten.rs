//! Boundary straightening (Julius 2006, thesis §5.2.3, first post-processing step): for each
//! pair of adjacent charts, a fuzzy area is grown from their common boundary into both charts
//! over the faces that fit the *other* chart's proxy below [`DChartsOptions::fuzzy`] · `F_max`
//! (so both proxies fit them). Each boundary segment between the two (a chain of edges with
//! two end vertices) is re-routed along the shortest path between its ends inside the fuzzy
//! area (its inner vertices touch only the two charts and not the mesh boundary), and the
//! fuzzy faces are given back to the side of the new path they lie on (flood from each chart's
//! faces outside the fuzzy area). A change is kept only when the boundary got shorter and both
//! charts stay connected.
//!
//! Choices where the thesis is silent or differs: the thesis bounds the fuzzy area by `F_max`
//! itself; a fraction of it (default a tenth) is used here, because the full bound moves whole
//! strips of faces between charts and raises the stretch. Proxies are those refitted to the
//! charts as they are. After one change the fuzzy area is stale, so a pair is re-routed once.
//! Closed boundary loops (the thesis' min-cut case) are left as they are.

use super::DChartsOptions;
use crate::geom::cut::Graph;
use crate::geom::heap::Lowest;
use crate::geom::mesh::{Mesh, Topology};
use crate::geom::proxy::{self, Moments, Proxy};
use std::collections::{BTreeMap, BTreeSet, BinaryHeap};

/// Total length of the chart boundaries: mesh edges between two different charts.
pub fn boundary_length(mesh: &Mesh, topo: &Topology, chart: &[usize]) -> f64 {
    topo.edges
        .iter()
        .filter(|e| match e.uses[..] {
            [(f, _), (h, _)] => chart.get(f) != chart.get(h),
            _ => false,
        })
        .map(|e| mesh.vertices[e.verts[0]].distance(mesh.vertices[e.verts[1]]))
        .sum()
}

/// Straighten the boundaries between the charts of `chart` (see the module doc); returns the
/// number of segments re-routed.
pub(super) fn straighten(
    mesh: &Mesh,
    topo: &Topology,
    g: &Graph,
    o: &DChartsOptions,
    chart: &mut [usize],
) -> usize {
    let nf = chart.len();
    let st = Straightener::new(mesh, topo, g);
    let proxies = refit(g, chart);
    let mut changed = 0;
    let mut fuzzy = vec![false; nf];
    for (a, b) in adjacent_pairs(topo, chart) {
        let (Some(pa), Some(pb)) = (proxies[a], proxies[b]) else {
            continue;
        };
        let common = st.common_edges(chart, a, b);
        if common.is_empty() {
            continue;
        }
        let fits = |f: usize| {
            let other = if chart[f] == a { &pb } else { &pa };
            other.error(g.normal[f]) < o.fuzzy * o.f_max
        };
        let region = st.fuzzy_area(chart, &common, &fits, &mut fuzzy);
        for (old, ends) in st.segments(&common) {
            if st.reroute(chart, &fuzzy, &region, &common, &old, &ends, (a, b)) {
                changed += 1;
                // The fuzzy area is stale after a change: this pair is done.
                break;
            }
        }
        for &f in &region {
            fuzzy[f] = false;
        }
    }
    changed
}

/// The proxy of every chart, refitted to its faces (`None` for a chart with no area).
fn refit(g: &Graph, chart: &[usize]) -> Vec<Option<Proxy>> {
    let count = chart.iter().copied().max().map_or(0, |m| m + 1);
    let mut mo = vec![Moments::default(); count];
    for f in 0..chart.len() {
        mo[chart[f]].add(g.normal[f], g.area[f]);
    }
    mo.iter().map(proxy::fit).collect()
}

/// The pairs of charts that share an edge, smaller chart first, ascending.
fn adjacent_pairs(topo: &Topology, chart: &[usize]) -> BTreeSet<(usize, usize)> {
    let mut pairs: BTreeSet<(usize, usize)> = Default::default();
    for e in &topo.edges {
        if let [(f, _), (h, _)] = e.uses[..] {
            let (a, b) = (chart[f], chart[h]);
            if a != b {
                pairs.insert((a.min(b), a.max(b)));
            }
        }
    }
    pairs
}

/// The mesh and what every boundary segment needs.
struct Straightener<'a> {
    mesh: &'a Mesh,
    topo: &'a Topology,
    g: &'a Graph,
    /// Faces around each vertex.
    vf: Vec<Vec<usize>>,
    on_mesh_boundary: Vec<bool>,
}

impl<'a> Straightener<'a> {
    fn new(mesh: &'a Mesh, topo: &'a Topology, g: &'a Graph) -> Self {
        let nv = mesh.vertices.len();
        let mut vf: Vec<Vec<usize>> = vec![Vec::new(); nv];
        for (f, face) in mesh.faces.iter().enumerate() {
            for &v in &face.verts {
                vf[v].push(f);
            }
        }
        let mut on_mesh_boundary = vec![false; nv];
        for e in &topo.edges {
            if e.uses.len() != 2 {
                on_mesh_boundary[e.verts[0]] = true;
                on_mesh_boundary[e.verts[1]] = true;
            }
        }
        Straightener {
            mesh,
            topo,
            g,
            vf,
            on_mesh_boundary,
        }
    }

    /// Length of edge `e`.
    fn len(&self, e: usize) -> f64 {
        let [a, b] = self.topo.edges[e].verts;
        self.mesh.vertices[a].distance(self.mesh.vertices[b])
    }

    /// The edges between charts `a` and `b`, ascending.
    fn common_edges(&self, chart: &[usize], a: usize, b: usize) -> Vec<usize> {
        let topo = self.topo;
        (0..topo.edges.len())
            .filter(|&e| match topo.edges[e].uses[..] {
                [(f, _), (h, _)] => {
                    (chart[f] == a && chart[h] == b) || (chart[f] == b && chart[h] == a)
                }
                _ => false,
            })
            .collect()
    }

    /// The fuzzy area: grown from the common boundary into each chart over the faces where
    /// `fits` holds (they fit the other chart's proxy); marks them in `fuzzy`.
    fn fuzzy_area(
        &self,
        chart: &[usize],
        common: &[usize],
        fits: &dyn Fn(usize) -> bool,
        fuzzy: &mut [bool],
    ) -> Vec<usize> {
        let mut region: Vec<usize> = Vec::new();
        for &e in common {
            for &(f, _) in &self.topo.edges[e].uses {
                if !fuzzy[f] && fits(f) {
                    fuzzy[f] = true;
                    region.push(f);
                }
            }
        }
        let mut k = 0;
        while k < region.len() {
            let t = region[k];
            k += 1;
            for &(u, _) in &self.g.adj[t] {
                if !fuzzy[u] && chart[u] == chart[t] && fits(u) {
                    fuzzy[u] = true;
                    region.push(u);
                }
            }
        }
        region
    }

    /// The boundary segments: components of the common edges (through shared vertices) that
    /// are chains with two ends, as (edges, ends).
    fn segments(&self, common: &[usize]) -> Vec<(Vec<usize>, Vec<usize>)> {
        let topo = self.topo;
        let mut deg: BTreeMap<usize, Vec<usize>> = Default::default();
        for &e in common {
            for v in topo.edges[e].verts {
                deg.entry(v).or_default().push(e);
            }
        }
        let mut seen_e: BTreeSet<usize> = Default::default();
        let mut segments: Vec<(Vec<usize>, Vec<usize>)> = Vec::new(); // (edges, ends)
        for &e0 in common {
            if seen_e.contains(&e0) {
                continue;
            }
            let mut comp = vec![e0];
            seen_e.insert(e0);
            let mut i = 0;
            while i < comp.len() {
                let e = comp[i];
                i += 1;
                for v in topo.edges[e].verts {
                    for &x in &deg[&v] {
                        if seen_e.insert(x) {
                            comp.push(x);
                        }
                    }
                }
            }
            let mut verts: Vec<usize> = comp.iter().flat_map(|&e| topo.edges[e].verts).collect();
            verts.sort_unstable();
            verts.dedup();
            let ends: Vec<usize> = verts
                .iter()
                .copied()
                .filter(|v| deg[v].len() == 1)
                .collect();
            let branching = verts.iter().any(|v| deg[v].len() > 2);
            if ends.len() == 2 && !branching {
                segments.push((comp, ends));
            }
        }
        segments
    }

    /// Re-route the segment `old` (ends `ends`) between charts `a` and `b` through the fuzzy
    /// area `region` and reassign the fuzzy faces to the side of the new path; true when the
    /// change is kept (shorter and both charts connected), else `chart` is left as it was.
    #[allow(clippy::too_many_arguments)]
    fn reroute(
        &self,
        chart: &mut [usize],
        fuzzy: &[bool],
        region: &[usize],
        common: &[usize],
        old: &[usize],
        ends: &[usize],
        (a, b): (usize, usize),
    ) -> bool {
        let old_len: f64 = old.iter().map(|&e| self.len(e)).sum();
        let Some((new_len, mut path)) = self.shortest_path(chart, fuzzy, region, old, ends, (a, b))
        else {
            return false;
        };
        if new_len >= old_len * (1.0 - 1e-9) {
            return false;
        }
        // The new boundary between the two: the other segments and the new path.
        path.extend(common.iter().copied().filter(|e| !old.contains(e)));
        path.sort_unstable();
        self.reassign(chart, fuzzy, region, &path, (a, b))
    }

    /// The shortest path between the segment's ends along the edges allowed (inside the fuzzy
    /// area, or the old segment itself; inner vertices touching only charts `a` and `b` and
    /// off the mesh boundary): its length and its edges, from `ends[1]` back to `ends[0]`.
    fn shortest_path(
        &self,
        chart: &[usize],
        fuzzy: &[bool],
        region: &[usize],
        old: &[usize],
        ends: &[usize],
        (a, b): (usize, usize),
    ) -> Option<(f64, Vec<usize>)> {
        let topo = self.topo;
        let clean = |v: usize| {
            !self.on_mesh_boundary[v] && self.vf[v].iter().all(|&f| chart[f] == a || chart[f] == b)
        };
        let mut adj: BTreeMap<usize, Vec<(usize, usize)>> = Default::default();
        let mut allowed: Vec<usize> = old.to_vec();
        for &f in region {
            for &e in &topo.face_edges[f] {
                if let [(x, _), (y, _)] = topo.edges[e].uses[..] {
                    if fuzzy[x] && fuzzy[y] {
                        allowed.push(e);
                    }
                }
            }
        }
        allowed.sort_unstable();
        allowed.dedup();
        for &e in &allowed {
            let [p, q] = topo.edges[e].verts;
            let ok = |v: usize| ends.contains(&v) || clean(v);
            if ok(p) && ok(q) {
                adj.entry(p).or_default().push((q, e));
                adj.entry(q).or_default().push((p, e));
            }
        }
        // Dijkstra from ends[0] to ends[1] over the allowed edges.
        let mut dist: BTreeMap<usize, f64> = Default::default();
        let mut via: BTreeMap<usize, usize> = Default::default();
        let mut heap = BinaryHeap::new();
        dist.insert(ends[0], 0.0);
        heap.push(Lowest::new(0.0, ends[0]));
        while let Some(Lowest { key, id: v, .. }) = heap.pop() {
            if key > dist[&v] || v == ends[1] {
                if v == ends[1] {
                    break;
                }
                continue;
            }
            for &(u, e) in adj.get(&v).map(|x| x.as_slice()).unwrap_or(&[]) {
                let nd = key + self.len(e);
                if dist.get(&u).is_none_or(|&d| nd < d) {
                    dist.insert(u, nd);
                    via.insert(u, e);
                    heap.push(Lowest::new(nd, u));
                }
            }
        }
        let &new_len = dist.get(&ends[1])?;
        let mut path: Vec<usize> = Vec::new();
        let mut v = ends[1];
        while v != ends[0] && path.len() <= allowed.len() {
            let e = via[&v];
            path.push(e);
            let [p, q] = topo.edges[e].verts;
            v = if p == v { q } else { p };
        }
        Some((new_len, path))
    }

    /// Reassign the fuzzy faces: flood from `a`'s faces outside the fuzzy area, not crossing
    /// the new boundary `path` (sorted); what `a` does not reach goes to `b`. Kept (true) when
    /// the boundary between the two got shorter and both stay connected; else undone.
    fn reassign(
        &self,
        chart: &mut [usize],
        fuzzy: &[bool],
        region: &[usize],
        path: &[usize],
        (a, b): (usize, usize),
    ) -> bool {
        let (mesh, topo, g) = (self.mesh, self.topo, self.g);
        let nf = chart.len();
        let saved: Vec<(usize, usize)> = region.iter().map(|&f| (f, chart[f])).collect();
        let mut to_a = vec![false; region.len()];
        let idx: BTreeMap<usize, usize> = region.iter().enumerate().map(|(i, &f)| (f, i)).collect();
        let mut stack: Vec<usize> = Vec::new();
        for &f in region {
            // Fuzzy faces next to a's non-fuzzy faces, across an edge not on the path.
            for &(u, _) in &g.adj[f] {
                if chart[u] == a && !fuzzy[u] {
                    let e = shared_edge(topo, f, u);
                    if e.is_some_and(|e| path.binary_search(&e).is_err()) && !to_a[idx[&f]] {
                        to_a[idx[&f]] = true;
                        stack.push(f);
                    }
                }
            }
        }
        let any_outside_a = (0..nf).any(|f| chart[f] == a && !fuzzy[f]);
        let any_outside_b = (0..nf).any(|f| chart[f] == b && !fuzzy[f]);
        if !any_outside_a || !any_outside_b {
            return false;
        }
        while let Some(f) = stack.pop() {
            for &(u, _) in &g.adj[f] {
                if let Some(&iu) = idx.get(&u) {
                    if to_a[iu] {
                        continue;
                    }
                    let e = shared_edge(topo, f, u);
                    if e.is_some_and(|e| path.binary_search(&e).is_err()) {
                        to_a[iu] = true;
                        stack.push(u);
                    }
                }
            }
        }
        for (i, &f) in region.iter().enumerate() {
            chart[f] = if to_a[i] { a } else { b };
        }
        let now: f64 = boundary_between(mesh, topo, chart, a, b);
        let before_total: f64 = {
            let cur: Vec<(usize, usize)> = region.iter().map(|&f| (f, chart[f])).collect();
            for &(f, c) in &saved {
                chart[f] = c;
            }
            let t = boundary_between(mesh, topo, chart, a, b);
            for &(f, c) in &cur {
                chart[f] = c;
            }
            t
        };
        if now < before_total * (1.0 - 1e-9)
            && chart_connected(g, chart, a)
            && chart_connected(g, chart, b)
        {
            return true;
        }
        for &(f, c) in &saved {
            chart[f] = c;
        }
        false
    }
}

/// Whether the faces of chart `c` are connected (and there are some).
fn chart_connected(g: &Graph, chart: &[usize], c: usize) -> bool {
    let faces: Vec<usize> = (0..chart.len()).filter(|&f| chart[f] == c).collect();
    let Some(&s) = faces.first() else {
        return false;
    };
    let mut seen = vec![false; chart.len()];
    seen[s] = true;
    let mut n = 1;
    let mut st = vec![s];
    while let Some(f) = st.pop() {
        for &(u, _) in &g.adj[f] {
            if chart[u] == c && !seen[u] {
                seen[u] = true;
                n += 1;
                st.push(u);
            }
        }
    }
    n == faces.len()
}

/// The edge two faces share, if any.
fn shared_edge(topo: &Topology, f: usize, h: usize) -> Option<usize> {
    topo.face_edges[f]
        .iter()
        .copied()
        .find(|&e| topo.edges[e].uses.iter().any(|u| u.0 == h))
}

/// Length of the boundary between charts `a` and `b`.
fn boundary_between(mesh: &Mesh, topo: &Topology, chart: &[usize], a: usize, b: usize) -> f64 {
    topo.edges
        .iter()
        .filter(|e| match e.uses[..] {
            [(f, _), (h, _)] => {
                (chart[f] == a && chart[h] == b) || (chart[f] == b && chart[h] == a)
            }
            _ => false,
        })
        .map(|e| mesh.vertices[e.verts[0]].distance(mesh.vertices[e.verts[1]]))
        .sum()
}
