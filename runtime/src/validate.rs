//! The one validation of a [`Program`]: it accepts what the compiler can
//! produce and refuses everything else with a message naming the stage and
//! the field. Every entry point that runs a program (the CLI's `run`,
//! `replay`, `bench`, `experiment`) validates it once; the controller and the
//! GA then trust it and index with it without checking again.
//!
//! Organised like the `Program` types: one function per part of a stage
//! ([`world`], [`modules`], [`links`], [`layout`], [`fitness`], [`run`], ...),
//! each checking its fields in declaration order. A new field of the program
//! gets its check in the function of the part that holds it. Resource limits
//! are the constants of [`crate::limits`], which the compiler checks too.

use std::fmt;

use crate::catalog::{self, ACT_SLOTS, CHANNELS};
use crate::expr::{Expr, Op};
use crate::limits::*;
use crate::program::*;
use crate::world::{blocker, crowded, Blocker, Crowded};

/// Why a program was refused: the stage (when the problem is in one), the
/// field (a path like `modules[1] (avoid).activation.params[3]`) and what is
/// wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    pub stage: Option<String>,
    pub field: String,
    pub message: String,
}

impl fmt::Display for Invalid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.stage {
            Some(s) => write!(f, "stage `{s}`, `{}`: {}", self.field, self.message),
            None => write!(f, "`{}`: {}", self.field, self.message),
        }
    }
}

impl std::error::Error for Invalid {}

type R = Result<(), Invalid>;

/// The reserved words of the language (the `keyword` rule of
/// `grammar/shaping.pest`; a compiler test keeps the two equal): no name is
/// one of them.
pub const RESERVED: [&str; 30] = [
    "robot",
    "sensor",
    "actuator",
    "genome",
    "stage",
    "extends",
    "module",
    "sense",
    "activation",
    "behavior",
    "learn",
    "reinforce",
    "links",
    "link",
    "world",
    "evolve",
    "test",
    "fitness",
    "and",
    "or",
    "not",
    "prev",
    "until",
    "within",
    "for",
    "uses",
    "per",
    "adds",
    "changes",
    "if",
];

/// A name as the language writes one (`ident` in the grammar): ASCII
/// letters, digits and `_`, starting with a letter or `_`, and not a
/// reserved word. Stage names become directories and module and hardware
/// names columns of `trace.csv`, so a program may hold no other name.
pub fn is_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !RESERVED.contains(&s)
}

/// Where a check is: the stage and the field path so far.
#[derive(Clone)]
struct At<'a> {
    stage: Option<&'a str>,
    path: String,
}

impl At<'_> {
    fn field(&self, name: impl fmt::Display) -> Self {
        let path = if self.path.is_empty() { name.to_string() } else { format!("{}.{name}", self.path) };
        At { stage: self.stage, path }
    }

    fn index(&self, i: usize) -> Self {
        At { stage: self.stage, path: format!("{}[{i}]", self.path) }
    }

    fn err(&self, message: impl Into<String>) -> R {
        Err(Invalid {
            stage: self.stage.map(str::to_string),
            field: self.path.clone(),
            message: message.into(),
        })
    }

    /// `cond` must hold, else `message`.
    fn ensure(&self, cond: bool, message: impl FnOnce() -> String) -> R {
        if cond {
            Ok(())
        } else {
            self.err(message())
        }
    }

    fn finite(&self, v: f32) -> R {
        self.ensure(v.is_finite(), || format!("{v} is not a finite number"))
    }

    /// A value range `lo..hi`: finite bounds, `lo <= hi`, and a finite
    /// width (genes decode to `lo + (hi - lo) * u`, random weights are drawn
    /// from it: a width beyond `f32::MAX` gives infinities and NaN).
    fn value_range(&self, lo: f32, hi: f32) -> R {
        self.field("lo").finite(lo)?;
        self.field("hi").finite(hi)?;
        self.ensure(lo <= hi, || format!("the range {lo}..{hi} is empty"))?;
        self.ensure((hi - lo).is_finite(), || {
            format!("the range {lo}..{hi} is too wide: its width is not a finite 32-bit number")
        })
    }

    /// A name of the language ([`is_name`]); the message quotes it escaped.
    fn name(&self, s: &str) -> R {
        self.ensure(is_name(s), || {
            let why = if RESERVED.contains(&s) {
                "it is a reserved word"
            } else {
                "a name is made of ASCII letters, digits and `_`, and starts with a letter or `_`"
            };
            format!("{s:?} is not a name: {why}")
        })
    }

    fn within(&self, v: f32, lo: f32, hi: f32) -> R {
        self.ensure(v >= lo && v <= hi, || format!("{v} is not between {lo} and {hi}"))
    }

    fn count(&self, v: u32, lo: u32, hi: u32) -> R {
        self.ensure(v >= lo && v <= hi, || format!("{v} is not between {lo} and {hi}"))
    }

    /// A length in mm: positive and at most [`MAX_LENGTH_MM`].
    fn length(&self, v: f32) -> R {
        self.ensure(v > 0.0 && v <= MAX_LENGTH_MM, || {
            format!("{v} mm is not a length between 0 (excluded) and {MAX_LENGTH_MM} mm")
        })
    }

    fn channel(&self, c: u16) -> R {
        self.ensure((c as usize) < CHANNELS, || {
            format!("channel {c} does not exist (the percept has {CHANNELS})")
        })
    }

    fn channels(&self, cs: &[u16]) -> R {
        cs.iter().enumerate().try_for_each(|(i, &c)| self.index(i).channel(c))
    }

    /// A network's inputs: channels that exist, each once (as a `sense`
    /// clause lists them).
    fn inputs(&self, cs: &[u16]) -> R {
        self.channels(cs)?;
        for (i, c) in cs.iter().enumerate() {
            if let Some(j) = cs[..i].iter().position(|d| d == c) {
                return self.index(i).err(format!("channel {c} is also input {j}"));
            }
        }
        Ok(())
    }
}

