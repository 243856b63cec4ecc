//! Print-and-cut (issue 25 item 4) as the pipeline composes it: the sheet printed with
//! registration marks, the cutter given only what it cuts, placed where the marks were found.
//!
//! - [`plan`](super::plan) with [`Toolpath::print_and_cut`](super::Toolpath): the nest's
//!   margin grows to keep pieces off the marks ([`Marks::margin`]); everything that is printed
//!   — labels, ids, folds, seam and grain lines — stays in the job whatever tools the device
//!   has (a printer draws them), and each sheet gets its marks
//!   ([`crate::toolpath::registration`]). The pictures (PDF 1:1, SVG, PNG) are that job.
//! - [`cutter_job`]: what goes to the cutter, in sheet millimetres: the cut strokes (outlines,
//!   holes, notches, weed lines) and, when the device has a scoring tool, the folds; never the
//!   marks or anything drawn. `cut` writes it as the nominal program (`<name>.plt`: where the
//!   cuts go if the printed sheet lies exactly at the machine's origin).
//! - [`register`]: the marks' measured positions (machine millimetres, from `--marks` or a
//!   sensor) against where they were printed: the least-squares similarity
//!   ([`crate::geom::similarity`]) from the sheet onto the machine, refused — before anything
//!   is sent — when a mark is off the media or off the sheet (loaded with its lower-left
//!   corner within the profile's `search` distance of the machine's origin), two marks coincide, the scale is
//!   beyond the profile's `max_scale_error` (±1 %) or a mark's residual beyond its
//!   `tolerance` (0.3 mm), naming the residual and the worst mark.
//! - [`registered_program`]: the cutter's job moved by the fit, then made as the device makes
//!   it (knife offset, overcut: after the move, in the machine's frame) and encoded.
//!
//! Frames: a measured position is in the machine's own axes and millimetres (what its display
//! or `?` status shows); it is taken back to the sheet frame by undoing the profile's axes
//! ([`machine_to_sheet`]), so the fit is a similarity of the sheet frame (an axis flip
//! conjugates a rotation into a rotation), and the moved job is encoded as any other.

use super::{Folds, Profile, Spec, Toolpath};
use crate::geom::similarity::{self, Fit, Similarity};
use crate::toolpath::registration::{self, Marks};
use crate::toolpath::{Job, SheetJob, StrokeKind, StrokeRole};
use crate::Error;
use glam::DVec2;
use serde_json::{json, Value};

/// What a print-and-cut run keeps for the send.
#[derive(Debug, Clone)]
pub struct PrintCut {
    /// The marks of each sheet.
    pub marks: Vec<Marks>,
    /// What the cutter makes, per sheet, in sheet mm, before registration.
    pub cutter: Job,
    /// The spec's margin (the knife's alignment precut goes there, outside the marks' inset).
    pub margin: f64,
}

impl PrintCut {
    /// The marks and the cutter's job of a planned print-and-cut `job` (marks added).
    pub(super) fn of(job: &Job, spec: &Spec, profile: &Profile) -> Result<PrintCut, Error> {
        let mut marks = Vec::with_capacity(job.sheets.len());
        for (i, s) in job.sheets.iter().enumerate() {
            marks.push(
                registration::layout(s.width, s.height, &profile.registration)
                    .map_err(|e| Error::Usage(format!("sheet {}: {e}", i + 1)))?,
            );
        }
        Ok(PrintCut {
            marks,
            cutter: cutter_job(job, profile),
            margin: spec.sheet.margin,
        })
    }
}

/// The spec as a print-and-cut job on `profile` is split and nested: its margin the spec's,
/// or more to clear the marks (a roll's marks are laid out on the length used).
pub(super) fn spec_with_margin(spec: &Spec, profile: &Profile) -> Spec {
    let r = &profile.registration;
    let clear = r.inset + r.square.max(r.width) + r.clearance;
    let mut s = spec.clone();
    s.sheet.margin = spec.sheet.margin.max(clear);
    s
}

