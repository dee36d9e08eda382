//! `shaping run`: evolves the stages in order, with checkpoints, statistics,
//! a progress bar and pictures.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use shaping_runtime::controller::{
    episode_rngs, run_episode, run_episode_on, Controller, EpisodeOptions, EpisodeResult, Trace,
};
use shaping_runtime::evolve::{self, Checkpoint, Evaluation, GenStats};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Param, Program, Stage, StageRun};
use shaping_runtime::sim::{Scene, Sim};

use crate::cluster::Coordinator;
use crate::episode::{self, Part, Recorder, Stoppable};
use crate::load::{self, create_dir, write_atomic, CliError};
use crate::out::outln;
use crate::{html, report};

pub struct RunArgs {
    pub file: PathBuf,
    pub stage: Option<String>,
    pub seed: Option<u64>,
    pub out: Option<PathBuf>,
    pub jobs: Option<usize>,
    pub quiet: bool,
    pub json: bool,
    pub fresh: bool,
    /// Write no `report.html` at the end.
    pub no_report: bool,
    pub error_format: crate::diag::ErrorFormat,
    /// Evaluate on a robot (`--robot`) instead of the simulator.
    pub robot: Option<crate::robot::RobotRun>,
    /// Settings changed from the command line (`--set`, one value each).
    pub sets: Vec<crate::sweep::Assignment>,
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
    let mut cur = Some(target);
    while let Some(i) = cur {
        need[i] = true;
        for (_, p) in program.stages[i].modules.iter().flat_map(|m| m.network_params()) {
            if let Param::Trained { stage, .. } = *p {
                if let Some(n) = need.get_mut(stage as usize) {
                    *n = true;
                }
            }
        }
        cur = program.stages[i].parent;
    }
    (0..program.stages.len()).filter(|&i| need[i]).collect()
}

/// Evaluation of one genome in an evolved stage: one episode with local learning on.
pub fn evaluator(stage: &Stage, actions: u32) -> impl Fn(&Genome, u64) -> Evaluation + Sync + '_ {
    move |genome: &Genome, seed: u64| {
        Evaluation::of_episode(run_episode(
            stage,
            genome,
            &EpisodeOptions { actions, learning: true, seed },
            None,
        ))
    }
}

/// Episodes whose world could not be placed apart: some placement (an
/// object, the robot's start, a virtual object coming back) ran out of
/// tries and kept an overlapping one, so the episode is not the declared
/// world and its fitness is not that world's. Worlds that can never be
/// placed are refused before a run (`sim::crowded`); one that is only
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
fn stale(path: &Path, e: &evolve::EvolveError) -> CliError {
    let hint = match e {
        evolve::EvolveError::TooManyGenerations { done, .. } => {
            format!("declare at least {done} generations, pass `--fresh` to start again, or choose another `--out`")
        }
        _ => "pass `--fresh` to start again, or choose another `--out`".to_string(),
    };
    CliError::io(format!("error: cannot resume from `{}`: {e}; {hint}", path.display()))
}

/// Ctrl-C (or SIGTERM) during a run in one process: the generation under
/// way finishes and is saved, then the run stops saying where; a second
/// Ctrl-C ends it at once. (On a robot the robot's own handler stops the
/// motors first, so there the second one does not end the process.)
fn interrupt_flag(exit_on_second: bool) -> Option<Arc<AtomicBool>> {
    static FLAG: OnceLock<Option<Arc<AtomicBool>>> = OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            if exit_on_second {
                signal_hook::flag::register_conditional_shutdown(sig, 2, Arc::clone(&flag)).ok()?;
            }
            signal_hook::flag::register(sig, Arc::clone(&flag)).ok()?;
        }
        Some(flag)
    })
    .clone()
}

