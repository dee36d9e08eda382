//! Teams at the end of their lives (EXPERIMENTS.md, "Teams: aggregation and
//! cooperative collect"): random walkers against the evolved teams, and
//! what the evolved teams do, life by life.
//!
//! ```sh
//! cargo run --release --example walkers -- FILE [--stage aggregate] [--lives 100]
//!     [--run DIR [--seeds 10] [--first-seed 1]] [--picture FILE.png]
//! ```
//!
//! It builds the team of stage `--stage` of `FILE` (its `robots`, start
//! region and arena) in `--lives` fresh lives, life `k` of seed
//! [`life_seed`]`(k)` (so every team, walkers or evolved, starts from the
//! same places), each as long as the stage's evolved lives. Without
//! `--run`, every robot is a random walker with obstacle avoidance: full
//! speed ahead, every 10 to 30 actions a turn on the spot of 1 to 4 actions
//! (43 degrees each) to a random side, and a turn away from whatever the
//! front proximity sensors read above 0.3 until they read less. With
//! `--run`, the robots are the chosen best of the stage in `DIR/seed-s/`,
//! for each of the `--seeds` seeds `s` from `--first-seed` (checked as
//! `lives` does: its checkpoint must fit the program, its seed must be
//! `s`), with learning on. One line per life:
//!
//! `walkers|seed S life K start S0 end S1 near N0 N1 group G0 G1 out O robots O0 O1 ...`
//!
//! the team's spread (`team.spread`, mm), the share of its robots with
//! another's body within 20 mm of their own, and the share in the largest
//! group (robots linked by such gaps), at action 0 and at the end; the
//! objects released outside by the team, then by each robot. Then the
//! medians (spreads and shares) and means (objects) over the lives, and
//! for `--run` the same per seed and over the seeds. `--picture` draws the
//! first life (of the walkers, or of the first seed's best): the arena,
//! each robot's path in a colour of its own from a small ring where it
//! starts to its body where it ends.

use std::path::Path;
use std::process::ExitCode;

mod common;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shaping_engine::rundir;
use shaping_runtime::catalog::{CHANNELS, CH_IR};
use shaping_runtime::controller::{EpisodeOptions, TeamRun};
use shaping_runtime::evolve::seed::mix;
use shaping_runtime::program::{Stage, StageRun};
use shaping_runtime::sim::{Command, Team};
use shaping_runtime::state::NEIGHBOUR_GAP;

struct Args {
    file: String,
    stage: String,
    lives: u32,
    run: Option<String>,
    seeds: u64,
    first_seed: u64,
    picture: Option<String>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        file: String::new(),
        stage: "aggregate".into(),
        lives: 100,
        run: None,
        seeds: 10,
        first_seed: 1,
        picture: None,
    };
    let mut file = None;
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        match arg.as_str() {
            "--stage" => a.stage = value("--stage")?,
            "--lives" => a.lives = value("--lives")?.parse().map_err(|e| format!("--lives: {e}"))?,
            "--run" => a.run = Some(value("--run")?),
            "--seeds" => a.seeds = value("--seeds")?.parse().map_err(|e| format!("--seeds: {e}"))?,
            "--picture" => a.picture = Some(value("--picture")?),
            "--first-seed" => {
                a.first_seed = value("--first-seed")?.parse().map_err(|e| format!("--first-seed: {e}"))?
            }
            s if s.starts_with('-') => return Err(format!("unknown option `{s}`")),
            s if file.is_none() => file = Some(s.to_string()),
            s => return Err(format!("unexpected argument `{s}`")),
        }
    }
    a.file = file.ok_or("usage: walkers FILE [--stage aggregate] [--lives 100] [--run DIR [--seeds 10] [--first-seed 1]] [--picture FILE.png]")?;
    if a.lives == 0 || a.seeds == 0 {
        return Err("--lives and --seeds must be at least 1".into());
    }
    Ok(a)
}

/// The seed of fresh life `k`, of its own (a run's episodes mix the run's
/// seed), the same for the walkers and every evolved team.
fn life_seed(k: u32) -> u64 {
    mix(0x0077_616c_6b65_7273, &[u64::from(k)])
}

/// One random walker's state: actions left before the next random turn,
/// and the turn under way (actions left, the left wheel's sign).
struct Walker {
    rng: ChaCha8Rng,
    next_turn: u32,
    turning: u32,
    side: f32,
}

impl Walker {
    fn new(seed: u64) -> Walker {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let next_turn = rng.random_range(10..=30);
        Walker { rng, next_turn, turning: 0, side: 1.0 }
    }

