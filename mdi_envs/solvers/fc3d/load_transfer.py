"""Semismooth Newton for FC3D problems whose normal impulses follow an affine load law.

The differential-drive robot's contacts (``mdi_envs.stepping._spatial_kernel``) give FC3D
problems (``problem.py``) of a special form. Per contact i, rows 3i (normal), 3i+1, 3i+2
(tangents), with friction impulses t = (r_T,0, r_T,1, ...) (2 nc,):

    u_N,i = r_N,i - (n0_i + K_i . t)         (W[3i, 3j] = delta_ij, W[3i, 3j+1+a] = -K[i, 2j+a])
    u_T   = G t + b                         (W[3i+1+a, 3j] = 0, W[3i+1+a, 3j+1+b] = G[2i+a, 2j+b])

that is ``q = (-n0_i, b_2i, b_2i+1)_i``: the normal velocity is a load law, the tangential
velocities do not depend on the normal impulses. Signorini's condition then has the closed form
``r_N,i = max(0, n0_i + K_i . t)`` (a contact lifts where its load would be negative), and
the problem reduces to a nonsmooth equation in t alone (2 nc unknowns, not 3 nc):

    phi_i(t) = t_i - P_D(R_i)(t_i - rho_i (G t + b)_i),   R_i = mu_i max(0, n0_i + K_i . t),

the tangential rows of the Alart-Curnier function (``newton_ac``) with the normal rows solved,
with the weight rho_i = 1 / ||G_ii||_F (contact i's 2 x 2 diagonal block).
phi = 0 exactly at the FC3D solutions. ``newton_load_transfer`` solves it by semismooth Newton
with an Armijo line search on |phi|^2 / 2; the Newton systems are solved by
``solve_consistent_inplace`` (two wheels on one axle give duplicated lateral rows). It has no
globalisation beyond the line search: when a Newton system is inconsistent or the line search
fails it stops with BREAKDOWN, and the caller falls back to the full method (``newton_ac``).
Convergence is judged on the shared FC3D residual of the full problem (``problem.py``), so a
converged result is what ``newton_ac`` would accept.

On the robot's 9-unknown problems a Newton step here solves a 6 x 6 system where ``newton_ac``
solves a 9 x 9 one.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mdi_envs._borrowing import REFERENCE_COUNTED
from mdi_envs._types import FloatArray
from mdi_envs._views import array_view
from mdi_envs.solvers._linalg import solve_consistent_inplace
from mdi_envs.solvers.fc3d.newton_ac import slide_direction
from mdi_envs.solvers.fc3d.problem import compute_velocity, residual_from_velocity
from mdi_envs.solvers.status import CODE_BREAKDOWN, CODE_CONVERGED, CODE_MAX_ITER

_PIVOT_TOL = 1e-14
"""Relative pivot tolerance below which the Newton matrix counts as singular."""
_CONSISTENCY_TOL = 1e-10
"""A singular Newton system counts as consistent below this fraction of |phi| (as newton_ac)."""


_NUM_VECTORS = 8
"""Length-2 nc scratch vectors (then three of length nc, two of 3 nc and the Jacobian)."""


@njit(cache=True)
def load_transfer_workspace_size(nc: int) -> int:
    """Length of the flat scratch buffer of ``newton_load_transfer`` for nc contacts."""
    m = 2 * nc
    return _NUM_VECTORS * m + 3 * nc + 6 * nc + m * m


@njit(cache=True, inline="always")
def _workspace_in(buffer: FloatArray, nc: int) -> tuple[FloatArray, ...]:
    """The scratch arrays of ``newton_load_transfer`` as views into ``buffer``."""
    m = 2 * nc
    at = _NUM_VECTORS * m
    return (
        buffer[0:m],  # t
        buffer[m:2 * m],  # v = G t + b
        buffer[2 * m:3 * m],  # phi
        buffer[3 * m:4 * m],  # d
        buffer[4 * m:5 * m],  # swaps of the singular solve
        buffer[5 * m:6 * m],  # trial t
        buffer[6 * m:7 * m],  # trial v
        buffer[7 * m:8 * m],  # trial phi
        buffer[at:at + nc],  # rho
        buffer[at + nc:at + 2 * nc],  # loads n0 + K t
        buffer[at + 2 * nc:at + 3 * nc],  # trial loads
        buffer[at + 3 * nc:at + 6 * nc],  # q of the full problem
        buffer[at + 6 * nc:at + 9 * nc],  # u of the full problem
        array_view(buffer, at + 9 * nc, (m, m)),  # J, then its factors
    )


@njit(cache=True, inline="always")
def _state(G: FloatArray, b: FloatArray, n0: FloatArray, K: FloatArray, t: FloatArray,
           v: FloatArray, loads: FloatArray) -> None:
    """The tangential velocities v = G t + b (2 nc,) and the loads n0 + K t (nc,)."""
    compute_velocity(G, b, t, v)
    compute_velocity(K, n0, t, loads)


@njit(cache=True, inline="always")
def _tangential_ac(mu: FloatArray, rho: FloatArray, G: FloatArray, K: FloatArray, t: FloatArray,
                   v: FloatArray, loads: FloatArray, phi: FloatArray, J: FloatArray,
                   with_jacobian: bool) -> float:
    """phi(t) (2 nc,) and, when ``with_jacobian``, an element J of its generalized Jacobian.

    Returns the merit |phi|^2 / 2.
    """
    m = t.shape[0]
    psi = 0.0
    for i in range(mu.shape[0]):
        k = 2 * i
        loaded = loads[i] > 0.0
        radius = mu[i] * loads[i] if loaded else 0.0
        a1 = t[k] - rho[i] * v[k]
        a2 = t[k + 1] - rho[i] * v[k + 1]
        norm = np.sqrt(a1 * a1 + a2 * a2)
        if radius > 0.0 and norm <= radius:  # stick: phi = rho v
            phi[k] = rho[i] * v[k]
            phi[k + 1] = rho[i] * v[k + 1]
            if with_jacobian:
                for j in range(m):
                    J[k, j] = rho[i] * G[k, j]
                    J[k + 1, j] = rho[i] * G[k + 1, j]
        else:  # slide (or unloaded): phi = t - R n, n = a / |a|
            n1, n2, s = slide_direction(a1, a2, norm, radius)
            phi[k] = t[k] - radius * n1
            phi[k + 1] = t[k + 1] - radius * n2
            if with_jacobian:
                # d(R n) = n dR + s (I - n n^T) da, dR = mu H(load) K_i dt, da = dt_i - rho G_i dt
                h = mu[i] if loaded else 0.0
                p11 = s * (1.0 - n1 * n1)
                p12 = -s * n1 * n2
                p22 = s * (1.0 - n2 * n2)
                for j in range(m):
                    g1 = rho[i] * G[k, j]
                    g2 = rho[i] * G[k + 1, j]
                    J[k, j] = -n1 * h * K[i, j] + p11 * g1 + p12 * g2
                    J[k + 1, j] = -n2 * h * K[i, j] + p12 * g1 + p22 * g2
                J[k, k] += 1.0 - p11
                J[k, k + 1] -= p12
                J[k + 1, k] -= p12
                J[k + 1, k + 1] += 1.0 - p22
        psi += 0.5 * (phi[k] * phi[k] + phi[k + 1] * phi[k + 1])
    return psi


@njit(cache=True, inline="always")
def _full_impulses_and_residual(q: FloatArray, mu: FloatArray, t: FloatArray, v: FloatArray,
                                loads: FloatArray, r: FloatArray, u: FloatArray) -> float:
    """The full impulses r = (max(0, load_i), t_i)_i, their velocity u and shared residual."""
    for i in range(mu.shape[0]):
        normal = max(loads[i], 0.0)
        r[3 * i] = normal
        r[3 * i + 1] = t[2 * i]
        r[3 * i + 2] = t[2 * i + 1]
        u[3 * i] = normal - loads[i]
        u[3 * i + 1] = v[2 * i]
        u[3 * i + 2] = v[2 * i + 1]
    return residual_from_velocity(q, mu, r, u)


@njit(cache=True, **REFERENCE_COUNTED)
def newton_load_transfer(
    G: FloatArray, b: FloatArray, n0: FloatArray, K: FloatArray, mu: FloatArray, r: FloatArray,
    max_iter: int, tol: float, armijo: float, max_backtracks: int, workspace: FloatArray,
) -> tuple[int, int, float]:
    """Solve the FC3D problem with the load law above by Newton on the friction impulses.

    Args:
        G: (2 nc, 2 nc) tangential Delassus block. b: (2 nc,) tangential free velocity.
        n0: (nc,) loads at zero friction. K: (nc, 2 nc) load transfer per friction impulse.
        mu: (nc,) friction coefficients >= 0.
        r: (3 nc,) impulses per contact (normal, tangent 1, tangent 2). In: the friction
            impulses are the starting point (the normal ones are not read). Out: the last
            iterate, normal impulses max(0, n0 + K t) (also when not converged).
        max_iter: Newton step limit. tol: shared-residual tolerance (``problem.py``).
        armijo: sufficient-decrease constant in (0, 1/2). max_backtracks: step halvings.
        workspace: flat scratch of ``load_transfer_workspace_size(nc)`` entries.

    Returns:
        (code, steps, residual): code 0 converged (shared residual <= tol), 1 step limit,
        3 breakdown (an inconsistent Newton system, a non-finite step or a failed line
        search); the shared residual of the returned r.
    """
    nc = mu.shape[0]
    m = 2 * nc
    (t, v, phi, d, swaps, trial_t, trial_v, trial_phi, rho, loads, trial_loads, q, u,
     J) = _workspace_in(workspace, nc)
    for i in range(nc):
        k = 2 * i
        acc = G[k, k] * G[k, k] + G[k, k + 1] * G[k, k + 1]
        acc += G[k + 1, k] * G[k + 1, k] + G[k + 1, k + 1] * G[k + 1, k + 1]
        rho[i] = 1.0 / np.sqrt(acc) if acc > 0.0 else 1.0
        q[3 * i] = -n0[i]
        q[3 * i + 1] = b[k]
        q[3 * i + 2] = b[k + 1]
        t[k] = r[3 * i + 1]
        t[k + 1] = r[3 * i + 2]
    _state(G, b, n0, K, t, v, loads)
    code = CODE_MAX_ITER
    steps = max_iter
    for step in range(max_iter + 1):
        residual = _full_impulses_and_residual(q, mu, t, v, loads, r, u)
        if residual <= tol:
            code = CODE_CONVERGED
            steps = step
            break
        if step == max_iter:
            break
        psi = _tangential_ac(mu, rho, G, K, t, v, loads, phi, J, True)
        for i in range(m):
            d[i] = -phi[i]
        solved = solve_consistent_inplace(J, d, swaps, _PIVOT_TOL, _CONSISTENCY_TOL)
        for i in range(m):
            if not np.isfinite(d[i]):
                solved = False
        accepted = False
        if solved:  # the Newton direction's slope is -|phi|^2 = -2 psi
            step_length = 1.0
            for _ in range(max_backtracks):
                for i in range(m):
                    trial_t[i] = t[i] + step_length * d[i]
                _state(G, b, n0, K, trial_t, trial_v, trial_loads)
                trial_psi = _tangential_ac(mu, rho, G, K, trial_t, trial_v, trial_loads,
                                           trial_phi, J, False)
                if trial_psi <= psi * (1.0 - 2.0 * armijo * step_length):
                    accepted = True
                    break
                step_length *= 0.5
        if not accepted:
            code = CODE_BREAKDOWN
            steps = step
            break
        for i in range(m):
            t[i] = trial_t[i]
            v[i] = trial_v[i]
        for i in range(nc):
            loads[i] = trial_loads[i]
    return code, steps, residual


__all__ = ["load_transfer_workspace_size", "newton_load_transfer"]
