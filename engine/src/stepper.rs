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
//! threads of the caller's rayon pool in one call (called outside a pool,
//! on the calling thread alone), each resetting itself on the step after
//! its life ended. Both are deterministic by seed.

use std::sync::Arc;

use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use shaping_runtime::catalog::{ActuatorKind, ACT_SLOTS, CHANNELS, SIGNALS};
use shaping_runtime::controller::{fitness_bonus_points, record_command, FastExpr, FAR};
use shaping_runtime::expr::Env;
use shaping_runtime::program::{Stage, World};
use shaping_runtime::sim::{Command, Outcome, Pose, Scene, Sim, Team};
use shaping_runtime::state::{
    Odometer, TeamReads, STATE_SLOTS, ST_SPREAD, ST_TARGETS, TEAM_OF_ONE, TEAM_SLOTS,
};
use shaping_runtime::world::Place;

use crate::descriptors::{self, Descriptors};
use crate::error::{Error, ErrorKind};
use crate::{plot, report};

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
    if stage.robots() > 1 {
        return Err(Error::new(
            ErrorKind::Invalid,
            format!(
                "error: stage `{}` has a team of {} robots, but a stepper drives one robot (one agent, one robot): \
                 step the team with `shaping.gym.make_parallel` (one agent per robot), run it with `shaping run`, \
                 or step a stage whose world has one robot",
                stage.name,
                stage.robots()
            ),
        ));
    }
    Ok(())
}

/// Refuses a stage whose world has one robot: a team stepper drives a team.
pub fn check_team(stage: &Stage) -> Result<(), Error> {
    if stage.robots() <= 1 {
        return Err(Error::new(
            ErrorKind::Invalid,
            format!(
                "error: stage `{}` has one robot, but a team stepper drives a team (`robots N` in the stage's `world`): \
                 step one robot with `shaping.gym.make` (`Stepper`)",
                stage.name
            ),
        ));
    }
    Ok(())
}

/// The bodies of a life driven from outside: one robot's simulator or a
/// team's, decided here and nowhere else (as `episode_with` decides a
/// run's). One robot reads the team state of a team of one.
enum Bodies {
    Solo(Box<Sim>),
    Team(Box<Team>),
}

impl Bodies {
    fn new(world: &World, seed: u64) -> Bodies {
        if world.robots > 1 {
            Bodies::Team(Box::new(Team::new(world, seed)))
        } else {
            Bodies::Solo(Box::new(Sim::new(world, seed)))
        }
    }

    fn sim(&self, i: usize) -> &Sim {
        match self {
            Bodies::Solo(s) => s,
            Bodies::Team(t) => t.sim(i),
        }
    }

    fn begin_action(&mut self) {
        if let Bodies::Team(t) = self {
            t.begin_action();
        }
    }

    fn prepare(&mut self, i: usize) {
        if let Bodies::Team(t) = self {
            t.prepare(i);
        }
    }

    fn end_action(&mut self) {
        if let Bodies::Team(t) = self {
            t.end_action();
        }
    }

    fn step(&mut self, i: usize, cmd: &Command) -> Outcome {
        match self {
            Bodies::Solo(s) => s.step(cmd),
            Bodies::Team(t) => t.step(i, cmd),
        }
    }

    fn sense(&mut self, i: usize, out: &mut [f32; CHANNELS]) {
        match self {
            Bodies::Solo(s) => s.sense(out),
            Bodies::Team(t) => t.sense(i, out),
        }
    }

    fn state(&mut self, reads: TeamReads) -> [f32; TEAM_SLOTS] {
        match self {
            Bodies::Solo(_) => TEAM_OF_ONE,
            Bodies::Team(t) => t.state(reads),
        }
    }

    /// The world now, every robot drawn: robot 0's scene and the others' poses.
    fn scene(&self) -> Scene {
        self.sim(0).scene()
    }
}