/// The saved stages a run would resume (`stages` in `out`: checkpoints and
/// trained weights) belong to one seed. Stages of two seeds (one of them
/// started again with `--fresh --stage S --seed N`) cannot be resumed by one
/// run with either seed: say which stage has which, and what to do.
fn one_seed(program: &Program, stages: &[usize], out: &Path, seed: u64) -> Result<(), CliError> {
    let mut saved: Vec<(&str, u64)> = Vec::new();
    for &i in stages {
        let st = &program.stages[i];
        let dir = out.join(&st.name);
        let found = match st.run {
            StageRun::Evolve(_) => read_checkpoint(&ckpt_path(&dir))?.map(|cp| cp.seed),
            StageRun::Train { .. } => read_trained(&dir.join("trained.json"))?.map(|t| t.run_seed),
            StageRun::Test { .. } => None,
        };
        if let Some(s) = found {
            saved.push((&st.name, s));
        }
    }
    let mut seeds: Vec<u64> = saved.iter().map(|&(_, s)| s).collect();
    seeds.sort_unstable();
    seeds.dedup();
    if seeds.len() < 2 {
        return Ok(());
    }
    let which: Vec<String> = saved.iter().map(|(name, s)| format!("`{name}` seed {s}")).collect();
    Err(CliError::io(format!(
        "error: `{}` holds stages of different seeds ({}); one run resumes stages of one seed: \
         pass `--fresh` to run every stage again with seed {seed}, or choose another `--out`",
        out.display(),
        which.join(", ")
    )))
}

fn ckpt_path(dir: &Path) -> PathBuf {
    dir.join("checkpoint.json")
}

fn read_checkpoint(path: &Path) -> Result<Option<Checkpoint>, CliError> {
    if !path.exists() {
        return Ok(None);
    }
    let bytes = load::read_bytes(path)?;
    serde_json::from_slice(&bytes).map(Some).map_err(|e| {
        CliError::io(format!(
            "error: the checkpoint `{}` is corrupt ({e}); move it away or pass `--fresh` to start the stage again",
            path.display()
        ))
    })
}

fn to_json<T: serde::Serialize>(value: &T) -> Result<String, CliError> {
    serde_json::to_string_pretty(value).map_err(|e| CliError::io(format!("error: cannot serialise: {e}")))
}

/// Runs the stages; with `cluster` (rank 0 of an MPI run) the episodes of
/// each generation are spread over the ranks.
pub fn run(args: RunArgs, cluster: Option<&Coordinator>) -> Result<(), CliError> {
    let mut program = load::load_program(&args.file, args.error_format)?;
    crate::sweep::apply(&mut program, &args.sets)?;
    let target = match args.stage.as_deref() {
        Some(_) => load::stage_index(&program, args.stage.as_deref())?,
        None => program.stages.len().saturating_sub(1),
    };
    if program.stages.is_empty() {
        return Err(CliError::io("error: the program has no stages"));
    }
    let stages =
        if args.stage.is_some() { chain(&program, target) } else { (0..program.stages.len()).collect() };
    load::check_memory(&program, &stages, 1)?;
    let out = args.out.clone().unwrap_or_else(|| default_out(&args.file));
    let seed = run_seed(&program, args.seed);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()
        .map_err(|e| CliError::io(format!("error: cannot start worker threads: {e}")))?;
    if !args.fresh {
        one_seed(&program, &stages, &out, seed)?;
    }
    create_dir(&out)?;
    let interrupted = if cluster.is_none() { interrupt_flag(args.robot.is_none()) } else { None };
    // The compiled program, for `shaping report` (and `shaping run program.json`).
    write_atomic(&out.join("program.json"), compact_json(&program)?.as_bytes())?;
    let started = Instant::now();
    let mut finals: Vec<Option<Checkpoint>> = vec![None; program.stages.len()];
    // What each stage ended with, for the last line of `--json`.
    let mut results = Vec::new();
    for &index in &stages {
        // Ctrl-C during a training life, a test or the choice of a best: the
        // step under way finished and is saved; stop before the next.
        if interrupted.as_ref().is_some_and(|f| f.load(Ordering::Relaxed)) {
            return Err(CliError::io(format!(
                "interrupted: stopped before stage `{}`; what ran is saved in `{}`, and the same command resumes",
                program.stages[index].name,
                out.display()
            )));
        }
        if let StageRun::Train { .. } = program.stages[index].run {
            let dir = out.join(&program.stages[index].name);
            create_dir(&dir)?;
            let trained = train_step(&program, index, seed, &dir, &args)?;
            evolve::train::bind(&mut program, index, &trained)
                .map_err(|e| CliError::io(format!("error: {e}")))?;
            results.push(serde_json::json!({
                "stage": program.stages[index].name, "kind": "train",
                "actions": trained.result.actions, "performance": trained.performance,
            }));
            continue;
        }
        let stage = &program.stages[index];
        let dir = out.join(&stage.name);
        create_dir(&dir)?;
        match &stage.run {
            StageRun::Evolve(_) => {
                let parent = evolved_parent(&program, index, &finals)?;
                let cp = match cluster {
                    None => pool.install(|| {
                        evolve_stage(&program, index, seed, parent, &dir, &args, None, interrupted.as_deref())
                    })?,
                    // The coordinator's loop calls MPI, so it stays on this thread.
                    Some(c) => evolve_stage(&program, index, seed, parent, &dir, &args, Some(c), None)?,
                };
                best_episode(stage, &cp, seed, &dir)?;
                if let Some((genome, fitness)) = evolve::best_of(&cp) {
                    results.push(serde_json::json!({
                        "stage": stage.name, "kind": "evolve", "generations": cp.generation,
                        "best": fitness, "genome": genome.to_bitstring(),
                    }));
                }
                finals[index] = Some(cp);
            }
            StageRun::Test { actions, lives, learning } => {
                let parent = evolved_parent(&program, index, &finals)?.ok_or_else(|| {
                    CliError::io(format!("error: test stage `{}` extends no evolved stage", stage.name))
                })?;
                let summary = test_stage(
                    &program,
                    index,
                    seed,
                    parent,
                    *actions,
                    *lives,
                    *learning,
                    &dir,
                    &args,
                    interrupted.as_deref(),
                )?;
                results.push(serde_json::json!({"kind": "test", "summary": summary, "stage": stage.name}));
            }
            StageRun::Train { .. } => unreachable!("training stages run above"),
        }
    }
    if interrupted.as_ref().is_some_and(|f| f.load(Ordering::Relaxed)) {
        return Err(CliError::io(format!(
            "interrupted: every stage is done and saved in `{0}`, but not `report.html` (`shaping report {0}` writes it)",
            out.display()
        )));
    }
    let report = if args.no_report { None } else { Some(html::write(&out, None)?) };
    if args.json {
        let line = serde_json::json!({
            "done": true, "out": out.display().to_string(), "seed": seed,
            "seconds": started.elapsed().as_secs_f64(), "stages": results,
            "report": report.as_ref().map(|p| p.display().to_string()),
        });
        outln!("{line}")?;
    }
    if !args.quiet && !args.json {
        eprintln!("done in {:.2} s; results in {}", started.elapsed().as_secs_f64(), out.display());
        if let Some(path) = report {
            eprintln!("report: {}", path.display());
        }
    }
    Ok(())
}

