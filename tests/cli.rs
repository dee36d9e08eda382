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
fn check_prints_warnings_and_exits_0() {
    let dir = scratch("warn");
    let file = dir.join("typo.bat");
    std::fs::write(
        &file,
        "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n\
         stage s { fitness per action wheels[0]  module wander { sense ir  behavior forward } }\n\
         stage t extends s { module wandr { sense ir  behavior back } }\n",
    )
    .unwrap();
    let out = run(shaping().arg("check").arg(&file).arg("--error-format").arg("plain"));
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let err = text(&out.stderr);
    assert!(err.contains("new module `wandr` is one edit away from inherited module `wander`"), "{err}");
    assert!(text(&out.stdout).contains("typo.bat: ok"), "{}", text(&out.stdout));

    let json = run(shaping().arg("check").arg(&file).arg("--error-format").arg("json"));
    assert_eq!(json.status.code(), Some(0));
    let first = text(&json.stdout).lines().next().unwrap_or_default().to_string();
    // One object per file: the good file's, its warnings inside.
    let v: serde_json::Value = serde_json::from_str(&first).unwrap();
    assert_eq!(text(&json.stdout).lines().count(), 1, "{}", text(&json.stdout));
    assert_eq!(v["ok"], true, "{v}");
    assert_eq!(v["warnings"]["related"][0]["severity"], "warning", "{v}");
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
    // One JSON line per generation: 6 + 4, then the end of the run.
    let lines: Vec<serde_json::Value> =
        text(&out.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 11);
    assert_eq!(lines[10]["done"], true);
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
    let out = replay_run(&tiny(), &dir, &pics, &["--stage", "second", "--actions", "80"]);
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

/// `replay --gif` writes the episode as an animated GIF: the collect stage
/// of `khepera.bat` as run, more than 10 frames, at most 300; `--mp4`
/// without `ffmpeg` on the PATH is refused naming it, before anything runs.
#[test]
fn replay_writes_an_animated_gif_and_mp4_needs_ffmpeg() {
    let dir = scratch("replay-gif");
    let khepera = root().join("examples/khepera.bat");
    let out = run(shaping().arg("run").arg(&khepera).args(["--quiet", "--no-report", "--out"]).arg(&dir));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let gif_path = dir.join("out.gif");
    let out = run(shaping()
        .arg("replay")
        .arg(&khepera)
        .args(["--stage", "collect", "--run"])
        .arg(&dir)
        .arg("--gif")
        .arg(&gif_path));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("animation: "), "{}", text(&out.stdout));
    let bytes = std::fs::read(&gif_path).unwrap();
    assert_eq!(&bytes[..6], b"GIF89a");
    let mut decoder = gif::DecodeOptions::new().read_info(bytes.as_slice()).unwrap();
    let (w, h) = (decoder.width(), decoder.height());
    let mut frames = 0;
    while let Some(f) = decoder.read_next_frame().unwrap() {
        assert!(f.left + f.width <= w && f.top + f.height <= h);
        frames += 1;
    }
    assert!((11..=300).contains(&frames), "{frames} frames");

    let empty = dir.join("no-programs");
    std::fs::create_dir_all(&empty).unwrap();
    let mp4 = dir.join("out.mp4");
    let out = run(shaping()
        .env("PATH", &empty)
        .arg("replay")
        .arg(&khepera)
        .args(["--stage", "collect", "--run"])
        .arg(&dir)
        .arg("--out")
        .arg(dir.join("never"))
        .arg("--mp4")
        .arg(&mp4));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("`ffmpeg`"), "{}", text(&out.stderr));
    assert!(!mp4.exists() && !dir.join("never").exists());
}

#[test]
fn bench_prints_one_json_line() {
    let out = run(shaping().arg("bench").arg(tiny()).args(["--runs", "1"]));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
    assert!(v["sim_steps_per_sec"].as_f64().unwrap() > 0.0);
    assert!(v["controller_actions_per_sec"].as_f64().unwrap() > 0.0);
    assert!(v["controller_episodes_per_sec"].as_f64().unwrap() > 0.0);
    // The timed robot moves: not pinned against a wall, not out of battery.
    assert!(v["sim_moving_share"].as_f64().unwrap() >= 0.9, "{v}");
    assert!(v["sim_collision_share"].as_f64().unwrap() < 0.1, "{v}");
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
    let out = replay_run(&report_bat(), &dir, &rep, &["--stage", "collect", "--report"]);
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

// ------------------------------------------------------------ trust (issue 19)

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

fn run_file(file: &Path, out: &Path, extra: &[&str]) -> Output {
    run(shaping().arg("run").arg(file).arg("--out").arg(out).arg("--no-report").args(extra))
}

/// `shaping replay FILE EXTRA --run RUN --out OUT`.
fn replay_run(file: &Path, run_dir: &Path, out: &Path, extra: &[&str]) -> Output {
    run(shaping().arg("replay").arg(file).args(extra).arg("--run").arg(run_dir).arg("--out").arg(out))
}

/// Editing anything a checkpoint depends on makes the run refuse it, saying
/// what changed; `--fresh` starts again and shows the new result. Fewer
/// generations than the checkpoint holds are refused naming both numbers;
/// more continue it to the result of a straight run, saying so.
#[test]
fn an_edited_file_is_not_resumed_from_its_old_checkpoint() {
    let dir = scratch("edited");
    let file = dir.join("s.bat");
    let out = dir.join("out");
    std::fs::write(&file, EDITED).unwrap();
    let first = run_file(&file, &out, &[]);
    assert!(first.status.success(), "{}", text(&first.stderr));
    let again = run_file(&file, &out, &[]);
    assert!(text(&again.stderr).contains("all 5 generations done before"), "{}", text(&again.stderr));

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
        std::fs::write(&file, &edit).unwrap();
        let stale = run_file(&file, &out, &[]);
        assert_eq!(stale.status.code(), Some(2));
        let err = text(&stale.stderr);
        assert!(err.contains("cannot resume from") && err.contains("checkpoint.json"), "{err}");
        assert!(err.contains(what) && err.contains("`--fresh`") && err.contains("`--out`"), "{err}");
    }
    // Nor does `replay` take the run's best for the edited stage.
    let replay = replay_run(&file, &out, &dir.join("r"), &[]);
    assert_eq!(replay.status.code(), Some(2));
    let err = text(&replay.stderr);
    assert!(err.contains("is not of this program") && err.contains("the world of `s` changed"), "{err}");
    // The last edit, started again: the fitness is that of the edited file.
    std::fs::write(&file, EDITED.replace("per action wheels[0]", "per action wheels[0] * 0.5 + 7")).unwrap();
    let fresh = run_file(&file, &out, &["--fresh", "--json"]);
    assert!(fresh.status.success(), "{}", text(&fresh.stderr));
    let last: serde_json::Value = serde_json::from_str(text(&fresh.stdout).lines().last().unwrap()).unwrap();
    let best = last["stages"][0]["best"].as_f64().unwrap();
    assert!(best > 700.0, "100 actions of at least 7: {best}");

    std::fs::write(&file, EDITED.replace("generations 5", "generations 4")).unwrap();
    let fewer = run_file(&file, &dir.join("fewer"), &[]);
    assert!(fewer.status.success());
    std::fs::write(&file, EDITED.replace("generations 5", "generations 3")).unwrap();
    let cut = run_file(&file, &dir.join("fewer"), &[]);
    assert_eq!(cut.status.code(), Some(2));
    let err = text(&cut.stderr);
    assert!(err.contains("holds 4 generations of stage `s`, which now declares 3"), "{err}");

    std::fs::write(&file, EDITED.replace("generations 5", "generations 7")).unwrap();
    let more = run_file(&file, &dir.join("fewer"), &[]);
    assert!(text(&more.stderr).contains("resuming `s` at generation 4 of 7"), "{}", text(&more.stderr));
    assert!(run_file(&file, &dir.join("straight"), &[]).status.success());
    let ckpt = |d: &str| std::fs::read(dir.join(d).join("s/checkpoint.json")).unwrap();
    assert!(ckpt("fewer") == ckpt("straight"), "the extended run differs from the straight run");
}

