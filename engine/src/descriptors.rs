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

use shaping_runtime::controller::{run_episode, EpisodeOptions, EpisodeResult};
use shaping_runtime::evolve::{seed, Episode, Evaluation, Events};
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
/// and its [`Descriptors`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Described {
    pub evaluation: Evaluation,
    pub collisions: u32,
    pub descriptors: Descriptors,
}

/// The episodes of individual `individual` of generation
/// `generation` of evolved stage `stage` evaluated with seed `seed`: those
/// a run with run seed `seed` gives the individual of that index in that
/// generation of the stage ([`seed::episode_seed`]`(seed, stage,
/// generation, individual, e)`, `e` from 0 to the stage's `evaluations` -
/// 1; one episode if it declares none). In a stage with variants, those
/// episodes in every variant ([`Episode::in_variant`]), variant after
/// variant (a run draws some with `draw N`; here all are run).
pub fn episodes(stage: &Stage, index: usize, seed: u64, generation: u32, individual: usize) -> Vec<Episode> {
    let episodes = match &stage.run {
        StageRun::Evolve(evo) => evo.evaluations.max(1),
        StageRun::Test { .. } | StageRun::Train { .. } => 1,
    };
    let one = |e| seed::episode_seed(seed, index, generation, individual, e);
    match &stage.variants {
        None => (0..episodes).map(|e| Episode::plain(one(e))).collect(),
        Some(v) => (0..v.list.len())
            .flat_map(|k| (0..episodes).map(move |e| Episode::in_variant(one(e), k)))
            .collect(),
    }
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
    let actions = actions(stage);
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
        let (r, d) = episode(world, genome, &EpisodeOptions { actions, learning: true, seed: e.seed });
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
