//! Saved results, called as a library: a run stopped or killed resumes to
//! the result of a straight run; a saved result that no longer fits the
//! program (an edited file, another seed, damage) is refused, naming the
//! file and what changed, and kept.

mod common;

use std::sync::atomic::AtomicBool;

use common::{
    as_if_killed, error, files, load, options, read_json, read_text, result_files, root, run, tiny, tiny_bat,
    write_bat, Log, Seen, StopAfter,
};
use shaping_engine::run::StageOutcome;
use shaping_engine::{replay, ErrorKind};

/// Stopped after its first generation (the interruption flag, as Ctrl-C
/// sets it), then left as a kill right after the checkpoint would leave
/// it, the run resumes to the files of one never stopped.
#[test]
fn a_stopped_or_killed_run_resumes_to_the_same_result() {
    let straight = tempfile::tempdir().unwrap();
    run(tiny(), &options(straight.path())).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let flag = AtomicBool::new(false);
    let stop = StopAfter::new(&flag, 1);
    let mut opts = options(dir.path());
    opts.jobs = Some(1);
    let err = stop.runner().run(tiny(), &opts).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::Interrupted, "{err}");
    assert!(err.message().contains("stage `first` stopped after generation 1 of 6"), "{err}");
    as_if_killed(&dir.path().join("first"));
    run(tiny(), &options(dir.path())).unwrap();
    for stage in ["first", "second"] {
        let a = std::fs::read(straight.path().join(stage).join("checkpoint.json")).unwrap();
        let b = std::fs::read(dir.path().join(stage).join("checkpoint.json")).unwrap();
        assert!(a == b, "stage {stage}: resumed run differs from the straight run");
    }
    assert!(result_files(straight.path()) == result_files(dir.path()), "the results differ");
}

#[test]
fn a_corrupt_checkpoint_is_reported_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    run(tiny(), &options(dir.path())).unwrap();
    let ckpt = dir.path().join("first/checkpoint.json");
    std::fs::write(&ckpt, b"{ not json").unwrap();
    let err = error(run(tiny(), &options(dir.path())));
    assert_eq!(err.kind(), ErrorKind::Corrupt, "{err}");
    assert!(err.message().contains("checkpoint.json") && err.message().contains("corrupt"), "{err}");
    assert_eq!(std::fs::read(&ckpt).unwrap(), b"{ not json", "the checkpoint must be left as it was");
    let mut fresh = options(dir.path());
    fresh.fresh = true;
    run(tiny(), &fresh).unwrap();
}

#[test]
fn resuming_with_a_changed_earlier_stage_fails_but_an_appended_stage_runs() {
    let dir = tempfile::tempdir().unwrap();
    let src = tempfile::tempdir().unwrap();
    run(tiny(), &options(dir.path())).unwrap();
    let source = read_text(&tiny_bat());
    let (_, appended) = write_bat(
        src.path(),
        "appended.bat",
        &format!("{source}\nstage third extends second {{\n  evolve {{ generations 2 }}\n  module back {{ sense ir[6..7]  behavior back(0.5) }}\n  links all evolvable\n}}\n"),
    );
    run(appended, &options(dir.path())).unwrap();
    assert!(dir.path().join("third/best.genome").exists());

    let (_, changed) = write_bat(
        src.path(),
        "changed.bat",
        &source.replace("module wander { sense ir ", "module wander { sense ir[0..5] "),
    );
    let err = error(run(changed, &options(dir.path())));
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    assert!(err.message().contains("first") && err.message().contains("--fresh"), "{err}");
}

/// The issue's file: two scripted modules, links evolved.
const EDITED: &str = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  evolve { population 20  generations 5  actions 100  seed 1 }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
  module n { sense ir  behavior turn left }
  links all evolvable
}
";

