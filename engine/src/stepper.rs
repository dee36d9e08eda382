//! A stage's world and robot driven one action at a time from outside: the
//! agent of a reinforcement-learning library (Python's `shaping.gym`), or
//! any program that chooses the commands itself instead of the stage's
//! modules.
//!
//! - The observation is the robot's declared sensors, in declaration order
//!   (earlier stages' first), each element 0..1.
//! - The action is the declared actuators: the two wheel speeds (-1..1 of
//!   `v_max`), then `arm` (above 0.5: down) and `claw` (above 0.5: closed)
//!   where the robot declares them, then `charge` (above 0.5: ask the
//!   charger to recharge; it charges within contact of the bar) where the
//!   world has a charger bar.
//! - The reward of an action is the stage's fitness for it: the per-action
//!   term, then each bonus times its events in that action. A life's
//!   rewards add up to the fitness a run gives that life's episode (the
//!   same world, seed and commands give the same episode: a test replays
//!   a controller's commands and compares).
//! - A life ends early (`terminated`) when the battery is empty, and is cut
//!   (`truncated`) at the stage's length of life (its `actions`).
//!
//! A stage whose world has a team is refused ([`check`]): one agent
//! drives one robot.
//!
//! [`Stepper`] is one robot; [`VecStepper`] is many, stepped on the
//! threads of the caller's rayon pool in one call, each resetting itself
//! on the step after its life ended. Both are deterministic by seed.

use std::sync::Arc;

use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use shaping_runtime::catalog::{ActuatorKind, ACT_SLOTS, CHANNELS, SIGNALS};
use shaping_runtime::controller::{bonus_points, record_command, FastExpr};
use shaping_runtime::expr::Env;
use shaping_runtime::program::Stage;
use shaping_runtime::sim::{Command, Outcome, Pose, Scene, Sim};

use crate::descriptors::{self, Descriptors};
use crate::error::{Error, ErrorKind};
use shaping_runtime::state::Odometer;

/// What an action of the robot commands: one element each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// A wheel's speed, -1..1 of `v_max` (0 left, 1 right).
    Wheel(usize),
    /// The gripper's arm: above 0.5 down, else up.
    Arm,
    /// The gripper's claw: above 0.5 closed, else open.
    Claw,
    /// Above 0.5: ask the charger to recharge.
    Charge,
    /// A broadcast value, 0..1.
    Signal(usize),
}

impl Control {
    /// The lowest and highest value of the element.
    fn bounds(self) -> (f32, f32) {
        match self {
            Control::Wheel(_) => (-1.0, 1.0),
            _ => (0.0, 1.0),
        }
    }
}

/// The shape of a stage's observations and actions.
#[derive(Clone, Debug, PartialEq)]
pub struct Spaces {
    /// The percept channel of each observation element.
    pub channels: Vec<usize>,
    /// Each observation element's name: `ir[0]`, ..., `battery`.
    pub observation: Vec<String>,
    /// What each action element commands.
    pub controls: Vec<Control>,
    /// Each action element's name: `wheels[0]`, `wheels[1]`, `arm`, `claw`, `charge`.
    pub action: Vec<String>,
}

impl Spaces {
    /// The observation and action elements of `stage`.
    pub fn of(stage: &Stage) -> Spaces {
        let (mut channels, mut observation) = (Vec::new(), Vec::new());
        for s in &stage.sensors {
            for i in 0..s.count {
                channels.push(usize::from(s.channel + i));
                observation.push(if s.count == 1 { s.name.clone() } else { format!("{}[{i}]", s.name) });
            }
        }
        let (mut controls, mut action) = (Vec::new(), Vec::new());
        let mut named = |c: Control, name: String| {
            controls.push(c);
            action.push(name);
        };
        for a in &stage.actuators {
            match a.kind {
                ActuatorKind::Speed => {
                    named(Control::Wheel(0), format!("{}[0]", a.name));
                    named(Control::Wheel(1), format!("{}[1]", a.name));
                }
                ActuatorKind::Lift => named(Control::Arm, a.name.clone()),
                ActuatorKind::Grip => named(Control::Claw, a.name.clone()),
                ActuatorKind::Broadcast => {
                    for k in 0..stage.world.body.rab.as_ref().map_or(1, |r| usize::from(r.signals)) {
                        named(Control::Signal(k), format!("{}[{k}]", a.name));
                    }
                }
            }
        }
        if stage.world.charger.is_some() {
            named(Control::Charge, "charge".to_string());
        }
        Spaces { channels, observation, controls, action }
    }

