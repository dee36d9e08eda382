//! What a stage does (evolve, test or train), the evolution settings and the fitness.

use shaping_runtime::catalog::ActuatorKind;
use shaping_runtime::expr::{Expr, Op};
use shaping_runtime::limits::*;
use shaping_runtime::program::*;

use super::*;
use crate::diag::{did_you_mean, Error};
use crate::syntax::ast;
use crate::syntax::Span;

/// The settings of `evolve { }`.
pub(crate) const EVOLVE_SETTINGS: [&str; 10] = [
    "population",
    "generations",
    "actions",
    "seed",
    "selection",
    "crossover",
    "mutation",
    "elitism",
    "evaluations",
    "inheritance",
];

/// The events of fitness bonuses.
pub(crate) const EVENTS: [&str; 4] = ["grip", "release outside", "recharge", "collision"];

impl Lower<'_> {
    pub(super) fn run(&mut self, st: &mut StageSt, decl: &ast::StageDecl, has_parent: bool) {
        use ast::StageItem as I;
        let mut evolve_span = None;
        let mut test_span: Option<Span> = None;
        let evolve_settings = decl.items.iter().flat_map(|i| match i {
            I::Evolve(settings, _) => settings.as_slice(),
            _ => &[],
        });
        self.repeated("evolution setting", evolve_settings.map(|s| (s.name.text.clone(), s.span)));
        for item in &decl.items {
            match item {
                I::Train { actions, span } => {
                    if let Some(e) = evolve_span.or(test_span) {
                        self.conflict_run(*span, e);
                    }
                    test_span = Some(*span);
                    if has_parent {
                        self.value_error(
                            *span,
                            format!("training stage `{}` extends another stage", decl.name.text),
                            "trains from scratch",
                            Some("a training stage stands alone; later stages use what it learned with `weights trained STAGE`".into()),
                        );
                    }
                    if let Some(n) = self.count_in(actions, "the training length", 1, MAX_ACTIONS.into()) {
                        st.run = StageRun::Train { actions: n as u32 };
                    }
                }
                I::Evolve(settings, sp) => {
                    if let Some(t) = test_span {
                        self.conflict_run(*sp, t);
                    }
                    evolve_span = Some(*sp);
                    self.evolve(st, settings);
                    st.run = StageRun::Evolve(st.evolution.clone());
                }
                I::Test { lives, actions, learning, span } => {
                    if let Some(e) = evolve_span.or(test_span) {
                        self.conflict_run(*span, e);
                    }
                    test_span = Some(*span);
                    if !has_parent {
                        self.value_error(
                            *span,
                            format!(
                                "stage `{}` tests the best individual, but extends no stage",
                                decl.name.text
                            ),
                            "nothing to test",
                            Some(
                                "a `test` stage must extend the stage whose best individual it tests".into(),
                            ),
                        );
                    }
                    let n = self.count_in(actions, "the test length", 1, MAX_ACTIONS.into());
                    let k = match lives {
                        Some(q) => self.count_in(q, "the number of lives", 1, MAX_ACTIONS.into()),
                        None => Some(1),
                    };
                    if let (Some(n), Some(k)) = (n, k) {
                        if n * k > u64::from(MAX_ACTIONS) {
                            self.value_error(
                                *span,
                                format!(
                                    "{k} lives of {n} actions make {} actions in each world, more than the limit of {MAX_ACTIONS}",
                                    n * k
                                ),
                                "too long",
                                Some("this limit keeps a run within the memory and time of one machine: fewer lives or shorter ones".into()),
                            );
                        } else {
                            st.run =
                                StageRun::Test { actions: n as u32, lives: k as u32, learning: *learning };
                        }
                    }
                }
                _ => {}
            }
        }
        if evolve_span.is_none() && test_span.is_none() {
            if let StageRun::Evolve(_) = st.run {
                st.run = StageRun::Evolve(st.evolution.clone());
            }
        }
    }

    /// An evolved stage has genes of its own (frozen ones never change):
    /// the error `S0029`, labelled where it evolves. Not reported after
    /// another error of the stage (a module that failed has no genes), nor
    /// for a stage that declares roles (a role without genes is `S0024`).
    pub(super) fn check_evolved_genes(&mut self, st: &StageSt, decl: &ast::StageDecl, s: u16, since: usize) {
        if !matches!(st.run, StageRun::Evolve(_))
            || st.genes.iter().any(|g| g.stage == s)
            || (decl.extends.is_none() && decl.roles().next().is_some())
            || self.errors[since..].iter().any(|e| !e.is_warning())
        {
            return;
        }
        let own = decl.items.iter().find_map(|i| match i {
            ast::StageItem::Evolve(_, sp) => Some(*sp),
            _ => None,
        });
        let (span, label) = match (own, &decl.extends) {
            (Some(sp), _) => (sp, "evolves here".to_string()),
            (None, Some(p)) => (decl.name.span, format!("evolves, as stage `{}` does", p.text)),
            (None, None) => (decl.name.span, "evolves (it has no `test` or `train`)".to_string()),
        };
        let help = match &decl.extends {
            Some(_) if !st.roles.is_empty() => format!("a stage that extends a stage with roles keeps their genes, frozen: give it genes of its own (modules added to a role, `role {} adds {{ module ... }}`, or a new role), or make it a test stage (`test best for N actions`) to run the team in this world", st.roles.first().map_or("ROLE", |r| r.name.as_str())),
            Some(p) => format!("give it genes of its own (a new module, or new evolvable links: `link FROM -> TO evolvable`), or make it a test stage (`test best for N actions`) that runs the best of stage `{}` in this world", p.text),
            None => super::roles::EVOLVABLE_HELP.to_string(),
        };
        self.errors.push(Error::EvolvedWithoutGenes {
            span: span.into(),
            stage: decl.name.text.clone(),
            label,
            help,
        });
    }

    pub(super) fn conflict_run(&mut self, span: Span, other: Span) {
        self.errors.push(Error::Conflict {
            span: span.into(),
            other: other.into(),
            message: "a stage either evolves, tests or trains: one of them".into(),
            label: "this".into(),
            other_label: "conflicts with this".into(),
        });
    }

    pub(super) fn evolve(&mut self, st: &mut StageSt, settings: &[ast::Setting]) {
        let ev = &mut st.evolution;
        let mut keep_span = None;
        let mut population_span = None;
        for set in settings {
            let n = set.name.text.as_str();
            match (&set.value, n) {
                (ast::SettingValue::Truncation(q), _) => {
                    if let Some(k) = self.count(q, "`keep`", 1) {
                        ev.selection = Selection::Truncation { keep: k as u32 };
                        keep_span = Some(q.span);
                    }
                }
                (ast::SettingValue::WordAndNumber(w, q), _) => self.selection_with_number(w, q),
                (ast::SettingValue::Word(w), "selection") => {
                    if w.text == "roulette" {
                        ev.selection = Selection::Roulette;
                    } else {
                        self.errors.push(Error::Unknown {
                            span: w.span.into(),
                            what: "selection",
                            name: w.text.clone(),
                            help: Some("write `selection truncation keep N` or `selection roulette`".into()),
                        });
                    }
                }
                (ast::SettingValue::Word(w), "inheritance") => match w.text.as_str() {
                    "darwinian" => st.inheritance = Inheritance::Darwinian,
                    "lamarckian" => st.inheritance = Inheritance::Lamarckian,
                    _ => self.errors.push(Error::Unknown {
                        span: w.span.into(),
                        what: "inheritance",
                        name: w.text.clone(),
                        help: did_you_mean(&w.text, ["darwinian", "lamarckian"]).or_else(|| {
                            Some("write `inheritance darwinian` or `inheritance lamarckian`".into())
                        }),
                    }),
                },
                (
                    ast::SettingValue::Quantity(q),
                    "population" | "generations" | "actions" | "elitism" | "evaluations" | "seed",
                ) => {
                    let min = if n == "elitism" || n == "seed" { 0 } else { 1 };
                    let max = match n {
                        "population" => MAX_POPULATION,
                        "generations" => MAX_GENERATIONS,
                        "actions" => MAX_ACTIONS,
                        "evaluations" => MAX_EVALUATIONS,
                        _ => u32::MAX,
                    };
                    if let Some(v) = self.count_in(q, &format!("`{n}`"), min, max.into()) {
                        if n == "population" {
                            population_span = Some(q.span);
                        }
                        match n {
                            "population" => ev.population = v as u32,
                            "generations" => ev.generations = v as u32,
                            "actions" => ev.actions = v as u32,
                            "elitism" => ev.elitism = v as u32,
                            "evaluations" => ev.evaluations = v as u32,
                            _ => ev.seed = v,
                        }
                    }
                }
                (ast::SettingValue::Quantity(q), "crossover" | "mutation") => {
                    if let Some(v) = self.plain(q, &format!("`{n}`"), 0.0, 1.0) {
                        if n == "crossover" {
                            ev.crossover = v;
                        } else {
                            ev.mutation = v;
                        }
                    }
                }
                _ if EVOLVE_SETTINGS.contains(&n) => {
                    self.value_error(
                        set.span,
                        format!("`{n}` has the wrong kind of value"),
                        "wrong value",
                        Some(evolve_help(n)),
                    );
                }
                _ => self.errors.push(Error::Unknown {
                    span: set.name.span.into(),
                    what: "evolution setting",
                    name: n.to_string(),
                    help: did_you_mean(n, EVOLVE_SETTINGS).or_else(|| {
                        Some(format!("the evolution settings are {}", expr::backticked(&EVOLVE_SETTINGS)))
                    }),
                }),
            }
        }
        self.check_population(st, settings, keep_span, population_span);
    }

    /// `selection WORD N`: a number where `selection` takes none, or takes it
    /// after `keep`; an unknown selection.
    fn selection_with_number(&mut self, w: &ast::Name, q: &ast::Quantity) {
        let message = match w.text.as_str() {
            "truncation" => "`selection truncation` takes its number after `keep`".to_string(),
            "roulette" => "`selection roulette` takes no number".to_string(),
            other => {
                self.errors.push(Error::Unknown {
                    span: w.span.into(),
                    what: "selection",
                    name: other.to_string(),
                    help: did_you_mean(other, ["truncation", "roulette"])
                        .map(|d| format!("{d} {}", evolve_help("selection")))
                        .or_else(|| Some(evolve_help("selection"))),
                });
                return;
            }
        };
        self.value_error(q.span, message, "unexpected number", Some(evolve_help("selection")));
    }

    /// The default `keep` of a truncation (a fifth of the population), and
    /// `keep` and `elitism` checked against the population.
    fn check_population(
        &mut self,
        st: &mut StageSt,
        settings: &[ast::Setting],
        keep_span: Option<Span>,
        population_span: Option<Span>,
    ) {
        if keep_span.is_some() || st.evolution.selection == Selection::Roulette {
            st.keep_default = false;
        }
        // A population written here but refused: nothing to compare with.
        let population_refused = population_span.is_none()
            && settings
                .iter()
                .any(|s| s.name.text == "population" && matches!(s.value, ast::SettingValue::Quantity(_)));
        if population_span.is_some() {
            st.population_span = population_span;
        }
        let ev = &mut st.evolution;
        if st.keep_default {
            ev.selection = Selection::Truncation { keep: (ev.population / 5).max(1) };
        }
        if let (Selection::Truncation { keep }, Some(sp), false) =
            (ev.selection, keep_span, population_refused)
        {
            if keep > ev.population {
                let pop = ev.population;
                self.value_error(
                    sp,
                    format!("truncation keeps {keep} individuals of a population of {pop}"),
                    "more than the population",
                    None,
                );
            }
        }
        if ev.elitism > ev.population && !population_refused {
            let (e, p) = (ev.elitism, ev.population);
            let sp = settings.iter().find(|s| s.name.text == "elitism").map(|s| s.span).unwrap_or_default();
            self.value_error(
                sp,
                format!("elitism keeps {e} individuals of a population of {p}"),
                "more than the population",
                None,
            );
        }
    }

    /// `old + x`, a stack too deep reported at `span`.
    fn added(&mut self, old: Expr, x: Expr, span: Span) -> Expr {
        let mut ops = old.ops;
        ops.extend(x.ops);
        ops.push(Op::Add);
        let depth = Expr::required_depth(&ops).unwrap_or(old.depth.max(x.depth) + 1);
        if depth as usize > shaping_runtime::expr::MAX_STACK {
            self.errors.push(Error::StackTooDeep {
                span: span.into(),
                depth: depth as usize,
                max: shaping_runtime::expr::MAX_STACK,
            });
        }
        Expr { ops, depth }
    }

    pub(super) fn fitness(&mut self, hw: &Hw, st: &mut StageSt, f: &ast::FitnessDecl) {
        let mut per_action: Option<Expr> = if f.adds { st.fitness.per_action.clone() } else { None };
        let mut at_end: Option<Expr> = if f.adds { st.fitness.at_end.clone() } else { None };
        let mut bonuses = if f.adds { st.fitness.bonuses.clone() } else { Vec::new() };
        let scope = Scope { only: None, state: true };
        for (terms, sum) in [(&f.per_action, &mut per_action), (&f.at_end, &mut at_end)] {
            for e in terms {
                if let Some(x) = self.expr(hw, e, &scope) {
                    *sum = Some(match sum.take() {
                        None => x,
                        Some(old) => self.added(old, x, e.span),
                    });
                }
            }
        }
        self.repeated("bonus for the event", f.bonuses.iter().map(|b| (b.event.text.clone(), b.span)));
        for b in &f.bonuses {
            let event = match b.event.text.as_str() {
                "grip" => Event::Grip,
                "release outside" => Event::ReleaseOutside,
                "recharge" => Event::Recharge,
                "collision" => Event::Collision,
                other => {
                    self.errors.push(Error::Unknown {
                        span: b.event.span.into(),
                        what: "event",
                        name: other.to_string(),
                        help: did_you_mean(other, EVENTS)
                            .or_else(|| Some(format!("the events are {}", expr::backticked(&EVENTS)))),
                    });
                    continue;
                }
            };
            let needs_claw = matches!(event, Event::Grip | Event::ReleaseOutside);
            if needs_claw && !hw.actuators.iter().any(|a| a.kind == ActuatorKind::Grip) {
                self.errors.push(Error::MissingHardware {
                    span: b.event.span.into(),
                    stage: hw.stage.clone(),
                    what: "actuator of kind",
                    name: "grip".into(),
                    help: Some(
                        "objects are gripped and released by a `grip` actuator (`actuator claw grip`)".into(),
                    ),
                });
            }
            if event == Event::Recharge && !hw.has_charger {
                self.errors.push(Error::MissingHardware {
                    span: b.event.span.into(),
                    stage: hw.stage.clone(),
                    what: "world item",
                    name: "charger".into(),
                    help: Some("declare `charger LENGTH on WALL wall` or a `zone ... charger` in the stage's `world`".into()),
                });
            }
            if !b.points.is_finite() {
                self.value_error(b.span, "bonus points must be a finite number".into(), "not finite", None);
            }
            bonuses.push(Bonus { event, points: b.points as f32 });
        }
        // `fitness adds` keeps the inherited team aggregate; a fitness that
        // replaces the inherited one starts from `mean`.
        let mut team = if f.adds { st.fitness.team } else { Aggregate::Mean };
        self.repeated("fitness clause", f.team.iter().map(|(_, sp)| ("team".to_string(), *sp)));
        if let Some((w, _)) = f.team.first() {
            match w.text.as_str() {
                "sum" => team = Aggregate::Sum,
                "mean" => team = Aggregate::Mean,
                "min" => team = Aggregate::Min,
                other => self.errors.push(Error::Unknown {
                    span: w.span.into(),
                    what: "aggregation of a team",
                    name: other.into(),
                    help: did_you_mean(other, TEAM_AGGREGATES).or_else(|| {
                        Some("`team sum`, `team mean` or `team min`: the sum, the mean or the lowest of the robots' fitness".into())
                    }),
                }),
            }
        }
        st.fitness = Fitness { per_action, at_end, bonuses, team };
        st.fitness_declared = true;
    }
}

