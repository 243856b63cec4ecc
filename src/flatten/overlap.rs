//! Triangle-level overlap of flat layouts: which faces of a piece (or of different pieces once
//! nested) cover each other in the plane. Every face is split into triangles (ear clipping) and
//! two triangles of different faces overlap when their interiors intersect: the separating-axis
//! test of [`crate::geom::polygon::triangles_overlap`] on the six edge normals, with a depth
//! below which they only touch. Shared edges and vertices are never overlaps.
//!
//! The broad phase is a uniform grid over the triangles' bounding boxes (cell: the 90th
//! percentile of the boxes' larger side, so a typical triangle covers one to four cells); each
//! pair is tested once, in the cell holding the lower-left corner of the intersection of the
//! two boxes, so the work is about linear in the number of triangles for a layout without
//! pathological slivers, whatever its shape (a long thin piece is no worse than a round one).
//!
//! Depth: [`exact_eps`] is the depth that counts as overlapping when the question is "do the
//! interiors intersect": rounding, not geometry — 1e-9 of the layout's extent (a rigid
//! motion or a solver's output moves a coordinate by a few ulps, never by a millionth of a
//! millimetre on a metre-sized piece). Choices where the sources are silent: the grid cell is
//! capped so that the grid has at most about 4 cells per triangle; pairs come out sorted.

use crate::geom::polygon;
use glam::DVec2;

/// The overlap depth that is rounding, not geometry, for points within `extent` mm of the
/// origin (see the module doc).
pub fn exact_eps(extent: f64) -> f64 {
    1e-9 * extent.max(1.0)
}

/// The larger absolute coordinate of any corner of `faces` (mm); 0 when there is none.
pub fn extent<'a>(faces: impl IntoIterator<Item = &'a [DVec2]>) -> f64 {
    faces
        .into_iter()
        .flat_map(|c| c.iter())
        .filter(|p| p.is_finite())
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max)
}

/// Triangles of flat faces: corner triples, each with the face it belongs to.
pub struct Triangles {
    tris: Vec<[DVec2; 3]>,
    owner: Vec<usize>,
}

impl Triangles {
    /// The triangles of the faces `faces` (face `k` owns its triangles; non-finite faces are
    /// left out).
    pub fn of<'a>(faces: impl IntoIterator<Item = &'a [DVec2]>) -> Self {
        let mut t = Triangles {
            tris: Vec::new(),
            owner: Vec::new(),
        };
        for (k, c) in faces.into_iter().enumerate() {
            t.push(k, c);
        }
        t
    }

    /// An empty set.
    pub fn new() -> Self {
        Triangles {
            tris: Vec::new(),
            owner: Vec::new(),
        }
    }

    /// Add face `owner` with corners `c` (left out when a corner is not finite).
    pub fn push(&mut self, owner: usize, c: &[DVec2]) {
        if c.len() < 3 || c.iter().any(|p| !p.is_finite()) {
            return;
        }
        for t in polygon::triangulate(c) {
            self.tris.push([c[t[0]], c[t[1]], c[t[2]]]);
            self.owner.push(owner);
        }
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// Whether there is no triangle.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Pairs of owners `(a, b)`, `a < b`, with a triangle of `a` and one of `b` overlapping
    /// deeper than `eps`, each pair once, sorted; at most `limit` of them (the first found:
    /// with a limit below the count, which ones is still deterministic). `same(a, b)` false
    /// skips a pair of owners (faces that may overlap, e.g. of different pieces before
    /// nesting).
    pub fn overlapping(
        &self,
        eps: f64,
        limit: usize,
        same: &dyn Fn(usize, usize) -> bool,
    ) -> Vec<(usize, usize)> {
        let n = self.tris.len();
        if n < 2 || limit == 0 {
            return Vec::new();
        }
        let boxes: Vec<(DVec2, DVec2)> = self
            .tris
            .iter()
            .map(|t| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])))
            .collect();
        let (lo, hi) = boxes.iter().fold((boxes[0].0, boxes[0].1), |(l, h), b| {
            (l.min(b.0), h.max(b.1))
        });
        let mut sizes: Vec<f64> = boxes.iter().map(|b| (b.1 - b.0).max_element()).collect();
        sizes.sort_by(f64::total_cmp);
        let span = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        // At most ~4n cells over the whole extent.
        let floor = span / (2.0 * (n as f64).sqrt()).max(1.0);
        let cell = sizes[sizes.len() * 9 / 10]
            .max(floor)
            .max(f64::MIN_POSITIVE);
        let at = |p: DVec2| {
            (
                ((p.x - lo.x) / cell).floor() as i64,
                ((p.y - lo.y) / cell).floor() as i64,
            )
        };
        // (cell, triangle) for every cell a box covers, sorted by cell.
        let mut entries: Vec<((i64, i64), u32)> = Vec::with_capacity(2 * n);
        for (i, b) in boxes.iter().enumerate() {
            let (x0, y0) = at(b.0);
            let (x1, y1) = at(b.1);
            for x in x0..=x1 {
                for y in y0..=y1 {
                    entries.push(((x, y), i as u32));
                }
            }
        }
        entries.sort_unstable();
        let mut out: Vec<(usize, usize)> = Vec::new();
        let mut s = 0;
        while s < entries.len() {
            let mut e = s + 1;
            while e < entries.len() && entries[e].0 == entries[s].0 {
                e += 1;
            }
            let c = entries[s].0;
            for p in s..e {
                let i = entries[p].1 as usize;
                for &(_, j) in &entries[p + 1..e] {
                    let j = j as usize;
                    let (a, b) = (self.owner[i], self.owner[j]);
                    if a == b {
                        continue;
                    }
                    let (bi, bj) = (boxes[i], boxes[j]);
                    let corner = bi.0.max(bj.0);
                    if bi.0.x >= bj.1.x - eps
                        || bj.0.x >= bi.1.x - eps
                        || bi.0.y >= bj.1.y - eps
                        || bj.0.y >= bi.1.y - eps
                        || at(corner) != c
                        || !same(a, b)
                    {
                        continue;
                    }
                    if polygon::triangles_overlap(&self.tris[i], &self.tris[j], eps) {
                        out.push((a.min(b), a.max(b)));
                    }
                }
            }
            s = e;
        }
        out.sort_unstable();
        out.dedup();
        out.truncate(limit);
        out
    }
}

