//! The strokes of one sheet, unordered: every piece's labels, marks, folds, notches and cut
//! contours moved to where the nest stage placed the piece.
//!
//! Text stays readable on the sheet whatever the piece's rotation: a piece label, which the
//! pattern stage sizes so that it fits inside the piece in any orientation, is turned back
//! about its centre to read along +x; an edge id or bend note, set along its edge, is turned
//! half a turn about its own centre when the placement would put it upside down.

use super::{Stroke, StrokeRole, ToolpathOptions};
use crate::nest::{Layout, Placement, Sheet};
use crate::pattern::Text;
use glam::DVec2;

/// All strokes of a sheet, piece by piece, in sheet millimetres.
pub(super) fn strokes(layout: &Layout, sheet: &Sheet, opts: &ToolpathOptions) -> Vec<Stroke> {
    let mut out = Vec::new();
    for &k in &sheet.pieces {
        let piece = &layout.pieces[k];
        let at = layout.placements[k];
        // `place`: the points are in the piece's frame (else already on the sheet).
        let mut open = |role, pts: &[DVec2], place: bool| {
            out.push(Stroke {
                role,
                points: if place {
                    pts.iter().map(|p| at.apply(*p)).collect()
                } else {
                    pts.to_vec()
                },
                closed: false,
                piece: Some(k),
                outer: false,
            })
        };
        if !opts.skip_drawing {
            for t in std::iter::once(&piece.label)
                .chain(piece.marks.iter().map(|m| &m.text))
                .chain(&piece.notes)
            {
                let role = if t.dir.is_none() {
                    StrokeRole::Label
                } else {
                    StrokeRole::Mark
                };
                for pts in upright(t, &at) {
                    open(role, &pts, false);
                }
            }
            for ring in &piece.seam_line {
                let mut pts = ring.clone();
                pts.extend(ring.first().copied());
                open(StrokeRole::Seam, &pts, true);
            }
            for s in &piece.grain_line {
                open(StrokeRole::Grain, s, true);
            }
            for n in piece.notches.iter().filter(|n| !n.cut) {
                open(StrokeRole::Mark, &n.stroke, true);
            }
        }
        for n in piece.notches.iter().filter(|n| n.cut) {
            open(StrokeRole::Notch, &n.stroke, true);
        }
        if !opts.skip_folds {
            for f in &piece.folds {
                let role = match f.kind {
                    crate::pattern::FoldKind::Mountain => StrokeRole::FoldMountain,
                    crate::pattern::FoldKind::Valley => StrokeRole::FoldValley,
                };
                open(role, &[f.a, f.b], true);
            }
        }
        for (i, ring) in piece.outline.iter().enumerate() {
            let mut points: Vec<DVec2> = ring.iter().map(|p| at.apply(*p)).collect();
            points.push(points[0]);
            out.push(Stroke {
                role: StrokeRole::Cut,
                points,
                closed: true,
                piece: Some(k),
                outer: i == 0,
            });
        }
    }
    out
}

