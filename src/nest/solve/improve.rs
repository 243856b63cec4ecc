//! Improvement by overlap minimisation, after sparrow (Gardeyn, Vanden Berghe, Wauters, "An
//! open-source heuristic to reboot 2D nesting research", EJOR 2025), itself after the guided
//! local search of Egeblad et al. 2007 and Umetani et al. 2009.
//!
//! **Separator** ([`separate`]): given a layout with overlaps in a container of fixed length,
//! repeat: every item that overlaps another (in random order) moves to the position and
//! orientation that minimise its *weighted* overlap with the others. A move evaluates the
//! current place, 25 samples around it (within its own bounding box) and 50 uniform samples in
//! the container, keeps the 3 best distinct ones, refines each by coordinate descent (steps
//! from 25 % down to 2 % of the item's smaller side, along x, y or a diagonal, growing × 1.1 on
//! success and halving on failure), then refines the best of those more finely (1 % down to
//! 0.1 %) — sparrow's sampling and two-stage refinement. Overlap between two items is the
//! pole-based proxy of [`crate::nest::collision::overlap_proxy`], counted only for pairs that
//! collide exactly. After every sweep the pair weights grow where the pair still overlaps
//! (× 1.2 … 2, more for the pairs that overlap most) and decay back towards 1 elsewhere
//! (× 0.95): this guided local search escapes the local minima that plain overlap
//! minimisation sticks in. A run of sweeps ends after 25 sweeps without a new least overlap
//! (one at least 2 % lower restarts the count) and is a strike unless it lowered the overlap
//! by 2 %; the least overlapping layout is restored, weights kept, and after 3 strikes in a row
//! the separator gives up (in compression: 5 strikes of 100 sweeps, as sparrow); zero overlap
//! is a feasible layout.
//!
//! **Strip** ([`optimise_strip`]): exploration (90 % of the budget, as in sparrow), then
//! compression. Exploration shrinks the best feasible strip by 0.1 % by cutting a slice out at
//! a random x and moving the items right of it left, then separates; success becomes the new
//! best. A failure goes into a pool of infeasible layouts of that length, ordered by overlap;
//! the next try is drawn from the pool (index `|N(0, 0.25)|` × pool size, so the least
//! overlapping most often) and disrupted: two large items of different shapes swap places, and
//! items lying under a swapped item's new place move into the room it left (sparrow).
//! Compression shrinks the best by a ratio that falls linearly from 0.05 % to 0.001 % over the
//! phase, at a random x, and separates more patiently (sparrow's compression). Only feasible
//! layouts are kept, so stopping at any time returns a valid layout.
//!
//! **Bins** ([`optimise_bins`]): the items of the last bin are moved one by one into earlier
//! bins (bottom-left if there is room, else inserted and separated); a bin that empties is
//! dropped. Then the last bin is compressed as a strip of its height whose length is at most
//! the bin's, so that what is left of it is one rectangle at its right end.
//!
//! Choices where sparrow is silent or differs: one search per thread (sparrow runs several
//! workers inside one separator sweep and keeps the best; here the searches are independent,
//! which needs no hand-over between threads every sweep); the pool keeps at most 64 layouts;
//! a move stops sampling as soon as it finds a place without overlap; "large" items are those
//! with at least the median area (sparrow: a convex-hull-area percentile); the exploration
//! cuts at a random x (sparrow cuts at the middle of the strip); samples closer than 5 % of
//! the item's smaller side count as one; weights persist across strikes within one separation
//! and start at 1. The item moves ([`Item::random_shape`], [`Item::nearby_shape`]) draw a
//! random allowed orientation, or keep the current one or turn it by up to 10°.

use super::state::{Ctx, State};
use crate::geom::rng::Rng;
use crate::nest::collision::{boxes_near, collide, in_material, overlap_proxy, Placed, Shape};
use crate::nest::problem::{Container, Item, Orient, Orients};
use glam::DVec2;
use std::sync::Arc;

const CONTAINER_SAMPLES: usize = 50;
const FOCUS_SAMPLES: usize = 25;
/// Samples refined by coordinate descent per move.
const DESCENTS: usize = 3;
/// Infeasible layouts kept during exploration.
const POOL: usize = 64;
/// Share of the strip budget spent exploring (the rest compresses), as in sparrow.
const EXPLORE_SHARE: f64 = 0.9;
/// Exploration shrinks the strip by this ratio after each success (sparrow's 0.1 %).
const EXPLORE_STEP: f64 = 0.001;
/// The compression separator's strikes and patience (sparrow's).
const COMPRESS_STRIKES: usize = 5;
const COMPRESS_PATIENCE: usize = 100;

