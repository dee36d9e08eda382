//! The files of a run directory, each read and written in one place with
//! one format:
//!
//! ```text
//! DIR/program.json            the compiled program (with any --set applied)
//! DIR/source.json             the name of the file it was compiled from
//! DIR/report.html
//! DIR/.lock                   held while a run writes (files::DirLock)
//! DIR/STAGE/checkpoint.json   evolved stages: resumable, with a checksum
//! DIR/STAGE/best.genome       evolved and test stages: the chosen best
//! DIR/STAGE/generations.csv   evolved stages
//! DIR/STAGE/trained.json      training stages: the learned weights, with a checksum
//! DIR/STAGE/summary.json      test stages
//! DIR/STAGE/episode.json, trace.csv, *.svg, *.png
//! DIR/STAGE/.seals            the checksums of the files above that a
//!                             report or a resume reads (files::write_sealed)
//! ```
//!
//! An experiment's directory holds `seed-N/` run directories (under a
//! sweep, `POINT/seed-N/`), and `summary.md`, `summary.json` (sealed in its
//! `.seals`). A stage directory is a directory, never a link to one.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::Serialize;
use shaping_runtime::evolve::{self, Checkpoint, Trained};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::Program;

use crate::episode::Episode;
use crate::error::{Error, ErrorKind, Result, Subject};
use crate::files::{read_bytes, read_checked, seal, unseal, write_atomic, write_sealed, Sealed, Unsealed};

mod generations;
mod summary;

pub use generations::{generations_csv, parse_generations, GenRow, Generations};

pub use summary::{
    nan_if_null, spread, CriterionFigures, DriveSummary, ExperimentSummary, GroupFigures, MeasureTests,
    PairTest, PointSummary, ReinforcementCounts, ReinforcementMeans, Signals, Spread, StageFigures, SweepSet,
    TestSummary, Tests, VariantLives, WorldTotals, SUMMARY_FORMAT,
};

/// The names of the files of a run, experiment, sweep, replay and drive
/// directory: here and nowhere else (the paths below join them; others
/// name them in messages).
pub mod names {
    pub const PROGRAM: &str = "program.json";
    pub const SOURCE: &str = "source.json";
    pub const REPORT: &str = "report.html";
    pub const CHECKPOINT: &str = "checkpoint.json";
    pub const TRAINED: &str = "trained.json";
    pub const BEST_GENOME: &str = "best.genome";
    pub const GENERATIONS: &str = "generations.csv";
    pub const SUMMARY: &str = "summary.json";
    pub const SUMMARY_MD: &str = "summary.md";
    pub const EPISODE: &str = "episode.json";
    pub const TRACE: &str = "trace.csv";
    /// A team's other robots' columns, beside its `episode.json`.
    pub const ROBOTS: &str = "robots.json";
    /// A replay's (and a drive's) genome, beside its `program.json`.
    pub const GENOME: &str = "genome";
    /// The default directories of a replay and a drive in a stage's.
    pub const REPLAY: &str = "replay";
    pub const DRIVE: &str = "drive";
    /// An experiment's directory beside a file's default run directory.
    pub const EXPERIMENT: &str = "experiment";
}
use names::*;

/// A stage's directory in run directory `out`.
pub fn stage_dir(out: &Path, stage: &str) -> PathBuf {
    out.join(stage)
}

/// Creates a stage's directory `dir` (or an experiment's seed or point
/// directory): a link planted there is refused, not followed, as the links
/// at temporary names are ([`crate::files::write_atomic`]).
pub fn create_stage_dir(dir: &Path) -> Result<()> {
    if let Ok(meta) = std::fs::symlink_metadata(dir) {
        if meta.file_type().is_symlink() {
            return Err(Error::invalid_setting(
                "--out",
                Some(&dir.display().to_string()),
                format!(
                    "error: `{}` is a symbolic link; a run writes only into directories of its own, never through \
                     a link: remove it, or choose another `--out`",
                    dir.display()
                ),
            ));
        }
    }
    crate::files::create_dir(dir)
}

/// The files only a run writes into its directories: one of them in a
/// directory makes it a run's (or a stage's, an experiment's).
const RUN_FILES: &[&str] =
    &[CHECKPOINT, TRAINED, GENERATIONS, BEST_GENOME, SUMMARY, crate::files::DirLock::FILE];

/// A stage directory holds results of a run (not only a replay's): one of
/// the files a stage's run writes.
pub fn holds_results(dir: &Path) -> bool {
    [CHECKPOINT, TRAINED, BEST_GENOME, SUMMARY, EPISODE].iter().any(|f| dir.join(f).exists())
}

