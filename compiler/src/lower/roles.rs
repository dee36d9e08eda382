//! The roles of a heterogeneous team: `role NAME robots N { MODULES LINKS }`.
//!
//! A stage that extends no stage may declare roles instead of modules. Each
//! role's modules and links are lowered as a stage's are, in a scope of
//! their own (names and links resolve within the role); the roles' modules
//! are concatenated in declaration order, so role `r` owns the next
//! `roles[r].modules` modules, their links and their genes, and its robots
//! follow the earlier roles' (robot 0 plays role 0). The team's robots are
//! the roles' sum. A stage that extends a stage with roles keeps them, with
//! their modules, links and genes (frozen), and may add modules and links
//! to a role (`role NAME adds { ... }`), add a role (`role NAME robots N {
//! ... }`, after the others) and change a role's robots (`role NAME robots
//! N`). A role's added modules follow its own, so the later roles' modules
//! move: their genes keep their place in the genome and are renumbered.
//! A role may declare the fitness of its robots (`fitness` in the role).

use shaping_runtime::limits::{MAX_MODULES, MAX_ROBOTS};
use shaping_runtime::program::{Role, StageRun};

use super::*;
use crate::diag::Error;
use crate::syntax::ast;

/// How to make a role's modules evolvable, for messages.
pub(super) const EVOLVABLE_HELP: &str = "give one of its modules genes: `activation evolvable`, `weights evolvable` in a `behavior neural { ... }`, or evolvable links between its modules (`links all evolvable`)";

/// Whether `inner` lies within `outer`.
fn within(inner: Span, outer: Span) -> bool {
    outer.start <= inner.start && inner.end <= outer.end
}

