//! The lexical scan of a source: comments, and the positions of the tokens
//! between them. The formatter finds with it where an item really ends,
//! its separators and the spelling of its numbers; the recovery of syntax
//! errors and the bracket finder split a file with it; the language server
//! reads the tokens before the cursor.

use crate::syntax::Span;

/// A comment as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Comment {
    pub span: Span,
    /// `//` comments end at the end of their line.
    pub line: bool,
}

/// A token: a word, an unsigned number or one punctuation character.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Token {
    pub span: Span,
    pub kind: TokenKind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TokenKind {
    Word,
    Number,
    Punct,
}

/// Comments and tokens of a source, in order.
pub struct Lexed {
    pub comments: Vec<Comment>,
    pub tokens: Vec<Token>,
}

fn is_word_char(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// Splits a source into comments and tokens, as the grammar reads them: a
/// comment starts at any `//` or `/*` between tokens.
pub fn lex(src: &str) -> Lexed {
    let b = src.as_bytes();
    let mut comments = Vec::new();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b'/' && b.get(i + 1) == Some(&b'/') {
            let start = i;
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            comments.push(Comment { span: Span::new(start, i), line: true });
        } else if c == b'/' && b.get(i + 1) == Some(&b'*') {
            let start = i;
            i += 2;
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                i += 1;
            }
            i = (i + 2).min(b.len());
            comments.push(Comment { span: Span::new(start, i), line: false });
        } else if c.is_ascii_digit() {
            let start = i;
            i = number_end(b, i);
            tokens.push(Token { span: Span::new(start, i), kind: TokenKind::Number });
        } else if is_word_char(c) {
            let start = i;
            while i < b.len() && is_word_char(b[i]) {
                i += 1;
            }
            tokens.push(Token { span: Span::new(start, i), kind: TokenKind::Word });
        } else {
            let len = src[i..].chars().next().map_or(1, char::len_utf8);
            tokens.push(Token { span: Span::new(i, i + len), kind: TokenKind::Punct });
            i += len;
        }
    }
    Lexed { comments, tokens }
}

/// The end of the unsigned number starting at `i` (the grammar's `unsigned`).
fn number_end(b: &[u8], mut i: usize) -> usize {
    let digits = |b: &[u8], mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    i = digits(b, i);
    if b.get(i) == Some(&b'.') && b.get(i + 1).is_some_and(u8::is_ascii_digit) {
        i = digits(b, i + 1);
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        if matches!(b.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        if b.get(j).is_some_and(u8::is_ascii_digit) {
            i = digits(b, j);
        }
    }
    i
}

impl Lexed {
    /// The index of the first token starting at or after `pos`.
    fn first_from(&self, pos: usize) -> usize {
        self.tokens.partition_point(|t| t.span.start < pos)
    }

    /// The end of the last token that starts before `end`: where an item
    /// whose span may include trailing comments really ends.
    pub fn token_end(&self, span: Span) -> usize {
        let i = self.first_from(span.end);
        match i.checked_sub(1).map(|i| self.tokens[i]) {
            Some(t) if t.span.start >= span.start => t.span.end,
            _ => span.start,
        }
    }

    /// The tokens within a span.
    pub fn tokens_in(&self, span: Span) -> &[Token] {
        let a = self.first_from(span.start);
        let b = self.first_from(span.end).max(a);
        &self.tokens[a..b]
    }

    /// The token just before `pos`.
    pub fn token_before(&self, pos: usize) -> Option<Token> {
        self.first_from(pos).checked_sub(1).map(|i| self.tokens[i])
    }

    /// The first token at or after `pos`.
    pub fn token_at(&self, pos: usize) -> Option<Token> {
        self.tokens.get(self.first_from(pos)).copied()
    }

    /// The comments within `start..end`.
    pub fn comments_in(&self, start: usize, end: usize) -> &[Comment] {
        let a = self.comments.partition_point(|c| c.span.start < start);
        let b = self.comments.partition_point(|c| c.span.start < end).max(a);
        &self.comments[a..b]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_and_tokens() {
        let src = "a 1.5e-3..2 // x\n/* y */ b,c";
        let l = lex(src);
        let texts: Vec<&str> = l.tokens.iter().map(|t| &src[t.span.start..t.span.end]).collect();
        assert_eq!(texts, ["a", "1.5e-3", ".", ".", "2", "b", ",", "c"]);
        let comments: Vec<&str> = l.comments.iter().map(|c| &src[c.span.start..c.span.end]).collect();
        assert_eq!(comments, ["// x", "/* y */"]);
        assert_eq!(l.token_end(Span::new(0, 16)), 11);
    }
}
