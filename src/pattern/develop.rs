//! Sheet-metal development of mesh pieces (issue 20, item 9): each fold of a metal piece
//! unfolded from a mesh becomes a bend with the allowance of its angle, so that the blank is
//! the flat pattern a press brake folds back into the model — the way FreeCAD's SheetMetal
//! workbench unfolds a part, with the formulas of [`crate::geom::bend`] (BA = θ·(R + K·t),
//! OSSB = (R + t)·tan(θ/2), BD = 2·OSSB − BA).
//!
//! **The mesh is the outer mold line.** A mesh is read as the outside of the part (a CAD box
//! of 100 mm is 100 mm outside), the sheet lying behind the printed side. A convex fold
//! (mountain) then has the mesh on its outside: each flange is measured to the outside mold
//! line's sharp corner and the blank loses BD = 2·(R + t)·tan(θ/2) − θ·(R + K·t) there. At a
//! concave fold (valley) the mesh is the inside of the bend: its flanges are measured to the
//! inside mold line's corner, setback R·tan(θ/2), and BD = 2·R·tan(θ/2) − BA, which is
//! negative for small radii (the blank is longer there). θ is the fold's deflection (π minus
//! the angle between the faces; 90° for a box), R the inside radius, t the thickness and K
//! the neutral surface's depth over the thickness, from `[material]` (`k_factor`,
//! `bend_radius`; defaults 0.4 and R = t).
//!
//! **How.** The faces joined by flat (non-fold) edges form panels, the flat walls of the part.
//! Each panel is trimmed by BD/2 along every fold on its border — its edge line moves inward
//! by BD/2 and the panel's corners slide along its other edges (a face's corner inside a panel
//! does not move) — and every panel is moved towards the panel it is joined to by BD across
//! the fold (the island's first face stays where it is), so that the two trimmed edges meet
//! again on the bend centre line, where the bend line is drawn, in the middle of the bend
//! zone BA wide. A face between two parallel folds of a box (100 mm outside) thus comes out
//! 100 − BD between its bend lines, one with a fold and a free edge 100 − BD/2 from the bend
//! line to the edge. Faces keep their corners (a developed face is the same polygon, its
//! corners moved), so seams, marks and splitting work on the developed piece as on any other.
//! A seam of a developed piece is as long as its sides are flat, shorter than in 3D by the
//! bends it runs into (and its two sides by different bends): it is not a seam mismatch
//! (`marks::seam_mismatches` leaves it out).
//!
//! **Corners** (where nothing says; the choices are a shop's). Where a bend line ends on the
//! border between two faces of one fold, the two trimmed corners both lie on the bend line and
//! the border runs along it from one to the other (nothing when the free edges are square to
//! the bend, a jog where they are not). Where two or more folds meet at a border vertex — a
//! box's corner, where the base's two bends meet — the flanges' bend zones overlap and so do
//! their trimmed corners; a shop cuts a corner relief there, and so does flatcut: a round hole
//! (FreeCAD SheetMetal's "circle" corner relief) centred where the bend centre lines meet (the
//! corner of the panel between the folds; the mean of those corners for three folds or more),
//! of the least radius that clears the intersection of the bend zones (each BA wide about its
//! bend line), the trimmed corners and any overlap of the flanges' sides: BA/√2 at a box's
//! corner. Its arc is cut within 0.01 mm of the circle; the bend lines stop on it. The flanges
//! keep their outside width up to the relief: two walls of a box meet on the outside line at
//! their seam, as the mesh says; a butt joint takes the thickness off one of them (left to the
//! user: the mesh cannot say which). Where a bend ends on a free edge that runs straight on (a
//! flange narrower than the wall it hangs from), the wall's corner moves onto the bend line
//! and its free edge leans by BD/2 over its length; a shop would cut a bend relief slot there
//! (not made). A corner moved further than ten times its offset (two nearly parallel edges)
//! is moved square to them instead.
//!
//! **What is not developed.** Pieces laid out from charts of a smooth mesh (their bends are
//! gradual, not brake bends), strips, fittings and spline surfaces (developed on their neutral
//! surface when they are made), paper and fabric. A piece whose development cannot be made
//! exactly is left as laid flat with the reason in [`Development::skipped`] (a
//! `bend-development` warning): folds that meet inside the piece (around an inside vertex),
//! panels around a closed loop of folds whose deductions do not agree, a face narrower than
//! the deductions of its folds, or an outline that would cross itself. A fold the split cut
//! (`split`) is a seam between two parts, not a bend: the parts are developed one by one.
//! The flat the pipeline keeps (`--uv-obj`, texture painting) is the one laid out, not
//! developed.

