"""The compiled Moreau-Jean midpoint step for one model, and its batched form.

This is the one place where impulses and complementarity variables are mapped to each other
(solvers speak ``M, q, z, w``; mechanics speaks mass matrix and coordinates). Notation of
DESIGN.md section 2, per step of length dt:

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

from mdi_envs.mechanics.compiled import CompiledEquations
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.solvers._linalg import dominates, invert_into
from mdi_envs.solvers.lcp.enumerative import enumerative_kernel
from mdi_envs.solvers.lcp.lemke import lemke_kernel
from mdi_envs.solvers.status import CODE_BREAKDOWN, CODE_CONVERGED, CODE_INACCURATE

GAP_TOLERANCE = 1e-12
"""[m] A contact counts as closed at the midpoint when g_i(q_M) <= this: a body resting on a
surface keeps gaps of rounding size (~1e-21 m), which must not open the contact for a step."""

IDEAL_BRAKE_IMPULSE = 1e6
"""[N s or N m s] A brake whose impulse bound a dt reaches this acts as the ideal brake
(equality row). The Tresca rows carry P_B = P_R - a dt, which loses all precision when a dt is
many orders above P_B; no brake of these models needs impulses anywhere near this bound."""

RESOLVED_INERTIA_FRACTION = 0.9
"""A step counts as resolved while the symmetric part of M_theta = M - dt/2 J exceeds this
fraction of M: the linearized velocity forces change the inertia by less than 10 % in every
direction (the manipulator from rest at dt = 0.01 s: up to 30-50 rad/s on both joints in
opposite senses, i.e. 0.6-1 rad of relative rotation per step)."""

# Outcomes of the smooth part of a step (``make_free_motion``).
MOTION_RESOLVED = 0  # M_theta = M - dt/2 J used
MOTION_UNDER_RESOLVED = 1  # dt too coarse for the linearization: status INACCURATE
MOTION_SINGULAR = 2  # the iteration matrix could not be inverted: status BREAKDOWN

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
    """

    skip_frictionless_rows: bool = True
    reuse_constant_mass: bool = True
    direct_solve_max_size: int = 3


Layout = dict[str, tuple[int, tuple[int, ...]]]


def _workspace_layout(model: type[ModelDefinition]) -> tuple[Layout, int, Layout, int]:
    """Offsets and shapes of the step's scratch arrays inside one float and one int buffer."""
    n, m = model.NUM_DOFS, model.NUM_INPUTS
    c, d, k = model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
    rows = c * d + k
    lcp = 3 * c + 2 * k  # LCP variables: 3 per contact, 2 per Tresca brake
    size = lcp + k  # plus the ideal-brake equalities
    float_shapes: dict[str, tuple[int, ...]] = {
        "qm": (n,), "M": (n, n), "Minv": (n, n), "h": (n,), "B": (n, m), "ufree": (n,),
        "g": (c,), "Wc": (c * d, n), "Wb": (k, n), "eps": (c,), "mu": (c,), "Wr": (rows, n),
        "MinvWt": (n, rows), "G": (rows, rows), "gfree": (rows,), "gpre": (rows,),
        "S": (rows, size), "s0": (rows,), "A": (size, size), "a": (size,),
        "Mred": (lcp, lcp), "qred": (lcp,), "z": (lcp,), "T": (lcp, lcp + 2),
        "pivot_row": (lcp + 2,), "Aee": (k, k), "Aee_inv": (k, k), "lu_work": (k, k),
        "lu_col": (k,), "v": (size,), "P": (rows,), "Mwork": (n, n), "col": (n,),
        "row_eps": (rows,),
        # the impact-locating step (``locate_impacts``): gaps at t_k, the state at the
        # impact, and one part's impulses and diagnostics
        "g0": (c,), "q_hit": (n,), "u_hit": (n,), "part_impulses": (rows,),
        "part_info": (INFO_SIZE,),
    }
    int_shapes: dict[str, tuple[int, ...]] = {
        "basis": (lcp,), "row_of": (2 * lcp + 1,), "slot_of": (2 * lcp + 1,),
        "slot_var": (lcp + 1,), "row_ref": (rows,), "row_var": (rows,),
        "mass_ready": (1,),
    }

    def offsets(shapes: dict[str, tuple[int, ...]]) -> tuple[Layout, int]:
        layout: Layout = {}
        total = 0
        for name, shape in shapes.items():
            layout[name] = (total, shape)
            total += int(np.prod(shape))
        return layout, total

    float_layout, float_total = offsets(float_shapes)
    int_layout, int_total = offsets(int_shapes)
    return float_layout, float_total, int_layout, int_total


