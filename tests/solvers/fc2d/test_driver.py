"""``solve_fc2d``: validation, trivial cases, the methods' agreement on random problems."""

from __future__ import annotations

import doctest

import numpy as np
import pytest
import scipy.sparse as sp
from solvers.fc2d.coulomb_2d import assert_coulomb_2d

from mdi_envs.solvers import FC2D_METHODS, SolverStatus, solve_fc2d
from mdi_envs.solvers.fc2d import driver
from mdi_envs.solvers.fc2d.lemke import friction_lcp
from mdi_envs.solvers.fc2d.nsgs import local_solve

METHODS = ["lemke", "newton_ac", "nsgs"]


def test_methods_are_registered() -> None:
    assert FC2D_METHODS.names() == METHODS


def test_docstring_example() -> None:
    assert doctest.testmod(driver).failed == 0


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"W": np.eye(3), "q": -np.ones(3), "mu": [0.5]}, "W must be \\(2 nc, 2 nc\\)"),
        ({"W": np.ones((2, 4)), "q": -np.ones(2), "mu": [0.5]}, "W must be square"),
        ({"W": np.eye(2), "q": -np.ones(3), "mu": [0.5]}, "q has length 3"),
        ({"W": np.eye(2), "q": -np.ones(2), "mu": [0.5, 1.0]}, "mu has length 2"),
        ({"W": np.eye(2), "q": -np.ones(2), "mu": [-0.5]}, "mu must be >= 0"),
        ({"W": np.diag([1.0, np.nan]), "q": -np.ones(2), "mu": [0.5]}, "W contains NaN"),
        ({"W": sp.csr_matrix(np.diag([1.0, np.inf])), "q": -np.ones(2), "mu": [0.5]},
         "W contains NaN"),
        ({"W": np.eye(2), "q": [np.nan, 1.0], "mu": [0.5]}, "q contains NaN"),
        ({"W": np.eye(2), "q": -np.ones(2), "mu": [0.5], "method": "pgs"},
         "unknown FC2D method"),
        ({"W": np.eye(2), "q": -np.ones(2), "mu": [0.5], "relaxation": 1.0},
         "unknown option"),
        ({"W": np.eye(2), "q": -np.ones(2), "mu": [0.5], "method": "nsgs", "r0": np.ones(3)},
         "r0 has length 3"),
    ],
)
def test_bad_input_raises_value_error(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        solve_fc2d(**kwargs)


@pytest.mark.parametrize("method", METHODS)
def test_take_off_and_empty(method: str) -> None:
    result = solve_fc2d(np.eye(4), np.array([1.0, 5.0, 0.0, -2.0]), [0.3, 0.3], method=method)
    assert result.status is SolverStatus.CONVERGED and result.num_iter == 0
    np.testing.assert_array_equal(result.r, 0.0)
    empty = solve_fc2d(np.zeros((0, 0)), np.zeros(0), np.zeros(0), method=method)
    assert empty.status is SolverStatus.CONVERGED and empty.r.shape == (0,)


@pytest.mark.parametrize("q_t", [0.2, -0.2, 3.0, -3.0])
@pytest.mark.parametrize("method", METHODS)
def test_one_contact_stick_and_slide(method: str, q_t: float) -> None:
    """W = I, q_N = -1: stick (r_T = -q_T) when |q_T| <= mu, else slide at r_T = -mu sign."""
    mu = 0.5
    result = solve_fc2d(np.eye(2), np.array([-1.0, q_t]), [mu], method=method, tol=1e-12)
    expected_t = -q_t if abs(q_t) <= mu else -mu * np.sign(q_t)
    np.testing.assert_allclose(result.r, [1.0, expected_t], atol=1e-10)


def test_local_solver_cases() -> None:
    """The exact one-contact solver on a coupled, non-symmetric 2 x 2 block."""
    rng = np.random.default_rng(1)
    for _ in range(200):
        A = rng.standard_normal((2, 2))
        W = A @ A.T + 0.2 * np.eye(2) + 0.05 * rng.standard_normal((2, 2))
        q = rng.standard_normal(2)
        mu = rng.uniform(0.0, 1.5)
        r = np.array(local_solve(W[0, 0], W[0, 1], W[1, 0], W[1, 1], q[0], q[1], mu))
        assert_coulomb_2d(W, q, np.array([mu]), r, 1e-12)


def _random_problem(seed: int, nc: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """W = J M^-1 J^T of random planar bodies (PSD, possibly singular), q, mu."""
    rng = np.random.default_rng(seed)
    J = rng.standard_normal((2 * nc, max(2, (3 * nc) // 2)))
    return J @ J.T + 1e-3 * np.eye(2 * nc), J @ rng.standard_normal(J.shape[1]), rng.uniform(
        0.1, 1.0, nc
    )


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("nc", [2, 5, 12])
def test_methods_solve_random_problems(seed: int, nc: int) -> None:
    """Every method reaches 1e-9 on random PSD problems, checked by the Coulomb conditions."""
    W, q, mu = _random_problem(seed, nc)
    for method in METHODS:
        options = {"max_iter": 100_000} if method == "nsgs" else {}
        result = solve_fc2d(W, q, mu, method=method, tol=1e-9, **options)
        assert result.status is SolverStatus.CONVERGED, (method, result.residual)
        assert_coulomb_2d(W, q, mu, result.r, 1e-9)


def test_lcp_reformulation_rows() -> None:
    """The LCP's rows are u_N, s + u_T, s - u_T, mu r_N - b_+ - b_- at z = (r_N, b_+, b_-, s)."""
    W, q, mu = _random_problem(0, 3)
    M, q_lcp = friction_lcp(W, q, mu)
    rng = np.random.default_rng(2)
    z = rng.uniform(0, 1, 12)
    r = np.empty(6)
    r[0::2], r[1::2] = z[0::4], z[1::4] - z[2::4]
    u = W @ r + q
    w = M @ z + q_lcp
    np.testing.assert_allclose(w[0::4], u[0::2], rtol=1e-12)
    np.testing.assert_allclose(w[1::4], z[3::4] + u[1::2], rtol=1e-12)
    np.testing.assert_allclose(w[2::4], z[3::4] - u[1::2], rtol=1e-12)
    np.testing.assert_allclose(w[3::4], mu * z[0::4] - z[1::4] - z[2::4], rtol=1e-12)
