//! Every ```bat block of `docs/language.md` compiles; blocks marked
//! ```bat,fails must fail.

use crate::root;

/// The ```bat blocks of `docs/language.md`: name (`language.md:LINE`),
/// source, and whether the block is marked ```bat,fails.
pub fn blocks() -> Vec<(String, String, bool)> {
    let text = std::fs::read_to_string(root().join("docs/language.md")).unwrap();
    let mut out = Vec::new();
    let mut lines = text.lines().enumerate();
    while let Some((i, line)) = lines.next() {
        let Some(info) = line.trim_start().strip_prefix("```bat") else { continue };
        let fails = info.trim() == ",fails";
        let mut src = String::new();
        for (_, l) in lines.by_ref() {
            if l.trim_start().starts_with("```") {
                break;
            }
            src.push_str(l);
            src.push('\n');
        }
        out.push((format!("language.md:{}", i + 1), src, fails));
    }
    out
}

#[test]
fn language_reference_examples() {
    let blocks = blocks();
    for (name, src, fails) in &blocks {
        match (shaping_compiler::compile(src, name), fails) {
            (Ok(p), false) => assert_eq!(p.validate(), Ok(()), "{name}"),
            (Err(_), true) => {}
            (Ok(_), true) => panic!("{name}: the block is marked `fails` but compiles"),
            (Err(d), false) => panic!("{name} does not compile:\n{}", crate::render(&d)),
        }
    }
    assert!(blocks.len() >= 10, "only {} examples in docs/language.md", blocks.len());
}

/// The numbers section 18 of `docs/language.md` states about the robot and
/// the world, measured on the simulator (default body, no noise).
mod world_facts {
    use shaping_runtime::catalog::{CHANNELS, CH_BARRIER, CH_BATTERY, CH_IR, CH_LIGHT};
    use shaping_runtime::program::{Battery, Body, Charger, Objects, Wall, World};
    use shaping_runtime::sim::{Command, Pose, Sim};
    use std::f32::consts::FRAC_PI_2;

    const RADIUS: f32 = 27.5;

    fn world() -> World {
        let body = Body { wheel_noise: 0.0, sensor_noise: 0.0, ..Body::default() };
        World {
            arena: [400.0, 600.0],
            body,
            charger: Some(Charger { wall: Wall::North, length: 200.0, lamp_height: Some(150.0) }),
            battery: Some(Battery { capacity: 200, recharge: 20 }),
            objects: None,
            items: Default::default(),
            robots: 1,
        }
    }

    /// The percept with the robot at `(x, y)`, heading `theta`.
    fn sense(w: &World, x: f32, y: f32, theta: f32) -> [f32; CHANNELS] {
        let mut s = Sim::new(w, 1);
        assert!(s.set_pose(Pose { x, y, theta }));
        let mut out = [0.0; CHANNELS];
        s.sense(&mut out);
        out
    }

    /// The robot facing the north wall (and the lamp) with `gap` mm between
    /// its body and the wall.
    fn facing_north(gap: f32) -> [f32; CHANNELS] {
        sense(&world(), 200.0, 600.0 - RADIUS - gap, FRAC_PI_2)
    }

    #[test]
    fn proximity_readings_by_distance() {
        let front = |gap: f32| {
            let p = facing_north(gap);
            [p[CH_IR + 2], p[CH_IR + 3]]
        };
        assert!(front(12.0).iter().all(|&v| v >= 0.98), "about 1 from 12 mm: {:?}", front(12.0));
        assert!(front(18.0).iter().all(|&v| (0.5..=0.95).contains(&v)), "{:?}", front(18.0));
        assert!(front(30.0).iter().all(|&v| v < 0.07), "{:?}", front(30.0));
        assert!(front(40.0).iter().all(|&v| v < 0.01), "{:?}", front(40.0));
    }

    #[test]
    fn another_robot_ahead() {
        use shaping_runtime::sim::Team;
        let mut w = world();
        w.robots = 2;
        let front = |gap: f32| {
            let mut team = Team::new(&w, 1);
            assert!(team.place(1, Pose { x: 40.0, y: 40.0, theta: 0.0 }));
            assert!(team.place(0, Pose { x: 150.0, y: 300.0, theta: 0.0 }));
            assert!(team.place(1, Pose { x: 150.0 + 2.0 * RADIUS + gap, y: 300.0, theta: 0.0 }));
            team.begin_action();
            team.prepare(0);
            let mut p = [0.0; CHANNELS];
            team.sense(0, &mut p);
            [p[CH_IR + 2], p[CH_IR + 3]]
        };
        assert!(front(10.0).iter().all(|&v| v > 0.9), "{:?}", front(10.0));
        assert!(front(18.0).iter().all(|&v| (0.1..=0.5).contains(&v)), "{:?}", front(18.0));
        assert!(front(30.0).iter().all(|&v| v < 0.01), "{:?}", front(30.0));
        assert!(front(40.0).iter().all(|&v| v == 0.0), "{:?}", front(40.0));
    }

