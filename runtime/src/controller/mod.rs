//! The controller: modules, winner-take-all arbitration, behavior generators,
//! CRBP and the episode runner.
//!
//! # One action
//!
//! 1. The percept `now` is the one sensed after the previous action (at the
//!    first action: sensed at the start of the episode).
//! 2. Every module's activation network runs on its input channels of `now`;
//!    the sum over its incoming links of `weight * activation of the source
//!    module at the previous action` is added to the output neuron's net
//!    input (all activations are 0 before the first action).
//! 3. Winner take all: the highest activation wins (compared on the net
//!    input, so modules whose sigmoid saturates at 1.0 still differ); ties go
//!    to the module declared first. Exception: a `commit` script that has
//!    started keeps its module in control until its last step has ended.
//! 4. The winner's behavior generator gives the motor command: a script (see
//!    [`script`] for its semantics: it keeps its position while its module
//!    keeps winning and restarts when another module has won in between) or a
//!    neural network whose outputs are read as bits (sampled with probability
//!    = output while the module learns, else `output > 0.5`) and decoded.
//! 5. The command is executed (`Sim::step`) and the percept after the action
//!    is sensed.
//! 6. Expressions evaluated after the action (reinforcement programs, `until`
//!    conditions, the per-action fitness) read `now` = the percept after the
//!    action, `prev` = the percept before it (the one the decision used), and
//!    the actuator slots = the command executed in this action (left and right
//!    wheel speeds, arm 1 = down, claw 1 = closed; an arm or claw the command
//!    leaves alone keeps its previous state). So `sign(max(prev ir) - max(ir))`
//!    compares before and after the move, and
//!    `abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir))` scores the commanded
//!    speeds with the IR after the move.
//! 7. The winner's reinforcement (its reinforcement program after the action,
//!    or a `reinforce` step its script ran during this action) is pushed to its
//!    performance indicator and, if the module was learning at the start of
//!    the action, trains the network by CRBP (see [`Learning`]).
//!
//! The episode ends after `EpisodeOptions::actions` actions or as soon as the
//! simulated battery is empty (`!Sim::alive()`, checked before each action).
//!
//! # CRBP
//!
//! Complementary reinforcement back-propagation (Ackley & Littman 1990): on a
//! reward, one delta-rule step (rate `rate_reward`) moves the outputs of the
//! last forward pass toward the bits that were acted on; on a punishment, one
//! step (rate `rate_punish`) toward their complement.
//! - On a neural behavior the bits are the sampled output bits.
//! - On an activation network the "bit" is "this module won and acted" (1):
//!   a reward pushes the activation up for the input pattern of the decision
//!   it judges, a punishment pushes it down. With a scripted behavior that
//!   decision is the action whose arbitration started the current run of the
//!   script (its first step): a `reinforce` step late in a script, after the
//!   robot has moved and lowered its arm, still trains the pattern the module
//!   chose to act on. Otherwise it is the action in which the reinforcement
//!   was delivered. The link term (of that action) stays part of the net
//!   input but link weights are not learned.
//!
//! Learning is on when `EpisodeOptions::learning` is set, the module declares
//! a [`Learning`], and either it learns `Always` or its performance indicator
//! (rolling mean of its last `window` non-zero reinforcements; 0 before any;
//! a module with a reinforcement program but no learning uses a window of 30)
//! is below the threshold at the start of the action.
//!
//! # Entry points
//!
//! [`run_episode`] (the contract used by the GA and the CLI) builds a
//! [`Controller`] and a [`Sim`] from the episode seed ([`episode_rngs`]) and
//! runs them on a stage that passed [`crate::validate`] (the controller
//! trusts it). [`validate`] checks a stage of unknown origin and a genome;
//! [`try_run_episode`] validates first and reports what is wrong. [`Controller::act`] runs one
//! action on anything implementing [`Robot`] (the simulator, or a test's
//! hand-driven robot).
//!
//! Initial weights: `Param::Gene` decoded from the genome, `Param::Fixed`,
//! `Param::Random` drawn from the controller's RNG when it is built (module
//! by module in declaration order: activation network, behavior network; then
//! links). Learned weights are thrown away at the end of the episode
//! (Darwinian) unless the stage is `Lamarckian`: then the learned activation
//! weights that are (unfrozen) genes are written back into
//! [`EpisodeResult::learned`].

mod block;
mod fast_expr;
mod life;
mod net;
mod perf;
pub mod script;
mod team;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::catalog::{ACT_ARM, ACT_CLAW, ACT_LEFT, ACT_RIGHT, ACT_SIGNAL, ACT_SLOTS, CHANNELS, SIGNALS};
use crate::expr::Env;
use crate::genome::Genome;
use crate::program::{Behavior, Decode, Event, LearnTarget, LearnWhen, Learning, Param, Stage};
use crate::sim::{Command, Outcome, Pose, Sim};
use crate::state::{Descriptors, Odometer, STATE_SLOTS, ST_SPREAD, TEAM_SLOTS};

pub use fast_expr::FastExpr;
pub use life::{live, team_result, Bodies, Hooks, Solo};
pub use net::{sigmoid, Net};
pub use perf::Rolling;
pub use script::ScriptRun;
pub use team::{
    episode_with, run_team_episode, run_team_episode_measured, run_team_episode_until, StopWhen, TeamBodies,
    TeamMember, TeamResult, TeamRun,
};

/// How to run one episode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EpisodeOptions {
    /// Most actions the episode lasts (it ends earlier when the battery dies).
    pub actions: u32,
    /// Enables local learning (CRBP) where the modules declare it.
    pub learning: bool,
    /// Seeds the simulator and the controller's RNG.
    pub seed: u64,
}

