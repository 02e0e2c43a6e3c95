"""The direct (one compiled call) path of ``solve_lcp`` against its generic path.

Lemke registers a direct path (``lemke_checked``): screening, trivial cases, the method and the
residual check in compiled code. Passing ``z0`` (ignored by Lemke) sends the same call through
the generic Python path (``LCP`` dataclass, ``solve_lemke``, ``natural_map``), so every result
of the two paths must be identical.
"""

from __future__ import annotations

import numpy as np
import pytest

from mdi_envs.solvers import LCP_METHODS, SolverStatus, lcp_residual, solve_lcp
from mdi_envs.solvers.lcp.problem import natural_map, screen


def _both_paths(M: np.ndarray, q: np.ndarray, **options: object) -> tuple[object, object]:
    direct = solve_lcp(M, q, method="lemke", **options)
    generic = solve_lcp(M, q, method="lemke", z0=np.zeros(len(q)), **options)
    return direct, generic


def _assert_same(direct: object, generic: object) -> None:
    np.testing.assert_array_equal(direct.z, generic.z)
    np.testing.assert_array_equal(direct.w, generic.w)
    assert direct.status is generic.status
    assert direct.num_iter == generic.num_iter
    assert direct.residual == generic.residual or (
        np.isnan(direct.residual) and np.isnan(generic.residual)
    )
    assert direct.method == generic.method


def test_lemke_registers_a_direct_path() -> None:
    """Only Lemke has one so far; the other methods go through the generic path."""
    assert LCP_METHODS.lookup("lemke").direct is not None
    assert LCP_METHODS.lookup("pgs").direct is None


@pytest.mark.parametrize("n", [0, 1, 2, 3, 7, 20, 45])
@pytest.mark.parametrize("seed", range(4))
def test_direct_equals_generic_on_random_problems(n: int, seed: int) -> None:
    """Random (nonsymmetric, possibly unsolvable) problems: the two paths agree bit for bit."""
    rng = np.random.default_rng([n, seed])
    M = rng.standard_normal((n, n)) + (seed % 2) * n * np.eye(n)
    q = rng.standard_normal(n)
    direct, generic = _both_paths(M, q)
    _assert_same(direct, generic)
    assert direct.residual == lcp_residual(M, q, direct.z)
    np.testing.assert_allclose(direct.w, M @ direct.z + q, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("m", [2.0, 0.0, -1.0])
@pytest.mark.parametrize("q", [-3.0, 0.0, 4.0])
def test_direct_equals_generic_on_scalars(m: float, q: float) -> None:
    """Size 1: the closed form (or NO_SOLUTION) on both paths."""
    _assert_same(*_both_paths(np.array([[m]]), np.array([q])))


def test_residual_check_on_the_direct_path() -> None:
    """A tolerance below what rounding allows gives INACCURATE, unless the check is off."""
    rng = np.random.default_rng(3)
    A = rng.standard_normal((30, 30))
    M, q = A @ A.T + 0.1 * np.eye(30), rng.standard_normal(30) * 1e3
    strict, generic = _both_paths(M, q, tol=1e-300)
    _assert_same(strict, generic)
    assert strict.status is SolverStatus.INACCURATE and strict.residual > 1e-300
    unchecked, generic = _both_paths(M, q, tol=1e-300, check_solution=False)
    _assert_same(unchecked, generic)
    assert unchecked.status is SolverStatus.CONVERGED


@pytest.mark.parametrize(
    ("bad_M", "bad_q", "match"),
    [
        (True, False, "M contains NaN or inf"),
        (False, True, "q contains NaN or inf"),
        (True, True, "q contains NaN or inf"),
    ],
)
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_screening_names_the_argument(
    bad_M: bool, bad_q: bool, match: str, value: float
) -> None:
    """NaN/inf anywhere (last entry included) raises ValueError on both paths, q first."""
    M, q = np.eye(4), -np.ones(4)
    if bad_M:
        M[3, 3] = value
    if bad_q:
        q[3] = value
    for z0 in (None, np.zeros(4)):
        with pytest.raises(ValueError, match=match):
            solve_lcp(M, q, z0=z0)


def test_screen_matches_isfinite() -> None:
    """The bit test of ``screen`` agrees with np.isfinite on extreme values."""
    values = [0.0, -0.0, 5e-324, -5e-324, 1.7976931348623157e308, -1.7976931348623157e308,
              np.inf, -np.inf, np.nan, -np.nan, 1.0]
    for v in values:
        M = np.eye(2)
        M[0, 1] = v
        q = np.array([1.0, v])
        is_M, is_q, is_trivial = screen(M, q)
        assert is_M == bool(np.isfinite(v)) and is_q == bool(np.isfinite(v))
        assert is_trivial == bool(np.isfinite(v) and v >= 0.0)


def test_natural_map_skips_zero_columns_exactly() -> None:
    """The column-wise M z + q equals the row-wise sum for a sparse z (zeros skipped)."""
    rng = np.random.default_rng(9)
    M = rng.standard_normal((12, 12))
    q = rng.standard_normal(12)
    z = np.where(rng.random(12) < 0.5, 0.0, rng.random(12))
    w = np.empty(12)
    residual = natural_map(M, q, z, w)
    reference = q.copy()
    for j in np.flatnonzero(z):
        reference += M[:, j] * z[j]
    np.testing.assert_allclose(w, reference, rtol=1e-15, atol=1e-15)
    expected = np.linalg.norm(np.minimum(z, reference)) / max(np.linalg.norm(q), 1.0)
    assert residual == pytest.approx(expected, rel=1e-14)
