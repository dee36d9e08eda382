"""The Gymnasium environments of `shaping.gym`: the checker passes, the
spaces are the stage's sensors and actuators, the reward is the stage's
fitness per action, lives end as the stage's do, and the vector
environment steps many robots deterministically with next-step autoreset."""

from pathlib import Path

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import shaping  # noqa: E402
import shaping.gym  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
KHEPERA = ROOT / "examples" / "khepera.bat"
NO_BATTERY = """robot khepera {
  sensor ir[8] proximity
  actuator wheels[2] speed
}
genome { bits 4 range -1..1 }
stage roam {
  world { arena 400mm x 600mm }
  evolve { population 4 generations 1 actions 50 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 50
  module wander { sense ir behavior forward(1.0) }
}
"""


@pytest.mark.parametrize("stage", ["navigation", "collect"])
def test_the_gymnasium_checker_passes(stage):
    env = shaping.gym.make(KHEPERA, stage, render_mode="rgb_array")
    check_env(env, skip_render_check=False)


def test_gymnasium_make_knows_the_environment():
    env = gymnasium.make(shaping.gym.ENV_ID, path=KHEPERA, stage="navigation", render_mode="rgb_array")
    check_env(env.unwrapped)
    obs, _ = env.reset(seed=2)
    assert obs.shape == (17,)
    env.close()


def test_spaces_are_the_declared_sensors_and_actuators():
    env = shaping.gym.make(KHEPERA, "collect")
    assert env.observation_names[:8] == [f"ir[{i}]" for i in range(8)]
    assert env.observation_names[8:] == [f"light[{i}]" for i in range(8)] + ["battery", "barrier"]
    assert env.observation_space.shape == (18,)
    assert env.action_names == ["wheels[0]", "wheels[1]", "arm", "claw", "charge"]
    np.testing.assert_array_equal(env.action_space.low, [-1, -1, 0, 0, 0])
    np.testing.assert_array_equal(env.action_space.high, [1, 1, 1, 1, 1])


def test_the_reward_is_the_stage_s_fitness_per_action_and_the_battery_ends_a_life():
    env = shaping.gym.make(KHEPERA, "navigation")
    obs, info = env.reset(seed=3)
    total, steps = 0.0, 0
    while True:
        obs, reward, terminated, truncated, info = env.step(np.array([1.0, 1.0, 0.0], np.float32))
        steps += 1
        # navigation: abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300,
        # ir the proximity readings after the action.
        assert reward == pytest.approx((1.0 - obs[:8].max()) / 300, abs=1e-6)
        total += reward
        if terminated or truncated:
            break
    # A battery of 200 actions, never recharged: the life ends at 200.
    assert (steps, terminated, truncated) == (200, True, False)
    assert obs[16] == 0.0 and info["battery"] == 0.0
    assert info["path_length"] > 0 and info["squares_visited"] >= 1
    assert 0 < total < 200 / 300


def test_a_life_is_cut_at_the_stage_s_length(tmp_path):
    path = tmp_path / "roam.bat"
    path.write_text(NO_BATTERY)
    env = shaping.gym.make(path, "roam")
    env.reset(seed=0)
    for i in range(50):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        assert not terminated
        assert truncated == (i == 49)
    with pytest.raises(ValueError, match="reset"):
        env.step(np.zeros(2, np.float32))


def test_the_same_seed_gives_the_same_life():
    def life(seed):
        env = shaping.gym.make(KHEPERA, "navigation")
        obs, info = env.reset(seed=seed)
        rng = np.random.default_rng(0)
        out = [obs]
        for _ in range(120):
            out.append(env.step(rng.uniform([-1, -1, 0], 1).astype(np.float32))[0])
        return np.array(out), info["episode_seed"]

    a, seed_a = life(7)
    b, seed_b = life(7)
    np.testing.assert_array_equal(a, b)
    assert seed_a == seed_b
    assert not np.array_equal(a, life(8)[0])
    # The world of an episode seed can be asked for directly.
    env = shaping.gym.make(KHEPERA, "navigation")
    obs, info = env.reset(options={"episode_seed": seed_a})
    np.testing.assert_array_equal(obs, a[0])


