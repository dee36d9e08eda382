//! Diagnostics: one error enum, and the collection a compilation returns.
//!
//! Messages are lowercase, without a final period, with user names in
//! backticks. Every variant labels the source; the [`Diagnostics`] holding
//! them owns the named source once.

use miette::{Diagnostic, LabeledSpan, NamedSource, SourceSpan};
use thiserror::Error;

/// One problem in an architecture file.
#[derive(Clone, Debug, Error, Diagnostic)]
pub enum Error {
    /// "expected X, found Y", or a bracket that is not closed.
    #[error("{message}")]
    #[diagnostic(code(S0001))]
    Syntax {
        #[label("{label}")]
        span: SourceSpan,
        message: String,
        label: String,
        #[label(collection)]
        others: Vec<LabeledSpan>,
        #[help]
        help: Option<String>,
    },

    #[error("the file is too complex to parse: {reason}")]
    #[diagnostic(code(S0002), help("architecture files are a few kilobytes; split this one or simplify it"))]
    TooComplex {
        #[label("parsing gave up here")]
        span: SourceSpan,
        reason: String,
    },

    #[error("line {line} is longer than {limit} bytes")]
    #[diagnostic(code(S0003), help("break it into shorter lines"))]
    LineTooLong {
        #[label("this line")]
        span: SourceSpan,
        line: usize,
        limit: usize,
    },

    #[error("{what} deeper than {limit} levels")]
    #[diagnostic(code(S0004), help("split the construct into simpler parts"))]
    TooDeep {
        #[label("too deep")]
        span: SourceSpan,
        what: &'static str,
        limit: usize,
    },

    #[error("the expression has more than {limit} parts")]
    #[diagnostic(code(S0005), help("split it, for example into several fitness terms"))]
    TooLarge {
        #[label("too large")]
        span: SourceSpan,
        limit: usize,
    },

    #[error("unknown {what} `{name}`")]
    #[diagnostic(code(S0006))]
    Unknown {
        #[label("not declared")]
        span: SourceSpan,
        what: &'static str,
        name: String,
        #[help]
        help: Option<String>,
    },

    #[error("{what} `{name}` is declared twice")]
    #[diagnostic(code(S0007))]
    Duplicate {
        #[label("declared again here")]
        span: SourceSpan,
        #[label("first declared here")]
        first: SourceSpan,
        what: &'static str,
        name: String,
    },

    #[error("index {index} is out of range for `{name}`, which has {count} elements")]
    #[diagnostic(code(S0008))]
    IndexOutOfRange {
        #[label("out of range")]
        span: SourceSpan,
        name: String,
        index: u64,
        count: usize,
        #[help]
        help: Option<String>,
    },

    #[error("the range `{range}` is {why}")]
    #[diagnostic(code(S0009))]
    BadRange {
        #[label("{why} range")]
        span: SourceSpan,
        range: String,
        why: &'static str,
        #[help]
        help: Option<String>,
    },

    #[error("expected {expected}, found {found}")]
    #[diagnostic(code(S0010))]
    Type {
        #[label("{found}")]
        span: SourceSpan,
        expected: String,
        found: String,
        #[help]
        help: Option<String>,
    },

    #[error("a gene has 1 to 16 bits, not {value}")]
    #[diagnostic(code(S0011))]
    Bits {
        #[label("bits out of range")]
        span: SourceSpan,
        value: String,
    },

    #[error("stages extend each other in a cycle: {cycle}")]
    #[diagnostic(code(S0012), help("a stage can only extend a stage that does not depend on it"))]
    Cycle {
        #[label("this stage is part of the cycle")]
        span: SourceSpan,
        cycle: String,
        #[label(collection)]
        others: Vec<LabeledSpan>,
    },

