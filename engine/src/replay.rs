//! Replays: one individual of a stage run with a trace, its files and
//! pictures (and animations); and the choice of that individual (`replay`, `drive`).

use std::path::{Path, PathBuf};

use shaping_runtime::controller::EpisodeOptions;
use shaping_runtime::evolve;
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Program, Stage, StageRun};
use shaping_runtime::sim::Sim;

use shaping_runtime::controller::EpisodeResult;

use crate::episode::TeamColumns;
use crate::error::Error;
use crate::files::create_dir;
use crate::run::{Event, Observer};
use crate::{animation, episode, html, load, report, run, rundir};

/// What to replay.
#[derive(Clone, Debug, Default)]
pub struct ReplayOptions {
    /// The architecture file, for the default run directory (`runs/<stem>`).
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
    /// Also write the episode as an animated GIF here.
    pub gif: Option<PathBuf>,
    /// Also write the episode as an MP4 here (through `ffmpeg`).
    pub mp4: Option<PathBuf>,
    /// Settings changed from the file's, as the run was made (`--set`).
    pub sets: Vec<crate::sweep::Assignment>,
    /// The robot of a team the pictures, the report's readout and the
    /// animations follow (`--robot`; 0, the first, by default).
    pub robot: u32,
    /// Live in this declared variant of the stage's world (`--variant`),
    /// not in the stage's own world.
    pub variant: Option<String>,
}

/// Stage `stage` in its variant `name` (see [`ReplayOptions::variant`]):
/// an error naming the stage's variants when it has no such one.
pub fn in_named_variant(stage: &Stage, name: &str) -> Result<Stage, Error> {
    let names: Vec<&str> =
        stage.variants.iter().flat_map(|v| v.list.iter().map(|x| x.name.as_str())).collect();
    if let Some(v) = names.iter().position(|n| *n == name) {
        return Ok(stage.in_variant(v));
    }
    if names.is_empty() {
        return Err(Error::invalid_setting(
            "--variant",
            Some(name),
            format!(
                "error: `--variant {name}`: stage `{}` declares no variants (`variants mean {{ ... }}` in its world)",
                stage.name
            ),
        ));
    }
    let listed: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    let hint = shaping_compiler::diag::did_you_mean(name, names.iter().copied())
        .map(|h| format!("; {h}"))
        .unwrap_or_default();
    Err(Error::invalid_setting(
        "--variant",
        Some(name),
        format!(
            "error: `--variant {name}`: stage `{}` has no variant `{name}` (its variants: {}){hint}",
            stage.name,
            listed.join(", ")
        ),
    ))
}

/// Refuses `--robot N` of a stage whose team has no robot `N`.
fn check_robot(stage: &Stage, robot: u32) -> Result<(), Error> {
    let robots = stage.robots();
    if robot < robots {
        return Ok(());
    }
    let has = if robots == 1 {
        "one robot, robot 0".to_string()
    } else {
        format!("{robots} robots, 0 to {}", robots - 1)
    };
    let message = format!("error: `--robot {robot}`: stage `{}` has {has}", stage.name);
    Err(Error::invalid_setting("--robot", Some(&robot.to_string()), message))
}

/// Reads `--genome`: an argument made only of `0`, `1`, `_` and blanks is
/// the genome itself; anything else is the path of a file holding one. A
/// string of digits that is not a genome (`2101`) is refused as such, not
/// looked for as a file.
pub fn parse_genome(arg: &str) -> Result<Genome, Error> {
    let (position, c) = match Genome::parse_bitstring(arg) {
        Ok(g) => return Ok(g),
        Err(bad) => bad,
    };
    let blank = |c: char| c == '_' || c.is_whitespace();
    if arg.chars().all(|c| c.is_ascii_digit() || blank(c)) {
        return Err(Error::invalid_setting(
            "--genome",
            Some(arg),
            format!(
                "error: `--genome {arg}` is not a genome: character {position} is `{c}`; a genome is a string of 0 and 1 (or the path of a file holding one)"
            ),
        ));
    }
    let path = Path::new(arg);
    if !path.is_file() {
        return Err(Error::invalid_setting(
            "--genome",
            Some(arg),
            format!("error: `--genome {arg}` is neither a string of 0 and 1 (character {position} is `{c}`) nor a file"),
        ));
    }
    read_genome(path)
}

pub use crate::rundir::read_genome;

/// What `replay` and `drive` run: the program with the weights of every
/// training stage bound (the one way every command binds them), the stage,
/// the individual, and for a training stage, its run seed.
pub struct Chosen {
    pub program: Program,
    pub index: usize,
    pub genome: Genome,
    /// The run seed of the training stage's life, when `index` is one.
    pub training_seed: Option<u64>,
}

