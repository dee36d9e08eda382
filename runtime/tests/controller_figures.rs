//! The paper's learning figures on the simulator: figure 5 (the obstacle
//! avoidance module learns from random weights) and a figure-10 analogue (the
//! grip module's activation network learns to tell objects from walls).
//! Run with `--nocapture` to see the curves.

use shaping_runtime::catalog::{CHANNELS, CH_BARRIER, CH_IR};
use shaping_runtime::controller::{episode_rngs, Controller};
use shaping_runtime::expr::{Expr, Op};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::*;
use shaping_runtime::sim::Sim;
use shaping_runtime::testkit::{self, expr, max_ir};

/// Figure 5's reinforcement program. With `i = max(ir)` after the action and
/// `p = max(prev ir)` before it:
/// `i - p > 0.02 ? -1 : p - i > 0.02 ? 1 : i > close ? -1 : i < 0.1 ? sign(wheels[0] + wheels[1]) : 0`:
/// punished when the highest proximity reading increases, rewarded when it
/// decreases (the paper's program, with a 0.02 dead band so the 0.01 sensor
/// noise gives no signal), punished for staying close to an obstacle (`i >
/// close`, e.g. pushing against a wall), and in free space rewarded for moving
/// forward and punished for moving back (turns give no signal).
fn avoid_reinforcement(close: f32) -> Expr {
    avoid_reinforcement_eps(close, 0.02)
}

fn avoid_reinforcement_eps(close: f32, eps: f32) -> Expr {
    let mut ops = max_ir(false);
    ops.extend(max_ir(true));
    ops.extend([Op::Sub, Op::Const(eps), Op::Gt, Op::Const(-1.0)]);
    ops.extend(max_ir(true));
    ops.extend(max_ir(false));
    ops.extend([Op::Sub, Op::Const(eps), Op::Gt, Op::Const(1.0)]);
    ops.extend(max_ir(false));
    ops.extend([Op::Const(close), Op::Gt, Op::Const(-1.0)]);
    ops.extend(max_ir(false));
    ops.extend([
        Op::Const(0.1),
        Op::Lt,
        Op::Act(0),
        Op::Act(1),
        Op::Add,
        Op::Sign,
        Op::Const(0.0),
        Op::Select,
    ]);
    ops.extend([Op::Select, Op::Select, Op::Select]);
    expr(ops)
}

/// The avoid module alone in the paper's arena (no battery): 8 IR -> 2 output
/// bits (back / left / right / forward), random initial weights in -0.5..0.5,
/// CRBP always with the given rates, performance window 30.
fn avoid_stage(reinforce: Expr, rate_reward: f32, rate_punish: f32) -> Stage {
    let mut s = testkit::bare_stage("avoid", testkit::arena_world());
    s.world.battery = None;
    let mut avoid = testkit::module("avoid", 0, vec![], testkit::avoid_behavior(0.5, 1.0));
    avoid.activation.params = vec![Param::Fixed(0.0)];
    avoid.learning = Some(testkit::crbp(LearnTarget::Behavior, rate_reward, rate_punish, 30));
    avoid.reinforce = Some(reinforce);
    s.modules = vec![avoid];
    s
}

/// The performance indicator after every action of one episode.
fn avoid_curve(stage: &Stage, seed: u64, actions: usize) -> Vec<f32> {
    let (sim_seed, rng) = episode_rngs(seed);
    let mut c = Controller::new(stage, &Genome::zeros(0), rng).unwrap();
    let mut sim = Sim::new(&stage.world, sim_seed);
    c.start(&mut sim);
    (0..actions)
        .map(|_| {
            c.act(&mut sim);
            c.performance(0)
        })
        .collect()
}

fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len() as f32
}

