//! A team's lives: one [`Controller`] per robot of a [`Team`], all of the
//! same genome, acting in turn.
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

use super::{episode_rngs, tally, Controller, ControllerError, EpisodeOptions, EpisodeResult, Robot, Trace};
use crate::catalog::CHANNELS;
use crate::genome::Genome;
use crate::program::Stage;
use crate::sim::{robot_seed, Command, Outcome, Pose, Team};

/// What a recorder sees of a team's life ([`TeamRun::run_watched`]): each
/// robot's sensing and commands, as they happen (the unit type sees nothing).
pub trait TeamWatch {
    /// Robot `i` sensed `out`, the team as it is now.
    fn sensed(&mut self, _i: usize, _out: &[f32; CHANNELS], _team: &Team) {}
    /// Robot `i` is about to execute `cmd`.
    fn commanded(&mut self, _i: usize, _cmd: &Command) {}
}

impl TeamWatch for () {}

/// Robot `i` of a team, as its controller sees it.
struct Member<'t, W: TeamWatch = ()> {
    team: &'t mut Team,
    i: usize,
    watch: &'t mut W,
}

impl<W: TeamWatch> Robot for Member<'_, W> {
    #[inline]
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        self.team.sense(self.i, out);
        self.watch.sensed(self.i, out, self.team);
    }
    #[inline]
    fn step(&mut self, cmd: &Command) -> Outcome {
        self.watch.commanded(self.i, cmd);
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
        run.grow(stage.world.robots.max(1) as usize)?;
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
        self.run_watched(team, opts, traces, &mut (), after)
    }

    /// [`TeamRun::run`], `watch` told of every robot's sensing and commands
    /// (a recorder of the life's frames; it draws no random number, so the
    /// life is the one [`TeamRun::run`] lives).
    pub fn run_watched<W: TeamWatch>(
        &mut self,
        team: &mut Team,
        opts: &EpisodeOptions,
        mut traces: Option<&mut [Trace]>,
        watch: &mut W,
        mut after: impl FnMut(&Team) -> bool,
    ) -> TeamResult {
        let n = team.len();
        if self.grow(n).is_err() {
            // The same stage and genome made robot 0's: never fails here.
            return TeamResult::default();
        }
        let ctls = &mut self.ctls[..n];
        let mut robots = vec![EpisodeResult::default(); n];
        let mut fitness = vec![0.0f64; n];
        let groups = crate::state::reads_groups(self.stage);
        let state = team.state(groups);
        for (i, c) in ctls.iter_mut().enumerate() {
            c.set_learning(opts.learning);
            c.set_team(state);
            if let Some(t) = traces.as_deref_mut().and_then(|t| t.get_mut(i)) {
                c.begin_trace(t);
            }
            team.prepare(i);
            c.start(&mut Member { team, i, watch: &mut *watch });
        }
        let mut actions = 0;
        for a in 0..opts.actions {
            if !team.sims().iter().any(|s| s.alive()) {
                break;
            }
            team.begin_action();
            for (i, c) in ctls.iter_mut().enumerate() {
                if !team.sim(i).alive() {
                    continue;
                }
                team.prepare(i);
                let member = &mut Member { team, i, watch: &mut *watch };
                let rep = c.act(member);
                tally(&mut robots[i], &mut fitness[i], &rep);
                if let Some(t) = traces.as_deref_mut().and_then(|t| t.get_mut(i)) {
                    t.rows.push(c.trace_row(a, &rep, &robots[i], member));
                }
            }
            actions += 1;
            let state = team.state(groups);
            for c in ctls.iter_mut() {
                c.set_team(state);
            }
            if !after(team) {
                break;
            }
        }
        for (i, c) in ctls.iter().enumerate() {
            let r = std::mem::take(&mut robots[i]);
            robots[i] = c.finish(&Member { team, i, watch: &mut *watch }, r, fitness[i]);
        }
        let mut total = EpisodeResult {
            fitness: self.stage.fitness.team.of(robots.iter().map(|r| r.fitness)),
            actions,
            ..EpisodeResult::default()
        };
        for r in &robots {
            total.grips += r.grips;
            total.releases_outside += r.releases_outside;
            total.recharges += r.recharges;
            total.collisions += r.collisions;
            total.placement_failures = total.placement_failures.saturating_add(r.placement_failures);
        }
        total.descriptors = robots[0].descriptors;
        TeamResult { team: total, robots }
    }
}

/// A team's episode of `genome` on `stage` (`stage.world.robots` robots),
/// as [`super::run_episode`] runs one robot's; Lamarckian stages write back
/// what the first robot of each role learned (robot 0's without roles).
pub fn run_team_episode(
    stage: &Stage,
    genome: &Genome,
    opts: &EpisodeOptions,
    traces: Option<&mut [Trace]>,
) -> Result<TeamResult, ControllerError> {
    let mut team = Team::new(&stage.world, opts.seed);
    let mut run = TeamRun::new(stage, genome, opts.seed)?;
    let mut res = run.run(&mut team, opts, traces, |_| true);
    if stage.inheritance == crate::program::Inheritance::Lamarckian {
        res.team.learned = Some(run.write_back(genome));
    }
    Ok(res)
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
