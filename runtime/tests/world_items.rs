//! The world's declared items in the simulator: inner walls, cylinders,
//! lamps, floor zones (the ground sensor, charging zones) and the start pose.

use shaping_runtime::catalog::{CHANNELS, CH_FLOOR, CH_IR, CH_LIGHT};
use shaping_runtime::program::{Battery, Body, Cylinder, InnerWall, Items, Lamp, Start, World, Zone};
use shaping_runtime::sim::{Command, Pose, Sim};
use shaping_runtime::world::{blocker, Blocker};

fn world(items: Items) -> World {
    World {
        arena: [400.0, 600.0],
        body: Body { wheel_noise: 0.0, sensor_noise: 0.0, ..Body::default() },
        charger: None,
        battery: None,
        objects: None,
        items,
        robots: 1,
    }
}

fn percept(sim: &mut Sim) -> [f32; CHANNELS] {
    let mut p = [0.0; CHANNELS];
    sim.sense(&mut p);
    p
}

fn forward() -> Command {
    Command { wheels: [1.0, 1.0], ..Command::default() }
}

fn wall_across(y: f32) -> Items {
    Items { walls: vec![InnerWall { name: None, from: [0.0, y], to: [400.0, y] }], ..Items::default() }
}

#[test]
fn an_inner_wall_blocks_the_body_and_is_seen_by_the_front_sensors() {
    let mut sim = Sim::new(&world(wall_across(300.0)), 1);
    // Facing north, 17.5 mm from the wall: front sensors read it, back do not.
    assert!(sim.set_pose(Pose { x: 200.0, y: 255.0, theta: std::f32::consts::FRAC_PI_2 }));
    let p = percept(&mut sim);
    assert!(p[CH_IR + 2] > 0.3 && p[CH_IR + 3] > 0.3, "{p:?}");
    assert!(p[CH_IR + 6] < 0.01, "{p:?}");
    // Driving on ends against it.
    let mut collided = false;
    for _ in 0..10 {
        collided |= sim.step(&forward()).collided;
    }
    assert!(collided);
    assert!(sim.pose().y <= 300.0 - 27.5 + 1e-3, "{:?}", sim.pose());
    // The body cannot be put across it.
    assert!(!sim.set_pose(Pose { x: 200.0, y: 310.0, theta: 0.0 }));
    // Without the wall the same place reads nothing ahead.
    let mut open = Sim::new(&world(Items::default()), 1);
    assert!(open.set_pose(Pose { x: 200.0, y: 255.0, theta: std::f32::consts::FRAC_PI_2 }));
    assert!(percept(&mut open)[CH_IR + 2] < 0.01);
}

#[test]
fn a_cylinder_blocks_and_reflects() {
    let items = Items {
        cylinders: vec![Cylinder { name: None, at: [200.0, 300.0], diameter: 50.0 }],
        ..Items::default()
    };
    let mut sim = Sim::new(&world(items.clone()), 1);
    assert!(!sim.set_pose(Pose { x: 200.0, y: 260.0, theta: 0.0 }));
    assert!(sim.set_pose(Pose { x: 200.0, y: 240.0, theta: std::f32::consts::FRAC_PI_2 }));
    let p = percept(&mut sim);
    assert!(p[CH_IR + 2] > 0.05, "{p:?}");
    assert_eq!(blocker(&items, [200.0, 260.0], 27.5), Some(Blocker::Cylinder(0)));
    assert_eq!(blocker(&items, [200.0, 200.0], 27.5), None);
}

#[test]
fn lamps_add_up_and_scale_with_intensity() {
    let lamp =
        |intensity: f32| Lamp { name: None, at: [200.0, 500.0], height: 150.0, intensity, switch: None };
    let read = |lamps: Vec<Lamp>| {
        let mut sim = Sim::new(&world(Items { lamps, ..Items::default() }), 1);
        assert!(sim.set_pose(Pose { x: 200.0, y: 100.0, theta: std::f32::consts::FRAC_PI_2 }));
        percept(&mut sim)[CH_LIGHT + 2]
    };
    let one = read(vec![lamp(1.0)]);
    assert!(one > 0.0 && one < 0.5, "{one}");
    assert!((read(vec![lamp(2.0)]) - 2.0 * one).abs() < 1e-5);
    assert!((read(vec![lamp(1.0), lamp(1.0)]) - 2.0 * one).abs() < 1e-5);
    assert_eq!(read(vec![]), 0.0);
}

