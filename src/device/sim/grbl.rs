//! The simulated cutter's GRBL 1.1 interpreter: one line in, `ok` or `error:N` out, as GRBL's
//! `gc_execute_line` decides for the subset a cutter, pen plotter or laser needs.
//!
//! Understood: `G0 G1` (motion), `G4 P` (dwell, seconds), `G17 G20 G21 G54 G90 G91 G94`,
//! `M2 M30` (program end: spindle off), `M3 M4 M5` with `S`, `M8 M9`, words `X Y Z F S P N`,
//! comments `( … )` and `; …`, `$` system commands (`$$ $# $G $I $N $C $X`, `$n=v`; `$H` is
//! `error:5` because homing is off). Errors follow GRBL's order of checks closely enough for a
//! host to see the same codes: a letterless word is `error:1`, a bad number `error:2`, an
//! unknown `$` command `error:3`, a line over 80 characters `error:11`, an unknown G or M code
//! `error:20`, two words of one modal group `error:21`, `G1` before any feed `error:22`, a
//! repeated word `error:25`, `G4` without `P` `error:28`, a G-code line while in alarm
//! `error:9`.
//!
//! Which tool is down is read off the profile's tool table (GRBL itself has no notion of it):
//! a knife is down while Z is below the midpoint between its `z_down` and `z_up`; a servo pen
//! while the spindle is on with `S` nearer `servo_down` than `servo_up`; a laser while the
//! spindle is on with `S > 0` during `G1` (GRBL's laser mode turns the beam off on `G0`). When
//! several tools qualify, the one whose setting is nearest wins. Profiles without such tools
//! (plain G-code) count Z < 0 as down.
//!
//! Motion time: `G1` at `F` (mm/min), `G0` at `RAPID_MM_MIN`, `G4` its `P`.

use super::record::Recorder;
use crate::profile::Profile;
use glam::{DVec2, DVec3};

/// Rapid (G0) rate, mm/min; GRBL's default `$110`/`$111` max rate is 500, cutters set more.
pub(crate) const RAPID_MM_MIN: f64 = 6000.0;

#[derive(Debug, Clone)]
enum ToolRule {
    Knife {
        name: String,
        z_down: f64,
        z_up: f64,
    },
    Servo {
        name: String,
        down: f64,
        up: f64,
    },
    Laser {
        name: String,
        power: f64,
    },
}

/// A GRBL controller's parser state (not its buffers: those are the simulator's).
#[derive(Debug, Clone)]
pub struct Grbl {
    rules: Vec<ToolRule>,
    pub pos: DVec3,
    g1: bool,
    relative: bool,
    inches: bool,
    feed: Option<f64>,
    spindle_on: bool,
    pub s: f64,
    pub alarm: bool,
    pub rec: Recorder,
    /// Lines executed without error.
    pub lines_ok: usize,
}

/// What a line does.
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    /// Planned motion or dwell of this many seconds (0 for mode changes).
    Motion(f64),
    /// A `$` command's text answer, lines without the final `ok`.
    Text(Vec<String>),
}

impl Grbl {
    pub fn new(profile: &Profile) -> Grbl {
        let mut rules = Vec::new();
        for (kind, t) in &profile.tools {
            if let (Some(z_down), Some(z_up)) = (t.z_down, t.z_up) {
                rules.push(ToolRule::Knife {
                    name: kind.clone(),
                    z_down,
                    z_up,
                });
            } else if let (Some(down), Some(up)) = (t.servo_down, t.servo_up) {
                rules.push(ToolRule::Servo {
                    name: kind.clone(),
                    down,
                    up,
                });
            } else if let Some(power) = t.power {
                rules.push(ToolRule::Laser {
                    name: kind.clone(),
                    power,
                });
            }
        }
        // The machine starts with its tool up: a knife at its highest `z_up` (the user zeroes
        // Z on the material and the controller is told where the tool is by the first `G0 Z`).
        let z0 = rules
            .iter()
            .filter_map(|r| match r {
                ToolRule::Knife { z_up, .. } => Some(*z_up),
                _ => None,
            })
            .fold(0.0f64, f64::max);
        Grbl {
            rules,
            pos: DVec3::new(0.0, 0.0, z0),
            g1: false,
            relative: false,
            inches: false,
            feed: None,
            spindle_on: false,
            s: 0.0,
            alarm: false,
            rec: Recorder::for_profile(profile),
            lines_ok: 0,
        }
    }