#[test]
#[ignore = "exploration: prints curves for several reinforcement programs and rates"]
fn figure5_explore() {
    let variants: Vec<(&str, Expr, f32, f32)> = vec![
        ("paper sign(max(prev ir)-max(ir)) .1/.01", testkit::ir_decrease(), 0.1, 0.01),
        ("paper sign(max(prev ir)-max(ir)) .2/.05", testkit::ir_decrease(), 0.2, 0.05),
        ("no stuck punishment .2/.05", avoid_reinforcement(2.0), 0.2, 0.05),
        ("eps .05 .2/.05", avoid_reinforcement_eps(0.5, 0.05), 0.2, 0.05),
        ("tuned (the test's) .2/.05", avoid_reinforcement(0.5), 0.2, 0.05),
        ("tuned .1/.01", avoid_reinforcement(0.5), 0.1, 0.01),
    ];
    println!(
        "columns: mean of actions 0..100, 100..300, each block of 500, 4000..5000; one row per seed 1..=5"
    );
    for (name, r, rr, rp) in variants {
        let s = avoid_stage(r, rr, rp);
        let mut rows = Vec::new();
        for seed in 1..=5 {
            let c = avoid_curve(&s, seed, 5000);
            let mut pts: Vec<f32> = vec![mean(&c[..100]), mean(&c[100..300])];
            pts.extend((1..=10usize).map(|k| mean(&c[k * 500 - 500..k * 500])));
            pts.push(mean(&c[4000..]));
            rows.push(pts);
        }
        println!("{name}");
        for r in rows {
            println!("  {}", r.iter().map(|v| format!("{v:5.2}")).collect::<Vec<_>>().join(" "));
        }
    }
}

/// Figure 5: from random weights, the avoid module's performance indicator
/// (rolling mean of its reinforcements, window 30) rises from about 0 to
/// clearly positive within a few thousand actions, on every one of 5 seeds.
#[test]
fn figure5_avoid_learns_from_random_weights() {
    let s = avoid_stage(avoid_reinforcement(0.5), 0.2, 0.05);
    let mut firsts = Vec::new();
    let mut lasts = Vec::new();
    println!("figure 5: avoid performance (mean over each block of 500 actions), seeds 1..=5");
    let mut blocks = vec![Vec::new(); 10];
    for seed in 1..=5 {
        let c = avoid_curve(&s, seed, 5000);
        let first = mean(&c[..300]);
        let last = mean(&c[4000..]);
        let row: Vec<f32> = (0..10).map(|k| mean(&c[k * 500..(k + 1) * 500])).collect();
        for (b, v) in blocks.iter_mut().zip(&row) {
            b.push(*v);
        }
        println!(
            "  seed {seed}: first 300 {first:5.2}  last 1000 {last:5.2}  | {}",
            row.iter().map(|v| format!("{v:5.2}")).collect::<Vec<_>>().join(" ")
        );
        assert!(last > first + 0.05, "seed {seed}: performance did not rise: {first} -> {last}");
        assert!(last > 0.15, "seed {seed}: final performance {last}");
        firsts.push(first);
        lasts.push(last);
    }
    let medians: Vec<String> = blocks
        .iter_mut()
        .map(|b| {
            b.sort_by(f32::total_cmp);
            format!("{:5.2}", b[b.len() / 2])
        })
        .collect();
    println!("  median over seeds, per 500 actions: {}", medians.join(" "));
    assert!(mean(&lasts) > mean(&firsts) + 0.2, "{firsts:?} -> {lasts:?}");
}

#[test]
#[ignore = "exploration: the ceiling of the reinforcement program with a hand-made avoider"]
fn figure5_ceiling() {
    for (close, gain, bias) in [(0.5, 10.0, 3.0), (0.5, 20.0, 2.0), (0.5, 5.0, 2.0)] {
        let mut s = avoid_stage(avoid_reinforcement(close), 0.1, 0.01);
        let Behavior::Neural(nb) = &mut s.modules[0].behavior else { panic!() };
        let mut p = vec![Param::Fixed(0.0); 18];
        p[0] = Param::Fixed(bias);
        p[9] = Param::Fixed(bias);
        for k in [3, 4, 5] {
            p[1 + k] = Param::Fixed(-gain);
        }
        for k in [0, 1, 2] {
            p[10 + k] = Param::Fixed(-gain);
        }
        nb.net.params = p;
        let mut out = Vec::new();
        for seed in 1..=5 {
            let (sim_seed, rng) = episode_rngs(seed);
            let mut c = Controller::new(&s, &Genome::zeros(0), rng).unwrap();
            c.set_learning(false);
            let mut sim = Sim::new(&s.world, sim_seed);
            c.start(&mut sim);
            let mut sum = 0.0;
            let mut n = 0;
            for _ in 0..3000 {
                let r = c.act(&mut sim).reinforcement;
                if r != 0.0 {
                    sum += r;
                    n += 1;
                }
            }
            out.push(sum / n as f32);
        }
        println!("close {close} gain {gain} bias {bias}: {out:?}");
    }
}

