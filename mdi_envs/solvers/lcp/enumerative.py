"""Exact solution of tiny LCPs by enumerating complementary index sets.

For each active set alpha (in order of size, the empty set first) solve
``M[alpha, alpha] z[alpha] = -q[alpha]`` and accept the first candidate with z >= 0 and
w = M z + q >= 0 (to a scale-relative tolerance). 2^n candidates, each an |alpha|^3 solve: the
right tool for the stepper's common case (one to three closed contacts or engaged brakes), and
a slow one beyond ``max_size``. Index sets whose principal block is singular are skipped, so a
solution reachable only through a singular block (possible for degenerate, non-P matrices) is
not found; that is reported as NO_SOLUTION.
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
from mdi_envs.solvers.lcp.problem import LCP
from mdi_envs.solvers.lcp.registry import LCP_METHODS
from mdi_envs.solvers.status import (
    CODE_CONVERGED,
    CODE_MAX_ITER,
    CODE_NO_SOLUTION,
    SolverStatus,
)


@dataclass(frozen=True)
class EnumerativeOptions(SolverOptions):
    """Options of the enumerative method.

    Attributes:
        max_iter: limit on the candidate index sets examined (the default covers n <= 24).
        max_size: largest n accepted (2^n candidates are examined in the worst case).
        feasibility_tol: a candidate's negative entries are accepted down to
            ``-feasibility_tol * max(|q|_inf, 1)``.
    """

    max_iter: int = 1 << 24
    max_size: int = 12
    feasibility_tol: float = 1e-12

    def __post_init__(self) -> None:
        super().__post_init__()
        require_integer_option(self, "max_size", minimum=1)
        require_real_option(self, "feasibility_tol", low=0.0, high=1.0)


@njit(cache=True)
def enumerative_kernel(
    M: FloatArray, q: FloatArray, max_iter: int, feasibility_tol: float, z: FloatArray
) -> tuple[int, int]:
    """Examine complementary index sets of LCP(M, q) by increasing size.

    Args:
        M: (n, n). q: (n,). max_iter, feasibility_tol: see ``EnumerativeOptions``.
        z: (n,) output, overwritten with the solution (zeros if none).

    Returns:
        (code, candidates examined): code 0 converged, 1 candidate limit, 5 no solution.
    """
    n = q.shape[0]
    q_scale = 1.0
    for i in range(n):
        q_scale = max(q_scale, abs(q[i]))
    floor = -feasibility_tol * q_scale
    A = np.empty((n, n))
    x = np.empty(n)
    index = np.empty(n, dtype=np.int64)
    examined = 0
    for size in range(n + 1):
        for mask in range(1 << n):
            if _popcount(mask) != size:
                continue
            if examined == max_iter:
                for i in range(n):
                    z[i] = 0.0
                return CODE_MAX_ITER, examined
            examined += 1
            k = 0
            for i in range(n):
                if mask >> i & 1:
                    index[k] = i
                    k += 1
            Ak = A[:k, :k]
            xk = x[:k]
            for a in range(k):
                xk[a] = -q[index[a]]
                for b in range(k):
                    Ak[a, b] = M[index[a], index[b]]
            if not lu_solve_inplace(Ak, xk, 1e-13):
                continue
            is_feasible = True
            for a in range(k):
                if xk[a] < floor:
                    is_feasible = False
            if not is_feasible:
                continue
            for i in range(n):
                z[i] = 0.0
            for a in range(k):
                z[index[a]] = max(xk[a], 0.0)
            for i in range(n):
                if mask >> i & 1:
                    continue
                w = q[i]
                for j in range(n):
                    w += M[i, j] * z[j]
                if w < floor:
                    is_feasible = False
                    break
            if is_feasible:
                return CODE_CONVERGED, examined
    for i in range(n):
        z[i] = 0.0
    return CODE_NO_SOLUTION, examined


@njit(cache=True)
def _popcount(mask: int) -> int:
    count = 0
    while mask:
        count += mask & 1
        mask >>= 1
    return count


@LCP_METHODS.register("enumerative", EnumerativeOptions, "exact enumeration of index sets (tiny n)")
def solve_enumerative(
    problem: LCP, z0: FloatArray | None, options: EnumerativeOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` exactly by enumeration; returns (z, status, candidates examined).

    Raises:
        ValueError: ``problem.size > options.max_size``.
    """
    if problem.size > options.max_size:
        raise ValueError(
            f"method 'enumerative' examines 2^n index sets; n = {problem.size} exceeds "
            f"max_size = {options.max_size} (use 'lemke')"
        )
    z = np.empty(problem.size)
    code, examined = enumerative_kernel(
        problem.M, problem.q, options.max_iter, options.feasibility_tol, z
    )
    return z, SolverStatus(code), examined


__all__ = ["EnumerativeOptions", "enumerative_kernel", "solve_enumerative"]
