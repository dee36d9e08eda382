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
        let body = self.read_raw();
        serde_json::from_slice(&body).unwrap()
    }

    /// The body of the next message, as the server wrote it.
    fn read_raw(&mut self) -> Vec<u8> {
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
        body
    }

    /// Writes bytes as they are.
    fn send_raw(&mut self, bytes: &[u8]) {
        self.stdin.write_all(bytes).unwrap();
        self.stdin.flush().unwrap();
    }

    /// The next response (skipping notifications), as written.
    fn response_raw(&mut self) -> String {
        loop {
            let body = String::from_utf8(self.read_raw()).unwrap();
            let m: Value = serde_json::from_str(&body).unwrap();
            if m.get("method").is_none() {
                return body;
            }
        }
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
        let mut params =
            json!({ "textDocument": { "uri": uri }, "position": { "line": line, "character": col } });
        if method == "textDocument/references" {
            params["context"] = json!({ "includeDeclaration": true });
        }
        if method == "textDocument/formatting" {
            params["options"] = json!({ "tabSize": 2, "insertSpaces": true });
        }
        self.request(method, params)
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
    assert_eq!(ligth["code"], json!("S0006"), "{ligth}");
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
    // completion in a stage's body offers what a stage may hold
    let comp = c.at("textDocument/completion", URI, &src, "links all", 0);
    let labels: Vec<&str> =
        comp["result"].as_array().unwrap().iter().filter_map(|i| i["label"].as_str()).collect();
    for want in ["module", "links", "link", "world", "evolve", "fitness", "test", "train", "genome", "robot"]
    {
        assert!(labels.contains(&want), "{want} missing from {labels:?}");
    }
    assert!(!labels.contains(&"wander") && !labels.contains(&"sense"), "{labels:?}");
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

/// Roles in the editor: the outline holds a stage's roles and each role its
/// modules; the definition of a module named in a role's link is that
/// role's module, though another role has one of the same name.
#[test]
fn roles_in_the_outline_and_definitions() {
    let mut c = Client::start();
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n\
               stage s {\n  world { arena 600mm x 600mm }\n  fitness per action wheels[0]\n\
               role a robots 2 {\n    module go { sense ir  behavior forward }\n    module turn { sense ir  behavior turn left }\n    links all evolvable\n  }\n\
               role b robots 1 {\n    module go { sense ir  behavior back }\n    module stay { sense ir  behavior stop }\n    link go -> stay evolvable\n  }\n}\n";
    c.open(URI, src);
    let s = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    let stage = &s["result"][1];
    assert_eq!(stage["name"], json!("s"), "{s}");
    let roles: Vec<(&str, Vec<&str>)> = stage["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let kids = r["children"].as_array().unwrap().iter().filter_map(|m| m["name"].as_str()).collect();
            (r["name"].as_str().unwrap(), kids)
        })
        .collect();
    assert_eq!(roles, [("a", vec!["go", "turn"]), ("b", vec!["go", "stay"])]);
    let d = c.at("textDocument/definition", URI, src, "link go -> stay", 5);
    let line = src[..src.find("module go { sense ir  behavior back").unwrap()].matches('\n').count();
    assert_eq!(d["result"][0]["range"]["start"]["line"], json!(line), "role b's `go`: {d}");
    c.stop();
}

/// A thousand random edits of an example, mended every 20: every one gets
/// diagnostics and a response to a request, hover answers on the modules of
/// the stages the edits left alone, and the server survives.
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
    // Each stage of the example, and its first module: while the stage's
    // text stands untouched (and outside a comment), hover on that module
    // answers whatever the edits did elsewhere.
    let stages: Vec<(String, String)> = split_stages(&text)
        .into_iter()
        .filter_map(|st| {
            let m = st.split("module ").nth(1)?.split_whitespace().next()?.to_string();
            Some((st, m))
        })
        .collect();
    assert_eq!(stages.len(), 3, "the stages with modules");
    let mut hovered = 0;
    let mut rng: u64 = 0x5eed;
    let mut next = |n: usize| {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng % n as u64) as usize
    };
    let original = text.clone();
    for version in 2..1002 {
        // Every 20 edits, the file is mended (the example again).
        if version % 20 == 0 {
            text = original.clone();
        }
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
        // formatting a file that does not parse answers an error saying so
        let formatting_refused = method == "textDocument/formatting"
            && r["error"]["message"].as_str().is_some_and(|m| m.contains("left as it is"));
        assert!(r.get("result").is_some() || formatting_refused, "{method} after edit {version}: {r}");
        let (stage, module) = &stages[next(stages.len())];
        if let Some(at) = text.find(stage.as_str()).filter(|&at| !commented(&text, at)) {
            let needle = format!("module {module}");
            let off = at + stage.find(&needle).unwrap() + 7;
            let h = c.at("textDocument/hover", URI, &text, "", off);
            let md = h["result"]["contents"]["value"].as_str().unwrap_or_default();
            assert!(
                md.contains(&format!("module `{module}`")),
                "hover on `{module}` after edit {version}: {h}"
            );
            hovered += 1;
        }
    }
    assert!(hovered > 200, "only {hovered} hovers on untouched modules");
    c.stop();
}

