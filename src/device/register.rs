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
    #[error("{port}: stopped by Ctrl-C while measuring the marks (nothing was cut)")]
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

/// What [`sim_job`] did: the program's stream (`None`: the caller refused before sending
/// anything) and the simulator's report.
pub type SimOutcome<E> = (Result<Result<StreamReport, StreamError>, E>, SimReport);

/// Print-and-cut on a simulated cutter: start it as `cfg` says (its printed sheet placed),
/// measure the marks at `nominal` (machine units) with its sensor, hand the measured points to
/// `prepare` (which fits them and makes the program, or refuses), and stream the program on
/// the same line. A failed measurement or a refusal stops the simulator with nothing cut; its
/// report says so.
pub fn sim_job<E: From<RegisterError>>(
    cfg: SimConfig,
    nominal: &[DVec2],
    opts: &StreamOptions,
    finish_within: Duration,
    prepare: impl FnOnce(&[DVec2]) -> Result<Vec<u8>, E>,
) -> Result<SimOutcome<E>, SimError> {
    let profile = cfg.profile.clone();
    let handle = super::sim::spawn(cfg)?;
    let mut port =
        super::serial::open(&profile, &handle.path, None)?.with_virtual_cts(handle.cts.clone());
    port.name = format!("the simulated {}", profile.name);
    let r = &profile.registration;
    let measured = digitize(&mut port, nominal, profile.units_per_mm, r.search, opts)
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
