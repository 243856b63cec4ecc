//! What the simulated cutter remembers of a job: every tool-down path, in device units, named
//! by the tool that made it, and the pen-up travel.
//!
//! A path starts where the tool went down and gets a point for every move made while it stays
//! down with the same tool; lifting the tool, or changing it, ends the path. A tool that goes
//! down and up without moving leaves a one-point path (a dot, or a knife prick).

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

/// Collects paths as the machine moves.
#[derive(Debug, Clone, Default)]
pub struct Recorder {
    pub paths: Vec<SimPath>,
    /// Whether the last path is still being drawn.
    open: bool,
    /// Pen-up travel, device units.
    pub travel: f64,
}

impl Recorder {
    /// The tool `tool` is down at `at` (start a path unless one with this tool is open).
    pub fn down(&mut self, tool: &str, at: DVec2) {
        if self.open && self.paths.last().is_some_and(|p| p.tool == tool) {
            return;
        }
        self.paths.push(SimPath {
            tool: tool.to_string(),
            points: vec![at.to_array()],
        });
        self.open = true;
    }

    /// The tool of the path being drawn, if one is open.
    pub fn open_tool(&self) -> Option<&str> {
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
    pub fn travel_to(&mut self, from: DVec2, to: DVec2, tool: Option<&str>) {
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
}
