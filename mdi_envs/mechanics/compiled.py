"""Compiled (numba) evaluation of a model's equations, from its single definition.

``compile_equations(Model)`` turns the ops-generic static methods of a ``ModelDefinition`` into
kernels that fill preallocated arrays, with ``ops = math``. The kernels are closures over the
model's jitted equations, so they are compiled once per model class and process.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from numba import njit

from mdi_envs.mechanics.models.base import ModelDefinition


class CompiledEquations(NamedTuple):
    """Array-filling kernels of one model (shapes as in ``ModelDefinition``).

    Each kernel overwrites its last argument: ``mass(q, p, M)``, ``forces(q, u, p, h)``,
    ``inputs(q, p, B)``, ``gaps(q, p, g)``, ``contact_rows(q, p, W)`` with W (c*d, n),
    ``brake_rows(q, p, WB)`` with WB (k, n), ``restitutions(p, eps)``,
    ``friction_coefficients(p, mu)``.
    """

    mass: Any
    forces: Any
    inputs: Any
    gaps: Any
    contact_rows: Any
    brake_rows: Any
    restitutions: Any
    friction_coefficients: Any


_CACHE: dict[type[ModelDefinition], CompiledEquations] = {}


def compile_equations(model: type[ModelDefinition]) -> CompiledEquations:
    """Compiled kernels of ``model`` (built once per class, then reused)."""
    if model not in _CACHE:
        _CACHE[model] = _build(model)
    return _CACHE[model]


def _matrix_filler(equation: Any, rows: int, cols: int, with_velocity: bool = False) -> Any:
    """A kernel writing the (rows, cols) tuple-of-rows returned by ``equation`` into ``out``."""
    if rows == 0 or cols == 0:

        @njit
        def nothing(*args: Any) -> None:
            return None

        return nothing
    jitted = njit(equation)

    @njit
    def fill(q: Any, p: Any, out: Any) -> None:
        values = jitted(q, p, math)
        for i in range(rows):
            row = values[i]
            for j in range(cols):
                out[i, j] = row[j]

    return fill


def _vector_filler(equation: Any, size: int, arguments: str) -> Any:
    """A kernel writing the ``size`` entries returned by ``equation`` into ``out``."""
    if size == 0:

        @njit
        def nothing(*args: Any) -> None:
            return None

        return nothing
    jitted = njit(equation)
    if arguments == "q,u":

        @njit
        def fill_qu(q: Any, u: Any, p: Any, out: Any) -> None:
            values = jitted(q, u, p, math)
            for i in range(size):
                out[i] = values[i]

        return fill_qu
    if arguments == "q":

        @njit
        def fill_q(q: Any, p: Any, out: Any) -> None:
            values = jitted(q, p, math)
            for i in range(size):
                out[i] = values[i]

        return fill_q

    @njit
    def fill_p(p: Any, out: Any) -> None:
        values = jitted(p)
        for i in range(size):
            out[i] = values[i]

    return fill_p


def _build(model: type[ModelDefinition]) -> CompiledEquations:
    n, m = model.NUM_DOFS, model.NUM_INPUTS
    c, d, k = model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
    return CompiledEquations(
        mass=_matrix_filler(model.mass_matrix, n, n),
        forces=_vector_filler(model.forces, n, "q,u"),
        inputs=_matrix_filler(model.input_matrix, n, m),
        gaps=_vector_filler(model.gaps, c, "q"),
        contact_rows=_matrix_filler(model.contact_directions, c * d, n),
        brake_rows=_matrix_filler(model.brake_directions, k, n),
        restitutions=_vector_filler(model.restitutions, c, "p"),
        friction_coefficients=_vector_filler(model.friction_coefficients, c, "p"),
    )


__all__ = ["CompiledEquations", "compile_equations"]
