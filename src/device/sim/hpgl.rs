//! The simulated cutter's HP-GL interpreter: the subset that flatcut's encoders and common
//! cutter drivers send — `IN`, `DF`, `SP`, `PU`, `PD`, `PA`, `PR`, `VS`, `FS` — executed as a
//! plotter would (and Roland's `!FS` force); anything else is ignored and counted by name, as
//! HP-GL devices do with instructions they do not know (HP 7475A Interfacing and Programming
//! Manual, ch. 14: an unknown instruction sets error 1 and is skipped).
//!
//! Instructions end with `;` or a line feed. Parameters are numbers separated by commas or
//! spaces, read by the crate's one HP-GL lexer (`output::hpgl::read`); `PU`/`PD` take
//! coordinate pairs, absolute after `PA` (the default after `IN`), relative after `PR`.
//! Roland's `!`-prefixed instructions (`!PZ`, `!ST`, …) are named with their three characters.
//! A stray odd coordinate is ignored, as a plotter does. A move to a point outside HP-GL's
//! coordinate range (±2^30 plotter units, HP 7475A manual ch. 14, error 3 "parameter out of
//! range") is ignored whole and counted as `XX (out of range)`.
//!
//! Digitizing (print-and-cut, HP 7475A manual ch. 14): with a registration sensor
//! ([`super::sensor`]) `DP` digitizes the mark the sensor finds near the head; `OS` answers
//! the status byte (bit 2, 4: a digitized point is available; bit 3, 8: initialized; bit 4,
//! 16: ready for data; bit 5, 32: an error, here a `DP` that found no mark), `OD` the
//! digitized point as `X,Y,P` (units, pen 0 up / 1 down) and clears bit 2, `DC` clears the
//! point; each answer ends with a carriage return. Without a sensor `DP` waits for a front
//! panel the simulator does not have: it is ignored and counted, and `OS`/`OD` still answer.
//!
//! Motion time: pen-down moves at the `VS` speed (cm/s; the profile's tool speed when the
//! program sets none), pen-up moves at [`TRAVEL_CM_S`]. This is what paces the simulated
//! buffer's draining.

use super::record::Recorder;
use crate::output::hpgl::read::{instruction, numbers};
use crate::profile::Profile;
use glam::DVec2;
use std::collections::BTreeMap;

/// Largest plotter coordinate, either sign (HP-GL: −2^30 … 2^30 − 1).
pub const RANGE: f64 = 1_073_741_823.0;

/// Pen-up speed, cm/s.
pub(crate) const TRAVEL_CM_S: f64 = 50.0;
/// Pen-down speed when neither the program nor the profile says, cm/s.
pub(crate) const DEFAULT_CM_S: f64 = 20.0;

/// For an instruction still arriving: the bytes at the front of `buf` that a plotter can
/// already execute, and the mnemonic to put back in front of the rest. A plotter moves as
/// coordinate pairs arrive; without this a host stopped by XOFF in the middle of a long `PD`
/// would wait for XON while the device waited for the `;`.
pub(crate) fn executable_prefix<'a>(
    buf: impl IntoIterator<Item = &'a u8>,
) -> Option<(usize, [u8; 2])> {
    let bytes: Vec<u8> = buf.into_iter().copied().take(4096).collect();
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace())?;
    let op = bytes.get(start..start + 2)?;
    let op = [op[0].to_ascii_uppercase(), op[1].to_ascii_uppercase()];
    if !matches!(&op, b"PU" | b"PD" | b"PA" | b"PR") {
        return None;
    }
    // Count separators after numbers; cut after the separator that ends a y coordinate.
    let mut numbers = 0;
    let mut in_number = false;
    let mut cut = None;
    for (i, &b) in bytes.iter().enumerate().skip(start + 2) {
        match b {
            b'0'..=b'9' | b'.' | b'-' | b'+' => in_number = true,
            b',' | b' ' => {
                if in_number {
                    numbers += 1;
                    in_number = false;
                    if numbers % 2 == 0 {
                        cut = Some(i + 1);
                    }
                }
            }
            _ => return None,
        }
    }
    cut.map(|c| (c, op))
}

/// An HP-GL plotter's state.
#[derive(Debug, Clone)]
pub struct Hpgl {
    units_per_mm: f64,
    /// Pen number → (stroke kind, force) of the tools using it, from the profile's tool table.
    pens: BTreeMap<u32, Vec<(String, Option<f64>)>>,
    force: Option<f64>,
    /// Pen number → default speed from the profile, cm/s.
    pen_speed: BTreeMap<u32, f64>,
    pos: DVec2,
    down: bool,
    pen: u32,
    relative: bool,
    speed_cm_s: Option<f64>,
    pub rec: Recorder,
    /// Instructions executed.
    pub instructions: usize,
    /// Instructions not understood, by mnemonic.
    pub ignored: BTreeMap<String, usize>,
    /// The registration sensor, if the machine has one and a printed sheet is loaded.
    pub(crate) sensor: Option<super::sensor::Sensor>,
    /// The last digitized point (units), until `OD` or `DC`.
    digitized: Option<DVec2>,
    /// A `DP` found no mark (status bit 5) since the last `OS`.
    digitize_failed: bool,
    /// Answers to output instructions, for the host.
    pub(crate) out: Vec<u8>,
}

