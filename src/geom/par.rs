//! Fork–join parallelism whose results do not depend on the number of threads, on the
//! work-stealing pool of `rayon-core` (one thread per core): [`join`] runs two closures, the
//! second taken by whichever thread of the pool is idle (else run after the first on this
//! one), nested calls included, so a thread that finishes its share early takes work forked
//! deeper in the other's; [`speculate`] runs the second only when an idle thread takes it
//! while the first runs, and [`first`] tries candidates two at a time with it; [`map`] splits
//! a list of independent jobs into halves of about equal weight and joins them, so a job may
//! itself fork (a chart whose halves are laid in parallel). Results always come back in the
//! jobs' order.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

/// Stack of each pool thread: the main thread's usual 8 MiB, since the jobs run what the
/// main thread would run alone (the default is 2 MiB).
const STACK_BYTES: usize = 8 << 20;

/// The pool, made on first use with [`STACK_BYTES`] (one made elsewhere first is kept).
fn pool() {
    static MADE: Once = Once::new();
    MADE.call_once(|| {
        let _ = rayon_core::ThreadPoolBuilder::new()
            .stack_size(STACK_BYTES)
            .build_global();
    });
}

/// `(a(), b())`, `b` taken by an idle thread of the pool when one is free, else run after
/// `a` on this one. A panic in either is raised again here.
pub fn join<A, B, FA, FB>(a: FA, b: FB) -> (A, B)
where
    A: Send,
    B: Send,
    FA: FnOnce() -> A + Send,
    FB: FnOnce() -> B + Send,
{
    pool();
    rayon_core::join(a, b)
}

/// `f()` run by a thread of the pool, so that the forks inside it are the pool's own (a fork
/// from outside the pool waits for a thread of it to wake and take the whole join).
pub fn within<R: Send, F: FnOnce() -> R + Send>(f: F) -> R {
    pool();
    if rayon_core::current_thread_index().is_some() {
        return f();
    }
    rayon_core::join(f, || ()).0
}

/// `(a(), Some(b()))` when an idle thread takes `b` while `a` runs, else `(a(), None)`
/// without running `b`: for work that is only worth doing beside other work (a second
/// candidate tried while the first is, its result used only when the first fails).
pub fn speculate<A, B, FA, FB>(a: FA, b: FB) -> (A, Option<B>)
where
    A: Send,
    B: Send,
    FA: FnOnce() -> A + Send,
    FB: FnOnce() -> B + Send,
{
    pool();
    let done = AtomicBool::new(false);
    rayon_core::join(
        || {
            let r = a();
            done.store(true, Ordering::Release);
            r
        },
        || (!done.load(Ordering::Acquire)).then(b),
    )
}

/// The first item, in order, for which `f` gives something, and what it gave: the items are
/// tried two at a time where a thread is idle ([`speculate`]), the second's result used
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
        // Run on an idle thread (and then its result is back) or not at all.
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
    fn within_runs_on_a_thread_of_the_pool_and_nests() {
        let (on_pool, inner) = within(|| {
            (
                rayon_core::current_thread_index().is_some(),
                within(|| join(|| 4, || 5)),
            )
        });
        assert!(on_pool);
        assert_eq!(inner, (4, 5));
        let r = std::panic::catch_unwind(|| within(|| -> u8 { panic!("boom") }));
        assert!(r.is_err());
    }

    #[test]
    fn a_panic_comes_back_to_the_caller() {
        let r = std::panic::catch_unwind(|| join(|| 1, || -> u8 { panic!("boom") }));
        assert!(r.is_err());
        // The pool is still there: a later join still runs both.
        assert_eq!(join(|| 2, || 3), (2, 3));
    }
}
