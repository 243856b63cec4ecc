//! Marks that tell a person which edge goes where and which way up a piece goes: seams with
//! the same id on both sides, notches at equal arc lengths, piece labels, grain lines and bend
//! notes (issue 8, item 1).
//!
//! **Seams.** A seam is a chain of consecutive border segments of one piece whose copies are
//! consecutive, in reverse order, on the border of another piece (or of the same piece): one
//! 3D edge chain cut into two piece boundaries. Chains are found by walking each border ring
//! and linking segment `k − 1` to `k` when their twins are `j` and `j − 1` on the same ring; a
//! chain never runs into its own other side (the two copies of an edge at a leaf of the cut
//! tree are adjacent on the border and make a one-segment seam). A ring that is one chain all
//! round starts at its segment 0. Seams are numbered 1, 2, … over the whole job, in the order
//! of pieces, rings and segments; the first piece met is side A.
//!
//! **Notches** go at equal arc lengths from side A's start, which is side B's end: every
//! `spacing` mm (on side B at the same fraction of the same mesh edge), plus a second notch 3 mm (at most a tenth of the seam) after the first one,
//! so that the pattern of notches is not symmetric and the pieces cannot be joined reversed.
//! A seam shorter than 1¼ spacings gets its pair at a third of its length; one shorter than
//! 5 mm gets none.
//!
//! **Text.** The seam id is written along the longest segment of each side, inside the face
//! (as the edge ids before it: at most 3 mm, 30 % of the segment, 35 % of the face's depth).
//! The label (name, then `#id` and which side faces up) is centred on the pole of
//! inaccessibility of the border and sized so that its whole block fits in 90 % of the
//! inscribed circle there: it stays inside the piece in any orientation, which lets the
//! toolpath stage turn it upright on the sheet whatever rotation the nest chose.
//!
//! **Grain line** (fabric): along the long side of the piece's minimum-area rectangle, the
//! longest chord in that direction that keeps clear of the label, 70 % of it, with arrowheads
//! at both ends. **Bend notes** (metal): `90° UP` (valley) or `90° DOWN` (mountain) beside each
//! bend line: which way the flange goes with the marked side up; written, and every text here
//! moved off the lines and texts it would cover, by [`super::legible`].

use super::{EdgeMark, Notch, PatternOptions, Piece};
use crate::flatten::Flat;
use crate::geom::{font, polygon};
use crate::surface::MaterialKind;
use glam::DVec2;
use std::collections::HashMap;

/// Single-stroke text placed on a piece.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Text {
    pub strokes: Vec<Vec<DVec2>>,
    /// Reading direction (unit) of text set along an edge; `None` for text that may be turned
    /// freely about its centre (the label).
    pub dir: Option<DVec2>,
}

impl Text {
    pub fn points(&self) -> impl Iterator<Item = DVec2> + '_ {
        self.strokes.iter().flatten().copied()
    }
    pub fn is_empty(&self) -> bool {
        self.strokes.is_empty()
    }
}

/// One piece's side of a seam.
#[derive(Debug, Clone, PartialEq)]
pub struct SeamSide {
    /// Seam id, the same on both sides and in report.json.
    pub id: usize,
    /// Side A (the first met) or B.
    pub is_a: bool,
    /// Id of the piece on the other side.
    pub partner: usize,
    /// Border ring and first segment of the chain, and its number of segments.
    pub ring: usize,
    pub first: usize,
    pub count: usize,
    /// The chain on this piece, `count + 1` points in border order.
    pub points: Vec<DVec2>,
    /// Its length (mm): the sum of its mesh edges' lengths, as laid flat on their faces.
    pub length: f64,
    /// The 3D length of its mesh edges (mm): what both sides' `length` should be.
    pub length_3d: f64,
    /// Notch positions as arc lengths from this side's first point (mm).
    pub notches: Vec<f64>,
    /// A glue tab was put on this side.
    pub tab: bool,
    /// The seam was made by splitting a piece too large for the sheet ([`super::split`]).
    pub split: bool,
}