/// The program a replay (or `drive`) of run directory `run_dir` runs:
/// `program` (the file's, with `given`, the `--set` values passed), or,
/// when the run's `program.json` is `program` with other settings (ones
/// `given` does not name: a run made with `--set`, or a setting since
/// edited in the file), the run's own program, which the observer is told
/// with the settings.
pub fn with_run_settings(
    program: Program,
    run_dir: &Path,
    given: &[crate::sweep::Assignment],
    observer: &dyn Observer,
) -> Program {
    let Some(ran) = rundir::read_program(run_dir) else { return program };
    if ran == program {
        return program;
    }
    let Some(found) = crate::sweep::settings_between(&program, &ran) else { return program };
    // A setting given for the replay is the user's to keep (`*.PATH` names
    // it in every stage).
    let named =
        |t: &str| given.iter().any(|(g, _)| g == t || g.strip_prefix('*').is_some_and(|p| t.ends_with(p)));
    if found.iter().any(|(t, _)| named(t)) {
        return program;
    }
    let sets: Vec<String> = found.iter().map(|(t, v)| format!("--set {t}={v}")).collect();
    observer.event(Event::Warning(format!(
        "note: the run in `{}` is of this file with other settings (`{}`): replaying the run's own program (its \
         `program.json`)",
        run_dir.display(),
        sets.join(" ")
    )));
    ran
}

/// Loads `file`, binds the training stages from run directory `run` (default
/// `runs/<file stem>`) and picks the individual: `--genome`, else the best
/// of the stage (or of the evolved stage it tests) in the run directory.
/// A training stage has no individual: its life is what there is to see.
pub fn choose(
    mut program: Program,
    file: &Path,
    stage: Option<&str>,
    genome: Option<&str>,
    run: Option<&Path>,
    observer: &dyn Observer,
) -> Result<Chosen, Error> {
    let index = load::stage_index(&program, stage)?;
    let run_dir = run.map_or_else(|| run::default_out(file), Path::to_path_buf);
    let seed = run::run_seed(&program, None);
    let trained = run::bind_training(&mut program, Some(&run_dir), seed, observer)?;
    let stage = &program.stages[index];
    let training_seed = trained.iter().find(|(i, _)| *i == index).map(|(_, t)| t.run_seed);
    let genome_arg = genome;
    let genome = match genome {
        Some(g) => parse_genome(g)?,
        None if training_seed.is_some() => Genome::zeros(0),
        // Nothing is evolved: the empty genome is the only individual.
        None if stage.layout.bits == 0 && run.is_none() => Genome::zeros(0),
        None => {
            let source = program.evolved_at_or_above(index).unwrap_or(index);
            let dir = rundir::stage_dir(&run_dir, &program.stages[source].name);
            let path = rundir::best_genome_path(&dir);
            if !path.exists() {
                let subject = crate::Subject::File { path: path.clone(), operation: "read".into() };
                return Err(Error::new(
                    crate::ErrorKind::NotFound,
                    format!(
                        "error: no evolved individual at `{}`; run `shaping run {}{}` first, or pass `--genome`",
                        path.display(),
                        file.display(),
                        run.map_or_else(String::new, |d| format!(" --out {}", d.display()))
                    ),
                )
                .about(subject));
            }
            // From the program as it is: the checkpoint, where there is one,
            // must still fit, and `best.genome` be its best.
            if rundir::checkpoint_path(&dir).exists() {
                not_of_this_program(&program, source, &dir, file, &run_dir)?;
                rundir::checked_best_with(&program, source, &dir, &|p| run::warn_unsealed(observer, p))?.1
            } else {
                let warn = |p: &Path| run::warn_unsealed(observer, p);
                rundir::read_best_genome(&dir, &warn)?.map_or_else(|| read_genome(&path), Ok)?
            }
        }
    };
    if genome.bits.len() != stage.layout.bits as usize {
        let message = format!(
            "error: the genome has {} bits but stage `{}` needs {}",
            genome.bits.len(),
            stage.name,
            stage.layout.bits
        );
        // An argument that cannot be used, or a saved genome of another program.
        return Err(match genome_arg {
            Some(g) => Error::invalid_setting("--genome", Some(g), message),
            None => {
                let source = program.evolved_at_or_above(index).unwrap_or(index);
                let path =
                    rundir::best_genome_path(&rundir::stage_dir(&run_dir, &program.stages[source].name));
                Error::stale(&path, format!("{} bits, not {}", genome.bits.len(), stage.layout.bits), message)
            }
        });
    }
    Ok(Chosen { program, index, genome, training_seed })
}

/// Refuses a saved best that is not of `program` (the file's, with the
/// replay's settings), saying how to replay it: with the run's own
/// `program.json` (which [`with_run_settings`] takes by itself when only
/// settings differ), or after running the file again elsewhere. A damaged
/// or missing checkpoint is left to [`rundir::checked_best`] to name.
fn not_of_this_program(
    program: &Program,
    index: usize,
    dir: &Path,
    file: &Path,
    run_dir: &Path,
) -> Result<(), Error> {
    let Ok(Some(cp)) = rundir::read_checkpoint(dir) else { return Ok(()) };
    let Err(e) = evolve::check_resume_of(program, index, &cp) else { return Ok(()) };
    let own = rundir::program_path(run_dir);
    let theirs = if own.exists() {
        format!(
            "replay it with the run's own program (`shaping replay {} --run {} --stage {}`), or ",
            own.display(),
            run_dir.display(),
            program.stages[index].name
        )
    } else {
        String::new()
    };
    Err(Error::stale(
        &rundir::checkpoint_path(dir),
        e.to_string(),
        format!(
            "error: the best individual in `{}` is not of this program: {e}; {theirs}run `{}` again into another \
             `--out` and replay that",
            dir.display(),
            file.display()
        ),
    ))
}

