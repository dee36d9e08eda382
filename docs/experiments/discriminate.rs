//! What grip and release decisions the proximity sensors allow
//! (EXPERIMENTS.md, "What the sensors allow the decisions").
//!
//! The oracle's `decisions` arbiter knows where the objects and walls are.
//! This one knows only what the grip and release modules sense: the eight
//! proximity readings and whether an object is held (the optical barrier).
//! It runs each seed's evolved collect best (`RUN/seed-N/collect/` of
//! `shaping experiment`: its checkpoint's best, checked against the file as
//! `shaping replay` checks it, with the training stages bound from the
//! run's `trained.json`) on episodes 101 to 103 and records, at every
//! action where a front sensor reads 0.2 or more:
//!
//! - not holding: *grip* (an object's centre within 25 mm of the body, in
//!   front) or *not* (no object within 40 mm);
//! - holding: *release* (a wall within 30 mm in front and no object within
//!   35 mm) or *not* (an object within 35 mm and no wall within 40 mm);
//!
//! other actions are ambiguous and left out. It fits three decision rules
//! on the proximity readings by logistic regression: *linear* (one sigmoid
//! unit, as the files' activation networks), *hidden 4* (four sigmoid
//! hidden units, every weight within the genes' -4..4, as `activation
//! hidden 4` could evolve) and *quadratic* (the readings and their pairwise
//! products, an unconstrained reference). Then, with the two halves of the
//! seeds fitted and tested crosswise (the rules fitted on seeds of one half
//! decide in the lives of the other), the arbiter makes grip win exactly
//! when nothing is held and its rule says grip, release exactly when an
//! object is held and its rule says release, and neither at other times;
//! the evolved architecture does the rest.
//!
//! It also fits the linear and quadratic rules to the real Khepera's
//! readings of a wall and of a 25 mm cylinder (`--ir-data`, the shared
//! tables): how well one proximity snapshot tells them apart on the robot.
//!
//! ```sh
//! cargo run --release --example discriminate -- FILE --run DIR [--seeds 10] [--first-seed 1] [--ir-data DIR]
//! ```

use std::path::Path;
use std::process::ExitCode;

mod common;

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shaping_engine::rundir;
use shaping_runtime::catalog::{CHANNELS, CH_IR};
use shaping_runtime::controller::{EpisodeOptions, Trace};
use shaping_runtime::genome::Genome;
use shaping_runtime::oracle::{self, run_arbitrated};
use shaping_runtime::program::Stage;
use shaping_runtime::sim::Sim;

const EPISODES: [u64; 3] = [101, 102, 103];
/// A front reading at or above this: the robot sees something.
const SEEN: f32 = 0.2;

struct Args {
    file: String,
    run: String,
    seeds: u64,
    first_seed: u64,
    ir_data: String,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        file: "examples/khepera.bat".into(),
        run: String::new(),
        seeds: 10,
        first_seed: 1,
        ir_data: "../shared/data/khepera-ir".into(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        match arg.as_str() {
            "--run" => a.run = value("--run")?,
            "--ir-data" => a.ir_data = value("--ir-data")?,
            "--seeds" => a.seeds = value("--seeds")?.parse().map_err(|e| format!("--seeds: {e}"))?,
            "--first-seed" => {
                a.first_seed = value("--first-seed")?.parse().map_err(|e| format!("--first-seed: {e}"))?
            }
            s if s.starts_with("--") => return Err(format!("unknown option `{s}`")),
            s => a.file = s.into(),
        }
    }
    if a.run.is_empty() {
        return Err("--run DIR (a `shaping experiment` output) is required".into());
    }
    if a.seeds < 2 {
        return Err("--seeds must be at least 2 (the seeds are split in two halves)".into());
    }
    Ok(a)
}

/// One labelled action: the eight proximity readings and the decision.
#[derive(Clone, Copy)]
struct Sample {
    ir: [f32; 8],
    yes: bool,
}

/// The labelled actions of one life, for the grip rule (not holding) and
/// the release rule (holding), and the evolved winner at each; the objects
/// the evolved architecture released outside in it.
#[derive(Default)]
struct Life {
    grip: Vec<(Sample, bool)>,
    release: Vec<(Sample, bool)>,
    released: u32,
}

fn ir_of(p: &[f32; CHANNELS]) -> [f32; 8] {
    std::array::from_fn(|k| p[CH_IR + k])
}

fn seen(ir: &[f32; 8]) -> bool {
    ir[..6].iter().any(|&v| v >= SEEN)
}