#[test]
fn walls_and_cylinders_between_a_lamp_and_a_sensor_shade_it() {
    let lamp = Lamp { name: None, at: [200.0, 500.0], height: 150.0, intensity: 1.0, switch: None };
    let north = std::f32::consts::FRAC_PI_2;
    let read = |items: Items, x: f32| {
        let mut sim = Sim::new(&world(Items { lamps: vec![lamp.clone()], ..items }), 1);
        assert!(sim.set_pose(Pose { x, y: 100.0, theta: north }));
        let p = percept(&mut sim);
        [p[CH_LIGHT + 2], p[CH_LIGHT + 3]]
    };
    let open = read(Items::default(), 200.0);
    assert!(open[0] > 0.05 && open[1] > 0.05, "{open:?}");
    // A wall across the arena between the robot and the lamp: dark.
    assert_eq!(read(wall_across(300.0), 200.0), [0.0, 0.0]);
    // A wall beside the line does not shade.
    let aside = Items {
        walls: vec![InnerWall { name: None, from: [300.0, 250.0], to: [390.0, 250.0] }],
        ..Items::default()
    };
    assert_eq!(read(aside, 200.0), open);
    // A cylinder on the line shades; beside it, it does not.
    let cylinder = |x: f32| Items {
        cylinders: vec![Cylinder { name: None, at: [x, 300.0], diameter: 60.0 }],
        ..Items::default()
    };
    assert_eq!(read(cylinder(200.0), 200.0), [0.0, 0.0]);
    assert_eq!(read(cylinder(350.0), 200.0), open);
    // A lamp of intensity 0 is off.
    let mut sim = Sim::new(
        &world(Items { lamps: vec![Lamp { intensity: 0.0, ..lamp.clone() }], ..Items::default() }),
        1,
    );
    assert!(sim.set_pose(Pose { x: 200.0, y: 100.0, theta: north }));
    assert!(percept(&mut sim)[CH_LIGHT..CH_LIGHT + 8].iter().all(|&v| v == 0.0));
}

#[test]
fn the_ground_sensor_reads_the_zone_under_the_body_and_a_charging_zone_refills() {
    let items = Items {
        zones: vec![
            Zone { name: None, from: [0.0, 0.0], to: [100.0, 100.0], grey: 0.5, charger: false },
            Zone { name: None, from: [300.0, 500.0], to: [400.0, 600.0], grey: 0.0, charger: true },
        ],
        ..Items::default()
    };
    let w = World { battery: Some(Battery { capacity: 10, recharge: 2 }), ..world(items) };
    let mut sim = Sim::new(&w, 1);
    assert!(sim.set_pose(Pose { x: 200.0, y: 300.0, theta: 0.0 }));
    assert_eq!(percept(&mut sim)[CH_FLOOR], 1.0);
    assert!(sim.set_pose(Pose { x: 50.0, y: 50.0, theta: 0.0 }));
    assert_eq!(percept(&mut sim)[CH_FLOOR], 0.5);
    // Drain eight actions standing still, then on the charging zone: two
    // actions (half a battery each) refill it, without a charge command.
    for _ in 0..8 {
        sim.step(&Command::default());
    }
    assert!((sim.battery() - 0.2).abs() < 1e-6);
    assert!(sim.set_pose(Pose { x: 350.0, y: 550.0, theta: 0.0 }));
    assert_eq!(percept(&mut sim)[CH_FLOOR], 0.0);
    assert!(!sim.step(&Command::default()).recharged);
    assert!((sim.battery() - 0.7).abs() < 1e-6);
    assert!(sim.step(&Command::default()).recharged);
    assert_eq!(sim.battery(), 1.0);
}

