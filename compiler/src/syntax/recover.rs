//! Syntax error recovery: a layer around the parser, not a second grammar.
//!
//! When a file does not parse, a lexical scan (comments skipped, braces
//! counted) splits it into top-level parts, each starting at `stage`, at
//! `robot` (not `robot adds`) or at a top-level `genome`, and a stage into
//! its items, each starting at a word that only starts a stage item
//! (`module`, `link`, `links all`, `fitness`, `evolve`, `world`, `test`,
//! `train for`, `genome`, `robot adds`). Each part, and each item of a stage
//! that does not parse, is parsed alone: what fails gives its syntax error
//! at its place and is blanked (spaces, newlines kept) in a copy of the
//! source. The copy then parses whole, so the AST of everything that parses
//! keeps the positions of the original source.

use pest::error::InputLocation;
use pest::Parser as _;

use super::parser::{syntax_error, syntax_error_shifted, BatParser, Rule};
use crate::diag::Error;
use crate::syntax::lex::{lex, Token, TokenKind};

/// What the wrapper of a lone stage item adds before it.
const ITEM_HEAD: &str = "stage _ {";
/// Most whole parts blanked after the first pass before giving up.
const MAX_RETRIES: usize = 8;

/// The source with every part that does not parse blanked, and the syntax
/// error of each such part, in source order. `None` when even the blanked
/// source does not parse (then the errors are what could be found).
pub(super) fn recover(src: &str) -> (Option<String>, Vec<Error>) {
    let lexed = lex(src);
    let tokens = lexed.tokens;
    // Bytes inside a comment (with the line break ending a `//` one), where
    // no missing `}` may be put.
    let mut commented = vec![false; src.len()];
    for c in &lexed.comments {
        let end = if c.line { c.span.end + 1 } else { c.span.end };
        commented[c.span.start..end.min(src.len())].fill(true);
    }
    let parts = top_level_parts(src, &tokens);
    let mut masked = src.as_bytes().to_vec();
    let mut errors: Vec<(usize, Error)> = Vec::new();
    // Parts whose whole text was blanked, and whether they reported an error.
    let mut reported = vec![false; parts.len()];
    for (k, &(a, b)) in parts.iter().enumerate() {
        let Err(e) = BatParser::parse(Rule::file, &src[a..b]) else { continue };
        let whole = located(src, e, a, b);
        let is_stage = word(src, tokens.get(first_token(&tokens, a))) == Some("stage");
        let found = if is_stage && !matches!(whole, Error::TooComplex { .. }) {
            stage_items(src, &tokens, &commented, (a, b), &mut masked)
        } else {
            None
        };
        match found {
            Some(mut item_errors) => {
                if item_errors.is_empty() {
                    item_errors.push(whole);
                }
                errors.extend(item_errors.into_iter().map(|e| (a, e)));
            }
            None => {
                blank(&mut masked, a, b);
                errors.push((a, whole));
            }
        }
        reported[k] = true;
    }
    // The blanked copy should parse; if a part still fails there, blank it whole.
    let mut text = String::from_utf8(masked).unwrap_or_default();
    for _ in 0..MAX_RETRIES {
        let pos = match BatParser::parse(Rule::file, &text) {
            Ok(_) => {
                errors.sort_by_key(|e| e.0);
                return (Some(text), errors.into_iter().map(|e| e.1).collect());
            }
            // Over pest's call budget: what parses is too large to check again.
            Err(e) if matches!(e.variant, pest::error::ErrorVariant::CustomError { .. }) => {
                errors.push((0, syntax_error(src, e)));
                break;
            }
            Err(e) => position(&e),
        };
        let Some(k) = parts.iter().position(|&(a, b)| a <= pos && (pos < b || b == src.len())) else { break };
        let (a, b) = parts[k];
        if text[a..b].trim().is_empty() {
            break;
        }
        if !reported[k] {
            if let Err(e) = BatParser::parse(Rule::file, &src[a..b]) {
                errors.push((a, located(src, e, a, b)));
            }
            reported[k] = true;
        }
        let mut bytes = text.into_bytes();
        blank(&mut bytes, a, b);
        text = String::from_utf8(bytes).unwrap_or_default();
    }
    errors.sort_by_key(|e| e.0);
    (None, errors.into_iter().map(|e| e.1).collect())
}

