//! From text to AST. The only module that sees pest types.

use pest::iterators::Pair;
use pest::pratt_parser::{Assoc, Op, PrattParser};
use pest::Parser as _;

use super::ast::*;
use super::span::Span;
use crate::diag::Error;

#[derive(pest_derive::Parser)]
#[grammar = "../../grammar/shaping.pest"]
pub(super) struct BatParser;

/// The reserved words of the grammar's `keyword` rule: the runtime's list,
/// which `Program::validate` refuses as names (one list, checked against
/// the grammar by the tests).
pub use shaping_runtime::validate::RESERVED;

/// Deepest nesting of brackets (and `? :`) accepted before parsing.
const MAX_NESTING: usize = 48;
/// Most grammar nodes in one expression (bounds every recursion over it).
const MAX_EXPR_NODES: usize = 256;
/// Longest line accepted, in bytes. Diagnostics show the line with its
/// labels, and renderers (miette) cannot pad a label past 65535 columns.
const MAX_LINE: usize = 4096;
/// Budget of pest rule calls for one file.
const CALL_LIMIT: usize = 20_000_000;

/// Parses a file. On syntax errors, returns every one of them (each part
/// that does not parse gives its own, see [`parse_recovering`]).
pub fn parse(src: &str) -> Result<File, Vec<Error>> {
    match parse_with_limit(src, CALL_LIMIT) {
        Parsed { file: Some(file), errors, .. } if errors.is_empty() => Ok(file),
        Parsed { errors, .. } => Err(errors),
    }
}

/// Parses a file as far as it can: on syntax errors, the AST of the parts
/// that parse (top-level items, and the items of a stage) beside every
/// syntax error, each at its place. `None` for a file refused before
/// parsing (the limits on line length, nesting and pest's call budget).
pub fn parse_recovering(src: &str) -> (Option<File>, Vec<Error>) {
    let p = parse_with_limit(src, CALL_LIMIT);
    (p.file, p.errors)
}

/// Parses a file for checking: the AST when the file parses and its only
/// errors are unknown units (`0.25s`), which leave the AST whole, so that
/// the checks that follow report every other mistake too. Each unit error
/// comes with the span of its quantity (read as a number without a unit):
/// what the checks say about the quantity is a consequence of it.
pub fn parse_for_check(src: &str) -> Result<(File, UnitErrors), Vec<Error>> {
    match parse_with_limit(src, CALL_LIMIT) {
        Parsed { file: Some(file), errors, units } if errors.len() == units.len() => {
            Ok((file, units.into_iter().zip(errors).collect()))
        }
        Parsed { errors, .. } => Err(errors),
    }
}

/// Parses `src` as one expression and nothing else (a measure given from
/// outside a file: Python's `evaluate(measures=...)`), with the file's
/// limits; its spans are offsets into `src`.
pub fn parse_expr(src: &str) -> Result<Expr, Vec<Error>> {
    if let Some(err) = check_lines(src).or_else(|| check_nesting(src)) {
        return Err(vec![err]);
    }
    pest::set_call_limit(std::num::NonZeroUsize::new(CALL_LIMIT));
    pest::set_error_detail(true);
    let pairs = BatParser::parse(Rule::expr, src).map_err(|e| vec![syntax_error(src, e)])?;
    if let Some(err) = check_numbers(&pairs) {
        return Err(vec![err]);
    }
    let Some(p) = pairs.clone().next() else {
        return Err(vec![Error::Syntax {
            span: Span::new(0, 0).into(),
            message: "expected an expression, found nothing".into(),
            label: "empty".into(),
            others: Vec::new(),
            help: None,
        }]);
    };
    let end = span(&p).end;
    let rest = &src[end..];
    let trailing = rest.len() - rest.trim_start().len();
    if end + trailing < src.len() {
        let (at, found) = token_at(src, end + trailing);
        let word = found.trim_matches('`');
        // An operator that did not parse has no operand after it (`1 +`).
        let operator = word.starts_with(['+', '-', '*', '/', '<', '>', '=', '!', '?', ':'])
            || word == "and"
            || word == "or";
        let (message, help) = if operator {
            (
                format!("expected an expression after {found}, found the end of the expression"),
                "an operand is missing".to_string(),
            )
        } else {
            (
                format!("expected an operator or the end of the expression, found {found}"),
                "a measure is one expression, as a fitness `at end` term is".to_string(),
            )
        };
        return Err(vec![Error::Syntax {
            span: at.into(),
            message,
            label: "unexpected here".into(),
            others: Vec::new(),
            help: Some(help),
        }]);
    }
    let mut b = Builder { pratt: pratt(), errors: Vec::new() };
    let e = b.expr(p);
    if b.errors.is_empty() {
        Ok(e)
    } else {
        Err(b.errors)
    }
}

/// The errors of unknown units, each with the span of its quantity.
pub type UnitErrors = Vec<(Span, Error)>;

/// What a parse gives: the AST, if any, every error, and the spans of the
/// quantities with an unknown unit (one per error of that kind).
struct Parsed {
    file: Option<File>,
    errors: Vec<Error>,
    units: Vec<Span>,
}

impl Parsed {
    fn refused(errors: Vec<Error>) -> Parsed {
        Parsed { file: None, errors, units: Vec::new() }
    }
}

fn parse_with_limit(src: &str, call_limit: usize) -> Parsed {
    // A byte order mark some editors put at the start of a UTF-8 file is no
    // part of the text: read as three spaces, so every span stays the place
    // of the same bytes of the file.
    let unmarked;
    let src = match src.strip_prefix('\u{feff}') {
        Some(rest) => {
            unmarked = format!("   {rest}");
            unmarked.as_str()
        }
        None => src,
    };
    if let Some(err) = check_lines(src).or_else(|| check_nesting(src)) {
        return Parsed::refused(vec![err]);
    }
    pest::set_call_limit(std::num::NonZeroUsize::new(call_limit));
    // Literals the parse expected, for messages at the right place (set on
    // every parse, never unset, so that every thread gets the same messages).
    pest::set_error_detail(true);
    let (masked, mut errors) = match BatParser::parse(Rule::file, src) {
        Ok(pairs) => return build(pairs, Vec::new()),
        Err(e) if matches!(e.variant, pest::error::ErrorVariant::CustomError { .. }) => {
            return Parsed::refused(vec![syntax_error(src, e)])
        }
        Err(e) => {
            let (masked, mut errors) = super::recover::recover(src);
            if errors.is_empty() {
                errors.push(syntax_error(src, e));
            }
            (masked, errors)
        }
    };
    match masked.as_deref().map(|m| BatParser::parse(Rule::file, m)) {
        Some(Ok(pairs)) => build(pairs, errors),
        _ => {
            errors.dedup_by_key(|e| (e.to_string(), first_label(e)));
            Parsed::refused(errors)
        }
    }
}

/// Where the first label of an error is.
fn first_label(e: &Error) -> Option<usize> {
    use miette::Diagnostic;
    e.labels().and_then(|mut l| l.next()).map(|l| l.offset())
}

/// The AST of a parsed file, with the errors found building it after the
/// syntax errors already found.
fn build(mut pairs: pest::iterators::Pairs<Rule>, mut errors: Vec<Error>) -> Parsed {
    if let Some(err) = check_numbers(&pairs) {
        errors.push(err);
    }
    // Unknown units are errors that leave the AST whole: the only ones when
    // the file is otherwise right (see `parse_for_check`).
    let (units, unit_errors): (Vec<Span>, Vec<Error>) = unknown_units(&pairs).into_iter().unzip();
    let units = if errors.is_empty() { units } else { Vec::new() };
    errors.extend(unit_errors);
    let mut b = Builder { pratt: pratt(), errors: Vec::new() };
    let file =
        pairs.next().map(|p| b.file(p)).unwrap_or(File { robots: vec![], genomes: vec![], stages: vec![] });
    let units = if b.errors.is_empty() { units } else { Vec::new() };
    errors.extend(b.errors);
    Parsed { file: Some(file), errors, units }
}

