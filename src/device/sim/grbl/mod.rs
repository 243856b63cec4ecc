//! The simulated cutter's GRBL interpreter: one line in, `ok` or `error:N` out, as GRBL 1.1h's
//! `gc_execute_line` and `system_execute_line` decide, for the G-code a cutter, pen plotter or
//! laser sends and the commands a host uses. Where this and the real firmware
//! (`../shared/peers/grbl-sim`) disagree, the firmware is right; `tests/suite/grbl_firmware.rs`
//! sends both the same lines and compares the answers.
//!
//! Understood: `G0 G1 G2 G3` (arcs by offsets or radius, in the plane of `G17 G18 G19`), `G4 P`
//! (dwell, seconds), `G10 L2`/`L20`, `G28 G30` (with their `.1`), `G53`, `G54`–`G59`, `G92`
//! (and `.1`), `G20 G21 G90 G91 G93 G94 G40 G43.1 G49 G61 G80`; `M0` (pause until `~`), `M1`,
//! `M2 M30` (program end), `M3 M4 M5` with `S`, `M8 M9`; words `X Y Z I J K R F S P L N T`;
//! comments `( … )` and `; …`; `$` commands (`$ $$ $# $G $I $N $X $C`, `$n=v`; `$H` is
//! `error:5` because homing is off). Block parsing and its errors are [`super::grbl_block`];
//! then, in GRBL's order: `N` over 9,999,999 `error:27`, `T` over 255 `38`, an undefined feed
//! for `G1`–`G3` (none yet, `F0`, `G93` without `F`) `22`, `G4` without `P` `28`, `G10` without
//! `L`/`P` `28`, its `P` over 6 `29`, `G53` outside `G0`/`G1` `30`, axis words under `G80`
//! `31`, an arc without axis words in its plane `32`, an arc whose end is not on its circle
//! `33`, a radius too small `34`, an offset arc without offsets in its plane `35`, words no
//! command used `36`, more than 79 significant characters `11`, a G-code line in alarm `9`.
//!
//! What waits for the planner to empty, as in GRBL (the line's `ok` is held): a spindle or
//! coolant change, an `S` change while the spindle runs (in laser mode `$32=1` not when the
//! block moves under `G1`–`G3`), `G4` (its `ok` after the dwell), `G10`, `G28.1`, `G30.1`, `M0`,
//! `M2`, `M30`. `$$`, `$#`, `$n=v`, `$C` and `$X` while the machine moves are `error:8`.
//!
//! Which tool is down is read off the profile's tool table (GRBL itself has no notion of it):
//! a knife is down while Z is below the midpoint between its `z_down` and `z_up`; a servo pen
//! while the spindle is on with `S` nearer `servo_down` than `servo_up`; a laser while the
//! spindle is on with `S > 0` during `G1`–`G3` (laser mode turns the beam off on `G0`). When
//! several tools qualify, the one whose setting is nearest wins. Profiles without such tools
//! (plain G-code) count Z < 0 as down.
//!
//! Motion time: GRBL's planner as [`crate::device::motion`] models it, with the settings
//! `$110`–`$122` and `$11` (from the profile's `[grbl]`, changeable with `$n=v`); arcs are cut
//! into chords within `$12` as `mc_arc` does; `G4` its `P`.

use super::grbl_block::{self as gb, AxisCommand, Block, Motion, NonModal};
mod system;

