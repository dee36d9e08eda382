//! `shaping lsp`: a language server over stdio (`lsp-server` + `lsp-types`).
//!
//! Documents are synchronised whole. Every change recompiles the document
//! and publishes its diagnostics; requests (hover, definition, references,
//! completion, document symbols, formatting) work from the last text. Every
//! request handler runs under `catch_unwind`: a bug answers an error, it
//! never stops the server.

use std::collections::HashMap;

use lsp_server::{Connection, Message, Notification, Request, Response};
use lsp_types::{self as lt, Uri};
use miette::Diagnostic as _;
use serde_json::Value;
use shaping_compiler::fmt::{lex, TokenKind};
use shaping_compiler::syntax::{self, ast};
use shaping_compiler::{compile, render_layout, Program};

use crate::load::CliError;

/// Runs the server on stdin and stdout until the client says `exit`.
pub fn lsp() -> Result<(), CliError> {
    let (conn, io) = Connection::stdio();
    serve(&conn).map_err(|e| CliError::io(format!("error: language server: {e}")))?;
    drop(conn);
    io.join().map_err(|e| CliError::io(format!("error: language server I/O: {e}")))
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
        ..Default::default()
    }
}

fn serve(conn: &Connection) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let caps = serde_json::to_value(capabilities())?;
    conn.initialize(caps)?;
    let mut docs: HashMap<String, (Uri, String)> = HashMap::new();
    for msg in &conn.receiver {
        match msg {
            Message::Request(req) => {
                if conn.handle_shutdown(&req)? {
                    return Ok(());
                }
                let id = req.id.clone();
                let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| request(&docs, &req)));
                let resp = match result {
                    Ok(Ok(v)) => Response::new_ok(id, v),
                    Ok(Err(msg)) => Response::new_err(id, lsp_server::ErrorCode::MethodNotFound as i32, msg),
                    Err(_) => Response::new_err(
                        id,
                        lsp_server::ErrorCode::InternalError as i32,
                        "internal error of the shaping language server".into(),
                    ),
                };
                conn.sender.send(Message::Response(resp))?;
            }
            Message::Notification(n) => {
                if let Some((uri, text)) = document_change(&n) {
                    let diags =
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| diagnostics(&uri, &text)))
                            .unwrap_or_default();
                    let params =
                        lt::PublishDiagnosticsParams { uri: uri.clone(), diagnostics: diags, version: None };
                    conn.sender.send(Message::Notification(Notification::new(
                        "textDocument/publishDiagnostics".into(),
                        params,
                    )))?;
                    docs.insert(uri.as_str().to_string(), (uri, text));
                } else if n.method == "textDocument/didClose" {
                    if let Ok(p) = serde_json::from_value::<lt::DidCloseTextDocumentParams>(n.params) {
                        docs.remove(p.text_document.uri.as_str());
                    }
                }
            }
            Message::Response(_) => {}
        }
    }
    Ok(())
}

/// The new text of a document opened or changed.
fn document_change(n: &Notification) -> Option<(Uri, String)> {
    match n.method.as_str() {
        "textDocument/didOpen" => {
            let p: lt::DidOpenTextDocumentParams = serde_json::from_value(n.params.clone()).ok()?;
            Some((p.text_document.uri, p.text_document.text))
        }
        "textDocument/didChange" => {
            let p: lt::DidChangeTextDocumentParams = serde_json::from_value(n.params.clone()).ok()?;
            let text = p.content_changes.into_iter().next_back()?.text;
            Some((p.text_document.uri, text))
        }
        _ => None,
    }
}

