//! Polygon booleans and offsets on [`DVec2`] rings, through the `i_overlay` crate (pure Rust,
//! MIT): union, difference, intersection, outward/inward offset of shapes with mitred corners,
//! and the outline of an open polyline of a given width.
//!
//! Why a crate: seam allowances, glue tabs and kerf compensation need offsets and booleans
//! that stay valid on the non-convex, many-vertex outlines an unfolding produces (self-
//! intersections of a naive offset resolved, touching contours merged). `i_overlay` snaps to
//! an integer grid scaled to the inputs' bounds (about 1e-6 mm for a 1 m piece) and resolves
//! everything there, so its results are valid polygons by construction.
//!
//! Conventions (as [`super::polygon`]): a ring has no closing duplicate; a [`Shape`] is an
//! outer ring (counter-clockwise) followed by its holes (clockwise). Inputs are read with the
//! non-zero fill rule, so overlapping input rings of the same orientation simply merge.

use glam::DVec2;
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::mesh::outline::offset::OutlineOffset;
use i_overlay::mesh::stroke::offset::StrokeOffset;
use i_overlay::mesh::style::{LineCap, LineJoin, OutlineStyle, StrokeStyle};

/// An outer ring followed by its holes.
pub type Shape = Vec<Vec<DVec2>>;

fn to_raw(rings: &[Vec<DVec2>]) -> Vec<Vec<[f64; 2]>> {
    rings
        .iter()
        .filter(|r| r.len() >= 3)
        .map(|r| r.iter().map(|p| [p.x, p.y]).collect())
        .collect()
}

fn from_raw(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Vec<Shape> {
    shapes
        .into_iter()
        .map(|s| {
            s.into_iter()
                .map(|r| r.into_iter().map(|p| DVec2::new(p[0], p[1])).collect())
                .collect()
        })
        .collect()
}

fn overlay(a: &[Vec<DVec2>], b: &[Vec<DVec2>], rule: OverlayRule) -> Vec<Shape> {
    let (a, b) = (to_raw(a), to_raw(b));
    if a.is_empty() && b.is_empty() {
        return Vec::new();
    }
    from_raw(a.overlay(&b, rule, FillRule::NonZero))
}

/// Union of two sets of rings.
pub fn union(a: &[Vec<DVec2>], b: &[Vec<DVec2>]) -> Vec<Shape> {
    overlay(a, b, OverlayRule::Union)
}

/// `a` minus `b`.
pub fn difference(a: &[Vec<DVec2>], b: &[Vec<DVec2>]) -> Vec<Shape> {
    if b.is_empty() {
        return overlay(a, &[], OverlayRule::Subject);
    }
    overlay(a, b, OverlayRule::Difference)
}

/// Intersection of two sets of rings.
pub fn intersection(a: &[Vec<DVec2>], b: &[Vec<DVec2>]) -> Vec<Shape> {
    overlay(a, b, OverlayRule::Intersect)
}

/// Grows a shape by `d` mm (shrinks for `d < 0`): the outer ring moves out, holes move in.
/// Corners are mitred; a corner sharper than 30° is bevelled so that a spike never reaches
/// far beyond the offset distance.
pub fn offset(shape: &[Vec<DVec2>], d: f64) -> Vec<Shape> {
    let raw = to_raw(shape);
    if raw.is_empty() || !d.is_finite() {
        return Vec::new();
    }
    if d == 0.0 {
        return from_raw(vec![raw]);
    }
    let style = OutlineStyle::new(d).line_join(LineJoin::Miter(30f64.to_radians()));
    from_raw(raw.outline(&style))
}

/// The region within `d` mm of an open polyline (a band of width `2 d`, flat ends).
pub fn band(path: &[DVec2], d: f64) -> Vec<Shape> {
    if path.len() < 2 || d.is_nan() || d <= 0.0 {
        return Vec::new();
    }
    let raw: Vec<[f64; 2]> = path.iter().map(|p| [p.x, p.y]).collect();
    let style = StrokeStyle::new(2.0 * d)
        .line_join(LineJoin::Miter(30f64.to_radians()))
        .start_cap(LineCap::Butt)
        .end_cap(LineCap::Butt);
    from_raw(raw.stroke(style, false))
}

/// Every ring of a list of shapes, flattened (outer rings and holes alike).
pub fn rings(shapes: Vec<Shape>) -> Vec<Vec<DVec2>> {
    shapes.into_iter().flatten().collect()
}

/// Total signed area of shapes (holes count negative).
pub fn area(shapes: &[Shape]) -> f64 {
    shapes
        .iter()
        .flatten()
        .map(|r| super::polygon::signed_area(r))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(x0, y0),
            DVec2::new(x1, y0),
            DVec2::new(x1, y1),
            DVec2::new(x0, y1),
        ]
    }

    #[test]
    fn booleans_and_offsets_have_the_right_areas() {
        let a = vec![rect(0.0, 0.0, 10.0, 10.0)];
        let b = vec![rect(5.0, 0.0, 15.0, 10.0)];
        assert!((area(&union(&a, &b)) - 150.0).abs() < 1e-6);
        assert!((area(&difference(&a, &b)) - 50.0).abs() < 1e-6);
        assert!((area(&intersection(&a, &b)) - 50.0).abs() < 1e-6);
        // Mitred offset of a square stays a square.
        let grown = offset(&a, 2.0);
        assert_eq!(grown.len(), 1);
        assert!((area(&grown) - 196.0).abs() < 1e-6, "{}", area(&grown));
        // A hole shrinks when the shape grows.
        let ring = vec![
            rect(0.0, 0.0, 20.0, 20.0),
            rect(5.0, 5.0, 15.0, 15.0).into_iter().rev().collect(),
        ];
        let g = offset(&ring, 1.0);
        assert!((area(&g) - (22.0 * 22.0 - 8.0 * 8.0)).abs() < 1e-6);
        // A band around a 10 mm segment.
        let s = band(&[DVec2::ZERO, DVec2::new(10.0, 0.0)], 1.0);
        assert!((area(&s) - 20.0).abs() < 1e-6);
    }
}
