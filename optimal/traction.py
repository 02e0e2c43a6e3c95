"""On-line estimate of the friction factor (times the model's) that explains measured steps.

``FrictionEstimator`` replays every measured step (q, u, tau) -> u' with the simulator's own
step (``MoreauJeanStepper``), the model's parameters with every friction coefficient (the fields
named ``*_friction``) scaled by a factor, and measures a weighted squared velocity error summed
over the last ``WINDOW`` steps. The estimate (1 at first: the model) stays while its error is
within ``TOLERANCE`` per step of the smallest over a grid of factors ``FACTORS``: while every
contact sticks, friction does not enter the steps and every factor fits equally. Otherwise the
grid's best factor (of those within the tolerance, the nearest the estimate) is refined by a
bounded scalar minimization within one grid step, and taken if it reproduces the window to
``FIT_TOLERANCE`` per step: a slipping contact's impulse is mu times its normal impulse, which
singles out its factor, while a mismatch of another parameter (a mass) fits no factor once the
robot turns (both chassis velocities measured; along a straight line one factor can fit it)
and leaves the estimate where it is.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from mdi_envs._types import FloatArray
from mdi_envs.stepping import MoreauJeanStepper

FACTORS = np.round(np.arange(0.5, 1.5001, 0.025), 3)
"""The candidate friction factors [-]: 0.5 to 1.5 of the model's coefficients."""

WINDOW = 5
"""Measured steps whose errors are summed."""

TOLERANCE = 1e-6
"""[-] a factor fits as well as the best when its error exceeds the smallest by at most this
per step (weighted units: squared velocity error over the squared tolerance of the weights)."""

FIT_TOLERANCE = 1e-8
"""[-] a refined factor is taken when its error is at most this per step (the simulator's own
step reproduces a measured one to about 1e-12; 10 % more mass than the model: 1e-6 to 1e-2)."""


def scaled_friction(parameters: Any, factor: float) -> Any:
    """``parameters`` (a dataclass) with every ``*_friction`` field times ``factor``."""
    names = [f.name for f in dataclasses.fields(parameters) if f.name.endswith("_friction")]
    if not names:
        raise ValueError(f"{type(parameters).__name__} has no *_friction field")
    return dataclasses.replace(parameters, **{name: factor * getattr(parameters, name)
                                              for name in names})


class FrictionEstimator:
    """The friction factor consistent with the last measured steps (see the module docstring).

    Args:
        model: the model class. parameters: its nominal parameters. time_step: the measured
            steps' dt [s]. weight: (n,) weight of each velocity's squared error.

    Attributes:
        factor: the current estimate [-] (1.0 until a step rules it out).
    """

    def __init__(self, model: Any, parameters: Any, time_step: float,
                 weight: FloatArray) -> None:
        self._model, self._parameters, self._time_step = model, parameters, float(time_step)
        self._steppers = [self._stepper(float(f)) for f in FACTORS]
        self._weight = np.asarray(weight, dtype=float)
        self._steps: deque[tuple[FloatArray, FloatArray, FloatArray, FloatArray]] = deque(
            maxlen=WINDOW)
        self._errors: deque[FloatArray | None] = deque(maxlen=WINDOW)
        self.factor = 1.0

    def reset(self) -> None:
        """A new episode: no measured step, the estimate 1."""
        self._steps.clear()
        self._errors.clear()
        self.factor = 1.0

    def update(self, q: FloatArray, u: FloatArray, tau: FloatArray, u_next: FloatArray) -> float:
        """The estimate after a measured step: (q, u) under ``tau`` to velocities ``u_next``.

        The grid's errors of a step are computed when first needed: while the estimate's own
        error is within the tolerance of zero, no factor's is smaller by more.
        """
        self._steps.append((q, u, tau, u_next))
        self._errors.append(None)
        steps, error = len(self._steps), self.window_error(self.factor)
        if error <= TOLERANCE * steps:
            return self.factor
        for i, step in enumerate(self._steps):
            if self._errors[i] is None:
                self._errors[i] = np.array([self._error(stepper, *step)
                                            for stepper in self._steppers])
        grid = np.sum(self._errors, axis=0)
        best = grid.min() + TOLERANCE * steps
        if error <= best:
            return self.factor
        candidates = FACTORS[grid <= best]
        center = float(candidates[np.argmin(np.abs(candidates - self.factor))])
        spacing = float(FACTORS[1] - FACTORS[0])
        bounds = (max(center - spacing, FACTORS[0]), min(center + spacing, FACTORS[-1]))
        refined = minimize_scalar(self.window_error, bounds=bounds, method="bounded",
                                  options={"xatol": 1e-6})
        if refined.fun <= FIT_TOLERANCE * steps:
            self.factor = float(refined.x)
        return self.factor

    def window_error(self, factor: float) -> float:
        """The weighted squared velocity error of ``factor`` summed over the window's steps."""
        stepper = self._stepper(factor)
        return float(sum(self._error(stepper, *step) for step in self._steps))

    def _stepper(self, factor: float) -> MoreauJeanStepper:
        return MoreauJeanStepper(self._model, scaled_friction(self._parameters, factor),
                                 self._time_step)

    def _error(self, stepper: MoreauJeanStepper, q: FloatArray, u: FloatArray, tau: FloatArray,
               u_next: FloatArray) -> float:
        return float(np.square(stepper.step(q, u, tau).u - u_next) @ self._weight)


__all__ = ["FACTORS", "FIT_TOLERANCE", "TOLERANCE", "WINDOW", "FrictionEstimator",
           "scaled_friction"]
