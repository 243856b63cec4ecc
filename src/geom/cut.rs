//! Cutting a chart of a mesh open into a topological disk (Julius 2006, thesis §5.2.3, "cuts
//! connecting the boundary loops"), shared by the segmentation (`surface::dcharts`, which
//! cuts every chart it makes) and the flatten stage (which cuts again after splitting a chart,
//! and cuts darts and gussets).
//!
//! - [`Graph`]: the face graph of a mesh (normals, areas, centroids, neighbours across manifold
//!   edges), with Dijkstra distances through face centroids.
//! - [`open`]: a chart opened along its cut edges, one local vertex per wedge of faces around a
//!   mesh vertex ([`Opened`]), with its Euler characteristic and boundary loops.
//! - [`disk_cuts`]: the edges to cut so that a chart becomes a disk: a tube gets the shortest
//!   path between its two rims, a sphere with holes a tree of such paths, a closed shell one
//!   path between two far-apart vertices; a chart with handles (genus g > 0) is cut open
//!   along 2g loops as well (tree–cotree, Eppstein 2003, with the greedy shortest system of
//!   loops of Erickson and Whittlesey 2005). Bent edges count shorter (`cut_weight`), so
//!   seams follow creases.
//! - `bisect` and `split_between`: a chart that cutting cannot make a disk (faces joined only
//!   through a vertex, a non-manifold edge) or whose layout overlaps is split in two through
//!   the face graph.
//!
//! Choices where the thesis is silent: the cut weight (an edge bent by `SHARP_DEG` or more
//! costs a quarter of its length); the roots (the boundary loop through the lowest boundary
//! vertex, or on a closed chart its lowest vertex); ties break on the smaller index
//! everywhere, so cuts are deterministic.

use super::heap::Lowest;
use super::mesh::{Mesh, Topology};
use super::proxy::Moments;
use super::unionfind::UnionFind;
use glam::DVec3;
use std::collections::BinaryHeap;

/// No index (a face outside the chart, a vertex not reached).
const NONE: usize = usize::MAX;

/// The face graph of a mesh: what chart growing, cutting and splitting need per face.
pub struct Graph {
    /// Unit normal per face (zero for a degenerate face).
    pub(crate) normal: Vec<DVec3>,
    pub(crate) area: Vec<f64>,
    pub(crate) centroid: Vec<DVec3>,
    /// Sum of the lengths of the face's edges.
    pub(crate) perimeter: Vec<f64>,
    /// Neighbours across manifold edges: (face, shared edge length).
    pub(crate) adj: Vec<Vec<(usize, f64)>>,
}

impl Graph {
    /// The face graph of `mesh` with its topology `topo`.
    pub fn new(mesh: &Mesh, topo: &Topology) -> Graph {
        let nf = mesh.faces.len();
        let mut adj = vec![Vec::new(); nf];
        let mut perimeter = vec![0.0; nf];
        for e in &topo.edges {
            let len = mesh.vertices[e.verts[0]].distance(mesh.vertices[e.verts[1]]);
            for &(f, _) in &e.uses {
                perimeter[f] += len;
            }
            if let [(f, _), (g, _)] = e.uses[..] {
                if f != g {
                    adj[f].push((g, len));
                    adj[g].push((f, len));
                }
            }
        }
        Graph {
            normal: (0..nf).map(|f| mesh.face_normal(f)).collect(),
            area: (0..nf).map(|f| mesh.face_area(f)).collect(),
            centroid: (0..nf)
                .map(|f| {
                    let p = mesh.face_points(f);
                    p.iter().copied().sum::<DVec3>() / p.len().max(1) as f64
                })
                .collect(),
            perimeter,
            adj,
        }
    }

    /// The faces' normals weighted by their areas, for a proxy fit ([`super::proxy`]).
    pub(crate) fn moments(&self, faces: impl IntoIterator<Item = usize>) -> Moments {
        let mut m = Moments::default();
        for f in faces {
            m.add(self.normal[f], self.area[f]);
        }
        m
    }

    /// Dijkstra distances (through centroids) from `sources`, over faces where `inside` holds.
    pub(crate) fn distances(&self, sources: &[usize], inside: &dyn Fn(usize) -> bool) -> Vec<f64> {
        let mut d = vec![f64::INFINITY; self.area.len()];
        let mut heap = BinaryHeap::new();
        for &s in sources {
            d[s] = 0.0;
            heap.push(Lowest::new(0.0, s));
        }
        while let Some(Lowest { key, id: face, .. }) = heap.pop() {
            if key > d[face] {
                continue;
            }
            for &(g, _) in &self.adj[face] {
                if !inside(g) {
                    continue;
                }
                let nd = key + self.centroid[face].distance(self.centroid[g]);
                if nd < d[g] {
                    d[g] = nd;
                    heap.push(Lowest::new(nd, g));
                }
            }
        }
        d
    }
}

