//! The `shaping` command line: the only place that touches files and terminals.

mod bench;
mod cluster;
mod experiment;
mod fmt;
mod load;
mod lsp;
mod out;
mod replay;
mod robot;
mod run;
mod signals;
mod terminal;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use out::{out, outln};
pub use shaping_engine::diag::{self as diag, ErrorFormat};
/// Every command's error: the engine's, printed as it is.
pub use shaping_engine::Error as CliError;
use shaping_engine::{html, sweep};

/// Most worker threads `--jobs` accepts.
const MAX_JOBS: u64 = shaping_engine::run::MAX_JOBS as u64;
/// Most seeds an experiment runs.
use shaping_engine::experiment::MAX_SEEDS;

/// Declarative behavior architectures for autonomous robots, evolved and
/// trained incrementally (Urzelai, Floreano, Dorigo, Colombetti 1998).
#[derive(Parser)]
#[command(name = "shaping", version, about, max_term_width = 100)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check architecture files and report every error.
    Check {
        /// `.bat` files to check.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        #[arg(long, default_value = "human", value_parser = error_format())]
        error_format: ErrorFormat,
    },
    /// Format architecture files in place (standard input to standard output
    /// when no file is given); a file that does not parse is left untouched.
    Fmt {
        /// `.bat` files to format.
        files: Vec<PathBuf>,
        /// Change nothing; name the files that would change and exit 1 if any.
        #[arg(long)]
        check: bool,
        #[arg(long, default_value = "human", value_parser = error_format())]
        error_format: ErrorFormat,
    },
    /// Run the language server on standard input and output (for editors).
    Lsp,
    /// Explain a diagnostic code (`S0006`): what it means, a file that
    /// produces it and the same file fixed.
    Explain { code: String },
    /// Show the genome layout the compiler derived for a stage.
    Layout {
        file: PathBuf,
        /// Stage name (default: the last stage).
        #[arg(long)]
        stage: Option<String>,
        #[arg(long, value_enum, default_value = "text")]
        format: LayoutFormat,
        #[arg(long, default_value = "human", value_parser = error_format())]
        error_format: ErrorFormat,
    },
    /// Print the module graph of a stage as Graphviz DOT.
    Graph {
        file: PathBuf,
        #[arg(long)]
        stage: Option<String>,
        #[arg(long, default_value = "human", value_parser = error_format())]
        error_format: ErrorFormat,
    },
    /// Compile to a `Program` (JSON) that `run`, `replay` and `bench` also accept.
    Build {
        file: PathBuf,
        /// Output file: new, or a program `build` wrote before (nothing else is replaced).
        #[arg(short, long)]
        output: PathBuf,
        #[arg(long, default_value = "human", value_parser = error_format())]
        error_format: ErrorFormat,
    },
    /// Evolve the stages in order, resuming from checkpoints; writes statistics,
    /// best genomes and plots under `runs/<file stem>/<stage>/`.
    Run {
        file: PathBuf,
        /// Run only this stage and the stages it extends.
        #[arg(long)]
        stage: Option<String>,
        /// Run seed (default: the seed the first evolved stage declares).
        #[arg(long)]
        seed: Option<u64>,
        /// Output directory (default: `runs/<file stem>`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads (default: one per core). Results do not depend on it.
        #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=MAX_JOBS))]
        jobs: Option<usize>,
        /// No progress bar and no summary.
        #[arg(long)]
        quiet: bool,
        /// One JSON line per generation on stdout.
        #[arg(long)]
        json: bool,
        /// Ignore existing checkpoints and start every stage again.
        #[arg(long)]
        fresh: bool,
        /// Write no `report.html` at the end.
        #[arg(long)]
        no_report: bool,
        /// Under MPI: seconds rank 0 waits for a rank's answer to a batch
        /// before it ends the run, naming the rank.
        #[arg(long, value_name = "SECONDS", default_value_t = cluster::DEFAULT_RANK_TIMEOUT)]
        rank_timeout: u64,
        /// Evaluate the individuals one after another on the robot at this
        /// serial port (see `docs/robot.md`); every episode is saved as it ends.
        #[arg(long)]
        robot: Option<PathBuf>,
        /// `STAGE.SECTION.FIELD=VALUE`: change a setting of the program
        /// (the settings `experiment --set` sweeps; one value here).
        #[arg(long = "set", value_name = "STAGE.SECTION.FIELD=VALUE", value_parser = sweep::parse_set)]
        sets: Vec<sweep::Set>,
        /// Baud rate of `--robot`.
        #[arg(long, default_value_t = 9600, requires = "robot")]
        baud: u32,
        /// Action period in ms on the robot (default: the world's action length).
        #[arg(long, requires = "robot")]
        period: Option<u64>,
        /// Longest wait for an answer of the robot, ms.
        #[arg(long, default_value_t = 1000, requires = "robot")]
        timeout: u64,
        #[arg(long, default_value = "human", value_parser = error_format())]
        error_format: ErrorFormat,
    },
    /// Run one individual on a Khepera over its serial port; writes the same
    /// trace and pictures as `replay`. The motors are stopped before exiting,
    /// whatever happens (Ctrl-C, a lost link, a bad answer).
    Drive(robot::drive::DriveArgs),
    /// An emulated Khepera: answers the serial protocol from the simulator on
    /// a pseudo-terminal made at `--port`, until Ctrl-C.
    Emulate(robot::emulate::EmulateArgs),
    /// Run one individual with a trace; writes `trace.csv` and the pictures
    /// (module activations, reinforcement, trajectory).
    Replay(replay::ReplayArgs),
    /// Run every stage over several seeds, or a sweep of settings (`--set`),
    /// and summarise (median and range): `summary.md`, `summary.json` and
    /// pictures.
    Experiment {
        file: PathBuf,
        /// Number of seeds.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..=MAX_SEEDS))]
        seeds: u64,
        /// First seed; the seeds are consecutive.
        #[arg(long, default_value_t = 1)]
        first_seed: u64,
        /// Output directory (default: `runs/<file stem>/experiment`).
        #[arg(long)]
        out: Option<PathBuf>,
        #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=MAX_JOBS))]
        jobs: Option<usize>,
        /// `STAGE=FITNESS`: report the generation at which the best reaches it.
        #[arg(long)]
        criterion: Vec<String>,
        /// `STAGE.SECTION.FIELD=V1,V2,...`: sweep a setting; several `--set`
        /// sweep the cartesian product, every point over the seeds. Fields:
        /// `evolve.` population, generations, actions, crossover, mutation,
        /// elitism, evaluations, keep, selection, inheritance; `world.`
        /// arena, charger, lamp, battery, recharge, objects, diameter, robots;
        /// `world.body.` radius, wheel_base, v_max, action, wheel_noise,
        /// sensor_noise, rab_signals; `variants.` aggregate, draw; `fitness.team`; `test.actions`,
        /// `test.lives`; `train.actions`; `MODULE.` reward,
        /// punish, window, threshold, range. STAGE may be `*` (every stage).
        #[arg(long = "set", value_name = "STAGE.SECTION.FIELD=V1,V2,...", value_parser = sweep::parse_set)]
        sets: Vec<sweep::Set>,
        /// Run only this stage and the stages it needs.
        #[arg(long)]
        stage: Option<String>,
        /// Ignore existing checkpoints.
        #[arg(long)]
        fresh: bool,
        /// Write no `report.html` at the end.
        #[arg(long)]
        no_report: bool,
        /// Under MPI: seconds rank 0 waits for a rank's answer to a batch
        /// before it ends the run, naming the rank.
        #[arg(long, value_name = "SECONDS", default_value_t = cluster::DEFAULT_RANK_TIMEOUT)]
        rank_timeout: u64,
        #[arg(long, default_value = "human", value_parser = error_format())]
        error_format: ErrorFormat,
    },
    /// Compare finished experiment directories (each with its `seed-N/`
    /// runs, the same stages in each): per stage and measure the median with
    /// its bootstrap 95% interval and, for every pair, the Mann-Whitney U
    /// test's p-value and the Vargha-Delaney A12 (Holm-corrected for more
    /// than two directories), as Markdown or `--json`.
    Compare {
        /// Experiment directories (at least two, each of at least 2 seeds).
        #[arg(required = true, num_args = 2..)]
        dirs: Vec<PathBuf>,
        /// `STAGE=FITNESS`: also compare the generation reaching it.
        #[arg(long)]
        criterion: Vec<String>,
        /// Compare this stage only (directories that ran other stages too).
        #[arg(long)]
        stage: Option<String>,
        /// Print the comparison as JSON (the `tests` of `summary.json`).
        #[arg(long)]
        json: bool,
    },
    /// Write one self-contained HTML page (no network needed) for a run, stage,
    /// experiment or replay directory: the replay animated with its module
    /// activations, fitness, architecture and genome layout.
    Report {
        /// The directory a `run`, `experiment` or `replay` wrote.
        dir: PathBuf,
        /// Output file (default: `DIR/report.html`): new, or an earlier report
        /// (nothing else is replaced).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Measure simulator steps and controller actions per second (one JSON
    /// line); with `world.robots` N > 1, N robots acting in turn in one world
    /// (`robot_steps_per_sec`). The bench picks its own life lengths, printed
    /// in the line: controller lives of `controller_episode_actions` (300,
    /// fewer for a large team but at least 100; the stage's own is
    /// `stage_actions`), and simulated worlds that live at most
    /// `sim_episode_actions`. The line also says the build (`debug` or
    /// `release`) and the peak memory (`peak_memory_mb`).
    Bench {
        file: PathBuf,
        #[arg(long)]
        stage: Option<String>,
        /// Timed runs; the median is reported.
        #[arg(long, default_value_t = 5, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1000))]
        runs: usize,
        /// Change a setting as `run --set` does (`STAGE.world.robots=100`).
        #[arg(long = "set", value_name = "STAGE.SECTION.FIELD=VALUE", value_parser = sweep::parse_set)]
        sets: Vec<sweep::Set>,
        #[arg(long, default_value = "human", value_parser = error_format())]
        error_format: ErrorFormat,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum LayoutFormat {
    Text,
    Json,
}

/// The exit status of a failed command: 1 for diagnostics about the
/// user's file, 2 for everything else (usage, I/O, a refused run).
pub fn exit_code(e: &CliError) -> i32 {
    match e.kind() {
        shaping_engine::ErrorKind::Diagnostics => 1,
        _ => 2,
    }
}

/// `--error-format human|plain|json`.
fn error_format() -> impl clap::builder::TypedValueParser<Value = ErrorFormat> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(["human", "plain", "json"]).map(|s| match s.as_str() {
        "plain" => ErrorFormat::Plain,
        "json" => ErrorFormat::Json,
        _ => ErrorFormat::Human,
    })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Err(e) = refuse_without_mpi(&cli.command) {
        eprintln!("{e}");
        return ExitCode::from(exit_code(&e) as u8);
    }
    if let Command::Lsp = cli.command {
        // The protocol's status: 1 when `exit` came without `shutdown`.
        return match lsp::stdio() {
            Ok(ending) => ExitCode::from(ending.status()),
            Err(e) => {
                eprintln!("error: language server: {e}");
                ExitCode::from(2)
            }
        };
    }
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let msg = e.to_string();
            if !msg.is_empty() {
                eprintln!("{msg}");
            }
            ExitCode::from(exit_code(&e) as u8)
        }
    }
}

