//! Compiled expressions: reinforcement programs, fitness terms and `until`
//! conditions, as postfix code over a small fixed stack.
//!
//! Semantics: every value is an `f32`; comparisons and logic give 1 or 0 and
//! treat any non-zero value as true; `x / 0` is 0; `sign(0)` is 0.

use serde::{Deserialize, Serialize};

use crate::catalog::{ACT_SLOTS, CHANNELS, STATE_SLOTS};

/// Deepest stack an expression may need; the compiler rejects deeper ones.
pub const MAX_STACK: usize = 32;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Op {
    Const(f32),
    /// Percept channel, this action.
    Chan(u16),
    /// Percept channel, previous action.
    Prev(u16),
    /// Actuator slot (see `catalog::ACT_*`), as commanded this action.
    Act(u16),
    /// The robot's state (see `state::ST_*`): its pose, distance, time, squares.
    State(u16),
    Neg,
    Not,
    Abs,
    Sign,
    /// Square root of the value, 0 for a negative one.
    Sqrt,
    Add,
    Sub,
    Mul,
    Div,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
    /// Pops `else`, `then`, `cond` (pushed in that order: cond, then, else).
    Select,
    /// Pops `n` values.
    Max(u16),
    Min(u16),
    Sum(u16),
    Mean(u16),
}

/// A compiled expression: postfix code whose evaluation needs at most `depth`
/// stack slots.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Expr {
    pub ops: Vec<Op>,
    pub depth: u16,
}

/// What an expression reads.
pub struct Env<'a> {
    pub now: &'a [f32; CHANNELS],
    pub prev: &'a [f32; CHANNELS],
    pub act: &'a [f32; ACT_SLOTS],
    /// The robot's state (`state::ST_*`).
    pub state: &'a [f32; STATE_SLOTS],
}

impl Env<'_> {
    /// A state of zeros, for expressions evaluated outside a life.
    pub const NO_STATE: [f32; STATE_SLOTS] = [0.0; STATE_SLOTS];
}

fn truth(b: bool) -> f32 {
    if b {
        1.0
    } else {
        0.0
    }
}

impl Expr {
    pub fn constant(v: f32) -> Expr {
        Expr { ops: vec![Op::Const(v)], depth: 1 }
    }

    /// Computes the stack depth the code needs, or `None` if it is malformed
    /// (pops from an empty stack or does not leave exactly one value).
    pub fn required_depth(ops: &[Op]) -> Option<u16> {
        let mut sp: i64 = 0;
        let mut max = 0i64;
        for op in ops {
            let (pop, push) = match *op {
                Op::Const(_) | Op::Chan(_) | Op::Prev(_) | Op::Act(_) | Op::State(_) => (0, 1),
                Op::Neg | Op::Not | Op::Abs | Op::Sign | Op::Sqrt => (1, 1),
                Op::Select => (3, 1),
                Op::Max(n) | Op::Min(n) | Op::Sum(n) | Op::Mean(n) => {
                    if n == 0 {
                        return None;
                    }
                    (n as i64, 1)
                }
                _ => (2, 1),
            };
            if sp < pop {
                return None;
            }
            sp = sp - pop + push;
            max = max.max(sp);
        }
        if sp == 1 {
            u16::try_from(max).ok()
        } else {
            None
        }
    }

    /// True when every channel and actuator index is in range and the code is
    /// well formed within [`MAX_STACK`].
    pub fn is_valid(&self) -> bool {
        let indices_ok = self.ops.iter().all(|op| match *op {
            Op::Chan(c) | Op::Prev(c) => (c as usize) < CHANNELS,
            Op::Act(a) => (a as usize) < ACT_SLOTS,
            Op::State(v) => (v as usize) < STATE_SLOTS,
            _ => true,
        });
        indices_ok
            && matches!(Self::required_depth(&self.ops), Some(d) if d == self.depth && (d as usize) <= MAX_STACK)
    }

    /// Evaluates the expression. The expression must be valid ([`Expr::is_valid`]).
    #[inline]
    pub fn eval(&self, env: &Env) -> f32 {
        let mut stack = [0.0f32; MAX_STACK];
        let mut sp = 0usize;
        for &op in &self.ops {
            sp = apply(op, &mut stack, sp, env);
        }
        stack[0]
    }
}

/// `-1`, `0` or `1`.
#[inline]
pub fn sign(v: f32) -> f32 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The value of an aggregate op (`Max`, `Min`, `Sum`, `Mean`) over `vals`.
#[inline]
pub fn aggregate(op: Op, vals: &[f32]) -> f32 {
    match op {
        Op::Max(_) => vals.iter().copied().fold(f32::NEG_INFINITY, f32::max),
        Op::Min(_) => vals.iter().copied().fold(f32::INFINITY, f32::min),
        Op::Sum(_) => vals.iter().sum(),
        _ => vals.iter().sum::<f32>() / vals.len() as f32,
    }
}

