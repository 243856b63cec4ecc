//! 3D convex hulls with facet adjacency and orientation, and the local-convexity test of an
//! edge (a segment on the convex hull of its neighbourhood) that strips (Wang–Tang §3.2) and
//! boundary triangulations (Rose et al. §2.1, after Frey) share.
//!
//! - [`hull`]: incremental construction (the initial tetrahedron from extreme points, then each
//!   point in input order adds the cone over the horizon of the facets it sees). A point sees a
//!   facet when it lies more than `ε = 1e-9 ×` the bounding-box diagonal above its plane, so
//!   points on or within ε of the hull (coplanar with a facet, or repeated) are left out rather
//!   than making slivers; that is the "robust" part, the predicates are plain `f64`.
//! - Planar input is detected first: when every point lies within ε of the plane through the
//!   initial triangle (extreme point, farthest point, farthest from their line), the hull is the 2D convex polygon in that
//!   plane ([`Hull::planar`], [`Hull::ring`]), with its faces a fan of that polygon on one side.
//! - Facets are triangles wound counter-clockwise seen from outside; [`Hull::neighbours`]
//!   gives, for each facet edge `verts[i] → verts[i+1]`, the facet on its other side
//!   (`usize::MAX` on the rim of a planar hull). [`Hull::coplanar_facets`] merges adjacent
//!   triangles of one plane into one facet (a union-find over the adjacency).
//! - Indices are into the caller's point slice; fewer than three non-collinear points give
//!   `None`. Deterministic: ties go to the lowest index.

use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// A convex hull: triangles over the input points, outward and adjacent.
#[derive(Debug, Clone, PartialEq)]
pub struct Hull {
    /// Triangles, counter-clockwise seen from outside (for a planar hull: about [`Hull::planar`]).
    pub faces: Vec<[usize; 3]>,
    /// Facet across edge `i` (`faces[f][i] → faces[f][(i + 1) % 3]`), `usize::MAX` for none.
    pub neighbours: Vec<[usize; 3]>,
    /// `Some(unit normal)` when all the points lie in one plane (within ε).
    pub planar: Option<DVec3>,
    /// Planar hull: the convex polygon, counter-clockwise about the normal. Empty otherwise.
    pub ring: Vec<usize>,
}

fn tri_normal(p: &[DVec3], f: [usize; 3]) -> DVec3 {
    (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]])
}

