//! `--set STAGE.SECTION.FIELD=V1,V2,...`: settings of the compiled program
//! changed from the command line (`run` takes one value, `experiment` sweeps
//! the cartesian product of several).
//!
//! A value is applied to the compiled `Program` and the program is then
//! validated again as a whole (`Program::validate`), so a bad value gets the
//! message a bad `program.json` would. A value set on a stage also goes to
//! the stages that extend it (directly or not) where they had the stage's
//! value before the change, as an inherited setting does in a file; a stage
//! that had another value keeps it. `*` in place of the stage sets every
//! stage that has the field.

use shaping_compiler::diag::did_you_mean;
use shaping_runtime::program::{
    Aggregate, Evolution, Inheritance, LearnWhen, Module, Program, Selection, Stage, StageRun, World,
};

use crate::error::{Error, ErrorKind};

/// One `--set TARGET=V1,V2,...`, as written: `TARGET` is `STAGE.PATH`.
#[derive(Clone, Debug, PartialEq)]
pub struct Set {
    pub target: String,
    pub values: Vec<String>,
}

/// One setting of a point: a target and one of its values.
pub type Assignment = (String, String);

/// Splits `TARGET=V1,V2,...` (the syntax only; [`apply`] resolves it).
pub fn parse_set(text: &str) -> Result<Set, String> {
    let (target, values) = text
        .split_once('=')
        .ok_or_else(|| format!("`{text}` is not of the form STAGE.SECTION.FIELD=V1,V2,..."))?;
    let target = target.trim();
    if target.split('.').count() < 3 || target.split('.').any(str::is_empty) {
        return Err(format!(
            "`{target}` is not of the form STAGE.SECTION.FIELD (`navigation.evolve.mutation`)"
        ));
    }
    let values: Vec<String> = values.split(',').map(|v| v.trim().to_string()).collect();
    if values.iter().any(String::is_empty) {
        return Err(format!("`{text}` has an empty value"));
    }
    Ok(Set { target: target.to_string(), values })
}

/// Every point of the sweep: the cartesian product of the values, the first
/// `--set` varying slowest. No `--set`: one point with no assignment.
pub fn points(sets: &[Set]) -> Vec<Vec<Assignment>> {
    let mut out: Vec<Vec<Assignment>> = vec![Vec::new()];
    for s in sets {
        out = out
            .into_iter()
            .flat_map(|p| {
                s.values.iter().map(move |v| {
                    let mut q = p.clone();
                    q.push((s.target.clone(), v.clone()));
                    q
                })
            })
            .collect();
    }
    out
}

/// The name of a point, and its directory in an experiment:
/// `navigation.evolve.mutation=0.02,collect.evolve.mutation=0.01`.
pub fn point_name(point: &[Assignment]) -> String {
    point.iter().map(|(t, v)| format!("{t}={v}")).collect::<Vec<_>>().join(",")
}

