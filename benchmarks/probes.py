"""Probes run in a fresh interpreter, each printing one line: ``python -m benchmarks.probes NAME``.

* ``first-call``: JSON of the import times and the first and second call times [s] of the LCP
  entries (``solvers``).
* ``in-place MODEL``: ``min median`` µs per ``InPlaceStepper.step()`` over 300 batches of 200
  steps (``before_after``).
* ``startup ENTRY ENV_ID``: JSON of the time (``time.time()``) the first env step returned and
  each phase's time [s] (``startup``); ENV_ID ``numba-floor``: one trivial cached numba kernel
  instead (the floor of any numba env).
"""

from __future__ import annotations

import json
import sys
import time

FLOOR = "numba-floor"  # The pseudo id of the numba floor case (see the module docstring).


def first_call() -> None:
    """Print the import and first-call report of the LCP entries as JSON."""
    import importlib
    from functools import partial

    from benchmarks.timing import timed_call

    import_times = {name: timed_call(partial(importlib.import_module, name))[1]
                    for name in ("mdi_envs.solvers.lcp", "quantecon.optimize")}
    from benchmarks import problems as entries

    problem = entries.random_problem("spd", 5, 0)
    probes = [entries.KERNEL, *map(entries.driver_entry, entries.LCP_METHODS), entries.QUANTECON]
    first, second = [{e.name: timed_call(partial(e.solve, problem.M, problem.q))[1]
                      for e in probes} for _ in range(2)]
    print(json.dumps({"import_s": import_times, "first_call_s": first, "second_call_s": second}))


def in_place(model_name: str) -> None:
    """Print ``min median`` [µs per step] of the scene's in-place step."""
    import timeit

    import numpy as np

    from mdi_envs.mechanics import BlockableManipulator, DiffDriveRobot
    from mdi_envs.stepping import MoreauJeanStepper

    model, time_step, torques = {"manipulator": (BlockableManipulator, 1e-3, (0.1,)),
                                 "diff_drive": (DiffDriveRobot, 1e-2, (1.0, 0.4))}[model_name]
    stepper = MoreauJeanStepper(model, time_step=time_step).in_place(
        np.zeros(model.NUM_DOFS), np.zeros(model.NUM_DOFS))
    stepper.tau[:] = torques
    step = stepper.step
    for _ in range(1000):
        step()
    batches = timeit.repeat(step, setup="gc.enable()", number=200, repeat=300)  # [s] each
    per_step = sorted(seconds / 200 * 1e6 for seconds in batches)
    print(f"{per_step[0]:.6f} {per_step[len(per_step) // 2]:.6f}")


def startup(entry: str, env_id: str) -> None:
    """Create the env of ``env_id`` through ``entry``, reset, step once, print the JSON line."""
    phases: dict[str, float] = {}
    began = time.perf_counter()
    import gymnasium as gym
    import numpy as np

    if env_id.startswith("mdi_envs/"):
        import mdi_envs  # noqa: F401 - registers the ids
    if env_id == FLOOR:
        from benchmarks._numba_floor import first_sum

        phases["import"] = time.perf_counter() - began
        first_sum(np.ones(3))
        phases["make_reset"] = time.perf_counter() - began - phases["import"]
        phases["step"] = 0.0
        print(json.dumps({"done": time.time(), "phases": phases}), flush=True)
        return
    phases["import"] = time.perf_counter() - began
    if entry in ("single", "vector"):
        env = gym.make(env_id) if entry == "single" else gym.make_vec(env_id, num_envs=64)
        env.reset(seed=0)
        phases["make_reset"] = time.perf_counter() - began - phases["import"]
        env.step(env.action_space.sample())
    elif entry == "subproc":
        from stable_baselines3.common.env_util import make_vec_env
        from stable_baselines3.common.vec_env import SubprocVecEnv

        # the workers import the package from the id's "module:" prefix (Gymnasium's form)
        module = env_id.split("/")[0] + ":" if "/" in env_id else ""
        env = make_vec_env(module + env_id, n_envs=2, seed=0, vec_env_cls=SubprocVecEnv)
        env.reset()
        phases["make_reset"] = time.perf_counter() - began - phases["import"]
        env.step(np.stack([env.action_space.sample() for _ in range(2)]))
    else:
        raise SystemExit(f"unknown entry {entry!r}: single, vector or subproc")
    done = time.time()
    phases["step"] = time.perf_counter() - began - phases["import"] - phases["make_reset"]
    print(json.dumps({"done": done, "phases": phases}), flush=True)
    env.close()


if __name__ == "__main__":
    {"first-call": first_call, "in-place": in_place, "startup": startup}[sys.argv[1]](
        *sys.argv[2:])
