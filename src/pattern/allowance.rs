//! What a material adds to the border of a piece before it is cut (issue 8, item 2): glue tabs
//! for paper, a seam allowance for fabric, V notches at bend lines and kerf compensation for
//! metal. The result is the piece's `outline`; its `border` stays the surface's edge.
//!
//! **Glue tabs** (`--tabs one-side|both`). A tab runs along a whole seam side, outside the
//! piece: the band of `tab_height` mm along the chain, its ends cut at 45° (the classic
//! trapezoid, following the chain where it bends). Before it is accepted it loses everything
//! that would overlap its own piece, come closer than [`TAB_GAP`] to the piece's other border
//! segments, or come closer than [`TAB_GAP`] to a tab already placed on the piece — the
//! overlap problem Blender's paper-model add-on leaves to the user. Of what remains, the part
//! attached to the seam is kept; when that is less than 35 % of the nominal tab, the tab is
//! tried again at 60 % and 36 % of the height, then dropped (the seam id still says where it
//! goes). With `one-side`, both sides are tried and the one with the larger tab wins (ties go
//! to side A); tabs are placed in seam order, so the result is deterministic. The tab's fold
//! is a mountain fold along the seam (the tab folds behind the printed side), bending by the
//! surface's angle there. Other pieces are the nest stage's business: the tabs are part of
//! the outline it nests. What a tab loses is worked out over a box round its band only (the
//! piece's rings and the tabs placed cut down to it, `polygon::clip_to_box`), so a piece of
//! thousands of border segments and tabs costs per tab what lies near that tab.
//!
//! **Seam allowance** (fabric): the border offset outward by `allowance` mm with mitred
//! corners (corners sharper than 30° are bevelled); holes shrink by the same amount. The
//! border becomes the drawn sewing line; notches are slits cut from the new outline inward.
//!
//! Every outline is finally [`clean`]ed: zero-width slits of the net closed, features below
//! what a knife can cut (0.1 mm) dropped, so that the rounded device coordinates still make
//! simple rings.
//!
//! **Bend notches** (metal, `--bend-notches`): a V 1.5 mm deep and 2 mm wide cut into the
//! outline where a bend line meets it. **Kerf**: every cut contour moves `kerf / 2` away from
//! the material (outline out, holes in), last, so that the cut edge lands on the border.

use super::{Fold, FoldKind, PatternOptions, Piece, Tabs};
use crate::flatten::Flat;
use crate::geom::boolean::{self, Shape};
use crate::geom::polygon;
use glam::DVec2;

/// Least distance (mm) between a tab and its piece's other edges or other tabs.
pub const TAB_GAP: f64 = 0.5;

/// Adds tabs, allowance, bend notches and kerf to the pieces of one flat, then the notch
/// strokes.
pub(super) fn apply(flat: &Flat, pieces: &mut [Piece], opts: &PatternOptions) {
    for p in pieces.iter_mut() {
        if let Some(outline) = clean(&p.border) {
            p.outline = outline;
        }
    }
    if opts.tabs != Tabs::None && opts.tab_height > 0.0 {
        tabs(flat, pieces, opts);
    }
    for p in pieces.iter_mut() {
        if opts.allowance > 0.0 {
            if let Some(outline) =
                single(boolean::offset(&p.border, opts.allowance)).and_then(|o| clean(&o))
            {
                p.outline = outline;
                p.seam_line = p.border.clone();
            }
        }
        if opts.bend_notches {
            bend_notches(p);
        }
        if opts.kerf > 0.0 {
            if let Some(outline) =
                single(boolean::offset(&p.outline, 0.5 * opts.kerf)).and_then(|o| clean(&o))
            {
                p.outline = outline;
            }
        }
        clip_folds(p);
        super::marks::notch_strokes(p, opts);
    }
}

