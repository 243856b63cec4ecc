//! Exact unfolding of polyhedral meshes: every face is moved into the plane by a rigid motion,
//! so every edge length and angle is kept (to rounding, far below 1e-9 relative).
//!
//! Which edges to cut is a spanning forest of the face graph built greedily in the manner of
//! Kruskal, as Blender's Export Paper Model add-on does: interior edges are visited by priority
//! `w · |angle| / π − 0.05 · length / mean length`, with `w` = 0.5 for convex and 1 for concave
//! bends (the add-on's defaults: flat and convex edges are the cheapest to keep, long edges are
//! kept before short ones), and each joins the two islands it separates unless the joined island
//! would overlap itself; then the edge stays cut. The smaller island is the one moved, so each
//! face moves O(log n) times; overlap is tested triangle against triangle (separating axes)
//! against a uniform grid of the larger island.
//!
//! Tolerance: real meshes are stored with rounded coordinates, so "planar" regions have tiny
//! angle defects and an exact test would cut at almost every vertex. Faces may therefore overlap
//! by less than
//! [`UnfoldOptions::tolerance`] (0.02 mm, under one HP-GL plotter unit, capped at 1 % of the mean
//! edge length); faces that merely touch along a fold or at a vertex never count. After the
//! forest is built, cut edges whose two copies coincide within that distance inside one island
//! (typically inside planar regions) are joined again, because cutting there would only slit the
//! material. Edges the source lists in [`Surface::cuts`] are never joined (the seam where a
//! closed spline surface is opened).
//!
//! `unfold_onto` runs the same joins with some faces held where another layout put them
//! (each such layout an island that moves only rigidly and is never joined to another): the
//! chart flattener grafts small pieces onto their neighbours with it (issue 20).

use super::{Flat, FlattenError};
use crate::geom::mesh::{Mesh, Topology};
use crate::geom::polygon;
use crate::surface::Surface;
use glam::{DVec2, DVec3};
use std::borrow::Cow;
use std::collections::HashMap;

/// Options of the unfolder.
#[derive(Debug, Clone, PartialEq)]
pub struct UnfoldOptions {
    /// Weight of edge length (relative to the mean) in the join priority.
    pub length_weight: f64,
    /// Weight of convex bend angle (fraction of π) in the join priority.
    pub convex_weight: f64,
    /// Weight of concave bend angle (fraction of π) in the join priority.
    pub concave_weight: f64,
    /// Overlap (depth, in mm) below which faces count as touching, not overlapping; also the
    /// distance within which the two copies of a cut edge count as coincident. Capped at 1 % of
    /// the mean edge length so that tiny meshes are not swallowed by it.
    pub tolerance: f64,
}

impl UnfoldOptions {
    /// The join priority of an edge (lower joins first) with bend `dihedral` (radians, positive
    /// convex) and `length` relative to the mean.
    fn key(&self, dihedral: f64, length: f64) -> f64 {
        let t = dihedral / std::f64::consts::PI;
        let w = if t > 0.0 {
            self.convex_weight
        } else {
            -self.concave_weight
        };
        w * t - self.length_weight * length
    }
}

impl Default for UnfoldOptions {
    fn default() -> Self {
        UnfoldOptions {
            length_weight: 0.05,
            convex_weight: 0.5,
            concave_weight: 1.0,
            tolerance: 0.02,
        }
    }
}

type Cell = (i64, i64);

struct Grid {
    cell: f64,
}

impl Grid {
    fn cells(&self, lo: DVec2, hi: DVec2) -> impl Iterator<Item = Cell> {
        let (x0, y0) = (
            (lo.x / self.cell).floor() as i64,
            (lo.y / self.cell).floor() as i64,
        );
        let (x1, y1) = (
            (hi.x / self.cell).floor() as i64,
            (hi.y / self.cell).floor() as i64,
        );
        (x0..=x1).flat_map(move |x| (y0..=y1).map(move |y| (x, y)))
    }
}

