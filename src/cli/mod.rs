//! Command line: clap argument structs, one file per subcommand, each of which parses its
//! flags, calls [`crate::pipeline`] and prints; no subcommand's file calls another's. What
//! several subcommands share lives beside them: the flag groups ([`args`]), the link to a
//! machine with its progress bars and Ctrl-C ([`link`]), print-and-cut's flags and send
//! ([`printcut`]), and the summary `cut` and `fitting`
//! print. `main.rs` only parses and maps errors to exit codes.

pub mod args;
pub mod check;
pub mod cut;
pub mod fitting;
pub mod flatten;
pub mod link;
pub mod nest;
pub mod ports;
pub mod printcut;
pub mod resume;
pub mod send;
pub mod sim;

use crate::pipeline::CutRun;
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
  flatcut resume out/cube                             go on with a job that stopped (hang-up, Ctrl-C)
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
    /// Go on with a job that stopped, from the last stroke the machine is known to have cut.
    #[command(after_help = EXAMPLES)]
    Resume(resume::ResumeArgs),
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
        Command::Resume(a) => resume::run(&a),
        Command::Sim(a) => sim::run(&a),
        Command::Ports => ports::ports(),
        Command::Devices => ports::devices(),
    }
}

/// What `cut` and `fitting` print after the files are written.
fn print_cut(spec: &Spec, run: &CutRun, device: &str, dry_run: bool) {
    let layout = &run.layout;
    let n = run.job.sheets.len();
    let cut: f64 = layout.pieces.iter().map(|p| p.cut_length()).sum();
    let fold: f64 = layout.pieces.iter().map(|p| p.fold_length()).sum::<f64>() + 0.0; // not -0
    println!(
        "{}: {} pieces on {} {} ({:.0} mm cut, {:.0} mm folds), device {}",
        spec.name,
        layout.pieces.len(),
        layout.sheets.len(),
        if layout.roll {
            "roll"
        } else if n == 1 {
            "sheet"
        } else {
            "sheets"
        },
        cut,
        fold,
        device
    );
    for i in 0..layout.sheets.len() {
        println!(
            "  {} {}: {:.0} × {:.0} mm, {:.1} % used",
            if layout.roll { "roll" } else { "sheet" },
            i + 1,
            layout.sheets[i].width,
            layout.sheets[i].height,
            100.0 * layout.utilisation(i)
        );
    }
    if let Some(len) = layout.roll_length() {
        println!("  roll length used: {len:.1} mm");
    }
    if let Some((lo, hi)) = layout.remnant {
        println!(
            "  left on the last sheet: {:.0} × {:.0} mm at ({:.0}, {:.0})",
            hi.x - lo.x,
            hi.y - lo.y,
            lo.x,
            lo.y
        );
    }
    println!("wrote {}: {}", run.dir.display(), run.files.join(", "));
    if dry_run {
        println!("dry run: nothing sent");
    }
}
