//! Roles of a heterogeneous team (`role NAME robots N { ... }`): what the
//! compiler writes into the program, and what a later stage inherits.

use shaping_runtime::program::{Param, Role, StageRun};

use crate::compile_ok;

fn roles_src() -> String {
    std::fs::read_to_string(crate::root().join("tests/lower/roles.bat")).unwrap()
}

fn role(name: &str, robots: u32, modules: u16) -> Role {
    Role { name: name.into(), robots, modules, fitness: None }
}

#[test]
fn two_roles_make_the_program_s_roles() {
    let p = compile_ok(&roles_src(), "roles.bat");
    let s = &p.stages[0];
    assert_eq!(s.roles, [role("seeker", 3, 1), role("anchor", 2, 2)]);
    assert_eq!(s.world.robots, 5);
    let names: Vec<&str> = s.modules.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["brain", "brain", "avoid"]);
    // `links all` of role `anchor` joins its two modules, numbered in the stage.
    let links: Vec<(u16, u16)> = s.links.iter().map(|l| (l.from, l.to)).collect();
    assert_eq!(links, [(2, 1), (1, 2)]);
    // Role `seeker`'s genes are its brain's behavior (an activation fixed 0);
    // `anchor`'s the activation networks of its modules and its links.
    let of = |m: u16| s.layout.genes.iter().filter(|g| g.module == m).count();
    assert_eq!((of(0), of(1), of(2)), (7, 3, 3), "genes per module");
    assert!(s.layout.genes.windows(2).all(|w| w[0].module <= w[1].module), "role by role");
    for l in &s.links {
        let Param::Gene(g) = l.weight else { panic!("an evolvable link") };
        assert_eq!(s.layout.genes[g as usize].module, l.to);
    }
    assert_eq!(s.role_of(2), 0);
    assert_eq!(s.role_of(3), 1);
}

#[test]
fn a_stage_extending_a_role_stage_keeps_its_roles() {
    let p = compile_ok(&roles_src(), "roles.bat");
    let (gather, check, wider) = (&p.stages[0], &p.stages[1], &p.stages[2]);
    assert!(matches!(check.run, StageRun::Test { lives: 2, .. }));
    for s in [check, wider] {
        assert_eq!(s.roles, gather.roles, "{}", s.name);
        assert_eq!(s.modules, gather.modules, "{}", s.name);
        assert_eq!(s.links, gather.links, "{}", s.name);
        assert_eq!(s.world.robots, 5);
        assert_eq!(s.layout.genes.len(), gather.layout.genes.len());
        assert!(s.layout.genes.iter().all(|g| g.frozen), "{}: inherited genes are frozen", s.name);
    }
    assert_eq!(wider.world.arena, [800.0, 800.0]);
}

#[test]
fn the_runtime_accepts_every_stage() {
    let p = compile_ok(&roles_src(), "roles.bat");
    shaping_runtime::validate::program(&p).expect("a valid program");
}

#[test]
fn a_program_without_roles_writes_none() {
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s { world { robots 3 }  fitness per action wheels[0]  module m { sense ir  behavior forward } }";
    let p = compile_ok(src, "clones.bat");
    assert!(p.stages[0].roles.is_empty());
    let json = serde_json::to_string(&p).unwrap();
    assert!(!json.contains("roles"), "{json}");
}

#[test]
fn a_robots_count_equal_to_the_roles_is_accepted() {
    let src = roles_src().replace("arena 600mm x 600mm }", "arena 600mm x 600mm  robots 5 }");
    let p = compile_ok(&src, "roles.bat");
    assert_eq!(p.stages[0].world.robots, 5);
}

