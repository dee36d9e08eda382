//! The `shaping` binary, run as a user runs it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn shaping() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shaping"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tiny() -> PathBuf {
    root().join("tests/cli/tiny.bat")
}

/// A fresh, empty scratch directory for one test, removed when dropped
/// (also when the test fails).
struct Scratch(tempfile::TempDir);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.path().as_os_str()
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        self.0.path()
    }
}

fn scratch(name: &str) -> Scratch {
    Scratch(tempfile::Builder::new().prefix(&format!("shaping-cli-{name}-")).tempdir().unwrap())
}

fn run(cmd: &mut Command) -> Output {
    cmd.output().expect("the binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn run_tiny(out: &Path, extra: &[&str]) -> Output {
    run(shaping().arg("run").arg(tiny()).arg("--out").arg(out).arg("--quiet").args(extra))
}

#[test]
fn check_accepts_every_example() {
    let examples: Vec<PathBuf> = std::fs::read_dir(root().join("examples"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bat"))
        .collect();
    assert!(examples.len() >= 3);
    let out = run(shaping().arg("check").args(&examples));
    assert!(out.status.success(), "{}", text(&out.stderr));
    // The ok lines go to stdout, diagnostics to stderr.
    assert!(text(&out.stdout).contains("khepera.bat: ok"), "{}", text(&out.stdout));
    assert!(!text(&out.stderr).contains(": ok"), "{}", text(&out.stderr));
}

#[test]
fn check_reports_diagnostics_with_exit_1() {
    let dir = scratch("diag");
    let bad = dir.join("bad.bat");
    std::fs::write(
        &bad,
        "robot r { sensor ir[8] proximty }\nstage s { module m { sense ir  behavior forward(1) } }\n",
    )
    .unwrap();
    let out = run(shaping().arg("check").arg(&bad).arg("--error-format").arg("plain"));
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("proximty"), "{err}");
    assert!(err.contains("proximity"), "a did-you-mean help is expected: {err}");

    let json = run(shaping().arg("check").arg(&bad).arg("--error-format").arg("json"));
    assert_eq!(json.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_str(text(&json.stdout).lines().next().unwrap()).unwrap();
    assert!(v.get("message").is_some(), "{v}");
}

#[test]
fn bad_inputs_give_an_error_never_a_panic() {
    let dir = scratch("bad-inputs");
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty.bat", Vec::new()),
        ("garbage.bat", b"\x01\x02 }{ ;; stage stage {{{".to_vec()),
        ("binary.bat", vec![0x66, 0x6f, 0xff, 0xfe, 0x00, 0x80]),
        (
            "nested.bat",
            format!("stage s {{ fitness per action {}1{} }}", "(".repeat(5000), ")".repeat(5000))
                .into_bytes(),
        ),
        ("huge.bat", "module m { sense ir }\n".repeat(20000).into_bytes()),
        ("deeper.bat", "(".repeat(100_000).into_bytes()),
        (
            "megabytes.bat",
            "stage s {\n module m { sense ir behavior forward }\n".repeat(200_000).into_bytes(),
        ),
        // Errors far to the right of a long line (miette cannot pad past 65535 columns).
        ("long_line.bat", format!("{}]", " ".repeat(70_000)).into_bytes()),
        ("long_binary.bat", [" ".repeat(70_000).as_bytes(), b"\xff"].concat()),
    ];
    for (name, bytes) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let out = run(shaping().arg("check").arg(&path));
        assert_eq!(out.status.code(), Some(1), "{name}: {}", text(&out.stderr));
        let err = text(&out.stderr);
        assert!(!err.contains("panicked"), "{name}: {err}");
        assert!(!err.trim().is_empty(), "{name} printed no diagnostic");
    }
    let missing = run(shaping().arg("check").arg(dir.join("nope.bat")));
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing.stderr).contains("nope.bat"));
    let directory = run(shaping().arg("check").arg(&dir));
    assert_eq!(directory.status.code(), Some(2));
    assert!(text(&directory.stderr).contains("cannot read"), "{}", text(&directory.stderr));
}