fn request(docs: &HashMap<String, (Uri, String)>, req: &Request) -> Result<Value, String> {
    let uri_of =
        |v: &Value| -> Option<String> { v.get("textDocument")?.get("uri")?.as_str().map(str::to_string) };
    let Some((uri, text)) = uri_of(&req.params).and_then(|u| docs.get(&u)) else {
        return Ok(Value::Null);
    };
    let pos = || -> Option<usize> {
        let p: lt::Position = serde_json::from_value(req.params.get("position")?.clone()).ok()?;
        Some(offset(text, p))
    };
    let json = |v: Option<Value>| -> Result<Value, String> { Ok(v.unwrap_or(Value::Null)) };
    match req.method.as_str() {
        "textDocument/hover" => json(pos().and_then(|o| hover(text, o))),
        "textDocument/definition" => json(pos().map(|o| locations(uri, text, o, false))),
        "textDocument/references" => json(pos().map(|o| locations(uri, text, o, true))),
        "textDocument/completion" => json(Some(completion(text))),
        "textDocument/documentSymbol" => json(Some(symbols(text))),
        "textDocument/formatting" => json(formatting(text)),
        m => Err(format!("`{m}` is not supported")),
    }
}

// ------------------------------------------------------------------ positions

/// The byte offset of an LSP position (UTF-16 columns), clamped to the text.
fn offset(text: &str, p: lt::Position) -> usize {
    let mut line_start = 0;
    for _ in 0..p.line {
        match text[line_start..].find('\n') {
            Some(i) => line_start += i + 1,
            None => return text.len(),
        }
    }
    let line = &text[line_start..];
    let line = &line[..line.find('\n').unwrap_or(line.len())];
    let mut units = 0;
    for (i, c) in line.char_indices() {
        if units >= p.character as usize {
            return line_start + i;
        }
        units += c.len_utf16();
    }
    line_start + line.len()
}

/// The LSP position of a byte offset.
fn position(text: &str, offset: usize) -> lt::Position {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count();
    let col = before.rfind('\n').map_or(before, |i| &before[i + 1..]);
    lt::Position::new(line as u32, col.encode_utf16().count() as u32)
}

fn range(text: &str, start: usize, end: usize) -> lt::Range {
    lt::Range::new(position(text, start), position(text, end))
}

// ------------------------------------------------------------------ diagnostics

/// Every error and warning of the document, with the related labels as
/// related information.
pub fn diagnostics(uri: &Uri, text: &str) -> Vec<lt::Diagnostic> {
    let (_, d) = shaping_compiler::check(text, "document.bat");
    d.errors()
        .iter()
        .map(|e| {
            let labels: Vec<miette::LabeledSpan> = e.labels().map(|l| l.collect()).unwrap_or_default();
            let primary = labels.iter().find(|l| l.primary()).or(labels.first());
            let r = primary.map_or(range(text, 0, 0), |l| range(text, l.offset(), l.offset() + l.len()));
            let mut message = e.to_string();
            if let Some(label) = primary.and_then(|l| l.label()) {
                message += &format!(" ({label})");
            }
            if let Some(help) = e.help() {
                message += &format!("\nhelp: {help}");
            }
            let related: Vec<lt::DiagnosticRelatedInformation> = labels
                .iter()
                .filter(|l| primary.is_none_or(|p| !std::ptr::eq(*l, p)))
                .map(|l| lt::DiagnosticRelatedInformation {
                    location: lt::Location::new(uri.clone(), range(text, l.offset(), l.offset() + l.len())),
                    message: l.label().unwrap_or("here").to_string(),
                })
                .collect();
            lt::Diagnostic {
                range: r,
                severity: Some(if e.is_warning() {
                    lt::DiagnosticSeverity::WARNING
                } else {
                    lt::DiagnosticSeverity::ERROR
                }),
                source: Some("shaping".into()),
                message,
                related_information: (!related.is_empty()).then_some(related),
                ..Default::default()
            }
        })
        .collect()
}

// ------------------------------------------------------------------ names

/// What a name is declared as.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Stage,
    Module,
    Sensor,
    Actuator,
}

