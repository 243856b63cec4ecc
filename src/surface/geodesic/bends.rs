//! Bend lines from the rulings.
//!
//! Bend lines: every fold is a ruling and a bend line with its angle (`bend_lines = "all"`),
//! none, or one every `spacing` mm along each line carrying the angle accumulated since the
//! previous one, as strips do, or a shop's equal shares ([`crate::surface::strip::shop`]).
//!
//! A bend's angle is signed: positive for a mountain seen from the printed side (+z).

use super::Ruling;
use crate::surface::strip::BendLines;
use crate::surface::Bend;
use glam::DVec3;

/// Signed fold angle in degrees: positive for a mountain seen from the printed side (+z).
pub(super) fn signed_deg(r: &Ruling, forward_left: bool) -> f64 {
    // The sheet just beyond the ruling, turned by the fold, goes below the printed side's
    // plane for a mountain.
    let m = if forward_left {
        r.dir.perp()
    } else {
        -r.dir.perp()
    };
    let rot = glam::DQuat::from_axis_angle(DVec3::new(r.dir.x, r.dir.y, 0.0), r.angle);
    let z = (rot * DVec3::new(m.x, m.y, 0.0)).z;
    let deg = r.angle.to_degrees();
    if z < 0.0 {
        deg
    } else {
        -deg
    }
}

/// Bend lines as `lines` asks, from the rulings of the pieces in order along their lines.
pub(super) fn pick_bends(rulings: &[Ruling], forward_left: &[bool], lines: BendLines) -> Vec<Bend> {
    const EPS_DEG: f64 = 0.01;
    let mut out = Vec::new();
    let mut acc = 0.0;
    let mut last: Option<(usize, f64)> = None;
    let mut pending: Option<usize> = None;
    if lines == BendLines::Shop {
        return shop_bends(rulings, forward_left);
    }
    for (r, &fl) in rulings.iter().zip(forward_left) {
        let Some(piece) = r.piece else { continue };
        let deg = signed_deg(r, fl);
        let push = |out: &mut Vec<Bend>, angle: f64| {
            for e in &r.edges {
                out.push(Bend {
                    verts: *e,
                    angle_deg: angle,
                });
            }
        };
        match lines {
            BendLines::None => {}
            BendLines::All => {
                if deg.abs() > EPS_DEG {
                    push(&mut out, deg);
                }
            }
            BendLines::Spacing(sp) => {
                // A new piece starts its own count.
                if last.is_some_and(|(p, _)| p != piece) {
                    if let Some(i) = pending.take() {
                        add_to_last(&mut out, i, acc);
                    }
                    acc = 0.0;
                    last = None;
                }
                acc += deg;
                let due = last.is_none_or(|(_, s)| r.s - s >= sp);
                if due && deg.abs() > EPS_DEG && !r.edges.is_empty() {
                    pending = Some(out.len());
                    push(&mut out, acc);
                    acc = 0.0;
                    last = Some((piece, r.s));
                }
            }
            BendLines::Shop => {}
        }
    }
    if let Some(i) = pending {
        add_to_last(&mut out, i, acc);
    }
    out
}

/// A shop's bend lines ([`crate::surface::strip::shop`]), each piece on its own: equal
/// shares of its bend on rulings at least the shop spacing apart along the line.
fn shop_bends(rulings: &[Ruling], forward_left: &[bool]) -> Vec<Bend> {
    let mut out = Vec::new();
    let mut group: Vec<(&Ruling, f64)> = Vec::new();
    let flush = |group: &mut Vec<(&Ruling, f64)>, out: &mut Vec<Bend>| {
        let along_deg: Vec<crate::surface::strip::shop::Ruling> = group
            .iter()
            .map(|(r, d)| crate::surface::strip::shop::Ruling::at(r.s, *d))
            .collect();
        for (k, angle_deg) in crate::surface::strip::shop::picks(&along_deg) {
            for e in &group[k].0.edges {
                out.push(Bend {
                    verts: *e,
                    angle_deg,
                });
            }
        }
        group.clear();
    };
    for (r, &fl) in rulings.iter().zip(forward_left) {
        let Some(piece) = r.piece else { continue };
        if group.first().is_some_and(|(g, _)| g.piece != Some(piece)) {
            flush(&mut group, &mut out);
        }
        // A ruling with no edges on the mesh cannot carry a line: left out.
        if !r.edges.is_empty() {
            group.push((r, signed_deg(r, fl)));
        }
    }
    flush(&mut group, &mut out);
    out
}

/// Add `deg` to the bend lines from index `i` on (the segments of one ruling).
pub(super) fn add_to_last(out: &mut [Bend], i: usize, deg: f64) {
    for b in out.iter_mut().skip(i) {
        b.angle_deg += deg;
    }
}
