//! What an editor asks of a file with roles: completion, hover, the
//! outline and definitions, for modules inside roles.

use shaping_compiler::ide::{self, CompletionKind, SymbolKind};

const SRC: &str = "robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage team {
  fitness per action wheels[0]
  role seeker robots 2 {
    module brain { sense ir  behavior forward }
    module flee { sense ir[0]  behavior back }
    link flee -> brain evolvable
  }
  role anchor robots 1 {
    module brain { sense light  behavior stop }
  }
}
";

/// The offset of the `n`th (from 0) occurrence of `needle`, plus `extra`.
fn at(needle: &str, n: usize, extra: usize) -> usize {
    SRC.match_indices(needle).nth(n).map(|(i, _)| i + extra).unwrap_or_else(|| panic!("{needle} #{n}"))
}

fn labels(c: &[ide::Completion]) -> Vec<&str> {
    c.iter().map(|c| c.label.as_str()).collect()
}

#[test]
fn completion_in_a_role_offers_its_words_and_its_modules() {
    // After `link ` in role `seeker`: its modules, not `anchor`'s.
    let text = SRC.replace("    link flee -> brain evolvable\n", "    link \n");
    let offset = text.find("link \n").unwrap() + 5;
    let got = ide::complete(&text, offset);
    assert!(got.iter().all(|c| c.kind == CompletionKind::Module), "{got:?}");
    assert_eq!(labels(&got), ["brain", "flee"]);
    // At the start of a role's line: the words of a role.
    let text = SRC.replace("    link flee -> brain evolvable\n", "    \n");
    let offset = text.find("    \n").unwrap() + 4;
    let got = ide::complete(&text, offset);
    let words = labels(&got);
    for w in ["module", "links", "link"] {
        assert!(words.contains(&w), "{w} in {words:?}");
    }
    // A role's robots may have a fitness of their own.
    assert!(words.contains(&"fitness"), "{words:?}");
    // In a stage: `role`; after `role NAME`: `robots` (and, in a later stage, `adds`).
    let text = SRC.replace("  fitness per action wheels[0]\n", "  fitness per action wheels[0]\n  \n");
    let offset = text.find("  \n").unwrap() + 2;
    assert!(labels(&ide::complete(&text, offset)).contains(&"role"));
    let text = SRC.replace("role anchor robots 1", "role anchor ");
    let offset = text.find("role anchor ").unwrap() + 12;
    assert_eq!(labels(&ide::complete(&text, offset)), ["robots", "adds"]);
}

#[test]
fn hover_on_a_role_s_module_describes_that_role_s() {
    let (_, md) = ide::hover(SRC, at("module brain", 1, 8)).expect("hover");
    assert!(md.contains("role `anchor`") && md.contains("light"), "{md}");
    assert!(md.contains("anchor.brain"), "its genes: {md}");
    let (_, md) = ide::hover(SRC, at("brain", 0, 1)).expect("hover");
    assert!(md.contains("role `seeker`") && md.contains("ir"), "{md}");
    let (_, md) = ide::hover(SRC, at("role", 0, 1)).expect("hover of the word");
    assert!(md.contains("heterogeneous team"), "{md}");
}

#[test]
fn the_outline_holds_roles_holding_their_modules() {
    let file = shaping_compiler::syntax::parse(SRC).unwrap();
    let out = ide::outline(&file);
    let stage = out.iter().find(|s| s.kind == SymbolKind::Stage).unwrap();
    let roles: Vec<(&str, Vec<&str>)> = stage
        .children
        .iter()
        .map(|r| {
            assert_eq!(r.kind, SymbolKind::Role);
            (r.name.text.as_str(), r.children.iter().map(|m| m.name.text.as_str()).collect())
        })
        .collect();
    assert_eq!(roles, [("seeker", vec!["brain", "flee"]), ("anchor", vec!["brain"])]);
    let modules: Vec<String> = ide::declarations(&file)
        .into_iter()
        .filter(|d| d.kind == ide::Kind::Module)
        .map(|d| d.name.text)
        .collect();
    assert_eq!(modules, ["brain", "flee", "brain"], "every role's modules are declarations");
}

#[test]
fn a_module_named_in_a_role_is_defined_in_that_role() {
    // `brain` in `link flee -> brain` of role `seeker`: seeker's brain.
    let use_at = at("-> brain", 0, 4);
    let def = ide::definition(SRC, use_at).expect("a definition");
    assert_eq!(def.start, at("module brain", 0, 7));
    // `brain` declared in role `anchor`: itself.
    let def = ide::definition(SRC, at("module brain", 1, 8)).expect("a definition");
    assert_eq!(def.start, at("module brain", 1, 7));
}

/// A later stage's roles: a link in `role NAME adds { }` completes the
/// role's modules, inherited ones included; a hover on a module of a role
/// added later describes that role's (decl order is not the team's).
#[test]
fn a_later_stages_roles_complete_and_hover_their_own_modules() {
    let later = format!(
        "{SRC}stage more extends team {{
  role anchor robots 2
  role scout robots 1 {{ module brain {{ sense ir[1]  behavior forward }} }}
  role seeker adds {{
    module dodge {{ sense ir[2]  behavior back }}
    link 
  }}
}}
"
    );
    let offset = later.find("link \n").unwrap() + 5;
    let got = ide::complete(&later, offset);
    assert_eq!(labels(&got), ["brain", "flee", "dodge"]);
    let scout = later.find("module brain { sense ir[1]").unwrap() + 8;
    let (_, md) = ide::hover(&later.replace("    link \n", ""), scout).expect("hover");
    assert!(md.contains("role `scout`") && md.contains("scout.brain"), "{md}");
}

/// After `team.` and `robot.` in a fitness: the fields of the team's and
/// the robot's state, with their meaning.
#[test]
fn completion_after_team_offers_the_team_s_measures() {
    let text = SRC.replace("fitness per action wheels[0]", "fitness at end team.");
    let offset = text.find("team.").unwrap() + 5;
    let got = ide::complete(&text, offset);
    assert!(got.iter().all(|c| c.kind == CompletionKind::Field), "{got:?}");
    assert_eq!(labels(&got), ["spread", "grouped", "largest", "nearest", "order", "connected"]);
    assert!(got[5].detail.contains("rab_range"), "{got:?}");
    // While the field is typed, too.
    let text = SRC.replace("fitness per action wheels[0]", "fitness at end team.ne");
    let offset = text.find("team.ne").unwrap() + 7;
    assert!(labels(&ide::complete(&text, offset)).contains(&"nearest"));
    let text = SRC.replace("fitness per action wheels[0]", "fitness at end robot.");
    let offset = text.find("robot.").unwrap() + 6;
    assert!(labels(&ide::complete(&text, offset)).contains(&"squares"));
}