use super::{PatternOptions, Ring, Step};
use crate::flatten::Flat;
use crate::geom::bend::{MoldLine, SheetBend};
use crate::geom::polygon;
use glam::DVec2;
use std::collections::{HashMap, HashSet, VecDeque};

/// The mesh edge of a border segment that is no edge of the mesh: a corner relief's arc or the
/// jog between two trimmed corners on a bend line.
pub const NO_EDGE: usize = usize::MAX;

/// Largest distance, in units of the offset, a trimmed corner may move from its vertex (a
/// miter limit): beyond it the two lines are taken as parallel.
const MITER_LIMIT: f64 = 10.0;

/// One bend of a developed piece.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendFigure {
    /// The mesh edge it bends along.
    pub edge: usize,
    /// Deflection angle θ (radians, unsigned).
    pub angle: f64,
    /// The mold line the mesh gives for it: outside for a mountain (convex) fold, inside for
    /// a valley.
    pub mold: MoldLine,
    /// Bend allowance BA (mm).
    pub allowance: f64,
    /// Setback (mm) from the mold line's sharp corner.
    pub setback: f64,
    /// Bend deduction BD (mm): what the blank loses against the mesh across the bend.
    pub deduction: f64,
}

/// How a piece was developed.
#[derive(Debug, Clone, PartialEq)]
pub struct Development {
    /// The sheet: thickness, K factor, inside radius.
    pub sheet: SheetBend,
    /// Its bends, by mesh edge.
    pub bends: Vec<BendFigure>,
    /// Radii (mm) of its corner reliefs, in border order.
    pub reliefs: Vec<f64>,
    /// Why the piece was left as laid flat, when it was.
    pub skipped: Option<String>,
}

impl Development {
    /// The bend along mesh edge `edge`.
    pub fn bend(&self, edge: usize) -> Option<&BendFigure> {
        self.bends
            .binary_search_by_key(&edge, |b| b.edge)
            .ok()
            .map(|i| &self.bends[i])
    }

    /// Whether the piece's bends changed its lengths (developed, with at least one bend).
    pub fn changed(&self) -> bool {
        self.skipped.is_none() && !self.bends.is_empty()
    }
}

/// A developed flat: the faces of the developed islands moved and trimmed, and per island
/// what `net` builds the piece from.
pub(super) struct Developed {
    pub flat: Flat,
    pub islands: Vec<Island>,
}

/// One island's development.
pub(crate) struct Island {
    /// Its border rings (points, mesh edge or [`NO_EDGE`], face), in `walk` order; `None`
    /// when it was not developed (then the piece is built from the flat as laid).
    pub rings: Option<Vec<Ring>>,
    /// Each bend line on its bend centre line, within the blank, by mesh edge.
    pub folds: HashMap<usize, (DVec2, DVec2)>,
    pub development: Development,
}

/// The development of `flat` when `opts` asks for it (a metal mesh laid out exactly), else
/// `None`.
pub(super) fn develop(flat: &Flat, opts: &PatternOptions) -> Option<Developed> {
    let sheet = opts.develop_for(&flat.surface.name)?;
    if flat.surface.charts.is_some() {
        return None;
    }
    let fold_at = super::bends::fold_angles(flat, opts.fold_threshold_deg.to_radians());
    let mut out = flat.clone();
    let mut islands = Vec::with_capacity(flat.islands.len());
    for k in 0..flat.islands.len() {
        let island = match island(flat, k, &fold_at, &sheet) {
            Ok(d) => {
                for (f, pts) in d.faces {
                    out.face_2d[f] = pts;
                }
                Island {
                    rings: Some(d.rings),
                    folds: d.folds,
                    development: Development {
                        sheet,
                        bends: d.bends,
                        reliefs: d.reliefs,
                        skipped: None,
                    },
                }
            }
            Err(why) => Island {
                rings: None,
                folds: HashMap::new(),
                development: Development {
                    sheet,
                    bends: Vec::new(),
                    reliefs: Vec::new(),
                    skipped: Some(why),
                },
            },
        };
        islands.push(island);
    }
    Some(Developed { flat: out, islands })
}

