//! A team's lives: one [`Controller`] per robot of a [`Team`], all of the
//! same genome, acting in turn (the loop is [`super::live`], the one of a
//! single robot too).
//!
//! Each action, robot 0, then 1, ... senses (what its last action left),
//! decides and moves, seeing the others where they are at that moment.
//! A robot whose battery is empty stops and stays as an obstacle; the
//! life ends when every robot's has or after the stage's actions. Each
//! robot's fitness is a single robot's (its terms, its events' bonuses);
//! the team's is their `sum`, `mean` or `min` (`Fitness::team`).
//! The team's state (`team.spread`, and `team.grouped` and `team.largest`
//! when the stage reads them) is given to every controller after each action. In a
//! heterogeneous team each robot runs its role's modules
//! ([`Controller::for_role`]), all decoded from the one genome.

use super::{
    episode_rngs, Bodies, Controller, ControllerError, EpisodeOptions, EpisodeResult, FastExpr, Hooks, Robot,
    Solo, Trace,
};
use crate::catalog::CHANNELS;
use crate::expr::Expr;
use crate::genome::Genome;
use crate::program::{Stage, World};
use crate::sim::{robot_seed, Command, Outcome, Pose, Sim, Team};
use crate::state::{TeamReads, TEAM_SLOTS};

/// Robot `i` of a team, as its controller sees it.
pub struct TeamMember<'t> {
    team: &'t mut Team,
    i: usize,
}

impl TeamMember<'_> {
    /// Its simulator.
    pub fn sim(&self) -> &Sim {
        self.team.sim(self.i)
    }
}

impl Robot for TeamMember<'_> {
    #[inline]
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        self.team.sense(self.i, out);
    }
    #[inline]
    fn step(&mut self, cmd: &Command) -> Outcome {
        self.team.step(self.i, cmd)
    }
    fn alive(&self) -> bool {
        self.team.sim(self.i).alive()
    }
    fn battery(&self) -> f32 {
        self.team.sim(self.i).battery()
    }
    fn pose(&self) -> Pose {
        self.team.sim(self.i).pose()
    }
    #[inline]
    fn position(&self) -> [f32; 2] {
        self.team.sim(self.i).position()
    }
    fn holding(&self) -> Option<bool> {
        Some(self.team.sim(self.i).holding())
    }
    fn placement_failures(&self) -> u32 {
        self.team.sim(self.i).placement_failures()
    }
}

/// What a team's life produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TeamResult {
    /// The team's: fitness aggregated over the robots as the stage says,
    /// the actions of the life (the most any robot did), the events and
    /// placement failures of all the robots, robot 0's descriptors.
    pub team: EpisodeResult,
    /// Each robot's own, in order.
    pub robots: Vec<EpisodeResult>,
}

/// The controllers of a team: one per robot, of one genome, living lives
/// together (what learning changed carries over, as for one controller).
pub struct TeamRun<'s> {
    stage: &'s Stage,
    genome: Genome,
    seed: u64,
    ctls: Vec<Controller<'s>>,
}

