"""Tests of the `shaping` package against the files of the repository and
the `shaping` command line (SHAPING_BIN, else target/{debug,release}/shaping,
else `shaping` on PATH; skipped without it, failing under CI=true)."""

import errno
import json
import os
import re
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
    with pytest.raises(shaping.CompileError) as e:
        shaping.compile(bad)
    assert e.value.kind == "diagnostics"
    assert isinstance(e.value, shaping.ShapingError)
    assert [d.line for d in e.value.diagnostics] == [3]
    out = shaping_cli("check", "--error-format", "plain", bad)
    assert out.returncode == 1
    assert str(e.value).strip() == out.stderr.strip()
    assert issubclass(shaping.ShapingError, Exception)


def test_a_missing_file_raises_with_the_cli_message(tmp_path):
    missing = tmp_path / "nope.bat"
    with pytest.raises(FileNotFoundError) as e:
        shaping.compile(missing)
    assert e.value.kind == "not_found"
    assert isinstance(e.value, shaping.NotFoundError) and isinstance(e.value, shaping.ShapingError)
    # The file as data, as a FileNotFoundError names it.
    assert e.value.filename == e.value.path == str(missing)
    assert e.value.errno == errno.ENOENT and e.value.operation == "read"
    assert e.value.setting is None and e.value.problem is None
    out = shaping_cli("check", missing)
    assert str(e.value).strip() == out.stderr.strip()
    with pytest.raises(shaping.ShapingError):
        shaping.check(missing)


def test_a_damaged_checkpoint_raises_corrupt_error_naming_the_file_and_the_problem(tmp_path):
    out = tmp_path / "r"
    args = dict(out=out, stage="first", set={"first.evolve.generations": 1}, report=False)
    shaping.run(TINY, **args)
    path = out / "first" / "checkpoint.json"
    text = path.read_text()
    # One bit of the population's first genome, flipped.
    at = text.index('"bits": [') + len('"bits": [')
    digit = min(i for i in (text.find("0", at), text.find("1", at)) if i >= 0)
    path.write_text(text[:digit] + ("1" if text[digit] == "0" else "0") + text[digit + 1 :])
    with pytest.raises(shaping.CorruptError) as e:
        shaping.run(TINY, **args)
    assert e.value.kind == "corrupt"
    assert (e.value.path, e.value.problem) == (str(path), "its checksum does not match its contents")
    assert (e.value.setting, e.value.operation) == (None, None)


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
    assert all((g["offset"] < half) == (g["team_role"] == "first") for g in genes)
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
    # An unknown setting or a bad value: ValueError with the CLI's message.
    for key, value in [("first.evolve.nothing", 2), ("first.evolve.mutation", "lots"), ("nope.evolve.mutation", 0.1)]:
        with pytest.raises(ValueError) as e:
            shaping.run(TINY, out=tmp_path / "c", set={key: value})
        res = shaping_cli("run", TINY, "--out", tmp_path / "d", "--set", f"{key}={value}")
        assert res.returncode == 2
        assert str(e.value).strip() == res.stderr.strip()
        assert not isinstance(e.value, shaping.ShapingError)
        # The setting as data, as given.
        assert (e.value.setting, e.value.value) == (key, str(value))
    with pytest.raises(ValueError, match="one value"):
        shaping.run(TINY, out=tmp_path / "e", set={"first.evolve.generations": [1, 2]})
    with pytest.raises(ValueError, match="STAGE.SECTION.FIELD"):
        shaping.run(TINY, out=tmp_path / "f", set={"generations": 2})
    for jobs in (0, -1, 1.5, 100000, "2"):
        with pytest.raises(ValueError, match="jobs must be an integer from 1 to 1024"):
            shaping.run(TINY, out=tmp_path / "g", jobs=jobs)
    with pytest.raises(ValueError, match="seed must be an integer from 0 to 18446744073709551615"):
        shaping.run(TINY, out=tmp_path / "g", seed=-1)
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
    runs to see it): the engine's flag stops it (the generation under way
    dropped, or, between two, after the last); KeyboardInterrupt with the
    CLI's message; resumable."""
    import signal
    import threading

    out = tmp_path / "long"
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt, match="interrupted: stage `navigation` stopped (after|in) generation"):
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


