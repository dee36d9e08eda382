//! One traced episode with what the HTML report's animation needs:
//! `episode.json`, the trace (the rows of `trace.csv`) plus, after every
//! action, the world as the robot left it (objects, gripper, what the
//! proximity sensors read).
//!
//! A simulated life, of one robot or of a team, is recorded by
//! [`record_life`]: the life's hooks take a snapshot each time a
//! controller has sensed (once at the start, then after every action). A
//! real robot's life (`drive`) is recorded by [`Recorder`], a [`Robot`]
//! that forwards every call to the robot and takes the same snapshot. Both
//! draw no random number of their own, so a recorded episode is the same
//! episode as an unrecorded one with the same seed.

use std::sync::atomic::{AtomicBool, Ordering};

use shaping_runtime::controller::{
    episode_with, ActionReport, Controller, Hooks, Solo, TeamBodies, TeamMember, TeamResult, TeamRun,
};
use shaping_runtime::program::World;

use serde::{Deserialize, Serialize};
use shaping_runtime::catalog::{
    ActuatorKind, ACT_SIGNAL, CHANNELS, CH_BARRIER, CH_FLOOR, CH_IR, CH_LAMP_DISTANCE, CH_LIGHT, CH_RAB,
    SENSOR_BEARING_DEG, SIGNALS,
};
use shaping_runtime::controller::{Robot, Trace, TraceRow};
use shaping_runtime::robot::{Link, SerialRobot};
use shaping_runtime::sim::{ir, Command, ObjectState, Outcome, Pose, Scene, Sim};

/// Version of the `episode.json` format.
pub const EPISODE_FORMAT: u32 = 1;

/// What the robot sensed and how the world was after one sensing.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub ir: [f32; ir::SENSORS],
    /// Ambient light on the same photodiodes.
    pub light: [f32; ir::SENSORS],
    pub barrier: bool,
    /// The ground sensor (the floor's grey level under the body).
    pub floor: f32,
    /// The distance to the nearest lamp, as sensed (0..1 of a metre).
    pub lamp_distance: f32,
    pub arm_down: bool,
    pub claw_closed: bool,
    /// The wheel command of the action that led here (zero at the start).
    pub wheels: [f32; 2],
    /// `[x, y, radius, state]` per object (state 0 floor, 1 held, 2 outside).
    pub objects: Vec<[f32; 4]>,
    /// The range-and-bearing board, when the body has one.
    pub board: Option<Box<BoardFrame>>,
}

/// The channels of the range-and-bearing board: its sectors, then the
/// signals heard (from [`CH_RAB`] to the percept's end).
pub const BOARD_CHANNELS: usize = CHANNELS - CH_RAB;

/// What a robot's range-and-bearing board read after an action, and what
/// the robot broadcast then.
#[derive(Clone, Debug, PartialEq)]
pub struct BoardFrame {
    /// The sectors, then the signals heard, as the percept has them from
    /// [`CH_RAB`].
    pub read: [f32; BOARD_CHANNELS],
    /// The values broadcast (a `broadcast` actuator's).
    pub signal: [f32; SIGNALS],
}

impl BoardFrame {
    /// The board in percept `out`, with the broadcast of the actuator
    /// slots `commanded`.
    fn of(out: &[f32; CHANNELS], commanded: &[f32; shaping_runtime::catalog::ACT_SLOTS]) -> Box<BoardFrame> {
        let mut read = [0.0; BOARD_CHANNELS];
        read.copy_from_slice(&out[CH_RAB..]);
        let mut signal = [0.0; SIGNALS];
        signal.copy_from_slice(&commanded[ACT_SIGNAL..ACT_SIGNAL + SIGNALS]);
        Box::new(BoardFrame { read, signal })
    }
}

/// A robot whose world can be drawn: the simulator, or a real robot with
/// the part of the world simulated on the host (virtual objects, battery).
pub trait Shown: Robot {
    fn scene(&self) -> Scene;
}

impl Shown for Sim {
    fn scene(&self) -> Scene {
        Sim::scene(self)
    }
}

impl<L: Link> Shown for SerialRobot<L> {
    fn scene(&self) -> Scene {
        self.host().scene()
    }
}

/// A [`Robot`] that records a [`Frame`] every time the controller senses:
/// once at the start, then once after every action.
pub struct Recorder<'a, R: Shown = Sim> {
    pub robot: &'a mut R,
    pub frames: Vec<Frame>,
    wheels: [f32; 2],
}

