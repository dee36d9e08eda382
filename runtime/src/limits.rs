//! Resource limits of a program, shared by the compiler (a diagnostic on the
//! number) and [`crate::validate`] (a loaded `program.json`), so both accept
//! the same programs. Checked before anything is allocated.
//!
//! Decided from what the language is for (the paper's runs: a population of
//! 100, genomes of a few hundred bits, lives of a few thousand actions) and
//! from what a 24 GiB machine holds: a population is stored one byte per bit,
//! twice during breeding, plus its pretty-printed checkpoint (about
//! [`CHECKPOINT_BYTES_PER_BIT`]), so [`MAX_POPULATION_BITS`] bounds a run's
//! genomes to about 7 GiB; a replay's trace keeps one row (about 100 bytes
//! plus 4 per module) per action, so [`MAX_ACTIONS`] bounds it to about 1 GiB.

/// Most individuals in a population.
pub const MAX_POPULATION: u32 = 100_000;
/// Most generations of a stage.
pub const MAX_GENERATIONS: u32 = 1_000_000;
/// Longest life (or test, or replay), in actions; also the most actions of
/// a test stage in one world, all its lives together (lives times actions).
pub const MAX_ACTIONS: u32 = 10_000_000;
/// Most episodes averaged per evaluation.
pub const MAX_EVALUATIONS: u32 = 1_000;
/// Most variants of a stage's world (`variants { ... }`): an episode seed
/// names its variant in 8 bits.
pub const MAX_VARIANTS: usize = 64;
/// Most objects in a world (the simulator checks every object at every action).
pub const MAX_OBJECTS: u32 = 1_024;
/// Most inner walls, cylinders, lamps or floor zones a world may have (each).
pub const MAX_ITEMS: usize = 1_024;
/// Most robots in one world (`robots N`).
pub const MAX_ROBOTS: u32 = 10_000;
/// Longest genome of a stage, in bits.
pub const MAX_GENOME_BITS: u32 = 1 << 20;
/// Most bits of a whole population (population times genome bits).
pub const MAX_POPULATION_BITS: u64 = 1 << 29;
/// Most hidden units of a network.
pub const MAX_HIDDEN: u16 = 256;
/// Most modules in a stage (module indices are `u16`, and `links all` makes
/// n * (n - 1) links).
pub const MAX_MODULES: usize = 256;
/// Longest performance window of a learning module, in reinforcement
/// signals: each controller keeps the last `window` of them per module (4
/// bytes each), so a million is 4 MB a module, and a window longer than a
/// life of the longest lives could hardly fill.
pub const MAX_WINDOW: u32 = 1_000_000;
/// Most stages in a program (stage indices are `u16`; real files have a few).
pub const MAX_STAGES: usize = 64;
/// Longest length in a world (arena side, body, charger, lamp height,
/// objects), mm: 100 m, far beyond any Khepera arena, and small enough that
/// `f32` positions keep sub-millimetre precision.
pub const MAX_LENGTH_MM: f32 = 100_000.0;

/// Bytes of a checkpoint's JSON text per genome bit (each bit is a line of
/// the pretty-printed population).
pub const CHECKPOINT_BYTES_PER_BIT: u64 = 12;

/// Bytes a run of `population` individuals of `bits` bits needs at its peak:
/// the population, the next generation bred from it, and the checkpoint's
/// JSON text while it is written.
pub fn population_bytes(population: u64, bits: u64) -> u64 {
    population.saturating_mul(bits).saturating_mul(2 + CHECKPOINT_BYTES_PER_BIT)
}
