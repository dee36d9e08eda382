//! The paper's learning figures on the simulator: figure 5 (the obstacle
//! avoidance module learns from random weights) and a figure-10 analogue (the
//! grip module's activation network learns to tell objects from walls).
//! Run with `--nocapture` to see the curves.

use shaping_runtime::catalog::{CHANNELS, CH_BARRIER, CH_IR};
use shaping_runtime::controller::{episode_rngs, Controller};
use shaping_runtime::expr::Op;
use shaping_runtime::genome::Genome;
use shaping_runtime::program::*;
use shaping_runtime::sim::Sim;
use shaping_runtime::testkit::{self, chans, expr};

// ------------------------------------------------------------------- figure 5

/// `avoid.bat`: a wander module (forward, activation fixed at 0) drives in
/// free space and the avoid module (activation `-0.3 + sum(ir)`) takes over
/// near obstacles, as the evolved arbitration does for the paper's figure 5
/// (the best individual of the first generation). The avoid module: 8 IR ->
/// 2 output bits (back / left / right / forward), random initial weights in
/// -0.5..0.5, CRBP always, performance window 30, and the paper's
/// reinforcement program `sign(max(prev ir) - max(ir))`.
fn avoid_stage(alone: bool, rates: (f32, f32), error: CrbpError) -> Stage {
    let mut s = testkit::bare_stage("avoid", testkit::arena_world());
    s.world.battery = None;
    let mut avoid = testkit::module("avoid", 0, chans(CH_IR, 8), testkit::avoid_behavior(0.5, 1.0));
    let mut act = vec![Param::Fixed(1.0); 9];
    act[0] = Param::Fixed(-0.3);
    avoid.activation = Network { inputs: 8, hidden: 0, outputs: 1, recurrent: false, params: act };
    let mut learning = testkit::crbp(LearnTarget::Behavior, rates.0, rates.1, 30);
    learning.error = error;
    avoid.learning = Some(learning);
    avoid.reinforce = Some(testkit::ir_decrease());
    let mut wander =
        testkit::module("wander", 0, vec![], testkit::script(Action::Wheels { left: 1.0, right: 1.0 }));
    wander.activation.params = vec![Param::Fixed(0.0)];
    s.modules = if alone { vec![avoid] } else { vec![wander, avoid] };
    s
}

/// The avoid module's performance indicator after every action of one life.
fn avoid_curve(stage: &Stage, seed: u64, actions: usize) -> Vec<f32> {
    let (sim_seed, rng) = episode_rngs(seed);
    let mut c = Controller::new(stage, &Genome::zeros(0), rng).unwrap();
    let mut sim = Sim::new(&stage.world, sim_seed);
    let m = stage.modules.len() - 1;
    c.start(&mut sim);
    (0..actions)
        .map(|_| {
            c.act(&mut sim);
            c.performance(m)
        })
        .collect()
}

fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len() as f32
}

fn median(mut v: Vec<f32>) -> f32 {
    v.sort_by(f32::total_cmp);
    (v[(v.len() - 1) / 2] + v[v.len() / 2]) / 2.0
}

/// Figure 5: from random weights, within one life of 300 actions, the avoid
/// module's performance indicator reaches 0.5 (the paper: about 0.6), on
/// each of nine seeds, and rises by at least 0.2 from its first 50 actions
/// on at least 7 of them (a life that starts in the open, away from the
/// walls, scores about 0.5 from the start: seed 3).
#[test]
fn figure5_avoid_learns_within_one_life() {
    let s = avoid_stage(false, (0.5, 0.1), CrbpError::Difference);
    println!("figure 5: avoid performance at actions 50, 100, 200, 300");
    let mut rises = 0;
    for seed in 1..=9 {
        let c = avoid_curve(&s, seed, 300);
        println!("  seed {seed}: {:5.2} {:5.2} {:5.2} {:5.2}", c[49], c[99], c[199], c[299]);
        assert!(c[299] >= 0.5, "seed {seed}: performance {} at action 300", c[299]);
        rises += u32::from(c[299] > mean(&c[..50]) + 0.2);
    }
    assert!(rises >= 7, "{rises} of 9 seeds rise by 0.2");
}

/// Why the module learns inside the architecture and not alone, and why
/// the paper's error `O - S` at rates 0.5 / 0.1: median performance at
/// action 300 over seeds 1..=9 for the module alone, and for the squared
/// error at the old rates 0.1 / 0.01, against the setting of `avoid.bat`.
#[test]
fn figure5_settings_that_do_not_learn_within_a_life() {
    let at300 = |s: &Stage| median((1..=9).map(|seed| avoid_curve(s, seed, 300)[299]).collect());
    let ours = at300(&avoid_stage(false, (0.5, 0.1), CrbpError::Difference));
    let alone = at300(&avoid_stage(true, (0.5, 0.1), CrbpError::Difference));
    let squared = at300(&avoid_stage(false, (0.1, 0.01), CrbpError::Squared));
    println!("median performance at action 300: avoid.bat {ours:.2}, alone {alone:.2}, squared error at 0.1/0.01 {squared:.2}");
    assert!(ours >= 0.6, "{ours}");
    assert!(alone < ours - 0.3, "alone {alone} vs {ours}");
    assert!(squared < ours - 0.2, "squared {squared} vs {ours}");
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
    Network { inputs: 9, hidden: 0, outputs: 1, recurrent: false, params: p }
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
/// and its activation stays clearly higher on the object patterns it was
/// rewarded for than on the wall patterns it was punished for (the gap
/// narrows from about 0.33 to 0.11..0.23: the activation is pushed down on
/// both, less on objects).
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
        // The activation network learns the percept on which the module
        // decided to start its script (far from the obstacle), not the
        // close-up one where the barrier judged it: in isolation wall
        // attempts halve rather than fall to a third, but inside the evolved
        // architecture this is the variant that changes decisions
        // (EXPERIMENTS.md, grip attempts at walls).
        assert!(w1 < w0 / 2.0, "seed {seed}: still tries walls: {w0} -> {w1}");
        assert!(o1 > 0.8, "seed {seed}: stopped trying objects: {o0} -> {o1}");
        assert!(gap1 > 0.05, "seed {seed}: activations converged: {gap0} -> {gap1}");
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
