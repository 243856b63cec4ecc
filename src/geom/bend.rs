//! Sheet-metal bend arithmetic, one place for every stage that develops a sheet: where the
//! neutral surface lies in the thickness, and a sharp bend's allowance, setback and
//! deduction (the formulas of FreeCAD's SheetMetal workbench and of every shop table).
//!
//! A bend of angle θ (its deflection: 0 = flat, 90° for a box's corner, π − the angle between
//! the two flanges) with inside radius R in a sheet t thick, whose neutral surface lies K·t
//! from the inside face:
//!
//! - bend allowance BA = θ·(R + K·t): the length of the neutral arc, what the bend takes of
//!   the blank;
//! - outside setback OSSB = (R + t)·tan(θ/2): from the outside mold line's sharp corner (where
//!   the two outside faces extended meet) to where the bend starts on the outside;
//! - inside setback ISSB = R·tan(θ/2), the same from the inside mold line's sharp corner;
//! - bend deduction BD = 2·setback − BA: how much shorter the blank is than the two flanges
//!   measured to the sharp corner of the mold line they are given by (outside: 2·OSSB − BA;
//!   inside: 2·ISSB − BA, which is negative for small radii: the blank is then longer).
//!
//! The fittings (`surface::fittings`, strips and splines in metal) are developed on the
//! neutral surface itself, [`neutral_depth`] from the inside face
//! ([`neutral_below_outside`] from the outside one); for a bend of large radius
//! the two agree: BD → θ·(1 − K)·t, the length the neutral surface lacks against the outside.

/// Depth (mm) of the neutral surface below the inside face of a sheet `t` mm thick with K
/// factor `k`: K·t (the outside face is `t` from the inside one).
pub fn neutral_depth(k: f64, t: f64) -> f64 {
    k * t
}

/// Depth (mm) of the neutral surface below the outside face: (1 − K)·t.
pub fn neutral_below_outside(k: f64, t: f64) -> f64 {
    (1.0 - k) * t
}

/// Which face of the sheet a bend's flanges are measured on: the outside mold line (the
/// convex side of the bend) or the inside one (the concave side).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoldLine {
    Outside,
    Inside,
}

impl MoldLine {
    pub fn name(self) -> &'static str {
        match self {
            MoldLine::Outside => "outside",
            MoldLine::Inside => "inside",
        }
    }
}

/// A sheet and the tooling that bends it: thickness, K factor and inside bend radius (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetBend {
    /// Sheet thickness t (mm).
    pub thickness: f64,
    /// K factor: the neutral surface's depth below the inside face over the thickness (0..1).
    pub k_factor: f64,
    /// Inside bend radius R (mm), the punch's.
    pub inside_radius: f64,
}

impl SheetBend {
    /// Bend allowance BA = θ·(R + K·t) (mm) of a bend of `angle` radians (unsigned).
    pub fn allowance(&self, angle: f64) -> f64 {
        angle.abs() * (self.inside_radius + neutral_depth(self.k_factor, self.thickness))
    }

    /// Setback (mm) of a bend of `angle` radians from the sharp corner of `mold`:
    /// (R + t)·tan(θ/2) outside, R·tan(θ/2) inside.
    pub fn setback(&self, angle: f64, mold: MoldLine) -> f64 {
        let r = match mold {
            MoldLine::Outside => self.inside_radius + self.thickness,
            MoldLine::Inside => self.inside_radius,
        };
        r * (0.5 * angle.abs()).tan()
    }

    /// Bend deduction BD = 2·setback − BA (mm) of a bend of `angle` radians whose flanges are
    /// measured to the sharp corner of `mold`; may be negative (inside, small radius).
    pub fn deduction(&self, angle: f64, mold: MoldLine) -> f64 {
        2.0 * self.setback(angle, mold) - self.allowance(angle)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn a_right_angle_bend_in_2mm_steel() {
        let s = SheetBend {
            thickness: 2.0,
            k_factor: 0.4,
            inside_radius: 2.0,
        };
        // BA = π/2 · (2 + 0.8), OSSB = 4, BD = 8 − BA.
        let ba = FRAC_PI_2 * 2.8;
        assert!((s.allowance(FRAC_PI_2) - ba).abs() < 1e-12);
        assert!((s.setback(FRAC_PI_2, MoldLine::Outside) - 4.0).abs() < 1e-12);
        assert!((s.deduction(FRAC_PI_2, MoldLine::Outside) - (8.0 - ba)).abs() < 1e-12);
        assert!((s.deduction(FRAC_PI_2, MoldLine::Inside) - (4.0 - ba)).abs() < 1e-12);
        // The sign of the angle does not matter.
        assert_eq!(s.allowance(-FRAC_PI_2), s.allowance(FRAC_PI_2));
    }

    #[test]
    fn a_gentle_bend_deducts_what_the_neutral_surface_lacks() {
        let s = SheetBend {
            thickness: 1.5,
            k_factor: 0.4,
            inside_radius: 3.0,
        };
        let theta = 1e-4;
        let bd = s.deduction(theta, MoldLine::Outside);
        let neutral = theta * (1.5 - neutral_depth(0.4, 1.5));
        assert!((bd - neutral).abs() < 1e-6 * neutral, "{bd} vs {neutral}");
    }
}
