//! What the subcommands that talk to a machine share: the link flags (`--port`, `--baud`,
//! `--simulate`, `--sim-speed`, `--timeout`), Ctrl-C, and streaming one or more programs to a
//! real port or to a simulated cutter started for the job.
//!
//! The default device `sim` is always simulated. Any other device is simulated with
//! `--simulate`, and otherwise needs `--port`. With the simulator, its picture and report are
//! written beside the program (`sim.png`, `sim.json`; `sim-<k>.*` per sheet when there are
//! several) and their paths printed.

use crate::device::sim::{self, SimConfig};
use crate::device::stream::{self, StreamOptions};
use crate::profile::Profile;
use crate::Error;
use clap::Args;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

#[derive(Debug, Clone, Args)]
pub struct LinkArgs {
    /// Serial port of the machine (e.g. /dev/ttyUSB0); see `flatcut ports`.
    #[arg(long)]
    pub port: Option<String>,
    /// Baud rate (overrides the device profile), 50 to 4000000.
    #[arg(long, value_parser = clap::value_parser!(u32).range(50..=4_000_000))]
    pub baud: Option<u32>,
    /// Send to a simulated cutter that behaves like the device instead of a real port.
    #[arg(long)]
    pub simulate: bool,
    /// Simulated cutter: run motion this many times faster than the machine (0: no motion
    /// time at all).
    #[arg(long, default_value_t = 10.0)]
    pub sim_speed: f64,
    /// Give up when the machine makes no progress for this many seconds.
    #[arg(long, default_value_t = 60.0)]
    pub timeout: f64,
}

/// Longest a simulated machine may work off its buffer after the last byte while it makes
/// progress (a job of a day at the simulated speed).
const SIM_FINISH_CAP: Duration = Duration::from_secs(24 * 3600);

/// The process-wide Ctrl-C flag; the handler is installed on first use.
pub fn cancel_flag() -> Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| {
        let f = Arc::new(AtomicBool::new(false));
        let g = f.clone();
        // If a handler cannot be installed, Ctrl-C ends the process the usual way.
        let _ = ctrlc::set_handler(move || g.store(true, Ordering::SeqCst));
        f
    })
    .clone()
}

/// Whether this run goes to a simulated cutter (the bundled simulator profiles, `sim` and
/// `sim-dragknife`, go there unless a port is given).
pub fn simulated(profile: &Profile, link: &LinkArgs) -> bool {
    link.simulate
        || (matches!(profile.name.as_str(), "sim" | "sim-dragknife") && link.port.is_none())
}

/// A real machine needs a port unless nothing is sent: refuse before any work is done.
pub fn need_port(profile: &Profile, link: &LinkArgs, dry_run: bool) -> Result<(), Error> {
    if !dry_run && !simulated(profile, link) && link.port.is_none() {
        return Err(Error::Usage(format!(
            "device `{}` is a real machine: give its serial port with --port (see `flatcut ports`), or use --simulate or --dry-run",
            profile.name
        )));
    }
    Ok(())
}

/// [`deliver`], printing what it says unless `quiet`.
pub fn deliver_and_print(
    programs: &[(String, Vec<u8>)],
    profile: &Profile,
    link: &LinkArgs,
    dir: &Path,
    quiet: bool,
) -> Result<(), Error> {
    for line in deliver(programs, profile, link, dir, quiet)? {
        if !quiet {
            println!("{line}");
        }
    }
    Ok(())
}

