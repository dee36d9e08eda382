//! Reading architecture files: `.bat` sources through the compiler, or a
//! `Program` previously written by `shaping build` (`.json`).

use std::fmt;
use std::path::{Path, PathBuf};

use miette::{Diagnostic, NamedSource, SourceSpan};
use shaping_runtime::limits;
use shaping_runtime::program::{Program, StageRun, FORMAT_VERSION};

use crate::diag::{ErrorFormat, Rendered};
use crate::error::{Error, ErrorKind, Result};

use crate::RECORDED_TRAINING_ACTIONS;

/// The source file is not UTF-8: reported like any other diagnostic, pointing
/// at the first invalid byte.
#[derive(Debug)]
struct NotUtf8 {
    /// None when the invalid byte is too far into its line to be shown
    /// (miette cannot pad a label past 65535 columns).
    src: Option<NamedSource<String>>,
    name: String,
    at: SourceSpan,
}

impl std::error::Error for NotUtf8 {}

impl fmt::Display for NotUtf8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.src {
            Some(_) => write!(f, "the file is not valid UTF-8"),
            None => write!(f, "`{}` is not valid UTF-8 (byte {})", self.name, self.at.offset()),
        }
    }
}

impl Diagnostic for NotUtf8 {
    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new("architecture files are UTF-8 text; was a binary file passed by mistake?"))
    }

    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        self.src.as_ref().map(|s| s as &dyn miette::SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        self.src.as_ref()?;
        Some(Box::new(std::iter::once(miette::LabeledSpan::new_with_span(
            Some("invalid byte here".into()),
            self.at,
        ))))
    }
}

/// Reads and compiles a `.bat` file, or loads a built `Program` (`.json`);
/// the warnings of a file that compiles are rendered and returned.
pub fn load_program(path: &Path, format: ErrorFormat) -> Result<(Program, Option<Rendered>), Error> {
    if path.extension().is_some_and(|e| e == "json") {
        return Ok((load_built(path)?, None));
    }
    let source = read_source(path, format)?;
    let name = path.display().to_string();
    let (program, diagnostics) = shaping_compiler::check(&source, &name);
    let Some(program) = program else {
        return Err(Error::diagnostics(Rendered::new(&diagnostics, format, &name, &source)));
    };
    let warnings = (!diagnostics.is_empty()).then(|| Rendered::new(&diagnostics, format, &name, &source));
    // The compiler's output always validates (a property test checks it);
    // validating here too makes every command run only validated programs.
    program.validate().map_err(|e| {
        Error::internal(format!("error: internal error: `{name}` compiled to an invalid program: {e}"))
    })?;
    Ok((program, warnings))
}

/// Reads a `.bat` source; a file that is not UTF-8 is a diagnostic that
/// points at the first invalid byte.
pub fn read_source(path: &Path, format: ErrorFormat) -> Result<String, Error> {
    let bytes = crate::files::read_input_file(path)?;
    let name = path.display().to_string();
    match String::from_utf8(bytes) {
        Ok(s) => Ok(s),
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            let mut lossy = String::from_utf8_lossy(e.as_bytes()).into_owned();
            // Offsets shift in the lossy copy only after the first invalid byte.
            // Show the text up to the end of that byte's line, at most 80 bytes more.
            let mut end = lossy[at..].find('\n').map_or(lossy.len(), |i| at + i).min(at + 80);
            while !lossy.is_char_boundary(end) {
                end += 1;
            }
            lossy.truncate(end);
            let column = at - lossy[..at].rfind('\n').map_or(0, |i| i + 1);
            let src = (column <= 1000).then(|| NamedSource::new(&name, lossy.clone()));
            let report = NotUtf8 { src, name: name.clone(), at: (at, 1).into() };
            Err(Error::diagnostics(Rendered::new(&report, format, &name, &lossy)))
        }
    }
}

/// Loads a `Program` written by `shaping build`.
pub fn load_built(path: &Path) -> Result<Program, Error> {
    parse_built(&crate::files::read_input_file(path)?, &path.display().to_string())
}

