//! ABF++ angles (Sheffer, Lévy, Mogilnitsky, Bogomyakov 2005): the angles of every triangle
//! of a chart that [`super::parameterize`] turns into a layout.
//!
//! Unknowns: the 3 angles α of every triangle. Targets β: the 3D angles, scaled at each
//! interior vertex so they sum to 2π (ABF, Sheffer & de Sturler 2001). Energy Σ (α − β)²/β²
//! under the constraints: triangle sums π, interior vertex sums 2π, and the wheel (law of
//! sines) condition Σ log sin α_next − Σ log sin α_prev = 0 around each interior vertex (the
//! log form of the paper's product, same zero set, better scaled). Newton steps on the
//! Lagrangian with the Hessian approximated by its diagonal Λ = 2/β² (ABF++ §4.1); each step is
//! solved through the ABF++ reduction: the triangle constraints are eliminated, and only the
//! Schur complement over the vertex and wheel multipliers is factored (sparse Cholesky)
//! (ABF++ §4.2, eq. 12–16).
//!
//! Choice where the paper is silent: steps are damped when a full Newton step would take an
//! angle out of (0, π) (the paper takes full steps); the iteration stops at
//! [`super::ABF_TOLERANCE`], or when it stalls at round-off level far below any visible angle
//! error, and fails after [`super::ABF_MAX_ITER`] steps.

use super::{spd_solve, Chart, ParamError, ABF_MAX_ITER, ABF_TOLERANCE};
use crate::flatten::distortion::corner_angle;
use faer::sparse::Triplet;
use std::f64::consts::PI;

/// ABF++: optimal angles per triangle.
pub(super) fn abf_angles(chart: &Chart) -> Result<Vec<[f64; 3]>, ParamError> {
    const M: &str = "ABF++";
    let nt = chart.tris.len();
    let abf = Abf::new(chart);
    let mut alpha = abf.beta.clone();
    let mut lam_t = vec![0.0f64; nt];
    let mut lam2 = vec![0.0f64; 2 * abf.ni];
    let m2 = 2 * abf.ni;
    let mut converged = false;
    let mut solver = None;
    let mut last_norm = f64::INFINITY;
    for _iter in 0..ABF_MAX_ITER {
        let gr = abf.gradient(&alpha, &lam_t, &lam2);
        let norm = gr
            .b1
            .iter()
            .flat_map(|b| b.iter())
            .chain(gr.c1.iter())
            .chain(gr.c2.iter())
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt();
        if !norm.is_finite() {
            return Err(chart.solver_error(M, "the Newton iteration diverged"));
        }
        let scale = (nt as f64).sqrt().max(1.0);
        // Converged; or stalled at round-off level (Newton no longer halves the residual)
        // with a residual that is still far below any visible angle error.
        if norm < ABF_TOLERANCE * scale || (norm > 0.5 * last_norm && norm < 1e-7 * scale) {
            converged = true;
            break;
        }
        last_norm = norm;
        let red = abf.reduced(&gr);
        let x = spd_solve(chart, M, m2, &red.triplets, &red.rhs, &mut solver, 0)?;
        let (d_alpha, d_lam_t, step) = abf.step(&gr, &red, &alpha, &x);
        if step.is_nan() || step <= 1e-6 {
            return Err(chart.solver_error(M, "the Newton step cannot keep the angles in (0, π)"));
        }
        for (l, dl) in lam_t.iter_mut().zip(&d_lam_t) {
            *l += step * dl;
        }
        for (a, da) in alpha.iter_mut().zip(&d_alpha) {
            for c in 0..3 {
                a[c] += step * da[c];
            }
        }
        for (l, dx) in lam2.iter_mut().zip(&x) {
            *l += step * dx;
        }
    }
    if !converged {
        return Err(chart.solver_error(M, format!("no convergence in {ABF_MAX_ITER} Newton steps")));
    }
    Ok(alpha)
}

/// The ABF++ problem of a chart: target angles, the Hessian's diagonal, the multiplier rows.
struct Abf<'a> {
    chart: &'a Chart,
    /// Interior vertex -> row pair (V = 2i, L = 2i + 1).
    row: Vec<Option<usize>>,
    /// Interior vertices.
    ni: usize,
    /// Target angles β per triangle corner.
    beta: Vec<[f64; 3]>,
    /// Λ = 2/β² per triangle corner.
    lam_diag: Vec<[f64; 3]>,
}

