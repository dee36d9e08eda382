//! Readable renderings of a compiled stage: the genome layout as a text
//! table, and the architecture as a Graphviz graph.

use std::fmt::Write as _;

use serde::Serialize;

use shaping_runtime::catalog::ActuatorKind;
use shaping_runtime::program::{
    Behavior, GeneRole, Network, NeuralBehavior, Param, Part, Program, Stage, StageRun, World,
};

/// The name of percept channel `c` in a stage: `ir[3]`, `battery`.
fn channel_name(stage: &Stage, c: u16) -> String {
    match stage.sensors.iter().find(|s| s.channel <= c && c < s.channel + s.count) {
        Some(s) if s.count == 1 => s.name.clone(),
        Some(s) => format!("{}[{}]", s.name, c - s.channel),
        None => format!("channel {c}"),
    }
}

/// The name of module `i` of a stage as the layout shows it: `avoid`, or
/// `role.avoid` in a stage with roles (two roles may each have an `avoid`).
pub fn module_label(stage: &Stage, i: usize) -> String {
    let Some(m) = stage.modules.get(i) else { return format!("#{i}") };
    if stage.roles.is_empty() {
        return m.name.clone();
    }
    let r = (0..stage.roles.len()).find(|&r| stage.role_modules(r).contains(&i));
    match r.and_then(|r| stage.roles.get(r)) {
        Some(role) => format!("{}.{}", role.name, m.name),
        None => m.name.clone(),
    }
}

/// One gene of a stage's layout, with the names the layout table shows:
/// what [`layout_rows`] returns, and `shaping layout --format json` prints.
/// A gene is `bits` bits of the genome from `offset`, the most significant
/// bit first, read as a whole number `g` and decoded to `lo + (hi - lo) * g
/// / (2^bits - 1)`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LayoutRow {
    /// The gene's index in the layout.
    pub gene: u32,
    pub offset: u32,
    pub bits: u8,
    /// The stage that introduced the gene.
    pub stage: String,
    /// Its module: `avoid`, or `role.avoid` in a stage with roles.
    pub module: String,
    /// The role of the team that runs the module, in a stage with roles.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub team_role: Option<String>,
    /// What it encodes, as the table's `role` column: `bias`, `weight
    /// ir[3]`, `link avoid -> wander`, `behavior out1 weight ir[0]`.
    pub what: String,
    /// `activation`, `behavior` (a neural behavior's network) or `link`.
    pub part: &'static str,
    /// `bias`, `weight`, `context` (a recurrent unit's weight from the
    /// previous activations) or `link`.
    pub kind: &'static str,
    /// The sensor element a weight reads: `ir[3]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input: Option<String>,
    /// The hidden unit the gene belongs to (its bias, or a weight into it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hidden: Option<u16>,
    /// The hidden unit a weight comes from (`weight h0 -> out`, `context h1 -> h0`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub from_hidden: Option<u16>,
    /// The output of a neural behavior of several outputs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub output: Option<u16>,
    /// The link a link weight is: `avoid -> wander`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link: Option<String>,
    /// The gene's range, `lo..hi`.
    pub lo: f32,
    pub hi: f32,
    /// Frozen (an earlier stage's: crossover and mutation leave it) or evolvable.
    pub frozen: bool,
}

/// The rows of stage `stage`'s genome layout (index into `program.stages`;
/// none for a stage the program lacks), in the layout's order.
pub fn layout_rows(program: &Program, stage: usize) -> Vec<LayoutRow> {
    let Some(st) = program.stages.get(stage) else { return Vec::new() };
    (0..st.layout.genes.len() as u32).map(|i| describe(Some(program), st, i)).collect()
}

/// What gene `gene` of a stage's layout encodes, as the layout table shows it:
/// `bias`, `weight ir[3]`, `link avoid -> wander`, `behavior out1 weight ir[0]`.
pub fn role_text(stage: &Stage, gene: u32) -> String {
    describe(None, stage, gene).what
}

