//! `shaping emulate`: an emulated Khepera on a pseudo-terminal (Unix only;
//! elsewhere the command says so).

use std::path::PathBuf;

#[cfg(unix)]
pub use pty::emulate;

/// Bits on the wire per byte: start, 8 data, 2 stop bits.
pub const BITS_PER_BYTE: u64 = 11;

/// A fault to inject at the N-th request (counted from 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// No answer to that request.
    Drop(u64),
    /// Garbage bytes instead of the answer.
    Garbage(u64),
    /// The link is closed at that request.
    Close(u64),
}

/// Reads `drop@N`, `garbage@N` or `close@N`.
pub fn parse_fault(s: &str) -> Result<Fault, String> {
    let (kind, n) = s.split_once('@').ok_or_else(|| format!("`{s}`: expected KIND@N, e.g. drop@200"))?;
    let n: u64 = n
        .parse()
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| format!("`{n}`: not a request number (1 or more)"))?;
    match kind {
        "drop" => Ok(Fault::Drop(n)),
        "garbage" => Ok(Fault::Garbage(n)),
        "close" => Ok(Fault::Close(n)),
        _ => Err(format!("`{kind}`: unknown fault (drop, garbage or close)")),
    }
}

/// The arguments of `shaping emulate`.
#[derive(clap::Args)]
pub struct EmulateArgs {
    /// Architecture file whose world is emulated (default: the built-in `examples/khepera.bat`).
    pub file: Option<PathBuf>,
    /// Path of the pseudo-terminal to create (a symbolic link).
    #[arg(long)]
    pub port: PathBuf,
    /// Stage whose world is emulated (default: the last).
    #[arg(long)]
    pub stage: Option<String>,
    /// Seed of the world (default: the run seed), as `drive --seed`.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Emulated line speed: each byte takes 11 bit times (0: no wire delay).
    #[arg(long, default_value_t = 9600)]
    pub baud: u32,
    /// The robot's own delay before each answer, ms.
    #[arg(long = "delay", id = "delay", value_name = "DELAY", default_value_t = 0)]
    pub delay_ms: u64,
    /// Inject a fault at the N-th request: `drop@N` (no answer), `garbage@N`, `close@N`.
    #[arg(long, value_parser = parse_fault)]
    pub fault: Option<Fault>,
    #[arg(long, default_value = "human", value_parser = crate::error_format())]
    pub error_format: crate::diag::ErrorFormat,
}

/// The emulator needs a pseudo-terminal, which Windows does not have.
#[cfg(not(unix))]
pub fn emulate(args: EmulateArgs) -> Result<(), crate::CliError> {
    Err(crate::CliError::io(format!(
        "error: `shaping emulate` needs a Unix pseudo-terminal and cannot make `{}` here; \
         drive a real robot's port, or run the emulator on Linux or macOS",
        args.port.display()
    )))
}

/// The emulator on a pseudo-terminal, over `rustix`.
#[cfg(unix)]
mod pty {
    use std::io::Write as _;
    use std::os::fd::OwnedFd;
    use std::path::{Path, PathBuf};
    use std::sync::atomic::Ordering;
    use std::time::{Duration, Instant};

