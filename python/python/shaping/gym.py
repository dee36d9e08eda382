"""Gymnasium environments of a stage's world and robot.

>>> import shaping.gym
>>> env = shaping.gym.make("examples/khepera.bat", "navigation")
>>> obs, info = env.reset(seed=0)
>>> obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

- The observation is the robot's declared sensors in declaration order,
  a float32 ``Box`` of 0..1 (``env.observation_names`` names them).
- The action is a float32 ``Box``: the two wheel speeds (-1..1 of
  ``v_max``), then ``arm`` (above 0.5: down) and ``claw`` (above 0.5:
  closed) where the robot declares a gripper, then ``charge`` (above 0.5:
  ask the charger to recharge; it charges when the body touches the bar)
  where the world has a charger (``env.action_names``).
- The reward is the stage's fitness for the action (its per-action term,
  and its bonuses for the events of the action): a life's rewards add up
  to the fitness a run gives that episode.
- ``terminated`` when the battery is empty; ``truncated`` at the stage's
  length of life (its ``actions``).
- ``render_mode="rgb_array"``: ``render()`` returns the arena from above,
  with the path of the life so far.

The robot is driven by the agent alone: the stage's modules, their
learning and the genome are not used. ``make_vec`` steps all its robots in
Rust in one call. ``make_parallel`` is a team's PettingZoo environment
(one agent per robot).

Needs ``gymnasium`` (``pip install "shaping[gym]"``, from this repository
``pip install "./python[gym]"``); without it, ``shaping.gym`` raises
ImportError saying so.
"""

from __future__ import annotations

import os
from typing import Any

import importlib.util

import numpy as np

if importlib.util.find_spec("gymnasium") is None:
    raise ImportError('shaping.gym needs gymnasium, which is not installed: pip install "shaping[gym]"')

import gymnasium  # noqa: E402
from gymnasium import spaces  # noqa: E402
from gymnasium.vector import AutoresetMode, VectorEnv  # noqa: E402

from . import Program, compile
from ._shaping import Stepper, TeamStepper, VecStepper, VecTeamStepper

__all__ = ["ENV_ID", "ShapingEnv", "ShapingTeamVecEnv", "ShapingVecEnv", "make", "make_parallel", "make_parallel_vec", "make_vec"]

ENV_ID = "shaping/Stage-v0"
"""The id under which Gymnasium knows the environment:
``gymnasium.make(shaping.gym.ENV_ID, path=..., stage=...)``."""


def _program(path: str | os.PathLike[str] | Program) -> Program:
    return path if isinstance(path, Program) else compile(path)


def _spaces(names_obs: list[str], bounds: tuple[list[float], list[float]]):
    observation = spaces.Box(0.0, 1.0, shape=(len(names_obs),), dtype=np.float32)
    low, high = (np.asarray(b, dtype=np.float32) for b in bounds)
    return observation, spaces.Box(low, high, dtype=np.float32)


def _action(action: Any, shape: tuple[int, ...] | None) -> np.ndarray:
    a = np.ascontiguousarray(action, dtype=np.float32)
    if a.shape != shape:
        raise ValueError(f"error: the action must be an array of shape {shape}, not {a.shape}")
    return a


