//! The `Program`: what the compiler produces and the runtime executes.
//!
//! Plain owned data, serde-serialisable, no source spans. One [`Stage`] holds
//! everything needed to run that stage on its own: the robot's declared
//! sensors and actuators, the world, the modules and links, the genome layout
//! (every gene of this stage and of the stages it extends, with the frozen
//! ones marked), the fitness and what to do (evolve or test).
//!
//! Channel indices (`u16`) refer to the percept array of [`crate::catalog`];
//! gene indices (`u32`) refer to `Stage::layout.genes`; module indices (`u16`)
//! refer to `Stage::modules` (declaration order, earlier stages' modules first).

use serde::{Deserialize, Serialize};

use crate::catalog::{ActuatorKind, SensorKind};
use crate::expr::Expr;

/// Bumped whenever the serialized shape changes incompatibly.
pub const FORMAT_VERSION: u32 = 1;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Program {
    pub format: u32,
    /// The architecture's name (the file stem, or the `robot` name).
    pub name: String,
    /// Stages in dependency order: a stage's `parent` always comes before it.
    pub stages: Vec<Stage>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stage {
    pub name: String,
    /// Index of the stage this one extends, if any.
    pub parent: Option<usize>,
    /// Declared sensors, in declaration order (earlier stages' first).
    pub sensors: Vec<SensorDecl>,
    pub actuators: Vec<ActuatorDecl>,
    pub world: World,
    pub modules: Vec<Module>,
    /// Links between modules (the activation of `from` at the previous action,
    /// times `weight`, is added to `to`'s activation network).
    pub links: Vec<Link>,
    pub layout: GenomeLayout,
    pub fitness: Fitness,
    pub run: StageRun,
    pub inheritance: Inheritance,
    /// The named variants of the world an individual is evaluated in
    /// (`variants mean { ... }`); `None`: only `world`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variants: Option<Variants>,
    /// The items a fitness measures the distance to (`distance_to(goal)`):
    /// state slot [`crate::catalog::ST_TARGETS`]` + i` reads target `i`, found
    /// by kind and name in the world of each episode (a variant's included).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub targets: Vec<Target>,
    /// The roles of a heterogeneous team, in order (empty: every robot runs
    /// all of `modules`). Role `r` owns the next `roles[r].modules` modules
    /// of `modules` (role 0's first), their links and their genes; its
    /// `robots` robots follow the previous roles' (robot 0 is role 0's).
    /// The counts add up to `world.robots`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub roles: Vec<Role>,
}

/// A role of a heterogeneous team ([`Stage::roles`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Role {
    pub name: String,
    /// How many of the team's robots play it.
    pub robots: u32,
    /// How many modules of [`Stage::modules`] are its own.
    pub modules: u16,
    /// The fitness of its robots, replacing the stage's (`fitness` inside
    /// the role); `None`: the stage's. The team's aggregate is the stage's
    /// (`Stage::fitness.team`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitness: Option<Fitness>,
}

/// The conditions an individual is evaluated in: named variants of the
/// stage's world, each its own complete world.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Variants {
    /// How the fitness of the variants makes the individual's.
    pub aggregate: Aggregate,
    /// Variants drawn per generation (the same for every individual of a
    /// generation, from the run seed); `None`: every variant.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub draw: Option<u32>,
    /// In declaration order (at least one).
    pub list: Vec<Variant>,
}

/// One named variant: the stage's world with the variant's changes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Variant {
    pub name: String,
    pub world: World,
}

/// How several fitness values make one: a stage's variants' (`mean` or
/// `min`), a team's robots' (`sum`, `mean` or `min`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Aggregate {
    #[default]
    Mean,
    Min,
    Sum,
}

impl Aggregate {
    /// Combines per-variant fitness values (f64 sums; none gives 0).
    pub fn of(self, values: impl IntoIterator<Item = f32>) -> f32 {
        let mut n = 0usize;
        let (mut sum, mut min) = (0.0f64, f32::INFINITY);
        for v in values {
            n += 1;
            sum += f64::from(v);
            min = if v.is_nan() { v } else { min.min(v) };
        }
        match (n, self) {
            (0, _) => 0.0,
            (_, Aggregate::Mean) => (sum / n as f64) as f32,
            (_, Aggregate::Min) => min,
            (_, Aggregate::Sum) => sum as f32,
        }
    }

