//! Command line: clap argument structs, one file per subcommand, and the composition of the
//! pipeline stages that the subcommands share. `main.rs` only parses and maps errors to exit
//! codes.

pub mod check;
pub mod cut;
pub mod fitting;
pub mod flatten;
pub mod link;
pub mod nest;
pub mod ports;
pub mod send;
pub mod sim;

use crate::flatten::{Flat, UnfoldOptions};
use crate::pattern::{PatternOptions, Piece};
use crate::spec::Spec;
use crate::Error;
use clap::{Parser, Subcommand};

const EXAMPLES: &str = "\
Examples:
  flatcut cut patterns/cube.toml -o out/cube          nest, write HPGL/SVG/PNG/report for the default device
  flatcut cut lamp.obj --device hpgl-pens --dry-run   a bare OBJ with defaults (paper, A4, 5 mm margin)
  flatcut cut box.toml --material fabric -o out       flags override the spec file
  flatcut flatten patterns/house.toml -o out/house    pieces only, as SVG and PNG
  flatcut fitting cone --bottom-diameter 300 --top-diameter 160 --height 200 --thickness 2 --dry-run
  flatcut fitting square-to-round --width 400 --depth 300 --diameter 250 --height 300 --bend-lines 50
  flatcut nest fu.json --nest-time 10 -o out/fu        nest an ESICUP instance, print the density
  flatcut check model.obj                             faces, edges, boundary loops, angle defect
  flatcut cut lamp.toml --device roland-gx24 --port /dev/ttyUSB0   cut on a real machine
  flatcut cut lamp.toml --device grbl-dragknife --simulate          try a device on the simulator
  flatcut send out/cube/cube.plt --device hpgl-pens --port /dev/ttyUSB0
  flatcut sim --device grbl-pen -o out/sim            a simulated cutter for other software
  flatcut ports                                       serial ports on this machine
  flatcut devices                                     device profiles";

/// flatcut: developable surfaces to nested flat patterns for cutter plotters.
#[derive(Debug, Parser)]
#[command(name = "flatcut", version, about, after_help = EXAMPLES)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Unfold, nest and write the cut program (and pictures, report) for a spec or an OBJ.
    #[command(after_help = EXAMPLES)]
    Cut(cut::CutArgs),
    /// Develop a sheet-metal fitting (cone, square-to-round, rect-to-rect, pipe-miter,
    /// lampshade) from shop dimensions in mm and cut it like `cut` does.
    #[command(after_help = EXAMPLES)]
    Fitting(Box<fitting::FittingArgs>),
    /// Unfold and write the pieces (SVG, PNG, report) without nesting on sheets.
    #[command(after_help = EXAMPLES)]
    Flatten(flatten::FlattenArgs),
    /// Nest an ESICUP strip-packing instance (JSON): solution.json, layout.svg, density.
    #[command(after_help = EXAMPLES)]
    Nest(nest::NestArgs),
    /// Report what a mesh is made of and whether it can be unfolded exactly.
    #[command(after_help = EXAMPLES)]
    Check(check::CheckArgs),
    /// Stream an existing .plt or .gcode program to a machine (or the simulated cutter).
    #[command(after_help = EXAMPLES)]
    Send(send::SendArgs),
    /// Run the simulated cutter on a pseudo-terminal for other software to talk to.
    #[command(after_help = EXAMPLES)]
    Sim(sim::SimArgs),
    /// List serial ports.
    Ports,
    /// List device profiles.
    Devices,
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> Result<(), Error> {
    match cli.command {
        Command::Cut(a) => cut::run(&a),
        Command::Fitting(a) => fitting::run(&a),
        Command::Flatten(a) => flatten::run(&a),
        Command::Nest(a) => nest::run(&a),
        Command::Check(a) => check::run(&a),
        Command::Send(a) => send::run(&a),
        Command::Sim(a) => sim::run(&a),
        Command::Ports => ports::ports(),
        Command::Devices => ports::devices(),
    }
}

/// Pattern settings on the command line; they override the spec's `[pattern]` table.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct PatternArgs {
    /// Glue tabs: none, one-side or both (default: one-side for paper, else none).
    #[arg(long, value_enum)]
    pub tabs: Option<crate::pattern::Tabs>,
    /// Notches along every seam, every MM millimetres (default 50 with the flag; fabric has
    /// them at 50 mm anyway; 0 turns them off).
    #[arg(long, value_name = "MM", num_args = 0..=1, default_missing_value = "50")]
    pub notches: Option<f64>,
    /// Seam allowance in mm (default: 10 for fabric, else 0).
    #[arg(long, value_name = "MM")]
    pub allowance: Option<f64>,
    /// Width of the cut in mm: cut contours move half of it away from the piece.
    #[arg(long, value_name = "MM")]
    pub kerf: Option<f64>,
    /// V notches in the outline where bend lines meet it (sheet metal).
    #[arg(long)]
    pub bend_notches: bool,
}

impl PatternArgs {
    /// Puts the flags into the spec (flags win), refusing values that make no sense.
    pub fn apply(&self, spec: &mut Spec) -> Result<(), Error> {
        let check = |v: Option<f64>, flag: &str| match v {
            Some(x) if !(x.is_finite() && x >= 0.0) => Err(Error::Usage(format!(
                "--{flag} {x}: must be a length in mm, at least 0"
            ))),
            _ => Ok(()),
        };
        check(self.notches, "notches")?;
        check(self.allowance, "allowance")?;
        check(self.kerf, "kerf")?;
        let p = &mut spec.pattern;
        p.tabs = self.tabs.or(p.tabs);
        p.notches = self.notches.or(p.notches);
        p.allowance = self.allowance.or(p.allowance);
        p.kerf = self.kerf.or(p.kerf);
        if self.bend_notches {
            p.bend_notches = Some(true);
        }
        Ok(())
    }
}

/// Surfaces → flats → pieces for a spec; prints import warnings to stderr.
pub fn pieces(spec: &Spec, quiet: bool) -> Result<(Vec<Flat>, Vec<Piece>), Error> {
    let mut flats = Vec::new();
    for s in &spec.surfaces {
        let surface = crate::surface::build(&s.for_material(&spec.material)).map_err(|e| {
            if s.line > 0 {
                Error::At {
                    file: spec.path.clone(),
                    line: s.line,
                    source: Box::new(e.into()),
                }
            } else {
                e.into()
            }
        })?;
        if !quiet {
            for w in &surface.warnings {
                eprintln!("flatcut: warning: {w}");
            }
        }
        // Charted (smooth) surfaces are parameterised, the rest unfolded exactly (issue 7).
        let opts = crate::flatten::charts::FlattenOptions {
            unfold: UnfoldOptions::default(),
            ..crate::flatten::charts::FlattenOptions::for_material(spec.material.kind)
        };
        let flat = crate::flatten::charts::flatten(surface, &opts)?;
        if !quiet && flat.surface.charts.is_some() {
            for w in flat
                .surface
                .warnings
                .iter()
                .filter(|w| w.contains("stretches by"))
            {
                eprintln!("flatcut: warning: {w}");
            }
        }
        flats.push(flat);
    }
    let opts = PatternOptions::from_spec(spec);
    let pieces = crate::pattern::build(&flats, &opts)?;
    Ok((flats, pieces))
}
