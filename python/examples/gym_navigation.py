"""Policies on the Gymnasium environment of navigation: a random one, and a
linear policy trained by the cross-entropy method on `make_vec`.

    pip install gymnasium
    python python/examples/gym_navigation.py [--seed 1] [--iterations 100]

The environment's reward is the stage's fitness per action, so a life's
return is the fitness a run gives an architecture's life in the same world
(navigation: straight, fast motion away from obstacles, 1 for a perfect
life of 300 actions; a battery of 200 actions that only the charger
refills). The linear policy maps the 17 sensor readings to the two wheels
(tanh) and to `charge` (a step at 0); the cross-entropy method keeps the
best 8 of 64 candidate weight sets each iteration, each candidate scored
by its mean return over 4 lives (256 robots stepped together in Rust, one
life each). The return of the random policy and of the final mean policy
are measured on 200 fresh lives.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import shaping.gym

KHEPERA = Path(__file__).resolve().parents[2] / "examples" / "khepera.bat"
STAGE = "navigation"
CANDIDATES, LIVES, ELITE = 64, 4, 8


def returns(envs, policy, seed: int) -> np.ndarray:
    """The return of the first life of each robot; `policy(obs)` gives
    the actions of every robot."""
    obs, _ = envs.reset(seed=seed)
    total = np.zeros(envs.num_envs)
    alive = np.ones(envs.num_envs, dtype=bool)
    while alive.any():
        obs, reward, terminated, truncated, _ = envs.step(policy(obs))
        total += np.where(alive, reward, 0.0)
        alive &= ~(terminated | truncated)
    return total


def linear(weights: np.ndarray):
    """Actions of a linear policy per robot: `weights` of shape (robots, 18, 3)."""

    def act(obs: np.ndarray) -> np.ndarray:
        x = np.concatenate([obs, np.ones((len(obs), 1), np.float32)], axis=1)
        y = np.einsum("ri,rio->ro", x, weights)
        return np.concatenate([np.tanh(y[:, :2]), (y[:, 2:] > 0)], axis=1).astype(np.float32)

    return act


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--iterations", type=int, default=100)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    test = shaping.gym.make_vec(KHEPERA, STAGE, num_envs=200)
    space = test.single_action_space

    def random_policy(obs):
        return rng.uniform(space.low, space.high, size=(len(obs), 3)).astype(np.float32)

    r = returns(test, random_policy, seed=10_000 + args.seed)
    print(f"random policy: return {r.mean():.3f} +- {r.std():.3f} over 200 lives")

    envs = shaping.gym.make_vec(KHEPERA, STAGE, num_envs=CANDIDATES * LIVES)
    mean, sd = np.zeros((18, 3)), np.ones((18, 3))
    start = time.perf_counter()
    for it in range(args.iterations):
        w = mean + sd * rng.standard_normal((CANDIDATES, 18, 3))
        r = returns(envs, linear(np.repeat(w, LIVES, axis=0)), seed=args.seed * 1000 + it)
        score = r.reshape(CANDIDATES, LIVES).mean(axis=1)
        elite = w[np.argsort(score)[-ELITE:]]
        mean, sd = elite.mean(axis=0), elite.std(axis=0) + 0.02
        if it % 10 == 9 or it == args.iterations - 1:
            print(f"iteration {it + 1}: best candidate {score.max():.3f}, mean of candidates {score.mean():.3f}", flush=True)
    secs = time.perf_counter() - start
    r = returns(test, linear(np.repeat(mean[None], 200, axis=0)), seed=10_000 + args.seed)
    print(f"linear policy (cross-entropy, {args.iterations} iterations, {secs:.0f} s): return {r.mean():.3f} +- {r.std():.3f} over 200 lives")


if __name__ == "__main__":
    main()