    /// The wheels for what the robot senses now.
    fn wheels(&mut self, percept: &[f32; CHANNELS]) -> [f32; 2] {
        let ir = &percept[CH_IR..CH_IR + 8];
        // ir[0] left (90 degrees) .. ir[5] right (-90 degrees).
        if ir[1..5].iter().cloned().fold(0.0, f32::max) > 0.3 {
            self.turning = 0;
            let left = ir[0] + ir[1] + ir[2];
            let right = ir[3] + ir[4] + ir[5];
            // Something on the left: turn right (left wheel forward).
            return if left >= right { [1.0, -1.0] } else { [-1.0, 1.0] };
        }
        if self.turning > 0 {
            self.turning -= 1;
            return [self.side, -self.side];
        }
        self.next_turn = self.next_turn.saturating_sub(1);
        if self.next_turn == 0 {
            self.next_turn = self.rng.random_range(10..=30);
            self.turning = self.rng.random_range(1..=4) - 1;
            self.side = if self.rng.random_bool(0.5) { 1.0 } else { -1.0 };
            return [self.side, -self.side];
        }
        [1.0, 1.0]
    }
}

/// One life of a team: spread, share with a neighbour and share in the
/// largest group ([`Team::groups`], bodies within [`NEIGHBOUR_GAP`]) at action 0 and at the end; objects released
/// outside by each robot.
struct Life {
    spread: [f32; 2],
    near: [f32; 2],
    group: [f32; 2],
    out: Vec<u32>,
}

impl Life {
    fn print(&self, who: &str, k: u32) {
        let per: Vec<String> = self.out.iter().map(|o| o.to_string()).collect();
        println!(
            "{who} life {k} start {:.1} end {:.1} near {:.2} {:.2} group {:.2} {:.2} out {} robots {}",
            self.spread[0],
            self.spread[1],
            self.near[0],
            self.near[1],
            self.group[0],
            self.group[1],
            self.out.iter().sum::<u32>(),
            per.join(" ")
        );
    }
}

/// Life `k` of stage `stage`'s team, each robot driven by `drive`
/// (a random walker), or of `ctl`'s team (an evolved genome).
/// With `paths`, each robot's centre at the start and after every action.
fn live(
    stage: &Stage,
    actions: u32,
    k: u32,
    ctl: Option<&mut TeamRun<'_>>,
    mut paths: Option<&mut Vec<Vec<[f32; 2]>>>,
) -> Life {
    let seed = life_seed(k);
    let mut team = Team::new(&stage.world, seed);
    let (spread0, (near0, group0)) = (team.spread(), team.groups(NEIGHBOUR_GAP));
    let mut record = |team: &Team| {
        if let Some(paths) = paths.as_deref_mut() {
            paths.resize(team.len(), Vec::new());
            for (path, sim) in paths.iter_mut().zip(team.sims()) {
                path.push(sim.position());
            }
        }
    };
    record(&team);
    let out = match ctl {
        Some(ctl) => {
            let opts = EpisodeOptions { actions, learning: true, seed };
            let res = ctl.run(&mut team, &opts, None, |team| {
                record(team);
                true
            });
            res.robots.iter().map(|r| r.releases_outside).collect()
        }
        None => {
            let mut walkers: Vec<Walker> =
                (0..team.len()).map(|i| Walker::new(mix(seed, &[i as u64]))).collect();
            let mut out = vec![0; team.len()];
            let mut percept = [0.0; CHANNELS];
            for _ in 0..actions {
                team.begin_action();
                for (i, w) in walkers.iter_mut().enumerate() {
                    team.prepare(i);
                    team.sense(i, &mut percept);
                    let cmd = Command { wheels: w.wheels(&percept), ..Command::default() };
                    out[i] += team.step(i, &cmd).releases_outside;
                }
                record(&team);
            }
            out
        }
    };
    let (near1, group1) = team.groups(NEIGHBOUR_GAP);
    Life { spread: [spread0, team.spread()], near: [near0, near1], group: [group0, group1], out }
}

/// Draws `paths` in an arena of `arena` mm into `file` (PNG, 1 px per
/// 2 mm): each robot's path in its own colour, a ring where it starts, its
/// body (`radius`) where it ends.
fn picture(file: &str, arena: [f32; 2], radius: f32, paths: &[Vec<[f32; 2]>]) -> Result<(), String> {
    use plotters::prelude::*;
    const MM_PER_PX: f32 = 2.0;
    let margin = 10;
    let (w, h) = ((arena[0] / MM_PER_PX) as i32, (arena[1] / MM_PER_PX) as i32);
    let size = ((w + 2 * margin) as u32, (h + 2 * margin) as u32);
    let root = BitMapBackend::new(file, size).into_drawing_area();
    let err = |e: DrawingAreaErrorKind<_>| format!("cannot draw `{file}`: {e}");
    // y up, as in the arena.
    let px = |p: [f32; 2]| (margin + (p[0] / MM_PER_PX) as i32, margin + h - (p[1] / MM_PER_PX) as i32);
    root.fill(&WHITE).map_err(err)?;
    root.draw(&Rectangle::new([(margin, margin), (margin + w, margin + h)], BLACK.stroke_width(2)))
        .map_err(err)?;
    let r = (radius / MM_PER_PX).round() as i32;
    for (i, path) in paths.iter().enumerate() {
        let colour = Palette99::pick(i);
        root.draw(&PathElement::new(path.iter().map(|&p| px(p)).collect::<Vec<_>>(), colour.stroke_width(1)))
            .map_err(err)?;
        if let (Some(&first), Some(&last)) = (path.first(), path.last()) {
            root.draw(&Circle::new(px(first), 3, colour.stroke_width(1))).map_err(err)?;
            root.draw(&Circle::new(px(last), r, colour.filled())).map_err(err)?;
            root.draw(&Circle::new(px(last), r, BLACK.stroke_width(1))).map_err(err)?;
        }
    }
    root.present().map_err(err)
}

