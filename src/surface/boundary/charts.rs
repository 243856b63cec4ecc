//! §3 charts of a subloop's convex hull, its envelopes, and the subloops a cover leaves.
//!
//! On the convex hull ([`crate::geom::hull`]) of a (sub)loop, a chart is a
//! connected set of hull triangles that (1) share edges with each other, (2) each have an
//! edge on the loop, (3) all run the same way as the loop. Subtracting charts from the loop
//! leaves subloops; a subloop that lies on its hull splits it into two *envelopes*.
//!
//! Chart area threshold: relative to the hull of the subloop being split (deeper subloops
//! are small; against the top hull they would never have charts).
//!
//! A flat subloop (its hull is planar) gets one envelope by ear clipping in its plane, on the
//! input points, or the points before the offset, or the offset ones, whichever is simple.
//! Charts and envelopes are cached per subloop.

use super::bnb::Search;
use super::{Chart, Sub};
use crate::geom::hull;
use crate::geom::mesh::newell;
use glam::{DVec2, DVec3};
use std::collections::{BTreeMap, HashSet};
use std::rc::Rc;

impl Search<'_> {
    /// Whether the directed loop edge `a → b` (a, b adjacent in the loop) is an input edge.
    pub(super) fn is_orig(&self, a: usize, b: usize) -> bool {
        (b == (a + 1) % self.m && self.orig[a]) || (a == (b + 1) % self.m && self.orig[b])
    }

    pub(super) fn interior(&self, t: [usize; 3]) -> bool {
        !(0..3).any(|k| self.is_orig(t[k], t[(k + 1) % 3]))
    }

    /// Remaining subloops after removing triangles (each sorted, i.e. in loop order).
    pub(super) fn subtract(&self, tris: &[[usize; 3]]) -> Vec<Vec<usize>> {
        let m = self.m;
        let mut rem: HashSet<(usize, usize)> = (0..m).map(|k| (k, (k + 1) % m)).collect();
        for t in tris {
            for k in 0..3 {
                let e = (t[k], t[(k + 1) % 3]);
                if !rem.remove(&e) {
                    rem.insert((e.1, e.0));
                }
            }
        }
        let mut out: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for &(a, b) in &rem {
            out.entry(a).or_default().push(b);
        }
        let mut loops = Vec::new();
        let off = |x: usize, from: usize| (x + m - from) % m;
        while let Some((&start, _)) = out.iter().find(|(_, v)| !v.is_empty()) {
            let first = out.get_mut(&start).and_then(|v| {
                v.sort_unstable();
                v.pop()
            });
            let Some(mut cur) = first else { break };
            let mut lp = vec![start];
            let mut prev = start;
            let mut guard = 0;
            while cur != start && guard <= m {
                guard += 1;
                lp.push(cur);
                let Some(cands) = out.get_mut(&cur) else {
                    break;
                };
                let lim = off(prev, cur);
                let pick = cands
                    .iter()
                    .enumerate()
                    .filter(|(_, &w)| off(w, cur) < lim || lim == 0)
                    .max_by_key(|(_, &w)| off(w, cur))
                    .map(|(i, _)| i)
                    .or(if cands.is_empty() { None } else { Some(0) });
                let Some(i) = pick else { break };
                let w = cands.swap_remove(i);
                prev = cur;
                cur = w;
            }
            if lp.len() >= 3 {
                let k = lp
                    .iter()
                    .enumerate()
                    .min_by_key(|(_, &v)| v)
                    .map_or(0, |(i, _)| i);
                lp.rotate_left(k);
                loops.push(lp);
            }
        }
        loops.sort();
        loops
    }

    /// Whether triangles (in loop order) have pairwise non-crossing chords.
    pub(super) fn non_crossing(tris: &[[usize; 3]]) -> bool {
        let mut chords: Vec<(usize, usize)> = Vec::new();
        for t in tris {
            chords.push((t[0], t[1]));
            chords.push((t[1], t[2]));
            chords.push((t[0], t[2]));
        }
        chords.sort_unstable();
        chords.dedup();
        for (i, &(a, b)) in chords.iter().enumerate() {
            for &(c, d) in &chords[i + 1..] {
                if c >= b {
                    break;
                }
                if a < c && c < b && b < d {
                    return false;
                }
            }
        }
        true
    }

    pub(super) fn chart_id(&mut self, mut tris: Vec<[usize; 3]>) -> usize {
        tris.sort_unstable();
        if let Some(&id) = self.chart_ids.get(&tris) {
            return id;
        }
        let area = tris
            .iter()
            .map(|t| {
                0.5 * (self.p[t[1]] - self.p[t[0]])
                    .cross(self.p[t[2]] - self.p[t[0]])
                    .length()
            })
            .sum();
        let id = self.charts.len();
        self.charts.push(Chart {
            tris: tris.clone(),
            area,
        });
        self.chart_ids.insert(tris, id);
        id
    }

    /// Envelopes and charts of a subloop's hull (cached).
    pub(super) fn analyse(&mut self, sub: &[usize]) -> Rc<Sub> {
        if let Some(s) = self.subs.get(sub) {
            return s.clone();
        }
        let s = Rc::new(self.analyse_uncached(sub));
        self.subs.insert(sub.to_vec(), s.clone());
        s
    }

    pub(super) fn analyse_uncached(&mut self, sub: &[usize]) -> Sub {
        let q = sub.len();
        let mut out = Sub::default();
        if q == 3 {
            out.envelopes.push(vec![[sub[0], sub[1], sub[2]]]);
            return out;
        }
        let hp: Vec<DVec3> = sub.iter().map(|&v| self.h[v]).collect();
        let Some(hull) = hull::hull(&hp) else {
            return out;
        };
        let sorted = |t: [usize; 3]| {
            let mut g = t.map(|x| sub[x]);
            g.sort_unstable();
            g
        };
        if hull.planar.is_some() {
            out.envelopes.extend(self.flat_envelope(sub, &hp));
            return out;
        }
        let nf = hull.faces.len();
        let is_sub_edge = |x: usize, y: usize| y == (x + 1) % q || x == (y + 1) % q;
        // Whether a subloop edge counts as polyline for charts (not a ruling or bridge).
        let counts = |x: usize, y: usize| -> bool {
            let (a, b) = (sub[x], sub[y]);
            if b == (a + 1) % self.m || a == (b + 1) % self.m {
                let k = if b == (a + 1) % self.m { a } else { b };
                self.orig[k]
            } else {
                true
            }
        };
        let mut sense = vec![false; nf];
        let mut has_edge = vec![false; nf];
        let mut eligible = vec![false; nf];
        let mut edge_seen = 0;
        for (f, t) in hull.faces.iter().enumerate() {
            let [i, j, l] = *t;
            sense[f] = u8::from(i < j) + u8::from(j < l) + u8::from(l < i) == 2;
            for k in 0..3 {
                let (x, y) = (t[k], t[(k + 1) % 3]);
                if is_sub_edge(x, y) {
                    has_edge[f] = true;
                    edge_seen += 1;
                    if counts(x, y) && self.valid(&[sorted(*t)]) {
                        eligible[f] = true;
                    }
                }
            }
        }
        let comps = |keep: &dyn Fn(usize, usize) -> bool| components(&hull, q, keep);
        // Envelopes: every subloop edge on the hull (each seen from both sides) and exactly two
        // components of one sense each.
        if edge_seen == 2 * q {
            let parts = comps(&|_, _| true);
            if parts.len() == 2 {
                for part in &parts {
                    let s0 = sense[part[0]];
                    if part.len() == q - 2 && part.iter().all(|&f| sense[f] == s0) {
                        let tris: Vec<[usize; 3]> =
                            part.iter().map(|&f| sorted(hull.faces[f])).collect();
                        if Self::non_crossing(&tris) && self.valid(&tris) {
                            out.envelopes.push(tris);
                        }
                    }
                }
            }
        }
        // Charts.
        let hull_area = hull.area(&hp);
        let parts = comps(&|f, g| eligible[f] && eligible[g] && sense[f] == sense[g]);
        for part in &parts {
            let tris: Vec<[usize; 3]> = part.iter().map(|&f| sorted(hull.faces[f])).collect();
            let area: f64 = part
                .iter()
                .map(|&f| {
                    0.5 * (hp[hull.faces[f][1]] - hp[hull.faces[f][0]])
                        .cross(hp[hull.faces[f][2]] - hp[hull.faces[f][0]])
                        .length()
                })
                .sum();
            if area < self.min_area * hull_area || !Self::non_crossing(&tris) || !self.valid(&tris)
            {
                continue;
            }
            let mut smooth = true;
            'check: for (k, &f) in part.iter().enumerate() {
                for e in 0..3 {
                    let g = hull.neighbours[f][e];
                    if g == usize::MAX {
                        continue;
                    }
                    let inside = part.contains(&g);
                    let interior_face = !has_edge[g];
                    if (inside || interior_face)
                        && self.dihedral(tris[k], sorted(hull.faces[g])) >= self.thr
                    {
                        smooth = false;
                        break 'check;
                    }
                }
            }
            if smooth {
                let id = self.chart_id(tris);
                out.charts.push(id);
            }
        }
        if out.charts.is_empty() && out.envelopes.is_empty() {
            // The pathological hull: each triangle a chart.
            for f in 0..nf {
                let t = sorted(hull.faces[f]);
                if t[0] != t[1] && t[1] != t[2] && self.valid(&[t]) {
                    let id = self.chart_id(vec![t]);
                    out.charts.push(id);
                }
            }
        }
        out.charts.sort_unstable();
        out.charts.dedup();
        out
    }

    /// A flat subloop: ear clipping in its plane, on the input points (the offset ones if those
    /// fold over), one envelope since both sides are the same.
    fn flat_envelope(&self, sub: &[usize], hp: &[DVec3]) -> Option<Vec<[usize; 3]>> {
        let q = sub.len();
        let sorted = |t: [usize; 3]| {
            let mut g = t.map(|x| sub[x]);
            g.sort_unstable();
            g
        };
        let op: Vec<DVec3> = sub.iter().map(|&v| self.p[v]).collect();
        let bp: Vec<DVec3> = sub
            .iter()
            .filter_map(|&v| self.base.get(v))
            .copied()
            .collect();
        for pts in [&op[..], &bp[..], hp] {
            if pts.len() != q {
                continue;
            }
            let n = newell(pts).normalize_or_zero();
            if n == DVec3::ZERO {
                continue;
            }
            let u = n.any_orthonormal_vector();
            let v = n.cross(u);
            let ring: Vec<DVec2> = pts.iter().map(|p| DVec2::new(p.dot(u), p.dot(v))).collect();
            if crate::geom::polygon::is_simple_ring(&ring) {
                let tris: Vec<[usize; 3]> = crate::geom::polygon::triangulate(&ring)
                    .iter()
                    .copied()
                    .map(sorted)
                    .collect();
                if tris.len() == q - 2 && Self::non_crossing(&tris) && self.valid(&tris) {
                    return Some(tris);
                }
            }
        }
        None
    }
}