impl<'a, R: Shown> Recorder<'a, R> {
    pub fn new(robot: &'a mut R) -> Recorder<'a, R> {
        Recorder { robot, frames: Vec::new(), wheels: [0.0; 2] }
    }
}

/// The frame of what a robot sensed (`out`), its gripper, the wheel
/// command that led there and the objects.
fn frame_of(
    out: &[f32; CHANNELS],
    arm_down: bool,
    claw_closed: bool,
    wheels: [f32; 2],
    objects: Vec<[f32; 4]>,
) -> Frame {
    let mut irv = [0.0; ir::SENSORS];
    irv.copy_from_slice(&out[CH_IR..CH_IR + ir::SENSORS]);
    let mut light = [0.0; ir::SENSORS];
    light.copy_from_slice(&out[CH_LIGHT..CH_LIGHT + ir::SENSORS]);
    Frame {
        ir: irv,
        light,
        barrier: out[CH_BARRIER] > 0.5,
        floor: out[CH_FLOOR],
        lamp_distance: out[CH_LAMP_DISTANCE],
        arm_down,
        claw_closed,
        wheels,
        objects,
        board: None,
    }
}

fn object_rows(scene: &Scene) -> Vec<[f32; 4]> {
    scene
        .objects
        .iter()
        .map(|o| {
            let state = match o.state {
                ObjectState::Floor => 0.0,
                ObjectState::Held => 1.0,
                ObjectState::Outside => 2.0,
            };
            [round(o.x, 1), round(o.y, 1), round(o.radius, 2), state]
        })
        .collect()
}

impl<R: Shown> Robot for Recorder<'_, R> {
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        self.robot.sense(out);
        let scene = self.robot.scene();
        self.frames.push(frame_of(out, scene.arm_down, scene.claw_closed, self.wheels, object_rows(&scene)));
    }
    fn step(&mut self, cmd: &Command) -> Outcome {
        self.wheels = cmd.wheels;
        self.robot.step(cmd)
    }
    fn alive(&self) -> bool {
        self.robot.alive()
    }
    fn battery(&self) -> f32 {
        self.robot.battery()
    }
    fn pose(&self) -> Pose {
        self.robot.pose()
    }
    fn holding(&self) -> Option<bool> {
        self.robot.holding()
    }
    fn placement_failures(&self) -> u32 {
        self.robot.placement_failures()
    }
}

/// The world of one part of an episode (a test stage's episode has two: the
/// parent's world, then the changed one).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EpisodeWorld {
    /// The stage whose world this is.
    pub stage: String,
    /// First action in this world.
    pub from: u32,
    /// Width and depth, mm.
    pub arena: [f32; 2],
    pub bar: Option<[[f32; 2]; 2]>,
    pub lamp: Option<[f32; 2]>,
    /// Inner walls' end points.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub walls: Vec<[[f32; 2]; 2]>,
    /// Cylinders: `[x, y, radius]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cylinders: Vec<[f32; 3]>,
    /// Declared lamps (the charger's is `lamp`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lamps: Vec<[f32; 2]>,
    /// Floor zones.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub zones: Vec<shaping_runtime::sim::SceneZone>,
    pub body_radius: f32,
    /// Pose before the first action: `[x, y, theta]`.
    pub start: [f32; 3],
    /// Objects before the first action: `[x, y, radius, state]`.
    pub objects: Vec<[f32; 4]>,
    /// A team's other robots (1, 2, ...) in this world: their poses before
    /// the first action, `[x, y, theta]` (absent for one robot).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub others: Vec<[f32; 3]>,
}

/// One robot's poses, per action.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseColumns {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub theta: Vec<f32>,
}

