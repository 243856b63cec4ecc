//! Crease conditions between neighbouring strips (Tang et al. 2016, §3.3): the kinds a spec
//! names, the intrinsic crease sine the stop test and the figures use, and the linearised rows
//! and residual of eq. 7 (fold), eq. 8 (geodesic) and the smooth condition, per sample
//! parameter of the strips that share the crease.
//!
//! Choices where the paper is silent (or mangled in the text):
//!
//! - Eq. 7–8 are written with c″ (the paper's c₀⁽²⁾ − c₁⁽²⁾ and c₁⁽²⁾ − c₂⁽²⁾ span the same
//!   osculating plane together with c′, and ⟨n, c′⟩ = 0 holds already on both sides), as the
//!   one equation ⟨n_L ± n_R, c″⟩ / |c″ ⟂ c′| = 0 per sample parameter of the strips, at the
//!   strips' own samples (3m − 2 per span: enforced numerically, as the paper says).
//! - Where the crease is straight (curvature ≤ [`STRAIGHT`] at diameter 1) or stands still
//!   (a tangent under [`STILL`]) the condition says nothing and is left out.
//! - Smooth: n_L − n_R = 0.
//! - A row is divided by |c″ ⟂ c′| but by no less than [`CREASE_FLOOR`]·|c″|, which keeps it
//!   bounded where the crease slows down.

use super::{normal_of, point_part, Layout, STILL};
use crate::surface::spline::system::{eval, Expr, Row};
use glam::DVec3;

/// The condition on an interior curve of a chain, shared by the strips to either side (spec
/// `creases`): eq. 7 (`Fold`: the sheet folds along it and unfolds in one piece), eq. 8
/// (`Geodesic`: the two sides unfold to mirror images), `Smooth` (equal normals, no crease)
/// or `Free` (no condition: the strips are cut apart there).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Crease {
    #[default]
    Free,
    Fold,
    Geodesic,
    Smooth,
}

