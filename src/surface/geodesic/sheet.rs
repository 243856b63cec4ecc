//! The flat sheet (§3.3): the outline and holes, cleaned and checked; the lines and curves on it;
//! where each ruling runs across it (from the line to the first boundary on each side, across
//! holes); and cut lines through holes that no ruling crosses.
//!
//! Rulings continue across holes (a ruling of a developable is a straight line through all of
//! it); beyond the first boundary on each side they stop (§3.3). A hole that no ruling crosses
//! gets a straight cut line of zero angle through it so that every face of the mesh is a
//! simple polygon; it is not a bend line.

use super::admissible::{inside, meet};
use super::path::Flat;
use super::{BentSpec, FlatPath, GeodesicError, Ruling};
use crate::geom::polygon;
use glam::{DVec2, DVec3};

/// Drop repeated and collinear points; orient counter-clockwise (`ccw`) or clockwise.
pub(super) fn clean_ring(ring: &[DVec2], ccw: bool) -> Vec<DVec2> {
    let mut r: Vec<DVec2> = Vec::with_capacity(ring.len());
    for &p in ring {
        if r.last().is_none_or(|q: &DVec2| q.distance(p) > 1e-9) {
            r.push(p);
        }
    }
    while r.len() > 1 && r[0].distance(r[r.len() - 1]) <= 1e-9 {
        r.pop();
    }
    loop {
        let n = r.len();
        if n < 3 {
            break;
        }
        let drop = (0..n).find(|&i| {
            let (a, b, c) = (r[(i + n - 1) % n], r[i], r[(i + 1) % n]);
            let e = (c - a).length().max(1e-12);
            ((b - a).perp_dot(c - a) / e).abs() < 1e-9
        });
        match drop {
            Some(i) => {
                r.remove(i);
            }
            None => break,
        }
    }
    if (polygon::signed_area(&r) > 0.0) != ccw {
        r.reverse();
    }
    r
}

/// The outline (ring 0, counter-clockwise) and the holes (clockwise), cleaned and checked.
pub(super) fn sheet_rings(spec: &BentSpec) -> Result<Vec<Vec<DVec2>>, GeodesicError> {
    let oerr = |m: String| GeodesicError::Outline(m);
    if spec.outline.iter().any(|p| !p.is_finite()) {
        return Err(oerr("a point is not finite".into()));
    }
    let outer = clean_ring(&spec.outline, true);
    if outer.len() >= 3 && !polygon::is_simple_ring(&outer) {
        return Err(oerr("crosses itself".into()));
    }
    if outer.len() < 3 || polygon::signed_area(&outer) < 1e-6 {
        return Err(oerr(
            "needs at least 3 points enclosing an area (rectangle `[width, height]` or a list of points)"
                .into(),
        ));
    }
    if !polygon::is_simple_ring(&outer) {
        return Err(oerr("crosses itself".into()));
    }
    let mut rings = vec![outer];
    for (h, hole) in spec.holes.iter().enumerate() {
        let r = clean_ring(hole, false);
        let herr = |m: &str| oerr(format!("hole {}: {m}", h + 1));
        if hole.iter().any(|p| !p.is_finite()) {
            return Err(herr("a point is not finite"));
        }
        if r.len() < 3 || polygon::signed_area(&r).abs() < 1e-6 {
            return Err(herr("needs at least 3 points enclosing an area"));
        }
        if !polygon::is_simple_ring(&r) {
            return Err(herr("crosses itself"));
        }
        if !r.iter().all(|&p| polygon::contains(&rings[0], p)) {
            return Err(herr("is not inside the outline"));
        }
        for other in &rings {
            let cross = (0..r.len()).any(|i| {
                (0..other.len()).any(|j| {
                    polygon::segments_intersect(
                        r[i],
                        r[(i + 1) % r.len()],
                        other[j],
                        other[(j + 1) % other.len()],
                    )
                })
            });
            if cross || other.iter().any(|&p| polygon::contains(&r, p)) {
                return Err(herr("crosses or contains the outline or another hole"));
            }
        }
        rings.push(r);
    }
    Ok(rings)
}