    #[error("the reinforcement program of `{module}` reads `{sensor}`, which the module does not sense")]
    #[diagnostic(code(S0013))]
    NotSensed {
        /// Primary: two reads in one module are two errors at two places,
        /// though the module's inputs come first in the file.
        #[label(primary, "read here")]
        span: SourceSpan,
        #[label("the module's inputs")]
        sense: Option<SourceSpan>,
        module: String,
        sensor: String,
        #[help]
        help: Option<String>,
    },

    #[error("`until` has no bound")]
    #[diagnostic(code(S0014), help("add `within N actions` so that the step cannot run forever"))]
    UnboundedUntil {
        #[label("this condition may never become true")]
        span: SourceSpan,
    },

    #[error("stage `{stage}` has no {what} `{name}`")]
    #[diagnostic(code(S0015))]
    MissingHardware {
        #[label("used here")]
        span: SourceSpan,
        stage: String,
        what: &'static str,
        name: String,
        #[help]
        help: Option<String>,
    },

    #[error("stage `{stage}` changes {what}, frozen by stage `{by}`")]
    #[diagnostic(code(S0016), help("a later stage may add modules and links, but the genes of earlier stages are masked; declare a new module instead"))]
    Frozen {
        #[label("changed here")]
        span: SourceSpan,
        #[label("frozen here")]
        frozen: SourceSpan,
        stage: String,
        by: String,
        what: String,
    },

    #[error("expected {expected}, found {found}")]
    #[diagnostic(code(S0017))]
    Unit {
        #[label("wrong unit")]
        span: SourceSpan,
        expected: &'static str,
        found: String,
        #[help]
        help: Option<String>,
    },

    #[error("{message}")]
    #[diagnostic(code(S0018))]
    Value {
        #[label("{label}")]
        span: SourceSpan,
        message: String,
        label: String,
        #[help]
        help: Option<String>,
    },

    #[error("the expression needs {depth} stack slots, more than {max}")]
    #[diagnostic(code(S0019), help("simplify it, for example by aggregating fewer values at once"))]
    StackTooDeep {
        #[label("too deep")]
        span: SourceSpan,
        depth: usize,
        max: usize,
    },

    /// A warning: the file compiles, but a name looks like a typo.
    #[error("new module `{name}` is one edit away from inherited module `{similar}`")]
    #[diagnostic(code(S0020), severity(Warning))]
    SimilarName {
        #[label("a new module")]
        span: SourceSpan,
        #[label("inherited from stage `{stage}`")]
        similar_span: SourceSpan,
        name: String,
        similar: String,
        stage: String,
        #[help]
        help: Option<String>,
    },

    #[error("{message}")]
    #[diagnostic(code(S0021))]
    Conflict {
        #[label("{label}")]
        span: SourceSpan,
        #[label("{other_label}")]
        other: SourceSpan,
        message: String,
        label: String,
        other_label: String,
    },

    #[error("{robots} robots do not fit in the start region, which holds {room}")]
    #[diagnostic(code(S0022))]
    TeamTooLarge {
        #[label(primary, "{robots} robots")]
        span: SourceSpan,
        /// The `start` item, or nothing when the region is the arena less
        /// the clearance (then the arena's span, if known).
        #[label("{region}")]
        region_span: Option<SourceSpan>,
        robots: u32,
        room: u32,
        region: String,
        #[help]
        help: String,
    },

    /// A warning: `team` in a stage whose world has one robot, or a fitness
    /// reading the team's state (`team.spread`), which is then a constant.
    #[error("stage `{stage}` {what}, but its world has one robot")]
    #[diagnostic(code(S0023), severity(Warning))]
    TeamOfOne {
        #[label("{label}")]
        span: SourceSpan,
        stage: String,
        /// `combines a team's fitness`, `reads `team.spread``.
        what: String,
        label: String,
        #[help]
        help: Option<String>,
    },

    #[error("role `{role}` has no genes: evolution would not change it")]
    #[diagnostic(code(S0024))]
    RoleWithoutGenes {
        #[label("{label}")]
        span: SourceSpan,
        role: String,
        label: String,
        #[help]
        help: String,
    },

