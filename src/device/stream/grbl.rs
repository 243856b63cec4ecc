//! GRBL streaming: the host side of GRBL's character-counting and send-response protocols
//! (GRBL wiki, "Interface", streaming protocols), driven by [`super::send`].
//!
//! Lines are sent while the bytes of the lines not yet answered (`ok` or `error:N`) fit in the
//! device's 128-byte receive buffer; `$` commands are sent alone, after every earlier line is
//! answered and the status says `Idle`, because GRBL executes them only when idle (an `ok`
//! means planned, not done). Before a job the controller is reset
//! (Ctrl-X) and its welcome awaited. `error:N` or `ALARM:N` stops the job with the line, GRBL's
//! meaning and the tool lifted (feed hold, wait for the hold, soft reset, then the cut tool's
//! "up" command).
//!
//! Progress that is not an `ok`: GRBL holds the `ok` of a line that waits for the planner to
//! empty (`M3`/`M4`/`M5`, `S` changes, `G4`, `M2`, and any line once the planner is full), so a
//! long move can hold the next answer for minutes. While a job runs the status is asked with
//! `?` (a real-time byte, never counted in the buffer) five times a second, and a machine
//! whose position moves, that enters `Run`, or that is held (`Hold`, `Door`: a pause waiting
//! for its operator) counts as busy. A machine that says `Run` but stays at one position for
//! the whole timeout has stopped: the timeout is about a machine that makes no progress.
//!
//! At connect the welcome says which GRBL it is (`Grbl 0.9…`: text errors and the 0.9 status,
//! read alike). On GRBL 1.1 a laser profile (tools with `power`) needs laser mode, `$32=1`, and
//! a servo pen needs it off (else `S` changes would not wait for the pen): `$$` is asked and a
//! wrong `$32` refused with the setting to send. Every line is checked against GRBL's 79
//! significant characters before the first byte.
//!
//! ETA: the progress bar counts machine seconds, not bytes: each line's motion time as the
//! simulated GRBL plans it (the profile's `[grbl]` rates and accelerations, junction speeds,
//! dwells), so the bar moves as the machine does.

// A stream error carries the job position for the user; it happens at most once per job.
#![allow(clippy::result_large_err)]

use super::{
    position, Bar, Failure, Position, StreamError, StreamOptions, StreamReport, ToolState,
};
use crate::device::grbl::{self as proto, Response};
use crate::device::serial::Link;
use crate::profile::{Profile, Protocol};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

pub(super) struct Grbl<'a> {
    link: &'a mut Link,
    profile: &'a Profile,
    program: &'a [u8],
    opts: &'a StreamOptions,
    bar: &'a Bar,
    port: String,
    /// Lines to send: (byte offset after the line, text without its ending, 1-based line number
    /// in the file). GRBL ends a line at `\n` or `\r`, so both split here.
    lines: Vec<(usize, String, usize)>,
    /// Lines in the file.
    file_lines: usize,
    /// Lines sent and not yet answered: (index into `lines`, bytes incl. newline).
    pending: std::collections::VecDeque<(usize, usize)>,
    in_flight: usize,
    acked: usize,
    acked_bytes: usize,
    partial: Vec<u8>,
    rep: StreamReport,
    /// Last sign of progress: an answer, a moving position, a busy state.
    last_answer: Instant,
    last_poll: Instant,
    state: String,
    mpos: Option<[f64; 3]>,
    version: proto::Version,
    /// Machine milliseconds from the start to the end of each line of `lines`.
    timeline: Vec<u64>,
}

enum Event {
    Answer(Response),
    Nothing,
}