/// The moves of an item in the separator (module docs).
impl Item {
    /// A random allowed shape.
    pub(crate) fn random_shape(&self, rng: &mut Rng) -> Arc<Shape> {
        match &self.orients {
            Orients::Set(_) => self.shapes[rng.below(self.shapes.len())].clone(),
            Orients::Free { mirror } => {
                let o = Orient {
                    angle_deg: rng.range(0.0, 360.0),
                    mirror: *mirror && rng.f64() < 0.5,
                };
                Arc::new(Shape::new(&self.rings, &self.poles, o))
            }
        }
    }

    /// A shape near `cur`: the same, or (free rotation) turned by a few degrees.
    pub(crate) fn nearby_shape(&self, cur: &Arc<Shape>, rng: &mut Rng) -> Arc<Shape> {
        match &self.orients {
            Orients::Set(_) => {
                if rng.f64() < 0.8 {
                    cur.clone()
                } else {
                    self.random_shape(rng)
                }
            }
            Orients::Free { .. } => {
                if rng.f64() < 0.5 {
                    cur.clone()
                } else {
                    let o = Orient {
                        angle_deg: (cur.orient.angle_deg + rng.range(-10.0, 10.0))
                            .rem_euclid(360.0),
                        mirror: cur.orient.mirror,
                    };
                    Arc::new(Shape::new(&self.rings, &self.poles, o))
                }
            }
        }
    }
}

/// Pair overlaps and weights of one state.
struct Sep {
    n: usize,
    ov: Vec<f64>,
    w: Vec<f64>,
}

impl Sep {
    fn new(ctx: &mut Ctx, st: &State) -> Sep {
        let n = st.placed.len();
        let mut sep = Sep {
            n,
            ov: vec![0.0; n * n],
            w: vec![1.0; n * n],
        };
        sep.recompute(ctx, st);
        sep
    }
    fn recompute(&mut self, ctx: &mut Ctx, st: &State) {
        self.ov.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..self.n {
            self.update_row(ctx, st, k);
        }
    }
    fn update_row(&mut self, ctx: &mut Ctx, st: &State, k: usize) {
        let s = ctx.prob.spacing;
        let a = &st.placed[k];
        for j in 0..self.n {
            if j == k {
                continue;
            }
            let b = &st.placed[j];
            let v = if collide(&a.shape, a.pos, &b.shape, b.pos, s, &mut ctx.work) {
                overlap_proxy(&a.shape, a.pos, &b.shape, b.pos, s, &mut ctx.work)
            } else {
                0.0
            };
            self.ov[k * self.n + j] = v;
            self.ov[j * self.n + k] = v;
        }
    }
    fn total(&self) -> f64 {
        let mut t = 0.0;
        for i in 0..self.n {
            for j in i + 1..self.n {
                t += self.ov[i * self.n + j];
            }
        }
        t
    }
    fn row_weighted(&self, k: usize) -> f64 {
        (0..self.n)
            .map(|j| self.w[k * self.n + j] * self.ov[k * self.n + j])
            .sum()
    }
    fn overlapping(&self, k: usize) -> bool {
        (0..self.n).any(|j| self.ov[k * self.n + j] > 0.0)
    }
    fn update_weights(&mut self) {
        let max = self.ov.iter().copied().fold(0.0, f64::max);
        let (ml, mu, dec) = (1.2, 2.0, 0.95);
        for i in 0..self.n {
            for j in i + 1..self.n {
                let v = self.ov[i * self.n + j];
                let w = &mut self.w[i * self.n + j];
                if v > 0.0 && max > 0.0 {
                    *w *= ml + (mu - ml) * v / max;
                } else {
                    *w = (*w * dec).max(1.0);
                }
                self.w[j * self.n + i] = self.w[i * self.n + j];
            }
        }
    }
}

/// Weighted overlap of item `k` of `st` if it were `cand`; stops early above `bound`.
fn evaluate(ctx: &mut Ctx, st: &State, sep: &Sep, k: usize, cand: &Placed, bound: f64) -> f64 {
    let s = ctx.prob.spacing;
    ctx.work += 2 + st.placed.len() as u64 / 16;
    let mut acc = 0.0;
    for (j, b) in st.placed.iter().enumerate() {
        if j == k || !boxes_near(&cand.shape, cand.pos, &b.shape, b.pos, s) {
            continue;
        }
        if collide(&cand.shape, cand.pos, &b.shape, b.pos, s, &mut ctx.work) {
            acc += sep.w[k * sep.n + j]
                * overlap_proxy(&cand.shape, cand.pos, &b.shape, b.pos, s, &mut ctx.work);
            if acc >= bound {
                return acc;
            }
        }
    }
    acc
}