fn compact_json<T: serde::Serialize>(value: &T) -> Result<String, CliError> {
    serde_json::to_string(value).map_err(|e| CliError::io(format!("error: cannot serialise: {e}")))
}

/// `episode.json` of an evolved stage: one recorded episode of its best
/// individual, the one `shaping replay FILE --stage S` shows by default
/// (the run seed, the stage's life, learning on).
fn best_episode(stage: &Stage, cp: &Checkpoint, seed: u64, dir: &Path) -> Result<(), CliError> {
    let StageRun::Evolve(evo) = &stage.run else { return Ok(()) };
    let Some((genome, _)) = evolve::best_of(cp) else { return Ok(()) };
    let opts = EpisodeOptions { actions: evo.actions, learning: true, seed };
    let (_, _, ep) =
        episode::run_recorded(stage, &genome, &opts).map_err(|e| CliError::io(format!("error: {e}")))?;
    write_atomic(&dir.join("episode.json"), compact_json(&ep)?.as_bytes())
}

/// The final checkpoint of the nearest evolved ancestor of `index`.
fn evolved_parent<'a>(
    program: &Program,
    index: usize,
    finals: &'a [Option<Checkpoint>],
) -> Result<Option<&'a Checkpoint>, CliError> {
    let mut cur = program.stages[index].parent;
    while let Some(p) = cur {
        if let StageRun::Evolve(_) = program.stages[p].run {
            return finals[p].as_ref().map(Some).ok_or_else(|| {
                CliError::io(format!("error: stage `{}` has not been run", program.stages[p].name))
            });
        }
        cur = program.stages[p].parent;
    }
    Ok(None)
}

