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
//! - GODT (§5, graph Γ: edges leaving an invalid bridge weigh 1), GMBT (§5, the dual-node graph
//!   Ω: each bridge has a P-node and a Q-node, so the energy on a bridge, which depends on the
//!   triangles before and after it, is a fixed edge weight), GMAT (§5, triangle areas), and
//!   GODT+GMBT (the paper's combination: fewest invalid bridges, then least energy, as a
//!   lexicographic cost on Ω). The graphs are monotone DAGs on the m×n grid, so instead of
//!   Dijkstra one O(mn) dynamic program in row order finds the same optimum (§8 asks for
//!   exactly this); tests compare it with a plain Dijkstra and with brute force. The nodes'
//!   costs are computed in bands of rows on every core, the recurrence runs on one thread
//!   (see [`Strip::global`]). Memory: three rows of states, a few bands of costs and one byte
//!   of back pointers per grid node (the surface stage refuses more than 64 million nodes and
//!   asks for a coarser tolerance).
//! - LODT + LMBT (§4), kept for comparison: the greedy walk; when neither successor is valid it
//!   finds the nearest valid bridge `E_{i',j'}` with i' > i and j' > j (fewest steps, then the
//!   one most balanced between P and Q, then smaller i'), or the ending bridge if there is
//!   none, and reaches it by LMBT.
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

use super::Bend;
use crate::geom::curve::Polyline;
use crate::geom::mesh::{Face, Mesh};
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

