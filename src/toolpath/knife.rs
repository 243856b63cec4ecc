//! What a machine's tools need beyond the ordered design: folds made as perforation dashes,
//! overcut on closed contours, and drag-knife blade-offset compensation with an alignment
//! precut. [`prepare`] turns the ordered [`Job`] (what the pictures show) into the job the
//! output stage encodes (what the machine's holder does); the order is kept.
//!
//! **Drag knife** (the scheme of Inkcut's blade-offset option — the holder runs ahead of the
//! cut by the offset and turns about the corner —; Inkcut's source was not at hand, so the
//! details below are flatcut's): the blade tip trails the
//! holder's axis by `offset` mm and moves only along the line from tip to holder (a tractrix;
//! the simulated cutter models exactly that, `device::sim::record`). To cut a segment `a → b`
//! with the blade already pointing along its direction `d`, the holder runs `a + r·d → b + r·d`
//! (r = offset) and the tip runs `a → b`. At a vertex where the direction turns from `d` to `e`
//! by more than `swivel_threshold_deg`, the holder makes an arc of radius `r` about the vertex
//! from `a + r·d` to `a + r·e`: moving at right angles to the blade, it turns the blade while
//! the tip stays on the vertex. A smaller turn is a straight chord between the same two points
//! (the tip strays by about r·θ²/8: 0.001 mm at 10° and 0.25 mm). The blade keeps its direction
//! while lifted, so it is carried from stroke to stroke, and each stroke starts with a swivel
//! from the carried direction. Its first direction on a sheet is made known by an alignment
//! precut: `PRECUT_MM` along +x in the margin, near the origin, before anything else.
//!
//! Choices where Inkcut is silent or differs: arcs are polylines of at most `ARC_STEP_DEG`
//! per step (holder chord error 0.001 mm at 0.25 mm offset, below one plotter unit); when a
//! tool makes more than one pass, every compensated stroke ends with a swivel back to the
//! direction it started with, so that the encoder's repeat (a closed path goes round again, an
//! open one is lifted and started again) begins with the blade where the first pass had it.
//! Only strokes whose tool is a drag knife are compensated ([`MachineOptions::knife_kinds`]);
//! pens and lasers are not, and move the carried blade only by translation.
//!
//! **Overcut**: a closed cut contour continues past its start along its own first edges for
//! `overcut` mm, so that the last cut meets the first whatever the blade did on entering.
//!
//! **Folds** use the tool `fold_kind` picks; with the perforate tool each
//! fold is cut as dashes of `perforation = [cut_mm, skip_mm]`, starting with a cut at its start
//! and ending with whatever part of a cut is left at its end.

use super::{Job, SheetJob, Stroke, StrokeKind, StrokeRole};
use crate::profile::{Profile, DEFAULT_PERFORATION};
use glam::DVec2;

/// Length of the alignment precut, mm.
pub(crate) const PRECUT_MM: f64 = 5.0;
/// Largest angle of one step of a swivel arc, degrees.
pub(crate) const ARC_STEP_DEG: f64 = 10.0;

/// What the machine's tools need (filled from the device profile: [`MachineOptions::from_profile`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MachineOptions {
    /// The tool kind that makes folds (`None`: folds are left out).
    pub fold_kind: Option<StrokeKind>,
    /// `[cut_mm, skip_mm]` of perforated folds.
    pub perforation: [f64; 2],
    /// Blade offset of the drag knife, mm (0: no compensation).
    pub knife_offset: f64,
    /// Turns sharper than this get a swivel arc, degrees.
    pub swivel_threshold_deg: f64,
    /// Stroke kinds made by the drag knife.
    pub knife_kinds: Vec<StrokeKind>,
    /// Stroke kinds whose tool makes more than one pass.
    pub multi_pass_kinds: Vec<StrokeKind>,
    /// Closed cut contours go on this far past their start, mm.
    pub overcut: f64,
    /// Where the alignment precut starts (sheet mm); it runs `PRECUT_MM` along +x.
    pub precut_at: DVec2,
}

impl Default for MachineOptions {
    fn default() -> Self {
        MachineOptions {
            fold_kind: Some(StrokeKind::Score),
            perforation: DEFAULT_PERFORATION,
            knife_offset: 0.0,
            swivel_threshold_deg: 10.0,
            knife_kinds: Vec::new(),
            multi_pass_kinds: Vec::new(),
            overcut: 0.0,
            precut_at: DVec2::new(2.5, 2.5),
        }
    }
}

