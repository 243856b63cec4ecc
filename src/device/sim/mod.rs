//! The simulated cutter: a real peer on the far end of a pseudo-terminal. Software talks to
//! the slave side (`/dev/pts/N`) exactly as to a USB-serial cutter; the simulator sits on the
//! master side and behaves like the machine described by a device profile.
//!
//! What it models, and the choices made where no device documentation decides:
//! - **The wire.** A pty has no baud rate, so the simulator takes bytes off the master side
//!   no faster than the profile's line would carry them (baud / 10 bytes a second, 8N1).
//!   Bytes still in the pty are bytes the host has not put on the wire yet. Its answers go
//!   back at the same rate; XON and XOFF go at once, ahead of queued answers.
//! - **The input buffer.** `profile.buffer` bytes (GRBL: its 128-byte receive buffer). A byte
//!   that arrives when it is full is lost and counted as an *overrun*, as a UART would.
//! - **Flow control.** XON/XOFF: XOFF (0x13) when the free space falls to a quarter of the
//!   buffer (at least 16 bytes, at most 256), XON (0x11) when it is back under a quarter full.
//!   RTS/CTS: the same thresholds drop and raise CTS; a pty has no modem lines, so CTS is a
//!   shared flag ([`SimHandle::cts`]) that flatcut's transport reads in place of the real
//!   line. After asking the host to stop, the simulator still takes up to `SKID` bytes (a
//!   UART FIFO's worth) and then leaves the rest in the pty, as a stopped transmitter would
//!   hold it. A host that ignores the stop is caught: the bytes waiting in the pty must stop
//!   growing within [`STOP_GRACE`] of the stop, or the growth is counted as
//!   `flow_violations`. (Only stops longer than the grace can catch a host this way; the
//!   grace is long enough for a loaded machine's kernel to act on XOFF.) This lets a plain program using the kernel's XON/XOFF (`stty ixon`)
//!   stream into the simulator. A profile with `status_query = "esc-b"` answers HP's
//!   `ESC . B` with its free buffer space as the bytes arrive, also while it holds the host
//!   off: it then reads on, takes the skid, holds the rest back as the stopped transmitter
//!   would and counts data that still arrives once the grace is over and the line has run dry as violations.
//! - **Execution.** HP-GL and GP-GL (`gpgl`) instructions are executed one at a time, each when the previous
//!   motion has finished; GRBL lines move from the receive buffer into a 15-block planner and
//!   are answered `ok` (or `error:N`) when planned, as GRBL does. Motion takes the time the
//!   interpreters compute (`hpgl`, [`grbl`]) divided by the time factor (`None`: no time).
//!   GRBL real-time bytes (`?`, `!`, `~`, Ctrl-X) act on arrival and are never buffered.
//! - **Print-and-cut**: a printed sheet placed on the bed with a known error and an optical
//!   sensor that digitizes its registration marks (HP-GL `DP`/`OS`/`OD`), see [`sensor`].
//! - **Faults** for tests ([`Faults`]): hang up after N bytes, stall (stop reading and
//!   executing) after N bytes, send garbage after N bytes, lose the XONs, answer a given
//!   GRBL line with `error:N`.
//!
//! Everything it cuts is recorded (`record`) and, on [`SimHandle::finish`], summarised in a
//! [`SimReport`] (written as `sim.json`) and drawn as `sim.png`, in the machine's own axes.

pub(crate) mod gpgl;
pub mod grbl;
pub(crate) mod grbl_block;
pub(crate) mod hpgl;
mod machine;
pub(crate) mod record;
pub mod sensor;

