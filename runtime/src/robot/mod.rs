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
