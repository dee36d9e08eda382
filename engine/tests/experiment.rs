//! Experiments and sweeps, called as a library: a point of a sweep is the
//! run with its settings, settings are checked before anything is written,
//! a stopped sweep resumes, and the summaries and reports show what ran.

mod common;

use std::path::Path;
use std::sync::atomic::AtomicBool;

use common::{
    as_if_killed, error, experiment, options, read_json, read_text, report_data, result_files, run, sets,
    tiny, tiny_experiment, StopAfter,
};
use shaping_engine::experiment::{ExperimentOptions, Plan};
use shaping_engine::run::RunOptions;
use shaping_engine::sweep::parse_set;
use shaping_engine::Engine;
use shaping_engine::ErrorKind;

/// The sweep of the tests: two mutation rates by two battery sizes, two seeds.
fn sweep(out: &Path) -> ExperimentOptions {
    ExperimentOptions {
        sets: vec![
            parse_set("first.evolve.mutation=0.01,0.2").unwrap(),
            parse_set("first.world.battery=100,300").unwrap(),
        ],
        jobs: Some(1),
        ..tiny_experiment(out, 2)
    }
}

/// A sweep runs every point of the cartesian product over every seed, each
/// point's seed writing what a run with the same settings writes, and
/// tables every point in `summary.md` and `summary.json`.
#[test]
fn a_sweep_point_is_the_run_with_its_settings() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    experiment(tiny(), sweep(&d.join("sweep"))).unwrap();
    let point = "first.evolve.mutation=0.2,first.world.battery=100";
    let alone = d.join("alone");
    let opts = RunOptions {
        seed: Some(2),
        sets: sets(&["first.evolve.mutation=0.2", "first.world.battery=100"]),
        ..options(&alone)
    };
    // As `shaping run tiny.bat` runs it (the file's name in `source.json`).
    Engine::default().run_file(tiny(), &common::tiny_bat(), &opts).unwrap();
    let in_sweep = result_files(&d.join("sweep").join(point).join("seed-2"));
    assert!(in_sweep.len() >= 6, "{in_sweep:?}");
    let names = |v: &[(String, Vec<u8>)]| v.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
    assert_eq!(names(&in_sweep), names(&result_files(&alone)));
    assert!(in_sweep == result_files(&alone), "the sweep's point differs from the run with its settings");
    // The settings reach the program: both stages (the second inherits the mutation).
    let program = read_json(&alone.join("program.json"));
    for stage in 0..2 {
        let s = &program["stages"][stage];
        assert!((s["run"]["Evolve"]["mutation"].as_f64().unwrap() - 0.2).abs() < 1e-6, "{}", s["name"]);
        assert_eq!(s["world"]["battery"]["capacity"], 100);
    }
    // And they change the results: another mutation rate evolves otherwise.
    let other =
        d.join("sweep/first.evolve.mutation=0.01,first.world.battery=100/seed-2/first/generations.csv");
    let this = d.join("sweep").join(point).join("seed-2/first/generations.csv");
    assert_ne!(std::fs::read(other).unwrap(), std::fs::read(this).unwrap());

    let summary = read_json(&d.join("sweep/summary.json"));
    let points = summary["points"].as_array().unwrap();
    assert_eq!(points.len(), 4);
    assert_eq!(points[2]["name"], point);
    assert_eq!(points[2]["settings"]["first.world.battery"], "100");
    let first = &points[2]["stages"][0];
    assert_eq!(first["stage"], "first");
    // The chosen best of each seed is the one in its checkpoint.
    let chosen: Vec<f64> = (1..=2)
        .map(|s| {
            let cp = read_json(&d.join("sweep").join(point).join(format!("seed-{s}/first/checkpoint.json")));
            cp["best"][1].as_f64().unwrap()
        })
        .collect();
    let (lo, hi) = (chosen[0].min(chosen[1]), chosen[0].max(chosen[1]));
    assert!((first["chosen_best"]["min"].as_f64().unwrap() - lo).abs() < 1e-6, "{first}");
    assert!((first["chosen_best"]["max"].as_f64().unwrap() - hi).abs() < 1e-6, "{first}");
    assert!((first["chosen_best"]["median"].as_f64().unwrap() - (lo + hi) / 2.0).abs() < 1e-6, "{first}");
    let md = read_text(&d.join("sweep/summary.md"));
    let head =
        "| point | `first.evolve.mutation` | `first.world.battery` | first final best | first chosen best |";
    assert!(md.contains(head), "{md}");
    assert!(md.contains("| 3 | 0.2 | 100 | "), "{md}");
    // One row per point in the table (the tests between points follow it).
    let table = md.split("\n## Tests between points").next().unwrap();
    assert_eq!(table.lines().filter(|l| l.starts_with("| ") && l.contains(" | 0.")).count(), 4, "{md}");
    assert!(d.join("sweep/sweep.svg").exists() && d.join("sweep/sweep.png").exists());
    assert!(d.join("sweep").join(point).join("summary.md").exists(), "no summary of the point");
}

