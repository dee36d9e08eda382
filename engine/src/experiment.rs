//! Experiments: the same architecture over several seeds (and the points
//! of a sweep), with the statistics the paper's figures are judged by
//! (median and range). The program is compiled once, by the caller; each
//! task (a point's seed) is a run of it with the point's settings.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use shaping_runtime::evolve::{Checkpoint, GenStats};
use shaping_runtime::program::{Program, StageRun};

use crate::error::{Error, ErrorKind};
use crate::files::DirLock;
use crate::load;
use crate::rundir::{self, StageFigures};
use crate::rundir::{spread, Spread};
use crate::sweep::{self, Assignment, Set};
use crate::{compare, plot, report, run};

/// What an experiment runs.
#[derive(Clone, Debug, Default)]
pub struct ExperimentOptions {
    /// The architecture file (its stem titles the summaries).
    pub file: PathBuf,
    pub seeds: u64,
    pub first_seed: u64,
    pub out: Option<PathBuf>,
    pub jobs: Option<usize>,
    pub criterion: Vec<String>,
    /// `--set`: the sweep's settings (one point without any).
    pub sets: Vec<Set>,
    /// Run only this stage and the stages it needs.
    pub stage: Option<String>,
    pub fresh: bool,
    /// Write no `report.html` at the end.
    pub no_report: bool,
}

fn fmt_spread(s: Option<Spread>, digits: usize) -> String {
    match s {
        Some(s) => format!(
            "{:.d$} ({:.d$} .. {:.d$}; mean {:.d$} ± {:.d$})",
            s.median,
            s.min,
            s.max,
            s.mean,
            s.sd,
            d = digits
        ),
        None => "-".into(),
    }
}

/// What an experiment runs, checked before anything runs (on every rank
/// of an MPI run alike): the program, the criteria, the seeds and the points
/// of the sweep, each point's program validated.
pub struct Plan {
    args: ExperimentOptions,
    program: Program,
    criteria: Vec<(String, f32)>,
    seeds: Vec<u64>,
    points: Vec<Vec<Assignment>>,
    /// The stages run (and summarised), in program order.
    stages: Vec<usize>,
    out: PathBuf,
}

/// One task of an experiment: a point of the sweep (its index) and a seed.
pub type Task = (u32, u64);

impl Plan {
    /// Checks `args` against `program` (the file's, compiled once).
    pub fn new(program: Program, args: ExperimentOptions) -> Result<Plan, Error> {
        let criteria = compare::criteria(&program, &args.criterion)?;
        if args.seeds == 0 {
            return Err(Error::new(ErrorKind::Invalid, "error: `--seeds` must be at least 1"));
        }
        if args.seeds > MAX_SEEDS {
            return Err(Error::new(
                ErrorKind::Invalid,
                format!("error: `--seeds {}` is more than the limit of {MAX_SEEDS}", args.seeds),
            ));
        }
        let end = args.first_seed.checked_add(args.seeds).ok_or_else(|| {
            Error::new(
                ErrorKind::Invalid,
                format!(
                    "error: `--first-seed {}` plus `--seeds {}` is past the largest seed",
                    args.first_seed, args.seeds
                ),
            )
        })?;
        sweep::check_sets(&args.sets)?;
        let points = sweep::points(&args.sets);
        if points.len() > MAX_POINTS {
            return Err(Error::new(
                ErrorKind::Invalid,
                format!("error: the sweep has {} points, more than the limit of {MAX_POINTS}", points.len()),
            ));
        }
        for point in &points {
            sweep::apply(&mut program.clone(), point)?;
        }
        let stages = match args.stage.as_deref() {
            Some(name) => run::chain(&program, load::stage_index(&program, Some(name))?),
            None => (0..program.stages.len()).collect(),
        };
        if let Some((stage, _)) =
            criteria.iter().find(|(c, _)| !stages.iter().any(|&i| program.stages[i].name == *c))
        {
            return Err(Error::new(
                ErrorKind::Invalid,
                format!(
                    "error: `--criterion {stage}=...`: stage `{stage}` is not run with `--stage {}`",
                    args.stage.as_deref().unwrap_or_default()
                ),
            ));
        }
        let out = args.out.clone().unwrap_or_else(|| rundir::experiment_dir(&run::default_out(&args.file)));
        Ok(Plan { seeds: (args.first_seed..end).collect(), args, program, criteria, points, stages, out })
    }

