//! The base protocol and JSON-RPC 2.0, as the language server reads and
//! writes them: frames (`Content-Length` headers, an empty line, a body),
//! and what a body is (a request, a notification, a response, or something
//! JSON-RPC calls a parse error or an invalid request).
//!
//! Nothing here ends the server but the end of the input and a frame whose
//! `Content-Length` is beyond [`MAX_MESSAGE_BYTES`]: a header line that is
//! not a header is skipped, and the next line holding `Content-Length:`
//! starts the next frame (resynchronisation); a body that is not JSON-RPC
//! is answered with the error JSON-RPC gives it.

use std::io::{self, BufRead, Read as _, Write};

use serde::Serialize;
use serde_json::value::RawValue;
use serde_json::Value;

/// The largest message the server reads: a document is at most a few MiB;
/// a `Content-Length` above this is refused before anything is allocated.
pub const MAX_MESSAGE_BYTES: usize = 64 << 20;

/// The longest header line kept; the rest of a longer line is skipped.
const MAX_HEADER_LINE: usize = 1024;

/// What the input gave.
#[derive(Debug)]
pub enum Frame {
    /// A body of the length its `Content-Length` gave.
    Body(Vec<u8>),
    /// Input that is not a frame was skipped: what was wrong with it.
    Skipped(String),
    /// The end of the input, between frames.
    End,
    /// The end of the input inside a body (its `Content-Length` was beyond
    /// the end).
    EndInBody,
}

/// A frame that cannot be read past: the stream is not the protocol.
#[derive(Debug)]
pub struct Fatal(pub String);

/// One header line, without its line end (CR LF, or LF alone); `None` at
/// the end of the input. A line longer than [`MAX_HEADER_LINE`] is
/// returned cut, its rest consumed.
fn header_line(input: &mut impl BufRead) -> io::Result<Option<(Vec<u8>, bool)>> {
    let mut line = Vec::new();
    if input.by_ref().take(MAX_HEADER_LINE as u64).read_until(b'\n', &mut line)? == 0 {
        return Ok(None);
    }
    let whole = line.last() == Some(&b'\n');
    if !whole && line.len() == MAX_HEADER_LINE {
        // Skip the rest of the line without keeping it.
        loop {
            let buf = input.fill_buf()?;
            if buf.is_empty() {
                break;
            }
            match buf.iter().position(|&b| b == b'\n') {
                Some(i) => {
                    input.consume(i + 1);
                    break;
                }
                None => {
                    let n = buf.len();
                    input.consume(n);
                }
            }
        }
        return Ok(Some((line, false)));
    }
    if line.last() == Some(&b'\n') {
        line.pop();
        if line.last() == Some(&b'\r') {
            line.pop();
        }
    }
    Ok(Some((line, true)))
}

/// Where `Content-Length:` starts in a line, whatever its case.
fn content_length_at(line: &[u8]) -> Option<usize> {
    const NAME: &[u8] = b"content-length:";
    line.windows(NAME.len()).position(|w| w.eq_ignore_ascii_case(NAME))
}

