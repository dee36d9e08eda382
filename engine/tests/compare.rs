//! `compare`: finished experiments compared stage by stage and measure by
//! measure (the numbers themselves are tested against SciPy's in the
//! library's `stats` and `compare` tests), and what it refuses.

mod common;

use std::path::{Path, PathBuf};

use common::{experiment, load, root, tiny, tiny_experiment};
use shaping_engine::compare::{compare, CompareOptions};
use shaping_engine::experiment::ExperimentOptions;
use shaping_engine::rundir::Tests;
use shaping_engine::stats;
use shaping_engine::sweep::parse_set;

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// Equal JSON, numbers within reading's rounding (serde_json's parser may
/// miss the nearest double by one unit in the last place).
fn same(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    use serde_json::Value::{Array, Number, Object};
    match (a, b) {
        (Number(x), Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            (x - y).abs() <= 1e-15 * x.abs().max(y.abs())
        }
        (Array(x), Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same(x, y)),
        (Object(x), Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same(v, w)))
        }
        _ => a == b,
    }
}

fn opts(dirs: &[&Path]) -> CompareOptions {
    CompareOptions { dirs: dirs.iter().map(|d| d.to_path_buf()).collect(), ..CompareOptions::default() }
}

fn err(o: &CompareOptions) -> String {
    compare(o).map(|_| ()).unwrap_err().message().to_string()
}

/// Each seed's chosen best of `stage`, from its checkpoint.
fn chosen(dir: &Path, seeds: std::ops::RangeInclusive<u64>, stage: &str) -> Vec<f64> {
    seeds
        .map(|s| {
            read_json(&dir.join(format!("seed-{s}/{stage}/checkpoint.json")))["best"][1].as_f64().unwrap()
                as f32 as f64
        })
        .collect()
}

fn tiny_into(dir: &Path, first_seed: u64, seeds: u64) -> PathBuf {
    experiment(tiny(), ExperimentOptions { first_seed, ..tiny_experiment(dir, seeds) }).unwrap();
    dir.to_path_buf()
}

#[test]
fn two_experiments_are_compared_measure_by_measure() {
    let d = tempfile::tempdir().unwrap();
    let a = tiny_into(&d.path().join("a"), 1, 3);
    let b = tiny_into(&d.path().join("b"), 4, 3);
    let t: Tests =
        compare(&CompareOptions { criterion: vec!["first=0.3".into()], ..opts(&[&a, &b]) }).unwrap();
    assert_eq!(t.groups, [a.display().to_string(), b.display().to_string()]);
    assert!(!t.holm);
    let names: Vec<String> = t.measures.iter().map(|m| format!("{} {}", m.stage, m.measure)).collect();
    let columns = "final_best chosen_best final_mean best_ever final_worst final_best_recharges final_best_grips final_best_releases_outside";
    let mut want: Vec<String> = columns.split(' ').map(|m| format!("first {m}")).collect();
    want.extend([
        "first generation_reaching_criterion".into(),
        "first evaluations_reaching_criterion".into(),
    ]);
    want.extend(columns.split(' ').map(|m| format!("second {m}")));
    assert_eq!(names, want);
    // Evaluations: generations of the population of 12.
    let (generations, evaluations) = (&t.measures[8].groups[0], &t.measures[9].groups[0]);
    assert_eq!(evaluations.median.unwrap(), generations.median.unwrap() * 12.0);
    // The chosen bests are the checkpoints', and the test is the statistics' on them.
    let m = &t.measures[11];
    let (va, vb) = (chosen(&a, 1..=3, "second"), chosen(&b, 4..=6, "second"));
    let want = stats::mann_whitney(&va, &vb).unwrap();
    assert_eq!(m.pairs[0].p_value, Some(want.p_value));
    assert_eq!(m.pairs[0].a12, stats::a12(&va, &vb));
    assert_eq!(m.groups[0].median, stats::median(&va));
    assert_eq!(m.groups[1].interval, stats::median_ci(&vb));
    let json = serde_json::to_value(&t).unwrap();
    for pair in json["measures"].as_array().unwrap().iter().flat_map(|m| m["pairs"].as_array().unwrap()) {
        assert!(pair["p_value"].is_number() && pair["a12"].is_number(), "{pair}");
    }
    // A criterion on `second` counts `first`'s 6 generations of 12 before its own.
    let t: Tests =
        compare(&CompareOptions { criterion: vec!["second=0".into()], ..opts(&[&a, &b]) }).unwrap();
    let evaluations = t.measures.iter().find(|m| m.measure == "evaluations_reaching_criterion").unwrap();
    assert_eq!(evaluations.stage, "second");
    // A best of at least 0 is reached in the stage's first generation.
    assert_eq!(evaluations.groups[0].median, Some(6.0 * 12.0 + 12.0));
}

