"""DAgger distillation of the LQR.

It imitates the expert better than the untrained network, the saved model plays as a trained
row, the hybrid brake conversion is exact, bad requests are errors.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3", reason="needs the rl extra")
import torch  # noqa: E402

from baselines.distill import (  # noqa: E402
    DAggerSettings,
    _Labels,
    add_distill_parser,
    dagger,
    distill,
    expert_label,
    imitation_loss,
    learner_env_kwargs,
    make_learner,
    native_action,
    noisy,
    perturbed_starts,
    play_labelled,
    validation_cost,
    validation_rank,
)
from baselines.evaluation import (  # noqa: E402
    DIFF_DRIVE_EFFORT_V1,
    MANIPULATOR_V1,
    load_policy,
    play,
)
from baselines.model_based import lqr_controller  # noqa: E402
from baselines.records import Episode  # noqa: E402

TINY = DAggerSettings(rounds=1, episodes=2, gradient_steps=400, net_arch=(32, 32), validation=1)


def expert_states(env_id: str, seeds: range, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """(observations, expert labels) of the LQR's own episodes from ``reset(seed=s)``."""
    expert = lqr_controller(env_id, "effort" if "Effort" in env_id else "time")
    assert expert is not None
    labels = _Labels([], [])
    kwargs = {**learner_env_kwargs(env_id, expert), "reset_noise_scale": scale}
    for seed in seeds:
        play_labelled(env_id, kwargs, expert, None, 1.0, seed, np.random.default_rng(0), labels)
    return np.array(labels.observations), np.array(labels.actions)


def test_dagger_imitates_the_expert_on_held_out_states(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    minari = pytest.importorskip("minari", reason="minari is in the datasets extra")
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path))
    name = "mdi_envs/DiffDriveRobotEffort/dagger-lqr-seed3-v0"
    model, record, env_kwargs = dagger(DIFF_DRIVE_EFFORT_V1, "lqr", TINY, seed=3, dataset=name)
    observations, actions = expert_states(DIFF_DRIVE_EFFORT_V1, range(2), 0.05)
    fresh = make_learner(DIFF_DRIVE_EFFORT_V1, env_kwargs, TINY, 3, observations)

    def error(policy: object) -> float:
        predicted = policy.predict(observations, deterministic=True)[0]  # type: ignore[attr-defined]
        return float(np.mean(np.abs(predicted - actions)))

    assert imitation_loss(model.policy, observations, actions) < imitation_loss(
        fresh.policy, observations, actions) - 1.0  # fmt: skip
    assert error(model.policy) < 0.5 * error(fresh.policy)
    # every visited state was labelled once: 1 + 2 episodes in round 0, 2 in round 1, 100 steps
    assert record.expert_calls == record.dataset_sizes[-1] == 5 * 100
    assert record.dataset_sizes == [300, 500] and record.expert_cpu_s > 0.0
    assert len(record.losses) == len(record.mixture_success) == len(record.validation_success) == 2
    assert len(record.validation_cost) == 2
    ranks = [validation_rank(success, cost) for success, cost
             in zip(record.validation_success, record.validation_cost, strict=True)]
    assert record.best_round == max(r for r in range(2) if ranks[r] == min(ranks))
    # the labelled episodes as a Minari dataset: a fresh expert relabels them identically
    dataset = minari.load_dataset(name)
    assert dataset.total_episodes == 5 and dataset.total_steps == record.expert_calls
    expert = lqr_controller(DIFF_DRIVE_EFFORT_V1, "effort")
    assert expert is not None
    for episode in dataset.iterate_episodes():
        policy = expert.make_policy(None)  # type: ignore[arg-type]
        relabelled = [policy(observation) for observation in episode.observations[:-1]]
        np.testing.assert_array_equal(relabelled, episode.actions)


def test_the_distilled_manipulator_loads_and_plays_as_a_trained_row(tmp_path: Path) -> None:
    settings = DAggerSettings(rounds=0, episodes=1, gradient_steps=50, net_arch=(16,), validation=1)
    path = distill(MANIPULATOR_V1, "lqr", settings, seed=1, output=tmp_path, eval_episodes=1)
    config = json.loads(path.with_suffix(".json").read_text())
    assert path.name == "BlockableManipulator-v1_time_dagger_seed1.zip"
    assert config["algo"] == "DAgger" and config["env_kwargs"]["action_mode"] == "hybrid"
    assert config["distillation"]["expert"] == "lqr"
    assert config["distillation"]["expert_calls"] == config["num_timesteps"] > 0
    assert config["command"].endswith("--validation 1")  # what reruns this seed
    torch.set_num_threads(2)
    controller = load_policy(path.with_suffix(".json"))
    assert controller.label == "DAgger" and controller.training is not None
    assert torch.get_num_threads() == 1  # one observation per call: no thread synchronisation
    episode = play(MANIPULATOR_V1, controller.make_policy, 0, **controller.env_kwargs)
    assert episode.num_steps > 0 and episode.brake_use is not None
    brake, torque = controller.make_policy(None)(np.zeros(7, np.float32))  # type: ignore[arg-type]
    assert brake in (0, 1) and torque.shape == (1,)


