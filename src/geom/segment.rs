//! Distances between points and segments, in 2D and 3D: the one kernel behind
//! `polygon::segment_distance`, `polygon::segment_segment_distance`, the sampling tolerance of
//! `curve` and the nest stage's exact collision test.
//!
//! The distances are squared (no square root in the hot loops of the nest stage's collision
//! test); callers that need the distance take the square root of the squared one, which gives
//! the same bits as measuring the distance directly (the square root is correctly rounded and
//! monotone, so it commutes with `min` too). The closest point on a segment is `a + (b − a) t`
//! with `t` the projection clamped to `[0, 1]`; a degenerate segment (`a = b`) is its point.

use glam::{DVec2, DVec3};
use std::ops::{Add, Mul, Sub};

/// A point type the kernels work on: [`DVec2`] and [`DVec3`] (their own glam methods).
pub trait Point: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f64, Output = Self> {
    fn dot(self, o: Self) -> f64;
    fn length_squared(self) -> f64;
    fn distance_squared(self, o: Self) -> f64;
}

/// Implements [`Point`] with the type's own glam methods.
macro_rules! impl_point {
    ($t:ty) => {
        impl Point for $t {
            #[inline]
            fn dot(self, o: Self) -> f64 {
                <$t>::dot(self, o)
            }
            #[inline]
            fn length_squared(self) -> f64 {
                <$t>::length_squared(self)
            }
            #[inline]
            fn distance_squared(self, o: Self) -> f64 {
                <$t>::distance_squared(self, o)
            }
        }
    };
}

impl_point!(DVec2);
impl_point!(DVec3);

/// Squared distance from `p` to the segment `a`–`b`.
#[inline]
pub fn point_segment_dist2<P: Point>(p: P, a: P, b: P) -> f64 {
    let ab = b - a;
    let l = ab.length_squared();
    let t = if l > 0.0 {
        ((p - a).dot(ab) / l).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t).distance_squared(p)
}

/// Least squared distance from an end point of one segment (`a`–`b`, `c`–`d`) to the other:
/// the distance of two segments that do not cross.
#[inline]
pub fn end_points_dist2(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> f64 {
    point_segment_dist2(a, c, d)
        .min(point_segment_dist2(b, c, d))
        .min(point_segment_dist2(c, a, b))
        .min(point_segment_dist2(d, a, b))
}

/// Orientation of `c` against the line `a`→`b`: positive on the left, negative on the right,
/// zero on it (twice the signed area of the triangle).
#[inline]
pub fn orient2(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Do segments `ab` and `cd` cross at a point interior to both (touching does not count)?
#[inline]
pub fn cross_properly(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o1 = orient2(a, b, c);
    let o2 = orient2(a, b, d);
    let o3 = orient2(c, d, a);
    let o4 = orient2(c, d, b);
    ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0))
        && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0))
}

/// Squared distance between segments `ab` and `cd`: 0 when they cross properly, else
/// [`end_points_dist2`] (which is 0 when they touch).
#[inline]
pub fn segment_segment_dist2(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> f64 {
    if cross_properly(a, b, c, d) {
        return 0.0;
    }
    end_points_dist2(a, b, c, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_to_segments() {
        let (a, b) = (DVec2::ZERO, DVec2::new(2.0, 0.0));
        assert_eq!(point_segment_dist2(DVec2::new(1.0, 3.0), a, b), 9.0);
        assert_eq!(point_segment_dist2(DVec2::new(5.0, 4.0), a, b), 25.0);
        assert_eq!(point_segment_dist2(DVec2::new(1.0, 1.0), a, a), 2.0);
        let d3 = point_segment_dist2(DVec3::new(1.0, 1.0, 1.0), DVec3::ZERO, DVec3::X * 2.0);
        assert_eq!(d3, 2.0);
        // Crossing, touching, apart.
        let (c, d) = (DVec2::new(1.0, -1.0), DVec2::new(1.0, 1.0));
        assert_eq!(segment_segment_dist2(a, b, c, d), 0.0);
        assert_eq!(segment_segment_dist2(a, b, DVec2::new(2.0, 0.0), d), 0.0);
        let e = DVec2::new(3.0, 1.0);
        assert_eq!(segment_segment_dist2(a, b, e, e + DVec2::Y), 2.0);
    }
}
