//! Small pieces merged with a slit or a dart (issue 20, item 3: no piece under 1 % of the area): a
//! small piece that no neighbour takes in any other way ([`super::merge`], [`super::hinge`])
//! often sits at a saddle vertex of the surface, where its faces and the neighbour's turn past
//! a full turn round a vertex on the border of the two as one. Laid flat, such a vertex's
//! faces overlap whatever the layout. Cut along an edge from that vertex into the piece (a
//! slit, as a dart is cut), its faces fall into two wedges that each turn less than a full
//! turn, and the two pieces may lie flat as one: the slit opens as far as the faces along it
//! give (a tip that turns less than a full turn, or the stretch the tolerance allows).
//!
//! Choices where the thesis is silent (§5.3 merges only charts whose union lies flat):
//! - **Which vertices.** Those on the union's border (its cuts opened) whose corner angles in
//!   3D sum to more than a full turn, the one that turns most first.
//! - **Which edge.** Of the vertex's edges inside the union, the one that splits its turn most
//!   evenly, both wedges under a full turn less [`WEDGE_MARGIN`], whose other end is not on
//!   the border (so the union stays in one piece). The tip is then on the border; where it
//!   turns past a full turn itself, the slit goes on from it, up to [`SLIT_EDGES`] edges.
//! - **Laid** anew ([`Charts::lay`]): the slit opens, which a layout started from the two as
//!   they lie (the slit closed) cannot do.
//! - **Kept** as a merge is ([`keeps`]: flip-free, within the tolerance, seams matched, no
//!   overlap) and when it fits the sheet.
//! - Neighbours tried: those sharing the longest boundary first, at most [`SLIT_TRIES`].
//!
//! A small piece on a bump of the surface (positive curvature) stretches the two as one past
//! the tolerance instead: they are laid out as one and relieved by darts as a chart over the
//! tolerance is ([`dart_merge`]; [`super::darts`]).
//!
//! Last, the two are laid out anew as one with none of their cuts but those the union needs
//! to be a disk ([`uncut_merge`]): a merge keeps the cuts of both, but a small piece that
//! fills a hole of its neighbour leaves the seam that opened the hole useless, and that seam
//! can be what makes the union overlap.

use super::darts::{darts, DART_MIN_FACES};
use super::join::fits_room;
use super::overlap::{as_one, keeps, laid_as_one};
use super::{Charts, FlattenOptions, Laid, Layout};
use crate::geom::cut::{open, Opened};
use std::collections::HashMap;
use std::f64::consts::TAU;

/// Neighbours a small piece is tried with.
pub(super) const SLIT_TRIES: usize = 3;
/// How far under a full turn (radians) each wedge of a slit vertex must stay.
const WEDGE_MARGIN: f64 = 0.02;

