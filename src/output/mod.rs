//! Output stage: turns a [`Job`](crate::toolpath::Job) into bytes — the program for the cutter
//! ([`program`]: HP-GL / Roland CAMM-GL mode 2 in [`hpgl`], GRBL G-code in `gcode`, Graphtec
//! GP-GL in [`gpgl`]), an SVG
//! document of all sheets ([`svg`]), a 1:1 PDF with a page per sheet and switchable layers
//! ([`pdf`]) and a PNG preview per sheet ([`png`]); a DXF per sheet of
//! the nested layout for CAD/CAM ([`dxf`]); a mesh as Wavefront OBJ, with its flat layout as
//! texture coordinates ([`obj`]); the run's report ([`report`]); the solved spline designs
//! ([`design`], `--spline-json`); and the atomic writing of a run's files ([`files`]).
//! Device units (plotter units, pixels) appear only here; everything upstream is millimetres,
//! x right, y up, origin at the sheet's lower-left corner.
//!
//! Choices shared by the encoders and kept in this module so that they agree:
//! - SVG, PDF and PNG: the colour and dash pattern of each [`StrokeRole`], and the drawing order
//!   (`DRAW_ORDER`: labels, marks, valley folds, mountain folds, cuts — cuts end up on top).
//! - HP-GL and G-code: the sheet-to-machine transform [`to_device`] (DESIGN.md "Devices": the
//!   profile's axes and units), applied to every absolute position, which each encoder then
//!   rounds once (plotter units, or 3 decimals of a mm with [`fmt_mm`]) — rounding never
//!   accumulates along a stroke. A stroke kind that the profile has no tool for is left out; a
//!   tool that lacks what the language needs is an error ([`OutputError::Tool`]), as is a
//!   position beyond what the language can address ([`OutputError::OutOfRange`]).

use crate::profile::{Language, Profile, StrokeKind, Tool};
use crate::toolpath::{SheetJob, Stroke, StrokeRole};
use glam::DVec2;

pub mod design;
pub mod dxf;
pub mod files;
pub(crate) mod gcode;
pub use gcode::reach as gcode_reach;
pub mod gpgl;
pub mod hpgl;
pub mod obj;
pub mod pdf;
pub mod png;
pub mod print;
pub mod report;
pub mod svg;
pub mod texture;

/// Errors of the output stage. Those about a sheet name it by its number as the user sees it
/// (1-based) when known: [`program`] does not know which sheet of the job it encodes, so the
/// caller adds it with [`OutputError::on_sheet`].
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The picture has a zero or non-finite size, or its pixels cannot be allocated.
    #[error("sheet {sheet}: picture of {width_px}×{height_px} px cannot be drawn")]
    Picture {
        sheet: usize,
        width_px: u32,
        height_px: u32,
    },
    /// Tiled printing (`--print`) cannot lay the job out on the paper.
    #[error("--print {paper}: {message}")]
    Print { paper: String, message: String },
    /// The PNG encoder refused the picture.
    #[error("sheet {sheet}: PNG encoding failed: {message}")]
    Encode { sheet: usize, message: String },
    /// The profile's dialect is not one the encoder of its language knows.
    #[error("device `{profile}` ({source_name}): unknown {language} dialect `{dialect}`; known: {known}")]
    Dialect {
        profile: String,
        source_name: String,
        language: &'static str,
        dialect: String,
        known: &'static str,
    },
    /// A tool of the profile lacks a setting the language needs, or has one out of range.
    #[error("device `{profile}` ({source_name}), tool `{kind}`: {message}")]
    Tool {
        profile: String,
        source_name: String,
        kind: String,
        message: String,
    },
    /// An `init` or `end` line of the profile that the language cannot carry.
    #[error("device `{profile}` ({source_name}), {which} line `{line}`: {message}")]
    ProfileLine {
        profile: String,
        source_name: String,
        which: &'static str,
        line: String,
        message: String,
    },
    /// A position of a stroke that the device cannot address: beyond its coordinate range, or
    /// not a number. `stroke` is 1-based in the sheet's cutting order; `value` is in device
    /// units (plotter units, or mm for G-code).
    #[error(
        "{}stroke {stroke} ({role}): coordinate {value} is beyond the ±{limit} {units} that device `{profile}` can address; is a piece placed far from the sheet?",
        sheet_prefix(.sheet)
    )]
    OutOfRange {
        sheet: Option<usize>,
        stroke: usize,
        role: &'static str,
        value: f64,
        limit: f64,
        units: &'static str,
        profile: String,
    },
    /// A file of the run could not be written (or its directory made).
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
}

