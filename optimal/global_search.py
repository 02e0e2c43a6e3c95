"""Global search for a reference: many starts, each continued and then mode-neighbourhood searched.

One start = (label, t_f guess, an optional mode pattern, an optional bend of the naive guess).
The pattern, when given, is solved first with its modes fixed
(``optimal.mode_search.solve_with_modes``, from the start's guess) and, if that converges, its
optimum starts the penalty/continuation; otherwise the continuation starts from the start's
guess (the naive one, bent by ``bump``). The continuation's optimum is re-solved with its
modes fixed and then improved by ``improve_modes`` (switches shifted by +-1, +-2 intervals,
phases merged or split). The starts:

* ``naive guess``: the problem's own guess, as ``mdi-envs optimize`` solves it;
* ``paper schedule`` (manipulator): the brake schedule of the paper's Fig. 3 (engaged 0-0.41,
  1.07-1.84, 2.39-4.53 s of 4.53 s), scaled to the t_f guess;
* ``random i``: t_f guess drawn uniformly in ``RANDOM_TIME_FACTORS`` x the problem's guess
  (time-optimal problems) and a random pattern: per brake or contact row, 0 to
  ``RANDOM_MAX_PHASES`` phases of the non-default mode (engaged; sliding) at random places and
  lengths; where the problem has a ``guess_bend_scale`` (the robot), the guess bent by a
  half sine of amplitude uniform in +-scale per coordinate (another path through the plane).

Starts run in worker processes (``workers``), with a progress bar; each returns plain data.
``GlobalSearch`` keeps every start's continuation optimum and local optimum, the best, and the
running best against the number of starts (does the search saturate?).
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from multiprocessing import get_context
from typing import Any

import numpy as np

from optimal.continuation import SCHEDULES, Schedule, solve_continuation
from optimal.mode_search import LocalSearch, ModeSolve, improve_modes, solve_with_modes
from optimal.modes import ModePattern
from optimal.problems import make_problem
from optimal.solution import read_modes
from optimal.transcription import OptimalControlProblem, Transcription

PAPER_BRAKE_SCHEDULE = ((0.0, 0.41), (1.07, 1.84), (2.39, 4.53))
"""[s] The paper's engaged phases (Fig. 3) of its 4.53 s maneuver."""
PAPER_FINAL_TIME = 4.53
"""[s] The paper's t_f."""

RANDOM_TIME_FACTORS = (0.66, 1.5)
"""Range of the random starts' t_f guess, in units of the problem's guess."""
RANDOM_MAX_PHASES = 3
"""Most phases of the non-default mode per row in a random start pattern."""


@dataclass(frozen=True, eq=False)
class Start:
    """One start of the global search.

    Attributes:
        label: "naive guess", "paper schedule" or "random i".
        final_time: the t_f guess [s] (the fixed t_f of effort problems).
        modes: the pattern solved first with modes fixed, or None (naive guess only).
        bump: (n,) the bend of the naive guess (``Transcription.set_naive_guess``), or None.
    """

    label: str
    final_time: float
    modes: ModePattern | None = None
    bump: tuple[float, ...] | None = None


@dataclass(frozen=True, eq=False)
class StartResult:
    """What one start found.

    Attributes:
        start: the start. pattern_converged: its pattern's fixed solve converged (and started
            the continuation); False also without a pattern. continuation_cost: the cost
            where the continuation ended (nan if it did not converge). continuation_success:
            it converged.
        local: the mode-neighbourhood search from the continuation's optimum (None when the
            continuation's optimum could not be re-solved with its modes fixed).
        wall_time: [s] of the whole start.
    """

    start: Start
    pattern_converged: bool
    continuation_cost: float
    continuation_success: bool
    local: LocalSearch | None
    wall_time: float

    @property
    def best(self) -> ModeSolve | None:
        """The start's best converged solve."""
        return None if self.local is None else self.local.best

    def summary(self) -> dict[str, Any]:
        """Plain-JSON record (costs, moves, solves, times)."""
        local = self.local
        return {
            "label": self.start.label, "guess_final_time": self.start.final_time,
            "guess_bend": self.start.bump, "pattern_converged": self.pattern_converged,
            "continuation_cost": self.continuation_cost,
            "continuation_converged": self.continuation_success,
            "local_cost": None if local is None else local.best.cost,
            "moves": [] if local is None else [dataclasses.asdict(s) for s in local.steps],
            "solves": 0 if local is None else local.solves,
            "failed_solves": 0 if local is None else local.failed,
            "wall_time": self.wall_time,
        }


