//! A run's evolved bests in a file's test stage, with the file's training
//! stages trained afresh (EXPERIMENTS.md, "Figure 13 over many lives"): what
//! the collect bests of one run do when their grip and release networks are
//! trained in another world, or when the test learns at other rates.
//!
//! ```sh
//! cargo run --release --example lives -- FILE --run DIR [--stage bigger] [--seeds 10]
//! ```
//!
//! For each seed `s` of `1..=--seeds`, it binds the training stages of `FILE`
//! by training them with seed `s` (as `shaping run --seed s` does when it
//! finds no `trained.json`; `FILE` may train them otherwise than the run
//! did), takes the best individual of `DIR/seed-s/PARENT/` (`PARENT` the
//! evolved stage the test stage extends in `FILE`), and runs the test stage
//! through the engine's `run::before_after`, as `shaping run` does: the same
//! episode seed, one controller throughout, the lives in the parent's world,
//! then in the test stage's. So with the file the run was made from, the
//! lives are those of the run's own test. The best is checked as the run
//! made it, not against `FILE` (whose training stages or learning rates may
//! differ on purpose): its checkpoint must fit the run's own
//! `DIR/seed-s/program.json` with the run's trained weights bound
//! (`rundir::checked_best`), its seed must be `s`, and its genome layout
//! must fit `FILE`'s stage. It prints one line per life:
//!
//! `seed S life L world before|after actions A grips G out O signals N sum X`
//!
//! where `N` and `X` count and sum the grip module's reinforcement signals.

use std::path::Path;
use std::process::ExitCode;

mod common;

use shaping_engine::load::load_built;
use shaping_engine::run::{before_after, Lives};
use shaping_engine::rundir;
use shaping_runtime::evolve::{self, seed};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::StageRun;

struct Args {
    file: String,
    run: String,
    stage: String,
    seeds: u64,
}

fn parse_args() -> Result<Args, String> {
    let mut file = None;
    let mut a = Args { file: String::new(), run: String::new(), stage: "bigger".into(), seeds: 10 };
    let mut run = None;
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        match arg.as_str() {
            "--run" => run = Some(value("--run")?),
            "--stage" => a.stage = value("--stage")?,
            "--seeds" => a.seeds = value("--seeds")?.parse().map_err(|e| format!("--seeds: {e}"))?,
            s if s.starts_with('-') => return Err(format!("unknown option `{s}`")),
            s if file.is_none() => file = Some(s.to_string()),
            s => return Err(format!("unexpected argument `{s}`")),
        }
    }
    a.file = file.ok_or("usage: lives FILE --run DIR [--stage bigger] [--seeds 10]")?;
    a.run = run.ok_or("--run DIR is needed: the run whose evolved bests are tested")?;
    Ok(a)
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let (program, index) = common::load(&args.file, &args.stage)?;
    let StageRun::Test { actions, lives, learning } = program.stages[index].run else {
        return Err(format!("stage `{}` of `{}` is not a test stage", args.stage, args.file));
    };
    let stage = &program.stages[index];
    let parent = stage.parent.ok_or_else(|| format!("stage `{}` extends no stage", args.stage))?;
    if !matches!(program.stages[parent].run, StageRun::Evolve(_)) {
        return Err(format!(
            "stage `{}` extends `{}`, which is not evolved",
            args.stage, program.stages[parent].name
        ));
    }
    let grip = stage
        .modules
        .iter()
        .position(|m| m.name == "grip")
        .ok_or_else(|| format!("stage `{}` has no module `grip`", args.stage))?;
    for s in 1..=args.seeds {
        let mut program = program.clone();
        common::bind(&mut program, None, s).map_err(|e| format!("seed {s}: {e}"))?;
        let stage = &program.stages[index];
        let genome = run_best(&args, &program.stages[parent].name, s)?;
        if genome.bits.len() != stage.layout.bits as usize {
            return Err(format!(
                "the best of `{}` has {} bits, stage `{}` of `{}` {}",
                rundir::stage_dir(&rundir::seed_dir(Path::new(&args.run), s), &program.stages[parent].name)
                    .display(),
                genome.bits.len(),
                args.stage,
                args.file,
                stage.layout.bits
            ));
        }
        let episode = seed::test_seed(s, evolve::test_seed_stage(&program, index), 0);
        let ba = before_after(
            &program.stages[parent],
            stage,
            &genome,
            Lives { actions, count: lives, learning },
            episode,
            None,
        )
        .map_err(common::message)?;
        let mut rows = ba.trace.rows.iter();
        for (half, results) in [&ba.before, &ba.after].into_iter().enumerate() {
            for (k, r) in results.iter().enumerate() {
                let signals: Vec<f32> = rows
                    .by_ref()
                    .take(r.actions as usize)
                    .map(|row| row.reinforcement[grip])
                    .filter(|&x| x != 0.0)
                    .collect();
                println!(
                    "seed {s} life {} world {} actions {} grips {} out {} signals {} sum {}",
                    half as u32 * lives + k as u32,
                    if half == 0 { "before" } else { "after" },
                    r.actions,
                    r.grips,
                    r.releases_outside,
                    signals.len(),
                    signals.iter().sum::<f32>()
                );
            }
        }
    }
    Ok(())
}

/// The chosen best of evolved stage `name` in the run directory of seed
/// `s`, checked against the program that run ran (its `program.json`, with
/// its training stages bound as the run bound them).
fn run_best(args: &Args, name: &str, s: u64) -> Result<Genome, String> {
    let dir = rundir::seed_dir(Path::new(&args.run), s);
    let mut ran = load_built(&rundir::program_path(&dir)).map_err(common::message)?;
    common::bind(&mut ran, Some(&dir), s)?;
    let index = ran
        .stage(name)
        .map(|(i, _)| i)
        .ok_or_else(|| format!("the run in `{}` has no stage `{name}`", dir.display()))?;
    common::best(&ran, index, &dir, s)
}

fn main() -> ExitCode {
    common::exit(run())
}