fn sheet_prefix(sheet: &Option<usize>) -> String {
    sheet.map(|s| format!("sheet {s}, ")).unwrap_or_default()
}

impl OutputError {
    /// The same error, naming the sheet (1-based) where it has no sheet yet.
    pub fn on_sheet(mut self, number: usize) -> Self {
        if let OutputError::OutOfRange { sheet, .. } = &mut self {
            sheet.get_or_insert(number);
        }
        self
    }
}

/// A [`OutputError::Tool`] for the tool of `kind` in `profile`.
pub(crate) fn tool_error(profile: &Profile, kind: &str, message: String) -> OutputError {
    OutputError::Tool {
        profile: profile.name.clone(),
        source_name: profile.source.clone(),
        kind: kind.to_string(),
        message,
    }
}

/// A [`OutputError::ProfileLine`] for an `init` or `end` line of `profile`.
pub(crate) fn line_error(
    profile: &Profile,
    which: &'static str,
    line: &str,
    message: String,
) -> OutputError {
    OutputError::ProfileLine {
        profile: profile.name.clone(),
        source_name: profile.source.clone(),
        which,
        line: line.to_string(),
        message,
    }
}

/// An `init` or `end` line of `profile`, trimmed: one `what` (instruction, block) of the
/// language; a line break inside it is an [`OutputError::ProfileLine`].
pub(crate) fn one_line<'a>(
    profile: &Profile,
    which: &'static str,
    line: &'a str,
    what: &str,
) -> Result<&'a str, OutputError> {
    let t = line.trim();
    if t.contains(['\n', '\r']) {
        return Err(line_error(
            profile,
            which,
            line,
            format!("one {what} per line: split it into several lines"),
        ));
    }
    Ok(t)
}

/// The tool that makes a stroke of `role` on `profile`, with its kind
/// ([`crate::toolpath::tool_kind`]); `None`: the profile has none and the stroke is left out.
pub(crate) fn stroke_tool(profile: &Profile, role: StrokeRole) -> Option<(StrokeKind, &Tool)> {
    let kind = crate::toolpath::tool_kind(role, |k| profile.has(k))?;
    Some((kind, profile.tool(kind)?))
}