/// Per-action columns (index = action).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EpisodeColumns {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub theta: Vec<f32>,
    pub winner: Vec<u16>,
    pub battery: Vec<f32>,
    pub holding: Vec<u8>,
    pub grips: Vec<u32>,
    pub releases: Vec<u32>,
    pub recharged: Vec<u8>,
    pub collided: Vec<u8>,
    /// Per module, per action.
    pub activation: Vec<Vec<f32>>,
    pub reinforcement: Vec<Vec<f32>>,
    pub performance: Vec<Vec<f32>>,
    /// Proximity readings the robot sensed after the action.
    pub ir: Vec<[f32; ir::SENSORS]>,
    /// Ambient light readings the robot sensed after the action.
    #[serde(default)]
    pub light: Vec<[f32; ir::SENSORS]>,
    pub barrier: Vec<u8>,
    /// The ground sensor and the sensed lamp distance after the action.
    #[serde(default)]
    pub floor: Vec<f32>,
    #[serde(default)]
    pub lamp_distance: Vec<f32>,
    pub arm_down: Vec<u8>,
    pub claw_closed: Vec<u8>,
    pub wheels: Vec<[f32; 2]>,
    /// Objects that changed at an action: `[action, index, x, y, radius, state]`.
    pub objects: Vec<[f32; 6]>,
    /// A team's other robots (1, 2, ...): each one's poses after every
    /// action, as long as the columns above (absent for one robot; zeros
    /// at the actions of a world with fewer robots, see
    /// [`EpisodeWorld::others`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub others: Vec<PoseColumns>,
    /// The range-and-bearing board after every action, when the body has
    /// one: for `trace.csv`, not written in `episode.json` (whose format
    /// stays as it is).
    #[serde(skip)]
    pub board: Vec<BoardFrame>,
}

impl EpisodeColumns {
    /// Columns of `modules` modules and no action yet.
    pub fn new(modules: usize) -> EpisodeColumns {
        EpisodeColumns {
            activation: vec![Vec::new(); modules],
            reinforcement: vec![Vec::new(); modules],
            performance: vec![Vec::new(); modules],
            ..EpisodeColumns::default()
        }
    }

    /// Adds what the controller did at one action (its trace row).
    pub fn push_row(&mut self, r: &TraceRow) {
        self.x.push(round(r.pose.x, 2));
        self.y.push(round(r.pose.y, 2));
        self.theta.push(round(r.pose.theta, 4));
        self.winner.push(r.winner);
        self.battery.push(round(r.battery, 4));
        self.holding.push(r.holding as u8);
        self.grips.push(r.grips);
        self.releases.push(r.releases_outside);
        self.recharged.push(r.recharged as u8);
        self.collided.push(r.collided as u8);
        for m in 0..self.activation.len() {
            self.activation[m].push(round(r.activations.get(m).copied().unwrap_or(0.0), 4));
            self.reinforcement[m].push(round(r.reinforcement.get(m).copied().unwrap_or(0.0), 4));
            self.performance[m].push(round(r.performance.get(m).copied().unwrap_or(0.0), 4));
        }
    }

    /// Adds what the robot sensed after one action and the wheel command
    /// that led there (the objects aside: they are kept as changes).
    pub fn push_frame(&mut self, f: &Frame) {
        self.ir.push(f.ir.map(|v| round(v, 3)));
        self.light.push(f.light.map(|v| round(v, 3)));
        self.barrier.push(f.barrier as u8);
        self.floor.push(round(f.floor, 3));
        self.lamp_distance.push(round(f.lamp_distance, 3));
        self.arm_down.push(f.arm_down as u8);
        self.claw_closed.push(f.claw_closed as u8);
        self.wheels.push(f.wheels.map(|v| round(v, 3)));
        if let Some(b) = &f.board {
            self.board.push(BoardFrame {
                read: b.read.map(|v| round(v, 3)),
                signal: b.signal.map(|v| round(v, 3)),
            });
        }
    }
}

/// `episode.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Episode {
    pub format: u32,
    pub stage: String,
    /// The episode seed, as a string: seeds use all 64 bits, more than a
    /// JavaScript number holds exactly.
    #[serde(with = "seed_string")]
    pub seed: u64,
    pub learning: bool,
    /// The robot has a gripper (arm and claw).
    pub gripper: bool,
    pub modules: Vec<String>,
    /// Bearings of the proximity sensors, degrees counter-clockwise from the
    /// heading: the body's declared ones, else the Khepera's nominal ones.
    pub sensor_bearings: [f32; ir::SENSORS],
    /// Reach of the proximity sensors beyond the body, mm.
    pub sensor_range: f32,
    pub worlds: Vec<EpisodeWorld>,
    pub actions: EpisodeColumns,
}

mod seed_string {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(seed: &u64, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&seed.to_string())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
        String::deserialize(d)?.parse().map_err(serde::de::Error::custom)
    }
}

fn round(v: f32, digits: i32) -> f32 {
    if !v.is_finite() {
        return 0.0;
    }
    let k = 10f32.powi(digits);
    (v * k).round() / k
}

