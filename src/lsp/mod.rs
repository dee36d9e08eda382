//! `shaping lsp`: a language server over stdio (`lsp-types` for the
//! messages, the base protocol and JSON-RPC in [`rpc`]).
//!
//! [`serve`] works on any reader and writer: the binary gives it stdin and
//! stdout, the fuzzer (`shaping-fuzz lsp`) and the unit tests byte
//! buffers. It is one thread: it reads a frame, handles it, writes and
//! flushes every answer before it reads the next, so whatever ends it
//! (`exit`, the end of the input, a frame it cannot read past) ends it
//! with every answer written.
//!
//! It never stops on a bad message: a body that is not JSON gets a parse
//! error, one that is not JSON-RPC an invalid request (with the id null
//! when the id itself is wrong), an unknown request "method not found",
//! parameters of the wrong shape "invalid params", a request before
//! `initialize` "server not initialized"; unknown notifications are
//! ignored; a header line that is not a header is skipped, said in a
//! `window/logMessage`, and the next `Content-Length:` starts the next
//! frame. Only a `Content-Length` above [`rpc::MAX_MESSAGE_BYTES`] ends it
//! (with an error). Every handler runs under `catch_unwind`: a bug answers
//! an internal error, it never stops the server.
//!
//! Documents are synchronised whole. Every change recompiles the document
//! and publishes its diagnostics; requests work from the last text
//! ([`handlers`]).

mod handlers;
pub mod rpc;

use std::collections::HashMap;
use std::io::{self, BufRead, Write};

use lsp_types as lt;
use serde_json::Value;

use rpc::{Frame, Incoming, RpcError};

/// Runs the server on stdin and stdout until the client says `exit` or
/// closes its end; how it ended.
pub fn stdio() -> Result<Ending, String> {
    let stdin = io::stdin().lock();
    let stdout = io::BufWriter::new(io::stdout().lock());
    serve(stdin, stdout)
}

/// How [`serve`] ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// The `exit` notification (after `shutdown`, or not: the protocol's
    /// exit status is then 1, [`Ending::status`]).
    Exit { shut_down: bool },
    /// The end of the input between frames.
    End,
    /// The end of the input inside a body.
    EndInBody,
}

impl Ending {
    /// The process's exit status after this ending: 1 for an `exit`
    /// without `shutdown` before it, as the protocol says, 0 otherwise.
    pub fn status(self) -> u8 {
        match self {
            Ending::Exit { shut_down: false } => 1,
            _ => 0,
        }
    }
}

/// Serves the messages of `input` on `output` until `exit` or the end of
/// the input. An error is a frame the server cannot read past, or output
/// it cannot write.
pub fn serve(mut input: impl BufRead, mut output: impl Write) -> Result<Ending, String> {
    let mut server = Server::default();
    loop {
        let frame = rpc::read_frame(&mut input).map_err(|e| e.0)?;
        let written = match frame {
            Frame::End => return Ok(Ending::End),
            Frame::EndInBody => return Ok(Ending::EndInBody),
            Frame::Skipped(what) => {
                let params = lt::LogMessageParams {
                    typ: lt::MessageType::WARNING,
                    message: format!("shaping language server: skipped {what}"),
                };
                rpc::write(&mut output, &rpc::Notification::new("window/logMessage", params))
            }
            Frame::Body(body) => match server.handle(rpc::classify(&body), &mut output) {
                Ok(Some(ending)) => return Ok(ending),
                Ok(None) => Ok(()),
                Err(e) => Err(e),
            },
        };
        written.map_err(|e| format!("cannot write the output: {e}"))?;
    }
}

/// Where the server is in the protocol's lifecycle.
#[derive(Clone, Copy, Default, PartialEq, Eq, Debug)]
enum Lifecycle {
    #[default]
    Uninitialized,
    Running,
    ShutDown,
}

/// An open document: its URI as the client wrote it, and its text.
struct Document {
    uri: lt::Uri,
    text: String,
}

#[derive(Default)]
struct Server {
    state: Lifecycle,
    docs: HashMap<String, Document>,
}

/// The parameters of a request, or "invalid params".
fn params<T: serde::de::DeserializeOwned>(v: Value) -> Result<T, RpcError> {
    serde_json::from_value(v)
        .map_err(|e| RpcError::new(RpcError::INVALID_PARAMS, format!("invalid params: {e}")))
}

fn capabilities() -> lt::ServerCapabilities {
    lt::ServerCapabilities {
        text_document_sync: Some(lt::TextDocumentSyncCapability::Kind(lt::TextDocumentSyncKind::FULL)),
        hover_provider: Some(lt::HoverProviderCapability::Simple(true)),
        definition_provider: Some(lt::OneOf::Left(true)),
        references_provider: Some(lt::OneOf::Left(true)),
        document_symbol_provider: Some(lt::OneOf::Left(true)),
        document_formatting_provider: Some(lt::OneOf::Left(true)),
        completion_provider: Some(lt::CompletionOptions::default()),
        rename_provider: Some(lt::OneOf::Right(lt::RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: Default::default(),
        })),
        code_action_provider: Some(lt::CodeActionProviderCapability::Simple(true)),
        ..Default::default()
    }
}