/// `trained.json` is tied to its training stage the same way.
#[test]
fn stale_trained_weights_are_refused() {
    let dir = scratch("stale-trained");
    let source = std::fs::read_to_string(root().join("examples/pretrained.bat")).unwrap();
    let file = dir.join("p.bat");
    std::fs::write(&file, &source).unwrap();
    let first = run_file(&file, &dir.join("out"), &["--stage", "avoidance"]);
    assert!(first.status.success(), "{}", text(&first.stderr));
    std::fs::write(&file, source.replace("train for 1000 actions", "train for 900 actions")).unwrap();
    let stale = run_file(&file, &dir.join("out"), &["--stage", "avoidance"]);
    assert_eq!(stale.status.code(), Some(2));
    let err = text(&stale.stderr);
    assert!(err.contains("trained.json") && err.contains("the settings of `avoidance` changed"), "{err}");
}

/// An activation network learned in a training stage reaches the stage that
/// uses it (`activation trained STAGE`): `trained.json` holds it, `layout`
/// lists it, and a `trained.json` written before activation weights were
/// saved is refused by `run`, saying so, and retrained by `replay`.
#[test]
fn trained_activation_weights_reach_the_next_stage() {
    let dir = scratch("trained-activation");
    let file = dir.join("dodge.bat");
    std::fs::write(
        &file,
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
    )
    .unwrap();
    let out = dir.join("out");
    let first = run_file(&file, &out, &[]);
    assert!(first.status.success(), "{}", text(&first.stderr));
    let path = out.join("practice/trained.json");
    let saved: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(saved["activation"][1].as_array().map(|w| w.len()), Some(21), "dodge: 2 x (8 + 1) + 3");
    let layout = run(shaping().arg("layout").arg(&file).args(["--stage", "evolved"]));
    let table = text(&layout.stdout);
    assert!(
        table.contains("trained: `dodge` activation network, 21 weights, learned by stage `practice`"),
        "{table}"
    );
    assert!(!table.contains("dodge   weight"), "trained weights are not genes: {table}");
    // As written before activation weights were saved.
    let mut old = saved.clone();
    old.as_object_mut().unwrap().remove("activation");
    std::fs::write(&path, serde_json::to_string(&old).unwrap()).unwrap();
    let refused = run_file(&file, &out, &["--stage", "evolved"]);
    assert_eq!(refused.status.code(), Some(2), "{}", text(&refused.stderr));
    let err = text(&refused.stderr);
    assert!(err.contains("trained.json") && err.contains("no activation weights"), "{err}");
    let replay = replay_run(&file, &out, &dir.join("replay"), &["--stage", "evolved"]);
    assert!(replay.status.success(), "{}", text(&replay.stderr));
    assert!(
        text(&replay.stderr).contains("no activation weights")
            && text(&replay.stderr).contains("training the stage again"),
        "{}",
        text(&replay.stderr)
    );
}

/// Starts `shaping run FILE --out OUT ARGS` (standard error piped) and
/// waits, 120 s at most, until `ready` exists.
#[cfg(unix)]
fn start_run_until(file: &Path, out: &Path, args: &[&str], ready: &Path) -> std::process::Child {
    let child = shaping()
        .arg("run")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !ready.exists() {
        assert!(start.elapsed() < Duration::from_secs(120), "`{}` was not written", ready.display());
        std::thread::sleep(Duration::from_millis(10));
    }
    child
}

/// Ctrl-C (SIGINT) to `child`.
#[cfg(unix)]
fn ctrl_c(child: &std::process::Child) {
    let kill = run(Command::new("kill").args(["-INT", &child.id().to_string()]));
    assert!(kill.status.success());
}

/// Ctrl-C lets the generation under way finish and be saved, and says where
/// the run stopped; the same command resumes it, saying so.
#[cfg(unix)]
#[test]
fn ctrl_c_says_where_the_run_stopped_and_it_resumes() {
    let dir = scratch("ctrl-c");
    let file = dir.join("s.bat");
    std::fs::write(&file, EDITED.replace("generations 5", "generations 1000")).unwrap();
    let out = dir.join("out");
    let child = start_run_until(&file, &out, &["--no-report", "--jobs", "1"], &out.join("s/checkpoint.json"));
    ctrl_c(&child);
    let done = child.wait_with_output().unwrap();
    assert_eq!(done.status.code(), Some(2));
    let err = text(&done.stderr);
    let at = err.find("interrupted: stage `s` stopped after generation ").unwrap_or_else(|| panic!("{err}"));
    let generation: u32 =
        err[at..].split("generation ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!(err.contains("of 1000, saved in") && err.contains("the same command resumes it"), "{err}");
    std::fs::write(&file, EDITED.replace("generations 5", &format!("generations {}", generation + 1)))
        .unwrap();
    let resumed = run_file(&file, &out, &[]);
    assert!(resumed.status.success(), "{}", text(&resumed.stderr));
    assert!(
        text(&resumed.stderr).contains(&format!("resuming `s` at generation {generation}")),
        "{}",
        text(&resumed.stderr)
    );
}

/// A checkpoint with a bit that is not 0 or 1 is refused naming the file and
/// the place; so is a genome argument or file that is not a bit string.
#[test]
fn bad_bits_and_genomes_are_refused_naming_where() {
    let dir = scratch("bits");
    assert!(run_tiny(&dir, &[]).status.success());
    let path = dir.join("first/checkpoint.json");
    let mut cp: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    cp["population"][3]["bits"][5] = serde_json::json!(2);
    std::fs::write(&path, serde_json::to_vec(&cp).unwrap()).unwrap();
    let out = run_tiny(&dir, &[]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("first/checkpoint.json") && err.contains("bit 5 of individual 3 is 2"), "{err}");

    let replay = |genome: &str| {
        run(shaping().arg("replay").arg(tiny()).args(["--stage", "first", "--genome", genome]))
    };
    let out = replay("2101");
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("`--genome 2101` is not a genome: character 1 is `2`"), "{err}");
    assert!(!err.contains("cannot read"), "not read as a file: {err}");
    let file = dir.join("g.genome");
    std::fs::write(&file, "0101\n0171\n").unwrap();
    let out = replay(file.to_str().unwrap());
    let err = text(&out.stderr);
    assert!(err.contains("g.genome` does not hold a genome: line 2, column 3 is `7`"), "{err}");
    let out = replay("no-such-file");
    let err = text(&out.stderr);
    assert!(err.contains("`--genome no-such-file` is neither a string of 0 and 1"), "{err}");
}