def test_experiment_gives_the_summarys_medians_and_tests(tmp_path):
    """`medians()` and `tests()` are summary.json's `tests` as records: a
    sweep of three points has each pair's p-value, Holm's and A12."""
    exp = shaping.experiment(
        TINY,
        seeds=3,
        out=tmp_path / "sweep",
        set={"first.evolve.mutation": [0.01, 0.2, 0.5]},
        report=False,
    )
    tests = exp.tests()
    names = ["first.evolve.mutation=0.01", "first.evolve.mutation=0.2", "first.evolve.mutation=0.5"]
    stored = exp.summary["tests"]
    assert stored["groups"] == names and stored["holm"] is True
    pairs = [(m, p) for m in stored["measures"] for p in m["pairs"]]
    assert len(tests) == len(pairs) > 0
    for t, (m, p) in zip(tests, pairs):
        assert (t["stage"], t["measure"]) == (m["stage"], m["measure"])
        assert (t["a"], t["b"]) == (names[p["a"] - 1], names[p["b"] - 1])
        for key in ["u", "p_value", "p_holm", "a12", "size", "method"]:
            assert t[key] == p[key], key
        assert 0 <= t["p_value"] <= t["p_holm"] <= 1 and 0 <= t["a12"] <= 1
        assert t["no_test"] is None
    assert {(t["a"], t["b"]) for t in tests} == {(names[0], names[1]), (names[0], names[2]), (names[1], names[2])}
    medians = exp.medians()
    assert len(medians) == 3 * len(stored["measures"])
    chosen = [r for r in medians if (r["stage"], r["measure"]) == ("second", "chosen_best")]
    assert [r["group"] for r in chosen] == names
    for r in chosen:
        assert r["seeds"] == 3 and r["low"] <= r["median"] <= r["high"]
    # One experiment: its medians, no pairs.
    one = shaping.experiment(TINY, seeds=2, out=tmp_path / "one", report=False)
    assert one.tests() == []
    assert {r["group"] for r in one.medians()} == {"tiny"}


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
    with pytest.raises(ValueError, match="seeds"):
        shaping.experiment(TINY, seeds=0, out=tmp_path / "none")
    with pytest.raises(ValueError, match="no stage `nope`"):
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
    # The runtime decodes in f32: the values its controllers use.
    np.testing.assert_allclose(genes.decode(program, "navigation", g)[0], levels, rtol=1e-6)
    # Gene 5 is level 5: bits 0101, most significant first.
    assert list(g[0, 20:24]) == [0, 1, 0, 1]
    # The frozen genes of a later stage are the base genome's.
    base = random_genomes(1, program.genome_bits("collect"), seed=5)[0]
    frozen = [x for x in program.layout("collect") if x["frozen"]]
    values = np.zeros((2, len(genes.evolvable(program, "collect"))))
    out = genes.encode(program, "collect", values, base=base)
    for x in frozen:
        np.testing.assert_array_equal(out[:, x["offset"] : x["offset"] + x["bits"]], [base[x["offset"] : x["offset"] + x["bits"]]] * 2)
    with pytest.raises(ValueError, match="48 columns"):
        genes.encode(program, "navigation", np.zeros((1, 3)))