    /// `mean`, `min` or `sum`, as written.
    pub fn word(self) -> &'static str {
        match self {
            Aggregate::Mean => "mean",
            Aggregate::Min => "min",
            Aggregate::Sum => "sum",
        }
    }

    /// For `skip_serializing_if`: the default is left out of files.
    pub fn is_mean(&self) -> bool {
        *self == Aggregate::Mean
    }
}

/// A named item of the world (`distance_to(NAME)`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Target {
    pub kind: ItemKind,
    pub name: String,
}

/// The kinds of named world items.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ItemKind {
    Wall,
    Cylinder,
    Lamp,
    Zone,
}

impl Stage {
    /// The team's size: its roles' robots, or without roles the world's
    /// `robots` (at least 1). Read this, not `world.robots`: with roles,
    /// the roles are the truth and every world's count is derived from
    /// them ([`Stage::set_role_robots`]).
    pub fn robots(&self) -> u32 {
        if self.roles.is_empty() {
            self.world.robots.max(1)
        } else {
            self.roles.iter().fold(0u32, |n, r| n.saturating_add(r.robots))
        }
    }

    /// Sets how many robots play role `role`, and derives from the roles
    /// the team of every world of the stage (its own and its variants').
    pub fn set_role_robots(&mut self, role: usize, robots: u32) {
        if let Some(r) = self.roles.get_mut(role) {
            r.robots = robots;
        }
        let team = self.robots();
        self.world.robots = team;
        for x in self.variants.iter_mut().flat_map(|v| v.list.iter_mut()) {
            x.world.robots = team;
        }
    }

    /// The number of worlds an individual is evaluated in: its variants, or 1.
    pub fn variant_count(&self) -> usize {
        self.variants.as_ref().map_or(1, |v| v.list.len().max(1))
    }

    /// This stage in variant `v` alone: its world is the variant's, and it
    /// has no variants (itself, without variants, for a stage that has none
    /// or a `v` out of range).
    pub fn in_variant(&self, v: usize) -> Stage {
        let mut st = self.clone();
        if let Some(var) = st.variants.take() {
            if let Some(x) = var.list.into_iter().nth(v) {
                st.world = x.world;
            }
        }
        st
    }

    /// The role robot `i` of the team plays: its index in `roles` (0 without
    /// roles, and for a robot past the roles' count).
    pub fn role_of(&self, i: usize) -> usize {
        let mut end = 0usize;
        for (r, role) in self.roles.iter().enumerate() {
            end += role.robots as usize;
            if i < end {
                return r;
            }
        }
        self.roles.len().saturating_sub(1)
    }

    /// The modules of role `r`: a range of indices into `modules` (all of
    /// them without roles).
    pub fn role_modules(&self, r: usize) -> std::ops::Range<usize> {
        if self.roles.is_empty() {
            return 0..self.modules.len();
        }
        let start: usize = self.roles.iter().take(r).map(|x| x.modules as usize).sum();
        let len = self.roles.get(r).map_or(0, |x| x.modules as usize);
        start.min(self.modules.len())..(start + len).min(self.modules.len())
    }

    /// The fitness of role `r`'s robots: the role's own, else the stage's.
    pub fn role_fitness(&self, r: usize) -> &Fitness {
        self.roles.get(r).and_then(|x| x.fitness.as_ref()).unwrap_or(&self.fitness)
    }

    /// Module `i`'s name as outputs and settings write it: `ROLE.MODULE` in
    /// a stage with roles (two roles may name a module alike), else its name.
    pub fn module_label(&self, i: usize) -> String {
        let name = self.modules.get(i).map_or("", |m| m.name.as_str());
        match self.roles.get(self.role_of_module(i)) {
            Some(role) => format!("{}.{name}", role.name),
            None => name.to_string(),
        }
    }

    /// The role module `i` belongs to (0 without roles).
    pub fn role_of_module(&self, i: usize) -> usize {
        (0..self.roles.len()).find(|&r| self.role_modules(r).contains(&i)).unwrap_or(0)
    }