@dataclass(frozen=True, eq=False)
class GlobalSearch:
    """All starts of one search, in completion order, and the best.

    Attributes:
        problem: the problem searched. results: one per start. wall_time: [s].
        workers: processes used.
    """

    problem: OptimalControlProblem
    results: list[StartResult] = field(repr=False)
    wall_time: float
    workers: int

    @property
    def best(self) -> StartResult:
        """The start whose local optimum is cheapest."""
        solved = [r for r in self.results if r.best is not None]
        if not solved:
            raise RuntimeError(f"no start of the {self.problem.name} search converged")
        return min(solved, key=lambda r: r.best.cost)  # type: ignore[union-attr]

    def running_best(self) -> list[float]:
        """The best cost after 1, 2, ... starts (in completion order; nan before the first)."""
        costs = [np.inf if r.best is None else r.best.cost for r in self.results]
        running = np.minimum.accumulate(costs).tolist()
        return [float("nan") if np.isinf(c) else float(c) for c in running]

    def distinct_optima(self, relative: float = 1e-6) -> list[float]:
        """The distinct local-optimum costs found, ascending (equal within ``relative``)."""
        costs = sorted(r.best.cost for r in self.results if r.best is not None)
        distinct: list[float] = []
        for cost in costs:
            if not distinct or cost > distinct[-1] * (1.0 + relative):
                distinct.append(cost)
        return distinct

    def summary(self) -> dict[str, Any]:
        """Plain-JSON record of the search (metadata of the shipped reference)."""
        best = self.best
        return {
            "starts": len(self.results),
            "solves": sum(r.summary()["solves"] for r in self.results),
            "wall_time": self.wall_time,
            "workers": self.workers,
            "best_start": best.start.label,
            "distinct_optima": self.distinct_optima()[:10],
            "running_best": self.running_best(),
            "per_start": [r.summary() for r in self.results],
        }


def make_starts(problem: OptimalControlProblem, count: int, seed: int = 0) -> list[Start]:
    """``count`` starts: the naive guess, the paper's schedule (manipulator), random ones.

    Args:
        problem: the problem (its ``final_time`` is the naive guess's t_f).
        count: the number of starts (>= 1). seed: of the random starts.
    """
    if count < 1:
        raise ValueError(f"count must be at least 1, got {count}")
    starts = [Start("naive guess", problem.final_time)]
    big_n = problem.num_intervals
    if problem.model.NUM_BRAKES and problem.cost == "time":
        grid = np.linspace(0.0, PAPER_FINAL_TIME, big_n + 1)
        midpoints = (grid[:-1] + grid[1:]) / 2
        engaged = np.zeros((problem.model.NUM_BRAKES, big_n), dtype=bool)
        for begin, end in PAPER_BRAKE_SCHEDULE:
            engaged[:, (midpoints >= begin) & (midpoints < end)] = True
        starts.append(Start("paper schedule", problem.final_time, ModePattern(engaged=engaged)))
    rng = np.random.default_rng(seed)
    for index in range(count - len(starts)):
        factor = rng.uniform(*RANDOM_TIME_FACTORS) if problem.cost == "time" else 1.0
        pattern = _random_pattern(problem, rng)
        scale = np.asarray(problem.guess_bend_scale, dtype=float)
        bump = tuple(rng.uniform(-scale, scale).tolist()) if scale.size else None
        starts.append(Start(f"random {index}", factor * problem.final_time, pattern, bump))
    return starts[:count]


