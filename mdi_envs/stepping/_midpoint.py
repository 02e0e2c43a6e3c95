"""The model's equations at the step's midpoint, compiled as straight-line code.

The smooth part of the Moreau-Jean step (``make_free_motion``) and the active set's rows
(``make_midpoint_rows``) are evaluated on tuples (registers): the model's equations return
tuples, and with every intermediate a local value the compiler evaluates shared subexpressions
once (the manipulator's sin(beta - alpha) enters h five times: once for h, four times for the
central differences of dh/du) and keeps the small matrix algebra in registers. Results go to
fixed offsets of one flat scratch buffer, written once, never through array views: each view
costs reference counting on every step. The source is
generated per model (sizes and flags are compile-time constants), like
``_kernel._make_carver``. The manipulator's free step in-kernel: ``python -m benchmarks.engine
--output /tmp/bench --quick``, scene "released".
"""

from __future__ import annotations

import math
from typing import Any

from numba import njit

from mdi_envs._kernel_cache import define
from mdi_envs._views import array_view
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.solvers._linalg import invert_into

RESOLVED_INERTIA_FRACTION = 0.9
"""A step counts as resolved while the symmetric part of M_theta = M - dt/2 J exceeds this
fraction of M: the linearized velocity forces change the inertia by less than 10 % in every
direction (the manipulator from rest at dt = 0.01 s: up to 30-50 rad/s on both joints in
opposite senses, i.e. 0.6-1 rad of relative rotation per step)."""

SINGULAR_PIVOT = 1e-14
"""Relative pivot (against max |M_theta|, or its square for a 2 x 2 determinant) below which the
iteration matrix counts as singular, as in ``invert_into``."""

# Outcomes of the smooth part of a step.
MOTION_RESOLVED = 0  # M_theta = M - dt/2 J used
MOTION_UNDER_RESOLVED = 1  # dt too coarse for the linearization: status INACCURATE
MOTION_SINGULAR = 2  # the iteration matrix could not be inverted: status BREAKDOWN


def free_motion_shapes(n: int, m: int) -> dict[str, tuple[int, ...]]:
    """The scratch arrays ``free_motion`` writes, in buffer order, for n coordinates, m inputs.

    Every workspace that serves ``free_motion`` starts with these (offsets from 0).
    """
    return {"qm": (n,), "M": (n, n), "Minv": (n, n), "h": (n,), "B": (n, m), "ufree": (n,),
            "Mwork": (n, n), "col": (n,)}


def offsets_of(shapes: dict[str, tuple[int, ...]]) -> tuple[dict[str, int], int]:
    """Offset of each array of ``shapes`` laid out one after another, and the total size."""
    offsets: dict[str, int] = {}
    total = 0
    for name, shape in shapes.items():
        offsets[name] = total
        size = 1
        for extent in shape:
            size *= extent
        total += size
    return offsets, total


def _tuple(entries: list[str]) -> str:
    return "(" + ", ".join(entries) + ",)"


class _Flat:
    """Flat-buffer addressing of the named arrays (generated source text)."""

    def __init__(self, buffer: str, shapes: dict[str, tuple[int, ...]]) -> None:
        self.buffer = buffer
        self.shapes = shapes
        self.offsets, _ = offsets_of(shapes)

    def __call__(self, name: str, *index: int) -> str:
        shape = self.shapes[name]
        flat = 0
        for i, extent in zip(index, shape, strict=True):
            flat = flat * extent + i
        return f"{self.buffer}[{self.offsets[name] + flat}]"

    def view(self, name: str) -> str:
        shape = self.shapes[name]
        return f"array_view({self.buffer}, {self.offsets[name]}, {shape!r})"


