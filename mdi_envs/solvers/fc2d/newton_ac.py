"""Sparse semismooth Newton on the planar Alart-Curnier function, with a line search.

Per contact i, with u = W r + q and rho_i = 1 / ||W_ii||_F:

    a_N = r_N - rho u_N,   a_T = r_T - rho u_T,   R = mu max(0, a_N),
    phi_N = r_N - max(0, a_N),   phi_T = r_T - clip(a_T, -R, R),

zero exactly at the FC2D solutions. On each piece d phi_i = A_i dr_i + B_i du_i, so a generalized
Jacobian is ``J = blockdiag(A) + blockdiag(B) W``, as sparse as W. Each step solves
``(J + lambda I) d = -phi`` with a sparse LU (SuperLU through scipy), lambda = ``shift`` |phi|:
a vanishing Levenberg shift that keeps the system regular where redundant contacts make W, and
so J, singular, and costs nothing in the local rate (an inexact Newton step with forcing term
O(|phi|)). The step backtracks on the merit psi = |phi|^2 / 2 (Armijo); a direction that is not
a descent direction is replaced by steepest descent -J^T phi. Convergence is judged on the shared
residual; the step limit is MAX_ITER, a failed line search BREAKDOWN.

Warm-started by a few Gauss-Seidel sweeps (``warm_sweeps``), as Siconos chains its solvers: the
sweeps find the contact regimes cheaply, the Newton steps then converge fast; on the granular
peer problems NSGS alone needs more than 10^5 sweeps for 1e-8.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from mdi_envs._types import FloatArray
from mdi_envs.solvers._registry import (
    SolverOptions,
    require_integer_option,
    require_real_option,
)
from mdi_envs.solvers.fc2d.nsgs import nsgs_fc2d_kernel
from mdi_envs.solvers.fc2d.problem import FrictionContact2D, natural_map
from mdi_envs.solvers.fc2d.registry import FC2D_METHODS
from mdi_envs.solvers.status import SolverStatus


@dataclass(frozen=True)
class FC2DNewtonOptions(SolverOptions):
    """Options of the FC2D sparse Newton method.

    Attributes:
        max_iter: Newton step limit.
        warm_sweeps: Gauss-Seidel sweeps before the first Newton step (0: none).
        armijo: sufficient-decrease constant of the line search, in (0, 1/2).
        max_backtracks: step halvings before the line search is declared failed.
        shift: Levenberg shift factor: lambda = shift * |phi|, >= 0.
    """

    max_iter: int = 200
    warm_sweeps: int = 50
    armijo: float = 1e-4
    max_backtracks: int = 40
    shift: float = 1.0

    def __post_init__(self) -> None:
        super().__post_init__()
        require_integer_option(self, "warm_sweeps", minimum=0)
        require_real_option(
            self, "armijo", low=0.0, high=0.5, low_inclusive=False, high_inclusive=False
        )
        require_integer_option(self, "max_backtracks", minimum=1)
        require_real_option(self, "shift", low=0.0)


@njit(cache=True)
def alart_curnier_2d(
    mu: FloatArray, rho: FloatArray, r: FloatArray, u: FloatArray, phi: FloatArray,
    A: FloatArray, B: FloatArray,
) -> float:
    """The planar AC function phi (2 nc,) and its blocks A, B (nc, 2, 2); returns |phi|^2 / 2.

    Args:
        mu, rho: (nc,). r, u: (2 nc,). phi, A, B: outputs (modified in place).
    """
    psi = 0.0
    for i in range(mu.shape[0]):
        k = 2 * i
        p = rho[i]
        a_n = r[k] - p * u[k]
        a_t = r[k + 1] - p * u[k + 1]
        for a in range(2):
            for b in range(2):
                A[i, a, b] = 0.0
                B[i, a, b] = 0.0
        if a_n > 0.0:
            phi[k] = p * u[k]
            B[i, 0, 0] = p
            radius = mu[i] * a_n
        else:
            phi[k] = r[k]
            A[i, 0, 0] = 1.0
            radius = 0.0
        if radius > 0.0 and abs(a_t) <= radius:
            phi[k + 1] = p * u[k + 1]
            B[i, 1, 1] = p
        else:
            s = 1.0 if a_t > 0.0 else (-1.0 if a_t < 0.0 else 0.0)
            phi[k + 1] = r[k + 1] - radius * s
            A[i, 1, 1] = 1.0
            if a_n > 0.0:
                A[i, 1, 0] = -mu[i] * s
                B[i, 1, 0] = mu[i] * s * p
        psi += 0.5 * (phi[k] * phi[k] + phi[k + 1] * phi[k + 1])
    return psi


def _block_diagonal(blocks: FloatArray) -> sp.bsr_matrix:
    """The (2 nc, 2 nc) block-diagonal sparse matrix of blocks (nc, 2, 2)."""
    nc = blocks.shape[0]
    return sp.bsr_matrix((blocks, np.arange(nc), np.arange(nc + 1)), shape=(2 * nc, 2 * nc))


@FC2D_METHODS.register(
    "newton_ac", FC2DNewtonOptions, "sparse semismooth Newton (Alart-Curnier), NSGS warm start"
)
def solve_fc2d_newton(
    problem: FrictionContact2D, r0: FloatArray | None, options: FC2DNewtonOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` from ``r0`` (default 0); returns (r, status, Newton steps)."""
    n = problem.q.shape[0]
    nc = n // 2
    args = (problem.indptr, problem.indices, problem.data, problem.q, problem.mu)
    W = sp.csr_matrix((problem.data, problem.indices, problem.indptr), shape=(n, n))
    r = np.zeros(n) if r0 is None else r0.copy()
    if options.warm_sweeps > 0:
        nsgs_fc2d_kernel(*args, r, int(options.warm_sweeps), float(options.tol))
    diagonal = np.array([W[2 * i:2 * i + 2, 2 * i:2 * i + 2].toarray() for i in range(nc)])
    norms = np.sqrt((diagonal**2).sum(axis=(1, 2)))
    rho = np.where(norms > 0.0, 1.0 / np.where(norms > 0.0, norms, 1.0), 1.0)
    u, phi, A, B = np.empty(n), np.empty(n), np.empty((nc, 2, 2)), np.empty((nc, 2, 2))
    trial_u, trial_phi = np.empty(n), np.empty(n)
    trial_A, trial_B = np.empty((nc, 2, 2)), np.empty((nc, 2, 2))
    identity = sp.identity(n, format="csc")
    for step in range(int(options.max_iter) + 1):
        residual = natural_map(*args, r, u)
        if residual <= options.tol:
            return r, SolverStatus.CONVERGED, step
        if step == options.max_iter:
            break
        psi = alart_curnier_2d(problem.mu, rho, r, u, phi, A, B)
        J = (_block_diagonal(A) + _block_diagonal(B) @ W).tocsc()
        grad = J.T @ phi
        lam = options.shift * np.sqrt(2.0 * psi)
        try:
            d = spla.splu(J + lam * identity).solve(-phi)
            slope = float(grad @ d)
            if not np.isfinite(slope) or slope >= 0.0:
                raise ValueError("not a descent direction")
        except (RuntimeError, ValueError):
            d = -grad
            slope = -float(grad @ grad)
        t = 1.0
        for _ in range(int(options.max_backtracks)):
            trial_r = r + t * d
            natural_map(*args, trial_r, trial_u)
            trial_psi = alart_curnier_2d(problem.mu, rho, trial_r, trial_u, trial_phi,
                                         trial_A, trial_B)
            if trial_psi <= psi + options.armijo * t * slope:
                r = trial_r
                break
            t *= 0.5
        else:  # the line search failed: Gauss-Seidel sweeps move r to another piece
            if options.warm_sweeps == 0:
                return r, SolverStatus.BREAKDOWN, step
            nsgs_fc2d_kernel(*args, r, int(options.warm_sweeps), float(options.tol))
    return r, SolverStatus.MAX_ITER, int(options.max_iter)


__all__ = ["FC2DNewtonOptions", "alart_curnier_2d", "solve_fc2d_newton"]