/// Every declaration of the document: (name, kind, span of the name, stage).
fn declarations(file: &ast::File) -> Vec<(String, Kind, ast::Name, Option<String>)> {
    let mut out = Vec::new();
    let hw = |h: &ast::Hardware, stage: Option<String>| {
        let k = if h.is_sensor { Kind::Sensor } else { Kind::Actuator };
        (h.name.text.clone(), k, h.name.clone(), stage)
    };
    for r in &file.robots {
        out.extend(r.hardware.iter().map(|h| hw(h, None)));
    }
    for s in &file.stages {
        out.push((s.name.text.clone(), Kind::Stage, s.name.clone(), None));
        for i in &s.items {
            match i {
                ast::StageItem::Module(m) => {
                    out.push((m.name.text.clone(), Kind::Module, m.name.clone(), Some(s.name.text.clone())))
                }
                ast::StageItem::RobotAdds(hws, _) => {
                    out.extend(hws.iter().map(|h| hw(h, Some(s.name.text.clone()))))
                }
                _ => {}
            }
        }
    }
    out
}

/// The word at a byte offset and its span.
fn word_at(text: &str, offset: usize) -> Option<(usize, usize)> {
    let lx = lex(text);
    lx.tokens
        .iter()
        .find(|t| t.kind == TokenKind::Word && t.span.start <= offset && offset <= t.span.end)
        .map(|t| (t.span.start, t.span.end))
}

/// Definitions (or, with `refs`, every use) of the name at `offset`.
fn locations(uri: &Uri, text: &str, offset: usize, refs: bool) -> Value {
    let Some((a, b)) = word_at(text, offset) else { return Value::Null };
    let word = &text[a..b];
    let Ok(file) = syntax::parse(text) else { return Value::Null };
    let decls: Vec<_> = declarations(&file).into_iter().filter(|d| d.0 == word).collect();
    if decls.is_empty() {
        return Value::Null;
    }
    let spans: Vec<(usize, usize)> = if refs {
        lex(text)
            .tokens
            .iter()
            .filter(|t| t.kind == TokenKind::Word && &text[t.span.start..t.span.end] == word)
            .map(|t| (t.span.start, t.span.end))
            .collect()
    } else {
        // The first declaration: a module redeclared by a later stage is defined where it first appears.
        decls.iter().take(1).map(|d| (d.2.span.start, d.2.span.end)).collect()
    };
    let locs: Vec<lt::Location> =
        spans.into_iter().map(|(a, b)| lt::Location::new(uri.clone(), range(text, a, b))).collect();
    serde_json::to_value(locs).unwrap_or(Value::Null)
}

// ------------------------------------------------------------------ hover

