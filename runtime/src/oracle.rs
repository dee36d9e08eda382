//! Ceilings of a collect stage: how many objects the world allows, measured
//! with arbiters that know the simulated world.
//!
//! Two measurements, each an upper bound for a part of the problem:
//!
//! - [`Decisions`]: an evolved individual's own architecture, except that
//!   the grip module wins exactly when nothing is held and an object is in
//!   reach (its centre within [`Decisions::grip_reach`] of the body surface,
//!   in front), and the release module exactly when an object is held and a
//!   wall is within [`Decisions::release_reach`] in front (their scripts
//!   steer toward what the proximity sensors see, then grip or release);
//!   at any other time neither can win and
//!   the highest activation among the other modules drives, as evolved. The
//!   gap between it and the individual alone is what perfect grip and
//!   release decisions would add to the evolved navigation.
//! - [`Search`]: no architecture. The robot drives straight at full speed,
//!   turns in place by a random angle when its front proximity sensors read
//!   above [`Search::turn_ir`]; when an object comes within
//!   [`Search::grip_reach`] in front it turns to it, brings it between the
//!   arms and grips it; holding one, when a wall comes within
//!   [`Search::release_reach`] in front it turns to face the wall, drives to
//!   it and releases (one action per arm or claw move, as the scripts do);
//!   it heads for the charger
//!   (knowing where it is) when the battery falls below
//!   [`Search::low_battery`] and charges there until full. Objects are found
//!   only by driving over them, as the robot must. What it collects bounds
//!   what any controller that searches blindly can collect in this world.
//!
//! Both run the episode the stage's episode seed gives (same start pose and
//! objects as [`crate::controller::run_episode`]), or with the objects put
//! where the caller says.

use std::f32::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::catalog::{CHANNELS, CH_IR};
use crate::controller::{episode_rngs, Controller, ControllerError, EpisodeOptions, EpisodeResult, Trace};
use crate::genome::Genome;
use crate::program::Stage;
use crate::sim::{Command, Pose, Sim};

/// The episode's simulator, with the objects put at `objects` (mm) when
/// given and the body moved clear of them if the new placement overlaps it.
fn world(stage: &Stage, sim_seed: u64, objects: Option<&[[f32; 2]]>) -> Result<Sim, ControllerError> {
    let mut sim = Sim::new(&stage.world, sim_seed);
    let Some(at) = objects else { return Ok(sim) };
    for (i, p) in at.iter().enumerate() {
        if !sim.set_object(i, p[0], p[1]) {
            return Err(ControllerError::Setup(format!(
                "object {i} cannot be put at ({}, {}) mm in stage `{}`",
                p[0], p[1], stage.name
            )));
        }
    }
    let start = sim.pose();
    let steps = [0.0f32, 40.0, -40.0, 80.0, -80.0, 120.0, -120.0];
    let clear = steps.iter().any(|&dx| {
        steps.iter().any(|&dy| sim.set_pose(Pose { x: start.x + dx, y: start.y + dy, theta: start.theta }))
    });
    if !clear {
        return Err(ControllerError::Setup(format!(
            "no start pose near ({}, {}) mm is clear of the objects in stage `{}`",
            start.x, start.y, stage.name
        )));
    }
    Ok(sim)
}

/// The index of the module named `name` in `stage`.
pub fn module(stage: &Stage, name: &str) -> Result<usize, String> {
    stage
        .modules
        .iter()
        .position(|m| m.name == name)
        .ok_or_else(|| format!("stage `{}` has no module `{name}`", stage.name))
}

/// Perfect grip and release decisions on an evolved architecture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decisions {
    /// The grip module's index.
    pub grip: usize,
    /// The release module's index.
    pub release: usize,
    /// Distance from the body surface to an object's centre in front at
    /// which the grip module is made to win, mm.
    pub grip_reach: f32,
    /// Distance from the body surface to a wall in front at which the
    /// release module is made to win, mm.
    pub release_reach: f32,
}

/// An object's centre within `reach` of the body surface, within 90
/// degrees of the heading.
fn object_in_front(sim: &Sim, reach: f32) -> Option<(f32, f32)> {
    let (fwd, side, gap) = sim.nearest_object()?;
    (gap <= reach && fwd + sim.body_radius() > 0.0).then_some((fwd, side))
}