/// Split faces in two along the bisector of the two faces farthest apart (through the face
/// graph restricted to `faces`). Each part is connected when `faces` is.
pub fn bisect(g: &Graph, faces: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let nf = g.area.len();
    let mut inside = vec![false; nf];
    for &f in faces {
        inside[f] = true;
    }
    let within = |f: usize| inside[f];
    let Some(&start) = faces.first() else {
        return (Vec::new(), Vec::new());
    };
    let d0 = g.distances(&[start], &within);
    // Faces not reached from the start (another component) go to the second part.
    if faces.iter().any(|&f| !d0[f].is_finite()) {
        return faces.iter().partition(|&&f| d0[f].is_finite());
    }
    let (da, db) = far_pair(g, faces, &within, &d0);
    faces.iter().partition(|&&f| da[f] <= db[f])
}

/// The distances (within `faces`, connected) from each of their two faces farthest apart:
/// the face farthest from where `d0` was measured, then the face farthest from it (ties:
/// lower face).
fn far_pair(
    g: &Graph,
    faces: &[usize],
    within: &dyn Fn(usize) -> bool,
    d0: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let da = g.distances(&[farthest(faces, d0)], within);
    let db = g.distances(&[farthest(faces, &da)], within);
    (da, db)
}

/// The face of `faces` farthest by `d` (ties: lower face).
fn farthest(faces: &[usize], d: &[f64]) -> usize {
    faces
        .iter()
        .copied()
        .max_by(|&a, &b| d[a].total_cmp(&d[b]).then(b.cmp(&a)))
        .unwrap_or(0)
}

/// The two faces farthest apart through the face graph restricted to `faces`, as [`bisect`]
/// finds them (the face farthest from the first face, then the face farthest from that);
/// `None` when `faces` is empty or not connected.
pub fn farthest_apart(g: &Graph, faces: &[usize]) -> Option<(usize, usize)> {
    let (inside, d0) = from_first(g, faces)?;
    let a = farthest(faces, &d0);
    let da = g.distances(&[a], &|f| inside[f]);
    Some((a, farthest(faces, &da)))
}

/// Which faces are among `faces`, and the distances from the first of them; `None` when
/// `faces` is empty or not connected.
fn from_first(g: &Graph, faces: &[usize]) -> Option<(Vec<bool>, Vec<f64>)> {
    let mut inside = vec![false; g.area.len()];
    for &f in faces {
        inside[f] = true;
    }
    let &start = faces.first()?;
    let d0 = g.distances(&[start], &|f| inside[f]);
    faces
        .iter()
        .all(|&f| d0[f].is_finite())
        .then_some((inside, d0))
}

/// Split faces in two of about equal area across the two faces farthest apart (as
/// [`bisect`] finds them): the faces in order of how much nearer they are to the first
/// (distance to the first less distance to the second, ties by face), the first part taking
/// them until it has half the area. `None` when `faces` is not connected or a part would be
/// empty or not connected.
pub fn bisect_area(g: &Graph, faces: &[usize]) -> Option<(Vec<usize>, Vec<usize>)> {
    let (inside, d0) = from_first(g, faces)?;
    let (da, db) = far_pair(g, faces, &|f| inside[f], &d0);
    let half = 0.5 * faces.iter().map(|&f| g.area[f]).sum::<f64>();
    split_ordered(g, faces, &da, &db, &|order| {
        let mut taken = 0.0;
        Some(
            order
                .iter()
                .position(|&f| {
                    taken += g.area[f];
                    taken >= half
                })
                .map_or(order.len(), |i| i + 1),
        )
    })
}

/// Split faces in two between faces `a` and `b`, each part of at least `least` area: as
/// [`split_between`] where both its parts have that, else with the faces in order of how much
/// nearer they are to `a` than to `b` (as [`bisect_area`] orders them), the first part taking
/// them until it has `least`, or leaving the second that. `None` when no such split keeps `a`
/// and `b` apart, or a part would not be connected.
pub fn split_between_area(
    g: &Graph,
    faces: &[usize],
    a: usize,
    b: usize,
    least: f64,
) -> Option<(Vec<usize>, Vec<usize>)> {
    let nf = g.area.len();
    let mut inside = vec![false; nf];
    for &f in faces {
        inside[f] = true;
    }
    let da = g.distances(&[a], &|f| inside[f]);
    let db = g.distances(&[b], &|f| inside[f]);
    if faces.iter().any(|&f| !da[f].is_finite()) {
        return None;
    }
    let (first, second) = split_ordered(g, faces, &da, &db, &|order| {
        // Areas of the first k faces, k = 0..=n.
        let mut before = vec![0.0];
        for &f in order {
            before.push(before.last().copied().unwrap_or(0.0) + g.area[f]);
        }
        let total = before[order.len()];
        let nearer = order.iter().take_while(|&&f| da[f] < db[f]).count();
        let ok = |k: usize| before[k] >= least && total - before[k] >= least;
        // The feasible count nearest the natural split.
        (0..=order.len())
            .filter(|&k| ok(k))
            .min_by_key(|&k| (k.abs_diff(nearer), k))
    })?;
    (first.contains(&a) && second.contains(&b)).then_some((first, second))
}

