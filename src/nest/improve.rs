//! Improvement by overlap minimisation, after sparrow (Gardeyn, Vanden Berghe, Wauters, "An
//! open-source heuristic to reboot 2D nesting research", EJOR 2025), itself after the guided
//! local search of Egeblad et al. 2007 and Umetani et al. 2009.
//!
//! **Separator** ([`separate`]): given a layout with overlaps in a container of fixed length,
//! repeat: every item that overlaps another (in random order) moves to the position and
//! orientation that minimise its *weighted* overlap with the others — sampled uniformly in the
//! container (40 samples), around its current position (20 samples), then refined by
//! coordinate descent with a shrinking step. Overlap between two items is the pole-based proxy
//! of [`super::engine::overlap_proxy`], counted only for pairs that collide exactly. After every
//! sweep the pair weights grow where the pair still overlaps (× 1.2 … 2, more for the pairs
//! that overlap most) and decay back towards 1 elsewhere (× 0.95): this guided local search
//! escapes the local minima that plain overlap minimisation sticks in. The best layout of the
//! run (least unweighted overlap) is restored after 50 sweeps without improvement (a "strike");
//! after 3 strikes the separator gives up; zero overlap is a feasible layout.
//!
//! **Strip** ([`optimise_strip`]): exploration (80 % of the budget, as in sparrow), then
//! compression. Exploration shrinks the best feasible strip by a ratio (start 2 %) by cutting
//! a slice out at a random x and moving the items right of it left, then separates; success
//! becomes the new best. A failed width is retried from the failed layout after a disruption
//! (two large items of different shapes swap places, as in sparrow); after three failures the
//! ratio halves (down to 0.1 %) and the search restarts from the best layout. Compression
//! shrinks the best by small random ratios (between 0.01 % and a bound that falls from 0.5 % to
//! 0.01 % over the phase) with a shorter separator. Only
//! feasible layouts are kept, so stopping at any time returns a valid layout.
//!
//! **Bins** ([`optimise_bins`]): the items of the last bin are moved one by one into earlier
//! bins (bottom-left if there is room, else inserted and separated); a bin that empties is
//! dropped. Then the last bin is compressed as a strip of its height whose length is at most
//! the bin's, so that what is left of it is one rectangle at its right end.
//!
//! Choices where sparrow is silent or differs: exploration works on one infeasible layout at a
//! time (sparrow keeps a pool of them); the refinement step starts at
//! 10 % of the item's larger side and stops below 0.1 %; weights persist across strikes within
//! one separation and start at 1 for each.

use super::engine::{boxes_near, collide, overlap_proxy, Placed};
use super::problem::{Container, Ctx, State};
use glam::DVec2;

const CONTAINER_SAMPLES: usize = 40;
const FOCUS_SAMPLES: usize = 20;

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

