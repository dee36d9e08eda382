//! Hand-made [`Stage`]s for tests and benchmarks, so they do not need the
//! compiler.
//!
//! - [`navigation`]: the paper's stage 1 (wander, avoid, follow, recharge;
//!   links all evolvable; fitness `abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300`);
//! - [`collect`]: stage 2 extending it (barrier, arm and claw; 8 virtual 10 mm
//!   objects; grip and release scripts whose activation networks learn by CRBP;
//!   bonuses 0.5 per grip and 1.0 per release outside);
//! - small helpers ([`expr`], [`max_ir`], [`module`], [`lay_out`], ...) to
//!   build other stages.
//!
//! Genes are laid out the way the compiler does: stage-major; within a stage,
//! module by module in declaration order, each module's new genes as bias,
//! then input weights, then incoming links (by source module). A parameter is
//! marked evolvable with [`EVOLVABLE`] and [`lay_out`] gives it its gene.

use rand::Rng;

use crate::catalog::{ActuatorKind, SensorKind, CH_BARRIER, CH_BATTERY, CH_IR, CH_LIGHT};
use crate::expr::{Expr, Op};
use crate::genome::Genome;
use crate::program::*;

/// Placeholder for "an evolvable value": [`lay_out`] replaces it by a gene.
pub const EVOLVABLE: Param = Param::Gene(u32::MAX);

/// Bits and range of the genes [`lay_out`] creates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneSpec {
    pub bits: u8,
    pub lo: f32,
    pub hi: f32,
}

impl Default for GeneSpec {
    /// The paper's 4-bit genes, mapped to -1..1.
    fn default() -> Self {
        GeneSpec { bits: 4, lo: -1.0, hi: 1.0 }
    }
}

/// An expression from postfix code (depth computed; panics on malformed code,
/// which is a bug in the test that wrote it).
pub fn expr(ops: Vec<Op>) -> Expr {
    let depth = Expr::required_depth(&ops).expect("well-formed test expression");
    Expr { ops, depth }
}

/// Postfix code pushing `max` of the 8 IR channels (`prev` = previous percept).
pub fn max_ir(prev: bool) -> Vec<Op> {
    let mut ops: Vec<Op> =
        (CH_IR as u16..CH_IR as u16 + 8).map(|c| if prev { Op::Prev(c) } else { Op::Chan(c) }).collect();
    ops.push(Op::Max(8));
    ops
}

/// `sign(max(prev ir) - max(ir))`: the paper's obstacle-avoidance reinforcement.
pub fn ir_decrease() -> Expr {
    let mut ops = max_ir(true);
    ops.extend(max_ir(false));
    ops.extend([Op::Sub, Op::Sign]);
    expr(ops)
}

/// `abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / life`: the paper's stage-1 fitness.
pub fn straight_and_far(life: f32) -> Expr {
    let mut ops = vec![Op::Act(0), Op::Act(1), Op::Add, Op::Abs, Op::Const(2.0), Op::Div, Op::Const(1.0)];
    ops.extend(max_ir(false));
    ops.extend([Op::Sub, Op::Mul, Op::Const(life), Op::Div]);
    expr(ops)
}

/// Channels `start..start + n`.
pub fn chans(start: usize, n: usize) -> Vec<u16> {
    (start as u16..(start + n) as u16).collect()
}

/// A module with an evolvable single-layer activation network over `inputs`
/// and no learning.
pub fn module(name: &str, stage: u16, inputs: Vec<u16>, behavior: Behavior) -> Module {
    let n = inputs.len();
    Module {
        name: name.to_string(),
        stage,
        activation: Network {
            inputs: n as u16,
            hidden: 0,
            outputs: 1,
            recurrent: false,
            params: vec![EVOLVABLE; n + 1],
        },
        inputs,
        behavior,
        learning: None,
        reinforce: None,
    }
}

/// A one-step script.
pub fn script(action: Action) -> Behavior {
    Behavior::Script(Script { steps: vec![Step::new(action, StepEnd::Actions(1))], commit: false })
}

