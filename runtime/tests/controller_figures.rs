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
        ("no stuck .1/.01", avoid_reinforcement(2.0), 0.1, 0.01),
        ("stuck .5 eps .05 .1/.01", avoid_reinforcement_eps(0.5, 0.05), 0.1, 0.01),
        ("stuck .5 eps .1 .1/.01", avoid_reinforcement_eps(0.5, 0.1), 0.1, 0.01),
        ("stuck .5 eps .1 .2/.05", avoid_reinforcement_eps(0.5, 0.1), 0.2, 0.05),
        ("stuck .5 .1/.01", avoid_reinforcement(0.5), 0.1, 0.01),
        ("stuck .5 .05/.01", avoid_reinforcement(0.5), 0.05, 0.01),
        ("stuck .5 .02/.005", avoid_reinforcement(0.5), 0.02, 0.005),
        ("stuck .5 .2/.05", avoid_reinforcement(0.5), 0.2, 0.05),
        ("stuck .3 .1/.01", avoid_reinforcement(0.3), 0.1, 0.01),
    ];
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
        assert!(last > first + 0.1, "seed {seed}: performance did not rise: {first} -> {last}");
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

/// The grip test script: turn toward what the IR sees until it is close in
/// front (at most 6 actions), lower the arm, reinforce `barrier ? 1 : -1`
/// (what the barrier sees right after lowering the arm), close the claw,
/// lift the arm, open the claw (the object falls in front), turn away.
fn grip_test_script() -> Script {
    let step = |action, end| Step { action, end };
    Script {
        steps: vec![
            step(
                Action::Toward { channels: testkit::chans(CH_IR, 8), speed: 0.5 },
                StepEnd::Until { cond: testkit::front_above(0.5), within: 6 },
            ),
            step(Action::Arm(true), StepEnd::Actions(1)),
            step(Action::Reinforce(testkit::barrier_select(1.0, -1.0)), StepEnd::Actions(1)),
            step(Action::Claw(true), StepEnd::Actions(1)),
            step(Action::Arm(false), StepEnd::Actions(1)),
            step(Action::Claw(false), StepEnd::Actions(1)),
            step(Action::Wheels { left: 1.0, right: -1.0 }, StepEnd::Actions(3)),
        ],
    }
}

/// A one-step script turning in place for `n` actions (`left` or right).
fn turn(left: bool, n: u32) -> Behavior {
    let w = if left { [-1.0, 1.0] } else { [1.0, -1.0] };
    Behavior::Script(Script {
        steps: vec![Step { action: Action::Wheels { left: w[0], right: w[1] }, end: StepEnd::Actions(n) }],
    })
}

/// Wander (forward, activation 0.5); avoid-left and avoid-right (turn away,
/// activation `sigmoid(-2 + 3 (two side sensors))`); avoid-front (turn left,
/// activation `sigmoid(-3 + 2 (ir2 + ir3))`, above wander only for something
/// large in front such as a wall) and grip (the script above; activation
/// initially `sigmoid(grip.0 + grip.1 (ir2 + ir3))`, above every other module
/// for anything in front, so it first tries walls and objects alike; CRBP on
/// its activation network always) in the arena with 8 virtual objects of
/// 10 mm, no battery.
fn grip_stage(
    rate_reward: f32,
    rate_punish: f32,
    grip: (f32, f32),
    wander: (f32, f32),
    objects: u32,
) -> Stage {
    let mut s = testkit::bare_stage("grip", testkit::arena_world());
    s.world.battery = None;
    s.world.objects = Some(Objects { count: objects, diameter: 10.0, virtual_: true });
    let mut inputs = testkit::chans(CH_IR, 8);
    inputs.push(CH_BARRIER as u16);
    let with = |name: &str, behavior: Behavior, act: Network| {
        let mut m = testkit::module(name, 0, inputs.clone(), behavior);
        m.activation = act;
        m
    };
    let wander = with(
        "wander",
        testkit::script(Action::Wheels { left: wander.1, right: wander.1 }),
        fixed_activation(wander.0, 0.0, &[]),
    );
    let avoid_l = with("avoid-left", turn(false, 2), fixed_activation(-2.0, 3.0, &[0, 1]));
    let avoid_r = with("avoid-right", turn(true, 2), fixed_activation(-2.0, 3.0, &[4, 5]));
    let avoid_f = with("avoid-front", turn(true, 3), fixed_activation(-3.0, 2.0, &[2, 3]));
    let mut grip_m =
        with("grip", Behavior::Script(grip_test_script()), fixed_activation(grip.0, grip.1, &[2, 3]));
    grip_m.learning = Some(testkit::crbp(LearnTarget::Activation, rate_reward, rate_punish, 30));
    s.modules = vec![wander, avoid_l, avoid_r, avoid_f, grip_m];
    s
}

/// Index of the grip module in [`grip_stage`].
const GRIP: usize = 4;

