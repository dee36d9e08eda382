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

/// The runtime's list of reserved words (which `Program::validate` refuses
/// as names in a `program.json`) is the grammar's `keyword` rule.
#[test]
fn the_runtimes_reserved_words_are_the_grammars_keywords() {
    let grammar = std::fs::read_to_string(crate::root().join("grammar/shaping.pest")).unwrap();
    let rule = grammar.split("\nkeyword = @{").nth(1).expect("a `keyword` rule").split("\n}").next().unwrap();
    let mut words: Vec<&str> = rule.split('"').skip(1).step_by(2).collect();
    let mut reserved = shaping_runtime::validate::RESERVED.to_vec();
    words.sort_unstable();
    reserved.sort_unstable();
    assert_eq!(words, reserved);
    for w in shaping_runtime::validate::RESERVED {
        let src = format!(
            "robot r {{ sensor ir[8] proximity  actuator wheels[2] speed }}\nstage {w} {{ fitness per action 1  module m {{ sense ir behavior forward }} }}\n"
        );
        assert!(shaping_compiler::compile(&src, "k.bat").is_err(), "`{w}` is a name");
        assert!(!shaping_runtime::validate::is_name(w));
    }
    assert!(shaping_runtime::validate::is_name("robots"));
}

/// A UTF-8 byte order mark at the start of a file (some editors write one)
/// is skipped: the file compiles as without it, its diagnostics point at the
/// same text, and the formatter drops the mark.
#[test]
fn a_leading_byte_order_mark_is_skipped() {
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\nstage s {\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n";
    let marked = format!("\u{feff}{src}");
    assert_eq!(
        shaping_compiler::compile(&marked, "b.bat").unwrap(),
        shaping_compiler::compile(src, "b.bat").unwrap()
    );
    assert_eq!(shaping_compiler::fmt::format(&marked, "b.bat").unwrap(), src);

    let bad = format!("\u{feff}{}", src.replace("behavior forward", "behavior forwrd"));
    let d = shaping_compiler::compile(&bad, "b.bat").unwrap_err();
    let text = crate::render(&d);
    assert!(text.contains("[b.bat:4:33]") && !text.contains("found \u{feff}"), "{text}");
    // A syntax error at the first word names that word, not the mark.
    let syntax = format!("\u{feff}{}", src.replacen("robot", "robt", 1));
    let d = shaping_compiler::compile(&syntax, "b.bat").unwrap_err();
    assert_eq!(d.errors().len(), 1);
    assert_eq!(d.errors()[0].to_string(), "expected `genome`, `robot`, `stage` or end of file, found `robt`");
}
