//! GRBL 1.1 G-code programs (dialect `grbl`) for a drag knife on Z, a servo-lifted pen or a
//! laser, one block per line, absolute millimetres.
//!
//! The shape of a program (the simulated cutter relies on it):
//!
//! ```text
//! G21                      millimetres
//! G90                      absolute coordinates
//! G94                      feed in units per minute
//! <profile init lines>     verbatim
//! ... strokes, in the job's order, each by its tool:
//!   knife (z_down, z_up)         servo pen (servo_down/_up)    laser (power)
//!   G0 Z2        (if not up)     M3 S30    } (if not up)
//!                                G4 P0.15  }
//!   G0 X10 Y10   travel          G0 X10 Y10                    G0 X10 Y10
//!   G1 Z-1 F1200 plunge          M3 S90                        M4 S1000  (first stroke only)
//!                                G4 P0.15
//!   G1 X20 Y10   cut             G1 X20 Y10 F3000              G1 X20 Y10 F300 (S when it changes)
//!   G1 X20 Y20                   G1 X20 Y20                    G1 X20 Y20
//!   G0 Z2        lift            M3 S30                        (nothing: G0 is beam off)
//!                                G4 P0.15
//! M5                       spindle / laser off
//! <profile end lines>      verbatim
//! M2                       program end
//! ```
//!
//! Documentation followed: GRBL 1.1 (gnea/grbl, `doc/markdown/commands.md` and the g-code
//! parser): `G21`/`G90`/`G94` modal states, `G0`/`G1` with a modal `F` in mm/min, `G4 P` in
//! seconds, `M3`/`M4`/`M5` with `S`, `M2` program end; laser mode (`doc/markdown/laser_mode.md`):
//! `M4 S` is dynamic power, the beam is only on during `G1`; GRBL's line buffer
//! (`LINE_BUFFER_SIZE` 80 in `grbl/protocol.h`: 80 significant characters or more overflow),
//! so no line here has more than [`LINE_MAX`] significant characters.
//!
//! Choices where the documents are silent:
//! - Coordinates: every point goes through [`super::to_device`] (axes and units per
//!   mm, 1 for G-code) and is printed with [`fmt_mm`], at most 3 decimals of
//!   its absolute value, so rounding never accumulates; a point repeated after rounding is sent
//!   once; a one-point stroke is a `G1` to where the tool already is. Positions beyond
//!   ±[`LIMIT_MM`] are an error (no machine is that big, and lines stay short).
//! - One point per `G1` line, which keeps every line short whatever the stroke.
//! - `F` is modal: a `G1` carries it only when it differs from the feed in effect (the knife's
//!   plunge always carries it, so the knife's cutting moves do not).
//! - The tool kind is read off the tool table: `z_down` and `z_up` make a knife; else
//!   `servo_down` and `servo_up` a servo pen (`dwell` seconds after each servo move, 0.15 when
//!   absent); else `power` a laser (at most the profile's `max_power`). A tool with none of
//!   them, or without `speed` (the feed, mm/min: GRBL refuses `G1` without one), is an error.
//!   A stroke kind the profile has no tool for is left out. Different kinds may be different
//!   tools (a cut and a score knife with other depths and feeds): parameters switch between
//!   strokes, there is no `M6`.
//! - Before its first stroke a knife or a servo pen is lifted (it may be down after a reset);
//!   later strokes start with it up, since every stroke ends with a lift.
//! - `passes`: a closed stroke (its last point, after rounding, is its first) goes round again
//!   without lifting; an open one is lifted, moved back to its start and cut again.
//! - Laser: GRBL's laser mode (`$32=1`, which the streamer checks at connect) keeps the beam
//!   off during `G0` and scales `M4` power with the actual speed, and it changes `S` on a
//!   `G1` without stopping; `M4` and `M5` stop the machine until the planner is empty. So the
//!   beam is turned on once, `M4 S<power>` before the first laser stroke, a stroke of another
//!   power carries its `S` on its first `G1`, travel is `G0`, and `M5` comes once at the end.
//! - The end: the tool is up after the last stroke's lift; then `M5` (once), the profile's
//!   `end` lines, `M2`.
//! - Every line (and every profile `init`/`end` line) has at most [`LINE_MAX`] significant
//!   characters, GRBL's limit (spaces and comments not counted).