/// `faces` in order of `da − db` (ties by face), split after the count `at` picks from that
/// order; `None` when it picks none, or a part would be empty or not connected.
fn split_ordered(
    g: &Graph,
    faces: &[usize],
    da: &[f64],
    db: &[f64],
    at: &dyn Fn(&[usize]) -> Option<usize>,
) -> Option<(Vec<usize>, Vec<usize>)> {
    let nf = g.area.len();
    let mut order = faces.to_vec();
    order.sort_by(|&x, &y| (da[x] - db[x]).total_cmp(&(da[y] - db[y])).then(x.cmp(&y)));
    let n = at(&order)?;
    let second = order.split_off(n.min(order.len()));
    let connected = |part: &[usize]| {
        let mut within = vec![false; nf];
        for &f in part {
            within[f] = true;
        }
        let d = g.distances(&part[..1], &|f| within[f]);
        part.iter().all(|&f| d[f].is_finite())
    };
    (!order.is_empty() && !second.is_empty() && connected(&order) && connected(&second))
        .then_some((order, second))
}

/// Corridors through `faces` from the faces `from` beside them to other regions: for each
/// region `to` names (a face's region, `None` for a face of neither), nearest first, at most
/// `most`, the faces of `faces` on a shortest path (through centroids) from one next to a
/// face of `from` to the nearest next to a face of that region, from that end back.
pub fn corridors(
    g: &Graph,
    faces: &[usize],
    from: &[usize],
    to: &dyn Fn(usize) -> Option<usize>,
    may_end: &dyn Fn(usize) -> bool,
    most: usize,
) -> Vec<Vec<usize>> {
    let mut inside = vec![false; g.area.len()];
    for &f in faces {
        inside[f] = true;
    }
    let mut sources: Vec<usize> = from
        .iter()
        .flat_map(|&s| g.adj[s].iter().map(|&(f, _)| f))
        .filter(|&f| inside[f])
        .collect();
    sources.sort_unstable();
    sources.dedup();
    let d = g.distances(&sources, &|f| inside[f]);
    // Each face next to a region, by its distance (ties: lower face, then lower region).
    let mut ends: Vec<(f64, usize, usize)> = faces
        .iter()
        .filter(|&&f| d[f].is_finite() && may_end(f))
        .flat_map(|&f| g.adj[f].iter().filter_map(move |&(h, _)| Some((f, to(h)?))))
        .map(|(f, region)| (d[f], f, region))
        .collect();
    ends.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    let step = |f: usize, h: usize| d[h] + g.centroid[f].distance(g.centroid[h]);
    let mut reached: Vec<usize> = Vec::new();
    let mut out = Vec::new();
    for (_, end, region) in ends {
        if out.len() == most {
            break;
        }
        if reached.contains(&region) {
            continue;
        }
        reached.push(region);
        // Back along the shortest path: each face's predecessor is the neighbour nearer the
        // start through which its distance was reached (ties: lower face).
        let mut path = vec![end];
        let mut at = end;
        while d[at] > 0.0 && path.len() <= faces.len() {
            let back = g.adj[at]
                .iter()
                .map(|&(h, _)| h)
                .filter(|&h| inside[h] && d[h] < d[at])
                .min_by(|&x, &y| step(at, x).total_cmp(&step(at, y)).then(x.cmp(&y)));
            let Some(h) = back else {
                break;
            };
            path.push(h);
            at = h;
        }
        out.push(path);
    }
    out
}

/// The connected parts of `faces` through the face graph restricted to them, each in the
/// order of `faces`, in the order of their first faces.
pub fn components(g: &Graph, faces: &[usize]) -> Vec<Vec<usize>> {
    let mut inside = vec![false; g.area.len()];
    for &f in faces {
        inside[f] = true;
    }
    let mut part = vec![usize::MAX; g.area.len()];
    let mut count = 0;
    for &f in faces {
        if part[f] != usize::MAX {
            continue;
        }
        part[f] = count;
        let mut stack = vec![f];
        while let Some(x) = stack.pop() {
            for &(h, _) in &g.adj[x] {
                if inside[h] && part[h] == usize::MAX {
                    part[h] = count;
                    stack.push(h);
                }
            }
        }
        count += 1;
    }
    let mut out = vec![Vec::new(); count];
    for &f in faces {
        out[part[f]].push(f);
    }
    out
}

/// Split faces in two by which of faces `a` and `b` is nearer through the face graph restricted
/// to `faces` (used to separate two faces whose layouts overlap). Each part is connected when
/// `faces` is.
pub fn split_between(g: &Graph, faces: &[usize], a: usize, b: usize) -> (Vec<usize>, Vec<usize>) {
    let nf = g.area.len();
    let mut inside = vec![false; nf];
    for &f in faces {
        inside[f] = true;
    }
    let within = |f: usize| inside[f];
    let da = g.distances(&[a], &within);
    let db = g.distances(&[b], &within);
    faces
        .iter()
        .partition(|&&f| da[f] < db[f] || (da[f] == db[f] && da[f].is_finite() && f < b))
}

