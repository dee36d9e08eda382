//! Running a program's stages in order into a run directory: training
//! stages, evolution with resume and fingerprint checks, test stages; the
//! files of each stage, and what the caller is told as it goes.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use serde_json::Value;
use shaping_runtime::controller::{EpisodeOptions, EpisodeResult, TeamRun, Trace};
use shaping_runtime::evolve::{self, Checkpoint, Episode, Evaluation, GenStats, Trained};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Param, Program, Stage, StageRun};
use shaping_runtime::sim::Scene;

use crate::episode::{self, Part};
use crate::error::{Error, ErrorKind, Result};
use crate::files::{create_dir, unsealed_warning, DirLock, Unsealed};
use crate::rundir::{self, TestSummary};
use crate::sweep::Assignment;
use crate::{html, report, Engine, RECORDED_TRAINING_ACTIONS};

/// What a run does: which stages, with which seed, into which directory.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Run only this stage and the stages it needs (all stages: `None`).
    pub stage: Option<String>,
    /// The run seed (default: the first evolved stage's declared seed).
    pub seed: Option<u64>,
    /// The run directory.
    pub out: PathBuf,
    /// Worker threads for local evaluation (default: one per core).
    pub jobs: Option<usize>,
    /// Start every stage again, ignoring saved results.
    pub fresh: bool,
    /// Write no `report.html` at the end.
    pub no_report: bool,
    /// Settings changed from the program's (`--set`, one value each).
    pub sets: Vec<Assignment>,
}

/// What a run tells its caller as it goes. The engine prints nothing: a
/// command line draws progress bars from these, a notebook may log them.
#[derive(Debug)]
#[non_exhaustive]
pub enum Event<'a> {
    /// An evolved stage starts, or resumes with `done` of its `generations` done.
    EvolveStart { stage: &'a str, generations: u32, done: u32 },
    /// A stage resumes from its checkpoint (`finished`: nothing is left to do).
    Resumed { stage: &'a str, generation: u32, generations: u32, finished: bool, checkpoint: &'a Path },
    /// A generation was evaluated and saved.
    Generation { stage: &'a str, stats: &'a GenStats },
    /// The generations of an evolved stage are done (its best is chosen
    /// next), or stopped (`completed` false: the run was interrupted).
    EvolveEnd { stage: &'a str, completed: bool },
    /// An evolved stage is done: its last generation and chosen best.
    Evolved { stage: &'a str, generations: u32, last: Option<&'a GenStats>, chosen: f32, dir: &'a Path },
    /// A training stage is done (`reused`: from its saved `trained.json`);
    /// `recorded` of its actions are in its trace.
    Trained { stage: &'a Stage, trained: &'a Trained, recorded: u32, reused: bool, dir: &'a Path },
    /// A test stage is done: its `summary.json`, and the totals of each world.
    Tested {
        stage: &'a str,
        summary: &'a TestSummary,
        lives: u32,
        before: &'a EpisodeResult,
        after: &'a EpisodeResult,
        dir: &'a Path,
    },
    /// Something the user should know: the results are not what they seem
    /// (a crowded world), or a saved file was not used.
    Warning(String),
}

impl serde::Serialize for Event<'_> {
    /// The one JSON form of an event, for every front (`run --json`'s
    /// lines, Python's callback): `{"event": "generation", "stage": ...}`.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        let path = |p: &Path| p.display().to_string();
        let record = match *self {
            Event::EvolveStart { stage, generations, done } => {
                Record::EvolveStart { stage, generations, done }
            }
            Event::Resumed { stage, generation, generations, finished, checkpoint } => {
                Record::Resumed { stage, generation, generations, finished, checkpoint: path(checkpoint) }
            }
            Event::Generation { stage, stats } => Record::Generation { stage, stats },
            Event::EvolveEnd { stage, completed } => Record::EvolveEnd { stage, completed },
            Event::Evolved { stage, generations, last, chosen, dir } => {
                Record::Evolved { stage, generations, last, chosen, dir: path(dir) }
            }
            Event::Trained { stage, trained, recorded, reused, dir } => Record::Trained {
                stage: &stage.name,
                actions: trained.result.actions,
                performance: &trained.performance,
                recorded,
                reused,
                dir: path(dir),
            },
            Event::Tested { stage, summary, lives, dir, .. } => {
                Record::Tested { stage, summary, lives, dir: path(dir) }
            }
            Event::Warning(ref message) => Record::Warning { message },
        };
        record.serialize(serializer)
    }
}

/// [`Event`]'s JSON form.
#[derive(serde::Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
enum Record<'a> {
    EvolveStart { stage: &'a str, generations: u32, done: u32 },
    Resumed { stage: &'a str, generation: u32, generations: u32, finished: bool, checkpoint: String },
    Generation { stage: &'a str, stats: &'a GenStats },
    EvolveEnd { stage: &'a str, completed: bool },
    Evolved { stage: &'a str, generations: u32, last: Option<&'a GenStats>, chosen: f32, dir: String },
    Trained { stage: &'a str, actions: u32, performance: &'a [f32], recorded: u32, reused: bool, dir: String },
    Tested { stage: &'a str, summary: &'a TestSummary, lives: u32, dir: String },
    Warning { message: &'a str },
}

/// Receives a run's [`Event`]s.
pub trait Observer {
    fn event(&self, event: Event<'_>);
}

/// An observer that ignores everything.
pub struct Silent;

impl Observer for Silent {
    fn event(&self, _: Event<'_>) {}
}

/// Where the episodes of an evolved stage are evaluated: on this process's
/// threads ([`Local`]), over MPI ranks, on a robot. Evaluations come back in
/// the order of `jobs`, and an episode's result depends only on its genome
/// and seed, so every evaluator gives the same files.
pub trait Evaluate {
    /// Called before the first evaluation of evolved stage `index`, whose
    /// files are in `dir`; `digest` names the stage as it is (its
    /// fingerprint's), `fresh` that saved results are not to be used.
    fn begin_stage(
        &self,
        _program: &Program,
        _index: usize,
        _dir: &Path,
        _digest: u64,
        _fresh: bool,
    ) -> Result<()> {
        Ok(())
    }
    /// Evaluates `jobs` (genome, episode seed) of evolved stage `index`,
    /// episodes of `actions` actions with learning on; a failed evaluation
    /// has a NaN fitness, and [`Evaluate::failure`] says why.
    fn evaluate(
        &self,
        program: &Program,
        index: usize,
        actions: u32,
        jobs: &[(&Genome, Episode)],
    ) -> Vec<Evaluation>;
    /// What the next evaluations are for, and the checkpoint a new run would
    /// resume from (for the messages of a failure).
    fn context(&self, _what: String, _checkpoint: &Path) {}
    /// Why evaluations failed, if they did.
    fn failure(&self) -> Option<Error> {
        None
    }
}

/// Most worker threads a caller may ask for (`--jobs`, Python's `jobs=`).
pub const MAX_JOBS: usize = 1024;

/// Evaluation on this process's threads (a rayon pool of `jobs` threads).
pub struct Local<'a> {
    pool: rayon::ThreadPool,
    stop: Option<&'a AtomicBool>,
}

impl Local<'static> {
    /// A pool of `jobs` threads (one per core: `None`; 1 to [`MAX_JOBS`]).
    pub fn new(jobs: Option<usize>) -> Result<Local<'static>> {
        if let Some(j) = jobs.filter(|j| !(1..=MAX_JOBS).contains(j)) {
            return Err(Error::new(
                ErrorKind::Invalid,
                format!("error: jobs must be from 1 to {MAX_JOBS} worker threads, not {j}"),
            ));
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs.unwrap_or(0))
            .build()
            .map_err(|e| Error::io(format!("error: cannot start worker threads: {e}")))?;
        Ok(Local { pool, stop: None })
    }
}

impl Local<'_> {
    /// Once `stop` is set, the episodes not yet started are not run and a
    /// team's episode under way is given up at its next action: their
    /// fitness is NaN, so the generation fails and nothing of it is kept
    /// (see [`Engine`]).
    pub fn stopped_by(self, stop: Option<&AtomicBool>) -> Local<'_> {
        Local { pool: self.pool, stop }
    }
}

impl Evaluate for Local<'_> {
    fn evaluate(
        &self,
        program: &Program,
        index: usize,
        actions: u32,
        jobs: &[(&Genome, Episode)],
    ) -> Vec<Evaluation> {
        let stage = &program.stages[index];
        let opts = evolve::EvalOptions { actions, learning: true };
        let stop = self.stop;
        let evaluate =
            evolve::evaluator_until(stage, opts, || stop.is_some_and(|s| s.load(Ordering::Relaxed)));
        self.pool.install(|| evolve::evaluate_many(&evaluate, jobs))
    }
}

