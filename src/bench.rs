//! `shaping bench`: simulator steps, controller actions and episodes per
//! second for an architecture, as one JSON line (median of several timed
//! runs, one thread), with what the timed robots did: the share of steps in
//! which the robot moved and in which it collided. A benchmark of a robot
//! pinned against a wall, or with an empty battery, times nothing a run
//! does.

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shaping_runtime::catalog::{CHANNELS, CH_IR};
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

    // Simulator alone, with a robot that keeps moving (after the rule of
    // Enki's benchmark): full speed ahead, and while one of the four front
    // sensors reads above 0.3, backing away on a turn (a body touching a
    // wall cannot spin in place here: the turn would overlap it); a new
    // world (the next seed) whenever the battery is empty, as a new episode
    // of evolution starts.
    let steps = 200_000u32;
    let mut sim_rates = Vec::with_capacity(runs);
    let (mut moved, mut collided) = (0u64, 0u64);
    let mut percept = [0.0f32; CHANNELS];
    let front = [CH_IR + 1, CH_IR + 2, CH_IR + 3, CH_IR + 4];
    for run in 0..runs {
        let mut world = run as u64 * 1_000_000;
        let mut sim = Sim::new(&stage.world, world);
        let t = Instant::now();
        for _ in 0..steps {
            if !sim.alive() {
                world += 1;
                sim = Sim::new(&stage.world, world);
            }
            sim.sense(&mut percept);
            let blocked = front.iter().any(|&c| percept[c] > 0.3);
            let wheels = if blocked { [-0.2, -1.0] } else { [1.0, 1.0] };
            let outcome = black_box(sim.step(&Command { wheels, ..Command::default() }));
            // Moved: a wheel turned (no pose angles in the timed loop).
            moved += u64::from(sim.wheel_travel() != [0.0, 0.0]);
            collided += u64::from(outcome.collided);
        }
        sim_rates.push(steps as f64 / t.elapsed().as_secs_f64());
    }
    let timed = f64::from(steps) * runs as f64;

    // Controller and simulator: whole episodes of a random individual, as
    // evolution runs them; and how far its robot went.
    let episodes = 200u64;
    let actions = 300;
    let mut ctl_rates = Vec::with_capacity(runs);
    let mut episode_rates = Vec::with_capacity(runs);
    let (mut done_all, mut path) = (0u64, 0.0f64);
    for run in 0..runs {
        let t = Instant::now();
        let mut done = 0u64;
        for e in 0..episodes {
            let opts = EpisodeOptions { actions, learning: true, seed: run as u64 * episodes + e };
            done += black_box(run_episode(stage, &genome, &opts, None)).actions as u64;
        }
        let secs = t.elapsed().as_secs_f64();
        ctl_rates.push(done as f64 / secs);
        episode_rates.push(episodes as f64 / secs);
        done_all += done;
    }
    // The same episodes again, untimed, with their paths.
    for e in 0..episodes {
        let opts = EpisodeOptions { actions, learning: true, seed: e };
        path += f64::from(shaping_engine::descriptors::episode(stage, &genome, &opts).1.path_length);
    }
    let line = serde_json::json!({
        "file": args.file.display().to_string(),
        "stage": stage.name,
        "runs": runs,
        "sim_steps_per_sec": median(sim_rates).round(),
        "sim_moving_share": (moved as f64 / timed * 1000.0).round() / 1000.0,
        "sim_collision_share": (collided as f64 / timed * 1000.0).round() / 1000.0,
        "controller_actions_per_sec": median(ctl_rates).round(),
        "controller_episodes_per_sec": median(episode_rates).round(),
        "controller_actions_per_episode": (done_all as f64 / (episodes as f64 * runs as f64)).round(),
        "controller_mm_per_action": (path / (done_all as f64 / runs as f64) * 10.0).round() / 10.0,
        "modules": stage.modules.len(),
        "genome_bits": stage.layout.bits,
    });
    outln!("{line}")?;
    Ok(())
}
