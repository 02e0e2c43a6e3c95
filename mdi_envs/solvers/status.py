"""Solver status codes shared by every complementarity problem type.

Non-convergence is reported through these codes, never raised: callers (the stepper, the
environments) put the status into their diagnostics.
"""

from __future__ import annotations

from enum import IntEnum


class SolverStatus(IntEnum):
    """Outcome of one solve.

    Attributes:
        CONVERGED: the method's own stopping test passed *and* the shared residual measure of the
            problem type is within the requested tolerance.
        MAX_ITER: the iteration (or pivot) limit was reached first.
        RAY_TERMINATION: Lemke's method left along a secondary ray. On an infeasible LCP this is
            the correct answer; on a feasible one it means the matrix class is outside what
            Lemke's method handles (e.g. bimatrix games).
        BREAKDOWN: a numerical failure: a singular Newton system, a failed line search, or a
            non-positive diagonal entry where the method divides by it.
        INACCURATE: the method stopped believing it had solved the problem, but the shared
            residual measure exceeds the tolerance (so it is never reported as CONVERGED).
        NO_SOLUTION: an exhaustive method (enumeration) examined every candidate and none
            satisfies the conditions.
    """

    CONVERGED = 0
    MAX_ITER = 1
    RAY_TERMINATION = 2
    BREAKDOWN = 3
    INACCURATE = 4
    NO_SOLUTION = 5

    @property
    def is_success(self) -> bool:
        """Whether the result can be used as a solution."""
        return self is SolverStatus.CONVERGED



# Plain-int copies for compiled kernels, which return codes; wrappers turn them back into
# ``SolverStatus(code)``.
CODE_CONVERGED = int(SolverStatus.CONVERGED)
CODE_MAX_ITER = int(SolverStatus.MAX_ITER)
CODE_RAY_TERMINATION = int(SolverStatus.RAY_TERMINATION)
CODE_BREAKDOWN = int(SolverStatus.BREAKDOWN)
CODE_NO_SOLUTION = int(SolverStatus.NO_SOLUTION)
CODE_INACCURATE = int(SolverStatus.INACCURATE)

__all__ = [
    "CODE_BREAKDOWN",
    "CODE_CONVERGED",
    "CODE_INACCURATE",
    "CODE_MAX_ITER",
    "CODE_NO_SOLUTION",
    "CODE_RAY_TERMINATION",
    "SolverStatus",
]