/// Finds the seams of one flat's pieces: each piece gets its side of every seam it has, in
/// seam order, without notches (see [`place`]).
pub(super) fn find(flat: &Flat, pieces: &mut [Piece], next_id: &mut usize) {
    // Where each cut mesh edge lies on the borders: (piece, ring, segment).
    type Loc = (usize, usize, usize);
    let mut at: HashMap<usize, Vec<Loc>> = HashMap::new();
    for (pi, p) in pieces.iter().enumerate() {
        for (r, ring) in p.border_edges.iter().enumerate() {
            // A corner of a developed metal piece is no mesh edge (`develop::NO_EDGE`).
            for (k, &e) in ring
                .iter()
                .enumerate()
                .filter(|(_, &e)| e < flat.topology.edges.len())
            {
                at.entry(e).or_default().push((pi, r, k));
            }
        }
    }
    let twin = |l: Loc| -> Option<Loc> {
        let e = pieces[l.0].border_edges[l.1][l.2];
        let locs = at.get(&e)?;
        if locs.len() != 2 {
            return None;
        }
        locs.iter().copied().find(|&o| o != l)
    };
    let len_of = |pi: usize, r: usize| pieces[pi].border_edges[r].len();
    // Segment k continues the chain of k − 1.
    let linked = |l: Loc| -> bool {
        let n = len_of(l.0, l.1);
        let prev = (l.0, l.1, (l.2 + n - 1) % n);
        match (twin(prev), twin(l)) {
            (Some(tp), Some(tk)) => {
                let m = len_of(tp.0, tp.1);
                tk.0 == tp.0 && tk.1 == tp.1 && tk.2 == (tp.2 + m - 1) % m && tk != prev
            }
            _ => false,
        }
    };

    let mut done: std::collections::HashSet<Loc> = Default::default();
    let mut found: Vec<(Loc, usize, Loc)> = Vec::new(); // (A start, count, B start)
    for (pi, piece) in pieces.iter().enumerate() {
        for r in 0..piece.border_edges.len() {
            let n = len_of(pi, r);
            // Chain starts: segments with a twin not linked to their predecessor; a ring
            // linked all round starts at 0.
            let mut starts: Vec<usize> = (0..n)
                .filter(|&k| twin((pi, r, k)).is_some() && !linked((pi, r, k)))
                .collect();
            if starts.is_empty() && n > 0 && twin((pi, r, 0)).is_some() {
                starts.push(0);
            }
            for k0 in starts {
                if done.contains(&(pi, r, k0)) {
                    continue;
                }
                let mut other: std::collections::HashSet<Loc> = Default::default();
                let mut count = 0;
                let mut k = k0;
                let mut b_start = (0, 0, 0);
                loop {
                    let l = (pi, r, k);
                    let Some(t) = twin(l) else { break };
                    if done.contains(&l) || other.contains(&l) || (count > 0 && !linked(l)) {
                        break;
                    }
                    done.insert(l);
                    done.insert(t);
                    other.insert(t);
                    b_start = t;
                    count += 1;
                    k = (k + 1) % n;
                    if k == k0 {
                        break;
                    }
                }
                if count > 0 {
                    found.push(((pi, r, k0), count, b_start));
                }
            }
        }
    }

    for (a, count, b) in found {
        let id = *next_id;
        *next_id += 1;
        let side = |l: Loc, is_a: bool, partner: usize| {
            let ring = &pieces[l.0].border[l.1];
            let n = ring.len();
            let points: Vec<DVec2> = (0..=count).map(|i| ring[(l.2 + i) % n]).collect();
            // Each segment measured on its own face (the next border point belongs to the
            // next face, placed within the unfolding's tolerance): the 3D edge length.
            let length = (0..count)
                .map(|i| {
                    let j = (l.2 + i) % n;
                    let f = pieces[l.0].border_faces[l.1][j];
                    let c = &flat.face_2d[f];
                    match c.iter().position(|q| *q == ring[j]) {
                        Some(k) => c[k].distance(c[(k + 1) % c.len()]),
                        None => ring[j].distance(ring[(j + 1) % n]),
                    }
                })
                .sum();
            let mesh = &flat.surface.mesh;
            let length_3d = (0..count)
                .map(|i| {
                    let e = pieces[l.0].border_edges[l.1][(l.2 + i) % n];
                    flat.topology.edges.get(e).map_or(0.0, |e| {
                        mesh.vertices[e.verts[0]].distance(mesh.vertices[e.verts[1]])
                    })
                })
                .sum();
            SeamSide {
                id,
                is_a,
                partner,
                ring: l.1,
                first: l.2,
                count,
                points,
                length,
                length_3d,
                notches: Vec::new(),
                tab: false,
                split: false,
            }
        };
        let sa = side(a, true, pieces[b.0].id);
        let sb = side(b, false, pieces[a.0].id);
        pieces[a.0].seams.push(sa);
        pieces[b.0].seams.push(sb);
    }
}