impl Lower<'_> {
    /// The heads of the roles `decl` declares (names, robots): into
    /// `st.roles` (each new role with no module yet) when the stage may
    /// have roles. A stage that extends a stage with roles may add roles,
    /// add to its roles and change their robots; one that extends a stage
    /// without roles declares none. For each role `decl` declares, the
    /// index in `st.roles` of the role whose modules it lowers (`None`: it
    /// lowers none, or was refused).
    pub(super) fn role_heads(&mut self, st: &mut StageSt, decl: &ast::StageDecl) -> Vec<Option<usize>> {
        // A `world changes`' `role NAME robots N`s, after the stage's roles.
        let world_roles = self.world_roles(st, decl);
        let roles: Vec<&ast::RoleDecl> = decl.roles().chain(&world_roles).collect();
        let Some(first) = roles.first() else { return Vec::new() };
        if let Some(e) = &decl.extends {
            if st.roles.is_empty() {
                let parent = e.text.clone();
                for r in &roles {
                    self.errors.push(Error::RolesNotHere {
                        span: r.head().into(),
                        other: Some(e.span.into()),
                        message: format!("stage `{}` extends stage `{parent}`, whose team has no roles, and declares roles", decl.name.text),
                        label: "a role".into(),
                        other_label: "extends here".into(),
                        help: "roles are declared by a stage that extends no stage; a stage that extends it keeps its roles and may add modules to them (`role NAME adds { ... }`) and roles (`role NAME robots N { ... }`)".into(),
                    });
                }
                return vec![None; roles.len()];
            }
            return self.later_role_heads(st, decl, &roles);
        }
        let mut seen: HashMap<&str, Span> = HashMap::new();
        let mut heads = Vec::new();
        let mut lowered = Vec::new();
        for r in &roles {
            if let Some(f) = seen.get(r.name.text.as_str()) {
                self.errors.push(Error::Duplicate {
                    span: r.name.span.into(),
                    first: (*f).into(),
                    what: "role",
                    name: r.name.text.clone(),
                });
            } else {
                seen.insert(&r.name.text, r.name.span);
            }
            if r.adds {
                self.errors.push(Error::UnknownRole {
                    span: r.head().into(),
                    message: format!(
                        "stage `{}` adds to role `{}`, but it extends no stage: there is no role to add to",
                        decl.name.text, r.name.text
                    ),
                    label: "no such role yet".into(),
                    help: Some(format!(
                        "declare the role with its robots: `role {} robots N {{ module ... }}`",
                        r.name.text
                    )),
                });
            }
            lowered.push(Some(self.new_role(st, r)));
            heads.push(r.head());
        }
        self.check_robot_limit(st, first.head(), &decl.name.text);
        st.role_heads = heads;
        lowered
    }

    /// The `role NAME robots N` items of `decl`'s `world changes`, as the
    /// stage's own `role NAME robots N`: in a stage that extends a stage
    /// with roles only. Elsewhere (a stage without inherited roles, a
    /// `world` or `world adds`, a variant) they are refused.
    /// A role declared with its robots and modules (`role NAME robots N {
    /// ... }`, in a first stage or added by a later one) appended to the
    /// stage's roles, its modules lowered later; its index. A role without
    /// modules is an error (a first stage's `adds` is one already).
    fn new_role(&mut self, st: &mut StageSt, r: &ast::RoleDecl) -> usize {
        let robots = r
            .robots
            .as_ref()
            .and_then(|q| self.count_in(q, "the robots of a role", 1, MAX_ROBOTS.into()))
            .unwrap_or(1);
        if r.modules().next().is_none() && !r.adds {
            self.errors.push(Error::EmptyRole {
                span: r.head().into(),
                role: r.name.text.clone(),
                help: format!(
                    "declare the modules its robots run inside its braces: `role {} robots N {{ module NAME {{ ... }} }}`",
                    r.name.text
                ),
            });
        }
        st.roles.push(Role { name: r.name.text.clone(), robots: robots as u32, modules: 0, fitness: None });
        st.roles.len() - 1
    }

    fn world_roles(&mut self, st: &StageSt, decl: &ast::StageDecl) -> Vec<ast::RoleDecl> {
        let later = decl.extends.is_some() && !st.roles.is_empty();
        let mut out = Vec::new();
        let refuse = |lw: &mut Self, span: Span, message: String, help: String| {
            lw.errors.push(Error::RolesNotHere {
                span: span.into(),
                other: None,
                message,
                label: "a role's robots".into(),
                other_label: String::new(),
                help,
            });
        };
        for item in &decl.items {
            match item {
                ast::StageItem::World(w) => {
                    for x in &w.items {
                        let ast::WorldItem::RoleRobots { name, robots, span } = x else { continue };
                        if !later {
                            let message = match &decl.extends {
                                None => format!(
                                    "the world of stage `{}` says how many robots play role `{}`, but the stage declares its roles",
                                    decl.name.text, name.text
                                ),
                                Some(p) => format!(
                                    "the world of stage `{}` changes the robots of role `{}`, but the team of stage `{}` has no roles",
                                    decl.name.text, name.text, p.text
                                ),
                            };
                            refuse(
                                self,
                                *span,
                                message,
                                format!("a stage that declares its roles gives their robots in them (`role {} robots N {{ ... }}`); a later stage changes them, in its `world changes` or among its items", name.text),
                            );
                        } else if w.mode != ast::WorldMode::Changes {
                            refuse(
                                self,
                                *span,
                                format!("stage `{}` changes the robots of role `{}` outside `world changes`", decl.name.text, name.text),
                                format!("write it in `world changes {{ role {} robots N }}`, or among the stage's items", name.text),
                            );
                        } else {
                            out.push(ast::RoleDecl {
                                name: name.clone(),
                                robots: Some(robots.clone()),
                                adds: false,
                                body: false,
                                items: Vec::new(),
                                span: *span,
                                head: *span,
                            });
                        }
                    }
                }
                ast::StageItem::Variants(v) => {
                    for d in &v.variants {
                        for x in &d.world.items {
                            let ast::WorldItem::RoleRobots { name, span, .. } = x else { continue };
                            refuse(
                                self,
                                *span,
                                format!("variant `{}` changes the robots of role `{}`", d.name.text, name.text),
                                format!("every variant's world has the stage's roles: change the role's robots for the stage, with `role {} robots N` among its items or in its `world changes`", name.text),
                            );
                        }
                    }
                }
                _ => {}
            }
        }
        out
    }

    /// More robots in the roles than the limit: an error at `at`.
    fn check_robot_limit(&mut self, st: &StageSt, at: Span, stage: &str) {
        let sum: u64 = st.roles.iter().map(|r| u64::from(r.robots)).sum();
        if sum > u64::from(MAX_ROBOTS) {
            self.value_error(
                at,
                format!(
                    "the roles of stage `{stage}` have {sum} robots, more than the limit of {MAX_ROBOTS}"
                ),
                "too many robots",
                Some("this limit keeps a run within the memory and time of one machine".into()),
            );
        }
    }

    /// The heads of the roles of `decl`, a stage that extends a stage with
    /// roles (in `st.roles`): `role NAME adds { ... }` adds to a role the
    /// team has, `role NAME robots N` changes its robots, `role NAME robots
    /// N { ... }` adds a role (not in a test stage, which evolves nothing).
    fn later_role_heads(
        &mut self,
        st: &mut StageSt,
        decl: &ast::StageDecl,
        roles: &[&ast::RoleDecl],
    ) -> Vec<Option<usize>> {
        let stage = decl.name.text.clone();
        let inherited = st.roles.len();
        let test = decl.items.iter().find_map(|i| match i {
            ast::StageItem::Test { span, .. } => Some(*span),
            _ => None,
        });
        // What this stage said of each role, for repetitions: (adds, robots).
        let mut said: HashMap<(String, bool), Span> = HashMap::new();
        let mut lowered = Vec::new();
        let mut changed: Option<Span> = None;
        for r in roles {
            let at = st.roles.iter().position(|x| x.name == r.name.text);
            let new_role = r.robots.is_some() && r.body && !r.adds;
            let key = (r.name.text.clone(), r.adds || new_role);
            if let Some(first) = said.get(&key) {
                self.errors.push(Error::Duplicate {
                    span: r.head().into(),
                    first: (*first).into(),
                    what: if r.adds { "addition to role" } else { "role" },
                    name: r.name.text.clone(),
                });
                lowered.push(None);
                continue;
            }
            said.insert(key, r.head());
            let unknown = |lw: &mut Self, what: &str| {
                let names = lw.role_names(st);
                lw.errors.push(Error::UnknownRole {
                    span: r.name.span.into(),
                    message: format!(
                        "stage `{stage}` {what} role `{}`, which the team of stage `{}` does not have",
                        r.name.text,
                        decl.extends.as_ref().map_or("", |e| e.text.as_str())
                    ),
                    label: "no such role".into(),
                    help: did_you_mean(&r.name.text, st.roles.iter().map(|x| x.name.as_str())).or_else(|| {
                        Some(format!(
                            "the team's roles are {names}; to add a role, declare it with its robots and modules: `role {} robots N {{ module ... }}`",
                            r.name.text
                        ))
                    }),
                });
            };
            if r.adds || !r.body {
                let Some(i) = at.filter(|&i| i < inherited) else {
                    unknown(self, if r.adds { "adds to" } else { "changes the robots of" });
                    lowered.push(None);
                    continue;
                };
                if let Some(q) = &r.robots {
                    if let Some(n) = self.count_in(q, "the robots of a role", 1, MAX_ROBOTS.into()) {
                        st.roles[i].robots = n as u32;
                        changed = changed.or(Some(r.head()));
                    }
                }
                lowered.push(r.adds.then_some(i));
                continue;
            }
            // A new role.
            if let Some(i) = at {
                let first = st.role_heads.get(i).copied().unwrap_or(r.name.span);
                self.errors.push(Error::Duplicate {
                    span: r.name.span.into(),
                    first: first.into(),
                    what: "role",
                    name: r.name.text.clone(),
                });
                lowered.push(None);
                continue;
            }
            if let Some(t) = test {
                self.errors.push(Error::RoleInTest {
                    span: r.head().into(),
                    test: Some(t.into()),
                    stage: stage.clone(),
                    role: r.name.text.clone(),
                    help: format!(
                        "a test stage runs the best of the stage it extends, which has no genes for role `{}`: add the role in a stage that evolves (without `test best ...`), and test that stage's best",
                        r.name.text
                    ),
                });
                lowered.push(None);
                continue;
            }
            lowered.push(Some(self.new_role(st, r)));
            st.role_heads.push(r.head());
            changed = changed.or(Some(r.head()));
        }
        if let Some(h) = changed {
            self.check_robot_limit(st, h, &stage);
        }
        lowered
    }

    /// With roles, a team too large for the start region (reported since
    /// error `since`) is made smaller in its roles: the help says so.
    pub(super) fn role_team_help(&mut self, roles: &[Role], since: usize) {
        let Some(first) = roles.first() else { return };
        let list = roles.iter().map(|r| format!("`{}` {}", r.name, r.robots)).collect::<Vec<_>>().join(", ");
        for e in &mut self.errors[since..] {
            if let Error::TeamTooLarge { help, .. } = e {
                *help = format!(
                    "{help}; with roles, the team is the roles' robots ({list}): fewer robots in a role (`role {} robots N`)",
                    first.name
                );
            }
        }
    }

    /// The roles of `st`, for messages: `` `a`, `b` ``.
    fn role_names(&self, st: &StageSt) -> String {
        st.roles.iter().map(|r| format!("`{}`", r.name)).collect::<Vec<_>>().join(", ")
    }

    /// With roles, the team is the roles' robots: a `robots N` written in
    /// `block` (the span of a stage or a variant) that says otherwise is
    /// refused, and the world's robots become the roles' sum.
    pub(super) fn role_robots(
        &mut self,
        ws: &mut WorldSt,
        st_roles: &[Role],
        heads: &[Span],
        block: Span,
        what: String,
        changed: Option<Span>,
    ) {
        if st_roles.is_empty() {
            return;
        }
        let sum: u64 = st_roles.iter().map(|r| u64::from(r.robots)).sum();
        let robots = ws.world.robots;
        match ws.spans.get("robots").copied() {
            Some(sp) if within(sp, block) && u64::from(robots) != sum => {
                self.errors.push(Error::RoleRobots {
                    span: sp.into(),
                    first_role: heads.first().map(|&h| h.into()),
                    where_: what,
                    robots,
                    roles: sum,
                    help: self.role_robots_help(st_roles, heads, block),
                });
            }
            Some(sp) if within(sp, block) => {}
            // The team changes here (a role's robots, a new role): a team
            // too large for the start region is reported here.
            Some(_) if changed.is_some() => {
                if let Some(c) = changed {
                    ws.spans.insert("robots", c);
                }
            }
            Some(_) => {}
            // The roles declare the team: a team too large for the start
            // region is reported at the first role.
            None => {
                if let Some(&h) = heads.first() {
                    ws.spans.insert("robots", h);
                }
            }
        }
        ws.world.robots = sum.min(u64::from(MAX_ROBOTS)) as u32;
    }

    /// How to make `robots N` in `block` agree with the roles: in the stage
    /// that declares them, leave it out or change the roles; in a stage that
    /// inherits them, leave it out, and change a role's robots with `role
    /// NAME robots N` in the stage (or, for a run, with `--set`).
    fn role_robots_help(&self, st_roles: &[Role], heads: &[Span], block: Span) -> String {
        let roles =
            st_roles.iter().map(|r| format!("`{}` {}", r.name, r.robots)).collect::<Vec<_>>().join(", ");
        let declaring = heads.first().and_then(|&h| self.file.stages.iter().find(|s| within(h, s.span)));
        match declaring {
            Some(d) if !within(block, d.span) => {
                let role = st_roles.first().map_or("ROLE", |r| r.name.as_str());
                let here = self.file.stages.iter().find(|s| within(block, s.span));
                let stage = here.map_or("STAGE", |s| s.name.text.as_str());
                format!(
                    "with roles, the team is the roles' robots ({roles}), declared by stage `{}` and kept by the stages that extend it: leave `robots` out here, and change a role's robots in stage `{stage}` with `role {role} robots N` (or for one run with `--set {stage}.{role}.robots=N`)",
                    d.name.text
                )
            }
            _ => format!(
                "with roles, the team is the roles' robots ({roles}): leave `robots` out of the world, or change the roles' `robots`"
            ),
        }
    }

    /// A stage with roles (declared, or inherited from the stage it
    /// extends) declares its modules and links in its roles: its modules
    /// and links outside them are refused. `true` when the stage's modules
    /// are its roles' (lowered by [`Lower::role_modules`]).
    pub(super) fn check_role_items(&mut self, st: &StageSt, decl: &ast::StageDecl, inherited: bool) -> bool {
        if st.roles.is_empty() {
            return false;
        }
        let what = |item: &ast::StageItem| -> Option<(Span, String)> {
            Some(match item {
                ast::StageItem::Module(m) => (m.name.span, format!("module `{}`", m.name.text)),
                ast::StageItem::Link(l) => (l.span, format!("the link `{} -> {}`", l.from.text, l.to.text)),
                ast::StageItem::LinksAll(_, sp) => (*sp, "`links all`".into()),
                _ => return None,
            })
        };
        let first_role = st.role_heads.first().copied().unwrap_or(decl.name.span);
        let role = st.roles.first().map_or("ROLE", |r| r.name.as_str()).to_string();
        for item in &decl.items {
            let Some((span, what)) = what(item) else { continue };
            if inherited {
                let parent = decl.extends.as_ref().map(|e| e.text.clone()).unwrap_or_default();
                self.errors.push(Error::RolesNotHere {
                    span: span.into(),
                    other: Some(first_role.into()),
                    message: format!(
                        "stage `{}` extends stage `{parent}`, whose team has roles, and declares {what} outside them",
                        decl.name.text
                    ),
                    label: "declared here".into(),
                    other_label: format!("the roles of stage `{parent}`"),
                    help: format!("each robot of a team with roles runs its role's modules and links only: add it to a role (`role {role} adds {{ ... }}`), or declare a role (`role NAME robots N {{ ... }}`)"),
                });
            } else {
                self.errors.push(Error::OutsideRole {
                    span: span.into(),
                    role: first_role.into(),
                    stage: decl.name.text.clone(),
                    what,
                    help: "move it into a role (`role NAME robots N { module ... }`): each robot of a team with roles runs its role's modules and links only".into(),
                });
            }
        }
        true
    }

    /// The modules and links of the roles `decl` declares (`lowered`, from
    /// [`Lower::role_heads`], says which role each one's are): each role's
    /// lowered in a scope of its own, after the modules and links it has
    /// (inherited, their genes frozen); then every role's modules are
    /// concatenated in role order (the roles' module counts set), their
    /// links and inherited genes renumbered to match.
    pub(super) fn role_modules(
        &mut self,
        hw: &Hw,
        st: &mut StageSt,
        decl: &ast::StageDecl,
        s: u16,
        lowered: &[Option<usize>],
    ) {
        let roles: Vec<&ast::RoleDecl> = decl.roles().collect();
        let n = st.roles.len();
        let (mut mods, mut links, starts) = split_by_role(st);
        let old: Vec<usize> = mods.iter().map(Vec::len).collect();
        // The names of every role's modules (its own and those it declares
        // here): a link to another role's is named so.
        let mut names: Vec<Vec<String>> =
            mods.iter().map(|m| m.iter().map(|x| x.name.clone()).collect()).collect();
        for (d, r) in roles.iter().zip(lowered) {
            if let Some(ns) = r.and_then(|r| names.get_mut(r)) {
                ns.extend(d.modules().map(|m| m.name.text.clone()));
            }
        }
        let mut total = st.modules.len();
        for (d, &r) in roles.iter().zip(lowered) {
            let Some(r) = r.filter(|&r| r < n) else { continue };
            let role = st.roles[r].name.clone();
            let mut declared_here: HashMap<String, Span> = HashMap::new();
            for m in d.modules() {
                if let Some(x) = mods[r].iter().find(|x| x.name == m.name.text && x.stage < s) {
                    self.errors.push(Error::RoleModuleExists {
                        span: m.name.span.into(),
                        first: x.span.into(),
                        role: role.clone(),
                        module: m.name.text.clone(),
                        by: self.stage_names.get(x.stage as usize).cloned().unwrap_or_default(),
                        help: format!(
                            "a later stage keeps the modules of role `{role}` as they are, their genes frozen: give the new module a name of its own"
                        ),
                    });
                    continue;
                }
                if !self.declare_module(&mut declared_here, &m.name) {
                    continue;
                }
                if total >= MAX_MODULES {
                    self.value_error(
                        m.name.span,
                        format!("stage `{}` has more than {MAX_MODULES} modules", decl.name.text),
                        "one module too many",
                        None,
                    );
                    break;
                }
                self.module(hw, &mut mods[r], m, s);
                total += 1;
            }
            for m in mods[r].iter().filter(|m| m.stage == s) {
                self.check_module(m);
            }
            let others: Vec<(String, String)> = names
                .iter()
                .enumerate()
                .filter(|&(o, _)| o != r)
                .flat_map(|(o, ns)| ns.iter().map(move |x| (x.clone(), o)))
                .map(|(x, o)| (x, st.roles[o].name.clone()))
                .collect();
            self.links_of(&mods[r], &mut links[r], &decl.name.text, &d.items, s, Some((&role, &others)));
        }
        join_roles(st, mods, links, &starts, &old);
    }

    /// The fitness each role of `decl` declares (`fitness` inside the
    /// role), checked as a stage's: it replaces the stage's for the role's
    /// robots (`fitness adds` adds to the role's fitness: its own, or the
    /// stage's). A fitness of the team's only role is a warning; one that
    /// reads an actuator only the other roles' modules command, an error.
    pub(super) fn role_fitness(
        &mut self,
        hw: &Hw,
        st: &mut StageSt,
        decl: &ast::StageDecl,
        lowered: &[Option<usize>],
    ) {
        for (d, &r) in decl.roles().zip(lowered) {
            let fits: Vec<&ast::FitnessDecl> = d.fitness().collect();
            let (Some(r), Some(&first)) = (r, fits.first()) else { continue };
            let Some(role) = st.roles.get(r).cloned() else { continue };
            let saved = (st.fitness.clone(), st.fitness_declared);
            st.fitness = role.fitness.clone().unwrap_or_else(|| saved.0.clone());
            let mut first_span: Option<Span> = None;
            for f in &fits {
                if let (Some(first), false) = (first_span, f.adds) {
                    self.errors.push(Error::Conflict {
                        span: f.span.into(),
                        other: first.into(),
                        message: format!(
                            "role `{}` declares its fitness twice; add terms with `fitness adds ...` or after a `,`",
                            role.name
                        ),
                        label: "replaces the first".into(),
                        other_label: "first `fitness`".into(),
                    });
                    continue;
                }
                first_span = first_span.or(Some(f.span));
                for (_, sp) in &f.team {
                    self.value_error(
                        *sp,
                        format!("the fitness of role `{}` says how the team's fitness is made", role.name),
                        "the team's, not the role's",
                        Some("the team's fitness aggregates every robot's, whatever its role: write `team sum|mean|min` in the stage's fitness".into()),
                    );
                }
                self.fitness(hw, st, f);
            }
            let mut fitness = std::mem::replace(&mut st.fitness, saved.0);
            fitness.team = st.fitness.team;
            st.fitness_declared = saved.1;
            if st.roles.len() == 1 {
                self.errors.push(Error::RoleFitnessAlone {
                    span: first.span.into(),
                    role: role.name.clone(),
                    help: "with one role, a role's fitness is every robot's: declare it as the stage's fitness (outside the role)".into(),
                });
            }
            self.check_role_fitness_actuators(st, r, &fitness, first.span);
            if let Some(x) = st.roles.get_mut(r) {
                x.fitness = Some(fitness);
            }
        }
    }

    /// A role's fitness that reads the arm, the claw or the broadcast,
    /// which no module of the role commands but another role's does: for
    /// the role's robots, a constant.
    fn check_role_fitness_actuators(&mut self, st: &StageSt, r: usize, fitness: &Fitness, span: Span) {
        use shaping_runtime::catalog::{ACT_ARM, ACT_CLAW, ACT_SIGNAL, SIGNALS};
        use shaping_runtime::expr::Op;
        // The actuator's slots: the broadcast has one per value.
        let slots = |slot: usize| if slot == ACT_SIGNAL { slot..slot + SIGNALS } else { slot..slot + 1 };
        let read = |slot: usize| {
            fitness
                .per_action
                .iter()
                .chain(&fitness.at_end)
                .any(|e| slots(slot).any(|k| e.ops.contains(&Op::Act(k as u16))))
        };
        let commands = |m: &ModuleSt, slot: usize| match &m.behavior {
            Some(Behavior::Script(sc)) => sc.steps.iter().any(|x| match x.action {
                Action::Arm(_) => slot == ACT_ARM,
                Action::Claw(_) => slot == ACT_CLAW,
                Action::Signal(_) => slot == ACT_SIGNAL,
                _ => false,
            }),
            // A network with broadcast outputs (`broadcast NAME`).
            Some(Behavior::Neural(nb)) => slot == ACT_SIGNAL && nb.signals > 0,
            _ => false,
        };
        let mut start = 0usize;
        let ranges: Vec<std::ops::Range<usize>> = st
            .roles
            .iter()
            .map(|x| {
                let range = start..(start + x.modules as usize).min(st.modules.len());
                start = range.end;
                range
            })
            .collect();
        let by = |k: usize, slot: usize| {
            ranges.get(k).is_some_and(|rg| st.modules[rg.clone()].iter().any(|m| commands(m, slot)))
        };
        let kinds = [
            (ACT_ARM, ActuatorKind::Lift),
            (ACT_CLAW, ActuatorKind::Grip),
            (ACT_SIGNAL, ActuatorKind::Broadcast),
        ];
        for (slot, kind) in kinds {
            if !read(slot) || by(r, slot) {
                continue;
            }
            let others: Vec<String> = (0..st.roles.len())
                .filter(|&k| k != r && by(k, slot))
                .map(|k| format!("role `{}`", st.roles[k].name))
                .collect();
            if others.is_empty() {
                continue;
            }
            let actuator =
                st.actuators.iter().find(|a| a.kind == kind).map_or("", |a| a.name.as_str()).to_string();
            let role = st.roles[r].name.clone();
            self.errors.push(Error::RoleFitnessReadsOther {
                span: span.into(),
                role: role.clone(),
                actuator: actuator.clone(),
                others: others.join(", "),
                help: format!(
                    "each robot's fitness reads its own actuators, and no module of role `{role}` commands `{actuator}`, so for its robots the term never changes: measure what the role's robots do, or move the term into the fitness of a role that commands `{actuator}`"
                ),
            });
        }
    }

    /// In an evolved stage, every role has a gene of its own (inherited
    /// frozen genes count, as they do for the runtime).
    pub(super) fn check_role_genes(&mut self, st: &StageSt, decl: &ast::StageDecl) {
        if !matches!(st.run, StageRun::Evolve(_)) || st.roles.is_empty() {
            return;
        }
        let own: Vec<&ast::RoleDecl> = decl.roles().collect();
        let mut start = 0usize;
        for role in &st.roles {
            let mine = start..start + role.modules as usize;
            start = mine.end;
            if role.modules == 0 || st.genes.iter().any(|g| mine.contains(&(g.module as usize))) {
                continue;
            }
            // The role declared here (a stage's first, or a later stage's new role).
            let declared = own.iter().find(|d| d.name.text == role.name && d.body && !d.adds);
            let (span, label) = match declared {
                Some(d) => (d.name.span, "its modules have no evolvable weights or links".to_string()),
                None => {
                    (decl.name.span, format!("evolves role `{}`, whose modules have no genes", role.name))
                }
            };
            self.errors.push(Error::RoleWithoutGenes {
                span: span.into(),
                role: role.name.clone(),
                label,
                help: EVOLVABLE_HELP.into(),
            });
        }
    }

    /// A training stage trains the modules of one robot: it has no roles.
    pub(super) fn check_role_training(&mut self, st: &StageSt, decl: &ast::StageDecl) {
        if st.roles.is_empty() || decl.extends.is_some() {
            return;
        }
        let Some(train) = decl.items.iter().find_map(|i| match i {
            ast::StageItem::Train { span, .. } => Some(*span),
            _ => None,
        }) else {
            return;
        };
        for r in decl.roles() {
            self.errors.push(Error::RolesNotHere {
                span: r.head().into(),
                other: Some(train.into()),
                message: format!("training stage `{}` has roles", decl.name.text),
                label: "a role".into(),
                other_label: "trains here".into(),
                help: "a training stage trains the modules of one robot: train a role's modules in a training stage without roles, and use what they learned with `weights trained STAGE` in the role's modules".into(),
            });
        }
    }
}

