"""Symbolic (CasADi) evaluation of a model's equations, from its single definition.

The optimal-control transcription (``optimal/``) needs M, h, B, g and the contact and brake
directions as CasADi expressions with exact derivatives. They come from the very same static
methods the compiled stepper runs, evaluated with ``ops = casadi`` on ``SX`` symbols. CasADi is
imported here only, lazily: the rest of the package never needs it.
"""

from __future__ import annotations

from typing import Any, NamedTuple

from mdi_envs.mechanics.models.base import ModelDefinition


class SymbolicEquations(NamedTuple):
    """CasADi functions of one model with fixed parameters (shapes as in ``ModelDefinition``).

    Attributes:
        mass: q -> M (n, n). forces: (q, u) -> h (n,). inputs: q -> B (n, m).
        gaps: q -> g (c,). contact_rows: q -> (c*d, n). brake_rows: q -> (k, n).
    """

    mass: Any
    forces: Any
    inputs: Any
    gaps: Any
    contact_rows: Any
    brake_rows: Any


def symbolic_equations(model: type[ModelDefinition], parameters: Any = None) -> SymbolicEquations:
    """Build the CasADi functions of ``model`` with ``parameters`` (default: its defaults).

    Raises:
        ImportError: CasADi is not installed (``pip install 'mdi-envs[optimal]'``).
    """
    try:
        import casadi
    except ImportError as error:  # pragma: no cover - depends on the installed extras
        raise ImportError("symbolic models need CasADi: pip install 'mdi-envs[optimal]'") from error
    chosen = parameters if parameters is not None else model.Parameters()  # type: ignore[attr-defined]
    p = chosen.values()
    n = model.NUM_DOFS
    q = casadi.SX.sym("q", n)
    u = casadi.SX.sym("u", n)

    def matrix(rows: tuple[tuple[Any, ...], ...], num_cols: int) -> Any:
        if len(rows) == 0:
            return casadi.SX(0, num_cols)
        return casadi.vertcat(*[casadi.horzcat(*row) for row in rows])

    def vector(entries: tuple[Any, ...]) -> Any:
        return casadi.vertcat(*entries) if len(entries) else casadi.SX(0, 1)

    return SymbolicEquations(
        mass=casadi.Function("M", [q], [matrix(model.mass_matrix(q, p, casadi), n)]),
        forces=casadi.Function("h", [q, u], [vector(model.forces(q, u, p, casadi))]),
        inputs=casadi.Function(
            "B", [q], [matrix(model.input_matrix(q, p, casadi), model.NUM_INPUTS)]
        ),
        gaps=casadi.Function("g", [q], [vector(model.gaps(q, p, casadi))]),
        contact_rows=casadi.Function(
            "W_contact", [q], [matrix(model.contact_directions(q, p, casadi), n)]
        ),
        brake_rows=casadi.Function(
            "W_brake", [q], [matrix(model.brake_directions(q, p, casadi), n)]
        ),
    )


__all__ = ["SymbolicEquations", "symbolic_equations"]
