//! How long a GRBL machine takes for its moves: trapezoidal speed profiles under per-axis
//! maximum rates and accelerations, with corners taken at GRBL's junction speed. Used by the
//! simulated GRBL (as its planner's clock) and by the streamer's ETA, so both agree.
//!
//! Follows GRBL 1.1 `planner.c`: a block's nominal speed is its feed (or the rapid rate for
//! `G0`) capped by each axis's `$110`–`$112` in proportion to its share of the move, its
//! acceleration the smallest `$120`–`$122` so scaled; the junction speed between two blocks
//! is `sqrt(a · δ · sin(θ/2) / (1 − sin(θ/2)))` with δ the junction deviation `$11` and θ the
//! angle between them (straight on: no limit; a reversal: zero).
//!
//! Choices where GRBL's planner is more elaborate: the plan looks one block ahead, not sixteen
//! (a block ends at the junction speed of the next when the next is known, at rest when it is
//! not), which is exact for chains of long moves and optimistic only where a run of very short
//! moves could not reach the junction speed GRBL would plan over more blocks.

use crate::profile::GrblMachine;
use glam::DVec3;

/// One planned move.
#[derive(Debug, Clone, Copy)]
struct Block {
    length: f64,
    unit: DVec3,
    /// Nominal speed and acceleration, mm/s and mm/s².
    speed: f64,
    accel: f64,
    entry: f64,
}

/// A one-block-lookahead copy of GRBL's planner.
#[derive(Debug, Clone)]
pub(crate) struct Planner {
    m: GrblMachine,
    last: Option<Block>,
}

impl Planner {
    pub(crate) fn new(m: &GrblMachine) -> Planner {
        Planner {
            m: m.clone(),
            last: None,
        }
    }

    /// The machine set new rates or accelerations (`$110`–`$122`, `$11`).
    pub(crate) fn set(&mut self, m: &GrblMachine) {
        self.m = m.clone();
    }

    /// The machine came to rest (the planner ran empty, a dwell, a sync command).
    pub(crate) fn stop(&mut self) {
        self.last = None;
    }

    /// Plan a move of `delta` mm at `feed` mm/min (`None`: rapid). Returns the seconds of this
    /// move (ending at rest) and the change to the previous move's seconds, now that it ends at
    /// the junction speed instead of at rest (≤ 0; 0 when the machine was at rest).
    pub(crate) fn line(&mut self, delta: DVec3, feed: Option<f64>) -> (f64, f64) {
        let length = delta.length();
        if length <= 0.0 {
            return (0.0, 0.0);
        }
        let unit = delta / length;
        let (mut speed, mut accel) = (f64::INFINITY, f64::INFINITY);
        for i in 0..3 {
            let u = unit[i].abs();
            if u > 1e-12 {
                speed = speed.min(self.m.max_rate[i] / 60.0 / u);
                accel = accel.min(self.m.acceleration[i] / u);
            }
        }
        if let Some(f) = feed {
            speed = speed.min(f / 60.0);
        }
        if !(speed.is_finite() && speed > 0.0 && accel.is_finite() && accel > 0.0) {
            return (0.0, 0.0);
        }
        let mut correction = 0.0;
        let mut entry = 0.0;
        if let Some(prev) = self.last {
            let cos = -prev.unit.dot(unit);
            let junction = if cos > 0.999_999 {
                0.0
            } else if cos < -0.999_999 {
                f64::INFINITY
            } else {
                let sin_half = ((1.0 - cos) / 2.0).max(0.0).sqrt();
                (accel * self.m.junction_deviation * sin_half / (1.0 - sin_half)).sqrt()
            };
            let reachable = (prev.entry * prev.entry + 2.0 * prev.accel * prev.length).sqrt();
            entry = junction.min(speed).min(prev.speed).min(reachable);
            correction = profile_time(prev.length, prev.entry, prev.speed, entry, prev.accel)
                - profile_time(prev.length, prev.entry, prev.speed, 0.0, prev.accel);
        }
        // This move may not enter faster than it can stop within its length.
        entry = entry.min((2.0 * accel * length).sqrt());
        let block = Block {
            length,
            unit,
            speed,
            accel,
            entry,
        };
        self.last = Some(block);
        (
            profile_time(length, entry, speed, 0.0, accel),
            correction.min(0.0),
        )
    }
}

/// Seconds to cover `d` starting at `v0`, at most `vm`, ending at `v1`, under acceleration `a`.
fn profile_time(d: f64, v0: f64, vm: f64, v1: f64, a: f64) -> f64 {
    let vm = vm.max(v0).max(v1);
    let da = (vm * vm - v0 * v0) / (2.0 * a);
    let dd = (vm * vm - v1 * v1) / (2.0 * a);
    if da + dd <= d {
        return (vm - v0) / a + (vm - v1) / a + (d - da - dd) / vm;
    }
    let peak = ((2.0 * a * d + v0 * v0 + v1 * v1) / 2.0).sqrt();
    if peak < v0.max(v1) {
        // Cannot change speed that much within d: at the mean speed.
        return 2.0 * d / (v0 + v1).max(1e-9);
    }
    (peak - v0) / a + (peak - v1) / a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoids_and_corners() {
        let m = GrblMachine {
            max_rate: [6000.0, 6000.0, 600.0],
            acceleration: [100.0, 100.0, 100.0],
            ..GrblMachine::default()
        };
        let mut p = Planner::new(&m);
        // 100 mm at 50 mm/s, a = 100: 0.5 s up, 0.5 s down (12.5 mm each), 75 mm in 1.5 s.
        let (t, c) = p.line(DVec3::new(100.0, 0.0, 0.0), Some(3000.0));
        assert!((t - 2.5).abs() < 1e-9 && c == 0.0, "{t}");
        // Straight on: the previous move no longer stops: its last 12.5 mm take 0.25 s, not
        // 0.5 s.
        let (_, c) = p.line(DVec3::new(100.0, 0.0, 0.0), Some(3000.0));
        assert!((c + 0.25).abs() < 1e-9, "{c}");
        // A reversal stops.
        let (_, c) = p.line(DVec3::new(-10.0, 0.0, 0.0), Some(3000.0));
        assert_eq!(c, 0.0);
        // Z alone at its own rate: 10 mm at 10 mm/s with a = 100: 0.1 up, 0.1 down, 0.9 s.
        p.stop();
        let (t, _) = p.line(DVec3::new(0.0, 0.0, 10.0), None);
        assert!((t - 1.1).abs() < 1e-9, "{t}");
        // A short move never reaches its speed: 1 mm, a = 100: 2·sqrt(1/100) = 0.2 s.
        p.stop();
        let (t, _) = p.line(DVec3::new(1.0, 0.0, 0.0), Some(6000.0));
        assert!((t - 0.2).abs() < 1e-9, "{t}");
    }
}