/// What a replay did: the episode's result, where its files are, its
/// report (if asked for).
#[derive(Clone, Debug)]
pub struct Replayed {
    pub stage: String,
    pub result: EpisodeResult,
    pub out: PathBuf,
    pub report: Option<PathBuf>,
    /// The animations written (`--gif`, `--mp4`).
    pub animations: Vec<PathBuf>,
}

/// Replays an individual of `program` (the file's; see [`choose`]) and
/// writes its files: `trace.csv`, the pictures, `episode.json`,
/// `program.json`, `genome`, and `report.html` and the animations if
/// asked for (`--mp4` without `ffmpeg` is refused before anything runs).
pub fn replay(
    mut program: Program,
    args: &ReplayOptions,
    observer: &dyn Observer,
) -> Result<Replayed, Error> {
    crate::sweep::apply(&mut program, &args.sets)?;
    if args.mp4.is_some() {
        animation::ffmpeg()?;
    }
    let run_dir = args.run.clone().unwrap_or_else(|| run::default_out(&args.file));
    let program = with_run_settings(program, &run_dir, &args.sets, observer);
    let chosen = choose(
        program,
        &args.file,
        args.stage.as_deref(),
        args.genome.as_deref(),
        args.run.as_deref(),
        observer,
    )?;
    let Chosen { program, index, genome, training_seed } = chosen;
    let in_variant =
        args.variant.as_deref().map(|v| in_named_variant(&program.stages[index], v)).transpose()?;
    let stage = in_variant.as_ref().unwrap_or(&program.stages[index]);
    check_robot(stage, args.robot)?;
    let robot = args.robot as usize;
    let out = args.out.clone().unwrap_or_else(|| rundir::replay_dir(&run_dir, &stage.name));
    rundir::check_replay_out(&out)?;
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
    let recorded = episode::record(stage, &genome, &EpisodeOptions { actions, learning, seed })
        .map_err(|e| Error::new(crate::ErrorKind::Invalid, format!("error: {e}")))?;
    let episode::Recorded { result: r, trace, others, episode: ep, scene: team_scene } = recorded;
    let mut crowding = run::Crowding::default();
    crowding.add(r.placement_failures);
    if let Some(w) = crowding.warning(&stage.name, &out, ("episode", "episodes")) {
        observer.event(Event::Warning(w));
    }
    create_dir(&out)?;
    // A team's world is the one its robots started in.
    let scene = if others.is_empty() { Sim::new(&stage.world, seed).scene() } else { team_scene };
    if robot == 0 {
        let lived = report::Lived { trace: &trace, others: &others, scene: &scene };
        report::episode_files(&out, stage, lived, &ep, &report::Drawing::titled(&stage.name))?;
    } else {
        rundir::write_trace(&out, &report::team_trace_csv(&trace, &others, stage, &ep))?;
        let (mine, rest) = report::followed(&trace, &others, robot);
        report::followed_pictures(&out, &stage.name, stage, robot, (&mine, &rest), &scene)?;
    }
    // Robot `robot`'s columns, for the report and the animations to follow
    // (robot 0's are `episode.json`'s own).
    let team = (robot != 0)
        .then(|| TeamColumns::of(stage, &others, ep.actions.x.len(), args.robot))
        .flatten()
        .map(|t| TeamColumns { board: report::board_columns(stage, &ep, &others), ..t });
    if let Some(team) = &team {
        rundir::write_robots(&out, team)?;
    }
    rundir::write_episode(&out, &ep)?;
    rundir::write_program(&out, &program)?;
    rundir::write_genome_file(&out, &genome)?;
    let report = if args.report { Some(html::write(&out, None)?) } else { None };
    let mut animations = Vec::new();
    if args.gif.is_some() || args.mp4.is_some() {
        let following = team.as_ref().map(|t| ep.following(t, robot));
        let roles: Vec<(String, u32)> = stage.roles.iter().map(|r| (r.name.clone(), r.robots)).collect();
        let frames = animation::frames_of_team(&scene, following.as_ref().unwrap_or(&ep), &roles, robot)?;
        if let Some(path) = &args.gif {
            animation::write_gif(path, &frames)?;
            animations.push(path.clone());
        }
        if let Some(path) = &args.mp4 {
            animation::write_mp4(path, &frames)?;
            animations.push(path.clone());
        }
    }
    Ok(Replayed { stage: stage.name.clone(), result: r, out, report, animations })
}
