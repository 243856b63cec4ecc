//! The linear algebra of guided projection (Tang et al. 2016, eq. 6), shared by the spline
//! solver's constraint kinds: sparse rows of linearised equations over the unknowns, point
//! expressions over the model's control points, and the regularised normal equations
//! (HᵀW²H + ε₂²I) x = HᵀW²r + ε₂²xₖ (the fairness rows come in as rows weighted ε₁) solved by
//! a sparse Cholesky (faer) whose symbolic factorisation is kept while the pattern holds.

use crate::geom::bspline::apply;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
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

/// The normal equations' lower triangle and right-hand side.
pub(super) fn normal_equations(
    n: usize,
    rows: &[Row],
    x: &[f64],
    eps2: f64,
) -> (Vec<Triplet<usize, usize, f64>>, Vec<f64>) {
    let mut t = Vec::new();
    let mut b: Vec<f64> = x.iter().map(|v| eps2 * eps2 * v).collect();
    for i in 0..n {
        t.push(Triplet::new(i, i, eps2 * eps2));
    }
    for r in rows {
        let w2 = r.w * r.w;
        for &(i, vi) in &r.entries {
            b[i] += w2 * vi * r.rhs;
            for &(j, vj) in &r.entries {
                if i >= j {
                    t.push(Triplet::new(i, j, w2 * vi * vj));
                }
            }
        }
    }
    (t, b)
}

pub(super) fn sparse_solve(
    n: usize,
    t: &[Triplet<usize, usize, f64>],
    b: &[f64],
    symbolic: &mut Option<SymbolicLlt<usize>>,
) -> Result<Vec<f64>, String> {
    let a =
        SparseColMat::<usize, f64>::try_new_from_triplets(n, n, t).map_err(|e| format!("{e:?}"))?;
    let sym = match symbolic {
        Some(s) => s.clone(),
        None => {
            let s =
                SymbolicLlt::try_new(a.symbolic(), Side::Lower).map_err(|e| format!("{e:?}"))?;
            *symbolic = Some(s.clone());
            s
        }
    };
    let llt = Llt::try_new_with_symbolic(sym, a.as_ref(), Side::Lower)
        .map_err(|e| format!("not positive definite ({e:?})"))?;
    let x = llt.solve(&Mat::<f64>::from_fn(n, 1, |i, _| b[i]));
    Ok((0..n).map(|i| x[(i, 0)]).collect())
}
