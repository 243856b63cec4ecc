//! Improvement of a constructed layout by overlap minimisation, after sparrow (Gardeyn,
//! Vanden Berghe, Wauters, "An open-source heuristic to reboot 2D nesting research", EJOR
//! 2025): shrink the container, then let the separator ([`super::separate`]) resolve the
//! overlaps; keep what ends feasible.
//!
//! **Strip** ([`optimise_strip`]): exploration (90 % of the budget, as in sparrow), then
//! compression. Exploration shrinks the best feasible strip by 0.1 % by cutting a slice out at
//! a random x and moving the items right of it left, then separates (3 strikes of 25 sweeps);
//! success becomes the new best. A failure goes into a pool of infeasible layouts of that
//! length, ordered by overlap; the next try is drawn from the pool (index `|N(0, 0.25)|` × pool
//! size, so the least overlapping most often) and disrupted: two large items of different
//! shapes swap places, and items lying under a swapped item's new place move into the room it
//! left (sparrow). Compression shrinks the best by a ratio that falls linearly from 0.05 % to
//! 0.001 % over the phase, at a random x, and separates more patiently (5 strikes of 100
//! sweeps, sparrow's compression). Only feasible layouts are kept, so stopping at any time
//! returns a valid layout.
//!
//! **Bins** ([`optimise_bins`]): the items of the last bin are moved one by one into earlier
//! bins (bottom-left if there is room, else inserted and separated); a bin that empties is
//! dropped. Then the last bin is compressed as a strip of its height whose length is at most
//! the bin's, so that what is left of it is one rectangle at its right end.
//!
//! Choices where sparrow is silent or differs: the pool keeps at most 64 layouts; "large"
//! items are those with at least the median area (sparrow: a convex-hull-area percentile); the
//! exploration cuts at a random x (sparrow cuts at the middle of the strip).

use super::separate::{clamp_pos, separate};
use super::state::{Ctx, State};
use crate::nest::collision::{in_material, Placed};
use crate::nest::problem::Container;
use glam::DVec2;

/// Infeasible layouts kept during exploration.
const POOL: usize = 64;
/// Share of the strip budget spent exploring (the rest compresses), as in sparrow.
const EXPLORE_SHARE: f64 = 0.9;
/// Exploration shrinks the strip by this ratio after each success (sparrow's 0.1 %).
const EXPLORE_STEP: f64 = 0.001;
/// The compression separator's strikes and patience (sparrow's).
const COMPRESS_STRIKES: usize = 5;
const COMPRESS_PATIENCE: usize = 100;

/// Cut a slice `delta` wide out at a random x of a layout `len` long: items right of the cut
/// move left; every item is kept inside the new length. None if an item cannot fit.
pub(crate) fn shrink(ctx: &mut Ctx, st: &State, len: f64, new_len: f64) -> Option<State> {
    let delta = len - new_len;
    let cut = ctx.rng.range(0.0, new_len);
    let mut out = st.clone();
    let height = ctx.prob.container.height();
    for p in out.placed.iter_mut() {
        if p.shape.size.x > new_len + 1e-12 {
            return None;
        }
        if p.pos.x + 0.5 * p.shape.size.x > cut {
            p.pos.x -= delta;
        }
        p.pos = clamp_pos(p.pos, p.shape.size, new_len, height);
    }
    Some(out)
}

/// Shortest feasible layout found within the budget; `st` must be feasible and at most
/// `max_len` long.
pub(crate) fn optimise_strip(ctx: &mut Ctx, st: State, max_len: f64) -> State {
    let mut best = st;
    if best.placed.len() <= 1 {
        return best;
    }
    let height = ctx.prob.container.height();
    let area: f64 = best.items.iter().map(|&i| ctx.prob.items[i].area).sum();
    let widest = best
        .items
        .iter()
        .filter_map(|&i| ctx.prob.items[i].min_length(height))
        .fold(0.0, f64::max);
    let lower = (area / height).max(widest);
    let mut best_len = best.extent().min(max_len);
    let start = ctx.progress();
    let end_explore = start + EXPLORE_SHARE * (1.0 - start);
    // Exploration: shrink the best by `EXPLORE_STEP` and separate; a failure goes into a pool
    // of infeasible layouts of this length, from which the next try is drawn and disrupted.
    let mut pool: Vec<(f64, State)> = Vec::new();
    let mut cur: Option<(State, f64)> = None;
    while !ctx.done() && ctx.progress() < end_explore && best_len > lower * (1.0 + 1e-6) {
        let (mut cand, len) = match cur.take() {
            Some(c) => c,
            None => {
                let new_len = (best_len * (1.0 - EXPLORE_STEP)).max(lower);
                match shrink(ctx, &best, best_len, new_len) {
                    Some(c) => (c, new_len),
                    None => break,
                }
            }
        };
        let loss = separate(ctx, &mut cand, len, 3, 25);
        if loss == 0.0 {
            best_len = cand.extent().min(len);
            best = cand;
            pool.clear();
        } else {
            let at = pool.partition_point(|(l, _)| *l <= loss);
            pool.insert(at, (loss, cand));
            pool.truncate(POOL);
            // Better layouts are drawn more often (|N(0, 0.25)| of the pool's length).
            let pick = (ctx.rng.normal().abs() * 0.25).min(0.999);
            let mut next = pool[(pick * pool.len() as f64) as usize].1.clone();
            disrupt(ctx, &mut next, len);
            cur = Some((next, len));
        }
    }
    // Compression: small shrinks of the best, kept when they separate; the ratio falls from
    // 0.05 % to 0.001 % over the phase.
    let (hi0, lo0) = (0.0005, 0.00001);
    let start = ctx.progress();
    while !ctx.done() && best_len > lower * (1.0 + 1e-6) {
        let t = ((ctx.progress() - start) / (1.0 - start).max(1e-9)).clamp(0.0, 1.0);
        let r = hi0 + (lo0 - hi0) * t;
        let new_len = (best_len * (1.0 - r)).max(lower);
        let Some(mut cand) = shrink(ctx, &best, best_len, new_len) else {
            break;
        };
        if separate(ctx, &mut cand, new_len, COMPRESS_STRIKES, COMPRESS_PATIENCE) == 0.0 {
            best_len = cand.extent().min(new_len);
            best = cand;
        }
    }
    best
}

