//! Checks of the input boundary. The paper assumes a closed, simple polyline (§3: "a closed 3D
//! polyline"); these checks turn every way a user's loops can break that into a message: at
//! least three finite points per loop, no repeated consecutive points (the last against the
//! first included), and no two non-adjacent segments of any loops closer than 1e-9 × the size
//! of the boundary (3D segment distance, so touching counts as crossing).

use super::BoundaryError;
use glam::DVec3;

/// Check loops: at least three finite points, no repeated consecutive points (the last one
/// against the first included).
pub fn check_loops(loops: &[Vec<DVec3>]) -> Result<(), BoundaryError> {
    if loops.is_empty() {
        return Err(BoundaryError::NoLoop);
    }
    for (l, pts) in loops.iter().enumerate() {
        if let Some(i) = pts.iter().position(|p| !p.is_finite()) {
            return Err(BoundaryError::NonFinite { looop: l, point: i });
        }
        if pts.len() < 3 {
            return Err(BoundaryError::TooFew {
                looop: l,
                got: pts.len(),
            });
        }
        let scale = size(pts);
        for i in 0..pts.len() {
            let j = (i + 1) % pts.len();
            if pts[i].distance(pts[j]) <= 1e-9 * scale.max(1e-300) {
                return Err(BoundaryError::Repeated {
                    looop: l,
                    point: j,
                    prev: i,
                });
            }
        }
    }
    Ok(())
}

pub(super) fn size(p: &[DVec3]) -> f64 {
    let Some(first) = p.first() else { return 0.0 };
    let (lo, hi) = p
        .iter()
        .fold((*first, *first), |(lo, hi), q| (lo.min(*q), hi.max(*q)));
    (hi - lo).length()
}

/// Distance between segments `p0 p1` and `q0 q1`, and the midpoint of the closest pair.
pub(super) fn segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> (f64, DVec3) {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let (s, t);
    if a <= 1e-300 && e <= 1e-300 {
        return (p0.distance(q0), 0.5 * (p0 + q0));
    }
    if a <= 1e-300 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= 1e-300 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 1e-12 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    let cp = p0 + d1 * s;
    let cq = q0 + d2 * t;
    (cp.distance(cq), 0.5 * (cp + cq))
}

/// Check that no two non-adjacent segments of the loops come closer than 1e-9 × the size.
/// `labels[l][i]` is the user's (loop, point) name of point `i` of loop `l`.
pub(super) fn check_crossings(
    loops: &[Vec<DVec3>],
    labels: &[Vec<(usize, usize)>],
) -> Result<(), BoundaryError> {
    let all: Vec<DVec3> = loops.iter().flatten().copied().collect();
    let tol = 1e-9 * size(&all);
    let segs: Vec<(usize, usize, DVec3, DVec3)> = loops
        .iter()
        .enumerate()
        .flat_map(|(l, p)| (0..p.len()).map(move |i| (l, i, p[i], p[(i + 1) % p.len()])))
        .collect();
    // Bounding boxes to skip far pairs cheaply.
    let boxes: Vec<(DVec3, DVec3)> = segs
        .iter()
        .map(|s| {
            (
                s.2.min(s.3) - DVec3::splat(tol),
                s.2.max(s.3) + DVec3::splat(tol),
            )
        })
        .collect();
    for x in 0..segs.len() {
        for y in x + 1..segs.len() {
            let (la, i, a0, a1) = segs[x];
            let (lb, j, b0, b1) = segs[y];
            if la == lb {
                let n = loops[la].len();
                if j == i + 1 || (i == 0 && j == n - 1) {
                    continue; // adjacent: they share a point
                }
            }
            let (bx, by) = (boxes[x], boxes[y]);
            if bx.0.cmpgt(by.1).any() || by.0.cmpgt(bx.1).any() {
                continue;
            }
            let (d, at) = segment_distance(a0, a1, b0, b1);
            if d <= tol {
                let na = loops[la].len();
                let nb = loops[lb].len();
                let (ul, ua) = labels[la][i];
                let (_, ua1) = labels[la][(i + 1) % na];
                let (vl, vb) = labels[lb][j];
                let (_, vb1) = labels[lb][(j + 1) % nb];
                return Err(BoundaryError::SelfIntersecting {
                    la: ul,
                    a: ua,
                    a1: ua1,
                    lb: vl,
                    b: vb,
                    b1: vb1,
                    x: at.x,
                    y: at.y,
                    z: at.z,
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_cases() {
        let (d, _) = segment_distance(
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, -1.0, 1.0),
            DVec3::new(0.5, 1.0, 1.0),
        );
        assert!((d - 1.0).abs() < 1e-12);
        let (d, _) = segment_distance(
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
        );
        assert!((d - 1.0).abs() < 1e-12);
    }
}
