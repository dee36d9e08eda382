//! Genome layout snapshots of every stage of every file in `examples/` and
//! `tests/lower/`.

use crate::compile_ok;

fn all_layouts(path: &std::path::Path) -> String {
    let src = std::fs::read_to_string(path).unwrap();
    let name = path.file_name().unwrap().to_string_lossy();
    let p = compile_ok(&src, &name);
    (0..p.stages.len()).map(|i| shaping_compiler::render_layout(&p, i)).collect::<Vec<_>>().join("\n")
}

#[test]
fn example_layouts() {
    insta::glob!("../../..", "examples/*.bat", |path| {
        insta::assert_snapshot!(all_layouts(path));
    });
}

#[test]
fn lower_layouts() {
    insta::glob!("../../..", "tests/lower/*.bat", |path| {
        insta::assert_snapshot!(all_layouts(path));
    });
}

#[test]
fn khepera_graph() {
    let path = crate::root().join("examples/khepera.bat");
    let src = std::fs::read_to_string(path).unwrap();
    let p = compile_ok(&src, "khepera.bat");
    insta::assert_snapshot!(shaping_compiler::render_graph(&p, 1));
}

#[test]
fn rendering_a_missing_stage_says_so() {
    let src = std::fs::read_to_string(crate::root().join("examples/tutorial.bat")).unwrap();
    let p = compile_ok(&src, "tutorial.bat");
    assert!(shaping_compiler::render_layout(&p, 9).starts_with("no stage 9"));
    assert!(shaping_compiler::render_graph(&p, 9).starts_with("digraph"));
}

#[test]
fn truncation_keeps_a_fifth_of_the_population_unless_told() {
    use shaping_runtime::program::{Selection, StageRun};
    let keep = |src: &str, stage: usize| match &compile_ok(src, "keep.bat").stages[stage].run {
        StageRun::Evolve(e) => e.selection,
        StageRun::Test { .. } | StageRun::Train { .. } => panic!("an evolved stage"),
    };
    let head = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n";
    let body = "fitness per action wheels[0]  module m { sense ir  behavior forward }";
    let small = format!("{head}stage s {{ evolve {{ population 12 }} {body} }}\nstage t extends s {{ evolve {{ population 30 }} module n {{ sense ir  behavior back }} }}");
    assert_eq!(keep(&small, 0), Selection::Truncation { keep: 2 });
    assert_eq!(keep(&small, 1), Selection::Truncation { keep: 6 });
    let told = format!(
        "{head}stage s {{ evolve {{ population 12  selection truncation keep 3 }} {body} }}\nstage t extends s {{ evolve {{ population 30 }} module n {{ sense ir  behavior back }} }}"
    );
    assert_eq!(keep(&told, 0), Selection::Truncation { keep: 3 });
    assert_eq!(keep(&told, 1), Selection::Truncation { keep: 3 }, "an explicit keep is inherited");
    assert_eq!(keep(&format!("{head}stage s {{ {body} }}"), 0), Selection::Truncation { keep: 20 });
}

/// `layout_rows` (`shaping layout --format json`): the names the table
/// shows, and what each gene is, field by field.
#[test]
fn layout_rows_name_what_the_table_shows() {
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage first {
  fitness per action wheels[0]
  module go {
    sense ir[2]
    behavior neural { hidden 1 recurrent  outputs sign(2) -> forward | right | left | back  weights evolvable }
  }
}
stage second extends first {
  module back_off { sense ir[0]  activation evolvable hidden 1  behavior back }
  links all evolvable
}
stage team {
  fitness per action wheels[0]
  role seeker robots 2 { module m { sense ir[7]  behavior forward } }
}
";
    let p = compile_ok(src, "rows.bat");
    let rows = shaping_compiler::layout_rows(&p, 1);
    let table = shaping_compiler::render_layout(&p, 1);
    for r in &rows {
        let line = table.lines().nth(2 + r.gene as usize).unwrap();
        assert!(line.contains(&r.what) && line.contains(&r.module) && line.contains(&r.stage), "{line}");
    }
    let team = shaping_compiler::layout_rows(&p, 2);
    let json = serde_json::to_string_pretty(&serde_json::json!({ "second": rows, "team": team })).unwrap();
    insta::assert_snapshot!(json);
    assert!(shaping_compiler::layout_rows(&p, 9).is_empty());
}
