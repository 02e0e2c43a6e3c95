"""PPO training throughput: the batched adapter vs SB3's DummyVecEnv and SubprocVecEnv.

``python -m benchmarks.vec_env_throughput`` trains the shipped PPO settings for ``--rollouts``
rollouts through each vector env and writes ``vec_env_throughput.json`` and ``.png``: set-up,
steps per second, rollout and update time. Needs the ``rl`` extra.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from functools import partial
from pathlib import Path
from typing import Any

from benchmarks import report
from benchmarks.timing import arguments, timed_call

BACKENDS = ("batched adapter", "DummyVecEnv", "SubprocVecEnv")
"""The vector envs compared, in the order they run."""


def make_backend(backend: str, env_id: str, num_envs: int, env_kwargs: dict[str, Any]) -> Any:
    """An SB3 ``VecEnv`` of ``num_envs`` copies of ``env_id`` through ``backend``."""
    from stable_baselines3.common.env_util import make_vec_env as sb3_make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecMonitor

    from baselines.vec_env import make_vec_env

    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; known: {', '.join(BACKENDS)}")
    if backend == "batched adapter":
        return VecMonitor(make_vec_env(env_id, num_envs, **env_kwargs))
    subproc = backend == "SubprocVecEnv"
    return sb3_make_vec_env(env_id, num_envs, seed=0, env_kwargs=env_kwargs,
                            vec_env_cls=SubprocVecEnv if subproc else DummyVecEnv,
                            vec_env_kwargs={"start_method": "fork"} if subproc else None)


def measure(backend: str, env_id: str, num_envs: int, rollouts: int) -> dict[str, Any]:
    """Train PPO for ``rollouts`` rollouts through ``backend``; times [s] and steps per second."""
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import VecNormalize

    from baselines.hyperparameters import get_hyperparameters

    class RolloutTimer(BaseCallback):
        rollout_s, _start = 0.0, 0.0  # [s] rollouts' total, the current one's start

        def _on_rollout_start(self) -> None:
            self._start = time.perf_counter()

        def _on_rollout_end(self) -> None:
            self.rollout_s += time.perf_counter() - self._start

        def _on_step(self) -> bool:
            return True

    torch.set_num_threads(1)
    entry = get_hyperparameters(env_id, "PPO")
    start = time.perf_counter()
    venv = make_backend(backend, env_id, num_envs, entry["env_kwargs"])
    if entry["normalize_reward"]:
        venv = VecNormalize(venv, norm_obs=False, norm_reward=True,
                            gamma=entry["algo_kwargs"]["gamma"])  # fmt: skip
    setup_s = time.perf_counter() - start
    model = PPO("MlpPolicy", venv, seed=0, device="cpu", **entry["algo_kwargs"])
    timer = RolloutTimer()
    _, train_s = timed_call(partial(model.learn, rollouts * model.n_steps * num_envs,
                                    callback=timer))
    venv.close()
    timesteps = int(model.num_timesteps)
    return {"backend": backend, "setup_s": setup_s, "train_s": train_s, "timesteps": timesteps,
            "train_steps_per_s": timesteps / train_s, "rollout_s": timer.rollout_s,
            "rollout_steps_per_s": timesteps / timer.rollout_s,
            "update_s": train_s - timer.rollout_s}  # fmt: skip


def plot(record: dict[str, Any], path: Path) -> None:
    """Bars: training and rollout steps per second per vector env."""
    results, config = record["results"], record["config"]
    fig, ax = report.plt.subplots(figsize=(8, 3.4))
    report.bars(ax, [r["backend"] for r in results], {
        "training (rollouts + updates)": [r["train_steps_per_s"] for r in results],
        "rollout collection only": [r["rollout_steps_per_s"] for r in results]},
        f"environment steps / s: PPO on {config['env_id'].split('/')[-1]}, "
        f"{config['num_envs']} copies, {results[0]['timesteps']:,} steps each", log=False)
    report.save_figure(fig, path, dpi=110)


def main(argv: Sequence[str] | None = None) -> int:
    """Measure every backend, write the JSON and PNG, print the table; returns 0."""
    args = arguments(__doc__, argv, ("--env-id", {"default": "mdi_envs/BlockableManipulator-v0"}),
                     ("--num-envs", {"type": int, "default": 64}),
                     ("--rollouts", {"type": int, "default": 20, "help": "PPO rollouts each"}),
                     ("--backends", {"nargs": "+", "choices": BACKENDS,
                                     "default": list(BACKENDS)}), quick=False)
    config = {"env_id": args.env_id, "num_envs": args.num_envs, "rollouts": args.rollouts,
              "command": " ".join(["python -m benchmarks.vec_env_throughput",
                                   *(argv if argv is not None else sys.argv[1:])])}
    with report.study("vec_env_throughput", args.output, config) as (record, say, _):
        record["results"] = []
        for backend in args.backends:
            say(f"{backend}: {args.num_envs} copies, {args.rollouts} PPO rollouts")
            result = measure(backend, args.env_id, args.num_envs, args.rollouts)
            say(f"{backend}: {result['train_steps_per_s']:,.0f} steps/s")
            record["results"].append(result)
        plot(record, args.output / "vec_env_throughput.png")
    print(report.flat_table(record["results"], ["backend", "setup_s", "train_steps_per_s",
                                                "rollout_steps_per_s", "update_s"]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