#[allow(clippy::too_many_arguments)]
fn evolve_stage(
    program: &Program,
    index: usize,
    seed: u64,
    parent: Option<&Checkpoint>,
    dir: &Path,
    args: &RunArgs,
    cluster: Option<&Coordinator>,
    interrupted: Option<&AtomicBool>,
) -> Result<Checkpoint, CliError> {
    let stage = &program.stages[index];
    let StageRun::Evolve(evo) = &stage.run else { unreachable!("evolve_stage is called for evolved stages") };
    let path = ckpt_path(dir);
    let existing = if args.fresh { None } else { read_checkpoint(&path)? };
    let mut cp = match existing {
        Some(mut cp) => {
            if cp.seed != seed {
                return Err(CliError::io(format!(
                    "error: `{}` belongs to a run with seed {} (this run has seed {seed}); pass `--seed {}` to resume it, `--fresh` to start again, or another `--out`",
                    path.display(),
                    cp.seed,
                    cp.seed
                )));
            }
            evolve::resume(program, index, &mut cp).map_err(|e| stale(&path, &e))?;
            if !args.quiet && !args.json {
                if evolve::is_finished(program, &cp) && cp.validated {
                    eprintln!(
                        "stage {:<12} all {} generations done before, from {}",
                        stage.name,
                        cp.generation,
                        path.display()
                    );
                } else {
                    eprintln!(
                        "resuming `{}` at generation {} of {}",
                        stage.name, cp.generation, evo.generations
                    );
                }
            }
            cp
        }
        None => evolve::start_stage(program, index, seed, parent)
            .map_err(|e| CliError::io(format!("error: {e}")))?,
    };
    // Every individual would silently score 0 on a stage the controller
    // cannot run (e.g. weights of a training stage that was not bound).
    let probe = Genome::zeros(stage.layout.bits as usize);
    shaping_runtime::controller::validate(stage, &probe)
        .map_err(|e| CliError::io(format!("error: stage `{}` cannot run: {e}", stage.name)))?;
    let bar = progress_bar(args, stage, evo.generations, cp.generation);
    let sim_eval = evaluator(stage, evo.actions);
    // The robot's episode log is tied to the stage as the checkpoint is.
    let digest = evolve::fingerprint::digest(&cp.fingerprint);
    let robot_eval =
        args.robot.as_ref().map(|r| r.evaluator(stage, evo.actions, dir, digest, args.fresh)).transpose()?;
    let eval: &(dyn Fn(&Genome, u64) -> Evaluation + Sync) = match &robot_eval {
        Some(e) => e,
        None => &sim_eval,
    };
    let fail = |e| {
        args.robot.as_ref().and_then(|r| r.failure()).unwrap_or_else(|| CliError::io(format!("error: {e}")))
    };
    // The episodes this process runs for the stage, for the warning about
    // a crowded world (the generations' are in their statistics too).
    let run_now = std::cell::Cell::new(Crowding::default());
    let many = |jobs: &[(&Genome, u64)]| {
        let evaluations = match cluster {
            Some(c) => c.evaluate(program, index, evo.actions, jobs),
            None => evolve::evaluate_many(eval, jobs),
        };
        let mut tally = run_now.get();
        for ev in &evaluations {
            tally.add(ev.placement_failures);
        }
        run_now.set(tally);
        evaluations
    };
    let mut warned = false;
    let context = |what: String| {
        if let Some(c) = cluster {
            c.set_context(what, &path);
        }
    };
    while !evolve::is_finished(program, &cp) {
        context(format!("generation {} of stage `{}`", cp.generation, stage.name));
        let stats = evolve::step_generation_with(program, &mut cp, &many).map_err(fail)?;
        write_atomic(&path, to_json(&cp)?.as_bytes())?;
        write_atomic(&dir.join("generations.csv"), report::generations_csv(&cp.history).as_bytes())?;
        report_generation(args, &bar, &stats)?;
        if stats.crowded_episodes > 0 && !warned {
            // Said at once (a long run may be stopped), and again with the
            // totals at the end of the stage.
            warned = true;
            bar.suspend(|| {
                eprintln!(
                    "warning: the world of stage `{}` is too crowded: in generation {}, {} of {} episodes placed \
                     objects (or the robot) overlapping; the run goes on, and the end of the stage gives the count",
                    stage.name,
                    stats.stage_generation,
                    stats.crowded_episodes,
                    u64::from(evo.population) * u64::from(evo.evaluations.max(1))
                )
            });
        }
        if interrupted.is_some_and(|f| f.load(Ordering::Relaxed)) && !evolve::is_finished(program, &cp) {
            bar.abandon();
            return Err(CliError::io(format!(
                "interrupted: stage `{}` stopped after generation {} of {}, saved in `{}`; the same command resumes it",
                stage.name,
                cp.generation,
                evo.generations,
                path.display()
            )));
        }
    }
    bar.finish_and_clear();
    let generations_now = run_now.get();
    if !cp.validated {
        // Pick the stage's best by its mean over fresh episodes, not by its
        // luckiest single evaluation.
        context(format!("the choice of the best of stage `{}`", stage.name));
        evolve::validate_best_with(
            program,
            &mut cp,
            &many,
            evolve::VALIDATE_CANDIDATES,
            evolve::VALIDATE_EPISODES,
        )
        .map_err(fail)?;
        write_atomic(&path, to_json(&cp)?.as_bytes())?;
    }
    let now = run_now.get();
    let choice = Crowding {
        episodes: now.episodes - generations_now.episodes,
        crowded: now.crowded - generations_now.crowded,
        placements: now.placements - generations_now.placements,
    };
    if let Some(w) =
        stage_crowding(&cp, &stage.name, evo, choice).warning(&stage.name, dir, ("episode", "episodes"))
    {
        eprintln!("{w}");
    }
    let (genome, fitness) = evolve::best_of(&cp)
        .ok_or_else(|| CliError::io(format!("error: stage `{}` evaluated no individual", stage.name)))?;
    write_atomic(&dir.join("best.genome"), format!("{}\n", genome.to_bitstring()).as_bytes())?;
    write_atomic(&dir.join("generations.csv"), report::generations_csv(&cp.history).as_bytes())?;
    report::fitness_plot(dir, &format!("{}: fitness per generation", stage.name), &cp.history)?;
    if !args.quiet && !args.json {
        let last = cp.history.last();
        eprintln!(
            "stage {:<12} {} generations  last best {:.3}  mean {:.3}  chosen best {:.3} (mean of {} fresh episodes)  -> {}",
            stage.name,
            cp.generation,
            last.map_or(0.0, |h| h.best),
            last.map_or(0.0, |h| h.mean),
            fitness,
            evolve::VALIDATE_EPISODES,
            dir.display()
        );
    }
    Ok(cp)
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
/// is empty.
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

#[allow(clippy::too_many_arguments)]
pub fn before_after(
    parent: &Stage,
    stage: &Stage,
    genome: &Genome,
    actions: u32,
    lives: u32,
    learning: bool,
    seed: u64,
    stop: Option<&AtomicBool>,
) -> Result<BeforeAfter, CliError> {
    if lives == 0 {
        return Err(CliError::io(format!("error: test stage `{}` has no life to run", stage.name)));
    }
    let (_, rng) = episode_rngs(seed);
    let mut ctl = Controller::new(stage, genome, rng)
        .map_err(|e| CliError::io(format!("error: stage `{}`: {e}", stage.name)))?;
    let opts = EpisodeOptions { actions, learning, seed };
    let mut trace = Trace::default();
    let mut life = Trace::default();
    let mut parts = Vec::new();
    let mut results = [Vec::new(), Vec::new()];
    for (half, world) in [parent, stage].into_iter().enumerate() {
        for k in 0..lives {
            let sim = Sim::new(&world.world, evolve::seed::test_life_seed(seed, half == 1, k));
            let scene = sim.scene();
            let mut robot = Stoppable::new(sim, stop);
            let mut rec = Recorder::new(&mut robot);
            results[half].push(ctl.run(&mut rec, &opts, Some(&mut life)));
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                // The life was cut short: nothing of this test is a result.
                return Err(interrupted_test(stage, half == 1, k, lives));
            }
            let frames = rec.frames;
            let from = trace.rows.len() as u32;
            trace.modules.clone_from(&life.modules);
            trace.rows.extend(life.rows.drain(..).map(|mut r| {
                r.action += from;
                r
            }));
            parts.push(Part { stage: &world.name, scene, frames });
        }
    }
    let switch = results[0].iter().map(|r| r.actions).sum();
    let scene = parts[lives as usize].scene.clone();
    let episode = episode::episode(stage, seed, learning, &trace, &parts);
    let [before, after] = results;
    Ok(BeforeAfter { trace, switch, before, after, scene, episode })
}