/// Fold lines end on the border, but cleaning the outline ([`clean`]) trims an acute corner of
/// the border by more than [`CLEAN_MM`] (an opening by `d` cuts a corner of angle θ back by
/// about `d / sin(θ/2)`), leaving the end of a fold there outside the cut line (a tab fold
/// 0.31 mm out on couplingdown at 300 mm, past the sheet's margin). A fold with an end more
/// than `CLEAN_MM` outside (what the nest allows a mark: `Piece::OVERHANG_MM`) is cut back to
/// the longest part of it that lies inside the outline, one with nothing inside is dropped;
/// ends closer are left as they are, so that fold lengths scale with the model.
fn clip_folds(p: &mut Piece) {
    let outline = &p.outline;
    let on_or_inside = |q: DVec2| polygon::rings_distance(outline, q) >= -CLEAN_MM;
    p.folds.retain_mut(|f| {
        if on_or_inside(f.a) && on_or_inside(f.b) {
            return true;
        }
        let len = f.a.distance(f.b);
        if len <= 0.0 {
            return false;
        }
        let d = (f.b - f.a) / len;
        let best = polygon::line_intervals(outline, f.a, d)
            .into_iter()
            .map(|(t0, t1)| (t0.max(0.0), t1.min(len)))
            .filter(|(t0, t1)| t1 > t0)
            .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)));
        match best {
            Some((t0, t1)) if t1 - t0 > CLEAN_MM => {
                let a = f.a;
                f.a = a + d * t0;
                f.b = a + d * t1;
                true
            }
            _ => false,
        }
    });
}

/// Features narrower than twice this (mm) are closed or dropped from cut outlines: no knife
/// separates them, and rounding to device units would turn them into crossings.
pub const CLEAN_MM: f64 = 0.05;

/// A cut outline a machine can follow: the rings as one region (a zero-width slit of the net,
/// where both copies of an edge lie on each other, is closed: the faces simply stay joined
/// there), gaps narrower than `2 CLEAN_MM` closed and slivers as thin dropped
/// (morphological closing then opening, mitred), vertices closer than `CLEAN_MM / 2` to the
/// previous one merged. `None` when that does not leave exactly one shape.
pub fn clean(rings: &[Vec<DVec2>]) -> Option<Vec<Vec<DVec2>>> {
    let step =
        |shapes: Vec<Shape>, d: f64| -> Vec<Shape> { boolean::offset(&boolean::rings(shapes), d) };
    let closed = step(boolean::offset(rings, CLEAN_MM), -CLEAN_MM);
    let opened = step(step(closed.clone(), -CLEAN_MM), CLEAN_MM);
    // An opening that splits the piece at a thin neck would lose part of it: keep the closing.
    let shape = single(opened).or_else(|| single(closed))?;
    let shape: Vec<Vec<DVec2>> = shape
        .into_iter()
        .map(|ring| {
            let mut out: Vec<DVec2> = Vec::with_capacity(ring.len());
            for q in ring {
                if out.last().is_none_or(|l| l.distance(q) >= 0.5 * CLEAN_MM) {
                    out.push(q);
                }
            }
            while out.len() > 3 && out[0].distance(out[out.len() - 1]) < 0.5 * CLEAN_MM {
                out.pop();
            }
            out
        })
        .filter(|r| r.len() >= 3)
        .collect();
    (!shape.is_empty()).then_some(shape)
}

/// The one shape of a boolean result, with its outer ring first.
fn single(mut shapes: Vec<Shape>) -> Option<Vec<Vec<DVec2>>> {
    if shapes.len() != 1 || shapes[0].is_empty() {
        return None;
    }
    shapes.pop()
}

/// A candidate tab on one seam side: its region and area, or `None`.
struct Candidate {
    region: Shape,
    area: f64,
}

