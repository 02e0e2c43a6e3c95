"""Equations of the blockable manipulator, derived again independently.

* M(q) against the kinetic energy of two uniform rods, integrated along the rods (Gauss
  quadrature, exact: point velocities are linear along a rod).
* h(q, u) against the Lagrangian derivation from M (finite differences), and along smooth
  motions (scipy's DOP853): dT/dt = tau alpha' and, for tau = 0, L = (1, 1) . M u constant.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mechanics.models.lagrange import (
    forces,
    inputs,
    lagrangian_forces,
    mass,
    smooth_energy_balance,
)
from scipy.integrate import solve_ivp

from mdi_envs.mechanics.models import BlockableManipulator, BlockableManipulatorParameters

Model = BlockableManipulator
DEFAULT = BlockableManipulatorParameters().values()
HYPOTHESIS = settings(max_examples=60, deadline=None, derandomize=True, database=None)
angles = st.floats(-10.0, 10.0)
rates = st.floats(-20.0, 20.0)
positive = st.floats(0.05, 20.0)
parameter_sets = st.builds(BlockableManipulatorParameters, positive, positive, positive, positive)


def rod_mass_matrix(q: np.ndarray, p: BlockableManipulatorParameters) -> np.ndarray:
    """Sum over both rods of integral rho J(s)^T J(s) ds, J = d(point position)/d(alpha, beta)."""
    alpha, beta = q
    nodes, weights = np.polynomial.legendre.leggauss(3)
    result = np.zeros((2, 2))
    e1 = np.array([-math.sin(alpha), math.cos(alpha)])  # d/dalpha of the link-1 direction
    e2 = np.array([-math.sin(beta), math.cos(beta)])
    for mass_, length, link in ((p.link1_mass, p.link1_length, 1),
                                (p.link2_mass, p.link2_length, 2)):  # fmt: skip
        for node, weight in zip(nodes, weights, strict=True):
            s = 0.5 * length * (node + 1.0)  # arc length from the rod's hinge
            jac = np.zeros((2, 2))
            if link == 1:
                jac[:, 0] = s * e1
            else:
                jac[:, 0] = p.link1_length * e1
                jac[:, 1] = s * e2
            result += (mass_ / length) * (0.5 * length * weight) * jac.T @ jac
    return result


@HYPOTHESIS
@given(angles, angles, parameter_sets)
def test_mass_matrix_is_the_rods_kinetic_energy(
    alpha: float, beta: float, parameters: BlockableManipulatorParameters
) -> None:
    q = np.array([alpha, beta])
    expected = rod_mass_matrix(q, parameters)
    actual = mass(Model, q, parameters.values())
    np.testing.assert_allclose(actual, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


@HYPOTHESIS
@given(angles, angles, parameter_sets)
def test_mass_matrix_is_symmetric_positive_definite(
    alpha: float, beta: float, parameters: BlockableManipulatorParameters
) -> None:
    p = parameters
    m = mass(Model, np.array([alpha, beta]), p.values())
    assert m[0, 1] == m[1, 0]
    assert np.linalg.eigvalsh(m).min() > 0.0
    np.linalg.cholesky(m)
    # det = m11 m22 - c^2 cos^2 >= (m1 m2 / 9 + m2^2 / 12) l1^2 l2^2: bounded away from 0.
    bound = (p.link1_mass * p.link2_mass / 9 + p.link2_mass**2 / 12) * (
        p.link1_length * p.link2_length
    ) ** 2
    assert np.linalg.det(m) >= bound * (1 - 1e-9)


@HYPOTHESIS
@given(angles, angles, rates, rates, parameter_sets)
def test_forces_match_the_lagrangian(
    alpha: float, beta: float, alpha_dot: float, beta_dot: float,
    parameters: BlockableManipulatorParameters,
) -> None:  # fmt: skip
    """Coriolis/centrifugal h from M alone (no potential: horizontal plane)."""
    q, u, p = np.array([alpha, beta]), np.array([alpha_dot, beta_dot]), parameters.values()
    expected = lagrangian_forces(Model, q, u, p, lambda q, p: 0.0)
    actual = forces(Model, q, u, p)
    scale = np.abs(mass(Model, q, p)).max() * (np.abs(u).max() ** 2 + 1.0)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=1e-7 * scale)


def test_power_of_the_forces_is_minus_half_u_mdot_u() -> None:
    """U^T h = -u^T M' u / 2 (M' = dM/dt along u, by central differences): T' = u^T h + ... ."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        q, u = rng.uniform(-4, 4, 2), rng.normal(0, 5, 2)
        eps = 1e-6
        m_dot = (mass(Model, q + eps * u, DEFAULT) - mass(Model, q - eps * u, DEFAULT)) / (2 * eps)
        power = u @ forces(Model, q, u, DEFAULT)
        assert power == pytest.approx(-0.5 * u @ m_dot @ u, rel=1e-7, abs=1e-8)


def test_input_and_brake_directions() -> None:
    q = np.array([0.7, -1.9])
    np.testing.assert_array_equal(inputs(Model, q, DEFAULT), [[1.0], [0.0]])
    # The brake blocks d(beta - alpha)/dt.
    np.testing.assert_array_equal(Model.brake_directions(q, DEFAULT, math), ((-1.0, 1.0),))
    assert Model.NUM_BRAKES == 1 and Model.NUM_CONTACTS == 0


@pytest.mark.parametrize("seed", range(3))
def test_smooth_energy_balance_with_torque(seed: int) -> None:
    """DT/dt = tau(t) alpha' along a fine DOP853 integration of M u' = h + B tau."""
    rng = np.random.default_rng(seed)
    amplitude, frequency = rng.uniform(0.5, 3.0), rng.uniform(0.5, 4.0)
    change, work = smooth_energy_balance(
        Model, DEFAULT, lambda q, p: 0.0, rng.uniform(-3, 3, 2), rng.normal(0, 2, 2),
        lambda t: np.array([amplitude * math.sin(frequency * t)]), 3.0,
    )  # fmt: skip
    assert np.abs(work).max() > 0.1
    np.testing.assert_allclose(change, work, rtol=0, atol=1e-8)


def test_smooth_motion_conserves_angular_momentum() -> None:
    """Tau = 0: L = (1, 1) . M(q) u and T are constant along the exact motion."""
    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        q, u = y[:2], y[2:]
        return np.concatenate([u, np.linalg.solve(mass(Model, q, DEFAULT),
                                                  forces(Model, q, u, DEFAULT))])  # fmt: skip

    y0 = np.array([0.3, -1.0, 2.0, -3.0])
    solution = solve_ivp(rhs, (0.0, 5.0), y0, method="DOP853", rtol=1e-12, atol=1e-12)
    momenta = [np.ones(2) @ mass(Model, y[:2], DEFAULT) @ y[2:] for y in solution.y.T]
    energies = [0.5 * y[2:] @ mass(Model, y[:2], DEFAULT) @ y[2:] for y in solution.y.T]
    np.testing.assert_allclose(momenta, momenta[0], rtol=1e-9)
    np.testing.assert_allclose(energies, energies[0], rtol=1e-9)
    assert np.ptp(solution.y[1] - solution.y[0]) > 1.0  # the elbow really moves


def test_default_parameters_are_unit_rods() -> None:
    assert DEFAULT == (1.0, 1.0, 1.0, 1.0)
    np.testing.assert_allclose(mass(Model, np.zeros(2), DEFAULT), [[4 / 3, 0.5], [0.5, 1 / 3]])
