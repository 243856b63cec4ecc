//! Streaming a program into a device without ever overrunning it.
//!
//! - **Buffered** (HP-GL cutters): the program goes out in chunks of at most `CHUNK` bytes,
//!   paced at the line rate (baud / 10 bytes a second) so that no more than two chunks are in
//!   the kernel's queue when the device asks to stop. XON/XOFF: after every chunk the input is
//!   read; XOFF stops sending until XON. RTS/CTS: CTS is checked before every chunk. Without
//!   flow control nothing reports a full buffer, so byte b is not sent before the device can
//!   have executed byte b − `buffer`, estimated from the program's own speeds (line time plus
//!   motion time, +10 %): safe, slower than the machine could go; profiles should say
//!   `xon-xoff` or `rts-cts` wherever the machine can. A device that holds the host off longer
//!   than the timeout has stopped, unless its profile gives an output channel
//!   (`status_query = "esc-b"`): then it is asked HP's `ESC . B` twice a second, which it
//!   answers at once with its free buffer space, and space that changed is progress (a long
//!   move works off no byte until it ends: one move longer than the timeout still needs a
//!   longer `--timeout`).
//! - **GRBL character counting** (GRBL wiki, "Interface", streaming protocols): lines are sent
//!   while the bytes of the lines not yet answered (`ok` or `error:N`) fit in the device's
//!   128-byte receive buffer. `$` commands are sent alone, after every earlier line is
//!   answered (send-response), because GRBL executes them only when idle.
//! - **GRBL send-response**: one line, wait for its answer, the next.
//!
//! Before a GRBL job the controller is reset (Ctrl-X) and its welcome awaited, which also
//! proves it is there. `error:N` or `ALARM:N` stops the job with the line, GRBL's meaning and
//! the tool lifted. On Ctrl-C (the `cancel` flag), a hang-up or a timeout the stream stops,
//! lifts the tool when the line still works (HP-GL: `;PU;SP0;`, which the device executes after
//! what it has buffered, and the message says so; GRBL: feed hold, wait for
//! the hold, soft reset, then the cut tool's "up" command) and reports how far it got: the
//! stroke (counted from the program's pen-up moves) and the byte or line.
//!
//! Progress: a bar on stderr (strokes, ETA) when stderr is a terminal and not quiet. It counts
//! machine time, not bytes: HP-GL and GP-GL by the simulator's reading of the program's speeds
//! (the bar stands at the instructions more than a buffer behind what was sent), GRBL by its
//! planner's (`grbl`), whose status is polled with `?` five times a second while a job runs.

// A stream error carries the job position for the user; it happens at most once per job, so
// its size on the error path does not matter.
#![allow(clippy::result_large_err)]

mod grbl;

use super::serial::Link;
use super::sim::{Finish, SimConfig, SimError, SimReport, XOFF, XON};
use crate::profile::{FlowControl, Language, Profile, StatusQuery};
use grbl::Grbl;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Largest write of the buffered protocol, bytes.
pub(crate) const CHUNK: usize = 16;

/// How the stream behaves.
#[derive(Debug, Clone)]
pub struct StreamOptions {
    /// Give up when the device makes no progress (no XON, no CTS, no answer) for this long.
    pub timeout: Duration,
    /// How long to wait for GRBL's welcome after the reset.
    pub wake_timeout: Duration,
    /// Show a progress bar (only when stderr is a terminal).
    pub progress: bool,
    /// Set (by Ctrl-C) to stop the job.
    pub cancel: Arc<AtomicBool>,
}

impl Default for StreamOptions {
    fn default() -> Self {
        StreamOptions {
            timeout: Duration::from_secs(60),
            wake_timeout: Duration::from_secs(5),
            progress: true,
            cancel: Arc::new(AtomicBool::new(false)),
        }
    }
}

/// How far a job got.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Position {
    /// Bytes of the program written to the line (buffered) or answered (GRBL).
    pub bytes: usize,
    pub bytes_total: usize,
    /// Strokes begun, of all.
    pub stroke: usize,
    pub strokes_total: usize,
    /// GRBL: the last line answered `ok` (1-based in the program), and how many lines.
    pub line: Option<usize>,
    pub lines_total: usize,
    /// HP-GL: bytes the device is known to have executed, when that differs from `bytes`
    /// (what was written): the simulator's count, or for a real device without answers the
    /// bytes written less what its buffer and the line can still hold.
    pub confirmed: Option<usize>,
}