impl Lower<'_> {
    /// A `team` clause written in a stage whose world (and every variant's)
    /// has one robot: a warning, it has no effect.
    pub(super) fn check_team_clause(&mut self, stage: &Stage, decl: &ast::StageDecl) {
        let variants = stage.variants.iter().flat_map(|v| &v.list);
        if stage.world.robots > 1 || variants.clone().any(|v| v.world.robots > 1) {
            return;
        }
        for item in &decl.items {
            if let ast::StageItem::Fitness(f) = item {
                for (_, span) in &f.team {
                    self.errors.push(Error::TeamOfOne {
                        span: (*span).into(),
                        stage: stage.name.clone(),
                        what: "combines a team's fitness".into(),
                        label: "no effect with one robot".into(),
                        help: Some(
                            "`team` says how the fitness of several robots makes the team's: declare `robots N` in the stage's `world`, or remove the clause".into(),
                        ),
                    });
                }
                let mut reads = Vec::new();
                for e in f.per_action.iter().chain(&f.at_end) {
                    team_reads(e, &mut reads);
                }
                for (field, span) in reads {
                    // The value `team.FIELD` has for one robot (see `TEAM_FIELDS`).
                    let value = match field.as_str() {
                        "spread" | "grouped" | "nearest" => "0",
                        "largest" | "order" | "connected" => "1",
                        _ => continue,
                    };
                    self.errors.push(Error::TeamOfOne {
                        span: span.into(),
                        stage: stage.name.clone(),
                        what: format!("reads `team.{field}`"),
                        label: format!("always {value} with one robot"),
                        help: Some(format!(
                            "`team.{field}` measures a team of several robots: declare `robots N` in the stage's `world` (or a variant's), or read the robot's own state (`robot.x`, `robot.distance`, ...)"
                        )),
                    });
                }
            }
        }
    }
}