/// Editing anything a checkpoint depends on makes the run refuse it, saying
/// what changed; `--fresh` starts again and shows the new result. Fewer
/// generations than the checkpoint holds are refused naming both numbers;
/// more continue it to the result of a straight run, saying so.
#[test]
fn an_edited_file_is_not_resumed_from_its_old_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let (file, program) = write_bat(dir.path(), "s.bat", EDITED);
    run(program, &options(&out)).unwrap();
    let log = Log::default();
    log.runner().run(load(&file), &options(&out)).unwrap();
    let done = Seen::Resumed { stage: "s".into(), generation: 5, generations: 5, finished: true };
    assert_eq!(log.of("s")[0], done, "all 5 generations done before");

    for (edit, what) in [
        (
            EDITED.replace("per action wheels[0]", "per action wheels[0] * 0.5 + 7"),
            "the fitness of `s` changed",
        ),
        (EDITED.replace("behavior turn left", "behavior turn right"), "the modules of `s` changed"),
        (
            EDITED.replace("stage s {", "stage s {\n  world { arena 800mm x 800mm }"),
            "the world of `s` changed",
        ),
    ] {
        let (_, program) = write_bat(dir.path(), "s.bat", &edit);
        let err = error(run(program, &options(&out)));
        assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
        let msg = err.message();
        assert!(msg.contains("cannot resume from") && msg.contains("checkpoint.json"), "{err}");
        assert!(msg.contains(what) && msg.contains("`--fresh`") && msg.contains("`--out`"), "{err}");
    }
    // Nor does `replay` take the run's best for the edited stage, but for
    // the run's own program, which it replays when only settings differ.
    let args = replay::ReplayOptions {
        file: file.clone(),
        run: Some(out.clone()),
        out: Some(dir.path().join("r")),
        ..replay::ReplayOptions::default()
    };
    let log = Log::default();
    replay::replay(load(&file), &args, &log).unwrap();
    let said = log.warnings().join("\n");
    assert!(said.contains("is of this file with other settings (`--set s.world.arena="), "{said}");
    std::fs::remove_dir_all(dir.path().join("r")).unwrap();
    write_bat(dir.path(), "s.bat", &EDITED.replace("behavior turn left", "behavior turn right"));
    let err = error(replay::replay(load(&file), &args, &Log::default()));
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    assert!(
        err.message().contains("is not of this program")
            && err.message().contains("the modules of `s` changed")
            && err.message().contains("replay it with the run's own program (`shaping replay"),
        "{err}"
    );
    assert!(!dir.path().join("r").exists(), "the refused replay wrote nothing");
    // The last edit, started again: the fitness is that of the edited file.
    let (_, program) = write_bat(
        dir.path(),
        "s.bat",
        &EDITED.replace("per action wheels[0]", "per action wheels[0] * 0.5 + 7"),
    );
    let mut fresh = options(&out);
    fresh.fresh = true;
    let outcome = run(program, &fresh).unwrap();
    let StageOutcome::Evolve { best, .. } = outcome.stages[0] else { panic!("{:?}", outcome.stages) };
    assert!(best > 700.0, "100 actions of at least 7: {best}");

    let fewer = dir.path().join("fewer");
    let (_, four) = write_bat(dir.path(), "s.bat", &EDITED.replace("generations 5", "generations 4"));
    run(four, &options(&fewer)).unwrap();
    let (_, three) = write_bat(dir.path(), "s.bat", &EDITED.replace("generations 5", "generations 3"));
    let err = error(run(three, &options(&fewer)));
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    assert!(err.message().contains("holds 4 generations of stage `s`, which now declares 3"), "{err}");

    let (file, seven) = write_bat(dir.path(), "s.bat", &EDITED.replace("generations 5", "generations 7"));
    log.runner().run(seven, &options(&fewer)).unwrap();
    let resumed = Seen::Resumed { stage: "s".into(), generation: 4, generations: 7, finished: false };
    assert_eq!(log.of("s")[0], resumed, "resuming `s` at generation 4 of 7");
    run(load(&file), &options(&dir.path().join("straight"))).unwrap();
    let ckpt = |d: &str| std::fs::read(dir.path().join(d).join("s/checkpoint.json")).unwrap();
    assert!(ckpt("fewer") == ckpt("straight"), "the extended run differs from the straight run");
}

/// `trained.json` is tied to its training stage the same way.
#[test]
fn stale_trained_weights_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let source = read_text(&root().join("examples/pretrained.bat"));
    let (_, program) = write_bat(dir.path(), "p.bat", &source);
    let mut opts = options(&dir.path().join("out"));
    opts.stage = Some("avoidance".into());
    run(program, &opts).unwrap();
    let (_, edited) =
        write_bat(dir.path(), "p.bat", &source.replace("train for 1000 actions", "train for 900 actions"));
    let err = error(run(edited, &opts));
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    assert!(
        err.message().contains("trained.json")
            && err.message().contains("the settings of `avoidance` changed"),
        "{err}"
    );
}

