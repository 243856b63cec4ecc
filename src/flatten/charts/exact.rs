//! The two ways a piece is kept within the material's tolerance when stretch alone cannot do
//! it (issue 20, items 2 and 3; the thesis' §5.3 leaves both open):
//!
//! - **Exact layout** ([`exact`]): a chart still over the tolerance once it may be split no
//!   further (a horn, a finger tip, a knot's tight turn: too curved for its size) is laid out
//!   as the polyhedral unfolder lays a papercraft model ([`crate::flatten::unfold()`]): every
//!   face moved into the plane by a rigid motion, so every edge keeps its 3D length and the
//!   L2 stretch is 1. What that costs is slits: the edges the unfolder leaves cut inside an
//!   island become cuts of the piece, drawn with seam marks like any cut, and its bends are
//!   fold lines as on every piece. Where the unfolding would overlap itself it gives several
//!   islands, each a piece.
//! - **Grafting** ([`graft`]): a small piece that cannot be laid out again together with a
//!   neighbour (the two as one over the tolerance) is unfolded exactly onto its neighbours as
//!   they are laid ([`crate::flatten::unfold::unfold_onto`]): each neighbour is an island
//!   that keeps its layout, the small piece's faces start apart and are joined to the
//!   neighbours and to each other in the unfolder's order (flat and convex edges first, long
//!   before short), each join a rigid motion of the smaller island, refused where it would
//!   overlap or would join two neighbours. So the small piece may be shared out: a face at a
//!   saddle that fits beside no one neighbour's layout may fit beside another's. An edge
//!   joined to a neighbour has its two ends put exactly where the neighbour has them (they
//!   are off by the difference between the edge's length as the neighbour lays it, matched to
//!   3D, and its 3D length), and so does every grafted corner laid at those points. Edges of
//!   a grafted face left apart from the faces beside it in the same piece become cuts (slits
//!   with seam marks on both sides). The graft is kept when every face is joined to a
//!   neighbour and each neighbour stays flip-free and within the tolerance (the grafted
//!   faces are isometric up to those ends, so it does).

use super::{Charts, Laid};
use crate::flatten::{distortion, unfold, UnfoldOptions};
use crate::geom::mesh::{Face, Mesh, Topology};
use crate::surface::Surface;
use glam::DVec2;
use std::collections::HashMap;

/// `faces` laid out exactly (see the module doc): one [`Laid`] per island of the unfolding,
/// its cuts the edges left cut inside the island; `None` when the unfolder refuses a face.
/// The unfolder's overlap tolerance is `eps`, the charts' own.
pub(super) fn exact(ctx: &Charts, faces: &[usize], eps: f64) -> Option<Vec<Laid>> {
    let mesh = submesh(ctx, faces);
    let opts = UnfoldOptions {
        tolerance: eps,
        ..UnfoldOptions::default()
    };
    let flat = unfold(
        Surface {
            mesh,
            ..Surface::default()
        },
        &opts,
    )
    .ok()?;
    let mut out = Vec::with_capacity(flat.islands.len());
    for (k, island) in flat.islands.iter().enumerate() {
        let mut cuts = Vec::new();
        for &i in island {
            for (j, &le) in flat.topology.face_edges[i].iter().enumerate() {
                let edge = &flat.topology.edges[le];
                let inside =
                    edge.uses.len() == 2 && edge.uses.iter().all(|u| flat.face_island[u.0] == k);
                if inside && !flat.joined[le] {
                    cuts.push(ctx.topo.face_edges[faces[i]][j]);
                }
            }
        }
        cuts.sort_unstable();
        cuts.dedup();
        let gfaces: Vec<usize> = island.iter().map(|&i| faces[i]).collect();
        let uv: Vec<Vec<DVec2>> = island.iter().map(|&i| flat.face_2d[i].clone()).collect();
        let stretch = distortion::stretch(ctx.mesh, &gfaces, &uv);
        out.push(Laid {
            faces: gfaces,
            cuts,
            uv,
            stretch,
            gusset: false,
        });
    }
    Some(out)
}