/// Validates a whole program: its format, its stages and how they extend
/// each other.
pub fn program(p: &Program) -> R {
    let at = At { stage: None, path: String::new() };
    at.field("format")
        .ensure(p.format == FORMAT_VERSION, || format!("format {} is not {FORMAT_VERSION}", p.format))?;
    let stages = at.field("stages");
    stages.ensure(!p.stages.is_empty(), || "the program has no stages".into())?;
    stages.ensure(p.stages.len() <= MAX_STAGES, || {
        format!("{} stages, more than the limit of {MAX_STAGES}", p.stages.len())
    })?;
    for (i, s) in p.stages.iter().enumerate() {
        // Before anything names the stage: its name is a directory of a run.
        stages.index(i).field("name").name(&s.name)?;
        if let Some(j) = p.stages[..i].iter().position(|t| t.name == s.name) {
            return stages.index(i).field("name").err(format!("`{}` is also the name of stage {j}", s.name));
        }
        stage(s)?;
        extension(p, i)?;
        trained(p, i)?;
    }
    Ok(())
}

/// Weights that a training stage learns (`Param::Trained`) refer to an
/// earlier training stage, one of its modules with a network of that part
/// (a neural behavior, or any activation network), and one of its weights.
fn trained(p: &Program, i: usize) -> R {
    let s = &p.stages[i];
    let at = At { stage: Some(&s.name), path: String::new() };
    for (mi, m) in s.modules.iter().enumerate() {
        let (mut a, mut b) = (0, 0);
        for (part, q) in m.network_params() {
            let (field, k) = match part {
                Part::Activation => ("activation.params", &mut a),
                Part::Behavior => ("behavior.net.params", &mut b),
            };
            let at = at.field("modules").index(mi).field(field).index(*k);
            *k += 1;
            let Param::Trained { stage: t, module, index, part } = *q else { continue };
            let source = p.stages.get(t as usize).filter(|_| (t as usize) < i);
            let Some(source) = source.filter(|x| matches!(x.run, StageRun::Train { .. })) else {
                return at.err(format!("stage {t} is not a training stage before this one"));
            };
            let trained = source.modules.get(module as usize);
            let weights = match (part, trained.map(|x| (&x.activation, &x.behavior))) {
                (Part::Activation, Some((net, _))) => net.params.len(),
                (Part::Behavior, Some((_, Behavior::Neural(nb)))) => nb.net.params.len(),
                (Part::Behavior, _) => {
                    return at.err(format!("module {module} of `{}` has no neural behavior", source.name))
                }
                (Part::Activation, None) => {
                    return at.err(format!("`{}` has no module {module}", source.name))
                }
            };
            at.ensure((index as usize) < weights, || {
                format!("weight {index} of a network of {weights} weights")
            })?;
        }
    }
    Ok(())
}

/// No weight still waits for a training stage: what a controller needs (the
/// CLI binds trained weights before anything runs).
pub fn bound(s: &Stage) -> R {
    let at = At { stage: Some(&s.name), path: String::new() };
    for (mi, m) in s.modules.iter().enumerate() {
        if let Some((part, _)) = m.network_params().find(|(_, q)| matches!(q, Param::Trained { .. })) {
            let field = match part {
                Part::Activation => "activation.params",
                Part::Behavior => "behavior.net.params",
            };
            return at
                .field("modules")
                .index(mi)
                .field(field)
                .err("its weights come from a training stage that has not run");
        }
    }
    Ok(())
}

/// Validates one stage on its own: everything the controller and the
/// simulator index with, the numbers they compute with and the limits.
pub fn stage(s: &Stage) -> R {
    let at = At { stage: Some(&s.name), path: String::new() };
    hardware(&at, s)?;
    world(&at.field("world"), &s.world)?;
    layout(&at.field("layout"), s)?;
    modules(&at, s)?;
    links(&at, s)?;
    roles(&at, s)?;
    fitness(&at.field("fitness"), &s.fitness)?;
    run(&at.field("run"), s)?;
    variants(&at, s)?;
    Ok(())
}

