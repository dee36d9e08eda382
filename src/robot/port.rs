//! The serial port: 8N2 at a given baud rate, one command and its answer at
//! a time with a timeout, and the pacing of actions. Implements the
//! runtime's `Link` over the `serialport` crate, so that a real Khepera can
//! be driven from Unix and Windows alike (the emulator's pseudo-terminal is
//! Unix only: `emulate.rs`).

use std::io::{ErrorKind, Read as _, Write as _};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use serialport::{ClearBuffer, DataBits, FlowControl, Parity, StopBits};
use shaping_runtime::robot::protocol::LineBuffer;
use shaping_runtime::robot::{Link, LinkError};

use crate::CliError;

/// Sets up the flag that every signal that would end the process sets
/// (Ctrl-C, SIGTERM, SIGHUP from a closed terminal or ssh session, SIGQUIT,
/// SIGXCPU, ...: `crate::signals`): the robot is stopped and the trace kept
/// on each.
pub fn interrupt_flag() -> Result<Arc<AtomicBool>, CliError> {
    let flag = Arc::new(AtomicBool::new(false));
    crate::signals::register(&flag, false)
        .map_err(|e| CliError::io(format!("error: cannot catch Ctrl-C and the other signals: {e}")))?;
    Ok(flag)
}

/// A robot's serial port.
pub struct SerialPort {
    port: Box<dyn serialport::SerialPort>,
    name: String,
    lines: LineBuffer,
    timeout: Duration,
    period: Duration,
    next_tick: Option<Instant>,
    interrupted: Arc<AtomicBool>,
    /// Bytes written and read, for the rate report.
    pub bytes: u64,
}

/// The robot's port at `path`, which could not be opened.
fn opening(path: &Path) -> shaping_engine::Subject {
    shaping_engine::Subject::File { path: path.to_path_buf(), operation: "open".into() }
}

impl SerialPort {
    /// Opens `path` at `baud` with 8 data bits, 2 stop bits (the Khepera's
    /// setting), no parity and no flow control; an answer must come within
    /// `timeout`; one action lasts `period`; `interrupted` is the Ctrl-C flag.
    pub fn open(
        path: &Path,
        baud: u32,
        timeout: Duration,
        period: Duration,
        interrupted: Arc<AtomicBool>,
    ) -> Result<SerialPort, CliError> {
        let name = path.display().to_string();
        let port = serialport::new(path.to_string_lossy(), baud)
            .data_bits(DataBits::Eight)
            .stop_bits(StopBits::Two)
            .parity(Parity::None)
            .flow_control(FlowControl::None)
            .timeout(timeout)
            .open()
            .map_err(|e| match e.kind() {
                // Another program holds the port (its lock, or `TIOCEXCL`).
                serialport::ErrorKind::NoDevice => CliError::io(format!(
                    "error: the robot's port `{name}` is in use by another program: {}",
                    e.description
                ))
                .about(opening(path)),
                serialport::ErrorKind::InvalidInput | serialport::ErrorKind::Unknown => CliError::new(
                    shaping_engine::ErrorKind::Invalid,
                    format!(
                        "error: `{name}` is not a serial port (or refuses {baud} baud): {}",
                        e.description
                    ),
                )
                .about(opening(path)),
                _ => CliError::io(format!("error: cannot open the robot's port `{name}`: {}", e.description))
                    .about(opening(path)),
            })?;
        let _ = port.clear(ClearBuffer::All);
        Ok(SerialPort {
            port,
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
        loop {
            let waiting = self.port.bytes_to_read().map_err(|_| self.closed())? as usize;
            if waiting == 0 {
                return Ok(());
            }
            match self.port.read(&mut buf[..waiting.min(256)]) {
                Ok(0) => return Err(self.closed()),
                Ok(_) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(_) => return Err(self.closed()),
            }
        }
    }
}

impl Link for SerialPort {
    fn exchange(&mut self, command: &str) -> Result<Vec<u8>, LinkError> {
        self.drain()?;
        self.port.set_timeout(self.timeout).map_err(|_| self.closed())?;
        if self.port.write_all(command.as_bytes()).and_then(|()| self.port.flush()).is_err() {
            return Err(self.closed());
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
            let left = deadline.saturating_duration_since(Instant::now());
            let timed_out = || {
                LinkError(format!(
                    "no answer to `{}` within {} ms",
                    command.trim_end(),
                    self.timeout.as_millis()
                ))
            };
            if left.is_zero() {
                return Err(timed_out());
            }
            self.port.set_timeout(left).map_err(|_| self.closed())?;
            match self.port.read(&mut buf) {
                Ok(0) => return Err(self.closed()),
                Ok(n) => {
                    self.bytes += n as u64;
                    self.lines.push(&buf[..n]);
                }
                Err(e) if e.kind() == ErrorKind::TimedOut => return Err(timed_out()),
                Err(e) if matches!(e.kind(), ErrorKind::Interrupted | ErrorKind::WouldBlock) => {}
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
            return Err(LinkError(format!("interrupted ({})", crate::signals::last_name())));
        }
        // The next period starts now (a late action does not shorten it).
        self.next_tick = Some(Instant::now());
        Ok(())
    }
}
