//! What a GRBL profile says about the controller itself, beyond its tools: the firmware
//! generation and the motion settings that decide how long a job takes (`[grbl]` in a
//! profile). The simulated GRBL uses them as its `$110`–`$122` and `$32`, the progress bar's ETA
//! uses them as the machine would.
//!
//! Source: gnea/grbl `doc/markdown/settings.md` (`$110`–`$112` max rate, mm/min; `$120`–`$122`
//! acceleration, mm/s²; `$11` junction deviation, mm). GRBL's own defaults (500 mm/min,
//! 10 mm/s²) are far below what a configured machine uses; the defaults here are the typical
//! values of a small desktop machine (not documented: set yours from `$$`).

use serde::Deserialize;

/// Most significant characters on one line ([`significant_len`]): GRBL's line buffer
/// (`LINE_BUFFER_SIZE` 80, `protocol.c`) keeps 79 and answers the 80th with `error:11`.
pub const LINE_MAX: usize = 79;

/// The characters of `line` that GRBL's line reader keeps (1.1h and 0.9j `protocol.c`):
/// not whitespace or control characters, not `/`, nothing inside `( … )` or after `;`.
pub fn significant_len(line: &str) -> usize {
    let mut n = 0;
    let (mut paren, mut semi) = (false, false);
    for c in line.bytes() {
        if c == b'\n' || c == b'\r' {
            break;
        }
        if paren || semi {
            if c == b')' {
                paren = false;
            }
            continue;
        }
        match c {
            0..=b' ' | b'/' => {}
            b'(' => paren = true,
            b';' => semi = true,
            _ => n += 1,
        }
    }
    n
}

/// `[grbl]`: the controller's settings as the machine has them.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GrblMachine {
    /// `1.1` or `0.9`: what the simulator answers like (text errors, `<Idle,MPos:…>`). A real
    /// controller's welcome decides for the streamer.
    pub version: String,
    /// `$110`, `$111`, `$112`: the fastest each axis moves (and the rate of `G0`), mm/min.
    pub max_rate: [f64; 3],
    /// `$120`, `$121`, `$122`: acceleration of each axis, mm/s².
    pub acceleration: [f64; 3],
    /// `$11`: junction deviation, mm (how fast a corner is taken).
    pub junction_deviation: f64,
}

impl Default for GrblMachine {
    fn default() -> Self {
        GrblMachine {
            version: "1.1".into(),
            max_rate: [5000.0, 5000.0, 2000.0],
            acceleration: [300.0, 300.0, 300.0],
            junction_deviation: 0.01,
        }
    }
}

/// The checks of a profile's `[grbl]`: (key, message) of the first problem.
pub(super) fn check(g: &GrblMachine) -> Result<(), (&'static str, String)> {
    if g.version != "1.1" && g.version != "0.9" {
        return Err((
            "version",
            format!("must be \"1.1\" or \"0.9\", got {:?}", g.version),
        ));
    }
    let ok = |v: &f64| v.is_finite() && *v > 0.0 && *v < 1e7;
    if !g.max_rate.iter().all(ok) {
        return Err((
            "max_rate",
            format!("must be 3 positive mm/min, got {:?}", g.max_rate),
        ));
    }
    if !g.acceleration.iter().all(ok) {
        return Err((
            "acceleration",
            format!("must be 3 positive mm/s², got {:?}", g.acceleration),
        ));
    }
    if !(g.junction_deviation.is_finite() && (0.0..=10.0).contains(&g.junction_deviation)) {
        return Err((
            "junction_deviation",
            format!("must be 0 to 10 mm, got {}", g.junction_deviation),
        ));
    }
    Ok(())
}
