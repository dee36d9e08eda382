//! Parse snapshots: the AST of every file of `tests/parse/` (spans as
//! `start..end`, names as `"text"@start..end`).

#[test]
fn parse() {
    insta::glob!("../../..", "tests/parse/*.bat", |path| {
        let src = std::fs::read_to_string(path).unwrap();
        let file = match shaping_compiler::syntax::parse(&src) {
            Ok(f) => f,
            Err(e) => panic!("{} does not parse: {e:?}", path.display()),
        };
        // Every parse test is also a valid program.
        crate::compile_ok(&src, &path.file_name().unwrap().to_string_lossy());
        insta::assert_snapshot!(format!("{file:#?}"));
    });
}