/// What one episode produced.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EpisodeResult {
    /// Sum over the actions of the per-action fitness term, plus the bonuses
    /// times the event counts.
    pub fitness: f32,
    /// Actions executed.
    pub actions: u32,
    pub grips: u32,
    pub releases_outside: u32,
    pub recharges: u32,
    pub collisions: u32,
    /// Lamarckian: the genome with learned activation weights written back
    pub learned: Option<Genome>,
    /// Placements of objects or of the robot's start that found no free
    /// place and kept an overlapping one ([`Robot::placement_failures`]):
    /// 0 unless the world is too crowded, and then this episode is not the
    /// declared world. Left out of files when 0 (files written before it
    /// existed read as 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub placement_failures: u32,
    /// How the episode moved the robot (not kept in files).
    #[serde(skip)]
    pub descriptors: Descriptors,
}

/// What `distance_to(NAME)` reads when the life's world lacks the item
/// (the validation refuses such a program; a robot's world has none), mm.
pub const FAR: f32 = 1.0e6;

/// For `skip_serializing_if`: counts added to saved results are left out
/// while 0, so files without them stay as they were.
pub(crate) fn is_zero(n: &u32) -> bool {
    *n == 0
}

/// Per-action record of an episode (for replays, plots and tests).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    /// Module names, in declaration order (the columns of the per-module vectors).
    pub modules: Vec<String>,
    pub rows: Vec<TraceRow>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TraceRow {
    /// Action number, from 0.
    pub action: u32,
    /// Every module's activation level at this action.
    pub activations: Vec<f32>,
    /// The module that drove this action.
    pub winner: u16,
    /// Battery level after the action.
    pub battery: f32,
    /// An object is held after the action.
    pub holding: bool,
    /// Reinforcement each module received at this action (0 = none).
    pub reinforcement: Vec<f32>,
    /// Each module's performance indicator after this action.
    pub performance: Vec<f32>,
    /// Pose after the action.
    pub pose: Pose,
    /// Objects gripped so far in the episode.
    pub grips: u32,
    /// Objects released outside so far in the episode.
    pub releases_outside: u32,
    /// The battery was refilled during this action.
    pub recharged: bool,
    /// The move of this action was undone by a collision.
    pub collided: bool,
}

/// A stage or genome the controller cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ControllerError {
    #[error("the genome has {have} bits but the layout needs {need}")]
    GenomeTooShort { have: usize, need: usize },
    #[error("{0}")]
    Invalid(#[from] crate::validate::Invalid),
    /// A measurement's setup does not fit the stage ([`crate::oracle`]).
    #[error("{0}")]
    Setup(String),
}

// ------------------------------------------------------------------ robot

/// What the controller needs from the world: the simulator implements it;
/// tests implement it with hand-set percepts.
pub trait Robot {
    /// Fills the percept channels for the current state.
    fn sense(&mut self, out: &mut [f32; CHANNELS]);
    /// Executes one action.
    fn step(&mut self, cmd: &Command) -> Outcome;
    /// False once the robot can no longer act (battery empty).
    fn alive(&self) -> bool {
        true
    }
    /// Battery level 0..1.
    fn battery(&self) -> f32 {
        1.0
    }
    fn pose(&self) -> Pose {
        Pose::default()
    }
    /// The body centre, mm: [`Robot::pose`]'s position, which a robot may
    /// give without computing the heading.
    fn position(&self) -> [f32; 2] {
        let p = self.pose();
        [p.x, p.y]
    }
    /// Whether an object is held, if the robot knows (`None`: the controller
    /// tracks it from grips and claw openings).
    fn holding(&self) -> Option<bool> {
        None
    }
    /// Placements of the world so far (objects, the start, virtual objects
    /// coming back) that ran out of tries and kept an overlapping one
    /// ([`Sim::placement_failures`]); read once, at the end of an episode.
    fn placement_failures(&self) -> u32 {
        0
    }
}

impl Robot for Sim {
    #[inline]
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        Sim::sense(self, out)
    }
    #[inline]
    fn step(&mut self, cmd: &Command) -> Outcome {
        Sim::step(self, cmd)
    }
    fn alive(&self) -> bool {
        Sim::alive(self)
    }
    fn battery(&self) -> f32 {
        Sim::battery(self)
    }
    fn pose(&self) -> Pose {
        Sim::pose(self)
    }
    #[inline]
    fn position(&self) -> [f32; 2] {
        Sim::position(self)
    }
    fn holding(&self) -> Option<bool> {
        Some(Sim::holding(self))
    }
    fn placement_failures(&self) -> u32 {
        Sim::placement_failures(self)
    }
}

// ------------------------------------------------------------------ modules

#[derive(Clone, Debug)]
enum Gen<'s> {
    Script(ScriptRun),
    /// `signals`: the network's last outputs set the broadcast values.
    Neural {
        net: Net,
        decode: &'s Decode,
        bits: Vec<u8>,
        signals: usize,
    },
}

#[derive(Clone, Debug)]
struct Mod<'s> {
    activation: Net,
    /// Incoming links: (source module, weight).
    links: Vec<(usize, f32)>,
    gen: Gen<'s>,
    learning: Option<Learning>,
    reinforce: Option<FastExpr>,
    /// The script's `reinforce` steps deliver the reinforcement instead of `reinforce`.
    script_reinforces: bool,
    perf: Rolling,
    /// A script's decision: the percept and link input on which the module
    /// won the arbitration that started the current run of its script.
    decided: [f32; CHANNELS],
    decided_link: f32,
}

