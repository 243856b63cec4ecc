//! The folds of one piece: the smooth developable of the control curve (eq. 1, §3.1; §5 for a
//! curve on the sheet) replaced by an exactly developable folded sheet.
//!
//! The smooth surface is replaced by a *folded* one that is exactly developable: the flat sheet
//! is folded along straight ruling lines, `s_k = k·h` apart along the line (`h = L / n`), each
//! fold turning the sheet beyond it about the ruling by `|ω(s_k)|·h`, where `ω = τ_g T − κ_n b`
//! is the folding part of the Darboux vector of the arc-length parameterised control curve at
//! `s_k`, expressed in the curve's own frame (tangent `T`, surface normal `n` (`±N` for a
//! line), `b = n × T`): the flat ruling runs through the flat curve's point at `s_k` in the
//! direction `(ω·T) d + (ω·b) d⊥`, `d` the flat curve's unit tangent there. This is the
//! midpoint rule for the frame's rotation about the Darboux vector (the "instantaneous rotation
//! axis" of §3.1; for a curve on the sheet a Strang splitting: the in-sheet turn is exact
//! between folds), so the folded curve follows the control curve to O(h²), while every face
//! is a piece of the flat sheet moved rigidly: the mesh is isometric to the outline to
//! rounding, the curve's folded length is the flat curve's exactly, and the flatten stage gets
//! back the outline. `n` is chosen so that the sheet is bent by `h` steps with a sagitta
//! `h²|ω|/8` within the sampling tolerance; the folded curve's largest distance from the
//! control curve (at the folds) is measured and reported in a warning when it exceeds the
//!
//! Which side of the sheet faces where: the sheet's printed side (+z of the flat outline)
//! faces the surface normal `n`, chosen at the first curved point of the control curve: the
//! given start normal for handles, else the side with `n·z > 0` (then `n·y > 0`, `n·x > 0`
//! when `n` is horizontal; for a curve on the sheet, of its two normals the one with the
//! larger `n·z`, then `n·y`, then `n·x`). Bending a sheet that lies printed side up keeps it
//! up at the start. Where the curve is straight (an inflection, κ = 0) the normal is carried
//! over unchanged.
//!
//! Folds turning by less than 1e-9 rad are left out (straight stretches stay planar).
//!
//! Curves on the sheet (§5): `κ_n` is taken as 0 where `κ_n² < 1e-10 κ²` (the control curve
//! lies flat on the sheet there to 1e-5 of its curvature: an exact circle fitted to length
//! lands here, not on rounding noise), and a curvature short of `|c|` by 1e-9 relative is
//! rounding, not a refusal. Of the two normals (branches σ = ±1) the first curved point takes
//! the one by the sign rule above, later points the one nearer the previous normal. `θ'` is
//! a central difference over ±1 µm of arc length (one-sided at the ends), on the point's
//! branch. The flat curve must lie on the sheet (256 samples); rulings are drawn through its
//! points at the folds, so a flat curve's own curvature needs no sampling.

use super::control::{local, Local};
use super::path::Flat;
use super::spline::{ArcLength, Fitted, Param};
use super::{BentSpec, GeodesicError, LengthFit, PieceSpec};
use glam::{DAffine3, DVec2, DVec3};

/// One ruling of the bent sheet: a fold line on the flat sheet.
#[derive(Debug, Clone, PartialEq)]
pub struct Ruling {
    /// Piece (0-based) it belongs to; `None` for a zero-angle cut line through a hole.
    pub piece: Option<usize>,
    /// Arc length along the piece's line (mm).
    pub s: f64,
    /// Where the ruling crosses the line, on the flat sheet.
    pub point: DVec2,
    /// Unit direction of the ruling on the flat sheet.
    pub dir: DVec2,
    /// Fold angle (radians) about `dir`, right-handed, turning the sheet beyond the ruling
    /// (in the direction of the line) relative to the sheet before it.
    pub angle: f64,
    /// Where the ruling runs on the sheet: `(t0, t1)` along `dir` from `point`.
    pub extent: (f64, f64),
    /// The ruling's segments on the sheet (mesh vertex pairs).
    pub edges: Vec<[usize; 2]>,
    /// 3D direction of the ruling on the bent sheet (unit).
    pub dir_3d: DVec3,
}

