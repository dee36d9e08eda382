//! The `summary.json` files, one typed struct per kind: a test stage's
//! ([`TestSummary`]), an experiment's or a sweep's ([`ExperimentSummary`]:
//! a sweep is an experiment whose points have directories of their own)
//! and a drive's ([`DriveSummary`]).
//!
//! The bytes are those the files have always had: a summary is turned
//! into a `serde_json::Value` (whose objects are sorted maps: the
//! workspace's `serde_json` has no `preserve_order`) and printed pretty, so
//! the keys come in sorted order whatever the order of the fields below;
//! the figures the runtime computes in `f32` are kept here as the `f64`
//! the files hold (a figure that was not a number is written `null` and
//! read back as NaN).
//!
//! No summary carries a version key: version 1, the only one, is the
//! absence of `"format"`. A file with a `"format"` newer than
//! [`SUMMARY_FORMAT`] is refused naming the file and its version.

use std::collections::BTreeMap;

use serde::{Deserialize, Deserializer, Serialize};

use crate::stats::{Interval, Magnitude, Method};

/// The version of every kind of `summary.json` this shaping writes and reads.
pub const SUMMARY_FORMAT: u32 = 1;

/// A figure written `null` when it was not a number: read back as NaN.
pub fn nan_if_null<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Median, minimum and maximum; mean and standard deviation (the sample's,
/// 0 for one value).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Spread {
    #[serde(deserialize_with = "nan_if_null")]
    pub median: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub min: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub max: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub mean: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub sd: f64,
}

/// The [`Spread`] of `values` (`None` without any): the one median
/// ([`crate::stats::median`]'s definition) of all of them, NaN sorted last.
pub fn spread(values: &[f64]) -> Option<Spread> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    let median = crate::stats::median_of_sorted(&v)?;
    let mean = v.iter().sum::<f64>() / n as f64;
    let sd =
        if n > 1 { (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt() } else { 0.0 };
    Some(Spread { median, min: v[0], max: v[n - 1], mean, sd })
}

fn one() -> u32 {
    1
}

/// A test stage's `STAGE/summary.json`: the best of its parent tested
/// before and after the world changed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestSummary {
    pub stage: String,
    pub learning: bool,
    /// The seed of the test's lives.
    pub seed: u64,
    /// The evolved stage whose best is tested.
    pub parent: String,
    #[serde(deserialize_with = "nan_if_null")]
    pub parent_fitness: f64,
    /// After the change: the fitness (mean per life) and the events.
    #[serde(deserialize_with = "nan_if_null")]
    pub fitness: f64,
    pub grips: u32,
    pub releases_outside: u32,
    /// The totals of the lives before the change, in the parent's world.
    pub before: WorldTotals,
    /// The totals of the lives after it, in the stage's world.
    pub after: WorldTotals,
    /// Lives per world (runs before `N lives of` wrote none: one).
    #[serde(default = "one")]
    pub lives: u32,
    /// The actions of each life before and after the change.
    #[serde(default)]
    pub before_lives: Vec<u32>,
    #[serde(default)]
    pub after_lives: Vec<u32>,
    /// Each learning module's mean reinforcement.
    #[serde(default)]
    pub reinforcement_mean: BTreeMap<String, ReinforcementMeans>,
    /// Each learning module's signals counted life by life.
    #[serde(default)]
    pub reinforcement_counts: BTreeMap<String, ReinforcementCounts>,
    /// Per variant of the parent's world (a world with variants only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub before_variants: Option<Vec<VariantLives>>,
    /// Per variant of the stage's world.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after_variants: Option<Vec<VariantLives>>,
    /// Only when a world was too crowded to place apart: the lives that
    /// overlapped and their overlapping placements.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crowded_lives: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement_failures: Option<u64>,
}

/// One world's lives together: the actions and events summed, the fitness
/// the mean per life.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldTotals {
    pub actions: u32,
    #[serde(deserialize_with = "nan_if_null")]
    pub fitness: f64,
    pub grips: u32,
    pub releases_outside: u32,
    pub recharges: u32,
    #[serde(default)]
    pub collisions: u32,
}

/// A variant's lives of a world (life `k` runs variant `k` mod their number).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VariantLives {
    pub variant: String,
    pub lives: usize,
    #[serde(deserialize_with = "nan_if_null")]
    pub fitness: f64,
}

/// A learning module's mean reinforcement over the lives before the
/// change, the first 100 actions after it and the rest (`None`: no signal).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReinforcementMeans {
    pub before: Option<f64>,
    pub after_first_100: Option<f64>,
    pub after_rest: Option<f64>,
}

