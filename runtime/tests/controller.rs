//! Controller semantics on hand-made stages and a hand-driven robot:
//! arbitration, links, scripts, neural behaviors, CRBP, fitness, traces and
//! Lamarckian write-back.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use shaping_runtime::catalog::{CHANNELS, CH_BATTERY, CH_IR};
use shaping_runtime::controller::{
    run_episode, try_run_episode, Controller, ControllerError, EpisodeOptions, Robot, Trace,
};
use shaping_runtime::expr::{Expr, Op};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::*;
use shaping_runtime::sim::{Command, Outcome};
use shaping_runtime::testkit::{self, expr};

/// A robot whose percept the test sets; it records the commands it receives.
struct Puppet {
    percept: [f32; CHANNELS],
    commands: Vec<Command>,
    /// Outcome of every step.
    outcome: Outcome,
}

impl Default for Puppet {
    fn default() -> Puppet {
        Puppet { percept: [0.0; CHANNELS], commands: Vec::new(), outcome: Outcome::default() }
    }
}

impl Robot for Puppet {
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        *out = self.percept;
    }
    fn step(&mut self, cmd: &Command) -> Outcome {
        self.commands.push(*cmd);
        self.outcome
    }
}

fn bias_only(bias: f32) -> Network {
    Network { inputs: 0, hidden: 0, outputs: 1, recurrent: false, params: vec![Param::Fixed(bias)] }
}

/// A module whose activation is the constant `sigmoid(bias)` (plus links)
/// and whose behavior drives the wheels at `[id, id]`, so commands tell who won.
fn constant_module(name: &str, bias: f32, id: f32) -> Module {
    Module {
        name: name.into(),
        stage: 0,
        inputs: vec![],
        activation: bias_only(bias),
        behavior: testkit::script(Action::Wheels { left: id, right: id }),
        learning: None,
        reinforce: None,
    }
}

fn stage_of(modules: Vec<Module>, links: Vec<Link>) -> Stage {
    let mut s = testkit::bare_stage("test", testkit::arena_world());
    s.modules = modules;
    s.links = links;
    s
}

fn controller(stage: &Stage, seed: u64) -> Controller<'_> {
    let genome = Genome::zeros(stage.layout.bits as usize);
    Controller::new(stage, &genome, ChaCha8Rng::seed_from_u64(seed)).expect("valid stage")
}

fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

#[test]
fn winner_take_all_picks_the_highest_activation_and_breaks_ties_by_declaration_order() {
    let s = stage_of(
        vec![
            constant_module("low", 0.0, 0.1),
            constant_module("high1", 1.0, 0.2),
            constant_module("high2", 1.0, 0.3),
        ],
        vec![],
    );
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    for _ in 0..3 {
        let rep = c.act(&mut robot);
        assert_eq!(rep.winner, 1, "tie between modules 1 and 2 goes to the first declared");
        assert_eq!(rep.command.wheels, [0.2, 0.2]);
    }
    assert!((c.activations()[0] - 0.5).abs() < 1e-6);
    assert!((c.activations()[1] - sigmoid(1.0)).abs() < 1e-6);

    // Strictly highest wins even when declared last.
    let s = stage_of(vec![constant_module("a", 0.5, 0.1), constant_module("b", 0.6, 0.2)], vec![]);
    let mut c = controller(&s, 1);
    c.start(&mut robot);
    assert_eq!(c.act(&mut robot).winner, 1);

    // Saturated activations (both exactly 1.0 in f32) are still ordered by
    // their net input, not by declaration.
    let s = stage_of(vec![constant_module("a", 30.0, 0.1), constant_module("b", 40.0, 0.2)], vec![]);
    let mut c = controller(&s, 1);
    c.start(&mut robot);
    let rep = c.act(&mut robot);
    assert_eq!(c.activations(), &[1.0, 1.0], "both sigmoids saturate");
    assert_eq!(rep.winner, 1);
}

#[test]
fn an_inhibitory_link_suppresses_its_target_at_the_next_action() {
    // b wins the first action (no previous activations); a's activation then
    // inhibits b through the link, so a wins from the second action on.
    let links = vec![Link { from: 0, to: 1, weight: Param::Fixed(-10.0) }];
    let s = stage_of(vec![constant_module("a", 2.0, 0.1), constant_module("b", 3.0, 0.2)], links);
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    assert_eq!(c.act(&mut robot).winner, 1);
    assert!((c.activations()[1] - sigmoid(3.0)).abs() < 1e-6);
    assert_eq!(c.act(&mut robot).winner, 0);
    let expected = sigmoid(3.0 - 10.0 * sigmoid(2.0));
    assert!((c.activations()[1] - expected).abs() < 1e-6, "{} vs {expected}", c.activations()[1]);
    assert_eq!(c.act(&mut robot).winner, 0);

    // The same link, excitatory, keeps b ahead.
    let links = vec![Link { from: 0, to: 1, weight: Param::Fixed(10.0) }];
    let s = stage_of(vec![constant_module("a", 2.0, 0.1), constant_module("b", 3.0, 0.2)], links);
    let mut c = controller(&s, 1);
    c.start(&mut robot);
    for _ in 0..3 {
        assert_eq!(c.act(&mut robot).winner, 1);
    }
    assert!((c.activations()[1] - sigmoid(3.0 + 10.0 * sigmoid(2.0))).abs() < 1e-6);
}

