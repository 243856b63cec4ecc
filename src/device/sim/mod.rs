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
//!   stream into the simulator.
//! - **Execution.** HP-GL and GP-GL (`gpgl`) instructions are executed one at a time, each when the previous
//!   motion has finished; GRBL lines move from the receive buffer into a 15-block planner and
//!   are answered `ok` (or `error:N`) when planned, as GRBL does. Motion takes the time the
//!   interpreters compute (`hpgl`, [`grbl`]) divided by the time factor (`None`: no time).
//!   GRBL real-time bytes (`?`, `!`, `~`, Ctrl-X) act on arrival and are never buffered.
//! - **Faults** for tests ([`Faults`]): hang up after N bytes, stall (stop reading and
//!   executing) after N bytes, send garbage after N bytes, lose the XONs, answer a given
//!   GRBL line with `error:N`.
//!
//! Everything it cuts is recorded (`record`) and, on [`SimHandle::finish`], summarised in a
//! [`SimReport`] (written as `sim.json`) and drawn as `sim.png`, in the machine's own axes.

pub(crate) mod gpgl;
pub mod grbl;
mod grbl_block;
pub(crate) mod hpgl;
pub(crate) mod record;

use crate::device::grbl as proto;
use crate::profile::{FlowControl, Language, Profile};
pub use record::SimPath;
use serde::Serialize;
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
}

