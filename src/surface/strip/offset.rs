//! A strip moved by a distance along its surface normals (a sheet's thickness: the fittings
//! build the inside and outside of a blank from it, so both end on the same planes), and how far
//! inward a strip can be offset before its rings fold.

use super::{Step, Strip};
use crate::geom::mesh::newell;
use glam::DVec3;

impl Strip {
    /// The strip moved by `delta` mm against the surface normal (toward the inside, for the
    /// neutral surface of sheet metal). Closed curves stay in their (Newell) plane: each bank
    /// edge moves within it to where the plane of its BBT triangle, moved by `delta`, cuts it,
    /// and each vertex goes to where its two moved edges meet (a polygon offset with one
    /// distance per edge, so straight sides stay straight and corners stay sharp); the two
    /// copies of the seam vertex stay together. Open curves: each vertex moves along its
    /// area-weighted vertex normal.
    pub fn offset(&self, steps: &[Step], delta: f64) -> Strip {
        if delta == 0.0 {
            return self.clone();
        }
        let (m, n) = (self.m(), self.n());
        let ring = |i: usize, len: usize| if self.closed && i + 1 == len { 0 } else { i };
        let mut np = vec![DVec3::ZERO; m];
        let mut nq = vec![DVec3::ZERO; n];
        // Normal of the triangle on each bank edge.
        let mut edge_p = vec![DVec3::ZERO; m];
        let mut edge_q = vec![DVec3::ZERO; n];
        let (mut i, mut j) = (0, 0);
        for s in steps {
            let (nn, a) = self.tri_step(i, j, *s);
            let w = nn * a;
            match s {
                Step::P => edge_p[i] = nn,
                Step::Q => edge_q[j] = nn,
            }
            match s {
                Step::P => {
                    np[ring(i, m)] += w;
                    np[ring(i + 1, m)] += w;
                    nq[ring(j, n)] += w;
                    i += 1;
                }
                Step::Q => {
                    np[ring(i, m)] += w;
                    nq[ring(j, n)] += w;
                    nq[ring(j + 1, n)] += w;
                    j += 1;
                }
            }
        }
        let plane = |pts: &[DVec3]| -> Option<DVec3> {
            if self.closed {
                let nn = newell(&pts[..pts.len() - 1]);
                (nn.length() > 0.0).then(|| nn.normalize())
            } else {
                None
            }
        };
        let moved = |pts: &[DVec3], normals: &[DVec3], len: usize| -> Vec<DVec3> {
            let pl = plane(pts);
            (0..len)
                .map(|k| {
                    let nn = normals[ring(k, len)].normalize_or_zero();
                    let u = match pl {
                        Some(big) => (nn - big * nn.dot(big)).normalize_or_zero(),
                        None => nn,
                    };
                    let c = u.dot(nn);
                    if c > 0.05 {
                        pts[k] - u * (delta / c)
                    } else {
                        pts[k] - nn * delta
                    }
                })
                .collect()
        };
        let planar = |pts: &[DVec3], edges: &[DVec3], normals: &[DVec3], len: usize| {
            plane(pts)
                .and_then(|big| offset_ring(pts, edges, big, delta))
                .unwrap_or_else(|| moved(pts, normals, len))
        };
        Strip {
            p: planar(&self.p, &edge_p, &np, m),
            q: planar(&self.q, &edge_q, &nq, n),
            closed: self.closed,
        }
    }

    /// Smallest in-plane distance from a closed curve's vertices to its centroid (mm): how
    /// far the curve can move inward before it collapses; infinite for open strips.
    pub fn inner_reach(&self) -> f64 {
        if !self.closed {
            return f64::INFINITY;
        }
        let reach = |pts: &[DVec3]| {
            let c = pts[..pts.len() - 1].iter().copied().sum::<DVec3>() / (pts.len() - 1) as f64;
            pts.iter()
                .map(|x| x.distance(c))
                .fold(f64::INFINITY, f64::min)
        };
        reach(&self.p).min(reach(&self.q))
    }
}

/// A closed polyline (last point repeating the first) lying in the plane of normal `big`,
/// offset in that plane: edge k moves by `delta / cos` toward `−u`, where `u` is its
/// triangle's normal `edges[k]` projected into the plane; vertices go to where consecutive
/// moved edges meet (onto the moved edge when the two are parallel). `None` when an edge has no
/// usable triangle normal.
fn offset_ring(pts: &[DVec3], edges: &[DVec3], big: DVec3, delta: f64) -> Option<Vec<DVec3>> {
    use glam::DVec2;
    let r = pts.len().checked_sub(1)?;
    if r < 3 {
        return None;
    }
    let (a, b) = big.any_orthonormal_pair();
    let to2 = |x: DVec3| DVec2::new(x.dot(a), x.dot(b));
    let mut lines = Vec::with_capacity(r);
    for k in 0..r {
        let nn = edges[k].normalize_or_zero();
        let u = (nn - big * nn.dot(big)).normalize_or_zero();
        let c = u.dot(nn);
        if c < 0.05 {
            return None;
        }
        let x = to2(pts[k] - u * (delta / c));
        let e = to2(pts[k + 1] - pts[k]);
        if e.length_squared() <= 0.0 {
            return None;
        }
        lines.push((x, e));
    }
    let mut out = Vec::with_capacity(pts.len());
    for k in 0..r {
        let (x1, e1) = lines[(k + r - 1) % r];
        let (x2, e2) = lines[k];
        let det = e1.perp_dot(e2);
        let v = to2(pts[k]);
        let p = if det.abs() > 1e-6 * e1.length() * e2.length() {
            x1 + e1 * ((x2 - x1).perp_dot(e2) / det)
        } else {
            x2 + e2 * ((v - x2).dot(e2) / e2.length_squared())
        };
        let dv = p - v;
        out.push(pts[k] + a * dv.x + b * dv.y);
    }
    out.push(out[0]);
    Some(out)
}