/// Module 0: a script of three wheel steps (ids 1, 2, 3; the second lasts
/// two actions), activation 0.5. Module 1: drives `[9, 9]`, activation
/// `sigmoid(20 * battery - 10)`: it wins when the test sets battery to 1.
fn script_stage() -> Stage {
    let step = |v: f32, n: u32| Step::new(Action::Wheels { left: v, right: v }, StepEnd::Actions(n));
    let scripted = Module {
        name: "scripted".into(),
        stage: 0,
        inputs: vec![],
        activation: bias_only(0.0),
        behavior: Behavior::Script(Script {
            steps: vec![step(1.0, 1), step(2.0, 2), step(3.0, 1)],
            commit: false,
        }),
        learning: None,
        reinforce: None,
    };
    let other = Module {
        name: "other".into(),
        stage: 0,
        inputs: vec![CH_BATTERY as u16],
        activation: Network {
            inputs: 1,
            hidden: 0,
            outputs: 1,
            recurrent: false,
            params: vec![Param::Fixed(-10.0), Param::Fixed(20.0)],
        },
        behavior: testkit::script(Action::Wheels { left: 9.0, right: 9.0 }),
        learning: None,
        reinforce: None,
    };
    stage_of(vec![scripted, other], vec![])
}

#[test]
fn scripts_advance_while_winning_wrap_around_and_reset_when_preempted() {
    let s = script_stage();
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    let mut wheels = Vec::new();
    // The percept an action decides on is sensed at the end of the previous
    // action: setting it during action 1 pre-empts action 2, in the middle of
    // the script's second step.
    for a in 0..12 {
        robot.percept[CH_BATTERY] = if a == 1 { 1.0 } else { 0.0 };
        wheels.push(c.act(&mut robot).command.wheels[0]);
    }
    assert_eq!(wheels, vec![1.0, 2.0, 9.0, 1.0, 2.0, 2.0, 3.0, 1.0, 2.0, 2.0, 3.0, 1.0]);
    assert_eq!(c.script_position(0), Some(1));
}

#[test]
fn a_new_life_starts_scripts_and_links_afresh() {
    // A life that ends in the middle of the script's second step: the next
    // life (`start` on a fresh robot) starts the script at its first step.
    let s = script_stage();
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    let first: Vec<f32> = (0..2).map(|_| c.act(&mut robot).command.wheels[0]).collect();
    assert_eq!(first, vec![1.0, 2.0]);
    assert_eq!(c.script_position(0), Some(1));
    let mut robot = Puppet::default();
    c.start(&mut robot);
    assert_eq!(c.script_position(0), Some(0));
    assert_eq!(c.activations(), &[0.0, 0.0]);
    let next: Vec<f32> = (0..3).map(|_| c.act(&mut robot).command.wheels[0]).collect();
    assert_eq!(next, vec![1.0, 2.0, 2.0]);

    // The activations the links read are the new life's: b wins the first
    // action of every life, as it does in a fresh controller, before a's
    // inhibition reaches it.
    let links = vec![Link { from: 0, to: 1, weight: Param::Fixed(-10.0) }];
    let s = stage_of(vec![constant_module("a", 2.0, 0.1), constant_module("b", 3.0, 0.2)], links);
    let mut c = controller(&s, 1);
    for _ in 0..2 {
        let mut robot = Puppet::default();
        c.start(&mut robot);
        assert_eq!(c.act(&mut robot).winner, 1);
        assert_eq!(c.act(&mut robot).winner, 0);
    }
}

#[test]
fn until_steps_end_on_their_condition_or_bound_and_reinforce_steps_take_no_time() {
    // Step 0: wheels 1 until ir[0] > 0.5 within 3; step 1: reinforce ir[0] > 0.5 ? 1 : -1
    // (takes no time); step 2: wheels 2.
    let cond = expr(vec![Op::Chan(0), Op::Const(0.5), Op::Gt]);
    let r = expr(vec![Op::Chan(0), Op::Const(0.5), Op::Gt, Op::Const(1.0), Op::Const(-1.0), Op::Select]);
    let m = Module {
        name: "m".into(),
        stage: 0,
        inputs: vec![],
        activation: bias_only(0.0),
        behavior: Behavior::Script(Script {
            steps: vec![
                Step::new(Action::Wheels { left: 1.0, right: 1.0 }, StepEnd::Until { cond, within: 3 }),
                Step::new(Action::Reinforce(r), StepEnd::Actions(1)),
                Step::new(Action::Wheels { left: 2.0, right: 2.0 }, StepEnd::Actions(1)),
            ],
            commit: false,
        }),
        learning: None,
        reinforce: Some(expr(vec![Op::Const(5.0)])), // ignored: the script delivers reinforcement
    };
    let s = stage_of(vec![m], vec![]);
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    let mut log = Vec::new();
    // Condition never true: the step ends after 3 actions, then the reinforce step
    // (punishment, ir[0] = 0) runs in the same action as wheels 2.
    for _ in 0..5 {
        let rep = c.act(&mut robot);
        log.push((rep.command.wheels[0], rep.reinforcement));
    }
    assert_eq!(log, vec![(1.0, 0.0), (1.0, 0.0), (1.0, 0.0), (2.0, -1.0), (1.0, 0.0)]);
    // Condition true after the first action: the step ends at once.
    robot.percept[0] = 0.9;
    let rep = c.act(&mut robot);
    assert_eq!((rep.command.wheels[0], rep.reinforcement), (1.0, 0.0));
    let rep = c.act(&mut robot);
    assert_eq!((rep.command.wheels[0], rep.reinforcement), (2.0, 1.0));
    assert_eq!(c.performance(0), 0.0, "mean of -1 and +1");
}