/// Each role's modules and links, numbered within the role, and the index
/// of each role's first module in the stage's.
fn split_by_role(st: &StageSt) -> (Vec<Vec<ModuleSt>>, Vec<Vec<LinkSt>>, Vec<usize>) {
    let (mut mods, mut links, mut starts) = (Vec::new(), Vec::new(), Vec::new());
    let mut start = 0usize;
    for role in &st.roles {
        let len = (role.modules as usize).min(st.modules.len().saturating_sub(start));
        let range = start..start + len;
        mods.push(st.modules[range.clone()].to_vec());
        let inside = |i: u16| range.contains(&(i as usize));
        links.push(
            st.links
                .iter()
                .filter(|l| inside(l.from) && inside(l.to))
                .map(|l| LinkSt { from: l.from - start as u16, to: l.to - start as u16, ..l.clone() })
                .collect::<Vec<_>>(),
        );
        starts.push(start);
        start = range.end;
    }
    (mods, links, starts)
}

/// The roles' modules and links concatenated again in role order: a role's
/// added modules follow its own (the first `old[r]` of `mods[r]`, from
/// `starts[r]` in the stage), and the later roles' move, their links and
/// the genes of moved modules renumbered.
fn join_roles(
    st: &mut StageSt,
    mods: Vec<Vec<ModuleSt>>,
    links: Vec<Vec<LinkSt>>,
    starts: &[usize],
    old: &[usize],
) {
    // `map`: a module's old index to its new.
    let mut map: Vec<u16> = (0..st.modules.len() as u16).collect();
    let (mut modules, mut all_links) = (Vec::new(), Vec::new());
    for (r, (ms, ls)) in mods.into_iter().zip(links).enumerate() {
        let off = modules.len();
        for k in 0..old[r] {
            if let Some(x) = map.get_mut(starts[r] + k) {
                *x = (off + k) as u16;
            }
        }
        let o = off as u16;
        all_links.extend(ls.into_iter().map(|l| LinkSt { from: l.from + o, to: l.to + o, ..l }));
        st.roles[r].modules = ms.len() as u16;
        modules.extend(ms);
    }
    let moved = |i: u16| map.get(i as usize).copied().unwrap_or(i);
    for g in &mut st.genes {
        g.module = moved(g.module);
        if let GeneRole::Link { from } = &mut g.role {
            *from = moved(*from);
        }
    }
    st.modules = modules;
    st.links = all_links;
}