/// A value set on a stage goes to the stages extending it that had the same
/// value (inherited), not to one that sets its own.
#[test]
fn a_set_value_is_inherited_like_a_written_one() {
    let dir = tempfile::tempdir().unwrap();
    run(tiny(), &RunOptions { sets: sets(&["first.evolve.generations=3"]), ..options(dir.path()) }).unwrap();
    let program = read_json(&dir.path().join("program.json"));
    assert_eq!(program["stages"][0]["run"]["Evolve"]["generations"], 3);
    assert_eq!(program["stages"][1]["run"]["Evolve"]["generations"], 4, "`second` sets its own");
    let csv = read_text(&dir.path().join("first/generations.csv"));
    assert_eq!(csv.lines().count(), 4, "a header and 3 generations:\n{csv}");
}

/// The message of an experiment of `tests/cli/tiny.bat` with `--set`
/// values `texts` that cannot run, as the command line reads them (the
/// syntax, then the plan); the plan writes nothing into `out`.
fn refused(out: &Path, texts: &[&str], criterion: &[&str]) -> String {
    let mut parsed = Vec::new();
    for text in texts {
        match parse_set(text) {
            Ok(set) => parsed.push(set),
            Err(e) => return e,
        }
    }
    let opts = ExperimentOptions {
        sets: parsed,
        criterion: criterion.iter().map(|c| c.to_string()).collect(),
        ..tiny_experiment(out, 1)
    };
    let err = error(Plan::new(tiny(), opts));
    assert!(!out.exists(), "{texts:?}: files written before the error");
    err.message().to_string()
}

#[test]
fn bad_set_values_are_errors_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let x = dir.path().join("x");
    let cases: [(&str, &[&str]); 11] = [
        ("frist.evolve.mutation=0.1", &["no stage `frist`", "did you mean `first`?"]),
        ("first.evolve.mutatoin=0.1", &["no setting `evolve.mutatoin`", "did you mean `evolve.mutation`?"]),
        (
            "first.evolve.mutation=0.1,1.5",
            &["`--set first.evolve.mutation=1.5`", "1.5 is not between 0 and 1"],
        ),
        ("first.evolve.population=many", &["`many` is not a whole number"]),
        ("first.evolve.keep=40", &["selection.keep", "40 is not between 1 and 12"]),
        ("first.wandr.reward=0.5", &["no module `wandr`", "did you mean `wander`?"]),
        ("first.wander.reward=0.5", &["module `wander` of stage `first` does not learn"]),
        ("second.wander.range=-2..2", &["introduced by stage `first`", "set `first.wander.range`"]),
        ("first.world.objects=3", &["the world of stage `first` has no objects"]),
        ("first.evolve.selection=random", &["`random` is not one of truncation, roulette"]),
        ("first.evolve.seed=4", &["use `--seed` (`run`) or `--seeds`"]),
    ];
    for (set, wanted) in cases {
        let err = refused(&x, &[set], &[]);
        for w in wanted {
            assert!(err.contains(w), "--set {set}: `{w}` missing from:\n{err}");
        }
    }
    let err = error(Plan::new(
        tiny(),
        ExperimentOptions {
            stage: Some("first".into()),
            criterion: vec!["second=0.5".into()],
            ..tiny_experiment(&x, 1)
        },
    ));
    assert_eq!(err.kind(), ErrorKind::Invalid, "{err}");
    assert!(err.message().contains("stage `second` is not run with `--stage first`"), "{err}");
    let err = refused(&x, &["first.evolve.seed=1", "first.evolve.seed=2"], &[]);
    assert!(err.contains("given twice"), "{err}");
}

