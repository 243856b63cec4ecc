//! 2D polygons: signed area, containment, convex hull, minimum-area bounding rectangle,
//! ear-clipping triangulation, a separating-axis overlap test for triangles, where a line
//! crosses a polygon (`line_crossings`, `line_intervals`), and a ring cut down to a box
//! (`clip_to_box`).
//!
//! Conventions: a polygon is a slice of points without the closing duplicate; counter-clockwise
//! rings have positive area. Overlap tests take a tolerance: shapes that only touch (share an
//! edge or a vertex, or overlap by less than `eps` in depth) do not overlap, which is what a
//! cutter needs (two faces joined along a fold touch but never cover each other).

use glam::DVec2;
use std::borrow::Cow;

/// Signed area (positive for counter-clockwise).
pub fn signed_area(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    let mut s = 0.0;
    for i in 0..n {
        s += poly[i].perp_dot(poly[(i + 1) % n]);
    }
    0.5 * s
}

/// Perimeter of a closed polygon.
pub fn perimeter(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    (0..n).map(|i| poly[i].distance(poly[(i + 1) % n])).sum()
}

/// Axis-aligned bounds (min, max) of points; `None` when empty.
pub fn bounds(points: impl IntoIterator<Item = DVec2>) -> Option<(DVec2, DVec2)> {
    let mut it = points.into_iter();
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

/// The ring cut down to the box `lo`..`hi` (Sutherland–Hodgman, one side of the box at a
/// time): each stretch of the ring beyond a side is replaced by the straight run along that
/// side between where it leaves and comes back. A point strictly inside the box has the same
/// winding number about the result as about the ring (a stretch and the run that replaces
/// it close a loop outside the box), so a boolean under the non-zero rule is the same there
/// with the rings cut down; the result may run back and forth along the sides, and is empty
/// when the ring lies beyond one side. Work linear in the ring's points.
pub fn clip_to_box(ring: &[DVec2], lo: DVec2, hi: DVec2) -> Vec<DVec2> {
    let mut out = ring.to_vec();
    for (axis, bound, below) in [
        (0, lo.x, false),
        (0, hi.x, true),
        (1, lo.y, false),
        (1, hi.y, true),
    ] {
        let coord = |p: DVec2| if axis == 0 { p.x } else { p.y };
        let inside = |p: DVec2| {
            if below {
                coord(p) <= bound
            } else {
                coord(p) >= bound
            }
        };
        let mut next = Vec::with_capacity(out.len());
        for i in 0..out.len() {
            let (a, b) = (out[i], out[(i + 1) % out.len()]);
            if inside(a) {
                next.push(a);
            }
            if inside(a) != inside(b) {
                let t = (bound - coord(a)) / (coord(b) - coord(a));
                let mut x = a + (b - a) * t;
                if axis == 0 {
                    x.x = bound;
                } else {
                    x.y = bound;
                }
                next.push(x);
            }
        }
        out = next;
    }
    out
}

/// Even-odd point-in-polygon test (points on the boundary may go either way).
pub fn contains(poly: &[DVec2], p: DVec2) -> bool {
    let n = poly.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Convex hull, counter-clockwise, without collinear points (Andrew's monotone chain).
pub fn convex_hull(points: &[DVec2]) -> Vec<DVec2> {
    let mut pts: Vec<DVec2> = points.iter().copied().filter(|p| p.is_finite()).collect();
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    hull_of_sorted(pts)
}

/// [`convex_hull`] of finite points already sorted by x, then y (as `total_cmp` orders them):
/// Andrew's monotone chain, without the sort.
pub fn hull_of_sorted(mut pts: Vec<DVec2>) -> Vec<DVec2> {
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2 {
                let a = hull[hull.len() - 2];
                let b = hull[hull.len() - 1];
                if (b - a).perp_dot(p - a) <= 0.0 {
                    hull.pop();
                } else {
                    break;
                }
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Rotation angle (radians) that turns the points so that their axis-aligned bounding box has
/// the least area (rotating calipers over the hull edges), with the longer side along x.
pub fn min_area_rect_angle(points: &[DVec2]) -> f64 {
    hull_rect_angle(&convex_hull(points))
}

/// [`min_area_rect_angle`] of a convex hull as [`convex_hull`] gives it.
pub fn hull_rect_angle(hull: &[DVec2]) -> f64 {
    if hull.len() < 2 {
        return 0.0;
    }
    let mut best = (f64::INFINITY, 0.0);
    for i in 0..hull.len() {
        let d = hull[(i + 1) % hull.len()] - hull[i];
        if d.length_squared() == 0.0 {
            continue;
        }
        // Rotate by -atan2(d): this edge becomes horizontal.
        let angle = -d.y.atan2(d.x);
        let rot = DVec2::from_angle(angle);
        let Some((lo, hi)) = bounds(hull.iter().map(|p| rot.rotate(*p))) else {
            continue;
        };
        let size = hi - lo;
        let area = size.x * size.y;
        // Prefer a strictly smaller area; ties keep the first edge (deterministic).
        if area < best.0 * (1.0 - 1e-12) {
            let angle = if size.y > size.x {
                angle + std::f64::consts::FRAC_PI_2
            } else {
                angle
            };
            best = (area, angle);
        }
    }
    best.1
}

/// The triangles of a triangle, as [`triangulate`] gives them (borrowed: the flattening asks
/// for those of every face many times, and most faces are triangles).
pub const ONE_TRIANGLE: &[[usize; 3]] = &[[0, 1, 2]];

/// Ear-clipping triangulation of a simple polygon (either orientation). Returns index triples
/// in the polygon's own orientation ([`ONE_TRIANGLE`] for a triangle). Falls back to a fan
/// when no ear is found (degenerate input), so it always returns `n - 2` triangles for
/// `n >= 3`.
pub fn triangulate(poly: &[DVec2]) -> Cow<'static, [[usize; 3]]> {
    let n = poly.len();
    if n < 3 {
        return Cow::Borrowed(&[]);
    }
    if n == 3 {
        return Cow::Borrowed(ONE_TRIANGLE);
    }
    let sign = if signed_area(poly) >= 0.0 { 1.0 } else { -1.0 };
    let mut idx: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    while idx.len() > 3 {
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (a, b, c) = (poly[ia], poly[ib], poly[ic]);
            if sign * (b - a).perp_dot(c - b) <= 0.0 {
                continue; // reflex or flat corner
            }
            let tri = [a, b, c];
            let blocked = idx.iter().any(|&j| {
                j != ia && j != ib && j != ic && point_in_triangle_closed(poly[j], &tri, sign)
            });
            if !blocked {
                out.push([ia, ib, ic]);
                idx.remove(k);
                clipped = true;
                break;
            }
        }
        if !clipped {
            for k in 1..idx.len() - 1 {
                out.push([idx[0], idx[k], idx[k + 1]]);
            }
            return Cow::Owned(out);
        }
    }
    out.push([idx[0], idx[1], idx[2]]);
    Cow::Owned(out)
}

fn point_in_triangle_closed(p: DVec2, t: &[DVec2; 3], sign: f64) -> bool {
    (0..3).all(|i| sign * (t[(i + 1) % 3] - t[i]).perp_dot(p - t[i]) >= 0.0)
}

/// Whether two triangles overlap by more than `eps` (separating axis theorem on the six edge
/// normals): touching along an edge or at a vertex is not an overlap.
pub fn triangles_overlap(a: &[DVec2; 3], b: &[DVec2; 3], eps: f64) -> bool {
    for tri in [a, b] {
        for i in 0..3 {
            let d = tri[(i + 1) % 3] - tri[i];
            let len = d.length();
            if len == 0.0 {
                continue;
            }
            let axis = d.perp() / len;
            let (a0, a1) = project(a, axis);
            let (b0, b1) = project(b, axis);
            if a1 <= b0 + eps || b1 <= a0 + eps {
                return false;
            }
        }
    }
    true
}

fn project(t: &[DVec2; 3], axis: DVec2) -> (f64, f64) {
    let p = [t[0].dot(axis), t[1].dot(axis), t[2].dot(axis)];
    (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
}

/// Whether segments `ab` and `cd` cross or touch (closed segments).
pub fn segments_intersect(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o1 = orient(a, b, c);
    let o2 = orient(a, b, d);
    let o3 = orient(c, d, a);
    let o4 = orient(c, d, b);
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return true;
    }
    (o1 == 0.0 && on_segment(a, b, c))
        || (o2 == 0.0 && on_segment(a, b, d))
        || (o3 == 0.0 && on_segment(c, d, a))
        || (o4 == 0.0 && on_segment(c, d, b))
}

fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

fn on_segment(a: DVec2, b: DVec2, p: DVec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Whether a closed ring is simple: no two non-adjacent edges touch or cross (O(n²); for tests
/// and reports, not for hot loops).
pub fn is_simple_ring(ring: &[DVec2]) -> bool {
    let n = ring.len();
    if n < 3 {
        return false;
    }
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        for j in i + 1..n {
            if j == i + 1 || (i == 0 && j == n - 1) {
                continue;
            }
            let (c, d) = (ring[j], ring[(j + 1) % n]);
            if segments_intersect(a, b, c, d) {
                return false;
            }
        }
    }
    true
}

/// Distance from `p` to the segment `a`–`b`.
pub fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    super::segment::point_segment_dist2(p, a, b).sqrt()
}

/// Least distance between the segments `a`–`b` and `c`–`d` (0 when they touch or cross).
pub fn segment_segment_distance(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> f64 {
    if segments_intersect(a, b, c, d) {
        return 0.0;
    }
    super::segment::end_points_dist2(a, b, c, d).sqrt()
}

/// Even-odd containment in a set of rings (an outer ring and its holes).
pub fn contains_rings(rings: &[Vec<DVec2>], p: DVec2) -> bool {
    rings.iter().filter(|r| contains(r, p)).count() % 2 == 1
}

/// Signed distance from `p` to the boundary of a set of rings: positive inside.
pub fn rings_distance(rings: &[Vec<DVec2>], p: DVec2) -> f64 {
    let mut d = f64::INFINITY;
    for r in rings {
        let n = r.len();
        for i in 0..n {
            d = d.min(segment_distance(p, r[i], r[(i + 1) % n]));
        }
    }
    if contains_rings(rings, p) {
        d
    } else {
        -d
    }
}

/// Pole of inaccessibility of a polygon with holes: the inside point farthest from the
/// boundary, and that distance (the radius of the largest inscribed circle), to within
/// `precision` mm. Mapbox's "polylabel" (V. Agafonkin, 2016): best-first search over square
/// cells, pruning a cell when its centre distance plus half its diagonal cannot beat the best.
/// `None` for rings without area.
pub fn pole(rings: &[Vec<DVec2>], precision: f64) -> Option<(DVec2, f64)> {
    use std::cmp::Ordering;
    use std::collections::BinaryHeap;
    let (lo, hi) = bounds(rings.first()?.iter().copied())?;
    let size = hi - lo;
    // polylabel's first grid has cells the size of the shorter side; at most `POLE_GRID`
    // along the longer side, so a needle-thin ring costs no more than a square one.
    const POLE_GRID: f64 = 4096.0;
    let cell = size.min_element().max(size.max_element() / POLE_GRID);
    if cell.is_nan() || cell <= 0.0 || !cell.is_finite() {
        return None;
    }
    struct Cell {
        c: DVec2,
        h: f64,
        d: f64,
        max: f64,
    }
    impl PartialEq for Cell {
        fn eq(&self, o: &Self) -> bool {
            self.max == o.max
        }
    }
    impl Eq for Cell {}
    impl PartialOrd for Cell {
        fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for Cell {
        fn cmp(&self, o: &Self) -> Ordering {
            self.max.total_cmp(&o.max)
        }
    }
    let make = |c: DVec2, h: f64| {
        let d = rings_distance(rings, c);
        Cell {
            c,
            h,
            d,
            max: d + h * std::f64::consts::SQRT_2,
        }
    };
    let mut heap = BinaryHeap::new();
    let h = 0.5 * cell;
    // At most `POLE_GRID` + 1 steps a side: `x += cell` stalls where `cell` is below the
    // spacing of floats at `x`.
    let cap = POLE_GRID as usize + 1;
    let mut x = lo.x;
    let mut i = 0;
    while x < hi.x && i < cap {
        let mut y = lo.y;
        let mut j = 0;
        while y < hi.y && j < cap {
            heap.push(make(DVec2::new(x + h, y + h), h));
            y += cell;
            j += 1;
        }
        x += cell;
        i += 1;
    }
    // Start from the centroid of the outer ring, as polylabel does.
    let outer = &rings[0];
    let a = signed_area(outer);
    let mut best = make(0.5 * (lo + hi), 0.0);
    if a.abs() > 0.0 {
        let n = outer.len();
        let mut c = DVec2::ZERO;
        for i in 0..n {
            let (p, q) = (outer[i], outer[(i + 1) % n]);
            c += (p + q) * p.perp_dot(q);
        }
        let centroid = make(c / (6.0 * a), 0.0);
        if centroid.d > best.d {
            best = centroid;
        }
    }
    let mut steps = 0usize;
    while let Some(cell) = heap.pop() {
        if cell.d > best.d {
            best = Cell { ..cell };
        }
        if cell.max - best.d <= precision || steps > 100_000 {
            continue;
        }
        steps += 1;
        let h = 0.5 * cell.h;
        for (dx, dy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            heap.push(make(cell.c + DVec2::new(dx * h, dy * h), h));
        }
    }
    (best.d > 0.0).then_some((best.c, best.d))
}

/// Where the line `p + t d` crosses edge `edge` of ring `ring`: at `t` along the line, at
/// fraction `u` along the edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineCrossing {
    pub t: f64,
    pub ring: usize,
    pub edge: usize,
    pub u: f64,
}

/// Every crossing of the line `p + t d` (`d` a unit vector) with the edges of a set of rings,
/// sorted along the line. Half-open in the signed offset from the line, so a vertex on it
/// counts once.
pub fn line_crossings(rings: &[Vec<DVec2>], p: DVec2, d: DVec2) -> Vec<LineCrossing> {
    let mut out = Vec::new();
    for (ri, r) in rings.iter().enumerate() {
        let n = r.len();
        for i in 0..n {
            let (a, b) = (r[i], r[(i + 1) % n]);
            let (sa, sb) = (d.perp_dot(a - p), d.perp_dot(b - p));
            if (sa > 0.0) != (sb > 0.0) {
                let u = sa / (sa - sb);
                out.push(LineCrossing {
                    t: (a + (b - a) * u - p).dot(d),
                    ring: ri,
                    edge: i,
                    u,
                });
            }
        }
    }
    out.sort_by(|x, y| x.t.total_cmp(&y.t));
    out
}

/// The intervals of the line `p + t d` (`d` a unit vector) that lie inside a set of rings, as
/// sorted `(t0, t1)` pairs (even-odd rule).
pub fn line_intervals(rings: &[Vec<DVec2>], p: DVec2, d: DVec2) -> Vec<(f64, f64)> {
    line_crossings(rings, p, d)
        .chunks_exact(2)
        .map(|c| (c[0].t, c[1].t))
        .collect()
}

#[cfg(test)]
mod tests {

    /// A comb (concave, its teeth crossing the box's sides) cut down to a box: every point
    /// strictly inside the box is inside the cut ring exactly when it is inside the comb; a
    /// ring round the whole box becomes the box; a ring beyond a side is gone.
    #[test]
    fn a_ring_cut_down_to_a_box_fills_the_box_as_it_did() {
        let mut comb = vec![DVec2::new(0.0, 0.0), DVec2::new(100.0, 0.0)];
        for k in (0..5).rev() {
            let x = 20.0 * k as f64;
            comb.extend([
                DVec2::new(x + 20.0, 80.0),
                DVec2::new(x + 10.0, 80.0),
                DVec2::new(x + 10.0, 20.0),
            ]);
            comb.push(DVec2::new(x, 20.0 + 3.0 * k as f64));
        }
        comb.pop();
        comb.push(DVec2::new(0.0, 80.0));
        let (lo, hi) = (DVec2::new(15.0, 10.0), DVec2::new(72.0, 50.0));
        let cut = clip_to_box(&comb, lo, hi);
        assert!(cut.len() >= 3 && cut.len() < 3 * comb.len());
        let mut inside = 0;
        for i in 1..57 {
            for j in 1..40 {
                let p = lo + DVec2::new(i as f64 + 0.37, j as f64 + 0.61);
                assert!(p.x < hi.x && p.y < hi.y);
                assert_eq!(contains(&cut, p), contains(&comb, p), "at {p}");
                inside += contains(&comb, p) as usize;
            }
        }
        assert!(
            inside > 100 && inside < 56 * 39 - 100,
            "{inside} points inside"
        );
        let square = [
            DVec2::new(-1e3, -1e3),
            DVec2::new(1e3, -1e3),
            DVec2::new(1e3, 1e3),
            DVec2::new(-1e3, 1e3),
        ];
        let boxed = clip_to_box(&square, lo, hi);
        assert!((signed_area(&boxed) - (hi - lo).x * (hi - lo).y).abs() < 1e-9);
        let beyond: Vec<DVec2> = square
            .iter()
            .map(|&q| q * 0.01 + DVec2::new(200.0, 0.0))
            .collect();
        assert!(clip_to_box(&beyond, lo, hi).is_empty());
    }

    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn pole_and_line_intervals() {
        // An L shape: the pole is on the diagonal of the corner square, at distance t from both
        // outer sides and √2 (10 − t) from the inner corner: t = 10√2 / (1 + √2).
        let l = vec![vec![
            v(0.0, 0.0),
            v(30.0, 0.0),
            v(30.0, 10.0),
            v(10.0, 10.0),
            v(10.0, 40.0),
            v(0.0, 40.0),
        ]];
        let (c, r) = pole(&l, 0.01).unwrap();
        let t = 10.0 * 2f64.sqrt() / (1.0 + 2f64.sqrt());
        assert!((r - t).abs() < 0.02, "{r}");
        assert!(contains_rings(&l, c));
        // A square with a square hole: the line y = 5 crosses it in two intervals.
        let ring = vec![
            vec![v(0.0, 0.0), v(10.0, 0.0), v(10.0, 10.0), v(0.0, 10.0)],
            vec![v(3.0, 3.0), v(3.0, 7.0), v(7.0, 7.0), v(7.0, 3.0)],
        ];
        let iv = line_intervals(&ring, v(-1.0, 5.0), v(1.0, 0.0));
        assert_eq!(iv, vec![(1.0, 4.0), (8.0, 11.0)]);
        assert!(!contains_rings(&ring, v(5.0, 5.0)));
        let (c, r) = pole(&ring, 0.01).unwrap();
        // In a corner: t from two outer sides, √2 (3 − t) from the hole's corner.
        let t = 3.0 * 2f64.sqrt() / (1.0 + 2f64.sqrt());
        assert!((r - t).abs() < 0.02 && contains_rings(&ring, c), "{c} {r}");
    }

    #[test]
    fn the_hull_of_points_sorted_once_is_the_hull_of_any_subset() {
        let mut rng = crate::geom::rng::Rng::new(7);
        // On a coarse grid, so that points repeat and lie in line.
        let mut all: Vec<DVec2> = (0..400)
            .map(|_| v(rng.below(20) as f64, rng.below(12) as f64 * 0.5))
            .collect();
        all.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        for keep in [1, 2, 3, 7] {
            let subset: Vec<DVec2> = all.iter().copied().step_by(keep).collect();
            let mut shuffled = subset.clone();
            rng.shuffle(&mut shuffled);
            let hull = hull_of_sorted(subset);
            assert_eq!(hull, convex_hull(&shuffled));
            assert!(hull.len() >= 4 && signed_area(&hull) > 0.0);
            assert_eq!(hull_rect_angle(&hull), min_area_rect_angle(&shuffled));
        }
        assert_eq!(
            hull_of_sorted(vec![v(1.0, 1.0), v(1.0, 1.0)]),
            vec![v(1.0, 1.0)]
        );
    }

    #[test]
    fn area_hull_and_rect() {
        let sq = [v(0.0, 0.0), v(2.0, 0.0), v(2.0, 1.0), v(0.0, 1.0)];
        assert_eq!(signed_area(&sq), 2.0);
        assert_eq!(perimeter(&sq), 6.0);
        assert!(contains(&sq, v(1.0, 0.5)));
        assert!(!contains(&sq, v(3.0, 0.5)));
        let mut pts = sq.to_vec();
        pts.push(v(1.0, 0.5));
        pts.push(v(1.0, 0.0));
        assert_eq!(convex_hull(&pts).len(), 4);
        // A rectangle 4 x 1 turned by 30 degrees comes back axis aligned, long side along x.
        let r = DVec2::from_angle(0.5);
        let rect: Vec<_> = [v(0.0, 0.0), v(4.0, 0.0), v(4.0, 1.0), v(0.0, 1.0)]
            .iter()
            .map(|p| r.rotate(*p))
            .collect();
        let a = min_area_rect_angle(&rect);
        let back = DVec2::from_angle(a);
        let (lo, hi) = bounds(rect.iter().map(|p| back.rotate(*p))).unwrap();
        let size = hi - lo;
        assert!(
            (size.x - 4.0).abs() < 1e-9 && (size.y - 1.0).abs() < 1e-9,
            "{size}"
        );
    }

    #[test]
    fn ear_clipping_concave() {
        // An L shape: 6 vertices, 4 triangles whose areas add up.
        let l = [
            v(0.0, 0.0),
            v(2.0, 0.0),
            v(2.0, 1.0),
            v(1.0, 1.0),
            v(1.0, 2.0),
            v(0.0, 2.0),
        ];
        let t = triangulate(&l);
        assert_eq!(t.len(), 4);
        let total: f64 = t
            .iter()
            .map(|k| signed_area(&[l[k[0]], l[k[1]], l[k[2]]]))
            .sum();
        assert!((total - 3.0).abs() < 1e-12);
        assert!(t
            .iter()
            .all(|k| signed_area(&[l[k[0]], l[k[1]], l[k[2]]]) > 0.0));
    }

    #[test]
    fn sat_touching_is_not_overlap() {
        let a = [v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)];
        let b = [v(1.0, 0.0), v(0.0, 1.0), v(1.0, 1.0)];
        assert!(!triangles_overlap(&a, &b, 1e-9));
        let c = [v(0.2, 0.2), v(1.0, 0.2), v(0.2, 1.0)];
        assert!(triangles_overlap(&a, &c, 1e-9));
        let far = [v(5.0, 5.0), v(6.0, 5.0), v(5.0, 6.0)];
        assert!(!triangles_overlap(&a, &far, 1e-9));
    }

    #[test]
    fn simple_rings() {
        let sq = [v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)];
        assert!(is_simple_ring(&sq));
        let bow = [v(0.0, 0.0), v(1.0, 1.0), v(1.0, 0.0), v(0.0, 1.0)];
        assert!(!is_simple_ring(&bow));
    }
}