/// The Lagrangian's gradient at the current angles and multipliers.
struct Gradient {
    /// Per triangle corner: ∂/∂α.
    b1: Vec<[f64; 3]>,
    /// Per triangle: the angle sum minus π.
    c1: Vec<f64>,
    /// Per interior vertex: the angle sum minus 2π (V row) and the wheel condition (L row).
    c2: Vec<f64>,
    /// Per triangle corner: cot α.
    cot: Vec<[f64; 3]>,
}

/// The reduced system over the vertex and wheel multipliers, and what each triangle
/// contributes to it (for the back-substitution).
struct Reduced {
    triplets: Vec<Triplet<usize, usize, f64>>,
    rhs: Vec<f64>,
    local_b: Vec<[f64; 6]>,
    local_r1: Vec<f64>,
    local_d: Vec<f64>,
}

impl<'a> Abf<'a> {
    /// 3D angles and targets: the 3D angles scaled at each interior vertex to sum to 2π.
    fn new(chart: &'a Chart) -> Self {
        let nt = chart.tris.len();
        let nv = chart.pos.len();
        let mut phi = vec![[0.0f64; 3]; nt];
        let mut sum = vec![0.0f64; nv];
        for (t, tri) in chart.tris.iter().enumerate() {
            let p = tri.map(|v| chart.pos[v]);
            for c in 0..3 {
                phi[t][c] = corner_angle(p[c], p[(c + 1) % 3], p[(c + 2) % 3]);
                sum[tri[c]] += phi[t][c];
            }
        }
        let mut row: Vec<Option<usize>> = vec![None; nv];
        let mut ni = 0;
        for (slot, &on_boundary) in row.iter_mut().zip(&chart.boundary) {
            if !on_boundary {
                *slot = Some(ni);
                ni += 1;
            }
        }
        let mut beta = phi.clone();
        for (t, tri) in chart.tris.iter().enumerate() {
            for c in 0..3 {
                if row[tri[c]].is_some() {
                    beta[t][c] *= 2.0 * PI / sum[tri[c]];
                }
            }
        }
        let lam_diag: Vec<[f64; 3]> = beta.iter().map(|b| b.map(|x| 2.0 / (x * x))).collect();
        Abf {
            chart,
            row,
            ni,
            beta,
            lam_diag,
        }
    }

    /// Gradient of the Lagrangian and constraint values.
    fn gradient(&self, alpha: &[[f64; 3]], lam_t: &[f64], lam2: &[f64]) -> Gradient {
        let (chart, row, beta, lam_diag) = (self.chart, &self.row, &self.beta, &self.lam_diag);
        let nt = chart.tris.len();
        let mut c2 = vec![0.0f64; 2 * self.ni];
        for i in 0..self.ni {
            c2[2 * i] = -2.0 * PI;
        }
        let mut b1 = vec![[0.0f64; 3]; nt];
        let mut c1 = vec![0.0f64; nt];
        let mut cot = vec![[0.0f64; 3]; nt];
        for (t, tri) in chart.tris.iter().enumerate() {
            c1[t] = alpha[t][0] + alpha[t][1] + alpha[t][2] - PI;
            for c in 0..3 {
                let a = alpha[t][c];
                cot[t][c] = a.cos() / a.sin();
                let mut g = lam_diag[t][c] * (a - beta[t][c]) + lam_t[t];
                if let Some(r) = row[tri[c]] {
                    g += lam2[2 * r];
                    c2[2 * r] += a;
                }
                // This corner is "next" for the vertex at corner c+2, "prev" for c+1.
                if let Some(r) = row[tri[(c + 2) % 3]] {
                    g += lam2[2 * r + 1] * cot[t][c];
                    c2[2 * r + 1] += a.sin().ln();
                }
                if let Some(r) = row[tri[(c + 1) % 3]] {
                    g -= lam2[2 * r + 1] * cot[t][c];
                    c2[2 * r + 1] -= a.sin().ln();
                }
                b1[t][c] = g;
            }
        }
        Gradient { b1, c1, c2, cot }
    }

    /// The constraint Jacobian's row of corner `c` of triangle `t` over the triangle's local
    /// slots: 2k = V row of corner k's vertex, 2k + 1 = its L row.
    fn jac(&self, cot: &[[f64; 3]], t: usize, c: usize) -> [f64; 6] {
        let row = &self.row;
        let tri = self.chart.tris[t];
        let mut j = [0.0; 6];
        if row[tri[c]].is_some() {
            j[2 * c] = 1.0;
        }
        let cn = (c + 2) % 3;
        if row[tri[cn]].is_some() {
            j[2 * cn + 1] += cot[t][c];
        }
        let cp = (c + 1) % 3;
        if row[tri[cp]].is_some() {
            j[2 * cp + 1] -= cot[t][c];
        }
        j
    }

