//! Modules: inputs, activation networks, behaviors, learning, reinforcement.

use shaping_runtime::catalog::{self, ActuatorKind};
use shaping_runtime::limits::{MAX_HIDDEN, MAX_WINDOW};
use shaping_runtime::program::*;

use super::{expr::Scope, Hw, Lower, ModuleSt, Shape, Source, TrainedShape, DEFAULT_RATES, DEFAULT_WINDOW};
use crate::diag::{did_you_mean, Error};
use crate::syntax::ast::{self, ActionDecl, EndDecl, ModuleItem, Motion};
use crate::syntax::Span;

/// The words that start an action (`turn toward(...)` starts with `turn`).
pub(crate) const ACTIONS: [&str; 8] =
    ["forward", "back", "turn", "stop", "toward", "wait", "recharge", "reinforce"];

impl Lower<'_> {
    /// Declares a new module, or changes an inherited one.
    pub(super) fn module(&mut self, hw: &Hw, modules: &mut Vec<ModuleSt>, m: &ast::ModuleDecl, s: u16) {
        self.repeated_clauses(m);
        let existing = modules.iter().position(|x| x.name == m.name.text);
        let mut st = match existing {
            Some(i) => modules[i].clone(),
            None => new_module(m, s),
        };
        let inherited = existing.is_some();
        let by = self.stage_names[st.stage as usize].clone();
        // `activation trained STAGE`: the name and where the source was written.
        let mut trained_at = None;
        // Inputs and activation network: frozen once evolved.
        for item in &m.items {
            match item {
                ModuleItem::Sense(refs, span) => {
                    let Some(channels) = self.sensed(hw, refs) else { continue };
                    if inherited {
                        if channels != st.inputs {
                            self.errors.push(Error::Frozen {
                                span: (*span).into(),
                                frozen: st.inputs_span.unwrap_or(st.span).into(),
                                stage: hw.stage.clone(),
                                by: by.clone(),
                                what: format!("the inputs of module `{}`", st.name),
                            });
                        }
                        continue;
                    }
                    st.inputs = channels;
                    st.inputs_span = Some(*span);
                }
                ModuleItem::Activation(a) => {
                    let Some((hidden, source)) = self.activation(a) else { continue };
                    let recurrent = a.recurrent && hidden > 0;
                    if inherited {
                        if hidden != st.hidden || recurrent != st.recurrent || source != st.source {
                            self.errors.push(Error::Frozen {
                                span: a.span.into(),
                                frozen: st.act_span.unwrap_or(st.span).into(),
                                stage: hw.stage.clone(),
                                by: by.clone(),
                                what: format!("the activation network of module `{}`", st.name),
                            });
                        }
                        continue;
                    }
                    st.hidden = hidden;
                    st.recurrent = recurrent;
                    st.source = source;
                    if let Some(ast::WeightSource::Trained(name, sp)) = &a.source {
                        trained_at = Some((name.clone(), *sp));
                    }
                    st.act_span = Some(a.span);
                }
                _ => {}
            }
        }
        if !inherited {
            st.act_params = self.activation_params(&st, trained_at);
        }
        self.module_behavior(hw, &mut st, m, s);
        if st.behavior.is_none() && !m.items.iter().any(|i| matches!(i, ModuleItem::Behavior(_))) {
            self.value_error(
                m.name.span,
                format!("module `{}` has no behavior", m.name.text),
                "no `behavior` clause",
                Some("add `behavior STEP`, `behavior script { ... }` or `behavior neural { ... }`".into()),
            );
        }
        match existing {
            Some(i) => modules[i] = st,
            None => modules.push(st),
        }
    }

    /// The parameters of a new module's activation network: none for
    /// evolvable weights (genes, allocated with the stage), else its fixed,
    /// random or trained weights.
    fn activation_params(&mut self, st: &ModuleSt, trained_at: Option<(ast::Name, Span)>) -> Vec<Param> {
        match &st.source {
            Source::Evolvable(_) => Vec::new(), // genes, allocated with the stage
            Source::Fixed(vals) => {
                let n = Network::param_count_of(st.inputs.len(), st.hidden as usize, 1, st.recurrent);
                self.fixed_params(vals, n, st.act_span.unwrap_or(st.span))
            }
            Source::Random(lo, hi) => {
                let n = Network::param_count_of(st.inputs.len(), st.hidden as usize, 1, st.recurrent);
                vec![Param::Random { lo: *lo, hi: *hi }; n]
            }
            Source::Trained(_) => {
                let shape = (st.inputs.len() as u16, st.hidden, 1, st.recurrent);
                trained_at
                    .and_then(|(name, sp)| self.trained_params(&name, sp, &st.name, shape, Part::Activation))
                    .unwrap_or_default()
            }
        }
    }

    /// A module's clauses given twice (each reported).
    fn repeated_clauses(&mut self, m: &ast::ModuleDecl) {
        let mut seen: std::collections::HashMap<&str, &ModuleItem> = std::collections::HashMap::new();
        for item in &m.items {
            if let Some(first) = seen.get(item.keyword()).copied() {
                self.errors.push(Error::Duplicate {
                    span: item.span().into(),
                    first: first.span().into(),
                    what: "clause",
                    name: item.keyword().into(),
                });
            } else {
                seen.insert(item.keyword(), item);
            }
        }
    }

    /// A module's behavior, learning and reinforcement: what a later stage
    /// may change.
    fn module_behavior(&mut self, hw: &Hw, st: &mut ModuleSt, m: &ast::ModuleDecl, s: u16) {
        let sense_span = st.inputs_span;
        let inputs = st.inputs.clone();
        for item in &m.items {
            match item {
                ModuleItem::Behavior(b) => {
                    st.behavior_stage = s;
                    st.behavior_genes = None;
                    st.script_reinforces = false;
                    st.behavior = match b {
                        ast::BehaviorDecl::Script(steps, commit, _) => {
                            let scope =
                                Scope { only: Some((&m.name.text, &inputs, sense_span)), state: false };
                            let lowered: Vec<Step> =
                                steps.iter().filter_map(|x| self.step(hw, x, &scope)).collect();
                            st.script_reinforces =
                                steps.iter().any(|x| matches!(x.action, ast::ActionDecl::Reinforce(..)));
                            Some(Behavior::Script(Script { steps: lowered, commit: *commit }))
                        }
                        ast::BehaviorDecl::Neural(n) => {
                            let (nb, genes) = self.neural(hw, n, &inputs, &m.name.text);
                            st.behavior_genes = genes;
                            nb.map(Behavior::Neural)
                        }
                    };
                }
                ModuleItem::Learn(l) => {
                    st.learning = self.learn(l);
                    st.learn_span = Some(l.span);
                }
                ModuleItem::Reinforce(e, _) => {
                    let scope = Scope { only: Some((&m.name.text, &inputs, sense_span)), state: false };
                    st.reinforce = self.expr(hw, e, &scope);
                    st.reinforce_declared = true;
                }
                _ => {}
            }
        }
    }

    /// Checks that concern the whole module.
    pub(super) fn check_module(&mut self, m: &ModuleSt) {
        if let (Some(l), Some(span)) = (&m.learning, m.learn_span) {
            if !m.reinforce_declared && !m.script_reinforces {
                self.value_error(
                    span,
                    format!("module `{}` learns but has no reinforcement program", m.name),
                    "learning needs reinforcement",
                    Some("add `reinforce EXPR` to the module, or a `reinforce` step to its script".into()),
                );
            }
            if l.target == LearnTarget::Behavior && !matches!(m.behavior, Some(Behavior::Neural(_)) | None) {
                self.value_error(
                    span,
                    format!("module `{}` learns on its behavior, which is a script", m.name),
                    "CRBP needs a network",
                    Some("learn `on activation`, or give the module a `behavior neural { ... }`".into()),
                );
            }
        }
    }

    /// Resolves the inputs of a `sense` clause, `ir, light[0..3]`, to percept
    /// channels: each at most once (`sense ir, ir` would silently give the
    /// network every input twice).
    fn sensed(&mut self, hw: &Hw, refs: &[ast::SensorRef]) -> Option<Vec<u16>> {
        let mut first: Vec<(u16, Span)> = Vec::new();
        let mut ok = true;
        for r in refs {
            let Some(channels) = self.sensor_refs(hw, std::slice::from_ref(r)) else {
                ok = false;
                continue;
            };
            if let Some(&(_, at)) = channels.iter().find_map(|c| first.iter().find(|(f, _)| f == c)) {
                let again: Vec<u16> =
                    channels.iter().copied().filter(|c| first.iter().any(|(f, _)| f == c)).collect();
                let name = hw
                    .sensors
                    .iter()
                    .find(|s| s.channel <= again[0] && again[0] < s.channel + s.count)
                    .map(|s| s.elements_text(&again))
                    .unwrap_or_default();
                self.errors.push(Error::Conflict {
                    span: r.span.into(),
                    other: at.into(),
                    message: format!("`{name}` is sensed twice: a `sense` list names each input once"),
                    label: "sensed again here".into(),
                    other_label: "first sensed here".into(),
                });
                ok = false;
                continue;
            }
            first.extend(channels.into_iter().map(|c| (c, r.span)));
        }
        ok.then(|| first.into_iter().map(|(c, _)| c).collect())
    }

    /// Resolves `ir, light[0..3]` to percept channels.
    fn sensor_refs(&mut self, hw: &Hw, refs: &[ast::SensorRef]) -> Option<Vec<u16>> {
        let mut channels = Vec::new();
        let mut ok = true;
        for r in refs {
            match hw.sensors.iter().find(|x| x.name == r.name.text) {
                Some(sensor) => match self.elements(&sensor.name, sensor.count as usize, r.index.as_ref()) {
                    Some((a, b)) => channels.extend((a..=b).map(|i| sensor.channel + i as u16)),
                    None => ok = false,
                },
                None => {
                    if hw.actuators.iter().any(|a| a.name == r.name.text) {
                        self.value_error(
                            r.span,
                            format!("`{}` is an actuator, not a sensor", r.name.text),
                            "not a sensor",
                            None,
                        );
                    } else {
                        self.unknown_hardware(hw, "sensor", &r.name);
                    }
                    ok = false;
                }
            }
        }
        ok.then_some(channels)
    }

    fn activation(&mut self, a: &ast::ActivationDecl) -> Option<(u16, Source)> {
        let hidden = match &a.hidden {
            Some(q) => self.count_in(q, "the number of hidden units", 0, MAX_HIDDEN.into())? as u16,
            None => 0,
        };
        let range = match &a.range {
            Some(r) => Some(self.range(r)?),
            None => None,
        };
        let source = match &a.source {
            None | Some(ast::WeightSource::Evolvable(_)) => Source::Evolvable(range),
            Some(ast::WeightSource::Fixed(v, _)) => Source::Fixed(v.iter().map(|x| *x as f32).collect()),
            Some(ast::WeightSource::Random(r, _)) => {
                let (lo, hi) = self.range(r)?;
                Source::Random(lo, hi)
            }
            Some(ast::WeightSource::Trained(by, _)) => Source::Trained(by.text.clone()),
        };
        if range.is_some() && !matches!(source, Source::Evolvable(_)) {
            self.value_error(
                a.span,
                "only evolvable weights have a gene `range`".into(),
                "range without genes",
                None,
            );
        }
        Some((hidden, source))
    }

    fn fixed_params(&mut self, vals: &[f32], n: usize, span: Span) -> Vec<Param> {
        if vals.len() == 1 {
            return vec![Param::Fixed(vals[0]); n];
        }
        if vals.len() != n {
            self.value_error(
                span,
                format!("the network has {n} parameters, but {} fixed values are given", vals.len()),
                "wrong number of values",
                Some(
                    "give one value for all parameters, or one per parameter in the order bias, weights"
                        .into(),
                ),
            );
        }
        vals.iter().map(|v| Param::Fixed(*v)).collect()
    }

    fn speed(&mut self, v: Option<f64>, span: Span) -> f32 {
        let v = v.unwrap_or(1.0);
        if !(-1.0..=1.0).contains(&v) {
            self.value_error(
                span,
                format!("a speed is between -1 and 1 (of `v_max`), not {v}"),
                "speed out of range",
                None,
            );
        }
        v as f32
    }

    fn has_wheels(&mut self, hw: &Hw, span: Span) -> bool {
        if hw.actuators.iter().any(|a| a.kind == ActuatorKind::Speed) {
            return true;
        }
        if self.no_robot(span) {
            return false;
        }
        self.errors.push(Error::MissingHardware {
            span: span.into(),
            stage: hw.stage.clone(),
            what: "actuator of kind",
            name: "speed".into(),
            help: Some("declare the wheels: `actuator wheels[2] speed`".into()),
        });
        false
    }

    /// Reports `arm down` or `claw closed` when the robot has no actuator of
    /// that name, and the state is one of an actuator kind's (`down`, of a
    /// `lift`): the actuator to declare. False when it is not such a case.
    fn missing_gripper(&mut self, hw: &Hw, name: &ast::Name, state: Option<&ast::Name>) -> bool {
        if self.poisoned.contains(&name.text) || self.hw_origin.contains_key(&name.text) {
            return false;
        }
        let Some(state) = state else { return false };
        let Some(info) = catalog::ACTUATORS.iter().find(|a| a.states.contains(&state.text.as_str())) else {
            return false;
        };
        if self.no_robot(name.span) {
            return true;
        }
        let declared = hw.actuators.iter().find(|a| a.kind == info.kind);
        let help = match declared {
            Some(a) => format!(
                "the robot's `{}` actuator is `{}`: write `{} {}`",
                info.keyword, a.name, a.name, state.text
            ),
            None => format!(
                "declare `actuator {} {}` in the robot, or in this stage's `robot adds`",
                name.text, info.keyword
            ),
        };
        self.errors.push(Error::MissingHardware {
            span: name.span.into(),
            stage: hw.stage.clone(),
            what: "actuator",
            name: name.text.clone(),
            help: Some(help),
        });
        true
    }

    /// Reports a name in the place of an action that is neither an action
    /// nor an actuator of the stage (`forwrd(1.0)`, `forwrd`, `turm left`).
    fn unknown_action(&mut self, hw: &Hw, name: &ast::Name) {
        if self.poisoned.contains(&name.text) || self.hw_origin.contains_key(&name.text) {
            return self.unknown_hardware(hw, "actuator", name);
        }
        let actuators = hw.actuators.iter().map(|a| a.name.as_str());
        let turn = match name.text.as_str() {
            "left" | "right" => Some(format!("write `turn {}`", name.text)),
            "turn" => Some("`turn` needs a direction: `turn left` or `turn right`".to_string()),
            _ => None,
        };
        self.errors.push(Error::Unknown {
            span: name.span.into(),
            what: "action",
            name: name.text.clone(),
            help: turn.or_else(|| did_you_mean(&name.text, ACTIONS.into_iter().chain(actuators))).or_else(|| {
                Some(format!(
                    "the actions are {}, and an actuator's name with a state or speeds (`arm down`, `wheels(0.5, 0.5)`)",
                    super::expr::backticked(&ACTIONS)
                ))
            }),
        });
    }

    fn motion(&mut self, hw: &Hw, m: &Motion, span: Span) -> Option<[f32; 2]> {
        if let Motion::Wheels(name, _) = m {
            if !hw.actuators.iter().any(|a| a.name == name.text) {
                self.unknown_action(hw, name);
                return None;
            }
        }
        if !self.has_wheels(hw, span) {
            return None;
        }
        Some(match m {
            Motion::Forward(v) => {
                let v = self.speed(*v, span);
                [v, v]
            }
            Motion::Back(v) => {
                let v = self.speed(*v, span);
                [-v, -v]
            }
            Motion::TurnLeft(v) => {
                let v = self.speed(*v, span);
                [-v, v]
            }
            Motion::TurnRight(v) => {
                let v = self.speed(*v, span);
                [v, -v]
            }
            Motion::Stop => [0.0, 0.0],
            Motion::Wheels(name, speeds) => {
                match hw.actuators.iter().find(|a| a.name == name.text) {
                    Some(a) if a.kind == ActuatorKind::Speed => {}
                    Some(a) => {
                        self.value_error(
                            span,
                            format!("`{}` is not a `speed` actuator", a.name),
                            "takes a state, not speeds",
                            Some(format!(
                                "write `{} {}`",
                                a.name,
                                catalog::actuator_info(a.kind).states.first().copied().unwrap_or("?")
                            )),
                        );
                        return None;
                    }
                    None => return None,
                }
                let &[l, r] = &speeds[..] else {
                    self.value_error(
                        span,
                        format!("`{}(LEFT, RIGHT)` takes two speeds, not {}", name.text, speeds.len()),
                        "two speeds",
                        Some(format!("write `{}(0.5, -0.5)`, or `forward(0.5)`", name.text)),
                    );
                    return None;
                };
                [self.speed(Some(l), span), self.speed(Some(r), span)]
            }
        })
    }

    /// `signal(1, 0)`: every value of the broadcast actuator `name`, each
    /// 0..1; it takes no time, so it has no `for` or `until`.
    fn signal_step(
        &mut self,
        hw: &Hw,
        name: &ast::Name,
        values: &[f64],
        span: Span,
        timed: bool,
    ) -> Option<Action> {
        let a = hw.actuators.iter().find(|a| a.name == name.text)?;
        let mut ok = true;
        if values.len() != a.count as usize {
            self.errors.push(Error::SignalValues {
                span: span.into(),
                message: format!(
                    "`{}` broadcasts {} value{}, and this step gives {}",
                    a.name,
                    a.count,
                    if a.count == 1 { "" } else { "s" },
                    values.len()
                ),
                help: format!("give every value: `{}({})`", a.name, vec!["1"; a.count as usize].join(", ")),
            });
            ok = false;
        }
        if let Some(v) = values.iter().find(|v| !(0.0..=1.0).contains(*v)) {
            self.errors.push(Error::SignalValues {
                span: span.into(),
                message: format!("a broadcast value is 0 to 1, not {v}"),
                help: "a neighbour reads the value as it is sent: 0 silent .. 1 loudest".into(),
            });
            ok = false;
        }
        if timed {
            self.value_error(
                span,
                format!("`{}(...)` takes no time, so it cannot last `for` or `until`", a.name),
                "instant step",
                Some("put the duration on the step after it: the values stay until set again".into()),
            );
            ok = false;
        }
        ok.then(|| Action::Signal(values.iter().map(|&v| v as f32).collect()))
    }

    fn step(&mut self, hw: &Hw, x: &ast::StepDecl, scope: &Scope) -> Option<Step> {
        let span = x.action.span();
        let action = match &x.action {
            ActionDecl::Motion(Motion::Wheels(name, values), sp)
                if hw.actuators.iter().any(|a| a.name == name.text && a.kind == ActuatorKind::Broadcast) =>
            {
                self.signal_step(hw, name, values, *sp, x.end.is_some())?
            }
            ActionDecl::Motion(m, sp) => {
                let [left, right] = self.motion(hw, m, *sp)?;
                Action::Wheels { left, right }
            }
            ActionDecl::Toward { refs, speed, span } => self.toward(hw, refs, *speed, *span)?,
            ActionDecl::Wait(_) => Action::Wait { charge: x.uses_charger.is_some() },
            ActionDecl::Recharge(_) => Action::Wait { charge: true },
            ActionDecl::Reinforce(e, sp) => {
                if x.end.is_some() {
                    self.value_error(
                        *sp,
                        "`reinforce` takes no time, so it cannot last `for` or `until`".into(),
                        "instant step",
                        Some("put the duration on the step before it".into()),
                    );
                }
                Action::Reinforce(self.expr(hw, e, scope)?)
            }
            ActionDecl::Set { actuator, state, span } => {
                self.set_actuator(hw, actuator, state.as_ref(), *span)?
            }
        };
        if let Some(sp) = x.uses_charger {
            if !matches!(x.action, ActionDecl::Wait(_)) {
                self.value_error(
                    sp,
                    "only `wait` can use the charger".into(),
                    "not a `wait` step",
                    Some("write `wait ... uses charger` or `recharge`".into()),
                );
            }
        }
        if matches!(action, Action::Wait { charge: true }) && !hw.has_charger {
            self.errors.push(Error::MissingHardware {
                span: x.uses_charger.unwrap_or(span).into(),
                stage: hw.stage.clone(),
                what: "world item",
                name: "charger".into(),
                help: Some(
                    "declare `charger LENGTH on WALL wall` or a `zone ... charger` in the stage's `world`"
                        .into(),
                ),
            });
        }
        // Lowered first, so its errors are reported even when `end` fails.
        let when = x.cond.as_ref().map(|c| self.expr(hw, c, &Scope { only: None, state: false }));
        let end = match &x.end {
            None => StepEnd::Actions(1),
            Some(EndDecl::For(q)) => StepEnd::Actions(self.count(q, "a step's duration", 1)? as u32),
            Some(EndDecl::Until { cond, within, span }) => {
                let cond = self.expr(hw, cond, &Scope { only: None, state: false });
                let Some(w) = within else {
                    self.errors.push(Error::UnboundedUntil { span: (*span).into() });
                    return None;
                };
                let within = self.count(w, "the bound of `until`", 1)? as u32;
                StepEnd::Until { cond: cond?, within }
            }
        };
        let when = match when {
            Some(c) => Some(c?),
            None => None,
        };
        Some(Step { action, end, when })
    }

    /// `toward(SENSORS)`: steering toward sensors that have a direction.
    fn toward(&mut self, hw: &Hw, refs: &[ast::SensorRef], speed: Option<f64>, span: Span) -> Option<Action> {
        self.has_wheels(hw, span);
        let channels = self.sensor_refs(hw, refs)?;
        if let Some(c) = channels.iter().find(|c| catalog::channel_bearing(**c as usize).is_none()) {
            let name = hw
                .sensors
                .iter()
                .find(|s| s.channel <= *c && *c < s.channel + s.count)
                .map(|s| s.name.clone())
                .unwrap_or_default();
            self.value_error(
                span,
                format!("`toward` needs sensors with a direction, and `{name}` has none"),
                "no direction",
                Some("steer toward proximity or ambient sensors, e.g. `toward(light)`".into()),
            );
            return None;
        }
        let speed = self.speed(speed, span);
        Some(Action::Toward { channels, speed })
    }

    /// `ACTUATOR STATE`: the gripper's lift or claw set to one of its states.
    fn set_actuator(
        &mut self,
        hw: &Hw,
        actuator: &ast::Name,
        state: Option<&ast::Name>,
        span: Span,
    ) -> Option<Action> {
        let Some(a) = hw.actuators.iter().find(|a| a.name == actuator.text) else {
            if hw.sensors.iter().any(|s| s.name == actuator.text) {
                self.value_error(
                    actuator.span,
                    format!("`{}` is a sensor, not an actuator", actuator.text),
                    "not an actuator",
                    None,
                );
            } else if !self.missing_gripper(hw, actuator, state) {
                self.unknown_action(hw, actuator);
            }
            return None;
        };
        let info = catalog::actuator_info(a.kind);
        if info.states.is_empty() {
            self.value_error(
                span,
                format!("`{}` takes speeds, not a state", a.name),
                "no states",
                Some(format!("write `{}(0.5, 0.5)` or `forward`", a.name)),
            );
            return None;
        }
        let Some(state) = state else {
            self.value_error(
                span,
                format!("`{}` needs a state: `{}`", a.name, info.states.join("` or `")),
                "no state",
                Some(format!("write `{} {}`", a.name, info.states[0])),
            );
            return None;
        };
        let Some(i) = info.states.iter().position(|s| *s == state.text) else {
            self.errors.push(Error::Unknown {
                span: state.span.into(),
                what: "state",
                name: state.text.clone(),
                help: did_you_mean(&state.text, info.states.iter().copied())
                    .or_else(|| Some(format!("`{}` is {}", a.name, info.states.join(" or ")))),
            });
            return None;
        };
        Some(match a.kind {
            ActuatorKind::Lift => Action::Arm(i == 1),
            _ => Action::Claw(i == 1),
        })
    }

    /// A neural behavior; also gives the gene range when its weights evolve.
    fn neural(
        &mut self,
        hw: &Hw,
        n: &ast::NeuralDecl,
        module_inputs: &[u16],
        module: &str,
    ) -> (Option<NeuralBehavior>, Option<Option<(f32, f32)>>) {
        let inputs = match &n.sense {
            Some((refs, _)) => match self.sensed(hw, refs) {
                Some(c) => c,
                None => return (None, None),
            },
            None => module_inputs.to_vec(),
        };
        let hidden = match &n.hidden {
            Some(q) => match self.count_in(q, "the number of hidden units", 0, MAX_HIDDEN.into()) {
                Some(h) => h as u16,
                None => return (None, None),
            },
            None => 0,
        };
        let Some((wheels, decode)) = self.outputs(hw, n) else { return (None, None) };
        let signals = match &n.broadcast {
            Some(name) => match self.broadcast_outputs(hw, name) {
                Some(k) => k,
                None => return (None, None),
            },
            None => 0,
        };
        let outputs = wheels + signals;
        let recurrent = n.recurrent && hidden > 0;
        let count = Network::param_count_of(inputs.len(), hidden as usize, outputs as usize, recurrent);
        let (params, genes) = match &n.weights {
            None => (vec![Param::Random { lo: -1.0, hi: 1.0 }; count], None),
            Some(ast::WeightSource::Random(r, _)) => match self.range(r) {
                Some((lo, hi)) => (vec![Param::Random { lo, hi }; count], None),
                None => return (None, None),
            },
            Some(ast::WeightSource::Fixed(v, sp)) => {
                let vals: Vec<f32> = v.iter().map(|x| *x as f32).collect();
                (self.fixed_params(&vals, count, *sp), None)
            }
            Some(ast::WeightSource::Evolvable(_)) => (Vec::new(), Some(None)),
            Some(ast::WeightSource::Trained(by, sp)) => {
                let shape = (inputs.len() as u16, hidden, outputs, recurrent);
                match self.trained_params(by, *sp, module, shape, Part::Behavior) {
                    Some(p) => (p, None),
                    None => return (None, None),
                }
            }
        };
        let net = Network { inputs: inputs.len() as u16, hidden, outputs, recurrent, params };
        (Some(NeuralBehavior { inputs, net, decode, signals }), genes)
    }

    /// `broadcast NAME` in a neural behavior: one output per value of the
    /// `broadcast` actuator NAME.
    fn broadcast_outputs(&mut self, hw: &Hw, name: &ast::Name) -> Option<u16> {
        match hw.actuators.iter().find(|a| a.name == name.text) {
            Some(a) if a.kind == ActuatorKind::Broadcast => Some(a.count),
            Some(a) => {
                let broadcast = hw.actuators.iter().find(|a| a.kind == ActuatorKind::Broadcast);
                self.value_error(
                    name.span,
                    format!(
                        "`{}` is a `{}` actuator, not a `broadcast`",
                        a.name,
                        catalog::actuator_info(a.kind).keyword
                    ),
                    "not a broadcast",
                    Some(match broadcast {
                        Some(b) => {
                            format!("the robot broadcasts with `{}`: write `broadcast {}`", b.name, b.name)
                        }
                        None => "declare one in the robot: `actuator signal broadcast`".into(),
                    }),
                );
                None
            }
            None if hw.sensors.iter().any(|s| s.name == name.text) => {
                self.value_error(
                    name.span,
                    format!("`{}` is a sensor, not an actuator", name.text),
                    "not an actuator",
                    Some("`broadcast NAME` names a `broadcast` actuator of the robot".into()),
                );
                None
            }
            None => {
                self.unknown_hardware(hw, "actuator", name);
                None
            }
        }
    }

    /// A neural behavior's outputs and how they decode into wheel speeds:
    /// `linear`, or `sign(N)` and its table of motions.
    fn outputs(&mut self, hw: &Hw, n: &ast::NeuralDecl) -> Option<(u16, Decode)> {
        match &n.outputs {
            None => {
                self.value_error(
                    n.span,
                    "a neural behavior needs `outputs`".into(),
                    "no `outputs`",
                    Some("e.g. `outputs sign(2) -> forward | right | left | back`".into()),
                );
                None
            }
            Some(ast::OutputsDecl::Linear { scale, span }) => {
                let scale = scale.unwrap_or(1.0);
                // Checked as the runtime will hold it: `1e-46` is 0 in f32.
                if !(scale as f32 > 0.0 && scale <= 1.0) {
                    self.value_error(
                        *span,
                        format!("the scale is between 0 and 1, not {scale}"),
                        "out of range",
                        None,
                    );
                }
                if !self.has_wheels(hw, *span) {
                    return None;
                }
                Some((2u16, Decode::Linear { scale: scale as f32 }))
            }
            Some(ast::OutputsDecl::Sign { count, table, span }) => {
                let k = self.count(count, "the number of outputs", 1)?;
                if k > 4 {
                    self.value_error(
                        count.span,
                        format!("a sign decoding has 1 to 4 outputs, not {k}"),
                        "too many outputs",
                        None,
                    );
                    return None;
                }
                let want = 1usize << k;
                if table.len() != want {
                    self.value_error(
                        *span,
                        format!("{k} sign outputs select among {want} motions, but {} are listed", table.len()),
                        "wrong number of motions",
                        Some("list one motion per sign pattern, from all outputs positive down to all negative".into()),
                    );
                    return None;
                }
                let mut rows = Vec::with_capacity(want);
                for (m, sp) in table {
                    rows.push(self.motion(hw, m, *sp).unwrap_or([0.0, 0.0]));
                }
                // Listed from all outputs on (bits 11..1) down to all off (00..0).
                rows.reverse();
                Some((k as u16, Decode::Table(rows)))
            }
        }
    }

    /// `weights trained STAGE` (`part` behavior) or `activation trained
    /// STAGE`: the weights module `module` of the training stage `STAGE`
    /// learned for that network, which must have the same shape.
    fn trained_params(
        &mut self,
        by: &ast::Name,
        span: Span,
        module: &str,
        shape: Shape,
        part: Part,
    ) -> Option<Vec<Param>> {
        let Some((stage, modules)) = self.trained.get(&by.text) else {
            self.untrained(by);
            return None;
        };
        let stage = *stage;
        let Some((m, (_, behavior, activation))) =
            modules.iter().enumerate().find(|(_, (n, ..))| n == module)
        else {
            self.value_error(
                by.span,
                format!("training stage `{}` has no module `{module}`", by.text),
                "no such module there",
                Some("weights are trained by the module of the same name".into()),
            );
            return None;
        };
        let what = match (part, *behavior) {
            (Part::Activation, _) if *activation == shape => None,
            (Part::Activation, _) => Some(format!(
                "an activation network of {}, but this one has {}",
                activation_shape(*activation),
                activation_shape(shape)
            )),
            (Part::Behavior, TrainedShape::Network(s)) if s == shape => None,
            (Part::Behavior, TrainedShape::Failed) => return None,
            (Part::Behavior, found) => {
                let found = match found {
                    TrainedShape::Network((i, h, o, r)) => {
                        format!("{i} inputs, {h} {}hidden and {o} outputs", recurrent_word(r))
                    }
                    _ => "a scripted behavior".to_string(),
                };
                Some(format!(
                    "{found}, but this network has {} inputs, {} {}hidden and {} outputs",
                    shape.0,
                    shape.1,
                    recurrent_word(shape.3),
                    shape.2
                ))
            }
        };
        if let Some(what) = what {
            self.value_error(
                span,
                format!("module `{module}` of `{}` has {what}", by.text),
                "another shape",
                Some(match part {
                    Part::Behavior => {
                        "sense the same inputs and declare the same `hidden` and `outputs`".into()
                    }
                    Part::Activation => "sense the same inputs and declare the same `hidden`".into(),
                }),
            );
            return None;
        }
        let count =
            Network::param_count_of(shape.0 as usize, shape.1 as usize, shape.2 as usize, shape.3) as u32;
        Some((0..count).map(|index| Param::Trained { stage, module: m as u16, index, part }).collect())
    }

    /// Reports `weights trained STAGE` where `STAGE` has trained nothing
    /// before this stage: it is no stage, no training stage, this stage, or
    /// a training stage that uses this one's weights in turn. A training
    /// stage whose own declaration failed was reported already.
    fn untrained(&mut self, by: &ast::Name) {
        let file = self.file;
        let is_training =
            |s: &ast::StageDecl| s.items.iter().any(|i| matches!(i, ast::StageItem::Train { .. }));
        let Some(decl) = file.stages.iter().find(|s| s.name.text == by.text) else {
            let training = file.stages.iter().filter(|s| is_training(s)).map(|s| s.name.text.as_str());
            self.errors.push(Error::Unknown {
                span: by.span.into(),
                what: "training stage",
                name: by.text.clone(),
                help: did_you_mean(&by.text, training)
                    .or_else(|| Some("name a training stage (`train for N actions`)".into())),
            });
            return;
        };
        let current = self.stage_names.last().map(String::as_str);
        let (message, label, other_label) = if !is_training(decl) {
            (
                format!("stage `{}` is not a training stage: it trains no weights", by.text),
                "not a training stage",
                "declared here without `train for N actions`",
            )
        } else if current == Some(by.text.as_str()) {
            (format!("stage `{}` uses the weights it trains itself", by.text), "this stage", "declared here")
        } else if self.stage_names.contains(&by.text) {
            return;
        } else {
            (
                format!(
                    "training stage `{}` and this stage use each other's trained weights: neither can train first",
                    by.text
                ),
                "used before it is trained",
                "declared here",
            )
        };
        self.errors.push(Error::Conflict {
            span: by.span.into(),
            other: decl.name.span.into(),
            message,
            label: label.into(),
            other_label: other_label.into(),
        });
    }

    fn learn(&mut self, l: &ast::LearnDecl) -> Option<Learning> {
        let target = match l.target.text.as_str() {
            "behavior" => LearnTarget::Behavior,
            "activation" => LearnTarget::Activation,
            other => {
                self.errors.push(Error::Unknown {
                    span: l.target.span.into(),
                    what: "learning target",
                    name: other.into(),
                    help: did_you_mean(other, ["behavior", "activation"])
                        .or_else(|| Some("learn `on behavior` or `on activation`".into())),
                });
                return None;
            }
        };
        let (rate_reward, rate_punish) = match l.rates {
            Some((a, b, sp)) => {
                let a = self.in_range(a, sp, "a learning rate", 0.0, 1.0);
                let b = self.in_range(b, sp, "a learning rate", 0.0, 1.0);
                (a?, b?)
            }
            None => DEFAULT_RATES,
        };
        let error = match l.error.as_ref().map(|e| e.text.as_str()) {
            None | Some("difference") => CrbpError::Difference,
            Some("squared") => CrbpError::Squared,
            Some(other) => {
                let e = l.error.as_ref().expect("matched Some");
                self.errors.push(Error::Unknown {
                    span: e.span.into(),
                    what: "CRBP error",
                    name: other.into(),
                    help: did_you_mean(other, ["difference", "squared"])
                        .or_else(|| Some("the error is `difference` (the paper's) or `squared`".into())),
                });
                return None;
            }
        };
        let when = match l.below {
            None => LearnWhen::Always,
            Some(t) => LearnWhen::Below {
                threshold: self.in_range(t, l.span, "the performance threshold", -1.0, 1.0)?,
            },
        };
        let window = match &l.window {
            Some(q) => self.count_in(q, "the performance window", 1, MAX_WINDOW.into())? as u32,
            None => DEFAULT_WINDOW,
        };
        Some(Learning { target, rate_reward, rate_punish, when, window, error })
    }
}