/// A `Program` written by `shaping build` from its bytes (`name` names it in
/// errors): parsed, its format version checked, validated.
pub fn parse_built(bytes: &[u8], name: &str) -> Result<Program, Error> {
    let program: Program = serde_json::from_slice(bytes).map_err(|e| {
        Error::new(
            ErrorKind::Invalid,
            format!("error: `{name}` is not a program built by `shaping build`: {e}"),
        )
    })?;
    if program.format != FORMAT_VERSION {
        return Err(Error::new(
            ErrorKind::Invalid,
            format!(
                "error: `{name}` was built for program format {}, this shaping reads format {FORMAT_VERSION}; rebuild it",
                program.format
            ),
        ));
    }
    if let Err(e) = program.validate() {
        return Err(Error::new(ErrorKind::Invalid, format!("error: `{name}` is not a valid program: {e}")));
    }
    Ok(program)
}

/// The memory a run of `stages` of `program` needs at its peak (its largest
/// stage), in bytes: an evolved stage's population (see
/// `shaping_runtime::limits`) and the recording of its best's episode
/// (`episode.json`, every robot of a team), which is made while the
/// population is held; a test or training stage's recording
/// ([`recording_bytes`]).
pub fn memory_estimate(program: &Program, stages: &[usize]) -> u64 {
    stages
        .iter()
        .map(|&i| {
            let s = &program.stages[i];
            let modules = s.modules.len() as u64;
            match &s.run {
                StageRun::Evolve(e) => {
                    let population = limits::population_bytes(e.population.into(), s.layout.bits.into());
                    // The best's episode, in the stage's own world.
                    let (objects, items) = world_size(&s.world);
                    let robots = u64::from(s.robots());
                    let recorded = u64::from(e.actions).saturating_mul(robots);
                    population.saturating_add(recording_bytes(recorded, 1, modules, objects, items))
                }
                // Every action of every life of both worlds is recorded; the
                // lives before the change are in the parent's world.
                StageRun::Test { actions, lives, .. } => {
                    let parent = s.parent.and_then(|p| program.stages.get(p)).unwrap_or(s);
                    let (objects, items) = {
                        let (a, b) = (world_size(&s.world), world_size(&parent.world));
                        (a.0.max(b.0), a.1.max(b.1))
                    };
                    let lives = 2 * u64::from(*lives);
                    // A team's every robot is recorded.
                    let robots = u64::from(s.robots().max(parent.robots()));
                    let recorded = lives.saturating_mul((*actions).into()).saturating_mul(robots);
                    recording_bytes(recorded, lives, modules, objects, items)
                }
                // A training life is recorded for its first actions only.
                StageRun::Train { actions } => {
                    let (objects, items) = world_size(&s.world);
                    let recorded = u64::from((*actions).min(RECORDED_TRAINING_ACTIONS));
                    let robots = u64::from(s.robots());
                    recording_bytes(recorded.saturating_mul(robots), 1, modules, objects, items)
                }
            }
        })
        .max()
        .unwrap_or(0)
}

/// A world's objects, and its items weighted by what each costs a recorded
/// life (in units of [`RECORDED_ITEM_BYTES`]: a wall 9, a cylinder or a
/// lamp 7, a floor zone 16).
fn world_size(world: &shaping_runtime::program::World) -> (u64, u64) {
    let objects = world.objects.as_ref().map_or(0, |o| u64::from(o.count));
    let i = &world.items;
    let items = 9 * i.walls.len() + 7 * (i.cylinders.len() + i.lamps.len()) + 16 * i.zones.len();
    (objects, items as u64)
}

/// Bytes per recorded action with no module and no object: its trace row,
/// its recorded frame, its columns of `episode.json`, the text of
/// `episode.json` and `trace.csv`, each `Vec` up to twice its length.
pub const RECORDED_ACTION_BYTES: u64 = 680;
/// Bytes per recorded action per module (activation, reinforcement and
/// performance in the trace row, the episode's columns and the texts).
pub const RECORDED_MODULE_BYTES: u64 = 48;
/// Bytes per recorded action per object (the object's place in the frame).
pub const RECORDED_OBJECT_BYTES: u64 = 14;
/// Bytes per recorded life (its part of the episode: the world's scene twice,
/// its start) with no object and no item.
pub const RECORDED_LIFE_BYTES: u64 = 900;
/// Bytes per recorded life per object.
pub const RECORDED_LIFE_OBJECT_BYTES: u64 = 80;
/// Bytes per recorded life per unit of [`world_size`]'s weighted items.
pub const RECORDED_ITEM_BYTES: u64 = 8;