/// A chart opened along its cut edges: one local vertex per wedge of chart faces around a mesh
/// vertex (faces joined through chart edges that are not cut), so a cut path splits the
/// vertices along it and a pinched vertex (two fans meeting at a point) becomes two.
#[derive(Debug, Clone, PartialEq)]
pub struct Opened {
    /// Per chart face (in the order given): local vertex of each corner.
    pub corners: Vec<Vec<usize>>,
    /// Local vertex → mesh vertex.
    pub vertex: Vec<usize>,
    /// Faces connected through uncut chart edges.
    pub connected: bool,
    /// Euler characteristic of the opened chart (V − E + F).
    pub euler: i64,
    /// Boundary loops of the opened chart (each cut edge gives two boundary edges).
    pub loops: usize,
    /// Some edge is used by more than two chart faces.
    pub nonmanifold: bool,
}

impl Opened {
    /// Whether the opened chart is a topological disk.
    pub fn is_disk(&self) -> bool {
        self.connected && !self.nonmanifold && self.euler == 1 && self.loops == 1
    }
}

/// Local position of each chart face (`NONE` outside).
fn positions(nf: usize, faces: &[usize]) -> Vec<usize> {
    let mut at = vec![NONE; nf];
    for (k, &f) in faces.iter().enumerate() {
        if f < nf {
            at[f] = k;
        }
    }
    at
}

/// Whether edge `e` joins two faces of the chart (`at` from [`positions`]) and is not cut.
fn inner(topo: &Topology, at: &[usize], e: usize, cut: &dyn Fn(usize) -> bool) -> bool {
    let u = &topo.edges[e].uses;
    u.len() == 2 && at[u[0].0] != NONE && at[u[1].0] != NONE && u[0].0 != u[1].0 && !cut(e)
}

/// Open the chart `faces` along the edges where `cut` holds (see [`Opened`]).
pub fn open(mesh: &Mesh, topo: &Topology, faces: &[usize], cut: &dyn Fn(usize) -> bool) -> Opened {
    let nf = mesh.faces.len();
    let at = positions(nf, faces);
    let mut offset = Vec::with_capacity(faces.len() + 1);
    let mut n = 0;
    for &f in faces {
        offset.push(n);
        n += mesh.faces[f].verts.len();
    }
    offset.push(n);
    let mut corner_sets = UnionFind::new(n);
    let mut face_sets = UnionFind::new(faces.len());
    let mut nonmanifold = false;
    // Twice the number of local edges: inner edges are met from both faces.
    let mut twice_edges: i64 = 0;
    for (k, &f) in faces.iter().enumerate() {
        let vs = &mesh.faces[f].verts;
        for (i, &e) in topo.face_edges[f].iter().enumerate() {
            if topo.edges[e]
                .uses
                .iter()
                .filter(|u| at[u.0] != NONE)
                .count()
                > 2
            {
                nonmanifold = true;
            }
            if !inner(topo, &at, e, cut) {
                twice_edges += 2;
                continue;
            }
            twice_edges += 1;
            let &(g, _) = topo.edges[e]
                .uses
                .iter()
                .find(|u| u.0 != f)
                .unwrap_or(&(f, i));
            let kg = at[g];
            face_sets.union(k, kg);
            let gv = &mesh.faces[g].verts;
            for c in [i, (i + 1) % vs.len()] {
                if let Some(cg) = gv.iter().position(|&v| v == vs[c]) {
                    corner_sets.union(offset[k] + c, offset[kg] + cg);
                }
            }
        }
    }
    let mut local = vec![NONE; n];
    let mut vertex = Vec::new();
    let mut corners = Vec::with_capacity(faces.len());
    for (k, &f) in faces.iter().enumerate() {
        let vs = &mesh.faces[f].verts;
        let mut cs = Vec::with_capacity(vs.len());
        for (c, &v) in vs.iter().enumerate() {
            let r = corner_sets.find(offset[k] + c);
            if local[r] == NONE {
                local[r] = vertex.len();
                vertex.push(v);
            }
            cs.push(local[r]);
        }
        corners.push(cs);
    }
    let nv = vertex.len();
    let (mut loop_sets, on_boundary) = boundary_loops(mesh, topo, faces, &at, &corners, nv, cut);
    let loops = (0..nv)
        .filter(|&v| on_boundary[v] && loop_sets.find(v) == v)
        .count();
    let connected =
        faces.is_empty() || (0..faces.len()).all(|k| face_sets.find(k) == face_sets.find(0));
    Opened {
        corners,
        vertex,
        connected,
        euler: nv as i64 - twice_edges / 2 + faces.len() as i64,
        loops,
        nonmanifold,
    }
}

/// The boundary edges of an opened chart (`corners` as in [`Opened`], `nl` local vertices)
/// joined into loops: the sets of local vertices, and which local vertices are on a boundary.
fn boundary_loops(
    mesh: &Mesh,
    topo: &Topology,
    faces: &[usize],
    at: &[usize],
    corners: &[Vec<usize>],
    nl: usize,
    cut: &dyn Fn(usize) -> bool,
) -> (UnionFind, Vec<bool>) {
    let mut sets = UnionFind::new(nl);
    let mut on_boundary = vec![false; nl];
    for (k, &f) in faces.iter().enumerate() {
        let m = mesh.faces[f].verts.len();
        for (i, &e) in topo.face_edges[f].iter().enumerate() {
            if !inner(topo, at, e, cut) {
                let (a, b) = (corners[k][i], corners[k][(i + 1) % m]);
                on_boundary[a] = true;
                on_boundary[b] = true;
                sets.union(a, b);
            }
        }
    }
    (sets, on_boundary)
}

