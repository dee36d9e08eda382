//! One life, of one robot or of a team: the one episode loop.
//!
//! A single robot is a team of one. [`live`] runs the controllers of the
//! robots of a [`Bodies`] (one [`Robot`] of any kind through [`Solo`]:
//! the simulator, a recorder around it, the serial robot; or a
//! [`crate::sim::Team`]'s, through `team::TeamBodies`), each action robot
//! 0, 1, ... in turn sensing, deciding and moving; a robot whose battery is
//! empty stops, and the life ends when every robot's has or after the
//! stage's actions. What differs between one robot and a team is decided
//! by the bodies, here and nowhere else: a team finds each robot's
//! neighbours before it acts and has a state (`team.spread`, ...) that
//! every controller is given after each action; one robot has neither.
//! [`team_result`] is the one aggregation of the robots' results.

use super::{tally, ActionReport, Controller, EpisodeOptions, EpisodeResult, Robot, Trace, TraceRow};
use crate::catalog::CHANNELS;
use crate::program::Stage;
use crate::sim::{Command, Outcome, Pose};
use crate::state::{TeamReads, TEAM_SLOTS};

/// The bodies a life runs.
pub trait Bodies {
    /// Robot `i` as its controller sees it.
    type Member<'a>: Robot
    where
        Self: 'a;
    /// How many robots (at least one).
    fn robots(&self) -> usize;
    /// Whether robot `i` can still act.
    fn alive(&self, i: usize) -> bool;
    /// An action starts (a team: where every robot is now).
    fn begin_action(&mut self) {}
    /// Robot `i` is about to sense or act (a team: its neighbours found).
    fn prepare(&mut self, _i: usize) {}
    /// Every robot has acted in this action (a team with a
    /// range-and-bearing board: what each robot reads of the others,
    /// measured on one snapshot).
    fn end_action(&mut self) {}
    /// Robot `i`.
    fn member(&mut self, i: usize) -> Self::Member<'_>;
    /// The state every controller is given (`[team.spread, team.grouped,
    /// team.largest, team.nearest, team.order, team.connected]`, those
    /// `reads` leaves out not measured), or `None`: one robot has none,
    /// its controller's team slots stay as they start.
    fn state(&mut self, _reads: TeamReads) -> Option<[f32; TEAM_SLOTS]> {
        None
    }
}

/// One robot's body, of any kind.
pub struct Solo<'r, R: Robot>(pub &'r mut R);

impl<R: Robot> Bodies for Solo<'_, R> {
    type Member<'a>
        = &'a mut R
    where
        Self: 'a;
    fn robots(&self) -> usize {
        1
    }
    #[inline]
    fn alive(&self, _i: usize) -> bool {
        self.0.alive()
    }
    fn member(&mut self, _i: usize) -> &mut R {
        &mut *self.0
    }
}

impl<R: Robot> Robot for &mut R {
    #[inline]
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        (**self).sense(out)
    }
    #[inline]
    fn step(&mut self, cmd: &Command) -> Outcome {
        (**self).step(cmd)
    }
    #[inline]
    fn alive(&self) -> bool {
        (**self).alive()
    }
    #[inline]
    fn battery(&self) -> f32 {
        (**self).battery()
    }
    #[inline]
    fn pose(&self) -> Pose {
        (**self).pose()
    }
    #[inline]
    fn position(&self) -> [f32; 2] {
        (**self).position()
    }
    #[inline]
    fn holding(&self) -> Option<bool> {
        (**self).holding()
    }
    fn placement_failures(&self) -> u32 {
        (**self).placement_failures()
    }
}

/// What a caller of [`live`] does during the life (nothing, by default):
/// a recorder of its frames, a trace written as it goes, a stop.
pub trait Hooks<'s, B: Bodies> {
    /// Robot `i`'s controller started its life: it has sensed the world
    /// before the first action ([`Controller::percept`]).
    fn started(&mut self, _i: usize, _ctl: &Controller<'s>, _robot: &B::Member<'_>) {}
    /// Before robot `i`'s controller acts.
    fn before(&mut self, _i: usize, _ctl: &mut Controller<'s>, _robot: &B::Member<'_>) {}
    /// Robot `i` acted (`report`) and sensed what its action left
    /// ([`Controller::percept`]); `row` is its trace's row of the action
    /// when it is traced.
    fn acted(
        &mut self,
        _i: usize,
        _ctl: &Controller<'s>,
        _report: &ActionReport,
        _row: Option<&TraceRow>,
        _robot: &B::Member<'_>,
    ) {
    }
    /// After every robot acted once; `false` ends the life.
    fn after_action(&mut self, _bodies: &B) -> bool {
        true
    }
    /// The team's measures read from outside the stage (a caller's
    /// measures, [`super::run_team_episode_measured`]), measured besides
    /// those the stage reads.
    fn reads(&self) -> TeamReads {
        TeamReads::default()
    }
}