fn median(v: &[f32]) -> f32 {
    let v: Vec<f64> = v.iter().map(|&x| f64::from(x)).collect();
    shaping_engine::stats::median(&v).unwrap_or(f64::NAN) as f32
}

/// The medians of a set of lives (spreads and shares) and the mean of
/// their objects out, per team and per robot.
struct Summary {
    spread: [f32; 2],
    near: [f32; 2],
    group: [f32; 2],
    out: f32,
}

fn summarise(lives: &[Life]) -> Summary {
    let med = |f: &dyn Fn(&Life) -> f32| median(&lives.iter().map(f).collect::<Vec<_>>());
    Summary {
        spread: [med(&|l| l.spread[0]), med(&|l| l.spread[1])],
        near: [med(&|l| l.near[0]), med(&|l| l.near[1])],
        group: [med(&|l| l.group[0]), med(&|l| l.group[1])],
        out: lives.iter().map(|l| l.out.iter().sum::<u32>() as f32).sum::<f32>() / lives.len() as f32,
    }
}

impl Summary {
    fn print(&self, who: &str, robots: u32) {
        println!(
            "{who}: spread at the start {:.1} mm, at the end {:.1} mm; with a neighbour {:.2} -> {:.2}; \
             largest group {:.2} -> {:.2}; objects out per life {:.2} (per robot {:.2})",
            self.spread[0],
            self.spread[1],
            self.near[0],
            self.near[1],
            self.group[0],
            self.group[1],
            self.out,
            self.out / robots as f32
        );
    }
}

/// `name: median M, min A, max B, over N` of `v`.
fn over_seeds(name: &str, mut v: Vec<f32>) {
    v.sort_by(f32::total_cmp);
    let m = median(&v);
    println!("{name}: median {m:.2}, min {:.2}, max {:.2}, over {} seeds", v[0], v[v.len() - 1], v.len());
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let (program, index) = common::load(&args.file, &args.stage)?;
    let StageRun::Evolve(ev) = &program.stages[index].run else {
        return Err(format!("stage `{}` of `{}` is not evolved", args.stage, args.file));
    };
    let actions = ev.actions;
    let robots = program.stages[index].world.robots.max(1);
    println!("{robots} robots, {actions} actions, {} lives", args.lives);
    let world = &program.stages[index].world;
    let (arena, radius) = (world.arena, world.body.radius);
    let mut paths = Vec::new();
    let Some(run) = &args.run else {
        let lives: Vec<Life> = (0..args.lives)
            .map(|k| {
                let draw = (k == 0 && args.picture.is_some()).then_some(&mut paths);
                let l = live(&program.stages[index], actions, k, None, draw);
                l.print("walkers", k);
                l
            })
            .collect();
        if let Some(file) = &args.picture {
            picture(file, arena, radius, &paths)?;
        }
        summarise(&lives).print("walkers (medians over the lives)", robots);
        return Ok(());
    };
    let mut seeds = Vec::new();
    for s in args.first_seed..args.first_seed.saturating_add(args.seeds) {
        let dir = rundir::seed_dir(Path::new(run), s);
        let mut program = program.clone();
        common::bind(&mut program, Some(&dir), s).map_err(|e| format!("seed {s}: {e}"))?;
        let genome = common::best(&program, index, &dir, s)?;
        let stage = &program.stages[index];
        let mut lives = Vec::new();
        for k in 0..args.lives {
            let mut ctl = TeamRun::new(stage, &genome, life_seed(k)).map_err(|e| format!("seed {s}: {e}"))?;
            let draw = (k == 0 && s == args.first_seed && args.picture.is_some()).then_some(&mut paths);
            let l = live(stage, actions, k, Some(&mut ctl), draw);
            l.print(&format!("seed {s}"), k);
            lives.push(l);
        }
        let sum = summarise(&lives);
        sum.print(&format!("seed {s} (medians over the lives)"), robots);
        seeds.push(sum);
    }
    if let Some(file) = &args.picture {
        picture(file, arena, radius, &paths)?;
    }
    println!("over the seeds (each seed's medians over its lives):");
    over_seeds("  spread at the end, mm", seeds.iter().map(|s| s.spread[1]).collect());
    over_seeds("  share with a neighbour at the end", seeds.iter().map(|s| s.near[1]).collect());
    over_seeds("  share in the largest group at the end", seeds.iter().map(|s| s.group[1]).collect());
    if world.objects.is_some() {
        over_seeds("  objects out per life, team", seeds.iter().map(|s| s.out).collect());
        over_seeds(
            "  objects out per life, per robot",
            seeds.iter().map(|s| s.out / robots as f32).collect(),
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    common::exit(run())
}
