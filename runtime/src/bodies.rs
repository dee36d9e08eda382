//! Named bodies: `body khepera` (the default) and `body e-puck`.
//!
//! A preset is a whole [`Body`]: radius, wheel base, top speed, action
//! length, noise, and the places of the IR and ground sensors. What a preset
//! does not change is the IR *response* (how a reading falls with the
//! distance and the angle to a surface): every body reads with the response
//! fitted to the Khepera ([`crate::sim::ir::KHEPERA`]). The sources of the
//! e-puck's numbers are in `docs/language.md` (section 18).

use crate::program::{Body, IrLayout, SensorSpot};

/// The names of the presets, for `body NAME` and its diagnostics.
pub const PRESETS: [&str; 2] = ["khepera", "e-puck"];

/// The body of a preset, `None` for an unknown name.
pub fn preset(name: &str) -> Option<Body> {
    match name {
        "khepera" => Some(Body::default()),
        "e-puck" => Some(e_puck()),
        _ => None,
    }
}

/// The e-puck (GCTronic / EPFL), sensors in its own order `ps0..ps7`
/// (clockwise from the front right) and its ground sensors from the left.
fn e_puck() -> Body {
    let p = SensorSpot::Point;
    Body {
        // e-puck.org, "Mechanics of the e-puck": a body of 70 mm diameter,
        // wheels about 53 mm apart, at most about 1000 steps/s, one turn of
        // a wheel of about 41 mm diameter a second (pi * 41 = 128.8 mm/s).
        radius: 35.0,
        wheel_base: 53.0,
        v_max: 128.8,
        preset: Some("e-puck".into()),
        // Webots' E-puck.proto: the sensors' places (mm), and the Webots
        // guide's table of their orientations, turned to bearings from the
        // heading (the guide's angle minus 90 degrees).
        ir: Some(IrLayout {
            at: [
                p([30.0, -10.0]),
                p([22.0, -25.0]),
                p([0.0, -31.0]),
                p([-30.0, -15.0]),
                p([-30.0, 15.0]),
                p([0.0, 31.0]),
                p([22.0, 25.0]),
                p([30.0, 10.0]),
            ],
            facing: [-17.2, -45.9, -90.0, -151.5, 151.2, 90.0, 45.8, 17.1],
        }),
        // The ground-sensor module: three sensors 10 mm apart across the
        // front (Webots' E-puckGroundSensors.proto), at its slot 30 mm ahead
        // of the centre (E-puck.proto).
        ground: vec![[30.0, 10.0], [30.0, 0.0], [30.0, -10.0]],
        ..Body::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_known_and_khepera_is_the_default() {
        for name in PRESETS {
            assert!(preset(name).is_some(), "{name}");
        }
        assert_eq!(preset("khepera"), Some(Body::default()));
        assert_eq!(preset("epuck"), None);
    }

    #[test]
    fn the_e_puck_sensors_lie_inside_its_body_and_look_outward() {
        let b = preset("e-puck").unwrap();
        let ir = b.ir.as_ref().unwrap();
        for (spot, facing) in ir.at.iter().zip(ir.facing) {
            let SensorSpot::Point([x, y]) = *spot else { panic!("{spot:?}") };
            assert!(x.hypot(y) <= b.radius);
            // Each looks within 10 degrees of the direction it sits in.
            let sits = y.atan2(x).to_degrees();
            let off = (facing - sits + 540.0) % 360.0 - 180.0;
            assert!(off.abs() < 10.0, "sits at {sits}, faces {facing}");
        }
        assert!(b.ground.iter().all(|g| g[0].hypot(g[1]) <= b.radius));
    }
}
