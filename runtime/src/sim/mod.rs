//! The simulated Khepera world: a differential-drive body in a rectangular
//! arena, 8 IR proximity and ambient-light sensors, a battery recharged at a
//! bar under a lamp, and objects the gripper can catch and throw out.
//!
//! Frame: origin at the arena's south-west corner, x east (`arena[0]` wide),
//! y north (`arena[1]` deep), headings counter-clockwise from +x, mm.
//!
//! One [`Sim`] is one episode. Everything random (start pose, object
//! placement, wheel and sensor noise) comes from one `ChaCha8Rng` seeded with
//! the `seed` given to [`Sim::new`], so the same seed and commands give the
//! same trajectory. [`Sim::sense`] and [`Sim::step`] never allocate.
//!
//! The models, in brief (constants below and in [`ir`]):
//! - motion: exact differential-drive arc per action, wheel travel
//!   `command * v_max * action_ms` times `1 +- wheel_noise`; a move whose end
//!   or middle would overlap a wall or a physical object is retraced in 1 mm
//!   substeps and stops before the overlap (`Outcome::collided`);
//! - IR: [`ir::KHEPERA`], fitted to real readings; walls and floor objects
//!   add up, clamped at 1, plus `+-sensor_noise`;
//! - light: a lamp above the bar's middle, irradiance falling as
//!   `1 / (rho^2 + h^2)` times a `cos(1.5 a)` lobe around each sensor's axis;
//! - battery: integer charge, `-1/capacity` per action, `+1/recharge` per
//!   action asked to charge with the body within [`CONTACT`] mm of the bar;
//! - gripper: arm and claw change at the start of the action; closing the
//!   claw on an object in the catch zone grips it (a grip event only the
//!   first time for each object); opening it with a wall
//!   ahead throws the object out (a virtual one comes back elsewhere),
//!   otherwise drops it in front.

// Loops over the 8 sensors index several parallel arrays.
#![allow(clippy::needless_range_loop)]

pub mod ir;
mod scene;

use rand::{Rng, RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::catalog::{CHANNELS, CH_BARRIER, CH_BATTERY, CH_IR, CH_LIGHT};
use crate::program::{Wall, World};

pub use scene::{ObjectState, Scene, SceneObject};

/// What the controller asks of the robot for one action.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Command {
    /// Wheel speeds, -1..1 of `v_max`.
    pub wheels: [f32; 2],
    /// Move the arm (`Some(true)` = down), or leave it.
    pub arm: Option<bool>,
    /// Move the claw (`Some(true)` = closed), or leave it.
    pub claw: Option<bool>,
    /// Ask the charger to recharge (only works in contact with the bar).
    pub charge: bool,
}

/// What happened during one action.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Outcome {
    pub grips: u32,
    pub releases_outside: u32,
    pub recharged: bool,
    pub collided: bool,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pose {
    pub x: f32,
    pub y: f32,
    /// Heading, radians, counter-clockwise from +x.
    pub theta: f32,
}

/// Minimum clearance between the body and the walls at the start, mm.
pub const START_CLEARANCE: f32 = 40.0;
/// Minimum clearance between objects and the walls when placed, mm.
pub const OBJECT_CLEARANCE: f32 = 30.0;
/// The body is in contact with the bar when its surface is this close, mm.
pub const CONTACT: f32 = 3.0;
/// Catch zone of the gripper: object centres from this far beyond the body
/// surface, mm ...
pub const CATCH_NEAR: f32 = 5.0;
/// ... to this far, mm ...
pub const CATCH_FAR: f32 = 30.0;
/// ... and at most this far to either side of the heading, mm: half the open
/// claw's gap (about 27-29 mm on the K-Team gripper), which also covers the
/// +-20 degree dead band of `toward(...)` at catch distance (the spec's +-8
/// mm made a `toward(ir); arm down; back until barrier` sequence miss).
pub const CATCH_HALF_WIDTH: f32 = 15.0;
/// Opening the claw throws the object out when the body surface is this
/// close to a wall, mm ...
pub const RELEASE_REACH: f32 = 20.0;
/// ... and the wall's normal is within this angle of the heading, degrees.
pub const RELEASE_ANGLE_DEG: f32 = 30.0;
/// Horizontal distance from the lamp at which a sensor facing it reads 1, mm.
pub const LAMP_FULL: f32 = 100.0;
/// Largest number of objects simulated (a safety cap on the declaration).
pub const MAX_OBJECTS: usize = 1024;
/// Longest distance a wheel moves between collision checks when a move
/// collides, mm.
const SUBSTEP: f32 = 1.0;
/// Attempts at a random free position before giving up.
const PLACE_TRIES: u32 = 1000;
/// Attempts for all the objects of a world together (a crowded world is
/// filled quickly, overlaps allowed, instead of slowly).
const PLACE_BUDGET: u32 = 20_000;

