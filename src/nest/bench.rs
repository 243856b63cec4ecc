//! The few solver steps that the benchmarks in `benches/nest.rs` time, behind a narrow public
//! entry: a search on a problem ([`Search`]), with its random numbers and work budget; the
//! bottom-left construction of a strip; cutting a slice out of a strip layout; one separator
//! sweep. Nothing here is needed to nest: [`super::nest`] and [`super::esicup::solve`] are the
//! stage's API. The solver's internals stay crate-private.

use super::problem::Problem;
use super::solve::state::{Ctx, State};
use super::solve::{construct, improve, separate};

/// One search: its problem, its random numbers (from `seed`) and its work budget.
#[derive(Debug)]
pub struct Search<'a>(Ctx<'a>);

/// A layout of items in a strip: the items placed so far and where they are.
#[derive(Debug, Clone)]
pub struct StripLayout(State);

impl StripLayout {
    /// Length used: the right end of the rightmost item.
    pub fn extent(&self) -> f64 {
        self.0.extent()
    }
}

impl<'a> Search<'a> {
    /// A search on `problem` with the random numbers of `seed` and a budget of `seconds`.
    pub fn new(problem: &'a Problem, seed: u64, seconds: f64) -> Search<'a> {
        Search(Ctx::new(problem, seed, seconds))
    }

    /// Bottom-left fill of the strip with the items in `order` (indices into the problem's
    /// items); `None` when an item does not fit.
    pub fn fill_strip(&mut self, order: &[usize]) -> Option<StripLayout> {
        construct::fill_strip(&mut self.0, order).map(StripLayout)
    }

    /// `layout` (`len` long) made `new_len` long by cutting a slice out at a random x and
    /// moving the items right of it left; `None` if an item cannot fit.
    pub fn shrink(&mut self, layout: &StripLayout, len: f64, new_len: f64) -> Option<StripLayout> {
        improve::shrink(&mut self.0, &layout.0, len, new_len).map(StripLayout)
    }

    /// One separator sweep in a strip `len` long: every overlapping item moves once, then the
    /// weights are updated; returns the overlap left.
    pub fn sweep(&mut self, layout: &mut StripLayout, len: f64) -> f64 {
        separate::sweep(&mut self.0, &mut layout.0, len)
    }
}