/// What a run ended with, stage by stage.
#[derive(Clone, Debug)]
pub struct RunOutcome {
    pub out: PathBuf,
    pub seed: u64,
    pub stages: Vec<StageOutcome>,
    /// `report.html`, unless `no_report`.
    pub report: Option<PathBuf>,
}

/// What one stage of a run ended with.
#[derive(Clone, Debug)]
pub enum StageOutcome {
    Train { stage: String, actions: u32, performance: Vec<f32> },
    Evolve { stage: String, generations: u32, best: f32, genome: Genome },
    Test { stage: String, summary: Box<TestSummary> },
}

impl StageOutcome {
    /// The stage's name.
    pub fn stage(&self) -> &str {
        match self {
            StageOutcome::Train { stage, .. }
            | StageOutcome::Evolve { stage, .. }
            | StageOutcome::Test { stage, .. } => stage,
        }
    }

    /// As the last line of `shaping run --json` shows it.
    pub fn to_json(&self) -> Value {
        match self {
            StageOutcome::Train { stage, actions, performance } => serde_json::json!({
                "stage": stage, "kind": "train", "actions": actions, "performance": performance,
            }),
            StageOutcome::Evolve { stage, generations, best, genome } => serde_json::json!({
                "stage": stage, "kind": "evolve", "generations": generations,
                "best": best, "genome": genome.to_bitstring(),
            }),
            StageOutcome::Test { stage, summary } => {
                serde_json::json!({"kind": "test", "summary": summary, "stage": stage})
            }
        }
    }
}

/// The directory a run of `file` writes to by default: `runs/<file stem>`.
pub fn default_out(file: &Path) -> PathBuf {
    let stem = file.file_stem().map_or_else(|| "program".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from("runs").join(stem)
}

/// The run seed: `--seed`, else the first evolved stage's declared seed.
pub fn run_seed(program: &Program, seed: Option<u64>) -> u64 {
    seed.unwrap_or_else(|| {
        program
            .stages
            .iter()
            .find_map(|s| match &s.run {
                StageRun::Evolve(e) => Some(e.seed),
                StageRun::Test { .. } | StageRun::Train { .. } => None,
            })
            .unwrap_or(1)
    })
}

/// The stages to run for a target stage: it, its ancestors and the training
/// stages whose weights they use, in program order.
pub fn chain(program: &Program, target: usize) -> Vec<usize> {
    let mut need = vec![false; program.stages.len()];
    for i in program.lineage(target) {
        need[i] = true;
        for (_, p) in program.stages[i].modules.iter().flat_map(|m| m.network_params()) {
            if let Param::Trained { stage, .. } = *p {
                if let Some(n) = need.get_mut(stage as usize) {
                    *n = true;
                }
            }
        }
    }
    (0..program.stages.len()).filter(|&i| need[i]).collect()
}

/// Episodes whose world could not be placed apart: some placement (an
/// object, the robot's start, a virtual object coming back) ran out of
/// tries and kept an overlapping one, so the episode is not the declared
/// world and its fitness is not that world's. Worlds that can never be
/// placed are refused before a run (`world::crowded`); one that is only
/// crowded runs, and this says how often it did not fit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Crowding {
    /// Episodes (or lives) counted.
    pub episodes: u64,
    /// Those with a placement that overlaps.
    pub crowded: u64,
    /// Placements that overlap, over all of them.
    pub placements: u64,
}

impl Crowding {
    /// The episodes counted since `earlier`, a count of the same episodes
    /// taken before.
    pub fn since(self, earlier: Crowding) -> Crowding {
        Crowding {
            episodes: self.episodes - earlier.episodes,
            crowded: self.crowded - earlier.crowded,
            placements: self.placements - earlier.placements,
        }
    }

    /// Counts one episode with `placement_failures` overlapping placements.
    pub fn add(&mut self, placement_failures: u32) {
        self.episodes += 1;
        self.crowded += u64::from(placement_failures > 0);
        self.placements += u64::from(placement_failures);
    }

    /// The warning for stage `stage`, whose files are in `dir`, if any of
    /// its episodes was crowded; `what` names them, one and several
    /// (`("episode", "episodes")`).
    pub fn warning(&self, stage: &str, dir: &Path, what: (&str, &str)) -> Option<String> {
        (self.crowded > 0).then(|| {
            let (n, m, p) = (self.crowded, self.episodes, self.placements);
            let (which, those) = if m == 1 {
                (format!("in its {}", what.0), format!("its {}", what.0))
            } else {
                (format!("in {n} of {m} {}", what.1), format!("those {}", what.1))
            };
            let places = if p == 1 { "1 placement".to_string() } else { format!("{p} placements") };
            format!(
                "warning: the world of stage `{stage}` is too crowded: {which} objects (or the robot) could not be \
                 placed apart and overlap ({places} kept an overlapping last try), so the results of {those} are not \
                 of the world as declared; fewer or smaller objects, or a larger arena, give them room (results in `{}`)",
                dir.display()
            )
        })
    }
}

/// The error for a saved result (checkpoint or trained weights) that does
/// not belong to the program as it is now.
fn stale(path: &Path, e: &evolve::EvolveError) -> Error {
    let hint = match e {
        evolve::EvolveError::TooManyGenerations { done, .. } => {
            format!("declare at least {done} generations, pass `--fresh` to start again, or choose another `--out`")
        }
        _ => "pass `--fresh` to start again, or choose another `--out`".to_string(),
    };
    Error::stale(path, e.to_string(), format!("error: cannot resume from `{}`: {e}; {hint}", path.display()))
}

/// A saved result of another seed than the run's.
fn other_seed(path: &Path, saved: u64, seed: u64) -> Error {
    Error::stale(
        path,
        format!("seed {saved}, not {seed}"),
        format!(
            "error: `{}` belongs to a run with seed {saved} (this run has seed {seed}); pass `--seed {saved}` to resume it, `--fresh` to start again, or another `--out`",
            path.display()
        ),
    )
}

/// A stage the program cannot run or train as it is (the runtime's
/// refusal: a genome of another layout, a setup that does not fit).
fn unusable(e: impl std::fmt::Display) -> Error {
    Error::new(ErrorKind::Invalid, format!("error: {e}"))
}

/// The error of a run stopped by its interruption flag.
fn interrupted(message: String) -> Error {
    Error::new(ErrorKind::Interrupted, message)
}

