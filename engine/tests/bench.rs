//! `shaping bench`'s figures (not its speed): a team's timed robots move
//! and every robot's step is counted.

mod common;

use common::tiny;
use shaping_engine::bench::{bench, controller_lives, SIM_ROBOT_STEPS, TEAM_ACTIONS};

/// A team of 4 in `tiny.bat`'s first stage, with and without its battery
/// (200 actions: the team is made anew as its robots run out).
#[test]
fn a_team_bench_counts_every_robots_steps_and_its_robots_move() {
    for battery in [true, false] {
        let mut program = tiny();
        let world = &mut program.stages[0].world;
        world.robots = 4;
        if !battery {
            world.battery = None;
        }
        let b = bench(program, 0, 2).unwrap();
        assert_eq!(b.robots, 4);
        assert_eq!(b.actions, 2 * SIM_ROBOT_STEPS / 4, "battery {battery}");
        if battery {
            // A dead robot's turn is no step, until half the team is dead.
            assert!(b.robot_steps <= 4 * b.actions && b.robot_steps > 2 * b.actions, "{b:?}");
        } else {
            assert_eq!(b.robot_steps, 4 * b.actions, "a robot did not step");
        }
        assert!(b.sim_moving_share > 0.5, "battery {battery}: {b:?}");
        assert!(b.sim_collision_share < 0.5, "battery {battery}: {b:?}");
        assert!(b.robot_steps_per_sec > b.sim_steps_per_sec, "{b:?}");
        assert!(b.controller_actions_per_sec > 0.0 && b.controller_actions_per_episode > 0.0, "{b:?}");
    }
}

/// One robot: a robot-step is a step of the world.
#[test]
fn a_single_robot_bench_has_one_robot_step_per_step() {
    let b = bench(tiny(), 0, 1).unwrap();
    assert_eq!((b.robots, b.robot_steps, b.actions), (1, SIM_ROBOT_STEPS, SIM_ROBOT_STEPS));
    assert_eq!(b.robot_steps_per_sec, b.sim_steps_per_sec);
    assert!(b.sim_moving_share > 0.9, "{b:?}");
}

/// The controller runs' lives: one robot's 200 of 300 actions; a team's
/// fewer for as many robot-actions, but never shorter than 100 actions,
/// so that a large team's bench times its robots acting, not its placing.
#[test]
fn a_large_teams_controller_lives_are_100_actions_or_more() {
    assert_eq!(controller_lives(1), (200, 300));
    assert_eq!(controller_lives(10), (20, 300));
    assert_eq!(controller_lives(100), (2, 300));
    assert_eq!(controller_lives(400), (1, 150));
    for robots in [1_000, 10_000, 100_000] {
        assert_eq!(controller_lives(robots), (1, TEAM_ACTIONS), "{robots} robots");
    }
}