/// Refuses a replay's output directory `out` that is a run's: a stage
/// directory (a replay would replace its `episode.json` and `trace.csv`), a
/// run directory (its `program.json`) or an experiment's; and a link. A
/// replay's own directory (its `genome` beside `program.json`), a new one
/// or any other is fine.
pub fn check_replay_out(out: &Path) -> Result<()> {
    check_output_dir(out, "a replay", "replay")
}

/// [`check_replay_out`] for any command that writes an episode's files
/// (`who`: "a replay", "`drive`"), by default into `STAGE/{sub}` of the run.
pub fn check_output_dir(out: &Path, who: &str, sub: &str) -> Result<()> {
    let refuse = |what: String| {
        Error::invalid_setting(
            "--out",
            Some(&out.display().to_string()),
            format!(
                "error: `{}` is {what}; {who} never writes into a run's directories: choose another `--out` \
                 (by default {who} writes into `STAGE/{sub}` of the run)",
                out.display()
            ),
        )
    };
    // A stage's directory, made or not yet.
    let run = out.parent().filter(|p| program_path(p).exists());
    let name = out.file_name().map(|n| n.to_string_lossy().into_owned());
    if let (Some(run), Some(name)) = (run, name) {
        let program = crate::load::load_built(&program_path(run));
        if program.is_ok_and(|p| p.stage(&name).is_some()) {
            return Err(refuse(format!("the directory of stage `{name}` of the run in `{}`", run.display())));
        }
    }
    let Ok(meta) = std::fs::symlink_metadata(out) else { return Ok(()) };
    if meta.file_type().is_symlink() {
        return Err(refuse("a symbolic link".into()));
    }
    if !meta.is_dir() {
        return Ok(());
    }
    let replay = genome_file_path(out).exists() && episode_path(out).exists();
    if program_path(out).exists() && !replay {
        return Err(refuse("a run directory (it holds `program.json`)".into()));
    }
    // A drive's or a replay's own directory holds a `summary.json` too.
    let own = |f: &&&str| replay && **f == SUMMARY;
    if let Some(file) = RUN_FILES.iter().filter(|f| !own(f)).find(|f| out.join(f).exists()) {
        return Err(refuse(format!("a directory of a run (it holds `{file}`)")));
    }
    Ok(())
}

/// `STAGE/checkpoint.json`.
pub fn checkpoint_path(dir: &Path) -> PathBuf {
    dir.join(CHECKPOINT)
}

/// `STAGE/trained.json`.
pub fn trained_path(dir: &Path) -> PathBuf {
    dir.join(TRAINED)
}

/// `STAGE/best.genome`.
pub fn best_genome_path(dir: &Path) -> PathBuf {
    dir.join(BEST_GENOME)
}

/// `STAGE/generations.csv`.
pub fn generations_path(dir: &Path) -> PathBuf {
    dir.join(GENERATIONS)
}

/// `summary.json`: a test stage's (`STAGE/`), an experiment's or a sweep
/// point's, a sweep's, a drive's.
pub fn summary_path(dir: &Path) -> PathBuf {
    dir.join(SUMMARY)
}

/// `summary.md` of an experiment, a sweep point or a sweep.
pub fn summary_md_path(dir: &Path) -> PathBuf {
    dir.join(SUMMARY_MD)
}

/// `episode.json` of a stage, a replay or a drive.
pub fn episode_path(dir: &Path) -> PathBuf {
    dir.join(EPISODE)
}

/// `robots.json` of a team's stage or replay.
pub fn robots_path(dir: &Path) -> PathBuf {
    dir.join(ROBOTS)
}

/// `trace.csv` of a stage, a replay or a drive.
pub fn trace_path(dir: &Path) -> PathBuf {
    dir.join(TRACE)
}

/// `genome` of a replay's or a drive's directory.
pub fn genome_file_path(dir: &Path) -> PathBuf {
    dir.join(GENOME)
}

/// `report.html` of any directory a report is written for.
pub fn report_path(dir: &Path) -> PathBuf {
    dir.join(REPORT)
}

/// The pictures of a directory, each written as `NAME.svg` and `NAME.png`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    /// An evolved stage's fitness per generation.
    Fitness,
    /// An episode's module activations.
    Activations,
    /// An episode's reinforcement of learning modules.
    Reinforcement,
    /// An episode's path over its world.
    Trajectory,
    /// An experiment's (or a sweep point's) fitness over its seeds.
    FitnessSeeds,
    /// A sweep's figures per point.
    Sweep,
}

