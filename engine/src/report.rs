//! Turning runtime results into files: CSV tables and pictures.

use std::fmt::Write as _;
use std::fs::File;
use std::io::Write as _;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use shaping_runtime::catalog::{ActuatorKind, SensorKind, CH_IR, CH_LIGHT, CH_RAB};
use shaping_runtime::controller::{Trace, TraceRow};
use shaping_runtime::evolve::GenStats;
use shaping_runtime::program::{LearnTarget, Stage};
use shaping_runtime::sim::{ObjectState, Scene};

use crate::episode::{BoardColumns, Episode, EpisodeColumns, Frame, OtherRobot, TeamColumns};
use crate::error::Error;
use crate::plot;
use crate::rundir::{self, Picture};

/// The names of a stage's variants (none without variants).
pub fn variant_names(stage: &shaping_runtime::program::Stage) -> Vec<String> {
    stage.variants.as_ref().map_or_else(Vec::new, |v| v.list.iter().map(|x| x.name.clone()).collect())
}

/// Points for the fitness pictures, and where each stage starts.
pub fn fitness_points(history: &[GenStats]) -> (Vec<plot::GenPoint>, Vec<(u32, String)>) {
    let points = history
        .iter()
        .map(|h| plot::GenPoint { generation: h.generation, best: h.best, mean: h.mean })
        .collect();
    let mut starts: Vec<(u32, String)> = Vec::new();
    for h in history {
        if starts.last().is_none_or(|(_, name)| *name != h.stage) {
            starts.push((h.generation, h.stage.clone()));
        }
    }
    (points, starts)
}

/// Draws `fitness.{svg,png}` into `dir`.
pub fn fitness_plot(dir: &Path, title: &str, history: &[GenStats]) -> Result<(), Error> {
    if history.is_empty() {
        return Ok(());
    }
    let (points, starts) = fitness_points(history);
    plot::fitness_curves(&rundir::picture_path(dir, Picture::Fitness), title, &points, &starts, false)
        .map_err(Error::from)
}

/// Where the value of one declared sensor or actuator element comes from in
/// a recorded episode.
#[derive(Clone, Copy)]
enum Source {
    Ir(usize),
    Light(usize),
    Battery,
    Barrier,
    Floor,
    LampDistance,
    Wheel(usize),
    Arm,
    Claw,
    /// Channel `i` of the range-and-bearing board (from `CH_RAB`: its
    /// sectors, then the signals heard).
    Board(usize),
    /// Broadcast value `k`.
    Signal(usize),
}

impl Source {
    /// The value at action `k` (`NaN` where the episode has none).
    fn at(self, c: &EpisodeColumns, k: usize) -> f32 {
        let channel = |v: &[[f32; 8]], i: usize| v.get(k).and_then(|r| r.get(i)).copied();
        let flag = |v: &[u8]| v.get(k).map(|&b| f32::from(b));
        match self {
            Source::Ir(i) => channel(&c.ir, i),
            Source::Light(i) => channel(&c.light, i),
            Source::Battery => c.battery.get(k).copied(),
            Source::Barrier => flag(&c.barrier),
            Source::Floor => c.floor.get(k).copied(),
            Source::LampDistance => c.lamp_distance.get(k).copied(),
            Source::Wheel(i) => c.wheels.get(k).map(|w| w[i.min(1)]),
            Source::Arm => flag(&c.arm_down),
            Source::Claw => flag(&c.claw_closed),
            Source::Board(i) => c.board.get(k).and_then(|b| b.read.get(i)).copied(),
            Source::Signal(i) => c.board.get(k).and_then(|b| b.signal.get(i)).copied(),
        }
        .unwrap_or(f32::NAN)
    }
}