fn newell(p: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for i in 0..p.len() {
        n += p[i].cross(p[(i + 1) % p.len()]);
    }
    n
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
    pub fn locally_convex(&self, i: usize, j: usize) -> bool {
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
    pub fn energy(&self, i: usize, j: usize, prev: Step, next: Step) -> f64 {
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

    /// GODT / GMBT / GMAT / GODT+GMBT by dynamic programming on the dual-node graph.
    ///
    /// Everything at a node (i, j) comes from the bridge `d = q_j − p_i` and the four bank
    /// vectors there: the area vectors of the triangles before it (`d × e_p⁻`, `d × e_q⁻`) and
    /// after it (`e_p⁺ × d`, `e_q⁺ × d`), and the triple products of the convexity test, which
    /// `d` reduces to `d̂·(e_a × e_b)` (the `d` part of `q_{j±1} − p_i` drops out). This is
    /// [`Strip::locally_convex`] and [`Strip::energy`] rewritten without repeated work; the
    /// tests check both against the plain versions through a Dijkstra on the same graph.
    ///
    /// The work is split in two: what each node costs ([`Strip::cost_row`], independent per
    /// row, computed in bands of rows on every core) and the recurrence over the grid (one
    /// thread, in row order, a few comparisons per node). A band's first row recomputes the
    /// triangles it shares with the row above by the same expression the row above used, so
    /// the costs, and the triangulation, are bit-identical whatever the number of threads.
    fn global(&self, method: Method) -> Vec<Step> {
        match method {
            Method::Godt => self.global_dp::<true, false, false>(),
            Method::Gmbt => self.global_dp::<false, true, false>(),
            Method::Gmat => self.global_dp::<false, false, true>(),
            _ => self.global_dp::<true, true, false>(),
        }
    }

    /// [`Strip::global`] for one objective, known at compile time.
    fn global_dp<const COUNT: bool, const ENERGY: bool, const AREA: bool>(&self) -> Vec<Step> {
        let (m, n) = (self.m(), self.n());
        // Rows per band: enough work per hand-over, small enough to stay in cache.
        let band = (65_536 / n.max(1)).clamp(1, 64);
        let workers = if m * n < 250_000 {
            1
        } else {
            std::thread::available_parallelism().map_or(1, |p| p.get())
        };
        self.global_bands::<COUNT, ENERGY, AREA>(band, workers)
    }

    /// [`Strip::global_dp`] with `band` rows per band and the costs computed on `workers`
    /// threads (1: on this one).
    fn global_bands<const COUNT: bool, const ENERGY: bool, const AREA: bool>(
        &self,
        band: usize,
        workers: usize,
    ) -> Vec<Step> {
        let (m, n) = (self.m(), self.n());
        let pb = Self::banks(&self.p, self.closed);
        let qb = Self::banks(&self.q, self.closed);
        let band = band.max(1);
        let bands = m.div_ceil(band);
        let workers = workers.min(bands);
        let cols = Columns::new(&self.q, &qb);
        let compute = |b: usize, out: &mut Costs, row: &mut Tris| {
            let r0 = b * band;
            let r1 = (r0 + band).min(m);
            out.resize((r1 - r0) * n);
            row.resize(n);
            if r0 > 0 {
                // The P-step triangles after row r0 − 1, by the expression cost_row uses.
                row.after_p(&cols, self.p[r0 - 1], pb[r0 - 1].0[1]);
            }
            for (k, i) in (r0..r1).enumerate() {
                self.cost_row_fastest::<COUNT, ENERGY, AREA>(i, &pb, &cols, row, out, k * n);
            }
        };
        let mut dp = Recurrence::new(m, n);
        if workers <= 1 {
            let (mut out, mut row) = (Costs::default(), Tris::default());
            for b in 0..bands {
                compute(b, &mut out, &mut row);
                dp.rows(b * band, &out);
            }
        } else {
            use std::sync::atomic::{AtomicUsize, Ordering};
            use std::sync::mpsc;
            let next = AtomicUsize::new(0);
            // A worker takes a buffer before a band number, so the band the recurrence waits
            // for always has a buffer and a worker: no deadlock, at most `pool` bands in flight.
            let pool = 2 * workers;
            let (free_tx, free_rx) = mpsc::sync_channel::<Costs>(pool);
            for _ in 0..pool {
                let _ = free_tx.send(Costs::default());
            }
            let free_rx = std::sync::Mutex::new(free_rx);
            let (done_tx, done_rx) = mpsc::channel::<(usize, Costs)>();
            std::thread::scope(|sc| {
                for _ in 0..workers {
                    let done_tx = done_tx.clone();
                    let (free_rx, next, compute) = (&free_rx, &next, &compute);
                    sc.spawn(move || {
                        let mut row = Tris::default();
                        loop {
                            let buf = match free_rx.lock() {
                                Ok(rx) => rx.recv(),
                                Err(_) => return,
                            };
                            let Ok(mut buf) = buf else { return };
                            let b = next.fetch_add(1, Ordering::Relaxed);
                            if b >= bands {
                                return;
                            }
                            compute(b, &mut buf, &mut row);
                            if done_tx.send((b, buf)).is_err() {
                                return;
                            }
                        }
                    });
                }
                drop(done_tx);
                let mut waiting = std::collections::BTreeMap::new();
                let mut b = 0;
                while b < bands {
                    let buf = match waiting.remove(&b) {
                        Some(buf) => buf,
                        None => match done_rx.recv() {
                            Ok((k, buf)) => {
                                waiting.insert(k, buf);
                                continue;
                            }
                            // A worker died (it cannot: cost_row does not panic); fall back.
                            Err(_) => {
                                let (mut out, mut row) = (Costs::default(), Tris::default());
                                compute(b, &mut out, &mut row);
                                out
                            }
                        },
                    };
                    dp.rows(b * band, &buf);
                    let _ = free_tx.send(buf);
                    b += 1;
                }
                // Wake the workers waiting for a buffer: they see the bands are all taken.
                for _ in 0..workers {
                    let _ = free_tx.try_send(Costs::default());
                }
            });
        }
        dp.path()
    }

    /// [`Strip::cost_row`] compiled for the widest vector instructions the CPU has: AVX2 on
    /// x86-64 machines that have it (checked at run time), else the baseline. The compiler
    /// never fuses a multiply and an add on its own, so both give bit-identical costs.
    #[allow(clippy::too_many_arguments)]
    fn cost_row_fastest<const COUNT: bool, const ENERGY: bool, const AREA: bool>(
        &self,
        i: usize,
        pb: &[([DVec3; 3], [f64; 2])],
        cols: &Columns,
        row: &mut Tris,
        out: &mut Costs,
        at: usize,
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            unsafe { self.cost_row_avx2::<COUNT, ENERGY, AREA>(i, pb, cols, row, out, at) };
            return;
        }
        self.cost_row::<COUNT, ENERGY, AREA>(i, pb, cols, row, out, at);
    }

    /// [`Strip::cost_row`] with AVX2 instructions.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn cost_row_avx2<const COUNT: bool, const ENERGY: bool, const AREA: bool>(
        &self,
        i: usize,
        pb: &[([DVec3; 3], [f64; 2])],
        cols: &Columns,
        row: &mut Tris,
        out: &mut Costs,
        at: usize,
    ) {
        self.cost_row::<COUNT, ENERGY, AREA>(i, pb, cols, row, out, at);
    }

    /// The costs of every node of row `i`, written at `out[at..at + n]`. `row` holds, for
    /// each column, the P-step triangle that ends at the node (the one after the node of the
    /// row above; recomputed on row 0) and receives this row's.
    ///
    /// The columns go in chunks of [`LANES`] fixed-size arrays, each step a loop over the
    /// chunk with no dependency between columns, which the compiler turns into instructions
    /// that handle several columns at once; the only thing carried from one chunk to the
    /// next is the Q-step triangle after the chunk's last column.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn cost_row<const COUNT: bool, const ENERGY: bool, const AREA: bool>(
        &self,
        i: usize,
        pb: &[([DVec3; 3], [f64; 2])],
        cols: &Columns,
        row: &mut Tris,
        out: &mut Costs,
        at: usize,
    ) {
        const L: usize = LANES;
        let n = self.n();
        let ([ep0, ep1, cp], [lp0, lp1]) = pb[i];
        let pi = self.p[i];
        // The Q-step triangle after the previous column (before the current one).
        let mut carry = Tri3::default();
        for c0 in (0..n).step_by(L) {
            let w = L.min(n - c0);
            let ld = |v: &[f64]| -> [f64; L] {
                let mut a = [0.0; L];
                a.copy_from_slice(&v[c0..c0 + L]);
                a
            };
            let (qx, qy, qz) = (ld(&cols.q.x), ld(&cols.q.y), ld(&cols.q.z));
            let (mut dx, mut dy, mut dz, mut l2) = ([0.0; L], [0.0; L], [0.0; L], [0.0; L]);
            for k in 0..L {
                dx[k] = qx[k] - pi.x;
                dy[k] = qy[k] - pi.y;
                dz[k] = qz[k] - pi.z;
                l2[k] = dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k];
            }
            // After, by a P step (e_p⁺ × d) and by a Q step (e_q⁺ × d).
            let (e1x, e1y, e1z) = (ld(&cols.e1.x), ld(&cols.e1.y), ld(&cols.e1.z));
            let mut p1 = Chunk::default();
            let mut q1 = Chunk::default();
            for k in 0..L {
                p1.set(k, cross(ep1.x, ep1.y, ep1.z, dx[k], dy[k], dz[k]));
                q1.set(k, cross(e1x[k], e1y[k], e1z[k], dx[k], dy[k], dz[k]));
            }
            // Before, by a P step: d × e_p⁻ on row 0, else the row above's.
            let mut p0 = Chunk::default();
            if i == 0 {
                for k in 0..L {
                    p0.set(k, cross(dx[k], dy[k], dz[k], ep0.x, ep0.y, ep0.z));
                }
            } else {
                p0 = Chunk {
                    x: ld(&row.x),
                    y: ld(&row.y),
                    z: ld(&row.z),
                    len: ld(&row.len),
                    inv: ld(&row.inv),
                };
            }
            row.store(c0, &p1);
            // Before, by a Q step: the previous column's Q step after (d × e_q⁻ on column 0).
            if c0 == 0 {
                let e0 = DVec3::new(cols.e0.x[0], cols.e0.y[0], cols.e0.z[0]);
                carry = Tri3::of(cross(dx[0], dy[0], dz[0], e0.x, e0.y, e0.z));
            }
            let mut q0 = Chunk::default();
            q0.put(0, carry);
            for k in 1..L {
                q0.x[k] = q1.x[k - 1];
                q0.y[k] = q1.y[k - 1];
                q0.z[k] = q1.z[k - 1];
                q0.len[k] = q1.len[k - 1];
                q0.inv[k] = q1.inv[k - 1];
            }
            carry = q1.get(L - 1);

            let (cqx, cqy, cqz) = (ld(&cols.c.x), ld(&cols.c.y), ld(&cols.c.z));
            let (lq0, lq1) = (ld(&cols.l0), ld(&cols.l1));
            let mut invalid = [false; L];
            let (mut w00, mut w01, mut w10, mut w11) = ([0.0; L], [0.0; L], [0.0; L], [0.0; L]);
            let dot = |t: &Chunk, k: usize, e: DVec3| e.x * t.x[k] + e.y * t.y[k] + e.z * t.z[k];
            for k in 0..L {
                let l2 = l2[k];
                let len = [p0.len[k], p1.len[k], q0.len[k], q1.len[k]];
                // Triple products d·(e_a × e_b) over the banks p⁻, p⁺, q⁻, q⁺ (a < b).
                let t01 = dx[k] * cp.x + dy[k] * cp.y + dz[k] * cp.z;
                let t23 = dx[k] * cqx[k] + dy[k] * cqy[k] + dz[k] * cqz[k];
                let t02 = -dot(&q0, k, ep0);
                let t03 = dot(&q1, k, ep0);
                let t12 = -dot(&q0, k, ep1);
                let t13 = dot(&q1, k, ep1);
                if COUNT {
                    let l = l2.sqrt();
                    // len: the neighbours' distances from the bridge's line, times l.
                    let o0 = len[0] > 1e-12 * l * lp0.max(l);
                    let o1 = len[1] > 1e-12 * l * lp1.max(l);
                    let o2 = len[2] > 1e-12 * l * lq0[k].max(l);
                    let o3 = len[3] > 1e-12 * l * lq1[k].max(l);
                    // For a pair (a, b), a < b: x = l·t_ab is l³ times the 2D cross product
                    // of the projections, len[a]·len[b] is l² times their lengths' product.
                    // `ge`: b is not clearly clockwise of a, `le`: not clearly
                    // counter-clockwise; seen from b the roles swap (the cross product
                    // changes sign, the tolerance not).
                    let pair = |a: usize, b: usize, t: f64| {
                        let x = t * l;
                        let tol = 1e-9 * len[a] * len[b];
                        (x >= -tol, x <= tol)
                    };
                    let (ge01, le01) = pair(0, 1, t01);
                    let (ge02, le02) = pair(0, 2, t02);
                    let (ge03, le03) = pair(0, 3, t03);
                    let (ge12, le12) = pair(1, 2, t12);
                    let (ge13, le13) = pair(1, 3, t13);
                    let (ge23, le23) = pair(2, 3, t23);
                    // Some neighbour has every other one on one side of it (or at most one
                    // neighbour is off the bridge's line): the bridge is on the hull.
                    let hull0 = ((ge01 | !o1) & (ge02 | !o2) & (ge03 | !o3))
                        | ((le01 | !o1) & (le02 | !o2) & (le03 | !o3));
                    let hull1 = ((le01 | !o0) & (ge12 | !o2) & (ge13 | !o3))
                        | ((ge01 | !o0) & (le12 | !o2) & (le13 | !o3));
                    let hull2 = ((le02 | !o0) & (le12 | !o1) & (ge23 | !o3))
                        | ((ge02 | !o0) & (ge12 | !o1) & (le23 | !o3));
                    let hull3 = ((le03 | !o0) & (le13 | !o1) & (le23 | !o2))
                        | ((ge03 | !o0) & (ge13 | !o1) & (ge23 | !o2));
                    let any = (o0 & hull0) | (o1 & hull1) | (o2 & hull2) | (o3 & hull3);
                    let real = u8::from(o0) + u8::from(o1) + u8::from(o2) + u8::from(o3);
                    invalid[k] = !(any | (real <= 1));
                }
                if ENERGY {
                    // |N1 × N2| = |d|·|d·(a × b)|, so sin²θ·A/L² needs no cross product:
                    // A sin²θ / L² = ½(|N1|+|N2|)·t²/(|N1|²|N2|²). A degenerate triangle
                    // (inv 0) bends nothing.
                    let inv_l2 = if l2 > 0.0 { 1.0 / l2 } else { 0.0 };
                    let bend = |a: &Chunk, b: &Chunk, t: f64| {
                        let s2 = (t * t * l2 * a.inv[k] * b.inv[k]).min(1.0);
                        let ab = a.x[k] * b.x[k] + a.y[k] * b.y[k] + a.z[k] * b.z[k];
                        let sn = if ab >= 0.0 { s2 } else { 2.0 - s2 };
                        let live = f64::from(u8::from((a.inv[k] > 0.0) & (b.inv[k] > 0.0)));
                        live * 0.5 * (a.len[k] + b.len[k]) * sn * inv_l2
                    };
                    w00[k] = bend(&p0, &p1, t01);
                    w01[k] = bend(&p0, &q1, t03);
                    w10[k] = bend(&q0, &p1, t12);
                    w11[k] = bend(&q0, &q1, t23);
                }
                if AREA {
                    // The area of the triangle a step makes.
                    let (a0, a1) = (0.5 * p1.len[k], 0.5 * q1.len[k]);
                    w00[k] += a0;
                    w10[k] += a0;
                    w01[k] += a1;
                    w11[k] += a1;
                }
            }
            if i == 0 && c0 == 0 {
                // The starting bridge counts as valid and bends nothing; its step's area
                // counts.
                invalid[0] = false;
                let (a0, a1) = if AREA {
                    (0.5 * p1.len[0], 0.5 * q1.len[0])
                } else {
                    (0.0, 0.0)
                };
                (w00[0], w10[0], w01[0], w11[0]) = (a0, a0, a1, a1);
            }
            let o = at + c0;
            out.invalid[o..o + w].copy_from_slice(&invalid[..w]);
            let [[o00, o01], [o10, o11]] = &mut out.w;
            o00[o..o + w].copy_from_slice(&w00[..w]);
            o01[o..o + w].copy_from_slice(&w01[..w]);
            o10[o..o + w].copy_from_slice(&w10[..w]);
            o11[o..o + w].copy_from_slice(&w11[..w]);
        }
    }

    /// LODT + LMBT (§4).
    fn local(&self) -> Vec<Step> {
        let (m, n) = (self.m(), self.n());
        let valid = |i: usize, j: usize| self.is_end(i, j) || self.locally_convex(i, j);
        let mut steps = Vec::with_capacity(m + n - 2);
        let (mut i, mut j) = (0, 0);
        let mut prev = Step::P;
        // Steps of least energy at the current bridge, with a forced choice at the borders.
        let lmbt_step = |i: usize, j: usize, prev: Step, ti: usize, tj: usize| -> Step {
            if i == ti {
                Step::Q
            } else if j == tj {
                Step::P
            } else if self.energy(i, j, prev, Step::Q) < self.energy(i, j, prev, Step::P) {
                Step::Q
            } else {
                Step::P
            }
        };
        while i + 1 < m || j + 1 < n {
            let s = if i + 1 == m {
                Step::Q
            } else if j + 1 == n {
                Step::P
            } else {
                match (valid(i + 1, j), valid(i, j + 1)) {
                    (true, false) => Step::P,
                    (false, true) => Step::Q,
                    (true, true) => lmbt_step(i, j, prev, m, n),
                    (false, false) => {
                        // Nearest valid bridge beyond, then LMBT to it.
                        let (ti, tj) = self.nearest_valid(i, j);
                        while i < ti || j < tj {
                            let s = lmbt_step(i, j, prev, ti, tj);
                            steps.push(s);
                            match s {
                                Step::P => i += 1,
                                Step::Q => j += 1,
                            }
                            prev = s;
                        }
                        continue;
                    }
                }
            };
            steps.push(s);
            match s {
                Step::P => i += 1,
                Step::Q => j += 1,
            }
            prev = s;
        }
        steps
    }

    /// Nearest valid bridge (i', j') with i' > i and j' > j, else the ending bridge.
    fn nearest_valid(&self, i: usize, j: usize) -> (usize, usize) {
        let (m, n) = (self.m(), self.n());
        let max_d = (m - 1 - i) + (n - 1 - j);
        for d in 2..=max_d {
            // Most balanced first, then smaller i'.
            let mut cands: Vec<(usize, usize)> = (1..d)
                .map(|di| (i + di, j + d - di))
                .filter(|&(a, b)| a < m && b < n)
                .collect();
            cands.sort_by_key(|&(a, b)| ((a - i).abs_diff(b - j), a));
            for (a, b) in cands {
                if self.is_end(a, b) || self.locally_convex(a, b) {
                    return (a, b);
                }
            }
        }
        (m - 1, n - 1)
    }

    /// Bridges of a BBT in order, as (i, j), starting and ending bridge included.
    pub fn bridges(&self, steps: &[Step]) -> Vec<(usize, usize)> {
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
            }
        }
        // What bent after the last pick belongs to it (so the angles add up to the total).
        if let (BendLines::Spacing(_), Some(last)) = (lines, out.last_mut()) {
            last.angle_deg += acc.to_degrees();
        }
        out
    }

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