/// One object of the world.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Obj {
    x: f32,
    y: f32,
    state: ObjectState,
    /// Gripped before: gripping it again (after a drop inside the arena) is
    /// not a new grip event, so fitness cannot be farmed on one object.
    gripped: bool,
}

/// One simulated episode's world state.
#[derive(Clone, Debug)]
pub struct Sim {
    rng: ChaCha8Rng,
    // world
    width: f32,
    depth: f32,
    radius: f32,
    half_axle: f32,
    /// Wheel travel for a command of 1.0 during one action, mm.
    travel: f32,
    wheel_noise: f32,
    sensor_noise: f32,
    bar: Option<[[f32; 2]; 2]>,
    /// Lamp (x, y), height and the intensity constant.
    lamp: Option<([f32; 2], f32, f32)>,
    /// Battery capacity and recharge time in actions (`None`: no battery).
    battery_spec: Option<(u64, u64)>,
    obj_radius: f32,
    obj_virtual: bool,
    objects: Vec<Obj>,
    // precomputed IR
    geo: ir::Geometry,
    wall_k: ir::Coeffs,
    cyl_k: ir::Coeffs,
    // state
    pose: Pose,
    cos_t: f32,
    sin_t: f32,
    /// Battery charge in units of `1 / (capacity * recharge)`.
    charge: u64,
    arm_down: bool,
    claw_closed: bool,
    held: Option<usize>,
    /// Distance each wheel travelled during the last action, mm (what a real
    /// robot's wheel encoders measure).
    travelled: [f32; 2],
}

/// A uniform draw in `lo..hi` that never panics (the middle if `hi <= lo`).
fn uniform(rng: &mut ChaCha8Rng, lo: f32, hi: f32) -> f32 {
    let u: f32 = rng.random();
    if hi > lo {
        lo + (hi - lo) * u
    } else {
        (lo + hi) / 2.0
    }
}

/// Two uniform draws in `-n..n` from one 32-bit word (16 bits each: plenty
/// for noise, and half the generator work).
fn noise_pair(rng: &mut ChaCha8Rng, n: f32) -> (f32, f32) {
    let u: u32 = rng.random();
    let scale = 2.0 * n / 65535.0;
    ((u & 0xffff) as f32 * scale - n, (u >> 16) as f32 * scale - n)
}

/// `sin(x) / x`, given `sin(x)`.
fn sinc(x: f32, sin_x: f32) -> f32 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        sin_x / x
    }
}

fn finite_or(x: f32, default: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        default
    }
}

fn wrap_angle(t: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    if (-PI..=PI).contains(&t) {
        t
    } else {
        t - TAU * ((t + PI) / TAU).floor()
    }
}

