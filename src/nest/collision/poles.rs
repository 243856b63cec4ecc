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
use crate::geom::segment::point_segment_dist2;
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
    let near = Nearest::new(&segs, lo, hi, 6.0 * h);
    let at = |i: usize, j: usize| lo + DVec2::new((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
    let material = material_on_grid(rings, nx, ny, &at);
    // Each material grid point with its clearance: the distance to the boundary, lowered to
    // the distance to each pole's circle as the poles are found.
    let mut pts: Vec<(DVec2, f64)> = Vec::new();
    for i in 0..nx {
        for j in 0..ny {
            if material[j * nx + i] {
                let p = at(i, j);
                pts.push((p, near.dist(&segs, p)));
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
        if let Some(&(c, r)) = out.last() {
            for (p, v) in &mut pts {
                *v = v.min(c.distance(*p) - r);
            }
        }
        let mut best = (DVec2::ZERO, f64::NEG_INFINITY);
        for &(p, v) in &pts {
            if v > best.1 {
                best = (p, v);
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
                    let v = value(q, near.dist(&segs, q), &out);
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

/// [`in_material`] at every point `at(i, j)` of an `nx` × `ny` grid (index `j * nx + i`), a row
/// at a time: where each ring's edges cross the row, worked out as [`polygon::contains`] does,
/// once per row, then counted on each side of each point (so the same answer to the bit).
fn material_on_grid(
    rings: &[Vec<DVec2>],
    nx: usize,
    ny: usize,
    at: &dyn Fn(usize, usize) -> DVec2,
) -> Vec<bool> {
    let mut out = vec![false; nx * ny];
    let mut xs: Vec<Vec<f64>> = vec![Vec::new(); rings.len()];
    for j in 0..ny {
        let y = at(0, j).y;
        for (r, poly) in rings.iter().enumerate() {
            xs[r].clear();
            let n = poly.len();
            let mut k = n.wrapping_sub(1);
            for i in 0..n {
                let (a, b) = (poly[i], poly[k]);
                if (a.y > y) != (b.y > y) {
                    xs[r].push(a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x));
                }
                k = i;
            }
            xs[r].sort_by(f64::total_cmp);
        }
        // Inside a ring: an odd number of its crossings to the right (`p.x < x`).
        let inside = |r: usize, x: f64| (xs[r].len() - xs[r].partition_point(|&c| c <= x)) % 2 == 1;
        for i in 0..nx {
            let x = at(i, j).x;
            out[j * nx + i] =
                !rings.is_empty() && inside(0, x) && !(1..rings.len()).any(|r| inside(r, x));
        }
    }
    out
}

/// Up to this many segments, measuring every one is quicker than searching the cells.
const FEW_SEGMENTS: usize = 24;

/// The segments of a shape by the cells of a uniform grid over its box, for the distance from
/// a point to the nearest ([`super::shape::boundary_dist`]) without measuring every segment:
/// the cells are searched in square rings around the point's until the nearest found is
/// closer than any farther ring can be. The least of the same distances, so the same figure
/// to the bit.
struct Nearest {
    lo: DVec2,
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl Nearest {
    /// At most 64 × 64 cells of at least `cell` over `lo`–`hi`; each segment is listed in the
    /// cells its box touches.
    fn new(segs: &[[DVec2; 2]], lo: DVec2, hi: DVec2, cell: f64) -> Nearest {
        let size = hi - lo;
        let cell = cell.max(size.max_element() / 64.0).max(f64::MIN_POSITIVE);
        let nx = ((size.x / cell).ceil() as usize).clamp(1, 65);
        let ny = ((size.y / cell).ceil() as usize).clamp(1, 65);
        let mut n = Nearest {
            lo,
            cell,
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
        };
        for (k, [a, b]) in segs.iter().enumerate() {
            let (i0, j0) = n.at(a.min(*b));
            let (i1, j1) = n.at(a.max(*b));
            for i in i0..=i1 {
                for j in j0..=j1 {
                    n.cells[j * nx + i].push(k as u32);
                }
            }
        }
        n
    }

    /// The cell of `p`, clamped to the grid.
    fn at(&self, p: DVec2) -> (usize, usize) {
        let c = ((p - self.lo) / self.cell).floor().max(DVec2::ZERO);
        (
            (c.x as usize).min(self.nx - 1),
            (c.y as usize).min(self.ny - 1),
        )
    }

    /// [`super::shape::boundary_dist`] of `p`.
    fn dist(&self, segs: &[[DVec2; 2]], p: DVec2) -> f64 {
        if segs.len() <= FEW_SEGMENTS {
            return boundary_dist(segs, p);
        }
        let (ci, cj) = self.at(p);
        let mut best = f64::INFINITY;
        let reach = self.nx.max(self.ny);
        for r in 0..=reach {
            let (i0, i1) = (ci.saturating_sub(r), (ci + r).min(self.nx - 1));
            let (j0, j1) = (cj.saturating_sub(r), (cj + r).min(self.ny - 1));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    // The ring only: cells at Chebyshev distance r.
                    if i.abs_diff(ci) != r && j.abs_diff(cj) != r {
                        continue;
                    }
                    for &k in &self.cells[j * self.nx + i] {
                        let [a, b] = segs[k as usize];
                        best = best.min(point_segment_dist2(p, a, b));
                    }
                }
            }
            // Every cell of ring r + 1 is at least r cells away from `p`.
            let beyond = r as f64 * self.cell;
            if best <= beyond * beyond {
                break;
            }
        }
        best.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::rng::Rng;

    #[test]
    fn the_nearest_segment_by_cells_is_the_nearest_of_all() {
        // A star of 300 points with a hole: long and short segments, in and out of the box.
        let mut rng = Rng::new(3);
        let star: Vec<DVec2> = (0..300)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 300.0;
                DVec2::from_angle(a) * rng.range(40.0, 100.0)
            })
            .collect();
        let hole: Vec<DVec2> = (0..5)
            .map(|k| DVec2::from_angle(-(k as f64) * 1.2566) * 10.0)
            .collect();
        let mut segs = Vec::new();
        for r in [&star, &hole] {
            for k in 0..r.len() {
                segs.push([r[k], r[(k + 1) % r.len()]]);
            }
        }
        let (lo, hi) = (DVec2::splat(-100.0), DVec2::splat(100.0));
        for cell in [0.5, 3.0, 50.0, 1e3] {
            let near = Nearest::new(&segs, lo, hi, cell);
            for _ in 0..500 {
                let p = DVec2::new(rng.range(-130.0, 130.0), rng.range(-130.0, 130.0));
                assert_eq!(near.dist(&segs, p), boundary_dist(&segs, p), "{p} {cell}");
            }
        }
        let rings = [star.clone(), hole.clone()];
        let at = |i: usize, j: usize| DVec2::new(i as f64 * 0.73 - 104.0, j as f64 * 1.1 - 101.5);
        let grid = material_on_grid(&rings, 300, 190, &at);
        for j in 0..190 {
            for i in 0..300 {
                assert_eq!(grid[j * 300 + i], in_material(&rings, at(i, j)), "{i} {j}");
            }
        }
        assert!(grid.iter().any(|&m| m) && grid.iter().any(|&m| !m));
        let poles = poles(&[star, hole]);
        assert!(!poles.is_empty() && poles[0].1 > 10.0, "{poles:?}");
    }
}
