"""Lemke's method (``mdi_envs/solvers/lcp/lemke.py``).

Lemke is the default method and the only one that handles every class the stepper meets, so it is
held to the strictest standard: it must solve every feasible peer problem to 1e-10, ray-terminate
exactly where that is the correct answer, follow the exact lexicographic pivot path (pivot counts
from the README, and an exact-rational reference run), and solve every generated P-matrix and
PSD problem, degenerate or not.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from solvers.lcp.complementarity import (
    HYPOTHESIS_SETTINGS,
    Planted,
    assert_complementary,
    assert_result_consistent,
    assert_solved,
    natural_residual,
    planted_problems,
)
from solvers.lcp.exact_lemke import exact_lemke
from solvers.lcp.peer_lcp import PEER_DATA, PeerLCP, lcp_params, load, names_where

from mdi_envs.solvers import SolverStatus, solve_lcp
from mdi_envs.solvers.lcp.lemke import (
    LemkeOptions,
    lemke_kernel,
    lemke_solve,
    refine_basic_solution,
)


def _kernel_basis(M: np.ndarray, q: np.ndarray, max_iter: int) -> tuple[int, int, np.ndarray]:
    n = q.shape[0]
    basis = np.empty(n, dtype=np.int64)
    code, pivots = lemke_kernel(
        M, q, max_iter, 1e-12, 1e-11, np.empty((n, n + 2)), basis,
        np.empty(2 * n + 1, dtype=np.int64), np.empty(2 * n + 1, dtype=np.int64),
        np.empty(n + 1, dtype=np.int64), np.empty(n + 2), np.empty(n),
    )  # fmt: skip
    return code, pivots, basis


# ------------------------------------------------------------------------------------------
# Peer problems


@pytest.mark.parametrize("path", lcp_params())
def test_peer_problem(path: Path) -> None:
    """Solved to 1e-10 (or the correct ray) with the README's lexicographic pivot count."""
    M, q, info = load(path)
    result = solve_lcp(M, q, method="lemke")
    assert_result_consistent(M, q, result)
    assert result.method == "lemke"
    if info.ray_reason is not None:
        # Asserted expectation, not a failure: the ray is the right answer here.
        assert result.status is SolverStatus.RAY_TERMINATION, info.ray_reason
        assert natural_residual(M, q, result.z) > 1e-10
    else:
        assert_solved(M, q, result, tol=1e-10)
    if info.solution is not None:
        np.testing.assert_allclose(result.z, info.solution, rtol=1e-12, atol=1e-12)
    assert result.num_iter == info.lemke_pivots, "lexicographic pivot path changed"


def test_ray_terminations_are_exactly_the_tabled_ones() -> None:
    """Only CPS_3 (bimatrix game) and Pang_isolated_sol_perturbed (infeasible) may ray."""
    assert sorted(names_where(lambda i: i.ray_reason is not None)) == [
        "lcp_CPS_3",
        "lcp_Pang_isolated_sol_perturbed",
    ]


@pytest.mark.parametrize("path", lcp_params(names_where(lambda i: i.n <= 12)))
def test_peer_problem_matches_exact_rational_lemke(path: Path) -> None:
    """Same outcome, pivot count and z as the same algorithm run in exact arithmetic."""
    M, q, _ = load(path)
    exact = exact_lemke(M, q)
    result = solve_lcp(M, q, method="lemke")
    expected = {"solved": SolverStatus.CONVERGED, "ray": SolverStatus.RAY_TERMINATION}
    assert result.status is expected[exact.status]
    assert result.num_iter == exact.pivots
    if exact.status == "solved":
        z_exact = exact.z_float()
        np.testing.assert_allclose(
            result.z, z_exact, rtol=1e-10, atol=1e-12 * max(1.0, np.abs(z_exact).max())
        )


def _peer(name: str) -> tuple[np.ndarray, np.ndarray, PeerLCP]:
    path = PEER_DATA / "lcp" / f"{name}.dat"
    if not path.is_file():
        pytest.skip(f"peer data {PEER_DATA} absent")
    return load(path)


