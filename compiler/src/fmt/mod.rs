//! The formatter: one canonical layout for a `.bat` file, comments kept.
//!
//! It works from the AST (for the structure) and the source (for comments,
//! line breaks and the spelling of numbers). Every construct is turned into
//! a [`Doc`] by one function below (`item`, `module_item`, `step`, ...):
//! a line of text, a line of aligned cells, a conditional chain that breaks
//! when too long, or a `head { ... }` block of items. A new construct of the
//! language is one new arm in the function of its parent (the `match`es are
//! exhaustive, so the compiler points at them).
//!
//! The rules, applied to every block:
//! - two spaces of indentation per level; one space between words;
//! - a block written on one line (no line break nor comment inside) stays on
//!   one line if it fits in [`WIDTH`] columns (the width of `rustfmt.toml`),
//!   items separated by two spaces, else each item gets a line (so does a
//!   block whose first item is on the line of its `{`); any other block has its items on their own lines, except items
//!   written on the same line as the previous one, which stay there;
//! - blank lines between items are kept, at most one, never after `{` nor
//!   before `}`; separators `,` and `;` are kept between items on one line
//!   and dropped at the end of a line;
//! - comments stay before or after the item they were written before or
//!   after; a comment inside an item (between its words) moves to the line
//!   before it; trailing comments of consecutive lines are aligned two
//!   spaces after the longest line, and so are the kinds of consecutive
//!   `sensor` and `actuator` declarations;
//! - numbers are kept as written; parentheses are exactly those the
//!   expression needs; a `reinforce c1 ? a1 : c2 ? a2 : e` too long for one
//!   line breaks before each `:`.
//!
//! [`format`] checks its own result: the output must parse and compile to the
//! same program (or the same errors) as the input.

use crate::diag::Diagnostics;
use crate::syntax::ast::*;
use crate::syntax::{self, Span};

use crate::syntax::lex::{self, Comment, Lexed, TokenKind};

/// The width a block written on one line must fit in to stay there.
pub const WIDTH: usize = 110;
const INDENT: usize = 2;

/// Why a source was not formatted.
#[derive(Debug)]
pub enum FormatError {
    /// The source does not parse: it is left as it is.
    Syntax(Diagnostics),
    /// The formatted text would not mean the same (a bug of the formatter).
    Changed(String),
}

/// Formats a whole file. `file_name` names the source in diagnostics.
pub fn format(source: &str, file_name: &str) -> Result<String, FormatError> {
    let file =
        syntax::parse(source).map_err(|e| FormatError::Syntax(Diagnostics::new(file_name, source, e)))?;
    let out = format_file(source, &file);
    if let Err(e) = syntax::parse(&out) {
        let msgs: Vec<String> = e.iter().map(|e| e.to_string()).collect();
        return Err(FormatError::Changed(format!("the formatted text does not parse: {}", msgs.join("; "))));
    }
    let outcome = |src: &str| crate::compile(src, file_name).map_err(|d| errors_text(&d));
    if outcome(source) != outcome(&out) {
        return Err(FormatError::Changed("the formatted text compiles to a different program".into()));
    }
    Ok(out)
}

fn errors_text(d: &Diagnostics) -> Vec<String> {
    d.errors().iter().map(|e| e.to_string()).collect()
}

/// Formats a parsed file (no checks).
pub fn format_file(src: &str, file: &File) -> String {
    let f = F { src, lx: lex::lex(src) };
    let mut items: Vec<Item> = Vec::new();
    for r in &file.robots {
        items.push(f.item(r.span, f.robot(r)));
    }
    for g in &file.genomes {
        items.push(f.item(g.span, f.genome(g)));
    }
    for s in &file.stages {
        items.push(f.item(s.span, f.stage(s)));
    }
    items.sort_by_key(|i| i.start);
    let pieces = f.pieces(items, 0, src.len(), false).1;
    let mut lines = Vec::new();
    render_pieces(&pieces, 0, false, &mut lines);
    let mut out = String::new();
    for line in align(lines) {
        out.push_str(line.trim_end());
        out.push('\n');
    }
    if out.trim().is_empty() {
        return String::new();
    }
    out
}

// ------------------------------------------------------------------ documents

/// What an item prints as.
#[derive(Clone, Debug)]
enum Doc {
    Text(String),
    /// Cells aligned with the cells of the neighbouring lines.
    Cells(Vec<String>),
    /// `prefix c1 ? a1 : c2 ? a2 : e`: the parts are `c1 ? a1`, `c2 ? a2`, `e`.
    Chain {
        prefix: String,
        parts: Vec<String>,
    },
    Block(Block),
}

#[derive(Clone, Debug)]
struct Block {
    head: String,
    head_comment: Option<String>,
    pieces: Vec<Piece>,
    /// Written on one line, without comments.
    flat: bool,
    /// Written with its first item on the line of its `{`: if it cannot
    /// stay on one line, each item gets its own.
    opens_inline: bool,
    /// Between the braces, exclusive.
    interior: (usize, usize),
}

#[derive(Clone, Debug)]
enum Piece {
    Comment { text: String, blank: bool },
    Entry(Entry),
}

#[derive(Clone, Debug)]
struct Entry {
    doc: Doc,
    blank: bool,
    /// On the same line as the previous entry.
    joined: bool,
    /// The separator written after this entry.
    sep: Option<&'static str>,
    /// The separator written before it, as printed when it shares a line.
    sep_before: Option<&'static str>,
    trailing: Option<String>,
}

