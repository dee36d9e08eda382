//! Execution of scripted behaviors ([`crate::program::Script`]).
//!
//! Semantics (the runtime side of the language's `script { ... }`):
//! - A script's position (current step and the actions spent in it) is kept
//!   across actions **while its module keeps winning** the arbitration. When
//!   another module wins, the script is reset to its first step, so a script
//!   always starts from the beginning when its module regains control.
//! - After the last step the script wraps around to the first one.
//! - Every action the winning module runs its script up to the first step that
//!   moves something: `reinforce` steps take no time (they are executed and
//!   skipped in the same action) and read `now` = the current percept (the one
//!   the arbitration of this action used), `prev` = the one before, and the
//!   actuator slots of the previous action.
//! - After the action, the current step's end is checked: `Actions(n)` ends
//!   after `n` actions; `Until { cond, within }` ends when `cond` holds on the
//!   percept after the action (`now` = after, `prev` = before the action,
//!   actuators = this action's command) or after `within` actions.
//! - `toward(channels, speed)` steers to the vector sum of the channel
//!   readings along their sensors' bearings: it turns in place when that
//!   direction is more than 20 degrees off the heading, else drives forward at
//!   `speed`; with nothing sensed it drives forward.
//! - `wait` stops the wheels (with `charge`, asks the charger to recharge);
//!   `arm`/`claw` steps stop the wheels and move the gripper.
//! - A step with `if COND` is checked as it is reached, like a `reinforce`
//!   step (same `now`, `prev` and actuators): when COND is false it is
//!   skipped and takes no time.

use nalgebra::Vector2;

use super::fast_expr::FastExpr;
use crate::catalog::{channel_bearing_in, CHANNELS, CH_BATTERY, SIGNALS};
use crate::expr::Env;
use crate::program::{Action, Script, StepEnd};
use crate::sim::Command;

/// Angle beyond which `toward` turns in place instead of driving forward.
pub const TOWARD_DEAD_ZONE_DEG: f32 = 20.0;

/// Shortest summed sensor vector `toward` steers by; shorter is noise (the
/// simulator's sensor noise is 0.01 per channel) and counts as nothing sensed.
pub const TOWARD_MIN_LENGTH: f32 = 0.03;

/// One step with its precomputed data.
#[derive(Clone, Debug)]
enum Op {
    Wheels([f32; 2]),
    /// Channels with the unit vector of their bearing (body frame).
    Toward {
        dirs: Vec<(u16, Vector2<f32>)>,
        speed: f32,
    },
    Arm(bool),
    Claw(bool),
    Wait {
        charge: bool,
    },
    Reinforce(FastExpr),
    Signal([f32; SIGNALS]),
}

#[derive(Clone, Debug)]
enum End {
    Actions(u32),
    Until { cond: FastExpr, within: u32 },
}

/// A script ready to run, with its position.
#[derive(Clone, Debug)]
pub struct ScriptRun {
    steps: Vec<(Op, End)>,
    /// The `if` condition of each step (`None`: always runs).
    when: Vec<Option<FastExpr>>,
    /// The last [`ScriptRun::command`] ran a moving step (not only skipped or
    /// `reinforce` steps).
    acted: bool,
    /// Once started, keeps its module in control until its last step ends.
    commit: bool,
    /// Current step.
    pos: usize,
    /// Actions spent in the current step.
    spent: u32,
}

impl ScriptRun {
    /// `facing`: the bearings (degrees) of a declared IR layout, which
    /// `toward` steers by instead of the catalog's nominal ones; `sectors`:
    /// the range-and-bearing sectors (their bearings and their signals').
    pub fn new(script: &Script, facing: Option<&[f32; 8]>, sectors: usize) -> ScriptRun {
        let steps = script
            .steps
            .iter()
            .map(|s| {
                let op = match &s.action {
                    Action::Wheels { left, right } => Op::Wheels([*left, *right]),
                    Action::Toward { channels, speed } => Op::Toward {
                        dirs: channels
                            .iter()
                            .filter_map(|&c| Some((c, bearing_vector(c as usize, facing, sectors)?)))
                            .collect(),
                        speed: *speed,
                    },
                    Action::Arm(d) => Op::Arm(*d),
                    Action::Claw(c) => Op::Claw(*c),
                    Action::Wait { charge } => Op::Wait { charge: *charge },
                    Action::Reinforce(e) => Op::Reinforce(FastExpr::new(e)),
                    Action::Signal(v) => {
                        let mut values = [0.0; SIGNALS];
                        for (x, &y) in values.iter_mut().zip(v) {
                            *x = y;
                        }
                        Op::Signal(values)
                    }
                };
                let end = match &s.end {
                    StepEnd::Actions(n) => End::Actions(*n),
                    StepEnd::Until { cond, within } => {
                        End::Until { cond: FastExpr::new(cond), within: *within }
                    }
                };
                (op, end)
            })
            .collect();
        let when = script.steps.iter().map(|s| s.when.as_ref().map(FastExpr::new)).collect();
        ScriptRun { steps, when, acted: false, commit: script.commit, pos: 0, spent: 0 }
    }