def _free_motion_source(n: int, m: int, velocity_forces: bool, reuse_mass: bool) -> str:
    """Python source of ``free_motion`` for n coordinates and m inputs (see its docstring)."""
    at = _Flat("buffer", free_motion_shapes(n, m))
    lines = [
        "def free_motion(q, u, tau, dt, p, buffer, mass_ready):",
        "    q_m = " + _tuple([f"q[{i}] + 0.5 * dt * u[{i}]" for i in range(n)]),
        "    u_k = " + _tuple([f"u[{i}]" for i in range(n)]),
        "    h_k = forces(q_m, u_k, p, math)",
        "    B_k = inputs(q_m, p, math)",
    ]
    for i in range(n):
        drive = "".join(f" + B_k[{i}][{j}] * tau[{j}]" for j in range(m))
        lines.append(f"    f{i} = (h_k[{i}]{drive}) * dt")
        lines.append(f"    {at('qm', i)} = q_m[{i}]")
        lines.append(f"    {at('h', i)} = h_k[{i}]")
        lines.extend(f"    {at('B', i, j)} = B_k[{i}][{j}]" for j in range(m))
    lines.append("    motion = MOTION_RESOLVED")
    body = "    "
    if reuse_mass:
        lines.append("    if mass_ready[0] != 1:")
        body = "        "
    block = [
        "M_k = mass(q_m, p, math)",
    ]
    if velocity_forces:
        for j in range(n):
            for sign, name in ((" + 1.0", "hp"), (" - 1.0", "hm")):
                probe = _tuple([f"u[{i}]{sign}" if i == j else f"u[{i}]" for i in range(n)])
                block.append(f"{name}{j} = forces(q_m, {probe}, p, math)")
    for i in range(n):
        for j in range(n):
            theta = f" - 0.25 * dt * (hp{j}[{i}] - hm{j}[{i}])" if velocity_forces else ""
            block.append(f"a{i}_{j} = M_k[{i}][{j}]{theta}")
            block.append(f"{at('M', i, j)} = a{i}_{j}")
    if velocity_forces:
        # Cholesky-free dominance test: LDL^T of sym(A) - fraction M, every pivot d_j > 0.
        for i in range(n):
            for j in range(i + 1):
                block.append(f"s{i}_{j} = 0.5 * (a{i}_{j} + a{j}_{i}) - "
                             f"RESOLVED_INERTIA_FRACTION * M_k[{i}][{j}]")
        for j in range(n):
            block.append(f"d{j} = s{j}_{j}" + "".join(
                f" - l{j}_{t} * l{j}_{t} * d{t}" for t in range(j)))
            for r in range(j + 1, n):
                block.append(f"l{r}_{j} = (s{r}_{j}" + "".join(
                    f" - l{r}_{t} * l{j}_{t} * d{t}" for t in range(j)) + f") / d{j}")
        block.append("if not (" + " and ".join(f"d{j} > 0.0" for j in range(n)) + "):")
        block.append("    motion = MOTION_UNDER_RESOLVED")
    block.append("scale = max(" + ", ".join(
        f"abs(a{i}_{j})" for i in range(n) for j in range(n)) + ", 0.0)")
    if n == 2:
        # The adjugate over the determinant, as ``invert_into`` does for 2 x 2.
        block.extend([
            "det = a0_0 * a1_1 - a0_1 * a1_0",
            "if abs(det) > SINGULAR_PIVOT * scale * scale:",
            "    inv = 1.0 / det",
            f"    {at('Minv', 0, 0)} = a1_1 * inv",
            f"    {at('Minv', 0, 1)} = -a0_1 * inv",
            f"    {at('Minv', 1, 0)} = -a1_0 * inv",
            f"    {at('Minv', 1, 1)} = a0_0 * inv",
            "    pivoted = True",
            "else:",
            "    pivoted = False",
        ])
    else:
        # Gauss-Jordan without row exchanges on [A | I]; when a pivot is too small (sym(A)
        # indefinite), the pivoting LU of ``invert_into`` below decides.
        names = {(i, j): f"a{i}_{j}" for i in range(n) for j in range(n)}
        names.update({(i, n + j): ("1.0" if i == j else "0.0")
                      for i in range(n) for j in range(n)})
        block.append("pivoted = True")
        for k in range(n):
            pivot = names[(k, k)]
            block.append(f"pivoted = pivoted and abs({pivot}) > SINGULAR_PIVOT * scale")
            block.append(f"r{k} = 1.0 / {pivot} if pivoted else 0.0")
            for j in range(k + 1, 2 * n):
                block.append(f"g{k}_{k}_{j} = {names[(k, j)]} * r{k}")
            for i in range(n):
                if i == k:
                    continue
                for j in range(k + 1, 2 * n):
                    block.append(f"g{k}_{i}_{j} = {names[(i, j)]} - {names[(i, k)]} * "
                                 f"g{k}_{k}_{j}")
            for i in range(n):
                for j in range(k + 1, 2 * n):
                    names[(i, j)] = f"g{k}_{i}_{j}"
        block.append("if pivoted:")
        block.extend(f"    {at('Minv', i, j)} = {names[(i, n + j)]}"
                     for i in range(n) for j in range(n))
    block.extend([
        f"if not pivoted and not invert_into({at.view('M')}, {at.view('Minv')}, "
        f"{at.view('Mwork')}, {at.view('col')}):",
        "    motion = MOTION_SINGULAR",
        "mass_ready[0] = 0 if motion == MOTION_SINGULAR else 1",
    ])
    lines.extend(body + line for line in block)
    for i in range(n):
        lines.append(f"    {at('ufree', i)} = u_k[{i}]" + "".join(
            f" + {at('Minv', i, j)} * f{j}" for j in range(n)))
    lines.append("    return motion")
    return "\n".join(lines)


