//! Developable triangulations of a strip (Wang & Tang, seed 003): the boundary bridge
//! triangulation (BBT) between two polylines P = p₀…p_{m−1} and Q = q₀…q_{n−1} (§3.1), made of
//! m+n−2 triangles, each of two bridges `p_i q_j` and one bank edge, built by a sequence of
//! P-succeed and Q-succeed steps from the starting bridge `p₀q₀` to the ending one
//! `p_{m−1}q_{n−1}`.
//!
//! - Local convexity (§3.2, the Proposition): bridge `p_i q_j` is valid when it lies on the
//!   convex hull of `{p_{i−1}, p_i, p_{i+1}, q_{j−1}, q_j, q_{j+1}}`. A segment is on the hull of
//!   a point set exactly when some plane through it has every point on one side: projected
//!   along the bridge, the four neighbours must fit in a closed half-plane. The test runs on
//!   triple products `d̂·((o_k−p_i)×(o_l−p_i))` (the 2D cross products of the projections),
//!   so it needs no trigonometry; a relative tolerance of 1e-9 keeps planar strips valid.
//!   Missing neighbours (the ends of open curves) are left out; neighbours on the bridge's
//!   line are ignored. The starting and ending bridges are not counted (§4: "all the possible
//!   bridge edges except the starting and ending ones are checked").
//! - Bending energy (eq. 3, K = 1): `U = A sin²θ / L²` on an interior bridge of length L
//!   between two triangles at dihedral angle θ. The extracted text does not define A; here it
//!   is the sum of the two triangles' areas (the material that bends). The paper's formula
//!   assumes small angles: beyond 90° `sin²θ` falls again and would make a fold-back look
//!   cheap, so `2 − sin²θ` is used there (monotone in θ, equal at 90°). The first and last
//!   bridges carry no energy (eq. 4).
//! - Ties (equal costs) go to the P-succeed step, so results are deterministic.
//! - Orientation and start (the paper takes P and Q as given): open strips are used as given
//!   except that Q is reversed when that makes the two end bridges shorter in sum. Closed
//!   strips (both curves closed loops) are oriented alike (Q is reversed when its Newell normal
//!   points against P's) and start at the shortest locally convex bridge `p_i q_j` over all
//!   pairs (ties: lowest i, then j; the shortest bridge of all if none is convex). That is the
//!   seam: a ruling of the developable, and its shortest element, where a sheet-metal worker
//!   puts the seam of an oblique cone (a plain shortest bridge can cut across a flat triangle
//!   of an offset square-to-round, which no ruling does). Both loops are rotated to start there and their first point is
//!   repeated at the end, so the strip is an open band whose two copies of the seam are cut.
//! - Faces are wound `p_i p_{i+1} q_j` and `p_i q_{j+1} q_j`: with P below Q and both running
//!   counter-clockwise seen from +z (as the fittings build them), normals point outward.
//!
//! The searches live beside this file: `local` (LODT + LMBT, §4), `global` (GODT, GMBT,
//! GMAT, §5) on the cost rows of `lanes`; `offset` moves a strip by a sheet thickness.

mod global;
mod lanes;
mod local;
mod offset;
pub mod shop;

use super::Bend;
use crate::geom::curve::Polyline;
use crate::geom::mesh::{newell, Face, Mesh};
use glam::DVec3;

/// One step of a BBT: P-succeed (`p_i q_j → p_{i+1} q_j`) or Q-succeed (`→ p_i q_{j+1}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Step {
    P,
    Q,
}

/// Which triangulation to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Most locally convex bridges, then least bending energy (the paper's GODT+GMBT).
    #[default]
    GodtGmbt,
    /// Most locally convex bridges (ties to P-succeed).
    Godt,
    /// Least bending energy.
    Gmbt,
    /// Least area.
    Gmat,
    /// The local greedy LODT + LMBT.
    Local,
}

impl Method {
    pub const NAMES: [(&'static str, Method); 5] = [
        ("godt+gmbt", Method::GodtGmbt),
        ("godt", Method::Godt),
        ("gmbt", Method::Gmbt),
        ("gmat", Method::Gmat),
        ("local", Method::Local),
    ];
}

/// Which rulings become bend (metal) or score (paper) lines.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum BendLines {
    /// Every interior bridge that bends (by more than 0.01°).
    #[default]
    All,
    /// None: the blank gets no bend lines.
    None,
    /// Rulings about this far apart (mm, measured between bridge midpoints along the strip),
    /// each with the angle accumulated since the previous one (the last one also takes what
    /// bends after it). Only rulings that bend themselves are picked, so no bend line falls
    /// inside a flat triangle.
    Spacing(f64),
    /// As a sheet-metal shop marks them ([`shop`]): equal shares of the whole bend, on lines
    /// at least [`shop::SHOP_MIN_MM`] apart. The default of `flatcut fitting`.
    Shop,
}