    /// The tool that is down in the current state, if any.
    fn tool_down(&self, g1: bool) -> Option<String> {
        let mut best: Option<(f64, &String)> = None;
        for r in &self.rules {
            let candidate = match r {
                ToolRule::Knife { name, z_down, z_up } => (self.pos.z < 0.5 * (z_down + z_up))
                    .then(|| ((self.pos.z - z_down).abs(), name)),
                ToolRule::Servo { name, down, up } => (self.spindle_on
                    && (self.s - down).abs() < (self.s - up).abs())
                .then(|| ((self.s - down).abs(), name)),
                ToolRule::Laser { name, power } => {
                    (self.spindle_on && self.s > 0.0 && g1).then(|| ((self.s - power).abs(), name))
                }
            };
            if let Some((d, n)) = candidate {
                if best.is_none_or(|(b, _)| d < b) {
                    best = Some((d, n));
                }
            }
        }
        if self.rules.is_empty() && self.pos.z < 0.0 {
            return Some("z<0".into());
        }
        best.map(|(_, n)| n.clone())
    }

    /// The tool that is down now (a laser counts while it is on).
    pub(crate) fn tool_down_now(&self) -> Option<String> {
        self.tool_down(true)
    }

    /// Soft reset: spindle off, modes to defaults, position kept.
    pub fn reset(&mut self) {
        self.spindle_on = false;
        self.g1 = false;
        self.relative = false;
        self.inches = false;
        self.rec.up();
    }

    /// Execute one line (without its line ending).
    pub(crate) fn execute(&mut self, line: &str) -> Result<Effect, u32> {
        if line.len() > crate::device::grbl::LINE_MAX {
            return Err(11);
        }
        let trimmed = line.trim();
        if let Some(cmd) = trimmed.strip_prefix('$') {
            return self.system(cmd);
        }
        let text = strip(trimmed);
        if text.is_empty() {
            return Ok(Effect::Motion(0.0));
        }
        if self.alarm {
            return Err(9);
        }
        let block = Block::parse(&words(&text)?)?;
        self.apply(&block)
    }

    /// Carry out a parsed block: the effect of its words, in GRBL's order.
    fn apply(&mut self, k: &Block) -> Result<Effect, u32> {
        // Apply in GRBL's order: feed, spindle speed, spindle, dwell, units, distance, motion.
        if let Some(u) = k.units {
            self.inches = u;
        }
        let scale = if self.inches { 25.4 } else { 1.0 };
        if let Some(f) = k.f {
            self.feed = Some(f * scale);
        }
        if let Some(s) = k.s {
            self.s = s;
        }
        if let Some(sp) = k.spindle {
            self.spindle_on = sp.unwrap_or(false);
        }
        let mut seconds = 0.0;
        if k.dwell {
            let Some(p) = k.p else { return Err(28) };
            if p < 0.0 {
                return Err(4);
            }
            seconds += p;
        } else if k.p.is_some() {
            return Err(36);
        }
        if let Some(d) = k.distance {
            self.relative = d;
        }
        if let Some(m) = k.motion {
            self.g1 = m;
        }
        let axes = k.x.is_some() || k.y.is_some() || k.z.is_some();
        if axes && !k.dwell {
            if self.g1 && self.feed.is_none() {
                return Err(22);
            }
            let coord = |v: Option<f64>, cur: f64| match v {
                Some(v) if self.relative => cur + v * scale,
                Some(v) => v * scale,
                None => cur,
            };
            let target = DVec3::new(
                coord(k.x, self.pos.x),
                coord(k.y, self.pos.y),
                coord(k.z, self.pos.z),
            );
            let rate = if self.g1 {
                self.feed.unwrap_or(RAPID_MM_MIN)
            } else {
                RAPID_MM_MIN
            };
            if rate > 0.0 {
                seconds += self.pos.distance(target) / rate * 60.0;
            }
            self.move_to(target);
        }
        if k.end {
            self.spindle_on = false;
            self.relative = false;
            self.rec.up();
        }
        // Tool state may change without motion (M3/M5, Z-less): open or close paths.
        self.sync_tool();
        self.lines_ok += 1;
        Ok(Effect::Motion(seconds))
    }

