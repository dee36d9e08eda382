//! Replays, called as a library: the individual a replay chooses, the
//! files it writes, and its trace (also written as it goes, as `drive`
//! writes it).

mod common;

use std::path::Path;

use common::{
    error, load, options, read_json, read_text, root, run, sets, test_file, tiny, tiny_bat, write_bat, Log,
};
use shaping_engine::episode::{self, Recorder};
use shaping_engine::replay::{self, ReplayOptions};
use shaping_engine::report::{self, TraceWriter};
use shaping_engine::run::RunOptions;
use shaping_engine::rundir;
use shaping_engine::ErrorKind;
use shaping_runtime::controller::{episode_rngs, Controller, EpisodeOptions, Trace};
use shaping_runtime::genome::Genome;
use shaping_runtime::sim::Sim;

/// A replay of `file` with the run in `run_dir`, written to `out`.
fn opts(file: &Path, run_dir: &Path, out: &Path) -> ReplayOptions {
    ReplayOptions {
        file: file.to_path_buf(),
        run: Some(run_dir.to_path_buf()),
        out: Some(out.to_path_buf()),
        ..ReplayOptions::default()
    }
}

#[test]
fn an_unknown_stage_is_refused_and_a_replay_writes_its_pictures() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let err = error(run(tiny(), &RunOptions { stage: Some("fifth".into()), ..options(d) }));
    assert_eq!(err.kind(), ErrorKind::Invalid, "{err}");
    assert!(err.message().contains("no stage `fifth`"), "{err}");

    // Nothing run yet: what to do.
    let err = error(replay::replay(tiny(), &opts(&tiny_bat(), d, &d.join("none")), &Log::default()));
    assert!(err.message().contains("shaping run"), "{err}");
    // The file that is missing, as data: `best.genome` of the evolved stage.
    assert_eq!(err.kind(), ErrorKind::NotFound, "{err}");
    assert_eq!(err.path(), Some(d.join("second/best.genome").as_path()), "{err}");

    run(tiny(), &options(d)).unwrap();
    let pics = d.join("pics");
    let args =
        ReplayOptions { stage: Some("second".into()), actions: Some(80), ..opts(&tiny_bat(), d, &pics) };
    let replayed = replay::replay(tiny(), &args, &Log::default()).unwrap();
    assert_eq!((replayed.stage.as_str(), replayed.out.as_path()), ("second", pics.as_path()));
    for f in ["trace.csv", "activations.png", "activations.svg", "trajectory.png", "trajectory.svg"] {
        assert!(pics.join(f).exists(), "{f}");
    }
    let trace = read_text(&pics.join("trace.csv"));
    assert!(trace.lines().count() > 1 && trace.lines().count() <= 81);

    let short = ReplayOptions {
        stage: Some("second".into()),
        genome: Some("0101".into()),
        ..opts(&tiny_bat(), d, &pics)
    };
    let err = error(replay::replay(tiny(), &short, &Log::default()));
    assert!(err.message().contains("bits"), "{err}");
    // An argument that cannot be used, named with its value.
    assert_eq!(err.kind(), ErrorKind::Invalid, "{err}");
    assert_eq!(err.setting(), Some(("--genome", Some("0101"))), "{err}");

    let far = ReplayOptions { stage: Some("second".into()), robot: 7, ..opts(&tiny_bat(), d, &pics) };
    let err = error(replay::replay(tiny(), &far, &Log::default()));
    assert_eq!(err.message(), "error: `--robot 7`: stage `second` has one robot, robot 0");
    assert_eq!((err.kind(), err.setting()), (ErrorKind::Invalid, Some(("--robot", Some("7")))), "{err}");
}

