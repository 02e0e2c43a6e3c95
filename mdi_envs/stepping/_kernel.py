"""The compiled Moreau-Jean midpoint step for one model, and its batched form.

This is the one place where impulses and complementarity variables are mapped to each other
(solvers speak ``M, q, z, w``; mechanics speaks mass matrix and coordinates). Notation of
the documentation's Theory page (docs/theory.md), per step of length dt:

    q_M = q + dt/2 u
    M(q_M) (u+ - u) = (h(q_M, u) + theta J (u+ - u) + B tau) dt + W P,   J = dh/du(q_M, u)
    q+ = q_M + dt/2 u+

with theta = 1/2 (see ``make_free_motion``; the term vanishes when h does not depend on u)
and the laws on xi = W^T u+ + eps W^T u for the contacts closed at q_M (g_i(q_M) <= 0) and
for the active brakes. Planar Coulomb friction and Tresca brakes become LCP rows by splitting
the set-valued sign: P_R = mu P_N + P_T >= 0, P_L = mu P_N - P_T >= 0, xi_T = xi_R - xi_L
(paper eqs. 17-21, 32-33). An ideal brake is an equality row xi_B = 0 with P_B free, eliminated
by a Schur complement. Unknowns v = (x, y): x the LCP variables (per active contact P_N, then
P_R and xi_L if mu > 0; per Tresca brake P_R and xi_L), y the ideal-brake impulses.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numba import njit

from mdi_envs._borrowing import REFERENCE_COUNTED, borrowing_njit
from mdi_envs._kernel_cache import define
from mdi_envs._views import array_view
from mdi_envs.mechanics.compiled import CompiledEquations
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.solvers._linalg import invert_into
from mdi_envs.solvers.lcp.enumerative import enumerative_kernel
from mdi_envs.solvers.lcp.lemke import lemke_kernel
from mdi_envs.solvers.status import CODE_BREAKDOWN, CODE_CONVERGED, CODE_INACCURATE
from mdi_envs.stepping._midpoint import (
    MOTION_SINGULAR,
    MOTION_UNDER_RESOLVED,
    free_motion_shapes,
    make_free_motion,
    make_midpoint_rows,
    offsets_of,
)

GAP_TOLERANCE = 1e-12
"""[m] A contact counts as closed at the midpoint when g_i(q_M) <= this: a body resting on a
surface keeps gaps of rounding size (~1e-21 m), which must not open the contact for a step."""

IDEAL_BRAKE_IMPULSE = 1e6
"""[N s or N m s] A brake whose impulse bound a dt reaches this acts as the ideal brake
(equality row). The Tresca rows carry P_B = P_R - a dt, which loses all precision when a dt is
many orders above P_B; no brake of these models needs impulses anywhere near this bound."""

# Layout of the per-step diagnostics vector.
INFO_STATUS = 0  # SolverStatus code of the step's solve (CONVERGED when nothing to solve)
INFO_ITERATIONS = 1  # pivots / candidates of the LCP solve
INFO_ACTIVE_CONTACTS = 2  # contacts closed at the midpoint
INFO_LCP_SIZE = 3  # complementarity variables after elimination
INFO_EQUALITIES = 4  # ideal (equality) brake rows
INFO_SIZE = 5



class StepShortcuts(NamedTuple):
    """The exact shortcuts of the step ("skip what a scene doesn't need"), each switchable.

    Each can be turned off so that tests compare it with the full path.

    Attributes:
        skip_frictionless_rows: a closed contact with mu = 0 contributes only its normal row
            (full path: also the friction rows P_R, xi_L, which then carry P_T = 0).
        reuse_constant_mass: for a model with HAS_CONSTANT_MASS, M^-1 is computed on the first
            step and reused (full path: M(q_M) is evaluated and inverted every step).
        direct_solve_max_size: LCPs up to this size are solved by exact enumeration instead of
            Lemke's method (0: always Lemke).
        closed_form_single_row: a step with one impulse row (one frictionless contact or one
            brake: the manipulator's engaged brake) takes the law's closed-form solution, a
            projection of the unconstrained impulse onto [0, inf), [-a dt, a dt] or R (full
            path: the MLCP of that row).
    """

    skip_frictionless_rows: bool = True
    reuse_constant_mass: bool = True
    direct_solve_max_size: int = 3
    closed_form_single_row: bool = True


Layout = dict[str, tuple[int, tuple[int, ...]]]


def _workspace_layout(model: type[ModelDefinition]) -> tuple[Layout, int, Layout, int]:
    """Offsets and shapes of the step's scratch arrays inside one float and one int buffer."""
    n, m = model.NUM_DOFS, model.NUM_INPUTS
    c, d, k = model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
    rows = c * d + k
    lcp = 3 * c + 2 * k  # LCP variables: 3 per contact, 2 per Tresca brake
    size = lcp + k  # plus the ideal-brake equalities
    float_shapes: dict[str, tuple[int, ...]] = {
        # the free motion and the active set (``advance``, through flat offsets)
        **free_motion_shapes(n, m), "g": (c,), "Wc": (c * d, n), "Wb": (k, n),
        "eps": (c,), "mu": (c,),
        # the complementarity problem (``solve_active_set``)
        "Wr": (rows, n), "MinvWt": (n, rows), "G": (rows, rows), "gfree": (rows,),
        "gpre": (rows,), "S": (rows, size), "s0": (rows,), "A": (size, size), "a": (size,),
        "Mred": (lcp, lcp), "qred": (lcp,), "z": (lcp,), "T": (lcp, lcp + 2),
        "pivot_row": (lcp + 2,), "Aee": (k, k), "Aee_inv": (k, k), "lu_work": (k, k),
        "lu_col": (k,), "v": (size,), "P": (rows,), "row_eps": (rows,),
        # the impact-locating step (``locate_impacts``): gaps at t_k, the state at the
        # impact, and one part's impulses and diagnostics
        "g0": (c,), "q_hit": (n,), "u_hit": (n,), "part_impulses": (rows,),
        "part_info": (INFO_SIZE,),
    }
    int_shapes: dict[str, tuple[int, ...]] = {
        "mass_ready": (1,), "basis": (lcp,), "row_of": (2 * lcp + 1,),
        "slot_of": (2 * lcp + 1,), "slot_var": (lcp + 1,), "row_ref": (rows,),
        "row_var": (rows,),
    }

    def layout_of(shapes: dict[str, tuple[int, ...]]) -> tuple[Layout, int]:
        offsets, total = offsets_of(shapes)
        return {name: (offsets[name], shape) for name, shape in shapes.items()}, total

    float_layout, float_total = layout_of(float_shapes)
    int_layout, int_total = layout_of(int_shapes)
    return float_layout, float_total, int_layout, int_total


def make_workspace(model: type[ModelDefinition]) -> tuple[np.ndarray, np.ndarray]:
    """Scratch buffers of ``step`` for ``model`` (one float64, one int64), reused across steps.

    Two flat buffers keep the compiled call cheap to dispatch from Python (numba types every
    element of a tuple argument on each call); the step reads and writes its free-motion and
    active-set data at fixed offsets and carves array views only to solve a complementarity
    problem (``solve_active_set``) or to locate an impact.
    """
    _, float_total, _, int_total = _workspace_layout(model)
    return np.empty(max(float_total, 1)), np.zeros(max(int_total, 1), np.int64)


def _make_carver(layout: Layout) -> Any:
    """A compiled function returning the views of ``layout`` into a flat buffer, in order.

    Its source is generated so that every offset and shape is a compile-time constant.
    """
    lines = ["def carve(buffer):"]
    for name, (offset, shape) in layout.items():
        lines.append(f"    {name} = array_view(buffer, {offset}, {shape!r})")
    lines.append(f"    return ({', '.join(layout)},)")
    namespace: dict[str, Any] = {"array_view": array_view}
    define("\n".join(lines), namespace)
    return njit(namespace["carve"])


def make_step_kernels(
    model: type[ModelDefinition], eq: CompiledEquations, shortcuts: StepShortcuts,
    locate_impacts: bool = False,
) -> tuple[Any, Any]:
    """Compile ``step(...)`` and ``step_batch(...)`` for ``model`` (see their docstrings).

    ``locate_impacts``: take each step with ``located_advance`` instead of ``advance`` (models
    with contacts and without brakes only).
    """
    n = model.NUM_DOFS
    c, d, k = model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
    if c > 0 and d != 2:
        raise NotImplementedError(
            f"{model.__name__}: contact_dimension {d}; the LCP step handles planar contacts"
        )
    if locate_impacts and (c == 0 or k > 0):
        raise ValueError(
            f"{model.__name__}: locate_impacts needs a model with contacts and without brakes "
            f"(it has {c} contacts, {k} brakes)"
        )
    gaps = eq.gaps
    keep_frictionless_rows = not shortcuts.skip_frictionless_rows
    closed_form_single_row = shortcuts.closed_form_single_row
    direct_solve_max_size = shortcuts.direct_solve_max_size
    float_layout, _, int_layout, _ = _workspace_layout(model)
    carve_floats = _make_carver(float_layout)
    carve_ints = _make_carver(int_layout)
    free_motion = make_free_motion(model, shortcuts.reuse_constant_mass)
    midpoint_rows = make_midpoint_rows(
        model, {name: shape for name, (_, shape) in float_layout.items()})
    at_qm, at_Minv, at_ufree, at_col = (float_layout[name][0]
                                        for name in ("qm", "Minv", "ufree", "col"))
    at_g, at_Wc, at_Wb, at_eps, at_mu = (float_layout[name][0]
                                         for name in ("g", "Wc", "Wb", "eps", "mu"))

    @njit(inline="always")
    def advance(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info, fws, iws):  # noqa: ANN001
        """Advance one step of length dt [s].

        Args:
            q, u: (n,) coordinates and velocities at t_k. tau: (m,) inputs, held over the step.
            brake_bound: (k,) brake bounds a >= 0 [force or torque]: 0 released, inf (or any
                a with a dt >= IDEAL_BRAKE_IMPULSE) ideal.
            dt: step [s]. p: the model's parameter record.
            q_out, u_out: (n,) outputs at t_k + dt (overwritten).
            impulses: (c*d + k,) output, overwritten: per contact P_N then P_T, then the
                brake impulses [N s or N m s]; zero for open contacts and released brakes.
            info: (INFO_SIZE,) output diagnostics (see the INFO_* constants).
            fws, iws: the float and int buffers of ``make_workspace``.

        This inlined part takes the free motion, finds the active set and finishes the steps
        without a problem to solve, or with one row (closed form), on fixed offsets of the flat
        buffer; ``solve_active_set`` takes the rest on array views. (Every array view alive
        here would cost reference counting on each step: most of a free step's time.)
        """
        motion = free_motion(q, u, tau, dt, p, fws, iws)
        ok = motion != MOTION_SINGULAR
        for i in range(c * d + k):
            impulses[i] = 0.0
        info[INFO_STATUS] = (CODE_BREAKDOWN if not ok else CODE_INACCURATE
                             if motion == MOTION_UNDER_RESOLVED else CODE_CONVERGED)
        info[INFO_ITERATIONS] = 0.0
        info[INFO_ACTIVE_CONTACTS] = 0.0
        info[INFO_LCP_SIZE] = 0.0
        info[INFO_EQUALITIES] = 0.0

        # Active set: contacts closed at the midpoint, brakes with a positive bound.
        midpoint_rows(p, fws)
        num_rows = 0
        num_x = 0
        num_eq = 0
        num_active = 0
        last_row = -1  # impulse index of the last active row
        for i in range(c):
            if fws[at_g + i] <= GAP_TOLERANCE:
                frictional = fws[at_mu + i] > 0.0 or keep_frictionless_rows
                num_active += 1
                num_rows += 2 if frictional else 1
                num_x += 3 if frictional else 1
                last_row = i * d
        for j in range(k):
            if brake_bound[j] > 0.0:
                num_rows += 1
                last_row = c * d + j
                if brake_bound[j] * dt >= IDEAL_BRAKE_IMPULSE:
                    num_eq += 1
                else:
                    num_x += 2
        info[INFO_ACTIVE_CONTACTS] = num_active
        if num_rows == 0 or not ok:
            for i in range(n):
                u_out[i] = fws[at_ufree + i]
                q_out[i] = fws[at_qm + i] + 0.5 * dt * u_out[i]
            return
        if num_rows == 1 and closed_form_single_row:
            # One normal row (frictionless contact) or one brake row w: with G = w M^-1 w^T
            # and xi = w u_free + G P + eps w u, the law's unique solution is the projection
            # of P* = -(w u_free + eps w u) / G onto [0, inf) (Signorini-Newton), [-a dt, a dt]
            # (Tresca) or R (ideal brake).
            if last_row < c * d:
                at_w = at_Wc + last_row * n
                eps_row = fws[at_eps + last_row // d]
                low, high = 0.0, np.inf
            else:
                at_w = at_Wb + (last_row - c * d) * n
                eps_row = 0.0
                bound = brake_bound[last_row - c * d] * dt
                low, high = ((-np.inf, np.inf) if bound >= IDEAL_BRAKE_IMPULSE
                             else (-bound, bound))
            G_row = 0.0
            xi_free = 0.0
            for j in range(n):  # M^-1 w into the free motion's scratch ``col``
                acc = 0.0
                for t in range(n):
                    acc += fws[at_Minv + j * n + t] * fws[at_w + t]
                fws[at_col + j] = acc
                G_row += fws[at_w + j] * acc
                xi_free += fws[at_w + j] * (fws[at_ufree + j] + eps_row * u[j])
            if G_row > 0.0:
                P_row = min(max(-xi_free / G_row, low), high)
                impulses[last_row] = P_row
                info[INFO_LCP_SIZE] = num_x
                info[INFO_EQUALITIES] = num_eq
                for j in range(n):
                    u_out[j] = fws[at_ufree + j] + fws[at_col + j] * P_row
                    q_out[j] = fws[at_qm + j] + 0.5 * dt * u_out[j]
                return
        solve_active_set(q, u, brake_bound, dt, motion, num_rows, num_x, num_eq, q_out, u_out,
                         impulses, info, fws, iws)

    @njit(**REFERENCE_COUNTED)
    def solve_active_set(q, u, brake_bound, dt, motion, num_rows, num_x, num_eq,  # noqa: ANN001
                         q_out, u_out, impulses, info, fws, iws):
        """The step's complementarity problem on the active set ``advance`` found, and its end.

        ``num_rows`` impulse rows, ``num_x`` LCP variables, ``num_eq`` ideal brakes; the other
        arguments as ``advance``'s.
        """
        (qm, M, Minv, h, B, ufree, Mwork, col, g, Wc, Wb, eps, mu, Wr, MinvWt, G, gfree,
         gpre, S, s0, A, a, Mred, qred, z, T, pivot_row, Aee, Aee_inv, lu_work, lu_col, v, P,
         row_eps, _, _, _, _, _) = carve_floats(fws)
        _, basis, row_of, slot_of, slot_var, row_ref, row_var = carve_ints(iws)
        # Rows W (num_rows, n), their free and pre-step velocities, and eps on normal rows.
        r = 0
        for i in range(c):
            if g[i] <= GAP_TOLERANCE:
                for t in range(2 if mu[i] > 0.0 or keep_frictionless_rows else 1):
                    for j in range(n):
                        Wr[r, j] = Wc[i * d + t, j]
                    row_ref[r] = i * d + t
                    r += 1
        for b in range(k):
            if brake_bound[b] > 0.0:
                for j in range(n):
                    Wr[r, j] = Wb[b, j]
                row_ref[r] = c * d + b
                r += 1
        for j in range(n):
            for r in range(num_rows):
                acc = 0.0
                for t in range(n):
                    acc += Minv[j, t] * Wr[r, t]
                MinvWt[j, r] = acc
        for r in range(num_rows):
            gf = 0.0
            gp = 0.0
            for j in range(n):
                gf += Wr[r, j] * ufree[j]
                gp += Wr[r, j] * u[j]
            gfree[r] = gf
            gpre[r] = gp
            for s in range(num_rows):
                acc = 0.0
                for j in range(n):
                    acc += Wr[r, j] * MinvWt[j, s]
                G[r, s] = acc

        # P = S v + s0 and the MLCP rows A v + a, built contact by contact (module docstring).
        size = num_x + num_eq
        for r in range(num_rows):
            s0[r] = 0.0
            for s in range(size):
                S[r, s] = 0.0
        for r in range(size):
            a[r] = 0.0
            for s in range(size):
                A[r, s] = 0.0
        # One pass fills S, s0, the constant entries of A and a, and for each impulse row r
        # the MLCP row its xi feeds (row_var) and its restitution (row_eps).
        r = 0
        x = 0
        y = num_x
        for i in range(c):
            if g[i] > GAP_TOLERANCE:
                continue
            S[r, x] = 1.0
            row_var[r] = x
            row_eps[r] = eps[i]
            if mu[i] > 0.0 or keep_frictionless_rows:
                S[r + 1, x] = -mu[i]
                S[r + 1, x + 1] = 1.0
                row_var[r + 1] = x + 1
                row_eps[r + 1] = 0.0
                A[x + 1, x + 2] = 1.0  # xi_R = xi_T + xi_L
                A[x + 2, x] = 2.0 * mu[i]  # P_L = 2 mu P_N - P_R
                A[x + 2, x + 1] = -1.0
                x += 3
                r += 2
            else:
                x += 1
                r += 1
        for b in range(k):
            bound = brake_bound[b]
            if bound <= 0.0:
                continue
            row_eps[r] = 0.0
            if bound * dt >= IDEAL_BRAKE_IMPULSE:
                S[r, y] = 1.0
                row_var[r] = y
                y += 1
            else:
                S[r, x] = 1.0
                s0[r] = -bound * dt
                row_var[r] = x
                A[x, x + 1] = 1.0  # xi_R = xi_B + xi_L
                A[x + 1, x] = -1.0  # P_L = 2 a dt - P_R
                a[x + 1] = 2.0 * bound * dt
                x += 2
            r += 1
        # The rows of xi = G (S v + s0) + b, now that S and s0 are complete.
        for r in range(num_rows):
            _add_row(A, a, row_var[r], G, S, s0, gfree, gpre, r, row_eps[r], num_rows, size)

        code, iterations = _solve_mlcp(
            A, a, num_x, num_eq, direct_solve_max_size, v, Mred, qred, z, T, basis, row_of,
            slot_of, slot_var, pivot_row, Aee, Aee_inv, lu_work, lu_col,
        )
        if code == CODE_CONVERGED and motion == MOTION_UNDER_RESOLVED:
            code = CODE_INACCURATE
        info[INFO_STATUS] = code
        info[INFO_ITERATIONS] = iterations
        info[INFO_LCP_SIZE] = num_x
        info[INFO_EQUALITIES] = num_eq
        for r in range(num_rows):
            acc = s0[r]
            for s in range(size):
                acc += S[r, s] * v[s]
            P[r] = acc
            impulses[row_ref[r]] = acc
        for j in range(n):
            acc = ufree[j]
            for r in range(num_rows):
                acc += MinvWt[j, r] * P[r]
            u_out[j] = acc
            q_out[j] = qm[j] + 0.5 * dt * acc

    @njit(**REFERENCE_COUNTED)
    def located_advance(q, u, tau, brake_bound, dt, p, q_out, u_out,  # noqa: ANN001
                        impulses, info, fws, iws):
        """``advance``, but a step in which an open contact closes is split at the impact.

        The parts: flight to t*, the impact law alone (a step of length 0), the rest.

        The midpoint step applies an impact at the step's midpoint wherever in the step it
        happened, an O(|u| dt) error in position and O(|h| dt) in velocity per impact. Here
        t* is the first root in (0, dt] of the gap's quadratic model g(t_k + s) = g0 + s
        gamma0 + s^2 (gamma_free - gamma0) / (2 dt) (gamma = W_N^T u at the step start and
        after the free motion), exact for constant forces and linear gaps (the bouncing
        ball). Only the first impact of a step is located; a contact the model leaves open
        at t* (curved gaps: g(q(t*)) of order dt^3) is taken by the last part's midpoint as
        usual. Outputs as ``advance``: impulses summed over the parts, the worst status, the
        iterations summed, the other diagnostics of the part that closed the most contacts.
        """
        g0, q_hit, u_hit, part_impulses, part_info = carve_floats(fws)[-5:]
        advance(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info, fws, iws)
        gaps(q, p, g0)
        hit = dt
        for i in range(c):
            if g0[i] <= GAP_TOLERANCE:
                continue
            gamma0 = 0.0
            gamma_free = 0.0
            for j in range(n):
                gamma0 += fws[at_Wc + i * d * n + j] * u[j]
                gamma_free += fws[at_Wc + i * d * n + j] * fws[at_ufree + j]
            if g0[i] + 0.5 * dt * (gamma0 + gamma_free) > 0.0:
                continue  # still open at t_k + dt
            hit = min(hit, _first_root(g0[i], gamma0, 0.5 * (gamma_free - gamma0) / dt, dt))
        if hit >= dt:
            return
        for part in range(3):
            length = hit if part == 0 else 0.0 if part == 1 else dt - hit
            q_from = q if part == 0 else q_out
            u_from = u if part == 0 else u_out
            advance(q_from, u_from, tau, brake_bound, length, p, q_hit, u_hit, part_impulses,
                    part_info, fws, iws)
            for j in range(n):
                q_out[j] = q_hit[j]
                u_out[j] = u_hit[j]
            if part == 0:
                for r in range(c * d):
                    impulses[r] = part_impulses[r]
                for r in range(INFO_SIZE):
                    info[r] = part_info[r]
                continue
            for r in range(c * d):
                impulses[r] += part_impulses[r]
            info[INFO_STATUS] = max(info[INFO_STATUS], part_info[INFO_STATUS])
            info[INFO_ITERATIONS] += part_info[INFO_ITERATIONS]
            if part_info[INFO_ACTIVE_CONTACTS] > info[INFO_ACTIVE_CONTACTS]:
                for r in range(INFO_ACTIVE_CONTACTS, INFO_SIZE):
                    info[r] = part_info[r]

    step_once = located_advance if locate_impacts else advance

    @njit(inline="always")
    def step(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info, ws):  # noqa: ANN001
        """One step (arguments as ``advance``; ws = ``make_workspace(model)``)."""
        step_once(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info, ws[0], ws[1])

    @njit
    def step_batch(Q, U, TAU, BRAKE, dt, p, num_substeps, IMPULSES, INFO, ws):  # noqa: ANN001
        """Advance N independent copies by ``num_substeps`` steps each, in place.

        Args:
            Q, U: (N, n) states, overwritten. TAU: (N, m) inputs. BRAKE: (N, k) bounds.
            dt: step [s]. p: parameter record. num_substeps: steps per call.
            IMPULSES: (N, c*d + k) output: the impulses of each copy's last step.
            INFO: (N, INFO_SIZE) output: diagnostics of each copy's last step, except the status,
                which is the worst (largest code) over the substeps.
            ws: one workspace from ``make_workspace``, shared by the copies.
        """
        fws, iws = ws
        step_copies(Q, U, TAU, BRAKE, dt, p, num_substeps, IMPULSES, INFO, fws, iws,
                    np.empty(n), np.empty(n))

    @borrowing_njit
    def step_copies(Q, U, TAU, BRAKE, dt, p, num_substeps, IMPULSES, INFO, fws, iws,  # noqa: ANN001
                    q_next, u_next):
        """``step_batch``'s loop over the copies (q_next, u_next: (n,) scratch)."""
        num_copies = Q.shape[0]
        for e in range(num_copies):
            worst = 0.0
            q, u, tau, brake, impulses, info = Q[e], U[e], TAU[e], BRAKE[e], IMPULSES[e], INFO[e]
            for _ in range(num_substeps):
                step_once(q, u, tau, brake, dt, p, q_next, u_next, impulses, info, fws, iws)
                for j in range(n):
                    q[j] = q_next[j]
                    u[j] = u_next[j]
                if info[INFO_STATUS] > worst:
                    worst = info[INFO_STATUS]
            info[INFO_STATUS] = worst

    return step, step_batch


@njit(cache=True, **REFERENCE_COUNTED)
def _first_root(c0: float, c1: float, c2: float, limit: float) -> float:
    """The smallest root s in (0, limit] of c0 + c1 s + c2 s^2.

    Given c0 > 0 >= the value at ``limit`` (so one exists); the secant's root when rounding
    hides it.
    """
    if c2 != 0.0:
        discriminant = c1 * c1 - 4.0 * c2 * c0
        if discriminant >= 0.0:
            half = -0.5 * (c1 + np.copysign(np.sqrt(discriminant), c1))  # != 0 as c0 > 0
            best = np.inf
            for root in (half / c2, c0 / half):
                if 0.0 < root <= limit and root < best:
                    best = root
            if best <= limit:
                return best
    elif c1 < 0.0:
        return min(limit, -c0 / c1)
    return limit * c0 / (c0 - (c0 + limit * (c1 + limit * c2)))


@njit(cache=True, **REFERENCE_COUNTED)
def _add_row(A, a, row, G, S, s0, gfree, gpre, r, eps, num_rows, size):  # noqa: ANN001
    """A[row, :] += (G S)[r, :] and a[row] += (G s0)[r] + gfree[r] + eps gpre[r] (xi of row r)."""
    for s in range(size):
        acc = 0.0
        for t in range(num_rows):
            acc += G[r, t] * S[t, s]
        A[row, s] += acc
    acc = gfree[r] + eps * gpre[r]
    for t in range(num_rows):
        acc += G[r, t] * s0[t]
    a[row] += acc


@njit(cache=True, **REFERENCE_COUNTED)
def _solve_mlcp(A, a, num_x, num_eq, direct_solve_max_size, v, Mred, qred, z, T,  # noqa: ANN001
                basis, row_of, slot_of, slot_var, pivot_row, Aee, Aee_inv, lu_work, lu_col):
    """Solve [x; y] from 0 <= x _|_ A_xx x + A_xy y + a_x >= 0, A_yx x + A_yy y + a_y = 0.

    The equality block is eliminated (Schur complement), the reduced LCP solved by enumeration
    when it has at most ``direct_solve_max_size`` variables and by Lemke's method otherwise.
    Writes v = (x, y); returns (status code, iterations).
    """
    L = num_x
    E = num_eq
    if E > 0:
        for i in range(E):
            for j in range(E):
                Aee[i, j] = A[L + i, L + j]
        if not invert_into(Aee[:E, :E], Aee_inv[:E, :E], lu_work[:E, :E], lu_col[:E]):
            for i in range(L + E):
                v[i] = 0.0
            return CODE_BREAKDOWN, 0
    # Reduced LCP: Mred = A_xx - A_xy Aee^-1 A_yx, qred = a_x - A_xy Aee^-1 a_y.
    for i in range(L):
        qi = a[i]
        for e in range(E):
            coef = 0.0
            for f in range(E):
                coef += A[i, L + f] * Aee_inv[f, e]
            qi -= coef * a[L + e]
            for j in range(L):
                A[i, j] -= coef * A[L + e, j]
        qred[i] = qi
        for j in range(L):
            Mred[i, j] = A[i, j]
    code = CODE_CONVERGED
    iterations = 0
    if L > 0:
        Ml = Mred[:L, :L]
        ql = qred[:L]
        zl = z[:L]
        if L <= direct_solve_max_size:
            code, iterations = enumerative_kernel(Ml, ql, 1 << 24, 1e-12, zl)
        else:
            code, iterations = lemke_kernel(
                Ml, ql, 100 * L + 100, 1e-12, 1e-11, T[:L, : L + 2], basis[:L],
                row_of[: 2 * L + 1], slot_of[: 2 * L + 1], slot_var[: L + 1],
                pivot_row[: L + 2], zl,
            )
    for i in range(L):
        v[i] = z[i]
    for e in range(E):
        acc = 0.0
        for f in range(E):
            rhs = a[L + f]
            for j in range(L):
                rhs += A[L + f, j] * z[j]
            acc -= Aee_inv[e, f] * rhs
        v[L + e] = acc
    return code, iterations


__all__ = [
    "INFO_ACTIVE_CONTACTS",
    "INFO_EQUALITIES",
    "INFO_ITERATIONS",
    "INFO_LCP_SIZE",
    "INFO_SIZE",
    "GAP_TOLERANCE",
    "IDEAL_BRAKE_IMPULSE",
    "INFO_STATUS",
    "StepShortcuts",
    "make_step_kernels",
    "make_workspace",
]
