//! Print-and-cut on the command line (issue 25 item 4): the flags (`--print-and-cut`,
//! `--marks`, `--mark-inset`, `--square-corner`, `--sheet-offset`) and the send after the files
//! are written: measure each sheet's marks, fit, refuse or make the registered program
//! (`<name>-registered.plt`, per sheet `<name>-registered-<k>.plt`), record the registration
//! in report.json, and stream the program.
//!
//! Where the marks' positions come from: `--marks X1,Y1:X2,Y2:X3,Y3[:X4,Y4]` (machine mm, read
//! off the machine after jogging to each mark: mark 1 the square, then the Ls
//! counter-clockwise; one sheet per run), or `--jog` (the head goes to each mark where it was
//! printed and the arrow keys move it onto the mark: HP-GL `PU` moves, GRBL `$J=` jogs; Enter
//! takes it; see [`Keys`]), else the device's sensor (`[registration] sensor`:
//! HP-GL digitizing, which the simulated cutter has, or GRBL `G38.3` probing; see
//! `device::register`). A device with neither is an error that says how to measure. On a
//! real port the marks are measured, the port closed, and the registered program sent as any
//! program (checked, journalled for `flatcut resume`). On the simulator the printed sheet is placed with `--sheet-offset
//! DX,DY,DEG[,SX[,SY]]` (mm, degrees counter-clockwise about the machine's origin, scale along
//! X and Y; default 0,0,0) and the sensor finds its marks. With `--dry-run` nothing is
//! measured or sent: the files (the PDF to print, the nominal program) are written and the
//! steps are printed. Every refusal comes before the first byte of a cut; report.json keeps
//! the registration of the sheets that were measured.

use super::link::{self, LinkArgs};
use crate::device::register::{Key, ProbeMark, RegisterError};
use crate::device::serial::Link;
use crate::device::sim::sensor::{PrintedSheet, SheetPlacement};
use crate::device::sim::SimConfig;
use crate::pipeline::printcut::{self, PrintCut, Registered};
use crate::pipeline::{Before, CutRun};
use crate::profile::registration::{Corner, Sensor};
use crate::profile::{Language, Profile};
use crate::toolpath::registration::MarkKind;
use crate::Error;
use clap::Args;
use glam::DVec2;

#[derive(Debug, Clone, Default, Args)]
pub struct PrintCutArgs {
    /// Print-and-cut: registration marks on each sheet, everything drawn (labels, ids, folds)
    /// in the PDF to print, only the cut (and score) sent, after the marks are found on the
    /// machine (its sensor, or --marks).
    #[arg(long)]
    pub print_and_cut: bool,
    /// The marks' positions on the machine, mm in its own axes, read off it after jogging to
    /// each mark: `X1,Y1:X2,Y2:X3,Y3[:X4,Y4]`, mark 1 the square, then the Ls
    /// counter-clockwise.
    #[arg(long, value_name = "X1,Y1:X2,Y2:X3,Y3")]
    pub marks: Option<String>,
    /// Registration marks this far in from the sheet's edges, mm (overrides the profile's
    /// `[registration] inset`).
    #[arg(long, value_name = "MM")]
    pub mark_inset: Option<f64>,
    /// The corner of the square mark (overrides the profile's).
    #[arg(long, value_enum)]
    pub square_corner: Option<Corner>,
    /// Measure the marks by jogging the head onto each with the arrow keys (`+`/`-` change
    /// the step: 0.1, 1, 10 mm), Enter takes it, `q` stops; the same keys can be piped in.
    #[arg(long, conflicts_with = "marks")]
    pub jog: bool,
    /// Simulator: the printed sheet lies DX, DY mm off and turned DEG degrees
    /// (counter-clockwise about the origin), printed SX (and SY) times true size.
    #[arg(long, value_name = "DX,DY,DEG[,SX[,SY]]", allow_hyphen_values = true)]
    pub sheet_offset: Option<String>,
}

