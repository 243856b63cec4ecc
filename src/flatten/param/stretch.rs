//! Free-boundary L2 stretch minimisation (Sander, Snyder, Gortler, Hoppe 2001, §4: the L2
//! stretch norm and its minimisation one vertex at a time): a nonlinear Gauss–Seidel over the
//! vertices of a flip-free layout, each moved to lower the whole chart's scale-free L2
//! stretch E = (Σ A₃·f) · (Σ A₂), f = ‖J‖²_F with J the linear map from a flat triangle to
//! its 3D shape (the L2² of [`super::distortion::stretch`] up to a constant). A move that
//! would flip or collapse a triangle is refused, so the result stays flip-free, and E never
//! increases.
//!
//! Choices where the paper is silent:
//! - **The step.** With the other corners fixed, a triangle's ‖J‖²·D² (D twice its flat signed
//!   area) is a quadratic in the moving vertex and D is affine in it: ‖J‖² = ‖M + w xᵀ‖²/D²
//!   with M = Σᵢ sᵢ eᵢᵀ (sᵢ the 3D shape's corners in its plane, eᵢ the flat edge opposite
//!   corner i), w = s_{c+1} − s_{c+2} for the moving corner c, x the move. So the local energy's
//!   gradient and Hessian are closed-form, and each vertex takes a Newton step on it.
//! - **Over-relaxed**, as successive over-relaxation does for linear Gauss–Seidel: the Newton
//!   step is taken 1.9 times, no longer than the vertex's least height over an opposite edge
//!   (a gradient step of half that length where the Hessian is not positive definite), then
//!   halved (at most 12 times) until E decreases without a flip. Exact local steps leave the
//!   smooth part of the error to many sweeps; over-relaxed ones carry it further per sweep.
//! - **Stopping.** After `sweeps` sweeps, or when a sweep lowers E by less than 1e-5 of it.
//!
//! The free-boundary minimisation moves every vertex at once ([`super::lbfgs`]); these sweeps
//! relax the inside of a chart whose boundary is held (seam matching, [`super::seams`]) and
//! stand in where the quasi-Newton preconditioner cannot be factored.

use super::{shapes_from_3d, Chart};
use glam::{DMat2, DVec2};

/// Over-relaxation of the Newton step (see the module doc).
const OVER_RELAX: f64 = 1.9;

/// One triangle around the moving vertex, as its local energy needs it (see the module doc).
#[derive(Clone, Copy)]
struct Local {
    /// 3D area.
    a3: f64,
    /// ‖M‖², Mᵀw, ‖w‖² at the current position.
    n0: f64,
    u: DVec2,
    k: f64,
    /// D at the current position, its reciprocal, and its gradient.
    d0: f64,
    inv_d: f64,
    n: DVec2,
}

/// A triangle round a moving vertex: its vertices, 3D shape and area, and the vertex's corner.
#[derive(Clone, Copy)]
struct Corner {
    tri: [usize; 3],
    shape: [DVec2; 3],
    a3: f64,
    c: usize,
}

/// M and D of a triangle with flat corners `p` and 3D shape `shape` (see the module doc).
fn m_and_d(p: [DVec2; 3], shape: &[DVec2; 3]) -> (DMat2, f64) {
    let e = [p[2] - p[1], p[0] - p[2], p[1] - p[0]];
    let col = |j: usize| shape[0] * e[0][j] + shape[1] * e[1][j] + shape[2] * e[2][j];
    (DMat2::from_cols(col(0), col(1)), e[2].perp_dot(-e[1]))
}

