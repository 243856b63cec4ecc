//! `flatcut fitting KIND`: a sheet-metal fitting from shop dimensions in millimetres (see
//! [`crate::surface::fittings`]), developed as a strip and sent through the same pipeline as
//! `cut` ([`crate::pipeline::cut`]): the same device, `--dry-run` and `-o` handling, the same
//! files (program, SVG, PNG, DXF, report).
//!
//! Choices: the material is metal unless `--material` says otherwise; the thickness defaults to
//! 0 (develop the given surface), K to 0.4; the sheet is 2500 × 1250 mm (a common steel sheet)
//! unless `--sheet-width` / `--sheet-height` say otherwise, with a 10 mm margin; the job is
//! named after the kind (`cone`, `square-to-round`, …) unless `--name` is given; the device,
//! as for `cut`, defaults to `sim`; bend lines are a shop's (`--bend-lines shop`: equal shares
//! of the bend at least 20 mm apart), not every ruling of the fine strip.

use super::args::parse_bend_lines;
use crate::pipeline::{Extras, Search, Toolpath};
use crate::spec::{
    Material, MaterialKind, PatternSpec, SheetSpec, Spec, SurfaceKind, SurfaceSpec, Units,
};
use crate::surface::fittings::{Fitting, FittingOptions};
use crate::surface::strip::BendLines;
use crate::Error;
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// Kinds of fitting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FittingKind {
    /// Frustum between two circles (`--offset` for an offset hopper cone).
    Cone,
    /// Rectangle to circle transition.
    SquareToRound,
    /// Rectangle to rectangle transition.
    RectToRect,
    /// One segment of a mitred pipe elbow.
    PipeMiter,
    /// Between two circles, or ellipses with `--bottom-depth` / `--top-depth`.
    Lampshade,
}