#[test]
fn toward_wait_arm_and_claw_steps_give_their_commands() {
    let steps = vec![
        Step::new(Action::Toward { channels: testkit::chans(CH_IR, 8), speed: 0.5 }, StepEnd::Actions(1)),
        Step::new(Action::Arm(true), StepEnd::Actions(1)),
        Step::new(Action::Claw(true), StepEnd::Actions(1)),
        Step::new(Action::Wait { charge: true }, StepEnd::Actions(1)),
    ];
    let m = Module {
        name: "m".into(),
        stage: 0,
        inputs: vec![],
        activation: bias_only(0.0),
        behavior: Behavior::Script(Script { steps, commit: false }),
        learning: None,
        reinforce: None,
    };
    let s = stage_of(vec![m], vec![]);
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    robot.percept[CH_IR + 5] = 0.8; // something on the right
    c.start(&mut robot);
    for _ in 0..4 {
        c.act(&mut robot);
    }
    let cmds = &robot.commands;
    assert_eq!(cmds[0], Command { wheels: [0.5, -0.5], ..Command::default() });
    assert_eq!(cmds[1], Command { arm: Some(true), ..Command::default() });
    assert_eq!(cmds[2], Command { claw: Some(true), ..Command::default() });
    assert_eq!(cmds[3], Command { charge: true, ..Command::default() });
}

/// One module driven by a neural behavior over ir[0..2] with the paper's
/// 2-bit table, CRBP on the behavior with the given reinforcement.
fn neural_stage(reinforce: Expr, learning: Option<Learning>, params: Vec<Param>) -> Stage {
    let m = Module {
        name: "neural".into(),
        stage: 0,
        inputs: vec![],
        activation: bias_only(0.0),
        behavior: Behavior::Neural(NeuralBehavior {
            inputs: vec![0, 1],
            net: Network { inputs: 2, hidden: 0, outputs: 2, recurrent: false, params },
            decode: Decode::Table(vec![[-1.0, -1.0], [-1.0, 1.0], [1.0, -1.0], [1.0, 1.0]]),
            signals: 0,
        }),
        learning,
        reinforce: Some(reinforce),
    };
    stage_of(vec![m], vec![])
}

fn zero_params() -> Vec<Param> {
    vec![Param::Fixed(0.0); 6]
}

/// `wheels[0] > 0 ? v : 0`: a signal only when the first output bit was 1.
fn when_left_forward(v: f32) -> Expr {
    expr(vec![Op::Act(0), Op::Const(0.0), Op::Gt, Op::Const(v), Op::Const(0.0), Op::Select])
}

fn train_neural(s: &Stage, percept: [f32; CHANNELS], actions: usize) -> (Vec<f32>, Vec<f32>, usize) {
    let mut c = controller(s, 7);
    let mut robot = Puppet { percept, ..Puppet::default() };
    c.start(&mut robot);
    let before = c.probe_behavior(0, &percept);
    let mut left_forward = 0;
    for _ in 0..actions {
        left_forward += (c.act(&mut robot).command.wheels[0] > 0.0) as usize;
    }
    (before, c.probe_behavior(0, &percept), left_forward)
}

#[test]
fn crbp_reward_makes_the_sampled_output_more_likely_for_that_input() {
    let learn = Some(testkit::crbp(LearnTarget::Behavior, 0.5, 0.5, 30));
    let s = neural_stage(when_left_forward(1.0), learn, zero_params());
    let mut p = [0.0; CHANNELS];
    p[0] = 1.0;
    let (before, after, n) = train_neural(&s, p, 200);
    assert!((before[0] - 0.5).abs() < 1e-6);
    assert!(after[0] > 0.9, "output 0 should approach 1 when its 1s are rewarded: {before:?} -> {after:?}");
    assert!(n > 150, "the rewarded bit is sampled more and more often: {n} of 200");
}

#[test]
fn crbp_punishment_makes_the_sampled_output_less_likely_for_that_input() {
    let learn = Some(testkit::crbp(LearnTarget::Behavior, 0.5, 0.5, 30));
    let s = neural_stage(when_left_forward(-1.0), learn, zero_params());
    let mut p = [0.0; CHANNELS];
    p[1] = 1.0;
    let (_, after, n) = train_neural(&s, p, 200);
    assert!(after[0] < 0.2, "output 0 should approach 0 when its 1s are punished: {after:?}");
    assert!(n < 50, "the punished bit is sampled less and less often: {n} of 200");
}

#[test]
fn without_learning_outputs_are_thresholded_and_weights_stay() {
    let learn = Some(testkit::crbp(LearnTarget::Behavior, 0.5, 0.5, 30));
    // bias_0 = 0.3 (left bit 1), bias_1 = -0.3 (right bit 0): table row 2, turn right.
    let params = vec![Param::Fixed(0.3), Param::Fixed(0.0), Param::Fixed(0.0), Param::Fixed(-0.3)]
        .into_iter()
        .chain([Param::Fixed(0.0), Param::Fixed(0.0)])
        .collect();
    let s = neural_stage(when_left_forward(1.0), learn, params);
    let mut c = controller(&s, 7);
    c.set_learning(false);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    let w0 = c.behavior_weights(0).to_vec();
    for _ in 0..50 {
        assert_eq!(c.act(&mut robot).command.wheels, [1.0, -1.0]);
    }
    assert_eq!(c.behavior_weights(0), &w0[..]);
    assert_eq!(c.performance(0), 1.0, "reinforcement is still measured");
}

#[test]
fn learning_below_a_threshold_stops_once_performance_is_reached() {
    let mut learn = testkit::crbp(LearnTarget::Behavior, 0.5, 0.5, 10);
    learn.when = LearnWhen::Below { threshold: 0.5 };
    let s = neural_stage(expr(vec![Op::Const(1.0)]), Some(learn), zero_params());
    let mut c = controller(&s, 3);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    c.act(&mut robot); // performance 0 < 0.5: learns
    let w1 = c.behavior_weights(0).to_vec();
    assert_ne!(w1, vec![0.0; 6]);
    for _ in 0..5 {
        c.act(&mut robot); // performance 1: no more learning
    }
    assert_eq!(c.behavior_weights(0), &w1[..]);
}

