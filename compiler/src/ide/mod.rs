//! What an editor asks of a file, as plain data on byte offsets: the
//! language server (`src/lsp`) turns it into the protocol's types.
//!
//! - [`words`]: every word of the language, with its places, meaning and
//!   section of the reference;
//! - [`complete`]: the words and names the compiler accepts at an offset;
//! - [`keyword_at`]: the word of the language under the cursor (hover);
//! - [`declarations`], [`prepare_rename`], [`rename`]: the names a file
//!   declares, and renaming a module or a stage;
//! - [`outline`], [`definition`]: the document's symbols (roles holding
//!   their modules), and where a name used at an offset is declared;
//! - [`fixes`]: the edits a diagnostic's help proposes (quick fixes).

pub mod words;

use crate::diag::{Error, Suggestion};
use crate::lower::lower_partial;
use crate::syntax::lex::{lex, Token, TokenKind};
use crate::syntax::{ast, parse_recovering, Span, RESERVED};
use crate::{render_layout, Program};
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
                ast::StageItem::Role(r) => out.extend(r.modules().map(|m| Declaration {
                    name: m.name.clone(),
                    kind: Kind::Module,
                    stage: Some(s.name.text.clone()),
                })),
                _ => {}
            }
        }
    }
    out
}

/// What a symbol of the outline is.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum SymbolKind {
    Robot,
    Hardware,
    Stage,
    Role,
    Module,
}

/// A symbol of the document outline: its name, what it is, the span of
/// its whole declaration, and the symbols it holds.
#[derive(Clone, Debug)]
pub struct Symbol {
    pub name: ast::Name,
    pub kind: SymbolKind,
    pub span: Span,
    pub children: Vec<Symbol>,
}

/// The document outline, in source order: each robot with its hardware,
/// each stage with its modules and roles, each role with its modules.
pub fn outline(file: &ast::File) -> Vec<Symbol> {
    let leaf = |name: &ast::Name, kind, span| Symbol { name: name.clone(), kind, span, children: Vec::new() };
    let modules = |items: &[ast::StageItem]| -> Vec<Symbol> {
        items
            .iter()
            .filter_map(|i| match i {
                ast::StageItem::Module(m) => Some(leaf(&m.name, SymbolKind::Module, m.span)),
                ast::StageItem::Role(r) => Some(Symbol {
                    name: r.name.clone(),
                    kind: SymbolKind::Role,
                    span: r.span,
                    children: r.modules().map(|m| leaf(&m.name, SymbolKind::Module, m.span)).collect(),
                }),
                _ => None,
            })
            .collect()
    };
    let mut out: Vec<Symbol> = file
        .robots
        .iter()
        .map(|r| Symbol {
            name: r.name.clone(),
            kind: SymbolKind::Robot,
            span: r.span,
            children: r.hardware.iter().map(|h| leaf(&h.name, SymbolKind::Hardware, h.span)).collect(),
        })
        .collect();
    out.extend(file.stages.iter().map(|s| Symbol {
        name: s.name.clone(),
        kind: SymbolKind::Stage,
        span: s.span,
        children: modules(&s.items),
    }));
    out.sort_by_key(|s| s.span.start);
    out
}

/// Where the name at `offset` is declared: a module named inside a role is
/// that role's (two roles may each have a `brain`); any other name, its
/// first declaration.
pub fn definition(text: &str, offset: usize) -> Option<Span> {
    let span = word_at(text, offset)?;
    let word = &text[span.start..span.end];
    let file = parse_recovering(text).0?;
    let role =
        file.stages.iter().flat_map(|s| s.roles()).find(|r| r.span.start <= offset && offset <= r.span.end);
    if let Some(m) = role.and_then(|r| r.modules().find(|m| m.name.text == word)) {
        return Some(m.name.span);
    }
    declarations(&file).into_iter().find(|d| d.name.text == word).map(|d| d.name.span)
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
    /// A field of `robot.FIELD` or `team.FIELD`.
    Field,
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
    /// After `robot.` or `team.`: the fields of the robot's or the
    /// team's state.
    Fields(&'static [(&'static str, usize, &'static str)]),
    /// Only these words.
    Only(&'static [&'static str]),
    /// A new name, a number or punctuation: nothing to offer.
    Nothing,
}