/// `world.robots` and `fitness.team` reach the stage and the stages that
/// inherit them; a team too large for the start region, or above the
/// limit, is refused with a message naming the setting.
#[test]
fn a_team_is_set_and_one_too_large_is_refused() {
    use shaping_engine::sweep::apply;
    use shaping_runtime::program::Aggregate;
    let set = |t: &str, v: &str| vec![(t.to_string(), v.to_string())];
    let mut p = tiny();
    assert_eq!((p.stages[0].world.robots, p.stages[0].fitness.team), (1, Aggregate::Mean));
    apply(&mut p, &set("first.world.robots", "4")).unwrap();
    apply(&mut p, &set("first.fitness.team", "sum")).unwrap();
    for s in &p.stages {
        assert_eq!((s.world.robots, s.fitness.team), (4, Aggregate::Sum), "{}", s.name);
    }
    apply(&mut p, &set("second.fitness.team", "min")).unwrap();
    assert_eq!((p.stages[0].fitness.team, p.stages[1].fitness.team), (Aggregate::Sum, Aggregate::Min));
    // The arena of 400 x 600 mm holds 7 Kheperas without a `start`.
    apply(&mut tiny(), &set("first.world.robots", "7")).unwrap();
    let cases: [(&str, &str, &[&str]); 6] = [
        ("first.evolve.nothing", "2", &["`--set first.evolve.nothing=2`"]),
        ("nope.evolve.generations", "2", &["there is no stage `nope`"]),
        (
            "first.world.robots",
            "8",
            &["`--set first.world.robots=8`", "world.robots", "8 robots do not fit", "holds 7"],
        ),
        ("first.world.robots", "100000", &["`--set first.world.robots=100000`", "world.robots", "10000"]),
        ("first.world.robots", "0", &["world.robots", "0 is not between 1"]),
        ("first.fitness.team", "median", &["`median` is not one of sum, mean, min"]),
    ];
    for (target, value, wanted) in cases {
        let err = apply(&mut tiny(), &set(target, value)).unwrap_err();
        // A setting that cannot be used: `Invalid` (Python's ValueError), not a file's failure.
        assert_eq!(err.kind(), ErrorKind::Invalid, "--set {target}={value}");
        // The setting as data, as given.
        assert_eq!(err.setting(), Some((target, Some(value))), "--set {target}={value}");
        let err = err.to_string();
        for w in wanted {
            assert!(err.contains(w), "--set {target}={value}: `{w}` missing from:\n{err}");
        }
    }
}

/// `world.body.rab_signals=off` silences the board of the stage and of
/// the stages that inherit it; a world without a board refuses it, and
/// only `on` and `off` are taken.
#[test]
fn rab_signals_is_set_on_a_board_and_refused_without_one() {
    use shaping_engine::sweep::apply;
    use shaping_runtime::program::RangeBearing;
    let set = |t: &str, v: &str| vec![(t.to_string(), v.to_string())];
    let mut p = tiny();
    let err = apply(&mut p.clone(), &set("first.world.body.rab_signals", "off")).unwrap_err().to_string();
    assert!(err.contains("no range-and-bearing board"), "{err}");
    for s in &mut p.stages {
        s.world.body.rab = Some(RangeBearing { signals: 1, ..RangeBearing::DEFAULT });
    }
    apply(&mut p, &set("first.world.body.rab_signals", "off")).unwrap();
    assert!(p.stages.iter().all(|s| s.world.body.rab.as_ref().unwrap().silenced));
    apply(&mut p, &set("second.world.body.rab_signals", "on")).unwrap();
    let silenced: Vec<bool> = p.stages.iter().map(|s| s.world.body.rab.as_ref().unwrap().silenced).collect();
    assert_eq!(silenced, [true, false]);
    let err = apply(&mut p, &set("first.world.body.rab_signals", "mute")).unwrap_err().to_string();
    assert!(err.contains("`mute` is not one of on, off"), "{err}");
}