use super::record::Recorder;
use crate::device::motion::Planner;
use crate::profile::Profile;
use glam::{DVec2, DVec3};
use system::Settings;

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
    /// Machine position, mm.
    pub pos: DVec3,
    pub(crate) motion: Motion,
    g1: bool,
    relative: bool,
    inches: bool,
    inverse_time: bool,
    plane: u8,
    pub(crate) coord: usize,
    pub(crate) coords: [DVec3; 6],
    pub(crate) g28: DVec3,
    pub(crate) g30: DVec3,
    pub(crate) g92: DVec3,
    pub(crate) tlo: f64,
    feed: f64,
    /// 0 off, 1 M3, 2 M4.
    spindle: u8,
    coolant: bool,
    spindle_on: bool,
    pub s: f64,
    pub(crate) tool: f64,
    pub alarm: bool,
    pub(crate) check_mode: bool,
    pub(crate) settings: Settings,
    pub(crate) planner: Planner,
    pub rec: Recorder,
    /// A registration-mark sensor on the probe pin (`G38.3`), with a printed sheet loaded.
    pub(crate) probe: Option<crate::device::sim::sensor::Sensor>,
    /// Lines executed without error.
    pub lines_ok: usize,
    /// GRBL 0.9 (text errors, `<State,MPos:…>` status).
    pub(crate) v0_9: bool,
}

