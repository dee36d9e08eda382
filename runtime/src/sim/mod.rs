//! The simulated Khepera world (placeholder: the real model lands with the
//! simulator issue). The API below is the contract the controller uses.

use crate::catalog::CHANNELS;
use crate::program::World;

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

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose {
    pub x: f32,
    pub y: f32,
    /// Heading, radians, counter-clockwise from +x.
    pub theta: f32,
}

/// One simulated episode's world state.
#[derive(Clone, Debug)]
pub struct Sim {
    pose: Pose,
    battery: f32,
}

impl Sim {
    /// A fresh world for one episode; everything random comes from `seed`.
    pub fn new(world: &World, seed: u64) -> Sim {
        let _ = seed;
        Sim { pose: Pose { x: world.arena[0] / 2.0, y: world.arena[1] / 2.0, theta: 0.0 }, battery: 1.0 }
    }

    /// Fills the percept channels for the current state.
    pub fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        out.fill(0.0);
        out[crate::catalog::CH_BATTERY] = self.battery;
    }

    /// Executes one action.
    pub fn step(&mut self, cmd: &Command) -> Outcome {
        let _ = cmd;
        Outcome::default()
    }

    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// Battery level 0..1 (1 forever without a battery).
    pub fn battery(&self) -> f32 {
        self.battery
    }

    /// False once the battery is empty.
    pub fn alive(&self) -> bool {
        self.battery > 0.0
    }
}