/// One module with a learning activation network over ir[0] and ir[1] whose
/// reinforcement is `ir[0] > 0.5 ? 1 : -1` after the action.
/// A module `grip` on channels 0 and 1 whose activation network (all
/// weights 0) learns by CRBP at 0.5 / 0.5 from `reinforce`.
fn learning_grip(behavior: Behavior, reinforce: Expr) -> Module {
    Module {
        name: "grip".into(),
        stage: 0,
        inputs: vec![0, 1],
        activation: Network {
            inputs: 2,
            hidden: 0,
            outputs: 1,
            recurrent: false,
            params: vec![Param::Fixed(0.0); 3],
        },
        behavior,
        learning: Some(testkit::crbp(LearnTarget::Activation, 0.5, 0.5, 30)),
        reinforce: Some(reinforce),
    }
}

fn activation_learning_stage() -> Stage {
    let r = expr(vec![Op::Chan(0), Op::Const(0.5), Op::Gt, Op::Const(1.0), Op::Const(-1.0), Op::Select]);
    stage_of(vec![learning_grip(testkit::script(Action::Wheels { left: 0.0, right: 0.0 }), r)], vec![])
}

#[test]
fn crbp_on_an_activation_network_pushes_it_up_on_reward_and_down_on_punishment() {
    let s = activation_learning_stage();
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    let mut object = [0.0; CHANNELS];
    object[0] = 1.0;
    let mut wall = [0.0; CHANNELS];
    wall[1] = 1.0;
    c.start(&mut robot);
    let (o0, w0) = (c.probe_activation(0, &object), c.probe_activation(0, &wall));
    for i in 0..200 {
        robot.percept = if i % 2 == 0 { object } else { wall };
        c.start(&mut robot);
        c.act(&mut robot);
    }
    let (o1, w1) = (c.probe_activation(0, &object), c.probe_activation(0, &wall));
    assert!(o1 > o0 + 0.3, "rewarded pattern: {o0} -> {o1}");
    assert!(w1 < w0 - 0.3, "punished pattern: {w0} -> {w1}");
}

#[test]
fn a_reinforce_step_late_in_a_script_trains_the_pattern_the_script_started_on() {
    // Drive one action, then reward: the percept changes in between.
    let steps = vec![
        Step { action: Action::Wheels { left: 1.0, right: 1.0 }, end: StepEnd::Actions(1), when: None },
        Step { action: Action::Reinforce(expr(vec![Op::Const(1.0)])), end: StepEnd::Actions(1), when: None },
    ];
    let m = learning_grip(Behavior::Script(Script { steps, commit: true }), expr(vec![Op::Const(1.0)]));
    let s = stage_of(vec![m], vec![]);
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    robot.percept[0] = 1.0; // the decision: ir[0]
    c.start(&mut robot);
    robot.percept = [0.0; CHANNELS];
    robot.percept[1] = 1.0; // after the move: ir[1]
    c.act(&mut robot); // decides on ir[0] and drives
    assert_eq!(c.activation_weights(0), &[0.0, 0.0, 0.0][..], "no reinforcement yet");
    let rep = c.act(&mut robot); // the reinforce step, on ir[1]
    assert_eq!(rep.reinforcement, 1.0);
    let w = c.activation_weights(0);
    assert!(w[0] > 0.0 && w[1] > 0.0, "the decision's pattern is rewarded: {w:?}");
    assert_eq!(w[2], 0.0, "not the pattern at the reinforce step: {w:?}");
}

#[test]
fn fitness_sums_the_per_action_term_and_adds_bonuses_per_event() {
    let mut s = stage_of(vec![constant_module("fwd", 0.0, 1.0)], vec![]);
    s.fitness.per_action = Some(testkit::straight_and_far(300.0));
    s.fitness.bonuses = vec![
        Bonus { event: Event::Grip, points: 0.5 },
        Bonus { event: Event::ReleaseOutside, points: 1.0 },
        Bonus { event: Event::Collision, points: -0.25 },
    ];
    let genome = Genome::zeros(0);
    let mut c = Controller::new(&s, &genome, ChaCha8Rng::seed_from_u64(1)).unwrap();
    let mut robot = Puppet::default();
    robot.percept[CH_IR + 3] = 0.4;
    robot.outcome = Outcome { grips: 1, releases_outside: 0, recharged: false, collided: true };
    let mut trace = Trace::default();
    let opts = EpisodeOptions { actions: 30, learning: true, seed: 1 };
    let res = c.run(&mut robot, &opts, Some(&mut trace));
    assert_eq!(res.actions, 30);
    assert_eq!((res.grips, res.collisions, res.recharges), (30, 30, 0));
    let expected = 30.0 * (1.0 * 0.6 / 300.0) + 30.0 * 0.5 - 30.0 * 0.25;
    assert!((res.fitness - expected).abs() < 1e-4, "{} vs {expected}", res.fitness);
    assert_eq!(trace.modules, vec!["fwd".to_string()]);
    assert_eq!(trace.rows.len(), 30);
    assert_eq!(trace.rows[29].grips, 30);
    assert!(trace.rows[0].holding && trace.rows[0].collided);
}

