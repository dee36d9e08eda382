//! The data a report embeds, gathered from the files a run, an experiment or
//! a replay wrote: `program.json`, and per stage `generations.csv`,
//! `best.genome`, `episode.json` and `summary.json`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Serialize;
use shaping_runtime::evolve::{ranking, Checkpoint};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{
    Action, Behavior, Decode, Event, LearnTarget, LearnWhen, Param, Program, Stage, StageRun, StepEnd, World,
};

use crate::episode::{Episode, TeamColumns, EPISODE_FORMAT};
use crate::error::{Error, ErrorKind};
use crate::files::{read_checked, Unsealed};
use crate::rundir::{ExperimentSummary, GenRow, PointSummary, StageFigures};
use crate::{load, rundir};

/// The most robots of a team a report can follow (robot 0 and the next
/// ones): a larger team's others are drawn, not followed, so that the page
/// stays small.
pub const MAX_FOLLOWED: usize = 100;

/// The columns of the team of episode `ep` in `dir` (see
/// [`ReportData::robots`]): one that is not of that episode (other robots,
/// other lengths) is an error naming it.
fn read_team(dir: &Path, ep: &Episode, u: Unsealed<'_>) -> Result<Option<TeamColumns>, Error> {
    let Some(mut t) = rundir::read_robots(dir, u)? else { return Ok(None) };
    let n = ep.actions.x.len();
    let fits = |r: &crate::episode::RobotColumns| {
        let c = &r.actions;
        [c.x.len(), c.y.len(), c.theta.len(), c.winner.len(), c.battery.len(), c.ir.len(), c.wheels.len()]
            .iter()
            .all(|&k| k == n)
            && [&c.activation, &c.reinforcement, &c.performance]
                .iter()
                .all(|v| v.len() == r.modules.len() && v.iter().all(|m| m.len() == n))
    };
    if t.robots.len() != ep.actions.others.len() || !t.robots.iter().all(fits) {
        let path = rundir::robots_path(dir);
        return Err(Error::damaged(
            &path,
            "not of the episode beside it",
            format!(
                "error: `{}` is not of the episode beside it (other robots, or columns of other lengths); replay the stage again",
                path.display()
            ),
        ));
    }
    t.robots.truncate(MAX_FOLLOWED - 1);
    Ok(Some(t))
}

/// The range-and-bearing board of episode `ep`, from its team's
/// `robots.json` (`team`, as [`read_team`] read it; see
/// [`ReportData::boards`]), for the robots the page can follow; `None`
/// without a team or a board. A board that is not of the episode (other
/// robots, other lengths) is an error naming the file in `dir`.
fn read_board(
    dir: &Path,
    program: &Program,
    ep: &Episode,
    team: Option<&mut TeamColumns>,
) -> Result<Option<BoardView>, Error> {
    let Some(mut columns) = team.and_then(|t| t.board.take()) else { return Ok(None) };
    let n = ep.actions.x.len();
    let width = columns.names.len();
    let fits = columns.robots.len() == 1 + ep.actions.others.len()
        && columns.robots.iter().all(|r| r.len() == n && r.iter().all(|v| v.is_empty() || v.len() == width));
    if !fits {
        let path = rundir::robots_path(dir);
        return Err(Error::damaged(
            &path,
            "the board is not of the episode beside it",
            format!(
                "error: the board in `{}` is not of the episode beside it (other robots, or columns of other lengths); replay the stage again",
                path.display()
            ),
        ));
    }
    columns.robots.truncate(MAX_FOLLOWED);
    let worlds = ep
        .worlds
        .iter()
        .map(|w| {
            let rab = program.stage(&w.stage).and_then(|(_, s)| s.world.body.rab.as_ref());
            BoardWorld { range: rab.map_or(0.0, |r| r.range), occlusion: rab.is_some_and(|r| r.occlusion) }
        })
        .collect();
    Ok(Some(BoardView { worlds, columns }))
}

/// The range-and-bearing board of an episode, for the page: what each
/// robot's board read and sent at each action (the readout), and, per
/// world, what the replay needs to draw who hears whom.
#[derive(Clone, Debug, Serialize)]
pub struct BoardView {
    /// One per world of the episode (`Episode::worlds`, in order).
    pub worlds: Vec<BoardWorld>,
    #[serde(flatten)]
    pub columns: crate::episode::BoardColumns,
}

/// The board in one world of an episode.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct BoardWorld {
    /// How far robots perceive and hear each other, body surface to body
    /// surface, mm (`rab_range`; 0 in a world without a board).
    pub range: f32,
    /// Inner walls and cylinders between two robots' centres hide them
    /// from each other (`rab_occlusion`).
    pub occlusion: bool,
}

/// Version of the data embedded in a report.
pub const REPORT_FORMAT: u32 = 1;

#[derive(Clone, Debug, Serialize)]
pub struct ReportData {
    pub format: u32,
    /// The program's name.
    pub title: String,
    /// `run`, `experiment`, `sweep`, `stage` or `replay`.
    pub kind: &'static str,
    /// The directory the report was made from, as given.
    pub source: String,
    pub generator: String,
    /// The seeds of an experiment (empty otherwise).
    pub seeds: Vec<u64>,
    /// Where the episodes come from, in words (for an experiment: which seed).
    pub episodes_note: String,
    /// An experiment's seed whose genomes, episodes and test results are shown.
    pub shown_seed: Option<u64>,
    pub stages: Vec<StageView>,
    /// One series per evolved stage, in program order.
    pub fitness: Vec<FitnessSeries>,
    pub episodes: Vec<Episode>,
    /// One per episode, in order: a team's other robots' columns
    /// (`robots.json`, at most [`MAX_FOLLOWED`] robots in all), which the
    /// page's readout and timeline can follow; `None` for one robot.
    pub robots: Vec<Option<TeamColumns>>,
    /// One per episode, in order: its range-and-bearing board, for robot 0
    /// and the robots of `robots` (taken out of its `robots.json`, so that
    /// the page holds it once), which the readout shows and the replay
    /// draws; `None` without a board.
    pub boards: Vec<Option<BoardView>>,
    /// The `summary.json` of the sweep this experiment is a point of (or,
    /// for a sweep's own directory, of the sweep): every point's settings
    /// and figures, listed by the page.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep: Option<serde_json::Value>,
    /// The name of the point shown (its settings).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep_point: Option<String>,
    /// An experiment's or a sweep's statistics: the `tests` of its
    /// `summary.json`, as the experiment computed them (the page shows
    /// them; a summary written before them has none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tests: Option<crate::rundir::Tests>,
}

