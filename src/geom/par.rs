//! A parallel map whose result does not depend on the number of threads: independent jobs
//! shared out among the machine's cores (`std::thread::scope`, no pool), largest first so
//! that one big job does not start last, each result put back in the job's own slot.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// `f` applied to every item, on up to [`std::thread::available_parallelism`] threads, the
/// items started in decreasing `size` (ties in their order); the results in the items' order.
/// A panic in `f` is raised again here.
pub fn map_largest_first<T, R, F>(items: Vec<T>, size: &[usize], f: F) -> Vec<R>
where
    T: Send,
    R: Send,
    F: Fn(T) -> R + Sync,
{
    let n = items.len();
    let threads = std::thread::available_parallelism()
        .map_or(1, |p| p.get())
        .min(n);
    if threads <= 1 {
        return items.into_iter().map(f).collect();
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(size.get(i).copied().unwrap_or(0)));
    let jobs: Vec<Mutex<Option<T>>> = items.into_iter().map(|t| Mutex::new(Some(t))).collect();
    let slots: Vec<Mutex<Option<R>>> = (0..n).map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&i) = order.get(k) else { return };
                    let job = jobs[i].lock().unwrap_or_else(|e| e.into_inner()).take();
                    if let Some(job) = job {
                        let r = f(job);
                        *slots[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
                    }
                })
            })
            .collect();
        for w in workers {
            if let Err(p) = w.join() {
                std::panic::resume_unwind(p);
            }
        }
    });
    slots
        .into_iter()
        .map(|m| {
            m.into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .expect("every job ran: the workers took every index")
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_back_in_the_items_order() {
        let items: Vec<u64> = (0..50).collect();
        let size: Vec<usize> = (0..50).map(|i| (i * 37) % 11).collect();
        let out = map_largest_first(items, &size, |x| {
            // Uneven work, so that the threads finish out of order.
            let busy = (0..(x % 7) * 1000).fold(0u64, |a, b| a.wrapping_add(b % 3));
            (x * x, busy)
        });
        let squares: Vec<u64> = out.iter().map(|r| r.0).collect();
        assert_eq!(squares, (0..50u64).map(|x| x * x).collect::<Vec<_>>());
    }

    #[test]
    fn no_items_no_threads() {
        let out: Vec<u8> = map_largest_first(Vec::<u8>::new(), &[], |x| x);
        assert!(out.is_empty());
    }
}
