//! Type checking and lowering of expressions to postfix [`Expr`] code.
//!
//! Types: a *number*, or an *array* (a whole sensor such as `ir`, a slice
//! `ir[0..5]`, or `prev` of one). Arrays are only accepted by the
//! aggregates `max min sum mean`; a one-element array is a number.

use shaping_runtime::expr::{Expr, Op, MAX_STACK};
use shaping_runtime::program::{ItemKind, Target};
use shaping_runtime::state::{MAX_TARGETS, ST_SPREAD, ST_TARGETS};

use super::{Hw, Lower};
use crate::diag::{did_you_mean, Error};
use crate::syntax::ast::{self, BinOp, ExprKind, UnOp};
use crate::syntax::Span;

/// Which sensors an expression may read.
pub struct Scope<'a> {
    /// `Some((module, channels, sense span))`: only these channels (a
    /// reinforcement program reads what its module senses).
    pub only: Option<(&'a str, &'a [u16], Option<Span>)>,
    /// The robot's state (`robot.x` ...) may be read: a fitness term.
    pub state: bool,
}

/// The fields of `robot.FIELD` and their state slots.
pub const STATE_FIELDS: [(&str, usize, &str); 6] = [
    ("x", shaping_runtime::state::ST_X, "the body centre's x, mm from the arena's west wall"),
    ("y", shaping_runtime::state::ST_Y, "the body centre's y, mm from the arena's south wall"),
    (
        "heading",
        shaping_runtime::state::ST_HEADING,
        "the heading, radians counter-clockwise from east, -pi..pi (a start's `heading` is written in degrees)",
    ),
    (
        "distance",
        shaping_runtime::state::ST_DISTANCE,
        "the distance the body centre travelled in this life, mm",
    ),
    ("time", shaping_runtime::state::ST_TIME, "the actions done in this life so far"),
    ("squares", shaping_runtime::state::ST_SQUARES, "the 50 mm squares of the arena visited in this life"),
];

/// The fields of `team.FIELD` and their state slots.
pub const TEAM_FIELDS: [(&str, usize, &str); 6] = [
    (
        "spread",
        ST_SPREAD,
        "the mean distance of the team's robots' centres to the team's centre, mm (0 for one robot)",
    ),
    (
        "grouped",
        shaping_runtime::state::ST_GROUPED,
        "the share of the team's robots whose body is within 20 mm of another robot's, 0..1",
    ),
    (
        "largest",
        shaping_runtime::state::ST_LARGEST,
        "the share of the team's robots in its largest group (bodies within 20 mm of each other), 0..1",
    ),
    (
        "nearest",
        shaping_runtime::state::ST_NEAREST,
        "the mean over the team's robots of the distance to the nearest other robot, centre to centre, mm (0 for one robot)",
    ),
    (
        "order",
        shaping_runtime::state::ST_ORDER,
        "the length of the mean of the robots' unit heading vectors, 0..1: 1 when all head one way (1 for one robot)",
    ),
    (
        "connected",
        shaping_runtime::state::ST_CONNECTED,
        "the share of the team's robots in its largest group linked within the range-and-bearing range (`rab_range`, 300 mm without a board), 0..1",
    ),
];

/// Where an expression is lowered: the robot's hardware, what it may read,
/// and whether it is inside `prev` (only sensors have a previous value).
#[derive(Clone, Copy)]
struct At<'a> {
    hw: &'a Hw,
    scope: &'a Scope<'a>,
    prev: bool,
}

enum Val {
    /// Emitted onto the code.
    Num,
    /// Not yet emitted: the element loads, and a description for messages.
    Arr(Vec<Op>, String),
    /// An error was reported.
    Err,
}

pub(crate) const FUNCTIONS: [&str; 8] = ["max", "min", "sum", "mean", "abs", "sign", "sqrt", "distance_to"];

