"""Tests of the `shaping` package against the files of the repository and
the `shaping` command line (SHAPING_BIN, else target/{debug,release}/shaping,
else `shaping` on PATH; skipped without it, failing under CI=true)."""

import json
import os
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

import shaping

ROOT = Path(__file__).resolve().parents[2]
KHEPERA = ROOT / "examples" / "khepera.bat"
TINY = ROOT / "tests" / "cli" / "tiny.bat"
BAD = "robot khepera {\n  sensor ir[8] proximity\n  wheels\n}\n"


def cli():
    """The `shaping` binary, or a skip (a failure under CI=true)."""
    candidates = [os.environ.get("SHAPING_BIN")]
    target = os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))
    candidates += [str(Path(target) / p / "shaping") for p in ("debug", "release")]
    candidates.append(shutil.which("shaping"))
    for c in candidates:
        if c and Path(c).is_file() and os.access(c, os.X_OK):
            return c
    if os.environ.get("CI") == "true":
        pytest.fail("the `shaping` binary is missing (set SHAPING_BIN or build it: cargo build --bin shaping)")
    pytest.skip("the `shaping` binary is missing (cargo build --bin shaping)")


def shaping_cli(*args):
    return subprocess.run([cli(), *map(str, args)], capture_output=True, text=True, cwd=ROOT)


def random_genomes(n, bits, seed=1, dtype=np.uint8):
    return np.random.default_rng(seed).integers(0, 2, size=(n, bits)).astype(dtype)


# ------------------------------------------------------------------ compile, check


def test_compile_khepera_stages_and_bits_match_the_cli():
    program = shaping.compile(KHEPERA)
    assert program.stages == ["avoidance", "navigation", "collect", "bigger"]
    assert [program.kind(s) for s in program.stages] == ["train", "evolve", "evolve", "test"]
    checked = shaping_cli("check", "--error-format", "json", KHEPERA)
    assert checked.returncode == 0, checked.stderr
    cli_stages = json.loads(checked.stdout)["stages"]
    assert [(s["name"], s["bits"]) for s in cli_stages] == [
        (s, program.genome_bits(s)) for s in program.stages
    ]
    for stage in program.stages:
        out = shaping_cli("layout", KHEPERA, "--stage", stage, "--format", "json")
        assert out.returncode == 0, out.stderr
        layout = json.loads(out.stdout)
        assert program.layout(stage) == layout["genes"]
        assert layout["bits"] == program.genome_bits(stage)
        text = shaping_cli("layout", KHEPERA, "--stage", stage).stdout
        assert program.layout_text(stage).strip() == text.strip()


def test_layout_bits_add_up():
    program = shaping.compile(str(KHEPERA))
    genes = program.layout("collect")
    assert sum(g["bits"] for g in genes) == program.genome_bits("collect")
    assert any(g["frozen"] for g in genes) and not all(g["frozen"] for g in genes)


def test_check_good_and_bad_files(tmp_path):
    assert shaping.check(KHEPERA) == []
    bad = tmp_path / "bad.bat"
    bad.write_text(BAD)
    diags = shaping.check(bad)
    assert len(diags) == 1
    d = diags[0]
    assert d.severity == "error"
    assert (d.line, d.column) == (3, 3)
    assert "wheels" in d.message
    # The CLI's JSON says the same (line and column 1-based).
    out = shaping_cli("check", "--error-format", "json", bad)
    assert out.returncode == 1
    cli_diag = json.loads(out.stdout)
    related = cli_diag.get("related") or [cli_diag]
    assert (related[0]["line"], related[0]["column"]) == (3, 3)
    assert related[0]["message"] == d.message


def test_compile_errors_raise_with_the_cli_message(tmp_path):
    bad = tmp_path / "bad.bat"
    bad.write_text(BAD)
    with pytest.raises(shaping.ShapingError) as e:
        shaping.compile(bad)
    assert e.value.kind == "diagnostics"
    assert [d.line for d in e.value.diagnostics] == [3]
    out = shaping_cli("check", "--error-format", "plain", bad)
    assert out.returncode == 1
    assert str(e.value).strip() == out.stderr.strip()
    assert issubclass(shaping.ShapingError, Exception)