    /// The world of variant `v` (the stage's own without variants).
    pub fn variant_world(&self, v: usize) -> &World {
        self.variants.as_ref().and_then(|x| x.list.get(v)).map_or(&self.world, |x| &x.world)
    }
}

/// A named sensor of the robot: `count` consecutive channels from `channel`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorDecl {
    pub name: String,
    pub kind: SensorKind,
    pub count: u16,
    pub channel: u16,
    /// Index of the stage that added it.
    pub stage: u16,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActuatorDecl {
    pub name: String,
    pub kind: ActuatorKind,
    pub stage: u16,
}

// ---------------------------------------------------------------- world

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct World {
    /// Arena size in mm: width (x, west to east) and depth (y, south to north).
    pub arena: [f32; 2],
    pub body: Body,
    pub charger: Option<Charger>,
    pub battery: Option<Battery>,
    pub objects: Option<Objects>,
    /// Inner walls, cylinders, lamps, floor zones and the start pose.
    #[serde(default, skip_serializing_if = "Items::is_empty")]
    pub items: Items,
    /// Robots in the world: a team of clones of the evaluated individual,
    /// each with its own controller, battery and gripper, all starting in
    /// the start region (left out of files while 1, one robot). In a stage
    /// with roles it is derived from them (the compiler and
    /// [`Stage::set_role_robots`] write it; validation refuses a file where
    /// it differs): the simulator reads a world without its stage, and
    /// `program.json` keeps the key so that its bytes stay as they were.
    /// A stage's team is [`Stage::robots`].
    #[serde(default = "one_robot", skip_serializing_if = "is_one_robot")]
    pub robots: u32,
}

fn one_robot() -> u32 {
    1
}

fn is_one_robot(n: &u32) -> bool {
    *n == 1
}

/// The items a world may have any number of (and the start pose), in
/// declaration order. Coordinates are mm from the arena's south-west corner
/// (x east, y north).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Items {
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub walls: Vec<InnerWall>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cylinders: Vec<Cylinder>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lamps: Vec<Lamp>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub zones: Vec<Zone>,
    /// Where the robot starts; `None`: anywhere free, at a random heading.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<Start>,
    /// Where the robot is put during the life (`place ... after N actions`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub places: Vec<Placement>,
}

impl Items {
    pub fn is_empty(&self) -> bool {
        self == &Items::default()
    }
}

/// A thin wall segment inside the arena: blocks the body, reflects IR.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InnerWall {
    pub name: Option<String>,
    pub from: [f32; 2],
    pub to: [f32; 2],
}

/// A physical cylinder standing on the floor: blocks the body, reflects IR.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cylinder {
    pub name: Option<String>,
    pub at: [f32; 2],
    /// Diameter, mm.
    pub diameter: f32,
}

/// A lamp anywhere (also outside the arena): ambient light sensors read it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Lamp {
    pub name: Option<String>,
    pub at: [f32; 2],
    /// Height above the floor, mm.
    pub height: f32,
    /// 1: a sensor facing it from 100 mm (horizontally) reads 1, as under
    /// the charger's lamp; the irradiance scales with it.
    pub intensity: f32,
    /// `off at N` / `on at N`: the lamp switches after the life's `N`th
    /// action (off before it for `on`; lit at `intensity` before it for
    /// `off`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub switch: Option<LampSwitch>,
}

/// A lamp that switches on or off during a life.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LampSwitch {
    /// Switches on (`true`) or off.
    pub on: bool,
    /// After this many actions of the life (at least 1).
    pub at: u32,
}

/// `place [NAME] at (X, Y) heading A after N actions`: after the life's
/// `N`th action the robot is put at `at`, facing `heading` (radians,
/// counter-clockwise from east), wherever it was: what it did since the
/// start leaves nothing in its pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    pub name: Option<String>,
    pub at: [f32; 2],
    pub heading: f32,
    /// After this many actions of the life (at least 1).
    pub after: u32,
}

