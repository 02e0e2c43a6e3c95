"""Shared steppers for the stepping tests.

The compiled step is built once per model class and process (``mdi_envs.stepping.moreau_jean``
caches the kernels), so steppers with other parameters or time steps are cheap once one stepper
of the class exists. The session fixture below builds (and warms up) one stepper per model, so
that the ~10 s compile of each model is paid once per test session, whichever test runs first.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from mdi_envs.mechanics.models import BlockableManipulator, BouncingBall, SlidingBlock
from mdi_envs.stepping import MoreauJeanStepper

MODELS = (BouncingBall, SlidingBlock, BlockableManipulator)


def _warm(stepper: MoreauJeanStepper) -> MoreauJeanStepper:
    """Compile ``step`` and ``step_batch`` of the stepper's model by calling each once."""
    n, m, k = stepper.num_dofs, stepper.num_inputs, stepper.num_brakes
    stepper.step(np.zeros(n), np.zeros(n), np.zeros(m), np.zeros(k))
    stepper.step_batch(np.zeros((1, n)), np.zeros((1, n)), np.zeros((1, m)), np.zeros((1, k)))
    return stepper


@pytest.fixture(scope="session")
def make_stepper() -> Callable[..., MoreauJeanStepper]:
    """``make_stepper(Model, time_step, **parameters)``: a warmed-up stepper (cached kernels)."""
    warmed: set[type] = set()

    def make(model: type, time_step: float = 1e-3, **parameters: Any) -> MoreauJeanStepper:
        stepper = MoreauJeanStepper(model, model.Parameters(**parameters), time_step)
        if model not in warmed:
            _warm(stepper)
            warmed.add(model)
        return stepper

    return make
