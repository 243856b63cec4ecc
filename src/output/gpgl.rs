//! GP-GL programs for Graphtec cutting plotters (CE6000 / CE7000 / FC series) in their native
//! command mode (dialect `graphtec`), one instruction per line, each ended by ETX (0x03):
//!
//! ```text
//! H                        home: tool up, to the origin
//! <profile init lines>     verbatim, ETX added
//! J1                       tool (pen / holder) select, when it changes
//! !20                      speed, cm/s, when the tool's speed differs from the one in effect
//! FX14,1                   force level and the tool it is for, when it differs
//! M400,400                 move with the tool up to the start of a stroke
//! D800,400,800,800         draw with the tool down along it, at most 32 points per instruction
//! M800,800                 } only when the profile has `end` lines: the tool lifted where
//! <profile end lines>      } it is, then the user's lines
//! H                        always last: tool up, home
//! ```
//!
//! Coordinates are absolute, in GP-GL steps: each point goes through [`super::to_device`]
//! (the profile's axes and units per mm) and is rounded once, from the absolute position, so
//! rounding never accumulates. A point repeated after rounding is sent once; a stroke of one
//! point is a dot, `M x,y` then `D x,y`.
//!
//! Documentation followed: the GP-GL instruction summary of Graphtec's command reference as
//! transcribed in dim13's `robo` (doc/gp-gl.txt: `M` move, `D` draw with coordinate lists, `O`
//! and `E` their relative forms, `H` home, `J n` new pen with n = 1..8, `! l` speed, `FC`
//! cutter offset, the terminator ETX 0x03); Inkcut's GP-GL driver
//! (inkcut/device/protocols/gpgl.py: `H` to start, `M`/`D` absolute, `!v` speed, `FX f,1`
//! force). The step size (0.1 mm by default; 0.05, 0.025 or 0.01 mm as set on the cutter's
//! panel) is the profile's `units_per_mm` (10, 20, 40 or 100), checked when it is read.
//!
//! Choices where those sources are silent:
//! - `!` is sent in whole cm/s (the unit of the CE series' speed setting), rounded; a speed
//!   that rounds below 1 is an error. `FX` carries the profile's `force` as the cutter's force
//!   level, a whole number from 1 to [`MAX_FORCE`], and the tool's number as its second
//!   parameter; neither is sent when the tool does not set it (the panel's value stays).
//! - The cutter's own blade-offset compensation (`FC`) is not sent: flatcut compensates the
//!   knife offset in the toolpath stage when the profile has one, so a profile that does so
//!   should switch the machine's off in its `init` lines or on the panel. No origin offset
//!   (`^`) is sent either: positions are absolute from the origin set on the cutter.
//! - A line feed follows each ETX so that the file reads one instruction a line; the reader
//!   here, and the simulated cutter, end an instruction at ETX, LF or CR and skip empty ones.
//! - Coordinates beyond ±(2^23 − 1) steps are an error (a conservative bound: 838 m at 0.1 mm).
//! - `passes`: a closed stroke goes round again without lifting; an open one is lifted, moved
//!   back to its start and drawn again (as `output::hpgl`).
//!
//! [`parse`] reads back the tool-down paths of a program (tests, the simulator's lexer).

use super::{integer_steps, one_line, stroke_tool, tool_error, OutputError};
use crate::profile::{Profile, Tool};
use crate::toolpath::SheetJob;
use std::fmt::Write;

/// The GP-GL terminator, ETX.
pub const ETX: u8 = 0x03;
/// Points per `D` instruction.
const D_POINTS: usize = 32;
/// Largest coordinate magnitude, GP-GL steps.
pub(crate) const GPGL_LIMIT: i64 = (1 << 23) - 1;
/// Largest `FX` force level sent.
pub const MAX_FORCE: f64 = 48.0;
/// Tool numbers `J` takes.
const PENS: std::ops::RangeInclusive<u32> = 1..=8;

/// What a GP-GL program uses of a tool, checked.
struct GpglTool {
    pen: u32,
    speed: Option<i64>,
    force: Option<i64>,
    passes: u32,
}