/// The stages of a file: from each `stage` at the start of a line to the
/// `}` alone on a line that closes it.
fn split_stages(text: &str) -> Vec<String> {
    text.split("\nstage ").skip(1).map(|s| format!("stage {}\n}}", s.split("\n}").next().unwrap())).collect()
}

/// Whether `at` is inside a comment (a `//` line or a `/* */` block,
/// unterminated ones included).
fn commented(text: &str, at: usize) -> bool {
    let b = text.as_bytes();
    let mut i = 0;
    while i < at {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            if i > at {
                return true;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            i += 2;
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                i += 1;
            }
            if i >= at {
                return true;
            }
            i += 2;
        } else {
            i += 1;
        }
    }
    false
}

/// A file with syntax errors in two stages: the other stages keep hover
/// (with their genes), definition, references and symbols; every syntax
/// error is published.
#[test]
fn a_broken_file_keeps_its_intact_parts() {
    let mut c = Client::start();
    let src = example("khepera.bat");
    c.open(URI, &src);
    let bad = src
        .replacen("behavior forward(1.0)\n  }\n\n  // Starts", "behavior forward(\n  }\n\n  // Starts", 1)
        .replacen("world adds { objects 8 diameter 10mm virtual }", "world adds { objects 8 diameter }", 1);
    let d = c.change(URI, 2, &bad);
    assert_eq!(d.len(), 2, "{d:?}");
    let line_of = |needle: &str| bad[..bad.find(needle).unwrap()].matches('\n').count();
    assert_eq!(d[0]["range"]["start"]["line"], json!(line_of("behavior forward(\n") + 1));
    assert_eq!(d[1]["range"]["start"]["line"], json!(line_of("diameter }")));
    // hover on a module of the intact stage `navigation`: its genes
    let h = c.at("textDocument/hover", URI, &bad, "module follow", 8);
    let md = h["result"]["contents"]["value"].as_str().unwrap();
    assert!(md.contains("module `follow`") && md.contains("bias") && md.contains("senses: light[0]"), "{md}");
    // and on a module of the broken stage `collect` that parses
    let h = c.at("textDocument/hover", URI, &bad, "module grip", 8);
    assert!(h["result"]["contents"]["value"].as_str().unwrap().contains("module `grip`"), "{h}");
    // definition of a stage, references of a module
    let d = c.at("textDocument/definition", URI, &bad, "extends navigation", 9);
    assert_eq!(d["result"][0]["range"]["start"]["line"], json!(line_of("stage navigation")), "{d}");
    let r = c.at("textDocument/references", URI, &bad, "module avoid", 8);
    assert_eq!(r["result"].as_array().unwrap().len(), 2, "{r}");
    // symbols: every stage; `navigation` without the module that broke
    let s = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    let names: Vec<&str> =
        s["result"].as_array().unwrap().iter().filter_map(|s| s["name"].as_str()).collect();
    assert_eq!(names, ["khepera", "avoidance", "navigation", "collect", "bigger"]);
    let modules: Vec<&str> =
        s["result"][2]["children"].as_array().unwrap().iter().filter_map(|s| s["name"].as_str()).collect();
    assert_eq!(modules, ["avoid", "follow", "recharge"]);
    c.stop();
}

