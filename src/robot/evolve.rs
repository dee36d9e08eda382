//! `shaping run FILE --robot DEV`: the individuals of a generation are
//! evaluated one after another on the robot, each episode written to
//! `<stage>/robot-episodes.jsonl` as soon as it ends, so a crash or a lost
//! link loses at most the individual being evaluated: on resume, the
//! episodes already in the file are not run again.

use std::collections::HashMap;
use std::fs::OpenOptions;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use serde::{Deserialize, Serialize};
use shaping_engine::run::Evaluate;
use shaping_engine::ErrorKind;
use shaping_runtime::controller::{episode_rngs, Controller, EpisodeOptions};
use shaping_runtime::evolve::{Evaluation, Events};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Inheritance, Program, Stage};
use shaping_runtime::robot::SerialRobot;
use shaping_runtime::sim::Pose;

use super::drive::{check_robot_world, failure, has_gripper, period};
use super::port::{interrupt_flag, SerialPort};
use crate::load;
use crate::CliError;

/// One episode done on the robot, as a line of `robot-episodes.jsonl`.
#[derive(Serialize, Deserialize)]
struct Episode {
    seed: u64,
    fitness: f32,
    learned: Option<String>,
    /// The robot's pose at the end of the episode (odometry).
    pose: [f32; 3],
    /// Grips, releases outside and recharges (logs written before these
    /// were recorded read as none).
    #[serde(default)]
    events: Events,
    /// [`shaping_runtime::evolve::fingerprint::digest`] of the stage the episode was run for (none in
    /// logs written before it was recorded: those are not reused).
    #[serde(default)]
    program: Option<u64>,
    /// Placements of the virtual objects that kept an overlapping try (a
    /// too crowded world); left out while 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    placement_failures: u32,
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

struct State {
    port: Option<SerialPort>,
    /// Where the robot is (odometry), carried from episode to episode.
    pose: Option<Pose>,
    done: HashMap<u64, Evaluation>,
    log: Option<PathBuf>,
    error: Option<String>,
    /// The digest of the stage being evaluated, written with each episode.
    program: u64,
}

/// The robot of a `run --robot`, shared by the stages of the run.
pub struct RobotRun {
    pub device: PathBuf,
    pub baud: u32,
    pub period_ms: Option<u64>,
    pub timeout_ms: u64,
    flag: Arc<AtomicBool>,
    state: Mutex<State>,
}

impl RobotRun {
    pub fn new(
        device: PathBuf,
        baud: u32,
        period_ms: Option<u64>,
        timeout_ms: u64,
    ) -> Result<RobotRun, CliError> {
        Ok(RobotRun {
            device,
            baud,
            period_ms,
            timeout_ms,
            flag: interrupt_flag()?,
            state: Mutex::new(State {
                port: None,
                pose: None,
                done: HashMap::new(),
                log: None,
                error: None,
                program: 0,
            }),
        })
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// The individuals of an evolved stage evaluated on the robot, one after
/// another in the order of the generation (the robot's pose carries from
/// episode to episode). After a failure every evaluation gives NaN, so the
/// generation fails and its checkpoint is not written; `failure` says why.
impl Evaluate for RobotRun {
    /// Opens the stage's episode log in `dir`: episodes already in it are
    /// taken from there, if they were run for the stage as it is (`program`,
    /// the digest of its fingerprint; else the run is refused). With
    /// `fresh`, an existing log is moved aside to `robot-episodes.jsonl.old`
    /// and not used.
    fn begin_stage(
        &self,
        programs: &Program,
        index: usize,
        dir: &Path,
        program: u64,
        fresh: bool,
    ) -> Result<(), CliError> {
        let stage = &programs.stages[index];
        check_robot_world(stage)?;
        let log = dir.join("robot-episodes.jsonl");
        if fresh && log.exists() {
            let old = dir.join("robot-episodes.jsonl.old");
            std::fs::rename(&log, &old).map_err(|e| {
                let message = format!("error: cannot move `{}` aside: {e}", log.display());
                let subject =
                    shaping_engine::Subject::File { path: log.clone(), operation: "move aside".into() };
                CliError::new(ErrorKind::Io, message).about(subject)
            })?;
            eprintln!("stage {}: starting again; the earlier episodes are in {}", stage.name, old.display());
        }
        {
            let mut st = self.lock();
            st.done.clear();
            st.program = program;
            if log.exists() {
                let bytes = load::read_bytes(&log)?;
                // A torn last line (a crash while writing) is skipped.
                for (n, line) in bytes.split(|&b| b == b'\n').enumerate() {
                    if let Ok(e) = serde_json::from_slice::<Episode>(line) {
                        if e.program != Some(program) {
                            return Err(CliError::stale(
                                &log,
                                format!("line {} is an episode of another version of stage `{}`", n + 1, stage.name),
                                format!(
                                    "error: line {} of `{}` is an episode of another version of stage `{}`; pass `--fresh` to start again (the log is kept as `robot-episodes.jsonl.old`), or choose another `--out`",
                                    n + 1,
                                    log.display(),
                                    stage.name
                                ),
                            ));
                        }
                        let learned = e.learned.as_deref().and_then(Genome::from_bitstring);
                        st.done.insert(
                            e.seed,
                            Evaluation {
                                fitness: e.fitness,
                                learned,
                                events: e.events,
                                placement_failures: e.placement_failures,
                            },
                        );
                        st.pose = Some(Pose { x: e.pose[0], y: e.pose[1], theta: e.pose[2] });
                    }
                }
                if !st.done.is_empty() {
                    eprintln!(
                        "stage {}: {} episodes already done on the robot, from {}",
                        stage.name,
                        st.done.len(),
                        log.display()
                    );
                }
            }
            st.log = Some(log);
        }
        Ok(())
    }

    fn evaluate(
        &self,
        program: &Program,
        index: usize,
        actions: u32,
        jobs: &[(&Genome, shaping_runtime::evolve::Episode)],
    ) -> Vec<Evaluation> {
        // The robot lives in the room it is in: a variant's world is not
        // made, only its episode's seed is used.
        let stage = &program.stages[index];
        jobs.iter().map(|&(genome, e)| self.evaluate_one(stage, actions, genome, e.seed)).collect()
    }

    fn failure(&self) -> Option<CliError> {
        self.lock().error.clone().map(|e| CliError::new(ErrorKind::Evaluation, e))
    }
}

impl RobotRun {
    fn evaluate_one(&self, stage: &Stage, actions: u32, genome: &Genome, seed: u64) -> Evaluation {
        let nan = Evaluation::not_run();
        let mut st = self.lock();
        if st.error.is_some() {
            return nan;
        }
        if let Some(e) = st.done.get(&seed) {
            return e.clone();
        }
        let port = match st.port.take() {
            Some(p) => p,
            None => {
                let opened = SerialPort::open(
                    &self.device,
                    self.baud,
                    Duration::from_millis(self.timeout_ms),
                    period(stage, self.period_ms),
                    Arc::clone(&self.flag),
                );
                match opened {
                    Ok(p) => p,
                    Err(e) => {
                        st.error = Some(e.to_string());
                        return nan;
                    }
                }
            }
        };
        let (sim_seed, rng) = episode_rngs(seed);
        let Ok(mut ctl) = Controller::new(stage, genome, rng) else {
            st.error = Some(format!("error: a genome does not fit stage `{}`", stage.name));
            return nan;
        };
        let mut robot = SerialRobot::new(&stage.world, sim_seed, st.pose, has_gripper(stage), port);
        let result = robot
            .connect()
            .ok()
            .map(|()| ctl.run(&mut robot, &EpisodeOptions { actions, learning: true, seed }, None));
        let stopped = robot.stop();
        let pose = robot.host().pose();
        if let Some(err) = robot.error().cloned() {
            st.error = Some(format!(
                "{} (the individual being evaluated is lost; run the same command again to resume)",
                failure(&err, &stopped)
            ));
            return nan;
        }
        st.port = Some(robot.into_link());
        let Some(r) = result else { return nan };
        let learned = (stage.inheritance == Inheritance::Lamarckian).then(|| ctl.write_back(genome));
        let ev = Evaluation { learned, ..Evaluation::of_episode(r) };
        let line = Episode {
            seed,
            fitness: ev.fitness,
            learned: ev.learned.as_ref().map(Genome::to_bitstring),
            pose: [pose.x, pose.y, pose.theta],
            events: ev.events,
            program: Some(st.program),
            placement_failures: ev.placement_failures,
        };
        if let Some(log) = st.log.clone() {
            if let Err(e) = append_line(&log, &line) {
                st.error = Some(format!("error: cannot write `{}`: {e}", log.display()));
                return nan;
            }
        }
        st.pose = Some(pose);
        st.done.insert(seed, ev.clone());
        ev
    }
}

/// Appends one JSON line and makes it durable before the next episode.
fn append_line(path: &Path, episode: &Episode) -> std::io::Result<()> {
    let mut text = serde_json::to_string(episode).map_err(std::io::Error::other)?;
    text.push('\n');
    let mut f = OpenOptions::new().create(true).append(true).open(path)?;
    f.write_all(text.as_bytes())?;
    f.sync_data()
}