/// Disruption of an infeasible layout (sparrow): two large items (area at least the median)
/// of different shapes swap places; when all large items look alike, one of them moves to a
/// random place instead. Items whose largest pole ends up under a swapped item's new place
/// move into the room it left (by the same shift), as sparrow does, so that a large item
/// swapped with a small one does not land on a heap of small ones.
fn disrupt(ctx: &mut Ctx, st: &mut State, len: f64) {
    let height = ctx.prob.container.height();
    let n = st.placed.len();
    if n < 2 {
        return;
    }
    let mut areas: Vec<f64> = st.items.iter().map(|&i| ctx.prob.items[i].area).collect();
    areas.sort_by(f64::total_cmp);
    let median = areas[n / 2];
    let large: Vec<usize> = (0..n)
        .filter(|&k| ctx.prob.items[st.items[k]].area >= median)
        .collect();
    let i = large[ctx.rng.below(large.len())];
    let differs = |k: usize| {
        let (a, b) = (&ctx.prob.items[st.items[i]], &ctx.prob.items[st.items[k]]);
        (a.area - b.area).abs() > 1e-2 * a.area.abs().max(1.0)
    };
    let others: Vec<usize> = large.iter().copied().filter(|&k| differs(k)).collect();
    if others.is_empty() {
        let sz = st.placed[i].shape.size;
        st.placed[i].pos = DVec2::new(
            ctx.rng.range(0.0, (len - sz.x).max(0.0)),
            ctx.rng.range(0.0, (height - sz.y).max(0.0)),
        );
        return;
    }
    let j = others[ctx.rng.below(others.len())];
    let (pi, pj) = (st.placed[i].pos, st.placed[j].pos);
    let (si, sj) = (st.placed[i].shape.size, st.placed[j].shape.size);
    // Centres swap (bounding-box centres), clamped into the container.
    let ni = clamp_pos(pj + 0.5 * (sj - si), si, len, height);
    let nj = clamp_pos(pi + 0.5 * (si - sj), sj, len, height);
    st.placed[i].pos = ni;
    st.placed[j].pos = nj;
    let mut follow = Vec::new();
    for (moved, old, new) in [(i, pi, ni), (j, pj, nj)] {
        let m = &st.placed[moved];
        for (k, p) in st.placed.iter().enumerate() {
            if k == i || k == j {
                continue;
            }
            let Some((c, _)) = p.shape.poles.first() else {
                continue;
            };
            let c = *c + p.pos - m.pos;
            let inside = c.x >= 0.0 && c.y >= 0.0 && c.x <= m.shape.size.x && c.y <= m.shape.size.y;
            if inside && in_material(&m.shape.rings, c) {
                follow.push((k, old - new));
            }
        }
    }
    for (k, shift) in follow {
        let p = &mut st.placed[k];
        p.pos = clamp_pos(p.pos + shift, p.shape.size, len, height);
    }
}

/// Fewer bins, then the last one short (see the module docs).
pub(crate) fn optimise_bins(ctx: &mut Ctx, mut bins: Vec<State>, len: f64) -> Vec<State> {
    let Container::Bins { height, .. } = ctx.prob.container else {
        return bins;
    };
    let total = ctx.budget;
    // Phase 1, half the budget: empty the last bin into the others.
    let phase1 = total / 2;
    'outer: while bins.len() > 1 && ctx.work < phase1 && !ctx.done() {
        let last = bins.len() - 1;
        let mut moved_any = false;
        let mut k = 0;
        while k < bins[last].items.len() {
            if ctx.work >= phase1 || ctx.done() {
                break 'outer;
            }
            let item = bins[last].items[k];
            let mut placed = false;
            for bin in bins.iter_mut().take(last) {
                let mut cand = bin.clone();
                // Room left bottom-left? Else insert anywhere and separate.
                let shape = ctx.prob.items[item].random_shape(&mut ctx.rng);
                if shape.size.x > len + 1e-9 || shape.size.y > height + 1e-9 {
                    continue;
                }
                let pos = DVec2::new(
                    ctx.rng.range(0.0, (len - shape.size.x).max(0.0)),
                    ctx.rng.range(0.0, (height - shape.size.y).max(0.0)),
                );
                cand.items.push(item);
                cand.placed.push(Placed { shape, pos });
                if separate(ctx, &mut cand, len, 2, 30) == 0.0 {
                    *bin = cand;
                    placed = true;
                    break;
                }
            }
            if placed {
                bins[last].items.remove(k);
                bins[last].placed.remove(k);
                moved_any = true;
            } else {
                k += 1;
            }
        }
        if bins[last].items.is_empty() {
            bins.pop();
        } else if !moved_any {
            break;
        }
    }
    // Phase 2: the last bin as short as possible.
    if let Some(last) = bins.pop() {
        let last = optimise_strip(ctx, last, len);
        bins.push(last);
    }
    bins
}