/// Both sides of every seam of these pieces, as (piece index, seam index) of side A and of
/// side B, in seam order. A side without its partner is left out.
pub(super) fn pairs(pieces: &[Piece]) -> Vec<[(usize, usize); 2]> {
    let mut a: Vec<(usize, (usize, usize))> = Vec::new();
    let mut b: HashMap<usize, (usize, usize)> = HashMap::new();
    for (pi, p) in pieces.iter().enumerate() {
        for (si, s) in p.seams.iter().enumerate() {
            if s.is_a {
                a.push((s.id, (pi, si)));
            } else {
                b.insert(s.id, (pi, si));
            }
        }
    }
    a.sort_by_key(|x| x.0);
    a.into_iter()
        .filter_map(|(id, sa)| b.get(&id).map(|&sb| [sa, sb]))
        .collect()
}

/// Places the notches of every seam found by [`find`] and writes its id along both sides.
/// `by_arc`: put side B's notches at the same fraction of the whole side as side A's (chains
/// simplified by [`super::simplify`], whose two sides may differ in length by a little);
/// otherwise at the same fraction of the same mesh edge.
pub(super) fn place(flat: &Flat, pieces: &mut [Piece], opts: &PatternOptions, by_arc: bool) {
    for [(pa, ia), (pb, ib)] in pairs(pieces) {
        if let Some(spacing) = opts.notches {
            let (sa, sb) = (&pieces[pa].seams[ia], &pieces[pb].seams[ib]);
            let at_a = notch_positions(sa.length, spacing);
            let count = sa.count;
            let at_b: Vec<f64> = if by_arc {
                let (la, lb) = (polyline_length(&sa.points), polyline_length(&sb.points));
                at_a.iter()
                    .rev()
                    .map(|&s| if la > 0.0 { (1.0 - s / la) * lb } else { 0.0 })
                    .collect()
            } else {
                // Side B runs the chain backwards, segment for segment (each segment is one
                // mesh edge); a notch goes at the same fraction of the same edge on both
                // sides, which holds even where the two flat copies differ by the
                // unfolding's tolerance.
                at_a.iter()
                    .rev()
                    .map(|&s| {
                        let (k, t) = segment_at(&sa.points, s);
                        arc_at(&sb.points, count - 1 - k, 1.0 - t)
                    })
                    .collect()
            };
            pieces[pa].seams[ia].notches = at_a;
            pieces[pb].seams[ib].notches = at_b;
        }
        for (pi, si) in [(pa, ia), (pb, ib)] {
            let p = &pieces[pi];
            if let Some(m) = id_mark(flat, p, &p.seams[si]) {
                pieces[pi].marks.push(m);
            }
        }
    }
}

/// Largest difference between the two sides of a seam, or between a side and the seam's 3D
/// length, relative to the 3D length (issue 20): paper 0.2 %, metal 0.1 % (a blank must close
/// within a plotter's accuracy), fabric 1 % (sewing takes it up as ease).
pub fn seam_tolerance(kind: MaterialKind) -> f64 {
    match kind {
        MaterialKind::Paper => 2e-3,
        MaterialKind::Metal => 1e-3,
        MaterialKind::Fabric => 1e-2,
    }
}

