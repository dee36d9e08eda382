//! The per-action loop never allocates: the simulator's `sense` + `step`, and
//! whole episodes whose allocation count does not grow with their length.
//!
//! `allocation_counter::measure` counts the allocations of the current
//! thread only, so tests running in parallel do not disturb each other.

use allocation_counter::measure;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use shaping_runtime::catalog::CHANNELS;
use shaping_runtime::controller::{run_episode, EpisodeOptions};
use shaping_runtime::program::{
    Behavior, Cylinder, InnerWall, Items, Lamp, Network, Param, Placement, Stage, Start, Zone,
};
use shaping_runtime::sim::{Command, Sim};
use shaping_runtime::testkit;

#[test]
fn the_simulator_step_never_allocates() {
    for stage in [testkit::navigation(), testkit::collect(), with_items()] {
        let mut world = stage.world.clone();
        world.battery = None;
        let mut sim = Sim::new(&world, 5);
        let mut p = [0.0f32; CHANNELS];
        let info = measure(|| {
            for i in 0..5_000u32 {
                sim.sense(&mut p);
                let turn = if i % 40 < 5 { 0.8 } else { 0.0 };
                let cmd = Command {
                    wheels: [1.0 - turn, 1.0 + turn],
                    arm: (i % 97 == 0).then_some(i % 2 == 0),
                    claw: (i % 89 == 0).then_some(i % 3 == 0),
                    charge: i % 7 == 0,
                    signal: None,
                };
                sim.step(&cmd);
            }
        });
        assert_eq!(info.count_total, 0, "stage `{}`: sense + step allocated", stage.name);
    }
}

/// Navigation in a world with every kind of declared item, its neural
/// behaviors recurrent (hidden 3).
fn with_items() -> Stage {
    let mut stage = testkit::navigation();
    stage.name = "items".into();
    stage.world.items = Items {
        walls: vec![InnerWall { name: None, from: [100.0, 200.0], to: [300.0, 200.0] }],
        cylinders: vec![Cylinder { name: None, at: [100.0, 450.0], diameter: 40.0 }],
        lamps: vec![Lamp { name: None, at: [300.0, 100.0], height: 100.0, intensity: 1.0, switch: None }],
        zones: vec![Zone { name: None, from: [0.0, 0.0], to: [120.0, 120.0], grey: 0.0, charger: true }],
        start: Some(Start { from: [150.0, 300.0], to: [250.0, 400.0], heading: None }),
        places: vec![Placement { name: None, at: [200.0, 300.0], heading: 0.0, after: 50 }],
    };
    for m in &mut stage.modules {
        if let Behavior::Neural(nb) = &mut m.behavior {
            let n = nb.inputs.len();
            let count = Network::param_count_of(n, 3, nb.net.outputs as usize, true);
            nb.net = Network {
                inputs: n as u16,
                hidden: 3,
                outputs: nb.net.outputs,
                recurrent: true,
                params: vec![Param::Random { lo: -1.0, hi: 1.0 }; count],
            };
        }
    }
    stage
}

/// Collect with a team of 8 robots crowded in a small arena, so that
/// they meet often.
fn team() -> Stage {
    let mut stage = testkit::collect();
    stage.name = "team".into();
    stage.world.robots = 8;
    stage.world.arena = [500.0, 500.0];
    stage
}

/// Allocations of one untraced episode of `actions` actions.
fn episode_allocations(stage: &Stage, actions: u32) -> (u64, u32) {
    let genome = testkit::random_genome(stage, &mut ChaCha8Rng::seed_from_u64(9));
    let opts = EpisodeOptions { actions, learning: true, seed: 3 };
    let mut actions = 0;
    let info = measure(|| actions = run_episode(stage, &genome, &opts, None).actions);
    (info.count_total, actions)
}

#[test]
fn an_episode_allocates_the_same_whatever_its_length() {
    // Navigation (CRBP on a behavior network) and collect (scripts, gripper,
    // CRBP on activation networks), without a battery so every episode
    // lasts as long as asked.
    for mut stage in [testkit::navigation(), testkit::collect(), with_items(), team()] {
        stage.world.battery = None;
        let (short, n_short) = episode_allocations(&stage, 10);
        let (long, n_long) = episode_allocations(&stage, 3_000);
        assert_eq!((n_short, n_long), (10, 3_000));
        assert!(short > 0, "the episode's set-up allocates, so the counter works");
        assert_eq!(
            short,
            long,
            "stage `{}`: 2990 more actions made {} more allocations",
            stage.name,
            long - short
        );
    }
}

/// The densest team there is, bodies packed side by side: finding each
/// robot's neighbours, sensing, moving and the team's measures allocate nothing.
#[test]
fn a_packed_team_never_allocates() {
    use shaping_runtime::sim::{Pose, Team};
    let mut world = testkit::navigation().world;
    world.battery = None;
    world.arena = [4000.0, 4000.0];
    world.robots = 144;
    world.items.start = Some(Start { from: [2000.0, 100.0], to: [3900.0, 3900.0], heading: None });
    let mut team = Team::new(&world, 1);
    // Moved from their start (the east half) to a square block in the west
    // half, 56 mm apart (bodies 55 mm wide).
    for i in 0..144 {
        let pose = Pose { x: 300.0 + (i % 12) as f32 * 56.0, y: 1000.0 + (i / 12) as f32 * 56.0, theta: 0.0 };
        assert!(team.place(i, pose), "robot {i}");
    }
    let mut p = [0.0f32; CHANNELS];
    let info = measure(|| {
        for a in 0..50u32 {
            team.begin_action();
            for i in 0..144 {
                team.prepare(i);
                team.sense(i, &mut p);
                let turn = if (i as u32 + a).is_multiple_of(5) { 1.0 } else { 0.0 };
                team.step(i, &Command { wheels: [1.0 - turn, 1.0], ..Command::default() });
            }
            // The team's state, every measure (`team.largest`,
            // `team.nearest`, `team.connected` ...).
            std::hint::black_box(team.state(shaping_runtime::state::TeamReads::ALL));
        }
    });
    assert_eq!(info.count_total, 0, "a packed team allocated");
}