/// The folds of one piece and how to place the sheet in space.
pub(super) struct PieceFolds {
    pub(super) folds: Vec<Ruling>,
    /// Rigid map from the flat sheet (z = 0) to space for the part before the first fold.
    pub(super) place: DAffine3,
    /// Largest distance of the folded line's vertices from the control curve (mm).
    pub(super) drift: f64,
    /// Length of the fitted control curve (mm).
    pub(super) length: f64,
    pub(super) warnings: Vec<String>,
}

/// The folds of all pieces in order, where the first piece places the sheet, and per piece the
/// fitted length, the drift and the warnings.
pub(super) struct Folds {
    pub(super) rulings: Vec<Ruling>,
    pub(super) place: DAffine3,
    pub(super) warnings: Vec<String>,
    pub(super) lengths: Vec<f64>,
    pub(super) drifts: Vec<f64>,
}

/// Fold every piece along its own line (see the module doc).
pub(super) fn fold_pieces(
    spec: &BentSpec,
    curves: &[(&dyn Param, Option<DVec3>)],
    flats: &[Flat],
    tol: f64,
) -> Result<Folds, GeodesicError> {
    let mut warnings = Vec::new();
    let mut rulings: Vec<Ruling> = Vec::new();
    let mut place = DAffine3::IDENTITY;
    let mut lengths = Vec::new();
    let mut drifts = Vec::new();
    for (i, (p, (c, up))) in spec.pieces.iter().zip(curves).enumerate() {
        let mut pf = piece_folds(i, p, &flats[i], *c, *up, tol)?;
        if i == 0 {
            place = pf.place;
        }
        warnings.append(&mut pf.warnings);
        lengths.push(pf.length);
        drifts.push(pf.drift);
        rulings.append(&mut pf.folds);
    }
    Ok(Folds {
        rulings,
        place,
        warnings,
        lengths,
        drifts,
    })
}

/// Curvature (1/mm) below which a control curve counts as straight.
pub(super) const KMIN: f64 = 1e-9;
/// Below this `κ_n² / κ²` counts as zero: the control curve lies flat on the sheet there (its
/// normal curvature is under 1e-5 of its curvature; exact circles fitted to length land here).
pub(super) const FLAT_KN2: f64 = 1e-10;
/// A control curve's curvature may fall short of the flat curve's by this much (relative)
/// before it is refused: rounding, not geometry.
pub(super) const SHORT_REL: f64 = 1e-9;

/// |κ_n| = √(κ² − c²) (§5: the normal part of `p''` once the geodesic part `c` is taken).
pub(super) fn kn_abs(kappa: f64, c: f64) -> f64 {
    let kn2 = kappa * kappa - c * c;
    if kn2 <= FLAT_KN2 * kappa * kappa {
        0.0
    } else {
        kn2.sqrt()
    }
}

/// The two surface normals (branches σ = +1 and −1) along which the control curve has the
/// flat curve's geodesic curvature `c`: `n = σ (κ_n/κ) N + (c/κ) B`, so that
/// `p'' = c (n × T) + σ κ_n n` (§5). `None` where the curve is straight.
pub(super) fn normals_for(l: &Local, c: f64) -> Option<[DVec3; 2]> {
    let kappa = l.k.length();
    if kappa <= KMIN {
        return None;
    }
    if c == 0.0 {
        let n = l.k.normalize();
        return Some([n, -n]);
    }
    let nn = l.k / kappa;
    let bb = l.t.cross(nn);
    let a = kn_abs(kappa, c) / kappa;
    let beta = (c / kappa).clamp(-1.0, 1.0);
    Some([
        (nn * a + bb * beta).normalize(),
        (nn * -a + bb * beta).normalize(),
    ])
}