/// Rigid motion of the plane: rotation then translation.
#[derive(Clone, Copy)]
struct Motion {
    rot: DVec2,
    shift: DVec2,
}

impl Motion {
    /// The motion taking the segment `a0 → b0` onto `a1 → b1` (same length).
    fn between(a0: DVec2, b0: DVec2, a1: DVec2, b1: DVec2) -> Motion {
        let d0 = (b0 - a0).normalize_or_zero();
        let d1 = (b1 - a1).normalize_or_zero();
        // Rotation taking d0 to d1, as a unit complex number.
        let rot = DVec2::new(d0.dot(d1), d0.perp_dot(d1));
        let rot = rot.normalize_or(DVec2::X);
        let mid0 = 0.5 * (a0 + b0);
        let mid1 = 0.5 * (a1 + b1);
        Motion {
            rot,
            shift: mid1 - rot.rotate(mid0),
        }
    }
    fn apply(&self, p: DVec2) -> DVec2 {
        self.rot.rotate(p) + self.shift
    }
}

/// Corner positions of a face in its own plane: first vertex at the origin, first edge along +x,
/// counter-clockwise seen from the side the face normal points to.
fn face_in_plane(surface: &Surface, f: usize) -> Result<Vec<DVec2>, FlattenError> {
    plane_of(&surface.mesh, f).ok_or_else(|| FlattenError::Degenerate {
        surface: surface.name.clone(),
        face: f + 1,
        line: surface.mesh.faces[f].line,
    })
}

/// [`face_in_plane`] of a mesh's face; `None` for a face without area.
fn plane_of(mesh: &Mesh, f: usize) -> Option<Vec<DVec2>> {
    let pts = mesh.face_points(f);
    let n = mesh.face_normal(f);
    let x = (pts[1] - pts[0]).normalize_or_zero();
    let y = n.cross(x);
    if x == DVec3::ZERO || n == DVec3::ZERO || !y.is_finite() {
        return None;
    }
    Some(
        pts.iter()
            .map(|p| DVec2::new((*p - pts[0]).dot(x), (*p - pts[0]).dot(y)))
            .collect(),
    )
}

/// Islands being built: face positions, island membership and a grid per island.
struct Unfolder {
    pos: Vec<Vec<DVec2>>,
    tris: Vec<Cow<'static, [[usize; 3]]>>,
    face_island: Vec<usize>,
    members: Vec<Vec<usize>>,
    cells: Vec<HashMap<Cell, Vec<usize>>>,
    grid: Grid,
    stamp: Vec<u32>,
    round: u32,
    moved: Vec<Vec<DVec2>>,
    eps: f64,
    /// For each island: it holds a layout that stays as it is ([`unfold_onto`]); two such
    /// are never joined.
    anchored: Vec<bool>,
}

impl Unfolder {
    /// Every face of `pos` an island of its own, on a grid of cells a little over the typical
    /// face's size (`longest`: the longest edge).
    fn new(pos: Vec<Vec<DVec2>>, longest: f64, eps: f64) -> Unfolder {
        let nf = pos.len();
        let tris: Vec<Cow<'static, [[usize; 3]]>> =
            pos.iter().map(|p| polygon::triangulate(p)).collect();
        let mut sizes: Vec<f64> = pos
            .iter()
            .map(|p| {
                polygon::bounds(p.iter().copied())
                    .map(|(lo, hi)| (hi - lo).max_element())
                    .unwrap_or(0.0)
            })
            .collect();
        sizes.sort_by(f64::total_cmp);
        let typical = sizes.get(sizes.len() * 9 / 10).copied().unwrap_or(1.0);
        let grid = Grid {
            cell: typical.max(longest * 1e-6).max(1e-9),
        };
        let mut u = Unfolder {
            face_island: (0..nf).collect(),
            members: (0..nf).map(|f| vec![f]).collect(),
            cells: Vec::with_capacity(nf),
            grid,
            stamp: vec![0; nf],
            round: 0,
            moved: Vec::new(),
            eps,
            anchored: vec![false; nf],
            pos,
            tris,
        };
        for f in 0..nf {
            let mut m: HashMap<Cell, Vec<usize>> = HashMap::new();
            if let Some((lo, hi)) = polygon::bounds(u.pos[f].iter().copied()) {
                for c in u.grid.cells(lo, hi) {
                    m.entry(c).or_default().push(f);
                }
            }
            u.cells.push(m);
        }
        u
    }