def test_a_missing_file_raises_with_the_cli_message(tmp_path):
    missing = tmp_path / "nope.bat"
    with pytest.raises(shaping.ShapingError) as e:
        shaping.compile(missing)
    assert e.value.kind == "io"
    out = shaping_cli("check", missing)
    assert str(e.value).strip() == out.stderr.strip()
    with pytest.raises(shaping.ShapingError):
        shaping.check(missing)


def test_a_stage_that_does_not_exist():
    program = shaping.compile(KHEPERA)
    with pytest.raises(ValueError, match="no stage `nope`"):
        program.genome_bits("nope")
    with pytest.raises(ValueError, match="no stage `nope`"):
        program.evaluator("nope")
    with pytest.raises(ValueError, match="not evolved"):
        program.evaluator("avoidance")


# ------------------------------------------------------------------ evaluate


@pytest.fixture(scope="module")
def navigation():
    program = shaping.compile(KHEPERA)
    with pytest.warns(UserWarning, match="trained afresh"):
        ev = program.evaluator("navigation", seed=3)
    return program, ev


def test_evaluate_is_deterministic_and_complete(navigation):
    program, ev = navigation
    assert ev.bits == program.genome_bits("navigation") == 192
    genomes = random_genomes(8, ev.bits)
    a = ev.evaluate(genomes)
    b = ev.evaluate(genomes.copy())
    keys = {"fitness", "recharges", "grips", "releases_outside", "collisions", "x", "y", "heading",
            "path_length", "squares_visited", "placement_failures"}
    assert keys <= set(a)
    for k in keys:
        assert a[k].shape == (8,), k
        np.testing.assert_array_equal(a[k], b[k])
    assert a["fitness"].dtype == np.float32
    assert np.all(np.isfinite(a["fitness"]))
    # Inside the arena (400 x 600 mm), a path and at least the start square.
    assert np.all((a["x"] >= 0) & (a["x"] <= 400) & (a["y"] >= 0) & (a["y"] <= 600))
    assert np.all(np.abs(a["heading"]) <= np.pi + 1e-6)
    assert np.all(a["squares_visited"] >= 1) and np.all(a["path_length"] >= 0)
    # Each individual is evaluated on its own episodes: a row's result does
    # not depend on the other rows, only on its index.
    one = ev.evaluate(genomes[:1])
    assert one["fitness"][0] == a["fitness"][0]
    # bool and int arrays give the same results.
    np.testing.assert_array_equal(ev.evaluate(genomes.astype(bool))["fitness"], a["fitness"])
    np.testing.assert_array_equal(ev.evaluate(genomes.astype(np.int64))["fitness"], a["fitness"])
    # Another seed, other episodes.
    other = navigation[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ev2 = other.evaluator("navigation", seed=4)
    assert not np.array_equal(ev2.evaluate(genomes)["fitness"], a["fitness"])


def test_evaluate_a_team():
    # examples/aggregation.bat: 10 clones of each genome in one world, the
    # fitness 1 - team.spread / 400 (the robots' mean distance to their
    # centre, mm), as `shaping run` evaluates it.
    program = shaping.compile(ROOT / "examples" / "aggregation.bat")
    ev = program.evaluator("aggregate", seed=5, jobs=2)
    genomes = random_genomes(6, ev.bits, seed=2)
    a = ev.evaluate(genomes)
    np.testing.assert_array_equal(a["fitness"], ev.evaluate(genomes)["fitness"])
    # A spread is at most the arena's half diagonal (600 x 600 mm), and
    # positive: ten bodies cannot all stand at one point.
    assert np.all((a["fitness"] > 1 - 425 / 400) & (a["fitness"] < 1)), a["fitness"]
    # The genomes behave differently, so the teams end differently.
    assert len(set(a["fitness"].tolist())) > 1
    # Robot 0's descriptors: inside the arena.
    assert np.all((a["x"] >= 0) & (a["x"] <= 600) & (a["y"] >= 0) & (a["y"] <= 600))


def test_evaluate_a_team_with_roles():
    # examples/aggregation-roles.bat: two roles of 5 robots, each with its
    # own network: the genome is both roles' genes (twice aggregation.bat's),
    # and each role's genes change the team's life.
    clones = shaping.compile(ROOT / "examples" / "aggregation.bat").evaluator("aggregate", seed=5)
    ev = shaping.compile(ROOT / "examples" / "aggregation-roles.bat").evaluator("aggregate", seed=5, jobs=2)
    assert ev.bits == 2 * clones.bits
    g = random_genomes(4, ev.bits, seed=3)
    base = ev.evaluate(g)["fitness"]
    np.testing.assert_array_equal(base, ev.evaluate(g)["fitness"])
    assert np.all((base > 1 - 425 / 400) & (base < 1)), base
    program = shaping.compile(ROOT / "examples" / "aggregation-roles.bat")
    roles = program.roles("aggregate")
    assert [(r["name"], r["robots"], r["modules"]) for r in roles] == [("first", 5, [0]), ("second", 5, [1])]
    assert shaping.compile(ROOT / "examples" / "aggregation.bat").roles("aggregate") == []
    # Each role's genes are one half of the genome, the first role's first.
    genes = program.layout("aggregate")
    half = ev.bits // 2
    assert all((g["offset"] < half) == (g["module"] == 0) for g in genes)
    for part in (slice(0, half), slice(half, ev.bits)):
        changed = g.copy()
        changed[:, part] = 1 - changed[:, part]
        assert np.all(ev.evaluate(changed)["fitness"] != base), part


def test_evaluate_rejects_bad_arrays(navigation):
    _, ev = navigation
    g = random_genomes(4, ev.bits)
    with pytest.raises(ValueError, match=r"shape \(n, 192\)"):
        ev.evaluate(g[:, :-1])
    with pytest.raises(ValueError, match=r"shape \(n, 192\)"):
        ev.evaluate(g[0])
    with pytest.raises(ValueError, match="dtype float64"):
        ev.evaluate(g.astype(float))
    with pytest.raises(ValueError, match="0 and 1 only: row 1, column 5 holds 2"):
        bad = g.copy()
        bad[1, 5] = 2
        ev.evaluate(bad)
    with pytest.raises(ValueError, match="0 and 1 only"):
        ev.evaluate(-g.astype(np.int8) - 1)
    with pytest.raises(ValueError):
        ev.evaluate("not an array")
    assert ev.evaluate(np.zeros((0, ev.bits), np.uint8))["fitness"].shape == (0,)


def test_evaluate_equals_the_fitness_of_a_cli_run(tmp_path):
    """The reference: a run of the CLI (`shaping run`), its first generation
    evaluated in Rust; `evaluate` with the run's seed and weights gives the
    same fitness to the same individuals."""
    out = tmp_path / "run"
    res = shaping_cli(
        "run", KHEPERA, "--stage", "navigation", "--seed", 5, "--out", out, "--no-report",
        "--set", "navigation.evolve.generations=1", "--set", "navigation.evolve.population=8",
    )
    assert res.returncode == 0, res.stderr
    run = shaping.Run(out)
    assert run.stages == ["avoidance", "navigation"]
    genomes, fitness = run.population("navigation")
    assert genomes.shape == (8, 192) and fitness.dtype == np.float32
    program = shaping.compile(KHEPERA)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the run's weights: no warning
        ev = program.evaluator("navigation", run=run, seed=5)
    np.testing.assert_array_equal(ev.evaluate(genomes)["fitness"], fitness)
    # A directory works as well as a Run.
    ev = program.evaluator("navigation", run=str(out), seed=5)
    np.testing.assert_array_equal(ev.evaluate(genomes)["fitness"], fitness)
    # A later generation's episodes: those the run gave that generation.
    later = tmp_path / "later"
    res = shaping_cli(
        "run", KHEPERA, "--stage", "navigation", "--seed", 5, "--out", later, "--no-report",
        "--set", "navigation.evolve.generations=3", "--set", "navigation.evolve.population=8",
    )
    assert res.returncode == 0, res.stderr
    genomes, fitness = shaping.Run(later).population("navigation")
    np.testing.assert_array_equal(ev.evaluate(genomes, generation=2)["fitness"], fitness)
    assert not np.array_equal(ev.evaluate(genomes, generation=1)["fitness"], fitness)


# ------------------------------------------------------------------ run


def test_run_tiny(tmp_path):
    events = []
    run = shaping.run(TINY, out=tmp_path / "tiny", callback=events.append, jobs=2)
    assert run.stages == ["first", "second"]
    assert run.seed == 3
    assert run.report is not None and Path(run.report).is_file()
    program = shaping.compile(TINY)
    for stage, generations in [("first", 6), ("second", 4)]:
        g = run.generations(stage)
        assert set(g) >= {"stage", "generation", "best", "mean", "worst", "best_index"}
        rows = g["stage"] == stage
        assert rows.sum() == generations
        assert np.all(g["best"][rows] >= g["mean"][rows])
        best = run.best_genome(stage)
        assert best.shape == (program.genome_bits(stage),)
        assert set(np.unique(best)) <= {0, 1}
    kinds = [e["event"] for e in events]
    assert kinds.count("generation") == 10
    assert kinds.count("evolved") == 2
    # Run again: everything is resumed from the directory, same results.
    again = shaping.run(TINY, out=tmp_path / "tiny", report=False)
    np.testing.assert_array_equal(again.best_genome("second"), run.best_genome("second"))
    # The CLI writes the same best genome.
    cli_out = tmp_path / "cli"
    res = shaping_cli("run", TINY, "--out", cli_out, "--no-report")
    assert res.returncode == 0, res.stderr
    np.testing.assert_array_equal(shaping.Run(cli_out).best_genome("second"), run.best_genome("second"))


def test_run_set_and_bad_arguments(tmp_path):
    run = shaping.run(TINY, out=tmp_path / "a", stage="first", set={"first.evolve.generations": 2}, report=False)
    assert run.stages == ["first"]
    assert len(run.generations("first")["best"]) == 2
    with pytest.raises(ValueError, match="no stage `nope`"):
        shaping.run(TINY, out=tmp_path / "b", stage="nope")
    with pytest.raises(shaping.ShapingError) as e:
        shaping.run(TINY, out=tmp_path / "c", set={"first.evolve.nothing": 2})
    res = shaping_cli("run", TINY, "--out", tmp_path / "d", "--set", "first.evolve.nothing=2")
    assert res.returncode != 0
    assert str(e.value).strip() == res.stderr.strip()
    with pytest.raises(ValueError, match="one value"):
        shaping.run(TINY, out=tmp_path / "e", set={"first.evolve.generations": [1, 2]})
    with pytest.raises(ValueError, match="STAGE.SECTION.FIELD"):
        shaping.run(TINY, out=tmp_path / "f", set={"generations": 2})
    with pytest.raises(ValueError, match="jobs"):
        shaping.run(TINY, out=tmp_path / "g", jobs=0)
    with pytest.raises(ValueError, match="no stage"):
        run.best_genome("second")


def test_a_callback_exception_stops_the_run_resumably(tmp_path):
    out = tmp_path / "stop"

    def stop(event):
        if event["event"] == "generation" and event["stats"]["stage_generation"] == 1:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        shaping.run(TINY, out=out, callback=stop, report=False)
    # Stopped after generation 1 of `first`, resumable.
    done = shaping.Run(out).generations("first")
    assert len(done["best"]) == 2
    run = shaping.run(TINY, out=out, report=False)
    assert len(run.generations("first")["best"]) == 6


def test_ctrl_c_stops_the_run_resumably(tmp_path):
    """SIGINT during a run (sent here from the callback): KeyboardInterrupt,
    and the stage is saved after its generation, resumable."""
    import signal

    out = tmp_path / "int"
    seen = []

    def interrupt(event):
        seen.append(event["event"])
        if event["event"] == "generation" and seen.count("generation") == 1:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        shaping.run(TINY, out=out, callback=interrupt, report=False)
    assert 1 <= len(shaping.Run(out).generations("first")["best"]) < 6
    run = shaping.run(TINY, out=out, report=False)
    assert run.stages == ["first", "second"]


def test_evaluate_does_not_depend_on_threads(navigation):
    program, ev = navigation
    genomes = random_genomes(64, ev.bits, seed=9)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one = program.evaluator("navigation", seed=3, jobs=1)
    a, b = ev.evaluate(genomes), one.evaluate(genomes)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])
    with pytest.raises(ValueError, match="jobs"):
        program.evaluator("navigation", jobs=0)


