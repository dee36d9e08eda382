//! `mpirun -n N shaping run` against a single process (built with `--features
//! mpi`, with Open MPI's `mpirun` on the path): the same files byte for byte,
//! and a rank that dies or hangs ends the run with a message from rank 0 and
//! a checkpoint that any number of ranks resumes to the same result.
#![cfg(feature = "mpi")]

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("shaping-mpi-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn single() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shaping"))
}

/// `mpirun -n N shaping`; CI runs as root, which Open MPI refuses unless told.
fn mpirun(n: usize) -> Command {
    let mut c = Command::new("mpirun");
    c.args(["-n", &n.to_string(), "--oversubscribe"])
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .arg(env!("CARGO_BIN_EXE_shaping"));
    c
}

fn ok(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("the command starts");
    assert!(
        out.status.success(),
        "{cmd:?} failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Every file the comparison covers, relative to `dir`, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                if ["generations.csv", "best.genome", "checkpoint.json", "summary.md", "summary.json"]
                    .contains(&name.as_str())
                {
                    out.push(p.strip_prefix(dir).unwrap().to_path_buf());
                }
            }
        }
    }
    out.sort();
    out
}

fn assert_same_files(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    assert!(fa.len() >= 4, "too few files in {}: {fa:?}", a.display());
    assert_eq!(fa, fb, "{} and {} hold different files", a.display(), b.display());
    for f in &fa {
        let (x, y) = (std::fs::read(a.join(f)).unwrap(), std::fs::read(b.join(f)).unwrap());
        assert!(x == y, "{} differs between {} and {}", f.display(), a.display(), b.display());
    }
}

#[test]
fn any_number_of_ranks_writes_the_single_process_files() {
    let dir = scratch("ranks");
    let tiny = root().join("tests/cli/tiny.bat");
    let one = dir.join("one");
    ok(single().arg("run").arg(&tiny).arg("--out").arg(&one).arg("--quiet"));
    for n in [1, 2, 3, 5] {
        let out = dir.join(format!("n{n}"));
        let done = ok(mpirun(n).arg("run").arg(&tiny).arg("--out").arg(&out));
        let err = String::from_utf8_lossy(&done.stderr);
        assert!(err.contains(&format!("mpi: {n} ranks")), "no MPI summary from rank 0:\n{err}");
        assert_same_files(&one, &out);
    }
}

/// A team shaped stage by stage (roles that grow, a role added later, a
/// role's own fitness, robots changed by the file): on 3 ranks, the single
/// process's files.
#[test]
fn a_shaped_team_on_three_ranks_writes_the_single_process_files() {
    let dir = scratch("shaped-roles");
    let file = root().join("tests/lower/roles_shaped.bat");
    let one = dir.join("one");
    ok(single().arg("run").arg(&file).arg("--out").arg(&one).arg("--quiet"));
    let three = dir.join("three");
    ok(mpirun(3).arg("run").arg(&file).arg("--out").arg(&three));
    assert_same_files(&one, &three);
}

/// `shaping experiment tiny.bat --seeds 2 EXTRA... --out OUT`, on one process
/// and on 3 ranks: the files must be the same; returns rank 0's stderr and
/// the directory of the 3 ranks.
fn experiment_on_three_ranks(name: &str, extra: &[&str]) -> (String, PathBuf) {
    let dir = scratch(name);
    let tiny = root().join("tests/cli/tiny.bat");
    let run = |mut cmd: Command, out: &Path| {
        ok(cmd.arg("experiment").arg(&tiny).args(["--seeds", "2"]).args(extra).arg("--out").arg(out))
    };
    let one = dir.join("one");
    run(single(), &one);
    let three = dir.join("three");
    let done = run(mpirun(3), &three);
    assert_same_files(&one, &three);
    (String::from_utf8_lossy(&done.stderr).into_owned(), three)
}

/// 2 seeds on 3 ranks: fewer tasks than ranks, so each generation's
/// episodes go out in batches.
#[test]
fn experiment_on_three_ranks_matches_one_process() {
    let (err, three) = experiment_on_three_ranks("experiment", &[]);
    assert!(err.contains("mpi: 3 ranks") && err.contains("rounds"), "no batch summary:\n{err}");
    assert!(three.join("summary.md").exists() && three.join("seed-2/second/best.genome").exists());
}

/// A sweep of 2 points over 2 seeds on 3 ranks: 4 tasks, so whole seeds go to
/// ranks; every file is the single process's, byte for byte.
#[test]
fn a_sweep_on_three_ranks_hands_out_whole_seeds_and_matches_one_process() {
    let (err, three) =
        experiment_on_three_ranks("sweep", &["--set", "first.evolve.mutation=0.01,0.2", "--no-report"]);
    assert!(err.contains("mpi: 3 ranks") && err.contains("4 tasks (whole seeds)"), "no task summary:\n{err}");
    assert!(
        err.contains("done on rank 1") || err.contains("done on rank 2"),
        "no task ran on another rank:\n{err}"
    );
    assert!(three.join("summary.json").exists());
    assert!(three.join("first.evolve.mutation=0.2/seed-2/second/best.genome").exists());
}

