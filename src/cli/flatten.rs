//! `flatcut flatten SPEC|OBJ`: stops after the pattern stage and writes the pieces as SVG, PDF
//! and PNG (at `--dpi`; laid side by side on one long strip, no sheet limits) plus `report.json`
//! ([`crate::pipeline::flatten`]).

use super::args::{
    ask_alternatives, PatternArgs, PictureArgs, SearchArgs, SheetArgs, SizeArgs, SmoothArgs,
};
use crate::pipeline::Extras;
use crate::Error;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct FlattenArgs {
    /// Spec file (`.toml`) or a mesh (`.obj`, `.stl`, `.ply`, `.off`).
    pub input: PathBuf,
    /// Directory for the pictures and report (default: out/<name>).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Material: paper, fabric or metal (overrides the spec).
    #[arg(long)]
    pub material: Option<crate::spec::MaterialKind>,
    #[command(flatten)]
    pub metal: super::args::MetalArgs,
    #[command(flatten)]
    pub size: SizeArgs,
    #[command(flatten)]
    pub sheet: SheetArgs,
    #[command(flatten)]
    pub pattern: PatternArgs,
    #[command(flatten)]
    pub search: SearchArgs,
    /// Boundary surfaces: also write the N best distinct triangulations found, as
    /// `<surface>-alt-<k>.obj` (k = 1 is the one flattened).
    #[arg(long, value_name = "N")]
    pub alternatives: Option<usize>,
    #[command(flatten)]
    pub smooth: SmoothArgs,
    #[command(flatten)]
    pub pictures: PictureArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Also write the 3D surface mesh (all surfaces, mm) as a Wavefront OBJ file.
    #[arg(long, value_name = "FILE")]
    pub surface_obj: Option<PathBuf>,
    /// Also write the solved spline designs (knots, control points, strips, creases and where
    /// the curves lie on the flat pieces) as JSON; the spec needs a spline surface.
    #[arg(long, value_name = "FILE")]
    pub spline_json: Option<PathBuf>,
}

pub fn run(a: &FlattenArgs) -> Result<(), Error> {
    let mut spec = crate::spec::load(&a.input)?;
    if let Some(m) = a.material {
        spec.material.set_kind(m);
    }
    a.metal.apply(&mut spec)?;
    a.pattern.apply(&mut spec)?;
    a.size.apply(&mut spec);
    a.sheet.apply(&mut spec, None)?;
    ask_alternatives(&mut spec, a.alternatives);
    a.smooth.apply(&mut spec);
    let search = a.search.search()?;
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
    let run = crate::pipeline::flatten(&spec, &search, &extras)?;
    if !a.quiet {
        println!(
            "{}: {} pieces; wrote {}: {}",
            spec.name,
            run.layout.pieces.len(),
            run.dir.display(),
            run.files.join(", ")
        );
    }
    Ok(())
}