impl std::fmt::Display for Position {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.confirmed {
            Some(c) => write!(
                f,
                "{c} of {} bytes known executed by the device ({} written), stroke {} of {} begun",
                self.bytes_total, self.bytes, self.stroke, self.strokes_total
            )?,
            None => write!(
                f,
                "stroke {} of {}, byte {} of {}",
                self.stroke, self.strokes_total, self.bytes, self.bytes_total
            )?,
        }
        if let Some(l) = self.line {
            write!(f, ", last acknowledged line {l} of {}", self.lines_total)?;
        }
        Ok(())
    }
}

/// What became of the tool after a stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolState {
    Lifted,
    /// HP-GL: the tool-up command is sent; the device executes it after what it has buffered.
    LiftQueued,
    /// The line failed before the tool-up command could be sent.
    Unknown,
    /// The line works but the device took no tool-up command (it stalled or holds XOFF).
    NotTaken,
}

impl std::fmt::Display for ToolState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ToolState::Lifted => write!(f, "tool lifted"),
            ToolState::LiftQueued => write!(
                f,
                "tool-up sent: the machine lifts the tool once it has worked off its buffer"
            ),
            ToolState::Unknown => write!(
                f,
                "the line is gone, so the tool could not be lifted: check the machine"
            ),
            ToolState::NotTaken => write!(
                f,
                "the device took no tool-up command (it stopped reading or keeps asking to wait): the tool may still be down, check the machine"
            ),
        }
    }
}

/// Why a stream stopped early. Every message says how far the job got.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    #[error("{port}: timed out after {secs:.0} s {op} ({at}; {tool})")]
    Timeout {
        port: String,
        op: &'static str,
        secs: f64,
        at: Position,
        tool: ToolState,
    },
    #[error("{port}: the line closed {op} ({at}; {tool})")]
    HungUp {
        port: String,
        op: &'static str,
        at: Position,
        tool: ToolState,
    },
    #[error(
        "{port}: GRBL answered error:{code} ({meaning}) to line {line} `{text}` ({at}; {tool})"
    )]
    Grbl {
        port: String,
        code: u32,
        meaning: &'static str,
        line: usize,
        text: String,
        at: Position,
        tool: ToolState,
    },
    #[error("{port}: GRBL raised ALARM:{code} ({meaning}) ({at}; {tool})")]
    Alarm {
        port: String,
        code: u32,
        meaning: &'static str,
        at: Position,
        tool: ToolState,
    },
    #[error("{port}: GRBL did not answer the reset within {secs:.0} s: is it a GRBL controller at this baud rate?")]
    NoWelcome { port: String, secs: f64 },
    #[error("{port}: line {line} has {len} significant characters (spaces and comments not counted), more than the {max} GRBL keeps; nothing was sent")]
    LineTooLong {
        port: String,
        line: usize,
        len: usize,
        max: usize,
    },
    #[error("{port}: line {line} contains {what}, which GRBL acts on at once as a real-time command (or drops) instead of reading it as part of the line; nothing was sent")]
    RealtimeInLine {
        port: String,
        line: usize,
        what: String,
    },
    #[error("{port}: line {line} is a program pause (M0): GRBL would hold there until its cycle-start button or `~`, and flatcut does not resume a held machine within one program; split the program at the pause (flatcut's own jobs pause between programs); nothing was sent")]
    ProgramPause { port: String, line: usize },
    /// A controller setting does not suit the profile (nothing was sent).
    #[error("{port}: {message}")]
    Settings { port: String, message: String },
    #[error("{port}: stopped by Ctrl-C ({at}; {tool})")]
    Cancelled {
        port: String,
        at: Position,
        tool: ToolState,
    },
    #[error("{port}: cannot read the CTS line ({message}); RTS/CTS flow control needs it to know the device can take more, so sending stopped ({at}; {tool})")]
    Cts {
        port: String,
        message: String,
        at: Position,
        tool: ToolState,
    },
}

