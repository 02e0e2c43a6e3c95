"""Train one SB3 baseline and save it next to its exact config, episode log and curves.

``train("mdi_envs/DiffDriveRobot-v0", "PPO", objective="effort", output=Path("results/baselines"))``
checks the single env (Gymnasium's and SB3's ``check_env``), builds the batched env through the
``MoreauJeanVecEnv`` adapter wrapped in ``VecMonitor`` (and, for entries with
``normalize_reward``, in ``VecNormalize`` on the rewards only), trains with the table's settings
(``baselines.hyperparameters``), logs to TensorBoard, evaluates the deterministic policy with
``evaluate_policy`` on ``gym.make`` copies, and writes into ``output``:

- ``STEM.zip``: the SB3 model (``PPO.load``/``SAC.load``/``HybridPPO.load``, the class from
  ``algorithm_class(config["algo"])``);
- ``STEM.json``: env id, objective, algorithm, seed, the exact SB3 and env arguments, budget,
  package versions, git commit, wall time, training and evaluation scores;
- ``STEM_episodes.csv``: one row per finished training episode (timesteps, return, length,
  success, elapsed time [s], effort [N^2 m^2 s]); large, kept local;
- ``STEM_curve.csv``: the compact training curve shipped with a policy (``write_logs``: the
  success rate over the last 100 episodes at 200 steps), from which the seed plots draw their
  bands;
- ``STEM.png``: episode return and success rate vs environment steps;
- ``tensorboard/STEM_1/``: SB3's TensorBoard logs (``tensorboard --logdir OUTPUT/tensorboard``);

with STEM = ``{env name}_{objective}_{algo}_seed{seed}``, e.g.
``DiffDriveRobot-v0_effort_ppo_seed0``.

The algorithm names and their classes are in ``baselines.hyperparameters`` (``ALGORITHMS``,
``ALGORITHM_CLASSES``): SB3's PPO and SAC, sb3-contrib's TQC and CrossQ, and ``HybridPPO``
(``baselines.hybrid_ppo``) on the manipulator's hybrid action space.
"""

from __future__ import annotations

import copy
import importlib
import json
import platform
import sys
import time
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

import mdi_envs
from baselines.hyperparameters import (
    ALGORITHM_CLASSES,
    canonical_algorithm,
    get_hyperparameters,
    parse_schedule,
)
from mdi_envs.provenance import git_commit

EPISODE_COLUMNS = ("timesteps", "return", "length", "is_success", "elapsed_time", "effort")
"""Columns of ``STEM_episodes.csv`` (steps, -, steps, bool, s, N^2 m^2 s)."""


class EpisodeLog(BaseCallback):
    """Record every finished training episode from the ``VecMonitor`` infos.

    Attributes:
        rows: one tuple per episode, in ``EPISODE_COLUMNS`` order.
    """

    def __init__(self) -> None:
        super().__init__()
        self.rows: list[tuple[int, float, int, bool, float, float]] = []

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            episode = info.get("episode")
            if episode is not None:
                self.rows.append((int(self.num_timesteps), float(episode["r"]),
                                  int(episode["l"]), bool(info.get("is_success", False)),
                                  float(info.get("elapsed_time", np.nan)),
                                  float(info.get("effort", np.nan))))  # fmt: skip
        return True


@dataclass(frozen=True)
class PolicyEvaluation:
    """Deterministic episodes of a trained policy on ``gym.make`` (SB3's ``evaluate_policy``).

    Attributes:
        episodes: how many (0: none played, the scores None).
        seed: the first reset seed.
        mean_return: over the episodes, with std_return its standard deviation.
        mean_length: [steps].
        success_rate: fraction of the episodes ended at the goal.
        mean_elapsed_time: [s].
        mean_effort: [N^2 m^2 s].
    """

    episodes: int
    seed: int
    mean_return: float | None = None
    std_return: float | None = None
    mean_length: float | None = None
    success_rate: float | None = None
    mean_elapsed_time: float | None = None
    mean_effort: float | None = None


@dataclass(frozen=True)
class RecentEpisodes:
    """Mean return and success rate of the last 100 training episodes (None: no episode)."""

    mean_return: float | None
    success_rate: float | None


