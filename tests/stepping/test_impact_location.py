"""``MoreauJeanStepper(..., locate_impacts=True)``: steps split at the impact time.

With constant gravity and a flat ground the located step is exact for every isolated impact:
flight to the impact time (a root of the gap's quadratic), Newton's law, flight on. So the
bouncing ball's grid positions and velocities must equal the closed-form piecewise parabola to
rounding, bounce after bounce, where the midpoint step is off by O(|v| dt). Steps without an
impact must be the midpoint step's, exactly.
"""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest

import mdi_envs  # noqa: F401 - registers the ids
from mdi_envs.mechanics.models import (
    BlockableManipulator,
    BouncingBall,
    DiffDriveRobot,
    SlidingBlock,
)
from mdi_envs.stepping import MoreauJeanStepper

GRAVITY = 9.81
RADIUS = 0.05
HEIGHTS = np.random.default_rng(1).uniform(0.9, 1.1, 16)  # drop gaps h0 [m]


def located(model: type, time_step: float, **parameters: float) -> MoreauJeanStepper:
    return MoreauJeanStepper(model, model.Parameters(**parameters), time_step,
                             locate_impacts=True)  # fmt: skip


def run(stepper: MoreauJeanStepper, heights: np.ndarray, num_steps: int
        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """Drop from rest at gaps ``heights``: (y, v, normal impulse), rows are steps 0..N."""
    q = np.column_stack([np.zeros_like(heights), RADIUS + heights])
    u = np.zeros_like(q)
    tau = np.zeros((len(heights), 1))
    y, v, p_n = [q[:, 1].copy()], [u[:, 1].copy()], [np.zeros(len(heights))]
    for _ in range(num_steps):
        impulses, _ = stepper.step_batch(q, u, tau)
        y.append(q[:, 1].copy())
        v.append(u[:, 1].copy())
        p_n.append(impulses[:, 0].copy())
    return np.array(y), np.array(v), np.array(p_n)


def exact_drop(h0: float, eps: float, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form gap and velocity of a ball dropped from rest at gap h0 (before Zeno)."""
    gap, velocity = np.empty_like(times), np.empty_like(times)
    t_hit, v_up = np.sqrt(2.0 * h0 / GRAVITY), 0.0
    start, g_start, v_start = 0.0, h0, 0.0
    for i, t in enumerate(times):
        while t > t_hit:  # past the next impact: start the next flight there
            assert t_hit > start, "past the Zeno point"
            v_up = eps * np.sqrt(v_start**2 + 2.0 * GRAVITY * g_start)
            start, g_start, v_start = t_hit, 0.0, v_up
            t_hit = start + 2.0 * v_up / GRAVITY
        s = t - start
        gap[i] = g_start + v_start * s - 0.5 * GRAVITY * s**2
        velocity[i] = v_start - GRAVITY * s
    return gap, velocity


@pytest.mark.parametrize("eps", [0.5, 0.8, 1.0])
def test_located_drop_is_the_closed_form_to_rounding(eps: float) -> None:
    dt = 1e-3
    t_third = np.sqrt(2.0 * HEIGHTS / GRAVITY) * (1.0 + 2.0 * eps + 2.0 * eps**2)
    num_steps = int(1.02 * t_third.max() / dt)  # three impacts for every height
    assert eps == 1.0 or num_steps * dt < np.sqrt(2.0 * HEIGHTS.min() / GRAVITY) * (
        1.0 + eps) / (1.0 - eps)  # before the lowest drop's Zeno point
    y, v, p_n = run(located(BouncingBall, dt, restitution=eps), HEIGHTS, num_steps)
    times = dt * np.arange(num_steps + 1)
    for c, h0 in enumerate(HEIGHTS):
        gap, velocity = exact_drop(float(h0), eps, times)
        assert np.abs(y[:, c] - RADIUS - gap).max() <= 1e-9
        assert np.abs(v[:, c] - velocity).max() <= 1e-9
        assert np.count_nonzero(p_n[:, c]) >= 3  # one step per impact carries its impulse
    plain = MoreauJeanStepper(BouncingBall, BouncingBall.Parameters(restitution=eps), dt)
    y_plain, _, _ = run(plain, HEIGHTS, num_steps)
    assert (y_plain - RADIUS).min() < -1e-3  # the midpoint step's penetration, O(|v| dt)
    assert (y - RADIUS).min() >= -1e-12


def test_steps_without_a_closing_contact_are_the_midpoint_steps() -> None:
    """Free flight, rest on the ground and the block's persistent contact: identical."""
    dt = 1e-3
    for model, parameters, q0, u0, tau in (
        (BouncingBall, {}, [0.0, 1.0], [0.3, 0.0], [0.0]),  # flight, no impact in 400 steps
        (BouncingBall, {"restitution": 0.0}, [0.0, RADIUS], [0.0, 0.0], [0.5]),  # resting
        (SlidingBlock, {}, [0.0, 0.0], [0.2, 0.0], [3.0]),  # on the slope, pushed
    ):
        plain = MoreauJeanStepper(model, model.Parameters(**parameters), dt)
        split = located(model, dt, **parameters)
        qa, ua = np.array([q0]), np.array([u0])
        qb, ub = qa.copy(), ua.copy()
        for _ in range(400):
            ia, _ = plain.step_batch(qa, ua, np.array([tau]))
            ib, _ = split.step_batch(qb, ub, np.array([tau]))
            assert np.array_equal(qa, qb) and np.array_equal(ua, ub)
            assert np.array_equal(ia, ib)


@pytest.mark.parametrize("eps", [0.0, 0.5, 0.8])
def test_located_ball_comes_to_rest_without_energy_gain(eps: float) -> None:
    """Rest by the Zeno time within a few steps, without energy gain or penetration.

    No step gains more than g^2 dt^2 (the midpoint step's own bound in the Zeno phase).
    """
    dt = 1e-3
    t_inf = np.sqrt(2.0 * HEIGHTS / GRAVITY) * (1.0 + eps) / (1.0 - eps)
    y, v, _ = run(located(BouncingBall, dt, restitution=eps), HEIGHTS, int(1.5 * t_inf.max() / dt))
    energy = 0.5 * v**2 + GRAVITY * (y - RADIUS)
    assert np.diff(energy, axis=0).max() <= GRAVITY**2 * dt**2
    for c, t in enumerate(t_inf):
        after = int(np.ceil(t / dt)) + 5
        assert np.abs(v[after:, c]).max() <= GRAVITY * dt  # at rest (one step's gravity)
        assert np.abs(y[after:, c] - RADIUS).max() <= GRAVITY * dt**2
    assert (y - RADIUS).min() >= -GRAVITY * dt**2


def test_locate_impacts_is_refused_where_it_does_not_apply() -> None:
    with pytest.raises(ValueError, match="locate_impacts.*BlockableManipulator.*1 brakes"):
        MoreauJeanStepper(BlockableManipulator, locate_impacts=True)
    with pytest.raises(ValueError, match="locate_impacts.*DiffDriveRobot.*dimension 3"):
        MoreauJeanStepper(DiffDriveRobot, locate_impacts=True)


def test_bouncing_ball_env_takes_the_option_and_pickles() -> None:
    """Through gym.make (and its default off); no penetration over the first bounces."""
    penetration = {}
    for locate in (False, True):
        env = gym.make("mdi_envs/BouncingBall-v0", locate_impacts=locate)
        env.reset(seed=0)
        worst = 0.0
        for _ in range(150):  # 1.5 s: three impacts of the 0.95 m drop
            _, _, _, _, info = env.step(np.zeros(1, np.float32))
            worst = max(worst, info["penetration"])
        penetration[locate] = worst
        stepper = env.unwrapped.scene.stepper
        assert pickle.loads(pickle.dumps(stepper)).locate_impacts == locate
        env.close()
    assert penetration[True] <= 1e-12