/// Ctrl-C during a test stage: the life under way stopped at its next
/// action, and nothing of the test is written (its files, if any, are
/// those of an earlier run).
fn interrupted_test(stage: &Stage, after: bool, life: u32, lives: u32) -> CliError {
    let world = if after { "its own world" } else { "the world before the change" };
    CliError::io(format!(
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

#[allow(clippy::too_many_arguments)]
fn test_stage(
    program: &Program,
    index: usize,
    seed: u64,
    parent: &Checkpoint,
    actions: u32,
    lives: u32,
    learning: bool,
    dir: &Path,
    args: &RunArgs,
    stop: Option<&AtomicBool>,
) -> Result<serde_json::Value, CliError> {
    let stage = &program.stages[index];
    // Stopping at the next action on Ctrl-C.
    let eval = |genome: &Genome, episode: u64| {
        let opts = EpisodeOptions { actions, learning, seed: episode };
        Evaluation::of_episode(run_episode_on(stage, genome, &opts, None, |sim| Stoppable::new(sim, stop)))
    };
    // Checks that the parent fits and picks its best individual and the episode seed.
    let outcome = evolve::test_best(program, index, seed, parent, &eval)
        .map_err(|e| CliError::io(format!("error: {e}")))?;
    if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
        return Err(interrupted_test(stage, false, 0, lives));
    }
    let parent_stage = &program.stages[stage.parent.unwrap_or(parent.stage)];
    let ba =
        before_after(parent_stage, stage, &outcome.genome, actions, lives, learning, outcome.seed, stop)?;
    // Every file is written into `.writing/` first and moved into `dir`
    // once all are: Ctrl-C (or a failure) on the way leaves the files of an
    // earlier run of the stage, if any, as they were.
    let staging = dir.join(".writing");
    let _ = std::fs::remove_dir_all(&staging);
    create_dir(&staging)?;
    let written = test_files(&staging, stage, parent_stage, &outcome, &ba, lives, learning, stop);
    let summary = match written {
        Ok(summary) => summary,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&staging);
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Err(CliError::io(format!(
                    "interrupted: test stage `{}` stopped while its files were written; nothing of it was written \
                     (the stages before it are saved), and the same command runs it again",
                    stage.name
                )));
            }
            return Err(e);
        }
    };
    let moved = std::fs::read_dir(&staging).and_then(|entries| {
        for entry in entries {
            let entry = entry?;
            std::fs::rename(entry.path(), dir.join(entry.file_name()))?;
        }
        std::fs::remove_dir(&staging)
    });
    moved.map_err(|e| {
        CliError::io(format!(
            "error: cannot move the files of `{}` into `{}`: {e}",
            staging.display(),
            dir.display()
        ))
    })?;
    let (b, a) = (lives_total(&ba.before), lives_total(&ba.after));
    if let Some(w) = lives_crowding(&ba).warning(&stage.name, dir, ("life", "lives")) {
        eprintln!("{w}");
    }
    if args.json {
        outln!("{summary}")?;
    } else if !args.quiet {
        let how = if lives == 1 {
            String::new()
        } else {
            format!(" in {lives} lives each (fitness: mean per life)")
        };
        eprintln!(
            "stage {:<12} test of the best, {} actions before and {} after the change{how}: fitness {:.3} -> {:.3}, grips {} -> {}  -> {}",
            stage.name,
            b.actions,
            a.actions,
            b.fitness,
            a.fitness,
            b.grips,
            a.grips,
            dir.display()
        );
    }
    Ok(summary)
}