/// Positions of a shape of `size` in the container: [0, len − w] × [0, h − height].
fn clamp_pos(p: DVec2, size: DVec2, len: f64, height: f64) -> DVec2 {
    DVec2::new(
        p.x.clamp(0.0, (len - size.x).max(0.0)),
        p.y.clamp(0.0, (height - size.y).max(0.0)),
    )
}

/// The few best distinct samples of one move, best first.
struct Best {
    keep: usize,
    /// Samples closer than this (and of the same shape) count as one.
    unique: f64,
    list: Vec<(f64, Placed)>,
}

impl Best {
    /// Weighted overlap a sample must beat to be kept.
    fn bound(&self) -> f64 {
        if self.list.len() < self.keep {
            f64::INFINITY
        } else {
            self.list.last().map_or(f64::INFINITY, |b| b.0)
        }
    }
    fn report(&mut self, e: f64, cand: Placed) {
        if let Some(k) = self.list.iter().position(|(_, p)| {
            Arc::ptr_eq(&p.shape, &cand.shape) && p.pos.distance(cand.pos) < self.unique
        }) {
            if e < self.list[k].0 {
                self.list.remove(k);
            } else {
                return;
            }
        }
        if self.list.len() >= self.keep && e >= self.bound() {
            return;
        }
        let at = self.list.partition_point(|(b, _)| *b <= e);
        self.list.insert(at, (e, cand));
        self.list.truncate(self.keep);
    }
}

/// Coordinate descent from `start` (sparrow's refinement): two candidates a step either side
/// along one axis (x, y or a diagonal); a better one is taken and the step grows (× 1.1), else
/// the step shrinks (× 0.5) and another axis is drawn; it stops when both steps are below
/// `limit`.
fn descend(
    ctx: &mut Ctx,
    st: &State,
    sep: &Sep,
    k: usize,
    start: (f64, Placed),
    (step, limit): (f64, f64),
    len: f64,
) -> (f64, Placed) {
    let height = ctx.prob.container.height();
    let (mut best_e, mut best) = start;
    let mut steps = DVec2::splat(step);
    let mut axis = ctx.rng.below(4);
    while best_e > 0.0 && (steps.x >= limit || steps.y >= limit) {
        let d = match axis {
            0 => DVec2::new(steps.x, 0.0),
            1 => DVec2::new(0.0, steps.y),
            2 => steps,
            _ => DVec2::new(-steps.x, steps.y),
        };
        let mut better = false;
        for dir in [d, -d] {
            let pos = clamp_pos(best.pos + dir, best.shape.size, len, height);
            if pos == best.pos {
                continue;
            }
            let cand = Placed {
                shape: best.shape.clone(),
                pos,
            };
            let e = evaluate(ctx, st, sep, k, &cand, best_e);
            if e < best_e {
                best_e = e;
                best = cand;
                better = true;
            }
        }
        let m = if better { 1.1 } else { 0.5 };
        match axis {
            0 => steps.x *= m,
            1 => steps.y *= m,
            _ => steps *= f64::sqrt(m),
        }
        if !better {
            axis = ctx.rng.below(4);
        }
    }
    (best_e, best)
}

