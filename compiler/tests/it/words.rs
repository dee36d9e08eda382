//! One source for every word: the list of `shaping_compiler::ide::words`
//! (from which the language server's completion and hover come) against
//! the VS Code grammar, the grammar's doc comments and the reference. A
//! word added to the compiler and not to them fails here.

use shaping_compiler::ide::words::{words, WordKind};
use shaping_runtime::catalog;

use crate::root;

fn read(path: &str) -> String {
    std::fs::read_to_string(root().join(path)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The words of the alternations `(a|b|c)` of every regular expression of
/// the TextMate grammar.
fn textmate_words() -> Vec<String> {
    let g: serde_json::Value =
        serde_json::from_str(&read("editors/vscode/syntaxes/shaping.tmLanguage.json")).unwrap();
    let mut out = Vec::new();
    fn walk(v: &serde_json::Value, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Object(m) => {
                for (k, v) in m {
                    if let (true, Some(re)) = (k == "match" || k == "begin", v.as_str()) {
                        for group in re.split('(').skip(1) {
                            let group = group.split(')').next().unwrap_or("");
                            out.extend(
                                group
                                    .split('|')
                                    .filter(|w| {
                                        // `e-puck`: a preset's name may hold a `-`
                                        !w.is_empty()
                                            && w.chars()
                                                .all(|c| c.is_ascii_lowercase() || c == '_' || c == '-')
                                    })
                                    .map(str::to_string),
                            );
                        }
                    }
                    walk(v, out);
                }
            }
            serde_json::Value::Array(a) => a.iter().for_each(|v| walk(v, out)),
            _ => {}
        }
    }
    walk(&g, &mut out);
    out
}

#[test]
fn the_vscode_grammar_highlights_every_word() {
    let tm = textmate_words();
    let missing: Vec<&str> = words().iter().map(|w| w.text).filter(|w| !tm.iter().any(|t| t == w)).collect();
    assert_eq!(missing, Vec::<&str>::new(), "words editors/vscode/syntaxes/shaping.tmLanguage.json lacks");
    // the kinds, where a declaration's kind is highlighted
    let g = read("editors/vscode/syntaxes/shaping.tmLanguage.json");
    let kinds = g.lines().find(|l| l.contains("proximity|")).expect("the kinds' pattern");
    for k in catalog::SENSORS.iter().map(|s| s.keyword).chain(catalog::ACTUATORS.iter().map(|a| a.keyword)) {
        assert!(
            kinds.contains(&format!("|{k}|"))
                || kinds.contains(&format!("({k}|"))
                || kinds.contains(&format!("|{k})")),
            "the kinds' pattern lacks `{k}`: {kinds}"
        );
    }
}

/// The doc comments of `sensor_decl` and `actuator_decl` list every kind.
#[test]
fn the_grammars_doc_comments_list_every_kind() {
    let g = read("grammar/shaping.pest");
    let doc = |rule: &str| -> String {
        let at = g.find(&format!("\n{rule} =")).unwrap_or_else(|| panic!("{rule}"));
        g[..at].lines().rev().take_while(|l| l.starts_with("///")).collect::<Vec<_>>().join(" ")
    };
    for s in catalog::SENSORS {
        assert!(
            doc("sensor_decl").contains(&format!("`{}`", s.keyword)),
            "sensor_decl's doc lacks `{}`",
            s.keyword
        );
    }
    for a in catalog::ACTUATORS {
        assert!(
            doc("actuator_decl").contains(&format!("`{}`", a.keyword)),
            "actuator_decl's doc lacks `{}`",
            a.keyword
        );
    }
}

/// The words of the code of a Markdown text: inline code and code blocks.
fn code_words(md: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut code = String::new();
    for (i, part) in md.split("```").enumerate() {
        if i % 2 == 1 {
            code.push_str(part);
        } else {
            code.extend(part.split('`').skip(1).step_by(2).map(|s| format!("{s} ")));
        }
    }
    for w in code.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
        if !w.is_empty() {
            out.push(w.to_string());
        }
    }
    // and the words with an inner `-` (`e-puck`)
    for w in code.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-')) {
        if w.contains('-') {
            out.push(w.to_string());
        }
    }
    out
}

/// The reference shows every word in code, and its table of kinds lists
/// every sensor and actuator kind.
#[test]
fn the_reference_shows_every_word() {
    let md = read("docs/language.md");
    let shown = code_words(&md);
    let missing: Vec<&str> =
        words().iter().map(|w| w.text).filter(|w| !shown.iter().any(|s| s == w)).collect();
    assert_eq!(missing, Vec::<&str>::new(), "words docs/language.md never shows");
    for w in words().iter().filter(|w| matches!(w.kind, WordKind::SensorKind | WordKind::ActuatorKind)) {
        assert!(md.contains(&format!("\n| `{}`", w.text)), "the table of kinds lacks `{}`", w.text);
    }
    // every word's section exists
    let anchors: Vec<String> = md
        .lines()
        .filter(|l| l.starts_with("## ") || l.starts_with("### "))
        .map(|l| {
            l.trim_start_matches('#')
                .trim()
                .to_lowercase()
                .chars()
                .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
                .collect::<String>()
                .replace(' ', "-")
        })
        .collect();
    for w in words() {
        assert!(
            anchors.iter().any(|a| a == w.section),
            "`{}`: no section `{}` in {anchors:?}",
            w.text,
            w.section
        );
    }
}
