"""The input screen of a step, shared by ``MoreauJeanStepper.step`` and ``InPlaceStepper``.

``screen_inputs`` runs compiled (inside the in-place step's own compiled call too) and returns a
code; the caller raises ``ValueError(INPUT_PROBLEMS[code])`` for a non-zero one.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mdi_envs._borrowing import REFERENCE_COUNTED
from mdi_envs._types import FloatArray
from mdi_envs.solvers.status import SolverStatus

STATUS_OF_CODE = tuple(SolverStatus)
"""The solve status of each status code a kernel writes into its diagnostics."""

INPUT_PROBLEMS = (
    "",
    "q contains NaN or inf entries",
    "u contains NaN or inf entries",
    "tau contains NaN or inf entries",
    "brake_bound must be >= 0 (0 released, inf ideal), got NaN or < 0",
)
"""The message of each non-zero code of ``screen_inputs``."""


@njit(cache=True, **REFERENCE_COUNTED)
def screen_inputs(q: FloatArray, u: FloatArray, tau: FloatArray, brake: FloatArray) -> int:
    """0 if the step's inputs are valid, else the index of the problem in ``INPUT_PROBLEMS``."""
    for v in q:
        if not np.isfinite(v):
            return 1
    for v in u:
        if not np.isfinite(v):
            return 2
    for v in tau:
        if not np.isfinite(v):
            return 3
    for v in brake:
        if not v >= 0.0:
            return 4
    return 0
