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

mod collect;

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
}

impl StrokeRole {
    pub const ALL: [StrokeRole; 9] = [
        StrokeRole::Cut,
        StrokeRole::FoldMountain,
        StrokeRole::FoldValley,
        StrokeRole::Mark,
        StrokeRole::Label,
        StrokeRole::Notch,
        StrokeRole::Seam,
        StrokeRole::Grain,
        StrokeRole::Weed,
    ];

    /// The tool class that makes this stroke.
    pub fn kind(self) -> StrokeKind {
        match self {
            StrokeRole::Cut | StrokeRole::Notch | StrokeRole::Weed => StrokeKind::Cut,
            StrokeRole::FoldMountain | StrokeRole::FoldValley => StrokeKind::Score,
            StrokeRole::Mark | StrokeRole::Label | StrokeRole::Seam | StrokeRole::Grain => {
                StrokeKind::Draw
            }
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
    /// Leave fold lines out (a device without a scoring tool).
    pub skip_folds: bool,
    /// Leave marks and labels out (a device without a pen).
    pub skip_drawing: bool,
}

/// Order the strokes of every sheet of a layout.
pub fn plan(layout: &crate::nest::Layout, name: &str, opts: &ToolpathOptions) -> Job {
    let sheets = layout
        .sheets
        .iter()
        .map(|sheet| {
            let mut groups: [Vec<Stroke>; 4] = Default::default();
            for s in collect::strokes(layout, sheet, opts) {
                let g = match s.role {
                    StrokeRole::Mark | StrokeRole::Label | StrokeRole::Seam | StrokeRole::Grain => {
                        0
                    }
                    StrokeRole::FoldMountain | StrokeRole::FoldValley | StrokeRole::Notch => 1,
                    StrokeRole::Cut | StrokeRole::Weed if !s.outer => 2,
                    StrokeRole::Cut | StrokeRole::Weed => 3,
                };
                groups[g].push(s);
            }
            let mut pen = DVec2::ZERO;
            let mut strokes = Vec::new();
            for group in groups {
                strokes.extend(nearest_neighbour(group, &mut pen));
            }
            SheetJob {
                width: sheet.width,
                height: sheet.height,
                strokes,
            }
        })
        .collect();
    Job {
        name: name.to_string(),
        sheets,
    }
}

/// Pen-up travel of a sequence of strokes, starting from the origin.
pub fn travel(strokes: &[Stroke]) -> f64 {
    let mut pen = DVec2::ZERO;
    let mut total = 0.0;
    for s in strokes {
        if let (Some(first), Some(last)) = (s.points.first(), s.points.last()) {
            total += pen.distance(*first);
            pen = *last;
        }
    }
    total
}

/// Chain strokes by nearest neighbour from `pen`, reversing open strokes and rotating closed
/// ones to start at the nearest vertex. A uniform grid over the entry points keeps it near
/// O(n log n) for the thousands of short strokes of edge ids.
fn nearest_neighbour(mut strokes: Vec<Stroke>, pen: &mut DVec2) -> Vec<Stroke> {
    let n = strokes.len();
    if n == 0 {
        return strokes;
    }
    // Entry points: both ends of an open stroke, every vertex of a closed one.
    let mut entries: Vec<(DVec2, usize, usize)> = Vec::new();
    for (k, s) in strokes.iter().enumerate() {
        if s.closed {
            let m = s.points.len().saturating_sub(1).max(1);
            for (i, p) in s.points.iter().take(m).enumerate() {
                entries.push((*p, k, i));
            }
        } else if let Some(last) = s.points.len().checked_sub(1) {
            entries.push((s.points[0], k, 0));
            if last > 0 {
                entries.push((s.points[last], k, last));
            }
        }
    }
    let Some((lo, hi)) = crate::geom::polygon::bounds(entries.iter().map(|e| e.0)) else {
        return strokes;
    };
    let extent = (hi - lo).max_element().max(1e-9);
    let cell = extent / (entries.len() as f64).sqrt().max(1.0);
    let key = |p: DVec2| {
        (
            ((p.x - lo.x) / cell).floor() as i64,
            ((p.y - lo.y) / cell).floor() as i64,
        )
    };
    let cells_x = ((hi.x - lo.x) / cell).floor() as i64;
    let cells_y = ((hi.y - lo.y) / cell).floor() as i64;
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for (i, e) in entries.iter().enumerate() {
        grid.entry(key(e.0)).or_default().push(i);
    }
    let mut used = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for _ in 0..n {
        let c = key(*pen);
        let mut best: Option<(f64, usize, usize)> = None; // (distance, stroke, vertex)
        let max_r =
            (c.0.abs().max((c.0 - cells_x).abs())).max(c.1.abs().max((c.1 - cells_y).abs())) + 1;
        for r in 0..=max_r {
            if let Some((d, _, _)) = best {
                // Every point in ring r is at least (r - 1) cells away.
                if d < (r - 1) as f64 * cell {
                    break;
                }
            }
            for x in c.0 - r..=c.0 + r {
                for y in c.1 - r..=c.1 + r {
                    if (x - c.0).abs() != r && (y - c.1).abs() != r {
                        continue;
                    }
                    for &i in grid.get(&(x, y)).map(|v| v.as_slice()).unwrap_or(&[]) {
                        let (p, k, v) = entries[i];
                        if used[k] {
                            continue;
                        }
                        let d = pen.distance(p);
                        let better = match best {
                            None => true,
                            Some((bd, bk, bv)) => (d, k, v) < (bd, bk, bv),
                        };
                        if better {
                            best = Some((d, k, v));
                        }
                    }
                }
            }
        }
        let Some((_, k, v)) = best else {
            break;
        };
        used[k] = true;
        order.push((k, v));
        let s = &strokes[k];
        *pen = if s.closed {
            s.points[v]
        } else if v == 0 {
            *s.points.last().unwrap_or(pen)
        } else {
            s.points[0]
        };
    }
    let mut out = Vec::with_capacity(n);
    for (k, v) in order {
        let mut s = std::mem::replace(
            &mut strokes[k],
            Stroke {
                role: StrokeRole::Cut,
                points: Vec::new(),
                closed: false,
                piece: None,
                outer: false,
            },
        );
        if s.closed {
            s.points.pop();
            s.points.rotate_left(v);
            s.points.push(s.points[0]);
        } else if v != 0 {
            s.points.reverse();
        }
        out.push(s);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn open(a: (f64, f64), b: (f64, f64)) -> Stroke {
        Stroke {
            role: StrokeRole::Mark,
            points: vec![DVec2::new(a.0, a.1), DVec2::new(b.0, b.1)],
            closed: false,
            piece: None,
            outer: false,
        }
    }

    #[test]
    fn nearest_neighbour_chains_and_reverses() {
        let strokes = vec![
            open((100.0, 0.0), (90.0, 0.0)),
            open((12.0, 0.0), (50.0, 0.0)),
            open((1.0, 0.0), (10.0, 0.0)),
        ];
        let before = travel(&strokes);
        let mut pen = DVec2::ZERO;
        let out = nearest_neighbour(strokes, &mut pen);
        assert_eq!(out.len(), 3);
        assert_eq!(out[0].points[0], DVec2::new(1.0, 0.0));
        assert_eq!(out[1].points[0], DVec2::new(12.0, 0.0));
        assert_eq!(out[2].points[0], DVec2::new(90.0, 0.0));
        assert!((travel(&out) - (1.0 + 2.0 + 40.0)).abs() < 1e-12);
        assert!(travel(&out) < before);
    }

    #[test]
    fn closed_stroke_starts_at_nearest_vertex() {
        let ring = Stroke {
            role: StrokeRole::Cut,
            points: [
                (0.0, 0.0),
                (10.0, 0.0),
                (10.0, 10.0),
                (0.0, 10.0),
                (0.0, 0.0),
            ]
            .iter()
            .map(|p| DVec2::new(p.0, p.1))
            .collect(),
            closed: true,
            piece: None,
            outer: false,
        };
        let mut pen = DVec2::new(11.0, 11.0);
        let out = nearest_neighbour(vec![ring.clone()], &mut pen);
        assert_eq!(out[0].points[0], DVec2::new(10.0, 10.0));
        assert_eq!(out[0].points.last(), Some(&DVec2::new(10.0, 10.0)));
        assert!((out[0].length() - ring.length()).abs() < 1e-12);
    }
}