    /// True when the script contains `reinforce` steps (then they, not the
    /// module's reinforcement program after each action, deliver reinforcement).
    pub fn delivers_reinforcement(&self) -> bool {
        self.steps.iter().any(|(op, _)| matches!(op, Op::Reinforce(_)))
    }

    /// Back to the first step.
    pub fn reset(&mut self) {
        self.pos = 0;
        self.spent = 0;
    }

    /// A committed script between its first action and the end of its last
    /// step: its module keeps control whatever the activations.
    pub fn holds_control(&self) -> bool {
        self.commit && (self.pos > 0 || self.spent > 0)
    }

    /// At the first step with no action spent: the next action starts a run
    /// of the script.
    pub fn at_start(&self) -> bool {
        self.pos == 0 && self.spent == 0
    }

    /// The current step index (for tests and traces).
    pub fn position(&self) -> usize {
        self.pos
    }

    fn advance(&mut self) {
        self.pos = if self.pos + 1 >= self.steps.len() { 0 } else { self.pos + 1 };
        self.spent = 0;
    }

    /// Runs the script up to its next moving step and returns the command.
    /// `reinforcement` receives the sign of the last `reinforce` step run (0 if none).
    pub fn command(&mut self, env: &Env, reinforcement: &mut f32) -> Command {
        // Each step at most once per action, so a script made only of
        // `reinforce` steps cannot loop forever.
        self.acted = false;
        let mut signal = None;
        for _ in 0..self.steps.len() {
            if self.when[self.pos].as_ref().is_some_and(|w| w.eval(env) == 0.0) {
                self.advance();
                continue;
            }
            let op = &self.steps[self.pos].0;
            let cmd = match op {
                Op::Reinforce(e) => {
                    *reinforcement = crate::expr::sign(e.eval(env));
                    self.advance();
                    continue;
                }
                Op::Signal(v) => {
                    signal = Some(*v);
                    self.advance();
                    continue;
                }
                Op::Wheels(w) => Command { wheels: *w, ..Command::default() },
                Op::Toward { dirs, speed } => {
                    Command { wheels: toward(dirs, *speed, env.now), ..Command::default() }
                }
                Op::Arm(d) => Command { arm: Some(*d), ..Command::default() },
                Op::Claw(c) => Command { claw: Some(*c), ..Command::default() },
                Op::Wait { charge } => Command { charge: *charge, ..Command::default() },
            };
            self.acted = true;
            return Command { signal, ..cmd };
        }
        Command { signal, ..Command::default() }
    }

    /// Called after the action the script drove: counts it and moves to the
    /// next step when the current one has ended.
    pub fn after_action(&mut self, env: &Env) {
        if !self.acted {
            // Only reinforce or skipped steps were left this action (nothing moved).
            return;
        }
        let Some((_, end)) = self.steps.get(self.pos) else { return };
        self.spent += 1;
        let done = match end {
            End::Actions(n) => self.spent >= *n,
            End::Until { cond, within } => cond.eval(env) != 0.0 || self.spent >= *within,
        };
        if done {
            self.advance();
        }
    }
}

/// The unit vector (body frame) along a channel's bearing: the declared
/// layout's when there is one, else the catalog's.
fn bearing_vector(channel: usize, facing: Option<&[f32; 8]>, sectors: usize) -> Option<Vector2<f32>> {
    let b = channel_bearing_in(channel, sectors)?;
    let b = match facing {
        Some(f) if channel < CH_BATTERY => f[channel % 8].to_radians(),
        _ => b,
    };
    Some(Vector2::new(b.cos(), b.sin()))
}