    fn move_to(&mut self, target: DVec3) {
        let from = self.pos;
        // A Z move: the tool state changes at the end of it.
        if (target.z - from.z).abs() > 0.0 && (target.truncate() - from.truncate()).length() == 0.0
        {
            self.pos = target;
            self.sync_tool();
            return;
        }
        let tool = self.tool_down(self.g1);
        self.rec
            .travel_to(from.truncate(), target.truncate(), tool.as_deref());
        self.pos = target;
    }

    /// Start a path where a tool went down without moving; end it where it came up.
    fn sync_tool(&mut self) {
        match self.tool_down(self.g1) {
            // A laser only burns while moving under G1; nothing to start.
            Some(t) if !self.is_laser(&t) => self.rec.down(&t, self.pos.truncate()),
            Some(_) => {}
            None => self.rec.up(),
        }
    }

    fn is_laser(&self, name: &str) -> bool {
        self.rules
            .iter()
            .any(|r| matches!(r, ToolRule::Laser { name: n, .. } if n == name))
    }

    fn system(&mut self, cmd: &str) -> Result<Effect, u32> {
        let cmd = cmd.trim().to_ascii_uppercase();
        match cmd.as_str() {
            "" => Ok(Effect::Text(vec![
                "[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]".into(),
            ])),
            "$" => Ok(Effect::Text(vec![
                "$0=10".into(),
                "$30=1000".into(),
                "$31=0".into(),
                "$32=1".into(),
            ])),
            "X" => {
                self.alarm = false;
                Ok(Effect::Text(vec!["[MSG:Caution: Unlocked]".into()]))
            }
            "H" => Err(5),
            "G" => Ok(Effect::Text(vec![format!(
                "[GC:G{} G54 G17 G21 G{} G94 M{} M9 T0 F{} S{}]",
                if self.g1 { 1 } else { 0 },
                if self.relative { 91 } else { 90 },
                if self.spindle_on { 3 } else { 5 },
                self.feed.unwrap_or(0.0),
                self.s
            )])),
            "I" => Ok(Effect::Text(vec!["[VER:1.1h.20190830:flatcut-sim]".into()])),
            "#" | "N" | "C" => Ok(Effect::Text(Vec::new())),
            c if c.contains('=') => {
                let (k, v) = c.split_once('=').unwrap_or(("", ""));
                let k = k.trim_start_matches('N');
                if k.parse::<u32>().is_err() || (v.parse::<f64>().is_err() && !c.starts_with('N')) {
                    return Err(3);
                }
                Ok(Effect::Text(Vec::new()))
            }
            _ => Err(3),
        }
    }

    /// A status report in GRBL 1.1's format for the given state word.
    pub fn status(&self, state: &str) -> String {
        format!(
            "<{state}|MPos:{:.3},{:.3},{:.3}|FS:{},{}>",
            self.pos.x,
            self.pos.y,
            self.pos.z,
            self.feed.unwrap_or(0.0),
            if self.spindle_on { self.s } else { 0.0 }
        )
    }

    /// Where the machine is in the XY plane.
    pub fn xy(&self) -> DVec2 {
        self.pos.truncate()
    }
}

