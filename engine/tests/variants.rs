//! Conditions per evaluation: a stage's variants change its world as
//! declared, every individual is evaluated in each (or in the drawn ones),
//! and its fitness is the mean or the minimum of the variants' fitness.

use shaping_runtime::evolve::{self, seed, Episode, EvalOptions, Evaluation};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Aggregate, Program, Stage};

/// A robot that stands still where the variant starts it: its fitness is
/// the start's x.
const SRC: &str = r#"
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world {
    arena 400mm x 400mm
    start at (100mm, 200mm) heading 90
    body { wheel_noise 0  sensor_noise 0 }
  }
  variants mean {
    west { start at (100mm, 200mm) heading 90 }
    east { start at (300mm, 200mm) heading 90 }
    far  { start at (350mm, 200mm) heading 90 }
  }
  evolve { population 6  generations 2  actions 3 }
  fitness at end robot.x
  module m { sense ir  behavior stop }
}
"#;

fn program() -> Program {
    shaping_compiler::compile(SRC, "variants.bat").unwrap()
}

fn evaluator(stage: &Stage, actions: u32) -> impl Fn(&Genome, Episode) -> Evaluation + Sync + '_ {
    evolve::evaluator(stage, EvalOptions { actions, learning: true })
}

#[test]
fn a_variant_changes_the_world_as_declared() {
    let p = program();
    let st = &p.stages[0];
    let v = st.variants.as_ref().unwrap();
    let names: Vec<&str> = v.list.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["west", "east", "far"]);
    assert_eq!(v.list[0].world, st.world, "`west` restates the stage's start");
    let east = v.list[1].world.items.start.as_ref().unwrap();
    assert_eq!((east.from, east.to), ([300.0, 200.0], [300.0, 200.0]));
    assert_eq!(v.list[1].world.arena, st.world.arena);
    // An episode runs in the variant it names.
    let eval = evaluator(st, 3);
    let genome = Genome::zeros(st.layout.bits as usize);
    for (k, x) in [100.0, 300.0, 350.0].into_iter().enumerate() {
        let f = eval(&genome, Episode::in_variant(12345, k)).fitness;
        assert!((f - x).abs() < 1e-3, "variant {k}: {f}");
    }
}

/// The variant travels beside the seed: a seed never chooses one (a seed
/// whose low bits read 2 runs the variant it is given, or the stage's own
/// world without one), and a variant the stage does not declare runs
/// nothing (NaN), rather than some other variant.
#[test]
fn the_variant_is_the_episode_s_not_its_seed_s() {
    let p = program();
    let st = &p.stages[0];
    let eval = evaluator(st, 3);
    let genome = Genome::zeros(st.layout.bits as usize);
    let seed = seed::variant_seed(12345, 2);
    let east = eval(&genome, Episode { seed, variant: Some(1) }).fitness;
    assert!((east - 300.0).abs() < 1e-3, "{east}");
    let own = eval(&genome, Episode::plain(seed)).fitness;
    assert!((own - 100.0).abs() < 1e-3, "the stage's own start: {own}");
    assert!(eval(&genome, Episode { seed, variant: Some(3) }).fitness.is_nan());
    let d = shaping_engine::descriptors::evaluate(st, &genome, &[Episode { seed, variant: Some(64) }]);
    assert!(d.evaluation.fitness.is_nan());
}

fn run(p: &Program) -> Vec<evolve::GenStats> {
    let eval = evaluator(&p.stages[0], 3);
    let mut cp = evolve::start_stage(p, 0, 7, None).unwrap();
    let mut out = Vec::new();
    while !evolve::is_finished(p, &cp) {
        out.push(evolve::step_generation(p, &mut cp, &eval).unwrap());
    }
    out
}

#[test]
fn the_fitness_is_the_mean_or_the_minimum_of_the_variants() {
    let mut p = program();
    for g in run(&p) {
        assert_eq!(g.best_variants.len(), 3);
        let per: Vec<f32> = g.best_variants.iter().map(|f| f.unwrap()).collect();
        assert!((per[0] - 100.0).abs() < 1e-3 && (per[1] - 300.0).abs() < 1e-3, "{per:?}");
        assert!((g.best - 250.0).abs() < 1e-3, "mean of 100, 300 and 350: {}", g.best);
    }
    p.stages[0].variants.as_mut().unwrap().aggregate = Aggregate::Min;
    for g in run(&p) {
        assert!((g.best - 100.0).abs() < 1e-3, "the lowest: {}", g.best);
    }
}

#[test]
fn drawn_variants_are_the_same_for_a_generation_and_any_thread_count() {
    let mut p = program();
    p.stages[0].variants.as_mut().unwrap().draw = Some(1);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| run(&p));
    let four = rayon::ThreadPoolBuilder::new().num_threads(4).build().unwrap().install(|| run(&p));
    assert_eq!(one, four);
    for g in &one {
        let drawn: Vec<usize> = (0..3).filter(|&i| g.best_variants[i].is_some()).collect();
        assert_eq!(drawn.len(), 1, "{:?}", g.best_variants);
        assert_eq!(drawn, evolve::drawn_variants(&p.stages[0], 7, 0, g.stage_generation));
        // One variant drawn: the fitness is its own.
        assert_eq!(Some(g.best), g.best_variants[drawn[0]]);
    }
    // Over many generations, every variant is drawn.
    let mut seen = [false; 3];
    for gen in 0..40 {
        for v in evolve::drawn_variants(&p.stages[0], 7, 0, gen) {
            seen[v] = true;
        }
    }
    assert_eq!(seen, [true; 3]);
}

#[test]
fn set_reaches_the_variants_and_their_worlds() {
    use shaping_engine::sweep::apply;
    let mut p = program();
    let point = vec![
        ("s.variants.aggregate".to_string(), "min".to_string()),
        ("s.variants.draw".to_string(), "2".to_string()),
        ("s.world.body.wheel_noise".to_string(), "0.1".to_string()),
    ];
    apply(&mut p, &point).unwrap();
    let v = p.stages[0].variants.as_ref().unwrap();
    assert_eq!((v.aggregate, v.draw), (Aggregate::Min, Some(2)));
    assert!(v.list.iter().all(|x| x.world.body.wheel_noise == 0.1), "every variant's body too");
    // Drawing more than declared is refused, naming the field.
    let mut q = program();
    let err = apply(&mut q, &[("s.variants.draw".to_string(), "4".to_string())]).unwrap_err();
    assert!(err.to_string().contains("draw"), "{err}");
}

#[test]
fn the_variants_are_part_of_the_fingerprint() {
    use shaping_runtime::evolve::fingerprint::{changes, fingerprint};
    let p = program();
    let mut q = program();
    q.stages[0].variants.as_mut().unwrap().list[1].world.items.start.as_mut().unwrap().from[0] = 310.0;
    let said = changes(&fingerprint(&p, 0), &fingerprint(&q, 0));
    assert_eq!(said, ["the variants of `s` changed"]);
    let mut r = program();
    r.stages[0].variants.as_mut().unwrap().aggregate = Aggregate::Min;
    assert_eq!(changes(&fingerprint(&p, 0), &fingerprint(&r, 0)).len(), 1);
    assert!(changes(&fingerprint(&p, 0), &fingerprint(&program(), 0)).is_empty());
}