/// What a line does.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Effect {
    /// Planned motion of this many seconds (0 for mode changes), and the change to the time of
    /// the move still queued before it (≤ 0: it no longer ends at rest).
    pub seconds: f64,
    pub correction: f64,
    /// A dwell: the `ok` comes after this many seconds, once the planner is empty.
    pub dwell: Option<f64>,
    /// Lines sent before the `ok` (`$` answers, `[MSG:…]`).
    pub text: Vec<String>,
    /// `M0`: the machine holds after this line until cycle start.
    pub pause: bool,
    /// `$C` leaving check mode: GRBL resets itself after the answer.
    pub reset: bool,
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
        let laser = rules.iter().any(|r| matches!(r, ToolRule::Laser { .. }));
        let settings = Settings::for_profile(profile, laser);
        Grbl {
            rules,
            pos: DVec3::new(0.0, 0.0, z0),
            motion: Motion::Seek,
            g1: false,
            relative: false,
            inches: false,
            inverse_time: false,
            plane: 0,
            coord: 0,
            coords: [DVec3::ZERO; 6],
            g28: DVec3::ZERO,
            g30: DVec3::ZERO,
            g92: DVec3::ZERO,
            tlo: 0.0,
            feed: 0.0,
            spindle: 0,
            coolant: false,
            spindle_on: false,
            s: 0.0,
            tool: 0.0,
            alarm: false,
            check_mode: false,
            planner: Planner::new(&settings.machine()),
            settings,
            rec: Recorder::for_profile(profile),
            probe: None,
            lines_ok: 0,
            v0_9: profile.grbl.version == "0.9",
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

    /// Soft reset: spindle and coolant off, modes to defaults, position and offsets kept.
    pub fn reset(&mut self) {
        self.spindle_on = false;
        self.spindle = 0;
        self.coolant = false;
        self.g1 = false;
        self.motion = Motion::Seek;
        self.relative = false;
        self.inches = false;
        self.inverse_time = false;
        self.plane = 0;
        self.coord = 0;
        self.tlo = 0.0;
        self.check_mode = false;
        self.planner.stop();
        self.rec.up();
    }

    /// Whether `line` waits for the planner to empty before it runs (see the module docs).
    pub(crate) fn needs_sync(&self, line: &str) -> bool {
        let text = gb::strip(line);
        if text.is_empty() || text.starts_with('$') || self.alarm {
            return false;
        }
        let Ok(k) = gb::parse(&text) else {
            return false;
        };
        let spindle_after = k.spindle.unwrap_or(self.spindle);
        let moving = matches!(
            k.motion.unwrap_or(self.motion),
            Motion::Linear | Motion::Cw | Motion::Ccw
        ) && k.has_axes()
            && k.axis_command == AxisCommand::Motion;
        let s_change = k.get(b'S').is_some_and(|s| s != self.s)
            && spindle_after != 0
            && !(self.settings.laser_mode() && moving);
        k.spindle.is_some_and(|s| s != self.spindle)
            || k.coolant.is_some_and(|c| c != self.coolant)
            || s_change
            || matches!(
                k.non_modal,
                Some(
                    NonModal::Dwell | NonModal::SetCoord | NonModal::SetHome0 | NonModal::SetHome1
                )
            )
            || matches!(k.flow, Some(0 | 2 | 30))
    }

    /// Execute one line (without its line ending); `busy`: the machine is moving. An `Err` is
    /// GRBL's error code for the line.
    pub fn execute(&mut self, line: &str, busy: bool) -> Result<Effect, u32> {
        if crate::device::grbl::significant_len(line) > crate::device::grbl::LINE_MAX {
            return Err(11);
        }
        let text = gb::strip(line);
        if text.is_empty() {
            return Ok(Effect::default());
        }
        if let Some(cmd) = text.strip_prefix('$') {
            let cmd = cmd.to_string();
            return self.system(&cmd, busy);
        }
        if self.alarm {
            return Err(9);
        }
        let block = gb::parse(&text)?;
        let e = self.apply(&block)?;
        self.lines_ok += 1;
        Ok(e)
    }

    /// The checks of GRBL's step 3 that need the machine's state.
    fn check(&self, k: &Block) -> Result<(), u32> {
        if k.get(b'N').is_some_and(|n| n > 9_999_999.0) {
            return Err(27);
        }
        if k.get(b'T').is_some_and(|t| t > 255.0) {
            return Err(38);
        }
        let motion = k.motion.unwrap_or(self.motion);
        let inverse = k.inverse_time.unwrap_or(self.inverse_time);
        let moving = k.axis_command == AxisCommand::Motion;
        if moving
            && matches!(
                motion,
                Motion::Linear | Motion::Cw | Motion::Ccw | Motion::Probe
            )
        {
            let f = k.get(b'F');
            let undefined = if inverse {
                f.is_none_or(|f| f == 0.0)
            } else {
                f.unwrap_or(self.feed) == 0.0
            };
            if undefined {
                return Err(22);
            }
        }
        match k.non_modal {
            Some(NonModal::Dwell) if k.get(b'P').is_none() => return Err(28),
            Some(NonModal::SetCoord) => {
                if k.get(b'L').is_none() && k.get(b'P').is_none() {
                    return Err(28);
                }
                if !k.has_axes() {
                    return Err(26);
                }
                if k.get(b'P').is_some_and(|p| p.fract() != 0.0 || p > 6.0) {
                    return Err(29);
                }
                if !matches!(k.get(b'L'), Some(2.0) | Some(20.0)) {
                    return Err(20);
                }
            }
            Some(NonModal::SetOffset) if !k.has_axes() => return Err(26),
            Some(NonModal::Absolute) if !matches!(motion, Motion::Seek | Motion::Linear) => {
                return Err(30)
            }
            _ => {}
        }
        if motion == Motion::None
            && k.has_axes()
            && !matches!(k.axis_command, AxisCommand::NonModal)
        {
            return Err(31);
        }
        Ok(())
    }

    /// Carry out a parsed block: the effect of its words, in GRBL's order.
    fn apply(&mut self, k: &Block) -> Result<Effect, u32> {
        self.check(k)?;
        let arc = self.arc_plan(k)?;
        let unused = [b'I', b'J', b'K', b'R'].iter().any(|&l| k.get(l).is_some()) && arc.is_none()
            || k.get(b'P').is_some()
                && !matches!(k.non_modal, Some(NonModal::Dwell | NonModal::SetCoord))
            || k.get(b'L').is_some() && k.non_modal != Some(NonModal::SetCoord);
        if unused {
            return Err(36);
        }
        let mut e = Effect::default();
        if self.check_mode {
            return Ok(e);
        }
        if let Some(i) = k.inverse_time {
            self.inverse_time = i;
        }
        if let Some(u) = k.units {
            self.inches = u;
        }
        let scale = if self.inches { 25.4 } else { 1.0 };
        if let Some(f) = k.get(b'F') {
            self.feed = f * scale;
        }
        if let Some(s) = k.get(b'S') {
            self.s = s;
        }
        // GRBL only tracks the tool, from a value cleared at every block.
        self.tool = k.get(b'T').unwrap_or(0.0);
        if let Some(sp) = k.spindle {
            self.spindle = sp;
            self.spindle_on = sp != 0;
        }
        if let Some(c) = k.coolant {
            self.coolant = c;
        }
        if k.non_modal == Some(NonModal::Dwell) {
            let p = k.get(b'P').unwrap_or(0.0);
            self.planner.stop();
            e.dwell = Some(p);
        }
        if let Some(p) = k.plane {
            self.plane = p;
        }
        if let Some(t) = k.tool_length {
            self.tlo = if t {
                k.get(b'Z').unwrap_or(0.0) * scale
            } else {
                0.0
            };
        }
        if let Some(c) = k.coord {
            self.coord = c;
        }
        if let Some(d) = k.relative {
            self.relative = d;
        }
        if let Some(m) = k.motion {
            self.motion = m;
            self.g1 = matches!(m, Motion::Linear | Motion::Cw | Motion::Ccw | Motion::Probe);
        }
        let offset = self.offset();
        let axes = k.axes();
        let work = |i: usize, cur: f64| match axes[i] {
            Some(v) if self.relative => cur + v * scale,
            Some(v) => v * scale + offset[i],
            None => cur,
        };
        let target = DVec3::new(
            work(0, self.pos.x),
            work(1, self.pos.y),
            work(2, self.pos.z),
        );
        self.non_modal(k, target, scale, &mut e);
        if k.axis_command == AxisCommand::Motion {
            let target = if k.non_modal == Some(NonModal::Absolute) {
                DVec3::new(
                    axes[0].map_or(self.pos.x, |v| v * scale),
                    axes[1].map_or(self.pos.y, |v| v * scale),
                    axes[2].map_or(self.pos.z, |v| v * scale),
                )
            } else {
                target
            };
            let feed = (self.g1 && !self.inverse_time).then_some(self.feed);
            match self.motion {
                Motion::Seek => e.add(self.line_to(target, None)),
                Motion::Linear => e.add(self.line_to(target, feed)),
                Motion::Cw | Motion::Ccw => {
                    let (center, _) = arc.unwrap_or_default();
                    e.add(self.arc_to(target, center, self.motion == Motion::Cw, feed));
                }
                Motion::None => {}
                Motion::Probe => {
                    let (e2, text) = self.probe_to(target, feed);
                    e.add(e2);
                    e.text.push(text);
                }
            }
        }
        match k.flow {
            Some(0) => {
                e.pause = true;
                self.planner.stop();
            }
            Some(2 | 30) => {
                self.motion = Motion::Linear;
                self.g1 = true;
                self.plane = 0;
                self.relative = false;
                self.inverse_time = false;
                self.coord = 0;
                self.spindle = 0;
                self.spindle_on = false;
                self.coolant = false;
                self.planner.stop();
                self.rec.up();
                e.text.push("[MSG:Pgm End]".into());
            }
            _ => {}
        }
        if k.spindle.is_some() || k.coolant.is_some() {
            self.planner.stop();
        }
        // Tool state may change without motion (M3/M5, Z-less): open or close paths.
        self.sync_tool();
        Ok(e)
    }

    /// `G10`, `G92`, `G92.1`, `G28.1`, `G30.1`, `G28`, `G30`: `target` is the block's axis
    /// words as a machine position.
    fn non_modal(&mut self, k: &Block, target: DVec3, scale: f64, e: &mut Effect) {
        let axes = k.axes();
        match k.non_modal {
            Some(NonModal::SetCoord) => {
                let p = k.get(b'P').unwrap_or(0.0) as usize;
                let cs = if p == 0 { self.coord } else { p - 1 };
                let mut c = self.coords[cs];
                for i in 0..3 {
                    if let Some(v) = axes[i] {
                        c[i] = if k.get(b'L') == Some(20.0) {
                            self.pos[i] - self.g92[i] - v * scale
                        } else {
                            v * scale
                        };
                    }
                }
                self.coords[cs] = c;
                self.planner.stop();
            }
            Some(NonModal::SetOffset) => {
                for (i, v) in axes.iter().enumerate() {
                    if let Some(v) = v {
                        self.g92[i] = self.pos[i] - self.coords[self.coord][i] - v * scale;
                    }
                }
            }
            Some(NonModal::ResetOffset) => self.g92 = DVec3::ZERO,
            Some(NonModal::SetHome0) => self.g28 = self.pos,
            Some(NonModal::SetHome1) => self.g30 = self.pos,
            Some(h @ (NonModal::GoHome0 | NonModal::GoHome1)) => {
                let home = if h == NonModal::GoHome0 {
                    self.g28
                } else {
                    self.g30
                };
                let mut mid = self.pos;
                for i in 0..3 {
                    if axes[i].is_some() {
                        mid[i] = target[i];
                    }
                }
                e.add(self.line_to(mid, None));
                e.add(self.line_to(home, None));
            }
            _ => {}
        }
    }

    /// The work offset in effect (coordinate system, G92, tool length on Z).
    fn offset(&self) -> DVec3 {
        self.coords[self.coord] + self.g92 + DVec3::new(0.0, 0.0, self.tlo)
    }

    /// The plane's axes: (first, second, linear).
    fn plane_axes(&self) -> (usize, usize) {
        match self.plane {
            1 => (2, 0),
            2 => (1, 2),
            _ => (0, 1),
        }
    }

    /// An arc's centre (machine mm) and radius, checked as GRBL does; `None` when the block is
    /// no arc.
    fn arc_plan(&self, k: &Block) -> Result<Option<(DVec3, f64)>, u32> {
        let motion = k.motion.unwrap_or(self.motion);
        if !matches!(motion, Motion::Cw | Motion::Ccw) || k.axis_command != AxisCommand::Motion {
            return Ok(None);
        }
        let (a0, a1) = self.plane_axes();
        let axes = k.axes();
        if axes[a0].is_none() && axes[a1].is_none() {
            return Err(32);
        }
        let scale = if k.units.unwrap_or(self.inches) {
            25.4
        } else {
            1.0
        };
        let offset = self.offset();
        let relative = k.relative.unwrap_or(self.relative);
        let tgt = |i: usize| match axes[i] {
            Some(v) if relative => self.pos[i] + v * scale,
            Some(v) => v * scale + offset[i],
            None => self.pos[i],
        };
        let (x, y) = (tgt(a0) - self.pos[a0], tgt(a1) - self.pos[a1]);
        let mut center = self.pos;
        if let Some(r) = k.get(b'R') {
            let r = r * scale;
            if x == 0.0 && y == 0.0 {
                return Err(33);
            }
            let h = 4.0 * r * r - x * x - y * y;
            if h < 0.0 {
                return Err(34);
            }
            let mut h = -h.sqrt() / (x * x + y * y).sqrt();
            if motion == Motion::Ccw {
                h = -h;
            }
            let mut r = r;
            if r < 0.0 {
                h = -h;
                r = -r;
            }
            center[a0] += 0.5 * (x - y * h);
            center[a1] += 0.5 * (y + x * h);
            return Ok(Some((center, r)));
        }
        let ijk = [k.get(b'I'), k.get(b'J'), k.get(b'K')];
        if ijk[a0].is_none() && ijk[a1].is_none() {
            return Err(35);
        }
        let (i, j) = (
            ijk[a0].unwrap_or(0.0) * scale,
            ijk[a1].unwrap_or(0.0) * scale,
        );
        let r = (i * i + j * j).sqrt();
        let target_r = ((x - i).powi(2) + (y - j).powi(2)).sqrt();
        let delta = (target_r - r).abs();
        if delta > 0.005 && (delta > 0.5 || delta > 0.001 * r) {
            return Err(33);
        }
        center[a0] += i;
        center[a1] += j;
        Ok(Some((center, r)))
    }

    /// Plan a straight move to `target` (machine mm) at `feed` (`None`: rapid).
    fn line_to(&mut self, target: DVec3, feed: Option<f64>) -> Effect {
        let (seconds, correction) = self.planner.line(target - self.pos, feed);
        self.move_to(target);
        Effect {
            seconds,
            correction,
            ..Effect::default()
        }
    }

    /// `G38.3` toward `target`: the move stops where the probe (the registration sensor)
    /// first sees a mark; answers GRBL's `[PRB:x,y,z:1]` with the machine position there, or
    /// goes the whole way and answers `:0` (no sensor: never a contact).
    fn probe_to(&mut self, target: DVec3, feed: Option<f64>) -> (Effect, String) {
        let from = self.pos;
        let t = self.probe.as_ref().and_then(|s| {
            s.first_contact(DVec2::new(from.x, from.y), DVec2::new(target.x, target.y))
        });
        let end = t.map_or(target, |t| from.lerp(target, t));
        let e = self.line_to(end, feed);
        let p = self.pos;
        let text = format!(
            "[PRB:{:.3},{:.3},{:.3}:{}]",
            p.x,
            p.y,
            p.z,
            u8::from(t.is_some())
        );
        (e, text)
    }

    /// An arc as `mc_arc` cuts it: chords within the arc tolerance `$12`.
    fn arc_to(&mut self, target: DVec3, center: DVec3, cw: bool, feed: Option<f64>) -> Effect {
        let (a0, a1) = self.plane_axes();
        let lin = 3 - a0 - a1;
        let r0 = DVec2::new(self.pos[a0] - center[a0], self.pos[a1] - center[a1]);
        let r1 = DVec2::new(target[a0] - center[a0], target[a1] - center[a1]);
        let radius = r0.length();
        let mut angle = r0.perp_dot(r1).atan2(r0.dot(r1));
        if cw {
            if angle >= -1e-7 {
                angle -= std::f64::consts::TAU;
            }
        } else if angle <= 1e-7 {
            angle += std::f64::consts::TAU;
        }
        let tol = self.settings.get(12).max(1e-4);
        let n = ((0.5 * angle * radius).abs() / (tol * (2.0 * radius - tol)).max(1e-12).sqrt())
            .floor()
            .clamp(1.0, 10_000.0) as usize;
        let start = self.pos;
        let mut e = Effect::default();
        for s in 1..=n {
            let t = s as f64 / n as f64;
            let p = if s == n {
                target
            } else {
                let v = DVec2::from_angle(angle * t).rotate(r0);
                let mut p = center;
                p[a0] += v.x;
                p[a1] += v.y;
                p[lin] = start[lin] + (target[lin] - start[lin]) * t;
                p
            };
            e.add(self.line_to(p, feed));
        }
        e
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

    /// A status report in the firmware's format (1.1: `|` fields; 0.9: `,` fields with WPos).
    pub fn status(&self, state: &str, at: DVec3) -> String {
        let w = at - self.offset();
        if self.v0_9 {
            let state = state.split(':').next().unwrap_or(state);
            return format!(
                "<{state},MPos:{:.3},{:.3},{:.3},WPos:{:.3},{:.3},{:.3}>",
                at.x, at.y, at.z, w.x, w.y, w.z
            );
        }
        format!(
            "<{state}|MPos:{:.3},{:.3},{:.3}|FS:{},{}>",
            at.x,
            at.y,
            at.z,
            self.feed,
            if self.spindle_on { self.s } else { 0.0 }
        )
    }

    /// The `[GC:…]` line of `$G`.
    pub(crate) fn gc_state(&self) -> String {
        let motion = match self.motion {
            Motion::Seek => "G0",
            Motion::Linear => "G1",
            Motion::Cw => "G2",
            Motion::Ccw => "G3",
            Motion::None => "G80",
            Motion::Probe => "G38.3",
        };
        let f = |v: f64| crate::output::fmt_mm(v);
        format!(
            "[GC:{motion} G{} G{} G{} G{} G{} M{} M{} T{} F{} S{}]",
            54 + self.coord,
            17 + self.plane,
            if self.inches { 20 } else { 21 },
            if self.relative { 91 } else { 90 },
            if self.inverse_time { 93 } else { 94 },
            [5, 3, 4][self.spindle as usize % 3],
            if self.coolant { 8 } else { 9 },
            f(self.tool),
            f(self.feed / if self.inches { 25.4 } else { 1.0 }),
            f(self.s)
        )
    }

    /// Where the machine is in the XY plane.
    pub fn xy(&self) -> DVec2 {
        self.pos.truncate()
    }
}

impl Effect {
    /// Add a later move's time to this one's.
    fn add(&mut self, o: Effect) {
        if self.seconds == 0.0 {
            self.correction += o.correction;
        } else {
            self.seconds += o.correction;
        }
        self.seconds += o.seconds;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Grbl {
        fn execute_idle(&mut self, l: &str) -> Result<Effect, u32> {
            self.execute(l, false)
        }
    }

    /// Execute `lines`, each of which must be accepted.
    fn run(g: &mut Grbl, lines: &[&str]) {
        for l in lines {
            g.execute(l, false).unwrap();
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
        // Z 2 → -1 at Z's rapid rate and acceleration (2000 mm/min, 300 mm/s²: 33.3 mm/s is
        // not reached in 3 mm, a triangle of 2·sqrt(3/300) s); then 10 mm at 900 mm/min.
        g.planner.stop();
        let e = g.execute("G0 Z-1", false).unwrap();
        assert!(
            (e.seconds - 2.0 * (3.0f64 / 300.0).sqrt()).abs() < 1e-9,
            "{e:?}"
        );
        g.planner.stop();
        let e = g.execute("G1 X15", false).unwrap();
        let v = 15.0;
        let t = 2.0 * v / 300.0 + (10.0 - v * v / 300.0) / v;
        assert!((e.seconds - t).abs() < 1e-9, "{e:?} vs {t}");

        let mut fresh = Grbl::new(&knife());
        assert_eq!(fresh.execute_idle("G1 X1"), Err(22));
        assert_eq!(fresh.execute_idle("G5 X1"), Err(20));
        assert_eq!(fresh.execute_idle("G0 X1 X2"), Err(25));
        // GRBL 1.1h: the firmware's codes (tests/suite/grbl_firmware.rs compares them).
        assert_eq!(fresh.execute_idle("G0 G1 X2"), Err(24));
        assert_eq!(fresh.execute_idle("G17 G18"), Err(21));
        assert_eq!(fresh.execute_idle("G0 X1.2.3"), Err(1));
        assert_eq!(fresh.execute_idle("%"), Err(1));
        assert_eq!(fresh.execute_idle("G4"), Err(28));
        assert_eq!(fresh.execute_idle("$Q"), Err(2));
        assert_eq!(fresh.execute_idle("$999=1"), Err(3));
        assert_eq!(fresh.execute_idle("$100=-1"), Err(4));
        assert_eq!(fresh.execute_idle("$110=abc"), Err(2));
        assert_eq!(fresh.execute("$$", true), Err(8));
        assert_eq!(fresh.execute_idle("N99999999 G0 X1"), Err(27));
        assert_eq!(fresh.execute_idle("G1 F0 X3"), Err(22));
        assert_eq!(fresh.execute_idle("T300"), Err(38));
        assert_eq!(fresh.execute_idle("G53 G2 X1 I1 F100"), Err(30));
        assert_eq!(
            fresh.execute_idle(&format!("G1X1.{}", "0".repeat(75))),
            Err(11)
        );
        assert!(fresh
            .execute_idle(&format!("G0X1.{}", "0".repeat(74)))
            .is_ok());
        let listing = fresh.execute_idle("$$").unwrap().text;
        assert_eq!(listing.len(), 34);
        assert!(listing.contains(&"$32=0".to_string()), "{listing:?}");
        assert_eq!(fresh.execute_idle("$H"), Err(5));
        assert_eq!(fresh.execute_idle(&"G0 X1 ".repeat(20)), Err(11));
        assert!(fresh.execute_idle("(a comment) ; another").is_ok());
        fresh.alarm = true;
        assert_eq!(fresh.execute_idle("G0 X1"), Err(9));
        assert!(fresh.execute_idle("$X").is_ok());
        assert!(fresh.execute_idle("G0 X1").is_ok());
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
