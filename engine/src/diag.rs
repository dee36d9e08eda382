//! Diagnostics as data ([`Diagnosed`]: what a front renders, with its
//! lines and columns) and rendered as text (`--error-format
//! human|plain|json`).

use std::io::IsTerminal;

use miette::{
    Diagnostic, GraphicalReportHandler, GraphicalTheme, JSONReportHandler, ThemeCharacters, ThemeStyles,
};
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorFormat {
    /// Coloured (when standard error is a terminal) with source snippets
    /// and labels.
    Human,
    /// The same without colour, ASCII only.
    Plain,
    /// One JSON object per file, on stdout.
    Json,
}

/// Diagnostics rendered in the format a front asked for, and as data.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendered {
    /// As text, in the format asked for (JSON: miette's object).
    pub text: String,
    pub data: Diagnosed,
}

impl Rendered {
    /// `diag` (about `filename`, whose text is `source`) rendered in `format`
    /// and as data.
    pub fn new(diag: &dyn Diagnostic, format: ErrorFormat, filename: &str, source: &str) -> Rendered {
        Rendered { text: render(diag, format), data: Diagnosed::of(diag, filename, source) }
    }
}

/// Renders a diagnostic (with its related diagnostics) as text.
pub fn render(diag: &dyn Diagnostic, format: ErrorFormat) -> String {
    let mut out = String::new();
    let result = match format {
        ErrorFormat::Human => {
            let theme = if std::io::stderr().is_terminal() {
                GraphicalTheme::unicode()
            } else {
                GraphicalTheme::unicode_nocolor()
            };
            GraphicalReportHandler::new_themed(theme).with_width(100).render_report(&mut out, diag)
        }
        ErrorFormat::Plain => GraphicalReportHandler::new_themed(GraphicalTheme {
            characters: ThemeCharacters::ascii(),
            styles: ThemeStyles::none(),
        })
        .with_width(100)
        .render_report(&mut out, diag),
        ErrorFormat::Json => JSONReportHandler::new().render_report(&mut out, diag),
    };
    if result.is_err() {
        // Rendering into a String only fails if a Display impl fails; fall back to the message.
        out = diag.to_string();
    }
    out
}

/// A diagnostic as data: what `check --error-format json` prints, Python's
/// `Diagnostic` and the language server read, with the keys of miette's
/// JSON rendering and each label's line and column. A file's diagnostics
/// are one of these whose `related` are the errors and warnings.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnosed {
    pub message: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub code: Option<String>,
    /// `error`, `warning` or `advice`.
    pub severity: &'static str,
    /// The chain of errors under this one (none for the compiler's).
    pub causes: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub help: Option<String>,
    /// The file the labels point into (empty when none does).
    pub filename: String,
    pub labels: Vec<Label>,
    pub related: Vec<Diagnosed>,
    /// The first label's line and column (1-based, the column in
    /// characters), when it has a label.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub column: Option<usize>,
}

/// A labelled span of a [`Diagnosed`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Label {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    pub span: Span,
    /// Where the span starts (1-based, the column in characters).
    pub line: usize,
    pub column: usize,
}

/// Bytes `offset` to `offset + length` of the source.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Span {
    pub offset: usize,
    pub length: usize,
}

impl Diagnosed {
    /// `diag` as data, its labels' positions in `source` (the text its
    /// spans point into); `filename` when `diag` names no source of its own.
    pub fn of(diag: &dyn Diagnostic, filename: &str, source: &str) -> Diagnosed {
        let severity = match diag.severity() {
            Some(miette::Severity::Error) | None => "error",
            Some(miette::Severity::Warning) => "warning",
            Some(miette::Severity::Advice) => "advice",
        };
        let mut causes = Vec::new();
        let mut cause = std::error::Error::source(diag);
        while let Some(c) = cause {
            causes.push(c.to_string());
            cause = c.source();
        }
        let labels: Vec<Label> = diag
            .labels()
            .into_iter()
            .flatten()
            .map(|l| {
                let (line, column) = line_column(source, l.offset());
                Label {
                    label: l.label().map(str::to_string),
                    span: Span { offset: l.offset(), length: l.len() },
                    line,
                    column,
                }
            })
            .collect();
        let named = diag
            .source_code()
            .zip(labels.first())
            .and_then(|(src, l)| src.read_span(&(l.span.offset, l.span.length).into(), 0, 0).ok())
            .and_then(|c| c.name().map(str::to_string));
        Diagnosed {
            message: diag.to_string(),
            code: diag.code().map(|c| c.to_string()),
            severity,
            causes,
            help: diag.help().map(|h| h.to_string()),
            filename: named
                .unwrap_or_else(|| if labels.is_empty() { String::new() } else { filename.into() }),
            line: labels.first().map(|l| l.line),
            column: labels.first().map(|l| l.column),
            related: diag
                .related()
                .into_iter()
                .flatten()
                .map(|r| Diagnosed::of(r, filename, source))
                .collect(),
            labels,
        }
    }
}

/// Line and column (1-based, the column in characters) of byte `offset` of
/// `source` (an offset past the end or inside a character is taken back to
/// the character's start).
pub fn line_column(source: &str, offset: usize) -> (usize, usize) {
    let at = offset.min(source.len());
    let at = (0..=at).rev().find(|&i| source.is_char_boundary(i)).unwrap_or(0);
    let before = &source[..at];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    #[test]
    fn lines_and_columns_count_characters_from_one() {
        let src = "ab\nçd\n";
        assert_eq!(super::line_column(src, 0), (1, 1));
        assert_eq!(super::line_column(src, 3), (2, 1));
        assert_eq!(super::line_column(src, 5), (2, 2), "ç is two bytes, one character");
        assert_eq!(super::line_column(src, 4), (2, 1), "inside ç: its start");
        assert_eq!(super::line_column(src, 99), (3, 1));
    }
}
