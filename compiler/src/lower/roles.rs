//! The roles of a heterogeneous team: `role NAME robots N { MODULES LINKS }`.
//!
//! A stage that extends no stage may declare roles instead of modules. Each
//! role's modules and links are lowered as a stage's are, in a scope of
//! their own (names and links resolve within the role); the roles' modules
//! are concatenated in declaration order, so role `r` owns the next
//! `roles[r].modules` modules, their links and their genes, and its robots
//! follow the earlier roles' (robot 0 plays role 0). The team's robots are
//! the roles' sum. A stage that extends a stage with roles keeps them, with
//! their modules and links, and declares none.

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
    /// `st.roles` (each with no module yet) when the stage may have roles.
    /// A stage that extends another declares none.
    pub(super) fn role_heads(&mut self, st: &mut StageSt, decl: &ast::StageDecl) {
        let roles: Vec<&ast::RoleDecl> = decl.roles().collect();
        let Some(first) = roles.first() else { return };
        if let Some(e) = &decl.extends {
            let parent = e.text.clone();
            for r in &roles {
                self.errors.push(Error::RolesNotHere {
                    span: r.head().into(),
                    other: Some(e.span.into()),
                    message: format!("stage `{}` extends stage `{parent}` and declares roles", decl.name.text),
                    label: "a role".into(),
                    other_label: "extends here".into(),
                    help: "roles are declared by a stage that extends no stage; a stage that extends it keeps its roles, their modules and their links".into(),
                });
            }
            return;
        }
        let mut seen: HashMap<&str, Span> = HashMap::new();
        let mut heads = Vec::new();
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
            let robots = self.count_in(&r.robots, "the robots of a role", 1, MAX_ROBOTS.into()).unwrap_or(1);
            if r.modules().next().is_none() {
                self.errors.push(Error::EmptyRole {
                    span: r.head().into(),
                    role: r.name.text.clone(),
                    help: format!(
                        "declare the modules its robots run inside its braces: `role {} robots N {{ module NAME {{ ... }} }}`",
                        r.name.text
                    ),
                });
            }
            st.roles.push(Role { name: r.name.text.clone(), robots: robots as u32, modules: 0 });
            heads.push(r.head());
        }
        let sum: u64 = st.roles.iter().map(|r| u64::from(r.robots)).sum();
        if sum > u64::from(MAX_ROBOTS) {
            self.value_error(
                first.head(),
                format!(
                    "the roles of stage `{}` have {sum} robots, more than the limit of {MAX_ROBOTS}",
                    decl.name.text
                ),
                "too many robots",
                Some("this limit keeps a run within the memory and time of one machine".into()),
            );
        }
        st.role_heads = heads;
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
    /// inherits them (whose roles it may not change, `S0028`), leave it out,
    /// or change a role's robots for a run with `--set`.
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
                    "with roles, the team is the roles' robots ({roles}), declared by stage `{}` and kept by the stages that extend it: leave `robots` out here; to run this stage with other numbers, pass `--set {stage}.{role}.robots=N`",
                    d.name.text
                )
            }
            _ => format!(
                "with roles, the team is the roles' robots ({roles}): leave `robots` out of the world, or change the roles' `robots`"
            ),
        }
    }

    /// A stage with roles (declared, or inherited from the stage it
    /// extends) declares its modules and links in its roles: the modules,
    /// links and roles of a stage that extends one are refused, and so are
    /// a role stage's modules and links outside its roles. `true` when the
    /// stage's modules are its roles' (lowered by [`Lower::role_modules`]).
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
        for item in &decl.items {
            let Some((span, what)) = what(item) else { continue };
            if inherited {
                let parent = decl.extends.as_ref().map(|e| e.text.clone()).unwrap_or_default();
                self.errors.push(Error::RolesNotHere {
                    span: span.into(),
                    other: Some(first_role.into()),
                    message: format!(
                        "stage `{}` extends stage `{parent}`, whose team has roles, and declares {what}",
                        decl.name.text
                    ),
                    label: "declared here".into(),
                    other_label: format!("the roles of stage `{parent}`"),
                    help: "a stage that extends a stage with roles keeps its roles, their modules and their links, and adds none: change its world, its fitness or its evolution, or declare the modules in the roles of the first stage".into(),
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
        !inherited
    }

    /// The modules and links of the roles `decl` declares, role by role:
    /// each lowered in a scope of its own, then appended to the stage's
    /// (links renumbered), and each role's module count set.
    pub(super) fn role_modules(&mut self, hw: &Hw, st: &mut StageSt, decl: &ast::StageDecl, s: u16) {
        let roles: Vec<&ast::RoleDecl> = decl.roles().collect();
        for (r, role) in roles.iter().enumerate() {
            let mut modules: Vec<ModuleSt> = Vec::new();
            let mut declared_here: HashMap<String, Span> = HashMap::new();
            for m in role.modules() {
                if !self.declare_module(&mut declared_here, &m.name) {
                    continue;
                }
                if st.modules.len() + modules.len() >= MAX_MODULES {
                    self.value_error(
                        m.name.span,
                        format!("stage `{}` has more than {MAX_MODULES} modules", decl.name.text),
                        "one module too many",
                        None,
                    );
                    break;
                }
                self.module(hw, &mut modules, m, s);
            }
            for m in &modules {
                self.check_module(m);
            }
            let others: Vec<(String, String)> = roles
                .iter()
                .filter(|o| o.name.text != role.name.text)
                .flat_map(|o| o.modules().map(|m| (m.name.text.clone(), o.name.text.clone())))
                .collect();
            let mut links = Vec::new();
            self.links_of(&modules, &mut links, &decl.name.text, &role.items, s, &others);
            let offset = st.modules.len() as u16;
            for l in &mut links {
                l.from += offset;
                l.to += offset;
            }
            if let Some(x) = st.roles.get_mut(r) {
                x.modules = modules.len() as u16;
            }
            st.modules.extend(modules);
            st.links.extend(links);
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
        for (r, role) in st.roles.iter().enumerate() {
            let mine = start..start + role.modules as usize;
            start = mine.end;
            if role.modules == 0 || st.genes.iter().any(|g| mine.contains(&(g.module as usize))) {
                continue;
            }
            let (span, label) = match own.get(r) {
                Some(d) if decl.extends.is_none() => {
                    (d.name.span, "its modules have no evolvable weights or links".to_string())
                }
                _ => (decl.name.span, format!("evolves role `{}`, whose modules have no genes", role.name)),
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
