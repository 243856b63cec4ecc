//! The simulated cutter's machine: the thread on the far end of the pseudo-terminal that takes
//! bytes at the line's rate into a finite buffer, enforces the profile's flow control, hands
//! complete instructions to the interpreter of its language (HP-GL, GP-GL, GRBL) and answers as
//! the device would. [`super::spawn`] starts it; [`super::SimHandle`] steers it.

use super::*;
use glam::DVec3;
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
    pub(super) fn new(rate: f64) -> Line {
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

pub(super) struct Device {
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
    /// Each queued motion, the one in progress first.
    motion: VecDeque<Queued>,
    held: bool,
    /// GRBL: an `ok` (and maybe a pause) owed once the planner is empty (after a `G4`).
    owed_ok: Option<bool>,
    /// GRBL: `M0` holds its `ok` until cycle start.
    ok_on_resume: bool,
    grbl_lines: usize,
    garbage_sent: bool,
    /// The device answers HP's `ESC . B` (profile `status_query = "esc-b"`).
    esc_b: bool,
    /// Bytes of a device-control sequence (`ESC . X`) read so far.
    esc: u8,
    /// With `esc_b`: data bytes read past the skid while the host is held off, which a
    /// stopped transmitter would still hold (taken into the buffer when the stop ends).
    held_back: VecDeque<u8>,
    /// With `esc_b`, in a stop: the grace is over and the line ran dry once.
    drained: bool,
    stalled: bool,
    rep: SimReport,
    /// Answers produced, then queued for the line.
    out: Vec<u8>,
    tx: VecDeque<u8>,
    /// Flow-control characters, sent at once.
    urgent: Vec<u8>,
}

impl Device {
    pub(super) fn new(
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
            Language::Gcode => {
                let mut g = grbl::Grbl::new(p);
                if p.registration.sensor == crate::profile::registration::Sensor::GrblProbe {
                    g.probe = cfg.printed.as_ref().map(|s| sensor::Sensor::new(s, p));
                }
                Interp::Grbl(g)
            }
            Language::Hpgl => {
                let mut m = hpgl::Hpgl::new(p);
                if p.registration.sensor == crate::profile::registration::Sensor::HpglDigitize {
                    m.sensor = cfg.printed.as_ref().map(|s| sensor::Sensor::new(s, p));
                }
                Interp::Hpgl(m)
            }
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
            esc_b: !grbl && p.serial.status_query == crate::profile::StatusQuery::EscB,
            esc: 0,
            held_back: VecDeque::new(),
            drained: false,
            stalled: false,
            rep,
            out: Vec::new(),
            tx: VecDeque::new(),
            urgent: Vec::new(),
            cfg,
        }
    }

    pub(super) fn run(mut self) -> SimReport {
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
            // A device with an output channel reads on while it holds the host off, to answer
            // device-control queries (a stalled one reads no more than any other).
            if self.stopped && (!self.esc_b || self.stalled) {
                allowance = allowance.min(SKID.saturating_sub(self.taken_since_stop));
                self.watch_backlog(waiting);
            }
            // What the host had written before it stopped is its due, however much of it the
            // kernel still holds: once the grace is over and the line has run dry, any more
            // data is a host that did not stop.
            if self.stopped
                && self.esc_b
                && waiting == 0
                && self.stopped_at.is_some_and(|t| t.elapsed() >= STOP_GRACE)
            {
                self.drained = true;
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
                        if self.stopped && (!self.esc_b || self.stalled) {
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
                self.rep.ended = if self.stalled {
                    "stalled (fault)".into()
                } else {
                    "finished".into()
                };
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
        // Device-control queries are not data: they are not counted as received.
        if self.esc_b && !self.stalled && self.device_control(b) {
            return;
        }
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
                    // Where the machine is: along the move in progress, as GRBL counts its
                    // steps, or at the end of the last line when nothing moves.
                    let at = self.motion.front().map_or(g.pos, Queued::position);
                    let s = g.status(state, at);
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

    /// HP's RS-232 device control, handled as bytes arrive, ahead of the buffer: `ESC . B` is
    /// answered with the free buffer space and CR; other `ESC . X` sequences are taken and
    /// ignored. True when `b` was part of one, or was held back: while the host is held off the
    /// device reads on (to see the queries), takes a skid's worth of data and holds the rest
    /// back as a stopped transmitter would; data that still arrives once the grace
    /// ([`STOP_GRACE`]) is over and the line has run dry is a flow-control violation.
    fn device_control(&mut self, b: u8) -> bool {
        match (self.esc, b) {
            (0, 0x1b) => {
                self.esc = 1;
                return true;
            }
            (1, b'.') => {
                self.esc = 2;
                return true;
            }
            (2, c) => {
                self.esc = 0;
                if c == b'B' {
                    let free = self.cap.saturating_sub(self.rx.len());
                    self.out.extend_from_slice(format!("{free}\r").as_bytes());
                }
                return true;
            }
            _ => self.esc = 0,
        }
        if self.stopped {
            if self.taken_since_stop < SKID {
                self.taken_since_stop += 1;
                return false;
            }
            self.rep.bytes_received += 1;
            self.held_back.push_back(b);
            // What the host had written before it stopped is not held against it; what comes
            // once the line has run dry is.
            if self.drained {
                self.rep.flow_violations += 1;
            }
            return true;
        }
        false
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
            if front.left > left {
                front.left -= left;
                break;
            }
            left -= front.left;
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
                    self.out.append(&mut m.out);
                    self.rep.simulated_time_s += t;
                    if let Some(s) = self.scaled(t) {
                        self.motion
                            .push_back(Queued::new(s, DVec3::ZERO, DVec3::ZERO));
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
                        self.motion
                            .push_back(Queued::new(s, DVec3::ZERO, DVec3::ZERO));
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
        let from = g.pos;
        let result = match injected {
            Some(c) => Err(c),
            None => g.execute(&line, busy),
        };
        match result {
            Ok(e) => {
                self.rep.simulated_time_s += e.seconds + e.correction + e.dwell.unwrap_or(0.0);
                if let Some(c) = scale_time(tf, -e.correction) {
                    if let Some(back) = self.motion.back_mut() {
                        back.left = (back.left - c).max(0.0);
                        back.total = (back.total - c).max(back.left);
                    }
                }
                if let Some(s) = scale_time(tf, e.seconds) {
                    self.motion.push_back(Queued::new(s, from, g.pos));
                }
                for l in &e.text {
                    self.out.extend_from_slice(l.as_bytes());
                    self.out.extend_from_slice(b"\r\n");
                }
                if let Some(d) = e.dwell {
                    if let Some(s) = scale_time(tf, d) {
                        self.motion.push_back(Queued::new(s, g.pos, g.pos));
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
                    self.drained = false;
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
                    while let Some(b) = self.held_back.pop_front() {
                        self.buffer(b);
                    }
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
        // However it ended (finished, hung up, stopped), what is still buffered was not run.
        self.rep.unexecuted_bytes = self.rx.len();
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

/// One queued motion: the real seconds left of its whole, and the straight line it takes
/// (an arc reports its chord: the status position is only for a host to see motion).
struct Queued {
    left: f64,
    total: f64,
    from: DVec3,
    to: DVec3,
}

impl Queued {
    /// `seconds` from `from` to `to` (the same point for a dwell, and for an HP-GL or GP-GL
    /// instruction, whose position is never asked).
    fn new(seconds: f64, from: DVec3, to: DVec3) -> Self {
        Queued {
            left: seconds,
            total: seconds,
            from,
            to,
        }
    }

    fn position(&self) -> DVec3 {
        let done = if self.total > 0.0 {
            (1.0 - self.left / self.total).clamp(0.0, 1.0)
        } else {
            1.0
        };
        self.from.lerp(self.to, done)
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