#[derive(Clone, Debug, Serialize)]
pub struct StageView {
    pub name: String,
    pub parent: Option<String>,
    /// How the stage runs: `evolve, 40 generations of 100, 300 actions`.
    pub run: String,
    pub world: String,
    pub fitness: String,
    /// What this stage adds to or changes in the stage it extends.
    pub added: Vec<String>,
    pub sensors: Vec<String>,
    pub modules: Vec<ModuleView>,
    pub links: Vec<LinkView>,
    pub genes: Vec<GeneView>,
    /// Where the decoded gene values come from (`collect/best.genome`), if any.
    pub genome: Option<String>,
    /// `summary.json` of a test stage.
    pub results: Option<serde_json::Value>,
    /// Where the frozen genes of the best individual come from: which
    /// individual of the parent stage's final population (see [`provenance`]).
    pub frozen_from: Option<String>,
    /// When the stage's world was too crowded to place apart in some of its
    /// episodes (`checkpoint.json`'s statistics, a test's `summary.json`, a
    /// training stage's `trained.json`): how many, in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crowded: Option<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ModuleView {
    pub name: String,
    /// The stage that introduced the module.
    pub stage: String,
    /// Introduced by this stage.
    pub new: bool,
    pub sensors: Vec<String>,
    pub behavior: String,
    pub learning: Option<String>,
    pub reinforce: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct LinkView {
    pub from: u16,
    pub to: u16,
    /// `gene`, `fixed` or `random`.
    pub kind: &'static str,
    /// The weight: decoded from the best genome, or the constant.
    pub weight: Option<f32>,
    pub gene: Option<u32>,
    pub frozen: bool,
    pub new: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct GeneView {
    pub index: u32,
    pub offset: u32,
    pub bits: u8,
    pub stage: String,
    pub module: String,
    pub role: String,
    pub lo: f32,
    pub hi: f32,
    pub frozen: bool,
    /// Decoded from the best genome.
    pub value: Option<f32>,
    /// The gene's bits in the best genome.
    pub code: Option<String>,
    /// For a frozen gene whose value differs from the parent stage's
    /// `best.genome`: the value there.
    pub parent_value: Option<f32>,
}

/// Best and mean fitness per generation of one stage; for an experiment the
/// medians over seeds, with the range of the best.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FitnessSeries {
    pub stage: String,
    /// Global generation numbers, continuing across stages.
    pub generation: Vec<u32>,
    pub best: Vec<f32>,
    pub mean: Vec<f32>,
    /// Experiment only: lowest and highest best over seeds.
    pub best_min: Vec<f32>,
    pub best_max: Vec<f32>,
    /// Experiment only: how many seeds have this generation.
    pub seeds: Vec<u32>,
}

/// The bytes of `path` as the run wrote them: checked against its seal
/// (a damaged file is an error naming it; one without a seal is read and
/// `u` told).
fn read_sealed(path: &Path, u: Unsealed<'_>) -> Result<Vec<u8>, Error> {
    read_checked(path, rundir::REWRITE, u)?
        .map(|f| f.bytes)
        .ok_or_else(|| Error::file(crate::ErrorKind::NotFound, "read", path, "there is no such file"))
}

fn read_episode(path: &Path, u: Unsealed<'_>) -> Result<Episode, Error> {
    let bytes = read_sealed(path, u)?;
    let ep: Episode = serde_json::from_slice(&bytes).map_err(|e| {
        let problem = format!("not an episode written by shaping: {e}");
        Error::damaged(path, &problem, format!("error: `{}` is {problem}", path.display()))
    })?;
    if ep.format != EPISODE_FORMAT {
        return Err(Error::damaged(
            path,
            format!("episode format {}", ep.format),
            format!(
                "error: `{}` has episode format {}, this shaping reads format {EPISODE_FORMAT}; replay the stage again",
                path.display(),
                ep.format
            ),
        ));
    }
    let n = ep.actions.x.len();
    let c = &ep.actions;
    let per_action =
        [c.y.len(), c.theta.len(), c.winner.len(), c.battery.len(), c.ir.len(), c.arm_down.len()];
    let per_module = c.activation.len() == ep.modules.len()
        && c.reinforcement.len() == ep.modules.len()
        && c.performance.len() == ep.modules.len()
        && c.activation.iter().chain(&c.reinforcement).chain(&c.performance).all(|v| v.len() == n);
    if per_action.iter().any(|&k| k != n) || !per_module || ep.worlds.is_empty() {
        return Err(Error::damaged(
            path,
            "columns of different lengths, or no world",
            format!(
                "error: `{}` is inconsistent (columns of different lengths, or no world)",
                path.display()
            ),
        ));
    }
    Ok(ep)
}

/// The genome in `path` (`None` when there is no such file: the stage has
/// not run); one that is not a genome of `stage` is an error naming it.
fn read_genome(path: &Path, stage: &Stage, u: Unsealed<'_>) -> Result<Option<Genome>, Error> {
    let Some(genome) = rundir::read_sealed_genome(path, u)? else { return Ok(None) };
    if genome.bits.len() != stage.layout.bits as usize {
        return Err(Error::new(
            ErrorKind::Corrupt,
            format!(
                "error: `{}` is not a genome of stage `{}`: it has {} bits, the stage's genome {}",
                path.display(),
                stage.name,
                genome.bits.len(),
                stage.layout.bits
            ),
        ));
    }
    Ok(Some(genome))
}

fn sensor_list(stage: &Stage, channels: &[u16]) -> Vec<String> {
    let mut out = Vec::new();
    for s in &stage.sensors {
        let mine: Vec<u16> =
            channels.iter().copied().filter(|&c| s.channel <= c && c < s.channel + s.count).collect();
        if mine.is_empty() {
            continue;
        }
        let idx: Vec<u16> = mine.iter().map(|c| c - s.channel).collect();
        let contiguous = idx.windows(2).all(|w| w[1] == w[0] + 1);
        if s.count == 1 || idx.len() == s.count as usize && contiguous {
            out.push(s.name.clone());
        } else if contiguous && idx.len() > 1 {
            out.push(format!("{}[{}..{}]", s.name, idx[0], idx[idx.len() - 1]));
        } else {
            out.extend(idx.iter().map(|i| format!("{}[{i}]", s.name)));
        }
    }
    out
}

fn fmt_num(v: f32) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

fn action_text(stage: &Stage, a: &Action) -> String {
    match a {
        Action::Wheels { left, right } if left == right && *left > 0.0 => {
            format!("forward({})", fmt_num(*left))
        }
        Action::Wheels { left, right } if left == right && *left < 0.0 => format!("back({})", fmt_num(-left)),
        Action::Wheels { left, right } if *left == 0.0 && *right == 0.0 => "stop".into(),
        Action::Wheels { left, right } if -left == *right && *right > 0.0 => "turn left".into(),
        Action::Wheels { left, right } if -left == *right && *right < 0.0 => "turn right".into(),
        Action::Wheels { left, right } => format!("wheels({}, {})", fmt_num(*left), fmt_num(*right)),
        Action::Toward { channels, speed } => {
            format!("toward({}, {})", sensor_list(stage, channels).join(", "), fmt_num(*speed))
        }
        Action::Arm(down) => if *down { "arm down" } else { "arm up" }.into(),
        Action::Claw(closed) => if *closed { "claw closed" } else { "claw open" }.into(),
        Action::Wait { charge } => if *charge { "wait, uses charger" } else { "wait" }.into(),
        Action::Reinforce(_) => "reinforce".into(),
        Action::Signal(v) => {
            format!("signal({})", v.iter().map(|x| fmt_num(*x)).collect::<Vec<_>>().join(", "))
        }
    }
}

fn behavior_text(stage: &Stage, b: &Behavior) -> String {
    match b {
        Behavior::Script(s) => {
            let steps: Vec<String> = s
                .steps
                .iter()
                .map(|st| {
                    let mut t = action_text(stage, &st.action);
                    match &st.end {
                        StepEnd::Actions(n) if *n > 1 => {
                            let _ = write!(t, " for {n} actions");
                        }
                        StepEnd::Actions(_) => {}
                        StepEnd::Until { within, .. } => {
                            let _ = write!(t, " until … within {within}");
                        }
                    }
                    if st.when.is_some() {
                        t.push_str(" if …");
                    }
                    t
                })
                .collect();
            let kind = if s.commit { "script commit" } else { "script" };
            if steps.len() == 1 {
                steps[0].clone()
            } else {
                format!("{kind} {{ {} }}", steps.join("; "))
            }
        }
        Behavior::Neural(nb) => {
            let hidden =
                if nb.net.hidden > 0 { format!(", {} hidden", nb.net.hidden) } else { String::new() };
            let decode = match &nb.decode {
                Decode::Table(t) => format!("{} moves", t.len()),
                Decode::Linear { scale } => format!("wheel speeds × {}", fmt_num(*scale)),
            };
            let weights = match nb.net.params.first() {
                Some(Param::Random { lo, hi }) => {
                    format!(", weights random {}..{}", fmt_num(*lo), fmt_num(*hi))
                }
                Some(Param::Gene(_)) => ", weights evolved".into(),
                Some(Param::Fixed(_)) => ", weights fixed".into(),
                Some(Param::Trained { .. }) => ", weights trained by a training stage".into(),
                None => String::new(),
            };
            format!(
                "neural: {} → {} outputs{hidden} ({decode}){weights}",
                sensor_list(stage, &nb.inputs).join(", "),
                nb.net.outputs
            )
        }
    }
}

fn learning_text(m: &shaping_runtime::program::Module) -> Option<String> {
    let l = m.learning.as_ref()?;
    let on = match l.target {
        LearnTarget::Behavior => "behavior",
        LearnTarget::Activation => "activation",
    };
    let when = match l.when {
        LearnWhen::Always => "always".to_string(),
        LearnWhen::Below { threshold } => format!("while performance < {}", fmt_num(threshold)),
    };
    Some(format!(
        "CRBP({}, {}) on {on}, {when}, over {} signals",
        fmt_num(l.rate_reward),
        fmt_num(l.rate_punish),
        l.window
    ))
}

fn wall(w: shaping_runtime::program::Wall) -> &'static str {
    use shaping_runtime::program::Wall;
    match w {
        Wall::North => "north",
        Wall::South => "south",
        Wall::East => "east",
        Wall::West => "west",
    }
}

