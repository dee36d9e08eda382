//! The one error type of the engine: a kind a caller can match, the facts
//! a caller may use (the file, the setting, the lock: [`Subject`]) and the
//! message a user sees, rendered from them.

use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong, for a caller that acts on it (an exit status, a retry,
/// a hint); the message says it to a person.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// Diagnostics about the user's source file (rendered in the message).
    Diagnostics,
    /// The operating system failed an operation: a file or directory that
    /// could not be read or written, a device, a thread.
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
    /// A bug of shaping (a value it cannot serialise, a program its own
    /// compiler made that does not validate): not the caller's doing.
    Internal,
}

/// What an error is about, as data: the facts its message states, for a
/// caller that acts on them (a file to create, a setting to correct, a
/// process to wait for).
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Subject {
    /// A file or directory and the operation that failed on it (`read`,
    /// `write`, `create directory`, `remove`, `lock`, ...).
    File { path: PathBuf, operation: String },
    /// A saved file that is damaged ([`ErrorKind::Corrupt`]) or of another
    /// program, seed or setting ([`ErrorKind::Stale`]), and what is wrong
    /// with it (`checksum does not match`, `the modules of `s` changed`).
    Saved { path: PathBuf, problem: String },
    /// A setting or an argument the caller gave: its name as written
    /// (`first.evolve.mutation`, `--robot`, `--genome`) and the value
    /// given, if any.
    Setting { key: String, value: Option<String> },
    /// A run directory locked by another process or run, and its holder as
    /// its lock file names it (`shaping, process 1234`; empty if unknown).
    Lock { dir: PathBuf, holder: String },
}

/// An error of the engine: its [`ErrorKind`], what it is about
/// ([`Subject`], where known) and the message users see.
#[derive(Debug)]
pub struct Error {
    kind: ErrorKind,
    subject: Option<Subject>,
    message: String,
    /// The diagnostics as data, for an error of kind `Diagnostics`.
    diagnosed: Option<Box<crate::diag::Diagnosed>>,
}

impl Error {
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Error {
        Error { kind, subject: None, message: message.into(), diagnosed: None }
    }

    /// A failure of the operating system that is about no one file (a
    /// thread that cannot start, a device); a file's is [`Error::of_io`].
    pub fn io(message: impl Into<String>) -> Error {
        Error::new(ErrorKind::Io, message)
    }

    /// A failure of the file system's on `path` to `what` (`read`,
    /// `write`, ...): [`ErrorKind::NotFound`] when it does not exist, else
    /// [`ErrorKind::Io`]; the message names the path and the system's reason.
    pub fn of_io(what: &str, path: &Path, e: &std::io::Error) -> Error {
        let kind = if e.kind() == std::io::ErrorKind::NotFound { ErrorKind::NotFound } else { ErrorKind::Io };
        Error::file(kind, what, path, e)
    }

    /// An error of `kind` on `path` while doing `what` (`read`, `write`,
    /// ...), for `reason`: the message is `cannot WHAT `PATH`: REASON`.
    pub fn file(kind: ErrorKind, what: &str, path: &Path, reason: impl fmt::Display) -> Error {
        let subject = Subject::File { path: path.to_path_buf(), operation: what.to_string() };
        Error::new(kind, format!("error: cannot {what} `{}`: {reason}", path.display())).about(subject)
    }

    /// A bug of shaping ([`ErrorKind::Internal`]).
    pub fn internal(message: impl Into<String>) -> Error {
        Error::new(ErrorKind::Internal, message)
    }

    /// A setting or an argument `key` that cannot be used
    /// ([`ErrorKind::Invalid`]), with the value given, if any.
    pub fn invalid_setting(key: impl Into<String>, value: Option<&str>, message: impl Into<String>) -> Error {
        let subject = Subject::Setting { key: key.into(), value: value.map(str::to_string) };
        Error::new(ErrorKind::Invalid, message).about(subject)
    }

    /// A saved file `path` that is damaged ([`ErrorKind::Corrupt`]):
    /// `problem` says how.
    pub fn damaged(path: &Path, problem: impl Into<String>, message: impl Into<String>) -> Error {
        Error::saved(ErrorKind::Corrupt, path, problem, message)
    }

    /// A saved file `path` of another program, seed or setting than the
    /// run's ([`ErrorKind::Stale`]): `problem` says what disagrees.
    pub fn stale(path: &Path, problem: impl Into<String>, message: impl Into<String>) -> Error {
        Error::saved(ErrorKind::Stale, path, problem, message)
    }

