//! The stage pipeline and run directories, called as a library: what a run
//! writes, and the run directories a user can trust (a lock, temporary
//! files that follow no link, nothing written before the checks pass,
//! damage refused, not used).

mod common;

use std::cell::Cell;
use std::sync::{Arc, Barrier};

use common::{files, options, read_text, root, tiny, Holding};
use shaping_engine::files::{unseal, Sealed};
use shaping_engine::run::{Event, Observer, RunOptions, StageOutcome};
use shaping_engine::Engine;
use shaping_engine::{html, replay, ErrorKind};
use shaping_runtime::evolve::fingerprint::fnv1a;
use shaping_runtime::program::Program;

/// A run's files as hashes (a sealed file as the text it seals: the files
/// as they were before checksums, byte for byte).
fn hashes(dir: &std::path::Path) -> Vec<(String, u64)> {
    files(dir)
        .into_iter()
        .filter(|(name, _)| !name.ends_with(".png") && !name.ends_with(".svg"))
        .map(|(name, bytes)| {
            let text = String::from_utf8_lossy(&bytes).into_owned();
            let unsealed = match unseal(&text) {
                Sealed::Verified(body) => body.into_bytes(),
                Sealed::Unsealed(_) => bytes.clone(),
                Sealed::Damaged => panic!("{name}: damaged"),
            };
            (name, fnv1a(&unsealed))
        })
        .collect()
}

/// The files of a small run are those this program wrote before it was a
/// library (measured with the binary of commit b8f1daf, `shaping run
/// tests/cli/tiny.bat --no-report`), apart from the checksums the saved
/// results gain; pinned again when the simulator's generator became
/// xoshiro256++ (every episode changed; `program.json` did not).
#[test]
fn a_small_run_writes_the_same_files_as_before() {
    let dir = tempfile::tempdir().unwrap();
    let outcome = Engine::default().run(tiny(), &options(dir.path())).unwrap();
    let names: Vec<&str> = outcome.stages.iter().map(StageOutcome::stage).collect();
    assert_eq!(names, ["first", "second"]);
    let got = hashes(dir.path());
    let want: Vec<(&str, u64)> = PINNED.to_vec();
    let got_ref: Vec<(&str, u64)> = got.iter().map(|(n, h)| (n.as_str(), *h)).collect();
    assert_eq!(got_ref, want, "{got:#x?}");
    // The saved results are sealed.
    for name in ["first/checkpoint.json", "second/checkpoint.json"] {
        let text = std::fs::read_to_string(dir.path().join(name)).unwrap();
        assert!(matches!(unseal(&text), Sealed::Verified(_)), "{name}");
    }
}

/// fnv1a of each file of `shaping run tests/cli/tiny.bat --no-report` (the
/// pictures aside: their encoder is another crate's); each stage's `.seals`
/// (the checksums of its files) added when runs began to seal every file a
/// report or a resume reads, the other files unchanged.
const PINNED: &[(&str, u64)] = &[
    ("first/.seals", 0x571f0eba4bae61e2),
    ("first/best.genome", 0x480214959a4a19aa),
    ("first/checkpoint.json", 0x0476320b9b84f2e8),
    ("first/episode.json", 0x977c6fa353614cc2),
    ("first/generations.csv", 0xdfecbecec9f0e684),
    ("program.json", 0xbc88388b57178823),
    ("second/.seals", 0x8b7b5a7a765e4ee1),
    ("second/best.genome", 0xfdd3778abd260c7b),
    ("second/checkpoint.json", 0x2afa799289edab2c),
    ("second/episode.json", 0x990715aaf5b51c54),
    ("second/generations.csv", 0xc8fb2410d912abd1),
];