/// Seams of `pieces` over the material's [`seam_tolerance`]: (side A's piece name, message).
/// The two sides are compared with each other and with the 3D length; a simplified seam
/// (chords of a zig-zag, [`super::simplify`]) may be shorter than the 3D length it stands for.
pub fn seam_mismatches(pieces: &[Piece], kind: MaterialKind) -> Vec<(String, String)> {
    let tol = seam_tolerance(kind);
    let mut out = Vec::new();
    for [(pa, ia), (pb, ib)] in pairs(pieces) {
        let (a, b) = (&pieces[pa].seams[ia], &pieces[pb].seams[ib]);
        let l3 = a.length_3d;
        // A seam of a developed metal piece is shorter than in 3D by the bends it reaches,
        // and its two sides by different bends (`develop`): not a mismatch.
        let developed = |p: &Piece| p.development.as_ref().is_some_and(|d| d.changed());
        if l3.is_nan() || l3 <= 0.0 || a.split || developed(&pieces[pa]) || developed(&pieces[pb]) {
            continue;
        }
        let simplified = pieces[pa].simplified.is_some() || pieces[pb].simplified.is_some();
        let off = |x: f64| {
            if simplified {
                (x - l3).max(0.0)
            } else {
                (x - l3).abs()
            }
        };
        let worst = (a.length - b.length)
            .abs()
            .max(off(a.length))
            .max(off(b.length));
        if worst > tol * l3 {
            out.push((
                pieces[pa].name.clone(),
                format!(
                    "seam {} between pieces {} and {}: its sides are {:.2} and {:.2} mm long flat for {:.2} mm in 3D ({:.2} % off, over the {} tolerance of {} %); tabs and notches will not line up",
                    a.id,
                    pieces[pa].name,
                    pieces[pb].name,
                    a.length,
                    b.length,
                    l3,
                    100.0 * worst / l3,
                    kind,
                    100.0 * tol
                ),
            ));
        }
    }
    out
}

