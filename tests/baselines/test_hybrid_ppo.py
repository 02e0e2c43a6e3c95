"""HybridPPO: distribution vs torch.distributions, env boundary, smoke run, save/load, evaluation.

The training smoke run (<= 1000 steps) goes through ``baselines.train.train``.
"""

from __future__ import annotations

import argparse
import json
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3 import PPO
from stable_baselines3.common.evaluation import evaluate_policy
from torch.distributions import Categorical, Normal

import mdi_envs  # noqa: F401 - registers the ids
from baselines.cli import add_train_parser
from baselines.hybrid_ppo import (
    HybridActionVecEnv,
    HybridActorCriticPolicy,
    HybridDistribution,
    HybridPPO,
    flat_hybrid_space,
    hybrid_space,
    to_hybrid_actions,
)
from baselines.train import algorithm_class, run_name
from baselines.vec_env import make_vec_env

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
TINY = {"policy_kwargs": {"net_arch": [16, 16]}}


@pytest.fixture(autouse=True)
def _one_thread() -> None:
    th.set_num_threads(1)


def _hybrid_env(**kwargs: object) -> gym.Env:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return gym.make(MANIPULATOR, action_mode="hybrid", **kwargs)


def _distribution(batch: int, num_choices: int, action_dim: int, seed: int = 0
                  ) -> tuple[HybridDistribution, th.Tensor, th.Tensor]:  # fmt: skip
    generator = th.Generator().manual_seed(seed)
    params = th.randn(batch, num_choices + action_dim, generator=generator) * 2.0
    log_std = th.randn(action_dim, generator=generator) * 0.5
    dist = HybridDistribution(num_choices, action_dim).proba_distribution(params, log_std)
    return dist, params, log_std


# -- the distribution -------------------------------------------------------------------------
@pytest.mark.parametrize(("num_choices", "action_dim"), [(2, 1), (3, 2)])
def test_log_prob_and_entropy_are_the_sums_of_the_torch_factors(num_choices: int,
                                                                action_dim: int) -> None:
    dist, params, log_std = _distribution(64, num_choices, action_dim)
    logits, means = params[:, :num_choices], params[:, num_choices:]
    categorical = Categorical(logits=logits)
    gaussian = Normal(means, log_std.exp().expand_as(means))
    th.manual_seed(1)
    actions = dist.sample()
    assert actions.shape == (64, 1 + action_dim)
    choice = actions[:, 0].long()
    expected = categorical.log_prob(choice) + gaussian.log_prob(actions[:, 1:]).sum(dim=1)
    th.testing.assert_close(dist.log_prob(actions), expected)
    expected_entropy = categorical.entropy() + gaussian.entropy().sum(dim=1)
    th.testing.assert_close(dist.entropy(), expected_entropy)
    # summed over the choices at a fixed torque, the density is the Gaussian's alone
    torque = actions[:1, 1:].expand(num_choices, -1)
    all_choices = th.cat([th.arange(num_choices, dtype=th.float32)[:, None], torque], dim=1)
    repeated = HybridDistribution(num_choices, action_dim).proba_distribution(
        params[:1].expand(num_choices, -1), log_std)
    th.testing.assert_close(th.logsumexp(repeated.log_prob(all_choices), dim=0),
                            gaussian.log_prob(actions[:, 1:])[0].sum())  # fmt: skip


def test_samples_lie_in_the_support_with_the_softmax_frequencies() -> None:
    _, params, log_std = _distribution(1, 2, 1, seed=3)
    dist = HybridDistribution(2, 1).proba_distribution(params.expand(20_000, -1), log_std)
    th.manual_seed(4)
    actions = dist.sample()
    brake = actions[:, 0]
    assert set(brake.unique().tolist()) == {0.0, 1.0}
    probability = th.softmax(params[0, :2], dim=0)[1].item()
    assert brake.mean().item() == pytest.approx(probability, abs=0.015)  # > 4 sigma
    assert actions[:, 1].mean().item() == pytest.approx(params[0, 2].item(), abs=0.05)


def test_mode_is_argmax_and_mean() -> None:
    dist, params, _ = _distribution(32, 3, 2, seed=5)
    mode = dist.get_actions(deterministic=True)
    th.testing.assert_close(mode[:, 0], params[:, :3].argmax(dim=1).float())
    th.testing.assert_close(mode[:, 1:], params[:, 3:])
    actions, log_prob = dist.log_prob_from_params(params, th.zeros(2))
    th.testing.assert_close(log_prob, dist.log_prob(actions))


# -- spaces, env boundary, policy -------------------------------------------------------------
def test_flat_space_and_action_conversion() -> None:
    native = _hybrid_env().action_space
    flat = flat_hybrid_space(native)
    assert flat == spaces.Box(np.array([0, -1], np.float32), np.array([1, 1], np.float32))
    assert hybrid_space(flat) == native
    choice, torque = to_hybrid_actions(np.array([0.9, 0.25]), 2)  # type: ignore[misc]
    assert choice == 1 and torque.dtype == np.float32 and torque.tolist() == [0.25]
    batch = to_hybrid_actions(np.array([[0.0, -0.5], [1.0, 0.5]], np.float32), 2)
    assert isinstance(batch, list) and [a[0] for a in batch] == [0, 1]
    assert all(native.contains(action) for action in batch)
    for bad in (spaces.Box(-1, 1, (2,)), spaces.Tuple((spaces.Discrete(2, start=1),
                                                       spaces.Box(-1, 1, (1,))))):
        with pytest.raises(ValueError):
            flat_hybrid_space(bad)


