//! One generation of the GA on bit strings: selection, one-point crossover and
//! bit-flip mutation, all restricted to the evolvable (unmasked) bits.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::genome::Genome;
use crate::program::{Evolution, GenomeLayout, Selection};

/// The mask of a layout, one entry per bit: `true` for a bit of a frozen gene.
/// Bits outside every gene are evolvable (they carry no meaning).
pub fn frozen_mask(layout: &GenomeLayout) -> Vec<bool> {
    let mut mask = vec![false; layout.bits as usize];
    for gene in layout.genes.iter().filter(|g| g.frozen) {
        let start = (gene.offset as usize).min(mask.len());
        let end = (gene.offset as usize + gene.bits as usize).min(mask.len());
        mask[start..end].fill(true);
    }
    mask
}

/// Indices of the individuals sorted by fitness, best first; ties keep the
/// lower index first.
pub fn ranking(fitness: &[f32]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..fitness.len()).collect();
    order.sort_by(|&a, &b| fitness[b].total_cmp(&fitness[a]).then(a.cmp(&b)));
    order
}

/// Breeds the next population (same size) from an evaluated one.
///
/// Order of operations, which fixes the RNG draws:
/// 1. the best `elitism` individuals are copied unchanged to the first slots;
/// 2. the remaining `n - elitism` slots get parents: with truncation, the
///    ranked best `keep` repeated cyclically (each makes about
///    `n / keep` offspring) and then shuffled (Fisher-Yates); with roulette,
///    `n - elitism` fitness-proportional draws (fitness shifted so the
///    lowest is 0 when some are negative; uniform when all are equal);
/// 3. consecutive parents form pairs; with probability `crossover` a pair
///    exchanges the evolvable bits after one random cut point among the
///    evolvable bits (an odd last parent is copied); each child keeps the
///    frozen bits of its first parent;
/// 4. every evolvable bit of every child flips with probability `mutation`.
///
/// `mask[i]` is true for bits that never change. Inputs must be consistent
/// (same lengths); the driver checks that before calling.
pub fn next_generation(
    evo: &Evolution,
    mask: &[bool],
    population: &[Genome],
    fitness: &[f32],
    rng: &mut ChaCha8Rng,
) -> Vec<Genome> {
    let n = population.len();
    if n == 0 {
        return Vec::new();
    }
    let free: Vec<usize> = mask.iter().enumerate().filter(|(_, &frozen)| !frozen).map(|(i, _)| i).collect();
    let ranked = ranking(fitness);
    let elites = (evo.elitism as usize).min(n);
    let mut next: Vec<Genome> = ranked[..elites].iter().map(|&i| population[i].clone()).collect();
    let rest = n - elites;

    let parents: Vec<usize> = match evo.selection {
        Selection::Truncation { keep } => {
            let keep = (keep as usize).clamp(1, n);
            let mut parents: Vec<usize> = (0..rest).map(|j| ranked[j % keep]).collect();
            shuffle(&mut parents, rng);
            parents
        }
        Selection::Roulette => roulette(fitness, rest, rng),
    };

    for pair in parents.chunks(2) {
        let mut a = population[pair[0]].clone();
        if let [_, second] = pair {
            let mut b = population[*second].clone();
            if rng.random::<f32>() < evo.crossover && free.len() >= 2 {
                let cut = rng.random_range(1..free.len());
                for &bit in &free[cut..] {
                    std::mem::swap(&mut a.bits[bit], &mut b.bits[bit]);
                }
            }
            mutate(&mut a, &free, evo.mutation, rng);
            mutate(&mut b, &free, evo.mutation, rng);
            next.push(a);
            next.push(b);
        } else {
            mutate(&mut a, &free, evo.mutation, rng);
            next.push(a);
        }
    }
    next
}

fn mutate(genome: &mut Genome, free: &[usize], p: f32, rng: &mut ChaCha8Rng) {
    for &bit in free {
        if rng.random::<f32>() < p {
            genome.bits[bit] = u8::from(genome.bits[bit] == 0);
        }
    }
}

fn shuffle(items: &mut [usize], rng: &mut ChaCha8Rng) {
    for i in (1..items.len()).rev() {
        let j = rng.random_range(0..=i);
        items.swap(i, j);
    }
}

fn roulette(fitness: &[f32], draws: usize, rng: &mut ChaCha8Rng) -> Vec<usize> {
    let min = fitness.iter().copied().fold(0.0f32, f32::min) as f64;
    let mut cumulative = Vec::with_capacity(fitness.len());
    let mut total = 0.0f64;
    for &f in fitness {
        total += f as f64 - min;
        cumulative.push(total);
    }
    (0..draws)
        .map(|_| {
            if total > 0.0 {
                let x = rng.random::<f64>() * total;
                cumulative.partition_point(|&c| c <= x).min(fitness.len() - 1)
            } else {
                rng.random_range(0..fitness.len())
            }
        })
        .collect()
}
