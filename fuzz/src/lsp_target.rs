//! The `lsp` target: streams of random and malformed JSON-RPC frames
//! through the language server's own loop (`src/lsp`, compiled into this
//! crate as it is into `shaping`), in process, on byte buffers.
//!
//! A stream is the `initialize` request, the fuzzed bytes, then a valid
//! document and a request on it. The server must not panic (a handler's
//! panic, which it answers as an internal error, counts as one), must
//! write only whole messages of JSON, and must answer the last request
//! whatever came before, unless the fuzzed bytes legitimately end it: the
//! `exit` notification, a `Content-Length` that runs past the end of the
//! input, or one above the largest message (an error naming it). The
//! stream is padded with blank lines as long as the longest length the
//! fuzzed bytes declare (up to 1 MiB; beyond, the last request is not
//! checked), so that a body they start ends before the last frames.

use std::io::Cursor;

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde_json::{json, Value};

#[path = "../../src/lsp/mod.rs"]
#[allow(dead_code)]
mod lsp;

/// The id of the last request of a stream.
const LAST: &str = "fuzz-last-request";

pub fn frame(body: &[u8]) -> Vec<u8> {
    let mut out = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    out.extend_from_slice(body);
    out
}

/// The messages streams are made of: requests and notifications of every
/// kind the server knows (and some it does not), on the corpus's sources.
pub fn messages(sources: &[Vec<u8>]) -> Vec<Value> {
    let uri = "file:///fuzz.bat";
    let doc = json!({ "uri": uri });
    let at = |line: u32, character: u32| json!({ "textDocument": doc, "position": { "line": line, "character": character } });
    let mut out = Vec::new();
    for (i, s) in sources.iter().enumerate() {
        let text = String::from_utf8_lossy(&s[..s.len().min(4096)]).into_owned();
        let line = (i * 7 % 40) as u32;
        out.push(json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen",
            "params": { "textDocument": { "uri": uri, "languageId": "shaping", "version": 1, "text": text } } }));
        out.push(json!({ "jsonrpc": "2.0", "method": "textDocument/didChange",
            "params": { "textDocument": { "uri": uri, "version": 2 }, "contentChanges": [{ "text": text }] } }));
        for (n, method) in
            ["textDocument/hover", "textDocument/definition", "textDocument/completion"].iter().enumerate()
        {
            out.push(json!({ "jsonrpc": "2.0", "id": i * 10 + n, "method": method, "params": at(line, (i % 30) as u32) }));
        }
        let mut rename = at(line, 9);
        rename["newName"] = json!(["x", "module", "go", "2"][i % 4]);
        out.push(
            json!({ "jsonrpc": "2.0", "id": i * 10 + 5, "method": "textDocument/rename", "params": rename }),
        );
        out.push(json!({ "jsonrpc": "2.0", "id": i * 10 + 6, "method": "textDocument/prepareRename", "params": at(line, 9) }));
        out.push(json!({ "jsonrpc": "2.0", "id": i * 10 + 7, "method": "textDocument/codeAction",
            "params": { "textDocument": doc, "range": { "start": { "line": 0, "character": 0 }, "end": { "line": line, "character": 0 } },
                        "context": { "diagnostics": [] } } }));
        let mut refs = at(line, 8);
        refs["context"] = json!({ "includeDeclaration": true });
        out.push(json!({ "jsonrpc": "2.0", "id": format!("r{i}"), "method": "textDocument/references", "params": refs }));
    }
    out.push(json!({ "jsonrpc": "2.0", "id": 1, "method": "textDocument/documentSymbol", "params": { "textDocument": doc } }));
    out.push(json!({ "jsonrpc": "2.0", "id": 2, "method": "textDocument/formatting",
        "params": { "textDocument": doc, "options": { "tabSize": 2, "insertSpaces": true } } }));
    out.push(json!({ "jsonrpc": "2.0", "id": 3, "method": "shutdown" }));
    out.push(json!({ "jsonrpc": "2.0", "id": 4, "method": "initialize", "params": { "capabilities": {} } }));
    out.push(json!({ "jsonrpc": "2.0", "id": 5, "method": "workspace/symbol", "params": { "query": "" } }));
    out.push(
        json!({ "jsonrpc": "2.0", "method": "textDocument/didClose", "params": { "textDocument": doc } }),
    );
    out.push(json!({ "jsonrpc": "2.0", "method": "$/cancelRequest", "params": { "id": 1 } }));
    out.push(json!({ "jsonrpc": "2.0", "id": 6, "result": null }));
    out
}

