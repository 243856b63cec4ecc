//! The simulated cutter's printed sheet and its optical registration-mark sensor.
//!
//! The sheet: a print-and-cut sheet's marks ([`Marks`], sheet mm) laid on the bed with a known
//! error, [`SheetPlacement`]: a printed point `p` lies at the machine position (mm, the
//! machine's axes) `offset + R(angle) · diag(scale) · m(p)`, where `m(p)` is where `p` would
//! be if the sheet lay exactly at the origin (`output::to_device` in mm). So `7,-4,1.5` is the
//! sheet moved 7 mm along X and −4 mm along Y and turned 1.5° counter-clockwise about the
//! machine's origin; a scale of 1.03 is a print 3 % too large.
//!
//! The sensor (profile `[registration] sensor = "hpgl-digitize"`): on `DP` it looks within the
//! profile's `search` radius of the head for a mark and digitizes its reference point (a
//! square's centre, an L's outer corner) as the machine's integer units, as a sensor that
//! finds a mark's edges and intersects them would; no mark in reach leaves no point. A
//! scaled print moves the marks but the sensor still reports each mark's reference point as
//! printed (its size is not measured). With `sensor = "grbl-probe"` the same sensor is on
//! GRBL's probe pin: a `G38.3` move stops where it first sees ink (a mark's filled
//! rectangles, placed). Choices: no sensor noise beyond the rounding to
//! units; the nearest mark wins when several are in reach.

use crate::profile::Profile;
use crate::toolpath::registration::Marks;
use glam::DVec2;

/// Where the printed sheet lies on the bed (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetPlacement {
    /// mm, the machine's axes.
    pub offset: DVec2,
    /// Counter-clockwise, degrees.
    pub angle_deg: f64,
    /// Scale along the machine's X and Y (1: printed true to size).
    pub scale: DVec2,
}

impl Default for SheetPlacement {
    fn default() -> Self {
        SheetPlacement {
            offset: DVec2::ZERO,
            angle_deg: 0.0,
            scale: DVec2::ONE,
        }
    }
}

impl SheetPlacement {
    /// Where the machine position `m` of a sheet at the origin really is, mm.
    pub fn apply(&self, m: DVec2) -> DVec2 {
        DVec2::from_angle(self.angle_deg.to_radians()).rotate(m * self.scale) + self.offset
    }
}

/// A printed sheet on the simulated bed.
#[derive(Debug, Clone, PartialEq)]
pub struct PrintedSheet {
    pub marks: Marks,
    pub placement: SheetPlacement,
}

/// The sensor of one simulated machine.
#[derive(Debug, Clone)]
pub(crate) struct Sensor {
    /// Each mark's reference point on the bed, device units.
    found_at: Vec<DVec2>,
    /// Search radius, device units.
    reach: f64,
    /// The ink of the marks on the bed: each filled rectangle as its four corners, device
    /// units.
    ink: Vec<[DVec2; 4]>,
}

impl Sensor {
    pub(crate) fn new(sheet: &PrintedSheet, profile: &Profile) -> Sensor {
        let upm = profile.units_per_mm;
        let (w, h) = (sheet.marks.width, sheet.marks.height);
        let found_at = sheet
            .marks
            .references()
            .into_iter()
            .map(|p| {
                let m = crate::output::to_device(profile, w, h, p) / upm;
                sheet.placement.apply(m) * upm
            })
            .collect();
        let on_bed = |p: DVec2| {
            let m = crate::output::to_device(profile, w, h, p) / upm;
            sheet.placement.apply(m) * upm
        };
        let ink = sheet
            .marks
            .marks
            .iter()
            .flat_map(|m| &m.rects)
            .map(|(lo, hi)| {
                [
                    on_bed(*lo),
                    on_bed(DVec2::new(hi.x, lo.y)),
                    on_bed(*hi),
                    on_bed(DVec2::new(lo.x, hi.y)),
                ]
            })
            .collect();
        Sensor {
            found_at,
            reach: profile.registration.search * upm,
            ink,
        }
    }

    /// The mark the sensor finds from the head at `at` (device units): its reference point,
    /// rounded to units.
    pub(crate) fn find(&self, at: DVec2) -> Option<DVec2> {
        self.found_at
            .iter()
            .filter(|p| p.distance(at) <= self.reach)
            .min_by(|a, b| a.distance(at).total_cmp(&b.distance(at)))
            .map(|p| p.round())
    }
}

impl Sensor {
    /// A probe moving from `from` to `to` (device units): the fraction of the way at which it
    /// first sees ink (0 when it starts on a mark), if it does.
    pub(crate) fn first_contact(&self, from: DVec2, to: DVec2) -> Option<f64> {
        let d = to - from;
        let mut best: Option<f64> = None;
        for quad in &self.ink {
            if inside(quad, from) {
                return Some(0.0);
            }
            for k in 0..4 {
                let (a, b) = (quad[k], quad[(k + 1) % 4]);
                let e = b - a;
                let den = d.perp_dot(e);
                if den.abs() < 1e-15 {
                    continue;
                }
                let t = (a - from).perp_dot(e) / den;
                let u = (a - from).perp_dot(d) / den;
                if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
                    best = Some(best.map_or(t, |b: f64| b.min(t)));
                }
            }
        }
        best
    }
}

/// Whether `p` lies in the convex quadrilateral `q` (either orientation).
fn inside(q: &[DVec2; 4], p: DVec2) -> bool {
    let s: Vec<f64> = (0..4)
        .map(|k| (q[(k + 1) % 4] - q[k]).perp_dot(p - q[k]))
        .collect();
    s.iter().all(|v| *v >= 0.0) || s.iter().all(|v| *v <= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_placed_mark_within_reach_only() {
        let profile = crate::profile::find("sim").unwrap();
        let marks =
            crate::toolpath::registration::layout(210.0, 297.0, &profile.registration).unwrap();
        let placement = SheetPlacement {
            offset: DVec2::new(7.0, -4.0),
            angle_deg: 1.5,
            scale: DVec2::ONE,
        };
        let s = Sensor::new(&PrintedSheet { marks, placement }, &profile);
        // Lower-left L at (10, 10) mm.
        let truth = placement.apply(DVec2::new(10.0, 10.0)) * 40.0;
        assert_eq!(s.find(DVec2::new(400.0, 400.0)), Some(truth.round()));
        assert_eq!(s.find(DVec2::new(4000.0, 4000.0)), None);
        // A probe along x at y = 14 mm meets the lower-left L's upright arm on its outer edge.
        let (from, to) = (DVec2::new(0.0, 14.0 * 40.0), DVec2::new(800.0, 14.0 * 40.0));
        let t = s.first_contact(from, to).unwrap();
        let hit = from.lerp(to, t) / 40.0;
        // The edge: x = 10 on the sheet, placed.
        let a = placement.apply(DVec2::new(10.0, 10.0));
        let b = placement.apply(DVec2::new(10.0, 30.0));
        assert!(
            (b - a).perp_dot(hit - a).abs() / (b - a).length() < 1e-9,
            "{hit}"
        );
        assert_eq!(s.first_contact(DVec2::ZERO, DVec2::new(100.0, 0.0)), None);
    }
}