    #[error("stage `{stage}` has roles, but declares {what} outside them")]
    #[diagnostic(code(S0025))]
    OutsideRole {
        #[label("outside every role")]
        span: SourceSpan,
        #[label("the stage's first role")]
        role: SourceSpan,
        stage: String,
        what: String,
        #[help]
        help: String,
    },

    #[error("role `{role}` has no module")]
    #[diagnostic(code(S0026))]
    EmptyRole {
        #[label("no module")]
        span: SourceSpan,
        role: String,
        #[help]
        help: String,
    },

    #[error("{where_} has {robots} robots, but the roles have {roles}")]
    #[diagnostic(code(S0027))]
    RoleRobots {
        #[label(primary, "{robots} robots")]
        span: SourceSpan,
        #[label("the roles start here")]
        first_role: Option<SourceSpan>,
        where_: String,
        robots: u32,
        roles: u64,
        #[help]
        help: String,
    },

    #[error("{message}")]
    #[diagnostic(code(S0028))]
    RolesNotHere {
        #[label(primary, "{label}")]
        span: SourceSpan,
        #[label("{other_label}")]
        other: Option<SourceSpan>,
        message: String,
        label: String,
        other_label: String,
        #[help]
        help: String,
    },

    #[error("stage `{stage}` evolves, but has no genes of its own: evolution would not change it")]
    #[diagnostic(code(S0029))]
    EvolvedWithoutGenes {
        #[label("{label}")]
        span: SourceSpan,
        stage: String,
        label: String,
        #[help]
        help: String,
    },

    /// The robot's or the team's state, or `distance_to`, where only
    /// sensors are read (a module's reinforcement and conditions, `prev`).
    #[error("{message}")]
    #[diagnostic(code(S0030))]
    NotASensor {
        #[label("{label}")]
        span: SourceSpan,
        message: String,
        label: String,
        #[help]
        help: Option<String>,
    },

    /// A warning: a module senses ambient light in a stage whose world
    /// (and every variant's) has no lamp, so that every reading is 0.
    #[error("stage `{stage}` senses `{sensor}`, but its world has no lamp: every reading is 0")]
    #[diagnostic(code(S0031), severity(Warning))]
    NoLamp {
        #[label("module `{module}` senses it")]
        span: SourceSpan,
        stage: String,
        sensor: String,
        module: String,
        #[help]
        help: String,
    },

    /// A warning: a variant a stage inherits restates an item the stage
    /// changes, so that in that variant the stage's change is lost.
    #[error("variant `{variant}` of stage `{from}` restates {item}, which stage `{stage}` changes: in that variant the change is lost")]
    #[diagnostic(code(S0032), severity(Warning))]
    VariantUndoesChange {
        #[label(primary, "changed here")]
        span: SourceSpan,
        #[label("restated by variant `{variant}`")]
        variant_span: SourceSpan,
        stage: String,
        variant: String,
        from: String,
        item: String,
        #[help]
        help: String,
    },

    /// `place ... at (X, Y)` where the body would cross the arena's walls.
    #[error("the placement{name} puts the body (radius {radius} mm) across the arena's walls ({width} x {depth} mm)")]
    #[diagnostic(code(S0033), help("keep the place at least {radius} mm from every wall of the arena; coordinates are mm east and north of its south-west corner"))]
    PlaceOutside {
        #[label("the robot does not fit here")]
        span: SourceSpan,
        name: String,
        radius: f32,
        width: f32,
        depth: f32,
    },

    /// `place ... at (X, Y)` where the body would overlap an inner wall or
    /// a cylinder.
    #[error("the placement{name} puts the body inside {what}")]
    #[diagnostic(code(S0034), help("move the place so that the body (radius {radius} mm) clears {what}"))]
    PlaceBlocked {
        #[label(primary, "the body overlaps it here")]
        span: SourceSpan,
        #[label("declared here")]
        other: Option<SourceSpan>,
        name: String,
        what: String,
        radius: f32,
    },