/// The paper's obstacle-avoidance behavior: a neural network from the 8 IR
/// sensors to two output bits (left and right motor forward or back: table
/// back, turn left, turn right, forward), random initial weights in
/// `-init..init`, learning by CRBP always, with `reinforce`.
pub fn avoid_behavior(init: f32, speed: f32) -> Behavior {
    let params = vec![Param::Random { lo: -init, hi: init }; Network::param_count(8, 0, 2)];
    Behavior::Neural(NeuralBehavior {
        inputs: chans(CH_IR, 8),
        net: Network { inputs: 8, hidden: 0, outputs: 2, recurrent: false, params },
        decode: Decode::Table(vec![[-speed, -speed], [-speed, speed], [speed, -speed], [speed, speed]]),
        signals: 0,
    })
}

/// CRBP learning settings.
pub fn crbp(target: LearnTarget, rate_reward: f32, rate_punish: f32, window: u32) -> Learning {
    Learning {
        target,
        rate_reward,
        rate_punish,
        when: LearnWhen::Always,
        window,
        error: CrbpError::default(),
    }
}

/// Links between every ordered pair of distinct modules, evolvable.
pub fn all_links(n: usize) -> Vec<Link> {
    let mut links = Vec::new();
    for to in 0..n {
        for from in 0..n {
            if from != to {
                links.push(Link { from: from as u16, to: to as u16, weight: EVOLVABLE });
            }
        }
    }
    links
}

/// Replaces every [`EVOLVABLE`] parameter of the stage's activation networks
/// and links by a new gene of stage `stage_index`, appended to the layout in
/// the compiler's order (see the module docs). Genes already in the layout
/// are marked frozen when they belong to an earlier stage.
pub fn lay_out(stage: &mut Stage, stage_index: u16, spec: GeneSpec) {
    let layout = &mut stage.layout;
    for g in &mut layout.genes {
        g.frozen = g.stage < stage_index;
    }
    let new_gene = |layout: &mut GenomeLayout, module: u16, role: GeneRole| -> Param {
        let i = layout.genes.len() as u32;
        layout.genes.push(Gene {
            offset: layout.bits,
            bits: spec.bits,
            lo: spec.lo,
            hi: spec.hi,
            stage: stage_index,
            module,
            role,
            frozen: false,
        });
        layout.bits += spec.bits as u32;
        Param::Gene(i)
    };
    for (m, module) in stage.modules.iter_mut().enumerate() {
        let m16 = m as u16;
        let n = module.inputs.len();
        for (k, p) in module.activation.params.iter_mut().enumerate() {
            if *p == EVOLVABLE {
                let role = if k % (n + 1) == 0 {
                    GeneRole::Bias
                } else {
                    GeneRole::Weight { input: (k % (n + 1) - 1) as u16, hidden: None }
                };
                *p = new_gene(layout, m16, role);
            }
        }
        let mut incoming: Vec<&mut Link> = stage.links.iter_mut().filter(|l| l.to == m16).collect();
        incoming.sort_by_key(|l| l.from);
        for l in incoming {
            if l.weight == EVOLVABLE {
                l.weight = new_gene(layout, m16, GeneRole::Link { from: l.from });
            }
        }
    }
}

/// A uniformly random genome for a stage.
pub fn random_genome(stage: &Stage, rng: &mut impl Rng) -> Genome {
    Genome { bits: (0..stage.layout.bits).map(|_| rng.random_range(0..2u8)).collect() }
}

/// The paper's arena: 400 x 600 mm, charger on the north wall with a lamp,
/// battery of 200 actions recharged in 20.
pub fn arena_world() -> World {
    World {
        arena: [400.0, 600.0],
        body: Body::default(),
        charger: Some(Charger { wall: Wall::North, length: 200.0, lamp_height: Some(100.0) }),
        battery: Some(Battery { capacity: 200, recharge: 20 }),
        objects: None,
        items: Default::default(),
        robots: 1,
    }
}

