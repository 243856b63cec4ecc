//! The serial transport: opens a port with the profile's settings (overridable by `--port` and
//! `--baud`) through the `serialport` crate, built without its `libudev` feature so that no
//! system package is needed (port listing then reads `/sys/class/tty`).
//!
//! Flow control is done by flatcut itself, not left to the kernel, so that the same code
//! paces a real cutter and the simulated one on a pseudo-terminal:
//! - XON/XOFF: the port is opened without `IXON`; [`super::stream`] reads the device's XON
//!   and XOFF bytes and stops writing while stopped. Writes go out in small chunks paced at
//!   the line rate, so no more than a chunk is ever in the kernel's queue when XOFF arrives.
//! - RTS/CTS: the port is opened with hardware flow control (the UART stops on CTS by
//!   itself) and the CTS line is also read before every chunk. A pseudo-terminal has no modem
//!   lines; for the simulated cutter the transport reads the simulator's CTS flag instead
//!   ([`Link::with_virtual_cts`]). A CTS line that cannot be read is an error, never "clear".
//!
//! The port is taken exclusively while flatcut streams: `serialport` opens it with `TIOCEXCL`
//! (further opens fail with `EBUSY`, except for root) and an exclusive `flock` (which other
//! well-behaved programs honour); a port already held that way is reported as busy.
//!
//! Every port and pseudo-terminal flatcut opens is close-on-exec ([`close_on_exec`]):
//! `serialport` opens them without `O_CLOEXEC`, so a program started meanwhile (by another
//! thread, as the test suite does) inherited them and kept the line open after flatcut
//! closed it: a simulated cutter that hung up went unnoticed until the other program ended.

use crate::profile::{FlowControl, Parity, Profile};
use serialport::SerialPort;
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Errors opening or using a port; each names the port.
#[derive(Debug, thiserror::Error)]
pub enum SerialError {
    #[error("serial port {port}: {message}{hint}")]
    Open {
        port: String,
        message: String,
        hint: &'static str,
    },
}

/// An open line to a device.
pub struct Link {
    port: Box<dyn SerialPort>,
    pub name: String,
    pub baud: u32,
    pub flow: FlowControl,
    virtual_cts: Option<Arc<AtomicBool>>,
    /// Bytes written to the line so far.
    pub written: usize,
}

/// Poll interval of reads and writes; operations loop on it to watch deadlines and Ctrl-C.
pub(crate) const POLL: Duration = Duration::from_millis(20);

/// Open `port` with the profile's serial settings; `baud` overrides the profile's.
pub fn open(profile: &Profile, port: &str, baud: Option<u32>) -> Result<Link, SerialError> {
    let s = &profile.serial;
    let baud = baud.unwrap_or(s.baud);
    let data_bits = match s.data_bits {
        5 => serialport::DataBits::Five,
        6 => serialport::DataBits::Six,
        7 => serialport::DataBits::Seven,
        _ => serialport::DataBits::Eight,
    };
    let parity = match s.parity {
        Parity::None => serialport::Parity::None,
        Parity::Odd => serialport::Parity::Odd,
        Parity::Even => serialport::Parity::Even,
    };
    let stop_bits = if s.stop_bits == 2 {
        serialport::StopBits::Two
    } else {
        serialport::StopBits::One
    };
    let flow = if s.flow_control == FlowControl::RtsCts {
        serialport::FlowControl::Hardware
    } else {
        serialport::FlowControl::None
    };
    let opened = serialport::new(port, baud)
        .data_bits(data_bits)
        .parity(parity)
        .stop_bits(stop_bits)
        .flow_control(flow)
        .timeout(POLL)
        .exclusive(true)
        .open_native()
        .map(|p| {
            close_on_exec(&p);
            Box::new(p) as Box<dyn SerialPort>
        });
    let port_box = opened.map_err(|e| {
        let busy = {
            let d = e.description.to_ascii_lowercase();
            d.contains("lock") || d.contains("busy")
        };
        let hint = match e.kind() {
            serialport::ErrorKind::NoDevice if busy => {
                "; the port is busy: another program (or another flatcut) has it open; close that first, flatcut takes the port for itself while it streams"
            }
            serialport::ErrorKind::NoDevice => {
                "; is the cutter plugged in and switched on? `flatcut ports` lists the ports"
            }
            serialport::ErrorKind::Io(std::io::ErrorKind::NotFound) => {
                "; no such port: `flatcut ports` lists the ports"
            }
            serialport::ErrorKind::Io(std::io::ErrorKind::PermissionDenied) => {
                "; permission denied: add yourself to the `dialout` group"
            }
            _ => "",
        };
        SerialError::Open {
            port: port.to_string(),
            message: e.description,
            hint,
        }
    })?;
    Ok(Link {
        port: port_box,
        name: port.to_string(),
        baud,
        flow: s.flow_control,
        virtual_cts: None,
        written: 0,
    })
}