/// Every piece's line or curve lies on the sheet; a curve is also regular (256 samples).
pub(super) fn check_paths(spec: &BentSpec, rings: &[Vec<DVec2>]) -> Result<(), GeodesicError> {
    let on_sheet = |q: DVec2| {
        let r = &rings[0];
        (0..r.len()).any(|j| polygon::segment_distance(q, r[j], r[(j + 1) % r.len()]) <= 1e-6)
            || polygon::contains(r, q)
    };
    for (i, p) in spec.pieces.iter().enumerate() {
        let lerr = |message: String| GeodesicError::Line { piece: i, message };
        match &p.path {
            FlatPath::Line([a, b]) => {
                let (a, b) = (*a, *b);
                if !(a.is_finite() && b.is_finite()) {
                    return Err(lerr("a point is not finite".into()));
                }
                if a.distance(b) < 1e-6 {
                    return Err(lerr("its two points are the same".into()));
                }
                for q in [a, b] {
                    if !on_sheet(q) {
                        return Err(lerr(format!(
                            "point ({}, {}) is not on the sheet",
                            q.x, q.y
                        )));
                    }
                }
                continue;
            }
            FlatPath::Arc {
                center,
                radius,
                start_deg,
                end_deg,
            } => {
                if !(center.is_finite() && start_deg.is_finite() && end_deg.is_finite()) {
                    return Err(lerr("the arc's centre and angles must be finite".into()));
                }
                if !(radius.is_finite() && *radius >= 1e-3) {
                    return Err(lerr(format!(
                        "the arc's radius must be at least 0.001 mm, got {radius}"
                    )));
                }
                let sweep = (end_deg - start_deg).abs();
                if !(radius * sweep.to_radians() >= 1e-6 && sweep <= 360.0) {
                    return Err(lerr(format!(
                        "the arc must sweep more than nothing and at most 360°, from start_deg {start_deg} to end_deg {end_deg}"
                    )));
                }
            }
            FlatPath::Curve(c) => {
                if c.control().len() < 2 || c.control().iter().any(|q| !q.is_finite()) {
                    return Err(lerr(
                        "a curve on the sheet needs at least 2 finite control points".into(),
                    ));
                }
                let l = p.path.length();
                if l.is_nan() || l < 1e-6 {
                    return Err(lerr("the curve on the sheet has no length".into()));
                }
            }
        }
        // A curve: every sample on the sheet, and regular.
        let f = Flat::new(&p.path);
        let len = f.len();
        const SAMPLES: usize = 256;
        for j in 0..=SAMPLES {
            let s = len * j as f64 / SAMPLES as f64;
            let q = f.at(s);
            if !(q.p.is_finite() && q.t.is_finite() && q.c.is_finite()) {
                return Err(lerr(format!(
                    "the curve on the sheet is not smooth at s = {s:.2} mm (a cusp or a repeated control point?)"
                )));
            }
            if !on_sheet(q.p) {
                return Err(lerr(format!(
                    "the curve leaves the sheet at s = {s:.2} mm, point ({:.2}, {:.2})",
                    q.p.x, q.p.y
                )));
            }
        }
    }
    Ok(())
}

/// The intervals of a ruling on the sheet, from the line to the outline.
pub(super) type Chain = Vec<(Crossing, Crossing)>;

/// Where each ruling lies on the sheet: its chain of intervals, and its `extent` set.
pub(super) fn ruling_chains(rings: &[Vec<DVec2>], rulings: &mut [Ruling]) -> Vec<Chain> {
    let mut chains: Vec<Vec<(Crossing, Crossing)>> = Vec::with_capacity(rulings.len());
    for r in rulings.iter_mut() {
        let ch = chain(&crossings(rings, r.point, r.dir));
        r.extent = match (ch.first(), ch.last()) {
            (Some(f), Some(l)) => (f.0.t, l.1.t),
            _ => (0.0, 0.0),
        };
        chains.push(ch);
    }
    chains
}

