"""The linear complementarity problem LCP(M, q) and the one residual every LCP method is judged by.

Find z in R^n with

    z >= 0,   w = M z + q >= 0,   z . w = 0.

Residual (dimensionless): ``||min(z, w)||_2 / max(||q||_2, 1)`` -- the natural-map norm, which is
zero exactly at solutions, relative to the data's scale but never divided by a vanishing ``q``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from mdi_envs._types import FloatArray
from mdi_envs.solvers.status import SolverStatus


def as_float_array(value: ArrayLike, name: str, ndim: int) -> FloatArray:
    """Convert ``value`` to a C-contiguous float64 array with ``ndim`` dimensions.

    Finiteness is not checked here (see ``is_all_finite``).

    Raises:
        ValueError: a non-numeric entry or the wrong number of dimensions; the message names
            ``name``.
    """
    if (
        type(value) is np.ndarray
        and value.dtype == np.float64
        and value.flags.c_contiguous
        and value.ndim == ndim
    ):
        return value  # the common case, already in the required form
    try:
        if np.iscomplexobj(value):
            raise ValueError("complex entries")
        array = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as error:
        raise ValueError(f"{name} must be a numeric array of real values: {error}") from None
    if array.ndim != ndim:
        raise ValueError(f"{name} must have {ndim} dimension(s), got shape {array.shape}")
    return array


def as_finite_array(value: ArrayLike, name: str, ndim: int) -> FloatArray:
    """``as_float_array`` plus a check that every entry is finite.

    Raises:
        ValueError: as ``as_float_array``, or a NaN/inf entry; the message names ``name``.
    """
    array = as_float_array(value, name, ndim)
    if not is_all_finite(array.reshape(-1)):
        raise ValueError(f"{name} contains NaN or inf entries")
    return array


@njit(cache=True)
def is_all_finite(values: FloatArray) -> bool:
    """Whether every entry of the flat array ``values`` is finite."""
    for v in values:
        if not np.isfinite(v):
            return False
    return True


@njit(cache=True)
def _screen(M: FloatArray, q: FloatArray) -> tuple[bool, bool, bool]:
    """(M finite, q finite, q >= 0) for M (n, n), q (n,), in one compiled pass."""
    is_trivial = True
    for v in q:
        if not np.isfinite(v):
            return True, False, False
        if v < 0.0:
            is_trivial = False
    for v in M.reshape(-1):
        if not np.isfinite(v):
            return False, True, is_trivial
    return True, True, is_trivial


@dataclass(frozen=True)
class LCP:
    """Problem data of LCP(M, q): find z >= 0 with w = M z + q >= 0 and z . w = 0.

    Attributes:
        M: (n, n) matrix, any class (P, PSD, copositive, ...); no symmetry assumed.
        q: (n,) vector.

    Raises:
        ValueError: non-square M, mismatched q, or NaN/inf entries.
    """

    M: FloatArray
    q: FloatArray
    is_trivial: bool = field(init=False, repr=False)
    """Whether q >= 0, so that z = 0 solves the problem (derived from q)."""

    def __post_init__(self) -> None:
        M = as_float_array(self.M, "M", 2)
        q = as_float_array(self.q, "q", 1)
        if M.shape[0] != M.shape[1]:
            raise ValueError(f"M must be square, got shape {M.shape}")
        if q.shape[0] != M.shape[0]:
            raise ValueError(f"q has length {q.shape[0]} but M is {M.shape[0]}x{M.shape[1]}")
        is_M_finite, is_q_finite, is_trivial = _screen(M, q)
        if not is_M_finite:
            raise ValueError("M contains NaN or inf entries")
        if not is_q_finite:
            raise ValueError("q contains NaN or inf entries")
        object.__setattr__(self, "M", M)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "is_trivial", is_trivial)

    @property
    def size(self) -> int:
        """Number of complementarity pairs n."""
        return int(self.q.shape[0])

    def residual(self, z: FloatArray) -> float:
        """The shared residual ``||min(z, Mz+q)|| / max(||q||, 1)`` of a candidate z, shape (n,)."""
        return float(lcp_residual(self.M, self.q, np.ascontiguousarray(z, dtype=np.float64)))


class LCPResult(NamedTuple):
    """Result of ``solve_lcp``.

    Attributes:
        z: (n,) solution candidate.
        w: (n,) ``M z + q`` recomputed from the data.
        status: outcome; only ``CONVERGED`` guarantees ``residual <= tol``.
        num_iter: pivots (Lemke), sweeps (PGS), Newton steps or candidate bases examined.
        residual: the shared residual measure of this module.
        method: name of the method that produced the result.
    """

    z: FloatArray
    w: FloatArray
    status: SolverStatus
    num_iter: int
    residual: float
    method: str


@njit(cache=True)
def natural_map(M: FloatArray, q: FloatArray, z: FloatArray, w: FloatArray) -> float:
    """Fill w (n,) with M z + q and return the residual ``||min(z, w)||_2 / max(||q||_2, 1)``.

    Args:
        M: (n, n). q: (n,). z: (n,). w: (n,) output (modified in place).
    """
    n = q.shape[0]
    acc = 0.0
    qq = 0.0
    for i in range(n):
        wi = q[i]
        for j in range(n):
            wi += M[i, j] * z[j]
        w[i] = wi
        m = min(z[i], wi)
        acc += m * m
        qq += q[i] * q[i]
    return np.sqrt(acc) / max(np.sqrt(qq), 1.0)


@njit(cache=True)
def lcp_residual(M: FloatArray, q: FloatArray, z: FloatArray) -> float:
    """The shared residual ``||min(z, M z + q)||_2 / max(||q||_2, 1)`` for z (n,)."""
    return natural_map(M, q, z, np.empty(q.shape[0]))


__all__ = [
    "LCP",
    "LCPResult",
    "as_finite_array",
    "as_float_array",
    "is_all_finite",
    "lcp_residual",
    "natural_map",
]