@dataclass(frozen=True)
class TrainingRecord:
    """A trained run's ``STEM.json``: its exact settings, provenance and scores.

    Attributes:
        env_id, objective, algo, seed: the run. num_envs: batched copies. total_timesteps:
        the budget; num_timesteps: the steps SB3 took. normalize_reward: rewards scaled by
        ``VecNormalize`` in training. algo_kwargs: the SB3 arguments (algo_overrides: those
        replacing the table's). env_kwargs: the ``gym.make`` arguments. policy, device,
        torch_threads: as trained. wall_time_s [s]. num_episodes: training episodes.
        train_last100: the last 100 of them. evaluation: after training. versions: of the
        packages. commit: the git commit trained at. date. command: the CLI equivalent.
    """

    env_id: str
    objective: str
    algo: str
    seed: int
    num_envs: int
    total_timesteps: int
    num_timesteps: int
    algo_kwargs: dict[str, Any]
    algo_overrides: dict[str, Any]
    env_kwargs: dict[str, Any]
    policy: str
    device: str
    torch_threads: int
    wall_time_s: float
    num_episodes: int
    train_last100: RecentEpisodes
    evaluation: PolicyEvaluation
    versions: dict[str, str]
    commit: str | None
    date: str
    command: str
    normalize_reward: bool = False


def recent_episodes(rows: list[tuple[Any, ...]]) -> RecentEpisodes:
    """``RecentEpisodes`` of the last 100 of ``EpisodeLog.rows`` (``EPISODE_COLUMNS`` order)."""
    recent = rows[-100:]
    if not recent:
        return RecentEpisodes(None, None)
    return RecentEpisodes(float(np.mean([r[1] for r in recent])),
                          float(np.mean([r[3] for r in recent])))  # fmt: skip


def write_record(path: Path, record: TrainingRecord, **entries: Any) -> None:
    """Write ``record`` as the JSON ``path``, with dataclass ``entries`` beside its fields.

    E.g. ``write_record(path, record, distillation=Distillation(...))``.
    """
    data = {**asdict(record), **{name: asdict(entry) for name, entry in entries.items()}}
    Path(path).write_text(json.dumps(data, indent=2, default=str) + "\n")


def read_training(path: Path) -> TrainingRecord:
    """The ``TrainingRecord`` of a ``STEM.json`` (pydantic's ``ValidationError`` if malformed)."""
    from baselines.records import from_json

    return from_json(TrainingRecord, json.loads(Path(path).read_text()))


def run_name(env_id: str, objective: str, algo: str, seed: int) -> str:
    """The file stem of a run, e.g. ``BlockableManipulator-v0_time_ppo_seed0``."""
    return f"{env_id.split('/')[-1]}_{objective}_{algo.lower()}_seed{seed}"


SCHEDULED = ("learning_rate", "clip_range", "clip_range_vf")
"""The SB3 arguments that may be an rl-zoo3 schedule string."""


def with_schedules(algo_kwargs: dict[str, Any]) -> dict[str, Any]:
    """``algo_kwargs`` with rl-zoo3's schedule strings made SB3 schedules, as rl-zoo3 reads them.

    ``"lin_X"`` (``baselines.hyperparameters.parse_schedule``) becomes
    ``stable_baselines3.common.utils.LinearSchedule(X, 0, 1)``: X at the start of training, 0 at
    its end. Numbers stay as they are.
    """
    from stable_baselines3.common.utils import LinearSchedule

    resolved = dict(algo_kwargs)
    for key in SCHEDULED:
        if isinstance(resolved.get(key), str):
            start, _ = parse_schedule(key, resolved[key])
            resolved[key] = LinearSchedule(start, 0.0, 1.0)
    return resolved


def algorithm_class(algo: str) -> Any:
    """The SB3-compatible class of an algorithm name (case-insensitive), imported on use.

    Raises:
        KeyError: unknown name (the message lists ``ALGORITHM_CLASSES``).
    """
    name = canonical_algorithm(algo)
    if name not in ALGORITHM_CLASSES:
        raise KeyError(f"unknown algorithm {algo!r}; known: {', '.join(ALGORITHM_CLASSES)}")
    module, _, attribute = ALGORITHM_CLASSES[name].partition(":")
    return getattr(importlib.import_module(module), attribute)


def load_trained(algo: str, path: str | Path) -> Any:
    """A saved model of ``algo`` from ``path`` (``.zip``) on the CPU, for prediction.

    SB3 2.9 warns on loading an n-step off-policy model that ``n_steps`` "is ignored because a
    custom replay_buffer_class (NStepReplayBuffer) was passed": the class it sees is the one it
    chose itself at training time, and the saved ``replay_buffer_kwargs`` already carry
    ``n_steps`` and ``gamma``, so the loaded buffer does compute n-step returns. That false
    alarm alone is silenced; every other warning passes.
    """
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"`n_steps=\d+` is ignored because a custom "
                                r"`replay_buffer_class` \(`NStepReplayBuffer`\)")
        return algorithm_class(algo).load(path, device="cpu")