#[test]
fn layout_shows_frozen_and_evolvable_genes() {
    let out =
        run(shaping().arg("layout").arg(root().join("examples/khepera.bat")).args(["--stage", "collect"]));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let table = text(&out.stdout);
    let nav = table.lines().find(|l| l.contains(" navigation ")).expect("a navigation gene");
    assert!(nav.contains("frozen"), "{nav}");
    let new = table.lines().find(|l| l.contains(" collect ")).expect("a collect gene");
    assert!(new.contains("evolvable"), "{new}");
    assert!(table.contains("frozen:") && table.contains("evolvable:"), "totals missing");

    let bad = run(shaping().arg("layout").arg(root().join("examples/khepera.bat")).args(["--stage", "nope"]));
    assert_eq!(bad.status.code(), Some(2));
    let err = text(&bad.stderr);
    assert!(err.contains("no stage `nope`") && err.contains("navigation"), "{err}");
}

#[test]
fn graph_is_dot() {
    let out = run(shaping().arg("graph").arg(root().join("examples/khepera.bat")));
    assert!(out.status.success());
    let dot = text(&out.stdout);
    assert!(dot.starts_with("digraph") && dot.contains("avoid"), "{dot}");
}

#[test]
fn build_then_run_the_built_program() {
    let dir = scratch("build");
    let program = dir.join("tiny.json");
    let out = run(shaping().arg("build").arg(tiny()).arg("-o").arg(&program));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = run(shaping().arg("run").arg(&program).arg("--out").arg(dir.join("run")).arg("--quiet"));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(dir.join("run/second/best.genome").exists());

    std::fs::write(&program, b"{\"format\": 1, \"name\": 3}").unwrap();
    let out = run(shaping().arg("run").arg(&program).arg("--out").arg(dir.join("run2")));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("tiny.json"));
}

/// A built program edited into nonsense is refused before anything runs,
/// naming the stage and the field; nothing is written.
#[test]
fn an_edited_program_is_refused_naming_the_stage_and_field() {
    let dir = scratch("edited");
    let program = dir.join("tiny.json");
    let out = run(shaping().arg("build").arg(tiny()).arg("-o").arg(&program));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let good: serde_json::Value = serde_json::from_slice(&std::fs::read(&program).unwrap()).unwrap();
    let cases: [(&str, serde_json::Value, &str); 4] = [
        (
            "/stages/0/world/arena",
            serde_json::json!([1e30, -5]),
            "`world.arena[0]`: 1000000000000000000000000000000 mm",
        ),
        ("/stages/0/world/body/radius", serde_json::json!(-3), "`world.body.radius`: -3 mm is not a length"),
        (
            "/stages/0/run/Evolve/population",
            serde_json::json!(4_000_000_000u64),
            "`run.evolve.population`: 4000000000 is not between 1 and 100000",
        ),
        (
            "/stages/0/run/Evolve/mutation",
            serde_json::json!(1.5),
            "`run.evolve.mutation`: 1.5 is not between 0 and 1",
        ),
    ];
    for (pointer, value, message) in cases {
        let mut edited = good.clone();
        *edited.pointer_mut(pointer).unwrap_or_else(|| panic!("{pointer}")) = value;
        std::fs::write(&program, serde_json::to_vec(&edited).unwrap()).unwrap();
        let out_dir = dir.join("run");
        let out = run(shaping().arg("run").arg(&program).arg("--out").arg(&out_dir));
        assert_eq!(out.status.code(), Some(2), "{pointer}: {}", text(&out.stderr));
        let err = text(&out.stderr);
        assert!(err.contains("stage `first`") && err.contains(message), "{pointer}: {err}");
        assert!(!out_dir.exists(), "{pointer}: nothing is written");
    }
}

/// A population too large for the machine is a diagnostic on the number.
#[test]
fn a_population_beyond_the_limit_is_a_diagnostic() {
    let dir = scratch("limit");
    let src = std::fs::read_to_string(tiny()).unwrap();
    let big = dir.join("big.bat");
    let replaced = src.replacen("population 12", "population 4000000000", 1);
    assert_ne!(replaced, src, "tiny.bat sets a population");
    std::fs::write(&big, replaced).unwrap();
    let out = run(shaping().arg("check").arg(&big).arg("--error-format").arg("plain"));
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("`population` must be at most 100000"), "{}", text(&out.stderr));
}