/// The `bend-development` warnings of pieces left as laid flat: (piece name, message).
pub fn warnings(pieces: &[super::Piece]) -> Vec<(String, String)> {
    pieces
        .iter()
        .filter_map(|p| {
            let why = p.development.as_ref()?.skipped.as_ref()?;
            Some((
                p.name.clone(),
                format!(
                    "piece {}: its folds are not developed as bends (no bend allowance): {why}",
                    p.name
                ),
            ))
        })
        .collect()
}

/// What developing one island gives.
struct IslandOut {
    faces: Vec<(usize, Vec<DVec2>)>,
    rings: Vec<Ring>,
    folds: HashMap<usize, (DVec2, DVec2)>,
    bends: Vec<BendFigure>,
    reliefs: Vec<f64>,
}

/// Develops island `k` of `flat` (see the module doc), or says why it cannot.
fn island(
    flat: &Flat,
    k: usize,
    fold_at: &[Option<f64>],
    sheet: &SheetBend,
) -> Result<IslandOut, String> {
    let faces = &flat.islands[k];
    let mut cx = Ctx {
        flat,
        faces,
        local: faces.iter().enumerate().map(|(i, &f)| (f, i)).collect(),
        fold_at,
        bends: Vec::new(),
        tol: 1e-6 + 2.0 * flat.tolerance,
    };
    cx.bends = cx.figures(sheet);
    let shift = cx.shifts()?;
    let dev = cx.developed_faces(&shift)?;
    // The border, with the corners between trimmed faces, and the check that folds meet
    // only on it.
    let loops = super::walk(flat, faces).ok_or("its outline could not be traced")?;
    cx.check_inside(&loops, &dev)?;
    let mut rings = Vec::with_capacity(loops.len());
    let mut reliefs = Vec::new();
    for l in &loops {
        rings.push(cx.ring(l, &dev, &mut reliefs)?);
    }
    if crosses(&rings) {
        return Err("its outline would cross itself".into());
    }
    let folds = cx.bend_lines(&dev, &rings);
    Ok(IslandOut {
        faces: dev.into_iter().collect(),
        rings,
        folds,
        bends: cx.bends,
        reliefs,
    })
}

/// One island being developed.
struct Ctx<'a> {
    flat: &'a Flat,
    faces: &'a [usize],
    /// Each face's index in `faces`.
    local: HashMap<usize, usize>,
    fold_at: &'a [Option<f64>],
    /// The island's bends, by edge.
    bends: Vec<BendFigure>,
    /// How far (mm) two positions of one point may differ: the unfolding's own tolerance.
    tol: f64,
}

