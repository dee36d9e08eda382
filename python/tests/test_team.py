"""Teams from Python: `evaluate` gives every robot's descriptors and any
measure a fitness `at end` may be, and `shaping.gym.make_parallel` is a
PettingZoo parallel environment of a stage's team."""

import csv
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import shaping
from test_shaping import shaping_cli  # the CLI, as test_shaping.py calls it

ROOT = Path(__file__).resolve().parents[2]
AGGREGATION = ROOT / "examples" / "aggregation.bat"
ROLES = ROOT / "examples" / "aggregation-roles.bat"
RAB = ROOT / "examples" / "aggregation-rab.bat"
KHEPERA = ROOT / "examples" / "khepera.bat"
RECRUIT = ROOT / "examples" / "recruit.bat"


def random_genomes(n, bits, seed=1):
    return np.random.default_rng(seed).integers(0, 2, size=(n, bits), dtype=np.uint8)


# ------------------------------------------------------------------ evaluate


def test_a_team_s_evaluation_gives_every_robot_s_descriptors():
    ev = shaping.compile(AGGREGATION).evaluator("aggregate", seed=5, jobs=2)
    g = random_genomes(5, ev.bits, seed=2)
    a = ev.evaluate(g)
    robots = a["robots"]
    assert set(robots) == {"fitness", "x", "y", "heading", "path_length", "squares_visited", "recharges",
                           "grips", "releases_outside", "collisions"}
    for k, v in robots.items():
        assert v.shape == (5, 10), k
    assert robots["x"].dtype == np.float32 and robots["collisions"].dtype == np.uint32
    # The team's descriptors are robot 0's; its events the robots' sum.
    for k in ("x", "y", "heading", "path_length", "squares_visited"):
        np.testing.assert_array_equal(robots[k][:, 0], a[k])
    np.testing.assert_array_equal(robots["collisions"].sum(axis=1), a["collisions"])
    # `team mean`: the team's fitness is the mean of the robots' own.
    np.testing.assert_allclose(robots["fitness"].mean(axis=1), a["fitness"], rtol=0, atol=1e-5)
    # Every robot in the arena, each somewhere else.
    assert np.all((robots["x"] >= 0) & (robots["x"] <= 600) & (robots["y"] >= 0) & (robots["y"] <= 600))
    assert len(set(robots["x"][0].tolist())) == 10


def test_one_robot_s_evaluation_is_as_it_was():
    program = shaping.compile(KHEPERA)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ev = program.evaluator("navigation", seed=3)
    a = ev.evaluate(random_genomes(3, ev.bits))
    assert set(a) == {"fitness", "recharges", "grips", "releases_outside", "collisions", "x", "y", "heading",
                      "path_length", "squares_visited", "placement_failures"}


def test_measures_read_what_a_fitness_reads():
    ev = shaping.compile(AGGREGATION).evaluator("aggregate", seed=5, jobs=2)
    g = random_genomes(4, ev.bits, seed=7)
    plain = ev.evaluate(g)
    a = ev.evaluate(g, measures={
        "x": "robot.x",
        "fit": "1 - team.spread / 400",
        "spread": "team.spread",
        "order": "team.order",
        "nearest": "team.nearest",
        "moved": "robot.distance / robot.time",
        "ir": "max(ir)",
    })
    # Measures change nothing else.
    for k in ("fitness", "x", "collisions"):
        np.testing.assert_array_equal(a[k], plain[k])
    m = a["measures"]
    # Per robot where the expression reads a robot; the team's terms, one per individual.
    assert m["x"].shape == (4, 10) and m["moved"].shape == (4, 10) and m["ir"].shape == (4, 10)
    assert m["fit"].shape == (4,) and m["spread"].shape == (4,) and m["order"].shape == (4,)
    # A measure equal to a descriptor gives its numbers: the means over the
    # episodes of the squares visited and of the path's length (`x` is the
    # last episode's, its measure the mean).
    one = ev.evaluate(g, measures={"squares": "robot.squares", "d": "robot.distance"})
    # The stage's fitness is its own measure.
    np.testing.assert_allclose(m["fit"], a["fitness"], rtol=0, atol=1e-5)
    np.testing.assert_allclose(1 - m["spread"] / 400, a["fitness"], rtol=0, atol=1e-5)
    np.testing.assert_allclose(one["measures"]["squares"], one["robots"]["squares_visited"], rtol=1e-6)
    np.testing.assert_allclose(one["measures"]["d"], one["robots"]["path_length"], rtol=1e-5)
    assert np.all((m["order"] >= 0) & (m["order"] <= 1))
    assert np.all((m["nearest"] > 0) & (m["nearest"] < 600))
    assert np.all((m["ir"] >= 0) & (m["ir"] <= 1))