#[test]
fn run_writes_statistics_genomes_and_plots_and_is_deterministic() {
    let a = scratch("det-a");
    let b = scratch("det-b");
    assert!(run_tiny(&a, &["--jobs", "1"]).status.success());
    let out = run(shaping().arg("run").arg(tiny()).arg("--out").arg(&b).args(["--jobs", "2", "--json"]));
    assert!(out.status.success(), "{}", text(&out.stderr));
    // One JSON line per generation: 6 + 4.
    let lines: Vec<serde_json::Value> =
        text(&out.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 10);
    assert_eq!(lines[9]["generation"], 9);
    for stage in ["first", "second"] {
        for f in ["generations.csv", "best.genome", "checkpoint.json", "fitness.svg", "fitness.png"] {
            assert!(a.join(stage).join(f).exists(), "{stage}/{f}");
        }
        let ca = std::fs::read(a.join(stage).join("checkpoint.json")).unwrap();
        let cb = std::fs::read(b.join(stage).join("checkpoint.json")).unwrap();
        assert!(ca == cb, "stage {stage}: 1 and 2 threads differ");
    }
    let csv = std::fs::read_to_string(a.join("second/generations.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 10, "{csv}");
    // The best individual's events close every row, as counts.
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    assert_eq!(header[header.len() - 3..], ["best_recharges", "best_grips", "best_releases_outside"]);
    for line in csv.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len(), "{line}");
        assert!(cells[cells.len() - 3..].iter().all(|c| c.parse::<u32>().is_ok()), "{line}");
    }
}

#[test]
fn killed_run_resumes_to_the_same_result() {
    let straight = scratch("straight");
    assert!(run_tiny(&straight, &[]).status.success());

    let killed = scratch("killed");
    let mut child = shaping()
        .arg("run")
        .arg(tiny())
        .arg("--out")
        .arg(&killed)
        .arg("--quiet")
        .args(["--jobs", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill as soon as the first checkpoint of the first stage exists.
    let start = Instant::now();
    while !killed.join("first/checkpoint.json").exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(2));
    }
    let _ = child.kill();
    let _ = child.wait();
    let out = run_tiny(&killed, &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    for stage in ["first", "second"] {
        let a = std::fs::read(straight.join(stage).join("checkpoint.json")).unwrap();
        let b = std::fs::read(killed.join(stage).join("checkpoint.json")).unwrap();
        assert!(a == b, "stage {stage}: resumed run differs from the straight run");
    }
}

#[test]
fn corrupt_checkpoint_is_reported_and_kept() {
    let dir = scratch("corrupt");
    assert!(run_tiny(&dir, &[]).status.success());
    let ckpt = dir.join("first/checkpoint.json");
    std::fs::write(&ckpt, b"{ not json").unwrap();
    let out = run_tiny(&dir, &[]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("checkpoint.json") && err.contains("corrupt"), "{err}");
    assert_eq!(std::fs::read(&ckpt).unwrap(), b"{ not json", "the checkpoint must be left as it was");
    assert!(run_tiny(&dir, &["--fresh"]).status.success());
}

#[test]
fn resuming_with_changed_earlier_stage_fails_but_appended_stage_runs() {
    let dir = scratch("changed");
    assert!(run_tiny(&dir, &[]).status.success());
    let source = std::fs::read_to_string(tiny()).unwrap();

    let appended = dir.join("appended.bat");
    std::fs::write(
        &appended,
        format!("{source}\nstage third extends second {{\n  evolve {{ generations 2 }}\n  module back {{ sense ir[6..7]  behavior back(0.5) }}\n  links all evolvable\n}}\n"),
    )
    .unwrap();
    let out = run(shaping().arg("run").arg(&appended).arg("--out").arg(&dir).arg("--quiet"));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(dir.join("third/best.genome").exists());

    let changed = dir.join("changed.bat");
    std::fs::write(&changed, source.replace("module wander { sense ir ", "module wander { sense ir[0..5] "))
        .unwrap();
    let out = run(shaping().arg("run").arg(&changed).arg("--out").arg(&dir).arg("--quiet"));
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("first") && err.contains("--fresh"), "{err}");
}

#[test]
fn run_rejects_unknown_stage_and_replay_writes_pictures() {
    let dir = scratch("replay");
    let out = run(shaping().arg("run").arg(tiny()).args(["--stage", "fifth"]).arg("--out").arg(&dir));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("no stage `fifth`"));

    let missing = run(shaping().arg("replay").arg(tiny()).arg("--run").arg(&dir));
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing.stderr).contains("shaping run"), "{}", text(&missing.stderr));

    assert!(run_tiny(&dir, &[]).status.success());
    let pics = dir.join("pics");
    let out = run(shaping()
        .arg("replay")
        .arg(tiny())
        .args(["--stage", "second", "--actions", "80"])
        .arg("--run")
        .arg(&dir)
        .arg("--out")
        .arg(&pics));
    assert!(out.status.success(), "{}", text(&out.stderr));
    for f in ["trace.csv", "activations.png", "activations.svg", "trajectory.png", "trajectory.svg"] {
        assert!(pics.join(f).exists(), "{f}");
    }
    let trace = std::fs::read_to_string(pics.join("trace.csv")).unwrap();
    assert!(trace.lines().count() > 1 && trace.lines().count() <= 81);

    let short = run(shaping().arg("replay").arg(tiny()).args(["--stage", "second", "--genome", "0101"]));
    assert_eq!(short.status.code(), Some(2));
    assert!(text(&short.stderr).contains("bits"));
}