impl PrintCutArgs {
    /// Check the flags before any work, and put the mark flags into the job's profile.
    pub fn apply(&self, profile: &mut Profile) -> Result<(), Error> {
        let used = self.marks.is_some()
            || self.jog
            || self.mark_inset.is_some()
            || self.square_corner.is_some()
            || self.sheet_offset.is_some();
        if used && !self.print_and_cut {
            return Err(Error::Usage(
                "--marks, --jog, --mark-inset, --square-corner and --sheet-offset are for print-and-cut: add --print-and-cut".into(),
            ));
        }
        if let Some(v) = self.mark_inset {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::Usage(format!(
                    "--mark-inset must be 0 or a distance in mm, got {v}"
                )));
            }
            profile.registration.inset = v;
        }
        if let Some(c) = self.square_corner {
            profile.registration.square_corner = c;
        }
        if let Some(m) = &self.marks {
            parse_marks(m)?;
        }
        if let Some(s) = &self.sheet_offset {
            parse_placement("--sheet-offset", s)?;
        }
        Ok(())
    }
}

/// `--marks X1,Y1:X2,Y2:…`: the points, mm.
pub fn parse_marks(text: &str) -> Result<Vec<DVec2>, Error> {
    let bad = |why: String| Error::Usage(format!("--marks {text}: {why}"));
    let mut out = Vec::new();
    for (k, part) in text.split(':').enumerate() {
        let v: Vec<&str> = part.split(',').map(str::trim).collect();
        let num = |t: &str| t.parse::<f64>().ok().filter(|v| v.is_finite());
        match v.as_slice() {
            [x, y] => match (num(x), num(y)) {
                (Some(x), Some(y)) => out.push(DVec2::new(x, y)),
                _ => {
                    return Err(bad(format!(
                        "mark {}: `{part}` is not two numbers X,Y (mm)",
                        k + 1
                    )))
                }
            },
            _ => {
                return Err(bad(format!(
                    "mark {}: `{part}` is not X,Y; marks are separated by `:`",
                    k + 1
                )))
            }
        }
    }
    if out.len() < 3 {
        return Err(bad(format!(
            "{} marks given; the fit needs at least 3",
            out.len()
        )));
    }
    Ok(out)
}

/// `DX,DY,DEG[,SX[,SY]]` of `flag`.
pub fn parse_placement(flag: &str, text: &str) -> Result<SheetPlacement, Error> {
    let v: Option<Vec<f64>> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect();
    let bad = || {
        Error::Usage(format!(
            "{flag} {text}: expected DX,DY,DEG (mm, mm, degrees), optionally ,SX or ,SX,SY (scale, e.g. 1.03)"
        ))
    };
    let v = v.ok_or_else(bad)?;
    let (sx, sy) = match v.len() {
        3 => (1.0, 1.0),
        4 => (v[3], v[3]),
        5 => (v[3], v[4]),
        _ => return Err(bad()),
    };
    if !(sx > 0.0 && sy > 0.0) {
        return Err(bad());
    }
    Ok(SheetPlacement {
        offset: DVec2::new(v[0], v[1]),
        angle_deg: v[2],
        scale: DVec2::new(sx, sy),
    })
}

fn sheet_name(name: &str, i: usize, n: usize, ext: &str) -> String {
    if n == 1 {
        format!("{name}-registered.{ext}")
    } else {
        format!("{name}-registered-{}.{ext}", i + 1)
    }
}

/// report.json with the registration of the sheets `done`.
fn record(run: &CutRun, pc: &PrintCut, profile: &Profile, done: &[Registered]) {
    let path = run.dir.join("report.json");
    let Ok(text) = std::fs::read_to_string(&path) else {
        return;
    };
    let Ok(mut v) = serde_json::from_str::<serde_json::Value>(&text) else {
        return;
    };
    v["registration"] = printcut::report(pc, profile, done);
    let text = serde_json::to_string_pretty(&v).unwrap_or_default() + "\n";
    if let Err(e) = crate::pipeline::write_atomic(&path, text.as_bytes()) {
        eprintln!("flatcut: warning: {e}");
    }
}