/// Stage-1 sensors: ir[8], light[8], battery.
fn navigation_sensors() -> Vec<SensorDecl> {
    vec![
        SensorDecl {
            name: "ir".into(),
            kind: SensorKind::Proximity,
            count: 8,
            channel: CH_IR as u16,
            stage: 0,
        },
        SensorDecl {
            name: "light".into(),
            kind: SensorKind::Ambient,
            count: 8,
            channel: CH_LIGHT as u16,
            stage: 0,
        },
        SensorDecl {
            name: "battery".into(),
            kind: SensorKind::Level,
            count: 1,
            channel: CH_BATTERY as u16,
            stage: 0,
        },
    ]
}

fn evolution(actions: u32) -> StageRun {
    StageRun::Evolve(Evolution {
        population: 100,
        generations: 40,
        actions,
        seed: 1,
        selection: Selection::Truncation { keep: 20 },
        crossover: 0.2,
        mutation: 0.05,
        elitism: 1,
        evaluations: 1,
    })
}

/// An empty stage over the arena with the stage-1 sensors and the wheels.
pub fn bare_stage(name: &str, world: World) -> Stage {
    Stage {
        name: name.into(),
        parent: None,
        sensors: navigation_sensors(),
        actuators: vec![ActuatorDecl { name: "wheels".into(), kind: ActuatorKind::Speed, stage: 0 }],
        world,
        modules: Vec::new(),
        links: Vec::new(),
        layout: GenomeLayout { genes: Vec::new(), bits: 0 },
        fitness: Fitness { per_action: None, at_end: None, bonuses: Vec::new(), team: Default::default() },
        run: evolution(300),
        inheritance: Inheritance::Darwinian,
        variants: None,
        targets: Vec::new(),
        roles: Vec::new(),
    }
}

/// The paper's stage 1 (`navigation`), genes as [`GeneSpec::default`].
///
/// | module | activation inputs | behavior |
/// |---|---|---|
/// | wander | ir | forward at full speed |
/// | avoid | ir | neural 8 ir -> 2 bits, random init +-0.5, CRBP always on `sign(max(prev ir) - max(ir))` |
/// | follow | light, battery | `toward(light)` at speed 1 |
/// | recharge | ir 0..6, battery | `wait` with charging until `battery >= 1` within 40 actions |
pub fn navigation() -> Stage {
    navigation_with(GeneSpec::default())
}

/// [`navigation`] with other gene bits and range.
pub fn navigation_with(spec: GeneSpec) -> Stage {
    let mut s = bare_stage("navigation", arena_world());
    let ir = chans(CH_IR, 8);
    let wander = module("wander", 0, ir.clone(), script(Action::Wheels { left: 1.0, right: 1.0 }));
    let mut avoid = module("avoid", 0, ir, avoid_behavior(0.5, 1.0));
    avoid.learning = Some(crbp(LearnTarget::Behavior, 0.1, 0.01, 30));
    avoid.reinforce = Some(ir_decrease());
    let mut follow_in = chans(CH_LIGHT, 8);
    follow_in.push(CH_BATTERY as u16);
    let follow =
        module("follow", 0, follow_in, script(Action::Toward { channels: chans(CH_LIGHT, 8), speed: 1.0 }));
    let mut rech_in = chans(CH_IR, 6);
    rech_in.push(CH_BATTERY as u16);
    let full = expr(vec![Op::Chan(CH_BATTERY as u16), Op::Const(1.0), Op::Ge]);
    let recharge = module(
        "recharge",
        0,
        rech_in,
        Behavior::Script(Script {
            steps: vec![Step::new(Action::Wait { charge: true }, StepEnd::Until { cond: full, within: 40 })],
            commit: false,
        }),
    );
    s.modules = vec![wander, avoid, follow, recharge];
    s.links = all_links(4);
    s.fitness.per_action = Some(straight_and_far(300.0));
    lay_out(&mut s, 0, spec);
    s
}

/// `max(ir[2], ir[3]) > level`: something close in front.
pub fn front_above(level: f32) -> Expr {
    expr(vec![Op::Chan(CH_IR as u16 + 2), Op::Chan(CH_IR as u16 + 3), Op::Max(2), Op::Const(level), Op::Gt])
}

