//! The requests of the language server, on the documents it holds: each
//! takes the text and a position and answers with `lsp-types` values.

use std::collections::HashMap;

use lsp_types::{self as lt, Uri};
use miette::Diagnostic as _;
use serde_json::Value;
use shaping_compiler::lower::lower_partial;
use shaping_compiler::syntax::lex::{lex, Token, TokenKind};
use shaping_compiler::syntax::{self, ast, parse_recovering};
use shaping_compiler::{render_layout, Program};

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
    let Some(file) = parse_recovering(text).0 else { return Value::Null };
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
    let lines = Lines::new(text);
    let locs: Vec<lt::Location> =
        spans.into_iter().map(|(a, b)| lt::Location::new(uri.clone(), lines.range(a, b))).collect();
    serde_json::to_value(locs).unwrap_or(Value::Null)
}

// ------------------------------------------------------------------ hover

fn hover(text: &str, offset: usize) -> Option<Value> {
    let (a, b) = word_at(text, offset)?;
    let word = &text[a..b];
    let file = parse_recovering(text).0?;
    let decls = declarations(&file);
    let (_, kind, _, _) = decls.iter().find(|d| d.0 == word)?;
    // The stage the cursor is in (else the last one).
    let here = file.stages.iter().find(|s| s.span.start <= offset && offset <= s.span.end);
    // What stands of the program, errors or not (the parts with errors show
    // their placeholders; their diagnostics say what is wrong).
    let program = lower_partial(&file, "document.bat").0;
    let p = &program;
    let md = || -> Option<String> {
        Some(match kind {
            Kind::Stage => {
                let (i, st) = p.stage(word)?;
                let table = render_layout(p, i);
                let totals = table.lines().find(|l| l.starts_with("genes:")).unwrap_or("");
                let added: Vec<&str> =
                    st.modules.iter().filter(|m| m.stage as usize == i).map(|m| m.name.as_str()).collect();
                let parent =
                    st.parent.map(|j| format!(", extends `{}`", p.stages[j].name)).unwrap_or_default();
                format!(
                    "**stage `{word}`** ({} of {}{parent})\n\nadds modules: {}\n\n{totals}",
                    i + 1,
                    p.stages.len(),
                    if added.is_empty() { "none".to_string() } else { added.join(", ") }
                )
            }
            Kind::Module => {
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
                let extra =
                    if extra.is_empty() { String::new() } else { format!("\n\n{}", extra.join("\n")) };
                format!(
                    "**module `{word}`** in stage `{}`\n\nsenses: {}\n\n{genes}{extra}",
                    st.name,
                    if senses.is_empty() { "nothing".into() } else { senses.join(", ") },
                )
            }
            Kind::Sensor => {
                let s = p.stages.iter().find_map(|st| st.sensors.iter().find(|s| s.name == word))?;
                let chans = if s.count == 1 {
                    format!("channel {}", s.channel)
                } else {
                    format!("{} elements, channels {}..{}", s.count, s.channel, s.channel + s.count - 1)
                };
                let kind = format!("{:?}", s.kind).to_lowercase();
                format!("**sensor `{word}`**: `{kind}`, {chans}")
            }
            Kind::Actuator => {
                let a = p.stages.iter().find_map(|st| st.actuators.iter().find(|a| a.name == word))?;
                let kind = format!("{:?}", a.kind).to_lowercase();
                let slots = match kind.as_str() {
                    "speed" => "two wheel speeds, -1..1 of v_max: `[0]` left, `[1]` right",
                    "lift" => "states `up`, `down`",
                    _ => "states `open`, `closed`",
                };
                format!("**actuator `{word}`**: `{kind}`, {slots}")
            }
        })
    };
    // What the program does not hold (a stage in an `extends` cycle, say) is named only.
    let md = md().unwrap_or_else(|| format!("**{} `{word}`**", format!("{kind:?}").to_lowercase()));
    let lines = Lines::new(text);
    let h = lt::Hover {
        contents: lt::HoverContents::Markup(lt::MarkupContent { kind: lt::MarkupKind::Markdown, value: md }),
        range: Some(lines.range(a, b)),
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
    "lives",
    "trained",
    "error",
    "difference",
    "squared",
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
    "wall",
    "cylinder",
    "lamp",
    "zone",
    "start",
    "heading",
    "grey",
    "intensity",
    "recurrent",
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
    "ground",
    "lamp_distance",
    "speed",
    "lift",
    "grip",
    "max",
    "min",
    "sum",
    "mean",
    "abs",
    "sign",
    "sqrt",
];

/// Where the cursor is, as completion sees it.
#[derive(Debug, PartialEq, Eq)]
enum Context {
    /// After `sense` (or in its list), in `toward(`: the robot's sensors.
    Sensors,
    /// After `link` or `link A ->`: the modules of the stage.
    Modules,
    /// After `extends`: the other stages.
    Stages,
    /// After `trained`: the training stages.
    TrainingStages,
    /// In a `world { }` block: its items.
    World,
    /// After `on` in a world: the walls.
    Walls,
    /// After `behavior`, `->` or `|` of a decoding table: the motions.
    Motions,
    /// Anywhere else: keywords and names.
    Anywhere,
}

/// The words that start a world item, from the grammar's `world_item` rule
/// (each item's first keyword), so that they follow the grammar.
fn world_items() -> Vec<String> {
    const GRAMMAR: &str = include_str!("../../grammar/shaping.pest");
    // The first quoted word of a rule's definition, through `k_...` rules.
    fn first_word(rule: &str, depth: usize) -> Option<String> {
        let line = GRAMMAR.lines().find(|l| l.split_whitespace().next() == Some(rule) && l.contains('='))?;
        let body = &line[line.find('=')? + 1..];
        let body = body.trim_start_matches([' ', '_', '@', '{']);
        if let Some(rest) = body.strip_prefix('"') {
            return rest.split('"').next().map(str::to_string);
        }
        let head: String = body.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
        (depth < 4).then(|| first_word(&head, depth + 1)).flatten()
    }
    let Some(line) = GRAMMAR.lines().find(|l| l.starts_with("world_item")) else { return vec![] };
    let alts = line.split_once('{').map_or("", |x| x.1).trim_end().trim_end_matches('}');
    alts.split('|').filter_map(|r| first_word(r.trim(), 0)).collect()
}

/// The kind of the innermost block open at `offset` (`stage`, `module`,
/// `world`, ...: the keyword before its `{`), `None` at top level.
fn block_at<'t>(text: &'t str, tokens: &[Token]) -> Option<&'t str> {
    let mut stack: Vec<Option<&str>> = Vec::new();
    for (i, t) in tokens.iter().enumerate() {
        match &text[t.span.start..t.span.end] {
            "{" => {
                let head = tokens[i.saturating_sub(4)..i]
                    .iter()
                    .rev()
                    .map(|t| &text[t.span.start..t.span.end])
                    .find(|w| {
                        matches!(
                            *w,
                            "stage"
                                | "module"
                                | "world"
                                | "robot"
                                | "genome"
                                | "evolve"
                                | "body"
                                | "neural"
                                | "script"
                                | "behavior"
                        )
                    });
                stack.push(head);
            }
            "}" => {
                stack.pop();
            }
            _ => {}
        }
    }
    stack.pop().flatten()
}

