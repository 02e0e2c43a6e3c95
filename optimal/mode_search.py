"""Fixed-pattern solves and the mode-neighbourhood search.

The penalty/continuation lands in whichever local optimum of the discretized problem its start
and path lead to; its mode sequence (brake schedule, stick-slip pattern) is a by-product. Here
the sequence is the search variable:

* ``solve_with_modes(problem, pattern)``: the NLP with the modes fixed
  (``Transcription(problem, modes=pattern)``), no complementarity left; IPOPT optimizes t_f
  (or the effort) and the continuous trajectory within the pattern. Every converged point is
  feasible for the original problem (one side of every pair is zero, the other nonnegative).
* ``improve_modes(problem, start)``: from a solved pattern, solve every pattern one move away
  (``ModePattern.neighbours``: switches shifted by +-1, +-2 intervals, phases merged or split),
  each warm-started from the current best point, move to the best improvement, and repeat
  until no neighbour improves (best improvement, a local optimum in the mode neighbourhood).

Needs CasADi. Results carry plain arrays only, so that worker processes can return them.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mdi_envs._types import FloatArray
from optimal.continuation import (
    POLISH_BOUND_RELAXATION,
    POLISH_RELAXATION,
    Schedule,
    set_solver,
)
from optimal.modes import ModePattern
from optimal.solution import read_modes
from optimal.transcription import OptimalControlProblem, Transcription

FIXED_PATTERN_MAX_ITERATIONS = 500
"""IPOPT's iteration limit of one fixed-pattern solve (warm-started ones take 10-60)."""

IMPROVEMENT_TOLERANCE = 1e-7
"""A neighbour improves when its cost is below the current one by more than this fraction."""


@dataclass(frozen=True, eq=False)
class ModeSolve:
    """One fixed-pattern solve.

    Attributes:
        modes: the pattern imposed. found_modes: the pattern read off the solution
            (``read_modes``; a brake engaged with zero impulse reads as released
            where the relative velocity is not zero, and so on).
        cost: the problem's cost [s or N^2 m^2 s]. final_time: t_f [s].
        success: IPOPT converged (or to its acceptable level).
        status: IPOPT's return status. iterations: its iteration count.
        solve_time: wall time of the solve [s]; build_time: of building the NLP [s].
        point: (nx,) the NLP's variables at the solution (warm start of the neighbours).
        residual: the natural complementarity residual (scaled; ~0 by construction).
    """

    modes: ModePattern
    found_modes: ModePattern
    cost: float
    final_time: float
    success: bool
    status: str
    iterations: int
    solve_time: float
    build_time: float
    point: FloatArray = field(repr=False)
    residual: float


def solve_with_modes(problem: OptimalControlProblem, modes: ModePattern,
                     initial: FloatArray | None = None,
                     max_iterations: int = FIXED_PATTERN_MAX_ITERATIONS,
                     transcription: Transcription | None = None,
                     mu_strategy: str = "adaptive") -> ModeSolve:
    """Solve ``problem`` with its brake and contact modes fixed to ``modes``.

    Args:
        problem: the problem. modes: the pattern (N intervals, as the problem).
        initial: (nx,) the NLP point to start from (any pattern's solution of the same problem
            and N: the variables are the same); None starts from the naive guess.
        max_iterations: IPOPT's limit.
        transcription: a ``Transcription(problem, modes=modes)`` already built (its solution
            is then readable from it through ``ModeSolve.point``); None builds one.
        mu_strategy: IPOPT's barrier update (``Schedule.mu_strategy``).
    """
    start = time.perf_counter()
    transcription = transcription or Transcription(problem, modes=modes)
    opti = transcription.opti
    set_solver(transcription, Schedule(max_iterations=max_iterations, mu_strategy=mu_strategy),
               POLISH_BOUND_RELAXATION)
    opti.set_value(transcription.rho, 0.0)
    opti.set_value(transcription.relaxation, POLISH_RELAXATION)
    if initial is None:
        transcription.set_naive_guess()
    else:
        opti.set_initial(opti.x, initial)
    built = time.perf_counter()
    values: Callable[[Any], Any]
    try:
        values = opti.solve().value
    except RuntimeError:  # IPOPT did not converge: keep its last iterate
        values = opti.debug.value
    solved = time.perf_counter()
    stats = opti.stats()
    status = str(stats.get("return_status", "unknown"))
    final_time = transcription.final_time
    return ModeSolve(
        modes=modes, found_modes=read_modes(transcription, values),
        cost=float(values(transcription.cost)),
        final_time=final_time if isinstance(final_time, float) else float(values(final_time)),
        success=status in ("Solve_Succeeded", "Solved_To_Acceptable_Level"),
        status=status, iterations=int(stats.get("iter_count", -1)),
        solve_time=solved - built, build_time=built - start,
        point=np.asarray(values(opti.x), dtype=float).ravel(),
        residual=transcription.residuals(values)[0],
    )