    #[test]
    fn sensor_layout() {
        let w = world();
        let near = 5.0 + RADIUS;
        let strongest = |p: [f32; CHANNELS]| (0..8).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap();
        // heading north: the west wall on the left, the east wall on the right
        assert_eq!(strongest(sense(&w, near, 300.0, FRAC_PI_2)), 0, "ir[0] is on the left");
        assert_eq!(strongest(sense(&w, 400.0 - near, 300.0, FRAC_PI_2)), 5, "ir[5] on the right");
        // heading south: the north wall behind
        let back = sense(&w, 200.0, 600.0 - near, -FRAC_PI_2);
        assert!(back[CH_IR + 6] > 0.5 && back[CH_IR + 7] > 0.5, "ir[6..7] at the back: {back:?}");
        assert!(back[CH_IR..CH_IR + 6].iter().all(|&v| v < 0.01), "{back:?}");
        // the back pair reaches farther
        let behind = |gap: f32| {
            let p = sense(&w, 200.0, 600.0 - RADIUS - gap, -FRAC_PI_2);
            p[CH_IR + 6].max(p[CH_IR + 7])
        };
        assert!(behind(43.0) > 0.01 && behind(60.0) < 0.01, "{} {}", behind(43.0), behind(60.0));
        let ahead = facing_north(5.0);
        assert!(ahead[CH_IR + 2] > 0.99 && ahead[CH_IR + 3] > 0.99, "ir[2..3] ahead: {ahead:?}");
    }

    #[test]
    fn light_readings_by_distance() {
        let facing = |d: f32| sense(&world(), 200.0, 600.0 - d, FRAC_PI_2)[CH_LIGHT + 2];
        assert!(facing(100.0) >= 0.99 && facing(60.0) >= 0.99, "1 from 100 mm");
        assert!((facing(150.0) - 0.7).abs() < 0.05, "{}", facing(150.0));
        assert!((facing(300.0) - 0.3).abs() < 0.05, "{}", facing(300.0));
        // facing away: 0
        let away = sense(&world(), 200.0, 400.0, -FRAC_PI_2);
        assert!(away[CH_LIGHT..CH_LIGHT + 6].iter().all(|&v| v == 0.0), "{away:?}");
        let dark = World { charger: None, ..world() };
        assert!(sense(&dark, 200.0, 400.0, FRAC_PI_2)[CH_LIGHT..CH_LIGHT + 8].iter().all(|&v| v == 0.0));
    }

    #[test]
    fn charging_needs_3_mm_and_the_request() {
        let charge_after = |gap: f32, charge: bool| {
            let mut s = Sim::new(&world(), 1);
            assert!(s.set_pose(Pose { x: 200.0, y: 600.0 - RADIUS - gap, theta: FRAC_PI_2 }));
            for _ in 0..10 {
                s.step(&Command::default());
            }
            let before = s.battery();
            assert!((before - (1.0 - 10.0 / 200.0)).abs() < 1e-6, "1/200 per action: {before}");
            s.step(&Command { charge, ..Command::default() });
            s.battery() - before
        };
        assert!((charge_after(3.0, true) - 1.0 / 20.0).abs() < 1e-6, "1/20 per action within 3 mm");
        assert!(charge_after(4.0, true) < 0.0, "4 mm is too far");
        assert!(charge_after(0.5, false) < 0.0, "no charge without `uses charger`");
        let mut out = [0.0; CHANNELS];
        Sim::new(&world(), 3).sense(&mut out);
        assert_eq!(out[CH_BATTERY], 1.0, "a life starts with a full battery");
    }

    #[test]
    fn an_empty_battery_ends_the_life() {
        use shaping_runtime::controller::{run_episode, EpisodeOptions};
        let src = "robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }
stage s {
  world { battery 50 actions }
  fitness per action 1
  module m { sense ir  behavior forward }
}
";
        let p = shaping_compiler::compile(src, "battery.bat").unwrap();
        // The one module drives whatever its genes.
        let genome = shaping_runtime::genome::Genome { bits: vec![0; p.stages[0].layout.bits as usize] };
        let r = run_episode(
            &p.stages[0],
            &genome,
            &EpisodeOptions { actions: 300, learning: false, seed: 1 },
            None,
        );
        assert_eq!(r.actions, 50);
        assert_eq!(r.fitness, 50.0);
    }

    #[test]
    fn start_pose_keeps_40_mm_from_the_walls() {
        let w = world();
        for seed in 0..500 {
            let p = Sim::new(&w, seed).pose();
            let clearance =
                [p.x, 400.0 - p.x, p.y, 600.0 - p.y].into_iter().fold(f32::MAX, f32::min) - RADIUS;
            assert!(clearance >= 40.0, "seed {seed}: {clearance}");
        }
    }

    #[test]
    fn the_catch_zone_and_the_barrier() {
        // An object centre `ahead` mm beyond the body surface and `side` mm
        // to the left; the arm goes down, then the claw closes.
        let grip = |ahead: f32, side: f32| {
            let w = World { objects: Some(Objects { count: 1, diameter: 10.0, virtual_: true }), ..world() };
            let mut s = Sim::new(&w, 1);
            assert!(s.set_pose(Pose { x: 200.0, y: 300.0, theta: FRAC_PI_2 }));
            assert!(s.set_object(0, 200.0 - side, 300.0 + RADIUS + ahead));
            s.step(&Command { arm: Some(true), ..Command::default() });
            let mut out = [0.0; CHANNELS];
            s.sense(&mut out);
            let barrier = out[CH_BARRIER];
            let grips = s.step(&Command { claw: Some(true), ..Command::default() }).grips;
            (barrier, grips)
        };
        assert_eq!(grip(5.0, 0.0), (1.0, 1));
        assert_eq!(grip(30.0, 15.0), (1.0, 1));
        assert_eq!(grip(31.0, 0.0), (0.0, 0));
        assert_eq!(grip(4.0, 0.0), (0.0, 0));
        assert_eq!(grip(20.0, 16.0), (0.0, 0));
    }
}