/// The kind of the innermost block open among `tokens` (the keyword
/// before its `{`), `None` at the top level.
fn block_at<'t>(text: &'t str, tokens: &[Token]) -> Option<&'t str> {
    const HEADS: [&str; 12] = [
        "stage", "module", "world", "robot", "genome", "evolve", "body", "neural", "script", "behavior",
        "commit", "role",
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
    let w = |k: usize| back(text, &before, k);
    let kind = |k: usize| before.len().checked_sub(k + 1).map(|i| before[i].kind);
    let block = block_at(text, &before);
    // `robot.` and `team.`: their fields.
    if w(0) == "." {
        match w(1) {
            "robot" => return Context::Fields(&crate::lower::expr::STATE_FIELDS),
            "team" => return Context::Fields(&crate::lower::expr::TEAM_FIELDS),
            _ => {}
        }
    }
    if let Some(c) = keyword_context(text, &before, block) {
        return c;
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
        Some("role") => Context::Words(words::ROLE),
        Some("module") => Context::Words(words::MODULE),
        Some("world") => Context::Words(words::WORLD),
        Some("evolve") => Context::Words(words::EVOLVE),
        Some("body") => Context::Words(words::BODY),
        Some("genome") => Context::Words(words::GENOME),
        Some("neural") => Context::Words(words::NEURAL),
        Some(_) => Context::Steps,
    }
}

/// The context that the last words fix by themselves, whatever comes
/// before them: after `sense`, `link`, `turn`, `extends`, `selection`, ...
fn keyword_context(text: &str, before: &[Token], block: Option<&str>) -> Option<Context> {
    let w = |k: usize| back(text, before, k);
    let kind = |k: usize| before.len().checked_sub(k + 1).map(|i| before[i].kind);
    Some(match (w(0), w(1)) {
        ("sense", _) | ("(", "toward") => Context::Sensors,
        ("link", _) => Context::Modules,
        (">", "-") if w(3) == "link" => Context::Modules,
        (">", "-") | ("|", _) => Context::Table,
        ("behavior", _) | ("{" | ";", "script" | "behavior" | "commit") => Context::Steps,
        ("script", _) => Context::Only(&["commit"]),
        ("turn", _) => Context::Only(&["left", "right", "toward"]),
        ("extends", _) => Context::Stages,
        ("trained", _) => Context::TrainingStages,
        ("module", _) => Context::InheritedModules,
        ("on", _) if block == Some("world") => Context::Walls,
        ("on", _) => Context::Only(&["behavior", "activation"]),
        ("activation", _) => Context::Words(words::ACTIVATION),
        ("weights", _) if block == Some("neural") => {
            Context::Only(&["evolvable", "fixed", "random", "trained"])
        }
        ("outputs", _) => Context::Only(&["sign", "linear"]),
        ("learn", _) => Context::Only(&["crbp"]),
        ("links", _) if matches!(block, Some("stage" | "role")) => Context::Only(&["all"]),
        ("role", _) => Context::Nothing,
        (_, "role") if kind(0) == Some(TokenKind::Word) => Context::Only(&["robots", "adds"]),
        ("all", "links") => Context::Only(&["evolvable", "fixed"]),
        ("test", _) => Context::Only(&["best"]),
        ("best", _) | ("train", _) => Context::Only(&["for"]),
        ("world", _) => Context::Only(&["adds", "changes"]),
        ("fitness", _) => Context::Only(&["adds", "per"]),
        ("per", _) if kind(1) == Some(TokenKind::Number) => Context::Words(words::EVENT),
        ("per", _) => Context::Only(&["action"]),
        ("action", "per") => Context::Expression,
        ("uses", _) => Context::Only(&["charger"]),
        ("selection", _) => Context::Only(&["truncation", "roulette"]),
        ("body", _) => Context::Only(&["khepera", "e-puck"]),
        ("proximity", _) if block == Some("body") => Context::Only(&["at", "facing"]),
        ("ground", _) if block == Some("body") => Context::Only(&["at"]),
        ("inheritance", _) => Context::Only(&["darwinian", "lamarckian"]),
        ("stage" | "robot" | "sensor" | "actuator" | "lamp" | "wall" | "zone" | "cylinder", _) => {
            Context::Nothing
        }
        _ => return None,
    })
}

