//! Errors of the GA driver: every message says what went wrong and where
//! (stage name, generation, individual).

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum EvolveError {
    #[error("stage index {index} is out of range: the program has {count} stages")]
    StageIndex { index: usize, count: usize },

    #[error("stage `{stage}` extends `{parent}`, which is not an earlier stage")]
    ParentOrder { stage: String, parent: String },

    #[error("stage `{stage}` is a test or training stage, it is not evolved")]
    NotEvolved { stage: String },

    #[error("stage `{stage}` is evolved, not a test stage")]
    NotTest { stage: String },

    #[error("stage `{stage}` is not a training stage")]
    NotTrained { stage: String },

    #[error("stage `{stage}` extends no stage but its gene {gene} is frozen")]
    FrozenWithoutParent { stage: String, gene: usize },

    #[error("stage `{stage}`: gene {gene} is frozen but was not introduced by `{parent}`")]
    FrozenNewGene { stage: String, parent: String, gene: usize },

    #[error("stage `{stage}` does not extend the layout of `{parent}`: {what}")]
    NotAnExtension { stage: String, parent: String, what: String },

    #[error(
        "stage `{stage}` starts from the final population of `{parent}`, but no checkpoint of it was given"
    )]
    MissingParent { stage: String, parent: String },

    #[error("stage `{stage}` extends no stage, but a parent checkpoint was given")]
    UnexpectedParent { stage: String },

    #[error("stage `{stage}` starts from `{expected}`, but the given checkpoint is of stage `{found}`")]
    WrongParent { stage: String, expected: String, found: String },

    #[error("the checkpoint of stage `{stage}` holds no evaluated population")]
    ParentNotEvaluated { stage: String },

    #[error("stage `{stage}`, generation {generation}, individual {index}: fitness is {value}, not a finite number")]
    NonFiniteFitness { stage: String, generation: u32, index: usize, value: f32 },

    #[error("stage `{stage}`, generation {generation}, individual {index}: the learned genome has {found} bits, expected {expected}")]
    LearnedLength { stage: String, generation: u32, index: usize, expected: usize, found: usize },

    #[error("checkpoint format {found} is not supported (expected {expected})")]
    CheckpointFormat { found: u32, expected: u32 },

    /// A saved result (checkpoint, trained weights) of stage `stage` does not
    /// fit the program: the stage, or a stage it extends, is not defined as
    /// it was when the result was saved. `what` says what changed, one
    /// sentence per stage ([`super::fingerprint::changes`]).
    #[error("the definition of stage `{stage}` changed since it was saved: {what}")]
    Changed { stage: String, what: String },

    #[error("it holds {done} generations of stage `{stage}`, which now declares {declared}")]
    TooManyGenerations { stage: String, done: u32, declared: u32 },

    #[error("inconsistent checkpoint of stage `{stage}`: {what}")]
    Inconsistent { stage: String, what: String },
}
