"""The mixed LCP: equality rows with free variables beside complementarity rows.

Find u in R^m (free) and z in R^n with

    0 = A u + C z + a,
    w = D u + B z + b,   0 <= z  _|_  w >= 0.

In the stepper the equality rows are engaged brakes (bilateral constraints, impulse free in R)
and the complementarity rows are contacts. Residual (dimensionless):
``sqrt(||A u + C z + a||^2 + ||min(z, w)||^2) / max(||(a, b)||, 1)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.solvers.lcp.problem import as_finite_array
from mdi_envs.solvers.status import SolverStatus


@dataclass(frozen=True)
class MLCP:
    """Problem data of the mixed LCP (see the module docstring).

    Attributes:
        A: (m, m) block of the equality rows acting on the free variables u.
        C: (m, n) block of the equality rows acting on z.
        D: (n, m) block of the complementarity rows acting on u.
        B: (n, n) block of the complementarity rows acting on z.
        a: (m,) constant of the equality rows.
        b: (n,) constant of the complementarity rows.

    Raises:
        ValueError: NaN/inf entries or block shapes that do not fit together (names the block).
    """

    A: FloatArray
    C: FloatArray
    D: FloatArray
    B: FloatArray
    a: FloatArray
    b: FloatArray

    def __post_init__(self) -> None:
        a = as_finite_array(self.a, "a", 1)
        b = as_finite_array(self.b, "b", 1)
        m, n = a.shape[0], b.shape[0]
        expected = {"A": (m, m), "C": (m, n), "D": (n, m), "B": (n, n)}
        for name, shape in expected.items():
            block = as_finite_array(getattr(self, name), name, 2)
            if block.shape != shape:
                raise ValueError(
                    f"{name} must have shape {shape} (m = {m} equality rows from a, "
                    f"n = {n} complementarity rows from b), got {block.shape}"
                )
            object.__setattr__(self, name, block)
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)

    @property
    def num_equalities(self) -> int:
        """m, the number of equality rows (free variables)."""
        return int(self.a.shape[0])

    @property
    def num_complementarities(self) -> int:
        """n, the number of complementarity pairs."""
        return int(self.b.shape[0])

    def residual(self, u: FloatArray, z: FloatArray) -> float:
        """The shared residual of a candidate (u (m,), z (n,)); see the module docstring."""
        equality = self.A @ u + self.C @ z + self.a
        w = self.D @ u + self.B @ z + self.b
        violation = np.concatenate([equality, np.minimum(z, w)])
        scale = max(float(np.sqrt(self.a @ self.a + self.b @ self.b)), 1.0)
        return float(np.linalg.norm(violation)) / scale


class MLCPResult(NamedTuple):
    """Result of ``solve_mlcp``.

    Attributes:
        u: (m,) free variables. z: (n,) complementarity variables. w: (n,) D u + B z + b.
        status: outcome; only CONVERGED guarantees ``residual <= tol``.
        num_iter: iterations of the inner LCP solve.
        residual: the shared residual of this module.
        method: name of the method.
    """

    u: FloatArray
    z: FloatArray
    w: FloatArray
    status: SolverStatus
    num_iter: int
    residual: float
    method: str


__all__ = ["MLCP", "MLCPResult"]