def check_single_env(env_id: str, env_kwargs: dict[str, Any]) -> None:
    """Gymnasium's and SB3's ``check_env`` on ``gym.make(env_id, **env_kwargs)``.

    SB3's checker is skipped for a Tuple action space (``action_mode="hybrid"``): SB3 does not
    support one (its NaN check cannot even batch a Tuple sample); ``HybridPPO`` adapts it.

    Raises:
        AssertionError: the env breaks the API (raised by the checkers).
    """
    from gymnasium.utils.env_checker import check_env as gym_check_env
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make(env_id, **env_kwargs)
        gym_check_env(env.unwrapped, skip_render_check=True)
        if not isinstance(env.action_space, gym.spaces.Tuple):
            sb3_check_env(env, warn=False)
    env.close()


def train(
    env_id: str,
    algo: str,
    objective: str | None = None,
    seed: int | None = None,
    total_timesteps: int | None = None,
    output: Path = Path("results/baselines"),
    *,
    num_envs: int | None = None,
    algo_overrides: dict[str, Any] | None = None,
    eval_episodes: int = 10,
    progress_bar: bool | None = None,
    verbose: int = 0,
    torch_threads: int = 1,
) -> Path:
    """Train ``algo`` on ``env_id`` with the table's settings; returns the model's zip path.

    Args:
        env_id: ``mdi_envs/BlockableManipulator-v0`` or ``mdi_envs/DiffDriveRobot-v0``.
        algo: "PPO", "SAC" or "HybridPPO" (case-insensitive; ``ALGORITHMS``).
        objective: "time" or "effort" (diff drive); default the env's "time".
        seed: the run's seed (SB3's ``seed``: torch, the action noise and env copy i's
            start states from seed + i); default the table's.
        total_timesteps: environment steps to train (summed over copies); default the table's.
        output: folder for the files listed in the module docstring (created).
        num_envs: number of batched copies; default the table's.
        algo_overrides: SB3 arguments replacing the table's (tests use tiny networks).
        eval_episodes: deterministic evaluation episodes on ``gym.make`` after training.
        progress_bar: SB3's progress bar (tqdm + rich); default when stderr is a terminal.
        verbose: SB3's verbosity.
        torch_threads: torch's intra-op threads for the run. One by default: the networks are
            tiny (64-256 units), so more threads only add synchronisation, and on a busy
            2-core machine two threads made a PPO run about 20x slower.
    """
    import torch
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from baselines.vec_env import make_vec_env

    torch.set_num_threads(int(torch_threads))
    entry = get_hyperparameters(env_id, algo, objective)
    algo = canonical_algorithm(algo)
    objective = entry["env_kwargs"].get("objective", "time")
    seed = entry["seed"] if seed is None else int(seed)
    total_timesteps = entry["total_timesteps"] if total_timesteps is None else total_timesteps
    num_envs = entry["num_envs"] if num_envs is None else int(num_envs)
    algo_kwargs = {**entry["algo_kwargs"], **(algo_overrides or {})}
    env_kwargs = entry["env_kwargs"]
    if progress_bar is None:
        progress_bar = sys.stderr.isatty()
    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    stem = run_name(env_id, objective, algo, seed)

    check_single_env(env_id, env_kwargs)
    venv = VecMonitor(make_vec_env(env_id, num_envs, **env_kwargs))
    if entry["normalize_reward"]:  # training only: the policy never sees the scaled rewards
        venv = VecNormalize(venv, norm_obs=False, norm_reward=True, gamma=algo_kwargs["gamma"])
    model_class = algorithm_class(algo)
    model = model_class("MlpPolicy", venv, seed=seed, device="cpu", verbose=verbose,
                        tensorboard_log=str(output / "tensorboard"),
                        **with_schedules(copy.deepcopy(algo_kwargs)))  # fmt: skip
    log = EpisodeLog()
    start = time.perf_counter()
    model.learn(total_timesteps=total_timesteps, callback=log, tb_log_name=stem,
                progress_bar=progress_bar)  # fmt: skip
    wall_time = time.perf_counter() - start
    model_path = output / f"{stem}.zip"
    model.save(model_path)
    venv.close()

    evaluation = evaluate(model, env_id, env_kwargs, eval_episodes, seed=seed + 10_000)
    write_logs(log.rows, output / f"{stem}_episodes.csv", output / f"{stem}_curve.csv")
    record = TrainingRecord(
        env_id=env_id, objective=objective, algo=algo, seed=seed, num_envs=num_envs,
        total_timesteps=total_timesteps, num_timesteps=int(model.num_timesteps),
        algo_kwargs=algo_kwargs, algo_overrides=algo_overrides or {}, env_kwargs=env_kwargs,
        policy="MlpPolicy", device="cpu", torch_threads=torch.get_num_threads(),
        wall_time_s=wall_time, num_episodes=len(log.rows),
        train_last100=recent_episodes(log.rows),
        evaluation=evaluation, versions=versions(), commit=git_commit(),
        date=time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        command=f"mdi-envs train {env_id} {algo} --objective {objective} --seed {seed} "
                f"--timesteps {total_timesteps} --num-envs {num_envs}"
                + (" (plus algo_overrides)" if algo_overrides else ""),
        normalize_reward=entry["normalize_reward"])  # fmt: skip
    write_record(output / f"{stem}.json", record)
    from baselines.plots import plot_training

    plot_training(log.rows, output / f"{stem}.png", title=f"{stem} ({algo}, {num_envs} envs)")
    return model_path