    /// The lowest and highest value of each action element.
    pub fn action_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        self.controls.iter().map(|c| c.bounds()).unzip()
    }

    /// The command of `action`, or what is wrong with it (its length, an
    /// element outside its bounds or not finite), naming the element.
    pub fn command(&self, action: &[f32]) -> Result<Command, String> {
        if action.len() != self.controls.len() {
            return Err(format!(
                "an action has {} elements ({}), not {}",
                self.controls.len(),
                self.action.join(", "),
                action.len()
            ));
        }
        let mut cmd = Command::default();
        for (i, (&v, &c)) in action.iter().zip(&self.controls).enumerate() {
            let (lo, hi) = c.bounds();
            if !(lo..=hi).contains(&v) {
                return Err(format!("action element {i} (`{}`) is {v}, outside {lo}..{hi}", self.action[i]));
            }
            match c {
                Control::Wheel(w) => cmd.wheels[w] = v,
                Control::Arm => cmd.arm = Some(v > 0.5),
                Control::Claw => cmd.claw = Some(v > 0.5),
                Control::Charge => cmd.charge = v > 0.5,
                Control::Signal(k) => cmd.signal.get_or_insert([0.0; SIGNALS])[k] = v,
            }
        }
        Ok(cmd)
    }
}

/// What one action did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Step {
    /// The stage's fitness for this action.
    pub reward: f32,
    /// The life ended early: the battery is empty.
    pub terminated: bool,
    /// The life reached the stage's length.
    pub truncated: bool,
    /// The events of the action.
    pub outcome: Outcome,
}

/// Refuses a stage whose world has a team (`robots` above 1): an agent
/// drives one robot, and the others would have no controller.
pub fn check(stage: &Stage) -> Result<(), Error> {
    if stage.world.robots > 1 {
        return Err(Error::new(
            ErrorKind::Invalid,
            format!(
                "error: stage `{}` has a team of {} robots, but a stepper drives one robot (one agent, one robot): \
                 step a stage whose world has one robot, or run the team with `shaping run`",
                stage.name, stage.world.robots
            ),
        ));
    }
    Ok(())
}

/// One robot in a stage's world, driven one action at a time.
pub struct Stepper {
    stage: Arc<Stage>,
    spaces: Arc<Spaces>,
    fitness: Option<FastExpr>,
    at_end: Option<FastExpr>,
    reads_state: bool,
    life: u32,
    /// `None` before the first reset.
    sim: Option<Sim>,
    odo: Odometer,
    now: [f32; CHANNELS],
    next: [f32; CHANNELS],
    slots: [f32; ACT_SLOTS],
    actions: u32,
    ended: bool,
    /// The poses of the life so far, when kept ([`Stepper::keep_path`]).
    path: Option<Vec<[f32; 3]>>,
}

impl Stepper {
    /// A robot in `stage`'s world; call [`Stepper::reset`] before the first
    /// step. A team's stage is refused ([`check`]).
    pub fn new(stage: Arc<Stage>) -> Result<Stepper, Error> {
        check(&stage)?;
        let spaces = Arc::new(Spaces::of(&stage));
        Ok(Stepper::with_spaces(stage, spaces))
    }

    fn with_spaces(stage: Arc<Stage>, spaces: Arc<Spaces>) -> Stepper {
        Stepper {
            fitness: stage.fitness.per_action.as_ref().map(FastExpr::new),
            at_end: stage.fitness.at_end.as_ref().map(FastExpr::new),
            reads_state: shaping_runtime::state::reads_state(&stage),
            life: descriptors::actions(&stage),
            stage,
            spaces,
            sim: None,
            odo: Odometer::default(),
            now: [0.0; CHANNELS],
            next: [0.0; CHANNELS],
            slots: [0.0; ACT_SLOTS],
            actions: 0,
            ended: true,
            path: None,
        }
    }

    /// Keeps the poses of each life, for [`Stepper::path`] (pictures).
    pub fn keep_path(&mut self, keep: bool) {
        self.path = keep.then(Vec::new);
    }

    pub fn spaces(&self) -> &Spaces {
        &self.spaces
    }

    pub fn stage(&self) -> &Stage {
        &self.stage
    }