/// Each evolved stage writes its statistics, best genome, checkpoint and
/// fitness pictures, the same on one thread as on two; `generations.csv`
/// closes every row with the best individual's events, as counts.
#[test]
fn a_run_writes_its_files_the_same_on_one_or_two_threads() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    Engine::default().run(tiny(), &RunOptions { jobs: Some(1), ..options(a.path()) }).unwrap();
    Engine::default().run(tiny(), &options(b.path())).unwrap();
    for stage in ["first", "second"] {
        for f in ["generations.csv", "best.genome", "checkpoint.json", "fitness.svg", "fitness.png"] {
            assert!(a.path().join(stage).join(f).exists(), "{stage}/{f}");
        }
        let ca = std::fs::read(a.path().join(stage).join("checkpoint.json")).unwrap();
        let cb = std::fs::read(b.path().join(stage).join("checkpoint.json")).unwrap();
        assert!(ca == cb, "stage {stage}: 1 and 2 threads differ");
    }
    let csv = read_text(&a.path().join("second/generations.csv"));
    assert_eq!(csv.lines().count(), 1 + 10, "{csv}");
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    assert_eq!(header[header.len() - 3..], ["best_recharges", "best_grips", "best_releases_outside"]);
    for line in csv.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len(), "{line}");
        assert!(cells[cells.len() - 3..].iter().all(|c| c.parse::<u32>().is_ok()), "{line}");
    }
}

#[test]
fn a_second_run_into_a_directory_in_use_is_refused_and_the_first_finishes_unharmed() {
    let dir = tempfile::tempdir().unwrap();
    let straight = tempfile::tempdir().unwrap();
    Engine::default().run(tiny(), &options(straight.path())).unwrap();
    let barrier = Arc::new(Barrier::new(2));
    let out = dir.path().to_path_buf();
    let first = {
        let barrier = Arc::clone(&barrier);
        std::thread::spawn(move || {
            let observer = Holding::new(barrier);
            let runner = Engine { observer: &observer, ..Engine::default() };
            runner.run(tiny(), &options(&out)).map(|_| ())
        })
    };
    barrier.wait();
    let err = Engine::default().run(tiny(), &options(dir.path())).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::Locked, "{err}");
    assert!(err.message().contains("is in use by another run of this process"), "{err}");
    assert!(err.message().contains(&format!("process {}", std::process::id())), "{err}");
    // The directory and its holder as data.
    assert_eq!(err.path(), Some(dir.path()), "{err}");
    assert!(err.holder().is_some_and(|h| h.ends_with(&format!("process {}", std::process::id()))), "{err}");
    barrier.wait();
    first.join().unwrap().unwrap();
    assert_eq!(files(dir.path()), files(straight.path()), "the first run's files are a straight run's");
}

#[cfg(unix)]
#[test]
fn a_link_planted_at_a_temporary_name_is_not_followed() {
    let dir = tempfile::tempdir().unwrap();
    let victim = dir.path().join("victim");
    std::fs::write(&victim, "precious").unwrap();
    let out = dir.path().join("run");
    std::fs::create_dir_all(out.join("first")).unwrap();
    for name in ["best.genome.tmp", "checkpoint.json.tmp", "generations.csv.tmp"] {
        std::os::unix::fs::symlink(&victim, out.join("first").join(name)).unwrap();
    }
    std::os::unix::fs::symlink(&victim, out.join("program.json.tmp")).unwrap();
    Engine::default().run(tiny(), &options(&out)).unwrap();
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    let best = out.join("first/best.genome");
    assert!(!std::fs::symlink_metadata(&best).unwrap().file_type().is_symlink());
    assert!(std::fs::read_to_string(best).unwrap().trim().chars().all(|c| c == '0' || c == '1'));
}

#[test]
fn a_refused_run_has_written_nothing() {
    let dir = tempfile::tempdir().unwrap();
    Engine::default().run(tiny(), &options(dir.path())).unwrap();
    let before = files(dir.path());
    // The world of the first stage changed since: its checkpoint no longer fits.
    let mut changed = tiny();
    changed.stages[0].world.arena[0] *= 2.0;
    changed.stages[1].world.arena[0] *= 2.0;
    let err = Engine::default().run(changed, &options(dir.path())).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    assert!(err.message().contains("world"), "{err}");
    assert_eq!(files(dir.path()), before, "program.json and every other file as they were");
}

