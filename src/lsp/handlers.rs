//! The requests of the language server, on the documents it holds: each
//! takes the text and a position and answers with `lsp-types` values.

use std::collections::HashMap;

use lsp_types::{self as lt, Uri};
use miette::Diagnostic as _;
use serde_json::Value;
use shaping_compiler::ide::{self, Kind};
use shaping_compiler::syntax::{ast, parse_recovering};

use super::rpc::RpcError;
use super::{params, Document};

/// A request on an open document (`null` for a document that is not open).
pub(super) fn request(docs: &HashMap<String, Document>, method: &str, p: Value) -> Result<Value, RpcError> {
    /// The document and the byte offset of a position in it.
    fn at(docs: &HashMap<String, Document>, p: lt::TextDocumentPositionParams) -> Option<(&Document, usize)> {
        let doc = docs.get(p.text_document.uri.as_str())?;
        Some((doc, Lines::new(&doc.text).offset(p.position)))
    }
    let doc = |id: &lt::TextDocumentIdentifier| docs.get(id.uri.as_str());
    let answer = match method {
        "textDocument/hover" => {
            let p: lt::HoverParams = params(p)?;
            at(docs, p.text_document_position_params).and_then(|(d, o)| hover(&d.text, o))
        }
        "textDocument/definition" => {
            let p: lt::GotoDefinitionParams = params(p)?;
            at(docs, p.text_document_position_params).map(|(d, o)| locations(&d.uri, &d.text, o, false))
        }
        "textDocument/references" => {
            let p: lt::ReferenceParams = params(p)?;
            at(docs, p.text_document_position).map(|(d, o)| locations(&d.uri, &d.text, o, true))
        }
        "textDocument/completion" => {
            let p: lt::CompletionParams = params(p)?;
            at(docs, p.text_document_position).map(|(d, o)| completion(&d.text, o))
        }
        "textDocument/documentSymbol" => {
            let p: lt::DocumentSymbolParams = params(p)?;
            doc(&p.text_document).map(|d| symbols(&d.text))
        }
        "textDocument/formatting" => {
            let p: lt::DocumentFormattingParams = params(p)?;
            match doc(&p.text_document) {
                Some(d) => Some(formatting(&d.text)?),
                None => None,
            }
        }
        "textDocument/prepareRename" => {
            let p: lt::TextDocumentPositionParams = params(p)?;
            at(docs, p).and_then(|(d, o)| {
                let (span, name) = ide::prepare_rename(&d.text, o)?;
                let range = Lines::new(&d.text).range(span.start, span.end);
                serde_json::to_value(lt::PrepareRenameResponse::RangeWithPlaceholder {
                    range,
                    placeholder: name,
                })
                .ok()
            })
        }
        "textDocument/rename" => {
            let p: lt::RenameParams = params(p)?;
            match at(docs, p.text_document_position) {
                Some((d, o)) => {
                    let spans = ide::rename(&d.text, o, &p.new_name)
                        .map_err(|why| RpcError::new(RpcError::REQUEST_FAILED, why))?;
                    let lines = Lines::new(&d.text);
                    let edits: Vec<lt::TextEdit> = spans
                        .into_iter()
                        .map(|s| lt::TextEdit {
                            range: lines.range(s.start, s.end),
                            new_text: p.new_name.clone(),
                        })
                        .collect();
                    let edit = lt::WorkspaceEdit {
                        changes: Some([(d.uri.clone(), edits)].into_iter().collect()),
                        ..Default::default()
                    };
                    Some(serde_json::to_value(edit).expect("edits serialise"))
                }
                None => None,
            }
        }
        "textDocument/codeAction" => {
            let p: lt::CodeActionParams = params(p)?;
            doc(&p.text_document).map(|d| code_actions(d, p.range))
        }
        m => {
            return Err(RpcError::new(RpcError::METHOD_NOT_FOUND, format!("method not found: `{m}`")));
        }
    };
    Ok(answer.unwrap_or(Value::Null))
}

// ------------------------------------------------------------------ positions

/// A text with the offsets of its line starts: positions in time
/// logarithmic in the lines and linear in the line's length.
pub(super) struct Lines<'t> {
    text: &'t str,
    starts: Vec<usize>,
}

