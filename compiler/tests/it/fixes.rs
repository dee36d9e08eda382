//! Quick fixes: every "did you mean" of the ui tests is a replacement of
//! one word, every "declare `actuator ...`" or "`sensor ...`" hint a
//! declaration; applied, a fix removes its diagnostic.

use miette::Diagnostic;
use shaping_compiler::diag::Suggestion;
use shaping_compiler::ide;

use crate::root;

#[test]
fn every_did_you_mean_and_declare_hint_is_a_fix() {
    let (mut replaced, mut declared) = (0, 0);
    for entry in std::fs::read_dir(root().join("tests/ui")).unwrap() {
        let path = entry.unwrap().path();
        let src = std::fs::read_to_string(&path).unwrap();
        let (_, d) = shaping_compiler::check(&src, "ui.bat");
        for e in d.errors() {
            let help = e.help().map(|h| h.to_string()).unwrap_or_default();
            let name = path.display();
            match e.suggestion().and_then(|s| s.in_source(&src)) {
                Some(Suggestion::Replace { span, with }) => {
                    let old = &src[span.start..span.end];
                    assert!(
                        !old.is_empty() && old.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'),
                        "{name}: `{e}` would replace `{old}` by `{with}`"
                    );
                    assert_ne!(old, with, "{name}: `{e}`");
                    // applied, this diagnostic goes away
                    let mut fixed = src.clone();
                    fixed.replace_range(span.start..span.end, &with);
                    let (_, after) = shaping_compiler::check(&fixed, "ui.bat");
                    let at = |x: &shaping_compiler::Error| {
                        x.labels().and_then(|mut l| l.next()).map(|l| l.offset())
                    };
                    let same = |x: &shaping_compiler::Error| x.to_string() == e.to_string() && at(x) == at(e);
                    assert!(
                        !after.errors().iter().any(same),
                        "{name}: `{e}` stays after replacing `{old}` by `{with}`"
                    );
                    replaced += 1;
                }
                Some(Suggestion::Declare { line }) => {
                    let fixes = ide::fixes(&src, e);
                    assert_eq!(fixes.len(), 1, "{name}: `{e}`");
                    assert!(fixes[0].edits[0].1.contains(&line));
                    declared += 1;
                }
                None => {
                    // (a suggestion whose word is not in its label is dropped)
                    assert!(
                        e.suggestion().is_none(),
                        "{name}: `{e}`: a suggestion whose word is not in its label"
                    );
                    assert!(
                        !help.contains("did you mean `"),
                        "{name}: `{e}`: a did-you-mean without a fix: {help}"
                    );
                    let declares = help.starts_with("declare")
                        && (help.contains("`actuator ") || help.contains("`sensor "));
                    assert!(!declares, "{name}: `{e}`: a declare hint without a fix: {help}");
                }
            }
        }
    }
    assert!(replaced > 20 && declared >= 2, "{replaced} replacements, {declared} declarations");
}
