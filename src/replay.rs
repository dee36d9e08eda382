//! `shaping replay` on the terminal.

use shaping_engine::replay::{self, ReplayOptions};

use crate::out::outln;
use crate::terminal::Terminal;
use crate::{load, CliError, ErrorFormat};

pub fn replay(args: ReplayOptions, error_format: ErrorFormat) -> Result<(), CliError> {
    let program = load::load_program(&args.file, error_format)?;
    let r = replay::replay(program, &args, &Terminal::new(true, false))?;
    let e = &r.result;
    outln!(
        "{}: {} actions, fitness {:.3}, {} grips, {} released outside, {} recharges, {} collisions -> {}",
        r.stage,
        e.actions,
        e.fitness,
        e.grips,
        e.releases_outside,
        e.recharges,
        e.collisions,
        r.out.display()
    )?;
    if let Some(path) = r.report {
        outln!("report: {}", path.display())?;
    }
    for path in &r.animations {
        outln!("animation: {}", path.display())?;
    }
    Ok(())
}
