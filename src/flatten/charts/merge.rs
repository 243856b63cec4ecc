//! Few pieces (issue 20, item 3; thesis §5.2.3 merges charts, §5.3 keeps pieces a person can
//! handle): after every chart is laid flat, a piece under [`SMALL_SHARE`] of the surface's
//! area is merged into a neighbour when the two laid flat as one stay within the material's
//! tolerance, without a flip or an overlap, their seams matched as every layout's are.
//!
//! Choices where the thesis is silent: small pieces are tried smallest first; the neighbours
//! in order of the boundary length they share with it (longest first, ties by index), at most
//! [`MERGE_TRIES`] of them; a neighbour grown by a merge may take the next small piece too;
//! then another round, while the last one merged any (a piece that failed early may fit a
//! neighbour a later merge has changed; a pair that failed is not tried again while neither
//! piece has changed: [`super::overlap::Failed`]). The merged chart keeps the cuts of both
//! (and more where it is not a disk). Where that fails but not for being over the tolerance,
//! the small piece is laid out anew with one of its [`SLIT_TRIES`] nearest with none of
//! their cuts but those the two as one need to be a disk ([`uncut_merge`]): a piece filling a
//! hole of its neighbour leaves useless the seam that opened the hole, which can make the two
//! as one overlap; a union over the tolerance with its cuts would only be more so without
//! them. A small piece that no neighbour takes is shared out
//! with one of its [`REBALANCE_TRIES`] nearest: the two are halved anew (along the bisector,
//! then into halves of equal area, which differ where the two are long and narrow or bent)
//! and kept as the halves when neither half is small and both keep the tolerance
//! (`rebalance`; the count of pieces stays);
//! else it is grafted onto its neighbours as they lie ([`graft`]). The neighbours are tried
//! two at a time where a spare thread is free, the first that takes it winning as in order
//! (`first_merge`); so is the next small piece beside it, its fate kept where this one's
//! changed none of its neighbours (`merge_small_once`). What is still small once every merge below is done is hinged onto a
//! neighbour by one edge ([`super::hinge`]), and what hinges in no way is last shared out with
//! a neighbour where the two overlap (`share_apart`): split between two faces that fold over
//! each other, moved across where a part would be small; one its neighbour closes round
//! takes a corridor of the neighbour's faces out to a third piece (`pass_through`). A piece
//! too long for the sheet that hinges in no parts is shared out with a neighbour across its
//! length (`share_across`).
//!
//! Then any two neighbouring pieces are joined where their layouts already fit together
//! (`attach`): a CAD part made of developable patches meeting at folds (fandisk, the
//! thesis' Table 5.1: 4 charts) comes out in few pieces. Both sides of a fold of a developable
//! are the same curve laid flat, so one layout is moved onto the other by the rigid motion
//! that best fits their common boundary (2D Kabsch, least squares); the join is kept when
//! no common vertex is further off than [`NEAR_SHARE`] of the material's stretch tolerance
//! times the common boundary's length, and, the common vertices put where the larger piece has
//! them, the two as one have no flip, no overlap and an L2 stretch within [`NEAR_SHARE`] of the
//! tolerance (paper 1.001, metal 1.00033, fabric 1.01; the rest of the tolerance is left to
//! the small pieces). Nothing is laid out again, so a failed join costs a pass over the two
//! pieces. Pieces are tried smallest first, with the same neighbours as above, in rounds until
//! none joins; a pair that failed is not tried again unless one of the two has grown since.
//!
//! Last, neighbouring pieces of any size are laid out again as one ([`merge_laid`]): across a
//! curved fold the two sides are the same curve in 3D but not in the plane, so no rigid motion
//! joins their layouts, yet the two as one may lie flat within the tolerance. A trial costs a
//! layout (started from the two joined), so pairs are chosen by what decides it cheaply: the
//! angle defects (discrete Gaussian curvature) of the vertices the merge makes interior, summed
//! with their signs (a crease folded without stretch has none; a saw-tooth seam's ± cancel),
//! least first, under [`LAID_DEFECT`]; only pairs whose two layouts as they lie, taken as one
//! (about the least the union can have), stretch within the limit; and the trials lay out at
//! most [`LAID_BUDGET`] times the surface's faces. A merge is kept as `attach`'s are (within
//! [`NEAR_SHARE`] of the tolerance) and, when the pieces are split to fit the sheet, only
//! when the merged piece fits it ([`super::FlattenOptions::room`]): a piece larger than the
//! sheet is cut up again by the split, along lines that follow no feature, into more parts
//! than the two pieces were.

use super::exact::graft;
use super::join::{fits_room, moved_onto};
use super::overlap::{
    both_cuts, first_merge, keeps, laid_as_one, overlaps, self_overlap, Failed, Owners, Trial,
};
use super::slit::{uncut_merge, SLIT_TRIES};
use super::{Charts, FlattenOptions, Laid, Layout, Whole};
use crate::flatten::distortion;
use crate::geom::cut::{
    bisect, bisect_area, components, corridors, farthest_apart, split_between, split_between_area,
};
use glam::DVec2;

/// Pieces under this share of the surface's area are merged where they can be.
pub(crate) const SMALL_SHARE: f64 = 0.01;
/// Neighbours tried per small piece.
pub(crate) const MERGE_TRIES: usize = 8;
/// Rounds of [`merge_small`] at most (the corpus needs three).
const MERGE_ROUNDS: usize = 10;
/// Share of the material's tolerance (of L2 − 1) that a merge of two pieces of any size may
/// use ([`merge_near`]).
pub(crate) const NEAR_SHARE: f64 = 1.0 / 3.0;