fn world_parts(w: &World) -> Vec<String> {
    let mut parts = vec![format!("arena {} × {} mm", fmt_num(w.arena[0]), fmt_num(w.arena[1]))];
    if let Some(c) = &w.charger {
        let lamp = if c.lamp_height.is_some() { " with lamp" } else { "" };
        parts.push(format!("charger {} mm on the {} wall{lamp}", fmt_num(c.length), wall(c.wall)));
    }
    if let Some(b) = &w.battery {
        parts.push(format!("battery {} actions, recharge {}", b.capacity, b.recharge));
    }
    if let Some(o) = &w.objects {
        let v = if o.virtual_ { ", virtual" } else { "" };
        parts.push(format!("{} objects of {} mm{v}", o.count, fmt_num(o.diameter)));
    }
    parts
}

/// A stage's variants in words: their names, how many are drawn, and how
/// their fitness is combined.
fn variants_part(st: &Stage) -> Option<String> {
    let v = st.variants.as_ref()?;
    let names: Vec<&str> = v.list.iter().map(|x| x.name.as_str()).collect();
    let drawn = v
        .draw
        .filter(|&d| (d as usize) < names.len())
        .map_or(String::new(), |d| format!(", {d} drawn per generation"));
    Some(format!(
        "{} variants ({}){drawn}, fitness their {}",
        names.len(),
        names.join(", "),
        v.aggregate.word()
    ))
}

