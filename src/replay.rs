//! `shaping replay` on the terminal.

use std::path::PathBuf;

use shaping_engine::replay::{self, ReplayOptions};
use shaping_engine::sweep;

use crate::out::outln;
use crate::terminal::Terminal;
use crate::{load, CliError, ErrorFormat};

/// The arguments of `shaping replay`.
#[derive(clap::Args)]
pub struct ReplayArgs {
    pub file: PathBuf,
    /// Stage to replay (default: the last).
    #[arg(long)]
    pub stage: Option<String>,
    /// The genome: a string of 0 and 1, or a file holding one.
    #[arg(long, conflicts_with = "run")]
    pub genome: Option<String>,
    /// A run directory holding `<stage>/best.genome` (default: `runs/<file stem>`).
    #[arg(long)]
    pub run: Option<PathBuf>,
    /// Actions to run (default: the stage's life length).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(shaping_runtime::limits::MAX_ACTIONS)))]
    pub actions: Option<u32>,
    /// Output directory (default: `<run>/<stage>/replay`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Episode seed (default: the run seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Switch local learning off.
    #[arg(long)]
    pub no_learning: bool,
    /// Also write `report.html`: the episode animated in a web page.
    #[arg(long)]
    pub report: bool,
    /// Also write the episode as an animated GIF (at most 300 frames).
    #[arg(long, value_name = "FILE")]
    pub gif: Option<PathBuf>,
    /// Also write the episode as an MP4 video (needs `ffmpeg` on the PATH).
    #[arg(long, value_name = "FILE")]
    pub mp4: Option<PathBuf>,
    /// Change a setting as the run did (`--set` of `run`, one value each).
    #[arg(long = "set", value_name = "STAGE.SECTION.FIELD=VALUE", value_parser = sweep::parse_set)]
    pub sets: Vec<sweep::Set>,
    /// The robot of a team the pictures, the report and the animations follow.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub robot: u32,
    /// Live in this declared variant of the stage's world.
    #[arg(long, value_name = "NAME")]
    pub variant: Option<String>,
    #[arg(long, default_value = "human", value_parser = crate::error_format())]
    pub error_format: ErrorFormat,
}

impl ReplayArgs {
    /// The engine's options of the replay these arguments ask for (each
    /// `--set` of one value), and the format of errors.
    fn options(self) -> Result<(ReplayOptions, ErrorFormat), CliError> {
        let ReplayArgs {
            file,
            stage,
            genome,
            run,
            actions,
            out,
            seed,
            no_learning,
            report,
            gif,
            mp4,
            sets,
            robot,
            variant,
            error_format,
        } = self;
        let sets = crate::single_values(sets, "replay")?;
        let options = ReplayOptions {
            file,
            stage,
            genome,
            run,
            actions,
            out,
            seed,
            no_learning,
            report,
            gif,
            mp4,
            sets,
            robot,
            variant,
        };
        Ok((options, error_format))
    }
}

pub fn replay(args: ReplayArgs) -> Result<(), CliError> {
    let (args, error_format) = args.options()?;
    let program = load::load_program(&args.file, error_format)?;
    let r = replay::replay(program, &args, &Terminal::new(true, false))?;
    let e = &r.result;
    outln!(
        "{}: {} actions, fitness {:.3}, {} grips, {} released outside, {} recharges, {} collisions -> {}",
        r.stage,
        e.actions,
        e.fitness,
        e.grips,
        e.releases_outside,
        e.recharges,
        e.collisions,
        r.out.display()
    )?;
    if let Some(path) = r.report {
        outln!("report: {}", path.display())?;
    }
    for path in &r.animations {
        outln!("animation: {}", path.display())?;
    }
    Ok(())
}
