//! The damaged-file harness (issue 47): every file of a small run (a
//! training stage, two evolved stages, a test), of an experiment and of a
//! sweep is damaged in turn (bits flipped, a digit edited, truncated,
//! emptied, a field or a line removed), and the report and a resume of the
//! damaged directory either refuse, naming the damaged file, or give what
//! they give undamaged, byte for byte: never a silently different result.
//! (`program.json` is the program the user asked for: an edit of it is
//! another program's run, and `--genome` is the user's; neither is here.)

mod common;

use std::path::{Path, PathBuf};

use common::{experiment, files, load, options, run, test_file, tiny, tiny_experiment};
use shaping_engine::experiment::ExperimentOptions;
use shaping_engine::files::SEALS;
use shaping_engine::sweep::parse_set;
use shaping_engine::{html, Error};

/// The damages of a file's bytes, each with its name.
fn damages(name: &str, bytes: &[u8]) -> Vec<(String, Vec<u8>)> {
    let n = bytes.len();
    let mut out = Vec::new();
    if n == 0 {
        return out;
    }
    let picture = name.ends_with(".png") || name.ends_with(".svg");
    let places: &[usize] = if picture { &[n / 2] } else { &[0, n / 2, n - 1] };
    for &at in places {
        let mut b = bytes.to_vec();
        b[at] ^= 1;
        out.push((format!("bit 0 of byte {at} flipped"), b));
    }
    if picture {
        return out;
    }
    if let Some(at) = bytes[n / 2..].iter().position(u8::is_ascii_digit).map(|p| p + n / 2) {
        let mut b = bytes.to_vec();
        b[at] = b'0' + (b[at] - b'0' + 1) % 10;
        out.push((format!("digit at byte {at} edited"), b));
    }
    out.push(("truncated to half".into(), bytes[..n / 2].to_vec()));
    match serde_json::from_slice::<serde_json::Value>(bytes) {
        Ok(serde_json::Value::Object(map)) => {
            let keys: Vec<String> = map.keys().cloned().collect();
            let mut removed: Vec<&String> = keys.iter().take(1).collect();
            removed.extend(keys.iter().filter(|k| *k == "checksum" || *k == "fitness" || *k == "seeds"));
            for key in removed {
                let mut m = map.clone();
                m.remove(key);
                let v = serde_json::Value::Object(m);
                let text = if bytes.starts_with(b"{\n") {
                    serde_json::to_string_pretty(&v).unwrap()
                } else {
                    serde_json::to_string(&v).unwrap()
                };
                out.push((format!("field `{key}` removed"), text.into_bytes()));
            }
        }
        _ => {
            let text = String::from_utf8_lossy(bytes);
            let lines: Vec<&str> = text.lines().collect();
            if lines.len() > 1 {
                let kept = lines[..lines.len() - 1].join("\n") + "\n";
                out.push(("last line removed".into(), kept.into_bytes()));
            }
        }
    }
    out
}

/// Copies the directory tree `from` into `to`.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// What a report shows of a directory (where it was read from aside).
fn report(dir: &Path) -> Result<serde_json::Value, Error> {
    let mut v = serde_json::to_value(html::collect(dir)?).unwrap();
    v["source"] = serde_json::Value::Null;
    Ok(v)
}

/// An outcome is either what the undamaged directory gives or a refusal
/// naming the damaged file.
fn check(outcome: Result<(), Error>, damaged: &Path, case: &str) {
    if let Err(e) = outcome {
        assert!(
            e.message().contains(&format!("`{}`", damaged.display())),
            "{case}: refused without naming the damaged file: {e}"
        );
    }
}

/// The files a resume reads: every damage of them is resumed; of the
/// others (which a resume writes anew, or leaves), one damage in three, in
/// turn, so that a run's worth of resumes stays a few seconds.
fn read_by_resume(name: &str) -> bool {
    ["checkpoint.json", "trained.json", SEALS, "summary.json"].iter().any(|f| name.ends_with(f))
}

/// A scratch directory, in memory where there is one (`/dev/shm`): the
/// harness writes thousands of files, each synced.
fn scratch() -> tempfile::TempDir {
    let shm = Path::new("/dev/shm");
    let fast = shm.is_dir().then(|| tempfile::Builder::new().prefix("damage").tempdir_in(shm).ok()).flatten();
    fast.unwrap_or_else(|| tempfile::tempdir().unwrap())
}

/// Damages every file of `base` in turn (but `program.json`) and checks the
/// report and `resume` (which redoes what the directory's command did).
fn harness(base: &Path, resume: &dyn Fn(&Path) -> Result<(), Error>) -> usize {
    let scratch = scratch();
    let pristine = scratch.path().join("pristine");
    copy_tree(base, &pristine);
    let shown = report(&pristine).unwrap();
    resume(&pristine).unwrap();
    let resumed = files(&pristine);
    let mut cases = 0;
    for (k, (name, bytes)) in files(base).into_iter().enumerate() {
        if name.ends_with("program.json") {
            continue;
        }
        for (i, (how, damaged)) in damages(&name, &bytes).into_iter().enumerate() {
            cases += 1;
            let case = format!("`{name}` {how}");
            let dir = scratch.path().join(format!("case-{cases}"));
            copy_tree(base, &dir);
            let path = dir.join(&name);
            std::fs::write(&path, &damaged).unwrap();
            let shown_now = report(&dir);
            if let Ok(data) = &shown_now {
                assert!(data == &shown, "{case}: the report shows something else");
            }
            check(shown_now.map(|_| ()), &path, &case);
            if !read_by_resume(&name) && (i + k) % 3 != 0 {
                std::fs::remove_dir_all(&dir).unwrap();
                continue;
            }
            let resumed_now = resume(&dir);
            if resumed_now.is_ok() {
                for (file, want) in &resumed {
                    let got = std::fs::read(dir.join(file)).unwrap_or_default();
                    // The damaged file, where nothing reads or rewrites it, as it was left.
                    let untouched = *file == name && got == damaged;
                    assert!(got == *want || untouched, "{case}: resumed, `{file}` differs");
                }
            }
            check(resumed_now, &path, &case);
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }
    cases
}

fn stages_bat() -> PathBuf {
    test_file("stages.bat")
}

#[test]
fn a_damaged_file_of_a_run_is_refused_by_name_or_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    run(load(&stages_bat()), &options(dir.path())).unwrap();
    let cases = harness(dir.path(), &|d| run(load(&stages_bat()), &options(d)).map(|_| ()));
    assert!(cases > 50, "{cases}");
}

#[test]
fn a_damaged_file_of_an_experiment_or_a_sweep_is_refused_by_name_or_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let exp = |out: &Path| ExperimentOptions { jobs: Some(2), ..tiny_experiment(out, 2) };
    experiment(tiny(), exp(dir.path())).unwrap();
    let cases = harness(dir.path(), &|d| experiment(tiny(), exp(d)).map(|_| ()));
    assert!(cases > 50, "{cases}");

    let dir = tempfile::tempdir().unwrap();
    let sweep = |out: &Path| ExperimentOptions {
        sets: vec![parse_set("first.evolve.generations=2,3").unwrap()],
        stage: Some("first".into()),
        jobs: Some(2),
        ..tiny_experiment(out, 1)
    };
    experiment(tiny(), sweep(dir.path())).unwrap();
    let cases = harness(dir.path(), &|d| experiment(tiny(), sweep(d)).map(|_| ()));
    assert!(cases > 30, "{cases}");
}