fn event(e: Event) -> &'static str {
    match e {
        Event::Grip => "grip",
        Event::ReleaseOutside => "release outside",
        Event::Recharge => "recharge",
        Event::Collision => "collision",
    }
}

fn fitness_parts(st: &Stage) -> Vec<String> {
    let mut parts = Vec::new();
    if st.fitness.per_action.is_some() {
        parts.push("a term per action".to_string());
    }
    parts.extend(st.fitness.bonuses.iter().map(|b| format!("{} per {}", fmt_num(b.points), event(b.event))));
    parts
}

/// How stage `st` runs, in words; `seed`: the seed it ran with, where known
/// (the run's `--seed`, an experiment's seed), else the declared one is said
/// as such.
fn run_text(st: &Stage, seed: Option<u64>) -> String {
    match &st.run {
        StageRun::Evolve(e) => format!(
            "evolved: {} generations of {}, {} actions per life, {}",
            e.generations,
            e.population,
            e.actions,
            match seed {
                Some(s) => format!("seed {s}"),
                None => format!("declared seed {}", e.seed),
            }
        ),
        StageRun::Train { actions } => format!(
            "trained: one life of {actions} actions with learning on; the stages that use it start from the behavior weights learned"
        ),
        StageRun::Test { actions, lives: 1, learning } => format!(
            "test of the parent's best: {actions} actions in the parent's world, then {actions} in this one, learning {}",
            if *learning { "on" } else { "off" }
        ),
        StageRun::Test { actions, lives, learning } => format!(
            "test of the parent's best: {lives} lives of {actions} actions in the parent's world, then {lives} in this one, one controller throughout, learning {}",
            if *learning { "on" } else { "off" }
        ),
    }
}

/// What stage `index` adds to or changes in its parent.
fn added(program: &Program, index: usize) -> Vec<String> {
    let st = &program.stages[index];
    let i = index as u16;
    let mut out = Vec::new();
    let names = |v: Vec<&str>| v.join(", ");
    let sensors: Vec<&str> = st.sensors.iter().filter(|s| s.stage == i).map(|s| s.name.as_str()).collect();
    let actuators: Vec<&str> =
        st.actuators.iter().filter(|a| a.stage == i).map(|a| a.name.as_str()).collect();
    let labels: Vec<String> =
        (0..st.modules.len()).filter(|&m| st.modules[m].stage == i).map(|m| st.module_label(m)).collect();
    let modules: Vec<&str> = labels.iter().map(String::as_str).collect();
    let Some(parent) = st.parent.map(|p| &program.stages[p]) else {
        out.push(format!("modules {}", names(modules)));
        return out;
    };
    if !sensors.is_empty() {
        out.push(format!("sensors {}", names(sensors)));
    }
    if !actuators.is_empty() {
        out.push(format!("actuators {}", names(actuators)));
    }
    if !modules.is_empty() {
        out.push(format!("modules {}", names(modules)));
    }
    let new_genes = st.layout.genes.iter().filter(|g| !g.frozen).count();
    if new_genes > 0 {
        out.push(format!("{new_genes} evolvable genes ({} frozen)", st.layout.genes.len() - new_genes));
    }
    let (old, new) = (world_parts(&parent.world), world_parts(&st.world));
    for p in new.iter().filter(|p| !old.contains(p)) {
        out.push(format!("world: {p}"));
    }
    let (old, new) = (fitness_parts(parent), fitness_parts(st));
    for p in new.iter().filter(|p| !old.contains(p)) {
        out.push(format!("fitness: {p}"));
    }
    if out.is_empty() {
        out.push("nothing new".into());
    }
    out
}

