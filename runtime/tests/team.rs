//! Several robots in one world: a team of one is the one robot, robots
//! see and block each other, share the objects, take turns at the charger,
//! and a team's fitness is its robots' aggregated.

use shaping_runtime::catalog::{CHANNELS, CH_IR};
use shaping_runtime::controller::{
    run_episode, run_episode_until, run_team_episode, run_team_episode_until, EpisodeOptions, Trace,
};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::*;
use shaping_runtime::sim::{Command, ObjectState, Pose, Team};
use shaping_runtime::testkit;

fn quiet(mut w: World) -> World {
    w.body.wheel_noise = 0.0;
    w.body.sensor_noise = 0.0;
    w
}

fn genome_of(stage: &Stage, seed: u64) -> Genome {
    use rand::SeedableRng;
    testkit::random_genome(stage, &mut rand_chacha::ChaCha8Rng::seed_from_u64(seed))
}

#[test]
fn a_team_of_one_is_the_one_robot() {
    let stage = testkit::collect();
    for seed in 1..4 {
        let g = genome_of(&stage, seed);
        let opts = EpisodeOptions { actions: 400, learning: true, seed };
        let one = run_episode(&stage, &g, &opts, None);
        let team = run_team_episode(&stage, &g, &opts, None).unwrap();
        assert_eq!(team.robots.len(), 1);
        assert_eq!(team.team.fitness, one.fitness, "seed {seed}");
        assert_eq!(team.team.descriptors, one.descriptors, "seed {seed}");
        assert_eq!(team.robots[0].grips, one.grips);
    }
}

/// A team's episode asks whether to stop before it starts and after each
/// action, and gives up at once when told to (a large team's episode may
/// last minutes: Ctrl-C must not wait for its end); one not given up is
/// the episode itself.
#[test]
fn a_teams_episode_is_given_up_at_the_next_action_once_told() {
    let stage = Stage { world: World { robots: 3, ..testkit::collect().world }, ..testkit::collect() };
    let g = genome_of(&stage, 2);
    let opts = EpisodeOptions { actions: 50, learning: true, seed: 4 };
    let whole = run_team_episode(&stage, &g, &opts, None).unwrap();
    let asked = std::cell::Cell::new(0u32);
    let count = || {
        asked.set(asked.get() + 1);
        false
    };
    let same = run_team_episode_until(&stage, &g, &opts, None, count).unwrap();
    assert_eq!(same.as_ref(), Some(&whole));
    assert_eq!(asked.get(), 1 + whole.team.actions, "once before and once after each action");
    asked.set(0);
    let after_ten = || {
        asked.set(asked.get() + 1);
        asked.get() > 10
    };
    assert_eq!(run_team_episode_until(&stage, &g, &opts, None, after_ten).unwrap(), None);
    assert_eq!(asked.get(), 11, "given up after its tenth action");
    assert_eq!(run_episode_until(&stage, &g, &opts, || true), None);
    assert_eq!(run_episode_until(&stage, &g, &opts, || false), Some(run_episode(&stage, &g, &opts, None)));
}

#[test]
fn robots_see_each_other_with_their_proximity_sensors() {
    let world = quiet(World { robots: 2, ..testkit::arena_world() });
    let mut team = Team::new(&world, 1);
    // Robot 0 faces east at the middle; robot 1 is 10 mm ahead of its front.
    assert!(team.place(0, Pose { x: 150.0, y: 300.0, theta: 0.0 }));
    assert!(team.place(1, Pose { x: 150.0 + 55.0 + 10.0, y: 300.0, theta: std::f32::consts::PI }));
    team.begin_action();
    team.prepare(0);
    let mut near = [0.0; CHANNELS];
    team.sense(0, &mut near);
    // Without the other robot the front sensors read nothing there.
    assert!(team.place(1, Pose { x: 150.0, y: 520.0, theta: 0.0 }));
    team.begin_action();
    team.prepare(0);
    let mut alone = [0.0; CHANNELS];
    team.sense(0, &mut alone);
    let front = |p: &[f32; CHANNELS]| p[CH_IR + 2] + p[CH_IR + 3];
    assert!(front(&near) > 0.5, "front sensors {:?}", &near[CH_IR..CH_IR + 8]);
    assert_eq!(front(&alone), 0.0, "front sensors {:?}", &alone[CH_IR..CH_IR + 8]);
}