// ------------------------------------------------------------------ figure 10

/// Activation network over ir[0..8] + barrier, every weight fixed (learning
/// still changes them): `bias` and weight `w` on the given IR sensors.
fn fixed_activation(bias: f32, w: f32, sensors: &[usize]) -> Network {
    let mut p = vec![Param::Fixed(0.0); 10];
    p[0] = Param::Fixed(bias);
    for &k in sensors {
        p[1 + k] = Param::Fixed(w);
    }
    Network { inputs: 9, hidden: 0, outputs: 1, params: p }
}

/// Wander (forward, constant activation `sigmoid(wander_bias)`) and grip (the
/// test script; activation net over ir + barrier starting at
/// `sigmoid(init.0 + init.1 * (the init.2 sensors))`; CRBP on it, always).
fn trial_stage(rate_reward: f32, rate_punish: f32, init: (f32, f32, &[usize]), wander_bias: f32) -> Stage {
    let mut s = testkit::bare_stage("grip-trials", testkit::arena_world());
    s.world.battery = None;
    s.world.objects = Some(Objects { count: 1, diameter: 10.0, virtual_: true });
    let mut inputs = testkit::chans(CH_IR, 8);
    inputs.push(CH_BARRIER as u16);
    let mut wander = testkit::module(
        "wander",
        0,
        inputs.clone(),
        testkit::script(Action::Wheels { left: 0.5, right: 0.5 }),
    );
    wander.activation = fixed_activation(wander_bias, 0.0, &[]);
    let mut grip = testkit::module("grip", 0, inputs, Behavior::Script(grip_trial_script()));
    grip.activation = fixed_activation(init.0, init.1, init.2);
    grip.learning = Some(testkit::crbp(LearnTarget::Activation, rate_reward, rate_punish, 30));
    s.modules = vec![wander, grip];
    s
}

/// Turn toward what the IR sees until it is close in front (at most 4
/// actions), lower the arm, back until the barrier sees an object (at most 4
/// actions), reinforce `barrier ? 1 : -1`, close the claw, lift the arm, open
/// the claw.
fn grip_trial_script() -> Script {
    let step = Step::new;
    let barrier = expr(vec![Op::Chan(CH_BARRIER as u16)]);
    Script {
        steps: vec![
            step(
                Action::Toward { channels: testkit::chans(CH_IR, 8), speed: 0.5 },
                StepEnd::Until { cond: testkit::front_above(0.5), within: 4 },
            ),
            step(Action::Arm(true), StepEnd::Actions(1)),
            step(Action::Wheels { left: -0.3, right: -0.3 }, StepEnd::Until { cond: barrier, within: 4 }),
            step(Action::Reinforce(testkit::barrier_select(1.0, -1.0)), StepEnd::Actions(1)),
            step(Action::Claw(true), StepEnd::Actions(1)),
            step(Action::Arm(false), StepEnd::Actions(1)),
            step(Action::Claw(false), StepEnd::Actions(1)),
        ],
        commit: false,
    }
}