def _random_pattern(problem: OptimalControlProblem, rng: np.random.Generator) -> ModePattern:
    big_n = problem.num_intervals

    def rows(count: int) -> np.ndarray | None:
        if not count:
            return None
        pattern = np.zeros((count, big_n), dtype=bool)
        for row in pattern:
            for _ in range(rng.integers(0, RANDOM_MAX_PHASES + 1)):
                begin = int(rng.integers(0, big_n))
                row[begin:begin + int(rng.integers(1, big_n // 3 + 1))] = True
        return pattern

    model = problem.model
    return ModePattern(engaged=rows(model.NUM_BRAKES),
                       sliding=rows(model.NUM_CONTACTS if model.HAS_LOAD_TRANSFER else 0))


def run_start(problem: OptimalControlProblem, start: Start, schedule: Schedule | None = None,
              max_shift: int = 2) -> StartResult:
    """One start (see the module docstring); runs in a worker process."""
    clock = time.perf_counter()
    problem = dataclasses.replace(problem, final_time=start.final_time)
    transcription = Transcription(problem)
    transcription.set_naive_guess(None if start.bump is None else np.asarray(start.bump))
    initial = transcription.initial_point()
    pattern_converged = False
    if start.modes is not None:
        fixed = solve_with_modes(problem, start.modes, initial=initial)
        pattern_converged = fixed.success
        if fixed.success:
            initial = fixed.point
    result = solve_continuation(transcription, schedule, initial=initial)
    solved = result.transcription or transcription
    cost = float(result.values(solved.cost)) if result.success else float("nan")
    local = None
    if result.success:
        point = np.asarray(result.values(solved.opti.x), dtype=float).ravel()
        first = solve_with_modes(problem, read_modes(solved, result.values), initial=point)
        if first.success:
            local = improve_modes(problem, first, max_shift=max_shift)
    return StartResult(start=start, pattern_converged=pattern_converged, continuation_cost=cost,
                       continuation_success=result.success, local=local,
                       wall_time=time.perf_counter() - clock)


def global_search(name: str, num_starts: int, num_intervals: int | None = None,
                  schedule: Schedule | None = None, seed: int = 0,
                  workers: int | None = None, max_shift: int = 2,
                  starts: Sequence[Start] | None = None,
                  progress: Callable[[StartResult], None] | None = None,
                  show_bar: bool = True) -> GlobalSearch:
    """Run ``num_starts`` starts of problem ``name`` and collect them.

    Args:
        name: the problem. num_starts: how many (``make_starts``). num_intervals: N.
        schedule: the continuation's (default: the problem's in ``SCHEDULES``, else
            ``Schedule()``).
        seed: of the random starts. workers: processes (default: one per core; 1 runs in this
            process). max_shift: of the switch moves. starts: explicit starts instead.
        progress: called with each finished start. show_bar: a tqdm bar over the starts.
    """
    from tqdm import tqdm

    problem = make_problem(name, num_intervals)
    schedule = schedule or SCHEDULES.get(name)
    starts = list(starts) if starts is not None else make_starts(problem, num_starts, seed)
    workers = min(len(starts), os.cpu_count() or 1) if workers is None else int(workers)
    clock = time.perf_counter()
    results: list[StartResult] = []
    bar = tqdm(total=len(starts), desc=f"{name} starts", disable=not show_bar)

    def collect(result: StartResult) -> None:
        results.append(result)
        bar.update()
        best = min((r.best.cost for r in results if r.best is not None), default=float("nan"))
        bar.set_postfix(best=f"{best:.5g}")
        if progress is not None:
            progress(result)

    if workers > 1:
        with ProcessPoolExecutor(workers, mp_context=get_context("fork")) as pool:
            futures = [pool.submit(run_start, problem, start, schedule, max_shift)
                       for start in starts]
            for future in as_completed(futures):
                collect(future.result())
    else:
        for start in starts:
            collect(run_start(problem, start, schedule, max_shift))
    bar.close()
    return GlobalSearch(problem=problem, results=results,
                        wall_time=time.perf_counter() - clock, workers=workers)


__all__ = [
    "PAPER_BRAKE_SCHEDULE",
    "PAPER_FINAL_TIME",
    "RANDOM_MAX_PHASES",
    "RANDOM_TIME_FACTORS",
    "GlobalSearch",
    "Start",
    "StartResult",
    "global_search",
    "make_starts",
    "run_start",
]
