//! The incremental GA on synthetic fitness functions (no simulator needed).

use shaping_runtime::evolve::{
    self, best_of, check_resume, frozen_mask, is_finished, seed, start_stage, step_generation, test_best,
    Checkpoint, Episode, Evaluation, EvolveError, GenStats,
};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{
    Body, Evolution, Fitness, Gene, GeneRole, GenomeLayout, Inheritance, Program, Selection, Stage, StageRun,
    World, FORMAT_VERSION,
};

// ---------------------------------------------------------------- builders

/// A layout of `genes` 4-bit genes; the first `frozen` are frozen.
fn layout(genes: u32, frozen: u32) -> GenomeLayout {
    GenomeLayout {
        genes: (0..genes)
            .map(|i| Gene {
                offset: 4 * i,
                bits: 4,
                lo: -4.0,
                hi: 4.0,
                stage: u16::from(i >= frozen),
                module: 0,
                role: GeneRole::Bias,
                frozen: i < frozen,
            })
            .collect(),
        bits: 4 * genes,
    }
}

fn evolution(population: u32, generations: u32) -> Evolution {
    Evolution {
        population,
        generations,
        actions: 100,
        seed: 7,
        selection: Selection::Truncation { keep: population / 5 },
        crossover: 0.2,
        mutation: 0.05,
        elitism: 1,
        evaluations: 1,
    }
}

fn stage(name: &str, parent: Option<usize>, layout: GenomeLayout, run: StageRun) -> Stage {
    Stage {
        name: name.into(),
        parent,
        sensors: vec![],
        actuators: vec![],
        world: World {
            arena: [500.0, 500.0],
            body: Body::default(),
            charger: None,
            battery: None,
            objects: None,
            items: Default::default(),
            robots: 1,
        },
        modules: vec![],
        links: vec![],
        layout,
        fitness: Fitness { per_action: None, at_end: None, bonuses: vec![], team: Default::default() },
        run,
        inheritance: Inheritance::Darwinian,
        variants: None,
        targets: Vec::new(),
        roles: Vec::new(),
    }
}

/// Stage `first` (10 genes) evolved, then `second` extends it with 6 genes.
fn two_stages(population: u32, generations: u32) -> Program {
    Program {
        format: FORMAT_VERSION,
        name: "test".into(),
        stages: vec![
            stage("first", None, layout(10, 0), StageRun::Evolve(evolution(population, generations))),
            stage("second", Some(0), layout(16, 10), StageRun::Evolve(evolution(population, generations))),
        ],
    }
}

fn one_stage(population: u32, generations: u32) -> Program {
    let mut p = two_stages(population, generations);
    p.stages.truncate(1);
    p
}

/// Fraction of ones among the evolvable bits, plus a small seed-dependent
/// noise (so the episode seed matters, as in a noisy simulation).
fn onemax(mask: Vec<bool>) -> impl Fn(&Genome, Episode) -> Evaluation + Sync {
    move |g: &Genome, episode: Episode| {
        let free = mask.iter().filter(|&&m| !m).count().max(1);
        let ones = g.bits.iter().zip(&mask).filter(|(&b, &m)| b == 1 && !m).count();
        let noise = (seed::splitmix64(episode.seed) >> 40) as f32 / (1u64 << 24) as f32 * 0.01;
        Evaluation { fitness: ones as f32 / free as f32 + noise, learned: None, ..Default::default() }
    }
}

/// Noise-free: fraction of ones over all bits.
fn ones(g: &Genome, _episode: Episode) -> Evaluation {
    Evaluation {
        fitness: g.bits.iter().filter(|&&b| b == 1).count() as f32 / g.bits.len() as f32,
        ..Default::default()
    }
}

fn run_stage(program: &Program, cp: &mut Checkpoint, eval: evolve::Evaluate) -> Vec<GenStats> {
    let mut stats = Vec::new();
    while !is_finished(program, cp) {
        stats.push(step_generation(program, cp, eval).expect("generation"));
    }
    stats
}