impl Ctx<'_> {
    /// The other use (face, corner) of edge `e` than `u`.
    fn other(&self, e: usize, u: (usize, usize)) -> Option<(usize, usize)> {
        self.flat.topology.edges[e]
            .uses
            .iter()
            .copied()
            .find(|&w| w != u)
    }

    fn len(&self, f: usize) -> usize {
        self.flat.surface.mesh.faces[f].verts.len()
    }

    /// A fold of this island: a joined edge bending past the threshold.
    fn fold(&self, e: usize) -> bool {
        self.flat.joined[e] && self.fold_at[e].is_some()
    }

    /// A joined edge inside a panel.
    fn flat_join(&self, e: usize) -> bool {
        self.flat.joined[e] && self.fold_at[e].is_none()
    }

    fn figure(&self, e: usize) -> Option<&BendFigure> {
        self.bends
            .binary_search_by_key(&e, |b| b.edge)
            .ok()
            .map(|i| &self.bends[i])
    }

    /// How far (mm) a panel's edge along `e` moves in: half the bend deduction of a fold.
    fn half(&self, e: usize) -> f64 {
        self.figure(e).map_or(0.0, |b| 0.5 * b.deduction)
    }

    /// The bends, each once (from the face listed first on its edge), by edge.
    fn figures(&self, sheet: &SheetBend) -> Vec<BendFigure> {
        let topo = &self.flat.topology;
        let mut bends = Vec::new();
        for &f in self.faces {
            for (i, &e) in topo.face_edges[f].iter().enumerate() {
                let first = topo.edges[e].uses.first() == Some(&(f, i));
                if let (true, Some(d), true) = (self.flat.joined[e], self.fold_at[e], first) {
                    let mold = if d > 0.0 {
                        MoldLine::Outside
                    } else {
                        MoldLine::Inside
                    };
                    bends.push(BendFigure {
                        edge: e,
                        angle: d.abs(),
                        mold,
                        allowance: sheet.allowance(d),
                        setback: sheet.setback(d, mold),
                        deduction: sheet.deduction(d, mold),
                    });
                }
            }
        }
        bends.sort_by_key(|b| b.edge);
        bends
    }

    /// Each face's move with its panel, by its index in `faces`: by BD across every fold
    /// from the first face, towards the panel it is joined to.
    fn shifts(&self) -> Result<Vec<DVec2>, String> {
        let topo = &self.flat.topology;
        let mut shift: Vec<Option<DVec2>> = vec![None; self.faces.len()];
        let root = *self.faces.first().ok_or("the piece has no faces")?;
        shift[0] = Some(DVec2::ZERO);
        let mut queue = VecDeque::from([root]);
        while let Some(f) = queue.pop_front() {
            let Some(tf) = shift[self.local[&f]] else {
                continue;
            };
            for (i, &e) in topo.face_edges[f].iter().enumerate() {
                let Some((g, _)) = self.other(e, (f, i)).filter(|_| self.flat.joined[e]) else {
                    continue;
                };
                let Some(&lg) = self.local.get(&g) else {
                    continue;
                };
                let want = if self.fold(e) {
                    let (a, b) = self.flat.corner_edge(f, i);
                    tf + (b - a).normalize_or_zero().perp() * (2.0 * self.half(e))
                } else {
                    tf
                };
                match shift[lg] {
                    None => {
                        shift[lg] = Some(want);
                        queue.push_back(g);
                    }
                    Some(tg) if tg.distance(want) > self.tol => {
                        return Err(format!(
                            "its folds close a loop (through mesh edge {}) whose bend deductions do not add up",
                            e + 1
                        ))
                    }
                    Some(_) => {}
                }
            }
        }
        shift
            .into_iter()
            .map(|t| t.ok_or_else(|| "its faces are not all joined".to_string()))
            .collect()
    }

    /// Every face's corners where its panel, trimmed and moved, puts them; a face that
    /// would turn over is an error.
    fn developed_faces(&self, shift: &[DVec2]) -> Result<HashMap<usize, Vec<DVec2>>, String> {
        let mut dev = HashMap::with_capacity(self.faces.len());
        for &f in self.faces {
            let pts = (0..self.len(f))
                .map(|c| self.corner(shift, f, c))
                .collect::<Result<Vec<_>, _>>()?;
            let orig = &self.flat.face_2d[f];
            let n = pts.len();
            let kept =
                (0..n).all(|c| (pts[(c + 1) % n] - pts[c]).dot(orig[(c + 1) % n] - orig[c]) > 0.0);
            if !kept || polygon::signed_area(&pts) <= 0.0 {
                return Err(format!(
                    "face {} is narrower than the bend deductions of its folds",
                    f + 1
                ));
            }
            dev.insert(f, pts);
        }
        Ok(dev)
    }

    /// Corner `c` of face `f` developed: where the two border edges of its panel at that
    /// vertex (reached about it through flat joins), each moved in by half its deduction,
    /// meet; unchanged inside a panel or between two edges that do not move.
    fn corner(&self, shift: &[DVec2], f: usize, c: usize) -> Result<DVec2, String> {
        let topo = &self.flat.topology;
        let t = shift[self.local[&f]];
        let here = self.flat.face_2d[f][c] + t;
        let broken = || "its faces do not close around a vertex".to_string();
        let guard: usize = self.faces.iter().map(|&g| self.len(g)).sum::<usize>() + 1;
        // About the vertex through flat joins, each way, to the panel's border edges.
        let (mut g, mut j) = (f, c);
        let mut n = 0;
        while self.flat_join(topo.face_edges[g][j]) {
            let (h, kk) = self
                .other(topo.face_edges[g][j], (g, j))
                .ok_or_else(broken)?;
            (g, j) = (h, (kk + 1) % self.len(h));
            if (g, j) == (f, c) {
                return Ok(here); // inside the panel
            }
            n += 1;
            if n > guard {
                return Err(broken());
            }
        }
        let (go, jo) = (g, j);
        let (mut g, mut i) = (f, (c + self.len(f) - 1) % self.len(f));
        while self.flat_join(topo.face_edges[g][i]) {
            let (h, kk) = self
                .other(topo.face_edges[g][i], (g, i))
                .ok_or_else(broken)?;
            (g, i) = (h, (kk + self.len(h) - 1) % self.len(h));
            n += 1;
            if n > guard {
                return Err(broken());
            }
        }
        let (gi, ji) = (g, i);
        let (d_in, d_out) = (
            self.half(topo.face_edges[gi][ji]),
            self.half(topo.face_edges[go][jo]),
        );
        if d_in == 0.0 && d_out == 0.0 {
            return Ok(here);
        }
        let (p0, p1) = self.flat.corner_edge(gi, ji);
        let (q0, q1) = self.flat.corner_edge(go, jo);
        let (u_in, u_out) = ((p1 - p0).normalize_or_zero(), (q1 - q0).normalize_or_zero());
        let (a, b) = (p0 + t + u_in.perp() * d_in, q0 + t + u_out.perp() * d_out);
        let (oi, oo) = (u_in.perp() * d_in, u_out.perp() * d_out);
        let parallel = here
            + if d_in != 0.0 && d_out != 0.0 {
                0.5 * (oi + oo)
            } else {
                oi + oo
            };
        let cross = u_in.perp_dot(u_out);
        if cross.abs() < 1e-9 {
            return Ok(parallel);
        }
        let at = a + u_in * ((b - a).perp_dot(u_out) / cross);
        if at.distance(here) > MITER_LIMIT * d_in.abs().max(d_out.abs()) {
            return Ok(parallel);
        }
        Ok(at)
    }

    /// Folds meet only on the border: every vertex inside the island keeps one position.
    fn check_inside(
        &self,
        loops: &[Vec<Step>],
        dev: &HashMap<usize, Vec<DVec2>>,
    ) -> Result<(), String> {
        let mesh = &self.flat.surface.mesh;
        let vert = |f: usize, c: usize| mesh.faces[f].verts[c % self.len(f)];
        let on_border: HashSet<usize> =
            loops.iter().flatten().map(|s| vert(s.f, s.i + 1)).collect();
        let mut seen: HashMap<usize, DVec2> = HashMap::new();
        for &f in self.faces {
            for (c, &p) in dev[&f].iter().enumerate() {
                let v = vert(f, c);
                if on_border.contains(&v) {
                    continue;
                }
                let first = *seen.entry(v).or_insert(p);
                if first.distance(p) > self.tol {
                    return Err(format!(
                        "folds meet inside the piece (at mesh vertex {})",
                        v + 1
                    ));
                }
            }
        }
        Ok(())
    }

    /// Bend lines: the part of each bend centre line both faces reach, within the blank.
    fn bend_lines(
        &self,
        dev: &HashMap<usize, Vec<DVec2>>,
        rings: &[Ring],
    ) -> HashMap<usize, (DVec2, DVec2)> {
        let pts: Vec<Vec<DVec2>> = rings.iter().map(|r| r.0.clone()).collect();
        let mut folds = HashMap::new();
        for b in &self.bends {
            let e = b.edge;
            let (f, i) = self.flat.topology.edges[e].uses[0];
            let Some((g, j)) = self.other(e, (f, i)) else {
                continue;
            };
            let (a0, a1) = (dev[&f][i], dev[&f][(i + 1) % self.len(f)]);
            let length = a0.distance(a1);
            if length <= 0.0 {
                continue;
            }
            let u = (a1 - a0) / length;
            let (s0, s1) = (
                (dev[&g][j] - a0).dot(u),
                (dev[&g][(j + 1) % self.len(g)] - a0).dot(u),
            );
            let (lo, hi) = (s0.min(s1).max(0.0), s0.max(s1).min(length));
            let inside = polygon::line_intervals(&pts, a0, u)
                .into_iter()
                .map(|(t0, t1)| (t0.max(lo), t1.min(hi)))
                .filter(|(t0, t1)| t1 > t0)
                .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)));
            let (t0, t1) = inside.unwrap_or((lo, hi));
            if t1 - t0 > 1e-9 {
                folds.insert(e, (a0 + u * t0, a0 + u * t1));
            }
        }
        folds
    }

    /// One border ring of a developed island: each boundary half-edge from its trimmed
    /// start, and between two of them what their corners need: nothing when they meet, the
    /// segment along the bend line from one to the other across one fold, a corner relief
    /// where two or more folds meet (its radius pushed onto `reliefs`).
    fn ring(
        &self,
        steps: &[Step],
        dev: &HashMap<usize, Vec<DVec2>>,
        reliefs: &mut Vec<f64>,
    ) -> Result<Ring, String> {
        let n = steps.len();
        let at = |f: usize, c: usize| {
            let p = &dev[&f];
            p[c % p.len()]
        };
        let seg: Vec<(DVec2, DVec2)> = steps
            .iter()
            .map(|s| (at(s.f, s.i), at(s.f, s.i + 1)))
            .collect();
        let mut lo = vec![0.0_f64; n];
        let mut hi = vec![1.0_f64; n];
        let mut extra: Vec<Vec<DVec2>> = vec![Vec::new(); n];
        for k in 0..n {
            let next = (k + 1) % n;
            let folds: Vec<usize> = (0..steps[k].turn.len())
                .filter(|&q| self.fold(steps[k].turn[q].0))
                .collect();
            if folds.len() < 2 {
                if seg[k].1.distance(seg[next].0) > 1e-9 {
                    extra[k].push(seg[k].1);
                }
                continue;
            }
            let (c, r) = self.relief(&steps[k], &folds, dev, seg[k], seg[next]);
            let swallowed = || "a corner relief takes a whole edge of the piece".to_string();
            let (ta, _) = circle_hits(seg[k], c, r).ok_or_else(swallowed)?;
            let (_, tb) = circle_hits(seg[next], c, r).ok_or_else(swallowed)?;
            if !(0.0..=1.0).contains(&ta) || !(0.0..=1.0).contains(&tb) {
                return Err(swallowed());
            }
            hi[k] = hi[k].min(ta);
            lo[next] = lo[next].max(tb);
            let pa = seg[k].0 + (seg[k].1 - seg[k].0) * ta;
            let pb = seg[next].0 + (seg[next].1 - seg[next].0) * tb;
            extra[k] = arc(c, r, pa, pb);
            reliefs.push(r);
        }
        let (mut pts, mut edges, mut owners) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..n {
            if lo[k] >= hi[k] - 1e-9 {
                return Err("the corner reliefs at both ends of an edge overlap".into());
            }
            let (a, b) = seg[k];
            pts.push(if lo[k] == 0.0 { a } else { a + (b - a) * lo[k] });
            edges.push(steps[k].e);
            owners.push(steps[k].f);
            for &p in &extra[k] {
                pts.push(p);
                edges.push(NO_EDGE);
                owners.push(steps[k].f);
            }
        }
        Ok((pts, edges, owners))
    }

    /// The corner relief after border step `s`, whose turn crosses the folds `folds` (two or
    /// more): centred where the bend lines meet (the corners of the faces between the first
    /// and the last fold), of the radius that clears the bend zones' overlaps, the trimmed
    /// corners and a crossing of the flanges' sides `a` and `b`.
    fn relief(
        &self,
        s: &Step,
        folds: &[usize],
        dev: &HashMap<usize, Vec<DVec2>>,
        a: (DVec2, DVec2),
        b: (DVec2, DVec2),
    ) -> (DVec2, f64) {
        let at = |f: usize, c: usize| {
            let p = &dev[&f];
            p[c % p.len()]
        };
        let mids: Vec<DVec2> = folds[..folds.len() - 1]
            .iter()
            .map(|&q| {
                let (_, g, j) = s.turn[q];
                at(g, j)
            })
            .collect();
        let c = mids.iter().copied().sum::<DVec2>() / mids.len() as f64;
        let mut r = mids
            .iter()
            .chain([&a.1, &b.0])
            .map(|p| p.distance(c))
            .fold(0.0, f64::max);
        // Each bend zone: BA wide about its bend line (the fold's edge in the face after it).
        let zone = |q: usize| {
            let (e, g, j) = s.turn[q];
            let (p0, p1) = (at(g, j + self.len(g) - 1), at(g, j));
            let w = self.figure(e).map_or(0.0, |b| 0.5 * b.allowance);
            (p1, (p1 - p0).normalize_or_zero().perp(), w)
        };
        for w in folds.windows(2) {
            let ((pa, na, wa), (pb, nb, wb)) = (zone(w[0]), zone(w[1]));
            let det = na.perp_dot(nb);
            if det.abs() < 1e-3 {
                continue;
            }
            for sa in [-1.0, 1.0] {
                for sb in [-1.0, 1.0] {
                    let (ra, rb) = (na.dot(pa) + sa * wa, nb.dot(pb) + sb * wb);
                    let x = DVec2::new(ra * nb.y - rb * na.y, na.x * rb - nb.x * ra) / det;
                    r = r.max(x.distance(c));
                }
            }
        }
        if let Some(x) = crossing(a, b) {
            r = r.max(x.distance(c));
        }
        (c, r * (1.0 + 1e-9) + 1e-6)
    }
}

