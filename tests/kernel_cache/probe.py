"""Run in a fresh interpreter by tests/test_kernel_cache.py: step a model, report as JSON.

Usage: ``python probe.py MODEL_FILE [STIFFNESS]``: imports the model class ``Oscillator`` from
MODEL_FILE (a path, as module ``oscillator_model``), steps it 10 times from q = 1, u = 0 with
the single step, the batched step and the in-place step, and prints the final states, the last
status and numba's cache hits and misses of the three kernels (a miss is a compile, a hit a
load from the disk cache).
"""

import importlib.util
import json
import sys

import numpy as np

from mdi_envs.stepping import MoreauJeanStepper
from mdi_envs.stepping.in_place import _KERNELS as in_place_kernels


def main() -> None:
    """Print the probe's JSON line."""
    spec = importlib.util.spec_from_file_location("oscillator_model", sys.argv[1])
    module = importlib.util.module_from_spec(spec)
    sys.modules["oscillator_model"] = module
    spec.loader.exec_module(module)
    parameters = module.OscillatorParameters(*(float(value) for value in sys.argv[2:3]))
    steps = 10
    stepper = MoreauJeanStepper(module.Oscillator, parameters, time_step=0.01)
    q, u = np.array([1.0]), np.array([0.0])
    for _ in range(steps):
        result = stepper.step(q, u, [0.0])
        q, u = result.q, result.u
    Q, U = np.ones((3, 1)), np.zeros((3, 1))
    stepper.step_batch(Q, U, np.zeros((3, 1)), num_substeps=steps)
    in_place = stepper.in_place([1.0], [0.0])
    for _ in range(steps):
        in_place.step()
    kernels = (stepper.compiled_step, stepper.compiled_step_batch[0], *in_place_kernels.values())
    print(json.dumps({
        "q": float(q[0]), "u": float(u[0]), "status": result.status.name,
        "batch_q": Q[:, 0].tolist(), "in_place_q": float(in_place.q[0]),
        "hits": sum(sum(kernel.stats.cache_hits.values()) for kernel in kernels),
        "misses": sum(sum(kernel.stats.cache_misses.values()) for kernel in kernels),
    }))


if __name__ == "__main__":
    main()
