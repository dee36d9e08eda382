//! Training and test stages and the warnings of a run, called as a
//! library: what each stage writes, what the run's observer is told, and a
//! test stage stopped by the interruption flag.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use common::{
    error, experiment, load, options, read_json, read_text, report_data, root, run, sets, test_file,
    tiny_bat, write_bat, Log, Seen,
};
use shaping_engine::run::{RunOptions, StageOutcome};
use shaping_engine::Engine;
use shaping_engine::{html, replay, ErrorKind};

fn replay_opts(
    file: &std::path::Path,
    run: &std::path::Path,
    out: &std::path::Path,
) -> replay::ReplayOptions {
    replay::ReplayOptions {
        file: file.to_path_buf(),
        run: Some(run.to_path_buf()),
        out: Some(out.to_path_buf()),
        ..replay::ReplayOptions::default()
    }
}

/// A training stage is a step of its own (its directory, its weights, its
/// pictures), its weights are reused when run again, and the stage that
/// uses them shows them as parameters, not genes.
#[test]
fn a_training_stage_runs_as_a_step_and_its_weights_reach_the_next_stage() {
    let dir = tempfile::tempdir().unwrap();
    let file = root().join("examples/pretrained.bat");
    let opts = RunOptions { stage: Some("avoidance".into()), ..options(dir.path()) };
    let log = Log::default();
    log.runner().run(load(&file), &opts).unwrap();
    let trained = Seen::Trained { stage: "avoidance".into(), actions: 1000, recorded: 1000, reused: false };
    assert_eq!(log.of("avoidance"), [trained]);
    let saved = read_text(&dir.path().join("avoidance/trained.json"));
    let v: serde_json::Value = serde_json::from_str(&saved).unwrap();
    assert_eq!(v["weights"][1].as_array().map(|w| w.len()), Some(18), "the avoid module's 18 weights");
    assert!(dir.path().join("avoidance/reinforcement.png").exists());
    log.runner().run(load(&file), &opts).unwrap();
    let reused = Seen::Trained { stage: "avoidance".into(), actions: 1000, recorded: 1000, reused: true };
    assert_eq!(log.of("avoidance"), [reused]);
    assert_eq!(read_text(&dir.path().join("avoidance/trained.json")), saved);
    let program = load(&file);
    let (navigation, _) = program.stage("navigation").unwrap();
    let layout = shaping_compiler::render_layout(&program, navigation);
    assert!(
        layout.contains("trained: `avoid` behavior, 18 weights, learned by stage `avoidance`"),
        "{layout}"
    );
}

/// An activation network learned in a training stage reaches the stage that
/// uses it (`activation trained STAGE`): `trained.json` holds it, the
/// layout lists it, and a `trained.json` written before activation weights
/// were saved is refused by a run, saying so, and retrained by `replay`.
#[test]
fn trained_activation_weights_reach_the_next_stage() {
    let dir = tempfile::tempdir().unwrap();
    let (file, program) = write_bat(
        dir.path(),
        "dodge.bat",
        "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage practice {
  world { arena 400mm x 600mm }
  train for 2000 actions
  module wander { sense ir  activation fixed -1.5  behavior forward }
  module dodge {
    sense ir
    activation random -0.5..0.5 hidden 2
    behavior turn left for 2 actions
    learn crbp(0.5, 0.5) on activation always
    reinforce max(prev ir[1..4]) > 0.3 ? 1 : -1
  }
}
stage evolved {
  evolve { population 10  generations 2 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir))
  module wander { sense ir  behavior forward }
  module dodge { sense ir  activation trained practice hidden 2  behavior turn left for 2 actions }
  links all evolvable
}
",
    );
    let out = dir.path().join("out");
    run(program.clone(), &options(&out)).unwrap();
    let path = out.join("practice/trained.json");
    let saved = read_json(&path);
    assert_eq!(saved["activation"][1].as_array().map(|w| w.len()), Some(21), "dodge: 2 x (8 + 1) + 3");
    let (evolved, _) = program.stage("evolved").unwrap();
    let table = shaping_compiler::render_layout(&program, evolved);
    assert!(
        table.contains("trained: `dodge` activation network, 21 weights, learned by stage `practice`"),
        "{table}"
    );
    assert!(!table.contains("dodge   weight"), "trained weights are not genes: {table}");
    // As written before activation weights were saved (and before seals).
    std::fs::remove_file(out.join("practice").join(shaping_engine::files::SEALS)).unwrap();
    let mut old = saved.clone();
    old.as_object_mut().unwrap().remove("activation");
    std::fs::write(&path, serde_json::to_string(&old).unwrap()).unwrap();
    let opts = RunOptions { stage: Some("evolved".into()), ..options(&out) };
    let err = error(run(load(&file), &opts));
    assert!(
        err.message().contains("trained.json") && err.message().contains("no activation weights"),
        "{err}"
    );
    let log = Log::default();
    let args = replay::ReplayOptions {
        stage: Some("evolved".into()),
        ..replay_opts(&file, &out, &dir.path().join("replay"))
    };
    replay::replay(load(&file), &args, &log).unwrap();
    let warnings = log.warnings().join("\n");
    assert!(
        warnings.contains("no activation weights") && warnings.contains("training the stage again"),
        "{warnings}"
    );
}

