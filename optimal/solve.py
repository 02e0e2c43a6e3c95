"""Compute one reference: transcribe, run the continuation, read the solution off, replay it.

``solve_problem(name)`` returns a ``Reference`` (arrays + metadata, see ``optimal.references``)
that ``save_reference`` writes; ``mdi-envs optimize NAME`` does both with progress output.
"""

from __future__ import annotations

import dataclasses
import os
import platform
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from typing import TYPE_CHECKING, Any

from mdi_envs.provenance import git_commit
from optimal.continuation import SCHEDULES, Schedule, solve_continuation
from optimal.problems import make_problem, model_of
from optimal.references import Reference
from optimal.replay import replay
from optimal.solution import read_solution, values_at
from optimal.transcription import OptimalControlProblem, Transcription

if TYPE_CHECKING:
    from optimal.global_search import StartResult

GUESS_TIME_FACTORS = {"manipulator_time": (0.66, 0.88, 1.0, 1.1, 1.32)}
"""Multi-start: the naive guess is repeated with t_f scaled by these factors and the best
converged solution kept (the manipulator's problem has many local optima). Problems not listed
start once."""

SHIPPED_LEVEL_CHANGE = 0.005
"""``search_reference`` ships the coarsest refinement level whose cost changes by less than
this fraction (0.5 %) to the next finer one."""

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
    metadata = _metadata(problem, best["cost"], final_time, best["converged"])
    metadata.update(history=best["history"], residual=best["history"][-1]["residual"],
                    guess_final_time=problem.final_time, starts=starts,
                    solve_time=sum(entry["solve_time"] for entry in starts),
                    total_time=total_time, workers=workers)
    return _verified(Reference(name, arrays, metadata), progress)


def search_reference(
    name: str,
    num_starts: int,
    refine_factors: Sequence[int] = (2, 4),
    num_intervals: int | None = None,
    seed: int = 0,
    workers: int | None = None,
    progress: Callable[[str], None] | None = None,
    show_bar: bool = True,
) -> tuple[Reference, dict[str, Any]]:
    """The best optimum a global search finds, refined, verified by replay.

    Runs ``optimal.global_search.global_search`` (``num_starts`` starts, each continued and
    mode-neighbourhood searched), refines the best to N x ``refine_factors``
    (``optimal.refinement.refine``), and returns the reference at the coarsest level with at
    least the problem's default N (the grid the envs' comparisons use) whose cost changes by
    less than ``SHIPPED_LEVEL_CHANGE`` to the next (the finest level if none does), with the
    search and the refinement in its metadata. A search on a coarser grid than the default
    (``num_intervals``) is cheap, and its refinement factors reach the default.

    Args:
        name: the problem. num_starts: of the search. refine_factors: N multiples to refine
            to (empty: no refinement). num_intervals: N_0. seed: of the random starts.
        workers: processes of the search (default one per core). progress: one line per
            start and level. show_bar: a progress bar over the starts.

    Returns:
        (reference, report): the report holds the search's and the refinement's summaries
        (``GlobalSearch.summary``, ``Refinement.summary``) and the level shipped.
    """
    from optimal.global_search import global_search
    from optimal.refinement import refine

    clock = time.perf_counter()

    def started(result: StartResult) -> None:
        if progress is not None:
            local = "-" if result.best is None else f"{result.best.cost:.6g}"
            progress(f"  {result.start.label}: continuation {result.continuation_cost:.6g}, "
                     f"after the mode search {local} ({result.wall_time:.0f} s)")

    search = global_search(name, num_starts, num_intervals, seed=seed, workers=workers,
                           progress=started, show_bar=show_bar)
    best = search.best.best
    assert best is not None
    schedule = SCHEDULES.get(name) or Schedule()
    refinement = refine(search.problem, best, refine_factors, mu_strategy=schedule.mu_strategy,
                        make=lambda n: make_problem(name, n), progress=progress)
    changes = refinement.relative_changes()
    default_n = make_problem(name).num_intervals
    shipped = next((i for i, change in enumerate(changes)
                    if abs(change) < SHIPPED_LEVEL_CHANGE
                    and refinement.levels[i].problem.num_intervals >= default_n), len(changes))
    level = refinement.levels[shipped]
    problem, solve = level.problem, level.solve
    arrays, final_time = read_solution(*values_at(problem, solve.modes, solve.point))
    report = {"search": search.summary(), "refinement": refinement.summary(),
              "shipped_level": shipped}
    metadata = _metadata(problem, solve.cost, final_time, solve.success and solve.residual <= 1e-8)
    metadata.update(method=metadata["method"] + "; global search: multi-start + mode-"
                    "neighbourhood search (optimal.global_search), mesh refinement",
                    residual=solve.residual, guess_final_time=search.best.start.final_time,
                    total_time=time.perf_counter() - clock, **report)
    return _verified(Reference(name, arrays, metadata), progress), report


def _metadata(problem: OptimalControlProblem, cost: float, final_time: float,
              converged: bool) -> dict[str, Any]:
    """The metadata every reference carries (the solver's own records are added to it)."""
    model, parameters = model_of(problem)
    return {
        "name": problem.name,
        "description": problem.description,
        "env_id": problem.env_id,
        "env_version": ENV_VERSION,
        "env_kwargs": dict(problem.env_kwargs),
        "model": model.NAME,
        "parameters": dataclasses.asdict(parameters),
        "method": "midpoint transcription, penalty/continuation (SUMT) + active-set polish, "
                  "CasADi/IPOPT",
        "cost_kind": problem.cost,
        "cost": cost,
        "final_time": final_time,
        "num_intervals": problem.num_intervals,
        "time_step": final_time / problem.num_intervals,
        "torque_bound": problem.torque_bound,
        "converged": converged,
        "commit": git_commit() or "unknown",
        "casadi": _casadi_version(),
        "python": platform.python_version(),
    }


def _verified(reference: Reference, progress: Callable[[str], None] | None) -> Reference:
    """The reference with its replays at h and h/10 in ``metadata["replay"]``."""
    replays = []
    for substeps in (1, 10):
        report = replay(reference, substeps)[0]
        replays.append(report.as_dict())
        if progress is not None:
            progress(f"  replay at h/{substeps}: final-state error {report.state_error:.2e}, "
                     f"goal errors {_short(report.goal_errors)}, "
                     f"{'reaches' if report.reaches_goal else 'MISSES'} the goal")
    reference.metadata["replay"] = replays
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
    if progress is None and verbose:
        def progress(line: str) -> None:
            print(f"[guess t_f = {problem.final_time:.2f} s] {line}", flush=True)
    transcription = Transcription(problem)
    if progress is not None:
        progress(f"{name}: {problem.description}; N = {problem.num_intervals}, "
                 f"naive guess t_f = {problem.final_time:.3f} s")
    result = solve_continuation(transcription, schedule, progress)
    transcription = result.transcription or transcription
    arrays, final_time = read_solution(transcription, result.values)
    return {
        "factor": factor, "guess_final_time": problem.final_time,
        "cost": float(result.values(transcription.cost)), "converged": result.success,
        "solve_time": sum(r.solve_time for r in result.history),
        "history": [dataclasses.asdict(record) for record in result.history],
        "final_time": final_time, "arrays": arrays,
    }


def _short(errors: dict[str, float]) -> str:
    return ", ".join(f"{key} {value:.1e}" for key, value in errors.items())


def _casadi_version() -> str:
    import casadi

    return str(getattr(casadi, "__version__", "unknown"))


__all__ = ["ENV_VERSION", "SHIPPED_LEVEL_CHANGE", "search_reference", "solve_problem"]
