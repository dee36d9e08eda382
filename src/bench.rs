//! `shaping bench`: the engine's measurements (`shaping_engine::bench`) of
//! a stage, with `--set` applied, as one JSON line, with the file, the
//! build (a debug build's speeds are not figures) and the process's peak
//! memory.

use std::path::PathBuf;

use crate::load;
use crate::out::outln;
use crate::CliError;

pub struct BenchArgs {
    pub file: PathBuf,
    pub stage: Option<String>,
    pub runs: usize,
    /// Settings changed from the command line (`--set`, one value each).
    pub sets: Vec<shaping_engine::sweep::Assignment>,
    pub error_format: crate::diag::ErrorFormat,
}

pub fn bench(args: BenchArgs) -> Result<(), CliError> {
    let mut program = load::load_program(&args.file, args.error_format)?;
    shaping_engine::sweep::apply(&mut program, &args.sets)?;
    let index = load::stage_index(&program, args.stage.as_deref())?;
    let figures = shaping_engine::bench::bench(program, index, args.runs)?;
    let mut line = serde_json::json!(figures);
    line["file"] = args.file.display().to_string().into();
    line["build"] = if cfg!(debug_assertions) { "debug" } else { "release" }.into();
    line["peak_memory_mb"] = peak_memory_mb().into();
    outln!("{line}")?;
    Ok(())
}

/// The process's peak resident memory in MB (Linux's `VmHWM`), or `None`
/// where the system does not say.
fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: f64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .trim()
        .strip_suffix("kB")?
        .trim()
        .parse()
        .ok()?;
    Some((kb / 1024.0 * 10.0).round() / 10.0)
}