impl StreamError {
    pub fn position(&self) -> Option<&Position> {
        match self {
            StreamError::Timeout { at, .. }
            | StreamError::HungUp { at, .. }
            | StreamError::Grbl { at, .. }
            | StreamError::Alarm { at, .. }
            | StreamError::Cancelled { at, .. }
            | StreamError::Cts { at, .. } => Some(at),
            _ => None,
        }
    }
}

/// What a finished stream did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StreamReport {
    pub bytes: usize,
    pub strokes: usize,
    pub lines: usize,
    pub seconds: f64,
    /// Bytes a second over the whole job.
    pub rate: f64,
    pub xoff_received: usize,
    /// Input that was neither flow control nor a GRBL answer (noise on the line).
    pub garbage_bytes: usize,
}

/// Byte offsets where strokes start: HP-GL `PU` with coordinates, G-code `G0` with X or Y.
pub fn stroke_starts(program: &[u8], language: Language) -> Vec<usize> {
    let mut out = Vec::new();
    match language {
        Language::Hpgl => {
            for i in 0..program.len().saturating_sub(2) {
                if &program[i..i + 2] == b"PU"
                    && (program[i + 2].is_ascii_digit() || program[i + 2] == b'-')
                {
                    out.push(i);
                }
            }
        }
        Language::Gpgl => {
            // `M` with a coordinate at the start of an instruction.
            for i in 0..program.len().saturating_sub(1) {
                let starts = i == 0 || crate::output::gpgl::ends_instruction(program[i - 1]);
                if starts
                    && program[i] == b'M'
                    && (program[i + 1].is_ascii_digit() || program[i + 1] == b'-')
                {
                    out.push(i);
                }
            }
        }
        Language::Gcode => {
            let mut at = 0;
            for line in program.split(|&b| b == b'\n') {
                let l = String::from_utf8_lossy(line);
                let t = l.trim_start();
                if (t.starts_with("G0 ") || t.starts_with("G00 "))
                    && (t.contains('X') || t.contains('Y'))
                {
                    out.push(at);
                }
                at += line.len() + 1;
            }
        }
    }
    out
}

pub(crate) struct Bar {
    pub(crate) bar: Option<indicatif::ProgressBar>,
    pub(crate) starts: Vec<usize>,
    /// HP-GL, GP-GL with a bar shown: where each instruction ends and the machine's seconds
    /// up to its end; the bar then counts machine milliseconds, not bytes.
    machine: Vec<(usize, f64)>,
    /// The device's buffer: bytes sent but perhaps not yet executed.
    buffer: usize,
}

impl Bar {
    fn new(total: usize, starts: Vec<usize>, show: bool) -> Bar {
        use std::io::IsTerminal;
        let bar = (show && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(total as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{spinner} [{bar:32}] {bytes}/{total_bytes} {msg} ETA {eta}",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            b
        });
        Bar {
            bar,
            starts,
            machine: Vec::new(),
            buffer: 0,
        }
    }