/// The labels completion offers at the end of `needle` in `text`.
fn completions(c: &mut Client, text: &str, needle: &str) -> Vec<String> {
    c.change(URI, 2, text);
    let r = c.at("textDocument/completion", URI, text, needle, needle.len());
    r["result"].as_array().unwrap().iter().filter_map(|i| i["label"].as_str().map(str::to_string)).collect()
}

const TUTOR: &str = "robot r {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  actuator wheels[2] speed
}
stage practice {
  train for 100 actions
  module avoid { sense ir  activation fixed 0  behavior stop }
}
stage first {
  fitness per action wheels[0]
  module go { sense ir[2..3]  behavior forward }
}
stage second extends first {
  robot adds { sensor battery level }
  world { arena 400mm x 600mm  charger 200mm on north wall }
  module turn { sense ir  behavior turn left }
  module steer {
    sense ir
    behavior neural { outputs sign(1) -> forward | back  weights trained practice }
  }
  link turn -> go evolvable
}
";

#[test]
fn completion_after_sense_offers_the_sensors() {
    let mut c = Client::start();
    c.open(URI, TUTOR);
    // in `second`, which adds the battery
    let text = TUTOR.replacen("module turn { sense ir", "module turn { sense ", 1);
    let labels = completions(&mut c, &text, "module turn { sense ");
    assert_eq!(labels, ["ir", "light", "battery"]);
    // in a list, and while typing a name
    let text = TUTOR.replacen("module go { sense ir[2..3]", "module go { sense ir[2..3], li", 1);
    assert_eq!(completions(&mut c, &text, "ir[2..3], li"), ["ir", "light"], "`first` has no battery");
    c.stop();
}

#[test]
fn completion_after_link_and_arrow_offers_the_stages_modules() {
    let mut c = Client::start();
    c.open(URI, TUTOR);
    let text = TUTOR.replacen("link turn -> go", "link ", 1);
    assert_eq!(completions(&mut c, &text, "link "), ["go", "turn", "steer"]);
    let text = TUTOR.replacen("link turn -> go", "link turn -> ", 1);
    assert_eq!(completions(&mut c, &text, "link turn -> "), ["go", "turn", "steer"]);
    c.stop();
}

#[test]
fn completion_after_extends_and_trained_offers_the_stages() {
    let mut c = Client::start();
    c.open(URI, TUTOR);
    let text = TUTOR.replacen("stage second extends first", "stage second extends ", 1);
    assert_eq!(completions(&mut c, &text, "stage second extends "), ["practice", "first"]);
    let text = TUTOR.replacen("weights trained practice", "weights trained ", 1);
    assert_eq!(completions(&mut c, &text, "weights trained "), ["practice"], "training stages only");
    c.stop();
}

#[test]
fn completion_in_a_world_offers_its_items() {
    let mut c = Client::start();
    c.open(URI, TUTOR);
    let labels = completions(&mut c, TUTOR, "world { arena 400mm x 600mm ");
    for want in ["arena", "charger", "battery", "recharge", "objects", "body"] {
        assert!(labels.contains(&want.to_string()), "{want} missing from {labels:?}");
    }
    assert!(!labels.contains(&"module".to_string()), "{labels:?}");
    assert_eq!(completions(&mut c, TUTOR, "charger 200mm on "), ["north", "south", "east", "west"]);
    c.stop();
}

#[test]
fn completion_after_a_motion_offers_the_motions() {
    let mut c = Client::start();
    c.open(URI, TUTOR);
    for needle in ["sign(1) -> ", "sign(1) -> forward | ", "module go { sense ir[2..3]  behavior "] {
        let labels = completions(&mut c, TUTOR, needle);
        for want in ["forward", "back", "turn left", "stop", "wheels(0.5, 0.5)"] {
            assert!(labels.contains(&want.to_string()), "after `{needle}`: {want} missing from {labels:?}");
        }
        assert!(!labels.contains(&"ir".to_string()), "{labels:?}");
    }
    c.stop();
}

