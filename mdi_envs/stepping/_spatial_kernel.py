"""The compiled Moreau-Jean midpoint step for spatial (3-D Coulomb) contacts, and its batch form.

For models with ``CONTACT_DIMENSION == 3`` whose contacts are always closed and whose normal
forces are not velocity constraints but follow from a load balance, ``N = N0 + K F`` as a linear
function of the friction forces F (``model.normal_loads(p)``; the differential-drive robot,
paper section 3.2, set I_NC). Per step of length dt (notation of docs/theory.md):

    q_M = q + dt/2 u
    u_free = u + M^-1 (h(q_M, u) + B tau) dt
    W_T: the 2 tangent rows per contact at q_M,  G_TT = W_T M^-1 W_T^T,  b_T = W_T u_free
    u+ = u_free + M^-1 W_T^T P_T,                q+ = q_M + dt/2 u+.

The impulses r_i = (P_N,i, P_T,i) solve one FC3D problem (De Saxce's formulation,
``mdi_envs.solvers.fc3d``) whose tangent rows are the real slip velocities after the step,

    u_T = G_TT P_T + b_T                      (no tangential restitution),

and whose normal rows encode the load transfer,

    u_N,i = s (P_N,i - N0_i dt - K_i . P_T),   s > 0 (the mean of diag G_TT),

so that Signorini's condition 0 <= u_N _|_ P_N >= 0 gives P_N = N0 dt + K P_T while that load
is positive, and P_N = 0 (a lifted contact, counted in ``INFO_LIFTED_CONTACTS``) otherwise;
the cone conditions give isotropic Coulomb friction with normal impulses that depend on the
friction impulses. The complementarity is invariant under the positive scale s, which only
makes both kinds of rows commensurate. The problem is solved in units of the weight impulse
P0 = sum(N0) dt and the velocity s P0 (r / P0, u / (s P0)), to an absolute tolerance
``NEWTON_TOL`` in these units, warm-started from the impulses passed in (the previous step's).
First by semismooth Newton on the friction impulses alone (``newton_load_transfer``): with
normal rows that are a load law, Signorini's condition has the closed form
P_N = max(0, N0 dt + K P_T), which leaves 2c unknowns (6 for the robot, not 9). If that does
not converge within ``LOAD_TRANSFER_MAX_ITER`` steps, the full FC3D problem by the semismooth
Newton method on the Alart-Curnier function (``newton_ac_core``), from the warm start, then
from the static loads without friction, then from zero, keeping otherwise the iterate with the
smallest residual (``INFO_ITERATIONS`` counts all Newton steps).
Where the load transfer is strong enough to lift contacts (a tall, narrow robot that would tip
over) the problem can have several solutions and Newton may still fail: the status says so.

The wheels' lateral rows are identical (both lie on the axle), so G_TT is singular while both
wheels roll: the split of the lateral impulse between them is not determined by the rigid model
(any split inside the cones is a solution; the motion and the normal impulses, which depend on
its sum only, are). The Newton method solves its then singular but consistent systems with
the redundant increment at 0; the warm start selects the split.

Mode (the paper's Table 1) from the slip after the step: contact i slides when
``|W_T,i u+| > SLIP_RTOL * v_ref + SLIP_ATOL * s P0``, with v_ref the largest single term
``|W_T[r, j] u+_j|`` of any slip velocity (the robot's speed scale); ``model.slip_mode`` maps the
per-contact flags to the mode (2, 3 or 5 for the robot), reported in ``INFO_MODE``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from mdi_envs._borrowing import REFERENCE_COUNTED, borrowing_njit
from mdi_envs._views import array_view
from mdi_envs.mechanics.compiled import CompiledEquations
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.solvers.fc3d.load_transfer import (
    load_transfer_workspace_size,
    newton_load_transfer,
)
from mdi_envs.solvers.fc3d.newton_ac import contact_weights, newton_ac_core
from mdi_envs.solvers.fc3d.newton_ac import workspace_size as newton_workspace_size
from mdi_envs.solvers.status import CODE_BREAKDOWN, CODE_CONVERGED, CODE_INACCURATE
from mdi_envs.stepping._kernel import (
    INFO_ACTIVE_CONTACTS,
    INFO_EQUALITIES,
    INFO_ITERATIONS,
    INFO_LCP_SIZE,
    INFO_SIZE,
    INFO_STATUS,
    StepShortcuts,
)
from mdi_envs.stepping._midpoint import (
    MOTION_SINGULAR,
    MOTION_UNDER_RESOLVED,
    free_motion_shapes,
    make_free_motion,
    offsets_of,
)

# The spatial step's diagnostics extend the planar layout (same meaning of entries 0..4;
# INFO_LCP_SIZE holds the FC3D problem size 3 c).
INFO_MODE = INFO_SIZE  # the model's slip mode (Table 1: 2, 3, 5 DOF); 0 without modes
INFO_LIFTED_CONTACTS = INFO_SIZE + 1  # contacts whose load would be negative: P_N = 0
INFO_RESIDUAL = INFO_SIZE + 2  # the FC3D solver's shared (relative) residual
SPATIAL_INFO_SIZE = INFO_SIZE + 3

NEWTON_TOL = 1e-12
"""Absolute residual tolerance of the scaled FC3D problem (in units of the weight impulse)."""
NEWTON_TOL_FLOOR = 1e-14
"""Smallest relative tolerance asked of the solver (its residual is relative to |q|)."""
NEWTON_MAX_ITER = 100
LOAD_TRANSFER_MAX_ITER = 20
"""Newton steps on the friction impulses alone before the full FC3D problem is solved."""
SLIP_RTOL = 1e-7
"""A contact slides when its slip exceeds this fraction of the speed scale v_ref ..."""
SLIP_ATOL = 1e-8
"""... plus this fraction of the solver's velocity unit s P0 (its accuracy is ~1e-12 of it)."""


