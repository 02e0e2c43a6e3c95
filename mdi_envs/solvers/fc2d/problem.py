"""The planar Coulomb friction-contact problem (Siconos' local FC2D) and its shared residual.

Given the Delassus matrix W (2 nc x 2 nc, not assumed symmetric), the free velocity q (2 nc,)
and friction coefficients mu (nc,), find impulses r and velocities u = W r + q such that for
every contact i, with rows 2i (normal) and 2i+1 (tangent):

    0 <= u_N  _|_  r_N >= 0                                     (Signorini)
    |r_T| <= mu r_N;  u_T = 0 if |r_T| < mu r_N,
    r_T = -mu r_N sign(u_T) if u_T != 0                         (Coulomb)

equivalently (De Saxce) r_i in K_mu = {|x_T| <= mu x_N}, u_hat_i = (u_N + mu |u_T|, u_T) in
K_mu* = {mu |y_T| <= y_N}, r_i . u_hat_i = 0.

Residual (dimensionless), the one every method is judged by, as for FC3D:

    ||r - P_K(r - u_hat)||_2 / max(||q||_2, 1).

W is held in compressed sparse row form (``indptr``, ``indices``, ``data``) so that the large
granular problems of the Siconos collection (up to 14 004 rows, about 0.3 % nonzero) are solved
without a dense matrix; a dense W is converted on construction.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp
from numba import njit

from mdi_envs._types import FloatArray, IntArray
from mdi_envs.solvers.lcp.problem import as_finite_array
from mdi_envs.solvers.status import SolverStatus


@dataclass(frozen=True)
class FrictionContact2D:
    """Problem data of the planar friction-contact problem (see the module docstring).

    Attributes:
        W: (2 nc, 2 nc) Delassus matrix, a dense array or a ``scipy.sparse`` matrix; contact i
            owns rows 2i (normal) and 2i+1 (tangent).
        q: (2 nc,) free velocity.
        mu: (nc,) friction coefficients, >= 0.

    Raises:
        ValueError: NaN/inf entries, a non-square W or one of odd size, mismatched q or mu, or
            a negative mu; the message names the field.
    """

    W: Any
    q: FloatArray
    mu: FloatArray
    indptr: IntArray = field(init=False, repr=False)
    """(2 nc + 1,) CSR row pointers of W."""
    indices: IntArray = field(init=False, repr=False)
    """(nnz,) CSR column indices of W, sorted within each row."""
    data: FloatArray = field(init=False, repr=False)
    """(nnz,) CSR values of W."""
    is_trivial: bool = field(init=False, repr=False)
    """Whether every normal free velocity q_N >= 0, so that r = 0 solves the problem."""

    def __post_init__(self) -> None:
        if sp.issparse(self.W):
            csr = sp.csr_matrix(self.W, dtype=np.float64)
            if not np.all(np.isfinite(csr.data)):
                raise ValueError("W contains NaN or inf entries")
        else:
            csr = sp.csr_matrix(as_finite_array(self.W, "W", 2))
        csr.sum_duplicates()
        csr.sort_indices()
        q = as_finite_array(self.q, "q", 1)
        mu = as_finite_array(self.mu, "mu", 1)
        rows, cols = csr.shape
        if rows != cols:
            raise ValueError(f"W must be square, got shape {csr.shape}")
        if rows % 2 != 0:
            raise ValueError(f"W must be (2 nc, 2 nc), got shape {csr.shape}")
        if q.shape[0] != rows:
            raise ValueError(f"q has length {q.shape[0]} but W is {rows}x{cols}")
        if 2 * mu.shape[0] != rows:
            raise ValueError(f"mu has length {mu.shape[0]} but W has {rows // 2} contacts")
        if mu.shape[0] and mu.min() < 0.0:
            raise ValueError(f"mu must be >= 0, got min(mu) = {mu.min()!r}")
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "indptr", csr.indptr.astype(np.int64))
        object.__setattr__(self, "indices", csr.indices.astype(np.int64))
        object.__setattr__(self, "data", np.ascontiguousarray(csr.data, dtype=np.float64))
        object.__setattr__(self, "is_trivial", bool(rows == 0 or q[0::2].min() >= 0.0))

    @property
    def num_contacts(self) -> int:
        """Number of contacts nc."""
        return int(self.mu.shape[0])

    def dense_W(self) -> FloatArray:
        """W as a dense (2 nc, 2 nc) array."""
        n = self.q.shape[0]
        return sp.csr_matrix((self.data, self.indices, self.indptr), shape=(n, n)).toarray()

    def residual(self, r: FloatArray) -> float:
        """The shared residual of a candidate r, shape (2 nc,)."""
        u = np.empty(self.q.shape[0])
        return float(
            natural_map(self.indptr, self.indices, self.data, self.q, self.mu,
                        np.ascontiguousarray(r, dtype=np.float64), u)
        )


class FC2DResult(NamedTuple):
    """Result of ``solve_fc2d``.

    Attributes:
        r: (2 nc,) contact impulses (normal, tangent per contact).
        u: (2 nc,) ``W r + q`` recomputed from the data.
        status: outcome; only ``CONVERGED`` guarantees ``residual <= tol``.
        num_iter: pivots (lemke) or Gauss-Seidel sweeps (nsgs).
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
def cone_projection_2d(mu: float, x_n: float, x_t: float) -> tuple[float, float]:
    """Euclidean projection of x = (x_n, x_t) onto the planar cone {|x_t| <= mu x_n}."""
    t = abs(x_t)
    if t <= mu * x_n and x_n >= 0.0:
        return x_n, x_t
    if mu * t <= -x_n:
        return 0.0, 0.0
    beta = (x_n + mu * t) / (1.0 + mu * mu)
    return beta, mu * beta * np.sign(x_t)


