"""BlockableManipulator-v0: the brake through the env, the three action modes, the task's end."""

from __future__ import annotations

import warnings
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import mdi_envs  # noqa: F401 - registers the ids
from mdi_envs.maneuvers import MANIPULATOR_MANEUVER

ENV_ID = "mdi_envs/BlockableManipulator-v0"


def make(**kwargs: Any) -> gym.Env[Any, Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return gym.make(ENV_ID, **kwargs)


def test_engaged_brake_blocks_the_relative_motion_at_once() -> None:
    env = make(reset_noise_scale=0.0)
    env.reset(seed=0)
    for _ in range(20):  # spin up with the brake released: the links move relative
        env.step(np.array([1.0, -1.0], np.float32))
    u = env.unwrapped.u
    assert abs(u[1] - u[0]) > 0.1
    for _ in range(10):
        info = env.step(np.array([1.0, 1.0], np.float32))[4]
        u = env.unwrapped.u
        assert info["brake_engaged"]
        assert abs(u[1] - u[0]) <= 1e-12 * (1.0 + np.abs(u).max())


def test_brake_impulse_is_the_sum_over_the_physics_steps_of_an_env_step() -> None:
    """At an engagement the impact falls in the first physics step; the info reports it."""
    env = make(reset_noise_scale=0.0)
    env.reset(seed=0)
    for _ in range(20):
        env.step(np.array([1.0, -1.0], np.float32))
    scene = env.unwrapped.scene
    q, u = env.unwrapped.q, env.unwrapped.u
    steps = []
    for _ in range(scene.frame_skip):  # the same physics steps, one at a time
        result = scene.stepper.step(q, u, [scene.max_torque], [np.inf])
        q, u = result.q, result.u
        steps.append(result.impulses[0])
    info = env.step(np.array([1.0, 1.0], np.float32))[4]
    np.testing.assert_allclose(env.unwrapped.q, q, rtol=1e-13, atol=1e-13)
    assert info["brake_impulse"] == pytest.approx(sum(steps), rel=1e-12)
    assert scene.frame_skip == 2 and abs(steps[0]) > 10.0 * abs(steps[1])  # the impact first


def test_hybrid_action_mode_matches_the_box_mode() -> None:
    box, hybrid = make(), make(action_mode="hybrid")
    assert isinstance(hybrid.action_space, gym.spaces.Tuple)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(hybrid.unwrapped, skip_render_check=True)
    box.reset(seed=2)
    hybrid.reset(seed=2)
    rng = np.random.default_rng(0)
    for _ in range(50):
        torque, engaged = rng.uniform(-1, 1), int(rng.integers(2))
        obs_box = box.step(np.array([torque, 1.0 if engaged else -1.0], np.float32))[0]
        obs_hybrid = hybrid.step((engaged, np.array([torque], np.float32)))[0]
        np.testing.assert_array_equal(obs_box, obs_hybrid)
    with pytest.raises(ValueError, match="brake choice"):
        hybrid.unwrapped.step((2, np.zeros(1, np.float32)))


def test_brake_force_mode_is_a_tresca_element() -> None:
    """Level -1 releases; level b bounds |P_B| by a dt, a = max_brake_torque (b + 1) / 2."""
    released, weak = make(action_mode="brake_force"), make(action_mode="brake_force")
    box = make()
    for env in (released, weak, box):
        env.reset(seed=4)
    dt = released.unwrapped.dt  # the info sums the impulses of the env step's physics steps
    level = float(np.float32(-0.998))  # the value the float32 action carries
    bound = 0.5 * 50.0 * (level + 1.0)  # 0.05 N m: too weak to hold, the brake slips
    for _ in range(30):
        obs_released = released.step(np.array([1.0, -1.0], np.float32))[0]
        obs_box = box.step(np.array([1.0, -1.0], np.float32))[0]
        info = weak.step(np.array([1.0, level], np.float32))[4]
        impulse, u = abs(info["brake_impulse"]), weak.unwrapped.u
        assert impulse <= bound * dt * (1 + 1e-12)
        if impulse < bound * dt * (1 - 1e-9):  # below the bound the brake sticks
            assert abs(u[1] - u[0]) <= 1e-12
        np.testing.assert_array_equal(obs_released, obs_box)
    assert abs(u[1] - u[0]) > 1e-3 and impulse == pytest.approx(bound * dt, rel=1e-12)


def test_reaching_the_goal_at_rest_terminates_with_success() -> None:
    env = make(shaping_weight=0.0)
    env.reset(seed=0)
    env.unwrapped.set_state(np.array(MANIPULATOR_MANEUVER.goal_q) + 0.01, np.zeros(2))
    obs, reward, terminated, truncated, info = env.step(np.array([0.0, 1.0], np.float32))
    assert terminated and not truncated and info["is_success"]
    assert reward == pytest.approx(-env.unwrapped.dt, abs=1e-15)


def test_shaping_telescopes_to_the_potential_difference() -> None:
    """With gamma = 1 the shaping terms of an episode sum to Phi(s_end) - Phi(s_0)."""
    env = make(shaping_discount=1.0, reset_noise_scale=0.0)
    env.reset(seed=0)
    total, distance = 0.0, None
    for _ in range(40):
        info = env.step(np.array([0.7, -1.0], np.float32))[4]
        total += info["reward_shaping"]
        distance = info["distance_to_goal"]
    start = np.sqrt(2.0) * np.pi  # both wrapped angle errors pi, at rest
    assert total == pytest.approx(-distance + start, rel=1e-12)


def test_time_step_and_frame_skip_set_the_env_dt() -> None:
    env = make(time_step=0.005, frame_skip=4)
    assert env.unwrapped.dt == pytest.approx(0.02)
    assert env.metadata["render_fps"] == 50
    with pytest.raises(ValueError, match="time_step"):
        make(time_step=-1.0)
    with pytest.raises(ValueError, match="frame_skip"):
        make(frame_skip=0)
    with pytest.raises(ValueError, match="action_mode"):
        make(action_mode="joystick")
    with pytest.raises(ValueError, match="max_torque"):
        make(max_torque=float("nan"))
