//! `shaping drive`, `shaping run --robot` and their faults, end to end
//! against `shaping emulate` on a pseudo-terminal (the built binary).

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn shaping() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shaping"))
}

fn file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/cli/robot.bat")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("shaping-robot-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A running emulator, killed when dropped.
struct Emulator {
    child: Child,
    port: PathBuf,
}

impl Emulator {
    fn start(dir: &Path, extra: &[&str]) -> Emulator {
        let port = dir.join("khepera.pty");
        let child = shaping()
            .arg("emulate")
            .arg(file())
            .args(["--stage", "roam", "--baud", "0", "--port"])
            .arg(&port)
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the emulator starts");
        let t = Instant::now();
        while std::fs::symlink_metadata(&port).is_err() {
            // Generous: a loaded machine may take long to start a process.
            assert!(t.elapsed() < Duration::from_secs(120), "the emulator made no port");
            std::thread::sleep(Duration::from_millis(20));
        }
        Emulator { child, port }
    }

    /// Stops the emulator and returns the last wheel speeds it was sent.
    fn last_speed(mut self) -> Option<(i32, i32)> {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let mut out = String::new();
        self.child.stdout.take().unwrap().read_to_string(&mut out).unwrap();
        out.lines().rev().find_map(|l| {
            let mut w = l.strip_prefix("speed ")?.split(' ');
            Some((w.next()?.parse().ok()?, w.next()?.parse().ok()?))
        })
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Evolves the first stage in the simulator (once per test that needs it).
fn evolved(dir: &Path) -> PathBuf {
    let runs = dir.join("runs");
    let out = shaping()
        .arg("run")
        .arg(file())
        .args(["--stage", "roam", "--quiet", "--out"])
        .arg(&runs)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    runs
}

/// The longest wait for an answer of the emulator in the tests that expect
/// none to be late: generous, so a loaded machine cannot make one late.
const PATIENT_MS: &str = "10000";

fn drive(emu: &Emulator, runs: &Path, out: &Path, extra: &[&str]) -> Output {
    shaping()
        .arg("drive")
        .arg(file())
        .args(["--stage", "roam", "--period", "0", "--timeout", PATIENT_MS, "--run"])
        .arg(runs)
        .arg("--port")
        .arg(&emu.port)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn fitness_of(stdout: &[u8]) -> f32 {
    let s = text(stdout);
    let at = s.find("fitness ").unwrap_or_else(|| panic!("no fitness in `{s}`"));
    s[at + 8..].split(',').next().unwrap().trim().parse().unwrap()
}

#[test]
fn drive_runs_300_actions_and_writes_the_replay_files() {
    let dir = scratch("drive");
    let runs = evolved(&dir);
    let emu = Emulator::start(&dir, &[]);
    let out = drive(&emu, &runs, &dir.join("d"), &["--actions", "300"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let trace = std::fs::read_to_string(dir.join("d/trace.csv")).unwrap();
    assert_eq!(trace.lines().count(), 301, "a header and 300 actions");
    for f in ["activations.png", "trajectory.png", "reinforcement.png", "summary.json", "genome"] {
        assert!(dir.join("d").join(f).exists(), "{f}");
    }
    assert_eq!(emu.last_speed(), Some((0, 0)), "the motors are stopped at the end");
}

/// Over the emulated link, fitness follows `replay` of the same individual
/// and episode seed. The link quantizes (10-bit readings, integer speed units
/// of 8 mm/s, odometry in 0.08 mm pulses, virtual IR added to the quantized
/// reading), so only a decision sitting on a threshold could go the other
/// way: with learning off (outputs thresholded at 0.5) the episodes agree to
/// 0.01. With learning on they are not compared episode by episode: CRBP
/// samples each output bit with probability = output, a reading quantized
/// to 10 bits moves an output by about 1e-3, and over 300 actions some
/// sample flips in most episodes, after which the paths differ (measured on
/// these 8 seeds: 2 of 8 equal, differences up to 0.39).
#[test]
fn fitness_over_the_link_is_close_to_replay() {
    let dir = scratch("fitness");
    let runs = evolved(&dir);
    let mut pairs = Vec::new();
    for seed in 1..=8u64 {
        let s = seed.to_string();
        let emu = Emulator::start(&dir, &["--seed", &s]);
        let replay = shaping()
            .arg("replay")
            .arg(file())
            .args(["--stage", "roam", "--actions", "300", "--no-learning", "--seed", &s, "--run"])
            .arg(&runs)
            .arg("--out")
            .arg(dir.join("r"))
            .output()
            .unwrap();
        assert!(replay.status.success(), "{}", text(&replay.stderr));
        let driven = drive(&emu, &runs, &dir.join("d"), &["--actions", "300", "--no-learning", "--seed", &s]);
        assert!(driven.status.success(), "{}", text(&driven.stderr));
        pairs.push((fitness_of(&replay.stdout), fitness_of(&driven.stdout)));
    }
    assert!(pairs.iter().all(|(r, d)| (r - d).abs() <= 0.01), "(replay, drive): {pairs:?}");
    // The comparison has power only if the individual does something.
    assert!(pairs.iter().filter(|(r, _)| *r > 0.02).count() >= 2, "(replay, drive): {pairs:?}");
}

#[test]
fn run_on_the_robot_evolves_and_resumes_after_being_killed() {
    let dir = scratch("evolve");
    // The emulator drops its answer to request 1000 (an episode takes about
    // 164 requests: in the seventh), and the first run waits a minute for
    // it: it is killed there, whatever the machine's load, not in a race with
    // its own end.
    let mut emu = Emulator::start(&dir, &["--fault", "drop@1000"]);
    let mut said = std::io::BufReader::new(emu.child.stderr.take().unwrap());
    let out = dir.join("runs");
    let run = || {
        let mut c = shaping();
        c.arg("run")
            .arg(file())
            .args(["--stage", "roam", "--quiet", "--period", "0", "--robot"])
            .arg(&emu.port);
        c.arg("--out").arg(&out);
        c
    };
    let log = out.join("roam/robot-episodes.jsonl");
    let mut first =
        run().args(["--timeout", "60000"]).stdout(Stdio::null()).stderr(Stdio::null()).spawn().unwrap();
    // Killed once the emulator has dropped that answer (the run waits for it),
    // having evaluated a few individuals, in the second generation.
    let mut line = String::new();
    while !line.contains("fault: no answer to request 1000") {
        line.clear();
        let n = std::io::BufRead::read_line(&mut said, &mut line).unwrap();
        assert!(n > 0, "the emulator ended before the fault");
    }
    assert!(first.try_wait().unwrap().is_none(), "the run ended before it was killed");
    assert!(std::fs::read_to_string(&log).unwrap().lines().count() >= 5, "few episodes logged");
    first.kill().unwrap();
    first.wait().unwrap();
    let before = std::fs::read_to_string(&log).unwrap().lines().count();
    let second = run().args(["--timeout", PATIENT_MS]).output().unwrap();
    assert!(second.status.success(), "{}", text(&second.stderr));
    let err = text(&second.stderr);
    assert!(err.contains("episodes already done on the robot"), "{err}");
    let csv = std::fs::read_to_string(out.join("roam/generations.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3, "3 generations: {csv}");
    assert!(out.join("roam/best.genome").exists());
    // Every episode ran once: no seed twice in the log.
    let lines: Vec<String> = std::fs::read_to_string(&log).unwrap().lines().map(String::from).collect();
    assert!(lines.len() > before);
    let mut seeds: Vec<&str> = lines.iter().map(|l| l.split(',').next().unwrap()).collect::<Vec<_>>();
    let n = seeds.len();
    seeds.sort();
    seeds.dedup();
    assert_eq!(seeds.len(), n, "an episode was run twice");
    assert_eq!(emu.last_speed(), Some((0, 0)));
}

fn faulty_drive(name: &str, fault: &str) -> (Output, Option<(i32, i32)>) {
    let dir = scratch(name);
    let emu = Emulator::start(&dir, &["--fault", fault]);
    let genome = "1".repeat(80);
    let out = shaping()
        .arg("drive")
        .arg(file())
        .args([
            "--stage",
            "roam",
            "--period",
            "0",
            "--timeout",
            // The wait for the dropped answer; long enough that no answer of
            // a healthy emulator on a loaded machine comes later (with 300 ms,
            // one could, and the test saw a timeout, not its fault).
            "3000",
            "--actions",
            "300",
            "--genome",
            &genome,
        ])
        .arg("--port")
        .arg(&emu.port)
        .arg("--out")
        .arg(dir.join("d"))
        .output()
        .unwrap();
    (out, emu.last_speed())
}

#[test]
fn a_dropped_answer_stops_the_motors_with_a_message() {
    let (out, speed) = faulty_drive("drop", "drop@100");
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("no answer to") && err.contains("the motors were stopped"), "{err}");
    assert_eq!(speed, Some((0, 0)));
}

#[test]
fn a_garbage_answer_stops_the_motors_with_a_message() {
    let (out, speed) = faulty_drive("garbage", "garbage@100");
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("bad answer to") && err.contains("the motors were stopped"), "{err}");
    assert_eq!(speed, Some((0, 0)));
}

#[test]
fn a_closed_link_ends_with_a_message() {
    let (out, _) = faulty_drive("close", "close@100");
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    // Nothing can reach a robot whose link is gone; the message says so.
    assert!(err.contains("closed the link") && err.contains("may still be driving"), "{err}");
}

/// `drive` of the roam stage for 300 actions of 20 ms on the emulator,
/// writing into `dir/d`; its stdout and stderr both `out`'s kind.
fn spawn_drive(dir: &std::path::Path, emu: &Emulator, out: fn() -> Stdio) -> std::process::Child {
    let genome = "1".repeat(80);
    shaping()
        .arg("drive")
        .arg(file())
        .args(["--stage", "roam", "--period", "20", "--actions", "300", "--genome", &genome])
        .arg("--port")
        .arg(&emu.port)
        .arg("--out")
        .arg(dir.join("d"))
        .stdout(out())
        .stderr(out())
        .spawn()
        .unwrap()
}

/// `drive` sent `signal` (`INT`, `TERM`, `HUP`, ...) once it drives: what it
/// printed after, and the speed the robot was left with.
fn interrupted_drive(signal: &str) -> (String, Option<(i32, i32)>) {
    let dir = scratch(&format!("signal-{signal}"));
    let emu = Emulator::start(&dir, &[]);
    let mut child = spawn_drive(&dir, &emu, Stdio::piped);
    // Interrupted once it drives (its signal handlers are set by then).
    let mut err = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut first = String::new();
    std::io::BufRead::read_line(&mut err, &mut first).unwrap();
    assert!(first.contains("driving"), "{first}");
    std::thread::sleep(Duration::from_millis(200));
    let kill = Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let mut rest = String::new();
    err.read_to_string(&mut rest).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(2), "{rest}");
    assert!(dir.join("d/trace.csv").exists(), "the trace is kept: {rest}");
    (rest, emu.last_speed())
}

/// Every signal that would end the process and can be caught stops the
/// motors and keeps the trace, each named: Ctrl-C, SIGTERM, SIGHUP (a
/// closed terminal or ssh session), SIGQUIT, the limits' SIGXCPU and
/// SIGXFSZ, the user's and the timers' signals, the real-time ones (the
/// list is `src/signals.rs`; its unit test checks it against every signal).
#[test]
fn every_signal_that_would_end_drive_stops_the_motors() {
    let signals = [
        ("INT", "Ctrl-C"),
        ("TERM", "SIGTERM"),
        ("HUP", "SIGHUP"),
        ("QUIT", "SIGQUIT"),
        ("USR1", "SIGUSR1"),
        ("USR2", "SIGUSR2"),
        ("ALRM", "SIGALRM"),
        ("VTALRM", "SIGVTALRM"),
        ("PROF", "SIGPROF"),
        ("XCPU", "SIGXCPU"),
        ("XFSZ", "SIGXFSZ"),
        ("IO", "SIGIO"),
        ("PWR", "SIGPWR"),
        ("STKFLT", "SIGSTKFLT"),
        ("RTMIN", "SIGRTMIN"),
        ("RTMIN+3", "SIGRTMIN+3"),
    ];
    // Four drives at a time, each on its own emulator.
    for group in signals.chunks(4) {
        std::thread::scope(|s| {
            for &(signal, words) in group {
                s.spawn(move || {
                    let (rest, speed) = interrupted_drive(signal);
                    assert!(
                        rest.contains("interrupted") && rest.contains("the motors were stopped"),
                        "{rest}"
                    );
                    assert!(rest.contains(words), "{signal}: {rest}");
                    assert_eq!(speed, Some((0, 0)), "{signal}");
                });
            }
        });
    }
}

/// The lines of `trace` that are whole (ended by a newline).
fn whole_lines(trace: &str) -> Vec<&str> {
    trace.split_inclusive('\n').filter(|l| l.ends_with('\n')).map(|l| l.trim_end()).collect()
}

/// `drive` writes its trace as it goes: killed with SIGKILL (no handler
/// runs, nothing is written at the end), it leaves the header and a whole
/// row for every action but the last few, in order.
#[test]
fn a_drive_killed_with_sigkill_keeps_its_trace() {
    let dir = scratch("sigkill");
    let emu = Emulator::start(&dir, &[]);
    let mut child = spawn_drive(&dir, &emu, Stdio::null);
    let path = dir.join("d/trace.csv");
    // Killed once 30 actions are on disk, about 0.6 s into 6 s of driving.
    let start = Instant::now();
    let seen = loop {
        let driving = child.try_wait().unwrap().is_none();
        let rows = std::fs::read_to_string(&path).map_or(0, |t| whole_lines(&t).len().saturating_sub(1));
        assert!(driving, "drive ended before it was killed, {rows} actions on disk");
        if rows >= 30 {
            break rows;
        }
        assert!(start.elapsed() < Duration::from_secs(120), "{rows} actions on disk after 120 s");
        std::thread::sleep(Duration::from_millis(10));
    };
    child.kill().unwrap();
    child.wait().unwrap();
    let trace = std::fs::read_to_string(&path).unwrap();
    assert!(trace.ends_with('\n'), "a part of a line: {trace}");
    let lines = whole_lines(&trace);
    let header: Vec<&str> = lines[0].split(',').collect();
    assert_eq!(header[..2], ["action", "winner"]);
    let rows = &lines[1..];
    assert!(rows.len() >= seen && rows.len() < 300, "{} rows after the kill, {seen} before", rows.len());
    for (k, row) in rows.iter().enumerate() {
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells.len(), header.len(), "row {k}: {row}");
        assert_eq!(cells[0], k.to_string(), "row {k}: {row}");
    }
    assert!(!dir.join("d/summary.json").exists(), "drive ran to its end");
}

#[test]
fn a_port_in_use_is_refused() {
    let dir = scratch("busy");
    let emu = Emulator::start(&dir, &[]);
    let genome = "1".repeat(80);
    let drive_genome = |out: &str| {
        let mut c = shaping();
        c.arg("drive")
            .arg(file())
            .args(["--stage", "roam", "--period", "20", "--actions", "300", "--genome", &genome])
            .arg("--port")
            .arg(&emu.port)
            .arg("--out")
            .arg(dir.join(out));
        c
    };
    let mut first = drive_genome("first").stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut err = std::io::BufReader::new(first.stderr.take().unwrap());
    let mut line = String::new();
    std::io::BufRead::read_line(&mut err, &mut line).unwrap();
    assert!(line.contains("driving"), "{line}");
    // A second driver on the same port would interleave its commands.
    let second = drive_genome("second").output().unwrap();
    let _ = Command::new("kill").args(["-INT", &first.id().to_string()]).status();
    let _ = first.wait();
    assert_eq!(second.status.code(), Some(2), "{}", text(&second.stderr));
    assert!(text(&second.stderr).contains("is in use by another program"), "{}", text(&second.stderr));
}

#[test]
fn bad_robot_arguments_are_errors() {
    let dir = scratch("bad");
    let out = shaping()
        .arg("drive")
        .arg(file())
        .args(["--stage", "roam", "--genome", &"0".repeat(80), "--port"])
        .arg(dir.join("missing"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("cannot open the robot's port"), "{}", text(&out.stderr));
    let not_tty = dir.join("plain");
    std::fs::write(&not_tty, "x").unwrap();
    let out = shaping()
        .arg("drive")
        .arg(file())
        .args(["--stage", "roam", "--genome", &"0".repeat(80), "--port"])
        .arg(&not_tty)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("is not a serial port"), "{}", text(&out.stderr));
    let out = shaping().arg("emulate").arg("--port").arg(&not_tty).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("is not a symbolic link"), "{}", text(&out.stderr));
    let out = shaping().args(["emulate", "--fault", "melt@3", "--port"]).arg(dir.join("p")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("unknown fault"), "{}", text(&out.stderr));
}

/// `drive` binds trained weights as `replay` does (it used to refuse every
/// stage using a training stage's weights): every stage of every example is
/// driven for a few actions, its training stages trained on the fly (a
/// team's stages are refused), and with `--run` a run's training stage is
/// driven through its own life.
#[test]
fn drive_runs_every_stage_of_every_example() {
    let dir = scratch("every-stage");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let emu = Emulator::start(&dir, &[]);
    let built = dir.join("program.json");
    for example in std::fs::read_dir(root.join("examples")).unwrap() {
        let file = example.unwrap().path();
        if file.extension().is_none_or(|e| e != "bat") {
            continue;
        }
        let out = shaping().arg("build").arg(&file).arg("-o").arg(&built).output().unwrap();
        assert!(out.status.success(), "{}", text(&out.stderr));
        let program: serde_json::Value = serde_json::from_slice(&std::fs::read(&built).unwrap()).unwrap();
        for stage in program["stages"].as_array().unwrap() {
            let name = stage["name"].as_str().unwrap();
            let bits = stage["layout"]["bits"].as_u64().unwrap() as usize;
            let physical = stage["world"]["objects"].as_object().is_some_and(|o| o["virtual_"] == false);
            // A team (`robots N`, left out of the program while 1) is refused.
            let team = stage["world"]["robots"].as_u64().is_some_and(|n| n > 1);
            // In an empty directory: no `runs/` of an earlier run is used.
            let out = shaping()
                .current_dir(&dir)
                .arg("drive")
                .arg(&file)
                .args(["--stage", name, "--actions", "3", "--period", "0", "--timeout", PATIENT_MS])
                .args(["--genome", &"0".repeat(bits)])
                .arg("--port")
                .arg(&emu.port)
                .arg("--out")
                .arg(dir.join("d"))
                .output()
                .unwrap();
            let err = text(&out.stderr);
            if team {
                assert!(!out.status.success(), "{} {name}: a team was driven", file.display());
                assert!(err.contains("one robot on one serial port"), "{} {name}: {err}", file.display());
            } else if physical {
                assert!(err.contains("the objects must be `virtual`"), "{} {name}: {err}", file.display());
            } else {
                assert!(out.status.success(), "{} {name}: {err}", file.display());
            }
        }
    }
}

/// The robot's episode log is tied to the stage like a checkpoint: episodes
/// of another version are not reused (the run refuses), and `--fresh` moves
/// the log aside and starts again.
#[test]
fn robot_episodes_of_another_version_of_the_stage_are_not_reused() {
    let dir = scratch("stale-log");
    let emu = Emulator::start(&dir, &[]);
    let out = dir.join("runs");
    std::fs::create_dir_all(out.join("roam")).unwrap();
    let log = out.join("roam/robot-episodes.jsonl");
    std::fs::write(&log, "{\"seed\":1,\"fitness\":0.5,\"learned\":null,\"pose\":[0,0,0]}\n").unwrap();
    let run = |extra: &[&str]| {
        shaping()
            .arg("run")
            .arg(file())
            .args(["--stage", "roam", "--quiet", "--period", "0", "--timeout", PATIENT_MS, "--robot"])
            .arg(&emu.port)
            .arg("--out")
            .arg(&out)
            .args(extra)
            .output()
            .unwrap()
    };
    let stale = run(&[]);
    assert_eq!(stale.status.code(), Some(2));
    let err = text(&stale.stderr);
    assert!(err.contains("line 1 of") && err.contains("another version of stage `roam`"), "{err}");
    let fresh = run(&["--fresh"]);
    assert!(fresh.status.success(), "{}", text(&fresh.stderr));
    assert!(out.join("roam/robot-episodes.jsonl.old").exists());
    let lines = std::fs::read_to_string(&log).unwrap();
    assert!(lines.lines().all(|l| l.contains("\"program\":")), "{lines}");
}
