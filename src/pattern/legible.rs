//! Legible finishing (issue 20, item 10): every text on a piece — seam ids, bend notes, the
//! label — is placed so that its box overlaps no other text and no stroke of another kind
//! (cut outline, the border, fold lines, tab folds, notches, the sewing line, the grain arrow).
//! A text that collides where it would go is moved, then shrunk down to [`MIN_TEXT_MM`], then
//! left out with a [`LeftOut`] record that the toolpath stage turns into a `text-left-out`
//! warning naming the piece and the text.
//!
//! **Boxes.** A text set along a line (`dir` given) keeps its orientation on the piece: the
//! toolpath stage at most turns it half a turn about its centre to read upright, which maps
//! its box onto itself, so its box is the smallest rectangle round its strokes along `dir`
//! and across it. The label (`dir` none) is turned on the sheet about the centre of its
//! bounding box to read along the sheet's x axis whatever rotation the nest chose, so what it
//! may cover is the disc round that centre through its farthest stroke point: the label is
//! tested as that disc ([`Footprint`]).
//!
//! **Candidates**, tried in order until one lies inside the piece's border and clear of every
//! stroke and every text placed before it, by a tenth of its height:
//! 1. where it went before this step: a seam id where [`super::marks`] put it when it is at
//!    least [`MIN_TEXT_MM`] high there, the label where marks put it (so a piece without
//!    collisions keeps them as they were), a bend note at the middle of its line on either
//!    side, as large as the line allows up to the largest mark height, when that is at least
//!    [`MIN_TEXT_MM`] (a crease of a dense mesh, a few mm long, holds only a note too small to
//!    read: it is left out, its angle being in report.json);
//! 2. a seam id along each segment of its seam side, its own (the longest) first, then along
//!    chords of the side over runs of segments that stay within a quarter of the floor of
//!    the chord (on a saw-tooth seam of a dense mesh each segment holds only a text too small
//!    to read, which is where marks put it); a bend note along its line on either side: at each
//!    size, at the standard gap (a quarter of the height) then 1¼ and 2½ heights further off,
//!    sliding from the middle of the segment towards its ends; a text set along a line is
//!    never turned off it (a seam id or a bend note away from its line says nothing);
//! 3. the label at the point of the piece farthest from every stroke and every text already
//!    placed (a best-first search like polylabel's, on that clearance), as large as fits in
//!    90 % of that clearance (as before, in the inscribed circle) up to its largest height:
//!    its two lines, else its name alone; then the same in the piece's margin, the part of
//!    the cut outline outside its border (a glue tab, the seam allowance), still inside the
//!    outline. A textured piece (printed faces) tries its margin first, so that the label
//!    goes on a tab rather than over the print;
//! 4. sizes from the text's natural height down by a fifth at a time to [`MIN_TEXT_MM`]. A
//!    seam id that goes nowhere at that height or more (a small model, a seam shorter than
//!    the text) stays where marks put it under the floor, else moves at that height; the
//!    toolpath stage warns of it. Seam ids are placed in three passes ([`seam_ids`]): those
//!    legible where they were, those moved to a legible height, the rest, so that a legible
//!    text never gives way to one too small to read.
//!
//! Texts are placed seam ids first (each pass in seam order), then bend notes (in fold order),
//! then the label, which has the whole piece to choose from. Everything is deterministic: fixed
//! candidate orders, ties to the first.
//!
//! **Bounded time.** The strokes of a piece (thousands of fold segments on a fine strip) go
//! into a uniform grid of at most 128 × 128 cells, each segment into the cells it passes
//! through; a candidate tests only the segments and texts listed in the cells its box covers,
//! and the inside test casts its ray through the cells of one row.
//!
//! Choices where the issue is silent: bend notes are written by this step, once the folds are
//! final (tab folds added, folds cut back to the outline), no longer kept inside the face
//! beside the bend (a strip's faces are thin triangles, which made its notes 1–2 mm high): the
//! collision test keeps them off the other lines; the label keeps its "turn to read upright"
//! (it is never set along a line to squeeze between folds).

use super::{FoldKind, PatternOptions, Piece, Text};
use crate::geom::grid::Grid;
use crate::geom::{font, polygon};
use glam::DVec2;

/// Smallest height of text (mm) a knife scores or a pen draws legibly: texts are not shrunk
/// below it to make room, and the toolpath stage warns of texts under it (`text-too-small`).
pub const MIN_TEXT_MM: f64 = 2.0;

/// Clearance round a text set along a line, as a fraction of its height.
const MARGIN: f64 = 0.1;
/// Each smaller size is this fraction of the one before.
const SHRINK: f64 = 0.8;
/// Where along its segment a text is tried: fractions of the free length, middle first.
const SLIDE: [f64; 11] = [0.5, 0.4, 0.6, 0.3, 0.7, 0.2, 0.8, 0.1, 0.9, 0.0, 1.0];
/// Gaps between a text and its line tried, in heights.
const GAPS: [f64; 3] = [0.25, 1.25, 2.5];
/// At most this many segments of a seam side are tried (the longest), and as many chords.
const MAX_SEGMENTS: usize = 8;
/// How far (mm) a seam side may stray from a chord a seam id is written along: a quarter of
/// the smallest text, the gap the text keeps from its line.
const CHORD_BAND: f64 = 0.25 * MIN_TEXT_MM;
/// Points of a seam side a chord spans at most.
const MAX_CHORD_POINTS: usize = 64;

/// A text left off its piece: no place clear of the other texts and lines was found for it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LeftOut {
    /// `label`, `seam id` or `bend note`.
    pub what: &'static str,
    /// What it says.
    pub words: String,
}