    /// Faces `from..to` as one anchored island (island `from`), where they lie.
    fn fix(&mut self, from: usize, to: usize) {
        self.anchored[from] = true;
        for f in from + 1..to.min(self.pos.len()) {
            self.members[f].clear();
            self.members[from].push(f);
            self.face_island[f] = from;
            for (c, list) in std::mem::take(&mut self.cells[f]) {
                self.cells[from].entry(c).or_default().extend(list);
            }
        }
    }

    /// Join the two islands on either side of interior edge `e` by moving the smaller one onto
    /// the larger along the edge, unless that would make them overlap. Returns whether joined.
    fn try_join(&mut self, topology: &Topology, e: usize) -> bool {
        let [(mut f, mut i), (mut g, mut j)] =
            [topology.edges[e].uses[0], topology.edges[e].uses[1]];
        let (mut a, mut b) = (self.face_island[f], self.face_island[g]);
        if a == b || (self.anchored[a] && self.anchored[b]) {
            return false;
        }
        if self.members[a].len() < self.members[b].len() {
            std::mem::swap(&mut f, &mut g);
            std::mem::swap(&mut i, &mut j);
            std::mem::swap(&mut a, &mut b);
        }
        let pos = &self.pos;
        // Face f (island a) runs p → q along the edge; face g (island b) runs it backwards.
        let (p, q) = (pos[f][i], pos[f][(i + 1) % pos[f].len()]);
        let (q0, p0) = (pos[g][j], pos[g][(j + 1) % pos[g].len()]);
        let m = Motion::between(p0, q0, p, q);
        self.moved.clear();
        for &h in &self.members[b] {
            let tp: Vec<DVec2> = pos[h].iter().map(|&x| m.apply(x)).collect();
            let Some((lo, hi)) = polygon::bounds(tp.iter().copied()) else {
                continue;
            };
            // A fresh stamp per moved face: each face of `a` is tested once against it.
            self.round = self.round.wrapping_add(1);
            if self.round == 0 {
                self.stamp.iter_mut().for_each(|s| *s = 0);
                self.round = 1;
            }
            for c in self.grid.cells(lo, hi) {
                let Some(list) = self.cells[a].get(&c) else {
                    continue;
                };
                for &k in list {
                    if self.stamp[k] == self.round {
                        continue;
                    }
                    self.stamp[k] = self.round;
                    if faces_overlap(&tp, &self.tris[h], &pos[k], &self.tris[k], self.eps) {
                        return false;
                    }
                }
            }
            self.moved.push(tp);
        }
        let faces_b = std::mem::take(&mut self.members[b]);
        self.cells[b] = HashMap::new();
        for (h, tp) in faces_b.iter().zip(self.moved.drain(..)) {
            if let Some((lo, hi)) = polygon::bounds(tp.iter().copied()) {
                for c in self.grid.cells(lo, hi) {
                    self.cells[a].entry(c).or_default().push(*h);
                }
            }
            self.pos[*h] = tp;
            self.face_island[*h] = a;
        }
        self.members[a].extend(faces_b);
        self.anchored[a] |= self.anchored[b];
        true
    }
}