/// A stage with nothing evolved replays without a genome, and its avoid
/// module's performance indicator is high by action 300 (figure 5).
#[test]
fn a_replay_of_a_stage_without_genes_needs_no_genome() {
    let dir = tempfile::tempdir().unwrap();
    let file = root().join("examples/avoid.bat");
    let args =
        ReplayOptions { file: file.clone(), out: Some(dir.path().to_path_buf()), ..ReplayOptions::default() };
    let replayed = replay::replay(load(&file), &args, &Log::default()).unwrap();
    assert_eq!((replayed.stage.as_str(), replayed.result.actions), ("avoid", 1000));
    assert!(dir.path().join("reinforcement.png").exists());
    let trace = read_text(&dir.path().join("trace.csv"));
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "perf_avoid").expect("a performance column");
    let perf: Vec<f32> =
        trace.lines().skip(1).map(|l| l.split(',').nth(col).unwrap().parse().unwrap()).collect();
    let mean = |s: &[f32]| s.iter().sum::<f32>() / s.len() as f32;
    let (first, at300) = (mean(&perf[..100]), perf[299]);
    assert!(
        at300 >= 0.5 && at300 > first + 0.2,
        "performance {first} in the first 100 actions, {at300} at 300"
    );
}

/// Replaying a training stage of a run replays its training life.
#[test]
fn a_replay_of_a_training_stage_replays_its_life() {
    let dir = tempfile::tempdir().unwrap();
    let file = root().join("examples/pretrained.bat");
    let out = dir.path().join("out");
    run(load(&file), &RunOptions { stage: Some("avoidance".into()), seed: Some(5), ..options(&out) })
        .unwrap();
    let args =
        ReplayOptions { stage: Some("avoidance".into()), ..opts(&file, &out, &dir.path().join("life")) };
    let life = replay::replay(load(&file), &args, &Log::default()).unwrap();
    let trained = rundir::read_trained(&out.join("avoidance")).unwrap().unwrap();
    let (r, t) = (&life.result, &trained.result);
    assert_eq!(
        (r.actions, r.grips, r.releases_outside, r.recharges, r.collisions),
        (t.actions, t.grips, t.releases_outside, t.recharges, t.collisions),
        "not the training life"
    );
    assert_eq!(r.fitness, t.fitness, "not the training life's fitness");
    let trace = read_text(&dir.path().join("life/trace.csv"));
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "perf_avoid").unwrap();
    let last: f64 = trace.lines().last().unwrap().split(',').nth(col).unwrap().parse().unwrap();
    let learned = f64::from(trained.performance[1]);
    assert!((last - learned).abs() < 1e-3, "performance {last} at the end of the replay, {learned} trained");
}

/// Every way of running a stage binds the trained weights the same way: a
/// replay of every stage of every example (the training stages trained on
/// the fly: no run directory has them).
#[test]
fn a_replay_runs_every_stage_of_every_example() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("no-run");
    for example in std::fs::read_dir(root().join("examples")).unwrap() {
        let file = example.unwrap().path();
        if file.extension().is_none_or(|e| e != "bat") {
            continue;
        }
        let program = load(&file);
        for stage in &program.stages {
            let args = ReplayOptions {
                stage: Some(stage.name.clone()),
                actions: Some(5),
                genome: Some("0".repeat(stage.layout.bits as usize)),
                ..opts(&file, &empty, &dir.path().join("r"))
            };
            replay::replay(program.clone(), &args, &Log::default())
                .unwrap_or_else(|e| panic!("{} {}: {e}", file.display(), stage.name));
        }
    }
}

