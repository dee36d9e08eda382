//! The engine of `shaping` as a library: everything between a compiled
//! `Program` and the files of a run directory, for the command line, the
//! experiment programs, the MPI coordinator, tests and Python alike.
//!
//! Start at [`Engine`]: it loads, checks, runs, sweeps, replays and
//! evaluates programs. Its options and outcomes are in [`run`],
//! [`experiment`] and [`replay`], the files it writes in [`rundir`], the
//! diagnostics of a source file in [`diag`].
//!
//! It prints nothing, installs no signal handler, parses no argument and
//! calls no MPI: progress and warnings go to the caller as values
//! ([`run::Event`], serialisable), an interruption comes in as a flag, and
//! errors are one [`Error`] type whose [`ErrorKind`] a caller can match
//! (with the diagnostics as data for a file with errors).

// What a library user needs: the entry type's options, events and
// outcomes, and the files of a run directory.
pub mod diag;
pub mod error;
pub mod experiment;
pub mod replay;
pub mod run;
pub mod rundir;

// The project's own fronts (the command line, Python, the experiment
// programs) use these too; they are not the library's interface.
#[doc(hidden)]
pub mod animation;
#[doc(hidden)]
pub mod bench;
#[doc(hidden)]
pub mod compare;
#[doc(hidden)]
pub mod descriptors;
#[doc(hidden)]
pub mod episode;
#[doc(hidden)]
pub mod files;
#[doc(hidden)]
pub mod html;
#[doc(hidden)]
pub mod load;
#[doc(hidden)]
pub mod plot;
#[doc(hidden)]
pub mod report;
#[doc(hidden)]
pub mod stats;
#[doc(hidden)]
pub mod stepper;
#[doc(hidden)]
pub mod sweep;

mod entry;

pub use entry::Engine;
pub use error::{Error, ErrorKind, Result, Subject};

/// The longest part of a training life that a run records (from its
/// start) for `trace.csv`, `episode.json` and the pictures.
pub const RECORDED_TRAINING_ACTIONS: u32 = 20_000;