/// `"recurrent "` for a recurrent network, else nothing.
/// "8 inputs and 2 hidden units": an activation network's shape in words.
fn activation_shape((inputs, hidden, _, recurrent): Shape) -> String {
    match hidden {
        0 => format!("{inputs} inputs and no hidden units"),
        1 => format!("{inputs} inputs and 1 {}hidden unit", recurrent_word(recurrent)),
        h => format!("{inputs} inputs and {h} {}hidden units", recurrent_word(recurrent)),
    }
}

fn recurrent_word(recurrent: bool) -> &'static str {
    if recurrent {
        "recurrent "
    } else {
        ""
    }
}

/// A module declared for the first time, in stage `s`: no inputs, no
/// behavior, its activation network evolvable until its clauses say.
fn new_module(m: &ast::ModuleDecl, s: u16) -> ModuleSt {
    ModuleSt {
        name: m.name.text.clone(),
        span: m.name.span,
        stage: s,
        inputs: Vec::new(),
        inputs_span: None,
        hidden: 0,
        recurrent: false,
        source: Source::Evolvable(None),
        act_span: None,
        act_params: Vec::new(),
        behavior: None,
        behavior_genes: None,
        behavior_stage: s,
        learning: None,
        learn_span: None,
        reinforce: None,
        reinforce_declared: false,
        script_reinforces: false,
    }
}
