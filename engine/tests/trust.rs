//! Only what a run sealed is trusted (issue 47): a checksum removed is no
//! way around it, and every file a report or a resume reads is sealed.

mod common;

use common::{error, options, run, tiny, Log};
use shaping_engine::files::SEALS;
use shaping_engine::run::Runner;
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
    Runner { observer: &log, ..Runner::default() }.run(tiny(), &opts).unwrap();
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
