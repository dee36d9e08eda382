//! The `shaping` command line: the only place that touches files and terminals.

mod bench;
mod diag;
mod experiment;
mod load;
mod plot;
mod replay;
mod report;
mod run;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use diag::ErrorFormat;
use load::CliError;

/// Most worker threads `--jobs` accepts.
const MAX_JOBS: u64 = 1024;
/// Most seeds an experiment runs.
const MAX_SEEDS: u64 = 10_000;

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
        #[arg(long, value_enum, default_value = "human")]
        error_format: ErrorFormat,
    },
    /// Show the genome layout the compiler derived for a stage.
    Layout {
        file: PathBuf,
        /// Stage name (default: the last stage).
        #[arg(long)]
        stage: Option<String>,
        #[arg(long, value_enum, default_value = "text")]
        format: LayoutFormat,
        #[arg(long, value_enum, default_value = "human")]
        error_format: ErrorFormat,
    },
    /// Print the module graph of a stage as Graphviz DOT.
    Graph {
        file: PathBuf,
        #[arg(long)]
        stage: Option<String>,
        #[arg(long, value_enum, default_value = "human")]
        error_format: ErrorFormat,
    },
    /// Compile to a `Program` (JSON) that `run`, `replay` and `bench` also accept.
    Build {
        file: PathBuf,
        /// Output file.
        #[arg(short, long)]
        output: PathBuf,
        #[arg(long, value_enum, default_value = "human")]
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
        #[arg(long, value_enum, default_value = "human")]
        error_format: ErrorFormat,
    },
    /// Run one individual with a trace; writes `trace.csv` and the pictures
    /// (module activations, reinforcement, trajectory).
    Replay {
        file: PathBuf,
        /// Stage to replay (default: the last).
        #[arg(long)]
        stage: Option<String>,
        /// The genome: a string of 0 and 1, or a file holding one.
        #[arg(long, conflicts_with = "run")]
        genome: Option<String>,
        /// A run directory holding `<stage>/best.genome` (default: `runs/<file stem>`).
        #[arg(long)]
        run: Option<PathBuf>,
        /// Actions to run (default: the stage's life length).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(shaping_runtime::limits::MAX_ACTIONS)))]
        actions: Option<u32>,
        /// Output directory (default: `<run>/<stage>/replay`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Episode seed (default: the run seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Switch local learning off.
        #[arg(long)]
        no_learning: bool,
        #[arg(long, value_enum, default_value = "human")]
        error_format: ErrorFormat,
    },
    /// Run every stage over several seeds and summarise (median and range):
    /// `summary.md` and a multi-seed fitness picture.
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
        /// Ignore existing checkpoints.
        #[arg(long)]
        fresh: bool,
        #[arg(long, value_enum, default_value = "human")]
        error_format: ErrorFormat,
    },
    /// Measure simulator steps and controller actions per second (one JSON line).
    Bench {
        file: PathBuf,
        #[arg(long)]
        stage: Option<String>,
        /// Timed runs; the median is reported.
        #[arg(long, default_value_t = 5, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1000))]
        runs: usize,
        #[arg(long, value_enum, default_value = "human")]
        error_format: ErrorFormat,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum LayoutFormat {
    Text,
    Json,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let msg = e.to_string();
            if !msg.is_empty() {
                eprintln!("{msg}");
            }
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

fn dispatch(command: Command) -> Result<(), CliError> {
    match command {
        Command::Check { files, error_format } => check(&files, error_format),
        Command::Layout { file, stage, format, error_format } => {
            let program = load::load_program(&file, error_format)?;
            let index = load::stage_index(&program, stage.as_deref())?;
            match format {
                LayoutFormat::Text => print_text(&shaping_compiler::render_layout(&program, index)),
                LayoutFormat::Json => {
                    let json = serde_json::to_string_pretty(&program.stages[index].layout)
                        .map_err(|e| CliError::io(format!("error: cannot serialise the layout: {e}")))?;
                    println!("{json}");
                }
            }
            Ok(())
        }
        Command::Graph { file, stage, error_format } => {
            let program = load::load_program(&file, error_format)?;
            let index = load::stage_index(&program, stage.as_deref())?;
            print_text(&shaping_compiler::render_graph(&program, index));
            Ok(())
        }
        Command::Run { file, stage, seed, out, jobs, quiet, json, fresh, error_format } => {
            run::run(run::RunArgs { file, stage, seed, out, jobs, quiet, json, fresh, error_format })
        }
        Command::Replay { file, stage, genome, run, actions, out, seed, no_learning, error_format } => {
            replay::replay(replay::ReplayArgs {
                file,
                stage,
                genome,
                run,
                actions,
                out,
                seed,
                no_learning,
                error_format,
            })
        }
        Command::Experiment { file, seeds, first_seed, out, jobs, criterion, fresh, error_format } => {
            experiment::experiment(experiment::ExperimentArgs {
                file,
                seeds,
                first_seed,
                out,
                jobs,
                criterion,
                fresh,
                error_format,
            })
        }
        Command::Bench { file, stage, runs, error_format } => {
            bench::bench(bench::BenchArgs { file, stage, runs, error_format })
        }
        Command::Build { file, output, error_format } => {
            let program = load::load_program(&file, error_format)?;
            let json = serde_json::to_string_pretty(&program)
                .map_err(|e| CliError::io(format!("error: cannot serialise the program: {e}")))?;
            load::write_atomic(&output, json.as_bytes())?;
            eprintln!("wrote {} ({} stages)", output.display(), program.stages.len());
            Ok(())
        }
    }
}

/// Prints text to stdout, ending it with a newline.
fn print_text(text: &str) {
    if text.ends_with('\n') {
        print!("{text}");
    } else {
        println!("{text}");
    }
}

/// Checks every file, printing every diagnostic; the worst outcome decides the exit code.
fn check(files: &[PathBuf], format: ErrorFormat) -> Result<(), CliError> {
    let mut worst: Option<CliError> = None;
    for file in files {
        match load::load_program(file, format) {
            Ok(program) => {
                if format != ErrorFormat::Json {
                    let genes: Vec<String> =
                        program.stages.iter().map(|s| format!("{} {} bits", s.name, s.layout.bits)).collect();
                    println!("{}: ok ({})", file.display(), genes.join(", "));
                }
            }
            Err(e) => {
                if format == ErrorFormat::Json {
                    if let CliError::Diagnostics(s) = &e {
                        println!("{}", s.trim_end());
                    } else {
                        eprintln!("{e}");
                    }
                } else {
                    eprintln!("{e}");
                }
                // I/O problems (exit 2) outrank diagnostics (exit 1).
                if worst.as_ref().is_none_or(|w| w.exit_code() < e.exit_code()) {
                    worst = Some(e);
                }
            }
        }
    }
    match worst {
        None => Ok(()),
        // Already printed above: exit with its code and an empty message.
        Some(CliError::Diagnostics(_)) => Err(CliError::Diagnostics(String::new())),
        Some(CliError::Io(_)) => Err(CliError::Io(String::new())),
    }
}
