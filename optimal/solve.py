"""Compute one reference: transcribe, run the continuation, read the solution off, replay it.

``solve_problem(name)`` returns a ``Reference`` (arrays + metadata, see ``optimal.references``)
that ``save_reference`` writes; ``mdi-envs optimize NAME`` does both with progress output.
"""

from __future__ import annotations

import dataclasses
import os
import platform
import subprocess
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import numpy as np

from optimal.continuation import Schedule, solve_continuation
from optimal.problems import make_problem, model_of
from optimal.references import Reference
from optimal.replay import replay
from optimal.transcription import Transcription, numeric

BRAKE_VELOCITY_TOLERANCE = 1e-6
"""A brake counts as engaged over an interval when |W_B u_{k+1}| is below this fraction of the
problem's velocity scale (the polished solution has exact zeros there, ~1e-12). Where the
relative velocity is zero and the brake impulse too, engaged and released give the same step."""

SLIP_TOLERANCE = 1e-6
"""A contact slides over an interval when its slip speed exceeds this fraction of the
problem's velocity scale."""

GUESS_TIME_FACTORS = {"manipulator_time": (0.66, 0.88, 1.0, 1.1, 1.32)}
"""Multi-start: the naive guess is repeated with t_f scaled by these factors and the best
converged solution kept (the manipulator's problem has many local optima). Problems not listed
start once."""

SCHEDULES = {"diff_drive_time": Schedule(mu_strategy="monotone"),
             "diff_drive_effort": Schedule(mu_strategy="monotone")}
"""Per-problem continuation schedules (others: ``Schedule()``). The robot's first stage, from
the naive guess far from complementarity, takes 5-20x fewer IPOPT iterations with the monotone
barrier update."""

ENV_VERSION = 0
"""The ``-vN`` of the environment ids the references are computed for."""


def solve_problem(
    name: str,
    num_intervals: int | None = None,
    schedule: Schedule | None = None,
    progress: Callable[[str], None] | None = None,
    workers: int | None = None,
) -> Reference:
    """Solve the problem ``name`` from its naive guess and verify it by replay.

    Args:
        name: a key of ``optimal.problems.PROBLEMS``. num_intervals: N (default: the
            problem's). schedule: the continuation (default ``Schedule()``).
        progress: called with one line per stage and per replay (e.g. ``print``); the starts
            of a multi-start run in worker processes print their stage lines themselves.
        workers: processes for a multi-start's starts (default: one per core, at most one per
            start; 1 runs them in this process).

    Returns:
        The reference; ``metadata["converged"]`` says whether the last stage succeeded with a
        complementarity residual <= 1e-6.
    """
    base = make_problem(name, num_intervals)
    schedule = schedule or SCHEDULES.get(name)
    model, parameters = model_of(base)
    start = time.perf_counter()
    factors = GUESS_TIME_FACTORS.get(name, (1.0,))
    workers = min(len(factors), os.cpu_count() or 1) if workers is None else int(workers)
    jobs = [(name, num_intervals, schedule, factor, progress is not None) for factor in factors]
    if workers > 1:
        if progress is not None:
            progress(f"{name}: {len(factors)} starts on {workers} processes")
        with ProcessPoolExecutor(workers, mp_context=get_context("fork")) as pool:
            solved = list(pool.map(_solve_start, *zip(*jobs, strict=True)))
    else:
        solved = [_solve_start(*job, progress=progress) for job in jobs]
    converged = [s for s in solved if s["converged"]]
    best = min(converged or solved[-1:], key=lambda s: s["cost"])
    total_time = time.perf_counter() - start
    problem = dataclasses.replace(base, final_time=best["factor"] * base.final_time)
    arrays, final_time = best["arrays"], best["final_time"]
    starts = [{"guess_final_time": s["guess_final_time"], "cost": s["cost"],
               "converged": s["converged"], "solve_time": s["solve_time"]} for s in solved]
    big_n = problem.num_intervals
    metadata: dict[str, Any] = {
        "name": name,
        "description": problem.description,
        "env_id": problem.env_id,
        "env_version": ENV_VERSION,
        "env_kwargs": dict(problem.env_kwargs),
        "model": model.NAME,
        "parameters": dataclasses.asdict(parameters),
        "method": "midpoint transcription, penalty/continuation (SUMT) + active-set polish, "
                  "CasADi/IPOPT",
        "cost_kind": problem.cost,
        "cost": best["cost"],
        "final_time": final_time,
        "num_intervals": big_n,
        "time_step": final_time / big_n,
        "torque_bound": problem.torque_bound,
        "converged": best["converged"],
        "history": best["history"],
        "guess_final_time": problem.final_time,
        "starts": starts,
        "solve_time": sum(entry["solve_time"] for entry in starts),
        "total_time": total_time,
        "workers": workers,
        "commit": _commit(),
        "casadi": _casadi_version(),
        "python": platform.python_version(),
    }
    reference = Reference(name, arrays, metadata)
    replays = []
    for substeps in (1, 10):
        report = replay(reference, substeps)[0]
        replays.append(report.as_dict())
        if progress is not None:
            progress(f"  replay at h/{substeps}: final-state error {report.state_error:.2e}, "
                     f"goal errors {_short(report.goal_errors)}, "
                     f"{'reaches' if report.reaches_goal else 'MISSES'} the goal")
    metadata["replay"] = replays
    return reference