fn pratt() -> PrattParser<Rule> {
    PrattParser::new()
        .op(Op::infix(Rule::cond, Assoc::Right))
        .op(Op::infix(Rule::or, Assoc::Left))
        .op(Op::infix(Rule::and, Assoc::Left))
        .op(Op::prefix(Rule::not))
        .op(Op::infix(Rule::lt, Assoc::Left)
            | Op::infix(Rule::le, Assoc::Left)
            | Op::infix(Rule::gt, Assoc::Left)
            | Op::infix(Rule::ge, Assoc::Left)
            | Op::infix(Rule::eq, Assoc::Left)
            | Op::infix(Rule::ne, Assoc::Left))
        .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
        .op(Op::infix(Rule::mul, Assoc::Left) | Op::infix(Rule::div, Assoc::Left))
        .op(Op::prefix(Rule::neg) | Op::prefix(Rule::prev))
}

/// Rejects the first number a 32-bit float cannot hold (the runtime computes
/// in `f32`, so `1e39` would become infinite), and the first index or count
/// too large to read (it would be reported as another number).
fn check_numbers(pairs: &pest::iterators::Pairs<Rule>) -> Option<Error> {
    pairs.clone().flatten().find_map(|p| match p.as_rule() {
        Rule::number | Rule::unsigned => {
            let v = num(&p);
            (v.is_nan() || v.abs() > f32::MAX as f64).then(|| Error::Value {
                span: span(&p).into(),
                message: format!("the number `{}` is too large", p.as_str()),
                label: "too large".into(),
                help: Some(format!("numbers are at most {:e} in magnitude", f32::MAX)),
            })
        }
        // An index or a hardware count: whole, and read as a `u64`.
        Rule::integer if p.as_str().parse::<u64>().is_err() => Some(Error::Value {
            span: span(&p).into(),
            message: format!("the number `{}` is too large", p.as_str()),
            label: "too large".into(),
            help: Some(
                "an index or a count of elements is a small whole number (`ir[3]`, `sensor ir[8]`)".into(),
            ),
        }),
        _ => None,
    })
}

/// Every word glued to a number that is no unit (`0.25s`), with the span
/// of its quantity.
fn unknown_units(pairs: &pest::iterators::Pairs<Rule>) -> Vec<(Span, Error)> {
    let quantities = pairs.clone().flatten().filter(|p| p.as_rule() == Rule::quantity);
    quantities
        .filter_map(|q| {
            let mut it = q.clone().into_inner();
            let value = it.next()?;
            let u = it.next().filter(|u| u.as_rule() == Rule::unknown_unit)?;
            let help = match (u.as_str(), value.as_str().parse::<f64>()) {
                ("s" | "sec" | "secs" | "second" | "seconds", Ok(v)) => {
                    format!("durations are in milliseconds: `{}ms`", v * 1000.0)
                }
                ("m" | "metre" | "metres" | "meter" | "meters", Ok(v)) => {
                    format!("lengths are in millimetres or centimetres: `{}mm`", v * 1000.0)
                }
                _ => UNITS.into(),
            };
            let e = Error::Value {
                span: span(&u).into(),
                message: format!("unknown unit `{}`", u.as_str()),
                label: "not a unit".into(),
                help: Some(help),
            };
            Some((span(&q), e))
        })
        .collect()
}

/// The units of the grammar's `unit` rule, for messages.
const UNITS: &str = "the units are `mm` and `cm` (lengths), `ms` (durations), `actions` (counts) and `deg` and `rad` (angles); a length without a unit is in millimetres, an angle in degrees";

/// Rejects the first line longer than [`MAX_LINE`], labelled at its start.
fn check_lines(src: &str) -> Option<Error> {
    let mut start = 0;
    for (n, line) in src.split('\n').enumerate() {
        if line.len() > MAX_LINE {
            let first = line.chars().next().map_or(1, char::len_utf8);
            return Some(Error::LineTooLong {
                span: Span::new(start, start + first).into(),
                line: n + 1,
                limit: MAX_LINE,
            });
        }
        start += line.len() + 1;
    }
    None
}

/// Rejects nesting deep enough to exhaust the stack of a recursive parser.
fn check_nesting(src: &str) -> Option<Error> {
    let bytes = src.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i < bytes.len() && !(bytes[i] == b'*' && bytes.get(i + 1) == Some(&b'/')) {
                    i += 1;
                }
                i += 1;
            }
            b'(' | b'[' | b'{' | b'?' => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Some(Error::TooDeep {
                        span: Span::new(i, i + 1).into(),
                        what: "brackets nest",
                        limit: MAX_NESTING,
                    });
                }
            }
            b')' | b']' | b'}' | b':' => depth = depth.saturating_sub(1),
            _ => {}
        }
        i += 1;
    }
    None
}

/// What a rule expects, in the words of a syntax error's "expected ...".
fn describe(rule: Rule) -> Option<&'static str> {
    describe_file(rule)
        .or_else(|| describe_world(rule))
        .or_else(|| describe_stage(rule))
        .or_else(|| describe_module(rule))
}

/// What is expected in the file's outline, in a `robot` or `genome`
/// declaration, and the words of every part: names, numbers, units.
fn describe_file(rule: Rule) -> Option<&'static str> {
    Some(match rule {
        Rule::EOI => "end of file",
        // pest reports the whole rule when the first item fails at the start.
        Rule::file => "`genome`, `robot` or `stage`",
        Rule::ident => "a name",
        Rule::integer => "a whole number",
        Rule::number | Rule::quantity => "a number",
        Rule::unsigned | Rule::literal => "a number",
        Rule::unit | Rule::unknown_unit => "a unit",
        Rule::range => "a range `lo..hi`",
        Rule::variants_aggregate => "`mean` or `min`",
        Rule::robot | Rule::robot_adds => "`robot`",
        Rule::genome => "`genome`",
        Rule::stage => "`stage`",
        Rule::extends => "`extends`",
        Rule::sensor_decl => "`sensor`",
        Rule::actuator_decl => "`actuator`",
        Rule::count => "`[`",
        Rule::gene_setting | Rule::bits_setting | Rule::k_bits => "`bits`",
        Rule::range_setting | Rule::k_range => "`range`",
        Rule::gene_group => "`links`, `weights` or `biases`",
        _ => return None,
    })
}

/// What is expected in a `world` and its items.
fn describe_world(rule: Rule) -> Option<&'static str> {
    Some(match rule {
        Rule::world => "`world`",
        Rule::world_mode => "`adds` or `changes`",
        Rule::arena => "`arena`",
        Rule::charger => "`charger`",
        Rule::lamp => "`with lamp`",
        Rule::battery => "`battery`",
        Rule::robots | Rule::k_robots => "`robots`",
        Rule::team | Rule::k_team => "`team`",
        Rule::recharge_time | Rule::k_recharge | Rule::recharge_step => "`recharge`",
        Rule::objects => "`objects`",
        Rule::diameter => "`diameter`",
        Rule::object_kind => "`physical` or `virtual`",
        Rule::body => "`body`",
        Rule::body_preset => "a body preset (`khepera` or `e-puck`)",
        Rule::sensor_layout | Rule::layout_kind => "`proximity` or `ground`",
        Rule::layout_at => "`at [...]`",
        Rule::layout_spot => "an angle or a point `(X, Y)`",
        Rule::layout_facing | Rule::k_facing => "`facing [...]`",
        Rule::inner_wall | Rule::k_wall => "`wall`",
        Rule::cylinder | Rule::k_cylinder => "`cylinder`",
        Rule::lamp_item | Rule::k_lamp => "`lamp`",
        Rule::zone | Rule::k_zone => "`zone`",
        Rule::start | Rule::k_start => "`start`",
        Rule::place | Rule::k_place => "`place`",
        Rule::place_after | Rule::k_after => "`after N actions`",
        Rule::item_name => "a name",
        Rule::k_from => "`from`",
        Rule::k_at => "`at`",
        Rule::point => "a point `(X, Y)`",
        Rule::lamp_height => "`height`",
        Rule::lamp_intensity => "`intensity`",
        Rule::zone_grey => "`grey`",
        Rule::zone_charger => "`charger`",
        Rule::heading => "`heading`",
        _ => return None,
    })
}

