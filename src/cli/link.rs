//! What the subcommands that talk to a machine share: the link flags (`--port`, `--baud`,
//! `--simulate`, `--sim-speed`, `--timeout`), Ctrl-C, and streaming one or more programs to a
//! real port or to a simulated cutter started for the job.
//!
//! The default device `sim` is always simulated. Any other device is simulated with
//! `--simulate`, and otherwise needs `--port`. With the simulator, its picture and report are
//! written beside the program (`sim.png`, `sim.json`; `sim-<k>.*` per sheet when there are
//! several) and their paths printed.
//!
//! **Pauses.** On a real machine the job stops with the tool up (every program ends with it
//! lifted) before each sheet after the first, and before the knife pass of a tool change
//! (`--tool-change`), and waits for the operator: on a terminal for Enter; when standard input
//! is not a terminal, for a line on it (a script or a FIFO writes `\n` when the sheet is
//! loaded; `-q` does not skip the wait). If standard input is closed (end of file) the job
//! stops there with a message naming what is left, which `--sheets` sends later. Two sheets
//! are never sent back to back. Ctrl-C during a wait stops the job. The simulator needs no
//! operator: each sheet goes to a simulated machine of its own, the passes of a tool change to
//! the same one.
//!
//! **Media.** Before the first byte, a job wider than the profile's `media_width` (the largest
//! x of its strokes, across the media) or longer than its `media_length` (the largest y, along
//! the media) is refused, naming both sizes; `send` checks a program file alike.

use crate::device::journal::{self, Journal};
use crate::device::sim::{self, SimConfig};
use crate::device::stream::{self, StreamOptions};
use crate::pipeline::{Before, CutRun};
use crate::profile::Profile;
use crate::Error;
use clap::Args;
use std::path::{Path, PathBuf};
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
    /// Send only these sheets (1-based: `2`, `1,3`, `2-4`); every sheet's files are written.
    /// Between sheets flatcut waits for Enter, or a line on standard input when it is not a
    /// terminal.
    #[arg(long, value_name = "LIST")]
    pub sheets: Option<String>,
}

/// Longest a simulated machine may work off its buffer after the last byte while it makes
/// progress (a job of a day at the simulated speed).
pub(crate) const SIM_FINISH_CAP: Duration = Duration::from_secs(24 * 3600);

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

/// `cut` and `fitting`: refuse a job wider than the device's media before the first byte, then
/// [`deliver_and_print`] the run's programs with their pauses. A dry run sends nothing and
/// only warns of a job the device would refuse.
pub fn deliver_run(
    run: &CutRun,
    profile: &Profile,
    link: &LinkArgs,
    quiet: bool,
    dry_run: bool,
) -> Result<(), Error> {
    if dry_run {
        // The files are written and nothing is sent; a job the device would refuse is said
        // now, not when the user sends the files.
        if let Err(e) = check_media(profile, &run.job) {
            eprintln!("flatcut: warning: {e}");
        }
        return Ok(());
    }
    check_media(profile, &run.job)?;
    let sources: Vec<PathBuf> = run.programs.iter().map(|(n, _)| run.dir.join(n)).collect();
    deliver_and_print(
        &run.programs,
        &sources,
        &run.before,
        profile,
        link,
        &run.dir,
        quiet,
    )
}

/// A job whose strokes reach further across the media (sheet x) than the profile's
/// `media_width`, or further along it (sheet y) than its `media_length`, is an error naming
/// both sizes; a size of 0 (unknown, or a roll) passes.
pub fn check_media(profile: &Profile, job: &crate::toolpath::Job) -> Result<(), Error> {
    for (i, sheet) in job.sheets.iter().enumerate() {
        let points = || sheet.strokes.iter().flat_map(|s| &s.points);
        let wide = points().map(|q| q.x).fold(0.0, f64::max);
        let long = points().map(|q| q.y).fold(0.0, f64::max);
        let what = format!("{} sheet {} is {wide:.1} × {long:.1} mm", job.name, i + 1);
        media_fits(
            profile,
            &what,
            wide,
            long,
            "nest it on a smaller sheet or split the piece",
        )?;
    }
    Ok(())
}