fn check_tool(profile: &Profile, kind: &str, tool: &Tool) -> Result<GpglTool, OutputError> {
    let err = |m: String| tool_error(profile, kind, m);
    let pen = tool
        .pen
        .ok_or_else(|| err("no `pen`: GP-GL selects the tool with `J<pen>`".into()))?;
    if !PENS.contains(&pen) {
        return Err(err(format!(
            "`pen` must be 1 to 8 for GP-GL `J`, got {pen}"
        )));
    }
    let speed = match tool.speed {
        Some(v) if !(v.is_finite() && v.round() >= 1.0 && v < 1e4) => {
            return Err(err(format!(
                "`speed` must be a whole number of cm/s from 1 (GP-GL `!`), got {v}"
            )))
        }
        Some(v) => Some(v.round() as i64),
        None => None,
    };
    let force = match tool.force {
        Some(v) if !(v.is_finite() && v.round() >= 1.0 && v.round() <= MAX_FORCE) => {
            return Err(err(format!(
                "`force` must be a GP-GL force level from 1 to {MAX_FORCE} (`FX`), got {v}"
            )))
        }
        Some(v) => Some(v.round() as i64),
        None => None,
    };
    let passes = tool.passes.unwrap_or(1);
    if passes == 0 {
        return Err(err("`passes` must be at least 1".into()));
    }
    Ok(GpglTool {
        pen,
        speed,
        force,
        passes,
    })
}

/// Append one instruction and its terminator.
fn put(out: &mut String, instruction: &str) {
    out.push_str(instruction);
    out.push(ETX as char);
    out.push('\n');
}

/// An `init`/`end` line as one instruction, its ETX (if written) left to [`put`].
fn profile_line<'a>(
    profile: &Profile,
    which: &'static str,
    line: &'a str,
) -> Result<&'a str, OutputError> {
    let t = one_line(profile, which, line, "instruction")?;
    Ok(t.trim_end_matches(ETX as char))
}

/// Encode one sheet's strokes (see the module documentation for the exact text).
pub(crate) fn emit(sheet: &SheetJob, profile: &Profile) -> Result<Vec<u8>, OutputError> {
    if profile.dialect != "graphtec" {
        return Err(OutputError::Dialect {
            profile: profile.name.clone(),
            source_name: profile.source.clone(),
            language: "GP-GL",
            dialect: profile.dialect.clone(),
            known: "graphtec",
        });
    }
    let mut out = String::new();
    put(&mut out, "H");
    for line in profile.init.iter().filter(|l| !l.trim().is_empty()) {
        put(&mut out, profile_line(profile, "init", line)?);
    }
    let (mut pen, mut speed, mut force) = (None, None, None);
    let mut last: Option<(i64, i64)> = None;
    for (index, stroke) in sheet.strokes.iter().enumerate() {
        let Some((kind, tool)) = stroke_tool(profile, stroke.role) else {
            continue;
        };
        let tool = check_tool(profile, kind.name(), tool)?;
        let range = (GPGL_LIMIT as f64, "GP-GL steps");
        let pts = integer_steps(profile, sheet, index, stroke, range)?;
        let Some(&(x0, y0)) = pts.first() else {
            continue;
        };
        if pen != Some(tool.pen) {
            put(&mut out, &format!("J{}", tool.pen));
            pen = Some(tool.pen);
            // A new tool may carry its own conditions: say them again.
            (speed, force) = (None, None);
        }
        if tool.speed.is_some() && tool.speed != speed {
            put(&mut out, &format!("!{}", tool.speed.unwrap_or_default()));
            speed = tool.speed;
        }
        if tool.force.is_some() && tool.force != force {
            let f = tool.force.unwrap_or_default();
            put(&mut out, &format!("FX{f},{}", tool.pen));
            force = tool.force;
        }
        let closed = pts.len() > 2 && pts.first() == pts.last();
        for pass in 0..tool.passes {
            if pass == 0 || !closed {
                put(&mut out, &format!("M{x0},{y0}"));
            }
            let rest = if pts.len() == 1 { &pts[..] } else { &pts[1..] };
            for chunk in rest.chunks(D_POINTS) {
                let mut d = String::from("D");
                for (i, (x, y)) in chunk.iter().enumerate() {
                    if i > 0 {
                        d.push(',');
                    }
                    let _ = write!(d, "{x},{y}");
                }
                put(&mut out, &d);
            }
        }
        last = pts.last().copied();
    }
    let end: Vec<&String> = profile
        .end
        .iter()
        .filter(|l| !l.trim().is_empty())
        .collect();
    if !end.is_empty() {
        if let Some((x, y)) = last {
            put(&mut out, &format!("M{x},{y}"));
        }
        for line in end {
            put(&mut out, profile_line(profile, "end", line)?);
        }
    }
    put(&mut out, "H");
    Ok(out.into_bytes())
}

/// Whether `b` ends a GP-GL instruction: ETX, or a line feed or carriage return.
pub fn ends_instruction(b: u8) -> bool {
    matches!(b, ETX | b'\n' | b'\r')
}

/// Length of the complete instruction at the front of `buf` (terminator included), if its
/// terminator has arrived.
pub fn next_instruction<'a>(buf: impl IntoIterator<Item = &'a u8>) -> Option<usize> {
    buf.into_iter()
        .position(|&b| ends_instruction(b))
        .map(|i| i + 1)
}