/// The columns of the robot's declared sensors and actuators, one per
/// element, named `NAME[i]` after the declaration (also a single-valued one:
/// `battery[0]`, so no name can be one of the fixed columns).
fn declared_columns(stage: &Stage) -> Vec<(String, Source)> {
    let mut out = Vec::new();
    for s in &stage.sensors {
        for i in 0..s.count as usize {
            let ch = s.channel as usize + i;
            let source = match s.kind {
                SensorKind::Proximity => Source::Ir(ch.saturating_sub(CH_IR)),
                SensorKind::Ambient => Source::Light(ch.saturating_sub(CH_LIGHT)),
                SensorKind::Level => Source::Battery,
                SensorKind::Optical => Source::Barrier,
                SensorKind::Ground => Source::Floor,
                SensorKind::LampDistance => Source::LampDistance,
                SensorKind::RangeBearing | SensorKind::Signal => Source::Board(ch.saturating_sub(CH_RAB)),
            };
            out.push((format!("{}[{i}]", s.name), source));
        }
    }
    let signals = stage.world.body.rab.as_ref().map_or(1, |r| usize::from(r.signals));
    let broadcast: Vec<Source> = (0..signals).map(Source::Signal).collect();
    for a in &stage.actuators {
        let sources: &[Source] = match a.kind {
            ActuatorKind::Speed => &[Source::Wheel(0), Source::Wheel(1)],
            ActuatorKind::Lift => &[Source::Arm],
            ActuatorKind::Grip => &[Source::Claw],
            ActuatorKind::Broadcast => &broadcast,
        };
        out.extend(sources.iter().enumerate().map(|(i, &src)| (format!("{}[{i}]", a.name), src)));
    }
    out
}

/// `trace.csv`: one row per action: what the controller did (the winner,
/// activations, reinforcements, performance indicators), where the robot
/// went, and, named after the robot's declarations, what each sensor read
/// after the action and what each actuator was set to (from the recorded
/// `episode`, `NaN` where it has no value).
pub fn trace_csv(trace: &Trace, stage: &Stage, episode: &Episode) -> String {
    team_trace_csv(trace, &[], stage, episode)
}

/// `trace.csv` of a team: [`trace_csv`]'s columns after a first column
/// `robot` (0 for robot 0, whose rows are `trace`'s, then the `others`'),
/// the rows in the order of the actions, each action's robots in order.
/// Without others, the one robot's file, which has no `robot` column.
pub fn team_trace_csv(trace: &Trace, others: &[OtherRobot], stage: &Stage, episode: &Episode) -> String {
    let declared = declared_columns(stage);
    if others.is_empty() {
        let mut s = trace_header(&trace.modules, &declared);
        for (k, r) in trace.rows.iter().enumerate() {
            trace_row(&mut s, &trace.modules, &declared, r, &episode.actions, k);
        }
        return s;
    }
    // With roles, a column per module of every role (`ROLE.MODULE`), empty
    // in the rows of the other roles' robots.
    let modules: Vec<String> = if stage.roles.is_empty() {
        trace.modules.clone()
    } else {
        (0..stage.modules.len()).map(|i| stage.module_label(i)).collect()
    };
    let mut s = trace_header(&modules, &declared);
    s.insert_str(0, "robot,");
    // (action, robot, row, its sensed columns, the row's index in them)
    let mut rows: Vec<(u32, usize, &TraceRow, &EpisodeColumns, usize)> =
        trace.rows.iter().enumerate().map(|(k, r)| (r.action, 0, r, &episode.actions, k)).collect();
    for o in others {
        rows.extend(o.trace.rows.iter().enumerate().map(|(k, r)| (r.action, o.robot, r, &o.sensed, k)));
    }
    rows.sort_by_key(|&(action, robot, ..)| (action, robot));
    for (_, robot, r, columns, k) in rows {
        let _ = write!(s, "{robot},");
        if stage.roles.is_empty() {
            trace_row(&mut s, &modules, &declared, r, columns, k);
        } else {
            trace_row(&mut s, &modules, &declared, &in_all_modules(stage, robot, r), columns, k);
        }
    }
    s
}