/// One trial: a fresh world with the robot facing the east wall or the
/// object (`gap` mm from the body, `angle` rad off the heading, the object
/// `lateral` mm to the side), then actions until the grip module is
/// reinforced or 12 actions pass. Returns the reinforcement (0: the grip
/// module did not get that far) and the percept its activation network saw at
/// the action that delivered it (the pattern CRBP trained).
fn trial_with_percept(
    c: &mut Controller,
    stage: &Stage,
    seed: u64,
    object: bool,
    gap: f32,
    angle: f32,
    lateral: f32,
) -> (f32, [f32; CHANNELS]) {
    let mut sim = Sim::new(&stage.world, seed);
    let r = stage.world.body.radius;
    let placed = if object {
        let theta = angle;
        let ok = sim.set_pose(shaping_runtime::sim::Pose { x: 200.0, y: 300.0, theta });
        let (cx, cy) = (theta.cos(), theta.sin());
        let d = r + gap;
        ok && sim.set_object(0, 200.0 + d * cx - lateral * cy, 300.0 + d * cy + lateral * cx)
    } else {
        // Facing the east wall.
        sim.set_object(0, 30.0, 30.0)
            && sim.set_pose(shaping_runtime::sim::Pose {
                x: 400.0 - r - gap,
                y: 300.0 + lateral * 10.0,
                theta: angle,
            })
    };
    assert!(placed);
    c.start(&mut sim);
    for _ in 0..12 {
        let seen = *c.percept();
        let rep = c.act(&mut sim);
        if rep.winner == 1 && rep.reinforcement != 0.0 {
            return (rep.reinforcement, seen);
        }
    }
    (0.0, [0.0; CHANNELS])
}

/// Figure 10 analogue: trials with the robot in front of either a 10 mm
/// object or a wall (distance 10..25 mm, angle +-0.5 rad, lateral offset
/// +-5 mm); the grip module (activation initially `sigmoid(-0.5 + ir2 +
/// ir3)`, CRBP rates 1.0 / 0.5) tries when its activation beats wander's
/// constant `sigmoid(-1)` and learns on its activation network from the
/// barrier alone. Over 800 trials on each of 5 seeds: the rolling mean of
/// its reinforcements rises, it stops trying walls but keeps trying objects,
/// and its activation on the object patterns it was rewarded for and on the
/// wall patterns it was punished for diverges.
#[test]
fn figure10_grip_learns_to_tell_objects_from_walls() {
    let s = trial_stage(1.0, 0.5, (-0.5, 1.0, &[2, 3]), -1.0);
    figure10(&s, true);
}

#[test]
#[ignore = "exploration"]
fn figure10_explore() {
    for (init, wb) in [
        ((-0.5, 1.0, &[2usize, 3][..]), -1.0),
        ((0.0, 1.0, &[2usize, 3][..]), -0.5),
        ((-0.5, 1.0, &[2usize, 3][..]), -0.5),
    ] {
        for (rr, rp) in [(1.0, 0.3), (1.0, 0.5), (0.5, 0.5)] {
            println!("init {init:?} wander {wb} rates {rr}/{rp}");
            figure10(&trial_stage(rr, rp, init, wb), false);
        }
    }
}