/// A wall within `reach` of the body surface whose normal is within 90
/// degrees of the heading: its distance and the normal's bearing.
fn wall_in_front(sim: &Sim, reach: f32) -> Option<(f32, f32)> {
    let (gap, bearing) = sim.nearest_wall();
    (gap <= reach && bearing.abs() < PI / 2.0).then_some((gap, bearing))
}

impl Decisions {
    /// The modules named `grip` and `release`; objects within 25 mm (about
    /// where the proximity sensors see a 10 mm object), walls within 30 mm.
    pub fn by_name(stage: &Stage) -> Result<Decisions, String> {
        Ok(Decisions {
            grip: module(stage, "grip")?,
            release: module(stage, "release")?,
            grip_reach: 25.0,
            release_reach: 30.0,
        })
    }

    /// One episode of `genome` on `stage` (validated, trained weights bound)
    /// with these decisions imposed.
    pub fn run_episode(
        &self,
        stage: &Stage,
        genome: &Genome,
        opts: &EpisodeOptions,
        objects: Option<&[[f32; 2]]>,
        trace: Option<&mut Trace>,
    ) -> Result<EpisodeResult, ControllerError> {
        run_arbitrated(stage, genome, opts, objects, trace, |ctl, sim| {
            let (grip, release) = if sim.holding() {
                (false, wall_in_front(sim, self.release_reach).is_some())
            } else {
                (object_in_front(sim, self.grip_reach).is_some(), false)
            };
            if grip {
                ctl.force_winner(self.grip);
            } else if release {
                ctl.force_winner(self.release);
            }
            if !grip {
                ctl.forbid(self.grip);
            }
            if !release {
                ctl.forbid(self.release);
            }
        })
    }
}

/// One episode of `genome` on `stage` as evolved (no arbiter), with the
/// objects put at `objects` (mm) when given: an evolved individual in a
/// test placement, such as the paper's figure 11 (8 objects evenly spread).
/// With `objects: None` it is [`crate::controller::run_episode`]'s episode.
pub fn run_placed(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    objects: Option<&[[f32; 2]]>,
) -> Result<EpisodeResult, ControllerError> {
    run_arbitrated(stage, genome, opts, objects, None, |_, _| {})
}

/// One episode of `genome` on `stage` (the objects put at `objects` when
/// given), with `before` called before every action: the hook of an arbiter
/// outside the architecture, which may read the world and the controller
/// and call [`Controller::force_winner`] or [`Controller::forbid`].
pub fn run_arbitrated(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    objects: Option<&[[f32; 2]]>,
    trace: Option<&mut Trace>,
    before: impl FnMut(&mut Controller, &Sim),
) -> Result<EpisodeResult, ControllerError> {
    let (sim_seed, rng) = episode_rngs(opts.seed);
    let mut ctl = Controller::new(stage, genome, rng)?;
    let mut sim = world(stage, sim_seed, objects)?;
    Ok(ctl.run_with(&mut sim, opts, trace, before))
}

/// A blind search with perfect gripping, releasing and recharging, driving
/// the simulator directly (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Search {
    /// Front proximity reading above which the robot turns away.
    pub turn_ir: f32,
    /// Battery level below which the robot heads for the charger.
    pub low_battery: f32,
    /// Distance from the body surface to an object's centre in front at
    /// which the robot goes for it, mm.
    pub grip_reach: f32,
    /// Distance from the body surface to a wall in front at which the robot
    /// holding an object goes to release it there, mm.
    pub release_reach: f32,
    /// Actions a fetch or a delivery may take before the robot gives up.
    pub patience: u32,
}

impl Default for Search {
    fn default() -> Self {
        Search { turn_ir: 0.5, low_battery: 0.3, grip_reach: 25.0, release_reach: 30.0, patience: 8 }
    }
}

/// What [`Search`] is doing.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Explore,
    /// Turning in place for this many more actions, this way (+1 left).
    Turn(u32, f32),
    /// Bringing an object between the arms (actions left).
    Fetch(u32),
    /// Facing a wall and driving to it, holding an object (actions left).
    Deliver(u32),
    /// Gripping: arm down, claw closed, arm up (the step reached).
    Grip(u8),
    /// Releasing: claw open, arm up.
    Release(u8),
    /// On the way to the charger, then charging until full.
    Recharge,
}

