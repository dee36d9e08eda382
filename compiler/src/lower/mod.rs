//! Checking and lowering: AST to [`Program`], collecting every error.
//!
//! Stages are processed in dependency order. Each starts from a copy of its
//! parent's state (sensors, actuators, world, genome settings, evolution,
//! fitness, modules, links, genes) and applies its own declarations; then its
//! new genes are appended to the layout (see [`Lower::allocate`]). Errors are
//! pushed into a sink and lowering goes on with placeholders, so one mistake
//! is reported once and every independent mistake is reported.

pub(crate) mod expr;
mod genes;
mod measure;
pub(crate) mod module;
mod roles;
pub(crate) mod training;
pub(crate) mod variants;
pub(crate) mod world;

use std::collections::HashMap;

use shaping_runtime::catalog::{self, ActuatorKind, SensorKind};
use shaping_runtime::expr::Expr;
use shaping_runtime::limits::*;
use shaping_runtime::program::*;

use crate::diag::{did_you_mean, Error};
use crate::syntax::ast::{self, Quantity, Unit};
use crate::syntax::Span;
pub use expr::Scope;
#[cfg(test)]
use genes::network_roles;
pub use measure::measure;

/// A sensor of the robot at some stage.
#[derive(Clone, Debug)]
pub(crate) struct SensorSt {
    pub name: String,
    pub kind: SensorKind,
    pub count: u16,
    pub channel: u16,
    pub stage: u16,
    pub span: Span,
}

impl SensorSt {
    /// Some of this sensor's channels (in order), as a file would write
    /// them: `light` for all of them, `light[2]`, `light[2..5]`, or the
    /// first of them when they are not contiguous.
    pub(crate) fn elements_text(&self, channels: &[u16]) -> String {
        let (Some(&a), Some(&b)) = (channels.first(), channels.last()) else {
            return self.name.clone();
        };
        let (i, j) = (a - self.channel, b - self.channel);
        if self.count == 1 || (i == 0 && j + 1 == self.count && channels.len() == self.count as usize) {
            self.name.clone()
        } else if i == j || channels.len() != (j - i + 1) as usize {
            format!("{}[{i}]", self.name)
        } else {
            format!("{}[{i}..{j}]", self.name)
        }
    }
}

#[derive(Clone, Debug)]
pub(crate) struct ActuatorSt {
    pub name: String,
    pub kind: ActuatorKind,
    pub count: u16,
    pub slot: u16,
    pub stage: u16,
    pub span: Span,
}

/// The hardware visible to a stage, and where later hardware comes from.
pub(crate) struct Hw {
    pub stage: String,
    pub sensors: Vec<SensorSt>,
    pub actuators: Vec<ActuatorSt>,
    pub has_charger: bool,
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct GeneSpec {
    pub bits: u8,
    pub lo: f32,
    pub hi: f32,
}

/// Gene settings per group.
#[derive(Clone, Copy, Debug)]
pub(crate) struct GenomeSt {
    pub links: GeneSpec,
    pub weights: GeneSpec,
    pub biases: GeneSpec,
}

/// How the weights of a network are given.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Source {
    Evolvable(Option<(f32, f32)>),
    Fixed(Vec<f32>),
    Random(f32, f32),
    /// `trained STAGE`: what the module of the same name learned there.
    Trained(String),
}

#[derive(Clone, Debug)]
pub(crate) struct ModuleSt {
    pub name: String,
    pub span: Span,
    pub stage: u16,
    pub inputs: Vec<u16>,
    pub inputs_span: Option<Span>,
    pub hidden: u16,
    /// The activation network's hidden units are recurrent.
    pub recurrent: bool,
    pub source: Source,
    pub act_span: Option<Span>,
    pub act_params: Vec<Param>,
    pub behavior: Option<Behavior>,
    /// Gene source of a neural behavior whose genes are still to allocate.
    pub behavior_genes: Option<Option<(f32, f32)>>,
    pub behavior_stage: u16,
    pub learning: Option<Learning>,
    pub learn_span: Option<Span>,
    pub reinforce: Option<Expr>,
    /// A `reinforce` clause was written (even if it had errors).
    pub reinforce_declared: bool,
    pub script_reinforces: bool,
}

#[derive(Clone, Debug)]
pub(crate) struct LinkSt {
    pub from: u16,
    pub to: u16,
    /// `Ok(gene range)` for evolvable, `Err(weight)` for fixed.
    pub kind: Result<Option<(f32, f32)>, f32>,
    pub param: Option<Param>,
    pub stage: u16,
    pub span: Span,
}

#[derive(Clone, Debug)]
struct WorldSt {
    world: World,
    /// Where each optional item was declared: charger, battery, objects.
    spans: HashMap<&'static str, Span>,
    /// Where each list item was declared, by kind, parallel to the lists of
    /// `world.items` (`wall`, `cylinder`, `lamp`, `zone`).
    item_spans: HashMap<&'static str, Vec<Span>>,
    /// The arena's width and depth were written without a unit (millimetres).
    arena_bare: bool,
    /// Named list items refused with an error (kind, name): a later change
    /// of one is not reported again as an item the world lacks.
    refused: std::collections::HashSet<(&'static str, String)>,
}

#[derive(Clone, Debug)]
struct StageSt {
    sensors: Vec<SensorSt>,
    actuators: Vec<ActuatorSt>,
    world: WorldSt,
    genome: GenomeSt,
    evolution: Evolution,
    /// Where the population was set (here or in an ancestor), for the
    /// resource-limit diagnostic.
    population_span: Option<Span>,
    /// No `selection truncation keep N` written here or in an ancestor: the
    /// truncation keeps a fifth of the population (20 of the paper's 100).
    keep_default: bool,
    inheritance: Inheritance,
    run: StageRun,
    fitness: Fitness,
    fitness_declared: bool,
    /// A missing fitness was reported (by this stage or an ancestor).
    fitness_reported: bool,
    modules: Vec<ModuleSt>,
    links: Vec<LinkSt>,
    genes: Vec<Gene>,
    bits: u32,
    /// The items the fitness measures the distance to (`distance_to`).
    targets: Vec<Target>,
    variants: Option<variants::VariantsSt>,
    /// The roles of a heterogeneous team (declared here or inherited), and
    /// where their heads (`role NAME robots N`) are written.
    roles: Vec<Role>,
    role_heads: Vec<Span>,
}

pub(crate) struct Lower<'a> {
    pub errors: Vec<Error>,
    file: &'a ast::File,
    /// Hardware name -> the stage whose `robot adds` declares it.
    hw_origin: HashMap<String, String>,
    /// Module name -> the first stage that declares it.
    module_origin: HashMap<String, String>,
    /// Names of the processed stages, by program index.
    stage_names: Vec<String>,
    /// Hardware whose declaration failed: not reported again where used.
    poisoned: std::collections::HashSet<String>,
    /// Training stages lowered so far, by name: their program index and, per
    /// module, its name, its behavior and its activation network's shape.
    trained: HashMap<String, (u16, Vec<TrainedModule>)>,
    /// The first use of hardware in a file that declares no robot: the
    /// one error reported for all of them.
    no_robot: Option<Span>,
    /// While a stage's fitness is lowered: its world's items and its
    /// targets (`distance_to(NAME)`).
    pub(crate) items: Items,
    pub(crate) targets: Vec<Target>,
}

