//! Bad inputs: every file of `tests/ui/` must fail; the snapshot is the
//! source followed by the rendered diagnostics (no colour, 80 columns).

use crate::render;

#[test]
fn ui() {
    insta::glob!("../../..", "tests/ui/*.bat", |path| {
        let src = std::fs::read_to_string(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy();
        match shaping_compiler::compile(&src, &name) {
            Ok(_) => panic!("{name} compiles, but every file in tests/ui must fail"),
            Err(d) => {
                assert!(!d.is_empty());
                insta::assert_snapshot!(format!("{src}\n{}", render(&d)));
            }
        }
    });
}