/// An item of a block before its comments are placed: where it starts and
/// ends (its first and last words) and its document.
struct Item {
    start: usize,
    end: usize,
    doc: Doc,
}

impl Doc {
    fn flat(&self) -> Option<String> {
        match self {
            Doc::Text(t) => Some(t.clone()),
            Doc::Cells(c) => Some(c.join(" ")),
            Doc::Chain { prefix, parts } => Some(format!("{prefix}{}", parts.join(" : "))),
            Doc::Block(b) => {
                if !b.flat {
                    return None;
                }
                let mut s = format!("{} {{", b.head);
                let n = b.pieces.len();
                for (i, p) in b.pieces.iter().enumerate() {
                    let Piece::Entry(e) = p else { return None };
                    s.push(' ');
                    s.push_str(&e.doc.flat()?);
                    if i + 1 < n {
                        match e.sep {
                            Some(sep) => s.push_str(sep),
                            None => s.push(' '),
                        }
                    }
                }
                s.push_str(" }");
                Some(s)
            }
        }
    }
}

// ------------------------------------------------------------------ output lines

#[derive(Debug)]
struct Line {
    indent: usize,
    cells: Vec<String>,
    comment: Option<String>,
    blank: bool,
}

impl Line {
    fn new(indent: usize, cells: Vec<String>) -> Line {
        Line { indent, cells, comment: None, blank: false }
    }
}

fn render_pieces(pieces: &[Piece], indent: usize, one_per_line: bool, out: &mut Vec<Line>) {
    let mut first = true;
    // Whether the last line holds one entry that a joined entry may follow.
    let mut joinable = false;
    for p in pieces {
        match p {
            Piece::Comment { text, blank } => {
                if *blank && !first {
                    out.push(Line { indent: 0, cells: vec![], comment: None, blank: true });
                }
                out.push(Line { indent, cells: vec![], comment: Some(text.clone()), blank: false });
                joinable = false;
            }
            Piece::Entry(e) => {
                if e.joined && joinable && !one_per_line {
                    if let (Some(t), Some(last)) = (e.doc.flat(), out.last_mut()) {
                        let code = last.cells.join(" ");
                        last.cells = vec![format!("{code}{}{t}", e.sep_before.unwrap_or("  "))];
                        last.comment = e.trailing.clone();
                        joinable = e.trailing.is_none();
                        first = false;
                        continue;
                    }
                }
                if e.blank && !first {
                    out.push(Line { indent: 0, cells: vec![], comment: None, blank: true });
                }
                let flat = e.doc.flat().filter(|t| indent + t.len() <= WIDTH);
                let before = out.len();
                render_doc(&e.doc, flat, indent, out);
                if let Some(c) = &e.trailing {
                    if let Some(last) = out.last_mut() {
                        last.comment = Some(c.clone());
                    }
                }
                joinable = e.trailing.is_none() && out.len() == before + 1;
            }
        }
        first = false;
    }
}

fn render_doc(doc: &Doc, flat: Option<String>, indent: usize, out: &mut Vec<Line>) {
    match doc {
        Doc::Text(t) => out.push(Line::new(indent, vec![t.clone()])),
        Doc::Cells(c) => out.push(Line::new(indent, c.clone())),
        Doc::Chain { prefix, parts } => match flat {
            Some(t) => out.push(Line::new(indent, vec![t])),
            None => {
                out.push(Line::new(indent, vec![format!("{prefix}{}", parts[0])]));
                let hang = indent + prefix.len().saturating_sub(2);
                for p in &parts[1..] {
                    out.push(Line::new(hang, vec![format!(": {p}")]));
                }
            }
        },
        Doc::Block(b) => match flat {
            Some(t) => out.push(Line::new(indent, vec![t])),
            None => {
                let mut head = Line::new(indent, vec![format!("{} {{", b.head)]);
                head.comment = b.head_comment.clone();
                out.push(head);
                // A block begun on the line of its `{` that cannot stay on one
                // line gets one item per line.
                render_pieces(&b.pieces, indent + INDENT, b.flat || b.opens_inline, out);
                out.push(Line::new(indent, vec!["}".into()]));
            }
        },
    }
}