    /// Every (point, seed), point after point.
    pub fn tasks(&self) -> Vec<Task> {
        (0..self.points.len() as u32).flat_map(|p| self.seeds.iter().map(move |&s| (p, s))).collect()
    }

    /// The directory of a point: the experiment's without `--set`.
    fn point_dir(&self, point: usize) -> PathBuf {
        if self.args.sets.is_empty() {
            self.out.clone()
        } else {
            self.out.join(sweep::point_dir_name(&self.points[point], &self.args.sets))
        }
    }

    /// The experiment's directory.
    pub fn out(&self) -> &Path {
        &self.out
    }

    /// Locks the experiment's directory (created if missing) for this
    /// process while it runs: a second experiment into it is refused.
    pub fn lock(&self) -> Result<DirLock, Error> {
        DirLock::acquire(&self.out)
    }

    /// Runs one seed of one point, as `shaping run` with the point's `--set`
    /// values would (the same files, byte for byte), with `jobs` threads
    /// (the runner's evaluator, if it has one, evaluates instead).
    pub fn run_task(
        &self,
        (point, seed): Task,
        jobs: Option<usize>,
        runner: &crate::Engine<'_>,
    ) -> Result<run::RunOutcome, Error> {
        let assignments = self.points.get(point as usize).ok_or_else(|| {
            Error::new(
                ErrorKind::Invalid,
                format!("error: point {point} of a sweep of {} points", self.points.len()),
            )
        })?;
        let opts = run::RunOptions {
            stage: self.args.stage.clone(),
            seed: Some(seed),
            out: rundir::seed_dir(&self.point_dir(point as usize), seed),
            jobs,
            fresh: self.args.fresh,
            // One report per point, written at the end.
            no_report: true,
            sets: assignments.clone(),
        };
        // A seed's (or a point's) directory is the experiment's own: a link
        // planted there is refused, not followed.
        for dir in [self.point_dir(point as usize), opts.out.clone()] {
            if dir != self.out {
                rundir::create_stage_dir(&dir)?;
            }
        }
        runner.run_file(self.program.clone(), &self.args.file, &opts)
    }

    /// Names a task in progress lines: `seed 3` or `seed 3 of mutation=0.01`.
    pub fn describe(&self, (point, seed): Task) -> String {
        match self.points.get(point as usize) {
            Some(p) if !p.is_empty() => format!("seed {seed} of {}", sweep::point_name(p)),
            _ => format!("seed {seed}"),
        }
    }