/// Replaying a training stage of a run replays its training life.
#[test]
fn replay_of_a_training_stage_replays_its_life() {
    let dir = scratch("replay-training");
    let file = root().join("examples/pretrained.bat");
    let out = dir.join("out");
    let first = run_file(&file, &out, &["--stage", "avoidance", "--seed", "5"]);
    assert!(first.status.success(), "{}", text(&first.stderr));
    let life = replay_run(&file, &out, &dir.join("life"), &["--stage", "avoidance"]);
    assert!(life.status.success(), "{}", text(&life.stderr));
    let trained: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("avoidance/trained.json")).unwrap()).unwrap();
    let r = &trained["result"];
    let said = text(&life.stdout);
    let expected = format!(
        "avoidance: {} actions, fitness {:.3}, {} grips, {} released outside, {} recharges, {} collisions",
        r["actions"],
        r["fitness"].as_f64().unwrap(),
        r["grips"],
        r["releases_outside"],
        r["recharges"],
        r["collisions"]
    );
    assert!(said.starts_with(&expected), "{said} is not the training life: {expected}");
    let trace = std::fs::read_to_string(dir.join("life/trace.csv")).unwrap();
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "perf_avoid").unwrap();
    let last: f64 = trace.lines().last().unwrap().split(',').nth(col).unwrap().parse().unwrap();
    let learned = trained["performance"][1].as_f64().unwrap();
    assert!((last - learned).abs() < 1e-3, "performance {last} at the end of the replay, {learned} trained");
}

/// Every command that runs a stage binds the trained weights the same way:
/// `replay` of every stage of every example (the training stages trained
/// on the fly, no run directory needed).
#[test]
fn replay_runs_every_stage_of_every_example() {
    let dir = scratch("every-stage");
    for example in std::fs::read_dir(root().join("examples")).unwrap() {
        let file = example.unwrap().path();
        if file.extension().is_none_or(|e| e != "bat") {
            continue;
        }
        for (stage, bits) in stages_of(&file, &dir.join("program.json")) {
            // In an empty directory: no `runs/` of an earlier run is used.
            let out = run(shaping()
                .current_dir(&dir)
                .arg("replay")
                .arg(&file)
                .args(["--stage", &stage, "--actions", "5", "--genome", &"0".repeat(bits)])
                .arg("--out")
                .arg(dir.join("r")));
            assert!(out.status.success(), "{} {stage}: {}", file.display(), text(&out.stderr));
        }
    }
}

