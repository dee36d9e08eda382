//! Pictures of the project's results, drawn from plain data.
//!
//! Every function writes two files next to each other, `<stem>.svg` and
//! `<stem>.png`, creating the parent folder if needed. The inputs are plain
//! owned data defined here (the caller converts from runtime types), the
//! output is deterministic (the same data give the same SVG bytes on the same
//! machine), and no input makes these functions panic: bad input and failed
//! writes come back as a [`PlotError`] that names the file.
//!
//! Text is drawn with a system TrueType font registered at first use (see
//! [`font_path`]); without one the pictures are drawn without any text.

mod arena;
mod fitness;
mod points;
mod render;
mod series;
mod trace;

#[cfg(test)]
mod tests;

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

#[allow(unused_imports)]
pub use render::font_path;
#[allow(unused_imports)]
pub use series::rolling_mean;

/// Best and mean fitness of one generation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenPoint {
    /// Generation number, continuing across stages.
    pub generation: u32,
    /// Fitness of the best individual.
    pub best: f32,
    /// Mean fitness of the population.
    pub mean: f32,
}

/// What the robot and its modules did over one test run, one entry per action.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ActivationTrace {
    /// Module names, in the order of the columns of `activations`.
    pub modules: Vec<String>,
    /// Per action, the activation of every module (expected in 0..1; clamped).
    pub activations: Vec<Vec<f32>>,
    /// Per action, the index of the winning module; an index outside
    /// `modules` means no module won.
    pub winner: Vec<u16>,
    /// Per action, the battery level in 0..1; empty to leave the band out.
    pub battery: Vec<f32>,
    /// Per action, whether an object is in the gripper; empty to leave the band out.
    pub holding: Vec<bool>,
}

/// An object lying in the arena.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneObject {
    /// Centre, mm.
    pub x: f32,
    /// Centre, mm.
    pub y: f32,
    /// Radius, mm.
    pub radius: f32,
    /// A virtual object (sensed but not physical).
    pub virtual_: bool,
    /// Already picked up (drawn greyed out where it lies).
    pub collected: bool,
}

/// A top view of one run: the world and the path of the robot.
///
/// Coordinates are in mm with the origin at a corner of the arena, x to the
/// right, y up, heading counter-clockwise from +x in radians.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrajectoryScene {
    /// Width and height of the arena, mm.
    pub arena: [f32; 2],
    /// End points of the charger bar, mm.
    pub bar: Option<([f32; 2], [f32; 2])>,
    /// Position of the lamp, mm.
    pub lamp: Option<[f32; 2]>,
    /// Inner walls' end points, mm.
    pub walls: Vec<([f32; 2], [f32; 2])>,
    /// Cylinders: centre x, y and radius, mm.
    pub cylinders: Vec<[f32; 3]>,
    /// Declared lamps' positions, mm.
    pub lamps: Vec<[f32; 2]>,
    /// The indices in `lamps` of the lamps that are off (drawn dark).
    pub dark_lamps: Vec<usize>,
    /// Floor zones: south-west and north-east corners, grey level (0 black
    /// .. 1 white) and whether the zone is a charger.
    pub zones: Vec<([f32; 2], [f32; 2], f32, bool)>,
    /// Objects to draw.
    pub objects: Vec<SceneObject>,
    /// Pose `[x, y, theta]` after every action.
    pub path: Vec<[f32; 3]>,
    /// Radius of the robot body, mm.
    pub body_radius: f32,
    /// Labelled events at a path index (e.g. grip events).
    pub marks: Vec<(usize, String)>,
    /// Winning module per path point; when given the path is coloured by
    /// module instead of by time. Must have the length of `path`.
    pub path_modules: Option<Vec<u16>>,
    /// Names of the modules indexed by `path_modules` (legend only).
    pub module_names: Vec<String>,
    /// A team's other robots (1, 2, ...): each one's poses `[x, y, theta]`
    /// after every action, drawn one colour each with the robot's number
    /// at its start and its body at its end (empty for one robot).
    pub others: Vec<Vec<[f32; 3]>>,
    /// A heterogeneous team's roles, in order, and how many robots play
    /// each (robot 0 plays the first; empty without roles): each role's
    /// robots are drawn in its colour, named in the legend.
    pub roles: Vec<(String, u32)>,
    /// The team's robot whose path is `path` (0 unless a replay follows
    /// another, `replay --robot`); `others` are the rest, in order.
    pub robot: usize,
}

/// A picture could not be drawn or written.
#[derive(Debug)]
pub enum PlotError {
    /// The data cannot be drawn; `path` is the stem of the two files.
    Input { path: PathBuf, message: String },
    /// Writing a file failed.
    Io { path: PathBuf, source: io::Error },
    /// The plotting library failed while drawing a file.
    Draw { path: PathBuf, message: String },
}

impl PlotError {
    fn input(stem: &Path, message: impl Into<String>) -> PlotError {
        PlotError::Input { path: stem.to_path_buf(), message: message.into() }
    }

    /// The file (or stem) the error is about.
    #[allow(dead_code)]
    pub fn path(&self) -> &Path {
        match self {
            PlotError::Input { path, .. } | PlotError::Io { path, .. } | PlotError::Draw { path, .. } => path,
        }
    }
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlotError::Input { path, message } => write!(f, "cannot plot `{}`: {message}", path.display()),
            PlotError::Io { path, source } => write!(f, "cannot write `{}`: {source}", path.display()),
            PlotError::Draw { path, message } => write!(f, "cannot draw `{}`: {message}", path.display()),
        }
    }
}