impl<'s> TeamRun<'s> {
    /// The team of `stage`'s world in the episode of seed `seed`: robot
    /// `i`'s controller has the random stream of seed [`robot_seed`]`(seed, i)`.
    pub fn new(stage: &'s Stage, genome: &Genome, seed: u64) -> Result<TeamRun<'s>, ControllerError> {
        let mut run = TeamRun { stage, genome: genome.clone(), seed, ctls: Vec::new() };
        run.grow(stage.robots() as usize)?;
        Ok(run)
    }

    /// Controllers for robots up to `n` (a test's changed world may add robots).
    fn grow(&mut self, n: usize) -> Result<(), ControllerError> {
        while self.ctls.len() < n {
            let i = self.ctls.len();
            let (_, rng) = episode_rngs(robot_seed(self.seed, i));
            let role = self.stage.role_of(i);
            self.ctls.push(Controller::for_role(self.stage, role, &self.genome, rng)?);
        }
        Ok(())
    }

    /// The controllers, robot 0's first.
    pub fn controllers(&self) -> &[Controller<'s>] {
        &self.ctls
    }

    /// Every controller finds the stage's targets in `world` ([`Controller::use_world`]).
    pub fn use_world(&mut self, world: &crate::program::World) {
        for c in &mut self.ctls {
            c.use_world(world);
        }
    }

    /// Lives one life in `team`'s world (fresh), robot `i`'s trace in
    /// `traces[i]` when given; `after` is called after every action with
    /// the team, and stops the life when it returns false.
    pub fn run(
        &mut self,
        team: &mut Team,
        opts: &EpisodeOptions,
        traces: Option<&mut [Trace]>,
        after: impl FnMut(&Team) -> bool,
    ) -> TeamResult {
        self.run_in(&mut TeamBodies { team }, opts, traces, &mut AfterAction(after))
    }

    /// Lives one life in `bodies` (fresh: one robot's or a team's), robot
    /// `i`'s trace in `traces[i]` when given, `hooks` called as it goes.
    pub fn run_in<B: Bodies>(
        &mut self,
        bodies: &mut B,
        opts: &EpisodeOptions,
        traces: Option<&mut [Trace]>,
        hooks: &mut impl Hooks<'s, B>,
    ) -> TeamResult {
        if self.grow(bodies.robots()).is_err() {
            // The same stage and genome made robot 0's: never fails here.
            return TeamResult::default();
        }
        let (robots, actions) = super::live(self.stage, &mut self.ctls, bodies, opts, traces, hooks);
        TeamResult { team: super::team_result(self.stage, &robots, actions), robots }
    }
}

/// A team's robots as the bodies of a life ([`super::live`]).
pub struct TeamBodies<'t> {
    pub team: &'t mut Team,
}

impl Bodies for TeamBodies<'_> {
    type Member<'a>
        = TeamMember<'a>
    where
        Self: 'a;
    fn robots(&self) -> usize {
        self.team.len()
    }
    fn alive(&self, i: usize) -> bool {
        self.team.sim(i).alive()
    }
    fn begin_action(&mut self) {
        self.team.begin_action();
    }
    fn prepare(&mut self, i: usize) {
        self.team.prepare(i);
    }
    fn end_action(&mut self) {
        self.team.end_action();
    }
    fn member(&mut self, i: usize) -> TeamMember<'_> {
        TeamMember { team: &mut *self.team, i }
    }
    fn state(&mut self, reads: TeamReads) -> Option<[f32; TEAM_SLOTS]> {
        Some(self.team.state(reads))
    }
}

/// [`TeamRun::run`]'s `after`, called with the team after every action.
struct AfterAction<F>(F);

impl<'s, F: FnMut(&Team) -> bool> Hooks<'s, TeamBodies<'_>> for AfterAction<F> {
    fn after_action(&mut self, bodies: &TeamBodies<'_>) -> bool {
        (self.0)(bodies.team)
    }
}

/// An episode of `genome` on `stage`, of one robot or of a team
/// (`stage.world.robots` robots), every robot's result; Lamarckian stages
/// write back what the first robot of each role learned (robot 0's without
/// roles).
pub fn run_team_episode(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    traces: Option<&mut [Trace]>,
) -> Result<TeamResult, ControllerError> {
    Ok(run_team_episode_until(stage, genome, opts, traces, || false)?.unwrap_or_default())
}

/// [`run_team_episode`] given up once `stop` returns true, which is asked
/// before the episode and after each of its actions (an action of a large
/// team takes long, and an episode thousands of them): `None` when it was
/// given up, and nothing of the episode is a result. An episode that is not
/// given up is [`run_team_episode`]'s.
pub fn run_team_episode_until(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    traces: Option<&mut [Trace]>,
    stop: impl Fn() -> bool,
) -> Result<Option<TeamResult>, ControllerError> {
    episode_in(stage, genome, opts, traces, |sim| sim, stop)
}

/// [`run_team_episode_until`], one robot's simulator wrapped by `robot` (a
/// watch or a stop; a team's robots are not wrapped).
pub(crate) fn episode_in<R: Robot>(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    traces: Option<&mut [Trace]>,
    robot: impl FnOnce(Sim) -> R,
    stop: impl Fn() -> bool,
) -> Result<Option<TeamResult>, ControllerError> {
    Ok(measured(stage, genome, opts, traces, robot, stop, &[])?.map(|(res, _)| res))
}

