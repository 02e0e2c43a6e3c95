"""Run in a fresh interpreter by ``before_after``: ``python -m benchmarks.in_place_probe MODEL``.

Prints the minimum and median µs per ``InPlaceStepper.step()`` over 300 batches of 200 steps.
"""

from __future__ import annotations

import sys
import timeit

import numpy as np

from mdi_envs.mechanics import BlockableManipulator, DiffDriveRobot
from mdi_envs.stepping import MoreauJeanStepper

SCENES = {"manipulator": (BlockableManipulator, 1e-3, (0.1,)),
          "diff_drive": (DiffDriveRobot, 1e-2, (1.0, 0.4))}


def main(model_name: str) -> None:
    """Print ``min median`` [µs per step] of the scene's in-place step."""
    model, time_step, torques = SCENES[model_name]
    stepper = MoreauJeanStepper(model, time_step=time_step).in_place(
        np.zeros(model.NUM_DOFS), np.zeros(model.NUM_DOFS))
    stepper.tau[:] = torques
    step = stepper.step
    for _ in range(1000):
        step()
    batches = timeit.repeat(step, setup="gc.enable()", number=200, repeat=300)  # [s] each
    per_step = sorted(seconds / 200 * 1e6 for seconds in batches)
    print(f"{per_step[0]:.6f} {per_step[len(per_step) // 2]:.6f}")


if __name__ == "__main__":
    main(sys.argv[1])
