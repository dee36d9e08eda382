//! Reading architecture files: `.bat` sources through the compiler, or a
//! `Program` previously written by `shaping build` (`.json`).

use std::fmt;
use std::path::{Path, PathBuf};

use miette::{Diagnostic, NamedSource, SourceSpan};
use shaping_runtime::program::{Program, FORMAT_VERSION};

use crate::diag::{self, ErrorFormat};

/// A failure of the command line: either diagnostics about the user's file
/// (exit 1) or a usage / I/O problem (exit 2). The message is ready to print.
#[derive(Debug)]
pub enum CliError {
    Diagnostics(String),
    Io(String),
}

impl CliError {
    pub fn io(msg: impl Into<String>) -> CliError {
        CliError::Io(msg.into())
    }

    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::Diagnostics(_) => 1,
            CliError::Io(_) => 2,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Diagnostics(s) | CliError::Io(s) => f.write_str(s.trim_end()),
        }
    }
}

/// The source file is not UTF-8: reported like any other diagnostic, pointing
/// at the first invalid byte.
#[derive(Debug)]
struct NotUtf8 {
    src: NamedSource<String>,
    at: SourceSpan,
}

impl std::error::Error for NotUtf8 {}

impl fmt::Display for NotUtf8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "the file is not valid UTF-8")
    }
}

impl Diagnostic for NotUtf8 {
    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new("architecture files are UTF-8 text; was a binary file passed by mistake?"))
    }

    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        Some(&self.src)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        Some(Box::new(std::iter::once(miette::LabeledSpan::new_with_span(
            Some("invalid byte here".into()),
            self.at,
        ))))
    }
}

/// Reads a file, mapping I/O errors to a message that names the path.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, CliError> {
    std::fs::read(path).map_err(|e| CliError::io(format!("error: cannot read `{}`: {e}", path.display())))
}

/// Reads and compiles a `.bat` file, or loads a built `Program` (`.json`).
pub fn load_program(path: &Path, format: ErrorFormat) -> Result<Program, CliError> {
    if path.extension().is_some_and(|e| e == "json") {
        return load_built(path);
    }
    let bytes = read_bytes(path)?;
    let name = path.display().to_string();
    let source = match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            let lossy = String::from_utf8_lossy(e.as_bytes()).into_owned();
            // Offsets shift in the lossy copy only after the first invalid byte.
            let report = NotUtf8 { src: NamedSource::new(name, lossy), at: (at, 1).into() };
            return Err(CliError::Diagnostics(diag::render(&report, format)));
        }
    };
    shaping_compiler::compile(&source, &name).map_err(|d| CliError::Diagnostics(diag::render(&d, format)))
}

/// Loads a `Program` written by `shaping build`.
pub fn load_built(path: &Path) -> Result<Program, CliError> {
    let bytes = read_bytes(path)?;
    let program: Program = serde_json::from_slice(&bytes).map_err(|e| {
        CliError::io(format!("error: `{}` is not a program built by `shaping build`: {e}", path.display()))
    })?;
    if program.format != FORMAT_VERSION {
        return Err(CliError::io(format!(
            "error: `{}` was built for program format {}, this shaping reads format {FORMAT_VERSION}; rebuild it",
            path.display(),
            program.format
        )));
    }
    if let Err(e) = program.validate() {
        return Err(CliError::io(format!("error: `{}` is not a valid program: {e}", path.display())));
    }
    Ok(program)
}

/// Resolves `--stage NAME` to a stage index; without a name, the last stage.
pub fn stage_index(program: &Program, stage: Option<&str>) -> Result<usize, CliError> {
    match stage {
        None => {
            if program.stages.is_empty() {
                Err(CliError::io("error: the program has no stages"))
            } else {
                Ok(program.stages.len() - 1)
            }
        }
        Some(name) => program.stage(name).map(|(i, _)| i).ok_or_else(|| {
            let names: Vec<&str> = program.stages.iter().map(|s| s.name.as_str()).collect();
            CliError::io(format!("error: there is no stage `{name}`; the stages are: {}", names.join(", ")))
        }),
    }
}

/// Writes a file atomically: a temporary file next to it, then a rename.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), CliError> {
    let tmp: PathBuf = {
        let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
        name.push(".tmp");
        path.with_file_name(name)
    };
    std::fs::write(&tmp, contents)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| CliError::io(format!("error: cannot write `{}`: {e}", path.display())))
}

/// Creates a directory and its parents.
pub fn create_dir(path: &Path) -> Result<(), CliError> {
    std::fs::create_dir_all(path)
        .map_err(|e| CliError::io(format!("error: cannot create directory `{}`: {e}", path.display())))
}
