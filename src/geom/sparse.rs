//! Sparse matrices for the crate's Cholesky solves (faer): a compressed-column matrix
//! assembled from (row, column, value) triplets, and a factorisation kept for every system of
//! one pattern ([`Cholesky`]).
//!
//! Choices: the triplets are bucketed by row, then by column (two stable counting sorts, linear
//! in their number), so each column is sorted by row and its repeated entries are summed in the
//! order given; the values do not depend on anything but the input (faer's own constructor
//! sorts every triplet with a comparison sort). A solver that assembles systems of one pattern
//! again and again (Newton steps, one chart laid twice) keeps the [`Pattern`]: where each
//! triplet's value goes, so the next system of that pattern is filled in one pass, its values
//! summed in the same order and so the same to the bit. Its [`Cholesky`] keeps the ordering and
//! symbolic factorisation (faer's defaults, as its `Llt` solver makes them) with the numeric
//! factor's storage and work space, so a Newton step allocates nothing for its solve. Where
//! faer's factor is simplicial (up-looking, row by row), it also keeps what that factorisation
//! derives from the pattern alone for every system: the permuted upper triangle and each row's
//! elimination-tree reach, in faer's order. The numeric factorisation is then faer's loop, the
//! same operations in the same order (the same factor to the bit), without the permutation and
//! the tree walks; a supernodal factor is left to faer.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::utils::permute_self_adjoint_to_unsorted;
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat, Triplet};
use faer::{Conj, MatMut, Par, Side};
use std::sync::Arc;

/// The `n` × `n` matrix with the sum of the `triplets`' values at each (row, column) they
/// name; `None` when an index is `n` or more.
pub fn from_triplets(
    n: usize,
    triplets: &[Triplet<usize, usize, f64>],
) -> Option<SparseColMat<usize, f64>> {
    Pattern::new(n, triplets).map(|p| p.matrix(triplets))
}

/// Where the values of a list of triplets go in their compressed-column matrix (see the
/// module doc): built from one list, it fills any list with the same rows and columns in the
/// same order.
#[derive(Clone)]
pub struct Pattern {
    n: usize,
    /// Each triplet's (row, column), in order.
    keys: Vec<(usize, usize)>,
    /// Each triplet's index into the matrix's values.
    slot: Vec<usize>,
    symbolic: SymbolicSparseColMat<usize>,
}