def _spatial_shapes(model: type[ModelDefinition]) -> dict[str, tuple[int, ...]]:
    """The spatial step's float scratch arrays in buffer order (the free motion's first)."""
    n, m, c = model.NUM_DOFS, model.NUM_INPUTS, model.NUM_CONTACTS
    return {
        **free_motion_shapes(n, m), "Wc": (3 * c, n), "mu": (c,), "WT": (2 * c, n),
        "MinvWt": (n, 2 * c), "G": (2 * c, 2 * c), "bT": (2 * c,), "n0": (c,),
        "K": (c, 2 * c), "Wf": (3 * c, 3 * c), "qf": (3 * c,), "r": (3 * c,),
        "r_best": (3 * c,), "r_warm": (3 * c,), "newton": (newton_workspace_size(3 * c),),
        "load_transfer": (load_transfer_workspace_size(c),),
    }


def make_spatial_workspace(model: type[ModelDefinition]) -> tuple[np.ndarray, np.ndarray]:
    """Scratch buffers of the spatial ``step`` of ``model`` (one float64, one int64).

    Flat buffers keep the compiled call cheap to dispatch from Python; the step carves its
    arrays (``_spatial_shapes``, the free motion's first, then the Newton solver's scratch)
    from them. The int buffer holds the constant-mass flag, then the per-contact slip flags.
    """
    _, total = offsets_of(_spatial_shapes(model))
    return np.empty(total), np.zeros(1 + model.NUM_CONTACTS, np.int64)


