"""Mesh refinement of a solution: the same maneuver on N, 2N, 4N intervals.

A reference is an optimum of the h-discretized problem; whether its t_f (or effort) and switching
times belong to the continuous problem shows only by refining. Per level (factor f):

1. the mode pattern of the previous level, each interval repeated to the finer grid
   (``ModePattern.refined``), solved with the modes fixed from the naive guess with the
   previous t_f (``solve_with_modes``);
2. freed: the continuation's last penalty stage and polish from that point (the modes may move
   by fractions of the coarse step);
3. the mode-neighbourhood search at that level (``improve_modes``, switches +-1, +-2 fine
   intervals).

``Refinement.levels`` lists N, cost, t_f and the phases per level; ``relative_changes`` the
change of the cost from each level to the next, the convergence a reader checks.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from optimal.continuation import Schedule, solve_continuation
from optimal.mode_search import ModeSolve, improve_modes, solve_with_modes
from optimal.solution import read_modes, read_solution, values_at
from optimal.transcription import (
    GUESS_IMPULSES,
    OptimalControlProblem,
    Transcription,
    regridded_impulses,
)

FREEING_SCHEDULE = Schedule(penalties=(1e3,), relaxations=(1e-10,))
"""The continuation's last stage (and its polish), run from the fixed-pattern point."""


@dataclass(frozen=True, eq=False)
class Level:
    """One refinement level.

    Attributes:
        factor: N / N_0. problem: the problem at this N. solve: its best fixed-pattern solve.
        phases: engaged brakes / sliding contacts [s] (``ModePattern.phases``).
        wall_time: [s]. moves: the mode-neighbourhood moves accepted at this level.
    """

    factor: int
    problem: OptimalControlProblem
    solve: ModeSolve
    phases: dict[str, list[tuple[float, float]]]
    wall_time: float
    moves: list[str]

    def summary(self) -> dict[str, Any]:
        """Plain-JSON record."""
        return {"factor": self.factor, "num_intervals": self.problem.num_intervals,
                "cost": self.solve.cost, "final_time": self.solve.final_time,
                "converged": self.solve.success, "phases": self.phases,
                "moves": self.moves, "wall_time": self.wall_time}


@dataclass(frozen=True, eq=False)
class Refinement:
    """All levels, coarsest first."""

    levels: list[Level]

    def relative_changes(self) -> list[float]:
        """(cost_{l+1} - cost_l) / cost_l for consecutive levels."""
        costs = [level.solve.cost for level in self.levels]
        return [(b - a) / a for a, b in zip(costs, costs[1:], strict=False)]

    def summary(self) -> dict[str, Any]:
        """Plain-JSON record (metadata of the shipped reference)."""
        return {"levels": [level.summary() for level in self.levels],
                "relative_changes": self.relative_changes()}


def refine(problem: OptimalControlProblem, solve: ModeSolve, factors: Sequence[int] = (2, 4),
           max_rounds: int = 8, mu_strategy: str = "adaptive",
           make: Callable[[int], OptimalControlProblem] | None = None,
           progress: Callable[[str], None] | None = None) -> Refinement:
    """Refine ``solve`` (a solution of ``problem``) to N x each factor.

    Args:
        problem: the base problem (N_0 intervals). solve: its solution (the base level).
        factors: the refinement factors, increasing (each level starts from the previous).
        max_rounds: of each level's mode-neighbourhood search.
        mu_strategy: IPOPT's barrier update for the fixed-pattern solves from the naive guess.
        make: N -> the problem on N intervals (default: ``problem`` with ``num_intervals``
            replaced).
        progress: called with one line per level.
    """
    def at(num_intervals: int) -> OptimalControlProblem:
        return make(num_intervals) if make is not None else dataclasses.replace(
            problem, num_intervals=num_intervals)

    base_n = problem.num_intervals
    levels = [Level(1, problem, solve, _phases(solve), 0.0, [])]
    for factor in factors:
        clock = time.perf_counter()
        previous = levels[-1]
        fine = dataclasses.replace(at(base_n * factor), final_time=previous.solve.final_time)
        _, best, moves = refine_level(previous.problem, previous.solve, fine, max_rounds,
                                      mu_strategy)
        level = Level(factor, fine, best, _phases(best), time.perf_counter() - clock, moves)
        levels.append(level)
        if progress is not None:
            progress(f"  N = {fine.num_intervals}: cost {best.cost:.6g}, t_f "
                     f"{best.final_time:.5f} s, converged {best.success}, "
                     f"{len(moves)} moves ({level.wall_time:.0f} s)")
    return Refinement(levels)