class ShapingEnv(gymnasium.Env):
    """One robot of a stage (see the module's documentation)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        path: str | os.PathLike[str] | Program,
        stage: str,
        render_mode: str | None = None,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"error: render_mode must be None or 'rgb_array', not {render_mode!r}")
        self.program = _program(path)
        self.stage = stage
        self.render_mode = render_mode
        self._robot = Stepper(self.program, stage, keep_path=render_mode == "rgb_array")
        self.observation_names: list[str] = self._robot.observation_names
        self.action_names: list[str] = self._robot.action_names
        self.observation_space, self.action_space = _spaces(self.observation_names, self._robot.action_bounds)

    @property
    def life(self) -> int:
        """The length of a life, in actions."""
        return self._robot.life

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Starts a life. The world is that of an episode seed drawn from
        ``self.np_random`` (seeded by ``seed``), or of
        ``options["episode_seed"]`` (the world `Evaluator.evaluate`'s
        episode of that seed is placed in)."""
        super().reset(seed=seed)
        options = options or {}
        unknown = set(options) - {"episode_seed"}
        if unknown:
            raise ValueError(f"error: unknown reset options {sorted(unknown)} (known: 'episode_seed')")
        episode_seed = options.get("episode_seed")
        if episode_seed is None:
            episode_seed = int(self.np_random.integers(0, 2**63))
        obs = self._robot.reset(int(episode_seed))
        return obs, {"episode_seed": int(episode_seed)}

    def step(self, action: Any):
        a = _action(action, self.action_space.shape)
        return self._robot.step(a)

    def render(self):
        if self.render_mode != "rgb_array":
            gymnasium.logger.warn("render() needs render_mode='rgb_array'")
            return None
        return self._robot.render()