/// A checkpoint with a bit that is not 0 or 1 is refused naming the file and
/// the place; so is a genome argument or file that is not a bit string.
#[test]
fn bad_bits_and_genomes_are_refused_naming_where() {
    let dir = tempfile::tempdir().unwrap();
    run(tiny(), &options(dir.path())).unwrap();
    let path = dir.path().join("first/checkpoint.json");
    let mut cp = read_json(&path);
    cp["population"][3]["bits"][5] = serde_json::json!(2);
    // Sealed anew, and its directory's seals gone: a file that passes its
    // checksum (as the fuzzer makes them) still has its bits checked.
    std::fs::remove_file(dir.path().join("first").join(shaping_engine::files::SEALS)).unwrap();
    let text = shaping_engine::files::seal(&serde_json::to_string_pretty(&cp).unwrap());
    std::fs::write(&path, text).unwrap();
    let err = error(run(tiny(), &options(dir.path())));
    assert!(
        err.message().contains("first/checkpoint.json")
            && err.message().contains("bit 5 of individual 3 is 2"),
        "{err}"
    );

    // `--genome` of `replay` and `drive`.
    let err = error(replay::parse_genome("2101"));
    assert!(err.message().contains("`--genome 2101` is not a genome: character 1 is `2`"), "{err}");
    assert!(!err.message().contains("cannot read"), "not read as a file: {err}");
    let file = dir.path().join("g.genome");
    std::fs::write(&file, "0101\n0171\n").unwrap();
    let err = error(replay::parse_genome(file.to_str().unwrap()));
    assert!(err.message().contains("g.genome` does not hold a genome: line 2, column 3 is `7`"), "{err}");
    let err = error(replay::parse_genome("no-such-file"));
    assert!(err.message().contains("`--genome no-such-file` is neither a string of 0 and 1"), "{err}");
}

/// A directory whose stages ran with two seeds (one started again with
/// `--fresh --stage S --seed N`) cannot be resumed with either seed: the
/// error says which stage has which seed and what to do, not `--seed` advice
/// that fails on another stage.
#[test]
fn stages_of_two_seeds_in_one_directory_are_named() {
    let dir = tempfile::tempdir().unwrap();
    run(tiny(), &options(dir.path())).unwrap();
    let mut first_99 = options(dir.path());
    first_99.stage = Some("first".into());
    first_99.seed = Some(99);
    run(tiny(), &shaping_engine::run::RunOptions { fresh: true, ..first_99.clone() }).unwrap();
    for (seed, said) in [(Some(99), 99), (None, 3)] {
        let opts = shaping_engine::run::RunOptions { seed, ..options(dir.path()) };
        let err = error(run(tiny(), &opts));
        assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
        let msg = err.message();
        assert!(msg.contains("holds stages of different seeds (`first` seed 99, `second` seed 3)"), "{err}");
        assert!(msg.contains(&format!("pass `--fresh` to run every stage again with seed {said}")), "{err}");
        assert!(!msg.contains("pass `--seed"), "{err}");
    }
    // The stage alone still resumes; `--fresh` starts everything again.
    run(tiny(), &first_99).unwrap();
    run(tiny(), &shaping_engine::run::RunOptions { fresh: true, ..options(dir.path()) }).unwrap();
}

/// A run directory belongs to one program: a run of another file into it
/// is refused naming both files before anything is written (two files of
/// one robot share a program's name, and a stage name), and `--fresh`
/// replaces that run, as the message says. Through the library, with no
/// file named, a colliding stage of another seed is not said to resume
/// with `--seed` when it would not.
#[test]
fn a_run_of_another_file_into_a_directory_is_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = read_text(&tiny_bat());
    let (a, a_program) = write_bat(d, "a.bat", &source);
    let other = source.replace("population 12", "population 10").replace("seed 3", "seed 2");
    let (b, b_program) = write_bat(d, "b.bat", &other);
    let out = d.join("out");
    let runner = shaping_engine::Engine::default();
    runner.run_file(a_program.clone(), &a, &options(&out)).unwrap();
    let before = files(&out);
    let err = error(runner.run_file(b_program.clone(), &b, &options(&out)));
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    assert!(err.message().contains("holds a run of `a.bat`, not of `b.bat`"), "{err}");
    assert!(err.message().contains("pass `--fresh` to replace that run with this one"), "{err}");
    assert!(files(&out) == before, "nothing written");
    // The same file again resumes.
    runner.run_file(a_program, &a, &options(&out)).unwrap();

    // Without a file's name: its stages of seed 3 do not fit the other
    // program, so `--seed 3` is not the advice.
    let err = error(run(b_program.clone(), &options(&out)));
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    let msg = err.message();
    assert!(
        msg.contains("belongs to a run with seed 3 (this run has seed 2), which `--seed 3` would not resume"),
        "{err}"
    );
    assert!(msg.contains("the settings of `first` changed"), "{err}");
    assert!(files(&out) == before, "nothing written");
    let with_3 = shaping_engine::run::RunOptions { seed: Some(3), ..options(&out) };
    assert_eq!(error(run(b_program.clone(), &with_3)).kind(), ErrorKind::Stale);

    let fresh = shaping_engine::run::RunOptions { fresh: true, ..options(&out) };
    runner.run_file(b_program.clone(), &b, &fresh).unwrap();
    assert_eq!(read_json(&out.join("source.json"))["file"], "b.bat");
    runner.run_file(b_program, &b, &options(&out)).unwrap();
}

