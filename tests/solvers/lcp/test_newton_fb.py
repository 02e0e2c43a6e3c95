"""Semismooth Newton on the Fischer-Burmeister function (``mdi_envs/solvers/lcp/newton_fb.py``).

Guaranteed (and locally fast) on P-matrices; elsewhere it may stall, which must be reported as
MAX_ITER or BREAKDOWN, never as CONVERGED.
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
    assert_honest,
    assert_solved,
    natural_residual,
    planted_problems,
)
from solvers.lcp.peer_lcp import PEER_DATA, lcp_params, load

from mdi_envs.solvers import SolverStatus, solve_lcp
from mdi_envs.solvers.lcp.newton_fb import NewtonFBOptions, newton_fb_kernel


@pytest.mark.parametrize("path", lcp_params())
def test_peer_problem(path: Path) -> None:
    """Honest everywhere; CONVERGED on every P-matrix; never CONVERGED on an infeasible one."""
    M, q, info = load(path)
    result = solve_lcp(M, q, method="newton_fb")
    assert_honest(M, q, result)
    if info.p_matrix:
        assert_solved(M, q, result)
    if not info.has_solution:
        assert result.status is not SolverStatus.CONVERGED
    if info.unique and result.status is SolverStatus.CONVERGED:
        reference = solve_lcp(M, q, method="lemke")
        np.testing.assert_allclose(result.z, reference.z, rtol=1e-7, atol=1e-9)


def _mmc() -> tuple[np.ndarray, np.ndarray]:
    path = PEER_DATA / "lcp" / "lcp_mmc.dat"
    if not path.is_file():
        pytest.skip(f"peer data {PEER_DATA} absent")
    M, q, _ = load(path)
    return M, q


def test_step_limit_is_reported_not_hidden() -> None:
    """One Newton step on mmc is not enough: MAX_ITER with 1 step, never CONVERGED."""
    M, q = _mmc()
    result = solve_lcp(M, q, method="newton_fb", max_iter=1)
    assert result.status is SolverStatus.MAX_ITER
    assert result.num_iter == 1
    assert natural_residual(M, q, result.z) > 1e-10


def test_step_count_is_the_first_step_meeting_tol() -> None:
    """With k the steps needed: max_iter = k - 1 is MAX_ITER, max_iter = k is CONVERGED."""
    M, q = _mmc()
    needed = solve_lcp(M, q, method="newton_fb").num_iter
    assert needed > 2
    short = solve_lcp(M, q, method="newton_fb", max_iter=needed - 1)
    assert short.status is SolverStatus.MAX_ITER and short.num_iter == needed - 1
    enough = solve_lcp(M, q, method="newton_fb", max_iter=needed)
    assert enough.status is SolverStatus.CONVERGED and enough.num_iter == needed


def test_warm_start_at_the_solution_needs_no_step() -> None:
    """z0 = the solution: CONVERGED after 0 steps; z0 itself is not modified."""
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    q = np.array([-5.0, -6.0])
    z0 = np.array([4 / 3, 7 / 3])
    kept = z0.copy()
    result = solve_lcp(M, q, method="newton_fb", z0=z0)
    assert result.status is SolverStatus.CONVERGED and result.num_iter == 0
    np.testing.assert_array_equal(z0, kept)


def test_far_start_still_converges_on_a_p_matrix() -> None:
    """The line search globalizes the method: a start far from the solution still converges."""
    M = np.array([[4.0, -1.0, 0.5], [1.0, 3.0, -1.0], [-0.5, 1.0, 2.0]])
    q = np.array([-1.0, 2.0, -3.0])
    result = solve_lcp(M, q, method="newton_fb", z0=np.array([1e3, -1e3, 5e2]))
    assert_solved(M, q, result)
    np.testing.assert_allclose(result.z, solve_lcp(M, q).z, rtol=1e-8, atol=1e-10)


def test_infeasible_problem_is_not_converged() -> None:
    """M = -I, q < 0 has no solution: the kernel reports a failure code."""
    M = -np.eye(3)
    q = -np.ones(3)
    z = np.zeros(3)
    code, _ = newton_fb_kernel(M, q, z, 50, 1e-10, 1e-4, 40)
    assert code in (int(SolverStatus.MAX_ITER), int(SolverStatus.BREAKDOWN))
    result = solve_lcp(M, q, method="newton_fb")
    assert_honest(M, q, result)
    assert result.status in (SolverStatus.MAX_ITER, SolverStatus.BREAKDOWN)


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("armijo", 0.0, "option 'armijo' must be a finite number in"),
        ("armijo", 0.5, "option 'armijo' must be a finite number in"),
        ("armijo", float("nan"), "option 'armijo' must be a finite number in"),
        ("max_backtracks", 0, "option 'max_backtracks' must be an integer >= 1"),
        # max_backtracks is a count: a NaN or a fractional value is as invalid as 0.
        ("max_backtracks", float("nan"), "max_backtracks"),
        ("max_backtracks", 2.5, "max_backtracks"),
    ],
)
def test_invalid_options(option: str, value: float, message: str) -> None:
    """Invalid option values raise ValueError naming the option."""
    with pytest.raises(ValueError, match=message):
        solve_lcp(np.eye(2), -np.ones(2), method="newton_fb", **{option: value})


def test_default_options() -> None:
    """Defaults documented in NewtonFBOptions."""
    options = NewtonFBOptions()
    assert (options.max_iter, options.armijo, options.max_backtracks) == (100, 1e-4, 40)


@HYPOTHESIS_SETTINGS
@given(st.sampled_from(["p_diag_dominant", "pd_nonsymmetric", "spd"]).flatmap(
    lambda kind: planted_problems(kind, max_n=100)
))
def test_p_matrix_problems_are_solved(problem: Planted) -> None:
    """P-matrix (degenerate or not, scaled 1e-4..1e4): converges to the unique planted z*."""
    result = solve_lcp(problem.M, problem.q, method="newton_fb")
    assert_solved(problem.M, problem.q, result)
    scale = max(1.0, np.abs(problem.z).max())
    np.testing.assert_allclose(result.z, problem.z, rtol=0, atol=1e-7 * scale)


@HYPOTHESIS_SETTINGS
@given(planted_problems("psd_singular", max_n=40))
def test_honest_on_singular_psd(problem: Planted) -> None:
    """Singular PSD is outside the guarantee: any outcome, but an honest one."""
    result = solve_lcp(problem.M, problem.q, method="newton_fb")
    assert_honest(problem.M, problem.q, result)
