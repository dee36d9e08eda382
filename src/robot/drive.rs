//! `shaping drive`: one individual on a robot over its serial port, with the
//! same trace and pictures as `replay`; the trace is written as it goes.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use shaping_runtime::catalog::ActuatorKind;
use shaping_runtime::controller::{episode_rngs, Controller, EpisodeOptions, EpisodeResult, Trace};
use shaping_runtime::evolve::EvalOptions;
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Program, Stage};
use shaping_runtime::robot::{RobotError, SerialRobot};

use super::port::{interrupt_flag, SerialPort};
use crate::load::create_dir;
use crate::out::outln;
use crate::CliError;
use shaping_engine::episode::{self, Frame, Part, Recorder};
use shaping_engine::{replay, report};

use crate::terminal::Terminal;
use shaping_engine::run;

/// The arguments of `shaping drive`.
#[derive(clap::Args)]
pub struct DriveArgs {
    pub file: PathBuf,
    /// Stage to drive (default: the last).
    #[arg(long)]
    pub stage: Option<String>,
    /// The genome: a string of 0 and 1, or a file holding one.
    #[arg(long, conflicts_with = "run")]
    pub genome: Option<String>,
    /// A run directory holding `<stage>/best.genome` (default: `runs/<file stem>`).
    #[arg(long)]
    pub run: Option<PathBuf>,
    /// The robot's serial port (or an emulator's, see `shaping emulate`).
    #[arg(long)]
    pub port: PathBuf,
    #[arg(long, default_value_t = 9600)]
    pub baud: u32,
    /// Actions to run (default: the stage's life length).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(shaping_runtime::limits::MAX_ACTIONS)))]
    pub actions: Option<u32>,
    /// Output directory (default: `<run>/<stage>/drive`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Episode seed: places the virtual objects and the assumed start pose (default: the run seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Action period in ms (default: the world's action length; 0: as fast as the link allows).
    #[arg(long = "period", id = "period", value_name = "PERIOD")]
    pub period_ms: Option<u64>,
    /// Longest wait for an answer of the robot, ms.
    #[arg(long = "timeout", id = "timeout", value_name = "TIMEOUT", default_value_t = 1000)]
    pub timeout_ms: u64,
    /// Switch local learning off.
    #[arg(long)]
    pub no_learning: bool,
    #[arg(long, default_value = "human", value_parser = crate::error_format())]
    pub error_format: crate::diag::ErrorFormat,
}

/// The stage declares an arm or a claw.
pub fn has_gripper(stage: &Stage) -> bool {
    stage.actuators.iter().any(|a| matches!(a.kind, ActuatorKind::Lift | ActuatorKind::Grip))
}

/// A stage a Khepera can run (`robot::unfit_for_robot`).
pub fn check_robot_world(stage: &Stage) -> Result<(), CliError> {
    shaping_runtime::robot::unfit_for_robot(stage)
        .map_or(Ok(()), |m| Err(CliError::new(shaping_engine::ErrorKind::Invalid, format!("error: {m}"))))
}

/// The action period: `--period`, else the world's action length.
pub fn period(stage: &Stage, period_ms: Option<u64>) -> Duration {
    period_ms.map_or_else(
        || Duration::from_secs_f64(f64::from(stage.world.body.action_ms.max(0.0)) / 1000.0),
        Duration::from_millis,
    )
}

/// The message for a robot that failed: what happened, and whether the
/// motors were stopped.
pub fn failure(err: &RobotError, stopped: &Result<(), RobotError>) -> String {
    match stopped {
        Ok(()) => format!("error: {err}; the motors were stopped (speed 0 sent)"),
        Err(e) => {
            format!("error: {err}; stopping the motors failed too ({e}): the robot may still be driving")
        }
    }
}

/// What `drive` runs: the chosen individual of stage `index` of `program`,
/// the directory its files go to, and its episode.
struct Plan {
    program: Program,
    index: usize,
    genome: Genome,
    out: PathBuf,
    episode: EpisodeOptions,
}