/// One robot of a life: what its expressions read and what it did.
struct Member {
    role: usize,
    odo: Odometer,
    now: [f32; CHANNELS],
    next: [f32; CHANNELS],
    slots: [f32; ACT_SLOTS],
    state: [f32; STATE_SLOTS],
    ended: bool,
    /// The poses of the life so far, when kept.
    path: Option<Vec<[f32; 3]>>,
}

/// A role's fitness terms, compiled once.
struct Terms {
    per_action: Option<FastExpr>,
    at_end: Option<FastExpr>,
}

/// The world and the robots of one stage's lives, driven one action at a
/// time: the one loop of a [`Stepper`] (one robot) and of a
/// [`TeamStepper`] (each robot in turn senses what its last action left and
/// moves, seeing the others where they are, as in a run).
struct Lives {
    stage: Arc<Stage>,
    spaces: Arc<Spaces>,
    /// Each role's terms (one without roles).
    terms: Vec<Terms>,
    reads_state: bool,
    reads: TeamReads,
    targets: Vec<Option<Place>>,
    life: u32,
    /// `None` before the first reset.
    bodies: Option<Bodies>,
    members: Vec<Member>,
    /// The team's state after the last action.
    team: [f32; TEAM_SLOTS],
    actions: u32,
}

impl Lives {
    fn new(stage: Arc<Stage>, spaces: Arc<Spaces>) -> Lives {
        let terms = (0..stage.roles.len().max(1))
            .map(|r| {
                let f = stage.role_fitness(r);
                Terms {
                    per_action: f.per_action.as_ref().map(FastExpr::new),
                    at_end: f.at_end.as_ref().map(FastExpr::new),
                }
            })
            .collect();
        let members = (0..stage.world.robots.max(1) as usize)
            .map(|i| Member {
                role: stage.role_of(i),
                odo: Odometer::default(),
                now: [0.0; CHANNELS],
                next: [0.0; CHANNELS],
                slots: [0.0; ACT_SLOTS],
                state: [0.0; STATE_SLOTS],
                ended: true,
                path: None,
            })
            .collect();
        Lives {
            terms,
            reads_state: shaping_runtime::state::reads_state(&stage),
            reads: TeamReads::of(&stage),
            targets: stage.targets.iter().map(|t| Place::of(&stage.world, t)).collect(),
            life: descriptors::actions(&stage),
            stage,
            spaces,
            bodies: None,
            members,
            team: TEAM_OF_ONE,
            actions: 0,
        }
    }

    fn keep_path(&mut self, keep: bool) {
        for m in &mut self.members {
            m.path = keep.then(Vec::new);
        }
    }

    /// Starts a life in the world of episode seed `seed`; robot `i`'s first
    /// observation goes to row `i` of `obs`.
    fn reset(&mut self, seed: u64, obs: &mut [f32]) {
        let mut bodies = Bodies::new(&self.stage.world, seed);
        self.team = bodies.state(self.reads);
        for (i, m) in self.members.iter_mut().enumerate() {
            bodies.prepare(i);
            let sim = bodies.sim(i);
            m.odo.start(sim.position(), self.life);
            let pose = sim.pose();
            bodies.sense(i, &mut m.now);
            m.slots = [0.0; ACT_SLOTS];
            m.ended = false;
            if let Some(p) = &mut m.path {
                p.clear();
                p.push([pose.x, pose.y, pose.theta]);
            }
        }
        self.bodies = Some(bodies);
        self.actions = 0;
        self.observe(obs);
    }

    fn observe(&self, obs: &mut [f32]) {
        let width = self.spaces.channels.len();
        for (m, row) in self.members.iter().zip(obs.chunks_mut(width.max(1))) {
            for (o, &c) in row.iter_mut().zip(&self.spaces.channels) {
                *o = m.now[c].clamp(0.0, 1.0);
            }
        }
    }