impl<'t> Lines<'t> {
    pub(super) fn new(text: &'t str) -> Lines<'t> {
        let starts = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
        Lines { text, starts }
    }

    /// The byte offset of an LSP position (UTF-16 columns), clamped to the text.
    fn offset(&self, p: lt::Position) -> usize {
        let Some(&start) = self.starts.get(p.line as usize) else { return self.text.len() };
        let line = &self.text[start..];
        let line = &line[..line.find('\n').unwrap_or(line.len())];
        let mut units = 0;
        for (i, c) in line.char_indices() {
            if units >= p.character as usize {
                return start + i;
            }
            units += c.len_utf16();
        }
        start + line.len()
    }

    /// The LSP position of a byte offset.
    fn position(&self, offset: usize) -> lt::Position {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let col = self.text[self.starts[line]..offset].encode_utf16().count();
        lt::Position::new(line as u32, col as u32)
    }

    fn range(&self, start: usize, end: usize) -> lt::Range {
        lt::Range::new(self.position(start), self.position(end))
    }
}

// ------------------------------------------------------------------ diagnostics

/// Every error and warning of the document, with the related labels as
/// related information.
pub fn diagnostics(uri: &Uri, text: &str) -> Vec<lt::Diagnostic> {
    let (_, d) = shaping_compiler::check(text, "document.bat");
    let lines = Lines::new(text);
    d.errors()
        .iter()
        .map(|e| {
            let labels: Vec<miette::LabeledSpan> = e.labels().map(|l| l.collect()).unwrap_or_default();
            let primary = labels.iter().find(|l| l.primary()).or(labels.first());
            let r = primary.map_or(lines.range(0, 0), |l| lines.range(l.offset(), l.offset() + l.len()));
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
                    location: lt::Location::new(uri.clone(), lines.range(l.offset(), l.offset() + l.len())),
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
                code: e.code().map(|c| lt::NumberOrString::String(c.to_string())),
                message,
                related_information: (!related.is_empty()).then_some(related),
                ..Default::default()
            }
        })
        .collect()
}

// ------------------------------------------------------------------ quick fixes

/// The quick fixes of the diagnostics that touch `range`: each
/// suggestion of a help ("did you mean", "declare ...") as an edit.
fn code_actions(d: &Document, range: lt::Range) -> Value {
    let lines = Lines::new(&d.text);
    let (from, to) = (lines.offset(range.start), lines.offset(range.end));
    let (_, diagnostics) = shaping_compiler::check(&d.text, "document.bat");
    let published = self::diagnostics(&d.uri, &d.text);
    let mut actions = Vec::new();
    for (e, shown) in diagnostics.errors().iter().zip(published) {
        let (a, b) = (lines.offset(shown.range.start), lines.offset(shown.range.end));
        if b < from || a > to {
            continue;
        }
        for fix in ide::fixes(&d.text, e) {
            let edits: Vec<lt::TextEdit> = fix
                .edits
                .into_iter()
                .map(|(s, new_text)| lt::TextEdit { range: lines.range(s.start, s.end), new_text })
                .collect();
            actions.push(lt::CodeActionOrCommand::CodeAction(lt::CodeAction {
                title: fix.title,
                kind: Some(lt::CodeActionKind::QUICKFIX),
                diagnostics: Some(vec![shown.clone()]),
                edit: Some(lt::WorkspaceEdit {
                    changes: Some([(d.uri.clone(), edits)].into_iter().collect()),
                    ..Default::default()
                }),
                is_preferred: Some(true),
                ..Default::default()
            }));
        }
    }
    serde_json::to_value(actions).expect("code actions serialise")
}

// ------------------------------------------------------------------ names

/// Every declaration of the document: (name, kind, span of the name, stage).
fn declarations(file: &ast::File) -> Vec<(String, Kind, ast::Name, Option<String>)> {
    ide::declarations(file).into_iter().map(|d| (d.name.text.clone(), d.kind, d.name, d.stage)).collect()
}

/// The word at a byte offset and its span.
fn word_at(text: &str, offset: usize) -> Option<(usize, usize)> {
    ide::word_at(text, offset).map(|s| (s.start, s.end))
}

