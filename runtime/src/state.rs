//! The robot's state as expressions and descriptors read it: where it is,
//! how far it went, how long it has lived and how much of the arena it has
//! seen. One [`Odometer`] follows a life (the controller's, the stepper's),
//! so the fitness terms, the per-episode descriptors and Python's
//! `evaluate` all read the same numbers.

use serde::{Deserialize, Serialize};

use crate::expr::{Expr, Op};
use crate::program::{Action, Behavior, Stage, StepEnd};

// The slots' numbers live in the catalog, beside the channels' (so an
// expression knows how many there are without the state).
pub use crate::catalog::{
    MAX_TARGETS, STATE_SLOTS, ST_CONNECTED, ST_DISTANCE, ST_GROUPED, ST_HEADING, ST_LARGEST, ST_NEAREST,
    ST_ORDER, ST_SPREAD, ST_SQUARES, ST_TARGETS, ST_TIME, ST_X, ST_Y, TEAM_SLOTS,
};

/// The gap between two bodies within which robots are neighbours, mm: a
/// Khepera's proximity sensors see another body about this far.
pub const NEIGHBOUR_GAP: f32 = 20.0;

/// The gap between two bodies (surface to surface) within which
/// `team.connected` links two robots whose body has no range-and-bearing
/// board, mm: the board's default range (`rab_range`).
pub const LINK_RANGE: f32 = crate::program::RangeBearing::DEFAULT.range;

/// The team's slots for a team of one robot (and what a one-robot life's
/// expressions read): spread 0, grouped 0, largest 1, nearest 0, order 1,
/// connected 1.
pub const TEAM_OF_ONE: [f32; TEAM_SLOTS] = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0];

/// The side of the squares of [`Descriptors::squares_visited`], mm.
pub const SQUARE_MM: f32 = 50.0;

/// How a life (or the lives of an evaluation) moved the robot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Descriptors {
    /// The body centre at the end of the (last) life, mm from the arena's
    /// south-west corner.
    pub x: f32,
    pub y: f32,
    /// The heading at the end of the (last) life, radians counter-clockwise
    /// from +x, in `-pi..=pi`.
    pub heading: f32,
    /// The distance the body centre travelled, mm.
    pub path_length: f32,
    /// The squares of [`SQUARE_MM`] (a grid from the arena's south-west
    /// corner) the body centre was in at the start or after an action,
    /// counted once each.
    pub squares_visited: f32,
}

/// Follows one life's poses: the path length, the squares visited, the
/// actions done. It allocates only when [`Odometer::start`] reserves room.
#[derive(Clone, Debug, Default)]
pub struct Odometer {
    /// Where the body centre is, mm.
    at: [f32; 2],
    path: f64,
    actions: u32,
    square: (i64, i64),
    /// The squares visited, in the order first visited (a life visits few:
    /// a linear search when the square changes is cheaper than hashing).
    squares: Vec<(i64, i64)>,
}

fn square_of([x, y]: [f32; 2]) -> (i64, i64) {
    // Finite positions of any arena; a non-finite one counts as one square.
    let cell =
        |v: f32| if v.is_finite() { (f64::from(v) / f64::from(SQUARE_MM)).floor() as i64 } else { i64::MIN };
    (cell(x), cell(y))
}

impl Odometer {
    /// Starts a life at `at`, with room for `actions` actions' squares.
    pub fn start(&mut self, at: [f32; 2], actions: u32) {
        self.at = at;
        self.path = 0.0;
        self.actions = 0;
        self.square = square_of(at);
        self.squares.clear();
        self.squares.reserve(actions.min(1 << 16) as usize + 1);
        self.squares.push(self.square);
    }

    /// One action done, the body centre now at `at`.
    #[inline]
    pub fn moved(&mut self, at: [f32; 2]) {
        self.actions += 1;
        let (dx, dy) = (f64::from(at[0] - self.at[0]), f64::from(at[1] - self.at[1]));
        // hypot(d, 0) is |d| exactly: a robot that stood still or moved
        // along an axis needs no call.
        let d = if dy == 0.0 {
            dx.abs()
        } else if dx == 0.0 {
            dy.abs()
        } else {
            dx.hypot(dy)
        };
        if d.is_finite() {
            self.path += d;
        }
        self.at = at;
        let square = square_of(at);
        if square != self.square {
            self.square = square;
            if !self.squares.contains(&square) {
                self.squares.push(square);
            }
        }
    }

    /// Actions done in this life.
    pub fn actions(&self) -> u32 {
        self.actions
    }

    /// The state slots, with the robot's `heading`.
    pub fn state(&self, heading: f32) -> [f32; STATE_SLOTS] {
        let mut s = [0.0; STATE_SLOTS];
        s[ST_X] = self.at[0];
        s[ST_Y] = self.at[1];
        s[ST_HEADING] = heading;
        s[ST_DISTANCE] = self.path as f32;
        s[ST_TIME] = self.actions as f32;
        s[ST_SQUARES] = self.squares.len() as f32;
        s
    }