impl Search {
    /// One episode of the stage's world (its seed as
    /// [`crate::controller::run_episode`] derives it) driven by the search.
    /// The result counts actions, grips, releases outside, recharges and
    /// collisions; its fitness is the stage's bonuses for those events (the
    /// per-action term needs a controller and is left out).
    pub fn run_episode(
        &self,
        stage: &Stage,
        opts: &EpisodeOptions,
        objects: Option<&[[f32; 2]]>,
    ) -> Result<EpisodeResult, ControllerError> {
        let (sim_seed, _) = episode_rngs(opts.seed);
        let mut sim = world(stage, sim_seed, objects)?;
        let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
        rng.set_stream(7);
        let mut percept = [0.0f32; CHANNELS];
        let mut res = EpisodeResult::default();
        let mut mode = Mode::Explore;
        for _ in 0..opts.actions {
            if !sim.alive() {
                break;
            }
            sim.sense(&mut percept);
            let front = percept[CH_IR..CH_IR + 6].iter().fold(0.0f32, |a, &b| a.max(b));
            if sim.battery() < self.low_battery && matches!(mode, Mode::Explore | Mode::Turn(..)) {
                mode = Mode::Recharge;
            }
            if mode == Mode::Explore {
                if !sim.holding() && object_in_front(&sim, self.grip_reach).is_some() {
                    mode = Mode::Fetch(self.patience);
                } else if sim.holding() && wall_in_front(&sim, self.release_reach).is_some() {
                    mode = Mode::Deliver(self.patience);
                } else if front > self.turn_ir {
                    let turns = rng.random_range(2..=5);
                    mode = Mode::Turn(turns, if rng.random::<bool>() { 1.0 } else { -1.0 });
                }
            }
            // A fetch or delivery that has reached its goal grips or releases
            // in this action; one that runs out of patience gives up.
            if let Mode::Fetch(n) = mode {
                mode = if sim.object_in_reach() {
                    Mode::Grip(0)
                } else if n == 0 || sim.holding() {
                    Mode::Explore
                } else {
                    Mode::Fetch(n - 1)
                };
            }
            if let Mode::Deliver(n) = mode {
                mode = if sim.wall_ahead_within(crate::sim::RELEASE_REACH) {
                    Mode::Release(0)
                } else if n == 0 || !sim.holding() {
                    Mode::Explore
                } else {
                    Mode::Deliver(n - 1)
                };
            }
            let cmd = match mode {
                Mode::Explore => Command { wheels: [1.0, 1.0], ..Command::default() },
                Mode::Fetch(_) => match sim.nearest_object() {
                    Some((fwd, side, _)) => {
                        let bearing = side.atan2(fwd + sim.body_radius());
                        if bearing.abs() > 0.25 {
                            turn(bearing)
                        } else if fwd > crate::sim::CATCH_FAR - 5.0 {
                            Command { wheels: [0.5, 0.5], ..Command::default() }
                        } else {
                            Command { wheels: [-0.5, -0.5], ..Command::default() }
                        }
                    }
                    None => Command::default(),
                },
                Mode::Deliver(_) => {
                    let (_, bearing) = sim.nearest_wall();
                    if bearing.abs() > 0.3 {
                        turn(bearing)
                    } else {
                        Command { wheels: [0.5, 0.5], ..Command::default() }
                    }
                }
                Mode::Turn(n, dir) => {
                    mode = if n > 1 { Mode::Turn(n - 1, dir) } else { Mode::Explore };
                    Command { wheels: [-dir, dir], ..Command::default() }
                }
                Mode::Grip(k) => {
                    mode = if k < 2 { Mode::Grip(k + 1) } else { Mode::Explore };
                    match k {
                        0 => Command { arm: Some(true), claw: Some(false), ..Command::default() },
                        1 => Command { claw: Some(true), ..Command::default() },
                        _ => Command { arm: Some(false), ..Command::default() },
                    }
                }
                Mode::Release(k) => {
                    mode = if k < 1 { Mode::Release(k + 1) } else { Mode::Explore };
                    match k {
                        0 => Command { claw: Some(false), ..Command::default() },
                        _ => Command { arm: Some(false), ..Command::default() },
                    }
                }
                Mode::Recharge => {
                    let cmd = self.recharge(&sim);
                    if sim.battery() >= 1.0 {
                        mode = Mode::Explore;
                    }
                    cmd
                }
            };
            let out = sim.step(&cmd);
            res.actions += 1;
            res.grips += out.grips;
            res.releases_outside += out.releases_outside;
            res.recharges += u32::from(out.recharged);
            res.collisions += u32::from(out.collided);
        }
        let mut fitness = 0.0f64;
        crate::controller::add_bonuses(stage, &res, &mut fitness);
        res.fitness = fitness as f32;
        Ok(res)
    }

