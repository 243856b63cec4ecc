//! The data the cost rows of [`super::global`] run on: vectors one array per axis, padded to
//! whole chunks of [`LANES`] columns, so that each step of a row is a loop over a chunk with no
//! dependency between columns (the compiler turns it into vector instructions); triangles as
//! area vectors with their lengths; the per-node costs of a band of rows.

use glam::DVec3;

/// Columns per chunk in [`super::Strip::cost_row`].
pub(super) const LANES: usize = 4;

/// Vectors stored one array per axis (structure of arrays), padded with zeros to a whole
/// number of [`LANES`] chunks.
#[derive(Debug, Clone, Default)]
pub(super) struct Soa3 {
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) z: Vec<f64>,
}

impl Soa3 {
    pub(super) fn of(v: impl Iterator<Item = DVec3> + Clone) -> Soa3 {
        Soa3 {
            x: padded(v.clone().map(|p| p.x)),
            y: padded(v.clone().map(|p| p.y)),
            z: padded(v.map(|p| p.z)),
        }
    }
}

/// The values, then zeros up to a whole number of [`LANES`].
pub(super) fn padded(v: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut a: Vec<f64> = v.collect();
    a.resize(a.len().div_ceil(LANES) * LANES, 0.0);
    a
}

/// A triangle's area vector (twice its area, along its normal), its length and 1 / its
/// squared length (0 for a degenerate triangle).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Tri3 {
    pub(super) x: f64,
    pub(super) y: f64,
    pub(super) z: f64,
    pub(super) len: f64,
    pub(super) inv: f64,
}

impl Tri3 {
    #[inline(always)]
    pub(super) fn of((x, y, z): (f64, f64, f64)) -> Tri3 {
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
pub(super) struct Chunk {
    pub(super) x: [f64; LANES],
    pub(super) y: [f64; LANES],
    pub(super) z: [f64; LANES],
    pub(super) len: [f64; LANES],
    pub(super) inv: [f64; LANES],
}

impl Chunk {
    #[inline(always)]
    pub(super) fn put(&mut self, k: usize, t: Tri3) {
        (self.x[k], self.y[k], self.z[k], self.len[k], self.inv[k]) = (t.x, t.y, t.z, t.len, t.inv);
    }

    #[inline(always)]
    pub(super) fn set(&mut self, k: usize, v: (f64, f64, f64)) {
        self.put(k, Tri3::of(v));
    }

    pub(super) fn get(&self, k: usize) -> Tri3 {
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
pub(super) struct Tris {
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) z: Vec<f64>,
    pub(super) len: Vec<f64>,
    pub(super) inv: Vec<f64>,
}

impl Tris {
    pub(super) fn resize(&mut self, n: usize) {
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

    pub(super) fn store(&mut self, c0: usize, c: &Chunk) {
        self.x[c0..c0 + LANES].copy_from_slice(&c.x);
        self.y[c0..c0 + LANES].copy_from_slice(&c.y);
        self.z[c0..c0 + LANES].copy_from_slice(&c.z);
        self.len[c0..c0 + LANES].copy_from_slice(&c.len);
        self.inv[c0..c0 + LANES].copy_from_slice(&c.inv);
    }

    /// The P-step triangles after the bridges from `p` (bank `e1` to the next point):
    /// `e1 × (q_j − p)`, the expression [`super::Strip::cost_row`] computes them with.
    pub(super) fn after_p(&mut self, cols: &Columns, p: DVec3, e1: DVec3) {
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
pub(super) struct Columns {
    pub(super) q: Soa3,
    pub(super) e0: Soa3,
    pub(super) e1: Soa3,
    pub(super) c: Soa3,
    pub(super) l0: Vec<f64>,
    pub(super) l1: Vec<f64>,
}

impl Columns {
    pub(super) fn new(q: &[DVec3], qb: &[([DVec3; 3], [f64; 2])]) -> Columns {
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
pub(super) fn cross(ax: f64, ay: f64, az: f64, bx: f64, by: f64, bz: f64) -> (f64, f64, f64) {
    (ay * bz - by * az, az * bx - bz * ax, ax * by - bx * ay)
}

/// What the nodes of a band of rows cost, row after row: the bridge is not locally convex
/// (GODT), and the weight of the pair of steps through it, `w[made by][leaves by]` (P = 0,
/// Q = 1): bending energy (GMBT) or the area of the triangle it leaves by (GMAT).
#[derive(Debug, Clone, Default)]
pub(super) struct Costs {
    pub(super) invalid: Vec<bool>,
    pub(super) w: [[Vec<f64>; 2]; 2],
}

impl Costs {
    /// Room for `len` nodes; the values left are overwritten by [`super::Strip::cost_row`].
    pub(super) fn resize(&mut self, len: usize) {
        self.invalid.resize(len, false);
        for w in self.w.iter_mut().flatten() {
            w.resize(len, 0.0);
        }
    }
}