/// Components of hull faces joined across edges that are not subloop edges (`q` points), where
/// `keep(f, g)` allows the step from face `f` to face `g` (`keep(f, f)`: `f` may start one).
fn components(hull: &hull::Hull, q: usize, keep: &dyn Fn(usize, usize) -> bool) -> Vec<Vec<usize>> {
    let nf = hull.faces.len();
    let is_sub_edge = |x: usize, y: usize| y == (x + 1) % q || x == (y + 1) % q;
    let mut comp = vec![usize::MAX; nf];
    let mut list = Vec::new();
    for f0 in 0..nf {
        if comp[f0] != usize::MAX || !keep(f0, f0) {
            continue;
        }
        let id = list.len();
        let mut members = vec![f0];
        comp[f0] = id;
        let mut k = 0;
        while k < members.len() {
            let f = members[k];
            k += 1;
            for e in 0..3 {
                let g = hull.neighbours[f][e];
                let (x, y) = (hull.faces[f][e], hull.faces[f][(e + 1) % 3]);
                if g == usize::MAX || comp[g] != usize::MAX || is_sub_edge(x, y) {
                    continue;
                }
                if keep(f, g) {
                    comp[g] = id;
                    members.push(g);
                }
            }
        }
        list.push(members);
    }
    list
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subtract_gives_simple_subloops() {
        let p: Vec<DVec3> = (0..8)
            .map(|k| {
                let t = k as f64 / 8.0 * std::f64::consts::TAU;
                DVec3::new(t.cos(), t.sin(), 0.3 * (2.0 * t).cos())
            })
            .collect();
        let orig = vec![true; 8];
        let site: Vec<usize> = (0..8).collect();
        let s = Search::new(&p, p.clone(), &orig, (&site, false), 3.0, 0.0);
        // Triangle 1-2-5 leaves 0,1,5,6,7 and 2,3,4,5.
        let subs = s.subtract(&[[1, 2, 5]]);
        assert_eq!(subs, vec![vec![0, 1, 5, 6, 7], vec![2, 3, 4, 5]]);
        // Triangles touching at vertex 4: 2-3-4 and 4-5-6 leave 0,1,2,4,6,7.
        let subs = s.subtract(&[[2, 3, 4], [4, 5, 6]]);
        assert_eq!(subs, vec![vec![0, 1, 2, 4, 6, 7]]);
        // Interior triangle 0-3-6: three subloops.
        let subs = s.subtract(&[[0, 3, 6]]);
        assert_eq!(
            subs,
            vec![vec![0, 1, 2, 3], vec![0, 6, 7], vec![3, 4, 5, 6]]
        );
        assert!(Search::non_crossing(&[[0, 1, 2], [0, 2, 5]]));
        assert!(!Search::non_crossing(&[[0, 1, 3], [2, 3, 5]]));
    }
}
