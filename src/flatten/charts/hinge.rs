//! Small pieces hinged onto a neighbour (issue 20, item 3: no piece under 1 % of the area): a
//! small piece that no neighbour takes laid out again as one ([`super::merge`]), nor shared
//! out, nor grafted face by face, is joined to a neighbour as it lies, by one edge of their
//! common boundary, as a papercraft net joins a flap: its layout is turned and moved so that
//! the edge lies where the neighbour has it, the two ends put exactly there, and the rest of
//! the common boundary becomes a slit inside the piece (a cut with seam marks on both sides,
//! sewn or glued as a seam between two pieces is). Nothing is laid out again and both layouts
//! keep their stretch, so the union is within the tolerance when both were.
//!
//! Where no edge hinges without overlap, the slit's two sides often run side by side and
//! cross a little (the two layouts of one curve differ by their stretch): then the best
//! candidates are tried once more with every common edge whose ends land within
//! [`HINGE_REACH`] of a mean common edge's length joined, and the union relaxed as a merged
//! piece is ([`Charts::lay_from`]: started from the two as they lie) and checked as one is.
//!
//! Choices where the thesis is silent (§5.3 only merges charts whose union lies flat):
//! - **Which edge.** Every common edge is a candidate hinge; the motion that puts it in place
//!   also puts other common edges in place where the two boundaries run alike (a fold of a
//!   developable), and those are joined too. Candidates are tried by the common length they
//!   join, longest first (ties: longer hinge edge, then lower edge id), at most
//!   [`HINGE_TRIES`] per neighbour, and relaxed the first [`RELAX_TRIES`].
//! - **Which neighbour.** Those sharing the longest boundary first, as for merges.
//! - **Kept when** the union is flip-free, within the tolerance, its seams matched, without
//!   overlap (the moved piece against the neighbour's faces near it; a relaxed union as a
//!   whole) and, when pieces are split to fit the sheet, fitting it (else the split would cut
//!   it up again).
//! - A common edge counts as in place when both its ends land within twice the seam tolerance
//!   of its 3D length of the neighbour's: each side was matched to the 3D length within that
//!   tolerance, so the hinge edge itself always is.

use super::join::{common, fits_room, Common};
use super::merge::small_pieces;
use super::overlap::{keeps, self_overlap, Owners};
use super::{Charts, FlattenOptions, Laid, Layout, Whole};
use crate::flatten::distortion;
use crate::geom::polygon;
use glam::DVec2;
use std::collections::HashMap;

/// Candidate hinge edges tried per neighbour.
const HINGE_TRIES: usize = 64;
/// Rounds at most (a hinged union still small may hinge again).
const HINGE_ROUNDS: usize = 4;
/// Candidates tried with the union relaxed, per neighbour.
const RELAX_TRIES: usize = 2;
/// How near (in mean common edge lengths) a common edge's ends must land to be joined when
/// the union is relaxed.
const HINGE_REACH: f64 = 0.5;

/// A rigid motion of the plane: a unit complex number (the turn) and a shift.
type Motion = (DVec2, DVec2);

/// Which common edges a motion joins.
type Joins<'a> = &'a (dyn Fn(Motion, &Common) -> bool + Sync);

/// Hinge every small piece of `done` that has a neighbour it fits beside (see the module
/// doc), smallest first, in rounds while one hinges.
pub(super) fn hinge_small(ctx: &Charts, done: &mut Vec<Laid>, opts: &FlattenOptions, eps: f64) {
    for _ in 0..HINGE_ROUNDS {
        let (small, order) = small_pieces(ctx, done);
        let mut owners = Owners::new(ctx.mesh.faces.len(), done);
        let mut any = false;
        for si in order {
            if owners.gone[si] || ctx.area(&done[si].faces) >= small {
                continue;
            }
            let near = owners.neighbours(ctx, done, si);
            if let Some(k) = near
                .into_iter()
                .find(|&k| hinge(ctx, done, k, si, opts, eps))
            {
                owners.absorb(done, k, si);
                any = true;
            }
        }
        owners.drop_gone(done);
        if !any {
            break;
        }
    }
}

