//! `flatcut nest INSTANCE.json [--nest-time S] [--seed N] [--threads T] -o DIR`: nests an
//! ESICUP strip-packing instance (the JSON form of jagua-rs and sparrow, see
//! [`crate::nest::esicup`]) and writes `solution.json` (sparrow's solution form) and
//! `layout.svg` into DIR, then prints the density. A bad instance (unreadable, not JSON, an
//! item with fewer than 3 points, an item that fits the strip in no orientation) is a user
//! error naming the file and the item.

use crate::nest::esicup;
use crate::output::files::{create_dir, write_atomic};
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

/// Search flags shared by `nest`, `cut` and `flatten`.
#[derive(Debug, Args, Clone, Copy, Default)]
pub struct SearchArgs {
    /// Time for the nesting search in seconds (a deterministic work budget calibrated to
    /// seconds on a 2-core machine; default 1 for cut and flatten, 60 for nest).
    #[arg(long, value_name = "SECONDS")]
    pub nest_time: Option<f64>,
    /// Seed of the nesting search: the same seed and thread count give the same layout.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Independent nesting searches run in parallel (default 2).
    #[arg(long)]
    pub threads: Option<usize>,
}

impl SearchArgs {
    /// Apply the flags that were given to nest options.
    pub fn apply(&self, opts: &mut crate::nest::NestOptions) -> Result<(), Error> {
        if let Some(t) = self.nest_time {
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::Usage(format!(
                    "--nest-time must be a number of seconds ≥ 0, got {t}"
                )));
            }
            opts.seconds = t;
        }
        if let Some(s) = self.seed {
            opts.seed = s;
        }
        if let Some(t) = self.threads {
            opts.threads = t.clamp(1, 64);
        }
        Ok(())
    }
}

pub fn run(a: &NestArgs) -> Result<(), Error> {
    let inst = esicup::load(&a.input)?;
    let mut opts = crate::nest::NestOptions {
        seconds: 60.0,
        ..Default::default()
    };
    a.search.apply(&mut opts)?;
    let cfg = crate::nest::problem::Config {
        seconds: opts.seconds,
        seed: opts.seed,
        threads: opts.threads,
    };
    let t0 = std::time::Instant::now();
    let sol = esicup::solve(&inst, &cfg)?;
    if std::env::var_os("FLATCUT_NEST_DEBUG").is_some() {
        eprintln!("work {} in {:.2} s", sol.work, t0.elapsed().as_secs_f64());
    }
    let dir = a
        .output
        .clone()
        .unwrap_or_else(|| super::cut::default_dir(&inst.name));
    create_dir(&dir)?;
    let text = serde_json::to_string_pretty(&esicup::solution_json(&inst, &sol))
        .unwrap_or_default()
        + "\n";
    write_atomic(&dir.join("solution.json"), text.as_bytes())?;
    write_atomic(&dir.join("layout.svg"), esicup::svg(&inst, &sol).as_bytes())?;
    if !a.quiet {
        println!(
            "{}: {} items, strip {:.4} × {}, density {:.2} %; wrote {}: solution.json, layout.svg",
            inst.name,
            sol.placements.len(),
            sol.length,
            inst.height,
            100.0 * esicup::density(&inst, &sol),
            dir.display()
        );
    }
    Ok(())
}