/// Chooses what `drive` runs, as `replay` does: the program of the run
/// (with its `--set`), the stage and genome, and the life length, learning
/// and seed the stage declares unless `args` changes them; checks that a
/// Khepera can run the stage and that the output directory may be written.
fn plan(args: &DriveArgs, terminal: &Terminal) -> Result<Plan, CliError> {
    let program = crate::load::load_program(&args.file, args.error_format)?;
    // A run made with `--set`: its own program, as `replay` takes it.
    let run_dir = args.run.clone().unwrap_or_else(|| run::default_out(&args.file));
    let program = replay::with_run_settings(program, &run_dir, &[], terminal);
    let chosen = replay::choose(
        program,
        &args.file,
        args.stage.as_deref(),
        args.genome.as_deref(),
        args.run.as_deref(),
        terminal,
    )?;
    let replay::Chosen { program, index, genome, training_seed } = chosen;
    let stage = &program.stages[index];
    check_robot_world(stage)?;
    let out = args.out.clone().unwrap_or_else(|| shaping_engine::rundir::drive_dir(&run_dir, &stage.name));
    shaping_engine::rundir::check_output_dir(&out, "`drive`", "drive")?;
    // The life length and learning the stage declares, as in `replay`.
    let declared = EvalOptions::of(stage);
    let actions = args.actions.unwrap_or(declared.actions);
    let learning = declared.learning && !args.no_learning;
    let seed = args.seed.unwrap_or_else(|| match training_seed {
        Some(run_seed) => shaping_runtime::evolve::train::training_seed(run_seed, index),
        None => run::run_seed(&program, None),
    });
    Ok(Plan { program, index, genome, out, episode: EpisodeOptions { actions, learning, seed } })
}

/// What happened on the robot.
struct Driven {
    trace: Trace,
    /// What the robot sensed, action by action.
    frames: Vec<Frame>,
    /// The episode's result; none when the robot never answered.
    result: Option<EpisodeResult>,
    /// Whether the motors were stopped at the end.
    stopped: Result<(), RobotError>,
    /// What went wrong with the robot, if anything did.
    error: Option<RobotError>,
    seconds: f64,
    requests: u64,
    bytes: u64,
}

/// Runs `ctl`'s episode on `robot`, writing `trace.csv` into `out` as it
/// goes, and stops the motors whatever happens.
fn run_on_robot(
    mut robot: SerialRobot<SerialPort>,
    ctl: &mut Controller,
    stage: &Stage,
    episode: &EpisodeOptions,
    out: &Path,
) -> Result<Driven, CliError> {
    // The trace is written as the robot drives: a process killed (even with
    // SIGKILL) keeps every action but the last few.
    create_dir(out)?;
    let mut written = report::TraceWriter::create(&shaping_engine::rundir::trace_path(out), stage)?;
    let started = Instant::now();
    let mut trace = Trace::default();
    let mut frames = Vec::new();
    let result = match robot.connect() {
        Ok(()) => {
            // Recorded as `replay` records the simulator: what the robot sensed, for
            // `trace.csv` and `episode.json`.
            let mut rec = Recorder::new(&mut robot);
            let r = ctl
                .run_traced(&mut rec, episode, &mut trace, |row, rec| written.push(row, rec.frames.last()));
            frames = rec.frames;
            Some(r)
        }
        Err(_) => None,
    };
    // Whatever happened, the wheels stop before anything else.
    let stopped = robot.stop();
    let seconds = started.elapsed().as_secs_f64();
    let error = robot.error().cloned();
    let requests = robot.requests;
    let bytes = robot.into_link().bytes;
    written.finish()?;
    Ok(Driven { trace, frames, result, stopped, error, seconds, requests, bytes })
}