#[test]
fn the_start_pose_is_fixed_or_drawn_in_its_region() {
    let fixed = Items {
        start: Some(Start { from: [100.0, 150.0], to: [100.0, 150.0], heading: Some(1.0) }),
        ..Items::default()
    };
    for seed in 0..5 {
        let p = Sim::new(&world(fixed.clone()), seed).pose();
        assert_eq!((p.x, p.y), (100.0, 150.0));
        assert!((p.theta - 1.0).abs() < 1e-6);
    }
    let region = Items {
        start: Some(Start { from: [50.0, 400.0], to: [350.0, 550.0], heading: None }),
        ..wall_across(470.0)
    };
    let mut headings = Vec::new();
    for seed in 0..30 {
        let p = Sim::new(&world(region.clone()), seed).pose();
        assert!((50.0..=350.0).contains(&p.x) && (400.0..=550.0).contains(&p.y), "{p:?}");
        assert!((p.y - 470.0).abs() >= 27.5, "{p:?} overlaps the wall");
        headings.push(p.theta);
    }
    assert!(headings.iter().any(|&h| (h - headings[0]).abs() > 0.1));
}

#[test]
fn the_validation_refuses_items_outside_the_arena_and_a_start_where_the_body_does_not_fit() {
    use shaping_runtime::testkit;
    let check = |items: Items| {
        let mut s = testkit::navigation();
        s.world.items = items;
        shaping_runtime::validate::stage(&s).err().map(|e| e.to_string())
    };
    assert_eq!(check(wall_across(300.0)), None);
    let e = check(wall_across(700.0)).unwrap();
    assert!(e.contains("`world.items.walls[0]`") && e.contains("not inside the arena"), "{e}");
    let zone = |from, to| Items {
        zones: vec![Zone { name: None, from, to, grey: 0.0, charger: false }],
        ..Items::default()
    };
    assert_eq!(check(zone([0.0, 0.0], [50.0, 50.0])), None);
    let e = check(zone([500.0, 0.0], [600.0, 50.0])).unwrap();
    assert!(e.contains("does not overlap the arena"), "{e}");
    let start =
        |at: [f32; 2]| Items { start: Some(Start { from: at, to: at, heading: None }), ..Items::default() };
    assert_eq!(check(start([100.0, 100.0])), None);
    let e = check(start([10.0, 100.0])).unwrap();
    assert!(e.contains("`world.items.start`"), "{e}");
}

#[test]
fn the_lamp_distance_channel_reads_metres_to_the_nearest_lamp() {
    use shaping_runtime::catalog::CH_LAMP_DISTANCE;
    let lamp = |at| Lamp { name: None, at, height: 150.0, intensity: 1.0, switch: None };
    let items = Items { lamps: vec![lamp([200.0, 500.0]), lamp([200.0, 0.0])], ..Items::default() };
    let mut sim = Sim::new(&world(items), 1);
    assert!(sim.set_pose(Pose { x: 200.0, y: 350.0, theta: 0.0 }));
    assert!((percept(&mut sim)[CH_LAMP_DISTANCE] - 0.15).abs() < 1e-6);
    let mut dark = Sim::new(&world(Items::default()), 1);
    assert_eq!(percept(&mut dark)[CH_LAMP_DISTANCE], 1.0);
}