/// Gene `gene` of stage `stage` as a row of the layout (`program`, when
/// given, names the stage that introduced it).
fn describe(program: Option<&Program>, stage: &Stage, gene: u32) -> LayoutRow {
    let g = &stage.layout.genes[gene as usize];
    let module = stage.modules.get(g.module as usize);
    let mname =
        |i: u16| stage.modules.get(i as usize).map(|m| m.name.clone()).unwrap_or_else(|| format!("#{i}"));
    let neural = module.and_then(|m| match &m.behavior {
        Behavior::Neural(nb) if nb.net.params.contains(&Param::Gene(gene)) => Some(nb),
        _ => None,
    });
    let input = |i: u16| -> String {
        let chans = match (neural, module) {
            (Some(nb), _) => nb.inputs.get(i as usize).copied(),
            (None, Some(m)) => m.inputs.get(i as usize).copied(),
            _ => None,
        };
        chans.map(|c| channel_name(stage, c)).unwrap_or_else(|| format!("input {i}"))
    };
    let team_role = (0..stage.roles.len())
        .find(|&r| stage.role_modules(r).contains(&(g.module as usize)))
        .and_then(|r| stage.roles.get(r))
        .map(|r| r.name.clone());
    let mut row = LayoutRow {
        gene,
        offset: g.offset,
        bits: g.bits,
        stage: program
            .and_then(|p| p.stages.get(g.stage as usize))
            .map(|s| s.name.clone())
            .unwrap_or_default(),
        module: module.map(|_| module_label(stage, g.module as usize)).unwrap_or_default(),
        team_role,
        what: String::new(),
        part: if neural.is_some() { "behavior" } else { "activation" },
        kind: "weight",
        input: None,
        hidden: None,
        from_hidden: None,
        output: None,
        link: None,
        lo: g.lo,
        hi: g.hi,
        frozen: g.frozen,
    };
    let text = match g.role {
        GeneRole::Bias => {
            row.kind = "bias";
            "bias".to_string()
        }
        GeneRole::Weight { input: i, hidden } => {
            row.input = Some(input(i));
            row.hidden = hidden;
            match hidden {
                None => format!("weight {}", input(i)),
                Some(h) => format!("weight {} -> h{h}", input(i)),
            }
        }
        GeneRole::HiddenBias { hidden } => {
            (row.kind, row.hidden) = ("bias", Some(hidden));
            format!("bias h{hidden}")
        }
        GeneRole::HiddenOut { hidden } => {
            row.from_hidden = Some(hidden);
            format!("weight h{hidden} -> out")
        }
        GeneRole::Context { from, hidden } => {
            (row.kind, row.from_hidden, row.hidden) = ("context", Some(from), Some(hidden));
            format!("context h{from} -> h{hidden}")
        }
        GeneRole::Link { from } => {
            let link = format!("{} -> {}", mname(from), mname(g.module));
            (row.part, row.kind) = ("link", "link");
            row.link = Some(link.clone());
            format!("link {link}")
        }
    };
    row.what = match neural {
        Some(nb) if nb.net.outputs > 1 => {
            let pos = nb.net.params.iter().position(|p| *p == Param::Gene(gene)).unwrap_or(0);
            let per_out =
                if nb.net.hidden == 0 { nb.net.inputs as usize + 1 } else { nb.net.hidden as usize + 1 };
            // The hidden units' parameters (with their context weights).
            let (i, h) = (nb.net.inputs as usize, nb.net.hidden as usize);
            let before = if h == 0 { 0 } else { Network::param_count_of(i, h, 0, nb.net.recurrent) };
            if pos >= before {
                let out = (pos - before) / per_out;
                row.output = Some(out as u16);
                match signal_of(stage, nb, out) {
                    Some(signal) => format!("behavior out{out} ({signal}) {text}"),
                    None => format!("behavior out{out} {text}"),
                }
            } else {
                format!("behavior {text}")
            }
        }
        Some(_) => format!("behavior {text}"),
        None => text,
    };
    row
}

/// The broadcast value output `out` of a neural behavior sets, as
/// `signal[0]` (the actuator's name), if it is a signal output.
fn signal_of(stage: &Stage, nb: &NeuralBehavior, out: usize) -> Option<String> {
    let k = out.checked_sub(nb.wheel_outputs().into())?;
    let a = stage.actuators.iter().find(|a| a.kind == ActuatorKind::Broadcast)?;
    Some(format!("{}[{k}]", a.name))
}