fn dispatch(command: Command) -> Result<(), CliError> {
    match command {
        Command::Check { files, error_format } => check(&files, error_format),
        Command::Fmt { files, check, error_format } => fmt::fmt(&files, check, error_format),
        // Served by `main`, for the protocol's exit status.
        Command::Lsp => Ok(()),
        Command::Explain { code } => explain(&code),
        Command::Layout { file, stage, format, error_format } => {
            layout(&file, stage.as_deref(), format, error_format)
        }
        Command::Graph { file, stage, error_format } => {
            let program = load::load_program(&file, error_format)?;
            let index = load::stage_index(&program, stage.as_deref())?;
            print_text(&shaping_compiler::render_graph(&program, index))
        }
        Command::Compare { dirs, criterion, stage, json } => {
            compare(shaping_engine::compare::CompareOptions { dirs, criterion, stage }, json)
        }
        Command::Report { dir, output } => report(&dir, output.as_deref()),
        Command::Bench { file, stage, runs, sets, error_format } => bench::bench(bench::BenchArgs {
            file,
            stage,
            runs,
            sets: single_values(sets, "bench")?,
            error_format,
        }),
        Command::Build { file, output, error_format } => build(&file, &output, error_format),
        Command::Drive(args) => robot::drive::drive(args),
        Command::Emulate(args) => robot::emulate::emulate(args),
        Command::Replay(args) => replay::replay(args),
        run @ (Command::Run { .. } | Command::Experiment { .. }) => run_command(run),
    }
}