/// `θ'` for the surface normal `n = cos θ N + sin θ B` with `tan θ = c / (σ κ_n)` on branch
/// `sigma`: the geodesic torsion is `τ_g = τ + θ'`. Central difference over ±1 µm (one-sided
/// at the ends); zero on a straight flat line.
pub(super) fn theta_rate(
    curve: &dyn Param,
    arc: &ArcLength,
    flat: &Flat,
    s: f64,
    sigma: f64,
    len: f64,
) -> f64 {
    if flat.straight() {
        return 0.0;
    }
    let delta = 1e-3_f64.min(1e-3 * len);
    let theta = |s: f64| -> Option<f64> {
        let l = local(curve, arc.param(s))?;
        let kappa = l.k.length();
        if kappa <= KMIN {
            return None;
        }
        let c = flat.at(s).c;
        Some(c.atan2(sigma * kn_abs(kappa, c)))
    };
    let (s0, s1) = ((s - delta).max(0.0), (s + delta).min(len));
    match (theta(s0), theta(s1)) {
        (Some(a), Some(b)) if s1 > s0 => {
            let pi = std::f64::consts::PI;
            let mut d = b - a;
            if d > pi {
                d -= 2.0 * pi;
            } else if d < -pi {
                d += 2.0 * pi;
            }
            d / (s1 - s0)
        }
        _ => 0.0,
    }
}

/// Pick the branch of [`normals_for`] by the sign rule at the first curved point (see the
/// module doc): the one further along the hint, then +z, +y, +x. Returns the index.
pub(super) fn orient_pair(n: &[DVec3; 2], up: Option<DVec3>) -> usize {
    let refs = match up {
        Some(u) => vec![u],
        None => vec![DVec3::Z, DVec3::Y, DVec3::X],
    };
    for r in refs {
        let d = (n[0] - n[1]).dot(r);
        if d.abs() > 2e-6 {
            return if d > 0.0 { 0 } else { 1 };
        }
    }
    0
}

/// Rotation about the line through `q` (z = 0) with unit direction `dir` by `angle`.
pub(super) fn fold_map(q: DVec2, dir: DVec2, angle: f64) -> DAffine3 {
    let q3 = DVec3::new(q.x, q.y, 0.0);
    DAffine3::from_translation(q3)
        * DAffine3::from_axis_angle(DVec3::new(dir.x, dir.y, 0.0), angle)
        * DAffine3::from_translation(-q3)
}