def test_policy_head_and_initial_brake_probability() -> None:
    env = _hybrid_env()
    policy = HybridActorCriticPolicy(env.observation_space, env.action_space, lambda _: 3e-4,
                                     net_arch=[16])  # fmt: skip
    assert policy.action_space == flat_hybrid_space(env.action_space)
    assert policy.action_net.out_features == 3 and policy.log_std.shape == (1,)
    obs = th.as_tensor(np.stack([env.reset(seed=s)[0] for s in range(8)]))
    th.manual_seed(0)
    actions, values, log_prob = policy(obs)
    assert actions.shape == (8, 2) and values.shape == (8, 1) and log_prob.shape == (8,)
    _, log_prob_again, entropy = policy.evaluate_actions(obs, actions)
    th.testing.assert_close(log_prob_again, log_prob)
    probs = policy.get_distribution(obs).categorical.probs
    th.testing.assert_close(probs, th.full_like(probs, 0.5), atol=0.05, rtol=0)  # gain 0.01
    assert entropy is not None and entropy.shape == (8,)
    with pytest.raises(ValueError, match="not a hybrid"):  # a Box that is no flat hybrid one
        HybridActorCriticPolicy(env.observation_space, spaces.Box(-1, 1, (2,)), lambda _: 3e-4)
    with pytest.raises(ValueError, match="gSDE"):
        HybridActorCriticPolicy(env.observation_space, env.action_space, lambda _: 3e-4,
                                use_sde=True)  # fmt: skip


def test_hybrid_ppo_needs_a_hybrid_env() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        box_env = gym.make(MANIPULATOR)
    with pytest.raises(ValueError, match="Tuple"):
        HybridPPO("MlpPolicy", box_env, device="cpu")


def test_algorithm_names_resolve_case_insensitively() -> None:
    assert algorithm_class("hybridppo") is HybridPPO and algorithm_class("PPO") is PPO
    with pytest.raises(KeyError, match="known"):
        algorithm_class("DQN")
    parser = argparse.ArgumentParser()
    add_train_parser(parser.add_subparsers())
    assert parser.parse_args(["train", MANIPULATOR, "hybridPPO"]).algo == "HybridPPO"
    with pytest.raises(SystemExit):
        parser.parse_args(["train", MANIPULATOR, "DQN"])


# -- training -----------------------------------------------------------------------------------
@pytest.mark.slow
def test_save_load_round_trip_and_evaluate_policy(tmp_path: Path) -> None:
    venv = make_vec_env(MANIPULATOR, 2, action_mode="hybrid", max_episode_steps=40)
    model = HybridPPO("MlpPolicy", venv, n_steps=32, batch_size=32, n_epochs=2, seed=1,
                      device="cpu", **TINY)  # fmt: skip
    assert isinstance(model.get_env(), HybridActionVecEnv)
    model.learn(128)
    assert model.num_timesteps == 128
    model.save(tmp_path / "model.zip")
    env = _hybrid_env(max_episode_steps=40)
    loaded = HybridPPO.load(tmp_path / "model.zip", device="cpu")
    assert loaded.hybrid_action_space == env.action_space
    observations = np.stack([env.reset(seed=s)[0] for s in range(16)])
    expected, _ = model.predict(observations, deterministic=True)
    actual, _ = loaded.predict(observations, deterministic=True)
    assert [a for a, _ in actual] == [a for a, _ in expected]
    np.testing.assert_array_equal([t for _, t in actual], [t for _, t in expected])
    action, _ = loaded.predict(observations[0], deterministic=True)
    assert env.action_space.contains(action) and action[0] == expected[0][0]
    returns, lengths = evaluate_policy(loaded, env, n_eval_episodes=2, deterministic=True,
                                       return_episode_rewards=True, warn=False)  # fmt: skip
    assert len(returns) == 2 and np.isfinite(returns).all()
    assert all(1 <= length <= 40 for length in lengths)
    # loading with an env keeps training on it, through the same wrapper
    resumed = HybridPPO.load(tmp_path / "model.zip", env=env, device="cpu")
    resumed.learn(32, reset_num_timesteps=False)
    assert resumed.num_timesteps == 128 + 32


@pytest.mark.slow
def test_train_hybrid_ppo_smoke(tmp_path: Path) -> None:
    overrides = {"n_steps": 64, "batch_size": 64, "n_epochs": 2, **TINY}
    path = train_hybrid(tmp_path, overrides)
    assert path == tmp_path / f"{run_name(MANIPULATOR, 'time', 'HybridPPO', 3)}.zip"
    assert path.name == "BlockableManipulator-v0_time_hybridppo_seed3.zip"
    config = json.loads(path.with_suffix(".json").read_text())
    assert config["algo"] == "HybridPPO" and config["seed"] == 3
    assert config["num_timesteps"] >= 1000 and config["num_episodes"] >= 1
    assert config["env_kwargs"] == {"action_mode": "hybrid", "shaping_discount": 1.0}
    assert config["algo_kwargs"]["policy_kwargs"] == TINY["policy_kwargs"]
    assert np.isfinite(config["evaluation"]["mean_return"])
    for suffix in (".zip", ".png"):
        assert path.with_suffix(suffix).stat().st_size > 0
    model = HybridPPO.load(path, device="cpu")
    assert isinstance(model.policy, HybridActorCriticPolicy)
    env = _hybrid_env()
    action, _ = model.predict(env.reset(seed=0)[0], deterministic=True)
    assert env.action_space.contains(action)


def train_hybrid(output: Path, overrides: dict) -> Path:
    """``train`` of HybridPPO on the manipulator: 1000 steps on 2 copies, seed 3."""
    from baselines.train import train

    return train(MANIPULATOR, "hybridppo", seed=3, total_timesteps=1000, output=output,
                 num_envs=2, algo_overrides=overrides, eval_episodes=1, progress_bar=False)
