//! The GA driving real controller episodes of the hand-made navigation stage.

use shaping_runtime::evolve::{
    evaluate_with_controller, is_finished, start_stage, step_generation, EvalOptions,
};
use shaping_runtime::program::{Program, StageRun, FORMAT_VERSION};
use shaping_runtime::testkit;

#[test]
fn navigation_fitness_rises_over_five_generations() {
    let mut stage = testkit::navigation();
    if let StageRun::Evolve(evo) = &mut stage.run {
        evo.population = 40;
        evo.generations = 5;
        evo.selection = shaping_runtime::program::Selection::Truncation { keep: 8 };
        evo.actions = 300;
    }
    let program = Program { format: FORMAT_VERSION, name: "navigation".into(), stages: vec![stage] };
    let eval = evaluate_with_controller(&program.stages[0], EvalOptions::of(&program.stages[0])).unwrap();
    let mut cp = start_stage(&program, 0, 2024, None).unwrap();
    let mut stats = Vec::new();
    while !is_finished(&program, &cp) {
        stats.push(step_generation(&program, &mut cp, &eval).unwrap());
    }
    for s in &stats {
        eprintln!("generation {}: best {:.4} mean {:.4} worst {:.4}", s.generation, s.best, s.mean, s.worst);
    }
    let (first, last) = (&stats[0], &stats[4]);
    assert!(last.mean > first.mean * 1.5, "mean {} -> {}", first.mean, last.mean);
    assert!(last.best > first.best, "best {} -> {}", first.best, last.best);
}

#[test]
fn controller_runs_are_identical_on_one_and_two_threads() {
    let mut stage = testkit::navigation();
    if let StageRun::Evolve(evo) = &mut stage.run {
        evo.population = 12;
        evo.generations = 2;
        evo.selection = shaping_runtime::program::Selection::Truncation { keep: 4 };
        evo.actions = 100;
    }
    let program = Program { format: FORMAT_VERSION, name: "navigation".into(), stages: vec![stage] };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let eval =
                evaluate_with_controller(&program.stages[0], EvalOptions::of(&program.stages[0])).unwrap();
            let mut cp = start_stage(&program, 0, 77, None).unwrap();
            while !is_finished(&program, &cp) {
                step_generation(&program, &mut cp, &eval).unwrap();
            }
            cp
        })
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert!(one.fitness.iter().any(|&f| f > 0.0));
}

#[test]
fn an_invalid_stage_is_reported_before_evolving() {
    let mut stage = testkit::navigation();
    stage.layout.bits -= 1;
    assert!(evaluate_with_controller(&stage, EvalOptions::of(&stage)).is_err());
}

#[test]
fn collect_stage_starts_from_navigation_and_keeps_its_genes() {
    let small = |mut stage: shaping_runtime::program::Stage| {
        if let StageRun::Evolve(evo) = &mut stage.run {
            evo.population = 10;
            evo.generations = 2;
            evo.selection = shaping_runtime::program::Selection::Truncation { keep: 5 };
            evo.actions = 60;
        }
        stage
    };
    let program = Program {
        format: FORMAT_VERSION,
        name: "shaping".into(),
        stages: vec![small(testkit::navigation()), small(testkit::collect())],
    };
    let eval0 = evaluate_with_controller(&program.stages[0], EvalOptions::of(&program.stages[0])).unwrap();
    let mut cp0 = start_stage(&program, 0, 5, None).unwrap();
    while !is_finished(&program, &cp0) {
        step_generation(&program, &mut cp0, &eval0).unwrap();
    }
    let old = program.stages[0].layout.bits as usize;
    let eval1 = evaluate_with_controller(&program.stages[1], EvalOptions::of(&program.stages[1])).unwrap();
    let mut cp1 = start_stage(&program, 1, 5, Some(&cp0)).unwrap();
    while !is_finished(&program, &cp1) {
        step_generation(&program, &mut cp1, &eval1).unwrap();
    }
    assert!(program.stages[1].layout.bits as usize > old);
    for g in &cp1.population {
        assert_eq!(g.bits.len(), program.stages[1].layout.bits as usize);
        assert!(cp0.population.iter().any(|p| p.bits[..] == g.bits[..old]));
    }
    assert_eq!(cp1.history.len(), 4);
    assert_eq!(cp1.history[2].stage, "collect");
    assert_eq!(cp1.history[2].generation, 2);
}
