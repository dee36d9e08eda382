//! Only what a run sealed is trusted (issue 47): a checksum removed is no
//! way around it, every file a report or a resume reads is sealed, a
//! replay never writes into a run's stage directory, a link planted in
//! place of a stage directory is refused, a lock removed by hand is said
//! by the run that held it, and the temporary files of killed processes
//! go.

mod common;

use std::path::Path;
use std::sync::{Arc, Barrier};

use common::{error, files, options, run, tiny, tiny_bat, Holding, Log};
use shaping_engine::files::{remove_stale_temporaries, DirLock, SEALS};
use shaping_engine::replay::{self, ReplayOptions};
use shaping_engine::Engine;
use shaping_engine::{html, ErrorKind};

/// `text` with its last `"checksum"` field removed, as a hand edit leaves it.
fn without_checksum(text: &str) -> String {
    let at = text.rfind(",\n  \"checksum\"").expect("a checksum");
    format!("{}\n}}\n", &text[..at])
}

/// `text` with the first digit after `from` changed.
fn digit_changed(text: &str, from: &str) -> String {
    let start = text.find(from).unwrap() + from.len();
    let at = text[start..].find(|c: char| c.is_ascii_digit()).unwrap() + start;
    let d = text.as_bytes()[at] - b'0';
    format!("{}{}{}", &text[..at], (d + 1) % 10, &text[at + 1..])
}

/// 47.5: deleting the checkpoint's checksum (or misspelling its key) and
/// changing a digit does not make it a file from before checksums: its
/// directory's seal refuses it, naming it; only a directory that has no
/// seals reads it, with a warning.
#[test]
fn a_checkpoint_without_its_checksum_is_refused_unless_nothing_in_its_directory_is_sealed() {
    let dir = tempfile::tempdir().unwrap();
    let mut opts = options(dir.path());
    opts.stage = Some("first".into());
    run(tiny(), &opts).unwrap();
    let path = dir.path().join("first/checkpoint.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let removed = digit_changed(&without_checksum(&text), "\"fitness\": [");
    let misspelt = digit_changed(&text.replace("\"checksum\"", "\"checksun\""), "\"fitness\": [");
    for damaged in [&removed, &misspelt] {
        std::fs::write(&path, damaged).unwrap();
        let err = error(run(tiny(), &opts));
        assert_eq!(err.kind(), ErrorKind::Corrupt, "{err}");
        assert!(err.message().contains(&path.display().to_string()), "{err}");
        assert!(err.message().contains("checksum does not match"), "{err}");
        assert_eq!(&std::fs::read_to_string(&path).unwrap(), damaged, "kept as it is");
    }
    // A directory with no seals (written before them): the file is read,
    // and the run says so.
    std::fs::remove_file(dir.path().join("first").join(SEALS)).unwrap();
    std::fs::write(&path, &removed).unwrap();
    let log = Log::default();
    Engine { observer: &log, ..Engine::default() }.run(tiny(), &opts).unwrap();
    let warnings = log.warnings();
    assert!(
        warnings.iter().any(|w| w.starts_with("warning: `") && w.contains("checkpoint.json` has no seal")),
        "{warnings:?}"
    );
}

/// A small file with every kind of stage: training, two evolved, a test.
fn all_stages() -> shaping_runtime::program::Program {
    common::load(&common::test_file("stages.bat"))
}

/// 47.6: a test stage's `best.genome`, `summary.json`, `episode.json` and
/// an evolved stage's `generations.csv` changed by hand are named by the
/// report, not shown.
#[test]
fn every_file_the_report_reads_is_checked_against_its_seal() {
    let dir = tempfile::tempdir().unwrap();
    run(all_stages(), &options(dir.path())).unwrap();
    let straight = html::collect(dir.path()).unwrap();
    for (file, edit) in [
        ("check/best.genome", None),
        ("check/summary.json", Some("\"fitness\": ")),
        ("check/episode.json", Some("\"x\":[")),
        ("first/generations.csv", Some("\n")),
        ("first/episode.json", Some("\"battery\":[")),
        ("avoidance/episode.json", Some("\"x\":[")),
    ] {
        let path = dir.path().join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let changed = match edit {
            Some(from) => digit_changed(&text, from),
            None => {
                let first = if text.starts_with('0') { "1" } else { "0" };
                format!("{first}{}", &text[1..])
            }
        };
        std::fs::write(&path, &changed).unwrap();
        let err = error(html::collect(dir.path()));
        assert_eq!(err.kind(), ErrorKind::Corrupt, "{file}: {err}");
        assert!(err.message().contains(&path.display().to_string()), "{err}");
        std::fs::write(&path, &text).unwrap();
    }
    let again = html::collect(dir.path()).unwrap();
    assert_eq!(format!("{again:?}"), format!("{straight:?}"));
    // Without its seals, a stage is read with a word for each file.
    std::fs::remove_file(dir.path().join("check").join(SEALS)).unwrap();
    let told = std::cell::RefCell::new(Vec::new());
    let unsealed =
        html::data::collect_with(dir.path(), &|p| told.borrow_mut().push(p.to_path_buf())).unwrap();
    assert_eq!(format!("{unsealed:?}"), format!("{straight:?}"));
    let mut told = told.take();
    told.sort();
    told.dedup();
    let names: Vec<String> =
        told.iter().map(|p| p.strip_prefix(dir.path()).unwrap().display().to_string()).collect();
    assert_eq!(names, ["check/best.genome", "check/episode.json", "check/summary.json"]);
    let warning = shaping_engine::files::unsealed_warning(&told).unwrap();
    assert!(warning.starts_with("warning: 3 files have no seal (`"), "{warning}");
}