impl<'s, B: Bodies> Hooks<'s, B> for () {}

/// Lives one life of `bodies` (fresh), robot `i` driven by `ctls[i]`,
/// its trace in `traces[i]` when given: each robot's result (its fitness a
/// single robot's: its terms, its events' bonuses) and the actions the
/// life lasted.
pub fn live<'s, B: Bodies>(
    stage: &Stage,
    ctls: &mut [Controller<'s>],
    bodies: &mut B,
    opts: &EpisodeOptions,
    mut traces: Option<&mut [Trace]>,
    hooks: &mut impl Hooks<'s, B>,
) -> (Vec<EpisodeResult>, u32) {
    let n = bodies.robots().min(ctls.len());
    let ctls = &mut ctls[..n];
    let mut robots = vec![EpisodeResult::default(); n];
    let mut fitness = vec![0.0f64; n];
    let reads = TeamReads::of(stage).or(hooks.reads());
    let state = bodies.state(reads);
    for (i, c) in ctls.iter_mut().enumerate() {
        c.set_learning(opts.learning);
        c.set_life_length(opts.actions);
        if let Some(s) = state {
            c.set_team(s);
        }
        if let Some(t) = traces.as_deref_mut().and_then(|t| t.get_mut(i)) {
            c.begin_trace(t);
        }
        bodies.prepare(i);
        let mut member = bodies.member(i);
        c.start(&mut member);
        hooks.started(i, c, &member);
    }
    let mut actions = 0;
    for a in 0..opts.actions {
        if !(0..n).any(|i| bodies.alive(i)) {
            break;
        }
        bodies.begin_action();
        for (i, ((c, res), fit)) in ctls.iter_mut().zip(robots.iter_mut()).zip(fitness.iter_mut()).enumerate()
        {
            if !bodies.alive(i) {
                continue;
            }
            bodies.prepare(i);
            let mut member = bodies.member(i);
            hooks.before(i, c, &member);
            let rep = c.act(&mut member);
            tally(res, fit, &rep);
            let mut row = None;
            if let Some(t) = traces.as_deref_mut().and_then(|t| t.get_mut(i)) {
                t.rows.push(c.trace_row(a, &rep, res, &member));
                row = t.rows.last();
            }
            hooks.acted(i, c, &rep, row, &member);
        }
        actions += 1;
        bodies.end_action();
        if let Some(s) = bodies.state(reads) {
            for c in ctls.iter_mut() {
                c.set_team(s);
            }
        }
        if !hooks.after_action(bodies) {
            break;
        }
    }
    for (i, c) in ctls.iter().enumerate() {
        let r = std::mem::take(&mut robots[i]);
        robots[i] = c.finish(&bodies.member(i), r, fitness[i]);
    }
    (robots, actions)
}

/// The team's result of its robots' `robots` in a life of `actions`:
/// the fitness aggregated as the stage says (`Fitness::team`: of one robot,
/// its own), the events and placement failures of all the robots, robot
/// 0's descriptors.
pub fn team_result(stage: &Stage, robots: &[EpisodeResult], actions: u32) -> EpisodeResult {
    let mut total = EpisodeResult {
        fitness: stage.fitness.team.of(robots.iter().map(|r| r.fitness)),
        actions,
        ..EpisodeResult::default()
    };
    for r in robots {
        total.grips += r.grips;
        total.releases_outside += r.releases_outside;
        total.recharges += r.recharges;
        total.collisions += r.collisions;
        total.placement_failures = total.placement_failures.saturating_add(r.placement_failures);
    }
    total.descriptors = robots.first().map(|r| r.descriptors).unwrap_or_default();
    total
}