/// Executes one op on the stack (`sp` values on it) and returns the new
/// stack pointer. The code must be valid ([`Expr::is_valid`]).
#[inline(always)]
pub fn apply(op: Op, stack: &mut [f32; MAX_STACK], mut sp: usize, env: &Env) -> usize {
    match op {
        Op::Const(v) => {
            stack[sp] = v;
            sp += 1;
        }
        Op::Chan(c) => {
            stack[sp] = env.now[c as usize];
            sp += 1;
        }
        Op::Prev(c) => {
            stack[sp] = env.prev[c as usize];
            sp += 1;
        }
        Op::Act(a) => {
            stack[sp] = env.act[a as usize];
            sp += 1;
        }
        Op::State(v) => {
            stack[sp] = env.state[v as usize];
            sp += 1;
        }
        Op::Neg => stack[sp - 1] = -stack[sp - 1],
        Op::Not => stack[sp - 1] = truth(stack[sp - 1] == 0.0),
        Op::Abs => stack[sp - 1] = stack[sp - 1].abs(),
        Op::Sign => stack[sp - 1] = sign(stack[sp - 1]),
        Op::Sqrt => stack[sp - 1] = stack[sp - 1].max(0.0).sqrt(),
        Op::Select => {
            let (c, t, e) = (stack[sp - 3], stack[sp - 2], stack[sp - 1]);
            sp -= 2;
            stack[sp - 1] = if c != 0.0 { t } else { e };
        }
        Op::Max(n) | Op::Min(n) | Op::Sum(n) | Op::Mean(n) => {
            let n = n as usize;
            let v = aggregate(op, &stack[sp - n..sp]);
            sp -= n;
            stack[sp] = v;
            sp += 1;
        }
        bin => {
            let (a, b) = (stack[sp - 2], stack[sp - 1]);
            sp -= 1;
            stack[sp - 1] = match bin {
                Op::Add => a + b,
                Op::Sub => a - b,
                Op::Mul => a * b,
                Op::Div => {
                    if b == 0.0 {
                        0.0
                    } else {
                        a / b
                    }
                }
                Op::Lt => truth(a < b),
                Op::Le => truth(a <= b),
                Op::Gt => truth(a > b),
                Op::Ge => truth(a >= b),
                Op::Eq => truth(a == b),
                Op::Ne => truth(a != b),
                Op::And => truth(a != 0.0 && b != 0.0),
                Op::Or => truth(a != 0.0 || b != 0.0),
                _ => unreachable!("unary and n-ary ops are matched above"),
            };
        }
    }
    sp
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env_eval(ops: Vec<Op>, now: [f32; CHANNELS]) -> f32 {
        let depth = Expr::required_depth(&ops).unwrap();
        let e = Expr { ops, depth };
        assert!(e.is_valid());
        let prev = [0.5; CHANNELS];
        let act = [0.25, -0.75, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0];
        e.eval(&Env { now: &now, prev: &prev, act: &act, state: &Env::NO_STATE })
    }

    #[test]
    fn arithmetic_and_aggregates() {
        let mut now = [0.0; CHANNELS];
        now[0] = 0.2;
        now[1] = 0.9;
        // sign(max(prev ir0, prev ir1) - max(ir0, ir1)) = sign(0.5 - 0.9) = -1
        let v = env_eval(
            vec![
                Op::Prev(0),
                Op::Prev(1),
                Op::Max(2),
                Op::Chan(0),
                Op::Chan(1),
                Op::Max(2),
                Op::Sub,
                Op::Sign,
            ],
            now,
        );
        assert_eq!(v, -1.0);
        // abs(wheels0 + wheels1) / 2 = 0.25
        let v = env_eval(vec![Op::Act(0), Op::Act(1), Op::Add, Op::Abs, Op::Const(2.0), Op::Div], now);
        assert_eq!(v, 0.25);
        // ir1 > 0.5 ? 1 : -1
        let v = env_eval(
            vec![Op::Chan(1), Op::Const(0.5), Op::Gt, Op::Const(1.0), Op::Const(-1.0), Op::Select],
            now,
        );
        assert_eq!(v, 1.0);
        let v = env_eval(vec![Op::Const(1.0), Op::Const(0.0), Op::Div], now);
        assert_eq!(v, 0.0);
        let v = env_eval(vec![Op::Chan(0), Op::Chan(1), Op::Mean(2)], now);
        assert!((v - 0.55).abs() < 1e-6);
    }

    #[test]
    fn malformed_code_is_rejected() {
        assert_eq!(Expr::required_depth(&[Op::Add]), None);
        assert_eq!(Expr::required_depth(&[Op::Const(1.0), Op::Const(2.0)]), None);
        assert_eq!(Expr::required_depth(&[Op::Max(0)]), None);
        let e = Expr { ops: vec![Op::Chan(200)], depth: 1 };
        assert!(!e.is_valid());
    }
}
