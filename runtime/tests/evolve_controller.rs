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

/// An episode in a world too crowded to place apart says so in its result,
/// and a generation counts its crowded episodes; a world with room enough
/// counts none, and saved results without the counts are as before.
#[test]
fn crowded_episodes_are_counted_from_the_episode_to_the_generation() {
    use shaping_runtime::controller::{run_episode, EpisodeOptions, EpisodeResult};
    use shaping_runtime::genome::Genome;
    use shaping_runtime::program::Objects;
    let mut stage = testkit::navigation();
    if let StageRun::Evolve(evo) = &mut stage.run {
        evo.population = 30;
        evo.generations = 1;
        evo.selection = shaping_runtime::program::Selection::Truncation { keep: 4 };
        evo.actions = 5;
    }
    stage.world.objects = Some(Objects { count: 25, diameter: 60.0, virtual_: false });
    let genome = Genome::zeros(stage.layout.bits as usize);
    let episode = |stage: &shaping_runtime::program::Stage, seed| {
        run_episode(stage, &genome, &EpisodeOptions { actions: 5, learning: false, seed }, None)
    };
    // The simulator's seed is the episode seed: 25 fails, 1 does not
    // (runtime/tests/sim.rs).
    assert!(episode(&stage, 25).placement_failures > 0);
    assert_eq!(episode(&stage, 1).placement_failures, 0);

    let run = |stage: shaping_runtime::program::Stage, seed| {
        let program = Program { format: FORMAT_VERSION, name: "crowded".into(), stages: vec![stage] };
        let eval = evaluate_with_controller(&program.stages[0], EvalOptions::of(&program.stages[0])).unwrap();
        let mut cp = start_stage(&program, 0, seed, None).unwrap();
        let stats = step_generation(&program, &mut cp, &eval).unwrap();
        (stats, cp)
    };
    let mut crowded = stage.clone();
    crowded.world.objects = Some(Objects { count: 30, diameter: 60.0, virtual_: false });
    let (stats, cp) = run(crowded, 5);
    assert!(stats.crowded_episodes > 0 && stats.crowded_episodes < 30, "{stats:?}");
    assert!(stats.placement_failures >= stats.crowded_episodes, "{stats:?}");
    let json = serde_json::to_string(&cp).unwrap();
    assert!(json.contains("\"crowded_episodes\""), "{json}");

    let mut roomy = stage;
    roomy.world.objects = Some(Objects { count: 8, diameter: 25.0, virtual_: false });
    let (stats, cp) = run(roomy, 5);
    assert_eq!((stats.crowded_episodes, stats.placement_failures), (0, 0));
    let json = serde_json::to_string(&cp).unwrap();
    assert!(!json.contains("crowded") && !json.contains("placement"), "{json}");
    let old: EpisodeResult = serde_json::from_str(
        r#"{"fitness":1.5,"actions":3,"grips":0,"releases_outside":0,"recharges":0,"collisions":1,"learned":null}"#,
    )
    .unwrap();
    assert_eq!(old.placement_failures, 0);
    assert!(!serde_json::to_string(&old).unwrap().contains("placement"));
}
