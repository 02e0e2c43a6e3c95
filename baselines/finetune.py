"""Fine-tuning a distilled policy: PPO from its weights on the env's reward (``mdi-envs finetune``).

A distilled policy (``baselines.distill``) imitates its expert's labels; where the learner
leaves the states its expert visits, the labels it learned from are the expert's recovery
(on the robot the parking follower, far slower than the optimum). Fine-tuning trains the same
network with PPO on the task's own reward, from the distilled weights:

- the env is the distilled policy's (its record's ``env_kwargs``: the reference's time step),
  ``num_envs`` batched copies (``baselines.vec_env``) whose starts are perturbed at
  ``start_scale`` (``reset_noise_scale``), the elapsed time appended when the policy observes it
  (``baselines.vec_env.TimeAwareVecEnv``);
- the policy's log standard deviation is set to ``log_std`` (exploration about the distilled
  mean action), its optimizer is a fresh Adam (the saved one's moment estimates are the
  imitation's), and its value network, which the imitation never trained, is fitted first for
  ``value_warmup`` steps with every other weight frozen;
- then PPO (``learning_rate``, ``clip_range`` and ``target_kl`` small, so that the policy stays
  near the one it starts from) for ``timesteps`` steps;
- the deterministic policy plays ``validation`` starts (noise drawn log-uniformly in
  ``validation_scales``, reset seeds apart from the evaluations') before PPO and after every
  ``validate_every`` steps; the policy that succeeds most often, and among those arrives soonest
  (or spends least), is the one kept (the later one on a tie), as DAgger keeps its best round.
  PPO from a near-deterministic policy can lose what the imitation learned (the guide's
  fine-tuning section measures it on the robot); the policy kept is then an earlier one, at
  worst the distilled policy itself.

The result is written like every trained baseline (``baselines.train``: ``STEM.zip``,
``STEM.json``, ``STEM_curve.csv``, ``STEM.png``) with ``algo`` ``ALGO`` and
STEM = ``run_name(env_id, objective, ALGO, seed)``; its record's ``finetuning`` entry names the
distilled policy it started from. The zip holds the class it was saved from (``PPO`` or
``HybridPPO``) and loads with ``baselines.distill.DAgger.load``.
"""

from __future__ import annotations

import argparse
import copy
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from baselines.datasets import TASKS
from baselines.distill import ALGO as DISTILLED_ALGO
from baselines.distill import (
    DEFAULT_OUTPUT,
    DAgger,
    perturbed_starts,
    validation_cost,
    validation_rank,
)
from baselines.evaluation import OBJECTIVES, model_policy, play
from mdi_envs.provenance import git_commit

ALGO = "DAgger+PPO"
"""The ``algo`` of the records: the row label of the fine-tuned policies."""