/// Definitions (or, with `refs`, every use) of the name at `offset`.
fn locations(uri: &Uri, text: &str, offset: usize, refs: bool) -> Value {
    let Some((a, b)) = word_at(text, offset) else { return Value::Null };
    let word = &text[a..b];
    let Some(file) = parse_recovering(text).0 else { return Value::Null };
    let decls: Vec<_> = declarations(&file).into_iter().filter(|d| d.0 == word).collect();
    if decls.is_empty() {
        return Value::Null;
    }
    let spans: Vec<(usize, usize)> = if refs {
        ide::uses(text, word).into_iter().map(|s| (s.start, s.end)).collect()
    } else {
        // The first declaration (a module redeclared by a later stage is
        // defined where it first appears), or, inside a role, the role's.
        ide::definition(text, offset).into_iter().map(|s| (s.start, s.end)).collect()
    };
    let lines = Lines::new(text);
    let locs: Vec<lt::Location> =
        spans.into_iter().map(|(a, b)| lt::Location::new(uri.clone(), lines.range(a, b))).collect();
    serde_json::to_value(locs).unwrap_or(Value::Null)
}

// ------------------------------------------------------------------ hover

fn hover(text: &str, offset: usize) -> Option<Value> {
    let (span, value) = ide::hover(text, offset)?;
    let h = lt::Hover {
        contents: lt::HoverContents::Markup(lt::MarkupContent { kind: lt::MarkupKind::Markdown, value }),
        range: Some(Lines::new(text).range(span.start, span.end)),
    };
    serde_json::to_value(h).ok()
}

// ------------------------------------------------------------------ completion, symbols, formatting

fn completion(text: &str, offset: usize) -> Value {
    use ide::CompletionKind as C;
    use lt::CompletionItemKind as K;
    let items: Vec<lt::CompletionItem> = ide::complete(text, offset)
        .into_iter()
        .map(|c| lt::CompletionItem {
            kind: Some(match c.kind {
                C::Keyword | C::Motion => K::KEYWORD,
                C::Function => K::FUNCTION,
                C::Sensor | C::Actuator => K::VARIABLE,
                C::Module => K::MODULE,
                C::Stage => K::CLASS,
                C::Field => K::FIELD,
            }),
            detail: (!c.detail.is_empty()).then_some(c.detail),
            label: c.label,
            ..Default::default()
        })
        .collect();
    serde_json::to_value(items).expect("completions serialise")
}

#[allow(deprecated)] // `DocumentSymbol::deprecated` must be given
fn symbol(
    lines: &Lines,
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
        range: lines.range(name.span.start, name.span.end),
        selection_range: lines.range(name.span.start, name.span.end),
        children: (!children.is_empty()).then_some(children),
    }
}

fn symbols(text: &str) -> Value {
    use ide::SymbolKind as S;
    fn convert(lines: &Lines, s: &ide::Symbol) -> lt::DocumentSymbol {
        let kind = match s.kind {
            S::Robot => lt::SymbolKind::STRUCT,
            S::Hardware => lt::SymbolKind::FIELD,
            S::Stage => lt::SymbolKind::CLASS,
            S::Role => lt::SymbolKind::NAMESPACE,
            S::Module => lt::SymbolKind::MODULE,
        };
        let children = s.children.iter().map(|c| convert(lines, c)).collect();
        let mut sym = symbol(lines, &s.name, kind, children);
        // A stage's and a role's range is their whole declaration.
        if matches!(s.kind, S::Stage | S::Role) {
            sym.range = lines.range(s.span.start, s.span.end);
        }
        sym
    }
    let Some(file) = parse_recovering(text).0 else { return Value::Null };
    let lines = Lines::new(text);
    let out: Vec<lt::DocumentSymbol> = ide::outline(&file).iter().map(|s| convert(&lines, s)).collect();
    serde_json::to_value(out).unwrap_or(Value::Null)
}

/// The whole text formatted, or why it cannot be.
fn formatting(text: &str) -> Result<Value, RpcError> {
    use shaping_compiler::fmt::FormatError;
    let out = shaping_compiler::fmt::format(text, "document.bat").map_err(|e| {
        let why = match e {
            FormatError::Syntax(d) => {
                let n = d.error_count();
                let first =
                    d.errors().iter().find(|e| !e.is_warning()).map(|e| e.to_string()).unwrap_or_default();
                match n {
                    1 => format!("it does not parse: {first}"),
                    _ => format!("it does not parse ({n} errors; the first: {first})"),
                }
            }
            FormatError::Changed(why) => format!("a bug of the formatter: {why}"),
        };
        RpcError::new(RpcError::REQUEST_FAILED, format!("the document is left as it is: {why}"))
    })?;
    let edits = if out == text {
        vec![]
    } else {
        vec![lt::TextEdit { range: Lines::new(text).range(0, text.len()), new_text: out }]
    };
    Ok(serde_json::to_value(edits).expect("edits serialise"))
}
