"""RLlib PPO on the mission envs under their registered ids (the ``rllib`` extra).

RLlib creates each env inside its ``EnvRunner`` actors, fresh Ray worker processes that never
imported ``mdi_envs``: with the bare id ``gym.make("mdi_envs/...")`` raises ``NamespaceNotFound``
there, and RLlib reports only an ``IndexError`` in the driver. Two ways work:

- ``register_env(env_id)`` here: ``ray.tune.registry.register_env`` under the *same* id
  string, with a creator that imports ``mdi_envs`` in the worker and calls
  ``gym.make(env_id, **env_config)``; then ``PPOConfig().environment(env_id, env_config=...)``
  takes the id unchanged. ``ppo_config`` does it.
- Gymnasium's ``module:id`` form, ``"mdi_envs:mdi_envs/BlockableManipulator-v0"``, which makes
  ``gym.make`` import ``mdi_envs`` first, in any process.

``check_env_id`` turns an unknown id into a ``ValueError`` naming the known ids and both forms,
before RLlib's ``IndexError`` could hide it. ``ppo_config`` translates the shipped PPO entry
(``baselines/hyperparams/ppo.yml``) to RLlib: gamma, GAE lambda, clip, learning rate, epochs,
minibatch, rollout of ``n_steps x n_envs`` per iteration, gradient clipping, no entropy bonus,
2 x 64 tanh networks (policy and value separate), no KL penalty (SB3 has none), the env
arguments as ``env_config`` and ``n_envs`` copies per env runner (RLlib's own
``gym.make_vec``, not the batched adapter). Not translated: the "effort" entry's reward
normalization (SB3's ``VecNormalize``), so RLlib on that objective trains on the raw rewards.

``python -m baselines.rllib mdi_envs/BlockableManipulator-v0 --iterations 1`` trains (locally,
or on a cluster with ``--address``) and prints each iteration's return and steps.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable, Sequence
from typing import Any

import gymnasium as gym

import mdi_envs  # noqa: F401 - registers the ids in this process

ENV_FORMS = ('register_env(env_id) (baselines.rllib.register_env, then the id unchanged) '
             'or the module:id form "mdi_envs:mdi_envs/BlockableManipulator-v0"')  # fmt: skip
"""The two ways an mdi_envs id reaches RLlib's worker processes (for error messages)."""


def check_env_id(env_id: str) -> None:
    """Raise a clear ``ValueError`` if ``env_id`` is not a registered Gymnasium id.

    Raises:
        ValueError: unknown id; the message lists the ``mdi_envs`` ids and ``ENV_FORMS``.
    """
    if env_id.partition(":")[2] or env_id in gym.registry:
        return
    known = ", ".join(sorted(k for k in gym.registry if k.startswith("mdi_envs/")))
    raise ValueError(f"{env_id!r} is not a registered env id (known: {known}); RLlib would "
                     f"fail inside its workers with an IndexError. Use {ENV_FORMS}.")  # fmt: skip


def env_creator(env_id: str) -> Callable[[Any], gym.Env[Any, Any]]:
    """A Ray env creator: ``env_config -> gym.make(env_id, **env_config)``, run in any worker."""

    def create(env_config: Any) -> gym.Env[Any, Any]:
        import mdi_envs  # noqa: F401, F811 - registers the ids in the worker process

        return gym.make(env_id, **dict(env_config or {}))

    return create


def register_env(env_id: str) -> str:
    """Register ``env_id`` in Ray Tune's registry under the same name; returns the name.

    Raises:
        ValueError: unknown id (``check_env_id``).
    """
    from ray.tune.registry import register_env as ray_register_env

    check_env_id(env_id)
    ray_register_env(env_id, env_creator(env_id))
    return env_id


