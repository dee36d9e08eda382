//! `shaping fmt`: formats files in place, or stdin to stdout.

use std::path::PathBuf;

use shaping_compiler::fmt::{format, FormatError};

use crate::load;
use crate::out::{out, outln};
use crate::{diag, exit_code, CliError, ErrorFormat};

/// Formats the files (stdin to stdout when there are none). With `check`,
/// writes nothing and names the files that would change (exit 1).
pub fn fmt(files: &[PathBuf], check: bool, error_format: ErrorFormat) -> Result<(), CliError> {
    if files.is_empty() {
        return fmt_stdin(check, error_format);
    }
    let mut worst: Option<CliError> = None;
    let mut changed = 0;
    for file in files {
        let result = load::read_source(file, error_format).and_then(|src| {
            let out = format_one(&src, &file.display().to_string(), error_format)?;
            if out == src {
                return Ok(());
            }
            changed += 1;
            if check {
                outln!("{}", file.display())
            } else {
                load::write_atomic(file, out.as_bytes())?;
                eprintln!("formatted {}", file.display());
                Ok(())
            }
        });
        if let Err(e) = result {
            eprintln!("{e}");
            if worst.as_ref().is_none_or(|w| exit_code(w) < exit_code(&e)) {
                worst = Some(e);
            }
        }
    }
    match worst {
        Some(e) => Err(CliError::new(e.kind(), String::new())),
        None if check && changed > 0 => Err(CliError::diagnostics_text(format!(
            "{changed} file{} would be reformatted by `shaping fmt`",
            if changed == 1 { "" } else { "s" }
        ))),
        None => Ok(()),
    }
}

fn fmt_stdin(check: bool, error_format: ErrorFormat) -> Result<(), CliError> {
    let bytes = shaping_engine::files::read_input(std::io::stdin(), "standard input")?;
    let src = String::from_utf8(bytes).map_err(|e| {
        CliError::new(
            shaping_engine::ErrorKind::Invalid,
            format!("error: standard input is not UTF-8 text: {e}"),
        )
    })?;
    let out = format_one(&src, "<stdin>", error_format)?;
    if check {
        if out != src {
            outln!("<stdin>")?;
            return Err(CliError::diagnostics_text("standard input would be reformatted by `shaping fmt`"));
        }
        return Ok(());
    }
    out!("{out}")
}

fn format_one(src: &str, name: &str, error_format: ErrorFormat) -> Result<String, CliError> {
    format(src, name).map_err(|e| match e {
        FormatError::Syntax(d) => CliError::diagnostics_text(format!(
            "{}\n{name}: not formatted (it does not parse)",
            diag::render(&d, error_format).trim_end()
        )),
        FormatError::Changed(why) => {
            CliError::internal(format!("error: `{name}` was left as it is: {why} (a bug of `shaping fmt`)"))
        }
    })
}
