//! Fork–join parallelism whose results do not depend on the number of threads: [`join`] runs
//! two closures, the second on a scoped thread when one of the process's spare threads is
//! free (one fewer than the machine's cores, shared by every caller, nested calls included),
//! else after the first on this one; [`speculate`] runs the second only when a spare thread
//! is free, and [`first`] tries candidates two at a time with it; [`map`] splits a list of
//! independent jobs into halves of about equal weight and joins them, so a job may itself
//! fork (a chart whose halves are laid in parallel). Results always come back in the jobs'
//! order.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

/// Threads that may run besides the callers' own (cores − 1), taken and given back by
/// [`join`].
fn spare() -> &'static AtomicUsize {
    static SPARE: OnceLock<AtomicUsize> = OnceLock::new();
    SPARE.get_or_init(|| {
        let cores = std::thread::available_parallelism().map_or(1, |p| p.get());
        AtomicUsize::new(cores.saturating_sub(1))
    })
}

/// Take a spare thread if one is free.
fn take() -> bool {
    spare()
        .fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| n.checked_sub(1))
        .is_ok()
}

/// Gives a spare thread back when dropped (also when the job panics).
struct Token;

impl Drop for Token {
    fn drop(&mut self) {
        spare().fetch_add(1, Ordering::AcqRel);
    }
}

/// `(a(), b())`, `b` on another thread when a spare one is free. A panic in either is raised
/// again here.
pub fn join<A, B, FA, FB>(a: FA, b: FB) -> (A, B)
where
    A: Send,
    B: Send,
    FA: FnOnce() -> A + Send,
    FB: FnOnce() -> B + Send,
{
    if !take() {
        let ra = a();
        return (ra, b());
    }
    beside(a, b)
}

/// `(a(), b())`, `b` on a scoped thread holding the spare thread [`take`]n for it (given back
/// when it ends, also when it panics). A panic in either is raised again here.
fn beside<A, B, FA, FB>(a: FA, b: FB) -> (A, B)
where
    A: Send,
    B: Send,
    FA: FnOnce() -> A + Send,
    FB: FnOnce() -> B + Send,
{
    std::thread::scope(|s| {
        let hb = s.spawn(move || {
            let _token = Token;
            b()
        });
        let ra = a();
        let rb = hb.join().unwrap_or_else(|p| std::panic::resume_unwind(p));
        (ra, rb)
    })
}

/// `(a(), Some(b()))` with `b` on another thread when a spare one is free, else `(a(), None)`
/// without running `b`: for work that is only worth doing beside other work (a second
/// candidate tried while the first is, its result used only when the first fails).
pub fn speculate<A, B, FA, FB>(a: FA, b: FB) -> (A, Option<B>)
where
    A: Send,
    B: Send,
    FA: FnOnce() -> A + Send,
    FB: FnOnce() -> B + Send,
{
    if !take() {
        return (a(), None);
    }
    let (ra, rb) = beside(a, b);
    (ra, Some(rb))
}

/// The first item, in order, for which `f` gives something, and what it gave: the items are
/// tried two at a time where a spare thread is free ([`speculate`]), the second's result used
/// only when the first gives nothing, so the answer is the one trying them in turn finds.
pub fn first<T, R, F>(items: &[T], f: F) -> Option<(usize, R)>
where
    T: Sync,
    R: Send,
    F: Fn(&T) -> Option<R> + Sync,
{
    let mut i = 0;
    while let Some(x) = items.get(i) {
        let next = items.get(i + 1);
        let (here, beside) = speculate(|| f(x), || next.and_then(&f));
        if let Some(r) = here {
            return Some((i, r));
        }
        match beside {
            Some(Some(r)) => return Some((i + 1, r)),
            Some(None) => i += 2,
            None => i += 1,
        }
    }
    None
}

/// `f` applied to every item, the list halved by `weight` (each half about half the total)
/// and the halves [`join`]ed; the results in the items' order.
pub fn map<T, R, F>(items: Vec<T>, weight: &[usize], f: &F) -> Vec<R>
where
    T: Send,
    R: Send,
    F: Fn(T) -> R + Sync,
{
    let w: Vec<usize> = (0..items.len())
        .map(|i| weight.get(i).copied().unwrap_or(1).max(1))
        .collect();
    map_weighted(items, &w, f)
}

fn map_weighted<T, R, F>(mut items: Vec<T>, w: &[usize], f: &F) -> Vec<R>
where
    T: Send,
    R: Send,
    F: Fn(T) -> R + Sync,
{
    if items.len() <= 1 {
        return items.into_iter().map(f).collect();
    }
    // The split that leaves the two halves' weights nearest each other (each non-empty).
    let total: usize = w.iter().sum();
    let (mut best, mut acc, mut best_gap) = (1, 0usize, usize::MAX);
    for (k, &x) in w.iter().enumerate().take(w.len() - 1) {
        acc += x;
        let gap = acc.abs_diff(total - acc);
        if gap < best_gap {
            (best, best_gap) = (k + 1, gap);
        }
    }
    let right = items.split_off(best);
    let (wl, wr) = w.split_at(best);
    let (mut l, r) = join(|| map_weighted(items, wl, f), || map_weighted(right, wr, f));
    l.extend(r);
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_back_in_the_items_order() {
        let items: Vec<u64> = (0..50).collect();
        let weight: Vec<usize> = (0..50).map(|i| (i * 37) % 11).collect();
        let out = map(items, &weight, &|x: u64| {
            // Uneven work, so that the threads finish out of order; nested forks too.
            let busy = (0..(x % 7) * 1000).fold(0u64, |a, b| a.wrapping_add(b % 3));
            let (p, q) = join(|| x * x, || busy);
            (p, q)
        });
        let squares: Vec<u64> = out.iter().map(|r| r.0).collect();
        assert_eq!(squares, (0..50u64).map(|x| x * x).collect::<Vec<_>>());
    }

    #[test]
    fn speculation_runs_beside_or_not_at_all() {
        let ran = std::sync::atomic::AtomicBool::new(false);
        let (a, b) = speculate(
            || 1,
            || {
                ran.store(true, Ordering::SeqCst);
                2
            },
        );
        assert_eq!(a, 1);
        // Run on a spare thread (and then its result is back) or not at all.
        assert_eq!(b.is_some(), ran.load(Ordering::SeqCst));
        if std::thread::available_parallelism().map_or(1, |p| p.get()) == 1 {
            assert_eq!(b, None);
        }
    }

    #[test]
    fn the_first_found_is_the_first_in_order() {
        let items: Vec<u32> = (0..9).collect();
        for want in 0..9u32 {
            // Every item from `want` on gives something: the answer is `want` whichever ran.
            let got = first(&items, |&x| (x >= want).then_some(x * 10));
            assert_eq!(got, Some((want as usize, want * 10)));
        }
        assert_eq!(first(&items, |_| None::<u32>), None);
        assert_eq!(first(&[] as &[u32], |&x| Some(x)), None);
    }

    #[test]
    fn no_items_no_threads() {
        let out: Vec<u8> = map(Vec::<u8>::new(), &[], &|x| x);
        assert!(out.is_empty());
    }

    #[test]
    fn a_panic_comes_back_to_the_caller() {
        let r = std::panic::catch_unwind(|| join(|| 1, || -> u8 { panic!("boom") }));
        assert!(r.is_err());
        // The spare thread was given back: a later join can still fork.
        assert_eq!(join(|| 2, || 3), (2, 3));
    }
}