/// What is expected in a stage's settings, its run and its fitness.
fn describe_stage(rule: Rule) -> Option<&'static str> {
    Some(match rule {
        Rule::setting => "a setting",
        Rule::evolve => "`evolve`",
        Rule::selection => "`selection`",
        Rule::test_run => "`test`",
        Rule::train_run => "`train`",
        Rule::k_trained => "`trained`",
        Rule::test_learning => "`with learning` or `without learning`",
        Rule::test_lives => "a number of lives",
        Rule::k_lives => "`lives`",
        Rule::k_of => "`of`",
        Rule::fitness => "`fitness`",
        Rule::fitness_mode => "`adds`",
        Rule::per_action => "`per action`",
        Rule::at_end => "`at end`",
        Rule::bonus => "a bonus `N per EVENT`",
        Rule::k_outside => "`outside`",
        _ => return None,
    })
}

/// What is expected in a `module`, its behavior, learning and links, and
/// in an expression.
fn describe_module(rule: Rule) -> Option<&'static str> {
    Some(match rule {
        Rule::module => "`module`",
        Rule::sense => "`sense`",
        Rule::sensor_ref => "a sensor",
        Rule::index => "`[`",
        Rule::activation => "`activation`",
        Rule::weights_source => "`evolvable`, `fixed`, `random` or `trained`",
        Rule::k_evolvable => "`evolvable`",
        Rule::k_fixed => "`fixed`",
        Rule::k_random => "`random`",
        Rule::number_list => "`[`",
        Rule::hidden | Rule::k_hidden => "`hidden`",
        Rule::k_recurrent => "`recurrent`",
        Rule::behavior => "`behavior`",
        Rule::script => "`{`",
        Rule::commit => "`commit`",
        Rule::step => "a step",
        Rule::for_end => "`for`",
        Rule::until_end => "`until`",
        Rule::within => "`within`",
        Rule::uses_charger => "`uses charger`",
        Rule::step_if => "`if`",
        Rule::forward | Rule::k_forward => "`forward`",
        Rule::back | Rule::k_back => "`back`",
        Rule::turn | Rule::k_turn => "`turn`",
        Rule::bare_turn => "`left` or `right`",
        Rule::k_left => "`left`",
        Rule::k_right => "`right`",
        Rule::stop | Rule::k_stop => "`stop`",
        Rule::set_wheels => "a wheel command",
        Rule::speed => "`(`",
        Rule::toward | Rule::k_toward => "`toward`",
        Rule::wait | Rule::k_wait => "`wait`",
        Rule::reinforce_step | Rule::reinforce => "`reinforce`",
        Rule::set_actuator => "an actuator command",
        Rule::neural => "`neural`",
        Rule::outputs => "`outputs`",
        Rule::sign_outputs => "`sign`",
        Rule::linear_outputs => "`linear`",
        Rule::neural_weights => "`weights`",
        Rule::learn => "`learn`",
        Rule::rates => "`(`",
        Rule::learn_target => "`behavior` or `activation`",
        Rule::learn_error => "`difference` or `squared`",
        Rule::learn_when | Rule::k_always => "`always` or `when`",
        Rule::window => "`over`",
        Rule::role | Rule::k_role => "`role`",
        Rule::role_adds | Rule::k_adds => "`adds`",
        Rule::role_body => "`{`",
        Rule::links_all => "`links`",
        Rule::link => "`link`",
        Rule::k_all => "`all`",
        Rule::link_kind => "`evolvable` or `fixed`",
        Rule::expr | Rule::reference | Rule::call | Rule::state_ref | Rule::team_ref => "an expression",
        Rule::neg | Rule::not | Rule::prev => "an expression",
        Rule::add | Rule::sub | Rule::mul | Rule::div => "an operator",
        Rule::lt | Rule::le | Rule::gt | Rule::ge | Rule::eq | Rule::ne => "an operator",
        Rule::and | Rule::or | Rule::cond => "an operator",
        _ => return None,
    })
}

/// The token found at `pos`, for "found ..." labels.
fn token_at(src: &str, pos: usize) -> (Span, String) {
    let rest = &src[pos..];
    let Some(c) = rest.chars().next() else {
        return (Span::new(pos, pos), "end of file".into());
    };
    let len = if c.is_ascii_alphanumeric() || c == '_' {
        rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.')).unwrap_or(rest.len())
    } else {
        c.len_utf8()
    };
    let text = &rest[..len];
    let shown: String = text.chars().take(24).collect();
    let found = if c.is_control() { "a control character".to_string() } else { format!("`{shown}`") };
    (Span::new(pos, pos + len), found)
}

