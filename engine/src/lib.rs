//! The engine of `shaping` as a library: everything between a compiled
//! `Program` and the files of a run directory, for the command line, the
//! experiment programs, the MPI coordinator, tests and Python alike.
//!
//! It prints nothing, installs no signal handler, parses no argument and
//! calls no MPI: progress and warnings go to the caller as values, an
//! interruption comes in as a flag, and errors are one [`Error`] type whose
//! [`ErrorKind`] a caller can match.

pub mod animation;
pub mod bench;
pub mod compare;
pub mod descriptors;
pub mod diag;
pub mod episode;
pub mod error;
pub mod experiment;
pub mod files;
pub mod html;
pub mod load;
pub mod plot;
pub mod replay;
pub mod report;
pub mod run;
pub mod rundir;
pub mod stats;
pub mod stepper;
pub mod sweep;

pub use error::{Error, ErrorKind, Result};

/// The longest part of a training life that a run records (from its
/// start) for `trace.csv`, `episode.json` and the pictures.
pub const RECORDED_TRAINING_ACTIONS: u32 = 20_000;
