"""``solve_lcp``: the one entry point to every LCP method.

validate -> exact trivial cases -> dispatch to the registered method -> recompute the residual
with the shared measure, so that no method can report CONVERGED above its tolerance.

A method may register a *direct* path (Lemke does): the same steps after the shape checks --
NaN/inf screening, trivial cases, the method, ``natural_map`` and the status downgrade -- in one
compiled call, so the driver's fixed cost is one dispatch instead of several Python-level passes
over the data (about 3-4 us per call at n = 2: ``fixed_cost`` in
``benchmarks/results/solvers.json``, written by ``python -m mdi_envs bench solvers``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.solvers.lcp.problem import (
    LCP,
    LCPResult,
    as_finite_array,
    as_lcp_arrays,
    natural_map,
    raise_if_not_finite,
)
from mdi_envs.solvers.lcp.registry import DIRECT_M_NOT_FINITE, DIRECT_Q_NOT_FINITE, LCP_METHODS
from mdi_envs.solvers.status import SolverStatus


def solve_lcp(
    M: FloatArray,
    q: FloatArray,
    method: str = "lemke",
    z0: FloatArray | None = None,
    **options: Any,
) -> LCPResult:
    """Solve LCP(M, q): find z >= 0 with w = M z + q >= 0 and z . w = 0.

    Args:
        M: (n, n) matrix (no symmetry assumed).
        q: (n,) vector.
        method: one of ``LCP_METHODS.names()``: ``"lemke"`` (pivoting; the default),
            ``"pgs"`` (projected Gauss-Seidel), ``"newton_fb"`` (semismooth Newton on the
            Fischer-Burmeister function) or ``"enumerative"`` (exact, for tiny n).
        z0: (n,) starting point for the iterative methods (ignored by pivoting methods).
        **options: fields of the method's options dataclass (``tol``, ``max_iter``, ...).

    Returns:
        An ``LCPResult``; non-convergence is a status, not an exception.

    Raises:
        ValueError: NaN/inf or mis-shaped data, an unknown method or option.

    Example:
        >>> import numpy as np
        >>> result = solve_lcp(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]))
        >>> result.status.name, np.round(result.z, 6).tolist()
        ('CONVERGED', [1.333333, 2.333333])
    """
    spec = LCP_METHODS.lookup(method)
    opts = spec.make_options(options)
    if spec.direct is not None and z0 is None:
        M, q = as_lcp_arrays(M, q)
        n = q.shape[0]
        z, w = np.empty(n), np.empty(n)  # cheaper here than allocated and boxed by numba
        code, num_iter, residual = spec.direct(M, q, opts, z, w)
        if code < 0:
            raise_if_not_finite(code != DIRECT_M_NOT_FINITE, code != DIRECT_Q_NOT_FINITE)
        return LCPResult(z, w, _STATUS[code], num_iter, residual, method)
    problem = LCP(M, q)
    n = problem.size
    start = None if z0 is None else as_finite_array(z0, "z0", 1)
    if start is not None and start.shape[0] != n:
        raise ValueError(f"z0 has length {start.shape[0]}, expected {n}")

    if problem.is_trivial:
        z, status, num_iter = np.zeros(n), SolverStatus.CONVERGED, 0
    elif n == 1:
        z, status, num_iter = _solve_scalar(float(problem.M[0, 0]), float(problem.q[0]))
    else:
        z, status, num_iter = spec.solve(problem, start, opts)
    w = np.empty(n)
    residual = natural_map(problem.M, problem.q, z, w)
    if opts.check_solution and status is SolverStatus.CONVERGED and not residual <= opts.tol:
        status = SolverStatus.INACCURATE
    return LCPResult(z, w, status, num_iter, residual, method)


_STATUS = tuple(SolverStatus)
"""SolverStatus by code (indexing a tuple is cheaper than calling the enum)."""


def _solve_scalar(m: float, q: float) -> tuple[FloatArray, SolverStatus, int]:
    """Closed form of the 1x1 LCP with q < 0: z = -q/m if m > 0, otherwise no solution."""
    if m > 0.0:
        return np.array([-q / m]), SolverStatus.CONVERGED, 0
    return np.zeros(1), SolverStatus.NO_SOLUTION, 0


__all__ = ["solve_lcp"]