/// Completion offers exactly what the compiler accepts where the cursor is.
#[test]
fn completion_by_context_everywhere() {
    let mut c = Client::start();
    c.open(URI, TUTOR);
    let has = |labels: &[String], want: &[&str], not: &[&str], at: &str| {
        for w in want {
            assert!(labels.contains(&w.to_string()), "at `{at}`: {w} missing from {labels:?}");
        }
        for w in not {
            assert!(!labels.contains(&w.to_string()), "at `{at}`: {w} offered in {labels:?}");
        }
    };
    // after `behavior`: the steps, not the decoding table's bare turns
    let at = "module go { sense ir[2..3]  behavior ";
    let labels = completions(&mut c, TUTOR, at);
    has(
        &labels,
        &["script", "neural", "toward", "wait", "recharge", "forward", "turn", "stop", "wheels(0.5, 0.5)"],
        &["left", "right", "ir", "module"],
        at,
    );
    // in a module's body: what a module may hold
    let text = TUTOR.replacen(
        "module go { sense ir[2..3]  behavior forward }",
        "module go { sense ir[2..3]
    
  behavior forward }",
        1,
    );
    let labels = completions(
        &mut c,
        &text,
        "sense ir[2..3]
    ",
    );
    assert_eq!(labels, ["sense", "activation", "behavior", "learn", "reinforce"], "module body");
    // at the top level
    let labels = completions(&mut c, TUTOR, "  actuator wheels[2] speed\n}\n");
    assert_eq!(labels, ["robot", "genome", "stage"], "top level");
    // in `evolve { }`
    let text = TUTOR.replacen(
        "fitness per action wheels[0]",
        "fitness per action wheels[0]
  evolve { population 10  }",
        1,
    );
    let labels = completions(&mut c, &text, "evolve { population 10 ");
    has(
        &labels,
        &["population", "generations", "evaluations", "elitism", "selection"],
        &["module", "arena", "sense"],
        "evolve",
    );
    // in a fitness expression: functions and the hardware
    let text = TUTOR.replacen("fitness per action wheels[0]", "fitness per action wheels[0] * ", 1);
    let labels = completions(&mut c, &text, "wheels[0] * ");
    has(&labels, &["max", "abs", "not", "prev", "ir", "wheels"], &["module", "population"], "fitness");
    // after a number and `per`: the events
    let text = TUTOR.replacen("fitness per action wheels[0]", "fitness per action wheels[0], 0.5 per ", 1);
    let labels = completions(&mut c, &text, "0.5 per ");
    has(&labels, &["grip", "release", "collision", "recharge"], &["action", "module"], "bonus");
    // after `sensor NAME`: the kinds of the catalog
    let text = TUTOR.replacen("sensor light[8]    ambient", "sensor light[8] ", 1);
    let labels = completions(&mut c, &text, "sensor light[8] ");
    has(
        &labels,
        &["proximity", "ambient", "level", "optical", "ground", "lamp_distance"],
        &["speed"],
        "sensor kind",
    );
    // after `module` in a later stage: the inherited modules, to change one
    let text = TUTOR.replacen("module turn {", "module  turn {", 1);
    assert_eq!(completions(&mut c, &text, "module  "), ["go"]);
    c.stop();
}

#[test]
fn hover_on_keywords_says_what_they_mean_with_a_link() {
    let mut c = Client::start();
    let src = example("khepera.bat");
    c.open(URI, &src);
    for (needle, word, section) in [
        ("toward(", "toward", "10-scripts"),
        ("evolve {", "evolve", "7-evolution"),
        ("sense ", "sense", "9-modules"),
        ("proximity", "proximity", "3-the-robot"),
    ] {
        let h = c.at("textDocument/hover", URI, &src, needle, 1);
        let md = h["result"]["contents"]["value"].as_str().unwrap_or_default();
        assert!(md.starts_with(&format!("**`{word}`**: ")), "{needle}: {h}");
        assert!(md.contains(&format!("docs/language.md#{section}")), "{needle}: {md}");
    }
    c.stop();
}