/// A module of a training stage: its name, its behavior's shape and its
/// activation network's.
pub(crate) type TrainedModule = (String, TrainedShape, Shape);

/// A network's shape: inputs, hidden units, outputs, recurrent.
pub(crate) type Shape = (u16, u16, u16, bool);

/// The behavior of a module of a training stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum TrainedShape {
    Script,
    Network(Shape),
    /// The behavior did not compile (reported there): nothing to say about its shape.
    Failed,
}

const DEFAULT_BITS: u8 = 4;
const DEFAULT_WINDOW: u32 = 30;
const DEFAULT_LAMP_HEIGHT: f32 = 150.0;
const DEFAULT_RECHARGE: u32 = 20;
const DEFAULT_RATES: (f32, f32) = (0.5, 0.1);

fn default_evolution() -> Evolution {
    Evolution {
        population: 100,
        generations: 40,
        actions: 300,
        seed: 1,
        selection: Selection::Truncation { keep: 20 },
        crossover: 0.1,
        mutation: 0.01,
        elitism: 1,
        evaluations: 1,
    }
}

/// A robot, for messages that say how to declare one.
const EXAMPLE_ROBOT: &str = "robot khepera { sensor ir[8] proximity  actuator wheels[2] speed }";

/// How a piece of hardware of each kind is declared, for messages.
fn example_declaration(kind: &str) -> Option<&'static str> {
    Some(match kind {
        "proximity" => "sensor ir[8] proximity",
        "ambient" => "sensor light[8] ambient",
        "level" => "sensor battery level",
        "optical" => "sensor barrier optical",
        "ground" => "sensor floor ground",
        "lamp_distance" => "sensor home lamp_distance",
        "speed" => "actuator wheels[2] speed",
        "lift" => "actuator arm lift",
        "grip" => "actuator claw grip",
        _ => return None,
    })
}

/// A help for a kind of sensor or actuator written where its name is
/// expected (`speed[0]` for `wheels[0]`): the name of the hardware of that
/// kind, or how to declare one.
fn kind_hint(hw: &Hw, name: &str) -> Option<String> {
    let (what, declared) = if let Some(info) = catalog::sensor_by_keyword(name) {
        ("sensor", hw.sensors.iter().find(|s| s.kind == info.kind).map(|s| s.name.as_str()))
    } else if let Some(info) = catalog::actuator_by_keyword(name) {
        ("actuator", hw.actuators.iter().find(|a| a.kind == info.kind).map(|a| a.name.as_str()))
    } else {
        return None;
    };
    Some(match declared {
        Some(n) => {
            format!("`{name}` is a kind of {what}: write the name of the robot's `{name}` {what}, `{n}`")
        }
        None => format!(
            "`{name}` is a kind of {what}, and the robot has none: declare one, as in `{}`",
            example_declaration(name)?
        ),
    })
}

/// Whether an error of a stage whose parent is unknown stands without the
/// parent: a sensor or actuator that no stage declares, an index out of
/// range, a bad range, unit or gene size, an unknown function or event.
fn checkable_without_parent(e: &Error) -> bool {
    matches!(
        e,
        Error::Unknown { what: "sensor" | "actuator" | "function" | "event", .. }
            | Error::IndexOutOfRange { .. }
            | Error::BadRange { .. }
            | Error::Bits { .. }
            | Error::Unit { .. }
    )
}

/// Lowers a parsed file: the program when no diagnostic is an error, and
/// every diagnostic (errors and warnings), in source order.
pub fn lower(file: &ast::File, file_name: &str) -> (Option<Program>, Vec<Error>) {
    let (program, errors) = lower_partial(file, file_name);
    let failed = errors.iter().any(|e| !e.is_warning());
    ((!failed).then_some(program), errors)
}

/// Lowers what a file declares even where it has errors: the program, with
/// placeholders where an error stands (never to be run), beside every
/// diagnostic. For the language server, which describes the parts that stand.
pub fn lower_partial(file: &ast::File, file_name: &str) -> (Program, Vec<Error>) {
    let mut lw = Lower {
        errors: Vec::new(),
        file,
        hw_origin: HashMap::new(),
        module_origin: HashMap::new(),
        stage_names: Vec::new(),
        poisoned: Default::default(),
        trained: HashMap::new(),
        no_robot: None,
        items: Items::default(),
        targets: Vec::new(),
    };
    let program = lw.program(file_name);
    if let Some(at) = lw.no_robot {
        lw.value_error(
            at,
            "the file declares no robot".into(),
            "used here, but no robot declares it",
            Some(format!("declare the robot before the stages, as in `{EXAMPLE_ROBOT}`")),
        );
    }
    let mut errors = lw.errors;
    errors.sort_by_key(|e| {
        use miette::Diagnostic;
        e.labels().and_then(|mut l| l.next()).map(|l| l.offset()).unwrap_or(0)
    });
    (program, errors)
}

impl<'a> Lower<'a> {
    fn value_error(&mut self, span: Span, message: String, label: &str, help: Option<String>) {
        self.errors.push(Error::Value { span: span.into(), message, label: label.into(), help });
    }

    /// In a file that declares no robot, notes a use of hardware at `at`
    /// (reported once, at the first use) and says so.
    pub(crate) fn no_robot(&mut self, at: Span) -> bool {
        if !self.file.robots.is_empty() {
            return false;
        }
        if self.no_robot.is_none_or(|first| at.start < first.start) {
            self.no_robot = Some(at);
        }
        true
    }

    /// Reports an unknown sensor or actuator name, or one a later stage adds.
    pub(crate) fn unknown_hardware(&mut self, hw: &Hw, what: &'static str, name: &ast::Name) {
        if self.poisoned.contains(&name.text) {
            return;
        }
        if !self.hw_origin.contains_key(&name.text) && self.no_robot(name.span) {
            return;
        }
        if let Some(origin) = self.hw_origin.get(&name.text) {
            self.errors.push(Error::MissingHardware {
                span: name.span.into(),
                stage: hw.stage.clone(),
                what,
                name: name.text.clone(),
                help: Some(format!(
                    "`{}` is added by stage `{origin}`, which does not come before this one",
                    name.text
                )),
            });
            return;
        }
        let names =
            hw.sensors.iter().map(|s| s.name.as_str()).chain(hw.actuators.iter().map(|a| a.name.as_str()));
        let help = kind_hint(hw, &name.text).or_else(|| did_you_mean(&name.text, names));
        self.errors.push(Error::Unknown { span: name.span.into(), what, name: name.text.clone(), help });
    }