/// Unfold a polyhedral surface into non-overlapping islands.
pub fn unfold(surface: Surface, opts: &UnfoldOptions) -> Result<Flat, FlattenError> {
    let topology = surface.mesh.topology();
    let nf = surface.mesh.faces.len();
    let mut pos: Vec<Vec<DVec2>> = Vec::with_capacity(nf);
    for f in 0..nf {
        pos.push(face_in_plane(&surface, f)?);
    }

    let ne = topology.edges.len();
    let mut dihedral = vec![0.0; ne];
    let mut lengths = vec![0.0; ne];
    for (e, edge) in topology.edges.iter().enumerate() {
        lengths[e] =
            surface.mesh.vertices[edge.verts[0]].distance(surface.mesh.vertices[edge.verts[1]]);
        if let [(f, i), (g, _)] = edge.uses[..] {
            dihedral[e] = surface.mesh.signed_dihedral(f, i, g).unwrap_or(0.0);
        }
    }
    let longest = lengths
        .iter()
        .copied()
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let mean = lengths.iter().sum::<f64>() / ne.max(1) as f64;
    let eps = opts.tolerance.min(0.01 * mean);
    let mut u = Unfolder::new(pos, longest, eps);
    let mut joined = vec![false; ne];
    let key = |e: usize| opts.key(dihedral[e], lengths[e] / mean);

    // Join islands across edges in priority order (Kruskal), the smaller moved onto the larger;
    // the source's cuts (the seam of a closed spline surface) stay cut.
    let forced: std::collections::HashSet<[usize; 2]> = surface.cuts.iter().copied().collect();
    let is_forced = |e: usize| {
        let [a, b] = topology.edges[e].verts;
        forced.contains(&[a.min(b), a.max(b)])
    };
    let mut order: Vec<usize> = (0..ne)
        .filter(|&e| topology.edges[e].uses.len() == 2 && !joined[e] && !is_forced(e))
        .collect();
    order.sort_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    for e in order {
        let [(f, _), (g, _)] = [topology.edges[e].uses[0], topology.edges[e].uses[1]];
        if u.face_island[f] != u.face_island[g] && u.try_join(&topology, e) {
            joined[e] = true;
        }
    }
    let Unfolder {
        mut face_island,
        members,
        pos,
        ..
    } = u;

    // Edges cut inside one island whose copies coincide would only slit the material.
    for (e, edge) in topology.edges.iter().enumerate() {
        if joined[e] || edge.uses.len() != 2 || is_forced(e) {
            continue;
        }
        let [(f, i), (g, j)] = [edge.uses[0], edge.uses[1]];
        if face_island[f] != face_island[g] {
            continue;
        }
        let (p, q) = (pos[f][i], pos[f][(i + 1) % pos[f].len()]);
        let (q0, p0) = (pos[g][j], pos[g][(j + 1) % pos[g].len()]);
        let tol = eps;
        if p.distance(p0) <= tol && q.distance(q0) <= tol {
            joined[e] = true;
        }
    }

    // Renumber islands by their smallest face, so the numbering does not depend on merge order.
    let mut islands: Vec<Vec<usize>> = members.into_iter().filter(|m| !m.is_empty()).collect();
    for isl in &mut islands {
        isl.sort_unstable();
    }
    islands.sort_by_key(|m| m[0]);
    for (k, isl) in islands.iter().enumerate() {
        for &f in isl {
            face_island[f] = k;
        }
    }
    Ok(Flat {
        surface,
        topology,
        face_2d: pos,
        face_island,
        islands,
        joined,
        dihedral,
        tolerance: eps,
    })
}

/// What [`unfold_onto`] gives: each face's corners, the fixed layout each face ended in, and
/// for each edge whether it was joined.
type Onto = (Vec<Vec<DVec2>>, Vec<usize>, Vec<bool>);

