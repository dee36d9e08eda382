//! `shaping fmt` and `shaping lsp`, run as an editor runs them; the VS Code
//! extension's TextMate grammar.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

use serde_json::{json, Value};

fn shaping() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shaping"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn example(name: &str) -> String {
    std::fs::read_to_string(root().join("examples").join(name)).unwrap()
}

// ------------------------------------------------------------------ fmt

#[test]
fn fmt_formats_stdin_and_files_and_checks() {
    let dir = std::env::temp_dir().join(format!("shaping-fmt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let messy = "robot r{sensor ir[8] proximity   actuator wheels[2] speed}\nstage s { fitness per action wheels[0]\nmodule m { sense ir  behavior forward } }\n";
    let tidy = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\nstage s {\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n";
    // stdin to stdout
    let mut child = shaping().arg("fmt").stdin(Stdio::piped()).stdout(Stdio::piped()).spawn().unwrap();
    child.stdin.take().unwrap().write_all(messy.as_bytes()).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    assert_eq!(String::from_utf8_lossy(&out.stdout), tidy);
    // --check names the file and exits 1; fmt rewrites it; --check then passes
    let a = dir.join("a.bat");
    std::fs::write(&a, messy).unwrap();
    let out = shaping().arg("fmt").arg("--check").arg(&a).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("a.bat"));
    assert_eq!(std::fs::read_to_string(&a).unwrap(), messy);
    assert!(shaping().arg("fmt").arg(&a).status().unwrap().success());
    assert_eq!(std::fs::read_to_string(&a).unwrap(), tidy);
    assert!(shaping().arg("fmt").arg("--check").arg(&a).status().unwrap().success());
    // a file that does not parse is left untouched, with the error
    let b = dir.join("b.bat");
    std::fs::write(&b, "robot r {\n").unwrap();
    let out = shaping().arg("fmt").arg(&b).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not parse"));
    assert_eq!(std::fs::read_to_string(&b).unwrap(), "robot r {\n");
    let _ = std::fs::remove_dir_all(&dir);
}

// ------------------------------------------------------------------ lsp

struct Client {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
    next_id: i64,
}

impl Client {
    fn start() -> Client {
        let mut child = shaping()
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("shaping lsp starts");
        let stdin = child.stdin.take().unwrap();
        let stdout = BufReader::new(child.stdout.take().unwrap());
        let mut c = Client { child, stdin, stdout, next_id: 1 };
        let r = c.request("initialize", json!({ "capabilities": {}, "processId": null, "rootUri": null }));
        assert!(r["result"]["capabilities"]["hoverProvider"].as_bool().unwrap_or(false), "{r}");
        c.notify("initialized", json!({}));
        c
    }

    fn send(&mut self, v: Value) {
        let body = v.to_string();
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).unwrap();
        self.stdin.flush().unwrap();
    }

    fn read(&mut self) -> Value {
        let mut len = 0;
        loop {
            let mut line = String::new();
            assert!(self.stdout.read_line(&mut line).unwrap() > 0, "the server closed its output");
            let line = line.trim_end();
            if line.is_empty() {
                break;
            }
            if let Some(n) = line.strip_prefix("Content-Length: ") {
                len = n.parse().unwrap();
            }
        }
        let mut body = vec![0; len];
        self.stdout.read_exact(&mut body).unwrap();
        serde_json::from_slice(&body).unwrap()
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    /// Sends a request and returns its response (skipping notifications).
    fn request(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        self.send(json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }));
        loop {
            let m = self.read();
            if m["id"] == json!(id) {
                return m;
            }
        }
    }

    /// Waits for the next diagnostics.
    fn diagnostics(&mut self) -> Vec<Value> {
        loop {
            let m = self.read();
            if m["method"] == "textDocument/publishDiagnostics" {
                return m["params"]["diagnostics"].as_array().unwrap().clone();
            }
        }
    }

    fn open(&mut self, uri: &str, text: &str) -> Vec<Value> {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": uri, "languageId": "shaping", "version": 1, "text": text } }),
        );
        self.diagnostics()
    }

    fn change(&mut self, uri: &str, version: i64, text: &str) -> Vec<Value> {
        self.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": version }, "contentChanges": [{ "text": text }] }),
        );
        self.diagnostics()
    }

    fn at(&mut self, method: &str, uri: &str, text: &str, needle: &str, extra: usize) -> Value {
        let mut off =
            (text.find(needle).unwrap_or_else(|| panic!("{needle} not in the text")) + extra).min(text.len());
        while !text.is_char_boundary(off) {
            off -= 1;
        }
        let line = text[..off].matches('\n').count();
        let col = off - text[..off].rfind('\n').map_or(0, |i| i + 1);
        self.request(
            method,
            json!({ "textDocument": { "uri": uri }, "position": { "line": line, "character": col },
                    "context": { "includeDeclaration": true } }),
        )
    }

    fn stop(mut self) {
        let r = self.request("shutdown", Value::Null);
        assert!(r.get("error").is_none(), "{r}");
        self.notify("exit", Value::Null);
        assert!(self.child.wait().unwrap().success());
    }
}