pub(super) fn piece_folds(
    piece: usize,
    spec: &PieceSpec,
    flat: &Flat,
    curve: &dyn Param,
    up: Option<DVec3>,
    tol: f64,
) -> Result<PieceFolds, GeodesicError> {
    let cerr = |message: String| GeodesicError::Control { piece, message };
    let len = flat.len();
    let mut warnings = Vec::new();

    // Length (§4.1.3).
    let raw = ArcLength::new(curve);
    let total = raw.total();
    if !(total.is_finite() && total > 1e-9) {
        return Err(cerr("has no length".into()));
    }
    let (dom0, dom1) = curve.domain();
    let origin = curve.eval(dom0)[0];
    let fitted = match spec.fit {
        LengthFit::Scale => {
            let k = len / total;
            if (k - 1.0).abs() > 1e-3 {
                warnings.push(format!(
                    "piece {}: the control curve is {total:.2} mm long and the line {len:.2} mm: curve scaled by {k:.5} about its start",
                    piece + 1
                ));
            }
            Fitted {
                inner: curve,
                origin,
                scale: k,
                end: dom1,
            }
        }
        LengthFit::Trim => {
            if total < len * (1.0 - 1e-12) {
                return Err(cerr(format!(
                    "is {total:.3} mm long, shorter than the line ({len:.3} mm); with length_fit = \"trim\" it must be at least as long"
                )));
            }
            Fitted {
                inner: curve,
                origin,
                scale: 1.0,
                end: raw.param(len),
            }
        }
    };
    let arc = ArcLength::new(&fitted);
    let length = arc.total();

    // Step: sagitta h²|ω|/8 within the tolerance.
    let probes = 256;
    let mut wmax: f64 = 0.0;
    let (f0, f1) = fitted.domain();
    if flat.straight() {
        for j in 0..=probes {
            // |ω| does not depend on the parameterisation: probe evenly in the parameter.
            let u = f0 + (f1 - f0) * j as f64 / probes as f64;
            if let Some(l) = local(&fitted, u) {
                wmax = wmax.max(l.omega.length());
            }
        }
    } else {
        // A curve drawn on the sheet: probe by arc length (the flat curvature is given so),
        // refuse a control curve that curves less than it (§5), and bound the folding part
        // of ω by (|τ| + |θ'|, κ_n).
        let probes = 2 * probes;
        let mut worst: Option<(f64, f64, f64)> = None;
        for j in 0..=probes {
            let s = len * j as f64 / probes as f64;
            let Some(l) = local(&fitted, arc.param(s)) else {
                continue;
            };
            let c = flat.at(s).c;
            let kappa = l.k.length();
            let short = c.abs() - kappa;
            if short > SHORT_REL * c.abs() && worst.is_none_or(|w| short > w.1.abs() - w.2) {
                worst = Some((s, c, kappa));
            }
            let tau = l.omega.dot(l.t);
            let dtheta = theta_rate(&fitted, &arc, flat, s, 1.0, len);
            let tg = tau.abs() + dtheta.abs();
            let kn = kn_abs(kappa, c);
            wmax = wmax.max((tg * tg + kn * kn).sqrt());
        }
        if let Some((s, c, kappa)) = worst {
            return Err(GeodesicError::Curvature {
                piece,
                s,
                kappa,
                c: c.abs(),
                radius: 1.0 / c.abs(),
                short: c.abs() - kappa,
            });
        }
    }
    if !wmax.is_finite() {
        return Err(cerr("its curvature or torsion is not finite".into()));
    }
    let h_max = if wmax > 0.0 {
        (8.0 * tol / wmax).sqrt()
    } else {
        len
    };
    const MAX_STEPS: usize = 200_000;
    let folds_at = |n: usize| folds_at_n(piece, n, &fitted, &arc, flat, up, tol);
    let mut n = ((len / h_max).ceil() as usize).max(2);
    // The folded line strays O(h²) from the curve: refine until it is within the tolerance.
    let mut tries = 0;
    let (folds, place, drift) = loop {
        let (folds, place, drift) = folds_at(n)?;
        tries += 1;
        if drift <= tol || tries >= 4 || n >= MAX_STEPS {
            break (folds, place, drift);
        }
        let grow = ((drift / tol).sqrt() * 1.1).max(1.2);
        n = ((n as f64 * grow).ceil() as usize).min(MAX_STEPS);
    };
    if drift > tol {
        warnings.push(format!(
            "piece {}: the folded sheet strays up to {drift:.3} mm from the control curve (tolerance {tol} mm)",
            piece + 1
        ));
    }
    Ok(PieceFolds {
        folds,
        place,
        drift,
        length,
        warnings,
    })
}

