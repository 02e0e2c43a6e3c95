"""FC2D by its exact LCP reformulation, solved by Lemke's method (dense; moderate sizes).

Per contact i the LCP has four unknowns z = (r_N, b_+, b_-, s) >= 0, the tangential impulse
r_T = b_+ - b_- split into its positive and negative parts and s the slip speed, with

    w_N  = u_N              >= 0  _|_  r_N
    w_+  = s + u_T          >= 0  _|_  b_+
    w_-  = s - u_T          >= 0  _|_  b_-
    w_s  = mu r_N - b_+ - b_-  >= 0  _|_  s

and u = W (r_N, b_+ - b_-) + q. A slip u_T > 0 forces s >= u_T > 0, so b_+ = 0 and
b_- = mu r_N (w_s = 0), s = u_T (w_- = 0): r_T = -mu r_N. With u_T = 0 and s = 0,
|r_T| <= b_+ + b_- <= mu r_N: stick. Every LCP solution is thus a Coulomb solution and
conversely (Stewart & Trinkle's planar friction LCP, the reformulation Siconos' FC2D Lemke
solver uses). For a positive semidefinite W the matrix is copositive-plus, the class on which
Lemke's method terminates with a solution.
"""

from __future__ import annotations

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.solvers.fc2d.problem import FrictionContact2D
from mdi_envs.solvers.fc2d.registry import FC2D_METHODS
from mdi_envs.solvers.lcp.lemke import LemkeOptions, lemke_solve
from mdi_envs.solvers.status import SolverStatus


def friction_lcp(W: FloatArray, q: FloatArray, mu: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The LCP (M, q_lcp) of the module docstring for dense W (2 nc, 2 nc), q (2 nc,), mu (nc,).

    Returns:
        M (4 nc, 4 nc) and q_lcp (4 nc,), unknowns ordered (r_N, b_+, b_-, s) per contact.
    """
    nc = mu.shape[0]
    M = np.zeros((4 * nc, 4 * nc))
    columns = np.empty((2 * nc, 4 * nc))
    columns[:, 0::4] = W[:, 0::2]
    columns[:, 1::4] = W[:, 1::2]
    columns[:, 2::4] = -W[:, 1::2]
    columns[:, 3::4] = 0.0
    M[0::4] = columns[0::2]
    M[1::4] = columns[1::2]
    M[2::4] = -columns[1::2]
    contacts = np.arange(nc)
    M[4 * contacts + 1, 4 * contacts + 3] = 1.0
    M[4 * contacts + 2, 4 * contacts + 3] = 1.0
    M[4 * contacts + 3, 4 * contacts] = mu
    M[4 * contacts + 3, 4 * contacts + 1] = -1.0
    M[4 * contacts + 3, 4 * contacts + 2] = -1.0
    q_lcp = np.zeros(4 * nc)
    q_lcp[0::4] = q[0::2]
    q_lcp[1::4] = q[1::2]
    q_lcp[2::4] = -q[1::2]
    return M, q_lcp


@FC2D_METHODS.register("lemke", LemkeOptions, "Lemke's method on the exact LCP reformulation")
def solve_fc2d_lemke(
    problem: FrictionContact2D, r0: FloatArray | None, options: LemkeOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` through its LCP (``r0`` is ignored); returns (r, status, pivots)."""
    M, q_lcp = friction_lcp(problem.dense_W(), problem.q, problem.mu)
    z, code, pivots = lemke_solve(
        M, q_lcp, options.max_iter, options.pivot_tol, options.tie_tol, options.tol
    )
    r = np.empty(problem.q.shape[0])
    r[0::2] = z[0::4]
    r[1::2] = z[1::4] - z[2::4]
    return r, SolverStatus(code), pivots


__all__ = ["friction_lcp", "solve_fc2d_lemke"]
