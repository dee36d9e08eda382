//! `shaping run` on the terminal: the engine's run with a progress bar,
//! lines on standard error (or JSON lines on standard output), Ctrl-C and
//! SIGTERM as its interruption flag, and the robot or MPI ranks as its
//! evaluator.

use std::cell::RefCell;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
pub use shaping_engine::run::{default_out, run_seed};
use shaping_engine::run::{Evaluate, Event, Observer, RunOptions, Runner};
use shaping_runtime::evolve;

use crate::cluster::Coordinator;
use crate::out::outln;
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

/// What a run prints: with `quiet`, warnings only; with `json`, one JSON
/// line per generation and per training or test stage on standard output,
/// and warnings on standard error.
pub struct Terminal {
    quiet: bool,
    json: bool,
    bar: RefCell<Option<ProgressBar>>,
    /// The first failure to write standard output (a full disk behind `>`).
    failed: RefCell<Option<CliError>>,
}

impl Terminal {
    pub fn new(quiet: bool, json: bool) -> Terminal {
        Terminal { quiet, json, bar: RefCell::new(None), failed: RefCell::new(None) }
    }

    fn human(&self) -> bool {
        !self.quiet && !self.json
    }

    fn print_json(&self, line: String) {
        if let Err(e) = outln!("{line}") {
            self.failed.borrow_mut().get_or_insert(e);
        }
    }

    /// A failure to write standard output while the run went on.
    pub fn take_failure(&self) -> Option<CliError> {
        self.failed.borrow_mut().take()
    }
}

impl Observer for Terminal {
    fn event(&self, event: Event<'_>) {
        match event {
            Event::EvolveStart { stage, generations, done } => {
                *self.bar.borrow_mut() = Some(progress_bar(!self.human(), stage, generations, done));
            }
            Event::Resumed { stage, generation, generations, finished, checkpoint } if self.human() => {
                if finished {
                    eprintln!(
                        "stage {stage:<12} all {generation} generations done before, from {}",
                        checkpoint.display()
                    );
                } else {
                    eprintln!("resuming `{stage}` at generation {generation} of {generations}");
                }
            }
            Event::Generation { stats, .. } => {
                if let Some(bar) = self.bar.borrow().as_ref() {
                    bar.set_message(format!("best {:.3} mean {:.3}", stats.best, stats.mean));
                    bar.inc(1);
                }
                if self.json {
                    match serde_json::to_string(stats) {
                        Ok(line) => self.print_json(line),
                        Err(e) => {
                            self.failed
                                .borrow_mut()
                                .get_or_insert(CliError::io(format!("error: cannot serialise: {e}")));
                        }
                    }
                }
            }
            Event::EvolveEnd { completed, .. } => {
                if let Some(bar) = self.bar.borrow_mut().take() {
                    if completed {
                        bar.finish_and_clear();
                    } else {
                        bar.abandon();
                    }
                }
            }
            Event::Evolved { stage, generations, last, chosen, dir } if self.human() => {
                eprintln!(
                    "stage {:<12} {} generations  last best {:.3}  mean {:.3}  chosen best {:.3} (mean of {} fresh episodes)  -> {}",
                    stage,
                    generations,
                    last.map_or(0.0, |h| h.best),
                    last.map_or(0.0, |h| h.mean),
                    chosen,
                    evolve::VALIDATE_EPISODES,
                    dir.display()
                );
            }
            Event::Trained { stage, trained, recorded, reused, dir } => {
                if reused {
                    if self.human() {
                        eprintln!("stage {:<12} trained before, reused  -> {}", stage.name, dir.display());
                    }
                } else if self.json {
                    self.print_json(
                        serde_json::json!({"stage": stage.name, "trained": trained.result.actions, "recorded": recorded, "performance": trained.performance})
                            .to_string(),
                    );
                } else if !self.quiet {
                    let perf: Vec<String> = stage
                        .modules
                        .iter()
                        .zip(&trained.performance)
                        .filter(|(m, _)| m.learning.is_some())
                        .map(|(m, p)| format!("{} {p:+.2}", m.name))
                        .collect();
                    let part = if recorded < trained.result.actions {
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
            }
            Event::Tested { stage, summary, lives, before, after, dir } => {
                if self.json {
                    self.print_json(serde_json::to_value(summary).map(|v| v.to_string()).unwrap_or_default());
                } else if !self.quiet {
                    let how = if lives == 1 {
                        String::new()
                    } else {
                        format!(" in {lives} lives each (fitness: mean per life)")
                    };
                    eprintln!(
                        "stage {:<12} test of the best, {} actions before and {} after the change{how}: fitness {:.3} -> {:.3}, grips {} -> {}  -> {}",
                        stage,
                        before.actions,
                        after.actions,
                        before.fitness,
                        after.fitness,
                        before.grips,
                        after.grips,
                        dir.display()
                    );
                }
            }
            Event::Warning(w) => match self.bar.borrow().as_ref() {
                Some(bar) => bar.suspend(|| eprintln!("{w}")),
                None => eprintln!("{w}"),
            },
            _ => {}
        }
    }
}

fn progress_bar(hidden: bool, stage: &str, generations: u32, done: u32) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(
        Some(generations as u64),
        if hidden { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() },
    );
    let style = ProgressStyle::with_template(
        "{prefix:>12} [{bar:30}] gen {pos:>3}/{len}  {msg}  {elapsed_precise} eta {eta}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_prefix(stage.to_string());
    bar.set_position(done as u64);
    bar
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
    let runner = Runner { observer: &terminal, evaluator, interrupt: interrupted.as_deref() };
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