#[test]
fn a_robot_cannot_drive_into_another() {
    let world = quiet(World { robots: 2, battery: None, ..testkit::arena_world() });
    let mut team = Team::new(&world, 2);
    assert!(team.place(0, Pose { x: 100.0, y: 300.0, theta: 0.0 }));
    assert!(team.place(1, Pose { x: 200.0, y: 300.0, theta: 0.0 }));
    let mut collided = false;
    for _ in 0..40 {
        team.begin_action();
        team.prepare(0);
        collided |= team.step(0, &Command { wheels: [1.0, 1.0], ..Command::default() }).collided;
        team.prepare(1);
        team.step(1, &Command::default());
    }
    let (a, b) = (team.sim(0).position(), team.sim(1).position());
    let gap = (b[0] - a[0]).hypot(b[1] - a[1]);
    assert!(collided, "the move into the other robot collides");
    assert!((55.0..57.0).contains(&gap), "the bodies touch and do not overlap: centres {gap} mm apart");
}

#[test]
fn the_robots_start_apart_in_the_start_region() {
    let mut world = quiet(World { arena: [1000.0, 1000.0], robots: 12, ..testkit::arena_world() });
    world.items.start = Some(Start { from: [300.0, 300.0], to: [700.0, 700.0], heading: None });
    assert!(world.robots <= shaping_runtime::world::team_room(&world));
    for seed in 0..5 {
        let team = Team::new(&world, seed);
        let at: Vec<[f32; 2]> = team.sims().iter().map(|s| s.position()).collect();
        for (i, p) in at.iter().enumerate() {
            assert!((300.0..=700.0).contains(&p[0]) && (300.0..=700.0).contains(&p[1]), "{p:?}");
            for q in &at[..i] {
                assert!((p[0] - q[0]).hypot(p[1] - q[1]) >= 55.0, "robots overlap at {p:?} and {q:?}");
            }
            assert_eq!(team.sim(i).placement_failures(), 0);
        }
        // The same seed places the same team.
        let again: Vec<[f32; 2]> = Team::new(&world, seed).sims().iter().map(|s| s.position()).collect();
        assert_eq!(at, again);
    }
}

#[test]
fn an_object_gripped_by_one_robot_is_gone_for_the_others() {
    let mut world = quiet(World { robots: 2, battery: None, ..testkit::arena_world() });
    world.objects = Some(Objects { count: 1, diameter: 25.0, virtual_: false });
    let mut team = Team::new(&world, 3);
    let o = &team.sim(0).scene().objects[0];
    let obj = [o.x, o.y];
    // Robot 0 just behind the object, facing it; robot 1 out of the way.
    let r = 27.5 + 15.0;
    assert!(
        team.place(1, Pose { x: 40.0, y: 40.0, theta: 0.0 })
            || team.place(1, Pose { x: 360.0, y: 40.0, theta: 0.0 })
    );
    let placed = {
        use std::f32::consts::{FRAC_PI_2, PI};
        [0.0f32, FRAC_PI_2, PI, -FRAC_PI_2]
    }
    .into_iter()
    .any(|theta| team.place(0, Pose { x: obj[0] - r * theta.cos(), y: obj[1] - r * theta.sin(), theta }));
    assert!(placed, "room behind the object at {obj:?}");
    team.begin_action();
    team.prepare(0);
    let out = team.step(0, &Command { arm: Some(true), claw: Some(true), ..Command::default() });
    assert_eq!(out.grips, 1);
    for i in 0..2 {
        assert_eq!(team.sim(i).scene().objects[0].state, ObjectState::Held, "robot {i}'s world");
    }
    assert!(team.sim(0).holding() && !team.sim(1).holding());
}

