//! The charts once laid, as one [`Flat`]: each laid chart an island (numbered by its smallest
//! face), the edges joined where both sides lie at one place inside an island, a warning on
//! the surface per piece left over the material's tolerance, and the cuts and charts the
//! pattern stage reads. Also the surface's own cuts as edge ids, the form the charts work in.

use super::{coincide, mean_edge, FlattenOptions, Laid};
use crate::flatten::Flat;
use crate::geom::mesh::Topology;
use crate::surface::Surface;
use glam::DVec2;

/// The surface's cuts as edge ids (pairs that are not edges of the mesh are ignored), sorted.
pub(super) fn edge_ids(topology: &Topology, pairs: &[[usize; 2]]) -> Vec<usize> {
    let mut edge_of: std::collections::HashMap<[usize; 2], usize> = Default::default();
    for (e, edge) in topology.edges.iter().enumerate() {
        let [a, b] = edge.verts;
        edge_of.insert([a.min(b), a.max(b)], e);
    }
    let mut ids: Vec<usize> = pairs
        .iter()
        .filter_map(|&[a, b]| edge_of.get(&[a.min(b), a.max(b)]).copied())
        .collect();
    ids.sort_unstable();
    ids.dedup();
    ids
}

/// The laid charts as islands (numbered by smallest face) of a [`Flat`]; the surface gets a
/// warning per piece over the tolerance, the cuts that stayed inside pieces and the islands
/// as its charts.
pub(super) fn assemble(
    mut surface: Surface,
    topology: Topology,
    mut done: Vec<Laid>,
    opts: &FlattenOptions,
) -> Flat {
    let mesh = &surface.mesh;
    let nf = mesh.faces.len();
    let mut over: Vec<(usize, f64)> = Vec::new();
    // Islands numbered by smallest face.
    done.sort_by_key(|l| l.faces.iter().copied().min().unwrap_or(0));
    let mut face_2d: Vec<Vec<DVec2>> = vec![Vec::new(); nf];
    let mut face_island = vec![0; nf];
    let mut islands = Vec::with_capacity(done.len());
    let ne = topology.edges.len();
    let mut is_cut = vec![false; ne];
    for (k, l) in done.iter().enumerate() {
        if l.stretch.l2 > opts.tolerance {
            over.push((k, l.stretch.l2));
        }
        for (f, c) in l.faces.iter().zip(&l.uv) {
            face_2d[*f] = c.clone();
            face_island[*f] = k;
        }
        for &e in &l.cuts {
            is_cut[e] = true;
        }
        let mut faces = l.faces.clone();
        faces.sort_unstable();
        islands.push(faces);
    }
    let mut joined = vec![false; ne];
    let mut dihedral = vec![0.0; ne];
    for (e, edge) in topology.edges.iter().enumerate() {
        let [(f, i), (g, j)] = edge.uses[..] else {
            continue;
        };
        dihedral[e] = mesh.signed_dihedral(f, i, g).unwrap_or(0.0);
        joined[e] = face_island[f] == face_island[g]
            && !is_cut[e]
            && coincide(&face_2d[f], i, &face_2d[g], j);
    }
    let mean = mean_edge(mesh, &topology);
    for (k, l2) in over {
        surface.warnings.push(format!(
            "surface `{}`: piece {} stretches by L2 {:.5}, over the material's {:.4}: expect wrinkles or gaps",
            surface.name,
            k + 1,
            l2,
            opts.tolerance
        ));
    }
    let mut cuts: Vec<[usize; 2]> = (0..ne)
        .filter(|&e| is_cut[e])
        .map(|e| {
            let [a, b] = topology.edges[e].verts;
            [a.min(b), a.max(b)]
        })
        .collect();
    cuts.sort_unstable();
    surface.cuts = cuts;
    surface.charts = Some(face_island.clone());
    Flat {
        surface,
        topology,
        face_2d,
        face_island,
        islands,
        joined,
        dihedral,
        tolerance: opts.unfold.tolerance.min(0.01 * mean),
    }
}

/// The islands of `flat` under 1 % of its area (`merge::SMALL_SHARE`) that are not a whole
/// connected part of the mesh (issue 20: a piece too small to handle, where a person would
/// rather have it joined to a neighbour).
pub fn small_islands(flat: &Flat) -> usize {
    let mesh = &flat.surface.mesh;
    let nf = mesh.faces.len();
    let mut parts = crate::geom::unionfind::UnionFind::new(nf);
    for e in &flat.topology.edges {
        for w in e.uses.windows(2) {
            parts.union(w[0].0, w[1].0);
        }
    }
    let mut part_faces = vec![0usize; nf];
    for f in 0..nf {
        part_faces[parts.find(f)] += 1;
    }
    let area = |faces: &[usize]| faces.iter().map(|&f| mesh.face_area(f)).sum::<f64>();
    let total: f64 = flat.islands.iter().map(|i| area(i)).sum();
    flat.islands
        .iter()
        .filter(|i| !i.is_empty() && area(i) < super::merge::SMALL_SHARE * total)
        .filter(|i| part_faces[parts.find(i[0])] != i.len())
        .count()
}
