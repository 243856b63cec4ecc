//! The simulated GRBL's `$` commands and settings, as GRBL 1.1h's `system_execute_line` and
//! `settings.c` answer them: `$$` lists the 34 settings of 1.1h (its defaults, with `$11`,
//! `$30`, `$32` and `$110`–`$122` from the profile: a laser profile's machine is in laser
//! mode), `$n=v` stores a known setting (`error:3` for an unknown number or a missing `=`,
//! `error:2` for a bad value, `error:4` for a negative one), `$#` the coordinate data, `$G` the
//! parser state, `$N` the startup lines, `$I` the build, `$X` unlocks, `$C` toggles check mode,
//! `$H` is `error:5` (homing off), any other `$` letter `error:2`. While the machine moves,
//! `$$ $# $C $X $H $N $n=v` are `error:8`, as GRBL's idle checks say.

use super::{Effect, Grbl};
use crate::profile::{GrblMachine, Profile};

/// GRBL 1.1h's settings in `$$` order with their defaults, and whether `$$` prints them as
/// integers.
const DEFAULTS: [(u32, f64, bool); 34] = [
    (0, 10.0, true),
    (1, 25.0, true),
    (2, 0.0, true),
    (3, 0.0, true),
    (4, 0.0, true),
    (5, 0.0, true),
    (6, 0.0, true),
    (10, 1.0, true),
    (11, 0.010, false),
    (12, 0.002, false),
    (13, 0.0, true),
    (20, 0.0, true),
    (21, 0.0, true),
    (22, 0.0, true),
    (23, 0.0, true),
    (24, 25.0, false),
    (25, 500.0, false),
    (26, 250.0, true),
    (27, 1.0, false),
    (30, 1000.0, true),
    (31, 0.0, true),
    (32, 0.0, true),
    (100, 250.0, false),
    (101, 250.0, false),
    (102, 250.0, false),
    (110, 500.0, false),
    (111, 500.0, false),
    (112, 500.0, false),
    (120, 10.0, false),
    (121, 10.0, false),
    (122, 10.0, false),
    (130, 200.0, false),
    (131, 200.0, false),
    (132, 200.0, false),
];

/// The controller's settings.
#[derive(Debug, Clone)]
pub(crate) struct Settings {
    values: [f64; 34],
}

impl Settings {
    pub(crate) fn for_profile(p: &Profile, laser: bool) -> Settings {
        let mut s = Settings {
            values: DEFAULTS.map(|d| d.1),
        };
        let g = &p.grbl;
        for i in 0..3 {
            s.set(110 + i as u32, g.max_rate[i]);
            s.set(120 + i as u32, g.acceleration[i]);
        }
        s.set(11, g.junction_deviation);
        s.set(32, if laser { 1.0 } else { 0.0 });
        if let Some(m) = p.max_power {
            s.set(30, m);
        }
        s
    }

    fn index(n: u32) -> Option<usize> {
        DEFAULTS.iter().position(|d| d.0 == n)
    }

    pub(crate) fn get(&self, n: u32) -> f64 {
        Self::index(n).map_or(0.0, |i| self.values[i])
    }

    fn set(&mut self, n: u32, v: f64) -> bool {
        match Self::index(n) {
            Some(i) => {
                self.values[i] = v;
                true
            }
            None => false,
        }
    }

    pub(crate) fn laser_mode(&self) -> bool {
        self.get(32) != 0.0
    }

    /// The motion settings as the planner reads them.
    pub(crate) fn machine(&self) -> GrblMachine {
        GrblMachine {
            version: "1.1".into(),
            max_rate: [self.get(110), self.get(111), self.get(112)],
            acceleration: [self.get(120), self.get(121), self.get(122)],
            junction_deviation: self.get(11),
        }
    }

    fn listing(&self) -> Vec<String> {
        DEFAULTS
            .iter()
            .zip(self.values)
            .map(|(&(n, _, int), v)| {
                if int {
                    format!("${n}={}", v.round() as i64)
                } else {
                    format!("${n}={v:.3}")
                }
            })
            .collect()
    }
}

