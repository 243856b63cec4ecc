//! The `[registration]` table of a device profile (print-and-cut): whether the machine has a
//! sensor that finds printed registration marks, where the marks go on a sheet and how big
//! they are, and how closely the measured marks must agree with a placement of the sheet.
//!
//! Defaults (flatcut's choices where no document decides): an L mark 20 mm long in three
//! corners and a 5 mm filled square in the fourth (the upper left), 10 mm in from the sheet's
//! edges — the layout and the 20 mm length and 10 mm inset of Silhouette Studio's default
//! registration marks as we remember its Registration panel, not checked against a document;
//! the arms 1 mm wide (Silhouette's are thinner; a wider mark is easier for a sensor to find
//! and for a person to jog onto). The nest keeps 2 mm clear of the marks. A fit is refused
//! above 0.3 mm of residual (about a knife's kerf and a half on paper) or beyond ±1 % of scale
//! (issue 25: "scale within ±1 %").

use serde::Deserialize;

/// How the marks of a printed sheet are found on the machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Sensor {
    /// None: the user jogs to each mark and gives its position (`--marks`).
    #[default]
    None,
    /// An optical sensor driven through HP-GL digitizing (HP 7475A Interfacing and
    /// Programming Manual, ch. 14: `DP` digitize point, `OS` status bit 2 "digitized point
    /// available", `OD` output digitized point): the host moves pen up over where a mark
    /// should be and sends `DP`; the sensor digitizes the mark it finds there. The simulated
    /// cutter's sensor works this way (`device::sim::sensor`).
    HpglDigitize,
    /// An optical mark sensor wired to GRBL's probe pin, beside the tool (no offset
    /// modelled): flatcut finds each mark's edges with `G38.3` probe moves across them
    /// (GRBL 1.1 answers `[PRB:x,y,z:1]` at the contact, `:0` without one) and takes the
    /// square's centre from two chords, an L's corner from two points on each outer edge.
    GrblProbe,
}

impl Sensor {
    pub fn name(self) -> &'static str {
        match self {
            Sensor::None => "none",
            Sensor::HpglDigitize => "hpgl-digitize",
            Sensor::GrblProbe => "grbl-probe",
        }
    }
}

/// The sheet corner that holds the square mark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Corner {
    #[default]
    UpperLeft,
    UpperRight,
    LowerRight,
    LowerLeft,
}

/// The `[registration]` table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Registration {
    pub sensor: Sensor,
    /// From the sheet's edge to a mark's outer edge, mm.
    pub inset: f64,
    /// Length of an L mark's arms, mm.
    pub length: f64,
    /// Width of an L mark's arms, mm.
    pub width: f64,
    /// Side of the square mark, mm.
    pub square: f64,
    pub square_corner: Corner,
    /// Room the nest keeps free around the marks, mm.
    pub clearance: f64,
    /// How far from where a mark should be the sensor looks for it, mm.
    pub search: f64,
    /// Largest residual of a mark accepted after the fit, mm.
    pub tolerance: f64,
    /// Largest scale error accepted, as a fraction (0.01: ±1 %).
    pub max_scale_error: f64,
}

impl Default for Registration {
    fn default() -> Self {
        Registration {
            sensor: Sensor::None,
            inset: 10.0,
            length: 20.0,
            width: 1.0,
            square: 5.0,
            square_corner: Corner::UpperLeft,
            clearance: 2.0,
            search: 10.0,
            tolerance: 0.3,
            max_scale_error: 0.01,
        }
    }
}

/// The sizes are positive and finite, the inset and clearance not negative, the arms longer
/// than wide: `(key, message)` of the first that is not.
pub(super) fn check(r: &Registration) -> Result<(), (&'static str, String)> {
    let sizes = [
        ("length", r.length),
        ("width", r.width),
        ("square", r.square),
        ("search", r.search),
        ("tolerance", r.tolerance),
        ("max_scale_error", r.max_scale_error),
    ];
    for (key, v) in sizes {
        if !(v.is_finite() && v > 0.0) {
            return Err((key, format!("must be a positive number, got {v}")));
        }
    }
    for (key, v) in [("inset", r.inset), ("clearance", r.clearance)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err((key, format!("must be 0 or a distance in mm, got {v}")));
        }
    }
    if r.width >= r.length {
        return Err((
            "width",
            format!(
                "must be less than the arms' length ({} mm), got {}",
                r.length, r.width
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_say_whether_there_is_a_sensor() {
        for p in crate::profile::all().unwrap() {
            let expect = if p.name.starts_with("sim") {
                Sensor::HpglDigitize
            } else {
                Sensor::None
            };
            assert_eq!(p.registration.sensor, expect, "{}", p.name);
            assert_eq!(p.registration.inset, 10.0, "{}", p.name);
        }
        let head = "name='x'\ndescription='d'\nlanguage='hpgl'\ndialect='hp-gl'\nunits_per_mm=40\n[tools.cut]\npen=1\n";
        let err = |extra: &str| {
            crate::profile::parse(&format!("{head}[registration]\n{extra}"), "x.toml")
                .unwrap_err()
                .to_string()
        };
        let e = err("inset = -1\n");
        assert!(e.contains("x.toml: line 9: `registration.inset`"), "{e}");
        let e = err("width = 30\n");
        assert!(e.contains("`registration.width` must be less than"), "{e}");
        let e = err("sensor = \"laser\"\n");
        assert!(e.contains("x.toml") && e.contains("sensor"), "{e}");
    }
}