/// Checks, before anything is written, what a run of `stages` would
/// resume from `out`: the saved stages belong to one seed (stages of two
/// seeds, one of them started again with `--fresh --stage S --seed N`,
/// cannot be resumed by one run with either seed), and each saved
/// checkpoint and `trained.json` fits the program (training stages bound
/// in order as the run binds them; the check stops at a training stage
/// that has to be trained again, whose weights are not known yet).
fn precheck(
    program: &Program,
    stages: &[usize],
    out: &Path,
    seed: u64,
    unsealed: Unsealed<'_>,
) -> Result<Saved> {
    let mut saved = Saved::none(program);
    let mut seeds_of: Vec<(&str, u64, PathBuf)> = Vec::new();
    let mut bound = program.clone();
    let mut binding = true;
    for &i in stages {
        let st = &program.stages[i];
        let dir = rundir::stage_dir(out, &st.name);
        match st.run {
            StageRun::Evolve(_) => {
                if let Some(cp) = rundir::read_checkpoint_with(&dir, unsealed)? {
                    seeds_of.push((&st.name, cp.seed, rundir::checkpoint_path(&dir)));
                    if binding && cp.seed == seed {
                        let path = rundir::checkpoint_path(&dir);
                        evolve::check_resume_of(&bound, i, &cp).map_err(|e| stale(&path, &e))?;
                    }
                    saved.checkpoints[i] = Some(cp);
                }
            }
            StageRun::Train { .. } => match rundir::read_trained_with(&dir, unsealed)? {
                Some(t) => {
                    seeds_of.push((&st.name, t.run_seed, rundir::trained_path(&dir)));
                    if binding && t.run_seed == seed {
                        let path = rundir::trained_path(&dir);
                        evolve::train::check(&bound, i, &t).map_err(|e| stale(&path, &e))?;
                        evolve::train::bind(&mut bound, i, &t).map_err(unusable)?;
                    } else {
                        binding = false;
                    }
                    saved.trained[i] = Some(t);
                }
                None => binding = false,
            },
            StageRun::Test { .. } => {}
        }
    }
    let mut seeds: Vec<u64> = seeds_of.iter().map(|&(_, s, _)| s).collect();
    seeds.sort_unstable();
    seeds.dedup();
    match seeds[..] {
        [] => return Ok(saved),
        [s] if s == seed => return Ok(saved),
        // Saved results of one other seed: `--seed` resumes them only if
        // they fit the program as it is; say so only then.
        [other] => {
            let path = &seeds_of[0].2;
            return Err(match precheck(program, stages, out, other, &|_| {}) {
                Ok(_) => other_seed(path, other, seed),
                Err(e) if e.kind() == ErrorKind::Stale => Error::new(
                    ErrorKind::Stale,
                    format!(
                        "error: `{}` belongs to a run with seed {other} (this run has seed {seed}), which `--seed {other}` \
                         would not resume either: {}",
                        path.display(),
                        e.message().trim_start_matches("error: ")
                    ),
                ),
                Err(e) => e,
            });
        }
        _ => {}
    }
    let which: Vec<String> = seeds_of.iter().map(|(name, s, _)| format!("`{name}` seed {s}")).collect();
    Err(Error::new(
        ErrorKind::Stale,
        format!(
            "error: `{}` holds stages of different seeds ({}); one run resumes stages of one seed: \
             pass `--fresh` to run every stage again with seed {seed}, or choose another `--out`",
            out.display(),
            which.join(", ")
        ),
    ))
}

/// A run directory belongs to one program: refuses a run of another into
/// `out` (`previous`: its `program.json`), by the file's name where both
/// are known (`source.json`, `source`), else by the program's name.
fn check_owner(
    out: &Path,
    previous: Option<&Program>,
    program: &Program,
    source: Option<&str>,
) -> Result<()> {
    let theirs = match (rundir::read_source(out), source) {
        (Some(was), Some(now)) if was != now => format!("`{was}`, not of `{now}`"),
        (Some(_), Some(_)) => return Ok(()),
        _ => match previous {
            Some(p) if p.name != program.name => format!("program `{}`, not of `{}`", p.name, program.name),
            _ => return Ok(()),
        },
    };
    Err(Error::stale(
        out,
        format!("a run of {theirs}"),
        format!(
            "error: `{}` holds a run of {theirs} (a run directory belongs to one program); choose another `--out`, \
             or pass `--fresh` to replace that run with this one",
            out.display()
        ),
    ))
}

/// `program.json` describes every stage directory beside it: refuses,
/// before anything is written, a run that would rewrite it with another
/// definition of a stage it does not run (a `--set` of a stage outside its
/// `--stage`, a stage edited in the file, a stage extending one that
/// changed) whose directory holds results. `file` is the file's program,
/// `sets` the run's settings, `program` the file's with them, `stages`
/// those the run runs. Where leaving some `--set` values out would do, the
/// message names them (found by leaving each out in turn and keeping the
/// omissions that bring the programs closer).
fn check_described(
    out: &Path,
    previous: &Program,
    (program, file, sets): (&Program, &Program, &[Assignment]),
    stages: &[usize],
) -> Result<()> {
    let changed = misdescribed(out, previous, program, stages);
    if changed.is_empty() {
        return Ok(());
    }
    let distance =
        |p: &Program| -> usize { misdescribed(out, previous, p, stages).iter().map(|m| m.parts).sum() };
    let mut keep: Vec<Assignment> = sets.to_vec();
    let mut left_out = Vec::new();
    let mut now = distance(program);
    for a in sets {
        let trial: Vec<Assignment> = keep.iter().filter(|k| *k != a).cloned().collect();
        let mut p = file.clone();
        if crate::sweep::apply(&mut p, &trial).is_err() {
            continue;
        }
        let d = distance(&p);
        if d < now {
            (now, keep) = (d, trial);
            left_out.push(format!("`--set {}={}`", a.0, a.1));
        }
    }
    let names: Vec<String> = changed.iter().map(|m| format!("`{}`", m.stage)).collect();
    let why: Vec<&str> = changed.iter().map(|m| m.what.as_str()).collect();
    let dirs: Vec<String> = changed.iter().map(|m| format!("`{}`", m.dir.display())).collect();
    let (stage, them, it) =
        if changed.len() == 1 { ("stage", "its", "it") } else { ("stages", "their", "them") };
    // Or the settings the directory's run was made with, missing here.
    let made_with = crate::sweep::settings_between(program, previous).filter(|f| !f.is_empty());
    let sets = match made_with {
        _ if now == 0 => format!("leave out {}, ", left_out.join(" and ")),
        Some(found) => {
            let found: Vec<String> = found.iter().map(|(t, v)| format!("--set {t}={v}")).collect();
            format!("add `{}` (the settings its run was made with), ", found.join(" "))
        }
        None => String::new(),
    };
    Err(Error::stale(
        &rundir::program_path(out),
        why.join("; "),
        format!(
            "error: this run would rewrite `{}` with another definition of {stage} {} ({}) without running {it}, \
             and {them} results in {} would no longer be of the program described there; {sets}pass `--fresh` \
             without `--stage` to run every stage again, move {} away, or choose another `--out`",
            rundir::program_path(out).display(),
            names.join(", "),
            why.join("; "),
            dirs.join(", "),
            dirs.join(", ")
        ),
    ))
}

/// A stage whose results `program.json` would no longer describe.
struct Misdescribed<'a> {
    stage: &'a str,
    /// What changed, in words.
    what: String,
    /// How many parts of its fingerprint changed.
    parts: usize,
    dir: PathBuf,
}

/// The stages of `program` outside `stages` whose directories in `out`
/// hold results and whose definition (their fingerprint: the stage and
/// the evolved stages it extends) differs from `previous`'s.
fn misdescribed<'a>(
    out: &Path,
    previous: &Program,
    program: &'a Program,
    stages: &[usize],
) -> Vec<Misdescribed<'a>> {
    use evolve::fingerprint::{changes, fingerprint};
    let mut found = Vec::new();
    for (i, st) in program.stages.iter().enumerate() {
        let dir = rundir::stage_dir(out, &st.name);
        if stages.contains(&i) || !rundir::holds_results(&dir) {
            continue;
        }
        let Some((j, _)) = previous.stage(&st.name) else { continue };
        let (was, now) = (fingerprint(previous, j), fingerprint(program, i));
        let what = changes(&was, &now);
        if what.is_empty() {
            continue;
        }
        let parts = was.len().abs_diff(now.len())
            + was
                .iter()
                .zip(&now)
                .map(|(a, b)| a.parts.iter().filter(|(k, v)| b.parts.get(*k) != Some(v)).count())
                .sum::<usize>();
        found.push(Misdescribed { stage: &st.name, what: what.join("; "), parts: parts.max(1), dir });
    }
    found
}