def _tobenna_swapped() -> tuple[np.ndarray, np.ndarray]:
    M, q, _ = _peer("lcp_tobenna")
    order = np.arange(q.shape[0])
    order[[1, 3]] = order[[3, 1]]
    return np.ascontiguousarray(M[np.ix_(order, order)]), q[order]


def test_tobenna_with_two_indices_swapped_terminates() -> None:
    """Renumbering two complementarity pairs (rows/columns 1 and 3) must not make Lemke cycle.

    The exact-rational lexicographic run solves the permuted problem in 63 pivots. A correct
    lexicographic rule cannot cycle, whatever the ordering.
    """
    M, q = _tobenna_swapped()
    exact = exact_lemke(M, q, max_pivots=1000)
    assert (exact.status, exact.pivots) == ("solved", 63)
    result = solve_lcp(M, q, method="lemke", max_iter=1000)
    assert_solved(M, q, result, tol=1e-10)
    assert result.num_iter == exact.pivots


# ------------------------------------------------------------------------------------------
# Invariances of the exact pivot path


@pytest.mark.parametrize("q_scale", [1e-12, 1e-6, 1e6])
@pytest.mark.parametrize("path", lcp_params())
def test_pivot_path_invariant_under_scaling_q(path: Path, q_scale: float) -> None:
    """LCP(M, s q) has solution s z and the same pivot path (ties are judged relative to q).

    The 1e-12 case is README section 4.5: a uniformly tiny q must not be mistaken for zero.
    """
    M, q, info = load(path)
    result = solve_lcp(M, q_scale * q, method="lemke")
    reference = solve_lcp(M, q, method="lemke")
    assert result.status is reference.status
    assert result.num_iter == info.lemke_pivots
    if info.ray_reason is None:
        np.testing.assert_allclose(
            result.z / q_scale,
            reference.z,
            rtol=1e-9,
            atol=1e-9 * max(1, np.abs(reference.z).max()),
        )


@pytest.mark.parametrize("m_scale", [1e-6, 1e6])
@pytest.mark.parametrize("path", lcp_params())
def test_pivot_path_invariant_under_scaling_m(path: Path, m_scale: float) -> None:
    """LCP(s M, q) has solution z / s; in exact arithmetic the lexicographic path is the same."""
    M, q, info = load(path)
    result = solve_lcp(m_scale * M, q, method="lemke")
    reference = solve_lcp(M, q, method="lemke")
    assert result.status is reference.status
    assert result.num_iter == info.lemke_pivots
    if info.ray_reason is None:
        assert_solved(m_scale * M, q, result)
        np.testing.assert_allclose(
            result.z * m_scale,
            reference.z,
            rtol=1e-8,
            atol=1e-8 * max(1, np.abs(reference.z).max()),
        )


def test_tobenna_with_m_scaled_by_1e9_terminates() -> None:
    """Scaling M by 1e9 (a change of units) leaves the exact lexicographic path unchanged.

    With z' = z / s the tableau of LCP(s M, q) is that of LCP(M, q) with rows and columns scaled
    by positive factors, so every ratio test and lexicographic comparison has the same outcome:
    127 pivots to the solution z / 1e9.
    """
    M, q, info = _peer("lcp_tobenna")
    result = solve_lcp(1e9 * M, q, method="lemke", max_iter=1000)
    assert_solved(1e9 * M, q, result)
    assert result.num_iter == info.lemke_pivots


# ------------------------------------------------------------------------------------------
# Pivot limit, refinement, options


@pytest.mark.parametrize("path", lcp_params(["lcp_exp_murty2"]))
def test_pivot_limit_is_reported_not_hidden(path: Path) -> None:
    """Murty's example needs 2^6 pivots: any smaller limit is MAX_ITER, 64 is enough."""
    M, q, _ = load(path)
    for limit in (1, 2, 63):
        result = solve_lcp(M, q, method="lemke", max_iter=limit)
        assert result.status is SolverStatus.MAX_ITER
        assert result.num_iter == limit
        assert natural_residual(M, q, result.z) > 1e-10
    result = solve_lcp(M, q, method="lemke", max_iter=64)
    assert result.status is SolverStatus.CONVERGED and result.num_iter == 64