    fn saved(kind: ErrorKind, path: &Path, problem: impl Into<String>, message: impl Into<String>) -> Error {
        let subject = Subject::Saved { path: path.to_path_buf(), problem: problem.into() };
        Error::new(kind, message).about(subject)
    }

    /// The same error about `subject`.
    pub fn about(mut self, subject: Subject) -> Error {
        self.subject = Some(subject);
        self
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

    /// What the error is about, where known.
    pub fn subject(&self) -> Option<&Subject> {
        self.subject.as_ref()
    }

    /// The file or directory the error is about: the one an operation
    /// failed on, a damaged or stale saved file, a locked directory.
    pub fn path(&self) -> Option<&Path> {
        match self.subject.as_ref()? {
            Subject::File { path, .. } | Subject::Saved { path, .. } => Some(path),
            Subject::Lock { dir, .. } => Some(dir),
            Subject::Setting { .. } => None,
        }
    }

    /// The operation that failed on [`Error::path`] (`read`, `write`, ...).
    pub fn operation(&self) -> Option<&str> {
        match self.subject.as_ref()? {
            Subject::File { operation, .. } => Some(operation),
            _ => None,
        }
    }

    /// The setting or argument that cannot be used, as the caller wrote
    /// it, and the value given (`("first.evolve.mutation", Some("2"))`).
    pub fn setting(&self) -> Option<(&str, Option<&str>)> {
        match self.subject.as_ref()? {
            Subject::Setting { key, value } => Some((key, value.as_deref())),
            _ => None,
        }
    }

    /// What is wrong with a damaged or stale saved file.
    pub fn problem(&self) -> Option<&str> {
        match self.subject.as_ref()? {
            Subject::Saved { problem, .. } => Some(problem),
            _ => None,
        }
    }

    /// Who holds a locked directory, as its lock file names it.
    pub fn holder(&self) -> Option<&str> {
        match self.subject.as_ref()? {
            Subject::Lock { holder, .. } => Some(holder),
            _ => None,
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_error_renders_its_message_from_its_path_operation_and_reason() {
        let path = Path::new("run/first/checkpoint.json");
        let gone = std::io::Error::from(std::io::ErrorKind::NotFound);
        let err = Error::of_io("read", path, &gone);
        assert_eq!(err.kind(), ErrorKind::NotFound);
        assert_eq!((err.path(), err.operation()), (Some(path), Some("read")));
        assert_eq!(err.to_string(), format!("error: cannot read `run/first/checkpoint.json`: {gone}"));
        let denied = std::io::Error::from(std::io::ErrorKind::PermissionDenied);
        assert_eq!(Error::of_io("write", path, &denied).kind(), ErrorKind::Io);
        assert_eq!((err.setting(), err.problem(), err.holder()), (None, None, None));
    }

    #[test]
    fn each_subject_answers_its_own_accessors_and_keeps_them_through_a_hint() {
        let err =
            Error::invalid_setting("first.evolve.mutation", Some("2"), "error: bad").with_hint("try 0.1");
        assert_eq!((err.kind(), err.message()), (ErrorKind::Invalid, "error: bad; try 0.1"));
        assert_eq!((err.setting(), err.path()), (Some(("first.evolve.mutation", Some("2"))), None));

        let err = Error::damaged(Path::new("s/best.genome"), "line 1, column 3 is `7`", "error: damaged");
        assert_eq!(
            (err.kind(), err.path(), err.problem()),
            (ErrorKind::Corrupt, Some(Path::new("s/best.genome")), Some("line 1, column 3 is `7`"))
        );
        let err = Error::stale(Path::new("out"), "seed 3, not 5", "error: stale");
        assert_eq!(
            (err.kind(), err.problem(), err.operation()),
            (ErrorKind::Stale, Some("seed 3, not 5"), None)
        );

        let lock = Subject::Lock { dir: "out".into(), holder: "shaping, process 7".into() };
        let err = Error::new(ErrorKind::Locked, "error: in use").about(lock.clone());
        assert_eq!(
            (err.path(), err.holder(), err.subject()),
            (Some(Path::new("out")), Some("shaping, process 7"), Some(&lock))
        );
        assert_eq!(Error::internal("error: cannot serialise").kind(), ErrorKind::Internal);
    }
}