fn xyz(v: glam::DVec3) -> String {
    format!("{:.3},{:.3},{:.3}", v.x, v.y, v.z)
}

impl Grbl {
    /// A `$` line (upper-cased, blanks removed), `busy` while the machine moves.
    pub(crate) fn system(&mut self, cmd: &str, busy: bool) -> Result<Effect, u32> {
        let idle_only = |r: Result<Effect, u32>| if busy { Err(8) } else { r };
        let text = |l: Vec<String>| {
            Ok(Effect {
                text: l,
                ..Effect::default()
            })
        };
        match cmd {
            "" => text(vec![
                "[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]".into(),
            ]),
            "$" => idle_only(text(self.settings.listing())),
            "#" => {
                let mut l: Vec<String> = (0..6)
                    .map(|i| format!("[G{}:{}]", 54 + i, xyz(self.coords[i])))
                    .collect();
                l.push(format!("[G28:{}]", xyz(self.g28)));
                l.push(format!("[G30:{}]", xyz(self.g30)));
                l.push(format!("[G92:{}]", xyz(self.g92)));
                l.push(format!("[TLO:{:.3}]", self.tlo));
                l.push("[PRB:0.000,0.000,0.000:0]".into());
                idle_only(text(l))
            }
            "G" => text(vec![self.gc_state()]),
            "I" => text(vec!["[VER:1.1h.20190830:]".into(), "[OPT:V,15,128]".into()]),
            "N" => idle_only(text(vec!["$N0=".into(), "$N1=".into()])),
            "X" => idle_only({
                let was = std::mem::replace(&mut self.alarm, false);
                text(if was {
                    vec!["[MSG:Caution: Unlocked]".into()]
                } else {
                    Vec::new()
                })
            }),
            "C" => idle_only({
                self.check_mode = !self.check_mode;
                Ok(Effect {
                    text: vec![if self.check_mode {
                        "[MSG:Enabled]".into()
                    } else {
                        "[MSG:Disabled]".into()
                    }],
                    reset: !self.check_mode,
                    ..Effect::default()
                })
            }),
            "H" => idle_only(Err(5)),
            c if c.starts_with("J=") => self.jog(&c[2..]),
            c if c.starts_with(|ch: char| ch.is_ascii_digit()) => idle_only(self.setting(c)),
            c if c.starts_with('N') && c[1..].starts_with(|ch: char| ch.is_ascii_digit()) => {
                idle_only(text(Vec::new()))
            }
            _ => Err(2),
        }
    }

    /// `$J=line` (GRBL 1.1 jogging): a feed move by the line's `G90`/`G91`, `G20`/`G21` and
    /// axis words, which needs `F` (error 22 without it) and leaves the parser's modal state
    /// as it was.
    fn jog(&mut self, line: &str) -> Result<Effect, u32> {
        let k =
            crate::device::sim::grbl_block::parse(&crate::device::sim::grbl_block::strip(line))?;
        let Some(f) = k.get(b'F').filter(|f| *f > 0.0) else {
            return Err(22);
        };
        let scale = if k.units.unwrap_or(self.inches) {
            25.4
        } else {
            1.0
        };
        let relative = k.relative.unwrap_or(self.relative);
        let (axes, offset) = (k.axes(), self.offset());
        let mut target = self.pos;
        for (i, v) in axes.iter().enumerate() {
            if let Some(v) = v {
                target[i] = if relative {
                    self.pos[i] + v * scale
                } else {
                    v * scale + offset[i]
                };
            }
        }
        Ok(self.line_to(target, Some(f * scale)))
    }

    /// `$n=v`.
    fn setting(&mut self, c: &str) -> Result<Effect, u32> {
        let Some((k, v)) = c.split_once('=') else {
            return Err(3);
        };
        let n: u32 = k.parse().map_err(|_| 2u32)?;
        let v: f64 = v.parse().map_err(|_| 2u32)?;
        if v < 0.0 {
            return Err(4);
        }
        if !self.settings.set(n, v) {
            return Err(3);
        }
        self.planner.set(&self.settings.machine());
        Ok(Effect::default())
    }
}
