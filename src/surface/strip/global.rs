//! The global searches (§5).
//!
//! GODT (§5, graph Γ: edges leaving an invalid bridge weigh 1), GMBT (§5, the dual-node graph
//! Ω: each bridge has a P-node and a Q-node, so the energy on a bridge, which depends on the
//! triangles before and after it, is a fixed edge weight), GMAT (§5, triangle areas), and
//! GODT+GMBT (the paper's combination: fewest invalid bridges, then least energy, as a
//! lexicographic cost on Ω). The graphs are monotone DAGs on the m×n grid, so instead of
//! Dijkstra one O(mn) dynamic program in row order finds the same optimum (§8 asks for
//! exactly this); tests compare it with a plain Dijkstra and with brute force. The nodes'
//! costs are computed in bands of rows on every core, the recurrence runs on one thread
//! (see [`Strip::global`]). Memory: three rows of states, a few bands of costs and one byte
//! of back pointers per grid node (the surface stage refuses more than 64 million nodes and
//! asks for a coarser tolerance).

use super::lanes::{cross, Chunk, Columns, Costs, Tri3, Tris, LANES};
use super::{Method, Step, Strip};
use glam::DVec3;

impl Strip {
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
    pub(super) fn global(&self, method: Method) -> Vec<Step> {
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
    pub(super) fn global_bands<const COUNT: bool, const ENERGY: bool, const AREA: bool>(
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
                let at_row = RowAt {
                    i,
                    pb: &pb,
                    cols: &cols,
                };
                self.cost_row_fastest::<COUNT, ENERGY, AREA>(at_row, row, out, k * n);
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
    fn cost_row_fastest<const COUNT: bool, const ENERGY: bool, const AREA: bool>(
        &self,
        at_row: RowAt,
        row: &mut Tris,
        out: &mut Costs,
        at: usize,
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            unsafe { self.cost_row_avx2::<COUNT, ENERGY, AREA>(at_row, row, out, at) };
            return;
        }
        self.cost_row::<COUNT, ENERGY, AREA>(at_row, row, out, at);
    }

    /// [`Strip::cost_row`] with AVX2 instructions.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn cost_row_avx2<const COUNT: bool, const ENERGY: bool, const AREA: bool>(
        &self,
        at_row: RowAt,
        row: &mut Tris,
        out: &mut Costs,
        at: usize,
    ) {
        self.cost_row::<COUNT, ENERGY, AREA>(at_row, row, out, at);
    }

