"""DiffDriveRobot-v0: rolling and slipping modes through the env, and the two objectives."""

from __future__ import annotations

import warnings
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import mdi_envs  # noqa: F401 - registers the ids
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER

ENV_ID = "mdi_envs/DiffDriveRobot-v0"


def make(**kwargs: Any) -> gym.Env[Any, Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return gym.make(ENV_ID, reset_noise_scale=0.0, **kwargs)


def test_equal_small_torques_roll_straight() -> None:
    env = make()
    env.reset(seed=0)
    for _ in range(20):
        obs, _, _, _, info = env.step(np.array([0.3, 0.3], np.float32))
        assert info["slip_mode"] == 2 and info["solver_status"] == 0
    q = env.unwrapped.q
    assert q[0] > 0.1 and abs(q[1]) < 1e-9 and abs(q[2]) < 1e-9
    assert obs[4] > 0.0 and abs(obs[5]) < 1e-9  # forward, no lateral velocity


def test_full_opposite_torques_spin_and_slip() -> None:
    env = make()
    env.reset(seed=0)
    modes = [env.step(np.array([-1.0, 1.0], np.float32))[4]["slip_mode"] for _ in range(20)]
    q = env.unwrapped.q
    # it turns about the axle midpoint, 0.1 m behind the CM: the CM stays on that circle
    assert abs(q[2]) > 0.1 and np.hypot(q[0], q[1]) < 2 * 0.1 + 0.02
    assert 5 in modes


def test_effort_objective_ends_at_the_fixed_horizon() -> None:
    env = make(objective="effort")
    env.reset(seed=0)
    num_steps = round(DIFF_DRIVE_MANEUVER.effort_final_time / env.unwrapped.dt)
    for k in range(num_steps):
        obs, reward, terminated, truncated, info = env.step(np.array([0.2, 0.1], np.float32))
        assert obs[9] == pytest.approx((num_steps - k - 1) * env.unwrapped.dt, abs=1e-6)
        assert terminated == (k == num_steps - 1)
    assert info["reward_goal"] == pytest.approx(-10.0 * info["distance_to_goal"])
    assert info["elapsed_time"] == pytest.approx(DIFF_DRIVE_MANEUVER.effort_final_time)
    assert info["effort"] == pytest.approx((0.04 + 0.01) * DIFF_DRIVE_MANEUVER.max_wheel_torque**2
                                           * DIFF_DRIVE_MANEUVER.effort_final_time, rel=1e-6)


def test_effort_horizon_must_be_a_whole_number_of_steps() -> None:
    with pytest.raises(ValueError, match="whole number"):
        make(objective="effort", time_step=0.01, frame_skip=7)
    with pytest.raises(ValueError, match="objective"):
        make(objective="distance")