    use rustix::event::{poll, PollFd, PollFlags, Timespec};
    use rustix::fs::{Mode, OFlags};
    use rustix::io::Errno;
    use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};
    use rustix::termios::{self, ControlModes, OptionalActions};
    use shaping_runtime::robot::protocol::LineBuffer;
    use shaping_runtime::robot::Emulator;

    use super::{EmulateArgs, Fault, BITS_PER_BYTE};
    use crate::load;
    use crate::robot::port::interrupt_flag;
    use crate::CliError;

    /// The paper's architecture, used when no file is given.
    const DEFAULT_FILE: &str = include_str!("../../examples/khepera.bat");

    /// Puts a terminal into raw mode at `baud` with 8 data bits and 2 stop bits
    /// (the Khepera's setting), no flow control.
    fn make_raw(fd: &OwnedFd, baud: u32) -> rustix::io::Result<()> {
        let mut t = termios::tcgetattr(fd)?;
        t.make_raw();
        t.control_modes |= ControlModes::CSTOPB | ControlModes::CLOCAL | ControlModes::CREAD;
        t.set_speed(baud)?;
        termios::tcsetattr(fd, OptionalActions::Now, &t)
    }

    /// Waits until `fd` is readable or `deadline` passes; `Ok(false)` on timeout.
    fn wait_readable(fd: &OwnedFd, deadline: Instant) -> Result<bool, Errno> {
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

    /// Removes the symlink at `path` when dropped.
    struct Symlink(PathBuf);

    impl Drop for Symlink {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    fn create_pty(port: &Path) -> Result<(OwnedFd, OwnedFd, Symlink), CliError> {
        let err = |e: Errno| CliError::io(format!("error: cannot create a pseudo-terminal: {e}"));
        let master = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY | OpenptFlags::CLOEXEC).map_err(err)?;
        grantpt(&master).map_err(err)?;
        unlockpt(&master).map_err(err)?;
        let name = ptsname(&master, Vec::new()).map_err(err)?;
        let slave_path = PathBuf::from(name.to_string_lossy().into_owned());
        // The emulator keeps the slave open itself: the master then never sees a
        // hang-up between two clients, and the line is raw before anyone connects.
        let slave =
            rustix::fs::open(&slave_path, OFlags::RDWR | OFlags::NOCTTY | OFlags::CLOEXEC, Mode::empty())
                .map_err(err)?;
        make_raw(&slave, 9600).map_err(err)?;
        match std::fs::symlink_metadata(port) {
            Ok(m) if m.file_type().is_symlink() => {
                let _ = std::fs::remove_file(port);
            }
            Ok(_) => {
                return Err(CliError::invalid_setting(
                    "--port",
                    Some(&port.display().to_string()),
                    format!(
                        "error: `{}` exists and is not a symbolic link; choose another `--port`",
                        port.display()
                    ),
                ))
            }
            Err(_) => {}
        }
        std::os::unix::fs::symlink(&slave_path, port).map_err(|e| CliError::of_io("create", port, &e))?;
        Ok((master, slave, Symlink(port.to_path_buf())))
    }

    fn write_all(fd: &OwnedFd, mut bytes: &[u8]) -> Result<(), Errno> {
        while !bytes.is_empty() {
            match rustix::io::write(fd, bytes) {
                Ok(n) => bytes = &bytes[n..],
                Err(Errno::INTR | Errno::AGAIN) => {}
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }

    pub fn emulate(args: EmulateArgs) -> Result<(), CliError> {
        let program = match &args.file {
            Some(f) => load::load_program(f, args.error_format)?,
            None => shaping_compiler::compile(DEFAULT_FILE, "khepera.bat")
                .map_err(|_| CliError::internal("error: the built-in example does not compile"))?,
        };
        let index = match args.stage.as_deref() {
            Some(_) => load::stage_index(&program, args.stage.as_deref())?,
            None => program.stages.len().checked_sub(1).ok_or_else(|| {
                CliError::new(shaping_engine::ErrorKind::Invalid, "error: the program has no stages")
            })?,
        };
        let stage = &program.stages[index];
        let seed = args.seed.unwrap_or_else(|| shaping_engine::run::run_seed(&program, None));
        let mut emu = Emulator::new(&stage.world, seed);
        let flag = interrupt_flag()?;
        let (master, _slave, link) = create_pty(&args.port)?;
        let p = emu.sim().pose();
        eprintln!(
        "emulated Khepera on {} (world of stage `{}`, seed {seed}, start x {:.0} mm y {:.0} mm heading {:.0} deg, {} baud{}); Ctrl-C to stop",
        args.port.display(),
        stage.name,
        p.x,
        p.y,
        p.theta.to_degrees(),
        args.baud,
        if args.delay_ms > 0 { format!(", {} ms per answer", args.delay_ms) } else { String::new() },
    );
        let mut stdout = std::io::stdout().lock();
        let mut lines = LineBuffer::new();
        let mut buf = [0u8; 256];
        let mut last_speed = None;
        loop {
            if flag.load(Ordering::Relaxed) {
                eprintln!("emulator stopped after {} requests, {} actions", emu.requests, emu.actions);
                return Ok(());
            }
            match wait_readable(&master, Instant::now() + Duration::from_millis(100)) {
                Ok(false) => continue,
                Ok(true) => {}
                Err(e) => return Err(CliError::io(format!("error: the pseudo-terminal failed: {e}"))),
            }
            let n = match rustix::io::read(&master, &mut buf) {
                Ok(n) => n,
                Err(Errno::INTR | Errno::AGAIN) => continue,
                Err(e) => return Err(CliError::io(format!("error: the pseudo-terminal failed: {e}"))),
            };
            lines.push(&buf[..n]);
            while let Some(line) = lines.next_line() {
                let started = Instant::now();
                let number = emu.requests + 1;
                let line = line.unwrap_or_default();
                let mut answer = emu.answer(&line);
                if emu.speed() != last_speed.unwrap_or([i32::MAX; 2]) {
                    last_speed = Some(emu.speed());
                    let [l, r] = emu.speed();
                    let _ = writeln!(stdout, "speed {l} {r} at request {number}");
                    let _ = stdout.flush();
                }
                match args.fault {
                    Some(Fault::Drop(n)) if n == number => {
                        eprintln!("fault: no answer to request {number}");
                        continue;
                    }
                    Some(Fault::Garbage(n)) if n == number => {
                        eprintln!("fault: garbage in answer to request {number}");
                        answer = "\u{15}#?%\u{7f}~\r\n".to_string();
                    }
                    Some(Fault::Close(n)) if n == number => {
                        eprintln!("fault: link closed at request {number}");
                        drop(master);
                        drop(_slave);
                        drop(link);
                        return Ok(());
                    }
                    _ => {}
                }
                // The wire's time for the command and its answer, and the robot's delay.
                let bytes = (line.len() + 1 + answer.len()) as u64;
                let wire = if args.baud > 0 {
                    Duration::from_micros(bytes * BITS_PER_BYTE * 1_000_000 / u64::from(args.baud))
                } else {
                    Duration::ZERO
                };
                let due = started + wire + Duration::from_millis(args.delay_ms);
                if let Some(wait) = due.checked_duration_since(Instant::now()) {
                    std::thread::sleep(wait);
                }
                if let Err(e) = write_all(&master, answer.as_bytes()) {
                    return Err(CliError::io(format!("error: the pseudo-terminal failed: {e}")));
                }
            }
        }
    }
}
