//! Two laid pieces as one layout, one moved rigidly onto the other along their common
//! boundary: what [`super::merge`] joins without laying anything out again (`attach`), and
//! where a merge laid out again starts from ([`super::overlap::merge_into`]). The common
//! boundary itself ([`common`]) is also where [`super::hinge`] hinges a small piece.
//!
//! Choices: the rigid motion is the least-squares fit of the common vertices (2D Kabsch, no
//! scaling: both layouts have their 3D size); a corner of the moved piece within twice the
//! worst misfit of the vertex it stands for is put where the other piece has that vertex, so
//! the two share their common vertices exactly.
//!
//! Whether a merged layout fits the sheet ([`fits_room`]) is judged here too: a layout fits the
//! room when the box of its minimum-area rectangle does, at a quarter turn (as the nest turns
//! pieces; a grain line, which fixes the turn, is not known here).

use super::{Charts, Laid};
use crate::geom::polygon;
use glam::DVec2;
use std::collections::HashMap;

/// Two laid pieces as one layout, one moved onto the other ([`moved_onto`]).
pub(super) struct Joined {
    /// The faces of both, `done[k]`'s first.
    pub faces: Vec<usize>,
    /// Their layout: `done[k]`'s as it lies, `done[part]`'s moved.
    pub uv: Vec<Vec<DVec2>>,
    /// Common edges, their mesh vertices, their length.
    pub edges: usize,
    pub verts: usize,
    pub length: f64,
    /// Farthest a common vertex of `done[part]` ends from where `done[k]` has it.
    pub worst: f64,
}

/// `done[part]`'s layout moved onto `done[k]`'s by the rigid motion that best fits their
/// common boundary ([`fit`]), each corner of `done[part]` within twice the worst misfit of a
/// common vertex put where `done[k]` has that vertex; `None` when they share no edge, or a
/// common vertex is in two places in `done[k]`.
pub(super) fn moved_onto(ctx: &Charts, done: &[Laid], k: usize, part: usize) -> Option<Joined> {
    let commons = common(ctx, done, k, part);
    if commons.is_empty() {
        return None;
    }
    // Each common vertex as `part` has it and where `done[k]` has it.
    let mut pairs: Vec<(DVec2, DVec2)> = Vec::new();
    let mut at: HashMap<usize, DVec2> = HashMap::new();
    for c in &commons {
        for ((&v, &p), &q) in c.verts.iter().zip(&c.here).zip(&c.there) {
            match at.get(&v) {
                Some(old) if old.distance(q) > 1e-9 * (1.0 + q.length()) => return None,
                Some(_) => {}
                None => {
                    at.insert(v, q);
                    pairs.push((p, q));
                }
            }
        }
    }
    let (edges, length) = (commons.len(), commons.iter().map(|c| c.length).sum());
    let (turn, shift) = fit(&pairs)?;
    let moved = |p: DVec2| turn.rotate(p) + shift;
    let worst = pairs
        .iter()
        .map(|&(p, q)| moved(p).distance(q))
        .fold(0.0, f64::max);
    let mut faces = done[k].faces.clone();
    let mut uv = done[k].uv.clone();
    for (&f, corners) in done[part].faces.iter().zip(&done[part].uv) {
        let verts = &ctx.mesh.faces[f].verts;
        faces.push(f);
        uv.push(
            verts
                .iter()
                .zip(corners)
                .map(|(v, &p)| {
                    let p = moved(p);
                    match at.get(v) {
                        Some(&q) if q.distance(p) <= 2.0 * worst + 1e-9 * (1.0 + q.length()) => q,
                        _ => p,
                    }
                })
                .collect(),
        );
    }
    Some(Joined {
        faces,
        uv,
        edges,
        verts: at.len(),
        length,
        worst,
    })
}

/// An edge of the common boundary of two laid pieces (a part and a neighbour).
pub(super) struct Common {
    /// Topology edge id.
    pub(super) edge: usize,
    /// Its two mesh vertices, as the part runs it.
    pub(super) verts: [usize; 2],
    /// Its ends in the part's layout, and in the neighbour's (same order).
    pub(super) here: [DVec2; 2],
    pub(super) there: [DVec2; 2],
    /// Its 3D length.
    pub(super) length: f64,
}

/// The common boundary of `done[part]` and `done[k]`, in the order of `done[part]`'s faces
/// and their edges; empty when they share no edge.
pub(super) fn common(ctx: &Charts, done: &[Laid], k: usize, part: usize) -> Vec<Common> {
    let in_k: HashMap<usize, usize> = done[k]
        .faces
        .iter()
        .enumerate()
        .map(|(i, &f)| (f, i))
        .collect();
    let mut out = Vec::new();
    for (pi, &f) in done[part].faces.iter().enumerate() {
        let n = ctx.mesh.faces[f].verts.len();
        for i in 0..n {
            let edge = ctx.topo.face_edges[f][i];
            let e = &ctx.topo.edges[edge];
            let Some(&(g, j)) = e.uses.iter().find(|u| u.0 != f) else {
                continue;
            };
            let (Some(&ki), 2) = (in_k.get(&g), e.uses.len()) else {
                continue;
            };
            let m = ctx.mesh.faces[g].verts.len();
            let verts = [
                ctx.mesh.faces[f].verts[i],
                ctx.mesh.faces[f].verts[(i + 1) % n],
            ];
            out.push(Common {
                edge,
                verts,
                here: [done[part].uv[pi][i], done[part].uv[pi][(i + 1) % n]],
                // The edge runs the other way round in `g`.
                there: [done[k].uv[ki][(j + 1) % m], done[k].uv[ki][j]],
                length: ctx.mesh.vertices[verts[0]].distance(ctx.mesh.vertices[verts[1]]),
            });
        }
    }
    out
}

