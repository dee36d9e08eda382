//! The ceilings of the collect stage (EXPERIMENTS.md, "What the world
//! allows"), with the arbiters of `shaping_runtime::oracle`:
//!
//! - `search`: a blind search with perfect gripping, releasing and
//!   recharging, no architecture: what the world allows;
//! - `decisions`: each seed's evolved collect best (`RUN/seed-N/STAGE/` of
//!   `shaping experiment`: its checkpoint's best, checked against the file
//!   as `shaping replay` checks it) with grip and release made to win
//!   exactly when they can succeed; `evolved`: the same individual alone, on
//!   the same episodes; `physical`: the same with physical objects (they
//!   block the robot and stay outside once thrown out), as in the paper's
//!   test.
//!
//! ```sh
//! cargo run --release --example oracle -- [FILE] [--stage collect] [--seeds 10] [--first-seed 1] [--actions 300] [--run DIR]
//! ```
//!
//! For `--seeds` run seeds from `--first-seed` (1 unless told; the seed of
//! the training stage that teaches the avoid module, and of the evolved run)
//! and episode seeds 101..=103 (those of `run.sh`'s replays; the search,
//! which has no architecture, runs episode seed `1000 * run seed + episode`
//! so that its lives differ), it prints one line per episode, objects at
//! random as the stage declares and evenly spread (the paper's figure 11: 8
//! objects evenly distributed), then the medians. Without `--run`, only
//! `search`. The training stages bind as in a run of each seed: from the
//! run's `trained.json` where it fits, else trained again with the seed.

use std::path::Path;
use std::process::ExitCode;

mod common;

use shaping_engine::rundir;
use shaping_runtime::controller::{run_episode, EpisodeOptions, EpisodeResult, Trace};
use shaping_runtime::oracle::{self, evenly_spread, run_placed, Decisions, Search};

struct Args {
    file: String,
    stage: String,
    seeds: u64,
    first_seed: u64,
    actions: u32,
    run: Option<String>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        file: "examples/khepera.bat".into(),
        stage: "collect".into(),
        seeds: 10,
        first_seed: 1,
        actions: 300,
        run: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        match arg.as_str() {
            "--stage" => a.stage = value("--stage")?,
            "--run" => a.run = Some(value("--run")?),
            "--seeds" => a.seeds = value("--seeds")?.parse().map_err(|e| format!("--seeds: {e}"))?,
            "--first-seed" => {
                a.first_seed = value("--first-seed")?.parse().map_err(|e| format!("--first-seed: {e}"))?
            }
            "--actions" => a.actions = value("--actions")?.parse().map_err(|e| format!("--actions: {e}"))?,
            s if s.starts_with("--") => return Err(format!("unknown option `{s}`")),
            s => a.file = s.into(),
        }
    }
    Ok(a)
}