/// The genome layout of stage `stage` (index into `program.stages`) as a
/// text table: offset, bits, introducing stage, module, role, range, and
/// whether the gene is frozen; then totals.
pub fn render_layout(program: &Program, stage: usize) -> String {
    let mut out = String::new();
    let Some(st) = program.stages.get(stage) else {
        let _ = writeln!(out, "no stage {stage}: `{}` has {} stages", program.name, program.stages.len());
        return out;
    };
    let _ = writeln!(
        out,
        "genome layout of stage `{}` ({} of {}) in `{}`",
        st.name,
        stage + 1,
        program.stages.len(),
        program.name
    );
    write_table(&mut out, program, stage);
    let frozen: Vec<_> = st.layout.genes.iter().filter(|g| g.frozen).collect();
    let fbits: u32 = frozen.iter().map(|g| g.bits as u32).sum();
    let n = st.layout.genes.len();
    let _ = writeln!(
        out,
        "genes: {n}, bits: {}, frozen: {} genes ({fbits} bits), evolvable: {} genes ({} bits)",
        st.layout.bits,
        frozen.len(),
        n - frozen.len(),
        st.layout.bits - fbits
    );
    write_roles(&mut out, program, st);
    write_trained(&mut out, program, st);
    if let StageRun::Train { actions } = st.run {
        let _ = writeln!(out, "training stage: its modules learn for {actions} actions; nothing is evolved");
    }
    write_variants(&mut out, st);
    out
}