/// A picture's path without its extension (see [`Picture`]).
pub fn picture_path(dir: &Path, picture: Picture) -> PathBuf {
    dir.join(match picture {
        Picture::Fitness => "fitness",
        Picture::Activations => "activations",
        Picture::Reinforcement => "reinforcement",
        Picture::Trajectory => "trajectory",
        Picture::FitnessSeeds => "fitness-seeds",
        Picture::Sweep => "sweep",
    })
}

/// The default directory of a replay of `stage` of run `run`.
pub fn replay_dir(run: &Path, stage: &str) -> PathBuf {
    stage_dir(run, stage).join(REPLAY)
}

/// The default directory of a drive of `stage` of run `run`.
pub fn drive_dir(run: &Path, stage: &str) -> PathBuf {
    stage_dir(run, stage).join(DRIVE)
}

/// The default directory of an experiment beside run directory `run`.
pub fn experiment_dir(run: &Path) -> PathBuf {
    run.join(EXPERIMENT)
}

/// The run directory of seed `seed` in an experiment's (or a sweep point's)
/// directory.
pub fn seed_dir(dir: &Path, seed: u64) -> PathBuf {
    dir.join(format!("seed-{seed}"))
}

/// Serialises to pretty JSON.
pub fn to_json<T: Serialize>(value: &T) -> Result<String> {
    serde_json::to_string_pretty(value).map_err(|e| Error::internal(format!("error: cannot serialise: {e}")))
}

/// Serialises to compact JSON.
pub fn compact_json<T: Serialize>(value: &T) -> Result<String> {
    serde_json::to_string(value).map_err(|e| Error::internal(format!("error: cannot serialise: {e}")))
}

/// Reads a saved result that carries a checksum ([`seal`]) and is sealed
/// in its directory ([`read_checked`]): `Ok(None)` if there is no file. A
/// file without its checksum is read only when its directory has no seal
/// for it either (written before checksums), and `unsealed` is told; one
/// that its seal lists is checked by it.
fn read_sealed<T: DeserializeOwned>(
    path: &Path,
    what: &str,
    advice: &str,
    unsealed: Unsealed<'_>,
) -> Result<Option<T>> {
    let Some(file) = read_checked(path, advice, &|_| {})? else { return Ok(None) };
    let legacy = if file.sealed { Legacy::Sealed } else { Legacy::Accept(unsealed) };
    parse_sealed(&file.bytes, path, what, advice, legacy).map(Some)
}

/// What [`parse_sealed`] does with a file without its checksum.
enum Legacy<'a> {
    /// Its directory's seal matched it: it is what the run wrote.
    Sealed,
    /// Nothing sealed it: read, and the caller told.
    Accept(Unsealed<'a>),
    /// Refused (bytes of unknown origin: the fuzzer's).
    Refuse,
}

/// A saved result from its bytes: its checksum verified, then parsed;
/// `path` and `what` name the file in errors, `advice` says what to do
/// with a damaged one.
fn parse_sealed<T: DeserializeOwned>(
    bytes: &[u8],
    path: &Path,
    what: &str,
    advice: &str,
    legacy: Legacy<'_>,
) -> Result<T> {
    let name = path.display();
    let corrupt = |why: String| {
        let message = format!("error: {what} `{name}` is corrupt ({why}); {advice}");
        Error::damaged(path, why, message)
    };
    let text = std::str::from_utf8(bytes).map_err(|e| corrupt(format!("not UTF-8: {e}")))?;
    let body = match unseal(text) {
        Sealed::Verified(body) => std::borrow::Cow::Owned(body),
        Sealed::Unsealed(body) => match legacy {
            Legacy::Sealed => std::borrow::Cow::Borrowed(body),
            Legacy::Accept(unsealed) => {
                unsealed(path);
                std::borrow::Cow::Borrowed(body)
            }
            Legacy::Refuse => {
                return Err(corrupt(
                    "it has no checksum: it was removed, or the file was not written by a run".into(),
                ))
            }
        },
        Sealed::Damaged => {
            return Err(corrupt(
                "its checksum does not match its contents: it was changed after it was written".into(),
            ))
        }
    };
    serde_json::from_str(&body).map_err(|e| corrupt(e.to_string()))
}

const CHECKPOINT_WORDS: (&str, &str) =
    ("the checkpoint", "move it away or pass `--fresh` to start the stage again");
const TRAINED_WORDS: (&str, &str) = ("the trained weights", "delete it or pass `--fresh`");

