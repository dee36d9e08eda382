//! The platform catalog: the sensor and actuator kinds the simulated Khepera
//! provides. The compiler checks `robot { ... }` declarations against this
//! table, so the names live in exactly one place.
//!
//! Every sensor reading of one action is a flat array of [`CHANNELS`] floats
//! (the *percept*). A declared sensor `ir[8] proximity` occupies the first 8
//! channels of the `proximity` kind; module inputs, expressions and scripted
//! behaviors refer to channels by index.

use serde::{Deserialize, Serialize};

/// Number of percept channels the simulator fills each action.
pub const CHANNELS: usize = CH_HEARD + RAB_SECTORS * SIGNALS;
/// Number of actuator slots visible to expressions (`wheels[0]`, `wheels[1]`,
/// arm, claw, then the broadcast values).
pub const ACT_SLOTS: usize = ACT_SIGNAL + SIGNALS;

/// Channel index of the first proximity (IR) sensor.
pub const CH_IR: usize = 0;
/// Channel index of the first ambient-light sensor.
pub const CH_LIGHT: usize = 8;
/// Channel index of the battery level.
pub const CH_BATTERY: usize = 16;
/// Channel index of the gripper's optical barrier.
pub const CH_BARRIER: usize = 17;
/// Channel index of the first ground (floor) sensor.
pub const CH_FLOOR: usize = 18;
/// Most ground sensors a robot may have (channels `CH_FLOOR..CH_FLOOR + 4`).
pub const GROUND_SENSORS: usize = 4;
/// Channel index of the distance to the nearest lamp.
pub const CH_LAMP_DISTANCE: usize = CH_FLOOR + GROUND_SENSORS;
/// Channel index of the range-and-bearing sensor's first sector.
pub const CH_RAB: usize = CH_LAMP_DISTANCE + 1;
/// Most sectors of the range-and-bearing sensor.
pub const RAB_SECTORS: usize = 8;
/// Channel index of the first heard signal (`signal` sensor): with `S`
/// sectors, signal `k`'s strongest value in sector `s` is channel
/// `CH_HEARD + k * S + s`.
pub const CH_HEARD: usize = CH_RAB + RAB_SECTORS;
/// Most values a robot broadcasts (`broadcast` actuator).
pub const SIGNALS: usize = 4;

/// Actuator slot of the left wheel's commanded speed (normalised to -1..1).
pub const ACT_LEFT: usize = 0;
/// Actuator slot of the right wheel's commanded speed (normalised to -1..1).
pub const ACT_RIGHT: usize = 1;
/// Actuator slot of the arm (0 up, 1 down).
pub const ACT_ARM: usize = 2;
/// Actuator slot of the claw (0 open, 1 closed).
pub const ACT_CLAW: usize = 3;
/// Actuator slot of the first broadcast value (0..1).
pub const ACT_SIGNAL: usize = 4;

/// Bearings of the 8 Khepera IR / ambient sensors, in degrees, counter-clockwise
/// from the robot's heading (K-Team order: 0 = left 90, ..., 5 = right 90,
/// 6 = back right, 7 = back left).
pub const SENSOR_BEARING_DEG: [f32; 8] = [90.0, 45.0, 10.0, -10.0, -45.0, -90.0, -170.0, 170.0];

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SensorKind {
    /// Reflected-IR proximity, 0 (nothing) .. 1 (saturated, very close).
    Proximity,
    /// Ambient light from the same photodiodes, 0 dark .. 1 bright.
    Ambient,
    /// Battery level, 0 empty .. 1 full.
    Level,
    /// Optical barrier between the gripper's arms, 0 or 1.
    Optical,
    /// Ground sensors under the body (the centre unless the body places
    /// them): the floor's grey level, 0 black .. 1 white.
    Ground,
    /// The distance from the body centre to the nearest lamp, 0 .. 1 (1 m
    /// or more, or no lamp): the simulator's knowledge, for fitness terms.
    LampDistance,
    /// Range and bearing: per sector around the body, the nearest other
    /// robot's proximity, 0 (none within range) .. 1 (touching).
    RangeBearing,
    /// What the other robots broadcast: per signal and sector, the
    /// strongest value heard from the robots within range there (0: none).
    Signal,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ActuatorKind {
    /// Two wheel speeds, normalised to -1..1 of `v_max`.
    Speed,
    /// Gripper arm, `up` or `down`.
    Lift,
    /// Gripper claw, `open` or `closed`.
    Grip,
    /// One to four values, 0..1, that the robots within range-and-bearing
    /// range hear at the next action.
    Broadcast,
}

/// One row of the sensor catalog.
#[derive(Clone, Copy, Debug)]
pub struct SensorInfo {
    pub kind: SensorKind,
    /// The keyword that names the kind in a `.bat` file.
    pub keyword: &'static str,
    /// Most elements a sensor of this kind may have.
    pub max_count: usize,
    /// First percept channel.
    pub channel: usize,
    /// One-line description for docs and `--help`.
    pub doc: &'static str,
}

/// One row of the actuator catalog.
#[derive(Clone, Copy, Debug)]
pub struct ActuatorInfo {
    pub kind: ActuatorKind,
    pub keyword: &'static str,
    /// Number of actuator slots (2 for wheels, 1 otherwise).
    pub count: usize,
    /// First actuator slot.
    pub slot: usize,
    /// Names of the discrete states (empty for continuous actuators).
    pub states: &'static [&'static str],
    pub doc: &'static str,
}