impl Sim {
    /// A fresh world for one episode; everything random comes from `seed`.
    pub fn new(world: &World, seed: u64) -> Sim {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let body = &world.body;
        let width = finite_or(world.arena[0], 0.0).max(1.0);
        let depth = finite_or(world.arena[1], 0.0).max(1.0);
        let radius = finite_or(body.radius, 27.5).max(0.1);
        let half_axle = finite_or(body.wheel_base, 53.0).max(0.1) / 2.0;
        let travel = finite_or(body.v_max * body.action_ms / 1000.0, 0.0).max(0.0);
        let bar = world.charger.as_ref().map(|c| bar_segment(c.wall, c.length, width, depth));
        let lamp = world.charger.as_ref().and_then(|c| {
            let h = finite_or(c.lamp_height?, 150.0).max(0.0);
            let b = bar_segment(c.wall, c.length, width, depth);
            let mid = [(b[0][0] + b[1][0]) / 2.0, (b[0][1] + b[1][1]) / 2.0];
            Some((mid, h, LAMP_FULL * LAMP_FULL + h * h))
        });
        let battery_spec =
            world.battery.as_ref().map(|b| (u64::from(b.capacity.max(1)), u64::from(b.recharge.max(1))));
        let (count, obj_radius, obj_virtual) = match &world.objects {
            Some(o) => (
                o.count.min(MAX_OBJECTS as u32) as usize,
                finite_or(o.diameter, 10.0).max(0.2) / 2.0,
                o.virtual_,
            ),
            None => (0, 5.0, true),
        };
        let model = &ir::KHEPERA;
        let mut sim = Sim {
            rng: ChaCha8Rng::seed_from_u64(0),
            width,
            depth,
            radius,
            half_axle,
            travel,
            wheel_noise: finite_or(body.wheel_noise, 0.0).clamp(0.0, 1.0),
            sensor_noise: finite_or(body.sensor_noise, 0.0).clamp(0.0, 1.0),
            bar,
            lamp,
            battery_spec,
            obj_radius,
            obj_virtual,
            objects: Vec::with_capacity(count),
            geo: ir::Geometry::new(model, radius),
            wall_k: ir::Coeffs::new(&model.wall.reach, &model.wall),
            cyl_k: ir::Coeffs::new(&model.cylinder_reach(obj_radius), &model.cylinder),
            pose: Pose::default(),
            cos_t: 1.0,
            sin_t: 0.0,
            charge: battery_spec.map_or(0, |(c, r)| c * r),
            arm_down: false,
            claw_closed: false,
            held: None,
            travelled: [0.0; 2],
        };
        // Objects first, then the robot somewhere free.
        let mut budget = PLACE_BUDGET;
        for _ in 0..count {
            let ((x, y), used) = sim.free_spot(&mut rng, None, budget.min(PLACE_TRIES));
            budget = budget.saturating_sub(used);
            sim.objects.push(Obj { x, y, state: ObjectState::Floor, gripped: false });
        }
        let margin = radius + START_CLEARANCE;
        let mut pose = Pose { x: width / 2.0, y: depth / 2.0, theta: 0.0 };
        for _ in 0..PLACE_TRIES {
            let x = uniform(&mut rng, margin, width - margin);
            let y = uniform(&mut rng, margin, depth - margin);
            pose = Pose { x, y, theta: 0.0 };
            let clear = sim.objects.iter().all(|o| {
                let d = radius + sim.obj_radius + 2.0;
                (o.x - x).powi(2) + (o.y - y).powi(2) >= d * d
            });
            if clear {
                break;
            }
        }
        pose.theta = uniform(&mut rng, -std::f32::consts::PI, std::f32::consts::PI);
        sim.set_pose_unchecked(pose);
        sim.rng = rng;
        sim
    }

    /// A random position for an object centre, at least [`OBJECT_CLEARANCE`]
    /// from the walls and not overlapping other floor objects (nor the robot
    /// when `robot` is given). Gives up after `tries` (at least one) and
    /// returns the last try; also returns the number of tries used.
    fn free_spot(&self, rng: &mut ChaCha8Rng, robot: Option<Pose>, tries: u32) -> ((f32, f32), u32) {
        let r = self.obj_radius;
        let m = r + OBJECT_CLEARANCE;
        let mut spot = (self.width / 2.0, self.depth / 2.0);
        let mut used = 0;
        while used < tries.max(1) {
            used += 1;
            let x = uniform(rng, m, self.width - m);
            let y = uniform(rng, m, self.depth - m);
            spot = (x, y);
            let clear_objects = self.objects.iter().all(|o| {
                o.state != ObjectState::Floor || (o.x - x).powi(2) + (o.y - y).powi(2) >= 4.0 * r * r
            });
            let clear_robot = robot.is_none_or(|p| {
                let d = self.radius + r + 2.0;
                (p.x - x).powi(2) + (p.y - y).powi(2) >= d * d
            });
            if clear_objects && clear_robot {
                break;
            }
        }
        (spot, used)
    }

