//! The `shaping` binary, run as a user runs it: what the command line
//! adds to the engine (arguments, exit codes, what is printed and where,
//! `--json`, signals, a closed standard output) and the commands that are
//! only the command line's (`check`, `build`, `layout`, `graph`, `bench`).
//! What a run, an experiment, a replay or a report does is tested through
//! the library, in `engine/tests/`.

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

/// `layout --format json`: the table's rows as data, with its names
/// (stages, modules, what each gene is), not indices and enums.
#[test]
fn layout_json_names_what_the_table_shows() {
    let file = root().join("examples/khepera.bat");
    let out = run(shaping().arg("layout").arg(&file).args(["--stage", "collect", "--format", "json"]));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["stage"], "collect");
    let genes = v["genes"].as_array().unwrap();
    let table = text(&run(shaping().arg("layout").arg(&file).args(["--stage", "collect"])).stdout);
    assert_eq!(
        genes.len(),
        table.lines().filter(|l| l.contains("frozen") || l.contains("evolvable")).count() - 1
    );
    assert_eq!(genes[0]["stage"], "navigation");
    assert!(genes[0]["module"].is_string() && genes[0]["frozen"] == true, "{}", genes[0]);
    assert_eq!(genes[0]["what"], "bias");
    let weight = genes.iter().find(|g| g["kind"] == "weight").unwrap();
    assert!(weight["input"].as_str().unwrap().contains('['), "{weight}");
    let link = genes.iter().find(|g| g["kind"] == "link").unwrap();
    assert_eq!(link["what"], format!("link {}", link["link"].as_str().unwrap()));
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

/// Whether `program` is on the PATH.
fn which(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(program).is_file()))
}

/// `replay --gif` writes the episode as an animated GIF: the collect stage
/// of `khepera.bat` as run, more than 10 frames, at most 300; `--mp4` the
/// same frames as an H.264 video; `--mp4` without `ffmpeg` on the PATH is
/// refused naming it, before anything runs.
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

    // With `ffmpeg` (and its `ffprobe`), `--mp4` writes the same frames as
    // a video that decodes; CI installs it, so there its absence fails.
    let mp4 = dir.join("out.mp4");
    if which("ffmpeg") && which("ffprobe") {
        let out = run(shaping()
            .arg("replay")
            .arg(&khepera)
            .args(["--stage", "collect", "--run"])
            .arg(&dir)
            .arg("--mp4")
            .arg(&mp4));
        assert!(out.status.success(), "{}", text(&out.stderr));
        let probe = run(Command::new("ffprobe")
            .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
            .args(["-show_entries", "stream=nb_read_frames,codec_name", "-of", "default=noprint_wrappers=1"])
            .arg(&mp4));
        assert!(probe.status.success(), "{}", text(&probe.stderr));
        let said = text(&probe.stdout);
        assert!(said.contains("codec_name=h264"), "{said}");
        assert!(said.contains(&format!("nb_read_frames={frames}")), "{frames} frames in the GIF: {said}");
        std::fs::remove_file(&mp4).unwrap();
    } else {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI has `ffmpeg` and `ffprobe` (.ci/run installs them)"
        );
    }

    let empty = dir.join("no-programs");
    std::fs::create_dir_all(&empty).unwrap();
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
    // One robot: its steps are the robot-steps.
    assert_eq!(v["robots"], 1, "{v}");
    assert_eq!(v["robot_steps_per_sec"], v["sim_steps_per_sec"], "{v}");
    assert!(v["file"].as_str().unwrap().ends_with("tiny.bat"), "{v}");
    // The bench's own life lengths are in the line, beside the stage's.
    assert_eq!(v["controller_episode_actions"], 300, "{v}");
    assert_eq!(v["controller_episodes_per_run"], 200, "{v}");
    assert!(v["stage_actions"].as_u64().unwrap() > 0, "{v}");
    assert!(v["sim_episode_actions"].as_u64().unwrap() > 0, "{v}");
    // The build that measured (these tests run a debug one) and the peak memory.
    assert_eq!(v["build"], if cfg!(debug_assertions) { "debug" } else { "release" }, "{v}");
    let mb = v["peak_memory_mb"].as_f64().unwrap();
    assert!(mb > 1.0 && mb < 1000.0, "{v}");
    // `--set` as `run` has it: applied, or refused saying why.
    let out =
        run(shaping().arg("bench").arg(tiny()).args(["--runs", "1", "--set", "second.world.arena=300x300"]));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out =
        run(shaping().arg("bench").arg(tiny()).args(["--runs", "1", "--set", "second.world.arena=1x1"]));
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("--set second.world.arena=1x1"), "{}", text(&out.stderr));
    let out = run(shaping().arg("bench").arg(tiny()).args(["--set", "second.world.arena=300x300,400x400"]));
    assert!(text(&out.stderr).contains("`bench` takes one value"), "{}", text(&out.stderr));
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