    /// Robot `i`'s state as its expressions read it (zeros where the stage
    /// reads none).
    fn fill_state(
        reads_state: bool,
        targets: &[Option<Place>],
        team: &[f32; TEAM_SLOTS],
        m: &mut Member,
        sim: &Sim,
    ) {
        if reads_state {
            m.state = m.odo.state(sim.pose().theta);
            let at = sim.position();
            for (slot, place) in m.state[ST_TARGETS..].iter_mut().zip(targets) {
                *slot = place.map_or(FAR, |p| p.distance(at));
            }
            m.state[ST_SPREAD..ST_SPREAD + TEAM_SLOTS].copy_from_slice(team);
        }
    }

    /// Runs one action: robot `i` (in turn, those whose life has not
    /// ended) does `cmds[i]`; its step goes to `steps[i]` (a robot whose
    /// life had ended gets a default step) and its observation to row `i`
    /// of `obs`. Each reward is the robot's own fitness for the action
    /// (its role's terms and bonuses), and its `at end` term when its life
    /// ends, read after every robot acted (the team's state of the action).
    fn run(&mut self, cmds: &[Command], obs: &mut [f32], steps: &mut [Step]) {
        let Some(bodies) = &mut self.bodies else { return };
        bodies.begin_action();
        let last = self.actions + 1 >= self.life;
        for (i, ((m, cmd), step)) in self.members.iter_mut().zip(cmds).zip(steps.iter_mut()).enumerate() {
            *step = Step::default();
            if m.ended {
                continue;
            }
            bodies.prepare(i);
            let outcome = bodies.step(i, cmd);
            m.odo.moved(bodies.sim(i).position());
            record_command(&mut m.slots, cmd);
            bodies.sense(i, &mut m.next);
            let terms = &self.terms[m.role.min(self.terms.len() - 1)];
            // The state only where a term reads it now: a role without a
            // per-action term reads it at the end of its life (below).
            let mut reward = 0.0;
            if let Some(e) = &terms.per_action {
                Lives::fill_state(self.reads_state, &self.targets, &self.team, m, bodies.sim(i));
                reward = e.eval(&Env { now: &m.next, prev: &m.now, act: &m.slots, state: &m.state });
            }
            let counts = [
                outcome.grips,
                outcome.releases_outside,
                u32::from(outcome.recharged),
                u32::from(outcome.collided),
            ];
            for points in fitness_bonus_points(self.stage.role_fitness(m.role), counts) {
                reward += points;
            }
            let terminated = !bodies.sim(i).alive();
            *step = Step { reward, terminated, truncated: !terminated && last, outcome };
        }
        bodies.end_action();
        // The team's state: for the next action's per-action terms, or for
        // the `at end` terms of the robots whose life ends now.
        let ending = steps.iter().any(|s| s.terminated || s.truncated);
        if matches!(bodies, Bodies::Team(_)) && (ending || self.terms.iter().any(|t| t.per_action.is_some()))
        {
            self.team = bodies.state(self.reads);
        }
        for (i, (m, step)) in self.members.iter_mut().zip(steps.iter_mut()).enumerate() {
            if m.ended {
                continue;
            }
            if step.terminated || step.truncated {
                let terms = &self.terms[m.role.min(self.terms.len() - 1)];
                if terms.per_action.is_none() {
                    // Where the robot ended its action (it has not moved since).
                    Lives::fill_state(self.reads_state, &self.targets, &self.team, m, bodies.sim(i));
                } else if self.reads_state {
                    m.state[ST_SPREAD..ST_SPREAD + TEAM_SLOTS].copy_from_slice(&self.team);
                }
                if let Some(e) = &terms.at_end {
                    let env = Env { now: &m.next, prev: &m.now, act: &m.slots, state: &m.state };
                    step.reward += e.eval(&env);
                }
                m.ended = true;
            }
            m.now = m.next;
            if let Some(p) = &mut m.path {
                let pose = bodies.sim(i).pose();
                p.push([pose.x, pose.y, pose.theta]);
            }
        }
        self.actions += 1;
        self.observe(obs);
    }