/// The words and punctuation a parse expected where a literal of the
/// grammar (`wall`, `->`, `}`) got further than any rule: pest reports
/// failed rules only, at the start of the rule around the literal, which
/// points at the wrong place (`charger` instead of the `wal` after it).
fn expected_literals(e: &pest::error::Error<Rule>, rule_pos: usize) -> Option<(usize, Vec<String>)> {
    let attempts = e.parse_attempts()?;
    if attempts.max_position <= rule_pos {
        return None;
    }
    // pest does not export its token type: its text is the literal, a
    // character range `a..z` or `BUILTIN_RULE`.
    let is_range = |t: &str| t.chars().count() == 4 && t.get(1..3) == Some("..");
    let mut tokens: Vec<String> = attempts
        .expected_tokens()
        .into_iter()
        .map(|t| t.to_string())
        // Whitespace, comments, and the characters that continue a name or
        // a number are not what the user missed.
        .filter(|t| {
            !(t.trim().is_empty()
                || is_range(t)
                || t == "BUILTIN_RULE"
                || t == "//"
                || t == "/*"
                || t == "-"
                || t == "."
                || (t.len() == 1 && t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')))
        })
        .map(|t| format!("`{t}`"))
        .collect();
    tokens.sort_unstable();
    tokens.dedup();
    (!tokens.is_empty()).then_some((attempts.max_position, tokens))
}

pub(super) fn syntax_error(src: &str, e: pest::error::Error<Rule>) -> Error {
    syntax_error_shifted(src, e, 0)
}

/// [`syntax_error`] for an error of a part of `src` parsed alone, whose
/// positions are `shift` bytes before their place in `src` (the recovery
/// parses a stage item wrapped in a stage of its own).
pub(super) fn syntax_error_shifted(src: &str, e: pest::error::Error<Rule>, shift: isize) -> Error {
    let pos = match e.location {
        pest::error::InputLocation::Pos(p) => p,
        pest::error::InputLocation::Span((a, _)) => a,
    };
    let literals = expected_literals(&e, pos);
    let place = |p: usize| p.saturating_add_signed(shift);
    let mut pos = place(literals.as_ref().map_or(pos, |(p, _)| *p)).min(src.len());
    // A literal that matched the start of a word (`l` of `left` in `link`)
    // leaves the position inside it: the word is what was found.
    let bytes = src.as_bytes();
    let word_char = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    while pos > 0
        && pos < src.len()
        && word_char(bytes[pos])
        && (bytes[pos - 1].is_ascii_alphabetic() || bytes[pos - 1] == b'_')
    {
        pos -= 1;
    }
    let (mut span, found) = token_at(src, pos);
    if pos == src.len() {
        // Point at the last token, so that the label shows.
        let end = src.trim_end().len();
        let start = src[..end].char_indices().next_back().map(|(i, _)| i).unwrap_or(0);
        span = Span::new(start, end.max(start));
    }
    let expected = match (&e.variant, literals) {
        (pest::error::ErrorVariant::CustomError { message }, _) => {
            return Error::TooComplex { span: span.into(), reason: message.to_lowercase() };
        }
        (_, Some((_, tokens))) => one_of(tokens.iter().map(String::as_str).collect()),
        (pest::error::ErrorVariant::ParsingError { positives, .. }, None) => {
            let mut names: Vec<&str> = positives.iter().filter_map(|r| describe(*r)).collect();
            names.sort_unstable();
            names.dedup();
            one_of(names)
        }
    };
    if let Some(e) = super::brackets::unclosed(src, pos, span, &found) {
        return e;
    }
    let word = found.trim_matches('`');
    let operand = expected.contains("an expression");
    let help = if RESERVED.contains(&word) && operand && super::brackets::CLAUSE_WORDS.contains(&word) {
        Some(format!("the expression before `{word}` is not finished: an operand is missing"))
    } else if RESERVED.contains(&word) && expected.contains("a name") && !operand {
        Some(format!("`{word}` is a reserved word; choose another name"))
    } else if pos == src.len() {
        Some("the file ends too early: is a `}` or `)` missing?".to_string())
    } else if expected == "`(`" {
        table_entry_help(src, pos, word)
    } else if expected == "`at`" || expected == "`from`" {
        world_item_help(src, pos, &expected)
    } else {
        misspelt_keyword(word, &expected)
    };
    Error::Syntax {
        span: span.into(),
        message: format!("expected {expected}, found {found}"),
        label: "unexpected here".into(),
        others: Vec::new(),
        help,
    }
}

/// The forms of the world items placed by a point.
const PLACED_ITEMS: [(&str, &str); 6] = [
    ("lamp", "lamp [NAME] at (X, Y) [height H] [intensity K]"),
    ("cylinder", "cylinder [NAME] at (X, Y) diameter D"),
    ("wall", "wall [NAME] from (X, Y) to (X, Y)"),
    ("zone", "zone [NAME] from (X, Y) to (X, Y) [grey G] [charger]"),
    ("start", "start at (X, Y) [heading A]` or `start from (X, Y) to (X, Y) [heading A]"),
    ("place", "place [NAME] at (X, Y) heading A after N actions"),
];

/// A world item without its position (`lamp sun intensity 0.5`), where the
/// parse expected `at` or `from` (`expected`) at `pos`: its form, and in
/// `world changes`, that a change restates the whole item.
fn world_item_help(src: &str, pos: usize, expected: &str) -> Option<String> {
    let words: Vec<&str> = src[..pos].split_whitespace().rev().take(2).collect();
    let (kw, name) = match words[..] {
        [n, k, ..] if PLACED_ITEMS.iter().any(|(w, _)| *w == k) => (k, Some(n)),
        [k, ..] => (k, None),
        [] => return None,
    };
    let form = PLACED_ITEMS.iter().find(|(w, _)| *w == kw)?.1;
    if super::brackets::innermost_block(src, pos).as_deref() != Some("the `world changes` block") {
        return Some(format!("a {kw} is written `{form}`"));
    }
    // The rest of the item as written, up to the end of the block or line.
    let rest = &src[pos..];
    let rest = rest[..rest.find(['}', '\n']).unwrap_or(rest.len())].trim();
    let point = if kw == "start" { "at" } else { expected.trim_matches('`') };
    let name = name.map(|n| format!(" {n}")).unwrap_or_default();
    let example = format!("{kw}{name} {point} (X, Y) {rest}");
    Some(format!(
        "`world changes` replaces an item whole, so a change restates it with its position: `{}`",
        example.trim_end()
    ))
}

/// A word one or two edits from a word the parse expected (`wrold` where
/// `world` may stand): "did you mean `world`?".
fn misspelt_keyword(word: &str, expected: &str) -> Option<String> {
    if word.is_empty() || !word.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return None;
    }
    let words = expected.split('`').skip(1).step_by(2).filter(|w| w.chars().all(|c| c.is_ascii_alphabetic()));
    let units = if expected.contains("a unit") { &["actions", "action"][..] } else { &[] };
    // Of candidates as far from the word, a swap of neighbours (`wrold`) is
    // the likelier slip: the closest by that count first.
    let mut candidates: Vec<&str> = words.chain(units.iter().copied()).filter(|w| *w != word).collect();
    candidates.sort_by_key(|w| strsim::osa_distance(word, w));
    crate::diag::did_you_mean(word, candidates)
}

/// A decoding table's entry that is no wheel motion (`sign(2) -> forward |
/// arm down`) reads as the start of `NAME(l, r)`, so the parse expects `(`:
/// say what a table holds. `pos` is where `(` was expected, `word` what is
/// there.
fn table_entry_help(src: &str, pos: usize, word: &str) -> Option<String> {
    let before = src[..pos].trim_end();
    let start = before.rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).map_or(0, |i| i + 1);
    let name = &before[start..];
    let after = before[..start].trim_end();
    if name.is_empty() || !(after.ends_with('|') || after.ends_with("->")) {
        return None;
    }
    let entry = if !word.is_empty() && word.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        format!("{name} {word}")
    } else {
        name.to_string()
    };
    Some(format!(
        "a decoding table holds only wheel motions: `forward`, `back`, `left`, `right`, `turn left`, `turn right`, `stop` (each with an optional speed) or the two speeds of the `speed` actuator, as in `wheels(1, -0.5)`; `{entry}` is not one"
    ))
}

/// `a`, `a or b`, `a, b or c`.
fn one_of(names: Vec<&str>) -> String {
    match names.len() {
        0 => "something else".to_string(),
        1 => names[0].to_string(),
        n => format!("{} or {}", names[..n - 1].join(", "), names[n - 1]),
    }
}

/// The span of a pair, without the whitespace a trailing optional part
/// may have skipped.
fn span(p: &Pair<Rule>) -> Span {
    let s = p.as_span();
    Span::new(s.start(), s.start() + p.as_str().trim_end().len())
}

fn name(p: Pair<Rule>) -> Name {
    Name { text: p.as_str().to_string(), span: span(&p) }
}

fn num(p: &Pair<Rule>) -> f64 {
    p.as_str().parse::<f64>().unwrap_or(f64::NAN)
}

fn int(p: &Pair<Rule>) -> u64 {
    p.as_str().parse::<u64>().unwrap_or(u64::MAX)
}

fn unit(p: &Pair<Rule>) -> Unit {
    match p.as_str() {
        "mm" => Unit::Mm,
        "cm" => Unit::Cm,
        "ms" => Unit::Ms,
        "deg" => Unit::Deg,
        "rad" => Unit::Rad,
        _ => Unit::Actions,
    }
}

fn quantity(p: Pair<Rule>) -> Quantity {
    let sp = span(&p);
    let mut it = p.into_inner();
    let value = it.next().map(|n| num(&n)).unwrap_or(f64::NAN);
    // An unknown unit is reported on its own: the number is read bare.
    let unit = it.next().filter(|u| u.as_rule() == Rule::unit).map(|u| unit(&u));
    Quantity { value, unit, span: sp }
}

fn range(p: Pair<Rule>) -> Range {
    let sp = span(&p);
    let mut it = p.into_inner();
    let lo = it.next().map(|n| num(&n)).unwrap_or(f64::NAN);
    let hi = it.next().map(|n| num(&n)).unwrap_or(f64::NAN);
    Range { lo, hi, span: sp }
}

fn index(p: Pair<Rule>) -> Index {
    let sp = span(&p);
    let mut it = p.into_inner();
    let first = it.next().map(|n| int(&n)).unwrap_or(0);
    let last = it.next().map(|n| int(&n));
    Index { first, last, span: sp }
}

fn sensor_ref(p: Pair<Rule>) -> SensorRef {
    let sp = span(&p);
    let mut it = p.into_inner();
    let n = it.next().map(name).unwrap_or(Name { text: String::new(), span: sp });
    SensorRef { name: n, index: it.next().map(index), span: sp }
}

fn hardware(p: Pair<Rule>) -> Hardware {
    let sp = span(&p);
    let is_sensor = p.as_rule() == Rule::sensor_decl;
    let mut n = None;
    let mut count = None;
    let mut kind = None;
    for c in p.into_inner() {
        match c.as_rule() {
            Rule::ident if n.is_none() => n = Some(name(c)),
            Rule::ident => kind = Some(name(c)),
            Rule::count => {
                let s = span(&c);
                count = c.into_inner().next().map(|i| (int(&i), s));
            }
            _ => {}
        }
    }
    let blank = Name { text: String::new(), span: sp };
    Hardware { is_sensor, name: n.unwrap_or(blank.clone()), count, kind: kind.unwrap_or(blank), span: sp }
}

fn speed(p: Option<Pair<Rule>>) -> Option<f64> {
    p.and_then(|s| s.into_inner().next()).map(|n| num(&n))
}