/// A rectangle of the floor with a grey level (what a ground sensor reads
/// above it), optionally a charger: the battery refills there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Zone {
    pub name: Option<String>,
    /// South-west and north-east corners.
    pub from: [f32; 2],
    pub to: [f32; 2],
    /// 0 black .. 1 white (the arena floor is white, 1).
    pub grey: f32,
    pub charger: bool,
}

/// The start pose: a fixed point, or uniformly random in a rectangle; a
/// fixed heading (radians, counter-clockwise from east) or a random one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Start {
    pub from: [f32; 2],
    /// Equal to `from` for a fixed point.
    pub to: [f32; 2],
    pub heading: Option<f32>,
}

/// The robot's body and motion parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Body {
    /// Body radius, mm (Khepera: 27.5).
    pub radius: f32,
    /// Distance between the wheels, mm (53).
    pub wheel_base: f32,
    /// Wheel speed for a command of 1.0, mm/s (80).
    pub v_max: f32,
    /// Duration of one action, ms (250).
    pub action_ms: f32,
    /// Multiplicative uniform wheel noise, e.g. 0.05 for +-5 %.
    pub wheel_noise: f32,
    /// Additive uniform sensor noise amplitude (0.01).
    pub sensor_noise: f32,
    /// The preset the body was declared from (`body e-puck`); `None` for
    /// the default, `khepera`. Informative: the values above and below are
    /// what the simulator uses.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Where the eight IR (and ambient light) sensors sit and look;
    /// `None`: the geometry fitted to the Khepera ([`crate::sim::ir::KHEPERA`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ir: Option<IrLayout>,
    /// Where the ground sensors sit, body frame (mm, x ahead, y to the
    /// left), sensor `k` at `ground[k]`; a ground sensor without a place
    /// here sits under the body centre.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ground: Vec<[f32; 2]>,
    /// The range-and-bearing board (sensor, signals heard, broadcast);
    /// `None` when the robot has none of them: nothing of it is computed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rab: Option<RangeBearing>,
}

/// The range-and-bearing board: what a robot perceives of the other
/// robots within `range` and what it broadcasts to them
/// (`docs/language.md`, section 18).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RangeBearing {
    /// Sectors around the body, 1..=8 (the `range_bearing` sensor's count;
    /// 8 when only signals are declared): sector `s` is centred on
    /// `s * 360 / sectors` degrees counter-clockwise from the heading.
    pub sectors: u8,
    /// Values each robot broadcasts, 0..=4 (the `broadcast` actuator's count).
    pub signals: u8,
    /// How far another robot is perceived and heard, body surface to body
    /// surface, mm.
    pub range: f32,
    /// Uniform noise in `-n..n` added to a perceived proximity.
    pub range_noise: f32,
    /// Uniform noise in `-b..b` degrees added to a perceived bearing.
    pub bearing_noise: f32,
    /// Inner walls and cylinders between two robots' centres hide them
    /// from each other (as they shade a lamp).
    pub occlusion: bool,
    /// Every broadcast is heard as 0 (`rab_signals off`): the robots still
    /// set their broadcast values, which expressions read, but no `signal`
    /// sensor hears them (the ablation of signalling, with the genome as
    /// it is). Written only when set, so files without it keep their bytes.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub silenced: bool,
}

impl RangeBearing {
    /// The defaults: 8 sectors, 300 mm, 0.02 proximity noise, 5 degrees
    /// bearing noise, occluded by walls and cylinders, broadcasts heard.
    pub const DEFAULT: RangeBearing = RangeBearing {
        sectors: 8,
        signals: 0,
        range: 300.0,
        range_noise: 0.02,
        bearing_noise: 5.0,
        occlusion: true,
        silenced: false,
    };
}

/// A declared layout of the eight IR sensors (the ambient light sensors
/// share it). The response to a surface at a given distance and angle stays
/// the one fitted to the Khepera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IrLayout {
    /// Where each sensor sits.
    pub at: [SensorSpot; 8],
    /// Where each sensor looks, degrees counter-clockwise from the heading.
    pub facing: [f32; 8],
}

/// Where a sensor sits on the body.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorSpot {
    /// On the body rim, at this angle (degrees counter-clockwise from the
    /// heading): it follows the body's radius.
    Rim(f32),
    /// At this point of the body frame, mm (x ahead, y to the left).
    Point([f32; 2]),
}