impl Mod<'_> {
    fn learning_on(&self) -> bool {
        match &self.learning {
            None => false,
            Some(l) => match l.when {
                LearnWhen::Always => true,
                LearnWhen::Below { threshold } => self.perf.mean() < threshold,
            },
        }
    }

    fn reset_script(&mut self) {
        if let Gen::Script(s) = &mut self.gen {
            s.reset();
        }
    }
}

/// What one action did (returned by [`Controller::act`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActionReport {
    pub winner: usize,
    pub command: Command,
    pub outcome: Outcome,
    /// The winner's reinforcement at this action (0 = none).
    pub reinforcement: f32,
    /// The per-action fitness term (0 without one).
    pub fitness: f32,
}

/// The controller of one individual for one episode: decoded networks,
/// scripts, links, learning state and the per-action buffers, allocated once
/// in [`Controller::new`]; [`Controller::act`] allocates nothing.
#[derive(Clone, Debug)]
pub struct Controller<'s> {
    stage: &'s Stage,
    /// The fitness of its robot: its role's ([`Stage::role_fitness`]).
    role_fitness: &'s crate::program::Fitness,
    /// The modules it runs: the stage's, or its role's ([`Controller::for_role`]).
    modules: &'s [crate::program::Module],
    mods: Vec<Mod<'s>>,
    /// The activation networks evaluated together, when they all fit
    /// ([`block::Block::new`]); else one by one.
    block: Option<block::Block>,
    /// Activations of the current action and of the previous one.
    act: Vec<f32>,
    prev_act: Vec<f32>,
    /// Reinforcement per module at the last action.
    reinf: Vec<f32>,
    rng: ChaCha8Rng,
    learning: bool,
    /// Percept before the last action (`prev`), the current one (`now`) and
    /// the scratch for the next.
    before: [f32; CHANNELS],
    now: [f32; CHANNELS],
    next: [f32; CHANNELS],
    /// Actuator slots of the last executed command.
    slots: [f32; ACT_SLOTS],
    last_winner: Option<usize>,
    /// A winner imposed on the next action (see [`Controller::force_winner`]).
    forced: Option<usize>,
    /// Modules that cannot win the next action ([`Controller::forbid`]).
    forbidden: Vec<bool>,
    holding: bool,
    fitness: Option<FastExpr>,
    /// The fitness term of the life's end.
    at_end: Option<FastExpr>,
    /// The life so far: pose, distance, squares, actions.
    odo: Odometer,
    /// The length of the lives it lives, for the room the odometer keeps
    /// ([`Controller::set_life_length`]).
    life_actions: u32,
    /// The state the expressions read (`robot.x` ...), filled only when one does.
    state: [f32; STATE_SLOTS],
    /// `team.spread` ... `team.connected`, as the team last gave them
    /// ([`Controller::set_team`]).
    team: [f32; TEAM_SLOTS],
    reads_state: bool,
    /// Where the stage's targets (`distance_to(NAME)`) are in the world of
    /// the life (`None`: not in it; its distance reads [`FAR`]).
    targets: Vec<Option<crate::world::Place>>,
}