/// Move item `k` to the best position found (see the module docs).
fn move_item(ctx: &mut Ctx, st: &mut State, sep: &mut Sep, k: usize, len: f64) {
    let height = ctx.prob.container.height();
    let item = &ctx.prob.items[st.items[k]];
    let cur = st.placed[k].clone();
    let mut best = cur.clone();
    let mut best_e = sep.row_weighted(k);
    let fits = |sz: DVec2| sz.x <= len + 1e-9 && sz.y <= height + 1e-9;
    for _ in 0..CONTAINER_SAMPLES {
        if best_e <= 0.0 {
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
        let e = evaluate(ctx, st, sep, k, &cand, best_e);
        if e < best_e {
            best_e = e;
            best = cand;
        }
    }
    for _ in 0..FOCUS_SAMPLES {
        if best_e <= 0.0 {
            break;
        }
        let shape = item.nearby_shape(&cur.shape, &mut ctx.rng);
        if !fits(shape.size) {
            continue;
        }
        let r = 0.25 * cur.shape.size.max_element();
        let d = DVec2::new(ctx.rng.range(-r, r), ctx.rng.range(-r, r));
        let pos = clamp_pos(cur.pos + d, shape.size, len, height);
        let cand = Placed { shape, pos };
        let e = evaluate(ctx, st, sep, k, &cand, best_e);
        if e < best_e {
            best_e = e;
            best = cand;
        }
    }
    // Coordinate descent.
    let scale = best.shape.size.max_element();
    let mut step = 0.1 * scale;
    while best_e > 0.0 && step > 1e-3 * scale {
        let mut moved = false;
        for dir in [DVec2::X, DVec2::NEG_X, DVec2::Y, DVec2::NEG_Y] {
            let pos = clamp_pos(best.pos + dir * step, best.shape.size, len, height);
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
                moved = true;
                break;
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    st.placed[k] = best;
    sep.update_row(ctx, st, k);
}

/// One iteration of the separator (for the benchmark): every overlapping item of `st` moves
/// once, then the weights are updated; returns the overlap left.
pub fn sweep(ctx: &mut Ctx, st: &mut State, len: f64) -> f64 {
    let mut sep = Sep::new(ctx, st);
    let mut order: Vec<usize> = (0..sep.n).filter(|&k| sep.overlapping(k)).collect();
    ctx.rng.shuffle(&mut order);
    for &k in &order {
        if sep.overlapping(k) {
            move_item(ctx, st, &mut sep, k, len);
        }
    }
    sep.update_weights();
    sep.total()
}

/// Resolve the overlaps of `st` in a container `len` long; true when it ends feasible (then
/// `st` is the feasible layout), else `st` is the least-overlapping layout found.
pub fn separate(ctx: &mut Ctx, st: &mut State, len: f64, strikes: usize, patience: usize) -> bool {
    let mut sep = Sep::new(ctx, st);
    let mut best_total = sep.total();
    if best_total == 0.0 {
        return true;
    }
    let mut best = st.clone();
    let mut order: Vec<usize> = Vec::new();
    for _ in 0..strikes {
        let mut idle = 0;
        let mut improved = false;
        while idle < patience && !ctx.done() {
            order.clear();
            order.extend((0..sep.n).filter(|&k| sep.overlapping(k)));
            ctx.rng.shuffle(&mut order);
            for &k in &order {
                if sep.overlapping(k) {
                    move_item(ctx, st, &mut sep, k, len);
                }
            }
            let total = sep.total();
            if std::env::var_os("FLATCUT_NEST_DEBUG2").is_some() {
                eprintln!(
                    "  sweep total {total:.6} overlapping {} / {} idle {idle}",
                    (0..sep.n).filter(|&k| sep.overlapping(k)).count(),
                    sep.n
                );
            }
            if total == 0.0 {
                return true;
            }
            if total < best_total {
                best_total = total;
                best = st.clone();
                idle = 0;
                improved = true;
            } else {
                idle += 1;
            }
            sep.update_weights();
        }
        *st = best.clone();
        sep.recompute(ctx, st);
        if ctx.done() || !improved {
            break;
        }
    }
    false
}

/// Cut a slice `delta` wide out at a random x of a layout `len` long: items right of the cut
/// move left; every item is kept inside the new length. None if an item cannot fit.
pub fn shrink(ctx: &mut Ctx, st: &State, len: f64, new_len: f64) -> Option<State> {
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
pub fn optimise_strip(ctx: &mut Ctx, st: State, max_len: f64) -> State {
    let height = ctx.prob.container.height();
    let mut best = st;
    if best.placed.len() <= 1 {
        return best;
    }
    let area: f64 = best.items.iter().map(|&i| ctx.prob.items[i].area).sum();
    let widest = best
        .items
        .iter()
        .filter_map(|&i| ctx.prob.items[i].min_length(height))
        .fold(0.0, f64::max);
    let lower = (area / height).max(widest);
    let mut best_len = best.extent().min(max_len);
    let mut ratio: f64 = 0.02;
    let mut tries = 0;
    // The infeasible layout being worked on (exploration) and its length.
    let mut cur: Option<(State, f64)> = None;
    let start = ctx.progress();
    while !ctx.done() && best_len > lower * (1.0 + 1e-6) {
        let explore = ctx.progress() < start + 0.8 * (1.0 - start);
        let (mut cand, new_len) = match cur.take() {
            Some((mut st, len)) if explore => {
                disrupt(ctx, &mut st, len);
                (st, len)
            }
            _ => {
                let r = if explore {
                    ratio
                } else {
                    // 0.5 % down to 0.01 % over the compression phase, at random below.
                    let t = ((ctx.progress() - start) / (1.0 - start) - 0.8) / 0.2;
                    let hi = 0.005 * (1.0 - t.clamp(0.0, 1.0)) + 0.0001;
                    ctx.rng.range(0.0001, hi)
                };
                let new_len = (best_len * (1.0 - r)).max(lower);
                let Some(cand) = shrink(ctx, &best, best_len, new_len) else {
                    break;
                };
                (cand, new_len)
            }
        };
        let (strikes, patience) = if explore { (3, 50) } else { (2, 25) };
        let ok = separate(ctx, &mut cand, new_len, strikes, patience);
        if std::env::var_os("FLATCUT_NEST_DEBUG").is_some() {
            eprintln!(
                "{} len {new_len:.4} ok {ok} work {:.3}",
                if explore { "E" } else { "C" },
                ctx.progress()
            );
        }
        if ok {
            best_len = cand.extent().min(new_len);
            best = cand;
            tries = 0;
        } else if explore {
            tries += 1;
            if tries >= 3 {
                ratio = (ratio * 0.5).max(0.001);
                tries = 0;
            } else {
                cur = Some((cand, new_len));
            }
        }
    }
    best
}

/// Disruption of an infeasible layout (sparrow): two large items (area at least the median)
/// of different shapes swap places; when all large items look alike, one of them moves to a
/// random place instead.
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
        (a.area - b.area).abs() > 1e-9 * a.area.abs().max(1.0)
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
    st.placed[i].pos = clamp_pos(pj, si, len, height);
    st.placed[j].pos = clamp_pos(pi, sj, len, height);
}

/// Fewer bins, then the last one short (see the module docs).
pub fn optimise_bins(ctx: &mut Ctx, mut bins: Vec<State>, len: f64) -> Vec<State> {
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
                if separate(ctx, &mut cand, len, 2, 30) {
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
