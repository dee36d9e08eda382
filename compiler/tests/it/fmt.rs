//! The formatter: idempotent, meaning-preserving and comment-preserving on
//! every example, every example of `docs/language.md`, every parse and ui
//! test input, and generated programs; the examples and the documentation
//! are kept formatted.

use proptest::prelude::*;
use shaping_compiler::fmt::{format, FormatError};
use shaping_compiler::syntax::lex::lex;
use shaping_compiler::{compile, syntax};

use crate::root;

/// Every source of the repository that parses: (name, text).
fn sources() -> Vec<(String, String)> {
    let mut out = Vec::new();
    for dir in ["examples", "tests/parse", "tests/ui", "tests/lower"] {
        let Ok(entries) = std::fs::read_dir(root().join(dir)) else { continue };
        let mut paths: Vec<_> = entries.map(|e| e.unwrap().path()).collect();
        paths.sort();
        for p in paths {
            if p.extension().is_some_and(|e| e == "bat") {
                out.push((
                    format!("{dir}/{}", p.file_name().unwrap().to_string_lossy()),
                    std::fs::read_to_string(&p).unwrap(),
                ));
            }
        }
    }
    out.extend(doc_examples());
    out
}

/// The ```bat blocks of `docs/language.md`.
fn doc_examples() -> Vec<(String, String)> {
    crate::docs::blocks().into_iter().map(|(name, src, _)| (name, src)).collect()
}

/// The comments of a source, as written (trailing spaces aside).
fn comments(src: &str) -> Vec<String> {
    lex(src).comments.iter().map(|c| src[c.span.start..c.span.end].trim_end().to_string()).collect()
}

/// Formats a source that parses, checking every property.
fn check_properties(name: &str, src: &str) -> Result<(), String> {
    let out = match format(src, name) {
        Ok(out) => out,
        Err(FormatError::Syntax(_)) => return Ok(()),
        Err(FormatError::Changed(why)) => return Err(format!("{name}: {why}\n--- input\n{src}")),
    };
    let again = format(&out, name).map_err(|e| format!("{name}: formatted text fails: {e:?}\n{out}"))?;
    if again != out {
        return Err(format!("{name}: not idempotent\n--- once\n{out}--- twice\n{again}"));
    }
    let before = compile(src, name).map_err(|d| d.errors().iter().map(|e| e.to_string()).collect::<Vec<_>>());
    let after = compile(&out, name).map_err(|d| d.errors().iter().map(|e| e.to_string()).collect::<Vec<_>>());
    if before != after {
        return Err(format!("{name}: the meaning changed\n{out}"));
    }
    let (mut a, mut b) = (comments(src), comments(&out));
    a.sort();
    b.sort();
    if a != b {
        return Err(format!("{name}: comments changed: {a:?} -> {b:?}\n{out}"));
    }
    if let Some(l) = out.lines().find(|l| l.ends_with(' ')) {
        return Err(format!("{name}: trailing spaces in {l:?}"));
    }
    Ok(())
}

#[test]
fn formatting_is_idempotent_and_keeps_meaning_and_comments() {
    let sources = sources();
    assert!(sources.len() > 30, "only {} sources", sources.len());
    let mut formatted = 0;
    for (name, src) in &sources {
        check_properties(name, src).unwrap_or_else(|e| panic!("{e}"));
        formatted += usize::from(syntax::parse(src).is_ok());
    }
    assert!(formatted > 30, "only {formatted} sources parse");
}

/// `shaping fmt --check` passes on the documentation's examples.
#[test]
fn documented_examples_are_formatted() {
    for (name, src) in doc_examples() {
        if syntax::parse(&src).is_err() {
            continue;
        }
        let out = format(&src, &name).unwrap();
        assert_eq!(out, src, "{name} is not formatted; formatted it reads:\n{out}");
    }
}

/// `shaping fmt --check examples/*.bat` passes.
#[test]
fn examples_are_formatted() {
    for entry in std::fs::read_dir(root().join("examples")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "bat") {
            let src = std::fs::read_to_string(&path).unwrap();
            let out = format(&src, "example.bat").unwrap();
            assert!(out == src, "{} is not formatted: run `shaping fmt {}`", path.display(), path.display());
        }
    }
}

#[test]
fn a_file_that_does_not_parse_is_an_error() {
    assert!(matches!(format("robot r {", "x.bat"), Err(FormatError::Syntax(_))));
}

#[test]
fn layout_rules() {
    let src = "robot r{sensor ir[8] proximity   actuator wheels[2] speed}\n\n\n\
               // the stage\nstage s { fitness per action (wheels[0]) + ((1 - max(ir))) // f\n\
               world {\narena 400mm x 600mm\nbattery 200 actions, recharge 20 actions;\n}\n\
               module m { sense ir , ir[0 .. 2]  behavior   neural{outputs sign(1)->forward|left}\n\
               learn crbp on behavior always  reinforce a ? 1 : b ? 2 : 3 }\n\
               module n {\nsense ir /* x */ behavior script { forward(1.0) for 2 actions; turn left(0.5) } } }\n";
    let out = format(src, "x.bat").unwrap();
    let expected = "\
robot r { sensor ir[8] proximity  actuator wheels[2] speed }

// the stage
stage s {
  fitness per action wheels[0] + (1 - max(ir))  // f
  world {
    arena 400mm x 600mm
    battery 200 actions, recharge 20 actions
  }
  module m {
    sense ir, ir[0..2]
    behavior neural { outputs sign(1) -> forward | left }
    learn crbp on behavior always
    reinforce a ? 1 : b ? 2 : 3
  }
  module n {
    sense ir  /* x */
    behavior script { forward(1.0) for 2 actions; turn left(0.5) }
  }
}
";
    assert_eq!(out, expected);
}

