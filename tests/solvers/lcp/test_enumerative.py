"""Enumeration of complementary index sets (``mdi_envs/solvers/lcp/enumerative.py``).

Exact for tiny n: every solvable peer problem with n <= 12 is solved, an infeasible one is
NO_SOLUTION, and a larger one is refused with a ValueError naming the problem.
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
from solvers.lcp.peer_lcp import lcp_params, load

from mdi_envs.solvers import SolverStatus, solve_lcp
from mdi_envs.solvers.lcp.enumerative import EnumerativeOptions, enumerative_kernel


@pytest.mark.parametrize("path", lcp_params())
def test_peer_problem(path: Path) -> None:
    """For n <= 12: solved when a solution exists, NO_SOLUTION otherwise; n > 12: ValueError."""
    M, q, info = load(path)
    if info.n > EnumerativeOptions().max_size:
        with pytest.raises(ValueError, match=f"n = {info.n} exceeds max_size = 12"):
            solve_lcp(M, q, method="enumerative")
        return
    result = solve_lcp(M, q, method="enumerative")
    assert_honest(M, q, result)
    if info.has_solution:
        assert_solved(M, q, result)
    else:
        assert result.status is SolverStatus.NO_SOLUTION
        assert result.num_iter == 2**info.n  # every index set was examined
    if info.unique:
        reference = solve_lcp(M, q, method="lemke")
        np.testing.assert_allclose(result.z, reference.z, rtol=1e-10, atol=1e-12)


def test_candidates_are_examined_by_increasing_size() -> None:
    """Diagonal M, q = -1: the solution needs the full index set, the last of 2^n candidates."""
    n = 6
    result = solve_lcp(np.diag(np.arange(1.0, n + 1)), -np.ones(n), method="enumerative")
    assert result.status is SolverStatus.CONVERGED
    assert result.num_iter == 2**n
    np.testing.assert_allclose(result.z, 1 / np.arange(1.0, n + 1), rtol=1e-15)


def test_smallest_support_is_returned_first() -> None:
    """CPS_1-like M = [[1, 1], [1, 1]], q = -1: a one-element support is found before {0, 1}."""
    result = solve_lcp(np.ones((2, 2)), -np.ones(2), method="enumerative")
    assert result.status is SolverStatus.CONVERGED
    assert result.num_iter == 2  # the empty set, then {0}
    np.testing.assert_array_equal(result.z, [1.0, 0.0])


@pytest.mark.parametrize("max_size", [2, 3])
def test_size_limit_names_the_problem(max_size: int) -> None:
    """A problem with n > max_size is refused up front; the message gives n and the limit."""
    M = np.eye(4)
    q = -np.ones(4)
    with pytest.raises(ValueError, match=f"'enumerative'.*n = 4 exceeds max_size = {max_size}"):
        solve_lcp(M, q, method="enumerative", max_size=max_size)


def test_size_limit_can_be_raised() -> None:
    """max_size = 13 admits a 13x13 problem."""
    n = 13
    result = solve_lcp(2 * np.eye(n), -np.ones(n), method="enumerative", max_size=n)
    assert_solved(2 * np.eye(n), -np.ones(n), result)


def test_singular_block_solution_is_reported_honestly() -> None:
    """A solution reachable only through singular principal blocks is out of reach (documented).

    M = [[0, 1], [0, 0]], q = (-1, 0) is solved by z = (0, 1) (w = 0), but every index set
    containing index 1 has a singular block. The method may miss it; it must not claim a wrong z.
    """
    M = np.array([[0.0, 1.0], [0.0, 0.0]])
    q = np.array([-1.0, 0.0])
    assert natural_residual(M, q, np.array([0.0, 1.0])) == 0.0
    result = solve_lcp(M, q, method="enumerative")
    assert_honest(M, q, result)
    assert result.status in (SolverStatus.CONVERGED, SolverStatus.NO_SOLUTION)


def test_loose_feasibility_tol_is_caught_by_the_residual_check() -> None:
    """feasibility_tol = 0.5 accepts z = 0 although w = q < 0: the driver reports INACCURATE.

    This is the enumerative method's own acceptance test disagreeing with the shared residual;
    with ``check_solution=False`` the method's CONVERGED claim goes through unchecked.
    """
    M = np.eye(2)
    q = np.array([-0.1, -0.1])
    result = solve_lcp(M, q, method="enumerative", feasibility_tol=0.5)
    assert result.status is SolverStatus.INACCURATE
    np.testing.assert_array_equal(result.z, 0.0)
    assert result.residual == pytest.approx(np.sqrt(0.02))
    unchecked = solve_lcp(M, q, method="enumerative", feasibility_tol=0.5, check_solution=False)
    assert unchecked.status is SolverStatus.CONVERGED


def test_kernel_no_solution_zeroes_z() -> None:
    """NO_SOLUTION leaves z = 0 (not the last candidate)."""
    z = np.full(2, 7.0)
    code, examined = enumerative_kernel(-np.eye(2), -np.ones(2), 1 << 24, 1e-12, z)
    assert (code, examined) == (int(SolverStatus.NO_SOLUTION), 4)
    np.testing.assert_array_equal(z, 0.0)


@pytest.mark.parametrize(
    ("option", "value"),
    [
        # A negative tolerance demands w_i >= |tol| > 0 and z_i >= |tol|, so degenerate and
        # even ordinary solutions are rejected (M = I, q = (-1, 0) then reports NO_SOLUTION).
        ("feasibility_tol", -1.0),
        # NaN makes every comparison false, so the first candidate (z = 0) is accepted.
        ("feasibility_tol", float("nan")),
        # A size limit is a count; 2.5 is accepted today and silently acts as 2.
        ("max_size", 2.5),
    ],
)
def test_invalid_options(option: str, value: float) -> None:
    """Invalid option values raise ValueError naming the option (as the other methods do)."""
    with pytest.raises(ValueError, match=option):
        solve_lcp(np.eye(2), np.array([-1.0, 0.0]), method="enumerative", **{option: value})


def test_default_options() -> None:
    """Defaults documented in EnumerativeOptions."""
    options = EnumerativeOptions()
    assert (options.max_size, options.feasibility_tol) == (12, 1e-12)


@HYPOTHESIS_SETTINGS
@given(st.sampled_from(["p_diag_dominant", "pd_nonsymmetric", "spd"]).flatmap(
    lambda kind: planted_problems(kind, max_n=10)
))
def test_p_matrix_problems_are_solved(problem: Planted) -> None:
    """P-matrix: every principal block is nonsingular, so the unique z* is found."""
    result = solve_lcp(problem.M, problem.q, method="enumerative")
    assert_solved(problem.M, problem.q, result)
    scale = max(1.0, np.abs(problem.z).max())
    np.testing.assert_allclose(result.z, problem.z, rtol=0, atol=1e-9 * scale)


@HYPOTHESIS_SETTINGS
@given(planted_problems("psd_singular", max_n=8))
def test_honest_on_singular_psd(problem: Planted) -> None:
    """Singular PSD (singular blocks possible): solved or NO_SOLUTION, honestly."""
    result = solve_lcp(problem.M, problem.q, method="enumerative")
    assert_honest(problem.M, problem.q, result)
    assert result.status in (SolverStatus.CONVERGED, SolverStatus.NO_SOLUTION)
