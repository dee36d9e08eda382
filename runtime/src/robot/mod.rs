//! Running the controller on a Khepera over its serial protocol.
//!
//! - [`protocol`]: the Khepera II ASCII protocol as a pure codec (commands,
//!   answers, line framing, unit conversions);
//! - [`serial`]: [`SerialRobot`], the controller's [`crate::controller::Robot`]
//!   over a [`Link`], with the battery and virtual objects simulated on the
//!   host and the pose from odometry;
//! - [`emulator`]: [`Emulator`], a robot answering the protocol from the
//!   simulator, for tests and for trying without hardware.
//!
//! No I/O here: the CLI implements [`Link`] over a serial port and serves the
//! emulator on a pseudo-terminal.

pub mod emulator;
pub mod protocol;
pub mod serial;

pub use emulator::Emulator;
pub use serial::{odometry, Link, LinkError, RobotError, SerialRobot};

use crate::program::{Stage, World};
use crate::sim::{Pose, Sim};

/// Why `stage` cannot run on a Khepera over its serial link, if it cannot:
/// physical objects (the host does not see them move), or a body whose IR
/// sensors are not the Khepera's (another preset, a declared layout: the
/// robot's own sensors read the walls, the host's layout the virtual
/// objects, and the two would disagree).
pub fn unfit_for_robot(stage: &Stage) -> Option<String> {
    let name = &stage.name;
    if stage.robots() > 1 {
        return Some(format!(
            "stage `{name}` has a team of {} robots; the robot link drives one robot on one serial port (`robots 1`, the default)",
            stage.robots()
        ));
    }
    if stage.world.objects.as_ref().is_some_and(|o| !o.virtual_ && o.count > 0) {
        return Some(format!(
            "stage `{name}` has physical objects; on a robot the objects must be `virtual` (simulated on the host, as in the paper)"
        ));
    }
    let body = &stage.world.body;
    if body.ir.is_some() || body.preset.as_deref().is_some_and(|p| p != "khepera") {
        let what = body
            .preset
            .as_deref()
            .map_or("a declared sensor layout".to_string(), |p| format!("the `{p}` body"));
        return Some(format!(
            "stage `{name}` has {what}; the robot link speaks to a Khepera, whose IR sensors are the Khepera's (`body khepera`, no `proximity` layout)"
        ));
    }
    None
}

/// The world a robot has physically: the arena, lamp and charger bar, and
/// physical objects, without the virtual objects and the battery (which the
/// host simulates).
pub fn physical_world(world: &World) -> World {
    let mut w = world.clone();
    if w.objects.as_ref().is_some_and(|o| o.virtual_) {
        w.objects = None;
    }
    w.battery = None;
    w
}

/// Where a robot starts an episode seeded with `sim_seed`: the start pose
/// of its physical world, so the same seed gives the same start in every
/// stage of an arena, whatever virtual objects a stage adds. The emulator
/// starts there and the host assumes it (a real robot is put there by hand).
pub fn start_pose(world: &World, sim_seed: u64) -> Pose {
    Sim::new(&physical_world(world), sim_seed).pose()
}
