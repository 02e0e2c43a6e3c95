"""``baselines.heuristics``: the floors reach the goal the way they are meant to."""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from baselines import heuristics
from mdi_envs.maneuvers import MANIPULATOR_MANEUVER


def _play(env: gym.Env, policy: Callable[[np.ndarray], np.ndarray], seed: int,
          key: str) -> tuple[bool, dict[str, Any], list[Any]]:
    """One episode from ``reset(seed)``: (terminated, last info, ``info[key]`` per step)."""
    obs, _ = env.reset(seed=seed)
    values, done = [], False
    while not done:
        obs, _, terminated, truncated, info = env.step(policy(obs))
        values.append(info[key])
        done = terminated or truncated
    return terminated, info, values


def test_rigid_arm_bang_bang_takes_the_double_integrators_time() -> None:
    """Brake engaged throughout; time = the rigid body's bang-bang time into the goal box."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make("mdi_envs/BlockableManipulator-v1", reset_noise_scale=0.0)
    terminated, info, engaged = _play(env, heuristics.rigid_arm_bang_bang(env), 0,
                                      "brake_engaged")
    assert terminated and info["is_success"] and all(engaged)
    p = env.unwrapped.scene.parameters
    inertia = (p.link1_mass * p.link1_length**2 / 3 + p.link2_mass * p.link1_length**2
               + p.link2_mass * p.link1_length * p.link2_length
               + p.link2_mass * p.link2_length**2 / 3)  # rigid arm about the base
    a = env.unwrapped.scene.max_torque / inertia
    # full torque to the midpoint, full reverse until the speed falls to the tolerance
    expected = 2 * math.sqrt(math.pi / a) - MANIPULATOR_MANEUVER.velocity_tolerance / a
    assert info["elapsed_time"] == pytest.approx(expected, abs=3 * env.unwrapped.dt)


def test_speed_profile_is_the_fastest_within_the_acceleration_circle() -> None:
    """On a straight line: the triangle profile v = sqrt(2 a min(s, L - s)) (rest to rest)."""
    s = np.linspace(0.0, 2.0, 2001)
    v = heuristics.speed_profile(s, np.zeros_like(s), 1.5, 10.0)
    np.testing.assert_allclose(v, np.sqrt(2 * 1.5 * np.minimum(s, 2.0 - s)), atol=1e-9)
    capped = heuristics.speed_profile(s, np.zeros_like(s), 1.5, 1.0)
    assert capped.max() == pytest.approx(1.0)
    circle = heuristics.speed_profile(s, np.full_like(s, 2.0), 1.5, 10.0)  # radius 0.5 m
    assert circle.max() == pytest.approx(math.sqrt(1.5 / 2.0))  # v^2 k = a


def test_bezier_half_turn_is_close_to_a_semicircle() -> None:
    radius = 0.5
    s, xy, heading, curvature = heuristics.bezier_path(
        [(0.0, 0.0, math.pi / 2), (2 * radius, 0.0, -math.pi / 2)], [4 * radius / 3])
    # one cubic per half-turn: within 2 % of the circle's radius and length, a right turn
    assert s[-1] == pytest.approx(math.pi * radius, rel=0.02)
    assert heading[-1] - heading[0] == pytest.approx(-math.pi)
    np.testing.assert_allclose(np.hypot(xy[:, 0] - radius, xy[:, 1]), radius, rtol=0.02)
    np.testing.assert_allclose(curvature, -1 / radius, rtol=0.3)


def test_rolling_path_follower_reaches_the_goal_without_slipping() -> None:
    """Time objective from a perturbed start: at the goal, every step in the rolling mode."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make("mdi_envs/DiffDriveRobot-v1", reset_noise_scale=0.1)
    terminated, info, modes = _play(env, heuristics.rolling_path_follower(env), 3, "slip_mode")
    assert terminated and info["is_success"]
    assert set(modes) == {2}  # both wheels roll throughout


@pytest.mark.parametrize("behind", [False, True])
def test_parking_follower_drives_into_the_goal_forward_or_in_reverse(behind: bool) -> None:
    """Parking from rest 0.4 m before or behind the goal, the nominal model, 20 % less friction.

    Heading 0.1 rad off; driven forward from before the goal, in reverse from behind it: in
    the goal box within 2 s, both wheels rolling throughout.
    """
    from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER
    from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters

    nominal = DiffDriveParameters()
    slippery = dataclasses.replace(nominal, wheel_friction=0.8 * nominal.wheel_friction,
                                   stick_friction=0.8 * nominal.stick_friction)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make("mdi_envs/DiffDriveRobot-v1", reset_noise_scale=0.0, parameters=slippery)
    env.reset(seed=0)
    gx, gy, gphi = DIFF_DRIVE_MANEUVER.goal_pose  # heading -y: "before" is at larger y
    env.unwrapped.set_state(np.array([gx, gy + (-0.4 if behind else 0.4), gphi + 0.1, 0.0, 0.0]),
                            np.zeros(5))
    obs = env.unwrapped.state.obs[0].copy()
    policy = heuristics.parking_follower(nominal, env.unwrapped.dt,
                                         env.unwrapped.scene.max_wheel_torque, obs)
    speeds, done = [], False
    while not done:
        obs, _, terminated, truncated, info = env.step(policy(obs))
        speeds.append(float(obs[4]))  # forward speed, body frame
        assert info["slip_mode"] == 2
        done = terminated or truncated
    assert terminated and info["is_success"] and info["elapsed_time"] <= 2.0
    assert (max(speeds) if behind else -min(speeds)) < 0.01  # one direction throughout


@pytest.mark.parametrize("max_lag", [0.1, None])
def test_parking_clock_waits_for_a_heavier_robot(max_lag: float | None) -> None:
    """Parking in reverse from 0.31 m behind and 0.16 m beside the goal, 10 % more mass.

    The heading is 0.14 rad off, turned away from the goal's side, so the path bends one way
    and back. With the clock waiting (``max_lag``) the robot parks within 3 s; with the env's
    clock the heading turns on time while the heavier robot lags, and it stops at rest about
    0.1 m beside the goal, outside the box.
    """
    from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER
    from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters

    nominal = DiffDriveParameters()
    heavy = dataclasses.replace(nominal, mass=1.1 * nominal.mass)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make("mdi_envs/DiffDriveRobot-v1", reset_noise_scale=0.0, parameters=heavy,
                       max_episode_steps=125)
    env.reset(seed=0)
    gx, gy, gphi = DIFF_DRIVE_MANEUVER.goal_pose
    env.unwrapped.set_state(np.array([gx - 0.16, gy - 0.31, gphi + 0.14, 0.0, 0.0]), np.zeros(5))
    obs = env.unwrapped.state.obs[0].copy()
    policy = heuristics.parking_follower(nominal, env.unwrapped.dt,
                                         env.unwrapped.scene.max_wheel_torque, obs,
                                         max_lag=max_lag)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(policy(obs))
        done = terminated or truncated
    beside = abs(env.unwrapped.q[0] - gx)
    if max_lag is None:
        assert truncated and not info["is_success"] and beside > 0.05
    else:
        assert terminated and info["is_success"] and info["elapsed_time"] <= 3.0
