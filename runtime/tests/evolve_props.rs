//! Property tests of the GA's masks: frozen bits never change.

use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use shaping_runtime::evolve::{
    frozen_mask, next_generation, start_stage, step_generation, Episode, Evaluation,
};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{
    Body, Evolution, Fitness, Gene, GeneRole, GenomeLayout, Inheritance, Program, Selection, Stage, StageRun,
    World, FORMAT_VERSION,
};

fn selection() -> impl Strategy<Value = Selection> {
    prop_oneof![(1u32..8).prop_map(|keep| Selection::Truncation { keep }), Just(Selection::Roulette)]
}

fn evolution(
    population: u32,
    selection: Selection,
    crossover: f32,
    mutation: f32,
    elitism: u32,
) -> Evolution {
    let selection = match selection {
        Selection::Truncation { keep } => Selection::Truncation { keep: keep.min(population) },
        s => s,
    };
    Evolution {
        population,
        generations: 30,
        actions: 10,
        seed: 0,
        selection,
        crossover,
        mutation,
        elitism: elitism.min(population),
        evaluations: 1,
    }
}

/// A layout from gene sizes and frozen flags.
fn layout(genes: &[(u8, bool)]) -> GenomeLayout {
    let mut offset = 0;
    let genes = genes
        .iter()
        .map(|&(bits, frozen)| {
            let g = Gene {
                offset,
                bits,
                lo: 0.0,
                hi: 1.0,
                stage: u16::from(!frozen),
                module: 0,
                role: GeneRole::Bias,
                frozen,
            };
            offset += bits as u32;
            g
        })
        .collect();
    GenomeLayout { genes, bits: offset }
}

fn stage(name: &str, parent: Option<usize>, layout: GenomeLayout, evo: Evolution) -> Stage {
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
        run: StageRun::Evolve(evo),
        inheritance: Inheritance::Darwinian,
        variants: None,
        targets: Vec::new(),
        roles: Vec::new(),
    }
}

fn frozen_part(g: &Genome, mask: &[bool]) -> Vec<u8> {
    g.bits.iter().zip(mask).filter(|(_, &m)| m).map(|(&b, _)| b).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Arbitrary masks (not only a frozen prefix) and arbitrary populations
    /// whose individuals differ in their frozen bits: over many generations,
    /// each individual's frozen bits are always those of one individual of
    /// the initial population, never a mix; and where the population starts
    /// with shared frozen bits, they stay exactly as they were.
    #[test]
    fn breeding_never_changes_or_mixes_frozen_bits(
        genes in prop::collection::vec((1u8..6, any::<bool>()), 1..12),
        population in 1u32..24,
        sel in selection(),
        crossover in 0.0f32..=1.0,
        mutation in 0.0f32..=1.0,
        elitism in 0u32..3,
        seed in any::<u64>(),
    ) {
        let layout = layout(&genes);
        let mask = frozen_mask(&layout);
        let evo = evolution(population, sel, crossover, mutation, elitism);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut pop: Vec<Genome> = (0..population)
            .map(|_| Genome { bits: (0..layout.bits).map(|_| u8::from(rand::Rng::random::<bool>(&mut rng))).collect() })
            .collect();
        let initial: Vec<Vec<u8>> = pop.iter().map(|g| frozen_part(g, &mask)).collect();
        let shared = pop[0].clone();
        let mut same: Vec<Genome> = pop.iter().map(|g| {
            let mut g = g.clone();
            for (i, &m) in mask.iter().enumerate() {
                if m { g.bits[i] = shared.bits[i]; }
            }
            g
        }).collect();
        for _ in 0..30 {
            let fitness: Vec<f32> = pop.iter().map(|g| g.bits.iter().map(|&b| b as f32).sum()).collect();
            pop = next_generation(&evo, &mask, &pop, &fitness, &mut rng);
            prop_assert_eq!(pop.len(), population as usize);
            for g in &pop {
                prop_assert_eq!(g.bits.len(), layout.bits as usize);
                prop_assert!(g.bits.iter().all(|&b| b <= 1));
                prop_assert!(initial.contains(&frozen_part(g, &mask)));
            }
            let fitness: Vec<f32> = same.iter().map(|g| g.bits.iter().map(|&b| b as f32).sum()).collect();
            same = next_generation(&evo, &mask, &same, &fitness, &mut rng);
            for g in &same {
                prop_assert_eq!(frozen_part(g, &mask), frozen_part(&shared, &mask));
            }
        }
    }

    /// Through the stage API: a random first stage, then a second stage that
    /// appends random genes; over many generations every individual keeps the
    /// frozen bits it inherited from one individual of the parent population.
    #[test]
    fn a_later_stage_never_changes_its_frozen_genes(
        old in prop::collection::vec(1u8..6, 1..6),
        new in prop::collection::vec(1u8..6, 1..6),
        sel in selection(),
        crossover in 0.0f32..=1.0,
        mutation in 0.0f32..=1.0,
        seed in any::<u64>(),
    ) {
        let first: Vec<(u8, bool)> = old.iter().map(|&b| (b, false)).collect();
        let second: Vec<(u8, bool)> =
            old.iter().map(|&b| (b, true)).chain(new.iter().map(|&b| (b, false))).collect();
        let program = Program {
            format: FORMAT_VERSION,
            name: "prop".into(),
            stages: vec![
                stage("a", None, layout(&first), evolution(12, sel, crossover, mutation, 1)),
                stage("b", Some(0), layout(&second), evolution(16, sel, crossover, mutation, 1)),
            ],
        };
        // Fitness counts every bit, frozen ones too: selection would favour
        // changing them if the GA could.
        let eval = |g: &Genome, _: Episode| Evaluation { fitness: g.bits.iter().map(|&b| b as f32).sum(), learned: None, ..Default::default() };
        let mut cp0 = start_stage(&program, 0, seed, None).unwrap();
        for _ in 0..3 {
            step_generation(&program, &mut cp0, &eval).unwrap();
        }
        let mask = frozen_mask(&program.stages[1].layout);
        let parents: Vec<Vec<u8>> = cp0.population.iter().map(|g| g.bits.clone()).collect();
        let mut cp1 = start_stage(&program, 1, seed, Some(&cp0)).unwrap();
        for _ in 0..25 {
            step_generation(&program, &mut cp1, &eval).unwrap();
            for g in &cp1.population {
                prop_assert_eq!(g.bits.len(), program.stages[1].layout.bits as usize);
                prop_assert!(parents.contains(&frozen_part(g, &mask)));
            }
        }
    }
}
