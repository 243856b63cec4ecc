//! The separator of sparrow (Gardeyn, Vanden Berghe, Wauters, "An open-source heuristic to
//! reboot 2D nesting research", EJOR 2025), itself after the guided local search of Egeblad et
//! al. 2007 and Umetani et al. 2009: overlap minimisation of a layout in a container of fixed
//! length.
//!
//! [`separate`]: given a layout with overlaps, repeat: every item that overlaps another (in
//! random order) moves to the position and orientation that minimise its *weighted* overlap
//! with the others. A move evaluates the current place, 25 samples around it (within its own
//! bounding box) and 50 uniform samples in the container, keeps the 3 best distinct ones,
//! refines each by coordinate descent (steps from 25 % down to 2 % of the item's smaller side,
//! along x, y or a diagonal, growing × 1.1 on success and halving on failure), then refines the
//! best of those more finely (1 % down to 0.1 %) — sparrow's sampling and two-stage refinement.
//! Overlap between two items is the pole-based proxy of
//! [`crate::nest::collision::overlap_proxy`], counted only for pairs that collide exactly.
//! After every sweep the pair weights grow where the pair still overlaps (× 1.2 … 2, more for
//! the pairs that overlap most) and decay back towards 1 elsewhere (× 0.95): this guided local
//! search escapes the local minima that plain overlap minimisation sticks in. A run of sweeps
//! ends after `patience` sweeps without a new least overlap (one at least 2 % lower restarts
//! the count) and is a strike unless it lowered the overlap by 2 %; the least overlapping
//! layout is restored, weights kept, and after `strikes` strikes in a row the separator gives
//! up; zero overlap is a feasible layout.
//!
//! Choices where sparrow is silent or differs: one separator per search and one search per
//! thread (sparrow runs several workers inside one separator sweep and keeps the best; here
//! the searches are independent, which needs no hand-over between threads every sweep); a
//! move stops sampling as soon as it finds a place without overlap; samples closer than 5 % of
//! the item's smaller side count as one; weights persist across strikes within one separation
//! and start at 1. The item moves ([`Item::random_shape`], [`Item::nearby_shape`]) draw a
//! random allowed orientation, or keep the current one or turn it by up to 10°.

use super::state::{Ctx, State};
use crate::geom::rng::Rng;
use crate::nest::collision::{boxes_near, collide, overlap_proxy, Placed, Shape};
use crate::nest::problem::{Item, Orient, Orients};
use glam::DVec2;
use std::sync::Arc;

const CONTAINER_SAMPLES: usize = 50;
const FOCUS_SAMPLES: usize = 25;
/// Samples refined by coordinate descent per move.
const DESCENTS: usize = 3;

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
pub(super) fn clamp_pos(p: DVec2, size: DVec2, len: f64, height: f64) -> DVec2 {
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