/// The rigid motion (unit complex turn, shift) that puts `c`'s ends as the small piece lays
/// them onto the neighbour's: the turn of the edge's direction, the midpoints matched.
fn motion(c: &Common) -> Option<Motion> {
    let (d, t) = (c.here[1] - c.here[0], c.there[1] - c.there[0]);
    let r = DVec2::new(d.dot(t), d.perp_dot(t));
    let len = r.length();
    if !(len > 1e-300 && len.is_finite()) {
        return None;
    }
    let turn = r / len;
    let shift = 0.5 * (c.there[0] + c.there[1]) - turn.rotate(0.5 * (c.here[0] + c.here[1]));
    Some((turn, shift))
}

/// Try to hinge `done[part]` onto `done[k]` (see the module doc); true when it was, the
/// union then being `done[k]`.
fn hinge(
    ctx: &Charts,
    done: &mut [Laid],
    k: usize,
    part: usize,
    opts: &FlattenOptions,
    eps: f64,
) -> bool {
    let commons = common(ctx, done, k, part);
    let place = |(turn, shift): Motion, p: DVec2| turn.rotate(p) + shift;
    let in_place = |m: Motion, c: &Common| {
        let near = 2.0 * opts.seam_tolerance * c.length + 1e-9 * (1.0 + c.there[0].length());
        (0..2).all(|i| place(m, c.here[i]).distance(c.there[i]) <= near)
    };
    // Candidates: (joined length, hinge length, edge id, motion), best first.
    let mut cands: Vec<(f64, f64, usize, Motion)> = commons
        .iter()
        .filter_map(|c| {
            let m = motion(c)?;
            let joined: f64 = commons
                .iter()
                .filter(|o| in_place(m, o))
                .map(|o| o.length)
                .sum();
            Some((joined, c.length, c.edge, m))
        })
        .collect();
    cands.sort_by(|x, y| {
        y.0.total_cmp(&x.0)
            .then(y.1.total_cmp(&x.1))
            .then(x.2.cmp(&y.2))
    });
    // Each candidate rigidly, then the best joined wherever the two sides run within reach,
    // the union relaxed.
    let mean = commons.iter().map(|c| c.length).sum::<f64>() / commons.len().max(1) as f64;
    let reach = |m: Motion, c: &Common| {
        (0..2).all(|i| place(m, c.here[i]).distance(c.there[i]) <= HINGE_REACH * mean)
    };
    let tries: [(usize, Joins, bool); 2] =
        [(HINGE_TRIES, &in_place, false), (RELAX_TRIES, &reach, true)];
    for (n, joined, relax) in tries {
        let motions: Vec<Motion> = cands.iter().take(n).map(|c| c.3).collect();
        let try_one =
            |&m: &Motion| hinged(ctx, done, k, part, &commons, m, joined, opts, eps, relax);
        // A relaxed trial lays the union out: two at a time where a spare thread is free.
        let found = if relax {
            crate::geom::par::first(&motions, try_one).map(|(_, l)| l)
        } else {
            motions.iter().find_map(try_one)
        };
        if let Some(l) = found {
            done[k] = l;
            return true;
        }
    }
    false
}

