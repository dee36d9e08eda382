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

/// `lives`, `life` and `of` are no reserved words, and the test stages of
/// `declarations.bat` lower to their lives (one when not said).
#[test]
fn test_stages_lower_to_their_lives() {
    use shaping_runtime::program::StageRun;
    let src = std::fs::read_to_string(crate::root().join("tests/parse/declarations.bat")).unwrap();
    let p = crate::compile_ok(&src, "declarations.bat");
    let run = |name: &str| p.stage(name).map(|(_, s)| s.run.clone());
    assert_eq!(run("t"), Some(StageRun::Test { actions: 100, lives: 1, learning: false }));
    assert_eq!(run("lives"), Some(StageRun::Test { actions: 300, lives: 10, learning: true }));
    assert_eq!(run("of"), Some(StageRun::Test { actions: 20, lives: 1, learning: true }));
}
