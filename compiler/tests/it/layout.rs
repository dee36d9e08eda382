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