/// Move item `k` to the best position found (see the module docs).
fn move_item(ctx: &mut Ctx, st: &mut State, sep: &mut Sep, k: usize, len: f64) {
    let height = ctx.prob.container.height();
    let item = &ctx.prob.items[st.items[k]];
    let cur = st.placed[k].clone();
    let min_dim = cur.shape.size.min_element().max(1e-9);
    let mut best = Best {
        keep: DESCENTS,
        unique: 0.05 * min_dim,
        list: Vec::with_capacity(DESCENTS + 1),
    };
    best.report(sep.row_weighted(k), cur.clone());
    let fits = |sz: DVec2| sz.x <= len + 1e-9 && sz.y <= height + 1e-9;
    let clear = |b: &Best| b.list.first().is_some_and(|f| f.0 <= 0.0);
    for _ in 0..FOCUS_SAMPLES {
        if clear(&best) {
            break;
        }
        let shape = item.nearby_shape(&cur.shape, &mut ctx.rng);
        if !fits(shape.size) {
            continue;
        }
        let r = 0.5 * cur.shape.size;
        let d = DVec2::new(ctx.rng.range(-r.x, r.x), ctx.rng.range(-r.y, r.y));
        let pos = clamp_pos(cur.pos + d, shape.size, len, height);
        let cand = Placed { shape, pos };
        let bound = best.bound();
        let e = evaluate(ctx, st, sep, k, &cand, bound);
        best.report(e, cand);
    }
    for _ in 0..CONTAINER_SAMPLES {
        if clear(&best) {
            break;
        }
        let shape = item.random_shape(&mut ctx.rng);
        if !fits(shape.size) {
            continue;
        }
        let pos = DVec2::new(
            ctx.rng.range(0.0, (len - shape.size.x).max(0.0)),
            ctx.rng.range(0.0, (height - shape.size.y).max(0.0)),
        );
        let cand = Placed { shape, pos };
        let bound = best.bound();
        let e = evaluate(ctx, st, sep, k, &cand, bound);
        best.report(e, cand);
    }
    // Refine the best few, then the best of them more finely.
    let starts = std::mem::take(&mut best.list);
    let mut top: Option<(f64, Placed)> = None;
    for s in starts {
        let r = descend(ctx, st, sep, k, s, (0.25 * min_dim, 0.02 * min_dim), len);
        if top.as_ref().is_none_or(|t| r.0 < t.0) {
            top = Some(r);
        }
    }
    let Some(top) = top else { return };
    let (_, fin) = descend(ctx, st, sep, k, top, (0.01 * min_dim, 0.001 * min_dim), len);
    st.placed[k] = fin;
    sep.update_row(ctx, st, k);
}

/// Every item of `st` that overlaps another moves once, in random order.
fn move_overlapping(
    ctx: &mut Ctx,
    st: &mut State,
    sep: &mut Sep,
    len: f64,
    order: &mut Vec<usize>,
) {
    order.clear();
    order.extend((0..sep.n).filter(|&k| sep.overlapping(k)));
    ctx.rng.shuffle(order);
    for &k in order.iter() {
        if sep.overlapping(k) {
            move_item(ctx, st, sep, k, len);
        }
    }
}

/// One iteration of the separator (for the benchmark): every overlapping item of `st` moves
/// once, then the weights are updated; returns the overlap left.
pub(crate) fn sweep(ctx: &mut Ctx, st: &mut State, len: f64) -> f64 {
    let mut sep = Sep::new(ctx, st);
    move_overlapping(ctx, st, &mut sep, len, &mut Vec::new());
    sep.update_weights();
    sep.total()
}

/// Resolve the overlaps of `st` in a container `len` long (Fig. "separator" of sparrow).
/// Returns the least unweighted overlap met: 0 when it ends feasible (then `st` is the
/// feasible layout), else `st` is the least-overlapping layout found.
///
/// A run of sweeps ends after `patience` sweeps without a new least overlap (a new least that
/// is at least 2 % lower restarts the count); it is a strike unless it lowered the overlap
/// by 2 % from where it started; after `strikes` strikes in a row the separator gives up.
/// Every run restarts from the least-overlapping layout with the weights it has reached.
pub(crate) fn separate(
    ctx: &mut Ctx,
    st: &mut State,
    len: f64,
    strikes: usize,
    patience: usize,
) -> f64 {
    let mut sep = Sep::new(ctx, st);
    let mut min_loss = sep.total();
    if min_loss == 0.0 {
        return 0.0;
    }
    let mut best = st.clone();
    let mut order: Vec<usize> = Vec::new();
    let mut n_strikes = 0;
    while n_strikes < strikes && !ctx.done() {
        let start_loss = sep.total();
        let mut idle = 0;
        while idle < patience && !ctx.done() {
            move_overlapping(ctx, st, &mut sep, len, &mut order);
            let total = sep.total();
            if total == 0.0 {
                return 0.0;
            }
            if total < min_loss {
                if total < 0.98 * min_loss {
                    idle = 0;
                }
                min_loss = total;
                best = st.clone();
            } else {
                idle += 1;
            }
            sep.update_weights();
        }
        if start_loss * 0.98 <= min_loss {
            n_strikes += 1;
        } else {
            n_strikes = 0;
        }
        *st = best.clone();
        sep.recompute(ctx, st);
    }
    min_loss
}

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
