"""The Alart-Curnier function and its Jacobian; the Newton method on the peer problems."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from peer_data import peer_params

from mdi_envs.solvers.fc3d import solve_fc3d
from mdi_envs.solvers.fc3d.newton_ac import (
    NewtonACOptions,
    alart_curnier,
    alart_curnier_local,
    contact_weights,
)
from mdi_envs.solvers.siconos_io import read_friction_contact
from mdi_envs.solvers.status import SolverStatus

ROVER = [
    "Rover1039", "Rover1040", "Rover1041", "Rover11035", "Rover11211", "Rover3865", "Rover4144",
    "Rover4396", "Rover4493", "Rover4516", "Rover4609", "Rover4613", "Rover4622", "Rover9770",
]  # fmt: skip
SMALL_PEERS = [
    *ROVER,
    "OneObject-i1028-138.hdf5",
    "OneObject-i100000-316.hdf5",
    "OneObject-i100000-499.hdf5",
    "BoxesStack1-i100000-32.hdf5",
    "FC3D_Example1",
    "FC3D_Example1_SBM",
    "FrictionContact3D_1c",
    "FrictionContact3D_RR_1c",
]


def test_every_listed_peer_file_exists() -> None:
    params = peer_params("fc3d", names=SMALL_PEERS)
    if params[0].values[0] is None:
        pytest.skip("peer data absent")
    assert sorted(p.values[0].stem for p in params) == sorted(SMALL_PEERS)


@pytest.mark.parametrize("path", peer_params("fc3d", names=SMALL_PEERS))
def test_small_peer_problems(path, check_coulomb) -> None:
    data = read_friction_contact(path)
    result = solve_fc3d(data.W, data.q, data.mu, method="newton_ac")
    assert result.status is SolverStatus.CONVERGED, result
    assert result.residual <= 1e-8
    check_coulomb(data.W, data.q, data.mu, result.r, 1e-8)


# --- the Alart-Curnier function ----------------------------------------------------------------


def _phi(rho: float, mu: float, r: np.ndarray, u: np.ndarray) -> np.ndarray:
    phi, A, B = np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    alart_curnier_local(rho, mu, r, u, phi, A, B, False)
    return phi


@pytest.mark.parametrize(
    ("r", "u"),
    [
        ([0.0, 0.0, 0.0], [0.7, 3.0, -1.0]),  # take-off
        ([2.0, 0.3, -0.4], [0.0, 0.0, 0.0]),  # stick
        ([2.0, -0.6, -0.8], [0.0, 3.0, 4.0]),  # slide, mu = 0.5: r_T = -mu r_N u_T / |u_T|
    ],
)
def test_phi_vanishes_at_solutions(r, u) -> None:
    for rho in (0.1, 1.0, 7.0):
        np.testing.assert_allclose(_phi(rho, 0.5, np.array(r), np.array(u)), 0.0, atol=1e-15)


@settings(max_examples=60)
@given(
    seed=st.integers(0, 2**32 - 1),
    rho=st.floats(0.1, 10.0),
    mu=st.floats(0.0, 1.5),
)
def test_jacobian_blocks_match_finite_differences(seed: int, rho: float, mu: float) -> None:
    rng = np.random.default_rng(seed)
    r, u = rng.normal(size=3), rng.normal(size=3)
    phi, A, B = np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    alart_curnier_local(rho, mu, r, u, phi, A, B, True)
    # skip points within reach of a kink (a_N = 0 or |a_T| = mu a_N)
    a = r - rho * u
    kink = min(abs(a[0]), abs(np.hypot(a[1], a[2]) - mu * max(a[0], 0.0)))
    h = 1e-7
    if kink < 1e3 * h * (1 + rho):
        return
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        np.testing.assert_allclose(
            (_phi(rho, mu, r + e, u) - _phi(rho, mu, r - e, u)) / (2 * h), A[:, j], atol=1e-6
        )
        np.testing.assert_allclose(
            (_phi(rho, mu, r, u + e) - _phi(rho, mu, r, u - e)) / (2 * h), B[:, j], atol=1e-6
        )


def test_stacked_function_and_merit() -> None:
    rng = np.random.default_rng(3)
    nc = 4
    r, u = rng.normal(size=3 * nc), rng.normal(size=3 * nc)
    mu, rho = rng.uniform(0, 1, nc), rng.uniform(0.5, 2, nc)
    phi, A, B = np.empty(3 * nc), np.empty((nc, 3, 3)), np.empty((nc, 3, 3))
    psi = alart_curnier(mu, rho, r, u, phi, A, B, True)
    assert psi == pytest.approx(0.5 * phi @ phi)
    for i in range(nc):
        np.testing.assert_array_equal(
            phi[3 * i : 3 * i + 3], _phi(rho[i], mu[i], r[3 * i : 3 * i + 3], u[3 * i : 3 * i + 3])
        )


def test_contact_weights() -> None:
    W = np.zeros((6, 6))
    W[:3, :3] = np.diag([3.0, 4.0, 0.0])
    W[3:, :3] = 10.0  # second diagonal block is zero: fall back to 1 / max|W|
    np.testing.assert_allclose(contact_weights(W, 1.0), [0.2, 0.1])
    np.testing.assert_allclose(contact_weights(W, 2.0), [0.4, 0.2])
    np.testing.assert_allclose(contact_weights(np.zeros((3, 3)), 1.0), [1.0])


# --- method behaviour --------------------------------------------------------------------------


def test_options_defaults_and_validation() -> None:
    options = NewtonACOptions()
    assert options.tol == 1e-10 and options.max_iter == 100 and options.prox_sigma > 0.0
    with pytest.raises(ValueError, match="max_backtracks"):
        NewtonACOptions(max_backtracks=0)


def test_redundant_contacts_need_the_proximal_safeguard() -> None:
    # BoxesStack: W is singular (identical rows from redundant contacts). Plain Newton with its
    # line search alone stalls; the proximal regularisation gets it to the tolerance.
    (param,) = peer_params("fc3d", names=["BoxesStack1-i100000-32.hdf5"])
    if param.values[0] is None:
        pytest.skip("peer data absent")
    data = read_friction_contact(param.values[0])
    plain = solve_fc3d(data.W, data.q, data.mu, method="newton_ac", prox_sigma=0.0)
    assert plain.status is not SolverStatus.CONVERGED
    assert (plain.residual <= 1e-10) == (plain.status is SolverStatus.CONVERGED)
    safeguarded = solve_fc3d(data.W, data.q, data.mu, method="newton_ac")
    assert safeguarded.status is SolverStatus.CONVERGED


def test_quadratic_convergence_near_a_nondegenerate_solution() -> None:
    W = np.array([[2.0, 0.3, 0.1], [0.3, 1.5, 0.2], [0.1, 0.2, 1.8]])
    q, mu = np.array([-1.0, 2.0, -1.0]), np.array([0.3])
    residuals = [
        solve_fc3d(W, q, mu, method="newton_ac", max_iter=k, tol=1e-300).residual
        for k in range(1, 6)
    ]
    assert residuals[-1] < 1e-14
    # once close, each step at least squares the error (up to a constant)
    k = next(i for i, res in enumerate(residuals) if res < 1e-2)
    if k + 1 < len(residuals) and residuals[k + 1] > 1e-15:
        assert residuals[k + 1] <= 10 * residuals[k] ** 2 + 1e-15
