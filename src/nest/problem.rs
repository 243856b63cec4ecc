//! The nesting problem as the optimiser sees it, independent of flatcut's pieces and of the
//! ESICUP files: items (polygons with holes, allowed orientations), a container (a strip of
//! fixed height and free length, or bins of fixed size), the spacing; the search state of one
//! container; [`solve`], which runs the independent searches (one per thread) and keeps the
//! best.
//!
//! Determinism: the searches count their work (segment pairs and pole pairs looked at, see
//! [`super::engine::collide`]) and stop when the budget derived from the time limit is spent,
//! not on the wall clock, so the same seed and thread count give the same layout on any machine
//! and load. [`WORK_PER_SECOND`] converts seconds to work; it was measured on the 2-core
//! development machine with a release build. A wall-clock safety stop at ten times the time
//! limit (plus 5 s) only matters on a machine far slower than that, or in an unoptimised build.

use super::engine::{poles, Orient, Placed, Rng, Shape};
use glam::DVec2;
use std::sync::Arc;
use std::time::Instant;

/// Work units per second of the time limit (see the module docs).
pub const WORK_PER_SECOND: f64 = 5.0e7;

/// Allowed orientations of an item.
#[derive(Debug, Clone, PartialEq)]
pub enum Orients {
    /// A finite set.
    Set(Vec<Orient>),
    /// Any rotation, mirrored too when `mirror`.
    Free { mirror: bool },
}

/// An item to place.
#[derive(Debug, Clone)]
pub struct Item {
    /// Outer ring (counter-clockwise) then holes (clockwise), no repeated point.
    pub rings: Vec<Vec<DVec2>>,
    pub area: f64,
    pub poles: Vec<(DVec2, f64)>,
    pub orients: Orients,
    /// Shapes tried by the construction (for a set: all of them, in order).
    pub shapes: Vec<Arc<Shape>>,
}

impl Item {
    /// Normalises ring orientation, finds the poles and turns the construction shapes.
    pub fn new(mut rings: Vec<Vec<DVec2>>, orients: Orients) -> Item {
        use crate::geom::polygon::signed_area;
        for (k, r) in rings.iter_mut().enumerate() {
            let a = signed_area(r);
            if (k == 0) != (a > 0.0) {
                r.reverse();
            }
        }
        let area = signed_area(&rings[0]) + rings[1..].iter().map(|r| signed_area(r)).sum::<f64>();
        let poles = poles(&rings);
        let cons: Vec<Orient> = match &orients {
            Orients::Set(v) => v.clone(),
            Orients::Free { mirror } => {
                let a = crate::geom::polygon::min_area_rect_angle(&rings[0]).to_degrees();
                let mut v = Vec::new();
                for m in [false, true] {
                    if m && !mirror {
                        continue;
                    }
                    for q in 0..4 {
                        v.push(Orient {
                            deg: (a + 90.0 * q as f64).rem_euclid(360.0),
                            mirror: m,
                        });
                    }
                }
                v
            }
        };
        let shapes = cons
            .iter()
            .map(|o| Arc::new(Shape::new(&rings, &poles, *o)))
            .collect();
        Item {
            rings,
            area,
            poles,
            orients,
            shapes,
        }
    }

    /// A random allowed shape.
    pub fn random_shape(&self, rng: &mut Rng) -> Arc<Shape> {
        match &self.orients {
            Orients::Set(_) => self.shapes[rng.below(self.shapes.len())].clone(),
            Orients::Free { mirror } => {
                let o = Orient {
                    deg: rng.range(0.0, 360.0),
                    mirror: *mirror && rng.f64() < 0.5,
                };
                Arc::new(Shape::new(&self.rings, &self.poles, o))
            }
        }
    }

    /// A shape near `cur`: the same, or (free rotation) turned by a few degrees.
    pub fn nearby_shape(&self, cur: &Arc<Shape>, rng: &mut Rng) -> Arc<Shape> {
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
                        deg: (cur.orient.deg + rng.range(-10.0, 10.0)).rem_euclid(360.0),
                        mirror: cur.orient.mirror,
                    };
                    Arc::new(Shape::new(&self.rings, &self.poles, o))
                }
            }
        }
    }

    /// Smallest length (x extent) over the construction shapes that fit the height.
    pub fn min_length(&self, height: f64) -> Option<f64> {
        self.shapes
            .iter()
            .filter(|s| s.size.y <= height + 1e-9)
            .map(|s| s.size.x)
            .min_by(f64::total_cmp)
    }
}

/// What the items go into.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Container {
    /// Height fixed, length (x) to minimise.
    Strip { height: f64 },
    /// Bins of this size: fewest bins, then the last one as short (in x) as possible.
    Bins { length: f64, height: f64 },
}

