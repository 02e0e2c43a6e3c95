"""Semismooth Newton method on the Fischer-Burmeister reformulation, with Armijo line search.

``phi(a, b) = sqrt(a^2 + b^2) - a - b`` vanishes iff a >= 0, b >= 0, a b = 0, so the LCP is the
nonsmooth equation ``Phi(z)_i = phi(z_i, w_i) = 0`` with w = M z + q. Each step solves
``H d = -Phi`` with an element H = diag(D_a) + diag(D_b) M of the generalized Jacobian, then
backtracks on the merit function ``Psi = |Phi|^2 / 2``; if the Newton direction is not a descent
direction (or H is singular) it takes the steepest-descent direction ``-H^T Phi`` instead
(De Luca, Facchinei & Kanzow, 1996). Locally quadratic for P-matrices; may stall elsewhere,
which is reported as MAX_ITER or BREAKDOWN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mdi_envs._types import FloatArray
from mdi_envs.solvers._linalg import lu_solve_inplace
from mdi_envs.solvers._registry import (
    SolverOptions,
    require_integer_option,
    require_real_option,
)
from mdi_envs.solvers.lcp.problem import LCP, lcp_residual
from mdi_envs.solvers.lcp.registry import LCP_METHODS
from mdi_envs.solvers.status import CODE_BREAKDOWN, CODE_CONVERGED, CODE_MAX_ITER, SolverStatus


@dataclass(frozen=True)
class NewtonFBOptions(SolverOptions):
    """Options of the Fischer-Burmeister Newton method.

    Attributes:
        max_iter: Newton step limit.
        armijo: sufficient-decrease constant sigma of the line search, in (0, 1/2).
        max_backtracks: step halvings before the line search is declared failed (BREAKDOWN).
    """

    max_iter: int = 100
    armijo: float = 1e-4
    max_backtracks: int = 40

    def __post_init__(self) -> None:
        super().__post_init__()
        require_real_option(
            self, "armijo", low=0.0, high=0.5, low_inclusive=False, high_inclusive=False
        )
        require_integer_option(self, "max_backtracks", minimum=1)


@njit(cache=True)
def _fb_merit(M: FloatArray, q: FloatArray, z: FloatArray, phi: FloatArray) -> float:
    """Fill phi (n,) with Phi(z) and return Psi = |phi|^2 / 2."""
    n = q.shape[0]
    psi = 0.0
    for i in range(n):
        w = q[i]
        for j in range(n):
            w += M[i, j] * z[j]
        p = np.sqrt(z[i] * z[i] + w * w) - z[i] - w
        phi[i] = p
        psi += 0.5 * p * p
    return psi


@njit(cache=True)
def newton_fb_kernel(
    M: FloatArray,
    q: FloatArray,
    z: FloatArray,
    max_iter: int,
    tol: float,
    armijo: float,
    max_backtracks: int,
) -> tuple[int, int]:
    """Semismooth Newton iterations on the FB function of LCP(M, q).

    Args:
        M: (n, n). q: (n,).
        z: (n,) starting point, overwritten by the iterate (modified in place).
        max_iter, tol, armijo, max_backtracks: see ``NewtonFBOptions``.

    Returns:
        (code, steps): code 0 converged, 1 step limit, 3 line search failure.
    """
    n = q.shape[0]
    phi = np.empty(n)
    trial_phi = np.empty(n)
    H = np.empty((n, n))
    d = np.empty(n)
    grad = np.empty(n)
    trial = np.empty(n)
    psi = _fb_merit(M, q, z, phi)
    for step in range(max_iter):
        if lcp_residual(M, q, z) <= tol:
            return CODE_CONVERGED, step
        for i in range(n):
            w = q[i]
            for j in range(n):
                w += M[i, j] * z[j]
            norm = np.sqrt(z[i] * z[i] + w * w)
            if norm > 1e-300:
                da = z[i] / norm - 1.0
                db = w / norm - 1.0
            else:  # the kink at (0, 0): any element of the generalized gradient will do
                da = 1.0 / np.sqrt(2.0) - 1.0
                db = da
            for j in range(n):
                H[i, j] = db * M[i, j]
            H[i, i] += da
            d[i] = -phi[i]
        for j in range(n):
            g = 0.0
            for i in range(n):
                g += H[i, j] * phi[i]
            grad[j] = g
        is_newton = lu_solve_inplace(H, d, 1e-14)
        slope = 0.0
        d_norm2 = 0.0
        g_norm2 = 0.0
        if is_newton:
            for i in range(n):
                slope += grad[i] * d[i]
                d_norm2 += d[i] * d[i]
        for i in range(n):
            g_norm2 += grad[i] * grad[i]
        if not is_newton or slope > -1e-12 * np.sqrt(d_norm2 * g_norm2):
            for i in range(n):
                d[i] = -grad[i]
            slope = -g_norm2
        if slope == 0.0:
            return CODE_BREAKDOWN, step
        t = 1.0
        accepted = False
        for _ in range(max_backtracks):
            for i in range(n):
                trial[i] = z[i] + t * d[i]
            trial_psi = _fb_merit(M, q, trial, trial_phi)
            if trial_psi <= psi + armijo * t * slope:
                accepted = True
                break
            t *= 0.5
        if not accepted:
            return CODE_BREAKDOWN, step
        for i in range(n):
            z[i] = trial[i]
            phi[i] = trial_phi[i]
        psi = trial_psi
    if lcp_residual(M, q, z) <= tol:
        return CODE_CONVERGED, max_iter
    return CODE_MAX_ITER, max_iter


@LCP_METHODS.register("newton_fb", NewtonFBOptions, "semismooth Newton on Fischer-Burmeister")
def solve_newton_fb(
    problem: LCP, z0: FloatArray | None, options: NewtonFBOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` from ``z0`` (default z = 0); returns (z, status, Newton steps).

    The iterate is returned as is: FB iterates may carry tiny negative entries, which the shared
    residual measures.
    """
    z = np.zeros(problem.size) if z0 is None else z0.copy()
    code, steps = newton_fb_kernel(
        problem.M, problem.q, z, options.max_iter, options.tol, options.armijo,
        options.max_backtracks,
    )
    return z, SolverStatus(code), steps


__all__ = ["NewtonFBOptions", "newton_fb_kernel", "solve_newton_fb"]
