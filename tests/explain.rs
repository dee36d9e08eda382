//! `shaping explain CODE`, and the codes in `check`'s output.

use std::process::Command;

fn shaping() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shaping"))
}

#[test]
fn explain_prints_every_code_with_its_examples() {
    for e in shaping_compiler::explain::EXPLANATIONS {
        let out = shaping().args(["explain", &e.code.to_lowercase()]).output().unwrap();
        assert!(out.status.success(), "{}", e.code);
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(text.starts_with(&format!("{}: {}", e.code, e.title)), "{text}");
        assert!(text.contains("For example, this file:") && text.contains("is fixed so:"), "{text}");
    }
    let out = shaping().args(["explain", "S9999"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no diagnostic has the code `S9999`"));
}

#[test]
fn check_shows_the_code_in_text_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a.bat");
    let e = shaping_compiler::explain::explain("S0006").unwrap();
    std::fs::write(&file, e.wrong).unwrap();
    let out = shaping().arg("check").arg("--error-format").arg("plain").arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("Error: S0006"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = shaping().arg("check").arg("--error-format").arg("json").arg(&file).output().unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["related"][0]["code"], "S0006", "{v}");
}