impl MachineOptions {
    /// What a machine with `profile` needs ([`prepare`]); `margin` is the sheet margin (mm),
    /// where the alignment precut goes.
    pub fn from_profile(profile: &Profile, margin: f64) -> MachineOptions {
        let fold_kind = super::fold_kind(|k| profile.has(k));
        let kinds = [
            StrokeKind::Cut,
            StrokeKind::Score,
            StrokeKind::Perforate,
            StrokeKind::Draw,
            StrokeKind::Etch,
        ];
        let m = if margin.is_finite() {
            margin.max(0.0)
        } else {
            0.0
        };
        MachineOptions {
            fold_kind,
            perforation: profile
                .tool(StrokeKind::Perforate)
                .map(|t| t.perforation())
                .unwrap_or(DEFAULT_PERFORATION),
            knife_offset: profile.knife_offset,
            swivel_threshold_deg: profile.swivel_threshold_deg,
            knife_kinds: kinds
                .into_iter()
                .filter(|k| profile.is_drag_knife(*k))
                .collect(),
            multi_pass_kinds: kinds
                .into_iter()
                .filter(|k| profile.tool(*k).is_some_and(|t| t.passes() > 1))
                .collect(),
            overcut: profile.overcut,
            // Half way into the margin, far enough right that the trailing tip stays on it.
            precut_at: DVec2::new(0.5 * m + profile.knife_offset, 0.5 * m),
        }
    }

    /// The tool kind of a stroke of `role` (folds: [`MachineOptions::fold_kind`]).
    pub fn kind(&self, role: StrokeRole) -> Option<StrokeKind> {
        match role.kind() {
            StrokeKind::Score => self.fold_kind,
            k => Some(k),
        }
    }

    fn compensates(&self, role: StrokeRole) -> bool {
        self.knife_offset > 0.0
            && self
                .kind(role)
                .is_some_and(|k| self.knife_kinds.contains(&k))
    }
}

/// The job as the machine makes it (see the module documentation).
pub fn prepare(job: &Job, opts: &MachineOptions) -> Job {
    Job {
        name: job.name.clone(),
        sheets: job.sheets.iter().map(|s| prepare_sheet(s, opts)).collect(),
    }
}

/// One sheet of [`prepare`].
pub fn prepare_sheet(sheet: &SheetJob, opts: &MachineOptions) -> SheetJob {
    let mut strokes: Vec<Stroke> = Vec::with_capacity(sheet.strokes.len());
    for s in &sheet.strokes {
        let folds = matches!(s.role, StrokeRole::FoldMountain | StrokeRole::FoldValley);
        if folds && opts.fold_kind == Some(StrokeKind::Perforate) {
            strokes.extend(perforate(s, opts.perforation));
        } else if s.role == StrokeRole::Cut && s.closed && opts.overcut > 0.0 {
            strokes.push(overcut(s, opts.overcut));
        } else {
            strokes.push(s.clone());
        }
    }
    let knife = opts.knife_offset.is_finite()
        && opts.knife_offset > 0.0
        && strokes.iter().any(|s| opts.compensates(s.role));
    if !knife {
        return SheetJob {
            width: sheet.width,
            height: sheet.height,
            strokes,
        };
    }
    let r = opts.knife_offset;
    let threshold = opts.swivel_threshold_deg.to_radians();
    let mut out = Vec::with_capacity(strokes.len() + 1);
    // The precut: the holder runs along +x; the blade, wherever it pointed, ends along +x.
    let p = opts.precut_at;
    out.push(Stroke {
        role: StrokeRole::Cut,
        points: vec![p, p + DVec2::X * PRECUT_MM],
        closed: false,
        piece: None,
        outer: false,
    });
    let mut blade = DVec2::X;
    for s in strokes {
        if !opts.compensates(s.role) || s.points.len() < 2 {
            out.push(s);
            continue;
        }
        let restore = opts
            .kind(s.role)
            .is_some_and(|k| opts.multi_pass_kinds.contains(&k));
        let (points, dir) = compensate(&s.points, blade, r, threshold, restore);
        blade = dir;
        let closed = points.len() > 2 && points.first() == points.last();
        out.push(Stroke {
            points,
            closed,
            ..s
        });
    }
    SheetJob {
        width: sheet.width,
        height: sheet.height,
        strokes: out,
    }
}

