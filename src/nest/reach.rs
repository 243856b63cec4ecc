//! What the nest places for a piece: the polygon that holds everything the cutter will do
//! to it. That is the cut outline (`outline`), unless a stroke of the piece (a fold's end, a
//! seam id, a notch, a label) lies outside it — cleaning and simplifying the outline can move
//! it past marks that stay where the seam was — and then it is the outline grown by how far the
//! farthest such point lies outside ([`reach`]), so that the margins and the spacing the nest
//! keeps hold for every stroke, and [`super::verify`] checks exactly what was nested.
//!
//! Choices: a point counts as outside when the even-odd test says so and it is farther than
//! [`SLACK_MM`] from the outline (the outline went through polygon booleans, which snap to a
//! grid of about 1e-6 mm, so a stroke ending on it may stand a rounding step outside); the offset is mitred ([`crate::geom::boolean::offset`]), and
//! grown again (doubled, a few times) in the rare case a bevelled sharp corner leaves a point
//! out; pieces with nothing outside are nested as they are, unchanged.

use crate::geom::{boolean, polygon};
use crate::pattern::Piece;
use glam::DVec2;

/// How far (mm) a point may lie outside what was nested and still count as on it: rounding of
/// the outline's booleans, far below a plotter unit (0.025 mm).
pub const SLACK_MM: f64 = 1e-4;

/// Rows of an outline's edges, for even-odd tests of many points against it.
struct Rows {
    lo: f64,
    h: f64,
    rows: Vec<Vec<(DVec2, DVec2)>>,
}

impl Rows {
    fn new(rings: &[Vec<DVec2>]) -> Option<Rows> {
        let (lo, hi) = polygon::bounds(rings.iter().flatten().copied())?;
        let n: usize = rings.iter().map(|r| r.len()).sum();
        let count = ((n as f64).sqrt().ceil() as usize).clamp(1, 4096);
        let h = ((hi.y - lo.y) / count as f64).max(f64::MIN_POSITIVE);
        let mut rows = vec![Vec::new(); count];
        for r in rings {
            for i in 0..r.len() {
                let (a, b) = (r[i], r[(i + 1) % r.len()]);
                let (y0, y1) = (a.y.min(b.y), a.y.max(b.y));
                let r0 = (((y0 - lo.y) / h).floor().max(0.0) as usize).min(count - 1);
                let r1 = (((y1 - lo.y) / h).floor().max(0.0) as usize).min(count - 1);
                for row in &mut rows[r0..=r1] {
                    row.push((a, b));
                }
            }
        }
        Some(Rows { lo: lo.y, h, rows })
    }

    /// Even-odd containment (as [`polygon::contains`]).
    fn contains(&self, p: DVec2) -> bool {
        let k = (p.y - self.lo) / self.h;
        if k.is_nan() || k < 0.0 || k as usize > self.rows.len() {
            return false;
        }
        let row = &self.rows[(k as usize).min(self.rows.len() - 1)];
        let mut inside = false;
        for &(a, b) in row {
            if (a.y > p.y) != (b.y > p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if p.x < x {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

/// Distance from `p` to the nearest edge of `rings`.
fn distance(rings: &[Vec<DVec2>], p: DVec2) -> f64 {
    rings
        .iter()
        .flat_map(|r| {
            (0..r.len()).map(move |i| polygon::segment_distance(p, r[i], r[(i + 1) % r.len()]))
        })
        .fold(f64::INFINITY, f64::min)
}

/// The points of `piece` outside the cut outline `rings` (see the module doc).
fn outside(piece: &Piece, rings: &[Vec<DVec2>]) -> Vec<DVec2> {
    let Some(rows) = Rows::new(rings) else {
        return Vec::new();
    };
    piece
        .points()
        .filter(|p| p.is_finite() && !rows.contains(*p) && distance(rings, *p) > SLACK_MM)
        .collect()
}

/// How far (mm) the farthest stroke point of `piece` lies outside its cut outline; 0 when
/// none does.
pub fn reach(piece: &Piece) -> f64 {
    let rings: Vec<Vec<DVec2>> = piece
        .outline
        .iter()
        .filter(|r| r.len() >= 3)
        .cloned()
        .collect();
    outside(piece, &rings)
        .into_iter()
        .map(|p| distance(&rings, p))
        .fold(0.0, f64::max)
}

/// The rings the nest places for `piece`: its cut outline, grown to hold every stroke when
/// one lies outside it (see the module doc).
pub fn nested_rings(piece: &Piece) -> Vec<Vec<DVec2>> {
    let rings: Vec<Vec<DVec2>> = piece
        .outline
        .iter()
        .filter(|r| r.len() >= 3)
        .cloned()
        .collect();
    let out = outside(piece, &rings);
    if out.is_empty() {
        return rings;
    }
    let far = out.iter().map(|&p| distance(&rings, p)).fold(0.0, f64::max);
    let mut d = far * 1.01 + 1e-6;
    for _ in 0..6 {
        let grown = boolean::offset(&rings, d);
        // The largest part (the outline's own), its holes kept.
        if let Some(shape) = grown
            .into_iter()
            .max_by(|a, b| polygon::signed_area(&a[0]).total_cmp(&polygon::signed_area(&b[0])))
        {
            if let Some(rows) = Rows::new(&shape) {
                if piece
                    .points()
                    .all(|p| !p.is_finite() || rows.contains(p) || distance(&shape, p) <= SLACK_MM)
                {
                    return shape;
                }
            }
        }
        d *= 2.0;
    }
    // Nothing held them: the outline's convex hull with every point, grown.
    let pts: Vec<DVec2> = piece.points().filter(|p| p.is_finite()).collect();
    let hull = polygon::convex_hull(&pts);
    boolean::offset(std::slice::from_ref(&hull), 1e-6)
        .into_iter()
        .next()
        .unwrap_or_else(|| vec![hull])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mark_outside_grows_what_is_nested_to_hold_it() {
        let ring = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(50.0, 0.0),
            DVec2::new(50.0, 20.0),
            DVec2::new(0.0, 20.0),
        ];
        let mut piece = Piece::from_outline(1, "1".into(), ring.clone());
        assert_eq!(reach(&piece), 0.0);
        assert_eq!(nested_rings(&piece), vec![ring]);
        piece.folds.push(crate::pattern::Fold {
            a: DVec2::new(10.0, -0.3),
            b: DVec2::new(10.0, 10.0),
            kind: crate::pattern::FoldKind::Mountain,
            angle: 0.5,
            edge: 0,
            tab: false,
        });
        assert!((reach(&piece) - 0.3).abs() < 1e-12);
        let shape = nested_rings(&piece);
        let rows = Rows::new(&shape).unwrap();
        assert!(piece.points().all(|p| rows.contains(p)));
        let (lo, _) = polygon::bounds(shape.iter().flatten().copied()).unwrap();
        assert!(lo.y < -0.3 && lo.y > -0.4, "{lo}");
    }
}
