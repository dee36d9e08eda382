//! The engine as a library: compile `examples/khepera.bat`, run its stages
//! into a temporary directory, print each stage's name and chosen best.
//!
//! ```sh
//! cargo run --release --example library
//! ```

use shaping_engine::run::{RunOptions, Runner, StageOutcome};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let source = std::fs::read_to_string("examples/khepera.bat")?;
    let program = shaping_compiler::compile(&source, "khepera.bat").map_err(|d| format!("{d:?}"))?;
    let out = std::env::temp_dir().join(format!("shaping-library-{}", std::process::id()));
    let options = RunOptions { out: out.clone(), no_report: true, ..RunOptions::default() };
    let outcome = Runner::default().run(program, &options)?;
    for stage in &outcome.stages {
        match stage {
            StageOutcome::Evolve { stage, best, genome, .. } => {
                println!("{stage}: chosen best {best:.3} ({} bits)", genome.bits.len())
            }
            StageOutcome::Train { stage, performance, .. } => println!("{stage}: trained, {performance:?}"),
            StageOutcome::Test { stage, summary } => {
                println!("{stage}: tested, fitness {} after the change", summary.fitness)
            }
        }
    }
    std::fs::remove_dir_all(&out)?;
    Ok(())
}
