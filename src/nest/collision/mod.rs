//! Collision detection of the nest stage, in exact `f64` geometry, and the overlap measure the
//! separator minimises.
//!
//! An item is a polygon with holes (outer ring counter-clockwise, holes clockwise). An
//! [`Orient`] (rotation, optional mirror in x first) turns it into a [`Shape`]: the turned
//! rings shifted so that their bounding box starts at the origin, its segments, and its
//! *poles* ([`poles`]). A shape is placed by the position of its bounding box's lower-left
//! corner, so "inside the container" is a box test.
//!
//! Two placed shapes **collide** ([`collide`]) when their material comes closer than the
//! spacing `s`:
//! - `s > 0`: some pair of segments is closer than `s` (segment–segment distance), or one
//!   shape's first pole centre (an interior point) lies in the other's material (inside the
//!   outer ring and outside every hole) — the containment cases;
//! - `s = 0`: some pair of segments crosses properly (touching, collinear overlap and shared
//!   vertices are allowed, so that rectangles tile exactly), or the first pole centre of one
//!   lies in the other's material; when boundaries touch (some orientation test is exactly
//!   zero), every pole centre and edge midpoint is probed, and counts when it lies in the
//!   other's material farther than 1e-9 mm from its boundary (this catches the collinear
//!   "sliding" overlaps that have no proper crossing).
//!
//! A piece inside the hole of another does not collide with it: holes are usable.
//!
//! The files: [`shape`] (orientations, turned shapes, bounding boxes, the material test),
//! [`poles`] (poles of inaccessibility), [`overlap`] (sparrow's pole-based overlap proxy
//! between two colliding shapes). The segment distances are the shared kernel
//! [`crate::geom::segment`].
//!
//! Why not jagua-rs: it computes in `f32` and takes no holes; this engine is exact in `f64`
//! (so a feasible layout needs no safety margin and no separate verification pass), handles
//! holes and spacing directly, and the nesting instances have at most tens of vertices per item,
//! where the quadratic segment test behind a bounding-box filter is cheap (see `benches/nest.rs`).
//! Pattern pieces can have thousands (an unfolded mesh's outline): a shape with many segments
//! lists them by grid cell ([`shape::SegIndex`]), and each of the other shape's segments near it
//! is tested only against those in its cells; the pairs left out would fail the box test, so
//! the answer is the same.

pub(crate) mod overlap;
pub(crate) mod poles;
pub(crate) mod shape;

pub(crate) use overlap::overlap_proxy;
pub(crate) use poles::poles;
pub use shape::Orient;
pub(crate) use shape::{boxes_near, in_material, rotor, Placed, Shape};

use crate::geom::segment::{orient2, segment_segment_dist2};
use glam::DVec2;
use shape::boundary_dist;

