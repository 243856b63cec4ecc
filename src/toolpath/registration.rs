//! Registration marks of a print-and-cut sheet (issue 25 item 4): where they go, what they
//! look like as printed strokes, and the room the nest leaves them.
//!
//! A sheet gets four marks, one per corner, each `inset` mm in from both edges: a filled
//! square in the profile's `square_corner`, an L in each other corner with its arms along the
//! two edges. A mark's reference point — what a sensor or a person finds and what the fit
//! uses — is the square's centre, and the outer corner of an L (where its two outer edges
//! meet). Marks are numbered from 1 for messages and `--marks`: the square first, then the Ls
//! counter-clockwise from it.
//!
//! The marks are printed, never cut: they are strokes of [`StrokeRole::Register`] that the
//! pictures draw black and [`SIZE_STROKE_MM`] wide, the square as parallel strokes that fill
//! it. The nest keeps pieces off them by a wider margin: everything of a mark lies within
//! `inset + max(square, width)` of the sheet's edges, and pieces stay `clearance` further in
//! ([`Marks::margin`]), which is also how Silhouette Studio keeps the border outside its
//! marks free.
//!
//! Choices: the layout is in sheet millimetres (x right, y up, origin at the lower-left
//! corner); a sheet too small for its marks (two marks closer than their own size) is an
//! error naming the profile's `[registration]` keys and the flags that set them.

use super::{Stroke, StrokeRole};
use crate::profile::registration::{Corner, Registration};
use glam::DVec2;
use serde::Serialize;

/// Width the pictures draw a registration stroke, mm: the L arms are single strokes of it.
pub const SIZE_STROKE_MM: f64 = 1.0;

/// What a mark is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MarkKind {
    Square,
    L,
}

/// One mark on a sheet.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    pub kind: MarkKind,
    /// The corner of the sheet it is in.
    pub corner: &'static str,
    /// The point that is found and fitted: the square's centre, the L's outer corner (mm).
    pub reference: DVec2,
    /// The filled rectangles that make it, (min, max) corners in sheet mm.
    pub rects: Vec<(DVec2, DVec2)>,
}

/// The marks of one sheet.
#[derive(Debug, Clone, PartialEq)]
pub struct Marks {
    pub width: f64,
    pub height: f64,
    pub marks: Vec<Mark>,
    /// The nest's margin that keeps pieces `clearance` off the marks.
    pub margin: f64,
}

/// A sheet whose marks cannot be laid out.
#[derive(Debug, thiserror::Error)]
#[error("the {width:.1} × {height:.1} mm sheet has no room for registration marks {inset} mm in with {length} mm arms (the profile's [registration] inset and length, --mark-inset): use a larger sheet or a smaller inset")]
pub struct NoRoom {
    pub width: f64,
    pub height: f64,
    pub inset: f64,
    pub length: f64,
}

const CORNERS: [(Corner, &str); 4] = [
    (Corner::LowerLeft, "lower-left"),
    (Corner::LowerRight, "lower-right"),
    (Corner::UpperRight, "upper-right"),
    (Corner::UpperLeft, "upper-left"),
];

/// The marks of a `width` × `height` sheet as `r` sets them.
pub fn layout(width: f64, height: f64, r: &Registration) -> Result<Marks, NoRoom> {
    let reach = r.inset + r.length.max(r.square);
    if !(width.is_finite() && height.is_finite())
        || width < 2.0 * reach + r.clearance
        || height < 2.0 * reach + r.clearance
    {
        return Err(NoRoom {
            width,
            height,
            inset: r.inset,
            length: r.length,
        });
    }
    let start = CORNERS
        .iter()
        .position(|(c, _)| *c == r.square_corner)
        .unwrap_or(0);
    let mut marks = Vec::with_capacity(4);
    for k in 0..4 {
        let (_, name) = CORNERS[(start + k) % 4];
        // The corner's outer point and the directions into the sheet.
        let sx = if name.ends_with("left") { 1.0 } else { -1.0 };
        let sy = if name.starts_with("lower") { 1.0 } else { -1.0 };
        let o = DVec2::new(
            if sx > 0.0 { r.inset } else { width - r.inset },
            if sy > 0.0 { r.inset } else { height - r.inset },
        );
        let rect = |a: DVec2, b: DVec2| (a.min(b), a.max(b));
        let d = DVec2::new(sx, sy);
        let mark = if k == 0 {
            Mark {
                kind: MarkKind::Square,
                corner: name,
                reference: o + d * (r.square / 2.0),
                rects: vec![rect(o, o + d * r.square)],
            }
        } else {
            Mark {
                kind: MarkKind::L,
                corner: name,
                reference: o,
                rects: vec![
                    rect(o, o + DVec2::new(sx * r.length, sy * r.width)),
                    rect(o, o + DVec2::new(sx * r.width, sy * r.length)),
                ],
            }
        };
        marks.push(mark);
    }
    Ok(Marks {
        width,
        height,
        marks,
        margin: r.inset + r.square.max(r.width) + r.clearance,
    })
}