/// Writes a test stage's files into `dir` (`trace.csv`, the pictures,
/// `episode.json`, `best.genome`, then `summary.json`), stopping between
/// them once `stop` is set; returns the summary.
#[allow(clippy::too_many_arguments)]
fn test_files(
    dir: &Path,
    stage: &Stage,
    parent_stage: &Stage,
    outcome: &evolve::TestOutcome,
    ba: &BeforeAfter,
    lives: u32,
    learning: bool,
    stop: Option<&AtomicBool>,
) -> Result<serde_json::Value, CliError> {
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let check = || if stopped() { Err(CliError::io(report::STOPPED)) } else { Ok(()) };
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
    report::episode_files_until(
        dir,
        &stage.name,
        stage,
        &ba.trace,
        &ba.episode,
        &ba.scene,
        &marks,
        Some((first, &what)),
        &stopped,
    )?;
    check()?;
    write_atomic(&dir.join("episode.json"), compact_json(&ba.episode)?.as_bytes())?;
    check()?;
    write_atomic(&dir.join("best.genome"), format!("{}\n", outcome.genome.to_bitstring()).as_bytes())?;
    let perf = |r: &EpisodeResult| {
        serde_json::json!({
            "actions": r.actions, "fitness": r.fitness, "grips": r.grips,
            "releases_outside": r.releases_outside, "recharges": r.recharges, "collisions": r.collisions,
        })
    };
    let (b, a) = (lives_total(&ba.before), lives_total(&ba.after));
    let counts = |v: &[EpisodeResult]| v.iter().map(|r| r.actions).collect::<Vec<u32>>();
    let mut summary = serde_json::json!({
        "stage": stage.name, "learning": learning, "seed": outcome.seed,
        "parent": parent_stage.name, "parent_fitness": outcome.parent_fitness,
        "fitness": a.fitness, "grips": a.grips, "releases_outside": a.releases_outside,
        "before": perf(&b), "after": perf(&a),
        "lives": lives, "before_lives": counts(&ba.before), "after_lives": counts(&ba.after),
        "reinforcement_mean": reinforcement_means(stage, &ba.trace, ba.switch),
    });
    // Only when a world was too crowded to place apart: the lives that
    // overlap and their overlapping placements (absent: none).
    let crowding = lives_crowding(ba);
    if crowding.crowded > 0 {
        summary["crowded_lives"] = serde_json::json!(crowding.crowded);
        summary["placement_failures"] = serde_json::json!(crowding.placements);
    }
    check()?;
    write_atomic(&dir.join("summary.json"), to_json(&summary)?.as_bytes())?;
    Ok(summary)
}