    /// Reports every setting named again in one scope (a block, or the
    /// blocks of one stage): the later one would silently replace the first.
    pub(crate) fn repeated(
        &mut self,
        what: &'static str,
        settings: impl IntoIterator<Item = (String, Span)>,
    ) {
        let mut first: HashMap<String, Span> = HashMap::new();
        for (name, span) in settings {
            match first.get(&name) {
                Some(f) => {
                    self.errors.push(Error::Duplicate { span: span.into(), first: (*f).into(), what, name })
                }
                None => {
                    first.insert(name, span);
                }
            }
        }
    }

    /// Gene settings named twice in the `genome` blocks of one scope.
    fn repeated_genes<'g>(&mut self, blocks: impl IntoIterator<Item = &'g ast::GenomeBlock>) {
        let mut settings = Vec::new();
        for set in blocks.into_iter().flat_map(|b| &b.settings) {
            let group = set.group.as_ref().map(|g| format!("{} ", g.text)).unwrap_or_default();
            if let Some(q) = &set.bits {
                settings.push((format!("{group}bits"), q.span));
            }
            if let Some(r) = &set.range {
                settings.push((format!("{group}range"), r.span));
            }
        }
        self.repeated("gene setting", settings);
    }

    // ------------------------------------------------------------ quantities

    /// A whole number, with no unit or `actions`.
    fn count(&mut self, q: &Quantity, what: &str, min: u64) -> Option<u64> {
        self.count_in(q, what, min, u32::MAX as u64)
    }

    /// A whole number in `min..=max`; above `max` it is refused as a
    /// resource limit (see `shaping_runtime::limits`).
    fn count_in(&mut self, q: &Quantity, what: &str, min: u64, max: u64) -> Option<u64> {
        if let Some(u) = q.unit {
            if u != Unit::Actions {
                self.errors.push(Error::Unit {
                    span: q.span.into(),
                    expected: "a count",
                    found: unit_desc(u),
                    help: Some(format!("{what} is a whole number, with no unit or `actions`")),
                });
                return None;
            }
        }
        if q.value.fract() != 0.0 || q.value < 0.0 || !q.value.is_finite() {
            self.value_error(q.span, format!("{what} must be a whole number"), "not a whole number", None);
            return None;
        }
        if q.value > max as f64 {
            let help = (max < u32::MAX as u64)
                .then(|| "this limit keeps a run within the memory and time of one machine".to_string());
            self.value_error(q.span, format!("{what} must be at most {max}"), "too large", help);
            return None;
        }
        let v = q.value as u64;
        if v < min {
            self.value_error(q.span, format!("{what} must be at least {min}"), "too small", None);
            return None;
        }
        Some(v)
    }

    /// A length in mm (`mm`, `cm` or no unit), positive.
    fn length(&mut self, q: &Quantity, what: &str) -> Option<f32> {
        self.millimetres(q, what, false)
    }

    /// A coordinate in mm (`mm`, `cm` or no unit): 0 and negative values
    /// allowed, at most [`MAX_LENGTH_MM`] in magnitude.
    fn coordinate(&mut self, q: &Quantity, what: &str) -> Option<f32> {
        self.millimetres(q, what, true)
    }

    fn millimetres(&mut self, q: &Quantity, what: &str, coordinate: bool) -> Option<f32> {
        let factor = match q.unit {
            None | Some(Unit::Mm) => 1.0,
            Some(Unit::Cm) => 10.0,
            Some(u) => {
                self.errors.push(Error::Unit {
                    span: q.span.into(),
                    expected: "a length",
                    found: unit_desc(u),
                    help: Some(format!(
                        "{what} is a length in `mm` or `cm`, or a number of millimetres without a unit"
                    )),
                });
                return None;
            }
        };
        let mm = q.value * factor;
        if coordinate {
            if !(q.value.is_finite() && mm.abs() <= MAX_LENGTH_MM as f64) {
                self.value_error(
                    q.span,
                    format!("{what} must be within {MAX_LENGTH_MM} mm of the arena's corner"),
                    "too far",
                    None,
                );
                return None;
            }
            return Some(mm as f32);
        }
        // Checked as the runtime will hold it: `1e-46` is 0 in f32.
        if !(q.value.is_finite() && mm as f32 > 0.0) {
            self.value_error(q.span, format!("{what} must be positive"), "not positive", None);
            return None;
        }
        if mm > MAX_LENGTH_MM as f64 {
            self.value_error(
                q.span,
                format!("{what} must be at most {MAX_LENGTH_MM} mm"),
                "too long",
                Some("lengths are in mm (or `cm`); an arena is a few metres at most".into()),
            );
            return None;
        }
        Some(mm as f32)
    }

    /// A plain number (no unit), within `lo..=hi`.
    fn plain(&mut self, q: &Quantity, what: &str, lo: f64, hi: f64) -> Option<f32> {
        if let Some(u) = q.unit {
            self.errors.push(Error::Unit {
                span: q.span.into(),
                expected: "a plain number",
                found: unit_desc(u),
                help: Some(format!("{what} has no unit")),
            });
            return None;
        }
        self.in_range(q.value, q.span, what, lo, hi)
    }

    fn in_range(&mut self, v: f64, span: Span, what: &str, lo: f64, hi: f64) -> Option<f32> {
        if !(v >= lo && v <= hi) {
            self.value_error(span, format!("{what} must be between {lo} and {hi}"), "out of range", None);
            return None;
        }
        Some(v as f32)
    }

    /// A value range `lo..hi` with `lo < hi`.
    fn range(&mut self, r: &ast::Range) -> Option<(f32, f32)> {
        if !(r.lo.is_finite() && r.hi.is_finite()) {
            self.value_error(r.span, "range bounds must be finite numbers".into(), "not finite", None);
            return None;
        }
        if r.lo >= r.hi {
            let why = if r.lo == r.hi { "empty" } else { "inverted" };
            self.errors.push(Error::BadRange {
                span: r.span.into(),
                range: format!("{}..{}", r.lo, r.hi),
                why,
                help: Some("a range goes from its lower to its higher bound, as in `-1..1`".into()),
            });
            return None;
        }
        // Checked as the runtime will hold it: in 32-bit floats, a gene is
        // decoded as `lo + (hi - lo) * u` and a random weight drawn from a
        // range of width `hi - lo`, so that width must be a finite number.
        let (lo, hi) = (r.lo as f32, r.hi as f32);
        if !(hi - lo).is_finite() {
            self.value_error(
                r.span,
                "the range is too wide: `hi - lo` must be at most about 3.4e38".into(),
                "too wide",
                Some("the runtime computes in 32-bit floats; narrow the range, as in `-1e38..1e38`".into()),
            );
            return None;
        }
        if lo >= hi {
            self.errors.push(Error::BadRange {
                span: r.span.into(),
                range: format!("{}..{}", r.lo, r.hi),
                why: "empty",
                help: Some("its bounds are the same 32-bit number (the runtime computes in 32-bit floats); write bounds further apart".into()),
            });
            return None;
        }
        Some((lo, hi))
    }

    // ------------------------------------------------------------ program

    fn program(&mut self, file_name: &str) -> Program {
        let file = self.file;
        for r in file.robots.iter().skip(1) {
            self.errors.push(Error::Conflict {
                span: r.name.span.into(),
                other: file.robots[0].name.span.into(),
                message: "a file has one robot; a stage adds hardware with `robot adds { ... }`".into(),
                label: "a second robot".into(),
                other_label: "the robot of this file".into(),
            });
        }
        let name = file.robots.first().map(|r| r.name.text.clone()).unwrap_or_else(|| stem(file_name));
        if file.stages.is_empty() {
            let at = file.robots.first().map(|r| r.name.span).unwrap_or_default();
            self.value_error(
                at,
                "the file declares no stage".into(),
                "no stage in this file",
                Some("add `stage NAME { ... }` with the modules to train".into()),
            );
        }
        if let Some(extra) = file.stages.get(MAX_STAGES) {
            self.value_error(
                extra.name.span,
                format!("the file has more than {MAX_STAGES} stages"),
                "one stage too many",
                None,
            );
            return Program { format: FORMAT_VERSION, name, stages: Vec::new() };
        }
        let by_name = self.stages_by_name();
        let (parent, orphan) = self.parents(&by_name);
        let in_cycle = self.stage_cycles(&parent);
        let (order, index) = self.stage_order(&by_name, &parent, &in_cycle);
        let mut states: Vec<StageSt> = Vec::new();
        let mut stages: Vec<Stage> = Vec::new();
        for &i in &order {
            let decl = &file.stages[i];
            let s = stages.len() as u16;
            self.stage_names.push(decl.name.text.clone());
            let parent_index = parent[i].and_then(|p| index[p]);
            let base = match parent_index {
                Some(p) => states[p].clone(),
                None => self.root_state(s),
            };
            // A stage whose parent is unknown is checked as if it had none;
            // most of its errors would be consequences of the missing parent,
            // but those about the robot, numbers and names that no stage of
            // the file could have declared are its own.
            let saved = self.errors.len();
            let (state, stage) = self.stage(decl, s, parent_index, base);
            if orphan[i] {
                let own: Vec<Error> = self.errors.drain(saved..).filter(checkable_without_parent).collect();
                self.errors.extend(own);
            }
            if let Some(p) = parent_index {
                if let (StageRun::Train { .. }, Some(e)) = (&stages[p].run, &decl.extends) {
                    self.value_error(
                        e.span,
                        format!("stage `{}` extends training stage `{}`", decl.name.text, stages[p].name),
                        "a training stage",
                        Some(format!(
                            "use what it learned with `weights trained {}` in a neural behavior",
                            stages[p].name
                        )),
                    );
                }
            }
            self.check_training(decl, &stage, s);
            states.push(state);
            stages.push(stage);
        }
        Program { format: FORMAT_VERSION, name, stages }
    }

    /// The stages by name (a duplicate name reported), and where the
    /// hardware and the modules of later stages come from.
    fn stages_by_name(&mut self) -> HashMap<&'a str, usize> {
        let file = self.file;
        let mut by_name: HashMap<&str, usize> = HashMap::new();
        for (i, s) in file.stages.iter().enumerate() {
            if let Some(&j) = by_name.get(s.name.text.as_str()) {
                self.errors.push(Error::Duplicate {
                    span: s.name.span.into(),
                    first: file.stages[j].name.span.into(),
                    what: "stage",
                    name: s.name.text.clone(),
                });
            } else {
                by_name.insert(&s.name.text, i);
            }
            for item in &s.items {
                if let ast::StageItem::RobotAdds(hw, _) = item {
                    for h in hw {
                        self.hw_origin.entry(h.name.text.clone()).or_insert_with(|| s.name.text.clone());
                    }
                }
            }
            for m in s.all_modules() {
                self.module_origin.entry(m.name.text.clone()).or_insert_with(|| s.name.text.clone());
            }
        }
        by_name
    }

    /// The stage each stage extends, and which stages extend an unknown one
    /// (reported).
    fn parents(&mut self, by_name: &HashMap<&str, usize>) -> (Vec<Option<usize>>, Vec<bool>) {
        let file = self.file;
        let mut parent: Vec<Option<usize>> = vec![None; file.stages.len()];
        let mut orphan = vec![false; file.stages.len()];
        for (i, s) in file.stages.iter().enumerate() {
            if let Some(p) = &s.extends {
                match by_name.get(p.text.as_str()) {
                    Some(&j) => parent[i] = Some(j),
                    None => {
                        orphan[i] = true;
                        self.errors.push(Error::Unknown {
                            span: p.span.into(),
                            what: "stage",
                            name: p.text.clone(),
                            help: did_you_mean(&p.text, file.stages.iter().map(|s| s.name.text.as_str())),
                        });
                    }
                }
            }
        }
        (parent, orphan)
    }

    /// The order in which the stages are lowered (their indices in the file),
    /// and each stage's place in it: none for a stage left out (a duplicate
    /// name, in a cycle, or extending one left out).
    fn stage_order(
        &self,
        by_name: &HashMap<&str, usize>,
        parent: &[Option<usize>],
        in_cycle: &[bool],
    ) -> (Vec<usize>, Vec<Option<usize>>) {
        let file = self.file;
        // Dependency order, stable by declaration: parents first, and the
        // stages whose weights a stage uses (`weights trained STAGE`). Uses
        // that depend on each other cannot all be met: then the first stage
        // whose parent is ready goes next, and reports the use it misses.
        let uses: Vec<Vec<usize>> = file
            .stages
            .iter()
            .map(|s| trained_uses(s).filter_map(|n| by_name.get(n.text.as_str()).copied()).collect())
            .collect();
        let mut index: Vec<Option<usize>> = vec![None; file.stages.len()];
        let mut order = Vec::new();
        let eligible = |i: usize, index: &[Option<usize>]| {
            index[i].is_none()
                && !in_cycle[i]
                && by_name.get(file.stages[i].name.text.as_str()) == Some(&i)
                && parent[i].is_none_or(|p| index[p].is_some())
        };
        loop {
            let mut progress = false;
            for i in 0..file.stages.len() {
                if eligible(i, &index) && uses[i].iter().all(|&u| u == i || index[u].is_some()) {
                    index[i] = Some(order.len());
                    order.push(i);
                    progress = true;
                }
            }
            if !progress {
                let Some(i) = (0..file.stages.len()).find(|&i| eligible(i, &index)) else { break };
                index[i] = Some(order.len());
                order.push(i);
            }
        }
        (order, index)
    }

    /// The stages in a cycle of `extends` (walking up from every stage),
    /// each cycle reported once.
    fn stage_cycles(&mut self, parent: &[Option<usize>]) -> Vec<bool> {
        let file = self.file;
        let mut in_cycle = vec![false; file.stages.len()];
        for i in 0..file.stages.len() {
            let mut path = vec![i];
            let mut cur = i;
            while let Some(p) = parent[cur] {
                if let Some(pos) = path.iter().position(|&x| x == p) {
                    let cycle = &path[pos..];
                    if cycle.iter().all(|&c| !in_cycle[c]) {
                        let mut members = cycle.to_vec();
                        members.sort_unstable();
                        for &c in &members {
                            in_cycle[c] = true;
                        }
                        let first = members[0];
                        let text: Vec<String> = {
                            let mut order = vec![first];
                            let mut c = first;
                            while let Some(p) = parent[c] {
                                if p == first {
                                    break;
                                }
                                order.push(p);
                                c = p;
                            }
                            order.push(first);
                            order.iter().map(|&c| format!("`{}`", file.stages[c].name.text)).collect()
                        };
                        let span_of = |c: usize| {
                            file.stages[c]
                                .extends
                                .as_ref()
                                .map(|e| e.span)
                                .unwrap_or(file.stages[c].name.span)
                        };
                        self.errors.push(Error::Cycle {
                            span: span_of(first).into(),
                            cycle: text.join(" extends "),
                            others: members[1..]
                                .iter()
                                .map(|&c| {
                                    miette::LabeledSpan::new_with_span(
                                        Some("and this one".into()),
                                        span_of(c),
                                    )
                                })
                                .collect(),
                        });
                    }
                    break;
                }
                path.push(p);
                cur = p;
            }
        }
        in_cycle
    }

    /// A training stage (`train ...`): it must have no genes, and its
    /// modules' shapes are kept for the stages that use its weights.
    fn check_training(&mut self, decl: &ast::StageDecl, stage: &Stage, s: u16) {
        let trains = decl.items.iter().any(|i| matches!(i, ast::StageItem::Train { .. }));
        if let (StageRun::Train { .. }, true) = (&stage.run, trains) {
            if !stage.layout.genes.is_empty() {
                self.value_error(
                    decl.name.span,
                    format!(
                        "training stage `{}` evolves nothing, but declares {} genes",
                        decl.name.text,
                        stage.layout.genes.len()
                    ),
                    "has genes",
                    Some(
                        "declare its activation weights, behavior weights and links `fixed` or `random`"
                            .into(),
                    ),
                );
            }
            let shapes = stage
                .modules
                .iter()
                .map(|m| {
                    let shape = match &m.behavior {
                        Behavior::Neural(nb) => TrainedShape::Network((
                            nb.net.inputs,
                            nb.net.hidden,
                            nb.net.outputs,
                            nb.net.recurrent,
                        )),
                        // A script has a step: none is the placeholder of a failed behavior.
                        Behavior::Script(sc) if sc.steps.is_empty() => TrainedShape::Failed,
                        Behavior::Script(_) => TrainedShape::Script,
                    };
                    let a = &m.activation;
                    (m.name.clone(), shape, (a.inputs, a.hidden, a.outputs, a.recurrent))
                })
                .collect();
            self.trained.insert(decl.name.text.clone(), (s, shapes));
        }
    }

    fn root_state(&mut self, s: u16) -> StageSt {
        let spec = GeneSpec { bits: DEFAULT_BITS, lo: -1.0, hi: 1.0 };
        let mut st = StageSt {
            sensors: Vec::new(),
            actuators: Vec::new(),
            world: WorldSt {
                world: World {
                    arena: [400.0, 600.0],
                    body: Body::default(),
                    charger: None,
                    battery: None,
                    objects: None,
                    items: Default::default(),
                    robots: 1,
                },
                spans: HashMap::new(),
                item_spans: HashMap::new(),
                arena_bare: false,
                refused: Default::default(),
            },
            genome: GenomeSt { links: spec, weights: spec, biases: spec },
            evolution: default_evolution(),
            keep_default: true,
            population_span: None,
            inheritance: Inheritance::Darwinian,
            run: StageRun::Evolve(default_evolution()),
            fitness: Fitness {
                per_action: None,
                at_end: None,
                bonuses: Vec::new(),
                team: Default::default(),
            },
            fitness_declared: false,
            fitness_reported: false,
            modules: Vec::new(),
            links: Vec::new(),
            genes: Vec::new(),
            bits: 0,
            targets: Vec::new(),
            variants: None,
            roles: Vec::new(),
            role_heads: Vec::new(),
        };
        let file = self.file;
        if let Some(r) = file.robots.first() {
            // Report hardware errors of the robot once, for the first root stage.
            let report = s == 0;
            let saved = self.errors.len();
            self.hardware(&mut st, &r.hardware, s);
            if !report {
                self.errors.truncate(saved);
            }
        }
        if s == 0 {
            self.repeated_genes(&file.genomes);
        }
        for g in &file.genomes {
            let saved = self.errors.len();
            self.genome(&mut st.genome, g);
            if s != 0 {
                self.errors.truncate(saved);
            }
        }
        st
    }

    fn hardware(&mut self, st: &mut StageSt, hw: &[ast::Hardware], s: u16) {
        for h in hw {
            let first = st
                .sensors
                .iter()
                .map(|x| (&x.name, x.span))
                .chain(st.actuators.iter().map(|x| (&x.name, x.span)))
                .find(|(n, _)| **n == h.name.text)
                .map(|(_, sp)| sp);
            if let Some(first) = first {
                self.errors.push(Error::Duplicate {
                    span: h.name.span.into(),
                    first: first.into(),
                    what: if h.is_sensor { "sensor" } else { "actuator" },
                    name: h.name.text.clone(),
                });
                continue;
            }
            if h.is_sensor {
                let Some(info) = catalog::sensor_by_keyword(&h.kind.text) else {
                    self.poisoned.insert(h.name.text.clone());
                    let kinds: Vec<&str> = catalog::SENSORS.iter().map(|s| s.keyword).collect();
                    self.errors.push(Error::Unknown {
                        span: h.kind.span.into(),
                        what: "sensor kind",
                        name: h.kind.text.clone(),
                        help: did_you_mean(&h.kind.text, kinds.iter().copied())
                            .or_else(|| Some(format!("the sensor kinds are {}", expr::backticked(&kinds)))),
                    });
                    continue;
                };
                let count = match h.count {
                    None => 1,
                    Some((n, sp)) => {
                        if n == 0 || n as usize > info.max_count {
                            self.value_error(
                                sp,
                                format!(
                                    "a sensor of kind `{}` has 1 to {} elements, not {n}",
                                    info.keyword, info.max_count
                                ),
                                "wrong number of elements",
                                None,
                            );
                        }
                        (n as usize).clamp(1, info.max_count) as u16
                    }
                };
                if let Some(other) = st.sensors.iter().find(|x| x.kind == info.kind) {
                    self.poisoned.insert(h.name.text.clone());
                    self.errors.push(Error::Conflict {
                        span: h.span.into(),
                        other: other.span.into(),
                        message: format!(
                            "sensors `{}` and `{}` are both `{}` sensors",
                            other.name, h.name.text, info.keyword
                        ),
                        label: "second one here".into(),
                        other_label: "first one here".into(),
                    });
                    continue;
                }
                st.sensors.push(SensorSt {
                    name: h.name.text.clone(),
                    kind: info.kind,
                    count,
                    channel: info.channel as u16,
                    stage: s,
                    span: h.span,
                });
            } else {
                let Some(info) = catalog::actuator_by_keyword(&h.kind.text) else {
                    self.poisoned.insert(h.name.text.clone());
                    let kinds: Vec<&str> = catalog::ACTUATORS.iter().map(|a| a.keyword).collect();
                    self.errors.push(Error::Unknown {
                        span: h.kind.span.into(),
                        what: "actuator kind",
                        name: h.kind.text.clone(),
                        help: did_you_mean(&h.kind.text, kinds.iter().copied())
                            .or_else(|| Some(format!("the actuator kinds are {}", expr::backticked(&kinds)))),
                    });
                    continue;
                };
                // A broadcast actuator has 1 to its most values; the others
                // exactly their count.
                let variable = info.kind == catalog::ActuatorKind::Broadcast;
                let mut count = info.count as u16;
                if variable {
                    count = h.count.map_or(1, |(n, _)| (n as usize).clamp(1, info.count) as u16);
                }
                if let Some((n, sp)) = h.count.filter(|_| variable) {
                    if n == 0 || n as usize > info.count {
                        self.value_error(
                            sp,
                            format!("a `broadcast` actuator has 1 to {} values, not {n}", info.count),
                            "wrong number of values",
                            None,
                        );
                    }
                } else if let Some((n, sp)) = h.count {
                    if n as usize != info.count {
                        self.value_error(
                            sp,
                            format!(
                                "an actuator of kind `{}` has {} elements, not {n}",
                                info.keyword, info.count
                            ),
                            "wrong number of elements",
                            None,
                        );
                    }
                }
                if let Some(other) = st.actuators.iter().find(|x| x.kind == info.kind) {
                    self.poisoned.insert(h.name.text.clone());
                    self.errors.push(Error::Conflict {
                        span: h.span.into(),
                        other: other.span.into(),
                        message: format!(
                            "actuators `{}` and `{}` are both `{}` actuators",
                            other.name, h.name.text, info.keyword
                        ),
                        label: "second one here".into(),
                        other_label: "first one here".into(),
                    });
                    continue;
                }
                st.actuators.push(ActuatorSt {
                    name: h.name.text.clone(),
                    kind: info.kind,
                    count,
                    slot: info.slot as u16,
                    stage: s,
                    span: h.span,
                });
            }
        }
    }

    fn genome(&mut self, g: &mut GenomeSt, block: &ast::GenomeBlock) {
        for set in &block.settings {
            let bits = set.bits.as_ref().and_then(|q| {
                let ok = q.unit.is_none() && q.value.fract() == 0.0 && (1.0..=16.0).contains(&q.value);
                if !ok {
                    self.errors.push(Error::Bits { span: q.span.into(), value: format_num(q.value, q.unit) });
                    None
                } else {
                    Some(q.value as u8)
                }
            });
            let range = set.range.as_ref().and_then(|r| self.range(r));
            let targets: Vec<&mut GeneSpec> = match set.group.as_ref().map(|n| n.text.as_str()) {
                Some("links") => vec![&mut g.links],
                Some("weights") => vec![&mut g.weights],
                Some("biases") => vec![&mut g.biases],
                _ => vec![&mut g.links, &mut g.weights, &mut g.biases],
            };
            for t in targets {
                if let Some(b) = bits {
                    t.bits = b;
                }
                if let Some((lo, hi)) = range {
                    t.lo = lo;
                    t.hi = hi;
                }
            }
        }
    }

    // ------------------------------------------------------------ one stage

    fn stage(
        &mut self,
        decl: &ast::StageDecl,
        s: u16,
        parent: Option<usize>,
        mut st: StageSt,
    ) -> (StageSt, Stage) {
        use ast::StageItem as I;
        let sname = decl.name.text.clone();
        let errors_before = self.errors.len();
        // Hardware first: everything else may use it.
        for item in &decl.items {
            if let I::RobotAdds(hw, _) = item {
                self.hardware(&mut st, hw, s);
            }
        }
        self.repeated_genes(decl.items.iter().filter_map(|i| match i {
            I::Genome(g) => Some(g),
            _ => None,
        }));
        for item in &decl.items {
            if let I::Genome(g) = item {
                self.genome(&mut st.genome, g);
            }
        }
        for item in &decl.items {
            if let I::World(w) = item {
                self.world(&mut st.world, w, &sname);
            }
        }
        let inherited_roles = !st.roles.is_empty();
        let role_decls = self.role_heads(&mut st, decl);
        let (roles, heads) = (st.roles.clone(), st.role_heads.clone());
        let changed = team_change(decl);
        self.role_robots(
            &mut st.world,
            &roles,
            &heads,
            decl.span,
            format!("the world of stage `{sname}`"),
            changed,
        );
        self.check_charger(&st.world);
        self.check_fit(&st.world, decl.name.span, decl.span);
        self.check_ground(&st, s, decl.span);
        self.rab_board(&mut st, s, decl.span);
        self.check_items(&st.world, decl.span);
        self.check_crowded(&st.world, decl.span);
        let before_team = self.errors.len();
        self.check_team(&st.world, decl.span);
        self.role_team_help(&st.roles, before_team);
        self.variants_decl(&mut st, decl);
        self.run(&mut st, decl, parent.is_some());
        let (life, life_span) = life(&st.run, decl);
        let in_stage = |sp: Span| decl.span.start <= sp.start && sp.end <= decl.span.end;
        self.check_place_life(&st.world, &sname, life, life_span, &|sp| in_stage(sp) || life_span.is_some());
        let hw = Hw {
            stage: sname.clone(),
            sensors: st.sensors.clone(),
            actuators: st.actuators.clone(),
            has_charger: st.world.world.charger.is_some()
                || st.world.world.items.zones.iter().any(|z| z.charger),
        };
        self.check_role_training(&st, decl);
        // Modules: a stage's, or its roles'.
        let role_stage = !st.roles.is_empty();
        let own_roles = self.check_role_items(&st, decl, inherited_roles);
        if own_roles {
            self.role_modules(&hw, &mut st, decl, s, &role_decls);
        }
        if !role_stage {
            self.stage_modules(&hw, &mut st, decl, s);
        }
        for m in &st.modules {
            if m.stage == s {
                self.check_module(m);
            }
        }
        if st.modules.is_empty() && decl.roles().next().is_none() {
            self.value_error(
                decl.name.span,
                format!("stage `{sname}` has no modules"),
                "no modules",
                Some("declare at least one `module NAME { ... }`".into()),
            );
        }
        if !role_stage {
            self.links(&mut st, decl, s);
        }
        self.stage_fitness(&hw, &mut st, decl, &role_decls);
        st.targets = std::mem::take(&mut self.targets);
        self.allocate(&mut st, s);
        self.check_role_genes(&st, decl);
        self.check_evolved_genes(&st, decl, s, errors_before);
        self.check_genome_size(&st, decl);
        let mut stage = assemble(&st, &sname, s, parent);
        stage.variants = self.variant_worlds(&st, &sname, decl);
        self.check_team_clause(&stage, decl);
        self.check_lamp(&st, &stage, s);
        (st, stage)
    }

    /// The modules a stage without roles declares, lowered in order after
    /// the ones it inherits (a module of the same name replaces one).
    fn stage_modules(&mut self, hw: &Hw, st: &mut StageSt, decl: &ast::StageDecl, s: u16) {
        let sname = &decl.name.text;
        let mut declared_here: HashMap<String, Span> = HashMap::new();
        for item in &decl.items {
            if let ast::StageItem::Module(m) = item {
                if !self.declare_module(&mut declared_here, &m.name) {
                    continue;
                }
                if st.modules.len() >= MAX_MODULES && !st.modules.iter().any(|x| x.name == m.name.text) {
                    self.value_error(
                        m.name.span,
                        format!("stage `{sname}` has more than {MAX_MODULES} modules"),
                        "one module too many",
                        None,
                    );
                    break;
                }
                self.similar_module(&st.modules, m, s);
                self.module(hw, &mut st.modules, m, s);
            }
        }
    }

    /// A stage's fitness (its own, replaced or added to) and its roles';
    /// an evolved stage without any is an error. The stage's targets are
    /// `self.targets` while its fitness terms are read.
    fn stage_fitness(
        &mut self,
        hw: &Hw,
        st: &mut StageSt,
        decl: &ast::StageDecl,
        role_decls: &[Option<usize>],
    ) {
        use ast::StageItem as I;
        let sname = &decl.name.text;
        // A `fitness` without `adds` replaces the fitness: after another
        // `fitness` of the same stage, it would silently drop that one.
        let mut first_fitness: Option<Span> = None;
        self.items = st.world.world.items.clone();
        self.targets = std::mem::take(&mut st.targets);
        for item in &decl.items {
            if let I::Fitness(f) = item {
                if let (Some(first), false) = (first_fitness, f.adds) {
                    self.errors.push(Error::Conflict {
                        span: f.span.into(),
                        other: first.into(),
                        message: format!(
                            "stage `{sname}` declares its fitness twice; add terms with `fitness adds ...` or after a `,`"
                        ),
                        label: "replaces the first".into(),
                        other_label: "first `fitness`".into(),
                    });
                    continue;
                }
                first_fitness = first_fitness.or(Some(f.span));
                self.fitness(hw, st, f);
            }
        }
        self.role_fitness(hw, st, decl, role_decls);
        // Where every role has a fitness of its own, the stage needs none.
        let roles_fit = !st.roles.is_empty() && st.roles.iter().all(|r| r.fitness.is_some());
        if matches!(st.run, StageRun::Evolve(_)) && !st.fitness_declared && !st.fitness_reported && !roles_fit
        {
            st.fitness_reported = true;
            self.value_error(
                decl.name.span,
                format!("stage `{sname}` evolves but has no fitness"),
                "no `fitness` for this stage",
                Some("add `fitness per action EXPR` or declare a `test` stage".into()),
            );
        }
    }
}