/// The strokes of a text on the sheet, reading upright: a label keeps its own orientation
/// (only its centre moves with the piece); text set along an edge turns with the piece, and
/// half a turn more about its centre when it would read right to left or downwards. On a
/// mirrored piece the text is set again in its (symmetric) box so that it never reads
/// mirrored. The box is centred where the piece puts it, so the text stays where it was.
fn upright(t: &Text, at: &Placement) -> Vec<Vec<DVec2>> {
    // The text's axes in the piece; the centre of its box along them (the box the pattern
    // stage kept clear, so that the half turn lands the text on itself; the centre of the
    // axis-aligned bounds would not, for text set at an angle).
    let (r, up) = match t.dir {
        None => (DVec2::X, DVec2::Y),
        Some(r) => (r, r.perp()),
    };
    let along = t.points().map(|q| DVec2::new(q.dot(r), q.dot(up)));
    let Some((lo, hi)) = crate::geom::polygon::bounds(along) else {
        return Vec::new();
    };
    let mid = 0.5 * (lo + hi);
    let c = r * mid.x + up * mid.y;
    let cs = at.apply(c);
    // Its box's axes on the sheet.
    let (mut e1, mut e2) = match t.dir {
        None => (DVec2::X, DVec2::Y),
        Some(r) => (
            (at.apply(c + r) - cs).normalize_or_zero(),
            (at.apply(c + r.perp()) - cs).normalize_or_zero(),
        ),
    };
    if e1.perp_dot(e2) < 0.0 {
        e1 = -e1;
    }
    if e1.x < -1e-9 || (e1.x.abs() <= 1e-9 && e1.y < 0.0) {
        (e1, e2) = (-e1, -e2);
    }
    t.strokes
        .iter()
        .map(|s| {
            s.iter()
                .map(|q| {
                    let d = *q - c;
                    cs + e1 * d.dot(r) + e2 * d.dot(up)
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// "12" set along the edge (0,0)→(10,0), as the pattern stage does.
    fn text() -> Text {
        crate::pattern::marks::edge_text("12", DVec2::ZERO, DVec2::new(10.0, 0.0), 10.0, 3.0)
    }

    /// Reading direction and "up" of the first glyph's strokes on the sheet, from the text's
    /// box: the first stroke of "1" lies left of the last stroke of "2" when read upright.
    fn reads_upright(strokes: &[Vec<DVec2>]) -> bool {
        let first = strokes.first().unwrap()[0];
        let last = *strokes.last().unwrap().last().unwrap();
        last.x > first.x
    }

    #[test]
    fn text_reads_upright_whatever_the_placement() {
        let t = text();
        let own: Vec<DVec2> = t.points().collect();
        let (lo, hi) = crate::geom::polygon::bounds(own.iter().copied()).unwrap();
        let (w, h) = (hi.x - lo.x, hi.y - lo.y);
        for mirror in [false, true] {
            for quarter in 0..4 {
                let at = Placement {
                    sheet: 0,
                    rotation: quarter as f64 * std::f64::consts::FRAC_PI_2,
                    mirror,
                    offset: DVec2::new(100.0, 100.0),
                };
                let s = upright(&t, &at);
                assert!(
                    reads_upright(&s),
                    "mirror {mirror}, {quarter} quarter turns"
                );
                // Never mirrored: the same shape up to a rotation (compare box sizes and the
                // signed area swept by the "2", whose orientation a mirror would flip).
                let pts: Vec<DVec2> = s.iter().flatten().copied().collect();
                let (l2, h2) = crate::geom::polygon::bounds(pts.iter().copied()).unwrap();
                let (w2, hh2) = (h2.x - l2.x, h2.y - l2.y);
                assert!(
                    ((w2 - w).abs() < 1e-9 && (hh2 - h).abs() < 1e-9)
                        || ((w2 - h).abs() < 1e-9 && (hh2 - w).abs() < 1e-9)
                );
                let two = |v: &[Vec<DVec2>]| crate::geom::polygon::signed_area(v.last().unwrap());
                assert!((two(&s) - two(&t.strokes)).abs() < 1e-9);
                // It stays centred where the piece puts its box.
                let c = at.apply(0.5 * (lo + hi));
                assert!((0.5 * (l2 + h2) - c).length() < 1e-9);
            }
        }
    }

    /// Text set along a slanted edge, on a piece turned half a turn: it is turned back about
    /// the centre of its own box (along its edge), so it covers exactly the box the pattern
    /// stage kept clear (fandisk: a seam id turned about the centre of its axis-aligned
    /// bounds poked 0.008 mm out of its piece).
    #[test]
    fn slanted_text_turned_back_stays_in_its_box() {
        let t =
            crate::pattern::marks::edge_text("17", DVec2::ZERO, DVec2::new(10.0, 4.0), 10.0, 3.0);
        let r = t.dir.unwrap();
        let frame = |pts: &mut dyn Iterator<Item = DVec2>| {
            crate::geom::polygon::bounds(pts.map(|q| DVec2::new(q.dot(r), q.dot(r.perp()))))
                .unwrap()
        };
        let (lo, hi) = frame(&mut t.points());
        let at = Placement {
            sheet: 0,
            rotation: std::f64::consts::PI,
            mirror: false,
            offset: DVec2::ZERO,
        };
        let s = upright(&t, &at);
        // Back in the piece's frame, the turned text spans the same box.
        let back: Vec<DVec2> = s.iter().flatten().map(|q| -*q).collect();
        let (l2, h2) = frame(&mut back.into_iter());
        assert!(
            (l2 - lo).length() < 1e-9 && (h2 - hi).length() < 1e-9,
            "{lo} {hi} vs {l2} {h2}"
        );
    }
}
