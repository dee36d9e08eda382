//! Reading architecture files: `.bat` sources through the compiler, or a
//! `Program` previously written by `shaping build` (`.json`).

use std::fmt;
use std::path::{Path, PathBuf};

use miette::{Diagnostic, NamedSource, SourceSpan};
use shaping_runtime::limits;
use shaping_runtime::program::{Program, StageRun, FORMAT_VERSION};

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
/// Warnings go to standard error.
pub fn load_program(path: &Path, format: ErrorFormat) -> Result<Program, CliError> {
    let (program, warnings) = load_program_warnings(path, format)?;
    if let Some(w) = warnings {
        eprintln!("{}", w.trim_end());
    }
    Ok(program)
}

/// Like [`load_program`], with the warnings rendered and returned.
pub fn load_program_warnings(
    path: &Path,
    format: ErrorFormat,
) -> Result<(Program, Option<String>), CliError> {
    if path.extension().is_some_and(|e| e == "json") {
        return Ok((load_built(path)?, None));
    }
    let source = read_source(path, format)?;
    let name = path.display().to_string();
    let (program, diagnostics) = shaping_compiler::check(&source, &name);
    let Some(program) = program else {
        return Err(CliError::Diagnostics(diag::render(&diagnostics, format)));
    };
    let warnings = (!diagnostics.is_empty()).then(|| diag::render(&diagnostics, format));
    // The compiler's output always validates (a property test checks it);
    // validating here too makes every command run only validated programs.
    program.validate().map_err(|e| {
        CliError::io(format!("error: internal error: `{name}` compiled to an invalid program: {e}"))
    })?;
    Ok((program, warnings))
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

/// The memory a run of `stages` of `program` needs at its peak (its largest
/// stage: see `shaping_runtime::limits`), in bytes.
pub fn memory_estimate(program: &Program, stages: &[usize]) -> u64 {
    stages
        .iter()
        .map(|&i| {
            let s = &program.stages[i];
            match &s.run {
                StageRun::Evolve(e) => limits::population_bytes(e.population.into(), s.layout.bits.into()),
                // Every life of both worlds is traced.
                StageRun::Test { actions, lives, .. } => {
                    limits::trace_bytes(2 * u64::from(*actions) * u64::from(*lives), s.modules.len() as u64)
                }
                // A training life is traced for its first actions only.
                StageRun::Train { actions } => limits::trace_bytes(
                    (*actions).min(crate::run::RECORDED_TRAINING_ACTIONS).into(),
                    s.modules.len() as u64,
                ),
            }
        })
        .max()
        .unwrap_or(0)
}

/// The memory this machine has available (Linux: `MemAvailable` of
/// `/proc/meminfo`), or `None` where it cannot be read.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Refuses, before anything starts, a run of `stages` that would need more
/// memory than the machine has available, with the estimate. `copies` runs
/// are held at once (an experiment's seeds run one after another: 1).
pub fn check_memory(program: &Program, stages: &[usize], copies: u64) -> Result<(), CliError> {
    check_memory_within(program, stages, copies, available_memory())
}

fn check_memory_within(
    program: &Program,
    stages: &[usize],
    copies: u64,
    available: Option<u64>,
) -> Result<(), CliError> {
    let need = memory_estimate(program, stages).saturating_mul(copies.max(1));
    match available {
        Some(have) if need > have => {
            let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
            let biggest = stages
                .iter()
                .copied()
                .max_by_key(|&i| memory_estimate(program, &[i]))
                .map(|i| program.stages[i].name.clone())
                .unwrap_or_default();
            Err(CliError::io(format!(
                "error: this run needs about {:.1} GiB of memory (stage `{biggest}`), but only {:.1} GiB are available; \
                 reduce the population, the genome or the number of actions",
                gib(need),
                gib(have)
            )))
        }
        _ => Ok(()),
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn program(population: u32, bits: u32) -> Program {
        let mut stage = shaping_runtime::testkit::navigation();
        if let StageRun::Evolve(e) = &mut stage.run {
            e.population = population;
        }
        stage.layout.bits = bits;
        Program { format: FORMAT_VERSION, name: "p".into(), stages: vec![stage] }
    }

    #[test]
    fn a_run_larger_than_the_available_memory_is_refused_with_the_estimate() {
        let p = program(100_000, 5_000);
        let need = memory_estimate(&p, &[0]);
        assert_eq!(need, 100_000 * 5_000 * (2 + limits::CHECKPOINT_BYTES_PER_BIT));
        assert!(check_memory_within(&p, &[0], 1, Some(need)).is_ok());
        assert!(check_memory_within(&p, &[0], 1, None).is_ok(), "unknown memory: no refusal");
        let err = check_memory_within(&p, &[0], 1, Some(4 << 30)).unwrap_err().to_string();
        assert!(
            err.contains("needs about 6.5 GiB of memory (stage `navigation`), but only 4.0 GiB"),
            "{err}"
        );
    }

    #[test]
    fn a_training_stage_is_estimated_by_the_actions_it_traces() {
        let mut p = program(100, 10);
        let modules = p.stages[0].modules.len() as u64;
        p.stages[0].run = StageRun::Train { actions: 10_000_000 };
        let traced = u64::from(crate::run::RECORDED_TRAINING_ACTIONS);
        assert_eq!(memory_estimate(&p, &[0]), limits::trace_bytes(traced, modules));
        p.stages[0].run = StageRun::Train { actions: 1000 };
        assert_eq!(memory_estimate(&p, &[0]), limits::trace_bytes(1000, modules));
    }
}
