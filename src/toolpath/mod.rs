//! Toolpath stage: turns a nested [`Layout`](crate::nest::Layout) into a [`Job`], the ordered
//! strokes per sheet, in millimetres, that an output language then encodes.
//!
//! Order (issue 8, DESIGN.md "toolpath/"): drawn marks, labels, sewing and grain lines first,
//! then folds and notches, then cuts, inner contours (holes) before the outline that surrounds
//! them, so that the material is still held while it is worked on; weed lines last. With
//! [`ToolpathOptions::per_piece`] (fabric, or any material that may shift once a piece is cut
//! free) each piece gets all of that before the next piece starts, pieces taken nearest first;
//! otherwise the groups span the whole sheet. Inside each group travel is made short by
//! [`order`] (nearest neighbour, then 2-opt; the collection order is kept if it is shorter).
//!
//! The ordered job is the design (what the SVG and PNG show). What a machine's tools need on top
//! of it — folds as perforation dashes, overcut, drag-knife offset compensation with an
//! alignment precut — is [`knife::prepare`], applied to the job that is encoded. Which tool makes
//! a fold is `fold_kind`: the scoring tool, else the perforating one, else the pen.
//! [`weed`] adds weed lines for vinyl. [`passes`] names what a device has no tool for and
//! splits a job into the pen and knife passes of a tool change. [`registration`] lays out the
//! printed registration marks of a print-and-cut sheet.
//!
//! Choices where the issue is silent: the pen starts at the sheet origin (0, 0); notches
//! are cut with the folds, before the outline they open; strokes of no piece (weed lines) come
//! after every piece; everything is deterministic (counts, never clocks, bound the search).

pub use crate::profile::StrokeKind;
use glam::DVec2;
use serde::Serialize;

mod collect;
pub mod cuttable;
pub mod knife;
pub mod order;
pub mod passes;
pub mod registration;
pub mod weed;

/// What a stroke is for; decides the SVG layer and, through [`StrokeKind`], the tool.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StrokeRole {
    /// Piece outlines and holes.
    Cut,
    /// Fold where the printed side ends up on the outside of the crease (convex edge).
    FoldMountain,
    /// Fold where the printed side ends up on the inside of the crease (concave edge).
    FoldValley,
    /// Reference marks: the edge ids written beside both copies of a cut edge.
    Mark,
    /// Piece labels.
    Label,
    /// Seam notches: short slits cut from the outline into the piece (or its allowance).
    Notch,
    /// The sewing line of a piece cut with a seam allowance (drawn).
    Seam,
    /// Grain-line arrows on fabric pieces (drawn).
    Grain,
    /// Weed lines cut through the waste between pieces (vinyl).
    Weed,
    /// Print-and-cut registration marks ([`registration`]): printed, never sent to a cutter.
    Register,
}

impl StrokeRole {
    pub const ALL: [StrokeRole; 10] = [
        StrokeRole::Cut,
        StrokeRole::FoldMountain,
        StrokeRole::FoldValley,
        StrokeRole::Mark,
        StrokeRole::Label,
        StrokeRole::Notch,
        StrokeRole::Seam,
        StrokeRole::Grain,
        StrokeRole::Weed,
        StrokeRole::Register,
    ];

    /// The tool class that makes this stroke.
    pub fn kind(self) -> StrokeKind {
        match self {
            StrokeRole::Cut | StrokeRole::Notch | StrokeRole::Weed => StrokeKind::Cut,
            StrokeRole::FoldMountain | StrokeRole::FoldValley => StrokeKind::Score,
            StrokeRole::Mark
            | StrokeRole::Label
            | StrokeRole::Seam
            | StrokeRole::Grain
            | StrokeRole::Register => StrokeKind::Draw,
        }
    }

    /// Name used for SVG layers and reports.
    pub fn name(self) -> &'static str {
        match self {
            StrokeRole::Cut => "cut",
            StrokeRole::FoldMountain => "fold-mountain",
            StrokeRole::FoldValley => "fold-valley",
            StrokeRole::Mark => "mark",
            StrokeRole::Label => "label",
            StrokeRole::Notch => "notch",
            StrokeRole::Seam => "seam",
            StrokeRole::Grain => "grain",
            StrokeRole::Weed => "weed",
            StrokeRole::Register => "registration",
        }
    }
}

