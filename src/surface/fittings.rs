//! Sheet-metal fittings a shop makes every day (issue 4, item 3), each built as a developable
//! strip ([`super::strip`], Wang–Tang GODT+GMBT) between its two boundary curves:
//!
//! - `cone`: a frustum between a bottom circle (z = 0) and a top circle (z = height), the top
//!   moved by `offset` along +x for an offset (oblique) hopper cone;
//! - `square-to-round`: a rectangle `width` (x) × `depth` (y) at z = 0 to a circle at
//!   z = height, optionally offset in x and y; the strip finds the classical four flat triangles
//!   and four corner cones by itself;
//! - `rect-to-rect`: a rectangle to another (`top_width` × `top_depth`), optionally offset;
//! - `pipe-miter`: a cylinder of `diameter` cut square at z = 0 and at `angle` degrees from
//!   square at the top (centre-line length `length`), one segment of a mitred elbow (a 90°
//!   two-piece elbow has 45° cuts);
//! - `lampshade`: between two circles, or ellipses when a depth is given.
//!
//! Dimensions are the outside of the part. Thickness (item 5): a metal blank is developed on
//! its neutral surface, which lies K·t from the inside face, i.e. (1 − K)·t inside the outside
//! face given here ([`FittingOptions::k_factor`] K = 0.4 by default, as FreeCAD's SheetMetal
//! workbench). "Inside" is the concave side of the bends: toward the axis for cone, pipe and
//! lampshade, toward the duct's interior for square-to-round and rect-to-rect. Thickness 0
//! develops the given surface. The strip moves the boundary curves within their planes (see
//! [`super::strip::Strip::offset`]), so the blank still ends on the same planes.
//!
//! The seam is the strip's starting bridge: the shortest ruling (for an offset cone the short
//! side; for a square-to-round the middle of a long side; for a pipe miter the short side).
//! Curves start on +x and run counter-clockwise seen from +z, so the outside is the printed
//! side and every bend of a convex fitting is a mountain there (BEND_DOWN in the DXF).

use crate::geom::curve::{circle_segments, Curve};
use crate::surface::strip::{BendLines, Method};
use crate::surface::StripSpec;
use glam::DVec3;

/// A fitting and its dimensions (mm, degrees for angles).
#[derive(Debug, Clone, PartialEq)]
pub enum Fitting {
    Cone {
        bottom_diameter: f64,
        top_diameter: f64,
        height: f64,
        offset: f64,
    },
    SquareToRound {
        width: f64,
        depth: f64,
        diameter: f64,
        height: f64,
        offset_x: f64,
        offset_y: f64,
    },
    RectToRect {
        width: f64,
        depth: f64,
        top_width: f64,
        top_depth: f64,
        height: f64,
        offset_x: f64,
        offset_y: f64,
    },
    PipeMiter {
        diameter: f64,
        length: f64,
        angle_deg: f64,
    },
    Lampshade {
        bottom_diameter: f64,
        bottom_depth: Option<f64>,
        top_diameter: f64,
        top_depth: Option<f64>,
        height: f64,
    },
}

/// Material and strip settings of a fitting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittingOptions {
    /// Sheet thickness (mm); 0 develops the given (outside) surface.
    pub thickness: f64,
    /// Position of the neutral surface from the inside face, as a fraction of the thickness.
    pub k_factor: f64,
    /// Which rulings become bend lines; default: a shop's ([`BendLines::Shop`]).
    pub bend_lines: BendLines,
    /// Chordal tolerance of the curves (mm).
    pub tolerance: f64,
}

impl Default for FittingOptions {
    fn default() -> Self {
        FittingOptions {
            thickness: 0.0,
            k_factor: 0.4,
            bend_lines: BendLines::Shop,
            tolerance: crate::geom::curve::DEFAULT_TOLERANCE,
        }
    }
}

/// A dimension that cannot make a fitting; names the command-line flag.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("--{flag}: {message}")]
pub struct FittingError {
    pub flag: &'static str,
    pub message: String,
}

fn err(flag: &'static str, message: String) -> FittingError {
    FittingError { flag, message }
}