/// In a stage with roles, `ROLE.robots` sets a role's robots (and the
/// team's), `world.robots` is refused with the roles' settings named, and a
/// module's settings are `ROLE.MODULE.FIELD`.
#[test]
fn a_roles_robots_and_modules_are_set_by_role() {
    use shaping_engine::sweep::apply;
    use shaping_runtime::program::{Program, FORMAT_VERSION};
    let set = |t: &str, v: &str| vec![(t.to_string(), v.to_string())];
    let roles = || Program {
        format: FORMAT_VERSION,
        name: "roles".into(),
        stages: vec![shaping_runtime::testkit::two_roles(|_| ())],
    };
    let mut p = roles();
    apply(&mut p, &set("roles.sitters.robots", "3")).unwrap();
    assert_eq!((p.stages[0].roles[1].robots, p.stages[0].world.robots), (3, 5));
    apply(&mut p, &set("roles.movers.go.range", "-2..2")).unwrap();
    let ranges: Vec<(u16, f32)> = p.stages[0].layout.genes.iter().map(|g| (g.module, g.hi)).collect();
    assert!(
        ranges.iter().all(|&(m, hi)| (m == 0) == (hi == 2.0)),
        "only the movers' `go` changes: {ranges:?}"
    );
    let cases: [(&str, &str, &[&str]); 3] = [
        (
            "roles.world.robots",
            "4",
            &["stage `roles` has roles", "`roles.movers.robots`, `roles.sitters.robots`"],
        ),
        ("roles.go.range", "-1..1", &["no module `go`", "its modules: movers.go, movers.turn, sitters.go"]),
        ("roles.sitters.robots", "0", &["roles[1].robots", "0 is not between 1"]),
    ];
    for (target, value, wanted) in cases {
        let err = apply(&mut roles(), &set(target, value)).unwrap_err().to_string();
        for w in wanted {
            assert!(err.contains(w), "--set {target}={value}: `{w}` missing from:\n{err}");
        }
    }
}

/// A criterion no fitness can reach (`nan`, `inf`, beyond f32) is refused
/// before anything runs, as a word is; so are non-finite `--set` values.
#[test]
fn non_finite_criteria_and_settings_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let x = dir.path().join("x");
    for value in ["nan", "NaN", "inf", "-inf", "infinity", "1e40", "abc"] {
        let err = refused(&x, &[], &[&format!("first={value}")]);
        assert!(err.contains(&format!("criterion `first={value}`: `{value}` is not a")), "{value}: {err}");
    }
    for value in ["nan", "inf", "-inf", "1e40"] {
        let err = refused(&x, &[&format!("first.evolve.mutation={value}")], &[]);
        assert!(err.contains("first.evolve.mutation"), "{value}: {err}");
    }
}

/// A sweep stopped in the middle of its second point, and left as a kill
/// right after a checkpoint would leave it, ends with the files of one that
/// was never stopped when started again.
#[test]
fn a_stopped_or_killed_sweep_resumes_to_the_same_result() {
    let dir = tempfile::tempdir().unwrap();
    let straight = dir.path().join("straight");
    experiment(tiny(), sweep(&straight)).unwrap();
    let killed = dir.path().join("killed");
    let plan = Plan::new(tiny(), sweep(&killed)).unwrap();
    {
        let _lock = plan.lock().unwrap();
        let tasks = plan.tasks();
        // The first point's two seeds, then the second point's first seed, stopped.
        for &task in &tasks[..2] {
            plan.run_task(task, Some(1), &Engine::default()).unwrap();
        }
        let flag = AtomicBool::new(false);
        let stop = StopAfter::new(&flag, 1);
        let err = error(plan.run_task(tasks[2], Some(1), &stop.runner()));
        assert_eq!(err.kind(), ErrorKind::Interrupted, "{err}");
    }
    let mid = killed.join("first.evolve.mutation=0.01,first.world.battery=300/seed-1/first");
    assert!(mid.join("checkpoint.json").exists(), "stopped elsewhere");
    as_if_killed(&mid);
    assert!(!killed.join("summary.json").exists(), "the sweep ended before it was stopped");
    experiment(tiny(), sweep(&killed)).unwrap();
    let (a, b) = (result_files(&straight), result_files(&killed));
    assert_eq!(a.len(), b.len());
    for ((pa, xa), (pb, xb)) in a.iter().zip(&b) {
        assert_eq!(pa, pb);
        assert!(xa == xb, "{pa} differs after resuming");
    }
}