/// The rotation (as a unit complex number) and shift that best move the first points of
/// `pairs` onto the second (least squares); `None` for fewer than two distinct points.
fn fit(pairs: &[(DVec2, DVec2)]) -> Option<(DVec2, DVec2)> {
    let n = pairs.len() as f64;
    let cp = pairs.iter().map(|p| p.0).sum::<DVec2>() / n;
    let cq = pairs.iter().map(|p| p.1).sum::<DVec2>() / n;
    let (mut dot, mut cross) = (0.0, 0.0);
    for &(p, q) in pairs {
        let (a, b) = (p - cp, q - cq);
        dot += a.dot(b);
        cross += a.perp_dot(b);
    }
    let r = DVec2::new(dot, cross);
    let len = r.length();
    if len <= 1e-300 || !len.is_finite() {
        return None;
    }
    let turn = r / len;
    Some((turn, cq - turn.rotate(cp)))
}

/// Whether a layout fits `room` (width, height; see [`super::FlattenOptions::room`]), if
/// any: the box of its minimum-area rectangle, at a quarter turn.
pub(super) fn fits_room(room: Option<[f64; 2]>, uv: &[Vec<DVec2>]) -> bool {
    room_parts(room, uv) <= 1
}

/// The fewest parts a layout is cut into to fit `room` (see [`fits_room`]): the box of its
/// minimum-area rectangle cut into a grid of room-sized cells, at the better quarter turn (1
/// where it fits, or there is no room). The pattern stage cuts along the piece's own edges,
/// so it may need more.
pub(super) fn room_parts(room: Option<[f64; 2]>, uv: &[Vec<DVec2>]) -> usize {
    let Some(room) = room else {
        return 1;
    };
    let pts: Vec<DVec2> = uv.iter().flatten().copied().collect();
    let turn = DVec2::from_angle(polygon::min_area_rect_angle(&pts));
    let Some((lo, hi)) = polygon::bounds(pts.iter().map(|&p| turn.rotate(p))) else {
        return 1;
    };
    let size = hi - lo;
    let cells = |w: f64, h: f64| {
        let across = |len: f64, cell: f64| match (len / cell).ceil() {
            n if n.is_nan() => f64::INFINITY,
            n => n.max(1.0),
        };
        across(w, room[0]) * across(h, room[1])
    };
    let k = cells(size.x, size.y).min(cells(size.y, size.x));
    if k.is_finite() {
        k.min(usize::MAX as f64) as usize
    } else {
        usize::MAX
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_layout_fits_the_room_at_a_quarter_turn_of_its_least_rectangle() {
        // A 100 x 20 mm strip of two triangles, turned by 30°.
        let turn = DVec2::from_angle(30f64.to_radians());
        let p = [(0.0, 0.0), (100.0, 0.0), (100.0, 20.0), (0.0, 20.0)]
            .map(|(x, y)| turn.rotate(DVec2::new(x, y)) + DVec2::new(7.0, -3.0));
        let uv = vec![vec![p[0], p[1], p[2]], vec![p[0], p[2], p[3]]];
        assert!(fits_room(None, &uv));
        assert!(fits_room(Some([100.5, 20.5]), &uv));
        assert!(fits_room(Some([20.5, 100.5]), &uv), "a quarter turn");
        assert!(fits_room(Some([100.5, f64::INFINITY]), &uv), "a roll");
        assert!(!fits_room(Some([99.5, 20.5]), &uv));
        assert!(!fits_room(Some([100.5, 19.5]), &uv));
        // Judged as the nest turns it (its least rectangle square to the sheet), not as it
        // lies: its box as it lies is 96.6 x 67.3 mm.
        assert!(!fits_room(Some([97.0, 68.0]), &uv));
        // Parts: the least rectangle in room-sized cells, at the better quarter turn.
        assert_eq!(room_parts(Some([100.5, 20.5]), &uv), 1);
        assert_eq!(room_parts(Some([40.5, 20.5]), &uv), 3);
        assert_eq!(room_parts(Some([20.5, 40.5]), &uv), 3, "a quarter turn");
        assert_eq!(
            room_parts(Some([40.5, 10.5]), &uv),
            6,
            "3 cells along, 2 across"
        );
        assert_eq!(room_parts(Some([30.0, f64::INFINITY]), &uv), 1, "a roll");
        assert_eq!(room_parts(Some([15.0, f64::INFINITY]), &uv), 2);
        assert_eq!(room_parts(None, &uv), 1);
    }
}
