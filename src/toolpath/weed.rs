//! Weed lines for vinyl (and any material whose waste is peeled off the carrier): a border
//! around the used area of a sheet, and straight lines through the waste between the pieces,
//! so that the waste comes off in small parts instead of one sheet that tears the pieces up.
//!
//! What is cut: the rectangle around every piece's outer contour, grown by `clearance`
//! (clamped to the sheet); then horizontal and vertical lines every `step` mm across that
//! rectangle, each cut only where it stays at least `clearance` from every piece (outside the
//! piece, and farther than `clearance` from each edge of its outer contour). So no weed line
//! crosses or touches a piece. Pieces of fewer than 3 points are ignored.
//!
//! Choices (vinyl tools such as Inkcut leave weeding to the user; the figures are flatcut's):
//! a piece's zone is the union, per edge, of the capsule of radius `clearance` around it and
//! of the inside of the contour, intersected with each line exactly (a capsule is convex, so
//! each edge forbids one interval); free runs shorter than `min_length` are dropped (too short
//! to help and a needless blade plunge). Lines are placed at `step`, 2·`step`, … from the
//! rectangle's lower-left corner.

use super::{Stroke, StrokeRole};
use crate::nest::{Layout, Sheet};
use glam::DVec2;

/// How weed lines are laid out (mm).
#[derive(Debug, Clone, PartialEq)]
pub struct WeedOptions {
    /// Least distance from a weed line to any piece.
    pub clearance: f64,
    /// Distance between parallel weed lines.
    pub step: f64,
    /// Shortest free run cut.
    pub min_length: f64,
}

impl Default for WeedOptions {
    fn default() -> Self {
        WeedOptions {
            clearance: 1.0,
            step: 20.0,
            min_length: 2.0,
        }
    }
}

/// The weed lines of one sheet: the border first (closed), then the lines.
pub fn lines(layout: &Layout, sheet: &Sheet, opts: &WeedOptions) -> Vec<Stroke> {
    let rings: Vec<Vec<DVec2>> = sheet
        .pieces
        .iter()
        .filter_map(|&k| {
            let at = layout.placements.get(k)?;
            let ring = layout.pieces.get(k)?.outline.first()?;
            (ring.len() >= 3).then(|| ring.iter().map(|p| at.apply(*p)).collect())
        })
        .collect();
    weed_rings(&rings, sheet.width, sheet.height, opts)
}

/// The weed lines around and between `rings` (outer contours, sheet mm) on a `width` × `height`
/// sheet.
pub(crate) fn weed_rings(
    rings: &[Vec<DVec2>],
    width: f64,
    height: f64,
    opts: &WeedOptions,
) -> Vec<Stroke> {
    let g = if opts.clearance.is_finite() {
        opts.clearance.max(0.0)
    } else {
        0.0
    };
    let Some((lo, hi)) = crate::geom::polygon::bounds(rings.iter().flatten().copied()) else {
        return Vec::new();
    };
    let lo = (lo - DVec2::splat(g)).max(DVec2::ZERO);
    let hi = (hi + DVec2::splat(g)).min(DVec2::new(width, height).max(lo));
    let mut out = vec![Stroke {
        role: StrokeRole::Weed,
        points: vec![lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y), lo],
        closed: true,
        piece: None,
        outer: false,
    }];
    if !(opts.step.is_finite() && opts.step > 0.0) {
        return out;
    }
    // Horizontal lines, then vertical ones.
    for (dir, from, to) in [(DVec2::X, lo.y, hi.y), (DVec2::Y, lo.x, hi.x)] {
        let across = DVec2::new(dir.y, dir.x);
        let (t0, t1) = (lo.dot(dir), hi.dot(dir));
        let mut c = from + opts.step;
        while c < to - 1e-9 {
            let p = across * c;
            for (a, b) in free_runs(rings, p, dir, t0, t1, g) {
                if b - a >= opts.min_length {
                    out.push(Stroke {
                        role: StrokeRole::Weed,
                        points: vec![p + dir * a, p + dir * b],
                        closed: false,
                        piece: None,
                        outer: false,
                    });
                }
            }
            c += opts.step;
        }
    }
    out
}

/// The runs of `p + t dir`, `t0 ≤ t ≤ t1`, farther than `g` from every ring and outside them.
fn free_runs(
    rings: &[Vec<DVec2>],
    p: DVec2,
    dir: DVec2,
    t0: f64,
    t1: f64,
    g: f64,
) -> Vec<(f64, f64)> {
    let mut blocked: Vec<(f64, f64)> = Vec::new();
    for ring in rings {
        blocked.extend(crate::geom::polygon::line_intervals(
            std::slice::from_ref(ring),
            p,
            dir,
        ));
        let n = ring.len();
        for i in 0..n {
            if let Some(iv) = capsule_interval(ring[i], ring[(i + 1) % n], g, p, dir) {
                blocked.push(iv);
            }
        }
    }
    blocked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut free = Vec::new();
    let mut at = t0;
    for (a, b) in blocked {
        if a > at {
            free.push((at, a.min(t1)));
        }
        at = at.max(b);
        if at >= t1 {
            break;
        }
    }
    if at < t1 {
        free.push((at, t1));
    }
    free.retain(|(a, b)| b > a);
    free
}