    /// `place` in a world of a team: every robot would be put on one spot.
    #[error(
        "the placement{name} would put the {robots} robots of the team on one spot, on top of each other"
    )]
    #[diagnostic(code(S0035), help("a placement moves the world's one robot; keep `place` for worlds without `robots N` (or with `robots 1`)"))]
    PlaceTeam {
        #[label(primary, "every robot is put here")]
        span: SourceSpan,
        #[label("{robots} robots")]
        robots_span: Option<SourceSpan>,
        name: String,
        robots: u32,
    },

    /// `place ... after N actions` in a stage whose lives end before.
    #[error("the placement{name} comes after action {after}, but stage `{stage}`'s lives last {life} actions: it never happens")]
    #[diagnostic(
        code(S0036),
        help("place the robot after fewer actions (at most {last}), or give the stage longer lives")
    )]
    PlaceAfterLife {
        #[label(primary, "never reached")]
        span: SourceSpan,
        #[label("the lives' length")]
        life_span: Option<SourceSpan>,
        name: String,
        stage: String,
        after: u32,
        life: u32,
        last: u32,
    },

    /// A later stage names a role its team does not have (`role NAME adds
    /// { ... }`, `role NAME robots N`).
    #[error("{message}")]
    #[diagnostic(code(S0037))]
    UnknownRole {
        #[label("{label}")]
        span: SourceSpan,
        message: String,
        label: String,
        #[help]
        help: Option<String>,
    },

    /// `role NAME adds { module M ... }` where role NAME has a module M.
    #[error("role `{role}` already has a module `{module}`")]
    #[diagnostic(code(S0038))]
    RoleModuleExists {
        #[label(primary, "declared again here")]
        span: SourceSpan,
        #[label("declared by stage `{by}`")]
        first: SourceSpan,
        role: String,
        module: String,
        by: String,
        #[help]
        help: String,
    },

    /// A link of a role that names a module of another role.
    #[error("`{module}` is a module of role `{other}`, not of role `{role}`: a link joins two modules of one role")]
    #[diagnostic(code(S0039))]
    LinkAcrossRoles {
        #[label("a module of role `{other}`")]
        span: SourceSpan,
        module: String,
        role: String,
        other: String,
        #[help]
        help: String,
    },

    /// A role added by a test stage: no evolution gives its genes.
    #[error("test stage `{stage}` adds role `{role}`, whose genes no stage evolves")]
    #[diagnostic(code(S0040))]
    RoleInTest {
        #[label(primary, "a new role")]
        span: SourceSpan,
        #[label("tests here")]
        test: Option<SourceSpan>,
        stage: String,
        role: String,
        #[help]
        help: String,
    },

    /// A role's fitness reads an actuator that only other roles' modules
    /// command: for this role's robots it never changes.
    #[error("the fitness of role `{role}` reads `{actuator}`, which only the modules of {others} command")]
    #[diagnostic(code(S0041))]
    RoleFitnessReadsOther {
        #[label("role `{role}`'s modules never command it")]
        span: SourceSpan,
        role: String,
        actuator: String,
        others: String,
        #[help]
        help: String,
    },

    /// A warning: a role's fitness in a team of one role, which replaces
    /// the stage's fitness for every robot.
    #[error("role `{role}` has a fitness of its own, but it is the team's only role")]
    #[diagnostic(code(S0042), severity(Warning))]
    RoleFitnessAlone {
        #[label("the fitness of every robot")]
        span: SourceSpan,
        role: String,
        #[help]
        help: String,
    },

    /// A range-and-bearing range of 0, or longer than the arena's diagonal.
    #[error("{message}")]
    #[diagnostic(code(S0043))]
    RabRange {
        #[label("this range")]
        span: SourceSpan,
        message: String,
        #[help]
        help: String,
    },

    /// A `signal` sensor whose elements are not whole sectors of the
    /// values robots broadcast.
    #[error("{message}")]
    #[diagnostic(code(S0044))]
    SignalChannels {
        #[label("this sensor")]
        span: SourceSpan,
        message: String,
        #[help]
        help: String,
    },

    /// A warning: a broadcast actuator that no robot can hear.
    #[error("{message}")]
    #[diagnostic(code(S0045), severity(Warning))]
    Unheard {
        #[label("broadcast here")]
        span: SourceSpan,
        message: String,
        #[help]
        help: String,
    },

    /// A `signal(...)` step with the wrong number of values, or a value
    /// outside 0..1.
    #[error("{message}")]
    #[diagnostic(code(S0046))]
    SignalValues {
        #[label("this step")]
        span: SourceSpan,
        message: String,
        #[help]
        help: String,
    },

    /// A warning: range-and-bearing settings of a body whose robot has
    /// no range-and-bearing hardware.
    #[error("{message}")]
    #[diagnostic(code(S0047), severity(Warning))]
    RabUnused {
        #[label("no robot uses it")]
        span: SourceSpan,
        message: String,
        #[help]
        help: String,
    },

    /// A warning: `rab_signals off` in a body whose robot broadcasts
    /// nothing: there is nothing to silence.
    #[error("{message}")]
    #[diagnostic(code(S0048), severity(Warning))]
    SilencedNothing {
        #[label("silences nothing")]
        span: SourceSpan,
        message: String,
        #[help]
        help: String,
    },
}

