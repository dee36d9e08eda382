//! What a command prints while the engine runs: a progress bar, lines on
//! standard error, or JSON lines on standard output (`run`, `experiment`,
//! `replay`, `drive` alike).

use std::cell::RefCell;
use std::path::Path;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use shaping_engine::run::{Event, Observer};
use shaping_runtime::controller::EpisodeResult;
use shaping_runtime::evolve::{self, train::Trained};
use shaping_runtime::program::Stage;

use crate::out::outln;
use crate::CliError;

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
        // `--json`: a generation's, a training's and a test's event, one line each.
        let line = self.json.then(|| serde_json::to_string(&event));
        let json = || match &line {
            None => {}
            Some(Ok(line)) => self.print_json(line.clone()),
            Some(Err(e)) => {
                self.failed
                    .borrow_mut()
                    .get_or_insert(CliError::internal(format!("error: cannot serialise: {e}")));
            }
        };
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
                    json();
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
                    json();
                } else if !self.quiet {
                    eprintln!("{}", trained_line(stage, trained, recorded, dir));
                }
            }
            Event::Tested { stage, lives, before, after, dir, .. } => {
                if self.json {
                    json();
                } else if !self.quiet {
                    eprintln!("{}", tested_line(stage, lives, before, after, dir));
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

/// The line of a training stage `stage` done: its life of `trained`, the
/// performance of each module that learns, how much of it the trace and
/// pictures in `dir` hold (its first `recorded` actions).
fn trained_line(stage: &Stage, trained: &Trained, recorded: u32, dir: &Path) -> String {
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
    format!(
        "stage {:<12} trained for {} actions, performance {}{part}  -> {}",
        stage.name,
        trained.result.actions,
        perf.join(", "),
        dir.display()
    )
}

/// The line of a test stage `stage` done: the best's episodes before and
/// after the change (means over `lives` lives), whose files are in `dir`.
fn tested_line(stage: &str, lives: u32, before: &EpisodeResult, after: &EpisodeResult, dir: &Path) -> String {
    let how =
        if lives == 1 { String::new() } else { format!(" in {lives} lives each (fitness: mean per life)") };
    format!(
        "stage {:<12} test of the best, {} actions before and {} after the change{how}: fitness {:.3} -> {:.3}, grips {} -> {}  -> {}",
        stage,
        before.actions,
        after.actions,
        before.fitness,
        after.fitness,
        before.grips,
        after.grips,
        dir.display()
    )
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
