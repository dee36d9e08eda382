//! `shaping experiment`: the same architecture over several seeds, with the
//! statistics the paper's figures are judged by (median and range).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use shaping_runtime::evolve::{Checkpoint, GenStats};
use shaping_runtime::program::{Program, StageRun};

use crate::load::{self, write_atomic, CliError};
use crate::{plot, report, run};

pub struct ExperimentArgs {
    pub file: PathBuf,
    pub seeds: u64,
    pub first_seed: u64,
    pub out: Option<PathBuf>,
    pub jobs: Option<usize>,
    pub criterion: Vec<String>,
    pub fresh: bool,
    /// Write no `report.html` at the end.
    pub no_report: bool,
    pub error_format: crate::diag::ErrorFormat,
}

/// Median, minimum and maximum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    pub median: f64,
    pub min: f64,
    pub max: f64,
}

pub fn spread(values: &[f64]) -> Option<Spread> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    let median = if n % 2 == 1 { v[n / 2] } else { (v[n / 2 - 1] + v[n / 2]) / 2.0 };
    Some(Spread { median, min: v[0], max: v[n - 1] })
}

fn fmt_spread(s: Option<Spread>, digits: usize) -> String {
    match s {
        Some(s) => format!("{:.d$} ({:.d$} .. {:.d$})", s.median, s.min, s.max, d = digits),
        None => "-".into(),
    }
}

/// Parses `STAGE=VALUE` criteria (`navigation=0.7`).
fn criteria(program: &Program, args: &[String]) -> Result<Vec<(String, f32)>, CliError> {
    args.iter()
        .map(|c| {
            let (stage, value) = c.split_once('=').ok_or_else(|| {
                CliError::io(format!("error: criterion `{c}` is not of the form STAGE=FITNESS"))
            })?;
            load::stage_index(program, Some(stage))?;
            let v: f32 = value
                .parse()
                .map_err(|_| CliError::io(format!("error: criterion `{c}`: `{value}` is not a number")))?;
            Ok((stage.to_string(), v))
        })
        .collect()
}