/// Wheel speeds steering toward the vector sum of the channel readings.
fn toward(dirs: &[(u16, Vector2<f32>)], speed: f32, now: &[f32; CHANNELS]) -> [f32; 2] {
    let sum = dirs.iter().fold(Vector2::zeros(), |sum, (c, dir)| sum + dir * now[*c as usize]);
    // A vector shorter than TOWARD_MIN_LENGTH is sensor noise: nothing is
    // sensed, drive forward instead of spinning on noise.
    if sum.norm_squared() < TOWARD_MIN_LENGTH * TOWARD_MIN_LENGTH {
        return [speed, speed];
    }
    let side = match ahead(sum.x, sum.y) {
        Some(ahead) => ahead,
        None => side_by_atan2(sum.x, sum.y),
    };
    match side {
        Side::Ahead => [speed, speed],
        // Target on the left (counter-clockwise): turn left in place.
        Side::Left => [-speed, speed],
        Side::Right => [speed, -speed],
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Ahead,
    Left,
    Right,
}

/// Where the vector `(x, y)` points, without the arc tangent, when it is
/// clearly within or outside the dead zone (tangent ratios 0.1% inside and
/// outside `tan(20 deg)` = 0.36397; `atan2` errs by far less); `None` in the
/// thin band between, and for values that are not finite, which are left to
/// `atan2` so that every decision is the one `atan2` makes.
#[inline]
fn ahead(x: f32, y: f32) -> Option<Side> {
    const TAN_IN: f32 = 0.3636;
    const TAN_OUT: f32 = 0.3644;
    if !(x.is_finite() && y.is_finite()) {
        return None;
    }
    // atan2 is positive for y = +0 behind (pi), negative for y = -0 (-pi).
    let outside = if y.is_sign_positive() { Side::Left } else { Side::Right };
    if x <= 0.0 {
        // At least 90 degrees off (the zero vector returned earlier).
        return Some(outside);
    }
    let t = y.abs();
    if t <= x * TAN_IN {
        Some(Side::Ahead)
    } else if t >= x * TAN_OUT {
        Some(outside)
    } else {
        None
    }
}

/// Where the vector `(x, y)` points by its bearing's arc tangent,
/// counter-clockwise from the heading: the rule [`ahead`] follows.
fn side_by_atan2(x: f32, y: f32) -> Side {
    let angle = y.atan2(x);
    if angle.abs() <= TOWARD_DEAD_ZONE_DEG.to_radians() {
        Side::Ahead
    } else if angle > 0.0 {
        Side::Left
    } else {
        Side::Right
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::{CH_IR, CH_LIGHT};

    fn dirs(chans: std::ops::Range<usize>) -> Vec<(u16, Vector2<f32>)> {
        chans.map(|c| (c as u16, bearing_vector(c, None, 8).unwrap())).collect()
    }

    #[test]
    fn a_step_whose_if_condition_is_false_is_skipped_and_takes_no_time() {
        use crate::catalog::{ACT_SLOTS, CH_BARRIER};
        use crate::expr::{Expr, Op};
        use crate::program::Step;
        let not_barrier = Expr { ops: vec![Op::Chan(CH_BARRIER as u16), Op::Not], depth: 1 };
        let step = |action, when| Step { action, end: StepEnd::Actions(1), when };
        let script = Script {
            steps: vec![
                step(Action::Arm(true), None),
                step(Action::Claw(false), Some(not_barrier)),
                step(Action::Wheels { left: -0.5, right: -0.5 }, None),
            ],
            commit: true,
        };
        let act = [0.0; ACT_SLOTS];
        let mut r = 0.0;
        for barrier in [0.0, 1.0] {
            let mut p = [0.0; CHANNELS];
            p[CH_BARRIER] = barrier;
            let env = Env { now: &p, prev: &p, act: &act, state: &Env::NO_STATE };
            let mut s = ScriptRun::new(&script, None, 8);
            assert_eq!(s.command(&env, &mut r).arm, Some(true));
            s.after_action(&env);
            let cmd = s.command(&env, &mut r);
            if barrier == 0.0 {
                assert_eq!(cmd.claw, Some(false), "the condition holds: the claw opens");
                s.after_action(&env);
                assert_eq!(s.command(&env, &mut r).wheels, [-0.5, -0.5]);
            } else {
                assert_eq!(cmd.claw, None, "skipped: the next step runs in the same action");
                assert_eq!(cmd.wheels, [-0.5, -0.5]);
            }
            s.after_action(&env);
            assert_eq!(s.position(), 0, "the script ended and wrapped around");
            assert!(!s.holds_control());
        }
        // Every step skipped: nothing moves and nothing is counted.
        let never = Expr { ops: vec![Op::Const(0.0)], depth: 1 };
        let script = Script { steps: vec![step(Action::Arm(true), Some(never))], commit: false };
        let mut s = ScriptRun::new(&script, None, 8);
        let p = [0.0; CHANNELS];
        let env = Env { now: &p, prev: &p, act: &act, state: &Env::NO_STATE };
        assert_eq!(s.command(&env, &mut r), Command::default());
        s.after_action(&env);
        assert_eq!((s.position(), s.holds_control()), (0, false));
    }

    #[test]
    fn toward_turns_to_the_stronger_side_and_goes_forward_when_ahead() {
        let d = dirs(CH_LIGHT..CH_LIGHT + 8);
        let mut p = [0.0; CHANNELS];
        assert_eq!(toward(&d, 0.5, &p), [0.5, 0.5], "nothing sensed: forward");
        p[CH_LIGHT] = 0.02; // noise-level reading on the left: still nothing
        assert_eq!(toward(&d, 0.5, &p), [0.5, 0.5], "noise is not a direction");
        p[CH_LIGHT] = 1.0; // left 90 degrees
        assert_eq!(toward(&d, 0.5, &p), [-0.5, 0.5]);
        p[CH_LIGHT] = 0.0;
        p[CH_LIGHT + 5] = 1.0; // right 90 degrees
        assert_eq!(toward(&d, 0.5, &p), [0.5, -0.5]);
        p[CH_LIGHT + 5] = 0.0;
        p[CH_LIGHT + 2] = 1.0;
        p[CH_LIGHT + 3] = 0.8; // front pair: straight ahead
        assert_eq!(toward(&d, 0.5, &p), [0.5, 0.5]);
        let d = dirs(CH_IR..CH_IR + 8);
        let mut p = [0.0; CHANNELS];
        p[CH_IR + 6] = 1.0; // back right
        assert_eq!(toward(&d, 1.0, &p), [1.0, -1.0]);
    }

    #[test]
    fn the_dead_zone_without_atan2_decides_as_atan2_does() {
        let by_atan2 = side_by_atan2;
        let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(5);
        let mut decided = 0;
        let mut check = |x: f32, y: f32| {
            if let Some(side) = ahead(x, y) {
                decided += 1;
                assert_eq!(side, by_atan2(x, y), "({x}, {y})");
            }
        };
        use rand::Rng;
        for _ in 0..200_000 {
            // Anywhere, and close to the dead zone's edges.
            let r = rng.random_range(0.001f32..8.0);
            let a = if rng.random::<bool>() {
                rng.random_range(-std::f32::consts::PI..std::f32::consts::PI)
            } else {
                let edge = TOWARD_DEAD_ZONE_DEG.to_radians() * if rng.random::<bool>() { 1.0 } else { -1.0 };
                edge + rng.random_range(-0.01f32..0.01)
            };
            check(r * a.cos(), r * a.sin());
        }
        for (x, y) in
            [(1.0, 0.0), (1.0, -0.0), (-1.0, 0.0), (-1.0, -0.0), (0.0, 1.0), (-0.0, -1.0), (0.0, -0.5)]
        {
            check(x, y);
        }
        assert!(decided > 150_000, "the shortcut should decide most cases: {decided}");
        assert_eq!(ahead(f32::NAN, 1.0), None);
    }

    #[test]
    fn toward_steers_by_a_declared_layouts_bearings() {
        // The e-puck's order: sensor 0 looks ahead and a little right, 2 to
        // the right, 5 to the left.
        let facing = [-17.2, -45.9, -90.0, -151.5, 151.2, 90.0, 45.8, 17.1];
        let chans: Vec<u16> = (CH_IR as u16..CH_IR as u16 + 8).collect();
        let d: Vec<(u16, Vector2<f32>)> =
            chans.iter().map(|&c| (c, bearing_vector(c as usize, Some(&facing), 8).unwrap())).collect();
        let mut p = [0.0; CHANNELS];
        p[CH_IR + 5] = 1.0;
        assert_eq!(toward(&d, 0.5, &p), [-0.5, 0.5], "sensor 5 is on the left");
        p[CH_IR + 5] = 0.0;
        p[CH_IR + 2] = 1.0;
        assert_eq!(toward(&d, 0.5, &p), [0.5, -0.5], "sensor 2 is on the right");
        p[CH_IR + 2] = 0.0;
        p[CH_IR] = 1.0;
        p[CH_IR + 7] = 1.0;
        assert_eq!(toward(&d, 0.5, &p), [0.5, 0.5], "0 and 7 look ahead");
        // the light channels share the bearings
        let v = bearing_vector(CH_LIGHT + 5, Some(&facing), 8).unwrap();
        assert!((v.y - 1.0).abs() < 1e-6);
        // without a layout, the catalog's: sensor 5 on the right
        assert!(bearing_vector(CH_IR + 5, None, 8).unwrap().y < -0.99);
    }
}
