//! A uniform grid over a box, for finding the items (boxes, segments) a query box or a ray
//! may meet without looking at all of them: at most 128 cells along the box's longer side,
//! none under 0.5 mm. An item is listed in every cell it may touch; one outside the box, in
//! the edge cells nearest it, so a query inside the box still finds it. A query gives
//! candidates, each once, in order; the caller makes the exact test.

use glam::DVec2;

/// A uniform grid of items by their bounds; an item is listed in every cell it may touch.
pub struct Grid {
    lo: DVec2,
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl Grid {
    /// At most 128 cells along the longer side of `lo`–`hi`, none under 0.5 mm.
    pub fn new(lo: DVec2, hi: DVec2) -> Grid {
        let size = (hi - lo).max(DVec2::splat(1e-9));
        let cell = (size.max_element() / 128.0).max(0.5);
        let nx = ((size.x / cell).ceil() as usize).clamp(1, 129);
        let ny = ((size.y / cell).ceil() as usize).clamp(1, 129);
        Grid {
            lo,
            cell,
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
        }
    }

    fn col(&self, x: f64) -> usize {
        (((x - self.lo.x) / self.cell).floor().max(0.0) as usize).min(self.nx - 1)
    }

    fn row(&self, y: f64) -> usize {
        (((y - self.lo.y) / self.cell).floor().max(0.0) as usize).min(self.ny - 1)
    }

    /// Lists item `id` in every cell of the box `lo`–`hi`.
    pub fn insert_box(&mut self, lo: DVec2, hi: DVec2, id: u32) {
        if !(lo.is_finite() && hi.is_finite()) {
            return;
        }
        for i in self.col(lo.x)..=self.col(hi.x) {
            for j in self.row(lo.y)..=self.row(hi.y) {
                self.cells[j * self.nx + i].push(id);
            }
        }
    }

    /// Lists segment `id` in the cells it passes through: column by column, the rows its part
    /// in that column spans.
    pub fn insert_segment(&mut self, a: DVec2, b: DVec2, id: u32) {
        if !(a.is_finite() && b.is_finite()) {
            return;
        }
        let (a, b) = if a.x <= b.x { (a, b) } else { (b, a) };
        let (c0, c1) = (self.col(a.x), self.col(b.x));
        for i in c0..=c1 {
            let x0 = (self.lo.x + i as f64 * self.cell).max(a.x);
            let x1 = (self.lo.x + (i + 1) as f64 * self.cell).min(b.x);
            let y_at = |x: f64| {
                if b.x - a.x > 0.0 {
                    a.y + (b.y - a.y) * ((x - a.x) / (b.x - a.x)).clamp(0.0, 1.0)
                } else {
                    a.y
                }
            };
            let (ya, yb) = if c0 == c1 {
                (a.y, b.y)
            } else {
                (y_at(x0), y_at(x1))
            };
            for j in self.row(ya.min(yb))..=self.row(ya.max(yb)) {
                self.cells[j * self.nx + i].push(id);
            }
        }
    }

    /// The items listed in the cells of the box `lo`–`hi`, each once, in order.
    pub fn query(&self, lo: DVec2, hi: DVec2, out: &mut Vec<u32>) {
        out.clear();
        for i in self.col(lo.x)..=self.col(hi.x) {
            for j in self.row(lo.y)..=self.row(hi.y) {
                out.extend_from_slice(&self.cells[j * self.nx + i]);
            }
        }
        out.sort_unstable();
        out.dedup();
    }
    /// Whether `hit` holds for an item listed in the cells of the box `lo`–`hi`, cell by cell,
    /// stopping at the first (an item in several cells may be tried more than once): what
    /// [`Grid::query`] then a search gives, without gathering and sorting the candidates.
    pub fn any(&self, lo: DVec2, hi: DVec2, mut hit: impl FnMut(u32) -> bool) -> bool {
        for i in self.col(lo.x)..=self.col(hi.x) {
            for j in self.row(lo.y)..=self.row(hi.y) {
                if self.cells[j * self.nx + i].iter().any(|&k| hit(k)) {
                    return true;
                }
            }
        }
        false
    }

    /// The items listed in the cells from `q`'s to the grid's right edge, in `q`'s row, each
    /// once, in order (the candidates a ray from `q` towards +x may cross); false, with `out`
    /// empty, when `q` is outside the grid.
    pub fn ray(&self, q: DVec2, out: &mut Vec<u32>) -> bool {
        out.clear();
        let top = self.lo + DVec2::new(self.nx as f64, self.ny as f64) * self.cell;
        if !(q.cmpge(self.lo).all() && q.cmple(top).all()) {
            return false;
        }
        let j = self.row(q.y);
        for i in self.col(q.x)..self.nx {
            out.extend_from_slice(&self.cells[j * self.nx + i]);
        }
        out.sort_unstable();
        out.dedup();
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_finds_every_segment_a_box_meets() {
        let mut g = Grid::new(DVec2::ZERO, DVec2::splat(1000.0));
        g.insert_segment(DVec2::new(0.0, 0.0), DVec2::new(1000.0, 700.0), 0);
        g.insert_segment(DVec2::new(500.0, 0.0), DVec2::new(500.0, 1000.0), 1);
        let mut out = Vec::new();
        g.query(DVec2::new(499.0, 349.0), DVec2::new(501.0, 351.0), &mut out);
        assert_eq!(out, vec![0, 1]);
        g.query(DVec2::new(900.0, 100.0), DVec2::new(950.0, 150.0), &mut out);
        assert!(out.is_empty(), "{out:?}");
        // `any` tries the same candidates, and stops at the first that holds.
        let (lo, hi) = (DVec2::new(499.0, 349.0), DVec2::new(501.0, 351.0));
        let mut tried = Vec::new();
        assert!(g.any(lo, hi, |k| {
            tried.push(k);
            k == 1
        }));
        assert!(
            tried.contains(&1) && tried.iter().all(|&k| k <= 1),
            "{tried:?}"
        );
        assert!(!g.any(lo, hi, |k| k == 2));
        assert!(!g.any(DVec2::new(900.0, 100.0), DVec2::new(950.0, 150.0), |_| true));
    }
}