@dataclass(frozen=True, eq=False)
class SearchStep:
    """One accepted move of ``improve_modes``: its label and the cost after it."""

    move: str
    cost: float


@dataclass(frozen=True, eq=False)
class LocalSearch:
    """The result of ``improve_modes``.

    Attributes:
        best: the best solve found (a local optimum in the mode neighbourhood, or the start
            when nothing improved). start: the solve the search began from.
        steps: the accepted moves, in order. solves: fixed-pattern solves run.
        failed: of those, the ones IPOPT did not converge on (infeasible or stuck patterns).
        wall_time: [s].
    """

    best: ModeSolve
    start: ModeSolve
    steps: list[SearchStep]
    solves: int
    failed: int
    wall_time: float


def improve_modes(problem: OptimalControlProblem, start: ModeSolve, max_shift: int = 2,
                  max_rounds: int = 50,
                  progress: Callable[[str], None] | None = None) -> LocalSearch:
    """Best-improvement search over the mode neighbourhood of ``start``.

    Each round solves every not yet solved neighbour of the current pattern
    (``ModePattern.neighbours(max_shift)``), warm-started from the current point, and moves
    to the cheapest converged one if it improves the cost by more than
    ``IMPROVEMENT_TOLERANCE``; the search stops when none does or after ``max_rounds``.

    Args:
        problem: the problem. start: a converged solve (e.g. the continuation's optimum
            re-solved with its modes fixed).
        max_shift: the largest switch shift [intervals]. max_rounds: the round limit.
        progress: called with one line per round.
    """
    clock = time.perf_counter()
    best = start
    seen = {start.modes.key()}
    steps: list[SearchStep] = []
    solves = failed = 0
    for round_index in range(max_rounds):
        candidates = [(move, pattern) for move, pattern in best.modes.neighbours(max_shift)
                      if pattern.key() not in seen]
        round_best: tuple[str, ModeSolve] | None = None
        for move, pattern in candidates:
            seen.add(pattern.key())
            solve = solve_with_modes(problem, pattern, initial=best.point)
            solves += 1
            failed += not solve.success
            if solve.success and (round_best is None or solve.cost < round_best[1].cost):
                round_best = (move, solve)
        improved = round_best is not None and (
            round_best[1].cost < best.cost * (1.0 - IMPROVEMENT_TOLERANCE))
        if progress is not None:
            found = "none converged" if round_best is None else (
                f"best neighbour {round_best[1].cost:.6g} ({round_best[0]})")
            progress(f"  round {round_index + 1}: {len(candidates)} neighbours, {found}; "
                     f"{'moved' if improved else 'stop'} at cost "
                     f"{(round_best[1] if improved and round_best else best).cost:.6g}")
        if not improved or round_best is None:
            break
        best = round_best[1]
        steps.append(SearchStep(round_best[0], best.cost))
    return LocalSearch(best=best, start=start, steps=steps, solves=solves, failed=failed,
                       wall_time=time.perf_counter() - clock)


__all__ = [
    "FIXED_PATTERN_MAX_ITERATIONS",
    "IMPROVEMENT_TOLERANCE",
    "LocalSearch",
    "ModeSolve",
    "SearchStep",
    "improve_modes",
    "solve_with_modes",
]
