//! Comparisons of experiments: per stage and per measure, each group's
//! (a sweep's point, or an experiment directory given to `shaping compare`)
//! median over its seeds with its bootstrap 95% interval, and for every pair
//! of groups the two-sided Mann-Whitney U test and the Vargha-Delaney A12,
//! Holm-corrected over the pairs of a measure when there are more than two
//! groups (the numbers: `stats`). Read from the files the seeds' runs wrote.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use shaping_runtime::evolve::{Checkpoint, GenStats};
use shaping_runtime::program::{Program, StageRun};

use crate::error::{Error, ErrorKind};
use crate::stats;
use crate::{load, rundir};

// The comparison's figures are part of `summary.json`'s schema.
use crate::rundir::{GroupFigures, MeasureTests, PairTest, Tests};

/// One stage's measures over the seeds of a group: each measure's value per
/// seed, in the seeds' order (NaN: missing from the seed's files).
#[derive(Clone, Debug, PartialEq)]
pub struct StageMeasures {
    pub stage: String,
    pub kind: &'static str,
    pub measures: Vec<(&'static str, Vec<f64>)>,
}

/// The measures compared: an evolved stage's, a test stage's (a training
/// stage has none: its figure is per learning module, not per seed).
pub const EVOLVE_MEASURES: [&str; 10] = [
    "final_best",
    "chosen_best",
    "final_mean",
    "best_ever",
    "final_worst",
    "final_best_recharges",
    "final_best_grips",
    "final_best_releases_outside",
    "generation_reaching_criterion",
    "evaluations_reaching_criterion",
];
pub const TEST_MEASURES: [&str; 3] = ["fitness", "grips", "releases_outside"];

/// The measures of `stages` of `program` over `seeds` in experiment
/// directory `dir` (its `seed-N/` run directories), as the summaries read
/// them: an evolved stage's final best, chosen best, final mean and best
/// ever, the last generation's worst and its best's recharges, grips and
/// releases outside (the other columns of `generations.csv`), and, with a
/// criterion, the generation whose best first reaches it and the
/// evaluations until then (the episodes of that many generations: the
/// population times its episodes per individual, plus every generation of
/// the evolved stages it extends: the cost of the whole path to the
/// criterion; a seed that
/// never reaches it counts as the stage's generations plus one, after every
/// seed that does); a test stage's fitness, grips and releases outside.
pub fn read_measures(
    program: &Program,
    stages: &[usize],
    dir: &Path,
    seeds: &[u64],
    criteria: &[(String, f32)],
) -> Result<Vec<StageMeasures>, Error> {
    let mut out = Vec::new();
    for (index, stage) in stages.iter().map(|&i| (i, &program.stages[i])) {
        match &stage.run {
            StageRun::Evolve(evo) => {
                let criterion = criteria.iter().find(|(s, _)| *s == stage.name).map(|c| c.1);
                let earlier = earlier_evaluations(program, index);
                let mut v: [Vec<f64>; 10] = Default::default();
                for &seed in seeds {
                    let sdir = rundir::stage_dir(&rundir::seed_dir(dir, seed), &stage.name);
                    let cp: Checkpoint = rundir::read_checkpoint(&sdir)?
                        .ok_or_else(|| rundir::missing(&rundir::checkpoint_path(&sdir)))?;
                    let own: Vec<&GenStats> = cp.history.iter().filter(|h| h.stage == stage.name).collect();
                    // The last generation's columns of `generations.csv`.
                    let last = |f: fn(&GenStats) -> f64| own.last().map_or(f64::NAN, |l| f(l));
                    v[0].push(last(|l| l.best as f64));
                    v[1].push(shaping_runtime::evolve::best_of(&cp).map_or(f64::NAN, |(_, f)| f as f64));
                    v[2].push(last(|l| l.mean as f64));
                    v[3].push(own.iter().map(|h| h.best as f64).fold(f64::NAN, f64::max));
                    v[4].push(last(|l| l.worst as f64));
                    v[5].push(last(|l| l.best_recharges as f64));
                    v[6].push(last(|l| l.best_grips as f64));
                    v[7].push(last(|l| l.best_releases_outside as f64));
                    if let Some(c) = criterion {
                        let generations = own
                            .iter()
                            .find(|h| h.best >= c)
                            .map_or(f64::from(evo.generations) + 1.0, |h| h.stage_generation as f64 + 1.0);
                        v[8].push(generations);
                        v[9].push(earlier + generations * episodes(evo));
                    }
                }
                let measures = EVOLVE_MEASURES
                    .iter()
                    .zip(v)
                    .filter(|(_, values)| !values.is_empty())
                    .map(|(&m, values)| (m, values))
                    .collect();
                out.push(StageMeasures { stage: stage.name.clone(), kind: "evolve", measures });
            }
            StageRun::Test { .. } => {
                let mut v: [Vec<f64>; 3] = Default::default();
                for &seed in seeds {
                    let s = rundir::seed_test_summary(dir, seed, &stage.name, &|_| {})?;
                    for (k, x) in
                        [s.fitness, f64::from(s.grips), f64::from(s.releases_outside)].into_iter().enumerate()
                    {
                        v[k].push(x);
                    }
                }
                let measures = TEST_MEASURES.iter().copied().zip(v).collect();
                out.push(StageMeasures { stage: stage.name.clone(), kind: "test", measures });
            }
            StageRun::Train { .. } => {}
        }
    }
    Ok(out)
}

/// What [`Tests::method`] says: how the intervals are computed and, when
/// there are pairs, the tests.
fn method_words(groups: usize, holm: bool) -> String {
    let interval = format!(
        "median over seeds with its percentile bootstrap 95% interval ({} resamples, ChaCha8 seeded with {})",
        stats::BOOTSTRAP_RESAMPLES,
        stats::BOOTSTRAP_SEED,
    );
    if groups < 2 {
        return interval;
    }
    format!(
        "{interval}; two-sided Mann-Whitney U test, exact when neither sample has ties and one has at most 8 seeds, \
         else normal: the normal approximation with tie and continuity corrections (SciPy's `mannwhitneyu`, method `auto`); \
         Vargha-Delaney A12, the probability that a seed of the first group has the larger value (ties half), \
         small from 0.56 (or 0.44), medium from 0.64 (0.36), large from 0.71 (0.29){}",
        if holm { "; p-values Holm-corrected over the pairs of each measure" } else { "" }
    )
}

/// Compares `groups` (a name and its stages' measures, every group with the
/// same stages and measures): every measure's figures per group and the
/// test of every pair.
pub fn tests(groups: &[(String, Vec<StageMeasures>)]) -> Tests {
    let holm = groups.len() > 2;
    let mut measures = Vec::new();
    let Some((_, first)) = groups.first() else {
        return Tests { groups: Vec::new(), method: method_words(0, holm), holm, measures };
    };
    for (s, stage) in first.iter().enumerate() {
        for (m, (measure, _)) in stage.measures.iter().enumerate() {
            let values: Vec<&[f64]> = groups
                .iter()
                .map(|(_, g)| g.get(s).and_then(|st| st.measures.get(m)).map_or(&[][..], |x| &x.1[..]))
                .collect();
            let figures = values
                .iter()
                .map(|v| GroupFigures {
                    seeds: v.iter().filter(|x| x.is_finite()).count(),
                    median: stats::median(v),
                    interval: stats::median_ci(v),
                })
                .collect::<Vec<_>>();
            let mut pairs = Vec::new();
            for a in 0..values.len() {
                for b in a + 1..values.len() {
                    let few = [a, b].into_iter().find(|&g| figures[g].seeds < 2);
                    let test = if few.is_none() { stats::mann_whitney(values[a], values[b]) } else { None };
                    pairs.push(PairTest {
                        a: a + 1,
                        b: b + 1,
                        u: test.map(|t| t.u),
                        p_value: test.map(|t| t.p_value),
                        p_holm: None,
                        a12: test.and_then(|_| stats::a12(values[a], values[b])),
                        size: test.and_then(|_| stats::magnitude(values[a], values[b])),
                        method: test.map(|t| t.method),
                        no_test: few.map(|g| {
                            format!(
                                "`{}` has {} seed{} with a value; a test needs at least 2 seeds per side",
                                groups[g].0,
                                figures[g].seeds,
                                if figures[g].seeds == 1 { "" } else { "s" }
                            )
                        }),
                    });
                }
            }
            if holm {
                let p: Vec<f64> = pairs.iter().map(|p| p.p_value.unwrap_or(f64::NAN)).collect();
                for (pair, q) in pairs.iter_mut().zip(stats::holm(&p)) {
                    pair.p_holm = q.is_finite().then_some(q);
                }
            }
            measures.push(MeasureTests {
                stage: stage.stage.clone(),
                measure: measure.to_string(),
                groups: figures,
                pairs,
            });
        }
    }
    Tests {
        groups: groups.iter().map(|g| g.0.clone()).collect(),
        method: method_words(groups.len(), holm),
        holm,
        measures,
    }
}

/// The episodes a generation of `evo` runs: its population times the
/// episodes of each individual.
fn episodes(evo: &shaping_runtime::program::Evolution) -> f64 {
    f64::from(evo.population) * f64::from(evo.evaluations)
}

/// The evaluations (episodes) of the evolved stages stage `index` extends,
/// before its own: every generation of each (a training stage's life is
/// not counted).
fn earlier_evaluations(program: &Program, index: usize) -> f64 {
    program
        .lineage(index)
        .skip(1)
        .filter_map(|i| match &program.stages[i].run {
            StageRun::Evolve(e) => Some(f64::from(e.generations) * episodes(e)),
            _ => None,
        })
        .sum()
}

/// Digits a measure's values are shown with.
pub(crate) fn digits(measure: &str) -> usize {
    match measure {
        // A median of an even count may fall halfway.
        "generation_reaching_criterion" | "evaluations_reaching_criterion" => 1,
        "final_best_recharges" | "final_best_grips" | "final_best_releases_outside" => 1,
        "grips" | "releases_outside" => 1,
        _ => 3,
    }
}

pub(crate) fn p_text(p: f64) -> String {
    if p >= 0.001 {
        format!("{p:.4}")
    } else {
        format!("{p:.1e}")
    }
}

/// The comparison as Markdown under `heading`: one table, for each stage
/// and measure a row per group (its seeds, median and interval), then a row
/// per pair (U, p-value, A12, its size, the test's method).
pub fn markdown(t: &Tests, heading: &str) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "{heading}\n");
    let groups: Vec<String> = t.groups.iter().enumerate().map(|(i, g)| format!("{} `{g}`", i + 1)).collect();
    let _ = writeln!(md, "Groups: {}.\n", groups.join(", "));
    let _ = writeln!(md, "Figures: {}.\n", t.method);
    if t.measures.iter().any(|m| m.measure.ends_with("_reaching_criterion")) {
        let _ = writeln!(
            md,
            "A seed that never reaches a criterion counts as reaching it at the stage's generations plus one \
             (evaluations: the episodes of that many generations, the population times its episodes per \
             individual, plus every generation of the evolved stages it extends).\n"
        );
    }
    let mut head = vec!["stage", "measure", "group", "seeds", "median [95% interval]"];
    if t.groups.len() > 1 {
        head.extend(["pair", "U", "p-value"]);
        if t.holm {
            head.push("Holm p");
        }
        head.extend(["A12", "size", "test"]);
    }
    let _ = writeln!(md, "| {} |", head.join(" | "));
    let _ = writeln!(md, "|{}", "---|".repeat(head.len()));
    for m in &t.measures {
        let d = digits(&m.measure);
        let lead = [m.stage.clone(), m.measure.replace('_', " ")];
        for (i, g) in m.groups.iter().enumerate() {
            let median = match (g.median, g.interval) {
                (Some(x), Some(ci)) => format!("{x:.d$} [{:.d$}, {:.d$}]", ci.low, ci.high),
                _ => "-".to_string(),
            };
            let mut row: Vec<String> = lead.to_vec();
            row.extend([(i + 1).to_string(), g.seeds.to_string(), median]);
            row.resize(head.len(), String::new());
            let _ = writeln!(md, "| {} |", row.join(" | "));
        }
        for p in &m.pairs {
            let mut row: Vec<String> = lead.to_vec();
            row.extend([String::new(), String::new(), String::new(), format!("{} vs {}", p.a, p.b)]);
            match (p.u, p.p_value, p.a12, p.size, p.method) {
                (Some(u), Some(pv), Some(a12), Some(size), Some(method)) => {
                    row.extend([u.to_string(), p_text(pv)]);
                    if t.holm {
                        row.push(p.p_holm.map_or("-".to_string(), p_text));
                    }
                    row.extend([format!("{a12:.3}"), size.words().to_string(), method.words().to_string()]);
                }
                _ => {
                    row.resize(head.len() - 1, "-".to_string());
                    row.push(format!("no test: {}", p.no_test.as_deref().unwrap_or("no values")));
                }
            }
            let _ = writeln!(md, "| {} |", row.join(" | "));
        }
    }
    md
}