/// 47.8: `replay --out RUN/STAGE` would replace the stage's `episode.json`:
/// refused before anything runs, as are the run's own directory and a link.
#[test]
fn a_replay_never_writes_into_a_run_s_directories() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = dir.path().join("run");
    run(tiny(), &options(&run_dir)).unwrap();
    let before = files(&run_dir);
    let replay_into = |out: &Path| {
        let args = ReplayOptions {
            file: tiny_bat(),
            stage: Some("second".into()),
            run: Some(run_dir.clone()),
            out: Some(out.to_path_buf()),
            ..ReplayOptions::default()
        };
        replay::replay(tiny(), &args, &shaping_engine::run::Silent)
    };
    for (out, what) in [
        (
            run_dir.join("second"),
            format!("the directory of stage `second` of the run in `{}`", run_dir.display()),
        ),
        (run_dir.clone(), "a run directory (it holds `program.json`)".to_string()),
    ] {
        let err = error(replay_into(&out));
        assert_eq!(err.kind(), ErrorKind::Invalid, "{err}");
        assert_eq!(
            err.message(),
            format!(
                "error: `{}` is {what}; a replay never writes into a run's directories: choose another `--out` \
                 (by default a replay writes into `STAGE/replay` of the run)",
                out.display()
            )
        );
    }
    // A stage's directory that is not there yet is the stage's all the same.
    std::fs::remove_file(run_dir.join(DirLock::FILE)).unwrap();
    let mut program = tiny();
    program.stages[1].name = "third".into();
    shaping_engine::rundir::write_program(&run_dir, &program).unwrap();
    let err = error(replay_into(&run_dir.join("third")));
    assert!(err.message().contains("is the directory of stage `third` of the run in `"), "{err}");
    // A directory a run wrote, wherever it is.
    let moved = dir.path().join("moved");
    std::fs::create_dir(&moved).unwrap();
    std::fs::copy(run_dir.join("first/checkpoint.json"), moved.join("checkpoint.json")).unwrap();
    let err = error(replay_into(&moved));
    assert!(err.message().contains("is a directory of a run (it holds `checkpoint.json`)"), "{err}");
    assert!(!run_dir.join("third").exists());
    shaping_engine::rundir::write_program(&run_dir, &tiny()).unwrap();
    #[cfg(unix)]
    {
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(run_dir.join("first"), &link).unwrap();
        let err = error(replay_into(&link));
        assert!(err.message().contains("is a symbolic link"), "{err}");
    }
    assert_eq!(files(&run_dir), before, "nothing of the run was touched");
    // Its own directory, and an earlier replay's, are fine.
    let out = dir.path().join("replayed");
    replay_into(&out).unwrap();
    replay_into(&out).unwrap();
    replay_into(&run_dir.join("second/replay")).unwrap();
}

/// 47.8: a link planted in place of a stage's directory is refused, not
/// followed.
#[cfg(unix)]
#[test]
fn a_link_planted_in_place_of_a_stage_directory_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let elsewhere = dir.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    let out = dir.path().join("run");
    std::fs::create_dir(&out).unwrap();
    std::os::unix::fs::symlink(&elsewhere, out.join("first")).unwrap();
    let err = error(run(tiny(), &options(&out)));
    assert_eq!(err.kind(), ErrorKind::Invalid, "{err}");
    assert_eq!(
        err.message(),
        format!(
            "error: `{}` is a symbolic link; a run writes only into directories of its own, never through a \
             link: remove it, or choose another `--out`",
            out.join("first").display()
        )
    );
    assert_eq!(std::fs::read_dir(&elsewhere).unwrap().count(), 0, "nothing written through the link");
}