impl Hpgl {
    pub fn new(profile: &Profile) -> Hpgl {
        let mut pens = BTreeMap::new();
        let mut pen_speed = BTreeMap::new();
        for (kind, tool) in &profile.tools {
            if let Some(p) = tool.pen {
                pens.entry(p)
                    .or_insert_with(Vec::new)
                    .push((kind.clone(), tool.force));
                if let Some(s) = tool.speed {
                    pen_speed.entry(p).or_insert(s);
                }
            }
        }
        Hpgl {
            units_per_mm: profile.units_per_mm,
            pens,
            force: None,
            pen_speed,
            pos: DVec2::ZERO,
            down: false,
            pen: 0,
            relative: false,
            speed_cm_s: None,
            rec: Recorder::for_profile(profile),
            instructions: 0,
            ignored: BTreeMap::new(),
            sensor: None,
            digitized: None,
            digitize_failed: false,
            out: Vec::new(),
        }
    }

    /// The stroke kind of the tool in use: the profile's tool with this pen; where several
    /// share the pen (one knife holder, different forces), the one whose force is nearest the
    /// last `FS`.
    fn tool_name(&self) -> Option<String> {
        if self.pen == 0 {
            return None;
        }
        let Some(tools) = self.pens.get(&self.pen) else {
            return Some(format!("pen {}", self.pen));
        };
        let mut best: Option<(f64, &String)> = None;
        for (name, force) in tools {
            let d = match (self.force, force) {
                (Some(a), Some(b)) => (a - b).abs(),
                _ => 0.0,
            };
            if best.is_none_or(|(b, _)| d < b) {
                best = Some((d, name));
            }
        }
        best.map(|(_, n)| n.clone())
    }

    fn speed_units_s(&self, down: bool) -> f64 {
        let cm_s = if down {
            self.speed_cm_s
                .or_else(|| self.pen_speed.get(&self.pen).copied())
                .unwrap_or(DEFAULT_CM_S)
        } else {
            TRAVEL_CM_S
        };
        cm_s * 10.0 * self.units_per_mm
    }

    /// Execute one instruction (its bytes, terminator optional). Returns the time its motion
    /// takes, seconds.
    pub(crate) fn execute(&mut self, raw: &[u8]) -> f64 {
        let text = String::from_utf8_lossy(raw);
        let (op, args_text) = match instruction(&text) {
            None => return 0.0,
            Some(Err(())) => {
                *self.ignored.entry("?".into()).or_default() += 1;
                return 0.0;
            }
            Some(Ok(it)) => it,
        };
        let Ok(nums) = numbers(args_text) else {
            *self
                .ignored
                .entry(format!("{op} (bad parameters)"))
                .or_default() += 1;
            return 0.0;
        };
        if matches!(op.as_str(), "PU" | "PD" | "PA" | "PR") && !self.in_range(&op, &nums) {
            *self
                .ignored
                .entry(format!("{op} (out of range)"))
                .or_default() += 1;
            return 0.0;
        }
        self.instructions += 1;
        match op.as_str() {
            "IN" | "DF" => {
                if op == "IN" {
                    self.lift();
                    self.pen = 0;
                    self.force = None;
                }
                self.relative = false;
                self.speed_cm_s = None;
                0.0
            }
            "SP" => {
                self.lift();
                self.pen = nums.first().map(|&v| v.max(0.0) as u32).unwrap_or(0);
                0.0
            }
            "PA" | "PR" => {
                self.relative = op == "PR";
                self.moves(&nums)
            }
            "PU" => {
                self.lift();
                self.moves(&nums)
            }
            "PD" => {
                if self.down && self.tool_name().as_deref() != self.current_tool() {
                    self.rec.up();
                }
                self.down = true;
                if let Some(t) = self.tool_name() {
                    self.rec.down(&t, self.pos);
                }
                self.moves(&nums)
            }
            "VS" => {
                self.speed_cm_s = nums.first().copied().filter(|v| *v > 0.0);
                0.0
            }
            "DP" => {
                let Some(sensor) = &self.sensor else {
                    self.instructions -= 1;
                    *self.ignored.entry("DP (no sensor)".into()).or_default() += 1;
                    return 0.0;
                };
                self.digitized = sensor.find(self.pos);
                self.digitize_failed = self.digitized.is_none();
                0.0
            }
            "DC" => {
                self.digitized = None;
                0.0
            }
            "OS" => {
                let status = 8
                    + 16
                    + u32::from(self.down)
                    + if self.digitized.is_some() { 4 } else { 0 }
                    + if std::mem::take(&mut self.digitize_failed) {
                        32
                    } else {
                        0
                    };
                self.out.extend_from_slice(format!("{status}\r").as_bytes());
                0.0
            }
            "OD" => {
                let p = self.digitized.take().unwrap_or(self.pos);
                self.out.extend_from_slice(
                    format!("{},{},{}\r", p.x.round(), p.y.round(), u32::from(self.down))
                        .as_bytes(),
                );
                0.0
            }
            "FS" | "!FS" => {
                // The new force applies from the next pen-down, as on cutters.
                self.force = nums.first().copied().filter(|v| *v >= 0.0);
                0.0
            }
            _ => {
                self.instructions -= 1;
                *self.ignored.entry(op).or_default() += 1;
                0.0
            }
        }
    }

