//! §6.1 darts.
//!
//! A dart is a polyline from a loop point (of any loop) to its tip, inserted
//! twice with reversed orientation into its loop: the loop point and the dart's points are
//! duplicated (left copy, tip once, right copy), and the two copies *coincide* in 3D — the
//! sewn dart. The triangulation treats them as two boundary sections, so the flat piece
//! opens them into the V that a pattern cuts out. Coinciding points break hulls and local
//! convexity predicates, so, as the §7 radial offset does, hulls are computed on perturbed
//! points only: the copies opened into a narrow V (at the mouth `width`, default 2 % of the
//! dart's length, along the boundary, narrowing to the tip); triangles and all angles use
//! the real points. A triangle with two copies of one point, a triangle without area, or
//! an edge in space used by more than two triangles (the surface folded onto itself around
//! the tip) is refused in charts, envelopes, covers and results. Should the coinciding
//! sides give no valid triangulation, or only one over the limits while the V gives one
//! within them, the darts are opened into that V for real and a warning says so (only as
//! this fallback; with neither valid the result is an error). A
//! dart tip that lies off the surface the rest of the boundary asks for (the dart takes
//! fabric in) is what makes the flat V open; a tip barely off it can need the fallback.
//!
//! [`sites_valid`] is the test that refuses those triangles; every stage of the search uses it
//! when a region has copies (dart sides or the two ends of a joining edge).

use super::checks::size;
use super::{BoundaryError, Dart};
use glam::DVec3;
use std::collections::HashMap;

/// One loop with its darts inserted (see the module doc).
pub(super) struct Darted {
    /// The points; a dart's two copies coincide (or form the opened V with `open`).
    pub(super) pts: Vec<DVec3>,
    /// The points for hulls and the crossing check: the copies always opened into a V.
    pub(super) hull: Vec<DVec3>,
    /// For each point, the point it coincides with: the left copy for a right copy, else itself.
    pub(super) twin: Vec<usize>,
    /// Old point index → new.
    pub(super) map: Vec<usize>,
    /// The user's (loop, point) name of each new point, 0-based.
    pub(super) labels: Vec<(usize, usize)>,
}

/// Insert the darts `(index, dart)` of loop `l` into its points (see the module doc).
pub(super) fn insert_darts(
    pts: &[DVec3],
    l: usize,
    darts: &[(usize, &Dart)],
    open: bool,
) -> Result<Darted, BoundaryError> {
    let n = pts.len();
    let mut by_at: Vec<Option<usize>> = vec![None; n];
    for (di, &(k, d)) in darts.iter().enumerate() {
        let err = |message: String| BoundaryError::Dart { index: k, message };
        if d.at >= n {
            return Err(err(format!(
                "starts at point {} but loop {} has {n} points",
                d.at + 1,
                l + 1
            )));
        }
        if by_at[d.at].is_some() {
            return Err(err(format!(
                "point {} of loop {} already starts a dart",
                d.at + 1,
                l + 1
            )));
        }
        if d.points.is_empty() {
            return Err(err("needs at least one point (the tip)".into()));
        }
        if d.points.iter().any(|p| !p.is_finite()) {
            return Err(err("a point is not finite".into()));
        }
        let mut prev = pts[d.at];
        for (i, p) in d.points.iter().enumerate() {
            if p.distance(prev) <= 1e-9 * size(pts) {
                return Err(err(format!("point {} repeats the point before it", i + 1)));
            }
            prev = *p;
        }
        if let Some(w) = d.width {
            if !(w.is_finite() && w > 0.0) {
                return Err(err(format!(
                    "width must be a positive number of mm, got {w}"
                )));
            }
        }
        by_at[d.at] = Some(di);
    }
    let mut out = Darted {
        pts: Vec::new(),
        hull: Vec::new(),
        twin: Vec::new(),
        map: vec![0; n],
        labels: Vec::new(),
    };
    for i in 0..n {
        let Some(di) = by_at[i] else {
            out.map[i] = out.pts.len();
            out.twin.push(out.pts.len());
            out.pts.push(pts[i]);
            out.hull.push(pts[i]);
            out.labels.push((l, i));
            continue;
        };
        let d = darts[di].1;
        let a = pts[i];
        let t = (pts[(i + 1) % n] - pts[(i + n - 1) % n]).normalize_or_zero();
        let mut chain = vec![a];
        chain.extend_from_slice(&d.points);
        let mut cum = vec![0.0];
        for w in chain.windows(2) {
            cum.push(cum.last().copied().unwrap_or(0.0) + w[0].distance(w[1]));
        }
        let len = cum.last().copied().unwrap_or(0.0);
        let half = 0.5 * d.width.unwrap_or(0.02 * len);
        let m = chain.len();
        // Left copy (mouth to tip, on the side of the previous point), tip, right copy back.
        out.map[i] = out.pts.len();
        let left = out.pts.len();
        for j in 0..m - 1 {
            let v = chain[j] - t * half * (1.0 - cum[j] / len);
            out.twin.push(out.pts.len());
            out.pts.push(if open { v } else { chain[j] });
            out.hull.push(v);
            out.labels.push((l, i));
        }
        out.twin.push(out.pts.len());
        out.pts.push(chain[m - 1]);
        out.hull.push(chain[m - 1]);
        out.labels.push((l, i));
        for j in (0..m - 1).rev() {
            let v = chain[j] + t * half * (1.0 - cum[j] / len);
            out.twin.push(if open { out.pts.len() } else { left + j });
            out.pts.push(if open { v } else { chain[j] });
            out.hull.push(v);
            out.labels.push((l, i));
        }
    }
    Ok(out)
}

/// Whether triangles over vertices with sites are valid pieces of a boundary triangulation:
/// no triangle with two vertices at one site or with no area, no site pair (edge in space) in
/// more than two triangles.
pub(super) fn sites_valid(p: &[DVec3], site: &[usize], tris: &[[usize; 3]]) -> bool {
    let mut count: HashMap<(usize, usize), u8> = HashMap::new();
    for t in tris {
        let s = t.map(|x| site[x]);
        if s[0] == s[1] || s[1] == s[2] || s[0] == s[2] {
            return false;
        }
        let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
        let longest = a
            .distance_squared(b)
            .max(b.distance_squared(c))
            .max(c.distance_squared(a));
        if (b - a).cross(c - a).length() <= 1e-9 * longest {
            return false;
        }
        for k in 0..3 {
            let (x, y) = (s[k], s[(k + 1) % 3]);
            let n = count.entry((x.min(y), x.max(y))).or_default();
            *n += 1;
            if *n > 2 {
                return false;
            }
        }
    }
    true
}
