//! Merging (Julius 2006, thesis §5.2.3): two adjacent charts merge when the faces within
//! [`DChartsOptions::merge_rings`] rings of their common boundary fit a cylinder (`θ = π/2`)
//! with mean error below `η` ([`DChartsOptions::eta`]), best pair first, and only when the
//! merged chart can be cut into a disk ([`disk_cuts`]).
//!
//! A merge that makes a handle (two charts meeting along two separate boundary segments,
//! closing a ring) is allowed: the thesis' criterion is about developability alone, the merged
//! region fits a cylinder near the common boundary by `η`, and handles are cut open like any
//! chart that is not a disk. Whether the merged chart flattens within the material's tolerance
//! is the flatten stage's question (it knows the material): it adds darts and gussets, and
//! splits or reports a piece that stays over. Checking it here would need the parameteriser
//! inside the surface stage.
//!
//! Choices where the thesis is silent: a pair rejected because its merge cannot be cut into a
//! disk is tried again once one of its charts has changed; ties between equal errors go to
//! the pair with the smaller chart numbers.

use super::{compact_ids, DChartsOptions};
use crate::geom::cut::{disk_cuts, Graph};
use crate::geom::mesh::{Mesh, Topology};
use crate::geom::proxy;

/// Merge adjacent charts whose common boundary region fits a cylinder (§5.2.3); returns the
/// number of merges.
pub(super) fn merge(
    mesh: &Mesh,
    topo: &Topology,
    g: &Graph,
    o: &DChartsOptions,
    chart: &mut [usize],
    count: &mut usize,
) -> usize {
    let nf = chart.len();
    let mut merges = 0;
    let mut rejected: std::collections::HashSet<(usize, usize)> = Default::default();
    loop {
        // Boundary faces of each adjacent pair.
        let mut pairs: std::collections::BTreeMap<(usize, usize), Vec<usize>> = Default::default();
        for f in 0..nf {
            for &(u, _) in &g.adj[f] {
                let (a, b) = (chart[f], chart[u]);
                if a != b {
                    pairs.entry((a.min(b), a.max(b))).or_default().push(f);
                }
            }
        }
        let mut best: Option<(f64, (usize, usize))> = None;
        let mut stamp = vec![usize::MAX; nf];
        for (k, (&(a, b), border)) in pairs.iter().enumerate() {
            if rejected.contains(&(a, b)) {
                continue;
            }
            // Rings around the common boundary, inside the two charts.
            let mut region: Vec<usize> = Vec::new();
            for &f in border {
                if stamp[f] != k {
                    stamp[f] = k;
                    region.push(f);
                }
            }
            let mut startk = 0;
            for _ in 0..o.merge_rings {
                let end = region.len();
                for i in startk..end {
                    let t = region[i];
                    for &(u, _) in &g.adj[t] {
                        if stamp[u] != k && (chart[u] == a || chart[u] == b) {
                            stamp[u] = k;
                            region.push(u);
                        }
                    }
                }
                startk = end;
            }
            let Some(err) = proxy::cylinder_error(&g.moments(region.iter().copied())) else {
                continue;
            };
            if err < o.eta && best.is_none_or(|(e, _)| err < e) {
                best = Some((err, (a, b)));
            }
        }
        let Some((_, (a, b))) = best else { break };
        let faces: Vec<usize> = (0..nf)
            .filter(|&f| chart[f] == a || chart[f] == b)
            .collect();
        if disk_cuts(mesh, topo, g, &faces, &|_| false).is_none() {
            rejected.insert((a, b));
            continue;
        }
        for c in chart.iter_mut() {
            if *c == b {
                *c = a;
            }
        }
        // Pairs involving a changed: test them again.
        rejected.retain(|&(x, y)| x != a && y != a && x != b && y != b);
        merges += 1;
    }
    compact_ids(chart, count);
    merges
}
