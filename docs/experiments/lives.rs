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
//! finds no `trained.json`), takes the best individual of
//! `DIR/seed-s/PARENT/checkpoint.json` (`PARENT` the evolved stage the test
//! stage extends in `FILE`; the genome layout must fit), and runs the test stage as `shaping
//! run` does: the same episode seed, one controller throughout, the lives in
//! the parent's world, then in the test stage's. So with the file the run was
//! made from, the lives are those of the run's own test. It prints one line
//! per life:
//!
//! `seed S life L world before|after actions A grips G out O signals N sum X`
//!
//! where `N` and `X` count and sum the grip module's reinforcement signals.

use std::process::ExitCode;

mod common;

use shaping_runtime::controller::{episode_rngs, Controller, EpisodeOptions, Trace};
use shaping_runtime::evolve::{best_of, seed, train_all, Checkpoint};
use shaping_runtime::program::StageRun;
use shaping_runtime::sim::Sim;

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
    let before_stage = &program.stages[parent];
    let grip = stage
        .modules
        .iter()
        .position(|m| m.name == "grip")
        .ok_or_else(|| format!("stage `{}` has no module `grip`", args.stage))?;
    for s in 1..=args.seeds {
        let mut program = program.clone();
        train_all(&mut program, s).map_err(|e| format!("seed {s}: {e}"))?;
        let stage = &program.stages[index];
        let path = format!("{}/seed-{s}/{}/checkpoint.json", args.run, program.stages[parent].name);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("cannot read `{path}`: {e}"))?;
        let cp: Checkpoint = serde_json::from_str(&text).map_err(|e| format!("`{path}`: {e}"))?;
        let (genome, _) = best_of(&cp).ok_or_else(|| format!("`{path}` holds no evaluated individual"))?;
        if genome.bits.len() != stage.layout.bits as usize {
            return Err(format!(
                "`{path}`: its best has {} bits, stage `{}` of `{}` {}",
                genome.bits.len(),
                args.stage,
                args.file,
                stage.layout.bits
            ));
        }
        let episode = seed::test_seed(s, index, 0);
        let mut ctl = Controller::new(stage, &genome, episode_rngs(episode).1).map_err(|e| e.to_string())?;
        let opts = EpisodeOptions { actions, learning, seed: episode };
        let mut trace = Trace::default();
        for (half, world) in [&before_stage.world, &stage.world].into_iter().enumerate() {
            for k in 0..lives {
                let mut sim = Sim::new(world, seed::test_life_seed(episode, half == 1, k));
                let r = ctl.run(&mut sim, &opts, Some(&mut trace));
                let signals: Vec<f32> =
                    trace.rows.iter().map(|row| row.reinforcement[grip]).filter(|&x| x != 0.0).collect();
                println!(
                    "seed {s} life {} world {} actions {} grips {} out {} signals {} sum {}",
                    half as u32 * lives + k,
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

fn main() -> ExitCode {
    common::exit(run())
}
