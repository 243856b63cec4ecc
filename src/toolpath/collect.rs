//! The strokes of one sheet, unordered: every piece's labels, marks, folds, notches and cut
//! contours moved to where the nest stage placed the piece.
//!
//! Text stays readable on the sheet whatever the piece's rotation: a piece label, which the
//! pattern stage sizes so that it fits inside the piece in any orientation, is turned back
//! about its centre to read along +x; an edge id or bend note, set along its edge, is turned
//! half a turn about its own centre when the placement would put it upside down.

use super::{Stroke, StrokeRole, ToolpathOptions};
use crate::nest::{Layout, Sheet};
use glam::DVec2;

/// All strokes of a sheet, piece by piece, in sheet millimetres.
pub(super) fn strokes(layout: &Layout, sheet: &Sheet, opts: &ToolpathOptions) -> Vec<Stroke> {
    let mut out = Vec::new();
    for &k in &sheet.pieces {
        let piece = &layout.pieces[k];
        let at = layout.placements[k];
        let mut open = |role, pts: &[DVec2]| {
            out.push(Stroke {
                role,
                points: pts.iter().map(|p| at.apply(*p)).collect(),
                closed: false,
                piece: Some(k),
                outer: false,
            })
        };
        if !opts.skip_drawing {
            for s in &piece.label {
                open(StrokeRole::Label, s);
            }
            for m in &piece.marks {
                for s in &m.strokes {
                    open(StrokeRole::Mark, s);
                }
            }
        }
        if !opts.skip_folds {
            for f in &piece.folds {
                let role = match f.kind {
                    crate::pattern::FoldKind::Mountain => StrokeRole::FoldMountain,
                    crate::pattern::FoldKind::Valley => StrokeRole::FoldValley,
                };
                open(role, &[f.a, f.b]);
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