impl Server {
    /// Handles one message, writing its answers; `Some` when it ends the
    /// server.
    fn handle(&mut self, message: Incoming, out: &mut impl Write) -> io::Result<Option<Ending>> {
        match message {
            Incoming::Request { id, method, params } => {
                let answer = self.request(&method, params);
                rpc::write(out, &rpc::Response::new(Some(&id), &answer))?;
            }
            Incoming::Invalid { id, error } => {
                rpc::write(out, &rpc::Response::new(id.as_deref(), &Err(error)))?;
            }
            Incoming::Notification { method, params } => {
                if method == "exit" {
                    return Ok(Some(Ending::Exit { shut_down: self.state == Lifecycle::ShutDown }));
                }
                if self.state == Lifecycle::Running {
                    self.notification(&method, params, out)?;
                }
            }
            Incoming::Response => {}
        }
        Ok(None)
    }

    fn request(&mut self, method: &str, params: Value) -> Result<Value, RpcError> {
        match (self.state, method) {
            (Lifecycle::Uninitialized, "initialize") => {
                let _: lt::InitializeParams = self::params(params)?;
                self.state = Lifecycle::Running;
                let result = lt::InitializeResult {
                    capabilities: capabilities(),
                    server_info: Some(lt::ServerInfo {
                        name: "shaping".into(),
                        version: Some(env!("CARGO_PKG_VERSION").into()),
                    }),
                };
                Ok(serde_json::to_value(result).expect("the capabilities serialise"))
            }
            (Lifecycle::Uninitialized, _) => {
                Err(RpcError::new(RpcError::SERVER_NOT_INITIALIZED, "the server is not initialized"))
            }
            (Lifecycle::ShutDown, _) => {
                Err(RpcError::new(RpcError::INVALID_REQUEST, "the server is shut down: only `exit` is left"))
            }
            (Lifecycle::Running, "initialize") => {
                Err(RpcError::new(RpcError::INVALID_REQUEST, "the server is already initialized"))
            }
            (Lifecycle::Running, "shutdown") => {
                self.state = Lifecycle::ShutDown;
                Ok(Value::Null)
            }
            (Lifecycle::Running, _) => {
                let docs = &self.docs;
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    handlers::request(docs, method, params)
                }))
                .unwrap_or_else(|_| {
                    Err(RpcError::new(
                        RpcError::INTERNAL_ERROR,
                        "internal error of the shaping language server",
                    ))
                })
            }
        }
    }

    fn notification(&mut self, method: &str, params: Value, out: &mut impl Write) -> io::Result<()> {
        let (uri, text) = match method {
            "textDocument/didOpen" => match self::params::<lt::DidOpenTextDocumentParams>(params) {
                Ok(p) => (p.text_document.uri, p.text_document.text),
                Err(_) => return Ok(()),
            },
            "textDocument/didChange" => match self::params::<lt::DidChangeTextDocumentParams>(params) {
                Ok(p) => match p.content_changes.into_iter().next_back() {
                    Some(change) => (p.text_document.uri, change.text),
                    None => return Ok(()),
                },
                Err(_) => return Ok(()),
            },
            "textDocument/didClose" => {
                if let Ok(p) = self::params::<lt::DidCloseTextDocumentParams>(params) {
                    self.docs.remove(p.text_document.uri.as_str());
                }
                return Ok(());
            }
            _ => return Ok(()),
        };
        let diagnostics =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| handlers::diagnostics(&uri, &text)))
                .unwrap_or_default();
        let params = lt::PublishDiagnosticsParams { uri: uri.clone(), diagnostics, version: None };
        rpc::write(out, &rpc::Notification::new("textDocument/publishDiagnostics", params))?;
        self.docs.insert(uri.as_str().to_string(), Document { uri, text });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(v: &str) -> String {
        format!("Content-Length: {}\r\n\r\n{v}", v.len())
    }

    /// The messages the server writes for `input`, after `initialize`.
    fn answers(input: &str) -> (Vec<Value>, String, Result<Ending, String>) {
        let init = frame(r#"{"jsonrpc":"2.0","id":0,"method":"initialize","params":{"capabilities":{}}}"#);
        let mut out = Vec::new();
        let end = serve(io::Cursor::new(format!("{init}{input}").into_bytes()), &mut out);
        let mut msgs = Vec::new();
        let mut rest = &out[..];
        while let Some(at) = rest.windows(4).position(|w| w == b"\r\n\r\n") {
            let head = std::str::from_utf8(&rest[..at]).unwrap();
            let n: usize = head.strip_prefix("Content-Length: ").unwrap().parse().unwrap();
            msgs.push(serde_json::from_slice(&rest[at + 4..at + 4 + n]).unwrap());
            rest = &rest[at + 4 + n..];
        }
        assert!(rest.is_empty());
        (msgs.split_off(1), String::from_utf8(out).unwrap(), end)
    }

    #[test]
    fn requests_after_bad_ones_are_answered() {
        let input = [
            frame("{"),
            frame(r#"{"jsonrpc":"2.0","id":{"a":1},"method":"x"}"#),
            frame(r#"{"jsonrpc":"2.0","id":99999999999999999999,"method":"nope"}"#),
            frame(r#"{"jsonrpc":"2.0","method":"nope"}"#),
            frame(r#"{"jsonrpc":"2.0","id":"s","method":"textDocument/hover","params":3}"#),
            frame(r#"{"jsonrpc":"2.0","id":7,"method":"shutdown"}"#),
            frame(r#"{"jsonrpc":"2.0","method":"exit"}"#),
        ]
        .concat();
        let (msgs, raw, end) = answers(&input);
        let codes: Vec<String> = msgs.iter().map(|m| format!("{} {}", m["id"], m["error"]["code"])).collect();
        assert_eq!(codes, ["null -32700", "null -32600", "1e+20 -32601", "\"s\" -32602", "7 null"]);
        assert!(raw.contains(r#""id":99999999999999999999,"#), "{raw}");
        assert_eq!(end, Ok(Ending::Exit { shut_down: true }));
    }
}
