//! Expressions prepared for the per-action loop: the same semantics as
//! [`Expr::eval`], with runs of consecutive channel reads feeding an
//! aggregate (`max(ir)` compiles to `Chan(0) .. Chan(7) Max(8)`) fused into
//! one instruction, which removes most of the interpreter's dispatch in the
//! reinforcement and fitness programs. Equivalence with [`Expr::eval`] is
//! tested on random programs.

use crate::expr::{aggregate, apply, Env, Expr, Op, MAX_STACK};

#[derive(Clone, Copy, Debug, PartialEq)]
enum FOp {
    Op(Op),
    /// Pushes the aggregate of channels `start..start + n` of `now` (or `prev`).
    Run {
        /// The aggregate op (`Max`, `Min`, `Sum` or `Mean`).
        agg: Op,
        prev: bool,
        start: u16,
        n: u16,
    },
    /// A push (`Const`, `Chan`, `Prev` or `Act`) and the binary op that
    /// follows it: one dispatch instead of two, the same operations.
    Then {
        push: Op,
        op: Op,
    },
}

/// A prepared expression; build it from a valid [`Expr`].
#[derive(Clone, Debug, PartialEq)]
pub struct FastExpr {
    ops: Vec<FOp>,
}

impl FastExpr {
    pub fn new(e: &Expr) -> FastExpr {
        let src = &e.ops;
        let mut ops = Vec::with_capacity(src.len());
        let mut i = 0;
        while i < src.len() {
            if let Some((fused, len)) = fuse(&src[i..]) {
                ops.push(fused);
                i += len;
            } else if let (push @ (Op::Const(_) | Op::Chan(_) | Op::Prev(_) | Op::Act(_)), Some(&op)) =
                (src[i], src.get(i + 1).filter(|op| is_binary(**op)))
            {
                ops.push(FOp::Then { push, op });
                i += 2;
            } else {
                ops.push(FOp::Op(src[i]));
                i += 1;
            }
        }
        FastExpr { ops }
    }

    /// Evaluates like [`Expr::eval`] (the source expression must be valid).
    #[inline]
    pub fn eval(&self, env: &Env) -> f32 {
        let mut stack = [0.0f32; MAX_STACK];
        let mut sp = 0usize;
        for op in &self.ops {
            match *op {
                FOp::Run { agg, prev, start, n } => {
                    let src = if prev { env.prev } else { env.now };
                    stack[sp] = aggregate(agg, &src[start as usize..start as usize + n as usize]);
                    sp += 1;
                }
                FOp::Then { push, op } => {
                    sp = apply(push, &mut stack, sp, env);
                    sp = apply(op, &mut stack, sp, env);
                }
                FOp::Op(op) => sp = apply(op, &mut stack, sp, env),
            }
        }
        stack[0]
    }
}

/// An op that pops two values and pushes one.
fn is_binary(op: Op) -> bool {
    matches!(
        op,
        Op::Add
            | Op::Sub
            | Op::Mul
            | Op::Div
            | Op::Lt
            | Op::Le
            | Op::Gt
            | Op::Ge
            | Op::Eq
            | Op::Ne
            | Op::And
            | Op::Or
    )
}

