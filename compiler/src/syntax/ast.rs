//! The abstract syntax tree: plain owned data with spans, no pest types.

use super::span::Span;

/// A name as written, with where it was written.
#[derive(Clone, PartialEq)]
pub struct Name {
    pub text: String,
    pub span: Span,
}

impl std::fmt::Debug for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}@{:?}", self.text, self.span)
    }
}

/// A unit written after a number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    Mm,
    Cm,
    Ms,
    Actions,
    /// Degrees, for an angle (`heading 90deg`).
    Deg,
    /// Radians, for an angle (`heading 1.57rad`).
    Rad,
}

impl Unit {
    pub fn as_str(self) -> &'static str {
        match self {
            Unit::Mm => "mm",
            Unit::Cm => "cm",
            Unit::Ms => "ms",
            Unit::Actions => "actions",
            Unit::Deg => "deg",
            Unit::Rad => "rad",
        }
    }
}

/// A number with an optional unit.
#[derive(Clone, Debug, PartialEq)]
pub struct Quantity {
    pub value: f64,
    pub unit: Option<Unit>,
    pub span: Span,
}

/// An inclusive interval `lo..hi`.
#[derive(Clone, Debug, PartialEq)]
pub struct Range {
    pub lo: f64,
    pub hi: f64,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct File {
    pub robots: Vec<Robot>,
    pub genomes: Vec<GenomeBlock>,
    pub stages: Vec<StageDecl>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Robot {
    pub name: Name,
    pub hardware: Vec<Hardware>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Hardware {
    pub is_sensor: bool,
    pub name: Name,
    /// `[N]`, with its span.
    pub count: Option<(u64, Span)>,
    pub kind: Name,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct GenomeBlock {
    pub settings: Vec<GeneSetting>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct GeneSetting {
    /// `links`, `weights` or `biases`; `None` for every gene.
    pub group: Option<Name>,
    pub bits: Option<Quantity>,
    pub range: Option<Range>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct StageDecl {
    pub name: Name,
    pub extends: Option<Name>,
    pub items: Vec<StageItem>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum StageItem {
    RobotAdds(Vec<Hardware>, Span),
    Genome(GenomeBlock),
    World(WorldBlock),
    Evolve(Vec<Setting>, Span),
    /// `test best for [LIVES lives of] ACTIONS [with|without learning]`.
    Test {
        lives: Option<Quantity>,
        actions: Quantity,
        learning: bool,
        span: Span,
    },
    Train {
        actions: Quantity,
        span: Span,
    },
    Fitness(FitnessDecl),
    Module(ModuleDecl),
    LinksAll(LinkKind, Span),
    Link(LinkDecl),
    Variants(VariantsDecl),
    /// `role NAME robots N { ... }`: a role of a heterogeneous team.
    Role(RoleDecl),
}

/// `role NAME robots N { MODULES LINKS FITNESS }`: a role of a
/// heterogeneous team; in a stage that extends a stage with roles, also
/// `role NAME adds { ... }` (modules and links added to a role) and `role
/// NAME robots N` without braces (how many robots play a role).
#[derive(Clone, Debug, PartialEq)]
pub struct RoleDecl {
    pub name: Name,
    /// How many robots play it (`None`: `role NAME adds { ... }`).
    pub robots: Option<Quantity>,
    /// `adds { ... }`: what a later stage adds to an existing role.
    pub adds: bool,
    /// Braces were written (`role NAME robots N` alone has none).
    pub body: bool,
    /// Its modules, links and fitness (`StageItem::Module`, `LinksAll`,
    /// `Link` and `Fitness`).
    pub items: Vec<StageItem>,
    pub span: Span,
    /// The head: `role NAME robots N` or `role NAME adds`.
    pub head: Span,
}

impl RoleDecl {
    /// The head `role NAME robots N` (up to its count) or `role NAME adds`.
    pub fn head(&self) -> Span {
        self.head
    }

    /// The fitness declarations of the role.
    pub fn fitness(&self) -> impl Iterator<Item = &FitnessDecl> {
        self.items.iter().filter_map(|i| match i {
            StageItem::Fitness(f) => Some(f),
            _ => None,
        })
    }

    /// The modules the role declares.
    pub fn modules(&self) -> impl Iterator<Item = &ModuleDecl> {
        self.items.iter().filter_map(|i| match i {
            StageItem::Module(m) => Some(m),
            _ => None,
        })
    }
}

impl StageDecl {
    /// The roles the stage declares.
    pub fn roles(&self) -> impl Iterator<Item = &RoleDecl> {
        self.items.iter().filter_map(|i| match i {
            StageItem::Role(r) => Some(r),
            _ => None,
        })
    }

    /// Every module the stage declares: its own, then each role's.
    pub fn all_modules(&self) -> impl Iterator<Item = &ModuleDecl> {
        let own = self.items.iter().filter_map(|i| match i {
            StageItem::Module(m) => Some(m),
            _ => None,
        });
        own.chain(self.roles().flat_map(RoleDecl::modules))
    }
}

/// `variants mean [draw N] { NAME { ITEMS } ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct VariantsDecl {
    /// `mean` or `min` (any word: the compiler names an unknown one).
    pub aggregate: Name,
    pub draw: Option<Quantity>,
    pub variants: Vec<VariantDecl>,
    pub span: Span,
}

/// `NAME { ITEMS }`: one variant; its items are a `world changes` block
/// (`world.mode` is `Changes`, `world.span` the braces and items).
#[derive(Clone, Debug, PartialEq)]
pub struct VariantDecl {
    pub name: Name,
    pub world: WorldBlock,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorldMode {
    Set,
    Adds,
    Changes,
}

#[derive(Clone, Debug, PartialEq)]
pub struct WorldBlock {
    pub mode: WorldMode,
    pub items: Vec<WorldItem>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum WorldItem {
    Arena {
        width: Quantity,
        depth: Quantity,
        span: Span,
    },
    Charger {
        length: Quantity,
        wall: Name,
        lamp: Option<Option<Quantity>>,
        span: Span,
    },
    Battery(Quantity, Span),
    Recharge(Quantity, Span),
    /// `robots N`: a team of N clones.
    Robots(Quantity, Span),
    /// `role NAME robots N` in a later stage's `world changes`: how many
    /// robots play role NAME (lowered with the stage's roles).
    RoleRobots {
        name: Name,
        robots: Quantity,
        span: Span,
    },
    Objects {
        count: Option<Quantity>,
        diameter: Option<Quantity>,
        virtual_: Option<bool>,
        span: Span,
    },
    /// `body [PRESET] [{ ... }]`
    Body {
        preset: Option<Name>,
        items: Vec<BodyItem>,
        span: Span,
    },
    Wall {
        name: Option<Name>,
        from: Point,
        to: Point,
        span: Span,
    },
    Cylinder {
        name: Option<Name>,
        at: Point,
        diameter: Quantity,
        span: Span,
    },
    Lamp {
        name: Option<Name>,
        at: Point,
        height: Option<Quantity>,
        intensity: Option<Quantity>,
        /// `on at N` (true) or `off at N`.
        switch: Option<(bool, Quantity)>,
        span: Span,
    },
    Zone {
        name: Option<Name>,
        from: Point,
        to: Point,
        grey: Option<Quantity>,
        charger: bool,
        span: Span,
    },
    Start {
        from: Point,
        to: Option<Point>,
        heading: Option<Quantity>,
        span: Span,
    },
    /// `place [NAME] at (X, Y) heading A after N actions`
    Place {
        name: Option<Name>,
        at: Point,
        heading: Quantity,
        after: Quantity,
        span: Span,
    },
}

/// `(X, Y)` in a world item.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub x: Quantity,
    pub y: Quantity,
}

impl WorldItem {
    /// What the item is, as a change names it: its kind (`lamp`, `start`,
    /// `objects`, ...) and, for the items of lists, its name.
    pub fn key(&self) -> (&'static str, Option<&str>) {
        fn name(n: &Option<Name>) -> Option<&str> {
            n.as_ref().map(|n| n.text.as_str())
        }
        match self {
            WorldItem::Arena { .. } => ("arena", None),
            WorldItem::Charger { .. } => ("charger", None),
            WorldItem::Battery(..) => ("battery", None),
            WorldItem::Recharge(..) => ("recharge", None),
            WorldItem::Robots(..) => ("robots", None),
            WorldItem::RoleRobots { name: n, .. } => ("role", Some(n.text.as_str())),
            WorldItem::Objects { .. } => ("objects", None),
            WorldItem::Body { .. } => ("body", None),
            WorldItem::Wall { name: n, .. } => ("wall", name(n)),
            WorldItem::Cylinder { name: n, .. } => ("cylinder", name(n)),
            WorldItem::Lamp { name: n, .. } => ("lamp", name(n)),
            WorldItem::Zone { name: n, .. } => ("zone", name(n)),
            WorldItem::Start { .. } => ("start", None),
            WorldItem::Place { name: n, .. } => ("place", name(n)),
        }
    }

    pub fn span(&self) -> Span {
        match self {
            WorldItem::Arena { span, .. }
            | WorldItem::Charger { span, .. }
            | WorldItem::Battery(_, span)
            | WorldItem::Recharge(_, span)
            | WorldItem::Robots(_, span)
            | WorldItem::RoleRobots { span, .. }
            | WorldItem::Objects { span, .. }
            | WorldItem::Body { span, .. }
            | WorldItem::Wall { span, .. }
            | WorldItem::Cylinder { span, .. }
            | WorldItem::Lamp { span, .. }
            | WorldItem::Zone { span, .. }
            | WorldItem::Start { span, .. }
            | WorldItem::Place { span, .. } => *span,
        }
    }
}

/// One item of a `body { }` block, in the order written.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyItem {
    Setting(Setting),
    Layout(SensorLayout),
}

/// `proximity at [...] facing [...]` or `ground at [...]` in a body.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorLayout {
    /// `proximity` or `ground`.
    pub kind: Name,
    /// Where the sensors sit, with the span of the list.
    pub at: Option<(Vec<Spot>, Span)>,
    /// Where they look (degrees), with the span of the list.
    pub facing: Option<(Vec<Quantity>, Span)>,
    pub span: Span,
}

/// Where one sensor sits: a rim angle, or a point of the body frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Spot {
    Angle(Quantity),
    Point(Point),
}

/// `NAME VALUE` in `evolve { }` and `body { }`.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    pub name: Name,
    pub value: SettingValue,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum SettingValue {
    Quantity(Quantity),
    Word(Name),
    /// `selection truncation keep N`
    Truncation(Quantity),
    /// `selection WORD N`: a word and a number, which only `truncation keep`
    /// takes (an error the compiler names).
    WordAndNumber(Name, Quantity),
}

#[derive(Clone, Debug, PartialEq)]
pub struct FitnessDecl {
    pub adds: bool,
    pub per_action: Vec<Expr>,
    /// `at end EXPR` terms.
    pub at_end: Vec<Expr>,
    pub bonuses: Vec<BonusDecl>,
    /// `team sum|mean|min` clauses (the word, and the clause's span).
    pub team: Vec<(Name, Span)>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct BonusDecl {
    pub points: f64,
    /// The event name; `release outside` is written as two words.
    pub event: Name,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ModuleDecl {
    pub name: Name,
    pub items: Vec<ModuleItem>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ModuleItem {
    Sense(Vec<SensorRef>, Span),
    Activation(ActivationDecl),
    Behavior(BehaviorDecl),
    Learn(LearnDecl),
    Reinforce(Expr, Span),
}

impl ModuleItem {
    pub fn span(&self) -> Span {
        match self {
            ModuleItem::Sense(_, s) | ModuleItem::Reinforce(_, s) => *s,
            ModuleItem::Activation(a) => a.span,
            ModuleItem::Behavior(b) => b.span(),
            ModuleItem::Learn(l) => l.span,
        }
    }

    pub fn keyword(&self) -> &'static str {
        match self {
            ModuleItem::Sense(..) => "sense",
            ModuleItem::Activation(..) => "activation",
            ModuleItem::Behavior(..) => "behavior",
            ModuleItem::Learn(..) => "learn",
            ModuleItem::Reinforce(..) => "reinforce",
        }
    }
}

/// `ir`, `ir[3]`, `ir[0..5]`
#[derive(Clone, Debug, PartialEq)]
pub struct SensorRef {
    pub name: Name,
    pub index: Option<Index>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Index {
    pub first: u64,
    /// The last element of an inclusive slice.
    pub last: Option<u64>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum WeightSource {
    Evolvable(Span),
    Fixed(Vec<f64>, Span),
    Random(Range, Span),
    /// `trained STAGE`: the weights a training stage's module of the same
    /// name learned.
    Trained(Name, Span),
}

impl WeightSource {
    pub fn span(&self) -> Span {
        match self {
            WeightSource::Evolvable(s)
            | WeightSource::Fixed(_, s)
            | WeightSource::Random(_, s)
            | WeightSource::Trained(_, s) => *s,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct ActivationDecl {
    pub source: Option<WeightSource>,
    pub hidden: Option<Quantity>,
    /// `hidden N recurrent`
    pub recurrent: bool,
    pub range: Option<Range>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum BehaviorDecl {
    /// The steps, and whether the script commits (runs to its end once started).
    Script(Vec<StepDecl>, bool, Span),
    Neural(NeuralDecl),
}

impl BehaviorDecl {
    pub fn span(&self) -> Span {
        match self {
            BehaviorDecl::Script(_, _, s) => *s,
            BehaviorDecl::Neural(n) => n.span,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct StepDecl {
    pub action: ActionDecl,
    pub end: Option<EndDecl>,
    pub uses_charger: Option<Span>,
    /// `if COND`: run the step only when the condition holds.
    pub cond: Option<Expr>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum EndDecl {
    For(Quantity),
    Until { cond: Expr, within: Option<Quantity>, span: Span },
}

/// A wheel motion: also an entry of a neural decoding table.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    Forward(Option<f64>),
    Back(Option<f64>),
    TurnLeft(Option<f64>),
    TurnRight(Option<f64>),
    Stop,
    /// `wheels(l, r)`: by the name of a `speed` actuator.
    /// Any other count of numbers is an error the compiler names.
    Wheels(Name, Vec<f64>),
}

#[derive(Clone, Debug, PartialEq)]
pub enum ActionDecl {
    Motion(Motion, Span),
    Toward {
        refs: Vec<SensorRef>,
        speed: Option<f64>,
        span: Span,
    },
    Wait(Span),
    Recharge(Span),
    Reinforce(Expr, Span),
    /// `arm down`: an actuator and a state. A lone name (`forwrd`) has no
    /// state: the compiler reports it as an unknown action or a missing state.
    Set {
        actuator: Name,
        state: Option<Name>,
        span: Span,
    },
}

impl ActionDecl {
    pub fn span(&self) -> Span {
        match self {
            ActionDecl::Motion(_, s)
            | ActionDecl::Toward { span: s, .. }
            | ActionDecl::Wait(s)
            | ActionDecl::Recharge(s)
            | ActionDecl::Reinforce(_, s)
            | ActionDecl::Set { span: s, .. } => *s,
        }
    }
}

#[derive(Clone, PartialEq)]
pub struct NeuralDecl {
    pub sense: Option<(Vec<SensorRef>, Span)>,
    pub hidden: Option<Quantity>,
    /// `hidden N recurrent`
    pub recurrent: bool,
    pub outputs: Option<OutputsDecl>,
    /// `broadcast NAME`: the `broadcast` actuator the network's extra
    /// outputs set.
    pub broadcast: Option<Box<Name>>,
    pub weights: Option<WeightSource>,
    pub span: Span,
}

/// As derived, but without `broadcast` when there is none: the parse
/// snapshots of files written before it stay as they are.
impl std::fmt::Debug for NeuralDecl {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut d = f.debug_struct("NeuralDecl");
        d.field("sense", &self.sense)
            .field("hidden", &self.hidden)
            .field("recurrent", &self.recurrent)
            .field("outputs", &self.outputs);
        if let Some(b) = &self.broadcast {
            d.field("broadcast", b);
        }
        d.field("weights", &self.weights).field("span", &self.span).finish()
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum OutputsDecl {
    Sign { count: Quantity, table: Vec<(Motion, Span)>, span: Span },
    Linear { scale: Option<f64>, span: Span },
}

#[derive(Clone, Debug, PartialEq)]
pub struct LearnDecl {
    pub rates: Option<(f64, f64, Span)>,
    /// `error difference|squared` in the parentheses.
    pub error: Option<Name>,
    pub target: Name,
    /// `None` for `always`, else the threshold.
    pub below: Option<f64>,
    pub window: Option<Quantity>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LinkKind {
    Evolvable(Option<Range>),
    Fixed(f64),
}

#[derive(Clone, Debug, PartialEq)]
pub struct LinkDecl {
    pub from: Name,
    pub to: Name,
    pub kind: LinkKind,
    pub span: Span,
}

// ------------------------------------------------------------------ expressions

#[derive(Clone, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

/// Expressions print as s-expressions, with the span of the whole:
/// `(+ 1 (* 2 ir[3]))@10..22`.
impl std::fmt::Debug for Expr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}@{:?}", self.sexpr(), self.span)
    }
}

impl Expr {
    /// The expression as an s-expression, without spans.
    pub fn sexpr(&self) -> String {
        match &self.kind {
            ExprKind::Number(v, None) => format!("{v}"),
            ExprKind::Number(v, Some(u)) => format!("{v}{}", u.as_str()),
            ExprKind::Ref(n, None) => n.text.clone(),
            ExprKind::Ref(n, Some(Index { first, last: None, .. })) => format!("{}[{first}]", n.text),
            ExprKind::Ref(n, Some(Index { first, last: Some(l), .. })) => format!("{}[{first}..{l}]", n.text),
            ExprKind::State(n) => format!("robot.{}", n.text),
            ExprKind::Team(n) => format!("team.{}", n.text),
            ExprKind::Call(n, args) => {
                let args: Vec<String> = args.iter().map(Expr::sexpr).collect();
                format!("({} {})", n.text, args.join(" "))
            }
            ExprKind::Unary(op, e) => {
                let op = match op {
                    UnOp::Neg => "neg",
                    UnOp::Not => "not",
                    UnOp::Prev => "prev",
                };
                format!("({op} {})", e.sexpr())
            }
            ExprKind::Binary(op, a, b) => {
                let op = op.text();
                format!("({op} {} {})", a.sexpr(), b.sexpr())
            }
            ExprKind::Cond(c, a, b) => format!("(? {} {} {})", c.sexpr(), a.sexpr(), b.sexpr()),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnOp {
    Neg,
    Not,
    Prev,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
}

impl BinOp {
    /// The operator as written in the language.
    pub fn text(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::And => "and",
            BinOp::Or => "or",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    Number(f64, Option<Unit>),
    /// A sensor or actuator, whole or indexed.
    Ref(Name, Option<Index>),
    /// `robot.FIELD`: the robot's state (the name is the field).
    State(Name),
    /// `team.FIELD`: the team's state (the name is the field).
    Team(Name),
    Call(Name, Vec<Expr>),
    Unary(UnOp, Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `c ? a : b`
    Cond(Box<Expr>, Box<Expr>, Box<Expr>),
}