fn say_fit(reg: &Registered) -> String {
    let t = &reg.fit.transform;
    format!(
        "sheet {}: marks found by {}: sheet at ({:.3}, {:.3}) mm, turned {:.3}°, scale {:.5}; residual {:.3} mm RMS, {:.3} mm max (mark {})",
        reg.sheet + 1,
        reg.source,
        t.translation.x,
        t.translation.y,
        t.angle.to_degrees(),
        t.scale,
        reg.fit.rms,
        reg.fit.max,
        reg.fit.worst + 1
    )
}

/// Measure, fit and send each chosen sheet of a print-and-cut run (see the module docs).
pub fn deliver(
    run: &CutRun,
    profile: &Profile,
    link: &LinkArgs,
    args: &PrintCutArgs,
    quiet: bool,
    dry_run: bool,
) -> Result<(), Error> {
    let Some(pc) = &run.print_cut else {
        return link::deliver_run(run, profile, link, quiet, dry_run);
    };
    let pdf = format!("{}.pdf", run.job.name);
    if dry_run {
        if let Err(e) = link::check_media(profile, &pc.cutter) {
            eprintln!("flatcut: warning: {e}");
        }
        say(quiet, format!(
            "print-and-cut, dry run: nothing measured or sent. Print {} at 100 % (marks included), load the sheet with its lower-left corner at the machine's origin, then run again without --dry-run{}",
            run.dir.join(&pdf).display(),
            if profile.registration.sensor == Sensor::None {
                " and with --marks (jog to each mark, read its position)"
            } else {
                ""
            }
        ));
        return Ok(());
    }
    link::check_media(profile, &pc.cutter)?;
    let sim = link::simulated(profile, link);
    if args.sheet_offset.is_some() && !sim {
        return Err(Error::Usage(
            "--sheet-offset places the printed sheet on the simulated cutter: add --simulate"
                .into(),
        ));
    }
    let n = pc.marks.len();
    let chosen = link::chosen_sheets(link.sheets.as_deref(), n)?;
    let given = args.marks.as_deref().map(parse_marks).transpose()?;
    if given.is_some() && chosen.len() > 1 {
        return Err(Error::Usage(format!(
            "--marks: the job has {n} sheets, each with its own marks; measure and send one at a time with --sheets K --marks …"
        )));
    }
    if given.is_none() && !args.jog && profile.registration.sensor == Sensor::None {
        return Err(Error::Usage(format!(
            "device `{}` has no registration sensor ([registration] sensor = \"none\", {}): jog to each printed mark and give the positions the machine shows with --marks X1,Y1:X2,Y2:X3,Y3[:X4,Y4] (mm; mark 1 the square, then the Ls counter-clockwise); {pdf} is written",
            profile.name, profile.source
        )));
    }
    let speaks = match profile.registration.sensor {
        Sensor::HpglDigitize => Language::Hpgl,
        Sensor::GrblProbe => Language::Gcode,
        Sensor::None => profile.language,
    };
    if given.is_none() && !args.jog && profile.language != speaks {
        return Err(Error::Usage(format!(
            "device `{}`: its sensor ({}) is driven in {}, and the device speaks {} ([registration] sensor, {}); give the marks with --marks",
            profile.name,
            profile.registration.sensor.name(),
            speaks.label(),
            profile.language.label(),
            profile.source
        )));
    }
    let placement = args
        .sheet_offset
        .as_deref()
        .map(|s| parse_placement("--sheet-offset", s))
        .transpose()?
        .unwrap_or_default();
    let ext = profile.language.extension();
    let mut done: Vec<Registered> = Vec::new();
    let opts = link::stream_options(link, quiet)?;
    let mut keys = args.jog.then(Keys::open);
    for (t, &k) in chosen.iter().enumerate() {
        let name = sheet_name(&run.job.name, k - 1, n, ext);
        if t > 0 && !sim {
            let left: Vec<String> = chosen[t..]
                .iter()
                .map(|k| sheet_name(&run.job.name, k - 1, n, ext))
                .collect();
            link::wait_for_operator(&format!("load printed sheet {k} of {n}"), &left, &opts)?;
        }
        let one = One {
            run,
            pc,
            profile,
            link,
            opts: &opts,
            quiet,
            i: k - 1,
            n,
            path: run.dir.join(&name),
            name,
        };
        match &given {
            Some(measured) => one.by_hand(measured, &mut done)?,
            None => one.by_sensor(placement, sim, keys.as_mut(), &mut done)?,
        }
    }
    Ok(())
}

