//! Shapes of the nest stage: an item's rings turned by an [`Orient`] and shifted so that their
//! bounding box starts at the origin, with the segments, edge midpoints and poles the
//! collision test and the overlap proxy read; a [`Placed`] shape; the bounding-box test that
//! filters pairs; the material test (inside the outer ring, outside every hole).
//!
//! Choices: rotations by a multiple of 90° are exact ([`rotor`]), so that rectangles stay edge
//! to edge; a mirror reverses the rings' point order, which is undone so that the outer ring
//! stays counter-clockwise; the poles are also kept in fixed-size lanes ([`PoleLanes`]) for
//! the vectorised overlap proxy; a shape of many segments lists them by grid cell
//! ([`SegIndex`]), so that the collision test of two large pieces (a pattern piece's outline
//! has thousands) looks at the pairs that can meet rather than at all of them.

use crate::geom::polygon;
use crate::geom::segment::point_segment_dist2;
use glam::DVec2;
use std::sync::Arc;

/// Rotation (counter-clockwise) after an optional mirror `x → −x`.
///
/// The one angle of the stage kept in degrees: the search draws and perturbs orientations in
/// degrees (a uniform draw below 360, a turn by up to ±10°, reduced modulo 360), multiples of
/// 90° are recognised exactly there (`rotor`), and ESICUP instances and solutions give
/// degrees; the layout's [`crate::nest::Placement::rotation`] is in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orient {
    /// Degrees, counter-clockwise.
    pub angle_deg: f64,
    pub mirror: bool,
}

/// Rotation by `deg` degrees, exact for multiples of 90°.
pub(crate) fn rotor(deg: f64) -> DVec2 {
    let q = deg.rem_euclid(360.0);
    if q == 0.0 {
        DVec2::new(1.0, 0.0)
    } else if q == 90.0 {
        DVec2::new(0.0, 1.0)
    } else if q == 180.0 {
        DVec2::new(-1.0, 0.0)
    } else if q == 270.0 {
        DVec2::new(0.0, -1.0)
    } else {
        DVec2::from_angle(deg.to_radians())
    }
}

impl Orient {
    /// The point turned (mirror first, then rotation).
    pub fn apply(&self, p: DVec2) -> DVec2 {
        let p = if self.mirror {
            DVec2::new(-p.x, p.y)
        } else {
            p
        };
        rotor(self.angle_deg).rotate(p)
    }
}

/// An item turned by an orientation and shifted so that its bounding box starts at 0.
#[derive(Debug, Clone)]
pub(crate) struct Shape {
    pub orient: Orient,
    /// Rings, outer first; a mirror reverses their order of points, which is undone so that
    /// the outer ring stays counter-clockwise.
    pub rings: Vec<Vec<DVec2>>,
    pub segs: Vec<[DVec2; 2]>,
    /// Edge midpoints (probes for the zero-spacing containment test).
    pub mids: Vec<DVec2>,
    pub poles: Vec<(DVec2, f64)>,
    /// The poles again, one array per coordinate, padded with empty circles far away, for
    /// the vectorised [`super::overlap_proxy`].
    pub lanes: PoleLanes,
    pub size: DVec2,
    /// The segments by grid cell, for a shape with more than [`INDEX_SEGS`] of them.
    pub index: Option<SegIndex>,
    /// Area of the material.
    pub area: f64,
    /// Add to a turned item point to get the shape point: `shape = orient(q) + shift`.
    pub shift: DVec2,
}