impl Pattern {
    /// The pattern of `triplets` in an `n` × `n` matrix; `None` when an index is `n` or more.
    pub fn new(n: usize, triplets: &[Triplet<usize, usize, f64>]) -> Option<Pattern> {
        if triplets.iter().any(|t| t.row >= n || t.col >= n) {
            return None;
        }
        // Two stable counting sorts: by row, then that order by column. Each column then
        // holds its entries by row, equal ones in the triplets' order (summed as given).
        let mut by_row = vec![0usize; n + 1];
        for t in triplets {
            by_row[t.row + 1] += 1;
        }
        for r in 0..n {
            by_row[r + 1] += by_row[r];
        }
        let mut rows = vec![0usize; triplets.len()];
        for (i, t) in triplets.iter().enumerate() {
            rows[by_row[t.row]] = i;
            by_row[t.row] += 1;
        }
        let mut start = vec![0usize; n + 1];
        for t in triplets {
            start[t.col + 1] += 1;
        }
        for c in 0..n {
            start[c + 1] += start[c];
        }
        let mut next = start.clone();
        let mut entries = vec![0usize; triplets.len()];
        for &i in &rows {
            let c = triplets[i].col;
            entries[next[c]] = i;
            next[c] += 1;
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx: Vec<usize> = Vec::with_capacity(triplets.len());
        let mut slot = vec![0usize; triplets.len()];
        col_ptr.push(0);
        for c in 0..n {
            for &i in &entries[start[c]..start[c + 1]] {
                let r = triplets[i].row;
                if row_idx.len() == col_ptr[c] || row_idx.last() != Some(&r) {
                    row_idx.push(r);
                }
                slot[i] = row_idx.len() - 1;
            }
            col_ptr.push(row_idx.len());
        }
        Some(Pattern {
            n,
            keys: triplets.iter().map(|t| (t.row, t.col)).collect(),
            slot,
            symbolic: SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
        })
    }

    /// The matrix's rows and columns.
    pub fn symbolic(&self) -> &SymbolicSparseColMat<usize> {
        &self.symbolic
    }

    /// Whether `triplets` name the rows and columns this pattern was built from, in order.
    pub fn fits(&self, n: usize, triplets: &[Triplet<usize, usize, f64>]) -> bool {
        n == self.n
            && triplets.len() == self.keys.len()
            && triplets
                .iter()
                .zip(&self.keys)
                .all(|(t, &(r, c))| t.row == r && t.col == c)
    }

    /// The matrix of `triplets`, which must [`Pattern::fits`] this pattern.
    pub fn matrix(&self, triplets: &[Triplet<usize, usize, f64>]) -> SparseColMat<usize, f64> {
        let mut val = vec![0.0f64; self.symbolic.row_idx().len()];
        let mut set = vec![false; val.len()];
        for (t, &k) in triplets.iter().zip(&self.slot) {
            // The first value of an entry is taken as it is (so −0.0 stays −0.0), the
            // next ones added in order.
            if set[k] {
                val[k] += t.val;
            } else {
                val[k] = t.val;
                set[k] = true;
            }
        }
        SparseColMat::new(self.symbolic.clone(), val)
    }
}

/// A sparse Cholesky factorisation kept for systems of one [`Pattern`]: the fill-reducing
/// ordering and symbolic factorisation made once, the numeric factor and the work space
/// reused by every system factorised with it. A copy for another pattern of the same
/// structure ([`Cholesky::for_pattern`]) shares the pattern-only part and has its own numeric
/// factor and work space: one symbolic factorisation serves every system of one structure
/// (the attempts of a chart's seam matching).
pub struct Cholesky {
    shared: Arc<Symbolic>,
    values: Vec<f64>,
    scratch: MemBuffer,
    /// Work space of [`Plan::factor`]: the dense row being eliminated, and each column's next
    /// free slot.
    x: Vec<f64>,
    next: Vec<usize>,
}

/// What a [`Cholesky`] derives from its pattern alone: faer's ordering and symbolic
/// factorisation, the [`Plan`] of a simplicial factor, and the structure it was made for.
struct Symbolic {
    symbolic: SymbolicCholesky<usize>,
    plan: Option<Plan>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

/// The pattern-only part of faer's simplicial up-looking LLᵀ, made once per pattern: the
/// permuted upper triangle (each entry's row and the index of its value in the matrix given)
/// and each row's elimination-tree reach, both in the order faer's own factorisation takes
/// them, so [`Plan::factor`] performs faer's arithmetic in faer's order (the same factor to
/// the bit) without permuting the matrix and walking the tree for every system.
struct Plan {
    a_ptr: Vec<usize>,
    a_row: Vec<usize>,
    a_src: Vec<usize>,
    reach_ptr: Vec<usize>,
    reach: Vec<usize>,
    l_ptr: Vec<usize>,
    l_row: Vec<usize>,
}

impl Plan {
    /// The plan of `pattern` under `symbolic`; `None` where faer's factor is supernodal or
    /// unpermuted (faer factorises those itself).
    fn new(pattern: &Pattern, symbolic: &SymbolicCholesky<usize>) -> Option<Plan> {
        let SymbolicCholeskyRaw::Simplicial(s) = symbolic.raw() else {
            return None;
        };
        let perm = symbolic.perm()?;
        let n = pattern.n;
        let nnz = pattern.symbolic.row_idx().len();
        // The matrix with each entry's own index as its value, permuted as faer permutes.
        let index: Vec<f64> = (0..nnz).map(|i| i as f64).collect();
        let a = SparseColMatRef::new(pattern.symbolic.as_ref(), &index);
        let mut val = vec![0.0f64; nnz];
        let mut col_ptr = vec![0usize; n + 1];
        let mut row_idx = vec![0usize; nnz];
        let mut buf = MemBuffer::try_new(StackReq::new::<usize>(n)).ok()?;
        let permuted = permute_self_adjoint_to_unsorted(
            &mut val,
            &mut col_ptr,
            &mut row_idx,
            a,
            perm,
            Side::Lower,
            Side::Upper,
            MemStack::new(&mut buf),
        );
        let (a_ptr, a_row) = (
            permuted.symbolic().col_ptr().to_vec(),
            permuted.symbolic().row_idx().to_vec(),
        );
        let a_src: Vec<usize> = permuted.val().iter().map(|&v| v as usize).collect();
        let (l_ptr, l_row) = (s.col_ptr().to_vec(), s.row_idx().to_vec());
        // The elimination tree: each column's first row below the diagonal.
        let parent: Vec<usize> = (0..n)
            .map(|j| {
                if l_ptr[j] + 1 < l_ptr[j + 1] {
                    l_row[l_ptr[j] + 1]
                } else {
                    usize::MAX
                }
            })
            .collect();
        // Each row's reach: the paths up the tree from the row's entries left of the
        // diagonal, the later paths in front.
        let mut visited = vec![usize::MAX; n];
        let mut stack = vec![0usize; n];
        let mut reach_ptr = Vec::with_capacity(n + 1);
        let mut reach = Vec::with_capacity(l_row.len().saturating_sub(n));
        reach_ptr.push(0);
        for k in 0..n {
            let mut top = n;
            visited[k] = k;
            for &i0 in &a_row[a_ptr[k]..a_ptr[k + 1]] {
                if i0 >= k {
                    continue;
                }
                let (mut i, mut len) = (i0, 0);
                while visited[i] != k {
                    stack[len] = i;
                    len += 1;
                    visited[i] = k;
                    i = parent[i];
                    if i >= n {
                        return None;
                    }
                }
                stack.copy_within(..len, top - len);
                top -= len;
            }
            reach.extend_from_slice(&stack[top..]);
            reach_ptr.push(reach.len());
        }
        Some(Plan {
            a_ptr,
            a_row,
            a_src,
            reach_ptr,
            reach,
            l_ptr,
            l_row,
        })
    }