fn frozen_part(g: &Genome, mask: &[bool]) -> Vec<u8> {
    g.bits.iter().zip(mask).filter(|(_, &m)| m).map(|(&b, _)| b).collect()
}

// ---------------------------------------------------------------- tests

#[test]
fn fitness_rises_over_five_generations() {
    let program = one_stage(40, 5);
    let eval = onemax(frozen_mask(&program.stages[0].layout));
    let mut cp = start_stage(&program, 0, 42, None).unwrap();
    let stats = run_stage(&program, &mut cp, &eval);
    assert_eq!(stats.len(), 5);
    assert_eq!(cp.generation, 5);
    let (first, last) = (&stats[0], &stats[4]);
    assert!(last.best > first.best, "best {} -> {}", first.best, last.best);
    assert!(last.mean > first.mean + 0.1, "mean {} -> {}", first.mean, last.mean);
    for s in &stats {
        assert!(s.worst <= s.mean && s.mean <= s.best, "{s:?}");
        assert_eq!(cp.history.len(), 5);
    }
    // The final checkpoint holds the evaluated final population.
    assert_eq!(cp.fitness.len(), 40);
    assert_eq!(cp.fitness[last.best_index as usize], last.best);
    let best = cp.best.as_ref().unwrap();
    assert_eq!(best.1, stats.iter().map(|s| s.best).fold(f32::MIN, f32::max));
}

#[test]
fn roulette_selection_also_improves() {
    let mut program = one_stage(40, 8);
    if let StageRun::Evolve(evo) = &mut program.stages[0].run {
        evo.selection = Selection::Roulette;
        evo.crossover = 0.1;
        evo.mutation = 0.02;
        evo.elitism = 0;
    }
    let mut cp = start_stage(&program, 0, 3, None).unwrap();
    let stats = run_stage(&program, &mut cp, &ones);
    assert!(stats[7].mean > stats[0].mean + 0.03, "mean {} -> {}", stats[0].mean, stats[7].mean);
}

#[test]
fn elitism_keeps_the_best_unchanged() {
    let mut program = one_stage(20, 6);
    if let StageRun::Evolve(evo) = &mut program.stages[0].run {
        evo.mutation = 0.5; // everything else is scrambled
        evo.elitism = 2;
    }
    let mut cp = start_stage(&program, 0, 11, None).unwrap();
    step_generation(&program, &mut cp, &ones).unwrap();
    for _ in 1..6 {
        let ranked = evolve::ranking(&cp.fitness);
        let elites: Vec<Genome> = ranked[..2].iter().map(|&i| cp.population[i].clone()).collect();
        let previous_best = cp.fitness[ranked[0]];
        let stats = step_generation(&program, &mut cp, &ones).unwrap();
        assert_eq!(&cp.population[..2], &elites[..], "elites copied to the first slots");
        assert!(stats.best >= previous_best);
    }
    // Without elitism and with this mutation rate, the best is lost.
    if let StageRun::Evolve(evo) = &mut program.stages[0].run {
        evo.elitism = 0;
    }
    let mut cp = start_stage(&program, 0, 11, None).unwrap();
    let stats = run_stage(&program, &mut cp, &ones);
    assert!(stats.windows(2).any(|w| w[1].best < w[0].best), "{stats:?}");
}

#[test]
fn identical_results_on_one_and_two_threads() {
    let program = two_stages(30, 4);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let eval0 = onemax(frozen_mask(&program.stages[0].layout));
            let mut cp0 = start_stage(&program, 0, 5, None).unwrap();
            run_stage(&program, &mut cp0, &eval0);
            let eval1 = onemax(frozen_mask(&program.stages[1].layout));
            let mut cp1 = start_stage(&program, 1, 5, Some(&cp0)).unwrap();
            run_stage(&program, &mut cp1, &eval1);
            (cp0, cp1)
        })
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    assert_eq!(one.1.history.len(), 8);
    // A different run seed gives a different run.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let other = pool.install(|| start_stage(&program, 0, 6, None).unwrap());
    assert_ne!(other.population, start_stage(&program, 0, 5, None).unwrap().population);
}