    /// The summaries (`summary.md`, `summary.json`), the pictures and the
    /// reports, from the files the tasks wrote.
    pub fn finish(&self) -> Result<Finished, Error> {
        let mut finished = Finished { out: self.out.clone(), ..Finished::default() };
        let unsealed = std::cell::RefCell::new(Vec::new());
        let u = |p: &Path| unsealed.borrow_mut().push(p.to_path_buf());
        let program = &self.program;
        // Titled by the file: several files may share a robot (and so a program name).
        let title = self
            .args
            .file
            .file_stem()
            .map_or_else(|| program.name.clone(), |s| s.to_string_lossy().into_owned());
        let mut points = Vec::new();
        let mut table = Vec::new();
        let mut groups = Vec::new();
        for (i, point) in self.points.iter().enumerate() {
            let dir = self.point_dir(i);
            let name = sweep::point_name(point);
            let heading = if point.is_empty() { title.clone() } else { format!("{title}, {name},") };
            // The point's program: the values that ran, not the file's.
            let mut ran = program.clone();
            sweep::apply(&mut ran, point)?;
            let (mut md, stages) =
                summarise(&ran, &self.stages, &heading, &dir, &self.seeds, &self.criteria, &u)?;
            groups.push((
                if point.is_empty() { title.clone() } else { name.clone() },
                compare::read_measures(&ran, &self.stages, &dir, &self.seeds, &self.criteria)?,
            ));
            if self.args.sets.is_empty() {
                // One point: its medians' intervals (a sweep's tests are in its table).
                md.push('\n');
                md.push_str(&compare::markdown(
                    &compare::tests(&groups),
                    "## Medians with their 95% intervals",
                ));
            }
            rundir::write_summary_md(&dir, &md)?;
            if self.args.sets.is_empty() {
                finished.summary.push_str(&md);
            }
            let settings = point.iter().map(|(t, v)| (t.clone(), v.clone())).collect();
            let dir_name = if point.is_empty() {
                ".".to_string()
            } else {
                sweep::point_dir_name(point, &self.args.sets)
            };
            table.push((point.clone(), stages.clone()));
            points.push(rundir::PointSummary { name, dir: dir_name, settings, stages });
        }
        let sets = self
            .args
            .sets
            .iter()
            .map(|s| rundir::SweepSet { target: s.target.clone(), values: s.values.clone() })
            .collect();
        // The tests between points (a point's median and interval alone
        // without a sweep), after the figures that were there before them.
        let tests = compare::tests(&groups);
        let summary =
            rundir::ExperimentSummary { file: title.clone(), seeds: self.seeds.clone(), sets, points, tests };
        rundir::write_experiment_summary(&self.out, &summary)?;
        if !self.args.sets.is_empty() {
            let mut md = sweep_table(&title, &self.args.sets, &self.seeds, &table);
            md.push('\n');
            md.push_str(&compare::markdown(&summary.tests, "## Tests between points"));
            rundir::write_summary_md(&self.out, &md)?;
            finished.summary.push_str(&md);
            sweep_plot(&rundir::picture_path(&self.out, rundir::Picture::Sweep), &title, &table)?;
        }
        if !self.args.no_report {
            // After `summary.json`: a point's report lists the sweep's points.
            for i in 0..self.points.len() {
                finished.reports.push(crate::html::write_with(&self.point_dir(i), None, &u)?);
            }
            if !self.args.sets.is_empty() {
                finished.reports.push(crate::html::write_with(&self.out, None, &u)?);
            }
        }
        finished.unsealed = unsealed.take();
        finished.unsealed.sort();
        finished.unsealed.dedup();
        Ok(finished)
    }
}

/// What an experiment's end wrote: the summary to show (the `summary.md`
/// of its point, or the sweep's table) and the reports; and the files it
/// read without a seal (written before seals), for a warning
/// ([`crate::files::unsealed_warning`]).
#[derive(Clone, Debug, Default)]
pub struct Finished {
    /// The experiment's directory.
    pub out: PathBuf,
    pub summary: String,
    pub reports: Vec<PathBuf>,
    pub unsealed: Vec<PathBuf>,
}

/// Most seeds an experiment runs.
pub const MAX_SEEDS: u64 = 10_000;

/// Most points a sweep runs.
const MAX_POINTS: usize = 10_000;