/// Two boundary polylines ready to triangulate.
#[derive(Debug, Clone, PartialEq)]
pub struct Strip {
    pub p: Vec<DVec3>,
    pub q: Vec<DVec3>,
    /// Both curves were closed loops (the last point repeats the first).
    pub closed: bool,
}

/// What can be wrong with a strip's curves.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum StripError {
    #[error("`{curve}` needs at least 2 distinct points, got {got}")]
    TooFewPoints { curve: &'static str, got: usize },
    #[error("`p` and `q` are the same curve: a strip needs two different boundaries")]
    Same,
    #[error("`p` is {p} but `q` is {q}: both must be open or both closed")]
    Mixed { p: &'static str, q: &'static str },
    #[error("`{curve}` has a coordinate that is not a finite number")]
    NonFinite { curve: &'static str },
}

/// Quality figures of a BBT.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metrics {
    /// Interior bridges (m+n−3).
    pub interior: usize,
    /// Interior bridges that are locally convex.
    pub convex: usize,
    /// Total bending energy (eq. 4).
    pub energy: f64,
    /// Total area (mm²).
    pub area: f64,
}

fn kind(closed: bool) -> &'static str {
    if closed {
        "closed"
    } else {
        "open"
    }
}

impl Strip {
    /// Strip from two sampled curves, oriented and (closed) started as the module doc says.
    pub fn new(p: &Polyline, q: &Polyline) -> Result<Strip, StripError> {
        for (curve, c) in [("p", p), ("q", q)] {
            if c.points.iter().any(|x| !x.is_finite()) {
                return Err(StripError::NonFinite { curve });
            }
            if c.points.len() < 2 {
                return Err(StripError::TooFewPoints {
                    curve,
                    got: c.points.len(),
                });
            }
        }
        if p.closed != q.closed {
            return Err(StripError::Mixed {
                p: kind(p.closed),
                q: kind(q.closed),
            });
        }
        let size = p
            .points
            .iter()
            .chain(&q.points)
            .map(|x| x.length())
            .fold(1.0, f64::max);
        let same = p.points.len() == q.points.len() && {
            let direct = p
                .points
                .iter()
                .zip(&q.points)
                .all(|(a, b)| a.distance(*b) <= 1e-9 * size);
            let reversed = p
                .points
                .iter()
                .zip(q.points.iter().rev())
                .all(|(a, b)| a.distance(*b) <= 1e-9 * size);
            direct || reversed || (p.closed && same_loop(&p.points, &q.points, size))
        };
        if same {
            return Err(StripError::Same);
        }
        let (mut pp, mut qq) = (p.points.clone(), q.points.clone());
        if !p.closed {
            let (p0, p1) = (pp[0], pp[pp.len() - 1]);
            let (q0, q1) = (qq[0], qq[qq.len() - 1]);
            if p0.distance(q1) + p1.distance(q0) < p0.distance(q0) + p1.distance(q1) {
                qq.reverse();
            }
            return Ok(Strip {
                p: pp,
                q: qq,
                closed: false,
            });
        }
        if newell(&pp).dot(newell(&qq)) < 0.0 {
            qq.reverse();
        }
        // Seam: the shortest locally convex bridge, else the shortest bridge.
        let ring = Strip {
            p: pp.iter().chain(pp.first()).copied().collect(),
            q: qq.iter().chain(qq.first()).copied().collect(),
            closed: true,
        };
        let (mut bi, mut bj, mut best) = (0, 0, f64::INFINITY);
        let (mut ci, mut cj, mut best_convex) = (0, 0, f64::INFINITY);
        for (i, a) in pp.iter().enumerate() {
            for (j, b) in qq.iter().enumerate() {
                let d = a.distance_squared(*b);
                if d < best {
                    (bi, bj, best) = (i, j, d);
                }
                if d < best_convex && ring.locally_convex(i, j) {
                    (ci, cj, best_convex) = (i, j, d);
                }
            }
        }
        if best_convex.is_finite() {
            (bi, bj) = (ci, cj);
        }
        pp.rotate_left(bi);
        qq.rotate_left(bj);
        pp.push(pp[0]);
        qq.push(qq[0]);
        Ok(Strip {
            p: pp,
            q: qq,
            closed: true,
        })
    }