/// Send each program (name, bytes) in turn; returns the lines to print.
pub fn deliver(
    programs: &[(String, Vec<u8>)],
    profile: &Profile,
    link: &LinkArgs,
    dir: &Path,
    quiet: bool,
) -> Result<Vec<String>, Error> {
    if !(link.timeout.is_finite() && link.timeout > 0.0) {
        return Err(Error::Usage(format!(
            "--timeout must be a positive number of seconds, got {}",
            link.timeout
        )));
    }
    if !(link.sim_speed.is_finite() && link.sim_speed >= 0.0) {
        return Err(Error::Usage(format!(
            "--sim-speed must be 0 or a positive factor, got {}",
            link.sim_speed
        )));
    }
    let opts = StreamOptions {
        timeout: Duration::from_secs_f64(link.timeout),
        progress: !quiet,
        cancel: cancel_flag(),
        ..StreamOptions::default()
    };
    let mut said = Vec::new();
    let several = programs.len() > 1;
    // Every program is checked before the first byte of the first one goes out.
    let mut checked = Vec::with_capacity(programs.len());
    for (name, bytes) in programs {
        if profile.language != crate::profile::Language::Hpgl {
            checked.push(bytes.clone());
            continue;
        }
        let c = crate::device::check::check_hpgl(bytes, profile)
            .map_err(|e| Error::Usage(format!("{name}: {e}")))?;
        if !quiet {
            for w in &c.warnings {
                eprintln!("flatcut: warning: {name}: {w}");
            }
        }
        checked.push(c.bytes);
    }
    for (k, ((name, _), bytes)) in programs.iter().zip(&checked).enumerate() {
        if simulated(profile, link) {
            let mut cfg = SimConfig::new(profile.clone());
            // The simulated line runs at the rate the host uses.
            if let Some(b) = link.baud {
                cfg.profile.serial.baud = b;
            }
            cfg.time_factor = (link.sim_speed > 0.0).then_some(link.sim_speed);
            // The simulated machine works off what it has buffered, as a real one would (after
            // Ctrl-C that includes the tool-up command, queued behind the buffer), for as long
            // as it makes progress: `--timeout` without progress, or Ctrl-C, ends the wait.
            let (sent, report) = stream::stream_job(cfg, bytes, &opts, SIM_FINISH_CAP)?;
            let stem = if several {
                format!("sim-{}", k + 1)
            } else {
                "sim".into()
            };
            let (png, json) = sim::write_outputs(&report, profile, dir, &stem)?;
            let rep = sent?;
            if report.violations() > 0 {
                return Err(Error::Usage(format!(
                    "the simulated {} lost data: {} bytes overran its {}-byte buffer and {} were sent while it asked to stop (see {}); a real machine would have cut this job wrong",
                    profile.name,
                    report.overruns,
                    report.buffer,
                    report.flow_violations,
                    json.display()
                )));
            }
            said.push(format!(
                "sent {name} to the simulated {} ({} bytes, {} strokes, {:.1} s at {} baud); it cut {} paths, {:.0} mm, {} overruns",
                profile.name,
                rep.bytes,
                rep.strokes,
                rep.seconds,
                report.baud,
                report.paths.len(),
                report.per_tool.values().map(|t| t.length_mm).sum::<f64>() + 0.0,
                report.violations(),
            ));
            said.push(format!(
                "picture of the cut: {} (report {})",
                png.display(),
                json.display()
            ));
        } else {
            let Some(path) = link.port.as_deref() else {
                return Err(Error::Usage(format!(
                    "device `{}` is a real machine: give its serial port with --port (see `flatcut ports`), or use --simulate or --dry-run",
                    profile.name
                )));
            };
            if several && k > 0 {
                wait_for_sheet(k + 1, programs.len(), quiet);
            }
            let mut port = crate::device::serial::open(profile, path, link.baud)?;
            let rep = stream::send(&mut port, profile, bytes, &opts)?;
            said.push(format!(
                "sent {name} to {} on {path}: {} bytes, {} strokes in {:.1} s ({:.0} bytes/s)",
                profile.name, rep.bytes, rep.strokes, rep.seconds, rep.rate
            ));
        }
    }
    Ok(said)
}

/// Before sheet k of n on a real machine: ask for the sheet when someone is there to load it.
fn wait_for_sheet(k: usize, n: usize, quiet: bool) {
    use std::io::IsTerminal;
    if quiet || !std::io::stdin().is_terminal() {
        return;
    }
    eprintln!("load sheet {k} of {n} and press Enter");
    let mut s = String::new();
    let _ = std::io::stdin().read_line(&mut s);
}