/// The toolpath options of a print-and-cut job: everything printed is kept.
pub(super) fn printed_options(tp: &mut crate::toolpath::ToolpathOptions, choices: &Toolpath) {
    tp.skip_drawing = false;
    tp.skip_folds = choices.folds == Some(Folds::None);
}

/// The marks of every sheet of `job`, put at the front of its strokes (printed first).
pub(super) fn add_marks(job: &mut Job, profile: &Profile) -> Result<Vec<Marks>, Error> {
    let mut all = Vec::with_capacity(job.sheets.len());
    for (i, sheet) in job.sheets.iter_mut().enumerate() {
        let marks = registration::layout(sheet.width, sheet.height, &profile.registration)
            .map_err(|e| {
                Error::Usage(format!(
                    "sheet {}: {e} (device `{}`, {})",
                    i + 1,
                    profile.name,
                    profile.source
                ))
            })?;
        let mut strokes = marks.strokes();
        strokes.append(&mut sheet.strokes);
        sheet.strokes = strokes;
        all.push(marks);
    }
    Ok(all)
}

/// What goes to the cutter (see the module documentation): cut strokes, and folds when the
/// device has a scoring tool.
pub fn cutter_job(job: &Job, profile: &Profile) -> Job {
    let score = profile.has(StrokeKind::Score);
    let keep = |r: StrokeRole| match r.kind() {
        StrokeKind::Cut => true,
        StrokeKind::Score => score,
        _ => false,
    };
    Job {
        name: job.name.clone(),
        sheets: job
            .sheets
            .iter()
            .map(|s| SheetJob {
                width: s.width,
                height: s.height,
                strokes: s.strokes.iter().filter(|s| keep(s.role)).cloned().collect(),
            })
            .collect(),
    }
}

/// A point of a `w` × `h` sheet in the machine's axes, mm (`output::to_device` without the
/// units).
pub fn sheet_to_machine(profile: &Profile, w: f64, h: f64, p: DVec2) -> DVec2 {
    crate::output::to_device(profile, w, h, p) / profile.units_per_mm
}

/// The inverse of [`sheet_to_machine`].
pub fn machine_to_sheet(profile: &Profile, w: f64, h: f64, m: DVec2) -> DVec2 {
    let axes = &profile.axes;
    let (ext_x, ext_y) = if axes.swap_xy { (h, w) } else { (w, h) };
    let x = if axes.flip_x { ext_x - m.x } else { m.x };
    let y = if axes.flip_y { ext_y - m.y } else { m.y };
    if axes.swap_xy {
        DVec2::new(y, x)
    } else {
        DVec2::new(x, y)
    }
}

/// A sheet registered: its marks where printed and where found, and the fit.
#[derive(Debug, Clone)]
pub struct Registered {
    pub sheet: usize,
    /// Sheet mm.
    pub nominal: Vec<DVec2>,
    /// Machine mm, as measured.
    pub measured: Vec<DVec2>,
    /// Sheet frame: the similarity from where a point was printed to where it lies.
    pub fit: Fit,
    /// Where the marks were measured: `--marks` or the sensor.
    pub source: String,
}

/// Marks closer than this (mm) are taken as one mark measured twice.
pub const COINCIDE_MM: f64 = 1.0;