impl Shape {
    /// Turn an item's rings and poles.
    pub(crate) fn new(rings: &[Vec<DVec2>], poles: &[(DVec2, f64)], orient: Orient) -> Shape {
        let mut turned: Vec<Vec<DVec2>> = rings
            .iter()
            .map(|r| r.iter().map(|p| orient.apply(*p)).collect())
            .collect();
        if orient.mirror {
            for r in &mut turned {
                r.reverse();
            }
        }
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for p in turned.first().into_iter().flatten() {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        if !lo.is_finite() {
            lo = DVec2::ZERO;
            hi = DVec2::ZERO;
        }
        let shift = -lo;
        for r in &mut turned {
            for p in r.iter_mut() {
                *p += shift;
            }
        }
        let mut segs = Vec::new();
        let mut mids = Vec::new();
        for r in &turned {
            for k in 0..r.len() {
                let (a, b) = (r[k], r[(k + 1) % r.len()]);
                segs.push([a, b]);
                mids.push((a + b) * 0.5);
            }
        }
        let poles: Vec<(DVec2, f64)> = poles
            .iter()
            .map(|(c, r)| (orient.apply(*c) + shift, *r))
            .collect();
        let lanes = PoleLanes::new(&poles);
        let area = turned.iter().map(|r| polygon::signed_area(r)).sum();
        let size = hi - lo;
        let index = (segs.len() > INDEX_SEGS).then(|| SegIndex::new(&segs, size));
        Shape {
            orient,
            rings: turned,
            segs,
            mids,
            poles,
            lanes,
            size,
            index,
            area,
            shift,
        }
    }

    /// Is `p` (in the shape's frame) in its material: [`in_material`] of its rings, the same
    /// answer to the bit. With an index only the segments listed in the cells along the ray
    /// from `p` (from a cell before it) to the right are looked at: a segment that crosses the
    /// ray there has its box, and so its cells, on the ray, and the crossing is computed as
    /// `polygon::contains` computes it, from the segment's end.
    pub(crate) fn in_material(&self, p: DVec2) -> bool {
        let Some(index) = &self.index else {
            return in_material(&self.rings, p);
        };
        if self.rings.is_empty() {
            return false;
        }
        let mut near = Vec::new();
        let lo = DVec2::new(p.x - index.cell, p.y);
        let hi = DVec2::new(p.x.max(self.size.x) + index.cell, p.y);
        index.query(lo, hi, &mut near);
        // Each ring's segments end where its points do in `segs`, ring after ring.
        let ends: Vec<usize> = self
            .rings
            .iter()
            .scan(0, |n, r| {
                *n += r.len();
                Some(*n)
            })
            .collect();
        let mut odd = vec![false; self.rings.len()];
        for &k in &near {
            let k = k as usize;
            // `contains` walks each edge from its end back to its start.
            let [b, a] = self.segs[k];
            if (a.y > p.y) != (b.y > p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if p.x < x {
                    let r = ends.partition_point(|&e| e <= k);
                    odd[r] = !odd[r];
                }
            }
        }
        odd[0] && !odd[1..].iter().any(|&o| o)
    }
}

/// Shapes with more segments than this list them by grid cell ([`SegIndex`]).
pub(crate) const INDEX_SEGS: usize = 48;

/// A shape's segments listed in every cell of a uniform grid over its box that their own
/// boxes touch (about as many cells as segments, at most 256 along a side); a segment outside
/// the grid is listed in the edge cells nearest it, and a query outside finds those.
#[derive(Debug, Clone)]
pub(crate) struct SegIndex {
    cell: f64,
    nx: usize,
    ny: usize,
    /// Cell `c`'s segments are `ids[start[c]..start[c + 1]]`, in order.
    start: Vec<usize>,
    ids: Vec<u32>,
}

impl SegIndex {
    fn new(segs: &[[DVec2; 2]], size: DVec2) -> SegIndex {
        let n = segs.len().max(1) as f64;
        let side = size.max(DVec2::splat(1e-9));
        let cell = (side.x * side.y / n)
            .sqrt()
            .max(side.max_element() / 256.0)
            .max(1e-9);
        let mut index = SegIndex {
            cell,
            nx: ((side.x / cell).ceil() as usize).clamp(1, 256),
            ny: ((side.y / cell).ceil() as usize).clamp(1, 256),
            start: Vec::new(),
            ids: Vec::new(),
        };
        // Count, then fill: each segment in the cells of its box.
        let mut count = vec![0usize; index.nx * index.ny + 1];
        for [a, b] in segs {
            index.each_cell(a.min(*b), a.max(*b), |c| count[c] += 1);
        }
        let mut start = vec![0usize; count.len()];
        for c in 1..count.len() {
            start[c] = start[c - 1] + count[c - 1];
        }
        let mut ids = vec![0u32; start[count.len() - 1]];
        let mut next = start.clone();
        for (k, [a, b]) in segs.iter().enumerate() {
            index.each_cell(a.min(*b), a.max(*b), |c| {
                ids[next[c]] = k as u32;
                next[c] += 1;
            });
        }
        index.start = start;
        index.ids = ids;
        index
    }