/// The interval of `t` where `p + t dir` (unit `dir`) is within `g` of the segment `ab`
/// (closed: a point at exactly `g` is blocked), if any.
fn capsule_interval(a: DVec2, b: DVec2, g: f64, p: DVec2, dir: DVec2) -> Option<(f64, f64)> {
    let n = dir.perp();
    // Quick reject: both ends farther than g on the same side of the line.
    let (sa, sb) = (n.dot(a - p), n.dot(b - p));
    if (sa > g && sb > g) || (sa < -g && sb < -g) {
        return None;
    }
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut add = |iv: Option<(f64, f64)>| {
        if let Some((x, y)) = iv {
            lo = lo.min(x);
            hi = hi.max(y);
        }
    };
    // Disks at the ends.
    for c in [a, b] {
        let q = c - p;
        let along = q.dot(dir);
        let off = q.perp_dot(dir);
        let h = g * g - off * off;
        if h >= 0.0 {
            add(Some((along - h.sqrt(), along + h.sqrt())));
        }
    }
    // The band between them: 0 ≤ (x - a)·u ≤ len and |(x - a)·v| ≤ g, x = p + t dir.
    let len = a.distance(b);
    if len > 0.0 {
        let u = (b - a) / len;
        let v = u.perp();
        let band = |c0: f64, c1: f64, lo: f64, hi: f64| -> Option<(f64, f64)> {
            // c0 + c1 t ∈ [lo, hi]
            if c1.abs() < 1e-15 {
                return (c0 >= lo && c0 <= hi).then_some((f64::NEG_INFINITY, f64::INFINITY));
            }
            let (x, y) = ((lo - c0) / c1, (hi - c0) / c1);
            Some((x.min(y), x.max(y)))
        };
        let w = p - a;
        let r1 = band(w.dot(u), dir.dot(u), 0.0, len);
        let r2 = band(w.dot(v), dir.dot(v), -g, g);
        if let (Some(r1), Some(r2)) = (r1, r2) {
            let (x, y) = (r1.0.max(r2.0), r1.1.min(r2.1));
            if x <= y {
                add(Some((x, y)));
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(pts: &[(f64, f64)]) -> Vec<DVec2> {
        pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
    }

    fn square(x: f64, y: f64, s: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(x, y),
            DVec2::new(x + s, y),
            DVec2::new(x + s, y + s),
            DVec2::new(x, y + s),
        ]
    }

    /// No weed line crosses or touches a piece; the waste between the pieces is cut.
    #[test]
    fn weed_lines_keep_clear_of_every_piece() {
        // A triangle, a square with a notch cut in and a diamond, spaced 3 mm and more.
        let rings = vec![
            ring(&[(5.0, 5.0), (60.0, 5.0), (30.0, 50.0)]),
            ring(&[
                (63.0, 5.0),
                (110.0, 5.0),
                (110.0, 60.0),
                (90.0, 60.0),
                (90.0, 20.0),
                (80.0, 20.0),
                (80.0, 60.0),
                (63.0, 60.0),
            ]),
            ring(&[(40.0, 55.0), (55.0, 70.0), (40.0, 85.0), (25.0, 70.0)]),
            square(70.0, 70.0, 20.0),
        ];
        let opts = WeedOptions::default();
        let weeds = weed_rings(&rings, 200.0, 200.0, &opts);
        assert!(weeds.len() > 8, "{} weed strokes", weeds.len());
        assert!(weeds[0].closed);
        let mut least = f64::INFINITY;
        for w in &weeds {
            assert_eq!(w.role, StrokeRole::Weed);
            for s in w.points.windows(2) {
                for r in &rings {
                    for i in 0..r.len() {
                        let d = crate::geom::polygon::segment_segment_distance(
                            s[0],
                            s[1],
                            r[i],
                            r[(i + 1) % r.len()],
                        );
                        least = least.min(d);
                    }
                    // Not inside a piece either.
                    let mid = (s[0] + s[1]) * 0.5;
                    assert!(!crate::geom::polygon::contains(r, mid), "{mid}");
                }
            }
        }
        assert!(
            least >= opts.clearance - 1e-9,
            "a weed line comes {least} mm from a piece"
        );
        // The slot in the second piece (10 mm wide) gets a vertical line down it.
        assert!(weeds.iter().any(|w| {
            let (a, b) = (w.points[0], w.points[1]);
            a.x == b.x && a.x > 80.0 && a.x < 90.0 && a.y.min(b.y) < 25.0
        }));
        // The border holds everything, clear of every piece.
        let (lo, hi) = (weeds[0].points[0], weeds[0].points[2]);
        assert_eq!((lo, hi), (DVec2::new(4.0, 4.0), DVec2::new(111.0, 91.0)));
    }
}