    /// The reduced system over the vertex and wheel multipliers (ABF++ §4.2, eq. 12–16): the
    /// triangle constraints eliminated, per triangle.
    fn reduced(&self, gr: &Gradient) -> Reduced {
        let (chart, row, lam_diag) = (self.chart, &self.row, &self.lam_diag);
        let (b1, c1, cot) = (&gr.b1, &gr.c1, &gr.cot);
        let nt = chart.tris.len();
        let mut triplets: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(nt * 21);
        let mut rhs = gr.c2.clone();
        let mut local_b = vec![[0.0f64; 6]; nt];
        let mut local_r1 = vec![0.0f64; nt];
        let mut local_d = vec![0.0f64; nt];
        for (t, tri) in chart.tris.iter().enumerate() {
            let js = [
                self.jac(cot, t, 0),
                self.jac(cot, t, 1),
                self.jac(cot, t, 2),
            ];
            let inv = lam_diag[t].map(|x| 1.0 / x);
            let d = inv[0] + inv[1] + inv[2];
            let mut bt = [0.0f64; 6];
            let mut jb = [0.0f64; 6];
            let mut r1 = c1[t];
            for c in 0..3 {
                r1 -= b1[t][c] * inv[c];
                for s in 0..6 {
                    bt[s] += js[c][s] * inv[c];
                    jb[s] += js[c][s] * b1[t][c] * inv[c];
                }
            }
            let slot_row = |s: usize| row[tri[s / 2]].map(|r| 2 * r + s % 2);
            for s in 0..6 {
                let Some(rs) = slot_row(s) else { continue };
                rhs[rs] -= jb[s] + bt[s] * r1 / d;
                for q in 0..6 {
                    let Some(rq) = slot_row(q) else { continue };
                    if rs < rq {
                        continue;
                    }
                    let mut v = -bt[s] * bt[q] / d;
                    for c in 0..3 {
                        v += js[c][s] * js[c][q] * inv[c];
                    }
                    // Zeros kept: the pattern must not change between steps.
                    triplets.push(Triplet::new(rs, rq, v));
                }
            }
            local_b[t] = bt;
            local_r1[t] = r1;
            local_d[t] = d;
        }
        Reduced {
            triplets,
            rhs,
            local_b,
            local_r1,
            local_d,
        }
    }

    /// The Newton step from the multipliers' solution `x`: the angle and triangle multiplier
    /// changes, and the largest step fraction keeping every angle inside (0, π) with a margin
    /// (a damped Newton step; ABF++ takes full steps, which can leave the domain on hard
    /// charts).
    fn step(
        &self,
        gr: &Gradient,
        red: &Reduced,
        alpha: &[[f64; 3]],
        x: &[f64],
    ) -> (Vec<[f64; 3]>, Vec<f64>, f64) {
        let (chart, row, lam_diag) = (self.chart, &self.row, &self.lam_diag);
        let nt = chart.tris.len();
        let mut d_alpha = vec![[0.0f64; 3]; nt];
        let mut d_lam_t = vec![0.0f64; nt];
        let mut step = 1.0f64;
        for (t, tri) in chart.tris.iter().enumerate() {
            let xl: [f64; 6] =
                std::array::from_fn(|s| row[tri[s / 2]].map(|r| x[2 * r + s % 2]).unwrap_or(0.0));
            let bx: f64 = (0..6).map(|s| red.local_b[t][s] * xl[s]).sum();
            let dl1 = (red.local_r1[t] - bx) / red.local_d[t];
            d_lam_t[t] = dl1;
            for c in 0..3 {
                let j = self.jac(&gr.cot, t, c);
                let jx: f64 = (0..6).map(|s| j[s] * xl[s]).sum();
                let da = -(gr.b1[t][c] + dl1 + jx) / lam_diag[t][c];
                let a = alpha[t][c];
                if da < 0.0 {
                    step = step.min(0.9 * a / -da);
                } else if da > 0.0 {
                    step = step.min(0.9 * (PI - a) / da);
                }
                d_alpha[t][c] = da;
            }
        }
        (d_alpha, d_lam_t, step)
    }
}
