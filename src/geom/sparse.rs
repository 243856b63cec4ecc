//! Sparse matrices for the crate's Cholesky solves (faer): a compressed-column matrix
//! assembled from (row, column, value) triplets.
//!
//! Choices: the triplets are bucketed by column (a counting sort, linear in their number),
//! each column sorted by row and its repeated entries summed in the order given, so the
//! values do not depend on anything but the input (faer's own constructor sorts every triplet
//! with a comparison sort).

use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};

/// The `n` × `n` matrix with the sum of the `triplets`' values at each (row, column) they
/// name; `None` when an index is `n` or more.
pub fn from_triplets(
    n: usize,
    triplets: &[Triplet<usize, usize, f64>],
) -> Option<SparseColMat<usize, f64>> {
    if triplets.iter().any(|t| t.row >= n || t.col >= n) {
        return None;
    }
    // Bucket by column, keeping the triplets' order within a column.
    let mut start = vec![0usize; n + 1];
    for t in triplets {
        start[t.col + 1] += 1;
    }
    for c in 0..n {
        start[c + 1] += start[c];
    }
    let mut next = start.clone();
    let mut entries = vec![(0usize, 0.0f64); triplets.len()];
    for t in triplets {
        entries[next[t.col]] = (t.row, t.val);
        next[t.col] += 1;
    }
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut row_idx = Vec::with_capacity(triplets.len());
    let mut val = Vec::with_capacity(triplets.len());
    col_ptr.push(0);
    for c in 0..n {
        let column = &mut entries[start[c]..start[c + 1]];
        // Stable: equal rows keep their order, so they are summed as given.
        column.sort_by_key(|e| e.0);
        for &(r, v) in column.iter() {
            if row_idx.len() > col_ptr[c] && row_idx.last() == Some(&r) {
                *val.last_mut()? += v;
            } else {
                row_idx.push(r);
                val.push(v);
            }
        }
        col_ptr.push(row_idx.len());
    }
    let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    Some(SparseColMat::new(symbolic, val))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triplets_are_summed_where_they_repeat_and_laid_out_by_column() {
        let t = |r, c, v| Triplet::new(r, c, v);
        let trip = [
            t(2, 0, 1.0),
            t(0, 0, 4.0),
            t(2, 0, 0.5),
            t(1, 1, 3.0),
            t(2, 2, 5.0),
            t(2, 1, -1.0),
        ];
        let m = from_triplets(3, &trip).unwrap();
        let faer_m = SparseColMat::<usize, f64>::try_new_from_triplets(3, 3, &trip).unwrap();
        assert_eq!(m.symbolic().col_ptr(), faer_m.symbolic().col_ptr());
        assert_eq!(m.symbolic().row_idx(), faer_m.symbolic().row_idx());
        assert_eq!(m.val(), faer_m.val());
        assert_eq!(m.val(), &[4.0, 1.5, 3.0, -1.0, 5.0]);
        assert!(from_triplets(2, &trip).is_none(), "row 2 in a 2 x 2 matrix");
        assert_eq!(from_triplets(0, &[]).map(|m| m.val().len()), Some(0));
    }
}