#[test]
fn a_checkpoint_changed_by_one_digit_is_refused_not_resumed() {
    let dir = tempfile::tempdir().unwrap();
    let mut opts = options(dir.path());
    opts.stage = Some("first".into());
    Engine::default().run(tiny(), &opts).unwrap();
    let path = dir.path().join("first/checkpoint.json");
    let text = std::fs::read_to_string(&path).unwrap();
    // One bit of the population's first genome.
    let at = text.find("\"bits\": [").unwrap() + "\"bits\": [".len();
    let digit = text[at..].find(['0', '1']).unwrap() + at;
    let flipped = if &text[digit..=digit] == "0" { "1" } else { "0" };
    let damaged = format!("{}{flipped}{}", &text[..digit], &text[digit + 1..]);
    std::fs::write(&path, &damaged).unwrap();
    let err = Engine::default().run(tiny(), &options(dir.path())).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::Corrupt, "{err}");
    assert!(err.message().contains("checkpoint.json"), "{err}");
    assert!(err.message().contains("checksum does not match"), "{err}");
    assert_eq!(err.path(), Some(path.as_path()), "{err}");
    assert_eq!(err.problem(), Some("its checksum does not match its contents"), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), damaged, "the damaged file is kept");
}

#[test]
fn an_edited_best_genome_is_refused_by_replay_and_the_report() {
    let dir = tempfile::tempdir().unwrap();
    Engine::default().run(tiny(), &options(dir.path())).unwrap();
    let path = dir.path().join("second/best.genome");
    let text = std::fs::read_to_string(&path).unwrap();
    let edited: String = text
        .trim()
        .chars()
        .enumerate()
        .map(|(i, c)| {
            if i == 0 {
                if c == '0' {
                    '1'
                } else {
                    '0'
                }
            } else {
                c
            }
        })
        .collect();
    std::fs::write(&path, format!("{edited}\n")).unwrap();
    let file = root().join("tests/cli/tiny.bat");
    let err =
        replay::choose(tiny(), &file, Some("second"), None, Some(dir.path()), &shaping_engine::run::Silent)
            .err()
            .expect("refused");
    assert_eq!(err.kind(), ErrorKind::Corrupt, "{err}");
    assert!(err.message().contains("best.genome") && err.message().contains("checkpoint"), "{err}");
    let err = html::write(dir.path(), None).unwrap_err();
    assert!(err.message().contains("best.genome"), "{err}");
    // Derived anew from the checkpoint, it is accepted again.
    std::fs::remove_file(&path).unwrap();
    Engine::default().run(tiny(), &options(dir.path())).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
}