    /// Count a buffered program's progress in the machine's time (the simulator's reading of
    /// its speeds, the line time of every byte), so that the ETA follows the machine's motion:
    /// the bar stands at the end of the instructions the device has surely executed, those
    /// more than its buffer behind what was sent.
    fn in_machine_time(mut self, profile: &Profile, program: &[u8]) -> Bar {
        let Some(b) = &self.bar else { return self };
        self.machine = execution_timeline(profile, program);
        self.buffer = profile.buffer;
        let total = self.machine.last().map_or(0.0, |&(_, t)| t);
        b.set_length(((total * 1000.0) as u64).max(1));
        b.set_style(
            indicatif::ProgressStyle::with_template("{spinner} [{bar:32}] {msg} machine ETA {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        self
    }

    fn stroke_at(&self, byte: usize) -> usize {
        self.starts.partition_point(|&s| s < byte)
    }

    pub(crate) fn set(&self, byte: usize, extra: &str) {
        if let Some(b) = &self.bar {
            if self.machine.is_empty() {
                b.set_position(byte as u64);
            } else {
                let done = byte.saturating_sub(self.buffer);
                let k = self.machine.partition_point(|&(end, _)| end <= done);
                let t = k.checked_sub(1).map_or(0.0, |i| self.machine[i].1);
                b.set_position((t * 1000.0) as u64);
            }
            b.set_message(format!(
                "stroke {}/{}{extra}",
                self.stroke_at(byte),
                self.starts.len()
            ));
        }
    }

    fn done(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Send `program` to the device on `link` as the profile says.
pub fn send(
    link: &mut Link,
    profile: &Profile,
    program: &[u8],
    opts: &StreamOptions,
) -> Result<StreamReport, StreamError> {
    let start = Instant::now();
    let starts = stroke_starts(program, profile.language);
    let mut bar = Bar::new(program.len(), starts, opts.progress);
    if profile.language != Language::Gcode {
        bar = bar.in_machine_time(profile, program);
    }
    // Profile validation ties the GRBL protocols to G-code, so the language decides.
    let result = if profile.language == Language::Gcode {
        Grbl::new(link, profile, program, opts, &bar).run()
    } else {
        buffered(link, profile, program, opts, &bar)
    };
    bar.done();
    let mut rep = result?;
    rep.seconds = start.elapsed().as_secs_f64();
    rep.rate = rep.bytes as f64 / rep.seconds.max(1e-9);
    rep.strokes = bar.starts.len();
    Ok(rep)
}

pub(crate) fn position(bar: &Bar, bytes: usize, total: usize) -> Position {
    Position {
        bytes,
        bytes_total: total,
        stroke: bar.stroke_at(bytes),
        strokes_total: bar.starts.len(),
        line: None,
        lines_total: 0,
        confirmed: None,
    }
}

/// Where a buffered job stopped: a buffered device answers nothing, so what it has surely
/// executed is what was written less what its buffer and the line (two chunks) can still hold.
fn unanswered_position(bar: &Bar, sent: usize, total: usize, buffer: usize) -> Position {
    let mut at = position(bar, sent, total);
    let executed = sent.saturating_sub(buffer + 2 * CHUNK);
    at.confirmed = Some(executed);
    at.stroke = bar.stroke_at(executed);
    at
}

/// Stream an HP-GL program under the profile's flow control (XON/XOFF, RTS/CTS, or none:
/// paced by the program's own execution time), at the line rate.
fn buffered(
    link: &mut Link,
    profile: &Profile,
    program: &[u8],
    opts: &StreamOptions,
    bar: &Bar,
) -> Result<StreamReport, StreamError> {
    let rate = link.baud.max(1) as f64 / 10.0;
    let flow = profile.serial.flow_control;
    let mut rep = StreamReport::default();
    let mut sent = 0usize;
    let mut stopped = false;
    let t0 = Instant::now();
    let mut wire_free = t0;
    // Without flow control nothing tells us the buffer is full: never send byte b before the
    // device can have executed byte b − buffer, by the program's own speeds.
    let timeline = if flow == FlowControl::None {
        execution_timeline(profile, program)
    } else {
        Vec::new()
    };
    let chunk_time = Duration::from_secs_f64(CHUNK as f64 / rate);
    let mut last_progress = Instant::now();
    let mut input = [0u8; 256];
    let total = program.len();
    let port = link.name.clone();
    let mut last_bar = Instant::now();
    // The device's answers to `ESC . B` while it holds us off (profiles with an output channel).
    let mut query = (profile.serial.status_query == StatusQuery::EscB).then(Query::default);

    let fail = |link: &mut Link, kind: Failure, sent: usize, stopped: bool| -> StreamError {
        let at = unanswered_position(bar, sent, total, profile.buffer);
        let tool = if matches!(kind, Failure::HungUp(_)) {
            ToolState::Unknown
        } else {
            let (ends, up) = tool_up(profile.language);
            let end = program[sent..]
                .iter()
                .position(|&b| ends(b))
                .map_or(total, |i| sent + i + 1);
            lift_hpgl(link, &program[sent..end], up, stopped)
        };
        kind.into_error(port.clone(), at, tool, opts.timeout)
    };

    while sent < total {
        if opts.cancel.load(Ordering::SeqCst) {
            return Err(fail(link, Failure::Cancelled, sent, stopped));
        }
        // Listen: XON/XOFF and anything else the device says.
        match link.read_ready(&mut input) {
            Ok(n) => take_in(
                &input[..n],
                flow,
                &mut rep,
                &mut stopped,
                &mut last_progress,
                query.as_mut(),
            ),
            Err(_) => return Err(fail(link, Failure::HungUp("while sending"), sent, stopped)),
        }
        let cts = match link.clear_to_send() {
            Ok(c) => c,
            Err(e) => return Err(fail(link, Failure::Cts(e.to_string()), sent, stopped)),
        };
        if stopped || !cts {
            if last_progress.elapsed() > opts.timeout {
                let op = if stopped {
                    "waiting for XON from the device (it sent XOFF and never resumed)"
                } else {
                    "waiting for the device to raise CTS"
                };
                return Err(fail(link, Failure::Timeout(op), sent, stopped));
            }
            let heard = wait_held(
                link,
                flow,
                &mut rep,
                &mut stopped,
                &mut last_progress,
                query.as_mut(),
                &mut input,
            );
            if let Err(op) = heard {
                return Err(fail(link, Failure::HungUp(op), sent, stopped));
            }
            continue;
        }
        // Pace at the line rate: `wire_free` is when the line will have carried everything
        // written; write when at most one chunk is still queued, so no more than two chunks
        // are ever ahead of the wire (and a long stop never turns into a burst).
        let now = Instant::now();
        let queued = wire_free.saturating_duration_since(now);
        if queued > chunk_time {
            std::thread::sleep((queued - chunk_time).min(Duration::from_millis(10)));
            continue;
        }
        let n = CHUNK.min(total - sent);
        if !timeline.is_empty() && sent + n > profile.buffer {
            let need = sent + n - profile.buffer;
            let k = timeline.partition_point(|&(end, _)| end < need);
            let t_ready = timeline.get(k).map_or(0.0, |&(_, t)| t * PACING_MARGIN);
            let wait = t_ready - t0.elapsed().as_secs_f64();
            if wait > 0.0 {
                // Waiting on our own estimate is not the device failing to make progress.
                last_progress = Instant::now();
                std::thread::sleep(Duration::from_secs_f64(wait.min(0.01)));
                continue;
            }
        }
        match link.write_some(&program[sent..sent + n]) {
            Ok(0) => {
                if last_progress.elapsed() > opts.timeout {
                    return Err(fail(
                        link,
                        Failure::Timeout("writing to the device (it stopped reading)"),
                        sent,
                        stopped,
                    ));
                }
            }
            Ok(k) => {
                sent += k;
                wire_free = wire_free.max(now) + Duration::from_secs_f64(k as f64 / rate);
                last_progress = Instant::now();
                if last_bar.elapsed() > Duration::from_millis(100) {
                    bar.set(sent, "");
                    last_bar = Instant::now();
                }
            }
            Err(_) => return Err(fail(link, Failure::HungUp("while sending"), sent, stopped)),
        }
    }
    let _ = link.flush();
    bar.set(sent, "");
    rep.bytes = sent;
    Ok(rep)
}

/// While the device holds the host off: ask a device with an output channel how much room it
/// has (room that changes is a device at work, however long it holds us off), then wait for
/// the next byte (XON, an answer) or for the CTS line. The error says what hung up.
fn wait_held(
    link: &mut Link,
    flow: FlowControl,
    rep: &mut StreamReport,
    stopped: &mut bool,
    last_progress: &mut Instant,
    mut query: Option<&mut Query>,
    input: &mut [u8],
) -> Result<(), &'static str> {
    if let Some(q) = query.as_deref_mut() {
        if q.asked.is_none_or(|t| t.elapsed() > QUERY_EVERY) {
            link.write_some(ESC_B)
                .map_err(|_| "while asking the device for its buffer space")?;
            q.asked = Some(Instant::now());
        }
    }
    if flow == FlowControl::XonXoff || query.is_some() {
        let n = link.read_some(input).map_err(|_| "while waiting for XON")?;
        take_in(&input[..n], flow, rep, stopped, last_progress, query);
    } else {
        std::thread::sleep(Duration::from_micros(500));
    }
    Ok(())
}

/// Without flow control, how much later than the program's own timeline a byte is sent: a safe
/// upper bound of when the device has made room for it.
const PACING_MARGIN: f64 = 1.1;

/// HP's device-control query for the free buffer space (`ESC . B`).
const ESC_B: &[u8] = b"\x1b.B";
/// How often a device that holds the host off is asked for its buffer space.
const QUERY_EVERY: Duration = Duration::from_millis(500);

/// The state of `ESC . B` queries: when the last went out, the answer being read, the last
/// answer (free bytes).
#[derive(Default)]
struct Query {
    asked: Option<Instant>,
    line: Vec<u8>,
    free: Option<usize>,
}

/// Take in bytes the device sent while a buffered program goes out: XOFF stops the sender and
/// XON resumes it (under XON/XOFF flow control); with `query`, digits ending in CR are an
/// answer to `ESC . B`, progress when the free space differs from the last answer; anything
/// else is counted as garbage.
fn take_in(
    bytes: &[u8],
    flow: FlowControl,
    rep: &mut StreamReport,
    stopped: &mut bool,
    last_progress: &mut Instant,
    mut query: Option<&mut Query>,
) {
    for &b in bytes {
        if let Some(q) = query.as_deref_mut() {
            if b.is_ascii_digit() && q.line.len() < 12 {
                q.line.push(b);
                continue;
            }
            if (b == b'\r' || b == b'\n') && !q.line.is_empty() {
                let free = std::str::from_utf8(&q.line)
                    .ok()
                    .and_then(|t| t.parse().ok());
                if free.is_some() && free != q.free {
                    if q.free.is_some() {
                        *last_progress = Instant::now();
                    }
                    q.free = free;
                }
                q.line.clear();
                continue;
            }
            if b == b'\r' || b == b'\n' {
                continue;
            }
            rep.garbage_bytes += q.line.len();
            q.line.clear();
        }
        match b {
            XOFF if flow == FlowControl::XonXoff => {
                if !*stopped {
                    rep.xoff_received += 1;
                }
                *stopped = true;
            }
            XON if flow == FlowControl::XonXoff => {
                *stopped = false;
                *last_progress = Instant::now();
            }
            _ => rep.garbage_bytes += 1,
        }
    }
}

/// For each HP-GL or GP-GL instruction, where it ends in the program and when (seconds after
/// the first byte) the device will have executed it: the line time of every byte up to it plus
/// the motion time of every instruction up to it (from the speeds the program and profile set,
/// read by the simulator's interpreter). Pacing adds [`PACING_MARGIN`] to it.
fn execution_timeline(profile: &Profile, program: &[u8]) -> Vec<(usize, f64)> {
    let rate = profile.serial.baud.max(1) as f64 / 10.0;
    let mut m = super::sim::hpgl::Hpgl::new(profile);
    let mut g = super::sim::gpgl::Gpgl::new(profile);
    let gpgl = profile.language == Language::Gpgl;
    let next = |r: &[u8]| {
        if gpgl {
            crate::output::gpgl::next_instruction(r)
        } else {
            crate::output::hpgl::read::next_instruction(r)
        }
    };
    let (mut at, mut motion) = (0usize, 0.0f64);
    let mut out = Vec::new();
    let mut rest = program;
    while let Some(n) = next(rest) {
        motion += if gpgl {
            g.execute(&rest[..n])
        } else {
            m.execute(&rest[..n])
        };
        at += n;
        out.push((at, motion + at as f64 / rate));
        rest = &rest[n..];
    }
    out
}

pub(crate) enum Failure {
    Timeout(&'static str),
    HungUp(&'static str),
    Cancelled,
    /// CTS could not be read (the message).
    Cts(String),
}

impl Failure {
    pub(crate) fn into_error(
        self,
        port: String,
        at: Position,
        tool: ToolState,
        t: Duration,
    ) -> StreamError {
        match self {
            Failure::Timeout(op) => StreamError::Timeout {
                port,
                op,
                secs: t.as_secs_f64(),
                at,
                tool,
            },
            Failure::HungUp(op) => StreamError::HungUp { port, op, at, tool },
            Failure::Cancelled => StreamError::Cancelled { port, at, tool },
            Failure::Cts(message) => StreamError::Cts {
                port,
                message,
                at,
                tool,
            },
        }
    }
}

/// What ends an instruction of a plotter language, and the command that lifts the tool after
/// it: HP-GL `;` then `PU;SP0;`; GP-GL ETX (or a line end) then `H` (tool up, home: GP-GL has
/// no tool-up without a move).
fn tool_up(language: Language) -> (fn(u8) -> bool, &'static [u8]) {
    match language {
        Language::Gpgl => (crate::output::gpgl::ends_instruction, b"\x03\nH\x03\n"),
        _ => (|b| b == b';', b"\nPU;SP0;\n"),
    }
}

/// Lift the tool of an HP-GL (or GP-GL) device: send the rest of the instruction in progress (a chunk may
/// have ended inside a coordinate, which a bare `;` would turn into a stray cut), then pen up
/// and put the pen away. Honours XOFF/CTS (starting from the state the stream was in) for a
/// few seconds; the device lifts after working off its buffer, and the result says so.
fn lift_hpgl(
    link: &mut Link,
    rest_of_instruction: &[u8],
    tool_up: &[u8],
    mut stopped: bool,
) -> ToolState {
    let mut cmd = rest_of_instruction.to_vec();
    cmd.extend_from_slice(tool_up);
    let deadline = Instant::now() + Duration::from_secs(3);
    let mut sent = 0;
    let mut input = [0u8; 64];
    while sent < cmd.len() && Instant::now() < deadline {
        if let Ok(n) = link.read_ready(&mut input) {
            for &b in &input[..n] {
                if b == XOFF {
                    stopped = true;
                } else if b == XON {
                    stopped = false;
                }
            }
        }
        if (stopped && link.flow == FlowControl::XonXoff) || !link.clear_to_send().unwrap_or(false)
        {
            std::thread::sleep(Duration::from_millis(2));
            continue;
        }
        match link.write_some(&cmd[sent..]) {
            Ok(k) => sent += k,
            Err(_) => return ToolState::Unknown,
        }
    }
    if sent == cmd.len() && link.flush().is_ok() {
        ToolState::LiftQueued
    } else {
        ToolState::NotTaken
    }
}

/// Stream `program` through a pseudo-terminal into a new simulator set up by `cfg`, exactly
/// as flatcut's transport streams to a real port (CTS read from the simulator's flag), then let
/// the simulated machine work off what it holds, as a real one would: while it makes progress,
/// until it made none for `opts.timeout` (a stall: the stream then fails with a timeout), until
/// Ctrl-C (`opts.cancel`, the stream then fails as cancelled), and at most `finish_within`.
/// Returns the stream's outcome and the simulator's report; the report exists even when the
/// stream failed. A failed HP-GL stream's position gives the bytes the simulated device
/// executed (`Position::confirmed`).
pub fn stream_job(
    cfg: SimConfig,
    program: &[u8],
    opts: &StreamOptions,
    finish_within: Duration,
) -> Result<(Result<StreamReport, StreamError>, SimReport), SimError> {
    let profile = cfg.profile.clone();
    let handle = super::sim::spawn(cfg)?;
    let port =
        super::serial::open(&profile, &handle.path, None)?.with_virtual_cts(handle.cts.clone());
    stream_into(handle, port, &profile, program, opts, finish_within)
}

/// The rest of [`stream_job`] on a simulator already started and a line already open to it
/// (`device::register` measures the marks on the same line first).
pub(crate) fn stream_into(
    handle: super::sim::SimHandle,
    mut port: Link,
    profile: &Profile,
    program: &[u8],
    opts: &StreamOptions,
    finish_within: Duration,
) -> Result<(Result<StreamReport, StreamError>, SimReport), SimError> {
    let mut sent = send(&mut port, profile, program, opts);
    let written = port.written;
    drop(port);
    // Cancelled while sending: the tool-up is queued behind the buffer; let the device work
    // it off (at most 30 s), as a real one would.
    let stopped_early = opts.cancel.load(Ordering::SeqCst);
    let unset = AtomicBool::new(false);
    let (wait, cancel) = if stopped_early {
        (finish_within.min(Duration::from_secs(30)), &unset)
    } else {
        (finish_within, &*opts.cancel)
    };
    let (report, end) = handle.finish_watching(written, opts.timeout, wait, cancel)?;
    if profile.language == Language::Hpgl {
        let executed = report
            .bytes_received
            .saturating_sub(report.unexecuted_bytes)
            .min(program.len());
        let starts = stroke_starts(program, profile.language);
        let at = Position {
            bytes: written.min(program.len()),
            bytes_total: program.len(),
            stroke: starts.partition_point(|&s| s < executed),
            strokes_total: starts.len(),
            confirmed: Some(executed),
            ..Position::default()
        };
        let tool = if report.tool_down_at_end.is_some() {
            ToolState::NotTaken
        } else {
            ToolState::Lifted
        };
        let port = handle_port_name(&report);
        sent = match (sent, end) {
            (Ok(_), Finish::Cancelled) => Err(StreamError::Cancelled { port, at, tool }),
            // Done with a whole instruction left unexecuted is a device that stopped working
            // (the host may have written everything before the device stalled).
            (Ok(_), end)
                if (end == Finish::Idle && executed < program.len())
                    || crate::output::hpgl::read::next_instruction(&program[executed..])
                        .is_some() =>
            {
                Err(StreamError::Timeout {
                    port,
                    op:
                        "waiting for the device to work off its buffer (it stopped making progress)",
                    secs: opts.timeout.as_secs_f64(),
                    at,
                    tool,
                })
            }
            (Err(mut e), _) => {
                set_confirmed(&mut e, executed, at.stroke, tool);
                Err(e)
            }
            (ok, _) => ok,
        };
    }
    Ok((sent, report))
}

/// The name the simulated device goes by in messages.
fn handle_port_name(report: &SimReport) -> String {
    format!("the simulated {}", report.device)
}

/// Put the device's own count of executed bytes (and what it did with the tool) into a failed
/// stream's position.
fn set_confirmed(e: &mut StreamError, executed: usize, stroke: usize, state: ToolState) {
    match e {
        StreamError::Timeout { at, tool, .. }
        | StreamError::HungUp { at, tool, .. }
        | StreamError::Cancelled { at, tool, .. }
        | StreamError::Cts { at, tool, .. } => {
            at.confirmed = Some(executed);
            at.stroke = stroke;
            // The simulator knows what became of the tool.
            if state != ToolState::Lifted || *tool != ToolState::LiftQueued {
                *tool = state;
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A buffered program's bar counts machine time: a long move is most of the job, however
    /// few bytes it is, and the bar stands behind what was sent by the device's buffer.
    #[test]
    fn the_hpgl_bar_counts_machine_time() {
        let profile = crate::profile::find("sim").unwrap();
        // 1 mm moves, then one 500 mm move, then 1 mm moves again.
        let mut p = String::from("IN;SP1;PU0,0;");
        for k in 1..=20 {
            p.push_str(&format!("PD{},0;", k * 40));
        }
        let long_at = p.len();
        p.push_str("PD20800,0;");
        let long_end = p.len();
        for k in 1..=20 {
            p.push_str(&format!("PD{},0;", 20800 + k * 40));
        }
        p.push_str("PU;SP0;");
        let mut bar = Bar::new(p.len(), Vec::new(), false);
        bar.bar = Some(indicatif::ProgressBar::hidden());
        let bar = bar.in_machine_time(&profile, p.as_bytes());
        let b = bar.bar.clone().unwrap();
        let total = b.length().unwrap() as f64;
        let at = |byte: usize| {
            bar.set(byte + profile.buffer, "");
            b.position() as f64 / total
        };
        let (before, after) = (at(long_at), at(long_end));
        assert!(before < 0.1, "{before}");
        assert!(
            after > 0.85,
            "{after}: the long move is most of the machine's time"
        );
        assert_eq!(at(0), 0.0);
        assert!((at(p.len()) - 1.0).abs() < 1e-3);
        bar.set(long_end, "");
        assert!(
            (b.position() as f64 / total) < 0.1,
            "the buffer is not yet executed"
        );
    }
}