/// One instruction's mnemonic (upper-cased) and its numbers: the mnemonic is everything before
/// the first digit, sign, point, comma or space (`M`, `D`, `!`, `FX`, `\`…). `None`: an empty
/// instruction; `Some(Err(text))`: a parameter that is not a finite number.
pub fn instruction(raw: &[u8]) -> Option<Result<(String, Vec<f64>), String>> {
    let text = String::from_utf8_lossy(raw);
    let text = text.trim_matches(|c: char| c.is_whitespace() || c == ETX as char || c == '\0');
    if text.is_empty() {
        return None;
    }
    let split = text
        .find(|c: char| c.is_ascii_digit() || matches!(c, '-' | '+' | '.' | ',' | ' '))
        .unwrap_or(text.len());
    let op = text[..split].to_ascii_uppercase();
    let nums: Result<Vec<f64>, String> = text[split..]
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| s.to_string())
        })
        .collect();
    Some(nums.map(|n| (op, n)))
}

/// A tool-down path read back from a GP-GL program: the tool (`J`), speed (`!`) and force
/// (`FX`) in effect, and the points in steps.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedStroke {
    pub pen: u32,
    pub speed: Option<f64>,
    pub force: Option<f64>,
    pub points: Vec<(i64, i64)>,
}

/// Read back the tool-down paths of a program made by [`emit`]: absolute `M`/`D`, `H`, `J`,
/// `!` and `FX`; other instructions are skipped, except the relative `O`/`E`, which this
/// reader does not follow (the simulator does).
pub fn parse(program: &[u8]) -> Result<Vec<ParsedStroke>, String> {
    let mut strokes: Vec<ParsedStroke> = Vec::new();
    let (mut pen, mut speed, mut force) = (0u32, None, None);
    let mut at = (0i64, 0i64);
    let mut down = false;
    for (n, raw) in program.split(|&b| ends_instruction(b)).enumerate() {
        let Some(it) = instruction(raw) else { continue };
        let (op, nums) =
            it.map_err(|bad| format!("instruction {}: `{bad}` is not a number", n + 1))?;
        match op.as_str() {
            "H" => {
                down = false;
                at = (0, 0);
            }
            "J" => {
                down = false;
                pen = nums.first().copied().unwrap_or(0.0) as u32;
            }
            "!" => speed = nums.first().copied(),
            "FX" => force = nums.first().copied(),
            "O" | "E" => {
                return Err(format!(
                    "instruction {}: relative moves are not read",
                    n + 1
                ))
            }
            "M" | "D" => {
                if nums.len() % 2 != 0 {
                    return Err(format!("instruction {}: odd coordinates", n + 1));
                }
                for xy in nums.chunks(2) {
                    let p = (xy[0].round() as i64, xy[1].round() as i64);
                    if op == "D" {
                        if !down {
                            strokes.push(ParsedStroke {
                                pen,
                                speed,
                                force,
                                points: vec![at],
                            });
                        }
                        if let Some(s) = strokes.last_mut() {
                            s.points.push(p);
                        }
                    }
                    down = op == "D";
                    at = p;
                }
            }
            _ => {}
        }
    }
    Ok(strokes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::fixtures::{half_unit_steps, sheet, stroke};
    use crate::profile::parse as parse_profile;
    use crate::toolpath::StrokeRole;

    const CUTTER: &str = "name='g'\ndescription='d'\nlanguage='gpgl'\ndialect='graphtec'\n\
        units_per_mm=10\n\
        [tools.cut]\npen=1\nforce=14\nspeed=20\n\
        [tools.score]\npen=1\nforce=5.4\nspeed=20\npasses=2\n\
        [tools.draw]\npen=2\nspeed=30\n";

    fn text(sheet: &SheetJob, profile_text: &str) -> String {
        let profile = parse_profile(profile_text, "test.toml").unwrap();
        String::from_utf8(emit(sheet, &profile).unwrap())
            .unwrap()
            .replace('\x03', "|")
    }

    #[test]
    fn the_exact_program() {
        let job = sheet(vec![
            stroke(StrokeRole::Label, &[(1.0, 1.0), (2.0, 1.0)]),
            stroke(StrokeRole::FoldValley, &[(1.0, 2.0), (2.0, 2.0)]),
            stroke(
                StrokeRole::Cut,
                &[(10.0, 10.0), (20.04, 10.0), (20.0, 20.0), (10.0, 10.0)],
            ),
            stroke(StrokeRole::Mark, &[(5.0, 5.0)]),
        ]);
        let t = text(&job, CUTTER);
        assert_eq!(
            t,
            "H|\nJ2|\n!30|\nM10,10|\nD20,10|\n\
             J1|\n!20|\nFX5,1|\nM10,20|\nD20,20|\nM10,20|\nD20,20|\n\
             FX14,1|\nM100,100|\nD200,100,200,200,100,100|\n\
             J2|\n!30|\nM50,50|\nD50,50|\nH|\n"
        );
        let back = parse(t.replace('|', "\x03").as_bytes()).unwrap();
        assert_eq!(back.len(), 5);
        assert_eq!((back[0].pen, back[0].speed), (2, Some(30.0)));
        assert_eq!(back[1], back[2]);
        assert_eq!(back[1].force, Some(5.0));
        assert_eq!(
            back[3].points,
            vec![(100, 100), (200, 100), (200, 200), (100, 100)]
        );
        assert_eq!(back[4].points, vec![(50, 50), (50, 50)]);
    }

    #[test]
    fn init_end_and_axes() {
        let p = CUTTER.replace(
            "units_per_mm=10\n",
            "units_per_mm=10\ninit=['FC0']\nend=[\"FO0\\u0003\"]\n\
             [axes]\nswap_xy=true\nflip_y=true\n",
        );
        let job = SheetJob {
            width: 100.0,
            height: 50.0,
            strokes: vec![stroke(StrokeRole::Cut, &[(0.0, 0.0), (100.0, 0.0)])],
        };
        let t = text(&job, &p);
        assert_eq!(
            t,
            "H|\nFC0|\nJ1|\n!20|\nFX14,1|\nM0,1000|\nD0,0|\nM0,0|\nFO0|\nH|\n"
        );
    }

    #[test]
    fn rounding_ranges_and_errors() {
        // 0.0125 mm steps at 0.01 mm per step: every point sent is the rounding of an
        // absolute position, never of a sum of rounded increments.
        let (pts, job) = half_unit_steps(0.0);
        let fine = CUTTER.replace("units_per_mm=10", "units_per_mm=100");
        let t = text(&job, &fine).replace('|', "\x03");
        let back = parse(t.as_bytes()).unwrap();
        let exact: Vec<i64> = pts.iter().map(|p| (p.0 * 100.0).round() as i64).collect();
        assert!(back[0].points.iter().all(|p| exact.contains(&p.0)));
        assert_eq!(back[0].points.last(), Some(&(10000, 0)));
        for line in t.lines().filter(|l| l.starts_with('D')) {
            assert!(line.matches(',').count() < 64, "{line}");
        }
        let p = parse_profile(CUTTER, "t.toml").unwrap();
        let far = sheet(vec![stroke(StrokeRole::Cut, &[(0.0, 0.0), (1e6, 0.0)])]);
        let e = emit(&far, &p).unwrap_err().on_sheet(2).to_string();
        assert!(
            e.contains("sheet 2, stroke 1 (cut)") && e.contains("GP-GL steps"),
            "{e}"
        );
        let job = sheet(vec![stroke(StrokeRole::Cut, &[(0.0, 0.0), (1.0, 0.0)])]);
        for (key, bad, says) in [
            ("force=14", "force=60", "force level from 1 to 48"),
            ("force=14", "force=0.2", "force level"),
            (
                "speed=20\n[tools.score]",
                "speed=0.4\n[tools.score]",
                "whole number of cm/s",
            ),
            ("pen=1\nforce=14", "pen=9\nforce=14", "1 to 8"),
        ] {
            let p = parse_profile(&CUTTER.replacen(key, bad, 1), "t.toml").unwrap();
            let e = emit(&job, &p).unwrap_err().to_string();
            assert!(e.contains("tool `cut`") && e.contains(says), "{e}");
        }
        let mut p = parse_profile(CUTTER, "t.toml").unwrap();
        p.dialect = "silhouette".into();
        assert!(emit(&job, &p).unwrap_err().to_string().contains("graphtec"));
    }

    #[test]
    fn lexer() {
        assert_eq!(
            instruction(b"FX14,1\x03"),
            Some(Ok(("FX".into(), vec![14.0, 1.0])))
        );
        assert_eq!(instruction(b"h"), Some(Ok(("H".into(), vec![]))));
        assert_eq!(instruction(b"!20"), Some(Ok(("!".into(), vec![20.0]))));
        assert_eq!(instruction(b"\x03\n"), None);
        assert!(matches!(instruction(b"D1,x"), Some(Err(_))));
        assert_eq!(next_instruction(b"M1,2\x03D".iter()), Some(5));
        assert_eq!(next_instruction(b"M1,2".iter()), None);
        assert!(parse(b"O10,10\x03").is_err());
    }
}
