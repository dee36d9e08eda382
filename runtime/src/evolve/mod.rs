//! The incremental GA over stages, with checkpoints as plain data.
//!
//! A run goes stage by stage. An evolved stage starts with [`start_stage`]
//! (the first stage from random genomes; a later one from the final
//! population of the stage it extends, its new genes random), then
//! [`step_generation`] is called until [`is_finished`]. A test stage runs the
//! parent's best individual once through [`test_best`]. The episode itself is
//! injected as an [`Evaluate`] function, so this module knows nothing of the
//! simulator or the controller.
//!
//! **Trust.** The program must have passed [`crate::validate`]: the GA takes
//! its evolution settings and layouts as valid (population, selection,
//! probabilities, gene sizes) and checks only what a checkpoint brings
//! (its stage, population and parent).
//!
//! **Generation semantics.** Generation `g` of a stage (0-based,
//! `Checkpoint::generation` counts the generations done) is: for `g > 0`,
//! breed a new population from the evaluated population of `g - 1` (see
//! [`ga::next_generation`]); then evaluate every individual (in parallel);
//! then record its [`GenStats`] and update the stage's best. A checkpoint thus
//! always holds an evaluated population with its fitness (except right after
//! [`start_stage`], when `fitness` is empty), and the final checkpoint of a
//! stage holds the evaluated final population. `Checkpoint::best` is the best
//! evaluated individual of the stage (the genome as evaluated, before any
//! Lamarckian write-back) until [`validate_best`] replaces it, at the end of
//! the stage, by the candidate with the best mean over fresh episodes: the
//! one a test stage and `replay` use.
//!
//! **Masks.** Bits of genes marked `frozen` in the stage's layout never
//! change: crossover cuts only among evolvable bits and each child keeps its
//! first parent's frozen bits; mutation flips only evolvable bits; a
//! Lamarckian write-back only copies evolvable bits.
//!
//! **Determinism.** No RNG state is carried from one generation to the next:
//! generation `g`'s breeding RNG is seeded from `(run seed, stage, g)`, each
//! episode from `(run seed, stage, g, individual, episode)` (see [`seed`]).
//! Evaluations run on rayon's current thread pool and are collected in index
//! order, so any thread count gives bit-identical results, and a run resumed
//! from a checkpoint equals the same run done straight. The `_with` variants
//! take an [`EvaluateMany`] that runs a generation's list of episodes
//! wherever it likes (the CLI spreads them over MPI ranks) and returns the
//! results in order, which keeps the same guarantee.

pub mod error;
pub mod fingerprint;
pub mod ga;
pub mod glue;
pub mod seed;
pub mod train;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

pub use error::EvolveError;
pub use fingerprint::{fingerprint, Fingerprint};
pub use ga::{frozen_mask, next_generation, ranking};
pub use glue::{evaluate_with_controller, evaluator, evaluator_until, EvalOptions, VariantStages};
pub use train::{train_all, train_stage, Trained};

use crate::genome::Genome;
use crate::program::{Evolution, Inheritance, Program, Stage, StageRun};

/// Version of the [`Checkpoint`] format.
pub const CHECKPOINT_FORMAT: u32 = 2;

/// One episode to run: its seed and, in a stage with variants, which of
/// the stage's declared variants (by index) its world is. The variant
/// travels beside the seed: whatever a caller passes as a seed, it never
/// chooses a variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Episode {
    pub seed: u64,
    /// `None`: the stage's own world (a stage without variants; in a stage
    /// with variants, its world before any variant's changes).
    pub variant: Option<usize>,
}

impl Episode {
    /// An episode of the stage's own world.
    pub fn plain(seed: u64) -> Episode {
        Episode { seed, variant: None }
    }

    /// Episode `seed` in variant `variant`: its seed is
    /// [`seed::variant_seed`]`(seed, variant)`, a seed of its own per variant.
    pub fn in_variant(seed: u64, variant: usize) -> Episode {
        Episode { seed: seed::variant_seed(seed, variant), variant: Some(variant) }
    }
}

/// Runs one episode of a genome.
pub type Evaluate<'a> = &'a (dyn Fn(&Genome, Episode) -> Evaluation + Sync);

/// Runs a list of episodes, each a genome and its episode, and returns
/// their results in the same order: the hook through which the episodes of a
/// generation can be spread over several processes (the CLI's MPI backend).
/// Which process or thread runs an episode must not change its result.
pub type EvaluateMany<'a> = &'a dyn Fn(&[(&Genome, Episode)]) -> Vec<Evaluation>;