/// Convex hull of `points` (see the module doc). `None` for fewer than three non-collinear
/// points or non-finite coordinates.
pub fn hull(points: &[DVec3]) -> Option<Hull> {
    if points.len() < 3 || points.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let (lo, hi) = points.iter().fold((points[0], points[0]), |(lo, hi), p| {
        (lo.min(*p), hi.max(*p))
    });
    let scale = (hi - lo).length();
    if scale <= 0.0 {
        return None;
    }
    let eps = 1e-9 * scale;
    // Initial simplex: extreme x, farthest from it, farthest from their line, farthest from
    // their plane.
    let argmax = |f: &dyn Fn(DVec3) -> f64| -> (usize, f64) {
        let mut best = (0, f64::NEG_INFINITY);
        for (i, p) in points.iter().enumerate() {
            let v = f(*p);
            if v > best.1 {
                best = (i, v);
            }
        }
        best
    };
    let i0 = argmax(&|p| -p.x).0;
    let (i1, d1) = argmax(&|p| p.distance_squared(points[i0]));
    if d1.sqrt() <= eps {
        return None;
    }
    let dir = (points[i1] - points[i0]).normalize();
    let (i2, d2) = argmax(&|p| (p - points[i0]).cross(dir).length());
    if d2 <= eps {
        return None;
    }
    let n0 = (points[i1] - points[i0])
        .cross(points[i2] - points[i0])
        .normalize();
    let (i3, d3) = argmax(&|p| (p - points[i0]).dot(n0).abs());
    if d3 <= eps {
        return Some(planar(points, n0));
    }
    let mut faces: Vec<Option<[usize; 3]>> = Vec::new();
    let mut edge: HashMap<(usize, usize), usize> = HashMap::new();
    let add = |faces: &mut Vec<Option<[usize; 3]>>,
               edge: &mut HashMap<(usize, usize), usize>,
               f: [usize; 3]| {
        let id = faces.len();
        faces.push(Some(f));
        for k in 0..3 {
            edge.insert((f[k], f[(k + 1) % 3]), id);
        }
    };
    let (a, b, c, d) = if (points[i3] - points[i0]).dot(n0) > 0.0 {
        (i0, i2, i1, i3) // i3 above (i0,i1,i2): flip the base so it faces away from i3
    } else {
        (i0, i1, i2, i3)
    };
    for f in [[a, b, c], [a, d, b], [b, d, c], [c, d, a]] {
        add(&mut faces, &mut edge, f);
    }
    let mut units: Vec<DVec3> = faces
        .iter()
        .map(|f| tri_normal(points, f.unwrap_or_default()).normalize())
        .collect();
    for (pi, &p) in points.iter().enumerate() {
        if [i0, i1, i2, i3].contains(&pi) {
            continue;
        }
        let visible: Vec<usize> = (0..faces.len())
            .filter(|&f| faces[f].is_some_and(|t| units[f].dot(p - points[t[0]]) > eps))
            .collect();
        if visible.is_empty() {
            continue;
        }
        let is_vis = |f: usize, vis: &[usize]| vis.binary_search(&f).is_ok();
        let mut horizon = Vec::new();
        for &f in &visible {
            let Some(t) = faces[f] else { continue };
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                match edge.get(&(v, u)) {
                    Some(&g) if is_vis(g, &visible) => {}
                    _ => horizon.push((u, v)),
                }
            }
        }
        for &f in &visible {
            if let Some(t) = faces[f].take() {
                for k in 0..3 {
                    let key = (t[k], t[(k + 1) % 3]);
                    if edge.get(&key) == Some(&f) {
                        edge.remove(&key);
                    }
                }
            }
        }
        for (u, v) in horizon {
            let f = [u, v, pi];
            add(&mut faces, &mut edge, f);
            units.push(tri_normal(points, f).normalize_or_zero());
        }
    }
    let live: Vec<[usize; 3]> = faces.into_iter().flatten().collect();
    Some(with_adjacency(live, None, Vec::new()))
}

fn with_adjacency(faces: Vec<[usize; 3]>, planar: Option<DVec3>, ring: Vec<usize>) -> Hull {
    let mut at: HashMap<(usize, usize), usize> = HashMap::new();
    for (f, t) in faces.iter().enumerate() {
        for k in 0..3 {
            at.insert((t[k], t[(k + 1) % 3]), f);
        }
    }
    let neighbours = faces
        .iter()
        .map(|t| {
            let mut nb = [usize::MAX; 3];
            for (k, slot) in nb.iter_mut().enumerate() {
                if let Some(&g) = at.get(&(t[(k + 1) % 3], t[k])) {
                    *slot = g;
                }
            }
            nb
        })
        .collect();
    Hull {
        faces,
        neighbours,
        planar,
        ring,
    }
}