fn positive(flag: &'static str, v: f64) -> Result<(), FittingError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(flag, format!("must be more than 0 mm, got {v}")))
    }
}

fn finite(flag: &'static str, v: f64) -> Result<(), FittingError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(err(flag, format!("must be a finite number, got {v}")))
    }
}

impl Fitting {
    /// Command-line name of the kind.
    pub fn kind(&self) -> &'static str {
        match self {
            Fitting::Cone { .. } => "cone",
            Fitting::SquareToRound { .. } => "square-to-round",
            Fitting::RectToRect { .. } => "rect-to-rect",
            Fitting::PipeMiter { .. } => "pipe-miter",
            Fitting::Lampshade { .. } => "lampshade",
        }
    }

    /// Check the dimensions; the error names the flag.
    pub fn validate(&self) -> Result<(), FittingError> {
        match *self {
            Fitting::Cone {
                bottom_diameter,
                top_diameter,
                height,
                offset,
            } => {
                positive("bottom-diameter", bottom_diameter)?;
                positive("top-diameter", top_diameter)?;
                positive("height", height)?;
                // Equal diameters make a cylinder: fine, the strip handles it.
                finite("offset", offset)?;
            }
            Fitting::SquareToRound {
                width,
                depth,
                diameter,
                height,
                offset_x,
                offset_y,
            } => {
                positive("width", width)?;
                positive("depth", depth)?;
                positive("diameter", diameter)?;
                positive("height", height)?;
                finite("offset-x", offset_x)?;
                finite("offset-y", offset_y)?;
            }
            Fitting::RectToRect {
                width,
                depth,
                top_width,
                top_depth,
                height,
                offset_x,
                offset_y,
            } => {
                positive("width", width)?;
                positive("depth", depth)?;
                positive("top-width", top_width)?;
                positive("top-depth", top_depth)?;
                positive("height", height)?;
                finite("offset-x", offset_x)?;
                finite("offset-y", offset_y)?;
            }
            Fitting::PipeMiter {
                diameter,
                length,
                angle_deg,
            } => {
                positive("diameter", diameter)?;
                positive("length", length)?;
                if !(angle_deg.is_finite() && (0.0..80.0).contains(&angle_deg)) {
                    return Err(err(
                        "angle",
                        format!("must be at least 0° and less than 80°, got {angle_deg}"),
                    ));
                }
                let short = length - 0.5 * diameter * angle_deg.to_radians().tan();
                if short <= 0.0 {
                    return Err(err(
                        "length",
                        format!(
                            "{length} mm is too short for a {angle_deg}° cut on a {diameter} mm pipe: the short side would be {short:.1} mm"
                        ),
                    ));
                }
            }
            Fitting::Lampshade {
                bottom_diameter,
                bottom_depth,
                top_diameter,
                top_depth,
                height,
            } => {
                positive("bottom-diameter", bottom_diameter)?;
                positive("top-diameter", top_diameter)?;
                positive("height", height)?;
                if let Some(d) = bottom_depth {
                    positive("bottom-depth", d)?;
                }
                if let Some(d) = top_depth {
                    positive("top-depth", d)?;
                }
            }
        }
        Ok(())
    }

    /// The smallest radius of the fitting's boundaries (half the shorter side of a rectangle)
    /// and the flag it comes from: the sheet cannot be thicker.
    fn smallest_radius(&self) -> (f64, &'static str) {
        let mut best = (f64::INFINITY, "");
        let mut see = |v: f64, flag: &'static str| {
            if v < best.0 {
                best = (v, flag);
            }
        };
        match *self {
            Fitting::Cone {
                bottom_diameter,
                top_diameter,
                ..
            } => {
                see(0.5 * bottom_diameter, "bottom-diameter");
                see(0.5 * top_diameter, "top-diameter");
            }
            Fitting::SquareToRound {
                width,
                depth,
                diameter,
                ..
            } => {
                see(0.5 * width, "width");
                see(0.5 * depth, "depth");
                see(0.5 * diameter, "diameter");
            }
            Fitting::RectToRect {
                width,
                depth,
                top_width,
                top_depth,
                ..
            } => {
                see(0.5 * width, "width");
                see(0.5 * depth, "depth");
                see(0.5 * top_width, "top-width");
                see(0.5 * top_depth, "top-depth");
            }
            Fitting::PipeMiter { diameter, .. } => see(0.5 * diameter, "diameter"),
            Fitting::Lampshade {
                bottom_diameter,
                bottom_depth,
                top_diameter,
                top_depth,
                ..
            } => {
                see(0.5 * bottom_diameter, "bottom-diameter");
                see(0.5 * top_diameter, "top-diameter");
                if let Some(d) = bottom_depth {
                    see(0.5 * d, "bottom-depth");
                }
                if let Some(d) = top_depth {
                    see(0.5 * d, "top-depth");
                }
            }
        }
        best
    }

    /// The two boundary curves (bottom P, top Q).
    pub fn curves(&self, tol: f64) -> (Curve, Curve) {
        let at = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        match *self {
            Fitting::Cone {
                bottom_diameter,
                top_diameter,
                height,
                offset,
            } => (
                Curve::Circle {
                    center: DVec3::ZERO,
                    radius: 0.5 * bottom_diameter,
                },
                Curve::Circle {
                    center: at(offset, 0.0, height),
                    radius: 0.5 * top_diameter,
                },
            ),
            Fitting::SquareToRound {
                width,
                depth,
                diameter,
                height,
                offset_x,
                offset_y,
            } => (
                Curve::Rect {
                    center: DVec3::ZERO,
                    width,
                    height: depth,
                    corner_radius: 0.0,
                },
                Curve::Circle {
                    center: at(offset_x, offset_y, height),
                    radius: 0.5 * diameter,
                },
            ),
            Fitting::RectToRect {
                width,
                depth,
                top_width,
                top_depth,
                height,
                offset_x,
                offset_y,
            } => (
                Curve::Rect {
                    center: DVec3::ZERO,
                    width,
                    height: depth,
                    corner_radius: 0.0,
                },
                Curve::Rect {
                    center: at(offset_x, offset_y, height),
                    width: top_width,
                    height: top_depth,
                    corner_radius: 0.0,
                },
            ),
            Fitting::PipeMiter {
                diameter,
                length,
                angle_deg,
            } => {
                let r = 0.5 * diameter;
                let n = circle_segments(r, tol, 4);
                let slope = angle_deg.to_radians().tan();
                let top = (0..n)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / n as f64;
                        at(r * a.cos(), r * a.sin(), length + r * a.cos() * slope)
                    })
                    .collect();
                (
                    Curve::Circle {
                        center: DVec3::ZERO,
                        radius: r,
                    },
                    Curve::Points {
                        points: top,
                        closed: true,
                    },
                )
            }
            Fitting::Lampshade {
                bottom_diameter,
                bottom_depth,
                top_diameter,
                top_depth,
                height,
            } => {
                let ring = |d: f64, depth: Option<f64>, z: f64| match depth {
                    None => Curve::Circle {
                        center: at(0.0, 0.0, z),
                        radius: 0.5 * d,
                    },
                    Some(e) => Curve::Ellipse {
                        center: at(0.0, 0.0, z),
                        rx: 0.5 * d,
                        ry: 0.5 * e,
                    },
                };
                (
                    ring(bottom_diameter, bottom_depth, 0.0),
                    ring(top_diameter, top_depth, height),
                )
            }
        }
    }

    /// The strip a fitting is made of, with its neutral-surface shift.
    pub fn strip_spec(&self, opts: &FittingOptions) -> Result<StripSpec, FittingError> {
        self.validate()?;
        let t = opts.thickness;
        if !(t.is_finite() && t >= 0.0) {
            return Err(err("thickness", format!("must be 0 mm or more, got {t}")));
        }
        let k = opts.k_factor;
        if !(k.is_finite() && (0.0..=1.0).contains(&k)) {
            return Err(err("k-factor", format!("must be between 0 and 1, got {k}")));
        }
        let (r, flag) = self.smallest_radius();
        if t >= r {
            return Err(err(
                "thickness",
                format!("{t} mm is not less than the smallest radius, {r} mm (half of --{flag})"),
            ));
        }
        let (p, q) = self.curves(opts.tolerance);
        Ok(StripSpec {
            p,
            q,
            method: Method::GodtGmbt,
            bend_lines: opts.bend_lines,
            tolerance: opts.tolerance,
            neutral_offset: crate::geom::bend::neutral_below_outside(k, t),
            sheet: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{SurfaceKind, SurfaceSpec, Units};
    use std::f64::consts::PI;

    fn surface(f: &Fitting, opts: &FittingOptions) -> crate::surface::Surface {
        let spec = SurfaceSpec {
            kind: SurfaceKind::Strip,
            path: "fitting".into(),
            scale: 1.0,
            units: Units::Mm,
            size: None,
            name: f.kind().into(),
            line: 0,
            strip: Some(f.strip_spec(opts).unwrap()),
            bent: None,
            boundary: None,
            spline: None,
            segment: Default::default(),
        };
        crate::surface::build(&spec).unwrap()
    }

    fn area(s: &crate::surface::Surface) -> f64 {
        s.mesh.area()
    }

    #[test]
    fn strip_fitting_cone_area_and_neutral_shift() {
        let cone = Fitting::Cone {
            bottom_diameter: 300.0,
            top_diameter: 160.0,
            height: 200.0,
            offset: 0.0,
        };
        let s = surface(&cone, &FittingOptions::default());
        let slant = (70.0f64 * 70.0 + 200.0 * 200.0).sqrt();
        let exact = PI * (150.0 + 80.0) * slant;
        assert!((area(&s) - exact).abs() / exact < 1e-3, "{}", area(&s));
        // A shop's bend lines (the default), each a mountain.
        let bends = s.bends.as_ref().unwrap();
        assert!(bends.iter().all(|b| b.angle_deg > 0.0));
        // 2 mm, K 0.4: the neutral radii are 1.2 mm / cos(β) smaller.
        let opts = FittingOptions {
            thickness: 2.0,
            ..FittingOptions::default()
        };
        let t = surface(&cone, &opts);
        let shift = 1.2 * slant / 200.0;
        let exact_t = PI * (150.0 - shift + 80.0 - shift) * slant;
        assert!(
            (area(&t) - exact_t).abs() / exact_t < 1e-3,
            "{} {exact_t}",
            area(&t)
        );
        let e = cone
            .strip_spec(&FittingOptions {
                thickness: 90.0,
                ..opts
            })
            .unwrap_err();
        assert_eq!(e.flag, "thickness");
    }

    #[test]
    fn strip_fitting_bend_spacing_accumulates_the_angle() {
        let cone = Fitting::Cone {
            bottom_diameter: 300.0,
            top_diameter: 160.0,
            height: 200.0,
            offset: 0.0,
        };
        let all = surface(
            &cone,
            &FittingOptions {
                bend_lines: BendLines::All,
                ..FittingOptions::default()
            },
        );
        let total: f64 = all
            .bends
            .as_ref()
            .unwrap()
            .iter()
            .map(|b| b.angle_deg)
            .sum();
        let spaced = surface(
            &cone,
            &FittingOptions {
                bend_lines: BendLines::Spacing(25.0),
                ..FittingOptions::default()
            },
        );
        let b = spaced.bends.as_ref().unwrap();
        // Mid-height circumference π·230 ≈ 722 mm: about 28 bend lines 25 mm apart.
        assert!((26..=29).contains(&b.len()), "{}", b.len());
        let sum: f64 = b.iter().map(|b| b.angle_deg).sum();
        assert!((sum - total).abs() < 1e-9 * total, "{sum} {total}");
    }

    #[test]
    fn strip_fitting_offset_transitions_are_fully_developable() {
        // Every ruling locally convex (no warning), seam included, for offset fittings.
        for f in [
            Fitting::SquareToRound {
                width: 400.0,
                depth: 300.0,
                diameter: 250.0,
                height: 300.0,
                offset_x: 40.0,
                offset_y: -25.0,
            },
            Fitting::Cone {
                bottom_diameter: 600.0,
                top_diameter: 200.0,
                height: 400.0,
                offset: 150.0,
            },
        ] {
            let s = surface(&f, &FittingOptions::default());
            assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        }
    }
}