/// Fit sheet `sheet`'s (0-based) marks to `measured` (machine mm, in mark order; at least 3,
/// at most as many as marks), checked as the module documentation says. `source` names where
/// the positions came from in messages (`--marks`, the sensor).
pub fn register(
    pc: &PrintCut,
    sheet: usize,
    measured: &[DVec2],
    profile: &Profile,
    source: &str,
) -> Result<Registered, Error> {
    let marks = &pc.marks[sheet];
    let r = &profile.registration;
    let n = marks.marks.len();
    let bad = |why: String| Error::Usage(format!("{source}: {why}"));
    if measured.len() < 3 || measured.len() > n {
        return Err(bad(format!(
            "{} mark positions given; sheet {} has {n} marks and the fit needs 3 to {n} of them, in order (1: the square, then the Ls counter-clockwise)",
            measured.len(),
            sheet + 1
        )));
    }
    let (w, h) = (marks.width, marks.height);
    let describe = |k: usize| {
        let m = &marks.marks[k];
        format!(
            "mark {} ({} {})",
            k + 1,
            m.corner,
            match m.kind {
                registration::MarkKind::Square => "square",
                registration::MarkKind::L => "L",
            }
        )
    };
    for (k, q) in measured.iter().enumerate() {
        let over = |v: f64, size: f64| size > 0.0 && v > size + 1e-9;
        if !q.is_finite() || q.x < 0.0 || q.y < 0.0 {
            return Err(bad(format!(
                "{} at ({:.3}, {:.3}) mm is not on the machine (its coordinates start at 0)",
                describe(k),
                q.x,
                q.y
            )));
        }
        let (across, along) = if profile.axes.swap_xy {
            (q.y, q.x)
        } else {
            (q.x, q.y)
        };
        if over(across, profile.media_width) || over(along, profile.media_length) {
            return Err(bad(format!(
                "{} at ({:.3}, {:.3}) mm is outside the media of device `{}` ({} × {} mm)",
                describe(k),
                q.x,
                q.y,
                profile.name,
                profile.media_width,
                profile.media_length
            )));
        }
        let s = machine_to_sheet(profile, w, h, *q);
        let e = r.search;
        if s.x < -e || s.y < -e || s.x > w + e || s.y > h + e {
            return Err(bad(format!(
                "{} at ({:.3}, {:.3}) mm is outside the {w:.0} × {h:.0} mm sheet, which is loaded with its lower-left corner within {e} mm of the machine's origin ([registration] search); was the sheet loaded, or the mark read off, elsewhere?",
                describe(k),
                q.x,
                q.y
            )));
        }
        for (j, p) in measured[..k].iter().enumerate() {
            if p.distance(*q) < COINCIDE_MM {
                return Err(bad(format!(
                    "{} and {} coincide (measured {:.3} mm apart at ({:.3}, {:.3}) mm); each mark is measured where it is",
                    describe(j),
                    describe(k),
                    p.distance(*q),
                    q.x,
                    q.y
                )));
            }
        }
    }
    let nominal: Vec<DVec2> = marks.references()[..measured.len()].to_vec();
    let found: Vec<DVec2> = measured
        .iter()
        .map(|q| machine_to_sheet(profile, w, h, *q))
        .collect();
    let fit = similarity::fit(&nominal, &found)
        .ok_or_else(|| bad("the marks do not fix a placement of the sheet".into()))?;
    let t = &fit.transform;
    let residual = format!(
        "residual {:.3} mm RMS, {:.3} mm at {} (worst)",
        fit.rms,
        fit.max,
        describe(fit.worst)
    );
    if (t.scale - 1.0).abs() > r.max_scale_error {
        return Err(bad(format!(
            "refused before the first cut: the marks say the print is scaled by {:.4} ({:+.2} %), beyond the ±{} % of device `{}` ([registration] max_scale_error, {}); {residual}. Print the PDF at 100 % (no \"fit to page\") and measure again",
            t.scale,
            100.0 * (t.scale - 1.0),
            100.0 * r.max_scale_error,
            profile.name,
            profile.source
        )));
    }
    if fit.max > r.tolerance {
        return Err(bad(format!(
            "refused before the first cut: {residual}, above the {} mm tolerance of device `{}` ([registration] tolerance, {}): no placement of the sheet (moved, turned, scaled) puts the marks where they were measured; measure {} again, or check that the print is not stretched",
            r.tolerance,
            profile.name,
            profile.source,
            describe(fit.worst)
        )));
    }
    Ok(Registered {
        sheet,
        nominal,
        measured: measured.to_vec(),
        fit,
        source: source.to_string(),
    })
}