/// Columns per chunk in [`Strip::cost_row`].
const LANES: usize = 4;

/// Vectors stored one array per axis (structure of arrays), padded with zeros to a whole
/// number of [`LANES`] chunks.
#[derive(Debug, Clone, Default)]
struct Soa3 {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl Soa3 {
    fn of(v: impl Iterator<Item = DVec3> + Clone) -> Soa3 {
        Soa3 {
            x: padded(v.clone().map(|p| p.x)),
            y: padded(v.clone().map(|p| p.y)),
            z: padded(v.map(|p| p.z)),
        }
    }
}

/// The values, then zeros up to a whole number of [`LANES`].
fn padded(v: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut a: Vec<f64> = v.collect();
    a.resize(a.len().div_ceil(LANES) * LANES, 0.0);
    a
}

/// A triangle's area vector (twice its area, along its normal), its length and 1 / its
/// squared length (0 for a degenerate triangle).
#[derive(Debug, Clone, Copy, Default)]
struct Tri3 {
    x: f64,
    y: f64,
    z: f64,
    len: f64,
    inv: f64,
}

impl Tri3 {
    #[inline(always)]
    fn of((x, y, z): (f64, f64, f64)) -> Tri3 {
        let q = x * x + y * y + z * z;
        Tri3 {
            x,
            y,
            z,
            len: q.sqrt(),
            inv: if q > 0.0 { 1.0 / q } else { 0.0 },
        }
    }
}

/// [`Tri3`]s of one chunk of columns, one array per field.
#[derive(Debug, Clone, Copy, Default)]
struct Chunk {
    x: [f64; LANES],
    y: [f64; LANES],
    z: [f64; LANES],
    len: [f64; LANES],
    inv: [f64; LANES],
}

impl Chunk {
    #[inline(always)]
    fn put(&mut self, k: usize, t: Tri3) {
        (self.x[k], self.y[k], self.z[k], self.len[k], self.inv[k]) = (t.x, t.y, t.z, t.len, t.inv);
    }