/// `sweep.svg`/`.png`: each evolved stage's chosen best per point.
fn sweep_plot(stem: &Path, title: &str, table: &[(Vec<Assignment>, Vec<StageFigures>)]) -> Result<(), Error> {
    let Some((_, first)) = table.first() else { return Ok(()) };
    let series: Vec<plot::SweepSeries> = first
        .iter()
        .enumerate()
        .filter(|(_, s)| matches!(s, StageFigures::Evolve { .. }))
        .map(|(k, s)| plot::SweepSeries {
            stage: s.stage().to_string(),
            values: table
                .iter()
                .map(|(_, stages)| {
                    let Some(StageFigures::Evolve { chosen_best: Some(c), .. }) = stages.get(k) else {
                        return None;
                    };
                    let finite = [c.median, c.min, c.max].iter().all(|x| x.is_finite());
                    finite.then_some((c.median, c.min, c.max))
                })
                .collect(),
        })
        .collect();
    if series.is_empty() {
        return Ok(());
    }
    // The values that vary from point to point name them.
    let value = |point: &[Assignment], t: &str| point.iter().find(|(u, _)| u == t).map(|(_, v)| v.clone());
    let varies = |t: &str| table.iter().any(|(p, _)| value(p, t) != value(&table[0].0, t));
    let labels: Vec<String> = table
        .iter()
        .map(|(point, _)| {
            let shown: Vec<&str> = point.iter().filter(|(t, _)| varies(t)).map(|(_, v)| v.as_str()).collect();
            shown.join(", ")
        })
        .collect();
    let targets: Vec<&str> = table[0].0.iter().map(|(t, _)| t.as_str()).filter(|t| varies(t)).collect();
    let axis = format!("{} (the rows of summary.md)", targets.join(", "));
    plot::sweep_points(
        stem,
        &format!("{title}: chosen best per point over the seeds"),
        &series,
        (&axis, &labels),
    )
    .map_err(Error::from)
}

/// The sweep's `summary.md`: one row per point, the median (min .. max)
/// over seeds of each evolved stage's final best, chosen best and the
/// generation reaching its criterion.
fn sweep_table(
    title: &str,
    sets: &[Set],
    seeds: &[u64],
    table: &[(Vec<Assignment>, Vec<StageFigures>)],
) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# {title}: a sweep of {} points over {} seeds ({:?})\n",
        table.len(),
        seeds.len(),
        seeds
    );
    let _ =
        writeln!(md, "Median (min .. max; mean ± standard deviation) over seeds; each point's own `summary.md` is in its directory.\n");
    let mut head: Vec<String> = vec!["point".to_string()];
    head.extend(sets.iter().map(|s| format!("`{}`", s.target)));
    let evolved: Vec<(String, bool)> = table.first().map_or_else(Vec::new, |(_, stages)| {
        stages
            .iter()
            .filter_map(|s| match s {
                StageFigures::Evolve { stage, criterion, .. } => Some((stage.clone(), criterion.is_some())),
                _ => None,
            })
            .collect()
    });
    for (stage, criterion) in &evolved {
        head.push(format!("{stage} final best"));
        head.push(format!("{stage} chosen best"));
        if *criterion {
            head.push(format!("{stage} generation reaching criterion"));
        }
    }
    // Test stages: the fitness after the change (mean per life).
    let tests: Vec<String> = table.first().map_or_else(Vec::new, |(_, stages)| {
        stages
            .iter()
            .filter(|s| matches!(s, StageFigures::Test { .. }))
            .map(|s| s.stage().to_string())
            .collect()
    });
    for stage in &tests {
        head.push(format!("{stage} test fitness"));
    }
    let _ = writeln!(md, "| {} |", head.join(" | "));
    let _ = writeln!(md, "|{}", "---|".repeat(head.len()));
    // A figure that is not a number (written `null`) leaves its cell empty.
    let cell = |v: &Option<Spread>, digits: usize| match v {
        Some(s) if [s.median, s.min, s.max, s.mean, s.sd].iter().all(|x| x.is_finite()) => {
            fmt_spread(Some(*s), digits)
        }
        _ => "-".to_string(),
    };
    for (i, (point, stages)) in table.iter().enumerate() {
        let mut row: Vec<String> = vec![(i + 1).to_string()];
        row.extend(point.iter().map(|(_, v)| v.clone()));
        for s in stages {
            let StageFigures::Evolve { final_best, chosen_best, criterion, .. } = s else { continue };
            row.push(cell(final_best, 3));
            row.push(cell(chosen_best, 3));
            if let Some(c) = criterion {
                let never = c.unreached;
                row.push(format!(
                    "{}{}",
                    cell(&c.generation, 0),
                    if never > 0 { format!("; {never} seeds never") } else { String::new() }
                ));
            }
        }
        for s in stages {
            if let StageFigures::Test { fitness, .. } = s {
                row.push(cell(fitness, 3));
            }
        }
        let _ = writeln!(md, "| {} |", row.join(" | "));
    }
    let _ =
        writeln!(md, "\nPicture: `sweep.svg` / `sweep.png` (each evolved stage's chosen best per point).");
    md
}

