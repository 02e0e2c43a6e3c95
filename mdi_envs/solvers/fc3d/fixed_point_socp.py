"""De Saxce's fixed point over convex second-order-cone QPs (``fixed_point_socp``).

For a fixed shift s (nc,) of the normal velocities and a fixed v (3 nc,), the cone
complementarity problem

    K_mu contains r  _|_  W_s r + q + v + s e_N  in K_mu*,      W_s = (W + W^T) / 2,

is the KKT system of the convex QP ``min 1/2 r^T W_s r + (q + v + s e_N)^T r, r in K_mu``
(``cone_qp.ConeQP``, solved by the Clarabel interior-point method; W_s positive semidefinite,
possibly singular). With s = mu ||u_T|| and v = W_a r (W_a = (W - W^T) / 2, u = W r + q), its
solutions are exactly those of FC3D (De Saxce's modified velocity ``u_hat = u + mu ||u_T|| e_N``).
The method iterates the map (s, v) -> (mu ||u_T(r)||, W_a r) of the QP minimiser r, relaxed by
``relaxation``: the Panagiotopoulos / De Saxce fixed point on the convex relaxation (Acary,
Cadoux, Lemarechal & Malick 2011), with the non-symmetric part of W carried as a data term.

Where the null spaces of W_s and W coincide (W = H M^-1 H^T, as in every Siconos peer problem),
W r and W_a r are the same for every QP minimiser, so the map is well defined although r is not
unique where W is rank deficient. Convergence of the fixed point is not guaranteed (it is known
for small mu); each step costs one interior-point solve. The best iterate (by the shared
residual) is kept, and the iteration stops after ``max_iter`` steps or once ``stall_iter``
steps in a row failed to bring the best residual below 0.9 times its value at the last such
improvement. The first iterate whose residual is at most ``polish_below`` (but above ``tol``)
is polished (below); if that does not converge the fixed point goes on. When it stops without
such a polish, the best iterate gets it. The best iterate of all is returned. A starting point
r0 that already meets ``tol`` is returned as is.

The polish is up to ``polish_cycles`` rounds of: at most ``polish_iter`` steps of the sparse
shifted Newton method of ``hybrid`` without NSGS sweeps (locally quadratic where the fixed
point is only linear), then, if that did not converge, ``unload_duplicates``
(``duplicate_contacts.py``): of each pair of loaded contacts with the same normal row of W,
the one with the higher normal velocity hands its impulse to the other. That regime change is
what the fixed point and Newton cannot do themselves on ``RockPile_tob1`` (74 such pairs).
CONVERGED: shared residual <= tol; MAX_ITER: budget spent; BREAKDOWN: a QP had no minimiser.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.solvers._registry import (
    SolverOptions,
    require_integer_option,
    require_real_option,
)
from mdi_envs.solvers.fc3d.cone_qp import ConeQP
from mdi_envs.solvers.fc3d.duplicate_contacts import duplicate_normal_pairs, unload_duplicates
from mdi_envs.solvers.fc3d.hybrid import HybridOptions, solve_hybrid
from mdi_envs.solvers.fc3d.problem import FrictionContact3D, natural_map
from mdi_envs.solvers.fc3d.registry import FC3D_METHODS
from mdi_envs.solvers.status import SolverStatus


@dataclass(frozen=True)
class FixedPointSOCPOptions(SolverOptions):
    """Options of the fixed point over cone QPs.

    Attributes:
        max_iter: fixed-point steps (one interior-point solve each).
        relaxation: omega in (0, 1]: (s, v) <- (s, v) + omega (map(s, v) - (s, v)).
        socp_tol: Clarabel's gap and feasibility tolerances for each QP, > 0.
        socp_max_iter: Clarabel's iteration limit per QP.
        stall_iter: steps without a 10 % improvement of the best residual that end the
            fixed point.
        polish_below: shared residual at which the polish starts, once (0: never polish).
        polish_iter: Newton step limit of each polishing round.
        polish_cycles: polishing rounds (Newton, then unloading duplicate contacts).
    """

    max_iter: int = 300
    relaxation: float = 0.5
    socp_tol: float = 1e-10
    socp_max_iter: int = 200
    stall_iter: int = 50
    polish_below: float = 1e-6
    polish_iter: int = 1000
    polish_cycles: int = 5

    def __post_init__(self) -> None:
        super().__post_init__()
        require_real_option(self, "relaxation", low=0.0, high=1.0, low_inclusive=False)
        require_real_option(self, "socp_tol", low=0.0, low_inclusive=False)
        require_integer_option(self, "socp_max_iter", minimum=1)
        require_integer_option(self, "stall_iter", minimum=1)
        require_real_option(self, "polish_below", low=0.0)
        require_integer_option(self, "polish_iter", minimum=1)
        require_integer_option(self, "polish_cycles", minimum=1)


def _polish(
    problem: FrictionContact3D, r: FloatArray, options: FixedPointSOCPOptions
) -> tuple[FloatArray, float, int]:
    """Newton rounds alternating with ``unload_duplicates`` from r.

    Returns:
        (the best iterate, its shared residual, the Newton steps taken).
    """
    newton = HybridOptions(tol=options.tol, max_iter=options.polish_iter, warm_sweeps=0)
    pairs = duplicate_normal_pairs(problem.W)
    best_r, best, steps = r, problem.residual(r), 0
    for _ in range(int(options.polish_cycles)):
        r, status, taken = solve_hybrid(problem, r, newton)
        steps += taken
        residual = problem.residual(r)
        if residual < best:
            best_r, best = r, residual
        if status is SolverStatus.CONVERGED:
            break
        r, moved = unload_duplicates(problem.W, problem.q, r, pairs)
        if moved == 0:
            break
    return best_r, best, steps


@FC3D_METHODS.register(
    "fixed_point_socp", FixedPointSOCPOptions,
    "De Saxce fixed point on convex cone QPs (Clarabel), Newton polish; needs clarabel",
)
def solve_fixed_point_socp(
    problem: FrictionContact3D, r0: FloatArray | None, options: FixedPointSOCPOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem``; returns (r, status, fixed-point steps + polish steps).

    The fixed point starts from s = mu ||u_T(r0)||, v = W_a r0 (r0 = 0 by default).

    Raises:
        ImportError: clarabel is not installed (the message names the ``conic`` extra).
    """
    W, q, mu = problem.W, problem.q, problem.mu
    n = q.shape[0]
    W_a = 0.5 * (W - W.T)
    qp = ConeQP(0.5 * (W + W.T), mu, options.socp_tol, options.socp_max_iter)
    tol, omega = float(options.tol), float(options.relaxation)
    r = np.zeros(n) if r0 is None else r0.copy()
    u = np.empty(n)
    if natural_map(W, q, mu, r, u) <= tol:
        return r, SolverStatus.CONVERGED, 0
    s, v = mu * np.hypot(u[1::3], u[2::3]), W_a @ r
    best_r, best, mark, last_progress = r, np.inf, np.inf, 0
    is_polished, polish_steps, steps = False, 0, 0
    for steps in range(1, int(options.max_iter) + 1):
        c = q + v
        c[0::3] += s
        r_qp = qp.solve(c)
        if r_qp is None:
            return best_r, SolverStatus.BREAKDOWN, steps + polish_steps
        residual = natural_map(W, q, mu, r_qp, u)
        if residual <= tol:
            return r_qp, SolverStatus.CONVERGED, steps + polish_steps
        if residual < best:
            best_r, best = r_qp, residual
        if not is_polished and residual <= options.polish_below:
            is_polished = True
            r_polish, polished, polish_steps = _polish(problem, r_qp, options)
            if polished <= tol:
                return r_polish, SolverStatus.CONVERGED, steps + polish_steps
            if polished < best:
                best_r, best = r_polish, polished
        if residual < 0.9 * mark:
            mark, last_progress = residual, steps
        elif steps - last_progress >= options.stall_iter:
            break
        s += omega * (mu * np.hypot(u[1::3], u[2::3]) - s)
        v += omega * (W_a @ r_qp - v)
    if not is_polished and options.polish_below > 0.0:
        r_polish, polished, polish_steps = _polish(problem, best_r, options)
        if polished <= tol:
            return r_polish, SolverStatus.CONVERGED, steps + polish_steps
        if polished < best:
            best_r = r_polish
    return best_r, SolverStatus.MAX_ITER, steps + polish_steps

__all__ = ["FixedPointSOCPOptions", "solve_fixed_point_socp"]