/// [`EvaluateMany`] over `evaluate` on rayon's current thread pool.
pub fn evaluate_many(evaluate: Evaluate, jobs: &[(&Genome, Episode)]) -> Vec<Evaluation> {
    jobs.par_iter().map(|&(genome, episode)| evaluate(genome, episode)).collect()
}

/// The result of one episode.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    pub fitness: f32,
    /// The genome with learned values re-encoded. In a stage with
    /// `inheritance: lamarckian` its evolvable bits replace the individual's
    /// in the population; otherwise it is ignored.
    pub learned: Option<Genome>,
    /// What happened in the episode (for the statistics only: the GA
    /// selects on `fitness`).
    #[serde(default)]
    pub events: Events,
    /// Placements of the episode's world that found no free place and kept
    /// an overlapping one ([`crate::controller::EpisodeResult::placement_failures`]):
    /// 0 unless the world is too crowded.
    #[serde(default, skip_serializing_if = "crate::controller::is_zero")]
    pub placement_failures: u32,
}

impl Evaluation {
    /// The result of an episode that did not run or was given up (a
    /// variant its stage does not declare, Ctrl-C, a lost robot): its
    /// fitness is NaN, so no generation keeps it.
    pub fn not_run() -> Evaluation {
        Evaluation { fitness: f32::NAN, ..Evaluation::default() }
    }

    /// The evaluation of one controller episode.
    pub fn of_episode(result: crate::controller::EpisodeResult) -> Evaluation {
        Evaluation {
            fitness: result.fitness,
            events: Events {
                grips: result.grips,
                releases_outside: result.releases_outside,
                recharges: result.recharges,
            },
            learned: result.learned,
            placement_failures: result.placement_failures,
        }
    }
}

/// Counts of the events of an episode (or, summed, of an individual's
/// episodes in one generation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Events {
    /// Objects gripped.
    pub grips: u32,
    /// Objects released outside the arena.
    pub releases_outside: u32,
    /// Times the battery was recharged.
    pub recharges: u32,
}

impl Events {
    fn add(&mut self, other: Events) {
        self.grips = self.grips.saturating_add(other.grips);
        self.releases_outside = self.releases_outside.saturating_add(other.releases_outside);
        self.recharges = self.recharges.saturating_add(other.recharges);
    }
}

/// Statistics of one evaluated generation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GenStats {
    pub stage: String,
    /// Global number (0-based) continuing across the chain of stages, as in
    /// the paper's figure 9.
    pub generation: u32,
    /// Number within the stage (0-based).
    pub stage_generation: u32,
    pub best: f32,
    pub mean: f32,
    pub worst: f32,
    /// Index of the best individual in the evaluated population.
    pub best_index: u32,
    /// The best individual's events in its evaluation (summed over its
    /// episodes when the stage evaluates each individual more than once).
    /// Checkpoints written before these existed read as zero.
    #[serde(default)]
    pub best_recharges: u32,
    #[serde(default)]
    pub best_grips: u32,
    #[serde(default)]
    pub best_releases_outside: u32,
    /// Episodes of this generation whose world could not be placed apart
    /// (some placement kept an overlapping try: the world is too crowded),
    /// and the placements that did, over all of them. Left out of files
    /// while 0.
    #[serde(default, skip_serializing_if = "crate::controller::is_zero")]
    pub crowded_episodes: u32,
    #[serde(default, skip_serializing_if = "crate::controller::is_zero")]
    pub placement_failures: u32,
    /// In a stage with variants, the best individual's fitness in each
    /// declared variant (its mean over the variant's episodes), `None` for
    /// a variant not drawn this generation. Empty without variants.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub best_variants: Vec<Option<f32>>,
}

/// The variants generation `generation` of `stage` (index `index`) is
/// evaluated in, in declaration order: every variant, or the `draw N`
/// drawn from [`seed::draw_seed`] (the same for every individual). Empty for
/// a stage without variants.
pub fn drawn_variants(stage: &Stage, run_seed: u64, index: usize, generation: u32) -> Vec<usize> {
    let Some(vars) = &stage.variants else { return Vec::new() };
    let n = vars.list.len();
    let mut all: Vec<usize> = (0..n).collect();
    let Some(k) = vars.draw.map(|d| d as usize).filter(|&d| d < n) else { return all };
    // A partial Fisher-Yates shuffle: the first `k` are a uniform draw.
    let mut rng = seed::rng(seed::draw_seed(run_seed, index, generation));
    for i in 0..k {
        let j = rand::Rng::random_range(&mut rng, i..n);
        all.swap(i, j);
    }
    all.truncate(k);
    all.sort_unstable();
    all
}

