"""Distilled policies: DAgger with a model-based controller as the expert (``mdi-envs distill``).

DAgger (S. Ross, G. Gordon, D. Bagnell, "A Reduction of Imitation Learning and Structured
Prediction to No-Regret Online Learning", AISTATS 2011) trains a network to act as an expert
controller of ``baselines.model_based`` (``EXPERTS``) on a v1 task, in the expert's own env
configuration (one env step per transcription interval of the reference):

- round 0, behaviour cloning: the expert plays from the nominal start (the optimal reference's
  states, labelled with the reference's controls) and from ``episodes`` perturbed starts;
- rounds 1 ... ``rounds``: episodes from new perturbed starts are played by the mixture that
  takes the expert's action with probability beta_i = ``beta_decay`` ** i at each step and the
  learner's otherwise; every visited state is labelled with the expert's action (the expert is
  called at every step, so its step counter follows the episode, and told the learner's
  torques when they are played, so a friction estimate follows the robot), added to the data,
  and the learner is trained further on all of it (``gradient_steps`` Adam steps on random
  minibatches, the learning rate decaying from ``learning_rate`` to a tenth in each round).

With ``expert_noise`` sigma > 0 the expert's actions are played with Gaussian noise of standard
deviation sigma (a fraction of the action bound) added to their continuous components and
clipped to the bound, while the labels stay the expert's own: DART (M. Laskey, J. Lee, R. Fox,
A. Dragan, K. Goldberg, "DART: Noise Injection for Robust Imitation Learning", CoRL 2017), which
visits the states around the expert's own episodes from which it corrects.

After each round the learner plays ``validation`` perturbed starts alone (the same starts every
round); the round whose learner succeeds most often, and among those the one with the lowest mean
cost (time or effort) over its successes (the later one on a tie), is the policy returned:
Ross et al.'s choice of the best policy on validation, in the tables' order (success, then the
ratio).

Perturbed starts draw the start noise half-width ``reset_noise_scale`` log-uniformly in
``DAggerSettings.start_scales`` [rad, rad/s, m, m/s] (the validation starts in
``validation_scales`` if given) and reset seeds from
``FIRST_TRAINING_SEED`` on, apart from the evaluation's seeds 0, 1, ....

The learner is an SB3 policy: ``PPO``'s ``ActorCriticPolicy`` on the robots' Box actions,
``HybridPPO``'s policy on the manipulator with ``action_mode="hybrid"``, so the brake is a
discrete choice (the expert's Box action ``[torque, brake]`` becomes the choice
``brake > 0`` with the same torque: ``expert_label``), its inputs standardized by the mean and
deviation of round 0's data (``Standardized``). The loss is the negative log-likelihood of
the expert's actions (``policy.evaluate_actions``), minimised by the policy's own optimizer. The
model is saved with SB3's ``save`` as ``STEM.zip`` beside a ``STEM.json`` ``TrainingRecord``
(algo ``"DAgger"``) whose ``distillation`` entry (``Distillation``) holds the expert and its label
budget, so ``baselines.evaluation.load_policy`` and ``mdi-envs compare --trained FOLDER`` play it
as a trained row; ``DAgger.load`` reads the zip with the class it was saved from.

The field's library, ``imitation`` (BC and DAgger on SB3 policies), does not install beside this
project: its latest release (1.0.1) pins stable-baselines3 ~2.2.1 and gymnasium 0.29.

The labelled episodes can also be written as a Minari dataset (``write_labels``, ``--dataset``):
the visited observations with the expert's actions, the imitation data of the run.

``mdi-envs distill mdi_envs/DiffDriveRobot-v1 --seeds 0 1 --output baselines/distilled``.
"""

from __future__ import annotations

import argparse
import copy
import math
import os
import time
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch as th
from stable_baselines3.common.torch_layers import FlattenExtractor