/// The view of stage `index`, with gene values decoded from `genome`.
pub fn stage_view(program: &Program, index: usize, genome: Option<(&Genome, String)>) -> StageView {
    let st = &program.stages[index];
    let stage_name =
        |i: u16| program.stages.get(i as usize).map_or_else(|| format!("#{i}"), |s| s.name.clone());
    let module_name = |i: u16| match st.modules.get(i as usize) {
        Some(_) => st.module_label(i as usize),
        None => format!("#{i}"),
    };
    let g = genome.as_ref().map(|(g, _)| *g);
    let genes = st
        .layout
        .genes
        .iter()
        .enumerate()
        .map(|(i, gene)| GeneView {
            index: i as u32,
            offset: gene.offset,
            bits: gene.bits,
            stage: stage_name(gene.stage),
            module: module_name(gene.module),
            role: shaping_compiler::role_text(st, i as u32),
            lo: gene.lo,
            hi: gene.hi,
            frozen: gene.frozen,
            value: g.map(|g| g.decode(gene)),
            code: g.map(|g| {
                let (a, b) = (gene.offset as usize, gene.offset as usize + gene.bits as usize);
                g.bits.get(a..b).map_or_else(String::new, |bits| {
                    bits.iter().map(|&b| if b != 0 { '1' } else { '0' }).collect()
                })
            }),
            parent_value: None,
        })
        .collect();
    let links = st
        .links
        .iter()
        .map(|l| {
            let introduced = |m: u16| st.modules.get(m as usize).map_or(0, |m| m.stage);
            let (kind, weight, gene, frozen, new) = match l.weight {
                Param::Gene(i) => {
                    let gene = st.layout.genes.get(i as usize);
                    let w = match (g, gene) {
                        (Some(g), Some(gene)) => Some(g.decode(gene)),
                        _ => None,
                    };
                    (
                        "gene",
                        w,
                        Some(i),
                        gene.is_some_and(|x| x.frozen),
                        gene.is_some_and(|x| x.stage as usize == index),
                    )
                }
                Param::Fixed(w) => {
                    let new = introduced(l.from).max(introduced(l.to)) as usize == index;
                    ("fixed", Some(w), None, false, new)
                }
                Param::Random { .. } | Param::Trained { .. } => {
                    let new = introduced(l.from).max(introduced(l.to)) as usize == index;
                    let kind = if matches!(l.weight, Param::Random { .. }) { "random" } else { "trained" };
                    (kind, None, None, false, new)
                }
            };
            LinkView { from: l.from, to: l.to, kind, weight, gene, frozen, new }
        })
        .collect();
    StageView {
        name: st.name.clone(),
        parent: st.parent.map(|p| program.stages[p].name.clone()),
        run: run_text(st, None),
        world: world_parts(&st.world).into_iter().chain(variants_part(st)).collect::<Vec<_>>().join("; "),
        fitness: fitness_parts(st).join(", "),
        added: added(program, index),
        sensors: st
            .sensors
            .iter()
            .map(|s| if s.count == 1 { s.name.clone() } else { format!("{}[{}]", s.name, s.count) })
            .collect(),
        modules: st
            .modules
            .iter()
            .enumerate()
            .map(|(k, m)| ModuleView {
                name: st.module_label(k),
                stage: stage_name(m.stage),
                new: m.stage as usize == index,
                sensors: sensor_list(st, &m.inputs),
                behavior: behavior_text(st, &m.behavior),
                learning: learning_text(m),
                reinforce: m.reinforce.is_some()
                    || matches!(&m.behavior, Behavior::Script(s) if s.steps.iter().any(|x| matches!(x.action, Action::Reinforce(_)))),
            })
            .collect(),
        links,
        genes,
        genome: genome.map(|(_, src)| src),
        results: None,
        frozen_from: None,
        crowded: None,
    }
}

/// Per evolved stage, its own rows of one run's `generations.csv` files.
fn run_fitness(program: &Program, run: &Path, u: Unsealed<'_>) -> Result<Vec<Vec<GenRow>>, Error> {
    let mut out = vec![Vec::new(); program.stages.len()];
    for (i, st) in program.stages.iter().enumerate() {
        if !matches!(st.run, StageRun::Evolve(_)) {
            continue;
        }
        let Some(g) = rundir::read_generations(&rundir::stage_dir(run, &st.name), u)? else { continue };
        out[i] = g.rows.into_iter().filter(|r| r.stage == st.name).collect();
    }
    Ok(out)
}

fn single_series(stage: &str, rows: &[GenRow]) -> FitnessSeries {
    FitnessSeries {
        stage: stage.to_string(),
        generation: rows.iter().map(|r| r.generation).collect(),
        best: rows.iter().map(|r| r.best).collect(),
        mean: rows.iter().map(|r| r.mean).collect(),
        ..FitnessSeries::default()
    }
}

/// Median best and mean per generation over seeds, with the range of the best.
pub fn seed_series(stage: &str, seeds: &[Vec<GenRow>]) -> FitnessSeries {
    let mut s = FitnessSeries { stage: stage.to_string(), ..FitnessSeries::default() };
    let n = seeds.iter().map(Vec::len).max().unwrap_or(0);
    for k in 0..n {
        let rows: Vec<&GenRow> = seeds.iter().filter_map(|r| r.get(k)).collect();
        let best: Vec<f64> = rows.iter().map(|r| r.best as f64).collect();
        let mean: Vec<f64> = rows.iter().map(|r| r.mean as f64).collect();
        let (Some(b), Some(m)) = (rundir::spread(&best), rundir::spread(&mean)) else { continue };
        s.generation.push(rows[0].generation);
        s.best.push(b.median as f32);
        s.mean.push(m.median as f32);
        s.best_min.push(b.min as f32);
        s.best_max.push(b.max as f32);
        s.seeds.push(rows.len() as u32);
    }
    s
}

/// A run directory's stage views, its episodes, their teams' columns and
/// their boards (one per episode).
type RunStages = (Vec<StageView>, Vec<Episode>, Vec<Option<TeamColumns>>, Vec<Option<BoardView>>);