/// Bends above this many degrees count fully as "sharp" when choosing where to cut.
const SHARP_DEG: f64 = 30.0;

/// Length of edge `e` as a cut costs it: edges that bend are cheaper (down to a quarter at
/// [`SHARP_DEG`] and beyond), so seams follow creases where there are some.
pub(crate) fn cut_weight(mesh: &Mesh, topo: &Topology, g: &Graph, e: usize) -> f64 {
    let ed = &topo.edges[e];
    let len = mesh.vertices[ed.verts[0]].distance(mesh.vertices[ed.verts[1]]);
    let bend = match ed.uses[..] {
        [(f, _), (h, _)] => {
            let a = g.normal[f].angle_between(g.normal[h]);
            if a.is_finite() {
                a
            } else {
                0.0
            }
        }
        _ => 0.0,
    };
    len * (1.0 - 0.75 * (bend / SHARP_DEG.to_radians()).min(1.0))
}

/// Vertex graph of the chart's inner (uncut) edges: per mesh vertex, (neighbour, edge).
fn inner_graph(
    mesh: &Mesh,
    topo: &Topology,
    faces: &[usize],
    cut: &dyn Fn(usize) -> bool,
) -> Vec<Vec<(usize, usize)>> {
    let at = positions(mesh.faces.len(), faces);
    let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); mesh.vertices.len()];
    let mut edges: Vec<usize> = faces
        .iter()
        .flat_map(|&f| topo.face_edges[f].iter().copied())
        .filter(|&e| inner(topo, &at, e, cut))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    for e in edges {
        let [a, b] = topo.edges[e].verts;
        adj[a].push((b, e));
        adj[b].push((a, e));
    }
    adj
}

/// Dijkstra over `adj` from `sources` with edge weights `w`, stopping at the first vertex where
/// `stop` holds; returns the distances, the edge each vertex was reached through with the
/// vertex it came from, and the vertex it stopped at.
fn vertex_paths(
    adj: &[Vec<(usize, usize)>],
    w: &dyn Fn(usize) -> f64,
    sources: &[usize],
    stop: &dyn Fn(usize) -> bool,
) -> (Vec<f64>, Vec<(usize, usize)>, Option<usize>) {
    let nv = adj.len();
    let mut d = vec![f64::INFINITY; nv];
    let mut via = vec![(NONE, NONE); nv];
    let mut heap = BinaryHeap::new();
    for &s in sources {
        if d[s] > 0.0 {
            d[s] = 0.0;
            heap.push(Lowest::new(0.0, s));
        }
    }
    while let Some(Lowest { key, id: v, .. }) = heap.pop() {
        if key > d[v] {
            continue;
        }
        if key > 0.0 && stop(v) {
            return (d, via, Some(v));
        }
        for &(u, e) in &adj[v] {
            let nd = key + w(e);
            if nd < d[u] {
                d[u] = nd;
                via[u] = (e, v);
                heap.push(Lowest::new(nd, u));
            }
        }
    }
    (d, via, None)
}

/// The edges of the shortest path (weights `w`) over `adj` (per vertex: neighbour, edge) from
/// any of `sources` to `target`, from `target` back to the source; `None` when it cannot be
/// reached.
pub(crate) fn path_to(
    adj: &[Vec<(usize, usize)>],
    w: &dyn Fn(usize) -> f64,
    sources: &[usize],
    target: usize,
    topo: &Topology,
) -> Option<Vec<usize>> {
    let stop = |v: usize| v == target;
    let (_, via, hit) = vertex_paths(adj, w, sources, &stop);
    hit.map(|v| trace(topo, &via, v))
}

/// The edges of the path that reached `v` (through `via`), from `v` back to a source.
fn trace(topo: &Topology, via: &[(usize, usize)], mut v: usize) -> Vec<usize> {
    let mut out = Vec::new();
    while via[v].0 != NONE && out.len() <= via.len() {
        let e = via[v].0;
        out.push(e);
        let [a, b] = topo.edges[e].verts;
        v = if a == v { b } else { a };
    }
    out
}

