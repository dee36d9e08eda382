//! `shaping bench`'s measurements: simulator steps, controller actions and
//! episodes per second for a stage (median of several timed runs, one
//! thread), with what the timed robots did: the share of robot-steps in
//! which a robot moved and in which it collided. A benchmark of a robot
//! pinned against a wall, or with an empty battery, times nothing a run
//! does. The caller prints [`Bench`] (it serializes to `shaping bench`'s
//! JSON line, but for the file's name).
//!
//! A stage of one robot times one [`Sim`]; a stage of a team
//! (`world.robots` N > 1) times the N robots of one [`Team`], each acting
//! in turn every action, as a team's lives run.

use std::hint::black_box;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use shaping_runtime::catalog::{CHANNELS, CH_IR};
use shaping_runtime::controller::{run_episode, run_team_episode, EpisodeOptions};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Program, World};
use shaping_runtime::sim::{Command, Sim, Team};

use crate::Result;

/// What `shaping bench` measured for a stage. Rates are medians over the
/// runs; shares and means are over all of them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bench {
    pub stage: String,
    pub runs: usize,
    /// Robots in the stage's world (`world.robots`).
    pub robots: u32,
    /// Steps of the simulated world per second: every robot moved once.
    pub sim_steps_per_sec: f64,
    /// Robot-steps per second: `robots` x `sim_steps_per_sec` while every
    /// robot lives (a dead robot's turn is no step).
    pub robot_steps_per_sec: f64,
    /// Share of the robot-steps in which the robot's wheels turned.
    pub sim_moving_share: f64,
    /// Share of the robot-steps in which the robot collided.
    pub sim_collision_share: f64,
    /// Controller actions (a robot's controller deciding and its robot
    /// moving once) per second in whole episodes of a random individual.
    pub controller_actions_per_sec: f64,
    /// Episodes (a team's: one life of every robot) per second.
    pub controller_episodes_per_sec: f64,
    /// The mean length of a life in actions.
    pub controller_actions_per_episode: f64,
    /// The bench's own life length for the controller runs (a life ends
    /// there or when its battery is empty): [`EPISODE_ACTIONS`], shorter
    /// for a large team but at least [`TEAM_ACTIONS`], whatever the stage
    /// declares.
    pub controller_episode_actions: u32,
    /// The life length the stage declares (`evolve { actions N }`), which
    /// the controller runs do not use.
    pub stage_actions: u32,
    /// Episodes in each timed controller run ([`EPISODES`], fewer for a team).
    pub controller_episodes_per_run: u64,
    /// The longest a simulated world lives in the timed simulator runs
    /// before a new one is made, in actions (a new one is made sooner when
    /// one robot's battery, or half a team's, is empty).
    pub sim_episode_actions: u32,
    /// How far robot 0 went per action of its lives, mm.
    pub controller_mm_per_action: f64,
    pub modules: usize,
    pub genome_bits: u32,
    /// Robot-steps the timed simulator runs made, and their moving and
    /// colliding ones (not printed: the shares are).
    #[serde(skip)]
    pub robot_steps: u64,
    #[serde(skip)]
    pub moved: u64,
    #[serde(skip)]
    pub collided: u64,
    /// Actions (every robot once) the timed simulator runs made.
    #[serde(skip)]
    pub actions: u64,
}

/// Robot-steps each timed simulator run makes (about: whole actions).
pub const SIM_ROBOT_STEPS: u64 = 200_000;
/// Episodes and actions each controller run makes with one robot; a team
/// runs fewer (and shorter ones beyond 200 robots) for about as many
/// robot-actions, but never lives shorter than [`TEAM_ACTIONS`].
pub const EPISODES: u64 = 200;
pub const EPISODE_ACTIONS: u32 = 300;
/// The shortest life a team's controller runs time, in actions: shorter
/// ones would time placing the team more than its robots sensing,
/// deciding and acting (a team of 10,000 made 6-action lives before).
pub const TEAM_ACTIONS: u32 = 100;

/// The episodes of a timed controller run and their length in actions, for
/// a team of `robots`: about [`EPISODES`] x [`EPISODE_ACTIONS`]
/// robot-actions, but lives of at least [`TEAM_ACTIONS`] for a team.
pub fn controller_lives(robots: u32) -> (u64, u32) {
    let n = u64::from(robots.max(1));
    let episodes = (EPISODES / n).max(1);
    let actions = EPISODE_ACTIONS.min((EPISODES * u64::from(EPISODE_ACTIONS) / (n * episodes)).max(1) as u32);
    (episodes, if n == 1 { actions } else { actions.max(TEAM_ACTIONS) })
}