use crate::device::grbl as proto;
use crate::profile::{FlowControl, Language, Profile};
pub use record::SimPath;
use serde::Serialize;
use serialport::SerialPort;
use std::collections::{BTreeMap, VecDeque};
use std::io::{Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU8, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub const XON: u8 = 0x11;
pub const XOFF: u8 = 0x13;

/// Bytes the simulator still takes after asking the host to stop.
pub(crate) const SKID: usize = 16;
/// Time a host has to react to XOFF or CTS before growth of its backlog counts as a violation.
pub const STOP_GRACE: Duration = Duration::from_millis(250);
/// GRBL planner blocks (`BLOCK_BUFFER_SIZE` 16, one kept free).
pub(crate) const PLANNER_BLOCKS: usize = 15;

/// Faults to inject.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Faults {
    /// Close the line after this many bytes have been received.
    pub hang_up_after: Option<usize>,
    /// Stop reading and executing (but keep the line open) after this many bytes.
    pub stall_after: Option<usize>,
    /// Send a burst of garbage to the host after this many bytes.
    pub garbage_after: Option<usize>,
    /// Lose every XON on the line (the device believes it sent them).
    pub lose_xon: bool,
    /// GRBL: answer line N (1-based, counting every line received) with `error:code`.
    pub grbl_error: Option<(usize, u32)>,
}

/// How the simulator is set up.
#[derive(Debug, Clone)]
pub struct SimConfig {
    /// The machine to behave like.
    pub profile: Profile,
    /// Motion runs this many times faster than the real machine; `None`: motion takes no time.
    pub time_factor: Option<f64>,
    pub faults: Faults,
    /// Print-and-cut: the printed sheet on the bed, which a registration sensor finds
    /// ([`sensor`]); `None`: nothing printed is loaded.
    pub printed: Option<sensor::PrintedSheet>,
}

impl SimConfig {
    pub fn new(profile: Profile) -> SimConfig {
        SimConfig {
            profile,
            time_factor: None,
            faults: Faults::default(),
            printed: None,
        }
    }
}

/// Stroke count and length for one tool.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ToolTotals {
    pub strokes: usize,
    pub length_mm: f64,
}

/// What the simulated cutter saw and did (`sim.json`).
#[derive(Debug, Clone, Default, Serialize)]
pub struct SimReport {
    pub device: String,
    pub language: String,
    pub baud: u32,
    pub flow_control: String,
    pub buffer: usize,
    pub bytes_received: usize,
    /// HP-GL instructions or GRBL lines executed.
    pub executed: usize,
    /// HP-GL instructions ignored, by mnemonic.
    pub ignored: BTreeMap<String, usize>,
    /// GRBL: `[line, code]` of every `error:N` sent.
    pub errors_sent: Vec<(usize, u32)>,
    /// GRBL alarms raised.
    pub alarms: Vec<u32>,
    /// Bytes lost because the buffer was full.
    pub overruns: usize,
    /// Bytes the host queued after being told to stop (past the grace time).
    pub flow_violations: usize,
    /// The tool that was down when the simulator stopped (`None`: all tools up).
    pub tool_down_at_end: Option<String>,
    /// Bytes left in the buffer at the end, never run: a fragment that no further byte
    /// completed, or what a stall, a hang-up or a stop left.
    pub unexecuted_bytes: usize,
    /// Fullest the input buffer ever was.
    pub max_buffer_fill: usize,
    pub xoff_sent: usize,
    pub xon_sent: usize,
    pub per_tool: BTreeMap<String, ToolTotals>,
    pub travel_mm: f64,
    /// Time the real machine would have taken for the motion, seconds.
    pub simulated_time_s: f64,
    pub faults: Faults,
    /// Why the simulator stopped: `finished`, `stopped`, `hung up (fault)`, `host closed`.
    pub ended: String,
    /// Every tool-down path, device units, machine axes.
    pub paths: Vec<SimPath>,
}

impl SimReport {
    /// Sum of the two protocol-violation counters.
    pub fn violations(&self) -> usize {
        self.overruns + self.flow_violations
    }
}

