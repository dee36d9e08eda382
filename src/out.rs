//! Standard output. Every command prints through [`write`] (the `out!` and
//! `outln!` macros), never `print!`: a reader that goes away
//! (`shaping layout f.bat | head`) is not an error and not a panic. The
//! rest of the output is dropped, the command does the rest of its work
//! (files are written as without the pipe) and exits with its own status.
//! Any other failure to write (a full disk behind `>`) is an error.

use std::io::{ErrorKind, Write as _};
use std::sync::atomic::{AtomicBool, Ordering};

use crate::CliError;

/// Set when a write found standard output closed; later writes are skipped.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes to standard output (and flushes, so that a closed pipe is seen here).
pub fn write(args: std::fmt::Arguments) -> Result<(), CliError> {
    if CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out.write_fmt(args).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(CliError::io(format!("error: cannot write to standard output: {e}"))),
    }
}

/// `print!` to standard output through [`write`]; a `Result` to `?`.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::out::write(format_args!($($arg)*))
    };
}

/// `println!` to standard output through [`write`]; a `Result` to `?`.
macro_rules! outln {
    () => {
        $crate::out::write(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::out::write(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {out, outln};