/// A stage's checkpoint, if there is one (a damaged one is an error); one
/// written before checksums is read without a word (see
/// [`read_checkpoint_with`]).
pub fn read_checkpoint(dir: &Path) -> Result<Option<Checkpoint>> {
    read_checkpoint_with(dir, &|_| {})
}

/// [`read_checkpoint`], telling `unsealed` of a checkpoint written before
/// checksums (no checksum and no seal), for a warning.
pub fn read_checkpoint_with(dir: &Path, unsealed: Unsealed<'_>) -> Result<Option<Checkpoint>> {
    read_sealed(&checkpoint_path(dir), CHECKPOINT_WORDS.0, CHECKPOINT_WORDS.1, unsealed)
}

/// A checkpoint from the bytes of a `checkpoint.json` (`name` names it in
/// errors; one without its checksum is refused); whether it fits a program
/// is [`evolve::resume`]'s to say.
pub fn parse_checkpoint(bytes: &[u8], name: &str) -> Result<Checkpoint> {
    parse_sealed(bytes, Path::new(name), CHECKPOINT_WORDS.0, CHECKPOINT_WORDS.1, Legacy::Refuse)
}

/// Trained weights from the bytes of a `trained.json` (`name` names it in
/// errors; one without its checksum is refused); whether they fit a
/// program is [`evolve::train::check`]'s to say.
pub fn parse_trained(bytes: &[u8], name: &str) -> Result<Trained> {
    parse_sealed(bytes, Path::new(name), TRAINED_WORDS.0, TRAINED_WORDS.1, Legacy::Refuse)
}

/// The bytes of a stage's checkpoint as written: sealed ([`seal`]).
pub fn checkpoint_bytes(cp: &Checkpoint) -> Result<Vec<u8>> {
    Ok(seal(&to_json(cp)?).into_bytes())
}

/// Writes a stage's checkpoint, sealed.
pub fn write_checkpoint(dir: &Path, cp: &Checkpoint) -> Result<()> {
    write_sealed(dir, &[(CHECKPOINT, &checkpoint_bytes(cp)?)])
}

/// A training stage's learned weights, if saved (a damaged file is an
/// error; see [`read_checkpoint`]).
pub fn read_trained(dir: &Path) -> Result<Option<Trained>> {
    read_trained_with(dir, &|_| {})
}

/// [`read_trained`], telling `unsealed` of a file written before checksums.
pub fn read_trained_with(dir: &Path, unsealed: Unsealed<'_>) -> Result<Option<Trained>> {
    read_sealed(&trained_path(dir), TRAINED_WORDS.0, TRAINED_WORDS.1, unsealed)
}

/// The bytes of `trained.json`: sealed.
pub fn trained_bytes(trained: &Trained) -> Result<Vec<u8>> {
    Ok(seal(&to_json(trained)?).into_bytes())
}

/// Writes a training stage's learned weights, sealed.
pub fn write_trained(dir: &Path, trained: &Trained) -> Result<()> {
    write_sealed(dir, &[(TRAINED, &trained_bytes(trained)?)])
}

/// The bytes of a genome file.
pub fn genome_bytes(genome: &Genome) -> Vec<u8> {
    format!("{}\n", genome.to_bitstring()).into_bytes()
}

/// Writes `best.genome`, sealed.
pub fn write_best_genome(dir: &Path, genome: &Genome) -> Result<()> {
    write_sealed(dir, &[(BEST_GENOME, &genome_bytes(genome))])
}

/// Writes an evolved stage's checkpoint and its `generations.csv` (of its
/// history), sealed together: after each generation.
pub fn write_generation(dir: &Path, cp: &Checkpoint, variants: &[String]) -> Result<()> {
    let csv = generations_csv(&cp.history, variants);
    write_sealed(dir, &[(CHECKPOINT, &checkpoint_bytes(cp)?), (GENERATIONS, csv.as_bytes())])
}

/// Writes an evolved stage's chosen best (`best.genome`) and its
/// `generations.csv`, sealed together: at the stage's end.
pub fn write_evolved(dir: &Path, genome: &Genome, cp: &Checkpoint, variants: &[String]) -> Result<()> {
    let csv = generations_csv(&cp.history, variants);
    write_sealed(dir, &[(BEST_GENOME, &genome_bytes(genome)), (GENERATIONS, csv.as_bytes())])
}

/// Writes `episode.json`, sealed (compact JSON).
pub fn write_episode(dir: &Path, episode: &Episode) -> Result<()> {
    write_sealed(dir, &[(EPISODE, compact_json(episode)?.as_bytes())])
}