def make_spatial_step_kernels(
    model: type[ModelDefinition], eq: CompiledEquations, shortcuts: StepShortcuts,
    load_transfer_max_iter: int = LOAD_TRANSFER_MAX_ITER,
) -> tuple[Any, Any]:
    """Compile ``step(...)`` and ``step_batch(...)`` for a spatial ``model``.

    The kernels have the planar kernels' signatures (``mdi_envs.stepping._kernel``) and write
    ``SPATIAL_INFO_SIZE`` diagnostics. ``load_transfer_max_iter`` bounds the Newton steps on
    the friction impulses alone before the full FC3D problem is solved (0: always the full
    problem unless the warm start solves it; tests compare both paths).

    Raises:
        NotImplementedError: the model is not spatial, has brakes, or lacks ``normal_loads``.
    """
    n = model.NUM_DOFS
    c, d, k = model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
    if d != 3 or c == 0:
        raise NotImplementedError(f"{model.__name__}: the spatial step needs 3-D contacts")
    if k > 0:
        raise NotImplementedError(f"{model.__name__}: brakes are not supported with 3-D contacts")
    if not model.HAS_LOAD_TRANSFER:
        raise NotImplementedError(
            f"{model.__name__}: the spatial step needs normal loads N = N0 + K F "
            "(unilateral 3-D contacts with normal rows are not implemented)"
        )
    contact_rows, friction_coefficients = eq.contact_rows, eq.friction_coefficients
    normal_loads = njit(model.normal_loads)
    slip_mode = njit(model.slip_mode)
    free_motion = make_free_motion(model, shortcuts.reuse_constant_mass)
    c2 = 2 * c
    c3 = 3 * c
    at, _ = offsets_of(_spatial_shapes(model))
    qm_at, minv_at, ufree_at, wc_at, mu_at = at["qm"], at["Minv"], at["ufree"], at["Wc"], at["mu"]
    wt_at, minvwt_at, g_at, bt_at, n0_at = at["WT"], at["MinvWt"], at["G"], at["bT"], at["n0"]
    k_at, wf_at, qf_at, r_at = at["K"], at["Wf"], at["qf"], at["r"]
    best_at, warm_at, newton_at = at["r_best"], at["r_warm"], at["newton"]
    lt_at = at["load_transfer"]
    newton_size = newton_workspace_size(c3)
    lt_size = load_transfer_workspace_size(c)

    @njit(inline="always")
    def views_of(ws):  # noqa: ANN001, ANN202
        """The step's arrays carved from the (float, int) workspace buffers."""
        fws, iws = ws
        return (
            fws, iws[0:1], fws[qm_at:qm_at + n], array_view(fws, minv_at, (n, n)),
            fws[ufree_at:ufree_at + n], array_view(fws, wc_at, (c3, n)),
            fws[mu_at:mu_at + c], array_view(fws, wt_at, (c2, n)),
            array_view(fws, minvwt_at, (n, c2)),
            array_view(fws, g_at, (c2, c2)), fws[bt_at:bt_at + c2],
            fws[n0_at:n0_at + c], array_view(fws, k_at, (c, c2)),
            array_view(fws, wf_at, (c3, c3)), fws[qf_at:qf_at + c3],
            fws[r_at:r_at + c3], fws[best_at:best_at + c3],
            fws[warm_at:warm_at + c3], fws[newton_at:newton_at + newton_size],
            fws[lt_at:lt_at + lt_size], iws[1:1 + c],
        )

    @borrowing_njit
    def advance(q, u, tau, dt, p, q_out, u_out, impulses, info, ws):  # noqa: ANN001
        """One step (arguments as ``step``).

        It carves its arrays from ``ws`` itself: passing them would flatten twenty views into
        some two hundred call arguments per step.
        """
        (fws, mass_ready, qm, Minv, ufree, Wc, mu, WT, MinvWt, G, bT, n0, K, Wf, qf, r, r_best,
         r_warm, nws, lws, sliding) = views_of(ws)

        # The warm start, read before the impulses are overwritten.
        warm_load = 0.0
        for i in range(c3):
            r[i] = impulses[i]
            if not np.isfinite(impulses[i]):
                warm_load = -np.inf
        for i in range(c):
            warm_load += impulses[3 * i]
        motion = free_motion(q, u, tau, dt, p, fws, mass_ready)
        ok = motion != MOTION_SINGULAR
        for i in range(c3):
            impulses[i] = 0.0
        info[INFO_STATUS] = CODE_CONVERGED
        info[INFO_ITERATIONS] = 0.0
        info[INFO_ACTIVE_CONTACTS] = c
        info[INFO_LCP_SIZE] = c3
        info[INFO_EQUALITIES] = 0.0
        info[INFO_MODE] = 0.0
        info[INFO_LIFTED_CONTACTS] = 0.0
        info[INFO_RESIDUAL] = 0.0
        if not ok:
            info[INFO_STATUS] = CODE_BREAKDOWN
            info[INFO_ACTIVE_CONTACTS] = 0.0
            info[INFO_LCP_SIZE] = 0.0
            for i in range(n):
                u_out[i] = ufree[i]
                q_out[i] = qm[i] + 0.5 * dt * ufree[i]
            return

        # Tangent rows at the midpoint, G_TT = W_T M^-1 W_T^T and b_T = W_T u_free.
        contact_rows(qm, p, Wc)
        friction_coefficients(p, mu)
        for i in range(c):
            for a in range(2):
                for j in range(n):
                    WT[2 * i + a, j] = Wc[3 * i + 1 + a, j]
        for j in range(n):
            for s in range(c2):
                acc = 0.0
                for t in range(n):
                    acc += Minv[j, t] * WT[s, t]
                MinvWt[j, s] = acc
        trace = 0.0
        for r_ in range(c2):
            acc = 0.0
            for j in range(n):
                acc += WT[r_, j] * ufree[j]
            bT[r_] = acc
            for s in range(r_, c2):  # G is symmetric (M is): its upper triangle, mirrored
                acc = 0.0
                for j in range(n):
                    acc += WT[r_, j] * MinvWt[j, s]
                G[r_, s] = acc
                G[s, r_] = acc
            trace += G[r_, r_]
        scale = trace / c2
        if not scale > 0.0:
            scale = 1.0

        # Loads N = N0 + K F, and the weight impulse P0 as the impulse unit.
        loads0, loads_k = normal_loads(p)
        weight = 0.0
        for i in range(c):
            n0[i] = loads0[i]
            weight += loads0[i]
            row = loads_k[i]
            for s in range(c2):
                K[i, s] = row[s]
        p0 = weight * dt
        if not p0 > 0.0:
            p0 = dt
        v0 = scale * p0

        # The problem in units of P0 and s P0 (r' = r / p0, u' = u / (s p0)): G, b_T and the
        # static loads N0 dt scaled in place.
        q_norm = 0.0
        inv_scale = 1.0 / scale
        inv_v0 = 1.0 / v0
        load_unit = dt / p0
        for r_ in range(c2):
            bT[r_] *= inv_v0
            q_norm += bT[r_] * bT[r_]
            for s in range(c2):
                G[r_, s] *= inv_scale
        for i in range(c):
            n0[i] *= load_unit
            q_norm += n0[i] * n0[i]
        # The solver's residual is relative to max(|q|, 1): ask for NEWTON_TOL absolute, that
        # is in units of the weight impulse, whatever the speed (floored above round-off).
        tol = max(NEWTON_TOL / max(np.sqrt(q_norm), 1.0), NEWTON_TOL_FLOOR)
        for i in range(c3):
            r_warm[i] = r[i] / p0 if warm_load > 0.0 else 0.0
            r[i] = r_warm[i]
        # First Newton on the friction impulses alone, the loads solved in closed form.
        code, iterations, residual = newton_load_transfer(
            G, bT, n0, K, mu, r, load_transfer_max_iter, tol, 1e-4, 40, lws)
        if code != CODE_CONVERGED:  # then the full FC3D problem
            code, steps, residual = _solve_full_problem(
                G, bT, n0, K, mu, r, r_warm, warm_load > 0.0, tol, Wf, qf, r_best, nws)
            iterations += steps
        if code == CODE_CONVERGED and motion == MOTION_UNDER_RESOLVED:
            code = CODE_INACCURATE
        info[INFO_STATUS] = code
        info[INFO_ITERATIONS] = iterations
        info[INFO_RESIDUAL] = residual
        finite = True
        for i in range(c3):
            if not np.isfinite(r[i]):
                finite = False
        if finite:
            for i in range(c3):
                impulses[i] = p0 * r[i]
        else:  # keep the state finite (and the next step cold); the status says it failed
            info[INFO_STATUS] = CODE_BREAKDOWN

        # u+ = u_free + M^-1 W_T^T P_T, q+ = q_M + dt/2 u+.
        for j in range(n):
            acc = ufree[j]
            for i in range(c):
                acc += MinvWt[j, 2 * i] * impulses[3 * i + 1]
                acc += MinvWt[j, 2 * i + 1] * impulses[3 * i + 2]
            u_out[j] = acc
            q_out[j] = qm[j] + 0.5 * dt * acc

        # Slip after the step, mode and lifted contacts.
        v_ref = 0.0
        for r_ in range(c2):
            for j in range(n):
                term = abs(WT[r_, j] * u_out[j])
                if term > v_ref:
                    v_ref = term
        slip_tol = SLIP_RTOL * v_ref + SLIP_ATOL * v0
        lifted = 0
        for i in range(c):
            s1 = 0.0
            s2 = 0.0
            for j in range(n):
                s1 += WT[2 * i, j] * u_out[j]
                s2 += WT[2 * i + 1, j] * u_out[j]
            sliding[i] = 1 if np.sqrt(s1 * s1 + s2 * s2) > slip_tol else 0
            if impulses[3 * i] <= 1e-10 * p0:
                lifted += 1
        info[INFO_LIFTED_CONTACTS] = lifted
        info[INFO_MODE] = slip_mode(sliding)

    @borrowing_njit
    def step(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info, ws):  # noqa: ANN001
        """Advance one step of length dt [s].

        Args:
            q, u: (n,) coordinates and velocities at t_k. tau: (m,) inputs, held over the step.
            brake_bound: (0,) unused (no brakes). dt: step [s]. p: parameter record.
            q_out, u_out: (n,) outputs at t_k + dt (overwritten).
            impulses: (c*3,) per contact (P_N, P_T1, P_T2) [N s]. In: the warm start (the
                previous step's impulses; no positive normal impulse or a non-finite entry
                means a cold start). Out: this step's impulses.
            info: (SPATIAL_INFO_SIZE,) output diagnostics (INFO_* constants).
            ws: (float, int) buffers from ``make_spatial_workspace``.
        """
        advance(q, u, tau, dt, p, q_out, u_out, impulses, info, ws)

    @njit
    def step_batch(Q, U, TAU, BRAKE, dt, p, num_substeps, IMPULSES, INFO, ws):  # noqa: ANN001
        """Advance N independent copies by ``num_substeps`` steps each, in place.

        Args:
            Q, U: (N, n) states, overwritten. TAU: (N, m) inputs. BRAKE: (N, 0) unused.
            dt: step [s]. p: parameter record. num_substeps: steps per call.
            IMPULSES: (N, c*3) the impulses of each copy's last step. Read first as each
                copy's warm start (zeros: a cold start), as in ``step``.
            INFO: (N, SPATIAL_INFO_SIZE) output: diagnostics of each copy's last step, except
                the status, which is the worst (largest code) over the substeps.
            ws: one workspace from ``make_spatial_workspace``, shared by the copies.
        """
        step_copies(Q, U, TAU, dt, p, num_substeps, IMPULSES, INFO, ws, np.empty(n), np.empty(n))

    @borrowing_njit
    def step_copies(Q, U, TAU, dt, p, num_substeps, IMPULSES, INFO, ws, q_next,  # noqa: ANN001
                    u_next):
        """``step_batch``'s loop over the copies (q_next, u_next: (n,) scratch)."""
        num_copies = Q.shape[0]
        for e in range(num_copies):
            worst = 0.0
            q, u, tau, impulses, info = Q[e], U[e], TAU[e], IMPULSES[e], INFO[e]
            for _ in range(num_substeps):
                advance(q, u, tau, dt, p, q_next, u_next, impulses, info, ws)
                for j in range(n):
                    q[j] = q_next[j]
                    u[j] = u_next[j]
                if info[INFO_STATUS] > worst:
                    worst = info[INFO_STATUS]
            info[INFO_STATUS] = worst

    return step, step_batch