#[test]
fn bench_prints_one_json_line() {
    let out = run(shaping().arg("bench").arg(tiny()).args(["--runs", "1"]));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
    assert!(v["sim_steps_per_sec"].as_f64().unwrap() > 0.0);
    assert!(v["controller_actions_per_sec"].as_f64().unwrap() > 0.0);
}

/// A stage with nothing evolved replays without a genome, and its avoid
/// module's performance indicator is high by action 300 (figure 5 from the
/// command line).
#[test]
fn replay_of_a_stage_without_genes_needs_no_genome() {
    let dir = scratch("avoid");
    let out = run(shaping().arg("replay").arg(root().join("examples/avoid.bat")).arg("--out").arg(&dir));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("avoid: 1000 actions"), "{}", text(&out.stdout));
    assert!(dir.join("reinforcement.png").exists());
    let trace = std::fs::read_to_string(dir.join("trace.csv")).unwrap();
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
    let _ = std::fs::remove_dir_all(&dir);
}

/// `run` trains a training stage as a step of its own (its directory, its
/// weights, its pictures), reuses the weights when run again, and `layout`
/// shows the trained weights of the stage that uses them as parameters, not
/// genes.
#[test]
fn training_stage_runs_as_a_step_and_its_weights_reach_the_next_stage() {
    let dir = scratch("pretrained");
    let file = root().join("examples/pretrained.bat");
    let first = run(shaping().arg("run").arg(&file).args(["--stage", "avoidance", "--out"]).arg(&dir));
    assert!(first.status.success(), "{}", text(&first.stderr));
    assert!(text(&first.stderr).contains("trained for 1000 actions"), "{}", text(&first.stderr));
    let trained = std::fs::read_to_string(dir.join("avoidance/trained.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&trained).unwrap();
    assert_eq!(v["weights"][1].as_array().map(|w| w.len()), Some(18), "the avoid module's 18 weights");
    assert!(dir.join("avoidance/reinforcement.png").exists());
    let again = run(shaping().arg("run").arg(&file).args(["--stage", "avoidance", "--out"]).arg(&dir));
    assert!(text(&again.stderr).contains("trained before, reused"), "{}", text(&again.stderr));
    assert_eq!(std::fs::read_to_string(dir.join("avoidance/trained.json")).unwrap(), trained);
    let layout = run(shaping().arg("layout").arg(&file).args(["--stage", "navigation"]));
    assert!(
        text(&layout.stdout).contains("trained: `avoid` behavior, 18 weights, learned by stage `avoidance`"),
        "{}",
        text(&layout.stdout)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn report_bat() -> PathBuf {
    root().join("tests/cli/report.bat")
}

/// The data a report embeds.
fn report_data(path: &Path) -> serde_json::Value {
    let html = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let open = "<script type=\"application/json\" id=\"data\">";
    let start = html.find(open).expect("the report embeds its data") + open.len();
    let len = html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..start + len]).unwrap()
}

#[test]
fn run_writes_a_report_of_every_stage_and_report_reads_any_directory() {
    let dir = scratch("report-run");
    let out = run(shaping().arg("run").arg(report_bat()).arg("--out").arg(&dir));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let err = text(&out.stderr);
    let page = dir.join("report.html");
    assert!(err.contains(&format!("report: {}", page.display())), "{err}");
    assert!(dir.join("program.json").exists());
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
    let trace = std::fs::read_to_string(dir.join("bigger/trace.csv")).unwrap();
    assert_eq!(bigger["actions"]["x"].as_array().unwrap().len(), trace.lines().count() - 1);
    // Fitness: one series per evolved stage, as long as its generations.
    let fit = data["fitness"].as_array().unwrap();
    assert_eq!(fit.len(), 2);
    assert_eq!(fit[0]["best"].as_array().unwrap().len(), 4);
    assert_eq!(fit[1]["generation"][0], 4, "generations continue across stages");

    // The evolved stage's episode is the one `replay` shows by default.
    let rep = dir.join("rep");
    let out = run(shaping()
        .arg("replay")
        .arg(report_bat())
        .args(["--stage", "collect", "--report"])
        .arg("--run")
        .arg(&dir)
        .arg("--out")
        .arg(&rep));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("report: "), "{}", text(&out.stdout));
    let replay = report_data(&rep.join("report.html"));
    assert_eq!(replay["kind"], "replay");
    assert_eq!(replay["episodes"][0]["actions"], eps[1]["actions"]);

    // A stage directory, and another output file.
    let other = dir.join("collect.html");
    let out = run(shaping().arg("report").arg(dir.join("collect")).arg("-o").arg(&other));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stage = report_data(&other);
    assert_eq!(stage["kind"], "stage");
    assert_eq!(stage["episodes"].as_array().unwrap().len(), 1);

    // Not a run: a clear error, exit 2.
    let out = run(shaping().arg("report").arg(dir.join("navigation").join("nothing")));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("is not a directory"), "{}", text(&out.stderr));
    let empty = scratch("report-empty");
    let out = run(shaping().arg("report").arg(&*empty));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("no `program.json`"), "{}", text(&out.stderr));
    // A damaged episode is named.
    std::fs::write(dir.join("collect/episode.json"), "{}").unwrap();
    let out = run(shaping().arg("report").arg(&dir));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("collect/episode.json"), "{}", text(&out.stderr));

    let quiet = scratch("report-none");
    assert!(run(shaping().arg("run").arg(tiny()).arg("--out").arg(&quiet).args(["--quiet", "--no-report"]))
        .status
        .success());
    assert!(!quiet.join("report.html").exists());
}