fn median(v: Vec<f64>) -> f64 {
    shaping_engine::stats::median(&v).unwrap_or(f64::NAN)
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let (base, index) = common::load(&args.file, &args.stage)?;
    let search = Search::default();
    println!(
        "search: turn above {} front IR, recharge below battery {}, release with a wall within {} mm",
        search.turn_ir, search.low_battery, search.release_reach
    );
    println!("who placement seed episode: actions released_outside grips recharges");
    let mut all: Vec<(&str, &str, EpisodeResult)> = Vec::new();
    // Under `decisions` with random placement: grip and release signals
    // (rewarded, punished) and the actions won by wander, avoid, follow.
    let (mut grip_signals, mut release_signals, mut drove) = ((0, 0), (0, 0), [0usize; 3]);
    for seed in args.first_seed..args.first_seed + args.seeds {
        let run = args.run.as_ref().map(|dir| rundir::seed_dir(Path::new(dir), seed));
        let mut program = base.clone();
        common::bind(&mut program, run.as_deref(), seed)?;
        let stage = &program.stages[index];
        let mut physical = stage.clone();
        if let Some(o) = physical.world.objects.as_mut() {
            o.virtual_ = false;
        }
        let spread = stage.world.objects.as_ref().map(|o| evenly_spread(o.count as usize, stage.world.arena));
        let best = match &run {
            Some(dir) => Some(common::best(&program, index, dir, seed)?),
            None => None,
        };
        let decisions = Decisions::by_name(stage)?;
        for episode in 101..=103u64 {
            let opts = EpisodeOptions { actions: args.actions, learning: true, seed: episode };
            for (placement, at) in [("random", None), ("even", spread.as_deref())] {
                // The search has no architecture, so the run seed does not
                // change it: its 30 lives are 30 distinct episodes instead.
                let world_only = EpisodeOptions { seed: 1000 * seed + episode, ..opts };
                let mut runs =
                    vec![("search", search.run_episode(stage, &world_only, at).map_err(|e| e.to_string())?)];
                if let Some(g) = &best {
                    let mut trace = Trace::default();
                    let d = decisions
                        .run_episode(stage, g, &opts, at, Some(&mut trace))
                        .map_err(|e| e.to_string())?;
                    let signals = |m: usize| {
                        let r = trace.rows.iter().map(|row| row.reinforcement[m]);
                        (r.clone().filter(|&x| x > 0.0).count(), r.filter(|&x| x < 0.0).count())
                    };
                    let (gok, gbad) = signals(decisions.grip);
                    let (rok, rbad) = signals(decisions.release);
                    let won: Vec<usize> = ["wander", "avoid", "follow"]
                        .iter()
                        .map(|name| match oracle::module(stage, name) {
                            Ok(m) => trace.rows.iter().filter(|row| row.winner as usize == m).count(),
                            Err(_) => 0,
                        })
                        .collect();
                    println!(
                        "  decisions {placement} {seed} {episode}: grip rewarded {gok} punished {gbad}, \
                         release rewarded {rok} punished {rbad}; actions won by wander {}, avoid {}, follow {}",
                        won[0], won[1], won[2]
                    );
                    if at.is_none() {
                        grip_signals = (grip_signals.0 + gok, grip_signals.1 + gbad);
                        release_signals = (release_signals.0 + rok, release_signals.1 + rbad);
                        for (d, w) in drove.iter_mut().zip(&won) {
                            *d += w;
                        }
                    }
                    runs.push(("decisions", d));
                    if at.is_none() {
                        runs.push(("evolved", run_episode(stage, g, &opts, None)));
                    } else {
                        runs.push(("evolved", run_placed(stage, g, &opts, at).map_err(|e| e.to_string())?));
                    }
                    // The paper's test of figure 11 used real objects: the
                    // same episode with physical ones (they block the robot
                    // and do not come back once thrown out).
                    runs.push(("physical", run_placed(&physical, g, &opts, at).map_err(|e| e.to_string())?));
                }
                for (who, r) in runs {
                    println!(
                        "{who} {placement} {seed} {episode}: {} {} {} {}",
                        r.actions, r.releases_outside, r.grips, r.recharges
                    );
                    all.push((who, placement, r));
                }
            }
        }
    }
    for who in ["search", "decisions", "evolved", "physical"] {
        for placement in ["random", "even"] {
            let v: Vec<&EpisodeResult> =
                all.iter().filter(|(w, p, _)| *w == who && *p == placement).map(|(_, _, r)| r).collect();
            if v.is_empty() {
                continue;
            }
            let col = |g: fn(&EpisodeResult) -> u32| v.iter().map(|r| g(r) as f64).collect::<Vec<_>>();
            let out = col(|r| r.releases_outside);
            println!(
                "{who} {placement}: {} episodes; released outside median {} (range {}..{}, mean {:.2}); \
                 grips median {}; actions median {}; recharged in {} of {}",
                v.len(),
                median(out.clone()),
                out.iter().cloned().fold(f64::INFINITY, f64::min),
                out.iter().cloned().fold(0.0, f64::max),
                out.iter().sum::<f64>() / v.len() as f64,
                median(col(|r| r.grips)),
                median(col(|r| r.actions)),
                v.iter().filter(|r| r.recharges > 0).count(),
                v.len()
            );
        }
    }
    let lives = all.iter().filter(|(w, p, _)| *w == "decisions" && *p == "random").count();
    if lives > 0 {
        let per = |n: usize| n as f64 / lives as f64;
        println!(
            "decisions random, {lives} lives: grip rewarded {} punished {}; release rewarded {} punished {}; \
             actions per life won by wander {:.0}, avoid {:.0}, follow {:.0}",
            grip_signals.0,
            grip_signals.1,
            release_signals.0,
            release_signals.1,
            per(drove[0]),
            per(drove[1]),
            per(drove[2])
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    common::exit(run())
}