/// The stages of one run directory, with genomes, results and episodes.
fn run_stages(
    program: &Program,
    run: &Path,
    only: Option<usize>,
    u: Unsealed<'_>,
) -> Result<RunStages, Error> {
    let mut views = Vec::new();
    let mut episodes = Vec::new();
    let mut teams = Vec::new();
    let mut boards = Vec::new();
    for (i, st) in program.stages.iter().enumerate() {
        let dir = rundir::stage_dir(run, &st.name);
        if only.is_some_and(|o| o != i) || only.is_none() && !dir.is_dir() {
            continue;
        }
        let genome = read_genome(&rundir::best_genome_path(&dir), st, u)?;
        let cp = rundir::read_checkpoint_with(&dir, u)?;
        if let (Some(g), Some(cp), StageRun::Evolve(_)) = (&genome, &cp, &st.run) {
            // The best the checkpoint beside it holds (a `best.genome`
            // changed after the run wrote it is an error naming it).
            rundir::check_best(&dir, g, cp)?;
        }
        let src = format!("{}/{}", st.name, rundir::names::BEST_GENOME);
        let mut view = stage_view(program, i, genome.as_ref().map(|g| (g, src)));
        // The seed the stage ran with is its checkpoint's (`--seed`, an
        // experiment's seed), not necessarily the one the file declares.
        if let Some(cp) = &cp {
            view.run = run_text(st, Some(cp.seed));
            view.crowded = crowded_generations(st, cp);
        }
        if let Some(r) = rundir::read_test_summary(&dir, u)? {
            if let (Some(n), Some(p)) = (r.crowded_lives, r.placement_failures) {
                view.crowded = Some(crowded_text(n, 2 * u64::from(r.lives), p, "lives"));
            }
            view.results = Some(to_value(&r)?);
        }
        if matches!(st.run, StageRun::Train { .. }) {
            view.crowded = crowded_training(&dir, u)?;
        }
        // An evolved stage's frozen genes come from the nearest evolved ancestor.
        let ancestor = matches!(st.run, StageRun::Evolve(_)).then(|| program.evolved_above(i)).flatten();
        if let (Some(g), Some(a)) = (&genome, ancestor) {
            let pst = &program.stages[a];
            let pdir = rundir::stage_dir(run, &pst.name);
            if let Some(cp) = rundir::read_checkpoint_with(&pdir, u)? {
                let parent_best = read_genome(&rundir::best_genome_path(&pdir), pst, u)?;
                provenance(program, i, a, g, &cp, parent_best.as_ref(), &mut view);
            }
        }
        views.push(view);
        let ep = rundir::episode_path(&dir);
        if ep.exists() {
            let ep = read_episode(&ep, u)?;
            let mut team = read_team(&dir, &ep, u)?;
            boards.push(read_board(&dir, program, &ep, team.as_mut())?);
            teams.push(team);
            episodes.push(ep);
        }
    }
    Ok((views, episodes, teams, boards))
}

/// The words for `n` of `m` episodes (or lives) whose placement overlapped,
/// `p` placements in all.
fn crowded_text(n: u64, m: u64, p: u64, what: &str) -> String {
    crowded_words(&format!("in {n} of {m} {what}"), p)
}

fn crowded_words(which: &str, p: u64) -> String {
    let places = if p == 1 { "1 placement".to_string() } else { format!("{p} placements") };
    format!(
        "the world was too crowded: {which} objects (or the robot) could not be placed apart and overlapped \
         ({places}), and the results there are not of the world as declared"
    )
}

/// The crowded episodes of an evolved stage's generations, if any.
fn crowded_generations(st: &shaping_runtime::program::Stage, cp: &Checkpoint) -> Option<String> {
    let StageRun::Evolve(evo) = &st.run else { return None };
    let own: Vec<_> = cp.history.iter().filter(|h| h.stage == st.name).collect();
    let n: u64 = own.iter().map(|h| u64::from(h.crowded_episodes)).sum();
    let p: u64 = own.iter().map(|h| u64::from(h.placement_failures)).sum();
    let m = own.len() as u64 * u64::from(evo.population) * u64::from(evo.evaluations.max(1));
    (n > 0).then(|| crowded_text(n, m, p, "episodes of its generations"))
}

/// The training life's overlapping placements, if any (`trained.json` in
/// stage directory `dir`; a damaged one is an error naming it).
fn crowded_training(dir: &Path, u: Unsealed<'_>) -> Result<Option<String>, Error> {
    let Some(t) = rundir::read_trained_with(dir, u)? else { return Ok(None) };
    let p = u64::from(t.result.placement_failures);
    Ok((p > 0).then(|| crowded_words("in its training life", p)))
}

/// Says where the frozen genes of `best` (the best individual of stage
/// `index`) come from. A stage starts from the whole final population of
/// its evolved ancestor `parent` (individual `i` takes the genes of the
/// parent's individual of rank `i`) and never changes those genes, so they
/// are the genes of some individuals of `cp`, the parent's final
/// checkpoint: not necessarily of the parent's `best.genome`, chosen
/// afterwards by its mean over fresh episodes. Sets `view.frozen_from`,
/// and each frozen gene's `parent_value` where it differs from `parent_best`.
pub fn provenance(
    program: &Program,
    index: usize,
    parent: usize,
    best: &Genome,
    cp: &Checkpoint,
    parent_best: Option<&Genome>,
    view: &mut StageView,
) {
    let st = &program.stages[index];
    let pname = &program.stages[parent].name;
    let kept = program.stages[parent].layout.bits as usize;
    let frozen: Vec<usize> = st
        .layout
        .genes
        .iter()
        .enumerate()
        .filter(|(_, g)| g.frozen && (g.offset + g.bits as u32) as usize <= kept)
        .map(|(i, _)| i)
        .collect();
    let (Some(prefix), false) = (best.bits.get(..kept), frozen.is_empty()) else { return };
    let rank_of = ranking(&cp.fitness);
    let matches: Vec<usize> =
        (0..cp.population.len()).filter(|&i| cp.population[i].bits.get(..kept) == Some(prefix)).collect();
    let mut text = format!("The {} frozen genes of this stage's best individual ", frozen.len());
    match matches.first() {
        None => {
            let _ = write!(
                text,
                "match no individual of stage `{pname}`'s final population (its checkpoint is from another run?)"
            );
        }
        Some(&first) => {
            let who = |i: usize| {
                let rank = rank_of.iter().position(|&r| r == i).map(|r| r + 1);
                let fit = cp.fitness.get(i).map(|f| format!(", fitness {}", fmt_num(*f))).unwrap_or_default();
                match rank {
                    Some(r) => format!("#{i} (rank {r} of {}{fit})", cp.population.len()),
                    None => format!("#{i}"),
                }
            };
            let _ = write!(text, "come from individual {} of stage `{pname}`'s final population", who(first));
            if matches.len() > 1 {
                let _ =
                    write!(text, ", and {} other individuals with the same genes there", matches.len() - 1);
            }
        }
    }
    match parent_best {
        Some(pb) => {
            let mut differ = 0;
            for &i in &frozen {
                let gene = &st.layout.genes[i];
                let (a, b) = (gene.offset as usize, gene.offset as usize + gene.bits as usize);
                if best.bits.get(a..b) != pb.bits.get(a..b) {
                    differ += 1;
                    view.genes[i].parent_value = Some(pb.decode(gene));
                }
            }
            if differ == 0 {
                let _ = write!(text, "; they equal `{pname}/best.genome`.");
            } else {
                let _ = write!(
                    text,
                    "; {differ} of them differ from `{pname}/best.genome` (selected by its mean over fresh episodes), whose values are shown beside them."
                );
            }
        }
        None => text.push('.'),
    }
    view.frozen_from = Some(text);
}