/// The text of a word token.
pub(super) fn word<'s>(src: &'s str, t: Option<&Token>) -> Option<&'s str> {
    t.filter(|t| t.kind == TokenKind::Word).map(|t| &src[t.span.start..t.span.end])
}

/// The punctuation character of a token.
fn punct(src: &str, t: &Token) -> Option<u8> {
    (t.kind == TokenKind::Punct).then(|| src.as_bytes()[t.span.start])
}

/// The index of the first token starting at or after `pos`.
fn first_token(tokens: &[Token], pos: usize) -> usize {
    tokens.partition_point(|t| t.span.start < pos)
}

/// The top-level parts: from each `stage`, `robot` (not `robot adds`) or
/// top-level `genome` to the next, and what comes before the first one.
fn top_level_parts(src: &str, tokens: &[Token]) -> Vec<(usize, usize)> {
    let mut starts = Vec::new();
    let mut depth = 0i64;
    for (i, t) in tokens.iter().enumerate() {
        let top = match word(src, Some(t)) {
            Some("stage") => true,
            Some("robot") => word(src, tokens.get(i + 1)) != Some("adds"),
            Some("genome") => depth <= 0,
            _ => false,
        };
        if top {
            starts.push(t.span.start);
            depth = 0;
        }
        match punct(src, t) {
            Some(b'{') => depth += 1,
            Some(b'}') => depth -= 1,
            _ => {}
        }
    }
    let mut parts = Vec::new();
    let first = starts.first().copied().unwrap_or(src.len());
    if tokens.first().is_some_and(|t| t.span.start < first) {
        parts.push((0, first));
    }
    for (k, &a) in starts.iter().enumerate() {
        parts.push((a, starts.get(k + 1).copied().unwrap_or(src.len())));
    }
    parts
}

/// Whether token `i` starts a stage item (a reserved word written where a
/// name is expected, as in `module link {`, does not).
pub(super) fn starts_item(src: &str, tokens: &[Token], i: usize) -> bool {
    let prev = i.checked_sub(1).and_then(|p| tokens.get(p));
    if matches!(word(src, prev), Some("module" | "link" | "extends" | "trained"))
        || prev.and_then(|t| punct(src, t)) == Some(b'>')
    {
        return false;
    }
    let next = word(src, tokens.get(i + 1));
    match word(src, tokens.get(i)) {
        Some("module" | "link" | "fitness" | "evolve" | "world" | "test" | "genome") => true,
        Some("links") => next == Some("all"),
        Some("robot") => next == Some("adds"),
        Some("train") => next == Some("for"),
        // `role NAME robots N {`: a role (its modules are its own items).
        Some("role") => next.is_some_and(|n| !super::RESERVED.contains(&n)),
        _ => false,
    }
}

/// The words that start a stage item.
const ITEM_WORDS: [&str; 10] =
    ["module", "link", "links", "fitness", "evolve", "world", "test", "train", "genome", "robot"];

/// Whether token `i` looks like a misspelt word starting a stage item
/// (`fitnes per action ...`): a word close to one of [`ITEM_WORDS`], first on
/// its line, after a token that ends something (no operator or comma, which
/// the line would continue). Splitting there lets each misspelling be
/// reported, each with its own did-you-mean.
fn misspelt_item(src: &str, tokens: &[Token], i: usize) -> bool {
    let Some(w) = word(src, tokens.get(i)) else { return false };
    let Some(prev) = i.checked_sub(1).map(|p| tokens[p]) else { return false };
    let line_break = src[prev.span.end..tokens[i].span.start].contains('\n');
    let ends = match punct(src, &prev) {
        Some(c) => matches!(c, b'}' | b')' | b']'),
        None => {
            !matches!(word(src, Some(&prev)), Some("and" | "or" | "not" | "prev" | "per" | "if" | "until"))
        }
    };
    line_break && ends && !ITEM_WORDS.contains(&w) && crate::diag::did_you_mean(w, ITEM_WORDS).is_some()
}