/// The episodes of one individual: `episodes` episodes per variant of
/// `variants` (episode `e` of variant `v`: [`Episode::in_variant`]`(seed(e),
/// v)`), or `episodes` episodes without variants.
pub fn individual_episodes<'v>(
    variants: &'v [usize],
    episodes: u32,
    seed: impl Fn(u32) -> u64 + Copy + 'v,
) -> impl Iterator<Item = Episode> + 'v {
    let plain = variants.is_empty().then(|| (0..episodes).map(move |e| Episode::plain(seed(e))));
    let varied = variants
        .iter()
        .copied()
        .flat_map(move |v| (0..episodes).map(move |e| Episode::in_variant(seed(e), v)));
    plain.into_iter().flatten().chain(varied)
}

/// The jobs of one individual: its [`individual_episodes`].
fn individual_jobs<'g>(
    genome: &'g Genome,
    variants: &'g [usize],
    episodes: u32,
    seed: impl Fn(u32) -> u64 + Copy + 'g,
) -> impl Iterator<Item = (&'g Genome, Episode)> + 'g {
    individual_episodes(variants, episodes, seed).map(move |e| (genome, e))
}

/// An individual's fitness from its episodes' (`episodes` per variant of
/// `variants`, in the order of [`individual_jobs`]): the mean over its
/// episodes without variants; with them, the mean per variant, aggregated
/// as the stage declares. Also the per-variant means (by declared index).
fn individual_fitness(
    stage: &Stage,
    variants: &[usize],
    episodes: u32,
    scores: &[f32],
) -> (f32, Vec<Option<f32>>) {
    let mean = |xs: &[f32]| (xs.iter().map(|&f| f as f64).sum::<f64>() / xs.len().max(1) as f64) as f32;
    let Some(vars) = stage.variants.as_ref().filter(|_| !variants.is_empty()) else {
        return (mean(scores), Vec::new());
    };
    let mut per = vec![None; vars.list.len()];
    for (k, &v) in variants.iter().enumerate() {
        let chunk = &scores[k * episodes as usize..(k + 1) * episodes as usize];
        if let Some(slot) = per.get_mut(v) {
            *slot = Some(mean(chunk));
        }
    }
    (vars.aggregate.of(per.iter().flatten().copied()), per)
}

/// Everything needed to continue a run: plain data, serde (JSON) friendly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// [`CHECKPOINT_FORMAT`].
    pub format: u32,
    /// [`fingerprint()`] of `stage`: what the checkpoint was computed from.
    pub fingerprint: Fingerprint,
    /// Index of the stage in `Program::stages`.
    pub stage: usize,
    /// Generations done in this stage.
    pub generation: u32,
    /// The run seed.
    pub seed: u64,
    pub population: Vec<Genome>,
    /// Fitness of `population` (empty before the first generation).
    pub fitness: Vec<f32>,
    /// Statistics of every generation of this stage and of the stages it
    /// extends, oldest first.
    pub history: Vec<GenStats>,
    /// Best evaluated individual of this stage and its fitness: during the
    /// stage, the best single evaluation; once [`validate_best`] has run,
    /// the candidate with the best mean over fresh episodes.
    pub best: Option<(Genome, f32)>,
    /// [`validate_best`] has chosen `best`.
    #[serde(default)]
    pub validated: bool,
    /// The best single evaluation `best` held before [`validate_best`]
    /// replaced it: [`resume`] puts it back when the stage is given more
    /// generations, so the extended run equals a straight one.
    #[serde(default)]
    pub evaluated_best: Option<(Genome, f32)>,
}

/// The evolution parameters of an evolved stage.
pub fn evolution(stage: &Stage) -> Result<&Evolution, EvolveError> {
    match &stage.run {
        StageRun::Evolve(evo) => Ok(evo),
        StageRun::Test { .. } | StageRun::Train { .. } => {
            Err(EvolveError::NotEvolved { stage: stage.name.clone() })
        }
    }
}

