"""Problem data and the shared residual (``mdi_envs/solvers/lcp/problem.py``)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from solvers.lcp.complementarity import HYPOTHESIS_SETTINGS, natural_residual

from mdi_envs.solvers.lcp.problem import LCP, as_finite_array, lcp_residual, natural_map


def test_lcp_converts_to_contiguous_float64() -> None:
    """Integer, Fortran-ordered input is stored as C-contiguous float64."""
    problem = LCP(np.asfortranarray(np.array([[2, 1], [0, 3]])), [-1, 2])
    assert problem.M.dtype == np.float64 and problem.M.flags.c_contiguous
    assert problem.q.dtype == np.float64
    np.testing.assert_array_equal(problem.M, [[2.0, 1.0], [0.0, 3.0]])
    assert problem.size == 2


@pytest.mark.parametrize(
    ("q", "trivial"),
    [([1.0, 0.0], True), ([0.0, -0.0], True), ([1.0, -1e-300], False), ([-1.0, -1.0], False)],
)
def test_is_trivial_means_q_nonnegative(q: list[float], trivial: bool) -> None:
    """``is_trivial`` is q >= 0 (a -0.0 counts as 0)."""
    assert LCP(np.eye(2), q).is_trivial is trivial


def test_empty_problem_is_trivial() -> None:
    """The empty problem (n = 0)."""
    problem = LCP(np.zeros((0, 0)), np.zeros(0))
    assert problem.is_trivial and problem.size == 0


def test_lcp_is_frozen() -> None:
    """Problem data cannot be reassigned after validation."""
    problem = LCP(np.eye(2), [-1.0, 1.0])
    with pytest.raises(dataclasses.FrozenInstanceError):
        problem.q = np.zeros(2)  # type: ignore[misc]


@pytest.mark.parametrize(
    ("M", "q", "match"),
    [
        (np.ones((2, 3)), np.ones(2), "M must be square"),
        (np.eye(2), np.ones(3), "q has length 3 but M is 2x2"),
        (np.eye(2), [1.0, np.inf], "q contains NaN or inf"),
        ([[1.0, "x"], [0.0, 1.0]], [1.0, 1.0], "M must be a numeric array"),
    ],
)
def test_lcp_rejects_bad_data(M: object, q: object, match: str) -> None:
    """The dataclass validates on construction."""
    with pytest.raises(ValueError, match=match):
        LCP(M, q)


def test_as_finite_array_names_the_argument() -> None:
    """Messages name the argument so the caller knows which input is wrong."""
    with pytest.raises(ValueError, match="^gamma must have 1 dimension"):
        as_finite_array(np.eye(2), "gamma", 1)
    with pytest.raises(ValueError, match="^gamma contains NaN"):
        as_finite_array([np.nan], "gamma", 1)
    out = as_finite_array([1, 2], "gamma", 1)
    assert out.dtype == np.float64


def test_residual_is_zero_exactly_at_solutions() -> None:
    """The natural-map residual vanishes at a solution and not at a non-solution."""
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    q = np.array([-5.0, -6.0])
    assert lcp_residual(M, q, np.array([4.0, 7.0]) / 3) < 1e-15
    assert lcp_residual(M, q, np.zeros(2)) == pytest.approx(1.0)  # min(0, q) = q, ||q|| > 1
    assert LCP(M, q).residual([4 / 3, 7 / 3]) < 1e-15


def test_residual_scale_is_max_of_norm_q_and_one() -> None:
    """Relative to ||q|| for large q, absolute for ||q|| < 1 (never divided by a tiny q)."""
    M = np.eye(2)
    big = np.array([-300.0, -400.0])
    assert lcp_residual(M, big, np.zeros(2)) == pytest.approx(1.0)
    tiny = np.array([-3e-9, -4e-9])
    assert lcp_residual(M, tiny, np.zeros(2)) == pytest.approx(5e-9)


def test_residual_counts_negative_z() -> None:
    """min(z, w) catches negative z even when w is large (z = -1, w = 10)."""
    M = np.array([[1.0]])
    assert lcp_residual(M, np.array([11.0]), np.array([-1.0])) == pytest.approx(1 / 11)


@HYPOTHESIS_SETTINGS
@given(
    st.integers(1, 12).flatmap(
        lambda n: st.tuples(
            hnp.arrays(np.float64, (n, n), elements=st.floats(-1e3, 1e3)),
            hnp.arrays(np.float64, n, elements=st.floats(-1e3, 1e3)),
            hnp.arrays(np.float64, n, elements=st.floats(-1e3, 1e3)),
        )
    )
)
def test_natural_map_against_numpy(data: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
    """natural_map fills w = Mz + q and returns the residual that numpy computes."""
    M, q, z = data
    w = np.full(q.shape, np.nan)
    residual = natural_map(M, q, z, w)
    expected_w = M @ z + q
    atol = 64 * np.finfo(float).eps * (np.abs(M) @ np.abs(z) + np.abs(q) + 1.0)
    np.testing.assert_allclose(w, expected_w, rtol=0, atol=atol.max())
    expected = natural_residual(M, q, z)
    denominator = max(np.linalg.norm(q), 1.0)
    assert abs(residual - expected) <= 1e-12 * expected + np.linalg.norm(atol) / denominator
    assert lcp_residual(M, q, z) == residual