/// The directory of a point in a sweep of `sets`: its name without the
/// settings every point shares (a `--set` of one value), unless every
/// setting has one value, and with `*` (every stage) written `all`:
/// `navigation.evolve.mutation=0.02,collect.evolve.mutation=0.01`.
pub fn point_dir_name(point: &[Assignment], sets: &[Set]) -> String {
    let varies = |t: &str| sets.iter().any(|s| s.target == t && s.values.len() > 1);
    let shown: Vec<Assignment> = if point.iter().any(|(t, _)| varies(t)) {
        point.iter().filter(|(t, _)| varies(t)).cloned().collect()
    } else {
        point.to_vec()
    };
    point_name(&shown)
        .split(',')
        .map(|a| match a.strip_prefix("*.") {
            Some(rest) => format!("all.{rest}"),
            None => a.to_string(),
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// Checks the sets of an experiment: a target set twice is an error.
pub fn check_sets(sets: &[Set]) -> Result<(), Error> {
    for (i, s) in sets.iter().enumerate() {
        if sets[..i].iter().any(|t| t.target == s.target) {
            return Err(Error::invalid_setting(
                &s.target,
                None,
                format!("error: `--set {}` is given twice", s.target),
            ));
        }
        if let Some(v) = s.values.iter().enumerate().find_map(|(k, v)| s.values[..k].contains(v).then_some(v))
        {
            return Err(Error::invalid_setting(
                &s.target,
                Some(v.as_str()),
                format!("error: `--set {}`: the value `{v}` is given twice", s.target),
            ));
        }
    }
    Ok(())
}

/// Applies a point's settings to `program` and validates the result.
pub fn apply(program: &mut Program, point: &[Assignment]) -> Result<(), Error> {
    for (target, text) in point {
        let fail = |m: String| {
            Error::invalid_setting(target, Some(text), format!("error: `--set {target}={text}`: {m}"))
        };
        let (stage, path) = target.split_once('.').ok_or_else(|| fail("no stage in the target".into()))?;
        let indices: Vec<usize> = if stage == "*" {
            let having: Vec<usize> =
                (0..program.stages.len()).filter(|&i| get(&program.stages[i], path).is_ok()).collect();
            if having.is_empty() {
                check_path(program, 0, path).map_err(fail)?;
                return Err(fail(format!("no stage has `{path}`")));
            }
            having
        } else {
            let names = program.stages.iter().map(|s| s.name.as_str());
            let i = program.stage(stage).map(|(i, _)| i).ok_or_else(|| {
                let hint = did_you_mean(stage, names).map(|h| format!("; {h}")).unwrap_or_default();
                fail(format!("there is no stage `{stage}`{hint}"))
            })?;
            check_path(program, i, path).map_err(fail)?;
            vec![i]
        };
        let kind = kind(path).ok_or_else(|| fail(format!("`{path}` is not a setting")))?;
        let value = parse(kind, text).map_err(fail)?;
        for i in indices {
            // With `*`, a stage extending one already set may have the value.
            if stage == "*" && get(&program.stages[i], path).as_ref() == Ok(&value) {
                continue;
            }
            set(program, i, path, &value).map_err(fail)?;
        }
    }
    program.validate().map_err(|e| {
        let message = format!("error: `--set {}`: {e}", point_name(point));
        match point {
            [(target, value)] => Error::invalid_setting(target, Some(value), message),
            _ => Error::new(ErrorKind::Invalid, message),
        }
    })
}

/// The settings that make `file` (a file's program, with any settings
/// already given) into `ran` (a run's `program.json`), as `--set` values
/// in stage order, if settings alone do: each one found is applied as
/// `--set` applies it (to the stages extending it that had its value), and
/// the result must be `ran` itself. `None` when something else differs (or
/// nothing does: `Some` of none).
pub fn settings_between(file: &Program, ran: &Program) -> Option<Vec<Assignment>> {
    let names = |p: &Program| p.stages.iter().map(|s| s.name.clone()).collect::<Vec<_>>();
    if names(file) != names(ran) {
        return None;
    }
    let mut now = file.clone();
    let mut found = Vec::new();
    for i in 0..now.stages.len() {
        let stage = &now.stages[i];
        let mut paths: Vec<String> = FIELDS.iter().map(|(p, _)| p.to_string()).collect();
        for m in 0..stage.modules.len() {
            paths.extend(MODULE_FIELDS.iter().map(|(f, _)| format!("{}.{f}", stage.module_label(m))));
        }
        paths.extend(stage.roles.iter().map(|r| format!("{}.robots", r.name)));
        for path in paths {
            let (Ok(was), Ok(value)) = (get(&now.stages[i], &path), get(&ran.stages[i], &path)) else {
                continue;
            };
            if was == value {
                continue;
            }
            set(&mut now, i, &path, &value).ok()?;
            found.push((format!("{}.{path}", now.stages[i].name), text(kind(&path)?, &value)));
        }
    }
    (now == *ran).then_some(found)
}

/// A value as `--set` takes it (numbers as the `f32` they are held in).
fn text(kind: Kind, value: &Value) -> String {
    let short = |v: f64| (v as f32).to_string();
    match (kind, value) {
        (_, Value::Count(n)) => n.to_string(),
        (_, Value::Real(v)) => short(*v),
        (_, Value::Word(w)) => w.clone(),
        (Kind::Range, Value::Pair(lo, hi)) => format!("{}..{}", short(*lo), short(*hi)),
        (_, Value::Pair(w, d)) => format!("{}x{}", short(*w), short(*d)),
    }
}

/// The value kinds of the settings.
#[derive(Clone, Copy, Debug)]
enum Kind {
    /// A whole number, with an optional unit after it.
    Count(Option<&'static str>),
    /// A number, with an optional unit after it.
    Real(Option<&'static str>),
    Word(&'static [&'static str]),
    /// `WIDTHxDEPTH` in mm.
    Arena,
    /// `LO..HI`.
    Range,
}

#[derive(Clone, Debug, PartialEq)]
enum Value {
    Count(u64),
    Real(f64),
    Word(String),
    Pair(f64, f64),
}

impl Value {
    /// The value of a whole-number setting (0 for a value of another kind).
    fn whole(&self) -> Result<u32, String> {
        let n = match self {
            Value::Count(v) => *v,
            _ => 0,
        };
        u32::try_from(n).map_err(|_| format!("{n} is too large"))
    }

    /// The value of a real setting (a count as it is; 0 for a value of another kind).
    fn real(&self) -> f32 {
        let r = match self {
            Value::Count(v) => *v as f64,
            Value::Real(v) => *v,
            _ => 0.0,
        };
        r as f32
    }

    /// The value of a setting that takes a word (empty for a value of another kind).
    fn word(&self) -> &str {
        match self {
            Value::Word(w) => w.as_str(),
            _ => "",
        }
    }
}

/// The settings of a stage, with their kinds (a module's are `MODULE.FIELD`).
const FIELDS: &[(&str, Kind)] = &[
    ("evolve.population", Kind::Count(None)),
    ("evolve.generations", Kind::Count(None)),
    ("evolve.actions", Kind::Count(Some("actions"))),
    ("evolve.crossover", Kind::Real(None)),
    ("evolve.mutation", Kind::Real(None)),
    ("evolve.elitism", Kind::Count(None)),
    ("evolve.evaluations", Kind::Count(None)),
    ("evolve.keep", Kind::Count(None)),
    ("evolve.selection", Kind::Word(&["truncation", "roulette"])),
    ("evolve.inheritance", Kind::Word(&["darwinian", "lamarckian"])),
    ("test.actions", Kind::Count(Some("actions"))),
    ("test.lives", Kind::Count(None)),
    ("train.actions", Kind::Count(Some("actions"))),
    ("variants.aggregate", Kind::Word(&["mean", "min"])),
    ("variants.draw", Kind::Count(None)),
    ("fitness.team", Kind::Word(&["sum", "mean", "min"])),
    ("world.arena", Kind::Arena),
    ("world.charger", Kind::Real(Some("mm"))),
    ("world.lamp", Kind::Real(Some("mm"))),
    ("world.battery", Kind::Count(Some("actions"))),
    ("world.recharge", Kind::Count(Some("actions"))),
    ("world.objects", Kind::Count(None)),
    ("world.robots", Kind::Count(None)),
    ("world.diameter", Kind::Real(Some("mm"))),
    ("world.body.radius", Kind::Real(Some("mm"))),
    ("world.body.wheel_base", Kind::Real(Some("mm"))),
    ("world.body.v_max", Kind::Real(None)),
    ("world.body.action", Kind::Real(Some("ms"))),
    ("world.body.wheel_noise", Kind::Real(None)),
    ("world.body.sensor_noise", Kind::Real(None)),
    ("world.body.rab_signals", Kind::Word(&["on", "off"])),
];

/// A module's settings: its CRBP rates, window and threshold, and the range
/// of its evolvable activation weights.
const MODULE_FIELDS: &[(&str, Kind)] = &[
    ("reward", Kind::Real(None)),
    ("punish", Kind::Real(None)),
    ("window", Kind::Count(Some("actions"))),
    ("threshold", Kind::Real(None)),
    ("range", Kind::Range),
];

fn kind(path: &str) -> Option<Kind> {
    if let Some(&(_, k)) = FIELDS.iter().find(|(p, _)| *p == path) {
        return Some(k);
    }
    let (_, field) = path.rsplit_once('.')?;
    if field == "robots" {
        return Some(Kind::Count(None));
    }
    MODULE_FIELDS.iter().find(|(p, _)| *p == field).map(|&(_, k)| k)
}

/// `path` names a setting of stage `i` (whether the stage has it is for
/// [`get`]): else an error naming the closest one.
fn check_path(program: &Program, i: usize, path: &str) -> Result<(), String> {
    let stage = &program.stages[i];
    let module = |name: &str| (0..stage.modules.len()).any(|i| stage.module_label(i) == name);
    let role = |name: &str| stage.roles.iter().any(|r| r.name == name);
    if path == "evolve.seed" {
        return Err(
            "`evolve.seed` only gives the run seed when none is given: use `--seed` (`run`) or `--seeds` and `--first-seed` (`experiment`)"
                .into(),
        );
    }
    let known = match path.rsplit_once('.') {
        Some((r, "robots")) if role(r) => true,
        Some((m, f)) if module(m) => MODULE_FIELDS.iter().any(|(p, _)| *p == f),
        _ => FIELDS.iter().any(|(p, _)| *p == path),
    };
    if known {
        return Ok(());
    }
    if let Some((m, f)) = path.rsplit_once('.') {
        if MODULE_FIELDS.iter().any(|(p, _)| *p == f) {
            let labels: Vec<String> = (0..stage.modules.len()).map(|i| stage.module_label(i)).collect();
            let names: Vec<&str> = labels.iter().map(String::as_str).collect();
            let hint = did_you_mean(m, names.iter().copied()).map(|h| format!("; {h}")).unwrap_or_default();
            return Err(format!(
                "stage `{}` has no module `{m}`{hint} (its modules: {})",
                stage.name,
                names.join(", ")
            ));
        }
    }
    let mut all: Vec<String> = FIELDS.iter().map(|(p, _)| p.to_string()).collect();
    for i in 0..stage.modules.len() {
        all.extend(MODULE_FIELDS.iter().map(|(f, _)| format!("{}.{f}", stage.module_label(i))));
    }
    all.extend(stage.roles.iter().map(|r| format!("{}.robots", r.name)));
    let hint = did_you_mean(path, all.iter().map(String::as_str))
        .map_or_else(|| "; `shaping experiment --help` lists the settings".to_string(), |h| format!("; {h}"));
    Err(format!("stage `{}` has no setting `{path}`{hint}", stage.name))
}

fn parse(kind: Kind, text: &str) -> Result<Value, String> {
    let number = |t: &str, unit: Option<&str>| -> Result<f64, String> {
        let t = unit.and_then(|u| t.strip_suffix(u)).unwrap_or(t).trim();
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("`{text}` is not a number")),
        }
    };
    match kind {
        Kind::Count(unit) => {
            let t = unit.and_then(|u| text.strip_suffix(u)).unwrap_or(text).trim();
            t.parse::<u64>()
                .map(Value::Count)
                .map_err(|_| format!("`{text}` is not a whole number of 0 or more"))
        }
        Kind::Real(unit) => number(text, unit).map(Value::Real),
        Kind::Word(words) => {
            if words.contains(&text) {
                Ok(Value::Word(text.to_string()))
            } else {
                Err(format!("`{text}` is not one of {}", words.join(", ")))
            }
        }
        Kind::Arena => {
            let (w, d) = text
                .split_once('x')
                .ok_or_else(|| format!("`{text}` is not of the form WIDTHxDEPTH (`400x600`)"))?;
            Ok(Value::Pair(number(w, Some("mm"))?, number(d, Some("mm"))?))
        }
        Kind::Range => {
            let (lo, hi) = text
                .split_once("..")
                .ok_or_else(|| format!("`{text}` is not of the form LO..HI (`-2..2`)"))?;
            let (lo, hi) = (number(lo, None)?, number(hi, None)?);
            if lo >= hi {
                return Err(format!("the range `{text}` is empty (LO must be below HI)"));
            }
            Ok(Value::Pair(lo, hi))
        }
    }
}

/// Sets `path` of stage `i` and of the stages that extend it and had its value.
fn set(program: &mut Program, i: usize, path: &str, value: &Value) -> Result<(), String> {
    let old = get(&program.stages[i], path)?;
    // A module's activation genes are set in the stage that introduced them:
    // later stages hold them frozen, with the same range.
    if let Some((name, "range")) = path.rsplit_once('.') {
        let (_, m) = module(&program.stages[i], name)?;
        let owner = &program.stages[m.stage as usize].name;
        if m.stage as usize != i {
            return Err(format!(
                "the genes of module `{name}` are introduced by stage `{owner}` (frozen in `{}`): set `{owner}.{name}.range`",
                program.stages[i].name
            ));
        }
    }
    put(&mut program.stages[i], path, value)?;
    let mut changed = vec![false; program.stages.len()];
    changed[i] = true;
    for j in i + 1..program.stages.len() {
        let inherits = program.stages[j].parent.is_some_and(|p| changed[p]);
        if inherits && get(&program.stages[j], path).as_ref() == Ok(&old) {
            put(&mut program.stages[j], path, value)?;
            changed[j] = true;
        }
    }
    Ok(())
}

fn evolution(s: &Stage) -> Result<&Evolution, String> {
    match &s.run {
        StageRun::Evolve(e) => Ok(e),
        _ => Err(format!("stage `{}` does not evolve", s.name)),
    }
}

/// The module `name` (`ROLE.MODULE` in a stage with roles) of `s`.
fn module<'a>(s: &'a Stage, name: &str) -> Result<(usize, &'a Module), String> {
    s.modules
        .iter()
        .enumerate()
        .find(|&(i, _)| s.module_label(i) == name)
        .ok_or_else(|| format!("stage `{}` has no module `{name}`", s.name))
}

/// Activation genes of module `m` (not its links).
fn activation_gene(g: &shaping_runtime::program::Gene, m: usize) -> bool {
    g.module as usize == m && !matches!(g.role, shaping_runtime::program::GeneRole::Link { .. })
}

fn missing(s: &Stage, what: &str) -> String {
    format!("the world of stage `{}` has no {what}", s.name)
}

/// The current value of `path` in stage `s`, or why the stage has none.
fn get(s: &Stage, path: &str) -> Result<Value, String> {
    let w: &World = &s.world;
    let real = |v: f32| Ok(Value::Real(v as f64));
    let count = |v: u32| Ok(Value::Count(v as u64));
    match path {
        "evolve.population" => count(evolution(s)?.population),
        "evolve.generations" => count(evolution(s)?.generations),
        "evolve.actions" => count(evolution(s)?.actions),
        "evolve.crossover" => real(evolution(s)?.crossover),
        "evolve.mutation" => real(evolution(s)?.mutation),
        "evolve.elitism" => count(evolution(s)?.elitism),
        "evolve.evaluations" => count(evolution(s)?.evaluations),
        "evolve.keep" => match evolution(s)?.selection {
            Selection::Truncation { keep } => count(keep),
            Selection::Roulette => Err(format!("stage `{}` selects by roulette (no `keep`)", s.name)),
        },
        "evolve.selection" => Ok(Value::Word(
            match evolution(s)?.selection {
                Selection::Truncation { .. } => "truncation",
                Selection::Roulette => "roulette",
            }
            .into(),
        )),
        "evolve.inheritance" => Ok(Value::Word(
            match evolution(s).map(|_| s.inheritance)? {
                Inheritance::Darwinian => "darwinian",
                Inheritance::Lamarckian => "lamarckian",
            }
            .into(),
        )),
        "test.actions" => match s.run {
            StageRun::Test { actions, .. } => count(actions),
            _ => Err(format!("stage `{}` is not a test stage", s.name)),
        },
        "test.lives" => match s.run {
            StageRun::Test { lives, .. } => count(lives),
            _ => Err(format!("stage `{}` is not a test stage", s.name)),
        },
        "train.actions" => match s.run {
            StageRun::Train { actions } => count(actions),
            _ => Err(format!("stage `{}` is not a training stage", s.name)),
        },
        "variants.aggregate" | "variants.draw" => {
            let v = s.variants.as_ref().ok_or_else(|| format!("stage `{}` has no variants", s.name))?;
            if path == "variants.draw" {
                count(v.draw.unwrap_or(v.list.len() as u32))
            } else {
                Ok(Value::Word(v.aggregate.word().to_string()))
            }
        }
        "fitness.team" => Ok(Value::Word(s.fitness.team.word().to_string())),
        "world.arena" => Ok(Value::Pair(w.arena[0] as f64, w.arena[1] as f64)),
        "world.charger" => real(w.charger.as_ref().ok_or_else(|| missing(s, "charger"))?.length),
        "world.lamp" => {
            let c = w.charger.as_ref().ok_or_else(|| missing(s, "charger"))?;
            real(c.lamp_height.ok_or_else(|| missing(s, "lamp"))?)
        }
        "world.battery" => count(w.battery.as_ref().ok_or_else(|| missing(s, "battery"))?.capacity),
        "world.recharge" => count(w.battery.as_ref().ok_or_else(|| missing(s, "battery"))?.recharge),
        "world.objects" => count(w.objects.as_ref().ok_or_else(|| missing(s, "objects"))?.count),
        "world.diameter" => real(w.objects.as_ref().ok_or_else(|| missing(s, "objects"))?.diameter),
        "world.robots" => count(w.robots),
        "world.body.radius" => real(w.body.radius),
        "world.body.wheel_base" => real(w.body.wheel_base),
        "world.body.v_max" => real(w.body.v_max),
        "world.body.action" => real(w.body.action_ms),
        "world.body.wheel_noise" => real(w.body.wheel_noise),
        "world.body.sensor_noise" => real(w.body.sensor_noise),
        "world.body.rab_signals" => {
            let rab = w.body.rab.as_ref().ok_or_else(|| missing(s, "range-and-bearing board"))?;
            Ok(Value::Word(if rab.silenced { "off" } else { "on" }.into()))
        }
        _ => {
            let (name, field) = path.rsplit_once('.').ok_or_else(|| format!("`{path}` is not a setting"))?;
            if let (Some(role), "robots") = (s.roles.iter().find(|r| r.name == name), field) {
                return count(role.robots);
            }
            let (mi, m) = module(s, name)?;
            let learning = || {
                m.learning
                    .as_ref()
                    .ok_or_else(|| format!("module `{name}` of stage `{}` does not learn", s.name))
            };
            match field {
                "reward" => real(learning()?.rate_reward),
                "punish" => real(learning()?.rate_punish),
                "window" => count(learning()?.window),
                "threshold" => match learning()?.when {
                    LearnWhen::Below { threshold } => real(threshold),
                    LearnWhen::Always => {
                        Err(format!("module `{name}` of stage `{}` learns always (no threshold)", s.name))
                    }
                },
                "range" => {
                    let g = s.layout.genes.iter().find(|g| activation_gene(g, mi)).ok_or_else(|| {
                        format!("module `{name}` of stage `{}` has no evolvable activation weights", s.name)
                    })?;
                    Ok(Value::Pair(g.lo as f64, g.hi as f64))
                }
                _ => Err(format!("`{path}` is not a setting")),
            }
        }
    }
}

/// Writes `value` into the setting `path` (`world.…`) of a world of stage `name`.
fn put_world(w: &mut World, name: &str, path: &str, value: &Value) -> Result<(), String> {
    let r32 = value.real();
    match path {
        "world.arena" => {
            if let Value::Pair(a, b) = value {
                w.arena = [*a as f32, *b as f32];
            }
        }
        "world.charger" => {
            w.charger.as_mut().ok_or_else(|| format!("stage `{name}` has no charger"))?.length = r32
        }
        "world.lamp" => {
            w.charger.as_mut().ok_or_else(|| format!("stage `{name}` has no charger"))?.lamp_height =
                Some(r32)
        }
        "world.battery" => {
            w.battery.as_mut().ok_or_else(|| format!("stage `{name}` has no battery"))?.capacity =
                value.whole()?
        }
        "world.recharge" => {
            w.battery.as_mut().ok_or_else(|| format!("stage `{name}` has no battery"))?.recharge =
                value.whole()?
        }
        "world.objects" => {
            w.objects.as_mut().ok_or_else(|| format!("stage `{name}` has no objects"))?.count =
                value.whole()?
        }
        "world.diameter" => {
            w.objects.as_mut().ok_or_else(|| format!("stage `{name}` has no objects"))?.diameter = r32
        }
        "world.robots" => w.robots = value.whole()?,
        "world.body.radius" => w.body.radius = r32,
        "world.body.wheel_base" => w.body.wheel_base = r32,
        "world.body.v_max" => w.body.v_max = r32,
        "world.body.action" => w.body.action_ms = r32,
        "world.body.wheel_noise" => w.body.wheel_noise = r32,
        "world.body.sensor_noise" => w.body.sensor_noise = r32,
        "world.body.rab_signals" => {
            w.body
                .rab
                .as_mut()
                .ok_or_else(|| format!("stage `{name}` has no range-and-bearing board"))?
                .silenced = value.word() == "off"
        }
        _ => return Err(format!("`{path}` is not a setting")),
    }
    Ok(())
}

/// Writes `value` into `path` of stage `s` (its presence checked by [`get`]).
fn put(s: &mut Stage, path: &str, value: &Value) -> Result<(), String> {
    let name = s.name.clone();
    if let Some(rest) = path.strip_prefix("evolve.") {
        return put_evolve(s, rest, path, value);
    }
    if let Some(rest) = path.strip_prefix("variants.") {
        let v = s.variants.as_mut().ok_or_else(|| format!("stage `{name}` has no variants"))?;
        match rest {
            "aggregate" => v.aggregate = if value.word() == "min" { Aggregate::Min } else { Aggregate::Mean },
            "draw" => v.draw = Some(value.whole()?),
            _ => return Err(format!("`{path}` is not a setting")),
        }
        return Ok(());
    }
    if path == "fitness.team" {
        s.fitness.team = match value.word() {
            "sum" => Aggregate::Sum,
            "min" => Aggregate::Min,
            _ => Aggregate::Mean,
        };
        return Ok(());
    }
    if path == "world.robots" && !s.roles.is_empty() {
        let roles: Vec<String> = s.roles.iter().map(|r| format!("`{name}.{}.robots`", r.name)).collect();
        return Err(format!(
            "stage `{name}` has roles: its robots are its roles' (set {})",
            roles.join(", ")
        ));
    }
    if path.starts_with("world.") {
        // The variants' worlds have the stage's arena, body, charger ...
        // (a variant changes items): the setting changes them too.
        if let Some(v) = s.variants.as_mut() {
            for x in &mut v.list {
                put_world(&mut x.world, &name, path, value)?;
            }
        }
        return put_world(&mut s.world, &name, path, value);
    }
    match path {
        "test.actions" | "train.actions" => match &mut s.run {
            StageRun::Test { actions, .. } | StageRun::Train { actions } => *actions = value.whole()?,
            StageRun::Evolve(_) => return Err(format!("stage `{name}` evolves")),
        },
        "test.lives" => match &mut s.run {
            StageRun::Test { lives, .. } => *lives = value.whole()?,
            _ => return Err(format!("stage `{name}` is not a test stage")),
        },
        _ => {
            let (module_name, field) =
                path.rsplit_once('.').ok_or_else(|| format!("`{path}` is not a setting"))?;
            if let (Some(r), "robots") = (s.roles.iter().position(|r| r.name == module_name), field) {
                return put_role_robots(s, r, value);
            }
            return put_module(s, module_name, field, path, value);
        }
    }
    Ok(())
}

/// Writes `value` into the setting `evolve.REST` (`path`) of stage `s`.
fn put_evolve(s: &mut Stage, rest: &str, path: &str, value: &Value) -> Result<(), String> {
    let StageRun::Evolve(e) = &mut s.run else { return Err(format!("stage `{}` does not evolve", s.name)) };
    match rest {
        "population" => {
            let new = value.whole()?;
            // The default `keep` is a fifth of the population, as in the compiler.
            if let Selection::Truncation { keep } = &mut e.selection {
                if *keep == (e.population / 5).max(1) {
                    *keep = (new / 5).max(1);
                }
            }
            e.population = new;
        }
        "generations" => e.generations = value.whole()?,
        "actions" => e.actions = value.whole()?,
        "crossover" => e.crossover = value.real(),
        "mutation" => e.mutation = value.real(),
        "elitism" => e.elitism = value.whole()?,
        "evaluations" => e.evaluations = value.whole()?,
        "keep" => e.selection = Selection::Truncation { keep: value.whole()? },
        "selection" => {
            e.selection = match (value.word(), e.selection) {
                ("roulette", _) => Selection::Roulette,
                (_, Selection::Truncation { keep }) => Selection::Truncation { keep },
                (_, Selection::Roulette) => Selection::Truncation { keep: (e.population / 5).max(1) },
            }
        }
        "inheritance" => {
            s.inheritance =
                if value.word() == "lamarckian" { Inheritance::Lamarckian } else { Inheritance::Darwinian }
        }
        _ => return Err(format!("`{path}` is not a setting")),
    }
    Ok(())
}

/// Writes `value` into the robots of role `r` of stage `s` (and the team
/// it makes into every world of the stage).
fn put_role_robots(s: &mut Stage, r: usize, value: &Value) -> Result<(), String> {
    s.set_role_robots(r, value.whole()?);
    Ok(())
}

/// Writes `value` into the setting `FIELD` of module `module_name` of
/// stage `s` (`path` is `MODULE.FIELD`): the range of its activation
/// weights or a setting of its learning.
fn put_module(
    s: &mut Stage,
    module_name: &str,
    field: &str,
    path: &str,
    value: &Value,
) -> Result<(), String> {
    let mi = module(s, module_name)?.0;
    if field == "range" {
        let Value::Pair(lo, hi) = value else { return Err(format!("`{path}` takes LO..HI")) };
        for g in s.layout.genes.iter_mut().filter(|g| activation_gene(g, mi)) {
            (g.lo, g.hi) = (*lo as f32, *hi as f32);
        }
        return Ok(());
    }
    let l = s.modules[mi]
        .learning
        .as_mut()
        .ok_or_else(|| format!("module `{module_name}` of stage `{}` does not learn", s.name))?;
    match field {
        "reward" => l.rate_reward = value.real(),
        "punish" => l.rate_punish = value.real(),
        "window" => l.window = value.whole()?,
        "threshold" => l.when = LearnWhen::Below { threshold: value.real() },
        _ => return Err(format!("`{path}` is not a setting")),
    }
    Ok(())
}
