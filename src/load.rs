//! Loading for the command line: the engine's loaders, with a file's
//! warnings printed to standard error.

use std::path::Path;

use shaping_engine::diag::ErrorFormat;
pub use shaping_engine::files::{create_dir, read_bytes, write_atomic};
pub use shaping_engine::load::{read_source, replaceable_program, same_entry, stage_index};
use shaping_runtime::program::Program;

use crate::CliError;

/// Reads and compiles a `.bat` file, or loads a built `Program` (`.json`).
/// Warnings go to standard error.
pub fn load_program(path: &Path, format: ErrorFormat) -> Result<Program, CliError> {
    let (program, warnings) = shaping_engine::load::load_program(path, format)?;
    if let Some(w) = warnings {
        eprintln!("{}", w.text.trim_end());
    }
    Ok(program)
}
