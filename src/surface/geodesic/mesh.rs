//! The folded sheet as a mesh (§3.3 step 4, §3.4, §4.2): the sheet is cut along the rulings
//! into regions (a planar subdivision by half-edges), each region is moved rigidly by the folds
//! between it and the region holding the first piece's start, and triangulated.
//!
//! Regions the rulings do not reach (corners beyond the first and last ruling, the sheet beyond
//! the line's ends, the sheet between several curved pieces) are simply not folded: they stay
//! planar and join the curved part tangentially along its end ruling (§3.4, §4.2). Several
//! curved pieces are folds along their own lines; the first piece is placed where its control
//! curve is, the others follow rigidly through the sheet (§4.2: "wield the polygon B to its
//! shared edge with A using a rigid transformation"), so only their shape, not their position,
//!
//! Every triangle is checked to be the flat one moved rigidly (edge lengths to 1e-7 relative):
//! rulings meeting where the admissibility checks do not look would break that.

use super::folds::fold_map;
use super::path::Flat;
use super::sheet::{Chain, Crossing};
use super::{GeodesicError, Ruling};
use crate::geom::mesh::{Face, Mesh};
use crate::geom::polygon;
use glam::{DAffine3, DVec2, DVec3};
use std::collections::{HashMap, VecDeque};

/// The sheet cut along the rulings: nodes on the flat sheet, undirected edges
/// `(from, to, ruling)` (ring edges run with the sheet on their left), faces as loops of
/// half-edges (`2e` runs from → to, `2e + 1` back) and the face of each half-edge.
pub(super) struct Subdivision {
    pub(super) pos: Vec<DVec2>,
    edges: Vec<(usize, usize, Option<usize>)>,
    faces: Vec<Vec<usize>>,
    face_of: Vec<usize>,
}

impl Subdivision {
    fn from(&self, h: usize) -> usize {
        let e = self.edges[h / 2];
        if h % 2 == 0 {
            e.0
        } else {
            e.1
        }
    }

    fn to(&self, h: usize) -> usize {
        self.from(h ^ 1)
    }
}

/// Cut the sheet along the rulings' chains; sets each ruling's `edges` (node pairs).
pub(super) fn subdivide(
    rings: &[Vec<DVec2>],
    chains: &[Chain],
    rulings: &mut [Ruling],
) -> Result<Subdivision, GeodesicError> {
    let (pos, edges) = graph(rings, chains, rulings);
    let (faces, face_of) = faces(&pos, &edges)?;
    Ok(Subdivision {
        pos,
        edges,
        faces,
        face_of,
    })
}

/// Nodes (ring vertices, then ruling ends on ring edges) and undirected edges.
#[allow(clippy::type_complexity)]
fn graph(
    rings: &[Vec<DVec2>],
    chains: &[Chain],
    rulings: &mut [Ruling],
) -> (Vec<DVec2>, Vec<(usize, usize, Option<usize>)>) {
    let mut pos: Vec<DVec2> = Vec::new();
    let mut ring_node: Vec<Vec<usize>> = Vec::new();
    for r in rings {
        ring_node.push((pos.len()..pos.len() + r.len()).collect());
        pos.extend_from_slice(r);
    }
    let mut on_edge: HashMap<(usize, usize), Vec<(f64, usize)>> = HashMap::new();
    let mut node_at = |c: &Crossing, pos: &mut Vec<DVec2>| -> usize {
        let r = &rings[c.ring];
        let n = r.len();
        let (a, b) = (r[c.edge], r[(c.edge + 1) % n]);
        let len = a.distance(b);
        if c.u * len <= 1e-9 {
            return ring_node[c.ring][c.edge];
        }
        if (1.0 - c.u) * len <= 1e-9 {
            return ring_node[c.ring][(c.edge + 1) % n];
        }
        let list = on_edge.entry((c.ring, c.edge)).or_default();
        if let Some(&(_, id)) = list.iter().find(|(u, _)| (u - c.u).abs() * len <= 1e-9) {
            return id;
        }
        let id = pos.len();
        pos.push(a + (b - a) * c.u);
        list.push((c.u, id));
        id
    };
    // Undirected edges: (from, to, ruling) — ring edges run with the sheet on their left.
    let mut edges: Vec<(usize, usize, Option<usize>)> = Vec::new();
    for (ri, ch) in chains.iter().enumerate() {
        let mut segs = Vec::new();
        for (c0, c1) in ch {
            let (n0, n1) = (node_at(c0, &mut pos), node_at(c1, &mut pos));
            if n0 != n1 && pos[n0].distance(pos[n1]) > 1e-9 {
                edges.push((n0, n1, Some(ri)));
                segs.push([n0, n1]);
            }
        }
        rulings[ri].edges = segs;
    }
    for (ri, r) in rings.iter().enumerate() {
        for i in 0..r.len() {
            let mut pts = vec![(0.0, ring_node[ri][i])];
            if let Some(list) = on_edge.get(&(ri, i)) {
                let mut l = list.clone();
                l.sort_by(|a, b| a.0.total_cmp(&b.0));
                pts.extend(l);
            }
            pts.push((1.0, ring_node[ri][(i + 1) % r.len()]));
            for w in pts.windows(2) {
                edges.push((w[0].1, w[1].1, None));
            }
        }
    }
    (pos, edges)
}