/// Faces unfolded onto layouts that stay as they are (`charts::exact::graft`): the first
/// faces of `mesh` are the layouts of `fixed`, one after the other, each an island where it
/// lies; the other faces start apart, each in its own plane, and are joined in the
/// unfolder's order (see the module doc; with `anchor_first`, the edges between a fixed
/// layout and another face before all others), a join that would overlap deeper than `eps`
/// or that would join two of the fixed layouts left cut. A fixed layout moves only rigidly, when
/// a larger island is joined onto it. The positions of all faces, the fixed layout each face
/// ended in, and the edges joined (ids of `topology`, the mesh's); `None` when a face has no
/// area or stays apart from every fixed layout.
pub(super) fn unfold_onto(
    mesh: &Mesh,
    topology: &Topology,
    fixed: &[&[Vec<DVec2>]],
    opts: &UnfoldOptions,
    eps: f64,
    anchor_first: bool,
) -> Option<Onto> {
    let nf = mesh.faces.len();
    let n: usize = fixed.iter().map(|l| l.len()).sum();
    if fixed.iter().any(|l| l.is_empty()) || n > nf {
        return None;
    }
    let mut pos: Vec<Vec<DVec2>> = fixed.iter().flat_map(|l| l.iter().cloned()).collect();
    for f in n..nf {
        pos.push(plane_of(mesh, f)?);
    }
    let ne = topology.edges.len();
    let length = |e: usize| {
        let [a, b] = topology.edges[e].verts;
        mesh.vertices[a].distance(mesh.vertices[b])
    };
    let free: Vec<usize> = (0..ne)
        .filter(|&e| {
            let uses = &topology.edges[e].uses;
            uses.len() == 2 && uses.iter().any(|u| u.0 >= n)
        })
        .collect();
    let longest = free
        .iter()
        .map(|&e| length(e))
        .fold(f64::MIN_POSITIVE, f64::max);
    let mean = free.iter().map(|&e| length(e)).sum::<f64>() / free.len().max(1) as f64;
    let mut keys: Vec<(f64, usize)> = free
        .iter()
        .map(|&e| {
            let [(f, i), (g, _)] = [topology.edges[e].uses[0], topology.edges[e].uses[1]];
            let d = mesh.signed_dihedral(f, i, g).unwrap_or(0.0);
            // Edges to a fixed layout before all others, when asked.
            let first = if anchor_first && (f < n || g < n) {
                -10.0
            } else {
                0.0
            };
            (
                first + opts.key(d, length(e) / mean.max(f64::MIN_POSITIVE)),
                e,
            )
        })
        .collect();
    keys.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut u = Unfolder::new(pos, longest, eps);
    let mut starts = Vec::with_capacity(fixed.len());
    let mut at = 0;
    for l in fixed {
        u.fix(at, at + l.len());
        starts.push(at);
        at += l.len();
    }
    let mut joined = vec![false; ne];
    for (_, e) in keys {
        let [(f, _), (g, _)] = [topology.edges[e].uses[0], topology.edges[e].uses[1]];
        if u.face_island[f] != u.face_island[g] && u.try_join(topology, e) {
            joined[e] = true;
        }
    }
    let which: Vec<usize> = (0..nf)
        .map(|f| {
            starts
                .iter()
                .position(|&s| u.face_island[s] == u.face_island[f])
        })
        .collect::<Option<_>>()?;
    Some((u.pos, which, joined))
}

fn faces_overlap(
    pa: &[DVec2],
    ta: &[[usize; 3]],
    pb: &[DVec2],
    tb: &[[usize; 3]],
    eps: f64,
) -> bool {
    let (Some((alo, ahi)), Some((blo, bhi))) = (
        polygon::bounds(pa.iter().copied()),
        polygon::bounds(pb.iter().copied()),
    ) else {
        return false;
    };
    if alo.x >= bhi.x - eps || blo.x >= ahi.x - eps || alo.y >= bhi.y - eps || blo.y >= ahi.y - eps
    {
        return false;
    }
    ta.iter().any(|x| {
        let a = [pa[x[0]], pa[x[1]], pa[x[2]]];
        tb.iter().any(|y| {
            let b = [pb[y[0]], pb[y[1]], pb[y[2]]];
            polygon::triangles_overlap(&a, &b, eps)
        })
    })
}

