//! Poles of inaccessibility of an item, after sparrow (Gardeyn, Vanden Berghe, Wauters, "An
//! open-source heuristic to reboot 2D nesting research", 2025, arXiv:2509.13329): the shape is
//! approximated by a set of disjoint inscribed circles, the largest inscribed circle first,
//! then the largest circle in what remains, and so on. [`super::overlap`] measures overlap
//! with them.
//!
//! Choices where the paper is silent: at most [`POLE_LANES`] (12) poles per item; a pole
//! smaller than 8 % of the first ends the list; the poles are found on a grid of about 4000
//! points (at most 400 × 400) refined by pattern search; a shape thinner than the grid gets
//! one tiny pole at a material point.

use super::shape::{boundary_dist, in_material, POLE_LANES};
use crate::geom::polygon;
use glam::DVec2;

/// Poles of inaccessibility of a polygon with holes: disjoint inscribed circles, largest
/// first (see the module docs).
pub(crate) fn poles(rings: &[Vec<DVec2>]) -> Vec<(DVec2, f64)> {
    const MAX_POLES: usize = POLE_LANES;
    let Some(outer) = rings.first() else {
        return vec![];
    };
    let mut segs = Vec::new();
    for r in rings {
        for k in 0..r.len() {
            segs.push([r[k], r[(k + 1) % r.len()]]);
        }
    }
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in outer {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let size = hi - lo;
    if !(size.x > 0.0 && size.y > 0.0) {
        return vec![];
    }
    let area: f64 = rings
        .iter()
        .map(|r| polygon::signed_area(r))
        .sum::<f64>()
        .abs()
        .max(1e-12);
    let h = (area / 4000.0).sqrt().max(size.max_element() / 300.0);
    let nx = ((size.x / h).ceil() as usize).clamp(1, 400);
    let ny = ((size.y / h).ceil() as usize).clamp(1, 400);
    let mut pts: Vec<(DVec2, f64)> = Vec::new();
    for i in 0..nx {
        for j in 0..ny {
            let p = lo + DVec2::new((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
            if in_material(rings, p) {
                pts.push((p, boundary_dist(&segs, p)));
            }
        }
    }
    let value = |p: DVec2, d0: f64, poles: &[(DVec2, f64)]| {
        poles
            .iter()
            .map(|(c, r)| c.distance(p) - r)
            .fold(d0, f64::min)
    };
    let mut out: Vec<(DVec2, f64)> = Vec::new();
    while out.len() < MAX_POLES {
        let mut best = (DVec2::ZERO, f64::NEG_INFINITY);
        for (p, d0) in &pts {
            let v = value(*p, *d0, &out);
            if v > best.1 {
                best = (*p, v);
            }
        }
        if best.1 <= 0.0 {
            break;
        }
        // Pattern search from the best grid point.
        let mut step = h * 0.5;
        while step > h / 64.0 {
            let mut moved = false;
            for dir in [DVec2::X, DVec2::NEG_X, DVec2::Y, DVec2::NEG_Y] {
                let q = best.0 + dir * step;
                if in_material(rings, q) {
                    let v = value(q, boundary_dist(&segs, q), &out);
                    if v > best.1 {
                        best = (q, v);
                        moved = true;
                    }
                }
            }
            if !moved {
                step *= 0.5;
            }
        }
        if let Some((_, r0)) = out.first() {
            if best.1 < 0.08 * r0 {
                break;
            }
        }
        out.push(best);
    }
    if out.is_empty() {
        // Degenerate (thinner than the grid): one tiny pole at a material point, if any.
        let c = pts.first().map(|p| p.0).unwrap_or((lo + hi) * 0.5);
        out.push((c, h * 0.1));
    }
    out
}
