//! HP-GL programs, plain (dialect `hp-gl`) and Roland CAMM-GL mode 2 (dialect `camm-gl2`), one
//! instruction per line:
//!
//! ```text
//! IN;                      initialise (absolute coordinates, pen up)
//! <profile init lines>     verbatim, `;` added where missing
//! SP1;                     pen select, when the pen changes
//! VS20;                    velocity, cm/s, when the tool's speed differs from the one in effect
//! FS120;                   force (camm-gl2: `!FS120;`), when it differs from the one in effect
//! PU400,400;               pen-up move to the start of a stroke
//! PD800,400,800,800;       pen-down moves along it, at most 32 points per instruction
//! PU;                      } only when the profile has `end` lines: pen up first,
//! <profile end lines>      } then the user's lines
//! PU;SP0;                  always last: pen up, pen put away
//! ```
//!
//! Coordinates are absolute, in plotter units: each point goes through
//! [`super::to_device`] (the profile's axes and units per mm, 40 for HP-GL's
//! 0.025 mm plotter unit) and is rounded once, from the absolute position, so rounding never
//! accumulates. A point repeated after rounding is sent once. A stroke of one point is a dot:
//! `PU x,y;` then `PD x,y;`.
//!
//! Documentation followed:
//! - HP-GL: HP 7475A Interfacing and Programming Manual (`IN`, `SP`, `PU`/`PD` with coordinate
//!   pairs, `VS` in cm/s, the plotter unit of 0.025 mm).
//! - Roland CAMM-GL mode 2: Roland's CAMM-GL II Programmer's Guide as summarised in
//!   Ti-Ion/EGX-300-USB-Drive `CAMM-GL2_REFERENCE.md` (mode 2 instructions are two letters
//!   ended by `;`; `!`-prefixed instructions work in either mode; `IN` restores the defaults,
//!   absolute coordinates and the tool up); the GX-24 programs written by MIT's fab modules
//!   (`fab_write_camm` in fab.c, and mods' `mod_Roland_GX_24_path`: `PA;PA;!ST1;!FS<gf>;VS<cm/s>;`
//!   then `PU`/`PD` at 40 units per mm), which is where `!FS` for the force in grams comes from;
//!   Inkcut's Roland driver (inkcut/device/protocols/camm.py) also starts with `IN;` and sets
//!   `VS` and `SP`. The coordinate range, ±(2^26 − 1), is the one of CAMM-GL III's instruction
//!   list (Roland PNC-900 CAMM-1 User's Manual, "List of CAMM-GL III instructions", note *1).
//!
//! Choices where the documents are silent or disagree:
//! - `FS` (plain HP-GL): its unit is the device's (HP pen plotters take a level, most HP-GL
//!   vinyl cutters grams); the profile's `force` is sent as is, rounded to a whole number.
//!   camm-gl2 sends `!FS` instead, in grams (fab modules), and not the `!ST1` that fab modules
//!   also send, whose meaning is not documented in the sources above (a profile can put it in
//!   `init`). `VS` is sent with up to 3 decimals, trailing zeros trimmed.
//! - VS and FS are stateful on the device, so they are sent when a stroke's tool asks for a
//!   value other than the one in effect (the first time after `IN;`, and when the tool
//!   changes to one with other settings). A tool without `speed` or `force` leaves the value
//!   in effect (the previous tool's, or the machine panel's).
//! - `passes`: a closed stroke (its last point, after rounding, is its first) goes round again
//!   without lifting; an open one is lifted, moved back to its start and cut again.
//! - `end` lines come after a `PU;` so that a user's page feed or move home happens with the
//!   tool up, and the program still ends with `PU;SP0;` whatever those lines did.
//! - `PD` instructions carry at most 32 points, because some cutters limit the length of an
//!   instruction. A stroke kind the profile has no tool for is left out; a tool without `pen`
//!   is an error, as is a coordinate beyond ±(2^23 − 1) plotter units in plain HP-GL (a
//!   conservative bound: HP-GL devices differ, 2^23 units is 209 m at 40 per mm).
//!
//! [`read`] is the one HP-GL reader (instructions, numbers, pen-down paths) that the tests and
//! the simulated cutter use.