/// The variants: 1 to [`crate::limits::MAX_VARIANTS`] of them, named once
/// each, a draw of 1 to their number, each world valid and with the arena
/// and body of the stage's; every target of the stage (at most
/// [`catalog::MAX_TARGETS`]) found in every world.
fn variants(at: &At, s: &Stage) -> R {
    at.field("targets").ensure(s.targets.len() <= catalog::MAX_TARGETS, || {
        format!("{} targets, more than {}", s.targets.len(), catalog::MAX_TARGETS)
    })?;
    let found = |at: &At, w: &World| -> R {
        for (i, t) in s.targets.iter().enumerate() {
            at.field("targets").index(i).ensure(crate::world::Place::of(w, t).is_some(), || {
                format!("its world has no {:?} `{}`", t.kind, t.name).to_lowercase()
            })?;
        }
        Ok(())
    };
    found(at, &s.world)?;
    let Some(v) = &s.variants else { return Ok(()) };
    let at = at.field("variants");
    at.field("list").count(v.list.len() as u32, 1, crate::limits::MAX_VARIANTS as u32)?;
    if let Some(d) = v.draw {
        at.field("draw").count(d, 1, v.list.len() as u32)?;
    }
    for (i, x) in v.list.iter().enumerate() {
        let at = at.field("list").index(i);
        at.field("name").name(&x.name)?;
        at.field("name").ensure(!v.list[..i].iter().any(|y| y.name == x.name), || {
            format!("`{}` names two variants", x.name)
        })?;
        world(&at.field("world"), &x.world)?;
        at.field("world").ensure(x.world.arena == s.world.arena && x.world.body == s.world.body, || {
            "a variant has the stage's arena and body".into()
        })?;
        found(&at.field("world"), &x.world)?;
    }
    Ok(())
}

/// A stage extends its parent: the parent comes before it, its layout starts
/// with the parent's genes (same place, size and range), and exactly the
/// genes of earlier stages are frozen.
fn extension(p: &Program, i: usize) -> R {
    let s = &p.stages[i];
    let at = At { stage: Some(&s.name), path: String::new() };
    let genes = &s.layout.genes;
    let inherited = match s.parent {
        None => 0,
        Some(j) => {
            at.field("parent").ensure(j < i, || format!("stage {j} does not come before this stage"))?;
            let parent = &p.stages[j].layout;
            let n = parent.genes.len();
            at.field("layout.genes").ensure(genes.len() >= n && s.layout.bits >= parent.bits, || {
                format!("{} genes, fewer than the {n} of the stage it extends", genes.len())
            })?;
            let ps = &p.stages[j];
            let pr = &ps.roles;
            // A stage with roles extends no stage; one that extends it keeps
            // its roles, in order, each with at least its modules, and may
            // add roles after them.
            let kept_roles = s.roles.len() >= pr.len()
                && s.roles.iter().zip(pr).all(|(a, b)| a.name == b.name && a.modules >= b.modules)
                && (s.roles.is_empty() || !pr.is_empty());
            at.field("roles").ensure(kept_roles, || {
                "a stage with roles extends no stage, and a stage that extends it keeps its roles and their modules".into()
            })?;
            // A module keeps its name and role; with roles, a role's
            // added modules may move the later roles' (their index).
            let label = |st: &Stage, m: u16| {
                if st.roles.is_empty() {
                    format!("#{m}")
                } else {
                    st.module_label(m as usize)
                }
            };
            for (k, (c, q)) in genes.iter().zip(&parent.genes).enumerate() {
                at.field("layout.genes").index(k).ensure(
                    (c.offset, c.bits, c.lo, c.hi, c.stage, label(s, c.module))
                        == (q.offset, q.bits, q.lo, q.hi, q.stage, label(ps, q.module)),
                    || "differs from the gene of the stage it extends".into(),
                )?;
            }
            n
        }
    };
    for (k, g) in genes.iter().enumerate() {
        let frozen = k < inherited;
        at.field("layout.genes").index(k).field("frozen").ensure(g.frozen == frozen, || {
            if frozen {
                "a gene of an earlier stage must be frozen".into()
            } else {
                "a gene this stage introduces cannot be frozen".into()
            }
        })?;
    }
    Ok(())
}

/// Declared sensors and actuators: each sensor's channels are those of its
/// kind in the catalog.
fn hardware(at: &At, s: &Stage) -> R {
    for (i, d) in s.sensors.iter().enumerate() {
        let at = at.field("sensors").index(i);
        at.field("name").name(&d.name)?;
        if let Some(j) = s.sensors[..i].iter().position(|e| e.name == d.name) {
            return at.field("name").err(format!("`{}` is also the name of sensor {j}", d.name));
        }
        let info = catalog::sensor_info(d.kind);
        at.field("count").ensure(d.count >= 1 && (d.count as usize) <= info.max_count, || {
            format!("{} is not between 1 and {}", d.count, info.max_count)
        })?;
        at.field("channel").ensure(d.channel as usize == info.channel, || {
            format!("{} is not the first channel of its kind ({})", d.channel, info.channel)
        })?;
    }
    for (i, d) in s.actuators.iter().enumerate() {
        let at = at.field("actuators").index(i);
        at.field("name").name(&d.name)?;
        let taken = s.sensors.iter().map(|e| &e.name).chain(s.actuators[..i].iter().map(|e| &e.name));
        if taken.into_iter().any(|n| *n == d.name) {
            return at
                .field("name")
                .err(format!("`{}` is also the name of another sensor or actuator", d.name));
        }
    }
    Ok(())
}