/// The holder's path that makes the blade tip cut `tip` (see the module documentation), for a
/// blade pointing along `blade` (unit) at the start; returns it and the blade's direction at
/// the end. `restore`: end with a swivel back to `blade`.
pub fn compensate(
    tip: &[DVec2],
    blade: DVec2,
    r: f64,
    threshold: f64,
    restore: bool,
) -> (Vec<DVec2>, DVec2) {
    let start_blade = blade;
    let mut dir = blade;
    let mut out = vec![tip[0] + dir * r];
    for w in tip.windows(2) {
        let (a, b) = (w[0], w[1]);
        let v = b - a;
        let len = v.length();
        if len < 1e-12 {
            continue;
        }
        let e = v / len;
        turn(&mut out, a, dir, e, r, threshold);
        out.push(b + e * r);
        dir = e;
    }
    if restore {
        if let Some(&end) = tip.last() {
            turn(&mut out, end, dir, start_blade, r, threshold);
            dir = start_blade;
        }
    }
    out.dedup();
    (out, dir)
}

/// Turn the blade about the tip at `at` from `from` to `to`: a swivel arc when sharper than
/// `threshold` (radians), else a chord. The arc's first point is already in `out`.
fn turn(out: &mut Vec<DVec2>, at: DVec2, from: DVec2, to: DVec2, r: f64, threshold: f64) {
    let angle = from.perp_dot(to).atan2(from.dot(to));
    if angle.abs() > threshold {
        let steps = (angle.abs() / ARC_STEP_DEG.to_radians()).ceil().max(1.0) as usize;
        for k in 1..steps {
            let rot = DVec2::from_angle(angle * k as f64 / steps as f64);
            out.push(at + rot.rotate(from) * r);
        }
    }
    out.push(at + to * r);
}

/// A closed contour that goes on along its first edges for `extra` mm.
fn overcut(s: &Stroke, extra: f64) -> Stroke {
    let mut points = s.points.clone();
    let mut left = extra;
    for w in s.points.windows(2) {
        let len = w[0].distance(w[1]);
        if len <= 0.0 {
            continue;
        }
        if len >= left {
            points.push(w[0] + (w[1] - w[0]) * (left / len));
            break;
        }
        points.push(w[1]);
        left -= len;
    }
    Stroke {
        points,
        ..s.clone()
    }
}