#[test]
fn genes_and_random_params_are_decoded_deterministically() {
    let s = testkit::navigation();
    let mut genome = Genome::zeros(s.layout.bits as usize);
    // wander's bias gene to 15 (= 1.0), its first weight gene stays 0 (= -1.0).
    genome.set_gene_int(&s.layout.genes[0], 15);
    let c = Controller::new(&s, &genome, ChaCha8Rng::seed_from_u64(5)).unwrap();
    assert_eq!(c.activation_weights(0)[0], 1.0);
    assert_eq!(c.activation_weights(0)[1], -1.0);
    let w = c.behavior_weights(1).to_vec();
    assert_eq!(w.len(), 18);
    assert!(w.iter().all(|&x| (-0.5..0.5).contains(&x)));
    let c2 = Controller::new(&s, &genome, ChaCha8Rng::seed_from_u64(5)).unwrap();
    assert_eq!(c2.behavior_weights(1), &w[..]);
    let c3 = Controller::new(&s, &genome, ChaCha8Rng::seed_from_u64(6)).unwrap();
    assert_ne!(c3.behavior_weights(1), &w[..]);
}

#[test]
fn lamarckian_inheritance_writes_learned_activation_genes_back() {
    let mut s = activation_learning_stage();
    // The activation weights become genes 0..3 (4 bits, -1..1).
    s.modules[0].activation.params = vec![Param::Gene(0), Param::Gene(1), Param::Gene(2)];
    for i in 0..3 {
        s.layout.genes.push(Gene {
            offset: 4 * i,
            bits: 4,
            lo: -1.0,
            hi: 1.0,
            stage: 0,
            module: 0,
            role: GeneRole::Bias,
            frozen: false,
        });
    }
    s.layout.bits = 12;
    let mut genome = Genome::zeros(12);
    for g in &s.layout.genes {
        genome.set_gene_int(g, 7); // -0.0667
    }
    // Always punished with only ir[1] on: the bias and w1 go down, w0 (input 0) stays.
    let mut c = Controller::new(&s, &genome, ChaCha8Rng::seed_from_u64(1)).unwrap();
    let mut robot = Puppet::default();
    robot.percept[1] = 1.0;
    let opts = EpisodeOptions { actions: 100, learning: true, seed: 1 };
    c.run(&mut robot, &opts, None);
    let learned = c.write_back(&genome);
    assert!(learned.gene_int(&s.layout.genes[0]) < 7, "{}", learned.to_bitstring());
    assert_eq!(learned.gene_int(&s.layout.genes[1]), 7, "input 0 was 0: weight unchanged");
    assert!(learned.gene_int(&s.layout.genes[2]) < 7, "{}", learned.to_bitstring());

    // Frozen genes (earlier stages) are never written back.
    s.layout.genes[0].frozen = true;
    let mut c = Controller::new(&s, &genome, ChaCha8Rng::seed_from_u64(1)).unwrap();
    c.run(&mut robot, &opts, None);
    let learned = c.write_back(&genome);
    assert_eq!(learned.gene_int(&s.layout.genes[0]), 7, "frozen bias kept");
    assert!(learned.gene_int(&s.layout.genes[2]) < 7);

    // run_episode returns the written-back genome only for Lamarckian stages.
    assert_eq!(run_episode(&s, &genome, &opts, None).learned, None);
    s.inheritance = Inheritance::Lamarckian;
    let lam = run_episode(&s, &genome, &opts, None);
    assert_eq!(lam.learned.expect("lamarckian result carries a genome").bits.len(), 12);
}

/// A range whose width `hi - lo` is beyond `f32::MAX` (each bound finite) is
/// refused: a random weight drawn from it panics in `rand`, a gene decoded in
/// it is infinite or NaN. A hand-edited program.json could hold one.
#[test]
fn ranges_wider_than_f32_are_refused() {
    let s = testkit::navigation();
    let g = Genome::zeros(s.layout.bits as usize);
    let opts = EpisodeOptions { actions: 10, learning: true, seed: 1 };
    let mut bad = s.clone();
    bad.modules[0].activation.params[0] = Param::Random { lo: -2e38, hi: 2e38 };
    let e = try_run_episode(&bad, &g, &opts, None).unwrap_err().to_string();
    assert!(
        e.contains("`modules[0].activation.params[0]`: the range -200000000000000000000000000000000000000..200000000000000000000000000000000000000 is too wide"),
        "{e}"
    );
    let mut bad = s.clone();
    bad.layout.genes[1].lo = -3e38;
    bad.layout.genes[1].hi = 3e38;
    let e = try_run_episode(&bad, &g, &opts, None).unwrap_err().to_string();
    assert!(e.contains("`layout.genes[1]`: the range") && e.contains("is too wide"), "{e}");
    // The widest range that is still finite runs.
    let mut wide = s.clone();
    wide.modules[0].activation.params[0] = Param::Random { lo: -1.7e38, hi: 1.7e38 };
    assert!(try_run_episode(&wide, &g, &opts, None).is_ok());
}

