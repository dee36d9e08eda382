//! `shaping replay`: runs one individual with a trace and writes the pictures.

use std::path::{Path, PathBuf};

use shaping_runtime::controller::EpisodeOptions;
use shaping_runtime::evolve;
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Program, StageRun};
use shaping_runtime::sim::Sim;

use crate::load::{self, create_dir, write_atomic, CliError};
use crate::out::outln;
use crate::{episode, html, report, run};

pub struct ReplayArgs {
    pub file: PathBuf,
    pub stage: Option<String>,
    pub genome: Option<String>,
    pub run: Option<PathBuf>,
    pub actions: Option<u32>,
    pub out: Option<PathBuf>,
    pub seed: Option<u64>,
    pub no_learning: bool,
    /// Also write `report.html` for the episode.
    pub report: bool,
    pub error_format: crate::diag::ErrorFormat,
}

/// Reads `--genome`: an argument made only of `0`, `1`, `_` and blanks is
/// the genome itself; anything else is the path of a file holding one. A
/// string of digits that is not a genome (`2101`) is refused as such, not
/// looked for as a file.
pub(crate) fn parse_genome(arg: &str) -> Result<Genome, CliError> {
    let (position, c) = match Genome::parse_bitstring(arg) {
        Ok(g) => return Ok(g),
        Err(bad) => bad,
    };
    let blank = |c: char| c == '_' || c.is_whitespace();
    if arg.chars().all(|c| c.is_ascii_digit() || blank(c)) {
        return Err(CliError::io(format!(
            "error: `--genome {arg}` is not a genome: character {position} is `{c}`; a genome is a string of 0 and 1 (or the path of a file holding one)"
        )));
    }
    let path = Path::new(arg);
    if !path.is_file() {
        return Err(CliError::io(format!(
            "error: `--genome {arg}` is neither a string of 0 and 1 (character {position} is `{c}`) nor a file"
        )));
    }
    read_genome(path)
}

/// Reads a genome file (`best.genome`): a string of 0 and 1; any other
/// character is refused naming its line and column.
pub(crate) fn read_genome(path: &Path) -> Result<Genome, CliError> {
    let bytes = load::read_bytes(path)?;
    let text = String::from_utf8_lossy(&bytes);
    Genome::parse_bitstring(&text).map_err(|(position, c)| {
        let before: String = text.chars().take(position - 1).collect();
        let line = before.matches('\n').count() + 1;
        let column = before.chars().rev().take_while(|&c| c != '\n').count() + 1;
        CliError::io(format!(
            "error: `{}` does not hold a genome: line {line}, column {column} is `{}`; a genome is a string of 0 and 1",
            path.display(),
            c.escape_debug()
        ))
    })
}

/// What `replay` and `drive` run: the program with the weights of every
/// training stage bound (the one way every command binds them), the stage,
/// the individual, and for a training stage, its run seed.
pub(crate) struct Chosen {
    pub program: Program,
    pub index: usize,
    pub genome: Genome,
    /// The run seed of the training stage's life, when `index` is one.
    pub training_seed: Option<u64>,
}

/// Loads `file`, binds the training stages from run directory `run` (default
/// `runs/<file stem>`) and picks the individual: `--genome`, else the best
/// of the stage (or of the evolved stage it tests) in the run directory.
/// A training stage has no individual: its life is what there is to see.
pub(crate) fn choose(
    file: &Path,
    stage: Option<&str>,
    genome: Option<&str>,
    run: Option<&Path>,
    error_format: crate::diag::ErrorFormat,
) -> Result<Chosen, CliError> {
    let mut program = load::load_program(file, error_format)?;
    let index = load::stage_index(&program, stage)?;
    let run_dir = run.map_or_else(|| run::default_out(file), Path::to_path_buf);
    let seed = run::run_seed(&program, None);
    let trained = run::bind_training(&mut program, Some(&run_dir), seed)?;
    let stage = &program.stages[index];
    let training_seed = trained.iter().find(|(i, _)| *i == index).map(|(_, t)| t.run_seed);
    let genome = match genome {
        Some(g) => parse_genome(g)?,
        None if training_seed.is_some() => Genome::zeros(0),
        // Nothing is evolved: the empty genome is the only individual.
        None if stage.layout.bits == 0 && run.is_none() => Genome::zeros(0),
        None => {
            let source = evolved_source(&program, index);
            let dir = run_dir.join(&program.stages[source].name);
            let path = dir.join("best.genome");
            if !path.exists() {
                return Err(CliError::io(format!(
                    "error: no evolved individual at `{}`; run `shaping run {}{}` first, or pass `--genome`",
                    path.display(),
                    file.display(),
                    run.map_or_else(String::new, |d| format!(" --out {}", d.display()))
                )));
            }
            check_run(&program, source, &dir)?;
            read_genome(&path)?
        }
    };
    if genome.bits.len() != stage.layout.bits as usize {
        return Err(CliError::io(format!(
            "error: the genome has {} bits but stage `{}` needs {}",
            genome.bits.len(),
            stage.name,
            stage.layout.bits
        )));
    }
    Ok(Chosen { program, index, genome, training_seed })
}

