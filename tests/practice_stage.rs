//! `examples/khepera-practice.bat` is `examples/khepera.bat` with the
//! deviations listed at its top and nothing else: its avoidance,
//! navigation and collect stages compile to those of `khepera.bat` with
//! each deviation applied to the text, its training stage `practice`
//! trains the activation networks of collect's grip and release, and its
//! three test stages test collect's best in the same lives.

use shaping_runtime::evolve::test_seed_stage;
use shaping_runtime::program::{Param, Part, Program, StageRun};

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn compile(source: &str, name: &str) -> Program {
    let program = shaping_compiler::compile(source, name).expect("compiles");
    program.validate().unwrap();
    program
}

/// `khepera.bat` with deviations 1 to 5 applied as text, and the
/// practice stage of `khepera-practice.bat` appended.
fn deviated(practice: &str) -> String {
    let mut s = std::fs::read_to_string(root().join("examples/khepera.bat")).unwrap();
    let mut rep = |old: &str, new: &str, n: usize| {
        assert_eq!(s.matches(old).count(), n, "`{old}` in khepera.bat");
        s = s.replace(old, new);
    };
    rep("forward | right | left | back", "forward | right | left | right", 2);
    rep(
        "evolve { population 100  generations 40  actions 300  seed 1  mutation 0.02 }",
        "evolve { population 100  generations 100  actions 300  seed 1  mutation 0.02  evaluations 3 }",
        1,
    );
    rep("evolve { generations 40 }", "evolve { generations 80  inheritance lamarckian }", 1);
    rep("learn crbp(1, 0.5) on activation always", "learn crbp(0.5, 0.1) on activation always", 2);
    rep("    sense ir, barrier\n", "    sense ir, barrier\n    activation trained practice hidden 4\n", 2);
    s + practice
}

#[test]
fn khepera_practice_is_khepera_with_its_listed_deviations() {
    let source = std::fs::read_to_string(root().join("examples/khepera-practice.bat")).unwrap();
    let program = compile(&source, "khepera-practice.bat");
    let at = source.find("stage practice {").unwrap();
    let end = at + source[at..].find("\n}\n").unwrap() + 3;
    let reference = compile(&deviated(&source[at..end]), "khepera-practice.bat");
    let names: Vec<&str> = program.stages.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        ["avoidance", "navigation", "practice", "collect", "bigger", "bigger_nolearning", "bigger_unchanged"]
    );
    for (i, name) in names[..4].iter().enumerate() {
        assert_eq!(program.stages[i], reference.stages[i], "stage `{name}`");
    }

    let collect = &program.stages[3];
    let practice = 2;
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

    // Figure 13: 40 + 40 lives with learning, without, and unchanged; the
    // same lives in all three.
    for (i, learn) in [(4, true), (5, false), (6, true)] {
        let s = &program.stages[i];
        assert_eq!(s.parent, Some(3));
        assert!(
            matches!(s.run, StageRun::Test { actions: 300, lives: 40, learning } if learning == learn),
            "{}",
            s.name
        );
        assert_eq!(test_seed_stage(&program, i), 4, "{} runs the lives of `bigger`", s.name);
    }
    let diameter = |i: usize| program.stages[i].world.objects.as_ref().unwrap().diameter;
    assert_eq!((diameter(4), diameter(5)), (25.0, 25.0));
    assert_eq!((diameter(3), diameter(6)), (10.0, 10.0));
}
