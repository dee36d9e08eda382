//! Properties: compiling never panics; appending a stage never changes the
//! layouts of the stages before it; `Program` survives a JSON round trip.

use proptest::prelude::*;
use shaping_compiler::{compile, Program};

use crate::root;

/// Words and symbols of the language, to build inputs that get deep into
/// the grammar (random strings mostly stop at the first character).
const TOKENS: &[&str] = &[
    "robot",
    "r",
    "{",
    "}",
    "sensor",
    "ir",
    "[8]",
    "[",
    "]",
    "proximity",
    "actuator",
    "wheels",
    "speed",
    "stage",
    "s",
    "t",
    "extends",
    "module",
    "m",
    "sense",
    "behavior",
    "forward",
    "back",
    "turn",
    "left",
    "until",
    "within",
    "for",
    "3",
    "actions",
    "mm",
    "0.5",
    "-1",
    "..",
    ",",
    ";",
    "(",
    ")",
    "max",
    "prev",
    "?",
    ":",
    "+",
    "*",
    "and",
    "not",
    "fitness",
    "per",
    "action",
    "links",
    "all",
    "evolvable",
    "link",
    "->",
    "genome",
    "bits",
    "range",
    "world",
    "arena",
    "x",
    "evolve",
    "population",
    "test",
    "best",
    "learn",
    "crbp",
    "on",
    "always",
    "reinforce",
    "neural",
    "outputs",
    "sign",
    "|",
    "script",
    "role",
    "robots",
    "// c\n",
];

fn khepera() -> String {
    std::fs::read_to_string(root().join("examples/khepera.bat")).unwrap()
}

/// A stage appended to `khepera.bat`, built from generated choices.
fn extra_stage(parent: usize, modules: &[(u8, u8, bool)], links: bool) -> String {
    let parent = ["navigation", "collect", "bigger"][parent];
    let mut s =
        format!("stage extra extends {parent} {{\n  evolve {{ generations 3 }}\n  genome {{ bits 5 }}\n");
    for (i, &(first, len, hidden)) in modules.iter().enumerate() {
        let first = first % 8;
        let last = (first + len % 4).min(7);
        let hidden = if hidden { "activation hidden 2" } else { "" };
        s += &format!(
            "  module x{i} {{ sense ir[{first}..{last}] {hidden} behavior turn left for 2 actions }}\n"
        );
    }
    if links {
        s += "  links all evolvable range -2..2\n";
    }
    s + "}\n"
}

proptest! {
    // 256 cases, or PROPTEST_CASES for a longer search.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256),
        ..ProptestConfig::default()
    })]

    #[test]
    fn any_string_compiles_or_gives_a_diagnostic(src in any::<String>()) {
        if let Err(d) = compile(&src, "any.bat") {
            prop_assert!(!d.is_empty());
        }
    }

    #[test]
    fn any_token_soup_compiles_or_gives_a_diagnostic(tokens in prop::collection::vec(prop::sample::select(TOKENS), 0..120)) {
        let src = tokens.join(" ");
        let result = compile(&src, "soup.bat");
        if let Ok(p) = &result {
            prop_assert_eq!(p.validate(), Ok(()));
        }
        if let Err(d) = result {
            prop_assert!(!d.is_empty());
            // Rendering never panics either.
            let _ = crate::render(&d);
        }
    }

    #[test]
    fn mutated_example_compiles_or_gives_a_diagnostic(at in 0usize..4000, len in 0usize..40, insert in prop::sample::select(TOKENS)) {
        let mut src = khepera();
        let at = at.min(src.len());
        let end = (at + len).min(src.len());
        if src.is_char_boundary(at) && src.is_char_boundary(end) {
            src.replace_range(at..end, insert);
        }
        match compile(&src, "mutated.bat") {
            Ok(p) => prop_assert_eq!(p.validate(), Ok(())),
            Err(d) => prop_assert!(!d.is_empty()),
        }
    }

    #[test]
    fn appending_a_stage_leaves_earlier_layouts_unchanged(
        parent in 0usize..3,
        modules in prop::collection::vec((any::<u8>(), any::<u8>(), any::<bool>()), 1..4),
        links in any::<bool>(),
    ) {
        let base = compile(&khepera(), "khepera.bat").unwrap();
        let src = khepera() + &extra_stage(parent, &modules, links);
        let grown = match compile(&src, "khepera.bat") {
            Ok(p) => p,
            Err(d) => return Err(TestCaseError::fail(crate::render(&d))),
        };
        prop_assert_eq!(grown.stages.len(), base.stages.len() + 1);
        for (a, b) in base.stages.iter().zip(&grown.stages) {
            prop_assert_eq!(&a.layout, &b.layout);
            prop_assert_eq!(a, b);
        }
        // The new stage starts with its parent's genes, all frozen.
        let new = grown.stages.last().unwrap();
        // Stage 0 of khepera.bat is the training stage `avoidance`.
        let old = &grown.stages[parent + 1].layout;
        prop_assert_eq!(new.layout.genes.len() > old.genes.len(), true);
        for (g, o) in new.layout.genes.iter().zip(&old.genes) {
            prop_assert!(g.frozen);
            prop_assert_eq!((g.offset, g.bits, g.module, g.role), (o.offset, o.bits, o.module, o.role));
        }
        for g in &new.layout.genes[old.genes.len()..] {
            prop_assert!(!g.frozen);
            prop_assert_eq!(g.bits, 5);
        }
        // Gene offsets are contiguous.
        let mut offset = 0;
        for g in &new.layout.genes {
            prop_assert_eq!(g.offset, offset);
            offset += g.bits as u32;
        }
        prop_assert_eq!(offset, new.layout.bits);
        prop_assert!(serde_roundtrip(&grown));
        prop_assert_eq!(grown.validate(), Ok(()));
    }
}

