"""Projected Gauss-Seidel (``mdi_envs/solvers/lcp/pgs.py``).

PGS is guaranteed to converge only for symmetric positive (semi)definite M with a positive
diagonal (and a solvable problem); elsewhere it may fail, but it must say so.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from solvers.lcp.complementarity import (
    HYPOTHESIS_SETTINGS,
    Planted,
    assert_honest,
    assert_solved,
    gram_pd,
    natural_residual,
    planted_problems,
)
from solvers.lcp.peer_lcp import PEER_DATA, lcp_params, load

from mdi_envs.solvers import SolverStatus, solve_lcp
from mdi_envs.solvers.lcp.pgs import PGSOptions, pgs_kernel


@pytest.mark.parametrize("path", lcp_params())
def test_peer_problem(path: Path) -> None:
    """Honest everywhere; CONVERGED on the symmetric PSD problems with positive diagonal."""
    M, q, info = load(path)
    result = solve_lcp(M, q, method="pgs")
    assert_honest(M, q, result)
    if info.sym_psd and info.has_solution:
        assert_solved(M, q, result)
    if info.unique and result.status is SolverStatus.CONVERGED:
        reference = solve_lcp(M, q, method="lemke")
        np.testing.assert_allclose(result.z, reference.z, rtol=1e-6, atol=1e-8)
    if np.diag(M).min() <= 0.0:
        # PGS divides by M_ii: a non-positive diagonal is a breakdown before the first sweep.
        assert result.status is SolverStatus.BREAKDOWN
        assert result.num_iter == 0
        np.testing.assert_array_equal(result.z, 0.0)
    if not info.has_solution:
        assert result.status is not SolverStatus.CONVERGED


def _mmc() -> tuple[np.ndarray, np.ndarray]:
    path = PEER_DATA / "lcp" / "lcp_mmc.dat"
    if not path.is_file():
        pytest.skip(f"peer data {PEER_DATA} absent")
    M, q, _ = load(path)
    return M, q


def test_sweep_limit_is_reported_not_hidden() -> None:
    """One sweep on mmc (26x26, badly scaled) is not enough: MAX_ITER, never CONVERGED."""
    M, q = _mmc()
    result = solve_lcp(M, q, method="pgs", max_iter=1)
    assert result.status is SolverStatus.MAX_ITER
    assert result.num_iter == 1
    assert natural_residual(M, q, result.z) > 1e-10


def test_sweep_count_is_the_first_sweep_meeting_tol() -> None:
    """With k the sweeps PGS needs: max_iter = k - 1 is MAX_ITER, max_iter = k is CONVERGED."""
    M, q = _mmc()
    needed = solve_lcp(M, q, method="pgs").num_iter
    assert needed > 2
    short = solve_lcp(M, q, method="pgs", max_iter=needed - 1)
    assert short.status is SolverStatus.MAX_ITER and short.num_iter == needed - 1
    assert short.residual > 1e-10
    enough = solve_lcp(M, q, method="pgs", max_iter=needed)
    assert enough.status is SolverStatus.CONVERGED and enough.num_iter == needed


def test_warm_start_at_the_solution_needs_no_sweep() -> None:
    """z0 = the solution: CONVERGED after 0 sweeps; z0 itself is not modified."""
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    q = np.array([-5.0, -6.0])
    z0 = np.array([4 / 3, 7 / 3])
    kept = z0.copy()
    result = solve_lcp(M, q, method="pgs", z0=z0)
    assert result.status is SolverStatus.CONVERGED and result.num_iter == 0
    np.testing.assert_array_equal(z0, kept)


def test_negative_start_is_projected() -> None:
    """A negative z0 is projected onto z >= 0 first, so it behaves exactly like z0 = 0."""
    M = gram_pd(np.random.default_rng(3), 8)
    q = -np.ones(8)
    from_zero = solve_lcp(M, q, method="pgs")
    from_negative = solve_lcp(M, q, method="pgs", z0=-np.arange(1.0, 9.0))
    assert from_negative.num_iter == from_zero.num_iter
    np.testing.assert_array_equal(from_negative.z, from_zero.z)


@pytest.mark.parametrize("relaxation", [0.5, 1.0, 1.5])
def test_relaxation_converges_on_spd(relaxation: float) -> None:
    """Any omega in (0, 2) converges on an SPD problem, to the same (unique) solution."""
    M = gram_pd(np.random.default_rng(11), 12)
    q = np.linspace(-2.0, 1.0, 12)
    result = solve_lcp(M, q, method="pgs", relaxation=relaxation)
    assert_solved(M, q, result)
    np.testing.assert_allclose(result.z, solve_lcp(M, q).z, rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("relaxation", [0.0, 2.0, -0.5, 2.5, float("nan")])
def test_invalid_relaxation(relaxation: float) -> None:
    """The relaxation omega must lie in the open interval (0, 2)."""
    message = "option 'relaxation' must be a finite number in \\(0, 2\\)"
    with pytest.raises(ValueError, match=message):
        solve_lcp(np.eye(2), -np.ones(2), method="pgs", relaxation=relaxation)


def test_kernel_reports_breakdown_on_a_zero_diagonal() -> None:
    """The kernel returns code BREAKDOWN with 0 sweeps and an infinite residual."""
    M = np.array([[0.0, 1.0], [1.0, 1.0]])
    code, sweeps, residual = pgs_kernel(M, np.array([-1.0, -1.0]), np.zeros(2), 10, 1e-10, 1.0)
    assert (code, sweeps, residual) == (int(SolverStatus.BREAKDOWN), 0, np.inf)


def test_default_options() -> None:
    """Defaults documented in PGSOptions."""
    options = PGSOptions()
    assert (options.max_iter, options.tol, options.relaxation) == (10_000, 1e-10, 1.0)


@HYPOTHESIS_SETTINGS
@given(planted_problems("spd", max_n=30))
def test_spd_problems_are_solved(problem: Planted) -> None:
    """Symmetric PD: PGS converges to the unique (planted) solution."""
    result = solve_lcp(problem.M, problem.q, method="pgs")
    assert_solved(problem.M, problem.q, result)
    scale = max(1.0, np.abs(problem.z).max())
    np.testing.assert_allclose(result.z, problem.z, rtol=0, atol=1e-8 * scale)


@HYPOTHESIS_SETTINGS
@given(planted_problems("p_diag_dominant", max_n=30))
def test_honest_outside_its_class(problem: Planted) -> None:
    """Non-symmetric P-matrices are outside PGS's class: any outcome, but an honest one."""
    result = solve_lcp(problem.M, problem.q, method="pgs", max_iter=200)
    assert_honest(problem.M, problem.q, result)