impl Marks {
    /// The reference points, in mark order.
    pub fn references(&self) -> Vec<DVec2> {
        self.marks.iter().map(|m| m.reference).collect()
    }

    /// The marks as printed strokes: each rectangle filled by strokes [`SIZE_STROKE_MM`] wide
    /// along its long side (one for an L's arm), drawn with the pictures' round caps.
    pub fn strokes(&self) -> Vec<Stroke> {
        let w = SIZE_STROKE_MM;
        let mut out = Vec::new();
        for m in &self.marks {
            for &(lo, hi) in &m.rects {
                let size = hi - lo;
                let along_x = size.x >= size.y;
                let (long, short) = if along_x {
                    (size.x, size.y)
                } else {
                    (size.y, size.x)
                };
                // Strokes centred w/2 in from the short ends and spread across the short side.
                let n = ((short - w) / (0.8 * w)).ceil().max(0.0) as usize + 1;
                for i in 0..n {
                    let across = if n == 1 {
                        short / 2.0
                    } else {
                        w / 2.0 + (short - w) * i as f64 / (n - 1) as f64
                    };
                    let (a, b) = (w / 2.0, (long - w / 2.0).max(w / 2.0));
                    let pts = if along_x {
                        [lo + DVec2::new(a, across), lo + DVec2::new(b, across)]
                    } else {
                        [lo + DVec2::new(across, a), lo + DVec2::new(across, b)]
                    };
                    out.push(Stroke {
                        role: StrokeRole::Register,
                        points: pts.to_vec(),
                        closed: false,
                        piece: None,
                        outer: false,
                    });
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_marks_square_first_inside_the_margin() {
        let r = Registration::default();
        let m = layout(210.0, 297.0, &r).unwrap();
        assert_eq!(m.marks.len(), 4);
        assert_eq!(m.marks[0].kind, MarkKind::Square);
        assert_eq!(m.marks[0].corner, "upper-left");
        assert_eq!(m.marks[0].reference, DVec2::new(12.5, 284.5));
        assert_eq!(m.marks[1].corner, "lower-left");
        assert_eq!(m.marks[1].reference, DVec2::new(10.0, 10.0));
        assert_eq!(m.marks[2].reference, DVec2::new(200.0, 10.0));
        assert_eq!(m.marks[3].reference, DVec2::new(200.0, 287.0));
        assert_eq!(m.margin, 17.0);
        // Every mark lies within its rectangles' band: closer to the edge than the margin.
        for mk in &m.marks {
            for (lo, hi) in &mk.rects {
                let inner = |p: DVec2| p.x.min(p.y).min(210.0 - p.x).min(297.0 - p.y);
                assert!(inner(*lo).min(inner(*hi)) >= 10.0 - 1e-12);
                assert!(
                    lo.x.min(210.0 - hi.x) <= m.margin - r.clearance + 1e-12
                        || lo.y.min(297.0 - hi.y) <= m.margin - r.clearance + 1e-12
                );
            }
        }
        // The strokes fill the rectangles (ends and sides at w/2 in).
        let s = m.strokes();
        assert!(s.iter().all(|s| s.role == StrokeRole::Register));
        let sq: Vec<&Stroke> = s
            .iter()
            .filter(|s| s.points[0].y > 270.0 && s.points[0].x < 20.0)
            .collect();
        assert_eq!(sq.len(), 6, "{sq:?}");
        assert!((sq[0].points[0].y - 282.5).abs() < 1e-12);
        assert!((sq[5].points[0].y - 286.5).abs() < 1e-12);
        let other = layout(
            300.0,
            300.0,
            &Registration {
                square_corner: Corner::LowerRight,
                ..r.clone()
            },
        )
        .unwrap();
        assert_eq!(other.marks[0].corner, "lower-right");
        assert_eq!(other.marks[0].reference, DVec2::new(287.5, 12.5));
        assert!(layout(50.0, 297.0, &r)
            .unwrap_err()
            .to_string()
            .contains("--mark-inset"));
    }
}