/// Where a stage changes the team it inherits: a role it adds or whose
/// robots it changes, or a role's robots changed in its `world`; none for
/// a stage that extends none.
fn team_change(decl: &ast::StageDecl) -> Option<Span> {
    let in_world = decl.items.iter().find_map(|i| match i {
        ast::StageItem::World(w) => w.items.iter().find_map(|x| match x {
            ast::WorldItem::RoleRobots { span, .. } => Some(*span),
            _ => None,
        }),
        _ => None,
    });
    decl.extends.as_ref().and(decl.roles().find(|r| r.robots.is_some()).map(|r| r.head()).or(in_world))
}

/// The length of a stage's lives (actions), and where `decl` sets it
/// (`actions` of `evolve`, a `test` or `train` clause), if it does.
fn life(run: &StageRun, decl: &ast::StageDecl) -> (u32, Option<Span>) {
    use ast::StageItem as I;
    let span = decl.items.iter().rev().find_map(|i| match i {
        I::Evolve(settings, _) => settings.iter().rev().find(|s| s.name.text == "actions").map(|s| s.span),
        I::Test { span, .. } | I::Train { span, .. } => Some(*span),
        _ => None,
    });
    let life = match run {
        StageRun::Evolve(e) => e.actions,
        StageRun::Test { actions, .. } | StageRun::Train { actions } => *actions,
    };
    (life, span)
}