/// Recovers the items of the stage in `a..b`: blanks those that do not
/// parse (and what follows the stage's closing brace) and returns their
/// errors. `None` when the stage's head (`stage NAME [extends P] {`) is not
/// readable or its closing brace cannot be placed: then the caller blanks
/// the whole part.
fn stage_items(
    src: &str,
    tokens: &[Token],
    commented: &[bool],
    (a, b): (usize, usize),
    masked: &mut [u8],
) -> Option<Vec<Error>> {
    let toks = &tokens[first_token(tokens, a)..first_token(tokens, b)];
    let is_name = |t: Option<&Token>| word(src, t).is_some_and(|w| !super::RESERVED.contains(&w));
    let mut i = 2;
    if !is_name(toks.get(1)) {
        return None;
    }
    if word(src, toks.get(2)) == Some("extends") {
        if !is_name(toks.get(3)) {
            return None;
        }
        i = 4;
    }
    if toks.get(i).and_then(|t| punct(src, t)) != Some(b'{') {
        return None;
    }
    let body = toks[i].span.end;
    let (items, close) = split_items(src, toks, i, b);
    let mut errors = Vec::new();
    let mut last_kept = body;
    for &(s, e) in &items {
        let text = &src[s..e];
        if text.trim().is_empty() {
            continue;
        }
        let wrapped = format!("{ITEM_HEAD}{text}\n}}");
        match BatParser::parse(Rule::file, &wrapped) {
            // After the item's last token: its trailing blanks may take a missing `}`.
            Ok(_) => last_kept = tokens[first_token(tokens, e) - 1].span.end,
            Err(err) => {
                // A role: its modules and links that parse are kept.
                let is_role = word(src, tokens.get(first_token(tokens, s))) == Some("role");
                match is_role.then(|| role_items(src, tokens, (s, e), masked)).flatten() {
                    Some(inner) => {
                        errors.extend(inner);
                        last_kept = tokens[first_token(tokens, e) - 1].span.end;
                    }
                    None => {
                        let pos = position(&err).saturating_sub(ITEM_HEAD.len()).min(text.len());
                        errors.push(at(src, err, s + pos));
                        blank(masked, s, e);
                    }
                }
            }
        }
    }
    match close {
        Some(c) => {
            // What follows the closing brace, up to the next part, is not a stage item.
            let after = c + 1;
            if !src[after..b].trim().is_empty() {
                if let Err(err) = BatParser::parse(Rule::file, &src[after..b]) {
                    errors.push(located(src, err, after, b));
                }
                blank(masked, after, b);
            }
        }
        None => {
            // Put the missing `}` on a blank after the last item kept, outside comments.
            let blank_byte = |k: usize| {
                masked[k].is_ascii_whitespace() && (masked[k] != src.as_bytes()[k] || !commented[k])
            };
            let spot = (last_kept..b).rev().find(|&k| blank_byte(k))?;
            masked[spot] = b'}';
        }
    }
    Some(errors)
}

/// The items of a stage whose `{` is `toks[i]`, as byte ranges split at
/// item words, and the stage's closing brace: a `}` at an item's own depth
/// 0; without one the last item ends at `b`.
fn split_items(src: &str, toks: &[Token], i: usize, b: usize) -> (Vec<(usize, usize)>, Option<usize>) {
    let mut items: Vec<(usize, usize)> = Vec::new();
    let mut start = toks[i].span.end;
    let mut depth = 0i64;
    let mut close = None;
    // Inside a role's braces, its modules and links belong to the role's item.
    let mut in_role = false;
    for (j, t) in toks.iter().enumerate().skip(i + 1) {
        let inner = in_role && depth > 0;
        let starts = !inner && (starts_item(src, toks, j) || (depth == 0 && misspelt_item(src, toks, j)));
        if starts {
            in_role = word(src, Some(t)) == Some("role");
        }
        if starts && t.span.start > start {
            items.push((start, t.span.start));
            start = t.span.start;
            depth = 0;
        } else if starts {
            depth = 0;
        }
        match punct(src, t) {
            Some(b'{') => depth += 1,
            Some(b'}') if depth == 0 => {
                close = Some(t.span.start);
                break;
            }
            Some(b'}') => depth -= 1,
            _ => {}
        }
    }
    let end = close.unwrap_or(b);
    if src[start..end].trim() != "" || items.is_empty() {
        items.push((start, end));
    }
    (items, close)
}

