//! Fingerprints: what a saved result (a checkpoint, trained weights) was
//! computed from, part by part, so a run can tell whether the program
//! changed since, and say what changed.
//!
//! A result of stage `s` depends on the whole of `s` and on every evolved
//! stage it extends (it starts from their final populations). Trained
//! weights a stage uses are part of it: the CLI binds them into the program
//! (`Param::Trained` becomes the learned constant) before anything runs, so
//! they are hashed with the modules that use them, and a change in a
//! training stage that changes what it learned changes the stages using it.
//!
//! A [`Fingerprint`] lists one [`StagePrint`] per stage it depends on, the
//! result's own stage first. A stage print holds one hash per part of the
//! stage ([`PARTS`]): each part is serialized as compact `serde_json` (field
//! order is the declaration order, floats are printed shortest-roundtrip) and
//! hashed with 64-bit FNV-1a, so the value is the same on every platform and
//! run. The result's own `generations` is the one part not compared: raising
//! it extends a run (fewer generations than a checkpoint holds is refused by
//! [`super::check_resume`]).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::program::{Program, Stage, StageRun};

/// The parts of a stage a fingerprint hashes separately, in the order
/// [`changes`] names them.
pub const PARTS: [&str; 12] = [
    "position",
    "extends",
    "robot",
    "world",
    "modules",
    "links",
    "genes",
    "fitness",
    "settings",
    "generations",
    "inheritance",
    "variants",
];

/// The part of a result's own stage that may differ: its generations.
const OWN_FREE: &str = "generations";

/// One hash per part of a stage.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct StagePrint {
    pub stage: String,
    pub parts: BTreeMap<String, u64>,
}

/// The stages a result depends on, its own stage first.
pub type Fingerprint = Vec<StagePrint>;

/// 64-bit FNV-1a.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

fn hash<T: Serialize + ?Sized>(value: &T) -> u64 {
    // Serializing plain data with derived impls cannot fail; an empty string
    // would only weaken the check, never panic.
    fnv1a(serde_json::to_string(value).unwrap_or_default().as_bytes())
}

/// The print of stage `index` of `program` (an index past the end gives an
/// empty print, which differs from every stage's).
pub fn stage_print(program: &Program, index: usize) -> StagePrint {
    let Some(stage) = program.stages.get(index) else {
        return StagePrint { stage: format!("#{index}"), parts: BTreeMap::new() };
    };
    let Stage {
        name,
        parent,
        sensors,
        actuators,
        world,
        modules,
        links,
        layout,
        fitness,
        run,
        inheritance,
        variants,
        targets,
        roles,
    } = stage;
    let parent = parent.and_then(|p| program.stages.get(p)).map(|p| p.name.as_str());
    let (settings, generations) = match run {
        StageRun::Evolve(evo) => {
            let mut settings = evo.clone();
            settings.generations = 0;
            (hash(&StageRun::Evolve(settings)), hash(&evo.generations))
        }
        other => (hash(other), hash(&0u32)),
    };
    let values = [
        hash(&index),
        hash(&parent),
        hash(&(sensors, actuators)),
        hash(world),
        // The roles only where there are some (as the targets).
        if roles.is_empty() { hash(modules) } else { hash(&(modules, roles)) },
        hash(links),
        hash(layout),
        // The targets only where there are some, so the prints of stages
        // without them stay as they were.
        if targets.is_empty() { hash(fitness) } else { hash(&(fitness, targets)) },
        settings,
        generations,
        hash(inheritance),
        variants.as_ref().map_or(0, hash),
    ];
    // A stage without variants has no `variants` part: its print is the
    // one saved before variants existed.
    StagePrint {
        stage: name.clone(),
        parts: PARTS
            .iter()
            .zip(values)
            .filter(|(p, _)| **p != "variants" || variants.is_some())
            .map(|(p, v)| (p.to_string(), v))
            .collect(),
    }
}

/// The fingerprint of a result of stage `index`: the stage, then the evolved
/// stages it extends, nearest first.
pub fn fingerprint(program: &Program, index: usize) -> Fingerprint {
    // The stage, then the evolved stages it extends, nearest first (an
    // evolved stage starts from the nearest evolved ancestor).
    let evolved = |&i: &usize| matches!(program.stages[i].run, StageRun::Evolve(_));
    std::iter::once(index)
        .chain(program.lineage(index).skip(1).filter(evolved))
        .map(|i| stage_print(program, i))
        .collect()
}

/// One number for a fingerprint, its own `generations` left out (they may
/// grow): for files that hold many results of one stage, one per line (the
/// episodes of `run --robot`).
pub fn digest(print: &[StagePrint]) -> u64 {
    let mut print = print.to_vec();
    if let Some(own) = print.first_mut() {
        own.parts.remove(OWN_FREE);
    }
    hash(&print)
}

/// What differs between a saved fingerprint and the program's, in words,
/// one sentence per stage ("the fitness of `s` changed"): empty when the
/// saved result still belongs to the program. The result's own
/// `generations` is not compared.
pub fn changes(saved: &[StagePrint], now: &[StagePrint]) -> Vec<String> {
    let mut out = Vec::new();
    let (Some(own_saved), Some(own_now)) = (saved.first(), now.first()) else {
        if saved.len() != now.len() {
            out.push("the saved result names no stage".to_string());
        }
        return out;
    };
    if own_saved.stage != own_now.stage {
        out.push(format!("it was saved for stage `{}`, not `{}`", own_saved.stage, own_now.stage));
        return out;
    }
    let parts = |a: &StagePrint, b: &StagePrint, skip: Option<&str>| -> Vec<&'static str> {
        PARTS.iter().copied().filter(|&p| Some(p) != skip && a.parts.get(p) != b.parts.get(p)).collect()
    };
    let own = parts(own_saved, own_now, Some(OWN_FREE));
    if !own.is_empty() {
        out.push(format!("the {} of `{}` changed", join(&own), own_now.stage));
    }
    for dep in &now[1..] {
        match saved[1..].iter().find(|s| s.stage == dep.stage) {
            None => out.push(format!("`{}` now extends `{}`", own_now.stage, dep.stage)),
            Some(old) => {
                let diff = parts(old, dep, None);
                if !diff.is_empty() {
                    out.push(format!(
                        "the {} of `{}`, which `{}` extends, changed",
                        join(&diff),
                        dep.stage,
                        own_now.stage
                    ));
                }
            }
        }
    }
    for old in &saved[1..] {
        if !now[1..].iter().any(|s| s.stage == old.stage) {
            out.push(format!("`{}` no longer extends `{}`", own_now.stage, old.stage));
        }
    }
    out
}

/// `a`, `a and b`, `a, b and c`.
fn join(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
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

    #[test]
    fn lists_are_joined_in_words() {
        assert_eq!(join(&["fitness"]), "fitness");
        assert_eq!(join(&["fitness", "world"]), "fitness and world");
        assert_eq!(join(&["a", "b", "c"]), "a, b and c");
    }
}