impl Default for Body {
    fn default() -> Self {
        Body {
            radius: 27.5,
            wheel_base: 53.0,
            v_max: 80.0,
            action_ms: 250.0,
            wheel_noise: 0.05,
            sensor_noise: 0.01,
            preset: None,
            ir: None,
            ground: Vec::new(),
            rab: None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Wall {
    North,
    South,
    East,
    West,
}

/// The recharging bar, centred on a wall, with an optional lamp above it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Charger {
    pub wall: Wall,
    /// Bar length, mm.
    pub length: f32,
    /// Lamp height above the bar, mm; `None` for no lamp.
    pub lamp_height: Option<f32>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Battery {
    /// Actions a full battery lasts.
    pub capacity: u32,
    /// Actions in contact with the bar (while recharging) to refill completely.
    pub recharge: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Objects {
    pub count: u32,
    /// Diameter, mm.
    pub diameter: f32,
    /// Virtual objects add sensor readings and can be gripped, but never block.
    pub virtual_: bool,
}

// ---------------------------------------------------------------- modules

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Module {
    pub name: String,
    /// Index of the stage that introduced this module.
    pub stage: u16,
    /// Percept channels feeding the activation network (in order).
    pub inputs: Vec<u16>,
    /// Activation network: `inputs.len()` inputs, one sigmoid output; the
    /// link-weighted sum of the other modules' previous activations is added
    /// to the output neuron's net input.
    pub activation: Network,
    pub behavior: Behavior,
    pub learning: Option<Learning>,
    /// Reinforcement program: +1 reward, -1 punishment, 0 no signal (the value's
    /// sign is used). Evaluated after each action the module drove, unless the
    /// behavior is a script containing `reinforce` steps, which deliver it.
    pub reinforce: Option<Expr>,
}

/// A feed-forward network of sigmoid units.
///
/// Parameter order in `params`:
/// - `hidden == 0`: for each output `o`: `bias_o, w_o0, w_o1, ..., w_o(n-1)`;
/// - `hidden > 0`: for each hidden unit `h`: `bias_h, w_h0 .. w_h(n-1)`
///   (and, `recurrent`, `c_h0 .. c_h(hidden-1)` from the context); then
///   for each output `o`: `bias_o, w_o,h0 .. w_o,h(hidden-1)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Network {
    pub inputs: u16,
    pub hidden: u16,
    pub outputs: u16,
    /// Elman-style context: each hidden unit also reads every hidden unit's
    /// activation of the previous forward pass (0 at the start of an
    /// episode); its weights follow the unit's input weights.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub recurrent: bool,
    pub params: Vec<Param>,
}

impl Network {
    /// Number of parameters a feed-forward network of this shape has.
    pub fn param_count(inputs: usize, hidden: usize, outputs: usize) -> usize {
        Network::param_count_of(inputs, hidden, outputs, false)
    }

    /// Number of parameters of a network of this shape, recurrent or not:
    /// per hidden unit a bias, `inputs` weights and (recurrent) `hidden`
    /// context weights; per output a bias and `hidden` weights.
    pub fn param_count_of(inputs: usize, hidden: usize, outputs: usize, recurrent: bool) -> usize {
        if hidden == 0 {
            outputs * (inputs + 1)
        } else {
            let context = if recurrent { hidden } else { 0 };
            hidden * (inputs + 1 + context) + outputs * (hidden + 1)
        }
    }
}

/// Where one weight comes from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Param {
    /// Decoded from gene `i` of the stage's layout.
    Gene(u32),
    /// A constant.
    Fixed(f32),
    /// Drawn uniformly in `lo..hi` at the start of each episode from the
    /// individual's RNG (e.g. a behavior network that learns from random weights).
    Random { lo: f32, hi: f32 },
    /// Weight `index` of the network `part` (behavior or activation) that
    /// module `module` of the training stage `stage` learned. Bound to
    /// `Fixed` by [`bind_trained`] once that stage has run; a controller
    /// refuses an unbound one.
    Trained {
        stage: u16,
        module: u16,
        index: u32,
        /// Absent in programs written before activation networks could be
        /// trained: a behavior weight.
        #[serde(default)]
        part: Part,
    },
}

/// The network of a module a weight belongs to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Part {
    #[default]
    Behavior,
    Activation,
}

impl Module {
    /// The parameters of the module's networks: the activation network's,
    /// then the neural behavior's (none for a script), each with its part.
    pub fn network_params(&self) -> impl Iterator<Item = (Part, &Param)> {
        let behavior: &[Param] = match &self.behavior {
            Behavior::Neural(nb) => &nb.net.params,
            Behavior::Script(_) => &[],
        };
        let activation = self.activation.params.iter().map(|p| (Part::Activation, p));
        activation.chain(behavior.iter().map(|p| (Part::Behavior, p)))
    }

