//! The simulated Khepera world: a differential-drive body in a rectangular
//! arena, 8 IR proximity and ambient-light sensors, a battery recharged at a
//! bar under a lamp, and objects the gripper can catch and throw out.
//!
//! Frame: origin at the arena's south-west corner, x east (`arena[0]` wide),
//! y north (`arena[1]` deep), headings counter-clockwise from +x, mm.
//!
//! Geometry is written on `nalgebra`'s fixed-size `f32` types: positions are
//! `Point2`, directions and offsets `Vector2`, the robot's pose an `Isometry2`
//! (its translation is the body centre, its `UnitComplex` rotation the
//! heading as `(cos, sin)`), so the body frame (x ahead, y to the left) maps
//! to the world by the pose. Sensors are fixed in the body frame
//! ([`ir::Geometry`]); walls, objects and the lamp are brought into the body
//! frame by the pose's inverse, once per surface rather than once per sensor.
//! [`Pose`] is the same pose as plain data for reports, traces and tests.
//!
//! One [`Sim`] is one episode. Everything random (start pose, object
//! placement, wheel and sensor noise) comes from one xoshiro256++ generator
//! ([`rng::Xoshiro256pp`]) seeded with the `seed` given to [`Sim::new`], so the same seed and commands give the
//! same trajectory. [`Sim::sense`] and [`Sim::step`] never allocate.
//!
//! The models, in brief (constants below and in [`ir`]):
//! - motion: exact differential-drive arc per action, wheel travel
//!   `command * v_max * action_ms` times `1 +- wheel_noise`; a move whose end
//!   or middle would overlap a wall or a physical object is retraced in 1 mm
//!   substeps and stops before the overlap (`Outcome::collided`);
//! - IR: [`ir::KHEPERA`], fitted to real readings; walls and floor objects
//!   add up, clamped at 1, plus `+-sensor_noise`;
//! - light: a lamp above the bar's middle (and the declared lamps),
//!   irradiance falling as `1 / (rho^2 + h^2)` times a `cos(1.5 a)` lobe
//!   around each sensor's axis; an inner wall or a cylinder across the line
//!   from a sensor to the point below a lamp shades the sensor from it;
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
pub mod rng;
mod scene;
pub mod simd;
mod team;

use crate::world::{segment_distance2, OBJECT_CLEARANCE, START_CLEARANCE};
use nalgebra::{Isometry2, Point2, UnitComplex, Vector2};
use rand::{Rng, RngCore, SeedableRng};
use rng::Xoshiro256pp;
use simd::{Kernel, Lanes};

use crate::catalog::{
    CHANNELS, CH_BARRIER, CH_BATTERY, CH_FLOOR, CH_IR, CH_LAMP_DISTANCE, CH_LIGHT, GROUND_SENSORS, SIGNALS,
};
use crate::program::{Wall, World};

pub use scene::{ObjectState, Scene, SceneObject, SceneZone};
pub use team::{robot_seed, Team};

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
    /// Set the values the robot broadcasts (each 0..1), or leave them.
    pub signal: Option<[f32; SIGNALS]>,
}

/// What happened during one action.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Outcome {
    pub grips: u32,
    pub releases_outside: u32,
    pub recharged: bool,
    pub collided: bool,
}

/// A pose as plain data: the body centre and the heading. The simulator
/// keeps it as an [`Isometry2`]; the two convert into each other.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pose {
    pub x: f32,
    pub y: f32,
    /// Heading, radians, counter-clockwise from +x.
    pub theta: f32,
}

impl From<Pose> for Isometry2<f32> {
    fn from(p: Pose) -> Isometry2<f32> {
        Isometry2::new(Vector2::new(p.x, p.y), p.theta)
    }
}

impl From<Isometry2<f32>> for Pose {
    /// The heading in `-pi..=pi`.
    fn from(iso: Isometry2<f32>) -> Pose {
        let t = iso.translation.vector;
        Pose { x: t.x, y: t.y, theta: iso.rotation.angle() }
    }
}

/// The body is in contact with the bar when its surface is this close, mm.
pub const CONTACT: f32 = 3.0;
/// Catch zone of the gripper: object centres from this far beyond the body
/// surface, mm ...
pub const CATCH_NEAR: f32 = 5.0;
/// ... to this far, mm ...
pub const CATCH_FAR: f32 = 30.0;
/// ... and at most this far to either side of the heading, mm: half the open
/// claw's gap (about 27-29 mm on the K-Team gripper), which also covers the
/// +-20 degree dead band of `toward(...)` at catch distance (a first +-8 mm
/// made a `toward(ir); arm down; back until barrier` sequence miss; the
/// gripper's numbers and their sources: `docs/language.md`, section 18).
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
    /// Centre (where it lay last, while held or outside).
    at: Point2<f32>,
    state: ObjectState,
    /// Gripped before: gripping it again (after a drop inside the arena) is
    /// not a new grip event, so fitness cannot be farmed on one object.
    gripped: bool,
}

/// One simulated episode's world state.
#[derive(Clone, Debug)]
pub struct Sim {
    rng: Xoshiro256pp,
    // world
    width: f32,
    depth: f32,
    radius: f32,
    half_axle: f32,
    /// Distance each wheel travelled during the last action, mm (what a real
    /// robot's wheel encoders measure).
    travelled: [f32; 2],
    /// Wheel travel for a command of 1.0 during one action, mm.
    travel: f32,
    wheel_noise: f32,
    sensor_noise: f32,
    /// The charger bar's end points.
    bar: Option<[Point2<f32>; 2]>,
    lamp: Option<Lamp>,
    /// Battery capacity and recharge time in actions (`None`: no battery).
    battery_spec: Option<(u64, u64)>,
    obj_radius: f32,
    obj_virtual: bool,
    objects: Vec<Obj>,
    /// Inner wall segments' end points.
    inner: Vec<[Point2<f32>; 2]>,
    cylinders: Vec<Cyl>,
    /// Declared lamps (the charger's is `lamp`).
    lamps: Vec<Lamp>,
    /// Some declared lamp switches on or off during the life.
    switches: bool,
    /// Actions done (the clock of the lamps' switches and the placements).
    actions: u32,
    /// Where the robot is put after the life's Nth action (`place`), in
    /// the order declared.
    places: Vec<(u32, Pose)>,
    /// Inner walls or cylinders may shade a sensor from a lamp.
    shades: bool,
    zones: Vec<FloorZone>,
    /// Where each ground sensor sits, body frame (the centre unless declared).
    ground: [Point2<f32>; GROUND_SENSORS],
    // precomputed IR
    geo: ir::Geometry,
    /// The sensors' positions and axes as lanes.
    lanes: SensorLanes,
    /// The per-sensor code's path (AVX2 where the CPU has it).
    path: simd::Path,
    wall_k: ir::Coeffs,
    cyl_k: ir::Coeffs,
    /// From this squared distance of its centre on, a floor object reads
    /// exactly 0 on every sensor ([`unseen_beyond2`]).
    obj_unseen2: f32,
    // state
    /// The body frame in the world frame.
    pose: Isometry2<f32>,
    /// Battery charge in units of `1 / (capacity * recharge)`.
    charge: u64,
    /// The last action charged: a charging bout is under way.
    charging: bool,
    /// The bout under way started at most half full: filling the battery
    /// counts as a recharge (once).
    bout_counts: bool,
    arm_down: bool,
    claw_closed: bool,
    held: Option<usize>,
    /// Placements (objects, the robot's start, virtual objects coming back)
    /// that ran out of tries and kept their last, overlapping, try.
    placement_failures: u32,
    // a team's
    /// The centres of the other robots near this one ([`Team`] fills it
    /// before this robot's action; empty for one robot): bodies its
    /// sensors see and its moves cannot overlap.
    others: Vec<Point2<f32>>,
    /// IR constants of another robot's body (a cylinder of the body radius).
    body_k: ir::Coeffs,
    /// The charger may serve this robot (false while another robot of the
    /// team holds it).
    charger_free: bool,
}