/// The world: a positive arena the body fits in, a charger on a wall long
/// enough, a battery, objects within the limits.
fn world(at: &At, w: &World) -> R {
    let [width, depth] = w.arena;
    at.field("arena").index(0).length(width)?;
    at.field("arena").index(1).length(depth)?;
    body(&at.field("body"), &w.body)?;
    let diameter = 2.0 * w.body.radius;
    at.field("body.radius").ensure(diameter < width.min(depth), || {
        format!("a body {diameter} mm wide does not fit in an arena of {width} x {depth} mm")
    })?;
    if let Some(c) = &w.charger {
        let at = at.field("charger");
        at.field("length").length(c.length)?;
        let wall = match c.wall {
            Wall::North | Wall::South => width,
            Wall::East | Wall::West => depth,
        };
        at.field("length").ensure(c.length <= wall, || {
            format!("the charger ({} mm) is longer than its wall ({wall} mm)", c.length)
        })?;
        if let Some(h) = c.lamp_height {
            at.field("lamp_height").length(h)?;
        }
    }
    at.field("robots").count(w.robots, 1, MAX_ROBOTS)?;
    let room = crate::world::team_room(w);
    at.field("robots").ensure(w.robots <= room, || {
        format!("{} robots do not fit in the start region, which holds {room}", w.robots)
    })?;
    if let Some(b) = &w.battery {
        let at = at.field("battery");
        at.field("capacity").count(b.capacity, 1, u32::MAX)?;
        at.field("recharge").count(b.recharge, 1, u32::MAX)?;
    }
    if let Some(o) = &w.objects {
        let at = at.field("objects");
        at.field("count").count(o.count, 0, MAX_OBJECTS)?;
        at.field("diameter").length(o.diameter)?;
    }
    items(at, &w.items, [width, depth], w.body.radius)?;
    let item = |b: Blocker| match b {
        Blocker::Wall(i) => format!("inner wall {i}"),
        Blocker::Cylinder(i) => format!("cylinder {i}"),
    };
    for (i, p) in w.items.places.iter().enumerate() {
        let at = at.field("items").field("places").index(i);
        at.ensure(w.robots == 1, || {
            format!("a team of {} robots would all be placed at one spot, on top of each other", w.robots)
        })?;
        if let Some(b) = blocker(&w.items, p.at, w.body.radius) {
            at.err(format!("the placement puts the body inside {}", item(b)))?;
        }
    }
    match crowded(w) {
        None => Ok(()),
        Some(Crowded::Objects { need, room }) => at.field("objects").err(format!(
            "the objects do not fit in the arena: they need {need:.0} mm² of floor and find {room:.0} mm²"
        )),
        Some(Crowded::ObjectsCovered(b)) => {
            at.field("items").err(format!("{} covers every place an object can be put", item(b)))
        }
        Some(Crowded::StartCovered(b)) => {
            at.field("items").err(format!("{} covers every place the robot can start", item(b)))
        }
    }
}

