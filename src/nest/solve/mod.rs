//! The solver: [`solve`] runs independent searches, one per thread, and keeps the best; each
//! search builds a layout with the constructive start ([`construct`]: bottom-left fill) and
//! then improves it ([`improve`]: strip exploration and compression, with sparrow's separator
//! ([`separate`]) resolving the overlaps each shrink leaves; for bins, emptying the last bin,
//! then compressing it). The searches' state and deterministic work budget are in [`state`].
//!
//! Threads: the seeds of the searches derive from the seed and the thread number; odd threads
//! start from a different order (neighbours in the largest-first order swapped at random), so
//! that two searches explore differently. The best is the one with the fewest bins, then the
//! shortest length, then the lowest thread, so the result depends only on the seed and the
//! thread count.

pub(crate) mod construct;
pub(crate) mod improve;
pub(crate) mod separate;
pub(crate) mod state;

use super::problem::{
    check_fit, Config, Container, ItemPlacement, Orient, Problem, Solution, Unfit,
};
use glam::DVec2;
use state::Ctx;

/// Run `cfg.threads` independent searches (seeds derived from `cfg.seed`) and keep the best:
/// fewest bins, then shortest length, then the lowest thread.
pub(crate) fn solve(prob: &Problem, cfg: &Config) -> Result<Solution, Unfit> {
    check_fit(prob)?;
    let threads = cfg.threads.max(1);
    let run = |t: usize| {
        let seed = cfg
            .seed
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(t as u64);
        let mut ctx = Ctx::new(prob, seed, cfg.seconds);
        search(&mut ctx, t)
    };
    let results: Vec<Option<Solution>> = if threads == 1 {
        vec![run(0)]
    } else {
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..threads).map(|t| s.spawn(move || run(t))).collect();
            handles
                .into_iter()
                .map(|h| h.join().ok().flatten())
                .collect()
        })
    };
    let mut best: Option<Solution> = None;
    for r in results.into_iter().flatten() {
        let better = match &best {
            None => true,
            Some(b) => (r.bins, r.length) < (b.bins, b.length),
        };
        if better {
            best = Some(r);
        }
    }
    best.ok_or_else(|| {
        // Name the item that does not fit alone (the searches only say that one failed).
        let max_len = match prob.container {
            Container::Strip { .. } => f64::INFINITY,
            Container::Bins { length, .. } => length,
        };
        let mut ctx = Ctx::new(prob, cfg.seed, cfg.seconds);
        let item = construct::unplaceable(&mut ctx, max_len).unwrap_or(0);
        let size = prob
            .items
            .get(item)
            .and_then(|it| it.shapes.first())
            .map_or(DVec2::ZERO, |s| s.size);
        Unfit { item, size }
    })
}

/// One search: construction, then improvement.
fn search(ctx: &mut Ctx, thread: usize) -> Option<Solution> {
    let prob = ctx.prob;
    let mut order: Vec<usize> = (0..prob.items.len()).collect();
    // Largest first (by convex-hull-free measure: area, then bounding box), ties by index.
    let key = |i: usize| {
        let it = &prob.items[i];
        let bb = it
            .shapes
            .first()
            .map(|s| s.size.x * s.size.y)
            .unwrap_or(0.0);
        it.area.max(0.0) + 0.25 * bb
    };
    order.sort_by(|&a, &b| key(b).total_cmp(&key(a)).then(a.cmp(&b)));
    if thread % 2 == 1 {
        // A second, different start: neighbours in the order swap at random.
        for k in 1..order.len() {
            if ctx.rng.f64() < 0.3 {
                order.swap(k - 1, k);
            }
        }
    }
    let bins = match prob.container {
        Container::Strip { .. } => {
            let st = construct::fill_strip(ctx, &order)?;
            let st = improve::optimise_strip(ctx, st, f64::INFINITY);
            vec![st]
        }
        Container::Bins { length, .. } => {
            let sheets = construct::fill_bins(ctx, &order, length)?;
            improve::optimise_bins(ctx, sheets, length)
        }
    };
    let mut placements = vec![
        ItemPlacement {
            bin: 0,
            orient: Orient {
                angle_deg: 0.0,
                mirror: false
            },
            translation: DVec2::ZERO,
        };
        prob.items.len()
    ];
    for (b, st) in bins.iter().enumerate() {
        for (k, &i) in st.items.iter().enumerate() {
            let p = &st.placed[k];
            placements[i] = ItemPlacement {
                bin: b,
                orient: p.shape.orient,
                translation: p.shape.shift + p.pos,
            };
        }
    }
    Some(Solution {
        placements,
        bins: bins.len(),
        length: bins.last().map_or(0.0, |s| s.extent()),
        work: ctx.work,
    })
}
