//! `shaping run` on the terminal: the engine's run with a progress bar,
//! lines on standard error (or JSON lines on standard output), Ctrl-C and
//! SIGTERM as its interruption flag, and the robot or MPI ranks as its
//! evaluator.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use shaping_engine::run::{default_out, Evaluate, RunOptions};
use shaping_engine::Engine;

use crate::cluster::Coordinator;
use crate::out::outln;
use crate::terminal::Terminal;
use crate::{load, CliError, ErrorFormat};

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
    pub error_format: ErrorFormat,
    /// Evaluate on a robot (`--robot`) instead of the simulator.
    pub robot: Option<crate::robot::RobotRun>,
    /// Settings changed from the command line (`--set`, one value each).
    pub sets: Vec<shaping_engine::sweep::Assignment>,
}

/// Ctrl-C, SIGTERM, SIGHUP or any other signal that would end the process
/// (`crate::signals`) during a run in one process: the generation under way
/// finishes and is saved, then the run stops saying where; a second signal
/// ends it at once. (On a robot the robot's own handler stops the motors
/// first, so there the second one does not end the process.)
pub fn interrupt_flag(exit_on_second: bool) -> Option<Arc<AtomicBool>> {
    static FLAG: OnceLock<Option<Arc<AtomicBool>>> = OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        crate::signals::register(&flag, exit_on_second).ok()?;
        Some(flag)
    })
    .clone()
}

/// Runs the stages; with `cluster` (rank 0 of an MPI run) the episodes of
/// each generation are spread over the ranks.
pub fn run(args: RunArgs, cluster: Option<&Coordinator>) -> Result<(), CliError> {
    let program = load::load_program(&args.file, args.error_format)?;
    let opts = RunOptions {
        stage: args.stage.clone(),
        seed: args.seed,
        out: args.out.clone().unwrap_or_else(|| default_out(&args.file)),
        jobs: args.jobs,
        fresh: args.fresh,
        no_report: args.no_report,
        sets: args.sets.clone(),
    };
    let interrupted = if cluster.is_none() { interrupt_flag(args.robot.is_none()) } else { None };
    let terminal = Terminal::new(args.quiet, args.json);
    let evaluator: Option<&dyn Evaluate> = match (&args.robot, cluster) {
        (Some(r), _) => Some(r),
        (None, Some(c)) => Some(c),
        (None, None) => None,
    };
    let runner = Engine { observer: &terminal, evaluator, interrupt: interrupted.as_deref() };
    let started = Instant::now();
    // A built program (`program.json`) names no file: the directory's own
    // program.json may be run into it.
    let outcome = runner.run_file(program, &args.file, &opts);
    if let Some(e) = terminal.take_failure() {
        return Err(e);
    }
    let outcome = outcome?;
    if args.json {
        let stages: Vec<serde_json::Value> = outcome.stages.iter().map(|s| s.to_json()).collect();
        let line = serde_json::json!({
            "done": true, "out": outcome.out.display().to_string(), "seed": outcome.seed,
            "seconds": started.elapsed().as_secs_f64(), "stages": stages,
            "report": outcome.report.as_ref().map(|p| p.display().to_string()),
        });
        outln!("{line}")?;
    }
    if !args.quiet && !args.json {
        eprintln!("done in {:.2} s; results in {}", started.elapsed().as_secs_f64(), outcome.out.display());
        if let Some(path) = outcome.report {
            eprintln!("report: {}", path.display());
        }
    }
    Ok(())
}
