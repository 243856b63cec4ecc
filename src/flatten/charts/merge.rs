//! Few pieces (issue 20, item 3; thesis §5.2.3 merges charts, §5.3 keeps pieces a person can
//! handle): after every chart is laid flat, a piece under [`SMALL_SHARE`] of the surface's
//! area is merged into a neighbour when the two laid flat as one stay within the material's
//! tolerance, without a flip or an overlap, their seams matched as every layout's are.
//!
//! Choices where the thesis is silent: small pieces are tried smallest first; the neighbours
//! in order of the boundary length they share with it (longest first, ties by index), at most
//! [`MERGE_TRIES`] of them; a neighbour grown by a merge may take the next small piece too.
//! The merged chart keeps the cuts of both (and more where it is not a disk).

use super::overlap::{merge_into, Owners};
use super::{Charts, FlattenOptions, Laid};

/// Pieces under this share of the surface's area are merged where they can be.
pub(crate) const SMALL_SHARE: f64 = 0.01;
/// Neighbours tried per small piece.
pub(crate) const MERGE_TRIES: usize = 3;

/// Merge the small pieces of `done` into neighbours (see the module doc).
pub(super) fn merge_small(ctx: &Charts, done: &mut Vec<Laid>, opts: &FlattenOptions, eps: f64) {
    let area = |fs: &[usize]| fs.iter().map(|&f| ctx.graph.area[f]).sum::<f64>();
    let total: f64 = done.iter().map(|l| area(&l.faces)).sum();
    let small = SMALL_SHARE * total;
    let mut owners = Owners::new(ctx.mesh.faces.len(), done);
    let mut order: Vec<(f64, usize)> = done
        .iter()
        .enumerate()
        .map(|(k, l)| (area(&l.faces), k))
        .filter(|&(a, _)| a < small)
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    for (_, si) in order {
        if owners.gone[si] || area(&done[si].faces) >= small {
            continue;
        }
        for k in owners
            .neighbours(ctx, done, si)
            .into_iter()
            .take(MERGE_TRIES)
        {
            if merge_into(ctx, done, k, si, opts, eps) {
                owners.absorb(done, k, si);
                break;
            }
        }
    }
    owners.drop_gone(done);
}
