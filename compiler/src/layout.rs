//! Readable renderings of a compiled stage: the genome layout as a text
//! table, and the architecture as a Graphviz graph.

use std::fmt::Write as _;

use shaping_runtime::program::{Behavior, GeneRole, Network, Param, Part, Program, Stage, StageRun, World};

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

/// What gene `gene` of a stage's layout encodes, as the layout table shows it:
/// `bias`, `weight ir[3]`, `link avoid -> wander`, `behavior out1 weight ir[0]`.
pub fn role_text(stage: &Stage, gene: u32) -> String {
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
    let text = match g.role {
        GeneRole::Bias => "bias".to_string(),
        GeneRole::Weight { input: i, hidden: None } => format!("weight {}", input(i)),
        GeneRole::Weight { input: i, hidden: Some(h) } => format!("weight {} -> h{h}", input(i)),
        GeneRole::HiddenBias { hidden } => format!("bias h{hidden}"),
        GeneRole::HiddenOut { hidden } => format!("weight h{hidden} -> out"),
        GeneRole::Context { from, hidden } => format!("context h{from} -> h{hidden}"),
        GeneRole::Link { from } => format!("link {} -> {}", mname(from), mname(g.module)),
    };
    match neural {
        Some(nb) if nb.net.outputs > 1 => {
            let pos = nb.net.params.iter().position(|p| *p == Param::Gene(gene)).unwrap_or(0);
            let per_out =
                if nb.net.hidden == 0 { nb.net.inputs as usize + 1 } else { nb.net.hidden as usize + 1 };
            // The hidden units' parameters (with their context weights).
            let (i, h) = (nb.net.inputs as usize, nb.net.hidden as usize);
            let before = if h == 0 { 0 } else { Network::param_count_of(i, h, 0, nb.net.recurrent) };
            if pos >= before {
                format!("behavior out{} {text}", (pos - before) / per_out)
            } else {
                format!("behavior {text}")
            }
        }
        Some(_) => format!("behavior {text}"),
        None => text,
    }
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
    let rows: Vec<[String; 7]> = st
        .layout
        .genes
        .iter()
        .enumerate()
        .map(|(i, g)| {
            [
                g.offset.to_string(),
                g.bits.to_string(),
                program.stages.get(g.stage as usize).map(|s| s.name.clone()).unwrap_or_default(),
                st.modules
                    .get(g.module as usize)
                    .map(|_| module_label(st, g.module as usize))
                    .unwrap_or_default(),
                role_text(st, i as u32),
                format!("{:.2}..{:.2}", g.lo, g.hi),
                if g.frozen { "frozen" } else { "evolvable" }.to_string(),
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
    line(&mut out, &header);
    for r in &rows {
        let cells: Vec<&str> = r.iter().map(String::as_str).collect();
        line(&mut out, &cells);
    }
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
    // The roles of a heterogeneous team: who plays them, which modules and
    // genes are theirs.
    let mut robot = 0u64;
    for (r, role) in st.roles.iter().enumerate() {
        let mods = st.role_modules(r);
        let genes = st.layout.genes.iter().filter(|g| mods.contains(&(g.module as usize))).count();
        let last = robot + u64::from(role.robots) - 1;
        let robots =
            if role.robots == 1 { format!("robot {robot}") } else { format!("robots {robot}..{last}") };
        let names: Vec<&str> = st.modules[mods].iter().map(|m| m.name.as_str()).collect();
        let _ = writeln!(out, "role `{}`: {robots}, modules {}, {genes} genes", role.name, names.join(", "));
        robot = last + 1;
    }
    // Parameters that are not genes: what training stages learned.
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
    if let StageRun::Train { actions } = st.run {
        let _ = writeln!(out, "training stage: its modules learn for {actions} actions; nothing is evolved");
    }
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
    out
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