/// The faces on the sheet's side, as half-edge loops, and the face of each half-edge.
#[allow(clippy::type_complexity)]
fn faces(
    pos: &[DVec2],
    edges: &[(usize, usize, Option<usize>)],
) -> Result<(Vec<Vec<usize>>, Vec<usize>), GeodesicError> {
    // Half-edges 2e (from → to) and 2e + 1; ring edges' twins face away from the sheet.
    let nh = 2 * edges.len();
    let from = |h: usize| {
        let e = edges[h / 2];
        if h % 2 == 0 {
            e.0
        } else {
            e.1
        }
    };
    let to = |h: usize| from(h ^ 1);
    let mut out: Vec<Vec<usize>> = vec![Vec::new(); pos.len()];
    for h in 0..nh {
        out[from(h)].push(h);
    }
    let ang = |h: usize| {
        let v = pos[to(h)] - pos[from(h)];
        v.y.atan2(v.x)
    };
    for o in out.iter_mut() {
        o.sort_by(|&a, &b| ang(a).total_cmp(&ang(b)));
    }
    let next = |h: usize| -> usize {
        let v = to(h);
        let o = &out[v];
        let twin = h ^ 1;
        let i = o.iter().position(|&x| x == twin).unwrap_or(0);
        o[(i + o.len() - 1) % o.len()]
    };
    let sheet_side = |h: usize| edges[h / 2].2.is_some() || h % 2 == 0;
    let mut face_of = vec![usize::MAX; nh];
    let mut faces: Vec<Vec<usize>> = Vec::new();
    for h0 in 0..nh {
        if face_of[h0] != usize::MAX || !sheet_side(h0) {
            continue;
        }
        let f = faces.len();
        let mut loop_ = Vec::new();
        let mut h = h0;
        let mut guard = 0;
        while face_of[h] == usize::MAX {
            face_of[h] = f;
            loop_.push(h);
            h = next(h);
            guard += 1;
            if guard > nh {
                break;
            }
        }
        if h != h0 {
            return Err(GeodesicError::Mesh(
                "the rulings and the outline do not make a valid subdivision of the sheet (rulings meeting on the outline?)"
                    .into(),
            ));
        }
        faces.push(loop_);
    }
    Ok((faces, face_of))
}

/// For each ruling, whether the line runs to its left (a hole's cut line: always).
pub(super) fn forward_left_of(rulings: &[Ruling], flats: &[Flat]) -> Vec<bool> {
    rulings
        .iter()
        .map(|r| {
            let line_dir = match r.piece {
                Some(p) => flats[p].at(r.s).t,
                None => r.dir.perp(),
            };
            r.dir.perp_dot(line_dir) > 0.0
        })
        .collect()
}

/// Region transforms, breadth first from the face holding the first piece's start.
pub(super) fn place_faces(
    sub: &Subdivision,
    rulings: &[Ruling],
    flats: &[Flat],
    forward_left: &[bool],
    place: DAffine3,
) -> Vec<Option<DAffine3>> {
    let Subdivision {
        pos,
        edges,
        faces,
        face_of,
    } = sub;
    let from = |h: usize| sub.from(h);
    let to = |h: usize| sub.to(h);
    let first_fold = rulings
        .iter()
        .filter(|r| r.piece == Some(0))
        .map(|r| r.s)
        .next()
        .unwrap_or(flats[0].len());
    let probe = flats[0]
        .at((0.5 * first_fold).min(1e-3 * first_fold.max(1.0)))
        .p;
    let face_poly = |f: usize| -> Vec<DVec2> { faces[f].iter().map(|&h| pos[from(h)]).collect() };
    let root = (0..faces.len())
        .find(|&f| polygon::contains(&face_poly(f), probe))
        .unwrap_or(0);
    let maps: Vec<DAffine3> = rulings
        .iter()
        .map(|r| fold_map(r.point, r.dir, r.angle))
        .collect();
    let mut xf: Vec<Option<DAffine3>> = vec![None; faces.len()];
    xf[root] = Some(place);
    let mut queue = VecDeque::from([root]);
    while let Some(f) = queue.pop_front() {
        let Some(m) = xf[f] else { continue };
        for &h in &faces[f] {
            let g = face_of[h ^ 1];
            if g == usize::MAX || xf[g].is_some() {
                continue;
            }
            let mg = match edges[h / 2].2 {
                None => m,
                Some(ri) => {
                    let r = &rulings[ri];
                    let along = (pos[to(h)] - pos[from(h)]).dot(r.dir) > 0.0;
                    // Face f lies left of h; f is on the ruling's left iff h runs along it.
                    let f_forward = along == forward_left[ri];
                    if f_forward {
                        m * maps[ri].inverse()
                    } else {
                        m * maps[ri]
                    }
                }
            };
            xf[g] = Some(mg);
            queue.push_back(g);
        }
    }
    xf
}