def test_genes_encode_refuses_a_stage_with_frozen_genes_without_their_source():
    from shaping import genes

    program = shaping.compile(KHEPERA)
    values = np.zeros((2, len(genes.evolvable(program, "collect"))))
    with pytest.raises(ValueError, match=r"stage `collect` has \d+ frozen genes.*run=.*base="):
        genes.encode(program, "collect", values)
    with pytest.raises(ValueError, match="not both"):
        genes.encode(program, "collect", values, base=np.zeros(344, np.uint8), run=ROOT)
    with pytest.raises(ValueError, match="base must be one genome"):
        genes.encode(program, "collect", values, base=np.zeros(343, np.uint8))
    with pytest.raises(ValueError, match="base must be one genome"):
        genes.encode(program, "collect", values, base=np.full(344, 2))


def test_genes_encode_takes_the_frozen_genes_from_a_run(tmp_path):
    from shaping import genes

    run = shaping.run(TINY, out=tmp_path / "run", set={"first.evolve.generations": 1}, report=False, stage="second")
    program = shaping.compile(TINY)
    frozen = [x for x in program.layout("second") if x["frozen"]]
    assert frozen
    values = np.zeros((3, len(genes.evolvable(program, "second"))))
    best = run.best_genome("first")
    for source in (run, run.out, str(run.out)):
        g = genes.encode(program, "second", values, run=source)
        assert g.shape == (3, program.genome_bits("second"))
        np.testing.assert_array_equal(g[:, : len(best)], [best] * 3)
    # First stage: no frozen genes, the run changes nothing.
    np.testing.assert_array_equal(
        genes.encode(program, "first", np.zeros((1, len(genes.evolvable(program, "first")))), run=run),
        genes.encode(program, "first", np.zeros((1, len(genes.evolvable(program, "first"))))),
    )
    # A run of another program is refused.
    other = shaping.compile(KHEPERA)
    with pytest.raises(ValueError, match="run= must be a run of this program"):
        genes.encode(other, "collect", np.zeros((1, len(genes.evolvable(other, "collect")))), run=run)
    with pytest.raises(ValueError, match="does not exist"):
        genes.encode(program, "second", values, run=tmp_path / "nothing")


def test_genes_encode_refuses_nan_and_rounds_halves_as_the_runtime():
    from shaping import genes

    program = shaping.compile(KHEPERA)
    n = len(genes.evolvable(program, "navigation"))
    x = np.zeros((2, n))
    x[1, 7] = np.nan
    with pytest.raises(ValueError, match="row 1, column 7 .* NaN"):
        genes.encode(program, "navigation", x)
    # Exact halves between two levels (in the f32 arithmetic of the
    # runtime's `Genome::encode`) take the upper level, as a run's
    # write-back does; np.rint would take the even one.
    lo, hi = np.float32(-4), np.float32(4)
    halves = []
    for k in range(15):
        v = np.float32(lo + (hi - lo) * np.float32((k + 0.5) / 15))
        if np.float32(np.float32(v - lo) / np.float32(hi - lo)) * np.float32(15) == np.float32(k + 0.5):
            halves.append((k, float(v)))
    assert len(halves) >= 3, halves
    for k, v in halves:
        g = genes.encode(program, "navigation", np.full((1, n), v))
        level = int("".join(map(str, g[0, :4])), 2)
        assert level == k + 1, (k, v, level)
    # Decoding is the runtime's too: every level's value, in f32.
    levels = lo + (hi - lo) * ((np.arange(n) % 16).astype(np.float32) / np.float32(15))
    np.testing.assert_array_equal(
        genes.decode(program, "navigation", genes.encode(program, "navigation", levels[None, :]))[0],
        levels.astype(np.float32),
    )


# ------------------------------------------------------------------ issue 46, 47