/// The table of the genes of stage `stage`: a line per gene, its cells
/// aligned in columns.
fn write_table(out: &mut String, program: &Program, stage: usize) {
    let rows: Vec<[String; 7]> = layout_rows(program, stage)
        .into_iter()
        .map(|r| {
            [
                r.offset.to_string(),
                r.bits.to_string(),
                r.stage,
                r.module,
                r.what,
                format!("{:.2}..{:.2}", r.lo, r.hi),
                if r.frozen { "frozen" } else { "evolvable" }.to_string(),
            ]
        })
        .collect();
    let header = ["offset", "bits", "stage", "module", "role", "range", "state"];
    let mut widths: Vec<usize> = header.iter().map(|h| h.len()).collect();
    for r in &rows {
        for (w, c) in widths.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |out: &mut String, cells: &[&str]| {
        let mut s = String::new();
        for (i, (c, w)) in cells.iter().zip(&widths).enumerate() {
            if i < 2 {
                let _ = write!(s, "{c:>w$}  ");
            } else {
                let _ = write!(s, "{c:<w$}  ");
            }
        }
        let _ = writeln!(out, "{}", s.trim_end());
    };
    line(out, &header);
    for r in &rows {
        let cells: Vec<&str> = r.iter().map(String::as_str).collect();
        line(out, &cells);
    }
}

/// The roles of a heterogeneous team: who plays them, which modules and
/// genes are theirs.
fn write_roles(out: &mut String, program: &Program, st: &Stage) {
    let mut robot = 0u64;
    for (r, role) in st.roles.iter().enumerate() {
        let mods = st.role_modules(r);
        let genes = st.layout.genes.iter().filter(|g| mods.contains(&(g.module as usize))).count();
        let last = robot + u64::from(role.robots) - 1;
        let robots =
            if role.robots == 1 { format!("robot {robot}") } else { format!("robots {robot}..{last}") };
        let names: Vec<&str> = st.modules[mods.clone()].iter().map(|m| m.name.as_str()).collect();
        // Which genes each earlier stage froze, and how many evolve here.
        let mut frozen: Vec<(u16, usize)> = Vec::new();
        for g in st.layout.genes.iter().filter(|g| g.frozen && mods.contains(&(g.module as usize))) {
            match frozen.iter_mut().find(|(s, _)| *s == g.stage) {
                Some((_, k)) => *k += 1,
                None => frozen.push((g.stage, 1)),
            }
        }
        let by: Vec<String> = frozen
            .iter()
            .map(|&(s, k)| {
                let name = program.stages.get(s as usize).map_or("?", |x| x.name.as_str());
                format!("{k} of stage `{name}`")
            })
            .collect();
        let evolvable = genes - frozen.iter().map(|(_, k)| k).sum::<usize>();
        let state = match (by.is_empty(), evolvable) {
            (true, _) => String::new(),
            (false, 0) => format!(" (frozen: {})", by.join(", ")),
            (false, e) => format!(" (frozen: {}; evolvable: {e})", by.join(", ")),
        };
        let own = if role.fitness.is_some() { ", its own fitness" } else { "" };
        let _ = writeln!(
            out,
            "role `{}`: {robots}, modules {}, {genes} genes{state}{own}",
            role.name,
            names.join(", ")
        );
        robot = last + 1;
    }
}

/// The parameters that are not genes: what training stages learned.
fn write_trained(out: &mut String, program: &Program, st: &Stage) {
    for (i, m) in st.modules.iter().enumerate() {
        for (part, name) in [(Part::Activation, "activation network"), (Part::Behavior, "behavior")] {
            let mut params = m.network_params().filter(|(p, _)| *p == part).map(|(_, q)| q);
            let Some(Param::Trained { stage: t, .. }) = params.next() else { continue };
            let by = program.stages.get(*t as usize).map(|s| s.name.as_str()).unwrap_or("?");
            let actions = match program.stages.get(*t as usize).map(|s| &s.run) {
                Some(StageRun::Train { actions }) => format!(" for {actions} actions"),
                _ => String::new(),
            };
            let _ = writeln!(
                out,
                "trained: `{}` {name}, {} weights, learned by stage `{by}`{actions} (not genes)",
                module_label(st, i),
                params.count() + 1
            );
        }
    }
}

/// A stage's variants: how they are drawn, how their fitness is combined,
/// and what each one changes in the stage's world.
fn write_variants(out: &mut String, st: &Stage) {
    if let Some(v) = &st.variants {
        let n = v.list.len();
        let how = match (v.draw, &st.run) {
            (_, StageRun::Test { .. }) => format!("life k in variant k mod {n}"),
            (Some(d), _) if (d as usize) < n => format!("{d} of them drawn per generation"),
            _ => "each individual in every one".to_string(),
        };
        let fitness = match &st.run {
            StageRun::Test { .. } => "the mean per life".to_string(),
            _ => format!("the {} of the variants'", v.aggregate.word()),
        };
        let _ = writeln!(out, "variants: {n} ({how}); fitness: {fitness}");
        for x in &v.list {
            let changes = variant_changes(&st.world, &x.world);
            let what = if changes.is_empty() { "the stage's world".to_string() } else { changes.join("; ") };
            let _ = writeln!(out, "  {}: {what}", x.name);
        }
    }
}

/// The items of `variant` that differ from `base`'s, in words.
fn variant_changes(base: &World, variant: &World) -> Vec<String> {
    fn name(n: &Option<String>) -> String {
        n.as_ref().map_or(String::new(), |n| format!(" `{n}`"))
    }
    let p = |a: [f32; 2]| format!("({}, {})", a[0], a[1]);
    let mut out = Vec::new();
    let (b, v) = (&base.items, &variant.items);
    for (i, w) in v.walls.iter().enumerate() {
        if b.walls.get(i) != Some(w) {
            out.push(format!("wall{} from {} to {}", name(&w.name), p(w.from), p(w.to)));
        }
    }
    for (i, c) in v.cylinders.iter().enumerate() {
        if b.cylinders.get(i) != Some(c) {
            out.push(format!("cylinder{} at {} diameter {}", name(&c.name), p(c.at), c.diameter));
        }
    }
    for (i, l) in v.lamps.iter().enumerate() {
        if b.lamps.get(i) != Some(l) {
            let switch = l
                .switch
                .map_or(String::new(), |s| format!(" {} at {}", if s.on { "on" } else { "off" }, s.at));
            out.push(format!(
                "lamp{} at {} height {} intensity {}{switch}",
                name(&l.name),
                p(l.at),
                l.height,
                l.intensity
            ));
        }
    }
    for (i, z) in v.zones.iter().enumerate() {
        if b.zones.get(i) != Some(z) {
            let charger = if z.charger { " charger" } else { "" };
            out.push(format!(
                "zone{} from {} to {} grey {}{charger}",
                name(&z.name),
                p(z.from),
                p(z.to),
                z.grey
            ));
        }
    }
    if v.start != b.start {
        if let Some(s) = &v.start {
            out.push(format!("start from {} to {}", p(s.from), p(s.to)));
        }
    }
    if (&base.charger, &base.battery, &base.objects) != (&variant.charger, &variant.battery, &variant.objects)
    {
        out.push("the charger, battery or objects".into());
    }
    out
}

fn dot_escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
}

