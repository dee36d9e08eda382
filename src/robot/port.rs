//! The serial port: raw 8N2 at a given baud rate, one command and its answer
//! at a time with a timeout, and the pacing of actions. Implements the
//! runtime's `Link`.

use std::os::fd::OwnedFd;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use rustix::event::{poll, PollFd, PollFlags, Timespec};
use rustix::fs::{Mode, OFlags};
use rustix::io::Errno;
use rustix::termios::{self, ControlModes, OptionalActions};
use shaping_runtime::robot::protocol::LineBuffer;
use shaping_runtime::robot::{Link, LinkError};

use crate::load::CliError;

/// Puts a terminal into raw mode at `baud` with 8 data bits and 2 stop bits
/// (the Khepera's setting), no flow control.
pub fn make_raw(fd: &OwnedFd, baud: u32) -> rustix::io::Result<()> {
    let mut t = termios::tcgetattr(fd)?;
    t.make_raw();
    t.control_modes |= ControlModes::CSTOPB | ControlModes::CLOCAL | ControlModes::CREAD;
    t.set_speed(baud)?;
    termios::tcsetattr(fd, OptionalActions::Now, &t)
}

/// Sets up the Ctrl-C (and SIGTERM) flag.
pub fn interrupt_flag() -> Result<Arc<AtomicBool>, CliError> {
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&flag))
            .map_err(|e| CliError::io(format!("error: cannot catch Ctrl-C: {e}")))?;
    }
    Ok(flag)
}

/// Waits until `fd` is readable or `deadline` passes; `Ok(false)` on timeout.
pub fn wait_readable(fd: &OwnedFd, deadline: Instant) -> Result<bool, Errno> {
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let ts = Timespec { tv_sec: left.as_secs() as _, tv_nsec: left.subsec_nanos() as _ };
        let mut fds = [PollFd::new(fd, PollFlags::IN)];
        match poll(&mut fds, Some(&ts)) {
            Ok(0) => return Ok(false),
            Ok(_) => {
                let ev = fds[0].revents();
                if ev.intersects(PollFlags::IN) {
                    return Ok(true);
                }
                // Hang-up or error without data.
                return Err(Errno::IO);
            }
            Err(Errno::INTR) => {
                if Instant::now() >= deadline {
                    return Ok(false);
                }
            }
            Err(e) => return Err(e),
        }
    }
}

/// A robot's serial port.
pub struct SerialPort {
    fd: OwnedFd,
    name: String,
    lines: LineBuffer,
    timeout: Duration,
    period: Duration,
    next_tick: Option<Instant>,
    interrupted: Arc<AtomicBool>,
    /// Bytes written and read, for the rate report.
    pub bytes: u64,
}

impl SerialPort {
    /// Opens `path` at `baud`; an answer must come within `timeout`; one
    /// action lasts `period`; `interrupted` is the Ctrl-C flag.
    pub fn open(
        path: &Path,
        baud: u32,
        timeout: Duration,
        period: Duration,
        interrupted: Arc<AtomicBool>,
    ) -> Result<SerialPort, CliError> {
        let name = path.display().to_string();
        let fd = rustix::fs::open(path, OFlags::RDWR | OFlags::NOCTTY | OFlags::CLOEXEC, Mode::empty())
            .map_err(|e| CliError::io(format!("error: cannot open the robot's port `{name}`: {e}")))?;
        make_raw(&fd, baud).map_err(|e| {
            CliError::io(format!("error: `{name}` is not a serial port (or refuses {baud} baud): {e}"))
        })?;
        let _ = termios::tcflush(&fd, termios::QueueSelector::IOFlush);
        Ok(SerialPort {
            fd,
            name,
            lines: LineBuffer::new(),
            timeout,
            period,
            next_tick: None,
            interrupted,
            bytes: 0,
        })
    }

    fn closed(&self) -> LinkError {
        LinkError(format!("the robot closed the link (`{}`)", self.name))
    }

    /// Drops whatever arrived unasked (a late answer after a timeout).
    fn drain(&mut self) -> Result<(), LinkError> {
        self.lines.clear();
        let mut buf = [0u8; 256];
        while wait_readable(&self.fd, Instant::now()).map_err(|_| self.closed())? {
            match rustix::io::read(&self.fd, &mut buf) {
                Ok(0) | Err(_) => return Err(self.closed()),
                Ok(_) => {}
            }
        }
        Ok(())
    }
}

impl Link for SerialPort {
    fn exchange(&mut self, command: &str) -> Result<Vec<u8>, LinkError> {
        self.drain()?;
        let mut out = command.as_bytes();
        while !out.is_empty() {
            match rustix::io::write(&self.fd, out) {
                Ok(n) => out = &out[n..],
                Err(Errno::INTR | Errno::AGAIN) => {}
                Err(_) => return Err(self.closed()),
            }
        }
        self.bytes += command.len() as u64;
        let deadline = Instant::now() + self.timeout;
        let mut buf = [0u8; 256];
        loop {
            if let Some(line) = self.lines.next_line() {
                return line.map_err(|e| {
                    LinkError(format!("garbage on the link after `{}`: {e}", command.trim_end()))
                });
            }
            match wait_readable(&self.fd, deadline) {
                Ok(true) => {}
                Ok(false) => {
                    return Err(LinkError(format!(
                        "no answer to `{}` within {} ms",
                        command.trim_end(),
                        self.timeout.as_millis()
                    )))
                }
                Err(_) => return Err(self.closed()),
            }
            match rustix::io::read(&self.fd, &mut buf) {
                Ok(0) => return Err(self.closed()),
                Ok(n) => {
                    self.bytes += n as u64;
                    self.lines.push(&buf[..n]);
                }
                Err(Errno::INTR | Errno::AGAIN) => {}
                Err(_) => return Err(self.closed()),
            }
        }
    }

    fn wait_action(&mut self) -> Result<(), LinkError> {
        let now = Instant::now();
        let tick = *self.next_tick.get_or_insert(now);
        let until = tick + self.period;
        while Instant::now() < until {
            if self.interrupted.load(Ordering::Relaxed) {
                break;
            }
            std::thread::sleep((until - Instant::now()).min(Duration::from_millis(20)));
        }
        if self.interrupted.load(Ordering::Relaxed) {
            return Err(LinkError("interrupted (Ctrl-C)".into()));
        }
        // The next period starts now (a late action does not shorten it).
        self.next_tick = Some(Instant::now());
        Ok(())
    }
}
