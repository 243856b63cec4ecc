//! Finding a printed sheet's registration marks with the machine's own sensor, before the cut
//! is sent on the same line (print-and-cut, issue 25 item 4).
//!
//! HP-GL digitizing (`[registration] sensor = "hpgl-digitize"`; HP 7475A Interfacing and
//! Programming Manual, ch. 14): for each mark, in order, the host sends `PU x,y;` to where the
//! mark should be (pen up), `DP;` (digitize: the sensor looks for the mark there) and `OS;`,
//! and reads the status byte. Bit 2 (4) set: a point was digitized, and `OD;` answers it as
//! `X,Y,P` in plotter units. Bit 2 clear: no mark was found near that place, an error naming
//! the mark. The marks are measured nearest the machine's origin first (a sheet turned
//! about the origin moves those least), the first where it was printed, the later ones where
//! the marks found so far put them (`predict`); the answers are returned in mark order. The
//! first mark must lie within the sensor's reach of where it was printed. Answers end with a carriage return; XON/XOFF bytes among them are skipped. Before
//! the first mark the host sends `IN;` (the cut program starts with its own `IN;` too).
//!
//! GRBL with a probe-pin sensor (`sensor = "grbl-probe"`, [`probe_grbl`]): after a reset
//! (Ctrl-X, the welcome awaited, `$X` if it asks) and `G21 G90` and the tool lifted (`G0 Z`
//! to the cut tool's `z_up`), each mark's edges are found with `G38.3` moves at 300 mm/min
//! from `search` mm outside to `search` mm inside (GRBL 1.1: `[PRB:x,y,z:1]` at the contact,
//! machine coordinates; `:0` without one, which is a mark not found): an L's outer corner is
//! where its two outer edges meet, each edge through two contacts 8 and 14 mm along the arm;
//! the square's centre is the middle of a chord probed from both sides, along one edge
//! direction, then the other, then the first again. The marks are measured in the same order
//! and from the same predictions as with digitizing.
//!
//! By hand ([`jog`]): the head goes to each mark where it was printed and the user moves it
//! with keys (HP-GL `PU` moves, GRBL `$J=` jog moves) and takes the position.
//!
//! A machine that does not answer within the stream's timeout, a garbled answer, a hang-up or
//! Ctrl-C stop the registration before any cut is sent. [`sim_job`] does the whole loop on the
//! simulated cutter: start it with the printed sheet, measure, let the caller fit and make the
//! program, stream it on the same line ([`super::stream`]).

use super::serial::Link;
use super::sim::{SimConfig, SimError, SimReport};
use super::stream::{StreamError, StreamOptions, StreamReport};
use glam::DVec2;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// Why the marks could not be measured.
#[derive(Debug, thiserror::Error)]
pub enum RegisterError {
    #[error("{port}: no answer to `{asked}` for mark {mark} within {secs:.0} s; is the device on and its registration sensor enabled? (nothing was cut)")]
    NoAnswer {
        port: String,
        asked: String,
        mark: usize,
        secs: f64,
    },
    #[error("{port}: the sensor found no mark {mark} within {search} mm of ({x:.2}, {y:.2}) mm, where it was printed; check that the sheet is loaded with its lower-left corner at the origin, face up, and that the marks printed (nothing was cut)")]
    NotFound {
        port: String,
        mark: usize,
        x: f64,
        y: f64,
        search: f64,
    },
    #[error(
        "{port}: cannot read the answer `{answer}` to `{asked}` for mark {mark} (nothing was cut)"
    )]
    Garbled {
        port: String,
        asked: String,
        answer: String,
        mark: usize,
    },
    #[error("{port}: the line failed while measuring mark {mark}: {message} (nothing was cut)")]
    Line {
        port: String,
        mark: usize,
        message: String,
    },
    #[error("{port}: stopped while measuring the marks (Ctrl-C, `q`, or the end of the input); nothing was cut")]
    Cancelled { port: String },
}