/// The report of a sweep shows its best point and lists every point; a
/// point's report lists them too, its own highlighted.
#[test]
fn the_report_of_a_sweep_lists_its_points() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let opts = ExperimentOptions {
        sets: vec![parse_set("first.evolve.mutation=0.01,0.2").unwrap()],
        no_report: false,
        ..tiny_experiment(d, 2)
    };
    experiment(tiny(), opts).unwrap();
    let root = report_data(&d.join("report.html"));
    assert_eq!(root["kind"], "sweep");
    let names: Vec<&str> =
        root["sweep"]["points"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["first.evolve.mutation=0.01", "first.evolve.mutation=0.2"]);
    // The point shown is the one with the highest median chosen best of the last evolved stage.
    let summary = read_json(&d.join("summary.json"));
    let score = |i: usize| summary["points"][i]["stages"][1]["chosen_best"]["median"].as_f64().unwrap();
    let best = if score(1) > score(0) { names[1] } else { names[0] };
    assert_eq!(root["sweep_point"], best);
    assert_eq!(root["seeds"], serde_json::json!([1, 2]));
    let point = report_data(&d.join("first.evolve.mutation=0.2/report.html"));
    assert_eq!(point["kind"], "experiment");
    assert_eq!(point["sweep_point"], "first.evolve.mutation=0.2");
    assert_eq!(point["sweep"]["points"].as_array().unwrap().len(), 2);
    // An experiment that is no sweep's point lists none.
    let alone = tempfile::tempdir().unwrap();
    experiment(tiny(), ExperimentOptions { no_report: false, ..tiny_experiment(alone.path(), 1) }).unwrap();
    assert!(report_data(&alone.path().join("report.html")).get("sweep").is_none());
}

/// An experiment of one stage runs that stage and the stages it needs, and
/// summarises them only.
#[test]
fn an_experiment_of_one_stage_runs_and_summarises_its_chain() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    experiment(tiny(), ExperimentOptions { stage: Some("first".into()), ..tiny_experiment(d, 1) }).unwrap();
    assert!(d.join("seed-1/first/best.genome").exists());
    assert!(!d.join("seed-1/second").exists(), "the stage after `first` ran");
    let md = read_text(&d.join("summary.md"));
    assert!(md.contains("| first | 6 |") && !md.contains("| second |"), "{md}");
}

#[test]
fn an_experiment_report_has_the_median_over_seeds() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let finished =
        experiment(tiny(), ExperimentOptions { no_report: false, ..tiny_experiment(d, 3) }).unwrap();
    assert_eq!(finished.reports, [d.join("report.html")]);
    assert!(!d.join("seed-1/report.html").exists(), "one report for the experiment, none per seed");
    let data = report_data(&d.join("report.html"));
    assert_eq!(data["kind"], "experiment");
    assert_eq!(data["seeds"], serde_json::json!([1, 2, 3]));
    let first = &data["fitness"][0];
    assert_eq!(first["seeds"][0], 3);
    // The median of the three seeds' best of the first generation.
    let mut bests: Vec<f64> = (1..=3)
        .map(|s| {
            let csv = read_text(&d.join(format!("seed-{s}/first/generations.csv")));
            csv.lines().nth(1).unwrap().split(',').nth(3).unwrap().parse().unwrap()
        })
        .collect();
    bests.sort_by(f64::total_cmp);
    assert!((first["best"][0].as_f64().unwrap() - bests[1]).abs() < 1e-6, "{first} vs {bests:?}");
    assert!((first["best_min"][0].as_f64().unwrap() - bests[0]).abs() < 1e-6);
    assert!((first["best_max"][0].as_f64().unwrap() - bests[2]).abs() < 1e-6);
}

/// An experiment's report shows the seeds its summaries cover, not every
/// `seed-N` an earlier experiment left in the directory.
#[test]
fn an_experiment_report_shows_the_seeds_its_summary_covers() {
    let dir = tempfile::tempdir().unwrap();
    experiment(tiny(), tiny_experiment(dir.path(), 3)).unwrap();
    experiment(tiny(), ExperimentOptions { no_report: false, ..tiny_experiment(dir.path(), 2) }).unwrap();
    let data = report_data(&dir.path().join("report.html"));
    assert_eq!(data["seeds"], serde_json::json!([1, 2]), "seed-3 is on disk but not summarised");
}