/// [`run_team_episode_until`], and the value of each of `measures` at the
/// end of each robot's life, read as the fitness's `at end` term is
/// (`values[m][i]`: measure `m` of robot `i`). The measures read the
/// robot's state and the team's measures whatever the stage reads; they
/// change nothing of the episode (Python's `evaluate(measures=...)`).
#[allow(clippy::type_complexity)]
pub fn run_team_episode_measured(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    measures: &[Expr],
    stop: impl Fn() -> bool,
) -> Result<Option<(TeamResult, Vec<Vec<f32>>)>, ControllerError> {
    measured(stage, genome, opts, None, |sim| sim, stop, measures)
}

#[allow(clippy::type_complexity)]
fn measured<R: Robot>(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    traces: Option<&mut [Trace]>,
    robot: impl FnOnce(Sim) -> R,
    stop: impl Fn() -> bool,
    measures: &[Expr],
) -> Result<Option<(TeamResult, Vec<Vec<f32>>)>, ControllerError> {
    if stop() {
        return Ok(None);
    }
    let mut run = TeamRun::new(stage, genome, opts.seed)?;
    if !measures.is_empty() {
        for c in &mut run.ctls {
            c.read_state();
        }
    }
    let mut hooks = StopWhen { stop, stopped: false, reads: TeamReads::of_exprs(measures) };
    let mut res = episode_with(&mut run, &stage.world, opts.seed, opts, traces, robot, &mut hooks);
    if hooks.stopped {
        return Ok(None);
    }
    if stage.inheritance == crate::program::Inheritance::Lamarckian {
        res.team.learned = Some(run.write_back(genome));
    }
    let values = measures
        .iter()
        .map(|m| {
            let e = FastExpr::new(m);
            run.ctls.iter().take(res.robots.len()).map(|c| c.at_end_value(&e)).collect()
        })
        .collect();
    Ok(Some((res, values)))
}

/// Hooks that end a life once `stop` returns true, asked after each action
/// (`stopped` says whether it did), and measure the team's `reads` besides
/// the stage's.
pub struct StopWhen<F> {
    pub stop: F,
    pub stopped: bool,
    pub reads: TeamReads,
}

impl<'s, B: Bodies, F: Fn() -> bool> Hooks<'s, B> for StopWhen<F> {
    fn after_action(&mut self, _: &B) -> bool {
        self.stopped = (self.stop)();
        !self.stopped
    }
    fn reads(&self) -> TeamReads {
        self.reads
    }
}

/// One life of `run`'s controllers in a fresh `world` of seed `seed` (its
/// robots', `world.robots`), `hooks` called as it goes: the one place that
/// decides the bodies of a life. One robot is a team of one, whose body
/// needs no neighbours and no team state; its simulator is wrapped by
/// `robot` (a watch or a stop; a team's robots are not wrapped).
pub fn episode_with<'s, R: Robot, H>(
    run: &mut TeamRun<'s>,
    world: &World,
    seed: u64,
    opts: &EpisodeOptions,
    traces: Option<&mut [Trace]>,
    robot: impl FnOnce(Sim) -> R,
    hooks: &mut H,
) -> TeamResult
where
    H: for<'b> Hooks<'s, Solo<'b, R>> + for<'b> Hooks<'s, TeamBodies<'b>>,
{
    if world.robots > 1 {
        run.run_in(&mut TeamBodies { team: &mut Team::new(world, seed) }, opts, traces, hooks)
    } else {
        let mut sim = robot(Sim::new(world, seed));
        run.run_in(&mut Solo(&mut sim), opts, traces, hooks)
    }
}

impl TeamRun<'_> {
    /// `genome` with the learned weights of the first robot of each role
    /// written back (robot 0's without roles): each role's genes are its own.
    pub fn write_back(&self, genome: &Genome) -> Genome {
        let mut g = genome.clone();
        let mut first = 0;
        for r in 0..self.stage.roles.len().max(1) {
            if let Some(c) = self.ctls.get(first) {
                g = c.write_back(&g);
            }
            first += self.stage.roles.get(r).map_or(0, |x| x.robots as usize);
        }
        g
    }
}
