//! How often the grip module's script catches an object it starts in front
//! of (EXPERIMENTS.md, "The grip script's catch rate"): the mechanics of the
//! script alone, without arbitration or learning.
//!
//! ```sh
//! cargo run --release --example grip -- [FILE] [--stage collect] [--diameter D]
//! ```
//!
//! The module `grip` of the stage (default `collect` of
//! `examples/khepera.bat`) is made to win with the robot in the middle of
//! the arena, facing east, and one virtual object (the stage's diameter, or
//! `--diameter` mm: 25 is stage `bigger`'s) whose centre is GAP mm from the
//! body surface at BEARING degrees from the heading, for GAP from -20 (under
//! the front of the body) to 25 mm and BEARING from -80 to 80 degrees, 20
//! episode seeds each (wheel and sensor noise differ); the other objects lie
//! in a corner (`shaping_runtime::oracle::grip_trial`). It prints the share
//! of trials rewarded (the object between the arms when the script judges)
//! per bearing and per gap.

use std::process::ExitCode;

mod common;

use shaping_runtime::genome::Genome;
use shaping_runtime::oracle::{grip_trial, module};

const GAPS: [f32; 8] = [-20.0, -10.0, 0.0, 5.0, 10.0, 15.0, 20.0, 25.0];
const BEARINGS: [f32; 9] = [-80.0, -60.0, -40.0, -20.0, 0.0, 20.0, 40.0, 60.0, 80.0];
const SEEDS: u64 = 20;

struct Args {
    file: String,
    stage: String,
    diameter: Option<f32>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args { file: "examples/khepera.bat".into(), stage: "collect".into(), diameter: None };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        match arg.as_str() {
            "--stage" => a.stage = value("--stage")?,
            "--diameter" => {
                let d: f32 = value("--diameter")?.parse().map_err(|e| format!("--diameter: {e}"))?;
                if !(d > 0.0 && d < 60.0) {
                    return Err(format!("--diameter: {d} mm is not between 0 and 60"));
                }
                a.diameter = Some(d);
            }
            s if s.starts_with("--") => return Err(format!("unknown option `{s}`")),
            s => a.file = s.into(),
        }
    }
    Ok(a)
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let (mut program, index) = common::load(&args.file, &args.stage)?;
    // The trained weights of other modules bind as in a run of seed 1; they
    // do not drive once the grip script has started.
    common::bind(&mut program, None, 1)?;
    let mut stage = program.stages[index].clone();
    let Some(objects) = stage.world.objects.as_mut() else {
        return Err(format!("stage `{}` has no objects", args.stage));
    };
    if let Some(d) = args.diameter {
        objects.diameter = d;
    }
    let diameter = objects.diameter;
    let grip = module(&stage, "grip")?;
    let genome = Genome::zeros(stage.layout.bits as usize);
    println!("the grip module of stage `{}` in `{}`, objects of {diameter} mm", args.stage, args.file);
    let mut by_bearing = vec![(0u32, 0u32); BEARINGS.len()];
    let mut by_gap = vec![(0u32, 0u32); GAPS.len()];
    for (bi, bearing) in BEARINGS.iter().enumerate() {
        for (gi, gap) in GAPS.iter().enumerate() {
            for seed in 1..=SEEDS {
                let judged =
                    grip_trial(&stage, &genome, grip, *gap, *bearing, seed).map_err(|e| e.to_string())?;
                let ok = u32::from(judged.is_some_and(|r| r > 0.0));
                by_bearing[bi] = (by_bearing[bi].0 + ok, by_bearing[bi].1 + 1);
                by_gap[gi] = (by_gap[gi].0 + ok, by_gap[gi].1 + 1);
            }
        }
    }
    let share = |(ok, n): (u32, u32)| f64::from(ok) / f64::from(n.max(1));
    let line = |v: &[(u32, u32)]| v.iter().map(|&c| format!("{:.2}", share(c))).collect::<Vec<_>>().join(" ");
    println!("bearing (deg) {}", BEARINGS.map(|b| format!("{b:+.0}")).join(" "));
    println!("caught        {}", line(&by_bearing));
    println!("gap (mm)      {}", GAPS.map(|g| format!("{g:.0}")).join(" "));
    println!("caught        {}", line(&by_gap));
    let all = by_gap.iter().fold((0, 0), |a, c| (a.0 + c.0, a.1 + c.1));
    let central = by_bearing[2..7].iter().fold((0, 0), |a, c| (a.0 + c.0, a.1 + c.1));
    println!(
        "caught in {} of {} trials ({:.2}); within 40 degrees of the heading {:.2}",
        all.0,
        all.1,
        share(all),
        share(central)
    );
    Ok(())
}

fn main() -> ExitCode {
    common::exit(run())
}