/// Measure each of `nominal` (machine units, where the marks should be) with HP-GL
/// digitizing; returns the digitized points (machine units), in order. `search` (mm) is only
/// for the message of a mark not found; `units_per_mm` converts positions for messages.
pub fn digitize(
    link: &mut Link,
    nominal: &[DVec2],
    units_per_mm: f64,
    search: f64,
    opts: &StreamOptions,
) -> Result<Vec<DVec2>, RegisterError> {
    let port = link.name.clone();
    let line = |mark: usize, e: std::io::Error| RegisterError::Line {
        port: port.clone(),
        mark,
        message: e.to_string(),
    };
    write_all(link, b"IN;", opts).map_err(|e| line(1, e))?;
    // Nearest the machine's origin first: a sheet turned about the origin moves those least.
    let mut order: Vec<usize> = (0..nominal.len()).collect();
    order.sort_by(|a, b| nominal[*a].length().total_cmp(&nominal[*b].length()));
    let mut out = vec![DVec2::ZERO; nominal.len()];
    let (mut seen, mut got) = (Vec::new(), Vec::new());
    for k in order {
        let mark = k + 1;
        let p = &predict(&seen, &got, nominal[k]);
        let (x, y) = (p.x.round() as i64, p.y.round() as i64);
        write_all(link, format!("PU{x},{y};DP;OS;").as_bytes(), opts).map_err(|e| line(mark, e))?;
        let status = answer(link, "OS", mark, opts)?;
        let garbled = |asked: &str, answer: &str| RegisterError::Garbled {
            port: port.clone(),
            asked: asked.into(),
            answer: answer.into(),
            mark,
        };
        let bits: u32 = status.trim().parse().map_err(|_| garbled("OS;", &status))?;
        if bits & 4 == 0 {
            return Err(RegisterError::NotFound {
                port: port.clone(),
                mark,
                x: p.x / units_per_mm,
                y: p.y / units_per_mm,
                search,
            });
        }
        write_all(link, b"OD;", opts).map_err(|e| line(mark, e))?;
        let od = answer(link, "OD", mark, opts)?;
        let v: Vec<f64> = od
            .split(',')
            .map(|t| t.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| garbled("OD;", &od))?;
        match v.as_slice() {
            [x, y, ..] if x.is_finite() && y.is_finite() => {
                out[k] = DVec2::new(*x, *y);
                seen.push(nominal[k]);
                got.push(out[k]);
            }
            _ => return Err(garbled("OD;", &od)),
        }
    }
    Ok(out)
}

/// Where to look for the mark printed at `at`, from the marks found so far (`found`, for
/// `nominal` in order): the first where printed, the second moved as the first was, the rest
/// where the least-squares similarity of those found puts them (as cutters look for the later
/// marks once the first are found, so that a sheet a little off or a print a little scaled
/// still has its marks within the sensor's reach).
fn predict(nominal: &[DVec2], found: &[DVec2], at: DVec2) -> DVec2 {
    match found.len() {
        0 => at,
        1 => at + (found[0] - nominal[0]),
        _ => crate::geom::similarity::fit(nominal, found).map_or(at, |f| f.transform.apply(at)),
    }
}

fn write_all(link: &mut Link, mut bytes: &[u8], opts: &StreamOptions) -> std::io::Result<()> {
    let deadline = Instant::now() + opts.timeout;
    while !bytes.is_empty() {
        let n = link.write_some(bytes)?;
        bytes = &bytes[n..];
        if n == 0 && Instant::now() > deadline {
            return Err(std::io::Error::new(
                std::io::ErrorKind::TimedOut,
                "the device took no data",
            ));
        }
    }
    link.flush()
}

