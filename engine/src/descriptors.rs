//! What an individual's evaluation did besides its fitness: the events of
//! its episodes and behaviour descriptors (the final pose, the length of
//! the path, the 50 mm squares of the arena visited), for optimizers that
//! look at more than a fitness (MAP-Elites, novelty search) and for Python's
//! `Program.evaluator`. The runtime's controller computes each episode's
//! descriptors ([`shaping_runtime::state::Odometer`], the same numbers the
//! fitness terms read as `robot.distance`, `robot.squares`, ...).
//!
//! The episodes are the ones a run evaluates: [`evaluate`] runs a genome's
//! episodes as [`shaping_runtime::evolve::evaluator`] runs each one (the stage's
//! `actions`, learning on) and combines them as `evolve` combines an
//! individual's `evaluations` episodes: the fitness is their mean (summed
//! in f64), the events are summed, and the learned genome is the last
//! episode's.

use std::sync::atomic::{AtomicBool, Ordering};

use shaping_runtime::controller::{
    run_episode, run_team_episode_measured, EpisodeOptions, EpisodeResult, TeamResult,
};
use shaping_runtime::evolve::{drawn_variants, individual_episodes, seed, Episode, Evaluation, Events};
use shaping_runtime::expr::Expr;
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Stage, StageRun};
pub use shaping_runtime::state::{Descriptors, SQUARE_MM};

/// One episode of `genome` on `stage`, as
/// [`shaping_runtime::controller::run_episode`] runs it, and its descriptors.
pub fn episode(stage: &Stage, genome: &Genome, opts: &EpisodeOptions) -> (EpisodeResult, Descriptors) {
    let result = run_episode(stage, genome, opts, None);
    let descriptors = result.descriptors;
    (result, descriptors)
}

/// What one individual's evaluation produced: its [`Evaluation`] as a run
/// computes it, the collisions (summed over its episodes, like the events)
/// and its [`Descriptors`] (of a team: robot 0's), and each robot's own.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Described {
    pub evaluation: Evaluation,
    pub collisions: u32,
    pub descriptors: Descriptors,
    /// Each robot's, robot 0's first (one for a single robot).
    pub robots: Vec<Robot>,
}

/// What one robot of an individual's team did over the individual's
/// episodes, combined as the team's are: its own fitness (the mean), its
/// events and collisions (summed), its final pose (the last episode's),
/// its path length and squares visited (the means), and the value of each
/// measure at the end of its lives ([`evaluate_measured`], the mean).
/// A robot that a variant's world lacks counts only the episodes it was in.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Robot {
    pub fitness: f32,
    pub events: Events,
    pub collisions: u32,
    pub descriptors: Descriptors,
    pub measures: Vec<f32>,
}

/// A robot's sums over the episodes it was in, for [`Robot`].
#[derive(Clone, Debug, Default)]
struct RobotSums {
    episodes: u32,
    fitness: f64,
    events: Events,
    collisions: u32,
    last: Descriptors,
    path: f64,
    squares: f64,
    measures: Vec<f64>,
}

impl RobotSums {
    fn add(&mut self, r: &EpisodeResult, measures: impl Iterator<Item = f32>) {
        self.episodes += 1;
        self.fitness += f64::from(r.fitness);
        self.events.grips = self.events.grips.saturating_add(r.grips);
        self.events.releases_outside = self.events.releases_outside.saturating_add(r.releases_outside);
        self.events.recharges = self.events.recharges.saturating_add(r.recharges);
        self.collisions = self.collisions.saturating_add(r.collisions);
        self.last = r.descriptors;
        self.path += f64::from(r.descriptors.path_length);
        self.squares += f64::from(r.descriptors.squares_visited);
        for (k, v) in measures.enumerate() {
            if let Some(m) = self.measures.get_mut(k) {
                *m += f64::from(v);
            }
        }
    }

    fn robot(&self) -> Robot {
        let n = f64::from(self.episodes.max(1));
        let mean = |v: f64| if self.episodes == 0 { f32::NAN } else { (v / n) as f32 };
        Robot {
            fitness: mean(self.fitness),
            events: self.events,
            collisions: self.collisions,
            descriptors: Descriptors {
                path_length: mean(self.path),
                squares_visited: mean(self.squares),
                ..self.last
            },
            measures: self.measures.iter().map(|&m| mean(m)).collect(),
        }
    }
}