def refine_level(coarse: OptimalControlProblem, solve: ModeSolve, fine: OptimalControlProblem,
                 max_rounds: int = 8, mu_strategy: str = "adaptive"
                 ) -> tuple[ModeSolve, ModeSolve, list[str]]:
    """Carry ``solve`` (a solution of ``coarse``) to ``fine``, whose N is a multiple of coarse's.

    The pattern refined (each interval repeated), solved with the modes fixed from the
    interpolated trajectory (``interpolated_guess``; IPOPT's barrier update ``mu_strategy``),
    then freed and mode-searched for at most ``max_rounds`` rounds (``settle``).

    Returns:
        (fixed, best, moves): the fixed-pattern solve, the best solve and the moves accepted.
    """
    pattern = solve.modes.refined(fine.num_intervals // coarse.num_intervals)
    guess = Transcription(fine, modes=pattern)
    interpolated_guess(guess, coarse, solve)
    fixed = solve_with_modes(fine, pattern, initial=guess.initial_point(), transcription=guess,
                             mu_strategy=mu_strategy)
    best, moves = settle(fine, fixed, max_rounds)
    return fixed, best, moves


def settle(problem: OptimalControlProblem, fixed: ModeSolve, max_rounds: int = 8
           ) -> tuple[ModeSolve, list[str]]:
    """Free a fixed-pattern solve and search its mode neighbourhood.

    The continuation's last stage and polish from ``fixed`` (``FREEING_SCHEDULE``: the modes
    may move), its optimum re-solved with its modes fixed, then ``improve_modes`` from the
    better of the two; returns the best solve and the moves accepted.
    """
    best = fixed
    transcription = Transcription(problem)
    freed = solve_continuation(transcription, FREEING_SCHEDULE, initial=fixed.point)
    if freed.success:
        solved = freed.transcription or transcription
        point = np.asarray(freed.values(solved.opti.x), dtype=float).ravel()
        again = solve_with_modes(problem, read_modes(solved, freed.values), initial=point)
        if again.success and (not best.success or again.cost < best.cost):
            best = again
    if not best.success:
        return best, []
    local = improve_modes(problem, best, max_rounds=max_rounds)
    return local.best, [step.move for step in local.steps]


def interpolated_guess(fine: Transcription, coarse: OptimalControlProblem,
                       solve: ModeSolve) -> None:
    """Set ``fine``'s initial guess to the trajectory of ``solve``, a solution of ``coarse``.

    ``fine.problem``'s N is an integer multiple of ``coarse``'s: q and u linearly
    interpolated, inputs held, t_f kept; the friction impulses (``GUESS_IMPULSES``) held and
    divided by the refinement ratio, slip speeds held, the other impulses zero, slacks
    consistent (``Transcription.set_guess``). Without the friction, the
    robot's time-optimal refinement from N = 25 to 50 did not converge.
    """
    arrays, final_time = read_solution(*values_at(coarse, solve.modes, solve.point))
    big_n = fine.problem.num_intervals
    ratio = big_n // coarse.num_intervals
    coarse_time = np.linspace(0.0, 1.0, coarse.num_intervals + 1)
    fine_time = np.linspace(0.0, 1.0, big_n + 1)

    def interpolated(values: np.ndarray) -> np.ndarray:
        return np.column_stack([np.interp(fine_time, coarse_time, column)
                                for column in values.T])

    impulses = regridded_impulses({key: arrays[key] for key in GUESS_IMPULSES if key in arrays},
                                  np.repeat(np.arange(coarse.num_intervals), ratio),
                                  1.0 / ratio)
    fine.set_guess(interpolated(arrays["q"]), interpolated(arrays["u"]),
                   np.repeat(arrays["tau"], ratio, axis=0), final_time, impulses)


def _phases(solve: ModeSolve) -> dict[str, list[tuple[float, float]]]:
    grid = np.linspace(0.0, solve.final_time, solve.modes.num_intervals + 1)
    return solve.found_modes.phases(grid)


__all__ = ["FREEING_SCHEDULE", "Level", "Refinement", "interpolated_guess", "refine", "settle"]