use super::{device_points, fmt_mm, line_error, one_line, stroke_tool, tool_error, OutputError};
use crate::profile::{significant_len, Profile, Tool, LINE_MAX};
use crate::toolpath::SheetJob;

/// Largest coordinate magnitude, mm.
pub(crate) const LIMIT_MM: f64 = 100_000.0;
/// Seconds to wait after a servo move when the tool does not say.
pub(crate) const DEFAULT_DWELL: f64 = 0.15;

/// How a tool goes down and up, with its numbers formatted.
#[derive(Debug, Clone, PartialEq)]
enum Action {
    Knife {
        down: String,
        up: String,
    },
    Servo {
        down: String,
        up: String,
        dwell: String,
    },
    Laser {
        power: String,
    },
}

/// What a G-code program uses of a tool, checked.
#[derive(Debug, Clone, PartialEq)]
struct GTool {
    action: Action,
    feed: String,
    passes: u32,
}

fn check_tool(profile: &Profile, kind: &str, tool: &Tool) -> Result<GTool, OutputError> {
    let err = |m: String| tool_error(profile, kind, m);
    let finite = |name: &str, v: f64| {
        if v.is_finite() {
            Ok(fmt_mm(v))
        } else {
            Err(err(format!("`{name}` must be a number, got {v}")))
        }
    };
    let feed = match tool.speed {
        None => {
            return Err(err(
                "no `speed`: G-code needs a feed rate (mm/min) for `G1`".into(),
            ))
        }
        Some(v) if !(v.is_finite() && v > 0.0 && v < 1e7) => {
            return Err(err(format!(
                "`speed` must be a positive feed in mm/min, got {v}"
            )))
        }
        Some(v) => fmt_mm(v),
    };
    let passes = tool.passes.unwrap_or(1);
    if passes == 0 {
        return Err(err("`passes` must be at least 1".into()));
    }
    let action = if let (Some(d), Some(u)) = (tool.z_down, tool.z_up) {
        let (down, up) = (finite("z_down", d)?, finite("z_up", u)?);
        if d >= u || d.abs() > 1e4 || u.abs() > 1e4 {
            return Err(err(format!(
                "`z_down` ({d}) must be below `z_up` ({u}), both within ±10000 mm"
            )));
        }
        Action::Knife { down, up }
    } else if let (Some(d), Some(u)) = (tool.servo_down, tool.servo_up) {
        let (down, up) = (finite("servo_down", d)?, finite("servo_up", u)?);
        let w = tool.dwell.unwrap_or(DEFAULT_DWELL);
        if !(w.is_finite() && (0.0..1e4).contains(&w)) || d < 0.0 || u < 0.0 {
            return Err(err(format!(
                "servo values must be ≥ 0 and `dwell` 0 to 10000 s (got {d}, {u}, {w})"
            )));
        }
        Action::Servo {
            down,
            up,
            dwell: fmt_mm(w),
        }
    } else if let Some(p) = tool.power {
        let max = profile.max_power.unwrap_or(f64::INFINITY);
        if !(p.is_finite() && p > 0.0 && p <= max && p < 1e7) {
            return Err(err(format!(
                "`power` must be above 0 and at most the profile's `max_power` ({}), got {p}",
                profile
                    .max_power
                    .map(fmt_mm)
                    .unwrap_or_else(|| "not set".into())
            )));
        }
        Action::Laser { power: fmt_mm(p) }
    } else {
        return Err(err(
            "nothing to lower it with in G-code: give `z_down` and `z_up` (knife), \
             `servo_down` and `servo_up` (servo pen) or `power` (laser)"
                .into(),
        ));
    };
    Ok(GTool {
        action,
        feed,
        passes,
    })
}

