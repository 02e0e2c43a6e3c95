"""Mixed LCP by elimination of the equality rows (Schur complement), then any LCP method.

With A nonsingular, u = -A^-1 (C z + a), and z solves LCP(B - D A^-1 C, b - D A^-1 a). For the
stepper's engaged brakes A is the brakes' Delassus block, nonsingular whenever the brake
directions are independent; a singular A (redundant brakes) is reported as BREAKDOWN.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np
import scipy.linalg

from mdi_envs._types import FloatArray
from mdi_envs.solvers._registry import SolverOptions
from mdi_envs.solvers.lcp.driver import solve_lcp
from mdi_envs.solvers.mlcp.problem import MLCP
from mdi_envs.solvers.mlcp.registry import MLCP_METHODS
from mdi_envs.solvers.status import SolverStatus


@dataclass(frozen=True)
class SchurOptions(SolverOptions):
    """Options of the Schur-complement method.

    Attributes:
        tol: tolerance on the shared MLCP residual.
        lcp_method: method for the reduced LCP (a name registered with ``solve_lcp``).
        lcp_options: options for that method (``tol`` defaults to this ``tol``).
        rcond: A counts as singular when its reciprocal condition number is below this.
    """

    lcp_method: str = "lemke"
    lcp_options: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    rcond: float = 1e-14


@MLCP_METHODS.register("schur", SchurOptions, "eliminate equality rows, then an LCP method")
def solve_schur(
    problem: MLCP, options: SchurOptions
) -> tuple[FloatArray, FloatArray, SolverStatus, int]:
    """Solve ``problem`` by elimination; returns (u, z, status, inner iterations)."""
    m, n = problem.num_equalities, problem.num_complementarities
    if m == 0:
        eliminated = np.empty((0, n + 1))
    else:
        with warnings.catch_warnings():  # singularity is judged below and reported as status
            warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)
            lu, pivots = scipy.linalg.lu_factor(problem.A, check_finite=False)
        diagonal = np.abs(np.diag(lu))
        if diagonal.min() <= options.rcond * max(diagonal.max(), np.finfo(float).tiny):
            return np.zeros(m), np.zeros(n), SolverStatus.BREAKDOWN, 0
        eliminated = scipy.linalg.lu_solve(
            (lu, pivots), np.column_stack([problem.C, problem.a]), check_finite=False
        )
    inverse_C, inverse_a = eliminated[:, :n], eliminated[:, n]
    lcp_options = {"tol": options.tol, **options.lcp_options}
    inner = solve_lcp(
        problem.B - problem.D @ inverse_C,
        problem.b - problem.D @ inverse_a,
        method=options.lcp_method,
        **lcp_options,
    )
    u = -(inverse_C @ inner.z + inverse_a)
    return u, inner.z, inner.status, inner.num_iter


__all__ = ["SchurOptions", "solve_schur"]
