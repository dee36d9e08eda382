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
