"""The registry of LCP methods; each method module registers itself here on import.

A method may also register a *direct* path, ``direct(M, q, options, z, w) -> (code, num_iter,
residual)``: given C-contiguous float64 M (n, n) and q (n,) of checked shapes, it screens them
for NaN/inf, solves the trivial cases, runs the method, writes z and w = M z + q into the (n,)
outputs and returns the shared residual (``natural_map``) with the status code already downgraded
to INACCURATE above ``options.tol`` (if ``options.check_solution``), all in one compiled call.
Its code is a ``SolverStatus`` value or one of the negative codes below (nothing solved).
"""

from __future__ import annotations

from mdi_envs.solvers._registry import MethodRegistry

LCP_METHODS = MethodRegistry("LCP")

DIRECT_M_NOT_FINITE = -1
"""A direct path's code when M has a NaN/inf entry (q is screened first)."""
DIRECT_Q_NOT_FINITE = -2
"""A direct path's code when q has a NaN/inf entry."""

__all__ = ["DIRECT_M_NOT_FINITE", "DIRECT_Q_NOT_FINITE", "LCP_METHODS"]