/// Starts evolved stage `stage` of `program` with run seed `seed`.
///
/// `parent` must be the final checkpoint of the nearest evolved ancestor
/// (`stage.parent`, skipping test stages) when the stage extends one, and
/// `None` otherwise. The new population has this stage's size: individual `i`
/// takes the bits of the parent's layout from the parent's individual of rank
/// `i mod parent size` (best first), and random bits for the rest. The
/// history continues the parent's.
pub fn start_stage(
    program: &Program,
    stage: usize,
    seed: u64,
    parent: Option<&Checkpoint>,
) -> Result<Checkpoint, EvolveError> {
    let st = get_stage(program, stage)?;
    let evo = evolution(st)?;
    let bits = st.layout.bits as usize;
    let mut rng = seed::rng(seed::init_seed(seed, stage));
    let random_bits = |rng: &mut rand_chacha::ChaCha8Rng, out: &mut Vec<u8>, n: usize| {
        use rand::Rng;
        out.extend((0..n).map(|_| u8::from(rng.random::<bool>())));
    };

    let ancestor = evolved_ancestor(program, stage)?;
    let (population, history) = match (ancestor, parent) {
        (None, None) => {
            if let Some(gene) = st.layout.genes.iter().position(|g| g.frozen) {
                return Err(EvolveError::FrozenWithoutParent { stage: st.name.clone(), gene });
            }
            let population = (0..evo.population)
                .map(|_| {
                    let mut b = Vec::with_capacity(bits);
                    random_bits(&mut rng, &mut b, bits);
                    Genome { bits: b }
                })
                .collect();
            (population, Vec::new())
        }
        (None, Some(_)) => return Err(EvolveError::UnexpectedParent { stage: st.name.clone() }),
        (Some(p), None) => {
            return Err(EvolveError::MissingParent {
                stage: st.name.clone(),
                parent: program.stages[p].name.clone(),
            })
        }
        (Some(p), Some(cp)) => {
            let pst = &program.stages[p];
            if cp.stage != p {
                let found =
                    program.stages.get(cp.stage).map_or_else(|| format!("#{}", cp.stage), |s| s.name.clone());
                return Err(EvolveError::WrongParent {
                    stage: st.name.clone(),
                    expected: pst.name.clone(),
                    found,
                });
            }
            check_resume(program, cp)?;
            check_extension(st, pst)?;
            if cp.population.is_empty() || cp.fitness.len() != cp.population.len() {
                return Err(EvolveError::ParentNotEvaluated { stage: pst.name.clone() });
            }
            let kept = pst.layout.bits as usize;
            let ranked = ranking(&cp.fitness);
            let population = (0..evo.population as usize)
                .map(|i| {
                    let mut b = Vec::with_capacity(bits);
                    b.extend_from_slice(&cp.population[ranked[i % ranked.len()]].bits[..kept]);
                    random_bits(&mut rng, &mut b, bits - kept);
                    Genome { bits: b }
                })
                .collect();
            (population, cp.history.clone())
        }
    };
    Ok(Checkpoint {
        format: CHECKPOINT_FORMAT,
        fingerprint: fingerprint(program, stage),
        stage,
        generation: 0,
        seed,
        population,
        fitness: Vec::new(),
        history,
        best: None,
        validated: false,
        evaluated_best: None,
    })
}

/// Runs one generation of the checkpoint's stage (see the module doc for the
/// order: breed if `generation > 0`, evaluate, record) and returns its stats.
///
/// With `evaluations > 1` an individual's fitness is the mean over its
/// episodes (summed in f64), and a Lamarckian write-back uses the last
/// episode's learned genome. The caller decides when to stop
/// ([`is_finished`]); stepping further extends the stage.
pub fn step_generation(
    program: &Program,
    cp: &mut Checkpoint,
    evaluate: Evaluate,
) -> Result<GenStats, EvolveError> {
    step_generation_with(program, cp, &|jobs| evaluate_many(evaluate, jobs))
}