    #[inline(always)]
    fn set(&mut self, k: usize, v: (f64, f64, f64)) {
        self.put(k, Tri3::of(v));
    }

    fn get(&self, k: usize) -> Tri3 {
        Tri3 {
            x: self.x[k],
            y: self.y[k],
            z: self.z[k],
            len: self.len[k],
            inv: self.inv[k],
        }
    }
}

/// [`Tri3`]s of a whole row, one array per field, padded to whole chunks: the P-step
/// triangles that end at the next row.
#[derive(Debug, Clone, Default)]
struct Tris {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    len: Vec<f64>,
    inv: Vec<f64>,
}

impl Tris {
    fn resize(&mut self, n: usize) {
        let n = n.div_ceil(LANES) * LANES;
        for a in [
            &mut self.x,
            &mut self.y,
            &mut self.z,
            &mut self.len,
            &mut self.inv,
        ] {
            a.resize(n, 0.0);
        }
    }

    fn store(&mut self, c0: usize, c: &Chunk) {
        self.x[c0..c0 + LANES].copy_from_slice(&c.x);
        self.y[c0..c0 + LANES].copy_from_slice(&c.y);
        self.z[c0..c0 + LANES].copy_from_slice(&c.z);
        self.len[c0..c0 + LANES].copy_from_slice(&c.len);
        self.inv[c0..c0 + LANES].copy_from_slice(&c.inv);
    }

