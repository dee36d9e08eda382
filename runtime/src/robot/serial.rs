//! A real (or emulated) Khepera behind a serial link, driven through the
//! controller's [`Robot`] trait, with its battery and virtual objects
//! simulated on the host as in the paper.
//!
//! One action ([`Robot::step`]): the gripper part of the command acts on the
//! host's virtual objects (and, when the stage has a gripper, the arm and
//! claw commands go to the turret); the wheel speeds are sent (`D`); the link
//! waits out the action period ([`Link::wait_action`]); the position
//! counters are read (`H`) and the pose is advanced by odometry (exact arc of
//! the two wheels' travel); the host's battery drains or recharges at that
//! pose. Sensing ([`Robot::sense`]): `N` and `O` give the proximity and
//! ambient readings, scaled to 0..1; the virtual objects' IR is added to the
//! proximity channels (clamped at 1); battery and barrier come from the host.
//!
//! The first failure of the link or of the protocol is kept
//! ([`SerialRobot::error`]) and makes the robot dead ([`Robot::alive`] false),
//! so the controller's episode ends at the next action; the caller then
//! stops the motors ([`SerialRobot::stop`]) and reports it.

use std::fmt;

use crate::catalog::{CHANNELS, CH_IR, CH_LIGHT};
use crate::controller::Robot;
use crate::program::World;
use crate::sim::{Command, Outcome, Pose, Sim};

use super::protocol::{
    parse_reply, reading_value, speed_units, ProtocolError, Reply, Request, ARM_DOWN, ARM_UP, MM_PER_PULSE,
};

/// The byte transport to a robot: the CLI implements it over a serial port.
pub trait Link {
    /// Sends one command line (with its line feed) and returns the answer
    /// line (without its end of line).
    fn exchange(&mut self, command: &str) -> Result<Vec<u8>, LinkError>;
    /// Returns when the current action period is over (a real robot moves
    /// meanwhile). The default returns at once.
    fn wait_action(&mut self) -> Result<(), LinkError> {
        Ok(())
    }
}

/// A transport failure (timeout, closed port, interruption), as a message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LinkError(pub String);

impl fmt::Display for LinkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// Why a robot stopped answering usefully.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RobotError {
    #[error("{0}")]
    Link(LinkError),
    #[error("bad answer to `{command}`: {error}")]
    Protocol { command: String, error: ProtocolError },
}

/// A robot wheel travel below this fraction of the commanded travel (with at
/// least one speed unit commanded) counts as a collision.
pub const STALL_FRACTION: f32 = 0.5;

/// A Khepera behind a [`Link`], its battery and virtual objects on the host.
pub struct SerialRobot<L: Link> {
    link: L,
    host: Sim,
    v_max: f32,
    action_s: f32,
    half_axle: f32,
    gripper: bool,
    counters: [i32; 2],
    pose: Pose,
    arm_down: bool,
    claw_closed: bool,
    error: Option<RobotError>,
    /// Requests exchanged so far.
    pub requests: u64,
}

impl<L: Link> SerialRobot<L> {
    /// A robot in `world`: the host world (virtual objects, battery,
    /// charger) is `Sim::new(world, sim_seed)`; the robot is assumed to stand
    /// at `start` (default: [`super::start_pose`]). `gripper`: the stage
    /// has an arm or a claw, whose commands then go to the turret too.
    pub fn new(world: &World, sim_seed: u64, start: Option<Pose>, gripper: bool, link: L) -> SerialRobot<L> {
        let mut host = Sim::new(world, sim_seed);
        let pose = start.unwrap_or_else(|| super::start_pose(world, sim_seed));
        host.place(pose);
        SerialRobot {
            link,
            host,
            v_max: world.body.v_max,
            action_s: world.body.action_ms / 1000.0,
            half_axle: (world.body.wheel_base / 2.0).max(0.1),
            gripper,
            counters: [0, 0],
            pose,
            arm_down: false,
            claw_closed: false,
            error: None,
            requests: 0,
        }
    }

    /// One command and its parsed answer; a failure is kept as the robot's error.
    pub fn request(&mut self, req: Request) -> Result<Reply, RobotError> {
        if let Some(e) = &self.error {
            return Err(e.clone());
        }
        self.requests += 1;
        let result = match self.link.exchange(&req.encode()) {
            Err(e) => Err(RobotError::Link(e)),
            Ok(line) => parse_reply(&req, &line)
                .map_err(|error| RobotError::Protocol { command: req.to_string(), error }),
        };
        if let Err(e) = &result {
            self.error = Some(e.clone());
        }
        result
    }

    /// Gets the robot ready: zeroes the position counters and, with a
    /// gripper, raises the arm and opens the claw. (No speed is sent: the
    /// first `D` is the first action's, and the emulator counts actions by
    /// them.)
    pub fn connect(&mut self) -> Result<(), RobotError> {
        self.request(Request::SetPosition([0, 0]))?;
        self.counters = [0, 0];
        if self.gripper {
            self.request(Request::Arm(ARM_UP))?;
            self.request(Request::Claw(false))?;
        }
        Ok(())
    }