/// The world's items: within the limits, finite, walls and cylinders inside
/// the arena, zones overlapping it, a start region where the body fits.
fn items(at: &At, it: &Items, arena: [f32; 2], radius: f32) -> R {
    let inside = |p: [f32; 2]| p[0] >= 0.0 && p[1] >= 0.0 && p[0] <= arena[0] && p[1] <= arena[1];
    let at = at.field("items");
    for (what, n) in [
        ("walls", it.walls.len()),
        ("cylinders", it.cylinders.len()),
        ("lamps", it.lamps.len()),
        ("zones", it.zones.len()),
    ] {
        at.field(what)
            .ensure(n <= MAX_ITEMS, || format!("{n} {what}, more than the limit of {MAX_ITEMS}"))?;
    }
    let point = |at: &At, p: [f32; 2]| -> R {
        at.index(0).within(p[0], -MAX_LENGTH_MM, MAX_LENGTH_MM)?;
        at.index(1).within(p[1], -MAX_LENGTH_MM, MAX_LENGTH_MM)
    };
    let named = |what: &str, names: &mut dyn Iterator<Item = &Option<String>>| -> R {
        for (i, n) in names.enumerate() {
            if let Some(n) = n {
                at.field(what).index(i).field("name").name(n)?;
            }
        }
        Ok(())
    };
    named("walls", &mut it.walls.iter().map(|w| &w.name))?;
    named("cylinders", &mut it.cylinders.iter().map(|c| &c.name))?;
    named("lamps", &mut it.lamps.iter().map(|l| &l.name))?;
    named("zones", &mut it.zones.iter().map(|z| &z.name))?;
    named("places", &mut it.places.iter().map(|p| &p.name))?;
    at.field("places").ensure(it.places.len() <= MAX_ITEMS, || {
        format!("{} places, more than the limit of {MAX_ITEMS}", it.places.len())
    })?;
    let fits = |p: [f32; 2]| {
        p[0] >= radius && p[1] >= radius && p[0] <= arena[0] - radius && p[1] <= arena[1] - radius
    };
    for (i, p) in it.places.iter().enumerate() {
        let at = at.field("places").index(i);
        point(&at.field("at"), p.at)?;
        at.field("heading").within(p.heading, -1e4, 1e4)?;
        at.field("after").count(p.after, 1, crate::limits::MAX_ACTIONS)?;
        at.ensure(fits(p.at), || "the placement leaves the body outside the arena".into())?;
    }
    for (i, w) in it.walls.iter().enumerate() {
        let at = at.field("walls").index(i);
        point(&at.field("from"), w.from)?;
        point(&at.field("to"), w.to)?;
        at.ensure(inside(w.from) && inside(w.to), || "the wall is not inside the arena".into())?;
    }
    for (i, c) in it.cylinders.iter().enumerate() {
        let at = at.field("cylinders").index(i);
        point(&at.field("at"), c.at)?;
        at.field("diameter").length(c.diameter)?;
        at.ensure(inside(c.at), || "the cylinder is not inside the arena".into())?;
    }
    for (i, l) in it.lamps.iter().enumerate() {
        let at = at.field("lamps").index(i);
        point(&at.field("at"), l.at)?;
        at.field("height").length(l.height)?;
        at.field("intensity").within(l.intensity, 0.0, 1e6)?;
        if let Some(sw) = &l.switch {
            at.field("switch").field("at").count(sw.at, 1, crate::limits::MAX_ACTIONS)?;
        }
    }
    for (i, z) in it.zones.iter().enumerate() {
        let at = at.field("zones").index(i);
        point(&at.field("from"), z.from)?;
        point(&at.field("to"), z.to)?;
        at.field("grey").within(z.grey, 0.0, 1.0)?;
        let (lo, hi) = (
            [z.from[0].min(z.to[0]), z.from[1].min(z.to[1])],
            [z.from[0].max(z.to[0]), z.from[1].max(z.to[1])],
        );
        let overlaps = lo[0] < arena[0]
            && lo[1] < arena[1]
            && hi[0] > 0.0
            && hi[1] > 0.0
            && lo[0] < hi[0]
            && lo[1] < hi[1];
        at.ensure(overlaps, || "the zone does not overlap the arena".into())?;
    }
    if let Some(s) = &it.start {
        let at = at.field("start");
        point(&at.field("from"), s.from)?;
        point(&at.field("to"), s.to)?;
        if let Some(h) = s.heading {
            at.field("heading").within(h, -1e4, 1e4)?;
        }
        let fits = |p: [f32; 2]| {
            p[0] >= radius && p[1] >= radius && p[0] <= arena[0] - radius && p[1] <= arena[1] - radius
        };
        at.ensure(fits(s.from) && fits(s.to), || "the start leaves the body outside the arena".into())?;
    }
    Ok(())
}

fn body(at: &At, b: &Body) -> R {
    at.field("radius").length(b.radius)?;
    at.field("wheel_base").length(b.wheel_base)?;
    at.field("v_max").within(b.v_max, 1e-3, 1e4)?;
    at.field("action_ms").within(b.action_ms, 1.0, 1e5)?;
    at.field("wheel_noise").within(b.wheel_noise, 0.0, 1.0)?;
    at.field("sensor_noise").within(b.sensor_noise, 0.0, 1.0)?;
    let inside = |at: &At, p: [f32; 2]| {
        at.ensure(p[0].is_finite() && p[1].is_finite() && p[0].hypot(p[1]) <= b.radius, || {
            format!("({}, {}) is not on or inside the body (radius {} mm)", p[0], p[1], b.radius)
        })
    };
    if let Some(ir) = &b.ir {
        for (k, spot) in ir.at.iter().enumerate() {
            let at = at.field("ir").field("at").index(k);
            match *spot {
                SensorSpot::Rim(deg) => at.within(deg, -180.0, 180.0)?,
                SensorSpot::Point(p) => inside(&at, p)?,
            }
        }
        for (k, &deg) in ir.facing.iter().enumerate() {
            at.field("ir").field("facing").index(k).within(deg, -180.0, 180.0)?;
        }
    }
    if let Some(r) = &b.rab {
        let at = at.field("rab");
        at.field("sectors").count(u32::from(r.sectors), 1, catalog::RAB_SECTORS as u32)?;
        at.field("signals").count(u32::from(r.signals), 0, catalog::SIGNALS as u32)?;
        at.field("range").within(r.range, 1.0, 1e6)?;
        at.field("range_noise").within(r.range_noise, 0.0, 1.0)?;
        at.field("bearing_noise").within(r.bearing_noise, 0.0, 180.0)?;
    }
    at.field("ground").ensure(b.ground.len() <= catalog::GROUND_SENSORS, || {
        format!("{} ground sensors, at most {}", b.ground.len(), catalog::GROUND_SENSORS)
    })?;
    for (k, &p) in b.ground.iter().enumerate() {
        inside(&at.field("ground").index(k), p)?;
    }
    Ok(())
}