fn series_of(program: &Program, fitness: &[Vec<GenRow>], only: Option<usize>) -> Vec<FitnessSeries> {
    program
        .stages
        .iter()
        .enumerate()
        .filter(|(i, _)| !fitness[*i].is_empty() && only.is_none_or(|o| o == *i))
        .map(|(i, st)| single_series(&st.name, &fitness[i]))
        .collect()
}

/// The run directories of an experiment's (or a sweep point's) seeds: those
/// its `summary.json` covers, when there is one (a directory may hold other
/// seeds' runs, from earlier experiments), else every `seed-N` on disk.
fn seed_dirs(dir: &Path, u: Unsealed<'_>) -> Result<Vec<(u64, PathBuf)>, Error> {
    let covered: Option<Vec<u64>> = summary_json(dir, u)?.map(|s| s.seeds);
    let mut seeds: Vec<(u64, PathBuf)> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let seed = name.strip_prefix("seed-")?.parse::<u64>().ok()?;
            let covered = covered.as_ref().is_none_or(|c| c.contains(&seed));
            (covered && rundir::program_path(&e.path()).exists()).then(|| (seed, e.path()))
        })
        .collect();
    seeds.sort();
    Ok(seeds)
}

/// An experiment's (or a sweep's) `summary.json` in `dir`, if there is
/// one (a damaged one, or one of a newer format, is an error naming it).
fn summary_json(dir: &Path, u: Unsealed<'_>) -> Result<Option<ExperimentSummary>, Error> {
    rundir::read_experiment_summary(dir, u)
}

/// A summary as the report's data holds it.
fn to_value<T: serde::Serialize>(summary: &T) -> Result<serde_json::Value, Error> {
    serde_json::to_value(summary)
        .map_err(|e| Error::internal(format!("error: cannot serialise a summary: {e}")))
}

fn base(kind: &'static str, program: &Program, dir: &Path) -> ReportData {
    ReportData {
        format: REPORT_FORMAT,
        title: program.name.clone(),
        kind,
        source: dir.display().to_string(),
        generator: format!("shaping {}", env!("CARGO_PKG_VERSION")),
        seeds: Vec::new(),
        episodes_note: String::new(),
        shown_seed: None,
        stages: Vec::new(),
        fitness: Vec::new(),
        episodes: Vec::new(),
        robots: Vec::new(),
        boards: Vec::new(),
        sweep: None,
        sweep_point: None,
        tests: None,
    }
}

/// The `summary.json` of a sweep in `dir`, if there is one (with points in
/// directories of their own).
fn sweep_summary(dir: &Path, u: Unsealed<'_>) -> Result<Option<ExperimentSummary>, Error> {
    Ok(summary_json(dir, u)?.filter(ExperimentSummary::is_sweep))
}

/// A sweep's directory: the experiment report of its best point (by the
/// median chosen best of the last evolved stage), listing every point.
fn sweep(dir: &Path, summary: ExperimentSummary, u: Unsealed<'_>) -> Result<ReportData, Error> {
    let score = |p: &PointSummary| {
        p.stages
            .iter()
            .rev()
            .find_map(|x| match x {
                StageFigures::Evolve { chosen_best, .. } => Some(chosen_best.map(|c| c.median)),
                _ => None,
            })
            .flatten()
            .filter(|m| m.is_finite())
            .unwrap_or(f64::NEG_INFINITY)
    };
    // The first of the best, so ties go to the earlier point.
    let best = summary.points.iter().fold(None::<&PointSummary>, |b, p| match b {
        Some(b) if score(b) >= score(p) => Some(b),
        _ => Some(p),
    });
    let Some(best) = best else {
        return Err(Error::damaged(
            dir,
            "no points",
            format!("error: the sweep in `{}` has no points", dir.display()),
        ));
    };
    let point_dir = dir.join(&best.dir);
    let seeds = seed_dirs(&point_dir, u)?;
    if seeds.is_empty() {
        let message = format!("error: the point `{}` has no seed directories", point_dir.display());
        return Err(Error::damaged(&point_dir, "no seed directories", message));
    }
    let mut data = experiment(&point_dir, &seeds, u)?;
    data.kind = "sweep";
    data.source = dir.display().to_string();
    let name = best.name.clone();
    data.episodes_note = format!("the best point, {name}: {}", data.episodes_note);
    data.sweep_point = Some(name);
    data.tests = Some(summary.tests.clone());
    data.sweep = Some(to_value(&summary)?);
    Ok(data)
}

/// Gathers a report's data from a run, stage, experiment or replay
/// directory. Every file read is checked against its seal (a damaged one
/// is an error naming it); one without a seal is read without a word (see
/// [`collect_with`]).
pub fn collect(dir: &Path) -> Result<ReportData, Error> {
    collect_with(dir, &|_| {})
}

