"""FrictionContact3D validation, the cone projection and the shared residual."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from mdi_envs.solvers.fc3d import FC3DResult, FrictionContact3D, fc3d_residual
from mdi_envs.solvers.fc3d.problem import cone_projection, natural_map
from mdi_envs.solvers.status import SolverStatus

FINITE = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


def _data(nc: int = 2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return np.eye(3 * nc), -np.ones(3 * nc), np.full(nc, 0.5)


def test_valid_problem_is_converted_and_frozen() -> None:
    W, q, mu = _data()
    problem = FrictionContact3D(W.tolist(), q.tolist(), [0.5, 0.5])
    assert problem.num_contacts == 2
    for array in (problem.W, problem.q, problem.mu):
        assert array.dtype == np.float64 and array.flags.c_contiguous
    assert not problem.is_trivial
    with pytest.raises(AttributeError):
        problem.q = q  # type: ignore[misc]


def test_trivial_flag_looks_only_at_normal_components() -> None:
    W, _, mu = _data()
    q = np.array([0.0, -5.0, 3.0, 1.0, -1.0, -1.0])
    assert FrictionContact3D(W, q, mu).is_trivial
    q[3] = -1e-12
    assert not FrictionContact3D(W, q, mu).is_trivial


def test_empty_problem() -> None:
    problem = FrictionContact3D(np.zeros((0, 0)), np.zeros(0), np.zeros(0))
    assert problem.num_contacts == 0 and problem.is_trivial
    assert problem.residual(np.zeros(0)) == 0.0


@pytest.mark.parametrize(
    ("W", "q", "mu", "field"),
    [
        (np.eye(6)[:, :5], -np.ones(6), np.ones(2), "W"),  # not square
        (np.eye(4), -np.ones(4), np.ones(1), "W"),  # not 3 nc
        (np.ones(6), -np.ones(6), np.ones(2), "W"),  # 1-D
        (np.eye(6), -np.ones(5), np.ones(2), "q"),
        (np.eye(6), -np.ones((6, 1)), np.ones(2), "q"),
        (np.eye(6), -np.ones(6), np.ones(3), "mu"),
        (np.eye(6), -np.ones(6), np.array([0.5, -0.1]), "mu"),
        (np.where(np.eye(6) > 0, np.nan, 0.0), -np.ones(6), np.ones(2), "W"),
        (np.eye(6), np.array([-1.0, np.inf, 0, 0, 0, 0]), np.ones(2), "q"),
        (np.eye(6), -np.ones(6), np.array([0.5, np.nan]), "mu"),
        (np.eye(6), ["a"] * 6, np.ones(2), "q"),
    ],
)
def test_bad_data_raises_naming_the_field(W, q, mu, field: str) -> None:
    with pytest.raises(ValueError, match=rf"\b{field}\b"):
        FrictionContact3D(W, q, mu)


@given(
    mu=st.floats(0.0, 3.0),
    x=arrays(np.float64, 3, elements=FINITE),
)
def test_cone_projection_is_the_euclidean_projection(mu: float, x: np.ndarray) -> None:
    p = np.array(cone_projection(mu, *x))
    # in the cone
    assert np.hypot(p[1], p[2]) <= mu * p[0] + 1e-9 * (1 + np.abs(x).max())
    assert p[0] >= 0.0
    # idempotent
    np.testing.assert_allclose(cone_projection(mu, *p), p, atol=1e-9 * (1 + np.abs(x).max()))
    # Moreau: x - P(x) is orthogonal to P(x) and lies in the polar cone -K*
    d = x - p
    scale = 1.0 + np.abs(x).max() ** 2
    assert abs(d @ p) <= 1e-9 * scale
    assert mu * np.hypot(d[1], d[2]) <= -d[0] + 1e-9 * (1 + np.abs(x).max())


def test_cone_projection_cases() -> None:
    assert cone_projection(0.5, 2.0, 0.3, 0.4) == (2.0, 0.3, 0.4)  # inside
    assert cone_projection(0.5, -2.0, 0.3, 0.4) == (0.0, 0.0, 0.0)  # polar
    assert cone_projection(0.0, 2.0, 0.3, 0.4) == (2.0, 0.0, 0.0)  # frictionless: a ray
    assert cone_projection(0.0, -2.0, 0.3, 0.4) == (0.0, 0.0, 0.0)
    # onto the boundary: x = (0, 1, 0), mu = 1 -> beta = 1/2, P = (1/2, 1/2, 0)
    np.testing.assert_allclose(cone_projection(1.0, 0.0, 1.0, 0.0), (0.5, 0.5, 0.0))


@settings(max_examples=40)
@given(
    nc=st.integers(1, 5),
    seed=st.integers(0, 2**32 - 1),
)
def test_residual_matches_an_independent_computation(nc, seed, recompute_residual) -> None:
    rng = np.random.default_rng(seed)
    W = rng.normal(size=(3 * nc, 3 * nc))
    q = rng.normal(size=3 * nc) * 10.0 ** rng.uniform(-3, 3)
    mu = rng.uniform(0.0, 1.5, size=nc)
    r = rng.normal(size=3 * nc)
    expected = recompute_residual(W, q, mu, r)
    assert fc3d_residual(W, q, mu, r) == pytest.approx(expected, rel=1e-12, abs=1e-15)
    u = np.empty(3 * nc)
    assert natural_map(W, q, mu, r, u) == pytest.approx(expected, rel=1e-12, abs=1e-15)
    np.testing.assert_allclose(u, W @ r + q, rtol=1e-12, atol=1e-12)


def test_residual_is_zero_at_a_solution_and_positive_elsewhere() -> None:
    # W = I, q = (-1, 2, 0), mu = 0.5: r = (1, -0.5, 0) (sliding), u = (0, 1.5, 0)
    problem = FrictionContact3D(np.eye(3), np.array([-1.0, 2.0, 0.0]), np.array([0.5]))
    assert problem.residual(np.array([1.0, -0.5, 0.0])) == 0.0
    assert problem.residual(np.zeros(3)) > 0.1
    assert problem.residual(np.array([1.0, -0.4, 0.0])) > 0.01


def test_residual_scale_uses_max_norm_q_one() -> None:
    # q ~ 0: the residual is absolute, not divided by a vanishing ||q||
    problem = FrictionContact3D(np.eye(3), np.array([1e-18, 0.0, 0.0]), np.array([0.3]))
    assert problem.residual(np.array([1.0, 0.0, 0.0])) == pytest.approx(1.0)


def test_result_fields() -> None:
    result = FC3DResult(np.zeros(3), np.ones(3), SolverStatus.CONVERGED, 0, 0.0, "nsgs")
    assert result._fields == ("r", "u", "status", "num_iter", "residual", "method")