/// What a run resumes from, read once by [`precheck`]: per stage, its
/// checkpoint or trained weights (none with `--fresh`).
struct Saved {
    checkpoints: Vec<Option<Checkpoint>>,
    trained: Vec<Option<Trained>>,
}

impl Saved {
    fn none(program: &Program) -> Saved {
        let n = program.stages.len();
        Saved { checkpoints: vec![None; n], trained: vec![None; n] }
    }
}

impl Engine<'_> {
    fn stopped(&self) -> bool {
        self.interrupt.is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// Runs the stages of `program` (with `opts.sets` applied) into
    /// `opts.out`, resuming what is saved there, and locks the directory
    /// while it does. The directory belongs to one program: a run of
    /// another (by `program.json`'s name) is refused unless `opts.fresh`.
    pub fn run(&self, program: Program, opts: &RunOptions) -> Result<RunOutcome> {
        self.run_source(program, None, opts)
    }

    /// [`Engine::run`] of the program loaded from the file `source`: of a
    /// `.bat` file, the directory records the file's name (`source.json`),
    /// and a run of another file into it is refused unless `opts.fresh`
    /// (several files may share a program's name, their robot's); a built
    /// program (`.json`) is [`Engine::run`]'s.
    pub fn run_file(&self, program: Program, source: &Path, opts: &RunOptions) -> Result<RunOutcome> {
        if source.extension().is_some_and(|e| e == "json") {
            return self.run(program, opts);
        }
        let name = source.file_name().map(|n| n.to_string_lossy().into_owned());
        self.run_source(program, name.as_deref(), opts)
    }

    fn run_source(
        &self,
        mut program: Program,
        source: Option<&str>,
        opts: &RunOptions,
    ) -> Result<RunOutcome> {
        // The file's own program, to tell a change made by `--set` from one
        // made in the file.
        let file = program.clone();
        crate::sweep::apply(&mut program, &opts.sets)?;
        if program.stages.is_empty() {
            return Err(Error::new(ErrorKind::Invalid, "error: the program has no stages"));
        }
        let stages = stages_to_run(&program, opts.stage.as_deref())?;
        crate::load::check_memory(&program, &stages, 1)?;
        let out = opts.out.clone();
        let seed = run_seed(&program, opts.seed);
        let local = Local::new(opts.jobs)?.stopped_by(self.interrupt);
        let _lock = DirLock::acquire(&out)?;
        let mut saved = self.take_over(&program, &file, source, opts, &stages, seed)?;
        let evaluator = self.evaluator.unwrap_or(&local);
        let mut finals: Vec<Option<Checkpoint>> = vec![None; program.stages.len()];
        let mut results = Vec::new();
        for &index in &stages {
            // Stopped during a training life, a test or the choice of a best:
            // the step under way finished and is saved; stop before the next.
            if self.stopped() {
                return Err(interrupted(format!(
                    "interrupted: stopped before stage `{}`; what ran is saved in `{}`, and the same command resumes",
                    program.stages[index].name,
                    out.display()
                )));
            }
            let dir = rundir::stage_dir(&out, &program.stages[index].name);
            rundir::create_stage_dir(&dir)?;
            if let StageRun::Train { .. } = program.stages[index].run {
                let trained = self.train_step(&program, index, seed, &dir, saved.trained[index].take())?;
                evolve::train::bind(&mut program, index, &trained).map_err(unusable)?;
                results.push(StageOutcome::Train {
                    stage: program.stages[index].name.clone(),
                    actions: trained.result.actions,
                    performance: trained.performance,
                });
                continue;
            }
            let stage = &program.stages[index];
            match &stage.run {
                StageRun::Evolve(_) => {
                    let parent = evolved_parent(&program, index, &finals)?;
                    let start = StageStart {
                        seed,
                        parent,
                        existing: saved.checkpoints[index].take(),
                        fresh: opts.fresh,
                    };
                    let cp = self.evolve_stage(&program, index, start, &dir, evaluator)?;
                    best_episode(stage, &cp, seed, &dir, self.interrupt)?;
                    if let Some((genome, best)) = evolve::best_of(&cp) {
                        results.push(StageOutcome::Evolve {
                            stage: stage.name.clone(),
                            generations: cp.generation,
                            best,
                            genome,
                        });
                    }
                    finals[index] = Some(cp);
                }
                StageRun::Test { actions, lives, learning } => {
                    let parent = evolved_parent(&program, index, &finals)?.ok_or_else(|| {
                        Error::new(
                            ErrorKind::Invalid,
                            format!("error: test stage `{}` extends no evolved stage", stage.name),
                        )
                    })?;
                    let test = TestRun {
                        program: &program,
                        index,
                        seed,
                        parent,
                        lives: Lives { actions: *actions, count: *lives, learning: *learning },
                    };
                    let summary = self.test_stage(&test, &dir)?;
                    results
                        .push(StageOutcome::Test { stage: stage.name.clone(), summary: Box::new(summary) });
                }
                StageRun::Train { .. } => unreachable!("training stages run above"),
            }
        }
        if self.stopped() {
            return Err(interrupted(format!(
                "interrupted: every stage is done and saved in `{0}`, but not `report.html` (`shaping report {0}` writes it)",
                out.display()
            )));
        }
        let report = if opts.no_report { None } else { Some(html::write(&out, None)?) };
        Ok(RunOutcome { out, seed, stages: results, report })
    }

    /// Makes the locked directory `opts.out` the run of `program` (the
    /// file's own program `file`, before `--set`, read from `source`): checks
    /// that the directory belongs to it and describes it, reads what the run
    /// resumes from (nothing with `--fresh`), and writes the program and the
    /// name of its file.
    fn take_over(
        &self,
        program: &Program,
        file: &Program,
        source: Option<&str>,
        opts: &RunOptions,
        stages: &[usize],
        seed: u64,
    ) -> Result<Saved> {
        let out = &opts.out;
        let warn = |path: &Path| warn_unsealed(self.observer, path);
        let previous = rundir::read_program(out);
        if !opts.fresh {
            check_owner(out, previous.as_ref(), program, source)?;
        }
        if let Some(previous) = &previous {
            check_described(out, previous, (program, file, &opts.sets), stages)?;
        }
        let saved =
            if opts.fresh { Saved::none(program) } else { precheck(program, stages, out, seed, &warn)? };
        // The compiled program, for `shaping report` (and `shaping run program.json`).
        rundir::write_program(out, program)?;
        // Whose it is: the file, where it is known; a run that replaced
        // another program's leaves no name of that one.
        if source.is_some() || opts.fresh {
            rundir::write_source(out, source)?;
        }
        Ok(saved)
    }
}

/// The stages a run of `program` runs, in order: `stage` and the stages it
/// extends, or every stage.
fn stages_to_run(program: &Program, stage: Option<&str>) -> Result<Vec<usize>> {
    Ok(match stage {
        Some(_) => chain(program, crate::load::stage_index(program, stage)?),
        None => (0..program.stages.len()).collect(),
    })
}