def test_evaluate_releases_the_gil(navigation):
    """While one thread evaluates, another runs Python: no long pause."""
    import threading
    import time

    program, _ = navigation
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ev = program.evaluator("navigation", seed=3, jobs=1)
    genomes = random_genomes(10000, ev.bits, seed=2)
    span = {}

    def work():
        span["start"] = time.perf_counter()
        ev.evaluate(genomes)
        span["end"] = time.perf_counter()

    t = threading.Thread(target=work)
    ticks = []
    t.start()
    while t.is_alive():
        ticks.append(time.perf_counter())
    t.join()
    duration = span["end"] - span["start"]
    inside = [x for x in ticks if span["start"] <= x <= span["end"]]
    gaps = np.diff([span["start"], *inside, span["end"]])
    assert duration > 0.1, "too quick to tell"
    assert gaps.max() < duration / 2, (gaps.max(), duration)


def test_several_evaluations_equal_the_run_s_fitness(tmp_path):
    """A stage of 3 evaluations per individual: the mean fitness of the
    run's first generation, without warnings (no training stage)."""
    source = TINY.read_text().replace("seed 3", "seed 3  evaluations 3", 1)
    assert "evaluations 3" in source
    path = tmp_path / "three.bat"
    path.write_text(source)
    run = shaping.run(path, out=tmp_path / "run", stage="first", set={"first.evolve.generations": 1}, report=False)
    genomes, fitness = run.population("first")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ev = shaping.compile(path).evaluator("first", seed=3)
    assert ev.episodes == 3
    result = ev.evaluate(genomes)
    np.testing.assert_array_equal(result["fitness"], fitness)
    g = run.generations("first")
    best = int(g["best_index"][0])
    assert result["recharges"][best] == g["best_recharges"][0]


