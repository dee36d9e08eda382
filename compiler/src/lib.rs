//! `shaping-compiler`: parses, checks and lowers `.bat` architecture files to a
//! runtime [`Program`]. Text in, `Program` or diagnostics out: no file I/O.
//!
//! ```text
//! text --syntax--> AST (spans) --lower (checks, collects every error)--> Program
//! ```
//!
//! - [`syntax`]: the pest grammar (`grammar/shaping.pest`), AST and spans;
//! - [`lower`]: resolves names, checks everything, derives genome layouts;
//! - [`layout`]: readable renderings of a compiled stage (layout table, DOT graph);
//! - [`fmt`]: the formatter (`shaping fmt`, the language server's formatting);
//! - [`diag`]: the error enum (each variant a stable code, `S0001`...) and the
//!   [`Diagnostics`] collection; [`explain`]: each code's long explanation;
//! - [`ide`]: what an editor asks (completion, hover words, rename, quick
//!   fixes), as plain data for the language server.

pub mod diag;
pub mod explain;
pub mod fmt;
pub mod ide;
pub mod layout;
pub mod lower;
pub mod span;
pub mod syntax;

pub use diag::{Diagnostics, Error};
pub use layout::{layout_rows, module_label, render_graph, render_layout, role_text, LayoutRow};
pub use lower::measure;
pub use shaping_runtime::program::Program;

/// Compiles the source of one architecture file. `file_name` names the
/// source in diagnostics and gives the program its default name (its stem).
/// Warnings are dropped: [`check`] returns them.
pub fn compile(source: &str, file_name: &str) -> Result<Program, Diagnostics> {
    match check(source, file_name) {
        (Some(program), _) => Ok(program),
        (None, diagnostics) => Err(diagnostics),
    }
}

/// Compiles like [`compile`], and returns every diagnostic, warnings
/// included: the program when no diagnostic is an error.
pub fn check(source: &str, file_name: &str) -> (Option<Program>, Diagnostics) {
    let (file, units) = match syntax::parse_for_check(source) {
        Ok(f) => f,
        Err(errors) => return (None, Diagnostics::new(file_name, source, errors)),
    };
    let (mut program, mut diagnostics) = lower::lower(&file, file_name);
    if !units.is_empty() {
        // Every unknown unit, and every other mistake: what the checks say
        // of a quantity with an unknown unit (read as a bare number), or of
        // a part of the file that holds one (`arena 1.2m x 1.2m`: an arena
        // too small for the body), is a consequence of the unit, not reported.
        program = None;
        diagnostics.retain(|e| {
            let Some((at, len)) = first_label(e) else { return true };
            !units.iter().any(|(q, _)| {
                let inside = q.start <= at && at < q.end.max(q.start + 1);
                let around = at <= q.start && q.end <= at + len;
                inside || around
            })
        });
        diagnostics.extend(units.into_iter().map(|(_, e)| e));
        diagnostics.sort_by_key(|e| first_label(e).map(|(at, _)| at));
    }
    (program, Diagnostics::new(file_name, source, diagnostics))
}

/// Where the first label of a diagnostic is: its offset and length.
fn first_label(e: &Error) -> Option<(usize, usize)> {
    use miette::Diagnostic;
    e.labels().and_then(|mut l| l.next()).map(|l| (l.offset(), l.len()))
}