/// Exact collision test of shape `a` at `pa` and `b` at `pb` with spacing `s` (see the module
/// docs). `work` counts segment pairs looked at, the search's deterministic clock.
pub(crate) fn collide(a: &Shape, pa: DVec2, b: &Shape, pb: DVec2, s: f64, work: &mut u64) -> bool {
    if !boxes_near(a, pa, b, pb, s) {
        return false;
    }
    *work += (a.segs.len() * b.segs.len()) as u64 / 16 + 4;
    // Work in a's frame.
    let d = pb - pa;
    // Window where both shapes' material can meet.
    let wlo = d.max(DVec2::ZERO) - DVec2::splat(s);
    let whi = (d + b.size).min(a.size) + DVec2::splat(s);
    let s2 = s * s;
    // Zero spacing: do some boundaries touch (a zero orientation)? Only then can material
    // overlap without a proper crossing and without one shape's pole in the other.
    let mut touch = false;
    // One pair of segments (b's in a's frame): true when they are closer than the spacing or
    // cross; `touch` set where an orientation is exactly zero.
    let mut pair = |a0: DVec2, a1: DVec2, alo: DVec2, ahi: DVec2, b0: DVec2, b1: DVec2| {
        let (blo, bhi) = (b0.min(b1), b0.max(b1));
        // Strictly apart only: touching segments must set `touch` below.
        if blo.x > ahi.x + s || blo.y > ahi.y + s || alo.x > bhi.x + s || alo.y > bhi.y + s {
            return false;
        }
        if s > 0.0 {
            return segment_segment_dist2(a0, a1, b0, b1) < s2;
        }
        let o1 = orient2(a0, a1, b0);
        let o2 = orient2(a0, a1, b1);
        let o3 = orient2(b0, b1, a0);
        let o4 = orient2(b0, b1, a1);
        if ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0))
            && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0))
        {
            return true;
        }
        if o1 == 0.0 || o2 == 0.0 || o3 == 0.0 || o4 == 0.0 {
            touch = true;
        }
        false
    };
    // Where b lists its segments by cell, only those near each of a's are looked at: the
    // others fail the box test anyway, and the answer does not depend on the order of pairs.
    let mut near: Vec<u32> = Vec::new();
    let pad = DVec2::splat(s + 1e-6 * (1.0 + d.abs().max_element()));
    for &[a0, a1] in &a.segs {
        let (alo, ahi) = (a0.min(a1), a0.max(a1));
        if ahi.x < wlo.x || ahi.y < wlo.y || alo.x > whi.x || alo.y > whi.y {
            continue;
        }
        let hit = match &b.index {
            Some(index) => {
                index.query(alo - d - pad, ahi - d + pad, &mut near);
                near.iter().any(|&k| {
                    let [b0, b1] = b.segs[k as usize];
                    pair(a0, a1, alo, ahi, b0 + d, b1 + d)
                })
            }
            None => b
                .segs
                .iter()
                .any(|&[b0, b1]| pair(a0, a1, alo, ahi, b0 + d, b1 + d)),
        };
        if hit {
            return true;
        }
    }
    // No boundaries meet: either apart, or one inside the other.
    if s > 0.0 || !touch {
        let inside_b = a.poles.first().is_some_and(|(c, _)| b.in_material(*c - d));
        let inside_a = b.poles.first().is_some_and(|(c, _)| a.in_material(*c + d));
        return inside_b || inside_a;
    }
    *work += ((a.mids.len() + a.poles.len()) * b.segs.len()) as u64 / 8;
    let deep = |sh: &Shape, p: DVec2| sh.in_material(p) && boundary_dist(&sh.segs, p) > 1e-9;
    a.poles
        .iter()
        .map(|(c, _)| *c)
        .chain(a.mids.iter().copied())
        .any(|p| deep(b, p - d))
        || b.poles
            .iter()
            .map(|(c, _)| *c)
            .chain(b.mids.iter().copied())
            .any(|p| deep(a, p + d))
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn rect(w: f64, h: f64) -> Vec<Vec<DVec2>> {
        vec![vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(w, 0.0),
            DVec2::new(w, h),
            DVec2::new(0.0, h),
        ]]
    }

    pub(super) fn shape(rings: Vec<Vec<DVec2>>) -> Shape {
        let p = poles(&rings);
        Shape::new(
            &rings,
            &p,
            Orient {
                angle_deg: 0.0,
                mirror: false,
            },
        )
    }

    #[test]
    fn touching_rectangles_do_not_collide_but_sliding_ones_do() {
        let a = shape(rect(2.0, 1.0));
        let mut w = 0;
        assert!(!collide(
            &a,
            DVec2::ZERO,
            &a,
            DVec2::new(2.0, 0.0),
            0.0,
            &mut w
        ));
        assert!(!collide(
            &a,
            DVec2::ZERO,
            &a,
            DVec2::new(2.0, 1.0),
            0.0,
            &mut w
        ));
        // Same height, overlapping by half: no proper crossing, found by the probes.
        assert!(collide(
            &a,
            DVec2::ZERO,
            &a,
            DVec2::new(1.0, 0.0),
            0.0,
            &mut w
        ));
        assert!(collide(&a, DVec2::ZERO, &a, DVec2::ZERO, 0.0, &mut w));
        // Spacing: 0.5 apart is too close for 0.6, fine for 0.5.
        assert!(collide(
            &a,
            DVec2::ZERO,
            &a,
            DVec2::new(2.5, 0.0),
            0.6,
            &mut w
        ));
        assert!(!collide(
            &a,
            DVec2::ZERO,
            &a,
            DVec2::new(2.5, 0.0),
            0.5,
            &mut w
        ));
    }

    #[test]
    fn a_small_piece_fits_in_a_hole() {
        let mut rings = rect(10.0, 10.0);
        rings.push(vec![
            DVec2::new(2.0, 2.0),
            DVec2::new(2.0, 8.0),
            DVec2::new(8.0, 8.0),
            DVec2::new(8.0, 2.0),
        ]);
        let frame = shape(rings);
        let small = shape(rect(4.0, 4.0));
        let mut w = 0;
        assert!(!collide(
            &frame,
            DVec2::ZERO,
            &small,
            DVec2::new(3.0, 3.0),
            0.5,
            &mut w
        ));
        assert!(collide(
            &frame,
            DVec2::ZERO,
            &small,
            DVec2::new(3.0, 3.0),
            1.5,
            &mut w
        ));
        assert!(collide(
            &frame,
            DVec2::ZERO,
            &small,
            DVec2::new(5.0, 3.0),
            0.0,
            &mut w
        ));
        // The largest pole of the frame lies in its material, not in the hole: in a corner,
        // touching the hole's corner (radius 2√2 / (1 + √2) ≈ 1.17).
        let (c, r) = frame.poles[0];
        assert!(
            in_material(&frame.rings, c) && r > 0.99 && r < 1.18,
            "{c} {r}"
        );
    }

    /// A star of `n` points (radii alternating 10 and 4 mm) about (10, 10).
    fn star(n: usize, turn: f64) -> Vec<Vec<DVec2>> {
        vec![(0..2 * n)
            .map(|k| {
                let a = turn + std::f64::consts::PI * k as f64 / n as f64;
                let r = if k % 2 == 0 { 10.0 } else { 4.0 };
                DVec2::new(10.0, 10.0) + r * DVec2::new(a.cos(), a.sin())
            })
            .collect()]
    }

    /// A shape of many segments says whether a point is in its material through its grid as
    /// the test of every ring does: a star of 80 points with a star-shaped hole of 30,
    /// mirrored and turned, at 3,721 points of a grid over it and beyond, every vertex among
    /// them (the rings' own heights, where a crossing is decided by `>`); both answers occur.
    #[test]
    fn a_shape_of_many_segments_finds_its_material_as_every_ring_does() {
        let mut rings = star(80, 0.1);
        let mut hole: Vec<DVec2> = star(30, 0.2)[0]
            .iter()
            .map(|&p| DVec2::new(10.0, 10.0) + (p - DVec2::new(10.0, 10.0)) * 0.3)
            .collect();
        hole.reverse();
        rings.push(hole);
        let sh = Shape::new(
            &rings,
            &[],
            Orient {
                angle_deg: 33.0,
                mirror: true,
            },
        );
        assert!(sh.index.is_some());
        let mut points: Vec<DVec2> = sh.rings.iter().flatten().copied().collect();
        for i in 0..61 {
            for j in 0..61 {
                points.push(DVec2::new(i as f64, j as f64) * 0.4 - DVec2::splat(2.0));
            }
        }
        let mut seen = [false; 2];
        for p in points {
            let want = in_material(&sh.rings, p);
            assert_eq!(sh.in_material(p), want, "at {p}");
            seen[want as usize] = true;
        }
        assert_eq!(seen, [true, true]);
    }

    /// Shapes with many segments are tested through their grid of segments: on two stars of
    /// 60 and 45 points (120 and 90 segments), at 441 positions from apart to deep inside one
    /// another and at spacings 0, 0.5 and 2 mm, the answer is the one the test of every pair
    /// gives, and both answers occur.
    #[test]
    fn a_shape_of_many_segments_collides_as_with_every_pair_tested() {
        let (a, b) = (shape(star(60, 0.0)), shape(star(45, 0.3)));
        assert!(a.index.is_some() && b.index.is_some());
        let plain = |s: &Shape| Shape {
            index: None,
            ..s.clone()
        };
        let (pa, pb) = (plain(&a), plain(&b));
        let mut seen = [0usize; 2];
        let mut w = 0;
        for i in 0..21 {
            for j in 0..21 {
                let at = DVec2::new(i as f64 - 10.0, j as f64 - 10.0) * 2.1;
                for s in [0.0, 0.5, 2.0] {
                    let fast = collide(&a, DVec2::ZERO, &b, at, s, &mut w);
                    assert_eq!(
                        fast,
                        collide(&pa, DVec2::ZERO, &pb, at, s, &mut w),
                        "{at} {s}"
                    );
                    assert_eq!(
                        collide(&b, at, &a, DVec2::ZERO, s, &mut w),
                        fast,
                        "{at} {s}"
                    );
                    seen[usize::from(fast)] += 1;
                }
            }
        }
        assert!(seen[0] > 100 && seen[1] > 100, "{seen:?}");
    }
}