impl SimConfig {
    pub fn new(profile: Profile) -> SimConfig {
        SimConfig {
            profile,
            time_factor: None,
            faults: Faults::default(),
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
    /// Bytes left in the buffer at the end that never made a whole instruction or line.
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
        .spawn(move || Device::new(cfg, master, slave, c2, k2, (e2, v2, r2, p2)).run())
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

use serialport::SerialPort;

/// One direction of a serial line: bytes complete one every `1 / rate` seconds.
struct Line {
    byte_time: f64,
    /// When the last byte taken finished arriving.
    busy_until: Instant,
    /// Nothing was waiting at the last look.
    idle: bool,
}

impl Line {
    fn new(rate: f64) -> Line {
        Line {
            byte_time: 1.0 / rate,
            busy_until: Instant::now(),
            idle: true,
        }
    }

    /// How many of `waiting` bytes have finished crossing the line by `now`.
    fn ready(&mut self, now: Instant, waiting: usize) -> usize {
        if waiting == 0 {
            self.idle = true;
            return 0;
        }
        if self.idle {
            // First sight of a byte after an idle line: it started at most one loop sleep
            // (a quarter millisecond) ago; the line cannot have carried it any earlier.
            self.idle = false;
            let floor = now - Duration::from_micros(250);
            if self.busy_until < floor {
                self.busy_until = floor;
            }
        }
        let elapsed = now.saturating_duration_since(self.busy_until).as_secs_f64();
        ((elapsed / self.byte_time) as usize).min(waiting)
    }

    fn took(&mut self, n: usize) {
        self.busy_until += Duration::from_secs_f64(n as f64 * self.byte_time);
    }
}

// One interpreter per simulator: the size of the enum does not matter.
#[allow(clippy::large_enum_variant)]
enum Interp {
    Hpgl(hpgl::Hpgl),
    Grbl(grbl::Grbl),
    Gpgl(gpgl::Gpgl),
}

struct Device {
    cfg: SimConfig,
    master: Option<serialport::TTYPort>,
    /// Kept open so that the master side does not see a hang-up between clients.
    slave: Option<serialport::TTYPort>,
    cts: Arc<AtomicBool>,
    ctl: Arc<AtomicU8>,
    expect: Arc<AtomicUsize>,
    violations: Arc<AtomicUsize>,
    received: Arc<AtomicUsize>,
    progress: Arc<AtomicUsize>,
    interp: Interp,
    rx: VecDeque<u8>,
    cap: usize,
    high: usize,
    low: usize,
    flow: FlowControl,
    /// The host has been told to stop (XOFF sent or CTS dropped).
    stopped: bool,
    stopped_at: Option<Instant>,
    taken_since_stop: usize,
    backlog_at_grace: Option<usize>,
    /// Remaining seconds (real time) of each queued motion.
    motion: VecDeque<f64>,
    held: bool,
    /// GRBL: an `ok` (and maybe a pause) owed once the planner is empty (after a `G4`).
    owed_ok: Option<bool>,
    /// GRBL: `M0` holds its `ok` until cycle start.
    ok_on_resume: bool,
    grbl_lines: usize,
    garbage_sent: bool,
    stalled: bool,
    rep: SimReport,
    /// Answers produced, then queued for the line.
    out: Vec<u8>,
    tx: VecDeque<u8>,
    /// Flow-control characters, sent at once.
    urgent: Vec<u8>,
}

impl Device {
    fn new(
        cfg: SimConfig,
        master: serialport::TTYPort,
        slave: serialport::TTYPort,
        cts: Arc<AtomicBool>,
        ctl: Arc<AtomicU8>,
        (expect, violations, received, progress): (
            Arc<AtomicUsize>,
            Arc<AtomicUsize>,
            Arc<AtomicUsize>,
            Arc<AtomicUsize>,
        ),
    ) -> Device {
        let p = &cfg.profile;
        let grbl = p.language == Language::Gcode;
        let cap = p.buffer.max(1);
        let headroom = (cap / 4).clamp(16.min(cap / 2).max(1), 256);
        let flow = if grbl {
            FlowControl::None
        } else {
            p.serial.flow_control
        };
        let interp = match p.language {
            Language::Gcode => Interp::Grbl(grbl::Grbl::new(p)),
            Language::Hpgl => Interp::Hpgl(hpgl::Hpgl::new(p)),
            Language::Gpgl => Interp::Gpgl(gpgl::Gpgl::new(p)),
        };
        let rep = SimReport {
            device: p.name.clone(),
            language: format!("{:?}", p.language).to_lowercase(),
            baud: p.serial.baud,
            flow_control: format!("{:?}", flow),
            buffer: cap,
            faults: cfg.faults.clone(),
            ..SimReport::default()
        };
        Device {
            master: Some(master),
            slave: Some(slave),
            cts,
            ctl,
            expect,
            violations,
            received,
            progress,
            interp,
            rx: VecDeque::with_capacity(cap),
            cap,
            high: cap.saturating_sub(headroom).max(1),
            low: cap / 4,
            flow,
            stopped: false,
            stopped_at: None,
            taken_since_stop: 0,
            backlog_at_grace: None,
            motion: VecDeque::new(),
            held: false,
            owed_ok: None,
            ok_on_resume: false,
            grbl_lines: 0,
            garbage_sent: false,
            stalled: false,
            rep,
            out: Vec::new(),
            tx: VecDeque::new(),
            urgent: Vec::new(),
            cfg,
        }
    }

    fn run(mut self) -> SimReport {
        let rate = self.cfg.profile.serial.baud.max(1) as f64 / 10.0;
        // Line clocks: when the byte now on each wire will have arrived. A byte that finds
        // the line idle starts when it is first seen, so it still takes its ten bit times.
        let mut rx_line = Line::new(rate);
        let mut tx_line = Line::new(rate);
        let mut last = Instant::now();
        let mut quiet_since = Instant::now();
        let mut buf = vec![0u8; 4096];
        self.rep.ended = "stopped".into();
        loop {
            let ctl = self.ctl.load(Ordering::SeqCst);
            if ctl == STOP {
                break;
            }
            let now = Instant::now();
            let dt = now.duration_since(last).as_secs_f64();
            last = now;

            // Receive.
            let Some(waiting) = self
                .master
                .as_mut()
                .map(|m| m.bytes_to_read().unwrap_or(0) as usize)
            else {
                break;
            };
            let on_line = rx_line.ready(now, waiting);
            let mut allowance = on_line;
            if self.stopped {
                allowance = allowance.min(SKID.saturating_sub(self.taken_since_stop));
                self.watch_backlog(waiting);
            }
            // With flow control the device asks to stop the moment the high-water mark is
            // reached: take no more than that in one read, so the request goes out in time.
            if !self.stopped && self.flow != FlowControl::None {
                allowance = allowance.min(self.high.saturating_sub(self.rx.len()).max(1));
            }
            let n = allowance.min(waiting).min(buf.len());
            if n < on_line {
                // Held back by flow control: those bytes are still at the host, and the line
                // clock starts again when they are let through.
                rx_line.idle = true;
            }
            if n > 0 {
                let Some(master) = self.master.as_mut() else {
                    break;
                };
                match master.read(&mut buf[..n]) {
                    Ok(k) => {
                        rx_line.took(k);
                        quiet_since = now;
                        for &b in &buf[..k] {
                            self.receive(b);
                        }
                        if self.stopped {
                            self.taken_since_stop += k;
                        }
                    }
                    Err(e)
                        if matches!(
                            e.kind(),
                            std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                        ) => {}
                    Err(_) => {
                        self.rep.ended = "host closed".into();
                        break;
                    }
                }
            }
            if self.faults_due() {
                break;
            }

            // Execute.
            if !self.stalled {
                self.advance(dt);
                self.execute();
            }
            self.flow_control();
            // Answers go back at the line rate too (XON/XOFF jump the queue, as a UART
            // sends its flow-control characters ahead of pending data).
            self.tx.extend(self.out.drain(..));
            let mut send: Vec<u8> = std::mem::take(&mut self.urgent);
            let k = tx_line.ready(now, self.tx.len());
            send.extend(self.tx.drain(..k));
            tx_line.took(k);
            if !send.is_empty() {
                if let Some(m) = self.master.as_mut() {
                    if m.write_all(&send).is_err() {
                        self.rep.ended = "host closed".into();
                        break;
                    }
                }
            }

            if ctl == FINISH
                && (self.rep.bytes_received >= self.expect.load(Ordering::SeqCst)
                    || self.stalled
                    || self.stopped)
                && (self.stalled
                    || (waiting == n && !self.has_complete_input() && self.motion.is_empty()))
                && self.tx.is_empty()
                && now.duration_since(quiet_since) > Duration::from_millis(30)
            {
                self.rep.unexecuted_bytes = self.rx.len();
                self.rep.ended = "finished".into();
                break;
            }
            self.violations
                .store(self.rep.violations(), Ordering::SeqCst);
            self.received
                .store(self.rep.bytes_received, Ordering::SeqCst);
            let busy = n > 0 || !self.tx.is_empty() || (!self.stalled && self.has_complete_input());
            if n > 0 || (!self.stalled && (!self.motion.is_empty() || self.has_complete_input())) {
                self.progress.fetch_add(1, Ordering::Relaxed);
            }
            std::thread::sleep(Duration::from_micros(if busy { 100 } else { 300 }));
        }
        self.close()
    }

    /// Whether the buffer holds a whole instruction or line (what is left is a fragment that
    /// no further byte will complete once the host is done).
    fn has_complete_input(&self) -> bool {
        match self.interp {
            Interp::Hpgl(_) => {
                crate::output::hpgl::read::next_instruction(self.rx.iter()).is_some()
            }
            Interp::Grbl(_) => self.rx.iter().any(|&b| b == b'\n' || b == b'\r'),
            Interp::Gpgl(_) => crate::output::gpgl::next_instruction(self.rx.iter()).is_some(),
        }
    }

    /// After a stop, check that the host stops adding bytes to the pty.
    fn watch_backlog(&mut self, waiting: usize) {
        let Some(at) = self.stopped_at else { return };
        if at.elapsed() < STOP_GRACE {
            return;
        }
        match self.backlog_at_grace {
            None => self.backlog_at_grace = Some(waiting),
            Some(b) if waiting > b => {
                self.rep.flow_violations += waiting - b;
                self.backlog_at_grace = Some(waiting);
            }
            _ => {}
        }
    }

    fn receive(&mut self, b: u8) {
        self.rep.bytes_received += 1;
        // A stalled device still fills its buffer (and asks to stop) but answers nothing.
        if self.stalled {
            self.buffer(b);
            return;
        }
        if let Interp::Grbl(g) = &mut self.interp {
            match b {
                proto::STATUS_QUERY => {
                    let state = if g.alarm {
                        "Alarm"
                    } else if self.held {
                        "Hold:0"
                    } else if self.motion.is_empty() && self.rx.is_empty() {
                        "Idle"
                    } else {
                        "Run"
                    };
                    let s = g.status(state);
                    self.out.extend_from_slice(s.as_bytes());
                    self.out.extend_from_slice(b"\r\n");
                    return;
                }
                proto::FEED_HOLD => {
                    self.held = true;
                    return;
                }
                proto::CYCLE_START => {
                    self.held = false;
                    if std::mem::take(&mut self.ok_on_resume) {
                        self.out.extend_from_slice(b"ok\r\n");
                    }
                    return;
                }
                proto::SOFT_RESET => {
                    let in_motion = !self.motion.is_empty() && !self.held;
                    self.rx.clear();
                    self.motion.clear();
                    self.held = false;
                    self.owed_ok = None;
                    self.ok_on_resume = false;
                    g.reset();
                    if in_motion {
                        g.alarm = true;
                        self.rep.alarms.push(3);
                    }
                    let welcome = welcome(g, in_motion);
                    self.out.extend_from_slice(welcome.as_bytes());
                    return;
                }
                _ => {}
            }
        }
        self.buffer(b);
    }

    fn buffer(&mut self, b: u8) {
        if self.rx.len() >= self.cap {
            self.rep.overruns += 1;
            return;
        }
        self.rx.push_back(b);
        self.rep.max_buffer_fill = self.rep.max_buffer_fill.max(self.rx.len());
    }

    /// Run down queued motion by `dt` real seconds.
    fn advance(&mut self, dt: f64) {
        if self.held {
            return;
        }
        let mut left = dt;
        while let Some(front) = self.motion.front_mut() {
            if *front > left {
                *front -= left;
                break;
            }
            left -= *front;
            self.motion.pop_front();
        }
    }

    fn scaled(&self, seconds: f64) -> Option<f64> {
        scale_time(self.cfg.time_factor, seconds)
    }

    fn execute(&mut self) {
        loop {
            match &mut self.interp {
                Interp::Hpgl(m) => {
                    if !self.motion.is_empty() {
                        return;
                    }
                    let instr: Vec<u8> = if let Some(n) =
                        crate::output::hpgl::read::next_instruction(self.rx.iter())
                    {
                        self.rx.drain(..n).collect()
                    } else if let Some((n, op)) = hpgl::executable_prefix(self.rx.iter()) {
                        let part = self.rx.drain(..n).collect();
                        self.rx.push_front(op[1]);
                        self.rx.push_front(op[0]);
                        part
                    } else {
                        return;
                    };
                    let t = m.execute(&instr);
                    self.rep.simulated_time_s += t;
                    if let Some(s) = self.scaled(t) {
                        self.motion.push_back(s);
                    }
                }
                Interp::Gpgl(m) => {
                    if !self.motion.is_empty() {
                        return;
                    }
                    let Some(n) = crate::output::gpgl::next_instruction(self.rx.iter()) else {
                        return;
                    };
                    let instr: Vec<u8> = self.rx.drain(..n).collect();
                    let t = m.execute(&instr);
                    self.rep.simulated_time_s += t;
                    if let Some(s) = self.scaled(t) {
                        self.motion.push_back(s);
                    }
                }
                Interp::Grbl(_) => {
                    if !self.execute_grbl() {
                        return;
                    }
                }
            }
        }
    }

    /// Take one GRBL line off the buffer and answer it; false when nothing more can run now.
    fn execute_grbl(&mut self) -> bool {
        let tf = self.cfg.time_factor;
        let Interp::Grbl(g) = &mut self.interp else {
            return false;
        };
        if self.held || self.motion.len() >= PLANNER_BLOCKS {
            return false;
        }
        if let Some(pause) = self.owed_ok {
            // GRBL's main loop is in the dwell: nothing else is read until it ends.
            if !self.motion.is_empty() {
                return false;
            }
            self.owed_ok = None;
            if pause {
                self.held = true;
                self.ok_on_resume = true;
            } else {
                self.out.extend_from_slice(b"ok\r\n");
            }
        }
        let Some(end) = self.rx.iter().position(|&b| b == b'\n' || b == b'\r') else {
            return false;
        };
        let line = String::from_utf8_lossy(&self.rx.iter().take(end).copied().collect::<Vec<u8>>())
            .to_string();
        // Sync commands wait (their line stays in the buffer) until the planner is empty.
        if !self.motion.is_empty() && g.needs_sync(&line) {
            return false;
        }
        self.rx.drain(..=end);
        if self.motion.is_empty() && self.cfg.time_factor.is_some() {
            g.planner.stop();
        }
        self.grbl_lines += 1;
        let injected = self
            .cfg
            .faults
            .grbl_error
            .filter(|(k, _)| *k == self.grbl_lines)
            .map(|(_, c)| c);
        let busy = !self.motion.is_empty();
        let result = match injected {
            Some(c) => Err(c),
            None => g.execute(&line, busy),
        };
        match result {
            Ok(e) => {
                self.rep.simulated_time_s += e.seconds + e.correction + e.dwell.unwrap_or(0.0);
                if let Some(c) = scale_time(tf, -e.correction) {
                    if let Some(back) = self.motion.back_mut() {
                        *back = (*back - c).max(0.0);
                    }
                }
                if let Some(s) = scale_time(tf, e.seconds) {
                    self.motion.push_back(s);
                }
                for l in &e.text {
                    self.out.extend_from_slice(l.as_bytes());
                    self.out.extend_from_slice(b"\r\n");
                }
                if let Some(d) = e.dwell {
                    if let Some(s) = scale_time(tf, d) {
                        self.motion.push_back(s);
                    }
                    self.owed_ok = Some(e.pause);
                    return true;
                }
                if e.pause {
                    // GRBL holds in the middle of the line: its `ok` comes after cycle start.
                    self.held = true;
                    self.ok_on_resume = true;
                } else {
                    self.out.extend_from_slice(b"ok\r\n");
                }
                if e.reset {
                    g.reset();
                    let w = welcome(g, false);
                    self.out.extend_from_slice(w.as_bytes());
                }
            }
            Err(code) => {
                self.rep.errors_sent.push((self.grbl_lines, code));
                let msg = if g.v0_9 {
                    format!("error: {}\r\n", proto::error_text_0_9(code))
                } else {
                    format!("error:{code}\r\n")
                };
                self.out.extend_from_slice(msg.as_bytes());
            }
        }
        true
    }

    fn flow_control(&mut self) {
        let fill = self.rx.len();
        match self.flow {
            FlowControl::None => {}
            FlowControl::XonXoff | FlowControl::RtsCts => {
                if !self.stopped && fill >= self.high {
                    self.stopped = true;
                    self.stopped_at = Some(Instant::now());
                    self.taken_since_stop = 0;
                    self.backlog_at_grace = None;
                    if self.flow == FlowControl::XonXoff {
                        self.urgent.push(XOFF);
                        self.rep.xoff_sent += 1;
                    } else {
                        self.cts.store(false, Ordering::SeqCst);
                    }
                } else if self.stopped && fill <= self.low && !self.stalled {
                    if self.flow == FlowControl::XonXoff {
                        // With `lose_xon` the XON is lost on the line: the device believes it
                        // sent it.
                        if !self.cfg.faults.lose_xon {
                            self.urgent.push(XON);
                            self.rep.xon_sent += 1;
                        }
                    } else {
                        self.cts.store(true, Ordering::SeqCst);
                    }
                    self.stopped = false;
                    self.stopped_at = None;
                }
            }
        }
    }

    /// Inject due faults; true when the line was hung up.
    fn faults_due(&mut self) -> bool {
        let got = self.rep.bytes_received;
        let f = self.cfg.faults.clone();
        if f.hang_up_after.is_some_and(|n| got >= n) {
            self.master = None;
            self.slave = None;
            self.rep.ended = "hung up (fault)".into();
            return true;
        }
        if f.stall_after.is_some_and(|n| got >= n) {
            self.stalled = true;
            self.motion.clear();
        }
        if !self.garbage_sent && f.garbage_after.is_some_and(|n| got >= n) {
            self.garbage_sent = true;
            self.out
                .extend_from_slice(b"\xfe\xff#%&garbage\x07\x00\xc3\r\n~~\xa5\r\n");
        }
        false
    }

    fn close(mut self) -> SimReport {
        let (rec, upm) = match &self.interp {
            Interp::Hpgl(m) => {
                self.rep.executed = m.instructions;
                self.rep.tool_down_at_end = m.tool_down();
                self.rep.ignored = m.ignored.clone();
                (m.rec.clone(), self.cfg.profile.units_per_mm)
            }
            Interp::Gpgl(m) => {
                self.rep.executed = m.instructions;
                self.rep.tool_down_at_end = m.tool_down();
                self.rep.ignored = m.ignored.clone();
                (m.rec.clone(), self.cfg.profile.units_per_mm)
            }
            Interp::Grbl(g) => {
                self.rep.executed = g.lines_ok;
                self.rep.tool_down_at_end = g.tool_down_now();
                (g.rec.clone(), self.cfg.profile.units_per_mm)
            }
        };
        for p in &rec.paths {
            let t = self.rep.per_tool.entry(p.tool.clone()).or_default();
            t.strokes += 1;
            t.length_mm += p.length() / upm;
        }
        self.rep.travel_mm = rec.travel / upm;
        self.rep.paths = rec.paths;
        if self.rep.ended == "stopped" && self.master.is_none() {
            self.rep.ended = "hung up (fault)".into();
        }
        let _ = self.slave.take();
        self.rep
    }
}

/// Real seconds of `seconds` of machine time at time factor `tf` (`None`: motion takes none).
fn scale_time(tf: Option<f64>, seconds: f64) -> Option<f64> {
    match tf {
        Some(f) if f > 0.0 && seconds > 0.0 => Some(seconds / f),
        _ => None,
    }
}

/// What GRBL prints after a reset: the alarm when it was reset in motion, the welcome, the
/// unlock hint (1.1 or 0.9 words, by the profile).
fn welcome(g: &grbl::Grbl, alarm: bool) -> String {
    let mut s = String::new();
    if alarm {
        s.push_str(if g.v0_9 {
            "ALARM: Abort during cycle\r\n"
        } else {
            "ALARM:3\r\n"
        });
    }
    s.push_str("\r\n");
    s.push_str(if g.v0_9 {
        proto::WELCOME_0_9
    } else {
        proto::WELCOME
    });
    s.push_str("\r\n");
    if g.alarm {
        s.push_str(if g.v0_9 {
            "['$H'|'$X' to unlock]\r\n"
        } else {
            "[MSG:'$H'|'$X' to unlock]\r\n"
        });
    }
    s
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