/// The peak memory of recording `actions` actions over `lives` lives (a
/// test stage; a training stage's recorded life), `modules` modules,
/// `objects` objects and `items` weighted items ([`world_size`]) per world:
/// the trace, the frames, the episode built from them and the text of its
/// files, which are all held at once at the peak. The constants are the
/// peak resident size (`/usr/bin/time -v`) of `shaping run` on test stages
/// of 1 to 300000 lives of 2 to 500000 actions, 1 to 20 modules, 0 to 20
/// objects and 1000 walls, cylinders or zones, rounded up: a `Vec` holds up
/// to twice its length, so the real peak is between about 0.8 and 1 times
/// the estimate.
pub fn recording_bytes(actions: u64, lives: u64, modules: u64, objects: u64, items: u64) -> u64 {
    let per_action =
        RECORDED_ACTION_BYTES + RECORDED_MODULE_BYTES * modules + RECORDED_OBJECT_BYTES * objects;
    let per_life = RECORDED_LIFE_BYTES + RECORDED_LIFE_OBJECT_BYTES * objects + RECORDED_ITEM_BYTES * items;
    actions.saturating_mul(per_action).saturating_add(lives.saturating_mul(per_life))
}

/// The memory a process may still use, and the limit that says so.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Room {
    bytes: u64,
    /// How the message says where the room is ("available", ...).
    limit: Limit,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Limit {
    /// The machine's available memory.
    Machine,
    /// The memory limit of the process's control group.
    Group,
    /// The process's address-space limit (`ulimit -v`, `RLIMIT_AS`).
    AddressSpace,
}

impl Room {
    /// "only 0.6 GiB are available" and the like.
    fn only(&self) -> String {
        let gib = self.bytes as f64 / (1u64 << 30) as f64;
        match self.limit {
            Limit::Machine => format!("only {gib:.1} GiB are available"),
            Limit::Group => format!("only {gib:.1} GiB are left under the memory limit of its control group"),
            Limit::AddressSpace => {
                format!("only {gib:.1} GiB of address space are left under its limit (`ulimit -v`)")
            }
        }
    }
}

/// The memory this process may use: the least of the machine's available
/// memory (Linux: `MemAvailable` of `/proc/meminfo`), the room under the
/// limit of its control group (`memory.max` less `memory.current`, cgroup
/// v2, as in a Slurm job) and the room under its address-space limit
/// (`ulimit -v`: the soft `RLIMIT_AS` of `/proc/self/limits` less the
/// process's `VmSize`); `None` where none can be read.
fn available_memory() -> Option<Room> {
    let machine = std::fs::read_to_string("/proc/meminfo").ok().and_then(|info| {
        let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(Room { bytes: kib * 1024, limit: Limit::Machine })
    });
    let group = std::fs::read_to_string("/proc/self/cgroup")
        .ok()
        .and_then(|c| cgroup_room(&c, Path::new("/sys/fs/cgroup")))
        .map(|bytes| Room { bytes, limit: Limit::Group });
    let address =
        match (std::fs::read_to_string("/proc/self/limits"), std::fs::read_to_string("/proc/self/status")) {
            (Ok(limits), Ok(status)) => address_room(&limits, &status),
            _ => None,
        }
        .map(|bytes| Room { bytes, limit: Limit::AddressSpace });
    [machine, group, address].into_iter().flatten().min_by_key(|r| r.bytes)
}

