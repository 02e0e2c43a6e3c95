"""The convex quadratic program over the Coulomb cones, solved by Clarabel (interior point).

    min_r  1/2 r^T P r + c^T r    subject to   r_i in K_mu_i  for every contact i,

with P (3 nc, 3 nc) symmetric positive semidefinite (possibly singular) and K_mu the Coulomb
cone of ``mdi_envs.solvers.fc3d.problem``. Its KKT conditions are the cone complementarity
problem ``K_mu contains r _|_ P r + c in K_mu*``; for singular P the minimiser r need not be
unique, but ``P r`` is. Clarabel (an optional dependency: ``pip install "mdi-envs[conic]"``)
takes second-order cones {(t, x) : ||x|| <= t}; the row scaling ``(mu r_N, r_T)`` maps K_mu onto
one. A contact with mu = 0 gets a nonnegative cone on r_N and a zero cone on r_T instead.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from mdi_envs._types import FloatArray

_FAILED = frozenset({"PrimalInfeasible", "DualInfeasible", "AlmostPrimalInfeasible",
                     "AlmostDualInfeasible"})
"""Clarabel outcomes that leave no usable minimiser (infeasible, or unbounded below)."""


def import_clarabel() -> Any:
    """Return the ``clarabel`` module.

    Raises:
        ImportError: clarabel is not installed; the message names the extra that provides it.
    """
    try:
        import clarabel
    except ImportError as error:
        raise ImportError(
            "the FC3D method 'fixed_point_socp' needs the conic solver clarabel: "
            'pip install "mdi-envs[conic]" (or pip install clarabel)'
        ) from error
    return clarabel


class ConeQP:
    """The cone QP for fixed P and mu; ``solve(c)`` for each linear term c.

    Args:
        P: (3 nc, 3 nc) symmetric positive semidefinite matrix, dense or ``scipy.sparse``.
        mu: (nc,) friction coefficients, >= 0.
        tol: Clarabel's gap and feasibility tolerances (``tol_gap_abs``, ``tol_gap_rel``,
            ``tol_feas``).
        max_iter: Clarabel's interior-point iteration limit.
    """

    def __init__(self, P: FloatArray | sp.spmatrix, mu: FloatArray, tol: float,
                 max_iter: int) -> None:
        clarabel = import_clarabel()
        nc = mu.shape[0]
        self._clarabel = clarabel
        self._P = sp.triu(sp.csc_matrix(P), format="csc")
        scale = np.ones((nc, 3))
        scale[:, 0] = np.where(mu > 0.0, mu, 1.0)
        self._A = -sp.diags(scale.ravel(), format="csc")
        self._b = np.zeros(3 * nc)
        self._cones: list[Any] = []
        for m in mu:
            if m > 0.0:
                self._cones.append(clarabel.SecondOrderConeT(3))
            else:
                self._cones += [clarabel.NonnegativeConeT(1), clarabel.ZeroConeT(2)]
        self._tol = float(tol)
        self._max_iter = int(max_iter)

    def _settings(self) -> Any:
        settings = self._clarabel.DefaultSettings()
        settings.verbose = False
        settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = self._tol
        settings.max_iter = self._max_iter
        settings.max_step_fraction = 0.999
        return settings

    def solve(self, c: FloatArray) -> FloatArray | None:
        """A minimiser r (3 nc,) for the linear term c (3 nc,); None when there is none.

        None means Clarabel found the problem infeasible or unbounded below (then the cone
        complementarity problem has no solution), or returned a non-finite point. Inaccurate
        interior-point outcomes (``AlmostSolved``, ``InsufficientProgress``, ...) still return
        their last iterate: the caller judges it by its own residual.
        """
        solution = self._clarabel.DefaultSolver(
            self._P, np.asarray(c, dtype=np.float64), self._A, self._b, self._cones,
            self._settings(),
        ).solve()
        r = np.array(solution.x, dtype=np.float64)
        if str(solution.status) in _FAILED or not np.all(np.isfinite(r)):
            return None
        return r


__all__ = ["ConeQP", "import_clarabel"]