    /// A strip from point lists used exactly as given (open, no reorientation).
    pub fn raw(p: Vec<DVec3>, q: Vec<DVec3>) -> Strip {
        Strip {
            p,
            q,
            closed: false,
        }
    }

    pub fn m(&self) -> usize {
        self.p.len()
    }

    pub fn n(&self) -> usize {
        self.q.len()
    }

    fn neighbours(len: usize, closed: bool, i: usize) -> (Option<usize>, Option<usize>) {
        if closed && len >= 3 {
            let prev = if i == 0 { len - 2 } else { i - 1 };
            let next = if i == len - 1 { 1 } else { i + 1 };
            (Some(prev), Some(next))
        } else {
            (i.checked_sub(1), (i + 1 < len).then_some(i + 1))
        }
    }

    /// Whether bridge `p_i q_j` lies on the convex hull of its six points (§3.2), by
    /// [`crate::geom::hull::segment_on_hull`].
    pub(crate) fn locally_convex(&self, i: usize, j: usize) -> bool {
        let (pp, pn) = Self::neighbours(self.m(), self.closed, i);
        let (qp, qn) = Self::neighbours(self.n(), self.closed, j);
        let mut v = [DVec3::ZERO; 4];
        let mut k = 0;
        for o in [
            pp.map(|x| self.p[x]),
            pn.map(|x| self.p[x]),
            qp.map(|x| self.q[x]),
            qn.map(|x| self.q[x]),
        ]
        .into_iter()
        .flatten()
        {
            v[k] = o;
            k += 1;
        }
        crate::geom::hull::segment_on_hull(self.p[i], self.q[j], &v[..k])
    }

    /// Validity matrix Ψ (row-major, m×n) of every bridge; start and end count as valid.
    pub fn validity(&self) -> Vec<bool> {
        let (m, n) = (self.m(), self.n());
        let mut out = Vec::with_capacity(m * n);
        for i in 0..m {
            for j in 0..n {
                out.push(self.is_end(i, j) || self.locally_convex(i, j));
            }
        }
        out
    }

    fn is_end(&self, i: usize, j: usize) -> bool {
        (i == 0 && j == 0) || (i + 1 == self.m() && j + 1 == self.n())
    }

    /// Unit normal and area of the triangle a P-succeed step makes from `p_i q_j`.
    fn tri_p(&self, i: usize, j: usize) -> (DVec3, f64) {
        tri(self.p[i], self.p[i + 1], self.q[j])
    }

    /// ... and a Q-succeed step.
    fn tri_q(&self, i: usize, j: usize) -> (DVec3, f64) {
        tri(self.p[i], self.q[j + 1], self.q[j])
    }

    /// Triangle a step from bridge (i, j) makes.
    fn tri_step(&self, i: usize, j: usize, s: Step) -> (DVec3, f64) {
        match s {
            Step::P => self.tri_p(i, j),
            Step::Q => self.tri_q(i, j),
        }
    }

    /// Bending energy on bridge (i, j) between the triangle that made it (`prev`) and the one
    /// that follows (`next`); zero on the starting bridge.
    pub(crate) fn energy(&self, i: usize, j: usize, prev: Step, next: Step) -> f64 {
        if i == 0 && j == 0 {
            return 0.0;
        }
        let t1 = match prev {
            Step::P => self.tri_p(i - 1, j),
            Step::Q => self.tri_q(i, j - 1),
        };
        let t2 = self.tri_step(i, j, next);
        bend_energy(t1, t2, self.p[i].distance_squared(self.q[j]))
    }

    /// The BBT a method finds.
    pub fn triangulate(&self, method: Method) -> Vec<Step> {
        match method {
            Method::Local => self.local(),
            _ => self.global(method),
        }
    }

    /// Bank vectors to the previous and next point of each vertex of a curve (zero where the
    /// curve has none), with their cross product.
    fn banks(pts: &[DVec3], closed: bool) -> Vec<([DVec3; 3], [f64; 2])> {
        (0..pts.len())
            .map(|i| {
                let (a, b) = Self::neighbours(pts.len(), closed, i);
                let e0 = a.map_or(DVec3::ZERO, |k| pts[k] - pts[i]);
                let e1 = b.map_or(DVec3::ZERO, |k| pts[k] - pts[i]);
                ([e0, e1, e0.cross(e1)], [e0.length(), e1.length()])
            })
            .collect()
    }

