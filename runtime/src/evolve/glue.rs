//! The evaluation of a stage's episodes by the controller and simulator: the
//! [`super::Evaluate`] function the CLI passes to the GA.

use crate::controller::{self, ControllerError, EpisodeOptions};
use crate::genome::Genome;
use crate::program::{Stage, StageRun};

use super::{Episode, Evaluation};

/// How episodes of a stage run: its life length in actions, and whether local
/// learning is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EvalOptions {
    pub actions: u32,
    pub learning: bool,
}

impl EvalOptions {
    /// What the stage declares: an evolved stage lives `Evolution::actions`
    /// actions with learning on (modules without `learning` never learn); a
    /// test stage one life as declared in `StageRun::Test`.
    pub fn of(stage: &Stage) -> EvalOptions {
        match &stage.run {
            StageRun::Evolve(evo) => EvalOptions { actions: evo.actions, learning: true },
            StageRun::Test { actions, learning, .. } => {
                EvalOptions { actions: *actions, learning: *learning }
            }
            StageRun::Train { actions } => EvalOptions { actions: *actions, learning: true },
        }
    }
}

/// The evaluation function of `stage`: one controller episode per call, in
/// the episode's variant, seeded with its seed (an episode of a variant the
/// stage does not declare has a NaN fitness), living and learning as `opts`
/// says. With `inheritance: lamarckian` the learned genome is returned for
/// write-back. The stage is not checked here ([`evaluate_with_controller`]
/// does).
pub fn evaluator(stage: &Stage, opts: EvalOptions) -> impl Fn(&Genome, Episode) -> Evaluation + Sync + '_ {
    evaluator_until(stage, opts, || false)
}

/// [`evaluator`] whose episodes are given up once `stop` returns true
/// (asked before an episode and after each action): a given-up episode has
/// a NaN fitness.
pub fn evaluator_until<'s>(
    stage: &'s Stage,
    opts: EvalOptions,
    stop: impl Fn() -> bool + Sync + 's,
) -> impl Fn(&Genome, Episode) -> Evaluation + Sync + 's {
    let worlds = VariantStages::of(stage);
    move |genome: &Genome, episode: Episode| {
        let Some(stage) = worlds.stage(episode) else { return Evaluation::not_run() };
        let opts = EpisodeOptions { actions: opts.actions, learning: opts.learning, seed: episode.seed };
        match controller::run_episode_until(stage, genome, &opts, &stop) {
            Some(r) => Evaluation::of_episode(r),
            None => Evaluation::not_run(),
        }
    }
}

/// [`evaluator`] of a stage checked once here (with a zero genome of its
/// layout's length), so the episodes of genomes of that length, which the
/// GA always makes, cannot fail.
pub fn evaluate_with_controller(
    stage: &Stage,
    opts: EvalOptions,
) -> Result<impl Fn(&Genome, Episode) -> Evaluation + Sync + '_, ControllerError> {
    controller::validate(stage, &Genome::zeros(stage.layout.bits as usize))?;
    Ok(evaluator(stage, opts))
}

/// A stage in each of its variants: which stage an [`Episode`] runs. Made
/// once per evaluation function, not per episode.
pub struct VariantStages<'s> {
    stage: &'s Stage,
    each: Vec<Stage>,
}

impl<'s> VariantStages<'s> {
    /// `stage` in each of its variants (none without variants).
    pub fn of(stage: &'s Stage) -> VariantStages<'s> {
        let each =
            (0..stage.variants.as_ref().map_or(0, |v| v.list.len())).map(|v| stage.in_variant(v)).collect();
        VariantStages { stage, each }
    }

    /// The stage `episode` runs: the stage in its variant, or the stage
    /// itself for an episode without one; `None` for a variant the stage
    /// does not declare.
    pub fn stage(&self, episode: Episode) -> Option<&Stage> {
        match episode.variant {
            None => Some(self.stage),
            Some(v) => self.each.get(v),
        }
    }
}
