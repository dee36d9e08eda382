//! `report.html`, called as a library: what a run's, a stage's and a
//! replay's page shows, and the damaged files it names rather than showing
//! a part silently empty.

mod common;

use common::{
    error, experiment, options, read_text, report_data, run, test_file, tiny, tiny_experiment, Log,
};
use shaping_engine::experiment::ExperimentOptions;
use shaping_engine::html;
use shaping_engine::replay::{self, ReplayOptions};
use shaping_engine::run::RunOptions;

fn report_bat() -> shaping_runtime::program::Program {
    common::load(&test_file("report.bat"))
}

#[test]
fn a_run_writes_a_report_of_every_stage_and_a_report_reads_any_directory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let outcome = run(report_bat(), &RunOptions { no_report: false, ..options(d) }).unwrap();
    let page = d.join("report.html");
    assert_eq!(outcome.report.as_deref(), Some(page.as_path()));
    assert!(d.join("program.json").exists());
    let data = report_data(&page);
    assert_eq!(data["kind"], "run");
    let stages: Vec<&str> =
        data["stages"].as_array().unwrap().iter().map(|s| s["name"].as_str().unwrap()).collect();
    assert_eq!(stages, ["navigation", "collect", "bigger"]);
    // The frozen genes of `collect` are traced to an individual of `navigation`'s final population.
    let from = data["stages"][1]["frozen_from"].as_str().unwrap_or_default();
    assert!(
        from.contains("come from individual #") && from.contains("stage `navigation`'s final population"),
        "{from}"
    );
    assert!(data["stages"][0]["frozen_from"].is_null() && data["stages"][2]["frozen_from"].is_null());
    // One episode per stage, the test stage's in two worlds as long as its trace.
    let eps = data["episodes"].as_array().unwrap();
    assert_eq!(eps.len(), 3);
    let bigger = &eps[2];
    assert_eq!(bigger["worlds"].as_array().unwrap().len(), 2);
    let trace = read_text(&d.join("bigger/trace.csv"));
    assert_eq!(bigger["actions"]["x"].as_array().unwrap().len(), trace.lines().count() - 1);
    // Fitness: one series per evolved stage, as long as its generations.
    let fit = data["fitness"].as_array().unwrap();
    assert_eq!(fit.len(), 2);
    assert_eq!(fit[0]["best"].as_array().unwrap().len(), 4);
    assert_eq!(fit[1]["generation"][0], 4, "generations continue across stages");

    // The evolved stage's episode is the one a replay shows by default.
    let rep = d.join("rep");
    let args = ReplayOptions {
        file: test_file("report.bat"),
        stage: Some("collect".into()),
        run: Some(d.to_path_buf()),
        out: Some(rep.clone()),
        report: true,
        ..ReplayOptions::default()
    };
    let replayed = replay::replay(report_bat(), &args, &Log::default()).unwrap();
    assert_eq!(replayed.report, Some(rep.join("report.html")));
    let replay = report_data(&rep.join("report.html"));
    assert_eq!(replay["kind"], "replay");
    assert_eq!(replay["episodes"][0]["actions"], eps[1]["actions"]);

    // A stage directory, and another output file.
    let other = d.join("collect.html");
    assert_eq!(html::write(&d.join("collect"), Some(&other)).unwrap(), other);
    let stage = report_data(&other);
    assert_eq!(stage["kind"], "stage");
    assert_eq!(stage["episodes"].as_array().unwrap().len(), 1);

    // Not a run: a clear error.
    let err = error(html::write(&d.join("navigation").join("nothing"), None));
    assert!(err.message().contains("is not a directory"), "{err}");
    let empty = tempfile::tempdir().unwrap();
    let err = error(html::write(empty.path(), None));
    assert!(err.message().contains("no `program.json`"), "{err}");
    // A damaged episode is named.
    std::fs::write(d.join("collect/episode.json"), "{}").unwrap();
    let err = error(html::write(d, None));
    assert!(err.message().contains("collect/episode.json"), "{err}");

    let quiet = tempfile::tempdir().unwrap();
    let outcome = run(tiny(), &options(quiet.path())).unwrap();
    assert_eq!(outcome.report, None);
    assert!(!quiet.path().join("report.html").exists());
}

/// The report names a damaged file and what is wrong with it rather than
/// showing a stage with its genes or results silently empty.
#[test]
fn the_report_names_a_damaged_genome_summary_or_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run(report_bat(), &options(d)).unwrap();
    let cases: [(&str, &str, &str); 6] = [
        ("navigation/best.genome", "1111\n", "is not a genome of stage `navigation`: it has 4 bits"),
        (
            "navigation/best.genome",
            "10x1\n",
            "does not hold a genome: line 1, column 3 is `x`; a genome is a string of 0 and 1",
        ),
        ("bigger/summary.json", "{}", "is not a test stage's summary: missing field `stage`"),
        ("bigger/summary.json", "[1]", "is not a test stage's summary: it is not a JSON object"),
        ("bigger/summary.json", "{", "is not a test stage's summary"),
        ("navigation/checkpoint.json", "{}", "is corrupt"),
    ];
    // Sealed, each is refused as not what the run wrote.
    for (file, content, _) in &cases {
        let path = d.join(file);
        let good = std::fs::read(&path).unwrap();
        std::fs::write(&path, content).unwrap();
        let err = error(html::write(d, None));
        assert_eq!(err.kind(), shaping_engine::ErrorKind::Corrupt, "{err}");
        assert!(
            err.message().contains(&format!("`{}` is corrupt", path.display())),
            "{file} = {content:?}: {err}"
        );
        std::fs::write(&path, good).unwrap();
    }
    // Without seals (a run from before them), what is wrong with each.
    for stage in ["navigation", "bigger"] {
        std::fs::remove_file(d.join(stage).join(shaping_engine::files::SEALS)).unwrap();
    }
    for (file, content, wanted) in cases {
        let path = d.join(file);
        let good = std::fs::read(&path).unwrap();
        std::fs::write(&path, content).unwrap();
        let err = error(html::write(d, None));
        assert!(
            err.message().contains(&format!("`{}` {wanted}", path.display())),
            "{file} = {content:?}: {err}"
        );
        std::fs::write(&path, good).unwrap();
    }
    html::write(d, None).unwrap();
}

/// The report says the seed a stage ran with (`--seed`, an experiment's
/// seed), not the seed the file declares.
#[test]
fn the_report_shows_the_seed_the_run_used() {
    let dir = tempfile::tempdir().unwrap();
    run(tiny(), &RunOptions { seed: Some(99), no_report: false, ..options(dir.path()) }).unwrap();
    let data = report_data(&dir.path().join("report.html"));
    for stage in data["stages"].as_array().unwrap() {
        let how = stage["run"].as_str().unwrap();
        assert!(how.ends_with("seed 99"), "{how}");
    }
    let exp = tempfile::tempdir().unwrap();
    let opts = ExperimentOptions { first_seed: 11, no_report: false, ..tiny_experiment(exp.path(), 2) };
    experiment(tiny(), opts).unwrap();
    let data = report_data(&exp.path().join("report.html"));
    let shown = data["shown_seed"].as_u64().unwrap();
    assert!(shown == 11 || shown == 12, "{shown}");
    for stage in data["stages"].as_array().unwrap() {
        let how = stage["run"].as_str().unwrap();
        assert!(how.ends_with(&format!("seed {shown}")), "{how}");
    }
}