/// The device positions ([`to_device`]) of the points of `stroke`, the sheet's stroke `index`
/// (0-based), each coordinate checked with `fits`: the first that does not fit is an
/// [`OutputError::OutOfRange`] that names `limit` in `units`.
pub(crate) fn device_points(
    profile: &Profile,
    sheet: &SheetJob,
    index: usize,
    stroke: &Stroke,
    (limit, units): (f64, &'static str),
    fits: impl Fn(f64) -> bool,
) -> Result<Vec<DVec2>, OutputError> {
    let mut out = Vec::with_capacity(stroke.points.len());
    for q in &stroke.points {
        let d = to_device(profile, sheet.width, sheet.height, *q);
        for v in [d.x, d.y] {
            if !fits(v) {
                return Err(OutputError::OutOfRange {
                    sheet: None,
                    stroke: index + 1,
                    role: stroke.role.name(),
                    value: v,
                    limit,
                    units,
                    profile: profile.name.clone(),
                });
            }
        }
        out.push(d);
    }
    Ok(out)
}

/// [`device_points`] of a stroke for a language with integer steps (HP-GL plotter units, GP-GL
/// steps): each rounded once from its absolute position, within ±`limit`, repeats dropped.
pub(crate) fn integer_steps(
    profile: &Profile,
    sheet: &SheetJob,
    index: usize,
    stroke: &Stroke,
    (limit, units): (f64, &'static str),
) -> Result<Vec<(i64, i64)>, OutputError> {
    let fits = |v: f64| v.round().is_finite() && v.round().abs() <= limit;
    let mut pts: Vec<(i64, i64)> =
        device_points(profile, sheet, index, stroke, (limit, units), fits)?
            .iter()
            .map(|d| (d.x.round() as i64, d.y.round() as i64))
            .collect();
    pts.dedup();
    Ok(pts)
}

/// The program for one sheet in the profile's language: HP-GL or Roland CAMM-GL mode 2
/// (`hpgl::emit`), GRBL G-code (`gcode::emit`) or Graphtec GP-GL ([`gpgl`]), by
/// `profile.language` and `profile.dialect`.
pub fn program(sheet: &SheetJob, profile: &Profile) -> Result<Vec<u8>, OutputError> {
    match profile.language {
        Language::Hpgl => hpgl::emit(sheet, profile),
        Language::Gcode => gcode::emit(sheet, profile),
        Language::Gpgl => gpgl::emit(sheet, profile),
    }
}

/// A point of a sheet (mm; x right, y up, origin at the lower-left corner; the sheet is
/// `sheet_w` × `sheet_h`, for a roll `sheet_h` is the length used) in the machine's
/// coordinates, unrounded, in device units:
/// 1. if `axes.swap_xy`, x and y are exchanged, and so are the extents (`sheet_h` becomes the
///    extent along X);
/// 2. if `axes.flip_x`, X becomes extent_x − X; if `axes.flip_y`, Y becomes extent_y − Y;
/// 3. both are multiplied by `units_per_mm`.
///
/// The encoders round the result once per absolute position.
pub fn to_device(profile: &Profile, sheet_w: f64, sheet_h: f64, p: DVec2) -> DVec2 {
    let axes = &profile.axes;
    let (mut x, mut y, ext_x, ext_y) = if axes.swap_xy {
        (p.y, p.x, sheet_h, sheet_w)
    } else {
        (p.x, p.y, sheet_w, sheet_h)
    };
    if axes.flip_x {
        x = ext_x - x;
    }
    if axes.flip_y {
        y = ext_y - y;
    }
    DVec2::new(x, y) * profile.units_per_mm
}

/// Roles in drawing order, back to front: what is drawn later lies on top.
/// The SVG layers follow this order too, after the sheet layer.
pub(crate) const DRAW_ORDER: [StrokeRole; 10] = [
    StrokeRole::Register,
    StrokeRole::Label,
    StrokeRole::Mark,
    StrokeRole::Grain,
    StrokeRole::Seam,
    StrokeRole::FoldValley,
    StrokeRole::FoldMountain,
    StrokeRole::Weed,
    StrokeRole::Notch,
    StrokeRole::Cut,
];

/// Colour (sRGB) and dash pattern (mm, on/off pairs; empty = solid) of a role.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RoleStyle {
    pub rgb: [u8; 3],
    pub dash_mm: &'static [f64],
}

impl RoleStyle {
    /// `#rrggbb`.
    pub fn hex(self) -> String {
        let [r, g, b] = self.rgb;
        format!("#{r:02x}{g:02x}{b:02x}")
    }
}

/// Style of each role: cut black; mountain fold red dash-dot; valley fold blue dashed;
/// marks green; labels dark green; notches black; sewing lines brown dashed; grain lines
/// purple; weed lines grey.
pub(crate) fn role_style(role: StrokeRole) -> RoleStyle {
    let (rgb, dash_mm): ([u8; 3], &'static [f64]) = match role {
        StrokeRole::Cut => ([0x00, 0x00, 0x00], &[]),
        StrokeRole::FoldMountain => ([0xd0, 0x00, 0x00], &[3.0, 1.0, 0.5, 1.0]),
        StrokeRole::FoldValley => ([0x00, 0x50, 0xd0], &[2.0, 1.0]),
        StrokeRole::Mark => ([0x00, 0x80, 0x00], &[]),
        StrokeRole::Label => ([0x00, 0x60, 0x00], &[]),
        StrokeRole::Notch => ([0x00, 0x00, 0x00], &[]),
        StrokeRole::Seam => ([0x80, 0x40, 0x00], &[4.0, 1.5]),
        StrokeRole::Grain => ([0x60, 0x00, 0x80], &[]),
        StrokeRole::Weed => ([0x90, 0x90, 0x90], &[]),
        StrokeRole::Register => ([0x00, 0x00, 0x00], &[]),
    };
    RoleStyle { rgb, dash_mm }
}

/// Formats a coordinate in mm with at most 3 decimals, without trailing zeros and without
/// "-0": `12.5`, `0`, `3.142`. Rounding is Rust's `{:.3}` of the `f64`, so the text depends only
/// on the value. A non-finite value prints as `0` so that a document stays well-formed
/// (upstream stages only produce finite coordinates).
pub fn fmt_mm(v: f64) -> String {
    if !v.is_finite() {
        return "0".to_string();
    }
    let mut s = format!("{v:.3}");
    if s.contains('.') {
        let trimmed = s.trim_end_matches('0').trim_end_matches('.').len();
        s.truncate(trimmed);
    }
    if s == "-0" {
        s = "0".to_string();
    }
    s
}

/// Small jobs for the encoders' tests.
#[cfg(test)]
pub(crate) mod fixtures {
    use crate::toolpath::{SheetJob, Stroke, StrokeRole};
    use glam::DVec2;

    /// A stroke through `pts`, closed when it ends where it starts.
    pub fn stroke(role: StrokeRole, pts: &[(f64, f64)]) -> Stroke {
        Stroke {
            role,
            points: pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            closed: pts.len() > 2 && pts.first() == pts.last(),
            piece: None,
            outer: false,
        }
    }

    /// A 100 × 100 mm sheet with these strokes.
    pub fn sheet(strokes: Vec<Stroke>) -> SheetJob {
        SheetJob {
            width: 100.0,
            height: 100.0,
            strokes,
        }
    }

    /// A 200 × 10 mm sheet with one cut along y = `y` from x = 0 to 100 in 8000 steps of
    /// 0.0125 mm (half a plotter unit: rounded increments would drift), and the cut's points.
    pub fn half_unit_steps(y: f64) -> (Vec<(f64, f64)>, SheetJob) {
        let mut pts = Vec::new();
        let mut x = 0.0;
        for _ in 0..=8000 {
            pts.push((x, y));
            x += 0.0125;
        }
        let sheet = SheetJob {
            width: 200.0,
            height: 10.0,
            strokes: vec![stroke(StrokeRole::Cut, &pts)],
        };
        (pts, sheet)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmt_mm_examples() {
        assert_eq!(fmt_mm(12.5), "12.5");
        assert_eq!(fmt_mm(0.0), "0");
        assert_eq!(fmt_mm(-0.0), "0");
        assert_eq!(fmt_mm(-0.0004), "0");
        assert_eq!(fmt_mm(std::f64::consts::PI), "3.142");
        assert_eq!(fmt_mm(100.0), "100");
        assert_eq!(fmt_mm(-7.25), "-7.25");
        assert_eq!(fmt_mm(1.9996), "2");
        assert_eq!(fmt_mm(f64::NAN), "0");
        assert_eq!(fmt_mm(f64::INFINITY), "0");
    }

    #[test]
    fn to_device_maps_the_corners() {
        let base = "name='t'\ndescription='d'\nlanguage='hpgl'\ndialect='hp-gl'\n\
            units_per_mm=40.0\n[tools.cut]\npen=1\n[axes]\n";
        let corners = [(0.0, 0.0), (300.0, 0.0), (300.0, 200.0), (0.0, 200.0)];
        let map = |axes: &str| -> Vec<(f64, f64)> {
            let p = crate::profile::parse(&format!("{base}{axes}"), "test.toml").unwrap();
            corners
                .iter()
                .map(|&(x, y)| {
                    let d = to_device(&p, 300.0, 200.0, DVec2::new(x, y));
                    (d.x, d.y)
                })
                .collect()
        };
        // As is, times 40.
        assert_eq!(
            map(""),
            vec![(0.0, 0.0), (12000.0, 0.0), (12000.0, 8000.0), (0.0, 8000.0)]
        );
        // Swapped: X from the sheet's y, Y from its x.
        assert_eq!(
            map("swap_xy=true\n"),
            vec![(0.0, 0.0), (0.0, 12000.0), (8000.0, 12000.0), (8000.0, 0.0)]
        );
        // Mirrored within the sheet.
        assert_eq!(
            map("flip_x=true\n"),
            vec![(12000.0, 0.0), (0.0, 0.0), (0.0, 8000.0), (12000.0, 8000.0)]
        );
        assert_eq!(
            map("flip_y=true\n"),
            vec![(0.0, 8000.0), (12000.0, 8000.0), (12000.0, 0.0), (0.0, 0.0)]
        );
        // Roll cutter: swap, then Y mirrored across the swapped extent (the sheet's width).
        assert_eq!(
            map("swap_xy=true\nflip_y=true\n"),
            vec![(0.0, 12000.0), (0.0, 0.0), (8000.0, 0.0), (8000.0, 12000.0)]
        );
        // Swap then mirror X uses the sheet's height as X's extent; unrounded.
        let p = crate::profile::parse(&format!("{base}swap_xy=true\nflip_x=true\n"), "test.toml")
            .unwrap();
        let d = to_device(&p, 300.0, 200.0, DVec2::new(0.01, 0.0125));
        assert!((d.x - (200.0 - 0.0125) * 40.0).abs() < 1e-9);
        assert!((d.y - 0.4).abs() < 1e-12);
    }

    #[test]
    fn program_dispatches_on_language() {
        let sheet = SheetJob {
            width: 10.0,
            height: 10.0,
            strokes: vec![],
        };
        let hpgl = crate::profile::parse(
            "name='h'\ndescription='d'\nlanguage='hpgl'\ndialect='hp-gl'\nunits_per_mm=40\n[tools.cut]\npen=1\n",
            "test.toml",
        )
        .unwrap();
        assert_eq!(program(&sheet, &hpgl).unwrap(), b"IN;\nPU;SP0;\n");
        let gcode = crate::profile::parse(
            "name='g'\ndescription='d'\nlanguage='gcode'\ndialect='grbl'\nunits_per_mm=1\nprotocol='grbl-character-counting'\nmax_power=1000\n[tools.cut]\npower=1\nspeed=1\n",
            "test.toml",
        )
        .unwrap();
        assert_eq!(program(&sheet, &gcode).unwrap(), b"G21\nG90\nG94\nM5\nM2\n");
    }

    #[test]
    fn styles() {
        assert_eq!(role_style(StrokeRole::FoldMountain).hex(), "#d00000");
        assert_eq!(role_style(StrokeRole::FoldValley).hex(), "#0050d0");
        assert_eq!(role_style(StrokeRole::Mark).hex(), "#008000");
        assert_eq!(role_style(StrokeRole::Label).hex(), "#006000");
        assert_eq!(role_style(StrokeRole::Cut).hex(), "#000000");
    }
}