    /// Faer's simplicial up-looking LLᵀ of the matrix with values `a` (of the pattern this
    /// plan was made for) into `l`; false at a pivot that is not positive, or where `a` or
    /// `l` is not of this plan's size.
    fn factor(&self, a: &[f64], l: &mut [f64], x: &mut [f64], next: &mut [usize]) -> bool {
        let n = next.len();
        if a.len() != self.a_src.len() || l.len() != self.l_row.len() || x.len() != n {
            return false;
        }
        x.iter_mut().for_each(|v| *v = 0.0);
        next.copy_from_slice(&self.l_ptr[..n]);
        for k in 0..n {
            for p in self.a_ptr[k]..self.a_ptr[k + 1] {
                x[self.a_row[p]] += a[self.a_src[p]];
            }
            let mut d = x[k];
            x[k] = 0.0;
            for &j in &self.reach[self.reach_ptr[k]..self.reach_ptr[k + 1]] {
                let j_start = self.l_ptr[j];
                let row = next[j] + 1;
                next[j] = row;
                let xj = x[j];
                x[j] = 0.0;
                let dj = 1.0 / l[j_start];
                let lkj = xj * dj;
                let xj = lkj;
                for p in j_start + 1..row {
                    x[self.l_row[p]] -= l[p] * xj;
                }
                d -= lkj * xj;
                l[row] = lkj;
            }
            // Not positive, or NaN.
            if d.is_nan() || d <= 0.0 {
                return false;
            }
            l[self.l_ptr[k]] = d.sqrt();
        }
        true
    }
}

impl Cholesky {
    /// The symbolic factorisation of `pattern`'s lower triangle; `None` where faer cannot
    /// order it (out of memory, an index overflow).
    pub fn new(pattern: &Pattern) -> Option<Cholesky> {
        let symbolic = factorize_symbolic_cholesky(
            pattern.symbolic().as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .ok()?;
        let plan = Plan::new(pattern, &symbolic);
        Cholesky::from_shared(Arc::new(Symbolic {
            symbolic,
            plan,
            col_ptr: pattern.symbolic.col_ptr().to_vec(),
            row_idx: pattern.symbolic.row_idx().to_vec(),
        }))
    }

    /// A factorisation of the pattern-only part `shared`, with its own numeric factor and
    /// work space; `None` where these cannot be allocated.
    fn from_shared(shared: Arc<Symbolic>) -> Option<Cholesky> {
        let symbolic = &shared.symbolic;
        let req = symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(2, Par::Seq));
        let scratch = MemBuffer::try_new(req).ok()?;
        let n = symbolic.nrows();
        Some(Cholesky {
            values: vec![0.0; symbolic.len_val()],
            x: vec![0.0; n],
            next: vec![0; n],
            scratch,
            shared,
        })
    }