/// The commands that evolve: `run` and `experiment` (`dispatch` gives no
/// other).
fn run_command(command: Command) -> Result<(), CliError> {
    match command {
        Command::Run {
            file,
            stage,
            seed,
            out,
            jobs,
            quiet,
            json,
            fresh,
            no_report,
            rank_timeout,
            robot,
            sets,
            baud,
            period,
            timeout,
            error_format,
        } => {
            let robot = robot.map(|dev| robot::RobotRun::new(dev, baud, period, timeout)).transpose()?;
            let sets = single_values(sets, "run")?;
            // One robot: its individuals are evaluated one after another.
            let jobs = if robot.is_some() { Some(1) } else { jobs };
            let args = run::RunArgs {
                file,
                stage,
                seed,
                out,
                jobs,
                quiet,
                json,
                fresh,
                no_report,
                error_format,
                robot,
                sets,
            };
            run_here_or_on_ranks(args, rank_timeout)
        }
        Command::Experiment {
            file,
            seeds,
            first_seed,
            out,
            jobs,
            criterion,
            sets,
            stage,
            fresh,
            no_report,
            rank_timeout,
            error_format,
        } => {
            let program = load::load_program(&file, error_format)?;
            let plan = shaping_engine::experiment::Plan::new(
                program,
                shaping_engine::experiment::ExperimentOptions {
                    file,
                    seeds,
                    first_seed,
                    out,
                    jobs,
                    criterion,
                    sets,
                    stage,
                    fresh,
                    no_report,
                },
            )?;
            experiment_here_or_on_ranks(&plan, jobs, rank_timeout)
        }
        _ => Err(CliError::new(
            shaping_engine::ErrorKind::Invalid,
            "error: internal error: a command that runs no program was taken for one",
        )),
    }
}