/// What `shaping compare` compares.
#[derive(Clone, Debug, Default)]
pub struct CompareOptions {
    /// Experiment directories (each with its `seed-N/` run directories).
    pub dirs: Vec<PathBuf>,
    /// `STAGE=FITNESS`: compare the generation reaching it.
    pub criterion: Vec<String>,
    /// Compare this stage only.
    pub stage: Option<String>,
}

/// The seeds of an experiment directory: its `seed-N/` directories, in order.
fn seeds_of(dir: &Path) -> Result<Vec<u64>, Error> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::of_io("read", dir, &e))?;
    let mut seeds: Vec<u64> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .filter_map(|e| e.file_name().to_str()?.strip_prefix("seed-")?.parse().ok())
        .collect();
    seeds.sort_unstable();
    Ok(seeds)
}

/// Why `dir` (without `seed-N/`) is no experiment's directory: a sweep's
/// names its points' directories, which are.
fn not_an_experiment(dir: &Path) -> String {
    let name = dir.display();
    let points: Vec<String> = rundir::read_experiment_summary(dir, &|_| {})
        .ok()
        .flatten()
        .map(|s| {
            let points = s.points.into_iter().map(|p| p.dir);
            points.filter(|p| p != ".").map(|p| format!("`{}`", dir.join(p).display())).collect()
        })
        .unwrap_or_default();
    if points.is_empty() {
        format!("error: `{name}` has no `seed-N` directory: it is not an experiment's directory")
    } else {
        format!("error: `{name}` is a sweep; compare its points' directories: {}", points.join(", "))
    }
}