    fn picture(&self) -> Option<plot::TrajectoryScene> {
        let bodies = self.bodies.as_ref()?;
        let mut paths = self.members.iter().map(|m| m.path.clone().unwrap_or_default());
        let mut picture = report::picture(&bodies.scene(), paths.next().unwrap_or_default());
        picture.others = paths.collect();
        picture.roles = self.stage.roles.iter().map(|r| (r.name.clone(), r.robots)).collect();
        Some(picture)
    }
}

/// One robot in a stage's world, driven one action at a time.
pub struct Stepper {
    lives: Lives,
    step: [Step; 1],
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
        Stepper { lives: Lives::new(stage, spaces), step: [Step::default()] }
    }

    /// Keeps the poses of each life, for [`Stepper::path`] (pictures).
    pub fn keep_path(&mut self, keep: bool) {
        self.lives.keep_path(keep);
    }

    pub fn spaces(&self) -> &Spaces {
        &self.lives.spaces
    }

    pub fn stage(&self) -> &Stage {
        &self.lives.stage
    }

    /// The length of a life, in actions.
    pub fn life(&self) -> u32 {
        self.lives.life
    }

    /// Starts a new life in the world of episode seed `seed` (the world an
    /// evolved individual's episode of that seed is placed in) and writes
    /// the first observation into `obs`.
    pub fn reset(&mut self, seed: u64, obs: &mut [f32]) {
        self.lives.reset(seed, obs);
    }

    /// Runs `action` (see the module's documentation) and writes the next
    /// observation into `obs`. An action of the wrong length or outside
    /// the bounds, or a step before [`Stepper::reset`] or after the life
    /// ended, is an [`ErrorKind::Invalid`] error and changes nothing.
    pub fn step(&mut self, action: &[f32], obs: &mut [f32]) -> Result<Step, Error> {
        let cmd = self
            .lives
            .spaces
            .command(action)
            .map_err(|e| Error::new(ErrorKind::Invalid, format!("error: {e}")))?;
        if self.ended() {
            return Err(Error::new(
                ErrorKind::Invalid,
                "error: the life has ended (or not started): reset before the next step",
            ));
        }
        Ok(self.run(&cmd, obs))
    }

    fn ended(&self) -> bool {
        self.lives.bodies.is_none() || self.lives.members[0].ended
    }

    fn run(&mut self, cmd: &Command, obs: &mut [f32]) -> Step {
        self.lives.run(std::slice::from_ref(cmd), obs, &mut self.step);
        self.step[0]
    }

    /// Actions of the life so far.
    pub fn actions(&self) -> u32 {
        self.lives.actions
    }

    /// The robot's pose now.
    pub fn pose(&self) -> Pose {
        self.lives.bodies.as_ref().map(|b| b.sim(0).pose()).unwrap_or_default()
    }

    /// The battery level now, 0..1.
    pub fn battery(&self) -> f32 {
        self.lives.bodies.as_ref().map_or(1.0, |b| b.sim(0).battery())
    }

    /// How the life so far moved the robot.
    pub fn descriptors(&self) -> Descriptors {
        self.lives.members[0].odo.descriptors(self.pose().theta)
    }

    /// The world now (before the first reset: `None`).
    pub fn scene(&self) -> Option<Scene> {
        self.lives.bodies.as_ref().map(|b| b.scene())
    }

    /// The poses of the life so far, if kept.
    pub fn path(&self) -> &[[f32; 3]] {
        self.lives.members[0].path.as_deref().unwrap_or_default()
    }

    /// A picture of the world now and the path of the life so far
    /// (before the first reset: `None`).
    pub fn picture(&self) -> Option<plot::TrajectoryScene> {
        self.lives.picture()
    }
}

/// A stage's team in its world, driven one action at a time: one agent per
/// robot, each with the stage's observation and action spaces (every role
/// has the robot's hardware). Robot `i`'s life ends when its battery is
/// empty (`terminated`) or at the stage's length of life (`truncated`);
/// the others go on. A robot's rewards add up to its own fitness (its
/// role's terms); the team's fitness is their aggregate (`team sum`,
/// `mean` or `min`), as a run gives it, except that the `at end` term of a
/// robot whose battery ran out is read when it ran out.
pub struct TeamStepper {
    lives: Lives,
    names: Vec<String>,
    commands: Vec<Command>,
    steps: Vec<Step>,
}