/// `trace.csv` has a column per declared sensor and actuator element, named
/// after the declaration, and `episode.json` the ambient light readings.
#[test]
fn the_trace_has_what_the_robot_sensed_and_did() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = ReplayOptions {
        stage: Some("first".into()),
        actions: Some(30),
        genome: Some("0".repeat(84)),
        ..opts(&tiny_bat(), &d.join("no-run"), d)
    };
    replay::replay(tiny(), &args, &Log::default()).unwrap();
    let trace = read_text(&d.join("trace.csv"));
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> =
        trace.lines().skip(1).map(|l| l.split(',').skip(2).map(|v| v.parse().unwrap()).collect()).collect();
    let col =
        |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no `{name}`")) - 2;
    let episode = read_json(&d.join("episode.json"));
    let light = episode["actions"]["light"].as_array().unwrap();
    assert_eq!(light.len(), rows.len());
    for (k, row) in rows.iter().enumerate() {
        for i in 0..8 {
            let ir = episode["actions"]["ir"][k][i].as_f64().unwrap();
            assert!((row[col(&format!("ir[{i}]"))] - ir).abs() < 1e-3, "ir[{i}] at {k}");
            assert!((row[col(&format!("light[{i}]"))] - light[k][i].as_f64().unwrap()).abs() < 1e-3);
        }
        assert_eq!(row[col("battery[0]")], row[col("battery")]);
        for i in 0..2 {
            let w = episode["actions"]["wheels"][k][i].as_f64().unwrap();
            assert!((row[col(&format!("wheels[{i}]"))] - w).abs() < 1e-3);
        }
    }
    // The lamp lights the arena: the light readings are not all zero.
    assert!(rows.iter().any(|r| r[col("light[0]")] > 0.0));
    assert!(rows.iter().any(|r| r[col("wheels[0]")] != 0.0));
}

/// A replay takes `--set` as a run does: a run made with a setting changed
/// on a parent stage replays with the same setting, given or not (the
/// file with the run's settings is the run's `program.json`: that program
/// replays, and the replay says so). A setting given that the run did not
/// have is refused with advice that works: the run's own program.
#[test]
fn a_replay_takes_the_settings_the_run_was_made_with() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("run");
    let set = sets(&["first.evolve.generations=2", "second.world.arena=500x700"]);
    run(tiny(), &RunOptions { sets: set.clone(), ..options(&out) }).unwrap();
    let plain = ReplayOptions { stage: Some("second".into()), ..opts(&tiny_bat(), &out, &d.join("plain")) };
    let log = Log::default();
    replay::replay(tiny(), &plain, &log).unwrap();
    let said = log.warnings().join("\n");
    assert!(
        said.contains(
            "is of this file with other settings (`--set first.evolve.generations=2 --set second.world.arena=500x700`): \
             replaying the run's own program"
        ),
        "{said}"
    );
    let with = ReplayOptions { sets: set, ..opts(&tiny_bat(), &out, &d.join("with")) };
    let with = ReplayOptions { stage: Some("second".into()), ..with };
    replay::replay(tiny(), &with, &log).unwrap();
    assert!(log.warnings().is_empty(), "the same settings given: nothing to say");
    assert!(read_text(&d.join("with/trace.csv")) == read_text(&d.join("plain/trace.csv")));

    let other = ReplayOptions { sets: sets(&["first.evolve.generations=3"]), ..plain.clone() };
    let err = error(replay::replay(tiny(), &other, &log));
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    let own = out.join("program.json");
    let advice = format!(
        "replay it with the run's own program (`shaping replay {} --run {} --stage second`)",
        own.display(),
        out.display()
    );
    assert!(err.message().contains("is not of this program"), "{err}");
    assert!(err.message().contains("the generations of `first`, which `second` extends, changed"), "{err}");
    assert!(err.message().contains(&advice), "{err}");
    // Following it.
    let ran = ReplayOptions { file: own.clone(), out: Some(d.join("own")), ..plain };
    replay::replay(load(&own), &ran, &log).unwrap();
    assert!(read_text(&d.join("own/trace.csv")) == read_text(&d.join("plain/trace.csv")));
}

