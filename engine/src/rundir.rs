//! The files of a run directory, each read and written in one place with
//! one format:
//!
//! ```text
//! DIR/program.json            the compiled program (with any --set applied)
//! DIR/report.html
//! DIR/.lock                   held while a run writes (files::DirLock)
//! DIR/STAGE/checkpoint.json   evolved stages: resumable, with a checksum
//! DIR/STAGE/best.genome       evolved and test stages: the chosen best
//! DIR/STAGE/generations.csv   evolved stages
//! DIR/STAGE/trained.json      training stages: the learned weights, with a checksum
//! DIR/STAGE/summary.json      test stages
//! DIR/STAGE/episode.json, trace.csv, *.svg, *.png
//! ```
//!
//! An experiment's directory holds `seed-N/` run directories (under a
//! sweep, `POINT/seed-N/`), and `summary.md`, `summary.json`.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::Serialize;
use shaping_runtime::evolve::{self, Checkpoint, Trained};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::Program;

use crate::error::{Error, ErrorKind, Result};
use crate::files::{read_bytes, seal, unseal, write_atomic, Sealed};

/// A stage's directory in run directory `out`.
pub fn stage_dir(out: &Path, stage: &str) -> PathBuf {
    out.join(stage)
}

/// `STAGE/checkpoint.json`.
pub fn checkpoint_path(dir: &Path) -> PathBuf {
    dir.join("checkpoint.json")
}

/// `STAGE/trained.json`.
pub fn trained_path(dir: &Path) -> PathBuf {
    dir.join("trained.json")
}

/// `STAGE/best.genome`.
pub fn best_genome_path(dir: &Path) -> PathBuf {
    dir.join("best.genome")
}

/// The run directory of seed `seed` in an experiment's (or a sweep point's)
/// directory.
pub fn seed_dir(dir: &Path, seed: u64) -> PathBuf {
    dir.join(format!("seed-{seed}"))
}

/// Serialises to pretty JSON.
pub fn to_json<T: Serialize>(value: &T) -> Result<String> {
    serde_json::to_string_pretty(value).map_err(|e| Error::io(format!("error: cannot serialise: {e}")))
}

/// Serialises to compact JSON.
pub fn compact_json<T: Serialize>(value: &T) -> Result<String> {
    serde_json::to_string(value).map_err(|e| Error::io(format!("error: cannot serialise: {e}")))
}

/// Reads a saved result that carries a checksum ([`seal`]): `Ok(None)` if
/// there is no file.
fn read_sealed<T: DeserializeOwned>(path: &Path, what: &str, advice: &str) -> Result<Option<T>> {
    if !path.exists() {
        return Ok(None);
    }
    parse_sealed(&read_bytes(path)?, &path.display().to_string(), what, advice).map(Some)
}

/// A saved result from its bytes: its checksum verified (a file without
/// one is read as it is), then parsed; `name` and `what` name the file in
/// errors, `advice` says what to do with a damaged one.
fn parse_sealed<T: DeserializeOwned>(bytes: &[u8], name: &str, what: &str, advice: &str) -> Result<T> {
    let corrupt = |why: String| {
        Error::new(ErrorKind::Corrupt, format!("error: {what} `{name}` is corrupt ({why}); {advice}"))
    };
    let text = std::str::from_utf8(bytes).map_err(|e| corrupt(format!("not UTF-8: {e}")))?;
    let body = match unseal(text) {
        Sealed::Verified(body) => std::borrow::Cow::Owned(body),
        Sealed::Unsealed(body) => std::borrow::Cow::Borrowed(body),
        Sealed::Damaged => {
            return Err(corrupt(
                "its checksum does not match its contents: it was changed after it was written".into(),
            ))
        }
    };
    serde_json::from_str(&body).map_err(|e| corrupt(e.to_string()))
}

const CHECKPOINT: (&str, &str) =
    ("the checkpoint", "move it away or pass `--fresh` to start the stage again");
const TRAINED: (&str, &str) = ("the trained weights", "delete it or pass `--fresh`");

/// A stage's checkpoint, if there is one (a damaged one is an error).
pub fn read_checkpoint(dir: &Path) -> Result<Option<Checkpoint>> {
    read_sealed(&checkpoint_path(dir), CHECKPOINT.0, CHECKPOINT.1)
}

/// A checkpoint from the bytes of a `checkpoint.json` (`name` names it in
/// errors); whether it fits a program is [`evolve::resume`]'s to say.
pub fn parse_checkpoint(bytes: &[u8], name: &str) -> Result<Checkpoint> {
    parse_sealed(bytes, name, CHECKPOINT.0, CHECKPOINT.1)
}