/// One part of an episode: the world it started in and its frames (the
/// first is the start, then one per action).
pub struct Part<'a> {
    pub stage: &'a str,
    pub scene: Scene,
    pub frames: Vec<Frame>,
}

/// Builds the episode from the trace and the recorded parts, in order.
pub fn episode(
    stage: &shaping_runtime::program::Stage,
    seed: u64,
    learning: bool,
    trace: &Trace,
    parts: &[Part<'_>],
) -> Episode {
    let mut c = EpisodeColumns::new(trace.modules.len());
    for r in &trace.rows {
        c.push_row(r);
    }
    let mut worlds = Vec::new();
    let mut from = 0u32;
    for part in parts {
        let start = part.frames.first();
        let p = part.scene.pose;
        worlds.push(EpisodeWorld {
            stage: part.stage.to_string(),
            from,
            arena: part.scene.arena,
            bar: part.scene.bar,
            lamp: part.scene.lamp,
            walls: part.scene.walls.clone(),
            cylinders: part.scene.cylinders.clone(),
            lamps: part.scene.lamps.clone(),
            zones: part.scene.zones.clone(),
            body_radius: part.scene.body_radius,
            start: [round(p.x, 2), round(p.y, 2), round(p.theta, 4)],
            objects: start.map_or_else(|| object_rows(&part.scene), |f| f.objects.clone()),
            others: Vec::new(),
        });
        let mut prev: Vec<[f32; 4]> = start.map(|f| f.objects.clone()).unwrap_or_default();
        for (k, f) in part.frames.iter().skip(1).enumerate() {
            let action = from + k as u32;
            c.push_frame(f);
            for (i, o) in f.objects.iter().enumerate() {
                if prev.get(i) != Some(o) {
                    c.objects.push([action as f32, i as f32, o[0], o[1], o[2], o[3]]);
                }
            }
            prev.clone_from(&f.objects);
        }
        from += part.frames.len().saturating_sub(1) as u32;
    }
    let gripper = stage.actuators.iter().any(|a| matches!(a.kind, ActuatorKind::Lift | ActuatorKind::Grip));
    Episode {
        format: EPISODE_FORMAT,
        stage: stage.name.clone(),
        seed,
        learning,
        gripper,
        modules: trace.modules.clone(),
        // a declared layout's bearings (`body e-puck`), else the Khepera's
        sensor_bearings: stage.world.body.ir.as_ref().map_or(SENSOR_BEARING_DEG, |l| l.facing),
        sensor_range: ir::RANGE,
        worlds,
        actions: c,
    }
}

/// Runs one traced and recorded episode of `genome` on `stage`, exactly as
/// [`shaping_runtime::controller::run_episode`] does (of a team: robot 0's
/// trace, the episode of every robot; [`record`] gives the others' traces).
pub fn run_recorded(
    stage: &shaping_runtime::program::Stage,
    genome: &shaping_runtime::genome::Genome,
    opts: &shaping_runtime::controller::EpisodeOptions,
) -> Result<(shaping_runtime::controller::EpisodeResult, Trace, Episode), String> {
    let r = record(stage, genome, opts)?;
    Ok((r.result, r.trace, r.episode))
}

/// Another robot of a team (robot 1, 2, ...) in one life of a recording.
#[derive(Clone, Debug)]
pub struct OtherRobot {
    /// Its index in the team.
    pub robot: usize,
    /// The part (life) of the recording it lived in ([`Part`]).
    pub part: usize,
    /// Its pose before the first action.
    pub start: Pose,
    /// Its rows, one per action of the life, at the actions of the whole
    /// recording (as robot 0's trace).
    pub trace: Trace,
    /// What it sensed after each of its rows (row `k`'s at index `k`; the
    /// objects aside).
    pub sensed: EpisodeColumns,
}

impl Episode {
    /// Adds a team's other robots (`others`, of the episode's parts): their
    /// starts in each world and their poses at every action. Nothing for
    /// one robot: a single robot's episode is as it was.
    pub fn add_others(&mut self, others: &[OtherRobot]) {
        let Some(most) = others.iter().map(|o| o.robot).max() else { return };
        let n = self.actions.x.len();
        self.actions.others =
            vec![PoseColumns { x: vec![0.0; n], y: vec![0.0; n], theta: vec![0.0; n] }; most];
        for o in others {
            if let Some(w) = self.worlds.get_mut(o.part) {
                if w.others.len() < o.robot {
                    w.others.resize(o.robot, [0.0; 3]);
                }
                let p = o.start;
                w.others[o.robot - 1] = [round(p.x, 2), round(p.y, 2), round(p.theta, 4)];
            }
            let c = &mut self.actions.others[o.robot - 1];
            for r in &o.trace.rows {
                let a = r.action as usize;
                if a < n {
                    c.x[a] = round(r.pose.x, 2);
                    c.y[a] = round(r.pose.y, 2);
                    c.theta[a] = round(r.pose.theta, 4);
                }
            }
        }
    }

    /// This episode as robot `robot` of the team lived it (`team`: the
    /// others' columns, [`TeamColumns`]): its columns, modules and starts
    /// in place of robot 0's, the others' poses (robot 0's among them, in
    /// the order of their numbers) around it; itself for robot 0 or a
    /// robot `team` does not have.
    pub fn following(&self, team: &TeamColumns, robot: usize) -> Episode {
        let Some(mine) = robot.checked_sub(1).and_then(|k| team.robots.get(k)) else { return self.clone() };
        let c0 = &self.actions;
        let pose = |j: usize| match j {
            0 => PoseColumns { x: c0.x.clone(), y: c0.y.clone(), theta: c0.theta.clone() },
            _ => c0.others.get(j - 1).cloned().unwrap_or_default(),
        };
        let nums: Vec<usize> = (0..=c0.others.len()).filter(|&j| j != robot).collect();
        let mut actions = mine.actions.clone();
        actions.objects.clone_from(&c0.objects);
        actions.others = nums.iter().map(|&j| pose(j)).collect();
        let worlds = self
            .worlds
            .iter()
            .map(|w| {
                let start = |j: usize| if j == 0 { Some(w.start) } else { w.others.get(j - 1).copied() };
                let others = if w.others.len() >= robot {
                    nums.iter().filter_map(|&j| start(j)).collect()
                } else {
                    Vec::new()
                };
                EpisodeWorld { start: start(robot).unwrap_or(w.start), others, ..w.clone() }
            })
            .collect();
        Episode { modules: mine.modules.clone(), worlds, actions, ..self.clone() }
    }

    /// The robots of the team in world `w` (1 for one robot).
    pub fn robots_in(&self, w: usize) -> usize {
        1 + self.worlds.get(w).map_or(0, |x| x.others.len())
    }
}

/// Version of `robots.json`.
pub const ROBOTS_FORMAT: u32 = 1;

/// `robots.json`, beside a team's `episode.json` (which keeps robot 0's
/// columns and only the poses of the others, as it always has): every
/// other robot's columns, for the report to follow any robot.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TeamColumns {
    pub format: u32,
    /// The robot a replay follows (`replay --robot N`): the report shows
    /// it first; 0 for a run's episode.
    #[serde(default)]
    pub follow: u32,
    /// The role robot 0 plays, in a team of roles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub role: Option<String>,
    /// Robots 1, 2, ... in order.
    pub robots: Vec<RobotColumns>,
    /// The range-and-bearing board of every robot (0, 1, ...), when the
    /// body has one (`report::board_columns`): for the report's readout,
    /// which `episode.json` (without the board) cannot give.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub board: Option<BoardColumns>,
}