fn hover(text: &str, offset: usize) -> Option<Value> {
    let (a, b) = word_at(text, offset)?;
    let word = &text[a..b];
    let file = syntax::parse(text).ok()?;
    let decls = declarations(&file);
    let (_, kind, _, _) = decls.iter().find(|d| d.0 == word)?;
    // The stage the cursor is in (else the last one).
    let here = file.stages.iter().find(|s| s.span.start <= offset && offset <= s.span.end);
    let program = compile(text, "document.bat").ok();
    let md = match (kind, &program) {
        (Kind::Stage, Some(p)) => {
            let (i, st) = p.stage(word)?;
            let table = render_layout(p, i);
            let totals = table.lines().find(|l| l.starts_with("genes:")).unwrap_or("");
            let added: Vec<&str> =
                st.modules.iter().filter(|m| m.stage as usize == i).map(|m| m.name.as_str()).collect();
            let parent = st.parent.map(|j| format!(", extends `{}`", p.stages[j].name)).unwrap_or_default();
            format!(
                "**stage `{word}`** ({} of {}{parent})\n\nadds modules: {}\n\n{totals}",
                i + 1,
                p.stages.len(),
                if added.is_empty() { "none".to_string() } else { added.join(", ") }
            )
        }
        (Kind::Module, Some(p)) => {
            let stage_name = here.map(|s| s.name.text.as_str());
            let (i, st) = match stage_name.and_then(|n| p.stage(n)) {
                Some((i, st)) if st.modules.iter().any(|m| m.name == word) => (i, st),
                _ => p
                    .stages
                    .iter()
                    .enumerate()
                    .rev()
                    .find(|(_, s)| s.modules.iter().any(|m| m.name == word))?,
            };
            let m = st.modules.iter().find(|m| m.name == word)?;
            let senses: Vec<String> = m.inputs.iter().map(|&c| channel(p, i, c)).collect();
            let table = render_layout(p, i);
            let mut rows: Vec<&str> = table.lines().skip(1).take(1).collect();
            rows.extend(table.lines().filter(|l| l.split_whitespace().nth(3) == Some(word)));
            // Weights that are not genes: what a training stage learned.
            let trained = format!("trained: `{word}` ");
            let extra: Vec<&str> = table.lines().filter(|l| l.starts_with(&trained)).collect();
            let genes = if rows.len() > 1 {
                format!("```text\n{}\n```", rows.join("\n"))
            } else {
                "no genes in this stage".to_string()
            };
            let extra = if extra.is_empty() { String::new() } else { format!("\n\n{}", extra.join("\n")) };
            format!(
                "**module `{word}`** in stage `{}`\n\nsenses: {}\n\n{genes}{extra}",
                st.name,
                if senses.is_empty() { "nothing".into() } else { senses.join(", ") },
            )
        }
        (Kind::Sensor, Some(p)) => {
            let s = p.stages.iter().find_map(|st| st.sensors.iter().find(|s| s.name == word))?;
            let chans = if s.count == 1 {
                format!("channel {}", s.channel)
            } else {
                format!("{} elements, channels {}..{}", s.count, s.channel, s.channel + s.count - 1)
            };
            let kind = format!("{:?}", s.kind).to_lowercase();
            format!("**sensor `{word}`**: `{kind}`, {chans}")
        }
        (Kind::Actuator, Some(p)) => {
            let a = p.stages.iter().find_map(|st| st.actuators.iter().find(|a| a.name == word))?;
            let kind = format!("{:?}", a.kind).to_lowercase();
            let slots = match kind.as_str() {
                "speed" => "two wheel speeds, -1..1 of v_max: `[0]` left, `[1]` right",
                "lift" => "states `up`, `down`",
                _ => "states `open`, `closed`",
            };
            format!("**actuator `{word}`**: `{kind}`, {slots}")
        }
        (k, None) => format!(
            "{} `{word}` (the file has errors: fix them for details)",
            format!("{k:?}").to_lowercase()
        ),
    };
    let h = lt::Hover {
        contents: lt::HoverContents::Markup(lt::MarkupContent { kind: lt::MarkupKind::Markdown, value: md }),
        range: Some(range(text, a, b)),
    };
    serde_json::to_value(h).ok()
}

/// The name of a percept channel: `ir[3]`, `battery`.
fn channel(p: &Program, stage: usize, c: u16) -> String {
    match p.stages[stage].sensors.iter().find(|s| s.channel <= c && c < s.channel + s.count) {
        Some(s) if s.count == 1 => s.name.clone(),
        Some(s) => format!("{}[{}]", s.name, c - s.channel),
        None => format!("channel {c}"),
    }
}

// ------------------------------------------------------------------ completion, symbols, formatting

/// Words of the language that are not reserved (those are
/// `syntax::RESERVED`), offered by completion.
const WORDS: &[&str] = &[
    "train",
    "trained",
    "error",
    "difference",
    "squared",
    "if",
    "script",
    "commit",
    "neural",
    "outputs",
    "weights",
    "hidden",
    "range",
    "bits",
    "crbp",
    "always",
    "evolvable",
    "fixed",
    "random",
    "forward",
    "back",
    "turn",
    "left",
    "right",
    "stop",
    "toward",
    "wait",
    "recharge",
    "arena",
    "charger",
    "battery",
    "objects",
    "body",
    "population",
    "generations",
    "actions",
    "seed",
    "selection",
    "mutation",
    "crossover",
    "proximity",
    "ambient",
    "level",
    "optical",
    "speed",
    "lift",
    "grip",
    "max",
    "min",
    "sum",
    "mean",
    "abs",
    "sign",
];

