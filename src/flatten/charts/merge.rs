//! Few pieces (issue 20, item 3; thesis §5.2.3 merges charts, §5.3 keeps pieces a person can
//! handle): after every chart is laid flat, a piece under [`SMALL_SHARE`] of the surface's
//! area is merged into a neighbour when the two laid flat as one stay within the material's
//! tolerance, without a flip or an overlap, their seams matched as every layout's are.
//!
//! Choices where the thesis is silent: small pieces are tried smallest first; the neighbours
//! in order of the boundary length they share with it (longest first, ties by index), at most
//! [`MERGE_TRIES`] of them; a neighbour grown by a merge may take the next small piece too.
//! The merged chart keeps the cuts of both (and more where it is not a disk).

use super::overlap::merge_into;
use super::{Charts, FlattenOptions, Laid};
use std::collections::BTreeMap;

/// Pieces under this share of the surface's area are merged where they can be.
pub(crate) const SMALL_SHARE: f64 = 0.01;
/// Neighbours tried per small piece.
pub(crate) const MERGE_TRIES: usize = 3;

/// Merge the small pieces of `done` into neighbours (see the module doc).
pub(super) fn merge_small(ctx: &Charts, done: &mut Vec<Laid>, opts: &FlattenOptions, eps: f64) {
    let nf = ctx.mesh.faces.len();
    let area = |fs: &[usize]| fs.iter().map(|&f| ctx.graph.area[f]).sum::<f64>();
    let total: f64 = done.iter().map(|l| area(&l.faces)).sum();
    let small = SMALL_SHARE * total;
    let mut owner = vec![usize::MAX; nf];
    for (k, l) in done.iter().enumerate() {
        for &f in &l.faces {
            owner[f] = k;
        }
    }
    let mut gone = vec![false; done.len()];
    let mut order: Vec<(f64, usize)> = done
        .iter()
        .enumerate()
        .map(|(k, l)| (area(&l.faces), k))
        .filter(|&(a, _)| a < small)
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    for (_, si) in order {
        if gone[si] || area(&done[si].faces) >= small {
            continue;
        }
        let mut shared: BTreeMap<usize, f64> = BTreeMap::new();
        for &f in &done[si].faces {
            for &(h, len) in &ctx.graph.adj[f] {
                let k = owner[h];
                if k != si && k != usize::MAX && !gone[k] {
                    *shared.entry(k).or_default() += len;
                }
            }
        }
        let mut cands: Vec<(f64, usize)> = shared.into_iter().map(|(k, l)| (l, k)).collect();
        cands.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        for &(_, k) in cands.iter().take(MERGE_TRIES) {
            if merge_into(ctx, done, k, si, opts, eps) {
                for &f in &done[si].faces {
                    owner[f] = k;
                }
                gone[si] = true;
                break;
            }
        }
    }
    let mut k = 0;
    done.retain(|_| {
        k += 1;
        !gone[k - 1]
    });
}
