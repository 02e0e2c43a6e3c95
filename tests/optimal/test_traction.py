"""``optimal.traction``: the friction factor that explains measured steps of the robot."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters, DiffDriveRobot
from mdi_envs.stepping import MoreauJeanStepper
from optimal.traction import FrictionEstimator, scaled_friction

DT = 0.025
WEIGHT = np.array([1.0, 1.0, 0.0, 0.0, 0.0]) / 0.05**2  # the chassis velocity
SPIN = np.array([3.0, -3.0])  # [N m] beyond the rolling traction: both wheels slip
HOLD = np.array([0.2, 0.2])  # [N m] at rest, below the skid's static friction: all stick


def _measured(parameters: DiffDriveParameters, tau: np.ndarray, steps: int,
              speed: float = 0.5) -> list[tuple[np.ndarray, ...]]:
    """``steps`` steps (q, u, tau, u') of ``parameters`` from rolling forward at ``speed``."""
    stepper = MoreauJeanStepper(DiffDriveRobot, parameters, DT)
    q, u = np.zeros(5), np.array([speed, 0.0, 0.0, 10 * speed, 10 * speed])
    result = []
    for _ in range(steps):
        nxt = stepper.step(q, u, tau)
        result.append((q, u, tau, nxt.u))
        q, u = nxt.q, nxt.u
    return result


@pytest.mark.parametrize("factor", [0.8, 1.2, 0.913])
def test_a_slipping_step_gives_the_floors_friction(factor: float) -> None:
    """On the grid or between its points, one slipping step is enough."""
    nominal = DiffDriveParameters()
    estimator = FrictionEstimator(DiffDriveRobot, nominal, DT, WEIGHT)
    for step in _measured(scaled_friction(nominal, factor), SPIN, 3):
        estimator.update(*step)
        assert estimator.factor == pytest.approx(factor, abs=1e-4)
    estimator.reset()
    assert estimator.factor == 1.0


def test_while_every_contact_sticks_the_estimate_holds() -> None:
    """At rest on a floor with 20 % less grip, held by static friction: the estimate stays.

    Friction enters no step there (its impulses are reactions).
    """
    nominal = DiffDriveParameters()
    estimator = FrictionEstimator(DiffDriveRobot, nominal, DT, WEIGHT)
    for factor in (1.0, 1.3):
        estimator.factor = factor
        for q, u, tau, u_next in _measured(scaled_friction(nominal, 0.8), HOLD, 5, speed=0.0):
            np.testing.assert_allclose(u_next, 0.0, atol=1e-12)
            assert estimator.update(q, u, tau, u_next) == factor


def test_a_mass_the_model_does_not_know_fits_no_friction() -> None:
    """10 % more mass, turning with the skid sliding: the estimate stays at the model's.

    No factor reproduces both chassis velocities.
    """
    nominal = DiffDriveParameters()
    heavier = dataclasses.replace(nominal, mass=1.1 * nominal.mass)
    estimator = FrictionEstimator(DiffDriveRobot, nominal, DT, WEIGHT)
    for step in _measured(heavier, np.array([2.0, 1.0]), 5):
        assert estimator.update(*step) == 1.0


def test_parameters_without_friction_are_refused() -> None:
    @dataclasses.dataclass
    class Frictionless:
        mass: float = 1.0

    with pytest.raises(ValueError, match="no \\*_friction field"):
        scaled_friction(Frictionless(), 0.5)
    scaled = scaled_friction(DiffDriveParameters(), 0.5)
    assert (scaled.wheel_friction, scaled.stick_friction) == (0.3, 0.15)