/// Mean reinforcement of each learning module over the lives before the
/// world changed, the first 100 actions after it, and the rest after it.
fn reinforcement_means(stage: &Stage, trace: &Trace, switch: u32) -> serde_json::Value {
    let mean = |v: &[f32]| {
        let xs: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
        if xs.is_empty() {
            serde_json::Value::Null
        } else {
            serde_json::json!(xs.iter().sum::<f32>() / xs.len() as f32)
        }
    };
    let mut out = serde_json::Map::new();
    for (i, name) in report::learning_modules(stage) {
        let sig = report::reinforcement_signals(trace, i);
        let s = (switch as usize).min(sig.len());
        let early = (s + 100).min(sig.len());
        out.insert(
            name,
            serde_json::json!({
                "before": mean(&sig[..s]), "after_first_100": mean(&sig[s..early]), "after_rest": mean(&sig[early..]),
            }),
        );
    }
    serde_json::Value::Object(out)
}

fn progress_bar(args: &RunArgs, stage: &Stage, generations: u32, done: u32) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(
        Some(generations as u64),
        if args.quiet || args.json { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() },
    );
    let style = ProgressStyle::with_template(
        "{prefix:>12} [{bar:30}] gen {pos:>3}/{len}  {msg}  {elapsed_precise} eta {eta}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_prefix(stage.name.clone());
    bar.set_position(done as u64);
    bar
}

fn report_generation(args: &RunArgs, bar: &ProgressBar, stats: &GenStats) -> Result<(), CliError> {
    bar.set_message(format!("best {:.3} mean {:.3}", stats.best, stats.mean));
    bar.inc(1);
    if args.json {
        outln!("{}", compact_json(stats)?)?;
    }
    Ok(())
}

/// The longest part of a training life that `run` records (from its start)
/// for `trace.csv`, `episode.json` and the pictures.
pub const RECORDED_TRAINING_ACTIONS: u32 = 20_000;

/// Runs training stage `index` (or reuses the `trained.json` a previous run
/// of the same stage and seed left in `dir`) and writes its files: the
/// learned weights, the trace of the training life (its first
/// [`RECORDED_TRAINING_ACTIONS`] actions) and its pictures.
fn train_step(
    program: &Program,
    index: usize,
    seed: u64,
    dir: &Path,
    args: &RunArgs,
) -> Result<evolve::Trained, CliError> {
    let stage = &program.stages[index];
    let path = dir.join("trained.json");
    if !args.fresh {
        if let Some(t) = read_trained(&path)? {
            if t.run_seed != seed {
                return Err(CliError::io(format!(
                    "error: `{}` belongs to a run with seed {} (this run has seed {seed}); pass `--seed {}` to resume it, `--fresh` to start again, or another `--out`",
                    path.display(),
                    t.run_seed,
                    t.run_seed
                )));
            }
            evolve::train::check(program, index, &t).map_err(|e| stale(&path, &e))?;
            if !args.quiet && !args.json {
                eprintln!("stage {:<12} trained before, reused  -> {}", stage.name, dir.display());
            }
            warn_training(stage, &t, dir);
            return Ok(t);
        }
    }
    let trained =
        evolve::train_stage(program, index, seed, None).map_err(|e| CliError::io(format!("error: {e}")))?;
    warn_training(stage, &trained, dir);
    // The same life recorded again (the same episode seed and genome), for
    // `trace.csv`, the pictures and `episode.json`: its first
    // `RECORDED_TRAINING_ACTIONS` actions (`trace.csv` and `episode.json` grow by about 500 bytes
    // per action, and a training life may last millions).
    let StageRun::Train { actions } = stage.run else { unreachable!("train_step runs training stages") };
    let episode_seed = evolve::train::training_seed(seed, index);
    let recorded = actions.min(RECORDED_TRAINING_ACTIONS);
    let opts = EpisodeOptions { actions: recorded, learning: true, seed: episode_seed };
    let (_, trace, ep) = episode::run_recorded(stage, &Genome::zeros(stage.layout.bits as usize), &opts)
        .map_err(|e| CliError::io(format!("error: {e}")))?;
    let scene = Sim::new(&stage.world, episode_rngs(episode_seed).0).scene();
    report::episode_files(dir, &stage.name, stage, &trace, &ep, &scene, &[], None)?;
    write_atomic(&dir.join("episode.json"), compact_json(&ep)?.as_bytes())?;
    write_atomic(&path, to_json(&trained)?.as_bytes())?;
    if args.json {
        outln!(
            "{}",
            serde_json::json!({"stage": stage.name, "trained": trained.result.actions, "recorded": recorded, "performance": trained.performance})
        )?;
    } else if !args.quiet {
        let perf: Vec<String> = stage
            .modules
            .iter()
            .zip(&trained.performance)
            .filter(|(m, _)| m.learning.is_some())
            .map(|(m, p)| format!("{} {p:+.2}", m.name))
            .collect();
        let part = if recorded < actions {
            format!(" (trace and pictures: its first {recorded} actions)")
        } else {
            String::new()
        };
        eprintln!(
            "stage {:<12} trained for {} actions, performance {}{part}  -> {}",
            stage.name,
            trained.result.actions,
            perf.join(", "),
            dir.display()
        );
    }
    Ok(trained)
}

