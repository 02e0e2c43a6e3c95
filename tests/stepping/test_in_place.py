"""``InPlaceStepper`` steps one copy exactly as ``MoreauJeanStepper.step`` does."""

from __future__ import annotations

import numpy as np
import pytest

from mdi_envs.mechanics import BlockableManipulator, BouncingBall, DiffDriveRobot
from mdi_envs.stepping import MoreauJeanStepper


def test_in_place_steps_equal_step_through_a_brake_schedule() -> None:
    stepper = MoreauJeanStepper(BlockableManipulator, time_step=1e-3)
    arm = stepper.in_place([0.0, 0.3], [0.0, 0.0])
    q, u = np.array([0.0, 0.3]), np.zeros(2)
    for k in range(1500):
        tau = 2.0 if (k // 200) % 2 == 0 else -2.0
        brake = (np.inf, 0.0, 0.4)[(k // 300) % 3]
        reference = stepper.step(q, u, [tau], [brake])
        arm.tau[0] = tau
        arm.brake_bound[0] = brake
        arm.step()
        q, u = reference.q, reference.u
        assert np.array_equal(arm.q, q) and np.array_equal(arm.u, u)
        assert np.array_equal(arm.impulses, reference.impulses)
        assert arm.status == reference.status


def test_in_place_ball_bounces_like_step() -> None:
    stepper = MoreauJeanStepper(BouncingBall, time_step=1e-3)
    ball = stepper.in_place([0.0, 0.5], [0.0, 0.0])
    q, u = np.array([0.0, 0.5]), np.zeros(2)
    for _ in range(1500):
        reference = stepper.step(q, u, [0.0])
        ball.step()
        q, u = reference.q, reference.u
        np.testing.assert_array_equal(ball.q, q)
    assert ball.impulses[0] >= 0.0


def test_in_place_robot_steps_equal_warm_started_step() -> None:
    """The robot's in-place steps equal warm-started ``step()`` bitwise.

    The spatial kernel runs through the in-place buffer (its int scratch an int64 view of
    it) under rolling, arc and wheel-spin torques.
    """
    stepper = MoreauJeanStepper(DiffDriveRobot, time_step=1e-3)
    robot = stepper.in_place(np.zeros(5), np.zeros(5))
    q, u, impulses = np.zeros(5), np.zeros(5), None
    for k in range(600):
        tau = [(0.5, 0.5), (0.2, 0.8), (5.0, 5.0)][k // 200]  # as benchmarks/engine_scenes
        reference = stepper.step(q, u, tau, warm_start=impulses)
        robot.tau[:] = tau
        robot.step()
        q, u, impulses = reference.q, reference.u, reference.impulses
        assert np.array_equal(robot.q, q) and np.array_equal(robot.u, u)
        assert np.array_equal(robot.impulses, impulses)
        assert robot.status == reference.status


@pytest.mark.parametrize(("field", "value", "message"), [
    ("tau", np.nan, "tau contains NaN"),
    ("u", np.inf, "u contains NaN"),
    ("brake_bound", -1.0, "brake_bound must be >= 0"),
])
def test_in_place_bad_inputs_raise_and_keep_the_state(field: str, value: float,
                                                      message: str) -> None:
    arm = MoreauJeanStepper(BlockableManipulator, time_step=1e-3).in_place([0.1, 0.2],
                                                                           [0.0, 0.0])
    getattr(arm, field)[0] = value
    q_before = arm.q.copy()
    with pytest.raises(ValueError, match=message):
        arm.step()
    np.testing.assert_array_equal(arm.q, q_before)


def test_in_place_rejects_wrong_state_shapes() -> None:
    stepper = MoreauJeanStepper(BlockableManipulator, time_step=1e-3)
    with pytest.raises(ValueError, match=r"q must have shape \(2,\)"):
        stepper.in_place([0.0, 0.0, 0.0], [0.0, 0.0])