/// `done[part]` moved by `m` beside `done[k]`, the common edges it `joins` joined (their ends
/// put where `done[k]` has them) and the others cut, the union `relax`ed or not; `None`
/// unless it is kept (see the module doc).
#[allow(clippy::too_many_arguments)]
fn hinged(
    ctx: &Charts,
    done: &[Laid],
    k: usize,
    part: usize,
    commons: &[Common],
    m: Motion,
    joins: Joins,
    opts: &FlattenOptions,
    eps: f64,
    relax: bool,
) -> Option<Laid> {
    let (turn, shift) = m;
    let place = |p: DVec2| turn.rotate(p) + shift;
    // Where the joined vertices go: (moved position, the neighbour's), per mesh vertex.
    let mut snap: HashMap<usize, Vec<(DVec2, DVec2)>> = HashMap::new();
    let mut cuts = done[k].cuts.clone();
    cuts.extend(&done[part].cuts);
    for c in commons {
        if joins(m, c) {
            for i in 0..2 {
                snap.entry(c.verts[i])
                    .or_default()
                    .push((place(c.here[i]), c.there[i]));
            }
        } else {
            cuts.push(c.edge);
        }
    }
    cuts.sort_unstable();
    cuts.dedup();
    let moved: Vec<Vec<DVec2>> = done[part]
        .faces
        .iter()
        .zip(&done[part].uv)
        .map(|(&f, corners)| {
            let verts = &ctx.mesh.faces[f].verts;
            verts
                .iter()
                .zip(corners)
                .map(|(v, &p)| {
                    let p = place(p);
                    snap.get(v)
                        .and_then(|l| {
                            l.iter()
                                .find(|(from, _)| from.distance(p) <= 1e-9 * (1.0 + p.length()))
                        })
                        .map_or(p, |&(_, to)| to)
                })
                .collect()
        })
        .collect();
    if !fits_room(opts.room, &[done[k].uv.as_slice(), &moved].concat()) {
        return None;
    }
    if !relax && overlaps_near(&done[k].uv, &moved, eps) {
        return None;
    }
    let mut faces = done[k].faces.clone();
    faces.extend(&done[part].faces);
    let mut uv = done[k].uv.clone();
    uv.extend(moved);
    let (uv, stretch) = if relax {
        match ctx.lay_from(&faces, &cuts, Some(&Whole::new(&faces, &uv))) {
            Ok(Layout::Laid(uv, stretch)) => (uv, stretch),
            _ => return None,
        }
    } else {
        let stretch = distortion::stretch(ctx.mesh, &faces, &uv);
        (uv, stretch)
    };
    let l = Laid {
        faces,
        cuts,
        uv,
        stretch,
        gusset: false,
    };
    // A rigid hinge's overlap was looked for where it can be (`overlaps_near`).
    let kept = if relax {
        keeps(ctx, &l, opts, eps)
    } else {
        stretch.flipped == 0
            && stretch.l2 <= opts.tolerance
            && ctx.seam_error(&l) <= opts.seam_tolerance
    };
    kept.then_some(l)
}

