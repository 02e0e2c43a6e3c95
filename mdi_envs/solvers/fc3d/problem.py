"""The 3-D (spatial, isotropic) Coulomb friction-contact problem and its one shared residual.

This is Siconos' "local" FC3D problem in De Saxce's formulation. Given the Delassus matrix W
(3 nc x 3 nc, *not* assumed symmetric), the free velocity q (3 nc,) and friction coefficients
mu (nc,), find the impulses r and velocities u = W r + q such that for every contact i, with
r_i = (r_N, r_T) and u_i = (u_N, u_T) the rows 3i (normal), 3i+1 and 3i+2 (tangents):

    K_mu  = {x : ||x_T|| <= mu x_N}                 (Coulomb cone; x_T = 0, x_N >= 0 if mu = 0)
    K_mu* = {y : mu ||y_T|| <= y_N}                 (its dual cone)
    u_hat_i = u_i + (mu_i ||u_T||, 0, 0)            (De Saxce's modified velocity)

    r_i in K_mu,   u_hat_i in K_mu*,   r_i . u_hat_i = 0.

This is equivalent to Signorini's condition ``0 <= u_N  _|_  r_N >= 0`` and Coulomb's law:
``u_T = 0`` and ``||r_T|| <= mu r_N`` (stick) or ``r_T = -mu r_N u_T / ||u_T||`` (slide).

Residual (dimensionless), judged the same way for every method:

    ||r - P_K(r - u_hat)||_2 / max(||q||_2, 1),

the natural map of the cone complementarity problem with rho = 1, stacked over all contacts.
It vanishes exactly at solutions; dividing by ``max(||q||, 1)`` makes it relative to the data's
scale without blowing up on problems with q ~ 0 (some Siconos files have ||q|| ~ 1e-19).

Projection onto K_mu of x = (x_N, x_T), t = ||x_T||:

* ``t <= mu x_N`` (and x_N >= 0): x is inside, P(x) = x;
* ``mu t <= -x_N`` (x is in the polar cone -K_mu*): P(x) = 0;
* otherwise P(x) = beta (1, mu x_T / t) with ``beta = (x_N + mu t) / (1 + mu^2)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numba import njit

from mdi_envs._types import FloatArray
from mdi_envs.solvers.lcp.problem import as_finite_array
from mdi_envs.solvers.status import SolverStatus


@dataclass(frozen=True)
class FrictionContact3D:
    """Problem data of the 3-D friction-contact problem (see the module docstring).

    Attributes:
        W: (3 nc, 3 nc) Delassus matrix; contact i owns rows 3i (normal), 3i+1, 3i+2
            (tangents). No symmetry or definiteness is assumed.
        q: (3 nc,) free velocity.
        mu: (nc,) friction coefficients, all >= 0.

    Raises:
        ValueError: NaN/inf entries, non-square W, a W whose size is not a multiple of 3,
            mismatched q or mu, or a negative mu; the message names the field.
    """

    W: FloatArray
    q: FloatArray
    mu: FloatArray
    is_trivial: bool = field(init=False, repr=False)
    """Whether every normal free velocity q_N >= 0, so that r = 0 solves the problem."""

    def __post_init__(self) -> None:
        W = as_finite_array(self.W, "W", 2)
        q = as_finite_array(self.q, "q", 1)
        mu = as_finite_array(self.mu, "mu", 1)
        if W.shape[0] != W.shape[1]:
            raise ValueError(f"W must be square, got shape {W.shape}")
        if W.shape[0] % 3 != 0:
            raise ValueError(f"W must be (3 nc, 3 nc), got shape {W.shape}")
        if q.shape[0] != W.shape[0]:
            raise ValueError(f"q has length {q.shape[0]} but W is {W.shape[0]}x{W.shape[1]}")
        if 3 * mu.shape[0] != W.shape[0]:
            raise ValueError(
                f"mu has length {mu.shape[0]} but W has {W.shape[0] // 3} contacts"
            )
        if mu.shape[0] and mu.min() < 0.0:
            raise ValueError(f"mu must be >= 0, got min(mu) = {mu.min()!r}")
        object.__setattr__(self, "W", W)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(
            self, "is_trivial", bool(q.shape[0] == 0 or q[0::3].min() >= 0.0)
        )

    @property
    def num_contacts(self) -> int:
        """Number of contacts nc."""
        return int(self.mu.shape[0])

    def residual(self, r: FloatArray) -> float:
        """The shared residual of a candidate r, shape (3 nc,) (see the module docstring)."""
        return float(
            fc3d_residual(self.W, self.q, self.mu, np.ascontiguousarray(r, dtype=np.float64))
        )


class FC3DResult(NamedTuple):
    """Result of ``solve_fc3d``.

    Attributes:
        r: (3 nc,) contact impulses (normal, tangent 1, tangent 2 per contact).
        u: (3 nc,) ``W r + q`` recomputed from the data.
        status: outcome; only ``CONVERGED`` guarantees ``residual <= tol``.
        num_iter: Newton steps or Gauss-Seidel sweeps.
        residual: the shared residual measure of this module.
        method: name of the method that produced the result.
    """

    r: FloatArray
    u: FloatArray
    status: SolverStatus
    num_iter: int
    residual: float
    method: str


@njit(cache=True)
def cone_projection(mu: float, x_n: float, x_t1: float, x_t2: float) -> tuple[float, float, float]:
    """Euclidean projection of x = (x_n, x_t1, x_t2) onto the Coulomb cone K_mu (mu >= 0)."""
    t = np.sqrt(x_t1 * x_t1 + x_t2 * x_t2)
    if t <= mu * x_n and x_n >= 0.0:
        return x_n, x_t1, x_t2
    if mu * t <= -x_n:
        return 0.0, 0.0, 0.0
    beta = (x_n + mu * t) / (1.0 + mu * mu)
    scale = mu * beta / t  # t > 0 here: t = 0 falls in one of the two cases above
    return beta, scale * x_t1, scale * x_t2


@njit(cache=True, inline="always")
def compute_velocity(W: FloatArray, q: FloatArray, r: FloatArray, u: FloatArray) -> None:
    """Fill u (m,) with W r + q, for W (m, n), q (m,), r (n,)."""
    for i in range(q.shape[0]):
        acc = q[i]
        for j in range(r.shape[0]):
            acc += W[i, j] * r[j]
        u[i] = acc


@njit(cache=True, inline="always")
def residual_from_velocity(q: FloatArray, mu: FloatArray, r: FloatArray, u: FloatArray) -> float:
    """The shared residual of r (3 nc,) given its velocity u = W r + q (3 nc,)."""
    acc = 0.0
    for i in range(mu.shape[0]):
        k = 3 * i
        u_t = np.sqrt(u[k + 1] * u[k + 1] + u[k + 2] * u[k + 2])
        x_n = r[k] - (u[k] + mu[i] * u_t)
        x_t1 = r[k + 1] - u[k + 1]
        x_t2 = r[k + 2] - u[k + 2]
        p_n, p_t1, p_t2 = cone_projection(mu[i], x_n, x_t1, x_t2)
        d_n = r[k] - p_n
        d_t1 = r[k + 1] - p_t1
        d_t2 = r[k + 2] - p_t2
        acc += d_n * d_n + d_t1 * d_t1 + d_t2 * d_t2
    qq = 0.0
    for v in q:
        qq += v * v
    return np.sqrt(acc) / max(np.sqrt(qq), 1.0)


@njit(cache=True)
def natural_map(
    W: FloatArray, q: FloatArray, mu: FloatArray, r: FloatArray, u: FloatArray
) -> float:
    """Fill u (3 nc,) with W r + q and return the shared residual of r (3 nc,)."""
    compute_velocity(W, q, r, u)
    return residual_from_velocity(q, mu, r, u)


@njit(cache=True)
def fc3d_residual(W: FloatArray, q: FloatArray, mu: FloatArray, r: FloatArray) -> float:
    """The shared residual ``||r - P_K(r - u_hat)||_2 / max(||q||_2, 1)`` of r (3 nc,).

    Args:
        W: (3 nc, 3 nc). q: (3 nc,). mu: (nc,). r: (3 nc,).
    """
    return natural_map(W, q, mu, r, np.empty(q.shape[0]))


__all__ = [
    "FC3DResult",
    "FrictionContact3D",
    "compute_velocity",
    "cone_projection",
    "fc3d_residual",
    "natural_map",
    "residual_from_velocity",
]
