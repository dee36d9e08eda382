"""CMA-ES (pycma) on navigation's genes through `Evaluator.evaluate`,
against shaping's own GA with the same number of evaluations.

    pip install cma
    python python/examples/cma_navigation.py [--seeds 10]

For each seed s: the GA is `shaping run --stage navigation --seed s` as
`examples/khepera.bat` declares it (a population of 100 for 40
generations: 4,000 evaluations, then its choice of the best by a mean
over fresh episodes). CMA-ES (default population for 48 dimensions,
initial step a quarter of the gene range) searches the 48 genes as real
values, each rounded to its gene's 16 levels, for the same 4,000
evaluations, each generation on fresh episodes (`generation=`) as the
GA's are; its result is whichever of its best-scoring individual and its
final mean scores better over 10 further episodes (the GA too chooses its
best by a mean over fresh episodes).
Both are then measured on the same 100 fresh episodes, with the trained
avoidance weights of the seed's run. Prints one line per seed and the
medians.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import warnings
from pathlib import Path

import cma
import numpy as np

import shaping
from shaping import genes

KHEPERA = Path(__file__).resolve().parents[2] / "examples" / "khepera.bat"
STAGE = "navigation"
BUDGET = 4000  # the GA's: population 100 x 40 generations
TEST_EPISODES = 100


def measure(program, run, seed, genome) -> float:
    """The mean fitness of `genome` over the same fresh episodes for every optimizer."""
    ev = program.evaluator(STAGE, run=run, seed=1_000_000 + seed)
    return float(ev.evaluate(np.repeat(genome[None, :], TEST_EPISODES, axis=0))["fitness"].mean())


def cma_es(program, run, seed) -> np.ndarray:
    lo, hi = genes.bounds(program, STAGE)
    ev = program.evaluator(STAGE, run=run, seed=seed)
    opts = {"seed": seed, "bounds": [lo.tolist(), hi.tolist()], "verbose": -9, "maxfevals": BUDGET}
    es = cma.CMAEvolutionStrategy(np.zeros(len(lo)), 0.25 * float(np.mean(hi - lo)), opts)
    best, best_fitness, generation, used = None, -np.inf, 0, 0
    while used < BUDGET:
        xs = es.ask()
        xs = xs[: BUDGET - used]
        g = genes.encode(program, STAGE, xs)
        fitness = ev.evaluate(g, generation=generation)["fitness"].astype(float)
        used += len(xs)
        generation += 1
        if len(xs) == es.popsize:
            es.tell(xs, (-fitness).tolist())
        i = int(np.argmax(fitness))
        if fitness[i] > best_fitness:
            best, best_fitness = g[i], fitness[i]
    # Like the GA, choose by a mean over fresh episodes, not by the luckiest
    # single episode: the best individual seen or CMA's mean, 10 episodes each.
    candidates = np.vstack([best[None, :], genes.encode(program, STAGE, es.mean)])
    choice = program.evaluator(STAGE, run=run, seed=2_000_000 + seed)
    means = [choice.evaluate(np.repeat(c[None, :], 10, axis=0))["fitness"].mean() for c in candidates]
    return candidates[int(np.argmax(means))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=10)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    program = shaping.compile(KHEPERA)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(1, args.seeds + 1):
            run = shaping.run(KHEPERA, out=Path(tmp) / f"ga-{seed}", seed=seed, stage=STAGE, report=False)
            ga = measure(program, run, seed, run.best_genome(STAGE))
            es = measure(program, run, seed, cma_es(program, run, seed))
            rows.append((ga, es))
            print(f"seed {seed:2}: GA {ga:.3f}  CMA-ES {es:.3f}", flush=True)
    ga, es = zip(*rows)
    print(
        f"median over {len(rows)} seeds of the fitness on {TEST_EPISODES} fresh episodes, "
        f"{BUDGET} evaluations each: GA {statistics.median(ga):.3f} (range {min(ga):.3f}..{max(ga):.3f}), "
        f"CMA-ES {statistics.median(es):.3f} (range {min(es):.3f}..{max(es):.3f}); "
        f"CMA-ES better on {sum(e > g for g, e in rows)} of {len(rows)} seeds"
    )


if __name__ == "__main__":
    main()