/// The summary of a drive of `stage` (`drive.json`): what `args` asked,
/// the action `period`, the episode's `seed`, and what `driven` did.
fn summary(
    stage: &Stage,
    args: &DriveArgs,
    period: Duration,
    seed: u64,
    driven: &Driven,
) -> shaping_engine::rundir::DriveSummary {
    let done = driven.trace.rows.len();
    let result = driven.result.as_ref();
    shaping_engine::rundir::DriveSummary {
        stage: stage.name.clone(),
        seed,
        port: args.port.display().to_string(),
        baud: args.baud,
        period_ms: period.as_millis() as u64,
        actions: done,
        seconds: driven.seconds,
        actions_per_second: if driven.seconds > 0.0 { done as f64 / driven.seconds } else { 0.0 },
        requests: driven.requests,
        bytes: driven.bytes,
        fitness: result.map(|r| f64::from(r.fitness)),
        grips: result.map(|r| r.grips),
        releases_outside: result.map(|r| r.releases_outside),
        recharges: result.map(|r| r.recharges),
        collisions: result.map(|r| r.collisions),
        error: driven.error.as_ref().map(|e| e.to_string()),
    }
}

pub fn drive(args: DriveArgs) -> Result<(), CliError> {
    let terminal = Terminal::new(true, false);
    let Plan { program, index, genome, out, episode } = plan(&args, &terminal)?;
    let stage = &program.stages[index];
    let seed = episode.seed;
    let (sim_seed, rng) = episode_rngs(seed);
    let mut ctl = Controller::new(stage, &genome, rng).map_err(|e| {
        let message = format!("error: the genome does not fit stage `{}`: {e}", stage.name);
        CliError::new(shaping_engine::ErrorKind::Invalid, message)
    })?;

    let flag = interrupt_flag()?;
    let period = period(stage, args.period_ms);
    let port = SerialPort::open(&args.port, args.baud, Duration::from_millis(args.timeout_ms), period, flag)?;
    let robot = SerialRobot::new(&stage.world, sim_seed, None, has_gripper(stage), port);
    let start = robot.host().pose();
    eprintln!(
        "driving `{}` on {} at {} baud, {} ms per action; the robot should stand at x {:.0} mm, y {:.0} mm, heading {:.0} deg",
        stage.name,
        args.port.display(),
        args.baud,
        period.as_millis(),
        start.x,
        start.y,
        start.theta.to_degrees()
    );
    let scene = robot.host().scene();
    let mut driven = run_on_robot(robot, &mut ctl, stage, &episode, &out)?;
    let summary = summary(stage, &args, period, seed, &driven);

    let parts =
        [Part { stage: &stage.name, scene: scene.clone(), frames: std::mem::take(&mut driven.frames) }];
    let ep = episode::episode(stage, seed, episode.learning, &driven.trace, &parts);
    report::episode_pictures(&out, &stage.name, stage, &driven.trace, &scene)?;
    // Sealed, as a replay's are (`trace.csv` is written as the robot drives).
    shaping_engine::rundir::write_driven(&out, &ep, &genome)?;
    shaping_engine::rundir::write_drive_summary(&out, &summary)?;
    if let Some(err) = &driven.error {
        eprintln!("stopped after {} actions; what ran is in {}", summary.actions, out.display());
        return Err(CliError::io(failure(err, &driven.stopped)));
    }
    if let Err(e) = &driven.stopped {
        return Err(CliError::io(format!(
            "error: stopping the motors failed ({e}): the robot may still be driving"
        )));
    }
    let r = driven.result.unwrap_or_default();
    outln!(
        "{}: {} actions, fitness {:.3}, {} grips, {} released outside, {} recharges, {} collisions, {:.1} actions/s -> {}",
        stage.name,
        r.actions,
        r.fitness,
        r.grips,
        r.releases_outside,
        r.recharges,
        r.collisions,
        summary.actions_per_second,
        out.display()
    )?;
    Ok(())
}