/// What the wrapper of a lone item of a role adds before it.
const ROLE_ITEM_HEAD: &str = "stage _ { role _ robots 1 {";

/// Recovers the items of the role in `s..e` (`role NAME robots N { ... }`),
/// which does not parse: blanks its modules and links that do not parse and
/// returns their errors, when the role then parses (else `None`, and the
/// caller blanks the role whole).
fn role_items(src: &str, tokens: &[Token], (s, e): (usize, usize), masked: &mut [u8]) -> Option<Vec<Error>> {
    let toks = &tokens[first_token(tokens, s)..first_token(tokens, e)];
    // `role NAME robots N {` or `role NAME adds {`
    let open = match (word(src, toks.get(2)), toks.get(3).and_then(|t| punct(src, t))) {
        (Some("adds"), Some(b'{')) => 3,
        _ if toks.get(4).and_then(|t| punct(src, t)) == Some(b'{') => 4,
        _ => return None,
    };
    let body = toks[open].span.end;
    let mut pieces: Vec<(usize, usize)> = Vec::new();
    let mut start = body;
    let mut depth = 0i64;
    let mut close = None;
    for (j, t) in toks.iter().enumerate().skip(open + 1) {
        if starts_item(src, toks, j) {
            if t.span.start > start {
                pieces.push((start, t.span.start));
            }
            start = t.span.start;
            depth = 0;
        }
        match punct(src, t) {
            Some(b'{') => depth += 1,
            Some(b'}') if depth == 0 => {
                close = Some(t.span.start);
                break;
            }
            Some(b'}') => depth -= 1,
            _ => {}
        }
    }
    let close = close?;
    pieces.push((start, close));
    let mut errors = Vec::new();
    for (a, b) in pieces {
        let text = &src[a..b];
        if text.trim().is_empty() {
            continue;
        }
        if let Err(err) = BatParser::parse(Rule::file, &format!("{ROLE_ITEM_HEAD}{text}\n}} }}")) {
            let pos = position(&err).saturating_sub(ROLE_ITEM_HEAD.len()).min(text.len());
            errors.push(at(src, err, a + pos));
            blank(masked, a, b);
        }
    }
    let role = String::from_utf8_lossy(&masked[s..e]).into_owned();
    let parses = BatParser::parse(Rule::file, &format!("{ITEM_HEAD}{role}\n}}")).is_ok();
    (parses && !errors.is_empty()).then_some(errors)
}

/// The byte position of a pest error.
fn position(e: &pest::error::Error<Rule>) -> usize {
    match e.location {
        InputLocation::Pos(p) => p,
        InputLocation::Span((p, _)) => p,
    }
}

/// The error of a part `a..b` parsed alone, placed in the whole source.
fn located(src: &str, e: pest::error::Error<Rule>, a: usize, b: usize) -> Error {
    let pos = (a + position(&e)).min(b);
    at(src, e, pos)
}

/// A pest error placed at `pos` of the whole source.
fn at(src: &str, e: pest::error::Error<Rule>, pos: usize) -> Error {
    let shift = pos as isize - position(&e) as isize;
    syntax_error_shifted(src, e, shift)
}

/// Replaces `a..b` by spaces, keeping line breaks (so every position keeps
/// its line and column).
fn blank(bytes: &mut [u8], a: usize, b: usize) {
    for c in &mut bytes[a..b] {
        if *c != b'\n' {
            *c = b' ';
        }
    }
}