@pytest.mark.parametrize("path", lcp_params(["lcp_mmc"]))
def test_check_solution_downgrades_lemke_to_inaccurate(path: Path) -> None:
    """Lemke's stopping test is combinatorial (the artificial left the basis), not the residual.

    With a tolerance no float solution can meet, the pivoting succeeds, the one refinement cannot
    reach it, and the driver's residual check reports INACCURATE -- unless switched off.
    """
    M, q, _ = load(path)
    strict = solve_lcp(M, q, method="lemke", tol=1e-300)
    assert strict.status is SolverStatus.INACCURATE
    assert strict.residual > 1e-300
    assert natural_residual(M, q, strict.z) < 1e-12  # still an excellent solution
    unchecked = solve_lcp(M, q, method="lemke", tol=1e-300, check_solution=False)
    assert unchecked.status is SolverStatus.CONVERGED
    assert unchecked.residual > 1e-300


def test_refine_basic_solution_recomputes_the_basic_point() -> None:
    """Refinement solves B x_B = q afresh: a corrupted z is restored from the final basis."""
    M = np.array([[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]])
    q = np.array([-1.0, -2.0, 3.0])
    code, _, basis = _kernel_basis(M, q, 100)
    assert code == int(SolverStatus.CONVERGED)
    expected = np.zeros(3)
    expected[:2] = np.linalg.solve(M[:2, :2], -q[:2])  # basis {z_0, z_1, w_2}
    z = expected + np.array([1e-3, -2e-3, 0.5])
    assert refine_basic_solution(M, q, basis, z, np.empty((3, 3)), np.empty(3))
    np.testing.assert_allclose(z, expected, rtol=1e-14, atol=1e-15)
    assert_complementary(M, q, z, None, tol=1e-14)


def test_refine_basic_solution_reports_a_singular_basis() -> None:
    """A basis whose matrix is singular is reported (False) and z is left untouched."""
    M = np.array([[1.0, 1.0], [1.0, 1.0]])
    q = np.array([-1.0, -1.0])
    basis = np.array([2, 3], dtype=np.int64)  # z_0 and z_1 basic: B = -M, singular
    z = np.array([0.25, 0.5])
    assert not refine_basic_solution(M, q, basis, z, np.empty((2, 2)), np.empty(2))
    np.testing.assert_array_equal(z, [0.25, 0.5])


def test_lemke_solve_returns_kernel_codes() -> None:
    """The compiled entry point returns (z, code, pivots) with the documented codes."""
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    z, code, pivots = lemke_solve(M, np.array([-5.0, -6.0]), 100, 1e-12, 1e-11, 1e-10)
    assert code == int(SolverStatus.CONVERGED) and pivots == 3
    np.testing.assert_allclose(z, [4 / 3, 7 / 3], rtol=1e-14)
    z, code, pivots = lemke_solve(-np.eye(2), np.array([-1.0, -1.0]), 100, 1e-12, 1e-11, 1e-10)
    assert code == int(SolverStatus.RAY_TERMINATION)


def test_infeasible_problem_ends_on_a_ray() -> None:
    """M = -I, q < 0 has no solution (w = -z + q < 0): the only honest answers are not CONVERGED."""
    result = solve_lcp(-np.eye(3), -np.ones(3), method="lemke")
    assert result.status is SolverStatus.RAY_TERMINATION


def test_z0_is_ignored() -> None:
    """Pivoting always starts from z = 0: a starting point changes nothing."""
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    q = np.array([-5.0, -6.0])
    cold = solve_lcp(M, q, method="lemke")
    warm = solve_lcp(M, q, method="lemke", z0=np.array([4 / 3, 7 / 3]))
    assert warm.num_iter == cold.num_iter == 3
    np.testing.assert_array_equal(warm.z, cold.z)


@pytest.mark.parametrize(
    ("option", "value"),
    [("pivot_tol", -1e-3), ("pivot_tol", 1.0), ("tie_tol", 1.5), ("tie_tol", float("nan"))],
)
def test_invalid_options(option: str, value: float) -> None:
    """pivot_tol and tie_tol must lie in [0, 1)."""
    with pytest.raises(ValueError, match=f"option '{option}' must be a finite number in"):
        solve_lcp(np.eye(2), -np.ones(2), method="lemke", **{option: value})