/// The genome layout: contiguous genes of 1 to 16 bits with finite ranges,
/// belonging to existing modules and stages, within the limits.
fn layout(at: &At, s: &Stage) -> R {
    let l = &s.layout;
    at.field("bits").count(l.bits, 0, MAX_GENOME_BITS)?;
    let mut offset = 0u64;
    for (i, g) in l.genes.iter().enumerate() {
        let at = at.field("genes").index(i);
        at.field("offset").ensure(u64::from(g.offset) == offset, || {
            format!("{} does not follow the previous gene (expected {offset})", g.offset)
        })?;
        at.field("bits")
            .ensure((1..=16).contains(&g.bits), || format!("{} is not between 1 and 16", g.bits))?;
        at.value_range(g.lo, g.hi)?;
        at.field("module").ensure((g.module as usize) < s.modules.len(), || {
            format!("module {} does not exist", g.module)
        })?;
        offset += u64::from(g.bits);
    }
    at.field("bits")
        .ensure(offset == u64::from(l.bits), || format!("{} bits, but the genes take {offset}", l.bits))
}

/// Every module: input channels, activation network (one output), behavior,
/// learning, reinforcement.
fn modules(at: &At, s: &Stage) -> R {
    at.field("modules").ensure(!s.modules.is_empty() && s.modules.len() <= MAX_MODULES, || {
        format!("{} modules, not between 1 and {MAX_MODULES}", s.modules.len())
    })?;
    for (i, m) in s.modules.iter().enumerate() {
        let at = at.field("modules").index(i);
        at.field("name").name(&m.name)?;
        // Names are the role's own: two roles may each have an `avoid`.
        let mine = s.role_modules(s.role_of_module(i));
        if let Some(j) = (mine.start..i).find(|&j| s.modules[j].name == m.name) {
            return at.field("name").err(format!("`{}` is also the name of module {j}", m.name));
        }
        at.field("inputs").inputs(&m.inputs)?;
        let act = at.field("activation");
        network(&act, s, &m.activation, m.inputs.len())?;
        act.field("outputs")
            .ensure(m.activation.outputs == 1, || "an activation network has one output".into())?;
        match &m.behavior {
            Behavior::Neural(nb) => {
                let at = at.field("behavior");
                at.field("inputs").inputs(&nb.inputs)?;
                network(&at.field("net"), s, &nb.net, nb.inputs.len())?;
                if nb.signals > 0 {
                    let values = s.world.body.rab.as_ref().map_or(0, |r| u16::from(r.signals));
                    at.field("signals").ensure(values == nb.signals, || {
                        format!("{} signal outputs, but the robot broadcasts {values} values", nb.signals)
                    })?;
                    at.field("signals").ensure(nb.signals < nb.net.outputs, || {
                        format!(
                            "{} signal outputs of {} outputs leave none for the wheels",
                            nb.signals, nb.net.outputs
                        )
                    })?;
                }
                let outputs = nb.wheel_outputs();
                match &nb.decode {
                    Decode::Table(t) => {
                        let at = at.field("decode");
                        at.ensure((1..=4).contains(&outputs) && t.len() == 1 << outputs, || {
                            format!("{} rows for {outputs} outputs (1 to 4 outputs, 2^outputs rows)", t.len())
                        })?;
                        for (k, row) in t.iter().enumerate() {
                            at.index(k).index(0).within(row[0], -1.0, 1.0)?;
                            at.index(k).index(1).within(row[1], -1.0, 1.0)?;
                        }
                    }
                    Decode::Linear { scale } => {
                        at.field("net.outputs")
                            .ensure(outputs == 2, || "linear decoding has two outputs".into())?;
                        let at = at.field("decode.scale");
                        at.ensure(*scale > 0.0 && *scale <= 1.0, || {
                            format!("{scale} is not in 0 (excluded) .. 1")
                        })?;
                    }
                }
            }
            Behavior::Script(sc) => script(&at.field("behavior"), sc)?,
        }
        if let Some(l) = &m.learning {
            let at = at.field("learning");
            at.field("rate_reward").within(l.rate_reward, 0.0, 1.0)?;
            at.field("rate_punish").within(l.rate_punish, 0.0, 1.0)?;
            if let LearnWhen::Below { threshold } = l.when {
                at.field("when.threshold").within(threshold, -1.0, 1.0)?;
            }
            at.field("window").count(l.window, 1, MAX_WINDOW)?;
            at.field("target").ensure(
                l.target == LearnTarget::Activation || matches!(m.behavior, Behavior::Neural(_)),
                || "only a neural behavior can learn".into(),
            )?;
        }
        if let Some(e) = &m.reinforce {
            expr(&at.field("reinforce"), e)?;
        }
    }
    Ok(())
}

