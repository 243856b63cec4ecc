//! Toolpath stage: turns a nested [`Layout`](crate::nest::Layout) into a [`Job`], the ordered
//! strokes per sheet, in millimetres, that an output language then encodes.
//!
//! Order (issue 2, DESIGN.md "toolpath/"): on each sheet, drawn marks and labels first, then
//! folds (scored), then cuts, inner contours (holes) before the outline that surrounds them, so
//! that the material is still held while it is worked on. Inside each group the strokes are
//! chained by nearest neighbour from the current pen position: an open stroke may be reversed,
//! a closed contour may start at whichever of its vertices is nearest.
//!
//! Choices where the issue is silent: the pen starts at the sheet origin (0, 0); ties in the
//! nearest-neighbour search go to the stroke that came first, so the order is deterministic.

use glam::DVec2;
use serde::Serialize;

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
}

impl StrokeRole {
    pub const ALL: [StrokeRole; 5] = [
        StrokeRole::Cut,
        StrokeRole::FoldMountain,
        StrokeRole::FoldValley,
        StrokeRole::Mark,
        StrokeRole::Label,
    ];

    /// The tool class that makes this stroke.
    pub fn kind(self) -> StrokeKind {
        match self {
            StrokeRole::Cut => StrokeKind::Cut,
            StrokeRole::FoldMountain | StrokeRole::FoldValley => StrokeKind::Score,
            StrokeRole::Mark | StrokeRole::Label => StrokeKind::Draw,
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
        }
    }
}

/// Tool classes of a device's tool table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StrokeKind {
    Cut,
    Score,
    Perforate,
    Draw,
    Etch,
}

impl StrokeKind {
    pub fn name(self) -> &'static str {
        match self {
            StrokeKind::Cut => "cut",
            StrokeKind::Score => "score",
            StrokeKind::Perforate => "perforate",
            StrokeKind::Draw => "draw",
            StrokeKind::Etch => "etch",
        }
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
