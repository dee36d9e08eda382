//! `docs/experiments/practice-stage.txt`, the training stage `run.sh`
//! appends to the exploring variant (`khepera-practice.bat`), compiles
//! appended to `examples/khepera.bat` the same way, and the collect stage's
//! grip and release take their activation networks from it.

use shaping_runtime::program::{Param, Part};

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_practice_stage_trains_the_activation_networks_of_grip_and_release() {
    let base = std::fs::read_to_string(root().join("examples/khepera.bat")).unwrap();
    let stage = std::fs::read_to_string(root().join("docs/experiments/practice-stage.txt")).unwrap();
    // As run.sh's sed: after each `sense ir, barrier` of the collect stage.
    let line = "    sense ir, barrier\n";
    assert_eq!(base.matches(line).count(), 2, "grip and release sense ir, barrier");
    let source = base.replace(line, &format!("{line}    activation trained practice hidden 4\n")) + &stage;
    let program = shaping_compiler::compile(&source, "khepera-practice.bat").expect("compiles");
    program.validate().unwrap();
    let collect = program.stages.iter().find(|s| s.name == "collect").unwrap();
    let practice = program.stages.iter().position(|s| s.name == "practice").unwrap();
    for name in ["grip", "release"] {
        let m = collect.modules.iter().find(|m| m.name == name).unwrap();
        let params = &m.activation.params;
        assert_eq!(params.len(), 45, "{name}: 4 hidden units on 9 inputs");
        assert!(
            params.iter().all(
                |p| matches!(p, Param::Trained { stage, part: Part::Activation, .. } if *stage as usize == practice)
            ),
            "{name}: every activation weight from `practice`"
        );
    }
    assert_eq!(program.stages[practice].layout.bits, 0, "a training stage evolves nothing");
}