    /// The P-step triangles after the bridges from `p` (bank `e1` to the next point):
    /// `e1 × (q_j − p)`, the expression [`Strip::cost_row`] computes them with.
    fn after_p(&mut self, cols: &Columns, p: DVec3, e1: DVec3) {
        for j in 0..self.x.len() {
            let (dx, dy, dz) = (cols.q.x[j] - p.x, cols.q.y[j] - p.y, cols.q.z[j] - p.z);
            let t = Tri3::of(cross(e1.x, e1.y, e1.z, dx, dy, dz));
            (self.x[j], self.y[j], self.z[j], self.len[j], self.inv[j]) =
                (t.x, t.y, t.z, t.len, t.inv);
        }
    }
}

/// The points of Q and their banks (to the previous and next point, their cross product and
/// lengths), by column, padded to whole chunks.
struct Columns {
    q: Soa3,
    e0: Soa3,
    e1: Soa3,
    c: Soa3,
    l0: Vec<f64>,
    l1: Vec<f64>,
}

impl Columns {
    fn new(q: &[DVec3], qb: &[([DVec3; 3], [f64; 2])]) -> Columns {
        Columns {
            q: Soa3::of(q.iter().copied()),
            e0: Soa3::of(qb.iter().map(|b| b.0[0])),
            e1: Soa3::of(qb.iter().map(|b| b.0[1])),
            c: Soa3::of(qb.iter().map(|b| b.0[2])),
            l0: padded(qb.iter().map(|b| b.1[0])),
            l1: padded(qb.iter().map(|b| b.1[1])),
        }
    }
}

/// `a × b`, component-wise (glam's expression, so results match `DVec3::cross`).
#[inline(always)]
fn cross(ax: f64, ay: f64, az: f64, bx: f64, by: f64, bz: f64) -> (f64, f64, f64) {
    (ay * bz - by * az, az * bx - bz * ax, ax * by - bx * ay)
}

/// What the nodes of a band of rows cost, row after row: the bridge is not locally convex
/// (GODT), and the weight of the pair of steps through it, `w[made by][leaves by]` (P = 0,
/// Q = 1): bending energy (GMBT) or the area of the triangle it leaves by (GMAT).
#[derive(Debug, Clone, Default)]
struct Costs {
    invalid: Vec<bool>,
    w: [[Vec<f64>; 2]; 2],
}

impl Costs {
    /// Room for `len` nodes; the values left are overwritten by [`Strip::cost_row`].
    fn resize(&mut self, len: usize) {
        self.invalid.resize(len, false);
        for w in self.w.iter_mut().flatten() {
            w.resize(len, 0.0);
        }
    }
}

/// The recurrence of the global triangulations, fed row by row with the nodes' costs: the best
/// (fewest invalid bridges, then least weight) way to reach each node by a P step and by a Q
/// step, for three rows at a time, and one byte of back pointers per node.
///
/// Each state has exactly one predecessor node (a P state the node above, a Q state the node
/// to the left), so a state is written once, with the better of the two states it can come
/// from (ties: P), without branches, as the comparisons are unpredictable. Unreachable states
/// hold INF (and ∞), which loses every comparison and stays far below `u32::MAX` after the at
/// most m + n increments. Along a row each node waits for the one before it; two rows are
/// worked on together, the lower one column behind, so that the processor overlaps two such
/// chains.
struct Recurrence {
    m: usize,
    n: usize,
    /// Row i's states at `(i % 3) · n + j`.
    st: Vec<State>,
    back: Vec<u8>,
}

/// The best costs of reaching a node by a P step ([0]) and by a Q step ([1]).
#[derive(Debug, Clone, Copy)]
struct State {
    c: [u32; 2],
    v: [f64; 2],
}

impl State {
    const NONE: State = State {
        c: [Recurrence::INF; 2],
        v: [f64::INFINITY; 2],
    };
}

impl Recurrence {
    const INF: u32 = 1 << 30;

