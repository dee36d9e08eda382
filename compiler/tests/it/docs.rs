//! Every ```bat block of `docs/language.md` compiles; blocks marked
//! ```bat,fails must fail.

use crate::root;

#[test]
fn language_reference_examples() {
    let text = std::fs::read_to_string(root().join("docs/language.md")).unwrap();
    let mut blocks = 0;
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
        let name = format!("language.md:{}", i + 1);
        match (shaping_compiler::compile(&src, &name), fails) {
            (Ok(p), false) => assert_eq!(p.validate(), Ok(()), "{name}"),
            (Err(_), true) => {}
            (Ok(_), true) => panic!("{name}: the block is marked `fails` but compiles"),
            (Err(d), false) => panic!("{name} does not compile:\n{}", crate::render(&d)),
        }
        blocks += 1;
    }
    assert!(blocks >= 10, "only {blocks} examples in docs/language.md");
}