    /// Bridges of a BBT in order, as (i, j), starting and ending bridge included.
    pub(crate) fn bridges(&self, steps: &[Step]) -> Vec<(usize, usize)> {
        let mut out = Vec::with_capacity(steps.len() + 1);
        let (mut i, mut j) = (0, 0);
        out.push((0, 0));
        for s in steps {
            match s {
                Step::P => i += 1,
                Step::Q => j += 1,
            }
            out.push((i, j));
        }
        out
    }

    /// Whether a step sequence is a complete BBT of this strip.
    pub fn is_complete(&self, steps: &[Step]) -> bool {
        let p = steps.iter().filter(|s| **s == Step::P).count();
        p + 1 == self.m() && steps.len() - p + 1 == self.n()
    }

    /// Convex bridges, energy and area of a BBT, walked triangle by triangle.
    pub fn metrics(&self, steps: &[Step]) -> Metrics {
        let b = self.bridges(steps);
        let mut convex = 0;
        let mut energy = 0.0;
        let mut area = 0.0;
        for k in 0..steps.len() {
            let (i, j) = b[k];
            area += self.tri_step(i, j, steps[k]).1;
            if k > 0 {
                if self.locally_convex(i, j) {
                    convex += 1;
                }
                energy += self.energy(i, j, steps[k - 1], steps[k]);
            }
        }
        Metrics {
            interior: steps.len().saturating_sub(1),
            convex,
            energy,
            area,
        }
    }

    /// The BBT as a mesh: vertices P then Q, one triangle per step.
    pub fn mesh(&self, steps: &[Step]) -> Mesh {
        let m = self.m();
        let mut vertices = self.p.clone();
        vertices.extend_from_slice(&self.q);
        let mut faces = Vec::with_capacity(steps.len());
        let (mut i, mut j) = (0, 0);
        for s in steps {
            let verts = match s {
                Step::P => vec![i, i + 1, m + j],
                Step::Q => vec![i, m + j + 1, m + j],
            };
            faces.push(Face { verts, line: None });
            match s {
                Step::P => i += 1,
                Step::Q => j += 1,
            }
        }
        Mesh { vertices, faces }
    }

    /// Bend lines of a BBT: vertex pairs (in [`Strip::mesh`] numbering) and signed angles
    /// (positive where the surface is convex seen from the normal side, i.e. a mountain).
    pub fn bends(&self, steps: &[Step], lines: BendLines) -> Vec<Bend> {
        const EPS_DEG: f64 = 0.01;
        let m = self.m();
        let b = self.bridges(steps);
        let mut out = Vec::new();
        let mut acc = 0.0;
        let mid = |k: usize| 0.5 * (self.p[b[k].0] + self.q[b[k].1]);
        let mut along = 0.0;
        let mut last_pick = 0.0;
        // Shop: every ruling (vertices, where it is), picked after the walk.
        let mut seen: Vec<([usize; 2], shop::Ruling)> = Vec::new();
        let arc = |pts: &[DVec3]| -> Vec<f64> {
            let mut out = vec![0.0];
            for w in pts.windows(2) {
                out.push(out[out.len() - 1] + w[0].distance(w[1]));
            }
            out
        };
        let (arc_p, arc_q) = if lines == BendLines::Shop {
            (arc(&self.p), arc(&self.q))
        } else {
            (Vec::new(), Vec::new())
        };
        for k in 1..steps.len() {
            along += mid(k).distance(mid(k - 1));
            let (i, j) = b[k];
            let (n1, _) = self.tri_step(b[k - 1].0, b[k - 1].1, steps[k - 1]);
            let (n2, _) = self.tri_step(i, j, steps[k]);
            let far = match steps[k] {
                Step::P => self.p[i + 1],
                Step::Q => self.q[j + 1],
            };
            let theta = n1.cross(n2).length().atan2(n1.dot(n2));
            let convex = n1.dot(far - self.p[i]) < 0.0;
            let signed = if convex { theta } else { -theta };
            acc += signed;
            let verts = [i, m + j];
            match lines {
                BendLines::None => {}
                BendLines::All => {
                    if signed.to_degrees().abs() > EPS_DEG {
                        out.push(Bend {
                            verts,
                            angle_deg: signed.to_degrees(),
                        });
                    }
                }
                BendLines::Spacing(s) => {
                    if along - last_pick >= s && signed.to_degrees().abs() > EPS_DEG {
                        out.push(Bend {
                            verts,
                            angle_deg: acc.to_degrees(),
                        });
                        acc = 0.0;
                        last_pick = along;
                    }
                }
                BendLines::Shop => seen.push((
                    verts,
                    shop::Ruling {
                        along,
                        ends: [
                            arc_p.get(i).copied().unwrap_or(along),
                            arc_q.get(j).copied().unwrap_or(along),
                        ],
                        deg: signed.to_degrees(),
                    },
                )),
            }
        }
        if lines == BendLines::Shop {
            let rulings: Vec<shop::Ruling> = seen.iter().map(|s| s.1).collect();
            out = shop::picks(&rulings)
                .into_iter()
                .map(|(k, angle_deg)| Bend {
                    verts: seen[k].0,
                    angle_deg,
                })
                .collect();
        }
        // What bent after the last pick belongs to it (so the angles add up to the total).
        if let (BendLines::Spacing(_), Some(last)) = (lines, out.last_mut()) {
            last.angle_deg += acc.to_degrees();
        }
        out
    }
}