impl Lower<'_> {
    /// Records module `name` as declared in `declared` (one stage's, or
    /// one role's): a second declaration is the error `Duplicate`, and
    /// false (the module is skipped).
    fn declare_module(&mut self, declared: &mut HashMap<String, Span>, name: &ast::Name) -> bool {
        if let Some(first) = declared.get(&name.text) {
            self.errors.push(Error::Duplicate {
                span: name.span.into(),
                first: (*first).into(),
                what: "module",
                name: name.text.clone(),
            });
            return false;
        }
        declared.insert(name.text.clone(), name.span);
        true
    }

    /// Warns about a new module whose name is one edit (or one swap of
    /// neighbours) from an inherited module's: most likely a typo that
    /// declares a module instead of changing the inherited one. Names under
    /// four letters and names that differ in digits only are left alone
    /// (`a` and `b`, `avoid` and `avoid2` are names, not typos).
    fn similar_module(&mut self, modules: &[ModuleSt], m: &ast::ModuleDecl, s: u16) {
        let name = &m.name.text;
        if name.chars().count() < 4 || modules.iter().any(|x| x.name == *name) {
            return;
        }
        let letters = |n: &str| n.chars().filter(|c| !c.is_ascii_digit()).collect::<String>();
        let close = modules.iter().find(|x| {
            x.stage < s
                && x.name.chars().count() >= 4
                && strsim::osa_distance(&x.name, name) == 1
                && letters(&x.name) != letters(name)
        });
        if let Some(x) = close {
            self.errors.push(Error::SimilarName {
                span: m.name.span.into(),
                similar_span: x.span.into(),
                name: name.clone(),
                similar: x.name.clone(),
                stage: self.stage_names.get(x.stage as usize).cloned().unwrap_or_default(),
                help: Some(format!(
                    "to change the inherited module, write `module {}`; to add a module, choose a name further from it",
                    x.name
                )),
            });
        }
    }

    /// The genome and the population's genomes within the resource limits
    /// (`shaping_runtime::limits`), checked before anything is allocated.
    fn check_genome_size(&mut self, st: &StageSt, decl: &ast::StageDecl) {
        let help = Some("this limit keeps a run within the memory of one machine".to_string());
        if st.bits > MAX_GENOME_BITS {
            self.value_error(
                decl.name.span,
                format!(
                    "stage `{}` has a genome of {} bits, more than the limit of {MAX_GENOME_BITS}",
                    decl.name.text, st.bits
                ),
                "genome too long",
                Some("use fewer evolvable weights, fewer hidden units or fewer bits per gene".into()),
            );
            return;
        }
        if let StageRun::Evolve(e) = &st.run {
            let total = u64::from(e.population) * u64::from(st.bits);
            if total > MAX_POPULATION_BITS {
                self.value_error(
                    st.population_span.unwrap_or(decl.name.span),
                    format!(
                        "a population of {} genomes of {} bits makes {total} bits, more than the limit of {MAX_POPULATION_BITS}",
                        e.population, st.bits
                    ),
                    "population too large for this genome",
                    help,
                );
            }
        }
    }
}