def test_a_time_aware_learner_sees_the_step_count_in_training_and_when_played(
        tmp_path: Path) -> None:  # fmt: skip
    expert = lqr_controller(MANIPULATOR_V1, "time")
    assert expert is not None
    labels = _Labels([], [])
    kwargs = {**learner_env_kwargs(MANIPULATOR_V1, expert), "reset_noise_scale": 0.05}
    play_labelled(MANIPULATOR_V1, kwargs, expert, None, 1.0, 2, np.random.default_rng(0), labels,
                  observe_time=True)  # fmt: skip
    inputs = np.array(labels.observations)
    limit = gym.make(MANIPULATOR_V1, **kwargs).spec.max_episode_steps  # type: ignore[union-attr]
    assert inputs.shape == (len(inputs), 8)
    np.testing.assert_allclose(inputs[:, -1], np.arange(len(inputs)) / limit, atol=1e-7)

    settings = DAggerSettings(rounds=0, episodes=1, gradient_steps=50, net_arch=(16,),
                              validation=1, observe_time=True)  # fmt: skip
    path = distill(MANIPULATOR_V1, "lqr", settings, seed=1, output=tmp_path, eval_episodes=1)
    config = json.loads(path.with_suffix(".json").read_text())
    assert config["algo_kwargs"]["observe_time"] and config["command"].endswith("--observe-time")
    controller = load_policy(path.with_suffix(".json"))
    env = gym.make(MANIPULATOR_V1, **controller.env_kwargs)
    policy = controller.make_policy(env)
    brake, torque = policy(env.reset(seed=0)[0])
    assert brake in (0, 1) and torque.shape == (1,)
    episode = play(MANIPULATOR_V1, controller.make_policy, 0, **controller.env_kwargs)
    assert episode.num_steps > 0


def test_the_hybrid_label_plays_exactly_the_experts_box_action() -> None:
    expert = lqr_controller(MANIPULATOR_V1, "time")
    assert expert is not None
    box = gym.make(MANIPULATOR_V1, **expert.env_kwargs, reset_noise_scale=0.05)
    hybrid = gym.make(MANIPULATOR_V1, **learner_env_kwargs(MANIPULATOR_V1, expert),
                      reset_noise_scale=0.05)  # fmt: skip
    policy = expert.make_policy(box)
    observation, _ = box.reset(seed=4)
    np.testing.assert_array_equal(hybrid.reset(seed=4)[0], observation)
    engaged = set()
    for _ in range(120):
        action = policy(observation)
        label = expert_label(action, hybrid=True)
        engaged.add(int(label[0]))
        assert label[1] == action[0] and label[0] == float(action[1] > 0)
        observation, reward, *_ = box.step(action)
        other, other_reward, *_ = hybrid.step(native_action(label, hybrid=True))
        np.testing.assert_array_equal(other, observation)
        assert other_reward == reward
    assert engaged == {0, 1}  # the reference brakes and releases within these steps
    np.testing.assert_array_equal(expert_label(np.array([0.5, -1.0]), hybrid=False), [0.5, -1.0])