/// The program being written and the machine state it leaves.
#[derive(Default)]
struct Writer {
    out: String,
    /// Last Z commanded.
    z: Option<String>,
    /// Last servo `M3 S` value commanded.
    servo: Option<String>,
    /// `M4` has been sent (laser mode: the beam follows `G1`/`G0` from then on).
    laser_on: bool,
    /// Laser power in effect (`S`), and the power the next cut should carry when it differs.
    s: Option<String>,
    want_s: Option<String>,
    /// Feed in effect.
    feed: Option<String>,
}

impl Writer {
    fn line(&mut self, s: &str) {
        self.out.push_str(s);
        self.out.push('\n');
    }

    fn servo_to(&mut self, s: &str, dwell: &str) {
        self.line(&format!("M3 S{s}"));
        self.line(&format!("G4 P{dwell}"));
        self.servo = Some(s.to_string());
    }

    /// Lift the tool unless it is known to be up already.
    fn ensure_up(&mut self, a: &Action) {
        match a {
            Action::Knife { up, .. } if self.z.as_ref() != Some(up) => self.lift(a),
            Action::Servo { up, .. } if self.servo.as_ref() != Some(up) => self.lift(a),
            _ => {}
        }
    }

    fn lift(&mut self, a: &Action) {
        match a {
            Action::Knife { up, .. } => {
                self.line(&format!("G0 Z{up}"));
                self.z = Some(up.clone());
            }
            Action::Servo { up, dwell, .. } => self.servo_to(up, dwell),
            // Laser mode: the G0 that follows turns the beam off.
            Action::Laser { .. } => {}
        }
    }

    fn lower(&mut self, a: &Action, feed: &str) {
        match a {
            Action::Knife { down, .. } => {
                self.line(&format!("G1 Z{down} F{feed}"));
                self.z = Some(down.clone());
                self.feed = Some(feed.to_string());
            }
            Action::Servo { down, dwell, .. } => self.servo_to(down, dwell),
            Action::Laser { power } if !self.laser_on => {
                self.line(&format!("M4 S{power}"));
                self.laser_on = true;
                self.s = Some(power.clone());
            }
            Action::Laser { power } => {
                if self.s.as_ref() != Some(power) {
                    self.want_s = Some(power.clone());
                }
            }
        }
    }

    fn cut_to(&mut self, (x, y): &(String, String), feed: &str) {
        let mut l = format!("G1 X{x} Y{y}");
        if self.feed.as_deref() != Some(feed) {
            l.push_str(&format!(" F{feed}"));
            self.feed = Some(feed.to_string());
        }
        if let Some(s) = self.want_s.take() {
            l.push_str(&format!(" S{s}"));
            self.s = Some(s);
        }
        self.line(&l);
    }
}

/// A profile's `init` or `end` line, checked to fit on one G-code line.
fn profile_line<'a>(
    profile: &Profile,
    which: &'static str,
    line: &'a str,
) -> Result<&'a str, OutputError> {
    let t = one_line(profile, which, line, "block")?;
    if significant_len(t) > LINE_MAX {
        return Err(line_error(
            profile,
            which,
            line,
            format!("more than the {LINE_MAX} significant characters GRBL keeps (spaces and comments not counted)"),
        ));
    }
    Ok(t)
}

