//! `flatcut cut SPEC|OBJ`: the whole pipeline. Reads the spec (or a bare OBJ with defaults),
//! applies the device profile and the flags (flags win), and runs [`crate::pipeline::cut`],
//! which writes into `-o DIR`: the program for the device (`<name>.plt`, or `<name>-<k>.plt`
//! per sheet when there are several), `<name>.svg`, `<name>.pdf` (1:1, a page per sheet),
//! `<name>-<k>.png` per sheet (at `--dpi`), with `--print` `<name>-print.pdf` (the sheets tiled
//! onto printer pages, [`crate::output::print`]), `<name>.dxf`
//! (or `<name>-<k>.dxf`) per sheet and `report.json`, each written whole or not at all. Then,
//! unless `--dry-run`, the program is streamed to the device: the simulated cutter for `sim`
//! (the default) or with `--simulate`, else the serial port given by `--port` (see
//! [`super::link`]). The files are written before anything is sent, so a failed or
//! interrupted send loses nothing. `--tool-change` makes the marks of a knife-only device in
//! a pen pass before the knife pass (see [`super::link`] for the pause between them).
//! `--print-and-cut` puts registration marks on each sheet and everything drawn in the PDF to
//! print; the cutter gets only the cut (and score), registered on the marks
//! ([`super::printcut`]).

use super::args::{
    ask_alternatives, PatternArgs, PictureArgs, SearchArgs, SheetArgs, SizeArgs, SmoothArgs,
    ToolpathArgs,
};
use super::link::LinkArgs;
use super::printcut::PrintCutArgs;
use crate::pipeline::Extras;
use crate::spec::MaterialKind;
use crate::Error;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct CutArgs {
    /// Spec file (`.toml`) or a mesh (`.obj`, `.stl`, `.ply`, `.off`) to cut with default
    /// settings.
    pub input: PathBuf,
    /// Directory for the program, pictures and report (default: out/<name>).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Device profile (see devices/; default: the spec's, else `sim`).
    #[arg(long)]
    pub device: Option<String>,
    /// Material: paper, fabric or metal (overrides the spec).
    #[arg(long)]
    pub material: Option<MaterialKind>,
    #[command(flatten)]
    pub metal: super::args::MetalArgs,
    /// Write the program and pictures but send nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// A device without a pen (a knife-only cutter): draw the labels and ids first with a pen
    /// in the knife holder (`<name>-pen.plt`), stop with the tool up for the knife (Enter, or
    /// a line on standard input), then cut. Without it they are left out, with a warning.
    #[arg(long)]
    pub tool_change: bool,
    #[command(flatten)]
    pub size: SizeArgs,
    #[command(flatten)]
    pub sheet: SheetArgs,
    #[command(flatten)]
    pub toolpath: ToolpathArgs,
    #[command(flatten)]
    pub pattern: PatternArgs,
    #[command(flatten)]
    pub link: LinkArgs,
    #[command(flatten)]
    pub print_cut: PrintCutArgs,
    #[command(flatten)]
    pub search: SearchArgs,
    /// Boundary surfaces: also write the N best distinct triangulations found, as
    /// `<surface>-alt-<k>.obj` (k = 1 is the one cut), to pick another by hand.
    #[arg(long, value_name = "N")]
    pub alternatives: Option<usize>,
    #[command(flatten)]
    pub smooth: SmoothArgs,
    #[command(flatten)]
    pub pictures: PictureArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Also write the 3D surface mesh (all surfaces, mm) as a Wavefront OBJ file, to look at in
    /// a 3D viewer.
    #[arg(long, value_name = "FILE")]
    pub surface_obj: Option<PathBuf>,
    /// Also write the solved spline designs (knots, control points, strips, creases and where
    /// the curves lie on the flat pieces) as JSON; the spec needs a spline surface.
    #[arg(long, value_name = "FILE")]
    pub spline_json: Option<PathBuf>,
}

pub fn run(a: &CutArgs) -> Result<(), Error> {
    let mut spec = crate::spec::load(&a.input)?;
    if let Some(m) = a.material {
        spec.material.set_kind(m);
    }
    a.metal.apply(&mut spec)?;
    a.pattern.apply(&mut spec)?;
    a.size.apply(&mut spec);
    ask_alternatives(&mut spec, a.alternatives);
    a.smooth.apply(&mut spec);
    let device = a
        .device
        .clone()
        .or_else(|| spec.device.clone())
        .unwrap_or_else(|| "sim".to_string());
    let mut profile = a.toolpath.device(&device)?;
    a.print_cut.apply(&mut profile)?;
    a.sheet.apply(&mut spec, Some(&profile))?;
    super::link::need_port(&profile, &a.link, a.dry_run)?;
    let extras = Extras {
        output: a.output.clone(),
        alternatives: a.alternatives,
        surface_obj: a.surface_obj.clone(),
        uv_obj: a.smooth.uv_obj.clone(),
        spline_json: super::args::spline_json(&spec, &a.spline_json)?,
        quiet: a.quiet,
        dpi: a.pictures.dpi(),
        print: a.pictures.print_options(),
    };
    let search = a.search.search()?;
    let choices = crate::pipeline::Toolpath {
        tool_change: a.tool_change,
        print_and_cut: a.print_cut.print_and_cut,
        ..a.toolpath.choices()
    };
    let run = crate::pipeline::cut(&spec, &profile, &search, &choices, &extras)?;
    if !a.quiet {
        super::print_cut(&spec, &run, &profile.name, a.dry_run);
    }
    super::printcut::deliver(&run, &profile, &a.link, &a.print_cut, a.quiet, a.dry_run)?;
    Ok(())
}