/// A training stage, a world crowded for the random placement, and a test
/// stage of two lives: what a run says about each.
const SAID: &str = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
genome { bits 4  range -1..1 }
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
stage crowded {
  world { arena 400mm x 600mm  objects 30 diameter 60mm physical }
  evolve { population 6  generations 2  actions 20  seed 3  selection truncation keep 2 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 20
  module wander { sense ir  behavior forward(1.0) }
  module spin { sense ir[2..3]  behavior turn left }
  links all evolvable
}
stage tested extends crowded {
  test best for 2 lives of 20 actions without learning
}
";

/// Every non-empty line of `stderr` is a warning, and there is one.
fn only_warnings(stderr: &str) {
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert!(!lines.is_empty() && lines.iter().all(|l| l.starts_with("warning: ")), "{stderr}");
}

/// What `run` says on the terminal, stage by stage (the engine tells it,
/// `engine/tests/stages.rs` checks what): a training stage's actions and
/// the part its trace records, an evolved stage's generations and chosen
/// best, a test stage's lives, warnings, what is reused when run again,
/// the report; `--quiet` prints the warnings only, `--json` the rest as
/// JSON lines; `replay` prints its episode and warns as `run` does.
#[test]
fn the_terminal_says_what_each_stage_did() {
    let dir = scratch("terminal");
    let file = dir.join("said.bat");
    std::fs::write(&file, SAID).unwrap();
    let out = dir.join("out");
    let first = run(shaping().arg("run").arg(&file).arg("--out").arg(&out));
    assert!(first.status.success(), "{}", text(&first.stderr));
    let report = format!("report: {}", out.join("report.html").display());
    let err = text(&first.stderr);
    for said in [
        "stage practice     trained for 30000 actions, performance avoid ",
        " (trace and pictures: its first 20000 actions)  -> ",
        "warning: the world of stage `crowded` is too crowded: in generation 0,",
        "stage crowded      2 generations  last best ",
        "warning: the world of stage `tested` is too crowded: in ",
        "stage tested       test of the best, ",
        " after the change in 2 lives each (fitness: mean per life): fitness ",
        "done in ",
        &report,
    ] {
        assert!(err.contains(said), "`{said}` missing from:\n{err}");
    }
    let again = run(shaping().arg("run").arg(&file).arg("--out").arg(&out));
    let err = text(&again.stderr);
    assert!(err.contains("stage practice     trained before, reused  -> "), "{err}");
    assert!(err.contains("stage crowded      all 2 generations done before, from "), "{err}");
    let quiet = run(shaping().arg("run").arg(&file).arg("--out").arg(&out).arg("--quiet"));
    assert!(quiet.status.success(), "{}", text(&quiet.stderr));
    only_warnings(&text(&quiet.stderr));

    let json = run(shaping().arg("run").arg(&file).arg("--out").arg(&out).args(["--json", "--fresh"]));
    assert!(json.status.success(), "{}", text(&json.stderr));
    only_warnings(&text(&json.stderr));
    let lines: Vec<serde_json::Value> =
        text(&json.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let trained = &lines[0];
    assert_eq!((trained["event"].as_str(), trained["stage"].as_str()), (Some("trained"), Some("practice")));
    assert_eq!((trained["actions"].as_u64(), trained["recorded"].as_u64()), (Some(30000), Some(20000)));
    assert_eq!(lines.len(), 1 + 2 + 1 + 1, "trained, 2 generations, tested, done: {lines:?}");
    assert_eq!(lines[3]["lives"], 2, "{}", lines[3]);
    assert_eq!(lines[4]["stages"][2]["summary"]["lives"], 2, "{}", lines[4]);

    let rep = dir.join("rep");
    let replay = run(shaping()
        .arg("replay")
        .arg(&file)
        .args(["--stage", "crowded", "--report", "--run"])
        .arg(&out)
        .arg("--out")
        .arg(&rep));
    assert!(replay.status.success(), "{}", text(&replay.stderr));
    let said = text(&replay.stdout);
    let lines: Vec<&str> = said.lines().collect();
    assert!(lines[0].starts_with("crowded: 20 actions, fitness "), "{said}");
    assert!(lines[0].ends_with(&format!(" collisions -> {}", rep.display())), "{said}");
    assert_eq!(lines[1], format!("report: {}", rep.join("report.html").display()));
    let err = text(&replay.stderr);
    assert!(err.contains("warning: the world of stage `crowded` is too crowded: in its episode"), "{err}");
}

/// `run` and `replay` take one value per `--set` (`experiment` sweeps
/// several); a setting that cannot run is an error, exit 2, before
/// anything is written (`engine/tests/experiment.rs` checks the messages).
#[test]
fn a_set_value_the_command_cannot_take_is_refused() {
    let dir = scratch("bad-set");
    let out = run_tiny(&dir.join("y"), &["--set", "first.evolve.mutation=0.1,0.2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("`run` takes one value"), "{}", text(&out.stderr));
    assert!(!dir.join("y").exists());
    let out = run(shaping()
        .arg("experiment")
        .arg(tiny())
        .args(["--seeds", "1", "--set", "frist.evolve.mutation=0.1", "--out"])
        .arg(dir.join("x")));
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("did you mean `first`?"), "{}", text(&out.stderr));
    assert!(!dir.join("x").exists(), "files written before the error");
}

// ------------------------------------------------------------ trust (issue 19)

/// The file: two scripted modules, links evolved.
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

/// Ctrl-C stops the run (the generation under way dropped, or after the
/// last between two), saying where; the same command resumes it, saying so.
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
    // Between two generations it stops after the last; within one, that
    // one is dropped (the engine's evaluator sees the flag too).
    let number = |after: &str| -> Option<u32> {
        let at = err.find(after)? + after.len();
        err[at..].split(' ').next()?.parse().ok()
    };
    let generation = match (number("stopped after generation "), number("stopped in generation ")) {
        (Some(g), None) => {
            assert!(err.contains("of 1000, saved in"), "{err}");
            g
        }
        (None, Some(g)) => {
            assert!(err.contains(&format!("which is dropped; the {} before it are saved", g - 1)), "{err}");
            g - 1
        }
        _ => panic!("{err}"),
    };
    assert!(
        err.contains("interrupted: stage `s` stopped") && err.contains("the same command resumes it"),
        "{err}"
    );
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
        let lines: Vec<serde_json::Value> =
            text(&out.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        if pass == 0 {
            // One line per generation: 6 + 4, then the end of the run.
            assert_eq!(lines.len(), 11, "{}", text(&out.stdout));
            assert_eq!(lines[9]["stats"]["generation"], 9);
            assert_eq!(lines[9]["event"], "generation");
        }
        let last = lines.last().unwrap();
        assert_eq!(last["done"], true, "pass {pass}: {last}");
        let stages = last["stages"].as_array().unwrap();
        assert_eq!(stages.len(), 2);
        let best = std::fs::read_to_string(dir.join("run/second/best.genome")).unwrap();
        assert_eq!(stages[1]["genome"].as_str().unwrap(), best.trim());
        assert!(stages[1]["best"].as_f64().is_some());
    }
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
    // `check` prints a line per file: many small files.
    let small = dir.join("small.bat");
    std::fs::copy(tiny(), &small).unwrap();
    let many: Vec<&Path> = vec![small.as_path(); 2000];
    let all = run(shaping().arg("check").args(&many));
    assert!(all.stdout.len() > 64 << 10, "{} bytes fit in a pipe's buffer", all.stdout.len());
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

/// `report` shows a damaged file by name, exit 2, and warns about files
/// from before seals (read, but unchecked); `replay --out` and `drive
/// --out` into a stage's directory are refused before anything runs.
#[test]
fn report_names_a_damaged_file_and_warns_about_unsealed_ones() {
    let dir = scratch("seals");
    let runs = dir.join("run");
    assert!(run_tiny(&runs, &["--no-report"]).status.success());
    let genome = runs.join("first/best.genome");
    let good = std::fs::read_to_string(&genome).unwrap();
    let flipped = match good.strip_prefix('0') {
        Some(rest) => format!("1{rest}"),
        None => format!("0{}", &good[1..]),
    };
    std::fs::write(&genome, flipped).unwrap();
    let r = run(shaping().arg("report").arg(&runs));
    assert_eq!(r.status.code(), Some(2), "{}", text(&r.stderr));
    assert!(
        text(&r.stderr).contains(&format!("error: `{}` is corrupt", genome.display())),
        "{}",
        text(&r.stderr)
    );
    std::fs::write(&genome, good).unwrap();
    std::fs::remove_file(runs.join("first/.seals")).unwrap();
    let r = run(shaping().arg("report").arg(&runs));
    assert!(r.status.success(), "{}", text(&r.stderr));
    let err = text(&r.stderr);
    assert!(
        err.starts_with(&format!(
            "warning: 3 files have no seal (`{}` and 2 more): written before runs sealed their files",
            genome.display()
        )),
        "{err}"
    );
    let episode = std::fs::read(runs.join("second/episode.json")).unwrap();
    let r = run(shaping()
        .arg("replay")
        .arg(tiny())
        .args(["--stage", "second", "--run"])
        .arg(&runs)
        .arg("--out")
        .arg(runs.join("second")));
    assert_eq!(r.status.code(), Some(2), "{}", text(&r.stderr));
    assert!(
        text(&r.stderr).contains("a replay never writes into a run's directories"),
        "{}",
        text(&r.stderr)
    );
    assert_eq!(std::fs::read(runs.join("second/episode.json")).unwrap(), episode);
    // `drive` too, before the port is opened.
    let r = run(shaping()
        .arg("drive")
        .arg(tiny())
        .args(["--stage", "second", "--port", "/dev/no-such-port", "--run"])
        .arg(&runs)
        .arg("--out")
        .arg(runs.join("second")));
    assert_eq!(r.status.code(), Some(2), "{}", text(&r.stderr));
    assert!(text(&r.stderr).contains("`drive` never writes into a run's directories"), "{}", text(&r.stderr));
    assert_eq!(std::fs::read(runs.join("second/episode.json")).unwrap(), episode);
    // A life of no actions, or of more than a life may have, as `replay` refuses.
    let (replay, drive) = (&["replay"][..], &["drive", "--port", "/dev/no-such-port"][..]);
    for (command, actions) in [(replay, "0"), (drive, "0"), (drive, "4000000000")] {
        let r = run(shaping().arg(command[0]).arg(tiny()).args(&command[1..]).args(["--actions", actions]));
        assert_eq!(r.status.code(), Some(2), "{command:?} --actions {actions}: {}", text(&r.stderr));
        assert!(text(&r.stderr).contains("--actions <ACTIONS>"), "{}", text(&r.stderr));
    }
}

/// A run directory belongs to one file: a run of another file into it is
/// refused naming both, with nothing written, and `--fresh` replaces it;
/// the directory's own `program.json` may be run into it again.
#[test]
fn a_run_of_another_file_into_a_run_directory_is_refused_naming_both() {
    let dir = scratch("owner");
    let out = dir.join("out");
    assert!(run_tiny(&out, &["--no-report"]).status.success());
    let other = dir.join("other.bat");
    std::fs::write(&other, std::fs::read_to_string(tiny()).unwrap().replace("population 12", "population 8"))
        .unwrap();
    let before = std::fs::read(out.join("program.json")).unwrap();
    let r = run_file(&other, &out, &[]);
    let err = text(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("holds a run of `tiny.bat`, not of `other.bat`"), "{err}");
    assert_eq!(std::fs::read(out.join("program.json")).unwrap(), before);
    let own = run_file(&out.join("program.json"), &out, &[]);
    assert!(own.status.success(), "{}", text(&own.stderr));
    let r = run_file(&other, &out, &["--fresh"]);
    assert!(r.status.success(), "{}", text(&r.stderr));
    assert!(text(&std::fs::read(out.join("source.json")).unwrap()).contains("\"other.bat\""));
}

/// `compare` of two finished experiments prints the tests as Markdown (or
/// JSON with `--json`); a directory of one seed is refused with status 2,
/// saying why, and so is a single directory.
#[test]
fn compare_prints_the_tests_of_two_experiments() {
    let dir = scratch("compare");
    let (a, b, one) = (dir.join("a"), dir.join("b"), dir.join("one"));
    for (out, seeds, first) in [(&a, "3", "1"), (&b, "3", "4"), (&one, "1", "1")] {
        let args = ["--seeds", seeds, "--first-seed", first, "--no-report", "--jobs", "2"];
        let done = run(shaping().arg("experiment").arg(tiny()).arg("--out").arg(out).args(args));
        assert!(done.status.success(), "{}", text(&done.stderr));
    }
    let out = run(shaping().arg("compare").arg(&a).arg(&b));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let md = text(&out.stdout);
    assert!(md.starts_with("# Comparison\n"), "{md}");
    assert!(md.contains("| pair | U | p-value | A12 | size | test |") && md.contains("| 1 vs 2 |"), "{md}");
    let out = run(shaping().arg("compare").arg(&a).arg(&b).arg("--json"));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pair = &json["measures"][0]["pairs"][0];
    assert!(pair["p_value"].is_number() && pair["a12"].is_number(), "{json}");
    let out = run(shaping().arg("compare").arg(&a).arg(&one));
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("no test: `") && err.contains("needs at least 2 seeds per side"), "{err}");
    assert_eq!(run(shaping().arg("compare").arg(&a)).status.code(), Some(2));
}

/// `replay --robot N` of a robot the team does not have, and `--variant`
/// of a variant the stage does not declare: exit 2, saying what and where,
/// nothing written.
#[test]
fn replay_refuses_a_robot_or_a_variant_the_stage_does_not_have() {
    let dir = scratch("replay-robot");
    let file = root().join("examples/aggregation.bat");
    let genome = "0".repeat(176);
    let replay = |extra: &[&str]| {
        run(shaping()
            .arg("replay")
            .arg(&file)
            .args(["--genome", &genome, "--actions", "5"])
            .arg("--out")
            .arg(dir.join("out"))
            .args(extra))
    };
    let out = replay(&["--robot", "10"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("`--robot 10`: stage `aggregate` has 10 robots, 0 to 9"),
        "{}",
        text(&out.stderr)
    );
    let out = replay(&["--variant", "dark"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("`--variant dark`: stage `aggregate` declares no variants"),
        "{}",
        text(&out.stderr)
    );
    assert!(!dir.join("out").exists(), "nothing written");
    let out = replay(&["--robot", "9"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(dir.join("out/robots.json").exists());
}
