//! What the engine's tests share: the small programs of `tests/cli/`, run
//! and experiment options, the files of a directory, the data a report
//! embeds, and observers that keep what a run tells them or stop it.

// Each test file uses some of these.
#![allow(dead_code)]

use std::cell::{Cell, RefCell};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use shaping_engine::diag::ErrorFormat;
use shaping_engine::experiment::{ExperimentOptions, Finished, Plan};
use shaping_engine::files::DirLock;
use shaping_engine::run::{Event, Observer, RunOptions, RunOutcome};
use shaping_engine::Engine;
use shaping_engine::Error;
use shaping_runtime::program::Program;

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `tests/cli/NAME`.
pub fn test_file(name: &str) -> PathBuf {
    root().join("tests/cli").join(name)
}

/// `tests/cli/tiny.bat`: two small evolved stages, `first` and `second`.
pub fn tiny_bat() -> PathBuf {
    test_file("tiny.bat")
}

/// A source file compiled and validated as every command loads one.
pub fn load(path: &Path) -> Program {
    shaping_engine::load::load_program(path, ErrorFormat::Plain)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

pub fn tiny() -> Program {
    load(&tiny_bat())
}

/// Writes `source` to `dir/name` and loads it.
pub fn write_bat(dir: &Path, name: &str, source: &str) -> (PathBuf, Program) {
    let path = dir.join(name);
    std::fs::write(&path, source).unwrap();
    let program = load(&path);
    (path, program)
}

/// A run into `out` on two threads, without `report.html`.
pub fn options(out: &Path) -> RunOptions {
    RunOptions { out: out.to_path_buf(), no_report: true, jobs: Some(2), ..RunOptions::default() }
}

/// `--set` values of a run, as `(target, value)`.
pub fn sets(values: &[&str]) -> Vec<(String, String)> {
    values
        .iter()
        .map(|s| {
            let (t, v) = s.split_once('=').unwrap();
            (t.to_string(), v.to_string())
        })
        .collect()
}

/// Runs `program` with no observer, evaluator or interruption.
pub fn run(program: Program, opts: &RunOptions) -> Result<RunOutcome, Error> {
    Engine::default().run(program, opts)
}

/// The error of what should have failed.
pub fn error<T>(result: Result<T, Error>) -> Error {
    match result {
        Ok(_) => panic!("it did not fail"),
        Err(e) => e,
    }
}

/// An experiment as `shaping experiment` runs one: the plan checked, the
/// directory locked, every task in order, then the summaries.
pub fn experiment(program: Program, opts: ExperimentOptions) -> Result<Finished, Error> {
    let jobs = opts.jobs;
    let plan = Plan::new(program, opts)?;
    let _lock = plan.lock()?;
    for task in plan.tasks() {
        plan.run_task(task, jobs, &Engine::default())?;
    }
    plan.finish()
}

/// An experiment of `tests/cli/tiny.bat` into `out` (seeds from 1, as the
/// command line counts them), without reports.
pub fn tiny_experiment(out: &Path, seeds: u64) -> ExperimentOptions {
    ExperimentOptions {
        file: tiny_bat(),
        seeds,
        first_seed: 1,
        out: Some(out.to_path_buf()),
        no_report: true,
        ..ExperimentOptions::default()
    }
}

/// The files of a directory, by relative path (not the lock).
pub fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.file_name().is_some_and(|n| n != DirLock::FILE) {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// The results under `dir` (`.csv`, `.json`, `.genome` and `.md` files),
/// relative to it, sorted, with their bytes: not `report.html`, the
/// pictures or temporary files.
pub fn result_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    files(dir)
        .into_iter()
        .filter(|(name, _)| [".csv", ".json", ".genome", ".md"].iter().any(|e| name.ends_with(e)))
        .collect()
}

pub fn read_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).unwrap()
}

pub fn read_text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The data a report embeds.
pub fn report_data(path: &Path) -> serde_json::Value {
    let html = read_text(path);
    let open = "<script type=\"application/json\" id=\"data\">";
    let start = html.find(open).expect("the report embeds its data") + open.len();
    let len = html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..start + len]).unwrap()
}

/// What an observer was told, as owned values.
#[derive(Clone, Debug, PartialEq)]
pub enum Seen {
    Resumed { stage: String, generation: u32, generations: u32, finished: bool },
    Generation { stage: String },
    Evolved { stage: String, generations: u32 },
    Trained { stage: String, actions: u32, recorded: u32, reused: bool },
    Tested { stage: String, lives: u32 },
    Warning(String),
}