/// The engine's one median ([`crate::stats::median`]) of the runs' rates.
fn median(v: Vec<f64>) -> f64 {
    crate::stats::median(&v).unwrap_or(f64::NAN)
}

fn share(part: u64, whole: u64) -> f64 {
    (part as f64 / whole.max(1) as f64 * 1000.0).round() / 1000.0
}

/// Measures stage `index` of `program` (its training stages bound as a
/// run binds them) over `runs` timed runs (at least one).
pub fn bench(mut program: Program, index: usize, runs: usize) -> Result<Bench> {
    let seed = crate::run::run_seed(&program, None);
    crate::run::bind_training(&mut program, None, seed, &crate::run::Silent)?;
    let stage = &program.stages[index];
    let runs = runs.max(1);
    let robots = stage.robots();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let genome = Genome { bits: (0..stage.layout.bits).map(|_| rng.random_range(0..2u8)).collect() };

    let sim = if robots == 1 { time_sim(&stage.world, runs) } else { time_team(&stage.world, runs) };

    // Controller and simulator: whole episodes of a random individual, as
    // evolution runs them; and how far its robot (robot 0) went.
    let (episodes, actions) = controller_lives(robots);
    let mut ctl_rates = Vec::with_capacity(runs);
    let mut episode_rates = Vec::with_capacity(runs);
    // Lives' lengths over all runs; robot 0's path and actions in run 0's.
    let (mut lives, mut path, mut first) = (0u64, 0.0f64, 0u64);
    for run in 0..runs {
        let t = Instant::now();
        let mut done = 0u64;
        for e in 0..episodes {
            let opts = EpisodeOptions { actions, learning: true, seed: run as u64 * episodes + e };
            // The life's length, the robot-actions, robot 0's path and actions.
            let (life, robot_actions, mm, own) = if robots == 1 {
                let r = black_box(run_episode(stage, &genome, &opts, None));
                (r.actions, u64::from(r.actions), r.descriptors.path_length, r.actions)
            } else {
                let r = black_box(run_team_episode(stage, &genome, &opts, None)).unwrap_or_default();
                let all = r.robots.iter().map(|x| u64::from(x.actions)).sum();
                let own = r.robots.first().map_or(0, |x| x.actions);
                (r.team.actions, all, r.team.descriptors.path_length, own)
            };
            done += robot_actions;
            lives += u64::from(life);
            if run == 0 {
                first += u64::from(own);
                path += f64::from(mm);
            }
        }
        let secs = t.elapsed().as_secs_f64();
        ctl_rates.push(done as f64 / secs);
        episode_rates.push(episodes as f64 / secs);
    }
    Ok(Bench {
        stage: stage.name.clone(),
        runs,
        robots,
        sim_steps_per_sec: median(sim.world_rates).round(),
        robot_steps_per_sec: median(sim.robot_rates).round(),
        sim_moving_share: share(sim.moved, sim.steps),
        sim_collision_share: share(sim.collided, sim.steps),
        controller_actions_per_sec: median(ctl_rates).round(),
        controller_episodes_per_sec: median(episode_rates).round(),
        controller_actions_per_episode: (lives as f64 / (episodes * runs as u64) as f64).round(),
        controller_episode_actions: actions,
        stage_actions: shaping_runtime::evolve::EvalOptions::of(stage).actions,
        controller_episodes_per_run: episodes,
        sim_episode_actions: match (robots, &stage.world.battery) {
            (1, Some(b)) => b.capacity,
            (1, None) => SIM_ROBOT_STEPS as u32,
            _ => EPISODE_ACTIONS,
        },
        controller_mm_per_action: (path / first.max(1) as f64 * 10.0).round() / 10.0,
        modules: stage.modules.len(),
        genome_bits: stage.layout.bits,
        robot_steps: sim.steps,
        moved: sim.moved,
        collided: sim.collided,
        actions: sim.actions,
    })
}

/// The timed simulator runs.
struct SimTimes {
    world_rates: Vec<f64>,
    robot_rates: Vec<f64>,
    steps: u64,
    actions: u64,
    moved: u64,
    collided: u64,
}