/// A long training life is trained in full, but a run records only its
/// first 20000 actions for the trace and the pictures, and says so: a
/// record of millions of actions would take gigabytes.
#[test]
fn a_long_training_life_records_its_first_actions_only() {
    let dir = tempfile::tempdir().unwrap();
    let (_, program) = write_bat(
        dir.path(),
        "long.bat",
        "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage practice {
  world { arena 400mm x 600mm }
  train for 30000 actions
  module avoid {
    sense ir
    activation fixed 1
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights random -0.5..0.5
    }
    learn crbp(0.5, 0.1) on behavior always over 30 actions
    reinforce sign(max(prev ir) - max(ir))
  }
}
",
    );
    let log = Log::default();
    let outcome = log.runner().run(program, &options(&dir.path().join("out"))).unwrap();
    let said = Seen::Trained { stage: "practice".into(), actions: 30000, recorded: 20000, reused: false };
    assert_eq!(log.of("practice"), [said]);
    assert!(matches!(outcome.stages[0], StageOutcome::Train { actions: 30000, .. }), "{:?}", outcome.stages);
    let trace = read_text(&dir.path().join("out/practice/trace.csv"));
    assert_eq!(trace.lines().count(), 1 + 20000, "a header and 20000 rows");
}

/// A test stage of several lives: `summary.json` says how many and how long
/// each was, `trace.csv` holds every action of every life (the action index
/// running on), `episode.json` every life as a part; the same seed gives the
/// same lives; replay, `--set` and an experiment take them.
#[test]
fn a_test_stage_lives_several_lives_in_each_world() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let stage = "\nstage third extends second {\n  world changes { battery 25 actions }\n  test best for 2 lives of 40 actions with learning\n}\n";
    let (file, program) = write_bat(d, "lives.bat", &(read_text(&tiny_bat()) + stage));
    let log = Log::default();
    log.runner().run(program.clone(), &RunOptions { no_report: false, ..options(&d.join("a")) }).unwrap();
    assert_eq!(log.of("third"), [Seen::Tested { stage: "third".into(), lives: 2 }]);
    let summary = read_json(&d.join("a/third/summary.json"));
    assert_eq!(summary["lives"], 2);
    let counts = |key: &str| -> Vec<u64> {
        summary[key].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect()
    };
    let (before, after) = (counts("before_lives"), counts("after_lives"));
    assert_eq!((before.len(), after.len()), (2, 2), "{summary}");
    assert!(before.iter().chain(&after).all(|&n| (1..=40).contains(&n)), "{summary}");
    let (b, a): (u64, u64) = (before.iter().sum(), after.iter().sum());
    assert_eq!(summary["before"]["actions"].as_u64(), Some(b));
    assert_eq!(summary["after"]["actions"].as_u64(), Some(a));
    let trace = read_text(&d.join("a/third/trace.csv"));
    let actions: Vec<u64> =
        trace.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    assert_eq!(actions, (0..b + a).collect::<Vec<u64>>(), "one row per action of every life");
    // The trajectory draws one life, over its own world.
    let svg = read_text(&d.join("a/third/trajectory.svg"));
    assert!(svg.contains("third: trajectory, the first of the 2 lives after the change"), "{svg}");
    let ep = read_json(&d.join("a/third/episode.json"));
    let worlds = ep["worlds"].as_array().unwrap();
    let parts: Vec<(&str, u64)> =
        worlds.iter().map(|w| (w["stage"].as_str().unwrap(), w["from"].as_u64().unwrap())).collect();
    assert_eq!(parts, [("second", 0), ("second", before[0]), ("third", b), ("third", b + after[0])]);
    let page = report_data(&d.join("a/report.html"));
    assert_eq!(page["episodes"][2]["worlds"].as_array().map(Vec::len), Some(4));

    // The same seed, the same lives; the outcome says how many.
    let outcome = run(program.clone(), &options(&d.join("b"))).unwrap();
    let last = outcome.stages[2].to_json();
    assert_eq!(last["summary"]["lives"], 2, "{last}");
    for f in ["trace.csv", "summary.json", "episode.json"] {
        let same = std::fs::read(d.join("a/third").join(f)).unwrap()
            == std::fs::read(d.join("b/third").join(f)).unwrap();
        assert!(same, "{f} differs between two runs of the same seed");
    }

    // `--set STAGE.test.lives`: the first life is the same life.
    run(program.clone(), &RunOptions { sets: sets(&["third.test.lives=3"]), ..options(&d.join("c")) })
        .unwrap();
    let s3 = read_json(&d.join("c/third/summary.json"));
    assert_eq!(s3["lives"], 3);
    assert_eq!(s3["before_lives"].as_array().map(Vec::len), Some(3));
    assert_eq!(s3["before_lives"][0], summary["before_lives"][0]);
    let zero = RunOptions { sets: sets(&["third.test.lives=0"]), ..options(&d.join("d")) };
    let err = error(run(program.clone(), &zero));
    assert!(err.message().contains("test.lives"), "{err}");
    assert!(!d.join("d").exists(), "nothing written before the error");

    // A replay of the test stage: one life in its world.
    let args = replay::ReplayOptions {
        stage: Some("third".into()),
        ..replay_opts(&file, &d.join("a"), &d.join("rep"))
    };
    replay::replay(program.clone(), &args, &Log::default()).unwrap();
    let rows = read_text(&d.join("rep/trace.csv")).lines().count() - 1;
    assert!((1..=40).contains(&rows), "{rows}");

    // An experiment over seeds tables the lives.
    let opts = shaping_engine::experiment::ExperimentOptions {
        file: file.clone(),
        seeds: 2,
        first_seed: 1,
        out: Some(d.join("e")),
        no_report: true,
        ..Default::default()
    };
    experiment(program, opts).unwrap();
    let md = read_text(&d.join("e/summary.md"));
    assert!(md.contains("| third | test, 2 lives of 40 actions"), "{md}");
}