def test_default_options() -> None:
    """Defaults documented in LemkeOptions (a 10 000-pivot budget for exponential paths)."""
    options = LemkeOptions()
    assert (options.max_iter, options.tol, options.pivot_tol, options.tie_tol) == (
        10_000,
        1e-10,
        1e-12,
        1e-11,
    )


# ------------------------------------------------------------------------------------------
# Generated problems (Hypothesis, deterministic)


@HYPOTHESIS_SETTINGS
@given(st.sampled_from(["p_diag_dominant", "pd_nonsymmetric", "spd"]).flatmap(
    lambda kind: planted_problems(kind, max_n=100)
))
def test_p_matrix_problems_are_solved_uniquely(problem: Planted) -> None:
    """On a P-matrix the planted z* is the unique solution; Lemke must find it."""
    result = solve_lcp(problem.M, problem.q, method="lemke")
    assert_solved(problem.M, problem.q, result)
    scale = max(1.0, np.abs(problem.z).max())
    np.testing.assert_allclose(result.z, problem.z, rtol=0, atol=1e-8 * scale)


@HYPOTHESIS_SETTINGS
@given(planted_problems("psd_singular", max_n=100))
def test_singular_psd_problems_are_solved(problem: Planted) -> None:
    """Symmetric PSD with a solution: Lemke solves it; w = Mz + q is unique (= w*)."""
    result = solve_lcp(problem.M, problem.q, method="lemke")
    assert_solved(problem.M, problem.q, result)
    scale = max(1.0, np.abs(problem.w).max(), np.abs(problem.q).max())
    np.testing.assert_allclose(result.w, problem.w, rtol=0, atol=1e-8 * scale)


@HYPOTHESIS_SETTINGS
@given(st.sampled_from(["p_diag_dominant", "psd_singular"]).flatmap(
    lambda kind: planted_problems(kind, max_n=60, degenerate=True, integer=True)
))
def test_degenerate_integer_problems_are_solved(problem: Planted) -> None:
    """Degenerate planted pairs (z_i = w_i = 0) with integer data: exact ties in the ratio test."""
    result = solve_lcp(problem.M, problem.q, method="lemke")
    assert_solved(problem.M, problem.q, result)


@st.composite
def _small_integer_problems(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    n = draw(st.integers(2, 7))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    kind = draw(st.sampled_from(["psd", "any", "nonnegative", "p"]))
    if kind == "psd":
        B = rng.integers(-2, 3, (n, max(1, n // 2)))
        M = (B @ B.T).astype(float)
    elif kind == "any":
        M = rng.integers(-3, 4, (n, n)).astype(float)
    elif kind == "nonnegative":
        M = rng.integers(0, 3, (n, n)).astype(float)
    else:
        M = rng.integers(-2, 3, (n, n)).astype(float)
        np.fill_diagonal(M, 0.0)
        M[np.diag_indices(n)] = np.abs(M).sum(axis=1) + 1.0
    q = rng.integers(-3, 3, n).astype(float)
    q[rng.integers(n)] = -1.0
    return M, q


@HYPOTHESIS_SETTINGS
@given(_small_integer_problems())
def test_small_integer_problems_follow_the_exact_path(problem: tuple) -> None:
    """Any small integer LCP (any matrix class, many ties): same result as exact arithmetic."""
    M, q = problem
    exact = exact_lemke(M, q, max_pivots=200)
    result = solve_lcp(M, q, method="lemke", max_iter=200)
    expected = {
        "solved": SolverStatus.CONVERGED,
        "ray": SolverStatus.RAY_TERMINATION,
        "max_iter": SolverStatus.MAX_ITER,
    }
    assert result.status is expected[exact.status]
    assert result.num_iter == exact.pivots
    if exact.status == "solved":
        np.testing.assert_allclose(result.z, exact.z_float(), rtol=1e-12, atol=1e-12)
        assert_solved(M, q, result)