class ShapingVecEnv(VectorEnv):
    """``num_envs`` robots of a stage, stepped together in Rust on ``jobs``
    threads (None: one per core). Each robot starts a new life on the step
    after its life ended (Gymnasium's next-step autoreset): that step's
    action is ignored, its reward is 0."""

    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        path: str | os.PathLike[str] | Program,
        stage: str,
        num_envs: int,
        jobs: int | None = None,
    ) -> None:
        self.program = _program(path)
        self.stage = stage
        self._robots = VecStepper(self.program, stage, num_envs, jobs)
        probe = Stepper(self.program, stage)
        self.num_envs = self._robots.num_envs
        self.observation_names: list[str] = probe.observation_names
        self.action_names: list[str] = probe.action_names
        self.single_observation_space, self.single_action_space = _spaces(
            self.observation_names, probe.action_bounds
        )
        self.observation_space = gymnasium.vector.utils.batch_space(self.single_observation_space, self.num_envs)
        self.action_space = gymnasium.vector.utils.batch_space(self.single_action_space, self.num_envs)
        self.render_mode = None
        self._seeded = False

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Starts a life of every robot; robot i's worlds come from stream i
        of ``seed`` (or of a seed drawn from ``self.np_random``)."""
        if options:
            raise ValueError(f"error: make_vec's reset takes no options, not {sorted(options)}")
        if isinstance(seed, (list, tuple)):
            raise ValueError("error: make_vec's reset takes one seed (robot i takes stream i of it), not a list")
        if seed is not None or not self._seeded:
            self._worlds, _ = gymnasium.utils.seeding.np_random(seed)
            self._seeded = True
        world_seed = int(self._worlds.integers(0, 2**63))
        return self._robots.reset(world_seed), {}

    def step(self, actions: Any):
        a = _action(actions, self.action_space.shape)
        obs, rewards, terminated, truncated = self._robots.step(a)
        return obs, rewards, terminated, truncated, {}


class ShapingTeamVecEnv:
    """``num_envs`` worlds of a stage's team stepped together in Rust (see
    ``shaping.gym.make_parallel_vec``): arrays in and out, one row per
    world and robot, no Python per robot."""

    def __init__(self, program: Program, stage: str, num_envs: int, jobs: int | None = None) -> None:
        self.program = program
        self.stage = stage
        self._worlds = VecTeamStepper(program, stage, num_envs, jobs)
        probe = TeamStepper(program, stage)
        self.num_envs: int = self._worlds.num_envs
        self.agents: list[str] = self._worlds.agents
        self.observation_names: list[str] = probe.observation_names
        self.action_names: list[str] = probe.action_names
        low, high = (np.asarray(b, dtype=np.float32) for b in probe.action_bounds)
        self.single_observation_space = spaces.Box(0.0, 1.0, shape=(len(self.observation_names),), dtype=np.float32)
        self.single_action_space = spaces.Box(low, high, dtype=np.float32)
        self._seeds, _ = gymnasium.utils.seeding.np_random(None)

    def reset(self, seed: int | None = None):
        """Starts a life of every world; world w's worlds come from stream
        w of ``seed`` (or of a seed drawn from the environment's generator).
        Returns the observations, shape ``(num_envs, robots, observation)``, and ``{}``."""
        if seed is not None:
            self._seeds, _ = gymnasium.utils.seeding.np_random(seed)
        return self._worlds.reset(int(self._seeds.integers(0, 2**63))), {}

    def step(self, actions: Any):
        """``actions``: shape ``(num_envs, robots, action)``. Returns the
        observations, rewards, terminated, truncated (``(num_envs,
        robots)``) and ``{}``. A world whose team's life ended at the last
        step starts again instead (its actions ignored, rewards 0)."""
        a = _action(actions, (self.num_envs, len(self.agents), len(self.action_names)))
        obs, rewards, terminated, truncated = self._worlds.step(a)
        return obs, rewards, terminated, truncated, {}


def make(
    path: str | os.PathLike[str] | Program,
    stage: str,
    render_mode: str | None = None,
) -> ShapingEnv:
    """A Gymnasium environment of stage ``stage`` of the ``.bat`` file
    ``path`` (or of a compiled :class:`shaping.Program`)."""
    return ShapingEnv(path, stage, render_mode=render_mode)


def make_parallel(
    path: str | os.PathLike[str] | Program,
    stage: str,
    render_mode: str | None = None,
):
    """A PettingZoo parallel environment of the team of stage ``stage``
    (a world of ``robots N``): one agent per robot, named by its role and
    its index in the role (``guard_0``; ``robot_0`` ... without roles),
    each with the stage's observation and action spaces (every role has
    the robot's hardware), the whole team stepped in Rust in one call.

    An agent's reward is its robot's own fitness for the action (its role's
    terms and bonuses; its ``at end`` term when its life ends): a robot's
    rewards add up to its fitness in a run of the same episode, and the
    team's fitness is their ``team sum``, ``mean`` or ``min``. An agent is
    ``terminated`` when its battery is empty (its robot stays as an
    obstacle) and ``truncated`` at the stage's length of life; the others
    go on. ``render_mode="rgb_array"`` draws every robot and its path.
    A stage with one robot raises ShapingError: use :func:`make`.

    Needs ``pettingzoo`` (``pip install "shaping[pettingzoo]"``).
    """
    if importlib.util.find_spec("pettingzoo") is None:
        raise ImportError('shaping.gym.make_parallel needs pettingzoo, which is not installed: pip install "shaping[pettingzoo]"')
    from ._parallel import make as make_team

    return make_team(path, stage, render_mode=render_mode)


def make_parallel_vec(
    path: str | os.PathLike[str] | Program,
    stage: str,
    num_envs: int,
    jobs: int | None = None,
):
    """``num_envs`` worlds of the team of stage ``stage`` stepped together
    in Rust in one call on ``jobs`` threads, for batched training: arrays
    of one row per world and robot (observations ``(num_envs, robots,
    observation)``, actions ``(num_envs, robots, action)``, rewards and
    ends ``(num_envs, robots)``), each robot's as in :func:`make_parallel`.
    A world whose team's life ended starts a new one on the next step (its
    actions are ignored, its rewards 0); within a life, the row of a robot
    whose life ended is ignored. World w's worlds come from stream w of
    the seed. A stage with one robot raises ShapingError (use
    :func:`make_vec`)."""
    return ShapingTeamVecEnv(_program(path), stage, num_envs, jobs=jobs)


def make_vec(
    path: str | os.PathLike[str] | Program,
    stage: str,
    num_envs: int,
    jobs: int | None = None,
) -> ShapingVecEnv:
    """A Gymnasium vector environment of ``num_envs`` robots of stage
    ``stage``, stepped in Rust in one call on ``jobs`` threads."""
    return ShapingVecEnv(path, stage, num_envs, jobs=jobs)


if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="shaping.gym:ShapingEnv")