/// The fields of `team.FIELD` an expression reads, where.
fn team_reads(e: &ast::Expr, out: &mut Vec<(String, Span)>) {
    use ast::ExprKind as K;
    match &e.kind {
        K::Team(field) => out.push((field.text.clone(), e.span)),
        K::Number(..) | K::Ref(..) | K::State(_) => {}
        K::Call(_, args) => args.iter().for_each(|a| team_reads(a, out)),
        K::Unary(_, a) => team_reads(a, out),
        K::Binary(_, a, b) => {
            team_reads(a, out);
            team_reads(b, out);
        }
        K::Cond(c, a, b) => {
            team_reads(c, out);
            team_reads(a, out);
            team_reads(b, out);
        }
    }
}

/// The words of `team WORD` in a fitness.
pub(crate) const TEAM_AGGREGATES: [&str; 3] = ["sum", "mean", "min"];

pub(super) fn evolve_help(n: &str) -> String {
    match n {
        "selection" => "write `selection truncation keep N` or `selection roulette`".into(),
        "inheritance" => "write `inheritance darwinian` or `inheritance lamarckian`".into(),
        "crossover" | "mutation" => format!("`{n}` is a probability, e.g. `{n} 0.1`"),
        _ => format!("`{n}` is a whole number, e.g. `{n} 100`"),
    }
}