/// `barrier ? hit : miss`.
pub fn barrier_select(hit: f32, miss: f32) -> Expr {
    expr(vec![Op::Chan(CH_BARRIER as u16), Op::Const(hit), Op::Const(miss), Op::Select])
}

/// The grip script (the paper's sequence): turn toward what the IR sees until
/// it is close in front, lower the arm, back until the barrier sees something
/// (at most 4 actions; the approach usually ends too close for the catch
/// zone), reinforce `barrier ? 1 : -1`, close the claw, lift the arm.
pub fn grip_script() -> Script {
    let step = Step::new;
    let barrier = expr(vec![Op::Chan(CH_BARRIER as u16)]);
    Script {
        steps: vec![
            step(
                Action::Toward { channels: chans(CH_IR, 8), speed: 0.5 },
                StepEnd::Until { cond: front_above(0.5), within: 10 },
            ),
            step(Action::Arm(true), StepEnd::Actions(1)),
            step(Action::Wheels { left: -0.3, right: -0.3 }, StepEnd::Until { cond: barrier, within: 4 }),
            step(Action::Reinforce(barrier_select(1.0, -1.0)), StepEnd::Actions(1)),
            step(Action::Claw(true), StepEnd::Actions(1)),
            step(Action::Arm(false), StepEnd::Actions(1)),
        ],
        commit: false,
    }
}

/// `min(ir[2], ir[3]) > level`: something wide and close in front (a wall).
pub fn wall_ahead(level: f32) -> Expr {
    expr(vec![Op::Chan(CH_IR as u16 + 2), Op::Chan(CH_IR as u16 + 3), Op::Min(2), Op::Const(level), Op::Gt])
}

/// The release script: turn toward what the IR sees until it is close in
/// front, reinforce `min(ir[2], ir[3]) > 0.5 ? 1 : -1` (both front sensors
/// high: a wall, where an object is thrown out; the simulator's barrier stays
/// on while an object is held, so it cannot tell walls here), open the claw.
pub fn release_script() -> Script {
    let step = Step::new;
    let wall = wall_ahead(0.5);
    let reinforce =
        expr(wall.ops.iter().copied().chain([Op::Const(1.0), Op::Const(-1.0), Op::Select]).collect());
    Script {
        steps: vec![
            step(
                Action::Toward { channels: chans(CH_IR, 8), speed: 0.5 },
                StepEnd::Until { cond: front_above(0.5), within: 10 },
            ),
            step(Action::Reinforce(reinforce), StepEnd::Actions(1)),
            step(Action::Claw(false), StepEnd::Actions(1)),
        ],
        commit: false,
    }
}

/// The paper's stage 2 (`collect`, parent 0) extending [`navigation`]:
/// adds the barrier, arm and claw, 8 virtual 10 mm objects, the grip and
/// release modules (activation inputs ir + barrier, CRBP on the activation
/// network always, rates 0.1 / 0.05, window 30), all links evolvable, and
/// the bonuses 0.5 per grip and 1.0 per release outside.
pub fn collect() -> Stage {
    collect_with(GeneSpec::default())
}

/// [`collect`] with other gene bits and range.
pub fn collect_with(spec: GeneSpec) -> Stage {
    let mut s = navigation_with(spec);
    s.name = "collect".into();
    s.parent = Some(0);
    s.sensors.push(SensorDecl {
        name: "barrier".into(),
        kind: SensorKind::Optical,
        count: 1,
        channel: CH_BARRIER as u16,
        stage: 1,
    });
    s.actuators.push(ActuatorDecl { name: "arm".into(), kind: ActuatorKind::Lift, stage: 1 });
    s.actuators.push(ActuatorDecl { name: "claw".into(), kind: ActuatorKind::Grip, stage: 1 });
    s.world.objects = Some(Objects { count: 8, diameter: 10.0, virtual_: true });
    let mut inputs = chans(CH_IR, 8);
    inputs.push(CH_BARRIER as u16);
    let mut grip = module("grip", 1, inputs.clone(), Behavior::Script(grip_script()));
    grip.learning = Some(crbp(LearnTarget::Activation, 0.1, 0.05, 30));
    let mut release = module("release", 1, inputs, Behavior::Script(release_script()));
    release.learning = Some(crbp(LearnTarget::Activation, 0.1, 0.05, 30));
    s.modules.push(grip);
    s.modules.push(release);
    for to in 0..6u16 {
        for from in 0..6u16 {
            if from != to && (from >= 4 || to >= 4) {
                s.links.push(Link { from, to, weight: EVOLVABLE });
            }
        }
    }
    s.fitness.bonuses =
        vec![Bonus { event: Event::Grip, points: 0.5 }, Bonus { event: Event::ReleaseOutside, points: 1.0 }];
    lay_out(&mut s, 1, spec);
    s
}