fn say(quiet: bool, s: String) {
    if !quiet {
        println!("{s}");
    }
}

/// One sheet of a print-and-cut send.
struct One<'a> {
    run: &'a CutRun,
    pc: &'a PrintCut,
    profile: &'a Profile,
    link: &'a LinkArgs,
    opts: &'a crate::device::stream::StreamOptions,
    quiet: bool,
    /// The sheet, 0-based, of `n`.
    i: usize,
    n: usize,
    /// The registered program's file name and path.
    name: String,
    path: std::path::PathBuf,
}

impl One<'_> {
    /// Fit `measured` (machine mm), refuse or make and write the program.
    fn prepare(&self, measured: &[DVec2], source: &str) -> Result<(Registered, Vec<u8>), Error> {
        let reg = printcut::register(self.pc, self.i, measured, self.profile, source)?;
        let bytes = printcut::registered_program(self.pc, &reg, self.profile)?;
        crate::pipeline::write_atomic(&self.path, &bytes)?;
        Ok((reg, bytes))
    }

    /// Keep a fit (printed, in report.json).
    fn keep(&self, reg: Option<Registered>, done: &mut Vec<Registered>) {
        if let Some(reg) = reg {
            say(self.quiet, say_fit(&reg));
            done.push(reg);
        }
        record(self.run, self.pc, self.profile, done);
    }

    /// `--marks`: fit, then send as any program.
    fn by_hand(&self, measured: &[DVec2], done: &mut Vec<Registered>) -> Result<(), Error> {
        let prepared = self.prepare(measured, "--marks");
        let (reg, bytes) = match prepared {
            Ok((reg, bytes)) => (Some(reg), Ok(bytes)),
            Err(e) => (None, Err(e)),
        };
        self.keep(reg, done);
        self.send(bytes?)
    }

    /// The registered program sent as any program of a run (`link::deliver`: checked,
    /// journalled for `flatcut resume`).
    fn send(&self, bytes: Vec<u8>) -> Result<(), Error> {
        let one = LinkArgs {
            sheets: None,
            ..self.link.clone()
        };
        link::deliver_and_print(
            &[(self.name.clone(), bytes)],
            std::slice::from_ref(&self.path),
            &[Before::Start],
            self.profile,
            &one,
            &self.run.dir,
            self.quiet,
        )
    }

    /// The device's sensor finds the marks (on the simulator, the printed sheet placed by
    /// `placement`), then the program goes out on the same line.
    fn by_sensor(
        &self,
        placement: SheetPlacement,
        sim: bool,
        keys: Option<&mut Keys>,
        done: &mut Vec<Registered>,
    ) -> Result<(), Error> {
        let (profile, link) = (self.profile, self.link);
        let marks = &self.pc.marks[self.i];
        let upm = profile.units_per_mm;
        let sensor_name = match keys {
            Some(_) => "--jog".to_string(),
            None => format!("the sensor of `{}`", profile.name),
        };
        let measure: Box<Measure<'_>> = match keys {
            Some(keys) => Box::new(jogger(profile, marks, self.opts, keys)),
            None => Box::new(measurer(profile, marks, self.opts)),
        };
        let mut reg_out = None;
        let mut fit_and_make = |m: &[DVec2]| -> Result<Vec<u8>, Error> {
            let mm: Vec<DVec2> = m.iter().map(|p| *p / upm).collect();
            let (reg, bytes) = self.prepare(&mm, &sensor_name)?;
            reg_out = Some(reg);
            Ok(bytes)
        };
        if !sim {
            let Some(port) = link.port.as_deref() else {
                return Err(Error::Usage(format!(
                    "device `{}` is a real machine: give its serial port with --port",
                    profile.name
                )));
            };
            let mut line = crate::device::serial::open(profile, port, link.baud)?;
            let measured = measure(&mut line)?;
            drop(line);
            let bytes = fit_and_make(&measured);
            self.keep(reg_out.take(), done);
            // Sent as any program (checked, journalled for `flatcut resume`), the port opened
            // again: the machine keeps its place and the sheet.
            return self.send(bytes?);
        }
        let mut cfg = SimConfig::new(profile.clone());
        if let Some(b) = link.baud {
            cfg.profile.serial.baud = b;
        }
        cfg.time_factor = (link.sim_speed > 0.0).then_some(link.sim_speed);
        cfg.printed = Some(PrintedSheet {
            marks: marks.clone(),
            placement,
        });
        let (outcome, report) = crate::device::register::sim_job(
            cfg,
            self.opts,
            link::SIM_FINISH_CAP,
            measure,
            fit_and_make,
        )?;
        let stem = if self.n > 1 {
            format!("sim-{}", self.i + 1)
        } else {
            "sim".into()
        };
        let (png, json) =
            crate::device::sim::write_outputs(&report, profile, &self.run.dir, &stem)?;
        self.keep(reg_out.take(), done);
        let rep = outcome??;
        say(
            self.quiet,
            format!(
                "sent {} to the simulated {} ({} bytes, {} strokes, {:.1} s)",
                self.name, profile.name, rep.bytes, rep.strokes, rep.seconds
            ),
        );
        if report.violations() > 0 {
            return Err(Error::Usage(format!(
                "the simulated {} lost data: {} bytes overran its buffer (see {})",
                profile.name,
                report.violations(),
                json.display()
            )));
        }
        say(
            self.quiet,
            format!(
                "the simulated {} cut {} paths, {:.0} mm; picture {} (report {})",
                profile.name,
                report.paths.len(),
                report.per_tool.values().map(|t| t.length_mm).sum::<f64>() + 0.0,
                png.display(),
                json.display()
            ),
        );
        Ok(())
    }
}