impl<'s> Controller<'s> {
    /// Decodes `genome` through `stage.layout` and builds the modules. Random
    /// initial weights are drawn from `rng`, which then drives CRBP sampling.
    ///
    /// The stage must have passed [`crate::validate`] (the entry points
    /// validate a program once; the controller trusts it); only the genome's
    /// length, and that trained weights have been bound, are checked here.
    pub fn new(
        stage: &'s Stage,
        genome: &Genome,
        rng: ChaCha8Rng,
    ) -> Result<Controller<'s>, ControllerError> {
        Controller::for_role(stage, 0, genome, rng)
    }

    /// [`Controller::new`] for a robot of role `role` of a heterogeneous
    /// team: the role's modules and links only (all of them without roles;
    /// winners and traces number the role's modules from 0).
    pub fn for_role(
        stage: &'s Stage,
        role: usize,
        genome: &Genome,
        mut rng: ChaCha8Rng,
    ) -> Result<Controller<'s>, ControllerError> {
        check_genome(stage, genome)?;
        let own = stage.role_modules(role);
        let modules = &stage.modules[own.clone()];
        crate::validate::bound(stage)?;
        let genes = genome.decode_all(&stage.layout);
        let mut value = |p: &Param| match *p {
            Param::Gene(i) => genes[i as usize],
            Param::Fixed(v) => v,
            Param::Random { lo, hi } => {
                if hi > lo {
                    rng.random_range(lo..hi)
                } else {
                    lo
                }
            }
            Param::Trained { .. } => unreachable!("`validate::bound` refused unbound trained weights"),
        };
        let mut mods = Vec::with_capacity(modules.len());
        for m in modules {
            let a = &m.activation;
            let activation = Net::with_context(
                m.inputs.clone(),
                a.hidden as usize,
                a.outputs as usize,
                a.recurrent,
                a.params.iter().map(&mut value).collect(),
            );
            let gen = match &m.behavior {
                Behavior::Script(s) => Gen::Script(ScriptRun::new(
                    s,
                    stage.world.body.ir.as_ref().map(|l| &l.facing),
                    stage.world.body.rab.as_ref().map_or(crate::catalog::RAB_SECTORS, |r| r.sectors.into()),
                )),
                Behavior::Neural(nb) => Gen::Neural {
                    net: Net::with_context(
                        nb.inputs.clone(),
                        nb.net.hidden as usize,
                        nb.net.outputs as usize,
                        nb.net.recurrent,
                        nb.net.params.iter().map(&mut value).collect(),
                    ),
                    decode: &nb.decode,
                    bits: vec![0; nb.net.outputs as usize],
                    signals: nb.signals.into(),
                },
            };
            let script_reinforces = matches!(&gen, Gen::Script(s) if s.delivers_reinforcement());
            let window = m.learning.as_ref().map_or(30, |l| l.window as usize);
            mods.push(Mod {
                activation,
                links: Vec::new(),
                gen,
                learning: m.learning.clone(),
                reinforce: m.reinforce.as_ref().map(FastExpr::new),
                script_reinforces,
                decided: [0.0; CHANNELS],
                decided_link: 0.0,
                perf: Rolling::new(window),
            });
        }
        for l in stage.links.iter().filter(|l| own.contains(&(l.to as usize))) {
            let w = value(&l.weight);
            mods[l.to as usize - own.start].links.push((l.from as usize - own.start, w));
        }
        let n = mods.len();
        Ok(Controller {
            stage,
            modules,
            block: block::Block::new(mods.iter().map(|m| &m.activation)),
            mods,
            act: vec![0.0; n],
            prev_act: vec![0.0; n],
            reinf: vec![0.0; n],
            rng,
            learning: true,
            before: [0.0; CHANNELS],
            now: [0.0; CHANNELS],
            next: [0.0; CHANNELS],
            slots: [0.0; ACT_SLOTS],
            last_winner: None,
            forced: None,
            forbidden: vec![false; n],
            holding: false,
            role_fitness: stage.role_fitness(role),
            fitness: stage.role_fitness(role).per_action.as_ref().map(FastExpr::new),
            at_end: stage.role_fitness(role).at_end.as_ref().map(FastExpr::new),
            odo: Odometer::default(),
            life_actions: 1024,
            state: [0.0; STATE_SLOTS],
            team: crate::state::TEAM_OF_ONE,
            reads_state: crate::state::reads_state(stage),
            targets: stage.targets.iter().map(|t| crate::world::Place::of(&stage.world, t)).collect(),
        })
    }

    /// Turns local learning on or off (on after `new`).
    pub fn set_learning(&mut self, on: bool) {
        self.learning = on;
    }

    /// Lives of `actions` actions follow (1,024 unless said): the odometer
    /// keeps room for as many squares, up to 1,024, so that a life does not
    /// allocate, and a team of thousands does not hold room it never uses.
    pub fn set_life_length(&mut self, actions: u32) {
        self.life_actions = actions.min(1024);
    }

    /// Starts a life: forgets what belonged to the previous one (a script
    /// under way, the activations the links read, a recurrent network's
    /// context, what the gripper held) and senses the initial percept; call
    /// once before the first [`Controller::act`] of each life. What learning
    /// changed in the weights, the performance indicators and the random
    /// stream carry over, so one controller can live several lives (a test
    /// stage's lives, before and after its world changes).
    pub fn start<R: Robot>(&mut self, sim: &mut R) {
        for m in &mut self.mods {
            m.reset_script();
            m.activation.forget();
            if let Gen::Neural { net, bits, .. } = &mut m.gen {
                net.forget();
                bits.fill(0);
            }
            m.decided = [0.0; CHANNELS];
            m.decided_link = 0.0;
        }
        self.act.fill(0.0);
        self.prev_act.fill(0.0);
        self.reinf.fill(0.0);
        self.slots = [0.0; ACT_SLOTS];
        self.last_winner = None;
        self.forced = None;
        self.forbidden.fill(false);
        self.holding = false;
        self.odo.start(sim.position(), self.life_actions);
        self.observe_state(sim);
        sim.sense(&mut self.now);
        self.before = self.now;
    }

    /// Fills the state the expressions read.
    #[inline]
    fn observe_state<R: Robot>(&mut self, sim: &R) {
        if self.reads_state {
            self.state = self.odo.state(sim.pose().theta);
            let at = sim.position();
            for (slot, place) in self.state[crate::state::ST_TARGETS..].iter_mut().zip(&self.targets) {
                *slot = place.map_or(FAR, |p| p.distance(at));
            }
            self.state[ST_SPREAD..ST_SPREAD + TEAM_SLOTS].copy_from_slice(&self.team);
        }
    }

    /// Gives the team's state the expressions read from now on: its
    /// spread, the share of its robots grouped and in its largest group,
    /// the mean distance to the nearest robot, the order of the headings
    /// and the share connected (`team.spread` ... `team.connected`).
    pub fn set_team(&mut self, team: [f32; TEAM_SLOTS]) {
        self.team = team;
        if self.reads_state {
            self.state[ST_SPREAD..ST_SPREAD + TEAM_SLOTS].copy_from_slice(&team);
        }
    }

    /// Finds the stage's targets (`distance_to(NAME)`) in `world`, the
    /// world of the lives that follow (a test's lives run in several).
    pub fn use_world(&mut self, world: &crate::program::World) {
        for (place, t) in self.targets.iter_mut().zip(&self.stage.targets) {
            *place = crate::world::Place::of(world, t);
        }
    }

    /// How this life has moved the robot so far.
    pub fn descriptors<R: Robot>(&self, sim: &R) -> Descriptors {
        self.odo.descriptors(sim.pose().theta)
    }

    /// Activation levels of the last action.
    pub fn activations(&self) -> &[f32] {
        &self.act
    }

    /// Reinforcement per module at the last action (0 = none).
    pub fn reinforcements(&self) -> &[f32] {
        &self.reinf
    }

    /// The performance indicator of module `m` (rolling mean of its non-zero
    /// reinforcements).
    pub fn performance(&self, m: usize) -> f32 {
        self.mods[m].perf.mean()
    }

    /// The current percept (after the last action).
    pub fn percept(&self) -> &[f32; CHANNELS] {
        &self.now
    }

    /// The actuator slots of the last command executed, as expressions read
    /// them (`wheels[0]`, a broadcast's values, which stay until set again).
    pub fn commanded(&self) -> &[f32; ACT_SLOTS] {
        &self.slots
    }

    /// The current step of module `m`'s script (`None` for a neural behavior).
    pub fn script_position(&self, m: usize) -> Option<usize> {
        match &self.mods[m].gen {
            Gen::Script(s) => Some(s.position()),
            Gen::Neural { .. } => None,
        }
    }

    /// Module `m`'s activation network evaluated on `percept` with no link
    /// input, using its current (possibly learned) weights. Does not disturb
    /// the stored forward pass used by learning.
    pub fn probe_activation(&self, m: usize, percept: &[f32; CHANNELS]) -> f32 {
        let mut net = self.mods[m].activation.clone();
        net.forward(percept, 0.0)[0]
    }

    /// Module `m`'s behavior network outputs on `percept` (empty for a script).
    pub fn probe_behavior(&self, m: usize, percept: &[f32; CHANNELS]) -> Vec<f32> {
        match &self.mods[m].gen {
            Gen::Neural { net, .. } => net.clone().forward(percept, 0.0).to_vec(),
            Gen::Script(_) => Vec::new(),
        }
    }

    /// Current weights of module `m`'s activation network (`Network::params` order).
    pub fn activation_weights(&self, m: usize) -> &[f32] {
        &self.mods[m].activation.w
    }

    /// Current weights of module `m`'s behavior network (empty for a script).
    pub fn behavior_weights(&self, m: usize) -> &[f32] {
        match &self.mods[m].gen {
            Gen::Neural { net, .. } => &net.w,
            Gen::Script(_) => &[],
        }
    }

    /// An object is held (as far as the controller knows: gripped and not
    /// released since).
    pub fn holding(&self) -> bool {
        self.holding
    }

    /// Runs one action (see the module documentation).
    pub fn act<R: Robot>(&mut self, sim: &mut R) -> ActionReport {
        // 1-3: activations and arbitration.
        std::mem::swap(&mut self.act, &mut self.prev_act);
        // The winner is compared on the net input of the activation unit:
        // the same order as the activation, but f32 sigmoids saturate to
        // exactly 1.0 above a net input of about 17, and saturated modules
        // would otherwise tie and fall back to declaration order.
        let mut winner = 0usize;
        let mut best = f32::NEG_INFINITY;
        if let Some(block) = &self.block {
            let mut link = [0.0f32; block::LANES];
            for (l, module) in link.iter_mut().zip(&self.mods) {
                *l = module.links.iter().map(|&(from, w)| w * self.prev_act[from]).sum();
            }
            let z = block.net_inputs(&self.now, &link);
            for (m, &z) in z[..block.lanes()].iter().enumerate() {
                self.act[m] = self.mods[m].activation.record_single(z);
                if z > best && !self.forbidden[m] {
                    best = z;
                    winner = m;
                }
            }
        } else {
            for m in 0..self.mods.len() {
                let module = &mut self.mods[m];
                let link: f32 = module.links.iter().map(|&(from, w)| w * self.prev_act[from]).sum();
                self.act[m] = module.activation.forward(&self.now, link)[0];
                let z = module.activation.net_inputs()[0];
                if z > best && !self.forbidden[m] {
                    best = z;
                    winner = m;
                }
            }
        }
        self.reinf.fill(0.0);
        if self.mods.is_empty() {
            let outcome = sim.step(&Command::default());
            self.odo.moved(sim.position());
            sim.sense(&mut self.next);
            self.before = self.now;
            self.now = self.next;
            return ActionReport {
                winner: 0,
                command: Command::default(),
                outcome,
                reinforcement: 0.0,
                fitness: 0.0,
            };
        }
        if let Some(f) = self.forced.take() {
            winner = f.min(self.mods.len() - 1);
        }
        self.forbidden.fill(false);
        // A committed script that has started keeps control until it ends.
        if let Some(l) = self.last_winner {
            if matches!(&self.mods[l].gen, Gen::Script(s) if s.holds_control()) {
                winner = l;
            }
        }
        if self.last_winner != Some(winner) {
            if let Some(l) = self.last_winner {
                self.mods[l].reset_script();
            }
            self.mods[winner].reset_script();
            self.last_winner = Some(winner);
        }
        let learn = self.learning && self.mods[winner].learning_on();
        {
            let module = &mut self.mods[winner];
            if matches!(&module.gen, Gen::Script(s) if s.at_start()) {
                module.decided = self.now;
                module.decided_link = module.links.iter().map(|&(from, w)| w * self.prev_act[from]).sum();
            }
        }

        // 4: the winner's behavior.
        let mut r = 0.0f32;
        let module = &mut self.mods[winner];
        let cmd = match &mut module.gen {
            Gen::Script(s) => {
                let env = Env { now: &self.now, prev: &self.before, act: &self.slots, state: &self.state };
                s.command(&env, &mut r)
            }
            Gen::Neural { net, decode, bits, signals } => {
                let y = net.forward(&self.now, 0.0);
                for (b, &p) in bits.iter_mut().zip(y) {
                    let on = if learn { self.rng.random::<f32>() < p } else { p > 0.5 };
                    *b = on as u8;
                }
                let w = y.len() - *signals;
                Command {
                    wheels: decode_wheels(decode, &bits[..w], &y[..w], learn),
                    signal: (*signals > 0).then(|| decode_signals(&bits[w..], &y[w..], learn)),
                    ..Command::default()
                }
            }
        };

        // 5: act and sense.
        let outcome = sim.step(&cmd);
        self.odo.moved(sim.position());
        self.observe_state(sim);
        record_command(&mut self.slots, &cmd);
        if cmd.claw == Some(false) {
            self.holding = false;
        }
        if outcome.grips > 0 {
            self.holding = true;
        }
        if let Some(h) = sim.holding() {
            self.holding = h;
        }
        sim.sense(&mut self.next);

        // 6-7: after-action expressions, reinforcement and learning.
        let env = Env { now: &self.next, prev: &self.now, act: &self.slots, state: &self.state };
        let module = &mut self.mods[winner];
        if let Gen::Script(s) = &mut module.gen {
            s.after_action(&env);
        }
        if !module.script_reinforces {
            if let Some(e) = &module.reinforce {
                r = crate::expr::sign(e.eval(&env));
            }
        }
        if r != 0.0 {
            self.reinf[winner] = r;
            module.perf.push(r);
            if learn {
                crbp(module, winner, &mut self.block, &self.now, r);
            }
        }
        let fitness = self.fitness.as_ref().map_or(0.0, |e| e.eval(&env));
        self.before = self.now;
        self.now = self.next;
        ActionReport { winner, command: cmd, outcome, reinforcement: r, fitness }
    }

    /// Imposes module `m` as the winner of the next [`Controller::act`] in
    /// place of the arbitration (activations are still computed and traced;
    /// a committed script that has started still keeps control). For
    /// measurements with an arbiter outside the architecture, such as
    /// [`crate::oracle`]; evolution never uses it.
    pub fn force_winner(&mut self, m: usize) {
        self.forced = Some(m);
    }

    /// Keeps module `m` from winning the next [`Controller::act`]: the
    /// highest activation among the others wins (if every module is
    /// forbidden, the first). Same use as [`Controller::force_winner`].
    pub fn forbid(&mut self, m: usize) {
        if let Some(f) = self.forbidden.get_mut(m) {
            *f = true;
        }
    }

    /// Runs a whole episode on `sim` (which must be fresh) and returns its result.
    pub fn run<R: Robot>(
        &mut self,
        sim: &mut R,
        opts: &EpisodeOptions,
        trace: Option<&mut Trace>,
    ) -> EpisodeResult {
        self.run_with(sim, opts, trace, |_, _| {})
    }

    /// [`Controller::run`] with `before` called before every action, with
    /// the controller and the robot as they are then (e.g. to
    /// [`Controller::force_winner`]).
    pub fn run_with<R: Robot>(
        &mut self,
        sim: &mut R,
        opts: &EpisodeOptions,
        trace: Option<&mut Trace>,
        before: impl FnMut(&mut Self, &R),
    ) -> EpisodeResult {
        self.run_hooked(sim, opts, trace, before, |_, _| {})
    }

    /// [`Controller::run`] with `after` called after every action with the
    /// trace's row of that action and the robot as the action left it: for
    /// a caller that writes the trace as it goes (`drive`, where a killed
    /// process keeps what it wrote).
    pub fn run_traced<R: Robot>(
        &mut self,
        sim: &mut R,
        opts: &EpisodeOptions,
        trace: &mut Trace,
        after: impl FnMut(&TraceRow, &R),
    ) -> EpisodeResult {
        self.run_hooked(sim, opts, Some(trace), |_, _| {}, after)
    }

    fn run_hooked<R: Robot>(
        &mut self,
        sim: &mut R,
        opts: &EpisodeOptions,
        trace: Option<&mut Trace>,
        before: impl FnMut(&mut Self, &R),
        after: impl FnMut(&TraceRow, &R),
    ) -> EpisodeResult {
        let stage = self.stage;
        let (robots, _) = life::live(
            stage,
            std::slice::from_mut(self),
            &mut life::Solo(sim),
            opts,
            trace.map(std::slice::from_mut),
            &mut SoloHooks { before, after },
        );
        robots.into_iter().next().unwrap_or_default()
    }

    /// Starts `trace` for a life of this controller's.
    fn begin_trace(&self, trace: &mut Trace) {
        trace.modules = self.modules.iter().map(|m| m.name.clone()).collect();
        trace.rows.clear();
    }

    /// The trace row of action `a`, just done with report `rep`, the life's
    /// counts so far `res`.
    fn trace_row<R: Robot>(&self, a: u32, rep: &ActionReport, res: &EpisodeResult, sim: &R) -> TraceRow {
        TraceRow {
            action: a,
            activations: self.act.clone(),
            winner: rep.winner as u16,
            battery: sim.battery(),
            holding: self.holding,
            reinforcement: self.reinf.clone(),
            performance: self.mods.iter().map(|m| m.perf.mean()).collect(),
            pose: sim.pose(),
            grips: res.grips,
            releases_outside: res.releases_outside,
            recharged: rep.outcome.recharged,
            collided: rep.outcome.collided,
        }
    }

    /// Ends a life: the at-end term and the bonuses added to the sum of the
    /// per-action terms `fitness`, the placements and the descriptors.
    fn finish<R: Robot>(&self, sim: &R, mut res: EpisodeResult, mut fitness: f64) -> EpisodeResult {
        if let Some(e) = &self.at_end {
            fitness += f64::from(self.at_end_value(e));
        }
        let counts = [res.grips, res.releases_outside, res.recharges, res.collisions];
        for points in fitness_bonus_points(self.role_fitness, counts) {
            fitness += points as f64;
        }
        res.fitness = fitness as f32;
        res.placement_failures = sim.placement_failures();
        res.descriptors = self.descriptors(sim);
        res
    }

    /// The value of `e` read as the fitness's `at end` term reads it at the
    /// end of a life: the last percept, the one before it, the last command
    /// and the robot's state (filled only where the stage reads it, or
    /// after [`Controller::read_state`]).
    pub fn at_end_value(&self, e: &FastExpr) -> f32 {
        let env = Env { now: &self.now, prev: &self.before, act: &self.slots, state: &self.state };
        e.eval(&env)
    }

    /// Fills the robot's state (`robot.x` ..., `team.spread` ...) after
    /// each action even where the stage's own expressions do not read it,
    /// for expressions read from outside ([`Controller::at_end_value`]).
    pub fn read_state(&mut self) {
        self.reads_state = true;
    }

    /// The genome with the learned weights that are genes (activation networks
    /// and evolvable neural behaviors) written back (nearest encodable value).
    /// Frozen genes (from earlier stages) are
    /// left as they are: a later stage never changes what an earlier one froze.
    pub fn write_back(&self, genome: &Genome) -> Genome {
        let mut g = genome.clone();
        let mut put = |params: &[Param], learned: &[f32]| {
            for (p, &w) in params.iter().zip(learned) {
                if let Param::Gene(i) = *p {
                    let gene = &self.stage.layout.genes[i as usize];
                    if !gene.frozen {
                        g.encode(gene, w);
                    }
                }
            }
        };
        for (m, module) in self.modules.iter().enumerate() {
            put(&module.activation.params, &self.mods[m].activation.w);
            // Evolvable weights of a neural behavior generator learn too.
            if let (Behavior::Neural(nb), Gen::Neural { net, .. }) = (&module.behavior, &self.mods[m].gen) {
                put(&nb.net.params, &net.w);
            }
        }
        g
    }
}