#[test]
fn a_run_resumed_is_the_run_straight_and_tells_its_observer() {
    struct Count(Cell<u32>, Cell<u32>);
    impl Observer for Count {
        fn event(&self, event: Event<'_>) {
            match event {
                Event::Generation { .. } => self.0.set(self.0.get() + 1),
                Event::Resumed { finished: true, .. } => self.1.set(self.1.get() + 1),
                _ => {}
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let count = Count(Cell::new(0), Cell::new(0));
    let runner = Engine { observer: &count, ..Engine::default() };
    runner.run(tiny(), &options(dir.path())).unwrap();
    assert_eq!(count.0.get(), 10, "6 + 4 generations");
    let before = files(dir.path());
    runner.run(tiny(), &options(dir.path())).unwrap();
    assert_eq!(count.1.get(), 2, "both stages done before");
    assert_eq!(files(dir.path()), before);
}

fn khepera() -> Program {
    let path = root().join("examples/khepera.bat");
    shaping_engine::load::load_program(&path, shaping_engine::diag::ErrorFormat::Plain).unwrap().0
}

/// Inheritance is set on the evolved stages named (and those that
/// inherit it), whatever other stages the file has; `*` sets every
/// evolved stage.
#[test]
fn inheritance_is_set_in_a_file_with_stages_that_do_not_evolve() {
    use shaping_runtime::program::Inheritance;
    let lamarck = |t: &str| vec![(t.to_string(), "lamarckian".to_string())];
    let mut p = khepera();
    shaping_engine::sweep::apply(&mut p, &lamarck("collect.evolve.inheritance")).unwrap();
    assert_eq!(p.stage("collect").unwrap().1.inheritance, Inheritance::Lamarckian);
    let mut p = khepera();
    shaping_engine::sweep::apply(&mut p, &lamarck("*.evolve.inheritance")).unwrap();
    for name in ["navigation", "collect"] {
        assert_eq!(p.stage(name).unwrap().1.inheritance, Inheritance::Lamarckian, "{name}");
    }
    let err =
        shaping_engine::sweep::apply(&mut khepera(), &lamarck("bigger.evolve.inheritance")).unwrap_err();
    assert!(err.message().contains("stage `bigger` does not evolve"), "{err}");
}

/// A point's directory names what varies, never `*`.
#[test]
fn a_point_directory_names_what_varies_and_holds_no_star() {
    use shaping_engine::sweep::{parse_set, point_dir_name};
    let sets =
        [parse_set("*.evolve.mutation=0.01,0.02").unwrap(), parse_set("first.evolve.generations=3").unwrap()];
    let point = vec![
        ("*.evolve.mutation".to_string(), "0.02".to_string()),
        ("first.evolve.generations".to_string(), "3".to_string()),
    ];
    assert_eq!(point_dir_name(&point, &sets), "all.evolve.mutation=0.02");
    assert_eq!(point_dir_name(&point[1..], &sets[1..]), "first.evolve.generations=3");
}

/// An experiment's summaries show the values that ran (`--set`), not the
/// file's, and its report the seeds they cover.
#[test]
fn an_experiment_summarises_the_settings_that_ran() {
    use shaping_engine::experiment::{ExperimentOptions, Plan};
    use shaping_engine::sweep::parse_set;
    let dir = tempfile::tempdir().unwrap();
    let opts = ExperimentOptions {
        file: root().join("tests/cli/tiny.bat"),
        seeds: 2,
        first_seed: 1,
        out: Some(dir.path().to_path_buf()),
        sets: vec![parse_set("first.evolve.generations=2").unwrap()],
        stage: Some("first".into()),
        no_report: true,
        ..ExperimentOptions::default()
    };
    let plan = Plan::new(tiny(), opts).unwrap();
    let _lock = plan.lock().unwrap();
    for task in plan.tasks() {
        plan.run_task(task, Some(1), &Engine::default()).unwrap();
    }
    plan.finish().unwrap();
    let md = std::fs::read_to_string(dir.path().join("first.evolve.generations=2/summary.md")).unwrap();
    assert!(md.contains("| first | 2 |"), "{md}");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["points"][0]["stages"][0]["generations"], 2, "{summary}");
    assert_eq!(summary["points"][0]["dir"], "first.evolve.generations=2");
    // Mean and standard deviation beside median and range.
    let chosen = &summary["points"][0]["stages"][0]["chosen_best"];
    let (lo, hi, mean, sd) = (
        chosen["min"].as_f64().unwrap(),
        chosen["max"].as_f64().unwrap(),
        chosen["mean"].as_f64().unwrap(),
        chosen["sd"].as_f64().unwrap(),
    );
    assert!((mean - (lo + hi) / 2.0).abs() < 1e-9, "two seeds: the mean is the middle: {chosen}");
    assert!((sd - (hi - lo) / 2f64.sqrt()).abs() < 1e-9, "two seeds: sd = range / sqrt 2: {chosen}");
    // A second experiment into the directory while this one holds it is refused.
    let again = Plan::new(
        tiny(),
        ExperimentOptions { out: Some(dir.path().to_path_buf()), seeds: 1, ..ExperimentOptions::default() },
    )
    .unwrap();
    assert_eq!(again.lock().unwrap_err().kind(), ErrorKind::Locked);
}
