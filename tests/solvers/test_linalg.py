"""Dense kernels of the solvers (``mdi_envs/solvers/_linalg.py``)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mdi_envs.solvers._linalg import lu_solve_inplace, solve_consistent_inplace


@settings(max_examples=40, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow])  # fmt: skip
@given(st.integers(1, 40), st.integers(0, 2**32 - 1), st.integers(-100, 100))
def test_random_systems_match_numpy(n: int, seed: int, log10_scale: int) -> None:
    """Random (well conditioned, any scale) systems: the same x as numpy.linalg.solve."""
    rng = np.random.default_rng(seed)
    A = (rng.standard_normal((n, n)) + n * np.eye(n) * rng.choice([-1.0, 1.0])) * 10.0**log10_scale
    b = rng.standard_normal(n)
    expected = np.linalg.solve(A, b)
    A_work, x = A.copy(), b.copy()
    assert lu_solve_inplace(A_work, x, 1e-14)
    np.testing.assert_allclose(x, expected, rtol=1e-10, atol=1e-12 * np.abs(expected).max())
    np.testing.assert_allclose(A @ x, b, rtol=0, atol=1e-10 * max(1.0, np.abs(b).max()))


@pytest.mark.parametrize("seed", range(5))
def test_general_random_systems_match_numpy(seed: int) -> None:
    """Plain Gaussian matrices (no diagonal boost), so partial pivoting does real work."""
    rng = np.random.default_rng(seed)
    n = 25
    A = rng.standard_normal((n, n))
    b = rng.standard_normal(n)
    x = b.copy()
    assert lu_solve_inplace(A.copy(), x, 1e-14)
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-8, atol=1e-10)


def test_zero_leading_pivot_needs_row_exchange() -> None:
    """A[0, 0] = 0 is solvable with partial pivoting."""
    A = np.array([[0.0, 1.0, 2.0], [1.0, 0.0, 3.0], [4.0, -3.0, 8.0]])
    b = np.array([1.0, 2.0, 3.0])
    x = b.copy()
    assert lu_solve_inplace(A.copy(), x, 1e-14)
    np.testing.assert_allclose(A @ x, b, atol=1e-13)


@pytest.mark.parametrize(
    "A",
    [
        np.array([[1.0, 2.0], [2.0, 4.0]]),
        np.zeros((3, 3)),
        np.array([[1.0, 1.0, 1.0], [1.0, 2.0, 3.0], [2.0, 3.0, 4.0]]),  # row 3 = row 1 + row 2
        np.array([[1e-300, 0.0], [0.0, 0.0]]),
    ],
    ids=["rank1", "zero", "rank2", "tiny_rank1"],
)
def test_singular_matrix_is_reported(A: np.ndarray) -> None:
    """A singular matrix returns False instead of raising or returning garbage as success."""
    assert np.linalg.matrix_rank(A) < A.shape[0]
    assert not lu_solve_inplace(A.copy(), np.ones(A.shape[0]), 1e-14)


def test_random_rank_deficient_matrices_are_reported() -> None:
    """Products B C with inner dimension < n are singular to rounding: reported as such."""
    rng = np.random.default_rng(1)
    for n in (2, 5, 20):
        A = rng.standard_normal((n, n - 1)) @ rng.standard_normal((n - 1, n))
        assert not lu_solve_inplace(A, rng.standard_normal(n), 1e-12)


def test_relative_pivot_tolerance() -> None:
    """A pivot below rel_pivot_tol * max|A| counts as singular; above it, it is used."""
    A = np.array([[1.0, 0.0], [0.0, 1e-10]])
    assert not lu_solve_inplace(A.copy(), np.ones(2), 1e-9)
    x = np.ones(2)
    assert lu_solve_inplace(A.copy(), x, 1e-11)
    np.testing.assert_allclose(x, [1.0, 1e10])


def test_scale_invariance() -> None:
    """The test is relative: a uniformly tiny, well-conditioned matrix is not singular."""
    A = np.array([[2.0, 1.0], [1.0, 3.0]]) * 1e-200
    x = np.array([3.0, 5.0]) * 1e-200
    assert lu_solve_inplace(A.copy(), x, 1e-14)
    np.testing.assert_allclose(x, [0.8, 1.4], rtol=1e-14)


def test_empty_system() -> None:
    """The empty system (n = 0) is trivially solvable."""
    assert lu_solve_inplace(np.zeros((0, 0)), np.zeros(0), 1e-14)


def test_works_on_a_strided_view() -> None:
    """The enumerative method passes the leading block of a larger workspace."""
    work = np.full((5, 5), np.nan)
    rhs = np.full(5, np.nan)
    block = np.array([[4.0, 1.0], [2.0, 3.0]])
    work[:2, :2] = block
    rhs[:2] = [1.0, 2.0]
    assert lu_solve_inplace(work[:2, :2], rhs[:2], 1e-14)
    np.testing.assert_allclose(rhs[:2], np.linalg.solve(block, [1.0, 2.0]), rtol=1e-14)
    assert np.isnan(rhs[2:]).all() and np.isnan(work[2:, :]).all()


def test_inputs_are_overwritten() -> None:
    """Documented in-place behaviour: b becomes x, A holds the LU factors."""
    A = np.array([[4.0, 3.0], [6.0, 3.0]])
    b = np.array([10.0, 12.0])
    A_work = A.copy()
    assert lu_solve_inplace(A_work, b, 1e-14)
    np.testing.assert_allclose(b, [1.0, 2.0], rtol=1e-14)
    assert not np.array_equal(A_work, A)


@pytest.mark.parametrize("seed", range(5))
def test_consistent_singular_systems_are_solved_exactly(seed: int) -> None:
    """Duplicated rows (rank n - 2): LU gives up, the elimination with deferred columns solves."""
    rng = np.random.default_rng(seed)
    n = 9
    A = rng.standard_normal((n, n))
    A[4] = A[1]
    A[7] = -2.0 * A[2]
    x_true = rng.standard_normal(n)
    b = A @ x_true
    assert not lu_solve_inplace(A.copy(), b.copy(), 1e-14)
    A_work, x = A.copy(), b.copy()
    assert solve_consistent_inplace(A_work, x, np.empty(n), 1e-14, 1e-10)
    np.testing.assert_allclose(A @ x, b, rtol=0, atol=1e-12 * np.abs(b).max())
    # regular systems: the unique solution
    M = rng.standard_normal((n, n))
    y = M @ x_true
    assert solve_consistent_inplace(M.copy(), y, np.empty(n), 1e-14, 1e-10)
    np.testing.assert_allclose(y, x_true, rtol=1e-9, atol=1e-9)
    # ... computed by exactly LU's elimination
    lu_x = M @ x_true
    assert lu_solve_inplace(M.copy(), lu_x, 1e-14)
    np.testing.assert_array_equal(y, lu_x)


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("twins", [(2, 5), (0, 3), (6, 8)])
def test_duplicated_columns_are_deferred(seed: int, twins: tuple[int, int]) -> None:
    """Two contacts on one line: a symmetric J with a duplicated row and column.

    The second twin's column has no pivot once the first is eliminated: it is deferred, its
    unknown is 0 and the rest solve every equation.
    """
    rng = np.random.default_rng(seed)
    n = 9
    first, second = twins
    root = rng.standard_normal((n, n))
    A = root @ root.T
    A[second] = A[first]
    A[:, second] = A[:, first]
    b = A @ rng.standard_normal(n)
    x = b.copy()
    assert solve_consistent_inplace(A.copy(), x, np.empty(n), 1e-14, 1e-10)
    np.testing.assert_allclose(A @ x, b, rtol=0, atol=1e-12 * np.abs(b).max())
    assert x[first] == 0.0 or x[second] == 0.0


def test_a_zero_leading_column_is_deferred() -> None:
    A = np.array([[0.0, 1.0, 2.0], [0.0, 3.0, 1.0], [0.0, 1.0, 1.0]])
    A[2] = A[0] + A[1]  # rank 2: column 0 and a row redundant
    x_true = np.array([0.0, 1.0, -2.0])
    x = A @ x_true
    assert solve_consistent_inplace(A.copy(), x, np.empty(3), 1e-14, 1e-10)
    np.testing.assert_allclose(x, x_true, rtol=0, atol=1e-14)


def test_inconsistent_singular_systems_are_refused() -> None:
    A = np.array([[1.0, 2.0], [1.0, 2.0]])
    assert not solve_consistent_inplace(A.copy(), np.array([1.0, 1.5]), np.empty(2), 1e-14, 1e-10)
    assert solve_consistent_inplace(A.copy(), np.array([1.0, 1.0]), np.empty(2), 1e-14, 1e-10)
    assert solve_consistent_inplace(np.zeros((2, 2)), np.zeros(2), np.empty(2), 1e-14, 1e-10)
    assert not solve_consistent_inplace(np.zeros((2, 2)), np.array([0.0, 1.0]), np.empty(2),
                                        1e-14, 1e-10)