/// Reads the next frame. Headers other than `Content-Length` are ignored;
/// a line that is not a header is skipped, unless `Content-Length:` is in
/// it (the end of a body longer than its length, say), where the frame
/// starts.
pub fn read_frame(input: &mut impl BufRead) -> Result<Frame, Fatal> {
    let io = |e: io::Error| Fatal(format!("cannot read the input: {e}"));
    let mut size: Option<usize> = None;
    // Two `Content-Length`s that disagree: the frame is read with the
    // smaller and skipped, so that a longer one cannot swallow the next.
    let mut disagree: Option<(usize, usize)> = None;
    let mut headers = 0;
    let mut wrong: Option<String> = None;
    loop {
        let Some((line, whole)) = header_line(input).map_err(io)? else {
            return Ok(match headers {
                0 => Frame::End,
                _ => Frame::Skipped("the input ends inside the headers of a message".into()),
            });
        };
        let shown = || String::from_utf8_lossy(&line[..line.len().min(80)]).into_owned();
        if !whole {
            return Ok(Frame::Skipped(format!(
                "a header line longer than {MAX_HEADER_LINE} bytes: {:?}",
                shown()
            )));
        }
        if line.is_empty() {
            if headers == 0 {
                // A blank line between frames.
                continue;
            }
            if let Some(w) = wrong {
                return Ok(Frame::Skipped(w));
            }
            let Some(size) = size else {
                return Ok(Frame::Skipped("a message without `Content-Length`".into()));
            };
            let mut body = vec![0; size];
            return match input.read_exact(&mut body) {
                Ok(()) => Ok(match disagree {
                    Some((a, b)) => {
                        Frame::Skipped(format!("a message with two Content-Length headers, {a} and {b}"))
                    }
                    None => Frame::Body(body),
                }),
                Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => Ok(Frame::EndInBody),
                Err(e) => Err(io(e)),
            };
        }
        let line = match content_length_at(&line) {
            Some(at) if at > 0 => {
                // Garbage before the header: a new frame starts here.
                size = None;
                disagree = None;
                headers = 0;
                wrong = None;
                &line[at..]
            }
            _ => &line[..],
        };
        let text = String::from_utf8_lossy(line);
        let Some((name, value)) = text.split_once(':') else {
            if headers == 0 {
                return Ok(Frame::Skipped(format!("not a header: {:?}", shown())));
            }
            wrong.get_or_insert(format!("a malformed header {:?}", shown()));
            headers += 1;
            continue;
        };
        headers += 1;
        if name.trim().eq_ignore_ascii_case("Content-Length") {
            let value = value.trim();
            match value.parse::<u64>() {
                Ok(n) if n > MAX_MESSAGE_BYTES as u64 => {
                    return Err(Fatal(format!(
                    "a message of {n} bytes (its Content-Length) is larger than the {} MiB the server reads",
                    MAX_MESSAGE_BYTES >> 20
                )))
                }
                Ok(n) => {
                    let n = n as usize;
                    if let Some(before) = size.filter(|&b| b != n) {
                        disagree = Some((before, n));
                    }
                    size = Some(size.map_or(n, |b| b.min(n)));
                }
                Err(e) => {
                    wrong.get_or_insert(format!("a bad Content-Length {value:?}: {e}"));
                }
            }
        }
    }
}

/// An error of JSON-RPC, or of the language server protocol.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct RpcError {
    pub code: i32,
    pub message: String,
}

impl RpcError {
    pub const PARSE_ERROR: i32 = -32700;
    pub const INVALID_REQUEST: i32 = -32600;
    pub const METHOD_NOT_FOUND: i32 = -32601;
    pub const INVALID_PARAMS: i32 = -32602;
    pub const INTERNAL_ERROR: i32 = -32603;
    pub const SERVER_NOT_INITIALIZED: i32 = -32002;
    pub const REQUEST_FAILED: i32 = -32803;

    pub fn new(code: i32, message: impl Into<String>) -> RpcError {
        RpcError { code, message: message.into() }
    }
}

/// What a body is.
#[derive(Debug)]
pub enum Incoming {
    /// A request, whose `id` (a number or a string, exactly as written) the
    /// response repeats.
    Request {
        id: Box<RawValue>,
        method: String,
        params: Value,
    },
    Notification {
        method: String,
        params: Value,
    },
    /// A response to the server (which sends no requests): ignored.
    Response,
    /// What JSON-RPC answers with an error: the id when it could be read
    /// (else the answer's id is null).
    Invalid {
        id: Option<Box<RawValue>>,
        error: RpcError,
    },
}

