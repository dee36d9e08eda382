//! Syntax error recovery: a file with syntax errors reports each of them
//! at its place, and still yields the AST of what parses.

use shaping_compiler::syntax::{ast, parse_recovering};
use shaping_compiler::{compile, Error};

const ROBOT: &str = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n";

fn stage_names(f: &ast::File) -> Vec<&str> {
    f.stages.iter().map(|s| s.name.text.as_str()).collect()
}

fn modules(s: &ast::StageDecl) -> Vec<&str> {
    s.items
        .iter()
        .filter_map(|i| match i {
            ast::StageItem::Module(m) => Some(m.name.text.as_str()),
            _ => None,
        })
        .collect()
}

/// The line (from 1) of each error's first label.
fn lines(src: &str, errors: &[Error]) -> Vec<usize> {
    use miette::Diagnostic;
    errors
        .iter()
        .map(|e| {
            let at = e.labels().and_then(|mut l| l.next()).map(|l| l.offset()).unwrap();
            src[..at].matches('\n').count() + 1
        })
        .collect()
}

#[test]
fn three_errors_in_three_stages_are_reported_at_once() {
    let src = format!(
        "{ROBOT}stage a {{\n  fitness per action wheels[0] +\n  module m {{ sense ir  behavior forward }}\n}}\n\
         stage b extends a {{\n  module n {{ sense ir  behavior forward(0.5 }}\n}}\n\
         stage c extends b {{\n  link m -> n evolvable range 0..\n}}\n"
    );
    let d = compile(&src, "three.bat").unwrap_err();
    assert_eq!(d.errors().len(), 3, "{:?}", d.errors());
    assert!(d.errors().iter().all(|e| matches!(e, Error::Syntax { .. })));
    assert_eq!(lines(&src, d.errors()), [4, 7, 11]);
}

#[test]
fn intact_stages_and_items_are_kept() {
    // `b` lacks a motion in one module; its other module, and stages `a`
    // and `c`, parse.
    let src = format!(
        "{ROBOT}stage a {{\n  fitness per action wheels[0]\n  module m {{ sense ir  behavior forward }}\n}}\n\
         stage b extends a {{\n  module broken {{ sense ir  behavior }}\n  module fine {{ sense ir  behavior stop }}\n  links all evolvable\n}}\n\
         stage c extends b {{ module k {{ sense ir[0]  behavior back }} }}\n"
    );
    let (file, errors) = parse_recovering(&src);
    assert_eq!(lines(&src, &errors), [7]);
    let file = file.expect("an AST of what parses");
    assert_eq!(stage_names(&file), ["a", "b", "c"]);
    assert_eq!(modules(&file.stages[1]), ["fine"]);
    assert!(file.stages[1].items.iter().any(|i| matches!(i, ast::StageItem::LinksAll(..))));
    assert_eq!(modules(&file.stages[2]), ["k"]);
    // Spans are those of the source.
    let k = &file.stages[2].items[0];
    let ast::StageItem::Module(k) = k else { panic!() };
    assert_eq!(&src[k.name.span.start..k.name.span.end], "k");
    assert_eq!(file.robots.len(), 1);
}

#[test]
fn a_missing_brace_keeps_the_stages_after_it() {
    // The module of `a` is not closed: `a` loses it, `b` is intact.
    let src = format!(
        "{ROBOT}stage a {{\n  fitness per action wheels[0]\n  module m {{ sense ir  behavior forward\n}}\n\
         stage b extends a {{ module n {{ sense ir  behavior stop }} }}\n"
    );
    let (file, errors) = parse_recovering(&src);
    assert_eq!(errors.len(), 1, "{errors:?}");
    let file = file.unwrap();
    assert_eq!(stage_names(&file), ["a", "b"]);
    assert_eq!(modules(&file.stages[1]), ["n"]);
    // A stage not closed before the next one: the stage is kept.
    let src = format!(
        "{ROBOT}stage a {{\n  fitness per action wheels[0]\n  module m {{ sense ir  behavior forward }}\n\n\
         stage b extends a {{ module n {{ sense ir  behavior stop }} }}\n"
    );
    let (file, errors) = parse_recovering(&src);
    assert_eq!(lines(&src, &errors), [6]);
    let file = file.unwrap();
    assert_eq!(stage_names(&file), ["a", "b"]);
    assert_eq!(modules(&file.stages[0]), ["m"]);
}

#[test]
fn garbage_between_items_and_after_a_stage() {
    let src = format!(
        "{ROBOT}stage a {{\n  fitness per action wheels[0]\n  ) module m {{ sense ir  behavior forward }}\n}} junk\n\
         stage b extends a {{ module n {{ sense ir  behavior stop }} }}\n"
    );
    let (file, errors) = parse_recovering(&src);
    assert_eq!(lines(&src, &errors), [4, 5]);
    let file = file.unwrap();
    assert_eq!(stage_names(&file), ["a", "b"]);
    assert_eq!(modules(&file.stages[0]), ["m"]);
}