#[test]
fn resumed_run_equals_straight_run() {
    let program = one_stage(30, 8);
    let eval = onemax(frozen_mask(&program.stages[0].layout));
    let mut straight = start_stage(&program, 0, 9, None).unwrap();
    run_stage(&program, &mut straight, &eval);

    let mut cp = start_stage(&program, 0, 9, None).unwrap();
    for _ in 0..3 {
        step_generation(&program, &mut cp, &eval).unwrap();
    }
    let json = serde_json::to_string(&cp).unwrap();
    let mut resumed: Checkpoint = serde_json::from_str(&json).unwrap();
    assert_eq!(resumed, cp);
    check_resume(&program, &resumed).unwrap();
    run_stage(&program, &mut resumed, &eval);
    assert_eq!(resumed.population, straight.population);
    assert_eq!(resumed.fitness, straight.fitness);
    assert_eq!(resumed.history, straight.history);
    assert_eq!(resumed, straight);
}

#[test]
fn next_stage_keeps_frozen_bits_and_grows_the_genome() {
    let mut program = two_stages(20, 10);
    if let StageRun::Evolve(evo) = &mut program.stages[1].run {
        evo.mutation = 0.3;
        evo.crossover = 1.0;
        evo.population = 30; // larger than the parent's: parents are reused by rank
    }
    let eval0 = onemax(frozen_mask(&program.stages[0].layout));
    let mut cp0 = start_stage(&program, 0, 1, None).unwrap();
    run_stage(&program, &mut cp0, &eval0);
    let parent_bits: Vec<Vec<u8>> = cp0.population.iter().map(|g| g.bits.clone()).collect();

    let mask = frozen_mask(&program.stages[1].layout);
    assert_eq!(mask.iter().filter(|&&m| m).count(), 40);
    let mut cp1 = start_stage(&program, 1, 1, Some(&cp0)).unwrap();
    assert_eq!(cp1.population.len(), 30);
    assert!(cp1.population.iter().all(|g| g.bits.len() == 64));
    // Individual i starts from the parent of rank i mod 20.
    let ranked = evolve::ranking(&cp0.fitness);
    for (i, g) in cp1.population.iter().enumerate() {
        assert_eq!(g.bits[..40], parent_bits[ranked[i % 20]][..]);
    }
    // New genes are random.
    let new_ones: usize =
        cp1.population.iter().map(|g| g.bits[40..].iter().filter(|&&b| b == 1).count()).sum();
    assert!((200..=520).contains(&new_ones), "{new_ones} ones among 720 new bits");
    assert_eq!(cp1.history, cp0.history);

    // Evolution (fitness counts the new bits only) never touches the old ones:
    // every individual's frozen bits remain one of the parent's, whole.
    let eval1 = onemax(mask.clone());
    let stats = run_stage(&program, &mut cp1, &eval1);
    for g in &cp1.population {
        let frozen = frozen_part(g, &mask);
        assert!(parent_bits.iter().any(|p| p[..40] == frozen[..]));
    }
    // Global numbering continues from the first stage.
    assert_eq!(stats[0].generation, 10);
    assert_eq!(stats[0].stage_generation, 0);
    assert_eq!(stats[0].stage, "second");
    assert_eq!(cp1.history.len(), 20);
    assert!(stats[9].mean > stats[0].mean);
}