impl TeamStepper {
    /// The team of `stage`'s world; call [`TeamStepper::reset`] before the
    /// first step. A stage with one robot is refused ([`check_team`]).
    pub fn new(stage: Arc<Stage>) -> Result<TeamStepper, Error> {
        check_team(&stage)?;
        let spaces = Arc::new(Spaces::of(&stage));
        Ok(TeamStepper::with_spaces(stage, spaces))
    }

    fn with_spaces(stage: Arc<Stage>, spaces: Arc<Spaces>) -> TeamStepper {
        let lives = Lives::new(stage, spaces);
        let n = lives.members.len();
        TeamStepper {
            names: agent_names(&lives.stage),
            lives,
            commands: vec![Command::default(); n],
            steps: vec![Step::default(); n],
        }
    }

    /// Keeps the poses of each life, for [`TeamStepper::picture`].
    pub fn keep_path(&mut self, keep: bool) {
        self.lives.keep_path(keep);
    }

    pub fn spaces(&self) -> &Spaces {
        &self.lives.spaces
    }

    pub fn stage(&self) -> &Stage {
        &self.lives.stage
    }

    /// The number of robots.
    pub fn robots(&self) -> usize {
        self.lives.members.len()
    }

    /// Each robot's agent name ([`agent_names`]).
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The length of a life, in actions.
    pub fn life(&self) -> u32 {
        self.lives.life
    }

    /// Actions of the life so far.
    pub fn actions(&self) -> u32 {
        self.lives.actions
    }

    /// Whether robot `i`'s life has ended (or not started).
    pub fn ended(&self, i: usize) -> bool {
        self.lives.bodies.is_none() || self.lives.members.get(i).is_none_or(|m| m.ended)
    }

    /// Starts a new life of the team in the world of episode seed `seed`
    /// (the world a run's episode of that seed places the team in); robot
    /// `i`'s first observation goes to row `i` of `obs` (robots rows of
    /// the observation's length).
    pub fn reset(&mut self, seed: u64, obs: &mut [f32]) {
        self.lives.reset(seed, obs);
    }

    /// Runs one action of the team: robot `i` does row `i` of `actions`
    /// (robots rows of the action's length; the rows of robots whose life
    /// has ended are ignored). Each robot's next observation goes to its row
    /// of `obs`; its step is `steps()[i]`. A malformed row of a robot
    /// whose life goes on is an [`ErrorKind::Invalid`] error naming the
    /// robot's agent and the element, and no robot moves; so is a step
    /// once every life has ended, or before the first reset.
    pub fn step(&mut self, actions: &[f32], obs: &mut [f32]) -> Result<&[Step], Error> {
        let (n, dims) = (self.robots(), self.lives.spaces.controls.len());
        if actions.len() != n * dims {
            return Err(Error::new(
                ErrorKind::Invalid,
                format!(
                    "error: the actions must be {n} rows (one per robot) of {dims} ({}), not {} values",
                    self.lives.spaces.action.join(", "),
                    actions.len()
                ),
            ));
        }
        if (0..n).all(|i| self.ended(i)) {
            return Err(Error::new(
                ErrorKind::Invalid,
                "error: the team's life has ended (or not started): reset before the next step",
            ));
        }
        for i in 0..n {
            if self.ended(i) {
                self.commands[i] = Command::default();
                continue;
            }
            self.commands[i] =
                self.lives.spaces.command(&actions[i * dims..(i + 1) * dims]).map_err(|e| {
                    Error::new(
                        ErrorKind::Invalid,
                        format!("error: the action of `{}` (robot {i}): {e}", self.names[i]),
                    )
                })?;
        }
        self.lives.run(&self.commands, obs, &mut self.steps);
        Ok(&self.steps)
    }