/// Aligns the second cells of consecutive two-cell lines, and the trailing
/// comments of consecutive lines, then writes the lines out.
fn align(mut lines: Vec<Line>) -> Vec<String> {
    let n = lines.len();
    let mut i = 0;
    while i < n {
        let run = |l: &Line, first: &Line| !l.blank && l.cells.len() == 2 && l.indent == first.indent;
        let mut j = i;
        while j < n && run(&lines[j], &lines[i]) {
            j += 1;
        }
        if j > i {
            let w = lines[i..j].iter().map(|l| l.cells[0].len()).max().unwrap_or(0);
            for l in &mut lines[i..j] {
                let c0 = format!("{:w$} {}", l.cells[0], l.cells[1]);
                l.cells = vec![c0];
            }
            i = j;
        } else {
            i += 1;
        }
    }
    let code: Vec<String> = lines.iter().map(|l| l.cells.join(" ")).collect();
    let has_trailing =
        |l: &Line, c: &str| !c.is_empty() && l.comment.as_ref().is_some_and(|t| !t.contains('\n'));
    let mut out = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        if has_trailing(&lines[i], &code[i]) {
            // The run: the following code lines of the same indentation.
            let mut j = i;
            while j < n && !lines[j].blank && !code[j].is_empty() && lines[j].indent == lines[i].indent {
                j += 1;
            }
            let w = (i..j)
                .filter(|&k| has_trailing(&lines[k], &code[k]))
                .map(|k| code[k].len())
                .max()
                .unwrap_or(0);
            for k in i..j {
                let pad = " ".repeat(lines[k].indent);
                out.push(match &lines[k].comment {
                    Some(c) if has_trailing(&lines[k], &code[k]) => format!("{pad}{:w$}  {c}", code[k]),
                    Some(c) => format!("{pad}{}  {c}", code[k]),
                    None => format!("{pad}{}", code[k]),
                });
            }
            i = j;
            continue;
        }
        let l = &lines[i];
        out.push(match (&l.comment, code[i].is_empty()) {
            _ if l.blank => String::new(),
            (Some(c), true) => format!("{}{c}", " ".repeat(l.indent)),
            (Some(c), false) => format!("{}{}  {c}", " ".repeat(l.indent), code[i]),
            (None, _) => format!("{}{}", " ".repeat(l.indent), code[i]),
        });
        i += 1;
    }
    out
}

// ------------------------------------------------------------------ building

struct F<'a> {
    src: &'a str,
    lx: Lexed,
}