/// The text of the `k`th token before the cursor (0: the last), or "".
fn back<'t>(text: &'t str, before: &[Token], k: usize) -> &'t str {
    before.len().checked_sub(k + 1).map_or("", |i| &text[before[i].span.start..before[i].span.end])
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
    let hardware = |sensor: bool| hardware_names(file, &stages, sensor);
    // The role the cursor is in: its modules are the ones a link names.
    let role = here.and_then(|s| s.roles().find(|r| r.span.start <= offset && offset <= r.span.end));
    let modules = |stages: &[&ast::StageDecl]| module_names(stages, role);
    match ctx {
        Context::Words(places) => of_words(places),
        Context::Only(list) => {
            list.iter().map(|t| completion(t, K::Keyword, words::word(t).map_or("", |w| w.meaning))).collect()
        }
        Context::Nothing => Vec::new(),
        Context::Fields(fields) => fields.iter().map(|(f, _, what)| completion(f, K::Field, what)).collect(),
        Context::Sensors => hardware(true).iter().map(|n| completion(n, K::Sensor, "sensor")).collect(),
        Context::Modules => modules(&stages).iter().map(|n| completion(n, K::Module, "module")).collect(),
        Context::InheritedModules => {
            let parents: Vec<&ast::StageDecl> = stages.iter().skip(1).copied().collect();
            // A role's modules are new: a stage with roles extends none.
            let parents = if here.is_some() && role.is_none() { parents } else { Vec::new() };
            modules(&parents)
                .iter()
                .map(|n| completion(n, K::Module, "inherited module: changes it"))
                .collect()
        }
        Context::Stages | Context::TrainingStages => file
            .iter()
            .flat_map(|f| f.stages.iter())
            .filter(|s| here.is_none_or(|h| h.name.text != s.name.text))
            .filter(|s| {
                ctx == Context::Stages || s.items.iter().any(|i| matches!(i, ast::StageItem::Train { .. }))
            })
            .map(|s| completion(&s.name.text, K::Stage, "stage"))
            .collect(),
        Context::Walls => {
            ["north", "south", "east", "west"].iter().map(|w| completion(w, K::Keyword, "wall")).collect()
        }
        Context::Steps | Context::Table => {
            let places = if ctx == Context::Steps { words::STEP } else { words::TABLE };
            let mut out = of_words(places);
            if ctx == Context::Table {
                out.retain(|c| c.label != "turn");
            }
            out.extend(["turn left", "turn right"].iter().map(|m| completion(m, K::Motion, "turn in place")));
            for a in hardware(false) {
                out.push(completion(
                    &format!("{a}(0.5, 0.5)"),
                    K::Actuator,
                    "wheel speeds (a `speed` actuator)",
                ));
                if ctx == Context::Steps {
                    out.push(completion(
                        &a,
                        K::Actuator,
                        "an actuator and a state: `arm down`, `claw closed`",
                    ));
                }
            }
            out
        }
        Context::Expression => {
            let mut out = of_words(words::EXPR);
            out.extend(hardware(true).iter().map(|n| completion(n, K::Sensor, "sensor")));
            out.extend(hardware(false).iter().map(|n| completion(n, K::Actuator, "actuator")));
            out
        }
    }
}

/// A completion item.
fn completion(label: &str, kind: CompletionKind, detail: &str) -> Completion {
    Completion { label: label.to_string(), kind, detail: detail.to_string() }
}

/// The words of the language that fit `places`, as completion items.
fn of_words(places: Places) -> Vec<Completion> {
    use CompletionKind as K;
    words::words()
        .into_iter()
        .filter(|w| w.places & places != 0)
        .map(|w| {
            let kind = match w.kind {
                words::WordKind::Function => K::Function,
                _ if places & (words::STEP | words::TABLE) != 0 => K::Motion,
                _ => K::Keyword,
            };
            completion(w.text, kind, w.meaning)
        })
        .collect()
}

/// The names of the sensors (`sensor`) or the actuators the robot and
/// `stages` declare, each once.
fn hardware_names(file: Option<&ast::File>, stages: &[&ast::StageDecl], sensor: bool) -> Vec<String> {
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
}

/// The names of the modules of `stages`, each once, or of `role`'s modules
/// in them: those of the role of that name in each stage (`role NAME adds
/// { ... }` adds to them).
fn module_names(stages: &[&ast::StageDecl], role: Option<&ast::RoleDecl>) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    let declared: Vec<&ast::ModuleDecl> = match role {
        Some(r) => stages
            .iter()
            .rev()
            .flat_map(|s| s.roles().filter(|x| x.name.text == r.name.text))
            .flat_map(|x| x.modules())
            .collect(),
        None => stages.iter().rev().flat_map(|s| s.all_modules()).collect(),
    };
    for m in declared {
        if !names.contains(&m.name.text) {
            names.push(m.name.text.clone());
        }
    }
    names
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

// ------------------------------------------------------------------ hover

