//! Seed derivation: every random stream of a run is a pure function of the
//! run seed and its coordinates, so results do not depend on thread count,
//! scheduling, or where a run was checkpointed.
//!
//! Mixing function: `h = splitmix64(run_seed)`, then for each coordinate `p`
//! (a domain tag first, then stage, generation, ...) `h = splitmix64(h ^ p)`.
//! `splitmix64` is the finaliser of Steele, Lea & Flood's SplitMix64 generator
//! (add the golden-ratio increment, then two xor-shift-multiply rounds). The
//! result seeds a `ChaCha8Rng` through `SeedableRng::seed_from_u64`.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Domain tags keep the streams apart (ASCII of the name).
const DOMAIN_INIT: u64 = 0x494e_4954; // "INIT"
const DOMAIN_BREED: u64 = 0x0042_5245_4544; // "BREED"
const DOMAIN_EVAL: u64 = 0x4556_414c; // "EVAL"
const DOMAIN_TEST: u64 = 0x5445_5354; // "TEST"
const DOMAIN_VALIDATE: u64 = 0x5641_4c49_4441_5445; // "VALIDATE"
const DOMAIN_LIFE: u64 = 0x4c49_4645; // "LIFE"
const DOMAIN_DRAW: u64 = 0x4452_4157; // "DRAW"

/// What the simulator seed of a test stage's first life in its own world
/// differs from the episode seed by (xor): the one-life test's derivation.
const AFTER_CHANGE: u64 = 0x9e37_79b9_7f4a_7c15;

/// One SplitMix64 step: a bijective 64-bit mixer.
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Folds coordinates into the run seed (see the module doc).
pub fn mix(run_seed: u64, parts: &[u64]) -> u64 {
    parts.iter().fold(splitmix64(run_seed), |h, &p| splitmix64(h ^ p))
}

/// Seed of one episode: stage index, generation within the stage (0-based),
/// individual index in the population, and episode number within the
/// individual's evaluation (0-based, for `evaluations > 1`).
pub fn episode_seed(run_seed: u64, stage: usize, generation: u32, index: usize, episode: u32) -> u64 {
    mix(run_seed, &[DOMAIN_EVAL, stage as u64, generation as u64, index as u64, episode as u64])
}

/// Seed of the GA's RNG that breeds generation `generation` (>= 1) of a stage
/// from the evaluated generation before it.
pub fn breed_seed(run_seed: u64, stage: usize, generation: u32) -> u64 {
    mix(run_seed, &[DOMAIN_BREED, stage as u64, generation as u64])
}

/// Seed of the RNG drawing a stage's initial population (its new genes).
pub fn init_seed(run_seed: u64, stage: usize) -> u64 {
    mix(run_seed, &[DOMAIN_INIT, stage as u64])
}

/// Seed of episode `episode` of a test stage.
pub fn test_seed(run_seed: u64, stage: usize, episode: u32) -> u64 {
    mix(run_seed, &[DOMAIN_TEST, stage as u64, episode as u64])
}

/// Simulator seed of life `life` (0-based) of a test stage whose episode
/// seed is `episode_seed` (from [`test_seed`]), in the parent's world
/// (`after` false) or in the stage's own world (`after` true). Life 0 is the
/// one-life test's: the episode seed itself before the change, and the
/// episode seed xor `0x9e37_79b9_7f4a_7c15` after it. Life `k > 0` of a world
/// is `mix(s0, [LIFE, k])`, `s0` being that world's life-0 seed.
pub fn test_life_seed(episode_seed: u64, after: bool, life: u32) -> u64 {
    let first = if after { episode_seed ^ AFTER_CHANGE } else { episode_seed };
    if life == 0 {
        first
    } else {
        mix(first, &[DOMAIN_LIFE, life as u64])
    }
}

/// Seed of episode `episode` of the re-evaluation that picks a stage's best.
pub fn validate_seed(run_seed: u64, stage: usize, episode: u32) -> u64 {
    mix(run_seed, &[DOMAIN_VALIDATE, stage as u64, episode as u64])
}

/// The low bits of an episode seed that [`variant_seed`] replaces: 8.
const VARIANT_MASK: u64 = 0xff;

// Every variant's seeds differ from every other's only while the variants
// fit in the replaced bits.
const _: () = assert!(crate::limits::MAX_VARIANTS as u64 <= VARIANT_MASK + 1);

/// The seed of episode `seed` in variant `variant` of a stage with
/// variants: `seed` with its low 8 bits replaced by the variant's index, so
/// each variant's episode has a seed of its own (the variant itself travels
/// in [`super::Episode::variant`], never read back from the seed).
pub fn variant_seed(seed: u64, variant: usize) -> u64 {
    (seed & !VARIANT_MASK) | (variant as u64 & VARIANT_MASK)
}

/// Seed of the RNG that draws the variants generation `generation` of a
/// stage is evaluated in (`variants ... draw N`).
pub fn draw_seed(run_seed: u64, stage: usize, generation: u32) -> u64 {
    mix(run_seed, &[DOMAIN_DRAW, stage as u64, generation as u64])
}

pub(crate) fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_matches_reference_values() {
        // First outputs of the reference SplitMix64 generator seeded with 0:
        // its state advances by the increment, then the same finaliser runs.
        assert_eq!(splitmix64(0), 0xe220_a839_7b1d_cdaf);
        assert_eq!(splitmix64(0x9e37_79b9_7f4a_7c15), 0x6e78_9e6a_a1b9_65f4);
    }

    #[test]
    fn coordinates_give_distinct_seeds() {
        let a = episode_seed(1, 0, 0, 0, 0);
        assert_ne!(a, episode_seed(1, 0, 0, 1, 0));
        assert_ne!(a, episode_seed(1, 0, 1, 0, 0));
        assert_ne!(a, episode_seed(1, 1, 0, 0, 0));
        assert_ne!(a, episode_seed(2, 0, 0, 0, 0));
        assert_ne!(breed_seed(1, 0, 1), init_seed(1, 0));
        assert_eq!(a, episode_seed(1, 0, 0, 0, 0));
    }

    #[test]
    fn test_lives_keep_the_one_life_seeds_and_differ() {
        let e = test_seed(1, 3, 0);
        assert_eq!(test_life_seed(e, false, 0), e);
        assert_eq!(test_life_seed(e, true, 0), e ^ 0x9e37_79b9_7f4a_7c15);
        let mut all: Vec<u64> =
            (0..50).flat_map(|k| [test_life_seed(e, false, k), test_life_seed(e, true, k)]).collect();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all.len(), 100, "every life of both worlds has its own seed");
    }
}