#[derive(Debug, Args)]
pub struct FittingArgs {
    /// What to make.
    pub kind: FittingKind,
    /// Cone, lampshade: bottom diameter (mm; the x axis of an ellipse).
    #[arg(long, allow_negative_numbers = true)]
    pub bottom_diameter: Option<f64>,
    /// Cone, lampshade: top diameter (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub top_diameter: Option<f64>,
    /// Lampshade: bottom ellipse's y axis (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub bottom_depth: Option<f64>,
    /// Lampshade: top ellipse's y axis; rect-to-rect: top rectangle depth (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub top_depth: Option<f64>,
    /// Height between the two ends (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub height: Option<f64>,
    /// Cone: the top's centre moved along x (mm), for an offset cone.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub offset: f64,
    /// Square-to-round, rect-to-rect: rectangle width along x (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub width: Option<f64>,
    /// Square-to-round, rect-to-rect: rectangle depth along y (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub depth: Option<f64>,
    /// Square-to-round, pipe-miter: diameter of the round end or the pipe (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub diameter: Option<f64>,
    /// Rect-to-rect: top rectangle width (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub top_width: Option<f64>,
    /// Square-to-round, rect-to-rect: top moved along x (mm).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub offset_x: f64,
    /// Square-to-round, rect-to-rect: top moved along y (mm).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub offset_y: f64,
    /// Pipe-miter: centre-line length (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub length: Option<f64>,
    /// Pipe-miter: cut angle from square (degrees; 45 for a two-piece 90° elbow).
    #[arg(long, allow_negative_numbers = true)]
    pub angle: Option<f64>,
    /// Sheet thickness (mm); 0 develops the given surface, more develops the neutral surface.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub thickness: f64,
    /// Neutral surface position from the inside face, as a fraction of the thickness.
    #[arg(long, default_value_t = 0.4, allow_negative_numbers = true)]
    pub k_factor: f64,
    /// Bend lines: shop (default: the whole bend in equal shares on lines at least 20 mm
    /// apart, as a brake operator bumps a cone), all (every ruling that bends, often hundreds
    /// of a degree or two), none, or a spacing in mm (rulings about that far apart, each with
    /// the angle accumulated since the previous one).
    #[arg(long, default_value = "shop", value_parser = parse_bend_lines)]
    pub bend_lines: BendLines,
    /// Chordal tolerance of the curves (mm).
    #[arg(long, default_value_t = crate::geom::curve::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    /// Sheet width (mm).
    #[arg(long, default_value_t = 2500.0)]
    pub sheet_width: f64,
    /// Sheet height (mm).
    #[arg(long, default_value_t = 1250.0)]
    pub sheet_height: f64,
    /// A blank too large for the sheet: auto (made of segments joined along rulings, each
    /// with its bend lines) or none (refused). Default: auto.
    #[arg(long, value_enum)]
    pub split: Option<crate::pattern::split::Split>,
    /// Job name (file names, labels); default: the kind.
    #[arg(long)]
    pub name: Option<String>,
    /// Directory for the program, pictures, DXF and report (default: out/<name>).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Device profile (default `sim`).
    #[arg(long)]
    pub device: Option<String>,
    /// Material: metal (default), paper or fabric.
    #[arg(long)]
    pub material: Option<MaterialKind>,
    /// Write the program and pictures but send nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// A device without a pen (a knife-only cutter): draw the labels, seam marks and bend notes
    /// first with a pen in the knife holder (`<name>-pen.plt`), stop with the tool up for the
    /// knife (Enter, or a line on standard input), then cut. Without it they are left out, with
    /// a warning.
    #[arg(long)]
    pub tool_change: bool,
    /// Units of the dimensions and the thickness: mm (default), cm, m or in (the
    /// tolerance and the sheet flags stay in mm).
    #[arg(long, value_name = "mm|cm|m|in", value_parser = super::args::parse_units)]
    pub units: Option<Units>,
    #[command(flatten)]
    pub sheet: super::args::SheetArgs,
    #[command(flatten)]
    pub link: super::link::LinkArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

fn need(v: Option<f64>, flag: &str, kind: &str) -> Result<f64, Error> {
    v.ok_or_else(|| Error::Usage(format!("--{flag}: missing: a {kind} needs it")))
}

/// The fitting the flags describe.
pub fn fitting(a: &FittingArgs) -> Result<Fitting, Error> {
    let k = match a.kind {
        FittingKind::Cone => "cone",
        FittingKind::SquareToRound => "square-to-round",
        FittingKind::RectToRect => "rect-to-rect",
        FittingKind::PipeMiter => "pipe-miter",
        FittingKind::Lampshade => "lampshade",
    };
    let u = a.units.map_or(1.0, |u| u.mm());
    Ok(match a.kind {
        FittingKind::Cone => Fitting::Cone {
            bottom_diameter: need(a.bottom_diameter, "bottom-diameter", k)? * u,
            top_diameter: need(a.top_diameter, "top-diameter", k)? * u,
            height: need(a.height, "height", k)? * u,
            offset: a.offset * u,
        },
        FittingKind::SquareToRound => Fitting::SquareToRound {
            width: need(a.width, "width", k)? * u,
            depth: need(a.depth, "depth", k)? * u,
            diameter: need(a.diameter, "diameter", k)? * u,
            height: need(a.height, "height", k)? * u,
            offset_x: a.offset_x * u,
            offset_y: a.offset_y * u,
        },
        FittingKind::RectToRect => Fitting::RectToRect {
            width: need(a.width, "width", k)? * u,
            depth: need(a.depth, "depth", k)? * u,
            top_width: need(a.top_width, "top-width", k)? * u,
            top_depth: need(a.top_depth, "top-depth", k)? * u,
            height: need(a.height, "height", k)? * u,
            offset_x: a.offset_x * u,
            offset_y: a.offset_y * u,
        },
        FittingKind::PipeMiter => Fitting::PipeMiter {
            diameter: need(a.diameter, "diameter", k)? * u,
            length: need(a.length, "length", k)? * u,
            angle_deg: need(a.angle, "angle", k)?,
        },
        FittingKind::Lampshade => Fitting::Lampshade {
            bottom_diameter: need(a.bottom_diameter, "bottom-diameter", k)? * u,
            bottom_depth: a.bottom_depth.map(|v| v * u),
            top_diameter: need(a.top_diameter, "top-diameter", k)? * u,
            top_depth: a.top_depth.map(|v| v * u),
            height: need(a.height, "height", k)? * u,
        },
    })
}

/// The spec `fitting` cuts: one strip surface, metal, one big sheet.
pub fn spec(a: &FittingArgs) -> Result<Spec, Error> {
    let f = fitting(a)?;
    let opts = FittingOptions {
        thickness: a.thickness * a.units.map_or(1.0, |u| u.mm()),
        k_factor: a.k_factor,
        bend_lines: a.bend_lines,
        tolerance: a.tolerance,
    };
    if !(a.tolerance.is_finite() && a.tolerance > 0.0) {
        return Err(Error::Usage(format!(
            "--tolerance: must be more than 0 mm, got {}",
            a.tolerance
        )));
    }
    for (flag, v) in [
        ("sheet-width", a.sheet_width),
        ("sheet-height", a.sheet_height),
    ] {
        if !(v.is_finite() && v > 20.0) {
            return Err(Error::Usage(format!(
                "--{flag}: must be more than twice the 10 mm margin, got {v}"
            )));
        }
    }
    let strip = f
        .strip_spec(&opts)
        .map_err(|e| Error::Usage(e.to_string()))?;
    let name = a.name.clone().unwrap_or_else(|| f.kind().to_string());
    if let Err(m) = crate::pipeline::check_file_name(&name) {
        return Err(Error::Usage(format!("--name: {m}")));
    }
    let path = PathBuf::from(format!("fitting {}", f.kind()));
    let kind = a.material.unwrap_or(MaterialKind::Metal);
    Ok(Spec {
        name: name.clone(),
        path: path.clone(),
        device: None,
        size: None,
        sheet_given: true,
        surfaces: vec![SurfaceSpec {
            kind: SurfaceKind::Strip,
            path,
            scale: 1.0,
            units: Units::Mm,
            size: None,
            name,
            line: 0,
            strip: Some(strip),
            bent: None,
            boundary: None,
            spline: None,
            segment: Default::default(),
        }],
        material: Material {
            kind,
            thickness: if a.thickness > 0.0 {
                a.thickness * a.units.map_or(1.0, |u| u.mm())
            } else {
                kind.default_thickness()
            },
            k_factor: a.k_factor,
            bend_radius: None,
            thickness_given: a.thickness > 0.0,
        },
        sheet: SheetSpec {
            width: a.sheet_width,
            height: Some(a.sheet_height),
            margin: 10.0,
            spacing: 5.0,
        },
        pattern: PatternSpec {
            split: a.split,
            ..PatternSpec::default()
        },
    })
}

pub fn run(a: &FittingArgs) -> Result<(), Error> {
    let mut spec = spec(a)?;
    let device = a.device.clone().unwrap_or_else(|| "sim".to_string());
    let profile = crate::pipeline::device(&device, None, None)?;
    a.sheet.apply(&mut spec, Some(&profile))?;
    super::link::need_port(&profile, &a.link, a.dry_run)?;
    let extras = Extras {
        output: a.output.clone(),
        quiet: a.quiet,
        ..Default::default()
    };
    let run = crate::pipeline::cut(
        &spec,
        &profile,
        &Search::default(),
        &Toolpath {
            tool_change: a.tool_change,
            ..Toolpath::default()
        },
        &extras,
    )?;
    if !a.quiet {
        super::print_cut(&spec, &run, &profile.name, a.dry_run);
    }
    super::link::deliver_run(&run, &profile, &a.link, a.quiet, a.dry_run)?;
    Ok(())
}
