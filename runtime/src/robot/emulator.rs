//! An emulated Khepera: answers the serial protocol from the simulator, with
//! the real robot's quantization (integer speed units, 10-bit readings,
//! position counters in pulses).
//!
//! The emulated robot has only the physical world ([`super::physical_world`]):
//! walls, lamp and charger bar. Virtual objects and the battery are the
//! host's. It starts at [`super::start_pose`], where the host assumes it; in a
//! world without objects that is also where a replay with the same seed
//! starts, and the random streams (sensor and wheel noise) are the same.
//!
//! Time: the simulator advances by one action of the world's period at each
//! speed command (`D`), with the speeds it sets, and senses once after it
//! (`N` and `O` answer from that percept). A host that sends one `D` per
//! action, as [`super::SerialRobot`] does, sees the simulator's episode; a
//! real robot moves continuously instead.

use crate::catalog::{CHANNELS, CH_IR, CH_LIGHT};
use crate::program::World;
use crate::sim::{Command, Sim};

use super::protocol::{speed_command, value_reading, Reply, Request, MAX_LINE, MM_PER_PULSE};

/// The emulated robot's state.
pub struct Emulator {
    sim: Sim,
    v_max: f32,
    percept: [f32; CHANNELS],
    /// Wheel travel since the counters were last set, mm.
    travel: [f64; 2],
    /// Position counters at the last `G`.
    base: [i32; 2],
    speed: [i32; 2],
    /// Requests answered so far.
    pub requests: u64,
    /// Actions simulated so far (speed commands).
    pub actions: u64,
}

impl Emulator {
    /// An emulated robot in `world`, seeded with `seed`.
    pub fn new(world: &World, seed: u64) -> Emulator {
        let mut sim = Sim::new(&super::physical_world(world), seed);
        let mut percept = [0.0; CHANNELS];
        sim.sense(&mut percept);
        Emulator {
            sim,
            v_max: world.body.v_max,
            percept,
            travel: [0.0; 2],
            base: [0, 0],
            speed: [0, 0],
            requests: 0,
            actions: 0,
        }
    }

    /// The last wheel speeds set, in units.
    pub fn speed(&self) -> [i32; 2] {
        self.speed
    }

    /// The simulated world.
    pub fn sim(&self) -> &Sim {
        &self.sim
    }

    fn readings(&self, first: usize) -> [u16; 8] {
        std::array::from_fn(|k| value_reading(self.percept[first + k]))
    }

    /// The answer to one command line (without its end of line), with its
    /// `\r\n`; a command the robot does not know gets `z,...` as on a real
    /// Khepera.
    pub fn answer(&mut self, line: &[u8]) -> String {
        self.requests += 1;
        let req = match Request::parse(line) {
            Ok(r) => r,
            Err(_) => return "z,Protocol error\r\n".to_string(),
        };
        let reply = match req {
            Request::Version => Reply::Version("5.02,shaping-emulator".into()),
            Request::SetSpeed(units) => {
                self.speed = units;
                let wheels = [speed_command(units[0], self.v_max), speed_command(units[1], self.v_max)];
                self.sim.step(&Command { wheels, ..Command::default() });
                let t = self.sim.wheel_travel();
                self.travel[0] += f64::from(t[0]);
                self.travel[1] += f64::from(t[1]);
                self.sim.sense(&mut self.percept);
                self.actions += 1;
                Reply::Done
            }
            Request::SetPosition(p) => {
                self.base = p;
                self.travel = [0.0; 2];
                Reply::Done
            }
            Request::ReadPosition => {
                let pulses = |k: usize| {
                    let p = (self.travel[k] / f64::from(MM_PER_PULSE)).round();
                    self.base[k].wrapping_add(p.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32)
                };
                Reply::Position([pulses(0), pulses(1)])
            }
            Request::ReadProximity => Reply::Proximity(self.readings(CH_IR)),
            Request::ReadAmbient => Reply::Ambient(self.readings(CH_LIGHT)),
            // The turret has nothing physical to catch: the objects are the host's.
            Request::Claw(_) | Request::Arm(_) => Reply::Done,
            Request::ReadBarrier => Reply::Barrier(0),
        };
        let out = reply.encode(&req);
        debug_assert!(out.len() <= MAX_LINE + 2);
        out
    }
}