/// What a text may cover on the sheet (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Footprint {
    /// Centre, unit axis `u` (the reading direction), half extents along `u` and across it.
    Box {
        c: DVec2,
        u: DVec2,
        hu: f64,
        hv: f64,
    },
    /// The label: every way it can be turned about `c`.
    Disc { c: DVec2, r: f64 },
}

impl Footprint {
    /// The footprint of a text's strokes; `None` for no text.
    pub fn of(t: &Text) -> Option<Footprint> {
        let mut pts = t.points().peekable();
        pts.peek()?;
        Some(match t.dir {
            Some(u) => {
                let v = u.perp();
                let (lo, hi) = polygon::bounds(t.points().map(|q| DVec2::new(q.dot(u), q.dot(v))))?;
                let m = 0.5 * (lo + hi);
                Footprint::Box {
                    c: u * m.x + v * m.y,
                    u,
                    hu: 0.5 * (hi.x - lo.x),
                    hv: 0.5 * (hi.y - lo.y),
                }
            }
            None => {
                let (lo, hi) = polygon::bounds(t.points())?;
                let c = 0.5 * (lo + hi);
                let r = t.points().map(|q| q.distance(c)).fold(0.0, f64::max);
                Footprint::Disc { c, r }
            }
        })
    }

    /// The same footprint grown by `m` on every side.
    fn grown(self, m: f64) -> Footprint {
        match self {
            Footprint::Box { c, u, hu, hv } => Footprint::Box {
                c,
                u,
                hu: hu + m,
                hv: hv + m,
            },
            Footprint::Disc { c, r } => Footprint::Disc { c, r: r + m },
        }
    }

    fn center(&self) -> DVec2 {
        match *self {
            Footprint::Box { c, .. } | Footprint::Disc { c, .. } => c,
        }
    }

    /// Axis-aligned bounds.
    fn bounds(&self) -> (DVec2, DVec2) {
        match *self {
            Footprint::Box { c, u, hu, hv } => {
                let e = (u * hu).abs() + (u.perp() * hv).abs();
                (c - e, c + e)
            }
            Footprint::Disc { c, r } => (c - DVec2::splat(r), c + DVec2::splat(r)),
        }
    }

    /// A point in the box's own frame (along `u`, across).
    fn local(c: DVec2, u: DVec2, q: DVec2) -> DVec2 {
        let d = q - c;
        DVec2::new(d.dot(u), d.dot(u.perp()))
    }

    /// Distance from `q` to the footprint (0 inside).
    fn distance(&self, q: DVec2) -> f64 {
        match *self {
            Footprint::Box { c, u, hu, hv } => {
                let l = Self::local(c, u, q);
                DVec2::new((l.x.abs() - hu).max(0.0), (l.y.abs() - hv).max(0.0)).length()
            }
            Footprint::Disc { c, r } => (q.distance(c) - r).max(0.0),
        }
    }

    /// Whether the segment `a`–`b` enters the open footprint.
    pub fn hits_segment(&self, a: DVec2, b: DVec2) -> bool {
        match *self {
            Footprint::Disc { c, r } => polygon::segment_distance(c, a, b) < r,
            Footprint::Box { c, u, hu, hv } => {
                let (a, b) = (Self::local(c, u, a), Self::local(c, u, b));
                // Liang–Barsky against the open box.
                let d = b - a;
                let (mut t0, mut t1) = (0.0f64, 1.0f64);
                for (p, q) in [
                    (-d.x, a.x + hu),
                    (d.x, hu - a.x),
                    (-d.y, a.y + hv),
                    (d.y, hv - a.y),
                ] {
                    if p == 0.0 {
                        if q <= 0.0 {
                            return false;
                        }
                    } else {
                        let r = q / p;
                        if p < 0.0 {
                            t0 = t0.max(r);
                        } else {
                            t1 = t1.min(r);
                        }
                    }
                }
                t0 < t1
            }
        }
    }

    /// Whether two open footprints overlap.
    pub fn overlaps(&self, o: &Footprint) -> bool {
        match (*self, *o) {
            (Footprint::Disc { c: c1, r: r1 }, Footprint::Disc { c: c2, r: r2 }) => {
                c1.distance(c2) < r1 + r2
            }
            (Footprint::Disc { c, r }, b @ Footprint::Box { .. })
            | (b @ Footprint::Box { .. }, Footprint::Disc { c, r }) => b.distance(c) < r,
            (
                Footprint::Box {
                    c: c1,
                    u: u1,
                    hu: a1,
                    hv: b1,
                },
                Footprint::Box {
                    c: c2,
                    u: u2,
                    hu: a2,
                    hv: b2,
                },
            ) => {
                // Separating axes: the two boxes' own.
                let d = c2 - c1;
                [u1, u1.perp(), u2, u2.perp()].into_iter().all(|n| {
                    let r1 = a1 * u1.dot(n).abs() + b1 * u1.perp().dot(n).abs();
                    let r2 = a2 * u2.dot(n).abs() + b2 * u2.perp().dot(n).abs();
                    d.dot(n).abs() < r1 + r2
                })
            }
        }
    }
}

/// Rings (an outer contour and its holes) with their segments in a grid, for a fast inside
/// test.
struct Rings {
    segments: Vec<(DVec2, DVec2)>,
    grid: Grid,
}

impl Rings {
    fn new(rings: &[Vec<DVec2>], lo: DVec2, hi: DVec2) -> Rings {
        let segments: Vec<(DVec2, DVec2)> = rings
            .iter()
            .flat_map(|r| (0..r.len()).map(move |k| (r[k], r[(k + 1) % r.len()])))
            .collect();
        let mut grid = Grid::new(lo, hi);
        for (k, s) in segments.iter().enumerate() {
            grid.insert_segment(s.0, s.1, k as u32);
        }
        Rings { segments, grid }
    }