/// One answer line (up to CR or LF), flow-control bytes skipped.
fn answer(
    link: &mut Link,
    asked: &str,
    mark: usize,
    opts: &StreamOptions,
) -> Result<String, RegisterError> {
    let port = link.name.clone();
    let deadline = Instant::now() + opts.timeout;
    let mut got = Vec::new();
    let mut buf = [0u8; 1];
    loop {
        if opts.cancel.load(Ordering::SeqCst) {
            return Err(RegisterError::Cancelled { port });
        }
        if Instant::now() > deadline {
            return Err(RegisterError::NoAnswer {
                port,
                asked: format!("{asked};"),
                mark,
                secs: opts.timeout.as_secs_f64(),
            });
        }
        let n = link.read_some(&mut buf).map_err(|e| RegisterError::Line {
            port: port.clone(),
            mark,
            message: e.to_string(),
        })?;
        if n == 0 {
            continue;
        }
        match buf[0] {
            b'\r' | b'\n' if got.is_empty() => {}
            b'\r' | b'\n' => return Ok(String::from_utf8_lossy(&got).into_owned()),
            super::sim::XON | super::sim::XOFF => {}
            b => got.push(b),
        }
        if got.len() > 256 {
            return Err(RegisterError::Garbled {
                port,
                asked: format!("{asked};"),
                answer: String::from_utf8_lossy(&got).into_owned(),
                mark,
            });
        }
    }
}

/// A mark as the GRBL prober needs it, machine mm: its reference point where printed, the
/// directions of its two edges into the sheet (`u` along the sheet's x, `v` along its y), and
/// whether it is the square (side `square`) or an L.
#[derive(Debug, Clone, Copy)]
pub struct ProbeMark {
    pub at: DVec2,
    pub u: DVec2,
    pub v: DVec2,
    pub square: Option<f64>,
}

/// Probe feed, mm/min.
const PROBE_FEED: f64 = 300.0;

/// Measure each of `marks` with `G38.3` probe moves (see the module documentation); returns
/// the reference points found, machine mm, in mark order.
pub fn probe_grbl(
    link: &mut Link,
    marks: &[ProbeMark],
    z_up: Option<f64>,
    search: f64,
    opts: &StreamOptions,
) -> Result<Vec<DVec2>, RegisterError> {
    let mut g = GrblLine { link, opts };
    g.wake()?;
    g.send("G21G90", 1)?;
    if let Some(z) = z_up {
        g.send(&format!("G0Z{z:.3}"), 1)?;
    }
    let nominal: Vec<DVec2> = marks.iter().map(|m| m.at).collect();
    let mut order: Vec<usize> = (0..marks.len()).collect();
    order.sort_by(|a, b| nominal[*a].length().total_cmp(&nominal[*b].length()));
    let mut out = vec![DVec2::ZERO; marks.len()];
    let (mut seen, mut got) = (Vec::new(), Vec::new());
    for k in order {
        let m = &marks[k];
        // The mark's edge directions as the marks found so far turn the sheet.
        let f = crate::geom::similarity::fit(&seen, &got);
        let turn = |d: DVec2| {
            f.as_ref()
                .map_or(d, |f| DVec2::from_angle(f.transform.angle).rotate(d))
        };
        let (u, v) = (turn(m.u), turn(m.v));
        let c = predict(&seen, &got, m.at);
        let port = g.link.name.clone();
        let not_found = || RegisterError::NotFound {
            port: port.clone(),
            mark: k + 1,
            x: c.x,
            y: c.y,
            search,
        };
        let mut hit = |from: DVec2, to: DVec2| -> Result<DVec2, RegisterError> {
            g.probe(from, to, k + 1)?.ok_or_else(not_found)
        };
        let r = search;
        let found = match m.square {
            Some(_) => {
                let mut p = c;
                for d in [u, v, u] {
                    let a = hit(p - d * r, p + d * r)?;
                    let b = hit(p + d * r, p - d * r)?;
                    p = (a + b) / 2.0;
                }
                p
            }
            None => {
                // Two points on the outer edge along v (met moving along u), two along u.
                let e1 = [
                    hit(c + v * 8.0 - u * r, c + v * 8.0 + u * r)?,
                    hit(c + v * 14.0 - u * r, c + v * 14.0 + u * r)?,
                ];
                let e2 = [
                    hit(c + u * 8.0 - v * r, c + u * 8.0 + v * r)?,
                    hit(c + u * 14.0 - v * r, c + u * 14.0 + v * r)?,
                ];
                meet(e1, e2).ok_or_else(not_found)?
            }
        };
        out[k] = found;
        seen.push(m.at);
        got.push(found);
    }
    Ok(out)
}