/// The arc of a corner relief from `pa` to just before `pb`, clockwise about `c` (the hole on
/// the right of the border, the material on its left), within 0.01 mm of the circle.
fn arc(c: DVec2, r: f64, pa: DVec2, pb: DVec2) -> Vec<DVec2> {
    let (fa, fb) = ((pa - c).to_angle(), (pb - c).to_angle());
    let sweep = (fa - fb).rem_euclid(std::f64::consts::TAU);
    let step = (2.0 * (1.0 - 0.01 / r).max(-1.0).acos()).clamp(1e-3, 15f64.to_radians());
    let parts = (sweep / step).ceil().max(1.0) as usize;
    let mut out = vec![pa];
    for m in 1..parts {
        let phi = fa - sweep * m as f64 / parts as f64;
        out.push(c + DVec2::from_angle(phi) * r);
    }
    out
}

/// Where the segment `s` (from `s.0` to `s.1`) meets the circle about `c` of radius `r`: the
/// parameters of entering and leaving; `None` when it does not enter the circle from outside
/// and leave it again as a segment crossing the border must (the start inside for the first,
/// the end inside for the second are fine: each caller uses one).
fn circle_hits(s: (DVec2, DVec2), c: DVec2, r: f64) -> Option<(f64, f64)> {
    let d = s.1 - s.0;
    let f = s.0 - c;
    let a = d.length_squared();
    if a <= 0.0 {
        return None;
    }
    let b = 2.0 * f.dot(d);
    let cc = f.length_squared() - r * r;
    let disc = b * b - 4.0 * a * cc;
    if disc < 0.0 {
        return None;
    }
    let q = disc.sqrt();
    Some(((-b - q) / (2.0 * a), (-b + q) / (2.0 * a)))
}