/// The completion context at `offset`.
fn context(text: &str, offset: usize) -> Context {
    let all = lex(text).tokens;
    // The tokens before the word being typed.
    let before: Vec<Token> = all
        .into_iter()
        .take_while(|t| t.span.end < offset || (t.span.start < offset && t.kind != TokenKind::Word))
        .collect();
    let w = |k: usize| -> &str {
        before.len().checked_sub(k + 1).map_or("", |i| &text[before[i].span.start..before[i].span.end])
    };
    match (w(0), w(1)) {
        ("sense", _) | ("(", "toward") => return Context::Sensors,
        ("link", _) => return Context::Modules,
        (">", "-") if w(3) == "link" => return Context::Modules,
        (">", "-") | ("|", _) | ("behavior", _) => return Context::Motions,
        ("extends", _) => return Context::Stages,
        ("trained", _) => return Context::TrainingStages,
        _ => {}
    }
    // In a list of sensors: `sense ir, light[2..5], `.
    if w(0) == "," {
        for k in 1..before.len() {
            match w(k) {
                "sense" => return Context::Sensors,
                "toward" => return Context::Sensors,
                "," | "[" | "]" | "." | "(" => {}
                x if x.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') => {}
                _ => break,
            }
        }
    }
    match block_at(text, &before) {
        Some("world") if w(0) == "on" => Context::Walls,
        Some("world") => Context::World,
        _ => Context::Anywhere,
    }
}

/// The stage declared around `offset`, and its ancestors by `extends`.
fn lineage(file: &ast::File, offset: usize) -> Vec<&ast::StageDecl> {
    let mut out: Vec<&ast::StageDecl> = Vec::new();
    let mut cur = file.stages.iter().find(|s| s.span.start <= offset && offset <= s.span.end);
    while let Some(s) = cur {
        if out.iter().any(|o| std::ptr::eq(*o, s)) {
            break;
        }
        out.push(s);
        cur = s.extends.as_ref().and_then(|e| file.stages.iter().find(|p| p.name.text == e.text));
    }
    out
}

fn item(label: &str, kind: lt::CompletionItemKind, detail: &str) -> lt::CompletionItem {
    lt::CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail: (!detail.is_empty()).then(|| detail.to_string()),
        ..Default::default()
    }
}