fn tabs(flat: &Flat, pieces: &mut [Piece], opts: &PatternOptions) {
    // Seam ids present in this flat, in order, with both sides' (piece index, side index).
    let mut seams: Vec<(usize, Vec<(usize, usize)>)> = Vec::new();
    for (pi, p) in pieces.iter().enumerate() {
        for (si, s) in p.seams.iter().enumerate() {
            match seams.iter_mut().find(|(id, _)| *id == s.id) {
                Some((_, v)) => v.push((pi, si)),
                None => seams.push((s.id, vec![(pi, si)])),
            }
        }
    }
    seams.sort_by_key(|(id, _)| *id);
    let mut placed: Vec<Vec<Shape>> = vec![Vec::new(); pieces.len()];
    // Per piece, the rings a new tab keeps clear of: each placed tab grown by TAB_GAP (grown
    // once, when it is placed).
    let mut gaps: Vec<Vec<Vec<DVec2>>> = vec![Vec::new(); pieces.len()];
    for (_, sides) in seams {
        let mut sides = sides;
        sides.sort_by_key(|&(pi, si)| !pieces[pi].seams[si].is_a);
        // The two sides' candidates do not depend on each other: on two cores when there are.
        let view: &[Piece] = pieces;
        let cand = |(pi, si): (usize, usize)| candidate(&view[pi], si, &gaps[pi], opts.tab_height);
        let cands: Vec<Option<Candidate>> = match sides[..] {
            [x, y] => {
                let (a, b) = crate::geom::par::join(|| cand(x), || cand(y));
                vec![a, b]
            }
            _ => sides.iter().map(|&s| cand(s)).collect(),
        };
        let chosen: Vec<usize> = match opts.tabs {
            Tabs::None => Vec::new(),
            Tabs::Both => (0..sides.len()).filter(|&i| cands[i].is_some()).collect(),
            Tabs::OneSide => {
                let best = (0..sides.len())
                    .filter(|&i| cands[i].is_some())
                    .max_by(|&i, &j| {
                        let (a, b) = (cands[i].as_ref(), cands[j].as_ref());
                        let (a, b) = (a.map_or(0.0, |c| c.area), b.map_or(0.0, |c| c.area));
                        // Larger area wins; on a tie the earlier side (A).
                        a.total_cmp(&b).then(j.cmp(&i))
                    });
                best.into_iter().collect()
            }
        };
        for i in chosen {
            let (pi, si) = sides[i];
            let Some(c) = cands[i].as_ref() else { continue };
            // Both sides may be on one piece (`both`): re-check against what was just placed.
            let c = if placed[pi].is_empty() || i == 0 {
                Candidate {
                    region: c.region.clone(),
                    area: c.area,
                }
            } else {
                match candidate(&pieces[pi], si, &gaps[pi], opts.tab_height) {
                    Some(c) => c,
                    None => continue,
                }
            };
            gaps[pi].extend(boolean::rings(boolean::offset(&c.region, TAB_GAP)));
            placed[pi].push(c.region);
            let p = &mut pieces[pi];
            p.seams[si].tab = true;
            let s = &p.seams[si];
            let n = p.border_edges[s.ring].len();
            let mut folds = Vec::new();
            for k in 0..s.count {
                let e = p.border_edges[s.ring][(s.first + k) % n];
                folds.push(Fold {
                    a: s.points[k],
                    b: s.points[k + 1],
                    kind: FoldKind::Mountain,
                    angle: flat.dihedral[e].abs(),
                    edge: e,
                    tab: true,
                });
            }
            p.folds.extend(folds);
        }
    }
    // Outline: the border with its tabs, when they make one simple shape; each piece on its
    // own, so on two cores when there are.
    let items: Vec<(&mut Piece, Vec<Shape>)> = pieces
        .iter_mut()
        .zip(placed)
        .filter(|(_, tabs)| !tabs.is_empty())
        .collect();
    let weight: Vec<usize> = items
        .iter()
        .map(|(p, tabs)| tabs.len() + p.border.iter().map(Vec::len).sum::<usize>())
        .collect();
    crate::geom::par::map(items, &weight, &|(p, tabs)| outline_with_tabs(p, &tabs));
}

/// `p`'s outline with its `tabs` joined on, when they make one simple shape; else its tabs
/// are dropped (the piece stays cuttable).
fn outline_with_tabs(p: &mut Piece, tabs: &[Shape]) {
    // Each tab grown by 0.01 mm, so that it overlaps its seam instead of meeting it along
    // a line (no sliver between them survives the union); TAB_GAP leaves room for this.
    let all: Vec<Vec<DVec2>> = tabs
        .iter()
        .flat_map(|t| boolean::rings(boolean::offset(t, 0.01)))
        .collect();
    let mut u = boolean::union(&p.outline, &all);
    // Keep the border's own holes; fill the pockets (usually specks of a few µm² where a
    // tab meets a corner of the border) that tabs close off.
    let inside: Vec<DVec2> = p.border[1..]
        .iter()
        .filter_map(|h| {
            let ccw: Vec<DVec2> = h.iter().rev().copied().collect();
            polygon::pole(&[ccw], 0.01).map(|(c, _)| c)
        })
        .collect();
    for shape in &mut u {
        let mut k = 0;
        shape.retain(|r| {
            k += 1;
            k == 1 || inside.iter().any(|c| polygon::contains(r, *c))
        });
    }
    match single(u).and_then(|o| clean(&o)) {
        Some(outline) if polygon::is_simple_ring(&outline[0]) => p.outline = outline,
        _ => {
            // Cannot happen with tabs kept apart by TAB_GAP; keep the piece cuttable.
            p.folds.retain(|f| !f.tab);
            for s in &mut p.seams {
                s.tab = false;
            }
        }
    }
}