def make_workspace(model: type[ModelDefinition]) -> tuple[np.ndarray, np.ndarray]:
    """Scratch buffers of ``step`` for ``model`` (one float64, one int64), reused across steps.

    Two flat buffers keep the compiled call cheap to dispatch from Python (numba types every
    element of a tuple argument on each call); the step carves its arrays out of them once per
    call, also for a whole batch.
    """
    _, float_total, _, int_total = _workspace_layout(model)
    return np.empty(max(float_total, 1)), np.zeros(max(int_total, 1), np.int64)


def _make_carver(layout: Layout) -> Any:
    """A compiled function returning the views of ``layout`` into a flat buffer, in order.

    Its source is generated so that every offset and shape is a compile-time constant.
    """
    lines = ["def carve(buffer):"]
    for name, (offset, shape) in layout.items():
        size = int(np.prod(shape))
        lines.append(f"    {name} = buffer[{offset}:{offset + size}].reshape({shape!r})")
    lines.append(f"    return ({', '.join(layout)},)")
    namespace: dict[str, Any] = {}
    exec("\n".join(lines), namespace)  # noqa: S102 - generated from the layout's constants
    return njit(namespace["carve"])


def make_free_motion(
    model: type[ModelDefinition], eq: CompiledEquations, shortcuts: StepShortcuts
) -> Any:
    """Compile the smooth part of the step shared by the planar and the spatial kernels.

    ``free_motion(q, u, tau, dt, p, qm, M, Minv, h, B, ufree, Mwork, col, mass_ready)`` writes
    q_M = q + dt/2 u and u_free = u + M_theta^-1 (h(q_M, u) + B tau) dt, where the iteration
    matrix M_theta = M(q_M) - theta dt dh/du(q_M, u) with theta = 1/2 (M_theta = M when h does
    not depend on u), into ``M`` and its inverse into ``Minv``. All arrays are modified in place;
    M^-1 is kept across steps when the model's mass is constant, h independent of u and the
    shortcut on. Returns ``MOTION_RESOLVED``; ``MOTION_UNDER_RESOLVED`` when the step is too
    coarse for the linearization (the symmetric part of M_theta does not exceed 0.9 M: dt |u|
    is no longer small against the configuration scale, e.g. an arm turning about a radian per
    step; the step is still taken with M_theta, and reports ``INACCURATE``: dropping J there
    was tried and diverges to inf, while M_theta near singular can multiply the energy);
    ``MOTION_SINGULAR`` if the matrix cannot be inverted.

    The theta term makes velocity-dependent forces linearly implicit (the theta-method of
    Siconos' MoreauJeanOSI): the step then solves M(q_M)(u+ - u) = (h + theta J (u+ - u) + B tau)
    dt + W P, with J = dh/du, which for the quadratic Coriolis/centrifugal forces of a Lagrangian
    model is h evaluated bilinearly in u and u+. The explicit form (theta = 0) pumps energy and
    angular momentum into a spinning manipulator (+89 % energy over 50 s at dt = 0.01 s); this
    form keeps the drift at O(dt^2) (4e-5). J's columns are the exact central differences
    (h(u + e_j) - h(u - e_j)) / 2 of a function at most quadratic in u.
    """
    n, num_inputs = model.NUM_DOFS, model.NUM_INPUTS
    mass, forces, inputs = eq.mass, eq.forces, eq.inputs
    velocity_forces = model.HAS_VELOCITY_FORCES
    reuse_mass = (shortcuts.reuse_constant_mass and model.HAS_CONSTANT_MASS
                  and not velocity_forces)

    @njit(inline="always")
    def free_motion(q, u, tau, dt, p, qm, M, Minv, h, B, ufree, Mwork, col,  # noqa: ANN001
                    mass_ready):
        for i in range(n):
            qm[i] = q[i] + 0.5 * dt * u[i]
        forces(qm, u, p, h)
        inputs(qm, p, B)
        motion = MOTION_RESOLVED
        if not (reuse_mass and mass_ready[0] == 1):
            mass(qm, p, M)
            if velocity_forces:
                # M -= theta dt J with theta = 1/2; M(q_M) kept in Minv until the inversion,
                # probes in ufree, col and Mwork[0].
                for i in range(n):
                    for j in range(n):
                        Minv[i, j] = M[i, j]
                for j in range(n):
                    for i in range(n):
                        ufree[i] = u[i]
                    ufree[j] = u[j] + 1.0
                    forces(qm, ufree, p, col)
                    ufree[j] = u[j] - 1.0
                    forces(qm, ufree, p, Mwork[0])
                    for i in range(n):
                        M[i, j] -= 0.25 * dt * (col[i] - Mwork[0, i])
                if not dominates(M, Minv, RESOLVED_INERTIA_FRACTION, Mwork):
                    motion = MOTION_UNDER_RESOLVED
            if not invert_into(M, Minv, Mwork, col):
                motion = MOTION_SINGULAR
            mass_ready[0] = 0 if motion == MOTION_SINGULAR else 1
        for i in range(n):
            f = h[i]
            for j in range(num_inputs):
                f += B[i, j] * tau[j]
            col[i] = f * dt
        for i in range(n):
            acc = u[i]
            for j in range(n):
                acc += Minv[i, j] * col[j]
            ufree[i] = acc
        return motion

    return free_motion


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
    contact_rows, brake_rows = eq.contact_rows, eq.brake_rows
    restitutions, friction_coefficients = eq.restitutions, eq.friction_coefficients
    keep_frictionless_rows = not shortcuts.skip_frictionless_rows
    free_motion = make_free_motion(model, eq, shortcuts)
    direct_solve_max_size = shortcuts.direct_solve_max_size
    float_layout, _, int_layout, _ = _workspace_layout(model)
    carve_floats = _make_carver(float_layout)
    carve_ints = _make_carver(int_layout)

    @njit(inline="always")
    def advance(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info, fs, js):  # noqa: ANN001
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
            fs, js: the float and int scratch views carved from ``make_workspace``'s buffers.
        """
        (qm, M, Minv, h, B, ufree, g, Wc, Wb, eps, mu, Wr, MinvWt, G, gfree, gpre, S, s0,
         A, a, Mred, qred, z, T, pivot_row, Aee, Aee_inv, lu_work, lu_col, v, P, Mwork,
         col, row_eps, _, _, _, _, _) = fs
        basis, row_of, slot_of, slot_var, row_ref, row_var, mass_ready = js
        motion = free_motion(q, u, tau, dt, p, qm, M, Minv, h, B, ufree, Mwork, col, mass_ready)
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
        gaps(qm, p, g)
        contact_rows(qm, p, Wc)
        brake_rows(qm, p, Wb)
        restitutions(p, eps)
        friction_coefficients(p, mu)
        num_rows = 0
        num_x = 0
        num_eq = 0
        num_active = 0
        for i in range(c):
            if g[i] <= GAP_TOLERANCE:
                num_active += 1
                num_rows += 2 if mu[i] > 0.0 or keep_frictionless_rows else 1
                num_x += 3 if mu[i] > 0.0 or keep_frictionless_rows else 1
        for j in range(k):
            if brake_bound[j] > 0.0:
                num_rows += 1
                if brake_bound[j] * dt >= IDEAL_BRAKE_IMPULSE:
                    num_eq += 1
                else:
                    num_x += 2
        info[INFO_ACTIVE_CONTACTS] = num_active
        if num_rows == 0 or not ok:
            for i in range(n):
                u_out[i] = ufree[i]
                q_out[i] = qm[i] + 0.5 * dt * u_out[i]
            return

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

    @njit
    def located_advance(q, u, tau, brake_bound, dt, p, q_out, u_out,  # noqa: ANN001
                        impulses, info, fs, js):
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
        Wc, ufree = fs[7], fs[5]
        g0, q_hit, u_hit, part_impulses, part_info = fs[-5], fs[-4], fs[-3], fs[-2], fs[-1]
        advance(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info, fs, js)
        gaps(q, p, g0)
        hit = dt
        for i in range(c):
            if g0[i] <= GAP_TOLERANCE:
                continue
            gamma0 = 0.0
            gamma_free = 0.0
            for j in range(n):
                gamma0 += Wc[i * d, j] * u[j]
                gamma_free += Wc[i * d, j] * ufree[j]
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
                    part_info, fs, js)
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

    @njit
    def step(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info, ws):  # noqa: ANN001
        """One step (arguments as ``advance``; ws = ``make_workspace(model)``)."""
        step_once(q, u, tau, brake_bound, dt, p, q_out, u_out, impulses, info,
                  carve_floats(ws[0]), carve_ints(ws[1]))

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
        num_copies = Q.shape[0]
        fs = carve_floats(ws[0])
        js = carve_ints(ws[1])
        q_next = np.empty(n)
        u_next = np.empty(n)
        for e in range(num_copies):
            worst = 0.0
            for _ in range(num_substeps):
                step_once(Q[e], U[e], TAU[e], BRAKE[e], dt, p, q_next, u_next, IMPULSES[e],
                          INFO[e], fs, js)
                for j in range(n):
                    Q[e, j] = q_next[j]
                    U[e, j] = u_next[j]
                if INFO[e, INFO_STATUS] > worst:
                    worst = INFO[e, INFO_STATUS]
            INFO[e, INFO_STATUS] = worst

    return step, step_batch


@njit(cache=True)
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


@njit(cache=True)
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


@njit(cache=True)
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
    "make_free_motion",
    "make_step_kernels",
    "make_workspace",
]