/// The pid of rank `rank` among the children of `mpirun`.
fn rank_pid(mpirun: u32, rank: usize) -> Option<u32> {
    let want = format!("OMPI_COMM_WORLD_RANK={rank}");
    for e in std::fs::read_dir("/proc").ok()? {
        let Ok(pid) = e.ok()?.file_name().to_string_lossy().parse::<u32>() else { continue };
        let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else { continue };
        let ppid = stat.rsplit_once(')').and_then(|(_, r)| r.split_whitespace().nth(1)?.parse::<u32>().ok());
        if ppid != Some(mpirun) {
            continue;
        }
        let env = std::fs::read(format!("/proc/{pid}/environ")).unwrap_or_default();
        if env.split(|&b| b == 0).any(|v| v == want.as_bytes()) {
            return Some(pid);
        }
    }
    None
}

/// Starts `mpirun -n 3` on the long run with `--rank-timeout timeout`,
/// waits for `generations` JSON lines, sends `signal` to rank `rank` and
/// returns rank 0's stderr and the exit status.
///
/// The timeout must be long enough for a healthy rank's batch on a loaded
/// machine (25 episodes of 1000 actions, a fraction of a second unloaded):
/// with 3 s, a CI machine busy with other builds could time out a healthy
/// rank before the disturbed one, and the message named the wrong rank.
fn disturb(out: &Path, rank: usize, signal: &str, generations: usize, timeout: u64) -> (String, u32, bool) {
    let long = root().join("tests/mpi/long.bat");
    let mut child: Child = mpirun(3)
        .arg("run")
        .arg(&long)
        .arg("--out")
        .arg(out)
        .args(["--json", "--rank-timeout", &timeout.to_string()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    for _ in 0..generations {
        lines.next().expect("a generation line").unwrap();
    }
    let pid = rank_pid(child.id(), rank).expect("the rank's process");
    assert!(Command::new("kill").args([signal, &pid.to_string()]).status().unwrap().success());
    let started = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if started.elapsed() > Duration::from_secs(timeout + 120) {
            let _ = child.kill();
            panic!("mpirun still runs {} s after rank {rank} got {signal}", timeout + 120);
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    for _ in lines {}
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    (err, pid, status.success())
}

fn straight(dir: &Path) -> PathBuf {
    let one = dir.join("one");
    ok(single().arg("run").arg(root().join("tests/mpi/long.bat")).arg("--out").arg(&one).arg("--quiet"));
    one
}

#[test]
fn a_dead_rank_is_named_and_the_checkpoint_resumes_on_other_ranks() {
    let dir = scratch("dead");
    let out = dir.join("mpi");
    // A death is seen at once (mpirun ends the other ranks): no timeout needed.
    let (err, pid, success) = disturb(&out, 2, "-KILL", 3, 600);
    assert!(!success, "the run succeeded with a dead rank:\n{err}");
    // Under load mpirun may take another rank down before rank 0 notices the
    // dead one: the message then names both ("error: rank 1 (...), rank 2
    // (...) died"), and must name the killed one.
    let named = err.lines().find(|l| l.starts_with("error: rank ")).unwrap_or_default();
    assert!(named.contains(&format!("rank 2 (pid {pid} on ")), "rank 0 did not name the rank:\n{err}");
    assert!(named.contains("died during generation"), "no generation in the message:\n{err}");
    assert!(err.contains("checkpoint.json` is valid"), "no word on the checkpoint:\n{err}");
    ok(mpirun(2).arg("run").arg(root().join("tests/mpi/long.bat")).arg("--out").arg(&out).arg("--quiet"));
    assert_same_files(&straight(&dir), &out);
}

/// The `--rank-timeout` of the hung-rank test: the time the test waits for
/// the stopped rank to be named, and far longer than a healthy batch takes.
const HUNG_TIMEOUT: u64 = 20;

#[test]
fn a_hung_rank_times_out_and_the_checkpoint_resumes_on_one_process() {
    let dir = scratch("hung");
    let out = dir.join("mpi");
    let (err, pid, success) = disturb(&out, 1, "-STOP", 2, HUNG_TIMEOUT);
    assert!(!success, "the run succeeded with a stopped rank:\n{err}");
    assert!(err.contains(&format!("error: rank 1 (pid {pid} on ")), "rank 0 did not name the rank:\n{err}");
    assert!(err.contains(&format!("within {HUNG_TIMEOUT} s during ")), "no timeout in the message:\n{err}");
    assert!(
        err.contains("generation") || err.contains("the best of stage"),
        "no generation in the message:\n{err}"
    );
    let _ = Command::new("kill").args(["-KILL", &pid.to_string()]).status();
    ok(single().arg("run").arg(root().join("tests/mpi/long.bat")).arg("--out").arg(&out).arg("--quiet"));
    assert_same_files(&straight(&dir), &out);
}
