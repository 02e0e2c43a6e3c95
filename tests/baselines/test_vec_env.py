"""The SB3 VecEnv adapters: SB3's contract and equality with DummyVecEnv over gym.make."""

from __future__ import annotations

import warnings
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.vec_env import DummyVecEnv, VecMonitor

import mdi_envs  # noqa: F401 - registers the ids
from baselines.time_input import time_aware
from baselines.vec_env import MoreauJeanVecEnv, TimeAwareVecEnv, make_vec_env

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"
DIFF_DRIVE = "mdi_envs/DiffDriveRobot-v0"
# (env id, env kwargs): short truncation, a fixed-horizon termination, and both at once
CASES = [
    (MANIPULATOR, {"max_episode_steps": 37}),
    (DIFF_DRIVE, {"objective": "effort"}),
    (DIFF_DRIVE, {"objective": "effort", "max_episode_steps": 81}),
    (DIFF_DRIVE, {"objective": "time", "max_episode_steps": 23}),
]
NUM_ENVS = 4


def _single(env_id: str, kwargs: dict[str, Any]) -> gym.Env[Any, Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return gym.make(env_id, **kwargs)


def _actions(venv: Any, rng: np.random.Generator) -> np.ndarray:
    space = venv.action_space
    return rng.uniform(space.low, space.high, (venv.num_envs, *space.shape)).astype(space.dtype)


@pytest.mark.parametrize(("env_id", "kwargs", "num_envs"),
                         [(*case, NUM_ENVS) for case in CASES] + [(*CASES[0], 1)])
def test_equals_dummy_vec_env_step_for_step(env_id: str, kwargs: dict[str, Any],
                                            num_envs: int) -> None:
    ours = make_vec_env(env_id, num_envs, **kwargs)
    reference = DummyVecEnv([lambda: _single(env_id, kwargs) for _ in range(num_envs)])
    ours.seed(11)
    reference.seed(11)
    obs, expected = ours.reset(), reference.reset()
    np.testing.assert_allclose(obs, expected, rtol=1e-6, atol=1e-6)
    rng = np.random.default_rng(0)
    num_dones = 0
    for _ in range(300):
        actions = _actions(ours, rng)
        obs, rewards, dones, infos = ours.step(actions)
        obs_ref, rewards_ref, dones_ref, infos_ref = reference.step(actions)
        np.testing.assert_allclose(obs, obs_ref, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(rewards, rewards_ref, rtol=1e-6, atol=1e-9)
        np.testing.assert_array_equal(dones, dones_ref)
        for info, info_ref in zip(infos, infos_ref, strict=True):
            assert info["TimeLimit.truncated"] == info_ref["TimeLimit.truncated"]
            assert ("terminal_observation" in info) == ("terminal_observation" in info_ref)
            if "terminal_observation" in info:
                np.testing.assert_allclose(info["terminal_observation"],
                                           info_ref["terminal_observation"], rtol=1e-6,
                                           atol=1e-6)  # fmt: skip
            for key in ("is_success", "elapsed_time", "effort", "distance_to_goal"):
                assert info[key] == pytest.approx(info_ref[key], rel=1e-9, abs=1e-12)
        num_dones += int(dones.sum())
    assert num_dones >= num_envs  # every case ends episodes within the 300 steps


@pytest.mark.parametrize(("env_id", "kwargs"), CASES[:2])
def test_sb3_contract(env_id: str, kwargs: dict[str, Any]) -> None:
    venv = make_vec_env(env_id, NUM_ENVS, **kwargs)
    assert venv.num_envs == NUM_ENVS
    assert venv.get_attr("render_mode") == [None] * NUM_ENVS
    assert venv.env_is_wrapped(gym.Wrapper) == [False] * NUM_ENVS
    assert venv.get_attr("dt", indices=[1, 2]) == [venv.venv.dt] * 2
    assert venv.seed(5) == [5, 6, 7, 8]
    obs = venv.reset()
    shape = (NUM_ENVS, *venv.observation_space.shape)
    assert obs.shape == shape and obs.dtype == venv.observation_space.dtype
    rng = np.random.default_rng(1)
    episodes = [0] * NUM_ENVS  # episodes started per copy, to replay them on a single env
    for _ in range(250):
        obs, rewards, dones, infos = venv.step(_actions(venv, rng))
        assert obs.shape == shape and obs.dtype == np.float32
        assert rewards.shape == (NUM_ENVS,) and rewards.dtype == np.float32
        assert dones.shape == (NUM_ENVS,) and dones.dtype == np.bool_
        assert len(infos) == NUM_ENVS
        for i, info in enumerate(infos):
            assert ("terminal_observation" in info) == bool(dones[i])
            assert isinstance(info["is_success"], bool)
            assert {"elapsed_time", "effort", "TimeLimit.truncated"} <= info.keys()
            if dones[i]:
                assert info["terminal_observation"].shape == shape[1:]
                assert not np.array_equal(info["terminal_observation"], obs[i])
                episodes[i] += 1
                # the returned obs is what a fresh single env seeded 5 + i gives on reset k + 1
                single = _single(env_id, kwargs)
                first, _ = single.reset(seed=5 + i)
                for _ in range(episodes[i]):
                    first, _ = single.reset()
                np.testing.assert_allclose(obs[i], first, rtol=1e-6, atol=1e-6)
    assert sum(episodes) >= NUM_ENVS


def test_vec_monitor_reports_episodes() -> None:
    venv = VecMonitor(make_vec_env(DIFF_DRIVE, NUM_ENVS, objective="effort"))
    venv.seed(0)
    venv.reset()
    rng = np.random.default_rng(2)
    returns = np.zeros(NUM_ENVS)
    for _ in range(81):
        _, rewards, dones, infos = venv.step(_actions(venv, rng))
        returns += rewards
    assert dones.all()  # the "effort" horizon is 4.05 s = 81 steps of 0.05 s
    for i, info in enumerate(infos):
        assert info["episode"]["l"] == 81
        assert info["episode"]["r"] == pytest.approx(returns[i], rel=1e-4, abs=1e-4)
        assert info["elapsed_time"] == pytest.approx(4.05)


def test_set_attr_and_env_method_act_on_the_shared_env() -> None:
    venv = make_vec_env(MANIPULATOR, 2)
    venv.set_attr("max_episode_steps", 5)
    assert venv.get_attr("max_episode_steps") == [5, 5]
    with pytest.raises(ValueError, match="share one env"):
        venv.set_attr("max_episode_steps", 6, indices=[0])
    venv.reset()
    rng = np.random.default_rng(3)
    for _ in range(5):
        _, _, dones, infos = venv.step(_actions(venv, rng))
    assert dones.all() and all(info["TimeLimit.truncated"] for info in infos)
    assert isinstance(venv, MoreauJeanVecEnv)
    assert venv.env_method("__repr__", indices=[0, 1]) == [repr(venv.venv)] * 2
    venv.close()


def test_hybrid_actions_equal_dummy_vec_env_in_both_layouts() -> None:
    kwargs = {"action_mode": "hybrid", "max_episode_steps": 37}
    ours = make_vec_env(MANIPULATOR, NUM_ENVS, **kwargs)
    batched = make_vec_env(MANIPULATOR, NUM_ENVS, **kwargs)
    reference = DummyVecEnv([lambda: _single(MANIPULATOR, kwargs) for _ in range(NUM_ENVS)])
    assert ours.action_space == reference.action_space
    for venv in (ours, batched, reference):
        venv.seed(11)
        venv.reset()
    rng = np.random.default_rng(4)
    num_dones = 0
    for _ in range(100):
        choices = rng.integers(0, 2, NUM_ENVS)
        torques = rng.uniform(-1, 1, (NUM_ENVS, 1)).astype(np.float32)
        per_copy = [(int(c), t) for c, t in zip(choices, torques, strict=True)]  # SB3's layout
        obs, rewards, dones, infos = ours.step(per_copy)
        obs_batched, rewards_batched, _, _ = batched.step((choices, torques))  # Gymnasium's
        obs_ref, rewards_ref, dones_ref, infos_ref = reference.step(per_copy)
        np.testing.assert_array_equal(obs, obs_batched)
        np.testing.assert_array_equal(rewards, rewards_batched)
        np.testing.assert_allclose(obs, obs_ref, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(rewards, rewards_ref, rtol=1e-6, atol=1e-9)
        np.testing.assert_array_equal(dones, dones_ref)
        assert [info["brake_engaged"] for info in infos] == (choices == 1).tolist()
        for info, info_ref in zip(infos, infos_ref, strict=True):
            assert info["brake_engaged"] == info_ref["brake_engaged"]
        num_dones += int(dones.sum())
    assert num_dones >= NUM_ENVS


def test_the_time_aware_adapter_equals_dummy_vec_env_over_time_aware_copies() -> None:
    env_id, kwargs = CASES[0]
    ours = TimeAwareVecEnv(make_vec_env(env_id, NUM_ENVS, **kwargs), kwargs["max_episode_steps"])
    reference = DummyVecEnv([lambda: time_aware(_single(env_id, kwargs))
                             for _ in range(NUM_ENVS)])  # fmt: skip
    assert ours.observation_space == reference.observation_space
    ours.seed(3)
    reference.seed(3)
    np.testing.assert_allclose(ours.reset(), reference.reset(), rtol=1e-6, atol=1e-6)
    rng = np.random.default_rng(1)
    finals = 0
    for _ in range(80):  # two episodes of 37 steps per copy, and a third begun
        actions = _actions(ours, rng)
        obs, _, dones, infos = ours.step(actions)
        obs_ref, _, dones_ref, infos_ref = reference.step(actions)
        np.testing.assert_allclose(obs, obs_ref, rtol=1e-6, atol=1e-6)
        np.testing.assert_array_equal(dones, dones_ref)
        for info, info_ref in zip(infos, infos_ref, strict=True):
            if "terminal_observation" in info_ref:
                finals += 1
                assert info["terminal_observation"][-1] == pytest.approx(1.0)
                np.testing.assert_allclose(info["terminal_observation"],
                                           info_ref["terminal_observation"], rtol=1e-6,
                                           atol=1e-6)  # fmt: skip
    assert finals == 2 * NUM_ENVS