const URI: &str = "file:///work/khepera.bat";

#[test]
fn diagnostics_as_you_type_with_related_information() {
    let mut c = Client::start();
    let src = example("khepera.bat");
    assert_eq!(c.open(URI, &src), Vec::<Value>::new());
    // a misspelt sensor and an index out of range, reported at once
    let bad =
        src.replacen("sense light, battery", "sense ligth, battery", 1).replacen("ir[0..5]", "ir[0..9]", 1);
    let d = c.change(URI, 2, &bad);
    assert_eq!(d.len(), 2, "{d:?}");
    let ligth = &d.iter().find(|d| d["message"].as_str().unwrap().contains("ligth")).unwrap();
    assert!(ligth["message"].as_str().unwrap().contains("did you mean `light`?"), "{ligth}");
    let line = bad[..bad.find("sense ligth").unwrap()].matches('\n').count();
    assert_eq!(ligth["range"]["start"]["line"], json!(line));
    // a module declared twice: the first declaration is related information
    let twice = src.replacen("module follow", "module wander", 1);
    let d = c.change(URI, 3, &twice);
    let dup = d.iter().find(|d| d["relatedInformation"].is_array()).expect("related information");
    assert_eq!(dup["relatedInformation"][0]["location"]["uri"], json!(URI));
    // fixed again
    assert_eq!(c.change(URI, 4, &src), Vec::<Value>::new());
    c.stop();
}

#[test]
fn warnings_have_the_warning_severity() {
    let mut c = Client::start();
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n\
               stage s { fitness per action wheels[0]  module wander { sense ir  behavior forward } }\n\
               stage t extends s { module wandr { sense ir  behavior back } }\n";
    let d = c.open(URI, src);
    assert_eq!(d.len(), 1, "{d:?}");
    // 2 is `DiagnosticSeverity::WARNING`
    assert_eq!(d[0]["severity"], json!(2), "{d:?}");
    assert!(d[0]["message"].as_str().unwrap().contains("`wandr`"), "{d:?}");
    assert_eq!(d[0]["relatedInformation"][0]["message"], json!("inherited from stage `s`"));
    c.stop();
}