/// [`step_generation`] with the episodes of the generation run by `many`.
pub fn step_generation_with(
    program: &Program,
    cp: &mut Checkpoint,
    many: EvaluateMany,
) -> Result<GenStats, EvolveError> {
    let st = get_stage(program, cp.stage)?;
    let evo = evolution(st)?;
    check_population(st, cp)?;
    let mask = frozen_mask(&st.layout);
    let g = cp.generation;
    // The checkpoint is only modified once the generation succeeded, so an
    // error leaves it as it was.
    let mut population = if g > 0 {
        let mut rng = seed::rng(seed::breed_seed(cp.seed, cp.stage, g));
        next_generation(evo, &mask, &cp.population, &cp.fitness, &mut rng)
    } else {
        cp.population.clone()
    };

    let (run_seed, stage) = (cp.seed, cp.stage);
    let episodes = evo.evaluations.max(1);
    let variants = drawn_variants(st, run_seed, stage, g);
    let per_individual = episodes as usize * variants.len().max(1);
    let jobs: Vec<(&Genome, Episode)> = population
        .iter()
        .enumerate()
        .flat_map(|(i, genome)| {
            individual_jobs(genome, &variants, episodes, move |e| {
                seed::episode_seed(run_seed, stage, g, i, e)
            })
        })
        .collect();
    let evaluations = many(&jobs);
    if evaluations.len() != jobs.len() {
        return Err(EvolveError::Inconsistent {
            stage: st.name.clone(),
            what: format!("{} results for {} episodes", evaluations.len(), jobs.len()),
        });
    }
    let crowded_episodes = evaluations.iter().filter(|ev| ev.placement_failures > 0).count() as u32;
    let placement_failures = evaluations.iter().fold(0u32, |n, ev| n.saturating_add(ev.placement_failures));
    let mut evaluations = evaluations.into_iter();
    let mut scores = Vec::with_capacity(per_individual);
    let mut per_variant = Vec::with_capacity(population.len());
    let results: Vec<(f32, Option<Genome>, Events)> = (0..population.len())
        .map(|_| {
            let mut learned = None;
            let mut events = Events::default();
            scores.clear();
            for ev in evaluations.by_ref().take(per_individual) {
                scores.push(ev.fitness);
                learned = ev.learned;
                events.add(ev.events);
            }
            let (f, per) = individual_fitness(st, &variants, episodes, &scores);
            per_variant.push(per);
            (f, learned, events)
        })
        .collect();

    let mut fitness = Vec::with_capacity(results.len());
    let mut learned_all = Vec::with_capacity(results.len());
    let mut events_all = Vec::with_capacity(results.len());
    for (i, (f, learned, events)) in results.into_iter().enumerate() {
        if !f.is_finite() {
            return Err(EvolveError::NonFiniteFitness {
                stage: st.name.clone(),
                generation: g,
                index: i,
                value: f,
            });
        }
        if let Some(l) = &learned {
            if l.bits.len() != st.layout.bits as usize {
                return Err(EvolveError::LearnedLength {
                    stage: st.name.clone(),
                    generation: g,
                    index: i,
                    expected: st.layout.bits as usize,
                    found: l.bits.len(),
                });
            }
        }
        fitness.push(f);
        learned_all.push(learned);
        events_all.push(events);
    }

    let ranked = ranking(&fitness);
    let (best_index, worst_index) = (ranked[0], ranked[ranked.len() - 1]);
    let best = fitness[best_index];
    if cp.best.as_ref().is_none_or(|(_, f)| best > *f) {
        cp.best = Some((population[best_index].clone(), best));
    }
    if st.inheritance == Inheritance::Lamarckian {
        for (genome, learned) in population.iter_mut().zip(&learned_all) {
            if let Some(l) = learned {
                for (bit, (&frozen, &v)) in genome.bits.iter_mut().zip(mask.iter().zip(&l.bits)) {
                    if !frozen {
                        *bit = u8::from(v != 0);
                    }
                }
            }
        }
    }

    let stats = GenStats {
        stage: st.name.clone(),
        generation: cp.history.len() as u32,
        stage_generation: g,
        best,
        mean: (fitness.iter().map(|&f| f as f64).sum::<f64>() / fitness.len() as f64) as f32,
        worst: fitness[worst_index],
        best_index: best_index as u32,
        best_recharges: events_all[best_index].recharges,
        best_grips: events_all[best_index].grips,
        best_releases_outside: events_all[best_index].releases_outside,
        crowded_episodes,
        placement_failures,
        best_variants: per_variant.swap_remove(best_index),
    };
    cp.population = population;
    cp.fitness = fitness;
    cp.generation = g + 1;
    cp.history.push(stats.clone());
    Ok(stats)
}

/// True when the checkpoint's stage has run all its declared generations (and
/// for a test stage or a stage the program does not have).
pub fn is_finished(program: &Program, cp: &Checkpoint) -> bool {
    match program.stages.get(cp.stage).map(|s| &s.run) {
        Some(StageRun::Evolve(evo)) => cp.generation >= evo.generations,
        _ => true,
    }
}

/// Checks that a checkpoint can continue with this program: same format,
/// made from the same stage and the same stages it extends (see
/// [`fingerprint`](mod@fingerprint); stages that do not matter to it may
/// change), no more generations than the stage declares, and a population,
/// fitness and best that fit the stage.
pub fn check_resume(program: &Program, cp: &Checkpoint) -> Result<(), EvolveError> {
    check_resume_of(program, cp.stage, cp)
}

/// [`check_resume`] for a checkpoint meant to be of stage `index` (the stage
/// may have moved since: that is a change).
pub fn check_resume_of(program: &Program, index: usize, cp: &Checkpoint) -> Result<(), EvolveError> {
    if cp.format != CHECKPOINT_FORMAT {
        return Err(EvolveError::CheckpointFormat { found: cp.format, expected: CHECKPOINT_FORMAT });
    }
    let st = get_stage(program, index)?;
    let what = fingerprint::changes(&cp.fingerprint, &fingerprint(program, index));
    if !what.is_empty() {
        return Err(EvolveError::Changed { stage: st.name.clone(), what: what.join("; ") });
    }
    if cp.stage != index {
        return Err(EvolveError::Inconsistent {
            stage: st.name.clone(),
            what: format!("it says it is of stage {}, this is stage {index}", cp.stage),
        });
    }
    let evo = evolution(st)?;
    if cp.generation > evo.generations {
        return Err(EvolveError::TooManyGenerations {
            stage: st.name.clone(),
            done: cp.generation,
            declared: evo.generations,
        });
    }
    check_population(st, cp)
}