def evaluate(model: Any, env_id: str, env_kwargs: dict[str, Any], episodes: int,
             seed: int, observe_time: bool = False) -> PolicyEvaluation:  # fmt: skip
    """SB3's ``evaluate_policy`` (deterministic) on ``gym.make`` from ``reset(seed=seed)``.

    ``observe_time``: the model sees the elapsed time (``baselines.time_input.time_aware``).
    """
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.monitor import Monitor

    from baselines.time_input import time_aware

    if episodes <= 0:
        return PolicyEvaluation(episodes, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make(env_id, **env_kwargs)
        env = Monitor(time_aware(env) if observe_time else env)
    env.reset(seed=seed)
    finals: list[dict[str, Any]] = []

    def record(local_vars: dict[str, Any], _: dict[str, Any]) -> None:
        if local_vars["done"]:
            finals.append(local_vars["info"])

    returns, lengths = evaluate_policy(model, env, n_eval_episodes=episodes, deterministic=True,
                                       return_episode_rewards=True, callback=record)  # fmt: skip
    env.close()
    return PolicyEvaluation(
        episodes, seed, float(np.mean(returns)), float(np.std(returns)), float(np.mean(lengths)),
        float(np.mean([bool(i.get("is_success")) for i in finals])),
        float(np.mean([i.get("elapsed_time", np.nan) for i in finals])),
        float(np.mean([i.get("effort", np.nan) for i in finals])))


def write_logs(rows: list[tuple[Any, ...]], episodes_path: Path, curve_path: Path) -> None:
    """Write the episode log (``EPISODE_COLUMNS``) and its compact training curve as CSV.

    The curve (``baselines.aggregate.sampled_curve``): timesteps, success_rate (moving mean
    over the last 100 episodes) at 200 steps.
    """
    import pandas as pd

    from baselines.aggregate import sampled_curve

    episodes = pd.DataFrame(rows, columns=list(EPISODE_COLUMNS))
    episodes.to_csv(episodes_path, index=False)
    steps, rates = sampled_curve(episodes["timesteps"].to_numpy(float),
                                 episodes["is_success"].to_numpy(float))
    pd.DataFrame({"timesteps": steps.astype(int), "success_rate": rates}).to_csv(
        curve_path, index=False, float_format="%.4f")


def versions() -> dict[str, str]:
    """Versions of Python and the packages a run depends on."""
    import stable_baselines3
    import torch

    return {"python": platform.python_version(), "mdi_envs": mdi_envs.__version__,
            "stable_baselines3": stable_baselines3.__version__, "torch": torch.__version__,
            "gymnasium": gym.__version__, "numpy": np.__version__}  # fmt: skip


__all__ = [
    "EpisodeLog", "PolicyEvaluation", "RecentEpisodes", "TrainingRecord", "algorithm_class",
    "check_single_env", "evaluate", "load_trained", "read_training", "recent_episodes",
    "run_name", "train", "with_schedules", "write_logs", "write_record",
]
