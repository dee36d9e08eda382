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
    /// None when the invalid byte is too far into its line to be shown
    /// (miette cannot pad a label past 65535 columns).
    src: Option<NamedSource<String>>,
    name: String,
    at: SourceSpan,
}

impl std::error::Error for NotUtf8 {}

impl fmt::Display for NotUtf8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.src {
            Some(_) => write!(f, "the file is not valid UTF-8"),
            None => write!(f, "`{}` is not valid UTF-8 (byte {})", self.name, self.at.offset()),
        }
    }
}

impl Diagnostic for NotUtf8 {
    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new("architecture files are UTF-8 text; was a binary file passed by mistake?"))
    }

    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        self.src.as_ref().map(|s| s as &dyn miette::SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        self.src.as_ref()?;
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
    let source = read_source(path, format)?;
    let name = path.display().to_string();
    shaping_compiler::compile(&source, &name).map_err(|d| CliError::Diagnostics(diag::render(&d, format)))
}

/// Reads a `.bat` source; a file that is not UTF-8 is a diagnostic that
/// points at the first invalid byte.
pub fn read_source(path: &Path, format: ErrorFormat) -> Result<String, CliError> {
    let bytes = read_bytes(path)?;
    let name = path.display().to_string();
    match String::from_utf8(bytes) {
        Ok(s) => Ok(s),
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            let mut lossy = String::from_utf8_lossy(e.as_bytes()).into_owned();
            // Offsets shift in the lossy copy only after the first invalid byte.
            // Show the text up to the end of that byte's line, at most 80 bytes more.
            let mut end = lossy[at..].find('\n').map_or(lossy.len(), |i| at + i).min(at + 80);
            while !lossy.is_char_boundary(end) {
                end += 1;
            }
            lossy.truncate(end);
            let column = at - lossy[..at].rfind('\n').map_or(0, |i| i + 1);
            let src = (column <= 1000).then(|| NamedSource::new(&name, lossy));
            let report = NotUtf8 { src, name, at: (at, 1).into() };
            Err(CliError::Diagnostics(diag::render(&report, format)))
        }
    }
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
