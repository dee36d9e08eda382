//! Stage fingerprints: a stable 64-bit hash per stage of what a checkpoint
//! depends on, so a resumed run can tell whether the program changed.
//!
//! Hashed: the stage's name, its parent, its inheritance mode, its genome
//! layout, and for an evolved stage every evolution parameter except
//! `generations` (raising it extends a run). Not hashed: the world, the
//! modules' wiring and the fitness (changing them keeps the genomes
//! meaningful). The bytes hashed are the compact `serde_json` serialization
//! of that selection (field order is the declaration order, floats are
//! printed shortest-roundtrip), hashed with 64-bit FNV-1a, so the value is
//! the same on every platform and run.

use serde::Serialize;

use crate::program::{Evolution, GenomeLayout, Inheritance, Selection, Stage, StageRun};

#[derive(Serialize)]
struct StageKey<'a> {
    name: &'a str,
    parent: Option<usize>,
    inheritance: Inheritance,
    layout: &'a GenomeLayout,
    run: RunKey,
}

#[derive(Serialize)]
enum RunKey {
    Train {
        actions: u32,
    },
    Evolve {
        population: u32,
        actions: u32,
        seed: u64,
        selection: Selection,
        crossover: f32,
        mutation: f32,
        elitism: u32,
        evaluations: u32,
    },
    Test,
}

/// 64-bit FNV-1a.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

/// The fingerprint of one stage (see the module doc for what it covers).
pub fn stage_fingerprint(stage: &Stage) -> u64 {
    let run = match &stage.run {
        StageRun::Evolve(Evolution {
            population,
            generations: _,
            actions,
            seed,
            selection,
            crossover,
            mutation,
            elitism,
            evaluations,
        }) => RunKey::Evolve {
            population: *population,
            actions: *actions,
            seed: *seed,
            selection: *selection,
            crossover: *crossover,
            mutation: *mutation,
            elitism: *elitism,
            evaluations: *evaluations,
        },
        StageRun::Test { .. } => RunKey::Test,
        StageRun::Train { actions } => RunKey::Train { actions: *actions },
    };
    let key = StageKey {
        name: &stage.name,
        parent: stage.parent,
        inheritance: stage.inheritance,
        layout: &stage.layout,
        run,
    };
    // Serializing plain data with derived impls cannot fail; an empty string
    // would only weaken the check, never panic.
    let text = serde_json::to_string(&key).unwrap_or_default();
    fnv1a(text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_reference_values() {
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
    }
}