/// Trained weights from the bytes of a `trained.json` (`name` names it in
/// errors); whether they fit a program is [`evolve::train::check`]'s to say.
pub fn parse_trained(bytes: &[u8], name: &str) -> Result<Trained> {
    parse_sealed(bytes, name, TRAINED.0, TRAINED.1)
}

/// Writes a stage's checkpoint, sealed.
pub fn write_checkpoint(dir: &Path, cp: &Checkpoint) -> Result<()> {
    write_atomic(&checkpoint_path(dir), seal(&to_json(cp)?).as_bytes())
}

/// A training stage's learned weights, if saved (a damaged file is an error).
pub fn read_trained(dir: &Path) -> Result<Option<Trained>> {
    read_sealed(&trained_path(dir), TRAINED.0, TRAINED.1)
}

/// Writes a training stage's learned weights, sealed.
pub fn write_trained(dir: &Path, trained: &Trained) -> Result<()> {
    write_atomic(&trained_path(dir), seal(&to_json(trained)?).as_bytes())
}

/// Writes `best.genome`.
pub fn write_best_genome(dir: &Path, genome: &Genome) -> Result<()> {
    write_atomic(&best_genome_path(dir), format!("{}\n", genome.to_bitstring()).as_bytes())
}

/// Reads a genome file (`best.genome`): a string of 0 and 1; any other
/// character is refused naming its line and column.
pub fn read_genome(path: &Path) -> Result<Genome> {
    let bytes = read_bytes(path)?;
    let text = String::from_utf8_lossy(&bytes);
    Genome::parse_bitstring(&text).map_err(|(position, c)| {
        let before: String = text.chars().take(position - 1).collect();
        let line = before.matches('\n').count() + 1;
        let column = before.chars().rev().take_while(|&c| c != '\n').count() + 1;
        Error::new(
            ErrorKind::Corrupt,
            format!(
                "error: `{}` does not hold a genome: line {line}, column {column} is `{}`; a genome is a string of 0 and 1",
                path.display(),
                c.escape_debug()
            ),
        )
    })
}

/// The best individual of an evolved stage's directory: `best.genome`,
/// which must be the checkpoint's best where a checkpoint is beside it (a
/// hand-edited or damaged `best.genome` is refused, naming it).
pub fn read_best(dir: &Path) -> Result<Genome> {
    let genome = read_genome(&best_genome_path(dir))?;
    if let Some(cp) = read_checkpoint(dir)? {
        check_best(dir, &genome, &cp)?;
    }
    Ok(genome)
}

/// `genome`, read from `dir`'s `best.genome`, must be the best of `cp`,
/// the checkpoint beside it.
pub fn check_best(dir: &Path, genome: &Genome, cp: &Checkpoint) -> Result<()> {
    match evolve::best_of(cp) {
        Some((best, _)) if best != *genome => Err(Error::new(
            ErrorKind::Corrupt,
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
    let path = checkpoint_path(dir);
    let cp = read_checkpoint(dir)?.ok_or_else(|| {
        Error::new(
            ErrorKind::Io,
            format!("error: there is no checkpoint `{}`: run the stage first", path.display()),
        )
    })?;
    evolve::check_resume_of(program, index, &cp).map_err(|e| {
        Error::new(
            ErrorKind::Stale,
            format!(
                "error: the best individual in `{}` is not of this program: {e}; run the file again (`shaping run` with `--fresh`)",
                dir.display()
            ),
        )
    })?;
    let (genome, fitness) = evolve::best_of(&cp).ok_or_else(|| {
        Error::new(ErrorKind::Corrupt, format!("error: `{}` holds no evaluated individual", path.display()))
    })?;
    let best = best_genome_path(dir);
    if best.exists() {
        check_best(dir, &read_genome(&best)?, &cp)?;
    }
    Ok((cp, genome, fitness))
}

/// `program.json` of a run directory (the program as it ran).
pub fn program_path(out: &Path) -> PathBuf {
    out.join("program.json")
}

/// Writes `program.json`.
pub fn write_program(out: &Path, program: &Program) -> Result<()> {
    write_atomic(&program_path(out), compact_json(program)?.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

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
        // A file written before checksums existed reads as before.
        std::fs::write(&path, to_json(&trained).unwrap()).unwrap();
        assert_eq!(read_trained(dir.path()).unwrap().unwrap(), trained);
    }
}