/// `episode.json` of an evolved stage: one recorded episode of its best
/// individual, the one `shaping replay FILE --stage S` shows by default
/// (the run seed, the stage's life, learning on). Once `stop` is set, a
/// team's episode is given up at its next action and nothing is written.
fn best_episode(
    stage: &Stage,
    cp: &Checkpoint,
    seed: u64,
    dir: &Path,
    stop: Option<&AtomicBool>,
) -> Result<()> {
    let StageRun::Evolve(evo) = &stage.run else { return Ok(()) };
    let Some((genome, _)) = evolve::best_of(cp) else { return Ok(()) };
    let opts = EpisodeOptions { actions: evo.actions, learning: true, seed };
    let recorded = episode::record_until(stage, &genome, &opts, stop).map_err(unusable)?;
    let Some(recorded) = recorded else {
        return Err(interrupted(format!(
            "interrupted: stage `{}` stopped while recording its best's episode (`episode.json`); the stage is saved \
             in `{}`, and the same command records it",
            stage.name,
            dir.display()
        )));
    };
    report::team_columns(dir, stage, &recorded.others, &recorded.episode)?;
    rundir::write_episode(dir, &recorded.episode)
}

/// Warns through `observer` that `path` was read without a seal.
pub fn warn_unsealed(observer: &dyn Observer, path: &Path) {
    if let Some(w) = unsealed_warning(&[path.to_path_buf()]) {
        observer.event(Event::Warning(w));
    }
}

/// The final checkpoint of the nearest evolved ancestor of `index`.
fn evolved_parent<'a>(
    program: &Program,
    index: usize,
    finals: &'a [Option<Checkpoint>],
) -> Result<Option<&'a Checkpoint>> {
    let Some(p) = program.evolved_above(index) else {
        return Ok(None);
    };
    finals[p].as_ref().map(Some).ok_or_else(|| {
        Error::new(ErrorKind::Invalid, format!("error: stage `{}` has not been run", program.stages[p].name))
    })
}

/// How an evolved stage starts: the run's seed, the checkpoint of the
/// stage it extends, its own checkpoint to resume from, and whether the
/// evaluator starts it afresh.
struct StageStart<'a> {
    seed: u64,
    parent: Option<&'a Checkpoint>,
    existing: Option<Checkpoint>,
    fresh: bool,
}

impl Engine<'_> {
    /// Runs (or resumes) evolved stage `index` to its end and its chosen best,
    /// writing its files into `dir`.
    fn evolve_stage(
        &self,
        program: &Program,
        index: usize,
        start: StageStart<'_>,
        dir: &Path,
        evaluator: &dyn Evaluate,
    ) -> Result<Checkpoint> {
        let StageStart { seed, parent, existing, fresh } = start;
        let stage = &program.stages[index];
        let StageRun::Evolve(evo) = &stage.run else {
            unreachable!("evolve_stage is called for evolved stages")
        };
        let path = rundir::checkpoint_path(dir);
        let mut cp = self.start_or_resume(program, index, seed, parent, &path, existing)?;
        self.observer.event(Event::EvolveStart {
            stage: &stage.name,
            generations: evo.generations,
            done: cp.generation,
        });
        // An evaluator's saved episodes (a robot's log) are tied to the stage
        // as the checkpoint is.
        evaluator.begin_stage(program, index, dir, evolve::fingerprint::digest(&cp.fingerprint), fresh)?;
        // A generation (or the choice of the best) whose episodes were given
        // up for Ctrl-C fails (no results, see `many`) before the checkpoint
        // changes: it is dropped whole, and the run resumes before it.
        let fail = |e: evolve::EvolveError, cp: &Checkpoint| {
            if let Some(f) = evaluator.failure() {
                return f;
            }
            if self.stopped() && matches!(e, evolve::EvolveError::Inconsistent { .. }) {
                return dropped(program, cp, &path);
            }
            Error::new(ErrorKind::Evaluation, format!("error: {e}"))
        };
        // The episodes this process runs for the stage, for the warning about
        // a crowded world (the generations' are in their statistics too).
        let run_now = std::cell::Cell::new(Crowding::default());
        let many = |jobs: &[(&Genome, Episode)]| {
            let evaluations = evaluator.evaluate(program, index, evo.actions, jobs);
            if self.stopped() && evaluations.iter().any(|ev| ev.fitness.is_nan()) {
                // Episodes given up for Ctrl-C: no result at all, so the
                // generation (or the choice of the best) fails as a whole.
                return Vec::new();
            }
            let mut tally = run_now.get();
            for ev in &evaluations {
                tally.add(ev.placement_failures);
            }
            run_now.set(tally);
            evaluations
        };
        let mut warned = false;
        while !evolve::is_finished(program, &cp) {
            evaluator.context(format!("generation {} of stage `{}`", cp.generation, stage.name), &path);
            let stats = match evolve::step_generation_with(program, &mut cp, &many) {
                Ok(stats) => stats,
                Err(e) => {
                    if self.stopped() {
                        self.observer.event(Event::EvolveEnd { stage: &stage.name, completed: false });
                    }
                    return Err(fail(e, &cp));
                }
            };
            rundir::write_generation(dir, &cp, &report::variant_names(stage))?;
            self.observer.event(Event::Generation { stage: &stage.name, stats: &stats });
            if stats.crowded_episodes > 0 && !warned {
                // Said at once (a long run may be stopped), and again with the
                // totals at the end of the stage.
                warned = true;
                self.observer.event(Event::Warning(crowded_generation(&stage.name, evo, &stats)));
            }
            if self.stopped() && !evolve::is_finished(program, &cp) {
                self.observer.event(Event::EvolveEnd { stage: &stage.name, completed: false });
                return Err(stopped_after(&stage.name, &cp, evo, &path));
            }
        }
        self.observer.event(Event::EvolveEnd { stage: &stage.name, completed: true });
        let generations_now = run_now.get();
        if !cp.validated {
            // Pick the stage's best by its mean over fresh episodes, not by its
            // luckiest single evaluation.
            evaluator.context(format!("the choice of the best of stage `{}`", stage.name), &path);
            evolve::validate_best_with(
                program,
                &mut cp,
                &many,
                evolve::VALIDATE_CANDIDATES,
                evolve::VALIDATE_EPISODES,
            )
            .map_err(|e| fail(e, &cp))?;
            rundir::write_checkpoint(dir, &cp)?;
        }
        self.finish_evolved(stage, evo, &cp, run_now.get().since(generations_now), dir)?;
        Ok(cp)
    }

    /// The end of evolved stage `stage`, whose checkpoint `cp` holds its
    /// chosen best (`evo` its evolution): the warning about a crowded world (`choice` counts the
    /// episodes of the choice of the best this process ran), the best's
    /// files and the fitness plot in `dir`, and the stage's summary event.
    fn finish_evolved(
        &self,
        stage: &Stage,
        evo: &shaping_runtime::program::Evolution,
        cp: &Checkpoint,
        choice: Crowding,
        dir: &Path,
    ) -> Result<()> {
        if let Some(w) =
            stage_crowding(cp, &stage.name, evo, choice).warning(&stage.name, dir, ("episode", "episodes"))
        {
            self.observer.event(Event::Warning(w));
        }
        let (genome, fitness) = evolve::best_of(cp).ok_or_else(|| {
            Error::new(
                ErrorKind::Evaluation,
                format!("error: stage `{}` evaluated no individual", stage.name),
            )
        })?;
        rundir::write_evolved(dir, &genome, cp, &report::variant_names(stage))?;
        report::fitness_plot(dir, &format!("{}: fitness per generation", stage.name), &cp.history)?;
        self.observer.event(Event::Evolved {
            stage: &stage.name,
            generations: cp.generation,
            last: cp.history.last(),
            chosen: fitness,
            dir,
        });
        Ok(())
    }

    /// Evolved stage `index`'s checkpoint to go on from: `existing`
    /// resumed (the same seed, fitting the program), or a new start from
    /// `parent`'s population; and the stage checked runnable, since every
    /// individual would silently score 0 on a stage the controller cannot
    /// run (e.g. weights of a training stage that was not bound).
    fn start_or_resume(
        &self,
        program: &Program,
        index: usize,
        seed: u64,
        parent: Option<&Checkpoint>,
        path: &Path,
        existing: Option<Checkpoint>,
    ) -> Result<Checkpoint> {
        let stage = &program.stages[index];
        let cp = match existing {
            Some(mut cp) => {
                if cp.seed != seed {
                    return Err(other_seed(path, cp.seed, seed));
                }
                evolve::resume(program, index, &mut cp).map_err(|e| stale(path, &e))?;
                if let StageRun::Evolve(evo) = &stage.run {
                    self.observer.event(Event::Resumed {
                        stage: &stage.name,
                        generation: cp.generation,
                        generations: evo.generations,
                        finished: evolve::is_finished(program, &cp) && cp.validated,
                        checkpoint: path,
                    });
                }
                cp
            }
            None => evolve::start_stage(program, index, seed, parent).map_err(unusable)?,
        };
        let probe = Genome::zeros(stage.layout.bits as usize);
        shaping_runtime::controller::validate(stage, &probe).map_err(|e| {
            Error::new(ErrorKind::Invalid, format!("error: stage `{}` cannot run: {e}", stage.name))
        })?;
        Ok(cp)
    }
}