/// 47.8: a `.lock` deleted by hand lets a second run in; the first says,
/// at its next write, that its lock was removed, and stops.
#[test]
fn a_run_whose_lock_was_removed_says_so_at_its_next_write() {
    let dir = tempfile::tempdir().unwrap();
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
    let lock = dir.path().join(DirLock::FILE);
    std::fs::remove_file(&lock).unwrap();
    // Another process gets in: its lock is a new file (in this process, a
    // second lock of the directory could be told from the first by nothing
    // but the thread).
    std::fs::write(&lock, "shaping, process 1").unwrap();
    barrier.wait();
    let err = first.join().unwrap().unwrap_err();
    assert_eq!(err.kind(), ErrorKind::Locked, "{err}");
    assert!(
        err.message().starts_with(&format!(
            "error: the lock `{}` was replaced while this process held it, so another run may be writing into `{}`; \
             stopped before writing `{}",
            lock.display(),
            dir.path().display(),
            dir.path().join("first").join(SEALS).display()
        )),
        "{err}"
    );
    // Removed and not replaced.
    let held = DirLock::acquire(dir.path()).unwrap();
    std::fs::remove_file(held.path()).unwrap();
    let err = shaping_engine::files::write_atomic(&dir.path().join("x"), b"x").unwrap_err();
    assert!(err.message().contains("` was removed while this process held it"), "{err}");
    drop(held);
    shaping_engine::files::write_atomic(&dir.path().join("x"), b"x").unwrap();
}

/// 47.9: a killed write's temporary file is removed by the next run in the
/// directory, under its lock; a live process's is not.
#[test]
fn the_next_run_removes_the_temporary_files_of_dead_processes() {
    let dir = tempfile::tempdir().unwrap();
    // A process that is gone: a child that has exited (and been waited for).
    let mut child = std::process::Command::new("true").spawn().unwrap();
    let dead = child.id();
    child.wait().unwrap();
    let alive = std::process::id();
    std::fs::create_dir_all(dir.path().join("first/.writing")).unwrap();
    let stale = [
        dir.path().join(format!(".program.json.{dead}.0.tmp")),
        dir.path().join(format!("first/.checkpoint.json.{dead}.7.tmp")),
        dir.path().join(format!("first/.writing/.summary.json.{dead}.2.tmp")),
    ];
    let kept = [
        dir.path().join(format!("first/.checkpoint.json.{alive}.3.tmp")),
        dir.path().join("first/.checkpoint.json.tmp"),
        dir.path().join(format!("first/checkpoint.json.{dead}.1.tmp")),
        dir.path().join(format!("first/.{dead}.1.tmp")),
    ];
    for f in stale.iter().chain(&kept) {
        std::fs::write(f, "partial").unwrap();
    }
    run(tiny(), &options(dir.path())).unwrap();
    for f in &stale {
        assert!(!f.exists(), "{} removed", f.display());
    }
    for f in &kept {
        assert!(f.exists(), "{} kept", f.display());
    }
    // Called directly: links are never removed or followed.
    #[cfg(unix)]
    {
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "precious").unwrap();
        let link = dir.path().join(format!(".best.genome.{dead}.0.tmp"));
        std::os::unix::fs::symlink(&victim, &link).unwrap();
        remove_stale_temporaries(dir.path());
        assert!(std::fs::symlink_metadata(&link).is_ok());
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    }
}

/// An experiment's summaries and reports read its seeds' files as a report
/// does: those without a seal are listed for a warning.
#[test]
fn an_experiment_lists_the_files_it_read_without_a_seal() {
    use shaping_engine::experiment::{ExperimentOptions, Plan};
    let dir = tempfile::tempdir().unwrap();
    let opts = || ExperimentOptions { no_report: false, ..common::tiny_experiment(dir.path(), 2) };
    let finished = common::experiment(tiny(), opts()).unwrap();
    assert_eq!(finished.unsealed, Vec::<std::path::PathBuf>::new());
    for seed in ["seed-1", "seed-2"] {
        std::fs::remove_file(dir.path().join(seed).join("second").join(SEALS)).unwrap();
    }
    let finished = Plan::new(tiny(), opts()).unwrap().finish().unwrap();
    let names: Vec<String> = finished
        .unsealed
        .iter()
        .map(|p| p.strip_prefix(dir.path()).unwrap().display().to_string())
        .filter(|p| p.contains("/second/"))
        .collect();
    assert!(names.iter().any(|n| n.ends_with("second/best.genome")), "{names:?}");
    assert!(names.iter().any(|n| n.ends_with("second/generations.csv")), "{names:?}");
}