#[test]
fn a_checkpoint_is_refused_when_anything_it_depends_on_changed_saying_what() {
    let program = two_stages(10, 2);
    let mut cp0 = start_stage(&program, 0, 1, None).unwrap();
    run_stage(&program, &mut cp0, &ones);
    let mut cp1 = start_stage(&program, 1, 1, Some(&cp0)).unwrap();
    step_generation(&program, &mut cp1, &ones).unwrap();
    check_resume(&program, &cp1).unwrap();
    let changed = |edit: &dyn Fn(&mut Program)| {
        let mut p = program.clone();
        edit(&mut p);
        match check_resume(&p, &cp1) {
            Err(EvolveError::Changed { stage, what }) => {
                assert_eq!(stage, "second");
                what
            }
            other => panic!("{other:?}"),
        }
    };

    // A new stage appended after the checkpoint's: accepted.
    let mut appended = program.clone();
    let mut third = stage("third", Some(1), layout(20, 16), StageRun::Evolve(evolution(10, 2)));
    third.inheritance = Inheritance::Lamarckian;
    appended.stages.push(third);
    check_resume(&appended, &cp1).unwrap();
    step_generation(&appended, &mut cp1.clone(), &ones).unwrap();

    // More generations for the current stage: accepted (extends the run).
    let mut longer = program.clone();
    if let StageRun::Evolve(evo) = &mut longer.stages[1].run {
        evo.generations = 5;
    }
    check_resume(&longer, &cp1).unwrap();

    // Everything else of the stage, and all of the stage it extends, counts.
    assert_eq!(changed(&|p| p.stages[1].fitness.bonuses.push(bonus())), "the fitness of `second` changed");
    assert_eq!(
        changed(&|p| {
            p.stages[1].world.arena = [800.0, 800.0];
            p.stages[1].fitness.bonuses.push(bonus());
        }),
        "the world and fitness of `second` changed"
    );
    assert_eq!(
        changed(&|p| if let StageRun::Evolve(evo) = &mut p.stages[1].run {
            evo.population = 12;
        }),
        "the settings of `second` changed"
    );
    assert_eq!(
        changed(&|p| p.stages[0].layout.genes[3].hi = 2.0),
        "the genes of `first`, which `second` extends, changed"
    );
    // The parent's generations decide the population the stage started from.
    assert_eq!(
        changed(&|p| if let StageRun::Evolve(evo) = &mut p.stages[0].run {
            evo.generations = 3;
        }),
        "the generations of `first`, which `second` extends, changed"
    );
    assert_eq!(
        changed(&|p| {
            p.stages[0].world.body.wheel_noise = 0.5;
            p.stages[1].world.body.wheel_noise = 0.5;
        }),
        "the world of `second` changed; the world of `first`, which `second` extends, changed"
    );
    // A stage inserted before it moves it (its seeds depend on its place).
    let mut moved = program.clone();
    moved.stages.insert(0, stage("zero", None, layout(1, 0), StageRun::Train { actions: 5 }));
    moved.stages[2].parent = Some(1);
    let err = evolve::resume(&moved, 2, &mut cp1.clone()).unwrap_err().to_string();
    assert!(err.contains("the definition of stage `second` changed since it was saved: the position of `second` changed; the position of `first`, which `second` extends, changed"), "{err}");
    assert!(!err.contains("another version"), "{err}");

    // A stage removed.
    assert!(matches!(
        check_resume(&one_stage(10, 2), &cp1),
        Err(EvolveError::StageIndex { index: 1, count: 1 })
    ));

    // A checkpoint of another format.
    let mut old = cp1.clone();
    old.format = 0;
    assert!(matches!(check_resume(&program, &old), Err(EvolveError::CheckpointFormat { .. })));

    // Starting the second stage from a parent made with another program fails too.
    let mut other = program.clone();
    other.stages[0].layout.genes[3].hi = 2.0;
    assert!(matches!(start_stage(&other, 1, 1, Some(&cp0)), Err(EvolveError::Changed { .. })));
}

fn bonus() -> shaping_runtime::program::Bonus {
    shaping_runtime::program::Bonus { event: shaping_runtime::program::Event::Grip, points: 1.0 }
}