use super::{integer_steps, one_line, stroke_tool, tool_error, OutputError};
use crate::profile::{Profile, Tool};
use crate::toolpath::SheetJob;
use std::fmt::Write;

pub mod read;
pub use read::{parse, ParsedStroke};

/// Points per `PD` instruction.
const PD_POINTS: usize = 32;

/// Largest coordinate magnitude, plotter units, of plain HP-GL.
pub(crate) const HPGL_LIMIT: i64 = (1 << 23) - 1;
/// Largest coordinate magnitude, plotter units, of Roland CAMM-GL (mode 2).
pub(crate) const CAMM_LIMIT: i64 = (1 << 26) - 1;

/// The HP-GL dialects flatcut writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Dialect {
    /// Plain HP-GL (`hp-gl`).
    Hpgl,
    /// Roland CAMM-GL mode 2 (`camm-gl2`).
    CammGl2,
}

impl Dialect {
    /// The dialect a profile names.
    pub fn of(profile: &Profile) -> Result<Dialect, OutputError> {
        match profile.dialect.as_str() {
            "hp-gl" => Ok(Dialect::Hpgl),
            "camm-gl2" => Ok(Dialect::CammGl2),
            other => Err(OutputError::Dialect {
                profile: profile.name.clone(),
                source_name: profile.source.clone(),
                language: "HP-GL",
                dialect: other.to_string(),
                known: "hp-gl, camm-gl2",
            }),
        }
    }

    /// Largest coordinate magnitude in plotter units.
    pub fn limit(self) -> i64 {
        match self {
            Dialect::Hpgl => HPGL_LIMIT,
            Dialect::CammGl2 => CAMM_LIMIT,
        }
    }

    /// The force instruction's mnemonic.
    fn force_op(self) -> &'static str {
        match self {
            Dialect::Hpgl => "FS",
            Dialect::CammGl2 => "!FS",
        }
    }
}

/// What an HP-GL program uses of a tool, checked.
struct HpglTool {
    pen: u32,
    speed: Option<String>,
    force: Option<String>,
    passes: u32,
}

fn check_tool(profile: &Profile, kind: &str, tool: &Tool) -> Result<HpglTool, OutputError> {
    let err = |m: String| tool_error(profile, kind, m);
    let pen = tool
        .pen
        .ok_or_else(|| err("no `pen`: HP-GL selects the tool with `SP<pen>`".into()))?;
    let speed = match tool.speed {
        Some(v) if !(v.is_finite() && v > 0.0) => {
            return Err(err(format!(
                "`speed` must be a positive number of cm/s, got {v}"
            )))
        }
        Some(v) => Some(super::fmt_mm(v)),
        None => None,
    };
    let force = match tool.force {
        Some(v) if !(0.0..1e6).contains(&v) => {
            return Err(err(format!(
                "`force` must be a number of grams ≥ 0, got {v}"
            )))
        }
        Some(v) => Some(format!("{}", v.round() as i64)),
        None => None,
    };
    let passes = tool.passes.unwrap_or(1);
    if passes == 0 {
        return Err(err("`passes` must be at least 1".into()));
    }
    Ok(HpglTool {
        pen,
        speed,
        force,
        passes,
    })
}

/// An `init`/`end` line as one terminated instruction line.
fn profile_line(profile: &Profile, which: &'static str, line: &str) -> Result<String, OutputError> {
    let t = one_line(profile, which, line, "instruction")?;
    Ok(if t.ends_with(';') {
        t.to_string()
    } else {
        format!("{t};")
    })
}

