"""Projected Gauss-Seidel (PGS) with over-/under-relaxation.

One sweep updates, for i = 1..n, ``z_i <- max(0, z_i - omega (q_i + M_i z) / M_ii)``. Converges
for symmetric positive (semi)definite M with positive diagonal and 0 < omega < 2; a slow but
cheap, warm-startable method, the usual choice for large contact problems.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mdi_envs._types import FloatArray
from mdi_envs.solvers._registry import SolverOptions, require_real_option
from mdi_envs.solvers.lcp.problem import LCP, lcp_residual
from mdi_envs.solvers.lcp.registry import LCP_METHODS
from mdi_envs.solvers.status import (
    CODE_BREAKDOWN,
    CODE_CONVERGED,
    CODE_MAX_ITER,
    SolverStatus,
)


@dataclass(frozen=True)
class PGSOptions(SolverOptions):
    """Options of projected Gauss-Seidel.

    Attributes:
        max_iter: sweep limit.
        tol: tolerance on the shared LCP residual, checked after every sweep.
        relaxation: omega in (0, 2); 1 is plain Gauss-Seidel.
    """

    max_iter: int = 10_000
    tol: float = 1e-10
    relaxation: float = 1.0

    def __post_init__(self) -> None:
        super().__post_init__()
        require_real_option(
            self, "relaxation", low=0.0, high=2.0, low_inclusive=False, high_inclusive=False
        )


@njit(cache=True)
def pgs_kernel(
    M: FloatArray, q: FloatArray, z: FloatArray, max_iter: int, tol: float, relaxation: float
) -> tuple[int, int, float]:
    """Projected Gauss-Seidel sweeps on LCP(M, q).

    Args:
        M: (n, n) with positive diagonal. q: (n,).
        z: (n,) starting point, overwritten by the iterate (modified in place).
        max_iter: sweep limit. tol: residual tolerance. relaxation: omega.

    Returns:
        (code, sweeps, residual): code 0 converged, 1 sweep limit, 3 non-positive diagonal.
    """
    n = q.shape[0]
    for i in range(n):
        if not M[i, i] > 0.0:
            return CODE_BREAKDOWN, 0, np.inf
        if z[i] < 0.0:
            z[i] = 0.0
    residual = lcp_residual(M, q, z)
    if residual <= tol:
        return CODE_CONVERGED, 0, residual
    for sweep in range(1, max_iter + 1):
        for i in range(n):
            w_i = q[i]
            for j in range(n):
                w_i += M[i, j] * z[j]
            z_i = z[i] - relaxation * w_i / M[i, i]
            z[i] = z_i if z_i > 0.0 else 0.0
        residual = lcp_residual(M, q, z)
        if residual <= tol:
            return CODE_CONVERGED, sweep, residual
    return CODE_MAX_ITER, max_iter, residual


@LCP_METHODS.register("pgs", PGSOptions, "projected Gauss-Seidel with relaxation")
def solve_pgs(
    problem: LCP, z0: FloatArray | None, options: PGSOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` by PGS from ``z0`` (default z = 0); returns (z, status, sweeps)."""
    z = np.zeros(problem.size) if z0 is None else z0.copy()
    code, sweeps, _ = pgs_kernel(
        problem.M, problem.q, z, options.max_iter, options.tol, options.relaxation
    )
    status = SolverStatus(code)
    return z, status, sweeps


__all__ = ["PGSOptions", "pgs_kernel", "solve_pgs"]
