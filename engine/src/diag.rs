//! Rendering diagnostics as text (`--error-format human|plain|json`).

use std::io::IsTerminal;

use miette::{
    Diagnostic, GraphicalReportHandler, GraphicalTheme, JSONReportHandler, ThemeCharacters, ThemeStyles,
};

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