/// Whether the `moved` piece overlaps itself or the faces of `fixed` near it (deeper than
/// `eps`).
fn overlaps_near(fixed: &[Vec<DVec2>], moved: &[Vec<DVec2>], eps: f64) -> bool {
    let Some((lo, hi)) = polygon::bounds(moved.iter().flatten().copied()) else {
        return false;
    };
    let nearby: Vec<Vec<DVec2>> = fixed
        .iter()
        .filter(|c| {
            polygon::bounds(c.iter().copied()).is_some_and(|(a, b)| {
                a.x <= hi.x + eps && a.y <= hi.y + eps && b.x >= lo.x - eps && b.y >= lo.y - eps
            })
        })
        .chain(moved)
        .cloned()
        .collect();
    self_overlap(&nearby, eps).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::charts::LayCache;
    use crate::geom::cut::Graph;
    use crate::geom::mesh::{Face, Mesh};
    use glam::DVec3;

    /// Six triangles round an apex at the origin, the rim vertices at `z(i)` over the unit
    /// hexagon.
    fn fan(z: impl Fn(usize) -> f64) -> Mesh {
        let mut vertices = vec![DVec3::ZERO];
        for i in 0..6 {
            let a = (60.0 * i as f64).to_radians();
            vertices.push(DVec3::new(10.0 * a.cos(), 10.0 * a.sin(), z(i)));
        }
        let faces = (0..6)
            .map(|i| Face {
                verts: vec![0, i + 1, (i + 1) % 6 + 1],
                line: None,
            })
            .collect();
        Mesh { vertices, faces }
    }

    /// The fan laid out exactly in two pieces: faces 0–4 round the apex from the direction of
    /// +x (the neighbour), face 5 on its own away from it (the small piece).
    fn laid(mesh: &Mesh) -> Vec<Laid> {
        let p = |v: usize| mesh.vertices[v];
        let angle = |i: usize| {
            let (a, b) = (p(i + 1), p((i + 1) % 6 + 1));
            a.angle_between(b)
        };
        let mut dir = 0.0;
        let mut spoke = Vec::new();
        for i in 0..6 {
            spoke.push(DVec2::from_angle(dir) * p(i + 1).length());
            dir += angle(i);
        }
        let uv_n: Vec<Vec<DVec2>> = (0..5)
            .map(|i| vec![DVec2::ZERO, spoke[i], spoke[i + 1]])
            .collect();
        let at = DVec2::new(50.0, 0.0);
        let uv_s = vec![vec![
            at,
            at + DVec2::X * p(6).length(),
            at + DVec2::from_angle(angle(5)) * p(1).length(),
        ]];
        let piece = |faces: Vec<usize>, uv: Vec<Vec<DVec2>>| Laid {
            stretch: distortion::stretch(mesh, &faces, &uv),
            faces,
            cuts: Vec::new(),
            uv,
            gusset: false,
        };
        vec![piece((0..5).collect(), uv_n), piece(vec![5], uv_s)]
    }

    fn try_hinge(mesh: &Mesh) -> Option<Laid> {
        let topo = mesh.topology();
        let graph = Graph::new(mesh, &topo);
        let opts = FlattenOptions::default();
        let ctx = Charts {
            mesh,
            topo: &topo,
            graph: &graph,
            method: opts.method,
            match_below: opts.tolerance,
            laid: &LayCache::default(),
        };
        let mut done = laid(mesh);
        for l in &done {
            assert!((l.stretch.l2 - 1.0).abs() < 1e-12, "laid exactly");
        }
        let eps = 1e-6;
        hinge(&ctx, &mut done, 0, 1, &opts, eps).then(|| {
            let l = done.swap_remove(0);
            // Exactly one of the two common spokes is a slit.
            let spokes = [0usize, 5].map(|f| topo.face_edges[f][0]);
            assert_eq!(l.cuts.len(), 1, "{:?}", l.cuts);
            assert!(spokes.contains(&l.cuts[0]));
            l
        })
    }

    /// A pyramid (positive angle defect at the apex): the union as one chart cannot lie flat
    /// without stretch, but the small face hinged on one spoke lies beside its neighbour as
    /// the unfolder would lay it, the other spoke a slit that opens by the angle defect.
    #[test]
    fn a_small_piece_hinges_where_the_slit_opens() {
        let mesh = fan(|_| -4.0);
        let l = try_hinge(&mesh).expect("hinged");
        assert_eq!(l.faces, vec![0, 1, 2, 3, 4, 5]);
        assert!((l.stretch.l2 - 1.0).abs() < 1e-9, "{}", l.stretch.l2);
        assert_eq!(l.stretch.flipped, 0);
        assert!(self_overlap(&l.uv, 1e-6).is_none());
        // The hinge spoke: face 5's copy where face 0 (or 4) has it; the apex shared.
        let (hinge_face, hinge_corner) = if l.cuts[0] == mesh.topology().face_edges[0][0] {
            (4, 2)
        } else {
            (0, 1)
        };
        assert_eq!(l.uv[5][0], l.uv[hinge_face][0]);
        let s_corner = if hinge_face == 0 { 2 } else { 1 };
        assert_eq!(l.uv[5][s_corner], l.uv[hinge_face][hinge_corner]);
        // The slit opens: its two copies of the rim end lie apart by about the defect's chord.
        let defect: f64 = 2.0 * std::f64::consts::PI
            - (0..6)
                .map(|i| mesh.vertices[i + 1].angle_between(mesh.vertices[(i + 1) % 6 + 1]))
                .sum::<f64>();
        assert!(defect > 0.1);
        let (a, b) = if hinge_face == 0 {
            (l.uv[5][1], l.uv[4][2])
        } else {
            (l.uv[5][2], l.uv[0][1])
        };
        let chord = 2.0 * mesh.vertices[1].length() * (0.5 * defect).sin();
        assert!(
            (a.distance(b) - chord).abs() < 1e-9 * chord,
            "{}",
            a.distance(b)
        );
    }

    /// A saddle (the rim up and down, more than a full turn of angle at the apex): the small
    /// face overlaps its neighbour on either spoke, so it is not hinged.
    #[test]
    fn a_small_piece_is_not_hinged_where_it_would_overlap() {
        let mesh = fan(|i| if i % 2 == 0 { 5.0 } else { -5.0 });
        let total: f64 = (0..6)
            .map(|i| mesh.vertices[i + 1].angle_between(mesh.vertices[(i + 1) % 6 + 1]))
            .sum();
        assert!(total > 2.0 * std::f64::consts::PI + 0.1, "{total}");
        assert!(try_hinge(&mesh).is_none());
    }
}
