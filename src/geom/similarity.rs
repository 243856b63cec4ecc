//! Least-squares similarity fit in the plane: the scale, rotation and translation that carry
//! a set of nominal points onto measured ones with the least sum of squared distances, and
//! what is left over (the residual of each point, their RMS and maximum).
//!
//! Method: the closed form of Umeyama (1991, "Least-squares estimation of transformation
//! parameters between two point patterns", eq. 40–42) written with complex numbers, which is
//! exact in 2D: with both sets centred on their centroids (`p'`, `q'`), the complex factor
//! `a = Σ conj(p'ᵢ) q'ᵢ / Σ |p'ᵢ|²` is the scale times the rotation (`scale = |a|`,
//! `angle = arg a`) and the translation is `q̄ − a p̄`. Reflections are not fitted (a printed
//! sheet cannot be laid mirrored face up).
//!
//! Choices: the residuals are the distances `|F(pᵢ) − qᵢ|` in the units of the points; the
//! RMS divides by the number of points (not by the degrees of freedom left), so that it reads
//! as "how far a mark is off, typically"; a set of fewer than two points, or whose nominal
//! points all coincide, or that holds a non-finite coordinate, has no fit (`None`).

use glam::DVec2;

/// `p ↦ scale · R(angle) · p + translation` (angle in radians, counter-clockwise).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Similarity {
    pub scale: f64,
    pub angle: f64,
    pub translation: DVec2,
}

impl Similarity {
    pub const IDENTITY: Similarity = Similarity {
        scale: 1.0,
        angle: 0.0,
        translation: DVec2::ZERO,
    };

    pub fn apply(&self, p: DVec2) -> DVec2 {
        DVec2::from_angle(self.angle).rotate(p) * self.scale + self.translation
    }
}

/// A fit and what it leaves unexplained.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    pub transform: Similarity,
    /// `|F(pᵢ) − qᵢ|` per point, in order.
    pub residuals: Vec<f64>,
    /// Root mean square of the residuals.
    pub rms: f64,
    /// Largest residual and its point (0-based).
    pub max: f64,
    pub worst: usize,
}

/// The least-squares similarity from `from` onto `to` (pairs in order; the shorter length
/// counts), see the module documentation; `None` when there is none to find.
pub fn fit(from: &[DVec2], to: &[DVec2]) -> Option<Fit> {
    let n = from.len().min(to.len());
    if n < 2 || from[..n].iter().chain(&to[..n]).any(|p| !p.is_finite()) {
        return None;
    }
    let pc = from[..n].iter().sum::<DVec2>() / n as f64;
    let qc = to[..n].iter().sum::<DVec2>() / n as f64;
    let (mut re, mut im, mut norm) = (0.0, 0.0, 0.0);
    for (p, q) in from[..n].iter().zip(&to[..n]) {
        let (p, q) = (*p - pc, *q - qc);
        re += p.x * q.x + p.y * q.y;
        im += p.x * q.y - p.y * q.x;
        norm += p.length_squared();
    }
    // All nominal points at one place: nothing fixes the rotation or the scale.
    if norm <= 1e-12 * (1.0 + pc.length_squared()) {
        return None;
    }
    let a = DVec2::new(re, im) / norm;
    let scale = a.length();
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    let angle = a.y.atan2(a.x);
    let mut t = Similarity {
        scale,
        angle,
        translation: DVec2::ZERO,
    };
    t.translation = qc - t.apply(pc);
    let residuals: Vec<f64> = from[..n]
        .iter()
        .zip(&to[..n])
        .map(|(p, q)| t.apply(*p).distance(*q))
        .collect();
    let rms = (residuals.iter().map(|r| r * r).sum::<f64>() / n as f64).sqrt();
    let (worst, max) = residuals
        .iter()
        .copied()
        .enumerate()
        .fold((0, 0.0), |b, (i, r)| if r > b.1 { (i, r) } else { b });
    Some(Fit {
        transform: t,
        residuals,
        rms,
        max,
        worst,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn marks() -> Vec<DVec2> {
        vec![
            DVec2::new(12.5, 274.5),
            DVec2::new(10.0, 10.0),
            DVec2::new(200.0, 10.0),
            DVec2::new(200.0, 287.0),
        ]
    }

    /// A known transform is recovered to 1e-9, with no residual.
    #[test]
    fn exact_recovery() {
        for (s, deg, t) in [
            (1.0, 1.5, DVec2::new(7.0, -4.0)),
            (0.993, -12.0, DVec2::new(-30.0, 55.5)),
            (1.01, 179.0, DVec2::new(400.0, 300.0)),
        ] {
            let truth = Similarity {
                scale: s,
                angle: f64::to_radians(deg),
                translation: t,
            };
            let from = marks();
            let to: Vec<DVec2> = from.iter().map(|p| truth.apply(*p)).collect();
            let f = fit(&from, &to).unwrap();
            assert!((f.transform.scale - s).abs() < 1e-9, "{f:?}");
            assert!((f.transform.angle - truth.angle).abs() < 1e-9, "{f:?}");
            assert!(f.transform.translation.distance(t) < 1e-9, "{f:?}");
            assert!(f.max < 1e-9 && f.rms < 1e-9, "{f:?}");
        }
    }

    /// Noise of known size: the corners of a square stretched along x and squeezed along y by
    /// e each (an area-keeping strain, which has no part a similarity can take out) are each
    /// left e·√2 from the fit, which is the identity.
    #[test]
    fn noise_gives_the_right_residual() {
        let from = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(100.0, 0.0),
            DVec2::new(100.0, 100.0),
            DVec2::new(0.0, 100.0),
        ];
        let e = 0.2;
        let to: Vec<DVec2> = from
            .iter()
            .map(|p| {
                let s = (*p - DVec2::splat(50.0)).signum();
                *p + DVec2::new(s.x * e, -s.y * e)
            })
            .collect();
        let f = fit(&from, &to).unwrap();
        assert!((f.transform.scale - 1.0).abs() < 1e-12, "{f:?}");
        assert!(f.transform.angle.abs() < 1e-12, "{f:?}");
        assert!(f.transform.translation.length() < 1e-12, "{f:?}");
        let r = e * 2f64.sqrt();
        for x in &f.residuals {
            assert!((x - r).abs() < 1e-12, "{f:?}");
        }
        assert!((f.rms - r).abs() < 1e-12 && (f.max - r).abs() < 1e-12);
        // One mark off by 1 mm in y: the fit spreads it, the worst is that mark.
        let mut to = marks();
        to[2].y += 1.0;
        let f = fit(&marks(), &to).unwrap();
        assert_eq!(f.worst, 2, "{f:?}");
        assert!(f.max > 0.5 && f.max < 1.0, "{f:?}");
    }

    #[test]
    fn no_fit_without_two_distinct_points() {
        let p = DVec2::new(1.0, 2.0);
        assert!(fit(&[p], &[p]).is_none());
        assert!(fit(&[p, p, p], &[p, p + DVec2::X, p]).is_none());
        assert!(fit(&[p, DVec2::NAN], &[p, p]).is_none());
    }
}