    fn set_pose_unchecked(&mut self, pose: Pose) {
        let theta = wrap_angle(finite_or(pose.theta, 0.0));
        self.pose = Pose { x: finite_or(pose.x, 0.0), y: finite_or(pose.y, 0.0), theta };
        let (s, c) = theta.sin_cos();
        self.sin_t = s;
        self.cos_t = c;
    }

    /// Puts the robot at `pose` (for tests and tools). Returns false, and
    /// leaves the robot where it was, if the body would overlap a wall or a
    /// physical object.
    pub fn set_pose(&mut self, pose: Pose) -> bool {
        if !self.free(pose.x, pose.y) {
            return false;
        }
        self.set_pose_unchecked(pose);
        true
    }

    /// Moves object `index` (on the floor) to `(x, y)` (for tests and tools).
    /// Returns false if there is no such object or it is not on the floor.
    pub fn set_object(&mut self, index: usize, x: f32, y: f32) -> bool {
        match self.objects.get_mut(index) {
            Some(o) if o.state == ObjectState::Floor && x.is_finite() && y.is_finite() => {
                o.x = x;
                o.y = y;
                true
            }
            _ => false,
        }
    }

    /// True when the body centred at `(x, y)` overlaps no wall and no
    /// physical object on the floor.
    fn free(&self, x: f32, y: f32) -> bool {
        let r = self.radius;
        if !(x >= r && x <= self.width - r && y >= r && y <= self.depth - r) {
            return false;
        }
        if self.obj_virtual {
            return true;
        }
        let d = r + self.obj_radius;
        let d2 = d * d;
        self.objects
            .iter()
            .all(|o| o.state != ObjectState::Floor || (o.x - x).powi(2) + (o.y - y).powi(2) >= d2)
    }

