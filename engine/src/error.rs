//! The one error type of the engine: a kind a caller can match and the
//! message a user sees.

use std::fmt;

/// What went wrong, for a caller that acts on it (an exit status, a retry,
/// a hint); the message says it to a person.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// Diagnostics about the user's source file (rendered in the message).
    Diagnostics,
    /// A file or directory could not be read or written.
    Io,
    /// A file or directory the caller named does not exist.
    NotFound,
    /// A saved file is damaged: it does not parse, or its checksum does not
    /// match its contents, or it disagrees with the file it was derived from.
    Corrupt,
    /// A saved result belongs to another program, seed or setting than the
    /// run's.
    Stale,
    /// The run was stopped by the interruption flag it was given.
    Interrupted,
    /// The run would need more memory than is available.
    Memory,
    /// A setting, an argument or a program that cannot be used.
    Invalid,
    /// The run directory is in use by another process.
    Locked,
    /// Evaluation failed (a robot link, a rank of a cluster).
    Evaluation,
}

/// An error of the engine: its [`ErrorKind`] and the message users see.
#[derive(Debug)]
pub struct Error {
    kind: ErrorKind,
    message: String,
    /// The diagnostics as data, for an error of kind `Diagnostics`.
    diagnosed: Option<Box<crate::diag::Diagnosed>>,
}

impl Error {
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Error {
        Error { kind, message: message.into(), diagnosed: None }
    }

    /// A file-system failure (also the kind of messages not classified).
    pub fn io(message: impl Into<String>) -> Error {
        Error::new(ErrorKind::Io, message)
    }

    /// A failure of the file system's on `path` to `what` (`read`,
    /// `write`, ...): [`ErrorKind::NotFound`] when it does not exist, else
    /// [`ErrorKind::Io`]; the message names the path and the system's reason.
    pub fn of_io(what: &str, path: &std::path::Path, e: &std::io::Error) -> Error {
        let kind = if e.kind() == std::io::ErrorKind::NotFound { ErrorKind::NotFound } else { ErrorKind::Io };
        Error::new(kind, format!("error: cannot {what} `{}`: {e}", path.display()))
    }

    /// Diagnostics about a source file: the message is their text, and
    /// [`Error::diagnosed`] their data.
    pub fn diagnostics(rendered: crate::diag::Rendered) -> Error {
        Error {
            diagnosed: Some(Box::new(rendered.data)),
            ..Error::new(ErrorKind::Diagnostics, rendered.text)
        }
    }

    /// Diagnostics known only as text (a command's own, such as `fmt
    /// --check`'s): no data.
    pub fn diagnostics_text(message: impl Into<String>) -> Error {
        Error::new(ErrorKind::Diagnostics, message)
    }

    /// The diagnostics as data (lines, columns, codes), for an error about
    /// a source file.
    pub fn diagnosed(&self) -> Option<&crate::diag::Diagnosed> {
        self.diagnosed.as_deref()
    }

    pub fn kind(&self) -> ErrorKind {
        self.kind
    }

    /// The message, as printed (without a trailing newline).
    pub fn message(&self) -> &str {
        self.message.trim_end()
    }

    /// The same error with `hint` appended to its message (`; hint`).
    pub fn with_hint(mut self, hint: &str) -> Error {
        self.message = format!("{}; {hint}", self.message.trim_end());
        self
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.message())
    }
}

impl std::error::Error for Error {}

/// The engine's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;