/// How the device's sensor measures `marks`: the measured reference points, device units.
fn measurer<'a>(
    profile: &'a Profile,
    marks: &'a crate::toolpath::registration::Marks,
    opts: &'a crate::device::stream::StreamOptions,
) -> impl FnOnce(&mut crate::device::serial::Link) -> Result<Vec<DVec2>, RegisterError> + 'a {
    let (w, h) = (marks.width, marks.height);
    let dev = move |p: DVec2| crate::output::to_device(profile, w, h, p);
    let r = &profile.registration;
    move |line| match r.sensor {
        Sensor::GrblProbe => {
            let upm = profile.units_per_mm;
            let probe: Vec<ProbeMark> = marks
                .marks
                .iter()
                .map(|m| {
                    let p = m.reference;
                    let inward = DVec2::new((w / 2.0 - p.x).signum(), (h / 2.0 - p.y).signum());
                    let along = |d: DVec2| ((dev(p + d) - dev(p)) / upm).normalize_or_zero();
                    ProbeMark {
                        at: dev(p) / upm,
                        u: along(DVec2::new(inward.x, 0.0)),
                        v: along(DVec2::new(0.0, inward.y)),
                        square: (m.kind == MarkKind::Square).then_some(r.square),
                    }
                })
                .collect();
            let z_up = profile
                .tool(crate::profile::StrokeKind::Cut)
                .and_then(|t| t.z_up);
            crate::device::register::probe_grbl(line, &probe, z_up, r.search, opts)
                .map(|v| v.into_iter().map(|p| p * upm).collect())
        }
        _ => {
            let nominal: Vec<DVec2> = marks.references().into_iter().map(dev).collect();
            crate::device::register::digitize(line, &nominal, profile.units_per_mm, r.search, opts)
        }
    }
}

/// How the marks of one sheet are measured on an open line: the positions, device units.
type Measure<'a> = dyn FnOnce(&mut Link) -> Result<Vec<DVec2>, RegisterError> + 'a;

