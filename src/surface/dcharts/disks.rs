//! Charts made disks (Julius 2006, thesis §5.2.3, "cuts connecting the chart boundary
//! loops"): every chart that is not a topological disk gets seams inside it (a tube, a sphere
//! with holes, a closed shell, a chart with handles: [`disk_cuts`]), carried by
//! [`super::Segmentation::cuts`] and [`crate::surface::Surface::cuts`]. Only a chart that
//! cutting cannot make a disk (faces joined through a single vertex, or across a non-manifold
//! edge) is split in two along the bisector of its two most distant faces ([`bisect`]).
//! Darts (partial cuts toward the most curved region) and gussets are made by the flatten
//! stage, which knows the stretch.

use crate::geom::cut::{bisect, disk_cuts, Graph};
use crate::geom::mesh::{Mesh, Topology};

/// Split every chart that cutting cannot make a disk ([`disk_cuts`]: faces joined only
/// through a vertex, or non-manifold charts; handles are cut, not split) until all can be;
/// returns the number of splits.
pub(super) fn make_disks(
    mesh: &Mesh,
    topo: &Topology,
    g: &Graph,
    chart: &mut [usize],
    count: &mut usize,
) -> usize {
    let mut splits = 0;
    let mut queue: Vec<usize> = (0..*count).collect();
    // Each split makes a smaller chart; single faces are disks, so this ends.
    while let Some(c) = queue.pop() {
        let faces: Vec<usize> = (0..chart.len()).filter(|&f| chart[f] == c).collect();
        if faces.len() <= 1 || disk_cuts(mesh, topo, g, &faces, &|_| false).is_some() {
            continue;
        }
        let (_, b) = bisect(g, &faces);
        if b.is_empty() || b.len() == faces.len() {
            continue;
        }
        let nc = *count;
        *count += 1;
        for f in b {
            chart[f] = nc;
        }
        splits += 1;
        queue.push(c);
        queue.push(nc);
    }
    splits
}

/// The edges cut open inside the charts so that every chart is a disk ([`disk_cuts`]), as
/// mesh vertex pairs (smaller first), sorted.
pub(super) fn chart_cuts(
    mesh: &Mesh,
    topo: &Topology,
    g: &Graph,
    chart: &[usize],
    count: usize,
) -> Vec<[usize; 2]> {
    let mut cuts = Vec::new();
    let mut faces_of: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (f, &c) in chart.iter().enumerate() {
        faces_of[c].push(f);
    }
    for faces in &faces_of {
        for e in disk_cuts(mesh, topo, g, faces, &|_| false).unwrap_or_default() {
            let [a, b] = topo.edges[e].verts;
            cuts.push([a.min(b), a.max(b)]);
        }
    }
    cuts.sort_unstable();
    cuts
}
