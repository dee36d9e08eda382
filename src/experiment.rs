//! `shaping experiment` on the terminal: the engine's plan, its tasks run
//! one after another (or over MPI ranks), the summary printed.

use shaping_engine::experiment::Plan;
use shaping_engine::Engine;

use crate::cluster::Coordinator;
use crate::out::out;
use crate::run::interrupt_flag;
use crate::terminal::Terminal;
use crate::CliError;

/// Runs every seed of every point, then the summaries. Under MPI (`cluster`
/// is rank 0's coordinator) with at least as many tasks as ranks, whole
/// seeds go to ranks; with fewer, the seeds run one after the other, each
/// generation's episodes spread over every rank.
pub fn experiment(plan: &Plan, jobs: Option<usize>, cluster: Option<&Coordinator>) -> Result<(), CliError> {
    let _lock = plan.lock()?;
    let tasks = plan.tasks();
    match cluster {
        Some(c) if c.distributes(tasks.len()) => {
            c.run_tasks(&tasks, &|task, threads| run_task(plan, task, Some(threads), true, None), &|t| {
                plan.describe(t)
            })?
        }
        _ => {
            for (i, &task) in tasks.iter().enumerate() {
                eprintln!("{} ({}/{})", plan.describe(task), i + 1, tasks.len());
                run_task(plan, task, jobs, false, cluster)?;
            }
        }
    }
    let finished = plan.finish()?;
    if let Some(w) = shaping_engine::files::unsealed_warning(&finished.unsealed) {
        eprintln!("{w}");
    }
    out!("{}", finished.summary)?;
    for path in finished.reports {
        eprintln!("report: {}", path.display());
    }
    Ok(())
}

/// Runs one task of `plan` as `shaping run` would, its progress on the
/// terminal (warnings only when `quiet`).
pub fn run_task(
    plan: &Plan,
    task: (u32, u64),
    jobs: Option<usize>,
    quiet: bool,
    cluster: Option<&Coordinator>,
) -> Result<(), CliError> {
    let terminal = Terminal::new(quiet, false);
    let interrupted = if cluster.is_none() { interrupt_flag(true) } else { None };
    let runner = Engine {
        observer: &terminal,
        evaluator: cluster.map(|c| c as &dyn shaping_engine::run::Evaluate),
        interrupt: interrupted.as_deref(),
    };
    let started = std::time::Instant::now();
    let outcome = plan.run_task(task, jobs, &runner)?;
    if !quiet {
        eprintln!("done in {:.2} s; results in {}", started.elapsed().as_secs_f64(), outcome.out.display());
    }
    Ok(())
}
