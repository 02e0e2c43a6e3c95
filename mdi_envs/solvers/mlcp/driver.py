"""``solve_mlcp``: the one entry point to the mixed-LCP methods (validate, dispatch, check)."""

from __future__ import annotations

from typing import Any

from mdi_envs._types import FloatArray
from mdi_envs.solvers.mlcp.problem import MLCP, MLCPResult
from mdi_envs.solvers.mlcp.registry import MLCP_METHODS
from mdi_envs.solvers.status import SolverStatus


def solve_mlcp(
    A: FloatArray,
    C: FloatArray,
    D: FloatArray,
    B: FloatArray,
    a: FloatArray,
    b: FloatArray,
    method: str = "schur",
    **options: Any,
) -> MLCPResult:
    """Solve the mixed LCP ``0 = A u + C z + a``, ``0 <= z _|_ D u + B z + b >= 0``.

    Args:
        A: (m, m). C: (m, n). D: (n, m). B: (n, n). a: (m,). b: (n,).
        method: one of ``MLCP_METHODS.names()`` (``"schur"``).
        **options: fields of the method's options dataclass.

    Returns:
        An ``MLCPResult``; non-convergence is a status, not an exception.

    Raises:
        ValueError: NaN/inf or mis-shaped blocks, an unknown method or option.

    Example:
        A brake (equality row) and a contact (complementarity row) sharing one body:

        >>> import numpy as np
        >>> r = solve_mlcp([[2.0]], [[1.0]], [[1.0]], [[2.0]], [1.0], [-4.0])
        >>> r.status.name, np.round(r.u, 6).tolist(), np.round(r.z, 6).tolist()
        ('CONVERGED', [-2.0], [3.0])
    """
    spec = MLCP_METHODS.lookup(method)
    opts = spec.make_options(options)
    problem = MLCP(A, C, D, B, a, b)
    u, z, status, num_iter = spec.solve(problem, opts)
    w = problem.D @ u + problem.B @ z + problem.b
    residual = problem.residual(u, z)
    if opts.check_solution and status is SolverStatus.CONVERGED and residual > opts.tol:
        status = SolverStatus.INACCURATE
    return MLCPResult(u, z, w, status, num_iter, residual, method)


__all__ = ["solve_mlcp"]
