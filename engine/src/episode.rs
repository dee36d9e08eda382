//! One traced episode with what the HTML report's animation needs:
//! `episode.json`, the trace (the rows of `trace.csv`) plus, after every
//! action, the world as the robot left it (objects, gripper, what the
//! proximity sensors read).
//!
//! The world is recorded by [`Recorder`], a [`Robot`] that forwards every
//! call to the simulator and takes a snapshot each time the controller
//! senses. It draws no random number of its own, so a recorded episode is
//! the same episode as an unrecorded one with the same seed.

use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};
use shaping_runtime::catalog::{
    ActuatorKind, CHANNELS, CH_BARRIER, CH_FLOOR, CH_IR, CH_LAMP_DISTANCE, CH_LIGHT, SENSOR_BEARING_DEG,
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

/// A robot that stops acting, as an empty battery makes it, once `stop` is
/// set (Ctrl-C during a long life of a test stage: the life ends at the
/// next action). Until then it is the robot it wraps, call for call.
pub struct Stoppable<'a, R> {
    pub robot: R,
    stop: Option<&'a AtomicBool>,
}

impl<'a, R> Stoppable<'a, R> {
    pub fn new(robot: R, stop: Option<&'a AtomicBool>) -> Stoppable<'a, R> {
        Stoppable { robot, stop }
    }
}

impl<R: Robot> Robot for Stoppable<'_, R> {
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        self.robot.sense(out);
    }
    fn step(&mut self, cmd: &Command) -> Outcome {
        self.robot.step(cmd)
    }
    fn alive(&self) -> bool {
        !self.stop.is_some_and(|s| s.load(Ordering::Relaxed)) && self.robot.alive()
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

impl<R: Shown> Shown for Stoppable<'_, R> {
    fn scene(&self) -> Scene {
        self.robot.scene()
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
        let mut irv = [0.0; ir::SENSORS];
        irv.copy_from_slice(&out[CH_IR..CH_IR + ir::SENSORS]);
        let mut light = [0.0; ir::SENSORS];
        light.copy_from_slice(&out[CH_LIGHT..CH_LIGHT + ir::SENSORS]);
        self.frames.push(Frame {
            ir: irv,
            light,
            barrier: out[CH_BARRIER] > 0.5,
            floor: out[CH_FLOOR],
            lamp_distance: out[CH_LAMP_DISTANCE],
            arm_down: scene.arm_down,
            claw_closed: scene.claw_closed,
            wheels: self.wheels,
            objects: object_rows(&scene),
        });
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
/// [`shaping_runtime::controller::run_episode`] does.
pub fn run_recorded(
    stage: &shaping_runtime::program::Stage,
    genome: &shaping_runtime::genome::Genome,
    opts: &shaping_runtime::controller::EpisodeOptions,
) -> Result<(shaping_runtime::controller::EpisodeResult, Trace, Episode), String> {
    use shaping_runtime::controller::{episode_rngs, Controller};
    let (sim_seed, rng) = episode_rngs(opts.seed);
    let mut ctl = Controller::new(stage, genome, rng).map_err(|e| format!("stage `{}`: {e}", stage.name))?;
    let mut sim = Sim::new(&stage.world, sim_seed);
    let scene = sim.scene();
    let mut trace = Trace::default();
    let mut rec = Recorder::new(&mut sim);
    let result = ctl.run(&mut rec, opts, Some(&mut trace));
    let frames = rec.frames;
    let ep = episode(stage, opts.seed, opts.learning, &trace, &[Part { stage: &stage.name, scene, frames }]);
    Ok((result, trace, ep))
}
