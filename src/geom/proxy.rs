//! The DCS proxy and its fit (Julius 2006, thesis §4.3, eq. 4.1 and eq. 5.4; §6.2.1, eq. 6.1):
//! the cone or cylinder of constant slope that D-Charts grows charts around
//! (`surface::dcharts`), that the DCS approximation moves triangles onto (`surface::dcs`),
//! and whose cylinder case (`θ = π/2`) is the merging criterion of §5.2.3 ([`cylinder_error`],
//! also used by the flatten stage to re-attach gussets).
//!
//! A DCS proxy is an axis `N` (unit) and the cosine `c = cos θ` of the constant angle between
//! the surface normals and the axis; the fitting error of a face with normal `n` is
//! `F = ((N·n − c)/2)²` (eq. 4.1).
//!
//! The thesis solves eq. 5.4 with a general solver (Knitro). It has a closed form: for a fixed
//! axis the best `c` is the area-weighted mean of `N·n`, and what is left is
//! `Nᵀ Σ A_t (n_t − n̄)(n_t − n̄)ᵀ N / 4`, minimised over unit `N` by the eigenvector of the
//! smallest eigenvalue of the weighted covariance of the normals. [`fit`] uses that (a 3×3
//! Jacobi eigen-solver). When the covariance vanishes (a plane) the proxy is the plane's own:
//! `N` = the mean normal, `c` = 1. Fits with a prescribed `c` (the planar test of §6.2.1 with
//! `c = 1`, the `|cos θ| ≤ 0.5` bound of eq. 6.1, the cylinder test of the merging step with
//! `c = 0`) minimise a quadratic on the unit sphere: `(M − λI) N = c b` with `λ` below the
//! smallest eigenvalue of `M`, found by bisection on `|N(λ)| = 1` ([`fit_with_cos`]).
//!
//! Faces with a zero normal (degenerate) weigh nothing in a fit and fit every proxy (F = 0):
//! they carry no direction.

use glam::{DMat3, DVec3};

/// A developable surface of constant slope: normals at a constant angle to `axis`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proxy {
    /// Unit axis `N`.
    pub axis: DVec3,
    /// `cos θ`: 1 for a plane with normal `axis`, 0 for a cylinder along `axis`.
    pub cos: f64,
}

impl Proxy {
    /// Fitting error of a face normal, eq. 4.1; 0 for a zero (degenerate) normal.
    pub fn error(&self, n: DVec3) -> f64 {
        if n == DVec3::ZERO {
            return 0.0;
        }
        let d = (self.axis.dot(n) - self.cos) * 0.5;
        d * d
    }
}

/// Eigenvalues (ascending) and unit eigenvectors of a symmetric 3×3 matrix (Jacobi).
#[allow(clippy::needless_range_loop)] // rows and columns of the same small matrix
pub fn eigen_sym(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    let mut a = m.to_cols_array_2d();
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs() + off;
        if off <= 1e-15 * scale.max(f64::MIN_POSITIVE) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() < 1e-300 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let vp = row[p];
                let vq = row[q];
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let vals = [a[idx[0]][idx[0]], a[idx[1]][idx[1]], a[idx[2]][idx[2]]];
    let col = |j: usize| DVec3::new(v[0][j], v[1][j], v[2][j]).normalize_or(DVec3::Z);
    (vals, [col(idx[0]), col(idx[1]), col(idx[2])])
}

/// Weighted sums of normals: `W = Σw`, `b = Σ w n`, `M = Σ w n nᵀ`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Moments {
    pub w: f64,
    pub b: DVec3,
    pub m: [[f64; 3]; 3],
}

impl Moments {
    /// Add a normal with weight `w` (zero normals and weights are skipped).
    pub fn add(&mut self, n: DVec3, w: f64) {
        if n == DVec3::ZERO || w.is_nan() || w <= 0.0 {
            return;
        }
        self.w += w;
        self.b += w * n;
        let a = n.to_array();
        for (i, row) in self.m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x += w * a[i] * a[j];
            }
        }
    }

    fn mat(&self) -> DMat3 {
        DMat3::from_cols_array_2d(&self.m)
    }
}