/// Reads a body as JSON-RPC 2.0.
pub fn classify(body: &[u8]) -> Incoming {
    let invalid = |id, message: String| Incoming::Invalid {
        id,
        error: RpcError::new(RpcError::INVALID_REQUEST, message),
    };
    // The whole body is checked first (UTF-8, syntax, lone surrogates in
    // strings), then its fields are taken as they are written.
    let value: Value = match serde_json::from_slice(body) {
        Ok(v) => v,
        Err(e) => {
            return Incoming::Invalid {
                id: None,
                error: RpcError::new(RpcError::PARSE_ERROR, format!("the message is not JSON: {e}")),
            }
        }
    };
    match &value {
        Value::Object(_) => {}
        Value::Array(_) => {
            return invalid(
                None,
                "a batch of messages: the language server protocol sends one at a time".into(),
            )
        }
        _ => return invalid(None, "a message is a JSON object".into()),
    }
    let Ok(mut fields) = serde_json::from_slice::<std::collections::HashMap<String, Box<RawValue>>>(body)
    else {
        return invalid(None, "a message is a JSON object".into());
    };
    let id = match fields.remove("id") {
        None => None,
        Some(raw) => match raw.get().as_bytes().first() {
            Some(b'"' | b'-' | b'0'..=b'9' | b'n') => Some(raw),
            _ => return invalid(None, format!("an id is a number or a string, not `{}`", short(raw.get()))),
        },
    };
    if value.get("jsonrpc") != Some(&Value::from("2.0")) {
        return invalid(id, "a message has `\"jsonrpc\": \"2.0\"`".into());
    }
    let params = value.get("params").cloned().unwrap_or(Value::Null);
    match value.get("method") {
        Some(Value::String(m)) => match id {
            Some(id) => Incoming::Request { id, method: m.clone(), params },
            None => Incoming::Notification { method: m.clone(), params },
        },
        Some(m) => invalid(id, format!("a method is a string, not `{}`", short(&m.to_string()))),
        None if id.is_some() && (value.get("result").is_some() || value.get("error").is_some()) => {
            Incoming::Response
        }
        None => invalid(id, "a message without a method".into()),
    }
}

/// The start of a long piece of JSON, for a message.
fn short(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

/// Writes one message and flushes it.
pub fn write(out: &mut impl Write, message: &impl Serialize) -> io::Result<()> {
    let body = serde_json::to_vec(message).map_err(io::Error::other)?;
    write!(out, "Content-Length: {}\r\n\r\n", body.len())?;
    out.write_all(&body)?;
    out.flush()
}

/// A response: `result` or `error`, with the request's id (null when it
/// could not be read).
#[derive(Serialize)]
pub struct Response<'a> {
    jsonrpc: &'static str,
    id: &'a RawValue,
    #[serde(skip_serializing_if = "Option::is_none")]
    result: Option<&'a Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<&'a RpcError>,
}

impl<'a> Response<'a> {
    pub fn new(id: Option<&'a RawValue>, answer: &'a Result<Value, RpcError>) -> Response<'a> {
        let id = id.unwrap_or_else(|| null());
        match answer {
            Ok(v) => Response { jsonrpc: "2.0", id, result: Some(v), error: None },
            Err(e) => Response { jsonrpc: "2.0", id, result: None, error: Some(e) },
        }
    }
}

fn null() -> &'static RawValue {
    static NULL: std::sync::OnceLock<Box<RawValue>> = std::sync::OnceLock::new();
    NULL.get_or_init(|| RawValue::from_string("null".into()).expect("null is JSON"))
}

/// A notification of the server.
#[derive(Serialize)]
pub struct Notification<'a, P: Serialize> {
    jsonrpc: &'static str,
    method: &'a str,
    params: P,
}