/// The motions of scripts and decoding tables.
const MOTIONS: &[&str] = &["forward", "back", "turn left", "turn right", "left", "right", "stop"];

fn completion(text: &str, offset: usize) -> Value {
    use lt::CompletionItemKind as K;
    let ctx = context(text, offset);
    let file = parse_recovering(text).0;
    let file = file.as_ref();
    let stages = lineage_or_all(file, offset);
    let hardware = |sensor: bool| -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        let robots = file.iter().flat_map(|f| f.robots.iter()).flat_map(|r| r.hardware.iter());
        let added = stages.iter().flat_map(|s| s.items.iter()).flat_map(|i| match i {
            ast::StageItem::RobotAdds(h, _) => h.iter().collect(),
            _ => Vec::new(),
        });
        for h in robots.chain(added) {
            if h.is_sensor == sensor && !names.contains(&h.name.text) {
                names.push(h.name.text.clone());
            }
        }
        names
    };
    let items: Vec<lt::CompletionItem> = match ctx {
        Context::Sensors => hardware(true).iter().map(|n| item(n, K::VARIABLE, "sensor")).collect(),
        Context::Modules => {
            let mut names: Vec<&str> = Vec::new();
            for s in stages.iter().rev() {
                for i in &s.items {
                    if let ast::StageItem::Module(m) = i {
                        if !names.contains(&m.name.text.as_str()) {
                            names.push(&m.name.text);
                        }
                    }
                }
            }
            names.iter().map(|n| item(n, K::MODULE, "module")).collect()
        }
        Context::Stages | Context::TrainingStages => {
            let here =
                file.and_then(|f| f.stages.iter().find(|s| s.span.start <= offset && offset <= s.span.end));
            file.iter()
                .flat_map(|f| f.stages.iter())
                .filter(|s| here.is_none_or(|h| h.name.text != s.name.text))
                .filter(|s| {
                    ctx == Context::Stages
                        || s.items.iter().any(|i| matches!(i, ast::StageItem::Train { .. }))
                })
                .map(|s| item(&s.name.text, K::CLASS, "stage"))
                .collect()
        }
        Context::World => world_items().iter().map(|w| item(w, K::KEYWORD, "world item")).collect(),
        Context::Walls => {
            ["north", "south", "east", "west"].iter().map(|w| item(w, K::KEYWORD, "wall")).collect()
        }
        Context::Motions => {
            let mut out: Vec<lt::CompletionItem> =
                MOTIONS.iter().map(|m| item(m, K::KEYWORD, "motion")).collect();
            for a in hardware(false) {
                out.push(item(&format!("{a}(0.5, 0.5)"), K::FUNCTION, "wheel speeds"));
            }
            out
        }
        Context::Anywhere => {
            let mut out: Vec<lt::CompletionItem> =
                syntax::RESERVED.iter().chain(WORDS).map(|k| item(k, K::KEYWORD, "")).collect();
            let mut seen = std::collections::HashSet::new();
            for (name, kind, _, _) in file.map(declarations).unwrap_or_default() {
                if seen.insert(name.clone()) {
                    let k = match kind {
                        Kind::Stage => K::CLASS,
                        Kind::Module => K::MODULE,
                        Kind::Sensor | Kind::Actuator => K::VARIABLE,
                    };
                    out.push(item(&name, k, &format!("{kind:?}").to_lowercase()));
                }
            }
            out
        }
    };
    serde_json::to_value(items).unwrap_or(Value::Null)
}

/// The stage at `offset` and its ancestors; outside any stage, every stage.
fn lineage_or_all(file: Option<&ast::File>, offset: usize) -> Vec<&ast::StageDecl> {
    let Some(f) = file else { return Vec::new() };
    let l = lineage(f, offset);
    if l.is_empty() {
        f.stages.iter().collect()
    } else {
        l
    }
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
    let Some(file) = parse_recovering(text).0 else { return Value::Null };
    let lines = Lines::new(text);
    let mut out = Vec::new();
    for r in &file.robots {
        let hw = r.hardware.iter().map(|h| symbol(&lines, &h.name, lt::SymbolKind::FIELD, vec![])).collect();
        out.push((r.span.start, symbol(&lines, &r.name, lt::SymbolKind::STRUCT, hw)));
    }
    for s in &file.stages {
        let modules = s
            .items
            .iter()
            .filter_map(|i| match i {
                ast::StageItem::Module(m) => Some(symbol(&lines, &m.name, lt::SymbolKind::MODULE, vec![])),
                _ => None,
            })
            .collect();
        let mut sym = symbol(&lines, &s.name, lt::SymbolKind::CLASS, modules);
        sym.range = lines.range(s.span.start, s.span.end);
        out.push((s.span.start, sym));
    }
    out.sort_by_key(|s| s.0);
    let out: Vec<lt::DocumentSymbol> = out.into_iter().map(|s| s.1).collect();
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