/// The DCS proxy minimising the area-weighted fitting error (eq. 5.4), with `cos θ ≥ 0`.
/// `None` when there is no weight (no faces, or only degenerate ones).
pub fn fit(mo: &Moments) -> Option<Proxy> {
    if mo.w <= 0.0 {
        return None;
    }
    let mean = mo.b / mo.w;
    // Covariance Σ w (n − n̄)(n − n̄)ᵀ = M − W n̄ n̄ᵀ.
    let cov = mo.mat() - DMat3::from_cols(mean * mean.x, mean * mean.y, mean * mean.z) * mo.w;
    let (vals, vecs) = eigen_sym(cov);
    let planar = vals[2] <= 1e-14 * mo.w;
    if planar {
        if let Some(n) = mean.try_normalize() {
            return Some(Proxy { axis: n, cos: 1.0 });
        }
    }
    let mut axis = vecs[0];
    let mut cos = axis.dot(mean);
    if cos < 0.0 {
        axis = -axis;
        cos = -cos;
    }
    Some(Proxy {
        axis,
        cos: cos.min(1.0),
    })
}

/// The axis minimising `Σ w (N·n − c)²` over unit `N` for a prescribed `c` (eq. 5.4 with
/// θ fixed). `None` without weight.
pub fn fit_with_cos(mo: &Moments, c: f64) -> Option<Proxy> {
    if mo.w <= 0.0 {
        return None;
    }
    let (mu, e) = eigen_sym(mo.mat());
    let rhs = mo.b * c;
    let coef = [rhs.dot(e[0]), rhs.dot(e[1]), rhs.dot(e[2])];
    let norm2 = |lam: f64| -> f64 {
        (0..3)
            .map(|i| {
                let d = mu[i] - lam;
                if d.abs() < 1e-300 {
                    f64::INFINITY
                } else {
                    (coef[i] / d).powi(2)
                }
            })
            .sum()
    };
    // |N(λ)| grows as λ rises to μ₀; in the "hard case" (b has no part along the smallest
    // eigenvector e₀, e.g. c = 0, or a symmetric patch) it stays finite, and when it stays
    // below 1 the minimiser is N(μ₀) completed by e₀ to unit length.
    let small = coef[0].abs() <= 1e-12 * (mo.w + rhs.length()).max(1e-300);
    let rest = (1..3).fold(DVec3::ZERO, |acc, i| {
        let d = mu[i] - mu[0];
        if d > 1e-12 * mu[2].abs().max(1e-300) {
            acc + e[i] * (coef[i] / d)
        } else {
            acc
        }
    });
    let axis = if small && rest.length_squared() < 1.0 {
        let mut a = rest + e[0] * (1.0 - rest.length_squared()).max(0.0).sqrt();
        if c == 0.0 && a.dot(mo.b) < 0.0 {
            a = -a;
        }
        a.try_normalize()?
    } else {
        let mut hi = mu[0];
        let mut lo = mu[0] - rhs.length() - 1.0;
        while norm2(lo) > 1.0 {
            lo -= (mu[0] - lo).max(1.0);
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if norm2(mid) > 1.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let lam = lo;
        let v = (0..3).fold(DVec3::ZERO, |acc, i| {
            let d = mu[i] - lam;
            if d.abs() < 1e-300 {
                acc
            } else {
                acc + e[i] * (coef[i] / d)
            }
        });
        v.try_normalize()?
    };
    Some(Proxy { axis, cos: c })
}

/// Mean (area-weighted) fitting error of a proxy over weighted normals.
pub fn mean_error(p: &Proxy, mo: &Moments) -> f64 {
    if mo.w <= 0.0 {
        return 0.0;
    }
    // Σ w (N·n − c)² = Nᵀ M N − 2c N·b + c² W.
    let n = p.axis;
    let q = n.dot(mo.mat() * n) - 2.0 * p.cos * n.dot(mo.b) + p.cos * p.cos * mo.w;
    (q.max(0.0) / 4.0) / mo.w
}

/// The DCS fit of eq. 6.1 with `|cos θ| ≤ 0.5`, after the planar test.
pub fn fit_local(mo: &Moments, planar_error: f64) -> Option<Proxy> {
    let plane = fit_with_cos(mo, 1.0)?;
    let plane_err = mean_error(&plane, mo);
    if plane_err <= planar_error {
        return Some(plane);
    }
    let free = fit(mo)?;
    let dcs = if free.cos <= 0.5 {
        free
    } else {
        fit_with_cos(mo, 0.5)?
    };
    let _ = plane_err;
    Some(dcs)
}

/// Mean fitting error of weighted normals to their best cylinder (a proxy with `θ = π/2`,
/// eq. 5.4): the merging criterion of §5.2.3, compared with `η`. `None` when the normals have
/// no weight.
pub fn cylinder_error(mo: &Moments) -> Option<f64> {
    let p = fit_with_cos(mo, 0.0)?;
    Some(mean_error(&p, mo))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_normals_fit_exactly() {
        let mut mo = Moments::default();
        for k in 0..12 {
            let t = k as f64 * 0.2;
            mo.add(DVec3::new(t.cos(), t.sin(), 0.0), 1.0);
        }
        let p = fit(&mo).unwrap();
        assert!(p.axis.z.abs() > 1.0 - 1e-9, "{p:?}");
        assert!(p.cos.abs() < 1e-9);
        assert!(mean_error(&p, &mo) < 1e-15);
    }

    #[test]
    fn cone_normals_fit_exactly_and_bounded_fit_respects_half() {
        let mut mo = Moments::default();
        let c: f64 = 0.8;
        let s = (1.0 - c * c).sqrt();
        for k in 0..10 {
            let t = k as f64 * 0.3;
            mo.add(DVec3::new(s * t.cos(), s * t.sin(), c), 1.0 + k as f64);
        }
        let p = fit(&mo).unwrap();
        assert!((p.cos - c).abs() < 1e-9, "{p:?}");
        assert!(mean_error(&p, &mo) < 1e-15);
        let q = fit_local(&mo, 1e-9).unwrap();
        assert!((q.cos - 0.5).abs() < 1e-12);
        // The bounded fit is the best with c = 0.5: no nearby axis does better.
        let e = mean_error(&q, &mo);
        for d in [DVec3::X, DVec3::Y, DVec3::Z] {
            let r = Proxy {
                axis: (q.axis + d * 1e-3).normalize(),
                cos: 0.5,
            };
            assert!(mean_error(&r, &mo) >= e - 1e-12);
        }
    }

    #[test]
    fn symmetric_patch_plane_fit_is_its_mean_normal() {
        // Normals spread evenly around z: b lies along z, the smallest eigenvectors across.
        let mut mo = Moments::default();
        mo.add(DVec3::Z, 1.0);
        for k in 0..6 {
            let t = k as f64 * std::f64::consts::PI / 3.0;
            mo.add(
                DVec3::new(0.1 * t.cos(), 0.1 * t.sin(), 1.0).normalize(),
                1.0,
            );
        }
        let p = fit_with_cos(&mo, 1.0).unwrap();
        assert!((p.axis - DVec3::Z).length() < 1e-9, "{p:?}");
        let q = fit_with_cos(&mo, 0.5).unwrap();
        assert!((q.axis.length() - 1.0).abs() < 1e-12);
        assert!(
            mean_error(&q, &mo)
                < mean_error(
                    &Proxy {
                        axis: DVec3::X,
                        cos: 0.5
                    },
                    &mo
                )
        );
    }

    #[test]
    fn plane_fits_as_plane() {
        let mut mo = Moments::default();
        mo.add(DVec3::Y, 2.0);
        mo.add(DVec3::Y, 1.0);
        let p = fit(&mo).unwrap();
        assert_eq!(p.cos, 1.0);
        assert!((p.axis - DVec3::Y).length() < 1e-12);
        assert!(fit(&Moments::default()).is_none());
    }
}