impl<'a> Grbl<'a> {
    pub(super) fn new(
        link: &'a mut Link,
        profile: &'a Profile,
        program: &'a [u8],
        opts: &'a StreamOptions,
        bar: &'a Bar,
    ) -> Grbl<'a> {
        let mut lines = Vec::new();
        let mut at = 0;
        let mut file_lines = 0;
        for (n, l) in program.split(|&b| b == b'\n').enumerate() {
            for part in l.split(|&b| b == b'\r') {
                at += part.len() + 1;
                let text = String::from_utf8_lossy(part).to_string();
                if !text.trim().is_empty() {
                    lines.push((at.min(program.len()), text, n + 1));
                    file_lines = n + 1;
                }
            }
        }
        let port = link.name.clone();
        Grbl {
            link,
            profile,
            program,
            opts,
            bar,
            port,
            lines,
            file_lines,
            pending: Default::default(),
            in_flight: 0,
            acked: 0,
            acked_bytes: 0,
            partial: Vec::new(),
            rep: StreamReport::default(),
            last_answer: Instant::now(),
            last_poll: Instant::now(),
            state: String::new(),
            mpos: None,
            version: proto::Version::V1_1,
            timeline: Vec::new(),
        }
        .with_timeline()
    }

    /// When a bar is shown: the machine time of every line, and the bar in those units.
    fn with_timeline(mut self) -> Self {
        let Some(b) = &self.bar.bar else {
            return self;
        };
        let mut g = crate::device::sim::grbl::Grbl::new(self.profile);
        let mut t = 0.0f64;
        for (_, text, _) in &self.lines {
            if let Ok(e) = g.execute(text, false) {
                t += e.seconds + e.correction + e.dwell.unwrap_or(0.0);
            }
            self.timeline.push((t.max(0.0) * 1000.0) as u64);
        }
        b.set_length(self.timeline.last().copied().unwrap_or(0).max(1));
        b.set_style(
            indicatif::ProgressStyle::with_template("{spinner} [{bar:32}] {msg} machine ETA {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        self
    }

    fn show_progress(&self) {
        let Some(b) = &self.bar.bar else { return };
        let done = self.pending.front().map_or(self.lines.len(), |&(i, _)| i);
        let ms = done
            .checked_sub(1)
            .and_then(|i| self.timeline.get(i))
            .copied()
            .unwrap_or(0);
        b.set_position(ms);
        let stroke = self.position().stroke;
        b.set_message(format!(
            "line {}/{} stroke {stroke}/{} {}",
            self.acked,
            self.file_lines,
            self.bar.starts.len(),
            self.state
        ));
    }

    fn position(&self) -> Position {
        let bytes = self.acked_bytes;
        let mut p = position(self.bar, bytes, self.program.len());
        p.line = Some(self.acked);
        p.lines_total = self.file_lines;
        p
    }

    /// Read one answer line if there is one (waits at most the poll interval).
    fn poll(&mut self) -> Result<Event, StreamError> {
        if let Some(i) = self.partial.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = self.partial.drain(..=i).collect();
            let text = String::from_utf8_lossy(&line).trim().to_string();
            if text.is_empty() {
                return Ok(Event::Nothing);
            }
            let r = proto::parse_response(&text);
            if let Response::Other(_) | Response::ErrorText(_) | Response::AlarmText(_) = &r {
                self.rep.garbage_bytes += line.len();
            }
            return Ok(Event::Answer(r));
        }
        let mut buf = [0u8; 512];
        match self.link.read_some(&mut buf) {
            Ok(n) => {
                self.partial.extend_from_slice(&buf[..n]);
                if n > 0 && self.partial.contains(&b'\n') {
                    return self.poll();
                }
                Ok(Event::Nothing)
            }
            Err(_) => Err(StreamError::HungUp {
                port: self.port.clone(),
                op: "while streaming G-code",
                at: self.position(),
                tool: ToolState::Unknown,
            }),
        }
    }

    fn write_all(&mut self, bytes: &[u8], op: &'static str) -> Result<(), StreamError> {
        let mut sent = 0;
        let t = Instant::now();
        while sent < bytes.len() {
            match self.link.write_some(&bytes[sent..]) {
                Ok(k) => sent += k,
                Err(_) => {
                    return Err(StreamError::HungUp {
                        port: self.port.clone(),
                        op,
                        at: self.position(),
                        tool: ToolState::Unknown,
                    })
                }
            }
            if t.elapsed() > self.opts.timeout {
                return Err(self.stop(Failure::Timeout(op)));
            }
        }
        Ok(())
    }

    /// Reset the controller and wait for its welcome.
    fn wake(&mut self) -> Result<(), StreamError> {
        self.write_all(&[proto::SOFT_RESET], "resetting GRBL")?;
        let deadline = Instant::now() + self.opts.wake_timeout;
        let mut alarm = false;
        let mut awake = false;
        while Instant::now() < deadline {
            match self.poll()? {
                Event::Answer(Response::Welcome(v)) => {
                    awake = true;
                    self.version = v;
                    // Let the messages that follow the welcome arrive.
                    std::thread::sleep(Duration::from_millis(20));
                }
                Event::Answer(Response::Alarm(_)) => alarm = true,
                Event::Answer(Response::Other(m)) if m.contains("$X") => alarm = true,
                Event::Answer(_) => {}
                Event::Nothing if awake => break,
                Event::Nothing => {}
            }
        }
        if !awake {
            return Err(StreamError::NoWelcome {
                port: self.port.clone(),
                secs: self.opts.wake_timeout.as_secs_f64(),
            });
        }
        self.partial.clear();
        if alarm {
            // Locked by an alarm from before (e.g. reset during motion): unlock, and wait for
            // the answer so that it is not taken for the first line's.
            self.write_all(b"$X\n", "unlocking GRBL after an alarm")?;
            let deadline = Instant::now() + self.opts.wake_timeout;
            loop {
                match self.poll()? {
                    Event::Answer(Response::Ok) => break,
                    Event::Answer(Response::Error(code)) => {
                        return Err(StreamError::Grbl {
                            port: self.port.clone(),
                            code,
                            meaning: proto::error_meaning(code),
                            line: 0,
                            text: "$X (unlock after an alarm)".into(),
                            at: self.position(),
                            tool: ToolState::Unknown,
                        })
                    }
                    _ if Instant::now() > deadline => {
                        return Err(StreamError::NoWelcome {
                            port: self.port.clone(),
                            secs: self.opts.wake_timeout.as_secs_f64(),
                        })
                    }
                    _ => {}
                }
            }
        }
        Ok(())
    }

    fn handle(&mut self, r: Response) -> Result<(), StreamError> {
        // Only answers to lines count as progress: a controller that reports its status but
        // never takes another line (stuck in Hold) must still time out.
        if matches!(r, Response::Ok | Response::Error(_) | Response::Alarm(_)) {
            self.last_answer = Instant::now();
        }
        let r = match r {
            // A 0.9 message flatcut does not know: an error all the same, without a number.
            Response::ErrorText(_) => Response::Error(0),
            Response::AlarmText(_) => Response::Alarm(0),
            r => r,
        };
        match r {
            Response::Ok => {
                if let Some((i, len)) = self.pending.pop_front() {
                    self.in_flight -= len;
                    self.acked = self.lines[i].2;
                    self.acked_bytes = self.lines[i].0;
                    self.rep.lines += 1;
                }
                Ok(())
            }
            Response::Error(code) => {
                let (i, len) = self.pending.pop_front().unwrap_or((self.acked, 0));
                self.in_flight = self.in_flight.saturating_sub(len);
                let text = self.lines.get(i).map(|l| l.1.clone()).unwrap_or_default();
                let line_no = self.lines.get(i).map_or(i + 1, |l| l.2);
                let tool = self.lift();
                Err(StreamError::Grbl {
                    port: self.port.clone(),
                    code,
                    meaning: proto::error_meaning(code),
                    line: line_no,
                    text,
                    at: self.position(),
                    tool,
                })
            }
            Response::Alarm(code) => {
                let tool = self.lift();
                Err(StreamError::Alarm {
                    port: self.port.clone(),
                    code,
                    meaning: proto::alarm_meaning(code),
                    at: self.position(),
                    tool,
                })
            }
            Response::Status(s) => {
                // A moving machine, or one paused by its operator (Hold, Door), is making
                // progress even when no `ok` comes; one that says Run but has not moved for the
                // whole timeout has stopped.
                let moved = s.mpos.is_some() && self.mpos.is_some() && s.mpos != self.mpos;
                let paused = s.busy() && s.state != "Run" && s.state != "Jog";
                if moved || paused || (s.busy() && s.state != self.state) {
                    self.last_answer = Instant::now();
                }
                self.state = s.state;
                if s.mpos.is_some() {
                    self.mpos = s.mpos;
                }
                Ok(())
            }
            Response::Welcome(_) => {
                // The controller reset under us: everything in flight is lost.
                Err(StreamError::HungUp {
                    port: self.port.clone(),
                    op: "while streaming G-code (GRBL reset itself)",
                    at: self.position(),
                    tool: ToolState::Unknown,
                })
            }
            Response::Other(_) | Response::ErrorText(_) | Response::AlarmText(_) => Ok(()),
        }
    }

    /// Stop the job: the tool goes up, and the error says where the job was.
    fn stop(&mut self, f: Failure) -> StreamError {
        let tool = self.lift();
        f.into_error(self.port.clone(), self.position(), tool, self.opts.timeout)
    }

    /// Feed hold, wait for the hold, soft reset, wait for the welcome, then the tool-up
    /// command of the profile's cut tool.
    fn lift(&mut self) -> ToolState {
        if self.link.write_some(&[proto::FEED_HOLD]).is_err() {
            return ToolState::Unknown;
        }
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut last_q = Instant::now() - Duration::from_secs(1);
        while Instant::now() < deadline {
            if last_q.elapsed() > Duration::from_millis(200) {
                if self.link.write_some(&[proto::STATUS_QUERY]).is_err() {
                    return ToolState::Unknown;
                }
                last_q = Instant::now();
            }
            match self.poll() {
                Ok(Event::Answer(Response::Status(s)))
                    if s.state == "Hold:0" || s.state == "Hold" || s.state == "Idle" =>
                {
                    break
                }
                Ok(_) => {}
                Err(_) => return ToolState::Unknown,
            }
        }
        if self.link.write_some(&[proto::SOFT_RESET]).is_err() {
            return ToolState::Unknown;
        }
        let deadline = Instant::now() + Duration::from_secs(3);
        let mut awake = false;
        let mut alarm = false;
        while Instant::now() < deadline {
            match self.poll() {
                Ok(Event::Answer(Response::Welcome(_))) => awake = true,
                Ok(Event::Answer(Response::Alarm(_))) => alarm = true,
                Ok(Event::Nothing) if awake => break,
                Ok(_) => {}
                Err(_) => return ToolState::Unknown,
            }
        }
        if !awake {
            return ToolState::Unknown;
        }
        let mut up = String::new();
        if alarm {
            up.push_str("$X\n");
        }
        if let Some(t) = self.profile.tool(crate::profile::StrokeKind::Cut) {
            if let Some(z) = t.z_up {
                up.push_str(&format!("G0 Z{}\n", crate::output::fmt_mm(z)));
            } else if let Some(s) = t.servo_up {
                up.push_str(&format!("M3 S{}\n", crate::output::fmt_mm(s)));
            }
        }
        up.push_str("M5\n");
        let bytes = up.as_bytes();
        let mut sent = 0;
        let deadline = Instant::now() + Duration::from_secs(2);
        while sent < bytes.len() {
            match self.link.write_some(&bytes[sent..]) {
                Ok(k) => sent += k,
                Err(_) => return ToolState::Unknown,
            }
            if Instant::now() > deadline {
                return ToolState::Unknown;
            }
        }
        let _ = self.link.flush();
        // Wait for the answers so the command is known to be taken.
        let want = up.lines().count();
        let mut got = 0;
        let deadline = Instant::now() + Duration::from_secs(3);
        while got < want && Instant::now() < deadline {
            match self.poll() {
                Ok(Event::Answer(Response::Ok)) => got += 1,
                Ok(Event::Answer(Response::Error(_))) => return ToolState::Unknown,
                Ok(_) => {}
                Err(_) => return ToolState::Unknown,
            }
        }
        if got == want {
            ToolState::Lifted
        } else {
            ToolState::Unknown
        }
    }

    /// Refuse, before the first byte, a line longer than GRBL keeps, and a line holding a
    /// character GRBL's serial reader takes out of the stream wherever it stands, comments
    /// included: `?` (status), `!` (feed hold: the job would stop there and wait for ever),
    /// `~` (cycle start), Ctrl-X (reset), or any byte above 0x7F (GRBL 1.1's overrides and
    /// jog cancel, the rest dropped); and a program pause (`M0`), which would hold the machine
    /// with no one to resume it.
    fn check_lines(&self) -> Result<(), StreamError> {
        for (_, text, line) in &self.lines {
            let what = text.chars().find_map(|c| {
                let named = |what: &str| Some(what.to_string());
                match c {
                    c if c == proto::STATUS_QUERY as char => named("`?` (status report)"),
                    c if c == proto::FEED_HOLD as char => named("`!` (feed hold)"),
                    c if c == proto::CYCLE_START as char => named("`~` (cycle start)"),
                    c if c == proto::SOFT_RESET as char => named("Ctrl-X (reset)"),
                    c if !c.is_ascii() => Some(format!(
                        "a byte that is not ASCII (`{}`)",
                        c.escape_unicode()
                    )),
                    _ => None,
                }
            });
            if let Some(what) = what {
                return Err(StreamError::RealtimeInLine {
                    port: self.port.clone(),
                    line: *line,
                    what,
                });
            }
            // Read as GRBL reads it (`M0`, `M00`, `M-0`, `M0.0` alike).
            let block =
                crate::device::sim::grbl_block::parse(&crate::device::sim::grbl_block::strip(text));
            if block.is_ok_and(|b| b.flow == Some(0)) {
                return Err(StreamError::ProgramPause {
                    port: self.port.clone(),
                    line: *line,
                });
            }
            let len = proto::significant_len(text);
            if len > proto::LINE_MAX {
                return Err(StreamError::LineTooLong {
                    port: self.port.clone(),
                    line: *line,
                    len,
                    max: proto::LINE_MAX,
                });
            }
        }
        Ok(())
    }

    /// GRBL 1.1's laser mode (`$32`) against what the profile's tools need: on for a laser
    /// (`power`), off for a servo pen; other profiles do not ask.
    fn check_laser_mode(&mut self) -> Result<(), StreamError> {
        let tools = self.profile.tools.values();
        let laser = tools
            .clone()
            .any(|t| t.power.is_some() && t.z_down.is_none());
        let servo = tools
            .clone()
            .any(|t| t.servo_down.is_some() && t.z_down.is_none());
        if self.version != proto::Version::V1_1 || !(laser || servo) {
            return Ok(());
        }
        self.write_all(b"$$\n", "asking GRBL for its settings ($$)")?;
        let deadline = Instant::now() + self.opts.wake_timeout;
        let mut mode = None;
        loop {
            match self.poll()? {
                Event::Answer(Response::Ok) => break,
                Event::Answer(Response::Other(l)) => {
                    if let Some(v) = l.strip_prefix("$32=") {
                        mode = v.trim().parse::<f64>().ok();
                    }
                }
                Event::Answer(Response::Error(_)) => break,
                _ if Instant::now() > deadline => {
                    return Err(StreamError::NoWelcome {
                        port: self.port.clone(),
                        secs: self.opts.wake_timeout.as_secs_f64(),
                    })
                }
                _ => {}
            }
        }
        self.rep.garbage_bytes = 0;
        let on = mode.is_some_and(|m| m != 0.0);
        let message = if laser && !on {
            format!(
                "GRBL's laser mode is off ($32={}): profile `{}` drives a laser with M4 and                  needs it on, else every S change stops the machine and G0 moves do not turn                  the beam off; send `$32=1` once from a terminal",
                mode.map_or("?".into(), crate::output::fmt_mm),
                self.profile.name
            )
        } else if servo && !laser && on {
            format!(
                "GRBL's laser mode is on ($32=1): profile `{}` lifts its pen with M3 S, which                  laser mode does not wait for; send `$32=0` once from a terminal",
                self.profile.name
            )
        } else {
            return Ok(());
        };
        Err(StreamError::Settings {
            port: self.port.clone(),
            message,
        })
    }

    pub(super) fn run(mut self) -> Result<StreamReport, StreamError> {
        self.check_lines()?;
        self.wake()?;
        self.check_laser_mode()?;
        let limit = match self.profile.protocol {
            Protocol::GrblSendResponse => 1,
            _ => self.profile.buffer.clamp(1, 1 << 20),
        };
        let send_response = self.profile.protocol == Protocol::GrblSendResponse;
        let mut next = 0;
        self.last_answer = Instant::now();
        while next < self.lines.len() || !self.pending.is_empty() {
            if self.opts.cancel.load(Ordering::SeqCst) {
                return Err(self.stop(Failure::Cancelled));
            }
            // Send what fits.
            if next < self.lines.len() {
                let text = self.lines[next].1.clone();
                let len = text.len() + 1;
                let system = text.trim_start().starts_with('$');
                let fits = if send_response || system {
                    self.pending.is_empty()
                } else {
                    (self.pending.is_empty() || self.in_flight + len <= limit)
                        && !self
                            .pending
                            .front()
                            .is_some_and(|&(i, _)| self.lines[i].1.trim_start().starts_with('$'))
                };
                if fits && system && !matches!(self.state.as_str(), "Idle" | "Alarm" | "Check") {
                    // GRBL refuses most `$` commands while it moves (`error:8`), and an `ok`
                    // only says a line was planned: wait until the status says Idle.
                    if self.last_poll.elapsed() > Duration::from_millis(50) {
                        self.last_poll = Instant::now();
                        self.state.clear();
                        self.write_all(&[proto::STATUS_QUERY], "asking GRBL for its status")?;
                    }
                } else if fits {
                    if system {
                        self.state.clear();
                    }
                    let mut bytes = text.into_bytes();
                    bytes.push(b'\n');
                    self.write_all(&bytes, "sending G-code")?;
                    self.pending.push_back((next, len));
                    self.in_flight += len;
                    next += 1;
                    continue;
                }
            }
            // Wait for an answer.
            match self.poll()? {
                Event::Answer(r) => self.handle(r)?,
                Event::Nothing => {
                    if self.last_answer.elapsed() > self.opts.timeout {
                        return Err(self.stop(Failure::Timeout(
                            "waiting for GRBL to answer `ok` (the machine neither answered nor moved)",
                        )));
                    }
                }
            }
            if self.last_poll.elapsed() > Duration::from_millis(200) {
                self.last_poll = Instant::now();
                self.write_all(&[proto::STATUS_QUERY], "asking GRBL for its status")?;
                self.show_progress();
            }
        }
        let _ = self.link.flush();
        self.rep.bytes = self.program.len();
        Ok(self.rep)
    }
}