/// The range-and-bearing board of a team's episode, robot by robot (in
/// `robots.json`, [`TeamColumns::board`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BoardColumns {
    /// The columns, as `trace.csv` names them: the `range_bearing` sensor's,
    /// the `signal` sensor's and the `broadcast` actuator's elements
    /// (`rab[0]`, ..., `heard[0]`, ..., `signal[0]`), as declared.
    pub names: Vec<String>,
    /// Robot `j`'s values at action `a`, one per name, as `trace.csv` has
    /// them: `robots[j][a]`; empty at an action the robot did not live
    /// (a world it was not in).
    pub robots: Vec<Vec<Vec<f32>>>,
}

/// One robot of a team ([`TeamColumns`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RobotColumns {
    pub robot: u32,
    /// The role it plays, in a team of roles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub role: Option<String>,
    /// Its modules (its role's), the columns of `actions`' per-module ones.
    pub modules: Vec<String>,
    /// Its columns, as long as the episode's (an action of a world it was
    /// not in repeats its last row, or is zeros before its first); without
    /// `objects` and `others`.
    pub actions: EpisodeColumns,
}

impl TeamColumns {
    /// The columns of a team's `others` (of an episode of `actions`
    /// actions), robot `follow` followed; `None` for one robot.
    pub fn of(
        stage: &shaping_runtime::program::Stage,
        others: &[OtherRobot],
        actions: usize,
        follow: u32,
    ) -> Option<TeamColumns> {
        let most = others.iter().map(|o| o.robot).max()?;
        let robots = (1..=most)
            .map(|j| {
                let mut rows: Vec<(&TraceRow, &EpisodeColumns, usize)> = others
                    .iter()
                    .filter(|o| o.robot == j)
                    .flat_map(|o| o.trace.rows.iter().enumerate().map(move |(k, r)| (r, &o.sensed, k)))
                    .collect();
                rows.sort_by_key(|(r, ..)| r.action);
                let modules =
                    others.iter().find(|o| o.robot == j).map(|o| o.trace.modules.clone()).unwrap_or_default();
                let mut c = EpisodeColumns::new(modules.len());
                let mut next = rows.iter().peekable();
                let mut last: Option<(&TraceRow, &EpisodeColumns, usize)> = None;
                for a in 0..actions {
                    while let Some(&&(r, sensed, k)) = next.peek() {
                        if r.action as usize > a {
                            break;
                        }
                        if r.action as usize == a {
                            last = Some((r, sensed, k));
                        }
                        next.next();
                    }
                    match last {
                        Some((r, sensed, k)) => {
                            c.push_row(r);
                            c.push_sensed(sensed, k);
                        }
                        None => c.push_blank(),
                    }
                }
                let role = stage.roles.get(stage.role_of(j)).map(|r| r.name.clone());
                RobotColumns { robot: j as u32, role, modules, actions: c }
            })
            .collect();
        let role = stage.roles.first().map(|r| r.name.clone());
        Some(TeamColumns { format: ROBOTS_FORMAT, follow, role, robots, board: None })
    }
}