#[test]
fn quick_fixes_for_did_you_mean_and_declare_hints() {
    let mut c = Client::start();
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n\
               stage s {\n  fitness per action wheels[0]\n\
               module m { sense irr  behavior script { claw closed; forward } }\n}\n";
    let d = c.open(URI, src);
    assert_eq!(d.len(), 2, "{d:?}");
    let actions = c.request(
        "textDocument/codeAction",
        json!({ "textDocument": { "uri": URI }, "range": { "start": { "line": 0, "character": 0 }, "end": { "line": 5, "character": 0 } },
                "context": { "diagnostics": [] } }),
    );
    let list = actions["result"].as_array().unwrap();
    let titles: Vec<&str> = list.iter().filter_map(|a| a["title"].as_str()).collect();
    assert_eq!(titles, ["replace with `ir`", "declare `actuator claw grip` in the robot"], "{actions}");
    // applied, the file compiles
    let mut fixed = src.to_string();
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    for a in list {
        for e in a["edit"]["changes"][URI].as_array().unwrap() {
            let off = |p: &Value| {
                let line = p["line"].as_u64().unwrap() as usize;
                let start: usize = src.split_inclusive('\n').take(line).map(str::len).sum();
                start + p["character"].as_u64().unwrap() as usize
            };
            edits.push((
                off(&e["range"]["start"]),
                off(&e["range"]["end"]),
                e["newText"].as_str().unwrap().into(),
            ));
        }
    }
    edits.sort_by_key(|e| std::cmp::Reverse(e.0));
    for (a, b, t) in edits {
        fixed.replace_range(a..b, &t);
    }
    assert_eq!(c.change(URI, 2, &fixed), Vec::<Value>::new(), "{fixed}");
    c.stop();
}

#[test]
fn rename_modules_and_stages() {
    let mut c = Client::start();
    c.open(URI, TUTOR);
    // a module: its declarations and every use
    let p = c.at("textDocument/prepareRename", URI, TUTOR, "link turn", 6);
    assert_eq!(p["result"]["placeholder"], json!("turn"), "{p}");
    let pos = |needle: &str, extra: usize| {
        let off = TUTOR.find(needle).unwrap() + extra;
        json!({ "line": TUTOR[..off].matches('\n').count(), "character": off - TUTOR[..off].rfind('\n').map_or(0, |i| i + 1) })
    };
    let r = c.request(
        "textDocument/rename",
        json!({ "textDocument": { "uri": URI }, "position": pos("module go", 8), "newName": "ahead" }),
    );
    let edits = r["result"]["changes"][URI].as_array().unwrap();
    assert_eq!(edits.len(), 2, "{r}");
    // a stage: its declaration, `extends` and nothing else
    let r = c.request(
        "textDocument/rename",
        json!({ "textDocument": { "uri": URI }, "position": pos("extends first", 9), "newName": "basic" }),
    );
    assert_eq!(r["result"]["changes"][URI].as_array().unwrap().len(), 2, "{r}");
    // refused: a sensor, a reserved word, a name in use
    let p = c.at("textDocument/prepareRename", URI, TUTOR, "sense ir", 7);
    assert_eq!(p["result"], Value::Null, "{p}");
    for (name, why) in
        [("module", "reserved"), ("steer", "already the name of a module"), ("2x", "not a name")]
    {
        let r = c.request(
            "textDocument/rename",
            json!({ "textDocument": { "uri": URI }, "position": pos("module go", 8), "newName": name }),
        );
        assert!(r["error"]["message"].as_str().unwrap_or_default().contains(why), "{name}: {r}");
    }
    c.stop();
}

// ------------------------------------------------------------------ the protocol

/// A body in a frame of the base protocol.
fn framed(body: &[u8]) -> Vec<u8> {
    let mut out = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    out.extend_from_slice(body);
    out
}

/// After the message or bytes that went before: a request is still
/// answered, with its results.
fn still_serving(c: &mut Client) {
    let src = example("khepera.bat");
    c.open(URI, &src);
    let s = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    assert_eq!(s["result"].as_array().map(Vec::len), Some(5), "{s}");
}