/// A line without its comments and blanks, upper-cased.
fn strip(trimmed: &str) -> String {
    let mut text = String::new();
    let mut in_paren = false;
    for c in trimmed.chars() {
        match c {
            '(' => in_paren = true,
            ')' => in_paren = false,
            ';' if !in_paren => break,
            c if in_paren || c.is_whitespace() => {}
            c => text.push(c.to_ascii_uppercase()),
        }
    }
    text
}

/// The words of a stripped line: a letter and its number each (error 1: not a letter; 2: a
/// bad number).
fn words(text: &str) -> Result<Vec<(u8, f64)>, u32> {
    let b = text.as_bytes();
    let mut words: Vec<(u8, f64)> = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let letter = b[i];
        if !letter.is_ascii_alphabetic() {
            return Err(1);
        }
        let start = i + 1;
        let mut j = start;
        while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.' || b[j] == b'-' || b[j] == b'+')
        {
            j += 1;
        }
        let v: f64 = text[start..j].parse().map_err(|_| 2u32)?;
        words.push((letter, v));
        i = j;
    }
    Ok(words)
}

/// The words of one block by modal group: `None` where the block does not set it.
#[derive(Debug, Default)]
struct Block {
    /// G0 (false) or G1 (true).
    motion: Option<bool>,
    /// G4.
    dwell: bool,
    /// G20 (true: inches) or G21.
    units: Option<bool>,
    /// G90 or G91 (true: relative).
    distance: Option<bool>,
    /// M3/M4 (`Some(true)`) or M5 (`Some(false)`).
    spindle: Option<Option<bool>>,
    /// M2 or M30.
    end: bool,
    x: Option<f64>,
    y: Option<f64>,
    z: Option<f64>,
    f: Option<f64>,
    s: Option<f64>,
    p: Option<f64>,
}