impl EpisodeColumns {
    /// Adds what `c` sensed at its index `k` (see [`Self::push_frame`]).
    fn push_sensed(&mut self, c: &EpisodeColumns, k: usize) {
        self.ir.push(c.ir.get(k).copied().unwrap_or_default());
        self.light.push(c.light.get(k).copied().unwrap_or_default());
        self.barrier.push(c.barrier.get(k).copied().unwrap_or_default());
        self.floor.push(c.floor.get(k).copied().unwrap_or_default());
        self.lamp_distance.push(c.lamp_distance.get(k).copied().unwrap_or_default());
        self.arm_down.push(c.arm_down.get(k).copied().unwrap_or_default());
        self.claw_closed.push(c.claw_closed.get(k).copied().unwrap_or_default());
        self.wheels.push(c.wheels.get(k).copied().unwrap_or_default());
    }

    /// Adds an action of a robot not yet in the episode's world: zeros.
    fn push_blank(&mut self) {
        let modules = self.activation.len();
        let row = TraceRow {
            action: 0,
            activations: vec![0.0; modules],
            winner: 0,
            battery: 0.0,
            holding: false,
            reinforcement: vec![0.0; modules],
            performance: vec![0.0; modules],
            pose: Pose::default(),
            grips: 0,
            releases_outside: 0,
            recharged: false,
            collided: false,
        };
        self.push_row(&row);
        self.push_sensed(&EpisodeColumns::default(), 0);
    }
}

/// Records a life ([`Hooks`]): every robot's frames (a frame each time
/// it has sensed: at the start, then after each of its actions; robot 0's
/// with the objects), every robot's start, and robot 0's world before the
/// first action; once `stop` is set, the life ends at the next action.
struct LifeRecorder<'a> {
    frames: Vec<Vec<Frame>>,
    starts: Vec<Pose>,
    scene: Option<Scene>,
    stop: Option<&'a AtomicBool>,
    /// The body has a range-and-bearing board: the frames keep it.
    board: bool,
}