/// `done[part]` and `done[k]` laid out anew as one, with a slit at each vertex of their
/// border that turns past a full turn (see the module doc); `None` when there is no such
/// vertex, one has no edge to slit, or the union is not kept.
pub(super) fn slit_merge(
    ctx: &Charts,
    done: &[Laid],
    k: usize,
    part: usize,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<Laid> {
    let (faces, cuts) = as_one(ctx, &done[k], &done[part])?;
    let cuts = slit_saddles(ctx, &faces, &cuts)?;
    laid_anew(ctx, faces, cuts, opts, eps)
}

/// `done[part]` and `done[k]` laid out as one ([`laid_as_one`]) and, where that is over the
/// tolerance, relieved by darts as a chart over it is ([`darts`]): a small piece on a bump
/// of the surface stretches the two as one past the tolerance, and a dart from their border
/// toward the bump opens it. `None` unless the union is then kept as a merge is and fits the
/// sheet.
pub(super) fn dart_merge(
    ctx: &Charts,
    done: &[Laid],
    k: usize,
    part: usize,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<Laid> {
    let mut l = laid_as_one(ctx, done, k, part)?;
    if l.stretch.l2 <= opts.tolerance || l.faces.len() < DART_MIN_FACES || opts.darts == 0 {
        return None;
    }
    darts(ctx, &mut l, opts, eps).ok()?;
    (keeps(ctx, &l, opts, eps) && fits_room(opts.room, &l.uv)).then_some(l)
}

/// `done[part]` and `done[k]` laid out anew as one with only the cuts the two as one need to
/// be a disk, where those are not the cuts of both (see the module doc): a small piece that
/// fills a hole of its neighbour (a region cut off it, a gusset) leaves the seam that opened
/// the hole useless, and the slits and darts of both were made for each alone. `None` unless
/// the union is kept as a merge is and fits the sheet.
pub(super) fn uncut_merge(
    ctx: &Charts,
    done: &[Laid],
    k: usize,
    part: usize,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<Laid> {
    let (faces, both) = as_one(ctx, &done[k], &done[part])?;
    let cuts = ctx.disk(&faces, &[])?;
    if cuts == both {
        return None;
    }
    laid_anew(ctx, faces, cuts, opts, eps)
}

/// `faces` opened along `cuts` laid out anew, when kept as a merge is ([`keeps`]) and fitting
/// the sheet.
fn laid_anew(
    ctx: &Charts,
    faces: Vec<usize>,
    cuts: Vec<usize>,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<Laid> {
    let Ok(Layout::Laid(uv, stretch)) = ctx.lay(&faces, &cuts) else {
        return None;
    };
    let l = Laid {
        faces,
        cuts,
        uv,
        stretch,
        gusset: false,
    };
    (keeps(ctx, &l, opts, eps) && fits_room(opts.room, &l.uv)).then_some(l)
}

/// `cuts` with slits added until no vertex on the border of `faces` opened along them turns
/// past a full turn (see the module doc), sorted; `None` when there was no such vertex, one
/// has no edge to slit, it takes more than [`SLIT_EDGES`] edges, or the chart is no longer a
/// disk.
pub(super) fn slit_saddles(ctx: &Charts, faces: &[usize], cuts: &[usize]) -> Option<Vec<usize>> {
    let mut out = cuts.to_vec();
    for added in 0..=SLIT_EDGES {
        let fan = Fans::new(ctx, faces, &out);
        // The vertex that turns most past a full turn first (ties: lower local vertex).
        let Some(v) = (0..fan.turn.len())
            .filter(|&v| fan.border[v] && fan.turn[v] > TAU)
            .max_by(|&a, &b| fan.turn[a].total_cmp(&fan.turn[b]).then(b.cmp(&a)))
        else {
            return (added > 0 && fan.op.is_disk()).then_some(out);
        };
        if added == SLIT_EDGES {
            return None;
        }
        out.push(fan.slit_at(v)?);
        out.sort_unstable();
    }
    None
}

/// Edges one slit may take at most (the slit goes on from a tip that turns past a full turn
/// itself).
const SLIT_EDGES: usize = 6;

/// A chart opened along its cuts, with each local vertex's turn (its corner angles in 3D
/// summed) and whether it is on the border.
struct Fans<'a> {
    ctx: &'a Charts<'a>,
    faces: &'a [usize],
    cuts: &'a [usize],
    op: Opened,
    inside: Vec<bool>,
    at: HashMap<usize, usize>,
    turn: Vec<f64>,
    border: Vec<bool>,
}

impl<'a> Fans<'a> {
    fn new(ctx: &'a Charts<'a>, faces: &'a [usize], cuts: &'a [usize]) -> Self {
        let (mesh, topo) = (ctx.mesh, ctx.topo);
        let op = open(mesh, topo, faces, &|e| cuts.binary_search(&e).is_ok());
        let mut inside = vec![false; mesh.faces.len()];
        for &f in faces {
            inside[f] = true;
        }
        let nl = op.vertex.len();
        let mut fans = Fans {
            ctx,
            faces,
            cuts,
            op,
            inside,
            at: faces.iter().enumerate().map(|(i, &f)| (f, i)).collect(),
            turn: vec![0.0; nl],
            border: vec![false; nl],
        };
        for (fi, &f) in faces.iter().enumerate() {
            let n = mesh.faces[f].verts.len();
            for i in 0..n {
                let v = fans.op.corners[fi][i];
                fans.turn[v] += fans.angle(f, i);
                if fans.open_edge(topo.face_edges[f][i]) {
                    fans.border[v] = true;
                    fans.border[fans.op.corners[fi][(i + 1) % n]] = true;
                }
            }
        }
        fans
    }

    /// The 3D angle of face `f` at its corner `i`.
    fn angle(&self, f: usize, i: usize) -> f64 {
        let (vs, ps) = (&self.ctx.mesh.faces[f].verts, &self.ctx.mesh.vertices);
        let n = vs.len();
        let p = ps[vs[i]];
        (ps[vs[(i + n - 1) % n]] - p).angle_between(ps[vs[(i + 1) % n]] - p)
    }

    /// Whether a chart edge is open: cut, or with no other chart face across it.
    fn open_edge(&self, e: usize) -> bool {
        let uses = &self.ctx.topo.edges[e].uses;
        self.cuts.binary_search(&e).is_ok()
            || uses.len() != 2
            || !uses.iter().all(|u| self.inside[u.0])
    }

    /// The edge to slit at border vertex `v` (see the module doc): walking its fan from an
    /// open edge, face by face across the edges that are not, the crossed edge that splits
    /// its turn most evenly into two wedges each under a full turn, whose other end is not on
    /// the border.
    fn slit_at(&self, v: usize) -> Option<usize> {
        let (mesh, topo, faces) = (self.ctx.mesh, self.ctx.topo, self.faces);
        let edges_at = |fi: usize, i: usize| {
            let f = faces[fi];
            let n = mesh.faces[f].verts.len();
            [topo.face_edges[f][(i + n - 1) % n], topo.face_edges[f][i]]
        };
        let corners: Vec<(usize, usize)> = (0..faces.len())
            .flat_map(|fi| (0..mesh.faces[faces[fi]].verts.len()).map(move |i| (fi, i)))
            .filter(|&(fi, i)| self.op.corners[fi][i] == v)
            .collect();
        let &(mut fi, mut i) = corners
            .iter()
            .find(|&&(fi, i)| edges_at(fi, i).iter().any(|&e| self.open_edge(e)))?;
        let [e_a, e_b] = edges_at(fi, i);
        let mut came = if self.open_edge(e_a) { e_a } else { e_b };
        let (mut before, turn) = (0.0, self.turn[v]);
        let mut best: Option<(f64, usize)> = None;
        for _ in 0..corners.len() {
            let f = faces[fi];
            let n = mesh.faces[f].verts.len();
            before += self.angle(f, i);
            let [x, y] = edges_at(fi, i);
            let next = if x == came { y } else { x };
            if self.open_edge(next) {
                break;
            }
            let tip = if next == topo.face_edges[f][i] {
                self.op.corners[fi][(i + 1) % n]
            } else {
                self.op.corners[fi][(i + n - 1) % n]
            };
            let even = (before - 0.5 * turn).abs();
            let fits = before < TAU - WEDGE_MARGIN && turn - before < TAU - WEDGE_MARGIN;
            if fits && !self.border[tip] && best.is_none_or(|(b, _)| even < b) {
                best = Some((even, next));
            }
            // Across `next` to the face beyond, at its corner of the vertex.
            let g = topo.edges[next].uses.iter().find(|u| u.0 != f)?.0;
            fi = *self.at.get(&g)?;
            i = (0..mesh.faces[g].verts.len()).find(|&j| self.op.corners[fi][j] == v)?;
            came = next;
        }
        best.map(|(_, e)| e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::charts::{strip_and_squares, zigzag_cone, Fixture};
    use crate::geom::mesh::{Face, Mesh};
    use crate::surface::MaterialKind;
    use glam::DVec3;

    /// A ring of eight cells round one cell: laid alone, the ring needs a seam from its hole
    /// to its rim. Merged with the cell that fills the hole, the two are a disk: the union is
    /// laid without the seam, every face in one piece. A cell beside the ring's rim leaves
    /// the same cuts: no such merge.
    #[test]
    fn a_piece_filling_its_neighbours_hole_merges_without_the_seam_that_opened_it() {
        let (mesh, blocks) = strip_and_squares(&[
            (0..3, 1..2),
            (0..1, 2..3),
            (2..3, 2..3),
            (0..3, 3..4),
            (1..2, 2..3),
            (3..4, 1..2),
        ]);
        let fx = Fixture::new(mesh);
        let opts = FlattenOptions::default();
        let ctx = fx.charts(&opts);
        let ring: Vec<usize> = blocks[..4].iter().flat_map(|b| b.clone()).collect();
        let seam = ctx.disk(&ring, &[]).expect("a ring is cut into a disk");
        assert!(!seam.is_empty());
        let Ok(Layout::Laid(uv, stretch)) = ctx.lay(&ring, &seam) else {
            panic!("the ring is not laid");
        };
        let done = vec![
            Laid {
                faces: ring.clone(),
                cuts: seam,
                uv,
                stretch,
                gusset: false,
            },
            ctx.piece(blocks[4].clone().collect()),
            ctx.piece(blocks[5].clone().collect()),
        ];
        let eps = 1e-6;
        let l = uncut_merge(&ctx, &done, 0, 1, &opts, eps).expect("merged without the seam");
        assert!(l.cuts.is_empty(), "cuts {:?}", l.cuts);
        assert_eq!(l.faces.len(), ring.len() + 2);
        assert!(l.stretch.l2 < 1.0 + 1e-9, "L2 {}", l.stretch.l2);
        assert!(uncut_merge(&ctx, &done, 0, 2, &opts, eps).is_none());
    }

    /// Five sectors of the cone as one chart turn 400° round the apex on its border: one
    /// slit from the apex into the chart splits them into two wedges under a full turn, and
    /// leaves a disk. Four sectors (320°) need none.
    #[test]
    fn a_border_vertex_past_a_full_turn_is_slit_into_two_wedges() {
        let mesh = zigzag_cone();
        let opts = FlattenOptions::default();
        let fx = Fixture::new(mesh);
        let (mesh, topo) = (&fx.mesh, &fx.topo);
        let ctx = fx.charts(&opts);
        let five: Vec<usize> = (0..15).collect();
        let fans = Fans::new(&ctx, &five, &[]);
        let apex = (0..fans.turn.len())
            .find(|&v| fans.op.vertex[v] == 0)
            .expect("apex");
        assert!(fans.border[apex]);
        assert!((fans.turn[apex] - 400f64.to_radians()).abs() < 1e-9);
        let cuts = slit_saddles(&ctx, &five, &[]).expect("slit");
        assert_eq!(cuts.len(), 1, "{cuts:?}");
        let e = &topo.edges[cuts[0]];
        let ends = [
            mesh.faces[e.uses[0].0].verts.clone(),
            mesh.faces[e.uses[1].0].verts.clone(),
        ];
        assert!(ends.iter().all(|v| v.contains(&0)), "an edge of the apex");
        let after = Fans::new(&ctx, &five, &cuts);
        assert!(after.op.is_disk());
        let wedges: Vec<f64> = (0..after.turn.len())
            .filter(|&v| after.op.vertex[v] == 0)
            .map(|v| after.turn[v])
            .collect();
        assert_eq!(wedges.len(), 2, "{wedges:?}");
        assert!(wedges.iter().all(|&w| w < TAU - WEDGE_MARGIN), "{wedges:?}");
        assert!((0..after.turn.len()).all(|v| !after.border[v] || after.turn[v] <= TAU));
        let four: Vec<usize> = (0..12).collect();
        assert_eq!(slit_saddles(&ctx, &four, &[]), None);
    }

    /// A cone of 12 facets round an apex that lacks 60° of a full turn, in three rings of
    /// slant 10 mm each: faces `0..12` round the apex, then 24 per ring.
    fn bump() -> Mesh {
        let half = (1.0 - 60.0 / 360.0f64).asin();
        let mut vertices = vec![DVec3::ZERO];
        for ring in 1..=3 {
            let s = 10.0 * ring as f64;
            for i in 0..12 {
                let a = TAU * i as f64 / 12.0;
                let r = s * half.sin();
                vertices.push(DVec3::new(r * a.cos(), r * a.sin(), -s * half.cos()));
            }
        }
        let at = |ring: usize, i: usize| 1 + 12 * (ring - 1) + i % 12;
        let mut faces: Vec<Face> = (0..12)
            .map(|i| Face {
                verts: vec![0, at(1, i), at(1, i + 1)],
                line: None,
            })
            .collect();
        for ring in 1..3 {
            for i in 0..12 {
                let (a, b) = (at(ring, i), at(ring, i + 1));
                let (c, d) = (at(ring + 1, i), at(ring + 1, i + 1));
                for verts in [vec![a, c, d], vec![a, d, b]] {
                    faces.push(Face { verts, line: None });
                }
            }
        }
        Mesh { vertices, faces }
    }

    /// A small piece from the bump's top to its border and the rest of it each lie flat, but
    /// laid out as one they stretch past metal's tolerance (the cone lacks 60° round its
    /// apex, now inside); with a dart from the border to the apex they lie flat within it, one
    /// piece.
    #[test]
    fn a_small_piece_on_a_bump_merges_with_its_neighbour_by_a_dart() {
        let opts = FlattenOptions::for_material(MaterialKind::Metal);
        let fx = Fixture::new(bump());
        let ctx = fx.charts(&opts);
        let eps = 1e-6;
        // The small piece: a strip of one facet from the apex to the border.
        let strip = vec![0, 12, 13, 36, 37];
        let rest: Vec<usize> = (0..60).filter(|f| !strip.contains(f)).collect();
        let done = vec![ctx.piece(rest), ctx.piece(strip)];
        assert!(done.iter().all(|l| l.stretch.l2 <= opts.tolerance));
        let one = laid_as_one(&ctx, &done, 0, 1).expect("laid as one");
        assert!(one.stretch.l2 > opts.tolerance, "{}", one.stretch.l2);
        let l = dart_merge(&ctx, &done, 0, 1, &opts, eps).expect("merged by a dart");
        assert!(l.stretch.l2 <= opts.tolerance, "{}", l.stretch.l2);
        assert!(keeps(&ctx, &l, &opts, eps));
        assert!(!l.cuts.is_empty());
        let mut faces = l.faces.clone();
        faces.sort_unstable();
        assert_eq!(faces, (0..60).collect::<Vec<_>>());
        // Within the tolerance as one already: nothing to relieve.
        let paper = FlattenOptions {
            tolerance: 1.5,
            ..opts
        };
        assert!(dart_merge(&ctx, &done, 0, 1, &paper, eps).is_none());
    }
}