#[test]
fn experiment_report_has_the_median_over_seeds() {
    let dir = scratch("report-exp");
    let out = run(shaping().arg("experiment").arg(tiny()).args(["--seeds", "3"]).arg("--out").arg(&dir));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(!dir.join("seed-1/report.html").exists(), "one report for the experiment, none per seed");
    let data = report_data(&dir.join("report.html"));
    assert_eq!(data["kind"], "experiment");
    assert_eq!(data["seeds"], serde_json::json!([1, 2, 3]));
    let first = &data["fitness"][0];
    assert_eq!(first["seeds"][0], 3);
    // The median of the three seeds' best of the first generation.
    let mut bests: Vec<f64> = (1..=3)
        .map(|s| {
            let csv = std::fs::read_to_string(dir.join(format!("seed-{s}/first/generations.csv"))).unwrap();
            csv.lines().nth(1).unwrap().split(',').nth(3).unwrap().parse().unwrap()
        })
        .collect();
    bests.sort_by(f64::total_cmp);
    assert!((first["best"][0].as_f64().unwrap() - bests[1]).abs() < 1e-6, "{first} vs {bests:?}");
    assert!((first["best_min"][0].as_f64().unwrap() - bests[0]).abs() < 1e-6);
    assert!((first["best_max"][0].as_f64().unwrap() - bests[2]).abs() < 1e-6);
}

/// Without the `mpi` feature, `run` under an MPI launcher would be N copies
/// writing the same files: it refuses; one process is fine.
#[cfg(not(feature = "mpi"))]
#[test]
fn run_under_an_mpi_launcher_without_mpi_support_refuses() {
    let dir = scratch("no-mpi");
    for var in ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"] {
        let out = run(shaping().arg("run").arg(tiny()).arg("--out").arg(dir.join("x")).env(var, "4"));
        assert_eq!(out.status.code(), Some(2));
        let err = text(&out.stderr);
        assert!(err.contains("built without MPI support") && err.contains(var), "{err}");
        assert!(err.contains("--features mpi"), "{err}");
        assert!(!dir.join("x").exists(), "it wrote files before refusing");
    }
    let out = run(shaping().args(["experiment", "--seeds", "1"]).arg(tiny()).env("PMIX_RANK", "0"));
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    let out = run_tiny(&dir.join("one"), &[]);
    assert!(out.status.success());
    let out = run(shaping()
        .arg("run")
        .arg(tiny())
        .arg("--out")
        .arg(dir.join("y"))
        .arg("--quiet")
        .env("OMPI_COMM_WORLD_SIZE", "1"));
    assert!(out.status.success(), "{}", text(&out.stderr));
}