    /// [`Module::network_params`], mutable.
    pub fn network_params_mut(&mut self) -> impl Iterator<Item = (Part, &mut Param)> {
        let behavior: &mut [Param] = match &mut self.behavior {
            Behavior::Neural(nb) => &mut nb.net.params,
            Behavior::Script(_) => &mut [],
        };
        let activation = self.activation.params.iter_mut().map(|p| (Part::Activation, p));
        activation.chain(behavior.iter_mut().map(|p| (Part::Behavior, p)))
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Behavior {
    Script(Script),
    Neural(NeuralBehavior),
}

/// A neural behavior generator: percept channels to motor outputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NeuralBehavior {
    pub inputs: Vec<u16>,
    pub net: Network,
    pub decode: Decode,
    /// The values of the `broadcast` actuator the network sets (`broadcast
    /// NAME`): its last `signals` outputs, after the wheels' (those of
    /// `decode`), each output the value broadcast (0..1; while learning by
    /// CRBP, its sampled bit, as the wheels of a `Linear` decoding). 0: the
    /// network broadcasts nothing.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub signals: u16,
}

impl NeuralBehavior {
    /// The outputs that drive the wheels (`decode`'s), before the signals'.
    pub fn wheel_outputs(&self) -> u16 {
        self.net.outputs.saturating_sub(self.signals)
    }
}

fn is_zero(n: &u16) -> bool {
    *n == 0
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Decode {
    /// Each output is a bit (sampled with probability = output when the module
    /// learns by CRBP, else `output > 0.5`); the bits, first output most
    /// significant, index the table of `[left, right]` wheel speeds (-1..1).
    /// The paper's obstacle avoidance: 2 outputs, table
    /// `[back, left turn, right turn, forward]` for bits `00, 01, 10, 11`.
    Table(Vec<[f32; 2]>),
    /// Two outputs `y` give wheel speeds `(2y - 1) * scale`.
    Linear { scale: f32 },
}

/// A programmed behavior: steps executed one after another, one per action
/// (a step with a duration spans several actions). While the module keeps
/// winning, the script continues where it was; after its last step it starts
/// again. When another module wins, the script is reset to its first step.
/// A `commit` script, once its module has won, keeps control of the robot
/// until its last step has ended (every step is bounded, so it always ends).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Script {
    pub steps: Vec<Step>,
    #[serde(default)]
    pub commit: bool,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Step {
    pub action: Action,
    pub end: StepEnd,
    /// `if COND`: the step runs only when this holds as it is reached
    /// (evaluated like a `reinforce` step); otherwise it is skipped and
    /// takes no time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub when: Option<Expr>,
}

impl Step {
    /// A step that always runs (no `if` condition).
    pub fn new(action: Action, end: StepEnd) -> Step {
        Step { action, end, when: None }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Action {
    /// Set both wheel speeds (-1..1): `forward(v)`, `back(v)`, `turn left`, `stop`, ...
    Wheels { left: f32, right: f32 },
    /// Steer toward the direction of the vector sum of these channels
    /// (each along its sensor's bearing): turn in place when the direction is
    /// more than ~20 degrees off the heading, else drive forward at `speed`.
    Toward { channels: Vec<u16>, speed: f32 },
    /// Move the arm: `true` = down.
    Arm(bool),
    /// Move the claw: `true` = closed.
    Claw(bool),
    /// Stop the wheels; with `charge`, also ask the charger to recharge.
    Wait { charge: bool },
    /// Deliver the module's reinforcement: the value of this expression.
    /// Takes no time: the next step runs in the same action.
    Reinforce(Expr),
    /// Set the values the robot broadcasts (`signal(1, 0)`: a `broadcast`
    /// actuator by its name; each 0..1, every declared value given). Takes
    /// no time: the next step runs in the same action, and the values
    /// stay until set again.
    Signal(Vec<f32>),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum StepEnd {
    /// The step lasts this many actions (1 for a plain step).
    Actions(u32),
    /// The step repeats until `cond` is true after an action, at most `within` actions.
    Until { cond: Expr, within: u32 },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Learning {
    pub target: LearnTarget,
    /// CRBP learning rate after a reward.
    pub rate_reward: f32,
    /// CRBP learning rate after a punishment.
    pub rate_punish: f32,
    pub when: LearnWhen,
    /// Window (in reinforcement signals) of the performance indicator.
    pub window: u32,
    /// The error the delta rule back-propagates.
    #[serde(default)]
    pub error: CrbpError,
}

/// The output error CRBP back-propagates toward the target bits `t`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CrbpError {
    /// `t - y`: the discrepancy itself, as the paper describes CRBP
    /// ("back-propagating the discrepancy (O - S)"); the gradient of the
    /// cross-entropy of sigmoid outputs, so a saturated output still learns.
    #[default]
    Difference,
    /// `(t - y) y (1 - y)`: the gradient of the squared error through the
    /// sigmoid; steps vanish where an output saturates.
    Squared,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum LearnTarget {
    Behavior,
    Activation,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum LearnWhen {
    Always,
    /// Learn while the performance indicator (rolling mean of the last
    /// `window` reinforcements) is below `threshold`.
    Below {
        threshold: f32,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Link {
    pub from: u16,
    pub to: u16,
    pub weight: Param,
}

// ---------------------------------------------------------------- genome

/// The genome layout of a stage: every gene of this stage and of the stages
/// it extends, in bit order. Genes of earlier stages come first (stage-major)
/// and are `frozen`: crossover and mutation never change them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GenomeLayout {
    pub genes: Vec<Gene>,
    /// Total length in bits.
    pub bits: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gene {
    /// First bit.
    pub offset: u32,
    pub bits: u8,
    /// Decoded range: `lo + (hi - lo) * g / (2^bits - 1)`.
    pub lo: f32,
    pub hi: f32,
    /// Stage that introduced the gene.
    pub stage: u16,
    /// Module the gene belongs to (for a link: the receiving module).
    pub module: u16,
    pub role: GeneRole,
    /// True when an earlier stage introduced the gene.
    pub frozen: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum GeneRole {
    /// Output bias of the activation network.
    Bias,
    /// Weight from input `input` (index into `Module::inputs`) to the output
    /// (or, with a hidden layer, to hidden unit `hidden`).
    Weight { input: u16, hidden: Option<u16> },
    /// Bias of hidden unit `hidden`.
    HiddenBias { hidden: u16 },
    /// Weight from hidden unit `hidden` to the output.
    HiddenOut { hidden: u16 },
    /// Weight from the context (hidden unit `from` at the previous forward
    /// pass) into hidden unit `hidden` of a recurrent network.
    Context { from: u16, hidden: u16 },
    /// Link weight from module `from` into the gene's module.
    Link { from: u16 },
}

// ---------------------------------------------------------------- fitness and run

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fitness {
    /// Evaluated after every action and summed over the life.
    pub per_action: Option<Expr>,
    /// Evaluated once after the life's last action and added (left out of
    /// files when absent, so programs written before it read as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_end: Option<Expr>,
    /// Points per event, added to the sum.
    pub bonuses: Vec<Bonus>,
    /// How the robots' fitness makes a team's (`World::robots` above 1):
    /// `sum`, `mean` or `min` (left out of files while `mean`).
    #[serde(default, skip_serializing_if = "Aggregate::is_mean")]
    pub team: Aggregate,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bonus {
    pub event: Event,
    pub points: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Event {
    /// An object was gripped.
    Grip,
    /// An object was released outside the arena.
    ReleaseOutside,
    /// The battery was refilled at the charger.
    Recharge,
    /// A move was undone by a collision.
    Collision,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum StageRun {
    Evolve(Evolution),
    /// No evolution: the best individual of the parent stage lives `lives`
    /// lives of at most `actions` actions in the parent's world, then as many
    /// in this stage's world, with one controller throughout and local
    /// learning on or off.
    Test {
        /// Most actions of each life.
        actions: u32,
        /// Lives in each world (1 in programs written before lives existed).
        #[serde(default = "one_life")]
        lives: u32,
        learning: bool,
    },
    /// No evolution and no genes: the stage's modules live one life of
    /// `actions` actions in its world with learning on, and later stages
    /// start from the behavior or activation weights they learned
    /// (`Param::Trained`).
    Train {
        actions: u32,
    },
}

/// The lives of a test stage that does not say (`test best for N actions`).
fn one_life() -> u32 {
    1
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evolution {
    pub population: u32,
    pub generations: u32,
    /// Life length in actions.
    pub actions: u32,
    pub seed: u64,
    pub selection: Selection,
    /// Probability of one-point crossover per pair.
    pub crossover: f32,
    /// Bit-flip probability per evolvable bit.
    pub mutation: f32,
    /// Best individuals copied unchanged.
    pub elitism: u32,
    /// Episodes averaged per evaluation.
    pub evaluations: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Selection {
    /// The best `keep` individuals each make `population / keep` offspring.
    Truncation { keep: u32 },
    /// Fitness-proportional.
    Roulette,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Inheritance {
    /// Learned weights are not written back to the genome.
    Darwinian,
    /// Learned weights that are genes (activation networks, evolvable neural
    /// behaviors) are written back (re-encoded) to the genome.
    Lamarckian,
}

impl Program {
    pub fn stage(&self, name: &str) -> Option<(usize, &Stage)> {
        self.stages.iter().enumerate().find(|(_, s)| s.name == name)
    }

    /// Stage `index` and the stages it extends, nearest first: the one walk
    /// up the program's `parent` links. It ends early at a parent out of
    /// range or not before its child (a malformed chain, which
    /// [`Program::validate`] refuses), so it never loops.
    pub fn lineage(&self, index: usize) -> impl Iterator<Item = usize> + '_ {
        let first = Some(index).filter(|&i| i < self.stages.len());
        std::iter::successors(first, move |&child| self.stages[child].parent.filter(|&p| p < child))
    }

    /// The nearest evolved stage among stage `index` and those it extends
    /// (itself if it evolves; test stages skipped).
    pub fn evolved_at_or_above(&self, index: usize) -> Option<usize> {
        self.lineage(index).find(|&i| matches!(self.stages[i].run, StageRun::Evolve(_)))
    }

    /// The nearest evolved stage among those stage `index` extends (not
    /// itself): the stage whose best or population it starts from.
    pub fn evolved_above(&self, index: usize) -> Option<usize> {
        self.lineage(index).skip(1).find(|&i| matches!(self.stages[i].run, StageRun::Evolve(_)))
    }
}

/// Replaces every `Param::Trained` that refers to training stage `stage`
/// with the weight its module learned: `behavior[m]` and `activation[m]`
/// are the weights of that stage's module `m` (`Network::params` order).
/// Returns how many parameters were bound.
pub fn bind_trained(
    program: &mut Program,
    stage: usize,
    behavior: &[Vec<f32>],
    activation: &[Vec<f32>],
) -> usize {
    let mut bound = 0;
    for st in &mut program.stages {
        for m in &mut st.modules {
            for (_, p) in m.network_params_mut() {
                if let Param::Trained { stage: s, module, index, part } = *p {
                    let learned = match part {
                        Part::Behavior => behavior,
                        Part::Activation => activation,
                    };
                    if s as usize == stage {
                        if let Some(&w) = learned.get(module as usize).and_then(|w| w.get(index as usize)) {
                            *p = Param::Fixed(w);
                            bound += 1;
                        }
                    }
                }
            }
        }
    }
    bound
}