#[test]
fn a_checkpoint_beyond_the_declared_generations_or_with_bad_bits_is_refused() {
    let program = one_stage(10, 4);
    let mut cp = start_stage(&program, 0, 1, None).unwrap();
    run_stage(&program, &mut cp, &ones);
    let mut shorter = program.clone();
    if let StageRun::Evolve(evo) = &mut shorter.stages[0].run {
        evo.generations = 3;
    }
    let err = check_resume(&shorter, &cp).unwrap_err();
    assert_eq!(err, EvolveError::TooManyGenerations { stage: "first".into(), done: 4, declared: 3 });
    assert!(err.to_string().contains("holds 4 generations of stage `first`, which now declares 3"), "{err}");

    let refused = |edit: &dyn Fn(&mut Checkpoint)| {
        let mut bad = cp.clone();
        edit(&mut bad);
        check_resume(&program, &bad).unwrap_err().to_string()
    };
    let err = refused(&|c| c.population[3].bits[5] = 2);
    assert!(err.contains("bit 5 of individual 3 is 2; bits are 0 or 1"), "{err}");
    let err = refused(&|c| c.best.as_mut().unwrap().0.bits[0] = 7);
    assert!(err.contains("bit 0 of the best individual is 7"), "{err}");
    let err = refused(&|c| c.fitness[2] = f32::NAN);
    assert!(err.contains("the fitness of individual 2 is NaN"), "{err}");
    let err = refused(&|c| c.generation = 2);
    assert!(err.contains("4 generations of statistics for 2 generations done"), "{err}");
    let err = refused(&|c| {
        c.validated = true;
        c.best = None;
    });
    assert!(err.contains("holds none"), "{err}");
}

#[test]
fn a_finished_stage_given_more_generations_ends_as_a_straight_run() {
    let (short, long) = (one_stage(20, 3), one_stage(20, 6));
    let eval = onemax(frozen_mask(&short.stages[0].layout));
    let mut straight = start_stage(&long, 0, 4, None).unwrap();
    run_stage(&long, &mut straight, &eval);
    evolve::validate_best(&long, &mut straight, &eval, 4, 2).unwrap();

    let mut cp = start_stage(&short, 0, 4, None).unwrap();
    run_stage(&short, &mut cp, &eval);
    evolve::validate_best(&short, &mut cp, &eval, 4, 2).unwrap();
    assert!(!evolve::resume(&short, 0, &mut cp).unwrap(), "finished: nothing to reopen");
    assert!(evolve::resume(&long, 0, &mut cp).unwrap());
    run_stage(&long, &mut cp, &eval);
    evolve::validate_best(&long, &mut cp, &eval, 4, 2).unwrap();
    assert_eq!(cp, straight);
}