fn assemble(st: &StageSt, name: &str, s: u16, parent: Option<usize>) -> Stage {
    let modules = st
        .modules
        .iter()
        .map(|m| Module {
            name: m.name.clone(),
            stage: m.stage,
            inputs: m.inputs.clone(),
            activation: Network {
                inputs: m.inputs.len() as u16,
                hidden: m.hidden,
                outputs: 1,
                recurrent: m.recurrent && m.hidden > 0,
                params: m.act_params.clone(),
            },
            behavior: m.behavior.clone().unwrap_or(Behavior::Script(Script { steps: vec![], commit: false })),
            learning: m.learning.clone(),
            reinforce: m.reinforce.clone(),
        })
        .collect();
    let mut links: Vec<&LinkSt> = st.links.iter().collect();
    links.sort_by_key(|l| (l.to, l.from));
    let links = links
        .into_iter()
        .map(|l| Link { from: l.from, to: l.to, weight: l.param.unwrap_or(Param::Fixed(0.0)) })
        .collect();
    let genes = st.genes.iter().map(|g| Gene { frozen: g.stage < s, ..g.clone() }).collect();
    Stage {
        name: name.to_string(),
        parent,
        sensors: st
            .sensors
            .iter()
            .map(|x| SensorDecl {
                name: x.name.clone(),
                kind: x.kind,
                count: x.count,
                channel: x.channel,
                stage: x.stage,
            })
            .collect(),
        actuators: st
            .actuators
            .iter()
            .map(|x| ActuatorDecl { name: x.name.clone(), kind: x.kind, stage: x.stage })
            .collect(),
        world: st.world.world.clone(),
        modules,
        links,
        layout: GenomeLayout { genes, bits: st.bits },
        fitness: st.fitness.clone(),
        run: st.run.clone(),
        inheritance: st.inheritance,
        variants: None,
        targets: st.targets.clone(),
        roles: st.roles.clone(),
    }
}