/// A sweep's `summary.json` holds the same tests as `compare` of its points.
#[test]
fn a_sweeps_tests_are_compares_of_its_points() {
    let d = tempfile::tempdir().unwrap();
    let sets = vec![parse_set("first.evolve.mutation=0.01,0.2,0.5").unwrap()];
    experiment(tiny(), ExperimentOptions { sets, ..tiny_experiment(d.path(), 3) }).unwrap();
    let summary = read_json(&d.path().join("summary.json"));
    let points: Vec<PathBuf> = summary["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| d.path().join(p["dir"].as_str().unwrap()))
        .collect();
    let t = compare(&opts(&points.iter().map(|p| p.as_path()).collect::<Vec<_>>())).unwrap();
    assert!(t.holm);
    let mut from_compare = serde_json::to_value(&t).unwrap();
    let mut in_summary = summary["tests"].clone();
    assert_eq!(
        in_summary["groups"],
        serde_json::json!([
            "first.evolve.mutation=0.01",
            "first.evolve.mutation=0.2",
            "first.evolve.mutation=0.5"
        ])
    );
    from_compare["groups"] = serde_json::Value::Null;
    in_summary["groups"] = serde_json::Value::Null;
    assert!(same(&from_compare, &in_summary), "{from_compare}\n{in_summary}");
    assert!(in_summary["measures"][0]["pairs"][2]["p_holm"].is_number(), "{in_summary}");
    let md = std::fs::read_to_string(d.path().join("summary.md")).unwrap();
    assert!(
        md.contains("## Tests between points") && md.contains("| Holm p |") && md.contains("| 2 vs 3 |"),
        "{md}"
    );
}

/// The report's page shows the statistics of `summary.json` (the same
/// numbers, not computed again): a sweep's page each pair's p-value, Holm's
/// and A12, a plain experiment's page its medians with their intervals.
#[test]
fn the_report_shows_the_summarys_tests() {
    let d = tempfile::tempdir().unwrap();
    let sets = vec![parse_set("first.evolve.mutation=0.01,0.2,0.5").unwrap()];
    experiment(tiny(), ExperimentOptions { sets, no_report: false, ..tiny_experiment(d.path(), 3) }).unwrap();
    let summary = read_json(&d.path().join("summary.json"));
    let tests: Tests = serde_json::from_value(summary["tests"].clone()).unwrap();
    let p_text = |p: f64| if p >= 0.001 { format!("{p:.4}") } else { format!("{p:.1e}") };
    let point = d.path().join(summary["points"][1]["dir"].as_str().unwrap());
    for page in [d.path().join("report.html"), point.join("report.html")] {
        let html = std::fs::read_to_string(&page).unwrap();
        let at = html.find("<section id=\"sec-stats\"").unwrap_or_else(|| panic!("{}", page.display()));
        let end = at + html[at..].find("</section>").unwrap();
        let section = &html[at..end];
        assert!(section.contains("Holm-corrected"), "{section}");
        assert!(section.contains("<code>first.evolve.mutation=0.5</code>"), "{section}");
        for m in &tests.measures {
            for p in &m.pairs {
                let row = format!(
                    "<tr><td>{}</td><td>{}</td><td>{} vs {}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{:.3}</td>",
                    m.stage,
                    m.measure.replace('_', " "),
                    p.a,
                    p.b,
                    p.u.unwrap(),
                    p_text(p.p_value.unwrap()),
                    p_text(p.p_holm.unwrap()),
                    p.a12.unwrap()
                );
                assert!(section.contains(&row), "{row}\n{section}");
            }
            let g = &m.groups[1];
            let (x, ci) = (g.median.unwrap(), g.interval.unwrap());
            let cell = format!("<td class=\"num\">{x:.3} [{:.3}, {:.3}] ({})</td>", ci.low, ci.high, g.seeds);
            assert!(m.measure.contains("criterion") || section.contains(&cell), "{cell}\n{section}");
        }
    }
    // One experiment: its medians and intervals, no pairs.
    let one = d.path().join("one");
    experiment(tiny(), ExperimentOptions { no_report: false, ..tiny_experiment(&one, 3) }).unwrap();
    let html = std::fs::read_to_string(one.join("report.html")).unwrap();
    let tests: Tests = serde_json::from_value(read_json(&one.join("summary.json"))["tests"].clone()).unwrap();
    let m = &tests.measures[0];
    let (x, ci) = (m.groups[0].median.unwrap(), m.groups[0].interval.unwrap());
    let row = format!(
        "<tr><td>{}</td><td>{}</td><td class=\"num\">{x:.3} [{:.3}, {:.3}] (3)</td></tr>",
        m.stage,
        m.measure.replace('_', " "),
        ci.low,
        ci.high
    );
    assert!(html.contains(&row), "{row}");
    assert!(html.contains("id=\"stats-medians\"") && !html.contains("id=\"stats-tests\""));
}

#[test]
fn compare_refuses_different_stages_single_seeds_and_missing_measures() {
    let d = tempfile::tempdir().unwrap();
    let a = tiny_into(&d.path().join("a"), 1, 2);
    let first_only = d.path().join("first-only");
    experiment(tiny(), ExperimentOptions { stage: Some("first".into()), ..tiny_experiment(&first_only, 2) })
        .unwrap();
    let e = err(&opts(&[&a, &first_only]));
    assert!(
        e.contains("ran different stages: `first` (evolved), `second` (evolved) against `first` (evolved)")
            && e.contains("`--stage NAME`"),
        "{e}"
    );
    // One stage that both ran compares.
    let t = compare(&CompareOptions { stage: Some("first".into()), ..opts(&[&a, &first_only]) }).unwrap();
    assert!(t.measures.iter().all(|m| m.stage == "first"));
    let e = err(&CompareOptions { stage: Some("second".into()), ..opts(&[&a, &first_only]) });
    assert!(e.contains("did not run stage `second`"), "{e}");

    let one = tiny_into(&d.path().join("one"), 1, 1);
    let e = err(&opts(&[&a, &one]));
    assert_eq!(
        e,
        format!(
            "error: no test: `{}` has 1 seed (`seed-1`); the Mann-Whitney test needs at least 2 seeds per side",
            one.display()
        )
    );
    let e = err(&opts(&[&a, d.path()]));
    assert!(e.contains("has no `seed-N` directory: it is not an experiment's directory"), "{e}");
    assert!(err(&opts(&[&a])).contains("at least two experiment directories"));
    let sweep = d.path().join("sweep");
    let sets = vec![parse_set("first.evolve.mutation=0.01,0.2").unwrap()];
    experiment(tiny(), ExperimentOptions { sets, ..tiny_experiment(&sweep, 2) }).unwrap();
    let e = err(&opts(&[&a, &sweep]));
    assert_eq!(
        e,
        format!(
            "error: `{0}` is a sweep; compare its points' directories: `{0}/first.evolve.mutation=0.01`, `{0}/first.evolve.mutation=0.2`",
            sweep.display()
        )
    );

    // A test stage's figure missing from one directory's files.
    let report = root().join("tests/cli/report.bat");
    let run = |dir: &Path, first_seed: u64| {
        let o = ExperimentOptions { file: report.clone(), first_seed, ..tiny_experiment(dir, 2) };
        experiment(load(&report), o).unwrap();
    };
    let (x, y) = (d.path().join("x"), d.path().join("y"));
    run(&x, 1);
    run(&y, 3);
    assert!(compare(&opts(&[&x, &y])).unwrap().measures.iter().any(|m| m.measure == "grips"));
    let summary = y.join("seed-4/bigger/summary.json");
    let mut s = read_json(&summary);
    s.as_object_mut().unwrap().remove("grips");
    std::fs::write(&summary, serde_json::to_string(&s).unwrap()).unwrap();
    // An edited file is refused as damaged (its seal); one without a seal
    // (written before seals) is read, and then its missing key named with
    // the file (the typed summary: no measure silently becomes NaN).
    let e = err(&opts(&[&x, &y]));
    assert!(e.contains("summary.json` is corrupt"), "{e}");
    std::fs::remove_file(y.join("seed-4/bigger/.seals")).unwrap();
    let e = err(&opts(&[&x, &y]));
    assert_eq!(
        e,
        format!("error: `{}` is not a test stage's summary: missing field `grips`", summary.display())
    );
}