/// A learning module's signals counted life by life in each world.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReinforcementCounts {
    pub before: Signals,
    pub after: Signals,
}

/// Per life, the positive (rewards) and negative (punishments) signals.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Signals {
    pub rewards: Vec<usize>,
    pub punishments: Vec<usize>,
}

/// An experiment's `summary.json` (one point, in the experiment's
/// directory) or a sweep's (a point per `--set` value, each in its own
/// directory).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExperimentSummary {
    /// The file's stem: the experiment's title.
    pub file: String,
    pub seeds: Vec<u64>,
    /// The sweep's `--set` targets and values (none: one point).
    pub sets: Vec<SweepSet>,
    pub points: Vec<PointSummary>,
    /// The tests between points (one point: its medians' intervals).
    pub tests: Tests,
}

impl ExperimentSummary {
    /// A sweep's: its points have directories of their own.
    pub fn is_sweep(&self) -> bool {
        !self.points.is_empty() && self.points.iter().all(|p| p.dir != ".")
    }
}

/// A `--set` of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepSet {
    pub target: String,
    pub values: Vec<String>,
}

/// A point of an experiment: its settings and its stages' figures over the seeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointSummary {
    /// `first.evolve.mutation=0.01` (empty without a sweep).
    pub name: String,
    /// Its directory in the experiment's (`.`: the experiment's own).
    pub dir: String,
    pub settings: BTreeMap<String, String>,
    pub stages: Vec<StageFigures>,
}

/// One stage's figures over the seeds of a point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum StageFigures {
    Evolve {
        stage: String,
        generations: u32,
        final_best: Option<Spread>,
        chosen_best: Option<Spread>,
        final_mean: Option<Spread>,
        best_ever: Option<Spread>,
        criterion: Option<CriterionFigures>,
    },
    Train {
        stage: String,
        actions: u32,
        performance: Option<Spread>,
    },
    Test {
        stage: String,
        actions: u32,
        lives: u32,
        learning: bool,
        fitness: Option<Spread>,
        grips: Option<Spread>,
        releases_outside: Option<Spread>,
    },
}

impl StageFigures {
    /// The stage's name.
    pub fn stage(&self) -> &str {
        match self {
            StageFigures::Evolve { stage, .. }
            | StageFigures::Train { stage, .. }
            | StageFigures::Test { stage, .. } => stage,
        }
    }
}

/// A criterion's figures: the generation reaching it, over the seeds that do.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CriterionFigures {
    pub fitness: f64,
    pub generation: Option<Spread>,
    pub unreached: u32,
}

/// A drive's `summary.json`: a robot's episode over its serial port.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DriveSummary {
    pub stage: String,
    pub seed: u64,
    pub port: String,
    pub baud: u32,
    pub period_ms: u64,
    pub actions: usize,
    pub seconds: f64,
    pub actions_per_second: f64,
    pub requests: u64,
    pub bytes: u64,
    /// The episode's result (none: the robot did not answer).
    pub fitness: Option<f64>,
    pub grips: Option<u32>,
    pub releases_outside: Option<u32>,
    pub recharges: Option<u32>,
    pub collisions: Option<u32>,
    /// What stopped the drive, if anything did.
    pub error: Option<String>,
}

// ------------------------------------------------ the tests of a comparison
// (`shaping compare`, a sweep's `tests`: computed in `compare`)

/// One group's figures of a measure.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GroupFigures {
    /// The seeds with a value.
    pub seeds: usize,
    pub median: Option<f64>,
    /// The bootstrap 95% interval of the median.
    pub interval: Option<Interval>,
}

/// The test of a pair of groups (`a` against `b`, numbered from 1).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PairTest {
    pub a: usize,
    pub b: usize,
    /// Mann-Whitney's U of `a`.
    pub u: Option<f64>,
    pub p_value: Option<f64>,
    /// Holm-corrected over the pairs of the measure (more than two groups only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p_holm: Option<f64>,
    /// The probability that a seed of `a` has the larger value (ties half).
    pub a12: Option<f64>,
    pub size: Option<Magnitude>,
    pub method: Option<Method>,
    /// Why there is no test (a side with fewer than 2 seeds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_test: Option<String>,
}

/// One measure of one stage, over the groups.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeasureTests {
    pub stage: String,
    pub measure: String,
    pub groups: Vec<GroupFigures>,
    pub pairs: Vec<PairTest>,
}

/// The comparison of groups: what `summary.json` keeps under `tests` and
/// `shaping compare` prints.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tests {
    /// The groups' names, numbered from 1 in the pairs.
    pub groups: Vec<String>,
    /// How the figures were computed, in words.
    pub method: String,
    pub holm: bool,
    pub measures: Vec<MeasureTests>,
}