/// Names in a program are names of the language: a stage's name is a
/// directory of a run (`../escaped`, `/tmp/x`, `` or `.` would write outside
/// its place), a module's or a sensor's a column of `trace.csv`.
#[test]
fn names_in_a_program_are_names_of_the_language() {
    let program = |s: Stage| Program { format: FORMAT_VERSION, name: "p".into(), stages: vec![s] };
    let refused = |s: Stage| program(s).validate().unwrap_err().to_string();
    assert_eq!(program(testkit::navigation()).validate(), Ok(()));
    for bad in ["../escaped", "/tmp/x", "", ".", "a b", "1st", "é", "stage"] {
        let mut s = testkit::navigation();
        s.name = bad.into();
        let e = refused(s);
        assert!(e.starts_with(&format!("`stages[0].name`: {bad:?} is not a name: ")), "{e}");
    }
    let mut s = testkit::navigation();
    s.name = "stage".into();
    assert!(refused(s).ends_with("it is a reserved word"));
    let mut s = testkit::navigation();
    s.name = "_ok_2".into();
    assert_eq!(program(s).validate(), Ok(()));

    let mut s = testkit::navigation();
    s.modules[0].name = "a,b\nc".into();
    let e = refused(s);
    assert!(e.contains("`modules[0].name`: \"a,b\\nc\" is not a name"), "{e}");
    let mut s = testkit::navigation();
    s.sensors[0].name = "ir,x".into();
    assert!(refused(s).contains("`sensors[0].name`: \"ir,x\" is not a name"));
    let mut s = testkit::collect();
    s.actuators[0].name = "wheels\"".into();
    assert!(refused(s).contains("`actuators[0].name`: \"wheels\\\"\" is not a name"));
    let mut s = testkit::collect();
    s.actuators[1].name = s.sensors[0].name.clone();
    assert!(refused(s).contains("`actuators[1].name`: `ir` is also the name of another sensor or actuator"));
    let mut s = testkit::navigation();
    s.world.items.walls.push(InnerWall { name: Some("w-1".into()), from: [10.0, 10.0], to: [20.0, 20.0] });
    assert!(refused(s).contains("`world.items.walls[0].name`: \"w-1\" is not a name"));

    // A network's inputs are channels listed once, as `sense` lists them.
    let mut s = testkit::navigation();
    let first = s.modules[0].inputs[0];
    s.modules[0].inputs.push(first);
    let n = s.modules[0].inputs.len() - 1;
    let e = refused(s);
    assert!(
        e.contains(&format!("`modules[0].inputs[{n}]`: channel ")) && e.contains("is also input 0"),
        "{e}"
    );

    // A script has at least one step, as in the language.
    let mut s = testkit::navigation();
    let Behavior::Script(script) = &mut s.modules[0].behavior else { panic!("a scripted module") };
    script.steps.clear();
    assert!(refused(s).contains("`modules[0].behavior.steps`: a script has at least one step"));
}

#[test]
fn invalid_stages_are_errors_not_panics() {
    let s = testkit::navigation();
    let short = Genome::zeros(3);
    let opts = EpisodeOptions { actions: 10, learning: true, seed: 1 };
    assert!(matches!(try_run_episode(&s, &short, &opts, None), Err(ControllerError::GenomeTooShort { .. })));
    assert_eq!(run_episode(&s, &short, &opts, None).actions, 0);
    let mut bad = s.clone();
    bad.modules[0].inputs[0] = 99;
    let g = Genome::zeros(s.layout.bits as usize);
    let e = try_run_episode(&bad, &g, &opts, None).unwrap_err();
    assert!(matches!(e, ControllerError::Invalid(_)), "{e}");
    assert!(e.to_string().contains("`modules[0].inputs[0]`: channel 99 does not exist"), "{e}");
    let mut bad = s.clone();
    bad.links[0].to = 42;
    let e = try_run_episode(&bad, &g, &opts, None).unwrap_err();
    assert!(e.to_string().contains("`links[0].to`: module 42 does not exist"), "{e}");

    // A script step's `if` condition reading a channel that does not exist,
    // as a hand-edited program.json could hold.
    let mut bad = testkit::collect();
    let g = Genome::zeros(bad.layout.bits as usize);
    let m = bad.modules.iter().position(|m| matches!(m.behavior, Behavior::Script(_))).unwrap();
    let Behavior::Script(script) = &mut bad.modules[m].behavior else { unreachable!() };
    script.steps[0].when = Some(Expr { ops: vec![Op::Chan(99)], depth: 1 });
    assert!(matches!(try_run_episode(&bad, &g, &opts, None), Err(ControllerError::Invalid(_))));
    let program =
        Program { format: FORMAT_VERSION, name: "bad".into(), stages: vec![testkit::navigation(), bad] };
    let e = program.validate().unwrap_err().to_string();
    assert!(e.contains(&format!("`modules[{m}].behavior.steps[0].when.ops[0]`: channel 99")), "{e}");
}

#[test]
fn episodes_are_deterministic_by_seed_and_trace_does_not_change_them() {
    let s = testkit::navigation();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let g = testkit::random_genome(&s, &mut rng);
    let opts = EpisodeOptions { actions: 300, learning: true, seed: 42 };
    let a = run_episode(&s, &g, &opts, None);
    let mut t = Trace::default();
    let b = run_episode(&s, &g, &opts, Some(&mut t));
    assert_eq!(a, b);
    assert_eq!(t.rows.len() as u32, a.actions);
    assert_eq!(t.modules, vec!["wander", "avoid", "follow", "recharge"]);
    let json = serde_json::to_string(&t.rows[0]).unwrap();
    assert!(json.contains("\"pose\":{\"x\":"), "{json}");
    let back: Trace = serde_json::from_str(&serde_json::to_string(&t).unwrap()).unwrap();
    assert_eq!(back, t);
}