pub const SENSORS: [SensorInfo; 8] = [
    SensorInfo {
        kind: SensorKind::Proximity,
        keyword: "proximity",
        max_count: 8,
        channel: CH_IR,
        doc: "reflected infrared, 0 far .. 1 touching; 6 front and 2 back",
    },
    SensorInfo {
        kind: SensorKind::Ambient,
        keyword: "ambient",
        max_count: 8,
        channel: CH_LIGHT,
        doc: "ambient light on the same photodiodes, 0 dark .. 1 bright",
    },
    SensorInfo {
        kind: SensorKind::Level,
        keyword: "level",
        max_count: 1,
        channel: CH_BATTERY,
        doc: "battery level, 0 empty .. 1 full",
    },
    SensorInfo {
        kind: SensorKind::Optical,
        keyword: "optical",
        max_count: 1,
        channel: CH_BARRIER,
        doc: "optical barrier between the gripper's arms, 0 or 1",
    },
    SensorInfo {
        kind: SensorKind::Ground,
        keyword: "ground",
        max_count: GROUND_SENSORS,
        channel: CH_FLOOR,
        doc: "ground sensors under the body: the floor's grey level, 0 black .. 1 white",
    },
    SensorInfo {
        kind: SensorKind::LampDistance,
        keyword: "lamp_distance",
        max_count: 1,
        channel: CH_LAMP_DISTANCE,
        doc: "distance to the nearest lamp in m, 0 .. 1 (1 m or more, or no lamp); simulated only",
    },
    SensorInfo {
        kind: SensorKind::RangeBearing,
        keyword: "range_bearing",
        max_count: RAB_SECTORS,
        channel: CH_RAB,
        doc: "range and bearing: per sector, the nearest other robot's proximity, 0 none in range .. 1 touching",
    },
    SensorInfo {
        kind: SensorKind::Signal,
        keyword: "signal",
        max_count: RAB_SECTORS * SIGNALS,
        channel: CH_HEARD,
        doc: "signals heard: per broadcast value and sector, the strongest value heard there, 0..1",
    },
];

pub const ACTUATORS: [ActuatorInfo; 4] = [
    ActuatorInfo {
        kind: ActuatorKind::Speed,
        keyword: "speed",
        count: 2,
        slot: ACT_LEFT,
        states: &[],
        doc: "left and right wheel speed, -1..1 of v_max",
    },
    ActuatorInfo {
        kind: ActuatorKind::Lift,
        keyword: "lift",
        count: 1,
        slot: ACT_ARM,
        states: &["up", "down"],
        doc: "gripper arm",
    },
    ActuatorInfo {
        kind: ActuatorKind::Grip,
        keyword: "grip",
        count: 1,
        slot: ACT_CLAW,
        states: &["open", "closed"],
        doc: "gripper claw",
    },
    ActuatorInfo {
        kind: ActuatorKind::Broadcast,
        keyword: "broadcast",
        count: SIGNALS,
        slot: ACT_SIGNAL,
        states: &[],
        doc: "one to four values, 0..1, the robots within range hear at the next action",
    },
];

/// Looks a sensor kind up by its keyword.
pub fn sensor_by_keyword(keyword: &str) -> Option<&'static SensorInfo> {
    SENSORS.iter().find(|s| s.keyword == keyword)
}

/// Looks an actuator kind up by its keyword.
pub fn actuator_by_keyword(keyword: &str) -> Option<&'static ActuatorInfo> {
    ACTUATORS.iter().find(|a| a.keyword == keyword)
}