/// Worlds whose objects or robot can never be placed, whatever the seed
/// (the simulator would keep its last try, overlapping): `crowded` says
/// why, and the validation refuses them. A world that only may be crowded
/// is not refused.
#[test]
fn worlds_that_can_never_be_placed_are_refused() {
    use shaping_runtime::program::Objects;
    use shaping_runtime::testkit;
    use shaping_runtime::world::{crowded, Crowded};
    let objects = |count, diameter| Some(Objects { count, diameter, virtual_: false });
    let cylinder =
        |at, diameter| Items { cylinders: vec![Cylinder { name: None, at, diameter }], ..Items::default() };
    assert_eq!(crowded(&world(Items::default())), None);

    let huge = world(cylinder([200.0, 300.0], 100_000.0));
    assert_eq!(crowded(&huge), Some(Crowded::StartCovered(Blocker::Cylinder(0))));
    // A large cylinder that leaves the corners free is no certain failure.
    assert_eq!(crowded(&world(cylinder([200.0, 300.0], 400.0))), None);

    let mut many = world(Items::default());
    many.objects = objects(100, 60.0);
    assert!(matches!(crowded(&many), Some(Crowded::Objects { .. })), "{:?}", crowded(&many));
    let mut small = world(Items::default());
    small.arena = [120.0, 120.0];
    small.objects = objects(50, 30.0);
    assert!(matches!(crowded(&small), Some(Crowded::Objects { .. })));
    // Crowded for random placement, perhaps, but not certainly impossible.
    let mut dense = world(Items::default());
    dense.objects = objects(40, 60.0);
    assert_eq!(crowded(&dense), None);
    // The paper's worlds: 8 objects of 10 or 25 mm.
    for d in [10.0, 25.0] {
        let mut paper = world(Items::default());
        paper.objects = objects(8, d);
        assert_eq!(crowded(&paper), None);
    }

    let mut covered = world(cylinder([200.0, 300.0], 700.0));
    covered.objects = objects(3, 20.0);
    assert_eq!(crowded(&covered), Some(Crowded::ObjectsCovered(Blocker::Cylinder(0))));

    let check = |w: World| {
        let mut s = testkit::navigation();
        s.world = w;
        shaping_runtime::validate::stage(&s).err().map(|e| e.to_string())
    };
    let e = check(huge).unwrap();
    assert!(e.contains("`world.items`: cylinder 0 covers every place the robot can start"), "{e}");
    let e = check(many).unwrap();
    assert!(e.contains("`world.objects`: the objects do not fit in the arena"), "{e}");
    assert_eq!(check(dense), None);
}

#[test]
fn a_lamp_switches_after_the_declared_action() {
    use shaping_runtime::program::LampSwitch;
    let north = std::f32::consts::FRAC_PI_2;
    let still = Command::default();
    // Light seen by a front sensor before each of the first 6 actions.
    let readings = |switch: LampSwitch| -> Vec<f32> {
        let lamp =
            Lamp { name: None, at: [200.0, 500.0], height: 150.0, intensity: 1.0, switch: Some(switch) };
        let mut sim = Sim::new(&world(Items { lamps: vec![lamp], ..Items::default() }), 1);
        assert!(sim.set_pose(Pose { x: 200.0, y: 100.0, theta: north }));
        let mut out = vec![percept(&mut sim)[CH_LIGHT + 2]];
        for _ in 0..5 {
            sim.step(&still);
            out.push(percept(&mut sim)[CH_LIGHT + 2]);
        }
        out
    };
    let off = readings(LampSwitch { on: false, at: 3 });
    let lit = off[0];
    assert!(lit > 0.05, "{off:?}");
    // Lit before actions 1 to 3, dark after the third.
    assert_eq!(off, vec![lit, lit, lit, 0.0, 0.0, 0.0]);
    let on = readings(LampSwitch { on: true, at: 2 });
    assert_eq!(on, vec![0.0, 0.0, lit, lit, lit, lit]);
    // A lamp that switches on is drawn dark until then.
    let lamp = Lamp {
        name: None,
        at: [200.0, 500.0],
        height: 150.0,
        intensity: 1.0,
        switch: Some(LampSwitch { on: true, at: 1 }),
    };
    let mut sim = Sim::new(&world(Items { lamps: vec![lamp], ..Items::default() }), 1);
    assert_eq!(sim.scene().dark_lamps, vec![0]);
    sim.step(&still);
    assert!(sim.scene().dark_lamps.is_empty());
}

#[test]
fn a_placement_puts_the_robot_after_the_declared_action() {
    use shaping_runtime::program::Placement;
    let north = std::f32::consts::FRAC_PI_2;
    let place = Placement { name: None, at: [300.0, 400.0], heading: 0.0, after: 3 };
    let mut sim = Sim::new(&world(Items { places: vec![place], ..Items::default() }), 1);
    assert!(sim.set_pose(Pose { x: 100.0, y: 100.0, theta: north }));
    for _ in 0..2 {
        sim.step(&forward());
    }
    let before = sim.pose();
    assert!(before.y > 100.0 && before.x == 100.0, "{before:?}");
    sim.step(&forward());
    // After the third action: at the place, facing east, whatever it did.
    assert_eq!(sim.pose(), Pose { x: 300.0, y: 400.0, theta: 0.0 });
    assert_eq!(sim.placement_failures(), 0);
    sim.step(&forward());
    let after = sim.pose();
    assert!(after.x > 300.0 && (after.y - 400.0).abs() < 1e-3, "{after:?}");
}

