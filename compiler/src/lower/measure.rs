//! A measure: one expression given from outside a file (Python's
//! `evaluate(measures=...)`), checked and lowered as a fitness `at end`
//! term of a compiled stage is, by the same code ([`Lower::expr`]).

use shaping_runtime::catalog::{self, ActuatorKind};
use shaping_runtime::expr::Expr;
use shaping_runtime::program::Stage;

use super::{expr::Scope, ActuatorSt, Hw, Lower, SensorSt};
use crate::diag::Diagnostics;
use crate::syntax::{ast, parse_expr, Span};

/// Lowers `text` as a fitness `at end` term of `stage` reads it: the
/// stage's sensors and actuators, the robot's state (`robot.x` ...), the
/// team's (`team.spread` ...) and `distance_to(NAME)` of its world's items
/// (an item the stage does not measure yet is added to `stage.targets`).
/// Errors are the compiler's diagnostics of the text, named `name`.
pub fn measure(stage: &mut Stage, name: &str, text: &str) -> Result<Expr, Diagnostics> {
    let text = text.trim();
    let e = parse_expr(text).map_err(|errors| Diagnostics::new(name, text, errors))?;
    let nowhere = Span::new(0, 0);
    let hw = Hw {
        stage: stage.name.clone(),
        sensors: stage
            .sensors
            .iter()
            .map(|s| SensorSt {
                name: s.name.clone(),
                kind: s.kind,
                count: s.count,
                channel: s.channel,
                stage: s.stage,
                span: nowhere,
            })
            .collect(),
        actuators: stage
            .actuators
            .iter()
            .map(|a| {
                let info = catalog::actuator_info(a.kind);
                let count = match a.kind {
                    ActuatorKind::Broadcast => {
                        stage.world.body.rab.as_ref().map_or(1, |r| u16::from(r.signals))
                    }
                    _ => info.count as u16,
                };
                ActuatorSt {
                    name: a.name.clone(),
                    kind: a.kind,
                    count,
                    slot: info.slot as u16,
                    stage: a.stage,
                    span: nowhere,
                }
            })
            .collect(),
        has_charger: stage.world.charger.is_some() || stage.world.items.zones.iter().any(|z| z.charger),
    };
    // A file with a robot: an unknown name is reported as such (a file
    // without one reports its missing robot instead).
    let robot = ast::Robot {
        name: ast::Name { text: String::new(), span: nowhere },
        hardware: Vec::new(),
        span: nowhere,
    };
    let file = ast::File { robots: vec![robot], genomes: Vec::new(), stages: Vec::new() };
    let mut lw = Lower {
        errors: Vec::new(),
        file: &file,
        hw_origin: Default::default(),
        module_origin: Default::default(),
        stage_names: Vec::new(),
        poisoned: Default::default(),
        trained: Default::default(),
        no_robot: None,
        items: stage.world.items.clone(),
        targets: stage.targets.clone(),
    };
    let lowered = lw.expr(&hw, &e, &Scope { only: None, state: true });
    let errors: Vec<_> = lw.errors.into_iter().filter(|e| !e.is_warning()).collect();
    match lowered {
        Some(x) if errors.is_empty() => {
            stage.targets = lw.targets;
            Ok(x)
        }
        _ => Err(Diagnostics::new(name, text, errors)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aggregation() -> Stage {
        let src =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/aggregation.bat"))
                .unwrap();
        crate::compile(&src, "aggregation.bat").unwrap().stages.remove(0)
    }

    /// A measure is lowered as the same text is in a fitness `at end`.
    #[test]
    fn a_measure_is_lowered_as_a_fitness_term() {
        let mut stage = aggregation();
        let e = measure(&mut stage, "measure fit", "  1 - team.spread / 400 ").unwrap();
        assert_eq!(Some(&e), stage.fitness.at_end.as_ref());
        let x = measure(&mut stage, "measure x", "robot.x + max(ir) * prev ir[3]").unwrap();
        assert!(x.ops.contains(&shaping_runtime::expr::Op::State(shaping_runtime::state::ST_X as u16)));
        assert!(stage.targets.is_empty());
    }

    /// A bad measure gets the compiler's diagnostics, pointing into its text.
    #[test]
    fn a_bad_measure_gets_the_compiler_s_diagnostics() {
        let mut stage = aggregation();
        for (text, says, at) in [
            ("robot.x + irr[0]", "unknown sensor `irr`", 10),
            ("team.spraed", "no field `spraed`", 5),
            ("robot.x robot.y", "expected an operator or the end of the expression", 8),
            ("1 +", "expected an expression after `+`", 2),
            ("ir", "expected a number", 0),
            ("distance_to(goal)", "unknown item of the world `goal`", 12),
        ] {
            use miette::Diagnostic;
            let d = measure(&mut stage, "measure m", text).unwrap_err();
            let text_of: Vec<String> = d.errors().iter().map(|e| e.to_string()).collect();
            assert!(text_of.iter().any(|m| m.contains(says)), "{text}: {text_of:?}");
            let first = d.errors()[0].labels().and_then(|mut l| l.next()).map(|l| l.offset());
            assert_eq!(first, Some(at), "{text}: {text_of:?}");
            assert!(d.to_string().contains("`measure m`"), "{d}");
        }
    }
}
