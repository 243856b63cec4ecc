//! Constructive start: bottom-left fill (Baker, Coffman, Rivest 1980, in the form used for
//! irregular pieces by e.g. Burke et al. 2006 and jagua-rs's example optimiser).
//!
//! Items go in the given order (largest first). For each allowed orientation the candidate
//! positions are the corners that the bounding boxes of the placed items offer (x: 0 and the
//! right end of every placed item plus the spacing; y: 0, the top, and the top and bottom of
//! every placed item with the spacing), scanned left to right, then bottom to top; the first
//! position free of collisions is slid down and left (bisection on the slide distance, two
//! rounds) to close the gaps that bounding boxes leave between irregular shapes. Of the
//! orientations, the one whose right end is leftmost wins (ties: the lower one). In bins the
//! items fill the first bin they fit in, opening a new one when none has room.
//!
//! Choices: the candidates come from bounding boxes (not no-fit polygons), which puts
//! rectangles exactly edge to edge; the slide keeps only positions tested free. The scan of one
//! shape is bounded by a count of box tests (`SCAN_BUDGET`), not by the coordinates: past it,
//! the shape goes right of everything placed (always free), so thousands of tiny pieces cost
//! O(n) each instead of O(n²) candidates.

use super::state::{Ctx, State};
use crate::nest::collision::{boxes_near, collide, Placed, Shape};
use crate::nest::problem::Container;
use glam::DVec2;
use std::sync::Arc;

/// Is `shape` at `pos` free of the `others`?
fn free(ctx: &mut Ctx, shape: &Shape, pos: DVec2, others: &[&Placed]) -> bool {
    let s = ctx.prob.spacing;
    !others
        .iter()
        .any(|o| collide(shape, pos, &o.shape, o.pos, s, &mut ctx.work))
}

/// Slide from a free position along `dir` (−x or −y) as far as stays free, at most `max`.
fn slide(
    ctx: &mut Ctx,
    shape: &Shape,
    pos: DVec2,
    dir: DVec2,
    max: f64,
    others: &[&Placed],
) -> DVec2 {
    if max <= 0.0 {
        return pos;
    }
    if free(ctx, shape, pos + dir * max, others) {
        return pos + dir * max;
    }
    let (mut lo, mut hi) = (0.0, max);
    for _ in 0..16 {
        let mid = 0.5 * (lo + hi);
        if free(ctx, shape, pos + dir * mid, others) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    pos + dir * lo
}

/// Box tests one shape's bottom-left scan may make before it takes the free place right of
/// everything placed.
const SCAN_BUDGET: usize = 50_000;

/// Bottom-left position of one shape among `others` in a container of `height` and at most
/// `max_len` long; only positions whose right end is left of `bound` count.
fn bottom_left(
    ctx: &mut Ctx,
    shape: &Arc<Shape>,
    others: &[Placed],
    height: f64,
    max_len: f64,
    bound: f64,
    exhausted: &mut bool,
) -> Option<DVec2> {
    let s = ctx.prob.spacing;
    let (w, h) = (shape.size.x, shape.size.y);
    if h > height + 1e-9 || w > max_len + 1e-9 {
        return None;
    }
    let top = (height - h).max(0.0);
    let mut xs: Vec<f64> = std::iter::once(0.0)
        .chain(others.iter().map(|o| o.hi().x + s))
        .filter(|x| x + w <= max_len + 1e-9)
        .collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let mut ys: Vec<f64> = [0.0, top]
        .into_iter()
        .chain(others.iter().flat_map(|o| [o.hi().y + s, o.lo().y - h - s]))
        .filter(|y| *y >= 0.0 && *y <= top)
        .collect();
    ys.sort_by(f64::total_cmp);
    ys.dedup();
    let mut work = 0usize;
    'columns: for x in xs {
        if x + w >= bound {
            break;
        }
        if work > SCAN_BUDGET {
            break 'columns;
        }
        work += others.len();
        // Items that can meet the shape anywhere in this column.
        let col: Vec<&Placed> = others
            .iter()
            .filter(|o| o.pos.x < x + w + s && o.hi().x + s > x)
            .collect();
        for &y in &ys {
            work += 1 + col.len();
            if work > SCAN_BUDGET {
                break 'columns;
            }
            let pos = DVec2::new(x, y);
            let near: Vec<&Placed> = col
                .iter()
                .copied()
                .filter(|o| boxes_near(shape, pos, &o.shape, o.pos, s))
                .collect();
            if !free(ctx, shape, pos, &near) {
                continue;
            }
            let mut p = pos;
            let all: Vec<&Placed> = others.iter().collect();
            for _ in 0..2 {
                p = slide(ctx, shape, p, DVec2::NEG_Y, p.y, &all);
                p = slide(ctx, shape, p, DVec2::NEG_X, p.x, &all);
            }
            return Some(p);
        }
    }
    if work <= SCAN_BUDGET {
        return None;
    }
    // Out of budget: right of everything placed (and the spacing) is free.
    *exhausted = true;
    let x = others.iter().map(|o| o.hi().x + s).fold(0.0, f64::max);
    (x + w <= max_len + 1e-9 && x + w < bound).then_some(DVec2::new(x, 0.0))
}

