//! What an editor asks of a file, as plain data on byte offsets: the
//! language server (`src/lsp`) turns it into the protocol's types.
//!
//! - [`words`]: every word of the language, with its places, meaning and
//!   section of the reference;
//! - [`complete`]: the words and names the compiler accepts at an offset;
//! - [`keyword_at`]: the word of the language under the cursor (hover);
//! - [`declarations`], [`prepare_rename`], [`rename`]: the names a file
//!   declares, and renaming a module or a stage;
//! - [`fixes`]: the edits a diagnostic's help proposes (quick fixes).

pub mod words;

use crate::diag::{Error, Suggestion};
use crate::syntax::lex::{lex, Token, TokenKind};
use crate::syntax::{ast, parse_recovering, Span, RESERVED};
use words::Places;

/// What a name is declared as.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Kind {
    Stage,
    Module,
    Sensor,
    Actuator,
}

impl Kind {
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Stage => "stage",
            Kind::Module => "module",
            Kind::Sensor => "sensor",
            Kind::Actuator => "actuator",
        }
    }
}

/// A declaration: the name, what it is, the stage it is declared in.
#[derive(Clone, Debug)]
pub struct Declaration {
    pub name: ast::Name,
    pub kind: Kind,
    pub stage: Option<String>,
}

/// Every declaration of a file, in order.
pub fn declarations(file: &ast::File) -> Vec<Declaration> {
    let mut out = Vec::new();
    let hw = |h: &ast::Hardware, stage: Option<String>| Declaration {
        name: h.name.clone(),
        kind: if h.is_sensor { Kind::Sensor } else { Kind::Actuator },
        stage,
    };
    for r in &file.robots {
        out.extend(r.hardware.iter().map(|h| hw(h, None)));
    }
    for s in &file.stages {
        out.push(Declaration { name: s.name.clone(), kind: Kind::Stage, stage: None });
        for i in &s.items {
            match i {
                ast::StageItem::Module(m) => out.push(Declaration {
                    name: m.name.clone(),
                    kind: Kind::Module,
                    stage: Some(s.name.text.clone()),
                }),
                ast::StageItem::RobotAdds(hws, _) => {
                    out.extend(hws.iter().map(|h| hw(h, Some(s.name.text.clone()))))
                }
                _ => {}
            }
        }
    }
    out
}

/// The word token at an offset (its end included).
pub fn word_at(text: &str, offset: usize) -> Option<Span> {
    lex(text)
        .tokens
        .iter()
        .find(|t| t.kind == TokenKind::Word && t.span.start <= offset && offset <= t.span.end)
        .map(|t| t.span)
}

/// The word of the language under the cursor, unless the file declares a
/// name spelt so (a module called `wait`: hover says what the module is).
pub fn keyword_at(text: &str, offset: usize) -> Option<(Span, words::Word)> {
    let span = word_at(text, offset)?;
    let word = words::word(&text[span.start..span.end])?;
    if let Some(file) = parse_recovering(text).0 {
        if declarations(&file).iter().any(|d| d.name.text == word.text) {
            return None;
        }
    }
    Some((span, word))
}

// ------------------------------------------------------------------ completion

/// What a completion is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompletionKind {
    Keyword,
    Function,
    Motion,
    Sensor,
    Actuator,
    Module,
    Stage,
}

/// One completion: the text, its kind, a line saying what it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Completion {
    pub label: String,
    pub kind: CompletionKind,
    pub detail: String,
}

/// Where the cursor is, as completion sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Context {
    /// Words of these places.
    Words(Places),
    /// After `sense` (or in its list), in `toward(`: the robot's sensors.
    Sensors,
    /// After `link` or `link A ->`: the modules of the stage.
    Modules,
    /// After `module`: the inherited modules (a new name is free).
    InheritedModules,
    /// After `extends`: the other stages.
    Stages,
    /// After `trained`: the training stages.
    TrainingStages,
    /// After `on` in a world: the walls.
    Walls,
    /// After `behavior` or in a script: the steps, and the actuators.
    Steps,
    /// In a decoding table: the motions and the wheels.
    Table,
    /// In an expression: functions, operators' words, sensors and actuators.
    Expression,
    /// Only these words.
    Only(&'static [&'static str]),
    /// A new name, a number or punctuation: nothing to offer.
    Nothing,
}

