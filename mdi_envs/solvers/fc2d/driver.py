"""``solve_fc2d``: the one entry point to every FC2D method.

validate -> exact trivial case -> dispatch to the registered method -> recompute u and the
shared residual, so that no method can report CONVERGED above its tolerance.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.solvers.fc2d.problem import FC2DResult, FrictionContact2D, natural_map
from mdi_envs.solvers.fc2d.registry import FC2D_METHODS
from mdi_envs.solvers.lcp.problem import as_finite_array
from mdi_envs.solvers.status import SolverStatus


def solve_fc2d(
    W: Any,
    q: FloatArray,
    mu: FloatArray,
    method: str = "lemke",
    r0: FloatArray | None = None,
    **options: Any,
) -> FC2DResult:
    """Solve the planar Coulomb friction problem: u = W r + q, Signorini and Coulomb per contact.

    Contact i owns rows 2i (normal) and 2i+1 (tangent), as in Siconos' FC2D; see
    ``mdi_envs.solvers.fc2d.problem`` for the conditions and the residual.

    Args:
        W: (2 nc, 2 nc) Delassus matrix, dense or ``scipy.sparse`` (no symmetry assumed).
        q: (2 nc,) free velocity.
        mu: (nc,) friction coefficients, >= 0.
        method: one of ``FC2D_METHODS.names()``: ``"lemke"`` (the exact LCP reformulation,
            4 nc unknowns, dense; the default) or ``"nsgs"`` (Gauss-Seidel over the contacts
            with an exact local solver; sparse, for large problems).
        r0: (2 nc,) starting point of ``nsgs`` (ignored by ``lemke``).
        **options: fields of the method's options dataclass (``tol``, ``max_iter``, ...).

    Returns:
        An ``FC2DResult``; non-convergence is a status, not an exception.

    Raises:
        ValueError: NaN/inf or mis-shaped data, mu < 0, an unknown method or option.

    Example:
        One contact, W = I, pressed down (q_N = -1) and pushed sideways hard enough to slide
        (|q_T| = 2 > mu = 0.5): r_N = 1, r_T = -0.5 and the slip u_T = 1.5.

        >>> import numpy as np
        >>> result = solve_fc2d(np.eye(2), np.array([-1.0, 2.0]), np.array([0.5]))
        >>> result.status.name, np.round(result.r, 6).tolist(), np.round(result.u, 6).tolist()
        ('CONVERGED', [1.0, -0.5], [0.0, 1.5])
    """
    spec = FC2D_METHODS.lookup(method)
    opts = spec.make_options(options)
    problem = FrictionContact2D(W, q, mu)
    n = problem.q.shape[0]
    start = None if r0 is None else as_finite_array(r0, "r0", 1)
    if start is not None and start.shape[0] != n:
        raise ValueError(f"r0 has length {start.shape[0]}, expected {n}")

    if problem.is_trivial:
        r, status, num_iter = np.zeros(n), SolverStatus.CONVERGED, 0
    else:
        r, status, num_iter = spec.solve(problem, start, opts)
    u = np.empty(n)
    residual = float(
        natural_map(problem.indptr, problem.indices, problem.data, problem.q, problem.mu, r, u)
    )
    if opts.check_solution and status is SolverStatus.CONVERGED and not residual <= opts.tol:
        status = SolverStatus.INACCURATE
    return FC2DResult(r, u, status, num_iter, residual, method)


__all__ = ["solve_fc2d"]