#[test]
fn the_charger_serves_one_robot_at_a_time() {
    let mut world = quiet(World { robots: 2, ..testkit::arena_world() });
    world.battery = Some(Battery { capacity: 50, recharge: 10 });
    let mut team = Team::new(&world, 4);
    // Both against the north bar (200 mm long in the middle of the 400 mm wall).
    let y = 600.0 - 27.5 - 1.0;
    assert!(team.place(0, Pose { x: 160.0, y, theta: std::f32::consts::FRAC_PI_2 }));
    assert!(team.place(1, Pose { x: 240.0, y, theta: std::f32::consts::FRAC_PI_2 }));
    // Drain both a little first.
    for _ in 0..30 {
        team.begin_action();
        for i in 0..2 {
            team.prepare(i);
            team.step(i, &Command::default());
        }
    }
    let charge = Command { charge: true, ..Command::default() };
    let mut holders = std::collections::BTreeSet::new();
    let mut recharged = [0u32; 2];
    let mut rises = [0u32; 2];
    for _ in 0..60 {
        team.begin_action();
        for (i, r) in recharged.iter_mut().enumerate() {
            let (before, other) = (team.sim(i).battery(), team.charger_holder());
            team.prepare(i);
            *r += u32::from(team.step(i, &charge).recharged);
            if team.sim(i).battery() > before {
                rises[i] += 1;
                // Only a robot the charger served: free, or its own.
                assert!(
                    other.is_none_or(|h| h == i),
                    "robot {i} charged while robot {other:?} held the charger"
                );
            }
        }
        holders.extend(team.charger_holder());
    }
    assert!(rises[0] > 0 && rises[1] > 0, "{rises:?}");
    assert_eq!(holders.len(), 2, "each robot had its turn: {holders:?}");
    assert_eq!(recharged, [1, 1], "both batteries were filled, one after the other");
}

#[test]
fn a_teams_fitness_is_its_robots_aggregated() {
    let mut stage = testkit::collect();
    stage.world.robots = 3;
    let g = genome_of(&stage, 9);
    let opts = EpisodeOptions { actions: 300, learning: true, seed: 11 };
    let mut traces = vec![Trace::default(); 3];
    let res = run_team_episode(&stage, &g, &opts, Some(&mut traces)).unwrap();
    let f: Vec<f32> = res.robots.iter().map(|r| r.fitness).collect();
    assert_eq!(res.team.fitness, Aggregate::Mean.of(f.iter().copied()));
    stage.fitness.team = Aggregate::Min;
    let min = run_team_episode(&stage, &g, &opts, None).unwrap();
    assert_eq!(min.team.fitness, f.iter().copied().fold(f32::INFINITY, f32::min));
    stage.fitness.team = Aggregate::Sum;
    let sum = run_team_episode(&stage, &g, &opts, None).unwrap();
    assert!((sum.team.fitness - f.iter().sum::<f32>()).abs() <= 1e-3 * f.iter().sum::<f32>().abs().max(1.0));
    // Each robot lived its own life, traced.
    for (t, r) in traces.iter().zip(&res.robots) {
        assert_eq!(t.rows.len() as u32, r.actions);
    }
    assert_ne!(traces[0].rows.last().unwrap().pose, traces[1].rows.last().unwrap().pose);
    // Deterministic by seed.
    stage.fitness.team = Aggregate::Mean;
    assert_eq!(run_team_episode(&stage, &g, &opts, None).unwrap(), res);
}

#[test]
fn team_spread_is_read_at_the_end() {
    let mut stage =
        testkit::bare_stage("spread", quiet(World { robots: 4, battery: None, ..testkit::arena_world() }));
    stage.fitness.at_end =
        Some(testkit::expr(vec![shaping_runtime::expr::Op::State(shaping_runtime::state::ST_SPREAD as u16)]));
    let g = Genome { bits: vec![] };
    let opts = EpisodeOptions { actions: 5, learning: false, seed: 3 };
    let res = run_team_episode(&stage, &g, &opts, None).unwrap();
    // No module: the robots stand still, so the spread is the start's.
    let spread = Team::new(&stage.world, 3).spread();
    assert!(spread > 10.0);
    for r in &res.robots {
        assert_eq!(r.fitness, spread);
    }
}