    /// The steps of the last action, robot by robot.
    pub fn steps(&self) -> &[Step] {
        &self.steps
    }

    /// Robot `i`'s pose now.
    pub fn pose(&self, i: usize) -> Pose {
        self.lives.bodies.as_ref().filter(|_| i < self.robots()).map(|b| b.sim(i).pose()).unwrap_or_default()
    }

    /// Robot `i`'s battery level now, 0..1.
    pub fn battery(&self, i: usize) -> f32 {
        self.lives.bodies.as_ref().filter(|_| i < self.robots()).map_or(1.0, |b| b.sim(i).battery())
    }

    /// How the life so far moved robot `i`.
    pub fn descriptors(&self, i: usize) -> Descriptors {
        self.lives.members.get(i).map(|m| m.odo.descriptors(self.pose(i).theta)).unwrap_or_default()
    }

    /// The team's state now: `[team.spread, team.grouped, team.largest,
    /// team.nearest, team.order, team.connected]`, those the stage does not
    /// read left as for a team of one.
    pub fn team_state(&self) -> [f32; TEAM_SLOTS] {
        self.lives.team
    }

    /// A picture of the world now, every robot's path of the life so far
    /// when kept (before the first reset: `None`).
    pub fn picture(&self) -> Option<plot::TrajectoryScene> {
        self.lives.picture()
    }
}

/// Each robot's agent name: its role's name and its index among the
/// role's robots (`guard_0`, `guard_1`, `scout_0`, ...), or `robot_i`
/// in a team without roles.
pub fn agent_names(stage: &Stage) -> Vec<String> {
    let n = stage.world.robots.max(1) as usize;
    if stage.roles.is_empty() {
        return (0..n).map(|i| format!("robot_{i}")).collect();
    }
    let mut seen = vec![0usize; stage.roles.len()];
    (0..n)
        .map(|i| {
            let r = stage.role_of(i);
            let k = seen[r];
            seen[r] += 1;
            format!("{}_{k}", stage.roles[r].name)
        })
        .collect()
}

/// The results of one step of every robot of a [`VecStepper`] (one row
/// each) or of a [`VecTeamStepper`] (one row per robot, world after world).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VecStep {
    /// A row of the observation's length per robot.
    pub observations: Vec<f32>,
    pub rewards: Vec<f32>,
    pub terminated: Vec<bool>,
    pub truncated: Vec<bool>,
}

/// What a batch steps: one robot's lives ([`Stepper`]) or a team's
/// ([`TeamStepper`]), both the one loop [`Lives`].
trait Lived: Send {
    fn lives(&self) -> &Lives;
    fn lives_mut(&mut self) -> &mut Lives;
}

impl Lived for Stepper {
    fn lives(&self) -> &Lives {
        &self.lives
    }
    fn lives_mut(&mut self) -> &mut Lives {
        &mut self.lives
    }
}

impl Lived for TeamStepper {
    fn lives(&self) -> &Lives {
        &self.lives
    }
    fn lives_mut(&mut self) -> &mut Lives {
        &mut self.lives
    }
}

/// One world of a batch.
struct Slot<E> {
    env: E,
    /// The world's stream of episode seeds.
    seeds: ChaCha8Rng,
    /// Its life ended at the last step: it starts a new one at the next.
    pending: bool,
    obs: Vec<f32>,
    cmds: Vec<Command>,
    steps: Vec<Step>,
}

/// Worlds of one stage stepped together on the caller's rayon pool, each
/// starting a new life on the step after its life ended (every robot's).
struct Batch<E> {
    spaces: Arc<Spaces>,
    slots: Vec<Slot<E>>,
    /// Robots per world.
    robots: usize,
    started: bool,
}