/// Writes a training stage's `episode.json` and `trained.json`, sealed together.
pub fn write_trained_episode(dir: &Path, episode: &Episode, trained: &Trained) -> Result<()> {
    write_sealed(dir, &[(EPISODE, compact_json(episode)?.as_bytes()), (TRAINED, &trained_bytes(trained)?)])
}

/// Writes a replay's `genome`, sealed.
pub fn write_genome_file(dir: &Path, genome: &Genome) -> Result<()> {
    write_sealed(dir, &[(GENOME, &genome_bytes(genome))])
}

/// Writes a drive's `episode.json` and `genome`, sealed together.
pub fn write_driven(dir: &Path, episode: &Episode, genome: &Genome) -> Result<()> {
    write_sealed(dir, &[(EPISODE, compact_json(episode)?.as_bytes()), (GENOME, &genome_bytes(genome))])
}

/// Writes a team's `robots.json`, sealed.
pub fn write_robots(dir: &Path, robots: &crate::episode::TeamColumns) -> Result<()> {
    write_sealed(dir, &[(ROBOTS, compact_json(robots)?.as_bytes())])
}

/// Removes a `robots.json` from `dir`, if there is one.
pub fn remove_robots(dir: &Path) -> Result<()> {
    match std::fs::remove_file(robots_path(dir)) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(Error::of_io("remove", &robots_path(dir), &e))
        }
        _ => Ok(()),
    }
}

/// Reads a team's `robots.json` (`None` where there is none: one robot,
/// or a run made before it was written); one that does not read, or is of
/// another format, is an error naming it.
pub fn read_robots(dir: &Path, u: Unsealed<'_>) -> Result<Option<crate::episode::TeamColumns>> {
    let path = robots_path(dir);
    let Some(f) = read_checked(&path, REWRITE, u)? else { return Ok(None) };
    let t: crate::episode::TeamColumns = serde_json::from_slice(&f.bytes).map_err(|e| {
        let problem = format!("not a team's columns written by shaping: {e}");
        Error::damaged(&path, &problem, format!("error: `{}` is {problem}", path.display()))
    })?;
    if t.format != crate::episode::ROBOTS_FORMAT {
        return Err(Error::damaged(
            &path,
            format!("format {}", t.format),
            format!(
                "error: `{}` has format {}, this shaping reads format {}; replay the stage again",
                path.display(),
                t.format,
                crate::episode::ROBOTS_FORMAT
            ),
        ));
    }
    Ok(Some(t))
}

/// Writes `trace.csv` (not sealed: a drive writes it as the robot drives).
pub fn write_trace(dir: &Path, csv: &str) -> Result<()> {
    write_atomic(&trace_path(dir), csv.as_bytes())
}

/// A summary's bytes: through a `serde_json::Value`, whose sorted maps give
/// the keys the order the files have always had (see [`summary`]).
fn summary_text<T: Serialize>(summary: &T) -> Result<String> {
    let value = serde_json::to_value(summary)
        .map_err(|e| Error::internal(format!("error: cannot serialise a summary: {e}")))?;
    to_json(&value)
}

/// A summary from the bytes of `path`, checked against its seal (`None`:
/// no file): one whose `"format"` is newer than [`SUMMARY_FORMAT`] is
/// refused naming the version; a damaged or missing key is an error
/// naming the file and the key (`what` says which summary it should be).
fn read_summary<T: DeserializeOwned>(path: &Path, what: &str, unsealed: Unsealed<'_>) -> Result<Option<T>> {
    let Some(file) = read_checked(path, REWRITE, unsealed)? else { return Ok(None) };
    let bad =
        |why: String| Error::damaged(path, &why, format!("error: `{}` is not {what}: {why}", path.display()));
    let value: serde_json::Value = serde_json::from_slice(&file.bytes).map_err(|e| bad(e.to_string()))?;
    if !value.is_object() {
        return Err(bad("it is not a JSON object".into()));
    }
    match value.get("format").map(|f| f.as_u64()) {
        None => {}
        Some(Some(n)) if n <= u64::from(SUMMARY_FORMAT) => {}
        Some(Some(n)) => {
            return Err(Error::damaged(
                path,
                format!("summary format {n}"),
                format!(
                    "error: `{}` has summary format {n}, this shaping reads format {SUMMARY_FORMAT} and before;                      a newer shaping wrote it",
                    path.display()
                ),
            ))
        }
        Some(None) => return Err(bad("`format` is not a whole number".into())),
    }
    serde_json::from_value(value).map(Some).map_err(|e| bad(e.to_string()))
}