#[test]
fn a_malformed_message_gets_a_parse_error_and_the_server_keeps_serving() {
    let mut c = Client::start();
    let cases: [(&[u8], i64); 7] = [
        (b"{\"jsonrpc\": \"2.0\", \"id\": 1, \"method\": ", -32700),
        (b"{1: 2}", -32700),
        (b"\xff\xfe{}", -32700),
        (b"{\"jsonrpc\": \"2.0\", \"id\": 1, \"method\": \"textDocument/hover\", \"params\": \"\xc3\x28\"}", -32700),
        (
            br#"{"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": { "textDocument": { "uri": "file:///a.bat", "languageId": "shaping", "version": 1, "text": "robot \ud800 r" } } }"#,
            -32700,
        ),
        (br#"[{"jsonrpc": "2.0", "id": 1, "method": "shutdown"}]"#, -32600),
        (b"17", -32600),
    ];
    for (body, code) in cases {
        c.send_raw(&framed(body));
        let r: Value = serde_json::from_str(&c.response_raw()).unwrap();
        assert_eq!(r["error"]["code"], json!(code), "{}: {r}", String::from_utf8_lossy(body));
        assert_eq!(r["id"], Value::Null, "{r}");
        assert!(!r["error"]["message"].as_str().unwrap().is_empty());
        still_serving(&mut c);
    }
    c.stop();
}

#[test]
fn bad_headers_are_skipped_and_the_next_frame_is_read() {
    let mut c = Client::start();
    let good = |id: i64| {
        framed(
            json!({ "jsonrpc": "2.0", "id": id, "method": "textDocument/documentSymbol",
                    "params": { "textDocument": { "uri": "file:///none.bat" } } })
            .to_string()
            .as_bytes(),
        )
    };
    let cases: Vec<Vec<u8>> = vec![
        b"garbage\r\n".to_vec(),
        b"Content-Type: text/plain\r\n\r\n{}".to_vec(),
        b"Content-Length: twelve\r\n\r\n{\"a\": 1}\r\n".to_vec(),
        b"Content-Length 5\r\n\r\n".to_vec(),
        format!("X-Long: {}\r\n\r\n", "x".repeat(100_000)).into_bytes(),
        b"\xff\xff\xff\r\n".to_vec(),
        // a body longer than its length: its end runs into the next frame's header
        b"Content-Length: 2\r\n\r\n{}}}".to_vec(),
    ];
    for (i, bad) in cases.iter().enumerate() {
        let id = 100 + i as i64;
        let mut bytes = bad.clone();
        bytes.extend(good(id));
        c.send_raw(&bytes);
        // (a body that is JSON but not JSON-RPC is answered with an error, id null)
        let r = loop {
            let r: Value = serde_json::from_str(&c.response_raw()).unwrap();
            if r["id"] != Value::Null {
                break r;
            }
            assert_eq!(r["error"]["code"], json!(-32600), "{r}");
        };
        assert_eq!(r["id"], json!(id), "after {:?}: {r}", String::from_utf8_lossy(bad));
        assert_eq!(r["result"], Value::Null, "{r}");
    }
    // LF alone and any case are read too
    let body = r#"{"jsonrpc":"2.0","id":7,"method":"textDocument/nothing"}"#;
    c.send_raw(format!("content-length: {}\n\n{body}", body.len()).as_bytes());
    let r: Value = serde_json::from_str(&c.response_raw()).unwrap();
    assert_eq!((r["id"].clone(), r["error"]["code"].clone()), (json!(7), json!(-32601)), "{r}");
    still_serving(&mut c);
    c.stop();
}

#[test]
fn every_id_json_rpc_allows_is_answered_with_itself() {
    let mut c = Client::start();
    let ids = [
        "0",
        "-1",
        "2147483647",
        "2147483648",
        "-2147483649",
        "9007199254740993",
        "18446744073709551615",
        "123456789012345678901234567890",
        "1.5",
        "null",
        r#""""#,
        r#""x""#,
        r#""\u00e9\ud83d\ude00 \"quoted\"""#,
    ];
    for id in ids {
        let body = format!(r#"{{"jsonrpc":"2.0","id":{id},"method":"shutdown_not","params":null}}"#);
        c.send_raw(&framed(body.as_bytes()));
        let raw = c.response_raw();
        assert!(raw.contains(&format!(r#""id":{id},"#)), "id {id}: {raw}");
        assert!(raw.contains("-32601"), "{raw}");
    }
    // an id that is an object, an array or a boolean is an invalid request
    for id in ["{}", "[1]", "true"] {
        let body = format!(r#"{{"jsonrpc":"2.0","id":{id},"method":"textDocument/hover","params":{{}}}}"#);
        c.send_raw(&framed(body.as_bytes()));
        let r: Value = serde_json::from_str(&c.response_raw()).unwrap();
        assert_eq!((r["id"].clone(), r["error"]["code"].clone()), (Value::Null, json!(-32600)), "{r}");
    }
    still_serving(&mut c);
    c.stop();
}

#[test]
fn unknown_methods_and_bad_params_get_their_errors() {
    let mut c = Client::start();
    let r = c.request("textDocument/semanticTokens/full", json!({ "textDocument": { "uri": URI } }));
    assert_eq!(r["error"]["code"], json!(-32601), "{r}");
    // an unknown notification is not answered: the next answer is the next request's
    c.notify("$/unknown", json!({}));
    c.notify("textDocument/didOpen", json!({ "nonsense": 1 }));
    for (method, params) in [
        ("textDocument/hover", json!({ "textDocument": { "uri": URI } })),
        ("textDocument/hover", json!([1, 2])),
        (
            "textDocument/completion",
            json!({ "textDocument": { "uri": 3 }, "position": { "line": 0, "character": 0 } }),
        ),
        (
            "textDocument/references",
            json!({ "textDocument": { "uri": URI }, "position": { "line": -1, "character": 0 } }),
        ),
        ("textDocument/formatting", Value::Null),
    ] {
        let r = c.request(method, params.clone());
        assert_eq!(r["error"]["code"], json!(-32602), "{method} {params}: {r}");
    }
    // initialize twice
    let r = c.request("initialize", json!({ "capabilities": {} }));
    assert_eq!(r["error"]["code"], json!(-32600), "{r}");
    still_serving(&mut c);
    c.stop();
}

#[test]
fn requests_before_initialize_and_after_shutdown_are_refused() {
    let mut child = shaping().arg("lsp").stdin(Stdio::piped()).stdout(Stdio::piped()).spawn().unwrap();
    let stdin = child.stdin.take().unwrap();
    let stdout = BufReader::new(child.stdout.take().unwrap());
    let mut c = Client { child, stdin, stdout, next_id: 1 };
    let r = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    assert_eq!(r["error"]["code"], json!(-32002), "{r}");
    let r = c.request("initialize", json!({ "capabilities": {} }));
    assert!(r["result"]["capabilities"].is_object(), "{r}");
    assert!(c.request("shutdown", Value::Null).get("error").is_none());
    let r = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    assert_eq!(r["error"]["code"], json!(-32600), "{r}");
    c.notify("exit", Value::Null);
    assert!(c.child.wait().unwrap().success());
}

/// `exit` without `shutdown` before it ends the server with status 1, as
/// the protocol says (after `shutdown`, 0: the test above).
#[test]
fn exit_without_shutdown_is_status_1() {
    let mut child = shaping().arg("lsp").stdin(Stdio::piped()).stdout(Stdio::piped()).spawn().unwrap();
    let stdin = child.stdin.take().unwrap();
    let stdout = BufReader::new(child.stdout.take().unwrap());
    let mut c = Client { child, stdin, stdout, next_id: 1 };
    let r = c.request("initialize", json!({ "capabilities": {} }));
    assert!(r["result"]["capabilities"].is_object(), "{r}");
    c.notify("exit", Value::Null);
    assert_eq!(c.child.wait().unwrap().code(), Some(1));
}

/// The input ends in the middle of a frame: every answer before it is
/// written whole, and the server exits cleanly.
#[test]
fn the_last_answers_are_written_whole_when_the_input_ends() {
    for end in ["Content-Length: 100\r\n\r\n{\"jsonrpc\"", "Content-Len", ""] {
        let mut child = shaping().arg("lsp").stdin(Stdio::piped()).stdout(Stdio::piped()).spawn().unwrap();
        let mut stdin = child.stdin.take().unwrap();
        let src = example("khepera.bat");
        let mut bytes = framed(
            json!({ "jsonrpc": "2.0", "id": 0, "method": "initialize", "params": { "capabilities": {} } })
                .to_string()
                .as_bytes(),
        );
        bytes.extend(framed(json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen",
            "params": { "textDocument": { "uri": URI, "languageId": "shaping", "version": 1, "text": src } } }).to_string().as_bytes()));
        for id in 1..=20 {
            bytes.extend(framed(
                json!({ "jsonrpc": "2.0", "id": id, "method": "textDocument/documentSymbol",
                "params": { "textDocument": { "uri": URI } } })
                .to_string()
                .as_bytes(),
            ));
        }
        bytes.extend(end.as_bytes());
        stdin.write_all(&bytes).unwrap();
        drop(stdin);
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success());
        let mut rest = &out.stdout[..];
        let mut ids = Vec::new();
        while !rest.is_empty() {
            let at = rest.windows(4).position(|w| w == b"\r\n\r\n").expect("a whole header");
            let n: usize = std::str::from_utf8(&rest[16..at]).unwrap().parse().unwrap();
            let m: Value = serde_json::from_slice(&rest[at + 4..at + 4 + n]).expect("a whole body");
            if let Some(id) = m["id"].as_i64() {
                ids.push(id);
            }
            rest = &rest[at + 4 + n..];
        }
        assert_eq!(ids, (0..=20).collect::<Vec<_>>());
    }
}

#[test]
fn formatting_a_broken_file_answers_why() {
    let mut c = Client::start();
    let bad = "robot r {\n";
    c.open(URI, bad);
    let f = c.request(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": URI }, "options": { "tabSize": 2, "insertSpaces": true } }),
    );
    let msg = f["error"]["message"].as_str().unwrap_or_default();
    assert!(msg.contains("does not parse") && msg.contains("robot"), "{f}");
    c.stop();
}

/// References of a name used on every line of a long file: linear in the
/// file (they were quadratic in the uses: 10,000 lines took seconds).
#[test]
fn references_in_a_long_file_are_fast() {
    let mut src = String::from("robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n");
    for s in 0..30 {
        src += &format!("stage s{s} {{\n  fitness per action wheels[0]\n");
        for m in 0..100 {
            src += &format!("  module m{m} {{\n    sense ir\n    behavior forward }}\n");
        }
        src += "}\n";
    }
    let mut c = Client::start();
    c.open(URI, &src);
    let start = std::time::Instant::now();
    let r = c.at("textDocument/references", URI, &src, "sensor ir", 8);
    let took = start.elapsed();
    assert_eq!(r["result"].as_array().unwrap().len(), 3001);
    let last = src.lines().count() - 3;
    assert_eq!(r["result"][3000]["range"]["start"], json!({ "line": last, "character": 10 }));
    // generous: a quadratic walk took about 2 s here, a linear one 0.05 s
    assert!(took.as_secs_f64() < 1.5, "{took:?}");
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

/// A `Content-Length` far beyond any document is refused with an error
/// naming it, before anything is allocated: no abort for want of memory.
#[test]
fn an_oversized_message_is_an_error_not_an_abort() {
    for before in [false, true] {
        let mut c = shaping()
            .arg("lsp")
            .stdin(Stdio::piped())
            .stderr(Stdio::piped())
            .stdout(Stdio::null())
            .spawn()
            .unwrap();
        let mut stdin = c.stdin.take().unwrap();
        if before {
            // After a good message too.
            let body = json!({ "jsonrpc": "2.0", "id": 1, "method": "initialize", "params": { "capabilities": {} } })
                .to_string();
            write!(stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).unwrap();
        }
        write!(stdin, "Content-Length: 99999999999\r\n\r\n{{}}").unwrap();
        drop(stdin);
        let out = c.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains("a message of 99999999999 bytes (its Content-Length) is larger than the 64 MiB"),
            "{err}"
        );
        assert!(!err.contains("memory allocation"), "{err}");
    }
}

#[test]
fn completion_in_a_body_offers_presets_settings_and_layouts() {
    let mut c = Client::start();
    let text = TUTOR.replacen(
        "fitness per action wheels[0]",
        "world { body e-puck { wheel_noise 0  proximity facing [0, 0, 0, 0, 0, 0, 0, 0] } }
  fitness per action wheels[0]",
        1,
    );
    c.open(URI, &text);
    assert_eq!(completions(&mut c, &text, "world { body "), ["khepera", "e-puck"]);
    let labels = completions(&mut c, &text, "body e-puck { wheel_noise 0 ");
    for want in ["radius", "wheel_base", "v_max", "sensor_noise", "proximity", "ground"] {
        assert!(labels.contains(&want.to_string()), "{want} missing from {labels:?}");
    }
    assert!(!labels.contains(&"arena".to_string()), "{labels:?}");
    assert_eq!(completions(&mut c, &text, "wheel_noise 0  proximity "), ["at", "facing"]);
    c.stop();
}
