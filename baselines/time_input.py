"""Policies that see the episode's elapsed time: Gymnasium's ``TimeAwareObservation`` input.

A network that imitates a time-indexed controller (an MPC that tracks the reference at its step
counter) needs that counter as an input. Such a policy takes the observation of
``gymnasium.wrappers.TimeAwareObservation(env, normalize_time=True)``: the env's observation
with ``steps / max_episode_steps`` in [0, 1] appended, ``steps`` the actions taken since the
reset. ``with_time`` builds that input from a policy's call count, so the policy plays in the
unwrapped env like every other row.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.wrappers import TimeAwareObservation


def time_aware(env: gym.Env[Any, Any]) -> gym.Env[Any, Any]:
    """``env`` wrapped so that its observations carry the normalized elapsed time."""
    return TimeAwareObservation(env, normalize_time=True)


def max_steps(env: gym.Env[Any, Any]) -> int:
    """The episode's step limit (``env.spec.max_episode_steps``).

    Raises:
        ValueError: ``env`` has no step limit (the elapsed time cannot be normalized).
    """
    if env.spec is None or env.spec.max_episode_steps is None:
        raise ValueError("a time-aware policy needs an env with max_episode_steps")
    return int(env.spec.max_episode_steps)


def with_time(observation: Any, steps: int, limit: int) -> np.ndarray:
    """``observation`` (d,) with ``steps / limit`` appended: (d + 1,) float32."""
    return np.append(np.asarray(observation, dtype=np.float32), np.float32(steps / limit))


def counting_policy(act: Callable[[np.ndarray], Any], env: gym.Env[Any, Any]
                    ) -> Callable[[Any], Any]:  # fmt: skip
    """A policy of one episode of ``env`` from its reset: ``act`` on the time-aware input.

    The n-th call (n = 0, 1, ...) passes ``with_time(observation, n, max_steps(env))`` to ``act``.
    """
    limit = max_steps(env)
    steps = 0

    def policy(observation: Any) -> Any:
        nonlocal steps
        action = act(with_time(observation, steps, limit))
        steps += 1
        return action

    return policy


__all__ = ["counting_policy", "max_steps", "time_aware", "with_time"]