/// Measuring by hand with [`Keys`] (`--jog`): the positions taken, device units.
fn jogger<'a>(
    profile: &'a Profile,
    marks: &'a crate::toolpath::registration::Marks,
    opts: &'a crate::device::stream::StreamOptions,
    keys: &'a mut Keys,
) -> impl FnOnce(&mut Link) -> Result<Vec<DVec2>, RegisterError> + 'a {
    let upm = profile.units_per_mm;
    let (w, h) = (marks.width, marks.height);
    let nominal: Vec<DVec2> = marks
        .references()
        .into_iter()
        .map(|p| crate::output::to_device(profile, w, h, p) / upm)
        .collect();
    let z_up = profile
        .tool(crate::profile::StrokeKind::Cut)
        .and_then(|t| t.z_up);
    let tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let mut said = 0;
    move |line| {
        crate::device::register::jog(
            line,
            profile.language,
            upm,
            z_up,
            &nominal,
            opts,
            |mark, p, step| {
                let m = &marks.marks[mark - 1];
                // On a terminal a status line; otherwise one line per mark.
                if !tty && said == mark {
                    return keys.next();
                }
                said = mark;
                eprint!(
                    "\rflatcut: mark {mark} ({} {}): head at ({:.2}, {:.2}) mm, step {step} mm; arrows move, +/- step, Enter takes it, q stops   ",
                    m.corner,
                    if m.kind == MarkKind::Square { "square's centre" } else { "L's corner" },
                    p.x,
                    p.y
                );
                if !tty {
                    eprintln!();
                }
                let k = keys.next();
                if tty && matches!(k, Key::Take | Key::Quit) {
                    eprintln!();
                }
                k
            },
        )
    }
}

/// Keys from standard input (`--jog`): on a terminal it is put in non-canonical mode without
/// echo (`stty -icanon -echo`, restored when done); piped bytes are read the same way. Arrows
/// (`ESC [ A`…`D`) move, `+`/`=` and `-` change the step, Enter takes, `q`, Ctrl-C or the end
/// of the input stop.
pub struct Keys {
    restore: Option<String>,
}

impl Keys {
    fn open() -> Keys {
        use std::io::IsTerminal;
        use std::process::{Command, Stdio};
        let mut restore = None;
        if std::io::stdin().is_terminal() {
            let saved = Command::new("stty")
                .arg("-g")
                .stdin(Stdio::inherit())
                .output()
                .ok()
                .filter(|o| o.status.success())
                .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
            let raw = Command::new("stty")
                .args(["-icanon", "-echo", "min", "1"])
                .stdin(Stdio::inherit())
                .status()
                .is_ok_and(|s| s.success());
            if raw {
                restore = saved;
            }
        }
        Keys { restore }
    }

    fn byte(&mut self) -> Option<u8> {
        use std::io::Read;
        let mut b = [0u8; 1];
        match std::io::stdin().lock().read(&mut b) {
            Ok(1) => Some(b[0]),
            _ => None,
        }
    }

    fn next(&mut self) -> Key {
        loop {
            let Some(b) = self.byte() else {
                return Key::Quit;
            };
            let k = match b {
                0x1b => {
                    if self.byte() != Some(b'[') {
                        continue;
                    }
                    match self.byte() {
                        Some(b'A') => Key::Up,
                        Some(b'B') => Key::Down,
                        Some(b'C') => Key::Right,
                        Some(b'D') => Key::Left,
                        Some(_) => continue,
                        None => return Key::Quit,
                    }
                }
                b'+' | b'=' => Key::Coarser,
                b'-' => Key::Finer,
                b'\r' | b'\n' => Key::Take,
                b'q' | b'Q' | 0x03 | 0x04 => Key::Quit,
                _ => continue,
            };
            return k;
        }
    }
}

impl Drop for Keys {
    fn drop(&mut self) {
        if let Some(saved) = &self.restore {
            let _ = std::process::Command::new("stty")
                .arg(saved)
                .stdin(std::process::Stdio::inherit())
                .status();
        }
    }
}