/// [`Controller::run_with`]'s and [`Controller::run_traced`]'s closures
/// as the life's hooks.
struct SoloHooks<F, G> {
    before: F,
    after: G,
}

impl<'s, R: Robot, F: FnMut(&mut Controller<'s>, &R), G: FnMut(&TraceRow, &R)>
    life::Hooks<'s, life::Solo<'_, R>> for SoloHooks<F, G>
{
    fn before(&mut self, _i: usize, ctl: &mut Controller<'s>, robot: &&mut R) {
        (self.before)(ctl, robot)
    }
    fn acted(
        &mut self,
        _i: usize,
        _: &Controller<'s>,
        _: &ActionReport,
        row: Option<&TraceRow>,
        robot: &&mut R,
    ) {
        if let Some(row) = row {
            (self.after)(row, robot)
        }
    }
}

/// Wheel speeds of a neural behavior's outputs.
fn decode_wheels(decode: &Decode, bits: &[u8], y: &[f32], sampled: bool) -> [f32; 2] {
    match decode {
        Decode::Table(table) => {
            let idx = bits.iter().fold(0usize, |acc, &b| (acc << 1) | b as usize);
            table.get(idx).copied().unwrap_or([0.0, 0.0])
        }
        Decode::Linear { scale } => {
            // While learning, the sampled bits drive the wheels (full speed
            // forward or back) so that CRBP reinforces what was done.
            let v = |o: usize| {
                let u = if sampled { bits[o] as f32 } else { y[o] };
                (2.0 * u - 1.0) * scale
            };
            [v(0), v(1)]
        }
    }
}