/// Writes a test stage's `summary.json`, sealed.
pub fn write_test_summary(dir: &Path, summary: &TestSummary) -> Result<()> {
    write_sealed(dir, &[(SUMMARY, summary_text(summary)?.as_bytes())])
}

/// A test stage's `summary.json` (`None`: the stage has not run); one
/// with `lives` 0 is refused.
pub fn read_test_summary(dir: &Path, unsealed: Unsealed<'_>) -> Result<Option<TestSummary>> {
    let path = summary_path(dir);
    let summary: Option<TestSummary> = read_summary(&path, "a test stage's summary", unsealed)?;
    if summary.as_ref().is_some_and(|s| s.lives == 0) {
        return Err(Error::damaged(
            &path,
            "`lives` is not a whole number of 1 or more",
            format!(
                "error: `{}` is not a test stage's summary: `lives` is not a whole number of 1 or more",
                path.display()
            ),
        ));
    }
    Ok(summary)
}

/// Writes an experiment's (or a sweep's) `summary.json`, sealed.
pub fn write_experiment_summary(dir: &Path, summary: &ExperimentSummary) -> Result<()> {
    write_sealed(dir, &[(SUMMARY, format!("{}\n", summary_text(summary)?).as_bytes())])
}

/// An experiment's (or a sweep's) `summary.json` in `dir` (`None`: none).
pub fn read_experiment_summary(dir: &Path, unsealed: Unsealed<'_>) -> Result<Option<ExperimentSummary>> {
    read_summary(&summary_path(dir), "an experiment's summary", unsealed)
}

/// Writes a drive's `summary.json`, sealed.
pub fn write_drive_summary(dir: &Path, summary: &DriveSummary) -> Result<()> {
    write_sealed(dir, &[(SUMMARY, summary_text(summary)?.as_bytes())])
}

/// A drive's `summary.json` in `dir` (`None`: none).
pub fn read_drive_summary(dir: &Path, unsealed: Unsealed<'_>) -> Result<Option<DriveSummary>> {
    read_summary(&summary_path(dir), "a drive's summary", unsealed)
}

/// A stage's `generations.csv` (`None`: the stage has not run; a damaged
/// file is an error naming it, the line and the column).
pub fn read_generations(dir: &Path, unsealed: Unsealed<'_>) -> Result<Option<Generations>> {
    let path = generations_path(dir);
    let Some(file) = read_checked(&path, REWRITE, unsealed)? else { return Ok(None) };
    let text = String::from_utf8(file.bytes).map_err(|_| {
        Error::damaged(&path, "not UTF-8 text", format!("error: `{}` is not UTF-8 text", path.display()))
    })?;
    parse_generations(&text, &path).map(Some)
}

/// Writes `summary.md` of an experiment, a sweep point or a sweep.
pub fn write_summary_md(dir: &Path, md: &str) -> Result<()> {
    write_atomic(&summary_md_path(dir), md.as_bytes())
}

/// What to do with a damaged file a run derived (a genome, statistics, an
/// episode, a summary).
pub const REWRITE: &str = "run the same command again to write it anew";

/// A stage's `best.genome` as the run wrote it (`None`: no file), checked
/// against its seal ([`read_checked`]); one without a seal is read, and
/// `unsealed` told.
pub fn read_best_genome(dir: &Path, unsealed: Unsealed<'_>) -> Result<Option<Genome>> {
    read_sealed_genome(&best_genome_path(dir), unsealed)
}

/// A genome file of a run, a replay or a drive (`best.genome`, `genome`)
/// as it was written (`None`: no file), checked against its seal as
/// [`read_best_genome`] does.
pub fn read_sealed_genome(path: &Path, unsealed: Unsealed<'_>) -> Result<Option<Genome>> {
    let Some(file) = read_checked(path, REWRITE, unsealed)? else { return Ok(None) };
    parse_genome(&file.bytes, path).map(Some)
}

/// Reads a genome file (`best.genome`): a string of 0 and 1; any other
/// character is refused naming its line and column.
pub fn read_genome(path: &Path) -> Result<Genome> {
    parse_genome(&read_bytes(path)?, path)
}

/// A genome from the bytes of file `path` (see [`read_genome`]).
fn parse_genome(bytes: &[u8], path: &Path) -> Result<Genome> {
    let text = String::from_utf8_lossy(bytes);
    Genome::parse_bitstring(&text).map_err(|(position, c)| {
        let before: String = text.chars().take(position - 1).collect();
        let line = before.matches('\n').count() + 1;
        let column = before.chars().rev().take_while(|&c| c != '\n').count() + 1;
        let problem = format!("line {line}, column {column} is `{}`", c.escape_debug());
        Error::damaged(
            path,
            &problem,
            format!(
                "error: `{}` does not hold a genome: {problem}; a genome is a string of 0 and 1",
                path.display()
            ),
        )
    })
}