#[test]
fn a_file_that_parses_has_no_errors_and_the_same_ast() {
    for e in std::fs::read_dir(crate::root().join("examples")).unwrap() {
        let src = std::fs::read_to_string(e.unwrap().path()).unwrap();
        let (file, errors) = parse_recovering(&src);
        assert!(errors.is_empty());
        assert_eq!(file, shaping_compiler::syntax::parse(&src).ok());
    }
}

#[test]
fn limits_still_refuse_before_parsing() {
    let deep = format!("{ROBOT}stage a {{ fitness per action {}1 }}\nstage b {{", "(".repeat(100));
    let (file, errors) = parse_recovering(&deep);
    assert!(file.is_none());
    assert!(errors[0].to_string().contains("deeper than"), "{errors:?}");
}

#[test]
fn many_broken_stages_are_recovered_in_linear_time() {
    // 20000 stages, every other one broken: every error is reported.
    let mut src = String::from(ROBOT);
    for i in 0..20_000 {
        if i % 2 == 0 {
            src.push_str(&format!("stage s{i} {{ module m {{ sense ir  behavior forward }} }}\n"));
        } else {
            src.push_str(&format!("stage s{i} {{ module m {{ sense ir  behavior }} }}\n"));
        }
    }
    let (file, errors) = parse_recovering(&src);
    assert_eq!(errors.len(), 10_000);
    assert_eq!(file.unwrap().stages.len(), 20_000);
}

#[test]
fn many_unclosed_brackets_in_one_stage_are_named_in_linear_time() {
    // 20000 modules in one stage, every other one with a `(` closed only
    // after the module's `}` (so that the brackets do not nest deeper and
    // deeper): each is named, and each is found reading its own item, not
    // the file.
    let mut src = format!("{ROBOT}stage s {{\n  fitness per action wheels[0]\n");
    for i in 0..20_000 {
        let (inside, after) = if i % 2 == 0 { (")", "") } else { ("", ")") };
        src.push_str(&format!("  module m{i} {{ sense ir  behavior forward(0.5{inside} }}{after}\n"));
    }
    src.push_str("}\n");
    let (file, errors) = parse_recovering(&src);
    assert_eq!(errors.len(), 10_000, "{:?}", errors[0]);
    assert!(errors.iter().all(|e| e.to_string() == "this `(` is not closed"), "{:?}", errors[0]);
    assert_eq!(modules(&file.unwrap().stages[0]).len(), 10_000);
}

#[test]
fn recovery_keeps_the_call_budget_on_huge_files() {
    // 200000 modules in one stage, and a syntax error before or after them:
    // the answer comes (an error, not a hang), with every error found.
    let modules = " module m { sense ir behavior forward }\n".repeat(200_000);
    for (before, after) in [("robot q {\n", ""), ("", " module broken { sense }\n")] {
        let src = format!("{ROBOT}{before}stage s {{\n fitness per action 1\n{modules}{after}}}\n");
        let (_, errors) = parse_recovering(&src);
        assert!(!errors.is_empty());
        let first = errors[0].to_string();
        assert!(first == "robot `q` is not closed" || first.contains("too complex"), "{first}");
    }
}

/// A syntax error in one role's module loses that module only: the role's
/// other modules, the stage's other roles and items, and the next stage,
/// are in the AST.
#[test]
fn an_error_in_a_role_keeps_the_other_roles() {
    let src = format!(
        "{ROBOT}stage s {{\n  fitness per action wheels[0]\n  role a robots 2 {{\n    module m {{ sense ir  behavior forward( }}\n    module k {{ sense ir  behavior stop }}\n  }}\n\
         role b robots 1 {{ module n {{ sense ir  behavior back }} }}\n}}\nstage t extends s {{ fitness per action 1 }}\n"
    );
    let (file, errors) = parse_recovering(&src);
    let file = file.expect("an AST");
    assert_eq!(lines(&src, &errors), [5]);
    assert_eq!(stage_names(&file), ["s", "t"]);
    let roles: Vec<(&str, Vec<&str>)> = file.stages[0]
        .roles()
        .map(|r| (r.name.text.as_str(), r.modules().map(|m| m.name.text.as_str()).collect()))
        .collect();
    assert_eq!(roles, [("a", vec!["k"]), ("b", vec!["n"])]);
    assert!(file.stages[0].items.iter().any(|i| matches!(i, ast::StageItem::Fitness(_))));
}