/// Merge the small pieces of `done` into neighbours (see the module doc), in rounds until
/// none merges (at most [`MERGE_ROUNDS`]).
pub(super) fn merge_small(
    ctx: &Charts,
    done: &mut Vec<Laid>,
    opts: &FlattenOptions,
    eps: f64,
    failed: &Failed,
) {
    for _ in 0..MERGE_ROUNDS {
        let before = done.len();
        merge_small_once(ctx, done, opts, eps, failed);
        if done.len() == before {
            break;
        }
    }
}

/// One round of [`merge_small`]: each small piece, smallest first, tried with its neighbours.
/// The next piece is tried beside it where a spare thread is free, on the pieces as they are
/// before this one's fate: that is kept when this one changed none of the pieces the next one
/// reads (itself and all its neighbours), and the next piece is tried again otherwise, so
/// the result is the one trying them in turn gives.
fn merge_small_once(
    ctx: &Charts,
    done: &mut Vec<Laid>,
    opts: &FlattenOptions,
    eps: f64,
    failed: &Failed,
) {
    let (small, order) = small_pieces(ctx, done);
    let mut owners = Owners::new(ctx.mesh.faces.len(), done);
    let mut i = 0;
    while let Some(&si) = order.get(i) {
        let next = order.get(i + 1).copied();
        let (here, beside) = crate::geom::par::speculate(
            || fate(ctx, done, &owners, si, small, opts, eps, failed),
            || {
                next.map(|sj| {
                    let mut reads = owners.neighbours(ctx, done, sj);
                    reads.push(sj);
                    (
                        fate(ctx, done, &owners, sj, small, opts, eps, failed),
                        reads,
                    )
                })
            },
        );
        let changed = here.apply(done, &mut owners, si);
        i += 1;
        if let (Some(sj), Some(Some((fate, reads)))) = (next, beside) {
            if !changed.iter().any(|c| reads.contains(c)) {
                fate.apply(done, &mut owners, sj);
                i += 1;
            }
        }
    }
    owners.drop_gone(done);
}

/// What becomes of a small piece in [`merge_small_once`].
enum Fate {
    /// Nothing: it is gone or no longer small, or no neighbour takes it.
    Stays,
    /// Laid out again as one with neighbour `k`.
    Merged(usize, Laid),
    /// Shared out with neighbour `k` (its new layout first).
    Shared(usize, (Laid, Laid)),
    /// Grafted onto the neighbours as they lie: each neighbour that takes faces, the faces it
    /// takes and what it becomes.
    Grafted(Vec<(usize, Vec<usize>, Laid)>),
}

/// The fate of the small piece `done[si]` (see [`merge_small`]): laid out again as one with
/// a neighbour, else shared out with one, else grafted onto the neighbours as they lie. The
/// neighbours are tried in turn, two at a time where a thread is idle ([`Failed::first`]).
#[allow(clippy::too_many_arguments)]
fn fate(
    ctx: &Charts,
    done: &[Laid],
    owners: &Owners,
    si: usize,
    small: f64,
    opts: &FlattenOptions,
    eps: f64,
    failed: &Failed,
) -> Fate {
    if owners.gone[si] || ctx.area(&done[si].faces) >= small {
        return Fate::Stays;
    }
    let near: Vec<usize> = owners.nearest(ctx, done, si, MERGE_TRIES);
    if let Some((k, union)) = first_merge(ctx, done, &near, si, opts, eps, failed) {
        return Fate::Merged(k, union);
    }
    // Without the cuts the two as one do not need, where the union with them was not over
    // the tolerance (see `Trial::Stretched`).
    let unstretched: Vec<usize> = near
        .iter()
        .take(SLIT_TRIES)
        .copied()
        .filter(|&k| !failed.known(Trial::Stretched, &done[k], &done[si]))
        .collect();
    if let Some((k, union)) = failed.first(Trial::Uncut, done, &unstretched, si, |k| {
        uncut_merge(ctx, done, k, si, opts, eps)
    }) {
        return Fate::Merged(k, union);
    }
    let share_with = &near[..near.len().min(REBALANCE_TRIES)];
    if let Some((k, halves)) = failed.first(Trial::Share, done, share_with, si, |k| {
        rebalance(ctx, done, k, si, small, opts, eps)
    }) {
        return Fate::Shared(k, halves);
    }
    match graft(ctx, done, &near, si, opts.tolerance, eps) {
        Some(took) => Fate::Grafted(took),
        None => Fate::Stays,
    }
}

impl Fate {
    /// Make it so for `done[si]`; the pieces it changed.
    fn apply(self, done: &mut [Laid], owners: &mut Owners, si: usize) -> Vec<usize> {
        match self {
            Fate::Stays => Vec::new(),
            Fate::Merged(k, union) => {
                done[k] = union;
                owners.absorb(done, k, si);
                vec![k, si]
            }
            Fate::Shared(k, halves) => {
                owners.shared(done, (k, si), halves);
                vec![k, si]
            }
            Fate::Grafted(took) => {
                let mut changed = vec![si];
                for (k, faces, laid) in took {
                    done[k] = laid;
                    for f in faces {
                        owners.owner[f] = k;
                    }
                    changed.push(k);
                }
                owners.gone[si] = true;
                changed
            }
        }
    }
}

