//! What the simulated cutter remembers of a job: every tool-down path, in device units, named
//! by the tool that made it, and the pen-up travel.
//!
//! A path starts where the tool went down and gets a point for every move made while it stays
//! down with the same tool; lifting the tool, or changing it, ends the path. A tool that goes
//! down and up without moving leaves a one-point path (a dot, or a knife prick).
//!
//! **Drag knife.** When the profile has a `knife_offset`, the paths of its drag-knife tools
//! (`Profile::is_drag_knife`) are where the blade tip went, not the holder: the tip trails the
//! holder at the offset and moves only along the line from tip to holder (pure pursuit; the
//! tip's track is a tractrix). Each holder move is followed in steps of at most 1/50 of the
//! offset, the tip put back on the line from the new holder position to the old tip at the
//! offset (error of second order in the step); the recorded tip path gets a point wherever
//! its heading has turned more than [`HEADING_TOL_DEG`] since the last point kept, so straight
//! runs stay two points. While the blade is up, or another tool is down, the tip moves with
//! the holder and keeps its direction. The blade starts pointing along +x (the machine's).

use glam::DVec2;
use serde::Serialize;

/// One tool-down path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimPath {
    /// The stroke kind whose tool made it (`cut`, `score`, `draw`, …), or a raw name such as
    /// `pen 7` when the profile has no tool of that description.
    pub tool: String,
    /// Device units (plotter units for HP-GL, mm for G-code), in the machine's axes.
    pub points: Vec<[f64; 2]>,
}

impl SimPath {
    /// Length in device units.
    pub fn length(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| DVec2::from(w[0]).distance(DVec2::from(w[1])))
            .sum()
    }
}

/// Heading change of the blade tip (degrees) after which the recorder keeps a point.
pub(crate) const HEADING_TOL_DEG: f64 = 0.5;
/// Drag-knife simulation steps in one move at most (1e6 steps of r / 50: 5 m at r = 0.25 mm).
const MAX_DRAG_STEPS: f64 = 1e6;

/// A trailing blade (see the module documentation).
#[derive(Debug, Clone, Default)]
struct Drag {
    /// Offset in device units.
    r: f64,
    /// Tools (stroke kind names) that are drag knives.
    knives: Vec<String>,
    /// Tip, once the holder's position is known.
    tip: Option<DVec2>,
    /// Heading of the tip when the last point was kept.
    heading: Option<DVec2>,
}

/// Collects paths as the machine moves.
#[derive(Debug, Clone, Default)]
pub struct Recorder {
    pub paths: Vec<SimPath>,
    /// Whether the last path is still being drawn.
    open: bool,
    /// Pen-up travel, device units.
    pub travel: f64,
    drag: Option<Drag>,
}

impl Recorder {
    /// A recorder for a machine: with a trailing blade when the profile has a knife offset.
    pub(crate) fn for_profile(profile: &crate::profile::Profile) -> Recorder {
        use crate::profile::StrokeKind;
        let knives: Vec<String> = [StrokeKind::Cut, StrokeKind::Score, StrokeKind::Perforate]
            .into_iter()
            .filter(|k| profile.is_drag_knife(*k))
            .map(|k| k.name().to_string())
            .collect();
        let r = profile.knife_offset * profile.units_per_mm;
        Recorder {
            drag: (!knives.is_empty() && r.is_finite() && r > 0.0).then_some(Drag {
                r,
                knives,
                tip: None,
                heading: None,
            }),
            ..Recorder::default()
        }
    }

    /// Where the blade tip is for a holder at `holder` (its first sight: trailing along -x).
    fn tip_at(&mut self, holder: DVec2) -> Option<DVec2> {
        let d = self.drag.as_mut()?;
        Some(*d.tip.get_or_insert(holder - DVec2::X * d.r))
    }

    fn is_knife(&self, tool: &str) -> bool {
        self.drag
            .as_ref()
            .is_some_and(|d| d.knives.iter().any(|k| k == tool))
    }

    /// The tool `tool` is down at `at` (start a path unless one with this tool is open).
    pub fn down(&mut self, tool: &str, at: DVec2) {
        if self.open && self.paths.last().is_some_and(|p| p.tool == tool) {
            return;
        }
        let at = if self.is_knife(tool) {
            if let Some(d) = self.drag.as_mut() {
                d.heading = None;
            }
            self.tip_at(at).unwrap_or(at)
        } else {
            at
        };
        self.paths.push(SimPath {
            tool: tool.to_string(),
            points: vec![at.to_array()],
        });
        self.open = true;
    }

    /// The tool of the path being drawn, if one is open.
    pub(crate) fn open_tool(&self) -> Option<&str> {
        if self.open {
            self.paths.last().map(|p| p.tool.as_str())
        } else {
            None
        }
    }

    /// The tool is lifted.
    pub fn up(&mut self) {
        self.open = false;
    }