/// Length of an open polyline (mm).
pub fn polyline_length(points: &[DVec2]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// Arc lengths of the notches along a seam of length `len` from side A's start.
pub fn notch_positions(len: f64, spacing: f64) -> Vec<f64> {
    if len.is_nan() || len < 5.0 || spacing.is_nan() || spacing <= 0.0 {
        return Vec::new();
    }
    let mut at: Vec<f64> = Vec::new();
    let mut s = spacing;
    while s < len - 0.25 * spacing {
        at.push(s);
        s += spacing;
    }
    if at.is_empty() {
        at.push(len / 3.0);
    }
    let d = 3f64.min(0.1 * len);
    // The extra notch goes after the first, unless the two would then sit where they sit with
    // the seam turned end for end (len = 2 × first + d); then before it.
    if at.len() == 1 && (2.0 * at[0] + d - len).abs() < 1.0 {
        at.insert(0, at[0] - d);
    } else {
        at.insert(1, at[0] + d);
    }
    at
}

/// The seam id written along the longest segment of a side.
fn id_mark(flat: &Flat, p: &Piece, s: &SeamSide) -> Option<EdgeMark> {
    let n = p.border[s.ring].len();
    let k = (0..s.count).map(|i| (s.first + i) % n).max_by(|&i, &j| {
        let ring = &p.border[s.ring];
        let li = ring[i].distance(ring[(i + 1) % n]);
        let lj = ring[j].distance(ring[(j + 1) % n]);
        li.total_cmp(&lj).then(j.cmp(&i))
    })?;
    let (a, b) = (p.border[s.ring][k], p.border[s.ring][(k + 1) % n]);
    let f = p.border_faces[s.ring][k];
    let face_depth = 2.0 * flat.surface.mesh.face_area(f) / a.distance(b).max(f64::MIN_POSITIVE);
    let id = s.id.to_string();
    let face_text = || edge_text(&id, a, b, face_depth, 3.0);
    let text = if p.simplified.is_some() {
        // A simplified side's segment may stand for many mesh edges, so its first face says
        // little about the room beside it: the room is measured in the piece itself, and the
        // text made smaller until it lies inside the piece.
        let room = room_inward(p, s.ring, k).max(face_depth);
        std::iter::successors(Some(room), |d| Some(d * 0.7))
            .take(8)
            .map(|d| edge_text(&id, a, b, d, 3.0))
            .find(|t| t.points().all(|q| polygon::contains_rings(&p.border, q)))
            .unwrap_or_else(face_text)
    } else {
        face_text()
    };
    Some(EdgeMark {
        id: s.id,
        edge: p.border_edges[s.ring][k],
        a,
        b,
        text,
    })
}

/// How far the piece reaches inward (to the left) from border segment `k` of ring `ring`:
/// the least distance, from nine points along the segment's middle, to the first other border
/// segment or fold line met going straight in.
fn room_inward(p: &Piece, ring: usize, k: usize) -> f64 {
    let r = &p.border[ring];
    let (a, b) = (r[k], r[(k + 1) % r.len()]);
    let len = a.distance(b);
    if len.is_nan() || len <= 0.0 {
        return 0.0;
    }
    let inward = ((b - a) / len).perp();
    let mut obstacles: Vec<(DVec2, DVec2)> = Vec::new();
    for (ri, rr) in p.border.iter().enumerate() {
        for j in 0..rr.len() {
            if ri != ring || j != k {
                obstacles.push((rr[j], rr[(j + 1) % rr.len()]));
            }
        }
    }
    obstacles.extend(p.folds.iter().filter(|f| !f.tab).map(|f| (f.a, f.b)));
    let mut room = f64::INFINITY;
    for i in 1..=9 {
        let q = a.lerp(b, 0.1 * i as f64);
        for &(c, d) in &obstacles {
            // q + t·inward = c + u·(d − c), t > 0, u in [0, 1].
            let e = d - c;
            let den = inward.perp_dot(e);
            if den.abs() < 1e-12 {
                continue;
            }
            let w = c - q;
            let t = w.perp_dot(e) / den;
            let u = w.perp_dot(inward) / den;
            if t > 1e-9 && (-1e-12..=1.0 + 1e-12).contains(&u) {
                room = room.min(t);
            }
        }
    }
    if room.is_finite() {
        room
    } else {
        0.0
    }
}

/// Label and grain line of a piece whose seams are known (bend notes are written once the
/// folds are final, by [`super::legible`]).
pub(super) fn finish(p: &mut Piece, opts: &PatternOptions) {
    let (label, label_r) = label(p, side_up(opts.material), opts.max_label_height);
    p.label = label;
    if opts.grain {
        let (dir, strokes) = grain_line(p, label_r);
        p.grain = Some(dir.y.atan2(dir.x));
        p.grain_line = strokes;
    }
}

/// Which side of the material the label says faces up.
pub(super) fn side_up(material: MaterialKind) -> &'static str {
    match material {
        MaterialKind::Fabric => "RIGHT SIDE UP",
        _ => "OUTSIDE UP",
    }
}

/// Notch strokes, once the outline is final: a slit from the cut line into the piece on
/// fabric (`allowance` mm outside the border), a tick drawn inward from the border otherwise.
pub(super) fn notch_strokes(p: &mut Piece, opts: &PatternOptions) {
    let cut = opts.material == MaterialKind::Fabric;
    let mut notches = Vec::new();
    for s in &p.seams {
        for &at in &s.notches {
            let Some((q, dir)) = point_at(&s.points, at) else {
                continue;
            };
            let inward = dir.perp();
            let stroke = if cut && opts.allowance > 0.0 {
                let a = opts.allowance;
                let depth = 3f64.min(0.5 * a);
                vec![q - inward * a, q - inward * (a - depth)]
            } else if cut {
                vec![q, q + inward * 2.0]
            } else {
                vec![q, q + inward * 2.5]
            };
            notches.push(Notch {
                seam: s.id,
                at: q,
                stroke,
                cut,
            });
        }
    }
    p.notches = notches;
}

/// Segment index and fraction along it of arc length `s` on a polyline.
pub fn segment_at(points: &[DVec2], s: f64) -> (usize, f64) {
    let mut left = s;
    let n = points.len().saturating_sub(1);
    for (k, w) in points.windows(2).enumerate() {
        let l = w[0].distance(w[1]);
        if left <= l || k + 1 == n {
            return (
                k,
                if l > 0.0 {
                    (left / l).clamp(0.0, 1.0)
                } else {
                    0.0
                },
            );
        }
        left -= l;
    }
    (0, 0.0)
}