def test_a_later_stage_takes_its_frozen_genes_from_the_genome(navigation):
    program, _ = navigation
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ev = program.evaluator("collect", seed=1)
    assert ev.bits == program.genome_bits("collect") == 344
    genomes = random_genomes(4, ev.bits, seed=4)
    changed = genomes.copy()
    changed[:, :192] = 1 - changed[:, :192]  # navigation's (frozen) genes
    assert not np.array_equal(ev.evaluate(genomes)["fitness"], ev.evaluate(changed)["fitness"])


def test_ctrl_c_without_a_callback(tmp_path):
    """SIGINT from another thread while the run is in Rust (no Python code
    runs to see it): the engine's flag stops it after the generation under
    way; KeyboardInterrupt with the CLI's message; resumable."""
    import signal
    import threading

    out = tmp_path / "long"
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt, match="interrupted: stage `navigation` stopped after generation"):
            shaping.run(KHEPERA, out=out, stage="navigation", set={"navigation.evolve.generations": 100000},
                        report=False, jobs=2)
    finally:
        timer.cancel()
    done = len(shaping.Run(out).generations("navigation")["best"])
    assert 1 <= done < 100000
    # The same call resumes where it stopped.
    events = []
    with pytest.raises(RuntimeError):
        def first_generation(event):
            events.append(event)
            if event["event"] == "generation":
                raise RuntimeError("seen")
        shaping.run(KHEPERA, out=out, stage="navigation", set={"navigation.evolve.generations": 100000},
                    report=False, callback=first_generation)
    assert any(e["event"] == "resumed" and e["generation"] == done for e in events)