/// Takes up a saved checkpoint of stage `index` to continue it: checks it
/// ([`check_resume`]), records the stage's generations as the program now
/// declares them, and if the stage was finished but now declares more
/// generations, puts its best back to the best single evaluation (see
/// [`Checkpoint::evaluated_best`]), to be chosen again at the end, as in a
/// straight run. Returns whether a finished stage was reopened.
pub fn resume(program: &Program, index: usize, cp: &mut Checkpoint) -> Result<bool, EvolveError> {
    check_resume_of(program, index, cp)?;
    cp.fingerprint = fingerprint(program, index);
    if !cp.validated || is_finished(program, cp) {
        return Ok(false);
    }
    cp.validated = false;
    cp.best = cp.evaluated_best.take();
    Ok(true)
}

/// How many candidates [`validate_best`] re-evaluates, and on how many episodes.
pub const VALIDATE_CANDIDATES: usize = 10;
pub const VALIDATE_EPISODES: u32 = 5;

/// Chooses the stage's best individual once its generations are done: the
/// best single evaluation of the stage is often a lucky episode, so the
/// candidates (that individual, then the final population by fitness, without
/// duplicates, `candidates` in all) are re-evaluated on the same `episodes`
/// fresh episodes ([`seed::validate_seed`]) and the best mean wins (ties to
/// the earlier candidate). Sets `best` and `validated`; calling it again
/// changes nothing. Deterministic for any thread count.
pub fn validate_best(
    program: &Program,
    cp: &mut Checkpoint,
    evaluate: Evaluate,
    candidates: usize,
    episodes: u32,
) -> Result<(Genome, f32), EvolveError> {
    validate_best_with(program, cp, &|jobs| evaluate_many(evaluate, jobs), candidates, episodes)
}

/// [`validate_best`] with the episodes run by `many`.
pub fn validate_best_with(
    program: &Program,
    cp: &mut Checkpoint,
    many: EvaluateMany,
    candidates: usize,
    episodes: u32,
) -> Result<(Genome, f32), EvolveError> {
    if cp.validated {
        if let Some(best) = &cp.best {
            return Ok(best.clone());
        }
    }
    let mut pool: Vec<&Genome> = Vec::with_capacity(candidates);
    if let Some((g, _)) = &cp.best {
        pool.push(g);
    }
    if cp.fitness.len() == cp.population.len() {
        for i in ranking(&cp.fitness) {
            if pool.len() >= candidates.max(1) {
                break;
            }
            let g = &cp.population[i];
            if !pool.contains(&g) {
                pool.push(g);
            }
        }
    }
    let name = get_stage(program, cp.stage)?.name.clone();
    if pool.is_empty() {
        return Err(EvolveError::ParentNotEvaluated { stage: name });
    }
    let episodes = episodes.max(1);
    let (run_seed, stage) = (cp.seed, cp.stage);
    let st = get_stage(program, stage)?;
    // Every variant, not a generation's draw.
    let variants = st.variants.as_ref().map_or(0, |v| v.list.len());
    let variants: Vec<usize> = (0..variants).collect();
    let per_candidate = episodes as usize * variants.len().max(1);
    let jobs: Vec<(&Genome, Episode)> = pool
        .iter()
        .flat_map(|&g| {
            individual_jobs(g, &variants, episodes, move |e| seed::validate_seed(run_seed, stage, e))
        })
        .collect();
    let scores: Vec<f32> = many(&jobs).into_iter().map(|ev| ev.fitness).collect();
    if scores.len() != jobs.len() {
        return Err(EvolveError::Inconsistent {
            stage: name,
            what: format!("{} results for {} episodes", scores.len(), jobs.len()),
        });
    }
    let mut best = (0usize, f64::NEG_INFINITY);
    for c in 0..pool.len() {
        let per = &scores[c * per_candidate..(c + 1) * per_candidate];
        if let Some(bad) = per.iter().find(|f| !f.is_finite()) {
            return Err(EvolveError::NonFiniteFitness {
                stage: name,
                generation: cp.generation,
                index: c,
                value: *bad,
            });
        }
        let mean = if variants.is_empty() {
            per.iter().map(|&f| f as f64).sum::<f64>() / episodes as f64
        } else {
            f64::from(individual_fitness(st, &variants, episodes, per).0)
        };
        if mean > best.1 {
            best = (c, mean);
        }
    }
    let chosen = (pool[best.0].clone(), best.1 as f32);
    cp.evaluated_best = cp.best.replace(chosen.clone());
    cp.validated = true;
    Ok(chosen)
}