/// The room under the soft address-space limit of `limits` (the text of
/// `/proc/self/limits`) for a process of the `VmSize` in `status` (the
/// text of `/proc/self/status`); `None` when there is no limit.
fn address_room(limits: &str, status: &str) -> Option<u64> {
    let soft = limits.lines().find_map(|l| l.strip_prefix("Max address space"))?.split_whitespace().next()?;
    let limit: u64 = soft.parse().ok()?;
    let size: u64 =
        status.lines().find_map(|l| l.strip_prefix("VmSize:"))?.split_whitespace().next()?.parse().ok()?;
    Some(limit.saturating_sub(size.saturating_mul(1024)))
}

/// The room left under the cgroup v2 memory limit of the group named in
/// `proc_cgroup` (the text of `/proc/self/cgroup`) under `root`, and of its
/// ancestors: the least `memory.max - memory.current` of them (`None` when no
/// group sets a limit).
fn cgroup_room(proc_cgroup: &str, root: &Path) -> Option<u64> {
    let group = proc_cgroup.lines().find_map(|l| l.strip_prefix("0::"))?.trim().trim_start_matches('/');
    let mut dir = root.join(group);
    let mut room: Option<u64> = None;
    loop {
        let read = |f: &str| std::fs::read_to_string(dir.join(f)).ok();
        if let Some(max) = read("memory.max").and_then(|m| m.trim().parse::<u64>().ok()) {
            let used = read("memory.current").and_then(|c| c.trim().parse::<u64>().ok()).unwrap_or(0);
            let left = max.saturating_sub(used);
            room = Some(room.map_or(left, |r| r.min(left)));
        }
        if dir == root || !dir.pop() || !dir.starts_with(root) {
            return room;
        }
    }
}

/// Refuses, before anything starts, a run of `stages` that would need more
/// memory than the machine has available, with the estimate. `copies` runs
/// are held at once (an experiment's seeds run one after another: 1).
pub fn check_memory(program: &Program, stages: &[usize], copies: u64) -> Result<()> {
    check_memory_within(program, stages, copies, available_memory())
}

/// Refuses to take `need` bytes for `what` ("evaluating 2 genomes") where
/// this process has not the room ([`available_memory`]; where nothing can
/// be read, above 1 TiB, which no machine has): an error of kind `Memory`
/// that says how much is needed, under which limit how much is left, and
/// `instead`, what to do.
pub fn check_room(need: u64, what: &str, instead: &str) -> Result<()> {
    let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
    let refuse = |left: String| {
        Error::new(
            ErrorKind::Memory,
            format!("error: {what} needs about {:.1} GiB of memory{left}; {instead}", gib(need)),
        )
    };
    match available_memory() {
        Some(room) if need > room.bytes => Err(refuse(format!(", but {}", room.only()))),
        None if need > 1 << 40 => Err(refuse(String::new())),
        _ => Ok(()),
    }
}

fn check_memory_within(
    program: &Program,
    stages: &[usize],
    copies: u64,
    available: Option<Room>,
) -> Result<()> {
    let need = memory_estimate(program, stages).saturating_mul(copies.max(1));
    match available {
        Some(have) if need > have.bytes => {
            let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
            let Some(biggest) = stages.iter().copied().max_by_key(|&i| memory_estimate(program, &[i])) else {
                return Ok(());
            };
            let stage = &program.stages[biggest];
            // What to make smaller: a team's robots too (every robot of its
            // best's episode is recorded).
            let robots = if stage.robots() > 1 { ", the number of robots" } else { "" };
            let what = match stage.run {
                StageRun::Evolve(_) => format!("the population, the genome{robots} or the number of actions"),
                StageRun::Test { .. } => format!("the number of lives{robots} or of actions"),
                StageRun::Train { .. } => format!("the number of actions{robots}"),
            };
            Err(Error::new(
                ErrorKind::Memory,
                format!(
                    "error: this run needs about {:.1} GiB of memory (stage `{}`), but {}; reduce {what}",
                    gib(need),
                    stage.name,
                    have.only(),
                ),
            ))
        }
        _ => Ok(()),
    }
}

/// Refuses, before it starts, a recorded episode of `actions` actions of
/// `stage` (`replay`: a training stage's life may be millions of actions;
/// a team's every robot is recorded) that would need more memory than the
/// machine has available.
pub fn check_recording(stage: &shaping_runtime::program::Stage, actions: u32) -> Result<()> {
    check_recording_within(stage, actions, available_memory())
}