    /// A straight move; `tool` is the tool that is down, if any.
    pub(crate) fn travel_to(&mut self, from: DVec2, to: DVec2, tool: Option<&str>) {
        if self.drag.is_some() {
            let knife = tool.filter(|t| self.is_knife(t));
            match knife {
                Some(t) => {
                    let t = t.to_string();
                    self.drag_to(from, to, &t);
                    return;
                }
                None => {
                    // The blade is carried along, turning nowhere.
                    if let Some(tip) = self.tip_at(from) {
                        if let Some(d) = self.drag.as_mut() {
                            d.tip = Some(tip + (to - from));
                        }
                    }
                }
            }
        }
        match tool {
            Some(t) => {
                self.down(t, from);
                if let Some(p) = self.paths.last_mut() {
                    if p.points.last() != Some(&to.to_array()) {
                        p.points.push(to.to_array());
                    }
                }
            }
            None => {
                self.open = false;
                self.travel += from.distance(to);
            }
        }
    }

    /// A knife move of the holder from `from` to `to`: the tip follows (pure pursuit).
    fn drag_to(&mut self, from: DVec2, to: DVec2, tool: &str) {
        let Some(mut tip) = self.tip_at(from) else {
            return;
        };
        self.down(tool, from);
        let Some(d) = self.drag.as_ref() else { return };
        let r = d.r;
        let len = from.distance(to);
        // Steps of r / 50, at most `MAX_DRAG_STEPS` per move (a move longer than that many
        // steps is straight long before its end, where the step size no longer matters).
        let steps = ((len / (r / 50.0)).ceil().min(MAX_DRAG_STEPS) as usize).max(1);
        let cos_tol = HEADING_TOL_DEG.to_radians().cos();
        for k in 1..=steps {
            let h = from + (to - from) * (k as f64 / steps as f64);
            let back = tip - h;
            let l = back.length();
            let new_tip = if l > 1e-12 { h + back * (r / l) } else { tip };
            let step = new_tip - tip;
            let Some(p) = self.paths.last_mut() else {
                return;
            };
            if step.length() > 1e-9 {
                let dir = step.normalize();
                let d = self.drag.as_mut().map(|d| &mut d.heading);
                if let Some(heading) = d {
                    match heading {
                        Some(hd) if hd.dot(dir) >= cos_tol => {
                            // Same heading: move the last point along.
                            if p.points.len() >= 2 {
                                p.points.pop();
                            }
                        }
                        _ => *heading = Some(dir),
                    }
                }
                p.points.push(new_tip.to_array());
            }
            tip = new_tip;
        }
        if let Some(d) = self.drag.as_mut() {
            d.tip = Some(tip);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drag() -> Recorder {
        let p = crate::profile::find("sim-dragknife").unwrap();
        Recorder::for_profile(&p)
    }

    /// The tip trails the holder by the offset (10 plotter units) and cuts inside a corner the
    /// holder turns sharply; a straight run stays two points.
    #[test]
    fn the_blade_tip_trails_the_holder() {
        let mut r = drag();
        let (a, b, c) = (
            DVec2::new(0.0, 0.0),
            DVec2::new(400.0, 0.0),
            DVec2::new(400.0, 400.0),
        );
        r.down("cut", a);
        r.travel_to(a, b, Some("cut"));
        let p = &r.paths[0].points;
        assert_eq!(p.len(), 2, "{p:?}");
        assert_eq!(p[0], [-10.0, 0.0]);
        assert!((p[1][0] - 390.0).abs() < 1e-9 && p[1][1].abs() < 1e-9);
        r.travel_to(b, c, Some("cut"));
        let p = &r.paths[0].points;
        let end = DVec2::from(*p.last().unwrap());
        // Back on the holder's line, 10 units behind it.
        assert!(end.distance(DVec2::new(400.0, 390.0)) < 0.01, "{end}");
        // The corner is cut round, inside: no tip point comes nearer the corner than 2 units.
        let nearest = p
            .iter()
            .map(|q| DVec2::from(*q).distance(b))
            .fold(f64::INFINITY, f64::min);
        assert!(nearest > 2.0, "{nearest}");
        // Lifted, the blade moves with the holder and keeps its direction.
        r.up();
        r.travel_to(c, DVec2::new(0.0, 800.0), None);
        r.down("cut", DVec2::new(0.0, 800.0));
        let start = DVec2::from(r.paths[1].points[0]);
        assert!(start.distance(DVec2::new(0.0, 790.0)) < 0.01, "{start}");
        // A recorder for a machine without an offset records the holder.
        let mut plain = Recorder::for_profile(&crate::profile::find("sim").unwrap());
        plain.down("cut", a);
        plain.travel_to(a, b, Some("cut"));
        assert_eq!(plain.paths[0].points, vec![[0.0, 0.0], [400.0, 0.0]]);
    }
}
