//! `flatcut nest INSTANCE.json [--nest-time S] [--seed N] [--threads T] -o DIR`: nests an
//! ESICUP strip-packing instance (the JSON form of jagua-rs and sparrow, see
//! [`crate::nest::esicup`]) and writes `solution.json` (sparrow's solution form) and
//! `layout.svg` into DIR, then prints the density. A bad instance (unreadable, not JSON, an
//! item with fewer than 3 points, an item that fits the strip in no orientation) is a user
//! error naming the file and the item.

use super::args::SearchArgs;
use crate::Error;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct NestArgs {
    /// ESICUP instance (JSON).
    pub input: PathBuf,
    /// Output directory for solution.json and layout.svg (default: out/<instance name>).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub search: SearchArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

pub fn run(a: &NestArgs) -> Result<(), Error> {
    let t0 = std::time::Instant::now();
    let run = crate::pipeline::nest_instance(&a.input, &a.search.search()?, a.output.clone())?;
    let (inst, sol) = (&run.instance, &run.solution);
    if std::env::var_os("FLATCUT_NEST_DEBUG").is_some() {
        eprintln!("work {} in {:.2} s", sol.work, t0.elapsed().as_secs_f64());
    }
    if !a.quiet {
        println!(
            "{}: {} items, strip {:.4} × {}, density {:.2} %; wrote {}: solution.json, layout.svg",
            inst.name,
            sol.placements.len(),
            sol.length,
            inst.height,
            100.0 * crate::nest::esicup::density(inst, sol),
            run.dir.display()
        );
    }
    Ok(())
}