/// Warns when the training life of `stage` had a world too crowded to place
/// apart (its weights were learned there).
fn warn_training(stage: &Stage, trained: &evolve::Trained, dir: &Path) {
    let mut life = Crowding::default();
    life.add(trained.result.placement_failures);
    if let Some(w) = life.warning(&stage.name, dir, ("training life", "training lives")) {
        eprintln!("{w}");
    }
}

/// A `trained.json`, if there is one (a corrupt one is an error).
fn read_trained(path: &Path) -> Result<Option<evolve::Trained>, CliError> {
    if !path.exists() {
        return Ok(None);
    }
    let bytes = std::fs::read(path)
        .map_err(|e| CliError::io(format!("error: cannot read `{}`: {e}", path.display())))?;
    serde_json::from_slice(&bytes).map(Some).map_err(|e| {
        CliError::io(format!(
            "error: `{}` is not a trained-weights file ({e}); delete it or pass `--fresh`",
            path.display()
        ))
    })
}

/// Binds the weights of every training stage into `program`: from the
/// `trained.json` files of run directory `run_dir` where they exist and fit
/// (a stale one is said and not used), else by training again from `seed`
/// (training is deterministic by seed). Returns what each training stage
/// learned. Every command that runs a stage of a file binds through here
/// (`run` binds each training stage as it runs it).
pub fn bind_training(
    program: &mut Program,
    run_dir: Option<&Path>,
    seed: u64,
) -> Result<Vec<(usize, evolve::Trained)>, CliError> {
    let mut all = Vec::new();
    for i in 0..program.stages.len() {
        if !matches!(program.stages[i].run, StageRun::Train { .. }) {
            continue;
        }
        let saved = match run_dir {
            Some(d) => {
                let path = d.join(&program.stages[i].name).join("trained.json");
                match read_trained(&path)? {
                    Some(t) => match evolve::train::check(program, i, &t) {
                        Ok(()) => Some(t),
                        Err(e) => {
                            eprintln!("note: not using `{}`: {e}; training the stage again", path.display());
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
            None => evolve::train_stage(program, i, seed, None)
                .map_err(|e| CliError::io(format!("error: {e}")))?,
        };
        evolve::train::bind(program, i, &trained).map_err(|e| CliError::io(format!("error: {e}")))?;
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
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/khepera.bat")).unwrap();
        let program = shaping_compiler::compile(&src, "khepera.bat").unwrap();
        let names = |c: Vec<usize>| c.into_iter().map(|i| program.stages[i].name.clone()).collect::<Vec<_>>();
        assert_eq!(names(chain(&program, 1)), ["avoidance", "navigation"]);
        assert_eq!(names(chain(&program, 3)), ["avoidance", "navigation", "collect", "bigger"]);
        assert_eq!(names(chain(&program, 0)), ["avoidance"]);
    }
}
