//! Bodies: what the compiler makes of presets, single values changed and
//! declared sensor layouts (`tests/lower/bodies.bat`), as the program the
//! runtime gets.

use shaping_runtime::bodies;
use shaping_runtime::program::{Body, SensorSpot};

use crate::compile_ok;

fn program() -> shaping_compiler::Program {
    let path = crate::root().join("tests/lower/bodies.bat");
    compile_ok(&std::fs::read_to_string(path).unwrap(), "bodies.bat")
}

fn body<'a>(p: &'a shaping_compiler::Program, stage: &str) -> &'a Body {
    &p.stages.iter().find(|s| s.name == stage).unwrap().world.body
}

/// Each stage's body as the serialized program has it.
#[test]
fn bodies_as_compiled() {
    let p = program();
    let bodies: Vec<(String, &Body)> = p.stages.iter().map(|s| (s.name.clone(), &s.world.body)).collect();
    insta::assert_snapshot!(serde_json::to_string_pretty(&bodies).unwrap());
}

#[test]
fn a_preset_then_single_values() {
    let p = program();
    let puck = body(&p, "puck");
    let e = bodies::preset("e-puck").unwrap();
    // everything of the preset but the two values written
    assert_eq!(*puck, Body { v_max: 100.0, wheel_noise: 0.0, ..e.clone() });
    // `body khepera { ... }` in a later stage starts from the Khepera again
    let back = body(&p, "back");
    assert_eq!(*back, Body { ground: vec![[10.0, 5.0], [10.0, 0.0], [10.0, -5.0]], ..Body::default() });
}

#[test]
fn declared_layouts() {
    let p = program();
    let placed = body(&p, "placed");
    assert_eq!(placed.radius, 30.0);
    let ir = placed.ir.as_ref().unwrap();
    assert_eq!(ir.at[0], SensorSpot::Rim(90.0));
    assert_eq!(ir.at[2], SensorSpot::Point([25.0, 5.0]));
    assert_eq!(ir.facing, [90.0, 45.0, 10.0, -10.0, -45.0, -90.0, -170.0, 170.0]);
    assert_eq!(placed.ground, vec![[20.0, 8.0], [20.0, 0.0], [20.0, -8.0]]);
    // `facing` alone: the sensors sit on the rim where they look, and the
    // rest of the e-puck (its ground sensors) is kept
    let bearings = body(&p, "bearings");
    let ir = bearings.ir.as_ref().unwrap();
    assert_eq!(ir.at[1], SensorSpot::Rim(40.0));
    assert_eq!(ir.facing[1], 40.0);
    assert_eq!(bearings.ground, bodies::preset("e-puck").unwrap().ground);
    for s in &p.stages {
        assert_eq!(p.validate(), Ok(()), "{}", s.name);
    }
}

/// A file without a body is the Khepera, exactly as before presets: no
/// preset, layout or ground places in its program.
#[test]
fn the_default_body_is_the_khepera() {
    let path = crate::root().join("examples/khepera.bat");
    let p = compile_ok(&std::fs::read_to_string(path).unwrap(), "khepera.bat");
    for s in &p.stages {
        assert_eq!(s.world.body, bodies::preset("khepera").unwrap(), "{}", s.name);
        let json = serde_json::to_string(&s.world.body).unwrap();
        assert!(!json.contains("preset") && !json.contains("\"ir\"") && !json.contains("ground"), "{json}");
    }
}

/// An angle is in degrees when bare or with `deg`, in radians with `rad`:
/// a start's heading and a layout's bearings alike.
#[test]
fn angles_in_degrees_or_radians() {
    let heading = |h: &str| {
        let src = format!(
            "robot r {{ sensor ir[8] proximity  actuator wheels[2] speed }}
stage s {{
  world {{ start at (200mm, 300mm) heading {h}  body {{ proximity facing [0, -45, -90, -150, 150, 90, 45, 0.5rad] }} }}
  fitness per action wheels[0]
  module m {{ sense ir  behavior forward }}
}}
"
        );
        let p = compile_ok(&src, "angles.bat");
        let w = &p.stages[0].world;
        let facing = w.body.ir.as_ref().expect("a layout").facing[7];
        (w.items.start.as_ref().unwrap().heading.unwrap(), facing)
    };
    let right = std::f32::consts::FRAC_PI_2;
    for h in ["90", "90deg", "90 deg", "1.5707963rad"] {
        let (got, facing) = heading(h);
        assert!((got - right).abs() < 1e-6, "{h}: {got}");
        assert!((facing - 0.5f32.to_degrees()).abs() < 1e-4, "{facing}");
    }
}
