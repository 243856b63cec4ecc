//! A binary-heap entry that pops the smallest key first, ties broken on the smaller id: the
//! priority queue of every Dijkstra search and region growing over mesh faces and vertices, so
//! that equal distances are settled in index order and results are deterministic.

use std::cmp::Ordering;

/// Entry of a [`std::collections::BinaryHeap`] used as a min-queue: smallest `key` first,
/// then smallest `id`; `data` rides along and takes no part in the order.
#[derive(Debug, Clone, Copy)]
pub struct Lowest<T = ()> {
    pub key: f64,
    pub id: usize,
    pub data: T,
}

impl Lowest {
    /// An entry with no data.
    pub fn new(key: f64, id: usize) -> Self {
        Lowest { key, id, data: () }
    }
}

impl<T> PartialEq for Lowest<T> {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl<T> Eq for Lowest<T> {}
impl<T> PartialOrd for Lowest<T> {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl<T> Ord for Lowest<T> {
    fn cmp(&self, o: &Self) -> Ordering {
        o.key.total_cmp(&self.key).then_with(|| o.id.cmp(&self.id))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BinaryHeap;

    #[test]
    fn smallest_key_then_smallest_id() {
        let mut h = BinaryHeap::new();
        for (k, i) in [(2.0, 0), (1.0, 5), (1.0, 3), (0.5, 9)] {
            h.push(Lowest::new(k, i));
        }
        let order: Vec<usize> = std::iter::from_fn(|| h.pop().map(|e| e.id)).collect();
        assert_eq!(order, vec![9, 3, 5, 0]);
    }
}
