//! `report.html`: one self-contained page for a run, a stage, an experiment
//! or a replay. The page's style and script are files next to this one,
//! included at build time; the data (see [`data`]) are embedded as JSON.
//! Nothing is fetched when the page opens.

pub mod data;
mod stats;

#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::files::{write_atomic, Unsealed};

pub use data::{collect, ReportData};

const TEMPLATE: &str = include_str!("page.html");
const STYLE: &str = include_str!("page.css");
const SCRIPT: &str = include_str!("page.js");

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The data as JSON that is safe inside a `<script>` element: every `<` is
/// escaped, so no `</script>` or `<!--` can end it early.
pub fn embedded_json(data: &ReportData) -> Result<String, Error> {
    let json = serde_json::to_string(data)
        .map_err(|e| Error::internal(format!("error: cannot serialise the report's data: {e}")))?;
    Ok(json.replace('<', "\\u003c"))
}

/// The page for `data`.
pub fn page(data: &ReportData) -> Result<String, Error> {
    let title = escape_html(&format!("{} · shaping report", data.title));
    let json = embedded_json(data)?;
    let stats = data.tests.as_ref().map(stats::section).unwrap_or_default();
    // Each mark is looked for in the rest of the template only, so nothing
    // in the values is taken for a placeholder.
    let mut out =
        String::with_capacity(TEMPLATE.len() + STYLE.len() + SCRIPT.len() + json.len() + stats.len());
    let mut rest = TEMPLATE;
    for (mark, value) in [
        ("{{title}}", title.as_str()),
        ("{{style}}", STYLE),
        ("{{stats}}", &stats),
        ("{{data}}", &json),
        ("{{script}}", SCRIPT),
    ] {
        let Some(at) = rest.find(mark) else {
            return Err(Error::internal(format!("error: the report template has no `{mark}`")));
        };
        out.push_str(&rest[..at]);
        out.push_str(value);
        rest = &rest[at + mark.len()..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Writes the report of `dir` to `out` (default `dir/report.html`) and
/// returns the path written.
pub fn write(dir: &Path, out: Option<&Path>) -> Result<PathBuf, Error> {
    write_with(dir, out, &|_| {})
}

/// [`write`], telling `unsealed` of each file read without a seal
/// ([`data::collect_with`]), for a warning.
pub fn write_with(dir: &Path, out: Option<&Path>, unsealed: Unsealed<'_>) -> Result<PathBuf, Error> {
    if let Some(out) = out {
        replaceable(out)?;
    }
    let data = data::collect_with(dir, unsealed)?;
    let html = page(&data)?;
    let path = out.map_or_else(|| crate::rundir::report_path(dir), Path::to_path_buf);
    write_atomic(&path, html.as_bytes())?;
    Ok(path)
}

/// `report -o FILE`: FILE is new or an earlier report. Anything else there
/// (a run's `program.json`, a checkpoint, a genome, a source file) would be
/// lost: refused.
fn replaceable(out: &Path) -> Result<(), Error> {
    let Ok(meta) = std::fs::metadata(out) else { return Ok(()) };
    if meta.is_dir() {
        return Err(Error::invalid_setting(
            "-o",
            Some(&out.display().to_string()),
            format!(
                "error: `{}` is a directory; give `-o` the file to write (e.g. `{}`)",
                out.display(),
                crate::rundir::report_path(out).display()
            ),
        ));
    }
    let mut head = Vec::new();
    let read = std::fs::File::open(out)
        .and_then(|f| std::io::Read::read_to_end(&mut std::io::Read::take(f, 64 << 10), &mut head));
    let head = String::from_utf8_lossy(&head);
    if read.is_ok() && is_report(&head) {
        return Ok(());
    }
    Err(Error::invalid_setting(
        "-o",
        Some(&out.display().to_string()),
        format!(
            "error: `{}` exists and is not a report; `shaping report -o` replaces only an earlier report \
             (choose a new file, e.g. one ending in `.html`)",
            out.display()
        ),
    ))
}

/// The beginning of a page [`page`] made.
fn is_report(head: &str) -> bool {
    head.starts_with("<!doctype html>") && head.contains(" · shaping report</title>")
}