    /// Fills the percept channels for the current state.
    pub fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        let mut irv = [0.0f32; ir::SENSORS];
        self.sense_ir(&mut irv);
        let mut light = [0.0f32; ir::SENSORS];
        self.sense_light(&mut light);
        let n = self.sensor_noise;
        if n > 0.0 {
            // 16 bits of randomness per channel, one generator call.
            let mut bits = [0u8; 4 * ir::SENSORS];
            self.rng.fill_bytes(&mut bits);
            let scale = 2.0 * n / 65535.0;
            let noise = |k: usize| f32::from(u16::from_le_bytes([bits[2 * k], bits[2 * k + 1]])) * scale - n;
            for s in 0..ir::SENSORS {
                irv[s] += noise(s);
                light[s] += noise(ir::SENSORS + s);
            }
        }
        for s in 0..ir::SENSORS {
            out[CH_IR + s] = irv[s].clamp(0.0, 1.0);
            out[CH_LIGHT + s] = light[s].clamp(0.0, 1.0);
        }
        out[CH_BATTERY] = self.battery();
        out[CH_BARRIER] = if self.barrier() { 1.0 } else { 0.0 };
    }

    /// Noise-free IR readings of the current state: walls, then objects.
    fn sense_ir(&self, out: &mut [f32; ir::SENSORS]) {
        self.ir_walls(out);
        self.ir_objects(out);
    }

    /// Adds the walls' noise-free IR readings to `out`.
    fn ir_walls(&self, out: &mut [f32; ir::SENSORS]) {
        let wt = &ir::tables().0;
        let Pose { x, y, .. } = self.pose;
        let (c, s) = (self.cos_t, self.sin_t);
        let g = &self.geo;
        let reach = self.radius + ir::RANGE;
        // Walls: (distance from the centre, outward normal in the world frame).
        let walls = [(x, -1.0, 0.0), (self.width - x, 1.0, 0.0), (y, 0.0, -1.0), (self.depth - y, 0.0, 1.0)];
        for &(dist, wx, wy) in &walls {
            if dist > reach {
                continue;
            }
            // The normal in the robot frame.
            let nx = wx * c + wy * s;
            let ny = -wx * s + wy * c;
            for k in 0..ir::SENSORS {
                let d = dist - (g.px[k] * nx + g.py[k] * ny);
                let cos_a = g.ax[k] * nx + g.ay[k] * ny;
                out[k] += wt.get(self.wall_k.z(k, d, cos_a));
            }
        }
    }

    /// Adds the floor objects' noise-free IR readings to `out`.
    fn ir_objects(&self, out: &mut [f32; ir::SENSORS]) {
        let ct = &ir::tables().1;
        let Pose { x, y, .. } = self.pose;
        let (c, s) = (self.cos_t, self.sin_t);
        let g = &self.geo;
        let reach = self.radius + ir::RANGE;
        let r = self.obj_radius;
        let reach = reach + r;
        let reach2 = reach * reach;
        for o in &self.objects {
            if o.state != ObjectState::Floor {
                continue;
            }
            let dx = o.x - x;
            let dy = o.y - y;
            if dx * dx + dy * dy > reach2 {
                continue;
            }
            let mut rx = dx * c + dy * s;
            let mut ry = -dx * s + dy * c;
            // Closer than the nearest measured distance (a virtual object under
            // the body): read it as if it were at that distance, same bearing.
            let near = self.radius + r + ir::NEAREST;
            let d2 = rx * rx + ry * ry;
            if d2 < near * near {
                let d = d2.sqrt();
                let (ux, uy) = if d > 1e-3 { (rx / d, ry / d) } else { (1.0, 0.0) };
                rx = ux * near;
                ry = uy * near;
            }
            for k in 0..ir::SENSORS {
                let vx = rx - g.px[k];
                let vy = ry - g.py[k];
                let dist = (vx * vx + vy * vy).sqrt().max(1e-3);
                let cos_a = (g.ax[k] * vx + g.ay[k] * vy) / dist;
                out[k] += ct.get(self.cyl_k.z(k, dist - r, cos_a));
            }
        }
    }

    /// Noise-free ambient light readings: the lamp's irradiance
    /// `K / (rho^2 + h^2)` (rho the horizontal distance, h the lamp height,
    /// `K` such that a sensor facing the lamp from [`LAMP_FULL`] mm reads 1)
    /// times the lobe `cos(1.5 a)` for a horizontal bearing `|a| < 60` degrees
    /// off the sensor's axis (0 beyond), clamped at 1.
    fn sense_light(&self, out: &mut [f32; ir::SENSORS]) {
        let Some(([lx, ly], h, k)) = self.lamp else {
            return;
        };
        let dx = lx - self.pose.x;
        let dy = ly - self.pose.y;
        let (c, s) = (self.cos_t, self.sin_t);
        let rx = dx * c + dy * s;
        let ry = -dx * s + dy * c;
        let rho2 = rx * rx + ry * ry;
        let intensity = k / (rho2 + h * h);
        let rho = rho2.sqrt();
        let g = &self.geo;
        for i in 0..ir::SENSORS {
            // cos of the bearing off the axis; straight below the lamp every
            // sensor sees it head-on.
            let cos_a = if rho > 1e-3 { (g.ax[i] * rx + g.ay[i] * ry) / rho } else { 1.0 };
            // cos(1.5 a) = 4 q^3 - 3 q with q = cos(a / 2).
            let q = ((1.0 + cos_a) * 0.5).max(0.0).sqrt();
            let lobe = (4.0 * q * q * q - 3.0 * q).max(0.0);
            out[i] = (intensity * lobe).min(1.0);
        }
    }

    /// The optical barrier: arm down, claw open and an object centre in the
    /// catch zone, or an object held.
    fn barrier(&self) -> bool {
        self.held.is_some() || (self.arm_down && !self.claw_closed && self.catchable().is_some())
    }

    /// The floor object whose centre lies in the catch zone (the nearest).
    fn catchable(&self) -> Option<usize> {
        let (c, s) = (self.cos_t, self.sin_t);
        let mut best: Option<(usize, f32)> = None;
        for (i, o) in self.objects.iter().enumerate() {
            if o.state != ObjectState::Floor {
                continue;
            }
            let dx = o.x - self.pose.x;
            let dy = o.y - self.pose.y;
            let fwd = dx * c + dy * s - self.radius;
            let side = -dx * s + dy * c;
            if (CATCH_NEAR..=CATCH_FAR).contains(&fwd)
                && side.abs() <= CATCH_HALF_WIDTH
                && best.is_none_or(|(_, f)| fwd < f)
            {
                best = Some((i, fwd));
            }
        }
        best.map(|(i, _)| i)
    }

    /// Executes one action.
    pub fn step(&mut self, cmd: &Command) -> Outcome {
        if !self.alive() {
            return Outcome::default();
        }
        let mut out = self.actuate(cmd);
        out.collided = self.drive(cmd.wheels);
        out.recharged = self.tick_battery(cmd.charge);
        out
    }

    /// The gripper part of an action (arm, then claw, at the current pose):
    /// grips and releases. [`Sim::step`] calls it before moving; a host
    /// simulating the virtual objects of a real robot calls it on its own.
    pub fn actuate(&mut self, cmd: &Command) -> Outcome {
        let mut out = Outcome::default();
        if let Some(down) = cmd.arm {
            self.arm_down = down;
        }
        match cmd.claw {
            Some(true) if !self.claw_closed => {
                if self.held.is_none() && self.arm_down {
                    if let Some(i) = self.catchable() {
                        let obj = &mut self.objects[i];
                        obj.state = ObjectState::Held;
                        out.grips += u32::from(!obj.gripped);
                        obj.gripped = true;
                        self.held = Some(i);
                    }
                }
                self.claw_closed = true;
            }
            Some(false) if self.claw_closed && self.release(&mut out) => self.claw_closed = false,
            _ => {}
        }
        out
    }

    /// The battery part of an action, after the move: recharges when asked
    /// to in contact with the bar, else drains one action's worth. Returns
    /// true when this action filled the battery.
    pub fn tick_battery(&mut self, charge: bool) -> bool {
        let Some((cap, rech)) = self.battery_spec else {
            return false;
        };
        let full = cap * rech;
        if charge && self.in_contact() {
            if self.charge < full {
                self.charge = (self.charge + cap).min(full);
                return self.charge == full;
            }
        } else {
            self.charge = self.charge.saturating_sub(rech);
        }
        false
    }

    /// Opens the claw on a held object: throws it out of the arena when a
    /// wall is within reach ahead, else drops it in front. Returns false (the
    /// claw stays closed) only if the object cannot be put down anywhere.
    fn release(&mut self, out: &mut Outcome) -> bool {
        let Some(i) = self.held else {
            return true;
        };
        if self.wall_ahead() {
            self.held = None;
            out.releases_outside += 1;
            if self.obj_virtual {
                let mut rng = self.rng.clone();
                let ((x, y), _) = self.free_spot(&mut rng, Some(self.pose), PLACE_TRIES);
                self.rng = rng;
                self.objects[i] = Obj { x, y, state: ObjectState::Floor, gripped: false };
            } else {
                self.objects[i].state = ObjectState::Outside;
            }
            return true;
        }
        let r = self.obj_radius;
        let ahead = self.radius + ((CATCH_NEAR + CATCH_FAR) / 2.0).max(r + 1.0);
        let x = (self.pose.x + ahead * self.cos_t).clamp(r, (self.width - r).max(r));
        let y = (self.pose.y + ahead * self.sin_t).clamp(r, (self.depth - r).max(r));
        let d = self.radius + r;
        if !self.obj_virtual && (x - self.pose.x).powi(2) + (y - self.pose.y).powi(2) < d * d {
            return false;
        }
        self.objects[i] = Obj { x, y, state: ObjectState::Floor, gripped: true };
        self.held = None;
        true
    }

    /// A wall within [`RELEASE_REACH`] of the body surface, within
    /// [`RELEASE_ANGLE_DEG`] of the heading.
    fn wall_ahead(&self) -> bool {
        let Pose { x, y, .. } = self.pose;
        let reach = self.radius + RELEASE_REACH;
        let cos_max = RELEASE_ANGLE_DEG.to_radians().cos();
        let walls = [(x, -1.0, 0.0), (self.width - x, 1.0, 0.0), (y, 0.0, -1.0), (self.depth - y, 0.0, 1.0)];
        walls.iter().any(|&(dist, wx, wy)| dist <= reach && wx * self.cos_t + wy * self.sin_t >= cos_max)
    }

    /// The body surface within [`CONTACT`] of the charger bar.
    fn in_contact(&self) -> bool {
        let Some([a, b]) = self.bar else {
            return false;
        };
        let (px, py) = (self.pose.x - a[0], self.pose.y - a[1]);
        let (ux, uy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = ux * ux + uy * uy;
        let t = if len2 > 0.0 { ((px * ux + py * uy) / len2).clamp(0.0, 1.0) } else { 0.0 };
        let (dx, dy) = (px - t * ux, py - t * uy);
        let reach = self.radius + CONTACT;
        dx * dx + dy * dy <= reach * reach
    }

    /// Moves the body for one action; returns true on a collision. The exact
    /// arc is taken in one go when its end and middle are free; otherwise it
    /// is retraced in substeps of at most [`SUBSTEP`] mm of wheel travel and
    /// stops before the first substep that would overlap.
    fn drive(&mut self, wheels: [f32; 2]) -> bool {
        let mut dl = finite_or(wheels[0], 0.0).clamp(-1.0, 1.0) * self.travel;
        let mut dr = finite_or(wheels[1], 0.0).clamp(-1.0, 1.0) * self.travel;
        if self.wheel_noise > 0.0 {
            let (a, b) = noise_pair(&mut self.rng, self.wheel_noise);
            dl *= 1.0 + a;
            dr *= 1.0 + b;
        }
        self.travelled = [dl, dr];
        if dl == 0.0 && dr == 0.0 {
            return false;
        }
        let start = self.pose;
        // The exact arc (spec 1.3) in chord form: the centre moves by
        // `d * sinc(phi / 2)` along `theta + phi / 2`, and halfway by
        // `d / 2 * sinc(phi / 4)` along `theta + phi / 4`. One `sin_cos` of
        // `phi / 4` and the cached heading give everything by double angles.
        let d = (dl + dr) / 2.0;
        let phi = (dr - dl) / (2.0 * self.half_axle);
        let q = phi / 4.0;
        let (s1, c1) = q.sin_cos();
        let (s2, c2) = (2.0 * s1 * c1, c1 * c1 - s1 * s1);
        let (s4, c4) = (2.0 * s2 * c2, c2 * c2 - s2 * s2);
        let (c0, s0) = (self.cos_t, self.sin_t);
        let rot = |c: f32, s: f32| (c0 * c - s0 * s, s0 * c + c0 * s);
        let (ce, se) = rot(c2, s2);
        let len = d * sinc(2.0 * q, s2);
        let (ex, ey) = (start.x + len * ce, start.y + len * se);
        let (cm, sm) = rot(c1, s1);
        let half = d / 2.0 * sinc(q, s1);
        let (mx, my) = (start.x + half * cm, start.y + half * sm);
        if self.free(ex, ey) && self.free(mx, my) {
            let (ct, st) = rot(c4, s4);
            let norm = 1.0 / (ct * ct + st * st).sqrt();
            self.pose = Pose { x: ex, y: ey, theta: wrap_angle(start.theta + phi) };
            self.cos_t = ct * norm;
            self.sin_t = st * norm;
            return false;
        }
        // Retrace in `n` equal sub-arcs: each moves the centre by the chord
        // `len` along the current heading turned by half its angle, then
        // turns the heading by its angle (rotations, no more `sin_cos`).
        let n = ((dl.abs().max(dr.abs()) / SUBSTEP).ceil() as u32).clamp(1, 10_000);
        let sub = phi / n as f32;
        let (sh, ch) = (sub / 2.0).sin_cos();
        let (sf, cf) = (2.0 * sh * ch, ch * ch - sh * sh);
        let len = d / n as f32 * sinc(sub / 2.0, sh);
        let (mut x, mut y, mut c, mut s) = (start.x, start.y, c0, s0);
        let mut k = 0;
        while k < n {
            let (nx, ny) = (x + len * (c * ch - s * sh), y + len * (s * ch + c * sh));
            if !self.free(nx, ny) {
                break;
            }
            (x, y, c, s) = (nx, ny, c * cf - s * sf, s * cf + c * sf);
            k += 1;
        }
        let norm = 1.0 / (c * c + s * s).sqrt();
        self.travelled = [dl * k as f32 / n as f32, dr * k as f32 / n as f32];
        self.pose = Pose { x, y, theta: wrap_angle(start.theta + sub * k as f32) };
        self.cos_t = c * norm;
        self.sin_t = s * norm;
        k < n
    }

    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// Distance each wheel (left, right) travelled during the last action,
    /// mm, noise included; less than commanded when a collision stopped the
    /// move.
    pub fn wheel_travel(&self) -> [f32; 2] {
        self.travelled
    }

    /// Puts the body at `pose` without any check: the pose a real robot's
    /// odometry measured, for a host that simulates its virtual objects and
    /// battery.
    pub fn place(&mut self, pose: Pose) {
        self.set_pose_unchecked(pose);
    }

    /// The part of the percept a host simulates for a real robot: the IR
    /// readings of the virtual objects alone (no walls, no noise: the robot
    /// senses those), the battery and the optical barrier. Light channels
    /// are 0.
    pub fn sense_virtual(&self, out: &mut [f32; CHANNELS]) {
        let mut irv = [0.0f32; ir::SENSORS];
        if self.obj_virtual {
            self.ir_objects(&mut irv);
        }
        for s in 0..ir::SENSORS {
            out[CH_IR + s] = irv[s].clamp(0.0, 1.0);
            out[CH_LIGHT + s] = 0.0;
        }
        out[CH_BATTERY] = self.battery();
        out[CH_BARRIER] = if self.barrier() { 1.0 } else { 0.0 };
    }

    /// Battery level 0..1 (1 forever without a battery).
    pub fn battery(&self) -> f32 {
        match self.battery_spec {
            Some((c, r)) => (self.charge as f64 / (c * r) as f64) as f32,
            None => 1.0,
        }
    }

    /// False once the battery is empty.
    pub fn alive(&self) -> bool {
        self.battery_spec.is_none() || self.charge > 0
    }

    /// True while the gripper holds an object.
    pub fn holding(&self) -> bool {
        self.held.is_some()
    }

    pub fn arm_down(&self) -> bool {
        self.arm_down
    }

    pub fn claw_closed(&self) -> bool {
        self.claw_closed
    }

    /// Plain data describing the current state, for pictures.
    pub fn scene(&self) -> Scene {
        Scene {
            arena: [self.width, self.depth],
            bar: self.bar,
            lamp: self.lamp.map(|(p, _, _)| p),
            objects: self
                .objects
                .iter()
                .map(|o| {
                    let (x, y) = if o.state == ObjectState::Held {
                        let a = self.radius + (CATCH_NEAR + CATCH_FAR) / 2.0;
                        (self.pose.x + a * self.cos_t, self.pose.y + a * self.sin_t)
                    } else {
                        (o.x, o.y)
                    };
                    SceneObject { x, y, radius: self.obj_radius, virtual_: self.obj_virtual, state: o.state }
                })
                .collect(),
            pose: self.pose,
            body_radius: self.radius,
            arm_down: self.arm_down,
            claw_closed: self.claw_closed,
        }
    }
}

/// The bar's end points: centred on `wall`, flush with it.
fn bar_segment(wall: Wall, length: f32, width: f32, depth: f32) -> [[f32; 2]; 2] {
    let along = match wall {
        Wall::North | Wall::South => width,
        Wall::East | Wall::West => depth,
    };
    let half = finite_or(length, 0.0).clamp(0.0, along) / 2.0;
    let mid = along / 2.0;
    match wall {
        Wall::North => [[mid - half, depth], [mid + half, depth]],
        Wall::South => [[mid - half, 0.0], [mid + half, 0.0]],
        Wall::East => [[width, mid - half], [width, mid + half]],
        Wall::West => [[0.0, mid - half], [0.0, mid + half]],
    }
}