    /// A factorisation for `pattern` made from this one's symbolic part where `pattern` has
    /// the same structure (the same rows in the same columns), else anew ([`Cholesky::new`]).
    pub fn for_pattern(&self, pattern: &Pattern) -> Option<Cholesky> {
        let s = &self.shared;
        if pattern.symbolic.col_ptr() == s.col_ptr && pattern.symbolic.row_idx() == s.row_idx {
            Cholesky::from_shared(s.clone())
        } else {
            Cholesky::new(pattern)
        }
    }

    /// Factorise `a` (of the pattern this was made for, its lower triangle given); false
    /// where it is not numerically positive definite.
    pub fn factor(&mut self, a: &SparseColMat<usize, f64>) -> bool {
        if let Some(plan) = &self.shared.plan {
            return plan.factor(a.val(), &mut self.values, &mut self.x, &mut self.next);
        }
        self.shared
            .symbolic
            .factorize_numeric_llt(
                &mut self.values,
                a.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.scratch),
                Default::default(),
            )
            .is_ok()
    }

    /// Solve the last factorised system in place for one or two right-hand sides: `x` holds
    /// them one after the other (`cols` of them), then the solutions; false (and `x` as it
    /// was) when `x` is not `cols` times the system's size.
    pub fn solve(&mut self, x: &mut [f64], cols: usize) -> bool {
        let n = self.shared.symbolic.nrows();
        if !(1..=2).contains(&cols) || x.len() != n * cols {
            return false;
        }
        let llt = LltRef::new(&self.shared.symbolic, &self.values);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, cols),
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
        true
    }
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

    #[test]
    fn a_pattern_fills_new_values_as_a_fresh_assembly_would() {
        let t = |r, c, v| Triplet::new(r, c, v);
        let trip = [
            t(2, 0, 1.0),
            t(0, 0, 4.0),
            t(2, 0, 0.5),
            t(1, 1, 3.0),
            t(2, 1, -1.0),
        ];
        let p = Pattern::new(3, &trip).unwrap();
        let again = [
            t(2, 0, 0.1),
            t(0, 0, 0.2),
            t(2, 0, 0.7),
            t(1, 1, -0.0),
            t(2, 1, 9.0),
        ];
        assert!(p.fits(3, &again));
        let (a, b) = (p.matrix(&again), from_triplets(3, &again).unwrap());
        assert_eq!(a.symbolic().col_ptr(), b.symbolic().col_ptr());
        assert_eq!(a.symbolic().row_idx(), b.symbolic().row_idx());
        let bits = |m: &SparseColMat<usize, f64>| -> Vec<u64> {
            m.val().iter().map(|x| x.to_bits()).collect()
        };
        assert_eq!(bits(&a), bits(&b));
        assert_eq!(a.val(), &[0.2, 0.1 + 0.7, -0.0, 9.0]);
        // Another order, another column, another size: does not fit.
        assert!(!p.fits(3, &[again[1], again[0], again[2], again[3], again[4]]));
        assert!(!p.fits(3, &again[..4]));
        assert!(!p.fits(4, &again));
    }