/// Edges to cut so that the chart `faces` (already cut where `cut` holds) becomes a disk
/// (thesis §5.2.3, "cuts connecting the chart boundary loops"): a tube or a sphere with holes
/// gets shortest paths joining its boundary loops one by one (each path from everything
/// already joined to the nearest loop not yet joined), a closed shell one path between two
/// vertices far apart (the second farthest from the first, the first farthest from the
/// chart's lowest vertex). Paths run along chart edges, bent edges counting shorter
/// (`cut_weight`). A chart with handles (V − E + F = 2 − 2g − b, g > 0) then gets its 2g
/// generator loops cut too (`handle_cuts`; on a closed chart they replace the path). Empty
/// when the chart already is a disk; `None` when cutting cannot make it one (faces not
/// connected through edges, or a non-manifold edge): the caller splits it.
pub fn disk_cuts(
    mesh: &Mesh,
    topo: &Topology,
    g: &Graph,
    faces: &[usize],
    cut: &dyn Fn(usize) -> bool,
) -> Option<Vec<usize>> {
    let op = open(mesh, topo, faces, cut);
    if op.is_disk() {
        return Some(Vec::new());
    }
    if !op.connected || op.nonmanifold {
        return None;
    }
    // Twice the genus: V − E + F = 2 − 2g − b.
    let twice_genus = 2 - op.loops as i64 - op.euler;
    if twice_genus < 0 || twice_genus % 2 != 0 {
        return None;
    }
    let adj = inner_graph(mesh, topo, faces, cut);
    let w = |e: usize| cut_weight(mesh, topo, g, e);
    let nv = mesh.vertices.len();
    let mut added: Vec<usize> = Vec::new();
    // Boundary loops as sets of mesh vertices (through the opened chart's local vertices).
    let nl = op.vertex.len();
    let at = positions(mesh.faces.len(), faces);
    let (mut loop_sets, on_b) = boundary_loops(mesh, topo, faces, &at, &op.corners, nl, cut);
    let mut loop_of = vec![NONE; nv];
    for (l, &v) in op.vertex.iter().enumerate() {
        if on_b[l] {
            let r = loop_sets.find(l);
            loop_of[v] = loop_of[v].min(r);
        }
    }
    // A closed surface with handles: the generators alone open it (below).
    if op.loops == 0 && twice_genus == 0 {
        let &low = faces
            .iter()
            .flat_map(|&f| mesh.faces[f].verts.iter())
            .min()?;
        let never = |_: usize| false;
        let far = |d: &[f64]| -> usize {
            (0..nv)
                .filter(|&v| d[v].is_finite())
                .max_by(|&a, &b| d[a].total_cmp(&d[b]).then(b.cmp(&a)))
                .unwrap_or(low)
        };
        let (d0, _, _) = vertex_paths(&adj, &w, &[low], &never);
        let a = far(&d0);
        let (da, via, _) = vertex_paths(&adj, &w, &[a], &never);
        let b = far(&da);
        added = trace(topo, &via, b);
    } else if op.loops > 0 {
        // Root: the loop through the lowest boundary vertex; the others joined one by one.
        let mut reached = vec![false; nv];
        let mut loop_reached: std::collections::BTreeSet<usize> = Default::default();
        let root = (0..nv).find(|&v| loop_of[v] != NONE).map(|v| loop_of[v])?;
        loop_reached.insert(root);
        let mut sources: Vec<usize> = (0..nv).filter(|&v| loop_of[v] == root).collect();
        for &s in &sources {
            reached[s] = true;
        }
        for _ in 1..op.loops {
            let stop = |v: usize| loop_of[v] != NONE && !loop_reached.contains(&loop_of[v]);
            let (_, via, hit) = vertex_paths(&adj, &w, &sources, &stop);
            let hit = hit?;
            let path = trace(topo, &via, hit);
            for &e in &path {
                for v in topo.edges[e].verts {
                    if !reached[v] {
                        reached[v] = true;
                        sources.push(v);
                    }
                }
            }
            added.extend(path);
            let l = loop_of[hit];
            loop_reached.insert(l);
            for v in 0..nv {
                if loop_of[v] == l && !reached[v] {
                    reached[v] = true;
                    sources.push(v);
                }
            }
        }
    }
    added.sort_unstable();
    added.dedup();
    if twice_genus > 0 {
        let with = |e: usize| cut(e) || added.binary_search(&e).is_ok();
        added.extend(handle_cuts(mesh, topo, g, faces, &with));
        added.sort_unstable();
        added.dedup();
    }
    let with = |e: usize| cut(e) || added.binary_search(&e).is_ok();
    open(mesh, topo, faces, &with).is_disk().then_some(added)
}

