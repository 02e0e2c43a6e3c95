"""Equations of the bouncing ball: a point mass in gravity over the ground y = r."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from mechanics.models.lagrange import (
    forces,
    inputs,
    lagrangian_forces,
    mass,
    smooth_energy_balance,
)

from mdi_envs.mechanics.models import BouncingBall, BouncingBallParameters

Model = BouncingBall
HYPOTHESIS = settings(max_examples=50, deadline=None, derandomize=True, database=None)
coordinates = st.floats(-100.0, 100.0)
parameter_sets = st.builds(
    BouncingBallParameters,
    mass=st.floats(1e-3, 1e3), radius=st.floats(1e-3, 10.0), gravity=st.floats(0.0, 30.0),
    restitution=st.floats(0.0, 1.0), friction_coefficient=st.floats(0.0, 2.0),
)  # fmt: skip


def potential(q: np.ndarray, p: object) -> float:
    """V = m g y [J]."""
    return p.mass * p.gravity * q[1]  # type: ignore[attr-defined]


@HYPOTHESIS
@given(coordinates, coordinates, coordinates, coordinates, parameter_sets)
def test_equations_against_closed_forms(x: float, y: float, vx: float, vy: float,
                                        parameters: BouncingBallParameters) -> None:  # fmt: skip
    q, u, p = np.array([x, y]), np.array([vx, vy]), parameters.values()
    m = mass(Model, q, p)
    np.testing.assert_array_equal(m, np.diag([p.mass, p.mass]))
    assert np.linalg.eigvalsh(m).min() > 0.0
    expected = lagrangian_forces(Model, q, u, p, potential)
    np.testing.assert_allclose(forces(Model, q, u, p), expected, rtol=1e-8,
                               atol=1e-8 * (1.0 + p.mass * p.gravity))  # fmt: skip
    np.testing.assert_array_equal(inputs(Model, q, p), [[1.0], [0.0]])
    # Gap and contact rows: the normal row is the gradient of the gap, the tangent row a unit
    # vector orthogonal to it.
    (gap,) = Model.gaps(q, p, math)
    assert gap == y - p.radius
    normal, tangent = (np.array(row) for row in Model.contact_directions(q, p, math))
    step = 1e-6
    gradient = [(Model.gaps(q + e, p, math)[0] - Model.gaps(q - e, p, math)[0]) / (2 * step)
                for e in np.eye(2) * step]  # fmt: skip
    np.testing.assert_allclose(normal, gradient, rtol=0, atol=1e-6)
    assert normal @ tangent == 0.0 and tangent @ tangent == 1.0
    assert Model.restitutions(p) == (p.restitution,)
    assert Model.friction_coefficients(p) == (p.friction_coefficient,)


def test_smooth_energy_balance() -> None:
    """E = m |u|^2 / 2 + m g y changes by the work of the horizontal force only."""
    p = BouncingBallParameters().values()
    def push(t: float) -> np.ndarray:
        return np.array([0.3 * math.cos(3 * t)])

    q0, u0 = np.array([0.0, 2.0]), np.array([1.0, 3.0])
    change, work = smooth_energy_balance(Model, p, potential, q0, u0, push, 2.0)
    assert np.abs(work).max() > 1e-2
    np.testing.assert_allclose(change, work, rtol=0, atol=1e-10)


def test_default_parameters() -> None:
    p = BouncingBallParameters()
    assert p.values() == (0.1, 0.05, 9.81, 0.8, 0.0)
    assert Model.NUM_DOFS == 2 and Model.NUM_CONTACTS == 1 and Model.CONTACT_DIMENSION == 2
    assert Model.HAS_CONSTANT_MASS and Model.NUM_BRAKES == 0
