"""The Python package's speed against the engine's, measured side by side.

    python python/bench.py [--rounds 5] [--jobs N]

R1 ``evaluate_vs_run``: episodes per second of ``Evaluator.evaluate`` on
1,000 random navigation genomes, divided by the episodes per second of a run
evaluating the same stage (``shaping.run`` with a population of 5,000
random individuals and one generation, timed from the stage's
``evolve_start`` event to its ``evolve_end``: the episodes, and the
checkpoint written after them), both on ``jobs`` threads.

R2 ``vec_env_vs_bench``: environment steps per second of
``shaping.gym.make_vec(..., num_envs=1024, jobs=1)`` with random actions
(drawn with numpy in the loop, as an agent would), divided by the
controller actions per second that ``shaping bench`` measures for that
stage (one thread).

R3 ``parallel_env_vs_bench``: robot-steps per second of a team of 100
robots of ``examples/aggregation.bat`` (its arena 4,900 mm square, 490 mm
times the square root of the robots) stepped by
``shaping.gym.make_parallel_vec(..., num_envs=1, jobs=1)`` with random
actions drawn with numpy (no Python per robot), divided by the
``robot_steps_per_sec`` that ``shaping bench`` measures for the same team
(``--set``, one thread).

Rounds alternate between the sides; the medians are compared. The last
line is one JSON object with the ratios (goals: R1 >= 0.9, R2 >= 0.5,
R3 >= 0.5) and ``bench_build``, the build of the ``shaping`` binary: the
package is always a release build, so with a debug binary (as
``python/ci.sh`` runs it, to see that the bench runs) R2 and R3 compare
it with a slow bench and are not figures.
The ``shaping`` binary is SHAPING_BIN, else target/release/shaping, else
``shaping`` on PATH; build it with ``cargo build --release``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import shaping
import shaping.gym

ROOT = Path(__file__).resolve().parents[1]
KHEPERA = ROOT / "examples" / "khepera.bat"
STAGE = "navigation"
# The run side's population: large enough that the generation's checkpoint,
# written (and synced) between the two events, is a small share of the time.
RUN_POPULATION = 5000


def binary() -> str:
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for c in (os.environ.get("SHAPING_BIN"), str(target / "release" / "shaping"), shutil.which("shaping")):
        if c and Path(c).is_file() and os.access(c, os.X_OK):
            return c
    raise SystemExit("bench.py: the `shaping` binary is missing: cargo build --release (or set SHAPING_BIN)")


def evaluate_rate(evaluator, genomes) -> float:
    t = time.perf_counter()
    evaluator.evaluate(genomes)
    return len(genomes) * evaluator.episodes / (time.perf_counter() - t)


def run_rate(population: int, jobs: int | None, episodes: int) -> float:
    marks = {}

    def clock(event):
        if event.get("stage") == STAGE and event["event"] in ("evolve_start", "evolve_end"):
            marks[event["event"]] = time.perf_counter()

    with tempfile.TemporaryDirectory() as out:
        shaping.run(
            KHEPERA,
            out=out,
            stage=STAGE,
            set={f"{STAGE}.evolve.population": population, f"{STAGE}.evolve.generations": 1},
            jobs=jobs,
            callback=clock,
            report=False,
        )
    return population * episodes / (marks["evolve_end"] - marks["evolve_start"])


def draw(rng, low, high, shape):
    """Random actions in the box ``[low, high]``, float32: numpy's
    ``random`` scaled (``uniform`` with array bounds took 18 us of a
    100-robot step, more than the step's half in Rust)."""
    return (rng.random(shape, dtype=np.float32) * (high - low) + low).astype(np.float32, copy=False)


def vec_env_rate(envs, steps: int, rng) -> float:
    low, high = envs.single_action_space.low, envs.single_action_space.high
    shape = (envs.num_envs, len(low))
    t = time.perf_counter()
    for _ in range(steps):
        envs.step(draw(rng, low, high, shape))
    return steps * envs.num_envs / (time.perf_counter() - t)


def bench_line(args: list[str]) -> dict:
    out = subprocess.run(args, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def bench_rate(cli: str) -> tuple[float, dict]:
    line = bench_line([cli, "bench", str(KHEPERA), "--stage", STAGE, "--runs", "3"])
    return float(line["controller_actions_per_sec"]), line


AGGREGATION = ROOT / "examples" / "aggregation.bat"
TEAM = 100
TEAM_ARENA = 4900


def team_env_rate(envs, steps: int, rng) -> float:
    low, high = envs.single_action_space.low, envs.single_action_space.high
    shape = (envs.num_envs, len(envs.agents), len(low))
    t = time.perf_counter()
    for _ in range(steps):
        envs.step(draw(rng, low, high, shape))
    return steps * envs.num_envs * len(envs.agents) / (time.perf_counter() - t)


def team_bench_rate(cli: str) -> float:
    sets = [f"aggregate.world.robots={TEAM}", f"aggregate.world.arena={TEAM_ARENA}x{TEAM_ARENA}"]
    args = [cli, "bench", str(AGGREGATION), "--stage", "aggregate", "--runs", "3"]
    for x in sets:
        args += ["--set", x]
    return float(bench_line(args)["robot_steps_per_sec"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--jobs", type=int, default=None, help="threads of R1 (default: one per core)")
    args = parser.parse_args()
    cli = binary()

    program = shaping.compile(KHEPERA)
    bits = program.genome_bits(STAGE)
    evaluator = program.evaluator(STAGE, seed=1, jobs=args.jobs)
    genomes = np.random.default_rng(0).integers(0, 2, size=(1000, bits), dtype=np.uint8)
    evaluate_rate(evaluator, genomes[:100])  # warm up the threads

    envs = shaping.gym.make_vec(KHEPERA, STAGE, num_envs=1024, jobs=1)
    envs.reset(seed=0)
    rng = np.random.default_rng(0)
    vec_env_rate(envs, 20, rng)

    # The same team as the bench's: the file with 100 robots in a 4,900 mm arena.
    team_dir = tempfile.TemporaryDirectory()
    team_file = Path(team_dir.name) / "aggregation-100.bat"
    text = AGGREGATION.read_text()
    text = text.replace("robots 10\n", f"robots {TEAM}\n").replace(
        "arena 600mm x 600mm", f"arena {TEAM_ARENA}mm x {TEAM_ARENA}mm"
    )
    team_file.write_text(text)
    teams = shaping.gym.make_parallel_vec(team_file, "aggregate", num_envs=1, jobs=1)
    assert len(teams.agents) == TEAM
    teams.reset(seed=0)
    team_env_rate(teams, 5, rng)

    rates = {"evaluate": [], "run": [], "vec_env": [], "bench": [], "team_env": [], "team_bench": []}
    last_bench = {}
    for r in range(args.rounds):
        rates["run"].append(run_rate(RUN_POPULATION, args.jobs, evaluator.episodes))
        rates["evaluate"].append(evaluate_rate(evaluator, genomes))
        rate, last_bench = bench_rate(cli)
        rates["bench"].append(rate)
        rates["vec_env"].append(vec_env_rate(envs, 300, rng))
        rates["team_bench"].append(team_bench_rate(cli))
        rates["team_env"].append(team_env_rate(teams, 300, rng))
        print(
            f"round {r + 1}: evaluate {rates['evaluate'][-1]:,.0f} episodes/s, run {rates['run'][-1]:,.0f}; "
            f"vec env {rates['vec_env'][-1]:,.0f} steps/s, bench {rates['bench'][-1]:,.0f} actions/s; "
            f"team env {rates['team_env'][-1]:,.0f} robot-steps/s, bench {rates['team_bench'][-1]:,.0f}",
            flush=True,
        )
    med = {k: statistics.median(v) for k, v in rates.items()}
    print(
        f"medians over {args.rounds} rounds: evaluate {med['evaluate']:,.0f} and run {med['run']:,.0f} "
        f"episodes/s ({evaluator.episodes} per individual, jobs {args.jobs or 'all cores'}); "
        f"make_vec(num_envs=1024, jobs=1) {med['vec_env']:,.0f} steps/s and shaping bench "
        f"{med['bench']:,.0f} controller actions/s (sim_moving_share {last_bench.get('sim_moving_share')}); "
        f"make_parallel_vec({TEAM} robots, num_envs=1, jobs=1) {med['team_env']:,.0f} robot-steps/s and "
        f"shaping bench {med['team_bench']:,.0f} robot-steps/s"
    )
    team_dir.cleanup()
    build = last_bench.get("build", "unknown")
    if build != "release":
        print(f"the `shaping` binary ({cli}) is a {build} build: vec_env_vs_bench and parallel_env_vs_bench are not figures")
    print(
        json.dumps(
            {
                "evaluate_vs_run": round(med["evaluate"] / med["run"], 3),
                "vec_env_vs_bench": round(med["vec_env"] / med["bench"], 3),
                "parallel_env_vs_bench": round(med["team_env"] / med["team_bench"], 3),
                "bench_build": build,
            }
        )
    )


if __name__ == "__main__":
    main()