/// The label of the current state, if it is not ambiguous: `(holding, yes)`.
fn label(sim: &Sim) -> Option<(bool, bool)> {
    let obj = sim.nearest_object();
    let near = |d: f32| obj.is_some_and(|(_, _, gap)| gap <= d);
    let (wall_gap, bearing) = sim.nearest_wall();
    if sim.holding() {
        let wall_front = wall_gap <= 30.0 && bearing.abs() < std::f32::consts::FRAC_PI_2;
        if wall_front && !near(35.0) {
            Some((true, true))
        } else if near(35.0) && wall_gap > 40.0 {
            Some((true, false))
        } else {
            None
        }
    } else {
        let in_reach = obj.is_some_and(|(fwd, _, gap)| gap <= 25.0 && fwd + sim.body_radius() > 0.0);
        if in_reach {
            Some((false, true))
        } else if !near(40.0) {
            Some((false, false))
        } else {
            None
        }
    }
}

/// A decision rule on the proximity readings: its net input (> 0: yes).
#[derive(Clone)]
enum Rule {
    Linear(Vec<f32>),
    Quadratic(Vec<f32>),
    Hidden { hidden: usize, w: Vec<f32> },
}

fn quadratic_features(ir: &[f32; 8]) -> Vec<f32> {
    let mut f = ir.to_vec();
    for i in 0..6 {
        for j in i..6 {
            f.push(ir[i] * ir[j]);
        }
    }
    f
}

fn sigmoid(z: f32) -> f32 {
    1.0 / (1.0 + (-z).exp())
}

fn dot(w: &[f32], x: &[f32]) -> f32 {
    w[0] + w[1..].iter().zip(x).map(|(a, b)| a * b).sum::<f32>()
}

impl Rule {
    fn net(&self, ir: &[f32; 8]) -> f32 {
        match self {
            Rule::Linear(w) => dot(w, ir),
            Rule::Quadratic(w) => dot(w, &quadratic_features(ir)),
            Rule::Hidden { hidden, w } => {
                let h: Vec<f32> = (0..*hidden).map(|j| sigmoid(dot(&w[j * 9..j * 9 + 9], ir))).collect();
                dot(&w[hidden * 9..], &h)
            }
        }
    }

    fn accuracy(&self, s: &[Sample]) -> f64 {
        s.iter().filter(|x| (self.net(&x.ir) > 0.0) == x.yes).count() as f64 / s.len().max(1) as f64
    }
}

/// Logistic regression by full-batch gradient descent from zero weights
/// (deterministic).
fn fit_logistic(s: &[Sample], features: impl Fn(&[f32; 8]) -> Vec<f32>) -> Vec<f32> {
    let x: Vec<Vec<f32>> = s.iter().map(|v| features(&v.ir)).collect();
    let mut w = vec![0.0f32; x.first().map_or(0, |f| f.len()) + 1];
    for _ in 0..2000 {
        let mut g = vec![0.0f32; w.len()];
        for (f, v) in x.iter().zip(s) {
            let d = v.yes as u8 as f32 - sigmoid(dot(&w, f));
            g[0] += d;
            for (gk, a) in g[1..].iter_mut().zip(f) {
                *gk += d * a;
            }
        }
        for (wk, gk) in w.iter_mut().zip(&g) {
            *wk += 3.0 * gk / s.len().max(1) as f32;
        }
    }
    w
}

/// A network of `hidden` sigmoid units and a sigmoid output, every weight
/// kept within `-limit..limit`, fitted by stochastic gradient descent on the
/// cross-entropy; the best of 4 starts on the training samples.
fn fit_hidden(s: &[Sample], hidden: usize, limit: f32, seed: u64) -> Rule {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut best: Option<(f64, Rule)> = None;
    for _ in 0..4 {
        let mut w: Vec<f32> = (0..hidden * 9 + hidden + 1).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut order: Vec<usize> = (0..s.len()).collect();
        for _ in 0..300 {
            order.shuffle(&mut rng);
            for &i in &order {
                let x = &s[i].ir;
                let h: Vec<f32> = (0..hidden).map(|j| sigmoid(dot(&w[j * 9..j * 9 + 9], x))).collect();
                let out = sigmoid(dot(&w[hidden * 9..], &h));
                let d = s[i].yes as u8 as f32 - out;
                let lr = 0.5;
                for j in 0..hidden {
                    let dh = d * w[hidden * 9 + 1 + j] * h[j] * (1.0 - h[j]);
                    w[j * 9] += lr * dh;
                    for k in 0..8 {
                        w[j * 9 + 1 + k] += lr * dh * x[k];
                    }
                }
                w[hidden * 9] += lr * d;
                for j in 0..hidden {
                    w[hidden * 9 + 1 + j] += lr * d * h[j];
                }
                for v in w.iter_mut() {
                    *v = v.clamp(-limit, limit);
                }
            }
        }
        let rule = Rule::Hidden { hidden, w };
        let acc = rule.accuracy(s);
        if best.as_ref().is_none_or(|(a, _)| acc > *a) {
            best = Some((acc, rule));
        }
    }
    best.expect("four starts").1
}