/// The lives of a test stage: spacing normalised, `life` for
/// one and `lives` otherwise, and the program unchanged.
#[test]
fn test_lives_are_formatted_and_keep_their_meaning() {
    let head = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n\
                stage s { fitness per action wheels[0]  module m { sense ir  behavior forward } }\n";
    for (test, expected) in [
        ("test best  for 10   lives\n of 300 actions", "test best for 10 lives of 300 actions"),
        (
            "test best for 1 lives of 20 actions with learning",
            "test best for 1 life of 20 actions with learning",
        ),
        ("test best for 3 life of 20 without learning", "test best for 3 lives of 20 without learning"),
        ("test best for 300 actions", "test best for 300 actions"),
    ] {
        let src = format!("{head}stage t extends s {{ {test} }}\n");
        let out = format(&src, "x.bat").unwrap();
        assert!(
            out.lines().any(|l| l
                .trim_start()
                .trim_start_matches("stage t extends s { ")
                .trim_end_matches(" }")
                == expected),
            "{out}"
        );
        assert_eq!(compile(&out, "x.bat").unwrap(), compile(&src, "x.bat").unwrap());
    }
}

#[test]
fn long_conditionals_break_before_each_colon() {
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\nstage s {\n  fitness per action wheels[0]\n  module m {\n    sense ir\n    behavior forward\n    learn crbp on activation always\n    reinforce max(ir) > max(prev ir) + 0.02 ? -1 : max(ir) < max(prev ir) - 0.02 ? 1 : max(ir) > 0.5 ? -1 : max(ir) < 0.1 ? sign(wheels[0] + wheels[1]) : 0\n  }\n}\n";
    let out = format(src, "x.bat").unwrap();
    assert!(out.contains(
        "    reinforce max(ir) > max(prev ir) + 0.02 ? -1\n            : max(ir) < max(prev ir) - 0.02 ? 1\n            : max(ir) > 0.5 ? -1\n            : max(ir) < 0.1 ? sign(wheels[0] + wheels[1])\n            : 0\n"
    ), "{out}");
}

// ------------------------------------------------------------------ generated programs

/// A small program from generated choices, written with random spacing,
/// line breaks and comments.
fn generated(choices: &[u8], spaces: &[u8]) -> String {
    let words = [
        "robot r { sensor ir[8] proximity, sensor battery level; actuator wheels[2] speed }",
        "genome { bits 4 range -1..1 links bits 6 range -2..2 }",
        "stage a { world { arena 400mm x 600mm battery 200 actions, recharge 20 actions } fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) module m { sense ir behavior forward(0.5) } }",
        "stage b extends a { evolve { generations 3 selection roulette } module k { sense ir[0..3], battery activation fixed [0.5, -1, 1, 2, 3, 4] behavior script commit { back(0.5) until max(ir) < 0.2 within 5 actions; wait if not (battery > 0.5 or prev battery < 0.1) } } links all evolvable range -2..2 }",
        "stage c extends b { module n { sense ir behavior neural { sense ir[2] hidden 2 outputs sign(2) -> forward | right | turn left(0.5) | back weights random -0.5..0.5 } learn crbp(0.1, 0.01) on behavior when performance < 0.5 over 20 actions reinforce -max(ir) + 1 < 0.3 ? 1 : -(1 - 2) } link n -> m fixed -1 }",
        "stage d extends c { test best for 300 actions without learning }",
        "stage e extends c { test best for 4 lives of 300 actions with learning }",
    ];
    let mut src = String::new();
    for (i, w) in words.iter().enumerate() {
        if i > 1 && choices.get(i).is_some_and(|c| c % 5 == 0) {
            continue;
        }
        src.push_str(w);
        src.push('\n');
    }
    // Respace: every space becomes a space, a newline, a comment or two spaces.
    let mut out = String::new();
    let mut k = 0;
    for ch in src.chars() {
        if ch == ' ' {
            let s = spaces.get(k % spaces.len().max(1)).copied().unwrap_or(0);
            k += 1;
            out.push_str(match s % 8 {
                0 => "\n",
                1 => "  ",
                2 => " /* c */ ",
                3 => " // line\n",
                _ => " ",
            });
        } else {
            out.push(ch);
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn generated_programs_format_well(
        choices in prop::collection::vec(any::<u8>(), 6),
        spaces in prop::collection::vec(any::<u8>(), 1..40),
    ) {
        let src = generated(&choices, &spaces);
        prop_assert!(syntax::parse(&src).is_ok(), "generated source does not parse:\n{}", src);
        if let Err(e) = check_properties("generated.bat", &src) {
            return Err(TestCaseError::fail(e));
        }
    }
}