/// `shaping explain CODE`.
fn explain(code: &str) -> Result<(), CliError> {
    match shaping_compiler::explain::explain(code) {
        Some(e) => out!("{}", shaping_compiler::explain::render(e)),
        None => Err(CliError::new(
            shaping_engine::ErrorKind::Invalid,
            format!(
                "error: no diagnostic has the code `{code}` (the codes are S0001 to S{:04})",
                shaping_compiler::explain::EXPLANATIONS.len()
            ),
        )),
    }
}

/// `shaping layout FILE [--stage S] [--format text|json]`.
fn layout(
    file: &std::path::Path,
    stage: Option<&str>,
    format: LayoutFormat,
    error_format: ErrorFormat,
) -> Result<(), CliError> {
    let program = load::load_program(file, error_format)?;
    let index = load::stage_index(&program, stage)?;
    match format {
        LayoutFormat::Text => print_text(&shaping_compiler::render_layout(&program, index)),
        LayoutFormat::Json => {
            let st = &program.stages[index];
            let layout = serde_json::json!({
                "stage": st.name,
                "bits": st.layout.bits,
                "genes": shaping_compiler::layout_rows(&program, index),
            });
            let json = serde_json::to_string_pretty(&layout)
                .map_err(|e| CliError::internal(format!("error: cannot serialise the layout: {e}")))?;
            outln!("{json}")
        }
    }
}