/// The stages named by the `weights trained STAGE` and `activation trained
/// STAGE` of a stage's modules.
fn trained_uses(s: &ast::StageDecl) -> impl Iterator<Item = &ast::Name> {
    s.all_modules().flat_map(|m| {
        m.items.iter().filter_map(|mi| match mi {
            ast::ModuleItem::Behavior(ast::BehaviorDecl::Neural(n)) => match &n.weights {
                Some(ast::WeightSource::Trained(by, _)) => Some(by),
                _ => None,
            },
            ast::ModuleItem::Activation(a) => match &a.source {
                Some(ast::WeightSource::Trained(by, _)) => Some(by),
                _ => None,
            },
            _ => None,
        })
    })
}

fn unit_desc(u: Unit) -> String {
    match u {
        Unit::Mm | Unit::Cm => format!("a length (`{}`)", u.as_str()),
        Unit::Ms => "a duration (`ms`)".into(),
        Unit::Actions => "a count (`actions`)".into(),
        Unit::Deg | Unit::Rad => format!("an angle (`{}`)", u.as_str()),
    }
}

fn format_num(v: f64, unit: Option<Unit>) -> String {
    match unit {
        Some(u) => format!("{v} {}", u.as_str()),
        None => format!("{v}"),
    }
}

fn stem(file_name: &str) -> String {
    let base = file_name.rsplit(['/', '\\']).next().unwrap_or(file_name);
    base.strip_suffix(".bat").unwrap_or(base).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn network_roles_follow_the_parameter_order_of_network() {
        for (i, h, o) in [(0, 0, 1), (3, 0, 1), (8, 0, 2), (2, 3, 1), (4, 2, 3)] {
            let roles = network_roles(i, h, o, false);
            assert_eq!(roles.len(), Network::param_count(i, h, o));
            let roles = network_roles(i, h, o, true);
            assert_eq!(roles.len(), Network::param_count_of(i, h, o, true));
        }
        assert_eq!(
            network_roles(1, 2, 1, true)[..4],
            [
                GeneRole::HiddenBias { hidden: 0 },
                GeneRole::Weight { input: 0, hidden: Some(0) },
                GeneRole::Context { from: 0, hidden: 0 },
                GeneRole::Context { from: 1, hidden: 0 },
            ]
        );
        assert_eq!(
            network_roles(2, 0, 1, false),
            [
                GeneRole::Bias,
                GeneRole::Weight { input: 0, hidden: None },
                GeneRole::Weight { input: 1, hidden: None }
            ]
        );
        assert_eq!(
            network_roles(1, 2, 1, false),
            [
                GeneRole::HiddenBias { hidden: 0 },
                GeneRole::Weight { input: 0, hidden: Some(0) },
                GeneRole::HiddenBias { hidden: 1 },
                GeneRole::Weight { input: 0, hidden: Some(1) },
                GeneRole::Bias,
                GeneRole::HiddenOut { hidden: 0 },
                GeneRole::HiddenOut { hidden: 1 },
            ]
        );
    }

    #[test]
    fn stems() {
        assert_eq!(stem("examples/khepera.bat"), "khepera");
        assert_eq!(stem("C:\\x\\a.bat"), "a");
        assert_eq!(stem("noext"), "noext");
    }
}