/// The four front IR sensors.
const FRONT: [usize; 4] = [CH_IR + 1, CH_IR + 2, CH_IR + 3, CH_IR + 4];

/// The moving rule (after Enki's benchmark): full speed ahead, and while
/// one of the four front sensors reads above 0.3, backing away on a turn
/// (a body touching a wall cannot spin in place here: the turn would
/// overlap it).
#[inline]
fn wheels(percept: &[f32; CHANNELS]) -> [f32; 2] {
    if FRONT.iter().any(|&c| percept[c] > 0.3) {
        [-0.2, -1.0]
    } else {
        [1.0, 1.0]
    }
}

/// One robot: a new world (the next seed) whenever the battery is empty,
/// as a new episode of evolution starts.
fn time_sim(world: &World, runs: usize) -> SimTimes {
    let steps = SIM_ROBOT_STEPS;
    let mut rates = Vec::with_capacity(runs);
    let (mut moved, mut collided) = (0u64, 0u64);
    let mut percept = [0.0f32; CHANNELS];
    for run in 0..runs {
        let mut seed = run as u64 * 1_000_000;
        let mut sim = Sim::new(world, seed);
        let t = Instant::now();
        for _ in 0..steps {
            if !sim.alive() {
                seed += 1;
                sim = Sim::new(world, seed);
            }
            sim.sense(&mut percept);
            let wheels = wheels(&percept);
            let outcome = black_box(sim.step(&Command { wheels, ..Command::default() }));
            // Moved: a wheel turned (no pose angles in the timed loop).
            moved += u64::from(sim.wheel_travel() != [0.0, 0.0]);
            collided += u64::from(outcome.collided);
        }
        rates.push(steps as f64 / t.elapsed().as_secs_f64());
    }
    let done = steps * runs as u64;
    SimTimes { world_rates: rates.clone(), robot_rates: rates, steps: done, actions: done, moved, collided }
}

/// A team: every action, each living robot in turn is given the others
/// within reach, senses and moves, then the board (if any) measures; a
/// new team (the next seed) once half the robots' batteries are empty
/// (until then a dead robot's turn is no step), and after [`EPISODE_ACTIONS`] actions, as evolution's lives are
/// (with time, a robot of this rule can wedge itself in a corner, its back
/// against one wall while a front sensor sees the other: a long-lived
/// team would time ever more robots that do not move).
fn time_team(world: &World, runs: usize) -> SimTimes {
    let n = world.robots.max(1) as usize;
    let actions = (SIM_ROBOT_STEPS / n as u64).max(1);
    let mut times = SimTimes {
        world_rates: Vec::with_capacity(runs),
        robot_rates: Vec::with_capacity(runs),
        steps: 0,
        actions: 0,
        moved: 0,
        collided: 0,
    };
    let mut percept = [0.0f32; CHANNELS];
    let living = |team: &Team| team.sims().iter().filter(|s| s.alive()).count();
    for run in 0..runs {
        let mut seed = run as u64 * 1_000_000;
        let mut team = Team::new(world, seed);
        let mut alive = living(&team);
        let (mut done, mut age) = (0u64, 0);
        let t = Instant::now();
        for _ in 0..actions {
            if 2 * alive <= n || age == EPISODE_ACTIONS {
                seed += 1;
                team = Team::new(world, seed);
                alive = living(&team);
                age = 0;
            }
            age += 1;
            team.begin_action();
            for i in 0..n {
                if !team.sim(i).alive() {
                    continue;
                }
                team.prepare(i);
                team.sense(i, &mut percept);
                let wheels = wheels(&percept);
                let outcome = black_box(team.step(i, &Command { wheels, ..Command::default() }));
                let sim = team.sim(i);
                times.moved += u64::from(sim.wheel_travel() != [0.0, 0.0]);
                times.collided += u64::from(outcome.collided);
                alive -= usize::from(!sim.alive());
                done += 1;
            }
            // The range-and-bearing board's measurement, as a life's.
            team.end_action();
        }
        let secs = t.elapsed().as_secs_f64();
        times.world_rates.push(actions as f64 / secs);
        times.robot_rates.push(done as f64 / secs);
        times.steps += done;
        times.actions += actions;
    }
    times
}