impl F<'_> {
    fn text(&self, span: Span) -> &str {
        &self.src[span.start..span.end]
    }

    fn comment_text(&self, c: &Comment) -> String {
        self.text(c.span).trim_end().to_string()
    }

    fn item(&self, span: Span, doc: Doc) -> Item {
        Item { start: span.start, end: self.lx.token_end(span), doc }
    }

    /// An item whose span starts after its keyword (`behavior`, `hidden`,
    /// `outputs`, `weights`).
    fn item_after_keyword(&self, span: Span, doc: Doc) -> Item {
        let start = self.lx.token_before(span.start).map_or(span.start, |t| t.span.start);
        Item { start, end: self.lx.token_end(span), doc }
    }

    fn has_newline(&self, a: usize, b: usize) -> bool {
        a < b && self.src[a..b].contains('\n')
    }

    fn has_blank_line(&self, a: usize, b: usize) -> bool {
        a < b && self.src[a..b].matches('\n').count() >= 2
    }

    /// A `head { items }` block spanning `span` (which ends with its `}`).
    fn block(&self, head: String, span: Span, mut items: Vec<Item>) -> Doc {
        items.sort_by_key(|i| i.start);
        let open = self
            .lx
            .tokens_in(span)
            .iter()
            .find(|t| self.text(t.span) == "{")
            .map_or(span.start, |t| t.span.start);
        let close = self.lx.token_end(span).saturating_sub(1).max(open);
        let flat = !self.has_newline(open, close)
            && self.lx.comments_in(span.start, close).is_empty()
            && items.iter().all(|i| i.doc.flat().is_some());
        let opens_inline = !self.has_newline(open, items.first().map_or(close, |i| i.start));
        let (head_comment, pieces) = self.pieces(items, open + 1, close, true);
        Doc::Block(Block { head, head_comment, pieces, flat, opens_inline, interior: (open + 1, close) })
    }

    /// Places the comments between `lo` and `hi` around the items.
    fn pieces(&self, items: Vec<Item>, lo: usize, hi: usize, has_head: bool) -> (Option<String>, Vec<Piece>) {
        let mut head_comment: Option<String> = None;
        let mut pieces: Vec<Piece> = Vec::new();
        let mut comments = self.lx.comments_in(lo, hi).iter().peekable();
        // The end of the last thing placed (for blank lines and line breaks).
        let mut prev_end = lo;
        // Whether the previous entry (or the head) can take a trailing comment.
        let mut trailing_target = has_head;
        let mut last_entry: Option<usize> = None;
        for (idx, it) in items.iter().enumerate() {
            // Comments before the item.
            let mut hoisted = Vec::new();
            while let Some(c) = comments.next_if(|c| c.span.start < it.end) {
                if c.span.start >= it.start {
                    let inner = match &it.doc {
                        Doc::Block(b) => c.span.start >= b.interior.0 && c.span.start < b.interior.1,
                        _ => false,
                    };
                    if !inner {
                        hoisted.push(self.comment_text(c));
                    }
                    continue;
                }
                let same_line = !self.has_newline(prev_end, c.span.start);
                if same_line && trailing_target {
                    let text = self.comment_text(c);
                    let slot = match last_entry {
                        Some(k) => match &mut pieces[k] {
                            Piece::Entry(e) => &mut e.trailing,
                            Piece::Comment { .. } => &mut head_comment,
                        },
                        None => &mut head_comment,
                    };
                    append_comment(slot, text);
                } else {
                    let blank = self.has_blank_line(prev_end, c.span.start);
                    pieces.push(Piece::Comment { text: self.comment_text(c), blank });
                    trailing_target = false;
                }
                prev_end = c.span.end;
            }
            let blank = self.has_blank_line(prev_end, it.start);
            let joined = idx > 0
                && trailing_target
                && hoisted.is_empty()
                && matches!(pieces.last(), Some(Piece::Entry(e)) if e.trailing.is_none())
                && !self.has_newline(prev_end, it.start);
            let entry_blank = blank && hoisted.is_empty();
            for (k, h) in hoisted.into_iter().enumerate() {
                pieces.push(Piece::Comment { text: h, blank: blank && k == 0 });
            }
            if let Some(k) = last_entry {
                let sep = items.get(idx.wrapping_sub(1)).and_then(|p| self.separator(p.end, it.start));
                if let Piece::Entry(e) = &mut pieces[k] {
                    e.sep = sep;
                }
            }
            pieces.push(Piece::Entry(Entry {
                doc: it.doc.clone(),
                blank: entry_blank,
                joined,
                sep: None,
                sep_before: None,
                trailing: None,
            }));
            last_entry = Some(pieces.len() - 1);
            trailing_target = true;
            prev_end = it.end;
        }
        for c in comments {
            let same_line = !self.has_newline(prev_end, c.span.start);
            let text = self.comment_text(c);
            if same_line && trailing_target {
                let slot = match last_entry.map(|k| &mut pieces[k]) {
                    Some(Piece::Entry(e)) => &mut e.trailing,
                    _ => &mut head_comment,
                };
                append_comment(slot, text);
            } else {
                let blank = self.has_blank_line(prev_end, c.span.start);
                pieces.push(Piece::Comment { text, blank });
                trailing_target = false;
            }
            prev_end = c.span.end;
        }
        separators_before(&mut pieces);
        (head_comment, pieces)
    }

    /// `,` or `;` between two items.
    fn separator(&self, end: usize, next: usize) -> Option<&'static str> {
        let t = self.lx.token_at(end)?;
        if t.span.start >= next {
            return None;
        }
        match self.text(t.span) {
            "," => Some(","),
            ";" => Some(";"),
            _ => None,
        }
    }

    // -------------------------------------------------------------- numbers

    /// A number as written within `span` (the first one with this value).
    fn num(&self, v: f64, span: Span) -> String {
        let toks = self.lx.tokens_in(span);
        for (i, t) in toks.iter().enumerate() {
            if t.kind != TokenKind::Number {
                continue;
            }
            let signed = i > 0 && self.text(toks[i - 1].span) == "-" && toks[i - 1].span.end == t.span.start;
            let text = if signed { &self.src[toks[i - 1].span.start..t.span.end] } else { self.text(t.span) };
            if text.parse::<f64>().is_ok_and(|x| x.to_bits() == v.to_bits()) {
                return text.to_string();
            }
        }
        format!("{v}")
    }

    fn qty(&self, q: &Quantity) -> String {
        let n = self.num(q.value, q.span);
        match q.unit {
            None => n,
            Some(u) => {
                let word = self
                    .lx
                    .tokens_in(q.span)
                    .iter()
                    .rev()
                    .find(|t| t.kind == TokenKind::Word)
                    .map_or(u.as_str(), |t| self.text(t.span));
                match u {
                    Unit::Actions => format!("{n} {word}"),
                    _ => format!("{n}{word}"),
                }
            }
        }
    }

    fn range(&self, r: &Range) -> String {
        format!("{}..{}", self.num(r.lo, r.span), self.num(r.hi, r.span))
    }

    fn index(i: &Option<Index>) -> String {
        match i {
            None => String::new(),
            Some(Index { first, last: None, .. }) => format!("[{first}]"),
            Some(Index { first, last: Some(l), .. }) => format!("[{first}..{l}]"),
        }
    }

    fn sensor_refs(refs: &[SensorRef]) -> String {
        let v: Vec<String> =
            refs.iter().map(|r| format!("{}{}", r.name.text, Self::index(&r.index))).collect();
        v.join(", ")
    }

    // -------------------------------------------------------------- top level

    fn robot(&self, r: &Robot) -> Doc {
        let items = r.hardware.iter().map(|h| self.item(h.span, self.hardware(h))).collect();
        self.block(format!("robot {}", r.name.text), r.span, items)
    }

    fn hardware(&self, h: &Hardware) -> Doc {
        let word = if h.is_sensor { "sensor" } else { "actuator" };
        let count = h.count.map_or(String::new(), |(n, _)| format!("[{n}]"));
        Doc::Cells(vec![format!("{word} {}{count}", h.name.text), h.kind.text.clone()])
    }

    fn genome(&self, g: &GenomeBlock) -> Doc {
        let items = g
            .settings
            .iter()
            .map(|s| {
                let mut words = Vec::new();
                if let Some(gr) = &s.group {
                    words.push(gr.text.clone());
                }
                if let Some(b) = &s.bits {
                    words.push(format!("bits {}", self.qty(b)));
                }
                if let Some(r) = &s.range {
                    words.push(format!("range {}", self.range(r)));
                }
                // `bits 4  range -1..1` reads as two settings; `links bits 6 range -2..2` as one.
                let sep = if s.group.is_some() { " " } else { "  " };
                self.item(s.span, Doc::Text(words.join(sep)))
            })
            .collect();
        self.block("genome".into(), g.span, items)
    }

    fn stage(&self, s: &StageDecl) -> Doc {
        let mut head = format!("stage {}", s.name.text);
        if let Some(p) = &s.extends {
            head += &format!(" extends {}", p.text);
        }
        let items = s.items.iter().map(|i| self.stage_item(i)).collect();
        self.block(head, s.span, items)
    }

    /// One declaration of a stage.
    fn stage_item(&self, i: &StageItem) -> Item {
        match i {
            StageItem::RobotAdds(hw, span) => {
                let items = hw.iter().map(|h| self.item(h.span, self.hardware(h))).collect();
                self.item(*span, self.block("robot adds".into(), *span, items))
            }
            StageItem::Genome(g) => self.item(g.span, self.genome(g)),
            StageItem::World(w) => {
                let head = match w.mode {
                    WorldMode::Set => "world",
                    WorldMode::Adds => "world adds",
                    WorldMode::Changes => "world changes",
                };
                let items = w.items.iter().map(|x| self.world_item(x)).collect();
                self.item(w.span, self.block(head.into(), w.span, items))
            }
            StageItem::Evolve(settings, span) => {
                let items = settings.iter().map(|s| self.item(s.span, Doc::Text(self.setting(s)))).collect();
                self.item(*span, self.block("evolve".into(), *span, items))
            }
            StageItem::Test { lives, actions, learning, span } => {
                let mut t = "test best for ".to_string();
                if let Some(l) = lives {
                    let word = if l.value == 1.0 { "life" } else { "lives" };
                    t += &format!("{} {word} of ", self.qty(l));
                }
                t += &self.qty(actions);
                if self.lx.tokens_in(*span).iter().any(|t| self.text(t.span) == "learning") {
                    t += if *learning { " with learning" } else { " without learning" };
                }
                self.item(*span, Doc::Text(t))
            }
            StageItem::Train { actions, span } => {
                self.item(*span, Doc::Text(format!("train for {}", self.qty(actions))))
            }
            StageItem::Fitness(f) => self.item(f.span, Doc::Text(self.fitness(f))),
            StageItem::Module(m) => {
                let items = m.items.iter().map(|x| self.module_item(x)).collect();
                self.item(m.span, self.block(format!("module {}", m.name.text), m.span, items))
            }
            StageItem::LinksAll(kind, span) => {
                self.item(*span, Doc::Text(format!("links all {}", self.link_kind(kind, *span))))
            }
            StageItem::Variants(v) => {
                let mut head = format!("variants {}", v.aggregate.text);
                if let Some(d) = &v.draw {
                    head += &format!(" draw {}", self.qty(d));
                }
                let items = v
                    .variants
                    .iter()
                    .map(|d| {
                        let items = d.world.items.iter().map(|x| self.world_item(x)).collect();
                        self.item(d.span, self.block(d.name.text.clone(), d.span, items))
                    })
                    .collect();
                self.item(v.span, self.block(head, v.span, items))
            }
            StageItem::Role(r) => {
                let head = match &r.robots {
                    Some(q) if !r.adds => format!("role {} robots {}", r.name.text, self.qty(q)),
                    _ => format!("role {} adds", r.name.text),
                };
                if !r.body {
                    return self.item(r.span, Doc::Text(head));
                }
                let items = r.items.iter().map(|x| self.stage_item(x)).collect();
                self.item(r.span, self.block(head, r.span, items))
            }
            StageItem::Link(l) => self.item(
                l.span,
                Doc::Text(format!(
                    "link {} -> {} {}",
                    l.from.text,
                    l.to.text,
                    self.link_kind(&l.kind, l.span)
                )),
            ),
        }
    }

    fn world_item(&self, x: &WorldItem) -> Item {
        let t = match x {
            WorldItem::Arena { width, depth, .. } => {
                format!("arena {} x {}", self.qty(width), self.qty(depth))
            }
            WorldItem::Charger { length, wall, lamp, .. } => {
                let mut t = format!("charger {} on {} wall", self.qty(length), wall.text);
                match lamp {
                    None => {}
                    Some(None) => t += " with lamp",
                    Some(Some(h)) => t += &format!(" with lamp {}", self.qty(h)),
                }
                t
            }
            WorldItem::Battery(q, _) => format!("battery {}", self.qty(q)),
            WorldItem::Recharge(q, _) => format!("recharge {}", self.qty(q)),
            WorldItem::Robots(q, _) => format!("robots {}", self.qty(q)),
            WorldItem::RoleRobots { name, robots, .. } => {
                format!("role {} robots {}", name.text, self.qty(robots))
            }
            WorldItem::Objects { count, diameter, virtual_, .. } => {
                let mut t = "objects".to_string();
                if let Some(c) = count {
                    t += &format!(" {}", self.qty(c));
                }
                if let Some(d) = diameter {
                    t += &format!(" diameter {}", self.qty(d));
                }
                match virtual_ {
                    Some(true) => t += " virtual",
                    Some(false) => t += " physical",
                    None => {}
                }
                t
            }
            WorldItem::Wall { name, from, to, .. } => {
                format!("wall{} from {} to {}", self.item_name(name), self.point(from), self.point(to))
            }
            WorldItem::Cylinder { name, at, diameter, .. } => {
                format!(
                    "cylinder{} at {} diameter {}",
                    self.item_name(name),
                    self.point(at),
                    self.qty(diameter)
                )
            }
            WorldItem::Lamp { name, at, height, intensity, switch, .. } => {
                let mut t = format!("lamp{} at {}", self.item_name(name), self.point(at));
                if let Some(h) = height {
                    t += &format!(" height {}", self.qty(h));
                }
                if let Some(k) = intensity {
                    t += &format!(" intensity {}", self.qty(k));
                }
                if let Some((on, n)) = switch {
                    t += &format!(" {} at {}", if *on { "on" } else { "off" }, self.qty(n));
                }
                t
            }
            WorldItem::Zone { name, from, to, grey, charger, .. } => {
                let mut t =
                    format!("zone{} from {} to {}", self.item_name(name), self.point(from), self.point(to));
                if let Some(g) = grey {
                    t += &format!(" grey {}", self.qty(g));
                }
                if *charger {
                    t += " charger";
                }
                t
            }
            WorldItem::Start { from, to, heading, .. } => {
                let mut t = match to {
                    None => format!("start at {}", self.point(from)),
                    Some(to) => format!("start from {} to {}", self.point(from), self.point(to)),
                };
                if let Some(h) = heading {
                    t += &format!(" heading {}", self.qty(h));
                }
                t
            }
            WorldItem::Place { name, at, heading, after, .. } => format!(
                "place{} at {} heading {} after {}",
                self.item_name(name),
                self.point(at),
                self.qty(heading),
                self.qty(after)
            ),
            WorldItem::Body { preset, items, span } => return self.body(preset.as_ref(), items, *span),
        };
        self.item(x.span(), Doc::Text(t))
    }

    /// `body [PRESET]`, and its block of settings and sensor layouts if it
    /// has one.
    fn body(&self, preset: Option<&Name>, items: &[BodyItem], span: Span) -> Item {
        let head = preset.map_or("body".to_string(), |p| format!("body {}", p.text));
        if !self.lx.tokens_in(span).iter().any(|t| self.text(t.span) == "{") {
            return self.item(span, Doc::Text(head));
        }
        let items = items
            .iter()
            .map(|i| match i {
                BodyItem::Setting(s) => self.item(s.span, Doc::Text(self.setting(s))),
                BodyItem::Layout(l) => self.item(l.span, Doc::Text(self.layout(l))),
            })
            .collect();
        self.item(span, self.block(head, span, items))
    }

    /// `proximity at [...] facing [...]`, `ground at [...]`.
    fn layout(&self, l: &SensorLayout) -> String {
        let mut t = l.kind.text.clone();
        if let Some((spots, _)) = &l.at {
            let spots: Vec<String> = spots
                .iter()
                .map(|s| match s {
                    Spot::Angle(q) => self.qty(q),
                    Spot::Point(p) => self.point(p),
                })
                .collect();
            t += &format!(" at [{}]", spots.join(", "));
        }
        if let Some((qs, _)) = &l.facing {
            let qs: Vec<String> = qs.iter().map(|q| self.qty(q)).collect();
            t += &format!(" facing [{}]", qs.join(", "));
        }
        t
    }

    fn point(&self, p: &Point) -> String {
        format!("({}, {})", self.qty(&p.x), self.qty(&p.y))
    }

    fn item_name(&self, n: &Option<Name>) -> String {
        n.as_ref().map_or(String::new(), |n| format!(" {}", n.text))
    }

    fn setting(&self, s: &Setting) -> String {
        match &s.value {
            SettingValue::Truncation(q) => format!("selection truncation keep {}", self.qty(q)),
            SettingValue::Quantity(q) => format!("{} {}", s.name.text, self.qty(q)),
            SettingValue::Word(w) => format!("{} {}", s.name.text, w.text),
            SettingValue::WordAndNumber(w, q) => format!("{} {} {}", s.name.text, w.text, self.qty(q)),
        }
    }

    fn fitness(&self, f: &FitnessDecl) -> String {
        let mut terms: Vec<(usize, String)> =
            f.per_action.iter().map(|e| (e.span.start, format!("per action {}", self.expr(e)))).collect();
        for e in &f.at_end {
            terms.push((e.span.start, format!("at end {}", self.expr(e))));
        }
        for b in &f.bonuses {
            terms.push((b.span.start, format!("{} per {}", self.num(b.points, b.span), b.event.text)));
        }
        for (w, span) in &f.team {
            terms.push((span.start, format!("team {}", w.text)));
        }
        terms.sort_by_key(|t| t.0);
        let terms: Vec<String> = terms.into_iter().map(|t| t.1).collect();
        format!("fitness {}{}", if f.adds { "adds " } else { "" }, terms.join(", "))
    }

    fn link_kind(&self, k: &LinkKind, span: Span) -> String {
        match k {
            LinkKind::Evolvable(None) => "evolvable".into(),
            LinkKind::Evolvable(Some(r)) => format!("evolvable range {}", self.range(r)),
            LinkKind::Fixed(v) => format!("fixed {}", self.num(*v, span)),
        }
    }

    // -------------------------------------------------------------- modules

    /// One declaration of a module.
    fn module_item(&self, x: &ModuleItem) -> Item {
        match x {
            ModuleItem::Sense(refs, span) => {
                self.item(*span, Doc::Text(format!("sense {}", Self::sensor_refs(refs))))
            }
            ModuleItem::Activation(a) => {
                let mut parts: Vec<(usize, String)> = Vec::new();
                if let Some(s) = &a.source {
                    parts.push((s.span().start, self.weights(s)));
                }
                if let Some(h) = &a.hidden {
                    let rec = if a.recurrent { " recurrent" } else { "" };
                    parts.push((h.span.start, format!("hidden {}{rec}", self.qty(h))));
                }
                if let Some(r) = &a.range {
                    parts.push((r.span.start, format!("range {}", self.range(r))));
                }
                parts.sort_by_key(|p| p.0);
                let words: Vec<String> = parts.into_iter().map(|p| p.1).collect();
                self.item(a.span, Doc::Text(format!("activation {}", words.join(" "))))
            }
            ModuleItem::Behavior(b) => self.behavior(b),
            ModuleItem::Learn(l) => {
                let mut t = "learn crbp".to_string();
                if let Some((r, p, s)) = l.rates {
                    t += &format!("({}, {}", self.num(r, s), self.num(p, s));
                    if let Some(e) = &l.error {
                        t += &format!(", error {}", e.text);
                    }
                    t += ")";
                }
                t += &format!(" on {}", l.target.text);
                match l.below {
                    None => t += " always",
                    Some(x) => t += &format!(" when performance < {}", self.num(x, l.span)),
                }
                if let Some(w) = &l.window {
                    t += &format!(" over {}", self.qty(w));
                }
                self.item(l.span, Doc::Text(t))
            }
            ModuleItem::Reinforce(e, span) => self.item(*span, self.chain("reinforce ", e)),
        }
    }

    fn weights(&self, s: &WeightSource) -> String {
        match s {
            WeightSource::Evolvable(_) => "evolvable".into(),
            WeightSource::Trained(stage, _) => format!("trained {}", stage.text),
            WeightSource::Random(r, _) => format!("random {}", self.range(r)),
            WeightSource::Fixed(vals, span) => {
                let v: Vec<String> = vals.iter().map(|v| self.num(*v, *span)).collect();
                if self.lx.tokens_in(*span).iter().any(|t| self.text(t.span) == "[") {
                    format!("fixed [{}]", v.join(", "))
                } else {
                    format!("fixed {}", v.join(", "))
                }
            }
        }
    }

    fn behavior(&self, b: &BehaviorDecl) -> Item {
        match b {
            BehaviorDecl::Script(steps, commit, span) => {
                let braced =
                    self.lx.token_at(span.start).is_some_and(|t| matches!(self.text(t.span), "script" | "{"));
                if !braced && steps.len() == 1 {
                    return self
                        .item_after_keyword(*span, Doc::Text(format!("behavior {}", self.step(&steps[0]))));
                }
                let head = if *commit { "behavior script commit" } else { "behavior script" };
                let items = steps.iter().map(|s| self.item(s.span, Doc::Text(self.step(s)))).collect();
                self.item_after_keyword(*span, self.block(head.into(), *span, items))
            }
            BehaviorDecl::Neural(n) => {
                let mut items = Vec::new();
                if let Some((refs, span)) = &n.sense {
                    items.push(self.item(*span, Doc::Text(format!("sense {}", Self::sensor_refs(refs)))));
                }
                if let Some(h) = &n.hidden {
                    let rec = if n.recurrent { " recurrent" } else { "" };
                    items.push(
                        self.item_after_keyword(h.span, Doc::Text(format!("hidden {}{rec}", self.qty(h)))),
                    );
                }
                if let Some(o) = &n.outputs {
                    let (t, span) = match o {
                        OutputsDecl::Sign { count, table, span } => {
                            let entries: Vec<String> =
                                table.iter().map(|(m, s)| self.table_entry(m, *s)).collect();
                            (format!("outputs sign({}) -> {}", self.qty(count), entries.join(" | ")), *span)
                        }
                        OutputsDecl::Linear { scale: None, span } => ("outputs linear".into(), *span),
                        OutputsDecl::Linear { scale: Some(s), span } => {
                            (format!("outputs linear scale {}", self.num(*s, *span)), *span)
                        }
                    };
                    items.push(self.item_after_keyword(span, Doc::Text(t)));
                }
                if let Some(b) = &n.broadcast {
                    items.push(self.item_after_keyword(b.span, Doc::Text(format!("broadcast {}", b.text))));
                }
                if let Some(w) = &n.weights {
                    items.push(
                        self.item_after_keyword(w.span(), Doc::Text(format!("weights {}", self.weights(w)))),
                    );
                }
                self.item_after_keyword(n.span, self.block("behavior neural".into(), n.span, items))
            }
        }
    }

    fn table_entry(&self, m: &Motion, span: Span) -> String {
        let bare =
            self.lx.token_at(span.start).is_some_and(|t| matches!(self.text(t.span), "left" | "right"));
        let t = self.motion(m, span);
        match t.strip_prefix("turn ") {
            Some(rest) if bare => rest.to_string(),
            _ => t,
        }
    }

    fn speed(&self, v: Option<f64>, span: Span) -> String {
        v.map_or(String::new(), |v| format!("({})", self.num(v, span)))
    }

    fn motion(&self, m: &Motion, span: Span) -> String {
        match m {
            Motion::Forward(v) => format!("forward{}", self.speed(*v, span)),
            Motion::Back(v) => format!("back{}", self.speed(*v, span)),
            Motion::TurnLeft(v) => format!("turn left{}", self.speed(*v, span)),
            Motion::TurnRight(v) => format!("turn right{}", self.speed(*v, span)),
            Motion::Stop => "stop".into(),
            Motion::Wheels(n, speeds) => {
                let speeds: Vec<String> = speeds.iter().map(|v| self.num(*v, span)).collect();
                format!("{}({})", n.text, speeds.join(", "))
            }
        }
    }

    /// A step of a script.
    fn step(&self, s: &StepDecl) -> String {
        let mut t = match &s.action {
            ActionDecl::Motion(m, span) => self.motion(m, *span),
            ActionDecl::Toward { refs, speed, span } => {
                let turn = self.lx.token_at(span.start).is_some_and(|t| self.text(t.span) == "turn");
                let mut t = format!("{}toward({}", if turn { "turn " } else { "" }, Self::sensor_refs(refs));
                if let Some(v) = speed {
                    t += &format!(", {}", self.num(*v, *span));
                }
                t + ")"
            }
            ActionDecl::Wait(_) => "wait".into(),
            ActionDecl::Recharge(_) => "recharge".into(),
            ActionDecl::Reinforce(e, _) => format!("reinforce {}", self.expr(e)),
            ActionDecl::Set { actuator, state: Some(state), .. } => {
                format!("{} {}", actuator.text, state.text)
            }
            ActionDecl::Set { actuator, state: None, .. } => actuator.text.clone(),
        };
        match &s.end {
            None => {}
            Some(EndDecl::For(q)) => t += &format!(" for {}", self.qty(q)),
            Some(EndDecl::Until { cond, within, .. }) => {
                t += &format!(" until {}", self.expr(cond));
                if let Some(w) = within {
                    t += &format!(" within {}", self.qty(w));
                }
            }
        }
        if s.uses_charger.is_some() {
            t += " uses charger";
        }
        if let Some(c) = &s.cond {
            t += &format!(" if {}", self.expr(c));
        }
        t
    }

    // -------------------------------------------------------------- expressions

    /// `prefix EXPR`, broken before each `:` of a conditional chain when too long.
    fn chain(&self, prefix: &str, e: &Expr) -> Doc {
        let mut parts = Vec::new();
        let mut e = e;
        while let ExprKind::Cond(c, a, b) = &e.kind {
            parts.push(format!("{} ? {}", self.sub(c, 2), self.expr(a)));
            e = b;
        }
        parts.push(self.sub(e, 1));
        Doc::Chain { prefix: prefix.to_string(), parts }
    }

    fn expr(&self, e: &Expr) -> String {
        match &e.kind {
            ExprKind::Number(v, unit) => {
                let n = self.num(*v, e.span);
                match unit {
                    None => n,
                    Some(_) => self.qty(&Quantity { value: *v, unit: *unit, span: e.span }),
                }
            }
            ExprKind::Ref(n, i) => format!("{}{}", n.text, Self::index(i)),
            ExprKind::State(n) => format!("robot.{}", n.text),
            ExprKind::Team(n) => format!("team.{}", n.text),
            ExprKind::Call(n, args) => {
                let a: Vec<String> = args.iter().map(|a| self.expr(a)).collect();
                format!("{}({})", n.text, a.join(", "))
            }
            ExprKind::Unary(UnOp::Neg, x) => format!("-{}", self.sub(x, 8)),
            ExprKind::Unary(UnOp::Prev, x) => format!("prev {}", self.sub(x, 8)),
            ExprKind::Unary(UnOp::Not, x) => format!("not {}", self.sub(x, 4)),
            ExprKind::Binary(op, a, b) => {
                let p = level(e);
                format!("{} {} {}", self.sub(a, p), op.text(), self.sub(b, p + 1))
            }
            ExprKind::Cond(c, a, b) => format!("{} ? {} : {}", self.sub(c, 2), self.expr(a), self.sub(b, 1)),
        }
    }

    /// An operand that must bind at least as tightly as `min`.
    fn sub(&self, e: &Expr, min: u8) -> String {
        let s = self.expr(e);
        if level(e) < min {
            format!("({s})")
        } else {
            s
        }
    }
}

