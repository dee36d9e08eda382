"""MAP-Elites (pyribs) over navigation's genes through `Evaluator.evaluate`,
with two behaviour descriptors: the 50 mm squares of the arena visited and
the recharges; against the population of shaping's GA.

    pip install ribs
    python python/examples/map_elites_navigation.py [--seed 1] [--evaluations 20000]

The archive is a grid of 24 x 4 cells: squares visited 0..96 (the arena of
400 x 600 mm has 8 x 12 squares) in steps of 4, and 0, 1, 2 or 3 or more
recharges. One Gaussian emitter (sigma 0.5 of a gene range of 8, batches
of 100: MAP-Elites) searches the 48 genes as real values, rounded to each
gene's 16 levels, each batch on fresh episodes. The GA is `shaping run
--stage navigation` (100 individuals, 40 generations: 4,000
evaluations); its last population is evaluated on the episodes the run
gave it and placed in a grid of the same cells. Prints the cells filled and
the best fitness of the archive after 4,000 evaluations (the GA's budget)
and at the end, and of the GA's last population.
"""

from __future__ import annotations

import argparse
import tempfile
import warnings
from pathlib import Path

import numpy as np
from ribs.archives import GridArchive
from ribs.emitters import GaussianEmitter
from ribs.schedulers import Scheduler

import shaping
from shaping import genes

KHEPERA = Path(__file__).resolve().parents[2] / "examples" / "khepera.bat"
STAGE = "navigation"
GA_BUDGET = 4000
BATCH = 100


def grid(seed: int, dims: int) -> GridArchive:
    return GridArchive(solution_dim=dims, dims=[24, 4], ranges=[(0, 96), (-0.5, 3.5)], seed=seed)


def measures(result) -> np.ndarray:
    return np.stack([result["squares_visited"], np.minimum(result["recharges"], 3)], axis=1)


def summary(archive: GridArchive) -> str:
    s = archive.stats
    return f"{s.num_elites} of {archive.cells} cells filled, best fitness {s.obj_max:.3f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--evaluations", type=int, default=20000)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    program = shaping.compile(KHEPERA)
    lo, hi = genes.bounds(program, STAGE)
    with tempfile.TemporaryDirectory() as tmp:
        run = shaping.run(KHEPERA, out=Path(tmp) / "ga", seed=args.seed, stage=STAGE, report=False)
        ev = program.evaluator(STAGE, run=run, seed=args.seed)

        # The GA's last population, on the episodes the run evaluated it on.
        population, fitness = run.population(STAGE)
        last = int(run.generations(STAGE)["stage_generation"][-1])
        result = ev.evaluate(population, generation=last)
        assert np.array_equal(result["fitness"], fitness), "evaluate must reproduce the run's fitness"
        ga = grid(args.seed, len(lo))
        ga.add(genes.decode(program, STAGE, population), result["fitness"], measures(result))
        print(f"GA (its last population of {len(population)}, after {GA_BUDGET} evaluations): {summary(ga)}")

        archive = grid(args.seed, len(lo))
        emitter = GaussianEmitter(
            archive, sigma=0.5, x0=np.zeros(len(lo)), bounds=list(zip(lo, hi)), batch_size=BATCH, seed=args.seed
        )
        scheduler = Scheduler(archive, [emitter])
        used, generation = 0, 0
        while used < args.evaluations:
            xs = scheduler.ask()
            result = ev.evaluate(genes.encode(program, STAGE, xs), generation=generation)
            scheduler.tell(result["fitness"], measures(result))
            used += len(xs)
            generation += 1
            if used == GA_BUDGET or used >= args.evaluations:
                print(f"MAP-Elites after {used} evaluations: {summary(archive)}", flush=True)


if __name__ == "__main__":
    main()