/// The individual a test stage runs, and its episode seed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestSubject {
    /// The parent stage's best individual.
    pub genome: Genome,
    /// Its fitness in the parent stage.
    pub parent_fitness: f32,
    /// The episode seed of the test; the lives of the test in both worlds
    /// take their simulator seeds from it ([`seed::test_life_seed`]).
    pub seed: u64,
}

/// The result of a test stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestOutcome {
    /// The genome that was run (the parent stage's best).
    pub genome: Genome,
    /// Its fitness in the parent stage.
    pub parent_fitness: f32,
    /// The episode seed used; the lives of the test in both worlds take
    /// their simulator seeds from it ([`seed::test_life_seed`]).
    pub seed: u64,
    pub evaluation: Evaluation,
}

/// Runs test stage `stage`: one episode of the best individual of `parent`
/// (the final checkpoint of the nearest evolved ancestor), with episode seed
/// [`seed::test_seed`]`(seed, stage, 0)`. Whether learning is on and how long
/// the episode lasts is read by the evaluation from `StageRun::Test`.
pub fn test_best(
    program: &Program,
    stage: usize,
    seed: u64,
    parent: &Checkpoint,
    evaluate: Evaluate,
) -> Result<TestOutcome, EvolveError> {
    let TestSubject { genome, parent_fitness, seed } = test_subject(program, stage, seed, parent)?;
    let evaluation = evaluate(&genome, Episode::plain(seed));
    Ok(TestOutcome { genome, parent_fitness, seed, evaluation })
}

/// What test stage `stage` runs, without running it: the best individual of
/// `parent` (which must be the final checkpoint of the nearest evolved
/// ancestor, and fit the program) and the episode seed
/// [`seed::test_seed`]`(seed, test_seed_stage(program, stage), 0)`.
pub fn test_subject(
    program: &Program,
    stage: usize,
    seed: u64,
    parent: &Checkpoint,
) -> Result<TestSubject, EvolveError> {
    let st = get_stage(program, stage)?;
    if let StageRun::Evolve(_) = st.run {
        return Err(EvolveError::NotTest { stage: st.name.clone() });
    }
    let Some(p) = evolved_ancestor(program, stage)? else {
        return Err(EvolveError::MissingParent { stage: st.name.clone(), parent: "(none)".into() });
    };
    let pst = &program.stages[p];
    if parent.stage != p {
        let found =
            program.stages.get(parent.stage).map_or_else(|| format!("#{}", parent.stage), |s| s.name.clone());
        return Err(EvolveError::WrongParent { stage: st.name.clone(), expected: pst.name.clone(), found });
    }
    check_resume(program, parent)?;
    let Some((genome, parent_fitness)) = best_of(parent) else {
        return Err(EvolveError::ParentNotEvaluated { stage: pst.name.clone() });
    };
    if genome.bits.len() != st.layout.bits as usize {
        return Err(EvolveError::NotAnExtension {
            stage: st.name.clone(),
            parent: pst.name.clone(),
            what: format!(
                "the test stage's genome has {} bits, the parent's {}",
                st.layout.bits,
                genome.bits.len()
            ),
        });
    }
    Ok(TestSubject {
        genome,
        parent_fitness,
        seed: seed::test_seed(seed, test_seed_stage(program, stage), 0),
    })
}

/// The stage whose place seeds the lives of test stage `stage`: the first
/// test stage that tests the same evolved stage. So every test of one best
/// runs the same lives (the same worlds, the same controller's random
/// numbers): tests that differ only in their change or in learning are
/// paired; the first (or only) test of a stage keeps its own seed.
pub fn test_seed_stage(program: &Program, stage: usize) -> usize {
    let Ok(Some(p)) = evolved_ancestor(program, stage) else { return stage };
    (0..stage)
        .find(|&i| {
            matches!(program.stages[i].run, StageRun::Test { .. })
                && evolved_ancestor(program, i).ok().flatten() == Some(p)
        })
        .unwrap_or(stage)
}

/// The best individual of a checkpoint's stage: `best`, or else the best of
/// the evaluated population.
pub fn best_of(cp: &Checkpoint) -> Option<(Genome, f32)> {
    if let Some(best) = &cp.best {
        return Some(best.clone());
    }
    if cp.population.is_empty() || cp.fitness.len() != cp.population.len() {
        return None;
    }
    let i = ranking(&cp.fitness)[0];
    Some((cp.population[i].clone(), cp.fitness[i]))
}