/// A trailing comment added to `slot`, after the one already there.
fn append_comment(slot: &mut Option<String>, text: String) {
    *slot = Some(match slot.take() {
        Some(t) => format!("{t} {text}"),
        None => text,
    });
}

/// The separator written between two entries goes to the later one (it is
/// printed only when they share a line).
fn separators_before(pieces: &mut [Piece]) {
    let mut sep = None;
    for p in pieces {
        if let Piece::Entry(e) = p {
            e.sep_before = sep.take().map(|s| if s == "," { ", " } else { "; " });
            sep = e.sep;
        } else {
            sep = None;
        }
    }
}

/// How tightly an expression binds (the grammar's precedence, 9 for operands).
fn level(e: &Expr) -> u8 {
    match &e.kind {
        ExprKind::Cond(..) => 1,
        ExprKind::Binary(op, ..) => match op {
            BinOp::Or => 2,
            BinOp::And => 3,
            BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge | BinOp::Eq | BinOp::Ne => 5,
            BinOp::Add | BinOp::Sub => 6,
            BinOp::Mul | BinOp::Div => 7,
        },
        ExprKind::Unary(UnOp::Not, _) => 4,
        ExprKind::Unary(..) => 8,
        ExprKind::Number(..)
        | ExprKind::Ref(..)
        | ExprKind::State(..)
        | ExprKind::Team(..)
        | ExprKind::Call(..) => 9,
    }
}