def test_generations_of_a_stage_with_variants(tmp_path):
    """examples/t-maze.bat's `maze` has four variants: their columns
    are floats; with `draw 2`, a generation leaves two out (NaN)."""
    tmaze = ROOT / "examples" / "t-maze.bat"
    run = shaping.run(tmaze, out=tmp_path / "all", stage="maze", set={"maze.evolve.generations": 2},
                      report=False)
    g = run.generations("maze")
    assert len(g["best"]) == 2
    names = ["left", "right", "left_seen", "right_seen"]
    for v in names:
        column = g[f"best_variant_{v}"]
        assert column.dtype == np.float64 and column.shape == (2,) and np.all(np.isfinite(column)), v
    assert g["best_index"].dtype == np.int64
    source = tmaze.read_text()
    assert source.count("variants mean {") >= 1
    drawn = tmp_path / "drawn.bat"
    drawn.write_text(source.replace("variants mean {", "variants mean draw 2 {", 1))
    run = shaping.run(drawn, out=tmp_path / "drawn", stage="maze",
                      set={"maze.evolve.generations": 3}, report=False)
    g = run.generations("maze")
    columns = np.array([g[f"best_variant_{v}"] for v in names])
    assert columns.shape == (4, 3)
    # Each generation draws two of the four: two numbers and two NaN.
    assert np.all(np.isnan(columns).sum(axis=0) == 2), columns


def test_a_row_s_result_does_not_depend_on_its_place_in_the_batch(navigation):
    """`individuals`: each row's index in its generation. Split three ways
    or reversed, every genome gets the numbers it got in one batch."""
    _, ev = navigation
    genomes = random_genomes(30, ev.bits, seed=11)
    whole = ev.evaluate(genomes, generation=2)
    ids = np.arange(30)
    parts = [ev.evaluate(genomes[a:b], generation=2, individuals=ids[a:b]) for a, b in [(0, 7), (7, 19), (19, 30)]]
    back = ev.evaluate(genomes[::-1], generation=2, individuals=ids[::-1].tolist())
    for k in whole:
        np.testing.assert_array_equal(np.concatenate([p[k] for p in parts]), whole[k], err_msg=k)
        np.testing.assert_array_equal(back[k][::-1], whole[k], err_msg=k)
    # The default is the rows' order; an index is any row's.
    np.testing.assert_array_equal(ev.evaluate(genomes, generation=2, individuals=ids)["fitness"], whole["fitness"])
    same = ev.evaluate(genomes[:2], generation=2, individuals=np.array([5, 5], dtype=np.uint16))
    assert same["fitness"][0] == ev.evaluate(genomes[:1], generation=2, individuals=[5])["fitness"][0]


def test_bad_individuals_generation_and_seed_name_the_argument(navigation):
    program, ev = navigation
    genomes = random_genomes(3, ev.bits)
    for bad, match in [
        ([0, 1], r"individuals must be an array of shape \(3,\)"),
        ([[0, 1, 2]], r"individuals must be an array of shape \(3,\)"),
        ([0, -1, 2], "individuals must be indices from 0 to 4294967295.*row 1 holds -1"),
        ([0, 1, 2**40], "individuals must be indices from 0 to 4294967295.*row 2 holds 1099511627776"),
        ([0.0, 1.0, 2.0], "individuals must be integers"),
    ]:
        with pytest.raises(ValueError, match=match):
            ev.evaluate(genomes, individuals=bad)
    for g in (-1, 2**32, 1.5, True):
        with pytest.raises(ValueError, match="generation must be an integer from 0 to 4294967295"):
            ev.evaluate(genomes, generation=g)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for seed in (-1, 2**64, 0.5):
            with pytest.raises(ValueError, match="seed must be an integer from 0 to 18446744073709551615"):
                program.evaluator("navigation", seed=seed)
        for jobs in (0, -1, 100000, 2.0):
            with pytest.raises(ValueError, match="jobs must be an integer from 1 to 1024"):
                program.evaluator("navigation", jobs=jobs)
        assert program.evaluator("navigation", seed=2**64 - 1, jobs=1024).seed == 2**64 - 1