#[test]
fn hover_definition_references_completion_symbols_and_formatting() {
    let mut c = Client::start();
    let src = example("khepera.bat");
    c.open(URI, &src);
    // hover a module: its genes in the stage
    // (the first `wander` is the training stage's, which has no genes)
    let h = c.at("textDocument/hover", URI, &src, "module wander {\n    sense ir\n    activation fixed", 8);
    let md = h["result"]["contents"]["value"].as_str().unwrap().to_string();
    assert!(md.contains("stage `avoidance`") && md.contains("no genes in this stage"), "{md}");
    let h = c.at("textDocument/hover", URI, &src, "module wander {\n    sense ir\n    behavior forward", 8);
    let md = h["result"]["contents"]["value"].as_str().unwrap().to_string();
    assert!(md.contains("module `wander`") && md.contains("bias") && md.contains("evolvable"), "{md}");
    assert!(md.contains("senses: ir[0]"), "{md}");
    // a module whose behavior a training stage learned
    let h = c.at("textDocument/hover", URI, &src, "module avoid {\n    sense ir\n    behavior neural", 8);
    let md = h["result"]["contents"]["value"].as_str().unwrap().to_string();
    assert!(md.contains("trained: `avoid` behavior, 18 weights"), "{md}");
    // hover a sensor and a stage
    let h = c.at("textDocument/hover", URI, &src, "sensor light", 8);
    assert!(h["result"]["contents"]["value"].as_str().unwrap().contains("channels 8..15"), "{h}");
    let h = c.at("textDocument/hover", URI, &src, "stage collect", 7);
    let md = h["result"]["contents"]["value"].as_str().unwrap();
    assert!(md.contains("grip") && md.contains("genes:"), "{md}");
    // definition of a stage from its `extends`
    let d = c.at("textDocument/definition", URI, &src, "extends navigation", 9);
    let want = src[..src.find("stage navigation").unwrap()].matches('\n').count();
    assert_eq!(d["result"][0]["range"]["start"]["line"], json!(want), "{d}");
    // references of a sensor
    let r = c.at("textDocument/references", URI, &src, "sensor battery", 8);
    assert!(r["result"].as_array().unwrap().len() >= 5, "{r}");
    // completion offers the names
    let comp = c.at("textDocument/completion", URI, &src, "links all", 0);
    let labels: Vec<&str> =
        comp["result"].as_array().unwrap().iter().filter_map(|i| i["label"].as_str()).collect();
    for want in ["wander", "navigation", "light", "claw", "module", "evolvable"] {
        assert!(labels.contains(&want), "{want} missing from {labels:?}");
    }
    // document symbols: the robot and the stages with their modules
    let s = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    let names: Vec<&str> =
        s["result"].as_array().unwrap().iter().filter_map(|s| s["name"].as_str()).collect();
    assert_eq!(names, ["khepera", "avoidance", "navigation", "collect", "bigger"]);
    assert_eq!(s["result"][1]["children"].as_array().unwrap().len(), 2, "the training stage's modules");
    assert_eq!(s["result"][2]["children"].as_array().unwrap().len(), 4);
    // formatting: the same as `shaping fmt`
    let messy = src.replace("  module wander {", "module   wander{");
    c.change(URI, 2, &messy);
    let f = c.request(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": URI }, "options": { "tabSize": 2, "insertSpaces": true } }),
    );
    let new_text = f["result"][0]["newText"].as_str().unwrap();
    let mut child = shaping().arg("fmt").stdin(Stdio::piped()).stdout(Stdio::piped()).spawn().unwrap();
    child.stdin.take().unwrap().write_all(messy.as_bytes()).unwrap();
    let expected = child.wait_with_output().unwrap();
    assert_eq!(new_text, String::from_utf8_lossy(&expected.stdout));
    c.stop();
}

/// A thousand random edits of an example: every one gets diagnostics and a
/// response to a request, and the server survives.
#[test]
fn random_edits_never_crash_the_server() {
    let mut c = Client::start();
    let mut text = example("khepera.bat");
    c.open(URI, &text);
    let pieces = [
        "{",
        "}",
        "(",
        "module",
        " ",
        "\n",
        "ir[",
        "..",
        "?",
        "-",
        "stage x extends",
        "//",
        "/*",
        "é",
        "0.5",
    ];
    let mut rng: u64 = 0x5eed;
    let mut next = |n: usize| {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng % n as u64) as usize
    };
    for version in 2..1002 {
        let mut at = next(text.len() + 1);
        while !text.is_char_boundary(at) {
            at -= 1;
        }
        if next(2) == 0 && at < text.len() {
            let mut end = (at + 1 + next(8)).min(text.len());
            while !text.is_char_boundary(end) {
                end += 1;
            }
            text.replace_range(at..end, "");
        } else {
            text.insert_str(at, pieces[next(pieces.len())]);
        }
        c.change(URI, version, &text);
        let method = [
            "textDocument/hover",
            "textDocument/completion",
            "textDocument/definition",
            "textDocument/formatting",
        ][next(4)];
        let r = c.at(method, URI, &text, "", next(text.len() + 1));
        assert!(r.get("result").is_some(), "{method} after edit {version}: {r}");
    }
    c.stop();
}

// ------------------------------------------------------------------ TextMate grammar

/// The grammar is valid JSON and every regular expression of it compiles
/// (with `regex`, whose syntax is a subset of Oniguruma's for these patterns).
#[test]
fn textmate_grammar_is_valid() {
    let text =
        std::fs::read_to_string(root().join("editors/vscode/syntaxes/shaping.tmLanguage.json")).unwrap();
    let g: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(g["scopeName"], "source.shaping");
    let pkg: Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("editors/vscode/package.json")).unwrap())
            .unwrap();
    assert_eq!(pkg["contributes"]["grammars"][0]["scopeName"], "source.shaping");
    let mut n = 0;
    fn walk(v: &Value, n: &mut usize) {
        match v {
            Value::Object(m) => {
                for (k, v) in m {
                    if matches!(k.as_str(), "match" | "begin" | "end") {
                        *n += 1;
                        assert!(v.as_str().is_some_and(|s| !s.is_empty()), "{k}: {v}");
                    }
                    walk(v, n);
                }
            }
            Value::Array(a) => a.iter().for_each(|v| walk(v, n)),
            _ => {}
        }
    }
    walk(&g, &mut n);
    assert!(n > 10);
}
