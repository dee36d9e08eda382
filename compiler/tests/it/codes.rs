//! Stable diagnostic codes: every code has an explanation whose wrong
//! example produces it and whose right example compiles without it.

use miette::Diagnostic;
use shaping_compiler::explain::{expand, EXPLANATIONS};

use crate::root;

fn codes(src: &str) -> (bool, Vec<String>) {
    let (program, d) = shaping_compiler::check(src, "example.bat");
    let codes = d.errors().iter().filter_map(|e| e.code().map(|c| c.to_string())).collect();
    (program.is_some(), codes)
}

#[test]
fn every_explanations_examples_produce_and_fix_its_code() {
    for (i, e) in EXPLANATIONS.iter().enumerate() {
        assert_eq!(e.code, format!("S{:04}", i + 1), "codes are numbered in order");
        let (_, wrong) = codes(&expand(e.wrong));
        assert!(wrong.contains(&e.code.to_string()), "{}: the wrong example gives {wrong:?}", e.code);
        let (compiles, right) = codes(&expand(e.right));
        assert!(
            compiles && !right.contains(&e.code.to_string()),
            "{}: the right example gives {right:?}",
            e.code
        );
    }
}

/// Every diagnostic of the ui tests has a code, and every code an explanation.
#[test]
fn every_diagnostic_has_a_code_with_an_explanation() {
    let mut seen = std::collections::BTreeSet::new();
    for entry in std::fs::read_dir(root().join("tests/ui")).unwrap() {
        let path = entry.unwrap().path();
        let src = std::fs::read_to_string(&path).unwrap();
        let (_, d) = shaping_compiler::check(&src, "ui.bat");
        for e in d.errors() {
            let code =
                e.code().unwrap_or_else(|| panic!("{}: `{e}` has no code", path.display())).to_string();
            assert!(shaping_compiler::explain::explain(&code).is_some(), "{code} has no explanation");
            seen.insert(code);
        }
    }
    // the ui tests cover every kind but the generated ones' (too complex)
    assert_eq!(seen.len() + 1, EXPLANATIONS.len(), "{seen:?}");
}

/// The reference's table of codes lists every code with its title.
#[test]
fn the_reference_lists_every_code() {
    let md = std::fs::read_to_string(root().join("docs/language.md")).unwrap();
    for e in EXPLANATIONS {
        assert!(md.contains(&format!("| `{}` | {} |", e.code, e.title)), "docs/language.md lacks {}", e.code);
    }
}
