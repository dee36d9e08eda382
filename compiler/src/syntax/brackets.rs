//! Brackets left open: where a parse fails because a `(`, `[` or `{` was
//! never closed, the syntax error names that bracket (and the block it
//! opens) instead of the token where the parse noticed.
//!
//! A lexical walk over the source around the error (its stage item, or its
//! top-level part), comments skipped: a closing
//! bracket closes the innermost bracket of its kind still open (the ones
//! it skips are left open, as `(` in `toward(light }`). A `}` that starts a
//! line less indented than the line of the `{` it closes most likely
//! belongs to an outer block: that `{` is a suspect, preferred when the
//! parse only fails at the end of the file or at the next stage.

use miette::LabeledSpan;

use super::recover::{starts_item, word};
use super::Span;
use crate::diag::Error;
use crate::syntax::lex::{lex, Token, TokenKind};

struct Open {
    /// Index of the bracket's token.
    tok: usize,
    bracket: u8,
}

fn closing(open: u8) -> u8 {
    match open {
        b'(' => b')',
        b'[' => b']',
        _ => b'}',
    }
}

/// The bracket left open that made the parse fail at `pos`, if the failure
/// looks like one: the token there closes a bracket outside the innermost,
/// opens a block or is an arrow `->` while a `(` or `[` is open,
/// the end of the file, a word that starts a stage or a stage item inside a
/// block that cannot hold it, or a word that starts a clause (see
/// [`CLAUSE_WORDS`]) while a `(` or `[` is open.
///
/// Only the source around `pos` is read (from the last line starting a
/// stage item, or at the end of the file and at a `stage` or `robot`, from
/// the last line starting with `stage` or `robot`), so that a file with
/// many syntax errors is not read whole for each.
pub(super) fn unclosed(src: &str, pos: usize, at: Span, found: &str) -> Option<Error> {
    // At the end of the file or at the next stage, the whole part matters
    // (its own `{`, and suspects); elsewhere the item around `pos` does.
    let rest = src[pos..].trim_start();
    let whole_part = rest.is_empty() || rest.starts_with("stage") || rest.starts_with("robot");
    let base = part_start(src, pos, !whole_part);
    let w = Window::new(src, base, pos, at);
    let (stack, suspects) = w.open_brackets();
    let chosen = w.choose(&stack, &suspects)?;
    Some(w.error(chosen, at, found))
}

/// The source read around a syntax error: its tokens, and where its lines
/// start.
struct Window<'s> {
    src: &'s str,
    tokens: Vec<Token>,
    /// The index of the first token after the error's position.
    end: usize,
    /// The start of each line, from the line of the window's first byte.
    line_starts: Vec<usize>,
}