/// The tool that makes folds on a device whose tool table has the kinds `has` accepts: the
/// scoring tool, else the perforating one (folds cut as dashes, see [`knife`]), else the pen;
/// `None`: the device cannot make folds and they are left out.
pub(crate) fn fold_kind(has: impl Fn(StrokeKind) -> bool) -> Option<StrokeKind> {
    [StrokeKind::Score, StrokeKind::Perforate, StrokeKind::Draw]
        .into_iter()
        .find(|k| has(*k))
}

/// The tool kind that makes a stroke of `role` on a device with the kinds `has` accepts
/// (folds: `fold_kind`; the rest: [`StrokeRole::kind`] if the device has it).
pub fn tool_kind(role: StrokeRole, has: impl Fn(StrokeKind) -> bool) -> Option<StrokeKind> {
    match role.kind() {
        StrokeKind::Score => fold_kind(has),
        k => has(k).then_some(k),
    }
}

/// One tool-down polyline in sheet millimetres (x right, y up, origin at the sheet's lower-left
/// corner). A closed stroke repeats its first point at the end.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    pub role: StrokeRole,
    pub points: Vec<DVec2>,
    pub closed: bool,
    /// Index of the piece in the layout this stroke belongs to.
    pub piece: Option<usize>,
    /// The outer contour of its piece (cut last, after everything inside it).
    pub outer: bool,
}

impl Stroke {
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| w[0].distance(w[1])).sum()
    }
}

/// The strokes of one sheet, in cutting order.
#[derive(Debug, Clone, PartialEq)]
pub struct SheetJob {
    /// Sheet size in mm. For a roll, `height` is the length of roll used.
    pub width: f64,
    pub height: f64,
    pub strokes: Vec<Stroke>,
}

/// Strokes for every sheet of a layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    pub name: String,
    pub sheets: Vec<SheetJob>,
}

/// Options of the toolpath stage.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ToolpathOptions {
    /// Leave fold lines out (a device with no tool to make them).
    pub skip_folds: bool,
    /// Leave marks and labels out (a device without a pen).
    pub skip_drawing: bool,
    /// Finish each piece (its drawing, folds, holes, outline) before starting the next, for
    /// material that may shift once a piece is free (fabric). Otherwise every piece's drawing
    /// comes first, then every fold, then every hole, then every outline.
    pub per_piece: bool,
    /// Weed lines for vinyl (see [`weed`]); `None`: none.
    pub weed: Option<weed::WeedOptions>,
}

/// Order group of a stroke inside a piece (or a sheet): drawing, then folds and notches, then
/// holes, then outer contours, then weed lines.
fn group_of(s: &Stroke) -> usize {
    match s.role {
        StrokeRole::Mark
        | StrokeRole::Label
        | StrokeRole::Seam
        | StrokeRole::Grain
        | StrokeRole::Register => 0,
        StrokeRole::FoldMountain | StrokeRole::FoldValley | StrokeRole::Notch => 1,
        StrokeRole::Weed => 4,
        StrokeRole::Cut if !s.outer => 2,
        StrokeRole::Cut => 3,
    }
}

/// Order the strokes of every sheet of a layout.
pub fn plan(layout: &crate::nest::Layout, name: &str, opts: &ToolpathOptions) -> Job {
    let sheets = layout
        .sheets
        .iter()
        .map(|sheet| {
            let mut all = collect::strokes(layout, sheet, opts);
            if let Some(w) = &opts.weed {
                all.extend(weed::lines(layout, sheet, w));
            }
            SheetJob {
                width: sheet.width,
                height: sheet.height,
                strokes: order_sheet(all, opts.per_piece),
            }
        })
        .collect();
    Job {
        name: name.to_string(),
        sheets,
    }
}

/// The strokes of one sheet in collection order (piece by piece, as [`plan`] gathers them
/// before ordering): the baseline that travel figures are compared with.
pub fn unordered(
    layout: &crate::nest::Layout,
    sheet: &crate::nest::Sheet,
    opts: &ToolpathOptions,
) -> Vec<Stroke> {
    collect::strokes(layout, sheet, opts)
}