/// Percepts with the robot facing a wall or an object (no noise), the
/// object's centre or the wall `gap` mm beyond the body surface.
fn facing(stage: &Stage, object: bool, gap: f32) -> [f32; CHANNELS] {
    let mut world = stage.world.clone();
    world.body.sensor_noise = 0.0;
    let mut sim = Sim::new(&world, 1);
    let r = world.body.radius;
    // Every object far away in the south-west corner.
    for i in 0..stage.world.objects.as_ref().map_or(0, |o| o.count as usize) {
        assert!(sim.set_object(i, 20.0, 20.0));
    }
    if object {
        assert!(sim.set_pose(shaping_runtime::sim::Pose { x: 200.0, y: 300.0, theta: 0.0 }));
        assert!(sim.set_object(0, 200.0 + r + gap, 300.0));
    } else {
        assert!(sim.set_pose(shaping_runtime::sim::Pose { x: 400.0 - r - gap, y: 300.0, theta: 0.0 }));
    }
    let mut p = [0.0; CHANNELS];
    sim.sense(&mut p);
    p
}

struct GripRun {
    /// Grip's performance indicator after every action.
    curve: Vec<f32>,
    /// Mean grip activation facing an object / a wall, before and after.
    object: (f32, f32),
    wall: (f32, f32),
    rewards: u32,
    punishments: u32,
}

fn grip_run(stage: &Stage, seed: u64, actions: usize) -> GripRun {
    let gaps = [5.0, 10.0, 15.0, 20.0];
    let objects: Vec<_> = gaps.iter().map(|&g| facing(stage, true, g)).collect();
    let walls: Vec<_> = gaps.iter().map(|&g| facing(stage, false, g)).collect();
    let (sim_seed, rng) = episode_rngs(seed);
    let mut c = Controller::new(stage, &Genome::zeros(0), rng).unwrap();
    let probe = |c: &Controller, ps: &[[f32; CHANNELS]]| {
        mean(&ps.iter().map(|p| c.probe_activation(GRIP, p)).collect::<Vec<_>>())
    };
    let (o0, w0) = (probe(&c, &objects), probe(&c, &walls));
    let mut sim = Sim::new(&stage.world, sim_seed);
    c.start(&mut sim);
    let (mut rewards, mut punishments) = (0, 0);
    let curve = (0..actions)
        .map(|_| {
            let rep = c.act(&mut sim);
            if rep.winner == GRIP {
                rewards += (rep.reinforcement > 0.0) as u32;
                punishments += (rep.reinforcement < 0.0) as u32;
            }
            c.performance(GRIP)
        })
        .collect();
    GripRun { curve, object: (o0, probe(&c, &objects)), wall: (w0, probe(&c, &walls)), rewards, punishments }
}

#[test]
#[ignore = "exploration: prints grip learning for several rates"]
fn figure10_explore() {
    for (rr, rp, g, w, n) in [
        (1.0, 0.5, (-0.5, 1.0), (-1.0, 0.5), 20),
        (2.0, 0.5, (-0.5, 1.0), (-1.0, 0.5), 20),
        (1.0, 1.0, (-0.5, 1.0), (-1.0, 0.5), 20),
        (1.0, 0.5, (-0.5, 1.0), (-1.0, 0.5), 8),
        (0.5, 0.25, (-0.5, 1.0), (-1.0, 0.5), 8),
    ] {
        let s = grip_stage(rr, rp, g, w, n);
        println!("rates {rr}/{rp} grip {g:?} wander {w:?} objects {n}");
        for seed in 1..=5 {
            let g = grip_run(&s, seed, 10000);
            let pts: Vec<String> =
                (1..=10usize).map(|k| format!("{:5.2}", mean(&g.curve[k * 1000 - 1000..k * 1000]))).collect();
            println!(
                "  seed {seed}: object {:.2}->{:.2} wall {:.2}->{:.2} +{} -{} | {}",
                g.object.0,
                g.object.1,
                g.wall.0,
                g.wall.1,
                g.rewards,
                g.punishments,
                pts.join(" ")
            );
        }
    }
}

#[test]
#[ignore = "debug"]
fn figure10_debug() {
    let s = grip_stage(1.0, 1.0, (-1.0, 2.5), (0.0, 1.0), 8);
    let (sim_seed, rng) = episode_rngs(1);
    let mut c = Controller::new(&s, &Genome::zeros(0), rng).unwrap();
    let mut sim = Sim::new(&s.world, sim_seed);
    c.start(&mut sim);
    let mut wins = [0; 5];
    for a in 0..400 {
        let rep = c.act(&mut sim);
        wins[rep.winner] += 1;
        let p = c.percept();
        if a < 150 || rep.reinforcement != 0.0 {
            let pose = sim.pose();
            println!(
                "{a:4} w{} act {:?} ir {:?} bar {} r {} pose {:.0} {:.0} {:.0}",
                rep.winner,
                c.activations().iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>(),
                p[..8].iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>(),
                p[CH_BARRIER],
                rep.reinforcement,
                pose.x,
                pose.y,
                pose.theta.to_degrees()
            );
        }
    }
    println!("{wins:?}");
}

#[test]
#[ignore = "debug"]
fn figure10_percepts() {
    let s = grip_stage(1.0, 1.0, (-1.0, 2.5), (0.0, 1.0), 8);
    for gap in [0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 40.0] {
        let o = facing(&s, true, gap);
        let w = facing(&s, false, gap);
        println!("gap {gap:3}: object {:?}", o[..8].iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>());
        println!("          wall   {:?}", w[..8].iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>());
    }
}