fn figure10(s: &Stage, check: bool) {
    use rand::{Rng, SeedableRng};
    println!("figure 10: grip reinforcement mean per 100 trials; attempt rate wall/object, first and last 200 trials");
    let mut blocks = vec![Vec::new(); 8];
    for seed in 1..=5u64 {
        let (_, crng) = episode_rngs(seed);
        let mut c = Controller::new(s, &Genome::zeros(0), crng).unwrap();
        let initial = c.clone();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed + 100);
        // (trial, object?, reinforcement)
        let mut log = Vec::new();
        let mut patterns: [Vec<[f32; CHANNELS]>; 2] = [Vec::new(), Vec::new()];
        for t in 0..800u64 {
            let object = rng.random::<bool>();
            let gap = rng.random_range(10.0..25.0);
            let angle = rng.random_range(-0.5..0.5f32);
            let lateral = rng.random_range(-5.0..5.0);
            let (r, seen) = trial_with_percept(&mut c, s, seed * 1000 + t, object, gap, angle, lateral);
            if r != 0.0 && t < 200 {
                patterns[object as usize].push(seen);
            }
            log.push((t, object, r));
        }
        let mean_r = |range: std::ops::Range<u64>| {
            let v: Vec<f32> =
                log.iter().filter(|l| range.contains(&l.0) && l.2 != 0.0).map(|l| l.2).collect();
            mean(&v)
        };
        let attempts = |range: std::ops::Range<u64>, object: bool| {
            let v: Vec<f32> = log
                .iter()
                .filter(|l| range.contains(&l.0) && l.1 == object)
                .map(|l| (l.2 != 0.0) as u8 as f32)
                .collect();
            mean(&v)
        };
        let act = |c: &Controller, ps: &[[f32; CHANNELS]]| {
            mean(&ps.iter().map(|p| c.probe_activation(1, p)).collect::<Vec<_>>())
        };
        let gap0 = act(&initial, &patterns[1]) - act(&initial, &patterns[0]);
        let gap1 = act(&c, &patterns[1]) - act(&c, &patterns[0]);
        let row: Vec<f32> = (0..8).map(|k| mean_r(k * 100..(k + 1) * 100)).collect();
        for (b, v) in blocks.iter_mut().zip(&row) {
            b.push(*v);
        }
        let (w0, o0, w1, o1) = (
            attempts(0..200, false),
            attempts(0..200, true),
            attempts(600..800, false),
            attempts(600..800, true),
        );
        println!(
            "  seed {seed}: {} | attempts wall {w0:.2}->{w1:.2} object {o0:.2}->{o1:.2} | activation object-wall {gap0:+.2}->{gap1:+.2} ({} object, {} wall patterns)",
            row.iter().map(|v| format!("{v:+.2}")).collect::<Vec<_>>().join(" "),
            patterns[1].len(),
            patterns[0].len()
        );
        if !check {
            continue;
        }
        assert!(row[7] > row[0] + 0.4, "seed {seed}: grip reinforcement did not rise: {row:?}");
        assert!(w1 < w0 / 3.0, "seed {seed}: still tries walls: {w0} -> {w1}");
        assert!(o1 > 0.8, "seed {seed}: stopped trying objects: {o0} -> {o1}");
        assert!(gap1 > gap0 + 0.2, "seed {seed}: activations did not diverge: {gap0} -> {gap1}");
    }
    let medians: Vec<String> = blocks
        .iter_mut()
        .map(|b| {
            b.sort_by(f32::total_cmp);
            format!("{:+.2}", b[b.len() / 2])
        })
        .collect();
    println!("  median over seeds, per 100 trials: {}", medians.join(" "));
}

#[test]
#[ignore = "diagnostic: where the plateau of figure 5 comes from (reinforcement mix of the learned policy)"]
fn figure5_signal_mix() {
    let s = avoid_stage(avoid_reinforcement(0.5), 0.2, 0.05);
    for seed in 1..=3 {
        let (sim_seed, rng) = episode_rngs(seed);
        let mut c = Controller::new(&s, &Genome::zeros(0), rng).unwrap();
        let mut sim = Sim::new(&s.world, sim_seed);
        c.start(&mut sim);
        // counts over the last 2000 of 5000 actions: [approach, leave, close, free fwd, free back, none], collisions
        let mut k = [0u32; 6];
        let mut coll = 0;
        let mut acts = [0u32; 4];
        for a in 0..5000 {
            let before = *c.percept();
            let rep = c.act(&mut sim);
            if a < 3000 {
                continue;
            }
            let p = c.percept();
            let i = p[..8].iter().copied().fold(0.0, f32::max);
            let q = before[..8].iter().copied().fold(0.0, f32::max);
            let idx = if i - q > 0.02 {
                0
            } else if q - i > 0.02 {
                1
            } else if i > 0.5 {
                2
            } else if i < 0.1 {
                if rep.reinforcement > 0.0 {
                    3
                } else if rep.reinforcement < 0.0 {
                    4
                } else {
                    5
                }
            } else {
                5
            };
            k[idx] += 1;
            coll += rep.outcome.collided as u32;
            let w = rep.command.wheels;
            acts[((w[0] > 0.0) as usize) << 1 | (w[1] > 0.0) as usize] += 1;
        }
        println!("seed {seed}: approach {} leave {} close {} free-fwd {} free-back {} none {} | collisions {coll} | back/left/right/fwd {acts:?}", k[0], k[1], k[2], k[3], k[4], k[5]);
    }
}