/// Order one sheet's strokes: by group (see [`group_of`]), piece by piece when `per_piece`,
/// and inside each group for short travel ([`order::order`]). The pen starts at the origin.
pub(crate) fn order_sheet(strokes: Vec<Stroke>, per_piece: bool) -> Vec<Stroke> {
    let mut pen = DVec2::ZERO;
    let mut out = Vec::with_capacity(strokes.len());
    if !per_piece {
        let mut groups: [Vec<Stroke>; 5] = Default::default();
        for s in strokes {
            groups[group_of(&s)].push(s);
        }
        for group in groups {
            out.extend(order::order(group, &mut pen));
        }
        return out;
    }
    // Per piece: the strokes of each piece in groups; strokes of no piece (weed lines) last.
    let mut pieces: std::collections::BTreeMap<usize, [Vec<Stroke>; 5]> = Default::default();
    let mut loose: [Vec<Stroke>; 5] = Default::default();
    for s in strokes {
        let g = group_of(&s);
        match s.piece {
            Some(k) if g < 4 => pieces.entry(k).or_default()[g].push(s),
            _ => loose[g].push(s),
        }
    }
    let mut pieces: Vec<[Vec<Stroke>; 5]> = pieces.into_values().collect();
    // Pieces one after the other, the next being the one whose first group comes nearest the
    // pen (ties: the lower piece index).
    while !pieces.is_empty() {
        let mut best = (f64::INFINITY, 0);
        for (i, groups) in pieces.iter().enumerate() {
            let d = groups
                .iter()
                .find(|g| !g.is_empty())
                .map_or(f64::INFINITY, |g| nearest_entry(g, pen));
            if d < best.0 {
                best = (d, i);
            }
        }
        let groups = pieces.remove(best.1);
        for group in groups {
            out.extend(order::order(group, &mut pen));
        }
    }
    for group in loose {
        out.extend(order::order(group, &mut pen));
    }
    out
}

/// Distance from `pen` to the nearest point a stroke of `group` can start at (an end of an open
/// stroke, any vertex of a closed one).
fn nearest_entry(group: &[Stroke], pen: DVec2) -> f64 {
    order::entry_points(group)
        .iter()
        .map(|(p, _, _)| pen.distance(*p))
        .fold(f64::INFINITY, f64::min)
}

/// Pen-up travel of a sequence of strokes, starting from the origin.
pub fn travel(strokes: &[Stroke]) -> f64 {
    order::travel_from(DVec2::ZERO, strokes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(role: StrokeRole, piece: usize, pts: &[(f64, f64)], outer: bool) -> Stroke {
        let closed = pts.first() == pts.last() && pts.len() > 2;
        Stroke {
            role,
            points: pts.iter().map(|p| DVec2::new(p.0, p.1)).collect(),
            closed,
            piece: Some(piece),
            outer,
        }
    }

    fn square(piece: usize, x: f64, size: f64, outer: bool) -> Stroke {
        s(
            StrokeRole::Cut,
            piece,
            &[
                (x, 0.0),
                (x + size, 0.0),
                (x + size, size),
                (x, size),
                (x, 0.0),
            ],
            outer,
        )
    }

    /// Draw, fold, hole, outline; per piece or across the sheet.
    #[test]
    fn groups_and_per_piece_order() {
        let strokes = vec![
            square(0, 0.0, 50.0, true),
            square(1, 100.0, 50.0, true),
            square(1, 110.0, 10.0, false),
            s(StrokeRole::Label, 1, &[(120.0, 30.0), (130.0, 30.0)], false),
            s(
                StrokeRole::FoldValley,
                0,
                &[(0.0, 25.0), (50.0, 25.0)],
                false,
            ),
            s(StrokeRole::Label, 0, &[(20.0, 30.0), (30.0, 30.0)], false),
            s(StrokeRole::Weed, 0, &[(60.0, 0.0), (60.0, 50.0)], false).with_piece(None),
        ];
        let key = |v: &[Stroke]| -> Vec<(StrokeRole, Option<usize>, bool)> {
            v.iter().map(|s| (s.role, s.piece, s.outer)).collect()
        };
        use StrokeRole::*;
        assert_eq!(
            key(&order_sheet(strokes.clone(), false)),
            vec![
                (Label, Some(0), false),
                (Label, Some(1), false),
                (FoldValley, Some(0), false),
                (Cut, Some(1), false),
                (Cut, Some(1), true),
                (Cut, Some(0), true),
                (Weed, None, false),
            ]
        );
        assert_eq!(
            key(&order_sheet(strokes, true)),
            vec![
                (Label, Some(0), false),
                (FoldValley, Some(0), false),
                (Cut, Some(0), true),
                (Label, Some(1), false),
                (Cut, Some(1), false),
                (Cut, Some(1), true),
                (Weed, None, false),
            ]
        );
    }

    impl Stroke {
        fn with_piece(mut self, piece: Option<usize>) -> Stroke {
            self.piece = piece;
            self
        }
    }
}