@dataclass(frozen=True)
class FinetuneSettings:
    """The settings of one fine-tuning run (PPO's arguments as in SB3).

    Attributes:
        timesteps: PPO's environment steps after the value warm-up.
        value_warmup: steps that fit the value network alone, before ``timesteps``.
        start_scale: the starts' noise half-width ``reset_noise_scale`` [rad, rad/s, m, m/s].
        log_std: the policy's log standard deviation at the start (normalized actions).
        learning_rate, clip_range, target_kl, gamma, gae_lambda, n_epochs, batch_size: PPO's.
        num_envs: batched env copies; n_steps: steps per copy per update.
        validation: starts the policy plays at each validation; validation_scales: (low,
            high) of their noise half-width; validate_every: PPO steps between validations.
    """

    timesteps: int = 2_000_000
    value_warmup: int = 400_000
    start_scale: float = 0.05
    log_std: float = -2.0
    learning_rate: float = 3e-5
    clip_range: float = 0.1
    target_kl: float = 0.02
    gamma: float = 0.999
    gae_lambda: float = 0.95
    n_epochs: int = 10
    batch_size: int = 1024
    num_envs: int = 64
    n_steps: int = 128
    validation: int = 20
    validation_scales: tuple[float, float] = (0.01, 0.1)
    validate_every: int = 250_000

    def __post_init__(self) -> None:
        for name in ("timesteps", "n_epochs", "batch_size", "num_envs", "n_steps", "validation",
                     "validate_every"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if self.value_warmup < 0 or self.start_scale <= 0.0 or self.learning_rate <= 0.0:
            raise ValueError(f"need value_warmup >= 0, start_scale > 0 and learning_rate > 0, "
                             f"got {self.value_warmup}, {self.start_scale}, {self.learning_rate}")
        low, high = self.validation_scales
        if not 0.0 < low <= high:
            raise ValueError(f"validation_scales must be (low, high) with 0 < low <= high, "
                             f"got {self.validation_scales}")
        if not 0.0 < self.gamma <= 1.0 or not 0.0 <= self.gae_lambda <= 1.0:
            raise ValueError(f"gamma must be in (0, 1] and gae_lambda in [0, 1], "
                             f"got {self.gamma} and {self.gae_lambda}")

    def ppo_arguments(self) -> dict[str, Any]:
        """The PPO attributes a loaded model takes (SB3's ``load`` keyword arguments)."""
        return {"learning_rate": self.learning_rate, "clip_range": self.clip_range,
                "target_kl": self.target_kl, "gamma": self.gamma, "gae_lambda": self.gae_lambda,
                "n_epochs": self.n_epochs, "batch_size": self.batch_size,
                "n_steps": self.n_steps, "ent_coef": 0.0}  # fmt: skip


@dataclass(frozen=True)
class Finetuning:
    """The ``finetuning`` entry of a fine-tuned policy's ``STEM.json``.

    Attributes:
        distilled: the stem of the distilled policy it started from; distilled_commit: the
            commit that policy was trained at. settings: ``FinetuneSettings`` as a dict.
        validated_at: PPO steps at each validation (0: the distilled policy).
        validation_success, validation_cost: its success rate and mean time [s] or effort
            over the successes (None: none). kept_at: the steps of the policy kept.
    """

    distilled: str
    distilled_commit: str | None
    settings: dict[str, Any]
    validated_at: list[int]
    validation_success: list[float]
    validation_cost: list[float | None]
    kept_at: int


def value_parameters_only(policy: Any, frozen: bool) -> None:
    """Freeze (``frozen``) or release every parameter of ``policy`` outside its value network."""
    for name, parameter in policy.named_parameters():
        if "value_net" not in name:
            parameter.requires_grad_(not frozen)


def finetune(distilled: Path, settings: FinetuneSettings = FinetuneSettings(),
             output: Path = DEFAULT_OUTPUT, eval_episodes: int = 10,
             log_line: Callable[[str], None] | None = None) -> Path:
    """Fine-tune the distilled policy of ``distilled`` (its ``STEM.json``); the new zip's path.

    ``log_line`` receives a line per validation.

    The run's seed is the distilled policy's (torch, and copy i's starts from seed + i).

    Raises:
        ValueError: ``distilled`` is not a distilled policy's record.
    """
    import torch
    from stable_baselines3.common.vec_env import VecMonitor

    from baselines.plots import plot_training
    from baselines.train import (
        EpisodeLog,
        TrainingRecord,
        evaluate,
        read_training,
        recent_episodes,
        run_name,
        versions,
        write_logs,
        write_record,
    )
    from baselines.vec_env import TimeAwareVecEnv, make_vec_env

    distilled = Path(distilled)
    source = read_training(distilled)
    if source.algo != DISTILLED_ALGO:
        raise ValueError(f"{distilled} is a {source.algo} record, not a distilled "
                         f"({DISTILLED_ALGO}) policy's")
    torch.set_num_threads(1)
    observe_time = bool(source.algo_kwargs.get("observe_time", False))
    env_kwargs = dict(source.env_kwargs)
    venv: Any = VecMonitor(make_vec_env(source.env_id, settings.num_envs, **env_kwargs,
                                        reset_noise_scale=settings.start_scale))
    if observe_time:
        venv = TimeAwareVecEnv(venv, int(env_kwargs["max_episode_steps"]))
    model = DAgger.load(distilled.with_suffix(".zip"), env=venv, **settings.ppo_arguments())
    model.set_random_seed(source.seed)
    venv.seed(source.seed)
    # a fresh Adam: the saved one holds the imitation's moment estimates
    model.policy.optimizer = model.policy.optimizer_class(
        model.policy.parameters(), lr=settings.learning_rate, **model.policy.optimizer_kwargs)
    if hasattr(model.policy, "log_std"):
        with torch.no_grad():
            model.policy.log_std.fill_(settings.log_std)
    log = EpisodeLog()
    starts = perturbed_starts(np.random.default_rng(source.seed), settings.validation,
                              settings.validation_scales)
    validated_at: list[int] = []
    success: list[float] = []
    costs: list[float | None] = []
    best: dict[str, Any] = {}

    def validate(steps: int) -> None:
        episodes = [play(source.env_id, model_policy(model, observe_time), reset_seed,
                         **{**env_kwargs, "reset_noise_scale": scale})
                    for scale, reset_seed in starts]  # fmt: skip
        validated_at.append(steps)
        success.append(float(np.mean([episode.is_success for episode in episodes])))
        costs.append(validation_cost(episodes, source.objective))
        rank = validation_rank(success[-1], costs[-1])
        if not best or rank <= validation_rank(success[best["index"]], costs[best["index"]]):
            best.update(index=len(success) - 1, state=copy.deepcopy(model.policy.state_dict()))
        if log_line is not None:
            log_line(f"{steps} steps: validation success {success[-1]:.2f}, cost {costs[-1]}")

    start = time.perf_counter()
    validate(0)
    if settings.value_warmup:
        value_parameters_only(model.policy, frozen=True)
        model.learn(settings.value_warmup, callback=log)
        value_parameters_only(model.policy, frozen=False)
    done = 0
    while done < settings.timesteps:
        chunk = min(settings.validate_every, settings.timesteps - done)
        model.learn(chunk, callback=log, reset_num_timesteps=False)
        done += chunk
        validate(done)
    model.policy.load_state_dict(best["state"])
    wall_time = time.perf_counter() - start
    venv.close()

    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    stem = run_name(source.env_id, source.objective, ALGO, source.seed)
    model.save(output / f"{stem}.zip")
    evaluation = evaluate(model, source.env_id, env_kwargs, eval_episodes, source.seed + 10_000,
                          observe_time)  # fmt: skip
    write_logs(log.rows, output / f"{stem}_episodes.csv", output / f"{stem}_curve.csv")
    budget = settings.value_warmup + settings.timesteps
    record = TrainingRecord(
        env_id=source.env_id, objective=source.objective, algo=ALGO, seed=source.seed,
        num_envs=settings.num_envs, total_timesteps=budget, num_timesteps=int(model.num_timesteps),
        algo_kwargs={**settings.ppo_arguments(), "observe_time": observe_time},
        algo_overrides={}, env_kwargs=env_kwargs, policy="MlpPolicy", device="cpu",
        torch_threads=torch.get_num_threads(), wall_time_s=wall_time, num_episodes=len(log.rows),
        train_last100=recent_episodes(log.rows),
        evaluation=evaluation, versions=versions(), commit=git_commit(),
        date=time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        command=f"mdi-envs finetune {source.env_id} --seeds {source.seed} --timesteps "
                f"{settings.timesteps} --value-warmup {settings.value_warmup} --start-scale "
                f"{settings.start_scale} --learning-rate {settings.learning_rate}")  # fmt: skip
    entry = Finetuning(distilled.stem, source.commit, asdict(settings), validated_at, success,
                       costs, validated_at[best["index"]])
    write_record(output / f"{stem}.json", record, finetuning=entry)
    plot_training(log.rows, output / f"{stem}.png",
                  title=f"{stem} (PPO from {distilled.stem}, {settings.num_envs} envs)")
    return output / f"{stem}.zip"


def add_finetune_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``finetune`` subcommand to an argparse subparsers object; returns its parser."""
    defaults = FinetuneSettings()
    parser = subparsers.add_parser(
        "finetune", help="fine-tune distilled policies with PPO on the env's reward",
        description="PPO from the weights of the distilled policies STEM_dagger_seedN in "
                    "--distilled; writes STEM_dagger+ppo_seedN.{zip,json,png} and the training "
                    "curve into --output. A seed whose JSON exists is skipped.")
    parser.add_argument("env_id", choices=TASKS, help="the task")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0], help="default: 0")
    parser.add_argument("--timesteps", type=int, default=defaults.timesteps,
                        help="PPO's steps after the value warm-up (default: %(default)s)")
    parser.add_argument("--value-warmup", type=int, default=defaults.value_warmup,
                        help="steps fitting the value network alone (default: %(default)s)")
    parser.add_argument("--start-scale", type=float, default=defaults.start_scale,
                        help="the starts' reset_noise_scale (default: %(default)s)")
    parser.add_argument("--learning-rate", type=float, default=defaults.learning_rate,
                        help="default: %(default)s")
    parser.add_argument("--distilled", type=Path, default=DEFAULT_OUTPUT,
                        help="the distilled policies' folder (default: the shipped ones)")
    parser.add_argument("--output", type=Path, default=DEFAULT_OUTPUT)
    parser.set_defaults(handler=run_finetune)
    return parser


def run_finetune(args: argparse.Namespace) -> int:
    """Handler of ``finetune``: one run per seed not yet in ``--output``."""
    from baselines.train import run_name

    objective = OBJECTIVES[args.env_id][0]
    try:
        settings = FinetuneSettings(timesteps=args.timesteps, value_warmup=args.value_warmup,
                                    start_scale=args.start_scale,
                                    learning_rate=args.learning_rate)
        for seed in args.seeds:
            stem = run_name(args.env_id, objective, ALGO, seed)
            if (args.output / f"{stem}.json").exists():
                print(f"{stem}: already in {args.output}")
                continue
            name = run_name(args.env_id, objective, DISTILLED_ALGO, seed)
            source = args.distilled / f"{name}.json"
            if not source.exists():
                raise ValueError(f"no distilled policy {source}")
            path = finetune(source, settings, args.output,
                            log_line=lambda line, s=seed: print(f"seed {s}: {line}", flush=True))
            print(path, flush=True)
    except ValueError as error:
        raise SystemExit(f"finetune: {error}") from error
    return 0


__all__ = ["ALGO", "FinetuneSettings", "Finetuning", "add_finetune_parser", "finetune",
           "value_parameters_only"]