/// Where the line through `a` meets the line through `b`.
fn meet(a: [DVec2; 2], b: [DVec2; 2]) -> Option<DVec2> {
    let (da, db) = (a[1] - a[0], b[1] - b[0]);
    let den = da.perp_dot(db);
    if den.abs() < 1e-12 {
        return None;
    }
    let t = (b[0] - a[0]).perp_dot(db) / den;
    Some(a[0] + da * t)
}

/// A GRBL controller answered line by line (send-response).
struct GrblLine<'a> {
    link: &'a mut Link,
    opts: &'a StreamOptions,
}

impl GrblLine<'_> {
    fn err(&self, mark: usize, message: String) -> RegisterError {
        RegisterError::Line {
            port: self.link.name.clone(),
            mark,
            message,
        }
    }

    /// Reset and wait for the welcome; unlock if it asks.
    fn wake(&mut self) -> Result<(), RegisterError> {
        let opts = self.opts;
        write_all(self.link, &[crate::device::grbl::SOFT_RESET], opts)
            .map_err(|e| self.err(1, e.to_string()))?;
        let mut lock = false;
        loop {
            let l = answer(self.link, "Ctrl-X (reset)", 1, opts)?;
            if l.contains("'$X' to unlock") {
                lock = true;
            }
            if l.starts_with("Grbl ") {
                break;
            }
        }
        // The unlock hint follows the welcome.
        std::thread::sleep(Duration::from_millis(50));
        let mut buf = [0u8; 256];
        let n = self.link.read_ready(&mut buf).unwrap_or(0);
        if lock || String::from_utf8_lossy(&buf[..n]).contains("'$X' to unlock") {
            self.send("$X", 1)?;
        }
        Ok(())
    }

    /// Send one line and collect what comes back up to its `ok`; `error:N` or an alarm is an
    /// error naming the line.
    fn send(&mut self, line: &str, mark: usize) -> Result<Vec<String>, RegisterError> {
        let opts = self.opts;
        write_all(self.link, format!("{line}\n").as_bytes(), opts)
            .map_err(|e| self.err(mark, e.to_string()))?;
        let mut said = Vec::new();
        loop {
            let l = answer(self.link, line, mark, opts)?;
            if l == "ok" {
                return Ok(said);
            }
            if l.starts_with("error") || l.starts_with("ALARM") {
                return Err(self.err(mark, format!("GRBL answered `{l}` to `{line}`")));
            }
            said.push(l);
        }
    }

    /// Probe from `from` to `to` (machine mm): the contact, if there was one.
    fn probe(
        &mut self,
        from: DVec2,
        to: DVec2,
        mark: usize,
    ) -> Result<Option<DVec2>, RegisterError> {
        self.send(&format!("G0X{:.3}Y{:.3}", from.x, from.y), mark)?;
        let line = format!("G38.3X{:.3}Y{:.3}F{PROBE_FEED}", to.x, to.y);
        let said = self.send(&line, mark)?;
        let prb = said
            .iter()
            .find_map(|l| l.strip_prefix("[PRB:").and_then(|r| r.strip_suffix(']')));
        let Some(prb) = prb else {
            return Err(self.err(mark, format!("no [PRB:…] answer to `{line}`")));
        };
        let (xyz, ok) = prb.rsplit_once(':').unwrap_or((prb, "0"));
        let v: Vec<f64> = xyz
            .split(',')
            .filter_map(|t| t.trim().parse().ok())
            .collect();
        match (v.as_slice(), ok.trim()) {
            ([x, y, ..], "1") => Ok(Some(DVec2::new(*x, *y))),
            (_, "0") => Ok(None),
            _ => Err(self.err(mark, format!("cannot read `[PRB:{prb}]`"))),
        }
    }
}

/// What [`sim_job`] did: the program's stream (`None`: the caller refused before sending
/// anything) and the simulator's report.
pub type SimOutcome<E> = (Result<Result<StreamReport, StreamError>, E>, SimReport);