impl<E: Lived> Batch<E> {
    fn new(spaces: Arc<Spaces>, envs: Vec<E>) -> Batch<E> {
        let robots = envs.first().map_or(1, |e| e.lives().members.len());
        let width = spaces.channels.len();
        let slots = envs
            .into_iter()
            .map(|env| Slot {
                env,
                seeds: ChaCha8Rng::seed_from_u64(0),
                pending: false,
                obs: vec![0.0; width * robots],
                cmds: vec![Command::default(); robots],
                steps: vec![Step::default(); robots],
            })
            .collect();
        Batch { spaces, slots, robots, started: false }
    }

    fn reset(&mut self, seed: u64, out: &mut VecStep) {
        for (i, slot) in self.slots.iter_mut().enumerate() {
            slot.seeds = ChaCha8Rng::seed_from_u64(seed);
            slot.seeds.set_stream(i as u64);
            slot.pending = false;
            slot.env.lives_mut().reset(slot.seeds.next_u64(), &mut slot.obs);
            slot.steps.fill(Step::default());
        }
        self.started = true;
        self.gather(out);
    }

    /// `actions`: a row per robot, world after world; the rows of robots
    /// whose life has ended, or of a world that starts again, are ignored.
    /// A malformed row is an error `what(world, robot, message)` says, and
    /// no robot moves.
    fn step(
        &mut self,
        actions: &[f32],
        out: &mut VecStep,
        what: impl Fn(usize, usize, &str) -> String,
    ) -> Result<(), Error> {
        let (n, dims) = (self.slots.len() * self.robots, self.spaces.controls.len());
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
        let spaces = &self.spaces;
        for (w, slot) in self.slots.iter_mut().enumerate() {
            for (i, cmd) in slot.cmds.iter_mut().enumerate() {
                let row = (w * self.robots + i) * dims;
                *cmd = if slot.pending || slot.env.lives().members[i].ended {
                    Command::default()
                } else {
                    spaces
                        .command(&actions[row..row + dims])
                        .map_err(|e| Error::new(ErrorKind::Invalid, what(w, i, &e)))?
                };
            }
        }
        let one = |slot: &mut Slot<E>| {
            if slot.pending {
                slot.pending = false;
                slot.env.lives_mut().reset(slot.seeds.next_u64(), &mut slot.obs);
                slot.steps.fill(Step::default());
            } else {
                let lives = slot.env.lives_mut();
                lives.run(&slot.cmds, &mut slot.obs, &mut slot.steps);
                slot.pending = lives.members.iter().all(|m| m.ended);
            }
        };
        // Outside a rayon pool, or with one world, on the calling thread:
        // rayon would hand the work to a pool thread and wait for it.
        if rayon::current_thread_index().is_some() && self.slots.len() > 1 {
            self.slots.par_iter_mut().with_min_len(32usize.div_ceil(self.robots)).for_each(one);
        } else {
            self.slots.iter_mut().for_each(one);
        }
        self.gather(out);
        Ok(())
    }

    fn gather(&self, out: &mut VecStep) {
        out.observations.clear();
        out.rewards.clear();
        out.terminated.clear();
        out.truncated.clear();
        for slot in &self.slots {
            out.observations.extend_from_slice(&slot.obs);
            out.rewards.extend(slot.steps.iter().map(|s| s.reward));
            out.terminated.extend(slot.steps.iter().map(|s| s.terminated));
            out.truncated.extend(slot.steps.iter().map(|s| s.truncated));
        }
    }
}

/// Many robots of one stage, each in its own world, stepped together.
pub struct VecStepper {
    batch: Batch<Stepper>,
}

impl VecStepper {
    /// `n` robots in `stage`'s world; call [`VecStepper::reset`] first. A
    /// team's stage is refused ([`check`]).
    pub fn new(stage: Arc<Stage>, n: usize) -> Result<VecStepper, Error> {
        check(&stage)?;
        let spaces = Arc::new(Spaces::of(&stage));
        let envs = (0..n).map(|_| Stepper::with_spaces(stage.clone(), spaces.clone())).collect();
        Ok(VecStepper { batch: Batch::new(spaces, envs) })
    }

    pub fn len(&self) -> usize {
        self.batch.slots.len()
    }