def test_expert_noise_perturbs_the_played_actions_and_keeps_the_labels() -> None:
    rng = np.random.default_rng(0)
    labels = np.tile(np.array([1.0, 0.9], dtype=np.float32), (4000, 1))
    played = np.array([noisy(label, 0.2, True, rng) for label in labels])
    assert np.all(played[:, 0] == 1.0)  # the brake choice is kept
    assert played[:, 1].max() == 1.0 and np.mean(played[:, 1] == 1.0) == pytest.approx(
        0.31, abs=0.03)  # clipped at the bound: P(N(0, 0.2^2) > 0.1) = 0.31
    box = np.array([noisy(np.zeros(2, np.float32), 0.2, False, rng) for _ in range(4000)])
    assert box.std(axis=0) == pytest.approx([0.2, 0.2], rel=0.05)

    expert = lqr_controller(DIFF_DRIVE_EFFORT_V1, "effort")
    assert expert is not None
    kwargs = {**learner_env_kwargs(DIFF_DRIVE_EFFORT_V1, expert), "reset_noise_scale": 0.01}
    clean, perturbed = _Labels([], []), _Labels([], [])
    play_labelled(DIFF_DRIVE_EFFORT_V1, kwargs, expert, None, 1.0, 3, np.random.default_rng(0),
                  clean)  # fmt: skip
    play_labelled(DIFF_DRIVE_EFFORT_V1, kwargs, expert, None, 1.0, 3, np.random.default_rng(0),
                  perturbed, expert_noise=0.3)  # fmt: skip
    np.testing.assert_array_equal(clean.observations[0], perturbed.observations[0])
    assert not np.allclose(clean.observations[5], perturbed.observations[5])  # other states
    # and every state of the noisy episode is labelled with the expert's own action there
    policy = expert.make_policy(gym.make(DIFF_DRIVE_EFFORT_V1, **kwargs))
    replayed = [policy(observation) for observation in perturbed.observations]
    np.testing.assert_allclose(np.array(perturbed.actions), np.array(replayed, np.float32))


def test_the_best_round_succeeds_most_and_then_costs_least() -> None:
    def episode(success: bool, time: float, effort: float) -> Episode:
        return Episode(0, success, time, effort, 0, 0.0)

    played = [episode(True, 4.0, 3.0), episode(True, 5.0, 1.0), episode(False, 1.0, 0.1)]
    assert validation_cost(played, "time") == 4.5  # failures do not count
    assert validation_cost(played, "effort") == 2.0
    assert validation_cost([episode(False, 1.0, 1.0)], "time") is None
    rounds = [(0.9, 4.0), (1.0, 5.0), (1.0, 4.5), (0.0, None)]
    assert min(range(4), key=lambda r: validation_rank(*rounds[r])) == 2
    assert validation_rank(0.0, None) > validation_rank(0.1, 100.0)


def test_perturbed_starts_span_the_scale_range_log_uniformly() -> None:
    starts = perturbed_starts(np.random.default_rng(0), 4000, (0.01, 0.3))
    scales = np.array([scale for scale, _ in starts])
    assert scales.min() >= 0.01 and scales.max() <= 0.3
    # log-uniform: the median is the geometric mean of the bounds, a fifth below 0.01 * 30**0.2
    assert np.median(scales) == pytest.approx(np.sqrt(0.01 * 0.3), rel=0.05)
    assert np.mean(scales < 0.01 * 30**0.2) == pytest.approx(0.2, abs=0.03)
    assert min(seed for _, seed in starts) >= 1_000_000  # apart from the evaluation's seeds


def test_bad_requests_are_errors(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="no distillation task"):
        dagger("mdi_envs/BlockableManipulator-v0")
    with pytest.raises(ValueError, match="unknown expert 'optimal'"):
        dagger(MANIPULATOR_V1, "optimal")
    with pytest.raises(ValueError, match="gradient_steps must be >= 1"):
        DAggerSettings(gradient_steps=0)
    with pytest.raises(ValueError, match="beta_decay must be in"):
        DAggerSettings(beta_decay=1.0)
    with pytest.raises(ValueError, match="start_scales must be"):
        DAggerSettings(start_scales=(0.1, 0.01))
    with pytest.raises(ValueError, match="start_scales must be"):
        DAggerSettings(start_scales=(0.0, 0.1))
    with pytest.raises(ValueError, match="validation_scales must be"):
        DAggerSettings(validation_scales=(0.3, 0.1))
    with pytest.raises(ValueError, match="expert_noise must be in"):
        DAggerSettings(expert_noise=-0.1)
    with pytest.raises(ValueError, match="shape"):
        expert_label(np.zeros(3), hybrid=True)
    parser = argparse.ArgumentParser()
    add_distill_parser(parser.add_subparsers())
    args = parser.parse_args(["distill", DIFF_DRIVE_EFFORT_V1, "--rounds", "-1",
                              "--output", str(tmp_path)])  # fmt: skip
    with pytest.raises(SystemExit, match="distill: rounds must be >= 0"):
        args.handler(args)
    (tmp_path / "DiffDriveRobotEffort-v1_effort_dagger_seed0.json").write_text("{}")
    args = parser.parse_args(["distill", DIFF_DRIVE_EFFORT_V1, "--output", str(tmp_path)])
    assert args.handler(args) == 0  # the seed is there: nothing is run