/// A fold as dashes: `[cut, skip]` mm, starting with a cut.
fn perforate(s: &Stroke, [cut, skip]: [f64; 2]) -> Vec<Stroke> {
    if !(cut > 0.0 && skip > 0.0 && cut.is_finite() && skip.is_finite()) {
        return vec![s.clone()];
    }
    let mut out = Vec::new();
    let mut dash: Vec<DVec2> = Vec::new();
    // Position along the dash pattern, 0 ≤ phase < cut + skip; cutting while phase < cut.
    let mut phase = 0.0;
    let period = cut + skip;
    let mut flush = |dash: &mut Vec<DVec2>| {
        if dash.len() >= 2 {
            out.push(Stroke {
                points: std::mem::take(dash),
                closed: false,
                ..s.clone()
            });
        }
        dash.clear();
    };
    for w in s.points.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = a.distance(b);
        if len <= 0.0 {
            continue;
        }
        let mut t = 0.0;
        while t < len {
            let p = a + (b - a) * (t / len);
            let cutting = phase < cut;
            let boundary = if cutting { cut } else { period };
            let step = (boundary - phase).min(len - t).max(1e-9);
            let q = a + (b - a) * ((t + step) / len);
            if cutting {
                if dash.is_empty() {
                    dash.push(p);
                }
                dash.push(q);
            }
            t += step;
            phase += step;
            if cutting && phase >= cut {
                flush(&mut dash);
            }
            if phase >= period - 1e-12 {
                phase = 0.0;
            }
        }
    }
    flush(&mut dash);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn stroke(role: StrokeRole, pts: &[(f64, f64)], closed: bool) -> Stroke {
        Stroke {
            role,
            points: pts.iter().map(|p| v(p.0, p.1)).collect(),
            closed,
            piece: Some(0),
            outer: closed,
        }
    }

    fn square() -> Stroke {
        stroke(
            StrokeRole::Cut,
            &[
                (0.0, 0.0),
                (10.0, 0.0),
                (10.0, 10.0),
                (0.0, 10.0),
                (0.0, 0.0),
            ],
            true,
        )
    }

    #[test]
    fn holder_runs_ahead_and_swivels_about_the_corners() {
        let (h, dir) = compensate(&square().points, DVec2::X, 0.25, 10f64.to_radians(), false);
        // Starts ahead of the first corner along the blade, ends ahead of it along -y.
        assert_eq!(h[0], v(0.25, 0.0));
        assert_eq!(dir, v(0.0, -1.0));
        assert!(h.last().unwrap().distance(v(0.0, -0.25)) < 1e-12);
        // Every holder point is at the offset from the square's outline or from a corner:
        // straight runs are the edges shifted along themselves, arcs are about corners.
        for p in &h {
            let corner = [v(0.0, 0.0), v(10.0, 0.0), v(10.0, 10.0), v(0.0, 10.0)]
                .iter()
                .map(|c| c.distance(*p))
                .fold(f64::INFINITY, f64::min);
            assert!((corner - 0.25).abs() < 1e-9 || corner > 0.25, "{p}");
        }
        // The arc about (10, 0) goes from (10.25, 0) to (10, 0.25) in 10° steps.
        let mid = v(10.0, 0.0) + DVec2::from_angle(40f64.to_radians()) * 0.25;
        assert!(h.iter().any(|p| p.distance(mid) < 1e-9));
        // A gentle turn is a chord, not an arc.
        let (h, _) = compensate(
            &[v(0.0, 0.0), v(10.0, 0.0), v(20.0, 1.0)],
            DVec2::X,
            0.25,
            10f64.to_radians(),
            false,
        );
        assert_eq!(h.len(), 4);
    }

    #[test]
    fn passes_restore_the_blade_so_the_repeat_starts_right() {
        let (h, dir) = compensate(&square().points, DVec2::X, 0.25, 10f64.to_radians(), true);
        assert_eq!(dir, DVec2::X);
        assert_eq!(h.first(), h.last(), "closed: the encoder goes round again");
    }

    #[test]
    fn prepare_adds_precut_overcut_and_keeps_the_rest() {
        let sheet = SheetJob {
            width: 100.0,
            height: 100.0,
            strokes: vec![
                stroke(StrokeRole::Mark, &[(1.0, 1.0), (2.0, 1.0)], false),
                square(),
            ],
        };
        let opts = MachineOptions {
            knife_offset: 0.25,
            knife_kinds: vec![StrokeKind::Cut],
            overcut: 1.0,
            ..MachineOptions::default()
        };
        let out = prepare_sheet(&sheet, &opts);
        assert_eq!(out.strokes.len(), 3);
        assert_eq!(out.strokes[0].points, vec![v(2.5, 2.5), v(7.5, 2.5)]);
        assert_eq!(out.strokes[1], sheet.strokes[0], "a pen is not compensated");
        // Overcut: the tip ends 1 mm along the first edge, so the holder 1.25 mm.
        assert!(
            out.strokes[2].points.last().unwrap().distance(v(1.25, 0.0)) < 1e-12,
            "{:?}",
            out.strokes[2].points.last()
        );
        // Without an offset only the overcut is added.
        let plain = prepare_sheet(
            &sheet,
            &MachineOptions {
                overcut: 1.0,
                ..MachineOptions::default()
            },
        );
        assert_eq!(plain.strokes.len(), 2);
        assert_eq!(plain.strokes[1].points.len(), 6);
        assert_eq!(plain.strokes[1].points[5], v(1.0, 0.0));
    }

    #[test]
    fn perforated_folds_are_dashes() {
        let fold = stroke(StrokeRole::FoldValley, &[(0.0, 0.0), (10.0, 0.0)], false);
        let dashes = perforate(&fold, [3.0, 1.0]);
        let spans: Vec<(f64, f64)> = dashes
            .iter()
            .map(|d| (d.points[0].x, d.points.last().unwrap().x))
            .collect();
        assert_eq!(spans, vec![(0.0, 3.0), (4.0, 7.0), (8.0, 10.0)]);
        assert!(dashes.iter().all(|d| d.role == StrokeRole::FoldValley));
        // Across a bend of the polyline, a dash follows it.
        let bent = stroke(
            StrokeRole::FoldMountain,
            &[(0.0, 0.0), (2.0, 0.0), (2.0, 5.0)],
            false,
        );
        let dashes = perforate(&bent, [3.0, 1.0]);
        assert_eq!(
            dashes[0].points,
            vec![v(0.0, 0.0), v(2.0, 0.0), v(2.0, 1.0)]
        );
        assert_eq!(dashes[1].points, vec![v(2.0, 2.0), v(2.0, 5.0)]);
        let sheet = SheetJob {
            width: 20.0,
            height: 20.0,
            strokes: vec![fold],
        };
        let opts = MachineOptions {
            fold_kind: Some(StrokeKind::Perforate),
            ..MachineOptions::default()
        };
        assert_eq!(prepare_sheet(&sheet, &opts).strokes.len(), 3);
    }
}