/// The stages run in a seed's directory (those with a directory), in program order.
fn stages_run(program: &Program, seed_dir: &Path) -> Vec<usize> {
    (0..program.stages.len())
        .filter(|&i| rundir::stage_dir(seed_dir, &program.stages[i].name).is_dir())
        .collect()
}

/// `shaping compare`: the experiments in `opts.dirs` compared stage by
/// stage, measure by measure. Every directory must have run the same stages
/// (`opts.stage`: that one only) with at least 2 seeds, and every measure
/// must be in every directory's files.
pub fn compare(opts: &CompareOptions) -> Result<Tests, Error> {
    if opts.dirs.len() < 2 {
        return Err(Error::new(
            ErrorKind::Invalid,
            "error: `compare` needs at least two experiment directories",
        ));
    }
    let mut groups = Vec::new();
    let mut first: Option<(String, Vec<(String, &'static str)>)> = None;
    for dir in &opts.dirs {
        let name = dir.display().to_string();
        let seeds = seeds_of(dir)?;
        let Some(&seed) = seeds.first() else {
            return Err(Error::new(ErrorKind::Invalid, not_an_experiment(dir)));
        };
        if seeds.len() < 2 {
            return Err(Error::new(
                ErrorKind::Invalid,
                format!("error: no test: `{name}` has 1 seed (`seed-{seed}`); the Mann-Whitney test needs at least 2 seeds per side"),
            ));
        }
        let seed_dir = rundir::seed_dir(dir, seed);
        let program = load::load_built(&rundir::program_path(&seed_dir))?;
        let mut stages = stages_run(&program, &seed_dir);
        if let Some(only) = &opts.stage {
            let i = load::stage_index(&program, Some(only))
                .map_err(|e| Error::new(ErrorKind::Invalid, format!("{} (in `{name}`)", e.message())))?;
            if !stages.contains(&i) {
                return Err(Error::new(
                    ErrorKind::Invalid,
                    format!("error: `{name}` did not run stage `{only}`"),
                ));
            }
            stages = vec![i];
        }
        let criteria = criteria(&program, &opts.criterion)?;
        if let Some((c, _)) =
            criteria.iter().find(|(c, _)| !stages.iter().any(|&i| program.stages[i].name == *c))
        {
            return Err(Error::new(
                ErrorKind::Invalid,
                format!(
                    "error: `--criterion {c}=...`: `{name}` did not run stage `{c}` among those compared"
                ),
            ));
        }
        let kinds: Vec<(String, &'static str)> = stages
            .iter()
            .map(|&i| {
                let s = &program.stages[i];
                let kind = match s.run {
                    StageRun::Evolve(_) => "evolved",
                    StageRun::Test { .. } => "test",
                    StageRun::Train { .. } => "training",
                };
                (s.name.clone(), kind)
            })
            .collect();
        match &first {
            None => first = Some((name.clone(), kinds)),
            Some((first_name, first_kinds)) if *first_kinds != kinds => {
                let show = |k: &[(String, &str)]| {
                    k.iter().map(|(n, kind)| format!("`{n}` ({kind})")).collect::<Vec<_>>().join(", ")
                };
                return Err(Error::new(
                    ErrorKind::Invalid,
                    format!(
                        "error: `{first_name}` and `{name}` ran different stages: {} against {}; `--stage NAME` compares one stage both ran",
                        show(first_kinds),
                        show(&kinds)
                    ),
                ));
            }
            Some(_) => {}
        }
        let measures = read_measures(&program, &stages, dir, &seeds, &criteria)?;
        groups.push((name, measures));
    }
    check_measures(&groups)?;
    Ok(tests(&groups))
}

/// A measure that some directory has for none of its seeds, or for only
/// some of them, while another has it: an error naming it.
fn check_measures(groups: &[(String, Vec<StageMeasures>)]) -> Result<(), Error> {
    let Some((_, first)) = groups.first() else { return Ok(()) };
    for (s, stage) in first.iter().enumerate() {
        for (m, (measure, _)) in stage.measures.iter().enumerate() {
            let values = |g: &(String, Vec<StageMeasures>)| g.1[s].measures[m].1.clone();
            let anywhere = groups.iter().any(|g| values(g).iter().any(|x| x.is_finite()));
            if !anywhere {
                continue;
            }
            for g in groups {
                let v = values(g);
                let gaps = v.iter().filter(|x| !x.is_finite()).count();
                if gaps > 0 {
                    return Err(Error::new(
                        ErrorKind::Invalid,
                        format!(
                            "error: measure `{measure}` of stage `{}` is missing in `{}` ({gaps} of {} seeds), which other directories have",
                            stage.stage,
                            g.0,
                            v.len()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Parses `STAGE=VALUE` criteria (`navigation=0.7`).
pub(crate) fn criteria(program: &Program, args: &[String]) -> Result<Vec<(String, f32)>, Error> {
    args.iter()
        .map(|c| {
            let (stage, value) = c.split_once('=').ok_or_else(|| {
                Error::new(ErrorKind::Invalid, format!("error: criterion `{c}` is not of the form STAGE=FITNESS"))
            })?;
            load::stage_index(program, Some(stage))?;
            let v: f32 = value
                .parse()
                .map_err(|_| Error::new(ErrorKind::Invalid, format!("error: criterion `{c}`: `{value}` is not a number")))?;
            // `nan`, `inf` and numbers beyond f32 parse, but no fitness reaches them.
            if !v.is_finite() {
                return Err(Error::new(ErrorKind::Invalid, format!(
                    "error: criterion `{c}`: `{value}` is not a finite number (a fitness to reach, e.g. `{stage}=0.5`)"
                )));
            }
            Ok((stage.to_string(), v))
        })
        .collect()
}

#[cfg(test)]
mod tests;