fn motion(p: Pair<Rule>) -> Motion {
    let rule = p.as_rule();
    let mut it = p.into_inner();
    match rule {
        Rule::forward => {
            it.next();
            Motion::Forward(speed(it.next()))
        }
        Rule::back => {
            it.next();
            Motion::Back(speed(it.next()))
        }
        Rule::turn | Rule::bare_turn => {
            if rule == Rule::turn {
                it.next();
            }
            let left = it.next().map(|d| d.as_rule() == Rule::k_left).unwrap_or(true);
            let v = speed(it.next());
            if left {
                Motion::TurnLeft(v)
            } else {
                Motion::TurnRight(v)
            }
        }
        Rule::set_wheels => {
            let n = it.next().map(name).unwrap_or(Name { text: String::new(), span: Span::default() });
            Motion::Wheels(n, it.map(|x| num(&x)).collect())
        }
        _ => Motion::Stop,
    }
}

fn weight_source(p: Pair<Rule>) -> WeightSource {
    let sp = span(&p);
    let mut it = p.into_inner();
    let head = it.next();
    match head.as_ref().map(|h| h.as_rule()) {
        Some(Rule::k_fixed) => {
            let vals = match it.next() {
                Some(v) if v.as_rule() == Rule::number_list => v.into_inner().map(|n| num(&n)).collect(),
                Some(v) => vec![num(&v)],
                None => vec![],
            };
            WeightSource::Fixed(vals, sp)
        }
        Some(Rule::k_random) => {
            let r = it.next().map(range).unwrap_or(Range { lo: -1.0, hi: 1.0, span: sp });
            WeightSource::Random(r, sp)
        }
        Some(Rule::k_trained) => match it.next() {
            Some(n) => WeightSource::Trained(name(n), sp),
            None => WeightSource::Trained(Name { text: String::new(), span: sp }, sp),
        },
        _ => WeightSource::Evolvable(sp),
    }
}

struct Builder {
    pratt: PrattParser<Rule>,
    errors: Vec<Error>,
}

impl Builder {
    /// Reports an option given again in one block (`hidden 1 hidden 2`):
    /// the AST keeps one of each, so the later one would silently win.
    fn once(&mut self, seen: &mut Vec<(Rule, Span)>, what: &'static str, p: &Pair<Rule>) {
        let name = match p.as_rule() {
            Rule::weights_source | Rule::neural_weights => "weights",
            Rule::hidden => "hidden",
            Rule::range_setting => "range",
            Rule::sense => "sense",
            Rule::outputs => "outputs",
            Rule::neural_broadcast => "broadcast",
            _ => return,
        };
        let key = if p.as_rule() == Rule::neural_weights { Rule::weights_source } else { p.as_rule() };
        match seen.iter().find(|(r, _)| *r == key) {
            Some((_, first)) => self.errors.push(Error::Duplicate {
                span: span(p).into(),
                first: (*first).into(),
                what,
                name: name.into(),
            }),
            None => seen.push((key, span(p))),
        }
    }

    fn file(&mut self, p: Pair<Rule>) -> File {
        let mut f = File { robots: vec![], genomes: vec![], stages: vec![] };
        for item in p.into_inner() {
            match item.as_rule() {
                Rule::robot => {
                    let sp = span(&item);
                    let mut it = item.into_inner();
                    let n = it.next().map(name).unwrap_or(Name { text: String::new(), span: sp });
                    f.robots.push(Robot { name: n, hardware: it.map(hardware).collect(), span: sp });
                }
                Rule::genome => f.genomes.push(genome(item)),
                Rule::stage => {
                    let s = self.stage(item);
                    f.stages.push(s);
                }
                _ => {}
            }
        }
        f
    }

    fn stage(&mut self, p: Pair<Rule>) -> StageDecl {
        let sp = span(&p);
        let mut it = p.into_inner().peekable();
        let n = it.next().map(name).unwrap_or(Name { text: String::new(), span: sp });
        let mut extends = None;
        let mut items = Vec::new();
        for c in it {
            let csp = span(&c);
            match c.as_rule() {
                Rule::extends => extends = c.into_inner().next().map(name),
                Rule::robot_adds => {
                    items.push(StageItem::RobotAdds(c.into_inner().map(hardware).collect(), csp))
                }
                Rule::genome => items.push(StageItem::Genome(genome(c))),
                Rule::world => items.push(StageItem::World(world(c))),
                Rule::variants => items.push(StageItem::Variants(variants(c))),
                Rule::evolve => items.push(StageItem::Evolve(c.into_inner().map(setting).collect(), csp)),
                Rule::train_run => {
                    let actions = c.into_inner().next().map(quantity).unwrap_or(Quantity {
                        value: 0.0,
                        unit: None,
                        span: csp,
                    });
                    items.push(StageItem::Train { actions, span: csp });
                }
                Rule::test_run => {
                    let mut ti = c.into_inner().peekable();
                    // `10 lives of`: the number, as a quantity with no unit.
                    let lives = ti.next_if(|p| p.as_rule() == Rule::test_lives).and_then(|p| {
                        let n = p.into_inner().next()?;
                        Some(Quantity { value: num(&n), unit: None, span: span(&n) })
                    });
                    let actions =
                        ti.next().map(quantity).unwrap_or(Quantity { value: 0.0, unit: None, span: csp });
                    let learning = ti.next().map(|l| !l.as_str().starts_with("without")).unwrap_or(true);
                    items.push(StageItem::Test { lives, actions, learning, span: csp });
                }
                Rule::fitness => {
                    let fit = self.fitness(c);
                    items.push(StageItem::Fitness(fit));
                }
                Rule::role => {
                    let mut ri = c
                        .into_inner()
                        .filter(|p| p.as_rule() != Rule::k_role && p.as_rule() != Rule::k_robots);
                    let blank = Name { text: String::new(), span: csp };
                    let role_name = ri.next().map(name).unwrap_or(blank);
                    let (mut robots, mut adds, mut body) = (None, false, None);
                    let mut head_end = role_name.span.end;
                    for p in ri {
                        match p.as_rule() {
                            Rule::quantity => {
                                let q = quantity(p);
                                head_end = q.span.end;
                                robots = Some(q);
                            }
                            Rule::role_adds => {
                                adds = true;
                                for q in p.into_inner() {
                                    match q.as_rule() {
                                        Rule::k_adds => head_end = span(&q).end,
                                        Rule::role_body => body = Some(q),
                                        _ => {}
                                    }
                                }
                            }
                            Rule::role_body => body = Some(p),
                            _ => {}
                        }
                    }
                    let has_body = body.is_some();
                    let role_items = body
                        .map(|b| b.into_inner().filter_map(|p| self.role_item(p)).collect())
                        .unwrap_or_default();
                    items.push(StageItem::Role(RoleDecl {
                        name: role_name,
                        robots,
                        adds,
                        body: has_body,
                        items: role_items,
                        span: csp,
                        head: Span { start: csp.start, end: head_end.max(csp.start) },
                    }));
                }
                Rule::module | Rule::links_all | Rule::link => items.extend(self.role_item(c)),
                _ => {}
            }
        }
        StageDecl { name: n, extends, items, span: sp }
    }

    /// A module, `links all` or `link` (of a stage or of a role).
    fn role_item(&mut self, c: Pair<Rule>) -> Option<StageItem> {
        let csp = span(&c);
        match c.as_rule() {
            Rule::module => Some(StageItem::Module(self.module(c))),
            Rule::fitness => Some(StageItem::Fitness(self.fitness(c))),
            Rule::links_all => {
                let kind = c.into_inner().nth(1).map(link_kind).unwrap_or(LinkKind::Evolvable(None));
                Some(StageItem::LinksAll(kind, csp))
            }
            Rule::link => {
                let mut li = c.into_inner();
                let blank = Name { text: String::new(), span: csp };
                let from = li.next().map(name).unwrap_or(blank.clone());
                let to = li.next().map(name).unwrap_or(blank);
                let kind = li.next().map(link_kind).unwrap_or(LinkKind::Evolvable(None));
                Some(StageItem::Link(LinkDecl { from, to, kind, span: csp }))
            }
            _ => None,
        }
    }