    /// The costs of every node of row `i`, written at `out[at..at + n]`. `row` holds, for
    /// each column, the P-step triangle that ends at the node (the one after the node of the
    /// row above; recomputed on row 0) and receives this row's.
    ///
    /// The columns go in chunks of [`LANES`] fixed-size arrays, each step a loop over the
    /// chunk with no dependency between columns, which the compiler turns into instructions
    /// that handle several columns at once; the only thing carried from one chunk to the
    /// next is the Q-step triangle after the chunk's last column.
    #[inline(always)]
    fn cost_row<const COUNT: bool, const ENERGY: bool, const AREA: bool>(
        &self,
        at_row: RowAt,
        row: &mut Tris,
        out: &mut Costs,
        at: usize,
    ) {
        const L: usize = LANES;
        let RowAt { i, pb, cols } = at_row;
        let n = self.n();
        let ([ep0, ep1, cp], [lp0, lp1]) = pb[i];
        let pi = self.p[i];
        // The Q-step triangle after the previous column (before the current one).
        let mut carry = Tri3::default();
        for c0 in (0..n).step_by(L) {
            let w = L.min(n - c0);
            let ld = |v: &[f64]| lanes(v, c0);
            let Around {
                dx,
                dy,
                dz,
                l2,
                p0,
                p1,
                q0,
                q1,
            } = around(i, c0, pi, (ep0, ep1), cols, row, &mut carry);

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
                    let lens = [lp0, lp1, lq0[k], lq1[k]];
                    invalid[k] = off_hull(len, [t01, t02, t03, t12, t13, t23], l2, lens);
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
}

/// What a cost row reads: its index `i`, the P banks and the Q columns.
#[derive(Clone, Copy)]
struct RowAt<'a> {
    i: usize,
    pb: &'a [([DVec3; 3], [f64; 2])],
    cols: &'a Columns,
}

/// A chunk of `LANES` values of `v` from `c0` (the arrays are padded to whole chunks).
#[inline(always)]
fn lanes(v: &[f64], c0: usize) -> [f64; LANES] {
    let mut a = [0.0; LANES];
    a.copy_from_slice(&v[c0..c0 + LANES]);
    a
}

/// The bridges `d = q_j − p_i` of one chunk of columns (and `|d|²`), and the four triangles
/// around each: before and after it by a P step (`p0`, `p1`) and by a Q step (`q0`, `q1`).
struct Around {
    dx: [f64; LANES],
    dy: [f64; LANES],
    dz: [f64; LANES],
    l2: [f64; LANES],
    p0: Chunk,
    p1: Chunk,
    q0: Chunk,
    q1: Chunk,
}

/// [`Around`] for row `i`, columns `c0..c0 + LANES`: stores this row's P-step triangles after
/// into `row`, and carries the Q-step triangle after the chunk's last column in `carry`.
#[inline(always)]
fn around(
    i: usize,
    c0: usize,
    pi: DVec3,
    (ep0, ep1): (DVec3, DVec3),
    cols: &Columns,
    row: &mut Tris,
    carry: &mut Tri3,
) -> Around {
    const L: usize = LANES;
    let ld = |v: &[f64]| lanes(v, c0);
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
        *carry = Tri3::of(cross(dx[0], dy[0], dz[0], e0.x, e0.y, e0.z));
    }
    let mut q0 = Chunk::default();
    q0.put(0, *carry);
    for k in 1..L {
        q0.x[k] = q1.x[k - 1];
        q0.y[k] = q1.y[k - 1];
        q0.z[k] = q1.z[k - 1];
        q0.len[k] = q1.len[k - 1];
        q0.inv[k] = q1.inv[k - 1];
    }
    *carry = q1.get(L - 1);
    Around {
        dx,
        dy,
        dz,
        l2,
        p0,
        p1,
        q0,
        q1,
    }
}

/// §3.2 local convexity of one bridge from the triple products `t = [t01, t02, t03, t12, t13,
/// t23]` over its banks p⁻, p⁺, q⁻, q⁺, their `len`gths off the bridge's line (times its
/// length), `|d|²` and the bank lengths `lens`: whether the bridge is *not* on the hull.
#[inline(always)]
fn off_hull(len: [f64; 4], t: [f64; 6], l2: f64, lens: [f64; 4]) -> bool {
    let [t01, t02, t03, t12, t13, t23] = t;
    let [lp0, lp1, lq0, lq1] = lens;
    let l = l2.sqrt();
    // len: the neighbours' distances from the bridge's line, times l.
    let o0 = len[0] > 1e-12 * l * lp0.max(l);
    let o1 = len[1] > 1e-12 * l * lp1.max(l);
    let o2 = len[2] > 1e-12 * l * lq0.max(l);
    let o3 = len[3] > 1e-12 * l * lq1.max(l);
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
    let hull0 =
        ((ge01 | !o1) & (ge02 | !o2) & (ge03 | !o3)) | ((le01 | !o1) & (le02 | !o2) & (le03 | !o3));
    let hull1 =
        ((le01 | !o0) & (ge12 | !o2) & (ge13 | !o3)) | ((ge01 | !o0) & (le12 | !o2) & (le13 | !o3));
    let hull2 =
        ((le02 | !o0) & (le12 | !o1) & (ge23 | !o3)) | ((ge02 | !o0) & (ge12 | !o1) & (le23 | !o3));
    let hull3 =
        ((le03 | !o0) & (le13 | !o1) & (le23 | !o2)) | ((ge03 | !o0) & (ge13 | !o1) & (ge23 | !o2));
    let any = (o0 & hull0) | (o1 & hull1) | (o2 & hull2) | (o3 & hull3);
    let real = u8::from(o0) + u8::from(o1) + u8::from(o2) + u8::from(o3);
    !(any | (real <= 1))
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