/// [`collect`], telling `u` of each file read without a seal (written
/// before runs sealed their files), for a warning.
pub fn collect_with(dir: &Path, u: Unsealed<'_>) -> Result<ReportData, Error> {
    if !dir.is_dir() {
        let kind = if dir.exists() { crate::ErrorKind::Invalid } else { crate::ErrorKind::NotFound };
        let subject = crate::Subject::File { path: dir.to_path_buf(), operation: "read".into() };
        return Err(Error::new(kind, format!("error: `{}` is not a directory", dir.display())).about(subject));
    }
    let here = rundir::program_path(dir);
    if here.exists() {
        let program = load::load_built(&here)?;
        if rundir::episode_path(dir).exists() {
            // A replay: one episode of one stage.
            let ep = read_episode(&rundir::episode_path(dir), u)?;
            let (index, _) = program.stage(&ep.stage).ok_or_else(|| {
                Error::damaged(
                    &rundir::episode_path(dir),
                    format!("stage `{}` is not in `{}`", ep.stage, here.display()),
                    format!(
                        "error: `{}` replays stage `{}`, which `{}` does not have",
                        dir.display(),
                        ep.stage,
                        here.display()
                    ),
                )
            })?;
            let st = &program.stages[index];
            let genome = read_genome(&rundir::genome_file_path(dir), st, u)?;
            let mut data = base("replay", &program, dir);
            data.stages.push(stage_view(
                &program,
                index,
                genome.as_ref().map(|g| (g, rundir::names::GENOME.to_string())),
            ));
            data.episodes_note = format!("replay of stage `{}`, seed {}", ep.stage, ep.seed);
            let mut team = read_team(dir, &ep, u)?;
            data.boards.push(read_board(dir, &program, &ep, team.as_mut())?);
            data.robots.push(team);
            data.episodes.push(ep);
            return Ok(data);
        }
        let mut data = base("run", &program, dir);
        let fitness = run_fitness(&program, dir, u)?;
        data.fitness = series_of(&program, &fitness, None);
        (data.stages, data.episodes, data.robots, data.boards) = run_stages(&program, dir, None, u)?;
        data.episodes_note = "the best individual of each stage".into();
        return Ok(data);
    }
    let seeds = seed_dirs(dir, u)?;
    if !seeds.is_empty() {
        let mut data = experiment(dir, &seeds, u)?;
        // A point of a sweep lists the sweep's points.
        let name = dir.file_name().map(|n| n.to_string_lossy().into_owned());
        let summary = match dir.parent() {
            Some(parent) => sweep_summary(parent, u)?,
            None => None,
        };
        if let (Some(summary), Some(name)) = (summary, name) {
            if summary.points.iter().any(|x| x.dir == name) {
                data.sweep_point = Some(name);
                data.tests = Some(summary.tests.clone());
                data.sweep = Some(to_value(&summary)?);
                return Ok(data);
            }
        }
        data.tests = summary_json(dir, u)?.map(|s| s.tests);
        return Ok(data);
    }
    if let Some(summary) = sweep_summary(dir, u)? {
        return sweep(dir, summary, u);
    }
    // A stage directory inside a run.
    let parent = dir.parent().filter(|p| rundir::program_path(p).exists());
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned());
    if let (Some(run), Some(name)) = (parent, name) {
        let program = load::load_built(&rundir::program_path(run))?;
        if let Some((index, _)) = program.stage(&name) {
            let mut data = base("stage", &program, dir);
            let fitness = run_fitness(&program, run, u)?;
            data.fitness = series_of(&program, &fitness, Some(index));
            (data.stages, data.episodes, data.robots, data.boards) =
                run_stages(&program, run, Some(index), u)?;
            data.episodes_note = format!("the best individual of stage `{name}`");
            return Ok(data);
        }
    }
    let subject = crate::Subject::File { path: dir.to_path_buf(), operation: "read".into() };
    Err(Error::new(
        crate::ErrorKind::Invalid,
        format!(
            "error: `{}` is not a run, stage, experiment, sweep or replay directory: no `program.json` in it or its parent (runs write one since this version of shaping; run the stage again)",
            dir.display()
        ),
    )
    .about(subject))
}

fn experiment(dir: &Path, seeds: &[(u64, PathBuf)], u: Unsealed<'_>) -> Result<ReportData, Error> {
    let program = load::load_built(&rundir::program_path(&seeds[0].1))?;
    let mut per_seed = Vec::new();
    for (_, run) in seeds {
        per_seed.push(run_fitness(&program, run, u)?);
    }
    let mut data = base("experiment", &program, dir);
    data.seeds = seeds.iter().map(|s| s.0).collect();
    data.fitness = program
        .stages
        .iter()
        .enumerate()
        .filter(|(i, _)| per_seed.iter().any(|f| !f[*i].is_empty()))
        .map(|(i, st)| {
            let rows: Vec<Vec<GenRow>> = per_seed.iter().map(|f| f[i].clone()).collect();
            seed_series(&st.name, &rows)
        })
        .collect();
    // The episodes of the median seed: the one whose final best fitness in
    // the last evolved stage is the (lower) median.
    let last = (0..program.stages.len()).rev().find(|&i| per_seed.iter().any(|f| !f[i].is_empty()));
    let mut order: Vec<(f32, usize)> = per_seed
        .iter()
        .enumerate()
        .map(|(k, f)| (last.and_then(|i| f[i].last()).map_or(f32::NEG_INFINITY, |r| r.best), k))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let pick = order[(order.len() - 1) / 2].1;
    let (seed, run) = &seeds[pick];
    (data.stages, data.episodes, data.robots, data.boards) = run_stages(&program, run, None, u)?;
    data.shown_seed = Some(*seed);
    data.episodes_note = format!(
        "seed {seed}, the median of {} seeds by the final best fitness{}; genomes and episodes of that seed",
        seeds.len(),
        last.map_or(String::new(), |i| format!(" of `{}`", program.stages[i].name))
    );
    Ok(data)
}
