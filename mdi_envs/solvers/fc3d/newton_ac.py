"""Global semismooth Newton on the Alart-Curnier function: line search, proximal safeguard.

Per contact i, with u = W r + q and a weight rho_i > 0, the Alart-Curnier function is

    a_N = r_N - rho u_N,                 a_T = r_T - rho u_T,
    phi_N = r_N - max(0, a_N),
    phi_T = r_T - P_D(R)(a_T),           R = mu max(0, a_N),

where P_D(R) projects onto the disk of radius R. phi = 0 exactly at the solutions of the FC3D
problem (Alart & Curnier, 1991). phi is piecewise smooth in (r, u); on each piece

    d phi_i = A_i dr_i + B_i du_i,       du_i = W_i. dr,

so an element of the generalized Jacobian is ``J = blockdiag(A) + blockrows(B) W``
(``alart_curnier_local`` computes phi_i, A_i and B_i of one contact; both this method and the
Gauss-Seidel method call it). Each step solves ``J d = -phi`` by Gaussian elimination with
partial pivoting and backtracks on the merit function ``psi = |phi|^2 / 2`` (Armijo). When J
is singular to working precision the same elimination defers the columns without a pivot
(``solve_consistent_inplace``) and solves the system if it is consistent (duplicated rows, as
two contacts on one line in the same state give: the redundant increments are set to 0, which
keeps the step exact on the current piece). When it is inconsistent or the Newton direction is
not a descent direction, the step is a Levenberg-Marquardt step
``(J^T J + lambda I) d = -J^T phi`` with lambda proportional to |phi|, and failing that the
steepest-descent direction ``-J^T phi``.

Redundant contacts make W (hence J) singular, and plain Newton then crawls (tiny accepted
steps) or stalls. After the first such poor step the method switches to proximal-point
iterations: Newton steps on the regularised problem FC3D(W + sigma D, q - sigma D c),
D = blockdiag(I / rho_i), whose solution is the proximal point of the centre c. The
regularised Jacobian ``J + sigma blockdiag(B_i / rho_i)`` is regular where J is not; its
velocity equals W r + q at r = c, so every fixed point is a solution of the original problem.
The centre moves to the iterate once the sub-problem's AC norm has dropped to a fraction of
the original AC norm at the centre; sigma shrinks tenfold when that took at most two steps and
improved the original AC norm, and grows tenfold on every poor step. A sigma beyond 1e8 is
reported as BREAKDOWN (as is a failed line search when ``prox_sigma = 0`` disables the
regularisation), the step limit as MAX_ITER. Convergence is always judged on the shared
residual of the original problem.

rho_i = 1 / ||W_ii||_F (the Frobenius norm of contact i's diagonal 3x3 block) makes the
two arguments of each projection commensurate; ``rho_scale`` multiplies it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mdi_envs._borrowing import REFERENCE_COUNTED
from mdi_envs._types import FloatArray
from mdi_envs._views import array_view
from mdi_envs.solvers._linalg import lu_solve_inplace, solve_consistent_inplace
from mdi_envs.solvers._registry import (
    SolverOptions,
    require_integer_option,
    require_real_option,
)
from mdi_envs.solvers.fc3d.problem import (
    FrictionContact3D,
    compute_velocity,
    residual_from_velocity,
)
from mdi_envs.solvers.fc3d.registry import FC3D_METHODS
from mdi_envs.solvers.status import CODE_BREAKDOWN, CODE_CONVERGED, CODE_MAX_ITER, SolverStatus

_PIVOT_TOL = 1e-14
"""Relative pivot tolerance below which the Newton matrix counts as singular."""
_CONSISTENCY_TOL = 1e-10
"""A singular Newton system counts as consistent when its eliminated residual is below this
fraction of |phi| (then the step solves it with the redundant unknowns' increments at 0)."""
_SLOW_STEP = 1.0 / 32.0
"""A step length below this counts as a poor step: regularise (more)."""
_PROX_ETA = 0.5
"""A proximal sub-problem counts as solved at this fraction of the AC norm at its centre."""
_PROX_DECREASE = 0.1
_MAX_SUB_STEPS = 10
"""Newton steps on one proximal sub-problem before sigma is increased."""
_PROX_INCREASE = 10.0
_PROX_SIGMA_MAX = 1e8
"""Largest proximal weight (relative to ||W_ii||) before the method reports a breakdown."""

@dataclass(frozen=True)
class NewtonACOptions(SolverOptions):
    """Options of the Alart-Curnier Newton method.

    Attributes:
        max_iter: Newton step limit.
        armijo: sufficient-decrease constant sigma of the line search, in (0, 1/2).
        max_backtracks: step halvings before the line search is declared failed (BREAKDOWN).
        rho_scale: factor on the per-contact weight rho_i = 1 / ||W_ii||_F, > 0.
        prox_sigma: initial proximal weight sigma (relative to ||W_ii||) once plain Newton
            steps stall; 0 disables the proximal regularisation.
    """

    max_iter: int = 100
    armijo: float = 1e-4
    max_backtracks: int = 40
    rho_scale: float = 1.0
    prox_sigma: float = 1.0

    def __post_init__(self) -> None:
        super().__post_init__()
        require_real_option(
            self, "armijo", low=0.0, high=0.5, low_inclusive=False, high_inclusive=False
        )
        require_integer_option(self, "max_backtracks", minimum=1)
        require_real_option(self, "rho_scale", low=0.0, low_inclusive=False)
        require_real_option(self, "prox_sigma", low=0.0)


@njit(cache=True)
def contact_weights(W: FloatArray, rho_scale: float) -> FloatArray:
    """rho_i = rho_scale / ||W_ii||_F per contact (W (3 nc, 3 nc)); 1 / max|W| for a zero block.

    Returns:
        (nc,) array of positive weights.
    """
    nc = W.shape[0] // 3
    rho = np.empty(nc)
    w_max = 0.0
    for v in W.reshape(-1):
        w_max = max(w_max, abs(v))
    fallback = 1.0 / w_max if w_max > 0.0 else 1.0
    for i in range(nc):
        k = 3 * i
        acc = 0.0
        for a in range(3):
            for b in range(3):
                acc += W[k + a, k + b] * W[k + a, k + b]
        rho[i] = rho_scale * (1.0 / np.sqrt(acc) if acc > 0.0 else fallback)
    return rho


@njit(cache=True, inline="always")
def slide_direction(a1: float, a2: float, norm: float, radius: float
                    ) -> tuple[float, float, float]:
    """(n1, n2, s): n = a / |a| and s = radius / |a| for a = (a1, a2), norm = |a| (0 for a = 0).

    Outside the disk of that radius its projection is ``radius n``, with derivative
    ``s (I - n n^T)`` in a.
    """
    if norm > 0.0:
        return a1 / norm, a2 / norm, radius / norm
    return 0.0, 0.0, 0.0


@njit(cache=True, inline="always")
def _alart_curnier_at(
    rho: float,
    mu: float,
    r: FloatArray,
    u: FloatArray,
    phi: FloatArray,
    A: FloatArray,
    B: FloatArray,
    k: int,
    i: int,
    with_jacobian: bool,
) -> None:
    """``alart_curnier_local`` of contact i at entries k..k+2 of r, u, phi (blocks A[i], B[i]).

    Indexes in place of slicing: array views in a hot loop cost reference counting.
    """
    a_n = r[k] - rho * u[k]
    a_t1 = r[k + 1] - rho * u[k + 1]
    a_t2 = r[k + 2] - rho * u[k + 2]
    if with_jacobian:
        for a in range(3):
            for b in range(3):
                A[i, a, b] = 0.0
                B[i, a, b] = 0.0
    if a_n > 0.0:  # normal impulse active: phi_N = rho u_N
        phi[k] = rho * u[k]
        radius = mu * a_n
        if with_jacobian:
            B[i, 0, 0] = rho
    else:  # separation: phi_N = r_N
        phi[k] = r[k]
        radius = 0.0
        if with_jacobian:
            A[i, 0, 0] = 1.0
    norm_t = np.sqrt(a_t1 * a_t1 + a_t2 * a_t2)
    if radius > 0.0 and norm_t <= radius:  # stick: phi_T = rho u_T
        phi[k + 1] = rho * u[k + 1]
        phi[k + 2] = rho * u[k + 2]
        if with_jacobian:
            B[i, 1, 1] = rho
            B[i, 2, 2] = rho
        return
    # slide (or no normal impulse): phi_T = r_T - R n, n = a_T / |a_T|
    n1, n2, s = slide_direction(a_t1, a_t2, norm_t, radius)
    phi[k + 1] = r[k + 1] - radius * n1
    phi[k + 2] = r[k + 2] - radius * n2
    if not with_jacobian:
        return
    # d(R n) = n mu H(a_N) da_N + s (I - n n^T) da_T, with da = dr - rho du
    h1 = mu * n1 if a_n > 0.0 else 0.0
    h2 = mu * n2 if a_n > 0.0 else 0.0
    p11 = s * (1.0 - n1 * n1)
    p12 = -s * n1 * n2
    p22 = s * (1.0 - n2 * n2)
    A[i, 1, 0] = -h1
    A[i, 2, 0] = -h2
    A[i, 1, 1] = 1.0 - p11
    A[i, 1, 2] = -p12
    A[i, 2, 1] = -p12
    A[i, 2, 2] = 1.0 - p22
    B[i, 1, 0] = rho * h1
    B[i, 2, 0] = rho * h2
    B[i, 1, 1] = rho * p11
    B[i, 1, 2] = rho * p12
    B[i, 2, 1] = rho * p12
    B[i, 2, 2] = rho * p22


@njit(cache=True)
def alart_curnier_local(
    rho: float,
    mu: float,
    r: FloatArray,
    u: FloatArray,
    phi: FloatArray,
    A: FloatArray,
    B: FloatArray,
    with_jacobian: bool,
) -> None:
    """The Alart-Curnier function of one contact and the blocks of a generalized Jacobian.

    Args:
        rho: weight > 0. mu: friction coefficient >= 0.
        r: (3,) impulse (normal, tangent 1, tangent 2). u: (3,) velocity W r + q of the contact.
        phi: (3,) output, the function value (modified in place).
        A, B: (3, 3) outputs, ``d phi = A dr + B du`` on the current piece (modified in place
            when ``with_jacobian``).
        with_jacobian: whether to fill A and B.
    """
    _alart_curnier_at(rho, mu, r, u, phi, A.reshape((1, 3, 3)), B.reshape((1, 3, 3)), 0, 0,
                      with_jacobian)


@njit(cache=True, inline="always")
def alart_curnier(
    mu: FloatArray,
    rho: FloatArray,
    r: FloatArray,
    u: FloatArray,
    phi: FloatArray,
    A: FloatArray,
    B: FloatArray,
    with_jacobian: bool,
) -> float:
    """Stack ``alart_curnier_local`` over all contacts; return the merit ``|phi|^2 / 2``.

    Args:
        mu, rho: (nc,). r, u: (3 nc,). phi: (3 nc,) output.
        A, B: (nc, 3, 3) outputs, filled when ``with_jacobian``.
    """
    psi = 0.0
    for i in range(mu.shape[0]):
        k = 3 * i
        _alart_curnier_at(rho[i], mu[i], r, u, phi, A, B, k, i, with_jacobian)
        psi += 0.5 * (phi[k] * phi[k] + phi[k + 1] * phi[k + 1] + phi[k + 2] * phi[k + 2])
    return psi


_NUM_VECTORS = 10
"""Length-n scratch vectors of ``newton_ac_core`` (then the A, B blocks and two n x n)."""


@njit(cache=True)
def workspace_size(n: int) -> int:
    """Length of the flat float64 scratch buffer of ``newton_ac_core`` for a problem of size n."""
    return _NUM_VECTORS * n + 2 * 9 * (n // 3) + 2 * n * n


@njit(cache=True, inline="always")
def _workspace_in(buffer: FloatArray, n: int) -> tuple[FloatArray, ...]:
    """The scratch arrays of ``newton_ac_core`` as views into ``buffer`` (``workspace_size(n)``).

    Carved on each call (a few integer operations each), so that the solver takes one flat
    buffer: a caller can keep it inside its own, and the call passes one array, not fourteen.
    """
    nc = n // 3
    blocks = _NUM_VECTORS * n
    matrices = blocks + 18 * nc
    return (
        buffer[0:n],  # u = W r + q
        buffer[n:2 * n],  # velocity of the proximal sub-problem
        buffer[2 * n:3 * n],  # proximal centre
        buffer[3 * n:4 * n],  # phi
        array_view(buffer, blocks, (nc, 3, 3)),  # A
        array_view(buffer, blocks + 9 * nc, (nc, 3, 3)),  # B
        array_view(buffer, matrices, (n, n)),  # J
        array_view(buffer, matrices + n * n, (n, n)),  # factored J (or LM)
        buffer[4 * n:5 * n],  # d
        buffer[5 * n:6 * n],  # grad = J^T phi
        buffer[6 * n:7 * n],  # W trial r + q (and the search direction's scratch)
        buffer[7 * n:8 * n],  # trial r
        buffer[8 * n:9 * n],  # trial u
        buffer[9 * n:10 * n],  # trial phi
    )


@njit(cache=True)
def make_workspace(n: int) -> FloatArray:
    """The flat scratch buffer of ``newton_ac_core`` for a problem of size n = 3 nc."""
    return np.empty(workspace_size(n))


@njit(cache=True, inline="always")
def _assemble_jacobian(
    W: FloatArray, A: FloatArray, B: FloatArray, sigma: float, rho: FloatArray, J: FloatArray
) -> None:
    """J = blockdiag(A) + blockrows(B) (W + sigma D), D = blockdiag(I / rho_i).

    Args:
        W, J: (n, n); J is the output. A, B: (nc, 3, 3). sigma: >= 0. rho: (nc,).
    """
    n = W.shape[0]
    for i in range(n // 3):
        k = 3 * i
        shift = sigma / rho[i]
        for a in range(3):
            row = k + a
            b0 = B[i, a, 0]
            b1 = B[i, a, 1]
            b2 = B[i, a, 2]
            for j in range(n):
                J[row, j] = b0 * W[k, j] + b1 * W[k + 1, j] + b2 * W[k + 2, j]
            for c in range(3):
                J[row, k + c] += A[i, a, c] + shift * B[i, a, c]


@njit(cache=True)
def _levenberg_marquardt_step(
    J: FloatArray, grad: FloatArray, phi_norm: float, H: FloatArray, d: FloatArray
) -> bool:
    """Levenberg-Marquardt step ``d = -(J^T J + lambda I)^-1 grad``; False if singular.

    lambda = min(phi_norm, 1) * mean(diag J^T J); H (n, n) is scratch, d (n,) the output.
    """
    n = J.shape[0]
    for a in range(n):
        for b in range(a, n):
            acc = 0.0
            for k in range(n):
                acc += J[k, a] * J[k, b]
            H[a, b] = acc
            H[b, a] = acc
    trace = 0.0
    for a in range(n):
        trace += H[a, a]
    lam = (min(phi_norm, 1.0) + 1e-12) * max(trace / n, 1e-300)
    for a in range(n):
        H[a, a] += lam
        d[a] = -grad[a]
    return lu_solve_inplace(H, d, _PIVOT_TOL)


@njit(cache=True, inline="always")
def _search_direction(
    J: FloatArray, phi: FloatArray, psi: float, H: FloatArray, d: FloatArray, grad: FloatArray,
    work: FloatArray,
) -> tuple[float, bool]:
    """Fill d with a descent direction of psi = |phi|^2 / 2.

    Newton (``J d = -phi``) if J is regular, or singular but consistent, and that is a descent
    direction, else Levenberg-Marquardt, else steepest descent. work: (n,) scratch.

    Returns:
        (slope, is_newton): the slope grad . d (0 when grad = J^T phi = 0) and whether d is the
        Newton direction.
    """
    n = J.shape[0]
    g_norm2 = 0.0
    for j in range(n):
        acc = 0.0
        for i in range(n):
            acc += J[i, j] * phi[i]
        grad[j] = acc
        g_norm2 += acc * acc
    if g_norm2 == 0.0:
        return 0.0, False
    for i in range(n):
        for j in range(n):
            H[i, j] = J[i, j]
        d[i] = -phi[i]
    # regular J: LU with partial pivoting; singular (duplicated rows: redundant contacts)
    # but consistent: still a Newton step, with the redundant increments at 0
    solved = solve_consistent_inplace(H, d, work, _PIVOT_TOL, _CONSISTENCY_TOL)
    if solved:
        slope = 0.0
        d_norm2 = 0.0
        for i in range(n):
            slope += grad[i] * d[i]
            d_norm2 += d[i] * d[i]
        if np.isfinite(slope) and slope < -1e-12 * np.sqrt(d_norm2 * g_norm2):
            return slope, True
    if _levenberg_marquardt_step(J, grad, np.sqrt(2.0 * psi), H, d):
        slope = 0.0
        for i in range(n):
            slope += grad[i] * d[i]
        if np.isfinite(slope) and slope < 0.0:
            return slope, False
    for i in range(n):
        d[i] = -grad[i]
    return -g_norm2, False


@njit(cache=True, inline="always")
def _proximal_velocity(
    v: FloatArray, r: FloatArray, center: FloatArray, sigma: float, rho: FloatArray,
    out: FloatArray,
) -> None:
    """The proximal sub-problem's velocity at r: out = v + sigma D (r - center).

    D = blockdiag(I / rho_i); v = W r + q; out = v when sigma = 0. All (n,) but rho (nc,).
    """
    for i in range(v.shape[0]):
        out[i] = v[i] + sigma * (r[i] - center[i]) / rho[i // 3] if sigma > 0.0 else v[i]


@njit(cache=True, **REFERENCE_COUNTED)
def newton_ac_core(
    W: FloatArray,
    q: FloatArray,
    mu: FloatArray,
    rho: FloatArray,
    r: FloatArray,
    max_iter: int,
    tol: float,
    armijo: float,
    max_backtracks: int,
    prox_sigma: float,
    workspace: FloatArray,
) -> tuple[int, int, float]:
    """Semismooth Newton iterations on the Alart-Curnier function of FC3D(W, q, mu).

    Plain Newton steps until a poor one (line search failed, not a Newton direction, or step
    length below ``_SLOW_STEP``); from then on proximal-point steps as described in the module
    docstring, where a step is poor if its line search failed, it is not a Newton direction,
    or the sub-problem is still unsolved after ``_MAX_SUB_STEPS`` steps.

    Args:
        W: (n, n), n = 3 nc. q: (n,). mu, rho: (nc,).
        r: (n,) starting point, overwritten by the iterate (modified in place).
        max_iter, tol, armijo, max_backtracks, prox_sigma: see ``NewtonACOptions``.
        workspace: flat scratch of at least ``workspace_size(n)`` entries (``make_workspace``).

    Returns:
        (code, steps, residual): code 0 converged (shared residual <= tol), 1 step limit,
        3 breakdown (no progress even with sigma at ``_PROX_SIGMA_MAX``, or with
        ``prox_sigma = 0`` a failed line search); the shared residual of the returned r.
    """
    n = q.shape[0]
    (u, u_sub, center, phi, A, B, J, H, d, grad, trial_v, trial_r, trial_u,
     trial_phi) = _workspace_in(workspace, n)
    sigma = 0.0
    center_norm = 0.0
    sub_steps = 0
    compute_velocity(W, q, r, u)
    for step in range(max_iter + 1):
        residual = residual_from_velocity(q, mu, r, u)
        if residual <= tol:
            return CODE_CONVERGED, step, residual
        if step == max_iter:
            break
        _proximal_velocity(u, r, center, sigma, rho, u_sub)
        psi = alart_curnier(mu, rho, r, u_sub, phi, A, B, True)
        if sigma > 0.0 and sub_steps > 0 and np.sqrt(2.0 * psi) <= _PROX_ETA * center_norm:
            # the sub-problem is solved well enough: move the centre to r
            psi = alart_curnier(mu, rho, r, u, phi, A, B, True)
            if sub_steps <= 2 and np.sqrt(2.0 * psi) < center_norm:
                sigma *= _PROX_DECREASE
            for i in range(n):
                center[i] = r[i]
                u_sub[i] = u[i]
            center_norm = np.sqrt(2.0 * psi)
            sub_steps = 0
        _assemble_jacobian(W, A, B, sigma, rho, J)
        slope, is_newton = _search_direction(J, phi, psi, H, d, grad, trial_v)
        t = 1.0
        accepted = False
        if slope < 0.0:
            for _ in range(max_backtracks):
                for i in range(n):
                    trial_r[i] = r[i] + t * d[i]
                # the trial's velocity afresh, not u + t W d: no accumulated rounding, and an
                # accepted first trial needs no further product with W
                compute_velocity(W, q, trial_r, trial_v)
                _proximal_velocity(trial_v, trial_r, center, sigma, rho, trial_u)
                trial_psi = alart_curnier(mu, rho, trial_r, trial_u, trial_phi, A, B, False)
                if trial_psi <= psi + armijo * t * slope:
                    accepted = True
                    break
                t *= 0.5
        if accepted:
            for i in range(n):
                r[i] = trial_r[i]
                u[i] = trial_v[i]
            sub_steps += 1
        if sigma == 0.0:
            is_poor = not accepted or not is_newton or t < _SLOW_STEP
        else:
            is_poor = not accepted or not is_newton or sub_steps >= _MAX_SUB_STEPS
        if is_poor:
            if prox_sigma <= 0.0:
                if accepted:
                    continue
                return CODE_BREAKDOWN, step, residual
            sigma = prox_sigma if sigma == 0.0 else sigma * _PROX_INCREASE
            if sigma > _PROX_SIGMA_MAX:
                return CODE_BREAKDOWN, step + 1, residual_from_velocity(q, mu, r, u)
            for i in range(n):
                center[i] = r[i]
            center_norm = np.sqrt(2.0 * alart_curnier(mu, rho, r, u, trial_phi, A, B, False))
            sub_steps = 0
    return CODE_MAX_ITER, max_iter, residual


@njit(cache=True)
def newton_ac_kernel(
    W: FloatArray,
    q: FloatArray,
    mu: FloatArray,
    r: FloatArray,
    max_iter: int,
    tol: float,
    armijo: float,
    max_backtracks: int,
    rho_scale: float,
    prox_sigma: float,
) -> tuple[int, int, float]:
    """``newton_ac_core`` with the default weights and a fresh workspace (same arguments)."""
    rho = contact_weights(W, rho_scale)
    workspace = make_workspace(q.shape[0])
    return newton_ac_core(
        W, q, mu, rho, r, max_iter, tol, armijo, max_backtracks, prox_sigma, workspace
    )


@FC3D_METHODS.register(
    "newton_ac", NewtonACOptions, "semismooth Newton on the Alart-Curnier function"
)
def solve_newton_ac(
    problem: FrictionContact3D, r0: FloatArray | None, options: NewtonACOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` from ``r0`` (default r = 0); returns (r, status, Newton steps)."""
    r = np.zeros(problem.q.shape[0]) if r0 is None else r0.copy()
    code, steps, _ = newton_ac_kernel(
        problem.W, problem.q, problem.mu, r, int(options.max_iter), float(options.tol),
        float(options.armijo), int(options.max_backtracks), float(options.rho_scale),
        float(options.prox_sigma),
    )
    return r, SolverStatus(code), steps


__all__ = [
    "NewtonACOptions",
    "alart_curnier",
    "alart_curnier_local",
    "contact_weights",
    "make_workspace",
    "newton_ac_core",
    "newton_ac_kernel",
    "slide_direction",
    "solve_newton_ac",
    "workspace_size",
]