/// Edges cutting the handles of a chart open (the chart already cut where `cut` holds, with
/// at most one boundary loop): the greedy system of loops of Erickson and Whittlesey (2005)
/// built by a tree–cotree decomposition (Eppstein 2003) of the opened chart. The tree `T` is
/// the shortest-path tree (weights [`cut_weight`]) from the boundary loop, all of its
/// vertices roots (or, on a closed surface, from the local vertex of the chart's lowest mesh
/// vertex); the cotree `C` is a maximum spanning tree of the dual graph over the edges not in
/// `T`, each weighted by the length of its loop (root → one end, the edge, other end → root);
/// the `2g` edges left over close the shortest loops, and each with its two tree paths is
/// cut. Cutting these loops (joined to the boundary, or through the root) leaves a disk.
/// Empty when nothing is left over (no handle).
fn handle_cuts(
    mesh: &Mesh,
    topo: &Topology,
    g: &Graph,
    faces: &[usize],
    cut: &dyn Fn(usize) -> bool,
) -> Vec<usize> {
    let op = open(mesh, topo, faces, cut);
    let at = positions(mesh.faces.len(), faces);
    let nl = op.vertex.len();
    // Local edges of the opened chart: (edge, local ends, local faces); boundary vertices.
    let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); nl];
    let mut dual: Vec<(usize, usize, usize, usize, usize)> = Vec::new(); // (e, a, b, k, kg)
    let mut root = vec![false; nl];
    for (k, &f) in faces.iter().enumerate() {
        let m = mesh.faces[f].verts.len();
        for (i, &e) in topo.face_edges[f].iter().enumerate() {
            let (a, b) = (op.corners[k][i], op.corners[k][(i + 1) % m]);
            if !inner(topo, &at, e, cut) {
                root[a] = true;
                root[b] = true;
                continue;
            }
            let Some(&(h, _)) = topo.edges[e].uses.iter().find(|u| u.0 != f) else {
                continue;
            };
            let kg = at[h];
            if k < kg {
                adj[a].push((b, e));
                adj[b].push((a, e));
                dual.push((e, a, b, k, kg));
            }
        }
    }
    if !root.iter().any(|&r| r) {
        // Closed: the local vertex of the lowest mesh vertex.
        let Some(r) = (0..nl).min_by_key(|&l| (op.vertex[l], l)) else {
            return Vec::new();
        };
        root[r] = true;
    }
    let w = |e: usize| cut_weight(mesh, topo, g, e);
    // Shortest-path tree from the roots over local vertices.
    let roots: Vec<usize> = (0..nl).filter(|&l| root[l]).collect();
    let (d, via, _) = vertex_paths(&adj, &w, &roots, &|_| false);
    let in_tree = |e: usize, a: usize, b: usize| via[a].0 == e || via[b].0 == e;
    // Cotree: maximum spanning tree of the dual over the edges not in T, longest loops first.
    let mut rest: Vec<(f64, usize, usize, usize, usize, usize)> = dual
        .iter()
        .filter(|&&(e, a, b, _, _)| !in_tree(e, a, b))
        .map(|&(e, a, b, k, kg)| (d[a] + d[b] + w(e), e, a, b, k, kg))
        .collect();
    rest.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let mut dual_sets = UnionFind::new(faces.len());
    let mut out: Vec<usize> = Vec::new();
    for &(_, e, a, b, k, kg) in &rest {
        if dual_sets.union(k, kg) {
            continue;
        }
        // A generator: the edge and the tree paths from its ends to the roots.
        out.push(e);
        for mut v in [a, b] {
            let mut steps = 0;
            while !root[v] && via[v].0 != NONE && steps <= nl {
                out.push(via[v].0);
                v = via[v].1;
                steps += 1;
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::mesh::Face;

    /// Unit squares (two triangles each): a strip 10 long and 1 wide, then a 10 × 10 block
    /// at its end.
    fn strip_and_block() -> Mesh {
        let mut at = std::collections::HashMap::new();
        let mut vertices = Vec::new();
        let mut v = |i: usize, j: usize| {
            *at.entry((i, j)).or_insert_with(|| {
                vertices.push(DVec3::new(i as f64, j as f64, 0.0));
                vertices.len() - 1
            })
        };
        let mut faces = Vec::new();
        for i in 0..20 {
            for j in 0..(if i < 10 { 1 } else { 10 }) {
                let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                for verts in [vec![a, b, c], vec![a, c, d]] {
                    faces.push(Face { verts, line: None });
                }
            }
        }
        Mesh { vertices, faces }
    }

    fn connected(g: &Graph, part: &[usize]) -> bool {
        let d = g.distances(&part[..1], &|f| part.contains(&f));
        part.iter().all(|&f| d[f].is_finite())
    }

    #[test]
    fn halves_of_equal_area_where_the_bisector_gives_unequal_ones() {
        let mesh = strip_and_block();
        let topo = mesh.topology();
        let g = Graph::new(&mesh, &topo);
        let faces: Vec<usize> = (0..mesh.faces.len()).collect();
        let area = |p: &[usize]| p.iter().map(|&f| g.area[f]).sum::<f64>();
        let total = area(&faces);
        assert!((total - 110.0).abs() < 1e-9, "{total}");
        // The bisector halves the way from the strip's end to the block's far corner, not
        // the area.
        let (a, b) = bisect(&g, &faces);
        let narrow = area(&a).min(area(&b));
        assert!(narrow < 0.4 * total, "{narrow}");
        let (a, b) = bisect_area(&g, &faces).expect("halves");
        let largest = faces.iter().map(|&f| g.area[f]).fold(0.0, f64::max);
        assert!((area(&a) - 0.5 * total).abs() <= largest, "{}", area(&a));
        assert!(area(&a) >= 0.5 * total - 1e-9);
        assert!(connected(&g, &a) && connected(&g, &b));
        let mut all = [a, b].concat();
        all.sort_unstable();
        assert_eq!(all, faces);
        // Two pieces of the strip that do not touch: no halves.
        let apart: Vec<usize> = (0..6).chain(10..16).collect();
        assert_eq!(bisect_area(&g, &apart), None);
    }

    #[test]
    fn a_split_between_two_faces_moves_across_to_leave_each_part_its_least_area() {
        let mesh = strip_and_block();
        let topo = mesh.topology();
        let g = Graph::new(&mesh, &topo);
        let faces: Vec<usize> = (0..mesh.faces.len()).collect();
        let area = |p: &[usize]| p.iter().map(|&f| g.area[f]).sum::<f64>();
        let sorted = |p: &[usize]| {
            let mut p = p.to_vec();
            p.sort_unstable();
            p
        };
        let largest = faces.iter().map(|&f| g.area[f]).fold(0.0, f64::max);
        // The strip's end against the block's far corner: the nearer of the two gives the
        // strip's end the strip and some of the block.
        let (a, b) = (0, faces.len() - 1);
        let (na, nb) = split_between(&g, &faces, a, b);
        let natural = area(&na);
        assert!(natural > 10.0 && area(&nb) > natural + 20.0, "{natural}");
        // Where both parts of that have the least area, it is that split.
        let (x, y) = split_between_area(&g, &faces, a, b, natural).expect("split");
        assert_eq!((sorted(&x), sorted(&y)), (sorted(&na), sorted(&nb)));
        // Else the first part takes faces across until it has the least area, the second
        // keeping as much.
        for least in [natural + 10.0, 0.5 * area(&faces)] {
            let (x, y) = split_between_area(&g, &faces, a, b, least).expect("split");
            assert!(
                area(&x) >= least && area(&x) < least + largest,
                "{}",
                area(&x)
            );
            assert!(area(&y) >= least, "{}", area(&y));
            assert!(x.contains(&a) && y.contains(&b));
            assert!(connected(&g, &x) && connected(&g, &y));
            assert_eq!(sorted(&[x, y].concat()), faces);
        }
        // Or leaves the second part that much: the two the other way round.
        let (x, y) = split_between_area(&g, &faces, b, a, natural + 10.0).expect("split");
        assert!(area(&y) >= natural + 10.0 && area(&y) < natural + 10.0 + largest);
        assert!(x.contains(&b) && y.contains(&a));
        // No split leaves both parts 60 of the 110, nor keeps apart faces not connected.
        assert_eq!(split_between_area(&g, &faces, a, b, 60.0), None);
        let apart: Vec<usize> = (0..6).chain(10..16).collect();
        assert_eq!(split_between_area(&g, &apart, 0, 12, 1.0), None);
    }

    /// The strip's cells 0–2 (faces 0..6) are the small region, cells 3–9 and the block's
    /// first column (faces 6..40) the faces a corridor runs through, the rest of the block
    /// two other regions (rows 0–4 and 5–9).
    #[test]
    fn corridors_run_from_a_region_through_the_faces_to_the_nearest_face_of_each_other() {
        let mesh = strip_and_block();
        let topo = mesh.topology();
        let g = Graph::new(&mesh, &topo);
        let from: Vec<usize> = (0..6).collect();
        let through: Vec<usize> = (6..40).collect();
        // Block cell (i, j) has faces 20 + 2 (10 (i − 10) + j) and the next.
        let region = |f: usize| (f >= 40).then(|| 1 + ((f - 20) / 2 % 10 >= 5) as usize);
        let adjacent = |f: usize, h: usize| g.adj[f].iter().any(|&(x, _)| x == h);
        let paths = corridors(&g, &through, &from, &region, &|_| true, 4);
        assert_eq!(paths.len(), 2, "one per other region");
        for (path, want) in paths.iter().zip([1, 2]) {
            let (end, start) = (path[0], path[path.len() - 1]);
            assert!(g.adj[end].iter().any(|&(h, _)| region(h) == Some(want)));
            assert!(from.iter().any(|&s| adjacent(start, s)), "{path:?}");
            assert!(path.windows(2).all(|w| adjacent(w[0], w[1])), "{path:?}");
            assert!(path.iter().all(|f| through.contains(f)));
        }
        // The nearer region first, along the strip to the block's first cell beside it.
        assert_eq!(paths[0][0] / 2, 10, "cell (10, 0): {:?}", paths[0]);
        assert!(paths[0].len() < paths[1].len());
        assert_eq!(
            corridors(&g, &through, &from, &region, &|_| true, 1).len(),
            1
        );
        // Ends that may not be used: the corridor goes on to the next cell of the column.
        let later = corridors(&g, &through, &from, &region, &|f| f / 2 != 10, 1);
        assert_eq!(later[0][0] / 2, 11, "cell (10, 1): {:?}", later[0]);
        // No corridor where no other region is next to the faces.
        assert!(corridors(&g, &through, &from, &|_| None, &|_| true, 4).is_empty());
    }

    #[test]
    fn components_are_the_connected_parts_in_order() {
        let mesh = strip_and_block();
        let topo = mesh.topology();
        let g = Graph::new(&mesh, &topo);
        let faces: Vec<usize> = [12, 13, 0, 1, 2, 3, 10].into();
        assert_eq!(
            components(&g, &faces),
            vec![vec![12, 13, 10], vec![0, 1, 2, 3]]
        );
        assert!(components(&g, &[]).is_empty());
    }
}