/// Ids JSON-RPC allows and ids it does not.
const IDS: &[&str] = &[
    "0",
    "-1",
    "2147483648",
    "-2147483649",
    "18446744073709551616",
    "1e400",
    "1.5",
    "null",
    "\"\"",
    "\"\\ud800\"",
    "\"\\u00e9\"",
    "{}",
    "[]",
    "[1]",
    "true",
    "\"a\\\"b\"",
];

/// Broken frames: headers and bodies that are not the protocol.
const BROKEN: &[&[u8]] = &[
    b"garbage\r\n",
    b"Content-Length: x\r\n\r\n",
    b"Content-Length: -1\r\n\r\n{}",
    b"Content-Type: a\r\n\r\n{}",
    b"Content-Length 3\r\n\r\n{}}",
    b"Content-Length: 2\r\n\r\n{}}}",
    b"Content-Length: 0\r\n\r\n",
    b"Content-Length: 4\r\n\r\n\xff\xfe\xfd\xfc",
    b"Content-Length: 2\r\n\r\n[]",
    b"Content-Length: 6\r\n\r\n{1: 2}",
    b"Content-Length: 4\r\n\r\nnull",
    b"\r\n\r\n\r\n",
    b"Content-Length: 5\nContent-Length: 2\n\n{}",
    b"Content-Length: 99999999999\r\n\r\n",
    b"\xff\r\n",
];

/// One fuzzed stream: messages (mutated, given odd ids), broken frames
/// and bytes, in any order, some framed with a wrong length; sometimes
/// mutated as bytes as a whole.
pub fn input(rng: &mut ChaCha8Rng, messages: &[Value], corpus: &[Vec<u8>]) -> Vec<u8> {
    let mut out = Vec::new();
    for _ in 0..1 + rng.random_range(0..6) {
        match rng.random_range(0..10) {
            0 => out.extend(BROKEN[rng.random_range(0..BROKEN.len())]),
            1 => {
                // A body that is not JSON: a piece of a source.
                let s = &corpus[rng.random_range(0..corpus.len())];
                let a = rng.random_range(0..s.len().max(1));
                out.extend(frame(&s[a.min(s.len())..(a + 64).min(s.len())]));
            }
            _ => {
                let mut m = messages[rng.random_range(0..messages.len())].clone();
                for _ in 0..rng.random_range(0..3) {
                    super::mutate_tree(rng, &mut m);
                }
                let mut body = serde_json::to_vec(&m).expect("a value serialises");
                if m.is_object() && rng.random_range(0..3) == 0 {
                    // An odd id, spliced as text (some are not JSON values serde makes).
                    let id = IDS[rng.random_range(0..IDS.len())];
                    let mut text = m.clone();
                    text["id"] = json!("@ID@");
                    body = serde_json::to_string(&text)
                        .expect("a value serialises")
                        .replace("\"@ID@\"", id)
                        .into_bytes();
                }
                if rng.random_range(0..8) == 0 {
                    super::mutate_bytes(rng, &mut body, corpus);
                }
                let mut f = frame(&body);
                if rng.random_range(0..10) == 0 {
                    // A wrong length, shorter than the body.
                    let n = body.len().saturating_sub(rng.random_range(1..8));
                    f = format!("Content-Length: {n}\r\n\r\n").into_bytes();
                    f.extend(&body);
                }
                out.extend(f);
            }
        }
    }
    if rng.random_range(0..4) == 0 {
        super::mutate_bytes(rng, &mut out, corpus);
    }
    out
}