def make_free_motion(model: type[ModelDefinition], reuse_constant_mass: bool) -> Any:
    """Compile the smooth part of the step shared by the planar and the spatial kernels.

    ``free_motion(q, u, tau, dt, p, buffer, mass_ready)`` writes, at the offsets of
    ``free_motion_shapes`` in the flat float64 ``buffer``: q_M = q + dt/2 u (n,),
    h(q_M, u) (n,), B(q_M) (n, m) and u_free = u + M_theta^-1 (h + B tau) dt (n,), where the
    iteration matrix M_theta = M(q_M) - theta dt dh/du(q_M, u) with theta = 1/2 (M_theta = M
    when h does not depend on u) goes into ``M`` (n, n) and its inverse into ``Minv``; ``Mwork``
    and ``col`` are scratch. M^-1 is kept across steps when the model's mass is constant, h
    independent of u and ``reuse_constant_mass`` on (int64 ``mass_ready[0] == 1`` once
    computed). Returns ``MOTION_RESOLVED``;
    ``MOTION_UNDER_RESOLVED`` when the step is too coarse for the linearization (the symmetric
    part of M_theta does not exceed 0.9 M: dt |u| is no longer small against the configuration
    scale, e.g. an arm turning about a radian per step; the step is still taken with M_theta,
    and reports ``INACCURATE``: dropping J there diverges to inf, while M_theta
    near singular can multiply the energy); ``MOTION_SINGULAR`` if the matrix cannot be
    inverted.

    The theta term makes velocity-dependent forces linearly implicit (the theta-method of
    Siconos' MoreauJeanOSI): the step then solves M(q_M)(u+ - u) = (h + theta J (u+ - u) + B tau)
    dt + W P, with J = dh/du, which for the quadratic Coriolis/centrifugal forces of a Lagrangian
    model is h evaluated bilinearly in u and u+. The explicit form (theta = 0) pumps energy and
    angular momentum into a spinning manipulator (+89 % energy over 50 s at dt = 0.01 s); this
    form keeps the drift at O(dt^2) (4e-5). J's columns are the exact central differences
    (h(u + e_j) - h(u - e_j)) / 2 of a function at most quadratic in u.
    """
    velocity_forces = model.HAS_VELOCITY_FORCES
    reuse_mass = reuse_constant_mass and model.HAS_CONSTANT_MASS and not velocity_forces
    source = _free_motion_source(model.NUM_DOFS, model.NUM_INPUTS, velocity_forces, reuse_mass)
    namespace: dict[str, Any] = {
        "array_view": array_view,
        "math": math,
        "forces": njit(model.forces),
        "inputs": njit(model.input_matrix),
        "mass": njit(model.mass_matrix),
        "invert_into": invert_into,
        "MOTION_RESOLVED": MOTION_RESOLVED,
        "MOTION_UNDER_RESOLVED": MOTION_UNDER_RESOLVED,
        "MOTION_SINGULAR": MOTION_SINGULAR,
        "RESOLVED_INERTIA_FRACTION": RESOLVED_INERTIA_FRACTION,
        "SINGULAR_PIVOT": SINGULAR_PIVOT,
    }
    define(source, namespace)
    return njit(inline="always", error_model="numpy")(namespace["free_motion"])


def make_midpoint_rows(model: type[ModelDefinition],
                       shapes: dict[str, tuple[int, ...]]) -> Any:
    """Compile ``midpoint_rows(p, buffer)``: the active set's data at q_M, into ``buffer``.

    Reads q_M (``qm``) from the flat float64 ``buffer`` laid out as ``shapes`` and writes the
    gaps ``g`` (c,), contact rows ``Wc`` (c*d, n), brake rows ``Wb`` (k, n), restitutions
    ``eps`` (c,) and friction coefficients ``mu`` (c,) at their offsets.
    """
    n, c, d, k = model.NUM_DOFS, model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
    at = _Flat("buffer", shapes)
    lines = ["def midpoint_rows(p, buffer):",
             "    q_m = " + _tuple([at("qm", i) for i in range(n)])]
    if c > 0:
        lines += ["    g_k = gaps(q_m, p, math)", "    W_k = contact_rows(q_m, p, math)",
                  "    eps_k = restitutions(p)", "    mu_k = friction_coefficients(p)"]
        for i in range(c):
            lines += [f"    {at('g', i)} = g_k[{i}]", f"    {at('eps', i)} = eps_k[{i}]",
                      f"    {at('mu', i)} = mu_k[{i}]"]
        lines += [f"    {at('Wc', r, j)} = W_k[{r}][{j}]" for r in range(c * d)
                  for j in range(n)]
    if k > 0:
        lines.append("    Wb_k = brake_rows(q_m, p, math)")
        lines += [f"    {at('Wb', b, j)} = Wb_k[{b}][{j}]" for b in range(k) for j in range(n)]
    lines.append("    return None")
    namespace: dict[str, Any] = {
        "math": math,
        "gaps": njit(model.gaps),
        "contact_rows": njit(model.contact_directions),
        "restitutions": njit(model.restitutions),
        "friction_coefficients": njit(model.friction_coefficients),
        "brake_rows": njit(model.brake_directions),
    }
    define("\n".join(lines), namespace)
    return njit(inline="always")(namespace["midpoint_rows"])


__all__ = [
    "MOTION_RESOLVED",
    "MOTION_SINGULAR",
    "MOTION_UNDER_RESOLVED",
    "RESOLVED_INERTIA_FRACTION",
    "free_motion_shapes",
    "make_free_motion",
    "make_midpoint_rows",
    "offsets_of",
]
