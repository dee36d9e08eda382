//! Every example compiles.

use crate::{compile_ok, root};

#[test]
fn every_example_compiles() {
    let mut n = 0;
    for entry in std::fs::read_dir(root().join("examples")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "bat") {
            let src = std::fs::read_to_string(&path).unwrap();
            let p = compile_ok(&src, &path.file_name().unwrap().to_string_lossy());
            assert!(!p.stages.is_empty());
            n += 1;
        }
    }
    assert!(n >= 1, "no examples found");
}

#[test]
fn khepera_has_a_training_stage_and_the_papers_three_stages() {
    use shaping_compiler::Program;
    use shaping_runtime::program::{Behavior, Decode, StageRun};
    let src = std::fs::read_to_string(root().join("examples/khepera.bat")).unwrap();
    let p: Program = compile_ok(&src, "khepera.bat");
    let names: Vec<&str> = p.stages.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["avoidance", "navigation", "collect", "bigger"]);
    assert_eq!(p.stages[0].run, StageRun::Train { actions: 1000 });
    assert!(p.stages[0].layout.genes.is_empty(), "a training stage has no genes");
    assert_eq!(p.stages[2].parent, Some(1));
    assert_eq!(p.stages[3].parent, Some(2));
    let nav = &p.stages[1];
    // 4 modules, all interconnected: 12 links.
    assert_eq!(nav.modules.len(), 4);
    assert_eq!(nav.links.len(), 12);
    // recharge senses ir[0..5] (six channels) and the battery (channel 16).
    assert_eq!(nav.modules[3].inputs, vec![0, 1, 2, 3, 4, 5, 16]);
    // avoid: neural, 2 sign outputs; bits 11 = forward, 00 = back.
    let Behavior::Neural(nb) = &nav.modules[1].behavior else { panic!("avoid is neural") };
    assert_eq!(nb.net.outputs, 2);
    // Its weights are what the training stage's avoid module (module 1) learns.
    use shaping_runtime::program::{Param, Part};
    assert!(nb
        .net
        .params
        .iter()
        .enumerate()
        .all(|(i, w)| *w == Param::Trained { stage: 0, module: 1, index: i as u32, part: Part::Behavior }));
    assert_eq!(nb.decode, Decode::Table(vec![[-1.0, -1.0], [-1.0, 1.0], [1.0, -1.0], [1.0, 1.0]]));
    // collect keeps navigation's genes as a frozen prefix.
    let col = &p.stages[2];
    assert_eq!(
        &col.layout.genes[..nav.layout.genes.len()].iter().map(|g| g.offset).collect::<Vec<_>>(),
        &nav.layout.genes.iter().map(|g| g.offset).collect::<Vec<_>>()
    );
    assert!(col.layout.genes[..nav.layout.genes.len()].iter().all(|g| g.frozen));
    assert!(col.layout.genes[nav.layout.genes.len()..].iter().all(|g| !g.frozen && g.stage == 2));
    assert_eq!(col.links.len(), 30);
    assert_eq!(col.world.objects.as_ref().map(|o| o.diameter), Some(10.0));
    assert_eq!(p.stages[3].world.objects.as_ref().map(|o| o.diameter), Some(25.0));
    assert_eq!(p.stages[3].run, StageRun::Test { actions: 300, lives: 1, learning: true });
    assert_eq!(col.fitness.bonuses.len(), 2);
}