    pub fn is_empty(&self) -> bool {
        self.batch.slots.is_empty()
    }

    pub fn spaces(&self) -> &Spaces {
        &self.batch.spaces
    }

    /// Robot `i`.
    pub fn get(&self, i: usize) -> Option<&Stepper> {
        self.batch.slots.get(i).map(|s| &s.env)
    }

    /// Starts a life of every robot: robot `i`'s lives take the episode
    /// seeds of stream `i` of `seed` (the same whatever the threads); the
    /// first observations go to `out.observations`.
    pub fn reset(&mut self, seed: u64, out: &mut VecStep) {
        self.batch.reset(seed, out);
    }

    /// Steps every robot with its row of `actions` (`n` rows of the
    /// action's length), in parallel on the current rayon pool (outside
    /// one, on this thread). A robot whose life ended at the previous step
    /// starts a new one instead: its row of `actions` is ignored, its
    /// reward is 0 and it is neither terminated nor truncated (Gymnasium's
    /// "next step" autoreset). A malformed action is an
    /// [`ErrorKind::Invalid`] error naming its row, and no robot moves.
    pub fn step(&mut self, actions: &[f32], out: &mut VecStep) -> Result<(), Error> {
        self.batch.step(actions, out, |w, _, e| format!("error: row {w} of the actions: {e}"))
    }
}

/// Many worlds of one stage's team, stepped together in one call (batched
/// training): world `w`'s robot `i` is row `w * robots + i` of the
/// observations, actions, rewards and ends. A world whose team's life
/// ended (every robot's) starts a new one on the next step: its rows of
/// actions are ignored, its rewards are 0 and its robots are neither
/// terminated nor truncated. Within a life, the row of a robot whose life
/// ended is ignored and its reward is 0.
pub struct VecTeamStepper {
    batch: Batch<TeamStepper>,
    names: Vec<String>,
}

impl VecTeamStepper {
    /// `n` worlds of `stage`'s team; call [`VecTeamStepper::reset`] first.
    /// A stage with one robot is refused ([`check_team`]).
    pub fn new(stage: Arc<Stage>, n: usize) -> Result<VecTeamStepper, Error> {
        check_team(&stage)?;
        let spaces = Arc::new(Spaces::of(&stage));
        let envs = (0..n).map(|_| TeamStepper::with_spaces(stage.clone(), spaces.clone())).collect();
        Ok(VecTeamStepper { names: agent_names(&stage), batch: Batch::new(spaces, envs) })
    }

    /// The number of worlds.
    pub fn len(&self) -> usize {
        self.batch.slots.len()
    }

    pub fn is_empty(&self) -> bool {
        self.batch.slots.is_empty()
    }

    /// Robots per world.
    pub fn robots(&self) -> usize {
        self.batch.robots
    }

    /// Each robot's agent name in a world ([`agent_names`]).
    pub fn names(&self) -> &[String] {
        &self.names
    }

    pub fn spaces(&self) -> &Spaces {
        &self.batch.spaces
    }

    /// World `w`.
    pub fn get(&self, w: usize) -> Option<&TeamStepper> {
        self.batch.slots.get(w).map(|s| &s.env)
    }

    /// Starts a life of every world: world `w`'s lives take the episode
    /// seeds of stream `w` of `seed`.
    pub fn reset(&mut self, seed: u64, out: &mut VecStep) {
        self.batch.reset(seed, out);
    }

    /// Steps every world with its robots' rows of `actions`, the worlds in
    /// parallel on the current rayon pool (outside one, on this thread). A
    /// malformed row (of a robot whose life goes on) is an
    /// [`ErrorKind::Invalid`] error naming the world, the agent and the
    /// element, and no robot moves.
    pub fn step(&mut self, actions: &[f32], out: &mut VecStep) -> Result<(), Error> {
        let names = &self.names;
        self.batch.step(actions, out, |w, i, e| {
            format!("error: world {w}, the action of `{}` (robot {i}): {e}", names[i])
        })
    }
}