fn fit(kind: &str, s: &[Sample], seed: u64) -> Rule {
    match kind {
        "linear" => Rule::Linear(fit_logistic(s, |ir| ir.to_vec())),
        "quadratic" => Rule::Quadratic(fit_logistic(s, quadratic_features)),
        _ => fit_hidden(s, 4, 4.0, seed),
    }
}

const KINDS: [&str; 3] = ["linear", "hidden 4", "quadratic"];

fn median(v: Vec<f64>) -> f64 {
    shaping_engine::stats::median(&v).unwrap_or(f64::NAN)
}

fn summary(v: &[u32]) -> String {
    let f: Vec<f64> = v.iter().map(|&x| x as f64).collect();
    format!(
        "median {} (range {}..{}, mean {:.2}), {} lives with 5 or more",
        median(f.clone()),
        v.iter().min().unwrap_or(&0),
        v.iter().max().unwrap_or(&0),
        f.iter().sum::<f64>() / f.len().max(1) as f64,
        v.iter().filter(|&&x| x >= 5).count()
    )
}

/// Share of the labelled actions where the evolved architecture's winner
/// was the module, among the "yes" ones (recall) and among the actions it
/// won (precision).
fn evolved_decisions(lives: &[&Life], release: bool) -> (f64, f64) {
    let all: Vec<&(Sample, bool)> =
        lives.iter().flat_map(|l| if release { &l.release } else { &l.grip }).collect();
    let won_yes = all.iter().filter(|(s, won)| *won && s.yes).count() as f64;
    let won = all.iter().filter(|(_, won)| *won).count() as f64;
    let yes = all.iter().filter(|(s, _)| s.yes).count() as f64;
    (won_yes / won.max(1.0), won_yes / yes.max(1.0))
}