    fn new(m: usize, n: usize) -> Recurrence {
        let mut r = Recurrence {
            m,
            n,
            st: vec![State::NONE; 3 * n],
            back: vec![0u8; m * n],
        };
        r.st[0] = State {
            c: [0, 0],
            v: [0.0, 0.0],
        };
        r
    }

    /// Rows `r0`, `r0 + 1`, … (in order, after all rows before `r0`), `n` costs each.
    fn rows(&mut self, r0: usize, costs: &Costs) {
        let n = self.n;
        let rows = costs.invalid.len() / n;
        let mut k = 0;
        while k < rows {
            let i = r0 + k;
            // Two rows together while neither is the last one (which has no P steps).
            if k + 1 < rows && i + 2 < self.m {
                self.two_rows(i, costs, k * n);
                k += 2;
            } else {
                self.one_row(i, costs, k * n);
                k += 1;
            }
        }
    }

    /// The states of node (i, j)'s successors, from its own and its costs at `costs[at + j]`:
    /// the P state of (i + 1, j) unless `i` is the last row, the Q state of (i, j + 1).
    #[inline(always)]
    fn node(&mut self, i: usize, j: usize, costs: &Costs, at: usize) {
        let n = self.n;
        let cur = (i % 3) * n;
        let s = self.st[cur + j];
        let inc = u32::from(costs.invalid[at + j]);
        let [[w00, w01], [w10, w11]] = &costs.w;
        let c = [s.c[0] + inc, s.c[1] + inc];
        let pick = |v: [f64; 2]| {
            let q = c[1] < c[0] || (c[1] == c[0] && v[1] < v[0]);
            (
                if q { c[1] } else { c[0] },
                if q { v[1] } else { v[0] },
                u8::from(q),
            )
        };
        if i + 1 < self.m {
            let (bc, bv, arg) = pick([s.v[0] + w00[at + j], s.v[1] + w10[at + j]]);
            let next = ((i + 1) % 3) * n;
            self.st[next + j].c[0] = bc;
            self.st[next + j].v[0] = bv;
            self.back[(i + 1) * n + j] |= arg;
        }
        if j + 1 < n {
            let (bc, bv, arg) = pick([s.v[0] + w01[at + j], s.v[1] + w11[at + j]]);
            self.st[cur + j + 1].c[1] = bc;
            self.st[cur + j + 1].v[1] = bv;
            self.back[i * n + j + 1] |= arg << 1;
        }
    }