/// Best bottom-left placement over the item's construction shapes.
/// `exhausted` is set when a scan ran out of its budget.
fn place_item(
    ctx: &mut Ctx,
    item: usize,
    others: &[Placed],
    max_len: f64,
    exhausted: &mut bool,
) -> Option<Placed> {
    let height = ctx.prob.container.height();
    let shapes = ctx.prob.items[item].shapes.clone();
    let mut best: Option<Placed> = None;
    for sh in &shapes {
        let bound = best.as_ref().map_or(f64::INFINITY, |b| b.hi().x + 1e-9);
        if let Some(p) = bottom_left(ctx, sh, others, height, max_len, bound, exhausted) {
            let cand = Placed {
                shape: sh.clone(),
                pos: p,
            };
            let better = match &best {
                None => true,
                Some(b) => {
                    let (cr, br) = (cand.hi().x, b.hi().x);
                    cr < br - 1e-9 || (cr <= br + 1e-9 && cand.pos.y < b.pos.y)
                }
            };
            if better {
                best = Some(cand);
            }
        }
    }
    best
}

/// The first item (in index order) that does not fit alone in an empty container `max_len`
/// long: what to name when no search could place everything.
pub(crate) fn unplaceable(ctx: &mut Ctx, max_len: f64) -> Option<usize> {
    (0..ctx.prob.items.len()).find(|&i| place_item(ctx, i, &[], max_len, &mut false).is_none())
}

/// Bottom-left fill of a strip.
pub(crate) fn fill_strip(ctx: &mut Ctx, order: &[usize]) -> Option<State> {
    let mut st = State::default();
    for &i in order {
        let p = place_item(ctx, i, &st.placed, f64::INFINITY, &mut false)?;
        st.items.push(i);
        st.placed.push(p);
    }
    Some(st)
}

/// Bottom-left fill of bins `max_len` long: first bin with room.
pub(crate) fn fill_bins(ctx: &mut Ctx, order: &[usize], max_len: f64) -> Option<Vec<State>> {
    debug_assert!(matches!(ctx.prob.container, Container::Bins { .. }));
    let mut bins: Vec<State> = Vec::new();
    // Area used in each bin: an item larger than what is left cannot fit, so its scan is
    // skipped. A bin where a scan ran out of budget and found no room is closed.
    let room = max_len * ctx.prob.container.height();
    let mut used: Vec<f64> = Vec::new();
    let mut closed: Vec<bool> = Vec::new();
    for &i in order {
        let mut done = false;
        let area = ctx.prob.items[i].area.max(0.0);
        for (k, b) in bins.iter_mut().enumerate() {
            if closed[k] || used[k] + area > room * (1.0 + 1e-9) {
                continue;
            }
            let mut exhausted = false;
            let placed = place_item(ctx, i, &b.placed, max_len, &mut exhausted);
            closed[k] = placed.is_none() && exhausted;
            if let Some(p) = placed {
                used[k] += area;
                b.items.push(i);
                b.placed.push(p);
                done = true;
                break;
            }
        }
        if !done {
            let p = place_item(ctx, i, &[], max_len, &mut false)?;
            used.push(area);
            closed.push(false);
            bins.push(State {
                items: vec![i],
                placed: vec![p],
            });
        }
    }
    Some(bins)
}