impl<'a, P: Serialize> Notification<'a, P> {
    pub fn new(method: &'a str, params: P) -> Self {
        Notification { jsonrpc: "2.0", method, params }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(input: &str) -> Vec<String> {
        let mut r = io::Cursor::new(input.as_bytes().to_vec());
        let mut out = Vec::new();
        loop {
            match read_frame(&mut r).unwrap() {
                Frame::Body(b) => out.push(String::from_utf8(b).unwrap()),
                Frame::Skipped(w) => out.push(format!("skipped: {w}")),
                Frame::End => return out,
                Frame::EndInBody => {
                    out.push("end in body".into());
                    return out;
                }
            }
        }
    }

    #[test]
    fn frames_resynchronise_after_bad_headers() {
        assert_eq!(frames("Content-Length: 2\r\n\r\n{}Content-Length: 2\r\n\r\n[]"), ["{}", "[]"]);
        assert_eq!(frames("content-length:2\nX-Other: a\n\n{}"), ["{}"], "LF alone and any case");
        assert_eq!(
            frames("garbage\r\nContent-Length: 2\r\n\r\n{}"),
            ["skipped: not a header: \"garbage\"", "{}"]
        );
        assert_eq!(
            frames("Content-Length: x\r\n\r\n{}\r\nContent-Length: 2\r\n\r\n{}"),
            [
                "skipped: a bad Content-Length \"x\": invalid digit found in string",
                "skipped: not a header: \"{}\"",
                "{}"
            ]
        );
        assert_eq!(
            frames("Content-Type: a\r\n\r\n{}\r\nContent-Length: 2\r\n\r\n{}"),
            ["skipped: a message without `Content-Length`", "skipped: not a header: \"{}\"", "{}"]
        );
        // a body longer than its length: the rest is skipped up to the next frame
        assert_eq!(frames("Content-Length: 1\r\n\r\n{}Content-Length: 2\r\n\r\n{}"), ["{", "{}"]);
        assert_eq!(frames("Content-Length: 9\r\n\r\n{}"), ["end in body"]);
        // A second Content-Length, larger or smaller, does not swallow the
        // next message; the same one twice is no error.
        assert_eq!(
            frames("Content-Length: 2\r\nContent-Length: 40\r\n\r\n{}Content-Length: 2\r\n\r\n[]"),
            ["skipped: a message with two Content-Length headers, 2 and 40", "[]"]
        );
        assert_eq!(
            frames("Content-Length: 40\r\nContent-Length: 2\r\n\r\n{}Content-Length: 2\r\n\r\n[]"),
            ["skipped: a message with two Content-Length headers, 40 and 2", "[]"]
        );
        assert_eq!(frames("Content-Length: 2\r\nContent-Length: 2\r\n\r\n{}"), ["{}"]);
        let long = format!("{}\r\nContent-Length: 2\r\n\r\n{{}}", "x".repeat(5000));
        assert_eq!(frames(&long).len(), 2);
        assert!(read_frame(&mut io::Cursor::new(b"Content-Length: 99999999999\r\n\r\n".to_vec())).is_err());
    }

    fn id_of(body: &str) -> String {
        match classify(body.as_bytes()) {
            Incoming::Request { id, .. } => id.get().to_string(),
            Incoming::Invalid { error, id } => {
                format!("{} {}", error.code, id.map_or("null".into(), |i| i.get().to_string()))
            }
            other => format!("{other:?}"),
        }
    }

    #[test]
    fn ids_are_repeated_as_written() {
        let req = |id: &str| format!(r#"{{"jsonrpc":"2.0","id":{id},"method":"m"}}"#);
        for id in
            ["1", "-3", "4294967296", "123456789012345678901234567890", "\"a\"", "\"\\ud83d\\ude00\"", "null"]
        {
            assert_eq!(id_of(&req(id)), id);
        }
        assert_eq!(id_of(&req("{}")), "-32600 null");
        assert_eq!(id_of(&req("[1]")), "-32600 null");
        assert_eq!(id_of("[]"), "-32600 null");
        assert_eq!(id_of("{"), "-32700 null");
        assert_eq!(id_of(r#"{"jsonrpc":"2.0","id":1,"method":"m","params":"\ud800"}"#), "-32700 null");
        assert_eq!(id_of(r#"{"jsonrpc":"2.0","id":1,"method":7}"#), "-32600 1");
    }
}