/// Print-and-cut on a simulated cutter: start it as `cfg` says (its printed sheet placed),
/// measure the marks with its sensor (`measure`: [`digitize`] or [`probe_grbl`]), hand the measured points to
/// `prepare` (which fits them and makes the program, or refuses), and stream the program on
/// the same line. A failed measurement or a refusal stops the simulator with nothing cut; its
/// report says so.
pub fn sim_job<E: From<RegisterError>>(
    cfg: SimConfig,
    opts: &StreamOptions,
    finish_within: Duration,
    measure: impl FnOnce(&mut Link) -> Result<Vec<DVec2>, RegisterError>,
    prepare: impl FnOnce(&[DVec2]) -> Result<Vec<u8>, E>,
) -> Result<SimOutcome<E>, SimError> {
    let profile = cfg.profile.clone();
    let handle = super::sim::spawn(cfg)?;
    let mut port =
        super::serial::open(&profile, &handle.path, None)?.with_virtual_cts(handle.cts.clone());
    port.name = format!("the simulated {}", profile.name);
    let measured = measure(&mut port)
        .map_err(E::from)
        .and_then(|m| prepare(&m));
    match measured {
        Ok(program) => {
            let (sent, rep) =
                super::stream::stream_into(handle, port, &profile, &program, opts, finish_within)?;
            Ok((Ok(sent), rep))
        }
        Err(e) => {
            drop(port);
            let rep = handle.stop()?;
            Ok((Err(e), rep))
        }
    }
}

/// A key of the interactive jog ([`jog`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    Left,
    Right,
    Up,
    Down,
    /// A step ten times smaller (down to 0.1 mm).
    Finer,
    /// A step ten times larger (up to 10 mm).
    Coarser,
    /// Take the head's position as the mark's.
    Take,
    /// Stop measuring.
    Quit,
}

/// Jog steps, mm.
const STEPS: [f64; 3] = [0.1, 1.0, 10.0];

/// Measure the marks by hand: for each mark in order the head goes (pen or tool up) to where
/// it was printed, `nominal` (machine mm), and moves by the keys `key` returns (given the mark,
/// 1-based, the head's position in mm and the step) — HP-GL `PU x,y;` moves, GRBL `$J=` jog
/// moves (`$J=G90G21X…Y…F2000`, after a reset and `$X` as for probing) — until `Take`. The
/// host knows where the head is, since it sent it there. Returns the positions taken,
/// machine units.
pub fn jog(
    link: &mut Link,
    language: crate::profile::Language,
    units_per_mm: f64,
    z_up: Option<f64>,
    nominal: &[DVec2],
    opts: &StreamOptions,
    mut key: impl FnMut(usize, DVec2, f64) -> Key,
) -> Result<Vec<DVec2>, RegisterError> {
    let grbl = language == crate::profile::Language::Gcode;
    let port = link.name.clone();
    let mut g = GrblLine { link, opts };
    if grbl {
        g.wake()?;
        g.send("G21G90", 1)?;
        if let Some(z) = z_up {
            g.send(&format!("G0Z{z:.3}"), 1)?;
        }
    } else {
        write_all(g.link, b"IN;", opts).map_err(|e| g.err(1, e.to_string()))?;
    }
    let mut step = 1;
    let mut out = Vec::with_capacity(nominal.len());
    for (k, at) in nominal.iter().enumerate() {
        let mark = k + 1;
        let mut p = *at;
        loop {
            if grbl {
                g.send(&format!("$J=G90G21X{:.3}Y{:.3}F2000", p.x, p.y), mark)?;
            } else {
                let (x, y) = (
                    (p.x * units_per_mm).round() as i64,
                    (p.y * units_per_mm).round() as i64,
                );
                write_all(g.link, format!("PU{x},{y};").as_bytes(), opts)
                    .map_err(|e| g.err(mark, e.to_string()))?;
            }
            let s = STEPS[step];
            match key(mark, p, s) {
                Key::Left => p.x -= s,
                Key::Right => p.x += s,
                Key::Up => p.y += s,
                Key::Down => p.y -= s,
                Key::Finer => step = step.saturating_sub(1),
                Key::Coarser => step = (step + 1).min(STEPS.len() - 1),
                Key::Take => break,
                Key::Quit => return Err(RegisterError::Cancelled { port }),
            }
        }
        out.push(p * units_per_mm);
    }
    Ok(out)
}