impl Lower<'_> {
    /// Lowers an expression that must give a number; `None` after an error.
    pub(super) fn expr(&mut self, hw: &Hw, e: &ast::Expr, scope: &Scope) -> Option<Expr> {
        let before = self.errors.len();
        let mut ops = Vec::new();
        let v = self.go(At { hw, scope, prev: false }, e, &mut ops);
        self.expect_num(v, e.span, &mut ops);
        if self.errors.len() > before {
            return None;
        }
        let depth = Expr::required_depth(&ops)?;
        if depth as usize > MAX_STACK {
            self.errors.push(Error::StackTooDeep {
                span: e.span.into(),
                depth: depth as usize,
                max: MAX_STACK,
            });
            return None;
        }
        Some(Expr { ops, depth })
    }

    fn expect_num(&mut self, v: Val, span: Span, ops: &mut Vec<Op>) -> bool {
        match v {
            Val::Num => true,
            Val::Arr(loads, _) if loads.len() == 1 => {
                ops.extend(loads);
                true
            }
            Val::Arr(loads, desc) => {
                // `desc` names the array as written: "the array `light`", "the slice `light[2..5]`".
                let written = desc.split('`').nth(1).unwrap_or("ir");
                let first = match written.split_once('[') {
                    Some((name, range)) => format!("{name}[{}]", range.split("..").next().unwrap_or("0")),
                    None => format!("{written}[0]"),
                };
                let what = if desc.starts_with("the slice") { "slice" } else { "array" };
                self.errors.push(Error::Type {
                    span: span.into(),
                    expected: "a number".into(),
                    found: format!("{desc} of {} values", loads.len()),
                    help: Some(format!(
                        "pick one element (`{first}`) or aggregate the {what} (`max({written})`)"
                    )),
                });
                false
            }
            Val::Err => false,
        }
    }

    fn go(&mut self, at: At, e: &ast::Expr, ops: &mut Vec<Op>) -> Val {
        match &e.kind {
            ExprKind::Number(v, unit) => {
                if let Some(u) = unit {
                    self.errors.push(Error::Unit {
                        span: e.span.into(),
                        expected: "a plain number",
                        found: format!("`{}`", u.as_str()),
                        help: Some("expressions compute on plain numbers (sensor values are 0..1)".into()),
                    });
                    return Val::Err;
                }
                ops.push(Op::Const(*v as f32));
                Val::Num
            }
            ExprKind::Ref(name, index) => self.reference(at, name, index.as_ref(), e.span, ops),
            ExprKind::State(field) => self.state(at, "robot", &STATE_FIELDS, field, e.span, ops),
            ExprKind::Team(field) => self.state(at, "team", &TEAM_FIELDS, field, e.span, ops),
            ExprKind::Unary(op, inner) => match op {
                UnOp::Prev => self.go(At { prev: true, ..at }, inner, ops),
                UnOp::Neg | UnOp::Not => {
                    let v = self.go(at, inner, ops);
                    if !self.expect_num(v, inner.span, ops) {
                        return Val::Err;
                    }
                    ops.push(if *op == UnOp::Neg { Op::Neg } else { Op::Not });
                    Val::Num
                }
            },
            ExprKind::Binary(op, a, b) => {
                let va = self.go(at, a, ops);
                let ok_a = self.expect_num(va, a.span, ops);
                let vb = self.go(at, b, ops);
                let ok_b = self.expect_num(vb, b.span, ops);
                if !(ok_a && ok_b) {
                    return Val::Err;
                }
                ops.push(match op {
                    BinOp::Add => Op::Add,
                    BinOp::Sub => Op::Sub,
                    BinOp::Mul => Op::Mul,
                    BinOp::Div => Op::Div,
                    BinOp::Lt => Op::Lt,
                    BinOp::Le => Op::Le,
                    BinOp::Gt => Op::Gt,
                    BinOp::Ge => Op::Ge,
                    BinOp::Eq => Op::Eq,
                    BinOp::Ne => Op::Ne,
                    BinOp::And => Op::And,
                    BinOp::Or => Op::Or,
                });
                Val::Num
            }
            ExprKind::Cond(c, a, b) => {
                let mut ok = true;
                for part in [c, a, b] {
                    let v = self.go(at, part, ops);
                    ok &= self.expect_num(v, part.span, ops);
                }
                if !ok {
                    return Val::Err;
                }
                ops.push(Op::Select);
                Val::Num
            }
            ExprKind::Call(f, args) => self.call(at, f, args, e.span, ops),
        }
    }

    fn call(&mut self, at: At, f: &ast::Name, args: &[ast::Expr], span: Span, ops: &mut Vec<Op>) -> Val {
        match f.text.as_str() {
            "abs" | "sign" | "sqrt" => {
                if args.len() != 1 {
                    self.errors.push(Error::Value {
                        span: span.into(),
                        message: format!("`{}` takes 1 argument, found {}", f.text, args.len()),
                        label: "wrong number of arguments".into(),
                        help: None,
                    });
                    return Val::Err;
                }
                let v = self.go(at, &args[0], ops);
                if !self.expect_num(v, args[0].span, ops) {
                    return Val::Err;
                }
                ops.push(match f.text.as_str() {
                    "abs" => Op::Abs,
                    "sqrt" => Op::Sqrt,
                    _ => Op::Sign,
                });
                Val::Num
            }
            "max" | "min" | "sum" | "mean" => {
                let mut n = 0usize;
                let mut ok = true;
                for a in args {
                    match self.go(at, a, ops) {
                        Val::Num => n += 1,
                        Val::Arr(loads, _) => {
                            n += loads.len();
                            ops.extend(loads);
                        }
                        Val::Err => ok = false,
                    }
                }
                if !ok {
                    return Val::Err;
                }
                let n = u16::try_from(n).unwrap_or(u16::MAX);
                ops.push(match f.text.as_str() {
                    "max" => Op::Max(n),
                    "min" => Op::Min(n),
                    "sum" => Op::Sum(n),
                    _ => Op::Mean(n),
                });
                Val::Num
            }
            "distance_to" => self.distance_to(at, f, args, span, ops),
            _ => {
                self.errors.push(Error::Unknown {
                    span: f.span.into(),
                    what: "function",
                    name: f.text.clone(),
                    help: did_you_mean(&f.text, FUNCTIONS)
                        .or_else(|| Some(format!("the functions are {}", backticked(&FUNCTIONS)))),
                });
                Val::Err
            }
        }
    }

    /// `distance_to(NAME)`: the distance from the body centre to the named
    /// wall, cylinder, lamp or zone of the stage's world, mm (a fitness only).
    fn distance_to(
        &mut self,
        at: At,
        f: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        ops: &mut Vec<Op>,
    ) -> Val {
        let target = match args {
            [ast::Expr { kind: ExprKind::Ref(n, None), .. }] => n,
            _ => {
                self.errors.push(Error::Value {
                    span: span.into(),
                    message: "`distance_to` takes the name of one item of the world".into(),
                    label: "not an item's name".into(),
                    help: Some("name a wall, cylinder, lamp or zone: `distance_to(goal)`".into()),
                });
                return Val::Err;
            }
        };
        if !at.scope.state || at.prev {
            self.errors.push(Error::NotASensor {
                span: span.into(),
                message: "`distance_to` is the simulator's knowledge of the robot: only a fitness reads it"
                    .into(),
                label: "not a sensor".into(),
                help: Some("a module's reinforcement and conditions read the robot's sensors".into()),
            });
            return Val::Err;
        }
        let _ = f;
        let items = &self.items;
        let kinds = [
            (ItemKind::Wall, items.walls.iter().map(|x| x.name.clone()).collect::<Vec<_>>()),
            (ItemKind::Cylinder, items.cylinders.iter().map(|x| x.name.clone()).collect()),
            (ItemKind::Lamp, items.lamps.iter().map(|x| x.name.clone()).collect()),
            (ItemKind::Zone, items.zones.iter().map(|x| x.name.clone()).collect()),
        ];
        let found =
            kinds.iter().find(|(_, names)| names.iter().any(|n| n.as_deref() == Some(target.text.as_str())));
        let Some((kind, _)) = found else {
            let all: Vec<String> = kinds.iter().flat_map(|(_, n)| n.iter().flatten().cloned()).collect();
            self.errors.push(Error::Unknown {
                span: target.span.into(),
                what: "item of the world",
                name: target.text.clone(),
                help: did_you_mean(&target.text, all.iter().map(String::as_str))
                    .or_else(|| Some("name a wall, cylinder, lamp or zone of the stage's world".into())),
            });
            return Val::Err;
        };
        let t = Target { kind: *kind, name: target.text.clone() };
        let i = match self.targets.iter().position(|x| *x == t) {
            Some(i) => i,
            None if self.targets.len() < MAX_TARGETS => {
                self.targets.push(t);
                self.targets.len() - 1
            }
            None => {
                self.value_error(
                    target.span,
                    format!("a stage measures the distance to at most {MAX_TARGETS} items"),
                    "one too many",
                    None,
                );
                return Val::Err;
            }
        };
        ops.push(Op::State((ST_TARGETS + i) as u16));
        Val::Num
    }

    /// `robot.FIELD` (`of` is `robot`, `fields` [`STATE_FIELDS`]) or
    /// `team.FIELD` ([`TEAM_FIELDS`]).
    fn state(
        &mut self,
        at: At,
        of: &str,
        fields: &[(&str, usize, &str)],
        field: &ast::Name,
        span: Span,
        ops: &mut Vec<Op>,
    ) -> Val {
        let Some(&(_, slot, _)) = fields.iter().find(|f| f.0 == field.text) else {
            self.errors.push(Error::Value {
                span: field.span.into(),
                message: format!("the {of}'s state has no field `{}`", field.text),
                label: "unknown field".into(),
                help: Some(
                    crate::diag::did_you_mean(&field.text, fields.iter().map(|f| f.0)).unwrap_or_else(|| {
                        let all: Vec<String> = fields.iter().map(|f| format!("`{of}.{}`", f.0)).collect();
                        format!("the fields are {}", all.join(", "))
                    }),
                ),
            });
            return Val::Err;
        };
        if !at.scope.state {
            self.errors.push(Error::NotASensor {
                span: span.into(),
                message: format!(
                    "`{of}.{}` is the simulator's knowledge of the {of}: only a fitness reads it",
                    field.text
                ),
                label: "not a sensor".into(),
                help: Some("a module's reinforcement and conditions read the robot's sensors".into()),
            });
            return Val::Err;
        }
        if at.prev {
            self.errors.push(Error::NotASensor {
                span: span.into(),
                message: format!("`prev` reads sensors only, and `{of}.{}` is the {of}'s state", field.text),
                label: "no previous value".into(),
                help: None,
            });
            return Val::Err;
        }
        ops.push(Op::State(slot as u16));
        Val::Num
    }

    fn reference(
        &mut self,
        at: At,
        name: &ast::Name,
        index: Option<&ast::Index>,
        span: Span,
        ops: &mut Vec<Op>,
    ) -> Val {
        if let Some(s) = at.hw.sensors.iter().find(|s| s.name == name.text) {
            let Some((first, last)) = self.elements(&s.name, s.count as usize, index) else {
                return Val::Err;
            };
            let channels: Vec<u16> = (first..=last).map(|i| s.channel + i as u16).collect();
            if let Some((module, allowed, sense)) = at.scope.only {
                let unsensed: Vec<u16> = channels.iter().copied().filter(|c| !allowed.contains(c)).collect();
                if !unsensed.is_empty() {
                    let elem = s.elements_text(&unsensed);
                    self.errors.push(Error::NotSensed {
                        span: span.into(),
                        sense: sense.map(Into::into),
                        module: module.to_string(),
                        sensor: elem,
                        help: Some(format!(
                            "add it to the `sense` list of `{module}`, or read only what it senses"
                        )),
                    });
                    return Val::Err;
                }
            }
            let loads: Vec<Op> =
                channels.iter().map(|&c| if at.prev { Op::Prev(c) } else { Op::Chan(c) }).collect();
            if index.is_some_and(|i| i.last.is_none()) || s.count == 1 {
                ops.extend(loads);
                return Val::Num;
            }
            let desc = match index {
                Some(i) => format!("the slice `{}[{}..{}]`", s.name, i.first, i.last.unwrap_or(i.first)),
                None => format!("the array `{}`", s.name),
            };
            return Val::Arr(loads, desc);
        }
        if let Some(a) = at.hw.actuators.iter().find(|a| a.name == name.text) {
            if at.prev {
                self.errors.push(Error::Value {
                    span: span.into(),
                    message: format!("`prev` reads sensors only, and `{}` is an actuator", a.name),
                    label: "no previous value".into(),
                    help: None,
                });
                return Val::Err;
            }
            let Some((first, last)) = self.elements(&a.name, a.count as usize, index) else {
                return Val::Err;
            };
            let loads: Vec<Op> = (first..=last).map(|i| Op::Act(a.slot + i as u16)).collect();
            if index.is_some_and(|i| i.last.is_none()) || a.count == 1 {
                ops.extend(loads);
                return Val::Num;
            }
            return Val::Arr(loads, format!("the array `{}`", a.name));
        }
        self.unknown_hardware(at.hw, "sensor", name);
        Val::Err
    }

    /// Checks an index against an array of `count` elements; gives the
    /// inclusive element range.
    pub(super) fn elements(
        &mut self,
        name: &str,
        count: usize,
        index: Option<&ast::Index>,
    ) -> Option<(u64, u64)> {
        let Some(ix) = index else {
            return Some((0, count.saturating_sub(1) as u64));
        };
        let last = ix.last.unwrap_or(ix.first);
        if last < ix.first {
            self.errors.push(Error::BadRange {
                span: ix.span.into(),
                range: format!("{}..{}", ix.first, last),
                why: "inverted",
                help: Some(format!("write `{}[{}..{}]`", name, last, ix.first)),
            });
            return None;
        }
        for i in [ix.first, last] {
            if i as usize >= count || i > u16::MAX as u64 {
                self.errors.push(Error::IndexOutOfRange {
                    span: ix.span.into(),
                    name: name.to_string(),
                    index: i,
                    count,
                    help: Some(if count == 1 {
                        format!("`{name}` is a single value: write `{name}` without an index")
                    } else {
                        format!("the elements of `{name}` are numbered 0 to {}", count - 1)
                    }),
                });
                return None;
            }
        }
        Some((ix.first, last))
    }
}

pub fn backticked(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.len() {
        0 => String::new(),
        1 => quoted[0].clone(),
        n => format!("{} and {}", quoted[..n - 1].join(", "), quoted[n - 1]),
    }
}