/// The kind of the innermost block open among `tokens` (the keyword
/// before its `{`), `None` at the top level.
fn block_at<'t>(text: &'t str, tokens: &[Token]) -> Option<&'t str> {
    const HEADS: [&str; 11] = [
        "stage", "module", "world", "robot", "genome", "evolve", "body", "neural", "script", "behavior",
        "commit",
    ];
    let mut stack: Vec<Option<&str>> = Vec::new();
    for (i, t) in tokens.iter().enumerate() {
        match &text[t.span.start..t.span.end] {
            "{" => {
                let head = tokens[i.saturating_sub(4)..i]
                    .iter()
                    .rev()
                    .map(|t| &text[t.span.start..t.span.end])
                    .find(|w| HEADS.contains(w));
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
    let kind = |k: usize| before.len().checked_sub(k + 1).map(|i| before[i].kind);
    let block = block_at(text, &before);
    match (w(0), w(1)) {
        ("sense", _) | ("(", "toward") => return Context::Sensors,
        ("link", _) => return Context::Modules,
        (">", "-") if w(3) == "link" => return Context::Modules,
        (">", "-") | ("|", _) => return Context::Table,
        ("behavior", _) | ("{" | ";", "script" | "behavior" | "commit") => return Context::Steps,
        ("script", _) => return Context::Only(&["commit"]),
        ("turn", _) => return Context::Only(&["left", "right", "toward"]),
        ("extends", _) => return Context::Stages,
        ("trained", _) => return Context::TrainingStages,
        ("module", _) => return Context::InheritedModules,
        ("on", _) if block == Some("world") => return Context::Walls,
        ("on", _) => return Context::Only(&["behavior", "activation"]),
        ("activation", _) => return Context::Words(words::ACTIVATION),
        ("weights", _) if block == Some("neural") => {
            return Context::Only(&["evolvable", "fixed", "random", "trained"])
        }
        ("outputs", _) => return Context::Only(&["sign", "linear"]),
        ("learn", _) => return Context::Only(&["crbp"]),
        ("links", _) if block == Some("stage") => return Context::Only(&["all"]),
        ("all", "links") => return Context::Only(&["evolvable", "fixed"]),
        ("test", _) => return Context::Only(&["best"]),
        ("best", _) | ("train", _) => return Context::Only(&["for"]),
        ("world", _) => return Context::Only(&["adds", "changes"]),
        ("fitness", _) => return Context::Only(&["adds", "per"]),
        ("per", _) if kind(1) == Some(TokenKind::Number) => return Context::Words(words::EVENT),
        ("per", _) => return Context::Only(&["action"]),
        ("action", "per") => return Context::Expression,
        ("uses", _) => return Context::Only(&["charger"]),
        ("selection", _) => return Context::Only(&["truncation", "roulette"]),
        ("inheritance", _) => return Context::Only(&["darwinian", "lamarckian"]),
        ("stage" | "robot" | "sensor" | "actuator" | "lamp" | "wall" | "zone" | "cylinder", _) => {
            return Context::Nothing
        }
        _ => {}
    }
    // `sensor NAME ` and `actuator NAME[8] `: the kinds.
    let declared = if kind(0) == Some(TokenKind::Word) {
        w(1)
    } else if w(0) == "]" && w(2) == "[" {
        w(4)
    } else {
        ""
    };
    match declared {
        "sensor" => return Context::Words(words::SENSOR_KIND),
        "actuator" => return Context::Words(words::ACTUATOR_KIND),
        _ => {}
    }
    // In a list of sensors: `sense ir, light[2..5], `.
    if w(0) == "," {
        for k in 1..before.len() {
            match w(k) {
                "sense" | "toward" => return Context::Sensors,
                "," | "[" | "]" | "." | "(" => {}
                x if x.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') => {}
                _ => break,
            }
        }
    }
    // After an operator, or an expression's keyword: an operand.
    let operator = matches!(
        w(0),
        "+" | "-"
            | "*"
            | "/"
            | "<"
            | ">"
            | "="
            | "("
            | "?"
            | ":"
            | ","
            | "and"
            | "or"
            | "not"
            | "prev"
            | "until"
            | "if"
            | "reinforce"
    );
    if operator && block != Some("world") && block != Some("evolve") && block != Some("body") {
        return Context::Expression;
    }
    // After a number: a setting's value ends in a block of settings; elsewhere
    // the clause goes on (`for 3` then `actions`).
    let settings = matches!(block, Some("world" | "evolve" | "body" | "genome"));
    if (kind(0) == Some(TokenKind::Number) && !settings) || w(0) == "(" {
        return Context::Nothing;
    }
    match block {
        None => Context::Words(words::TOP),
        Some("robot") => Context::Words(words::ROBOT),
        Some("stage") => Context::Words(words::STAGE),
        Some("module") => Context::Words(words::MODULE),
        Some("world") => Context::Words(words::WORLD),
        Some("evolve") => Context::Words(words::EVOLVE),
        Some("body") => Context::Words(words::BODY),
        Some("genome") => Context::Words(words::GENOME),
        Some("neural") => Context::Words(words::NEURAL),
        Some(_) => Context::Steps,
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

/// What completion offers at `offset`: exactly the words and names the
/// compiler accepts there.
pub fn complete(text: &str, offset: usize) -> Vec<Completion> {
    use CompletionKind as K;
    let ctx = context(text, offset);
    let file = parse_recovering(text).0;
    let file = file.as_ref();
    let stages = lineage_or_all(file, offset);
    let here = file.and_then(|f| f.stages.iter().find(|s| s.span.start <= offset && offset <= s.span.end));
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
    let item = |label: &str, kind: K, detail: &str| Completion {
        label: label.to_string(),
        kind,
        detail: detail.to_string(),
    };
    let of_words = |places: Places| -> Vec<Completion> {
        words::words()
            .into_iter()
            .filter(|w| w.places & places != 0)
            .map(|w| {
                let kind = match w.kind {
                    words::WordKind::Function => K::Function,
                    _ if places & (words::STEP | words::TABLE) != 0 => K::Motion,
                    _ => K::Keyword,
                };
                item(w.text, kind, w.meaning)
            })
            .collect()
    };
    let modules = |stages: &[&ast::StageDecl]| -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for s in stages.iter().rev() {
            for i in &s.items {
                if let ast::StageItem::Module(m) = i {
                    if !names.contains(&m.name.text) {
                        names.push(m.name.text.clone());
                    }
                }
            }
        }
        names
    };
    match ctx {
        Context::Words(places) => of_words(places),
        Context::Only(list) => {
            list.iter().map(|t| item(t, K::Keyword, words::word(t).map_or("", |w| w.meaning))).collect()
        }
        Context::Nothing => Vec::new(),
        Context::Sensors => hardware(true).iter().map(|n| item(n, K::Sensor, "sensor")).collect(),
        Context::Modules => modules(&stages).iter().map(|n| item(n, K::Module, "module")).collect(),
        Context::InheritedModules => {
            let parents: Vec<&ast::StageDecl> = stages.iter().skip(1).copied().collect();
            let parents = if here.is_some() { parents } else { Vec::new() };
            modules(&parents).iter().map(|n| item(n, K::Module, "inherited module: changes it")).collect()
        }
        Context::Stages | Context::TrainingStages => file
            .iter()
            .flat_map(|f| f.stages.iter())
            .filter(|s| here.is_none_or(|h| h.name.text != s.name.text))
            .filter(|s| {
                ctx == Context::Stages || s.items.iter().any(|i| matches!(i, ast::StageItem::Train { .. }))
            })
            .map(|s| item(&s.name.text, K::Stage, "stage"))
            .collect(),
        Context::Walls => {
            ["north", "south", "east", "west"].iter().map(|w| item(w, K::Keyword, "wall")).collect()
        }
        Context::Steps | Context::Table => {
            let places = if ctx == Context::Steps { words::STEP } else { words::TABLE };
            let mut out = of_words(places);
            if ctx == Context::Table {
                out.retain(|c| c.label != "turn");
            }
            out.extend(["turn left", "turn right"].iter().map(|m| item(m, K::Motion, "turn in place")));
            for a in hardware(false) {
                out.push(item(&format!("{a}(0.5, 0.5)"), K::Actuator, "wheel speeds (a `speed` actuator)"));
                if ctx == Context::Steps {
                    out.push(item(&a, K::Actuator, "an actuator and a state: `arm down`, `claw closed`"));
                }
            }
            out
        }
        Context::Expression => {
            let mut out = of_words(words::EXPR);
            out.extend(hardware(true).iter().map(|n| item(n, K::Sensor, "sensor")));
            out.extend(hardware(false).iter().map(|n| item(n, K::Actuator, "actuator")));
            out
        }
    }
}

// ------------------------------------------------------------------ rename

/// The module or stage whose name is at `offset`: its span there and the
/// name; `None` on anything else.
pub fn prepare_rename(text: &str, offset: usize) -> Option<(Span, String)> {
    let span = word_at(text, offset)?;
    let name = &text[span.start..span.end];
    let file = parse_recovering(text).0?;
    declarations(&file)
        .iter()
        .any(|d| d.name.text == name && matches!(d.kind, Kind::Module | Kind::Stage))
        .then(|| (span, name.to_string()))
}

/// Every use of a name: the word tokens spelt so (lexically, as find
/// references: a sensor spelt as a module is renamed with it).
pub fn uses(text: &str, name: &str) -> Vec<Span> {
    lex(text)
        .tokens
        .iter()
        .filter(|t| t.kind == TokenKind::Word && &text[t.span.start..t.span.end] == name)
        .map(|t| t.span)
        .collect()
}

/// The edits that rename the module or stage at `offset` to `new_name`,
/// or why it cannot be.
pub fn rename(text: &str, offset: usize, new_name: &str) -> Result<Vec<Span>, String> {
    let Some((_, old)) = prepare_rename(text, offset) else {
        return Err("only a module or a stage can be renamed".into());
    };
    let mut chars = new_name.chars();
    let first = chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    if !first || !chars.all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!(
            "`{new_name}` is not a name: letters, digits and `_`, starting with a letter or `_`"
        ));
    }
    if RESERVED.contains(&new_name) {
        return Err(format!("`{new_name}` is a reserved word"));
    }
    if let Some(file) = parse_recovering(text).0 {
        let decls = declarations(&file);
        if let Some(d) = decls.iter().find(|d| d.name.text == new_name) {
            return Err(format!("`{new_name}` is already the name of a {}", d.kind.as_str()));
        }
        if let Some(d) =
            decls.iter().find(|d| d.name.text == old && matches!(d.kind, Kind::Sensor | Kind::Actuator))
        {
            return Err(format!(
                "`{old}` is also the name of a {}: rename one of them by hand",
                d.kind.as_str()
            ));
        }
    }
    Ok(uses(text, &old))
}

// ------------------------------------------------------------------ quick fixes

/// A quick fix: a title and the edits (a span and its new text).
#[derive(Clone, Debug, PartialEq)]
pub struct Fix {
    pub title: String,
    pub edits: Vec<(Span, String)>,
}

/// The fixes a diagnostic proposes: its suggestion, made an edit.
pub fn fixes(text: &str, e: &Error) -> Vec<Fix> {
    let Some(s) = e.suggestion().and_then(|s| s.in_source(text)) else { return Vec::new() };
    match s {
        Suggestion::Replace { span, with } => {
            vec![Fix { title: format!("replace with `{with}`"), edits: vec![(span, with)] }]
        }
        Suggestion::Declare { line } => {
            // At the end of the (first) robot block, else at the top.
            let file = parse_recovering(text).0;
            let robot = file.as_ref().and_then(|f| f.robots.first());
            let edit = match robot {
                Some(r) => {
                    let close = text[..r.span.end].rfind('}').unwrap_or(r.span.end);
                    (Span { start: close, end: close }, format!("  {line}\n"))
                }
                None => (Span { start: 0, end: 0 }, format!("robot r {{\n  {line}\n}}\n")),
            };
            vec![Fix { title: format!("declare `{line}` in the robot"), edits: vec![edit] }]
        }
    }
}