/// Arc length of the point at fraction `t` of segment `k` of a polyline.
pub fn arc_at(points: &[DVec2], k: usize, t: f64) -> f64 {
    let before: f64 = points.windows(2).take(k).map(|w| w[0].distance(w[1])).sum();
    let l = points.get(k + 1).map_or(0.0, |b| points[k].distance(*b));
    before + t * l
}

/// The point at arc length `s` along a polyline and the direction of its segment there.
pub fn point_at(points: &[DVec2], s: f64) -> Option<(DVec2, DVec2)> {
    let (k, t) = segment_at(points, s);
    let (a, b) = (*points.get(k)?, *points.get(k + 1)?);
    Some((a.lerp(b, t), (b - a).try_normalize()?))
}

/// Strokes of `text` set along the edge `a → b` (interior on its left), inside the face.
pub fn edge_text(text: &str, a: DVec2, b: DVec2, depth: f64, max_h: f64) -> Text {
    let len = a.distance(b);
    if len <= 0.0 {
        return Text::default();
    }
    let d = (b - a) / len;
    let inward = d.perp();
    let mut h = max_h.min(0.3 * len).min(0.35 * depth);
    let w1 = font::text_width(text, 1.0);
    if w1 * h > 0.8 * len {
        h = 0.8 * len / w1;
    }
    if h.is_nan() || h <= 0.0 {
        return Text::default();
    }
    let w = w1 * h;
    let gap = 0.25 * h;
    // Read left to right: run along +x (or +y for vertical edges).
    let upright = d.x > 1e-9 || (d.x.abs() <= 1e-9 && d.y > 0.0);
    let (r, base) = if upright {
        (d, 0.5 * (a + b) - d * (0.5 * w) + inward * gap)
    } else {
        (-d, 0.5 * (a + b) + d * (0.5 * w) + inward * (gap + h))
    };
    let up = r.perp();
    let (strokes, _) = font::text_strokes(text, h);
    Text {
        strokes: strokes
            .into_iter()
            .map(|s| s.into_iter().map(|p| base + r * p.x + up * p.y).collect())
            .collect(),
        dir: Some(r),
    }
}

/// The label: `name` over `#id side`, centred on the border's pole of inaccessibility. Returns
/// it and the radius of the circle it fits in (0 when there is no room).
fn label(p: &Piece, side: &str, max_h: f64) -> (Text, f64) {
    let Some((center, r)) = polygon::pole(&p.border, 0.05 * max_h.max(0.1)) else {
        return (Text::default(), 0.0);
    };
    let line1 = p.name.clone();
    let line2 = format!("#{} {side}", p.id);
    let block = |h: f64| {
        let w = font::text_width(&line1, h).max(font::text_width(&line2, 0.6 * h));
        (w, 2.0 * h)
    };
    // Two lines when they can be at least 1.5 mm high, else the name alone.
    let (w1, _) = block(1.0);
    let h2 = (1.8 * r / (w1 * w1 + 4.0).sqrt()).min(max_h);
    if h2 >= 1.5 {
        let (w, hh) = block(h2);
        let strokes = label_block(&line1, Some(&line2), center, h2);
        return (Text { strokes, dir: None }, 0.5 * (w * w + hh * hh).sqrt());
    }
    let k = font::text_width(&line1, 1.0);
    let h = (1.8 * r / (k * k + 1.0).sqrt()).min(max_h);
    if h.is_nan() || h <= 0.0 {
        return (Text::default(), 0.0);
    }
    let w = font::text_width(&line1, h);
    let strokes = label_block(&line1, None, center, h);
    (Text { strokes, dir: None }, 0.5 * (w * w + h * h).sqrt())
}