/// `shaping run`: in this process, or over the ranks when an MPI launcher
/// started it (a build with MPI).
fn run_here_or_on_ranks(args: run::RunArgs, rank_timeout: u64) -> Result<(), CliError> {
    #[cfg(feature = "mpi")]
    if cluster::launcher().is_some() {
        if args.robot.is_some() {
            let message = "error: `--robot` evaluates on one robot; run it without `mpirun`";
            return Err(CliError::invalid_setting("--robot", None, message));
        }
        let (jobs, quiet) = (args.jobs, args.quiet || args.json);
        return cluster::with_mpi(jobs, rank_timeout, quiet, None, |c| run::run(args, Some(c)));
    }
    let _ = rank_timeout;
    run::run(args, None)
}

/// `shaping experiment`: in this process, or over the ranks when an MPI
/// launcher started it (a build with MPI).
fn experiment_here_or_on_ranks(
    plan: &shaping_engine::experiment::Plan,
    jobs: Option<usize>,
    rank_timeout: u64,
) -> Result<(), CliError> {
    #[cfg(feature = "mpi")]
    if cluster::launcher().is_some() {
        let task = |task, threads| experiment::run_task(plan, task, Some(threads), true, None);
        return cluster::with_mpi(jobs, rank_timeout, false, Some(&task), |c| {
            experiment::experiment(plan, jobs, Some(c))
        });
    }
    let _ = rank_timeout;
    experiment::experiment(plan, jobs, None)
}

/// `shaping compare DIR DIR...`: Markdown, or JSON with `--json`.
fn compare(opts: shaping_engine::compare::CompareOptions, json: bool) -> Result<(), CliError> {
    let tests = shaping_engine::compare::compare(&opts)?;
    if json {
        let text = serde_json::to_string_pretty(&tests)
            .map_err(|e| CliError::internal(format!("error: cannot serialise the comparison: {e}")))?;
        return print_text(&text);
    }
    print_text(&shaping_engine::compare::markdown(&tests, "# Comparison"))
}

/// `shaping report DIR [-o FILE]`.
fn report(dir: &std::path::Path, output: Option<&std::path::Path>) -> Result<(), CliError> {
    let unsealed = std::cell::RefCell::new(Vec::new());
    let path = html::write_with(dir, output, &|p| unsealed.borrow_mut().push(p.to_path_buf()))?;
    if let Some(w) = shaping_engine::files::unsealed_warning(&unsealed.borrow()) {
        eprintln!("{w}");
    }
    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    eprintln!("wrote {} ({} kB)", path.display(), size.div_ceil(1000));
    Ok(())
}

/// `shaping build FILE -o program.json`.
fn build(
    file: &std::path::Path,
    output: &std::path::Path,
    error_format: ErrorFormat,
) -> Result<(), CliError> {
    if load::same_entry(file, output) {
        return Err(CliError::invalid_setting(
            "-o",
            Some(&output.display().to_string()),
            format!(
                "error: `{}` is the file being built; give `-o` another file (e.g. `{}`)",
                output.display(),
                file.with_extension("json").display()
            ),
        ));
    }
    load::replaceable_program(output)?;
    let program = load::load_program(file, error_format)?;
    let json = serde_json::to_string_pretty(&program)
        .map_err(|e| CliError::internal(format!("error: cannot serialise the program: {e}")))?;
    load::write_atomic(output, json.as_bytes())?;
    eprintln!("wrote {} ({} stages)", output.display(), program.stages.len());
    Ok(())
}

/// A build without MPI support started by an MPI launcher with several
/// processes would run that many independent copies writing the same files:
/// `run` and `experiment` refuse.
fn refuse_without_mpi(command: &Command) -> Result<(), CliError> {
    if cfg!(feature = "mpi") || !matches!(command, Command::Run { .. } | Command::Experiment { .. }) {
        return Ok(());
    }
    match cluster::launcher() {
        Some((_, Some(size))) if size <= 1 => Ok(()),
        Some((var, size)) => {
            let n = size.map_or_else(|| "several".to_string(), |n| n.to_string());
            Err(CliError::new(shaping_engine::ErrorKind::Invalid, format!(
                "error: this `shaping` was built without MPI support, but an MPI launcher started it as one of {n} processes (`{var}` is set); rebuild it with `cargo build --release --features mpi`, or run it without `mpirun`"
            )))
        }
        None => Ok(()),
    }
}