/// [`piece_folds`] at `n` steps: the folds, the placement and the largest distance of the
/// folded flat curve from the control curve.
#[allow(clippy::too_many_arguments)]
pub(super) fn folds_at_n(
    piece: usize,
    n: usize,
    fitted: &dyn Param,
    arc: &ArcLength,
    flat: &Flat,
    up: Option<DVec3>,
    tol: f64,
) -> Result<(Vec<Ruling>, DAffine3, f64), GeodesicError> {
    let cerr = |message: String| GeodesicError::Control { piece, message };
    let len = flat.len();
    let length = arc.total();
    const MAX_STEPS: usize = 200_000;
    if n > MAX_STEPS {
        return Err(cerr(format!(
            "would need {n} rulings at a tolerance of {tol} mm (over {MAX_STEPS}); raise `tolerance` or bend less sharply"
        )));
    }
    let h = len / n as f64;

    // Frames at s = h/2 (the first segment) and at each fold s_k = k h, with the flat
    // curve's curvature there.
    let mut at: Vec<(f64, Local, f64)> = Vec::with_capacity(n + 1);
    for k in 0..n {
        let s = if k == 0 { 0.5 * h } else { k as f64 * h };
        let l = local(fitted, arc.param(s))
            .ok_or_else(|| cerr(format!("is singular (zero speed) at s = {s:.2} mm")))?;
        if !(l.omega.is_finite() && l.t.is_finite()) {
            return Err(cerr(format!("is not smooth at s = {s:.2} mm")));
        }
        let c = flat.at(s).c;
        at.push((s, l, c));
    }
    // Surface normals (§5; ±K for a line), continuous; carried over where K vanishes. The
    // branch σ (+1: first of `normals_for`) is kept for the geodesic torsion.
    let cands: Vec<Option<[DVec3; 2]>> = at.iter().map(|(_, l, c)| normals_for(l, *c)).collect();
    let first = cands.iter().position(|c| c.is_some());
    let mut normals = vec![DVec3::ZERO; at.len()];
    let mut sigma = vec![1.0; at.len()];
    match first {
        None => {
            let t = at[0].1.t;
            let mut n0 = DVec3::ZERO;
            for r in [up.unwrap_or(DVec3::Z), DVec3::Z, DVec3::Y, DVec3::X] {
                let v = r - t * r.dot(t);
                if v.length() > 1e-6 {
                    n0 = v.normalize();
                    break;
                }
            }
            normals.fill(n0);
        }
        Some(f) => {
            let pair = cands[f].unwrap_or([DVec3::Z, -DVec3::Z]);
            let i0 = orient_pair(&pair, up);
            normals[f] = pair[i0];
            sigma[f] = if i0 == 0 { 1.0 } else { -1.0 };
            for i in (0..f).rev() {
                let t = at[i].1.t;
                let v = normals[i + 1] - t * normals[i + 1].dot(t);
                normals[i] = v.normalize_or(normals[i + 1]);
            }
            for i in f + 1..at.len() {
                let t = at[i].1.t;
                let prev = normals[i - 1];
                normals[i] = match cands[i] {
                    Some(pair) => {
                        if pair[0].dot(prev) >= pair[1].dot(prev) {
                            pair[0]
                        } else {
                            sigma[i] = -1.0;
                            pair[1]
                        }
                    }
                    None => (prev - t * prev.dot(t)).normalize_or(prev),
                };
            }
        }
    }

    // Placement: the flat frame (d, d⊥, z) of the first segment ↦ (T, b, n) there,
    // b = n × T, with the flat curve's start at p(0).
    let (t0, n0) = (at[0].1.t, normals[0]);
    let b0 = n0.cross(t0).normalize();
    let n0 = t0.cross(b0);
    let p0 = fitted.eval(fitted.domain().0)[0];
    let a = flat.at(0.0).p;
    let d = flat.at(at[0].0).t;
    let dp = d.perp();
    let world = glam::DMat3::from_cols(t0, b0, n0);
    let flat_frame = glam::DMat3::from_cols(
        DVec3::new(d.x, d.y, 0.0),
        DVec3::new(dp.x, dp.y, 0.0),
        DVec3::Z,
    );
    let place = DAffine3::from_translation(p0)
        * DAffine3::from_mat3(world * flat_frame.transpose())
        * DAffine3::from_translation(-DVec3::new(a.x, a.y, 0.0));

    let mut folds = Vec::new();
    for k in 1..n {
        let (s, l, _) = &at[k];
        let t = l.t;
        let nn = normals[k];
        let bb = nn.cross(t);
        // The folding part of the Darboux vector: τ_g T − κ_n b (κ_g n turns the curve
        // inside the sheet, which the flat curve does by itself).
        let wt = l.omega.dot(t) + theta_rate(fitted, arc, flat, *s, sigma[k], len);
        let wb = l.omega.dot(bb);
        let mag = (wt * wt + wb * wb).sqrt();
        let angle = mag * h;
        if angle < 1e-9 {
            continue;
        }
        let q = flat.at(*s);
        let dir = (q.t * wt + q.t.perp() * wb) / mag;
        folds.push(Ruling {
            piece: Some(piece),
            s: *s,
            point: q.p,
            dir,
            angle,
            extent: (0.0, 0.0),
            edges: Vec::new(),
            dir_3d: DVec3::ZERO,
        });
    }

    // How far the folded flat curve strays from the control curve.
    let mut m = place;
    let mut drift: f64 = 0.0;
    let mut fi = 0;
    for k in 1..=n {
        let s = k as f64 * h;
        while fi < folds.len() && folds[fi].s < s - 0.5 * h {
            let f = &folds[fi];
            m *= fold_map(f.point, f.dir, f.angle);
            fi += 1;
        }
        let flat_pt = flat.at(s).p;
        let v = m.transform_point3(DVec3::new(flat_pt.x, flat_pt.y, 0.0));
        let target = fitted.eval(arc.param(s.min(length)))[0];
        drift = drift.max(v.distance(target));
    }
    Ok((folds, place, drift))
}