#[test]
fn validation_refuses_a_placement_outside_in_a_wall_or_for_a_team() {
    use shaping_runtime::program::Placement;
    let check = |items: Items, robots: u32| {
        let mut s = shaping_runtime::testkit::navigation();
        s.world = World { robots, ..world(items) };
        shaping_runtime::validate::stage(&s).err().map(|e| e.to_string())
    };
    let at = |x: f32, y: f32| Items {
        walls: vec![InnerWall { name: None, from: [200.0, 0.0], to: [200.0, 300.0] }],
        places: vec![Placement { name: None, at: [x, y], heading: 0.0, after: 5 }],
        ..Items::default()
    };
    assert_eq!(check(at(300.0, 100.0), 1), None);
    let e = check(at(390.0, 100.0), 1).unwrap();
    assert!(e.contains("outside the arena"), "{e}");
    let e = check(at(210.0, 100.0), 1).unwrap();
    assert!(e.contains("inside inner wall 0"), "{e}");
    let e = check(at(300.0, 100.0), 2).unwrap();
    assert!(e.contains("on top of each other"), "{e}");
}

/// The per-sensor code gives the same bits on the AVX2 path (where the CPU
/// has it) as on the portable one: percepts and poses of whole lives in a
/// world with every kind of surface and light (inner walls, cylinders,
/// physical and virtual objects, the charger's lamp and declared ones,
/// shading), with noise, driven by a rule that reads the percepts.
#[test]
fn both_lanes_paths_give_the_same_lives() {
    use shaping_runtime::program::{Charger, Objects, Wall};
    println!("AVX2 path in use: {}", shaping_runtime::sim::simd::avx2_in_use());
    let items = Items {
        walls: vec![InnerWall { name: None, from: [100.0, 200.0], to: [300.0, 260.0] }],
        cylinders: vec![
            Cylinder { name: None, at: [300.0, 450.0], diameter: 50.0 },
            Cylinder { name: None, at: [90.0, 420.0], diameter: 30.0 },
        ],
        lamps: vec![
            Lamp { name: None, at: [50.0, 550.0], height: 80.0, intensity: 0.7, switch: None },
            Lamp { name: None, at: [380.0, 100.0], height: 0.0, intensity: 1.0, switch: None },
        ],
        ..Items::default()
    };
    let (mut seen_ir, mut seen_light) = (0, 0);
    for virtual_ in [false, true] {
        let mut w = world(items.clone());
        w.body.sensor_noise = 0.05;
        w.body.wheel_noise = 0.1;
        w.charger = Some(Charger { wall: Wall::North, length: 150.0, lamp_height: Some(120.0) });
        w.objects = Some(Objects { count: 10, diameter: 25.0, virtual_ });
        for seed in 0..20u64 {
            let (mut best, mut portable) = (Sim::new(&w, seed), Sim::new(&w, seed));
            portable.force_portable_lanes();
            for step in 0..400 {
                let (a, b) = (percept(&mut best), percept(&mut portable));
                assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "seed {seed} step {step}: {a:?} {b:?}");
                let near = a[CH_IR + 1..CH_IR + 5].iter().any(|&v| v > 0.3);
                seen_ir += u32::from(near);
                seen_light += u32::from(a[CH_LIGHT..CH_LIGHT + 8].iter().any(|&v| v > 0.1 && v < 0.9));
                let bright = a[CH_LIGHT..CH_LIGHT + 8].iter().any(|&v| v > 0.5);
                let wheels = match (near, bright) {
                    (true, _) => [-0.3, -1.0],
                    (false, true) => [0.4, 1.0],
                    _ => [1.0, 0.9],
                };
                let cmd = Command { wheels, ..Command::default() };
                assert_eq!(best.step(&cmd), portable.step(&cmd));
                assert_eq!(best.pose(), portable.pose(), "seed {seed} step {step}");
            }
        }
    }
    // The lives saw surfaces and lamps, not an empty arena.
    assert!(seen_ir > 1000 && seen_light > 1000, "{seen_ir} {seen_light}");
}