#[test]
fn fingerprints_are_stable() {
    // The hashes of a fixed stage must not change across runs or platforms.
    let program = two_stages(10, 2);
    let fp = evolve::fingerprint(&program, 1);
    assert_eq!(fp, evolve::fingerprint(&program.clone(), 1));
    assert_eq!(fp.len(), 2, "the stage and the stage it extends");
    assert_ne!(fp[0].parts, fp[1].parts);
    let parts: Vec<String> = fp[1].parts.iter().map(|(k, v)| format!("{k} {v:016x}")).collect();
    insta::assert_snapshot!(parts.join("\n"), @r"
    extends 5b9bc4ba528108e4
    fitness 62fa0ab6d910691b
    generations af63af4c8601a015
    genes 9e81b87f7dfd2057
    inheritance 106ac1d7d7998448
    links 09612b07b5ecb5a5
    modules 09612b07b5ecb5a5
    position af63ad4c86019caf
    robot 9d73114e90492e2d
    settings a85cce9cbd713a73
    world 4a10de298bbc1f51
    ");
}

#[test]
fn lamarckian_write_back_changes_only_evolvable_bits() {
    let mut program = two_stages(10, 1);
    program.stages[1].inheritance = Inheritance::Lamarckian;
    let mut cp0 = start_stage(&program, 0, 2, None).unwrap();
    run_stage(&program, &mut cp0, &ones);
    let mut cp1 = start_stage(&program, 1, 2, Some(&cp0)).unwrap();
    let before = cp1.population.clone();
    // "Learning" sets every bit to 1, frozen ones included.
    let learn = |g: &Genome, _: Episode| Evaluation {
        fitness: 0.5,
        learned: Some(Genome { bits: vec![1; g.bits.len()] }),
        ..Default::default()
    };
    step_generation(&program, &mut cp1, &learn).unwrap();
    for (after, before) in cp1.population.iter().zip(&before) {
        assert_eq!(after.bits[..40], before.bits[..40]);
        assert!(after.bits[40..].iter().all(|&b| b == 1));
    }
    // The stage's best is the genome as evaluated.
    assert_eq!(cp1.best.as_ref().unwrap().0, before[0]);

    // Darwinian: ignored.
    program.stages[1].inheritance = Inheritance::Darwinian;
    let mut cp1 = start_stage(&program, 1, 2, Some(&cp0)).unwrap();
    step_generation(&program, &mut cp1, &learn).unwrap();
    assert_eq!(cp1.population, before);

    // A learned genome of the wrong length is an error, not a panic.
    program.stages[1].inheritance = Inheritance::Lamarckian;
    let bad = |_: &Genome, _: Episode| Evaluation {
        fitness: 0.5,
        learned: Some(Genome { bits: vec![1; 3] }),
        ..Default::default()
    };
    let mut cp1 = start_stage(&program, 1, 2, Some(&cp0)).unwrap();
    assert!(matches!(
        step_generation(&program, &mut cp1, &bad),
        Err(EvolveError::LearnedLength { expected: 64, found: 3, .. })
    ));
}

#[test]
fn evaluations_average_episodes_with_distinct_seeds() {
    let mut program = one_stage(6, 1);
    if let StageRun::Evolve(evo) = &mut program.stages[0].run {
        evo.evaluations = 3;
    }
    let seen = std::sync::Mutex::new(Vec::new());
    let eval = |_: &Genome, e: Episode| {
        let s = e.seed;
        seen.lock().unwrap().push(s);
        Evaluation { fitness: (s % 7) as f32, learned: None, ..Default::default() }
    };
    let mut cp = start_stage(&program, 0, 4, None).unwrap();
    step_generation(&program, &mut cp, &eval).unwrap();
    let mut seen = seen.into_inner().unwrap();
    assert_eq!(seen.len(), 18);
    for i in 0..6 {
        let seeds: Vec<u64> = (0..3).map(|e| seed::episode_seed(4, 0, 0, i, e)).collect();
        let mean = seeds.iter().map(|s| (s % 7) as f64).sum::<f64>() / 3.0;
        assert_eq!(cp.fitness[i], mean as f32);
    }
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(seen.len(), 18, "every episode has its own seed");
}

#[test]
fn test_stage_runs_the_parents_best() {
    let mut program = one_stage(10, 3);
    program.stages.push(stage(
        "check",
        Some(0),
        layout(10, 10),
        StageRun::Test { actions: 50, lives: 1, learning: false },
    ));
    let mut cp = start_stage(&program, 0, 8, None).unwrap();
    run_stage(&program, &mut cp, &ones);
    let (best, best_fitness) = best_of(&cp).unwrap();
    let out = test_best(&program, 1, 8, &cp, &ones).unwrap();
    assert_eq!(out.genome, best);
    assert_eq!(out.parent_fitness, best_fitness);
    assert_eq!(out.evaluation.fitness, ones(&best, Episode::plain(0)).fitness);
    assert_eq!(out.seed, seed::test_seed(8, 1, 0));
    // A stage extending a test stage starts from the evolved ancestor.
    program.stages.push(stage("more", Some(1), layout(12, 10), StageRun::Evolve(evolution(10, 1))));
    let cp2 = start_stage(&program, 2, 8, Some(&cp)).unwrap();
    assert_eq!(cp2.population[0].bits[..40], best.bits[..]);
    // A second test of the same best runs the first test's lives (paired).
    program.stages.push(stage(
        "check again",
        Some(0),
        layout(10, 10),
        StageRun::Test { actions: 50, lives: 1, learning: true },
    ));
    let again = test_best(&program, 3, 8, &cp, &ones).unwrap();
    assert_eq!((again.genome, again.seed), (best.clone(), out.seed));
    assert_eq!(shaping_runtime::evolve::test_seed_stage(&program, 3), 1);
    // Misuse is reported.
    assert!(matches!(test_best(&program, 0, 8, &cp, &ones), Err(EvolveError::NotTest { .. })));
    assert!(matches!(start_stage(&program, 1, 8, Some(&cp)), Err(EvolveError::NotEvolved { .. })));
}

/// A test stage lives at least one life in each world, and its lives
/// together are no longer than the longest life; a program saved before
/// lives existed has one.
#[test]
fn a_test_stage_has_at_least_one_life_and_old_programs_have_one() {
    use shaping_runtime::limits::MAX_ACTIONS;
    let mut st = shaping_runtime::testkit::navigation();
    st.parent = Some(0);
    let check = |st: &Stage, actions: u32, lives: u32| {
        let mut st = st.clone();
        st.run = StageRun::Test { actions, lives, learning: true };
        shaping_runtime::validate::stage(&st).map_err(|e| e.to_string())
    };
    assert_eq!(check(&st, 300, 10), Ok(()));
    let err = check(&st, 300, 0).unwrap_err();
    assert!(err.contains("`run.test.lives`: 0 is not between 1 and"), "{err}");
    let err = check(&st, MAX_ACTIONS, 2).unwrap_err();
    assert!(err.contains("`run.test.lives`: 2 lives of 10000000 actions make 20000000 actions"), "{err}");
    assert_eq!(check(&st, MAX_ACTIONS / 4, 4), Ok(()));

    let now = StageRun::Test { actions: 50, lives: 1, learning: true };
    let old = serde_json::to_string(&now).unwrap().replace(",\"lives\":1", "");
    assert!(!old.contains("lives"), "{old}");
    assert_eq!(serde_json::from_str::<StageRun>(&old).unwrap(), now);
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let program = two_stages(10, 2);
    assert!(matches!(start_stage(&program, 5, 1, None), Err(EvolveError::StageIndex { index: 5, count: 2 })));
    assert!(matches!(start_stage(&program, 1, 1, None), Err(EvolveError::MissingParent { .. })));
    let cp0 = start_stage(&program, 0, 1, None).unwrap();
    assert!(matches!(start_stage(&program, 0, 1, Some(&cp0)), Err(EvolveError::UnexpectedParent { .. })));
    assert!(matches!(start_stage(&program, 1, 1, Some(&cp0)), Err(EvolveError::ParentNotEvaluated { .. })));

    // The GA trusts a validated program; the validation refuses a population of 0.
    let mut zero = shaping_runtime::testkit::navigation();
    if let StageRun::Evolve(evo) = &mut zero.run {
        evo.population = 0;
    }
    let err = shaping_runtime::validate::stage(&zero).unwrap_err().to_string();
    assert!(err.contains("`run.evolve.population`: 0 is not between 1 and 100000"), "{err}");

    let mut frozen_first = program.clone();
    frozen_first.stages[0].layout = layout(10, 2);
    assert!(matches!(
        start_stage(&frozen_first, 0, 1, None),
        Err(EvolveError::FrozenWithoutParent { gene: 0, .. })
    ));

    let mut not_extension = program.clone();
    not_extension.stages[1].layout.genes[0].bits = 3;
    let mut cp0 = start_stage(&not_extension, 0, 1, None).unwrap();
    run_stage(&not_extension, &mut cp0, &ones);
    assert!(matches!(start_stage(&not_extension, 1, 1, Some(&cp0)), Err(EvolveError::NotAnExtension { .. })));

    let nan = |_: &Genome, _: Episode| Evaluation { fitness: f32::NAN, learned: None, ..Default::default() };
    let mut cp = start_stage(&program, 0, 1, None).unwrap();
    let err = step_generation(&program, &mut cp, &nan).unwrap_err();
    assert!(matches!(err, EvolveError::NonFiniteFitness { index: 0, generation: 0, .. }), "{err}");
    // A failed generation leaves the checkpoint as it was.
    step_generation(&program, &mut cp, &ones).unwrap();
    let before = cp.clone();
    let err = step_generation(&program, &mut cp, &nan).unwrap_err();
    assert!(matches!(err, EvolveError::NonFiniteFitness { generation: 1, .. }), "{err}");
    assert_eq!(cp, before);

    let mut truncated = start_stage(&program, 0, 1, None).unwrap();
    truncated.population[3].bits.pop();
    assert!(matches!(
        step_generation(&program, &mut truncated, &ones),
        Err(EvolveError::Inconsistent { .. })
    ));
}

#[test]
fn validate_best_prefers_the_best_mean_over_a_lucky_evaluation() {
    // A "lucky" evaluation: during evolution an all-zeros genome is scored
    // by a noisy evaluation that once gave it 10; on fresh episodes it is
    // worth 0, while an all-ones genome of the final population is worth 1.
    let program = one_stage(10, 2);
    let mut cp = start_stage(&program, 0, 3, None).unwrap();
    let bits = cp.population[0].bits.len();
    cp.population = (0..10).map(|i| Genome { bits: vec![u8::from(i == 4); bits] }).collect();
    cp.fitness = (0..10).map(|i| if i == 4 { 0.9 } else { 0.1 }).collect();
    cp.best = Some((Genome { bits: vec![0; bits] }, 10.0));
    let fresh = |g: &Genome, _e: Episode| ones(g, Episode::plain(0));
    let (g, f) = evolve::validate_best(&program, &mut cp, &fresh, 4, 3).unwrap();
    assert_eq!(g.bits, vec![1; bits], "the all-ones genome wins on fresh episodes");
    assert_eq!(f, 1.0);
    assert!(cp.validated);
    assert_eq!(best_of(&cp), Some((g.clone(), 1.0)));

    // Idempotent: a second call (e.g. after resuming a finished run) keeps it.
    let never = |_: &Genome, _: Episode| -> Evaluation { panic!("not evaluated again") };
    assert_eq!(evolve::validate_best(&program, &mut cp, &never, 4, 3).unwrap(), (g, 1.0));

    // Every candidate sees the same episode seeds, and they are distinct.
    let seen = std::sync::Mutex::new(Vec::new());
    let record = |g: &Genome, e: Episode| {
        seen.lock().unwrap().push((g.bits[0], e.seed));
        ones(g, e)
    };
    let mut cp2 = start_stage(&program, 0, 3, None).unwrap();
    cp2.fitness = vec![0.5; 10];
    evolve::validate_best(&program, &mut cp2, &record, 2, 3).unwrap();
    let mut seeds: Vec<u64> = seen.lock().unwrap().iter().map(|&(_, e)| e).collect();
    assert_eq!(seeds.len(), 6, "2 candidates x 3 episodes");
    seeds.sort_unstable();
    seeds.dedup();
    assert_eq!(seeds.len(), 3, "the candidates share the 3 episode seeds");
}

#[test]
fn generation_stats_carry_the_best_individuals_events_summed_over_its_episodes() {
    let mut program = one_stage(8, 1);
    if let StageRun::Evolve(evo) = &mut program.stages[0].run {
        evo.evaluations = 2;
    }
    // Events that identify the individual (its count of ones) and the episode.
    let eval = |g: &Genome, e: Episode| {
        let s = e.seed;
        let ones = g.bits.iter().filter(|&&b| b == 1).count() as u32;
        Evaluation {
            fitness: ones as f32,
            events: evolve::Events { grips: ones, releases_outside: (s % 3) as u32, recharges: 1 },
            ..Default::default()
        }
    };
    let mut cp = start_stage(&program, 0, 9, None).unwrap();
    for _ in 0..3 {
        let st = step_generation(&program, &mut cp, &eval).unwrap();
        let best = &cp.population[st.best_index as usize];
        let ones = best.bits.iter().filter(|&&b| b == 1).count() as u32;
        let g = st.stage_generation;
        let releases: u32 =
            (0..2).map(|e| (seed::episode_seed(9, 0, g, st.best_index as usize, e) % 3) as u32).sum();
        assert_eq!(st.best_grips, 2 * ones, "generation {g}");
        assert_eq!(st.best_releases_outside, releases, "generation {g}");
        assert_eq!(st.best_recharges, 2, "generation {g}");
        assert_eq!(cp.history.last(), Some(&st));
    }
}