/// Two faces of one island of an unfolding that overlap (deeper than the flat's tolerance),
/// if any: the exact triangle test over each island's faces, found by a sweep over x within
/// the island (O(n log n) for pieces that are not one long column of faces).
pub fn find_overlap(flat: &Flat) -> Option<(usize, usize)> {
    let eps = flat.tolerance;
    let tris: Vec<Cow<'static, [[usize; 3]]>> = flat
        .face_2d
        .iter()
        .map(|p| polygon::triangulate(p))
        .collect();
    for faces in &flat.islands {
        let mut boxes: Vec<(f64, f64, usize)> = faces
            .iter()
            .filter_map(|&f| {
                polygon::bounds(flat.face_2d[f].iter().copied()).map(|(lo, hi)| (lo.x, hi.x, f))
            })
            .collect();
        boxes.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        for (k, &(_, hx, f)) in boxes.iter().enumerate() {
            for &(lx, _, g) in &boxes[k + 1..] {
                if lx >= hx {
                    break;
                }
                if faces_overlap(&flat.face_2d[f], &tris[f], &flat.face_2d[g], &tris[g], eps) {
                    return Some((f.min(g), f.max(g)));
                }
            }
        }
    }
    None
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geom::mesh::{Face, Mesh};
    use std::path::PathBuf;

    fn surface(mesh: Mesh) -> Surface {
        Surface {
            name: "t".into(),
            source: PathBuf::from("t.obj"),
            mesh,
            warnings: Vec::new(),
            bends: None,
            charts: None,
            ..Default::default()
        }
    }

    pub(crate) fn cube(size: f64) -> Surface {
        surface(crate::surface::solids::cuboid(size, size, size))
    }

    fn check_isometry(flat: &Flat) {
        let mesh = &flat.surface.mesh;
        for (f, face) in mesh.faces.iter().enumerate() {
            let n = face.verts.len();
            for i in 0..n {
                for k in i + 1..n {
                    let d3 = mesh.vertices[face.verts[i]].distance(mesh.vertices[face.verts[k]]);
                    let d2 = flat.face_2d[f][i].distance(flat.face_2d[f][k]);
                    assert!((d3 - d2).abs() <= 1e-9 * d3, "face {f}: {d3} vs {d2}");
                }
            }
            assert!(polygon::signed_area(&flat.face_2d[f]) > 0.0);
        }
    }

    #[test]
    fn cube_unfolds_into_one_net_with_five_convex_folds() {
        let flat = unfold(cube(100.0), &UnfoldOptions::default()).unwrap();
        assert_eq!(flat.islands.len(), 1);
        assert_eq!(flat.joined.iter().filter(|&&j| j).count(), 5);
        for (e, &j) in flat.joined.iter().enumerate() {
            assert!((flat.dihedral[e] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
            let _ = j;
        }
        check_isometry(&flat);
        assert!(find_overlap(&flat).is_none());
        // Joined faces share the edge in the plane.
        for (e, edge) in flat.topology.edges.iter().enumerate() {
            if flat.joined[e] {
                let [(f, i), (g, j)] = [edge.uses[0], edge.uses[1]];
                let (p, q) = flat.corner_edge(f, i);
                let (q2, p2) = flat.corner_edge(g, j);
                assert!(p.distance(p2) < 1e-9 && q.distance(q2) < 1e-9);
            }
        }
    }

    #[test]
    fn a_fan_that_would_overlap_is_split() {
        // Twelve steep triangles around an apex: a cone with 720 degrees of total angle
        // at the tip (a saddle-like vertex) cannot lie flat in one piece.
        let mut vertices = vec![DVec3::new(0.0, 0.0, 0.0)];
        let n = 12;
        for k in 0..n {
            let t = k as f64 / n as f64 * std::f64::consts::TAU;
            let z = if k % 2 == 0 { 30.0 } else { -30.0 };
            vertices.push(DVec3::new(10.0 * t.cos(), 10.0 * t.sin(), z));
        }
        let faces = (0..n)
            .map(|k| Face {
                verts: vec![0, 1 + k, 1 + (k + 1) % n],
                line: None,
            })
            .collect();
        let flat = unfold(surface(Mesh { vertices, faces }), &UnfoldOptions::default()).unwrap();
        assert!(flat.islands.len() >= 2, "{}", flat.islands.len());
        check_isometry(&flat);
        assert!(find_overlap(&flat).is_none());
    }

    /// `unfold_onto` (issue 20, grafting): a cube's first two faces are two fixed layouts
    /// far apart; the four other faces join one or the other, each by a rigid motion (its
    /// edges as long as in 3D, its joined edges where the face it joins has them), and the two
    /// fixed layouts are never joined to each other or moved out of shape.
    #[test]
    fn faces_unfold_onto_fixed_layouts_without_joining_them() {
        let mesh = cube(10.0).mesh;
        let topo = mesh.topology();
        let a = vec![plane_of(&mesh, 0).unwrap()];
        let far = DVec2::new(1000.0, 0.0);
        let b = vec![plane_of(&mesh, 1)
            .unwrap()
            .into_iter()
            .map(|p| p + far)
            .collect::<Vec<_>>()];
        let (pos, which, joined) = unfold_onto(
            &mesh,
            &topo,
            &[&a, &b],
            &UnfoldOptions::default(),
            0.01,
            false,
        )
        .unwrap();
        assert_eq!((which[0], which[1]), (0, 1));
        assert!(which[2..].iter().all(|&w| w < 2));
        // The fixed layouts keep their shape (moved rigidly at most).
        let side = |f: usize, i: usize| pos[f][i].distance(pos[f][(i + 1) % 4]);
        for f in 0..6 {
            for i in 0..4 {
                assert!((side(f, i) - 10.0).abs() < 1e-9, "face {f}: {}", side(f, i));
            }
        }
        let mut joins = 0;
        for (e, edge) in topo.edges.iter().enumerate() {
            let [(f, i), (g, j)] = [edge.uses[0], edge.uses[1]];
            if joined[e] {
                joins += 1;
                assert_eq!(which[f], which[g], "edge {e} joins the two layouts");
                assert!(pos[f][i].distance(pos[g][(j + 1) % 4]) < 1e-9);
                assert!(pos[f][(i + 1) % 4].distance(pos[g][j]) < 1e-9);
            }
        }
        // Every free face joined once: four joins.
        assert_eq!(joins, 4);
        // Too few faces for the fixed layouts: refused.
        assert!(unfold_onto(
            &mesh,
            &topo,
            &[&a, &a, &a, &a, &a, &a, &a],
            &UnfoldOptions::default(),
            0.01,
            false
        )
        .is_none());
    }

    #[test]
    fn planar_grid_has_no_slits() {
        // A 3 x 3 grid of triangulated squares: everything joins, nothing cut inside.
        let mut vertices = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                vertices.push(DVec3::new(x as f64 * 10.0, y as f64 * 10.0, 0.0));
            }
        }
        let mut faces = Vec::new();
        for y in 0..3 {
            for x in 0..3 {
                let a = y * 4 + x;
                faces.push(Face {
                    verts: vec![a, a + 1, a + 5],
                    line: None,
                });
                faces.push(Face {
                    verts: vec![a, a + 5, a + 4],
                    line: None,
                });
            }
        }
        let flat = unfold(surface(Mesh { vertices, faces }), &UnfoldOptions::default()).unwrap();
        assert_eq!(flat.islands.len(), 1);
        let interior = flat
            .topology
            .edges
            .iter()
            .filter(|e| e.uses.len() == 2)
            .count();
        assert_eq!(flat.joined.iter().filter(|&&j| j).count(), interior);
    }
}