/// A network's shape matches its inputs and parameter list; every parameter
/// is a gene of the layout, a finite constant or a finite random range.
fn network(at: &At, s: &Stage, n: &Network, inputs: usize) -> R {
    at.field("inputs").ensure(n.inputs as usize == inputs, || {
        format!("{} inputs, but {inputs} input channels", n.inputs)
    })?;
    at.field("hidden").ensure(n.hidden <= MAX_HIDDEN, || {
        format!("{} hidden units, more than the limit of {MAX_HIDDEN}", n.hidden)
    })?;
    at.field("outputs").ensure(n.outputs >= 1, || "a network has at least one output".into())?;
    let want = Network::param_count_of(inputs, n.hidden as usize, n.outputs as usize, n.recurrent);
    at.field("params").ensure(n.params.len() == want, || {
        format!("{} parameters, but its shape has {want}", n.params.len())
    })?;
    for (i, p) in n.params.iter().enumerate() {
        param(&at.field("params").index(i), s, p)?;
    }
    Ok(())
}

fn param(at: &At, s: &Stage, p: &Param) -> R {
    match *p {
        Param::Gene(g) => {
            at.ensure((g as usize) < s.layout.genes.len(), || format!("gene {g} does not exist"))
        }
        Param::Fixed(v) => at.finite(v),
        Param::Random { lo, hi } => at.value_range(lo, hi),
        // Checked against the program in `trained`.
        Param::Trained { .. } => Ok(()),
    }
}

/// A script's steps: speeds in -1..1, channels in range, well-formed
/// expressions, bounded steps.
fn script(at: &At, sc: &Script) -> R {
    at.field("steps").ensure(!sc.steps.is_empty(), || "a script has at least one step".into())?;
    for (i, st) in sc.steps.iter().enumerate() {
        let at = at.field("steps").index(i);
        let action = at.field("action");
        match &st.action {
            Action::Wheels { left, right } => {
                action.field("left").within(*left, -1.0, 1.0)?;
                action.field("right").within(*right, -1.0, 1.0)?;
            }
            Action::Toward { channels, speed } => {
                action.field("channels").channels(channels)?;
                action.field("speed").within(*speed, -1.0, 1.0)?;
            }
            Action::Reinforce(e) => expr(&action, e)?,
            Action::Arm(_) | Action::Claw(_) | Action::Wait { .. } => {}
            Action::Signal(v) => {
                action.ensure(!v.is_empty() && v.len() <= catalog::SIGNALS, || {
                    format!("{} broadcast values (1 to {})", v.len(), catalog::SIGNALS)
                })?;
                for (k, &x) in v.iter().enumerate() {
                    action.index(k).within(x, 0.0, 1.0)?;
                }
            }
        }
        match &st.end {
            StepEnd::Actions(n) => at.field("end").count(*n, 1, u32::MAX)?,
            StepEnd::Until { cond, within } => {
                expr(&at.field("end.cond"), cond)?;
                at.field("end.within").count(*within, 1, u32::MAX)?;
            }
        }
        if let Some(w) = &st.when {
            expr(&at.field("when"), w)?;
        }
    }
    Ok(())
}

/// An expression: well formed within the stack limit, channels and actuator
/// slots in range, finite constants.
fn expr(at: &At, e: &Expr) -> R {
    for (i, op) in e.ops.iter().enumerate() {
        let at = at.field("ops").index(i);
        match *op {
            Op::Chan(c) | Op::Prev(c) => at.channel(c)?,
            Op::Act(a) => {
                at.ensure((a as usize) < ACT_SLOTS, || format!("actuator slot {a} does not exist"))?
            }
            Op::State(v) => {
                at.ensure((v as usize) < catalog::STATE_SLOTS, || format!("state slot {v} does not exist"))?
            }
            Op::Const(v) => at.finite(v)?,
            _ => {}
        }
    }
    at.ensure(e.is_valid(), || {
        "malformed expression (stack underflow, leftover values or wrong depth)".into()
    })
}

fn links(at: &At, s: &Stage) -> R {
    let n = s.modules.len();
    for (i, l) in s.links.iter().enumerate() {
        let at = at.field("links").index(i);
        at.field("from").ensure((l.from as usize) < n, || format!("module {} does not exist", l.from))?;
        at.field("to").ensure((l.to as usize) < n, || format!("module {} does not exist", l.to))?;
        param(&at.field("weight"), s, &l.weight)?;
    }
    Ok(())
}