def _solve_start(name: str, num_intervals: int | None, schedule: Schedule | None,
                 factor: float, verbose: bool,
                 progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """One start: the naive guess with t_f scaled by ``factor``, solved and read off.

    Runs in a worker process for multi-starts (so it returns plain arrays, no CasADi
    objects); ``verbose`` prints the stage lines there when no ``progress`` is given.
    """
    problem = make_problem(name, num_intervals)
    problem = dataclasses.replace(problem, final_time=factor * problem.final_time)
    model, _ = model_of(problem)
    if progress is None and verbose:
        def progress(line: str) -> None:
            print(f"[guess t_f = {problem.final_time:.2f} s] {line}", flush=True)
    transcription = Transcription(problem)
    if progress is not None:
        progress(f"{name}: {problem.description}; N = {problem.num_intervals}, "
                 f"naive guess t_f = {problem.final_time:.3f} s")
    result = solve_continuation(transcription, schedule, progress)
    transcription = result.transcription or transcription
    values = result.values
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
    if model.NUM_BRAKES:
        engaged = np.abs(outputs["brake_velocity"]) <= (
            BRAKE_VELOCITY_TOLERANCE * problem.velocity_scale)
        arrays["brake_bound"] = np.where(engaged, np.inf, 0.0)
        arrays["brake_impulse"] = outputs["brake_impulse"]
    if model.NUM_CONTACTS:
        arrays["normal_impulse"] = outputs["normal_impulse"]
    if "slip_speed" in outputs:
        arrays["tangent_impulse"] = outputs["tangent_impulse"]
        arrays["slip_speed"] = outputs["slip_speed"]
        sliding = (outputs["slip_speed"] > SLIP_TOLERANCE * problem.velocity_scale).astype(int)
        arrays["mode"] = np.array([model.slip_mode(row) for row in sliding], dtype=np.int64)
    return {
        "factor": factor, "guess_final_time": problem.final_time,
        "cost": float(values(transcription.cost)), "converged": result.success,
        "solve_time": sum(r.solve_time for r in result.history),
        "history": [dataclasses.asdict(record) for record in result.history],
        "final_time": final_time, "arrays": arrays,
    }


def _short(errors: dict[str, float]) -> str:
    return ", ".join(f"{key} {value:.1e}" for key, value in errors.items())


def _commit() -> str:
    """The repository's HEAD (with "+dirty" for uncommitted changes), or "unknown"."""
    root = Path(__file__).resolve().parent.parent
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain"], cwd=root, capture_output=True,
                               text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+dirty" if dirty else "")


def _casadi_version() -> str:
    import casadi

    return str(getattr(casadi, "__version__", "unknown"))


__all__ = ["BRAKE_VELOCITY_TOLERANCE", "ENV_VERSION", "SLIP_TOLERANCE", "solve_problem"]