    /// The descriptors of the life so far, the robot's heading now `heading`.
    pub fn descriptors(&self, heading: f32) -> Descriptors {
        Descriptors {
            x: self.at[0],
            y: self.at[1],
            heading,
            path_length: self.path as f32,
            squares_visited: self.squares.len() as f32,
        }
    }
}

/// Some expression of `stage` reads the robot's state (`robot.x` ...).
pub fn reads_state(stage: &Stage) -> bool {
    reads(stage, |_| true)
}

/// Which of the team's measures the expressions of a stage read: what
/// the team measures after each action beside `team.spread` (a sum over
/// the robots, always measured). The others cost a search of the robots'
/// neighbours, made only for a stage that reads them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TeamReads {
    /// `team.grouped` or `team.largest`.
    pub groups: bool,
    /// `team.nearest`.
    pub nearest: bool,
    /// `team.order`.
    pub order: bool,
    /// `team.connected`.
    pub connected: bool,
}

impl TeamReads {
    /// Every measure.
    pub const ALL: TeamReads = TeamReads { groups: true, nearest: true, order: true, connected: true };

    /// What `exprs` read.
    pub fn of_exprs(exprs: &[Expr]) -> TeamReads {
        let reads = |slot: &dyn Fn(usize) -> bool| {
            exprs.iter().any(|e| e.ops.iter().any(|op| matches!(*op, Op::State(v) if slot(v as usize))))
        };
        TeamReads {
            groups: reads(&|slot| slot == ST_GROUPED || slot == ST_LARGEST),
            nearest: reads(&|slot| slot == ST_NEAREST),
            order: reads(&|slot| slot == ST_ORDER),
            connected: reads(&|slot| slot == ST_CONNECTED),
        }
    }

    /// The measures either reads.
    pub fn or(self, other: TeamReads) -> TeamReads {
        TeamReads {
            groups: self.groups || other.groups,
            nearest: self.nearest || other.nearest,
            order: self.order || other.order,
            connected: self.connected || other.connected,
        }
    }

    /// What the expressions of `stage` read.
    pub fn of(stage: &Stage) -> TeamReads {
        TeamReads {
            groups: reads(stage, |slot| slot == ST_GROUPED || slot == ST_LARGEST),
            nearest: reads(stage, |slot| slot == ST_NEAREST),
            order: reads(stage, |slot| slot == ST_ORDER),
            connected: reads(stage, |slot| slot == ST_CONNECTED),
        }
    }
}

/// Some expression of `stage` reads a state slot that `slot` accepts.
fn reads(stage: &Stage, slot: impl Fn(usize) -> bool) -> bool {
    let mut exprs: Vec<&Expr> = Vec::new();
    exprs.extend(&stage.fitness.per_action);
    exprs.extend(&stage.fitness.at_end);
    for f in stage.roles.iter().filter_map(|r| r.fitness.as_ref()) {
        exprs.extend(&f.per_action);
        exprs.extend(&f.at_end);
    }
    for m in &stage.modules {
        exprs.extend(&m.reinforce);
        if let Behavior::Script(s) = &m.behavior {
            for st in &s.steps {
                exprs.extend(&st.when);
                if let Action::Reinforce(e) = &st.action {
                    exprs.push(e);
                }
                if let StepEnd::Until { cond, .. } = &st.end {
                    exprs.push(cond);
                }
            }
        }
    }
    exprs.iter().any(|e| e.ops.iter().any(|op| matches!(*op, Op::State(v) if slot(v as usize))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_odometer_counts_the_path_and_each_square_once() {
        let at = |x, y| [x, y];
        let mut o = Odometer::default();
        o.start(at(10.0, 10.0), 10);
        o.moved(at(40.0, 50.0)); // 50 mm, into square (0, 1)
        o.moved(at(60.0, 50.0));
        o.moved(at(40.0, 50.0)); // back to a square seen
        let d = o.descriptors(0.5);
        assert!((d.path_length - 90.0).abs() < 1e-4, "{d:?}");
        assert_eq!(d.squares_visited, 3.0);
        assert_eq!((d.x, d.y, d.heading), (40.0, 50.0, 0.5));
        let s = o.state(0.5);
        assert_eq!(s[ST_TIME], 3.0);
        assert_eq!(s[ST_SQUARES], 3.0);
        assert_eq!(o.actions(), 3);
        o.start(at(0.0, 0.0), 10);
        assert_eq!(o.descriptors(0.0).squares_visited, 1.0);
        assert_eq!(o.descriptors(0.0).path_length, 0.0);
    }
}
