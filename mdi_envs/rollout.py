"""Play one episode of a registered environment under a policy, recording what a user inspects.

Policies: ``"random"`` (the action space's sampler), an open-loop action file (``.npy`` or
``.csv``, one normalised action per row), or any callable ``obs -> action`` (e.g. a trained
SB3 model's ``predict``). ``mdi-envs simulate`` is the command-line face of ``rollout``.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import mdi_envs  # noqa: F401 - registers the ids

Policy = Callable[[Any], Any]


@dataclass
class Rollout:
    """One episode.

    Attributes:
        env_id: the environment. num_steps: env steps taken. total_reward: their sum.
        terminated, truncated: how it ended. last_info: the last step's ``info``.
        frames: rgb_array frames (H, W, 3) uint8 if recorded (the reset frame first).
        q: (num_steps + 1, n) coordinates along the episode.
        infos: the ``info`` dict of every step (num_steps entries).
    """

    env_id: str
    num_steps: int = 0
    total_reward: float = 0.0
    terminated: bool = False
    truncated: bool = False
    last_info: dict[str, Any] = field(default_factory=dict)
    frames: list[np.ndarray] = field(default_factory=list)
    q: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    infos: list[dict[str, Any]] = field(default_factory=list)


def open_loop_policy(actions: np.ndarray) -> Policy:
    """A policy replaying ``actions`` (num_steps, a) row by row, then repeating the last row."""
    if actions.ndim != 2 or len(actions) == 0:
        raise ValueError(f"open-loop actions must be a non-empty 2-D array, got {actions.shape}")
    step = iter(range(len(actions)))

    def policy(_obs: Any) -> Any:
        return actions[min(next(step, len(actions) - 1), len(actions) - 1)]

    return policy


def load_actions(path: Path) -> np.ndarray:
    """Open-loop actions from ``.npy`` or ``.csv`` (comma-separated, one action per row)."""
    if path.suffix == ".npy":
        actions = np.load(path)
    elif path.suffix == ".csv":
        actions = np.loadtxt(path, delimiter=",", ndmin=2)
    else:
        raise ValueError(f"action files are .npy or .csv, got {path.name!r}")
    return np.asarray(actions, dtype=np.float32).reshape(len(actions), -1)


def _sampler(space: gym.Space[Any]) -> Policy:
    """The random policy: a sample of ``space`` whatever the observation."""

    def act(_obs: Any) -> Any:
        return space.sample()

    return act


def rollout(
    env_id: str,
    policy: Policy | str = "random",
    seed: int = 0,
    max_steps: int | None = None,
    record: bool = False,
    render_mode: str | None = None,
    **env_kwargs: Any,
) -> Rollout:
    """Run one episode of ``gym.make(env_id, **env_kwargs)`` from ``reset(seed=seed)``.

    Args:
        policy: "random" or a callable obs -> action.
        max_steps: stop after this many steps (default: when the episode ends).
        record: keep an rgb_array frame per step in ``Rollout.frames``.
        render_mode: "human" opens a window (``record`` then is not possible).
    """
    if record and render_mode == "human":
        raise ValueError("record=True draws rgb_array frames; it cannot be combined with human")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make(env_id, render_mode="rgb_array" if record else render_mode, **env_kwargs)
    env.action_space.seed(seed)
    act: Policy
    if policy == "random":
        act = _sampler(env.action_space)
    elif callable(policy):
        act = policy
    else:
        raise ValueError(f"policy must be 'random' or a callable, got {policy!r}")
    obs, _ = env.reset(seed=seed)
    result = Rollout(env_id)
    model: Any = env.unwrapped  # a MoreauJeanEnv
    coordinates = [model.q]
    if record:
        result.frames.append(np.asarray(env.render()))
    while max_steps is None or result.num_steps < max_steps:
        obs, reward, terminated, truncated, info = env.step(act(obs))
        result.num_steps += 1
        result.total_reward += float(reward)
        result.last_info = info
        result.infos.append(info)
        coordinates.append(model.q)
        if record:
            result.frames.append(np.asarray(env.render()))
        if terminated or truncated:
            result.terminated, result.truncated = bool(terminated), bool(truncated)
            break
    env.close()
    result.q = np.array(coordinates)
    return result


__all__ = ["Policy", "Rollout", "load_actions", "open_loop_policy", "rollout"]