/// The team's groups, found in the grid, are those of a search over every
/// pair: robots placed at random, some touching, in teams of 1 to 60.
#[test]
fn team_groups_are_every_pairs() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    for (n, side) in [(1u32, 400.0f32), (2, 300.0), (7, 500.0), (25, 900.0), (60, 1500.0)] {
        let world = quiet(World {
            robots: n,
            battery: None,
            charger: None,
            arena: [side, side],
            ..testkit::arena_world()
        });
        let mut team = Team::new(&world, u64::from(n));
        let r = world.body.radius;
        // Each robot placed near the last one placed, or anywhere.
        for i in 1..n as usize {
            for _ in 0..50 {
                let prev = team.sim(rng.random_range(0..i)).position();
                let (x, y) = if rng.random_bool(0.6) {
                    let a: f32 = rng.random_range(0.0..std::f32::consts::TAU);
                    let d = 2.0 * r + rng.random_range(0.0..30.0);
                    (prev[0] + d * a.cos(), prev[1] + d * a.sin())
                } else {
                    (rng.random_range(30.0..side - 30.0), rng.random_range(30.0..side - 30.0))
                };
                if team.place(i, Pose { x, y, theta: 0.0 }) {
                    break;
                }
            }
        }
        team.begin_action();
        let at: Vec<[f32; 2]> = team.sims().iter().map(|s| s.position()).collect();
        let near = |i: usize, j: usize| (at[i][0] - at[j][0]).hypot(at[i][1] - at[j][1]) <= 2.0 * r + 20.0;
        let k = at.len();
        let with = (0..k).filter(|&i| (0..k).any(|j| j != i && near(i, j))).count();
        // The largest group by repeated spreading from each robot.
        let mut largest = 0;
        for first in 0..k {
            let mut seen = vec![false; k];
            seen[first] = true;
            let mut stack = vec![first];
            while let Some(i) = stack.pop() {
                for (j, s) in seen.iter_mut().enumerate() {
                    if !*s && near(i, j) {
                        *s = true;
                        stack.push(j);
                    }
                }
            }
            largest = largest.max(seen.iter().filter(|&&s| s).count());
        }
        let (grouped, big) = team.groups(shaping_runtime::state::NEIGHBOUR_GAP);
        assert_eq!(grouped, with as f32 / k as f32, "{n} robots");
        assert_eq!(big, largest as f32 / k as f32, "{n} robots");
        if n == 60 {
            assert!(
                with > 10 && largest > 2 && largest < k,
                "a mixed team: {with} grouped, largest {largest}"
            );
        }
    }
}

/// `team.grouped` and `team.largest` reach the fitness, measured where the
/// robots end.
#[test]
fn team_groups_are_read_at_the_end() {
    use shaping_runtime::expr::Op;
    use shaping_runtime::state::{ST_GROUPED, ST_LARGEST};
    let mut stage = testkit::bare_stage(
        "groups",
        quiet(World { robots: 6, battery: None, charger: None, ..testkit::arena_world() }),
    );
    // 10 x team.grouped + team.largest: both in one number.
    stage.fitness.at_end = Some(testkit::expr(vec![
        Op::State(ST_GROUPED as u16),
        Op::Const(10.0),
        Op::Mul,
        Op::State(ST_LARGEST as u16),
        Op::Add,
    ]));
    let opts = EpisodeOptions { actions: 5, learning: false, seed: 4 };
    let res = run_team_episode(&stage, &Genome { bits: vec![] }, &opts, None).unwrap();
    // No module: the robots stand where they start.
    let (grouped, largest) = Team::new(&stage.world, 4).groups(shaping_runtime::state::NEIGHBOUR_GAP);
    assert!(largest > 0.0);
    for r in &res.robots {
        assert_eq!(r.fitness, 10.0 * grouped + largest);
    }
}