/// A physical cylinder with its IR constants.
#[derive(Clone, Copy, Debug)]
struct Cyl {
    at: Point2<f32>,
    radius: f32,
    k: ir::Coeffs,
}

/// A rectangle of the floor.
#[derive(Clone, Copy, Debug)]
struct FloorZone {
    min: Point2<f32>,
    max: Point2<f32>,
    grey: f32,
    charger: bool,
}

impl FloorZone {
    fn contains(&self, p: &Point2<f32>) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }
}

/// A lamp: the one above the charger, or a declared one.
#[derive(Clone, Copy, Debug)]
struct Lamp {
    /// Where it is, seen from above.
    at: Point2<f32>,
    height: f32,
    /// The intensity constant `K` of `K / (rho^2 + h^2)` (0 while off).
    k: f32,
    /// `K` while lit.
    lit: f32,
    /// Switches on (`true`) or off after this many actions.
    switch: Option<(u32, bool)>,
}

/// The sensors' positions and axes in the body frame, one array per
/// coordinate (what the lanes load), from [`ir::Geometry`].
#[derive(Clone, Copy, Debug)]
struct SensorLanes {
    pos_x: [f32; ir::SENSORS],
    pos_y: [f32; ir::SENSORS],
    ray_x: [f32; ir::SENSORS],
    ray_y: [f32; ir::SENSORS],
}

impl SensorLanes {
    fn new(g: &ir::Geometry) -> SensorLanes {
        SensorLanes {
            pos_x: std::array::from_fn(|s| g.position(s).x),
            pos_y: std::array::from_fn(|s| g.position(s).y),
            ray_x: std::array::from_fn(|s| g.axis(s).x),
            ray_y: std::array::from_fn(|s| g.axis(s).y),
        }
    }
}

/// The log-intensity [`ir::Coeffs::z`] of every sensor.
#[inline(always)]
fn ir_z<L: Lanes>(k: &ir::Coeffs, d: L, cos_a: L) -> L {
    let lobe = L::load(&k.focus).mul(cos_a.sub(L::splat(1.0)));
    L::load(&k.offset).sub(d.mul(L::load(&k.inv_decay))).add(lobe)
}

/// One cylinder's readings by the sensors `g`: its centre `at` in the body
/// frame, its radius, its constants.
#[inline(always)]
fn cylinder_lanes<L: Lanes>(
    g: &SensorLanes,
    at: Vector2<f32>,
    radius: f32,
    k: &ir::Coeffs,
    ct: &ir::SatTable,
) -> L {
    let vx = L::splat(at.x).sub(L::load(&g.pos_x));
    let vy = L::splat(at.y).sub(L::load(&g.pos_y));
    let dist = vx.mul(vx).add(vy.mul(vy)).sqrt().max(L::splat(1e-3));
    let cos_a = L::load(&g.ray_x).mul(vx).add(L::load(&g.ray_y).mul(vy)).div(dist);
    simd::saturate(ir_z(k, dist.sub(L::splat(radius)), cos_a), ct)
}

/// The squared distance from the body centre beyond which a cylinder of
/// radius `r` with constants `k` reads exactly 0 on every sensor (infinite
/// if the constants give no such bound). A sensor's log-intensity is at most
/// `offset - d * inv_decay` (the lobe is never positive: focus >= 0, cosine
/// <= 1), which is below the saturation table's foot, where the lookup gives
/// exactly 0, once the sensor's distance `d` to the surface passes
/// `(offset - Z_MIN) / inv_decay`; and `d` is at least the centre's distance
/// less the sensor's distance from the body centre and `r`. One millimetre
/// more covers every rounding (a thousand times over), so skipping such an
/// object changes no reading's bits.
fn unseen_beyond2(g: &SensorLanes, k: &ir::Coeffs, r: f32) -> f32 {
    let (z_min, _) = ir::SatTable::SCALE;
    let mut far = 0.0f32;
    for s in 0..ir::SENSORS {
        if !(k.focus[s] >= 0.0 && k.inv_decay[s] > 0.0) {
            return f32::INFINITY;
        }
        let pos = g.pos_x[s].hypot(g.pos_y[s]);
        if !pos.is_finite() {
            return f32::INFINITY;
        }
        far = far.max(pos + (k.offset[s] - z_min) / k.inv_decay[s]);
    }
    let far = far + r + 1.0;
    if far.is_finite() {
        far * far
    } else {
        f32::INFINITY
    }
}

/// The noise-free readings of a state: IR (walls if `walls`, then
/// cylinders and objects; unclamped) and, if `light`, light (clamped at 1).
struct Readings<'a> {
    sim: &'a Sim,
    walls: bool,
    light: bool,
}

impl Kernel for Readings<'_> {
    type Out = ([f32; ir::SENSORS], [f32; ir::SENSORS]);

    #[inline(always)]
    fn run<L: Lanes>(self) -> Self::Out {
        let sim = self.sim;
        let mut acc = L::splat(0.0);
        if self.walls {
            acc = sim.ir_walls(acc);
        }
        acc = sim.ir_objects(acc);
        let (mut ir, mut light) = ([0.0; ir::SENSORS], [0.0; ir::SENSORS]);
        acc.store(&mut ir);
        if self.light {
            sim.light::<L>().store(&mut light);
        }
        (ir, light)
    }
}

