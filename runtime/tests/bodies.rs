//! Bodies and sensor layouts in the simulator: declared IR bearings and
//! places change the readings as the geometry says, several ground sensors
//! read the floor under each, and the default body reads as it always did.

use std::f32::consts::FRAC_PI_2;

use shaping_runtime::bodies;
use shaping_runtime::catalog::{CHANNELS, CH_FLOOR, CH_IR, CH_LIGHT, GROUND_SENSORS};
use shaping_runtime::program::{Body, IrLayout, Items, Lamp, SensorSpot, World, Zone};
use shaping_runtime::sim::ir::KHEPERA;
use shaping_runtime::sim::{Pose, Sim};

fn world(body: Body, items: Items) -> World {
    World {
        arena: [400.0, 600.0],
        body: Body { wheel_noise: 0.0, sensor_noise: 0.0, ..body },
        charger: None,
        battery: None,
        objects: None,
        items,
        robots: 1,
    }
}

fn percept(w: &World, pose: Pose) -> [f32; CHANNELS] {
    let mut sim = Sim::new(w, 1);
    assert!(sim.set_pose(pose), "{pose:?}");
    let mut p = [0.0; CHANNELS];
    sim.sense(&mut p);
    p
}

/// The fitted Khepera geometry, written as a declared layout.
fn khepera_layout() -> IrLayout {
    IrLayout { at: KHEPERA.position_deg.map(SensorSpot::Rim), facing: KHEPERA.axis_deg }
}

/// Facing north with the west wall `gap` mm from the body's left side.
fn by_the_west_wall(gap: f32) -> Pose {
    Pose { x: 27.5 + gap, y: 300.0, theta: FRAC_PI_2 }
}

#[test]
fn the_fitted_geometry_declared_reads_exactly_as_the_default() {
    let declared = Body { ir: Some(khepera_layout()), ..Body::default() };
    let lamp = Lamp { name: None, at: [300.0, 500.0], height: 100.0, intensity: 1.0, switch: None };
    let items = Items { lamps: vec![lamp], ..Items::default() };
    for gap in [3.0, 10.0, 20.0, 35.0] {
        for theta in [0.3, FRAC_PI_2, 2.0, -2.5] {
            let pose = Pose { theta, ..by_the_west_wall(gap) };
            let a = percept(&world(Body::default(), items.clone()), pose);
            let b = percept(&world(declared.clone(), items.clone()), pose);
            assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "gap {gap}, heading {theta}");
        }
    }
}

#[test]
fn a_sensor_turned_to_face_a_wall_reads_more() {
    // Sensor 0 on the rim at the left (90 degrees), the wall 12 mm to the
    // left: the more its axis turns from ahead (0) toward the wall's normal
    // (90), the more it reads; past the normal, less again.
    let read = |facing0: f32| {
        let mut layout = khepera_layout();
        layout.at[0] = SensorSpot::Rim(90.0);
        layout.facing[0] = facing0;
        let w = world(Body { ir: Some(layout), ..Body::default() }, Items::default());
        percept(&w, by_the_west_wall(12.0))[CH_IR]
    };
    let readings: Vec<f32> = [0.0, 30.0, 60.0, 90.0].iter().map(|&f| read(f)).collect();
    assert!(readings.windows(2).all(|w| w[0] < w[1]), "{readings:?}");
    assert!(read(150.0) < read(90.0));
    // As the model says: the lobe `focus * (cos(a) - 1)` of the fitted
    // sensor 0, at the sensor's distance from the wall.
    let model = |facing: f32| {
        let r = &KHEPERA.wall;
        let z = (r.reach[0] - 12.0) / r.decay[0] + r.focus[0] * (facing.to_radians().cos() - 1.0);
        shaping_runtime::sim::ir::saturate(z, r.knee)
    };
    for (facing, got) in [0.0, 30.0, 60.0, 90.0].iter().zip(&readings) {
        let want = model(90.0 - facing);
        assert!((got - want).abs() < 0.01, "facing {facing}: {got} against {want}");
    }
}

#[test]
fn a_sensor_placed_inside_the_body_reads_less_than_one_on_the_rim() {
    let read = |spot: SensorSpot| {
        let mut layout = khepera_layout();
        layout.at[0] = spot;
        layout.facing[0] = 90.0;
        let w = world(Body { ir: Some(layout), ..Body::default() }, Items::default());
        percept(&w, by_the_west_wall(15.0))[CH_IR]
    };
    let rim = read(SensorSpot::Rim(90.0));
    let inside = read(SensorSpot::Point([0.0, 20.0]));
    assert!(rim > inside && inside > 0.0, "rim {rim}, 7.5 mm further in {inside}");
}