def test_measures_of_one_episode_equal_the_descriptors():
    program = shaping.compile(KHEPERA)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ev = program.evaluator("navigation", seed=3)
    g = random_genomes(4, ev.bits, seed=4)
    a = ev.evaluate(g, measures={"x": "robot.x", "y": "robot.y", "heading": "robot.heading",
                                 "squares": "robot.squares", "battery": "battery"})
    m = a["measures"]
    assert ev.episodes == 1
    for k in ("x", "y", "heading"):
        assert m[k].shape == (4,)
        np.testing.assert_array_equal(m[k], a[k])
    np.testing.assert_array_equal(m["squares"], a["squares_visited"])
    assert np.all((m["battery"] >= 0) & (m["battery"] <= 1))


def test_episode_seeds_are_those_a_run_derives():
    """`Evaluator.episode_seeds` lists the episodes `evaluate` lives: the
    seeds `runtime/src/evolve/seed.rs` derives (its module doc: h =
    splitmix64(run seed), then h = splitmix64(h ^ p) for the tag "EVAL",
    the stage's index, the generation, the individual and the episode),
    and the variants of a stage that has them."""
    mask = (1 << 64) - 1

    def splitmix64(x):
        z = (x + 0x9E3779B97F4A7C15) & mask
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & mask
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
        return z ^ (z >> 31)

    def derived(run_seed, stage, generation, individual, episode):
        h = splitmix64(run_seed)
        for p in (0x4556414C, stage, generation, individual, episode):
            h = splitmix64(h ^ p)
        return h

    ev = shaping.compile(RAB).evaluator("aggregate", seed=5)
    assert ev.episode_seeds(7, 2) == [(derived(5, 0, 2, 7, e), None) for e in range(3)]
    assert ev.episode_seeds() == [(derived(5, 0, 0, 0, e), None) for e in range(3)]
    # A stage that draws one of its four variants per generation (`draw
    # 1`): the generation's variant, the same for every individual.
    recruit = shaping.compile(RECRUIT).evaluator("forage", seed=5)
    drawn = set()
    for generation in range(8):
        lives = recruit.episode_seeds(1, generation)
        assert len(lives) == recruit.episodes == 3
        [variant] = {v for _, v in lives}
        assert [v for _, v in recruit.episode_seeds(2, generation)] == [variant] * 3
        drawn.add(variant)
    assert drawn <= {"south_west", "south_east", "north_west", "north_east"} and len(drawn) > 1
    for bad in (-1, 1.5, True, "3"):
        with pytest.raises(ValueError, match="individual must be an integer"):
            ev.episode_seeds(bad)
    with pytest.raises(ValueError, match="generation must be an integer"):
        ev.episode_seeds(0, -2)


def test_a_stage_that_draws_its_variants_is_evaluated_as_its_run(tmp_path):
    """recruit.bat's `forage` draws one variant per generation: `evaluate`
    gives a generation's individuals the fitness the run gave them (it ran
    every variant before)."""
    out = tmp_path / "run"
    res = shaping_cli("run", RECRUIT, "--stage", "forage", "--seed", 5, "--out", out, "--no-report",
                      "--set", "forage.evolve.generations=2", "--set", "forage.evolve.population=4")
    assert res.returncode == 0, res.stderr
    genomes, fitness = shaping.Run(out).population("forage")
    ev = shaping.compile(RECRUIT).evaluator("forage", seed=5)
    np.testing.assert_array_equal(ev.evaluate(genomes, generation=1)["fitness"], fitness)