/// `what` reaches `wide` mm across the media and `long` mm along it: an error when that is
/// more than the profile's media (a size of 0 is not checked).
fn media_fits(
    profile: &Profile,
    what: &str,
    wide: f64,
    long: f64,
    hint: &str,
) -> Result<(), Error> {
    let over = |reach: f64, size: f64| size.is_finite() && size > 0.0 && reach > size + 1e-6;
    let (name, source) = (&profile.name, &profile.source);
    if over(wide, profile.media_width) {
        return Err(Error::Usage(format!(
            "{what} ({wide:.1} mm across the media), wider than the {:.0} mm media of device `{name}` ({source}): nothing was sent; {hint}",
            profile.media_width
        )));
    }
    if over(long, profile.media_length) {
        return Err(Error::Usage(format!(
            "{what} ({long:.1} mm along the media), longer than the {:.0} mm the device `{name}` can cut ({source}): nothing was sent; {hint}",
            profile.media_length
        )));
    }
    Ok(())
}

/// `send`: a program that reaches further across or along the media than the profile's
/// `media_width` and `media_length` is refused before the first byte, as [`check_media`] does
/// for a job. HP-GL and GP-GL: its tool-down points, in the machine's axes (across the media
/// is the machine's Y when the profile exchanges the axes, else X), their span. G-code: every
/// move, from the work zero (a flatbed's origin corner), which nothing may pass below either.
pub fn check_program_media(profile: &Profile, name: &str, bytes: &[u8]) -> Result<(), Error> {
    use crate::profile::Language;
    let points: Vec<(i64, i64)> = match profile.language {
        Language::Hpgl => crate::output::hpgl::parse(&String::from_utf8_lossy(bytes))
            .map(|v| v.into_iter().flat_map(|s| s.points).collect())
            .unwrap_or_default(),
        Language::Gpgl => crate::output::gpgl::parse(bytes)
            .map(|v| v.into_iter().flat_map(|s| s.points).collect())
            .unwrap_or_default(),
        Language::Gcode => {
            let Some([x0, y0, x1, y1]) = crate::output::gcode_reach(bytes) else {
                return Ok(());
            };
            let (lo_across, lo_along, hi_across, hi_along) = if profile.axes.swap_xy {
                (y0, x0, y1, x1)
            } else {
                (x0, y0, x1, y1)
            };
            let (wide, long) = (hi_across.max(0.0), hi_along.max(0.0));
            let what = format!("{name}: its moves reach {wide:.1} × {long:.1} mm");
            media_fits(
                profile,
                &what,
                wide,
                long,
                "move the work zero or nest it smaller",
            )?;
            let below = lo_across.min(lo_along);
            if below < -1e-6 && (profile.media_width > 0.0 || profile.media_length > 0.0) {
                return Err(Error::Usage(format!(
                    "{name}: its moves go {:.1} mm below the work zero, off the bed of device `{}` ({}): nothing was sent",
                    -below, profile.name, profile.source
                )));
            }
            return Ok(());
        }
    };
    let across = |p: &(i64, i64)| if profile.axes.swap_xy { p.1 } else { p.0 };
    let along = |p: &(i64, i64)| if profile.axes.swap_xy { p.0 } else { p.1 };
    let span = |f: &dyn Fn(&(i64, i64)) -> i64| {
        let (lo, hi) = points
            .iter()
            .map(f)
            .fold((i64::MAX, i64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        (hi >= lo).then(|| (hi - lo) as f64 / profile.units_per_mm)
    };
    let (Some(wide), Some(long)) = (span(&across), span(&along)) else {
        return Ok(());
    };
    let what = format!("{name}: its cuts span {wide:.1} × {long:.1} mm");
    media_fits(profile, &what, wide, long, "nest it on a smaller sheet")
}

/// [`deliver`], printing what it says unless `quiet`.
pub fn deliver_and_print(
    programs: &[(String, Vec<u8>)],
    sources: &[PathBuf],
    before: &[Before],
    profile: &Profile,
    link: &LinkArgs,
    dir: &Path,
    quiet: bool,
) -> Result<(), Error> {
    for line in deliver(programs, sources, before, profile, link, dir, quiet)? {
        if !quiet {
            println!("{line}");
        }
    }
    Ok(())
}

/// The sheet (1-based) of each program, from what comes before it.
fn sheet_of(before: &[Before], count: usize) -> Vec<usize> {
    let mut k = 1;
    (0..count)
        .map(|i| {
            match before.get(i) {
                Some(Before::Sheet { k: s, .. }) | Some(Before::ToolChange { k: s }) => k = *s,
                _ => {}
            }
            k
        })
        .collect()
}

/// The sheets `--sheets` names (1-based), of `n`; all when it is not given.
pub fn chosen_sheets(list: Option<&str>, n: usize) -> Result<Vec<usize>, Error> {
    let Some(list) = list else {
        return Ok((1..=n).collect());
    };
    let bad = |why: String| Error::Usage(format!("--sheets {list}: {why}"));
    let mut out = Vec::new();
    for part in list.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (a, b) = part.split_once('-').unwrap_or((part, part));
        let num = |t: &str| {
            t.trim().parse::<usize>().map_err(|_| {
                bad(format!(
                    "`{part}` is not a sheet number or a range like 2-4"
                ))
            })
        };
        let (a, b) = (num(a)?, num(b)?);
        if a == 0 || a > b || b > n {
            return Err(bad(format!(
                "`{part}`: the job has sheets 1 to {n} (1-based, ranges low-high)"
            )));
        }
        out.extend(a..=b);
    }
    out.sort_unstable();
    out.dedup();
    if out.is_empty() {
        return Err(bad("names no sheet".into()));
    }
    Ok(out)
}

/// Send each program (name, bytes) in turn, pausing as `before` says (see the module
/// documentation); returns the lines to print. `sources` are the programs' files (the journal
/// names them so that `flatcut resume` can read them again).
pub fn deliver(
    programs: &[(String, Vec<u8>)],
    sources: &[PathBuf],
    before: &[Before],
    profile: &Profile,
    link: &LinkArgs,
    dir: &Path,
    quiet: bool,
) -> Result<Vec<String>, Error> {
    let opts = stream_options(link, quiet)?;
    let sheets = sheet_of(before, programs.len());
    let n = sheets.last().copied().unwrap_or(1);
    let chosen = chosen_sheets(link.sheets.as_deref(), n)?;
    // Every program is checked before the first byte of the first one goes out.
    let programs = &checked(programs, profile, quiet)?;
    // What is sent, in order, as streams: one per program to a real machine; to the
    // simulator, one per sheet (the passes of a tool change go into one simulated machine,
    // which changes tools itself).
    let sim = simulated(profile, link);
    let mut streams: Vec<Stream> = Vec::new();
    for (i, &k) in sheets.iter().enumerate() {
        if !chosen.contains(&k) {
            continue;
        }
        let file = sources.get(i).map(|p| absolute(p)).unwrap_or_default();
        match streams.last_mut() {
            Some(s) if sim && s.sheet == k => {
                s.names.push(programs[i].0.clone());
                s.files.push(file);
                s.bytes.extend_from_slice(&programs[i].1);
            }
            _ => streams.push(Stream {
                sheet: k,
                names: vec![programs[i].0.clone()],
                files: vec![file],
                bytes: programs[i].1.clone(),
            }),
        }
    }
    let mut journal = Journal {
        device: profile.name.clone(),
        streams: streams
            .iter()
            .map(|s| journal::Entry {
                sheet: s.sheet,
                files: s.files.clone(),
                bytes: s.bytes.len(),
                hash: journal::hash(&s.bytes),
                strokes: stream::stroke_starts(&s.bytes, profile.language).len(),
                state: journal::State::Pending,
                finished: 0,
                why: String::new(),
            })
            .collect(),
    };
    let todo: Vec<(usize, usize)> = (0..streams.len()).map(|j| (j, 0)).collect();
    send_streams(&streams, &todo, &mut journal, n, profile, link, dir, &opts)
}

/// The stream options from the link flags, checked.
pub fn stream_options(link: &LinkArgs, quiet: bool) -> Result<StreamOptions, Error> {
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
    Ok(StreamOptions {
        timeout: Duration::from_secs_f64(link.timeout),
        progress: !quiet,
        cancel: cancel_flag(),
        ..StreamOptions::default()
    })
}

fn absolute(p: &Path) -> String {
    std::path::absolute(p)
        .unwrap_or_else(|_| p.to_path_buf())
        .display()
        .to_string()
}

/// One stream of a job: a sheet's program, or (to the simulator) the passes of a sheet.
#[derive(Debug, Clone)]
pub struct Stream {
    pub sheet: usize,
    pub names: Vec<String>,
    pub files: Vec<String>,
    pub bytes: Vec<u8>,
}

fn journal_error(e: journal::JournalError) -> Error {
    Error::Usage(e.to_string())
}

/// Send `streams[j]` for each `(j, from)` of `todo`, in order, and keep `journal` (whose entry
/// `j` is stream `j`) up to date in `dir`: `sending` before the first byte, then `done` or
/// `stopped` with the strokes known finished (`from`, the strokes the stream's bytes leave out
/// at its start, added). Between streams a real machine waits for the operator.
#[allow(clippy::too_many_arguments)]
pub fn send_streams(
    streams: &[Stream],
    todo: &[(usize, usize)],
    journal: &mut Journal,
    n: usize,
    profile: &Profile,
    link: &LinkArgs,
    dir: &Path,
    opts: &StreamOptions,
) -> Result<Vec<String>, Error> {
    journal.save(dir).map_err(journal_error)?;
    let mut said = Vec::new();
    for (t, &(j, from)) in todo.iter().enumerate() {
        let s = &streams[j];
        if t > 0 && !simulated(profile, link) {
            let left: Vec<String> = todo[t..]
                .iter()
                .flat_map(|(j, _)| streams[*j].names.clone())
                .collect();
            let what = if streams[todo[t - 1].0].sheet != s.sheet {
                format!("load sheet {} of {n}", s.sheet)
            } else {
                format!(
                    "sheet {}: take the pen out of the holder and put the knife in",
                    s.sheet
                )
            };
            wait_for_operator(&what, &left, opts)?;
        }
        journal.streams[j].state = journal::State::Sending;
        journal.save(dir).map_err(journal_error)?;
        let (result, lines) = if simulated(profile, link) {
            send_simulated(s, n, profile, link, dir, opts)?
        } else {
            send_real(s, profile, link, opts)?
        };
        let entry = &mut journal.streams[j];
        // Whether the program started: an error with no position (a line too long, a setting
        // that does not suit, no answer to the reset) came before its first byte, so there is
        // nothing to resume; the program or the machine needs fixing first.
        let started = match &result {
            Err(Error::Stream(e)) => e.position().is_some(),
            _ => false,
        };
        match &result {
            Ok(()) => {
                entry.state = journal::State::Done;
                entry.finished = entry.strokes;
                entry.why.clear();
            }
            Err(e) => {
                entry.state = journal::State::Stopped;
                let at = match e {
                    Error::Stream(e) => e.position(),
                    _ => None,
                };
                entry.finished = from
                    + at.map_or(0, |p| {
                        journal::finished_strokes(&s.bytes, profile.language, p)
                    });
                entry.why = e.to_string();
            }
        }
        let saved = journal.save(dir);
        said.extend(lines);
        if let Err(e) = result {
            // The error is the job's end; how to go on is said beside it.
            match saved {
                Ok(()) if !started || journal.streams[j].strokes == 0 => {}
                Ok(()) => eprintln!(
                    "flatcut: `flatcut resume {}` goes on from stroke {} of {} of {}",
                    dir.display(),
                    journal.streams[j].finished + 1,
                    journal.streams[j].strokes,
                    s.names.join(" + ")
                ),
                Err(w) => eprintln!("flatcut: warning: {w}"),
            }
            return Err(e);
        }
        saved.map_err(journal_error)?;
    }
    Ok(said)
}

/// One stream to the real machine on `--port`.
fn send_real(
    s: &Stream,
    profile: &Profile,
    link: &LinkArgs,
    opts: &StreamOptions,
) -> Result<(Result<(), Error>, Vec<String>), Error> {
    let Some(path) = link.port.as_deref() else {
        return Err(Error::Usage(format!(
            "device `{}` is a real machine: give its serial port with --port (see `flatcut ports`), or use --simulate or --dry-run",
            profile.name
        )));
    };
    let mut port = crate::device::serial::open(profile, path, link.baud)?;
    match stream::send(&mut port, profile, &s.bytes, opts) {
        Ok(rep) => Ok((
            Ok(()),
            vec![format!(
                "sent {} to {} on {path}: {} bytes, {} strokes in {:.1} s ({:.0} bytes/s)",
                s.names.join(" + "),
                profile.name,
                rep.bytes,
                rep.strokes,
                rep.seconds,
                rep.rate
            )],
        )),
        Err(e) => Ok((Err(e.into()), Vec::new())),
    }
}

/// The programs as they are sent: HP-GL and GP-GL ones checked (`device::check`), with the warnings
/// printed unless `quiet`; a program that cannot be sent is an error naming it.
pub fn checked(
    programs: &[(String, Vec<u8>)],
    profile: &Profile,
    quiet: bool,
) -> Result<Vec<(String, Vec<u8>)>, Error> {
    let mut out = Vec::with_capacity(programs.len());
    for (name, bytes) in programs {
        let c = match profile.language {
            crate::profile::Language::Hpgl => crate::device::check::check_hpgl(bytes, profile)
                .map_err(|e| Error::Usage(format!("{name}: {e}")))?,
            crate::profile::Language::Gpgl => crate::device::check::check_gpgl(bytes, profile),
            crate::profile::Language::Gcode => {
                out.push((name.clone(), bytes.clone()));
                continue;
            }
        };
        if !quiet {
            for w in &c.warnings {
                eprintln!("flatcut: warning: {name}: {w}");
            }
        }
        out.push((name.clone(), c.bytes));
    }
    Ok(out)
}

/// One stream to a simulated machine of its own (see [`deliver`]); no operator is waited for.
fn send_simulated(
    s: &Stream,
    n: usize,
    profile: &Profile,
    link: &LinkArgs,
    dir: &Path,
    opts: &StreamOptions,
) -> Result<(Result<(), Error>, Vec<String>), Error> {
    let k = s.sheet;
    let mut said = Vec::new();
    let mut cfg = SimConfig::new(profile.clone());
    // The simulated line runs at the rate the host uses.
    if let Some(b) = link.baud {
        cfg.profile.serial.baud = b;
    }
    cfg.time_factor = (link.sim_speed > 0.0).then_some(link.sim_speed);
    if s.names.len() > 1 {
        said.push(format!(
            "sheet {k}: tool change (the simulated machine changes tools itself)"
        ));
    }
    // The simulated machine works off what it has buffered, as a real one would (after
    // Ctrl-C that includes the tool-up command, queued behind the buffer), for as long
    // as it makes progress: `--timeout` without progress, or Ctrl-C, ends the wait.
    let (sent, report) = stream::stream_job(cfg, &s.bytes, opts, SIM_FINISH_CAP)?;
    let stem = if n > 1 {
        format!("sim-{k}")
    } else {
        "sim".into()
    };
    let (png, json) = sim::write_outputs(&report, profile, dir, &stem)?;
    let rep = match sent {
        Ok(rep) => rep,
        Err(e) => return Ok((Err(e.into()), said)),
    };
    said.push(format!(
        "sent {} to the simulated {} ({} bytes, {} strokes, {:.1} s at {} baud)",
        s.names.join(" + "),
        profile.name,
        rep.bytes,
        rep.strokes,
        rep.seconds,
        report.baud,
    ));
    if report.violations() > 0 {
        return Ok((
            Err(Error::Usage(format!(
                "the simulated {} lost data: {} bytes overran its {}-byte buffer and {} were sent while it asked to stop (see {}); a real machine would have cut this job wrong",
                profile.name,
                report.overruns,
                report.buffer,
                report.flow_violations,
                json.display()
            ))),
            said,
        ));
    }
    said.push(format!(
        "the simulated {} cut {} paths, {:.0} mm, {} overruns",
        profile.name,
        report.paths.len(),
        report.per_tool.values().map(|t| t.length_mm).sum::<f64>() + 0.0,
        report.violations(),
    ));
    said.push(format!(
        "picture of the cut: {} (report {})",
        png.display(),
        json.display()
    ));
    Ok((Ok(()), said))
}

/// Stop for the operator (`what` to do) before the programs `left` are sent: on a terminal
/// Enter, otherwise a line on standard input; closed input or Ctrl-C stops the job.
pub fn wait_for_operator(what: &str, left: &[String], opts: &StreamOptions) -> Result<(), Error> {
    use std::io::IsTerminal;
    let how = if std::io::stdin().is_terminal() {
        "press Enter"
    } else {
        "send a line to flatcut's standard input"
    };
    eprintln!("flatcut: the tool is up: {what}, then {how} (Ctrl-C stops)");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut s = String::new();
        let _ = tx.send(std::io::stdin().read_line(&mut s).map(|n| n > 0));
    });
    let stopped = |why: &str| {
        Error::Usage(format!(
            "stopped before \"{what}\": {why}; not sent: {} (send them later with --sheets)",
            left.join(", ")
        ))
    };
    loop {
        if opts.cancel.load(Ordering::SeqCst) {
            return Err(stopped("Ctrl-C"));
        }
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(Ok(true)) => return Ok(()),
            Ok(Ok(false)) => {
                return Err(stopped(
                    "standard input is closed, so nothing can say the operator is done",
                ))
            }
            Ok(Err(e)) => return Err(stopped(&format!("cannot read standard input: {e}"))),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(stopped("standard input failed"))
            }
        }
    }
}
