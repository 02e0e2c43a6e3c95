"""``solve_fc3d``: the one entry point to every FC3D method.

validate -> exact trivial case -> dispatch to the registered method -> recompute u and the
shared residual, so that no method can report CONVERGED above its tolerance.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.solvers.fc3d.problem import FC3DResult, FrictionContact3D, natural_map
from mdi_envs.solvers.fc3d.registry import FC3D_METHODS
from mdi_envs.solvers.lcp.problem import as_finite_array
from mdi_envs.solvers.status import SolverStatus


def solve_fc3d(
    W: FloatArray,
    q: FloatArray,
    mu: FloatArray,
    method: str = "newton_ac",
    r0: FloatArray | None = None,
    **options: Any,
) -> FC3DResult:
    """Solve the 3-D Coulomb friction problem: u = W r + q, K_mu contains r _|_ u_hat in K_mu*.

    Contact i owns rows 3i (normal), 3i+1 and 3i+2 (tangents); see
    ``mdi_envs.solvers.fc3d.problem`` for the formulation and the residual.

    Args:
        W: (3 nc, 3 nc) Delassus matrix (no symmetry assumed).
        q: (3 nc,) free velocity.
        mu: (nc,) friction coefficients, >= 0.
        method: one of ``FC3D_METHODS.names()``: ``"newton_ac"`` (global semismooth Newton on
            the Alart-Curnier function; the default), ``"nsgs"`` (non-smooth block
            Gauss-Seidel over the contacts), ``"hybrid"`` (sparse shifted Newton chained with
            NSGS) or ``"fixed_point_socp"`` (De Saxce's fixed point on convex cone QPs; needs
            clarabel, the ``conic`` extra).
        r0: (3 nc,) starting point (warm start; default 0). Unused when every q_N >= 0: then
            r = 0 is returned at once, as an exact solution.
        **options: fields of the method's options dataclass (``tol``, ``max_iter``, ...).

    Returns:
        An ``FC3DResult``; non-convergence is a status, not an exception.

    Raises:
        ValueError: NaN/inf or mis-shaped data, mu < 0, an unknown method or option.
        ImportError: ``"fixed_point_socp"`` without clarabel installed.

    Example:
        One contact, W = I, pressed down (q_N = -1) and pushed sideways hard enough to slide
        (|q_T| = 2 > mu): r_N = 1 and r_T on the cone boundary, against the sliding direction.

        >>> import numpy as np
        >>> result = solve_fc3d(np.eye(3), np.array([-1.0, 2.0, 0.0]), np.array([0.5]))
        >>> result.status.name, np.round(result.r, 6).tolist(), np.round(result.u, 6).tolist()
        ('CONVERGED', [1.0, -0.5, 0.0], [0.0, 1.5, 0.0])
    """
    spec = FC3D_METHODS.lookup(method)
    opts = spec.make_options(options)
    problem = FrictionContact3D(W, q, mu)
    n = problem.q.shape[0]
    start = None if r0 is None else as_finite_array(r0, "r0", 1)
    if start is not None and start.shape[0] != n:
        raise ValueError(f"r0 has length {start.shape[0]}, expected {n}")

    if problem.is_trivial:
        r, status, num_iter = np.zeros(n), SolverStatus.CONVERGED, 0
    else:
        r, status, num_iter = spec.solve(problem, start, opts)
    u = np.empty(n)
    residual = float(natural_map(problem.W, problem.q, problem.mu, r, u))
    if opts.check_solution and status is SolverStatus.CONVERGED and not residual <= opts.tol:
        status = SolverStatus.INACCURATE
    return FC3DResult(r, u, status, num_iter, residual, method)


__all__ = ["solve_fc3d"]
