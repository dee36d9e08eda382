//! Result bytes pinned before the engine's and the teams' refactors (issues
//! 48 and 49: a typed edge, one path for one robot and a team): the
//! paper's program with seed 1 run whole, the team examples for a few
//! generations, and the summaries of an experiment with a sweep. A
//! refactor changes none of these bytes; a change of results updates the
//! pins in the same commit and says why.

mod common;

use std::path::Path;

use common::{experiment, files, load, options, root, tiny_experiment};
use shaping_engine::files::{unseal, Sealed};
use shaping_engine::run::RunOptions;
use shaping_engine::sweep::parse_set;
use shaping_engine::Engine;
use shaping_runtime::evolve::fingerprint::fnv1a;

/// The result files a run, an experiment or a sweep writes (not the
/// pictures, the report or anything else beside them), each as the hash of
/// its bytes (a sealed file's as the text it seals).
fn digest(dir: &Path) -> Vec<(String, u64)> {
    const RESULTS: [&str; 8] = [
        "checkpoint.json",
        "best.genome",
        "generations.csv",
        "summary.json",
        "summary.md",
        "episode.json",
        "trace.csv",
        "program.json",
    ];
    files(dir)
        .into_iter()
        .filter(|(name, _)| RESULTS.iter().any(|r| name == r || name.ends_with(&format!("/{r}"))))
        .map(|(name, bytes)| {
            let text = String::from_utf8_lossy(&bytes).into_owned();
            let body = match unseal(&text) {
                Sealed::Verified(body) => body.into_bytes(),
                Sealed::Unsealed(_) => bytes,
                Sealed::Damaged => panic!("{name}: damaged"),
            };
            (name, fnv1a(&body))
        })
        .collect()
}

fn check(what: &str, dir: &Path, want: &[(&str, u64)]) {
    let got = digest(dir);
    let got_ref: Vec<(&str, u64)> = got.iter().map(|(n, h)| (n.as_str(), *h)).collect();
    assert_eq!(got_ref, want, "{what}: {got:#x?}");
}

/// `shaping run examples/khepera.bat --seed 1`: its four stages whole.
#[test]
fn khepera_seed_1_writes_the_pinned_files() {
    let dir = tempfile::tempdir().unwrap();
    let program = load(&root().join("examples/khepera.bat"));
    Engine::default().run(program, &RunOptions { seed: Some(1), ..options(dir.path()) }).unwrap();
    check("khepera.bat seed 1", dir.path(), KHEPERA);
}

/// The team examples (clones, roles, a team that collects) with every
/// evolved stage cut to 3 generations of 12, seed 1.
#[test]
fn the_team_examples_write_the_pinned_files() {
    for (file, want) in [
        ("aggregation.bat", AGGREGATION),
        ("aggregation-roles.bat", AGGREGATION_ROLES),
        ("team-collect.bat", TEAM_COLLECT),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let program = load(&root().join("examples").join(file));
        let sets = [("*.evolve.generations", "3"), ("*.evolve.population", "12")];
        let opts = RunOptions {
            seed: Some(1),
            sets: sets.iter().map(|&(t, v)| (t.to_string(), v.to_string())).collect(),
            ..options(dir.path())
        };
        Engine::default().run(program, &opts).unwrap();
        check(file, dir.path(), want);
    }
}

