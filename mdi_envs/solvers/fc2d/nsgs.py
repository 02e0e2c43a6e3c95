"""Non-smooth Gauss-Seidel over the contacts of FC2D, with an exact one-contact solver.

One sweep visits the contacts in order; contact i, the others frozen, sees the 2 x 2 problem
u_i = W_ii r_i + q_loc with q_loc = q_i + sum_{j != i} W_ij r_j, solved exactly by trying its
cases in turn: take-off (q_loc_N >= 0: r_i = 0), stick (W_ii r_i = -q_loc inside the cone),
slide in either direction (r_T = -s mu r_N, u_N = 0, s u_T >= 0). If none fits (a singular or
strongly non-symmetric W_ii), the candidate with the smallest local residual is kept. W is read
in CSR form, so a sweep costs O(nnz); the shared residual is checked after every sweep.
Convergence is linear at best and not guaranteed: the sweep limit is reported as MAX_ITER.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mdi_envs._types import FloatArray, IntArray
from mdi_envs.solvers._registry import SolverOptions
from mdi_envs.solvers.fc2d.problem import FrictionContact2D, cone_projection_2d, natural_map
from mdi_envs.solvers.fc2d.registry import FC2D_METHODS
from mdi_envs.solvers.status import CODE_CONVERGED, CODE_MAX_ITER, SolverStatus


@dataclass(frozen=True)
class FC2DNSGSOptions(SolverOptions):
    """Options of the FC2D Gauss-Seidel method.

    Attributes:
        max_iter: sweep limit.
        tol: tolerance on the shared residual, checked after every sweep.
    """

    max_iter: int = 100_000


@njit(cache=True)
def _local_residual(
    a: float, b: float, c: float, d: float, q_n: float, q_t: float, mu: float,
    r_n: float, r_t: float,
) -> float:
    """Natural-map residual of (r_n, r_t) on the 2 x 2 problem [[a, b], [c, d]] r + q."""
    u_n = a * r_n + b * r_t + q_n
    u_t = c * r_n + d * r_t + q_t
    p_n, p_t = cone_projection_2d(mu, r_n - (u_n + mu * abs(u_t)), r_t - u_t)
    return np.sqrt((r_n - p_n) ** 2 + (r_t - p_t) ** 2)


@njit(cache=True)
def local_solve(
    a: float, b: float, c: float, d: float, q_n: float, q_t: float, mu: float
) -> tuple[float, float]:
    """Exact solution (r_n, r_t) of the one-contact FC2D problem W = [[a, b], [c, d]], q.

    Cases in order: take-off, stick, slide with u_T >= 0, slide with u_T <= 0; if none is
    consistent, the candidate with the smallest local residual.
    """
    if q_n >= 0.0:
        return 0.0, 0.0
    best_n, best_t, best = 0.0, 0.0, _local_residual(a, b, c, d, q_n, q_t, mu, 0.0, 0.0)
    det = a * d - b * c
    if det != 0.0:
        r_n = (-q_n * d + b * q_t) / det
        r_t = (-a * q_t + c * q_n) / det
        if r_n >= 0.0 and abs(r_t) <= mu * r_n:
            return r_n, r_t
        if r_n > 0.0:
            r_t = max(-mu * r_n, min(mu * r_n, r_t))
            e = _local_residual(a, b, c, d, q_n, q_t, mu, r_n, r_t)
            if e < best:
                best_n, best_t, best = r_n, r_t, e
    for s in (1.0, -1.0):
        denominator = a - s * mu * b
        if denominator > 0.0:
            r_n = -q_n / denominator
            r_t = -s * mu * r_n
            u_t = c * r_n + d * r_t + q_t
            if s * u_t >= 0.0:
                return r_n, r_t
            e = _local_residual(a, b, c, d, q_n, q_t, mu, r_n, r_t)
            if e < best:
                best_n, best_t, best = r_n, r_t, e
    return best_n, best_t


@njit(cache=True)
def nsgs_fc2d_kernel(
    indptr: IntArray,
    indices: IntArray,
    data: FloatArray,
    q: FloatArray,
    mu: FloatArray,
    r: FloatArray,
    max_iter: int,
    tol: float,
) -> tuple[int, int, float]:
    """Gauss-Seidel sweeps on FC2D(W, q, mu), W in CSR form.

    Args:
        indptr: (n + 1,), indices, data: (nnz,): W (n, n), n = 2 nc, CSR. q: (n,). mu: (nc,).
        r: (n,) starting point, overwritten by the iterate (modified in place).
        max_iter, tol: see ``FC2DNSGSOptions``.

    Returns:
        (code, sweeps, residual): code 0 converged, 1 sweep limit; the shared residual of r.
    """
    n = q.shape[0]
    nc = n // 2
    diagonal = np.zeros((nc, 2, 2))
    for row in range(n):
        i = row // 2
        for k in range(indptr[row], indptr[row + 1]):
            col = indices[k]
            if col // 2 == i:
                diagonal[i, row - 2 * i, col - 2 * i] += data[k]
    u = np.empty(n)
    residual = natural_map(indptr, indices, data, q, mu, r, u)
    if residual <= tol:
        return CODE_CONVERGED, 0, residual
    for sweep in range(1, max_iter + 1):
        for i in range(nc):
            row = 2 * i
            acc_n = q[row]
            for k in range(indptr[row], indptr[row + 1]):
                col = indices[k]
                if col // 2 != i:
                    acc_n += data[k] * r[col]
            acc_t = q[row + 1]
            for k in range(indptr[row + 1], indptr[row + 2]):
                col = indices[k]
                if col // 2 != i:
                    acc_t += data[k] * r[col]
            r[row], r[row + 1] = local_solve(
                diagonal[i, 0, 0], diagonal[i, 0, 1], diagonal[i, 1, 0], diagonal[i, 1, 1],
                acc_n, acc_t, mu[i],
            )
        residual = natural_map(indptr, indices, data, q, mu, r, u)
        if residual <= tol:
            return CODE_CONVERGED, sweep, residual
    return CODE_MAX_ITER, max_iter, residual


@FC2D_METHODS.register("nsgs", FC2DNSGSOptions, "Gauss-Seidel over contacts, exact local solver")
def solve_fc2d_nsgs(
    problem: FrictionContact2D, r0: FloatArray | None, options: FC2DNSGSOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` by NSGS from ``r0`` (default r = 0); returns (r, status, sweeps)."""
    r = np.zeros(problem.q.shape[0]) if r0 is None else r0.copy()
    code, sweeps, _ = nsgs_fc2d_kernel(
        problem.indptr, problem.indices, problem.data, problem.q, problem.mu, r,
        int(options.max_iter), float(options.tol),
    )
    return r, SolverStatus(code), sweeps


__all__ = ["FC2DNSGSOptions", "local_solve", "nsgs_fc2d_kernel", "solve_fc2d_nsgs"]