impl Error {
    /// Whether this is a warning: the file still compiles.
    pub fn is_warning(&self) -> bool {
        self.severity() == Some(miette::Severity::Warning)
    }
}

/// Every diagnostic of one compilation (errors and warnings), with the
/// source they point into. A warning at the top when there is no error.
#[derive(Debug, Error)]
#[error("{}", self.title())]
pub struct Diagnostics {
    name: String,
    source_code: NamedSource<String>,
    errors: Vec<Error>,
}

impl Diagnostic for Diagnostics {
    fn severity(&self) -> Option<miette::Severity> {
        Some(if self.error_count() == 0 { miette::Severity::Warning } else { miette::Severity::Error })
    }

    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        Some(&self.source_code)
    }

    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn Diagnostic> + 'a>> {
        Some(Box::new(self.errors.iter().map(|e| e as &dyn Diagnostic)))
    }
}

fn count(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

impl Diagnostics {
    pub fn new(file_name: &str, source: &str, errors: Vec<Error>) -> Diagnostics {
        // A line too long is reported alone, at its start: show its beginning only.
        let mut shown = source.len();
        if let [Error::LineTooLong { span, .. }] = &errors[..] {
            shown = (span.offset() + 100).min(source.len());
            while !source.is_char_boundary(shown) {
                shown -= 1;
            }
        }
        Diagnostics {
            name: file_name.to_string(),
            source_code: NamedSource::new(file_name, source[..shown].to_string()),
            errors,
        }
    }

    /// Number of diagnostics, warnings included.
    pub fn len(&self) -> usize {
        self.errors.len()
    }

    pub fn is_empty(&self) -> bool {
        self.errors.is_empty()
    }

    /// Number of errors, warnings not included.
    pub fn error_count(&self) -> usize {
        self.errors.iter().filter(|e| !e.is_warning()).count()
    }

    /// The errors and warnings, in source order.
    pub fn errors(&self) -> &[Error] {
        &self.errors
    }

    /// `could not compile `a.bat`: 2 errors, 1 warning`, or `a.bat`: 1 warning`.
    fn title(&self) -> String {
        let errors = self.error_count();
        let warnings = self.errors.len() - errors;
        match (errors, warnings) {
            (0, w) => format!("`{}`: {}", self.name, count(w, "warning")),
            (e, 0) => format!("could not compile `{}`: {}", self.name, count(e, "error")),
            (e, w) => {
                format!("could not compile `{}`: {}, {}", self.name, count(e, "error"), count(w, "warning"))
            }
        }
    }
}

/// What a diagnostic's help proposes, as an edit an editor can make.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Suggestion {
    /// Write `with` instead of the word at `span` (a "did you mean").
    Replace { span: crate::span::Span, with: String },
    /// Declare this hardware (`actuator arm lift`) in the robot.
    Declare { line: String },
}