/// The strokes of a label block at height `h` round `center`: with a second line, line 1 (`h`
/// high) sits on the centre, 0.4 h above line 2 (0.6 h high), a block 2 h high; alone, line 1
/// is centred on it. Linear in `center` and `h`.
pub(super) fn label_block(
    line1: &str,
    line2: Option<&str>,
    center: DVec2,
    h: f64,
) -> Vec<Vec<DVec2>> {
    let mut strokes = Vec::new();
    let mut put = |words: &str, h: f64, o: DVec2| {
        let (s, _) = font::text_strokes(words, h);
        strokes.extend(
            s.into_iter()
                .map(|s| s.into_iter().map(|q| q + o).collect()),
        );
    };
    match line2 {
        Some(line2) => {
            let wa = font::text_width(line1, h);
            let wb = font::text_width(line2, 0.6 * h);
            put(line1, h, center + DVec2::new(-0.5 * wa, 0.0));
            put(line2, 0.6 * h, center + DVec2::new(-0.5 * wb, -h));
        }
        None => {
            let w = font::text_width(line1, h);
            put(line1, h, center - DVec2::new(0.5 * w, 0.5 * h));
        }
    }
    strokes
}

/// Grain direction (unit) and the arrow: the longest chord along it that keeps `label_r + 2`
/// mm from the label's centre, 70 % of it, arrowheads at both ends.
fn grain_line(p: &Piece, label_r: f64) -> (DVec2, Vec<Vec<DVec2>>) {
    let pts: Vec<DVec2> = p.border.first().cloned().unwrap_or_default();
    let angle = polygon::min_area_rect_angle(&pts);
    // min_area_rect_angle turns the piece so that its long side lies along x: the long side
    // is along the direction that rotation maps onto +x.
    let dir = DVec2::from_angle(-angle);
    let Some((center, _)) = polygon::pole(&p.border, 0.5) else {
        return (dir, Vec::new());
    };
    let Some((lo, hi)) = polygon::bounds(pts.iter().copied()) else {
        return (dir, Vec::new());
    };
    let extent = (hi - lo).length();
    let normal = dir.perp();
    let clear = label_r + 2.0;
    let mut best: Option<(f64, f64, f64)> = None; // (length, start, offset)
    for i in 0..=80 {
        let off = (i as f64 / 80.0 - 0.5) * extent;
        let origin = center + normal * off;
        for (t0, t1) in polygon::line_intervals(&p.border, origin, dir) {
            // Keep clear of the label: cut the interval where it passes within `clear`.
            let mut parts = vec![(t0, t1)];
            if off.abs() < clear {
                let half = (clear * clear - off * off).sqrt();
                parts = vec![(t0, t1.min(-half)), (t0.max(half), t1)];
            }
            for (a, b) in parts {
                if b - a > best.map_or(0.0, |x| x.0) {
                    best = Some((b - a, a, off));
                }
            }
        }
    }
    let Some((len, t0, off)) = best else {
        return (dir, Vec::new());
    };
    let l = 0.7 * len;
    if l < 10.0 {
        return (dir, Vec::new());
    }
    let origin = center + normal * off;
    let a = origin + dir * (t0 + 0.15 * len);
    let b = a + dir * l;
    let head = 4f64.min(0.15 * l);
    let wing = |tip: DVec2, back: DVec2| {
        let r1 = DVec2::from_angle(0.45).rotate(back);
        let r2 = DVec2::from_angle(-0.45).rotate(back);
        vec![tip + r1 * head, tip, tip + r2 * head]
    };
    (dir, vec![vec![a, b], wing(a, dir), wing(b, -dir)])
}

#[cfg(test)]
mod notch_tests {
    use super::notch_positions;

    /// Turned end for end, a seam's notches never land on themselves (so the two sides cannot
    /// be sewn or glued the wrong way round), at any length and spacing; all lie on the seam.
    #[test]
    fn notches_are_never_symmetric() {
        for spacing in [10.0, 25.0, 40.0] {
            for k in 500..40_000 {
                let len = k as f64 * 0.01;
                let at = notch_positions(len, spacing);
                assert!(at.len() >= 2, "{len} / {spacing}: {at:?}");
                assert!(at.iter().all(|&s| s > 0.0 && s < len), "{len}: {at:?}");
                let n = at.len();
                let turned = (0..n).any(|i| (at[i] - (len - at[n - 1 - i])).abs() > 0.5);
                assert!(turned, "{len} / {spacing}: {at:?}");
            }
        }
    }
}