impl<'s> Window<'s> {
    /// The window from `base` to the two tokens after `pos` (and `at`).
    fn new(src: &'s str, base: usize, pos: usize, at: Span) -> Window<'s> {
        let (tokens, end) = window_tokens(src, base, pos);
        let window_end = tokens.last().map_or(pos, |t| t.span.end).max(at.end).min(src.len());
        let line_starts: Vec<usize> = std::iter::once(base)
            .chain(src[base..window_end].match_indices('\n').map(|(i, _)| base + i + 1))
            .collect();
        Window { src, tokens, end, line_starts }
    }

    /// The line of byte `at`, counted from 1 at the window's first line;
    /// see `absolute` for messages.
    fn line_of(&self, at: usize) -> usize {
        self.line_starts.partition_point(|&s| s <= at)
    }

    /// The line of the file (from 1) of the window's line `line`.
    fn absolute(&self, line: usize) -> usize {
        self.src.as_bytes()[..self.line_starts[0]].iter().filter(|&&b| b == b'\n').count() + line
    }

    /// The indentation of the line of byte `at`.
    fn indent_of(&self, at: usize) -> usize {
        let line = &self.src[self.line_starts[self.line_of(at) - 1]..];
        line.len() - line.trim_start_matches([' ', '\t']).len()
    }

    /// Whether token `i` is the first of its line.
    fn first_on_line(&self, i: usize) -> bool {
        let t = &self.tokens;
        i == 0 || self.line_of(t[i - 1].span.start) < self.line_of(t[i].span.start)
    }

    /// The bracket or other punctuation that token `t` is, if any.
    fn punct(&self, t: &Token) -> Option<u8> {
        (t.kind == TokenKind::Punct).then(|| self.src.as_bytes()[t.span.start])
    }

    /// The brackets still open before the error's position (the innermost
    /// last), and the suspects: brackets most likely closed by a bracket
    /// of an outer one.
    fn open_brackets(&self) -> (Vec<Open>, Vec<Suspect>) {
        let tokens = &self.tokens;
        let mut stack: Vec<Open> = Vec::new();
        let mut suspects: Vec<Suspect> = Vec::new();
        for (i, t) in tokens[..self.end].iter().enumerate() {
            match self.punct(t) {
                Some(b @ (b'(' | b'[' | b'{')) => stack.push(Open { tok: i, bracket: b }),
                Some(c @ (b')' | b']' | b'}')) => {
                    let Some(k) = stack.iter().rposition(|o| closing(o.bracket) == c) else { continue };
                    let opened = stack[k].tok;
                    if c == b'}'
                        && self.first_on_line(i)
                        && self.indent_of(t.span.start) < self.indent_of(tokens[opened].span.start)
                    {
                        let outer = k.checked_sub(1).map(|o| stack[o].tok);
                        suspects.push(Suspect { open: opened, closed_by: i, outer });
                    }
                    let skipped = stack.drain(k..).skip(1);
                    suspects.extend(skipped.map(|o| Suspect { open: o.tok, closed_by: i, outer: None }));
                }
                _ => {}
            }
        }
        (stack, suspects)
    }

    /// The bracket to name, from what the parse failed at: the innermost
    /// open bracket, or a suspect inside it; `None` when the failure does
    /// not look like a bracket left open.
    fn choose(&self, stack: &[Open], suspects: &[Suspect]) -> Option<Suspect> {
        let (src, tokens, end) = (self.src, &self.tokens, self.end);
        let top = stack.last()?;
        let at_top = Suspect { open: top.tok, closed_by: end, outer: None };
        // A suspect inside the innermost open bracket, else that bracket.
        let candidate = suspects.iter().rev().find(|s| s.open > top.tok).copied().unwrap_or(at_top);
        let Some(n) = tokens.get(end) else { return Some(candidate) };
        Some(match self.punct(n) {
            // A closing bracket of an outer one (not a stray one).
            Some(c @ (b')' | b']' | b'}'))
                if c != closing(top.bracket) && stack.iter().any(|o| closing(o.bracket) == c) =>
            {
                at_top
            }
            // A block or a decoding table's arrow: never inside brackets.
            Some(b'{') if top.bracket != b'{' => at_top,
            Some(b'-') if top.bracket != b'{' && src[n.span.start..].starts_with("->") => at_top,
            _ => {
                let w = word(src, Some(n))?;
                let round = top.bracket != b'{';
                if round && CLAUSE_WORDS.contains(&w) {
                    at_top
                } else if starts_part(src, tokens, end)
                    || (!round && starts_item(src, tokens, end) && !opens_stage(src, tokens, top.tok))
                {
                    candidate
                } else {
                    return None;
                }
            }
        })
    }

    /// The error of the bracket `chosen` left open, the parse having
    /// failed at `at` on `found`: where the closing bracket is missing
    /// (there an editor shows it), labelling the bracket too.
    fn error(&self, chosen: Suspect, at: Span, found: &str) -> Error {
        let (src, tokens, end) = (self.src, &self.tokens, self.end);
        let open = tokens[chosen.open].span;
        let bracket = src.as_bytes()[open.start] as char;
        let close = closing(bracket as u8) as char;
        let block = (bracket == '{').then(|| block_name(src, tokens, chosen.open)).flatten();

        let message = match &block {
            Some(block) => format!("{block} is not closed"),
            None => format!("this `{bracket}` is not closed"),
        };
        let label =
            if block.is_some() { format!("its `{bracket}` opens here") } else { "opened here".into() };
        let before = match found {
            "end of file" => "the end of the file".to_string(),
            "`-`" if src[at.start..].starts_with("->") => "`->`".to_string(),
            _ => found.to_string(),
        };
        // Where the parse failed, or the bracket that closed this one instead
        // of an outer one.
        let other = match (tokens.get(chosen.closed_by).filter(|_| chosen.closed_by != end), chosen.outer) {
            (Some(c), Some(outer)) => {
                let outer = block_name(src, tokens, outer).unwrap_or_else(|| "the block around it".into());
                let this = block.as_deref().unwrap_or("it");
                (c.span, format!("this `}}` closes {this}, so {outer} is not closed"))
            }
            (Some(c), None) => {
                (c.span, format!("expected `{close}` before this `{}`", &src[c.span.start..c.span.end]))
            }
            (None, _) if found == "end of file" => (at, "the file ends here".into()),
            (None, _) => (at, format!("expected `{close}` before {before}")),
        };
        // The closing bracket goes after the last token before the one that
        // closed it instead, or before the token the parse failed at.
        let last = chosen.closed_by.checked_sub(1).filter(|&b| b > chosen.open).map(|b| tokens[b]);
        let same_line = last.is_some_and(|l| self.line_of(l.span.start) == self.line_of(other.0.start));
        let help = match (last, &block) {
            (Some(l), Some(block)) if !same_line => {
                format!(
                    "add `}}` at the end of line {}, where {block} ends",
                    self.absolute(self.line_of(l.span.start))
                )
            }
            (Some(l), None) if !same_line => format!(
                "add `{close}` at the end of line {}, or where the bracketed part ends",
                self.absolute(self.line_of(l.span.start))
            ),
            _ if other.0 == at => format!("add `{close}` before {before}"),
            _ => format!("add `{close}` before the `{}`", &src[other.0.start..other.0.end]),
        };
        Error::Syntax {
            span: other.0.into(),
            message,
            label: other.1,
            others: vec![LabeledSpan::new_with_span(Some(label), miette::SourceSpan::from(open))],
            help: Some(help),
        }
    }
}

/// The start of the line of the last `stage` or `robot` (not `robot adds`)
/// that starts a line before `pos`: where the top-level part around `pos`
/// begins, or 0. With `items`, a line starting with a word that starts a
/// stage item (`module`, `link`, ...) is a start too.
fn part_start(src: &str, pos: usize, items: bool) -> usize {
    let word = |t: &str, w: &str| {
        t.strip_prefix(w).is_some_and(|r| !r.starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_'))
    };
    const ITEMS: [&str; 9] =
        ["module", "link", "links", "fitness", "evolve", "world", "test", "train", "genome"];
    let starts_part = |t: &str| {
        word(t, "stage")
            || (word(t, "robot") && !word(t["robot".len()..].trim_start(), "adds"))
            || (items && ITEMS.iter().any(|w| word(t, w)))
    };
    let mut line_end = pos;
    loop {
        let start = src[..line_end].rfind('\n').map_or(0, |i| i + 1);
        let line = &src[start..];
        let text = line.trim_start_matches([' ', '\t']);
        if start + (line.len() - text.len()) < pos && starts_part(text) {
            return start;
        }
        if start == 0 {
            return 0;
        }
        line_end = start - 1;
    }
}

/// The tokens of `src[base..pos]` and the two tokens after `pos` (lexed
/// from a window that grows until it holds them whole), with the index of
/// the first token after `pos`.
fn window_tokens(src: &str, base: usize, pos: usize) -> (Vec<Token>, usize) {
    let shift =
        |t: Token, by: usize| Token { span: Span::new(t.span.start + by, t.span.end + by), kind: t.kind };
    let mut tokens: Vec<Token> = lex(&src[base..pos]).tokens.into_iter().map(|t| shift(t, base)).collect();
    let end = tokens.len();
    let mut len = 64;
    loop {
        let mut stop = (pos + len).min(src.len());
        while !src.is_char_boundary(stop) {
            stop += 1;
        }
        let next = lex(&src[pos..stop]).tokens;
        // A third token shows that the second one is whole.
        if stop == src.len() || next.len() >= 3 {
            tokens.extend(next.into_iter().take(2).map(|t| shift(t, pos)));
            return (tokens, end);
        }
        len *= 4;
    }
}

/// A bracket that may be the one left open: the token that opens it, the
/// token that closed it instead of an outer one (or where the parse
/// failed), and, for a `}` less indented than its `{`, the outer `{` it
/// most likely belongs to.
#[derive(Clone, Copy)]
struct Suspect {
    open: usize,
    closed_by: usize,
    outer: Option<usize>,
}

/// The reserved words that start a declaration, an item or a clause (not
/// the operators `and`, `or`, `not`, `prev`, nor the words inside a clause):
/// none may stand inside brackets, so one where a `(` or `[` is open
/// follows the place where it should have been closed.
pub(super) const CLAUSE_WORDS: [&str; 17] = [
    "robot",
    "sensor",
    "actuator",
    "genome",
    "stage",
    "module",
    "sense",
    "activation",
    "behavior",
    "learn",
    "reinforce",
    "links",
    "link",
    "world",
    "evolve",
    "test",
    "fitness",
];

/// Whether token `i` starts a top-level part: `stage`, or `robot` (not `robot adds`).
fn starts_part(src: &str, tokens: &[Token], i: usize) -> bool {
    match word(src, tokens.get(i)) {
        Some("stage") => true,
        Some("robot") => word(src, tokens.get(i + 1)) != Some("adds"),
        _ => false,
    }
}

/// Whether the `{` at token `i` opens a stage: `stage NAME {` or `stage
/// NAME extends PARENT {`.
fn opens_stage(src: &str, tokens: &[Token], i: usize) -> bool {
    let w = |k: usize| i.checked_sub(k).and_then(|k| word(src, tokens.get(k)));
    w(2) == Some("stage") || (w(4) == Some("stage") && w(2) == Some("extends"))
}

/// What the `{` at token `i` opens: `stage `s``, `module `m``, `robot
/// `r``, or `the `world` block` (`world changes`, `script`, `neural`, ...).
fn block_name(src: &str, tokens: &[Token], i: usize) -> Option<String> {
    let w = |k: usize| i.checked_sub(k).and_then(|k| word(src, tokens.get(k)));
    if opens_stage(src, tokens, i) {
        let name = if w(2) == Some("stage") { w(1) } else { w(3) };
        return name.map(|n| format!("stage `{n}`"));
    }
    if w(4) == Some("role") && w(2) == Some("robots") {
        return w(3).map(|n| format!("role `{n}`"));
    }
    match (w(2), w(1)?) {
        (Some(kw @ ("robot" | "world")), m @ ("adds" | "changes")) => Some(format!("the `{kw} {m}` block")),
        (Some(kw @ ("module" | "robot")), name) => Some(format!("{kw} `{name}`")),
        (Some("script"), "commit") => Some("the `script commit` block".into()),
        (_, kw @ ("world" | "evolve" | "body" | "genome" | "neural" | "script")) => {
            Some(format!("the `{kw}` block"))
        }
        _ => None,
    }
}

/// What the innermost `{` open at `pos` opens (see [`block_name`]).
pub(super) fn innermost_block(src: &str, pos: usize) -> Option<String> {
    let tokens = lex(src).tokens;
    let end = tokens.partition_point(|t| t.span.start < pos);
    let mut stack = Vec::new();
    for (i, t) in tokens[..end].iter().enumerate() {
        match (t.kind == TokenKind::Punct).then(|| src.as_bytes()[t.span.start]) {
            Some(b'{') => stack.push(i),
            Some(b'}') => {
                stack.pop();
            }
            _ => {}
        }
    }
    block_name(src, &tokens, *stack.last()?)
}