// ---------------------------------------------------------------- checks

fn get_stage(program: &Program, index: usize) -> Result<&Stage, EvolveError> {
    program.stages.get(index).ok_or(EvolveError::StageIndex { index, count: program.stages.len() })
}

/// The nearest evolved stage among `stage`'s ancestors (test stages
/// skipped; [`Program::evolved_above`]), or why the chain is malformed.
fn evolved_ancestor(program: &Program, stage: usize) -> Result<Option<usize>, EvolveError> {
    get_stage(program, stage)?;
    if let Some(p) = program.evolved_above(stage) {
        return Ok(Some(p));
    }
    // The walk ends early at a malformed link: name it.
    let last = program.lineage(stage).last().unwrap_or(stage);
    match program.stages[last].parent {
        Some(p) if p >= last => Err(EvolveError::ParentOrder {
            stage: program.stages[last].name.clone(),
            parent: get_stage(program, p)?.name.clone(),
        }),
        _ => Ok(None),
    }
}

/// The child's layout must start with the parent's genes (same place, size and
/// range) and may freeze only genes of that prefix.
fn check_extension(st: &Stage, pst: &Stage) -> Result<(), EvolveError> {
    let err =
        |what: String| EvolveError::NotAnExtension { stage: st.name.clone(), parent: pst.name.clone(), what };
    let (child, parent) = (&st.layout, &pst.layout);
    if child.bits < parent.bits || child.genes.len() < parent.genes.len() {
        return Err(err(format!(
            "it has {} genes in {} bits, the parent {} genes in {} bits",
            child.genes.len(),
            child.bits,
            parent.genes.len(),
            parent.bits
        )));
    }
    for (i, (c, p)) in child.genes.iter().zip(&parent.genes).enumerate() {
        if (c.offset, c.bits, c.lo, c.hi) != (p.offset, p.bits, p.lo, p.hi) {
            return Err(err(format!("gene {i} differs in position, size or range")));
        }
    }
    if let Some(gene) = child.genes.iter().position(|g| g.frozen && g.offset + g.bits as u32 > parent.bits) {
        return Err(EvolveError::FrozenNewGene { stage: st.name.clone(), parent: pst.name.clone(), gene });
    }
    Ok(())
}

fn check_population(st: &Stage, cp: &Checkpoint) -> Result<(), EvolveError> {
    let bad = |what: String| Err(EvolveError::Inconsistent { stage: st.name.clone(), what });
    let evo = evolution(st)?;
    let bits = st.layout.bits as usize;
    if cp.population.len() != evo.population as usize {
        return bad(format!("{} individuals, the stage declares {}", cp.population.len(), evo.population));
    }
    if let Some(i) = cp.population.iter().position(|g| g.bits.len() != bits) {
        return bad(format!("individual {i} has {} bits, the layout {bits}", cp.population[i].bits.len()));
    }
    let fits = |g: &Genome| g.bits.iter().position(|&b| b > 1).map(|p| (p, g.bits[p]));
    for (i, g) in cp.population.iter().enumerate() {
        if let Some((p, v)) = fits(g) {
            return bad(format!("bit {p} of individual {i} is {v}; bits are 0 or 1"));
        }
    }
    if cp.generation > 0 && cp.fitness.len() != cp.population.len() {
        return bad(format!("{} fitness values for {} individuals", cp.fitness.len(), cp.population.len()));
    }
    if cp.generation == 0 && !cp.fitness.is_empty() {
        return bad(format!("{} fitness values before the first generation", cp.fitness.len()));
    }
    if let Some(i) = cp.fitness.iter().position(|f| !f.is_finite()) {
        return bad(format!("the fitness of individual {i} is {}", cp.fitness[i]));
    }
    let own = cp.history.iter().filter(|h| h.stage == st.name).count();
    if own != cp.generation as usize {
        return bad(format!("{own} generations of statistics for {} generations done", cp.generation));
    }
    for (what, best) in [("best", &cp.best), ("evaluated best", &cp.evaluated_best)] {
        let Some((g, f)) = best else { continue };
        if g.bits.len() != bits {
            return bad(format!("the {what} individual has {} bits, the layout {bits}", g.bits.len()));
        }
        if let Some((p, v)) = fits(g) {
            return bad(format!("bit {p} of the {what} individual is {v}; bits are 0 or 1"));
        }
        if !f.is_finite() {
            return bad(format!("the fitness of the {what} individual is {f}"));
        }
    }
    if cp.validated && cp.best.is_none() {
        return bad("it says its best was chosen, but holds none".into());
    }
    Ok(())
}
