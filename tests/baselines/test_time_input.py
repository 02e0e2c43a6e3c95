"""A policy's time-aware input is exactly Gymnasium's ``TimeAwareObservation`` observation."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from baselines.time_input import counting_policy, max_steps, time_aware, with_time
from mdi_envs.registration import register_envs

MANIPULATOR = "mdi_envs/BlockableManipulator-v1"


def test_the_counted_input_equals_the_wrappers_observation_over_an_episode() -> None:
    register_envs()
    plain = gym.make(MANIPULATOR, max_episode_steps=30, reset_noise_scale=0.05)
    wrapped = time_aware(gym.make(MANIPULATOR, max_episode_steps=30, reset_noise_scale=0.05))
    seen: list[np.ndarray] = []

    def act(observation: np.ndarray) -> Any:
        seen.append(observation)
        return np.array([0.7, 1.0 if len(seen) % 7 == 0 else -1.0], np.float32)

    policy = counting_policy(act, plain)
    observation, _ = plain.reset(seed=3)
    expected = [wrapped.reset(seed=3)[0]]
    done = False
    while not done:
        action = policy(observation)
        observation, _, terminated, truncated, _ = plain.step(action)
        expected.append(wrapped.step(action)[0])
        done = terminated or truncated
    assert len(seen) == 30 and wrapped.observation_space.contains(seen[-1])
    np.testing.assert_allclose(np.array(seen), np.array(expected[:-1]), rtol=0, atol=1e-7)
    assert seen[0][-1] == 0.0 and seen[-1][-1] == pytest.approx(29 / 30)


def test_an_env_without_a_step_limit_is_refused() -> None:
    register_envs()
    env = gym.make(MANIPULATOR, max_episode_steps=None).unwrapped
    with pytest.raises(ValueError, match="max_episode_steps"):
        max_steps(env)
    np.testing.assert_array_equal(with_time(np.ones(2), 1, 4), np.array([1, 1, 0.25], np.float32))