/// The planar case: Andrew's monotone chain in the plane's own axes.
fn planar(points: &[DVec3], n: DVec3) -> Hull {
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let q: Vec<DVec2> = points
        .iter()
        .map(|p| DVec2::new(p.dot(u), p.dot(v)))
        .collect();
    let mut idx: Vec<usize> = (0..q.len()).collect();
    idx.sort_by(|&a, &b| {
        q[a].x
            .total_cmp(&q[b].x)
            .then(q[a].y.total_cmp(&q[b].y))
            .then(a.cmp(&b))
    });
    let (lo, hi) = q
        .iter()
        .fold((q[0], q[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let tol = 1e-12 * (hi - lo).length_squared();
    let cross = |o: usize, a: usize, b: usize| (q[a] - q[o]).perp_dot(q[b] - q[o]);
    let mut ring: Vec<usize> = Vec::new();
    for pass in 0..2 {
        let start = ring.len();
        let it: Box<dyn Iterator<Item = &usize>> = if pass == 0 {
            Box::new(idx.iter())
        } else {
            Box::new(idx.iter().rev())
        };
        for &i in it {
            while ring.len() >= start + 2
                && cross(ring[ring.len() - 2], ring[ring.len() - 1], i) <= tol
            {
                ring.pop();
            }
            ring.push(i);
        }
        ring.pop();
    }
    let faces: Vec<[usize; 3]> = (1..ring.len().saturating_sub(1))
        .map(|k| [ring[0], ring[k], ring[k + 1]])
        .collect();
    with_adjacency(faces, Some(n), ring)
}

impl Hull {
    /// Outward unit normal of facet `f`.
    pub fn normal(&self, points: &[DVec3], f: usize) -> DVec3 {
        tri_normal(points, self.faces[f]).normalize_or_zero()
    }

    /// Total area of the facets (for a planar hull: the polygon's area).
    pub fn area(&self, points: &[DVec3]) -> f64 {
        self.faces
            .iter()
            .map(|&f| 0.5 * tri_normal(points, f).length())
            .sum()
    }

    /// Facet id of each triangle: adjacent triangles whose normals differ by less than
    /// `angle_tol` radians share one (the lowest triangle index of the group).
    pub fn coplanar_facets(&self, points: &[DVec3], angle_tol: f64) -> Vec<usize> {
        let mut parent: Vec<usize> = (0..self.faces.len()).collect();
        fn root(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        let cos_tol = angle_tol.cos();
        for f in 0..self.faces.len() {
            for &g in &self.neighbours[f] {
                if g == usize::MAX || g < f {
                    continue;
                }
                if self.normal(points, f).dot(self.normal(points, g)) >= cos_tol {
                    let (a, b) = (root(&mut parent, f), root(&mut parent, g));
                    let (lo, hi) = (a.min(b), a.max(b));
                    parent[hi] = lo;
                }
            }
        }
        (0..self.faces.len())
            .map(|f| root(&mut parent, f))
            .collect()
    }
}

/// Whether segment `a b` lies on the convex hull of `{a, b} ∪ others`: some plane through the
/// segment has every other point on one side. Projected along the segment, the other points
/// must fit in a closed half-plane; the test runs on triple products `d̂·(w_s × w_t)` (2D cross
/// products of the projections) with a relative tolerance of 1e-9, so planar neighbourhoods
/// count as convex. Points on the segment's line are ignored; a degenerate segment is not on
/// the hull. (Wang–Tang §3.2 for bridges, Frey's local convexity for boundary triangulations.)
pub fn segment_on_hull(a: DVec3, b: DVec3, others: &[DVec3]) -> bool {
    let d = b - a;
    let l = d.length();
    if l <= 0.0 {
        return false;
    }
    let dh = d / l;
    let mut v: Vec<(DVec3, f64)> = Vec::with_capacity(others.len());
    for &o in others {
        let w = o - a;
        let c = w.cross(dh).length();
        if c > 1e-12 * w.length().max(l) {
            v.push((w, c));
        }
    }
    let k = v.len();
    if k <= 1 {
        return true;
    }
    'outer: for s in 0..k {
        let (mut pos, mut neg) = (true, true);
        for t in 0..k {
            if t == s {
                continue;
            }
            let x = dh.dot(v[s].0.cross(v[t].0));
            let tol = 1e-9 * v[s].1 * v[t].1;
            if x < -tol {
                pos = false;
            }
            if x > tol {
                neg = false;
            }
            if !pos && !neg {
                continue 'outer;
            }
        }
        return true;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_closed_convex(p: &[DVec3], h: &Hull) {
        let f = h.faces.len();
        // Closed 2-manifold: every edge has a neighbour, V − E + F = 2.
        let mut verts: Vec<usize> = h.faces.iter().flatten().copied().collect();
        verts.sort_unstable();
        verts.dedup();
        assert_eq!(verts.len() + f - 3 * f / 2, 2, "Euler characteristic");
        for (i, nb) in h.neighbours.iter().enumerate() {
            for &g in nb {
                assert!(g < f, "face {i} has an open edge");
            }
        }
        // Convex and outward: every point on or below every facet plane.
        let scale = 1e-7;
        for fi in 0..f {
            let n = h.normal(p, fi);
            for q in p {
                assert!(
                    n.dot(*q - p[h.faces[fi][0]]) <= scale,
                    "point above facet {fi}"
                );
            }
        }
    }

    #[test]
    fn hull_of_cube_corners_and_interior_points() {
        let mut p = Vec::new();
        for i in 0..8 {
            p.push(DVec3::new(
                (i & 1) as f64,
                ((i >> 1) & 1) as f64,
                ((i >> 2) & 1) as f64,
            ));
        }
        p.push(DVec3::splat(0.5));
        p.push(DVec3::new(0.5, 0.5, 1.0)); // on a face: left out
        let h = hull(&p).unwrap();
        assert_eq!(h.faces.len(), 12);
        assert!(h.planar.is_none());
        check_closed_convex(&p, &h);
        assert!((h.area(&p) - 6.0).abs() < 1e-12);
        let facets = h.coplanar_facets(&p, 1e-6);
        let mut ids = facets.clone();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), 6, "six square facets");
    }

    #[test]
    fn hull_of_random_sphere_points_is_closed_and_convex() {
        let mut rng = crate::geom::rng::Rng::new(7);
        let mut rnd = || rng.f64();
        let p: Vec<DVec3> = (0..300)
            .map(|_| DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize() * (50.0 + rnd()))
            .collect();
        let h = hull(&p).unwrap();
        check_closed_convex(&p, &h);
    }

    #[test]
    fn planar_points_in_any_orientation_give_a_polygon() {
        let rot = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let sq = [
            (0.0, 0.0),
            (2.0, 0.0),
            (1.0, 1.0), // inside
            (2.0, 2.0),
            (0.0, 2.0),
            (1.0, 0.0), // on an edge
        ];
        let p: Vec<DVec3> = sq
            .iter()
            .map(|&(x, y)| rot * DVec3::new(x, y, 0.0) + DVec3::new(5.0, -3.0, 9.0))
            .collect();
        let h = hull(&p).unwrap();
        let n = h.planar.expect("planar");
        assert!((n.dot(rot * DVec3::Z).abs() - 1.0).abs() < 1e-12);
        let mut ring = h.ring.clone();
        ring.sort_unstable();
        assert_eq!(ring, vec![0, 1, 3, 4]);
        assert!((h.area(&p) - 4.0).abs() < 1e-9);
        assert!(hull(&p[..2]).is_none());
        let line: Vec<DVec3> = (0..5).map(|i| DVec3::splat(i as f64)).collect();
        assert!(hull(&line).is_none());
    }

    #[test]
    fn nearly_planar_saddle_is_a_closed_hull() {
        let p: Vec<DVec3> = (0..40)
            .map(|k| {
                let t = k as f64 / 40.0 * std::f64::consts::TAU;
                DVec3::new(100.0 * t.cos(), 100.0 * t.sin(), 1e-3 * (2.0 * t).cos())
            })
            .collect();
        let h = hull(&p).unwrap();
        assert!(h.planar.is_none());
        check_closed_convex(&p, &h);
    }

    #[test]
    fn segment_on_hull_matches_simple_cases() {
        let a = DVec3::ZERO;
        let b = DVec3::X;
        // Neighbours all above the xy plane: on the hull.
        let up = [DVec3::new(0.0, 1.0, 1.0), DVec3::new(1.0, -1.0, 1.0)];
        assert!(segment_on_hull(a, b, &up));
        // Four neighbours around the segment: inside.
        let around = [DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
        assert!(!segment_on_hull(a, b, &around));
        // Planar neighbourhood on both sides: on the hull (the plane itself supports it).
        assert!(segment_on_hull(a, b, &[DVec3::Y, -DVec3::Y]));
        assert!(!segment_on_hull(a, a, &up));
    }
}