/// The real robot's readings of a table (`8 180 20 5 2` header, `TURN t`
/// blocks of 180 lines of 8 values).
fn real_table(path: &str) -> Result<Vec<[f32; 8]>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read `{path}`: {e}"))?;
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        let line = line.trim();
        if line.is_empty() || line == "END" || line.starts_with("TURN") {
            continue;
        }
        let v: Vec<f32> = line
            .split_whitespace()
            .map(|x| x.parse::<f32>().map_err(|e| format!("{path}:{}: {e}", n + 1)))
            .collect::<Result<_, _>>()?;
        let r: [f32; 8] = v.try_into().map_err(|_| format!("{path}:{}: expected 8 readings", n + 1))?;
        out.push(r);
    }
    Ok(out)
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let (base, index) = common::load(&args.file, "collect")?;
    let seeds: Vec<u64> = (args.first_seed..args.first_seed + args.seeds).collect();
    let mut stages: Vec<Stage> = Vec::new();
    let mut genomes: Vec<Genome> = Vec::new();
    let mut lives: Vec<Vec<Life>> = Vec::new();
    for &seed in &seeds {
        let run = rundir::seed_dir(Path::new(&args.run), seed);
        let mut program = base.clone();
        common::bind(&mut program, Some(&run), seed)?;
        let g = common::best(&program, index, &run, seed)?;
        let stage = program.stages[index].clone();
        let grip = oracle::module(&stage, "grip")?;
        let release = oracle::module(&stage, "release")?;
        let mut per_seed = Vec::new();
        for ep in EPISODES {
            let opts = EpisodeOptions { actions: 300, learning: true, seed: ep };
            let mut states: Vec<Option<(bool, Sample)>> = Vec::new();
            let mut trace = Trace::default();
            // Only records: this is the evolved architecture alone.
            let alone = run_arbitrated(&stage, &g, &opts, None, Some(&mut trace), |c, sim| {
                let ir = ir_of(c.percept());
                states.push(
                    label(sim).filter(|_| seen(&ir)).map(|(holding, yes)| (holding, Sample { ir, yes })),
                );
            })
            .map_err(|e| e.to_string())?;
            let mut life = Life { released: alone.releases_outside, ..Life::default() };
            for (row, state) in trace.rows.iter().zip(&states) {
                let Some((holding, s)) = state else { continue };
                if *holding {
                    life.release.push((*s, row.winner as usize == release));
                } else {
                    life.grip.push((*s, row.winner as usize == grip));
                }
            }
            per_seed.push(life);
        }
        stages.push(stage);
        genomes.push(g);
        lives.push(per_seed);
    }

    let half = seeds.len() / 2;
    let folds = [(0..half, half..seeds.len()), (half..seeds.len(), 0..half)];
    let samples = |range: std::ops::Range<usize>, release: bool| -> Vec<Sample> {
        lives[range]
            .iter()
            .flatten()
            .flat_map(|l| if release { &l.release } else { &l.grip })
            .map(|(s, _)| *s)
            .collect()
    };
    let all_grip = samples(0..seeds.len(), false);
    let all_release = samples(0..seeds.len(), true);
    let share = |s: &[Sample]| s.iter().filter(|x| x.yes).count() as f64 / s.len().max(1) as f64;
    println!(
        "labelled actions: grip {} (yes {:.2}), release {} (yes {:.2}), over {} lives",
        all_grip.len(),
        share(&all_grip),
        all_release.len(),
        share(&all_release),
        seeds.len() * EPISODES.len()
    );
    let flat: Vec<&Life> = lives.iter().flatten().collect();
    let (p, r) = evolved_decisions(&flat, false);
    let (pr, rr) = evolved_decisions(&flat, true);
    println!(
        "evolved: grip wins with precision {p:.2} recall {r:.2}; release precision {pr:.2} recall {rr:.2}"
    );

    let mut released: Vec<(&str, Vec<u32>)> = KINDS.iter().map(|k| (*k, Vec::new())).collect();
    let evolved: Vec<u32> = flat.iter().map(|l| l.released).collect();
    for (fold, (fit_on, test_on)) in folds.iter().enumerate() {
        let (g_train, r_train) = (samples(fit_on.clone(), false), samples(fit_on.clone(), true));
        let (g_test, r_test) = (samples(test_on.clone(), false), samples(test_on.clone(), true));
        for (k, kind) in KINDS.iter().enumerate() {
            let seed = 1000 + fold as u64 * 10 + k as u64;
            let (gr, rr) = (fit(kind, &g_train, seed), fit(kind, &r_train, seed + 100));
            println!(
                "fold {}: {kind}: accuracy grip {:.3} fitted / {:.3} tested, release {:.3} / {:.3}",
                fold + 1,
                gr.accuracy(&g_train),
                gr.accuracy(&g_test),
                rr.accuracy(&r_train),
                rr.accuracy(&r_test)
            );
            for i in test_on.clone() {
                let stage = &stages[i];
                let grip = oracle::module(stage, "grip")?;
                let release = oracle::module(stage, "release")?;
                for ep in EPISODES {
                    let opts = EpisodeOptions { actions: 300, learning: true, seed: ep };
                    let res = run_arbitrated(stage, &genomes[i], &opts, None, None, |c, sim| {
                        let ir = ir_of(c.percept());
                        let holding = sim.holding();
                        if !holding && seen(&ir) && gr.net(&ir) > 0.0 {
                            c.force_winner(grip);
                        } else {
                            c.forbid(grip);
                        }
                        if holding && seen(&ir) && rr.net(&ir) > 0.0 {
                            c.force_winner(release);
                        } else {
                            c.forbid(release);
                        }
                    })
                    .map_err(|e| e.to_string())?;
                    released[k].1.push(res.releases_outside);
                }
            }
        }
    }
    println!("released outside per life, seeds fitted and tested crosswise:");
    println!("  evolved alone: {}", summary(&evolved));
    for (kind, v) in &released {
        println!("  {kind} rule decides: {}", summary(v));
    }

    let wall = real_table(&format!("{}/khepera-wall.sample", args.ir_data))?;
    let cylinder = real_table(&format!("{}/khepera-cylinder.sample", args.ir_data))?;
    let real: Vec<Sample> = wall
        .iter()
        .map(|ir| Sample { ir: *ir, yes: false })
        .chain(cylinder.iter().map(|ir| Sample { ir: *ir, yes: true }))
        .filter(|s| seen(&s.ir))
        .collect();
    let base_rate = share(&real).max(1.0 - share(&real));
    println!(
        "real Khepera, a wall against a 25 mm cylinder ({} readings with a front sensor at {SEEN} or more, \
         majority {base_rate:.3}): linear {:.3}, quadratic {:.3}",
        real.len(),
        fit("linear", &real, 0).accuracy(&real),
        fit("quadratic", &real, 0).accuracy(&real)
    );
    Ok(())
}

fn main() -> ExitCode {
    common::exit(run())
}
