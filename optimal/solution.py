"""Reading a solution of the NLP: its mode pattern and the reference arrays.

``read_modes`` classifies each brake and contact per interval; ``read_solution`` evaluates the
trajectory, inputs, impulses and slips into the arrays of ``optimal.references``;
``values_at`` turns a stored NLP point back into an evaluator.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from optimal.modes import ModePattern
from optimal.transcription import OptimalControlProblem, Transcription, numeric

BRAKE_VELOCITY_TOLERANCE = 1e-6
"""A brake counts as engaged over an interval when |W_B u_{k+1}| is below this fraction of the
problem's velocity scale (the polished solution has exact zeros there, ~1e-12). Where the
relative velocity is zero and the brake impulse too, engaged and released give the same step."""

SLIP_TOLERANCE = 1e-6
"""A contact slides over an interval when its slip speed exceeds this fraction of the
problem's velocity scale."""

def read_solution(transcription: Transcription, values: Callable[[Any], Any]
                  ) -> tuple[dict[str, np.ndarray], float]:
    """The reference arrays (``optimal.references``) and t_f [s] of a solution.

    Args:
        transcription: the NLP solved. values: evaluates its expressions at the solution.
    """
    problem = transcription.problem
    model = problem.model
    final_time = float(values(transcription.final_time)) if problem.cost == "time" else float(
        problem.final_time)
    big_n = problem.num_intervals
    arrays: dict[str, np.ndarray] = {
        "time": np.linspace(0.0, final_time, big_n + 1),
        "q": numeric(values(transcription.q)).reshape(model.NUM_DOFS, big_n + 1).T.copy(),
        "u": numeric(values(transcription.u)).reshape(model.NUM_DOFS, big_n + 1).T.copy(),
        "tau": numeric(values(transcription.tau)).reshape(model.NUM_INPUTS, big_n).T.copy(),
    }
    outputs = {key: numeric(values(expr)).reshape(-1, big_n).T.copy()
               for key, expr in transcription.outputs.items()}
    modes = read_modes(transcription, values)
    if modes.engaged is not None:
        arrays["brake_bound"] = np.where(modes.engaged.T, np.inf, 0.0)
        arrays["brake_impulse"] = outputs["brake_impulse"]
    if model.NUM_CONTACTS:
        arrays["normal_impulse"] = outputs["normal_impulse"]
    if modes.sliding is not None:
        arrays["tangent_impulse"] = outputs["tangent_impulse"]
        arrays["slip_speed"] = outputs["slip_speed"]
        arrays["mode"] = np.array([model.slip_mode(row) for row in modes.sliding.T.astype(int)],
                                  dtype=np.int64)
    return arrays, final_time


def read_modes(transcription: Transcription, values: Callable[[Any], Any]) -> ModePattern:
    """The mode pattern of a solution.

    Brakes are engaged where |W_B u_{k+1}| is below ``BRAKE_VELOCITY_TOLERANCE``, contacts
    slide where the slip speed exceeds ``SLIP_TOLERANCE`` (both in units of the problem's
    velocity scale).
    """
    problem = transcription.problem
    outputs = transcription.outputs
    scale = problem.velocity_scale
    engaged = sliding = None
    if "brake_velocity" in outputs:
        velocity = _rows(outputs["brake_velocity"], values)
        engaged = np.abs(velocity) <= BRAKE_VELOCITY_TOLERANCE * scale
    if "slip_speed" in outputs:
        sliding = _rows(outputs["slip_speed"], values) > SLIP_TOLERANCE * scale
    return ModePattern(engaged=engaged, sliding=sliding)


def _rows(expression: Any, values: Callable[[Any], Any]) -> np.ndarray:
    """The value of a (rows, N) expression with its shape (CasADi drops unit dimensions)."""
    return numeric(values(expression)).reshape(expression.shape)


def values_at(problem: OptimalControlProblem, modes: ModePattern | None,
              point: np.ndarray, transcription: Transcription | None = None
              ) -> tuple[Transcription, Callable[[Any], Any]]:
    """(transcription, evaluator) of the NLP point ``point`` (nx,) of ``problem``.

    The transcription (built with ``modes``, None: free, unless one of ``problem`` is given)
    evaluates its expressions at the point (e.g.
    ``read_solution(*values_at(problem, solve.modes, solve.point))``).
    """
    transcription = transcription or Transcription(problem, modes=modes)
    opti = transcription.opti
    opti.set_initial(opti.x, point)

    def values(expression: Any) -> Any:
        return opti.value(expression, opti.initial())

    return transcription, values


__all__ = ["BRAKE_VELOCITY_TOLERANCE", "SLIP_TOLERANCE", "read_modes", "read_solution",
           "values_at"]