/// Runs the seeds one after the other; with `cluster` (rank 0 of an MPI run)
/// the episodes of each generation are spread over the ranks.
pub fn experiment(
    args: ExperimentArgs,
    cluster: Option<&crate::cluster::Coordinator>,
) -> Result<(), CliError> {
    let program = load::load_program(&args.file, args.error_format)?;
    let criteria = criteria(&program, &args.criterion)?;
    if args.seeds == 0 {
        return Err(CliError::io("error: `--seeds` must be at least 1"));
    }
    let out = args.out.clone().unwrap_or_else(|| run::default_out(&args.file).join("experiment"));
    load::create_dir(&out)?;
    let end = args.first_seed.checked_add(args.seeds).ok_or_else(|| {
        CliError::io(format!(
            "error: `--first-seed {}` plus `--seeds {}` is past the largest seed",
            args.first_seed, args.seeds
        ))
    })?;
    let seeds: Vec<u64> = (args.first_seed..end).collect();
    for (i, &seed) in seeds.iter().enumerate() {
        eprintln!("seed {seed} ({}/{})", i + 1, seeds.len());
        run::run(
            run::RunArgs {
                file: args.file.clone(),
                stage: None,
                seed: Some(seed),
                out: Some(out.join(format!("seed-{seed}"))),
                jobs: args.jobs,
                quiet: false,
                json: false,
                fresh: args.fresh,
                // One report for the whole experiment, written below.
                no_report: true,
                error_format: args.error_format,
                robot: None,
            },
            cluster,
        )?;
    }
    // Titled by the file: several files may share a robot (and so a program name).
    let title =
        args.file.file_stem().map_or_else(|| program.name.clone(), |s| s.to_string_lossy().into_owned());
    let summary = summarise(&program, &title, &out, &seeds, &criteria)?;
    write_atomic(&out.join("summary.md"), summary.as_bytes())?;
    print!("{summary}");
    if !args.no_report {
        let path = crate::html::write(&out, None)?;
        eprintln!("report: {}", path.display());
    }
    Ok(())
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, CliError> {
    let bytes = load::read_bytes(path)?;
    serde_json::from_slice(&bytes)
        .map_err(|e| CliError::io(format!("error: cannot read `{}`: {e}", path.display())))
}

/// Builds the Markdown summary and the multi-seed fitness picture.
fn summarise(
    program: &Program,
    title: &str,
    out: &Path,
    seeds: &[u64],
    criteria: &[(String, f32)],
) -> Result<String, CliError> {
    let mut md = String::new();
    let _ = writeln!(md, "# {title} over {} seeds ({:?})\n", seeds.len(), seeds);
    let _ = writeln!(md, "Median (min .. max) over seeds.\n");
    let _ = writeln!(
        md,
        "| stage | generations | final best | final mean | best ever | generation reaching criterion |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    let mut histories: Vec<Vec<GenStats>> = vec![Vec::new(); seeds.len()];
    for stage in &program.stages {
        match &stage.run {
            StageRun::Evolve(evo) => {
                let mut best = Vec::new();
                let mut mean = Vec::new();
                let mut ever = Vec::new();
                let mut reach = Vec::new();
                let mut unreached = 0;
                let criterion = criteria.iter().find(|(s, _)| *s == stage.name).map(|c| c.1);
                for &seed in seeds {
                    let cp: Checkpoint = read_json(
                        &out.join(format!("seed-{seed}")).join(&stage.name).join("checkpoint.json"),
                    )?;
                    let own: Vec<&GenStats> = cp.history.iter().filter(|h| h.stage == stage.name).collect();
                    if let Some(last) = own.last() {
                        best.push(last.best as f64);
                        mean.push(last.mean as f64);
                    }
                    ever.push(own.iter().map(|h| h.best as f64).fold(f64::NEG_INFINITY, f64::max));
                    if let Some(c) = criterion {
                        match own.iter().find(|h| h.best >= c) {
                            Some(h) => reach.push(h.stage_generation as f64 + 1.0),
                            None => unreached += 1,
                        }
                    }
                    // Per seed, keep the longest history (the deepest evolved stage's).
                    let slot = seeds.iter().position(|&s| s == seed).unwrap_or(0);
                    if cp.history.len() > histories[slot].len() {
                        histories[slot] = cp.history;
                    }
                }
                let reach_text = match criterion {
                    None => "-".to_string(),
                    Some(c) => format!(
                        "{} to reach {c}{}",
                        fmt_spread(spread(&reach), 0),
                        if unreached > 0 { format!("; {unreached} seeds never") } else { String::new() }
                    ),
                };
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {} |",
                    stage.name,
                    evo.generations,
                    fmt_spread(spread(&best), 3),
                    fmt_spread(spread(&mean), 3),
                    fmt_spread(spread(&ever), 3),
                    reach_text
                );
            }
            StageRun::Train { actions } => {
                let mut perf = Vec::new();
                for &seed in seeds {
                    let t: shaping_runtime::evolve::Trained =
                        read_json(&out.join(format!("seed-{seed}")).join(&stage.name).join("trained.json"))?;
                    let learners =
                        stage.modules.iter().zip(&t.performance).filter(|(m, _)| m.learning.is_some());
                    perf.extend(learners.map(|(_, p)| *p as f64));
                }
                let _ = writeln!(
                    md,
                    "| {} | training, {actions} actions | performance at the end {} | - | - | - |",
                    stage.name,
                    fmt_spread(spread(&perf), 2),
                );
            }
            StageRun::Test { actions, learning } => {
                let mut fit = Vec::new();
                let mut grips = Vec::new();
                let mut rel = Vec::new();
                for &seed in seeds {
                    let v: serde_json::Value =
                        read_json(&out.join(format!("seed-{seed}")).join(&stage.name).join("summary.json"))?;
                    fit.push(v["fitness"].as_f64().unwrap_or(f64::NAN));
                    grips.push(v["grips"].as_f64().unwrap_or(f64::NAN));
                    rel.push(v["releases_outside"].as_f64().unwrap_or(f64::NAN));
                }
                let _ = writeln!(
                    md,
                    "| {} | test, {actions} actions, learning {} | fitness {} | grips {} | released outside {} | - |",
                    stage.name,
                    if *learning { "on" } else { "off" },
                    fmt_spread(spread(&fit), 3),
                    fmt_spread(spread(&grips), 1),
                    fmt_spread(spread(&rel), 1),
                );
            }
        }
    }
    let runs: Vec<Vec<plot::GenPoint>> = histories.iter().map(|h| report::fitness_points(h).0).collect();
    if let Some(first) = histories.iter().filter(|h| !h.is_empty()).max_by_key(|h| h.len()) {
        let starts = report::fitness_points(first).1;
        plot::multi_seed_fitness(
            &out.join("fitness-seeds"),
            &format!("{title}: fitness over {} seeds (median, min-max)", seeds.len()),
            &runs,
            &starts,
        )
        .map_err(|e| CliError::io(format!("error: {e}")))?;
    }
    let _ = writeln!(
        md,
        "\nPicture: `fitness-seeds.svg` / `fitness-seeds.png` (median best and mean, min-max band)."
    );
    Ok(md)
}