def _replayed(tmp_path, genome, seed, name):
    """One life of `genome` in stage `aggregate` of aggregation-rab.bat, as
    `shaping replay` traces it: each robot's start (`episode.json`) and
    its rows of `trace.csv`, action after action."""
    out = tmp_path / name
    res = shaping_cli("replay", RAB, "--stage", "aggregate", "--genome", "".join(map(str, genome)),
                      "--seed", seed, "--out", out)
    assert res.returncode == 0, res.stderr
    world = json.loads((out / "episode.json").read_text())["worlds"][0]
    starts = [world["start"], *world["others"]]
    with open(out / "trace.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    robots = []
    for i, start in enumerate(starts):
        mine = [r for r in rows if int(r["robot"]) == i]
        assert [int(r["action"]) for r in mine] == list(range(len(mine)))
        robots.append({
            "xy": np.array([start[:2]] + [[float(r["x"]), float(r["y"])] for r in mine]),
            "theta": float(mine[-1]["theta"]),
            "rab": np.array([float(mine[-1][f"rab[{k}]"]) for k in range(8)]),
        })
    assert len(robots) == 10 and len(rows) == 10 * 400
    return robots


# trace.csv prints x and y with 2 decimals, theta with 4: a printed
# position is within 0.005 mm of the robot's in x and in y, so within
# 0.005 * sqrt(2) of it; a distance between two printed positions within
# 0.01 * sqrt(2) of the distance between the robots'. It prints the sensors
# with 4 decimals, but they are the episode's columns (`episode.json`),
# rounded to 3 (`EpisodeColumns::push_frame`): within 0.0005. A mean over
# episodes, cast to float32 as `evaluate` returns it, may be 1e-4 further.
XY = 0.005
THETA = 0.00005
SENSOR = 0.0005
DISTANCE = 0.01 * 2**0.5


def _squares(xy):
    """The 50 mm squares the printed positions `xy` lie in, counted once, as
    `runtime/src/state.rs` counts them (`square_of`, `SQUARE_MM`): the fewest
    and the most the robot's own positions can have been in (the same
    number unless a printed position is within 0.005 mm of a square's side)."""
    sure, unsure = set(), []
    for x, y in xy:
        xs = {int(np.floor((x - XY) / 50)), int(np.floor((x + XY) / 50))}
        ys = {int(np.floor((y - XY) / 50)), int(np.floor((y + XY) / 50))}
        cells = {(a, b) for a in xs for b in ys}
        if len(cells) == 1:
            sure |= cells
        else:
            unsure.append(cells)
    extra = set().union(*unsure) - sure if unsure else set()
    fewest = len(sure) + (1 if any(not (c & sure) for c in unsure) else 0)
    return fewest, len(sure) + len(extra)


def test_a_team_s_descriptors_and_measures_are_those_of_its_trace(tmp_path):
    """Issue 50: every robot's descriptors and the measures `evaluate` gives
    are those of the lives the CLI traces. An individual's evaluation is
    its episodes (the stage's `evaluations 3`), each replayed with `--seed`
    its episode seed: the final pose is the last episode's last row, the
    path length, the squares visited and each measure the mean over the
    episodes of what the trace gives."""
    seed, generation, individual = 5, 2, 7
    ev = shaping.compile(RAB).evaluator("aggregate", seed=seed, jobs=1)
    genome = random_genomes(1, ev.bits, seed=11)
    measures = {"x": "robot.x", "y": "robot.y", "distance": "robot.distance",
                "squares": "robot.squares", "spread": "team.spread", "nearest": "team.nearest",
                "rab": "max(rab)", "rab2": "rab[2]"}
    a = ev.evaluate(genome, generation=generation, individuals=[individual], measures=measures)
    robots, m = a["robots"], a["measures"]
    assert ev.episodes == 3
    lives = [_replayed(tmp_path, genome[0], s, f"e{e}")
             for e, (s, _) in enumerate(ev.episode_seeds(individual, generation))]
    last = lives[-1]
    # Each robot's final pose: its last row of the last episode's trace.
    for i, r in enumerate(last):
        x, y = r["xy"][-1]
        assert abs(robots["x"][0, i] - x) <= XY + 1e-6, (i, robots["x"][0, i], x)
        assert abs(robots["y"][0, i] - y) <= XY + 1e-6, (i, robots["y"][0, i], y)
        turn = (robots["heading"][0, i] - r["theta"] + np.pi) % (2 * np.pi) - np.pi
        assert abs(turn) <= THETA + 1e-6, (i, robots["heading"][0, i], r["theta"])
        assert abs(m["x"][0, i] - np.mean([life[i]["xy"][-1][0] for life in lives])) <= XY + 1e-4, i
        assert abs(m["y"][0, i] - np.mean([life[i]["xy"][-1][1] for life in lives])) <= XY + 1e-4, i
    # Each robot's path from its start (`episode.json`; trace.csv's rows are
    # the poses after each action) and the squares it was in, start included.
    for i in range(10):
        paths, moves, fewest, most = [], [], [], []
        for life in lives:
            steps = np.diff(life[i]["xy"], axis=0)
            paths.append(np.hypot(steps[:, 0], steps[:, 1]).sum())
            moves.append(int(np.count_nonzero(np.any(steps != 0, axis=1))))
            lo, hi = _squares(life[i]["xy"])
            fewest.append(lo)
            most.append(hi)
        # A step between two equal printed positions is 0 (the robot did not
        # move: a collision undid its move); each other step within DISTANCE.
        tolerance = DISTANCE * max(moves) + 1e-3
        assert abs(robots["path_length"][0, i] - np.mean(paths)) <= tolerance, (i, robots["path_length"][0, i],
                                                                                np.mean(paths), tolerance)
        assert abs(m["distance"][0, i] - np.mean(paths)) <= tolerance, i
        # (float32's rounding of the mean aside.)
        squares = robots["squares_visited"][0, i]
        assert np.mean(fewest) - 1e-5 <= squares <= np.mean(most) + 1e-5, (i, squares, fewest, most)
        if fewest == most:
            assert robots["squares_visited"][0, i] == pytest.approx(np.mean(fewest), abs=1e-5), i
        assert m["squares"][0, i] == pytest.approx(robots["squares_visited"][0, i], abs=1e-5), i
    # The team's measures, from every robot's last row: the mean distance to
    # the robots' mean centre, the mean distance to the nearest other robot.
    spreads, nearests = [], []
    for life in lives:
        at = np.array([r["xy"][-1] for r in life])
        spreads.append(np.hypot(*(at - at.mean(axis=0)).T).mean())
        gaps = np.hypot(*(at[:, None, :] - at[None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(gaps, np.inf)
        nearests.append(gaps.min(axis=1).mean())
    assert m["spread"].shape == (1,) and m["nearest"].shape == (1,)
    assert abs(m["spread"][0] - np.mean(spreads)) <= DISTANCE + 1e-4, (m["spread"][0], spreads)
    assert abs(m["nearest"][0] - np.mean(nearests)) <= DISTANCE + 1e-4, (m["nearest"][0], nearests)
    assert abs(a["fitness"][0] - (1 - np.mean(spreads) / 400)) <= (DISTANCE + 1e-4) / 400
    # The range-and-bearing board each robot read at its last action.
    for i in range(10):
        best = np.mean([life[i]["rab"].max() for life in lives])
        assert abs(m["rab"][0, i] - best) <= SENSOR + 1e-6, (i, m["rab"][0, i], best)
        sector = np.mean([life[i]["rab"][2] for life in lives])
        assert abs(m["rab2"][0, i] - sector) <= SENSOR + 1e-6, (i, m["rab2"][0, i], sector)
    # Not a still team: the test would say little of robots that never move.
    assert np.all(robots["path_length"][0] > 10) and np.any(last[0]["rab"] > 0)


def test_a_bad_measure_raises_the_compiler_s_diagnostic():
    ev = shaping.compile(AGGREGATION).evaluator("aggregate", seed=5)
    g = random_genomes(2, ev.bits)
    with pytest.raises(shaping.CompileError) as e:
        ev.evaluate(g, measures={"ok": "robot.x", "near": "team.nearset + 1"})
    assert "measure near" in str(e.value)
    assert "no field `nearset`" in str(e.value)
    [d] = e.value.diagnostics
    assert (d.file, d.line, d.column, d.severity) == ("measure near", 1, 6, "error")
    assert "nearest" in d.help
    with pytest.raises(shaping.CompileError) as e:
        ev.evaluate(g, measures={"two": "robot.x robot.y"})
    assert e.value.diagnostics[0].column == 9
    with pytest.raises(shaping.CompileError) as e:
        ev.evaluate(g, measures={"lamp": "distance_to(lamp)"})
    assert "unknown item of the world" in str(e.value)
    with pytest.raises(ValueError, match="must be a dict"):
        ev.evaluate(g, measures=["robot.x"])
    with pytest.raises(ValueError, match="measure `x` must be an expression"):
        ev.evaluate(g, measures={"x": 3})


# ------------------------------------------------------------------ batched teams


def test_teams_stepped_together_are_deterministic_and_start_again():
    gym = pytest.importorskip("shaping.gym")

    def run(jobs):
        envs = gym.make_parallel_vec(RAB, "aggregate", num_envs=3, jobs=jobs)
        assert envs.agents[:2] == ["robot_0", "robot_1"]
        obs, _ = envs.reset(seed=4)
        assert obs.shape == (3, 10, len(envs.observation_names))
        rng = np.random.default_rng(1)
        out = [obs]
        for _ in range(401):
            a = rng.uniform(0, 1, size=(3, 10, 3)).astype(np.float32)
            obs, rew, term, trunc, _ = envs.step(a)
            out.append((obs, rew, term, trunc))
        return out

    one = run(1)
    two = run(2)
    for a, b in zip(one[1:], two[1:]):
        for x, y in zip(a, b):
            np.testing.assert_array_equal(x, y)
    obs, rew, term, trunc = one[400]
    assert rew.shape == (3, 10) and trunc.all() and not term.any()
    obs, rew, term, trunc = one[401]
    assert (rew == 0).all() and not trunc.any()
    envs = gym.make_parallel_vec(RAB, "aggregate", num_envs=2)
    envs.reset(seed=0)
    bad = np.zeros((2, 10, 3), dtype=np.float32)
    bad[1, 4, 2] = 1.2
    with pytest.raises(ValueError, match=r"world 1, the action of `robot_4` \(robot 4\)"):
        envs.step(bad)
    with pytest.raises(ValueError, match=r"shape \(2, 10, 3\)"):
        envs.step(np.zeros((2, 3), dtype=np.float32))
    with pytest.raises(shaping.ShapingError, match="shaping.gym.make"):
        gym.make_parallel_vec(KHEPERA, "navigation", num_envs=2)


# ------------------------------------------------------------------ PettingZoo

pettingzoo = pytest.importorskip("pettingzoo")
import shaping.gym  # noqa: E402
from pettingzoo.test import parallel_api_test  # noqa: E402


@pytest.mark.parametrize("path", [AGGREGATION, ROLES, RAB])
def test_the_parallel_api_test_passes(path):
    env = shaping.gym.make_parallel(path, "aggregate")
    assert isinstance(env, pettingzoo.ParallelEnv)
    parallel_api_test(env, num_cycles=500)


def test_agents_are_named_by_role_with_their_role_s_spaces():
    env = shaping.gym.make_parallel(ROLES, "aggregate")
    assert env.possible_agents == [f"first_{k}" for k in range(5)] + [f"second_{k}" for k in range(5)]
    obs, infos = env.reset(seed=1)
    assert set(obs) == set(env.possible_agents)
    for a in env.possible_agents:
        assert env.observation_space(a).shape == (8,)
        assert env.observation_space(a).contains(obs[a])
        assert env.action_space(a).shape == (2,)
    rab = shaping.gym.make_parallel(RAB, "aggregate")
    assert rab.possible_agents[:2] == ["robot_0", "robot_1"]
    assert rab.action_names == ["wheels[0]", "wheels[1]", "signal[0]"]
    assert rab.observation_space("robot_3").shape == (len(rab.observation_names),)


def test_a_life_of_the_team_is_deterministic_and_ends_at_the_stage_s_length():
    def life(seed):
        env = shaping.gym.make_parallel(AGGREGATION, "aggregate")
        obs, _ = env.reset(seed=seed)
        rng = np.random.default_rng(0)
        totals = dict.fromkeys(env.possible_agents, 0.0)
        steps = 0
        while env.agents:
            actions = {a: rng.uniform(-1, 1, 2).astype(np.float32) for a in env.agents}
            obs, rew, term, trunc, info = env.step(actions)
            for a, r in rew.items():
                totals[a] += r
            steps += 1
        assert all(trunc.values()) and not any(term.values())
        return steps, totals, obs["robot_0"]

    steps, totals, last = life(4)
    assert steps == 400
    again = life(4)
    assert again[1] == totals
    np.testing.assert_array_equal(again[2], last)
    assert life(5)[1] != totals
    # The reward is the robot's own `at end` term: 1 - team.spread / 400, the same for every robot.
    values = set(round(v, 6) for v in totals.values())
    assert len(values) == 1 and -0.1 < values.pop() < 1


def test_an_episode_seed_gives_the_world_of_that_episode():
    env = shaping.gym.make_parallel(AGGREGATION, "aggregate")
    a, info = env.reset(options={"episode_seed": 17})
    assert info["robot_0"]["episode_seed"] == 17
    b, _ = env.reset(seed=3, options={"episode_seed": 17})
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])


def test_bad_actions_name_the_agent_and_the_element():
    env = shaping.gym.make_parallel(ROLES, "aggregate")
    with pytest.raises(ValueError, match="reset"):
        env.step({})
    env.reset(seed=0)
    actions = {a: np.zeros(2, dtype=np.float32) for a in env.agents}
    actions["second_2"] = np.array([0.0, 1.5], dtype=np.float32)
    with pytest.raises(ValueError, match=r"`second_2` \(robot 7\).*`wheels\[1\]`\) is 1.5, outside -1..1"):
        env.step(actions)
    actions["second_2"] = np.zeros(3, dtype=np.float32)
    with pytest.raises(ValueError, match=r"action of `second_2` must be an array of shape \(2,\)"):
        env.step(actions)
    del actions["second_2"]
    with pytest.raises(ValueError, match="no action for the live agents \\['second_2'\\]"):
        env.step(actions)
    actions["second_2"] = np.zeros(2, dtype=np.float32)
    actions["nobody"] = np.zeros(2, dtype=np.float32)
    with pytest.raises(ValueError, match="not live agents"):
        env.step(actions)


def test_a_stage_without_a_team_is_refused_naming_make():
    with pytest.raises(shaping.ShapingError, match="shaping.gym.make"):
        shaping.gym.make_parallel(KHEPERA, "navigation")


def test_render_draws_every_robot():
    env = shaping.gym.make_parallel(ROLES, "aggregate", render_mode="rgb_array")
    env.reset(seed=2)
    first = env.render()
    assert first.ndim == 3 and first.shape[2] == 3 and first.dtype == np.uint8
    for _ in range(30):
        env.step({a: np.array([1.0, 0.8], dtype=np.float32) for a in env.agents})
    later = env.render()
    assert later.shape == first.shape
    assert not np.array_equal(later, first)
    assert shaping.gym.make_parallel(ROLES, "aggregate").render() is None