    fn fitness(&mut self, p: Pair<Rule>) -> FitnessDecl {
        let sp = span(&p);
        let mut f = FitnessDecl {
            adds: false,
            per_action: vec![],
            at_end: vec![],
            bonuses: vec![],
            team: vec![],
            span: sp,
        };
        for c in p.into_inner() {
            let csp = span(&c);
            match c.as_rule() {
                Rule::fitness_mode => f.adds = true,
                Rule::per_action => {
                    if let Some(e) = c.into_inner().next() {
                        let e = self.expr(e);
                        f.per_action.push(e);
                    }
                }
                Rule::at_end => {
                    if let Some(e) = c.into_inner().find(|x| x.as_rule() == Rule::expr) {
                        let e = self.expr(e);
                        f.at_end.push(e);
                    }
                }
                Rule::bonus => {
                    let mut bi = c.into_inner();
                    let points = bi.next().map(|n| num(&n)).unwrap_or(0.0);
                    let mut ev = bi.next().map(name).unwrap_or(Name { text: String::new(), span: csp });
                    if let Some(o) = bi.next() {
                        ev.text.push_str(" outside");
                        ev.span = ev.span.to(span(&o));
                    }
                    f.bonuses.push(BonusDecl { points, event: ev, span: csp });
                }
                Rule::team => {
                    if let Some(w) = c.into_inner().nth(1) {
                        f.team.push((name(w), csp));
                    }
                }
                _ => {}
            }
        }
        f
    }

    fn module(&mut self, p: Pair<Rule>) -> ModuleDecl {
        let sp = span(&p);
        let mut it = p.into_inner();
        let n = it.next().map(name).unwrap_or(Name { text: String::new(), span: sp });
        let mut items = Vec::new();
        for c in it {
            let csp = span(&c);
            match c.as_rule() {
                Rule::sense => items.push(ModuleItem::Sense(c.into_inner().map(sensor_ref).collect(), csp)),
                Rule::activation => {
                    let mut a = ActivationDecl {
                        source: None,
                        hidden: None,
                        recurrent: false,
                        range: None,
                        span: csp,
                    };
                    let mut seen = Vec::new();
                    for o in c.into_inner() {
                        self.once(&mut seen, "activation option", &o);
                        match o.as_rule() {
                            Rule::weights_source => a.source = Some(weight_source(o)),
                            Rule::hidden => {
                                let mut h = o.into_inner();
                                a.hidden = h.nth(1).map(quantity);
                                a.recurrent = h.next().is_some();
                            }
                            Rule::range_setting => a.range = o.into_inner().nth(1).map(range),
                            _ => {}
                        }
                    }
                    items.push(ModuleItem::Activation(a));
                }
                Rule::behavior => {
                    if let Some(b) = c.into_inner().next() {
                        let bsp = span(&b);
                        let decl = match b.as_rule() {
                            Rule::neural => BehaviorDecl::Neural(self.neural(b)),
                            Rule::script => {
                                let mut commit = false;
                                let mut steps = Vec::new();
                                for s in b.into_inner() {
                                    if s.as_rule() == Rule::commit {
                                        commit = true;
                                    } else {
                                        steps.push(self.step(s));
                                    }
                                }
                                BehaviorDecl::Script(steps, commit, bsp)
                            }
                            _ => BehaviorDecl::Script(vec![self.step(b)], false, bsp),
                        };
                        items.push(ModuleItem::Behavior(decl));
                    }
                }
                Rule::learn => items.push(ModuleItem::Learn(learn(c))),
                Rule::reinforce => {
                    if let Some(e) = c.into_inner().next() {
                        let e = self.expr(e);
                        items.push(ModuleItem::Reinforce(e, csp));
                    }
                }
                _ => {}
            }
        }
        ModuleDecl { name: n, items, span: sp }
    }

    fn neural(&mut self, p: Pair<Rule>) -> NeuralDecl {
        let sp = span(&p);
        let mut n = NeuralDecl {
            sense: None,
            hidden: None,
            recurrent: false,
            outputs: None,
            broadcast: None,
            weights: None,
            span: sp,
        };
        let mut seen = Vec::new();
        for c in p.into_inner() {
            let csp = span(&c);
            self.once(&mut seen, "neural option", &c);
            match c.as_rule() {
                Rule::sense => n.sense = Some((c.into_inner().map(sensor_ref).collect(), csp)),
                Rule::hidden => {
                    let mut h = c.into_inner();
                    n.hidden = h.nth(1).map(quantity);
                    n.recurrent = h.next().is_some();
                }
                Rule::neural_weights => n.weights = c.into_inner().next().map(weight_source),
                Rule::neural_broadcast => n.broadcast = c.into_inner().nth(1).map(|x| Box::new(name(x))),
                Rule::outputs => {
                    if let Some(o) = c.into_inner().next() {
                        let osp = span(&o);
                        n.outputs = Some(if o.as_rule() == Rule::sign_outputs {
                            let mut oi = o.into_inner();
                            let count = oi.next().map(quantity).unwrap_or(Quantity {
                                value: 0.0,
                                unit: None,
                                span: osp,
                            });
                            let table = oi
                                .map(|m| {
                                    let ms = span(&m);
                                    (motion(m), ms)
                                })
                                .collect();
                            OutputsDecl::Sign { count, table, span: osp }
                        } else {
                            OutputsDecl::Linear { scale: o.into_inner().next().map(|x| num(&x)), span: osp }
                        });
                    }
                }
                _ => {}
            }
        }
        n
    }

    fn step(&mut self, p: Pair<Rule>) -> StepDecl {
        let sp = span(&p);
        let mut it = p.into_inner();
        let action = match it.next() {
            Some(a) => self.action(a),
            None => ActionDecl::Wait(sp),
        };
        let mut end = None;
        let mut uses_charger = None;
        let mut cond = None;
        for c in it {
            match c.as_rule() {
                Rule::for_end => {
                    end = c.into_inner().next().map(quantity).map(EndDecl::For);
                }
                Rule::until_end => {
                    let usp = span(&c);
                    let mut ui = c.into_inner();
                    let cond = match ui.next() {
                        Some(e) => self.expr(e),
                        None => Expr { kind: ExprKind::Number(0.0, None), span: usp },
                    };
                    let within = ui.next().and_then(|w| w.into_inner().next()).map(quantity);
                    end = Some(EndDecl::Until { cond, within, span: usp });
                }
                Rule::uses_charger => uses_charger = Some(span(&c)),
                Rule::step_if => {
                    let isp = span(&c);
                    cond = Some(match c.into_inner().next() {
                        Some(e) => self.expr(e),
                        None => Expr { kind: ExprKind::Number(0.0, None), span: isp },
                    });
                }
                _ => {}
            }
        }
        StepDecl { action, end, uses_charger, cond, span: sp }
    }

    fn action(&mut self, p: Pair<Rule>) -> ActionDecl {
        let sp = span(&p);
        match p.as_rule() {
            Rule::forward | Rule::back | Rule::turn | Rule::stop | Rule::set_wheels => {
                ActionDecl::Motion(motion(p), sp)
            }
            Rule::toward => {
                let mut refs = Vec::new();
                let mut speed = None;
                for c in p.into_inner() {
                    match c.as_rule() {
                        Rule::sensor_ref => refs.push(sensor_ref(c)),
                        Rule::number => speed = Some(num(&c)),
                        _ => {}
                    }
                }
                ActionDecl::Toward { refs, speed, span: sp }
            }
            Rule::wait => ActionDecl::Wait(sp),
            Rule::recharge_step => ActionDecl::Recharge(sp),
            Rule::reinforce_step => match p.into_inner().next() {
                Some(e) => {
                    let e = self.expr(e);
                    ActionDecl::Reinforce(e, sp)
                }
                None => ActionDecl::Wait(sp),
            },
            _ => {
                let mut it = p.into_inner();
                let blank = Name { text: String::new(), span: sp };
                let actuator = it.next().map(name).unwrap_or(blank);
                let state = it.next().map(name);
                ActionDecl::Set { actuator, state, span: sp }
            }
        }
    }

    /// Converts a top-level expression, refusing oversized ones before any
    /// recursion over them.
    fn expr(&mut self, p: Pair<Rule>) -> Expr {
        let sp = span(&p);
        if p.clone().into_inner().flatten().count() > MAX_EXPR_NODES {
            self.errors.push(Error::TooLarge { span: sp.into(), limit: MAX_EXPR_NODES });
            return Expr { kind: ExprKind::Number(0.0, None), span: sp };
        }
        expr_inner(&self.pratt, p)
    }
}