/// The tab on side `si` of a piece, clear of the piece and of the tabs already placed (`gaps`:
/// each grown by [`TAB_GAP`]).
fn candidate(p: &Piece, si: usize, gaps: &[Vec<DVec2>], height: f64) -> Option<Candidate> {
    let s = &p.seams[si];
    let chain = &s.points;
    if s.length < 4.0 * TAB_GAP {
        return None;
    }
    let mut h = height.min(0.45 * s.length);
    for _ in 0..3 {
        let got = tab_region(p, si, gaps, h);
        if let Some(c) = got {
            if c.area >= 0.35 * nominal_area(chain, h) {
                return Some(c);
            }
        }
        h *= 0.6;
    }
    None
}

/// Area of the nominal trapezoid tab along a chain.
fn nominal_area(chain: &[DVec2], h: f64) -> f64 {
    let len: f64 = chain.windows(2).map(|w| w[0].distance(w[1])).sum();
    (len - h).max(0.0) * h
}

fn tab_region(p: &Piece, si: usize, gaps: &[Vec<DVec2>], h: f64) -> Option<Candidate> {
    let s = &p.seams[si];
    let chain = &s.points;
    let n = chain.len();
    // The border runs with the material on its left: outward is to the right.
    let t0 = (chain[1] - chain[0]).try_normalize()?;
    let tn = (chain[n - 1] - chain[n - 2]).try_normalize()?;
    let (o0, on) = (-t0.perp(), -tn.perp());
    let band = boolean::band(chain, h);
    // The clip is only needed over the band: every ring is cut down to a box round it
    // (`polygon::clip_to_box`, which leaves the fill inside the box as it was), so a tab costs
    // work for what lies near it, not for the whole outline and every tab placed before.
    let (wlo, whi) = polygon::bounds(band.iter().flatten().flatten().copied())?;
    let (wlo, whi) = (wlo - DVec2::splat(TAB_GAP), whi + DVec2::splat(TAB_GAP));
    let window = |ring: &Vec<DVec2>| -> Option<Vec<DVec2>> {
        let (rlo, rhi) = polygon::bounds(ring.iter().copied())?;
        if rhi.x < wlo.x || rlo.x > whi.x || rhi.y < wlo.y || rlo.y > whi.y {
            return None;
        }
        Some(polygon::clip_to_box(ring, wlo, whi)).filter(|r| r.len() >= 3)
    };
    // Clip: the piece itself, the 45° corners at both ends, the gap to the piece's other
    // border segments nearby and to the tabs already placed.
    let mut clip: Vec<Vec<DVec2>> = p.border.iter().filter_map(window).collect();
    let e = 0.01 * h + 1e-3;
    let big = 2.0 * h + 1.0;
    // Beyond the 45° lines from the chain's ends, outward: a quad at each end.
    for mut quad in [
        vec![
            chain[0] - o0 * e,
            chain[0] + (t0 + o0) * big,
            chain[0] + (o0 - t0) * big,
            chain[0] - t0 * big - o0 * e,
        ],
        vec![
            chain[n - 1] - on * e,
            chain[n - 1] + tn * big - on * e,
            chain[n - 1] + (on + tn) * big,
            chain[n - 1] + (on - tn) * big,
        ],
    ] {
        if polygon::signed_area(&quad) < 0.0 {
            quad.reverse();
        }
        clip.push(quad);
    }
    let (lo, hi) = polygon::bounds(chain.iter().copied())?;
    let reach = h + TAB_GAP + 1e-6;
    let (lo, hi) = (lo - DVec2::splat(reach), hi + DVec2::splat(reach));
    let near = |a: DVec2, b: DVec2| {
        a.max(b).x >= lo.x && a.min(b).x <= hi.x && a.max(b).y >= lo.y && a.min(b).y <= hi.y
    };
    let ring = &p.border[s.ring];
    let m = ring.len();
    for (r, pts) in p.border.iter().enumerate() {
        let k = pts.len();
        for i in 0..k {
            let own = r == s.ring && (i + m - s.first) % m < s.count;
            let (a, b) = (pts[i], pts[(i + 1) % k]);
            if !own && near(a, b) {
                clip.extend(boolean::rings(boolean::band(&[a, b], TAB_GAP)));
            }
        }
    }
    clip.extend(gaps.iter().filter_map(window));
    // Non-zero winding over the clip rings: the piece's holes (clockwise) stay open unless
    // something else (a gap band, a placed tab) covers them.
    let rest = boolean::difference(&boolean::rings(band), &clip);
    // Keep the part attached to the chain: the shape just outside the middle of the chain's
    // longest segment.
    let k = (0..n - 1)
        .max_by(|&i, &j| {
            let (li, lj) = (
                chain[i].distance(chain[i + 1]),
                chain[j].distance(chain[j + 1]),
            );
            li.total_cmp(&lj).then(j.cmp(&i))
        })
        .unwrap_or(0);
    let t = (chain[k + 1] - chain[k]).try_normalize()?;
    let probe = 0.5 * (chain[k] + chain[k + 1]) - t.perp() * (0.05 * h).min(0.05);
    let region = rest
        .into_iter()
        .find(|sh| !sh.is_empty() && polygon::contains_rings(sh, probe))?;
    let area = boolean::area(std::slice::from_ref(&region));
    (area > 0.0).then_some(Candidate { region, area })
}

