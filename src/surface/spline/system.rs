//! The linear algebra of guided projection (Tang et al. 2016, eq. 6), shared by the spline
//! solver's constraint kinds: sparse rows of linearised equations over the unknowns, point
//! expressions over the model's control points, and the regularised normal equations
//! (HᵀW²H + ε₂²I) x = HᵀW²r + ε₂²xₖ (the fairness rows come in as rows weighted ε₁) solved by
//! a sparse Cholesky (faer) whose pattern and symbolic factorisation are kept while the
//! rows' structure stays the same.

use crate::geom::bspline::apply;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Mat, Side};
use glam::DVec3;

/// A point expression Σ w·P over the model's points (index into the flat point list).
pub(super) type Expr = Vec<(usize, f64)>;

/// One linearised equation: entries · x ≈ rhs, with weight w.
pub(super) struct Row {
    pub(super) entries: Vec<(usize, f64)>,
    pub(super) rhs: f64,
    pub(super) w: f64,
}

pub(super) fn eval(e: &Expr, p: &[DVec3]) -> DVec3 {
    apply(e, p)
}

/// The normal equations' lower triangle as (row, column) pairs with their values, and the
/// right-hand side.
pub(super) fn normal_equations(
    n: usize,
    rows: &[Row],
    x: &[f64],
    eps2: f64,
) -> (Vec<Pair<usize, usize>>, Vec<f64>, Vec<f64>) {
    let nnz: usize = rows
        .iter()
        .map(|r| r.entries.len() * (r.entries.len() + 1) / 2)
        .sum();
    let mut idx = Vec::with_capacity(n + nnz);
    let mut val = Vec::with_capacity(n + nnz);
    let mut b: Vec<f64> = x.iter().map(|v| eps2 * eps2 * v).collect();
    for i in 0..n {
        idx.push(Pair { row: i, col: i });
        val.push(eps2 * eps2);
    }
    for r in rows {
        let w2 = r.w * r.w;
        for &(i, vi) in &r.entries {
            b[i] += w2 * vi * r.rhs;
            for &(j, vj) in &r.entries {
                if i >= j {
                    idx.push(Pair { row: i, col: j });
                    val.push(w2 * vi * vj);
                }
            }
        }
    }
    (idx, val, b)
}

/// The sparsity pattern of the last solve: its (row, column) list, the matrix structure with
/// the order the values fill it in, and the symbolic Cholesky factorisation. Kept while the
/// list stays the same (it changes when a target point's footpoint moves to another strip or
/// a crease point turns straight).
pub(super) struct Pattern {
    idx: Vec<Pair<usize, usize>>,
    matrix: SymbolicSparseColMat<usize>,
    order: Argsort<usize>,
    llt: SymbolicLlt<usize>,
}

/// Solve the normal equations `(idx, val)` x = b, reusing `pattern` while it holds.
pub(super) fn sparse_solve(
    n: usize,
    idx: Vec<Pair<usize, usize>>,
    val: &[f64],
    b: &[f64],
    pattern: &mut Option<Pattern>,
) -> Result<Vec<f64>, String> {
    if pattern.as_ref().is_none_or(|p| p.idx != idx) {
        let (matrix, order) =
            SymbolicSparseColMat::try_new_from_indices(n, n, &idx).map_err(|e| format!("{e:?}"))?;
        let llt =
            SymbolicLlt::try_new(matrix.as_ref(), Side::Lower).map_err(|e| format!("{e:?}"))?;
        *pattern = Some(Pattern {
            idx,
            matrix,
            order,
            llt,
        });
    }
    let p = pattern.as_ref().ok_or("no pattern")?;
    let a = SparseColMat::<usize, f64>::new_from_argsort(p.matrix.clone(), &p.order, val)
        .map_err(|e| format!("{e:?}"))?;
    let llt = Llt::try_new_with_symbolic(p.llt.clone(), a.as_ref(), Side::Lower)
        .map_err(|e| format!("not positive definite ({e:?})"))?;
    let x = llt.solve(&Mat::<f64>::from_fn(n, 1, |i, _| b[i]));
    Ok((0..n).map(|i| x[(i, 0)]).collect())
}