impl LifeRecorder<'_> {
    /// Robot `i` has sensed (its controller's percept) after the command
    /// `wheels` (zero at the start); robot 0's frames keep the objects of
    /// its world, which is returned.
    fn sensed(
        &mut self,
        i: usize,
        ctl: &Controller<'_>,
        wheels: [f32; 2],
        robot: &impl Seen,
    ) -> Option<Scene> {
        if self.frames.len() <= i {
            self.frames.resize(i + 1, Vec::new());
        }
        let (gripper, world) = robot.seen(i == 0);
        let objects = world.as_ref().filter(|_| i == 0).map(object_rows).unwrap_or_default();
        let mut frame = frame_of(ctl.percept(), gripper[0], gripper[1], wheels, objects);
        if self.board {
            frame.board = Some(BoardFrame::of(ctl.percept(), ctl.commanded()));
        }
        self.frames[i].push(frame);
        world
    }

    /// Robot `i` started its life: its first frame, its start, and robot
    /// 0's world before the first action.
    fn started(&mut self, i: usize, ctl: &Controller<'_>, robot: &impl Seen) {
        let world = self.sensed(i, ctl, [0.0; 2], robot);
        if self.starts.len() <= i {
            self.starts.resize(i + 1, Pose::default());
        }
        self.starts[i] = robot.pose_now();
        if i == 0 {
            self.scene = world;
        }
    }

    fn go_on(&self) -> bool {
        !self.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }
}

/// What [`LifeRecorder`] reads of a robot of a life: its gripper `[arm
/// down, claw closed]` and, when asked, its world; its pose.
trait Seen {
    fn seen(&self, world: bool) -> ([bool; 2], Option<Scene>);
    fn pose_now(&self) -> Pose;
}

impl<R: Shown> Seen for &mut R {
    fn seen(&self, _: bool) -> ([bool; 2], Option<Scene>) {
        // One robot: its world gives the gripper too.
        let scene = self.scene();
        ([scene.arm_down, scene.claw_closed], Some(scene))
    }
    fn pose_now(&self) -> Pose {
        self.pose()
    }
}

impl Seen for TeamMember<'_> {
    fn seen(&self, world: bool) -> ([bool; 2], Option<Scene>) {
        let sim = self.sim();
        ([sim.arm_down(), sim.claw_closed()], world.then(|| sim.scene()))
    }
    fn pose_now(&self) -> Pose {
        self.sim().pose()
    }
}

impl<'s, R: Shown> Hooks<'s, Solo<'_, R>> for LifeRecorder<'_> {
    fn started(&mut self, i: usize, ctl: &Controller<'s>, robot: &&mut R) {
        LifeRecorder::started(self, i, ctl, robot);
    }
    fn acted(
        &mut self,
        i: usize,
        ctl: &Controller<'s>,
        rep: &ActionReport,
        _: Option<&TraceRow>,
        robot: &&mut R,
    ) {
        self.sensed(i, ctl, rep.command.wheels, robot);
    }
    fn after_action(&mut self, _: &Solo<'_, R>) -> bool {
        self.go_on()
    }
}

impl<'s> Hooks<'s, TeamBodies<'_>> for LifeRecorder<'_> {
    fn started(&mut self, i: usize, ctl: &Controller<'s>, robot: &TeamMember<'_>) {
        LifeRecorder::started(self, i, ctl, robot);
    }
    fn acted(
        &mut self,
        i: usize,
        ctl: &Controller<'s>,
        rep: &ActionReport,
        _: Option<&TraceRow>,
        robot: &TeamMember<'_>,
    ) {
        self.sensed(i, ctl, rep.command.wheels, robot);
    }
    fn after_action(&mut self, _: &TeamBodies<'_>) -> bool {
        self.go_on()
    }
}

/// One recorded life, of one robot or of a team.
pub struct TeamLife {
    pub result: TeamResult,
    /// Robot 0's trace and frames (the start, then one per action).
    pub trace: Trace,
    pub frames: Vec<Frame>,
    /// The other robots (part 0, actions from 0): none for one robot.
    pub others: Vec<OtherRobot>,
    /// Robot 0's world before the first action.
    pub scene: Scene,
}