/// End to end on the simulator: `toward(light)` brings the robot to the
/// charger under the lamp; the recharge module (activation
/// `sigmoid(-7 + 4 (ir2 + ir3))`, i.e. only very close to a wall) creeps into
/// contact and waits there with `charge`, so the robot outlives its
/// 200-action battery.
#[test]
fn follow_light_then_recharge_keeps_the_robot_alive() {
    let mut s = testkit::navigation();
    // follow: constant 0.5; wander and avoid off.
    let fixed = |v: &[(usize, f32)], n: usize| {
        let mut p = vec![Param::Fixed(0.0); n + 1];
        for &(i, w) in v {
            p[i] = Param::Fixed(w);
        }
        p
    };
    s.modules[0].activation.params = fixed(&[(0, -10.0)], 8);
    s.modules[1].activation.params = fixed(&[(0, -10.0)], 8);
    s.modules[2].activation.params = fixed(&[(0, 0.0)], 9);
    s.modules[3].activation.params = fixed(&[(0, -7.0), (3, 4.0), (4, 4.0)], 7);
    // Creep into contact with the bar, then wait there charging.
    let full = expr(vec![Op::Chan(CH_BATTERY as u16), Op::Const(1.0), Op::Ge]);
    s.modules[3].behavior = Behavior::Script(Script {
        steps: vec![
            Step::new(Action::Wheels { left: 0.3, right: 0.3 }, StepEnd::Actions(2)),
            Step::new(Action::Wait { charge: true }, StepEnd::Until { cond: full, within: 40 }),
        ],
        commit: false,
    });
    s.links.clear();
    let mut recharged = 0;
    for seed in 0..5 {
        let mut t = Trace::default();
        let g = Genome::zeros(s.layout.bits as usize);
        let r = run_episode(&s, &g, &EpisodeOptions { actions: 300, learning: true, seed }, Some(&mut t));
        let last = t.rows.last().unwrap();
        assert!(last.pose.y > 500.0, "seed {seed}: the light leads to the north wall: {:?}", last.pose);
        // Charged at all (a top-up too, which is not a `recharge` event).
        let charged = t.rows.windows(2).any(|w| w[1].battery > w[0].battery);
        if r.recharges > 0 {
            assert!(t.rows.iter().any(|row| row.recharged && row.winner == 3));
        }
        if charged {
            recharged += 1;
            assert_eq!(r.actions, 300, "seed {seed}: a recharged robot lives the whole episode");
        } else {
            assert_eq!(r.actions, 200, "seed {seed}: without recharge the battery lasts 200 actions");
        }
    }
    println!("{recharged} of 5 episodes recharged");
    assert!(recharged >= 3, "only {recharged} of 5 episodes recharged");
}

#[test]
fn linear_decoding_gives_continuous_speeds_without_learning_and_sampled_ones_with() {
    // bias_0 = 1 (y0 = 0.731), bias_1 = -1 (y1 = 0.269), no inputs used.
    let params = vec![Param::Fixed(1.0), Param::Fixed(0.0), Param::Fixed(0.0), Param::Fixed(-1.0)]
        .into_iter()
        .chain([Param::Fixed(0.0), Param::Fixed(0.0)])
        .collect();
    let mut s = neural_stage(expr(vec![Op::Const(0.0)]), None, params);
    let Behavior::Neural(nb) = &mut s.modules[0].behavior else { unreachable!() };
    nb.decode = Decode::Linear { scale: 0.5 };
    let mut c = controller(&s, 1);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    let w = c.act(&mut robot).command.wheels;
    let y0 = sigmoid(1.0);
    assert!(
        (w[0] - (2.0 * y0 - 1.0) * 0.5).abs() < 1e-6 && (w[1] + (2.0 * y0 - 1.0) * 0.5).abs() < 1e-6,
        "{w:?}"
    );

    s.modules[0].learning = Some(testkit::crbp(LearnTarget::Behavior, 0.0, 0.0, 30));
    let mut c = controller(&s, 1);
    c.start(&mut robot);
    for _ in 0..20 {
        let w = c.act(&mut robot).command.wheels;
        assert!(w.iter().all(|&v| v == 0.5 || v == -0.5), "sampled bits give full +-scale: {w:?}");
    }
}

#[test]
fn decode_tables_must_have_a_row_per_bit_pattern() {
    let mut s = neural_stage(expr(vec![Op::Const(0.0)]), None, zero_params());
    let Behavior::Neural(nb) = &mut s.modules[0].behavior else { unreachable!() };
    nb.decode = Decode::Table(vec![[1.0, 1.0]; 3]);
    let g = Genome::zeros(0);
    let opts = EpisodeOptions { actions: 1, learning: false, seed: 1 };
    let err = try_run_episode(&s, &g, &opts, None).unwrap_err().to_string();
    assert!(err.contains("`modules[0].behavior.decode`: 3 rows for 2 outputs"), "{err}");
}

/// A neural behavior with a signal output (`broadcast NAME`): its last
/// output is the value broadcast (sigmoid(1) here), or its sampled bit
/// while CRBP learns; the wheels read the outputs before it. A program
/// whose robot broadcasts fewer values than the behavior's signal outputs
/// is refused, naming the field.
#[test]
fn a_signal_output_sets_the_broadcast() {
    // Outputs 0 and 1: bias 1 (bits 1, 1: the table's last row); output 2: bias 1.
    let params = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0].into_iter().map(Param::Fixed).collect();
    let mut s = neural_stage(expr(vec![Op::Const(0.0)]), None, params);
    let Behavior::Neural(nb) = &mut s.modules[0].behavior else { unreachable!() };
    nb.net.outputs = 3;
    nb.signals = 1;
    let g = Genome::zeros(0);
    let opts = EpisodeOptions { actions: 1, learning: false, seed: 1 };
    let err = try_run_episode(&s, &g, &opts, None).unwrap_err().to_string();
    assert!(
        err.contains("`modules[0].behavior.signals`: 1 signal outputs, but the robot broadcasts 0 values"),
        "{err}"
    );
    s.world.body.rab = Some(RangeBearing { signals: 1, ..RangeBearing::DEFAULT });
    try_run_episode(&s, &g, &opts, None).expect("a valid stage");
    let mut c = controller(&s, 1);
    c.set_learning(false);
    let mut robot = Puppet::default();
    c.start(&mut robot);
    let cmd = c.act(&mut robot).command;
    assert_eq!(cmd.wheels, [1.0, 1.0], "the wheels from the first two outputs");
    assert_eq!(cmd.signal, Some([sigmoid(1.0), 0.0, 0.0, 0.0]));
    // Learning: the sampled bit, 1 with probability 0.73.
    s.modules[0].learning = Some(testkit::crbp(LearnTarget::Behavior, 0.1, 0.1, 30));
    let mut c = controller(&s, 1);
    c.start(&mut robot);
    let sent: Vec<f32> = (0..40).map(|_| c.act(&mut robot).command.signal.unwrap()[0]).collect();
    assert!(sent.iter().all(|&v| v == 0.0 || v == 1.0), "{sent:?}");
    assert!(sent.contains(&0.0) && sent.contains(&1.0), "both bits sampled: {sent:?}");
}

