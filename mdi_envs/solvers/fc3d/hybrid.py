"""Sparse semismooth Newton with a vanishing Levenberg shift, chained with NSGS (``hybrid``).

The Newton iteration of ``newton_ac`` (same Alart-Curnier function phi, same blocks A_i, B_i,
``J = blockdiag(A) + blockdiag(B) W``), but each step solves ``(J + lambda I) d = -phi`` by a
sparse LU (SuperLU through scipy) with lambda = ``shift`` |phi|, and the solver is chained with
the Gauss-Seidel method the way Siconos chains its solvers:

* ``warm_sweeps`` NSGS sweeps first: they find the contact regimes cheaply;
* Newton steps with an Armijo backtracking on psi = |phi|^2 / 2; a direction that is not a
  descent direction is replaced by steepest descent -J^T phi;
* when the line search fails (a kink of phi, typically where redundant contacts make W
  singular), ``warm_sweeps`` NSGS sweeps move r to another piece and Newton resumes.

The shift keeps the system regular where W is rank deficient (the capsule and rock-pile
problems of the Siconos collection, whose ``newton_ac`` stalls in proximal steps) and fades out
as |phi| -> 0, so the local rate is that of an inexact Newton method with forcing term O(|phi|).
W is used in compressed sparse row form (the large peer problems are 1-5 % nonzero), so a step
costs a sparse factorization instead of the dense O(n^3) elimination of ``newton_ac``.
Convergence is judged on the shared residual; the step limit is MAX_ITER.
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
from mdi_envs.solvers.fc3d.newton_ac import alart_curnier, contact_weights
from mdi_envs.solvers.fc3d.nsgs import NSGSOptions, nsgs_kernel
from mdi_envs.solvers.fc3d.problem import FrictionContact3D, natural_map
from mdi_envs.solvers.fc3d.registry import FC3D_METHODS
from mdi_envs.solvers.status import SolverStatus

_NSGS = NSGSOptions()
"""Options of the chained Gauss-Seidel sweeps (the NSGS defaults)."""


@dataclass(frozen=True)
class HybridOptions(SolverOptions):
    """Options of the Newton/NSGS hybrid.

    Attributes:
        max_iter: Newton step limit.
        warm_sweeps: NSGS sweeps before the first Newton step and after each failed line
            search (0: pure Newton; a failed line search is then a BREAKDOWN).
        armijo: sufficient-decrease constant of the line search, in (0, 1/2).
        max_backtracks: step halvings before the line search counts as failed.
        shift: Levenberg shift factor, lambda = shift * |phi|, >= 0.
        rho_scale: factor on the per-contact weight rho_i = 1 / ||W_ii||_F, > 0.
    """

    max_iter: int = 500
    warm_sweeps: int = 50
    armijo: float = 1e-4
    max_backtracks: int = 40
    shift: float = 1.0
    rho_scale: float = 1.0

    def __post_init__(self) -> None:
        super().__post_init__()
        require_integer_option(self, "warm_sweeps", minimum=0)
        require_real_option(
            self, "armijo", low=0.0, high=0.5, low_inclusive=False, high_inclusive=False
        )
        require_integer_option(self, "max_backtracks", minimum=1)
        require_real_option(self, "shift", low=0.0)
        require_real_option(self, "rho_scale", low=0.0, low_inclusive=False)


@njit(cache=True)
def alart_curnier_blocks(
    mu: FloatArray, rho: FloatArray, r: FloatArray, u: FloatArray, phi: FloatArray,
    A: FloatArray, B: FloatArray, with_jacobian: bool,
) -> float:
    """``alart_curnier`` (phi (3 nc,), blocks A, B (nc, 3, 3) in place); returns |phi|^2 / 2."""
    return alart_curnier(mu, rho, r, u, phi, A, B, with_jacobian)


def _block_diagonal(blocks: FloatArray) -> sp.bsr_matrix:
    """The (3 nc, 3 nc) block-diagonal sparse matrix of blocks (nc, 3, 3)."""
    nc = blocks.shape[0]
    return sp.bsr_matrix((blocks, np.arange(nc), np.arange(nc + 1)), shape=(3 * nc, 3 * nc))


def _sweeps(problem: FrictionContact3D, r: FloatArray, count: int, tol: float) -> None:
    """``count`` NSGS sweeps on r (in place) with the NSGS defaults."""
    nsgs_kernel(
        problem.W, problem.q, problem.mu, r, count, tol, _NSGS.local_max_iter, _NSGS.local_tol,
        _NSGS.armijo, _NSGS.max_backtracks, _NSGS.rho_scale, _NSGS.relaxation, _NSGS.damping,
    )


@FC3D_METHODS.register(
    "hybrid", HybridOptions, "sparse Newton (Levenberg shift) chained with NSGS sweeps"
)
def solve_hybrid(
    problem: FrictionContact3D, r0: FloatArray | None, options: HybridOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` from ``r0`` (default 0); returns (r, status, Newton steps)."""
    W_dense, q, mu = problem.W, problem.q, problem.mu
    n = q.shape[0]
    nc = n // 3
    tol = float(options.tol)
    W = sp.csr_matrix(W_dense)
    rho = contact_weights(W_dense, float(options.rho_scale))
    r = np.zeros(n) if r0 is None else r0.copy()
    if options.warm_sweeps > 0:
        _sweeps(problem, r, int(options.warm_sweeps), tol)
    u, phi = np.empty(n), np.empty(n)
    A, B = np.empty((nc, 3, 3)), np.empty((nc, 3, 3))
    trial_u, trial_phi = np.empty(n), np.empty(n)
    identity = sp.identity(n, format="csc")
    for step in range(int(options.max_iter) + 1):
        if natural_map(W_dense, q, mu, r, u) <= tol:
            return r, SolverStatus.CONVERGED, step
        if step == options.max_iter:
            break
        psi = alart_curnier_blocks(mu, rho, r, u, phi, A, B, True)
        J = (_block_diagonal(A) + _block_diagonal(B) @ W).tocsc()
        grad = J.T @ phi
        try:
            d = spla.splu(J + options.shift * np.sqrt(2.0 * psi) * identity).solve(-phi)
            slope = float(grad @ d)
            if not np.isfinite(slope) or slope >= 0.0:
                raise ValueError("not a descent direction")
        except (RuntimeError, ValueError):
            d = -grad
            slope = -float(grad @ grad)
        t = 1.0
        for _ in range(int(options.max_backtracks)):
            trial_r = r + t * d
            trial_u[:] = W @ trial_r + q
            trial_psi = alart_curnier_blocks(mu, rho, trial_r, trial_u, trial_phi, A, B, False)
            if trial_psi <= psi + options.armijo * t * slope:
                r = trial_r
                break
            t *= 0.5
        else:
            if options.warm_sweeps == 0:
                return r, SolverStatus.BREAKDOWN, step
            _sweeps(problem, r, int(options.warm_sweeps), tol)
    return r, SolverStatus.MAX_ITER, int(options.max_iter)


__all__ = ["HybridOptions", "alart_curnier_blocks", "solve_hybrid"]