/// Errors of the simulator.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    #[error("cannot open a pseudo-terminal for the simulated cutter: {0}")]
    Pty(String),
    #[error("the simulated cutter's thread failed")]
    Thread,
    /// Opening the simulator's pty as a serial port.
    #[error(transparent)]
    Serial(#[from] crate::device::serial::SerialError),
    /// Drawing or writing what it cut.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

const RUN: u8 = 0;
const FINISH: u8 = 1;
const STOP: u8 = 2;

/// A running simulator.
pub struct SimHandle {
    /// The slave side's path, e.g. `/dev/pts/7`.
    pub path: String,
    /// The CTS line as the simulated device drives it (true: clear to send).
    pub cts: Arc<AtomicBool>,
    ctl: Arc<AtomicU8>,
    expect: Arc<AtomicUsize>,
    /// Overruns plus flow-control violations so far, as the device counts them.
    violations: Arc<AtomicUsize>,
    /// Bytes received so far.
    received: Arc<AtomicUsize>,
    /// Ticks of the device's loop in which it received, executed or moved.
    progress: Arc<AtomicUsize>,
    thread: Option<JoinHandle<SimReport>>,
}

/// How [`SimHandle::finish_watching`] ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Finish {
    /// The device worked off everything it held.
    Done,
    /// It made no progress (took no byte, executed nothing, did not move) for the idle time.
    Idle,
    /// The cancel flag (Ctrl-C) was raised.
    Cancelled,
}