/// Files with roles, right and wrong in every way the runtime checks
/// roles: each either compiles to a program the runtime accepts, or gives
/// a diagnostic. None reaches the runtime's validation with an error.
#[test]
fn no_file_with_roles_reaches_the_runtime_s_refusals() {
    let robots = ["0", "1", "3"];
    let activations = ["", "activation fixed 0", "activation random -1..1"];
    let links =
        ["", "links all evolvable", "links all fixed 1", "link p -> q evolvable", "link q -> p fixed 1"];
    let worlds = ["", "world { robots 4 }", "world { robots 5 }"];
    let later = [
        "",
        "stage t extends s { test best for 50 actions }",
        "stage t extends s { world changes { robots 2 } fitness per action 1 }",
        "stage t extends s { module z { sense ir  behavior stop } }",
        "stage t extends s { role z robots 1 { module z { sense ir  behavior stop } } }",
        "stage t { train for 10 actions  role z robots 1 { module z { sense ir  activation fixed 0  behavior stop } } }",
    ];
    let (mut compiled, mut refused) = (0, 0);
    for r in robots {
        for a in activations {
            for l in links {
                for w in worlds {
                    for (k, t) in later.iter().enumerate() {
                        // The second role's name: its own, or the first's.
                        let second = if k % 2 == 0 { "b" } else { "a" };
                        let src = format!(
                            "robot x {{ sensor ir[8] proximity  actuator wheels[2] speed }}
stage s {{
  {w}
  fitness per action wheels[0]
  role a robots 2 {{ module p {{ sense ir  behavior forward }} }}
  role {second} robots {r} {{
    module p {{ sense ir  {a}  behavior back }}
    module q {{ sense ir[0]  activation fixed 0  behavior stop }}
    {l}
  }}
}}
{t}
"
                        );
                        match shaping_compiler::compile(&src, "roles.bat") {
                            Ok(p) => {
                                compiled += 1;
                                if let Err(e) = shaping_runtime::validate::program(&p) {
                                    panic!("compiles to a program the runtime refuses ({e}):\n{src}");
                                }
                            }
                            Err(d) => {
                                refused += 1;
                                assert!(d.error_count() > 0, "{src}");
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(compiled > 20 && refused > 20, "{compiled} compiled, {refused} refused");
}

/// A small two-role program and a test stage that extends it: each stage's
/// layout, the roles' robots and modules, and the GA's mask (a frozen bit
/// `#`, an evolvable one `.`) split by role.
#[test]
fn two_roles_layout_and_masks() {
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage pair {
  genome { bits 2 }
  fitness per action wheels[0], team sum
  role lead robots 1 { module go { sense ir[0]  behavior forward } }
  role follow robots 2 {
    module go { sense ir[1]  activation fixed 0  behavior neural { outputs linear  weights evolvable } }
    module stay { sense ir[2]  behavior stop }
    link stay -> go evolvable
  }
}
stage check extends pair { test best for 100 actions }
";
    let p = compile_ok(src, "pair.bat");
    let mut out = String::new();
    for (i, s) in p.stages.iter().enumerate() {
        out += &shaping_compiler::render_layout(&p, i);
        let mask = shaping_runtime::evolve::ga::frozen_mask(&s.layout);
        for r in 0..s.roles.len() {
            let mods = s.role_modules(r);
            let bits: String = s
                .layout
                .genes
                .iter()
                .filter(|g| mods.contains(&(g.module as usize)))
                .flat_map(|g| &mask[g.offset as usize..(g.offset + u32::from(g.bits)) as usize])
                .map(|&frozen| if frozen { '#' } else { '.' })
                .collect();
            out += &format!("mask of role `{}`: {bits}\n", s.roles[r].name);
        }
        out += "\n";
    }
    insta::assert_snapshot!(out);
}

/// The graph of a stage with roles boxes each role's modules, named
/// `role.module`.
#[test]
fn the_graph_boxes_each_role() {
    let p = compile_ok(&roles_src(), "roles.bat");
    let g = shaping_compiler::render_graph(&p, 0);
    assert!(
        g.contains("subgraph \"cluster_0\" {\n    label=\"role seeker (3 robots)\";\n    \"m:0\";\n  }"),
        "{g}"
    );
    assert!(g.contains("label=\"role anchor (2 robots)\";\n    \"m:1\";\n    \"m:2\";"), "{g}");
    assert!(g.contains("label=\"anchor.avoid\\n(script)\""), "{g}");
}