/// Unit normal (zero when degenerate) and area of a triangle.
fn tri(a: DVec3, b: DVec3, c: DVec3) -> (DVec3, f64) {
    let x = (b - a).cross(c - a);
    let l = x.length();
    if l > 0.0 {
        (x / l, 0.5 * l)
    } else {
        (DVec3::ZERO, 0.0)
    }
}

/// Eq. 3 with K = 1 (see the module doc for A and for angles beyond 90°).
fn bend_energy(t1: (DVec3, f64), t2: (DVec3, f64), l2: f64) -> f64 {
    if l2 <= 0.0 {
        return 0.0;
    }
    let s2 = t1.0.cross(t2.0).length_squared();
    let s = if t1.0.dot(t2.0) >= 0.0 { s2 } else { 2.0 - s2 };
    (t1.1 + t2.1) * s / l2
}

/// Whether two closed loops are the same points up to rotation of the start (either way).
fn same_loop(a: &[DVec3], b: &[DVec3], size: f64) -> bool {
    let n = a.len();
    let Some(k) = b.iter().position(|x| x.distance(a[0]) <= 1e-9 * size) else {
        return false;
    };
    let fwd = (0..n).all(|i| a[i].distance(b[(k + i) % n]) <= 1e-9 * size);
    let bwd = (0..n).all(|i| a[i].distance(b[(k + n - i) % n]) <= 1e-9 * size);
    fwd || bwd
}

/// Path cost: invalid bridges, then energy or area (the reference Dijkstra of the tests).
#[cfg(test)]
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cost {
    count: u32,
    value: f64,
}