/// Builds the Markdown summary and the multi-seed fitness picture.
/// Returns the Markdown and, per stage, its figures (`summary.json`).
fn summarise(
    program: &Program,
    stages: &[usize],
    title: &str,
    out: &Path,
    seeds: &[u64],
    criteria: &[(String, f32)],
    unsealed: crate::files::Unsealed<'_>,
) -> Result<(String, Vec<StageFigures>), Error> {
    let mut json = Vec::new();
    let mut md = String::new();
    let _ = writeln!(md, "# {title} over {} seeds ({:?})\n", seeds.len(), seeds);
    let _ = writeln!(md, "Median (min .. max; mean ± standard deviation) over seeds.\n");
    let _ = writeln!(
        md,
        "| stage | generations | final best | chosen best | final mean | best ever | generation reaching criterion |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    let mut histories: Vec<Vec<GenStats>> = vec![Vec::new(); seeds.len()];
    for stage in stages.iter().map(|&i| &program.stages[i]) {
        let (figures, row) = match &stage.run {
            StageRun::Evolve(evo) => {
                let criterion = criteria.iter().find(|(s, _)| *s == stage.name).map(|c| c.1);
                evolved_figures(stage, evo, out, seeds, criterion, unsealed, &mut histories)?
            }
            StageRun::Train { actions } => trained_figures(stage, *actions, out, seeds, unsealed)?,
            StageRun::Test { actions, lives, learning } => {
                tested_figures(stage, (*actions, *lives, *learning), out, seeds, unsealed)?
            }
        };
        json.push(figures);
        md.push_str(&row);
    }
    let runs: Vec<Vec<plot::GenPoint>> = histories.iter().map(|h| report::fitness_points(h).0).collect();
    if let Some(first) = histories.iter().filter(|h| !h.is_empty()).max_by_key(|h| h.len()) {
        let starts = report::fitness_points(first).1;
        plot::multi_seed_fitness(
            &rundir::picture_path(out, rundir::Picture::FitnessSeeds),
            &format!("{}: fitness over {} seeds (median, min-max)", title.trim_end_matches(','), seeds.len()),
            &runs,
            &starts,
        )
        .map_err(Error::from)?;
    }
    let _ = writeln!(
        md,
        "\nPicture: `fitness-seeds.svg` / `fitness-seeds.png` (median best and mean, min-max band)."
    );
    Ok((md, json))
}

/// An evolved stage's figures over the seeds (its row of `summary.md` and
/// its `summary.json` part); each seed's history kept in `histories` if
/// it is the longest so far (the deepest evolved stage's).
fn evolved_figures(
    stage: &shaping_runtime::program::Stage,
    evo: &shaping_runtime::program::Evolution,
    out: &Path,
    seeds: &[u64],
    criterion: Option<f32>,
    unsealed: crate::files::Unsealed<'_>,
    histories: &mut [Vec<GenStats>],
) -> Result<(StageFigures, String), Error> {
    let mut md = String::new();
    let mut chosen = Vec::new();
    let mut best = Vec::new();
    let mut mean = Vec::new();
    let mut ever = Vec::new();
    let mut reach = Vec::new();
    let mut unreached = 0;
    for &seed in seeds {
        let dir = rundir::stage_dir(&rundir::seed_dir(out, seed), &stage.name);
        let cp: Checkpoint = rundir::read_checkpoint_with(&dir, unsealed)?
            .ok_or_else(|| rundir::missing(&rundir::checkpoint_path(&dir)))?;
        let own: Vec<&GenStats> = cp.history.iter().filter(|h| h.stage == stage.name).collect();
        if let Some(last) = own.last() {
            best.push(last.best as f64);
            mean.push(last.mean as f64);
        }
        if let Some((_, f)) = shaping_runtime::evolve::best_of(&cp) {
            chosen.push(f as f64);
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
    let figures = StageFigures::Evolve {
        stage: stage.name.clone(),
        generations: evo.generations,
        final_best: spread(&best),
        chosen_best: spread(&chosen),
        final_mean: spread(&mean),
        best_ever: spread(&ever),
        criterion: criterion.map(|c| rundir::CriterionFigures {
            fitness: f64::from(c),
            generation: spread(&reach),
            unreached,
        }),
    };
    let _ = writeln!(
        md,
        "| {} | {} | {} | {} | {} | {} | {} |",
        stage.name,
        evo.generations,
        fmt_spread(spread(&best), 3),
        fmt_spread(spread(&chosen), 3),
        fmt_spread(spread(&mean), 3),
        fmt_spread(spread(&ever), 3),
        reach_text
    );
    Ok((figures, md))
}

/// A training stage's figures over the seeds: its learning modules' performance.
fn trained_figures(
    stage: &shaping_runtime::program::Stage,
    actions: u32,
    out: &Path,
    seeds: &[u64],
    unsealed: crate::files::Unsealed<'_>,
) -> Result<(StageFigures, String), Error> {
    let mut md = String::new();
    let mut perf = Vec::new();
    for &seed in seeds {
        let dir = rundir::stage_dir(&rundir::seed_dir(out, seed), &stage.name);
        let t = rundir::read_trained_with(&dir, unsealed)?
            .ok_or_else(|| rundir::missing(&rundir::trained_path(&dir)))?;
        let learners = stage.modules.iter().zip(&t.performance).filter(|(m, _)| m.learning.is_some());
        perf.extend(learners.map(|(_, p)| *p as f64));
    }
    let figures = StageFigures::Train { stage: stage.name.clone(), actions, performance: spread(&perf) };
    let _ = writeln!(
        md,
        "| {} | training, {actions} actions | performance at the end {} | - | - | - | - |",
        stage.name,
        fmt_spread(spread(&perf), 2),
    );
    Ok((figures, md))
}

/// A test stage's figures over the seeds: its fitness and events.
fn tested_figures(
    stage: &shaping_runtime::program::Stage,
    (actions, lives, learning): (u32, u32, bool),
    out: &Path,
    seeds: &[u64],
    unsealed: crate::files::Unsealed<'_>,
) -> Result<(StageFigures, String), Error> {
    let mut md = String::new();
    let mut fit = Vec::new();
    let mut grips = Vec::new();
    let mut rel = Vec::new();
    for &seed in seeds {
        let v = rundir::seed_test_summary(out, seed, &stage.name, unsealed)?;
        fit.push(v.fitness);
        grips.push(f64::from(v.grips));
        rel.push(f64::from(v.releases_outside));
    }
    let figures = StageFigures::Test {
        stage: stage.name.clone(),
        actions,
        lives,
        learning,
        fitness: spread(&fit),
        grips: spread(&grips),
        releases_outside: spread(&rel),
    };
    let length = match lives {
        1 => format!("{actions} actions"),
        _ => {
            format!("{lives} lives of {actions} actions (fitness: mean per life; events: totals)")
        }
    };
    let _ = writeln!(
        md,
        "| {} | test, {length}, learning {} | fitness {} | - | grips {} | released outside {} | - |",
        stage.name,
        if learning { "on" } else { "off" },
        fmt_spread(spread(&fit), 3),
        fmt_spread(spread(&grips), 1),
        fmt_spread(spread(&rel), 1),
    );
    Ok((figures, md))
}