impl Crease {
    /// The names a spec file uses, in the order messages list them.
    pub const NAMES: [(&'static str, Crease); 4] = [
        ("fold", Crease::Fold),
        ("geodesic", Crease::Geodesic),
        ("smooth", Crease::Smooth),
        ("free", Crease::Free),
    ];
}

/// One crease condition at one parameter: the samples (normals) of the strips to the left
/// (ending at the crease) and right (starting there), and the crease's second derivative.
pub(super) struct CreaseSample {
    pub(super) kind: Crease,
    pub(super) left: usize,
    pub(super) right: usize,
    pub(super) d2: Expr,
}

/// Curvature (in the diameter-1 frame) at or under which a crease point counts as straight:
/// the fold and geodesic conditions say nothing there.
pub const STRAIGHT: f64 = 1e-6;

/// The least share of |c″| a crease row is divided by (see [`crease_rows`]).
const CREASE_FLOOR: f64 = 0.1;

/// The crease's principal normal at a point (c″ without its tangential part), unit; `None`
/// where the crease is straight (curvature |c′ × c″| / |c′|³ at most `straight`).
fn principal_normal(t: DVec3, d2: DVec3, straight: f64) -> Option<DVec3> {
    let tl = t.length();
    if tl <= 1e-300 {
        return None;
    }
    let th = t / tl;
    let perp = d2 - th * d2.dot(th);
    (perp.length() / (tl * tl) > straight).then(|| perp.normalize())
}

/// The intrinsic crease sine at one crease point, from the tangent planes to either side: `el`
/// the left strip's ruling towards the crease, `er` the right strip's away from it (so that
/// both normals e × c′ lie on one side of the sheet), `t` = c′, `d2` = c″, `straight` the
/// curvature (1/mm, or in the scaled frame) under which eq. 7–8 say nothing. Fold (eq. 7):
/// the cosine between n_L + n_R and the principal normal; geodesic (eq. 8) the same with
/// n_L − n_R; smooth: |n_L − n_R| / 2, the sine of half the angle between the sides.
pub fn crease_sine(kind: Crease, el: DVec3, er: DVec3, t: DVec3, d2: DVec3, straight: f64) -> f64 {
    let nl = el.cross(t).normalize_or_zero();
    let nr = er.cross(t).normalize_or_zero();
    let sigma = match kind {
        Crease::Free => return 0.0,
        Crease::Smooth => return 0.5 * (nl - nr).length(),
        Crease::Fold => 1.0,
        Crease::Geodesic => -1.0,
    };
    let n = nl + sigma * nr;
    let len = n.length();
    match principal_normal(t, d2, straight) {
        Some(k) if len > 1e-9 => (n.dot(k) / len).abs().min(1.0),
        _ => 0.0,
    }
}

/// One crease condition's squared residual (as its row measures it) and its intrinsic sine;
/// nothing where the crease stands still.
pub(super) fn crease_residual(l: &Layout, x: &[f64], c: &CreaseSample) -> (f64, f64) {
    let (sl, sr) = (&l.samples[c.left], &l.samples[c.right]);
    let t = eval(&sr.ta, &l.points);
    if t.length() <= STILL {
        return (0.0, 0.0);
    }
    let (nl, nr) = (normal_of(x, sl), normal_of(x, sr));
    let d2 = eval(&c.d2, &l.points);
    let sum = match c.kind {
        Crease::Smooth => (nl - nr).length_squared(),
        Crease::Fold | Crease::Geodesic => {
            let sigma = if c.kind == Crease::Fold { 1.0 } else { -1.0 };
            principal_normal(t, d2, STRAIGHT).map_or(0.0, |k| (nl + sigma * nr).dot(k).powi(2))
        }
        Crease::Free => 0.0,
    };
    let (el, er) = (eval(&sl.e, &l.points), eval(&sr.e, &l.points));
    (sum, crease_sine(c.kind, el, er, t, d2, STRAIGHT))
}

/// The rows of one crease condition at the current iterate: ⟨n_L ± n_R, c″⟩ / |c″ ⟂ c′| for
/// a fold or geodesic crease, n_L − n_R = 0 (three rows) for a smooth one.
pub(super) fn crease_rows(l: &Layout, x: &[f64], c: &CreaseSample, rows: &mut Vec<Row>) {
    let (sl, sr) = (&l.samples[c.left], &l.samples[c.right]);
    let sigma = match c.kind {
        Crease::Free => return,
        Crease::Smooth => {
            for k in 0..3 {
                rows.push(Row {
                    entries: vec![(sl.normal + k, 1.0), (sr.normal + k, -1.0)],
                    rhs: 0.0,
                    w: 1.0,
                });
            }
            return;
        }
        Crease::Fold => 1.0,
        Crease::Geodesic => -1.0,
    };
    let t = eval(&sr.ta, &l.points);
    let d = eval(&c.d2, &l.points);
    let tl = t.length();
    let perp = if tl > STILL {
        (d - t * (d.dot(t) / (tl * tl))).length()
    } else {
        0.0
    };
    if tl <= STILL || perp / (tl * tl) <= STRAIGHT {
        return; // the crease stands still or is straight here: no condition
    }
    // Divided by |c″ ⟂ c′| the row is a cosine; where the crease slows down (c″ mostly along
    // c′) at most 1/CREASE_FLOOR times |c″| keeps its entries bounded.
    let scale = perp.max(CREASE_FLOOR * d.length());
    let n0 = normal_of(x, sl) + sigma * normal_of(x, sr);
    let mut entries = Vec::with_capacity(6 + 3 * c.d2.len());
    let mut rhs = 0.0;
    for k in 0..3 {
        entries.push((sl.normal + k, d[k] / scale));
        entries.push((sr.normal + k, sigma * d[k] / scale));
    }
    point_part(l, &c.d2, n0, scale, &mut entries, &mut rhs);
    rows.push(Row {
        entries,
        rhs,
        w: 1.0,
    });
}