/// An experiment of `tests/cli/tiny.bat` over two seeds and a sweep of two
/// points: every point's summaries and the sweep's table.
#[test]
fn an_experiments_and_a_sweeps_summaries_are_pinned() {
    let dir = tempfile::tempdir().unwrap();
    let opts = shaping_engine::experiment::ExperimentOptions {
        sets: vec![parse_set("first.evolve.mutation=0.01,0.2").unwrap()],
        jobs: Some(2),
        ..tiny_experiment(dir.path(), 2)
    };
    experiment(common::tiny(), opts).unwrap();
    check("sweep of tiny.bat", dir.path(), SWEEP);
    // The statistics (issue 51) were appended: without them, the summaries
    // are the bytes pinned before (`summary.json` 0xd4e4137643321c7c,
    // `summary.md` 0x808fc26fbee3eb0f).
    let json = std::fs::read_to_string(dir.path().join("summary.json")).unwrap();
    let value: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(value["tests"]["measures"].is_array(), "{json}");
    // `tests` is the last key: cut it out of the text.
    let (head, _) = json.split_once(",\n  \"tests\": ").unwrap();
    let before = format!("{head}\n}}\n");
    assert_eq!(fnv1a(before.as_bytes()), 0xd4e4137643321c7c, "{before}");
    let md = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
    let (table, tests) = md.split_once("\n## Tests between points").unwrap();
    assert_eq!(fnv1a(table.as_bytes()), 0x808fc26fbee3eb0f, "{table}");
    assert!(tests.contains("| p-value |") && tests.contains("1 vs 2"), "{tests}");
}