    /// Every cell of the box `lo`–`hi` (clamped to the grid).
    fn each_cell(&self, lo: DVec2, hi: DVec2, mut f: impl FnMut(usize)) {
        if !(lo.is_finite() && hi.is_finite()) {
            return;
        }
        let at = |v: f64, n: usize| ((v / self.cell).floor().max(0.0) as usize).min(n - 1);
        for j in at(lo.y, self.ny)..=at(hi.y, self.ny) {
            for i in at(lo.x, self.nx)..=at(hi.x, self.nx) {
                f(j * self.nx + i);
            }
        }
    }

    /// The segments listed in the cells of the box `lo`–`hi`, each once, in order: every
    /// segment whose box meets it is among them.
    pub(crate) fn query(&self, lo: DVec2, hi: DVec2, out: &mut Vec<u32>) {
        out.clear();
        self.each_cell(lo, hi, |c| {
            out.extend_from_slice(&self.ids[self.start[c]..self.start[c + 1]])
        });
        out.sort_unstable();
        out.dedup();
    }
}

/// A shape at a position (its bounding box's lower-left corner).
#[derive(Debug, Clone)]
pub(crate) struct Placed {
    pub shape: Arc<Shape>,
    pub pos: DVec2,
}

impl Placed {
    pub(crate) fn lo(&self) -> DVec2 {
        self.pos
    }
    pub(crate) fn hi(&self) -> DVec2 {
        self.pos + self.shape.size
    }
}

/// Do the bounding boxes come closer than `s` (touching at exactly `s` is apart)?
#[inline]
pub(crate) fn boxes_near(a: &Shape, pa: DVec2, b: &Shape, pb: DVec2, s: f64) -> bool {
    pa.x + a.size.x + s > pb.x
        && pb.x + b.size.x + s > pa.x
        && pa.y + a.size.y + s > pb.y
        && pb.y + b.size.y + s > pa.y
}

/// Is `p` in the material of the rings (inside the outer ring, outside every hole)?
pub(crate) fn in_material(rings: &[Vec<DVec2>], p: DVec2) -> bool {
    match rings.split_first() {
        Some((outer, holes)) => {
            polygon::contains(outer, p) && !holes.iter().any(|h| polygon::contains(h, p))
        }
        None => false,
    }
}

/// Distance from `p` to the nearest segment.
pub(crate) fn boundary_dist(segs: &[[DVec2; 2]], p: DVec2) -> f64 {
    segs.iter()
        .map(|[a, b]| point_segment_dist2(p, *a, *b))
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

/// Poles in lanes (see [`Shape::lanes`]): at most [`POLE_LANES`], the rest padded with
/// radius-0 circles far away, which add exactly 0 to the proxy.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PoleLanes {
    pub x: [f64; POLE_LANES],
    pub y: [f64; POLE_LANES],
    pub r: [f64; POLE_LANES],
}

/// Lanes of [`PoleLanes`]: the most poles an item keeps ([`super::poles`]).
pub(crate) const POLE_LANES: usize = 12;

impl PoleLanes {
    fn new(poles: &[(DVec2, f64)]) -> PoleLanes {
        let mut l = PoleLanes {
            x: [1e12; POLE_LANES],
            y: [1e12; POLE_LANES],
            r: [0.0; POLE_LANES],
        };
        for (k, (c, r)) in poles.iter().take(POLE_LANES).enumerate() {
            l.x[k] = c.x;
            l.y[k] = c.y;
            l.r[k] = *r;
        }
        l
    }
}