/// The point where two segments cross properly, if they do.
fn crossing(p: (DVec2, DVec2), q: (DVec2, DVec2)) -> Option<DVec2> {
    let (d, e) = (p.1 - p.0, q.1 - q.0);
    let den = d.perp_dot(e);
    if den == 0.0 {
        return None;
    }
    let t = (q.0 - p.0).perp_dot(e) / den;
    let u = (q.0 - p.0).perp_dot(d) / den;
    (t > 0.0 && t < 1.0 && u > 0.0 && u < 1.0).then(|| p.0 + d * t)
}

/// Whether two segments of the rings (not neighbours on one ring) cross properly.
fn crosses(rings: &[Ring]) -> bool {
    let mut segs: Vec<(usize, usize, usize, DVec2, DVec2)> = Vec::new();
    for (ri, r) in rings.iter().enumerate() {
        let n = r.0.len();
        for i in 0..n {
            segs.push((ri, i, n, r.0[i], r.0[(i + 1) % n]));
        }
    }
    segs.sort_by(|x, y| x.3.x.min(x.4.x).total_cmp(&y.3.x.min(y.4.x)));
    for (a, s) in segs.iter().enumerate() {
        let (x_hi, y_lo, y_hi) = (s.3.x.max(s.4.x), s.3.y.min(s.4.y), s.3.y.max(s.4.y));
        for t in &segs[a + 1..] {
            if t.3.x.min(t.4.x) > x_hi {
                break;
            }
            if t.3.y.max(t.4.y) < y_lo || t.3.y.min(t.4.y) > y_hi {
                continue;
            }
            let neighbours = s.0 == t.0 && ((s.1 + 1) % s.2 == t.1 || (t.1 + 1) % t.2 == s.1);
            if !neighbours && crossing((s.3, s.4), (t.3, t.4)).is_some() {
                return true;
            }
        }
    }
    false
}
