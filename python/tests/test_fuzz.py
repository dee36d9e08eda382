"""No call of the binding aborts the interpreter (issue 47): its entry points
fed random and malformed arguments for a bounded time, in a child process.

A child that dies of a signal (SIGABRT from a failed allocation, SIGSEGV, a
Rust panic across the boundary) or hangs fails the test and prints the call
it was making; every call may raise, but only an exception. The time is
``SHAPING_FUZZ_SECS`` seconds (10 by default); the calls come from a seeded
generator, so a failure is repeated by the same seed (``SHAPING_FUZZ_SEED``).
"""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

CHILD = textwrap.dedent(
    r"""
    import math, os, random, sys, tempfile, time, warnings
    import numpy as np
    import shaping
    from shaping import genes

    warnings.simplefilter("ignore")
    root, secs, seed = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
    rng = random.Random(seed)
    khepera = os.path.join(root, "examples", "khepera.bat")
    tiny = os.path.join(root, "tests", "cli", "tiny.bat")
    program = shaping.compile(khepera)
    ev = program.evaluator("navigation", seed=1, jobs=1)
    aggregation = os.path.join(root, "examples", "aggregation.bat")
    team = shaping._shaping.TeamStepper(shaping.compile(aggregation), "aggregate")
    scratch = tempfile.mkdtemp()

    INTS = [0, 1, -1, 2, 7, 2**31, 2**32, 2**63, 2**64, -(2**63), 10**30, 1.5, float("nan"), float("inf"),
            True, None, "3", [], (1,), object()]
    STRINGS = ["navigation", "collect", "", "nope", "\x00", "é" * 3, "a" * 10_000, None, 3, b"navigation"]
    PATHS = [khepera, tiny, "", "/", "/dev/null", "/nonexistent/x.bat", root, "\x00", 5, None,
             os.path.join(root, "Cargo.toml")]

    def genome_arrays():
        bits = ev.bits
        shapes = [(0, bits), (1, bits), (3, bits), (bits,), (2, bits - 1), (2, bits + 1), (1, 0), (0,), ()]
        shape = rng.choice(shapes)
        kind = rng.randrange(6)
        if kind == 0:
            return np.zeros(shape, np.uint8)
        if kind == 1:
            return np.full(shape, rng.choice([2, 255]), np.uint8)
        if kind == 2:
            return np.zeros(shape, rng.choice([np.float64, np.int64, np.bool_, np.int8, np.object_]))
        if kind == 3:
            return np.broadcast_to(np.zeros(bits, np.uint8), (rng.choice([2**20, 2**40, 2**62]), bits))
        if kind == 4:
            return np.zeros((2, bits), np.uint8)[:, ::2]
        return rng.choice([None, "0101", [[0, 1]], 3.0, object()])

    def reals():
        n = len(genes.evolvable(program, "navigation"))
        choice = rng.randrange(5)
        if choice == 0:
            return np.zeros((2, n))
        if choice == 1:
            return np.full((1, n), rng.choice([np.nan, np.inf, -np.inf, 1e300, -1e300]))
        if choice == 2:
            return np.zeros((2, n + rng.choice([-1, 1])))
        if choice == 3:
            return np.zeros(rng.choice([(0, n), (n,), ()]))
        return rng.choice([None, "x", [[1.0]], object()])

    calls = [
        lambda: shaping.check(rng.choice(PATHS)),
        lambda: shaping.compile(rng.choice(PATHS)),
        lambda: program.genome_bits(rng.choice(STRINGS)),
        lambda: program.layout(rng.choice(STRINGS)),
        lambda: program.roles(rng.choice(STRINGS)),
        lambda: program.kind(rng.choice(STRINGS)),
        lambda: program.evaluator(rng.choice(STRINGS), seed=rng.choice(INTS), jobs=rng.choice(INTS)),
        lambda: ev.evaluate(genome_arrays()),
        lambda: ev.evaluate(np.zeros((2, ev.bits), np.uint8), generation=rng.choice(INTS)),
        lambda: ev.evaluate(np.zeros((2, ev.bits), np.uint8),
                            individuals=rng.choice([np.array([0, 1]), np.array([-1, 0]), np.array([2**40, 0]),
                                                    np.array([0.5, 1.0]), np.array([0]), "01", None])),
        lambda: ev.evaluate(np.zeros((1, ev.bits), np.uint8),
                            measures=rng.choice([None, {}, {"x": "robot.x"}, {"x": rng.choice(STRINGS)},
                                                 {rng.choice(STRINGS): "1"}, {"d": "(" * 200 + "1"},
                                                 {"m": "max(" + "ir," * 3000 + "ir)"}, {"t": "team.nope"},
                                                 {"b": "1e39"}, ["robot.x"], "robot.x"])),
        lambda: genes.encode(program, rng.choice(STRINGS), reals()),
        lambda: genes.encode(program, "navigation", reals(), base=rng.choice([None, np.zeros(3, np.uint8)])),
        lambda: genes.decode(program, rng.choice(STRINGS), genome_arrays()),
        lambda: shaping.Run(rng.choice(PATHS)),
        lambda: shaping.run(rng.choice([tiny, "/nonexistent.bat"]), out=os.path.join(scratch, str(rng.randrange(3))),
                            seed=rng.choice(INTS), jobs=rng.choice(INTS), stage=rng.choice(STRINGS),
                            set=rng.choice([None, {}, {"first.evolve.generations": 1}, {"nope": 1},
                                            {"first.evolve.generations": -1}, {"*.world.robots": 10**6}]),
                            report=False),
        lambda: shaping.experiment(tiny, seeds=rng.choice(INTS), first_seed=rng.choice(INTS),
                                   out=os.path.join(scratch, "e"), set={"first.evolve.generations": 1},
                                   report=False),
    ]
    try:
        import shaping.gym as sgym
        calls += [
            lambda: sgym.make(rng.choice([khepera, tiny, "/nonexistent.bat"]), rng.choice(STRINGS)),
            lambda: sgym.make_vec(khepera, "navigation", num_envs=rng.choice(INTS + [10**9])),
            lambda: sgym.make_parallel_vec(rng.choice([khepera, aggregation]), rng.choice(STRINGS + ["aggregate"]),
                                           num_envs=rng.choice(INTS + [10**9])),
            lambda: shaping._shaping.TeamStepper(program, rng.choice(STRINGS)),
            lambda: team.step(np.full((10, 2), rng.choice([0.0, 2.0, np.nan]), np.float32)),
            lambda: team.reset(rng.choice([0, 1, 2**63])),
        ]
    except ImportError:
        pass

    end = time.monotonic() + secs
    n = 0
    while time.monotonic() < end:
        i = rng.randrange(len(calls))
        sys.stderr.write(f"call {n}: entry {i}\n")
        sys.stderr.flush()
        try:
            calls[i]()
        except Exception:
            pass
        n += 1
    print(f"{n} calls")
    """
)


def test_no_call_of_the_binding_aborts_the_interpreter(tmp_path):
    secs = float(os.environ.get("SHAPING_FUZZ_SECS", "10"))
    seed = int(os.environ.get("SHAPING_FUZZ_SEED", "1"))
    script = tmp_path / "fuzz.py"
    script.write_text(CHILD)
    try:
        child = subprocess.run(
            [sys.executable, str(script), str(ROOT), str(secs), str(seed)],
            capture_output=True,
            text=True,
            timeout=secs + 120,
            cwd=tmp_path,
        )
    except subprocess.TimeoutExpired as e:
        last = (e.stderr or b"").decode(errors="replace").strip().splitlines()[-1:]
        raise AssertionError(f"the binding hung: {last}") from None
    last = child.stderr.strip().splitlines()[-3:]
    assert child.returncode == 0, f"the child died ({child.returncode}) at {last}"
    calls = int(child.stdout.split()[0])
    assert calls > 20, child.stdout