/// A heterogeneous team of 3 robots, without noise, battery or charger:
/// role `movers` (robots 0 and 1) has two modules, one spinning left, one
/// right; role `sitters` (robot 2) one that stops. Each module's activation
/// is evolvable, so every role has its genes; `edit` is applied before the
/// genes are laid out.
pub fn two_roles(edit: impl Fn(&mut Stage)) -> Stage {
    let mut world = World { robots: 3, battery: None, charger: None, ..arena_world() };
    world.body.wheel_noise = 0.0;
    world.body.sensor_noise = 0.0;
    let mut st = bare_stage("roles", world);
    let ir = chans(CH_IR, 8);
    let wheels = |left, right| script(Action::Wheels { left, right });
    st.modules = vec![
        module("go", 0, ir.clone(), wheels(-1.0, 1.0)),
        module("turn", 0, ir.clone(), wheels(1.0, -1.0)),
        // The same name in another role: each role names its own modules.
        module("go", 0, ir, wheels(0.0, 0.0)),
    ];
    st.links = vec![Link { from: 0, to: 1, weight: EVOLVABLE }];
    st.roles = vec![
        Role { name: "movers".into(), robots: 2, modules: 2, fitness: None },
        Role { name: "sitters".into(), robots: 1, modules: 1, fitness: None },
    ];
    edit(&mut st);
    lay_out(&mut st, 0, GeneSpec::default());
    st
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn navigation_layout_is_module_major_bias_weights_links() {
        let s = navigation();
        // wander: bias + 8 weights + 3 links; avoid: same; follow: bias + 9 + 3; recharge: bias + 7 + 3.
        assert_eq!(s.layout.genes.len(), 12 + 12 + 13 + 11);
        assert_eq!(s.layout.bits, 4 * 48);
        let g = &s.layout.genes;
        assert_eq!(g[0].role, GeneRole::Bias);
        assert_eq!(g[1].role, GeneRole::Weight { input: 0, hidden: None });
        assert_eq!(g[9].role, GeneRole::Link { from: 1 });
        assert_eq!(g[11].role, GeneRole::Link { from: 3 });
        assert_eq!((g[12].module, g[12].role), (1, GeneRole::Bias));
        assert!(g.iter().all(|g| !g.frozen && g.stage == 0));
        assert_eq!(s.modules[0].activation.params[0], Param::Gene(0));
        assert_eq!(s.links[0].weight, Param::Gene(9));
    }

    #[test]
    fn collect_appends_new_genes_and_freezes_old_ones() {
        let nav = navigation();
        let s = collect();
        let old = nav.layout.genes.len();
        assert_eq!(
            &s.layout.genes[..old].iter().map(|g| g.offset).collect::<Vec<_>>()[..],
            &nav.layout.genes.iter().map(|g| g.offset).collect::<Vec<_>>()[..]
        );
        assert!(s.layout.genes[..old].iter().all(|g| g.frozen));
        assert!(s.layout.genes[old..].iter().all(|g| !g.frozen && g.stage == 1));
        // New: 2 links into each old module, then grip and release: bias + 9 weights + 5 links.
        assert_eq!(s.layout.genes.len() - old, 4 * 2 + 2 * 15);
        assert_eq!(s.modules[0].activation.params, nav.modules[0].activation.params);
    }
}