/// The broadcast values of a neural behavior's signal outputs: each output
/// as it is (0..1), or while learning its sampled bit, so that CRBP
/// reinforces what was sent; the values past the outputs 0.
fn decode_signals(bits: &[u8], y: &[f32], sampled: bool) -> [f32; SIGNALS] {
    let mut v = [0.0; SIGNALS];
    for (k, v) in v.iter_mut().enumerate().take(y.len()) {
        *v = if sampled { f32::from(bits[k]) } else { y[k] };
    }
    v
}

/// Adds one action's report to a life's counts and its sum of per-action terms.
fn tally(res: &mut EpisodeResult, fitness: &mut f64, rep: &ActionReport) {
    *fitness += rep.fitness as f64;
    res.actions += 1;
    res.grips += rep.outcome.grips;
    res.releases_outside += rep.outcome.releases_outside;
    res.recharges += rep.outcome.recharged as u32;
    res.collisions += rep.outcome.collided as u32;
}

/// Derives the simulator's seed and the controller's RNG from an episode seed
/// (separate ChaCha8 streams so the two never share random numbers).
pub fn episode_rngs(seed: u64) -> (u64, ChaCha8Rng) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(1);
    (seed, rng)
}

/// Adds to `fitness` the stage's bonuses for the events counted in `res`.
pub fn add_bonuses(stage: &Stage, res: &EpisodeResult, fitness: &mut f64) {
    let counts = [res.grips, res.releases_outside, res.recharges, res.collisions];
    for points in bonus_points(stage, counts) {
        *fitness += points as f64;
    }
}