    /// Heads for the nearest point of the bar knowing where it is, then
    /// charges in contact.
    fn recharge(&self, sim: &Sim) -> Command {
        let Some([a, b]) = sim.bar() else { return Command::default() };
        if sim.bar_distance().is_some_and(|d| d <= crate::sim::CONTACT * 0.5) {
            return Command { charge: true, ..Command::default() };
        }
        let pose = sim.pose();
        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        let bearing = (mid[1] - pose.y).atan2(mid[0] - pose.x);
        let mut off = bearing - pose.theta;
        while off > PI {
            off -= 2.0 * PI;
        }
        while off < -PI {
            off += 2.0 * PI;
        }
        if off.abs() > 0.2 {
            Command { charge: true, ..turn(off) }
        } else {
            let near = sim.bar_distance().unwrap_or(0.0);
            let speed = (near / 20.0).clamp(0.05, 1.0);
            Command { wheels: [speed, speed], charge: true, ..Command::default() }
        }
    }
}

/// Turns in place toward `bearing` (radians, positive to the left), at
/// most a half-speed action's worth.
fn turn(bearing: f32) -> Command {
    let dir = bearing.signum();
    Command { wheels: [-0.5 * dir, 0.5 * dir], ..Command::default() }
}

/// `n` object centres evenly spread over an arena of `arena` mm: a grid of
/// as many columns as fit the arena's aspect, each centre in the middle of
/// its cell (8 objects in 400 x 600 mm: 2 columns of 4).
pub fn evenly_spread(n: usize, arena: [f32; 2]) -> Vec<[f32; 2]> {
    if n == 0 {
        return Vec::new();
    }
    let aspect = (arena[0] / arena[1]).max(1e-3);
    let cols = ((n as f32 * aspect).sqrt().round() as usize).clamp(1, n);
    let rows = n.div_ceil(cols);
    (0..n)
        .map(|i| {
            let (c, r) = (i % cols, i / cols);
            [arena[0] * (c as f32 + 0.5) / cols as f32, arena[1] * (r as f32 + 0.5) / rows as f32]
        })
        .collect()
}

/// One trial of a scripted module started in front of a floor object (for
/// the grip module: does its script catch it?). The robot stands in the
/// middle of the arena facing +x, the stage's first object lies with its
/// centre `gap` mm from the body surface (negative: under the front of the
/// body, where a robot driving at full speed may find a virtual object) at
/// `bearing_deg` from the heading, the other objects in a corner out of
/// sight; `module` is made to win the first action and its committed script
/// runs. Returns the first reinforcement it delivers within 30 actions
/// (`None` if it delivers none). The world must have objects; `genome` is
/// the stage's (its other modules do not drive once the script has started).
pub fn grip_trial(
    stage: &Stage,
    genome: &Genome,
    module: usize,
    gap: f32,
    bearing_deg: f32,
    seed: u64,
) -> Result<Option<f32>, ControllerError> {
    let count = stage.world.objects.as_ref().map_or(0, |o| o.count as usize);
    if count == 0 {
        return Err(ControllerError::Setup(format!("stage `{}` has no objects", stage.name)));
    }
    let (sim_seed, rng) = episode_rngs(seed);
    let mut ctl = Controller::new(stage, genome, rng)?;
    let mut sim = Sim::new(&stage.world, sim_seed);
    let [w, d] = stage.world.arena;
    let (x, y) = (w / 2.0, d / 2.0);
    let reach = stage.world.body.radius + gap;
    let b = bearing_deg.to_radians();
    let corner = stage.world.objects.as_ref().map_or(1.0, |o| o.diameter / 2.0 + 1.0);
    let placed = sim.set_pose(Pose { x, y, theta: 0.0 })
        && sim.set_object(0, x + reach * b.cos(), y + reach * b.sin())
        && (1..count).all(|i| sim.set_object(i, corner, corner));
    if !placed {
        return Err(ControllerError::Setup(format!(
            "cannot put the robot at ({x}, {y}) mm and an object {gap} mm ahead at {bearing_deg} degrees in stage `{}`",
            stage.name
        )));
    }
    ctl.start(&mut sim);
    for _ in 0..30 {
        ctl.force_winner(module);
        let rep = ctl.act(&mut sim);
        if rep.winner == module && rep.reinforcement != 0.0 {
            return Ok(Some(rep.reinforcement));
        }
    }
    Ok(None)
}