/// The range-and-bearing board of a team's episode (robot 0's columns
/// `episode`, the `others`): every robot's values of `trace.csv`'s board
/// columns at every action; `None` when the stage declares no board.
pub fn board_columns(stage: &Stage, episode: &Episode, others: &[OtherRobot]) -> Option<BoardColumns> {
    let (names, sources): (Vec<String>, Vec<Source>) = declared_columns(stage)
        .into_iter()
        .filter(|(_, src)| matches!(src, Source::Board(_) | Source::Signal(_)))
        .unzip();
    if names.is_empty() {
        return None;
    }
    let n = episode.actions.x.len();
    let values = |c: &EpisodeColumns, k: usize| -> Vec<f32> {
        if c.board.get(k).is_none() {
            return Vec::new();
        }
        sources.iter().map(|s| s.at(c, k)).collect()
    };
    let most = others.iter().map(|o| o.robot).max().unwrap_or(0);
    let mut robots = vec![vec![Vec::new(); n]; most + 1];
    robots[0] = (0..n).map(|a| values(&episode.actions, a)).collect();
    for o in others {
        for (k, r) in o.trace.rows.iter().enumerate() {
            if let Some(slot) = robots[o.robot].get_mut(r.action as usize) {
                *slot = values(&o.sensed, k);
            }
        }
    }
    Some(BoardColumns { names, robots })
}

/// Row `r` of `robot`'s role, its winner and per-module values placed
/// among all the stage's modules (`NaN`, written empty, for the others').
fn in_all_modules(stage: &Stage, robot: usize, r: &TraceRow) -> TraceRow {
    let own = stage.role_modules(stage.role_of(robot));
    let widen = |v: &[f32]| {
        let mut all = vec![f32::NAN; stage.modules.len()];
        for (k, x) in v.iter().enumerate().take(own.len()) {
            all[own.start + k] = *x;
        }
        all
    };
    TraceRow {
        winner: r.winner + own.start as u16,
        activations: widen(&r.activations),
        reinforcement: widen(&r.reinforcement),
        performance: widen(&r.performance),
        ..r.clone()
    }
}

/// The first line of `trace.csv`.
fn trace_header(modules: &[String], declared: &[(String, Source)]) -> String {
    let mut s =
        String::from("action,winner,battery,holding,grips,releases_outside,recharged,collided,x,y,theta");
    for m in modules {
        let _ = write!(s, ",act_{m}");
    }
    for m in modules {
        let _ = write!(s, ",reinf_{m}");
    }
    for m in modules {
        let _ = write!(s, ",perf_{m}");
    }
    for (name, _) in declared {
        let _ = write!(s, ",{name}");
    }
    s.push('\n');
    s
}

/// Appends the line of trace row `r` to `s`, the declared sensors and
/// actuators read from `columns` at action `k`.
fn trace_row(
    s: &mut String,
    modules: &[String],
    declared: &[(String, Source)],
    r: &TraceRow,
    columns: &EpisodeColumns,
    k: usize,
) {
    let winner = modules.get(r.winner as usize).map_or("", |m| m.as_str());
    let _ = write!(
        s,
        "{},{},{:.4},{},{},{},{},{},{:.2},{:.2},{:.4}",
        r.action,
        winner,
        r.battery,
        r.holding as u8,
        r.grips,
        r.releases_outside,
        r.recharged as u8,
        r.collided as u8,
        r.pose.x,
        r.pose.y,
        r.pose.theta
    );
    for v in r.activations.iter().chain(&r.reinforcement).chain(&r.performance) {
        if v.is_nan() {
            s.push(',');
        } else {
            let _ = write!(s, ",{v:.4}");
        }
    }
    for (_, source) in declared {
        let _ = write!(s, ",{:.4}", source.at(columns, k));
    }
    s.push('\n');
}

/// The longest a row of [`TraceWriter`] waits in memory before it is
/// written: a process killed loses the actions of the last 0.1 s.
pub const TRACE_WRITE_EVERY: Duration = Duration::from_millis(100);

