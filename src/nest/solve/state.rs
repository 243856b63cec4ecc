//! The state of one search: the items of one container and where they are ([`State`]), and
//! the search's bookkeeping ([`Ctx`]): its problem, its random numbers and its clock.
//!
//! Determinism: the searches count their work (segment pairs and pole pairs looked at, see
//! [`crate::nest::collision::collide`]) and stop when the budget derived from the time limit
//! is spent, not on the wall clock, so the same seed and thread count give the same layout on
//! any machine and load. [`WORK_PER_SECOND`] converts seconds to work; it was measured on the
//! 2-core development machine with a release build. A wall-clock safety stop at ten times the
//! time limit (plus 5 s) only matters on a machine far slower than that, or in an unoptimised
//! build.

use crate::geom::rng::Rng;
use crate::nest::collision::Placed;
use crate::nest::problem::Problem;
use std::time::Instant;

/// Work units per second of the time limit (see the module docs).
pub(crate) const WORK_PER_SECOND: f64 = 5.0e7;

/// The items of one container and where they are; `placed[k]` belongs to `items[k]`.
#[derive(Debug, Clone, Default)]
pub(crate) struct State {
    pub items: Vec<usize>,
    pub placed: Vec<Placed>,
}

impl State {
    /// Length used: the right end of the rightmost item.
    pub(crate) fn extent(&self) -> f64 {
        self.placed.iter().map(|p| p.hi().x).fold(0.0, f64::max)
    }
}

/// One search's bookkeeping: its random numbers and its clock.
#[derive(Debug)]
pub(crate) struct Ctx<'a> {
    pub prob: &'a Problem,
    pub rng: Rng,
    pub work: u64,
    pub budget: u64,
    deadline: Instant,
}

impl<'a> Ctx<'a> {
    pub(crate) fn new(prob: &'a Problem, seed: u64, seconds: f64) -> Ctx<'a> {
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
    pub(crate) fn done(&self) -> bool {
        self.work >= self.budget || Instant::now() > self.deadline
    }
    /// Fraction of the budget spent.
    pub(crate) fn progress(&self) -> f64 {
        if self.budget == 0 {
            1.0
        } else {
            self.work as f64 / self.budget as f64
        }
    }
}