    /// Whether `q` is inside (even-odd over the rings, as [`polygon::contains_rings`]): the
    /// crossings of a ray towards +x, counted on the segments listed in the grid cells it
    /// passes.
    fn contains(&self, q: DVec2, ids: &mut Vec<u32>) -> bool {
        if !self.grid.ray(q, ids) {
            return false;
        }
        let mut inside = false;
        for &k in ids.iter() {
            let (a, b) = self.segments[k as usize];
            if (a.y > q.y) != (b.y > q.y) {
                let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if q.x < x {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

/// Where a text may go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Within {
    /// Inside the border: on the surface itself.
    Border,
    /// Inside the cut outline but not the border: on a glue tab or in the seam allowance.
    Margin,
}

/// The strokes of a piece that texts keep clear of, and the texts placed so far.
struct Room {
    border: Rings,
    outline: Rings,
    segments: Vec<(DVec2, DVec2)>,
    grid: Grid,
    texts: Vec<Footprint>,
    text_grid: Grid,
    scratch: Vec<u32>,
}

impl Room {
    fn new(p: &Piece) -> Room {
        let mut segments = Vec::new();
        for rings in [&p.outline, &p.border, &p.seam_line] {
            for r in rings.iter() {
                for k in 0..r.len() {
                    segments.push((r[k], r[(k + 1) % r.len()]));
                }
            }
        }
        segments.extend(p.folds.iter().map(|f| (f.a, f.b)));
        for s in p.notches.iter().map(|n| &n.stroke).chain(&p.grain_line) {
            segments.extend(s.windows(2).map(|w| (w[0], w[1])));
        }
        let (lo, hi) = polygon::bounds(segments.iter().flat_map(|s| [s.0, s.1]))
            .unwrap_or((DVec2::ZERO, DVec2::ONE));
        let mut grid = Grid::new(lo, hi);
        for (k, s) in segments.iter().enumerate() {
            grid.insert_segment(s.0, s.1, k as u32);
        }
        Room {
            border: Rings::new(&p.border, lo, hi),
            outline: Rings::new(&p.outline, lo, hi),
            segments,
            grid,
            texts: Vec::new(),
            text_grid: Grid::new(lo, hi),
            scratch: Vec::new(),
        }
    }

    /// Whether `q` lies where a text may go.
    fn inside(&mut self, q: DVec2, within: Within) -> bool {
        let mut ids = std::mem::take(&mut self.scratch);
        let ok = match within {
            Within::Border => self.border.contains(q, &mut ids),
            Within::Margin => {
                self.outline.contains(q, &mut ids) && !self.border.contains(q, &mut ids)
            }
        };
        self.scratch = ids;
        ok
    }

    /// Whether `f` (already grown by its margin) lies inside the border, crossing no stroke
    /// and no text placed so far.
    fn clear(&mut self, f: &Footprint) -> bool {
        self.clear_within(f, Within::Border)
    }

    /// [`Self::clear`], inside the border or in the margin outside it.
    fn clear_within(&mut self, f: &Footprint, within: Within) -> bool {
        if !self.inside(f.center(), within) {
            return false;
        }
        let (lo, hi) = f.bounds();
        !self.grid.any(lo, hi, |k| {
            let (a, b) = self.segments[k as usize];
            f.hits_segment(a, b)
        }) && !self
            .text_grid
            .any(lo, hi, |k| f.overlaps(&self.texts[k as usize]))
    }

    /// Remembers a placed text.
    fn take(&mut self, f: Footprint) {
        let (lo, hi) = f.bounds();
        self.text_grid.insert_box(lo, hi, self.texts.len() as u32);
        self.texts.push(f);
    }

    /// How far `q` is from every stroke and placed text, up to `cap`; 0 where no text may go.
    fn clearance(&mut self, q: DVec2, cap: f64, within: Within) -> f64 {
        if !self.inside(q, within) {
            return 0.0;
        }
        // Boxes growing from 1/64 of `cap`: whatever is nearer than a box's half side meets
        // the box, so the first box holding something that near gives the distance.
        let mut ids = std::mem::take(&mut self.scratch);
        let mut r = cap / 64.0;
        let d = loop {
            r = (2.0 * r).min(cap);
            let (lo, hi) = (q - DVec2::splat(r), q + DVec2::splat(r));
            let mut d = cap;
            self.grid.query(lo, hi, &mut ids);
            for &k in &ids {
                let (a, b) = self.segments[k as usize];
                d = d.min(polygon::segment_distance(q, a, b));
            }
            self.text_grid.query(lo, hi, &mut ids);
            for &k in &ids {
                d = d.min(self.texts[k as usize].distance(q));
            }
            if d <= r || r >= cap || !r.is_finite() {
                break d;
            }
        };
        self.scratch = ids;
        d
    }
}

/// Text set at one height along the x axis, baseline y = 0, with the bounds of its strokes.
struct Set {
    strokes: Vec<Vec<DVec2>>,
    lo: DVec2,
    hi: DVec2,
}

impl Set {
    fn new(words: &str, h: f64) -> Option<Set> {
        let (strokes, _) = font::text_strokes(words, h);
        let (lo, hi) = polygon::bounds(strokes.iter().flatten().copied())?;
        Some(Set { strokes, lo, hi })
    }

    /// The text beside the line from `a` along unit `d`, its box's middle `s` mm along it and
    /// `gap` mm off it on the side `n` (a unit normal), reading upright: the footprint and the
    /// text.
    fn beside(&self, a: DVec2, d: DVec2, n: DVec2, s: f64, gap: f64) -> (Footprint, Text) {
        let r = if d.x > 1e-9 || (d.x.abs() <= 1e-9 && d.y > 0.0) {
            d
        } else {
            -d
        };
        let up = r.perp();
        let (w, h) = (self.hi.x - self.lo.x, self.hi.y - self.lo.y);
        let c = a + d * s + n * (gap + 0.5 * h);
        // Local box middle → c; local y grows along `up`, which is ±n.
        let mid = 0.5 * (self.lo + self.hi);
        let base = c - r * mid.x - up * mid.y;
        let text = Text {
            strokes: self
                .strokes
                .iter()
                .map(|st| st.iter().map(|q| base + r * q.x + up * q.y).collect())
                .collect(),
            dir: Some(r),
        };
        let f = Footprint::Box {
            c,
            u: r,
            hu: 0.5 * w,
            hv: 0.5 * h,
        };
        (f, text)
    }
}

/// The heights tried for a text whose natural height is `h0`: `h0`, then a fifth smaller each
/// time down to `floor` (which is tried last); only `h0` when it is not above that.
fn sizes(h0: f64, floor: f64) -> Vec<f64> {
    if !(h0.is_finite() && h0 > 0.0) {
        return Vec::new();
    }
    let mut out = vec![h0];
    if floor.is_nan() || floor >= h0 {
        return out;
    }
    let mut h = h0 * SHRINK;
    while h > floor + 1e-9 && out.len() < 8 {
        out.push(h);
        h *= SHRINK;
    }
    out.push(floor);
    out
}

/// A text to write along one of `lines` (each `(a, b, sides)`: the text goes on the left of
/// `a → b` for side +1, on the right for −1), at most `max_h` high and, if need be, as small
/// as `floor`: the first clear place, or `None`.
fn along(
    room: &mut Room,
    words: &str,
    lines: &[(DVec2, DVec2, &[f64])],
    max_h: f64,
    floor: f64,
) -> Option<(Footprint, Text)> {
    let w1 = font::text_width(words, 1.0);
    let longest = lines
        .iter()
        .map(|(a, b, _)| a.distance(*b))
        .fold(0.0, f64::max);
    if w1.is_nan() || w1 <= 0.0 {
        return None;
    }
    let h0 = max_h.min(0.8 * longest / w1);
    for h in sizes(h0, floor) {
        let Some(set) = Set::new(words, h) else {
            continue;
        };
        let w = set.hi.x - set.lo.x;
        for &(a, b, sides) in lines {
            let len = a.distance(b);
            if w > 0.9 * len || len <= 0.0 {
                continue;
            }
            let d = (b - a) / len;
            for gap in GAPS {
                for &side in sides {
                    let n = d.perp() * side;
                    for f in SLIDE {
                        let s = 0.5 * w + f * (len - w);
                        let (fp, text) = set.beside(a, d, n, s, gap * h);
                        if room.clear(&fp.grown(MARGIN * h)) {
                            return Some((fp, text));
                        }
                    }
                }
            }
        }
    }
    None
}

/// [`along`] at [`MIN_TEXT_MM`] or more only: where no line holds the text at the floor,
/// `along` offers it at the size the longest line allows, under the floor.
fn legibly_along(
    room: &mut Room,
    words: &str,
    lines: &[(DVec2, DVec2, &[f64])],
    max_h: f64,
) -> Option<(Footprint, Text)> {
    along(room, words, lines, max_h, MIN_TEXT_MM).filter(|(_, t)| text_height(t) >= MIN_TEXT_MM)
}

/// Places every text of a piece whose strokes are final (see the module doc); writes the bend
/// notes when `opts.bend_notes`. `textured`: the piece's faces are printed with a texture.
pub(super) fn place(p: &mut Piece, opts: &PatternOptions, textured: bool) {
    let mut room = Room::new(p);
    let mut left_out = Vec::new();

    seam_ids(p, opts, &mut room, &mut left_out);
    p.marks.retain(|m| !m.text.is_empty());

    if opts.bend_notes {
        bend_notes(p, opts, &mut room, &mut left_out);
    }
    label(p, opts, textured, &mut room, &mut left_out);
    p.left_out = left_out;
}

/// The seam ids, in three passes so that legible text comes first: those legible where marks
/// put them stay there; those under [`MIN_TEXT_MM`] there (or no longer clear) go along their
/// seam side at that height or more ([`id_lines`]); last, those for which that found no place
/// stay where they were under the floor (a small model), else move at that height, else are
/// left out (in seam order).
fn seam_ids(p: &mut Piece, opts: &PatternOptions, room: &mut Room, left_out: &mut Vec<LeftOut>) {
    let was: Vec<Option<(Footprint, f64)>> = p
        .marks
        .iter()
        .map(|m| Footprint::of(&m.text).map(|f| (f, text_height(&m.text))))
        .collect();
    let mut moved = Vec::new();
    for (mi, w) in was.iter().enumerate() {
        match *w {
            Some((f, h)) if h >= MIN_TEXT_MM && room.clear(&f.grown(MARGIN * h)) => room.take(f),
            _ => moved.push(mi),
        }
    }
    let mut last = Vec::new();
    for mi in moved {
        let lines = id_lines(p, p.marks[mi].id, p.marks[mi].a, p.marks[mi].b);
        let words = p.marks[mi].id.to_string();
        match legibly_along(room, &words, &lines, opts.max_mark_height) {
            Some((f, text)) => {
                room.take(f);
                p.marks[mi].text = text;
            }
            None => last.push((mi, lines, words)),
        }
    }
    for (mi, lines, words) in last {
        let placed = was[mi]
            .filter(|&(_, h)| h < MIN_TEXT_MM)
            .and_then(|(f, h)| {
                if room.clear(&f.grown(MARGIN * h)) {
                    return Some((f, p.marks[mi].text.clone()));
                }
                along(room, &words, &lines, h, h)
            });
        match placed {
            Some((f, text)) => {
                room.take(f);
                p.marks[mi].text = text;
            }
            None => {
                p.marks[mi].text = Text::default();
                left_out.push(LeftOut {
                    what: "seam id",
                    words,
                });
            }
        }
    }
}

/// `90° UP` (valley) or `90° DOWN` (mountain) beside each bend line (not the tab folds): at
/// the middle of the line on either side, as large as the line allows (up to the largest mark
/// height), else the first clear place along it; `note_folds` says which line each is beside.
fn bend_notes(p: &mut Piece, opts: &PatternOptions, room: &mut Room, left_out: &mut Vec<LeftOut>) {
    let (mut notes, mut note_folds) = (Vec::new(), Vec::new());
    for (i, f) in p.folds.iter().enumerate() {
        if f.tab {
            continue;
        }
        let way = match f.kind {
            FoldKind::Mountain => "DOWN",
            FoldKind::Valley => "UP",
        };
        let words = format!("{:.0}° {way}", f.angle.to_degrees());
        // At the middle of the line, on either side, as large as the line allows, when that
        // is legible.
        let first = [(f.a, f.b), (f.b, f.a)].into_iter().find_map(|(a, b)| {
            let t = super::marks::edge_text(&words, a, b, f64::INFINITY, opts.max_mark_height);
            let fp = Footprint::of(&t)?;
            let h = text_height(&t);
            (h >= MIN_TEXT_MM && room.clear(&fp.grown(MARGIN * h))).then_some((fp, t))
        });
        let lines: [(DVec2, DVec2, &[f64]); 1] = [(f.a, f.b, &[1.0, -1.0])];
        let placed = first.or_else(|| legibly_along(room, &words, &lines, opts.max_mark_height));
        match placed {
            Some((fp, t)) => {
                room.take(fp);
                notes.push(t);
                note_folds.push(i);
            }
            None => left_out.push(LeftOut {
                what: "bend note",
                words,
            }),
        }
    }
    p.notes = notes;
    p.note_folds = note_folds;
}

/// The label where marks put it if it is clear, else at the clearest point of the piece, as
/// large as fits there: two lines, else the name alone; else at the clearest point of its
/// margin (glue tabs, seam allowance), where the outline leaves room; else left out. On a
/// textured piece, whose faces are printed, the margin comes first: the label goes on a tab
/// if it fits there, not over the print.
fn label(
    p: &mut Piece,
    opts: &PatternOptions,
    textured: bool,
    room: &mut Room,
    left_out: &mut Vec<LeftOut>,
) {
    let side = super::marks::side_up(opts.material);
    let words = format!("{} #{} {side}", p.name, p.id);
    let Some(f) = Footprint::of(&p.label) else {
        return;
    };
    let natural = text_height(&p.label);
    let floor = MIN_TEXT_MM.min(natural);
    let line2 = format!("#{} {side}", p.id);
    let search = |p: &mut Piece, room: &mut Room, within: Within| {
        for line2 in [Some(line2.as_str()), None] {
            if let Some(text) = free_label(&p.name, line2, opts, floor, room, within) {
                p.label = text;
                return true;
            }
        }
        false
    };
    if textured && search(p, room, Within::Margin) {
        return;
    }
    if room.clear(&f.grown(MARGIN * natural)) {
        room.take(f);
        return;
    }
    if search(p, room, Within::Border) || (!textured && search(p, room, Within::Margin)) {
        return;
    }
    p.label = Text::default();
    left_out.push(LeftOut {
        what: "label",
        words,
    });
}

/// A label of `line1` (over `line2`) at the clearest point `within` the piece, as large as
/// fits in 90 % of the clear disc there (as [`super::marks`] sizes it in the inscribed circle),
/// at most the largest label height; `None` under `floor`. The label is taken into the room.
fn free_label(
    line1: &str,
    line2: Option<&str>,
    opts: &PatternOptions,
    floor: f64,
    room: &mut Room,
    within: Within,
) -> Option<Text> {
    // The block at height 1 round the middle of its bounds: radius per mm of height.
    let unit = super::marks::label_block(line1, line2, DVec2::ZERO, 1.0);
    let (lo, hi) = polygon::bounds(unit.iter().flatten().copied())?;
    let mid = 0.5 * (lo + hi);
    let r1 = unit
        .iter()
        .flatten()
        .map(|q| q.distance(mid))
        .fold(0.0, f64::max);
    if r1.is_nan() || r1 <= 0.0 {
        return None;
    }
    let max_h = opts.max_label_height.max(floor);
    let cap = r1 * max_h / 0.9;
    let (c, clear) = clearest(room, cap, 0.05 * max_h.max(0.1), within)?;
    let h = (0.9 * clear / r1).min(max_h);
    if h < floor || h <= 0.0 {
        return None;
    }
    let strokes = super::marks::label_block(line1, line2, c - mid * h, h);
    let text = Text { strokes, dir: None };
    room.take(Footprint::of(&text)?);
    Some(text)
}

/// The point `within` the piece farthest from every stroke and placed text (up to `cap`), to
/// within `precision` mm: polylabel's best-first search over square cells on that clearance
/// (1-Lipschitz, so a cell cannot beat its centre's value plus its half diagonal).
fn clearest(room: &mut Room, cap: f64, precision: f64, within: Within) -> Option<(DVec2, f64)> {
    use crate::geom::heap::Lowest;
    use std::collections::BinaryHeap;
    let rings = match within {
        Within::Border => &room.border,
        Within::Margin => &room.outline,
    };
    let (lo, hi) = polygon::bounds(rings.segments.iter().flat_map(|s| [s.0, s.1]))?;
    let size = hi - lo;
    let cell = size.min_element().max(size.max_element() / 256.0);
    if !(cell.is_finite() && cell > 0.0 && cap > 0.0) {
        return None;
    }
    // Largest bound first (the smallest key of `Lowest` is its negation); among equals the
    // cell made first. Each cell carries its centre, half side and clearance.
    let mut made = 0usize;
    let mut make = |room: &mut Room, c: DVec2, h: f64| {
        let d = room.clearance(c, cap, within);
        made += 1;
        Lowest {
            key: -(d + h * std::f64::consts::SQRT_2).min(cap),
            id: made,
            data: (c, h, d),
        }
    };
    let mut heap = BinaryHeap::new();
    let h = 0.5 * cell;
    let (nx, ny) = (
        ((size.x / cell).ceil() as usize).clamp(1, 257),
        ((size.y / cell).ceil() as usize).clamp(1, 257),
    );
    for i in 0..nx {
        for j in 0..ny {
            let c = lo + DVec2::new((i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell);
            heap.push(make(room, c, h));
        }
    }
    let mut best: Option<(DVec2, f64)> = None;
    let mut steps = 0usize;
    while let Some(Lowest {
        key,
        data: (c, h, d),
        ..
    }) = heap.pop()
    {
        if best.is_none_or(|b| d > b.1) {
            best = Some((c, d));
        }
        let top = best.map_or(0.0, |b| b.1);
        if top >= cap {
            break;
        }
        if -key - top <= precision || steps > 20_000 {
            continue;
        }
        steps += 1;
        let h = 0.5 * h;
        for (dx, dy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            heap.push(make(room, c + DVec2::new(dx * h, dy * h), h));
        }
    }
    best.filter(|b| b.1 > 0.0)
}

/// Height of a text: its tallest stroke across its reading direction (as the toolpath stage
/// measures it), 0 for none.
/// The lines a seam id may be written along (see the module doc): the segment `a → b` marks
/// chose, the other segments of its seam side, longest first, then the chords of runs of
/// segments the side keeps within [`CHORD_BAND`] of (a seam of many short segments, whose
/// segments each hold only a text under [`MIN_TEXT_MM`]), longest first; [`MAX_SEGMENTS`]
/// of each at most.
fn id_lines(p: &Piece, id: usize, a: DVec2, b: DVec2) -> Vec<(DVec2, DVec2, &'static [f64])> {
    let mut lines: Vec<(DVec2, DVec2, &'static [f64])> = vec![(a, b, &[1.0])];
    let mut chords: Vec<(DVec2, DVec2)> = Vec::new();
    for s in p.seams.iter().filter(|s| s.id == id) {
        if !s.points.windows(2).any(|w| w[0] == a && w[1] == b) {
            continue;
        }
        let mut segs: Vec<(DVec2, DVec2)> = s
            .points
            .windows(2)
            .map(|w| (w[0], w[1]))
            .filter(|&(x, y)| (x, y) != (a, b))
            .collect();
        segs.sort_by(|x, y| y.0.distance(y.1).total_cmp(&x.0.distance(x.1)));
        segs.truncate(MAX_SEGMENTS - 1);
        lines.extend(segs.into_iter().map(|(x, y)| (x, y, &[1.0][..])));
        chords.extend(chords_of(&s.points, CHORD_BAND));
    }
    chords.sort_by(|x, y| y.0.distance(y.1).total_cmp(&x.0.distance(x.1)));
    chords.truncate(MAX_SEGMENTS);
    lines.extend(chords.into_iter().map(|(x, y)| (x, y, &[1.0][..])));
    lines
}

/// The chords of a polyline over runs of two segments or more whose inner points lie within
/// `band` of the chord and between its ends: from the first point, each as long as it can be
/// (at most [`MAX_CHORD_POINTS`] points), the next from where it ends.
fn chords_of(points: &[DVec2], band: f64) -> Vec<(DVec2, DVec2)> {
    let within = |i: usize, j: usize| {
        let (a, b) = (points[i], points[j]);
        let len = a.distance(b);
        if len.is_nan() || len <= 0.0 {
            return false;
        }
        let d = (b - a) / len;
        points[i + 1..j].iter().all(|&q| {
            let t = (q - a).dot(d);
            (0.0..=len).contains(&t) && (q - a).perp_dot(d).abs() <= band
        })
    };
    let mut out = Vec::new();
    let mut i = 0;
    while i + 2 < points.len() {
        let mut j = i + 1;
        while j + 1 < points.len() && j + 1 - i < MAX_CHORD_POINTS && within(i, j + 1) {
            j += 1;
        }
        if j >= i + 2 {
            out.push((points[i], points[j]));
        }
        i = j;
    }
    out
}

fn text_height(t: &Text) -> f64 {
    let n = t.dir.unwrap_or(DVec2::X).perp();
    t.strokes
        .iter()
        .filter_map(|s| polygon::bounds(s.iter().map(|q| DVec2::new(q.dot(n), 0.0))))
        .map(|(lo, hi)| hi.x - lo.x)
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_and_discs_overlap_as_drawn() {
        let b = Footprint::Box {
            c: DVec2::ZERO,
            u: DVec2::new(1.0, 1.0).normalize(),
            hu: 5.0,
            hv: 1.0,
        };
        // Along the diagonal the box reaches 5 mm, across it 1 mm.
        assert!(b.hits_segment(DVec2::new(3.0, -10.0), DVec2::new(3.0, 10.0)));
        assert!(!b.hits_segment(DVec2::new(-10.0, 2.0), DVec2::new(-1.0, 11.0)));
        let d = Footprint::Disc {
            c: DVec2::new(4.0, -4.0),
            r: 4.0,
        };
        // The disc's centre is 5.66 mm across the box's axis: 4.66 from its side.
        assert!(!d.overlaps(&b));
        assert!(d.grown(0.7).overlaps(&b));
        let b2 = Footprint::Box {
            c: DVec2::new(0.0, 2.6),
            u: DVec2::X,
            hu: 1.0,
            hv: 1.0,
        };
        assert!(b2.overlaps(&b) && b.overlaps(&b2));
        let b3 = Footprint::Box {
            c: DVec2::new(-2.0, 2.6),
            u: DVec2::X,
            hu: 0.5,
            hv: 0.5,
        };
        assert!(!b3.overlaps(&b));
    }

    /// The outline of a `w` × `h` mm rectangle from the origin, counter-clockwise.
    fn rectangle(w: f64, h: f64) -> Vec<DVec2> {
        vec![
            DVec2::ZERO,
            DVec2::new(w, 0.0),
            DVec2::new(w, h),
            DVec2::new(0.0, h),
        ]
    }

    /// A 40 × 16 mm strip with a fold every 1.5 mm: no room for its label anywhere (without the
    /// folds it would be 2.2 mm high, on two lines).
    fn crowded() -> Piece {
        let mut p = Piece::from_outline(1, "strip".into(), rectangle(40.0, 16.0));
        let opts = PatternOptions::default();
        super::super::marks::finish(&mut p, &opts);
        assert!(!p.label.is_empty());
        p.folds = (1..27)
            .map(|k| super::super::Fold {
                a: DVec2::new(1.5 * k as f64, 0.0),
                b: DVec2::new(1.5 * k as f64, 16.0),
                kind: FoldKind::Mountain,
                angle: 0.5,
                edge: k,
                tab: false,
            })
            .collect();
        p
    }

    #[test]
    fn a_label_with_no_clear_place_is_left_out_and_recorded() {
        let mut p = crowded();
        place(&mut p, &PatternOptions::default(), false);
        assert!(p.label.is_empty());
        assert_eq!(
            p.left_out,
            vec![LeftOut {
                what: "label",
                words: "strip #1 OUTSIDE UP".into()
            }]
        );
        // With a 12 mm margin along the bottom (a wide glue tab): the label goes there, the name
        // alone.
        let mut p = crowded();
        p.outline = vec![vec![
            DVec2::new(0.0, -12.0),
            DVec2::new(40.0, -12.0),
            DVec2::new(40.0, 16.0),
            DVec2::new(0.0, 16.0),
        ]];
        place(&mut p, &PatternOptions::default(), false);
        assert!(p.left_out.is_empty(), "{:?}", p.left_out);
        let Some(Footprint::Disc { c, r }) = Footprint::of(&p.label) else {
            panic!("a label")
        };
        assert!(c.y - r >= -12.0 && c.y + r <= 0.0, "{c} {r}");
        assert!(text_height(&p.label) >= MIN_TEXT_MM);
        // A textured piece takes the tab even when the face has room.
        let mut p = crowded();
        p.folds.clear();
        p.outline = vec![vec![
            DVec2::new(0.0, -12.0),
            DVec2::new(40.0, -12.0),
            DVec2::new(40.0, 16.0),
            DVec2::new(0.0, 16.0),
        ]];
        place(&mut p, &PatternOptions::default(), true);
        let Some(Footprint::Disc { c, .. }) = Footprint::of(&p.label) else {
            panic!("a label")
        };
        assert!(c.y < 0.0, "{c}");
        // Seven folds taken away: 12 mm free, a disc of 6 mm radius holds the name alone
        // 2.6 mm high (with its second line it would be 1.7 mm, under the floor).
        let mut p = crowded();
        p.folds.retain(|f| !(f.a.x > 12.5 && f.a.x < 23.5));
        place(&mut p, &PatternOptions::default(), false);
        assert!(p.left_out.is_empty(), "{:?}", p.left_out);
        let f = Footprint::of(&p.label).unwrap();
        let Footprint::Disc { c, r } = f else {
            panic!("the label is a disc")
        };
        assert!(c.x - r >= 12.0 && c.x + r <= 24.0, "{c} {r}");
        let h = text_height(&p.label);
        assert!((2.5..2.7).contains(&h), "{h}");
        // One line: every stroke within the cap height of the block's bottom.
        let (lo, hi) = polygon::bounds(p.label.points()).unwrap();
        assert!(hi.y - lo.y < h + 1e-9, "{lo} {hi}");
    }

    /// A 60 × 30 mm piece whose bottom side from x = 0 to 40 is seam 17, a saw-tooth of 1 mm
    /// steps 0.3 mm deep, marked where marks put a seam id: on its longest segment, as high
    /// as that segment allows (0.31 mm).
    fn saw_tooth() -> Piece {
        let tooth: Vec<DVec2> = (0..=40)
            .map(|k| DVec2::new(k as f64, if k % 2 == 1 { 0.3 } else { 0.0 }))
            .collect();
        let mut ring = tooth.clone();
        ring.extend([
            DVec2::new(60.0, 0.0),
            DVec2::new(60.0, 30.0),
            DVec2::new(0.0, 30.0),
        ]);
        let mut p = Piece::from_outline(1, "1".into(), ring);
        let (a, b) = (tooth[0], tooth[1]);
        p.marks = vec![super::super::EdgeMark {
            id: 17,
            edge: 0,
            a,
            b,
            text: super::super::marks::edge_text("17", a, b, f64::INFINITY, 3.0),
        }];
        p.seams = vec![super::super::marks::SeamSide {
            id: 17,
            is_a: true,
            partner: 2,
            ring: 0,
            first: 0,
            count: 40,
            length: super::super::marks::polyline_length(&tooth),
            length_3d: super::super::marks::polyline_length(&tooth),
            points: tooth,
            notches: Vec::new(),
            tab: false,
            split: false,
        }];
        p
    }

    #[test]
    fn a_seam_id_too_small_on_its_segment_goes_along_its_side_at_a_legible_height() {
        let mut p = saw_tooth();
        let was = text_height(&p.marks[0].text);
        assert!(was < 0.4, "{was}");
        place(&mut p, &PatternOptions::default(), false);
        assert!(p.left_out.is_empty(), "{:?}", p.left_out);
        let h = text_height(&p.marks[0].text);
        assert!(h >= MIN_TEXT_MM, "{h}");
        // Beside the saw-tooth, inside the piece, along x.
        let (lo, hi) = polygon::bounds(p.marks[0].text.points()).unwrap();
        assert!(
            lo.x >= 0.0 && hi.x <= 40.0 && lo.y > 0.3 && hi.y < 0.3 + 4.0 * h,
            "{lo} {hi}"
        );
        assert!(p.marks[0].text.dir.unwrap().abs().x > 0.99);
        // Where no chord of the side is long enough (a side of two teeth), it keeps its
        // height, beside the side.
        let mut p = saw_tooth();
        p.seams[0].points.truncate(3);
        p.seams[0].count = 2;
        place(&mut p, &PatternOptions::default(), false);
        assert!(p.left_out.is_empty(), "{:?}", p.left_out);
        assert!((text_height(&p.marks[0].text) - was).abs() < 1e-9);
        let (lo, hi) = polygon::bounds(p.marks[0].text.points()).unwrap();
        assert!(lo.x >= 0.0 && hi.x <= 2.0 && hi.y < 2.0, "{lo} {hi}");
    }

    #[test]
    fn chords_keep_within_their_band_and_stop_at_corners() {
        // Two saw-tooth runs at a right angle: one chord each, the corner their common end.
        let mut pts: Vec<DVec2> = (0..=10)
            .map(|k| DVec2::new(k as f64, if k % 2 == 1 { 0.3 } else { 0.0 }))
            .collect();
        pts.extend(
            (1..=10).map(|k| DVec2::new(10.0 - if k % 2 == 1 { 0.3 } else { 0.0 }, k as f64)),
        );
        let c = chords_of(&pts, 0.5);
        assert_eq!(c, vec![(pts[0], pts[10]), (pts[10], pts[20])]);
        // A band narrower than the teeth: no chord spans one.
        assert!(chords_of(&pts, 0.1).is_empty());
    }

    #[test]
    fn a_bend_note_too_small_to_read_on_its_line_is_left_out_not_drawn() {
        // A 60 × 40 mm piece with a crease 5 mm long (a note along it would be 0.7 mm high)
        // and a bend line across it.
        let mut p = Piece::from_outline(1, "1".into(), rectangle(60.0, 40.0));
        let fold = |a: DVec2, b: DVec2, edge: usize| super::super::Fold {
            a,
            b,
            kind: FoldKind::Mountain,
            angle: 0.5,
            edge,
            tab: false,
        };
        p.folds = vec![
            fold(DVec2::new(40.0, 0.0), DVec2::new(40.0, 5.0), 1),
            fold(DVec2::new(10.0, 0.0), DVec2::new(10.0, 40.0), 2),
        ];
        let opts = PatternOptions {
            bend_notes: true,
            ..PatternOptions::default()
        };
        place(&mut p, &opts, false);
        assert_eq!(p.note_folds, vec![1]);
        assert!(text_height(&p.notes[0]) >= MIN_TEXT_MM);
        assert_eq!(
            p.left_out,
            vec![LeftOut {
                what: "bend note",
                words: "29° DOWN".into()
            }]
        );
    }

    #[test]
    fn bend_notes_keep_off_each_other_and_off_the_lines() {
        // Folds 6 mm apart: a 3 mm note beside each would reach the next fold's note; they
        // slide along their lines instead.
        let mut p = crowded();
        p.folds.retain(|f| (f.a.x / 1.5).round() as i64 % 4 == 0);
        let n = p.folds.len();
        let opts = PatternOptions {
            bend_notes: true,
            ..PatternOptions::default()
        };
        place(&mut p, &opts, false);
        let placed: Vec<Footprint> = p.notes.iter().filter_map(Footprint::of).collect();
        assert_eq!(
            placed.len() + p.left_out.iter().filter(|l| l.what == "bend note").count(),
            n
        );
        for (i, a) in placed.iter().enumerate() {
            for b in &placed[i + 1..] {
                assert!(!a.overlaps(b), "{a:?} {b:?}");
            }
            for f in &p.folds {
                assert!(!a.hits_segment(f.a, f.b));
            }
        }
    }

    #[test]
    fn the_inside_test_agrees_with_the_polygon_one() {
        // A ring with a hole, tested on a grid of points.
        let outer: Vec<DVec2> = (0..40)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 40.0;
                DVec2::new(100.0 * a.cos(), 60.0 * a.sin() + 10.0 * (3.0 * a).sin())
            })
            .collect();
        let hole = vec![
            DVec2::new(-20.0, -10.0),
            DVec2::new(-20.0, 10.0),
            DVec2::new(30.0, 10.0),
            DVec2::new(30.0, -10.0),
        ];
        let mut p = Piece::from_outline(1, "1".into(), outer);
        p.border.push(hole);
        let mut room = Room::new(&p);
        let mut n = 0;
        for i in -60..=60 {
            for j in -40..=40 {
                let q = DVec2::new(1.7 * i as f64 + 0.013, 1.7 * j as f64 + 0.007);
                assert_eq!(
                    room.inside(q, Within::Border),
                    polygon::contains_rings(&p.border, q),
                    "{q}"
                );
                n += usize::from(room.inside(q, Within::Border));
            }
        }
        assert!(n > 3000, "{n}");
    }

    #[test]
    fn sizes_stop_at_the_floor() {
        assert_eq!(
            sizes(3.0, MIN_TEXT_MM),
            vec![3.0, 2.4000000000000004, MIN_TEXT_MM]
        );
        assert_eq!(sizes(1.5, MIN_TEXT_MM), vec![1.5]);
        assert_eq!(sizes(1.5, 1.2), vec![1.5, 1.2]);
        assert!(sizes(f64::NAN, MIN_TEXT_MM).is_empty());
    }
}
