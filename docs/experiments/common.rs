//! What the experiment examples (`oracle.rs`, `grip.rs`, `discriminate.rs`,
//! `lives.rs`, `walkers.rs`) share, all through the engine library
//! (`shaping_engine`), as `shaping run` and `shaping replay` do: loading a
//! file's stage (`load::load_program`, its warnings printed once to
//! stderr), binding its training stages (`run::bind_training`: a run's
//! `trained.json` where it fits, else trained again from the seed), the
//! best individual of an evolved stage of a run (`rundir::checked_best`:
//! the checkpoint must fit the program, `best.genome` must be its best,
//! and the run's seed the directory's), and turning an error into the exit
//! status.

#![allow(dead_code)] // each example uses part of it

use std::path::Path;
use std::process::ExitCode;

use shaping_engine::diag::ErrorFormat;
use shaping_engine::run::{bind_training, Event, Observer};
use shaping_engine::{load, rundir, Error, ErrorKind};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::Program;

/// An engine error as these examples report it ([`exit`] adds `error: `).
pub fn message(e: Error) -> String {
    let m = e.message();
    m.strip_prefix("error: ").unwrap_or(m).to_string()
}

/// Prints the engine's warnings (a saved file not used, a crowded world)
/// to stderr; stdout holds the results only.
pub struct Warnings;

impl Observer for Warnings {
    fn event(&self, event: Event<'_>) {
        if let Event::Warning(w) = event {
            eprintln!("{w}");
        }
    }
}

/// `file` loaded as `shaping run` loads it (a `.bat` compiled and
/// validated, or a built `.json`), its warnings printed to stderr, and the
/// index of its stage `stage`.
pub fn load(file: &str, stage: &str) -> Result<(Program, usize), String> {
    let (program, warnings) = match load::load_program(Path::new(file), ErrorFormat::Human) {
        Ok(loaded) => loaded,
        Err(e) if e.kind() == ErrorKind::Diagnostics => {
            eprintln!("{}", e.message());
            return Err(format!("`{file}` does not compile"));
        }
        Err(e) => return Err(message(e)),
    };
    if let Some(w) = warnings {
        eprintln!("{}", w.text.trim_end());
    }
    let index = load::stage_index(&program, Some(stage)).map_err(message)?;
    Ok((program, index))
}

/// Binds the training stages of `program` as a run of seed `seed` does:
/// from the `trained.json` files of run directory `run` where they fit,
/// else by training them again with `seed` (without `run`: always).
pub fn bind(program: &mut Program, run: Option<&Path>, seed: u64) -> Result<(), String> {
    bind_training(program, run, seed, &Warnings).map(|_| ()).map_err(message)
}

/// The best individual of evolved stage `index` of `program` in run
/// directory `run` (a `seed-N` directory of `shaping experiment`), made
/// with seed `seed`: its checkpoint must fit the program as it is (bind
/// the training stages first, see [`bind`]), and `best.genome` must be the
/// checkpoint's best ([`rundir::checked_best`]).
pub fn best(program: &Program, index: usize, run: &Path, seed: u64) -> Result<Genome, String> {
    let dir = rundir::stage_dir(run, &program.stages[index].name);
    let (cp, genome, _) = rundir::checked_best(program, index, &dir).map_err(message)?;
    if cp.seed != seed {
        return Err(format!(
            "`{}` belongs to a run with seed {}, not {seed}",
            rundir::checkpoint_path(&dir).display(),
            cp.seed
        ));
    }
    Ok(genome)
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