/// Saved stages of one other seed that fit the program: `--seed` resumes
/// them, as the message says, and nothing is written before it says so.
#[test]
fn saved_stages_of_another_seed_name_the_seed_that_resumes_them() {
    let dir = tempfile::tempdir().unwrap();
    let seven = shaping_engine::run::RunOptions { seed: Some(7), ..options(dir.path()) };
    run(tiny(), &seven).unwrap();
    let before = files(dir.path());
    let err = error(run(tiny(), &options(dir.path())));
    assert!(
        err.message()
            .contains("belongs to a run with seed 7 (this run has seed 3); pass `--seed 7` to resume it"),
        "{err}"
    );
    assert!(files(dir.path()) == before, "nothing written");
    run(tiny(), &seven).unwrap();
}

/// `program.json` describes every stage directory beside it: a run of one
/// stage that would describe another stage's results with settings they
/// were not run with (or with a parent they did not extend) is refused,
/// naming that stage and the ways out, and each way out works.
#[test]
fn a_run_that_would_misdescribe_a_stage_it_does_not_run_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    run(tiny(), &options(out)).unwrap();
    let before = files(out);
    let first = |sets: &[&str]| shaping_engine::run::RunOptions {
        stage: Some("first".into()),
        sets: common::sets(sets),
        ..options(out)
    };
    let err = error(run(tiny(), &first(&["second.world.arena=800x900"])));
    assert_eq!(err.kind(), ErrorKind::Stale, "{err}");
    let msg = err.message();
    assert!(
        msg.contains("with another definition of stage `second` (the world of `second` changed)"),
        "{err}"
    );
    assert!(msg.contains("leave out `--set second.world.arena=800x900`, "), "{err}");
    assert!(msg.contains("pass `--fresh` without `--stage` to run every stage again"), "{err}");
    assert!(files(out) == before, "nothing written");
    // A stage it extends changed: its results are of the old one.
    let fresh_first =
        shaping_engine::run::RunOptions { fresh: true, ..first(&["first.evolve.mutation=0.2"]) };
    let err = error(run(tiny(), &fresh_first));
    assert!(err.message().contains("which `second` extends, changed"), "{err}");
    assert!(err.message().contains("leave out `--set first.evolve.mutation=0.2`, "), "{err}");
    assert!(files(out) == before, "nothing written");
    // The ways out: without the setting of `second`; every stage again;
    // `second` moved away.
    run(tiny(), &first(&[])).unwrap();
    let all = shaping_engine::run::RunOptions { fresh: true, ..first(&["second.world.arena=800x900"]) };
    run(tiny(), &shaping_engine::run::RunOptions { stage: None, ..all }).unwrap();
    let program = read_json(&out.join("program.json"));
    assert_eq!(program["stages"][1]["world"]["arena"], serde_json::json!([800.0, 900.0]));
    // Now the file without the setting is what would misdescribe `second`.
    let err = error(run(tiny(), &first(&[])));
    assert!(
        err.message().contains("add `--set second.world.arena=800x900` (the settings its run was made with)"),
        "{err}"
    );
    run(tiny(), &first(&["second.world.arena=800x900"])).unwrap();
    std::fs::remove_dir_all(out.join("second")).unwrap();
    run(tiny(), &fresh_first).unwrap();
}