@njit(cache=True)
def csr_velocity(
    indptr: IntArray, indices: IntArray, data: FloatArray, q: FloatArray, r: FloatArray,
    u: FloatArray,
) -> None:
    """Fill u (n,) with W r + q for W in CSR form (indptr (n + 1,), indices, data (nnz,))."""
    for i in range(q.shape[0]):
        acc = q[i]
        for k in range(indptr[i], indptr[i + 1]):
            acc += data[k] * r[indices[k]]
        u[i] = acc


@njit(cache=True)
def residual_from_velocity(q: FloatArray, mu: FloatArray, r: FloatArray, u: FloatArray) -> float:
    """The shared residual of r (2 nc,) given its velocity u = W r + q (2 nc,)."""
    acc = 0.0
    for i in range(mu.shape[0]):
        k = 2 * i
        p_n, p_t = cone_projection_2d(
            mu[i], r[k] - (u[k] + mu[i] * abs(u[k + 1])), r[k + 1] - u[k + 1]
        )
        acc += (r[k] - p_n) ** 2 + (r[k + 1] - p_t) ** 2
    qq = 0.0
    for v in q:
        qq += v * v
    return np.sqrt(acc) / max(np.sqrt(qq), 1.0)


@njit(cache=True)
def natural_map(
    indptr: IntArray, indices: IntArray, data: FloatArray, q: FloatArray, mu: FloatArray,
    r: FloatArray, u: FloatArray,
) -> float:
    """Fill u (2 nc,) with W r + q (W in CSR form) and return the shared residual of r."""
    csr_velocity(indptr, indices, data, q, r, u)
    return residual_from_velocity(q, mu, r, u)


def fc2d_residual(W: Any, q: FloatArray, mu: FloatArray, r: FloatArray) -> float:
    """The shared residual ``||r - P_K(r - u_hat)||_2 / max(||q||_2, 1)`` of r (2 nc,).

    Args:
        W: (2 nc, 2 nc) dense or sparse. q: (2 nc,). mu: (nc,). r: (2 nc,).
    """
    return FrictionContact2D(W, q, mu).residual(r)


__all__ = [
    "FC2DResult",
    "FrictionContact2D",
    "cone_projection_2d",
    "csr_velocity",
    "fc2d_residual",
    "natural_map",
    "residual_from_velocity",
]