/// The stages of a file and their genome lengths.
fn stages_of(file: &Path, built: &Path) -> Vec<(String, usize)> {
    let out = run(shaping().arg("build").arg(file).arg("-o").arg(built));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let program: serde_json::Value = serde_json::from_slice(&std::fs::read(built).unwrap()).unwrap();
    program["stages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| (s["name"].as_str().unwrap().to_string(), s["layout"]["bits"].as_u64().unwrap() as usize))
        .collect()
}

/// `check --error-format json` prints one object per file, good files
/// included; `run --json` ends with the chosen best of every stage, also
/// for a run that had nothing left to do.
#[test]
fn machine_readable_output_covers_every_file_and_the_end_of_a_run() {
    let dir = scratch("json");
    let bad = dir.join("bad.bat");
    std::fs::write(
        &bad,
        "robot r { sensor ir[8] proximty }\nstage s { module m { sense ir  behavior forward(1) } }\n",
    )
    .unwrap();
    let out = run(shaping()
        .args(["check", "--error-format", "json"])
        .arg(tiny())
        .arg(&bad)
        .arg(dir.join("none.bat")));
    assert_eq!(out.status.code(), Some(2));
    let lines: Vec<serde_json::Value> =
        text(&out.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 3, "{}", text(&out.stdout));
    assert_eq!(lines[0]["ok"], true);
    assert_eq!(lines[0]["stages"][1]["name"], "second");
    assert!(lines[0]["file"].as_str().unwrap().ends_with("tiny.bat"));
    assert_eq!(lines[1]["ok"], false);
    assert!(lines[1]["related"][0]["message"].as_str().unwrap().contains("proximty"), "{}", lines[1]);
    assert_eq!(lines[2]["ok"], false);
    assert!(lines[2]["message"].as_str().unwrap().contains("cannot read"), "{}", lines[2]);

    for pass in 0..2 {
        let out = run_tiny(&dir.join("run"), &["--json", "--no-report"]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let last: serde_json::Value =
            serde_json::from_str(text(&out.stdout).lines().last().unwrap()).unwrap();
        assert_eq!(last["done"], true, "pass {pass}: {last}");
        let stages = last["stages"].as_array().unwrap();
        assert_eq!(stages.len(), 2);
        let best = std::fs::read_to_string(dir.join("run/second/best.genome")).unwrap();
        assert_eq!(stages[1]["genome"].as_str().unwrap(), best.trim());
        assert!(stages[1]["best"].as_f64().is_some());
    }
}

/// `trace.csv` has a column per declared sensor and actuator element, named
/// after the declaration, and `episode.json` the ambient light readings.
#[test]
fn the_trace_has_what_the_robot_sensed_and_did() {
    let dir = scratch("trace-columns");
    let out = run(shaping()
        .arg("replay")
        .arg(tiny())
        .args(["--stage", "first", "--actions", "30", "--genome", &"0".repeat(84), "--out"])
        .arg(&dir));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let trace = std::fs::read_to_string(dir.join("trace.csv")).unwrap();
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> =
        trace.lines().skip(1).map(|l| l.split(',').skip(2).map(|v| v.parse().unwrap()).collect()).collect();
    let col =
        |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no `{name}`")) - 2;
    let episode: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("episode.json")).unwrap()).unwrap();
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

/// Every regular file under `dir`, relative to it, sorted, with its bytes
/// (`report.html` and pictures aside: they are not the run's results).
fn result_files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
            if p.is_dir() {
                stack.push(p);
            } else if ["csv", "json", "genome", "md"].contains(&ext) {
                out.push((p.strip_prefix(dir).unwrap().to_path_buf(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// `shaping experiment tiny.bat ARGS... --out OUT`.
fn experiment_tiny(out: &Path, args: &[&str]) -> Output {
    run(shaping().arg("experiment").arg(tiny()).args(args).arg("--out").arg(out))
}

fn sweep(out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["--seeds", "2", "--no-report", "--set", "first.evolve.mutation=0.01,0.2"];
    args.extend(["--set", "first.world.battery=100,300"]);
    args.extend(extra);
    experiment_tiny(out, &args)
}

/// A sweep runs every point of the cartesian product over every seed, each
/// point's seed writing what `shaping run` with the same `--set` writes, and
/// tables every point in `summary.md` and `summary.json`.
#[test]
fn a_sweep_point_is_the_run_with_its_settings() {
    let dir = scratch("sweep");
    let out = sweep(&dir.join("sweep"), &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let point = "first.evolve.mutation=0.2,first.world.battery=100";
    let alone = dir.join("alone");
    let single = run_tiny(
        &alone,
        &[
            "--seed",
            "2",
            "--no-report",
            "--set",
            "first.evolve.mutation=0.2",
            "--set",
            "first.world.battery=100",
        ],
    );
    assert!(single.status.success(), "{}", text(&single.stderr));
    let in_sweep = result_files(&dir.join("sweep").join(point).join("seed-2"));
    assert!(in_sweep.len() >= 6, "{in_sweep:?}");
    let names = |v: &[(PathBuf, Vec<u8>)]| v.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
    assert_eq!(names(&in_sweep), names(&result_files(&alone)));
    assert!(in_sweep == result_files(&alone), "the sweep's point differs from the run with its settings");
    // The settings reach the program: both stages (the second inherits the mutation).
    let program: serde_json::Value =
        serde_json::from_slice(&std::fs::read(alone.join("program.json")).unwrap()).unwrap();
    for stage in 0..2 {
        let s = &program["stages"][stage];
        assert!((s["run"]["Evolve"]["mutation"].as_f64().unwrap() - 0.2).abs() < 1e-6, "{}", s["name"]);
        assert_eq!(s["world"]["battery"]["capacity"], 100);
    }
    // And they change the results: another mutation rate evolves otherwise.
    let other =
        dir.join("sweep/first.evolve.mutation=0.01,first.world.battery=100/seed-2/first/generations.csv");
    let this = dir.join("sweep").join(point).join("seed-2/first/generations.csv");
    assert_ne!(std::fs::read(other).unwrap(), std::fs::read(this).unwrap());

    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("sweep/summary.json")).unwrap()).unwrap();
    let points = summary["points"].as_array().unwrap();
    assert_eq!(points.len(), 4);
    assert_eq!(points[2]["name"], point);
    assert_eq!(points[2]["settings"]["first.world.battery"], "100");
    let first = &points[2]["stages"][0];
    assert_eq!(first["stage"], "first");
    // The chosen best of each seed is the one in its checkpoint.
    let chosen: Vec<f64> = (1..=2)
        .map(|s| {
            let cp: serde_json::Value = serde_json::from_slice(
                &std::fs::read(dir.join("sweep").join(point).join(format!("seed-{s}/first/checkpoint.json")))
                    .unwrap(),
            )
            .unwrap();
            cp["best"][1].as_f64().unwrap()
        })
        .collect();
    let (lo, hi) = (chosen[0].min(chosen[1]), chosen[0].max(chosen[1]));
    assert!((first["chosen_best"]["min"].as_f64().unwrap() - lo).abs() < 1e-6, "{first}");
    assert!((first["chosen_best"]["max"].as_f64().unwrap() - hi).abs() < 1e-6, "{first}");
    assert!((first["chosen_best"]["median"].as_f64().unwrap() - (lo + hi) / 2.0).abs() < 1e-6, "{first}");
    let md = std::fs::read_to_string(dir.join("sweep/summary.md")).unwrap();
    let head =
        "| point | `first.evolve.mutation` | `first.world.battery` | first final best | first chosen best |";
    assert!(md.contains(head), "{md}");
    assert!(md.contains("| 3 | 0.2 | 100 | "), "{md}");
    assert_eq!(md.lines().filter(|l| l.starts_with("| ") && l.contains(" | 0.")).count(), 4, "{md}");
    assert!(dir.join("sweep/sweep.svg").exists() && dir.join("sweep/sweep.png").exists());
    assert!(dir.join("sweep").join(point).join("summary.md").exists(), "no summary of the point");
}

/// A value set on a stage goes to the stages extending it that had the same
/// value (inherited), not to one that sets its own.
#[test]
fn a_set_value_is_inherited_like_a_written_one() {
    let dir = scratch("inherit");
    let out = run_tiny(&dir, &["--no-report", "--set", "first.evolve.generations=3"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let program: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("program.json")).unwrap()).unwrap();
    assert_eq!(program["stages"][0]["run"]["Evolve"]["generations"], 3);
    assert_eq!(program["stages"][1]["run"]["Evolve"]["generations"], 4, "`second` sets its own");
    let csv = std::fs::read_to_string(dir.join("first/generations.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "a header and 3 generations:\n{csv}");
}

#[test]
fn bad_set_values_are_errors_naming_them() {
    let dir = scratch("bad-set");
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
        let out = experiment_tiny(&dir.join("x"), &["--seeds", "1", "--set", set]);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--set {set}: {err}");
        for w in wanted {
            assert!(err.contains(w), "--set {set}: `{w}` missing from:\n{err}");
        }
        assert!(!dir.join("x").exists(), "--set {set}: files written before the error");
    }
    let out =
        run(shaping().arg("experiment").arg(tiny()).args(["--stage", "first", "--criterion", "second=0.5"]));
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("stage `second` is not run with `--stage first`"),
        "{}",
        text(&out.stderr)
    );
    let out = run_tiny(&dir.join("y"), &["--set", "first.evolve.mutation=0.1,0.2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("`run` takes one value"), "{}", text(&out.stderr));
    let out = run(shaping().arg("experiment").arg(tiny()).args([
        "--set",
        "first.evolve.seed=1",
        "--set",
        "first.evolve.seed=2",
    ]));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("given twice"), "{}", text(&out.stderr));
}

/// A sweep killed with SIGKILL and started again ends with the files of
/// one that was never interrupted.
#[test]
fn a_killed_sweep_resumes_to_the_same_result() {
    let dir = scratch("sweep-kill");
    let straight = dir.join("straight");
    assert!(sweep(&straight, &["--jobs", "1"]).status.success());
    let killed = dir.join("killed");
    let mut child = shaping()
        .arg("experiment")
        .arg(tiny())
        .args(["--seeds", "2", "--no-report", "--set", "first.evolve.mutation=0.01,0.2"])
        .args(["--set", "first.world.battery=100,300", "--jobs", "1"])
        .arg("--out")
        .arg(&killed)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill in the middle of the second point.
    let mid = killed.join("first.evolve.mutation=0.01,first.world.battery=300/seed-1/first/checkpoint.json");
    let start = Instant::now();
    while !mid.exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(2));
    }
    let _ = child.kill();
    let _ = child.wait();
    assert!(!killed.join("summary.json").exists(), "the sweep ended before it was killed");
    let out = sweep(&killed, &["--jobs", "1"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (a, b) = (result_files(&straight), result_files(&killed));
    assert_eq!(a.len(), b.len());
    for ((pa, xa), (pb, xb)) in a.iter().zip(&b) {
        assert_eq!(pa, pb);
        assert!(xa == xb, "{} differs after resuming", pa.display());
    }
}

/// The report of a sweep shows its best point and lists every point; a
/// point's report lists them too, its own highlighted.
#[test]
fn the_report_of_a_sweep_lists_its_points() {
    let dir = scratch("sweep-report");
    let out = experiment_tiny(&dir, &["--seeds", "2", "--set", "first.evolve.mutation=0.01,0.2"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let root = report_data(&dir.join("report.html"));
    assert_eq!(root["kind"], "sweep");
    let names: Vec<&str> =
        root["sweep"]["points"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["first.evolve.mutation=0.01", "first.evolve.mutation=0.2"]);
    // The point shown is the one with the highest median chosen best of the last evolved stage.
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    let score = |i: usize| summary["points"][i]["stages"][1]["chosen_best"]["median"].as_f64().unwrap();
    let best = if score(1) > score(0) { names[1] } else { names[0] };
    assert_eq!(root["sweep_point"], best);
    assert_eq!(root["seeds"], serde_json::json!([1, 2]));
    let point = report_data(&dir.join("first.evolve.mutation=0.2/report.html"));
    assert_eq!(point["kind"], "experiment");
    assert_eq!(point["sweep_point"], "first.evolve.mutation=0.2");
    assert_eq!(point["sweep"]["points"].as_array().unwrap().len(), 2);
    // An experiment that is no sweep's point lists none.
    let alone = scratch("exp-no-sweep");
    let out = experiment_tiny(&alone, &["--seeds", "1"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(report_data(&alone.join("report.html")).get("sweep").is_none());
}

/// `experiment --stage S` runs S and the stages it needs, and summarises them only.
#[test]
fn an_experiment_of_one_stage_runs_and_summarises_its_chain() {
    let dir = scratch("exp-stage");
    let out = experiment_tiny(&dir, &["--seeds", "1", "--stage", "first", "--no-report"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(dir.join("seed-1/first/best.genome").exists());
    assert!(!dir.join("seed-1/second").exists(), "the stage after `first` ran");
    let md = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    assert!(md.contains("| first | 6 |") && !md.contains("| second |"), "{md}");
}

/// A long training life is trained in full, but `run` records only its
/// first 20000 actions for the trace and the pictures, and says so: a record
/// of millions of actions would take gigabytes.
#[test]
fn a_long_training_life_records_its_first_actions_only() {
    let dir = scratch("long-training");
    let file = dir.join("long.bat");
    std::fs::write(
        &file,
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
    )
    .unwrap();
    let out = run_file(&file, &dir.join("out"), &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let said = text(&out.stderr);
    assert!(said.contains("trained for 30000 actions"), "{said}");
    assert!(said.contains("(trace and pictures: its first 20000 actions)"), "{said}");
    let trace = std::fs::read_to_string(dir.join("out/practice/trace.csv")).unwrap();
    assert_eq!(trace.lines().count(), 1 + 20000, "a header and 20000 rows");
    let json = run_file(&file, &dir.join("json"), &["--json"]);
    let line: serde_json::Value = serde_json::from_str(text(&json.stdout).lines().next().unwrap()).unwrap();
    assert_eq!((line["trained"].as_u64(), line["recorded"].as_u64()), (Some(30000), Some(20000)), "{line}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn read_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).unwrap()
}

/// A test stage of several lives: `summary.json` says how many and how long
/// each was, `trace.csv` holds every action of every life (the action index
/// running on), `episode.json` every life as a part; the same seed gives the
/// same lives; replay, `--set` and an experiment take them.
#[test]
fn a_test_stage_lives_several_lives_in_each_world() {
    let dir = scratch("lives");
    let file = dir.join("lives.bat");
    let stage = "\nstage third extends second {\n  world changes { battery 25 actions }\n  test best for 2 lives of 40 actions with learning\n}\n";
    std::fs::write(&file, std::fs::read_to_string(tiny()).unwrap() + stage).unwrap();
    let out = run(shaping().arg("run").arg(&file).arg("--out").arg(dir.join("a")));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("after the change in 2 lives each"), "{}", text(&out.stderr));
    let summary = read_json(&dir.join("a/third/summary.json"));
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
    let trace = std::fs::read_to_string(dir.join("a/third/trace.csv")).unwrap();
    let actions: Vec<u64> =
        trace.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    assert_eq!(actions, (0..b + a).collect::<Vec<u64>>(), "one row per action of every life");
    // The trajectory draws one life, over its own world.
    let svg = std::fs::read_to_string(dir.join("a/third/trajectory.svg")).unwrap();
    assert!(svg.contains("third: trajectory, the first of the 2 lives after the change"), "{svg}");
    let ep = read_json(&dir.join("a/third/episode.json"));
    let worlds = ep["worlds"].as_array().unwrap();
    let parts: Vec<(&str, u64)> =
        worlds.iter().map(|w| (w["stage"].as_str().unwrap(), w["from"].as_u64().unwrap())).collect();
    assert_eq!(parts, [("second", 0), ("second", before[0]), ("third", b), ("third", b + after[0])]);
    let page = report_data(&dir.join("a/report.html"));
    assert_eq!(page["episodes"][2]["worlds"].as_array().map(Vec::len), Some(4));

    // The same seed, the same lives; `--json` says how many.
    let json = run_file(&file, &dir.join("b"), &["--json"]);
    assert!(json.status.success(), "{}", text(&json.stderr));
    let last: serde_json::Value = serde_json::from_str(text(&json.stdout).lines().last().unwrap()).unwrap();
    assert_eq!(last["stages"][2]["summary"]["lives"], 2, "{last}");
    for f in ["trace.csv", "summary.json", "episode.json"] {
        let same = std::fs::read(dir.join("a/third").join(f)).unwrap()
            == std::fs::read(dir.join("b/third").join(f)).unwrap();
        assert!(same, "{f} differs between two runs of the same seed");
    }

    // `--set STAGE.test.lives`: the first life is the same life.
    let three = run_file(&file, &dir.join("c"), &["--quiet", "--set", "third.test.lives=3"]);
    assert!(three.status.success(), "{}", text(&three.stderr));
    let s3 = read_json(&dir.join("c/third/summary.json"));
    assert_eq!(s3["lives"], 3);
    assert_eq!(s3["before_lives"].as_array().map(Vec::len), Some(3));
    assert_eq!(s3["before_lives"][0], summary["before_lives"][0]);
    let zero = run_file(&file, &dir.join("d"), &["--quiet", "--set", "third.test.lives=0"]);
    assert_eq!(zero.status.code(), Some(2), "{}", text(&zero.stderr));
    assert!(text(&zero.stderr).contains("test.lives"), "{}", text(&zero.stderr));

    // A replay of the test stage: one life in its world.
    let rep = replay_run(&file, &dir.join("a"), &dir.join("rep"), &["--stage", "third"]);
    assert!(rep.status.success(), "{}", text(&rep.stderr));
    let rows = std::fs::read_to_string(dir.join("rep/trace.csv")).unwrap().lines().count() - 1;
    assert!((1..=40).contains(&rows), "{rows}");

    // An experiment over seeds tables the lives.
    let exp = run(shaping()
        .arg("experiment")
        .arg(&file)
        .args(["--seeds", "2", "--no-report", "--out"])
        .arg(dir.join("e")));
    assert!(exp.status.success(), "{}", text(&exp.stderr));
    let md = std::fs::read_to_string(dir.join("e/summary.md")).unwrap();
    assert!(md.contains("| third | test, 2 lives of 40 actions"), "{md}");
}

/// A file whose layout, graph and JSON outputs are each larger than a pipe's
/// buffer (64 KiB), so that writing them always meets a closed reader.
fn wide_bat(dir: &Path) -> PathBuf {
    let modules: String = (0..250)
        .map(|i| format!("  module m{i}_{} {{ sense ir behavior forward }}\n", "x".repeat(300)))
        .collect();
    let path = dir.join("wide.bat");
    std::fs::write(
        &path,
        format!(
            "robot r {{ sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }}\n\
             stage explore {{ evolve {{ population 4 generations 2 actions 30 }} fitness per action wheels[0]\n{modules}}}\n"
        ),
    )
    .unwrap();
    path
}

/// `shaping layout f.bat | head -c 10`: the reader goes away; the command
/// ends as it would have (exit 0 here), without a panic or a message.
#[test]
fn a_closed_standard_output_is_not_a_panic() {
    let dir = scratch("pipe");
    let wide = wide_bat(&dir);
    let many: Vec<&Path> = vec![wide.as_path(); 1000];
    let commands: Vec<Vec<std::ffi::OsString>> = vec![
        vec!["layout".into(), wide.clone().into()],
        vec!["layout".into(), "--format".into(), "json".into(), wide.clone().into()],
        vec!["graph".into(), wide.clone().into()],
        std::iter::once("check".into())
            .chain(["--error-format".into(), "json".into()])
            .chain(many.iter().map(|p| p.as_os_str().to_owned()))
            .collect(),
        std::iter::once("check".into()).chain(many.iter().map(|p| p.as_os_str().to_owned())).collect(),
    ];
    for args in commands {
        let mut child = shaping().args(&args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
        // Read a little, as `head -c 10` does, then close the pipe.
        let mut first = [0u8; 10];
        std::io::Read::read_exact(child.stdout.as_mut().unwrap(), &mut first).unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let what = format!("{:?}", &args[..2]);
        assert!(!text(&out.stderr).contains("panicked"), "{what}: {}", text(&out.stderr));
        assert!(out.status.success(), "{what}: {:?} {}", out.status, text(&out.stderr));
        assert!(text(&out.stderr).trim().is_empty(), "{what}: {}", text(&out.stderr));
    }
}

/// Ctrl-C during a long test stage stops it at once (within its life),
/// says so, exits 2 as an interrupted evolution does, and writes nothing of
/// the test: no `summary.json`, `trace.csv` or `episode.json` that could
/// pass for its result.
#[cfg(unix)]
#[test]
fn ctrl_c_stops_a_test_stage_and_writes_nothing_of_it() {
    let dir = scratch("ctrl-c-test");
    let file = dir.join("t.bat");
    std::fs::write(
        &file,
        "robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }\n\
         stage explore { evolve { population 4 generations 2 actions 30 } fitness per action wheels[0] \
         module m { sense ir behavior forward } }\n\
         stage long extends explore { test best for 1 lives of 1000000 actions with learning }\n",
    )
    .unwrap();
    let out = dir.join("out");
    // The evolved stage is done once its episode is written: the test is under way.
    let child = start_run_until(&file, &out, &["--no-report"], &out.join("explore/episode.json"));
    std::thread::sleep(Duration::from_millis(300));
    ctrl_c(&child);
    let sent = Instant::now();
    let pid = child.id();
    let done = std::thread::spawn(move || child.wait_with_output().unwrap());
    while !done.is_finished() {
        if sent.elapsed() > Duration::from_secs(10) {
            let _ = Command::new("kill").args(["-KILL", &pid.to_string()]).status();
            panic!("Ctrl-C did not stop the test stage within 10 s");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let done = done.join().unwrap();
    let err = text(&done.stderr);
    assert_eq!(done.status.code(), Some(2), "{err}");
    assert!(err.contains("interrupted: test stage `long` stopped in life 1 of 1"), "{err}");
    assert!(err.contains("nothing of it was written"), "{err}");
    for name in ["summary.json", "trace.csv", "episode.json", "best.genome"] {
        assert!(!out.join("long").join(name).exists(), "{name} was written: {err}");
    }
    assert!(!out.join("report.html").exists());
}

/// The report says the seed a stage ran with (`--seed`, an experiment's
/// seed), not the seed the file declares.
#[test]
fn the_report_shows_the_seed_the_run_used() {
    let dir = scratch("report-seed");
    let out = run(shaping().arg("run").arg(tiny()).arg("--out").arg(&*dir).args(["--quiet", "--seed", "99"]));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let data = report_data(&dir.join("report.html"));
    for stage in data["stages"].as_array().unwrap() {
        let how = stage["run"].as_str().unwrap();
        assert!(how.ends_with("seed 99"), "{how}");
    }
    let exp = scratch("report-seed-exp");
    let out = run(shaping()
        .arg("experiment")
        .arg(tiny())
        .args(["--seeds", "2", "--first-seed", "11"])
        .arg("--out")
        .arg(&*exp));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let data = report_data(&exp.join("report.html"));
    let shown = data["shown_seed"].as_u64().unwrap();
    assert!(shown == 11 || shown == 12, "{shown}");
    for stage in data["stages"].as_array().unwrap() {
        let how = stage["run"].as_str().unwrap();
        assert!(how.ends_with(&format!("seed {shown}")), "{how}");
    }
}

/// `build -o` and `report -o` never replace a file they did not write: the
/// source being built, another source, a run's program, checkpoint or genome.
#[test]
fn build_and_report_do_not_overwrite_what_they_did_not_write() {
    let dir = scratch("clobber");
    let src = dir.join("t.bat");
    std::fs::copy(tiny(), &src).unwrap();
    let original = std::fs::read(&src).unwrap();
    let other = dir.join("other.bat");
    std::fs::write(&other, "// another source\n").unwrap();
    for out in [src.clone(), dir.join(".").join("t.bat"), other.clone()] {
        let r = run(shaping().arg("build").arg(&src).arg("-o").arg(&out));
        assert_eq!(r.status.code(), Some(2), "{}", text(&r.stderr));
        assert!(text(&r.stderr).contains(&format!("`{}`", out.display())), "{}", text(&r.stderr));
    }
    assert_eq!(std::fs::read(&src).unwrap(), original);
    assert_eq!(std::fs::read_to_string(&other).unwrap(), "// another source\n");
    // A new file, then the same again: fine.
    let built = dir.join("t.json");
    for _ in 0..2 {
        let r = run(shaping().arg("build").arg(&src).arg("-o").arg(&built));
        assert!(r.status.success(), "{}", text(&r.stderr));
    }

    let runs = dir.join("run");
    assert!(run_tiny(&runs, &[]).status.success());
    for name in ["program.json", "first/checkpoint.json", "first/best.genome", "first/generations.csv"] {
        let path = runs.join(name);
        let before = std::fs::read(&path).unwrap();
        let r = run(shaping().arg("report").arg(&runs).arg("-o").arg(&path));
        assert_eq!(r.status.code(), Some(2), "{name}");
        assert!(text(&r.stderr).contains("exists and is not a report"), "{}", text(&r.stderr));
        assert_eq!(std::fs::read(&path).unwrap(), before, "{name} was changed");
    }
    let r = run(shaping().arg("report").arg(&runs).arg("-o").arg(runs.join("first")));
    assert_eq!(r.status.code(), Some(2));
    assert!(text(&r.stderr).contains("is a directory"), "{}", text(&r.stderr));
    // An earlier report is replaced.
    for _ in 0..2 {
        let r = run(shaping().arg("report").arg(&runs).arg("-o").arg(runs.join("again.html")));
        assert!(r.status.success(), "{}", text(&r.stderr));
    }
}

/// A criterion no fitness can reach (`nan`, `inf`, beyond f32) is refused
/// before anything runs, as a word is; so are non-finite `--set` values.
#[test]
fn non_finite_criteria_and_settings_are_refused() {
    let dir = scratch("nan");
    for value in ["nan", "NaN", "inf", "-inf", "infinity", "1e40", "abc"] {
        let out =
            experiment_tiny(&dir.join("x"), &["--seeds", "1", "--criterion", &format!("first={value}")]);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{value}: {err}");
        assert!(err.contains(&format!("criterion `first={value}`: `{value}` is not a")), "{value}: {err}");
        assert!(!dir.join("x").exists(), "{value}: files written before the error");
    }
    for value in ["nan", "inf", "-inf", "1e40"] {
        let out = experiment_tiny(
            &dir.join("x"),
            &["--seeds", "1", "--set", &format!("first.evolve.mutation={value}")],
        );
        assert_eq!(out.status.code(), Some(2), "{value}: {}", text(&out.stderr));
        assert!(!dir.join("x").exists());
    }
}

/// `report` names a damaged file and what is wrong with it (exit 2) rather
/// than showing a stage with its genes or results silently empty.
#[test]
fn report_names_a_damaged_genome_summary_or_checkpoint() {
    let dir = scratch("report-damaged");
    let out = run(shaping().arg("run").arg(report_bat()).arg("--out").arg(&*dir).arg("--quiet"));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let cases: [(&str, &str, &str); 6] = [
        ("navigation/best.genome", "1111\n", "is not a genome of stage `navigation`: it has 4 bits"),
        (
            "navigation/best.genome",
            "10x1\n",
            "is not a genome of stage `navigation`: it is not a string of 0 and 1",
        ),
        ("bigger/summary.json", "{}", "is not a test stage's summary: no `before.fitness`"),
        ("bigger/summary.json", "[1]", "is not a test stage's summary: it is not a JSON object"),
        ("bigger/summary.json", "{", "is not a test stage's summary"),
        ("navigation/checkpoint.json", "{}", "is corrupt"),
    ];
    for (file, content, wanted) in cases {
        let path = dir.join(file);
        let good = std::fs::read(&path).unwrap();
        std::fs::write(&path, content).unwrap();
        let out = run(shaping().arg("report").arg(&*dir));
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{file} = {content:?}: {err}");
        assert!(err.contains(&format!("`{}` {wanted}", path.display())), "{file} = {content:?}: {err}");
        std::fs::write(&path, good).unwrap();
    }
    assert!(run(shaping().arg("report").arg(&*dir)).status.success());
}

/// A directory whose stages ran with two seeds (one started again with
/// `--fresh --stage S --seed N`) cannot be resumed with either seed: the
/// error says which stage has which seed and what to do, not `--seed` advice
/// that fails on another stage.
#[test]
fn stages_of_two_seeds_in_one_directory_are_named() {
    let dir = scratch("two-seeds");
    assert!(run_tiny(&dir, &["--no-report"]).status.success());
    let out = run_tiny(&dir, &["--no-report", "--fresh", "--stage", "first", "--seed", "99"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    for (extra, seed) in [(&["--seed", "99"][..], 99), (&[][..], 3)] {
        let out = run_tiny(&dir, &[&["--no-report"][..], extra].concat());
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("holds stages of different seeds (`first` seed 99, `second` seed 3)"), "{err}");
        assert!(err.contains(&format!("pass `--fresh` to run every stage again with seed {seed}")), "{err}");
        assert!(!err.contains("pass `--seed"), "{err}");
    }
    // The stage alone still resumes; `--fresh` starts everything again.
    assert!(run_tiny(&dir, &["--no-report", "--stage", "first", "--seed", "99"]).status.success());
    assert!(run_tiny(&dir, &["--no-report", "--fresh"]).status.success());
}

/// A world crowded for the random placement (not certainly impossible, so
/// it runs) is no silent source of wrong numbers: `run` warns on stderr,
/// even with `--quiet`, naming the stage and how many episodes overlapped
/// (at the first crowded generation and with the totals at the end), a
/// test stage names its crowded lives and records them in `summary.json`,
/// the checkpoint's statistics count them, and `replay` warns too. A world
/// with room enough says nothing and writes none of it.
#[test]
fn a_crowded_world_is_warned_about_and_counted() {
    let dir = scratch("crowded");
    let file = root().join("tests/cli/crowded.bat");
    let out = dir.join("out");
    let ran = run_file(&file, &out, &["--quiet"]);
    assert!(ran.status.success(), "{}", text(&ran.stderr));
    let err = text(&ran.stderr);
    assert!(err.contains("warning: the world of stage `crowded` is too crowded: in generation 0,"), "{err}");
    let total = regex_lite_count(&err, "warning: the world of stage `crowded` is too crowded: in ", " of ");
    assert!(total.is_some_and(|(n, m)| n > 0 && n <= m && m >= 12), "{err}");
    assert!(err.contains("could not be placed apart and overlap"), "{err}");
    assert!(err.contains("warning: the world of stage `tested` is too crowded: in "), "{err}");
    assert!(err.contains(" of 4 lives "), "{err}");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("tested/summary.json")).unwrap()).unwrap();
    assert!(summary["crowded_lives"].as_u64().is_some_and(|n| (1..=4).contains(&n)), "{summary}");
    assert!(summary["placement_failures"].as_u64().is_some_and(|n| n >= 1), "{summary}");
    let checkpoint = std::fs::read_to_string(out.join("crowded/checkpoint.json")).unwrap();
    assert!(checkpoint.contains("\"crowded_episodes\""), "{checkpoint}");
    // The report's table of results says it for both stages.
    let reported = run(shaping().arg("report").arg(&out));
    assert!(reported.status.success(), "{}", text(&reported.stderr));
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.matches("the world was too crowded: in ").count() >= 2, "no note in the report");
    assert!(page.contains(" episodes of its generations objects"), "no note for the evolved stage");

    let replayed = replay_run(&file, &out, &dir.join("replay"), &["--stage", "crowded"]);
    assert!(replayed.status.success(), "{}", text(&replayed.stderr));
    let err = text(&replayed.stderr);
    assert!(err.contains("warning: the world of stage `crowded` is too crowded: in its episode"), "{err}");

    // The same file with room enough: no warning, no count in any file.
    let roomy = dir.join("roomy.bat");
    let src = std::fs::read_to_string(&file).unwrap();
    std::fs::write(&roomy, src.replace("objects 30 diameter 60mm", "objects 8 diameter 25mm")).unwrap();
    let ran = run_file(&roomy, &dir.join("roomy"), &["--quiet"]);
    assert!(ran.status.success(), "{}", text(&ran.stderr));
    assert!(text(&ran.stderr).trim().is_empty(), "{}", text(&ran.stderr));
    let checkpoint = std::fs::read_to_string(dir.join("roomy/crowded/checkpoint.json")).unwrap();
    assert!(!checkpoint.contains("crowded_episodes"), "{checkpoint}");
    let summary = std::fs::read_to_string(dir.join("roomy/tested/summary.json")).unwrap();
    assert!(!summary.contains("crowded_lives"), "{summary}");
    assert!(run(shaping().arg("report").arg(dir.join("roomy"))).status.success());
    let page = std::fs::read_to_string(dir.join("roomy/report.html")).unwrap();
    assert!(!page.contains("too crowded"), "a note in the report of a world with room enough");
}

/// The two numbers of `{prefix}N{between}M` in `text`.
fn regex_lite_count(text: &str, prefix: &str, between: &str) -> Option<(u64, u64)> {
    let rest = &text[text.rfind(prefix)? + prefix.len()..];
    let (n, rest) = rest.split_once(between)?;
    let m: String = rest.chars().take_while(char::is_ascii_digit).collect();
    Some((n.parse().ok()?, m.parse().ok()?))
}

/// Two runs into one `--out`: the second is refused at once, naming the
/// process that holds the directory; the first goes on unharmed (stopped
/// here by Ctrl-C, which it reports as usual). The lock goes with its
/// holder, also after `kill -9`.
#[cfg(unix)]
#[test]
fn a_second_run_into_a_directory_in_use_is_refused_naming_its_holder() {
    let dir = scratch("locked");
    let file = dir.join("s.bat");
    std::fs::write(&file, EDITED.replace("generations 5", "generations 1000")).unwrap();
    let out = dir.join("out");
    let child = start_run_until(&file, &out, &["--no-report", "--jobs", "1"], &out.join("s/checkpoint.json"));
    let second = run_file(&file, &out, &[]);
    let err = text(&second.stderr);
    assert_eq!(second.status.code(), Some(2), "{err}");
    assert!(err.contains("is in use by") && err.contains(&format!("process {}", child.id())), "{err}");
    assert!(err.contains("choose another `--out`"), "{err}");
    ctrl_c(&child);
    let first = child.wait_with_output().unwrap();
    assert!(text(&first.stderr).contains("interrupted: stage `s` stopped"), "{}", text(&first.stderr));
    let killed =
        start_run_until(&file, &out, &["--no-report", "--jobs", "1"], &out.join("s/checkpoint.json"));
    assert!(run(Command::new("kill").args(["-KILL", &killed.id().to_string()])).status.success());
    let _ = killed.wait_with_output().unwrap();
    // Resumed (or refused for its generations): not for a lock.
    std::fs::write(&file, EDITED).unwrap();
    let again = run_file(&file, &out, &[]);
    assert!(!text(&again.stderr).contains("is in use"), "{}", text(&again.stderr));
}

/// `replay` takes `--set` as `run` does: a run made with a setting changed
/// on a parent stage replays with the same setting.
#[test]
fn replay_takes_the_settings_the_run_was_made_with() {
    let dir = scratch("replay-set");
    let out = dir.join("run");
    let set = ["--set", "first.evolve.generations=2"];
    let made = run_tiny(&out, &set);
    assert!(made.status.success(), "{}", text(&made.stderr));
    let plain = replay_run(&tiny(), &out, &dir.join("plain"), &["--stage", "second"]);
    assert_eq!(plain.status.code(), Some(2), "{}", text(&plain.stderr));
    assert!(text(&plain.stderr).contains("is not of this program"), "{}", text(&plain.stderr));
    let with = replay_run(&tiny(), &out, &dir.join("with"), &["--stage", "second", set[0], set[1]]);
    assert!(with.status.success(), "{}", text(&with.stderr));
    assert!(dir.join("with/trace.csv").exists());
}

/// `check --error-format json` gives each diagnostic's line and column
/// (1-based, in characters), where the human format points.
#[test]
fn json_diagnostics_have_lines_and_columns() {
    let file = root().join("tests/ui/window_too_large.bat");
    let out = run(shaping().arg("check").arg(&file).args(["--error-format", "json"]));
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = &v["related"][0];
    assert_eq!((d["line"].as_u64(), d["column"].as_u64()), (Some(12), Some(50)), "{v}");
    assert_eq!(d["labels"][0]["line"], 12);
    let human = run(shaping().arg("check").arg(&file).args(["--error-format", "plain"]));
    assert!(text(&human.stderr).contains("window_too_large.bat:12:50"), "{}", text(&human.stderr));
}

/// An experiment's report shows the seeds its summaries cover, not every
/// `seed-N` an earlier experiment left in the directory.
#[test]
fn an_experiment_report_shows_the_seeds_its_summary_covers() {
    let dir = scratch("covered-seeds");
    assert!(experiment_tiny(&dir, &["--seeds", "3", "--no-report"]).status.success());
    let fewer = experiment_tiny(&dir, &["--seeds", "2"]);
    assert!(fewer.status.success(), "{}", text(&fewer.stderr));
    let data = report_data(&dir.join("report.html"));
    assert_eq!(data["seeds"], serde_json::json!([1, 2]), "seed-3 is on disk but not summarised");
}
