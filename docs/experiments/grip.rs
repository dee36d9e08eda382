//! How often the grip module's script catches an object it starts in front
//! of (EXPERIMENTS.md, "The grip script's catch rate"): the mechanics of the
//! script alone, without arbitration or learning.
//!
//! ```sh
//! cargo run --release --example grip -- [FILE] [--diameter 10]
//! ```
//!
//! The script is the one of the module `grip` in FILE (default
//! `examples/khepera.bat`). A one-module stage runs it on a robot at the
//! centre of the arena, facing east, with one virtual object (10 mm unless
//! `--diameter` says otherwise: 25 is stage `bigger`'s) whose
//! centre is GAP mm from the body surface at BEARING degrees from the
//! heading, for every GAP of 5, 10, 15, 20, 25 mm and BEARING of -80 to 80
//! degrees in steps of 20, and 20 episode seeds each (wheel and sensor
//! noise differ). It prints the share of trials rewarded (the object
//! between the arms when the script judges) per bearing and per gap.

use std::process::ExitCode;

use shaping_runtime::controller::{episode_rngs, Controller};
use shaping_runtime::genome::Genome;
use shaping_runtime::sim::{Pose, Sim};

const GAPS: [f32; 8] = [-20.0, -10.0, 0.0, 5.0, 10.0, 15.0, 20.0, 25.0];
const BEARINGS: [f32; 9] = [-80.0, -60.0, -40.0, -20.0, 0.0, 20.0, 40.0, 60.0, 80.0];
const SEEDS: u64 = 20;

/// The body of `behavior script ... { ... }` of `module grip` in `source`.
fn grip_script(source: &str) -> Option<&str> {
    let module = source.find("module grip {")?;
    let open = module + source[module..].find("behavior script")?;
    let body = open + source[open..].find('{')? + 1;
    let close = body + source[body..].find('}')?;
    Some(&source[body..close])
}

/// A one-module stage around the script: the robot of `khepera.bat`, the
/// arena, one virtual object of `diameter` mm, no battery.
fn trial_file(script: &str, diameter: f32) -> String {
    format!(
        "robot k {{\n  sensor ir[8] proximity\n  sensor barrier optical\n  actuator wheels[2] speed\n  \
         actuator arm lift\n  actuator claw grip\n}}\n\
         stage trials {{\n  world {{ arena 400mm x 600mm  objects 1 diameter {diameter}mm virtual }}\n  \
         evolve {{ population 2  generations 1 }}\n  fitness per action wheels[0]\n  \
         module grip {{\n    sense ir, barrier\n    activation fixed 1\n    behavior script commit {{{script}}}\n  }}\n}}\n"
    )
}

fn run() -> Result<(), String> {
    let (mut file, mut diameter) = ("examples/khepera.bat".to_string(), 10.0f32);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--diameter" => {
                let v = args.next().ok_or("--diameter needs a value")?;
                diameter = v.parse().map_err(|e| format!("--diameter: {e}"))?;
                if !(diameter > 0.0 && diameter < 60.0) {
                    return Err(format!("--diameter: {diameter} mm is not between 0 and 60"));
                }
            }
            s if s.starts_with("--") => return Err(format!("unknown option `{s}`")),
            s => file = s.to_string(),
        }
    }
    let source = std::fs::read_to_string(&file).map_err(|e| format!("cannot read `{file}`: {e}"))?;
    let script = grip_script(&source).ok_or_else(|| format!("`{file}` has no scripted module `grip`"))?;
    let text = trial_file(script, diameter);
    let program = shaping_compiler::compile(&text, "grip-trials.bat")
        .map_err(|d| format!("the trial stage does not compile ({} errors)", d.len()))?;
    let stage = &program.stages[0];
    println!("the grip script of `{file}`, objects of {diameter} mm:{script}");
    let mut by_bearing = vec![(0u32, 0u32); BEARINGS.len()];
    let mut by_gap = vec![(0u32, 0u32); GAPS.len()];
    for (bi, bearing) in BEARINGS.iter().enumerate() {
        for (gi, gap) in GAPS.iter().enumerate() {
            for seed in 1..=SEEDS {
                let (sim_seed, rng) = episode_rngs(seed);
                let mut sim = Sim::new(&stage.world, sim_seed);
                let (x, y) = (200.0, 300.0);
                let d = stage.world.body.radius + gap;
                let b = bearing.to_radians();
                if !(sim.set_pose(Pose { x, y, theta: 0.0 })
                    && sim.set_object(0, x + d * b.cos(), y + d * b.sin()))
                {
                    return Err("cannot place the robot and the object".into());
                }
                let mut ctl = Controller::new(stage, &Genome::zeros(0), rng).map_err(|e| e.to_string())?;
                ctl.start(&mut sim);
                let mut judged = 0.0;
                for _ in 0..30 {
                    let rep = ctl.act(&mut sim);
                    if rep.reinforcement != 0.0 {
                        judged = rep.reinforcement;
                        break;
                    }
                }
                let ok = u32::from(judged > 0.0);
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
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
