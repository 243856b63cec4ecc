//! The overlap proxy between two colliding shapes, after sparrow (Gardeyn, Vanden Berghe,
//! Wauters, "An open-source heuristic to reboot 2D nesting research", 2025, arXiv:2509.13329).
//!
//! Each shape is approximated by its poles ([`super::poles`]). For every pair of poles the
//! penetration depth `pd = r₁ + r₂ + s − d` is turned into a decaying positive value (`pd`
//! when `pd ≥ ε`, `ε² / (2ε − pd)` otherwise) weighted by the smaller radius; the sum `Σ` gives
//! the proxy `√(Σ + ε²) · (A₁ A₂)^¼` with `A` the areas and `ε` 1 % of the larger bounding-box
//! side. It is positive for every colliding pair, grows smoothly as shapes are pushed into
//! each other, and — through the square root and the `ε²` floor — makes many shallow overlaps
//! cost more than one deeper one, which keeps the separator from scattering overlaps.
//!
//! Choice where sparrow differs: sparrow sums over all pole pairs; here only pairs that are
//! near count: a pole farther from the other shape's bounding box than the two largest radii
//! plus the spacing is skipped, and so is a pair whose gap exceeds the sum of its radii
//! (`pd < −(r₁ + r₂)`). Far pairs add a long-range push that, summed over many pairs,
//! outweighs the `ε²` floor and spreads the layout. The pole pairs are evaluated a row at a
//! time, branch-free over fixed-size lanes, so that the compiler vectorises them (AVX2 when
//! the CPU has it, with bit-identical results).

use super::shape::{Shape, POLE_LANES};
use glam::DVec2;

/// Overlap proxy of two shapes known to collide (see the module docs); always > 0.
///
/// Each pole of `a` near `b`'s bounding box meets every lane of `b` at once, branch-free, so
/// that the compiler vectorises it; with AVX2 where the CPU has it (checked at run time). The
/// compiler never fuses a multiply and an add on its own, so both give bit-identical values.
pub(crate) fn overlap_proxy(
    a: &Shape,
    pa: DVec2,
    b: &Shape,
    pb: DVec2,
    s: f64,
    work: &mut u64,
) -> f64 {
    *work += (a.poles.len() * b.poles.len()) as u64 / 16 + 2;
    if a.poles.is_empty() || b.poles.is_empty() {
        return 1e-6;
    }
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        return unsafe { overlap_proxy_avx2(a, pa, b, pb, s) };
    }
    overlap_proxy_lanes(a, pa, b, pb, s)
}

/// [`overlap_proxy_lanes`] with AVX2 instructions.
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn overlap_proxy_avx2(a: &Shape, pa: DVec2, b: &Shape, pb: DVec2, s: f64) -> f64 {
    overlap_proxy_lanes(a, pa, b, pb, s)
}

#[inline(always)]
fn overlap_proxy_lanes(a: &Shape, pa: DVec2, b: &Shape, pb: DVec2, s: f64) -> f64 {
    let eps = 0.01 * a.size.max_element().max(b.size.max_element());
    let (eps2, two_eps) = (eps * eps, 2.0 * eps);
    let d = pb - pa;
    let l = &b.lanes;
    let (ra_max, rb_max) = (a.poles[0].1, l.r[0]);
    // Poles far from the other shape's bounding box add (almost) nothing: skipped, on `b`'s
    // side by a radius of 0 in the min-radius weight.
    let mut rw = l.r;
    for (j, w) in rw.iter_mut().enumerate() {
        let c = DVec2::new(l.x[j], l.y[j]) + d;
        let reach = *w + s + ra_max;
        if c.clamp(DVec2::ZERO, a.size).distance_squared(c) >= reach * reach {
            *w = 0.0;
        }
    }
    let mut acc = [0.0f64; POLE_LANES];
    for (ca, ra) in &a.poles {
        let ca = *ca - d;
        let reach = ra + s + rb_max;
        if ca.clamp(DVec2::ZERO, b.size).distance_squared(ca) >= reach * reach {
            continue;
        }
        let base = ra + s;
        for j in 0..POLE_LANES {
            let (dx, dy) = (ca.x - l.x[j], ca.y - l.y[j]);
            let pd = base + l.r[j] - (dx * dx + dy * dy).sqrt();
            let decay = eps2 / (two_eps - pd);
            let v = if pd >= eps { pd } else { decay };
            // Pairs farther apart than their radii sum count for nothing (module docs).
            let v = if pd > -(ra + l.r[j]) { v } else { 0.0 };
            acc[j] += v * ra.min(rw[j]);
        }
    }
    let sum: f64 = acc.iter().sum();
    (sum + eps2).sqrt() * (a.area.abs() * b.area.abs()).sqrt().sqrt()
}

#[cfg(test)]
mod tests {
    use super::super::tests::{rect, shape};
    use super::*;

    #[test]
    fn proxy_grows_with_penetration() {
        let a = shape(rect(4.0, 4.0));
        let mut w = 0;
        let p1 = overlap_proxy(&a, DVec2::ZERO, &a, DVec2::new(3.5, 0.0), 0.0, &mut w);
        let p2 = overlap_proxy(&a, DVec2::ZERO, &a, DVec2::new(2.0, 0.0), 0.0, &mut w);
        assert!(p2 > p1 && p1 > 0.0, "{p1} {p2}");
    }
}
