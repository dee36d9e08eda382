//! The evaluation of a stage's episodes by the controller and simulator: the
//! [`super::Evaluate`] function the CLI passes to the GA.

use crate::controller::{self, ControllerError, EpisodeOptions};
use crate::genome::Genome;
use crate::program::{Stage, StageRun};

use super::Evaluation;

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

/// An evaluation function running one controller episode of `stage` per call,
/// seeded with the episode seed. The stage is checked once here (with a zero
/// genome of its layout's length), so the episodes of genomes of that length,
/// which the GA always makes, cannot fail. With `inheritance: lamarckian`
/// the learned genome is returned for write-back.
pub fn evaluate_with_controller(
    stage: &Stage,
    opts: EvalOptions,
) -> Result<impl Fn(&Genome, u64) -> Evaluation + Sync + '_, ControllerError> {
    controller::validate(stage, &Genome::zeros(stage.layout.bits as usize))?;
    let worlds = VariantStages::of(stage);
    Ok(move |genome: &Genome, seed: u64| {
        let episode = EpisodeOptions { actions: opts.actions, learning: opts.learning, seed };
        Evaluation::of_episode(controller::run_episode(worlds.stage(seed), genome, &episode, None))
    })
}

/// A stage in each of its variants: which stage an episode seed runs
/// ([`super::seed::variant_seed`] names the variant in a stage with
/// variants). Made once per evaluation function, not per episode.
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

    /// The stage an episode of seed `seed` runs: the variant its seed
    /// names, or the stage itself without variants.
    pub fn stage(&self, seed: u64) -> &Stage {
        if self.each.is_empty() {
            return self.stage;
        }
        &self.each[super::seed::seed_variant(seed).min(self.each.len() - 1)]
    }
}