    #[test]
    fn the_kept_plan_factorises_as_faer_does_to_the_bit() {
        // A 12 x 9 grid's Laplacian with uneven weights plus a diagonal (lower triangle),
        // with repeated entries, as the solvers assemble theirs.
        let (w, h) = (12usize, 9usize);
        let n = w * h;
        let system = |k: f64| -> Vec<Triplet<usize, usize, f64>> {
            let mut trip = Vec::new();
            for y in 0..h {
                for x in 0..w {
                    let i = y * w + x;
                    trip.push(Triplet::new(i, i, 0.1 + k * (i % 7) as f64 * 0.01));
                    for j in [(x + 1 < w).then(|| i + 1), (y + 1 < h).then(|| i + w)]
                        .into_iter()
                        .flatten()
                    {
                        let c = 1.0 + ((i * 31 + j * 17) % 13) as f64 / (3.0 + k);
                        trip.push(Triplet::new(j, i, -c));
                        trip.push(Triplet::new(i, i, c));
                        trip.push(Triplet::new(j, j, c));
                    }
                }
            }
            trip
        };
        let p = Pattern::new(n, &system(1.0)).unwrap();
        let mut chol = Cholesky::new(&p).unwrap();
        assert!(
            chol.shared.plan.is_some(),
            "a simplicial factor gets a plan"
        );
        for k in [1.0, 2.5] {
            let a = p.matrix(&system(k));
            assert!(chol.factor(&a));
            let mut faer_values = vec![0.0; chol.values.len()];
            chol.shared
                .symbolic
                .factorize_numeric_llt(
                    &mut faer_values,
                    a.as_ref(),
                    Side::Lower,
                    LltRegularization::default(),
                    Par::Seq,
                    MemStack::new(&mut chol.scratch),
                    Default::default(),
                )
                .unwrap();
            let bits = |v: &[f64]| -> Vec<u64> { v.iter().map(|x| x.to_bits()).collect() };
            assert_eq!(bits(&chol.values), bits(&faer_values), "k = {k}");
            // A pattern of the same structure (its triplets in another order) shares the
            // symbolic part, and the copy factorises the matrix to the same bits; another
            // structure is factorised anew.
            let mut reversed = system(k);
            reversed.reverse();
            let q = Pattern::new(n, &reversed).unwrap();
            let mut copy = chol.for_pattern(&q).unwrap();
            assert!(Arc::ptr_eq(&copy.shared, &chol.shared));
            assert!(copy.factor(&a));
            assert_eq!(bits(&copy.values), bits(&chol.values), "k = {k}");
            let diagonal: Vec<_> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
            let d = Pattern::new(n, &diagonal).unwrap();
            let other = chol.for_pattern(&d).unwrap();
            assert!(!Arc::ptr_eq(&other.shared, &chol.shared));
        }
        // Not positive definite: refused by the plan as by faer.
        let mut negative = system(1.0);
        negative[0].val = -100.0;
        assert!(!chol.factor(&p.matrix(&negative)));
    }

    #[test]
    fn a_kept_factorisation_solves_every_system_of_its_pattern() {
        let t = |r, c, v| Triplet::new(r, c, v);
        // A path graph's Laplacian plus the identity (lower triangle), then twice it.
        let system = |k: f64| -> Vec<Triplet<usize, usize, f64>> {
            let mut trip = Vec::new();
            for i in 0..5 {
                trip.push(t(i, i, k * if i == 0 || i == 4 { 2.0 } else { 3.0 }));
                if i > 0 {
                    trip.push(t(i, i - 1, -k));
                }
            }
            trip
        };
        let product = |trip: &[Triplet<usize, usize, f64>], x: &[f64]| -> Vec<f64> {
            let mut y = vec![0.0; 5];
            for e in trip {
                y[e.row] += e.val * x[e.col];
                if e.row != e.col {
                    y[e.col] += e.val * x[e.row];
                }
            }
            y
        };
        let p = Pattern::new(5, &system(1.0)).unwrap();
        let mut chol = Cholesky::new(&p).unwrap();
        for k in [1.0, 2.0] {
            let trip = system(k);
            assert!(chol.factor(&p.matrix(&trip)));
            // Two right-hand sides at once, one after the other.
            let rhs: Vec<f64> = (0..10).map(|i| (i * i) as f64 - 3.0).collect();
            let mut x = rhs.clone();
            assert!(chol.solve(&mut x, 2));
            assert!(!chol.solve(&mut x[..9], 2), "not twice the size");
            for c in 0..2 {
                let back = product(&trip, &x[5 * c..5 * c + 5]);
                for (b, r) in back.iter().zip(&rhs[5 * c..5 * c + 5]) {
                    assert!((b - r).abs() < 1e-12, "{b} against {r} at k = {k}");
                }
            }
        }
        // Not positive definite: refused.
        assert!(!chol.factor(&p.matrix(&system(-1.0))));
    }
}