/// Each bonus of `stage`'s fitness for the event counts `[grips, releases
/// outside, recharges, collisions]`: its points times its event's count.
pub fn bonus_points(stage: &Stage, counts: [u32; 4]) -> impl Iterator<Item = f32> + '_ {
    fitness_bonus_points(&stage.fitness, counts)
}

/// Each bonus of `fitness` for the event counts `[grips, releases
/// outside, recharges, collisions]`: its points times its event's count.
pub fn fitness_bonus_points(
    fitness: &crate::program::Fitness,
    counts: [u32; 4],
) -> impl Iterator<Item = f32> + '_ {
    fitness.bonuses.iter().map(move |b| {
        let n = match b.event {
            Event::Grip => counts[0],
            Event::ReleaseOutside => counts[1],
            Event::Recharge => counts[2],
            Event::Collision => counts[3],
        };
        b.points * n as f32
    })
}

/// Writes what `cmd` commands into the actuator slots expressions read
/// (`wheels[0]`, the arm and the claw as 0 or 1; an arm or claw not
/// commanded keeps its slot).
pub fn record_command(slots: &mut [f32; ACT_SLOTS], cmd: &Command) {
    slots[ACT_LEFT] = cmd.wheels[0];
    slots[ACT_RIGHT] = cmd.wheels[1];
    if let Some(d) = cmd.arm {
        slots[ACT_ARM] = f32::from(u8::from(d));
    }
    if let Some(c) = cmd.claw {
        slots[ACT_CLAW] = f32::from(u8::from(c));
    }
    if let Some(v) = cmd.signal {
        slots[ACT_SIGNAL..ACT_SIGNAL + SIGNALS].copy_from_slice(&v);
    }
}