/// `team.nearest`, `team.order` and `team.connected` reach the fitness,
/// measured where the robots end.
#[test]
fn team_swarm_measures_are_read_at_the_end() {
    use shaping_runtime::expr::Op;
    use shaping_runtime::state::{TeamReads, ST_CONNECTED, ST_NEAREST, ST_ORDER};
    let mut stage = testkit::bare_stage(
        "swarm",
        quiet(World { robots: 6, battery: None, charger: None, ..testkit::arena_world() }),
    );
    // team.nearest + 1000 x team.order + 10000 x team.connected.
    stage.fitness.at_end = Some(testkit::expr(vec![
        Op::State(ST_NEAREST as u16),
        Op::State(ST_ORDER as u16),
        Op::Const(1000.0),
        Op::Mul,
        Op::Add,
        Op::State(ST_CONNECTED as u16),
        Op::Const(10000.0),
        Op::Mul,
        Op::Add,
    ]));
    let opts = EpisodeOptions { actions: 5, learning: false, seed: 4 };
    let res = run_team_episode(&stage, &Genome { bits: vec![] }, &opts, None).unwrap();
    // No module: the robots stand where they start.
    let s = Team::new(&stage.world, 4).state(TeamReads::ALL);
    let (nearest, order, connected) = (s[3], s[4], s[5]);
    assert!(nearest > 0.0 && order > 0.0 && connected > 0.0, "{s:?}");
    for r in &res.robots {
        assert_eq!(r.fitness, nearest + order * 1000.0 + connected * 10000.0);
    }
}

#[test]
fn the_robot_link_refuses_a_team() {
    let mut stage = testkit::collect();
    assert_eq!(shaping_runtime::robot::unfit_for_robot(&stage), None);
    stage.world.robots = 3;
    let why = shaping_runtime::robot::unfit_for_robot(&stage).unwrap();
    assert!(why.contains("a team of 3 robots") && why.contains("one serial port"), "{why}");
}

fn two_roles() -> Stage {
    testkit::two_roles(|_| ())
}

fn two_roles_with(edit: impl Fn(&mut Stage)) -> Stage {
    testkit::two_roles(edit)
}

#[test]
fn each_robot_runs_its_roles_modules() {
    let stage = two_roles();
    shaping_runtime::validate::stage(&stage).expect("a valid two-role stage");
    assert_eq!((0..4).map(|i| stage.role_of(i)).collect::<Vec<_>>(), [0, 0, 1, 1]);
    for seed in 1..4 {
        let g = genome_of(&stage, seed);
        let opts = EpisodeOptions { actions: 60, learning: true, seed };
        let mut traces = vec![Trace::default(); 3];
        let res = run_team_episode(&stage, &g, &opts, Some(&mut traces)).unwrap();
        assert_eq!(res.robots.len(), 3);
        assert_eq!(traces[0].modules, ["go", "turn"]);
        assert_eq!(traces[2].modules, ["go"]);
        // How much the robot moved and turned, action by action.
        let travel = |t: &Trace| -> f32 {
            t.rows
                .windows(2)
                .map(|w| {
                    (w[1].pose.x - w[0].pose.x).hypot(w[1].pose.y - w[0].pose.y)
                        + (w[1].pose.theta - w[0].pose.theta).abs()
                })
                .sum()
        };
        for t in &traces[..2] {
            assert!(t.rows.iter().all(|r| r.winner < 2 && r.activations.len() == 2));
            assert!(travel(t) > 1.0, "a mover moves or turns (seed {seed})");
        }
        assert!(traces[2].rows.iter().all(|r| r.winner == 0 && r.activations.len() == 1));
        assert_eq!(travel(&traces[2]), 0.0, "the sitter stays where it starts (seed {seed})");
    }
}

