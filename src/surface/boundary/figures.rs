//! §4 metrics of a finished triangulation, for the report: triangles, interior triangles
//! (predictability: no edge on the input), largest dihedral angle (smoothness), sum of squared
//! dihedral angles (fairness), and how many interior edges are locally convex (the hull test of
//! [`crate::geom::hull::segment_on_hull`] against the loop neighbours of the edge's ends); and
//! the output mesh over the vertices.

use super::Figures;
use crate::geom::hull::segment_on_hull;
use crate::geom::mesh::Mesh;
use glam::DVec3;
use std::collections::{HashMap, HashSet};

pub(super) fn to_mesh(verts: &[DVec3], faces: &[[usize; 3]]) -> Mesh {
    Mesh::from_polygons(verts.to_vec(), faces)
}

pub(super) fn unit_normal(p: &[DVec3], t: [usize; 3]) -> DVec3 {
    (p[t[1]] - p[t[0]])
        .cross(p[t[2]] - p[t[0]])
        .normalize_or_zero()
}

pub(super) fn angle(n1: DVec3, n2: DVec3) -> f64 {
    n1.cross(n2).length().atan2(n1.dot(n2))
}

/// Report figures of a finished triangulation (global vertex ids).
pub(super) fn figures(
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