/// `run --set`: one value each, no setting twice.
fn single_values(sets: Vec<sweep::Set>, command: &str) -> Result<Vec<sweep::Assignment>, CliError> {
    sweep::check_sets(&sets)?;
    sets.into_iter()
        .map(|s| match <[String; 1]>::try_from(s.values) {
            Ok([v]) => Ok((s.target, v)),
            Err(values) => {
                let message = format!(
                    "error: `--set {}={}`: `{command}` takes one value (`experiment` sweeps several)",
                    s.target,
                    values.join(",")
                );
                Err(CliError::invalid_setting(&s.target, Some(&values.join(",")), message))
            }
        })
        .collect()
}

/// Prints text to stdout, ending it with a newline.
fn print_text(text: &str) -> Result<(), CliError> {
    if text.ends_with('\n') {
        out!("{text}")
    } else {
        outln!("{text}")
    }
}

/// Checks every file, printing every diagnostic; the worst outcome decides the exit code.
/// With `--error-format json`, one JSON object per file on stdout, good files included.
fn check(files: &[PathBuf], format: ErrorFormat) -> Result<(), CliError> {
    let mut worst: Option<CliError> = None;
    for file in files {
        let result = shaping_engine::load::load_program(file, format);
        if format == ErrorFormat::Json {
            outln!("{}", check_json(file, &result))?;
        }
        match result {
            Ok((program, warnings)) => {
                if format != ErrorFormat::Json {
                    // Warnings do not change the exit code.
                    if let Some(w) = warnings {
                        eprintln!("{}", w.text.trim_end());
                    }
                    let genes: Vec<String> =
                        program.stages.iter().map(|s| format!("{} {} bits", s.name, s.layout.bits)).collect();
                    outln!("{}: ok ({})", file.display(), genes.join(", "))?;
                }
            }
            Err(e) => {
                if format != ErrorFormat::Json {
                    eprintln!("{e}");
                }
                // I/O problems (exit 2) outrank diagnostics (exit 1).
                if worst.as_ref().is_none_or(|w| exit_code(w) < exit_code(&e)) {
                    worst = Some(e);
                }
            }
        }
    }
    match worst {
        None => Ok(()),
        // Already printed above: exit with its code and an empty message.
        Some(e) => Err(CliError::new(e.kind(), String::new())),
    }
}

/// The JSON object `check --error-format json` prints for one file: `file`
/// and `ok` always; for a good file its stages and their genome bits; for a
/// bad one the diagnostic (`message`, `severity`, `labels`, `related`, ...).
fn check_json(
    file: &std::path::Path,
    result: &Result<(shaping_runtime::program::Program, Option<diag::Rendered>), CliError>,
) -> String {
    let name = file.display().to_string();
    let object = |v: serde_json::Value| match v {
        serde_json::Value::Object(map) => map,
        _ => serde_json::Map::new(),
    };
    let value = match result {
        Ok((program, warnings)) => {
            let stages: Vec<serde_json::Value> = program
                .stages
                .iter()
                .map(|s| serde_json::json!({"name": s.name, "bits": s.layout.bits}))
                .collect();
            let mut v = serde_json::json!({"file": name, "ok": true, "stages": stages});
            // A good file's warnings: the diagnostic object of the warnings.
            if let Some(w) = warnings {
                v["warnings"] = serde_json::to_value(&w.data).unwrap_or_default();
            }
            v
        }
        Err(e) => match e.diagnosed() {
            Some(d) => {
                let mut diagnostic = object(serde_json::to_value(d).unwrap_or_default());
                diagnostic.insert("file".into(), name.into());
                diagnostic.insert("ok".into(), false.into());
                serde_json::Value::Object(diagnostic)
            }
            None => {
                let msg = e.message().strip_prefix("error: ").unwrap_or(e.message());
                serde_json::json!({"file": name, "ok": false, "severity": "error", "message": msg})
            }
        },
    };
    value.to_string()
}