def test_bad_actions_and_arguments_raise():
    env = shaping.gym.make(KHEPERA, "navigation")
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"`wheels\[0\]`\) is 1.5, outside -1..1"):
        env.step(np.array([1.5, 0.0, 0.0], np.float32))
    with pytest.raises(ValueError, match=r"shape \(3,\)"):
        env.step(np.zeros(2))
    with pytest.raises(ValueError, match="NaN"):
        env.step([np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match="unknown reset options"):
        env.reset(options={"world": 1})
    with pytest.raises(ValueError, match="no stage `nope`"):
        shaping.gym.make(KHEPERA, "nope")
    with pytest.raises(shaping.ShapingError, match="cannot read"):
        shaping.gym.make(ROOT / "no-such-file.bat", "navigation")
    with pytest.raises(ValueError, match="render_mode"):
        shaping.gym.make(KHEPERA, "navigation", render_mode="human")


def test_render_draws_the_arena_in_one_size():
    env = shaping.gym.make(KHEPERA, "collect", render_mode="rgb_array")
    env.reset(seed=1)
    first = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    for _ in range(60):
        env.step(np.array([1.0, 0.5, 0.0, 0.0, 0.0], np.float32))
    later = env.render()
    assert later.shape == first.shape
    assert not np.array_equal(later, first)
    assert shaping.gym.make(KHEPERA, "collect").render() is None


def vec_lives(num_envs, jobs, steps=260):
    envs = shaping.gym.make_vec(KHEPERA, "navigation", num_envs=num_envs, jobs=jobs)
    obs, _ = envs.reset(seed=5)
    rng = np.random.default_rng(1)
    out = [(obs, None, None, None)]
    for _ in range(steps):
        actions = rng.uniform([-1, -1, 0], 1, size=(num_envs, 3)).astype(np.float32)
        obs, rewards, terminated, truncated, _ = envs.step(actions)
        out.append((obs, rewards, terminated, truncated))
    return out


def test_the_vector_environment_is_deterministic_and_resets_each_robot():
    one = vec_lives(16, jobs=1)
    two = vec_lives(16, jobs=2)
    for a, b in zip(one, two):
        for x, y in zip(a, b):
            np.testing.assert_array_equal(x, y)
    assert one[1][0].shape == (16, 17) and one[1][1].dtype == np.float32
    ended = False
    for t in range(1, len(one) - 1):
        obs, rewards, terminated, truncated = one[t]
        for r in np.flatnonzero(terminated | truncated):
            ended = True
            nobs, nrewards, nterm, ntrunc = one[t + 1]
            assert nrewards[r] == 0.0 and not nterm[r] and not ntrunc[r]
            assert nobs[r, 16] == 1.0  # a new life: a full battery
    assert ended, "no robot's life ended in 260 random actions"
    envs = shaping.gym.make_vec(KHEPERA, "navigation", num_envs=3)
    envs.reset(seed=0)
    with pytest.raises(ValueError, match="row 1 of the actions"):
        envs.step(np.array([[0, 0, 0], [0, 0, 2], [0, 0, 0]], np.float32))
    with pytest.raises(ValueError, match=r"shape \(3, 3\)"):
        envs.step(np.zeros((2, 3), np.float32))
    with pytest.raises(ValueError, match="num_envs"):
        shaping.gym.make_vec(KHEPERA, "navigation", num_envs=0)


def test_a_team_is_refused():
    # One agent drives one robot: a stage with a team of 10 is refused.
    with pytest.raises(shaping.ShapingError, match="team of 10 robots.*make_parallel"):
        shaping.gym.make(ROOT / "examples" / "aggregation.bat", "aggregate")


def test_bad_num_envs_and_jobs_raise():
    for n in (1.5, 0, -3, "4", True):
        with pytest.raises(ValueError, match="num_envs must be"):
            shaping.gym.make_vec(KHEPERA, "navigation", num_envs=n)
    assert shaping.gym.make_vec(KHEPERA, "navigation", num_envs=np.int64(3)).num_envs == 3
    with pytest.raises(ValueError, match="jobs must be an integer from 1 to 1024"):
        shaping.gym.make_vec(KHEPERA, "navigation", num_envs=2, jobs=100000)


def test_too_many_robots_for_the_memory_are_refused(tmp_path):
    """In a child process: before the fix, the allocation aborted the interpreter."""
    import re
    import subprocess
    import sys

    code = (
        "import shaping\n"
        "try:\n"
        f"    shaping.gym.make_vec({str(KHEPERA)!r}, 'navigation', num_envs=10**9)\n"
        "except MemoryError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert re.search(r"stepping 1000000000 robots needs about [\d.]+ GiB", out.stdout), out.stdout


def _step_in_child(envs, actions):
    envs.reset(seed=4)
    return envs.step(actions)[0]


def test_a_vector_environment_made_before_fork_works_in_the_child():
    import multiprocessing

    envs = shaping.gym.make_vec(KHEPERA, "navigation", num_envs=64, jobs=2)
    actions = np.full(envs.action_space.shape, 0.5, np.float32)
    expected = _step_in_child(envs, actions)  # the pool's threads run in the parent
    global _ENVS
    _ENVS = (envs, actions)
    with multiprocessing.get_context("fork").Pool(1) as pool:
        got = pool.apply_async(_inherited_step, ()).get(timeout=60)
    np.testing.assert_array_equal(got, expected)


_ENVS = None


def _inherited_step():
    return _step_in_child(*_ENVS)


def test_shaping_gym_loads_on_first_use_and_says_how_to_install_gymnasium(tmp_path):
    import subprocess
    import sys

    code = (
        "import shaping\n"
        f"env = shaping.gym.make({str(KHEPERA)!r}, 'navigation')\n"
        "print(type(env).__name__)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0 and out.stdout.strip() == "ShapingEnv", out.stderr
    # Without gymnasium: `import shaping` works, `shaping.gym` says what to install.
    code = (
        "import sys\n"
        "sys.modules['gymnasium'] = None\n"
        "import shaping\n"
        "try:\n"
        "    shaping.gym\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert 'pip install "shaping[gym]"' in out.stdout, out.stdout
