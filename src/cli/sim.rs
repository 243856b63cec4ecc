//! `flatcut sim --device D -o DIR`: run the simulated cutter on its own. It opens a
//! pseudo-terminal, prints `listening on /dev/pts/N` as its first line (so that any software —
//! a sign-making program, a shell `cat` with `stty ixon`, flatcut itself — can stream to it),
//! and on Ctrl-C writes `sim.png` and `sim.json` into DIR. `--for SECONDS` stops it by itself.
//! `--sheet-offset DX,DY,DEG[,SX[,SY]]` (and `--sheet-size W,H`, default 210,297) loads a
//! print-and-cut sheet with the profile's registration marks, placed that far off, for the
//! simulated sensor to find (`device::sim::sensor`).

use super::link::cancel_flag;
use crate::device::sim::{self, Faults, SimConfig};
use crate::Error;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

#[derive(Debug, Args)]
pub struct SimArgs {
    /// Device profile the simulator behaves like.
    #[arg(long, default_value = "sim")]
    pub device: String,
    /// Where the picture and report go on exit.
    #[arg(short, long, default_value = "out/sim")]
    pub output: PathBuf,
    /// Run motion this many times faster than the machine (0: motion takes no time).
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    /// Stop by itself after this many seconds (default: run until Ctrl-C).
    #[arg(long = "for")]
    pub run_for: Option<f64>,
    /// Fault injection: hang up after N bytes.
    #[arg(long)]
    pub hang_up_after: Option<usize>,
    /// Fault injection: stop executing after N bytes (buffer fills, no XON, no `ok`).
    #[arg(long)]
    pub stall_after: Option<usize>,
    /// Fault injection: send garbage after N bytes.
    #[arg(long)]
    pub garbage_after: Option<usize>,
    /// Fault injection: lose the first XON.
    #[arg(long)]
    pub lose_xon: bool,
    /// Print-and-cut: a printed sheet lies DX, DY mm off and turned DEG degrees
    /// (counter-clockwise about the origin), printed SX (and SY) times true size.
    #[arg(long, value_name = "DX,DY,DEG[,SX[,SY]]", allow_hyphen_values = true)]
    pub sheet_offset: Option<String>,
    /// Print-and-cut: the printed sheet's size, mm (its marks as the profile's
    /// `[registration]` says).
    #[arg(long, value_name = "W,H")]
    pub sheet_size: Option<String>,
}

pub fn run(a: &SimArgs) -> Result<(), Error> {
    let profile = crate::profile::find(&a.device)?;
    if !(a.speed.is_finite() && a.speed >= 0.0) {
        return Err(Error::Usage(format!(
            "--speed must be 0 or positive, got {}",
            a.speed
        )));
    }
    crate::pipeline::create_dir(&a.output)?;
    let cancel = cancel_flag();
    let mut cfg = SimConfig::new(profile.clone());
    cfg.time_factor = (a.speed > 0.0).then_some(a.speed);
    cfg.faults = Faults {
        hang_up_after: a.hang_up_after,
        stall_after: a.stall_after,
        garbage_after: a.garbage_after,
        lose_xon: a.lose_xon,
        grbl_error: None,
    };
    cfg.printed = printed(a, &profile)?;
    let handle = sim::spawn(cfg)?;
    println!("listening on {}", handle.path);
    println!(
        "simulating {} ({}, {} baud, {:?} flow control, {}-byte buffer); Ctrl-C to stop",
        profile.name,
        profile.language.label(),
        profile.serial.baud,
        profile.serial.flow_control,
        profile.buffer
    );
    let _ = std::io::stdout().flush();
    let start = Instant::now();
    while !cancel.load(Ordering::SeqCst)
        && a.run_for.is_none_or(|s| start.elapsed().as_secs_f64() < s)
    {
        std::thread::sleep(Duration::from_millis(50));
    }
    let report = handle.finish(0, Duration::from_secs(2))?;
    let (png, json) = sim::write_outputs(&report, &profile, &a.output, "sim")?;
    println!(
        "received {} bytes, cut {} paths ({:.0} mm), {} overruns, {} flow-control violations",
        report.bytes_received,
        report.paths.len(),
        report.per_tool.values().map(|t| t.length_mm).sum::<f64>() + 0.0,
        report.overruns,
        report.flow_violations
    );
    println!("picture: {}\nreport: {}", png.display(), json.display());
    Ok(())
}

/// The printed sheet `--sheet-offset` and `--sheet-size` load, if either is given.
fn printed(
    a: &SimArgs,
    profile: &crate::profile::Profile,
) -> Result<Option<crate::device::sim::sensor::PrintedSheet>, Error> {
    if a.sheet_offset.is_none() && a.sheet_size.is_none() {
        return Ok(None);
    }
    let placement = a
        .sheet_offset
        .as_deref()
        .map(|s| super::printcut::parse_placement("--sheet-offset", s))
        .transpose()?
        .unwrap_or_default();
    let (w, h) = match a.sheet_size.as_deref() {
        None => (210.0, 297.0),
        Some(t) => {
            let v: Option<Vec<f64>> = t
                .split(',')
                .map(|x| {
                    x.trim()
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite() && *v > 0.0)
                })
                .collect();
            match v.as_deref() {
                Some([w, h]) => (*w, *h),
                _ => {
                    return Err(Error::Usage(format!(
                        "--sheet-size {t}: expected W,H in mm, e.g. 210,297"
                    )))
                }
            }
        }
    };
    let marks = crate::toolpath::registration::layout(w, h, &profile.registration)
        .map_err(|e| Error::Usage(format!("--sheet-size {w},{h}: {e}")))?;
    Ok(Some(crate::device::sim::sensor::PrintedSheet {
        marks,
        placement,
    }))
}