#[test]
fn a_committed_script_keeps_control_until_its_last_step() {
    // `a` wins the first action (no link input yet); from the second action
    // the excitatory link a -> b makes `b`'s activation the highest. A plain
    // script gives way at once; a committed one finishes its three steps.
    let step = |id: f32, n: u32| Step::new(Action::Wheels { left: id, right: id }, StepEnd::Actions(n));
    for commit in [false, true] {
        let a = Module {
            name: "a".into(),
            stage: 0,
            inputs: vec![],
            activation: bias_only(1.0),
            behavior: Behavior::Script(Script { steps: vec![step(1.0, 1), step(2.0, 2)], commit }),
            learning: None,
            reinforce: None,
        };
        let links = vec![Link { from: 0, to: 1, weight: Param::Fixed(10.0) }];
        let s = stage_of(vec![a, constant_module("b", 0.0, 9.0)], links);
        let mut c = controller(&s, 1);
        let mut robot = Puppet::default();
        c.start(&mut robot);
        let winners: Vec<usize> = (0..5).map(|_| c.act(&mut robot).winner).collect();
        if commit {
            assert_eq!(winners, [0, 0, 0, 1, 1], "the committed script runs its 3 actions, then b wins");
        } else {
            assert_eq!(winners, [0, 1, 1, 1, 1]);
        }
    }
}

#[test]
fn lamarckian_inheritance_writes_learned_behavior_genes_back() {
    // The neural behavior's 6 weights are genes (4 bits, -4..4), starting
    // at 0 (integer 7.5 is not encodable: 8 decodes to +0.27). Rewarding the
    // first output's 1s with input 0 on raises that output's bias and w0.
    let learn = Some(testkit::crbp(LearnTarget::Behavior, 0.5, 0.5, 30));
    let mut s = neural_stage(when_left_forward(1.0), learn, (0..6).map(Param::Gene).collect());
    s.layout.genes = (0..6)
        .map(|i| Gene {
            offset: 4 * i,
            bits: 4,
            lo: -4.0,
            hi: 4.0,
            stage: 0,
            module: 0,
            role: GeneRole::Bias,
            frozen: false,
        })
        .collect();
    s.layout.bits = 24;
    let mut genome = Genome::zeros(24);
    for g in &s.layout.genes {
        genome.set_gene_int(g, 8);
    }
    let mut c = Controller::new(&s, &genome, ChaCha8Rng::seed_from_u64(3)).unwrap();
    let mut robot = Puppet::default();
    robot.percept[0] = 1.0;
    c.run(&mut robot, &EpisodeOptions { actions: 200, learning: true, seed: 3 }, None);
    let learned = c.write_back(&genome);
    // Output 0's parameters are genes 0 (bias), 1 (w from input 0), 2 (w from input 1).
    assert!(learned.gene_int(&s.layout.genes[0]) > 8, "{}", learned.to_bitstring());
    assert!(learned.gene_int(&s.layout.genes[1]) > 8, "{}", learned.to_bitstring());
    assert_eq!(learned.gene_int(&s.layout.genes[2]), 8, "input 1 was 0: its weight is unchanged");
}

/// Fitness terms read the robot's state: the time, the distance travelled
/// and the squares visited, the same numbers as the episode's descriptors.
#[test]
fn fitness_terms_read_the_robot_s_state_as_the_descriptors_report_it() {
    use shaping_runtime::state::{ST_DISTANCE, ST_SQUARES, ST_TIME, ST_X};
    let mut stage = shaping_runtime::testkit::navigation();
    let one = |ops: Vec<Op>| Expr { depth: Expr::required_depth(&ops).unwrap(), ops };
    let run = |stage: &Stage| {
        let genome = Genome::zeros(stage.layout.bits as usize);
        let opts = EpisodeOptions { actions: 150, learning: true, seed: 4 };
        run_episode(stage, &genome, &opts, None)
    };
    let plain = run(&stage);
    // Per action: the actions done so far (1, 2, ...): their sum.
    stage.fitness.per_action = Some(one(vec![Op::State(ST_TIME as u16)]));
    // At the end: the distance plus 1000 times the squares, minus x.
    stage.fitness.at_end = Some(one(vec![
        Op::State(ST_DISTANCE as u16),
        Op::State(ST_SQUARES as u16),
        Op::Const(1000.0),
        Op::Mul,
        Op::Add,
        Op::State(ST_X as u16),
        Op::Sub,
    ]));
    let r = run(&stage);
    // Reading the state changes nothing of the episode.
    assert_eq!(
        (r.actions, r.collisions, r.descriptors),
        (plain.actions, plain.collisions, plain.descriptors)
    );
    let n = f64::from(r.actions);
    let d = r.descriptors;
    assert!(d.path_length > 100.0 && d.squares_visited >= 3.0, "{d:?}");
    let expected = n * (n + 1.0) / 2.0 + f64::from(d.path_length) + 1000.0 * f64::from(d.squares_visited)
        - f64::from(d.x);
    assert!(
        (f64::from(r.fitness) - expected).abs() < 1e-2 * expected.abs().max(1.0),
        "{} vs {expected}",
        r.fitness
    );
}