impl Container {
    pub fn height(&self) -> f64 {
        match self {
            Container::Strip { height } | Container::Bins { height, .. } => *height,
        }
    }
}

/// A whole problem.
#[derive(Debug, Clone)]
pub struct Problem {
    pub items: Vec<Item>,
    pub container: Container,
    /// Smallest distance between the material of two items.
    pub spacing: f64,
}

/// The items of one container and where they are; `placed[k]` belongs to `items[k]`.
#[derive(Debug, Clone, Default)]
pub struct State {
    pub items: Vec<usize>,
    pub placed: Vec<Placed>,
}

impl State {
    /// Length used: the right end of the rightmost item.
    pub fn extent(&self) -> f64 {
        self.placed.iter().map(|p| p.hi().x).fold(0.0, f64::max)
    }
}

/// Search settings.
#[derive(Debug, Clone, Copy)]
pub struct Config {
    pub seconds: f64,
    pub seed: u64,
    pub threads: usize,
}

/// One search's bookkeeping: its random numbers and its clock.
#[derive(Debug)]
pub struct Ctx<'a> {
    pub prob: &'a Problem,
    pub rng: Rng,
    pub work: u64,
    pub budget: u64,
    deadline: Instant,
}

impl<'a> Ctx<'a> {
    pub fn new(prob: &'a Problem, seed: u64, seconds: f64) -> Ctx<'a> {
        let secs = seconds.max(0.0);
        Ctx {
            prob,
            rng: Rng::new(seed),
            work: 0,
            budget: (secs * WORK_PER_SECOND) as u64,
            deadline: Instant::now() + std::time::Duration::from_secs_f64(10.0 * secs + 5.0),
        }
    }
    /// Budget spent (or, as a safety net only, the wall clock far past the limit).
    pub fn done(&self) -> bool {
        self.work >= self.budget || Instant::now() > self.deadline
    }
    /// Fraction of the budget spent.
    pub fn progress(&self) -> f64 {
        if self.budget == 0 {
            1.0
        } else {
            self.work as f64 / self.budget as f64
        }
    }
}

/// Where an item went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ItemPlacement {
    /// Bin (0 for a strip).
    pub bin: usize,
    pub orient: Orient,
    /// `container point = orient(item point) + translation`.
    pub translation: DVec2,
}

/// A feasible layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// One per item, same order as [`Problem::items`].
    pub placements: Vec<ItemPlacement>,
    /// Bins used (1 for a strip).
    pub bins: usize,
    /// Strip length used, or the length (x) used on the last bin.
    pub length: f64,
    /// Work spent by the search that found it.
    pub work: u64,
}

/// An item that fits the container in no allowed orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unfit {
    pub item: usize,
    pub size: DVec2,
}

/// Check that every item fits the container in some orientation.
pub fn check_fit(prob: &Problem) -> Result<(), Unfit> {
    let h = prob.container.height();
    let max_len = match prob.container {
        Container::Strip { .. } => f64::INFINITY,
        Container::Bins { length, .. } => length,
    };
    for (i, it) in prob.items.iter().enumerate() {
        let fits = |s: &Shape| s.size.y <= h + 1e-9 && s.size.x <= max_len + 1e-9;
        let ok = match &it.orients {
            Orients::Set(_) => it.shapes.iter().any(|s| fits(s)),
            Orients::Free { mirror } => {
                it.shapes.iter().any(|s| fits(s))
                    || (0..360).any(|d| {
                        let o = Orient {
                            deg: d as f64,
                            mirror: *mirror,
                        };
                        fits(&Shape::new(&it.rings, &[], o))
                    })
            }
        };
        if !ok {
            let size = it.shapes.first().map(|s| s.size).unwrap_or_default();
            return Err(Unfit { item: i, size });
        }
    }
    Ok(())
}

/// Run `cfg.threads` independent searches (seeds derived from `cfg.seed`) and keep the best:
/// fewest bins, then shortest length, then the lowest thread.
pub fn solve(prob: &Problem, cfg: &Config) -> Result<Solution, Unfit> {
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
    best.ok_or(Unfit {
        item: 0,
        size: DVec2::ZERO,
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
            let st = super::construct::fill_strip(ctx, &order)?;
            let st = super::improve::optimise_strip(ctx, st, f64::INFINITY);
            vec![st]
        }
        Container::Bins { length, .. } => {
            let sheets = super::construct::fill_bins(ctx, &order, length)?;
            super::improve::optimise_bins(ctx, sheets, length)
        }
    };
    let mut placements = vec![
        ItemPlacement {
            bin: 0,
            orient: Orient {
                deg: 0.0,
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
