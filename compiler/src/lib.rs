//! `shaping-compiler`: parses, checks and lowers `.bat` architecture files to a
//! runtime [`Program`]. Text in, `Program` or diagnostics out: no file I/O.

pub use shaping_runtime::program::Program;

/// Every diagnostic of one compilation (placeholder until the compiler lands).
#[derive(Debug)]
pub struct CompileError {
    pub message: String,
}

/// Compiles the source of one architecture file.
pub fn compile(source: &str, file_name: &str) -> Result<Program, CompileError> {
    let _ = (source, file_name);
    Err(CompileError { message: "the compiler is not written yet".into() })
}