/// V notches where bend lines meet the outline.
fn bend_notches(p: &mut Piece) {
    let mut vs: Vec<Vec<DVec2>> = Vec::new();
    for f in p.folds.iter().filter(|f| !f.tab) {
        for (end, other) in [(f.a, f.b), (f.b, f.a)] {
            // Only where the outline is the border (no allowance or tab there).
            let on_border = p.outline.iter().any(|r| {
                (0..r.len())
                    .any(|i| polygon::segment_distance(end, r[i], r[(i + 1) % r.len()]) < 1e-3)
            });
            let Some(u) = (other - end).try_normalize() else {
                continue;
            };
            if !on_border {
                continue;
            }
            let v = u.perp();
            // Apex 1.5 mm into the piece, 2 mm wide where it meets the outline.
            vs.push(vec![
                end + u * 1.5,
                end - u * 0.5 + v * 1.33,
                end - u * 0.5 - v * 1.33,
            ]);
        }
    }
    if vs.is_empty() {
        return;
    }
    for v in &mut vs {
        if polygon::signed_area(v) < 0.0 {
            v.reverse();
        }
    }
    if let Some(outline) = single(boolean::difference(&p.outline, &vs)).and_then(|o| clean(&o)) {
        p.outline = outline;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folds_are_cut_back_to_the_outline() {
        let sq = vec![
            DVec2::ZERO,
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(0.0, 10.0),
        ];
        let mut p = Piece::from_outline(1, "1".into(), sq);
        let fold = |a: DVec2, b: DVec2| Fold {
            a,
            b,
            kind: FoldKind::Mountain,
            angle: 0.5,
            edge: 0,
            tab: true,
        };
        p.folds = vec![
            // Inside: kept as it is.
            fold(DVec2::new(1.0, 1.0), DVec2::new(9.0, 9.0)),
            // On the cut line: kept.
            fold(DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0)),
            // 0.31 mm past the outline at one end: cut back to it.
            fold(DVec2::new(5.0, 5.0), DVec2::new(5.0, -0.31)),
            // Outside: dropped.
            fold(DVec2::new(20.0, 0.0), DVec2::new(30.0, 5.0)),
        ];
        clip_folds(&mut p);
        assert_eq!(p.folds.len(), 3);
        assert_eq!(p.folds[0].b, DVec2::new(9.0, 9.0));
        assert_eq!(p.folds[1].b, DVec2::new(10.0, 0.0));
        let f = &p.folds[2];
        assert!(f.a.distance(DVec2::new(5.0, 5.0)) < 1e-12, "{:?}", f.a);
        assert!(f.b.distance(DVec2::new(5.0, 0.0)) < 1e-12, "{:?}", f.b);
    }
}
