//! Teams (`robots N`, `team sum|mean|min`, `team.spread`): what the
//! compiler writes into the program, and what a later stage inherits.

use shaping_runtime::expr::Op;
use shaping_runtime::program::Aggregate;
use shaping_runtime::state::ST_SPREAD;

use crate::compile_ok;

const SRC: &str = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage alone {
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage pack extends alone {
  world { robots 4 }
  fitness per action wheels[0], at end -team.spread / 100, team sum
  test best for 100 actions
}
stage more extends pack {
  world changes { robots 6 }
  fitness adds per action 1
  test best for 100 actions
}
stage again extends pack {
  fitness per action 1
  test best for 100 actions
}
stage least extends pack {
  fitness adds team min
  test best for 100 actions
}
stage varied extends alone {
  variants mean { few { } many { robots 3 } }
  fitness per action 1, team min
  test best for 2 lives of 100 actions
}
";

#[test]
fn robots_and_the_team_clause_reach_the_program() {
    let p = compile_ok(SRC, "teams.bat");
    let got: Vec<(&str, u32, Aggregate)> =
        p.stages.iter().map(|s| (s.name.as_str(), s.world.robots, s.fitness.team)).collect();
    assert_eq!(
        got,
        [
            ("alone", 1, Aggregate::Mean),
            ("pack", 4, Aggregate::Sum),
            // `fitness adds` keeps the inherited clause; a new fitness starts from `mean`
            ("more", 6, Aggregate::Sum),
            ("again", 4, Aggregate::Mean),
            ("least", 4, Aggregate::Min),
            ("varied", 1, Aggregate::Min),
        ]
    );
    let at_end = p.stages[1].fitness.at_end.as_ref().expect("an at-end term");
    assert_eq!(at_end.ops[0], Op::State(ST_SPREAD as u16));
    let v = p.stages[5].variants.as_ref().expect("variants");
    assert_eq!(v.list.iter().map(|x| x.world.robots).collect::<Vec<_>>(), [1, 3]);
    // A team of one robot stays out of the file, as before teams.
    let json = serde_json::to_string(&p.stages[0]).unwrap();
    assert!(!json.contains("robots") && !json.contains("\"team\""), "{json}");
}

/// The team example of `docs/language.md` is a team of 4 whose fitness
/// reads `team.spread`.
#[test]
fn the_documented_team_is_one() {
    let (name, src, _) =
        crate::docs::blocks().into_iter().find(|(_, s, _)| s.contains("robots 4")).expect("a team example");
    let p = compile_ok(&src, &name);
    assert_eq!(p.stages[0].world.robots, 4);
    let reads = |e: &Option<shaping_runtime::expr::Expr>| {
        e.as_ref().is_some_and(|e| e.ops.contains(&Op::State(ST_SPREAD as u16)))
    };
    assert!(reads(&p.stages[0].fitness.at_end) || reads(&p.stages[0].fitness.per_action));
}

/// `team.nearest`, `team.order` and `team.connected` read their state slots.
#[test]
fn the_teams_swarm_measures_are_fields() {
    use shaping_runtime::state::{ST_CONNECTED, ST_NEAREST, ST_ORDER};
    let src = SRC.replace("at end -team.spread / 100", "at end team.nearest - team.order + team.connected");
    let p = compile_ok(&src, "teams.bat");
    let at_end = p.stages[1].fitness.at_end.as_ref().expect("an at-end term");
    let slots: Vec<&Op> = at_end.ops.iter().filter(|op| matches!(op, Op::State(_))).collect();
    assert_eq!(
        slots,
        [&Op::State(ST_NEAREST as u16), &Op::State(ST_ORDER as u16), &Op::State(ST_CONNECTED as u16)]
    );
}

/// `team.grouped` and `team.largest` read their state slots.
#[test]
fn the_teams_groups_are_fields() {
    use shaping_runtime::state::{ST_GROUPED, ST_LARGEST};
    let src = SRC.replace("at end -team.spread / 100", "at end team.largest - team.grouped");
    let p = compile_ok(&src, "teams.bat");
    let at_end = p.stages[1].fitness.at_end.as_ref().expect("an at-end term");
    assert_eq!(at_end.ops[..2], [Op::State(ST_LARGEST as u16), Op::State(ST_GROUPED as u16)]);
}