impl SimHandle {
    /// Let the device work off what it has received, then stop: waits until the input is
    /// executed and no byte has arrived for a moment, or `timeout` passes.
    ///
    /// `bytes_sent` is what the host wrote: the simulator does not call it done before it has
    /// received that many, so a loaded machine's slow pty cannot cut the job short.
    pub fn finish(mut self, bytes_sent: usize, timeout: Duration) -> Result<SimReport, SimError> {
        self.expect.store(bytes_sent, Ordering::SeqCst);
        self.ctl.store(FINISH, Ordering::SeqCst);
        let t = self.thread.take().ok_or(SimError::Thread)?;
        let deadline = Instant::now() + timeout;
        while !t.is_finished() && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(2));
        }
        self.ctl.store(STOP, Ordering::SeqCst);
        t.join().map_err(|_| SimError::Thread)
    }

    /// [`SimHandle::finish`] as a host waits on a machine: as long as the device makes
    /// progress (a busy machine is not a stopped one), until it made none for `idle`, or until
    /// `cancel` is raised (Ctrl-C); then stop it.
    /// `within` caps the whole wait (then it ends as [`Finish::Idle`]).
    pub fn finish_watching(
        mut self,
        bytes_sent: usize,
        idle: Duration,
        within: Duration,
        cancel: &AtomicBool,
    ) -> Result<(SimReport, Finish), SimError> {
        let deadline = Instant::now().checked_add(within);
        self.expect.store(bytes_sent, Ordering::SeqCst);
        self.ctl.store(FINISH, Ordering::SeqCst);
        let t = self.thread.take().ok_or(SimError::Thread)?;
        let mut seen = self.progress.load(Ordering::SeqCst);
        let mut last = Instant::now();
        let end = loop {
            if t.is_finished() {
                break Finish::Done;
            }
            if cancel.load(Ordering::SeqCst) {
                break Finish::Cancelled;
            }
            let now = self.progress.load(Ordering::SeqCst);
            if now != seen {
                seen = now;
                last = Instant::now();
            } else if last.elapsed() > idle {
                break Finish::Idle;
            }
            if deadline.is_some_and(|d| Instant::now() > d) {
                break Finish::Idle;
            }
            std::thread::sleep(Duration::from_millis(2));
        };
        self.ctl.store(STOP, Ordering::SeqCst);
        let rep = t.join().map_err(|_| SimError::Thread)?;
        Ok((rep, end))
    }

    /// Wait until the device has counted a buffer overrun or a flow-control violation, or
    /// `timeout` passes; returns whether it did. A test that provokes one waits for it instead
    /// of sleeping a fixed time.
    pub fn wait_for_violation(&self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        loop {
            if self.violations.load(Ordering::SeqCst) > 0 {
                return true;
            }
            if Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Bytes the device has taken off the line so far (a test can see that nothing of a
    /// sheet arrived before the operator said so).
    pub fn bytes_received(&self) -> usize {
        self.received.load(Ordering::SeqCst)
    }

    /// Stop at once.
    pub fn stop(mut self) -> Result<SimReport, SimError> {
        self.ctl.store(STOP, Ordering::SeqCst);
        self.thread
            .take()
            .ok_or(SimError::Thread)?
            .join()
            .map_err(|_| SimError::Thread)
    }
}

impl Drop for SimHandle {
    fn drop(&mut self) {
        self.ctl.store(STOP, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Open a pseudo-terminal and start the simulator on its master side.
pub fn spawn(cfg: SimConfig) -> Result<SimHandle, SimError> {
    let (master, slave) = serialport::TTYPort::pair().map_err(|e| SimError::Pty(e.to_string()))?;
    // Not inherited by programs started meanwhile: one that held the master open would hide
    // the simulator's hang-up from the host.
    super::serial::close_on_exec(&master);
    super::serial::close_on_exec(&slave);
    let path = slave
        .name()
        .ok_or_else(|| SimError::Pty("the pty has no name".into()))?;
    let cts = Arc::new(AtomicBool::new(true));
    let ctl = Arc::new(AtomicU8::new(RUN));
    let expect = Arc::new(AtomicUsize::new(0));
    let violations = Arc::new(AtomicUsize::new(0));
    let received = Arc::new(AtomicUsize::new(0));
    let progress = Arc::new(AtomicUsize::new(0));
    let (c2, k2, e2, v2) = (cts.clone(), ctl.clone(), expect.clone(), violations.clone());
    let (r2, p2) = (received.clone(), progress.clone());
    let thread = std::thread::Builder::new()
        .name("flatcut-sim".into())
        .spawn(move || machine::Device::new(cfg, master, slave, c2, k2, (e2, v2, r2, p2)).run())
        .map_err(|e| SimError::Pty(e.to_string()))?;
    Ok(SimHandle {
        path,
        cts,
        ctl,
        expect,
        violations,
        received,
        progress,
        thread: Some(thread),
    })
}

/// Draw what the simulator cut, in the machine's axes (mm), and write `<stem>.png` and
/// `<stem>.json` into `dir`. Returns the two paths.
pub(crate) fn write_outputs(
    rep: &SimReport,
    profile: &Profile,
    dir: &Path,
    stem: &str,
) -> Result<(std::path::PathBuf, std::path::PathBuf), SimError> {
    use crate::toolpath::{SheetJob, Stroke, StrokeRole};
    use glam::DVec2;
    let upm = profile.units_per_mm;
    let mut strokes = Vec::new();
    let (mut w, mut h) = (10.0f64, 10.0f64);
    for p in &rep.paths {
        let role = match p.tool.as_str() {
            "cut" => StrokeRole::Cut,
            "score" | "perforate" => StrokeRole::FoldValley,
            "draw" => StrokeRole::Mark,
            _ => StrokeRole::Label,
        };
        let points: Vec<DVec2> = p
            .points
            .iter()
            .map(|q| DVec2::new(q[0] / upm, q[1] / upm))
            .collect();
        for q in &points {
            w = w.max(q.x);
            h = h.max(q.y);
        }
        strokes.push(Stroke {
            role,
            points,
            closed: false,
            piece: None,
            outer: false,
        });
    }
    let sheet = SheetJob {
        width: w.ceil() + 5.0,
        height: h.ceil() + 5.0,
        strokes,
    };
    let px = crate::output::png::DEFAULT_PX_PER_MM;
    let png = crate::output::png::render(&sheet, 0, px)?;
    let png_path = dir.join(format!("{stem}.png"));
    let json_path = dir.join(format!("{stem}.json"));
    crate::output::files::write_in_run(dir, &format!("{stem}.png"), &png)?;
    let text = serde_json::to_string_pretty(rep).unwrap_or_default() + "\n";
    crate::output::files::write_in_run(dir, &format!("{stem}.json"), text.as_bytes())?;
    Ok((png_path, json_path))
}