# ------------------------------------------------------------------ experiment


def test_experiment_writes_what_the_cli_writes(tmp_path):
    exp = shaping.experiment(TINY, seeds=2, first_seed=4, out=tmp_path / "py", jobs=2, report=False)
    assert exp.seeds == [4, 5]
    assert [r.seed for r in exp.runs] == [4, 5]
    assert all(r.stages == ["first", "second"] for r in exp.runs)
    assert "seed" in exp.summary_text or "median" in exp.summary_text
    summary = exp.summary
    assert summary["seeds"] == [4, 5]
    res = shaping_cli("experiment", TINY, "--seeds", 2, "--first-seed", 4, "--out", tmp_path / "cli", "--no-report")
    assert res.returncode == 0, res.stderr
    for name in ["summary.json", "summary.md"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    assert res.stdout == exp.summary_text
    for seed in (4, 5):
        np.testing.assert_array_equal(
            exp.runs[seed - 4].best_genome("second"),
            shaping.Run(tmp_path / "cli" / f"seed-{seed}").best_genome("second"),
        )


def test_experiment_sweeps_a_list_of_values(tmp_path):
    exp = shaping.experiment(
        TINY,
        seeds=1,
        out=tmp_path / "sweep",
        stage="first",
        set={"first.evolve.generations": [1, 2]},
        report=False,
    )
    assert len(exp.runs) == 2
    assert [len(r.generations("first")["best"]) for r in exp.runs] == [1, 2]
    points = exp.summary["points"]
    assert [p["settings"] for p in points] == [
        {"first.evolve.generations": "1"},
        {"first.evolve.generations": "2"},
    ]
    with pytest.raises(shaping.ShapingError, match="seeds"):
        shaping.experiment(TINY, seeds=0, out=tmp_path / "none")
    with pytest.raises(shaping.ShapingError, match="no stage `nope`"):
        shaping.experiment(TINY, seeds=1, out=tmp_path / "crit", criterion={"nope": 0.5})
    assert not (tmp_path / "none").exists()


def test_genes_encode_to_the_nearest_level_and_decode_back():
    from shaping import genes

    program = shaping.compile(KHEPERA)
    lo, hi = genes.bounds(program, "navigation")
    assert len(lo) == 48 and np.all(lo == -4) and np.all(hi == 4)
    levels = lo + (hi - lo) * (np.arange(48) % 16) / 15
    g = genes.encode(program, "navigation", levels + 0.1)
    assert g.shape == (1, program.genome_bits("navigation")) and g.dtype == np.uint8
    np.testing.assert_allclose(genes.decode(program, "navigation", g)[0], levels)
    # Gene 5 is level 5: bits 0101, most significant first.
    assert list(g[0, 20:24]) == [0, 1, 0, 1]
    # The frozen genes of a later stage are the base genome's.
    base = random_genomes(1, program.genome_bits("collect"))[0]
    frozen = [x for x in program.layout("collect") if x["frozen"]]
    values = np.zeros((2, len(genes.evolvable(program, "collect"))))
    out = genes.encode(program, "collect", values, base=base)
    for x in frozen:
        np.testing.assert_array_equal(out[:, x["offset"] : x["offset"] + x["bits"]], [base[x["offset"] : x["offset"] + x["bits"]]] * 2)
    with pytest.raises(ValueError, match="48 columns"):
        genes.encode(program, "navigation", np.zeros((1, 3)))