/// Encode one sheet's strokes (see the module documentation for the exact text).
pub(crate) fn emit(sheet: &SheetJob, profile: &Profile) -> Result<Vec<u8>, OutputError> {
    let dialect = Dialect::of(profile)?;
    let limit = dialect.limit();
    let mut out = String::from("IN;\n");
    for line in &profile.init {
        if !line.trim().is_empty() {
            out.push_str(&profile_line(profile, "init", line)?);
            out.push('\n');
        }
    }
    let mut pen: Option<u32> = None;
    let mut speed: Option<String> = None;
    let mut force: Option<String> = None;
    for (index, stroke) in sheet.strokes.iter().enumerate() {
        let Some((kind, tool)) = stroke_tool(profile, stroke.role) else {
            continue;
        };
        let tool = check_tool(profile, kind.name(), tool)?;
        let range = (limit as f64, "plotter units");
        let pts = integer_steps(profile, sheet, index, stroke, range)?;
        let Some(&(x0, y0)) = pts.first() else {
            continue;
        };
        if pen != Some(tool.pen) {
            let _ = writeln!(out, "SP{};", tool.pen);
            pen = Some(tool.pen);
        }
        if tool.speed.is_some() && tool.speed != speed {
            let _ = writeln!(out, "VS{};", tool.speed.as_deref().unwrap_or_default());
            speed = tool.speed.clone();
        }
        if tool.force.is_some() && tool.force != force {
            let f = tool.force.as_deref().unwrap_or_default();
            let _ = writeln!(out, "{}{f};", dialect.force_op());
            force = tool.force.clone();
        }
        let closed = pts.len() > 2 && pts.first() == pts.last();
        for pass in 0..tool.passes {
            if pass == 0 || !closed {
                let _ = writeln!(out, "PU{x0},{y0};");
            }
            if pts.len() == 1 {
                // A dot: put the tool down where it is.
                let _ = writeln!(out, "PD{x0},{y0};");
                continue;
            }
            for chunk in pts[1..].chunks(PD_POINTS) {
                out.push_str("PD");
                for (i, (x, y)) in chunk.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    let _ = write!(out, "{x},{y}");
                }
                out.push_str(";\n");
            }
        }
    }
    let end: Vec<&String> = profile
        .end
        .iter()
        .filter(|l| !l.trim().is_empty())
        .collect();
    if !end.is_empty() {
        out.push_str("PU;\n");
        for line in end {
            out.push_str(&profile_line(profile, "end", line)?);
            out.push('\n');
        }
    }
    out.push_str("PU;SP0;\n");
    Ok(out.into_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::fixtures::{half_unit_steps, sheet, stroke};
    use crate::profile::parse as parse_profile;
    use crate::toolpath::StrokeRole;

    /// The bundled `hpgl-pens` profile as it was when the exact text below was pinned: pens
    /// only, no axes, no init or end.
    const PENS: &str = "name='hpgl-pens'\ndescription='d'\nlanguage='hpgl'\ndialect='hp-gl'\n\
        units_per_mm=40.0\n[tools.cut]\npen=1\n[tools.score]\npen=2\n[tools.draw]\npen=3\n";

    fn text(sheet: &SheetJob, profile_text: &str) -> String {
        let profile = parse_profile(profile_text, "test.toml").unwrap();
        String::from_utf8(emit(sheet, &profile).unwrap()).unwrap()
    }

    fn small_job() -> SheetJob {
        sheet(vec![
            stroke(StrokeRole::Label, &[(1.0, 1.0), (2.0, 1.0)]),
            stroke(
                StrokeRole::Cut,
                &[(10.0, 10.0), (20.012, 10.0), (20.0, 20.0), (10.0, 10.0)],
            ),
        ])
    }

    #[test]
    fn pens_units_and_end() {
        let text = text(&small_job(), PENS);
        assert_eq!(
            text,
            "IN;\nSP3;\nPU40,40;\nPD80,40;\nSP1;\nPU400,400;\nPD800,400,800,800,400,400;\nPU;SP0;\n"
        );
        let back = parse(&text).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[1].pen, 1);
        assert_eq!(
            back[1].points,
            vec![(400, 400), (800, 400), (800, 800), (400, 400)]
        );
    }

    #[test]
    fn bundled_hpgl_pens_keeps_its_frame() {
        let profile = crate::profile::find("hpgl-pens").unwrap();
        let text = String::from_utf8(emit(&small_job(), &profile).unwrap()).unwrap();
        assert!(text.starts_with("IN;\n"), "{text}");
        assert!(text.ends_with("PU;SP0;\n"), "{text}");
        let back = parse(&text).unwrap();
        assert_eq!(back.iter().map(|s| s.pen).collect::<Vec<_>>(), vec![3, 1]);
    }

    const CUTTER: &str = "name='c'\ndescription='d'\nlanguage='hpgl'\ndialect='hp-gl'\n\
        units_per_mm=40.0\ninit=['!ST1', 'VS5;']\nend=['PU0,0']\n\
        [tools.cut]\npen=1\nforce=120\nspeed=20\n\
        [tools.score]\npen=1\nforce=50.4\nspeed=20\npasses=2\n\
        [tools.draw]\npen=2\nspeed=12.5\n";

    #[test]
    fn plain_hpgl_force_speed_passes_init_end() {
        let sheet = sheet(vec![
            stroke(StrokeRole::Cut, &[(1.0, 1.0), (2.0, 1.0)]),
            stroke(StrokeRole::Cut, &[(3.0, 1.0), (4.0, 1.0)]),
            stroke(StrokeRole::FoldValley, &[(1.0, 2.0), (2.0, 2.0)]),
            stroke(
                StrokeRole::FoldMountain,
                &[(1.0, 3.0), (2.0, 3.0), (2.0, 4.0), (1.0, 3.0)],
            ),
            stroke(StrokeRole::Mark, &[(5.0, 5.0)]),
            stroke(StrokeRole::Cut, &[(6.0, 6.0), (7.0, 6.0)]),
        ]);
        let t = text(&sheet, CUTTER);
        assert_eq!(
            t,
            "IN;\n!ST1;\nVS5;\n\
             SP1;\nVS20;\nFS120;\nPU40,40;\nPD80,40;\n\
             PU120,40;\nPD160,40;\n\
             FS50;\nPU40,80;\nPD80,80;\nPU40,80;\nPD80,80;\n\
             PU40,120;\nPD80,120,80,160,40,120;\nPD80,120,80,160,40,120;\n\
             SP2;\nVS12.5;\nPU200,200;\nPD200,200;\n\
             SP1;\nVS20;\nFS120;\nPU240,240;\nPD280,240;\n\
             PU;\nPU0,0;\nPU;SP0;\n"
        );
        let back = parse(&t).unwrap();
        assert_eq!(back.len(), 7);
        assert_eq!((back[0].speed, back[0].force), (Some(20.0), Some(120.0)));
        assert_eq!((back[2].speed, back[2].force), (Some(20.0), Some(50.0)));
        assert_eq!(back[2], back[3]);
        assert_eq!(back[4].points.len(), 7);
        assert_eq!((back[5].pen, back[5].speed), (2, Some(12.5)));
        assert_eq!(back[5].points, vec![(200, 200), (200, 200)]);
        assert_eq!(back[6].force, Some(120.0));
    }

    #[test]
    fn camm_gl2_uses_roland_force() {
        let profile = CUTTER
            .replace("dialect='hp-gl'", "dialect='camm-gl2'")
            .replace("init=['!ST1', 'VS5;']\nend=['PU0,0']\n", "");
        let t = text(
            &sheet(vec![stroke(StrokeRole::Cut, &[(1.0, 1.0), (2.0, 1.0)])]),
            &profile,
        );
        assert_eq!(
            t,
            "IN;\nSP1;\nVS20;\n!FS120;\nPU40,40;\nPD80,40;\nPU;SP0;\n"
        );
        let back = parse(&t).unwrap();
        assert_eq!(back[0].force, Some(120.0));
    }

    #[test]
    fn unknown_dialect_and_unusable_tools_are_errors() {
        let sheet = sheet(vec![stroke(StrokeRole::Cut, &[(1.0, 1.0), (2.0, 1.0)])]);
        // Profiles are validated when read; a profile built in code still meets these checks.
        let mut p = parse_profile(PENS, "test.toml").unwrap();
        p.dialect = "dmpl".into();
        let e = emit(&sheet, &p).unwrap_err().to_string();
        assert!(
            e.contains("hpgl-pens") && e.contains("`dmpl`") && e.contains("camm-gl2"),
            "{e}"
        );
        let mut p = parse_profile(PENS, "test.toml").unwrap();
        if let Some(t) = p.tools.get_mut("cut") {
            t.pen = None;
            t.speed = Some(3.0);
        }
        let e = emit(&sheet, &p).unwrap_err().to_string();
        assert!(e.contains("tool `cut`") && e.contains("`pen`"), "{e}");
        let mut p = parse_profile(PENS, "t.toml").unwrap();
        if let Some(t) = p.tools.get_mut("cut") {
            t.passes = Some(0);
        }
        assert!(emit(&sheet, &p).unwrap_err().to_string().contains("passes"));
    }

    #[test]
    fn out_of_range_names_sheet_and_stroke() {
        let p = parse_profile(PENS, "test.toml").unwrap();
        let far = sheet(vec![
            stroke(StrokeRole::Cut, &[(1.0, 1.0), (2.0, 1.0)]),
            stroke(StrokeRole::Cut, &[(1.0, 1.0), (300_000.0, 1.0)]),
        ]);
        let e = emit(&far, &p).unwrap_err().on_sheet(3).to_string();
        assert!(
            e.contains("sheet 3, stroke 2 (cut)") && e.contains("8388607"),
            "{e}"
        );
        // Roland addresses further.
        let p = parse_profile(&PENS.replace("'hp-gl'", "'camm-gl2'"), "t.toml").unwrap();
        assert!(emit(&far, &p).is_ok());
        let nan = sheet(vec![stroke(StrokeRole::Cut, &[(1.0, f64::NAN)])]);
        assert!(emit(&nan, &p).is_err());
    }

    #[test]
    fn axes_swap_and_flip() {
        // A 100 × 50 mm sheet on a roll cutter: x along the feed is the sheet's y, and Y is
        // mirrored across the media.
        let profile = format!("{PENS}[axes]\nswap_xy=true\nflip_y=true\n");
        let sheet = SheetJob {
            width: 100.0,
            height: 50.0,
            strokes: vec![stroke(
                StrokeRole::Cut,
                &[(0.0, 0.0), (100.0, 0.0), (100.0, 50.0), (0.0, 50.0)],
            )],
        };
        let back = parse(&text(&sheet, &profile)).unwrap();
        assert_eq!(
            back[0].points,
            vec![(0, 4000), (0, 0), (2000, 0), (2000, 4000)]
        );
    }

    #[test]
    fn absolute_rounding_does_not_drift() {
        // 8000 steps of 0.0125 mm (half a plotter unit): rounded increments would lose or
        // gain up to half a unit per step.
        let (pts, sheet) = half_unit_steps(0.0);
        let t = text(&sheet, PENS);
        let back = parse(&t).unwrap();
        let got = &back[0].points;
        assert_eq!(got.first(), Some(&(0, 0)));
        assert_eq!(got.last(), Some(&(4000, 0)));
        // Every point sent is the rounding of an absolute input position.
        let exact: Vec<i64> = pts.iter().map(|p| (p.0 * 40.0).round() as i64).collect();
        for p in got {
            assert!(exact.contains(&p.0), "{p:?}");
        }
        assert!(got.windows(2).all(|w| w[1].0 > w[0].0));
        // One instruction per line, at most 32 points each.
        for line in t.lines().filter(|l| l.starts_with("PD")) {
            assert!(line.matches(',').count() < 64, "{line}");
            assert_eq!(line.matches(';').count(), 1);
        }
    }

    #[test]
    fn parse_tolerates_extras() {
        let back = parse("IN;!ST1;VS10;FS3;SP1;PA;PU0,0;PD10,0;PA20,0;PU;DF;!PG;").unwrap();
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].points, vec![(0, 0), (10, 0), (20, 0)]);
        assert_eq!((back[0].speed, back[0].force), (Some(10.0), Some(3.0)));
        assert!(parse("PR10,0;").is_err());
    }
}