/// `trace.csv` written as an episode goes (`drive`: a robot's episode
/// lasts minutes, and a process killed with SIGKILL loses only its last
/// actions): the header at once, then the rows, written in whole lines
/// at least every [`TRACE_WRITE_EVERY`]. The file is the one [`trace_csv`]
/// writes at the end, byte for byte; unlike the other files of the engine,
/// it is written in place, in parts, so that a part is there to keep.
pub struct TraceWriter {
    path: PathBuf,
    /// `None` once a write failed.
    file: Option<File>,
    modules: Vec<String>,
    declared: Vec<(String, Source)>,
    /// Whole lines not written yet.
    pending: String,
    written: Instant,
    /// The first failure to write.
    error: Option<Error>,
}

impl TraceWriter {
    /// Creates `path` (emptied if it exists) and writes the header of the
    /// trace of `stage`.
    pub fn create(path: &Path, stage: &Stage) -> Result<TraceWriter, Error> {
        let file = File::create(path).map_err(|e| Error::of_io("write", path, &e))?;
        let modules: Vec<String> = stage.modules.iter().map(|m| m.name.clone()).collect();
        let declared = declared_columns(stage);
        let pending = trace_header(&modules, &declared);
        let mut w = TraceWriter {
            path: path.to_path_buf(),
            file: Some(file),
            modules,
            declared,
            pending,
            written: Instant::now(),
            error: None,
        };
        w.write_pending();
        match w.error.take() {
            Some(e) => Err(e),
            None => Ok(w),
        }
    }

    /// Adds the row of one action: what the controller did (`row`) and what
    /// the robot sensed after it (`frame`, the recorder's last; `None`: the
    /// declared sensors' values are `NaN`). A failure to write is kept for
    /// [`TraceWriter::finish`]: the episode goes on.
    pub fn push(&mut self, row: &TraceRow, frame: Option<&Frame>) {
        let mut one = EpisodeColumns::new(self.modules.len());
        one.push_row(row);
        if let Some(f) = frame {
            one.push_frame(f);
        }
        trace_row(&mut self.pending, &self.modules, &self.declared, row, &one, 0);
        if self.written.elapsed() >= TRACE_WRITE_EVERY {
            self.write_pending();
        }
    }

    fn write_pending(&mut self) {
        self.written = Instant::now();
        let Some(file) = self.file.as_mut() else { return };
        if self.pending.is_empty() {
            return;
        }
        // One write of whole lines.
        match file.write_all(self.pending.as_bytes()) {
            Ok(()) => self.pending.clear(),
            Err(e) => {
                self.error = Some(Error::of_io("write", &self.path, &e));
                self.file = None;
            }
        }
    }

    /// Writes the rows still in memory and syncs the file; the first
    /// failure to write, if there was one.
    pub fn finish(mut self) -> Result<(), Error> {
        self.write_pending();
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        match &self.file {
            Some(file) => file.sync_all().map_err(|e| Error::of_io("write", &self.path, &e)),
            None => Ok(()),
        }
    }
}

/// What was recorded of an episode, for its pictures: robot 0's trace, the
/// team's other robots (none for one robot) and the world's scene.
#[derive(Clone, Copy)]
pub struct Lived<'a> {
    pub trace: &'a Trace,
    pub others: &'a [OtherRobot],
    pub scene: &'a Scene,
}

/// How an episode's pictures are drawn: their title, marks on their time
/// axis (an action and its label), and `path`: the rows the trajectory
/// picture draws, and what they are (for its title), when it is not the
/// whole trace: a test stage draws its first life in the changed world,
/// over that life's scene (rows out of range or none: the whole trace).
#[derive(Clone, Default)]
pub struct Drawing<'a> {
    pub title: &'a str,
    pub marks: &'a [(u32, String)],
    pub path: Option<(Range<usize>, &'a str)>,
}

