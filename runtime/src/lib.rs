//! `shaping-runtime`: executes compiled shaping programs.
//!
//! - [`program`]: the `Program` types, the compiler's target (serde, no spans);
//! - [`catalog`]: the sensors and actuators of the simulated platform;
//! - [`bodies`]: the named bodies (`khepera`, `e-puck`);
//! - [`expr`]: compiled expressions (reinforcement, fitness, `until`);
//! - [`genome`]: bit-string genomes and decoding;
//! - [`sim`]: the simulated Khepera world;
//! - [`controller`]: modules, winner-take-all, behaviors, CRBP, episodes;
//! - [`evolve`]: the incremental GA over stages, with checkpoints as data;
//! - [`robot`]: the Khepera serial protocol, a serial robot with a host-side
//!   virtual world, and an emulated robot.
//! - [`validate`]: the one validation of a `Program`, with the [`limits`].
//!
//! This crate never depends on the compiler and does no file I/O.

pub mod bodies;
pub mod catalog;
pub mod controller;
pub mod evolve;
pub mod expr;
pub mod genome;
pub mod limits;
pub mod oracle;
pub mod program;
pub mod robot;
pub mod sim;
pub mod state;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
pub mod validate;
pub mod world;