    /// The length of a life, in actions.
    pub fn life(&self) -> u32 {
        self.life
    }

    /// Starts a new life in the world of episode seed `seed` (the world an
    /// evolved individual's episode of that seed is placed in) and writes
    /// the first observation into `obs`.
    pub fn reset(&mut self, seed: u64, obs: &mut [f32]) {
        let mut sim = Sim::new(&self.stage.world, seed);
        sim.sense(&mut self.now);
        self.odo.start(sim.position(), self.life);
        self.sim = Some(sim);
        self.slots = [0.0; ACT_SLOTS];
        self.actions = 0;
        self.ended = false;
        let pose = self.pose();
        if let Some(p) = &mut self.path {
            p.clear();
            p.push([pose.x, pose.y, pose.theta]);
        }
        self.observe(obs);
    }

    fn observe(&self, obs: &mut [f32]) {
        for (o, &c) in obs.iter_mut().zip(&self.spaces.channels) {
            *o = self.now[c].clamp(0.0, 1.0);
        }
    }

    /// Runs `action` (see the module's documentation) and writes the next
    /// observation into `obs`. An action of the wrong length or outside
    /// the bounds, or a step before [`Stepper::reset`] or after the life
    /// ended, is an [`ErrorKind::Invalid`] error and changes nothing.
    pub fn step(&mut self, action: &[f32], obs: &mut [f32]) -> Result<Step, Error> {
        let cmd =
            self.spaces.command(action).map_err(|e| Error::new(ErrorKind::Invalid, format!("error: {e}")))?;
        if self.ended {
            return Err(Error::new(
                ErrorKind::Invalid,
                "error: the life has ended (or not started): reset before the next step",
            ));
        }
        Ok(self.run(&cmd, obs))
    }

    fn run(&mut self, cmd: &Command, obs: &mut [f32]) -> Step {
        let Some(sim) = &mut self.sim else { return Step::default() };
        let outcome = sim.step(cmd);
        self.odo.moved(sim.position());
        record_command(&mut self.slots, cmd);
        sim.sense(&mut self.next);
        let state = if self.reads_state { self.odo.state(sim.pose().theta) } else { Default::default() };
        let env = Env { now: &self.next, prev: &self.now, act: &self.slots, state: &state };
        let mut reward = self.fitness.as_ref().map_or(0.0, |e| e.eval(&env));
        let counts = [
            outcome.grips,
            outcome.releases_outside,
            u32::from(outcome.recharged),
            u32::from(outcome.collided),
        ];
        for points in bonus_points(&self.stage, counts) {
            reward += points;
        }
        let terminated = !sim.alive();
        let truncated = !terminated && self.actions + 1 >= self.life;
        if terminated || truncated {
            if let Some(e) = &self.at_end {
                reward += e.eval(&env);
            }
        }
        self.now = self.next;
        self.actions += 1;
        self.ended = terminated || truncated;
        if let Some(p) = &mut self.path {
            let pose = sim.pose();
            p.push([pose.x, pose.y, pose.theta]);
        }
        self.observe(obs);
        Step { reward, terminated, truncated, outcome }
    }

    /// Actions of the life so far.
    pub fn actions(&self) -> u32 {
        self.actions
    }

    /// The robot's pose now.
    pub fn pose(&self) -> Pose {
        self.sim.as_ref().map(|s| s.pose()).unwrap_or_default()
    }

    /// The battery level now, 0..1.
    pub fn battery(&self) -> f32 {
        self.sim.as_ref().map_or(1.0, |s| s.battery())
    }

    /// How the life so far moved the robot.
    pub fn descriptors(&self) -> Descriptors {
        self.odo.descriptors(self.pose().theta)
    }

    /// The world now (before the first reset: `None`).
    pub fn scene(&self) -> Option<Scene> {
        self.sim.as_ref().map(|s| s.scene())
    }

    /// The poses of the life so far, if kept.
    pub fn path(&self) -> &[[f32; 3]] {
        self.path.as_deref().unwrap_or_default()
    }
}

/// The results of one step of every robot of a [`VecStepper`], one row each.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VecStep {
    /// `n` rows of the observation's length.
    pub observations: Vec<f32>,
    pub rewards: Vec<f32>,
    pub terminated: Vec<bool>,
    pub truncated: Vec<bool>,
}

