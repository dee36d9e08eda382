//! Garbage, empty, deeply nested and huge inputs give a diagnostic, never a
//! panic or a stack overflow.

use shaping_compiler::compile;

fn fails(src: &str) -> String {
    match compile(src, "limits.bat") {
        Ok(_) => panic!("compiled"),
        Err(d) => {
            assert!(!d.is_empty());
            d.errors().iter().map(|e| e.to_string()).collect::<Vec<_>>().join("\n")
        }
    }
}

const HEAD: &str = "robot r { sensor ir[8] proximity actuator wheels[2] speed }\nstage s {\n module m { sense ir behavior forward }\n fitness per action ";

#[test]
fn empty_and_whitespace() {
    assert!(fails("").contains("no stage"));
    assert!(fails("  \n\t// only a comment\n").contains("no stage"));
}

#[test]
fn garbage() {
    assert!(fails("\u{0}\u{1}\u{7f}").starts_with("expected"));
    assert!(fails("}}}}").starts_with("expected"));
    assert!(fails("stage s { module m { sense ir behavior forward } } \u{fffd}").starts_with("expected"));
}

#[test]
fn deep_brackets() {
    for open in ["(", "[", "{", "? 1 "] {
        let src = format!("{HEAD}{}", format!("{open}\n").repeat(100_000));
        assert!(fails(&src).contains("deeper than"), "{open}");
    }
}

#[test]
fn long_prefix_chains() {
    for op in ["-", "not ", "prev "] {
        let src = format!("{HEAD}{}ir[0]\n}}", format!("{op}\n").repeat(100_000));
        assert!(fails(&src).contains("more than 256 parts"), "{op}");
    }
}

#[test]
fn long_operator_chains() {
    let src = format!("{HEAD}{}1\n}}", "1 +\n".repeat(100_000));
    assert!(fails(&src).contains("more than 256 parts"));
    let src = format!("{HEAD}{}1\n}}", "1 ? 1 :\n".repeat(100_000));
    assert!(fails(&src).contains("more than 256 parts"));
}

#[test]
fn moderately_long_expressions_compile() {
    let src = format!("{HEAD}{}1\n}}", "ir[0] * ".repeat(40));
    assert!(compile(&src, "ok.bat").is_ok());
}

#[test]
fn huge_files() {
    // A few megabytes of modules: duplicate names, reported (once each).
    let mut src = String::from(
        "robot r { sensor ir[8] proximity actuator wheels[2] speed }\nstage s {\n fitness per action 1\n",
    );
    for _ in 0..50_000 {
        src.push_str(" module m { sense ir behavior forward }\n");
    }
    src.push('}');
    let msg = fails(&src);
    assert!(msg.contains("declared twice") || msg.contains("too complex"), "{}", &msg[..200.min(msg.len())]);
    // Megabytes of one token.
    let src = "x".repeat(4_000_000);
    assert!(fails(&src).contains("longer than"));
}

#[test]
fn long_lines_are_reported_and_render() {
    // An error far to the right of a long line would make miette's renderer
    // panic (label padding is limited to 65535 columns): long lines are an
    // error of their own, labelled at their start.
    for (src, line) in
        [(format!("{}]", " ".repeat(70_000)), 1), (format!("{HEAD}{}1\n}}", "ir[0] * ".repeat(200_000)), 4)]
    {
        let d = compile(&src, "long.bat").unwrap_err();
        assert_eq!(d.errors()[0].to_string(), format!("line {line} is longer than 4096 bytes"));
        let _ = crate::render(&d);
    }
}

#[test]
fn too_many_modules() {
    let mut src = String::from(
        "robot r { sensor ir[8] proximity actuator wheels[2] speed }\nstage s {\n fitness per action 1\n",
    );
    for i in 0..300 {
        src.push_str(&format!(" module m{i} {{ sense ir behavior forward }}\n"));
    }
    src.push_str(" links all evolvable\n}");
    assert!(fails(&src).contains("more than 256 modules"));
}

#[test]
fn too_many_stages_and_clauses() {
    let mut src = String::from("robot r { sensor ir[8] proximity actuator wheels[2] speed }\n");
    src.push_str("stage s0 { fitness per action 1 module m { sense ir behavior forward } }\n");
    for i in 1..100_000 {
        src.push_str(&format!("stage s{i} extends s{} {{ }}\n", i - 1));
    }
    assert!(fails(&src).contains("more than 64 stages"));
    let mut src = String::from("robot r { sensor ir[8] proximity actuator wheels[2] speed }\nstage s { fitness per action 1 module m { behavior forward ");
    src.push_str(&"sense ir\n".repeat(100_000));
    src.push_str("} }");
    assert!(fails(&src).contains("declared twice"));
}