pub fn sensor_info(kind: SensorKind) -> &'static SensorInfo {
    SENSORS.iter().find(|s| s.kind == kind).expect("every kind is in the catalog")
}

pub fn actuator_info(kind: ActuatorKind) -> &'static ActuatorInfo {
    ACTUATORS.iter().find(|a| a.kind == kind).expect("every kind is in the catalog")
}

/// The bearing (radians, counter-clockwise from the heading) a channel looks
/// along, for the `toward(...)` primitive; `None` for channels without a
/// direction (battery, barrier).
pub fn channel_bearing(channel: usize) -> Option<f32> {
    channel_bearing_in(channel, RAB_SECTORS)
}

/// [`channel_bearing`] with `sectors` range-and-bearing sectors: sector
/// `s` (and every signal heard in it) looks along `s * 360 / sectors`
/// degrees.
pub fn channel_bearing_in(channel: usize, sectors: usize) -> Option<f32> {
    let sectors = sectors.clamp(1, RAB_SECTORS);
    let sector = |s: usize| Some((s % sectors) as f32 * std::f32::consts::TAU / sectors as f32);
    match channel {
        c if c < CH_LIGHT => Some(SENSOR_BEARING_DEG[c - CH_IR].to_radians()),
        c if c < CH_BATTERY => Some(SENSOR_BEARING_DEG[c - CH_LIGHT].to_radians()),
        c if (CH_RAB..CH_HEARD).contains(&c) => sector(c - CH_RAB),
        c if (CH_HEARD..CHANNELS).contains(&c) => sector(c - CH_HEARD),
        _ => None,
    }
}

// ------------------------------------------------------------ state slots

/// Number of state slots an expression can read (`robot.x` ...,
/// `distance_to(NAME)`, `team.spread` ... `team.connected`).
pub const STATE_SLOTS: usize = ST_SPREAD + TEAM_SLOTS;
/// The team's slots, from [`ST_SPREAD`]: `team.spread`, `team.grouped`,
/// `team.largest`, `team.nearest`, `team.order`, `team.connected`.
pub const TEAM_SLOTS: usize = 6;
/// The team's spread (`team.spread`): the mean distance of its robots'
/// centres to the team's centre (their mean), mm, after the last action
/// all of them did (0 for one robot). After the targets, so the slots
/// before it keep their numbers.
pub const ST_SPREAD: usize = ST_TARGETS + MAX_TARGETS;
/// The share of the team's robots whose body is within [`crate::state::NEIGHBOUR_GAP`]
/// of another robot's (`team.grouped`; 0 for one robot).
pub const ST_GROUPED: usize = ST_SPREAD + 1;
/// The share of the team's robots in its largest group (`team.largest`):
/// robots joined by bodies within [`crate::state::NEIGHBOUR_GAP`] of each other, and
/// the robots joined to those (1 for one robot).
pub const ST_LARGEST: usize = ST_SPREAD + 2;
/// The mean over the team's robots of the distance from each one's centre
/// to the nearest other robot's centre, mm (`team.nearest`; 0 for one robot).
pub const ST_NEAREST: usize = ST_SPREAD + 3;
/// The length of the mean of the robots' unit heading vectors
/// (`team.order`): 1 when all head one way, near 0 when their headings
/// cancel out (1 for one robot).
pub const ST_ORDER: usize = ST_SPREAD + 4;
/// The share of the team's robots in its largest group connected by the
/// range-and-bearing board's links: robots whose bodies are within the
/// board's range of each other (surface to surface; [`crate::state::LINK_RANGE`]
/// without a board), and the robots linked to those (`team.connected`; 1
/// for one robot).
pub const ST_CONNECTED: usize = ST_SPREAD + 5;
/// The first slot of the distances to the stage's targets
/// (`Stage::targets`): slot `ST_TARGETS + i` is target `i`'s.
pub const ST_TARGETS: usize = 6;
/// The most named items one stage's expressions measure the distance to.
pub const MAX_TARGETS: usize = 8;
/// The body centre, mm from the arena's south-west corner.
pub const ST_X: usize = 0;
pub const ST_Y: usize = 1;
/// The heading, radians counter-clockwise from east, in `-pi..=pi`.
pub const ST_HEADING: usize = 2;
/// The distance the body centre travelled in this life so far, mm.
pub const ST_DISTANCE: usize = 3;
/// The actions done in the life so far (0 before the first; 1 in the
/// expressions evaluated after it).
pub const ST_TIME: usize = 4;
/// The squares of [`crate::state::SQUARE_MM`] the body centre has been in during this life.
pub const ST_SQUARES: usize = 5;