/// The segments `p1 p2` and `q1 q2` cross or touch.
fn segments_cross(p1: &Point2<f32>, p2: &Point2<f32>, q1: &Point2<f32>, q2: &Point2<f32>) -> bool {
    let cross = |o: &Point2<f32>, a: &Point2<f32>, b: &Point2<f32>| (a - o).perp(&(b - o));
    let (d1, d2) = (cross(q1, q2, p1), cross(q1, q2, p2));
    let (d3, d4) = (cross(p1, p2, q1), cross(p1, p2, q2));
    let straddles = |a: f32, b: f32| (a <= 0.0 && b >= 0.0) || (a >= 0.0 && b <= 0.0);
    if !(straddles(d1, d2) && straddles(d3, d4)) {
        return false;
    }
    if d1 == 0.0 && d2 == 0.0 {
        // Collinear: they cross when their extents overlap.
        let overlap = |a: f32, b: f32, c: f32, d: f32| a.min(b) <= c.max(d) && c.min(d) <= a.max(b);
        return overlap(p1.x, p2.x, q1.x, q2.x) && overlap(p1.y, p2.y, q1.y, q2.y);
    }
    true
}

/// A uniform draw in `lo..hi` that never panics (the middle if `hi <= lo`).
fn uniform(rng: &mut Xoshiro256pp, lo: f32, hi: f32) -> f32 {
    let u: f32 = rng.random();
    if hi > lo {
        lo + (hi - lo) * u
    } else {
        (lo + hi) / 2.0
    }
}

/// Two uniform draws in `-n..n` from the high 32 bits of one generator word
/// (16 bits each: plenty for noise).
fn noise_pair(rng: &mut Xoshiro256pp, n: f32) -> (f32, f32) {
    let u = rng.next_u64() >> 32;
    let scale = 2.0 * n / 65535.0;
    ((u & 0xffff) as f32 * scale - n, (u >> 16) as f32 * scale - n)
}