/// Encode one sheet's strokes (see the module documentation for the exact text).
pub(crate) fn emit(sheet: &SheetJob, profile: &Profile) -> Result<Vec<u8>, OutputError> {
    if profile.dialect != "grbl" {
        return Err(OutputError::Dialect {
            profile: profile.name.clone(),
            source_name: profile.source.clone(),
            language: "G-code",
            dialect: profile.dialect.clone(),
            known: "grbl",
        });
    }
    let mut w = Writer::default();
    for l in ["G21", "G90", "G94"] {
        w.line(l);
    }
    for line in &profile.init {
        let l = profile_line(profile, "init", line)?;
        if !l.is_empty() {
            w.line(l);
        }
    }
    for (index, stroke) in sheet.strokes.iter().enumerate() {
        let Some((kind, tool)) = stroke_tool(profile, stroke.role) else {
            continue;
        };
        let tool = check_tool(profile, kind.name(), tool)?;
        let fits = |v: f64| v.is_finite() && v.abs() <= LIMIT_MM;
        let mut pts: Vec<(String, String)> =
            device_points(profile, sheet, index, stroke, (LIMIT_MM, "mm"), fits)?
                .iter()
                .map(|d| (fmt_mm(d.x), fmt_mm(d.y)))
                .collect();
        pts.dedup();
        let Some(start) = pts.first().cloned() else {
            continue;
        };
        let a = &tool.action;
        w.ensure_up(a);
        let closed = pts.len() > 2 && pts.first() == pts.last();
        for pass in 0..tool.passes {
            if pass == 0 || !closed {
                if pass > 0 {
                    w.lift(a);
                }
                w.line(&format!("G0 X{} Y{}", start.0, start.1));
                w.lower(a, &tool.feed);
            }
            if pts.len() == 1 {
                w.cut_to(&start, &tool.feed);
            }
            for p in &pts[1..] {
                w.cut_to(p, &tool.feed);
            }
        }
        w.lift(a);
    }
    if !w.out.ends_with("\nM5\n") {
        w.line("M5");
    }
    for line in &profile.end {
        let l = profile_line(profile, "end", line)?;
        if !l.is_empty() {
            w.line(l);
        }
    }
    w.line("M2");
    Ok(w.out.into_bytes())
}