/// The architecture of stage `stage` as a Graphviz DOT graph: sensors
/// (boxes), modules (ellipses; grey when an earlier stage froze them), the
/// inputs of every module, and the links between modules.
pub fn render_graph(program: &Program, stage: usize) -> String {
    let mut out = String::new();
    let Some(st) = program.stages.get(stage) else {
        let _ = writeln!(out, "digraph empty {{}}");
        return out;
    };
    let _ = writeln!(out, "digraph \"{}\" {{", dot_escape(&format!("{}/{}", program.name, st.name)));
    let _ = writeln!(out, "  rankdir=LR;");
    let _ = writeln!(out, "  node [fontname=\"Helvetica\"];");
    let _ = writeln!(out, "  edge [fontname=\"Helvetica\", fontsize=10];");
    for s in &st.sensors {
        let label = if s.count == 1 { s.name.clone() } else { format!("{}[{}]", s.name, s.count) };
        let _ =
            writeln!(out, "  \"s:{}\" [shape=box, label=\"{}\"];", dot_escape(&s.name), dot_escape(&label));
    }
    for (i, m) in st.modules.iter().enumerate() {
        let kind = match m.behavior {
            Behavior::Script(_) => "script",
            Behavior::Neural(_) => "neural",
        };
        let style = if (m.stage as usize) < stage { ", style=filled, fillcolor=\"#dddddd\"" } else { "" };
        let _ = writeln!(
            out,
            "  \"m:{i}\" [shape=ellipse, label=\"{}\\n({kind})\"{style}];",
            dot_escape(&module_label(st, i))
        );
        let mut seen: Vec<&str> = Vec::new();
        for &c in &m.inputs {
            if let Some(s) = st.sensors.iter().find(|s| s.channel <= c && c < s.channel + s.count) {
                if !seen.contains(&s.name.as_str()) {
                    seen.push(&s.name);
                    let n = m.inputs.iter().filter(|&&x| s.channel <= x && x < s.channel + s.count).count();
                    let label = if s.count == 1 || n == s.count as usize {
                        String::new()
                    } else {
                        format!(" [label=\"{n} of {}\"]", s.count)
                    };
                    let _ = writeln!(out, "  \"s:{}\" -> \"m:{i}\"{label};", dot_escape(&s.name));
                }
            }
        }
    }
    // A heterogeneous team: each role's modules in a box of their own.
    for (r, role) in st.roles.iter().enumerate() {
        let _ = writeln!(out, "  subgraph \"cluster_{r}\" {{");
        let _ = writeln!(out, "    label=\"role {} ({} robots)\";", dot_escape(&role.name), role.robots);
        for i in st.role_modules(r) {
            let _ = writeln!(out, "    \"m:{i}\";");
        }
        let _ = writeln!(out, "  }}");
    }
    for l in &st.links {
        let label = match l.weight {
            Param::Gene(g) => format!("gene {g}"),
            Param::Fixed(w) => format!("{w:.2}"),
            Param::Random { lo, hi } => format!("random {lo:.2}..{hi:.2}"),
            Param::Trained { .. } => "trained".into(),
        };
        let frozen =
            matches!(l.weight, Param::Gene(g) if st.layout.genes.get(g as usize).is_some_and(|x| x.frozen));
        let style = if frozen { ", color=\"#999999\"" } else { "" };
        let _ =
            writeln!(out, "  \"m:{}\" -> \"m:{}\" [style=dashed, label=\"{label}\"{style}];", l.from, l.to);
    }
    let _ = writeln!(out, "}}");
    out
}
