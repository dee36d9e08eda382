"""PettingZoo's parallel environment of a stage's team (``shaping.gym.make_parallel``)."""

from __future__ import annotations

import os
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from pettingzoo import ParallelEnv  # type: ignore[import-untyped]

from ._shaping import Program, TeamStepper

__all__ = ["ShapingParallelEnv"]


class ShapingParallelEnv(ParallelEnv):
    """A stage's team, one agent per robot (see ``shaping.gym.make_parallel``)."""

    metadata: dict[str, Any] = {
        "render_modes": ["rgb_array"],
        "render_fps": 10,
        "name": "shaping_team_v0",
        "is_parallelizable": True,
    }

    def __init__(self, program: Program, stage: str, render_mode: str | None = None) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"error: render_mode must be None or 'rgb_array', not {render_mode!r}")
        self.program = program
        self.stage = stage
        self.render_mode = render_mode
        self._team = TeamStepper(program, stage, keep_path=render_mode == "rgb_array")
        self.possible_agents: list[str] = self._team.agents
        self.agents: list[str] = []
        self.observation_names: list[str] = self._team.observation_names
        self.action_names: list[str] = self._team.action_names
        low, high = (np.asarray(b, dtype=np.float32) for b in self._team.action_bounds)
        width = len(self.observation_names)
        # One space object per agent, the same at every call (PettingZoo's API test checks it).
        self.observation_spaces = {
            a: spaces.Box(0.0, 1.0, shape=(width,), dtype=np.float32) for a in self.possible_agents
        }
        self.action_spaces = {a: spaces.Box(low, high, dtype=np.float32) for a in self.possible_agents}
        self._index = {a: i for i, a in enumerate(self.possible_agents)}
        self._actions = np.zeros((len(self.possible_agents), len(self.action_names)), dtype=np.float32)
        self._worlds, _ = seeding.np_random(None)

    def observation_space(self, agent: str) -> spaces.Box:
        return self.observation_spaces[agent]

    def action_space(self, agent: str) -> spaces.Box:
        return self.action_spaces[agent]

    @property
    def life(self) -> int:
        """The length of a life, in actions."""
        return self._team.life

    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None):
        """Starts a life of the team. The world is that of an episode seed
        drawn from the environment's generator (seeded by ``seed``), or of
        ``options["episode_seed"]`` (the world a run's episode of that seed
        places the team in); other options are ignored."""
        if seed is not None:
            self._worlds, _ = seeding.np_random(seed)
        episode_seed = (options or {}).get("episode_seed")
        if episode_seed is None:
            episode_seed = int(self._worlds.integers(0, 2**63))
        obs = self._team.reset(int(episode_seed))
        self.agents = list(self.possible_agents)
        observations = {a: obs[i] for i, a in enumerate(self.agents)}
        infos: dict[str, dict[str, Any]] = {a: {"episode_seed": int(episode_seed)} for a in self.agents}
        return observations, infos

    def step(self, actions: dict[str, Any]):
        """Runs one action of every live agent (``actions`` has one for
        each, and no other); the team is stepped in Rust in one call. Agents
        whose life ended leave ``agents``."""
        if not self.agents:
            raise ValueError("error: every agent's life has ended (or not started): reset before the next step")
        unknown = [a for a in actions if a not in self.agents]
        if unknown:
            raise ValueError(f"error: actions for {unknown}, which are not live agents (live: {self.agents})")
        missing = [a for a in self.agents if a not in actions]
        if missing:
            raise ValueError(f"error: no action for the live agents {missing}")
        self._actions.fill(0.0)
        shape = (len(self.action_names),)
        for agent, action in actions.items():
            a = np.asarray(action, dtype=np.float32)
            if a.shape != shape:
                raise ValueError(f"error: the action of `{agent}` must be an array of shape {shape}, not {a.shape}")
            self._actions[self._index[agent]] = a
        obs, rewards, terminated, truncated, info = self._team.step(self._actions)
        live = self.agents
        pose, battery = info["pose"], info["battery"]
        observations = {a: obs[self._index[a]] for a in live}
        rew = {a: float(rewards[self._index[a]]) for a in live}
        term = {a: bool(terminated[self._index[a]]) for a in live}
        trunc = {a: bool(truncated[self._index[a]]) for a in live}
        infos = {
            a: {
                "x": float(pose[self._index[a], 0]),
                "y": float(pose[self._index[a], 1]),
                "heading": float(pose[self._index[a], 2]),
                "battery": float(battery[self._index[a]]),
            }
            for a in live
        }
        self.agents = [a for a in live if not (term[a] or trunc[a])]
        return observations, rew, term, trunc, infos

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        return self._team.render()

    def close(self) -> None:
        pass


def _program(path: str | os.PathLike[str] | Program) -> Program:
    from . import compile

    return path if isinstance(path, Program) else compile(path)


def make(path: str | os.PathLike[str] | Program, stage: str, render_mode: str | None = None) -> ShapingParallelEnv:
    return ShapingParallelEnv(_program(path), stage, render_mode=render_mode)
