//! Integration tests of the compiler: data-driven snapshots and properties.
//! Test data lives at the repository root: `examples/`, `tests/parse/`,
//! `tests/ui/`, `tests/lower/`.

mod bodies;
mod codes;
mod docs;
mod examples;
mod fixes;
mod fmt;
mod ide;
mod layout;
mod limits;
mod parse;
mod props;
mod recover;
mod roles;
mod teams;
mod ui;
mod words;

use std::path::Path;

/// The repository root.
pub fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// Renders diagnostics as the CLI does, without colour, 80 columns.
pub fn render(d: &dyn miette::Diagnostic) -> String {
    let mut s = String::new();
    miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
        .with_width(80)
        .render_report(&mut s, d)
        .expect("rendering to a string cannot fail");
    s
}

/// Compiles a file of the repository, panicking with the rendered diagnostics
/// (warnings included: the files of the repository have none).
pub fn compile_ok(src: &str, name: &str) -> shaping_compiler::Program {
    match shaping_compiler::check(src, name) {
        (Some(p), d) => {
            if !d.is_empty() {
                panic!("{name} compiles with warnings:\n{}", render(&d));
            }
            // What the compiler emits is always a program the runtime accepts.
            if let Err(e) = p.validate() {
                panic!("{name} compiles to an invalid program: {e}");
            }
            p
        }
        (None, e) => panic!("{name} does not compile:\n{}", render(&e)),
    }
}