/// Mark a port's descriptor close-on-exec, so that no program started later inherits the line
/// (see the module doc). Best effort: a descriptor it cannot mark stays as it was.
pub fn close_on_exec(port: &impl std::os::fd::AsRawFd) {
    let fd = port.as_raw_fd();
    // SAFETY: fcntl on a descriptor the port owns and keeps open; F_GETFD/F_SETFD only read
    // and set its flags.
    unsafe {
        let flags = libc::fcntl(fd, libc::F_GETFD);
        if flags >= 0 {
            libc::fcntl(fd, libc::F_SETFD, flags | libc::FD_CLOEXEC);
        }
    }
}

impl Link {
    /// Read CTS from a flag instead of the port (the simulated cutter on a pty).
    pub fn with_virtual_cts(mut self, cts: Arc<AtomicBool>) -> Link {
        self.virtual_cts = Some(cts);
        self
    }

    /// Whether the device lets us send (always true unless the profile uses RTS/CTS). `Err`
    /// when the port cannot report CTS: sending blind could overrun the device.
    pub(crate) fn clear_to_send(&mut self) -> std::io::Result<bool> {
        if self.flow != FlowControl::RtsCts {
            return Ok(true);
        }
        if let Some(c) = &self.virtual_cts {
            return Ok(c.load(Ordering::SeqCst));
        }
        self.port.read_clear_to_send().map_err(std::io::Error::from)
    }

    /// Write some of `bytes`; `Ok(0)` when the port would not take any within `POLL`.
    pub fn write_some(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        match self.port.write(bytes) {
            Ok(0) => Err(std::io::Error::new(
                std::io::ErrorKind::BrokenPipe,
                "the line was closed",
            )),
            Ok(n) => {
                self.written += n;
                Ok(n)
            }
            Err(e) => nothing_yet(e),
        }
    }

    /// Read what has arrived, waiting at most [`POLL`]; `Ok(0)` when nothing came.
    pub(crate) fn read_some(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self.port.read(buf) {
            Ok(0) => Err(std::io::Error::new(
                std::io::ErrorKind::BrokenPipe,
                "the line was closed",
            )),
            Ok(n) => Ok(n),
            Err(e) => nothing_yet(e),
        }
    }

    /// Read what has already arrived without waiting.
    pub(crate) fn read_ready(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = match self.port.bytes_to_read() {
            Ok(n) => n as usize,
            Err(e) => {
                let e = std::io::Error::from(e);
                if e.kind() == std::io::ErrorKind::Interrupted {
                    return Ok(0);
                }
                return Err(e);
            }
        };
        if n == 0 {
            return Ok(0);
        }
        let k = n.min(buf.len());
        self.read_some(&mut buf[..k])
    }

    /// Wait until the kernel has put everything written on the wire.
    pub fn flush(&mut self) -> std::io::Result<()> {
        loop {
            match self.port.flush() {
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                r => return r,
            }
        }
    }
}

/// `Ok(0)` when an operation only found nothing to do yet: its wait timed out, or a signal
/// (Ctrl-C) interrupted it, which is not a fault of the line. Other errors stand.
fn nothing_yet(e: std::io::Error) -> std::io::Result<usize> {
    match e.kind() {
        std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted => Ok(0),
        _ => Err(e),
    }
}

/// Serial ports on this machine: (path, description).
pub(crate) fn list_ports() -> Vec<(String, String)> {
    // Without libudev, serialport reads /sys/class/tty and panics if it is absent.
    if cfg!(target_os = "linux") && !std::path::Path::new("/sys/class/tty").is_dir() {
        return Vec::new();
    }
    let Ok(ports) = std::panic::catch_unwind(serialport::available_ports) else {
        return Vec::new();
    };
    let mut out: Vec<(String, String)> = ports
        .unwrap_or_default()
        .into_iter()
        .map(|p| {
            let what = match p.port_type {
                serialport::SerialPortType::UsbPort(u) => format!(
                    "USB {:04x}:{:04x}{}{}",
                    u.vid,
                    u.pid,
                    u.manufacturer.map(|m| format!(" {m}")).unwrap_or_default(),
                    u.product.map(|m| format!(" {m}")).unwrap_or_default()
                ),
                serialport::SerialPortType::PciPort => "PCI serial port".into(),
                serialport::SerialPortType::BluetoothPort => "Bluetooth serial port".into(),
                serialport::SerialPortType::Unknown => "serial port".into(),
            };
            (p.port_name, what)
        })
        .collect();
    out.sort();
    out
}