fn check_recording_within(
    stage: &shaping_runtime::program::Stage,
    actions: u32,
    available: Option<Room>,
) -> Result<()> {
    let (objects, items) = world_size(&stage.world);
    // A team's every robot is recorded.
    let recorded = u64::from(actions).saturating_mul(u64::from(stage.robots()));
    let need = recording_bytes(recorded, 1, stage.modules.len() as u64, objects, items);
    match available {
        Some(have) if need > have.bytes => {
            let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
            Err(Error::new(
                ErrorKind::Memory,
                format!(
                    "error: recording {actions} actions of stage `{}` needs about {:.1} GiB of memory, but {}; \
                     pass fewer `--actions`",
                    stage.name,
                    gib(need),
                    have.only()
                ),
            ))
        }
        _ => Ok(()),
    }
}

/// Resolves `--stage NAME` to a stage index; without a name, the last stage.
pub fn stage_index(program: &Program, stage: Option<&str>) -> Result<usize, Error> {
    match stage {
        None => {
            if program.stages.is_empty() {
                Err(Error::new(ErrorKind::Invalid, "error: the program has no stages"))
            } else {
                Ok(program.stages.len() - 1)
            }
        }
        Some(name) => program.stage(name).map(|(i, _)| i).ok_or_else(|| {
            let names: Vec<&str> = program.stages.iter().map(|s| s.name.as_str()).collect();
            Error::new(
                ErrorKind::Invalid,
                format!("error: there is no stage `{name}`; the stages are: {}", names.join(", ")),
            )
        }),
    }
}

/// Writing `output` (a new file renamed over its directory entry) would
/// replace `input`: the same directory entry, or the file `input` names
/// through symbolic links. (A symbolic link at `output` is replaced itself,
/// not what it points to.)
pub fn same_entry(input: &Path, output: &Path) -> bool {
    let entry = |p: &Path| -> Option<PathBuf> {
        let parent = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(std::fs::canonicalize(parent).ok()?.join(p.file_name()?))
    };
    let Some(out) = entry(output) else { return false };
    entry(input).is_some_and(|e| e == out) || std::fs::canonicalize(input).is_ok_and(|real| real == out)
}