/// An observer that keeps every event it is told, in order.
#[derive(Default)]
pub struct Log {
    seen: RefCell<Vec<Seen>>,
}

impl Log {
    /// Everything told so far; the log starts again empty.
    pub fn take(&self) -> Vec<Seen> {
        self.seen.take()
    }

    /// The warnings told so far, and the log starts again empty.
    pub fn warnings(&self) -> Vec<String> {
        self.take()
            .into_iter()
            .filter_map(|s| match s {
                Seen::Warning(w) => Some(w),
                _ => None,
            })
            .collect()
    }

    /// The events of stage `stage` other than generations, and the log
    /// starts again empty.
    pub fn of(&self, stage: &str) -> Vec<Seen> {
        self.take()
            .into_iter()
            .filter(|s| match s {
                Seen::Resumed { stage: s, .. }
                | Seen::Evolved { stage: s, .. }
                | Seen::Trained { stage: s, .. }
                | Seen::Tested { stage: s, .. } => s == stage,
                Seen::Generation { .. } | Seen::Warning(_) => false,
            })
            .collect()
    }

    /// A runner that tells this log.
    pub fn runner(&self) -> Engine<'_> {
        Engine { observer: self, ..Engine::default() }
    }
}

impl Observer for Log {
    fn event(&self, event: Event<'_>) {
        let seen = match event {
            Event::Resumed { stage, generation, generations, finished, .. } => {
                Seen::Resumed { stage: stage.into(), generation, generations, finished }
            }
            Event::Generation { stage, .. } => Seen::Generation { stage: stage.into() },
            Event::Evolved { stage, generations, .. } => Seen::Evolved { stage: stage.into(), generations },
            Event::Trained { stage, trained, recorded, reused, .. } => {
                Seen::Trained { stage: stage.name.clone(), actions: trained.result.actions, recorded, reused }
            }
            Event::Tested { stage, lives, .. } => Seen::Tested { stage: stage.into(), lives },
            Event::Warning(w) => Seen::Warning(w),
            _ => return,
        };
        self.seen.borrow_mut().push(seen);
    }
}

/// An observer that sets `flag`, as Ctrl-C does, once it has been told of
/// `generations` generations.
pub struct StopAfter<'a> {
    pub flag: &'a AtomicBool,
    pub generations: usize,
    told: Cell<usize>,
}

impl<'a> StopAfter<'a> {
    pub fn new(flag: &'a AtomicBool, generations: usize) -> StopAfter<'a> {
        StopAfter { flag, generations, told: Cell::new(0) }
    }

    /// A runner stopped by this observer.
    pub fn runner(&self) -> Engine<'_> {
        Engine { observer: self, evaluator: None, interrupt: Some(self.flag) }
    }
}

impl Observer for StopAfter<'_> {
    fn event(&self, event: Event<'_>) {
        if let Event::Generation { .. } = event {
            self.told.set(self.told.get() + 1);
            if self.told.get() >= self.generations {
                self.flag.store(true, Ordering::Relaxed);
            }
        }
    }
}

/// What a process killed right after writing a generation's checkpoint
/// would leave in stage directory `dir`: the checkpoint, but not yet the
/// `generations.csv` that follows it, and a temporary file of a write
/// under way.
pub fn as_if_killed(dir: &Path) {
    std::fs::remove_file(dir.join("generations.csv")).unwrap();
    std::fs::write(dir.join(".generations.csv.4242.7.tmp"), "stage,generation\nfirst,0").unwrap();
}

/// An observer that holds a run at its first generation until the test has
/// done what it does meanwhile: it waits twice on `barrier` (the test waits
/// once before and once after), then lets the run go on.
pub struct Holding {
    barrier: std::sync::Arc<std::sync::Barrier>,
    held: Cell<bool>,
}

impl Holding {
    pub fn new(barrier: std::sync::Arc<std::sync::Barrier>) -> Holding {
        Holding { barrier, held: Cell::new(false) }
    }
}

impl Observer for Holding {
    fn event(&self, event: Event<'_>) {
        if let Event::Generation { .. } = event {
            if !self.held.replace(true) {
                self.barrier.wait();
                self.barrier.wait();
            }
        }
    }
}