/// The best individual of an evolved stage's directory: `best.genome`,
/// which must be the checkpoint's best where a checkpoint is beside it (a
/// hand-edited or damaged `best.genome` is refused, naming it).
pub fn read_best(dir: &Path) -> Result<Genome> {
    let genome = match read_best_genome(dir, &|_| {})? {
        Some(genome) => genome,
        None => read_genome(&best_genome_path(dir))?,
    };
    if let Some(cp) = read_checkpoint(dir)? {
        check_best(dir, &genome, &cp)?;
    }
    Ok(genome)
}

/// `genome`, read from `dir`'s `best.genome`, must be the best of `cp`,
/// the checkpoint beside it.
pub fn check_best(dir: &Path, genome: &Genome, cp: &Checkpoint) -> Result<()> {
    match evolve::best_of(cp) {
        Some((best, _)) if best != *genome => Err(Error::damaged(
            &best_genome_path(dir),
            "not the best individual of the checkpoint beside it",
            format!(
                "error: `{}` is not the best individual of the checkpoint beside it (`{}`): it was changed \
                 after the run wrote it; delete it and run the same command again to write it anew",
                best_genome_path(dir).display(),
                checkpoint_path(dir).display()
            ),
        )),
        _ => Ok(()),
    }
}

/// The chosen best of evolved stage `index` of `program` from its directory
/// `dir` in a run: its checkpoint must be there and fit the program as it
/// is (the fingerprint of the stage and all it extends), and `best.genome`,
/// where present, must be the checkpoint's best. Returns the checkpoint and
/// the best with its fitness.
pub fn checked_best(program: &Program, index: usize, dir: &Path) -> Result<(Checkpoint, Genome, f32)> {
    checked_best_with(program, index, dir, &|_| {})
}

/// [`checked_best`], telling `unsealed` of files read without a seal.
pub fn checked_best_with(
    program: &Program,
    index: usize,
    dir: &Path,
    unsealed: Unsealed<'_>,
) -> Result<(Checkpoint, Genome, f32)> {
    let path = checkpoint_path(dir);
    let cp = read_checkpoint_with(dir, unsealed)?.ok_or_else(|| {
        let message = format!("error: there is no checkpoint `{}`: run the stage first", path.display());
        Error::new(ErrorKind::NotFound, message)
            .about(Subject::File { path: path.clone(), operation: "read".into() })
    })?;
    evolve::check_resume_of(program, index, &cp).map_err(|e| {
        Error::stale(
            &path,
            e.to_string(),
            format!(
                "error: the best individual in `{}` is not of this program: {e}; run the file again (`shaping run` with `--fresh`)",
                dir.display()
            ),
        )
    })?;
    let (genome, fitness) = evolve::best_of(&cp).ok_or_else(|| {
        Error::damaged(
            &path,
            "no evaluated individual",
            format!("error: `{}` holds no evaluated individual", path.display()),
        )
    })?;
    let best = best_genome_path(dir);
    if best.exists() {
        // The checkpoint's best (which says what changed), then the bytes
        // the run wrote.
        check_best(dir, &read_genome(&best)?, &cp)?;
        read_best_genome(dir, &|_| {})?;
    }
    Ok((cp, genome, fitness))
}

/// `program.json` of a run directory (the program as it ran).
pub fn program_path(out: &Path) -> PathBuf {
    out.join(PROGRAM)
}

/// Writes `program.json`.
pub fn write_program(out: &Path, program: &Program) -> Result<()> {
    write_atomic(&program_path(out), compact_json(program)?.as_bytes())
}

/// The program of a run directory as its `program.json` describes it, if
/// one is there and reads (a run's own file; one that does not read names
/// no program to compare with).
pub fn read_program(out: &Path) -> Option<Program> {
    let bytes = std::fs::read(program_path(out)).ok()?;
    crate::load::parse_built(&bytes, PROGRAM).ok()
}

/// `source.json` of a run directory: the name of the file (`khepera.bat`)
/// its program was compiled from, the program the directory belongs to.
pub fn source_path(out: &Path) -> PathBuf {
    out.join(SOURCE)
}

/// The contents of `source.json`.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Source {
    /// [`SOURCE_FORMAT`].
    pub format: u32,
    /// The file's name, without its directory.
    pub file: String,
}