impl Error {
    /// The suggestion of the help: a "did you mean `x`?" of
    /// [`did_you_mean`] on a diagnostic labelled on one word, or a
    /// "declare `sensor ...`" or "declare ... `actuator ...`". The span of
    /// a replacement is the diagnostic's label: [`Suggestion::in_source`]
    /// narrows it to the word.
    pub fn suggestion(&self) -> Option<Suggestion> {
        let help = self.help()?.to_string();
        let quoted = |from: &str| -> Option<String> {
            let rest = &help[help.find(from)? + from.len()..];
            Some(rest[..rest.find('`')?].to_string())
        };
        if let Some(with) = quoted(DID_YOU_MEAN) {
            let mut labels = self.labels()?;
            let l = labels.find(|l| l.primary()).or_else(|| self.labels()?.next())?;
            let span = crate::span::Span { start: l.offset(), end: l.offset() + l.len() };
            return Some(Suggestion::Replace { span, with });
        }
        if help.starts_with("declare") {
            let line = quoted("`")?;
            if line.starts_with("actuator ") || line.starts_with("sensor ") {
                return Some(Suggestion::Declare { line });
            }
        }
        None
    }
}

impl Suggestion {
    /// The suggestion on `source`: a replacement labelled on more than the
    /// misspelt word (`lamp bb at (1mm, 1mm)`) narrowed to the word of the
    /// label closest to the suggested one.
    pub fn in_source(self, source: &str) -> Option<Suggestion> {
        let Suggestion::Replace { span, with } = self else { return Some(self) };
        let text = source.get(span.start..span.end)?;
        let word = |c: char| c.is_ascii_alphanumeric() || c == '_';
        if !text.is_empty() && text.chars().all(word) {
            return Some(Suggestion::Replace { span, with });
        }
        let limit = with.chars().count().div_ceil(3).max(1);
        text.split(|c: char| !word(c))
            .filter(|w| !w.is_empty() && *w != with && w.starts_with(|c: char| !c.is_ascii_digit()))
            .map(|w| (strsim::levenshtein(w, &with), w))
            .filter(|(d, _)| *d <= limit)
            .min_by_key(|(d, _)| *d)
            .map(|(_, w)| {
                let start = span.start + (w.as_ptr() as usize - text.as_ptr() as usize);
                Suggestion::Replace {
                    span: crate::span::Span { start, end: start + w.len() },
                    with: with.clone(),
                }
            })
    }
}

/// How [`did_you_mean`] starts its help.
const DID_YOU_MEAN: &str = "did you mean `";

/// The closest candidate within a small Levenshtein distance (about one edit
/// per three characters of `name`), as a help message.
pub fn did_you_mean<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<String> {
    let limit = name.chars().count().div_ceil(3).max(1);
    candidates
        .into_iter()
        .map(|c| (strsim::levenshtein(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| format!("{DID_YOU_MEAN}{c}`?"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggestions_are_close_names_only() {
        assert_eq!(did_you_mean("wandr", ["avoid", "wander"]), Some("did you mean `wander`?".into()));
        assert_eq!(did_you_mean("ligth", ["light", "ir"]), Some("did you mean `light`?".into()));
        assert_eq!(did_you_mean("xyz", ["light", "ir"]), None);
    }
}