impl Default for Triangles {
    fn default() -> Self {
        Self::new()
    }
}

/// Pairs of faces (indices into `uv`, one corner list per face) of one layout whose interiors
/// intersect deeper than `eps`, sorted, at most `limit`.
pub fn pairs(uv: &[Vec<DVec2>], eps: f64, limit: usize) -> Vec<(usize, usize)> {
    Triangles::of(uv.iter().map(|c| c.as_slice())).overlapping(eps, limit, &|_, _| true)
}

/// Overlapping face pairs inside each island of `flat` (mesh face ids, sorted), deeper than
/// [`exact_eps`]: what must be empty for every piece that is output.
pub fn island_pairs(flat: &super::Flat) -> Vec<Vec<(usize, usize)>> {
    flat.islands
        .iter()
        .map(|faces| {
            let uv: Vec<&[DVec2]> = faces.iter().map(|&f| flat.face_2d[f].as_slice()).collect();
            let eps = exact_eps(extent(uv.iter().copied()));
            let mut p: Vec<(usize, usize)> = Triangles::of(uv)
                .overlapping(eps, usize::MAX, &|_, _| true)
                .into_iter()
                .map(|(a, b)| (faces[a].min(faces[b]), faces[a].max(faces[b])))
                .collect();
            p.sort_unstable();
            p
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> Vec<DVec2> {
        vec![
            DVec2::new(a.0, a.1),
            DVec2::new(b.0, b.1),
            DVec2::new(c.0, c.1),
        ]
    }

    #[test]
    fn shared_edges_and_vertices_are_not_overlaps_crossings_are() {
        let a = tri((0.0, 0.0), (10.0, 0.0), (0.0, 10.0));
        let b = tri((10.0, 0.0), (10.0, 10.0), (0.0, 10.0)); // shares an edge
        let c = tri((10.0, 10.0), (20.0, 10.0), (10.0, 20.0)); // shares a vertex
        let d = tri((1.0, 1.0), (3.0, 1.0), (1.0, 3.0)); // inside a
        let e = tri((9.0, 9.0), (12.0, 9.5), (9.5, 12.0)); // crosses b and c
        let eps = exact_eps(20.0);
        assert!(pairs(&[a.clone(), b.clone(), c.clone()], eps, 10).is_empty());
        assert_eq!(pairs(&[a.clone(), b.clone(), d], eps, 10), vec![(0, 2)]);
        assert_eq!(pairs(&[a, b, c, e], eps, 10), vec![(1, 3), (2, 3)]);
    }

    #[test]
    fn grid_finds_what_all_pairs_find() {
        // A fan of 40 thin triangles wound twice around the origin: every one overlaps the
        // one a turn later; the grid must find exactly the pairs brute force finds.
        let mut uv = Vec::new();
        for k in 0..40 {
            let t0 = k as f64 * 0.3;
            let t1 = t0 + 0.31;
            uv.push(tri(
                (0.0, 0.0),
                (50.0 * t0.cos(), 50.0 * t0.sin()),
                (50.0 * t1.cos(), 50.0 * t1.sin()),
            ));
        }
        let eps = exact_eps(50.0);
        let mut brute = Vec::new();
        for i in 0..uv.len() {
            for j in i + 1..uv.len() {
                let a = [uv[i][0], uv[i][1], uv[i][2]];
                let b = [uv[j][0], uv[j][1], uv[j][2]];
                if polygon::triangles_overlap(&a, &b, eps) {
                    brute.push((i, j));
                }
            }
        }
        assert!(brute.len() > 40, "{}", brute.len());
        assert_eq!(pairs(&uv, eps, usize::MAX), brute);
    }
}