/// Stage `name` (evolved by `evo`) stopped for Ctrl-C after the generation
/// of `cp`, which is saved at `path`: where the same command goes on.
fn stopped_after(
    name: &str,
    cp: &Checkpoint,
    evo: &shaping_runtime::program::Evolution,
    path: &Path,
) -> Error {
    interrupted(format!(
        "interrupted: stage `{}` stopped after generation {} of {}, saved in `{}`; the same command resumes it",
        name,
        cp.generation,
        evo.generations,
        path.display()
    ))
}

/// A generation (or the choice of the best) of the stage of `cp` given up
/// for Ctrl-C: dropped whole, and where the same command goes on.
fn dropped(program: &Program, cp: &Checkpoint, path: &Path) -> Error {
    let stage = &program.stages[cp.stage];
    let generations = match &stage.run {
        StageRun::Evolve(evo) => evo.generations,
        _ => cp.generation,
    };
    interrupted(if evolve::is_finished(program, cp) {
        format!(
            "interrupted: stage `{}` stopped while choosing its best, which is dropped; its generations \
             are saved in `{}`, and the same command resumes it",
            stage.name,
            path.display()
        )
    } else if cp.generation == 0 {
        format!(
            "interrupted: stage `{}` stopped in its first generation, which is dropped; nothing of the \
             stage was saved, and the same command runs it",
            stage.name
        )
    } else {
        format!(
            "interrupted: stage `{}` stopped in generation {} of {}, which is dropped; the {} before it \
             are saved in `{}`, and the same command resumes it",
            stage.name,
            cp.generation + 1,
            generations,
            cp.generation,
            path.display()
        )
    })
}

/// The warning of the first generation of stage `name` with crowded
/// episodes.
fn crowded_generation(name: &str, evo: &shaping_runtime::program::Evolution, stats: &GenStats) -> String {
    format!(
        "warning: the world of stage `{}` is too crowded: in generation {}, {} of {} episodes placed \
         objects (or the robot) overlapping; the run goes on, and the end of the stage gives the count",
        name,
        stats.stage_generation,
        stats.crowded_episodes,
        u64::from(evo.population) * u64::from(evo.evaluations.max(1))
    )
}

/// The crowded episodes of evolved stage `name`: its generations in the
/// checkpoint's history (those of an earlier, resumed run too) and the
/// choice of its best (`choice`, when this process made it).
fn stage_crowding(
    cp: &Checkpoint,
    name: &str,
    evo: &shaping_runtime::program::Evolution,
    choice: Crowding,
) -> Crowding {
    let per_generation = u64::from(evo.population) * u64::from(evo.evaluations.max(1));
    let mut c = choice;
    for h in cp.history.iter().filter(|h| h.stage == name) {
        c.episodes += per_generation;
        c.crowded += u64::from(h.crowded_episodes);
        c.placements += u64::from(h.placement_failures);
    }
    c
}

/// The lives of a test stage's individual: `lives` lives of at most
/// `actions` actions in the world of the stage it extends ("before"), then as
/// many in the stage's own world ("after"), with one controller, so what local
/// learning acquired (and the performance indicators) carries over from life
/// to life and across the change (the paper's section 4.9). Every life is a
/// fresh world (full battery, objects placed anew) with its own simulator
/// seed, [`evolve::seed::test_life_seed`]; a life ends early when the battery
/// is empty. In a world with variants, life `k` runs in variant `k` mod
/// their number.
pub struct BeforeAfter {
    /// Every life, in order, the action index running on.
    pub trace: Trace,
    /// Index of the first action in the changed world.
    pub switch: u32,
    /// What each life before the change produced.
    pub before: Vec<EpisodeResult>,
    /// What each life after the change produced.
    pub after: Vec<EpisodeResult>,
    /// The changed world at the start of its first life, for the trajectory picture.
    pub scene: Scene,
    /// The recorded episode, every life a part (`episode.json`).
    pub episode: episode::Episode,
    /// A team's other robots in every life, their rows at the actions of
    /// `trace` (none for one robot).
    pub others: Vec<episode::OtherRobot>,
}

impl BeforeAfter {
    /// The first action of every life but the first: the boundaries in the trace.
    pub fn life_starts(&self) -> Vec<u32> {
        let mut at = 0;
        let mut out = Vec::new();
        for r in self.before.iter().chain(&self.after) {
            if at > 0 {
                out.push(at);
            }
            at += r.actions;
        }
        out
    }
}

pub fn before_after(
    parent: &Stage,
    stage: &Stage,
    genome: &Genome,
    lives: Lives,
    seed: u64,
    stop: Option<&AtomicBool>,
) -> Result<BeforeAfter, Error> {
    let Lives { actions, count: lives, learning } = lives;
    if lives == 0 {
        return Err(Error::new(
            ErrorKind::Invalid,
            format!("error: test stage `{}` has no life to run", stage.name),
        ));
    }
    let mut run = TeamRun::new(stage, genome, seed)
        .map_err(|e| Error::new(ErrorKind::Invalid, format!("error: stage `{}`: {e}", stage.name)))?;
    let opts = EpisodeOptions { actions, learning, seed };
    let mut trace = Trace::default();
    let mut others = Vec::new();
    let mut parts = Vec::new();
    let mut results = [Vec::new(), Vec::new()];
    for (half, world) in [parent, stage].into_iter().enumerate() {
        for k in 0..lives {
            // With variants, life k runs in variant k mod their number.
            let w = world.variant_world(k as usize % world.variant_count());
            run.use_world(w);
            let life_seed = evolve::seed::test_life_seed(seed, half == 1, k);
            let life = episode::record_life(&mut run, w, life_seed, &opts, stop);
            results[half].push(life.result.team);
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                // The life was cut short: nothing of this test is a result.
                return Err(interrupted_test(stage, half == 1, k, lives));
            }
            let from = trace.rows.len() as u32;
            let shift = |t: &mut Trace| {
                for r in &mut t.rows {
                    r.action += from;
                }
            };
            let mut mine = life.trace;
            shift(&mut mine);
            trace.modules.clone_from(&mine.modules);
            trace.rows.append(&mut mine.rows);
            for mut o in life.others {
                shift(&mut o.trace);
                o.part = parts.len();
                others.push(o);
            }
            parts.push(Part { stage: &world.name, scene: life.scene, frames: life.frames });
        }
    }
    let switch = results[0].iter().map(|r| r.actions).sum();
    let scene = parts[lives as usize].scene.clone();
    let mut episode = episode::episode(stage, seed, learning, &trace, &parts);
    episode.add_others(&others);
    let [before, after] = results;
    Ok(BeforeAfter { trace, switch, before, after, scene, episode, others })
}