#[cfg(test)]
impl Cost {
    fn better(&self, o: &Cost) -> bool {
        self.count < o.count || (self.count == o.count && self.value < o.value)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::cmp::Ordering;
    use std::collections::BinaryHeap;

    pub(crate) use crate::geom::rng::Rng;

    /// A wavy random strip: two noisy curves about `width` apart.
    pub(crate) fn random_strip(rng: &mut Rng, m: usize, n: usize) -> Strip {
        let mut curve = |k: usize, y: f64| -> Vec<DVec3> {
            let mut x = 0.0;
            (0..k)
                .map(|_| {
                    x += 0.5 + rng.f64();
                    DVec3::new(x, y + 0.6 * (rng.f64() - 0.5), 2.0 * (rng.f64() - 0.5))
                })
                .collect()
        };
        let p = curve(m, 0.0);
        let q = curve(n, 3.0);
        Strip::raw(p, q)
    }

    #[derive(PartialEq)]
    struct Item(Cost, usize);
    impl Eq for Item {}
    impl PartialOrd for Item {
        fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for Item {
        fn cmp(&self, o: &Self) -> Ordering {
            // Min-heap on (count, value).
            o.0.count
                .cmp(&self.0.count)
                .then(o.0.value.total_cmp(&self.0.value))
        }
    }

    /// Plain Dijkstra on the dual-node graph Ω (nodes (i, j, s)), as in the paper; returns
    /// the optimal cost (count, value).
    fn dijkstra(strip: &Strip, method: Method) -> (u32, f64) {
        let (m, n) = (strip.m(), strip.n());
        let id = |i: usize, j: usize, s: usize| (i * n + j) * 2 + s;
        let mut dist = vec![
            Cost {
                count: u32::MAX,
                value: f64::INFINITY
            };
            m * n * 2
        ];
        let mut heap = BinaryHeap::new();
        let zero = Cost {
            count: 0,
            value: 0.0,
        };
        dist[id(0, 0, 0)] = zero;
        heap.push(Item(zero, id(0, 0, 0)));
        let step = |s: usize| if s == 0 { Step::P } else { Step::Q };
        while let Some(Item(c, u)) = heap.pop() {
            if dist[u].better(&c) {
                continue;
            }
            let (s, ij) = (u % 2, u / 2);
            let (i, j) = (ij / n, ij % n);
            for t in 0..2 {
                let (ti, tj) = if t == 0 { (i + 1, j) } else { (i, j + 1) };
                if ti >= m || tj >= n {
                    continue;
                }
                let mut w = c;
                let interior = !strip.is_end(i, j);
                if matches!(method, Method::Godt | Method::GodtGmbt)
                    && interior
                    && !strip.locally_convex(i, j)
                {
                    w.count += 1;
                }
                if matches!(method, Method::Gmbt | Method::GodtGmbt) {
                    w.value += strip.energy(i, j, step(s), step(t));
                }
                if method == Method::Gmat {
                    w.value += strip.tri_step(i, j, step(t)).1;
                }
                let v = id(ti, tj, t);
                if w.better(&dist[v]) {
                    dist[v] = w;
                    heap.push(Item(w, v));
                }
            }
        }
        let e = [dist[id(m - 1, n - 1, 0)], dist[id(m - 1, n - 1, 1)]];
        let b = if e[1].better(&e[0]) { e[1] } else { e[0] };
        (b.count, b.value)
    }

    fn cost_of(strip: &Strip, steps: &[Step], method: Method) -> (u32, f64) {
        let mt = strip.metrics(steps);
        let invalid = (mt.interior - mt.convex) as u32;
        match method {
            Method::Godt => (invalid, 0.0),
            Method::Gmbt => (0, mt.energy),
            Method::Gmat => (0, mt.area),
            Method::GodtGmbt | Method::Local => (invalid, mt.energy),
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-12)
    }

    #[test]
    fn strip_dp_equals_dijkstra_on_random_strips() {
        let mut rng = Rng::new(7);
        for trial in 0..40 {
            let m = 2 + (rng.f64() * 12.0) as usize;
            let n = 2 + (rng.f64() * 12.0) as usize;
            let s = random_strip(&mut rng, m, n);
            for method in [Method::Godt, Method::Gmbt, Method::Gmat, Method::GodtGmbt] {
                let steps = s.triangulate(method);
                assert!(s.is_complete(&steps));
                let (c, v) = cost_of(&s, &steps, method);
                let (dc, dv) = dijkstra(&s, method);
                assert_eq!(c, dc, "trial {trial} {method:?} m {m} n {n}");
                assert!(
                    close(v, dv),
                    "trial {trial} {method:?}: dp {v} dijkstra {dv}"
                );
            }
        }
    }

    /// Every step sequence with m−1 P's and n−1 Q's.
    #[test]
    fn strip_dp_is_the_same_on_any_number_of_threads_and_bands() {
        let mut rng = Rng::new(7);
        for (m, n) in [(37, 29), (120, 64)] {
            let s = random_strip(&mut rng, m, n);
            for method in [Method::GodtGmbt, Method::Godt, Method::Gmbt, Method::Gmat] {
                let one = s.triangulate(method);
                let run = |band: usize, workers: usize| match method {
                    Method::Godt => s.global_bands::<true, false, false>(band, workers),
                    Method::Gmbt => s.global_bands::<false, true, false>(band, workers),
                    Method::Gmat => s.global_bands::<false, false, true>(band, workers),
                    _ => s.global_bands::<true, true, false>(band, workers),
                };
                for (band, workers) in [(1, 1), (1, 3), (5, 2), (7, 4), (64, 2)] {
                    assert_eq!(
                        run(band, workers),
                        one,
                        "{method:?} band {band} workers {workers}"
                    );
                }
            }
        }
    }

    fn all_paths(m: usize, n: usize) -> Vec<Vec<Step>> {
        if m == 1 && n == 1 {
            return vec![vec![]];
        }
        let mut out = Vec::new();
        if m > 1 {
            for mut p in all_paths(m - 1, n) {
                p.push(Step::P);
                out.push(p);
            }
        }
        if n > 1 {
            for mut p in all_paths(m, n - 1) {
                p.push(Step::Q);
                out.push(p);
            }
        }
        out
    }

    #[test]
    fn strip_dp_equals_brute_force_on_tiny_strips() {
        let mut rng = Rng::new(99);
        for _ in 0..15 {
            let (m, n) = (
                2 + (rng.f64() * 5.0) as usize,
                2 + (rng.f64() * 5.0) as usize,
            );
            let s = random_strip(&mut rng, m, n);
            let paths = all_paths(m, n);
            for method in [Method::Godt, Method::Gmbt, Method::Gmat, Method::GodtGmbt] {
                let best = paths
                    .iter()
                    .map(|p| cost_of(&s, p, method))
                    .min_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)))
                    .unwrap();
                let got = cost_of(&s, &s.triangulate(method), method);
                assert_eq!(got.0, best.0, "{method:?}");
                assert!(close(got.1, best.1), "{method:?} {got:?} {best:?}");
            }
        }
    }

    #[test]
    fn strip_global_beats_local_on_random_strips() {
        let mut rng = Rng::new(2024);
        for _ in 0..30 {
            let s = random_strip(&mut rng, 30, 40);
            let g = s.metrics(&s.triangulate(Method::Godt));
            let gg = s.metrics(&s.triangulate(Method::GodtGmbt));
            let l = s.metrics(&s.triangulate(Method::Local));
            let gb = s.metrics(&s.triangulate(Method::Gmbt));
            assert!(
                g.convex >= l.convex,
                "GODT {} < LODT {}",
                g.convex,
                l.convex
            );
            assert_eq!(gg.convex, g.convex);
            assert!(
                gb.energy <= l.energy * (1.0 + 1e-12),
                "GMBT {} > LMBT {}",
                gb.energy,
                l.energy
            );
        }
    }

    #[test]
    fn strip_bbt_has_m_plus_n_minus_2_triangles_of_two_bridges_and_a_bank() {
        let mut rng = Rng::new(5);
        let s = random_strip(&mut rng, 17, 23);
        for method in Method::NAMES.map(|(_, m)| m) {
            let steps = s.triangulate(method);
            let mesh = s.mesh(&steps);
            assert_eq!(mesh.faces.len(), 17 + 23 - 2);
            for f in &mesh.faces {
                let on_p = f.verts.iter().filter(|&&v| v < 17).count();
                // Two bridges and one bank edge: two vertices on one curve, one on the other,
                // and the two on the same curve are neighbours.
                assert!(on_p == 1 || on_p == 2);
                let same: Vec<usize> = if on_p == 2 {
                    f.verts.iter().copied().filter(|&v| v < 17).collect()
                } else {
                    f.verts.iter().copied().filter(|&v| v >= 17).collect()
                };
                assert_eq!(same[0].abs_diff(same[1]), 1);
            }
            let topo = mesh.topology();
            assert_eq!(topo.boundary_loops(&mesh), 1);
        }
    }

    #[test]
    fn strip_convexity_test_on_a_cylinder_and_a_saddle() {
        // Cylinder: radial bridges are valid; a flat annulus: every bridge valid.
        let n = 24;
        let circle = |r: f64, z: f64| -> Polyline {
            Polyline {
                points: (0..n)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / n as f64;
                        DVec3::new(r * a.cos(), r * a.sin(), z)
                    })
                    .collect(),
                closed: true,
            }
        };
        let cyl = Strip::new(&circle(50.0, 0.0), &circle(50.0, 100.0)).unwrap();
        for i in 0..cyl.m() {
            assert!(cyl.locally_convex(i, i));
        }
        assert!(!cyl.locally_convex(3, 9));
        let flat = Strip::new(&circle(50.0, 0.0), &circle(80.0, 0.0)).unwrap();
        assert!((0..flat.m()).all(|i| (0..flat.n()).all(|j| flat.locally_convex(i, j))));
        let steps = cyl.triangulate(Method::GodtGmbt);
        let mt = cyl.metrics(&steps);
        assert_eq!(mt.convex, mt.interior);
        assert!(matches!(
            Strip::new(&circle(50.0, 0.0), &circle(50.0, 0.0)),
            Err(StripError::Same)
        ));
    }
}