/// A best individual taken from a run directory must come from the program
/// as it is: its stage's checkpoint must still fit.
fn check_run(program: &Program, index: usize, dir: &Path) -> Result<(), CliError> {
    let path = dir.join("checkpoint.json");
    if !path.exists() {
        return Ok(());
    }
    let cp: shaping_runtime::evolve::Checkpoint = serde_json::from_slice(&load::read_bytes(&path)?)
        .map_err(|e| CliError::io(format!("error: the checkpoint `{}` is corrupt ({e})", path.display())))?;
    shaping_runtime::evolve::check_resume_of(program, index, &cp).map_err(|e| {
        CliError::io(format!(
            "error: the best individual in `{}` is not of this program: {e}; run the file again (`shaping run` with `--fresh`)",
            dir.display()
        ))
    })
}

/// The stage whose best individual a replay of `index` uses by default: the
/// stage itself if evolved, else its nearest evolved ancestor.
pub(crate) fn evolved_source(program: &Program, index: usize) -> usize {
    let mut cur = Some(index);
    while let Some(i) = cur {
        if let StageRun::Evolve(_) = program.stages[i].run {
            return i;
        }
        cur = program.stages[i].parent;
    }
    index
}

pub fn replay(args: ReplayArgs) -> Result<(), CliError> {
    let chosen = choose(
        &args.file,
        args.stage.as_deref(),
        args.genome.as_deref(),
        args.run.as_deref(),
        args.error_format,
    )?;
    let Chosen { program, index, genome, training_seed } = chosen;
    let run_dir = args.run.clone().unwrap_or_else(|| run::default_out(&args.file));
    let stage = &program.stages[index];
    let (actions, learning) = match &stage.run {
        StageRun::Evolve(e) => (e.actions, true),
        // One life of the test, in the stage's own world.
        StageRun::Test { actions, learning, .. } => (*actions, *learning),
        StageRun::Train { actions } => (*actions, true),
    };
    let actions = args.actions.unwrap_or(actions);
    let learning = learning && !args.no_learning;
    // A training stage's own life by default: the one its weights were learned in.
    let seed = args.seed.unwrap_or_else(|| match training_seed {
        Some(run_seed) => evolve::train::training_seed(run_seed, index),
        None => run::run_seed(&program, None),
    });
    load::check_recording(stage, actions)?;
    let (r, trace, ep) = episode::run_recorded(stage, &genome, &EpisodeOptions { actions, learning, seed })
        .map_err(|e| CliError::io(format!("error: {e}")))?;
    let out = args.out.clone().unwrap_or_else(|| run_dir.join(&stage.name).join("replay"));
    let mut crowding = run::Crowding::default();
    crowding.add(r.placement_failures);
    if let Some(w) = crowding.warning(&stage.name, &out, ("episode", "episodes")) {
        eprintln!("{w}");
    }
    create_dir(&out)?;
    let scene = Sim::new(&stage.world, seed).scene();
    report::episode_files(&out, &stage.name, stage, &trace, &ep, &scene, &[], None)?;
    let err = |e: serde_json::Error| CliError::io(format!("error: cannot serialise: {e}"));
    write_atomic(&out.join("episode.json"), serde_json::to_string(&ep).map_err(err)?.as_bytes())?;
    write_atomic(&out.join("program.json"), serde_json::to_string(&program).map_err(err)?.as_bytes())?;
    outln!(
        "{}: {} actions, fitness {:.3}, {} grips, {} released outside, {} recharges, {} collisions -> {}",
        stage.name,
        r.actions,
        r.fitness,
        r.grips,
        r.releases_outside,
        r.recharges,
        r.collisions,
        out.display()
    )?;
    write_atomic(&out.join("genome"), format!("{}\n", genome.to_bitstring()).as_bytes())?;
    if args.report {
        let path = html::write(&out, None)?;
        outln!("report: {}", path.display())?;
    }
    Ok(())
}