/// `Chan(c) Chan(c+1) .. Chan(c+n-1) Agg(n)` (or the same with `Prev`) at the
/// start of `ops`: the fused instruction and how many ops it replaces.
fn fuse(ops: &[Op]) -> Option<(FOp, usize)> {
    let (prev, start) = match ops.first()? {
        Op::Chan(c) => (false, *c),
        Op::Prev(c) => (true, *c),
        _ => return None,
    };
    let mut n = 1usize;
    while let Some(op) = ops.get(n) {
        let next = start as usize + n;
        match (*op, prev) {
            (Op::Chan(c), false) | (Op::Prev(c), true) if c as usize == next => n += 1,
            _ => break,
        }
    }
    let agg = match *ops.get(n)? {
        agg @ (Op::Max(k) | Op::Min(k) | Op::Sum(k) | Op::Mean(k)) if k as usize == n => agg,
        _ => return None,
    };
    Some((FOp::Run { agg, prev, start, n: n as u16 }, n + 1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::{ACT_SLOTS, CHANNELS};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A random well-formed program of about `size` operations, biased toward
    /// channel runs and aggregates.
    fn random_ops(rng: &mut ChaCha8Rng, size: usize) -> Vec<Op> {
        let mut ops = Vec::new();
        let mut depth = 0usize;
        while ops.len() < size || depth != 1 {
            let can_pop = |k: usize| depth >= k;
            let choice = rng.random_range(0..10);
            if depth >= 20 || (ops.len() >= size && depth > 1) {
                ops.push([Op::Add, Op::Sub, Op::Mul, Op::Max(2), Op::Lt][rng.random_range(0..5)]);
                depth -= 1;
                continue;
            }
            match choice {
                0..=2 => {
                    // A channel run, maybe aggregated.
                    let n = rng.random_range(1..=8u16);
                    let start = rng.random_range(0..=(CHANNELS as u16 - n));
                    let prev = rng.random::<bool>();
                    for c in start..start + n {
                        ops.push(if prev { Op::Prev(c) } else { Op::Chan(c) });
                    }
                    depth += n as usize;
                    if rng.random::<bool>() {
                        ops.push([Op::Max(n), Op::Min(n), Op::Sum(n), Op::Mean(n)][rng.random_range(0..4)]);
                        depth -= n as usize - 1;
                    }
                }
                3 => {
                    ops.push(Op::Const([0.0, 1.0, -0.5, 2.0][rng.random_range(0..4)]));
                    depth += 1;
                }
                4 => {
                    ops.push(Op::Act(rng.random_range(0..ACT_SLOTS as u16)));
                    depth += 1;
                }
                5 if can_pop(1) => ops.push([Op::Neg, Op::Not, Op::Abs, Op::Sign][rng.random_range(0..4)]),
                6 | 7 if can_pop(2) => {
                    let bin = [
                        Op::Add,
                        Op::Sub,
                        Op::Mul,
                        Op::Div,
                        Op::Lt,
                        Op::Le,
                        Op::Gt,
                        Op::Ge,
                        Op::Eq,
                        Op::Ne,
                        Op::And,
                        Op::Or,
                    ];
                    ops.push(bin[rng.random_range(0..bin.len())]);
                    depth -= 1;
                }
                8 if can_pop(3) => {
                    ops.push(Op::Select);
                    depth -= 2;
                }
                9 if can_pop(2) => {
                    let n = rng.random_range(2..=depth.min(4)) as u16;
                    ops.push([Op::Max(n), Op::Min(n), Op::Sum(n), Op::Mean(n)][rng.random_range(0..4)]);
                    depth -= n as usize - 1;
                }
                _ => {
                    ops.push(Op::Const(0.25));
                    depth += 1;
                }
            }
        }
        ops
    }

    #[test]
    fn fused_evaluation_matches_the_reference_interpreter() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut fused_any = 0;
        for _ in 0..2000 {
            let size = rng.random_range(1..30);
            let ops = random_ops(&mut rng, size);
            let Some(depth) = Expr::required_depth(&ops) else { panic!("generator made bad code: {ops:?}") };
            let e = Expr { ops, depth };
            if !e.is_valid() {
                continue;
            }
            let f = FastExpr::new(&e);
            fused_any += (f.ops.len() < e.ops.len()) as u32;
            for _ in 0..5 {
                let mut now = [0.0f32; CHANNELS];
                let mut prev = [0.0f32; CHANNELS];
                let mut act = [0.0f32; ACT_SLOTS];
                for v in now.iter_mut().chain(prev.iter_mut()).chain(act.iter_mut()) {
                    *v = if rng.random_range(0..4) == 0 { 0.0 } else { rng.random_range(-1.0..1.0) };
                }
                let env = Env { now: &now, prev: &prev, act: &act, state: &Env::NO_STATE };
                let (a, b) = (e.eval(&env), f.eval(&env));
                assert!(a == b || (a.is_nan() && b.is_nan()), "{:?}: {a} vs {b}", e.ops);
            }
        }
        assert!(fused_any > 500, "the generator should exercise fusion: {fused_any}");
    }

    #[test]
    fn max_of_a_channel_run_is_one_instruction() {
        let e = crate::testkit::ir_decrease();
        let f = FastExpr::new(&e);
        assert_eq!(f.ops.len(), 4, "{:?}", f.ops);
    }

    #[test]
    fn a_push_and_the_binary_op_after_it_are_one_instruction() {
        // abs(wheels[0] + wheels[1]) / 2: Act Act Add Abs Const Div.
        let e =
            Expr { ops: vec![Op::Act(0), Op::Act(1), Op::Add, Op::Abs, Op::Const(2.0), Op::Div], depth: 2 };
        let f = FastExpr::new(&e);
        assert_eq!(
            f.ops,
            vec![
                FOp::Op(Op::Act(0)),
                FOp::Then { push: Op::Act(1), op: Op::Add },
                FOp::Op(Op::Abs),
                FOp::Then { push: Op::Const(2.0), op: Op::Div },
            ]
        );
        let act = [0.25, -0.75, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0];
        let p = [0.0; CHANNELS];
        assert_eq!(f.eval(&Env { now: &p, prev: &p, act: &act, state: &Env::NO_STATE }), 0.25);
    }
}