/// The two numbers of `{prefix}N{between}M` in `text`.
fn count_in(text: &str, prefix: &str, between: &str) -> Option<(u64, u64)> {
    let rest = &text[text.rfind(prefix)? + prefix.len()..];
    let (n, rest) = rest.split_once(between)?;
    let m: String = rest.chars().take_while(char::is_ascii_digit).collect();
    Some((n.parse().ok()?, m.parse().ok()?))
}

/// A world crowded for the random placement (not certainly impossible, so
/// it runs) is no silent source of wrong numbers: the run warns, naming the
/// stage and how many episodes overlapped (at the first crowded generation
/// and with the totals at the end), a test stage names its crowded lives
/// and records them in `summary.json`, the checkpoint's statistics count
/// them, and `replay` warns too. A world with room enough says nothing and
/// writes none of it.
#[test]
fn a_crowded_world_is_warned_about_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    let file = test_file("crowded.bat");
    let out = dir.path().join("out");
    let log = Log::default();
    log.runner().run(load(&file), &options(&out)).unwrap();
    let said = log.warnings().join("\n");
    assert!(
        said.contains("warning: the world of stage `crowded` is too crowded: in generation 0,"),
        "{said}"
    );
    let total = count_in(&said, "warning: the world of stage `crowded` is too crowded: in ", " of ");
    assert!(total.is_some_and(|(n, m)| n > 0 && n <= m && m >= 12), "{said}");
    assert!(said.contains("could not be placed apart and overlap"), "{said}");
    assert!(said.contains("warning: the world of stage `tested` is too crowded: in "), "{said}");
    assert!(said.contains(" of 4 lives "), "{said}");
    let summary = read_json(&out.join("tested/summary.json"));
    assert!(summary["crowded_lives"].as_u64().is_some_and(|n| (1..=4).contains(&n)), "{summary}");
    assert!(summary["placement_failures"].as_u64().is_some_and(|n| n >= 1), "{summary}");
    let checkpoint = read_text(&out.join("crowded/checkpoint.json"));
    assert!(checkpoint.contains("\"crowded_episodes\""), "{checkpoint}");
    // The report's table of results says it for both stages.
    html::write(&out, None).unwrap();
    let page = read_text(&out.join("report.html"));
    assert!(page.matches("the world was too crowded: in ").count() >= 2, "no note in the report");
    assert!(page.contains(" episodes of its generations objects"), "no note for the evolved stage");

    let args = replay::ReplayOptions {
        stage: Some("crowded".into()),
        ..replay_opts(&file, &out, &dir.path().join("replay"))
    };
    replay::replay(load(&file), &args, &log).unwrap();
    let said = log.warnings().join("\n");
    assert!(said.contains("warning: the world of stage `crowded` is too crowded: in its episode"), "{said}");

    // The same file with room enough: no warning, no count in any file.
    let src = read_text(&file);
    let (_, roomy) = write_bat(
        dir.path(),
        "roomy.bat",
        &src.replace("objects 30 diameter 60mm", "objects 8 diameter 25mm"),
    );
    let roomy_out = dir.path().join("roomy");
    log.runner().run(roomy, &options(&roomy_out)).unwrap();
    assert_eq!(log.warnings(), Vec::<String>::new());
    let checkpoint = read_text(&roomy_out.join("crowded/checkpoint.json"));
    assert!(!checkpoint.contains("crowded_episodes"), "{checkpoint}");
    let summary = read_text(&roomy_out.join("tested/summary.json"));
    assert!(!summary.contains("crowded_lives"), "{summary}");
    html::write(&roomy_out, None).unwrap();
    let page = read_text(&roomy_out.join("report.html"));
    assert!(!page.contains("too crowded"), "a note in the report of a world with room enough");
}