    /// Sends speed zero, whatever happened before (a kept error does not stop
    /// it). Retries a few times when the answer is lost or garbled.
    pub fn stop(&mut self) -> Result<(), RobotError> {
        let req = Request::SetSpeed([0, 0]);
        let mut last = None;
        for _ in 0..3 {
            match self.link.exchange(&req.encode()) {
                Ok(line) => match parse_reply(&req, &line) {
                    Ok(_) => return Ok(()),
                    Err(error) => last = Some(RobotError::Protocol { command: req.to_string(), error }),
                },
                Err(e) => last = Some(RobotError::Link(e)),
            }
        }
        Err(last.unwrap_or(RobotError::Link(LinkError("the robot does not answer".into()))))
    }

    /// The first failure, if any.
    pub fn error(&self) -> Option<&RobotError> {
        self.error.as_ref()
    }

    /// The host's world (virtual objects, charger), for pictures.
    pub fn host(&self) -> &Sim {
        &self.host
    }

    /// The link, given back.
    pub fn into_link(self) -> L {
        self.link
    }

    fn readings(&mut self, req: Request) -> Option<[u16; 8]> {
        match self.request(req) {
            Ok(Reply::Proximity(v) | Reply::Ambient(v)) => Some(v),
            _ => None,
        }
    }

    fn set_gripper(&mut self, cmd: &Command) {
        if !self.gripper {
            return;
        }
        if let Some(down) = cmd.arm {
            if down != self.arm_down
                && self.request(Request::Arm(if down { ARM_DOWN } else { ARM_UP })).is_ok()
            {
                self.arm_down = down;
            }
        }
        if let Some(closed) = cmd.claw {
            if closed != self.claw_closed && self.request(Request::Claw(closed)).is_ok() {
                self.claw_closed = closed;
            }
        }
    }
}

/// The pose after the wheels travelled `dl` and `dr` mm: the exact arc.
pub fn odometry(pose: Pose, dl: f32, dr: f32, half_axle: f32) -> Pose {
    let d = (dl + dr) / 2.0;
    let phi = (dr - dl) / (2.0 * half_axle);
    // The chord of the arc, along the heading turned by half the angle.
    let half = phi / 2.0;
    let chord = if half.abs() < 1e-4 { d } else { d * half.sin() / half };
    let a = pose.theta + half;
    let theta = pose.theta + phi;
    let theta =
        theta - std::f32::consts::TAU * ((theta + std::f32::consts::PI) / std::f32::consts::TAU).floor();
    Pose { x: pose.x + chord * a.cos(), y: pose.y + chord * a.sin(), theta }
}

impl<L: Link> Robot for SerialRobot<L> {
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        self.host.sense_virtual(out);
        let ir = self.readings(Request::ReadProximity).unwrap_or([0; 8]);
        let light = self.readings(Request::ReadAmbient).unwrap_or([0; 8]);
        for k in 0..8 {
            out[CH_IR + k] = (out[CH_IR + k] + reading_value(ir[k])).clamp(0.0, 1.0);
            out[CH_LIGHT + k] = reading_value(light[k]);
        }
    }

    fn step(&mut self, cmd: &Command) -> Outcome {
        if self.error.is_some() {
            return Outcome::default();
        }
        let mut out = self.host.actuate(cmd);
        self.set_gripper(cmd);
        let units = [speed_units(cmd.wheels[0], self.v_max), speed_units(cmd.wheels[1], self.v_max)];
        if self.request(Request::SetSpeed(units)).is_err() {
            return out;
        }
        if let Err(e) = self.link.wait_action() {
            self.error = Some(RobotError::Link(e));
            return out;
        }
        let Ok(Reply::Position(now)) = self.request(Request::ReadPosition) else {
            return out;
        };
        let pulses = [now[0].wrapping_sub(self.counters[0]), now[1].wrapping_sub(self.counters[1])];
        self.counters = now;
        let travel = [pulses[0] as f32 * MM_PER_PULSE, pulses[1] as f32 * MM_PER_PULSE];
        self.pose = odometry(self.pose, travel[0], travel[1], self.half_axle);
        self.host.place(self.pose);
        out.recharged = self.host.tick_battery(cmd.charge);
        // A wheel that moved much less than commanded was blocked.
        out.collided = (0..2).any(|k| {
            let expected = units[k] as f32 * super::protocol::MM_S_PER_UNIT * self.action_s;
            units[k] != 0 && travel[k].abs() < STALL_FRACTION * expected.abs()
        });
        out
    }

    fn alive(&self) -> bool {
        self.error.is_none() && self.host.alive()
    }

    fn battery(&self) -> f32 {
        self.host.battery()
    }

    fn pose(&self) -> Pose {
        self.pose
    }

    fn holding(&self) -> Option<bool> {
        Some(self.host.holding())
    }

    /// The virtual objects' placements on the host (the robot stands where
    /// it is put).
    fn placement_failures(&self) -> u32 {
        self.host.placement_failures()
    }
}