/// Holes no ruling crosses get a zero-angle cut line (see the module doc).
pub(super) fn cut_holes(
    rings: &[Vec<DVec2>],
    rulings: &mut Vec<Ruling>,
    chains: &mut Vec<Chain>,
) -> Result<(), GeodesicError> {
    for h in 1..rings.len() {
        if chains
            .iter()
            .flatten()
            .any(|(c0, c1)| c0.ring == h || c1.ring == h)
        {
            continue;
        }
        let hole = &rings[h];
        let centre = hole.iter().copied().sum::<DVec2>() / hole.len() as f64;
        let centre = if polygon::contains(hole, centre) {
            centre
        } else {
            0.5 * (hole[0] + hole[1]) + (hole[1] - hole[0]).perp().normalize() * -1e-3
        };
        let mut dirs: Vec<DVec2> = Vec::new();
        let mut near: Vec<&Ruling> = rulings.iter().collect();
        near.sort_by(|a, b| {
            a.point
                .distance(centre)
                .total_cmp(&b.point.distance(centre))
        });
        dirs.extend(near.iter().take(4).map(|r| r.dir));
        for deg in [0.0f64, 90.0, 45.0, 135.0, 22.5, 67.5, 112.5, 157.5] {
            dirs.push(DVec2::from_angle(deg.to_radians()));
        }
        let mut done = false;
        for dir in dirs {
            let cr = crossings(rings, centre, dir);
            let ch = chain(&cr);
            let Some(ext) = ch.first().zip(ch.last()).map(|(f, l)| (f.0.t, l.1.t)) else {
                continue;
            };
            let clash = rulings.iter().any(|r| {
                meet(centre, dir, r.point, r.dir)
                    .is_some_and(|(ta, tb)| ta > ext.0 - 1e-6 && ta < ext.1 + 1e-6 && inside(r, tb))
            });
            if clash || !ch.iter().any(|(a, b)| a.ring == h || b.ring == h) {
                continue;
            }
            rulings.push(Ruling {
                piece: None,
                s: 0.0,
                point: centre,
                dir,
                angle: 0.0,
                extent: ext,
                edges: Vec::new(),
                dir_3d: DVec3::ZERO,
            });
            chains.push(ch);
            done = true;
            break;
        }
        if !done {
            return Err(GeodesicError::Mesh(format!(
                "hole {h}: no straight line through it avoids the rulings; move it or the lines"
            )));
        }
    }
    Ok(())
}

/// Where a line crosses the sheet's rings.
pub(super) type Crossing = polygon::LineCrossing;

/// Every crossing of the line `p + t d` with the rings, sorted along it.
pub(super) fn crossings(rings: &[Vec<DVec2>], p: DVec2, d: DVec2) -> Vec<Crossing> {
    polygon::line_crossings(rings, p, d)
}

/// The intervals of a ruling on the sheet: the one through its point (or the two beside it when
/// the point is in a hole), continued across holes to the outer outline.
pub(super) fn chain(cr: &[Crossing]) -> Vec<(Crossing, Crossing)> {
    let m = cr.len() / 2;
    if m == 0 {
        return Vec::new();
    }
    let idx = cr.partition_point(|c| c.t <= 0.0);
    let (mut i0, mut i1) = if idx % 2 == 1 {
        ((idx - 1) / 2, (idx - 1) / 2)
    } else if idx == 0 {
        (0, 0)
    } else if idx >= 2 * m {
        (m - 1, m - 1)
    } else {
        (idx / 2 - 1, idx / 2)
    };
    while i0 > 0 && cr[2 * i0].ring != 0 {
        i0 -= 1;
    }
    while i1 + 1 < m && cr[2 * i1 + 1].ring != 0 {
        i1 += 1;
    }
    (i0..=i1).map(|i| (cr[2 * i], cr[2 * i + 1])).collect()
}
