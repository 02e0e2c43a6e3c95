"""Tests of the mixed LCP (``mdi_envs/solvers/mlcp``): conditions checked directly."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mdi_envs.solvers import SolverStatus
from mdi_envs.solvers.lcp import solve_lcp
from mdi_envs.solvers.mlcp import MLCP, solve_mlcp


def assert_mixed_complementary(problem: MLCP, u: np.ndarray, z: np.ndarray, tol: float) -> None:
    """Equality rows vanish, and 0 <= z _|_ w >= 0, with w recomputed from the data."""
    scale = max(np.linalg.norm(np.concatenate([problem.a, problem.b])), 1.0)
    equality = problem.A @ u + problem.C @ z + problem.a
    w = problem.D @ u + problem.B @ z + problem.b
    assert np.linalg.norm(equality) <= tol * scale
    assert z.min(initial=0.0) >= -tol * scale
    assert w.min(initial=0.0) >= -tol * scale
    assert abs(z @ w) <= tol * scale * max(1.0, np.abs(z).max(initial=0.0))


def test_brake_and_contact_closed_form() -> None:
    # 2u + z + 1 = 0, w = u + 2z - 4: the contact is active, z = 3, u = -2.
    result = solve_mlcp([[2.0]], [[1.0]], [[1.0]], [[2.0]], [1.0], [-4.0])
    assert result.status is SolverStatus.CONVERGED
    np.testing.assert_allclose(result.u, [-2.0], atol=1e-12)
    np.testing.assert_allclose(result.z, [3.0], atol=1e-12)
    np.testing.assert_allclose(result.w, [0.0], atol=1e-12)


def test_without_equalities_it_is_the_lcp() -> None:
    M, q = np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0])
    mixed = solve_mlcp(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((2, 0)), M, np.zeros(0), q)
    plain = solve_lcp(M, q)
    np.testing.assert_allclose(mixed.z, plain.z, atol=1e-14)
    assert mixed.u.shape == (0,)


def test_only_equalities_is_a_linear_solve() -> None:
    A = np.array([[4.0, 1.0], [1.0, 3.0]])
    a = np.array([1.0, -2.0])
    result = solve_mlcp(A, np.zeros((2, 0)), np.zeros((0, 2)), np.zeros((0, 0)), a, np.zeros(0))
    np.testing.assert_allclose(result.u, np.linalg.solve(A, -a), atol=1e-14)
    assert result.status is SolverStatus.CONVERGED


@settings(max_examples=30, deadline=None, derandomize=True)
@given(
    m=st.integers(1, 4),
    n=st.integers(1, 12),
    seed=st.integers(0, 2**31 - 1),
    lcp_method=st.sampled_from(["lemke", "newton_fb", "pgs"]),
)
def test_random_positive_definite_problems(m: int, n: int, seed: int, lcp_method: str) -> None:
    """Delassus-like data (a symmetric positive definite [[A, C], [D, B]]) always solves."""
    rng = np.random.default_rng(seed)
    J = rng.standard_normal((m + n, m + n + 2))
    G = J @ J.T / (m + n) + 0.1 * np.eye(m + n)
    c = rng.standard_normal(m + n)
    problem = MLCP(G[:m, :m], G[:m, m:], G[m:, :m], G[m:, m:], c[:m], c[m:])
    result = solve_mlcp(
        problem.A, problem.C, problem.D, problem.B, problem.a, problem.b,
        lcp_method=lcp_method, lcp_options={"max_iter": 100_000} if lcp_method == "pgs" else {},
    )
    assert result.status is SolverStatus.CONVERGED
    assert result.residual <= 1e-10
    assert_mixed_complementary(problem, result.u, result.z, 1e-8)


def test_singular_equality_block_is_reported() -> None:
    result = solve_mlcp([[0.0]], [[1.0]], [[1.0]], [[2.0]], [1.0], [-4.0])
    assert result.status is SolverStatus.BREAKDOWN


def test_inner_failure_is_reported() -> None:
    B = np.array([[2.0, 1.0, 0.5], [1.0, 2.0, 1.0], [0.5, 1.0, 2.0]])
    result = solve_mlcp(
        [[2.0]], [[1.0, 0.0, 0.0]], [[1.0], [0.0], [0.0]], B, [1.0], [-4.0, -1.0, -3.0],
        lcp_method="pgs", lcp_options={"max_iter": 1},
    )
    assert result.status is SolverStatus.MAX_ITER
    assert result.residual > 1e-10


@pytest.mark.parametrize(
    ("blocks", "match"),
    [
        (([[1.0, 0.0]], [[1.0]], [[1.0]], [[2.0]], [1.0], [-4.0]), "A must have shape"),
        (([[1.0]], [[1.0, 2.0]], [[1.0]], [[2.0]], [1.0], [-4.0]), "C must have shape"),
        (([[1.0]], [[1.0]], [[1.0]], [[np.nan]], [1.0], [-4.0]), "B contains NaN"),
        (([[1.0]], [[1.0]], [[1.0]], [[2.0]], [np.inf], [-4.0]), "a contains NaN"),
    ],
)
def test_bad_input_names_the_block(blocks: tuple, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        solve_mlcp(*blocks)


def test_unknown_method_and_option() -> None:
    data = ([[2.0]], [[1.0]], [[1.0]], [[2.0]], [1.0], [-4.0])
    with pytest.raises(ValueError, match="valid methods: \\['schur'\\]"):
        solve_mlcp(*data, method="nope")
    with pytest.raises(ValueError, match="unknown option"):
        solve_mlcp(*data, relaxation=1.0)
    with pytest.raises(ValueError, match="unknown LCP method"):
        solve_mlcp(*data, lcp_method="nope")