/// The episodes of individual `individual` of generation
/// `generation` of evolved stage `stage` evaluated with seed `seed`: those
/// a run with run seed `seed` gives the individual of that index in that
/// generation of the stage ([`seed::episode_seed`]`(seed, stage,
/// generation, individual, e)`, `e` from 0 to the stage's `evaluations` -
/// 1; one episode if it declares none). In a stage with variants, those
/// episodes in each variant the run evaluates that generation in
/// ([`Episode::in_variant`]; every variant, or the generation's `draw N`:
/// [`drawn_variants`]), variant after variant.
pub fn episodes(stage: &Stage, index: usize, seed: u64, generation: u32, individual: usize) -> Vec<Episode> {
    let episodes = match &stage.run {
        StageRun::Evolve(evo) => evo.evaluations.max(1),
        StageRun::Test { .. } | StageRun::Train { .. } => 1,
    };
    let variants = drawn_variants(stage, seed, index, generation);
    individual_episodes(&variants, episodes, |e| seed::episode_seed(seed, index, generation, individual, e))
        .collect()
}

/// The length of the episodes of `stage`: its evolution's `actions`, a
/// test's or a training stage's life.
pub fn actions(stage: &Stage) -> u32 {
    match &stage.run {
        StageRun::Evolve(evo) => evo.actions,
        StageRun::Test { actions, .. } | StageRun::Train { actions } => *actions,
    }
}

/// Evaluates `genome` on `stage` over `episodes` (the
/// stage's actions, learning on), combined as `evolve` combines an
/// individual's episodes: the fitness is the mean (summed in f64), the
/// events and collisions and placement failures are summed, the learned
/// genome is the last episode's (with variants, the fitness is the mean
/// per variant, aggregated as the stage declares); the final pose is the last episode's, the
/// path length and the squares visited the means over the episodes. An
/// episode in a variant the stage does not declare makes the fitness NaN.
pub fn evaluate(stage: &Stage, genome: &Genome, episodes: &[Episode]) -> Described {
    evaluate_unless(stage, genome, episodes, &AtomicBool::new(false)).unwrap_or_default()
}

/// [`evaluate`], stopped between two episodes once `stop` is set (Python's
/// Ctrl-C): `None` if it stopped, and then nothing of the individual is
/// kept. An episode is at most the stage's `actions`, so a caller that sets
/// the flag waits for one episode at most.
pub fn evaluate_unless(
    stage: &Stage,
    genome: &Genome,
    episodes: &[Episode],
    stop: &AtomicBool,
) -> Option<Described> {
    evaluate_measured(stage, genome, episodes, &[], stop)
}

