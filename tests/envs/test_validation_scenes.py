"""The validation scenes BouncingBall-v0 and SlidingBlock-v0 against their closed forms.

Through the environments (zero action): the ball's first impact time, first apex and Zeno
accumulation time; the block's sliding acceleration, exact sticking under a holding force and
its up-slope acceleration. A hand-written PD controller solves each scene; invalid physics and
NaN actions raise ValueError. (The generic API contracts are in test_api.py.)
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import mdi_envs  # noqa: F401  (registers the ids)
from mdi_envs.mechanics.models.bouncing_ball import BouncingBallParameters
from mdi_envs.mechanics.models.sliding_block import SlidingBlockParameters

BALL_ID = "mdi_envs/BouncingBall-v0"
BLOCK_ID = "mdi_envs/SlidingBlock-v0"


def make(env_id: str, **kwargs: Any) -> gym.Env[Any, Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return gym.make(env_id, **kwargs)


ZERO = np.zeros(1, np.float32)


# -- bouncing ball -----------------------------------------------------------------------------
def test_ball_free_fall_impacts_and_zeno_rest_match_closed_forms() -> None:
    env = make(BALL_ID, reset_noise_scale=0.0)
    p = env.unwrapped.scene.parameters
    dt = env.unwrapped.dt
    eps, g, r = p.restitution, p.gravity, p.radius
    drop = 1.0 - r  # the centre starts 1 m up: the fall to contact
    t1 = math.sqrt(2.0 * drop / g)
    t_inf = t1 * (1.0 + eps) / (1.0 - eps)
    obs, _ = env.reset(seed=0)
    assert obs[1] == pytest.approx(drop) and obs[3] == 0.0
    times, gaps, speeds = [], [], []
    num_steps = round((t_inf + 0.2) / dt)
    for _ in range(num_steps):
        obs, _, terminated, truncated, info = env.step(ZERO)
        assert not terminated and not truncated  # x stays at 0, 1 m from the goal
        assert info["solver_status"] == 0
        times.append(info["elapsed_time"])
        gaps.append(float(obs[1]))
        speeds.append(float(obs[3]))
        assert obs[0] == pytest.approx(-1.0) and obs[2] == 0.0  # no friction, no force
    times_a, gaps_a, speeds_a = np.array(times), np.array(gaps), np.array(speeds)
    # first impact: the first env step that ends moving up contains it
    first_up = int(np.argmax(speeds_a > 0.0))
    assert times_a[first_up] - dt <= t1 + 1e-9 <= times_a[first_up] + dt
    assert abs(times_a[first_up] - t1) <= dt
    # its rebound speed: eps times the impact speed sqrt(2 g drop), to O(g dt)
    assert speeds_a[first_up] == pytest.approx(eps * math.sqrt(2.0 * g * drop), abs=2 * g * dt)
    # first apex after the bounce: eps^2 (h0 - r) above contact, within O(dt)
    second_up = first_up + int(np.argmax(speeds_a[first_up:] < 0.0))
    apex = gaps_a[first_up : second_up + 1].max()
    time_step = env.unwrapped.scene.stepper.time_step
    impact_speed = math.sqrt(2.0 * g * drop)
    assert apex == pytest.approx(eps**2 * drop, abs=2.0 * impact_speed * time_step)
    # still bouncing well before t_inf, at rest on the ground shortly after it
    before = times_a <= 0.9 * t_inf
    assert np.abs(speeds_a[before][-20:]).max() > 0.1
    after = times_a >= t_inf + 0.1
    assert np.abs(gaps_a[after]).max() <= 1e-4
    assert np.abs(speeds_a[after]).max() <= 1e-6
    # at rest the contact carries the weight: P_N = m g dt over an env step
    assert info["normal_impulse"] == pytest.approx(p.mass * g * env.unwrapped.dt)
    assert info["num_active_contacts"] == 1
    assert info["penetration"] <= 1e-4


def test_ball_pd_controller_reaches_the_goal() -> None:
    env = make(BALL_ID)
    scene = env.unwrapped.scene
    kp, kd = 0.4, 0.4  # [N/m], [N s/m]: critically damped for the 0.1 kg ball (2 rad/s)
    obs, _ = env.reset(seed=3)
    terminated = truncated = False
    info: dict[str, Any] = {}
    while not (terminated or truncated):
        force = -kp * obs[0] - kd * obs[2]
        obs, _, terminated, truncated, info = env.step(
            np.array([force / scene.max_force], np.float32)
        )
    assert terminated and not truncated and info["is_success"]
    assert abs(obs[0]) <= 0.02 and abs(obs[2]) <= 0.05
    assert abs(obs[1]) <= 1e-3 and abs(obs[3]) <= 0.05


def test_ball_friction_brakes_the_horizontal_motion_at_impacts() -> None:
    env = make(BALL_ID, reset_noise_scale=0.0, friction_coefficient=0.5)
    env.reset(seed=0)
    env.unwrapped.set_state(np.array([0.0, 1.0]), np.array([2.0, 0.0]))
    speeds = []
    for _ in range(100):
        obs, *_ = env.step(ZERO)
        speeds.append(float(obs[2]))
    assert speeds[0] == pytest.approx(2.0)  # free flight: x' constant
    assert speeds[-1] < 2.0 - 1e-3  # the impacts' friction impulses slowed it
    assert np.all(np.diff(speeds) <= 1e-12)  # friction never accelerates


# -- sliding block -----------------------------------------------------------------------------
def block_constants(env: gym.Env[Any, Any]) -> tuple[float, float, float, float]:
    p = env.unwrapped.scene.parameters
    return p.mass, p.gravity, p.slope_angle, p.friction_coefficient


def test_block_slides_down_at_the_coulomb_acceleration() -> None:
    env = make(BLOCK_ID, reset_noise_scale=0.0)
    m, g, theta, mu = block_constants(env)
    assert math.tan(theta) > mu  # the default slope is steeper than the friction angle
    acceleration = g * (math.sin(theta) - mu * math.cos(theta))
    env.reset(seed=0)
    for k in range(1, 31):
        obs, _, _, _, info = env.step(ZERO)
        t = k * env.unwrapped.dt
        assert obs[1] == pytest.approx(acceleration * t, rel=1e-9)
        assert obs[2] == 0.0 and info["is_sticking"] == 0.0
    assert info["friction_impulse"] == pytest.approx(
        -mu * info["normal_impulse"]
    )  # sliding: P_T on the cone's edge, opposing s' > 0
    assert info["normal_impulse"] == pytest.approx(
        m * g * math.cos(theta) * env.unwrapped.dt
    )  # summed over the env step's physics steps


@pytest.mark.parametrize("fraction", [0.01, 0.5, 0.99])
def test_block_sticks_exactly_under_a_holding_force_in_the_cone(fraction: float) -> None:
    env = make(BLOCK_ID, reset_noise_scale=0.0)
    m, g, theta, mu = block_constants(env)
    low = -m * g * (math.sin(theta) + mu * math.cos(theta))
    high = -m * g * (math.sin(theta) - mu * math.cos(theta))
    force = high + fraction * (low - high)
    action = np.array([force / env.unwrapped.scene.max_force], np.float32)
    env.reset(seed=0)
    for _ in range(50):
        obs, _, _, _, info = env.step(action)
        assert abs(env.unwrapped.q[0]) <= 1e-12 and abs(obs[1]) <= 1e-12  # to round-off
        assert obs[2] == 1.0 and info["is_sticking"] == 1.0


def test_block_pushed_up_accelerates_at_the_closed_form() -> None:
    env = make(BLOCK_ID, reset_noise_scale=0.0)
    m, g, theta, mu = block_constants(env)
    force = -0.75 * env.unwrapped.scene.max_force  # beyond the cone: -15 N vs -9.01 N
    acceleration = force / m + g * (math.sin(theta) + mu * math.cos(theta))
    assert acceleration < 0.0
    env.reset(seed=0)
    for k in range(1, 11):
        obs, *_ = env.step(np.array([-0.75], np.float32))
        assert obs[1] == pytest.approx(acceleration * k * env.unwrapped.dt, rel=1e-9)


def test_block_pd_controller_reaches_the_goal() -> None:
    env = make(BLOCK_ID)
    m, g, theta, _ = block_constants(env)
    scene = env.unwrapped.scene
    kp, kd = 400.0, 40.0  # [N/m], [N s/m]: critically damped at 20 rad/s for 1 kg
    obs, _ = env.reset(seed=3)
    terminated = truncated = False
    info: dict[str, Any] = {}
    steps = 0
    while not (terminated or truncated):
        force = -m * g * math.sin(theta) - kp * obs[0] - kd * obs[1]  # gravity compensated
        obs, _, terminated, truncated, info = env.step(
            np.array([force / scene.max_force], np.float32)
        )
        steps += 1
    assert terminated and not truncated and info["is_success"]
    assert abs(obs[0]) <= 0.02 and abs(obs[1]) <= 0.02
    assert steps * env.unwrapped.dt < 2.0


# -- invalid arguments -------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("env_id", "kwargs", "field"),
    [
        (BALL_ID, {"parameters": "mass=-0.1"}, "mass"),
        (BALL_ID, {"friction_coefficient": -0.1}, "friction_coefficient"),
        (BALL_ID, {"restitution": 1.5}, "restitution"),
        (BALL_ID, {"restitution": -0.1}, "restitution"),
        (BALL_ID, {"time_step": 0.0}, "time_step"),
        (BALL_ID, {"time_step": -1e-3}, "time_step"),
        (BALL_ID, {"max_force": 0.0}, "max_force"),
        (BLOCK_ID, {"parameters": "mass=-1.0"}, "mass"),
        (BLOCK_ID, {"friction_coefficient": -0.5}, "friction_coefficient"),
        (BLOCK_ID, {"restitution": 2.0}, "restitution"),
        (BLOCK_ID, {"slope_angle": 2.0}, "slope_angle"),
        (BLOCK_ID, {"time_step": 0.0}, "time_step"),
        (BLOCK_ID, {"max_force": -1.0}, "max_force"),
    ],
)
def test_invalid_physics_raise_value_error_naming_the_field(
    env_id: str, kwargs: dict[str, Any], field: str
) -> None:
    with pytest.raises(ValueError, match=field):
        if "parameters" in kwargs:  # the dataclass validates on construction
            name, value = kwargs["parameters"].split("=")
            parameters_class = (
                BouncingBallParameters if env_id == BALL_ID else SlidingBlockParameters
            )
            make(env_id, parameters=parameters_class(**{name: float(value)}))
        else:
            make(env_id, **kwargs)


@pytest.mark.parametrize("env_id", [BALL_ID, BLOCK_ID])
def test_wrong_parameters_type_and_nan_action_raise(env_id: str) -> None:
    with pytest.raises(ValueError, match="parameters"):
        make(env_id, parameters={"mass": 1.0})
    env = make(env_id)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="NaN"):
        env.step(np.array([np.nan], np.float32))


def test_convenience_arguments_override_the_parameters() -> None:
    env = make(BALL_ID, parameters=BouncingBallParameters(mass=0.2), restitution=0.5)
    p = env.unwrapped.scene.parameters
    assert (p.mass, p.restitution, p.friction_coefficient) == (0.2, 0.5, 0.0)
    env = make(BLOCK_ID, friction_coefficient=0.7, slope_angle=0.3)
    p = env.unwrapped.scene.parameters
    assert (p.friction_coefficient, p.slope_angle, p.mass) == (0.7, 0.3, 1.0)