/// The format of `source.json`.
pub const SOURCE_FORMAT: u32 = 1;

/// The file a run directory's program was compiled from, if `source.json`
/// says (none for a run of a built program, or through the library).
pub fn read_source(out: &Path) -> Option<String> {
    let bytes = std::fs::read(source_path(out)).ok()?;
    let source: Source = serde_json::from_slice(&bytes).ok()?;
    (source.format == SOURCE_FORMAT).then_some(source.file)
}

/// Writes `source.json` (`None`: removes it, the program's file being unknown).
pub fn write_source(out: &Path, file: Option<&str>) -> Result<()> {
    match file {
        Some(file) => {
            let source = Source { format: SOURCE_FORMAT, file: file.to_string() };
            write_atomic(&source_path(out), to_json(&source)?.as_bytes())
        }
        None => match std::fs::remove_file(source_path(out)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(Error::of_io("remove", &source_path(out), &e))
            }
            _ => Ok(()),
        },
    }
}

/// The `summary.json` of test stage `stage` of seed `seed` of experiment
/// (or point) directory `out`, which the seed's run must have written.
pub fn seed_test_summary(out: &Path, seed: u64, stage: &str, unsealed: Unsealed<'_>) -> Result<TestSummary> {
    let dir = stage_dir(&seed_dir(out, seed), stage);
    read_test_summary(&dir, unsealed)?.ok_or_else(|| missing(&summary_path(&dir)))
}

/// A file that a seed's run must have written.
pub fn missing(path: &Path) -> Error {
    Error::file(ErrorKind::NotFound, "read", path, "the seed's run did not write it")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_summary_of_a_newer_format_or_with_a_key_missing_is_refused_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = summary_path(dir.path());
        std::fs::write(&path, r#"{"format": 2, "file": "x"}"#).unwrap();
        let err = read_experiment_summary(dir.path(), &|_| {}).unwrap_err();
        assert!(
            err.message().contains("summary format 2") && err.message().contains("summary.json"),
            "{err}"
        );
        std::fs::write(&path, r#"{"file": "x", "seeds": [1]}"#).unwrap();
        let err = read_experiment_summary(dir.path(), &|_| {}).unwrap_err();
        assert!(
            err.message().contains("missing field `sets`") && err.message().contains("summary.json"),
            "{err}"
        );
    }

    #[test]
    fn a_checkpoint_changed_by_one_digit_is_refused_as_corrupt() {
        let dir = tempfile::tempdir().unwrap();
        let trained = Trained {
            stage: "practice".into(),
            fingerprint: Vec::new(),
            run_seed: 3,
            weights: Vec::new(),
            activation: Vec::new(),
            performance: vec![0.25],
            result: Default::default(),
        };
        write_trained(dir.path(), &trained).unwrap();
        assert_eq!(read_trained(dir.path()).unwrap().unwrap(), trained);
        let path = trained_path(dir.path());
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, text.replace("0.25", "0.35")).unwrap();
        let err = read_trained(dir.path()).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::Corrupt);
        assert!(err.message().contains("checksum does not match"), "{err}");
        // Its checksum removed (or its key misspelt) and a digit changed:
        // its seal in `.seals` still refuses it.
        let unsealed = text.replace("0.25", "0.35");
        let at = unsealed.rfind(",\n  \"checksum\"").unwrap();
        for bare in [format!("{}\n}}", &unsealed[..at]), unsealed.replace("\"checksum\"", "\"checksun\"")] {
            std::fs::write(&path, &bare).unwrap();
            let err = read_trained(dir.path()).unwrap_err();
            assert_eq!(err.kind(), ErrorKind::Corrupt, "{bare}");
            assert!(err.message().contains("trained.json"), "{err}");
        }
        // A file written before checksums (and seals) existed is read, and
        // the caller told, for a warning.
        std::fs::remove_file(dir.path().join(crate::files::SEALS)).unwrap();
        std::fs::write(&path, to_json(&trained).unwrap()).unwrap();
        let told = std::cell::Cell::new(0);
        let read = read_trained_with(dir.path(), &|p| {
            assert_eq!(p, path);
            told.set(told.get() + 1);
        });
        assert_eq!(read.unwrap().unwrap(), trained);
        assert_eq!(told.get(), 1);
        // The same bytes from nowhere (the fuzzer's) are refused.
        let err = parse_trained(to_json(&trained).unwrap().as_bytes(), "t.json").unwrap_err();
        assert_eq!(err.kind(), ErrorKind::Corrupt);
        assert!(err.message().contains("no checksum"), "{err}");
    }
}