    /// Whether every point a move instruction goes to is within [`RANGE`].
    fn in_range(&self, op: &str, nums: &[f64]) -> bool {
        let relative = match op {
            "PA" => false,
            "PR" => true,
            _ => self.relative,
        };
        let mut at = self.pos;
        for xy in nums.chunks_exact(2) {
            let v = DVec2::new(xy[0], xy[1]);
            at = if relative { at + v } else { v };
            if !(at.x.abs() <= RANGE && at.y.abs() <= RANGE) {
                return false;
            }
        }
        true
    }

    /// Whether the pen is down (whatever tool it holds).
    pub fn pen_down(&self) -> bool {
        self.down
    }

    fn current_tool(&self) -> Option<&str> {
        self.rec.open_tool()
    }

    /// The tool that is down now, if any.
    pub(crate) fn tool_down(&self) -> Option<String> {
        if self.down {
            self.tool_name()
        } else {
            None
        }
    }

    fn lift(&mut self) {
        self.down = false;
        self.rec.up();
    }

    fn moves(&mut self, nums: &[f64]) -> f64 {
        let mut t = 0.0;
        let tool = if self.down { self.tool_name() } else { None };
        let speed = self.speed_units_s(self.down && tool.is_some());
        for xy in nums.chunks_exact(2) {
            let target = if self.relative {
                self.pos + DVec2::new(xy[0], xy[1])
            } else {
                DVec2::new(xy[0], xy[1])
            };
            t += self.pos.distance(target) / speed;
            self.rec.travel_to(self.pos, target, tool.as_deref());
            self.pos = target;
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::hpgl::read::next_instruction;

    fn profile() -> Profile {
        crate::profile::find("hpgl-pens").unwrap()
    }

    #[test]
    fn records_pen_down_paths_per_tool() {
        let mut m = Hpgl::new(&profile());
        let prog = "IN;SP3;PU40,40;PD80,40;SP1;PU400,400;PD800,400,800,800;PD400,400;PU;ZZ1;SP0;";
        let mut rest = prog.as_bytes();
        while let Some(n) = next_instruction(rest) {
            m.execute(&rest[..n]);
            rest = &rest[n..];
        }
        assert_eq!(m.rec.paths.len(), 2);
        assert_eq!(m.rec.paths[0].tool, "draw");
        assert_eq!(m.rec.paths[0].points, vec![[40.0, 40.0], [80.0, 40.0]]);
        assert_eq!(m.rec.paths[1].tool, "cut");
        assert_eq!(
            m.rec.paths[1].points,
            vec![
                [400.0, 400.0],
                [800.0, 400.0],
                [800.0, 800.0],
                [400.0, 400.0]
            ]
        );
        assert_eq!(m.ignored.get("ZZ"), Some(&1));
        // Travel: origin→(40,40), (80,40)→(400,400).
        let expect = 40.0 * 2f64.sqrt() + (320.0f64.powi(2) + 360.0f64.powi(2)).sqrt();
        assert!((m.rec.travel - expect).abs() < 1e-9);
    }

    #[test]
    fn partial_instructions_execute_whole_pairs() {
        assert_eq!(
            executable_prefix(b"PD10,20,30,40,5".iter()),
            Some((14, *b"PD"))
        );
        assert_eq!(executable_prefix(b" pu1,2,".iter()), Some((7, *b"PU")));
        assert_eq!(executable_prefix(b"PD10,20".iter()), None);
        assert_eq!(executable_prefix(b"SP1".iter()), None);
        assert_eq!(executable_prefix(b"PDx".iter()), None);
    }

    #[test]
    fn relative_moves_and_speed() {
        let mut m = Hpgl::new(&profile());
        m.execute(b"SP1;");
        m.execute(b"VS10;");
        m.execute(b"PR;");
        m.execute(b"PU100,0;");
        let t = m.execute(b"PD400,0,0,400;");
        // 800 units = 20 mm at 10 cm/s.
        assert!((t - 0.2).abs() < 1e-12, "{t}");
        assert_eq!(
            m.rec.paths[0].points,
            vec![[100.0, 0.0], [500.0, 0.0], [500.0, 400.0]]
        );
        // Bad parameters are counted, not executed.
        m.execute(b"PDx,y;");
        assert_eq!(m.ignored.get("PD (bad parameters)"), Some(&1));
    }
}