impl Local {
    /// The triangle `t` of `chart` (3D shape `shape`, 3D area `a3`) seen from its corner `c`,
    /// at the layout `uv`.
    fn new(tri: [usize; 3], shape: &[DVec2; 3], a3: f64, c: usize, uv: &[DVec2]) -> Local {
        let p = [uv[tri[0]], uv[tri[1]], uv[tri[2]]];
        let (m, _) = m_and_d(p, shape);
        let (c1, c2) = match c {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        let w = shape[c1] - shape[c2];
        let (a, b) = (p[c1], p[c2]);
        let d0 = (a - p[c]).perp_dot(b - p[c]);
        Local {
            a3,
            n0: m.x_axis.length_squared() + m.y_axis.length_squared(),
            u: m.transpose() * w,
            k: w.length_squared(),
            d0,
            inv_d: 1.0 / d0,
            n: (b - a).perp(),
        }
    }

    /// (A₃·f, A₂) where the vertex is; `None` when the triangle is flipped or collapsed.
    fn here(&self) -> Option<(f64, f64)> {
        if !(self.d0 > 0.0 && self.d0.is_finite()) {
            return None;
        }
        Some((self.a3 * self.n0 * self.inv_d * self.inv_d, 0.5 * self.d0))
    }

    /// (A₃·f, A₂) after moving the vertex by `x`; `None` when the triangle flips or collapses.
    fn at(&self, x: DVec2) -> Option<(f64, f64)> {
        let d = self.d0 + self.n.dot(x);
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        let num = self.n0 + 2.0 * self.u.dot(x) + self.k * x.length_squared();
        Some((self.a3 * num / (d * d), 0.5 * d))
    }

    /// The gradient of A₃·f in the vertex, where it is, and its Hessian's entries (xx, xy,
    /// yy).
    fn derivatives(&self) -> (DVec2, [f64; 3]) {
        let (n, u) = (self.n, self.u);
        let i2 = self.inv_d * self.inv_d;
        let i3 = i2 * self.inv_d;
        let g = u * (2.0 * i2) - n * (2.0 * self.n0 * i3);
        let (diag, cross, outer) = (2.0 * self.k * i2, 4.0 * i3, 6.0 * self.n0 * i2 * i2);
        let h = [
            diag - cross * (2.0 * u.x * n.x) + outer * n.x * n.x,
            -cross * (u.x * n.y + u.y * n.x) + outer * n.x * n.y,
            diag - cross * (2.0 * u.y * n.y) + outer * n.y * n.y,
        ];
        (g * self.a3, h.map(|v| v * self.a3))
    }
}

/// The sweeps on a flip-free layout `uv` (per local vertex), the vertices marked `fixed` left
/// where they are, at most `sweeps` sweeps; `None` when `uv` has a flipped or collapsed
/// triangle.
pub(super) fn minimise_stretch(
    chart: &Chart,
    mut uv: Vec<DVec2>,
    fixed: &[bool],
    sweeps: usize,
) -> Option<Vec<DVec2>> {
    let nv = chart.pos.len();
    let shapes = shapes_from_3d(chart);
    let a3: Vec<f64> = shapes
        .iter()
        .map(|s| 0.5 * (s[1] - s[0]).perp_dot(s[2] - s[0]))
        .collect();
    // Each vertex's triangles, listed flat by vertex, with what its steps read of them.
    let mut first = vec![0usize; nv + 1];
    for tri in &chart.tris {
        for &v in tri {
            first[v + 1] += 1;
        }
    }
    for v in 0..nv {
        first[v + 1] += first[v];
    }
    let mut next = first.clone();
    let mut slots = vec![(0usize, 0usize); first[nv]];
    for (t, tri) in chart.tris.iter().enumerate() {
        for (c, &v) in tri.iter().enumerate() {
            slots[next[v]] = (t, c);
            next[v] += 1;
        }
    }
    let corners: Vec<Corner> = slots
        .into_iter()
        .map(|(t, c)| Corner {
            tri: chart.tris[t],
            shape: shapes[t],
            a3: a3[t],
            c,
        })
        .collect();
    let totals = |uv: &[DVec2]| -> Option<(f64, f64)> {
        let (mut s, mut a) = (0.0, 0.0);
        for ((tri, shape), &a3) in chart.tris.iter().zip(&shapes).zip(&a3) {
            let (m, d) = m_and_d([uv[tri[0]], uv[tri[1]], uv[tri[2]]], shape);
            if !(d > 0.0 && d.is_finite()) {
                return None;
            }
            let n0 = m.x_axis.length_squared() + m.y_axis.length_squared();
            s += a3 * n0 / (d * d);
            a += 0.5 * d;
        }
        Some((s, a))
    };
    let (mut s_tot, mut a_tot) = totals(&uv)?;
    let mut e_prev = s_tot * a_tot;
    let mut around: Vec<Local> = Vec::new();
    for _sweep in 0..sweeps {
        for v in (0..nv).filter(|&v| !fixed[v]) {
            around.clear();
            around.extend(
                corners[first[v]..first[v + 1]]
                    .iter()
                    .map(|k| Local::new(k.tri, &k.shape, k.a3, k.c, &uv)),
            );
            if let Some(x) = step(&around, s_tot, a_tot) {
                uv[v] += x.0;
                (s_tot, a_tot) = (x.1, x.2);
            }
        }
        // Fresh sums (no drift), and stop when a sweep gains little.
        let (s, a) = totals(&uv)?;
        (s_tot, a_tot) = (s, a);
        let e = s * a;
        if e > e_prev * (1.0 - 1e-5) {
            break;
        }
        e_prev = e;
    }
    Some(uv)
}

/// The move of one vertex with the triangles `around` it, the chart's sums being `s_tot`
/// (Σ A₃·f) and `a_tot` (Σ A₂): the move and the new sums, or `None` when no move lowers E.
fn step(around: &[Local], s_tot: f64, a_tot: f64) -> Option<(DVec2, f64, f64)> {
    let (mut s_loc, mut a_loc) = (0.0, 0.0);
    let (mut gs, mut ga) = (DVec2::ZERO, DVec2::ZERO);
    let mut hs = [0.0; 3];
    // The vertex's least height over an opposite edge, D/|n| (|n| the edge's length), kept as
    // D and |n|² and compared cross-multiplied.
    let mut low: Option<(f64, f64)> = None;
    for l in around {
        let (s, a) = l.here()?;
        s_loc += s;
        a_loc += a;
        let (g, h) = l.derivatives();
        gs += g;
        for (sum, x) in hs.iter_mut().zip(h) {
            *sum += x;
        }
        ga += 0.5 * l.n;
        let n2 = l.n.length_squared();
        if low.is_none_or(|(d, m2)| l.d0 * l.d0 * m2 < d * d * n2) {
            low = Some((l.d0, n2));
        }
    }
    let reach = low.map_or(f64::INFINITY, |(d, n2)| d / n2.sqrt());
    let hs = DMat2::from_cols(DVec2::new(hs[0], hs[1]), DVec2::new(hs[1], hs[2]));
    let (s_rest, a_rest) = (s_tot - s_loc, a_tot - a_loc);
    let e_here = s_tot * a_tot;
    let grad = gs * a_tot + ga * s_tot;
    let gl = grad.length();
    if !(gl > 0.0 && gl.is_finite()) {
        return None;
    }
    let gsa = DMat2::from_cols(gs * ga.x, gs * ga.y);
    let h = hs * a_tot + gsa + gsa.transpose();
    let newton = (h.determinant() > 0.0 && h.x_axis.x > 0.0)
        .then(|| -(h.inverse() * grad))
        .filter(|x| x.is_finite() && x.dot(grad) < 0.0);
    let newton = newton.map(|x| x * OVER_RELAX);
    let mut x = match newton {
        Some(x) if x.length() <= reach => x,
        Some(x) => x * (reach / x.length()),
        None => -grad / gl * (0.5 * reach),
    };
    for _ in 0..12 {
        let (mut s_new, mut a_new) = (0.0, 0.0);
        let ok = around.iter().all(|l| match l.at(x) {
            Some((s, a)) => {
                s_new += s;
                a_new += a;
                true
            }
            None => false,
        });
        if ok && (s_rest + s_new) * (a_rest + a_new) < e_here {
            return Some((x, s_rest + s_new, a_rest + a_new));
        }
        x *= 0.5;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A₃·f of a triangle with flat corners `p` and 3D shape `s`, as distortion measures it.
    fn f(p: [DVec2; 3], s: &[DVec2; 3]) -> f64 {
        let q = DMat2::from_cols(s[1] - s[0], s[2] - s[0]);
        let pm = DMat2::from_cols(p[1] - p[0], p[2] - p[0]);
        let g = q * pm.inverse();
        0.5 * q.determinant() * (g.x_axis.length_squared() + g.y_axis.length_squared())
    }

    /// The closed form of one triangle's term, its gradient and its Hessian in each corner
    /// agree with the term computed from the Jacobian and with central differences.
    #[test]
    fn local_energy_value_gradient_and_hessian_are_exact() {
        let p = [
            DVec2::new(0.1, 0.2),
            DVec2::new(1.3, -0.1),
            DVec2::new(0.4, 1.1),
        ];
        let s = [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.3, 0.9)];
        let a3 = 0.5 * (s[1] - s[0]).perp_dot(s[2] - s[0]);
        let uv = p.to_vec();
        for c in 0..3 {
            let l = Local::new([0, 1, 2], &s, a3, c, &uv);
            let at = |x: DVec2| {
                let mut q = p;
                q[c] += x;
                q
            };
            for x in [
                DVec2::ZERO,
                DVec2::new(0.01, -0.02),
                DVec2::new(-0.05, 0.03),
            ] {
                let (term, area) = l.at(x).unwrap();
                let exact = f(at(x), &s);
                assert!((term - exact).abs() < 1e-12 * exact, "{term} vs {exact}");
                let q = at(x);
                assert!((area - 0.5 * (q[1] - q[0]).perp_dot(q[2] - q[0])).abs() < 1e-12);
            }
            let h = 1e-4;
            let fx = |x: DVec2| f(at(x), &s);
            let (g, hess) = l.derivatives();
            let (dx, dy) = (DVec2::X * h, DVec2::Y * h);
            let gfd = DVec2::new(fx(dx) - fx(-dx), fx(dy) - fx(-dy)) / (2.0 * h);
            assert!((g - gfd).length() < 1e-6 * g.length(), "{g} vs {gfd}");
            let f0 = fx(DVec2::ZERO);
            let hxx = (fx(dx) - 2.0 * f0 + fx(-dx)) / (h * h);
            let hyy = (fx(dy) - 2.0 * f0 + fx(-dy)) / (h * h);
            let hxy = (fx(dx + dy) - fx(dx - dy) - fx(dy - dx) + fx(-dx - dy)) / (4.0 * h * h);
            for (mine, fd) in [(hess[0], hxx), (hess[2], hyy), (hess[1], hxy)] {
                assert!((mine - fd).abs() < 1e-4 * hess[0].abs(), "{mine} vs {fd}");
            }
            let (here, exact) = (l.here().unwrap(), l.at(DVec2::ZERO).unwrap());
            assert!((here.0 - exact.0).abs() < 1e-12 * exact.0 && here.1 == exact.1);
        }
        // A flipped or collapsed move is refused.
        let l = Local::new([0, 1, 2], &s, a3, 0, &uv);
        let through = (p[1] + p[2]) * 0.5 - p[0];
        assert!(l.at(through).is_none());
        assert!(l.at(through * 2.0).is_none());
    }
}