/// `trace.csv` written as an episode goes (as `drive` writes it) is, once
/// complete, the file written at the episode's end, byte for byte (a stage
/// with columns of every kind: proximity, light, battery, barrier, wheels,
/// arm and claw); its rows reach the file while the episode runs.
#[test]
fn a_trace_written_as_it_goes_is_the_trace_written_at_the_end() {
    let program = load(&test_file("report.bat"));
    let (_, stage) = program.stage("collect").unwrap();
    let genome = Genome { bits: (0..stage.layout.bits as usize).map(|i| u8::from(i % 3 == 0)).collect() };
    let opts = EpisodeOptions { actions: 80, learning: true, seed: 9 };
    let (_, trace, ep) = episode::run_recorded(stage, &genome, &opts).unwrap();
    let whole = report::trace_csv(&trace, stage, &ep);
    assert_eq!(whole.lines().count(), 1 + 80);

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trace.csv");
    let mut writer = TraceWriter::create(&path, stage).unwrap();
    assert_eq!(read_text(&path), whole.lines().next().unwrap().to_string() + "\n", "the header at once");
    let (sim_seed, rng) = episode_rngs(opts.seed);
    let mut ctl = Controller::new(stage, &genome, rng).unwrap();
    let mut sim = Sim::new(&stage.world, sim_seed);
    let mut rec = Recorder::new(&mut sim);
    let mut streamed = Trace::default();
    let mut on_disk = Vec::new();
    ctl.run_traced(&mut rec, &opts, &mut streamed, |row, rec| {
        writer.push(row, rec.frames.last());
        if row.action == 40 {
            // Rows wait in memory at most `TRACE_WRITE_EVERY`: the next one writes them.
            std::thread::sleep(report::TRACE_WRITE_EVERY);
        }
        if row.action == 41 {
            on_disk = std::fs::read(&path).unwrap();
        }
    });
    writer.finish().unwrap();
    assert_eq!(streamed, trace);
    assert!(read_text(&path) == whole, "the trace written as it went differs");
    let lines: Vec<&str> = whole.split_inclusive('\n').take(1 + 42).collect();
    assert_eq!(
        String::from_utf8(on_disk).unwrap(),
        lines.concat(),
        "rows 0 to 41 on disk during the episode"
    );
}

/// `--variant NAME` lives in that declared variant of the stage's world; a
/// name the stage does not declare is refused with its variants, and the
/// nearest one; a stage without variants says so.
#[test]
fn a_replay_lives_in_a_named_variant() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = r#"
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 400mm x 400mm  start at (100mm, 200mm) heading 90 }
  variants mean {
    west { start at (100mm, 200mm) heading 90 }
    east { start at (300mm, 200mm) heading 90 }
  }
  evolve { population 6  generations 2  actions 5 }
  fitness at end robot.x
  module m { sense ir  behavior stop }
}
"#;
    let (file, program) = write_bat(d, "variants.bat", src);
    let genome = "0".repeat(program.stages[0].layout.bits as usize);
    let args = |variant: Option<&str>, out: &str| ReplayOptions {
        file: file.clone(),
        genome: Some(genome.clone()),
        out: Some(d.join(out)),
        variant: variant.map(str::to_string),
        ..ReplayOptions::default()
    };
    let start_x =
        |out: &str| read_json(&d.join(out).join("episode.json"))["worlds"][0]["start"][0].as_f64().unwrap();
    replay::replay(program.clone(), &args(None, "own"), &Log::default()).unwrap();
    replay::replay(program.clone(), &args(Some("east"), "east"), &Log::default()).unwrap();
    assert_eq!(start_x("own"), 100.0);
    assert_eq!(start_x("east"), 300.0, "the variant's start");

    let err = error(replay::replay(program.clone(), &args(Some("eats"), "bad"), &Log::default()));
    assert_eq!(
        err.message(),
        "error: `--variant eats`: stage `s` has no variant `eats` (its variants: `west`, `east`); did you mean `east`?"
    );
    assert!(!d.join("bad").exists(), "nothing written");
    let bits = tiny().stages.last().unwrap().layout.bits as usize;
    let plain = ReplayOptions { genome: Some("0".repeat(bits)), ..args(Some("east"), "none") };
    let err = error(replay::replay(tiny(), &plain, &Log::default()));
    assert!(err.message().contains("declares no variants"), "{err}");
}
