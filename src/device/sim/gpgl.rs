//! The simulated cutter's GP-GL interpreter (Graphtec cutters in native mode): the subset that
//! flatcut's encoder (`output::gpgl`) and common drivers send — `H`, `M`, `D`, `O`, `E`, `J`,
//! `!`, `FX` — executed as the cutter would; anything else is skipped and counted by name.
//!
//! Instructions end with ETX (0x03), a line feed or a carriage return and are read by the
//! crate's one GP-GL lexer (`output::gpgl::instruction`). `M x,y` moves with the tool up and
//! `D x1,y1,…` with it down, absolute; `O` and `E` are their relative forms; `H` lifts the tool
//! and goes to the origin; `J n` lifts the tool and takes tool n. A stray odd coordinate is
//! ignored. Which tool of the profile is down is told as in the HP-GL interpreter: the tool
//! with this number, and where several share it (one holder), the one whose force is nearest
//! the last `FX` (a tool with no force of its own only when none other is left, or no `FX` was
//! sent).
//!
//! Motion time: tool-down moves at the `!` speed (cm/s; the profile's tool speed when the
//! program sets none), tool-up moves at the HP-GL interpreter's travel speed.

use super::hpgl::{DEFAULT_CM_S, TRAVEL_CM_S};
use super::record::Recorder;
use crate::output::gpgl::instruction;
use crate::profile::Profile;
use glam::DVec2;
use std::collections::BTreeMap;

/// A Graphtec cutter's state.
#[derive(Debug, Clone)]
pub struct Gpgl {
    units_per_mm: f64,
    /// Tool number → (stroke kind, force) of the profile's tools with it.
    pens: BTreeMap<u32, Vec<(String, Option<f64>)>>,
    /// Tool number → the profile's speed for it, cm/s.
    pen_speed: BTreeMap<u32, f64>,
    force: Option<f64>,
    speed_cm_s: Option<f64>,
    pos: DVec2,
    down: bool,
    pen: u32,
    pub rec: Recorder,
    /// Instructions executed.
    pub instructions: usize,
    /// Instructions not understood, by mnemonic.
    pub ignored: BTreeMap<String, usize>,
}

impl Gpgl {
    pub fn new(profile: &Profile) -> Gpgl {
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
        Gpgl {
            units_per_mm: profile.units_per_mm,
            pens,
            pen_speed,
            force: None,
            speed_cm_s: None,
            pos: DVec2::ZERO,
            down: false,
            // A Graphtec cutter has a tool selected from power-on: tool 1.
            pen: 1,
            rec: Recorder::for_profile(profile),
            instructions: 0,
            ignored: BTreeMap::new(),
        }
    }

    /// The stroke kind of the tool in use (see the module documentation).
    fn tool_name(&self) -> Option<String> {
        let Some(tools) = self.pens.get(&self.pen) else {
            return Some(format!("pen {}", self.pen));
        };
        let mut best: Option<(f64, &String)> = None;
        for (name, force) in tools {
            // A tool without a force of its own is the last guess once a force is set.
            let d = match (self.force, force) {
                (Some(a), Some(b)) => (a - b).abs(),
                (Some(_), None) => f64::MAX,
                (None, _) => 0.0,
            };
            if best.is_none_or(|(b, _)| d < b) {
                best = Some((d, name));
            }
        }
        best.map(|(_, n)| n.clone())
    }

    /// Where the tool is, device units.
    pub(crate) fn position(&self) -> DVec2 {
        self.pos
    }

    /// Whether a tool is down now (whichever it is).
    pub(crate) fn is_down(&self) -> bool {
        self.down
    }

    /// The tool that is down now, if any.
    pub(crate) fn tool_down(&self) -> Option<String> {
        self.down.then(|| self.tool_name()).flatten()
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

    fn lift(&mut self) {
        self.down = false;
        self.rec.up();
    }

    /// Execute one instruction (its bytes, terminator optional). Returns the time its motion
    /// takes, seconds.
    pub(crate) fn execute(&mut self, raw: &[u8]) -> f64 {
        let (op, nums) = match instruction(raw) {
            None => return 0.0,
            Some(Err(_)) => {
                let op: String = String::from_utf8_lossy(raw)
                    .trim()
                    .chars()
                    .take_while(|c| c.is_ascii_alphabetic() || "!^\\".contains(*c))
                    .collect::<String>()
                    .to_ascii_uppercase();
                *self
                    .ignored
                    .entry(format!("{op} (bad parameters)"))
                    .or_default() += 1;
                return 0.0;
            }
            Some(Ok(it)) => it,
        };
        self.instructions += 1;
        match op.as_str() {
            "H" => {
                self.lift();
                self.moves(&[0.0, 0.0], false)
            }
            "J" => {
                self.lift();
                self.pen = nums.first().map(|&v| v.max(0.0) as u32).unwrap_or(1);
                0.0
            }
            "M" | "O" => {
                self.lift();
                self.moves(&nums, op == "O")
            }
            "D" | "E" => {
                if !self.down {
                    self.down = true;
                    if let Some(t) = self.tool_name() {
                        self.rec.down(&t, self.pos);
                    }
                }
                self.moves(&nums, op == "E")
            }
            "!" => {
                self.speed_cm_s = nums.first().copied().filter(|v| *v > 0.0);
                0.0
            }
            "FX" => {
                // The new force applies from the next tool-down, as on cutters.
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

    fn moves(&mut self, nums: &[f64], relative: bool) -> f64 {
        let tool = if self.down { self.tool_name() } else { None };
        let speed = self.speed_units_s(self.down && tool.is_some());
        let mut t = 0.0;
        for xy in nums.chunks_exact(2) {
            let v = DVec2::new(xy[0], xy[1]);
            let target = if relative { self.pos + v } else { v };
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
    use crate::output::gpgl::next_instruction;

    fn run(m: &mut Gpgl, prog: &[u8]) -> f64 {
        let mut rest = prog;
        let mut t = 0.0;
        while let Some(n) = next_instruction(rest) {
            t += m.execute(&rest[..n]);
            rest = &rest[n..];
        }
        t
    }

    #[test]
    fn records_tool_down_paths_per_tool() {
        let p = crate::profile::find("graphtec-ce6000-gpgl").unwrap();
        let mut m = Gpgl::new(&p);
        let prog = b"H\x03\nJ1\x03!20\x03FX14,1\x03M10,10\x03D20,10,20,20\x03\
            FX5,1\x03M0,0\x03D0,10\x03ZZ1\x03E10,0\x03H\x03";
        let t = run(&mut m, prog);
        assert_eq!(m.rec.paths.len(), 2);
        assert_eq!(m.rec.paths[0].tool, "cut");
        assert_eq!(m.rec.paths[1].tool, "score");
        assert_eq!(m.ignored.get("ZZ"), Some(&1));
        assert!(m.tool_down().is_none());
        assert!(t > 0.0);
        // 20 steps of 0.1 mm down at 20 cm/s = 0.01 s: the first path's drawing time.
        let mut m = Gpgl::new(&p);
        m.execute(b"!20");
        let t = m.execute(b"D0,20");
        assert!((t - 0.01).abs() < 1e-12, "{t}");
        assert_eq!(m.tool_down().as_deref(), Some("cut"));
        m.execute(b"D1,x");
        assert_eq!(m.ignored.get("D (bad parameters)"), Some(&1));
    }
}