fn expr_inner(pratt: &PrattParser<Rule>, p: Pair<Rule>) -> Expr {
    pratt
        .map_primary(|prim| primary(pratt, prim))
        .map_prefix(|op, rhs| {
            let sp = span(&op).to(rhs.span);
            let u = match op.as_rule() {
                Rule::neg => UnOp::Neg,
                Rule::not => UnOp::Not,
                _ => UnOp::Prev,
            };
            Expr { kind: ExprKind::Unary(u, Box::new(rhs)), span: sp }
        })
        .map_infix(|lhs, op, rhs| {
            let sp = lhs.span.to(rhs.span);
            let b = match op.as_rule() {
                Rule::add => BinOp::Add,
                Rule::sub => BinOp::Sub,
                Rule::mul => BinOp::Mul,
                Rule::div => BinOp::Div,
                Rule::lt => BinOp::Lt,
                Rule::le => BinOp::Le,
                Rule::gt => BinOp::Gt,
                Rule::ge => BinOp::Ge,
                Rule::eq => BinOp::Eq,
                Rule::ne => BinOp::Ne,
                Rule::and => BinOp::And,
                Rule::or => BinOp::Or,
                _ => {
                    let then = match op.into_inner().next() {
                        Some(e) => expr_inner(pratt, e),
                        None => Expr { kind: ExprKind::Number(0.0, None), span: sp },
                    };
                    return Expr {
                        kind: ExprKind::Cond(Box::new(lhs), Box::new(then), Box::new(rhs)),
                        span: sp,
                    };
                }
            };
            Expr { kind: ExprKind::Binary(b, Box::new(lhs), Box::new(rhs)), span: sp }
        })
        .parse(p.into_inner())
}

fn primary(pratt: &PrattParser<Rule>, p: Pair<Rule>) -> Expr {
    let sp = span(&p);
    match p.as_rule() {
        Rule::expr => expr_inner(pratt, p),
        Rule::call => {
            let mut it = p.into_inner();
            let f = it.next().map(name).unwrap_or(Name { text: String::new(), span: sp });
            let args = it.map(|a| expr_inner(pratt, a)).collect();
            Expr { kind: ExprKind::Call(f, args), span: sp }
        }
        Rule::state_ref => {
            let field = p.into_inner().next().map(name).unwrap_or(Name { text: String::new(), span: sp });
            Expr { kind: ExprKind::State(field), span: sp }
        }
        Rule::team_ref => {
            let field = p.into_inner().next().map(name).unwrap_or(Name { text: String::new(), span: sp });
            Expr { kind: ExprKind::Team(field), span: sp }
        }
        Rule::literal => {
            let mut it = p.into_inner();
            let v = it.next().map(|n| num(&n)).unwrap_or(0.0);
            let u = it.next().map(|u| unit(&u));
            Expr { kind: ExprKind::Number(v, u), span: sp }
        }
        _ => {
            let mut it = p.into_inner();
            let n = it.next().map(name).unwrap_or(Name { text: String::new(), span: sp });
            Expr { kind: ExprKind::Ref(n, it.next().map(index)), span: sp }
        }
    }
}

fn genome(p: Pair<Rule>) -> GenomeBlock {
    let sp = span(&p);
    let settings = p
        .into_inner()
        .map(|s| {
            let ssp = span(&s);
            let mut g = GeneSetting { group: None, bits: None, range: None, span: ssp };
            for c in s.into_inner() {
                match c.as_rule() {
                    Rule::gene_group => g.group = Some(name(c)),
                    Rule::bits_setting => g.bits = c.into_inner().nth(1).map(quantity),
                    Rule::range_setting => g.range = c.into_inner().nth(1).map(range),
                    _ => {}
                }
            }
            g
        })
        .collect();
    GenomeBlock { settings, span: sp }
}

fn world(p: Pair<Rule>) -> WorldBlock {
    let sp = span(&p);
    let mut mode = WorldMode::Set;
    let mut items = Vec::new();
    for c in p.into_inner() {
        let csp = span(&c);
        match c.as_rule() {
            Rule::world_mode => {
                mode = if c.as_str() == "adds" { WorldMode::Adds } else { WorldMode::Changes }
            }
            Rule::arena => {
                let mut it = c.into_inner();
                let q0 = Quantity { value: 0.0, unit: None, span: csp };
                let width = it.next().map(quantity).unwrap_or(q0.clone());
                let depth = it.next().map(quantity).unwrap_or(q0);
                items.push(WorldItem::Arena { width, depth, span: csp });
            }
            Rule::charger => {
                let mut it = c.into_inner();
                let length =
                    it.next().map(quantity).unwrap_or(Quantity { value: 0.0, unit: None, span: csp });
                let wall = it.next().map(name).unwrap_or(Name { text: String::new(), span: csp });
                let lamp = it.next().map(|l| l.into_inner().next().map(quantity));
                items.push(WorldItem::Charger { length, wall, lamp, span: csp });
            }
            Rule::battery => {
                if let Some(q) = c.into_inner().next() {
                    items.push(WorldItem::Battery(quantity(q), csp));
                }
            }
            Rule::recharge_time => {
                if let Some(q) = c.into_inner().nth(1) {
                    items.push(WorldItem::Recharge(quantity(q), csp));
                }
            }
            Rule::robots => {
                if let Some(q) = c.into_inner().nth(1) {
                    items.push(WorldItem::Robots(quantity(q), csp));
                }
            }
            Rule::role_robots => {
                let mut ri = c.into_inner().filter(|p| matches!(p.as_rule(), Rule::ident | Rule::quantity));
                if let (Some(n), Some(q)) = (ri.next(), ri.next()) {
                    items.push(WorldItem::RoleRobots { name: name(n), robots: quantity(q), span: csp });
                }
            }
            Rule::objects => {
                let mut count = None;
                let mut diameter = None;
                let mut virtual_ = None;
                for o in c.into_inner() {
                    match o.as_rule() {
                        Rule::quantity => count = Some(quantity(o)),
                        Rule::diameter => diameter = o.into_inner().next().map(quantity),
                        Rule::object_kind => virtual_ = Some(o.as_str() == "virtual"),
                        _ => {}
                    }
                }
                items.push(WorldItem::Objects { count, diameter, virtual_, span: csp });
            }
            Rule::body => {
                let mut preset = None;
                let mut body = Vec::new();
                for o in c.into_inner() {
                    match o.as_rule() {
                        Rule::body_preset => preset = Some(name(o)),
                        Rule::sensor_layout => body.push(BodyItem::Layout(sensor_layout(o))),
                        _ => body.push(BodyItem::Setting(setting(o))),
                    }
                }
                items.push(WorldItem::Body { preset, items: body, span: csp });
            }
            Rule::inner_wall | Rule::cylinder | Rule::lamp_item | Rule::zone | Rule::start | Rule::place => {
                items.push(placed_item(c))
            }
            _ => {}
        }
    }
    WorldBlock { mode, items, span: sp }
}

/// A placed world item: `wall`, `cylinder`, `lamp`, `zone`, `start` or
/// `place`, with its name, points and settings.
fn placed_item(c: Pair<Rule>) -> WorldItem {
    let csp = span(&c);
    let rule = c.as_rule();
    let mut name_ = None;
    let mut points = Vec::new();
    let (mut diameter, mut height, mut intensity, mut grey, mut heading) = (None, None, None, None, None);
    let mut switch = None;
    let mut after = None;
    let mut charger = false;
    for o in c.into_inner() {
        match o.as_rule() {
            Rule::item_name => name_ = o.into_inner().next().map(name),
            Rule::point => {
                let mut q = o.into_inner().map(quantity);
                let q0 = Quantity { value: 0.0, unit: None, span: csp };
                let x = q.next().unwrap_or(q0.clone());
                let y = q.next().unwrap_or(q0);
                points.push(Point { x, y });
            }
            Rule::diameter => diameter = o.into_inner().next().map(quantity),
            Rule::lamp_height => height = o.into_inner().next().map(quantity),
            Rule::lamp_intensity => intensity = o.into_inner().next().map(quantity),
            Rule::lamp_switch => {
                let mut it = o.into_inner();
                let on = it.next().is_some_and(|w| w.as_str() == "on");
                switch = it.find(|q| q.as_rule() == Rule::quantity).map(|q| (on, quantity(q)));
            }
            Rule::zone_grey => grey = o.into_inner().next().map(quantity),
            Rule::zone_charger => charger = true,
            Rule::heading => heading = o.into_inner().next().map(quantity),
            Rule::place_after => after = o.into_inner().find(|q| q.as_rule() == Rule::quantity).map(quantity),
            _ => {}
        }
    }
    let q0 = Quantity { value: 0.0, unit: None, span: csp };
    let p0 = Point { x: q0.clone(), y: q0.clone() };
    let mut points = points.into_iter();
    let first = points.next().unwrap_or(p0.clone());
    let second = points.next();
    match rule {
        Rule::inner_wall => WorldItem::Wall { name: name_, from: first, to: second.unwrap_or(p0), span: csp },
        Rule::cylinder => {
            WorldItem::Cylinder { name: name_, at: first, diameter: diameter.unwrap_or(q0), span: csp }
        }
        Rule::lamp_item => WorldItem::Lamp { name: name_, at: first, height, intensity, switch, span: csp },
        Rule::zone => {
            WorldItem::Zone { name: name_, from: first, to: second.unwrap_or(p0), grey, charger, span: csp }
        }
        Rule::place => WorldItem::Place {
            name: name_,
            at: first,
            heading: heading.unwrap_or(q0.clone()),
            after: after.unwrap_or(q0),
            span: csp,
        },
        _ => WorldItem::Start { from: first, to: second, heading, span: csp },
    }
}