/// The 3D position of every node and the triangles of the faces, checked to be rigid copies of
/// the flat ones.
pub(super) fn fold_triangles(
    sub: &Subdivision,
    xf: &[Option<DAffine3>],
) -> Result<(Vec<DVec3>, Vec<[usize; 3]>), GeodesicError> {
    let Subdivision { pos, faces, .. } = sub;
    let from = |h: usize| sub.from(h);
    let mut vert3 = vec![DVec3::NAN; pos.len()];
    let mut triangles = Vec::new();
    for (f, lp) in faces.iter().enumerate() {
        let m = xf[f].ok_or_else(|| {
            GeodesicError::Mesh("a part of the sheet is not connected to the rest".into())
        })?;
        let ids: Vec<usize> = lp.iter().map(|&h| from(h)).collect();
        for &v in &ids {
            if vert3[v].is_nan() {
                vert3[v] = m.transform_point3(DVec3::new(pos[v].x, pos[v].y, 0.0));
            }
        }
        let poly: Vec<DVec2> = ids.iter().map(|&v| pos[v]).collect();
        if polygon::signed_area(&poly) <= 1e-12 {
            continue;
        }
        for t in polygon::triangulate(&poly).iter() {
            let tri = [ids[t[0]], ids[t[1]], ids[t[2]]];
            let area = (pos[tri[1]] - pos[tri[0]]).perp_dot(pos[tri[2]] - pos[tri[0]]);
            if area > 1e-12 {
                triangles.push(tri);
            }
        }
    }
    // Every triangle must be the flat one moved rigidly; rulings meeting where the checks
    // above do not look (around holes, in concave corners) would break that.
    for t in &triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let (l2, l3) = (pos[a].distance(pos[b]), vert3[a].distance(vert3[b]));
            let err = (l3 - l2).abs();
            if err.is_nan() || err > 1e-7 * l2.max(1.0) {
                return Err(GeodesicError::Mesh(format!(
                    "the rulings cross on the sheet near ({:.2}, {:.2}): the sheet cannot bend this way without creasing; bend less there",
                    pos[a].x, pos[a].y
                )));
            }
        }
    }
    Ok((vert3, triangles))
}

/// Keep only used vertices: the mesh, the flat position of each vertex, and the rulings'
/// edges renumbered (with their 3D directions).
pub(super) fn compact(
    pos: &[DVec2],
    vert3: &[DVec3],
    triangles: &[[usize; 3]],
    rulings: &mut [Ruling],
) -> (Mesh, Vec<DVec2>) {
    let mut remap = vec![usize::MAX; pos.len()];
    let mut vertices = Vec::new();
    let mut flat = Vec::new();
    for t in triangles {
        for &v in t {
            if remap[v] == usize::MAX {
                remap[v] = vertices.len();
                vertices.push(vert3[v]);
                flat.push(pos[v]);
            }
        }
    }
    let mesh = Mesh {
        vertices,
        faces: triangles
            .iter()
            .map(|t| Face {
                verts: t.iter().map(|&v| remap[v]).collect(),
                line: None,
            })
            .collect(),
    };
    for r in rulings.iter_mut() {
        r.edges = r
            .edges
            .iter()
            .filter(|e| remap[e[0]] != usize::MAX && remap[e[1]] != usize::MAX)
            .map(|e| [remap[e[0]], remap[e[1]]])
            .collect();
        if let Some(e) = r.edges.first() {
            r.dir_3d = (mesh.vertices[e[1]] - mesh.vertices[e[0]]).normalize_or_zero();
        }
    }
    (mesh, flat)
}