/// [`evaluate_unless`], and each robot's value of each of `measures`
/// (expressions a fitness `at end` may be, read at the end of each of its
/// lives as that term is: [`Robot::measures`], in order). The measures
/// change nothing else of the evaluation.
pub fn evaluate_measured(
    stage: &Stage,
    genome: &Genome,
    episodes: &[Episode],
    measures: &[Expr],
    stop: &AtomicBool,
) -> Option<Described> {
    let actions = actions(stage);
    let mut robots: Vec<RobotSums> = Vec::new();
    let mut sum = 0.0f64;
    let mut events = Events::default();
    let (mut collisions, mut placement_failures) = (0u32, 0u32);
    let mut learned = None;
    let (mut path, mut squares) = (0.0f64, 0.0f64);
    let mut last = Descriptors::default();
    let worlds = shaping_runtime::evolve::VariantStages::of(stage);
    // With variants: each variant's fitness sum and episodes.
    let mut per = vec![(0.0f64, 0u32); stage.variants.as_ref().map_or(0, |v| v.list.len())];
    for &e in episodes {
        if stop.load(Ordering::Relaxed) {
            return None;
        }
        let Some(world) = worlds.stage(e) else {
            return Some(Described { evaluation: Evaluation::not_run(), ..Described::default() });
        };
        let opts = EpisodeOptions { actions, learning: true, seed: e.seed };
        let (team, values) = match run_team_episode_measured(world, genome, &opts, measures, || false) {
            Ok(Some((t, v))) => (t, v),
            // As `run_episode`: an empty result.
            _ => (TeamResult::default(), Vec::new()),
        };
        for (i, robot) in team.robots.iter().enumerate() {
            if robots.len() <= i {
                robots
                    .resize(i + 1, RobotSums { measures: vec![0.0; measures.len()], ..RobotSums::default() });
            }
            robots[i].add(robot, values.iter().map(|v| v.get(i).copied().unwrap_or(f32::NAN)));
        }
        let r = team.team;
        let d = r.descriptors;
        sum += f64::from(r.fitness);
        if let Some(p) = e.variant.and_then(|v| per.get_mut(v)) {
            p.0 += f64::from(r.fitness);
            p.1 += 1;
        }
        collisions = collisions.saturating_add(r.collisions);
        placement_failures = placement_failures.saturating_add(r.placement_failures);
        let ev = Evaluation::of_episode(r);
        events.grips = events.grips.saturating_add(ev.events.grips);
        events.releases_outside = events.releases_outside.saturating_add(ev.events.releases_outside);
        events.recharges = events.recharges.saturating_add(ev.events.recharges);
        learned = ev.learned;
        path += f64::from(d.path_length);
        squares += f64::from(d.squares_visited);
        last = d;
    }
    let n = episodes.len().max(1) as f64;
    let fitness = match &stage.variants {
        Some(v) if per.iter().any(|p| p.1 > 0) => {
            v.aggregate.of(per.iter().filter(|p| p.1 > 0).map(|p| (p.0 / f64::from(p.1)) as f32))
        }
        _ => (sum / n) as f32,
    };
    Some(Described {
        evaluation: Evaluation { fitness, learned, events, placement_failures },
        collisions,
        descriptors: Descriptors {
            path_length: (path / n) as f32,
            squares_visited: (squares / n) as f32,
            ..last
        },
        robots: robots.iter().map(RobotSums::robot).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::{bind_training, Silent};
    use rand::{Rng, SeedableRng};
    use shaping_runtime::evolve;
    use shaping_runtime::program::Program;

    fn khepera() -> Program {
        let src =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/khepera.bat")).unwrap();
        let mut program = shaping_compiler::compile(&src, "khepera.bat").unwrap();
        bind_training(&mut program, None, 1, &Silent).unwrap();
        program
    }

    fn random_genome(bits: u32, seed: u64) -> Genome {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        Genome { bits: (0..bits).map(|_| u8::from(rng.random::<bool>())).collect() }
    }

    /// One episode: the same evaluation as the run's evaluator, with
    /// descriptors that fit the arena.
    #[test]
    fn an_episode_is_the_run_s_episode() {
        let program = khepera();
        let stage = &program.stages[1];
        let StageRun::Evolve(evo) = &stage.run else { panic!("navigation is evolved") };
        let run = evolve::evaluator(stage, evolve::EvalOptions { actions: evo.actions, learning: true });
        for k in 0..4 {
            let genome = random_genome(stage.layout.bits, k);
            let s = 1000 + k;
            let d = evaluate(stage, &genome, &[Episode::plain(s)]);
            assert_eq!(d.evaluation, run(&genome, Episode::plain(s)));
            let r = shaping_runtime::controller::run_episode(
                stage,
                &genome,
                &EpisodeOptions { actions: evo.actions, learning: true, seed: s },
                None,
            );
            assert_eq!(d.collisions, r.collisions);
            let [w, h] = stage.world.arena;
            let p = d.descriptors;
            assert!((0.0..=w).contains(&p.x) && (0.0..=h).contains(&p.y), "{p:?}");
            assert!(p.heading.abs() <= std::f32::consts::PI + 1e-6);
            assert!(p.path_length >= 0.0 && p.squares_visited >= 1.0);
            // Deterministic.
            assert_eq!(evaluate(stage, &genome, &[Episode::plain(s)]), d);
        }
    }

    /// A team: robot 0's descriptors are the team's, the robots' events
    /// add up to the team's, each robot's fitness is its own (the team's is
    /// their mean), and measures read what the fitness reads: `robot.x`
    /// each robot's final x, the fitness's own expression its fitness.
    #[test]
    fn a_team_s_robots_are_described_and_measured() {
        let src =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/aggregation.bat"))
                .unwrap();
        let program = shaping_compiler::compile(&src, "aggregation.bat").unwrap();
        let mut stage = program.stages[0].clone();
        let exprs: Vec<Expr> = ["robot.x", "1 - team.spread / 400", "robot.distance", "team.order"]
            .iter()
            .map(|t| shaping_compiler::measure(&mut stage, "measure", t).unwrap())
            .collect();
        for k in 0..3 {
            let genome = random_genome(stage.layout.bits, k);
            let s = episodes(&stage, 0, 9, 0, k as usize);
            assert_eq!(s.len(), 3);
            let plain = evaluate(&stage, &genome, &s);
            let d = evaluate_measured(&stage, &genome, &s, &exprs, &AtomicBool::new(false)).unwrap();
            // Measures change nothing else.
            assert_eq!(d.evaluation, plain.evaluation);
            assert_eq!(d.robots.len(), 10);
            assert_eq!(d.robots[0].descriptors, d.descriptors);
            let collisions: u32 = d.robots.iter().map(|r| r.collisions).sum();
            assert_eq!(collisions, d.collisions);
            let mean = d.robots.iter().map(|r| f64::from(r.fitness)).sum::<f64>() / 10.0;
            assert!((mean - f64::from(d.evaluation.fitness)).abs() < 1e-4, "{mean} {:?}", d.evaluation);
            // The final x is the last episode's, a measure the mean of its episodes'.
            let last = evaluate_measured(&stage, &genome, &s[2..], &exprs, &AtomicBool::new(false)).unwrap();
            for r in &last.robots {
                assert_eq!(r.measures[0], r.descriptors.x, "{r:?}");
            }
            for (r, l) in d.robots.iter().zip(&last.robots) {
                assert_eq!(r.descriptors.x, l.descriptors.x);
                assert!((r.measures[1] - r.fitness).abs() < 1e-5, "{r:?}");
                assert!((r.measures[2] - r.descriptors.path_length).abs() < 1e-2, "{r:?}");
                assert!((0.0..=1.0).contains(&r.measures[3]));
                // Every robot reads the team's terms alike.
                assert_eq!(r.measures[3], d.robots[0].measures[3]);
            }
        }
    }

    /// A set stop flag stops the evaluation before its next episode and
    /// keeps nothing; an unset one changes nothing.
    #[test]
    fn a_stop_flag_stops_between_episodes() {
        let program = khepera();
        let stage = &program.stages[1];
        let genome = random_genome(stage.layout.bits, 3);
        let s = episodes(stage, 1, 5, 0, 2);
        let go = AtomicBool::new(false);
        assert_eq!(evaluate_unless(stage, &genome, &s, &go), Some(evaluate(stage, &genome, &s)));
        assert_eq!(evaluate_unless(stage, &genome, &s, &AtomicBool::new(true)), None);
    }

    /// Several evaluations: the fitness is the one a run's first generation
    /// gives the individual of the same index with the same seed.
    #[test]
    fn several_episodes_average_as_evolve_does() {
        let mut program = khepera();
        let StageRun::Evolve(evo) = &mut program.stages[1].run else { panic!("navigation is evolved") };
        evo.evaluations = 3;
        evo.population = 6;
        let actions = evo.actions;
        let seed = 7;
        let mut cp = evolve::start_stage(&program, 1, seed, None).unwrap();
        let stage = &program.stages[1];
        let run = evolve::evaluator(stage, evolve::EvalOptions { actions, learning: true });
        evolve::step_generation(&program, &mut cp, &run).unwrap();
        for (i, genome) in cp.population.iter().enumerate() {
            let s = episodes(stage, 1, seed, 0, i);
            assert_eq!(s.len(), 3);
            let d = evaluate(stage, genome, &s);
            assert_eq!(d.evaluation.fitness, cp.fitness[i], "individual {i}");
            let single: Vec<Described> = s.iter().map(|&x| evaluate(stage, genome, &[x])).collect();
            assert_eq!(d.descriptors.x, single[2].descriptors.x);
            assert_eq!(
                d.evaluation.events.recharges,
                single.iter().map(|x| x.evaluation.events.recharges).sum::<u32>()
            );
            assert_eq!(d.collisions, single.iter().map(|x| x.collisions).sum::<u32>());
            let mean = single.iter().map(|x| f64::from(x.descriptors.path_length)).sum::<f64>() / 3.0;
            assert!((f64::from(d.descriptors.path_length) - mean).abs() < 1e-3);
        }
        let best = cp.history[0].best_index as usize;
        let d = evaluate(stage, &cp.population[best], &episodes(stage, 1, seed, 0, best));
        assert_eq!(d.evaluation.events.recharges, cp.history[0].best_recharges);
    }
}