/// What hover shows at byte `offset` of `text`, as Markdown, and the span
/// of the word it is about: a word of the language (its meaning and its
/// section of the reference), or a declared stage, module, sensor or
/// actuator (what the program, as far as it compiles, makes of it).
pub fn hover(text: &str, offset: usize) -> Option<(Span, String)> {
    if let Some((span, w)) = keyword_at(text, offset) {
        let md = format!(
            "**`{}`**: {}\n\n[docs/language.md#{2}](docs/language.md#{2})",
            w.text, w.meaning, w.section
        );
        return Some((span, md));
    }
    let span = word_at(text, offset)?;
    let word = &text[span.start..span.end];
    let file = parse_recovering(text).0?;
    let kind = declarations(&file).into_iter().find(|d| d.name.text == word)?.kind;
    // The stage the cursor is in (else the last one).
    let here = file.stages.iter().find(|s| s.span.start <= offset && offset <= s.span.end);
    // What stands of the program, errors or not (the parts with errors show
    // their placeholders; their diagnostics say what is wrong).
    let program = lower_partial(&file, "document.bat").0;
    let p = &program;
    let md = || -> Option<String> {
        Some(match kind {
            Kind::Stage => hover_stage(p, word)?,
            Kind::Module => hover_module(p, word, here, offset)?,
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
    let md = md().unwrap_or_else(|| format!("**{} `{word}`**", kind.as_str()));
    Some((span, md))
}

/// The hover of stage `word`: its place, what it extends, the modules it
/// adds and its genome's totals.
fn hover_stage(p: &Program, word: &str) -> Option<String> {
    let (i, st) = p.stage(word)?;
    let table = render_layout(p, i);
    let totals = table.lines().find(|l| l.starts_with("genes:")).unwrap_or("");
    let added: Vec<&str> =
        st.modules.iter().filter(|m| m.stage as usize == i).map(|m| m.name.as_str()).collect();
    let parent = st.parent.map(|j| format!(", extends `{}`", p.stages[j].name)).unwrap_or_default();
    Some(format!(
        "**stage `{word}`** ({} of {}{parent})\n\nadds modules: {}\n\n{totals}",
        i + 1,
        p.stages.len(),
        if added.is_empty() { "none".to_string() } else { added.join(", ") }
    ))
}

/// The hover of module `word` (the one of the stage `here` and the role
/// at `offset`, else of the last stage that has one): what it senses and
/// its rows of the genome layout.
fn hover_module(p: &Program, word: &str, here: Option<&ast::StageDecl>, offset: usize) -> Option<String> {
    let stage_name = here.map(|s| s.name.text.as_str());
    let (i, st) = match stage_name.and_then(|n| p.stage(n)) {
        Some((i, st)) if st.modules.iter().any(|m| m.name == word) => (i, st),
        _ => p.stages.iter().enumerate().rev().find(|(_, s)| s.modules.iter().any(|m| m.name == word))?,
    };
    // In a stage with roles, the module of the role at the
    // cursor (two roles may each have a module of this name).
    let role_at = here
        .and_then(|s| s.roles().find(|r| r.span.start <= offset && offset <= r.span.end))
        .and_then(|d| st.roles.iter().position(|x| x.name == d.name.text));
    let in_role = role_at
        .filter(|_| !st.roles.is_empty())
        .and_then(|r| st.role_modules(r).find(|&k| st.modules[k].name == word));
    let mi = in_role.or_else(|| st.modules.iter().position(|m| m.name == word))?;
    let m = &st.modules[mi];
    let label = crate::module_label(st, mi);
    let senses: Vec<String> = m.inputs.iter().map(|&c| channel(p, i, c)).collect();
    let table = render_layout(p, i);
    let mut rows: Vec<&str> = table.lines().skip(1).take(1).collect();
    rows.extend(table.lines().filter(|l| l.split_whitespace().nth(3) == Some(label.as_str())));
    // Weights that are not genes: what a training stage learned.
    let trained = format!("trained: `{label}` ");
    let extra: Vec<&str> = table.lines().filter(|l| l.starts_with(&trained)).collect();
    let genes = if rows.len() > 1 {
        format!("```text\n{}\n```", rows.join("\n"))
    } else {
        "no genes in this stage".to_string()
    };
    let extra = if extra.is_empty() { String::new() } else { format!("\n\n{}", extra.join("\n")) };
    let role = match label.split_once('.') {
        Some((r, _)) if !st.roles.is_empty() => format!(", role `{r}`"),
        _ => String::new(),
    };
    Some(format!(
        "**module `{word}`** in stage `{}`{role}\n\nsenses: {}\n\n{genes}{extra}",
        st.name,
        if senses.is_empty() { "nothing".into() } else { senses.join(", ") },
    ))
}

/// The name of a percept channel: `ir[3]`, `battery`.
fn channel(p: &Program, stage: usize, c: u16) -> String {
    match p.stages[stage].sensors.iter().find(|s| s.channel <= c && c < s.channel + s.count) {
        Some(s) if s.count == 1 => s.name.clone(),
        Some(s) => format!("{}[{}]", s.name, c - s.channel),
        None => format!("channel {c}"),
    }
}