/// Graft `done[part]` onto its neighbours `near` (see the module doc): each neighbour that
/// takes faces becomes the two as one. The neighbours that took faces, each with the faces it
/// took and what it becomes; `None` when a face stays apart or a neighbour would end over
/// `tolerance` (the material's L2 tolerance). `eps` is the overlap depth that counts as
/// touching.
pub(super) fn graft(
    ctx: &Charts,
    done: &[Laid],
    near: &[usize],
    part: usize,
    tolerance: f64,
    eps: f64,
) -> Option<Vec<(usize, Vec<usize>, Laid)>> {
    let mut faces: Vec<usize> = near
        .iter()
        .flat_map(|&k| done[k].faces.iter().copied())
        .collect();
    let n = faces.len();
    faces.extend(&done[part].faces);
    let mesh = submesh(ctx, &faces);
    let topo = mesh.topology();
    let layouts: Vec<&[Vec<DVec2>]> = near.iter().map(|&k| done[k].uv.as_slice()).collect();
    // The unfolder's order, else the edges to the neighbours first.
    let opts = UnfoldOptions::default();
    let (mut uv, which, joined) = unfold::unfold_onto(&mesh, &topo, &layouts, &opts, eps, false)
        .or_else(|| unfold::unfold_onto(&mesh, &topo, &layouts, &opts, eps, true))?;
    snap_ends(&mesh, &topo, &mut uv, &joined, n);
    let mut out = Vec::new();
    for (t, &k) in near.iter().enumerate() {
        let took: Vec<usize> = (n..faces.len()).filter(|&f| which[f] == t).collect();
        if took.is_empty() {
            continue;
        }
        let local: Vec<usize> = (0..n)
            .filter(|&f| which[f] == t)
            .chain(took.iter().copied())
            .collect();
        let fs: Vec<usize> = local.iter().map(|&f| faces[f]).collect();
        let us: Vec<Vec<DVec2>> = local.iter().map(|&f| uv[f].clone()).collect();
        let s = distortion::stretch(ctx.mesh, &fs, &us);
        if s.flipped > 0 || s.l2 > tolerance {
            return None;
        }
        // Edges of the union with a face grafted whose two sides are apart.
        let mut cuts = done[k].cuts.clone();
        let mut inside = vec![false; faces.len()];
        for &f in &local {
            inside[f] = true;
        }
        for &f in &took {
            for (i, &e) in topo.face_edges[f].iter().enumerate() {
                let Some(&(g, j)) = topo.edges[e].uses.iter().find(|u| u.0 != f) else {
                    continue;
                };
                if topo.edges[e].uses.len() != 2 || !inside[g] {
                    continue;
                }
                if !super::coincide(&uv[f], i, &uv[g], j) {
                    cuts.push(ctx.topo.face_edges[faces[f]][i]);
                }
            }
        }
        cuts.sort_unstable();
        cuts.dedup();
        out.push((
            k,
            took.iter().map(|&f| faces[f]).collect(),
            Laid {
                faces: fs,
                cuts,
                uv: us,
                stretch: s,
                gusset: false,
            },
        ));
    }
    Some(out)
}

/// Put the ends of every edge joined between a fixed face (`< n`) and a grafted one where the
/// fixed face has them, and every grafted corner laid at such an end with it (see the module
/// doc).
fn snap_ends(mesh: &Mesh, topo: &Topology, uv: &mut [Vec<DVec2>], joined: &[bool], n: usize) {
    let mut ends: HashMap<usize, Vec<(DVec2, DVec2)>> = HashMap::new();
    for (e, edge) in topo.edges.iter().enumerate() {
        let [(f, i), (g, j)] = edge.uses[..] else {
            continue;
        };
        if !joined[e] || (f < n) == (g < n) {
            continue;
        }
        let ((f, i), (g, j)) = if f < n {
            ((f, i), (g, j))
        } else {
            ((g, j), (f, i))
        };
        let (mf, mg) = (uv[f].len(), uv[g].len());
        let [a, b] = [mesh.faces[f].verts[i], mesh.faces[f].verts[(i + 1) % mf]];
        // The edge runs the other way round in `g`.
        ends.entry(a)
            .or_default()
            .push((uv[g][(j + 1) % mg], uv[f][i]));
        ends.entry(b)
            .or_default()
            .push((uv[g][j], uv[f][(i + 1) % mf]));
    }
    let near = 1e-3 * super::mean_edge(mesh, topo);
    for (f, corners) in uv.iter_mut().enumerate().skip(n) {
        for (c, &v) in mesh.faces[f].verts.iter().enumerate() {
            let to = ends
                .get(&v)
                .and_then(|l| l.iter().find(|(from, _)| from.distance(corners[c]) <= near));
            if let Some(&(_, to)) = to {
                corners[c] = to;
            }
        }
    }
}

/// The mesh of `faces` alone (face `i` is `faces[i]`, vertices renumbered in order of first
/// use).
fn submesh(ctx: &Charts, faces: &[usize]) -> Mesh {
    let mut local: HashMap<usize, usize> = HashMap::new();
    let mut mesh = Mesh::default();
    for &f in faces {
        let face = &ctx.mesh.faces[f];
        let mut verts = Vec::with_capacity(face.verts.len());
        for &v in &face.verts {
            let next = mesh.vertices.len();
            let l = *local.entry(v).or_insert(next);
            if l == next {
                mesh.vertices.push(ctx.mesh.vertices[v]);
            }
            verts.push(l);
        }
        mesh.faces.push(Face {
            verts,
            line: face.line,
        });
    }
    mesh
}
