"""Non-smooth (projected block) Gauss-Seidel over the contacts, with proximal damping.

One sweep visits the contacts i = 1..nc in order. With the other contacts' impulses frozen at
their latest values, contact i sees the one-contact problem

    u_i = W_ii r_i + q_loc,     q_loc = q_i + sum_{j != i} W_ij r_j.

The sweep solves its proximally damped version, FC3D(W_ii + s I, q_loc - s r_i_old) with
s = damping * ||W_ii||_F, "exactly": r_i = 0 when its normal free velocity is >= 0 (take-off),
otherwise by the Alart-Curnier Newton method of ``newton_ac`` applied to the 3x3 problem,
warm-started at the current r_i. If that local solve does not reach ``local_tol``, the better
(by the local residual) of its iterate and of ``local_max_iter`` projected fixed-point steps
``r_i <- P_K(r_i - rho_i u_hat_i)`` is kept. The new r_i is relaxed,
``r_i <- omega r_i_new + (1 - omega) r_i_old``. After each sweep the shared residual of the whole
problem is checked against ``tol``.

At a fixed point r_i_new = r_i_old, so the damping term vanishes and the fixed points are exactly
the solutions. The small default damping (0.01) costs a few sweeps on easy problems but stops
the plain iteration from stalling or drifting away on problems whose W is non-symmetric and
singular (the OneObject files of the Siconos collection). Cheap per sweep (O(n^2) for dense W)
and warm-startable, the usual method for large contact problems; convergence is linear at
best and not guaranteed, so the sweep limit is reported as MAX_ITER.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mdi_envs._types import FloatArray
from mdi_envs.solvers._registry import (
    SolverOptions,
    require_integer_option,
    require_real_option,
)
from mdi_envs.solvers.fc3d.newton_ac import contact_weights, make_workspace, newton_ac_core
from mdi_envs.solvers.fc3d.problem import (
    FrictionContact3D,
    cone_projection,
    natural_map,
)
from mdi_envs.solvers.fc3d.registry import FC3D_METHODS
from mdi_envs.solvers.status import CODE_CONVERGED, CODE_MAX_ITER, SolverStatus

_LOCAL_PROX_SIGMA = 1.0
"""``prox_sigma`` of the one-contact Newton solves (see ``newton_ac``)."""


@dataclass(frozen=True)
class NSGSOptions(SolverOptions):
    """Options of the non-smooth Gauss-Seidel method.

    Attributes:
        max_iter: sweep limit.
        tol: tolerance on the shared residual, checked after every sweep.
        local_max_iter: Newton step limit of each one-contact solve (and number of projected
            fixed-point steps of the fallback).
        local_tol: tolerance of each one-contact solve, on that problem's shared residual.
        armijo, max_backtracks: line-search parameters of the one-contact Newton solves.
        rho_scale: factor on the per-contact weight rho_i = 1 / ||W_ii||_F, > 0.
        relaxation: omega in (0, 2); 1 is plain Gauss-Seidel.
        damping: proximal damping of the one-contact problems, relative to ||W_ii||_F, >= 0.
    """

    max_iter: int = 10_000
    tol: float = 1e-10
    local_max_iter: int = 20
    local_tol: float = 1e-14
    armijo: float = 1e-4
    max_backtracks: int = 30
    rho_scale: float = 1.0
    relaxation: float = 1.0
    damping: float = 0.01

    def __post_init__(self) -> None:
        super().__post_init__()
        require_integer_option(self, "local_max_iter", minimum=1)
        require_real_option(self, "local_tol", low=0.0, low_inclusive=False)
        require_real_option(
            self, "armijo", low=0.0, high=0.5, low_inclusive=False, high_inclusive=False
        )
        require_integer_option(self, "max_backtracks", minimum=1)
        require_real_option(self, "rho_scale", low=0.0, low_inclusive=False)
        require_real_option(
            self, "relaxation", low=0.0, high=2.0, low_inclusive=False, high_inclusive=False
        )
        require_real_option(self, "damping", low=0.0)


@njit(cache=True)
def _projection_steps(
    W: FloatArray,
    q: FloatArray,
    mu: FloatArray,
    rho: float,
    r: FloatArray,
    num_steps: int,
    u: FloatArray,
) -> float:
    """``num_steps`` projected steps r <- P_K(r - rho u_hat) on a one-contact problem.

    Args:
        W: (3, 3). q: (3,). mu: (1,). rho: step weight.
        r: (3,) start, overwritten by the result (modified in place). u: (3,) scratch.

    Returns:
        The shared residual of the one-contact problem at the returned r.
    """
    for _ in range(num_steps):
        for a in range(3):
            u[a] = q[a] + W[a, 0] * r[0] + W[a, 1] * r[1] + W[a, 2] * r[2]
        u_t = np.sqrt(u[1] * u[1] + u[2] * u[2])
        r[0], r[1], r[2] = cone_projection(
            mu[0],
            r[0] - rho * (u[0] + mu[0] * u_t),
            r[1] - rho * u[1],
            r[2] - rho * u[2],
        )
    return natural_map(W, q, mu, r, u)


@njit(cache=True)
def nsgs_kernel(
    W: FloatArray,
    q: FloatArray,
    mu: FloatArray,
    r: FloatArray,
    max_iter: int,
    tol: float,
    local_max_iter: int,
    local_tol: float,
    armijo: float,
    max_backtracks: int,
    rho_scale: float,
    relaxation: float,
    damping: float,
) -> tuple[int, int, float]:
    """Non-smooth Gauss-Seidel sweeps on FC3D(W, q, mu).

    Args:
        W: (n, n), n = 3 nc. q: (n,). mu: (nc,).
        r: (n,) starting point, overwritten by the iterate (modified in place).
        max_iter, tol, local_max_iter, local_tol: see ``NSGSOptions``.
        armijo, max_backtracks, rho_scale, relaxation, damping: see ``NSGSOptions``.

    Returns:
        (code, sweeps, residual): code 0 converged, 1 sweep limit; the shared residual of r.
    """
    n = q.shape[0]
    nc = n // 3
    rho = contact_weights(W, rho_scale)
    u = np.empty(n)
    q_loc = np.empty(3)
    mu_loc = np.empty(1)
    rho_loc = np.empty(1)
    r_newton = np.empty(3)
    r_proj = np.empty(3)
    u_loc = np.empty(3)
    W_loc = np.empty((3, 3))
    workspace = make_workspace(3)
    residual = natural_map(W, q, mu, r, u)
    if residual <= tol:
        return CODE_CONVERGED, 0, residual
    for sweep in range(1, max_iter + 1):
        for i in range(nc):
            k = 3 * i
            shift = damping * rho_scale / rho[i]  # damping * ||W_ii||_F
            for a in range(3):
                acc = q[k + a]
                row = k + a
                for j in range(k):
                    acc += W[row, j] * r[j]
                for j in range(k + 3, n):
                    acc += W[row, j] * r[j]
                q_loc[a] = acc - shift * r[k + a]
                for b in range(3):
                    W_loc[a, b] = W[row, k + b]
                W_loc[a, a] += shift
            if q_loc[0] >= 0.0:  # take-off is an exact solution of the local problem
                for a in range(3):
                    r[k + a] *= 1.0 - relaxation
                continue
            mu_loc[0] = mu[i]
            rho_loc[0] = rho[i]
            for a in range(3):
                r_newton[a] = r[k + a]
                r_proj[a] = r[k + a]
            code, _, local_residual = newton_ac_core(
                W_loc, q_loc, mu_loc, rho_loc, r_newton, local_max_iter, local_tol, armijo,
                max_backtracks, _LOCAL_PROX_SIGMA, workspace,
            )
            if code != CODE_CONVERGED:
                proj_residual = _projection_steps(
                    W_loc, q_loc, mu_loc, rho[i], r_proj, local_max_iter, u_loc
                )
                if proj_residual < local_residual:
                    for a in range(3):
                        r_newton[a] = r_proj[a]
            for a in range(3):
                r[k + a] = relaxation * r_newton[a] + (1.0 - relaxation) * r[k + a]
        residual = natural_map(W, q, mu, r, u)
        if residual <= tol:
            return CODE_CONVERGED, sweep, residual
    return CODE_MAX_ITER, max_iter, residual


@FC3D_METHODS.register("nsgs", NSGSOptions, "non-smooth block Gauss-Seidel over the contacts")
def solve_nsgs(
    problem: FrictionContact3D, r0: FloatArray | None, options: NSGSOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` by NSGS from ``r0`` (default r = 0); returns (r, status, sweeps)."""
    r = np.zeros(problem.q.shape[0]) if r0 is None else r0.copy()
    code, sweeps, _ = nsgs_kernel(
        problem.W, problem.q, problem.mu, r, int(options.max_iter), float(options.tol),
        int(options.local_max_iter), float(options.local_tol), float(options.armijo),
        int(options.max_backtracks), float(options.rho_scale), float(options.relaxation),
        float(options.damping),
    )
    return r, SolverStatus(code), sweeps


__all__ = ["NSGSOptions", "nsgs_kernel", "solve_nsgs"]
