//! A test stage's fitness before and after its world change, per seed, and
//! the Mann-Whitney U test between them (EXPERIMENTS.md, "Recruitment"):
//! `shaping compare` pairs directories, not the two worlds of one test
//! stage. For `recruit.bat`'s `forage_silent`, before is the evolved team
//! as it is and after the same lives with every broadcast heard as 0.
//!
//! ```sh
//! cargo run --release --example ablation -- DIR STAGE
//! ```
//!
//! It reads `DIR/seed-N/STAGE/summary.json` for every `seed-N` there and
//! prints one line per seed (`seed N before B after A`), then the medians,
//! the U test (unpaired, as `compare` makes it; `shaping_engine::stats`),
//! the A12 of before against after, and how many seeds lost by the change.

use std::path::Path;
use std::process::ExitCode;

use shaping_engine::stats;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [dir, stage] = args.as_slice() else {
        eprintln!("usage: ablation DIR STAGE");
        return ExitCode::from(2);
    };
    match run(Path::new(dir), stage) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(dir: &Path, stage: &str) -> Result<(), String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("cannot read `{}`: {e}", dir.display()))?;
    let mut seeds: Vec<u64> =
        entries.filter_map(|e| e.ok()?.file_name().to_str()?.strip_prefix("seed-")?.parse().ok()).collect();
    seeds.sort_unstable();
    if seeds.len() < 2 {
        return Err(format!("`{}` has fewer than 2 `seed-N` runs", dir.display()));
    }
    let (mut before, mut after) = (Vec::new(), Vec::new());
    for s in &seeds {
        let path = dir.join(format!("seed-{s}")).join(stage).join("summary.json");
        let text =
            std::fs::read_to_string(&path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
        let v: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| format!("`{}` is not JSON: {e}", path.display()))?;
        let fitness = |side: &str| {
            v[side]["fitness"].as_f64().ok_or_else(|| {
                format!("`{}` has no `{side}.fitness`: is `{stage}` a test stage?", path.display())
            })
        };
        let (b, a) = (fitness("before")?, fitness("after")?);
        println!("seed {s} before {b:.3} after {a:.3}");
        before.push(b);
        after.push(a);
    }
    let median = |x: &[f64]| stats::median(x).unwrap_or(f64::NAN);
    println!("median before {:.3} after {:.3}", median(&before), median(&after));
    if let (Some(u), Some(a12)) = (stats::mann_whitney(&before, &after), stats::a12(&before, &after)) {
        println!("Mann-Whitney U {:.1} p {:.4}; A12 (before > after) {a12:.3}", u.u, u.p_value);
    }
    let lost = before.iter().zip(&after).filter(|(b, a)| a < b).count();
    println!("seeds where the change lowered the fitness: {lost} of {}", seeds.len());
    Ok(())
}