def test_a_batch_too_large_for_the_memory_is_refused(tmp_path):
    """In a child process: before the fix, the allocation aborted the interpreter."""
    import sys

    code = (
        "import warnings\n"
        "import numpy as np\n"
        "import shaping\n"
        "warnings.simplefilter('ignore')\n"
        f"ev = shaping.compile({str(KHEPERA)!r}).evaluator('navigation', jobs=1)\n"
        "huge = np.broadcast_to(np.zeros(ev.bits, np.uint8), (2**40, ev.bits))\n"
        "try:\n"
        "    ev.evaluate(huge)\n"
        "except MemoryError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert re.search(r"evaluating 1099511627776 genomes needs about [\d.]+ GiB", out.stdout), out.stdout


def _evaluate_in_child(ev, genomes):
    return ev.evaluate(genomes)["fitness"]


def test_an_evaluator_made_before_fork_works_in_the_child(navigation):
    import multiprocessing

    _, ev = navigation
    genomes = random_genomes(6, ev.bits, seed=12)
    expected = ev.evaluate(genomes)["fitness"]  # the pool's threads run in the parent
    ctx = multiprocessing.get_context("fork")
    with ctx.Pool(2) as pool:
        # (Before the fix the children waited forever for the pool's threads.)
        got = pool.starmap_async(_evaluate_in_child, [(ev, genomes)] * 2, chunksize=1).get(timeout=120)
    for g in got:
        np.testing.assert_array_equal(g, expected)
    # jobs=1 too, and the evaluator inherited (not pickled) by the child.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one = navigation[0].evaluator("navigation", seed=3, jobs=1)
    one.evaluate(genomes)
    global _INHERITED
    _INHERITED = one
    with ctx.Pool(1) as pool:
        got = pool.apply_async(_evaluate_inherited, (genomes,)).get(timeout=120)
    np.testing.assert_array_equal(got, expected)


_INHERITED = None


def _evaluate_inherited(genomes):
    return _INHERITED.evaluate(genomes)["fitness"]


def test_a_program_and_an_evaluator_pickle(navigation, tmp_path):
    import pickle

    program, ev = navigation
    again = pickle.loads(pickle.dumps(program))
    assert again.stages == program.stages and again.path == program.path and again.name == program.name
    assert again.layout("collect") == program.layout("collect")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing is trained again
        copy = pickle.loads(pickle.dumps(ev))
    assert (copy.stage, copy.bits, copy.seed, copy.episodes) == (ev.stage, ev.bits, ev.seed, ev.episodes)
    genomes = random_genomes(5, ev.bits, seed=13)
    for k, v in ev.evaluate(genomes, generation=1).items():
        np.testing.assert_array_equal(copy.evaluate(genomes, generation=1)[k], v, err_msg=k)
    with pytest.raises(TypeError):
        pickle.dumps(shaping._shaping.Stepper(program, "navigation"))


def test_ctrl_c_stops_evaluate_within_a_second(tmp_path):
    """SIGINT to a process in a long `evaluate` (minutes): KeyboardInterrupt
    within about a second."""
    import signal
    import sys
    import time

    script = tmp_path / "long.py"
    script.write_text(
        "import sys, time, warnings\n"
        "import numpy as np\n"
        "import shaping\n"
        "warnings.simplefilter('ignore')\n"
        f"ev = shaping.compile({str(KHEPERA)!r}).evaluator('navigation', seed=1, jobs=1)\n"
        "g = np.random.default_rng(0).integers(0, 2, size=(200000, ev.bits), dtype=np.uint8)\n"
        "print('start', flush=True)\n"
        "try:\n"
        "    ev.evaluate(g)\n"
        "    print('finished', flush=True)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', time.monotonic(), flush=True)\n"
    )
    child = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        assert child.stdout.readline().strip() == "start"
        time.sleep(1.0)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        out, _ = child.communicate(timeout=30)
    finally:
        child.kill()
    assert out.startswith("interrupted"), out
    took = float(out.split()[1]) - sent
    assert took < 1.5, took