/// `build -o FILE`: FILE is new or an earlier built program (a JSON object
/// with `format` and `stages`); anything else there would be lost: refused.
pub fn replaceable_program(out: &Path) -> Result<()> {
    let Ok(meta) = std::fs::metadata(out) else { return Ok(()) };
    let built = meta.is_file()
        && std::fs::read(out)
            .ok()
            .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
            .is_some_and(|v| {
                v.get("format").is_some() && v.get("stages").is_some_and(serde_json::Value::is_array)
            });
    if built {
        return Ok(());
    }
    Err(Error::invalid_setting(
        "-o",
        Some(&out.display().to_string()),
        format!(
            "error: `{}` exists and is not a program `shaping build` wrote; `build -o` replaces only such a file \
             (choose a new file, e.g. one ending in `.json`)",
            out.display()
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn program(population: u32, bits: u32) -> Program {
        let mut stage = shaping_runtime::testkit::navigation();
        if let StageRun::Evolve(e) = &mut stage.run {
            e.population = population;
        }
        stage.layout.bits = bits;
        Program { format: FORMAT_VERSION, name: "p".into(), stages: vec![stage] }
    }

    fn room(bytes: u64) -> Option<Room> {
        Some(Room { bytes, limit: Limit::Machine })
    }

    #[test]
    fn a_run_larger_than_the_available_memory_is_refused_with_the_estimate() {
        let p = program(100_000, 5_000);
        let need = memory_estimate(&p, &[0]);
        let s = &p.stages[0];
        let StageRun::Evolve(e) = &s.run else { unreachable!() };
        let (objects, items) = world_size(&s.world);
        let best = recording_bytes(e.actions.into(), 1, s.modules.len() as u64, objects, items);
        assert_eq!(need, 100_000 * 5_000 * (2 + limits::CHECKPOINT_BYTES_PER_BIT) + best);
        assert!(check_memory_within(&p, &[0], 1, room(need)).is_ok());
        assert!(check_memory_within(&p, &[0], 1, None).is_ok(), "unknown memory: no refusal");
        let err = check_memory_within(&p, &[0], 1, room(4 << 30)).unwrap_err().to_string();
        assert!(
            err.contains(
                "needs about 6.5 GiB of memory (stage `navigation`), but only 4.0 GiB are available"
            ),
            "{err}"
        );
        assert!(err.contains("reduce the population, the genome or the number of actions"), "{err}");
    }

    /// The episode of an evolved team's best is recorded robot by robot
    /// while the population is held: 10,000 robots of 1,000 actions need
    /// gigabytes where the population needs a few megabytes (a run that
    /// went over `ulimit -v` after its checkpoint, at every rerun).
    #[test]
    fn an_evolved_team_is_estimated_with_the_recording_of_its_best() {
        let mut p = program(20, 100);
        let s = &mut p.stages[0];
        s.world.robots = 10_000;
        if let StageRun::Evolve(e) = &mut s.run {
            e.actions = 1_000;
        }
        let need = memory_estimate(&p, &[0]);
        assert!(need > 6 << 30, "{need}");
        let address = Room { bytes: 600 << 20, limit: Limit::AddressSpace };
        let err = check_memory_within(&p, &[0], 1, Some(address)).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::Memory);
        let err = err.to_string();
        assert!(
            err.contains("but only 0.6 GiB of address space are left under its limit (`ulimit -v`)"),
            "{err}"
        );
        assert!(
            err.contains("reduce the population, the genome, the number of robots or the number of actions")
        );
    }

    #[test]
    fn the_address_space_limit_leaves_the_room_above_the_process_size() {
        let limits = "Limit                     Soft Limit           Hard Limit           Units     \n\
                      Max cpu time              unlimited            unlimited            seconds   \n\
                      Max address space         716800000            unlimited            bytes     \n";
        let status = "Name:\tshaping\nVmPeak:\t  200000 kB\nVmSize:\t  100000 kB\nVmRSS:\t 5000 kB\n";
        assert_eq!(address_room(limits, status), Some(716_800_000 - 100_000 * 1024));
        let unlimited = limits.replace("716800000", "unlimited");
        assert_eq!(address_room(&unlimited, status), None);
        assert_eq!(address_room(limits, "Name:\tx\n"), None);
    }

    /// A test stage of `lives` lives of `actions` actions with `modules`
    /// modules, `objects` objects and `items` cylinders, walls or zones.
    fn test_program(lives: u32, actions: u32, modules: usize, objects: u32, items: &str) -> Program {
        let modules: String =
            (0..modules).map(|i| format!(" module m{i} {{ sense ir behavior forward }}")).collect();
        let objects = if objects > 0 { format!("objects {objects}") } else { String::new() };
        let items: String = (0..1000)
            .map(|x| {
                let x = 2.0 + 0.9 * f64::from(x);
                match items {
                    "cylinders" => format!("cylinder at ({x:.1}mm, 10mm) diameter 0.5mm\n"),
                    "walls" => format!("wall from ({x:.1}mm, 980mm) to ({:.1}mm, 980mm)\n", x + 0.5),
                    "zones" => {
                        format!("zone from ({x:.1}mm, 990mm) to ({:.1}mm, 1000mm) grey 0.5\n", x + 0.9)
                    }
                    _ => String::new(),
                }
            })
            .collect();
        let src = format!(
            "robot r {{ sensor ir[8] proximity  actuator wheels[2] speed }}\n\
             stage explore {{ evolve {{ population 4 generations 2 actions 30 }} \
             world {{ arena 1000mm x 1000mm {objects}\n{items} }} fitness per action wheels[0]{modules} }}\n\
             stage t extends explore {{ test best for {lives} lives of {actions} actions with learning }}\n"
        );
        shaping_compiler::compile(&src, "t.bat").unwrap()
    }

    /// The estimate against the peak resident size of `shaping run` on these
    /// test stages (`/usr/bin/time -f %M`, kB), less that of a test of 10
    /// actions (11736 kB: the process and the explore stage): never more
    /// than 5% under, at most 1.6 times over.
    #[test]
    fn a_test_stage_is_estimated_by_what_it_records() {
        // lives, actions, modules, objects, items, measured peak kB
        let measured = [
            (500_000, 2, 1, 0, "", 1_894_240),
            (1, 1_000_000, 1, 0, "", 1_140_668),
            (1, 150_000, 1, 0, "", 222_024),
            (1, 300_000, 1, 0, "", 354_316),
            (1, 150_000, 20, 0, "", 487_600),
            (1, 100_000, 1, 20, "", 192_780),
            (50_000, 2, 1, 0, "", 230_320),
            (50_000, 2, 1, 20, "", 438_760),
            (50_000, 2, 20, 0, "", 375_596),
            (10_000, 2, 1, 0, "", 56_872),
            (10, 50_000, 5, 8, "", 831_192),
            (20_000, 2, 1, 0, "cylinders", 1_740_012),
            (20_000, 2, 1, 0, "walls", 2_518_680),
            (10_000, 2, 1, 0, "zones", 2_358_804),
        ];
        for (lives, actions, modules, objects, items, kb) in measured {
            let p = test_program(lives, actions, modules, objects, items);
            let estimate = memory_estimate(&p, &[1]) as f64;
            let ratio = estimate / ((kb - 11_736) as f64 * 1024.0);
            assert!(
                (0.95..=1.6).contains(&ratio),
                "{lives} lives of {actions} actions, {modules} modules, {objects} objects, {items}: \
                 estimate {estimate} bytes, {ratio:.2} times the measured peak"
            );
        }
    }

    #[test]
    fn the_memory_limit_of_a_control_group_is_the_least_room_of_it_and_its_parents() {
        let root = tempfile::tempdir().unwrap();
        let job = root.path().join("slurm/job_7");
        std::fs::create_dir_all(&job).unwrap();
        std::fs::write(root.path().join("slurm/memory.max"), "8000\n").unwrap();
        std::fs::write(root.path().join("slurm/memory.current"), "1000\n").unwrap();
        std::fs::write(job.join("memory.max"), "4000\n").unwrap();
        std::fs::write(job.join("memory.current"), "500\n").unwrap();
        assert_eq!(cgroup_room("0::/slurm/job_7\n", root.path()), Some(3500));
        std::fs::write(job.join("memory.max"), "max\n").unwrap();
        assert_eq!(cgroup_room("0::/slurm/job_7\n", root.path()), Some(7000));
        assert_eq!(cgroup_room("1:memory:/x\n", root.path()), None, "cgroup v1: not read");
    }

    #[test]
    fn a_replay_larger_than_the_available_memory_is_refused() {
        let p = test_program(1, 10, 3, 0, "");
        let stage = &p.stages[0];
        let need = recording_bytes(10_000_000, 1, 3, 0, 0);
        assert!(check_recording_within(stage, 10_000_000, room(need)).is_ok());
        assert!(check_recording_within(stage, 10_000_000, None).is_ok());
        let err = check_recording_within(stage, 10_000_000, room(need - 1)).unwrap_err().to_string();
        assert!(err.contains("recording 10000000 actions of stage `explore` needs about 7.7 GiB"), "{err}");
        assert!(err.contains("pass fewer `--actions`"), "{err}");
    }

    #[test]
    fn a_training_stage_is_estimated_by_the_actions_it_traces() {
        let mut p = program(100, 10);
        let modules = p.stages[0].modules.len() as u64;
        p.stages[0].run = StageRun::Train { actions: 10_000_000 };
        let (objects, items) = world_size(&p.stages[0].world);
        let traced = u64::from(RECORDED_TRAINING_ACTIONS);
        assert_eq!(memory_estimate(&p, &[0]), recording_bytes(traced, 1, modules, objects, items));
        p.stages[0].run = StageRun::Train { actions: 1000 };
        assert_eq!(memory_estimate(&p, &[0]), recording_bytes(1000, 1, modules, objects, items));
    }
}
