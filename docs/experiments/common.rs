//! What the experiment examples (`oracle.rs`, `grip.rs`, `discriminate.rs`) share: loading a
//! file's stage, and turning a run's error into the exit status.

use std::process::ExitCode;

use shaping_compiler::Program;

/// `file` compiled and validated, and the index of its stage `stage`.
pub fn load(file: &str, stage: &str) -> Result<(Program, usize), String> {
    let source = std::fs::read_to_string(file).map_err(|e| format!("cannot read `{file}`: {e}"))?;
    let program = shaping_compiler::compile(&source, file)
        .map_err(|d| format!("`{file}` does not compile ({} errors): run `shaping check`", d.len()))?;
    program.validate().map_err(|e| format!("{file}: {e}"))?;
    let index = program
        .stages
        .iter()
        .position(|s| s.name == stage)
        .ok_or_else(|| format!("`{file}` has no stage `{stage}`"))?;
    Ok((program, index))
}

/// Exit status 0, or the error on stderr and status 2.
pub fn exit(result: Result<(), String>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