fn completion(text: &str) -> Value {
    let mut items: Vec<lt::CompletionItem> = syntax::RESERVED
        .iter()
        .chain(WORDS)
        .map(|k| lt::CompletionItem {
            label: k.to_string(),
            kind: Some(lt::CompletionItemKind::KEYWORD),
            ..Default::default()
        })
        .collect();
    if let Ok(file) = syntax::parse(text) {
        let mut seen = std::collections::HashSet::new();
        for (name, kind, _, _) in declarations(&file) {
            if seen.insert(name.clone()) {
                let k = match kind {
                    Kind::Stage => lt::CompletionItemKind::CLASS,
                    Kind::Module => lt::CompletionItemKind::MODULE,
                    Kind::Sensor | Kind::Actuator => lt::CompletionItemKind::VARIABLE,
                };
                items.push(lt::CompletionItem {
                    label: name,
                    kind: Some(k),
                    detail: Some(format!("{kind:?}").to_lowercase()),
                    ..Default::default()
                });
            }
        }
    } else {
        // A half-typed file: offer the words already written.
        let mut seen = std::collections::HashSet::new();
        for t in lex(text).tokens.iter().filter(|t| t.kind == TokenKind::Word) {
            let w = &text[t.span.start..t.span.end];
            if !syntax::RESERVED.contains(&w) && !WORDS.contains(&w) && seen.insert(w) {
                items.push(lt::CompletionItem { label: w.to_string(), ..Default::default() });
            }
        }
    }
    serde_json::to_value(items).unwrap_or(Value::Null)
}

#[allow(deprecated)] // `DocumentSymbol::deprecated` must be given
fn symbol(
    text: &str,
    name: &ast::Name,
    kind: lt::SymbolKind,
    children: Vec<lt::DocumentSymbol>,
) -> lt::DocumentSymbol {
    lt::DocumentSymbol {
        name: name.text.clone(),
        detail: None,
        kind,
        tags: None,
        deprecated: None,
        range: range(text, name.span.start, name.span.end),
        selection_range: range(text, name.span.start, name.span.end),
        children: (!children.is_empty()).then_some(children),
    }
}

fn symbols(text: &str) -> Value {
    let Ok(file) = syntax::parse(text) else { return Value::Null };
    let mut out = Vec::new();
    for r in &file.robots {
        let hw = r.hardware.iter().map(|h| symbol(text, &h.name, lt::SymbolKind::FIELD, vec![])).collect();
        out.push((r.span.start, symbol(text, &r.name, lt::SymbolKind::STRUCT, hw)));
    }
    for s in &file.stages {
        let modules = s
            .items
            .iter()
            .filter_map(|i| match i {
                ast::StageItem::Module(m) => Some(symbol(text, &m.name, lt::SymbolKind::MODULE, vec![])),
                _ => None,
            })
            .collect();
        let mut sym = symbol(text, &s.name, lt::SymbolKind::CLASS, modules);
        sym.range = range(text, s.span.start, s.span.end);
        out.push((s.span.start, sym));
    }
    out.sort_by_key(|s| s.0);
    let out: Vec<lt::DocumentSymbol> = out.into_iter().map(|s| s.1).collect();
    serde_json::to_value(out).unwrap_or(Value::Null)
}

fn formatting(text: &str) -> Option<Value> {
    let out = shaping_compiler::fmt::format(text, "document.bat").ok()?;
    let edits = if out == text {
        vec![]
    } else {
        vec![lt::TextEdit { range: range(text, 0, text.len()), new_text: out }]
    };
    serde_json::to_value(edits).ok()
}