/// The roles of a heterogeneous team: named once each, each with robots and
/// modules, together every module and every robot (of every variant's
/// world); a link joins two modules of one role; in an evolved stage every
/// role has genes of its own.
fn roles(at: &At, s: &Stage) -> R {
    if s.roles.is_empty() {
        return Ok(());
    }
    let at_roles = at.field("roles");
    at_roles.count(s.roles.len() as u32, 1, MAX_MODULES as u32)?;
    for (r, role) in s.roles.iter().enumerate() {
        let at = at_roles.index(r);
        at.field("name").name(&role.name)?;
        at.field("name").ensure(!s.roles[..r].iter().any(|x| x.name == role.name), || {
            format!("`{}` names two roles", role.name)
        })?;
        at.field("robots").count(role.robots, 1, MAX_ROBOTS)?;
        if let Some(f) = &role.fitness {
            fitness(&at.field("fitness"), f)?;
        }
        at.field("modules").count(u32::from(role.modules), 1, MAX_MODULES as u32)?;
        let evolved = matches!(s.run, StageRun::Evolve(_));
        let mine = s.role_modules(r);
        at.ensure(!evolved || s.layout.genes.iter().any(|g| mine.contains(&(g.module as usize))), || {
            format!("role `{}` has no genes: evolution would not change it", role.name)
        })?;
    }
    let modules: usize = s.roles.iter().map(|x| x.modules as usize).sum();
    at_roles.ensure(modules == s.modules.len(), || {
        format!("the roles have {modules} modules, the stage {}", s.modules.len())
    })?;
    let robots: u64 = s.roles.iter().map(|x| u64::from(x.robots)).sum();
    let worlds = std::iter::once(("world", &s.world))
        .chain(s.variants.iter().flat_map(|v| v.list.iter().map(|x| ("variants", &x.world))));
    for (field, w) in worlds {
        at.field(field).ensure(u64::from(w.robots) == robots, || {
            format!("{} robots, but the roles have {robots}", w.robots)
        })?;
    }
    for (i, l) in s.links.iter().enumerate() {
        at.field("links")
            .index(i)
            .ensure(s.role_of_module(l.from as usize) == s.role_of_module(l.to as usize), || {
                format!("module {} and module {} are of different roles", l.from, l.to)
            })?;
    }
    Ok(())
}

fn fitness(at: &At, f: &Fitness) -> R {
    if let Some(e) = &f.per_action {
        expr(&at.field("per_action"), e)?;
    }
    if let Some(e) = &f.at_end {
        expr(&at.field("at_end"), e)?;
    }
    for (i, b) in f.bonuses.iter().enumerate() {
        at.field("bonuses").index(i).field("points").finite(b.points)?;
    }
    Ok(())
}

/// What the stage does: evolution settings within the limits, or a test.
fn run(at: &At, s: &Stage) -> R {
    match &s.run {
        StageRun::Test { actions, lives, .. } => {
            at.field("test.actions").count(*actions, 1, MAX_ACTIONS)?;
            at.field("test.lives").count(*lives, 1, MAX_ACTIONS)?;
            let total = u64::from(*lives) * u64::from(*actions);
            at.field("test.lives").ensure(total <= u64::from(MAX_ACTIONS), || {
                format!(
                    "{lives} lives of {actions} actions make {total} actions in each world, more than the limit of {MAX_ACTIONS}"
                )
            })?;
            at.ensure(s.parent.is_some(), || "a test stage must extend the stage it tests".into())
        }
        StageRun::Train { actions } => {
            at.field("train.actions").count(*actions, 1, MAX_ACTIONS)?;
            at.ensure(s.parent.is_none(), || "a training stage extends no stage".into())?;
            at.field("layout").ensure(s.layout.genes.is_empty(), || "a training stage has no genes".into())
        }
        StageRun::Evolve(e) => {
            let at = at.field("evolve");
            at.field("population").count(e.population, 1, MAX_POPULATION)?;
            at.field("generations").count(e.generations, 1, MAX_GENERATIONS)?;
            at.field("actions").count(e.actions, 1, MAX_ACTIONS)?;
            at.field("evaluations").count(e.evaluations, 1, MAX_EVALUATIONS)?;
            at.field("elitism").count(e.elitism, 0, e.population)?;
            if let Selection::Truncation { keep } = e.selection {
                at.field("selection.keep").count(keep, 1, e.population)?;
            }
            at.field("crossover").within(e.crossover, 0.0, 1.0)?;
            at.field("mutation").within(e.mutation, 0.0, 1.0)?;
            let total = u64::from(e.population) * u64::from(s.layout.bits);
            at.field("population").ensure(total <= MAX_POPULATION_BITS, || {
                format!(
                    "{} individuals of {} bits make {total} bits, more than the limit of {MAX_POPULATION_BITS}",
                    e.population, s.layout.bits
                )
            })
        }
    }
}

impl Program {
    /// The one validation of a program (this module): what the
    /// runtime needs before it may index and compute with it.
    pub fn validate(&self) -> Result<(), Invalid> {
        program(self)
    }
}
