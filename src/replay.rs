//! `shaping replay`: runs one individual with a trace and writes the pictures.

use std::path::{Path, PathBuf};

use shaping_runtime::controller::EpisodeOptions;
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Program, StageRun};
use shaping_runtime::sim::Sim;

use crate::load::{self, create_dir, write_atomic, CliError};
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

/// Reads a genome given as a bit string or as the path of a file holding one.
pub(crate) fn parse_genome(arg: &str) -> Result<Genome, CliError> {
    if arg.trim().is_empty() {
        // A stage without evolvable values has an empty genome.
        return Ok(Genome { bits: Vec::new() });
    }
    if let Some(g) = Genome::from_bitstring(arg) {
        return Ok(g);
    }
    let path = Path::new(arg);
    let bytes = load::read_bytes(path)?;
    let text = String::from_utf8_lossy(&bytes);
    Genome::from_bitstring(text.trim()).filter(|g| !g.bits.is_empty()).ok_or_else(|| {
        CliError::io(format!("error: `{}` does not hold a genome (a string of 0 and 1)", path.display()))
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
    let mut program = load::load_program(&args.file, args.error_format)?;
    let index = load::stage_index(&program, args.stage.as_deref())?;
    let run_dir = args.run.clone().unwrap_or_else(|| run::default_out(&args.file));
    let train_seed = run::run_seed(&program, None);
    run::bind_training(&mut program, Some(&run_dir), train_seed)?;
    let stage = &program.stages[index];
    let genome = match &args.genome {
        Some(g) => parse_genome(g)?,
        // Nothing is evolved: the empty genome is the only individual.
        None if stage.layout.bits == 0 && args.run.is_none() => Genome::zeros(0),
        None => {
            let source = &program.stages[evolved_source(&program, index)];
            let path = run_dir.join(&source.name).join("best.genome");
            if !path.exists() {
                return Err(CliError::io(format!(
                    "error: no evolved individual at `{}`; run `shaping run {}` first, or pass `--genome` or `--run`",
                    path.display(),
                    args.file.display()
                )));
            }
            parse_genome(&path.to_string_lossy())?
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
    let (actions, learning) = match &stage.run {
        StageRun::Evolve(e) => (e.actions, true),
        StageRun::Test { actions, learning } => (*actions, *learning),
        StageRun::Train { actions } => (*actions, true),
    };
    let actions = args.actions.unwrap_or(actions);
    let learning = learning && !args.no_learning;
    let seed = args.seed.unwrap_or_else(|| run::run_seed(&program, None));
    let (r, trace, ep) = episode::run_recorded(stage, &genome, &EpisodeOptions { actions, learning, seed })
        .map_err(|e| CliError::io(format!("error: {e}")))?;
    let out = args.out.clone().unwrap_or_else(|| run_dir.join(&stage.name).join("replay"));
    create_dir(&out)?;
    let scene = Sim::new(&stage.world, seed).scene();
    report::episode_files(&out, &stage.name, stage, &trace, &scene, &[])?;
    let err = |e: serde_json::Error| CliError::io(format!("error: cannot serialise: {e}"));
    write_atomic(&out.join("episode.json"), serde_json::to_string(&ep).map_err(err)?.as_bytes())?;
    write_atomic(&out.join("program.json"), serde_json::to_string(&program).map_err(err)?.as_bytes())?;
    println!(
        "{}: {} actions, fitness {:.3}, {} grips, {} released outside, {} recharges, {} collisions -> {}",
        stage.name,
        r.actions,
        r.fitness,
        r.grips,
        r.releases_outside,
        r.recharges,
        r.collisions,
        out.display()
    );
    write_atomic(&out.join("genome"), format!("{}\n", genome.to_bitstring()).as_bytes())?;
    if args.report {
        let path = html::write(&out, None)?;
        println!("report: {}", path.display());
    }
    Ok(())
}