/// The values of every `Content-Length:` of the input, whatever its case.
fn declared_lengths(input: &[u8]) -> impl Iterator<Item = u64> + '_ {
    const NAME: &[u8] = b"content-length:";
    (0..input.len().saturating_sub(NAME.len() - 1)).filter_map(move |i| {
        if !input[i..i + NAME.len()].eq_ignore_ascii_case(NAME) {
            return None;
        }
        let rest = &input[i + NAME.len()..];
        let rest = &rest[rest.iter().take_while(|b| b.is_ascii_whitespace()).count()..];
        let digits: &[u8] = &rest[..rest.iter().take_while(|b| b.is_ascii_digit()).count()];
        if digits.is_empty() {
            return None;
        }
        std::str::from_utf8(digits).ok()?.parse().ok().or(Some(u64::MAX))
    })
}

/// Streams that ended before the last request (an `exit`, a length past
/// the end, one too large), and streams whose last request was answered.
pub static ENDED: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
pub static ANSWERED: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

pub fn target(input: &[u8]) {
    use std::sync::atomic::Ordering;
    let init = json!({ "jsonrpc": "2.0", "id": 0, "method": "initialize", "params": { "capabilities": {} } });
    let mut stream = frame(init.to_string().as_bytes());
    stream.extend(input);
    let uri = "file:///last.bat";
    let open = json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen",
        "params": { "textDocument": { "uri": uri, "languageId": "shaping", "version": 1, "text": "stage s { }" } } });
    let last = json!({ "jsonrpc": "2.0", "id": LAST, "method": "textDocument/documentSymbol",
        "params": { "textDocument": { "uri": uri } } });
    // Blank lines, as many as the longest length the input declares: a
    // body it starts (or a header it leaves open) ends inside them, and
    // the server reads the last frames whole.
    let longest = declared_lengths(input).max().unwrap_or(0);
    let checked = longest <= 1 << 20;
    stream.extend(b"\r\n".repeat(2 + longest.min(1 << 20) as usize / 2 + 1));
    stream.extend(frame(open.to_string().as_bytes()));
    stream.extend(frame(last.to_string().as_bytes()));
    let mut out = Vec::new();
    let ending = lsp::serve(Cursor::new(stream), &mut out);
    // Every message written is whole JSON; no handler panicked.
    let mut rest = &out[..];
    let mut last_answered = false;
    while !rest.is_empty() {
        let at = rest.windows(4).position(|w| w == b"\r\n\r\n").expect("a whole header");
        let head = std::str::from_utf8(&rest[..at]).expect("an ASCII header");
        let n: usize =
            head.strip_prefix("Content-Length: ").and_then(|n| n.parse().ok()).expect("Content-Length");
        let m: Value = serde_json::from_slice(&rest[at + 4..at + 4 + n]).expect("a message of JSON");
        assert_ne!(m["error"]["code"], json!(-32603), "a handler panicked: {m}");
        last_answered |= m["id"] == json!(LAST);
        rest = &rest[at + 4 + n..];
    }
    match ending {
        Ok(lsp::Ending::End) if !checked => {
            ENDED.fetch_add(1, Ordering::Relaxed);
        }
        Ok(lsp::Ending::End) => {
            assert!(last_answered, "the last request was not answered");
            ANSWERED.fetch_add(1, Ordering::Relaxed);
        }
        Ok(lsp::Ending::Exit { .. } | lsp::Ending::EndInBody) => {
            ENDED.fetch_add(1, Ordering::Relaxed);
        }
        Err(e) if e.contains("larger than the") => {
            ENDED.fetch_add(1, Ordering::Relaxed);
        }
        Err(e) => panic!("the server ended: {e}"),
    }
}