/// Values a mutated program's field may take: extremes of every kind.
fn extreme_values() -> Vec<serde_json::Value> {
    use serde_json::json;
    vec![
        json!(0),
        json!(-1),
        json!(1),
        json!(17),
        json!(18),
        json!(65535),
        json!(4_000_000_000u64),
        json!(-1e30),
        json!(1e30),
        json!(0.5),
        json!(2),
        json!([]),
        json!(null),
        json!(true),
    ]
}

/// Replaces the node reached by `path` (child indices, taken modulo the
/// number of children; the walk stops at a leaf or after `depth` steps).
fn mutate_at(v: &mut serde_json::Value, path: &[usize], depth: usize, new: serde_json::Value) {
    let child = match (path.first(), depth > 0) {
        (Some(&k), true) => match v {
            serde_json::Value::Array(a) if !a.is_empty() => {
                let n = a.len();
                Some(&mut a[k % n])
            }
            serde_json::Value::Object(o) if !o.is_empty() => {
                let n = o.len();
                o.values_mut().nth(k % n)
            }
            _ => None,
        },
        _ => None,
    };
    match child {
        Some(c) => mutate_at(c, &path[1..], depth - 1, new),
        None => *v = new,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// A compiled program with one field changed is either refused with a
    /// message naming the field, or accepted and runs every stage without a
    /// panic.
    #[test]
    fn a_mutated_program_is_refused_or_runs(
        example in prop::sample::select(vec!["khepera.bat", "tutorial.bat", "scratch.bat", "avoid.bat"]),
        path in prop::collection::vec(any::<usize>(), 12),
        depth in 1usize..12,
        new in prop::sample::select(extreme_values()),
    ) {
        use shaping_runtime::controller::{run_episode, EpisodeOptions};
        use shaping_runtime::genome::Genome;
        let src = std::fs::read_to_string(root().join("examples").join(example)).unwrap();
        let p = crate::compile_ok(&src, example);
        let mut v = serde_json::to_value(&p).unwrap();
        mutate_at(&mut v, &path, depth, new);
        let Ok(m) = serde_json::from_value::<Program>(v) else { return Ok(()) };
        match m.validate() {
            Err(e) => prop_assert!(e.to_string().contains('`'), "{e}"),
            Ok(()) => {
                // Bind what the training stages learn, as the CLI does.
                let mut m = m;
                if shaping_runtime::evolve::train_all(&mut m, 1).is_err() {
                    return Ok(());
                }
                for s in &m.stages {
                    let g = Genome::zeros(s.layout.bits as usize);
                    run_episode(s, &g, &EpisodeOptions { actions: 30, learning: true, seed: 1 }, None);
                }
            }
        }
    }
}

fn serde_roundtrip(p: &Program) -> bool {
    let json = serde_json::to_string(p).unwrap();
    let back: Program = serde_json::from_str(&json).unwrap();
    back == *p
}

#[test]
fn examples_survive_a_json_round_trip() {
    for name in ["khepera.bat", "scratch.bat", "tutorial.bat"] {
        let src = std::fs::read_to_string(root().join("examples").join(name)).unwrap();
        let p = crate::compile_ok(&src, name);
        assert!(serde_roundtrip(&p), "{name}");
    }
}

#[test]
fn every_expression_is_valid_for_the_runtime() {
    use shaping_runtime::program::{Action, Behavior, StepEnd};
    let src = khepera();
    let p = crate::compile_ok(&src, "khepera.bat");
    let mut n = 0;
    for st in &p.stages {
        let mut exprs: Vec<&shaping_runtime::expr::Expr> = st.fitness.per_action.iter().collect();
        for m in &st.modules {
            exprs.extend(m.reinforce.iter());
            if let Behavior::Script(s) = &m.behavior {
                for step in &s.steps {
                    if let Action::Reinforce(e) = &step.action {
                        exprs.push(e);
                    }
                    if let StepEnd::Until { cond, .. } = &step.end {
                        exprs.push(cond);
                    }
                }
            }
        }
        for e in exprs {
            assert!(e.is_valid(), "{e:?}");
            n += 1;
        }
    }
    assert!(n >= 10);
}