/// Ctrl-C during a test stage: the life under way stopped at its next
/// action, and nothing of the test is written (its files, if any, are
/// those of an earlier run).
fn interrupted_test(stage: &Stage, after: bool, life: u32, lives: u32) -> Error {
    let world = if after { "its own world" } else { "the world before the change" };
    interrupted(format!(
        "interrupted: test stage `{}` stopped in life {} of {lives} in {world}; nothing of it was written \
         (the stages before it are saved), and the same command runs it again",
        stage.name,
        life + 1
    ))
}

/// The crowded lives of a test, in both worlds.
fn lives_crowding(ba: &BeforeAfter) -> Crowding {
    let mut c = Crowding::default();
    for r in ba.before.iter().chain(&ba.after) {
        c.add(r.placement_failures);
    }
    c
}

/// The lives of one world together: actions and events summed, the fitness
/// the mean per life (comparable with a life's fitness in evolution).
fn lives_total(lives: &[EpisodeResult]) -> EpisodeResult {
    let mut t = EpisodeResult::default();
    let mut fitness = 0.0f64;
    for r in lives {
        t.actions += r.actions;
        t.grips += r.grips;
        t.releases_outside += r.releases_outside;
        t.recharges += r.recharges;
        t.collisions += r.collisions;
        t.placement_failures = t.placement_failures.saturating_add(r.placement_failures);
        fitness += f64::from(r.fitness);
    }
    t.fitness = (fitness / lives.len().max(1) as f64) as f32;
    t
}

/// A test stage to run: the program, the stage, the run seed, the final
/// checkpoint of the evolved stage it tests, and its lives.
struct TestRun<'a> {
    program: &'a Program,
    index: usize,
    seed: u64,
    parent: &'a Checkpoint,
    lives: Lives,
}

/// A test stage's lives: how many in each world, their most actions, and
/// whether the modules learn during them.
#[derive(Clone, Copy, Debug)]
pub struct Lives {
    pub actions: u32,
    pub count: u32,
    pub learning: bool,
}

impl Engine<'_> {
    /// Runs test stage `t` and writes its files into `dir` (all of them or,
    /// when stopped or failing on the way, none); returns its summary.
    fn test_stage(&self, t: &TestRun<'_>, dir: &Path) -> Result<TestSummary> {
        let stage = &t.program.stages[t.index];
        let stop = self.interrupt;
        // Checks that the parent fits and picks its best individual and the episode seed.
        let outcome = evolve::test_subject(t.program, t.index, t.seed, t.parent)
            .map_err(|e| Error::new(ErrorKind::Stale, format!("error: {e}")))?;
        let parent_stage = &t.program.stages[stage.parent.unwrap_or(t.parent.stage)];
        let ba = before_after(parent_stage, stage, &outcome.genome, t.lives, outcome.seed, stop)?;
        // Every file is written into `.writing/` first and moved into `dir`
        // once all are: an interruption (or a failure) on the way leaves the
        // files of an earlier run of the stage, if any, as they were.
        let staging = dir.join(".writing");
        let _ = std::fs::remove_dir_all(&staging);
        create_dir(&staging)?;
        let written = test_files(&staging, stage, parent_stage, &outcome, &ba, t.lives, stop);
        let summary = match written {
            Ok(summary) => summary,
            Err(e) => {
                let _ = std::fs::remove_dir_all(&staging);
                if self.stopped() {
                    return Err(interrupted(format!(
                        "interrupted: test stage `{}` stopped while its files were written; nothing of it was written \
                         (the stages before it are saved), and the same command runs it again",
                        stage.name
                    )));
                }
                return Err(e);
            }
        };
        crate::files::move_sealed(&staging, dir)?;
        let (b, a) = (lives_total(&ba.before), lives_total(&ba.after));
        if let Some(w) = lives_crowding(&ba).warning(&stage.name, dir, ("life", "lives")) {
            self.observer.event(Event::Warning(w));
        }
        self.observer.event(Event::Tested {
            stage: &stage.name,
            summary: &summary,
            lives: t.lives.count,
            before: &b,
            after: &a,
            dir,
        });
        Ok(summary)
    }
}

/// Writes a test stage's files into `dir` (`trace.csv`, the pictures,
/// `episode.json`, `best.genome`, then `summary.json`), stopping between
/// them once `stop` is set; returns the summary.
fn test_files(
    dir: &Path,
    stage: &Stage,
    parent_stage: &Stage,
    outcome: &evolve::TestSubject,
    ba: &BeforeAfter,
    lives: Lives,
    stop: Option<&AtomicBool>,
) -> Result<TestSummary, Error> {
    let Lives { count: lives, learning, .. } = lives;
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let check = || if stopped() { Err(interrupted(report::STOPPED.into())) } else { Ok(()) };
    // The change, and the other lives' starts lightly (unlabelled marks).
    let mut marks: Vec<(u32, String)> =
        ba.life_starts().into_iter().filter(|&a| a != ba.switch).map(|a| (a, String::new())).collect();
    marks.push((ba.switch, format!("world of `{}`", stage.name)));
    // The trajectory: the first life in the changed world, over its scene
    // (the lives before it ran in other worlds).
    let first = ba.switch as usize..(ba.switch + ba.after[0].actions) as usize;
    let what = if lives == 1 {
        "the life after the change".to_string()
    } else {
        format!("the first of the {lives} lives after the change")
    };
    let lived = report::Lived { trace: &ba.trace, others: &ba.others, scene: &ba.scene };
    let drawing = report::Drawing { title: &stage.name, marks: &marks, path: Some((first, &what)) };
    report::episode_files_until(dir, stage, lived, &ba.episode, &drawing, &stopped)?;
    check()?;
    rundir::write_episode(dir, &ba.episode)?;
    check()?;
    rundir::write_best_genome(dir, &outcome.genome)?;
    let perf = |r: &EpisodeResult| rundir::WorldTotals {
        actions: r.actions,
        fitness: f64::from(r.fitness),
        grips: r.grips,
        releases_outside: r.releases_outside,
        recharges: r.recharges,
        collisions: r.collisions,
    };
    let (b, a) = (lives_total(&ba.before), lives_total(&ba.after));
    let counts = |v: &[EpisodeResult]| v.iter().map(|r| r.actions).collect::<Vec<u32>>();
    // Per variant: its lives (k mod the number of variants) and their mean fitness.
    let variants = |st: &Stage, v: &[EpisodeResult]| -> Option<Vec<rundir::VariantLives>> {
        let vars = st.variants.as_ref()?;
        let n = vars.list.len().max(1);
        let rows = vars
            .list
            .iter()
            .enumerate()
            .map(|(i, x)| {
                let mine: Vec<EpisodeResult> = v.iter().skip(i).step_by(n).cloned().collect();
                let fitness = f64::from(lives_total(&mine).fitness);
                rundir::VariantLives { variant: x.name.clone(), lives: mine.len(), fitness }
            })
            .collect();
        Some(rows)
    };
    // Only when a world was too crowded to place apart: the lives that
    // overlap and their overlapping placements (absent: none).
    let crowding = lives_crowding(ba);
    let crowded = crowding.crowded > 0;
    let summary = TestSummary {
        stage: stage.name.clone(),
        learning,
        seed: outcome.seed,
        parent: parent_stage.name.clone(),
        parent_fitness: f64::from(outcome.parent_fitness),
        fitness: f64::from(a.fitness),
        grips: a.grips,
        releases_outside: a.releases_outside,
        before: perf(&b),
        after: perf(&a),
        lives,
        before_lives: counts(&ba.before),
        after_lives: counts(&ba.after),
        reinforcement_mean: reinforcement_means(stage, &ba.trace, ba.switch),
        reinforcement_counts: reinforcement_counts(stage, ba),
        before_variants: variants(parent_stage, &ba.before),
        after_variants: variants(stage, &ba.after),
        crowded_lives: crowded.then_some(crowding.crowded),
        placement_failures: crowded.then_some(crowding.placements),
    };
    check()?;
    rundir::write_test_summary(dir, &summary)?;
    Ok(summary)
}