def ppo_config(env_id: str, objective: str | None = None, *, num_env_runners: int = 0,
               num_envs_per_env_runner: int | None = None,
               train_batch_size: int | None = None, minibatch_size: int | None = None,
               num_epochs: int | None = None) -> Any:  # fmt: skip
    """RLlib's ``PPOConfig`` for ``env_id`` with the shipped PPO settings (``env_id`` registered).

    Args:
        env_id: a mission env id. objective: "time" or "effort" (diff drive), as ``mdi-envs train``.
        num_env_runners: remote env-runner actors (0: sample in the driver's process).
        num_envs_per_env_runner, train_batch_size, minibatch_size, num_epochs: overrides of the
            entry's copies, steps per iteration, minibatch and epochs (tests shrink them).

    Returns:
        A ``ray.rllib.algorithms.ppo.PPOConfig``; ``.build_algo()`` makes the algorithm.
    """
    from ray.rllib.algorithms.ppo import PPOConfig

    from baselines.hyperparameters import get_hyperparameters, parse_schedule

    entry = get_hyperparameters(env_id, "PPO", objective)
    sb3 = entry["algo_kwargs"]
    lr, decays = parse_schedule("learning_rate", sb3["learning_rate"])
    schedule = [[0, lr], [entry["total_timesteps"], 0.0]] if decays else lr  # RLlib's piecewise
    copies = entry["num_envs"] if num_envs_per_env_runner is None else num_envs_per_env_runner
    batch = sb3["n_steps"] * entry["num_envs"] if train_batch_size is None else train_batch_size
    return (
        PPOConfig()
        .environment(register_env(env_id), env_config=entry["env_kwargs"])
        .env_runners(num_env_runners=num_env_runners, num_envs_per_env_runner=copies)
        .training(gamma=sb3["gamma"], lambda_=sb3["gae_lambda"], clip_param=sb3["clip_range"],
                  lr=schedule, entropy_coeff=sb3["ent_coef"],
                  grad_clip=sb3["max_grad_norm"], use_kl_loss=False,
                  train_batch_size_per_learner=batch,
                  minibatch_size=sb3["batch_size"] if minibatch_size is None else minibatch_size,
                  num_epochs=sb3["n_epochs"] if num_epochs is None else num_epochs)
        .rl_module(model_config={"fcnet_hiddens": list(sb3["policy_kwargs"]["net_arch"]["pi"]),
                                 "fcnet_activation": "tanh", "vf_share_layers": False})
    )  # fmt: skip


def train_rllib(config: Any, iterations: int, log: Callable[[str], None] | None = None
                ) -> list[dict[str, Any]]:  # fmt: skip
    """Build the algorithm from ``config``, run ``iterations`` of ``train()``, stop it.

    Returns:
        Per iteration {"iteration", "env_steps" (lifetime), "episode_return_mean" (None before
        the first finished episode), "time_s"} (Ray must be initialised).
    """
    algo = config.build_algo()
    rows = []
    try:
        for iteration in range(1, iterations + 1):
            start = time.perf_counter()
            result = algo.train()
            runners = result.get("env_runners", {})
            rows.append({"iteration": iteration,
                         "env_steps": runners.get("num_env_steps_sampled_lifetime"),
                         "episode_return_mean": runners.get("episode_return_mean"),
                         "time_s": time.perf_counter() - start})  # fmt: skip
            if log:
                log(f"iteration {iteration}: {rows[-1]}")
    finally:
        algo.stop()
    return rows


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m baselines.rllib ENV_ID``: RLlib PPO for ``--iterations``; returns 0."""
    import ray

    parser = argparse.ArgumentParser(prog="python -m baselines.rllib",
                                     description=__doc__.split("\n")[0])  # fmt: skip
    parser.add_argument("env_id", help="a mission env id, e.g. mdi_envs/BlockableManipulator-v0")
    parser.add_argument("--objective", choices=("time", "effort"), default=None)
    parser.add_argument("--iterations", type=int, default=1)
    parser.add_argument("--num-env-runners", type=int, default=0)
    parser.add_argument("--address", default=None,
                        help="an existing Ray cluster (default: a local one on this machine)")
    args = parser.parse_args(argv)
    check_env_id(args.env_id)
    ray.init(address=args.address, include_dashboard=False)
    try:
        train_rllib(ppo_config(args.env_id, args.objective, num_env_runners=args.num_env_runners),
                    args.iterations, log=print)  # fmt: skip
    finally:
        ray.shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


__all__ = ["ENV_FORMS", "check_env_id", "env_creator", "ppo_config", "register_env",
           "train_rllib"]  # fmt: skip