    /// Clear the states of row `i` (its buffer last held row i − 3).
    fn clear(&mut self, i: usize) {
        let b = (i % 3) * self.n;
        self.st[b..b + self.n].fill(State::NONE);
    }

    /// Row `i`, whose costs start at `at` in `costs`.
    fn one_row(&mut self, i: usize, costs: &Costs, at: usize) {
        let n = self.n;
        if i + 1 < self.m {
            self.clear(i + 1);
        }
        let ends = if i + 1 == self.m { n - 1 } else { n };
        for j in 0..ends {
            self.node(i, j, costs, at);
        }
    }

    /// Rows `i` and `i + 1` (neither the last), costs at `at` and `at + n`: node (i + 1, j − 1)
    /// after node (i, j), which set its P state.
    fn two_rows(&mut self, i: usize, costs: &Costs, at: usize) {
        let n = self.n;
        self.clear(i + 1);
        self.clear(i + 2);
        self.node(i, 0, costs, at);
        for j in 1..n {
            self.node(i, j, costs, at);
            self.node(i + 1, j - 1, costs, at + n);
        }
        self.node(i + 1, n - 1, costs, at + n);
    }

    /// The steps of the best path, once every row has been fed.
    fn path(self) -> Vec<Step> {
        let (m, n) = (self.m, self.n);
        // Row m−1's last node: pick the better end state (ties: P).
        let e = self.st[((m - 1) % 3) * n + n - 1];
        let (ec, ev) = (e.c, e.v);
        let mut s = usize::from(ec[1] < ec[0] || (ec[1] == ec[0] && ev[1] < ev[0]));
        let mut steps = Vec::with_capacity(m + n - 2);
        let (mut i, mut j) = (m - 1, n - 1);
        while i > 0 || j > 0 {
            let b = (self.back[i * n + j] >> s) & 1;
            if s == 0 {
                steps.push(Step::P);
                i -= 1;
            } else {
                steps.push(Step::Q);
                j -= 1;
            }
            s = b as usize;
        }
        steps.reverse();
        steps
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

    /// Deterministic pseudo-random numbers (xorshift64*).
    pub(crate) struct Rng(pub u64);
    impl Rng {
        pub(crate) fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A wavy random strip: two noisy curves about `width` apart.
    pub(crate) fn random_strip(rng: &mut Rng, m: usize, n: usize) -> Strip {
        let mut curve = |k: usize, y: f64| -> Vec<DVec3> {
            let mut x = 0.0;
            (0..k)
                .map(|_| {
                    x += 0.5 + rng.next();
                    DVec3::new(x, y + 0.6 * (rng.next() - 0.5), 2.0 * (rng.next() - 0.5))
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
        let mut rng = Rng(7);
        for trial in 0..40 {
            let m = 2 + (rng.next() * 12.0) as usize;
            let n = 2 + (rng.next() * 12.0) as usize;
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
        let mut rng = Rng(7);
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
        let mut rng = Rng(99);
        for _ in 0..15 {
            let (m, n) = (
                2 + (rng.next() * 5.0) as usize,
                2 + (rng.next() * 5.0) as usize,
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
        let mut rng = Rng(2024);
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
        let mut rng = Rng(5);
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
