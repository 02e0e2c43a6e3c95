"""The one table of baseline settings, keyed by (env id, task, algorithm).

Each entry holds the SB3 constructor arguments, the number of batched copies, the training
budget, the seed and the environment arguments. Algorithms: SB3's PPO and SAC on the default
flattened Box action spaces, and ``HybridPPO`` (``baselines.hybrid_ppo``: PPO with a categorical
brake x Gaussian torque policy) on the manipulator's native ``action_mode="hybrid"`` space
``Tuple(Discrete(2), Box(-1, 1, (1,)))``. Choices shared by every entry:

- ``gamma = 0.99`` for every algorithm. The env's shaping term is
  ``shaping_discount * Phi(s') - Phi(s)`` with Phi = -distance; every entry sets
  ``shaping_discount = 1.0`` (``SHAPING_DISCOUNT``) except the manipulator's PPO, shipped with
  0.99 = gamma. With 1.0 the shaping telescopes to Phi(s_T) - Phi(s_0) per episode, so the
  episodic (undiscounted) objective is unchanged; with gamma < 1 it pays (1 - gamma) * distance
  per step for standing still, and the gamma-shaped HybridPPO and robot "time" runs settled
  there (0 % success at 5 x 10^6 steps) where the same settings with 1.0 reached 100 %.
- Diff drive "effort" PPO: ``goal_weight = 1000`` (the weight of the distance at the
  horizon's end) with ``normalize_reward`` (SB3's ``VecNormalize`` on the rewards only, during
  training; the policy never sees them). Without normalization, 5 x 10^6 steps: the env's
  default 10 stopped ~0.3 m short using 0.43 of the optimum's effort; 100 stopped 0.06-0.07 m
  short (effort 1.27x); 300 and 1000 ended 2.1 and 1.7 m away, their returns (down to -10^4)
  swamping the value function: 0 % success each (tolerance 0.05 m). SAC: ``goal_weight`` 100.
- PPO with many copies (64): the batched env steps them in one compiled call, so a rollout of
  64 x 256 = 16384 steps costs about as much as a few hundred single-env steps; minibatches
  of 2048, 10 epochs, GAE lambda 0.95, clip 0.2, no entropy bonus, 2 x 64 tanh MLPs (SB3's
  defaults otherwise, as in rl-zoo's continuous-control settings).
- HybridPPO: exactly the PPO settings (no per-algorithm tuning), only the action space differs.
- SAC with 64 copies and 4 gradient steps per 64 transitions (replay ratio 1/16, far below
  SAC's usual 1): a gradient step costs ~12-25 ms on this CPU whatever the width (overhead-
  bound), so the usual ratio would give ~40 transitions/s; 10^6 buffer, batch 256, 2 x 256 ReLU
  MLPs, automatic entropy tuning, 10^4 random warm-up steps.
- Budgets, the ones of the shipped policies (``baselines/trained``): PPO 10^7 steps on the
  manipulator, 4 x 10^6 on diff drive "time", 5 x 10^6 on "effort", HybridPPO 5 x 10^6,
  SAC 10^6 (what fitted one session on the 2-core machine: PPO runs at about 3-15 k steps/s
  there, SAC at 400-800). Episodes: manipulator up to 500 steps of 0.02 s, the optimum
  takes about 228; diff drive "time" up to 200 steps of 0.05 s, "effort" exactly 81.
  Untuned starting points: the shipped results say how far they get.
- Seed 0 everywhere; ``train(..., seed=...)`` overrides it.
"""

from __future__ import annotations

import copy
from typing import Any

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
DIFF_DRIVE = "mdi_envs/DiffDriveRobot-v0"
ALGORITHMS = ("PPO", "SAC", "HybridPPO")
"""The algorithm names, canonical spelling (lookups are case-insensitive)."""
ALGORITHM_CLASSES = {
    "PPO": "stable_baselines3:PPO",
    "SAC": "stable_baselines3:SAC",
    "HybridPPO": "baselines.hybrid_ppo:HybridPPO",
}
"""Algorithm name -> "module:class" of its SB3-compatible class (imported on use, see
``baselines.train.algorithm_class``; this module imports no SB3)."""

