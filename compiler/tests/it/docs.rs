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
