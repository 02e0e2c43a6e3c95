"""Run in a fresh interpreter by ``startup``: ``python -m benchmarks.startup_probe ENTRY ENV_ID``.

Prints one JSON line: the time (``time.time()``) the first step returned and each phase's time.
ENV_ID ``numba-floor``: one trivial cached numba kernel instead (the floor of any numba env).
"""

from __future__ import annotations

import json
import sys
import time

FLOOR = "numba-floor"  # The pseudo id of the numba floor case (see the module docstring).


def main(argv: list[str]) -> None:
    """Create the env of ``argv = [entry, env_id]``, reset, step once, print the JSON line."""
    entry, env_id = argv
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
    main(sys.argv[1:])
