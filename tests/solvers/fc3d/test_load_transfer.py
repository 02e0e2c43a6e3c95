"""Newton on the friction impulses of FC3D problems with a load law (``load_transfer.py``).

Each problem is also written out as the full FC3D problem (W, q) it stands for, which the
cone conditions (``conftest.assert_coulomb``) and the full Newton method judge independently.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from mdi_envs.solvers.fc3d.load_transfer import (
    load_transfer_workspace_size,
    newton_load_transfer,
)
from mdi_envs.solvers.fc3d.newton_ac import newton_ac_kernel
from mdi_envs.solvers.status import CODE_BREAKDOWN, CODE_CONVERGED


def full_problem(G: np.ndarray, b: np.ndarray, n0: np.ndarray, K: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(W, q) of the FC3D problem: u_N = r_N - (n0 + K r_T), u_T = G r_T + b, per contact."""
    nc = n0.shape[0]
    normal = 3 * np.arange(nc)
    tangent = np.ravel(np.column_stack([normal + 1, normal + 2]))
    W = np.zeros((3 * nc, 3 * nc))
    W[normal, normal] = 1.0
    W[np.ix_(normal, tangent)] = -K
    W[np.ix_(tangent, tangent)] = G
    q = np.zeros(3 * nc)
    q[normal] = -n0
    q[tangent] = b
    return W, q


def random_problem(rng: np.random.Generator, nc: int, transfer: float
                   ) -> tuple[np.ndarray, ...]:
    """(G, b, n0, K, mu): SPD G, loads n0 in [0.5, 2], transfer K of size ``transfer``."""
    A = rng.standard_normal((2 * nc, 2 * nc))
    G = A @ A.T + 0.1 * np.eye(2 * nc)
    return (G, rng.standard_normal(2 * nc), rng.uniform(0.5, 2.0, nc),
            transfer * rng.standard_normal((nc, 2 * nc)), rng.uniform(0.0, 1.0, nc))


def solve(G: np.ndarray, b: np.ndarray, n0: np.ndarray, K: np.ndarray, mu: np.ndarray,
          r0: np.ndarray | None = None, max_iter: int = 100) -> tuple[np.ndarray, int, int]:
    """(r, code, steps) of ``newton_load_transfer`` from r0 (default 0)."""
    nc = n0.shape[0]
    r = np.zeros(3 * nc) if r0 is None else r0.copy()
    workspace = np.full(load_transfer_workspace_size(nc), np.nan)
    code, steps, _ = newton_load_transfer(G, b, n0, K, mu, r, max_iter, 1e-12, 1e-4, 40,
                                          workspace)
    return r, code, steps


@pytest.mark.parametrize("seed", range(20))
def test_solutions_satisfy_the_cone_conditions_and_match_full_newton(
    seed: int, check_coulomb: Callable[..., object]
) -> None:
    rng = np.random.default_rng(seed)
    G, b, n0, K, mu = random_problem(rng, 3, 0.2)
    r, code, _ = solve(G, b, n0, K, mu)
    assert code == CODE_CONVERGED
    W, q = full_problem(G, b, n0, K)
    check_coulomb(W, q, mu, r, 1e-10)
    r_full = np.zeros_like(r)
    full_code, _, _ = newton_ac_kernel(W, q, mu, r_full, 100, 1e-12, 1e-4, 40, 1.0, 1.0)
    assert full_code == CODE_CONVERGED
    np.testing.assert_allclose(r, r_full, atol=1e-9)  # G regular: the solution is unique


def test_a_contact_whose_load_would_be_negative_lifts(
    check_coulomb: Callable[..., object]
) -> None:
    """Friction on contact 0 unloads contact 1 (K[1, 0] < 0): P_N,1 = 0, no friction there."""
    G = np.eye(4)
    b = np.array([-3.0, 0.0, 0.5, 0.0])  # contact 0 is pushed along its first tangent
    n0 = np.array([1.0, 0.2])
    K = np.array([[0.0, 0.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0]])
    mu = np.array([1.0, 1.0])
    r, code, _ = solve(G, b, n0, K, mu)
    assert code == CODE_CONVERGED
    check_coulomb(*full_problem(G, b, n0, K), mu, r, 1e-10)
    np.testing.assert_allclose(r[0:3], [1.0, 1.0, 0.0], atol=1e-12)  # contact 0 slides at mu N
    np.testing.assert_array_equal(r[3:], 0.0)  # load 0.2 - 1.0 < 0: lifted


def test_duplicated_rows_of_two_wheels_on_one_axle_are_solved(
    check_coulomb: Callable[..., object]
) -> None:
    """Two contacts with one lateral row make G, hence the Newton matrix, singular."""
    rng = np.random.default_rng(7)
    A = rng.standard_normal((5, 6))
    A[:, 3] = A[:, 1]  # t_3 (contact 1, lateral) acts exactly as t_1 (contact 0, lateral)
    G = A.T @ A
    _, b, n0, K, mu = random_problem(rng, 3, 0.2)
    b[3] = b[1]
    assert np.linalg.matrix_rank(G) == 5
    r, code, _ = solve(G, b, n0, K, mu)
    assert code == CODE_CONVERGED
    check_coulomb(*full_problem(G, b, n0, K), mu, r, 1e-10)


def test_a_warm_start_at_the_solution_takes_no_step() -> None:
    rng = np.random.default_rng(3)
    G, b, n0, K, mu = random_problem(rng, 3, 0.2)
    r, _, _ = solve(G, b, n0, K, mu)
    again, code, steps = solve(G, b, n0, K, mu, r0=r)
    assert code == CODE_CONVERGED and steps == 0
    np.testing.assert_array_equal(again, r)


def test_failure_is_reported_not_hidden() -> None:
    """A step limit too small to converge returns the step-limit code, not CONVERGED."""
    rng = np.random.default_rng(5)
    G, b, n0, K, mu = random_problem(rng, 3, 0.2)
    _, code, steps = solve(G, b, n0, K, mu, max_iter=0)
    assert code != CODE_CONVERGED and steps == 0
    _, code, _ = solve(G, b, n0, K, mu * np.nan)
    assert code == CODE_BREAKDOWN