/// The program for sheet `reg.sheet`: the cutter's job moved by the fit, made as the device
/// makes it, encoded.
pub fn registered_program(
    pc: &PrintCut,
    reg: &Registered,
    profile: &Profile,
) -> Result<Vec<u8>, Error> {
    let sheet = moved(&pc.cutter.sheets[reg.sheet], &reg.fit.transform);
    let job = Job {
        name: pc.cutter.name.clone(),
        sheets: vec![sheet],
    };
    let machine = crate::toolpath::knife::prepare(
        &job,
        &crate::toolpath::knife::MachineOptions::from_profile(profile, pc.margin),
    );
    let bytes = crate::output::program(&machine.sheets[0], profile)
        .map_err(|e| e.on_sheet(reg.sheet + 1))?;
    Ok(bytes)
}

/// A sheet's strokes moved by `t`.
pub fn moved(sheet: &SheetJob, t: &Similarity) -> SheetJob {
    let mut s = sheet.clone();
    for st in &mut s.strokes {
        for p in &mut st.points {
            *p = t.apply(*p);
        }
    }
    s
}

fn xy(p: DVec2) -> Value {
    json!([r4(p.x), r4(p.y)])
}

fn r4(v: f64) -> f64 {
    (v * 1e4).round() / 1e4
}

/// report.json's `registration`: the marks of each sheet and, for the sheets registered,
/// what was measured and the fit.
pub fn report(pc: &PrintCut, profile: &Profile, done: &[Registered]) -> Value {
    let r = &profile.registration;
    let sheets: Vec<Value> = pc
        .marks
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let marks: Vec<Value> = m
                .marks
                .iter()
                .enumerate()
                .map(|(k, mk)| {
                    json!({
                        "mark": k + 1,
                        "kind": mk.kind,
                        "corner": mk.corner,
                        "nominal_mm": xy(mk.reference),
                    })
                })
                .collect();
            let mut v = json!({ "sheet": i + 1, "marks": marks });
            if let Some(reg) = done.iter().find(|d| d.sheet == i) {
                let t = &reg.fit.transform;
                v["measured_by"] = json!(reg.source);
                v["measured_mm"] = json!(reg.measured.iter().map(|p| xy(*p)).collect::<Vec<_>>());
                v["fit"] = json!({
                    "maps": "a printed point p (sheet mm) lies at scale * rotate(p, rotation_deg) + translation_mm, in the sheet's frame",
                    "translation_mm": xy(t.translation),
                    "rotation_deg": (t.angle.to_degrees() * 1e6).round() / 1e6,
                    "scale": (t.scale * 1e7).round() / 1e7,
                    "residuals_mm": reg.fit.residuals.iter().map(|v| r4(*v)).collect::<Vec<_>>(),
                    "rms_mm": r4(reg.fit.rms),
                    "max_mm": r4(reg.fit.max),
                    "worst_mark": reg.fit.worst + 1,
                });
            }
            v
        })
        .collect();
    json!({
        "sensor": r.sensor.name(),
        "mark_inset_mm": r.inset,
        "l_length_mm": r.length,
        "l_width_mm": r.width,
        "square_mm": r.square,
        "tolerance_mm": r.tolerance,
        "max_scale_error": r.max_scale_error,
        "sheets": sheets,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn machine_frame_round_trips() {
        let mut p = crate::profile::find("roland-gx24").unwrap();
        for (swap, fx, fy) in [
            (true, false, false),
            (false, true, true),
            (true, true, false),
        ] {
            p.axes.swap_xy = swap;
            p.axes.flip_x = fx;
            p.axes.flip_y = fy;
            let q = DVec2::new(12.5, 200.25);
            let m = sheet_to_machine(&p, 210.0, 297.0, q);
            assert!(machine_to_sheet(&p, 210.0, 297.0, m).distance(q) < 1e-12);
        }
    }
}