/// `learn crbp(RATE, RATE[, error ERROR]) on TARGET always|when ... [over N]`.
fn learn(c: Pair<Rule>) -> LearnDecl {
    let csp = span(&c);
    let mut l = LearnDecl {
        rates: None,
        error: None,
        target: Name { text: String::new(), span: csp },
        below: None,
        window: None,
        span: csp,
    };
    for o in c.into_inner() {
        match o.as_rule() {
            Rule::rates => {
                let rs = span(&o);
                let mut v: Vec<f64> = Vec::new();
                for n in o.into_inner() {
                    match n.as_rule() {
                        Rule::learn_error => l.error = Some(name(n)),
                        _ => v.push(num(&n)),
                    }
                }
                if v.len() == 2 {
                    l.rates = Some((v[0], v[1], rs));
                }
            }
            Rule::learn_target => l.target = name(o),
            Rule::learn_when => {
                l.below = o.into_inner().find(|x| x.as_rule() == Rule::number).map(|n| num(&n))
            }
            Rule::window => l.window = o.into_inner().next().map(quantity),
            _ => {}
        }
    }
    l
}

/// `proximity at [...] facing [...]`, `ground at [...]`.
fn sensor_layout(p: Pair<Rule>) -> SensorLayout {
    let sp = span(&p);
    let mut kind = Name { text: String::new(), span: sp };
    let (mut at, mut facing) = (None, None);
    for o in p.into_inner() {
        let osp = span(&o);
        match o.as_rule() {
            Rule::layout_kind => kind = name(o),
            Rule::layout_at => {
                let spots = o
                    .into_inner()
                    .filter(|s| s.as_rule() == Rule::layout_spot)
                    .filter_map(|s| s.into_inner().next())
                    .map(|s| match s.as_rule() {
                        Rule::point => {
                            let mut q = s.into_inner().map(quantity);
                            let q0 = Quantity { value: 0.0, unit: None, span: osp };
                            let x = q.next().unwrap_or(q0.clone());
                            let y = q.next().unwrap_or(q0);
                            Spot::Point(Point { x, y })
                        }
                        _ => Spot::Angle(quantity(s)),
                    })
                    .collect();
                at = Some((spots, osp));
            }
            Rule::layout_facing => {
                let qs = o.into_inner().filter(|q| q.as_rule() == Rule::quantity).map(quantity).collect();
                facing = Some((qs, osp));
            }
            _ => {}
        }
    }
    SensorLayout { kind, at, facing, span: sp }
}

/// `variants mean [draw N] { NAME { ITEMS } ... }`.
fn variants(p: Pair<Rule>) -> VariantsDecl {
    let sp = span(&p);
    let mut aggregate = Name { text: String::new(), span: sp };
    let mut draw = None;
    let mut list = Vec::new();
    for c in p.into_inner() {
        match c.as_rule() {
            Rule::variants_aggregate => aggregate = name(c),
            Rule::variants_draw => {
                draw = c.into_inner().find(|q| q.as_rule() == Rule::quantity).map(quantity)
            }
            Rule::variant => {
                let vsp = span(&c);
                let n = c
                    .clone()
                    .into_inner()
                    .next()
                    .map(name)
                    .unwrap_or(Name { text: String::new(), span: vsp });
                let mut world = world(c);
                world.mode = WorldMode::Changes;
                list.push(VariantDecl { name: n, world, span: vsp });
            }
            _ => {}
        }
    }
    VariantsDecl { aggregate, draw, variants: list, span: sp }
}

fn setting(p: Pair<Rule>) -> Setting {
    let sp = span(&p);
    let rule = p.as_rule();
    let mut it = p.into_inner();
    if rule == Rule::selection {
        let v = match (it.next(), it.next()) {
            (Some(q), _) if q.as_rule() == Rule::quantity => SettingValue::Truncation(quantity(q)),
            (Some(w), Some(q)) => SettingValue::WordAndNumber(name(w), quantity(q)),
            (Some(w), None) => SettingValue::Word(name(w)),
            (None, _) => SettingValue::Word(Name { text: String::new(), span: sp }),
        };
        return Setting {
            name: Name { text: "selection".into(), span: Span::new(sp.start, sp.start + 9) },
            value: v,
            span: sp,
        };
    }
    let n = it.next().map(name).unwrap_or(Name { text: String::new(), span: sp });
    let value = match it.next() {
        Some(q) if q.as_rule() == Rule::quantity => SettingValue::Quantity(quantity(q)),
        Some(w) => SettingValue::Word(name(w)),
        None => SettingValue::Word(Name { text: String::new(), span: sp }),
    };
    Setting { name: n, value, span: sp }
}

fn link_kind(p: Pair<Rule>) -> LinkKind {
    let mut it = p.into_inner();
    match it.next() {
        Some(k) if k.as_rule() == Rule::k_fixed => LinkKind::Fixed(it.next().map(|n| num(&n)).unwrap_or(0.0)),
        _ => LinkKind::Evolvable(it.next().and_then(|r| r.into_inner().nth(1)).map(range)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exceeding_the_call_limit_is_a_diagnostic() {
        let src = "robot r { sensor ir[8] proximity }\nstage s { module m { sense ir behavior stop } }";
        let errors = parse_with_limit(src, 50).errors;
        assert!(matches!(&errors[..], [Error::TooComplex { .. }]), "{errors:?}");
        assert!(errors[0].to_string().starts_with("the file is too complex to parse"));
        assert!(parse_with_limit(src, CALL_LIMIT).errors.is_empty());
    }

    #[test]
    fn long_lines_are_rejected_before_parsing() {
        let ok = format!("{}\n{}", "x".repeat(MAX_LINE), "y".repeat(MAX_LINE));
        assert!(check_lines(&ok).is_none());
        let src = format!("// one\n{}]", " ".repeat(70_000));
        let Some(Error::LineTooLong { span, line: 2, .. }) = check_lines(&src) else { panic!() };
        assert_eq!((span.offset(), span.len()), (7, 1));
    }

    #[test]
    fn nesting_is_measured_outside_comments() {
        let deep = "(".repeat(MAX_NESTING + 1);
        assert!(check_nesting(&deep).is_some());
        assert!(check_nesting(&format!("// {deep}\n/* {deep} */")).is_none());
        assert!(check_nesting(&"(".repeat(MAX_NESTING)).is_none());
    }
}

#[cfg(test)]
mod keyword_tests {
    use super::*;

    /// `RESERVED` (used for help messages) matches the grammar's `keyword` rule.
    #[test]
    fn reserved_words_match_the_grammar() {
        for w in RESERVED {
            assert!(BatParser::parse(Rule::ident, w).map(|p| p.as_str() != w).unwrap_or(true), "{w}");
            assert!(BatParser::parse(Rule::keyword, w).is_ok(), "{w}");
        }
        assert!(BatParser::parse(Rule::ident, "forwarder").is_ok());
    }
}