impl<'a> Drawing<'a> {
    /// The whole episode, titled `title`, without marks.
    pub fn titled(title: &'a str) -> Drawing<'a> {
        Drawing { title, ..Drawing::default() }
    }
}

/// Writes `trace.csv` and the pictures of one episode into `dir`:
/// `activations` (figure 11), `reinforcement` (figures 5, 10, 13) for every
/// learning module, and `trajectory`.
pub fn episode_files(
    dir: &Path,
    stage: &Stage,
    lived: Lived<'_>,
    episode: &Episode,
    drawing: &Drawing<'_>,
) -> Result<(), Error> {
    episode_files_until(dir, stage, lived, episode, drawing, &|| false)
}

/// Writes a team's `robots.json` beside its `episode` (of the team's
/// `others`), or, for one robot, removes any earlier team's.
pub fn team_columns(
    dir: &Path,
    stage: &Stage,
    others: &[OtherRobot],
    episode: &Episode,
) -> Result<(), Error> {
    match TeamColumns::of(stage, others, episode.actions.x.len(), 0) {
        Some(mut team) => {
            team.board = board_columns(stage, episode, others);
            rundir::write_robots(dir, &team)
        }
        None => rundir::remove_robots(dir),
    }
}

/// The error [`episode_files_until`] stops with when `stop` says so.
pub const STOPPED: &str = "stopped";

/// [`episode_files`], stopping between files once `stop()` is true (with the
/// error [`STOPPED`]): Ctrl-C during a long test stage's files.
pub fn episode_files_until(
    dir: &Path,
    stage: &Stage,
    lived: Lived<'_>,
    episode: &Episode,
    drawing: &Drawing<'_>,
    stop: &dyn Fn() -> bool,
) -> Result<(), Error> {
    rundir::write_trace(dir, &team_trace_csv(lived.trace, lived.others, stage, episode))?;
    team_columns(dir, stage, lived.others, episode)?;
    if lived.trace.rows.is_empty() {
        return Ok(());
    }
    if stop() {
        return Err(Error::new(crate::ErrorKind::Interrupted, STOPPED));
    }
    pictures(dir, stage, 0, lived, drawing, stop)
}

/// Robot `robot`'s trace (its rows of every life, in order) and the
/// team's other robots with robot 0 among them (`trace` is robot 0's):
/// the team as robot `robot` lived it, for its pictures
/// ([`followed_pictures`]).
pub fn followed(trace: &Trace, others: &[OtherRobot], robot: usize) -> (Trace, Vec<OtherRobot>) {
    if robot == 0 {
        return (trace.clone(), others.to_vec());
    }
    let mine: Vec<&OtherRobot> = others.iter().filter(|o| o.robot == robot).collect();
    let mut rows: Vec<TraceRow> = mine.iter().flat_map(|o| o.trace.rows.iter().cloned()).collect();
    rows.sort_by_key(|r| r.action);
    let modules = mine.first().map(|o| o.trace.modules.clone()).unwrap_or_default();
    let zero = OtherRobot {
        robot: 0,
        part: 0,
        start: trace.rows.first().map(|r| r.pose).unwrap_or_default(),
        trace: trace.clone(),
        sensed: EpisodeColumns::default(),
    };
    let rest = std::iter::once(zero).chain(others.iter().filter(|o| o.robot != robot).cloned()).collect();
    (Trace { modules, rows }, rest)
}

/// The pictures of an episode as robot `robot` of the team lived it
/// (`trace` and `others` from [`followed`]): `replay --robot N`.
pub fn followed_pictures(
    dir: &Path,
    title: &str,
    stage: &Stage,
    robot: usize,
    (trace, others): (&Trace, &[OtherRobot]),
    scene: &Scene,
) -> Result<(), Error> {
    pictures(dir, stage, robot, Lived { trace, others, scene }, &Drawing::titled(title), &|| false)
}

/// The pictures of one episode whose `trace.csv` is written (see
/// [`TraceWriter`]): `activations`, `reinforcement`, `trajectory`, as
/// [`episode_files`] draws them.
pub fn episode_pictures(
    dir: &Path,
    title: &str,
    stage: &Stage,
    trace: &Trace,
    scene: &Scene,
) -> Result<(), Error> {
    pictures(dir, stage, 0, Lived { trace, others: &[], scene }, &Drawing::titled(title), &|| false)
}

/// The pictures of an episode as robot `robot` lived it (`lived.trace` is
/// its trace), drawn as `drawing` says, stopping between them once `stop()`.
fn pictures(
    dir: &Path,
    stage: &Stage,
    robot: usize,
    lived: Lived<'_>,
    drawing: &Drawing<'_>,
    stop: &dyn Fn() -> bool,
) -> Result<(), Error> {
    let Lived { trace, others, scene } = lived;
    let Drawing { title, marks, ref path } = *drawing;
    let to_err = Error::from;
    let check = || if stop() { Err(Error::new(crate::ErrorKind::Interrupted, STOPPED)) } else { Ok(()) };
    if trace.rows.is_empty() {
        return Ok(());
    }
    let act = plot::ActivationTrace {
        modules: trace.modules.clone(),
        activations: trace.rows.iter().map(|r| r.activations.clone()).collect(),
        winner: trace.rows.iter().map(|r| r.winner).collect(),
        battery: trace.rows.iter().map(|r| r.battery).collect(),
        holding: trace.rows.iter().map(|r| r.holding).collect(),
    };
    plot::activation_trace(
        &rundir::picture_path(dir, Picture::Activations),
        &format!("{title}: module activations"),
        &act,
    )
    .map_err(to_err)?;
    check()?;

    // The performance indicator the controller keeps: the rolling mean of the
    // module's last `window` reinforcement signals (the paper's figures 5, 10
    // and 13 average over signals, not over actions).
    // The learning modules of the robot's role, at their index in its trace.
    let own = stage.role_modules(stage.role_of(robot));
    let series: Vec<(String, Vec<f32>)> = learning_modules(stage)
        .into_iter()
        .filter(|(i, _)| own.contains(i))
        .map(|(i, name)| (name, performance_curve(trace, i - own.start)))
        .filter(|(_, v)| v.iter().any(|x| x.is_finite()))
        .collect();
    if !series.is_empty() {
        let window = stage.modules.iter().find_map(|m| m.learning.as_ref().map(|l| l.window)).unwrap_or(30);
        plot::rolling_reinforcement(
            &rundir::picture_path(dir, Picture::Reinforcement),
            &format!("{title}: performance (rolling mean of the last {window} reinforcements)"),
            &series,
            1,
            marks,
        )
        .map_err(to_err)?;
        check()?;
    }

    let (mut scene, what) = match path {
        Some((rows, what)) => {
            let rows = trace.rows.get(rows.clone()).filter(|r| !r.is_empty()).unwrap_or(&trace.rows);
            let part = Trace { modules: trace.modules.clone(), rows: rows.to_vec() };
            (trajectory_scene(scene, &part, others), format!("{title}: trajectory, {what}"))
        }
        None => (trajectory_scene(scene, trace, others), format!("{title}: trajectory")),
    };
    scene.roles = stage.roles.iter().map(|r| (r.name.clone(), r.robots)).collect();
    scene.robot = robot;
    plot::trajectory(&rundir::picture_path(dir, Picture::Trajectory), &what, &scene).map_err(to_err)
}

/// Modules that learn (or at least receive reinforcement), with their index.
pub fn learning_modules(stage: &Stage) -> Vec<(usize, String)> {
    stage
        .modules
        .iter()
        .enumerate()
        .filter(|(_, m)| m.learning.is_some() || m.reinforce.is_some())
        .map(|(i, m)| {
            let on = match m.learning.as_ref().map(|l| l.target) {
                Some(LearnTarget::Activation) => " (activation)",
                Some(LearnTarget::Behavior) => " (behavior)",
                None => "",
            };
            (i, format!("{}{on}", m.name))
        })
        .collect()
}

/// A module's performance indicator per action, NaN until its first
/// reinforcement signal.
pub fn performance_curve(trace: &Trace, module: usize) -> Vec<f32> {
    let mut seen = false;
    trace
        .rows
        .iter()
        .map(|r| {
            seen |= r.reinforcement.get(module).is_some_and(|&v| v != 0.0);
            match r.performance.get(module) {
                Some(&p) if seen => p,
                _ => f32::NAN,
            }
        })
        .collect()
}

/// A module's reinforcement signals, one per action: the signal where one was
/// delivered, NaN where none was (so rolling means skip the gaps).
pub fn reinforcement_signals(trace: &Trace, module: usize) -> Vec<f32> {
    trace
        .rows
        .iter()
        .map(|r| match r.reinforcement.get(module) {
            Some(&v) if v != 0.0 => v,
            _ => f32::NAN,
        })
        .collect()
}

/// The trajectory picture of robot 0's `trace` (the one robot's) and of
/// the team's other robots at the same actions (`others`: those of a
/// life among those actions).
fn trajectory_scene(scene: &Scene, trace: &Trace, others: &[OtherRobot]) -> plot::TrajectoryScene {
    let (first, last) = match (trace.rows.first(), trace.rows.last()) {
        (Some(a), Some(b)) => (a.action, b.action),
        _ => (1, 0),
    };
    let mut paths: Vec<(usize, Vec<[f32; 3]>)> = others
        .iter()
        .map(|o| {
            let rows = o.trace.rows.iter().filter(|r| (first..=last).contains(&r.action));
            (o.robot, rows.map(|r| [r.pose.x, r.pose.y, r.pose.theta]).collect::<Vec<_>>())
        })
        .filter(|(_, p)| !p.is_empty())
        .collect();
    paths.sort_by_key(|(robot, _)| *robot);
    let mut marks = Vec::new();
    let (mut grips, mut releases) = (0, 0);
    for (i, r) in trace.rows.iter().enumerate() {
        if r.grips > grips {
            marks.push((i, "grip".to_string()));
        }
        if r.releases_outside > releases {
            marks.push((i, "release".to_string()));
        }
        if r.recharged {
            marks.push((i, "recharged".to_string()));
        }
        grips = r.grips;
        releases = r.releases_outside;
    }
    plot::TrajectoryScene {
        marks,
        others: paths.into_iter().map(|(_, p)| p).collect(),
        path_modules: Some(trace.rows.iter().map(|r| r.winner).collect()),
        module_names: trace.modules.clone(),
        ..picture(scene, trace.rows.iter().map(|r| [r.pose.x, r.pose.y, r.pose.theta]).collect())
    }
}

/// The picture of `scene` with the robot's `path` (poses `[x, y, heading]`),
/// coloured by time, without marks.
pub fn picture(scene: &Scene, path: Vec<[f32; 3]>) -> plot::TrajectoryScene {
    plot::TrajectoryScene {
        arena: scene.arena,
        bar: scene.bar.map(|[a, b]| (a, b)),
        lamp: scene.lamp,
        walls: scene.walls.iter().map(|&[a, b]| (a, b)).collect(),
        cylinders: scene.cylinders.clone(),
        lamps: scene.lamps.clone(),
        dark_lamps: scene.dark_lamps.clone(),
        zones: scene.zones.iter().map(|z| (z.from, z.to, z.grey, z.charger)).collect(),
        objects: scene
            .objects
            .iter()
            .map(|o| plot::SceneObject {
                x: o.x,
                y: o.y,
                radius: o.radius,
                virtual_: o.virtual_,
                collected: o.state != ObjectState::Floor,
            })
            .collect(),
        path,
        body_radius: scene.body_radius,
        marks: Vec::new(),
        path_modules: None,
        module_names: Vec::new(),
        others: Vec::new(),
        roles: Vec::new(),
        robot: 0,
    }
}