/// The area under which a piece of `done` is small ([`SMALL_SHARE`] of the whole), and the
/// small pieces, smallest first (ties: lower index).
pub(super) fn small_pieces(ctx: &Charts, done: &[Laid]) -> (f64, Vec<usize>) {
    let total: f64 = done.iter().map(|l| ctx.area(&l.faces)).sum();
    let small = SMALL_SHARE * total;
    let mut order: Vec<(f64, usize)> = done
        .iter()
        .enumerate()
        .map(|(k, l)| (ctx.area(&l.faces), k))
        .filter(|&(a, _)| a < small)
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    (small, order.into_iter().map(|(_, k)| k).collect())
}

/// Neighbours a small piece is shared out with at most ([`rebalance`]).
const REBALANCE_TRIES: usize = 2;

/// Share the faces of a small piece `done[part]` and its neighbour `done[k]` out anew: the
/// two as one chart are halved along the bisector of their two faces farthest apart
/// ([`bisect`]), then, where a half would be under `small` or the halves are not kept,
/// across them into halves of equal area ([`bisect_area`]), and each half laid out,
/// starting from the two layouts joined ([`moved_onto`]), the second beside the first where
/// a spare thread is free. The halves (to become `done[k]` and `done[part]`) when neither is
/// under `small` in area and each is flip-free, without overlap, within the tolerance and
/// with its seams matched; else `None`.
fn rebalance(
    ctx: &Charts,
    done: &[Laid],
    k: usize,
    part: usize,
    small: f64,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<(Laid, Laid)> {
    let mut faces = done[k].faces.clone();
    faces.extend(&done[part].faces);
    let is_small = |(a, b): &(Vec<usize>, Vec<usize>)| ctx.area(a) < small || ctx.area(b) < small;
    // Along the bisector, then into halves of equal area where those are other halves.
    let along = bisect(ctx.graph, &faces);
    let equal = bisect_area(ctx.graph, &faces).filter(|h| *h != along);
    let halves: Vec<_> = [Some(along), equal]
        .into_iter()
        .flatten()
        .filter(|h| !is_small(h))
        .collect();
    if halves.is_empty() {
        return None;
    }
    let joined = moved_onto(ctx, done, k, part).map(|j| Whole::new(&j.faces, &j.uv));
    let cuts = both_cuts(&done[k], &done[part]);
    halves
        .into_iter()
        .find_map(|(a, b)| lay_halves(ctx, joined.as_deref(), &cuts, a, b, opts, eps))
}

/// The halves `a` and `b` of two pieces (their cuts `cuts`) each laid out, starting from the
/// two layouts `joined` where there are, the second beside the first where a spare thread is
/// free; both, when each is flip-free, without overlap, within the tolerance and with its
/// seams matched ([`keeps`]).
fn lay_halves(
    ctx: &Charts,
    joined: Option<&Whole>,
    cuts: &[usize],
    a: Vec<usize>,
    b: Vec<usize>,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<(Laid, Laid)> {
    let lay = |half: Vec<usize>| -> Option<Laid> {
        let hc = ctx.disk(&half, &ctx.cuts_within(&half, cuts))?;
        let Ok(Layout::Laid(uv, s)) = ctx.lay_from(&half, &hc, joined) else {
            return None;
        };
        let laid = Laid {
            faces: half,
            cuts: hc,
            uv,
            stretch: s,
            gusset: false,
        };
        keeps(ctx, &laid, opts, eps).then_some(laid)
    };
    let (ha, hb) = crate::geom::par::speculate(|| lay(a), || lay(b.clone()));
    Some((ha?, hb.unwrap_or_else(|| lay(b))?))
}

/// Partitions [`share_apart`] lays out at most per layout of the two pieces.
const APART_TRIES: usize = 3;
/// Overlapping pairs of faces [`share_apart`] splits between at most per layout.
const APART_PAIRS: usize = 16;

/// Share a small piece `done[part]` and its neighbour `done[k]` out anew where the two
/// overlap when joined: as they lie ([`moved_onto`]), then laid out as one
/// ([`laid_as_one`]). The two as one are split between two faces that overlap, each face
/// going with the nearer, moved across so that each part has at least `small` area
/// ([`split_between_area`]): what folds over the other goes to the other part, as a chart
/// that overlaps itself is split. The parts (to become `done[k]` and `done[part]`) are laid
/// out from that layout and kept as [`rebalance`] keeps its halves, and when each fits the
/// sheet; at most [`APART_TRIES`] partitions of the first [`APART_PAIRS`] overlapping pairs
/// of each layout are laid out.
pub(super) fn share_apart(
    ctx: &Charts,
    done: &[Laid],
    k: usize,
    part: usize,
    small: f64,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<(Laid, Laid)> {
    Shares::new(ctx, done, k, part, small, opts, eps)?.apart(done, k, part, &mut Some)
}

/// The share-outs of `pair[1]` (a small piece) and `pair[0]` (its neighbour) where the two
/// overlap, as [`share_apart`] finds them, but split between the two faces as they are
/// nearer ([`split_between`]) where a part is under `small` (or both are): each laid out and
/// kept as [`share_apart`]'s, larger part first, given to `take` in turn; the first that
/// `take` makes something of. What folds over the small piece (a narrow arm of the
/// neighbour) goes with one part, the rest with the other: a small part may fit beside a
/// third piece where the small piece fitted beside none ([`super::hinge`]'s `pass_on`).
pub(super) fn pass_apart<T>(
    ctx: &Charts,
    pair: &[Laid],
    small: f64,
    opts: &FlattenOptions,
    eps: f64,
    take: &mut impl FnMut((Laid, Laid)) -> Option<T>,
) -> Option<T> {
    let shares = Shares {
        ctx,
        cuts: both_cuts(&pair[0], &pair[1]),
        small,
        lopsided: true,
        opts,
        eps,
    };
    shares.apart(pair, 0, 1, take)
}

/// Corridors of each kind a small piece is passed through its neighbour by at most
/// ([`corridors_out`]).
const THROUGH_TRIES: usize = 4;

/// The corridors [`pass_through`] tries for the small piece `pair[1]` through its neighbour
/// `pair[0]`, to the pieces `third` names (a face's piece, `None` for the two's): first those
/// ending on a face that shares no vertex with the small piece, then any, each kind one per
/// third piece, nearest first, at most [`THROUGH_TRIES`] ([`corridors`]). A corridor ending
/// beside the small piece reaches the third piece round the vertex where the small piece and
/// its neighbour turned past a full turn, and the corridor with the small piece may turn past
/// one with the third piece there too.
pub(super) fn corridors_out(
    ctx: &Charts,
    pair: &[Laid],
    third: &dyn Fn(usize) -> Option<usize>,
) -> Vec<Vec<usize>> {
    let mut touched: Vec<usize> = pair[1]
        .faces
        .iter()
        .flat_map(|&f| ctx.mesh.faces[f].verts.iter().copied())
        .collect();
    touched.sort_unstable();
    touched.dedup();
    let apart = |f: usize| {
        let verts = &ctx.mesh.faces[f].verts;
        verts.iter().all(|v| touched.binary_search(v).is_err())
    };
    let (n, s) = (&pair[0].faces, &pair[1].faces);
    let mut out = corridors(ctx.graph, n, s, third, &apart, THROUGH_TRIES);
    for path in corridors(ctx.graph, n, s, third, &|_| true, THROUGH_TRIES) {
        if !out.contains(&path) {
            out.push(path);
        }
    }
    out
}

/// The share-outs of `pair[1]` (a small piece) and `pair[0]` (its neighbour) along
/// `corridors` (each a path of the neighbour's faces from the small piece to a third piece,
/// [`crate::geom::cut::corridors`]): the small piece takes the corridor's faces, the
/// neighbour keeps the rest. A small piece its neighbour closes round (a gusset at a saddle,
/// where the two as one turn past a full turn round a vertex) fits beside the neighbour in no
/// way; with a corridor it reaches a third piece, which it may fit beside. Each laid out from the two joined as they
/// lie ([`moved_onto`]) and kept as [`pass_apart`]'s parts are, the neighbour's part first,
/// given to `take` in turn; the first that `take` makes something of.
pub(super) fn pass_through<T>(
    ctx: &Charts,
    pair: &[Laid],
    corridors: &[Vec<usize>],
    opts: &FlattenOptions,
    eps: f64,
    take: &mut impl FnMut((Laid, Laid)) -> Option<T>,
) -> Option<T> {
    let joined = moved_onto(ctx, pair, 0, 1).map(|j| Whole::new(&j.faces, &j.uv));
    let cuts = both_cuts(&pair[0], &pair[1]);
    corridors.iter().find_map(|path| {
        let mut taken = path.clone();
        taken.sort_unstable();
        let rest: Vec<usize> = pair[0]
            .faces
            .iter()
            .copied()
            .filter(|f| taken.binary_search(f).is_err())
            .collect();
        // Where the corridor cuts the neighbour through, the small piece takes the parts
        // cut off too: the neighbour keeps its largest part (ties: the first).
        let mut parts = components(ctx.graph, &rest);
        let largest = (0..parts.len()).max_by(|&x, &y| {
            ctx.area(&parts[x])
                .total_cmp(&ctx.area(&parts[y]))
                .then(y.cmp(&x))
        })?;
        let a = parts.swap_remove(largest);
        let mut b = pair[1].faces.clone();
        b.extend(path);
        b.extend(parts.into_iter().flatten());
        lay_halves(ctx, joined.as_deref(), &cuts, a, b, opts, eps)
            .filter(|(ha, hb)| fits_room(opts.room, &ha.uv) && fits_room(opts.room, &hb.uv))
            .and_then(&mut *take)
    })
}

/// Share a piece `done[part]` too long for the sheet (and under twice `small` in area) and
/// its neighbour `done[k]` out anew across the piece: the two, joined as they lie
/// ([`moved_onto`]), are split between the piece's two faces farthest apart (moved across
/// where a part would be under `small`: [`split_between_area`]), so that each part takes
/// one end of the piece and some of the neighbour. Kept as [`share_apart`] keeps its parts
/// (each fitting the sheet): where the pattern stage would split the piece into two small
/// parts, there are two pieces of at least `small`.
pub(super) fn share_across(
    ctx: &Charts,
    done: &[Laid],
    k: usize,
    part: usize,
    small: f64,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<(Laid, Laid)> {
    let shares = Shares::new(ctx, done, k, part, small, opts, eps)?;
    let ends = farthest_apart(ctx.graph, &done[part].faces)?;
    let j = moved_onto(ctx, done, k, part)?;
    shares.between(&j.faces, &j.uv, &[ends], &mut Vec::new(), &mut Some)
}

/// What a share-out of two pieces laid as one needs besides the layout: the two pieces'
/// cuts, the small area, how the parts are split, the options.
struct Shares<'a> {
    ctx: &'a Charts<'a>,
    cuts: Vec<usize>,
    small: f64,
    /// A part under `small`, or both ([`pass_apart`]); else both at least that.
    lopsided: bool,
    opts: &'a FlattenOptions,
    eps: f64,
}

impl<'a> Shares<'a> {
    /// The share-out of `done[part]` and `done[k]`; `None` when the two have less than twice
    /// `small` in area (no split leaves both parts that).
    fn new(
        ctx: &'a Charts<'a>,
        done: &[Laid],
        k: usize,
        part: usize,
        small: f64,
        opts: &'a FlattenOptions,
        eps: f64,
    ) -> Option<Self> {
        (ctx.area(&done[k].faces) + ctx.area(&done[part].faces) >= 2.0 * small).then(|| Shares {
            ctx,
            cuts: both_cuts(&done[k], &done[part]),
            small,
            lopsided: false,
            opts,
            eps,
        })
    }

    /// The share-outs of `done[part]` and `done[k]` where the two overlap (see
    /// [`share_apart`]), each given to `take` in turn; the first `take` makes something of.
    fn apart<T>(
        &self,
        done: &[Laid],
        k: usize,
        part: usize,
        take: &mut impl FnMut((Laid, Laid)) -> Option<T>,
    ) -> Option<T> {
        let ctx = self.ctx;
        let mut tried: Vec<Vec<usize>> = Vec::new();
        // As they lie; where no split of that is kept, laid out as one.
        let layouts = [false, true].into_iter().filter_map(|relaxed| {
            if relaxed {
                laid_as_one(ctx, done, k, part).map(|l| (l.faces, l.uv))
            } else {
                moved_onto(ctx, done, k, part).map(|j| (j.faces, j.uv))
            }
        });
        for (faces, uv) in layouts {
            let pairs: Vec<(usize, usize)> = overlaps(&uv, self.eps, APART_PAIRS)
                .into_iter()
                .map(|(x, y)| (faces[x], faces[y]))
                .collect();
            let taken = self.between(&faces, &uv, &pairs, &mut tried, take);
            if taken.is_some() {
                return taken;
            }
        }
        None
    }

    /// `faces` split between `x` and `y`: moved across so that both parts have `small`
    /// ([`split_between_area`]); or, `lopsided`, as they are nearer ([`split_between`]) when
    /// a part is under `small` (or both are), the larger first.
    fn split(&self, faces: &[usize], x: usize, y: usize) -> Option<(Vec<usize>, Vec<usize>)> {
        let g = self.ctx.graph;
        if !self.lopsided {
            return split_between_area(g, faces, x, y, self.small);
        }
        let (a, b) = split_between(g, faces, x, y);
        let (sa, sb) = (self.ctx.area(&a), self.ctx.area(&b));
        if a.is_empty() || b.is_empty() || sa.min(sb) >= self.small {
            None
        } else if sa >= sb {
            Some((a, b))
        } else {
            Some((b, a))
        }
    }

    /// The partitions of `faces` (laid out as `uv`) between a pair of faces of `pairs`
    /// ([`Shares::split`]) not in `tried` whose parts are laid out from `uv` and kept (see
    /// [`share_apart`]), each given to `take` in turn; the first `take` makes something of.
    /// At most [`APART_TRIES`] are laid out, each noted in `tried`.
    fn between<T>(
        &self,
        faces: &[usize],
        uv: &[Vec<DVec2>],
        pairs: &[(usize, usize)],
        tried: &mut Vec<Vec<usize>>,
        take: &mut impl FnMut((Laid, Laid)) -> Option<T>,
    ) -> Option<T> {
        let (ctx, opts) = (self.ctx, self.opts);
        let whole = Whole::new(faces, uv);
        let mut laid = 0;
        for &(x, y) in pairs {
            if laid == APART_TRIES {
                break;
            }
            let Some((a, b)) = self.split(faces, x, y) else {
                continue;
            };
            let mut key = a.clone();
            key.sort_unstable();
            if tried.contains(&key) {
                continue;
            }
            tried.push(key);
            laid += 1;
            let taken = lay_halves(ctx, Some(&whole), &self.cuts, a, b, opts, self.eps)
                .filter(|(ha, hb)| fits_room(opts.room, &ha.uv) && fits_room(opts.room, &hb.uv))
                .and_then(&mut *take);
            if taken.is_some() {
                return taken;
            }
        }
        None
    }
}

/// Join neighbouring pieces of any size whose layouts fit together (see the module doc).
pub(super) fn merge_near(ctx: &Charts, done: &mut Vec<Laid>, opts: &FlattenOptions, eps: f64) {
    let near = 1.0 + (opts.tolerance - 1.0) * NEAR_SHARE;
    let mut owners = Owners::new(ctx.mesh.faces.len(), done);
    // Pairs that failed, with both pieces' face counts at the time.
    let mut failed = std::collections::HashSet::new();
    loop {
        let mut order: Vec<(f64, usize)> = (0..done.len())
            .filter(|&k| !owners.gone[k])
            .map(|k| (ctx.area(&done[k].faces), k))
            .collect();
        order.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut merged = false;
        for (_, si) in order {
            if owners.gone[si] {
                continue;
            }
            for k in owners
                .neighbours(ctx, done, si)
                .into_iter()
                .take(MERGE_TRIES)
            {
                let key = (k, done[k].faces.len(), si, done[si].faces.len());
                if failed.contains(&key) {
                    continue;
                }
                if attach(ctx, done, k, si, near, eps) {
                    owners.absorb(done, k, si);
                    merged = true;
                    break;
                }
                failed.insert(key);
            }
        }
        if !merged {
            break;
        }
    }
    owners.drop_gone(done);
}

/// Join `done[part]` to `done[k]` by moving its layout onto `done[k]`'s along their common
/// boundary (see the module doc); false, leaving both as they were, when it does not fit.
fn attach(ctx: &Charts, done: &mut [Laid], k: usize, part: usize, near: f64, eps: f64) -> bool {
    let Some(j) = moved_onto(ctx, done, k, part) else {
        return false;
    };
    // One path or one loop of common edges.
    if !(j.verts == j.edges || j.verts == j.edges + 1) || j.worst > (near - 1.0) * j.length {
        return false;
    }
    let s = distortion::stretch(ctx.mesh, &j.faces, &j.uv);
    if s.flipped > 0 || s.l2 > near || self_overlap(&j.uv, eps).is_some() {
        return false;
    }
    done[k] = Laid {
        faces: j.faces,
        cuts: both_cuts(&done[k], &done[part]),
        uv: j.uv,
        stretch: s,
        gusset: false,
    };
    true
}

/// Pairs [`merge_laid`] tries only when the angle defects of the vertices their merge makes
/// interior sum to less than this (radians, either sign): a bound on the trials; whether a
/// pair lies flat as one is the layout's to say.
const LAID_DEFECT: f64 = 1.0;
/// Faces [`merge_laid`]'s trials lay out in all, at most, as a multiple of the surface's.
const LAID_BUDGET: usize = 1;

/// Join neighbouring pieces of any size laid out again as one (see the module doc): pairs
/// whose merge makes interior vertices of little angle defect in all, least first, each
/// union started from the two layouts joined ([`laid_as_one`]) and kept when flip-free,
/// without overlap, within [`NEAR_SHARE`] of the tolerance and with its seams matched.
pub(super) fn merge_laid(ctx: &Charts, done: &mut Vec<Laid>, opts: &FlattenOptions, eps: f64) {
    let near = 1.0 + (opts.tolerance - 1.0) * NEAR_SHARE;
    let defect = distortion::angle_defect(ctx.mesh);
    let mut around = vec![0usize; ctx.mesh.vertices.len()];
    for face in &ctx.mesh.faces {
        for &v in &face.verts {
            around[v] += 1;
        }
    }
    let mut budget = LAID_BUDGET * ctx.mesh.faces.len();
    let mut owners = Owners::new(ctx.mesh.faces.len(), done);
    let mut failed = std::collections::HashSet::new();
    'rounds: loop {
        let mut pairs = Vec::new();
        for si in (0..done.len()).filter(|&k| !owners.gone[k]) {
            for k in owners.neighbours(ctx, done, si) {
                // Each pair once, the larger piece keeping its place.
                if (done[k].faces.len(), si) > (done[si].faces.len(), k)
                    && joined_l2(&done[k], &done[si]) <= near
                {
                    let d = merged_defect(ctx, &defect, &around, &done[k], &done[si]);
                    if d.abs() < LAID_DEFECT {
                        pairs.push((d.abs(), k, si));
                    }
                }
            }
        }
        pairs.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        for (_, k, si) in pairs {
            let key = (k, done[k].faces.len(), si, done[si].faces.len());
            let size = done[k].faces.len() + done[si].faces.len();
            if failed.contains(&key) || size > budget {
                continue;
            }
            budget -= size;
            let kept = laid_as_one(ctx, done, k, si).filter(|l| {
                l.stretch.flipped == 0
                    && l.stretch.l2 <= near
                    && ctx.seam_error(l) <= opts.seam_tolerance
                    && fits_room(opts.room, &l.uv)
                    && self_overlap(&l.uv, eps).is_none()
            });
            if let Some(l) = kept {
                done[k] = l;
                owners.absorb(done, k, si);
                continue 'rounds;
            }
            failed.insert(key);
        }
        break;
    }
    owners.drop_gone(done);
}

/// The L2 stretch of `a` and `b` as they lie, as one: about the least their union laid out
/// again has (its layout restricted to either is a layout of it, and each was laid out to
/// stretch least), seam matching and the minimisation's own shortfall aside.
fn joined_l2(a: &Laid, b: &Laid) -> f64 {
    let (sa, sb) = (&a.stretch, &b.stretch);
    let area = sa.area_3d + sb.area_3d;
    if area <= 0.0 {
        return f64::INFINITY;
    }
    ((sa.area_3d * sa.l2 * sa.l2 + sb.area_3d * sb.l2 * sb.l2) / area).sqrt()
}

/// The sum of the angle defects (`defect`, per vertex) of the vertices that `a` and `b` share
/// and that have all their faces (`around`, per vertex) in the two.
fn merged_defect(ctx: &Charts, defect: &[f64], around: &[usize], a: &Laid, b: &Laid) -> f64 {
    let mut count: std::collections::HashMap<usize, [usize; 2]> = Default::default();
    for (side, l) in [a, b].into_iter().enumerate() {
        for &f in &l.faces {
            for &v in &ctx.mesh.faces[f].verts {
                count.entry(v).or_default()[side] += 1;
            }
        }
    }
    let mut common: Vec<usize> = count
        .into_iter()
        .filter(|&(v, [x, y])| x > 0 && y > 0 && x + y == around[v])
        .map(|(v, _)| v)
        .collect();
    // Summed in one order, for the same figure on every run.
    common.sort_unstable();
    common.iter().map(|&v| defect[v]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::charts::{strip_and_squares, zigzag_cone, Fixture};

    /// A round of small-piece merges, the next piece tried beside each where a thread is
    /// free, ends as trying them in turn does: two squares of 80 cells and single cells
    /// round them, each under 1 % of the area: two cells of the 1.5 mm strip under each
    /// square, and a cell beside the first square with one beside it that touches nothing
    /// else (decided before the first merges, it would merge into the first, which is gone by
    /// then). Every piece's faces and layout are the same, bit for bit; and the small cells
    /// are gone.
    #[test]
    fn small_pieces_tried_side_by_side_merge_as_tried_in_turn() {
        let (mesh, ranges) = strip_and_squares(&[
            (0..8, 1..11),
            (12..20, 1..11),
            (8..9, 1..2),
            (9..10, 1..2),
            (11..12, 5..6),
            (2..3, 0..1),
            (5..6, 0..1),
            (15..16, 0..1),
            (17..18, 0..1),
        ]);
        let fx = Fixture::new(mesh);
        let opts = FlattenOptions::default();
        let ctx = fx.charts(&opts);
        let eps = 1e-6;
        let start: Vec<Laid> = ranges
            .iter()
            .map(|r| ctx.piece(r.clone().collect()))
            .collect();
        let (small, order) = small_pieces(&ctx, &start);
        // The strip's cells first, two by two; then the two cells one beside the other.
        assert_eq!(order, [5, 6, 7, 8, 2, 3, 4], "small {small}");
        let mut side_by_side = start.clone();
        merge_small_once(&ctx, &mut side_by_side, &opts, eps, &Failed::default());
        let mut in_turn = start.clone();
        let failed = Failed::default();
        let mut owners = Owners::new(ctx.mesh.faces.len(), &in_turn);
        for si in order {
            fate(&ctx, &in_turn, &owners, si, small, &opts, eps, &failed).apply(
                &mut in_turn,
                &mut owners,
                si,
            );
        }
        owners.drop_gone(&mut in_turn);
        assert_eq!(side_by_side.len(), in_turn.len());
        assert!(
            side_by_side.len() < start.len(),
            "{} pieces",
            side_by_side.len()
        );
        for (a, b) in side_by_side.iter().zip(&in_turn) {
            assert_eq!(a.faces, b.faces);
            assert_eq!(a.cuts, b.cuts);
            assert_eq!(a.uv, b.uv);
        }
    }

    /// Two halves of a fan of six triangles round an apex: flat, they merge; with the apex
    /// raised (305° round it) the two as one are over the tolerance, and that is noted
    /// (`Trial::Stretched`), so that they are not laid out again with fewer cuts
    /// (`uncut_merge`: less room, not more).
    #[test]
    fn a_merge_over_the_tolerance_is_noted_as_such() {
        use crate::geom::mesh::{Face, Mesh};
        use glam::DVec3;
        let fan = |h: f64| {
            let mut vertices = vec![DVec3::new(0.0, 0.0, h)];
            for i in 0..6 {
                let a = std::f64::consts::TAU * i as f64 / 6.0;
                vertices.push(DVec3::new(10.0 * a.cos(), 10.0 * a.sin(), 0.0));
            }
            let faces = (0..6)
                .map(|i| Face {
                    verts: vec![0, 1 + i, 1 + (i + 1) % 6],
                    line: None,
                })
                .collect();
            Mesh { vertices, faces }
        };
        for (h, over) in [(0.0, false), (6.0, true)] {
            let fx = Fixture::new(fan(h));
            let opts = FlattenOptions::default();
            let ctx = fx.charts(&opts);
            let done = vec![ctx.piece((0..3).collect()), ctx.piece((3..6).collect())];
            let failed = Failed::default();
            let got = first_merge(&ctx, &done, &[0], 1, &opts, 1e-6, &failed);
            assert_eq!(got.is_none(), over, "apex at {h} mm");
            assert_eq!(
                failed.known(Trial::Stretched, &done[0], &done[1]),
                over,
                "apex at {h} mm"
            );
        }
    }

    /// One sector of the zigzag cone beside the next four turns 400° round the apex: joined
    /// as they lie, or laid out as one, it folds over the fourth. Shared out where they
    /// overlap, the five sectors become two parts that each turn less than a full turn and
    /// have the least area asked for; where the five have less than twice that, there is no
    /// such split.
    #[test]
    fn a_small_piece_folding_over_its_neighbour_is_shared_out_where_they_overlap() {
        let opts = FlattenOptions::default();
        let fx = Fixture::new(zigzag_cone());
        let ctx = fx.charts(&opts);
        let eps = 1e-6;
        let done = vec![ctx.piece((3..15).collect()), ctx.piece((0..3).collect())];
        assert!(done.iter().all(|l| keeps(&ctx, l, &opts, eps)));
        let sector = ctx.area(&done[1].faces);
        let j = moved_onto(&ctx, &done, 0, 1).expect("joined");
        assert!(self_overlap(&j.uv, eps).is_some());
        assert!(laid_as_one(&ctx, &done, 0, 1).is_none_or(|l| !keeps(&ctx, &l, &opts, eps)));
        let small = 1.5 * sector;
        let (ha, hb) = share_apart(&ctx, &done, 0, 1, small, &opts, eps).expect("shared out");
        for h in [&ha, &hb] {
            assert!(
                ctx.area(&h.faces) >= small,
                "{}",
                ctx.area(&h.faces) / sector
            );
            assert!(keeps(&ctx, h, &opts, eps));
            assert!((h.stretch.l2 - 1.0).abs() < 1e-6, "{}", h.stretch.l2);
        }
        let mut all = [ha.faces, hb.faces].concat();
        all.sort_unstable();
        assert_eq!(all, (0..15).collect::<Vec<_>>());
        assert!(share_apart(&ctx, &done, 0, 1, 2.6 * sector, &opts, eps).is_none());
    }

    /// A square of 100 mm and a strip 200 mm long and 1.5 mm wide along its bottom, from its
    /// left side on past its right (so the strip is too long for a room of 150 mm, and only
    /// its left half touches the square): shared out across the strip, each part has one end
    /// of the strip, the right one with a corner of the square, both at least the least area
    /// asked for and fitting the room. Where the two have less than twice that, there is no
    /// such split.
    #[test]
    fn a_strip_too_long_for_the_sheet_is_shared_out_across_with_its_neighbour() {
        // The square's cells, then the strip's.
        let (mesh, _) = strip_and_squares(&[(0..10, 1..11), (0..20, 0..1)]);
        let opts = FlattenOptions {
            room: Some([150.0, 150.0]),
            ..FlattenOptions::default()
        };
        let fx = Fixture::new(mesh);
        let ctx = fx.charts(&opts);
        let eps = 1e-6;
        let done = vec![
            ctx.piece((0..200).collect()),
            ctx.piece((200..240).collect()),
        ];
        assert!(!fits_room(opts.room, &done[1].uv) && fits_room(opts.room, &done[0].uv));
        let least = 2000.0;
        let (ha, hb) = share_across(&ctx, &done, 0, 1, least, &opts, eps).expect("shared");
        for h in [&ha, &hb] {
            assert!(ctx.area(&h.faces) >= least, "{}", ctx.area(&h.faces));
            assert!(fits_room(opts.room, &h.uv));
            assert!(keeps(&ctx, h, &opts, eps));
            assert!((h.stretch.l2 - 1.0).abs() < 1e-9, "{}", h.stretch.l2);
        }
        // The strip's end cells: one in each part.
        let (left, right) = (200, 238);
        assert!(ha.faces.contains(&left) != hb.faces.contains(&left));
        assert!(ha.faces.contains(&left) != ha.faces.contains(&right));
        let mut all = [ha.faces, hb.faces].concat();
        all.sort_unstable();
        assert_eq!(all, (0..240).collect::<Vec<_>>());
        assert!(share_across(&ctx, &done, 0, 1, 5500.0, &opts, eps).is_none());
    }

    /// A one-cell piece in a hole of its neighbour (a 5 × 5 block of cells, the piece at
    /// column 2, row 3), a third piece beside the neighbour (columns 5–7): the corridors run
    /// from the hole to the third piece, the first ending away from the small piece's
    /// vertices; passed through the first, the small piece takes the corridor, the neighbour
    /// keeps the rest, both laid out and kept.
    #[test]
    fn a_small_piece_in_a_hole_of_its_neighbour_is_passed_through_it_to_a_third_piece() {
        let opts = FlattenOptions::default();
        let (mesh, blocks) = strip_and_squares(&[(0..5, 1..6), (5..8, 1..6)]);
        let fx = Fixture::new(mesh);
        let ctx = fx.charts(&opts);
        let eps = 1e-6;
        let cell = |i: usize, j: usize| 2 * ((j - 1) * 5 + i);
        let hole = [cell(2, 3), cell(2, 3) + 1];
        let around: Vec<usize> = blocks[0].clone().filter(|f| !hole.contains(f)).collect();
        let cuts = ctx.disk(&around, &[]).expect("cut to a disk");
        assert!(!cuts.is_empty(), "an annulus needs a cut");
        let Ok(Layout::Laid(uv, stretch)) = ctx.lay(&around, &cuts) else {
            panic!("neighbour not laid out");
        };
        let neighbour = Laid {
            faces: around.clone(),
            cuts,
            uv,
            stretch,
            gusset: false,
        };
        let pair = [neighbour, ctx.piece(hole.to_vec())];
        let third_faces = blocks[1].clone();
        let third = |f: usize| third_faces.contains(&f).then_some(2);
        let paths = corridors_out(&ctx, &pair, &third);
        assert!(!paths.is_empty());
        let verts = |f: usize| fx.mesh.faces[f].verts.clone();
        let touches_hole = |f: usize| {
            verts(f)
                .iter()
                .any(|v| hole.iter().any(|&h| verts(h).contains(v)))
        };
        assert!(!touches_hole(paths[0][0]), "{:?}", paths[0]);
        assert!(fx.graph.adj[paths[0][0]]
            .iter()
            .any(|&(h, _)| third(h).is_some()));
        let (a, b) = pass_through(&ctx, &pair, &paths, &opts, eps, &mut Some).expect("passed");
        assert!(hole.iter().all(|f| b.faces.contains(f)));
        assert!(paths[0].iter().all(|f| b.faces.contains(f)));
        let mut all = [a.faces.clone(), b.faces.clone()].concat();
        all.sort_unstable();
        assert_eq!(all, blocks[0].clone().collect::<Vec<_>>());
        for part in [&a, &b] {
            assert!(keeps(&ctx, part, &opts, eps));
            assert!((part.stretch.l2 - 1.0).abs() < 1e-9, "{}", part.stretch.l2);
        }
        // Nothing to pass through where no corridor reaches a third piece.
        assert!(corridors_out(&ctx, &pair, &|_| None).is_empty());
        assert!(pass_through(&ctx, &pair, &[], &opts, eps, &mut Some).is_none());
    }
}