/// Where a G-code program takes the machine: the least and greatest X and Y that its moves
/// reach, `[x_min, y_min, x_max, y_max]` in mm, or `None` when no line moves in X or Y. It
/// follows `G20`/`G21` (inches, millimetres) and `G90`/`G91` (absolute, incremental from the
/// start at 0,0), skips comments (`;…`, `(…)`) and lines that set coordinates without moving
/// (`G92`, `G10`, `G28.1`, `G30.1`), and counts an arc by its end point. For checking a program
/// against the machine's work area before it is sent; not a G-code validator.
pub fn reach(program: &[u8]) -> Option<[f64; 4]> {
    let text = String::from_utf8_lossy(program);
    let (mut inch, mut relative) = (false, false);
    let mut pos = [0.0f64; 2];
    let mut out: Option<[f64; 4]> = None;
    for line in text.lines() {
        let mut code = String::with_capacity(line.len());
        let mut depth = 0usize;
        for c in line.chars() {
            match c {
                ';' if depth == 0 => break,
                '(' => depth += 1,
                ')' => depth = depth.saturating_sub(1),
                _ if depth == 0 && !c.is_whitespace() => code.push(c.to_ascii_uppercase()),
                _ => {}
            }
        }
        let mut words: Vec<(char, &str)> = Vec::new();
        let mut rest = code.as_str();
        while let Some(letter) = rest.chars().next() {
            let tail = &rest[letter.len_utf8()..];
            let end = tail
                .find(|c: char| c.is_ascii_alphabetic())
                .unwrap_or(tail.len());
            words.push((letter, &tail[..end]));
            rest = &tail[end..];
        }
        let g = |w: &str| {
            words
                .iter()
                .any(|&(l, v)| l == 'G' && v.parse::<f64>().ok() == w.parse::<f64>().ok())
        };
        if g("20") {
            inch = true;
        }
        if g("21") {
            inch = false;
        }
        if g("90") {
            relative = false;
        }
        if g("91") {
            relative = true;
        }
        if g("92") || g("10") || g("28.1") || g("30.1") || g("53") {
            continue;
        }
        let scale = if inch { 25.4 } else { 1.0 };
        let mut moved = false;
        for &(l, v) in &words {
            let axis = match l {
                'X' => 0,
                'Y' => 1,
                _ => continue,
            };
            let Ok(v) = v.parse::<f64>() else { continue };
            if !v.is_finite() {
                continue;
            }
            pos[axis] = if relative {
                pos[axis] + v * scale
            } else {
                v * scale
            };
            moved = true;
        }
        if moved {
            let r = out.get_or_insert([pos[0], pos[1], pos[0], pos[1]]);
            *r = [
                r[0].min(pos[0]),
                r[1].min(pos[1]),
                r[2].max(pos[0]),
                r[3].max(pos[1]),
            ];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::fixtures::{half_unit_steps, sheet, stroke};
    use crate::profile::parse as parse_profile;
    use crate::toolpath::StrokeRole;
    use glam::DVec2;

    fn profile(tools: &str) -> Profile {
        let text = format!(
            "name='g'\ndescription='d'\nlanguage='gcode'\ndialect='grbl'\nunits_per_mm=1.0\n\
             protocol='grbl-character-counting'\nmax_power=1000.0\n{tools}"
        );
        parse_profile(&text, "test.toml").unwrap()
    }

    fn text(job: &SheetJob, p: &Profile) -> String {
        String::from_utf8(emit(job, p).unwrap()).unwrap()
    }

    const KNIFE: &str = "[tools.cut]\nz_down=-1.0\nz_up=2.0\nspeed=1200\npasses=2\n\
        [tools.score]\nz_down=-0.25\nz_up=5\nspeed=1500.5\n";
    const PEN: &str = "[tools.cut]\nservo_down=90\nservo_up=30\nspeed=3000\n\
        [tools.draw]\nservo_down=90\nservo_up=30\nspeed=2000\ndwell=0.3\n";
    const LASER: &str = "init=['M9']\nend=['G0 X0 Y0']\n\
        [tools.cut]\npower=1000\nspeed=300\npasses=2\n[tools.draw]\npower=150\nspeed=2000\n";

    fn small_job() -> SheetJob {
        sheet(vec![
            stroke(StrokeRole::Mark, &[(1.0, 1.0), (2.0, 1.0)]),
            stroke(
                StrokeRole::FoldValley,
                &[(1.0, 2.0), (2.0, 2.0), (2.0, 3.0), (1.0, 2.0)],
            ),
            stroke(
                StrokeRole::Cut,
                &[(10.0, 10.0), (20.0004, 10.0), (20.0, 20.5)],
            ),
        ])
    }

    #[test]
    fn knife_exact() {
        // No draw tool: the mark is left out. Score: closed, one pass. Cut: open, two passes.
        let t = text(&small_job(), &profile(KNIFE));
        assert_eq!(
            t,
            "G21\nG90\nG94\n\
             G0 Z5\nG0 X1 Y2\nG1 Z-0.25 F1500.5\nG1 X2 Y2\nG1 X2 Y3\nG1 X1 Y2\nG0 Z5\n\
             G0 Z2\nG0 X10 Y10\nG1 Z-1 F1200\nG1 X20 Y10\nG1 X20 Y20.5\nG0 Z2\n\
             G0 X10 Y10\nG1 Z-1 F1200\nG1 X20 Y10\nG1 X20 Y20.5\nG0 Z2\n\
             M5\nM2\n"
        );
        let paths = down_paths(&t, &profile(KNIFE));
        assert_eq!(paths.len(), 3);
        assert_eq!(paths[1], paths[2]);
    }

    #[test]
    fn servo_pen_exact() {
        // No scoring or perforating tool: the fold is drawn with the pen (`fold_kind`).
        let t = text(&small_job(), &profile(PEN));
        assert_eq!(
            t,
            "G21\nG90\nG94\n\
             M3 S30\nG4 P0.3\nG0 X1 Y1\nM3 S90\nG4 P0.3\nG1 X2 Y1 F2000\nM3 S30\nG4 P0.3\n\
             G0 X1 Y2\nM3 S90\nG4 P0.3\nG1 X2 Y2\nG1 X2 Y3\nG1 X1 Y2\nM3 S30\nG4 P0.3\n\
             G0 X10 Y10\nM3 S90\nG4 P0.15\nG1 X20 Y10 F3000\nG1 X20 Y20.5\n\
             M3 S30\nG4 P0.15\n\
             M5\nM2\n"
        );
    }

    #[test]
    fn laser_exact() {
        let job = sheet(vec![
            stroke(StrokeRole::Label, &[(1.0, 1.0), (2.0, 1.0)]),
            stroke(
                StrokeRole::Cut,
                &[(10.0, 10.0), (20.0, 10.0), (20.0, 20.0), (10.0, 10.0)],
            ),
        ]);
        let t = text(&job, &profile(LASER));
        assert_eq!(
            t,
            "G21\nG90\nG94\nM9\n\
             G0 X1 Y1\nM4 S150\nG1 X2 Y1 F2000\n\
             G0 X10 Y10\nG1 X20 Y10 F300 S1000\nG1 X20 Y20\nG1 X10 Y10\n\
             G1 X20 Y10\nG1 X20 Y20\nG1 X10 Y10\nM5\n\
             G0 X0 Y0\nM2\n"
        );
    }

    #[test]
    fn dialect_and_tool_errors() {
        let job = small_job();
        let mut p = profile(KNIFE);
        p.dialect = "marlin".into();
        let e = emit(&job, &p).unwrap_err().to_string();
        assert!(
            e.contains("`g`") && e.contains("`marlin`") && e.contains("grbl"),
            "{e}"
        );
        // Profiles are validated when read; a profile built in code still meets these checks.
        let with = |f: &dyn Fn(&mut crate::profile::Tool)| {
            let mut p = profile(KNIFE);
            if let Some(t) = p.tools.get_mut("cut") {
                f(t);
            }
            emit(&job, &p).unwrap_err().to_string()
        };
        let e = with(&|t| t.speed = None);
        assert!(e.contains("tool `cut`") && e.contains("`speed`"), "{e}");
        let e = with(&|t| {
            (t.z_down, t.z_up, t.pen) = (None, None, Some(1));
        });
        assert!(e.contains("z_down") && e.contains("power"), "{e}");
        let e = with(&|t| {
            (t.z_down, t.z_up, t.power) = (None, None, Some(2000.0));
        });
        assert!(e.contains("max_power"), "{e}");
        let e = with(&|t| {
            (t.z_down, t.z_up) = (Some(2.0), Some(1.0));
        });
        assert!(e.contains("below"), "{e}");
        // A comment and spaces do not count towards GRBL's 79; 80 significant characters do.
        let spaced = format!("init=['G4 P0 ({})']\n{KNIFE}", "x".repeat(80));
        assert!(emit(&job, &profile(&spaced)).is_ok());
        let long = format!("init=['G4 P0{}']\n{KNIFE}", "0".repeat(76));
        let e = emit(&job, &profile(&long)).unwrap_err().to_string();
        assert!(e.contains("init line") && e.contains("79"), "{e}");
        let fits = format!("init=['G4 P0{}']\n{KNIFE}", "0".repeat(75));
        assert!(emit(&job, &profile(&fits)).is_ok());
        let far = sheet(vec![stroke(StrokeRole::Cut, &[(0.0, 0.0), (2e5, 0.0)])]);
        let e = emit(&far, &profile(KNIFE))
            .unwrap_err()
            .on_sheet(2)
            .to_string();
        assert!(e.contains("sheet 2, stroke 1 (cut)"), "{e}");
    }

    #[test]
    fn long_strokes_keep_lines_short() {
        // A long spiral of far, many-decimal coordinates, with every tool type.
        let pts: Vec<(f64, f64)> = (0..2000)
            .map(|i| {
                let a = i as f64 * 0.01;
                (
                    -99_000.123_456 + a.cos() * (i as f64) * 0.4,
                    -99_998.987_654 + a.sin() * 1.000_1,
                )
            })
            .collect();
        let job = sheet(vec![
            stroke(StrokeRole::Cut, &pts),
            stroke(StrokeRole::FoldMountain, &pts),
            stroke(StrokeRole::Label, &pts),
        ]);
        for tools in [KNIFE, PEN, LASER] {
            let p = profile(tools);
            let t = text(&job, &p);
            for line in t.lines() {
                assert!(line.len() <= LINE_MAX, "{} chars: {line}", line.len());
            }
            assert!(t.lines().count() > 2000);
        }
    }

    #[test]
    fn program_end_leaves_the_tool_up_and_paths_match() {
        let job = small_job();
        for tools in [KNIFE, PEN, LASER] {
            let p = profile(tools);
            let t = text(&job, &p);
            let m = run(&t, &p);
            assert!(!m.down, "{tools}: tool down at the end");
            assert!(!m.spindle, "{tools}: spindle on at the end");
            assert!(t.ends_with("M5\nM2\n") || t.ends_with("M2\n"), "{t}");
            // Every tool-down path is a stroke of the job, in order, within 0.0005 mm.
            let mut expect = Vec::new();
            for s in &job.strokes {
                let Some(tool) =
                    crate::toolpath::tool_kind(s.role, |k| p.has(k)).and_then(|k| p.tool(k))
                else {
                    continue;
                };
                let closed = s.points.first() == s.points.last();
                let passes = tool.passes.unwrap_or(1);
                if closed {
                    let mut pts = s.points.clone();
                    for _ in 1..passes {
                        pts.extend_from_slice(&s.points[1..]);
                    }
                    expect.push(pts);
                } else {
                    for _ in 0..passes {
                        expect.push(s.points.clone());
                    }
                }
            }
            assert_eq!(m.paths.len(), expect.len(), "{tools}");
            for (got, want) in m.paths.iter().zip(&expect) {
                assert_eq!(got.len(), want.len(), "{tools}");
                for (g, w) in got.iter().zip(want) {
                    assert!(g.distance(*w) < 6e-4, "{tools}: {g} vs {w}");
                }
            }
        }
    }

    #[test]
    fn axes_swap_and_flip() {
        let mut p = profile(KNIFE);
        p.axes.swap_xy = true;
        p.axes.flip_x = true;
        let job = SheetJob {
            width: 100.0,
            height: 40.0,
            strokes: vec![stroke(
                StrokeRole::Cut,
                &[(0.0, 0.0), (100.0, 0.0), (100.0, 40.0)],
            )],
        };
        let paths = down_paths(&text(&job, &p), &p);
        // Swapped: X from the sheet's y (extent 40), Y from its x; then X mirrored.
        assert_eq!(
            paths[0],
            vec![
                DVec2::new(40.0, 0.0),
                DVec2::new(40.0, 100.0),
                DVec2::new(0.0, 100.0)
            ]
        );
    }

    #[test]
    fn absolute_rounding_does_not_drift() {
        let (pts, job) = half_unit_steps(5.0);
        let p = profile("[tools.cut]\nz_down=-1.0\nz_up=2.0\nspeed=1200\n");
        let paths = down_paths(&text(&job, &p), &p);
        let got = &paths[0];
        assert_eq!(got.len(), pts.len());
        for (g, w) in got.iter().zip(&pts) {
            assert!((g.x - w.0).abs() <= 0.0005 + 1e-12, "{g} vs {w:?}");
        }
        assert_eq!(got.last().map(|p| p.x), Some(100.0));
    }

    /// What the tiny interpreter below saw.
    #[derive(Default)]
    struct Machine {
        pos: DVec2,
        z: f64,
        s: f64,
        spindle: bool,
        laser: bool,
        /// The tool is down (as decided from the profile's tools).
        down: bool,
        /// A tool-down path is being recorded.
        recording: bool,
        paths: Vec<Vec<DVec2>>,
    }

    /// Whether a value is nearer one of the `down` settings than any `up` setting.
    fn nearest_is_down(v: f64, settings: &[(f64, bool)]) -> bool {
        settings
            .iter()
            .min_by(|a, b| (a.0 - v).abs().total_cmp(&(b.0 - v).abs()))
            .is_some_and(|s| s.1)
    }

    /// Run a program on a minimal GRBL model and record the tool-down paths, deciding "down"
    /// from the profile's tools as the simulated cutter does (the nearest setting wins).
    fn run(program: &str, p: &Profile) -> Machine {
        let mut knife = Vec::new();
        let mut servo = Vec::new();
        for t in p.tools.values() {
            if let (Some(d), Some(u)) = (t.z_down, t.z_up) {
                knife.extend([(d, true), (u, false)]);
            } else if let (Some(d), Some(u)) = (t.servo_down, t.servo_up) {
                servo.extend([(d, true), (u, false)]);
            }
        }
        let is_down = |m: &Machine, g1: bool| {
            (!knife.is_empty() && nearest_is_down(m.z, &knife))
                || (m.spindle && !m.laser && nearest_is_down(m.s, &servo))
                || (m.spindle && m.laser && m.s > 0.0 && g1)
        };
        let mut m = Machine {
            z: 1e9,
            ..Default::default()
        };
        for line in program.lines() {
            assert!(line.len() <= LINE_MAX, "{line}");
            let words: Vec<(char, f64)> = line
                .split(' ')
                .map(|w| (w.chars().next().unwrap(), w[1..].parse::<f64>().unwrap()))
                .collect();
            let (code, args) = (words[0], &words[1..]);
            let get = |c: char| args.iter().find(|w| w.0 == c).map(|w| w.1);
            match code {
                ('G', g) if g == 0.0 || g == 1.0 => {
                    if let Some(z) = get('Z') {
                        m.z = z;
                    }
                    let to = DVec2::new(get('X').unwrap_or(m.pos.x), get('Y').unwrap_or(m.pos.y));
                    m.down = is_down(&m, g == 1.0);
                    if !m.down {
                        m.recording = false;
                    } else if get('X').is_some() || get('Y').is_some() {
                        if !m.recording {
                            m.paths.push(vec![m.pos]);
                            m.recording = true;
                        }
                        m.paths.last_mut().unwrap().push(to);
                    }
                    m.pos = to;
                }
                ('M', c) if c == 3.0 || c == 4.0 || c == 5.0 || c == 2.0 => {
                    m.spindle = c == 3.0 || c == 4.0;
                    m.laser = c == 4.0;
                    if m.spindle {
                        m.s = get('S').unwrap();
                    }
                    m.down = is_down(&m, false);
                    if !m.down && !m.laser {
                        m.recording = false;
                    }
                    if c == 5.0 || c == 2.0 {
                        m.recording = false;
                    }
                }
                ('G', _) | ('M', _) => {}
                other => panic!("unexpected {other:?} in {line}"),
            }
        }
        m
    }

    fn down_paths(program: &str, p: &Profile) -> Vec<Vec<DVec2>> {
        run(program, p).paths
    }

    #[test]
    fn reach_follows_units_modes_and_comments() {
        let p = b"G21\nG90 (abs)\nG0 X10 Y-5 ; travel\nG1 X250.5 Y40 F600\n(G1 X999)\nG92 X0 Y0\nG20\nG0 X1 Y1\nG91\nG1 X-2 Y0.5\nM2\n";
        let r = reach(p).unwrap();
        let want = [-25.4, -5.0, 250.5, 40.0];
        for k in 0..4 {
            assert!((r[k] - want[k]).abs() < 1e-9, "{r:?}");
        }
        assert_eq!(reach(b"G21\nG90\nM3 S10\nM2\n"), None);
        assert_eq!(reach(b"\xff\xfe G1 Xnan Y"), None);
    }
}
