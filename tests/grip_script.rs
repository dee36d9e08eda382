//! The grip script of `examples/khepera.bat` catches the objects it is
//! started in front of (`shaping_runtime::oracle::grip_trial`, measured in
//! full by `docs/experiments/grip.rs`): its conditional turns face the
//! object before the arm comes down, and without them objects off the
//! heading are missed.

use shaping_runtime::evolve::train_all;
use shaping_runtime::genome::Genome;
use shaping_runtime::oracle::{grip_trial, module};

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The share of trials rewarded, over objects 0 to 20 mm ahead at the given
/// bearings, 4 episode seeds each, for the collect stage of `source`.
fn caught(source: &str, bearings: &[f32]) -> f64 {
    let mut program = shaping_compiler::compile(source, "khepera.bat").expect("compiles");
    train_all(&mut program, 1).unwrap();
    let stage = program.stages.iter().find(|s| s.name == "collect").unwrap();
    let grip = module(stage, "grip").unwrap();
    let genome = Genome::zeros(stage.layout.bits as usize);
    let (mut ok, mut n) = (0u32, 0u32);
    for &bearing in bearings {
        for gap in [0.0, 10.0, 20.0] {
            for seed in 1..=4 {
                let r = grip_trial(stage, &genome, grip, gap, bearing, seed).unwrap();
                ok += u32::from(r.is_some_and(|r| r > 0.0));
                n += 1;
            }
        }
    }
    f64::from(ok) / f64::from(n)
}

#[test]
fn the_grip_script_faces_the_object_and_catches_it() {
    let source = std::fs::read_to_string(root().join("examples/khepera.bat")).unwrap();
    // The same file without the four conditional turns of the grip and
    // release scripts (the scripts before they faced the object).
    let turns = |l: &&str| l.trim_start().starts_with("turn ") && l.contains(") if ir[");
    assert_eq!(source.lines().filter(turns).count(), 8, "four turns in each of grip and release");
    let without: String = source.lines().filter(|l| !turns(l)).map(|l| format!("{l}\n")).collect();
    let ahead = [-40.0, -20.0, 0.0, 20.0, 40.0];
    let aside = [-60.0, 60.0];
    let (facing, straight) = (caught(&source, &ahead), caught(&without, &ahead));
    let (facing_aside, straight_aside) = (caught(&source, &aside), caught(&without, &aside));
    println!("within 40 degrees: {facing:.2} with the turns, {straight:.2} without");
    println!("at 60 degrees: {facing_aside:.2} with the turns, {straight_aside:.2} without");
    assert!(facing >= 0.95, "the script catches {facing:.2} of the objects within 40 degrees");
    assert!(facing > straight, "the turns do not help: {facing:.2} against {straight:.2}");
    assert!(facing_aside >= 0.8, "the script catches {facing_aside:.2} of the objects at 60 degrees");
    assert!(straight_aside <= 0.5, "without the turns {straight_aside:.2} at 60 degrees");
}

#[test]
fn a_grip_trial_in_a_stage_without_objects_is_an_error() {
    let source = std::fs::read_to_string(root().join("examples/khepera.bat")).unwrap();
    let mut program = shaping_compiler::compile(&source, "khepera.bat").expect("compiles");
    train_all(&mut program, 1).unwrap();
    let nav = program.stages.iter().find(|s| s.name == "navigation").unwrap();
    let genome = Genome::zeros(nav.layout.bits as usize);
    let err = grip_trial(nav, &genome, 0, 10.0, 0.0, 1).unwrap_err();
    assert!(err.to_string().contains("has no objects"), "{err}");
}