/// Lives one life of `run` in a fresh `world` of seed `seed` (one robot's
/// or a team's: [`episode_with`]) and records every robot: each one's
/// trace has a row per action of the life and its frames a frame per
/// action (a robot whose battery emptied stays where it stopped, an
/// obstacle: its later rows repeat its last one with no activation, no
/// reinforcement and no event, its frames its last with the wheels
/// stopped). Once `stop` is set, the life ends at the next action.
pub fn record_life(
    run: &mut TeamRun<'_>,
    world: &World,
    seed: u64,
    opts: &shaping_runtime::controller::EpisodeOptions,
    stop: Option<&AtomicBool>,
) -> TeamLife {
    let n = world.robots.max(1) as usize;
    let mut traces = vec![Trace::default(); n];
    let mut rec = LifeRecorder {
        frames: vec![Vec::new(); n],
        starts: vec![Pose::default(); n],
        scene: None,
        stop,
        board: world.body.rab.is_some(),
    };
    let result = episode_with(run, world, seed, opts, Some(&mut traces), |sim| sim, &mut rec);
    let actions = result.team.actions;
    for t in &mut traces {
        pad_trace(t, actions);
    }
    for f in &mut rec.frames {
        pad_frames(f, actions as usize + 1);
    }
    let mut traces = traces.into_iter();
    let mut frames = rec.frames.into_iter();
    let trace = traces.next().unwrap_or_default();
    let frames0 = frames.next().unwrap_or_default();
    let starts = rec.starts;
    let others = traces
        .zip(frames)
        .enumerate()
        .map(|(k, (trace, frames))| {
            let mut sensed = EpisodeColumns::new(0);
            for f in frames.iter().skip(1) {
                sensed.push_frame(f);
            }
            OtherRobot { robot: k + 1, part: 0, start: starts[k + 1], trace, sensed }
        })
        .collect();
    // Robot 0 always starts; the world before it did, should it not.
    let scene = rec.scene.unwrap_or_else(|| Sim::new(world, seed).scene());
    TeamLife { result, trace, frames: frames0, others, scene }
}

/// Extends a stopped robot's trace to `actions` rows (see [`record_life`]).
fn pad_trace(t: &mut Trace, actions: u32) {
    while (t.rows.len() as u32) < actions {
        let Some(last) = t.rows.last() else { return };
        let mut r = last.clone();
        r.action += 1;
        r.activations.fill(0.0);
        r.reinforcement.fill(0.0);
        r.recharged = false;
        r.collided = false;
        t.rows.push(r);
    }
}

/// Extends a stopped robot's frames to `len` (see [`record_life`]).
fn pad_frames(f: &mut Vec<Frame>, len: usize) {
    while f.len() < len {
        let Some(last) = f.last() else { return };
        let mut next = last.clone();
        next.wheels = [0.0; 2];
        f.push(next);
    }
}

/// A recorded episode: its result, robot 0's trace (the one robot's), the
/// team's other robots (none for one robot), the episode, and the world
/// before the first action.
pub struct Recorded {
    pub result: shaping_runtime::controller::EpisodeResult,
    pub trace: Trace,
    pub others: Vec<OtherRobot>,
    pub episode: Episode,
    pub scene: Scene,
}

/// Runs one traced and recorded episode of `genome` on `stage`, exactly as
/// [`shaping_runtime::controller::run_episode`] does: of every robot of a
/// team.
pub fn record(
    stage: &shaping_runtime::program::Stage,
    genome: &shaping_runtime::genome::Genome,
    opts: &shaping_runtime::controller::EpisodeOptions,
) -> Result<Recorded, String> {
    record_until(stage, genome, opts, None)?
        .ok_or_else(|| format!("the episode of stage `{}` was stopped", stage.name))
}

/// [`record`], given up once `stop` is set: before it starts, and at its
/// next action; `None` when it was.
pub fn record_until(
    stage: &shaping_runtime::program::Stage,
    genome: &shaping_runtime::genome::Genome,
    opts: &shaping_runtime::controller::EpisodeOptions,
    stop: Option<&AtomicBool>,
) -> Result<Option<Recorded>, String> {
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    if stopped() {
        return Ok(None);
    }
    let mut run =
        TeamRun::new(stage, genome, opts.seed).map_err(|e| format!("stage `{}`: {e}", stage.name))?;
    let life = record_life(&mut run, &stage.world, opts.seed, opts, stop);
    if stopped() {
        return Ok(None);
    }
    let mut result = life.result.team;
    if stage.inheritance == shaping_runtime::program::Inheritance::Lamarckian {
        result.learned = Some(run.write_back(genome));
    }
    let parts = [Part { stage: &stage.name, scene: life.scene.clone(), frames: life.frames }];
    let mut episode = episode(stage, opts.seed, opts.learning, &life.trace, &parts);
    episode.add_others(&life.others);
    Ok(Some(Recorded { result, trace: life.trace, others: life.others, episode, scene: life.scene }))
}
