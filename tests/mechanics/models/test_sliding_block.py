"""Equations of the block on a slope: gravity in slope coordinates (s down-slope, n normal)."""

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

from mdi_envs.mechanics.models import SlidingBlock, SlidingBlockParameters

Model = SlidingBlock
HYPOTHESIS = settings(max_examples=50, deadline=None, derandomize=True, database=None)
coordinates = st.floats(-100.0, 100.0)
parameter_sets = st.builds(
    SlidingBlockParameters,
    mass=st.floats(1e-3, 1e3), gravity=st.floats(0.0, 30.0),
    slope_angle=st.floats(0.0, math.pi / 2 - 1e-6), restitution=st.floats(0.0, 1.0),
    friction_coefficient=st.floats(0.0, 2.0),
)  # fmt: skip


def potential(q: np.ndarray, p: object) -> float:
    """V = m g * height, height = n cos(theta) - s sin(theta) (s points down the slope)."""
    theta = p.slope_angle  # type: ignore[attr-defined]
    return p.mass * p.gravity * (q[1] * math.cos(theta) - q[0] * math.sin(theta))  # type: ignore[attr-defined]


@HYPOTHESIS
@given(coordinates, coordinates, coordinates, coordinates, parameter_sets)
def test_equations_against_closed_forms(s: float, n: float, vs: float, vn: float,
                                        parameters: SlidingBlockParameters) -> None:  # fmt: skip
    q, u, p = np.array([s, n]), np.array([vs, vn]), parameters.values()
    m = mass(Model, q, p)
    np.testing.assert_array_equal(m, np.diag([p.mass, p.mass]))
    assert np.linalg.eigvalsh(m).min() > 0.0
    weight = p.mass * p.gravity
    expected = lagrangian_forces(Model, q, u, p, potential)
    np.testing.assert_allclose(forces(Model, q, u, p), expected, rtol=0, atol=1e-7 * (1.0 + weight))
    np.testing.assert_allclose(
        forces(Model, q, u, p),
        [weight * math.sin(p.slope_angle), -weight * math.cos(p.slope_angle)], rtol=1e-15,
    )
    np.testing.assert_array_equal(inputs(Model, q, p), [[1.0], [0.0]])
    (gap,) = Model.gaps(q, p, math)
    assert gap == n
    normal, tangent = (np.array(row) for row in Model.contact_directions(q, p, math))
    np.testing.assert_array_equal(normal, [0.0, 1.0])  # = grad g
    np.testing.assert_array_equal(tangent, [1.0, 0.0])
    assert Model.restitutions(p) == (p.restitution,)
    assert Model.friction_coefficients(p) == (p.friction_coefficient,)


def test_smooth_energy_balance() -> None:
    """Off the slope: E = T + V changes by the work of the push only."""
    p = SlidingBlockParameters().values()
    def push(t: float) -> np.ndarray:
        return np.array([2.0 * math.sin(5 * t)])

    q0, u0 = np.array([0.0, 1.0]), np.array([0.5, 2.0])
    change, work = smooth_energy_balance(Model, p, potential, q0, u0, push, 1.0)
    assert np.abs(work).max() > 1e-2
    np.testing.assert_allclose(change, work, rtol=0, atol=1e-10)


def test_default_parameters() -> None:
    p = SlidingBlockParameters()
    assert p.values() == (1.0, 9.81, 0.5, 0.0, 0.5)
    # The documented default slides: tan(0.5) = 0.546 > mu = 0.5.
    assert math.tan(p.slope_angle) > p.friction_coefficient