#[test]
fn light_follows_the_declared_bearings() {
    // A lamp due west: the sensor turned to face west reads it, the same
    // sensor facing east does not.
    let lamp = Lamp { name: None, at: [0.0, 300.0], height: 50.0, intensity: 1.0, switch: None };
    let items = Items { lamps: vec![lamp], ..Items::default() };
    let read = |facing0: f32| {
        let mut layout = khepera_layout();
        layout.facing[0] = facing0;
        let w = world(Body { ir: Some(layout), ..Body::default() }, items.clone());
        percept(&w, Pose { x: 100.0, y: 300.0, theta: FRAC_PI_2 })[CH_LIGHT]
    };
    assert!(read(90.0) > 0.3 && read(-90.0) == 0.0, "{} {}", read(90.0), read(-90.0));
}

#[test]
fn ground_sensors_straddling_a_zone_edge_read_different_zones() {
    // A black strip west of x = 200; the robot on its edge, facing north:
    // the sensor 10 mm to its left is over the strip, the one 10 mm to its
    // right over the white floor, the one ahead on the edge's line (black:
    // the zone includes its border).
    let zone = Zone { name: None, from: [0.0, 0.0], to: [200.0, 600.0], grey: 0.0, charger: false };
    let items = Items { zones: vec![zone], ..Items::default() };
    let ground = vec![[0.0, 10.0], [0.0, -10.0], [20.0, 0.0]];
    let w = world(Body { ground, ..Body::default() }, items.clone());
    let p = percept(&w, Pose { x: 200.0, y: 300.0, theta: FRAC_PI_2 });
    assert_eq!(p[CH_FLOOR..CH_FLOOR + 3], [0.0, 1.0, 0.0]);
    // Turned round, left and right swap.
    let p = percept(&w, Pose { x: 200.0, y: 300.0, theta: -FRAC_PI_2 });
    assert_eq!(p[CH_FLOOR..CH_FLOOR + 2], [1.0, 0.0]);
    // A ground sensor the body does not place sits under the centre: on the
    // edge, black, as the default body's one sensor.
    assert_eq!(p[CH_FLOOR + 3], 0.0);
    let default = percept(&world(Body::default(), items), Pose { x: 210.0, y: 300.0, theta: 0.0 });
    assert_eq!(default[CH_FLOOR..CH_FLOOR + GROUND_SENSORS], [1.0; GROUND_SENSORS]);
}

#[test]
fn the_e_puck_sees_a_wall_ahead_with_ps0_and_ps7() {
    let w = world(bodies::preset("e-puck").unwrap(), Items::default());
    // Facing north, the body surface 10 mm from the north wall.
    let p = percept(&w, Pose { x: 200.0, y: 600.0 - 35.0 - 10.0, theta: FRAC_PI_2 });
    let ir = &p[CH_IR..CH_IR + 8];
    assert!(ir[0] > 0.1 && ir[7] > 0.1, "{ir:?}");
    assert!(ir[0] > 5.0 * ir[2].max(1e-6) && ir[7] > 5.0 * ir[5].max(1e-6), "{ir:?}");
    assert!(ir[3] < 1e-3 && ir[4] < 1e-3, "{ir:?}");
}

#[test]
fn a_robot_link_refuses_a_body_that_is_not_the_kheperas() {
    use shaping_runtime::robot::unfit_for_robot;
    use shaping_runtime::testkit::{arena_world, bare_stage};
    let with = |body: Body| bare_stage("s", World { body, ..arena_world() });
    assert_eq!(unfit_for_robot(&with(Body::default())), None);
    assert_eq!(unfit_for_robot(&with(bodies::preset("khepera").unwrap())), None);
    // calibrations and a virtual floor's ground sensors are the host's: allowed
    let calibrated = Body { radius: 28.0, wheel_base: 52.5, ground: vec![[10.0, 0.0]], ..Body::default() };
    assert_eq!(unfit_for_robot(&with(calibrated)), None);
    let epuck = unfit_for_robot(&with(bodies::preset("e-puck").unwrap())).unwrap();
    assert!(epuck.contains("`e-puck` body"), "{epuck}");
    let declared = unfit_for_robot(&with(Body { ir: Some(khepera_layout()), ..Body::default() })).unwrap();
    assert!(declared.contains("declared sensor layout"), "{declared}");
}
