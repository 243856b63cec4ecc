//! Machines with one tool (issue 23): what a job asks for that the device has no tool to make,
//! and the tool-change passes that make it anyway.
//!
//! A knife-only cutter (Roland, Graphtec, USCutter, a GRBL drag knife) has no tool for the
//! drawn strokes of a job: piece labels, seam ids, bend notes, sewing and grain lines, drawn
//! notches. Makers do one of two things, and flatcut offers both, never silently:
//! - **Leave them out**, with a warning on standard error and in report.json that names, per
//!   piece, what was dropped ([`dropped`]).
//! - **Change the tool** (`--tool-change`): pass 1 draws the marks with a pen put in the knife
//!   holder, the machine stops with the tool up while the operator puts the knife back, pass 2
//!   cuts. [`with_pen`] is the profile of pass 1 (the holder's tool used as the pen) and
//!   [`split`] divides a sheet's strokes between the passes.
//!
//! Choices where makers' practice is silent: the pen of pass 1 goes down and moves as the cut
//! tool does (same holder, same speed; HP-GL and GP-GL: no force is sent, so the one set on
//! the machine for the pen is used; G-code: the knife's Z heights) and makes one pass; it is
//! never blade-compensated (a pen has no trailing tip). A sheet's strokes keep their order
//! within each pass. Folds a fabric job does not give to the knife are drawn in pass 1 too.

use super::{tool_kind, SheetJob, StrokeKind};
use crate::nest::Layout;
use crate::profile::{Profile, Tool};
use serde::Serialize;
use std::collections::BTreeMap;

/// What one piece lost because the device had no tool for it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Dropped {
    /// The piece's id (1-based) and name, as the report and the label name it.
    pub piece: usize,
    pub name: String,
    /// Sheet (1-based) it is on.
    pub sheet: usize,
    /// What was left out: `label`, `edge_ids`, `bend_notes`, `seam_lines`, `grain_lines`,
    /// `notch_marks`, `folds` → how many.
    pub left_out: BTreeMap<&'static str, usize>,
    /// Why, in words.
    pub reason: String,
}

impl Dropped {
    /// `piece 3 (upper): 1 label, 4 edge ids`.
    pub fn describe(&self) -> String {
        let items: Vec<String> = self
            .left_out
            .iter()
            .map(|(k, n)| format!("{n} {}", k.replace('_', " ")))
            .collect();
        format!("piece {} ({}): {}", self.piece, self.name, items.join(", "))
    }
}

/// What each piece of `layout` loses when the drawn strokes (`drawing`) or the folds
/// (`folds`) are left out; `why_drawing` and `why_folds` say why. Pieces that lose nothing are
/// not listed.
pub fn dropped(
    layout: &Layout,
    drawing: bool,
    folds: bool,
    why_drawing: &str,
    why_folds: &str,
) -> Vec<Dropped> {
    let mut out = Vec::new();
    for (k, piece) in layout.pieces.iter().enumerate() {
        let mut left_out = BTreeMap::new();
        let mut reasons = Vec::new();
        if drawing {
            let counts = [
                ("label", 1),
                ("edge_ids", piece.marks.len()),
                ("bend_notes", piece.notes.len()),
                ("seam_lines", piece.seam_line.len()),
                ("grain_lines", piece.grain_line.len()),
                (
                    "notch_marks",
                    piece.notches.iter().filter(|n| !n.cut).count(),
                ),
            ];
            left_out.extend(counts.into_iter().filter(|(_, n)| *n > 0));
            reasons.push(why_drawing);
        }
        if folds && !piece.folds.is_empty() {
            left_out.insert("folds", piece.folds.len());
            reasons.push(why_folds);
        }
        if left_out.is_empty() {
            continue;
        }
        out.push(Dropped {
            piece: piece.id,
            name: piece.name.clone(),
            sheet: layout.placements.get(k).map_or(0, |p| p.sheet) + 1,
            left_out,
            reason: reasons.join("; "),
        });
    }
    out
}

/// The profile of a tool-change job: `profile` with a draw tool that is the cut tool's holder
/// used as a pen (see the module documentation). A profile that has a draw tool is returned as
/// it is.
pub fn with_pen(profile: &Profile) -> Profile {
    let mut p = profile.clone();
    if p.has(StrokeKind::Draw) {
        return p;
    }
    if let Some(cut) = p.tool(StrokeKind::Cut) {
        let pen = Tool {
            force: None,
            passes: Some(1),
            perforation: None,
            ..cut.clone()
        };
        p.tools.insert(StrokeKind::Draw.name().to_string(), pen);
    }
    p
}

/// A sheet's strokes divided between the passes of a tool change: those `profile` makes with
/// its draw tool (pass 1, the pen), then the rest (pass 2, the knife), each in the sheet's order.
pub fn split(sheet: &SheetJob, profile: &Profile) -> (SheetJob, SheetJob) {
    let (pen, knife): (Vec<_>, Vec<_>) = sheet
        .strokes
        .iter()
        .cloned()
        .partition(|s| tool_kind(s.role, |k| profile.has(k)) == Some(StrokeKind::Draw));
    let part = |strokes| SheetJob {
        width: sheet.width,
        height: sheet.height,
        strokes,
    };
    (part(pen), part(knife))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{Stroke, StrokeRole};
    use glam::DVec2;

    fn stroke(role: StrokeRole) -> Stroke {
        Stroke {
            role,
            points: vec![DVec2::ZERO, DVec2::X],
            closed: false,
            piece: Some(0),
            outer: false,
        }
    }

    #[test]
    fn pen_pass_and_knife_pass() {
        let roland = crate::profile::find("roland-gx24").unwrap();
        assert!(!roland.has(StrokeKind::Draw));
        let p = with_pen(&roland);
        let pen = p.tool(StrokeKind::Draw).unwrap();
        let cut = p.tool(StrokeKind::Cut).unwrap();
        assert_eq!((pen.pen, pen.force, pen.speed), (cut.pen, None, cut.speed));
        // A profile with a pen keeps it.
        let sim = crate::profile::find("sim").unwrap();
        assert_eq!(with_pen(&sim), sim);
        let sheet = SheetJob {
            width: 10.0,
            height: 10.0,
            strokes: vec![
                stroke(StrokeRole::Cut),
                stroke(StrokeRole::Label),
                stroke(StrokeRole::FoldValley),
                stroke(StrokeRole::Mark),
            ],
        };
        let (a, b) = split(&sheet, &p);
        let roles = |s: &SheetJob| s.strokes.iter().map(|s| s.role).collect::<Vec<_>>();
        assert_eq!(roles(&a), vec![StrokeRole::Label, StrokeRole::Mark]);
        assert_eq!(roles(&b), vec![StrokeRole::Cut, StrokeRole::FoldValley]);
    }
}