from baselines.datasets import TASKS, dataset_id
from baselines.evaluation import DISTILLED_DIR, OBJECTIVES, Controller, model_policy, play
from baselines.model_based import EXPERTS
from baselines.time_input import max_steps, time_aware, with_time
from mdi_envs.provenance import git_commit

FIRST_TRAINING_SEED = 1_000_000
"""Training episodes reset from seeds at or above this (evaluations use 0, 1, ...)."""

ALGO = "DAgger"
"""The ``algo`` of the records: the row label of the distilled policies."""

DEFAULT_OUTPUT = DISTILLED_DIR
"""Where ``mdi-envs distill`` writes by default (``--trained`` of ``mdi-envs compare``)."""


@dataclass(frozen=True)
class DAggerSettings:
    """The settings of one distillation.

    Attributes:
        rounds: DAgger rounds after the behaviour cloning round 0.
        episodes: perturbed-start episodes per round.
        beta_decay: beta_i = beta_decay ** i, the expert's share of the actions in round i.
        gradient_steps: minibatch steps on the aggregated data after each round.
        batch_size: samples per gradient step.
        learning_rate: of the policy's Adam optimizer.
        net_arch: hidden layer widths of the policy (and of its unused value net).
        validation: perturbed starts the learner plays alone after each round; the round
            whose learner succeeds most often (the later on a tie) is the one returned.
        start_scales: (low, high), the range of the perturbed starts' noise half-width
            ``reset_noise_scale`` [rad, rad/s, m, m/s], drawn log-uniformly.
        validation_scales: the same range for the validation starts; None: ``start_scales``.
        observe_time: the learner also sees the normalized elapsed time
            (``baselines.time_input``), as a time-indexed expert does.
        expert_noise: standard deviation of the Gaussian noise on the expert's played
            continuous actions, a fraction of their bound (0: none; DART).
    """

    rounds: int = 6
    episodes: int = 20
    beta_decay: float = 0.5
    gradient_steps: int = 2000
    batch_size: int = 256
    learning_rate: float = 1e-3
    net_arch: tuple[int, ...] = (256, 256)
    validation: int = 10
    start_scales: tuple[float, float] = (0.01, 0.1)
    validation_scales: tuple[float, float] | None = None
    observe_time: bool = False
    expert_noise: float = 0.0

    def __post_init__(self) -> None:
        for name in ("gradient_steps", "batch_size", "episodes", "validation"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if self.rounds < 0:
            raise ValueError(f"rounds must be >= 0, got {self.rounds}")
        if not 0.0 <= self.beta_decay < 1.0:
            raise ValueError(f"beta_decay must be in [0, 1), got {self.beta_decay}")
        for name in ("start_scales", "validation_scales"):
            scales = getattr(self, name)
            if scales is not None and not 0.0 < scales[0] <= scales[1]:
                raise ValueError(f"{name} must be (low, high) with 0 < low <= high, "
                                 f"got {scales}")
        if not 0.0 <= self.expert_noise <= 1.0:
            raise ValueError(f"expert_noise must be in [0, 1], got {self.expert_noise}")
        if self.learning_rate <= 0.0 or not self.net_arch or min(self.net_arch) < 1:
            raise ValueError(f"need learning_rate > 0 and a non-empty net_arch of positive "
                             f"widths, got {self.learning_rate} and {self.net_arch}")


@dataclass(frozen=True)
class Distillation:
    """The ``distillation`` entry of a distilled policy's ``STEM.json``.

    Attributes:
        expert: its name in ``EXPERTS``; expert_label: its row label.
        settings: the ``DAggerSettings``.
        expert_calls: labels computed (one per visited state, every round).
        expert_cpu_s: CPU time [s] of those calls.
        dataset_sizes: samples after each round (round 0 first).
        losses: the training loss (``imitation_loss`` on all the data) after each round.
        mixture_success: success rate of each round's episodes (round 0: the expert's).
        validation_success: the learner's alone after each round (``DAggerSettings``).
        validation_cost: the learner's mean time [s] or effort [N^2 m^2 s] over those successes
            after each round (None: none succeeded).
        best_round: the round whose learner is returned.
    """

    expert: str
    expert_label: str
    settings: DAggerSettings
    expert_calls: int
    expert_cpu_s: float
    dataset_sizes: list[int]
    losses: list[float]
    mixture_success: list[float]
    validation_success: list[float]
    validation_cost: list[float | None]
    best_round: int


def is_hybrid(env_id: str) -> bool:
    """Whether the learner of ``env_id`` plays ``action_mode="hybrid"`` (a scene with a brake)."""
    return "Manipulator" in env_id


def expert_label(action: np.ndarray, hybrid: bool) -> np.ndarray:
    """The learner's flat action (float32) for an expert's Box action.

    Box learners take it as is; the hybrid learner's flat action (``baselines.hybrid_ppo``) is
    ``[brake choice, torque]`` with the choice 1 iff the Box brake component ``action[1] > 0``
    (the env's "box" rule). ``action``: (2,) [torque / max_torque, brake] when ``hybrid``.
    """
    action = np.asarray(action, dtype=np.float32)
    if not hybrid:
        return action
    if action.shape != (2,):
        raise ValueError(f"a manipulator Box action is (torque, brake), got shape {action.shape}")
    return np.array([float(action[1] > 0.0), action[0]], dtype=np.float32)


def native_action(flat: np.ndarray, hybrid: bool) -> Any:
    """A flat learner action as the env takes it: the (choice, torques) tuple when ``hybrid``."""
    from baselines.hybrid_ppo import to_hybrid_actions

    return to_hybrid_actions(flat, 2) if hybrid else flat


def noisy(label: np.ndarray, sigma: float, hybrid: bool, rng: np.random.Generator) -> np.ndarray:
    """A flat expert label with N(0, sigma^2) noise on its continuous part, clipped to [-1, 1].

    ``label``: (a,) as ``expert_label`` returns it; the hybrid label's brake choice (its first
    entry) is kept.
    """
    played = np.array(label, dtype=np.float32)
    continuous = played[1:] if hybrid else played
    continuous[:] = np.clip(continuous + sigma * rng.standard_normal(continuous.shape), -1.0, 1.0)
    return played


def learner_env_kwargs(env_id: str, expert: Controller) -> dict[str, Any]:
    """The ``gym.make`` arguments the learner trains and plays with: the expert's, hybrid brake."""
    return {**expert.env_kwargs, **({"action_mode": "hybrid"} if is_hybrid(env_id) else {})}


class Standardized(FlattenExtractor):  # type: ignore[misc]
    """SB3's flattening features extractor, then (obs - mean) / scale with fixed (d,) vectors.

    The learner's inputs mix metres, radians and wheel rates of tens of rad/s; the statistics
    of the expert's data put them on one scale. They are saved with the model (its
    ``policy_kwargs`` and buffers).
    """

    def __init__(self, observation_space: gym.spaces.Box, mean: list[float],
                 scale: list[float]) -> None:  # fmt: skip
        super().__init__(observation_space)
        self.register_buffer("mean", th.as_tensor(mean, dtype=th.float32))
        self.register_buffer("scale", th.as_tensor(scale, dtype=th.float32))

    def forward(self, observations: th.Tensor) -> th.Tensor:
        """Standardized features (B, d) of observations (B, d)."""
        return (super().forward(observations) - self.mean) / self.scale


def make_learner(env_id: str, env_kwargs: dict[str, Any], settings: DAggerSettings, seed: int,
                 observations: np.ndarray) -> Any:  # fmt: skip
    """A fresh ``PPO`` (Box actions) or ``HybridPPO`` (hybrid) model whose policy is trained.

    ``observations`` (N, d): the data whose mean and standard deviation (1 where it is 0)
    standardize the policy's inputs (``Standardized``); with ``settings.observe_time`` its last
    column is the elapsed time of ``baselines.time_input``.
    """
    from stable_baselines3 import PPO

    from baselines.hybrid_ppo import HybridPPO

    std = observations.std(axis=0)
    statistics = {"mean": observations.mean(axis=0).tolist(),
                  "scale": np.where(std > 1e-6, std, 1.0).tolist()}  # fmt: skip
    model_class = HybridPPO if is_hybrid(env_id) else PPO
    env = gym.make(env_id, **env_kwargs)
    if settings.observe_time:
        env = time_aware(env)
    return model_class("MlpPolicy", env, seed=seed, device="cpu",
                       learning_rate=settings.learning_rate,
                       policy_kwargs={"net_arch": list(settings.net_arch),
                                      "features_extractor_class": Standardized,
                                      "features_extractor_kwargs": statistics})  # fmt: skip


@dataclass
class _Labels:
    """The aggregated data and the expert's budget."""

    observations: list[np.ndarray]
    actions: list[np.ndarray]
    calls: int = 0
    cpu_s: float = 0.0
    episodes: list[dict[str, Any]] = field(default_factory=list)
    """Per episode: its reset seed, observations (T + 1), the expert's Box actions (T) and
    the rewards, terminations and truncations (T) as played."""


def play_labelled(env_id: str, env_kwargs: dict[str, Any], expert: Controller, learner: Any,
                  beta: float, seed: int, rng: np.random.Generator, labels: _Labels,
                  observe_time: bool = False, expert_noise: float = 0.0) -> bool:  # fmt: skip
    """One episode of the beta-mixture from ``reset(seed=seed)``, every state labelled.

    At each step the expert is called (its action is the label); the action played is the
    expert's with probability ``beta`` (with ``noisy``'s noise when ``expert_noise`` > 0) and
    the learner's deterministic one otherwise.
    ``env_kwargs`` include the start noise. The learner's inputs (the labelled data) are the
    observations, with the elapsed time appended if ``observe_time``. Returns whether the
    episode ended at the goal.
    """
    hybrid = is_hybrid(env_id)
    env = gym.make(env_id, **env_kwargs)
    policy = expert.make_policy(env)
    limit = max_steps(env) if observe_time else 0
    observation, _ = env.reset(seed=seed)
    done, steps = False, 0
    info: dict[str, Any] = {}
    episode: dict[str, Any] = {"seed": seed, "observations": [observation], "actions": [],
                               "rewards": [], "terminations": [], "truncations": []}
    while not done:
        clock = time.process_time()
        action = policy(observation)
        labels.cpu_s += time.process_time() - clock
        label = expert_label(action, hybrid)
        labels.calls += 1
        learner_input = (with_time(observation, steps, limit) if observe_time
                         else np.asarray(observation, dtype=np.float32))  # fmt: skip
        labels.observations.append(learner_input)
        labels.actions.append(label)
        steps += 1
        if rng.random() < beta:
            flat = noisy(label, expert_noise, hybrid, rng) if expert_noise > 0.0 else label
        else:
            flat = learner.policy.predict(learner_input, deterministic=True)[0]
        if flat is not label and hasattr(policy, "applied"):
            policy.applied(flat)  # an expert whose state follows the torques played
        observation, reward, terminated, truncated, info = env.step(native_action(flat, hybrid))
        done = terminated or truncated
        for key, value in (("observations", observation), ("actions", action),
                           ("rewards", reward), ("terminations", terminated),
                           ("truncations", truncated)):  # fmt: skip
            episode[key].append(value)
    labels.episodes.append(episode)
    env.close()
    return bool(info.get("is_success", False))


def imitation_loss(policy: Any, observations: np.ndarray, actions: np.ndarray) -> float:
    """Mean negative log-likelihood of ``actions`` (N, a) at ``observations`` (N, d)."""
    with th.no_grad():
        _, log_prob, _ = policy.evaluate_actions(th.as_tensor(observations),
                                                 th.as_tensor(actions))  # fmt: skip
    return float(-log_prob.mean())


def fit(policy: Any, observations: np.ndarray, actions: np.ndarray, settings: DAggerSettings,
        rng: np.random.Generator) -> float:  # fmt: skip
    """``settings.gradient_steps`` Adam steps on the NLL of random minibatches; the final loss.

    The learning rate decays as a cosine from ``settings.learning_rate`` to a tenth of it.

    The final loss is ``imitation_loss`` over all of ``observations`` (N, d), ``actions`` (N, a).
    """
    policy.set_training_mode(True)
    obs, act = th.as_tensor(observations), th.as_tensor(actions)
    for step in range(settings.gradient_steps):
        decay = 0.55 + 0.45 * math.cos(math.pi * step / settings.gradient_steps)
        for group in policy.optimizer.param_groups:
            group["lr"] = settings.learning_rate * decay
        index = th.as_tensor(rng.integers(0, len(obs), settings.batch_size))
        _, log_prob, _ = policy.evaluate_actions(obs[index], act[index])
        loss = -log_prob.mean()
        policy.optimizer.zero_grad()
        loss.backward()
        th.nn.utils.clip_grad_norm_(policy.parameters(), 1.0)
        policy.optimizer.step()
    policy.set_training_mode(False)
    return imitation_loss(policy, observations, actions)


def validation_cost(episodes: list[Any], objective: str) -> float | None:
    """Mean time [s] (``objective`` "time") or effort over the successful ``episodes``."""
    costs = [episode.elapsed_time if objective == "time" else episode.effort
             for episode in episodes if episode.is_success]  # fmt: skip
    return float(np.mean(costs)) if costs else None


def validation_rank(success: float, cost: float | None) -> tuple[float, float]:
    """Sort key of a round's validation: more success first, then less cost."""
    return -success, math.inf if cost is None else cost


def perturbed_starts(rng: np.random.Generator, count: int, scales: tuple[float, float]
                     ) -> list[tuple[float, int]]:  # fmt: skip
    """``count`` (start noise half-width log-uniform in ``scales``, reset seed) pairs."""
    low, high = np.log(scales)
    return [(float(np.exp(rng.uniform(low, high))),
             int(rng.integers(FIRST_TRAINING_SEED, 2**31))) for _ in range(count)]  # fmt: skip


def dagger(env_id: str, expert: str = "lqr", settings: DAggerSettings = DAggerSettings(),
           seed: int = 0, log: Callable[[str], None] | None = None, dataset: str | None = None
           ) -> tuple[Any, Distillation, dict[str, Any]]:  # fmt: skip
    """Distil ``expert`` on ``env_id`` (see the module docstring).

    With ``dataset`` (a Minari dataset id) every labelled episode is also written as a Minari
    dataset (``write_labels``).

    Returns:
        (the SB3 model whose policy was trained, its ``Distillation``, the learner's
        ``gym.make`` arguments without the start noise).

    Raises:
        ValueError: an unknown task or expert, or an expert not available here.
    """
    if env_id not in TASKS:
        raise ValueError(f"no distillation task {env_id!r}; known: {', '.join(TASKS)}")
    if expert not in EXPERTS:
        raise ValueError(f"unknown expert {expert!r}; known: {', '.join(EXPERTS)}")
    objective = OBJECTIVES[env_id][0]
    controller = EXPERTS[expert](env_id, objective)
    if controller is None:
        raise ValueError(f"expert {expert!r} is not available here (the MPCs need CasADi)")
    th.set_num_threads(1)  # tiny networks: more threads only add synchronisation
    th.manual_seed(seed)
    rng = np.random.default_rng(seed)
    env_kwargs = learner_env_kwargs(env_id, controller)
    model: Any = None  # made after round 0, whose expert data give the observation statistics
    labels = _Labels([], [])
    validation = perturbed_starts(rng, settings.validation,
                                  settings.validation_scales or settings.start_scales)
    sizes, losses, mixture, validated, costs = [], [], [], [], []
    best, best_round = None, 0
    for round_ in range(settings.rounds + 1):
        beta = settings.beta_decay**round_
        starts = [(0.0, FIRST_TRAINING_SEED)] if round_ == 0 else []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reached = [play_labelled(env_id, {**env_kwargs, "reset_noise_scale": scale}, controller,
                                     model, beta, reset_seed, rng, labels, settings.observe_time,
                                     settings.expert_noise)
                       for scale, reset_seed in starts + perturbed_starts(rng, settings.episodes,
                                                                           settings.start_scales)]
            if model is None:
                model = make_learner(env_id, env_kwargs, settings, seed,
                                     np.array(labels.observations))  # fmt: skip
            losses.append(fit(model.policy, np.array(labels.observations),
                              np.array(labels.actions), settings, rng))  # fmt: skip
            episodes = [play(env_id, model_policy(model, settings.observe_time), reset_seed,
                             **{**env_kwargs, "reset_noise_scale": scale})
                        for scale, reset_seed in validation]  # fmt: skip
        validated.append(float(np.mean([episode.is_success for episode in episodes])))
        costs.append(validation_cost(episodes, objective))
        sizes.append(len(labels.actions))
        mixture.append(float(np.mean(reached)))
        score = validation_rank(validated[-1], costs[-1])
        if best is None or score <= validation_rank(validated[best_round], costs[best_round]):
            best, best_round = copy.deepcopy(model.policy.state_dict()), round_
        if log is not None:
            log(f"round {round_}: beta {beta:.3f}, {sizes[-1]} samples, loss {losses[-1]:.3f}, "
                f"success of the mixture {mixture[-1]:.2f}, of the learner {validated[-1]:.2f}, "
                f"expert {labels.cpu_s:.1f} s")
    model.policy.load_state_dict(best)
    record = Distillation(expert, controller.label, settings, labels.calls, labels.cpu_s, sizes,
                          losses, mixture, validated, costs, best_round)  # fmt: skip
    if dataset is not None:
        write_labels(env_id, controller, labels.episodes, dataset,
                     f"DAgger seed {seed}, expert {controller.label}, {settings}")  # fmt: skip
    return model, record, env_kwargs


def write_labels(env_id: str, expert: Controller, episodes: list[dict[str, Any]], dataset: str,
                 description: str) -> Any:  # fmt: skip
    """The DAgger-labelled episodes as the Minari dataset ``dataset``; returns it.

    Each episode's observations are those visited (the mixture's actions moved the state),
    its actions the expert's labels in the expert's own Box action space: the pairs
    (observation, action) are the imitation data, the transitions are not replayable by the
    actions. The env spec is the expert's configuration (``Controller.env_kwargs``).
    """
    import minari
    from minari.data_collector.episode_buffer import EpisodeBuffer

    buffers = [EpisodeBuffer(id=index, seed=episode["seed"],
                             observations=np.array(episode["observations"], np.float32),
                             actions=np.array(episode["actions"], np.float32),
                             rewards=episode["rewards"], terminations=episode["terminations"],
                             truncations=episode["truncations"])
               for index, episode in enumerate(episodes)]  # fmt: skip
    env = gym.make(env_id, **expert.env_kwargs)
    return minari.create_dataset_from_buffers(
        dataset, buffers, env=env, eval_env=env, algorithm_name="DAgger",
        author="mdi-envs", code_permalink=f"baselines/distill.py at commit {git_commit()}",
        description=f"{description}. Observations as visited, actions the expert's labels.")


class DAgger:
    """The loader of a distilled policy's zip (``ALGORITHM_CLASSES["DAgger"]``)."""

    @staticmethod
    def load(path: str | Path, device: str = "cpu", **kwargs: Any) -> Any:
        """The saved model, loaded with its class: ``HybridPPO`` for a hybrid policy, else ``PPO``.

        Raises:
            ValueError: the zip holds no policy class.
        """
        from stable_baselines3 import PPO
        from stable_baselines3.common.save_util import load_from_zip_file

        from baselines.hybrid_ppo import HybridActorCriticPolicy, HybridPPO

        data, _, _ = load_from_zip_file(path, device=device)
        policy_class = (data or {}).get("policy_class")
        if not isinstance(policy_class, type):
            raise ValueError(f"{path} holds no SB3 policy class")
        model_class = HybridPPO if issubclass(policy_class, HybridActorCriticPolicy) else PPO
        return model_class.load(path, device=device, **kwargs)


def distill(env_id: str, expert: str = "lqr", settings: DAggerSettings = DAggerSettings(),
            seed: int = 0, output: Path = DEFAULT_OUTPUT, eval_episodes: int = 10,
            log: Callable[[str], None] | None = None, dataset: str | None = None
            ) -> Path:  # fmt: skip
    """Run ``dagger`` and write ``STEM.zip`` and ``STEM.json`` into ``output``; the zip's path.

    ``dataset``: the Minari dataset id of the labelled episodes (None: none written).

    STEM = ``baselines.train.run_name(env_id, objective, "DAgger", seed)``. The record's
    ``evaluation`` is ``baselines.train.evaluate`` over ``eval_episodes`` starts at the env's
    default start noise, from reset seed ``seed + 10_000``.
    """
    from baselines.train import (
        PolicyEvaluation,
        RecentEpisodes,
        TrainingRecord,
        evaluate,
        run_name,
        versions,
        write_record,
    )

    start = time.perf_counter()
    model, record, env_kwargs = dagger(env_id, expert, settings, seed, log, dataset)
    wall_time = time.perf_counter() - start
    objective = OBJECTIVES[env_id][0]
    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    stem = run_name(env_id, objective, ALGO, seed)
    model.save(output / f"{stem}.zip")
    evaluation: PolicyEvaluation = evaluate(model, env_id, env_kwargs, eval_episodes, seed + 10_000,
                                            settings.observe_time)  # fmt: skip
    steps = record.expert_calls
    episodes = (settings.rounds + 1) * settings.episodes + 1
    training = TrainingRecord(
        env_id=env_id, objective=objective, algo=ALGO, seed=seed, num_envs=1,
        total_timesteps=steps, num_timesteps=steps, algo_kwargs=asdict(settings),
        algo_overrides={}, env_kwargs=env_kwargs, policy="MlpPolicy", device="cpu",
        torch_threads=th.get_num_threads(), wall_time_s=wall_time, num_episodes=episodes,
        train_last100=RecentEpisodes(None, record.mixture_success[-1]), evaluation=evaluation,
        versions=versions(), commit=git_commit(), date=time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        command=f"mdi-envs distill {env_id} --expert {expert} --seeds {seed} --rounds "
                f"{settings.rounds} --episodes {settings.episodes} "
                f"--gradient-steps {settings.gradient_steps} --start-scales "
                f"{settings.start_scales[0]} {settings.start_scales[1]} --validation "
                f"{settings.validation}"
                + (" --validation-scales {} {}".format(*settings.validation_scales)
                   if settings.validation_scales else "")
                + (" --observe-time" if settings.observe_time else "")
                + (f" --expert-noise {settings.expert_noise}" if settings.expert_noise else ""))
    write_record(output / f"{stem}.json", training, distillation=record)
    return output / f"{stem}.zip"


def add_distill_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``distill`` subcommand to an argparse subparsers object; returns its parser."""
    defaults = DAggerSettings()
    parser = subparsers.add_parser(
        "distill", help="distil a model-based controller into a network by DAgger",
        description="Train a network policy by DAgger with a model-based controller as the "
                    "expert; writes STEM.zip and STEM.json per seed into --output (a folder for "
                    "mdi-envs compare --trained). A seed whose JSON exists is skipped.")
    parser.add_argument("env_id", choices=TASKS, help="the task")
    parser.add_argument("--expert", choices=list(EXPERTS), default="lqr", help="default: lqr")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0], help="default: 0")
    parser.add_argument("--rounds", type=int, default=defaults.rounds)
    parser.add_argument("--episodes", type=int, default=defaults.episodes,
                        help="perturbed starts per round")
    parser.add_argument("--gradient-steps", type=int, default=defaults.gradient_steps,
                        help="minibatch steps after each round")
    parser.add_argument("--start-scales", type=float, nargs=2, default=defaults.start_scales,
                        metavar=("LOW", "HIGH"),
                        help="range of the perturbed starts' noise half-width, drawn "
                             "log-uniformly (default: %(default)s)")
    parser.add_argument("--validation", type=int, default=defaults.validation,
                        help="starts the learner plays alone after each round to choose the "
                             "round kept (default: %(default)s)")
    parser.add_argument("--validation-scales", type=float, nargs=2, default=None,
                        metavar=("LOW", "HIGH"),
                        help="range of the validation starts' noise half-width (default: "
                             "--start-scales)")
    parser.add_argument("--observe-time", action="store_true",
                        help="the learner also sees the normalized elapsed time (for a "
                             "time-indexed expert)")
    parser.add_argument("--expert-noise", type=float, default=defaults.expert_noise,
                        metavar="SIGMA",
                        help="Gaussian noise on the expert's played actions, a fraction of the "
                             "bound; the labels stay clean (DART; default: %(default)s)")
    parser.add_argument("--output", type=Path, default=DEFAULT_OUTPUT)
    parser.add_argument("--dataset", action="store_true",
                        help="also write each seed's labelled episodes as the Minari dataset "
                             "mdi_envs/<Task>/dagger-<expert>-seed<seed>-v0")
    parser.add_argument("--root", type=Path, default=None,
                        help="the datasets' folder (sets MINARI_DATASETS_PATH)")
    parser.set_defaults(handler=run_distill)
    return parser


def run_distill(args: argparse.Namespace) -> int:
    """Handler of ``distill``: one distillation per seed not yet in ``--output``."""
    from baselines.train import run_name

    if args.root is not None:
        os.environ["MINARI_DATASETS_PATH"] = str(args.root.resolve())
    try:
        settings = DAggerSettings(rounds=args.rounds, episodes=args.episodes,
                                   gradient_steps=args.gradient_steps,
                                   start_scales=tuple(args.start_scales),
                                   validation=args.validation,
                                   validation_scales=(None if args.validation_scales is None
                                                      else tuple(args.validation_scales)),
                                   observe_time=args.observe_time,
                                   expert_noise=args.expert_noise)
        for seed in args.seeds:
            stem = run_name(args.env_id, OBJECTIVES.get(args.env_id, ("",))[0], ALGO, seed)
            if (args.output / f"{stem}.json").exists():
                print(f"{stem}: already in {args.output}")
                continue
            dataset = dataset_id(args.env_id, f"dagger-{args.expert}-seed{seed}")
            path = distill(args.env_id, args.expert, settings, seed, args.output,
                           log=lambda line, s=seed: print(f"seed {s} {line}", flush=True),
                           dataset=dataset if args.dataset else None)  # fmt: skip
            print(f"{path}")
    except ValueError as error:
        raise SystemExit(f"distill: {error}") from error
    return 0


__all__ = [
    "ALGO", "DEFAULT_OUTPUT", "FIRST_TRAINING_SEED", "DAgger",
    "DAggerSettings", "Distillation", "Standardized", "add_distill_parser", "dagger", "distill",
    "expert_label", "imitation_loss", "is_hybrid", "learner_env_kwargs", "make_learner",
    "native_action", "noisy", "perturbed_starts", "play_labelled", "validation_cost",
    "validation_rank", "write_labels",
]
