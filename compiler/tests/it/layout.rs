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
