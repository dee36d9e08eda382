//! `shaping bench`: simulator steps and controller actions per second for an
//! architecture, as one JSON line (median of several timed runs, one thread).

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shaping_runtime::catalog::CHANNELS;
use shaping_runtime::controller::{run_episode, EpisodeOptions};
use shaping_runtime::genome::Genome;
use shaping_runtime::sim::{Command, Sim};

use crate::load;
use crate::out::outln;
use crate::CliError;

pub struct BenchArgs {
    pub file: PathBuf,
    pub stage: Option<String>,
    pub runs: usize,
    pub error_format: crate::diag::ErrorFormat,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

pub fn bench(args: BenchArgs) -> Result<(), CliError> {
    let mut program = load::load_program(&args.file, args.error_format)?;
    let index = load::stage_index(&program, args.stage.as_deref())?;
    let seed = crate::run::run_seed(&program, None);
    shaping_engine::run::bind_training(&mut program, None, seed, &shaping_engine::run::Silent)?;
    let stage = &program.stages[index];
    let runs = args.runs.max(1);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let genome = Genome { bits: (0..stage.layout.bits).map(|_| rng.random_range(0..2u8)).collect() };

    // Simulator alone: sense + step with a slowly changing command.
    let steps = 200_000u32;
    let mut sim_rates = Vec::with_capacity(runs);
    let mut percept = [0.0f32; CHANNELS];
    for run in 0..runs {
        let mut sim = Sim::new(&stage.world, run as u64);
        let t = Instant::now();
        for i in 0..steps {
            sim.sense(&mut percept);
            let turn = if (i / 16) % 2 == 0 { 0.3 } else { -0.3 };
            let cmd = Command { wheels: [0.8 + turn * percept[2], 0.8 - turn], ..Command::default() };
            black_box(sim.step(&cmd));
        }
        sim_rates.push(steps as f64 / t.elapsed().as_secs_f64());
    }

    // Controller and simulator: whole episodes.
    let episodes = 200u64;
    let actions = 300;
    let mut ctl_rates = Vec::with_capacity(runs);
    for run in 0..runs {
        let t = Instant::now();
        let mut done = 0u64;
        for e in 0..episodes {
            let opts = EpisodeOptions { actions, learning: true, seed: run as u64 * episodes + e };
            done += black_box(run_episode(stage, &genome, &opts, None)).actions as u64;
        }
        ctl_rates.push(done as f64 / t.elapsed().as_secs_f64());
    }
    let line = serde_json::json!({
        "file": args.file.display().to_string(),
        "stage": stage.name,
        "runs": runs,
        "sim_steps_per_sec": median(sim_rates).round(),
        "controller_actions_per_sec": median(ctl_rates).round(),
        "modules": stage.modules.len(),
        "genome_bits": stage.layout.bits,
    });
    outln!("{line}")?;
    Ok(())
}