_PPO: dict[str, Any] = {
    "num_envs": 64,
    "seed": 0,
    "algo_kwargs": {
        "n_steps": 256, "batch_size": 2048, "n_epochs": 10, "learning_rate": 3e-4,
        "gamma": 0.99, "gae_lambda": 0.95, "clip_range": 0.2, "ent_coef": 0.0,
        "max_grad_norm": 0.5,
        "policy_kwargs": {"net_arch": {"pi": [64, 64], "vf": [64, 64]}},
    },
}
_SAC: dict[str, Any] = {
    "num_envs": 64,
    "seed": 0,
    "algo_kwargs": {
        "buffer_size": 1_000_000, "batch_size": 256, "learning_rate": 3e-4, "gamma": 0.99,
        "tau": 0.005, "learning_starts": 10_000, "train_freq": 1, "gradient_steps": 4,
        "ent_coef": "auto", "policy_kwargs": {"net_arch": [256, 256]},
    },
}


SHAPING_DISCOUNT = 1.0
"""The env's ``shaping_discount`` in every entry that does not set its own."""


def _entry(base: dict[str, Any], env_kwargs: dict[str, Any], total_timesteps: int,
           normalize_reward: bool = False) -> dict[str, Any]:
    return {**copy.deepcopy(base), "total_timesteps": total_timesteps,
            "env_kwargs": {"shaping_discount": SHAPING_DISCOUNT, **env_kwargs},
            "normalize_reward": normalize_reward}  # fmt: skip


HYPERPARAMETERS: dict[tuple[str, str, str], dict[str, Any]] = {
    (MANIPULATOR, "time", "PPO"): _entry(_PPO, {"shaping_discount": 0.99}, 10_000_000),
    (MANIPULATOR, "time", "SAC"): _entry(_SAC, {}, 1_000_000),
    (MANIPULATOR, "time", "HybridPPO"): _entry(_PPO, {"action_mode": "hybrid"}, 5_000_000),
    (DIFF_DRIVE, "time", "PPO"): _entry(_PPO, {"task": "time"}, 4_000_000),
    (DIFF_DRIVE, "time", "SAC"): _entry(_SAC, {"task": "time"}, 1_000_000),
    (DIFF_DRIVE, "effort", "PPO"): _entry(_PPO, {"task": "effort", "goal_weight": 1000.0},
                                          5_000_000, normalize_reward=True),
    (DIFF_DRIVE, "effort", "SAC"): _entry(_SAC, {"task": "effort", "goal_weight": 100.0},
                                          1_000_000),
}
"""(env id, task, algorithm) -> {"num_envs", "total_timesteps", "seed", "algo_kwargs" (SB3
constructor arguments), "env_kwargs" (``gym.make`` arguments), "normalize_reward" (train on
rewards scaled by ``VecNormalize``)}."""

DEFAULT_TASKS = {MANIPULATOR: "time", DIFF_DRIVE: "time"}
"""The task used when none is given (the manipulator has only "time")."""


def canonical_algorithm(name: str) -> str:
    """The ``ALGORITHMS`` spelling of ``name`` ("ppo" -> "PPO", "hybridppo" -> "HybridPPO").

    An unknown name is returned unchanged (the caller's lookup then reports it).
    """
    return {algo.lower(): algo for algo in ALGORITHMS}.get(name.lower(), name)


def get_hyperparameters(env_id: str, algo: str, task: str | None = None) -> dict[str, Any]:
    """A deep copy of the table entry.

    Args:
        env_id: ``mdi_envs/BlockableManipulator-v0`` or ``mdi_envs/DiffDriveRobot-v0``.
        algo: "PPO", "SAC" or "HybridPPO" (case-insensitive; HybridPPO: manipulator only).
        task: "time" or "effort" (diff drive only); default ``DEFAULT_TASKS[env_id]``.

    Raises:
        KeyError: no entry for this combination (the message lists the known keys).
    """
    task = DEFAULT_TASKS.get(env_id) if task is None else task
    key = (env_id, str(task), canonical_algorithm(algo))
    if key not in HYPERPARAMETERS:
        known = ", ".join(" ".join(k) for k in HYPERPARAMETERS)
        raise KeyError(f"no hyperparameters for {' '.join(map(str, key))}; known: {known}")
    return copy.deepcopy(HYPERPARAMETERS[key])


__all__ = [
    "ALGORITHMS", "ALGORITHM_CLASSES", "DEFAULT_TASKS", "HYPERPARAMETERS", "SHAPING_DISCOUNT",
    "canonical_algorithm",
    "get_hyperparameters",
]