/// One robot of a [`VecStepper`].
struct Slot {
    env: Stepper,
    /// The robot's stream of episode seeds.
    seeds: ChaCha8Rng,
    /// Its life ended at the last step: it starts a new one at the next.
    pending: bool,
    obs: Vec<f32>,
}

/// Many robots of one stage, each in its own world, stepped together.
pub struct VecStepper {
    spaces: Arc<Spaces>,
    slots: Vec<Slot>,
    started: bool,
}

impl VecStepper {
    /// `n` robots in `stage`'s world; call [`VecStepper::reset`] first. A
    /// team's stage is refused ([`check`]).
    pub fn new(stage: Arc<Stage>, n: usize) -> Result<VecStepper, Error> {
        check(&stage)?;
        let spaces = Arc::new(Spaces::of(&stage));
        let width = spaces.channels.len();
        let slots = (0..n)
            .map(|_| Slot {
                env: Stepper::with_spaces(stage.clone(), spaces.clone()),
                seeds: ChaCha8Rng::seed_from_u64(0),
                pending: false,
                obs: vec![0.0; width],
            })
            .collect();
        Ok(VecStepper { spaces, slots, started: false })
    }

    pub fn len(&self) -> usize {
        self.slots.len()
    }

    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    pub fn spaces(&self) -> &Spaces {
        &self.spaces
    }

    /// Robot `i`.
    pub fn get(&self, i: usize) -> Option<&Stepper> {
        self.slots.get(i).map(|s| &s.env)
    }

    /// Starts a life of every robot: robot `i`'s lives take the episode
    /// seeds of stream `i` of `seed` (the same whatever the threads); the
    /// first observations go to `out.observations`.
    pub fn reset(&mut self, seed: u64, out: &mut VecStep) {
        for (i, slot) in self.slots.iter_mut().enumerate() {
            slot.seeds = ChaCha8Rng::seed_from_u64(seed);
            slot.seeds.set_stream(i as u64);
            slot.pending = false;
            slot.env.reset(slot.seeds.next_u64(), &mut slot.obs);
        }
        self.started = true;
        let n = self.slots.len();
        self.gather(out, vec![Step::default(); n]);
    }

    /// Steps every robot with its row of `actions` (`n` rows of the
    /// action's length), in parallel on the current rayon pool. A robot
    /// whose life ended at the previous step starts a new one instead: its
    /// row of `actions` is ignored, its reward is 0 and it is neither
    /// terminated nor truncated (Gymnasium's "next step" autoreset). A
    /// malformed action is an [`ErrorKind::Invalid`] error naming its row,
    /// and no robot moves.
    pub fn step(&mut self, actions: &[f32], out: &mut VecStep) -> Result<(), Error> {
        let (n, dims) = (self.slots.len(), self.spaces.controls.len());
        if actions.len() != n * dims {
            return Err(Error::new(
                ErrorKind::Invalid,
                format!(
                    "error: the actions must be {n} rows of {dims} ({}), not {} values",
                    self.spaces.action.join(", "),
                    actions.len()
                ),
            ));
        }
        if !self.started {
            return Err(Error::new(ErrorKind::Invalid, "error: reset before the first step"));
        }
        let commands = (0..n)
            .map(|i| {
                self.spaces.command(&actions[i * dims..(i + 1) * dims]).map_err(|e| {
                    Error::new(ErrorKind::Invalid, format!("error: row {i} of the actions: {e}"))
                })
            })
            .collect::<Result<Vec<Command>, Error>>()?;
        let steps = self
            .slots
            .par_iter_mut()
            .zip(commands.par_iter())
            .with_min_len(32)
            .map(|(slot, cmd)| {
                if slot.pending {
                    slot.pending = false;
                    slot.env.reset(slot.seeds.next_u64(), &mut slot.obs);
                    Step::default()
                } else {
                    let s = slot.env.run(cmd, &mut slot.obs);
                    slot.pending = s.terminated || s.truncated;
                    s
                }
            })
            .collect();
        self.gather(out, steps);
        Ok(())
    }

    fn gather(&self, out: &mut VecStep, steps: Vec<Step>) {
        out.observations.clear();
        for slot in &self.slots {
            out.observations.extend_from_slice(&slot.obs);
        }
        out.rewards = steps.iter().map(|s| s.reward).collect();
        out.terminated = steps.iter().map(|s| s.terminated).collect();
        out.truncated = steps.iter().map(|s| s.truncated).collect();
    }
}