@njit(cache=True, **REFERENCE_COUNTED)
def _solve_full_problem(G, b, n0, K, mu, r, r_warm, warm, tol, Wf, qf, r_best,  # noqa: ANN001
                        newton_workspace) -> tuple[int, int, float]:
    """The scaled FC3D problem ``u' = Wf r' + qf`` by ``newton_ac_core``, from several starts.

    The fallback when ``newton_load_transfer`` does not converge. Starts, until one converges:
    r_warm (if ``warm``), the static loads without friction, zero; the best result (by
    residual) is kept if none does.

    Args:
        G: (2c, 2c), b: (2c,), n0: (c,), K: (c, 2c), mu: (c,): the problem as
            ``newton_load_transfer`` takes it (scaled). r: (3c,) output. r_warm: (3c,).
        warm: whether to start from r_warm. tol: shared-residual tolerance.
        Wf, qf, r_best: (3c, 3c), (3c,), (3c,) scratch.
        newton_workspace: ``newton_ac_core``'s scratch.

    Returns:
        (code, Newton steps over all starts, residual).
    """
    c = mu.shape[0]
    for i in range(c):
        ni = 3 * i
        for j in range(c):
            nj = 3 * j
            Wf[ni, nj] = 1.0 if i == j else 0.0
            for a in range(2):
                Wf[ni, nj + 1 + a] = -K[i, 2 * j + a]
                Wf[ni + 1 + a, nj] = 0.0
                for s in range(2):
                    Wf[ni + 1 + a, nj + 1 + s] = G[2 * i + a, 2 * j + s]
        qf[ni] = -n0[i]
        qf[ni + 1] = b[2 * i]
        qf[ni + 2] = b[2 * i + 1]
    rho = contact_weights(Wf, 1.0)
    attempt = 0 if warm else 1
    code = CODE_BREAKDOWN
    iterations = 0
    residual = np.inf
    best = np.inf
    while attempt <= 2:
        for i in range(c):
            load = max(n0[i], 0.0) if attempt == 1 else 0.0
            r[3 * i] = r_warm[3 * i] if attempt == 0 else load
            r[3 * i + 1] = r_warm[3 * i + 1] if attempt == 0 else 0.0
            r[3 * i + 2] = r_warm[3 * i + 2] if attempt == 0 else 0.0
        code, steps, residual = newton_ac_core(
            Wf, qf, mu, rho, r, NEWTON_MAX_ITER, tol, 1e-4, 40, 1.0, newton_workspace
        )
        iterations += steps
        if code == CODE_CONVERGED:
            return code, iterations, residual
        if residual < best:
            best = residual
            for i in range(3 * c):
                r_best[i] = r[i]
        attempt += 1
    if best < np.inf:
        residual = best
        for i in range(3 * c):
            r[i] = r_best[i]
    return code, iterations, residual


__all__ = [
    "INFO_LIFTED_CONTACTS",
    "INFO_MODE",
    "INFO_RESIDUAL",
    "NEWTON_MAX_ITER",
    "NEWTON_TOL",
    "NEWTON_TOL_FLOOR",
    "SLIP_ATOL",
    "SLIP_RTOL",
    "SPATIAL_INFO_SIZE",
    "make_spatial_step_kernels",
    "make_spatial_workspace",
]