impl Block {
    /// Sort the words into modal groups, with GRBL's error numbers for two words of one
    /// group (21), an unsupported command (20), a repeated letter (25), a negative value (4).
    fn parse(words: &[(u8, f64)]) -> Result<Block, u32> {
        let mut blk = Block::default();
        let mut seen = [false; 26];
        for &(l, v) in words {
            match l {
                b'G' => {
                    let code = (v * 10.0).round() as i64;
                    match code {
                        0 | 10 => {
                            if blk.motion.replace(code == 10).is_some() {
                                return Err(21);
                            }
                        }
                        40 => blk.dwell = true,
                        200 | 210 => {
                            if blk.units.replace(code == 200).is_some() {
                                return Err(21);
                            }
                        }
                        900 | 910 => {
                            if blk.distance.replace(code == 910).is_some() {
                                return Err(21);
                            }
                        }
                        170 | 540 | 940 => {}
                        _ => return Err(20),
                    }
                }
                b'M' => {
                    let code = (v * 10.0).round() as i64;
                    match code {
                        20 | 300 => blk.end = true,
                        30 | 40 => {
                            if blk.spindle.replace(Some(true)).is_some() {
                                return Err(21);
                            }
                        }
                        50 => {
                            if blk.spindle.replace(Some(false)).is_some() {
                                return Err(21);
                            }
                        }
                        80 | 90 => {}
                        _ => return Err(20),
                    }
                }
                _ => {
                    let k = (l - b'A') as usize;
                    if seen[k] {
                        return Err(25);
                    }
                    seen[k] = true;
                    match l {
                        b'X' => blk.x = Some(v),
                        b'Y' => blk.y = Some(v),
                        b'Z' => blk.z = Some(v),
                        b'F' => {
                            if v < 0.0 {
                                return Err(4);
                            }
                            blk.f = Some(v)
                        }
                        b'S' => {
                            if v < 0.0 {
                                return Err(4);
                            }
                            blk.s = Some(v)
                        }
                        b'P' => blk.p = Some(v),
                        b'N' => {}
                        _ => return Err(20),
                    }
                }
            }
        }
        Ok(blk)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Execute `lines`, each of which must be accepted.
    fn run(g: &mut Grbl, lines: &[&str]) {
        for l in lines {
            g.execute(l).unwrap();
        }
    }

    fn knife() -> Profile {
        crate::profile::parse(
            "name='k'\ndescription='d'\nlanguage='gcode'\ndialect='grbl'\nunits_per_mm=1\nprotocol='grbl-character-counting'\nbuffer=128\n\
             [tools.cut]\nz_down=-1\nz_up=2\nspeed=600\n[tools.score]\nz_down=-0.3\nz_up=2\nspeed=900\n",
            "k.toml",
        )
        .unwrap()
    }

    #[test]
    fn knife_paths_and_errors() {
        let mut g = Grbl::new(&knife());
        run(
            &mut g,
            &[
                "G21",
                "G90",
                "G94",
                "G0 Z2",
                "G0 X10 Y10",
                "G1 Z-1 F600",
                "G1 X20",
                "G1 Y20",
                "G0 Z2",
            ],
        );
        run(&mut g, &["G0 X0 Y0", "G1 Z-0.3 F900", "G1 X5", "G0 Z2"]);
        assert_eq!(g.rec.paths.len(), 2);
        assert_eq!(g.rec.paths[0].tool, "cut");
        assert_eq!(
            g.rec.paths[0].points,
            vec![[10.0, 10.0], [20.0, 10.0], [20.0, 20.0]]
        );
        assert_eq!(g.rec.paths[1].tool, "score");
        // Z 2 → -1 at the rapid rate; then 10 mm at the last feed, 900 mm/min.
        assert_eq!(
            g.execute("G0 Z-1").unwrap(),
            Effect::Motion(3.0 / RAPID_MM_MIN * 60.0)
        );
        assert_eq!(
            g.execute("G1 X15").unwrap(),
            Effect::Motion(10.0 / 900.0 * 60.0)
        );

        let mut fresh = Grbl::new(&knife());
        assert_eq!(fresh.execute("G1 X1"), Err(22));
        assert_eq!(fresh.execute("G5 X1"), Err(20));
        assert_eq!(fresh.execute("G0 X1 X2"), Err(25));
        assert_eq!(fresh.execute("G0 G1 X2"), Err(21));
        assert_eq!(fresh.execute("G0 X1.2.3"), Err(2));
        assert_eq!(fresh.execute("%"), Err(1));
        assert_eq!(fresh.execute("G4"), Err(28));
        assert_eq!(fresh.execute("$Q"), Err(3));
        assert_eq!(fresh.execute("$H"), Err(5));
        assert_eq!(fresh.execute(&"G0 X1 ".repeat(20)), Err(11));
        assert!(fresh.execute("(a comment) ; another").is_ok());
        fresh.alarm = true;
        assert_eq!(fresh.execute("G0 X1"), Err(9));
        assert!(fresh.execute("$X").is_ok());
        assert!(fresh.execute("G0 X1").is_ok());
    }

    #[test]
    fn laser_burns_only_on_g1() {
        let p = crate::profile::parse(
            "name='l'\ndescription='d'\nlanguage='gcode'\ndialect='grbl'\nunits_per_mm=1\nprotocol='grbl-character-counting'\nmax_power=1000\n\
             [tools.cut]\npower=1000\nspeed=300\n[tools.draw]\npower=200\nspeed=1500\n",
            "l.toml",
        )
        .unwrap();
        let mut g = Grbl::new(&p);
        run(
            &mut g,
            &[
                "G0 X1 Y1",
                "M4 S200",
                "G1 X2 F1500",
                "G1 Y2",
                "M5",
                "G0 X5",
                "M4 S1000",
                "G0 X6",
                "G1 X7 F300",
                "M5",
            ],
        );
        assert_eq!(g.rec.paths.len(), 2);
        assert_eq!(g.rec.paths[0].tool, "draw");
        assert_eq!(
            g.rec.paths[0].points,
            vec![[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]]
        );
        assert_eq!(g.rec.paths[1].tool, "cut");
        assert_eq!(g.rec.paths[1].points, vec![[6.0, 2.0], [7.0, 2.0]]);
    }
}
