//! The engine as a library: load `examples/khepera.bat`, run its stages
//! into a temporary directory, print each stage's name and chosen best.
//!
//! ```sh
//! cargo run --release --example library
//! ```

use shaping_engine::run::{RunOptions, StageOutcome};
use shaping_engine::Engine;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let engine = Engine::default();
    let program = engine.load("examples/khepera.bat".as_ref())?;
    let out = std::env::temp_dir().join(format!("shaping-library-{}", std::process::id()));
    let options = RunOptions { out: out.clone(), no_report: true, ..RunOptions::default() };
    let outcome = engine.run(program, &options)?;
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
