"""Expert trajectories of the optimal-control tasks as Minari datasets (Farama's offline-RL format).

One dataset per task (a v1 env id) and expert: the optimal reference played open loop from the
nominal start (``"optimal"``, one episode: it is open loop), or a model-based controller around
that reference (``baselines.model_based.EXPERTS``: ``"lqr"``, the time-varying LQR;
``"tracking"``, the tracking MPC; ``"mpc"``, the shrinking-horizon MPC) from ``num_episodes``
starts drawn with ``reset(seed=first_seed + k)`` at the start noise ``scale``. Each expert plays
in its own env configuration (one env step per transcription interval of the reference), which
the dataset records as its env spec, so ``dataset.recover_environment()`` rebuilds exactly the
env the data came from. Episodes end at the goal (``terminations``) or at the step limit
(``truncations``); observations, actions and rewards are the env's own.

Dataset ids: ``mdi_envs/<Task>/<expert>-v0``, e.g. ``mdi_envs/BlockableManipulator/lqr-v0``. They
are written under ``MINARI_DATASETS_PATH`` (Minari's default ``~/.minari/datasets``; ``--root``
sets it) and read back with ``minari.load_dataset(dataset_id)``.

``mdi-envs dataset ENV_ID --expert lqr --episodes 100 --scale 0.1`` builds one.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium as gym

from baselines.evaluation import (
    DIFF_DRIVE_EFFORT_V1,
    DIFF_DRIVE_V1,
    MANIPULATOR_V1,
    OBJECTIVES,
    Controller,
    optimal_controller,
)
from baselines.model_based import EXPERTS
from mdi_envs.provenance import git_commit

TASKS = (MANIPULATOR_V1, DIFF_DRIVE_V1, DIFF_DRIVE_EFFORT_V1)
"""The v1 env ids a dataset can be built for (one objective each)."""

DATASET_EXPERTS: dict[str, Callable[[str, str], Controller | None]] = {
    "optimal": optimal_controller, **EXPERTS,
}  # fmt: skip
"""The reference open loop and the feedback experts (``baselines.model_based.EXPERTS``)."""


def dataset_id(env_id: str, expert: str, version: int = 0) -> str:
    """``mdi_envs/<Task>/<expert>-v<version>``, e.g. ``mdi_envs/DiffDriveRobot/lqr-v0``."""
    task = env_id.split("/")[-1].rsplit("-v", 1)[0]
    return f"mdi_envs/{task}/{expert}-v{version}"


def build_dataset(env_id: str, expert: str = "lqr", num_episodes: int = 100, scale: float = 0.1,
                  first_seed: int = 0, dataset: str | None = None) -> Any:  # fmt: skip
    """Play the expert and write its episodes as a Minari dataset; returns the ``MinariDataset``.

    Args:
        env_id: one of ``TASKS``.
        expert: one of ``DATASET_EXPERTS``; ``"optimal"`` plays one episode from
            the nominal start.
        num_episodes: episodes from perturbed starts (``reset(seed=first_seed + k)``).
        scale: the start noise half-width ``reset_noise_scale`` [rad, rad/s, m, m/s].
        first_seed: the first reset seed.
        dataset: the dataset id (default ``dataset_id(env_id, expert)``).

    Raises:
        ValueError: an unknown task or expert, no episodes, or an expert that is not available
            (the MPCs need CasADi).
    """
    import minari

    if env_id not in TASKS:
        raise ValueError(f"no dataset task {env_id!r}; known: {', '.join(TASKS)}")
    if expert not in DATASET_EXPERTS:
        raise ValueError(f"unknown expert {expert!r}; known: {', '.join(DATASET_EXPERTS)}")
    if num_episodes < 1:
        raise ValueError(f"num_episodes must be >= 1, got {num_episodes}")
    controller = DATASET_EXPERTS[expert](env_id, OBJECTIVES[env_id][0])
    if controller is None:
        raise ValueError(f"expert {expert!r} is not available here (the MPCs need CasADi)")
    if expert == "optimal":
        num_episodes, scale = 1, 0.0
    kwargs = {**controller.env_kwargs, "reset_noise_scale": scale}
    env = minari.DataCollector(gym.make(env_id, **kwargs))
    for episode in range(num_episodes):
        policy = controller.make_policy(gym.make(env_id, **kwargs))
        observation, _ = env.reset(seed=first_seed + episode)
        done = False
        while not done:
            observation, _, terminated, truncated, _ = env.step(policy(observation))
            done = terminated or truncated
    description = (f"{controller.label} on {env_id} ({kwargs}), {num_episodes} episodes from "
                   f"reset seeds {first_seed}-{first_seed + num_episodes - 1}.")  # fmt: skip
    result = env.create_dataset(
        dataset_id=dataset or dataset_id(env_id, expert), eval_env=gym.make(env_id, **kwargs),
        algorithm_name=controller.label, author="mdi-envs", description=description,
        code_permalink=f"baselines/datasets.py at commit {git_commit()}",
        num_episodes_average_score=10)  # fmt: skip
    env.close()
    return result


def add_dataset_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``dataset`` subcommand to an argparse subparsers object; returns its parser."""
    parser = subparsers.add_parser(
        "dataset", help="write an expert's trajectories as a Minari dataset",
        description=__doc__.split("\n\n")[1].replace("\n", " "))  # fmt: skip
    parser.add_argument("env_id", choices=TASKS, help="the task")
    parser.add_argument("--expert", choices=list(DATASET_EXPERTS), default="lqr",
                        help="default: lqr")
    parser.add_argument("--episodes", type=int, default=100, help="perturbed starts")
    parser.add_argument("--scale", type=float, default=0.1, help="start noise half-width")
    parser.add_argument("--first-seed", type=int, default=0, help="the first reset seed")
    parser.add_argument("--root", type=Path, default=None,
                        help="the datasets' folder (sets MINARI_DATASETS_PATH)")
    parser.set_defaults(handler=run_dataset)
    return parser


def run_dataset(args: argparse.Namespace) -> int:
    """Handler of ``dataset``: builds it and prints its id, size and where it is."""
    if args.root is not None:
        os.environ["MINARI_DATASETS_PATH"] = str(args.root.resolve())
    try:
        result = build_dataset(args.env_id, args.expert, args.episodes, args.scale,
                               args.first_seed)  # fmt: skip
    except ValueError as error:
        raise SystemExit(f"dataset: {error}") from error
    print(f"{result.spec.dataset_id}: {result.total_episodes} episodes, {result.total_steps} "
          f"steps, in {result.spec.data_path}")
    return 0


__all__ = ["DATASET_EXPERTS", "TASKS", "add_dataset_parser", "build_dataset", "dataset_id"]