/// A picture that cannot be drawn: its data ([`crate::ErrorKind::Invalid`])
/// or the system ([`crate::ErrorKind::Io`]), about its file.
impl From<PlotError> for crate::Error {
    fn from(e: PlotError) -> crate::Error {
        let (kind, operation) = match &e {
            PlotError::Input { .. } => (crate::ErrorKind::Invalid, "plot"),
            PlotError::Io { source, .. } if source.kind() == io::ErrorKind::NotFound => {
                (crate::ErrorKind::NotFound, "write")
            }
            PlotError::Io { .. } => (crate::ErrorKind::Io, "write"),
            PlotError::Draw { .. } => (crate::ErrorKind::Io, "draw"),
        };
        let subject = crate::Subject::File { path: e.path().to_path_buf(), operation: operation.to_string() };
        crate::Error::new(kind, format!("error: {e}")).about(subject)
    }
}

impl std::error::Error for PlotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            PlotError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Best (solid) and mean (dash-dotted) fitness per generation, with a dashed
/// vertical marker and name where each stage starts (figures 4 and 9).
/// `smooth` applies the paper's trailing rolling mean over 3 generations.
pub fn fitness_curves(
    stem: &Path,
    title: &str,
    gens: &[GenPoint],
    stage_starts: &[(u32, String)],
    smooth: bool,
) -> Result<(), PlotError> {
    if gens.is_empty() {
        return Err(PlotError::input(stem, "no generations to plot"));
    }
    render::render(stem, &fitness::Single { title, gens, stages: stage_starts, smooth })
}

/// Median best and median mean fitness over several runs (seeds), each with
/// its min–max band, aligned by generation number.
pub fn multi_seed_fitness(
    stem: &Path,
    title: &str,
    runs: &[Vec<GenPoint>],
    stage_starts: &[(u32, String)],
) -> Result<(), PlotError> {
    if runs.iter().all(|r| r.is_empty()) {
        return Err(PlotError::input(stem, "no generations to plot"));
    }
    render::render(stem, &fitness::Multi { title, runs, stages: stage_starts })
}

/// One stage's figures over the points of a sweep: per point, the median,
/// minimum and maximum over the seeds (`None` where it has none).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSeries {
    pub stage: String,
    pub values: Vec<Option<(f64, f64, f64)>>,
}

/// The points of a sweep along x (1, 2, ..., each tick named by its
/// `labels`), one marker per stage at the median with a bar from minimum
/// to maximum.
pub fn sweep_points(
    stem: &Path,
    title: &str,
    series: &[SweepSeries],
    (axis, labels): (&str, &[String]),
) -> Result<(), PlotError> {
    let points = series.iter().map(|s| s.values.len()).max().unwrap_or(0);
    if points == 0 || series.iter().all(|s| s.values.iter().all(Option::is_none)) {
        return Err(PlotError::input(stem, "no points to plot"));
    }
    render::render(stem, &points::Points { title, points, series, axis, labels })
}

/// Trailing rolling mean (over `window` actions) of reinforcement values in
/// -1..1, one line per named series, on a fixed -1..1 axis with a zero line
/// and labelled vertical marks at action indices (figures 5, 10 and 13); a
/// mark with an empty label is drawn as a light dotted line.
/// Pass `window = 1` for series that are already smoothed.
pub fn rolling_reinforcement(
    stem: &Path,
    title: &str,
    series: &[(String, Vec<f32>)],
    window: usize,
    marks: &[(u32, String)],
) -> Result<(), PlotError> {
    if window == 0 {
        return Err(PlotError::input(stem, "the rolling window must be at least 1"));
    }
    if series.iter().all(|(_, v)| v.is_empty()) {
        return Err(PlotError::input(stem, "no reinforcement values to plot"));
    }
    render::render(stem, &series::Reinforcement { title, series, window, marks })
}

/// One band per module showing its activation over the actions, filled where
/// the module wins, plus bands for the battery level and for an object held
/// (figure 11).
pub fn activation_trace(stem: &Path, title: &str, t: &ActivationTrace) -> Result<(), PlotError> {
    trace::check(t).map_err(|m| PlotError::input(stem, m))?;
    render::render(stem, &trace::Trace { title, t })
}

/// Top view of the arena to scale: walls, charger bar, lamp, objects, the path
/// coloured by time (or by winning module), marks, and the final pose.
pub fn trajectory(stem: &Path, title: &str, scene: &TrajectoryScene) -> Result<(), PlotError> {
    arena::check(scene).map_err(|m| PlotError::input(stem, m))?;
    render::render(stem, &arena::Arena::new(title, scene))
}

/// An RGB picture in memory: `height` rows of `width` pixels, 3 bytes each.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rgb {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<u8>,
}

/// [`trajectory`] drawn into memory, without text (the same size whatever
/// the fonts): the frames of an animation or of a Gymnasium environment.
/// Objects outside the arena are left out, so that every frame of a world
/// has one size.
pub fn trajectory_rgb(scene: &TrajectoryScene) -> Result<Rgb, PlotError> {
    let stem = Path::new("frame");
    let mut inside = scene.clone();
    let [w, h] = scene.arena;
    inside.objects.retain(|o| (0.0..=w).contains(&o.x) && (0.0..=h).contains(&o.y));
    arena::check(&inside).map_err(|m| PlotError::input(stem, m))?;
    render::to_rgb(stem, &arena::Arena::new("", &inside))
}
