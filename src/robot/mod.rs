//! The robot commands: `drive` (one individual on a robot), `emulate` (an
//! emulated robot on a pseudo-terminal) and the robot side of `run --robot`.
//! The protocol, the serial robot and the emulator's logic live in the
//! runtime (`shaping_runtime::robot`); the port and the pseudo-terminal here.

pub mod drive;
pub mod emulate;
pub mod evolve;
pub mod port;

pub use evolve::RobotRun;