/// Runs one episode of `genome` on `stage`, which must have passed
/// [`crate::validate`]. A genome shorter than the layout gives an empty
/// result with fitness 0; use [`try_run_episode`] to get the error.
pub fn run_episode(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    trace: Option<&mut Trace>,
) -> EpisodeResult {
    episode(stage, genome, opts, trace).unwrap_or_default()
}

/// [`run_episode`] given up once `stop` returns true: asked before the
/// episode and after each of its actions ([`run_team_episode_until`]).
/// `None` when it was given up; an episode that was not is
/// [`run_episode`]'s.
pub fn run_episode_until(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    stop: impl Fn() -> bool,
) -> Option<EpisodeResult> {
    match team::run_team_episode_until(stage, genome, opts, None, stop) {
        Ok(r) => r.map(|r| r.team),
        // As `run_episode`: an empty result.
        Err(_) => Some(EpisodeResult::default()),
    }
}

/// [`run_episode`] on a stage that may not have been validated: validates
/// it and the genome first and reports what is wrong.
pub fn try_run_episode(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    trace: Option<&mut Trace>,
) -> Result<EpisodeResult, ControllerError> {
    validate(stage, genome)?;
    episode(stage, genome, opts, trace)
}

/// [`run_episode`] on the robot `robot` makes of the episode's simulator
/// (a wrapper that watches or stops it: Ctrl-C during a test stage).
pub fn run_episode_on<R: Robot>(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    trace: Option<&mut Trace>,
    robot: impl FnOnce(Sim) -> R,
) -> EpisodeResult {
    episode_on(stage, genome, opts, trace, robot).unwrap_or_default()
}

fn episode(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    trace: Option<&mut Trace>,
) -> Result<EpisodeResult, ControllerError> {
    episode_on(stage, genome, opts, trace, |sim| sim)
}

fn episode_on<R: Robot>(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    trace: Option<&mut Trace>,
    robot: impl FnOnce(Sim) -> R,
) -> Result<EpisodeResult, ControllerError> {
    // Of a team: the team's result, robot 0's trace.
    let res = team::episode_in(stage, genome, opts, trace.map(std::slice::from_mut), robot, || false)?;
    Ok(res.unwrap_or_default().team)
}

/// Checks that the controller can run `stage` with `genome`: the stage passes
/// the one validation of a program ([`crate::validate::stage`]) and the
/// genome is long enough for its layout.
pub fn validate(stage: &Stage, genome: &Genome) -> Result<(), ControllerError> {
    crate::validate::stage(stage)?;
    crate::validate::bound(stage)?;
    check_genome(stage, genome)
}

fn check_genome(stage: &Stage, genome: &Genome) -> Result<(), ControllerError> {
    let need = stage.layout.bits as usize;
    if genome.bits.len() < need {
        return Err(ControllerError::GenomeTooShort { have: genome.bits.len(), need });
    }
    Ok(())
}

/// Step 7, CRBP: the winner `module` (index `winner`) learns from the
/// reinforcement `r` (not 0) of the action just done, its activation
/// network towards 1 on reward and 0 on punishment (a script's for the
/// percept that started it), or its behavior network towards the outputs
/// it gave (reward) or their complements (punishment); `block` keeps the
/// activations' copy in step.
fn crbp(
    module: &mut Mod<'_>,
    winner: usize,
    block: &mut Option<block::Block>,
    now: &[f32; CHANNELS],
    r: f32,
) {
    if let Some(l) = &module.learning {
        let rate = if r > 0.0 { l.rate_reward } else { l.rate_punish };
        match l.target {
            LearnTarget::Activation => {
                let t = if r > 0.0 { 1.0 } else { 0.0 };
                if let Gen::Script(_) = module.gen {
                    // The reinforcement judges the decision that
                    // started the script, not the percept where a
                    // later `reinforce` step delivered it.
                    let (p, link) = (module.decided, module.decided_link);
                    module.activation.forward(&p, link);
                    module.activation.train(&p, |_| t, rate, l.error);
                } else {
                    module.activation.train(now, |_| t, rate, l.error);
                }
                if let Some(b) = block {
                    b.load(winner, &module.activation);
                }
            }
            LearnTarget::Behavior => {
                if let Gen::Neural { net, bits, .. } = &mut module.gen {
                    let bits = &*bits;
                    let reward = r > 0.0;
                    net.train(
                        now,
                        |o| {
                            let b = bits[o] as f32;
                            if reward {
                                b
                            } else {
                                1.0 - b
                            }
                        },
                        rate,
                        l.error,
                    );
                }
            }
        }
    }
}