/// `out.len()` uniform draws in `-n..n`, 16 bits each, four from each
/// generator word (lowest bits first).
#[inline]
fn noise_fill(rng: &mut Xoshiro256pp, n: f32, out: &mut [f32; 2 * ir::SENSORS]) {
    let scale = 2.0 * n / 65535.0;
    for quad in out.chunks_exact_mut(4) {
        let w = rng.next_u64();
        for (k, x) in quad.iter_mut().enumerate() {
            *x = ((w >> (16 * k)) & 0xffff) as f32 * scale - n;
        }
    }
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

/// The unit vector a rotation turns +x into: `(cos, sin)` of its angle.
fn direction(r: &UnitComplex<f32>) -> Vector2<f32> {
    Vector2::new(r.re, r.im)
}

/// `r` scaled back to length 1 (rounding drifts it over many products).
/// Written out rather than `UnitComplex::renormalize`, which divides by a
/// `hypot`: this form is cheaper and gives the simulator's historical bits.
fn renormalized(r: UnitComplex<f32>) -> UnitComplex<f32> {
    let c = r.into_inner();
    let inv = 1.0 / c.norm_sqr().sqrt();
    UnitComplex::new_unchecked(c * inv)
}

impl Sim {
    /// A fresh world for one episode; everything random comes from `seed`.
    pub fn new(world: &World, seed: u64) -> Sim {
        let mut rng = Xoshiro256pp::seed_from_u64(seed);
        let body = &world.body;
        let width = finite_or(world.arena[0], 0.0).max(1.0);
        let depth = finite_or(world.arena[1], 0.0).max(1.0);
        let radius = finite_or(body.radius, 27.5).max(0.1);
        let half_axle = finite_or(body.wheel_base, 53.0).max(0.1) / 2.0;
        let travel = finite_or(body.v_max * body.action_ms / 1000.0, 0.0).max(0.0);
        let bar = world.charger.as_ref().map(|c| bar_segment(c.wall, c.length, width, depth));
        let lamp = world.charger.as_ref().and_then(|c| {
            let h = finite_or(c.lamp_height?, 150.0).max(0.0);
            let [a, b] = bar_segment(c.wall, c.length, width, depth);
            let k = LAMP_FULL * LAMP_FULL + h * h;
            Some(Lamp { at: nalgebra::center(&a, &b), height: h, k, lit: k, switch: None })
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
        let geo = match &body.ir {
            Some(layout) => ir::Geometry::from_layout(layout, radius),
            None => ir::Geometry::new(model, radius),
        };
        let items = &world.items;
        let pt = |p: [f32; 2]| Point2::new(finite_or(p[0], 0.0), finite_or(p[1], 0.0));
        let inner: Vec<[Point2<f32>; 2]> = items.walls.iter().map(|w| [pt(w.from), pt(w.to)]).collect();
        let cylinders: Vec<Cyl> = items
            .cylinders
            .iter()
            .map(|c| {
                let radius = finite_or(c.diameter, 0.0).max(0.2) / 2.0;
                let k = ir::Coeffs::new(&model.cylinder_reach(radius), &model.cylinder);
                Cyl { at: pt(c.at), radius, k }
            })
            .collect();
        let lamps: Vec<Lamp> = items
            .lamps
            .iter()
            .map(|l| {
                let h = finite_or(l.height, 0.0).max(0.0);
                let lit = (LAMP_FULL * LAMP_FULL + h * h) * finite_or(l.intensity, 0.0).max(0.0);
                let switch = l.switch.map(|s| (s.at, s.on));
                // A lamp that switches on is off until then.
                let k = if switch.is_some_and(|(_, on)| on) { 0.0 } else { lit };
                Lamp { at: pt(l.at), height: h, k, lit, switch }
            })
            .collect();
        let zones = items
            .zones
            .iter()
            .map(|z| {
                let (a, b) = (pt(z.from), pt(z.to));
                FloorZone {
                    min: Point2::new(a.x.min(b.x), a.y.min(b.y)),
                    max: Point2::new(a.x.max(b.x), a.y.max(b.y)),
                    grey: finite_or(z.grey, 1.0).clamp(0.0, 1.0),
                    charger: z.charger,
                }
            })
            .collect();
        let mut sim = Sim {
            rng: Xoshiro256pp::seed_from_u64(0),
            width,
            depth,
            radius,
            half_axle,
            travelled: [0.0; 2],
            travel,
            wheel_noise: finite_or(body.wheel_noise, 0.0).clamp(0.0, 1.0),
            sensor_noise: finite_or(body.sensor_noise, 0.0).clamp(0.0, 1.0),
            bar,
            lamp,
            battery_spec,
            obj_radius,
            obj_virtual,
            objects: Vec::with_capacity(count),
            shades: !inner.is_empty() || !cylinders.is_empty(),
            inner,
            cylinders,
            switches: lamps.iter().any(|l: &Lamp| l.switch.is_some()),
            actions: 0,
            places: items
                .places
                .iter()
                .map(|p| {
                    let at = pt(p.at);
                    (p.after, Pose { x: at.x, y: at.y, theta: finite_or(p.heading, 0.0) })
                })
                .collect(),
            lamps,
            zones,
            ground: std::array::from_fn(|k| body.ground.get(k).map_or(Point2::origin(), |&p| pt(p))),
            geo,
            lanes: SensorLanes::new(&geo),
            path: simd::Path::Best,
            wall_k: ir::Coeffs::new(&model.wall.reach, &model.wall),
            cyl_k: ir::Coeffs::new(&model.cylinder_reach(obj_radius), &model.cylinder),
            obj_unseen2: f32::INFINITY,
            pose: Isometry2::identity(),
            charge: battery_spec.map_or(0, |(c, r)| c * r),
            charging: false,
            bout_counts: false,
            arm_down: false,
            claw_closed: false,
            held: None,
            placement_failures: 0,
            others: Vec::new(),
            body_k: ir::Coeffs::new(&model.cylinder_reach(radius), &model.cylinder),
            charger_free: true,
        };
        sim.obj_unseen2 = unseen_beyond2(&sim.lanes, &sim.cyl_k, obj_radius);
        // Objects first, then the robot somewhere free.
        let mut budget = PLACE_BUDGET;
        for _ in 0..count {
            let (at, used, free) = sim.free_spot(&mut rng, None, budget.min(PLACE_TRIES));
            budget = budget.saturating_sub(used);
            sim.placement_failures = sim.placement_failures.saturating_add(u32::from(!free));
            sim.objects.push(Obj { at, state: ObjectState::Floor, gripped: false });
        }
        sim.place_start(&items.start, &mut rng, &[]);
        sim.rng = rng;
        sim
    }

    /// Places the robot in the start region (`start`, or anywhere free) at
    /// the start's heading (or a random one), clear of the floor objects,
    /// the inner walls, the cylinders and the bodies centred at `robots`
    /// (a team's robots placed before it); counts a placement failure when
    /// every try overlaps.
    fn place_start(
        &mut self,
        start: &Option<crate::program::Start>,
        rng: &mut Xoshiro256pp,
        robots: &[Point2<f32>],
    ) {
        let (width, depth, radius) = (self.width, self.depth, self.radius);
        let pt = |p: [f32; 2]| Point2::new(finite_or(p[0], 0.0), finite_or(p[1], 0.0));
        let margin = radius + START_CLEARANCE;
        let (lo, hi) = match start {
            Some(s) => {
                let (a, b) = (pt(s.from), pt(s.to));
                (Point2::new(a.x.min(b.x), a.y.min(b.y)), Point2::new(a.x.max(b.x), a.y.max(b.y)))
            }
            None => (Point2::new(margin, margin), Point2::new(width - margin, depth - margin)),
        };
        let mut centre = Point2::new(width / 2.0, depth / 2.0);
        let mut placed = false;
        let apart = 2.0 * radius + 2.0;
        for _ in 0..PLACE_TRIES {
            let x = uniform(rng, lo.x, hi.x);
            let y = uniform(rng, lo.y, hi.y);
            centre = Point2::new(x, y);
            let d = radius + self.obj_radius + 2.0;
            if self.objects.iter().all(|o| (o.at - centre).norm_squared() >= d * d)
                && self.clear_of_items(&centre, radius + 2.0)
                && robots.iter().all(|r| (r - centre).norm_squared() >= apart * apart)
            {
                placed = true;
                break;
            }
        }
        self.placement_failures = self.placement_failures.saturating_add(u32::from(!placed));
        let theta = match start.as_ref().and_then(|s| s.heading) {
            Some(h) => finite_or(h, 0.0),
            None => uniform(rng, -std::f32::consts::PI, std::f32::consts::PI),
        };
        self.set_pose_unchecked(Pose { x: centre.x, y: centre.y, theta });
    }

    /// A random position for an object centre, at least [`OBJECT_CLEARANCE`]
    /// from the walls and not overlapping other floor objects (nor the robot
    /// when the robot's centre `robot` is given). Gives up after `tries` (at
    /// least one) and returns the last try; also returns the number of tries
    /// used and whether the spot is free (false: the last try, overlapping).
    fn free_spot(
        &self,
        rng: &mut Xoshiro256pp,
        robot: Option<Point2<f32>>,
        tries: u32,
    ) -> (Point2<f32>, u32, bool) {
        let r = self.obj_radius;
        let m = r + OBJECT_CLEARANCE;
        let mut spot = Point2::new(self.width / 2.0, self.depth / 2.0);
        let mut used = 0;
        while used < tries.max(1) {
            used += 1;
            let x = uniform(rng, m, self.width - m);
            let y = uniform(rng, m, self.depth - m);
            spot = Point2::new(x, y);
            let clear_objects = self
                .objects
                .iter()
                .all(|o| o.state != ObjectState::Floor || (o.at - spot).norm_squared() >= 4.0 * r * r);
            let clear_robot = robot.is_none_or(|p| {
                let d = self.radius + r + 2.0;
                (p - spot).norm_squared() >= d * d
            });
            if clear_objects && clear_robot && self.clear_of_items(&spot, r + 2.0) {
                return (spot, used, true);
            }
        }
        (spot, used, false)
    }

    /// How many placements of this episode so far ran out of tries and kept
    /// their last try, which overlaps another object, the robot, an inner
    /// wall or cylinder, or the walls' clearance: the objects at the start,
    /// the robot's start, and virtual objects coming back after a release
    /// outside. 0 in a world with room enough; otherwise the episode is not
    /// the world as declared, and its results should not be trusted (the
    /// CLI warns).
    pub fn placement_failures(&self) -> u32 {
        self.placement_failures
    }

    fn set_pose_unchecked(&mut self, pose: Pose) {
        let (x, y, theta) = (finite_or(pose.x, 0.0), finite_or(pose.y, 0.0), finite_or(pose.theta, 0.0));
        self.pose = Pose { x, y, theta }.into();
    }

    /// The body centre.
    fn centre(&self) -> Point2<f32> {
        self.pose.translation.vector.into()
    }

    /// The unit vector of the heading.
    fn heading(&self) -> Vector2<f32> {
        direction(&self.pose.rotation)
    }

    /// Puts the robot at `pose` (for tests and tools). Returns false, and
    /// leaves the robot where it was, if the body would overlap a wall or a
    /// physical object.
    pub fn set_pose(&mut self, pose: Pose) -> bool {
        if !self.free(&Point2::new(pose.x, pose.y)) {
            return false;
        }
        self.set_pose_unchecked(pose);
        true
    }

    /// Moves object `index` (on the floor) to `(x, y)` (for tests and tools).
    /// Returns false if there is no such object, it is not on the floor, or
    /// its disc at `(x, y)` would not lie within the arena's walls.
    pub fn set_object(&mut self, index: usize, x: f32, y: f32) -> bool {
        let r = self.obj_radius;
        let inside = x >= r && x <= self.width - r && y >= r && y <= self.depth - r;
        match self.objects.get_mut(index) {
            Some(o) if o.state == ObjectState::Floor && inside => {
                o.at = Point2::new(x, y);
                true
            }
            _ => false,
        }
    }

    /// True when a disc of radius `r` centred at `p` overlaps no inner wall
    /// and no cylinder (true at once in a world without them).
    fn clear_of_items(&self, p: &Point2<f32>, r: f32) -> bool {
        self.inner.iter().all(|[a, b]| segment_distance2(p, a, b) >= r * r)
            && self.cylinders.iter().all(|c| (c.at - p).norm_squared() >= (r + c.radius) * (r + c.radius))
    }

    /// True when the body centred at `p` overlaps no wall, no cylinder and
    /// no physical object on the floor.
    fn free(&self, p: &Point2<f32>) -> bool {
        let r = self.radius;
        if !(p.x >= r && p.x <= self.width - r && p.y >= r && p.y <= self.depth - r) {
            return false;
        }
        if !self.clear_of_items(p, r) {
            return false;
        }
        let apart2 = 4.0 * r * r;
        if !self.others.iter().all(|o| (o - p).norm_squared() >= apart2) {
            return false;
        }
        if self.obj_virtual {
            return true;
        }
        let d = r + self.obj_radius;
        let d2 = d * d;
        self.objects.iter().all(|o| o.state != ObjectState::Floor || (o.at - p).norm_squared() >= d2)
    }

    /// The four walls seen from `p`: distance to each and its outward unit
    /// normal (west, east, south, north).
    fn walls(&self, p: &Point2<f32>) -> [(f32, Vector2<f32>); 4] {
        let (x, y) = (Vector2::x(), Vector2::y());
        [(p.x, -x), (self.width - p.x, x), (p.y, -y), (self.depth - p.y, y)]
    }

    /// Fills the percept channels for the current state.
    pub fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        let (mut irv, mut light) = simd::run(Readings { sim: self, walls: true, light: true }, self.path);
        let n = self.sensor_noise;
        if n > 0.0 {
            // 16 bits of randomness per channel, four channels a word.
            let mut noise = [0.0f32; 2 * ir::SENSORS];
            noise_fill(&mut self.rng, n, &mut noise);
            for s in 0..ir::SENSORS {
                irv[s] += noise[s];
                light[s] += noise[ir::SENSORS + s];
            }
        }
        for s in 0..ir::SENSORS {
            out[CH_IR + s] = irv[s].clamp(0.0, 1.0);
            out[CH_LIGHT + s] = light[s].clamp(0.0, 1.0);
        }
        out[CH_BATTERY] = self.battery();
        out[CH_BARRIER] = if self.barrier() { 1.0 } else { 0.0 };
        self.sense_ground(out);
        out[CH_LAMP_DISTANCE] = self.lamp_distance().map_or(1.0, |d| (d / 1000.0).min(1.0));
    }

    /// Runs the per-sensor code on the portable lanes even where the CPU
    /// has AVX2 (for tests that compare the two paths: they must give the
    /// same bits).
    #[doc(hidden)]
    pub fn force_portable_lanes(&mut self) {
        self.path = simd::Path::Portable;
    }

    /// What the first ground sensor reads (under the body centre unless
    /// the body places it elsewhere).
    pub fn floor(&self) -> f32 {
        self.floor_at(&(self.pose * self.ground[0]))
    }

    /// The grey level of the floor at `p` (world frame): the last declared
    /// floor zone there, else the white floor's 1.
    fn floor_at(&self, p: &Point2<f32>) -> f32 {
        self.zones.iter().rev().find(|z| z.contains(p)).map_or(1.0, |z| z.grey)
    }

    /// Fills the ground channels: each sensor reads the floor under it.
    fn sense_ground(&self, out: &mut [f32; CHANNELS]) {
        for (k, at) in self.ground.iter().enumerate() {
            out[CH_FLOOR + k] = if self.zones.is_empty() { 1.0 } else { self.floor_at(&(self.pose * at)) };
        }
    }

    /// Distance from the body centre to the nearest lamp, seen from above
    /// (the charger's lamp included), mm; `None` without lamps.
    pub fn lamp_distance(&self) -> Option<f32> {
        let c = self.centre();
        self.lamp.iter().chain(&self.lamps).map(|l| (l.at - c).norm()).reduce(f32::min)
    }

    /// Adds the walls' noise-free IR readings to `acc`.
    #[inline(always)]
    fn ir_walls<L: Lanes>(&self, mut acc: L) -> L {
        let centre = self.centre();
        let reach = self.radius + ir::RANGE;
        for (dist, normal) in self.walls(&centre) {
            if dist <= reach {
                acc = self.wall_ir(acc, dist, &normal);
            }
        }
        if !self.inner.is_empty() {
            acc = self.ir_inner_walls(acc, &centre, reach);
        }
        acc
    }

    /// Adds one flat wall's readings: `dist` from the body centre, `normal`
    /// its unit normal toward the wall (world frame).
    #[inline(always)]
    fn wall_ir<L: Lanes>(&self, acc: L, dist: f32, normal: &Vector2<f32>) -> L {
        let wt = &ir::tables().0;
        let (g, k) = (&self.lanes, &self.wall_k);
        // With `n` the normal in the body frame, each sensor is `pos . n`
        // nearer the wall than the centre, and its axis makes an angle
        // of cosine `ray . n` with the normal: all eight at once.
        let n = self.pose.rotation.inverse_transform_vector(normal);
        let (nx, ny) = (L::splat(n.x), L::splat(n.y));
        let nearer = L::load(&g.pos_x).mul(nx).add(L::load(&g.pos_y).mul(ny));
        let cos_a = L::load(&g.ray_x).mul(nx).add(L::load(&g.ray_y).mul(ny));
        let d = L::splat(dist).sub(nearer);
        acc.add(simd::saturate(ir_z(k, d, cos_a), wt))
    }

    /// An inner wall reads as a flat wall through its point nearest the
    /// centre, facing the body.
    #[inline(always)]
    fn ir_inner_walls<L: Lanes>(&self, mut acc: L, centre: &Point2<f32>, reach: f32) -> L {
        for [a, b] in &self.inner {
            let d2 = segment_distance2(centre, a, b);
            if d2 > reach * reach || d2 <= 0.0 {
                continue;
            }
            let dist = d2.sqrt();
            let ab = b - a;
            let len2 = ab.norm_squared();
            let t = if len2 > 0.0 { ((centre - a).dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
            let nearest = a + ab * t;
            acc = self.wall_ir(acc, dist, &((nearest - centre) / dist));
        }
        acc
    }

    /// Adds the floor objects' and cylinders' noise-free IR readings to
    /// `acc`. An object or cylinder beyond the sensing range costs one
    /// squared distance.
    #[inline(always)]
    fn ir_objects<L: Lanes>(&self, mut acc: L) -> L {
        let ct = &ir::tables().1;
        let centre = self.centre();
        let rot = &self.pose.rotation;
        let reach = self.radius + ir::RANGE;
        let r = self.obj_radius;
        let reach = reach + r;
        let reach2 = reach * reach;
        // Objects seen by no sensor cost no more than those out of range.
        let cull2 = reach2.min(self.obj_unseen2);
        for c in &self.cylinders {
            let offset = c.at - centre;
            let far = reach - r + c.radius;
            if offset.norm_squared() > far * far {
                continue;
            }
            let at = rot.inverse_transform_vector(&offset);
            acc = acc.add(self.cylinder_ir(at, c.radius, &c.k, ct));
        }
        // The other robots of a team: bodies like cylinders (read, like an
        // object, at the nearest measured distance if closer).
        let body = self.radius;
        let far = reach - r + body;
        let near = 2.0 * body + ir::NEAREST;
        for o in &self.others {
            let offset = o - centre;
            let d2 = offset.norm_squared();
            if d2 > far * far {
                continue;
            }
            let mut at = rot.inverse_transform_vector(&offset);
            if d2 < near * near {
                let d = d2.sqrt();
                at = if d > 1e-3 { at * (near / d) } else { Vector2::x() * near };
            }
            acc = acc.add(self.cylinder_ir(at, body, &self.body_k, ct));
        }
        for o in &self.objects {
            if o.state != ObjectState::Floor {
                continue;
            }
            let offset = o.at - centre;
            if offset.norm_squared() > cull2 {
                continue;
            }
            // The object's centre in the body frame.
            let mut at = rot.inverse_transform_vector(&offset);
            // Closer than the nearest measured distance (a virtual object under
            // the body): read it as if it were at that distance, same bearing.
            let near = self.radius + r + ir::NEAREST;
            let d2 = at.norm_squared();
            if d2 < near * near {
                let d = d2.sqrt();
                let u = if d > 1e-3 { at / d } else { Vector2::x() };
                at = u * near;
            }
            acc = acc.add(self.cylinder_ir(at, r, &self.cyl_k, ct));
        }
        acc
    }

    /// One cylinder's readings: its centre `at` in the body frame, its
    /// radius, its constants.
    #[inline(always)]
    fn cylinder_ir<L: Lanes>(&self, at: Vector2<f32>, radius: f32, k: &ir::Coeffs, ct: &ir::SatTable) -> L {
        cylinder_lanes(&self.lanes, at, radius, k, ct)
    }

    /// Noise-free ambient light readings: the lamp's irradiance
    /// `K / (rho^2 + h^2)` (rho the horizontal distance, h the lamp height,
    /// `K` such that a sensor facing the lamp from [`LAMP_FULL`] mm reads 1)
    /// times the lobe `cos(1.5 a)` for a horizontal bearing `|a| < 60` degrees
    /// off the sensor's axis (0 beyond), clamped at 1.
    #[inline(always)]
    fn light<L: Lanes>(&self) -> L {
        let mut acc = L::splat(0.0);
        if let Some(lamp) = &self.lamp {
            acc = self.add_lamp(lamp, acc);
        }
        for lamp in &self.lamps {
            acc = self.add_lamp(lamp, acc);
        }
        acc.min(L::splat(1.0))
    }

    /// Adds one lamp's readings to `acc` (unclamped). An inner wall or a
    /// cylinder on the line from a sensor to the point below the lamp,
    /// seen from above, shades that sensor from it (the arena's walls do
    /// not: they are the table's low border, and a lamp may stand outside).
    #[inline(always)]
    fn add_lamp<L: Lanes>(&self, lamp: &Lamp, acc: L) -> L {
        if lamp.k <= 0.0 {
            return acc;
        }
        let g = &self.lanes;
        // The lamp in the body frame.
        let rel = self.pose.inverse_transform_point(&lamp.at).coords;
        let rho2 = rel.norm_squared();
        let intensity = lamp.k / (rho2 + lamp.height * lamp.height);
        let rho = rho2.sqrt();
        let along = L::load(&g.ray_x).mul(L::splat(rel.x)).add(L::load(&g.ray_y).mul(L::splat(rel.y)));
        // cos of the bearing off the axis; straight below the lamp every
        // sensor sees it head-on.
        let cos_a = if rho > 1e-3 { along.div(L::splat(rho)) } else { L::splat(1.0) };
        // cos(1.5 a) = 4 q^3 - 3 q with q = cos(a / 2).
        let q = cos_a.add(L::splat(1.0)).mul(L::splat(0.5)).max(L::splat(0.0)).sqrt();
        let cubic = L::splat(4.0).mul(q).mul(q).mul(q).sub(L::splat(3.0).mul(q));
        let lit = L::splat(intensity).mul(cubic.max(L::splat(0.0)));
        if !self.shades {
            return acc.add(lit);
        }
        let (mut sum, mut add) = ([0.0; ir::SENSORS], [0.0; ir::SENSORS]);
        acc.store(&mut sum);
        lit.store(&mut add);
        for i in 0..ir::SENSORS {
            if !self.shaded(&(self.pose * self.geo.position(i)), &lamp.at) {
                sum[i] += add[i];
            }
        }
        L::load(&sum)
    }

    /// An inner wall or a cylinder crosses the segment from `from` to `to`.
    fn shaded(&self, from: &Point2<f32>, to: &Point2<f32>) -> bool {
        self.inner.iter().any(|[a, b]| segments_cross(from, to, a, b))
            || self.cylinders.iter().any(|c| segment_distance2(&c.at, from, to) < c.radius * c.radius)
    }

    /// The optical barrier: arm down, claw open and an object centre in the
    /// catch zone, or an object held.
    fn barrier(&self) -> bool {
        self.held.is_some() || (self.arm_down && !self.claw_closed && self.catchable().is_some())
    }

    /// The floor object whose centre lies in the catch zone (the nearest).
    fn catchable(&self) -> Option<usize> {
        let mut best: Option<(usize, f32)> = None;
        for (i, o) in self.objects.iter().enumerate() {
            if o.state != ObjectState::Floor {
                continue;
            }
            // The object's centre in the body frame: ahead, and to the side.
            let at = self.pose.inverse_transform_point(&o.at);
            let fwd = at.x - self.radius;
            let side = at.y;
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
        self.actions = self.actions.saturating_add(1);
        if self.switches {
            let done = self.actions;
            for lamp in &mut self.lamps {
                if let Some((at, on)) = lamp.switch {
                    if at == done {
                        lamp.k = if on { lamp.lit } else { 0.0 };
                    }
                }
            }
        }
        if !self.places.is_empty() {
            self.place_after(self.actions);
        }
        out
    }

    /// The placements due after `done` actions: the robot is put there
    /// (a place overlapping a physical object on the floor counts as a
    /// placement failure, [`Sim::placement_failures`]; walls and cylinders
    /// the compiler keeps clear).
    fn place_after(&mut self, done: u32) {
        let due: Option<Pose> = self.places.iter().rev().find(|(at, _)| *at == done).map(|(_, p)| *p);
        if let Some(pose) = due {
            let free = self.free(&Point2::new(pose.x, pose.y));
            self.placement_failures = self.placement_failures.saturating_add(u32::from(!free));
            self.set_pose_unchecked(pose);
        }
    }

    /// Actions done in this world so far.
    pub fn actions(&self) -> u32 {
        self.actions
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
    /// to in contact with the bar (or on a charging zone), else drains one
    /// action's worth. Returns true when this action filled the battery in
    /// a charging bout (consecutive charging actions) that started at most
    /// half full: a top-up, or staying at the charger, counts nothing.
    pub fn tick_battery(&mut self, charge: bool) -> bool {
        let Some((cap, rech)) = self.battery_spec else {
            return false;
        };
        let full = cap * rech;
        if self.charger_free && ((charge && self.in_contact()) || self.on_charging_zone()) {
            if !self.charging {
                self.charging = true;
                self.bout_counts = 2 * self.charge <= full;
            }
            if self.charge < full {
                self.charge = (self.charge + cap).min(full);
                if self.charge == full && self.bout_counts {
                    self.bout_counts = false;
                    return true;
                }
            }
        } else {
            self.charging = false;
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
                let (at, _, free) = self.free_spot(&mut rng, Some(self.centre()), PLACE_TRIES);
                self.rng = rng;
                self.placement_failures = self.placement_failures.saturating_add(u32::from(!free));
                self.objects[i] = Obj { at, state: ObjectState::Floor, gripped: false };
            } else {
                self.objects[i].state = ObjectState::Outside;
            }
            return true;
        }
        let r = self.obj_radius;
        let ahead = self.radius + ((CATCH_NEAR + CATCH_FAR) / 2.0).max(r + 1.0);
        let centre = self.centre();
        let front = centre + self.heading() * ahead;
        let at =
            Point2::new(front.x.clamp(r, (self.width - r).max(r)), front.y.clamp(r, (self.depth - r).max(r)));
        let d = self.radius + r;
        if !self.obj_virtual && (at - centre).norm_squared() < d * d {
            return false;
        }
        self.objects[i] = Obj { at, state: ObjectState::Floor, gripped: true };
        self.held = None;
        true
    }

    /// A wall within [`RELEASE_REACH`] of the body surface, within
    /// [`RELEASE_ANGLE_DEG`] of the heading.
    fn wall_ahead(&self) -> bool {
        self.wall_ahead_within(RELEASE_REACH)
    }

    /// The body surface within [`CONTACT`] of the charger bar.
    fn in_contact(&self) -> bool {
        let Some([a, b]) = self.bar else {
            return false;
        };
        let reach = self.radius + CONTACT;
        segment_distance2(&self.centre(), &a, &b) <= reach * reach
    }

    /// The body centre on a floor zone that is a charger (these charge
    /// without being asked to).
    fn on_charging_zone(&self) -> bool {
        let c = self.centre();
        self.zones.iter().any(|z| z.charger && z.contains(&c))
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
        let start = self.centre();
        let heading = self.pose.rotation;
        // The exact arc of a differential drive whose wheels keep their
        // speed for the whole action (the Khepera's motion, as Nolfi's
        // evorobotpy2 moves it: `docs/language.md`, section 18), in chord
        // form: the centre moves by `d * sinc(phi / 2)` along the heading
        // turned by `phi / 2`, and halfway by `d / 2 * sinc(phi / 4)` along
        // it turned by `phi / 4`. One `sin_cos` of `phi / 4` gives the turns
        // by `phi / 2` and `phi` as products of rotations.
        let d = (dl + dr) / 2.0;
        let phi = (dr - dl) / (2.0 * self.half_axle);
        let q = phi / 4.0;
        let (s1, c1) = q.sin_cos();
        let turn4 = UnitComplex::from_cos_sin_unchecked(c1, s1);
        let turn2 = turn4 * turn4;
        let end = start + direction(&(heading * turn2)) * (d * sinc(2.0 * q, turn2.im));
        let mid = start + direction(&(heading * turn4)) * (d / 2.0 * sinc(q, s1));
        if self.free(&end) && self.free(&mid) {
            self.pose = Isometry2::from_parts(end.into(), renormalized(heading * (turn2 * turn2)));
            return false;
        }
        // Retrace in `n` equal sub-arcs: each moves the centre by the chord
        // `len` along the current heading turned by half its angle, then
        // turns the heading by its angle (rotations, no more `sin_cos`).
        let n = ((dl.abs().max(dr.abs()) / SUBSTEP).ceil() as u32).clamp(1, 10_000);
        let sub = phi / n as f32;
        let (sh, ch) = (sub / 2.0).sin_cos();
        let half_turn = UnitComplex::from_cos_sin_unchecked(ch, sh);
        let turn = half_turn * half_turn;
        let len = d / n as f32 * sinc(sub / 2.0, sh);
        let (mut at, mut rot) = (start, heading);
        let mut k = 0;
        while k < n {
            let next = at + direction(&(rot * half_turn)) * len;
            if !self.free(&next) {
                break;
            }
            (at, rot) = (next, rot * turn);
            k += 1;
        }
        self.travelled = [dl * k as f32 / n as f32, dr * k as f32 / n as f32];
        self.pose = Isometry2::from_parts(at.into(), renormalized(rot));
        k < n
    }

    pub fn pose(&self) -> Pose {
        self.pose.into()
    }

    /// The body centre, mm (the pose without its heading).
    #[inline]
    pub fn position(&self) -> [f32; 2] {
        let t = self.pose.translation.vector;
        [t.x, t.y]
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
    /// senses those), the battery, the optical barrier and the floor zone
    /// under the body. Light channels are 0.
    pub fn sense_virtual(&self, out: &mut [f32; CHANNELS]) {
        let irv = if self.obj_virtual {
            simd::run(Readings { sim: self, walls: false, light: false }, self.path).0
        } else {
            [0.0f32; ir::SENSORS]
        };
        for s in 0..ir::SENSORS {
            out[CH_IR + s] = irv[s].clamp(0.0, 1.0);
            out[CH_LIGHT + s] = 0.0;
        }
        out[CH_BATTERY] = self.battery();
        out[CH_BARRIER] = if self.barrier() { 1.0 } else { 0.0 };
        self.sense_ground(out);
        out[CH_LAMP_DISTANCE] = self.lamp_distance().map_or(1.0, |d| (d / 1000.0).min(1.0));
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

    /// True when a floor object's centre lies in the gripper's catch zone
    /// (whatever the arm and claw): what an arbiter that knows the world
    /// ([`crate::oracle`]) reads as "an object is in reach".
    pub fn object_in_reach(&self) -> bool {
        self.catchable().is_some()
    }

    /// True when a wall lies within `reach` mm of the body surface, within
    /// [`RELEASE_ANGLE_DEG`] of the heading (opening the claw there, within
    /// [`RELEASE_REACH`], throws a held object out).
    pub fn wall_ahead_within(&self, reach: f32) -> bool {
        let reach = self.radius + reach;
        let cos_max = RELEASE_ANGLE_DEG.to_radians().cos();
        let heading = self.heading();
        self.walls(&self.centre()).iter().any(|(dist, n)| *dist <= reach && n.dot(&heading) >= cos_max)
    }

    /// The nearest floor object in the body frame: its centre's distance
    /// ahead of the body surface along the heading, to the left of the
    /// heading, and from the body surface, mm (`None` without one).
    pub fn nearest_object(&self) -> Option<(f32, f32, f32)> {
        let mut best: Option<(f32, f32, f32)> = None;
        for o in self.objects.iter().filter(|o| o.state == ObjectState::Floor) {
            let at = self.pose.inverse_transform_point(&o.at);
            let gap = at.coords.norm() - self.radius;
            if best.is_none_or(|(_, _, g)| gap < g) {
                best = Some((at.x - self.radius, at.y, gap));
            }
        }
        best
    }

    /// The nearest wall: its distance from the body surface, mm, and the
    /// bearing of its outward normal from the heading, radians (0: facing it
    /// squarely; positive: to the left).
    pub fn nearest_wall(&self) -> (f32, f32) {
        let centre = self.centre();
        let walls = self.walls(&centre);
        let (dist, n) = walls.iter().fold(walls[0], |a, b| if b.0 < a.0 { *b } else { a });
        let local = self.pose.rotation.inverse() * n;
        (dist - self.radius, local.y.atan2(local.x))
    }

    /// The body's radius, mm.
    pub fn body_radius(&self) -> f32 {
        self.radius
    }

    /// The charger bar's end points, mm (`None` without a charger).
    pub fn bar(&self) -> Option<[[f32; 2]; 2]> {
        self.bar.map(|[a, b]| [[a.x, a.y], [b.x, b.y]])
    }

    /// Distance from the body surface to the charger bar, mm (`None` without
    /// a charger).
    pub fn bar_distance(&self) -> Option<f32> {
        let [a, b] = self.bar?;
        Some(segment_distance2(&self.centre(), &a, &b).sqrt() - self.radius)
    }

    /// Plain data describing the current state, for pictures.
    pub fn scene(&self) -> Scene {
        let xy = |p: Point2<f32>| [p.x, p.y];
        Scene {
            arena: [self.width, self.depth],
            bar: self.bar.map(|[a, b]| [xy(a), xy(b)]),
            lamp: self.lamp.map(|l| xy(l.at)),
            objects: self
                .objects
                .iter()
                .map(|o| {
                    let at = if o.state == ObjectState::Held {
                        self.centre() + self.heading() * (self.radius + (CATCH_NEAR + CATCH_FAR) / 2.0)
                    } else {
                        o.at
                    };
                    SceneObject {
                        x: at.x,
                        y: at.y,
                        radius: self.obj_radius,
                        virtual_: self.obj_virtual,
                        state: o.state,
                    }
                })
                .collect(),
            walls: self.inner.iter().map(|&[a, b]| [xy(a), xy(b)]).collect(),
            cylinders: self.cylinders.iter().map(|c| [c.at.x, c.at.y, c.radius]).collect(),
            lamps: self.lamps.iter().map(|l| xy(l.at)).collect(),
            dark_lamps: self.lamps.iter().enumerate().filter(|(_, l)| l.k <= 0.0).map(|(i, _)| i).collect(),
            zones: self
                .zones
                .iter()
                .map(|z| SceneZone { from: xy(z.min), to: xy(z.max), grey: z.grey, charger: z.charger })
                .collect(),
            pose: self.pose(),
            body_radius: self.radius,
            arm_down: self.arm_down,
            claw_closed: self.claw_closed,
        }
    }
}

/// The bar's end points: centred on `wall`, flush with it.
fn bar_segment(wall: Wall, length: f32, width: f32, depth: f32) -> [Point2<f32>; 2] {
    let along = match wall {
        Wall::North | Wall::South => width,
        Wall::East | Wall::West => depth,
    };
    let half = finite_or(length, 0.0).clamp(0.0, along) / 2.0;
    let mid = along / 2.0;
    let p = Point2::new;
    match wall {
        Wall::North => [p(mid - half, depth), p(mid + half, depth)],
        Wall::South => [p(mid - half, 0.0), p(mid + half, 0.0)],
        Wall::East => [p(width, mid - half), p(width, mid + half)],
        Wall::West => [p(0.0, mid - half), p(0.0, mid + half)],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every sensor reads exactly 0 for an object just beyond the distance
    /// from which floor objects are skipped as unseen, at every bearing and
    /// for several object sizes, on both lanes paths; and just inside it,
    /// some bearing reads more (the bound is not loose beyond its margin).
    #[test]
    fn objects_skipped_as_unseen_read_zero() {
        for diameter in [2.0f32, 10.0, 25.0, 60.0] {
            let r = diameter / 2.0;
            let model = &ir::KHEPERA;
            let geo = ir::Geometry::new(model, 27.5);
            let lanes = SensorLanes::new(&geo);
            let k = ir::Coeffs::new(&model.cylinder_reach(r), &model.cylinder);
            let far = unseen_beyond2(&lanes, &k, r).sqrt();
            assert!(far.is_finite() && far < 27.5 + ir::RANGE + r, "{diameter}: {far}");
            struct One<'a>(&'a SensorLanes, &'a ir::Coeffs, Vector2<f32>, f32);
            impl Kernel for One<'_> {
                type Out = [f32; ir::SENSORS];
                #[inline(always)]
                fn run<L: Lanes>(self) -> Self::Out {
                    let mut out = [0.0; ir::SENSORS];
                    cylinder_lanes::<L>(self.0, self.2, self.3, self.1, &ir::tables().1).store(&mut out);
                    out
                }
            }
            let mut inside_max = 0.0f32;
            for b in 0..720 {
                let (sin, cos) = (b as f32 * 0.5).to_radians().sin_cos();
                for path in [simd::Path::Best, simd::Path::Portable] {
                    let beyond = simd::run(One(&lanes, &k, Vector2::new(cos, sin) * far, r), path);
                    assert!(beyond.iter().all(|v| v.to_bits() == 0), "{diameter} {b}: {beyond:?}");
                    let inside = simd::run(One(&lanes, &k, Vector2::new(cos, sin) * (far - 2.0), r), path);
                    inside_max = inside.iter().fold(inside_max, |m, &v| m.max(v));
                }
            }
            assert!(inside_max > 0.0, "{diameter}");
        }
    }
}