const KHEPERA: &[(&str, u64)] = &[
    ("avoidance/episode.json", 0xf3bbc44a29e67473),
    ("avoidance/trace.csv", 0x2d5177e69eff8aed),
    ("bigger/best.genome", 0xf0b854456ddd3f41),
    ("bigger/episode.json", 0xda2b8af8afc667d2),
    ("bigger/summary.json", 0x3ef40f5e0219a3b5),
    ("bigger/trace.csv", 0x691ca86f69042c9e),
    ("collect/best.genome", 0xf0b854456ddd3f41),
    ("collect/checkpoint.json", 0x5b0864f13e5acad6),
    ("collect/episode.json", 0xa1a07322b35c29d8),
    ("collect/generations.csv", 0xa661d989bf2daa6),
    ("navigation/best.genome", 0xcf762a66767d5337),
    ("navigation/checkpoint.json", 0x4b42853af76fd32f),
    ("navigation/episode.json", 0x1e4b2c3086d1c447),
    ("navigation/generations.csv", 0xb157bcc76f55e3bc),
    ("program.json", 0x4763726bad17a4e0),
];
const AGGREGATION: &[(&str, u64)] = &[
    ("aggregate/best.genome", 0xa3a43a0361712c62),
    ("aggregate/checkpoint.json", 0xcc2800a2129a8140),
    ("aggregate/episode.json", 0x5a2dfbb6987da462),
    ("aggregate/generations.csv", 0xd764438b93a8dba0),
    ("program.json", 0x3fc94b24ac7b4af2),
];
const AGGREGATION_ROLES: &[(&str, u64)] = &[
    ("aggregate/best.genome", 0xa8e00dc1c85e22ab),
    ("aggregate/checkpoint.json", 0x7af75c191ff8ef06),
    ("aggregate/episode.json", 0x30c6ead55c6b76ea),
    ("aggregate/generations.csv", 0x146e23413da53c3e),
    ("program.json", 0xe95c284b70aff586),
];
const TEAM_COLLECT: &[(&str, u64)] = &[
    ("avoidance/episode.json", 0xf3bbc44a29e67473),
    ("avoidance/trace.csv", 0x2d5177e69eff8aed),
    ("collect/best.genome", 0x9beb387b73a740f3),
    ("collect/checkpoint.json", 0x12558dd714cc379e),
    ("collect/episode.json", 0x114f80896f9b9313),
    ("collect/generations.csv", 0xc5eb1a27159230a9),
    ("navigation/best.genome", 0xc6c39239e13b902d),
    ("navigation/checkpoint.json", 0xd3aac4a5c69a364d),
    ("navigation/episode.json", 0xa2dc59a16762ef2b),
    ("navigation/generations.csv", 0xa3cf365ce6f1f5e5),
    ("program.json", 0x3344145fe01cbe31),
];
const SWEEP: &[(&str, u64)] = &[
    ("first.evolve.mutation=0.01/seed-1/first/best.genome", 0x3b9d1063b3b80e99),
    ("first.evolve.mutation=0.01/seed-1/first/checkpoint.json", 0xb9b01928ac27c4da),
    ("first.evolve.mutation=0.01/seed-1/first/episode.json", 0x372497fc73bc22ed),
    ("first.evolve.mutation=0.01/seed-1/first/generations.csv", 0x92a3f87326c20911),
    ("first.evolve.mutation=0.01/seed-1/program.json", 0xbc88388b57178823),
    ("first.evolve.mutation=0.01/seed-1/second/best.genome", 0x4c863108f24d6dde),
    ("first.evolve.mutation=0.01/seed-1/second/checkpoint.json", 0xb3ca9489bb55c2c9),
    ("first.evolve.mutation=0.01/seed-1/second/episode.json", 0xd0493efe14d9727e),
    ("first.evolve.mutation=0.01/seed-1/second/generations.csv", 0x3327dc517898d45c),
    ("first.evolve.mutation=0.01/seed-2/first/best.genome", 0x885573bfebde3b96),
    ("first.evolve.mutation=0.01/seed-2/first/checkpoint.json", 0xb3d5d47cd8d28e8e),
    ("first.evolve.mutation=0.01/seed-2/first/episode.json", 0x3a01dc8f60b058e8),
    ("first.evolve.mutation=0.01/seed-2/first/generations.csv", 0x4ce316a29ded3655),
    ("first.evolve.mutation=0.01/seed-2/program.json", 0xbc88388b57178823),
    ("first.evolve.mutation=0.01/seed-2/second/best.genome", 0xa419b15040768bbf),
    ("first.evolve.mutation=0.01/seed-2/second/checkpoint.json", 0x71c842b54c5b0de8),
    ("first.evolve.mutation=0.01/seed-2/second/episode.json", 0x1b919b658eee1226),
    ("first.evolve.mutation=0.01/seed-2/second/generations.csv", 0x14298954098d0240),
    ("first.evolve.mutation=0.01/summary.md", 0xdcdaffbefc7b994b),
    ("first.evolve.mutation=0.2/seed-1/first/best.genome", 0x7328e97b7eda856e),
    ("first.evolve.mutation=0.2/seed-1/first/checkpoint.json", 0x492bbb5f05dd22b3),
    ("first.evolve.mutation=0.2/seed-1/first/episode.json", 0x7139c19c43b6813d),
    ("first.evolve.mutation=0.2/seed-1/first/generations.csv", 0x33758cbee7370ae5),
    ("first.evolve.mutation=0.2/seed-1/program.json", 0x653e3675df184835),
    ("first.evolve.mutation=0.2/seed-1/second/best.genome", 0xb9735433b7158fe4),
    ("first.evolve.mutation=0.2/seed-1/second/checkpoint.json", 0xe77096201e33644b),
    ("first.evolve.mutation=0.2/seed-1/second/episode.json", 0xacd07ca3118f8308),
    ("first.evolve.mutation=0.2/seed-1/second/generations.csv", 0x2da31cec5c4e2687),
    ("first.evolve.mutation=0.2/seed-2/first/best.genome", 0xe3813f41bad4a843),
    ("first.evolve.mutation=0.2/seed-2/first/checkpoint.json", 0x65fd2c978d45313),
    ("first.evolve.mutation=0.2/seed-2/first/episode.json", 0xe33db570779025ae),
    ("first.evolve.mutation=0.2/seed-2/first/generations.csv", 0x2544b90fe2db4742),
    ("first.evolve.mutation=0.2/seed-2/program.json", 0x653e3675df184835),
    ("first.evolve.mutation=0.2/seed-2/second/best.genome", 0xc983ba52aff16cf3),
    ("first.evolve.mutation=0.2/seed-2/second/checkpoint.json", 0xa7457a3fc9fa844b),
    ("first.evolve.mutation=0.2/seed-2/second/episode.json", 0x453a7eaf4ea8f6a9),
    ("first.evolve.mutation=0.2/seed-2/second/generations.csv", 0x7400b864a706108d),
    ("first.evolve.mutation=0.2/summary.md", 0xca9eeeddaed0d351),
    // With the statistics appended (issue 51); the bytes before them are
    // checked in the test.
    ("summary.json", 0x55d46df4b061e596),
    ("summary.md", 0xc14616efee39d729),
];
