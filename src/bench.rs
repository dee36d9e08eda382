//! `shaping bench`: the engine's measurements (`shaping_engine::bench`) of
//! a stage, with `--set` applied, as one JSON line.

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
    outln!("{line}")?;
    Ok(())
}