/// The interruption flag set during a long test stage stops it at once
/// (within its life), says so, and writes nothing of the test: no
/// `summary.json`, `trace.csv` or `episode.json` that could pass for its
/// result.
#[test]
fn a_stopped_test_stage_stops_at_once_and_writes_nothing_of_it() {
    let dir = tempfile::tempdir().unwrap();
    let (_, program) = write_bat(
        dir.path(),
        "t.bat",
        "robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }\n\
         stage explore { evolve { population 4 generations 2 actions 30 } fitness per action wheels[0] \
         module m { sense ir behavior forward } }\n\
         stage long extends explore { test best for 1 lives of 1000000 actions with learning }\n",
    );
    let out = dir.path().join("out");
    let flag = Arc::new(AtomicBool::new(false));
    let (send, done) = std::sync::mpsc::channel();
    let opts = options(&out);
    let stop = Arc::clone(&flag);
    std::thread::spawn(move || {
        let runner = Engine { interrupt: Some(&stop), ..Engine::default() };
        let _ = send.send(runner.run(program, &opts));
    });
    // The evolved stage is done once its episode is written: the test is under way.
    let start = Instant::now();
    while !out.join("explore/episode.json").exists() {
        assert!(start.elapsed() < Duration::from_secs(120), "the evolved stage did not end");
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(300));
    flag.store(true, Ordering::Relaxed);
    let result = done.recv_timeout(Duration::from_secs(10)).expect("the test stage did not stop within 10 s");
    let err = error(result);
    assert_eq!(err.kind(), ErrorKind::Interrupted, "{err}");
    assert!(err.message().contains("interrupted: test stage `long` stopped in life 1 of 1"), "{err}");
    assert!(err.message().contains("nothing of it was written"), "{err}");
    for name in ["summary.json", "trace.csv", "episode.json", "best.genome"] {
        assert!(!out.join("long").join(name).exists(), "{name} was written: {err}");
    }
    assert!(!out.join("report.html").exists());
}

/// An e-puck file runs end to end: its episode carries the e-puck's
/// bearings for the pictures, its trace a column per ground sensor, and a
/// test stage that turns the sensors runs the same best with them.
#[test]
fn an_e_puck_file_runs_with_its_preset() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = "robot epuck {
  sensor ir[8] proximity  sensor floor[3] ground  actuator wheels[2] speed
}
stage roam {
  world {
    arena 400mm x 400mm
    body e-puck
    zone line from (0mm, 190mm) to (400mm, 210mm) grey 0
  }
  evolve { population 8 generations 2 actions 40 seed 5 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) * (1 - floor[1])
  module go { sense ir, floor  behavior neural { hidden 2  outputs linear  weights evolvable } }
  module away { sense ir  behavior toward(ir) }
  links all evolvable
}
stage turned extends roam {
  world changes { body { proximity facing [0, -45, -90, -150, 150, 90, 45, 0] } }
  test best for 40 actions
}
";
    let (_, program) = write_bat(d, "epuck.bat", source);
    let body = &program.stages[0].world.body;
    assert_eq!(body.radius, 35.0);
    run(program, &options(&d.join("a"))).unwrap();
    let ep = read_json(&d.join("a/roam/episode.json"));
    let bearings: Vec<f64> =
        ep["sensor_bearings"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert!((bearings[0] + 17.2).abs() < 1e-3 && (bearings[5] - 90.0).abs() < 1e-3, "{bearings:?}");
    let trace = read_text(&d.join("a/turned/trace.csv"));
    let header = trace.lines().next().unwrap();
    assert!(header.contains("floor[0]") && header.contains("floor[2]"), "{header}");
    let ep = read_json(&d.join("a/turned/episode.json"));
    assert_eq!(ep["sensor_bearings"][0].as_f64(), Some(0.0));
}