/// Mean reinforcement of each learning module over the lives before the
/// world changed, the first 100 actions after it, and the rest after it.
fn reinforcement_means(
    stage: &Stage,
    trace: &Trace,
    switch: u32,
) -> BTreeMap<String, rundir::ReinforcementMeans> {
    // A mean that is not a number is written `null`, as none is.
    let mean = |v: &[f32]| {
        let xs: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
        let m = xs.iter().sum::<f32>() / xs.len() as f32;
        (!xs.is_empty() && m.is_finite()).then_some(f64::from(m))
    };
    let mut out = BTreeMap::new();
    for (i, name) in report::learning_modules(stage) {
        let sig = report::reinforcement_signals(trace, i);
        let s = (switch as usize).min(sig.len());
        let early = (s + 100).min(sig.len());
        let means = rundir::ReinforcementMeans {
            before: mean(&sig[..s]),
            after_first_100: mean(&sig[s..early]),
            after_rest: mean(&sig[early..]),
        };
        out.insert(name, means);
    }
    out
}

/// Each learning module's reinforcement signals counted life by life:
/// `{module: {before: {rewards: [..], punishments: [..]}, after: {..}}}`,
/// one number per life of each world (rewards are positive signals,
/// punishments negative ones), so that a module's mean signal over any
/// lives can be computed from `summary.json` alone.
fn reinforcement_counts(stage: &Stage, ba: &BeforeAfter) -> BTreeMap<String, rundir::ReinforcementCounts> {
    let mut out = BTreeMap::new();
    for (i, name) in report::learning_modules(stage) {
        let sig = report::reinforcement_signals(&ba.trace, i);
        let mut at = 0usize;
        let mut world = |lives: &[EpisodeResult]| {
            let (mut rewards, mut punishments) = (Vec::new(), Vec::new());
            for r in lives {
                let end = (at + r.actions as usize).min(sig.len());
                let life = &sig[at.min(end)..end];
                rewards.push(life.iter().filter(|&&x| x > 0.0).count());
                punishments.push(life.iter().filter(|&&x| x < 0.0).count());
                at = end;
            }
            rundir::Signals { rewards, punishments }
        };
        let before = world(&ba.before);
        let after = world(&ba.after);
        out.insert(name, rundir::ReinforcementCounts { before, after });
    }
    out
}

impl Engine<'_> {
    /// Runs training stage `index` (or reuses the `trained.json` a previous
    /// run of the same stage and seed left in `dir`) and writes its files:
    /// the learned weights, the trace of the training life (its first
    /// [`RECORDED_TRAINING_ACTIONS`] actions) and its pictures.
    fn train_step(
        &self,
        program: &Program,
        index: usize,
        seed: u64,
        dir: &Path,
        saved: Option<Trained>,
    ) -> Result<Trained> {
        let stage = &program.stages[index];
        let StageRun::Train { actions } = stage.run else { unreachable!("train_step runs training stages") };
        let recorded = actions.min(RECORDED_TRAINING_ACTIONS);
        if let Some(t) = saved {
            let path = rundir::trained_path(dir);
            if t.run_seed != seed {
                return Err(other_seed(&path, t.run_seed, seed));
            }
            evolve::train::check(program, index, &t).map_err(|e| stale(&path, &e))?;
            self.warn_training(stage, &t, dir);
            self.observer.event(Event::Trained { stage, trained: &t, recorded, reused: true, dir });
            return Ok(t);
        }
        let trained = evolve::train_stage(program, index, seed, None).map_err(unusable)?;
        self.warn_training(stage, &trained, dir);
        // The same life recorded again (the same episode seed and genome), for
        // `trace.csv`, the pictures and `episode.json`: its first
        // `RECORDED_TRAINING_ACTIONS` actions (`trace.csv` and `episode.json`
        // grow by about 500 bytes per action, and a training life may last
        // millions).
        let episode_seed = evolve::train::training_seed(seed, index);
        let opts = EpisodeOptions { actions: recorded, learning: true, seed: episode_seed };
        let rec =
            episode::record(stage, &Genome::zeros(stage.layout.bits as usize), &opts).map_err(unusable)?;
        let (trace, ep) = (&rec.trace, &rec.episode);
        let lived = report::Lived { trace, others: &rec.others, scene: &rec.scene };
        report::episode_files(dir, stage, lived, ep, &report::Drawing::titled(&stage.name))?;
        rundir::write_trained_episode(dir, ep, &trained)?;
        self.observer.event(Event::Trained { stage, trained: &trained, recorded, reused: false, dir });
        Ok(trained)
    }

    /// Warns when the training life of `stage` had a world too crowded to
    /// place apart (its weights were learned there).
    fn warn_training(&self, stage: &Stage, trained: &Trained, dir: &Path) {
        let mut life = Crowding::default();
        life.add(trained.result.placement_failures);
        if let Some(w) = life.warning(&stage.name, dir, ("training life", "training lives")) {
            self.observer.event(Event::Warning(w));
        }
    }
}

/// Binds the weights of every training stage into `program`: from the
/// `trained.json` files of run directory `run_dir` where they exist and fit
/// (a stale one is said, as a warning, and not used), else by training
/// again from `seed` (training is deterministic by seed). Returns what each
/// training stage learned. Every command that runs a stage of a file binds
/// through here (`run` binds each training stage as it runs it).
pub fn bind_training(
    program: &mut Program,
    run_dir: Option<&Path>,
    seed: u64,
    observer: &dyn Observer,
) -> Result<Vec<(usize, Trained)>> {
    let mut all = Vec::new();
    for i in 0..program.stages.len() {
        if !matches!(program.stages[i].run, StageRun::Train { .. }) {
            continue;
        }
        let saved = match run_dir {
            Some(d) => {
                let dir = rundir::stage_dir(d, &program.stages[i].name);
                match rundir::read_trained_with(&dir, &|path| warn_unsealed(observer, path))? {
                    Some(t) => match evolve::train::check(program, i, &t) {
                        Ok(()) => Some(t),
                        Err(e) => {
                            observer.event(Event::Warning(format!(
                                "note: not using `{}`: {e}; training the stage again",
                                rundir::trained_path(&dir).display()
                            )));
                            None
                        }
                    },
                    None => None,
                }
            }
            None => None,
        };
        let trained = match saved {
            Some(t) => t,
            None => evolve::train_stage(program, i, seed, None).map_err(unusable)?,
        };
        evolve::train::bind(program, i, &trained).map_err(unusable)?;
        all.push((i, trained));
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Running a stage runs its ancestors and the training stages whose
    /// weights it uses, whatever their place in the file.
    #[test]
    fn the_chain_of_a_stage_includes_the_training_stages_it_uses() {
        let src =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/khepera.bat")).unwrap();
        let program = shaping_compiler::compile(&src, "khepera.bat").unwrap();
        let names = |c: Vec<usize>| c.into_iter().map(|i| program.stages[i].name.clone()).collect::<Vec<_>>();
        assert_eq!(names(chain(&program, 1)), ["avoidance", "navigation"]);
        assert_eq!(names(chain(&program, 3)), ["avoidance", "navigation", "collect", "bigger"]);
        assert_eq!(names(chain(&program, 0)), ["avoidance"]);
    }
}
