//! [`Engine`]: the engine's one entry type.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use shaping_runtime::evolve::{Episode, Evaluation};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::Program;

use crate::diag::{ErrorFormat, Rendered};
use crate::error::Result;
use crate::experiment::{ExperimentOptions, Finished, Plan};
use crate::replay::{ReplayOptions, Replayed};
use crate::run::{Evaluate, Event, Local, Observer, RunOutcome, Silent};

/// Loads, checks, runs, sweeps, replays and evaluates programs, for a
/// caller that says how: who is told of progress and warnings (an
/// [`Observer`]), who evaluates evolved stages' episodes (this process's
/// threads unless an [`Evaluate`] is given: MPI ranks, a robot) and which
/// flag stops it (Ctrl-C, a notebook's interrupt). The command line, the
/// experiment programs, the MPI coordinator and Python all go through it.
///
/// Every method's result depends only on the program, the options and
/// the seeds: not on the thread count, the evaluator or the observer.
///
/// ```
/// use shaping_engine::run::{RunOptions, StageOutcome};
/// use shaping_engine::Engine;
///
/// let engine = Engine::default();
/// let program = engine.load("../tests/cli/tiny.bat".as_ref())?;
/// let out = std::env::temp_dir().join(format!("shaping-doc-{}", std::process::id()));
/// let options = RunOptions { out: out.clone(), no_report: true, ..RunOptions::default() };
/// let outcome = engine.run(program, &options)?;
/// let StageOutcome::Evolve { best, .. } = &outcome.stages[1] else { panic!("an evolved stage") };
/// assert!(best.is_finite());
/// assert!(out.join("second/best.genome").is_file());
/// # std::fs::remove_dir_all(&out)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Engine<'a> {
    /// Told of progress and warnings.
    pub observer: &'a dyn Observer,
    /// Evaluates evolved stages' episodes (this process's threads: `None`).
    pub evaluator: Option<&'a dyn Evaluate>,
    /// Once set, the work stops at the next safe point (after the generation
    /// under way, at the next action of a test's life) and says where.
    pub interrupt: Option<&'a AtomicBool>,
}

impl Default for Engine<'_> {
    fn default() -> Self {
        Engine { observer: &Silent, evaluator: None, interrupt: None }
    }
}

impl Engine<'_> {
    /// The program of a `.bat` file (compiled and validated) or of a
    /// `shaping build` JSON; its warnings go to the observer, rendered as
    /// plain text. A file with errors is an error of kind
    /// [`crate::ErrorKind::Diagnostics`] whose [`crate::Error::diagnosed`]
    /// has them as data.
    pub fn load(&self, path: &Path) -> Result<Program> {
        let (program, warnings) = self.check(path, ErrorFormat::Plain)?;
        if let Some(w) = warnings {
            self.observer.event(Event::Warning(w.text.trim_end().to_string()));
        }
        Ok(program)
    }

    /// [`Engine::load`] with the warnings returned instead, rendered in
    /// `format` and as data (what `shaping check` prints).
    pub fn check(&self, path: &Path, format: ErrorFormat) -> Result<(Program, Option<Rendered>)> {
        crate::load::load_program(path, format)
    }

    /// Runs an experiment (a sweep when `options.sets` has several values):
    /// each point and seed as [`Engine::run`] would, one after the other,
    /// then its summaries and reports; the directory is locked while it
    /// runs. The runs' outcomes come in the order of [`Plan::tasks`].
    /// (The command line hands the tasks to MPI ranks through [`Plan`].)
    pub fn experiment(
        &self,
        program: Program,
        options: ExperimentOptions,
    ) -> Result<(Vec<RunOutcome>, Finished)> {
        let jobs = options.jobs;
        let plan = Plan::new(program, options)?;
        let _lock = plan.lock()?;
        let outcomes = plan
            .tasks()
            .into_iter()
            .map(|task| plan.run_task(task, jobs, self))
            .collect::<Result<Vec<_>>>()?;
        Ok((outcomes, plan.finish()?))
    }

    /// Replays an individual (a run's best, a genome given) in a fresh
    /// episode and writes its files ([`crate::replay::replay`]).
    pub fn replay(&self, program: Program, options: &ReplayOptions) -> Result<Replayed> {
        crate::replay::replay(program, options, self.observer)
    }

    /// Evaluates `jobs` (genome, episode) of evolved stage `index` of
    /// `program` as evolution does (episodes of `actions` actions, learning
    /// on), on the evaluator or `threads` threads of this process (one per
    /// core: `None`); in the order of `jobs`. An episode stopped by the
    /// interruption flag has a NaN fitness.
    pub fn evaluate(
        &self,
        program: &Program,
        index: usize,
        actions: u32,
        jobs: &[(&Genome, Episode)],
        threads: Option<usize>,
    ) -> Result<Vec<Evaluation>> {
        if index >= program.stages.len() {
            let n = program.stages.len();
            let message = format!("error: there is no stage {index} in a program of {n} stages");
            return Err(crate::Error::new(crate::ErrorKind::Invalid, message));
        }
        Ok(match self.evaluator {
            Some(e) => e.evaluate(program, index, actions, jobs),
            None => Local::new(threads)?.stopped_by(self.interrupt).evaluate(program, index, actions, jobs),
        })
    }
}