#[test]
fn a_teams_size_is_derived_from_its_roles() {
    let mut stage = two_roles();
    assert_eq!(stage.robots(), stage.roles.iter().map(|r| r.robots).sum::<u32>());
    stage.set_role_robots(1, 5);
    assert_eq!(stage.roles[1].robots, 5);
    assert_eq!(stage.robots(), stage.roles[0].robots + 5);
    assert_eq!(stage.world.robots, stage.robots(), "the world's team follows the roles");
    shaping_runtime::validate::stage(&stage).expect("the roles and the world agree");
    // Without roles, the world says.
    stage.roles.clear();
    stage.world.robots = 0;
    assert_eq!(stage.robots(), 1, "at least one robot");
}

#[test]
fn a_roles_genes_are_its_own() {
    let stage = two_roles();
    let opts = EpisodeOptions { actions: 60, learning: true, seed: 3 };
    let g = genome_of(&stage, 5);
    let base = run_team_episode(&stage, &g, &opts, None).unwrap();
    // Flip every bit of the sitters' gene (the third module's activation).
    let mut other = g.clone();
    for gene in stage.layout.genes.iter().filter(|x| x.module == 2) {
        for b in gene.offset..gene.offset + gene.bits as u32 {
            other.bits[b as usize] ^= 1;
        }
    }
    let changed = run_team_episode(&stage, &other, &opts, None).unwrap();
    // The sitter has one module: what its activation is does not change
    // what it does, nor the movers' lives.
    assert_eq!(changed.robots, base.robots);
    // The movers' genes do change the movers.
    let mut movers = g.clone();
    for gene in stage.layout.genes.iter().filter(|x| x.module < 2) {
        for b in gene.offset..gene.offset + gene.bits as u32 {
            movers.bits[b as usize] ^= 1;
        }
    }
    let moved = run_team_episode(&stage, &movers, &opts, None).unwrap();
    assert_ne!(moved.robots[..2], base.robots[..2]);
    assert_eq!(moved.robots[2], base.robots[2]);
}

#[test]
fn lamarckian_roles_write_back_every_roles_learning() {
    let mut stage = two_roles();
    stage.inheritance = Inheritance::Lamarckian;
    for m in &mut stage.modules {
        m.learning = Some(testkit::crbp(LearnTarget::Activation, 0.5, 0.5, 10));
        // Every action rewarded: whatever a module does, it learns.
        m.reinforce = Some(testkit::expr(vec![shaping_runtime::expr::Op::Const(1.0)]));
    }
    shaping_runtime::validate::stage(&stage).unwrap();
    let g = genome_of(&stage, 7);
    let opts = EpisodeOptions { actions: 300, learning: true, seed: 2 };
    let learned = run_team_episode(&stage, &g, &opts, None).unwrap().team.learned.unwrap();
    let differs = |module: u16| {
        stage.layout.genes.iter().filter(|x| x.module == module).any(|x| {
            let r = x.offset as usize..(x.offset + x.bits as u32) as usize;
            learned.bits[r.clone()] != g.bits[r]
        })
    };
    assert!(differs(0) || differs(1), "the movers' learning is written back");
    assert!(differs(2), "the sitters' learning is written back");
}

#[test]
fn bad_roles_are_refused() {
    let check = |edit: &dyn Fn(&mut Stage), expect: &str| {
        let s = two_roles_with(edit);
        let e = shaping_runtime::validate::stage(&s).expect_err(expect).to_string();
        assert!(e.contains(expect), "{e}");
    };
    check(&|s| s.world.robots = 4, "4 robots, but the roles have 3");
    check(&|s| s.links.push(Link { from: 0, to: 2, weight: Param::Fixed(1.0) }), "different roles");
    check(&|s| s.roles[1].name = "movers".into(), "`movers` names two roles");
    check(&|s| s.roles[1].modules = 2, "the roles have 4 modules, the stage 3");
    check(&|s| s.modules[2].activation.params = vec![Param::Fixed(0.0); 9], "role `sitters` has no genes");
    check(&|s| s.modules[1].name = "go".into(), "`go` is also the name of module 0");
}
