"""Mesh refinement toward the continuous-time optimum, and the manipulator's continuous optimum.

``polish_reference(name)`` polishes a shipped reference's brake and torque schedule in
continuous time (``optimal.polish``), from its own times and from variants of its end (the last
brake phase as an instant lock at t_f, or engaged up to t_f), and keeps the best;
``optimal/continuous/NAME.json`` holds it (the robots' continuous optima are
``optimal.phase_collocation``'s, in the same directory). ``solve_level`` solves the h-discrete
problem on N intervals on the continuous optimum's branch: its mode sequence on the grid
(``pattern_on_grid`` for a schedule, so a lock at t_f is the last interval engaged;
``phases_on_grid`` for stick-slip phases, the last interval the stop at rest), fixed, then
mode-searched for at most a round limit. Levels are independent, so a study is resumable:

    python -m optimal.convergence manipulator_time --levels 30,60,120,240,480

appends each level to ``optimal/continuous/NAME_refinement.json`` when it is done (levels in
the file are skipped) and redraws ``NAME_refinement.png``: N, the cost, the distance to the
continuous-time optimum and the observed order log2(d_N / d_2N). ``--chain`` makes the levels
the refinement chain from the shipped reference instead (``chain_levels``: each level refined
from the one before and freed by the continuation), solved in order and replacing the study's.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from collections.abc import Callable, Iterator
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from mdi_envs.stepping.event_driven import EventDrivenIntegrator
from optimal.mode_search import (
    FIXED_PATTERN_MAX_ITERATIONS,
    ModeSolve,
    improve_modes,
    solve_with_modes,
)
from optimal.modes import ModePattern
from optimal.polish import (
    ATOL,
    RTOL,
    SwitchingSchedule,
    pattern_on_grid,
    polish,
    schedule_from_reference,
    simulate_schedule,
)
from optimal.problems import make_problem, model_of
from optimal.references import load_reference
from optimal.refinement import interpolated_guess, refine_level
from optimal.transcription import (
    GUESS_IMPULSES,
    OptimalControlProblem,
    Transcription,
    regridded_impulses,
)

CONTINUOUS_DIR = Path(__file__).parent / "continuous"
"""Where the continuous-time optima and the refinement studies are stored."""

Start = Callable[[int], tuple[OptimalControlProblem, ModePattern, Transcription]]
"""N -> (problem, mode pattern, initial guess) on N intervals: where a level starts."""


def end_variants(schedule: SwitchingSchedule) -> dict[str, SwitchingSchedule]:
    """``schedule`` and two variants of its last brake phase (same starting times otherwise).

    "lock at t_f": the phases after the first replaced by one instant at t_f; "engaged to
    t_f": by one phase from the last one's start to t_f. Empty for schedules without brakes.
    """
    variants = {"as found": schedule}
    if not schedule.phases or not schedule.phases[0]:
        return variants
    t_f = schedule.final_time
    first, last = schedule.phases[0][0], schedule.phases[0][-1]
    for label, end in (("lock at t_f", (t_f, t_f)), ("engaged to t_f", (last[0], t_f))):
        phases = (first, end) if len(schedule.phases[0]) > 1 else (end,)
        variants[label] = dataclasses.replace(schedule, phases=(phases, *schedule.phases[1:]))
    return variants


def polish_reference(name: str, directory: Path = CONTINUOUS_DIR) -> dict[str, Any]:
    """Polish the shipped reference ``name`` from each ``end_variants`` start; write the JSON.

    Returns:
        The record written: the best polish (``PolishResult.as_dict``), every start's t_f and
        success, and the h-discrete optimum with the relative difference.
    """
    reference = load_reference(name)
    problem = make_problem(name)
    results = {label: polish(problem, start)
               for label, start in end_variants(schedule_from_reference(reference)).items()}
    converged = {label: r for label, r in results.items() if r.success} or results
    label, best = min(converged.items(), key=lambda item: item[1].schedule.final_time)
    record = {"name": name, "best_start": label, **best.as_dict(),
              "starts": {key: {"final_time": r.schedule.final_time, "success": r.success,
                               "goal_error": r.goal_error} for key, r in results.items()},
              "discrete_cost": reference.cost, "discrete_num_intervals":
              reference.metadata["num_intervals"],
              "relative_difference": best.schedule.final_time / reference.cost - 1.0}
    directory.mkdir(parents=True, exist_ok=True)
    (directory / f"{name}.json").write_text(json.dumps(record, indent=1) + "\n")
    return record


def solve_level(start: Start, num_intervals: int, max_rounds: int = 8,
                warm: tuple[OptimalControlProblem, ModeSolve] | None = None,
                max_iterations: int = FIXED_PATTERN_MAX_ITERATIONS
                ) -> tuple[dict[str, Any], OptimalControlProblem, ModeSolve]:
    """The h-discrete optimum on N intervals on one branch.

    ``start(N)`` gives the problem, the mode pattern on the grid and the initial guess
    (``schedule_start`` from a polished switching schedule, ``phase_start`` from a continuous
    optimum's stick-slip phases). The pattern is solved with the modes fixed, then
    mode-searched (``improve_modes``, switches +-1, +-2 intervals per move) for at most
    ``max_rounds`` rounds: the h-discrete optimum on that branch. (Freed by the continuation
    instead, as ``optimal.refinement.refine`` does, a coarse grid moves to another branch.)

    Args:
        warm: (problem, solve) of a coarser level whose N divides this one: its trajectory
            (``interpolated_guess``) replaces the start's as the initial guess (same pattern);
            the start's guess again if IPOPT does not converge from it.
        max_iterations: IPOPT's limit in the fixed-pattern solves of the start.

    Returns:
        A plain-JSON record: N, cost, t_f, converged, the fixed pattern's cost, whether the
        fixed solve's modes read back as imposed (``kept_pattern``; a sliding interval with
        zero slip reads as sticking), the phases [s], the moves of the mode search and its
        round limit (0: the pattern as projected, an upper bound of the branch's optimum),
        wall time [s]; then the problem and the best solve.
    """
    clock = time.perf_counter()
    problem, pattern, guess = start(num_intervals)
    start = guess.initial_point()
    if warm is not None:
        interpolated_guess(guess, *warm)
    fixed = solve_with_modes(problem, pattern, initial=guess.initial_point(),
                             max_iterations=max_iterations, transcription=guess)
    if warm is not None and not fixed.success:
        fixed = solve_with_modes(problem, pattern, initial=start, max_iterations=max_iterations,
                                 transcription=guess)
    local = improve_modes(problem, fixed, max_rounds=max_rounds)
    best = local.best
    record = _level_record(fixed, best, [step.move for step in local.steps], max_rounds, clock)
    return record, problem, best


def reference_solve(name: str) -> tuple[OptimalControlProblem, ModeSolve]:
    """The shipped reference ``name`` solved on its own grid with its own mode pattern fixed.

    The pattern: a brake engaged where the reference's brake bound is infinite, a contact
    sliding where its slip speed is positive; the initial guess is the reference itself, so
    the solve reproduces its cost.
    """
    reference = load_reference(name)
    arrays = reference.arrays
    problem = dataclasses.replace(make_problem(name, reference.tau.shape[0]),
                                  final_time=reference.final_time)
    pattern = ModePattern(
        engaged=np.isinf(arrays["brake_bound"]).T.copy() if "brake_bound" in arrays else None,
        sliding=(arrays["slip_speed"] > 0.0).T.copy() if "slip_speed" in arrays else None)
    guess = Transcription(problem, modes=pattern)
    guess.set_guess(reference.q, reference.u, reference.tau, reference.final_time,
                    {key: arrays[key] for key in GUESS_IMPULSES if key in arrays})
    return problem, solve_with_modes(problem, pattern, initial=guess.initial_point(),
                                     transcription=guess)


def chain_levels(name: str, levels: list[int], max_rounds: int = 0
                 ) -> Iterator[dict[str, Any]]:
    """The levels of the refinement chain from the shipped reference, coarsest first.

    The first level is the reference re-solved (``reference_solve``; its N must divide the
    first level's); each level after it is the one before carried to its N and freed by the
    continuation (``optimal.refinement.refine_level``), so its switches may move by fractions
    of an interval, then mode-searched for at most ``max_rounds`` rounds. Yields one record
    per level (as ``solve_level``'s) as soon as it is solved; a level that does not converge
    ends the chain.

    Raises:
        ValueError: a level's N is not a multiple of the one before (or of the reference's).
    """
    clock = time.perf_counter()
    problem, solve = reference_solve(name)
    for n in sorted(levels):
        if n % problem.num_intervals:
            raise ValueError(f"{name}: level N = {n} is not a multiple of "
                             f"N = {problem.num_intervals} before it in the chain")
        if n == problem.num_intervals:
            fixed, moves = solve, []
        else:
            fine = dataclasses.replace(make_problem(name, n), final_time=solve.final_time)
            fixed, solve, moves = refine_level(problem, solve, fine, max_rounds)
            problem = fine
        yield {**_level_record(fixed, solve, moves, max_rounds, clock),
               "start": "reference chain"}
        if not solve.success:
            return
        clock = time.perf_counter()


def _level_record(fixed: ModeSolve, best: ModeSolve, moves: list[str], max_rounds: int,
                  clock: float) -> dict[str, Any]:
    """A level's plain-JSON record (``solve_level``'s Returns); ``clock`` its start time."""
    num_intervals = best.modes.num_intervals
    phases = best.found_modes.phases(np.linspace(0.0, best.final_time, num_intervals + 1))
    return {"num_intervals": num_intervals, "cost": best.cost, "final_time": best.final_time,
            "converged": best.success, "start_cost": fixed.cost,
            "kept_pattern": fixed.found_modes.key() == fixed.modes.key(), "phases": phases,
            "moves": moves, "max_rounds": max_rounds,
            "wall_time": time.perf_counter() - clock}


def schedule_start(name: str, schedule: SwitchingSchedule, num_intervals: int
                   ) -> tuple[OptimalControlProblem, ModePattern, Transcription]:
    """(problem, pattern, guess) on N intervals from a continuous-time ``schedule``.

    The pattern is ``pattern_on_grid``; the guess the schedule's event-driven run sampled on
    the grid with t_f = the schedule's.
    """
    problem = dataclasses.replace(make_problem(name, num_intervals),
                                  final_time=schedule.final_time)
    model, parameters = model_of(problem)
    grid = np.linspace(0.0, schedule.final_time, num_intervals + 1)
    run = simulate_schedule(EventDrivenIntegrator(model, parameters, rtol=RTOL, atol=ATOL),
                            problem, schedule, grid)
    pattern = pattern_on_grid(schedule, num_intervals)
    guess = Transcription(problem, modes=pattern)
    guess.set_guess(run.q_samples, run.u_samples, _held_inputs(schedule, problem, grid),
                    schedule.final_time)
    return problem, pattern, guess


def phase_start(name: str, phases: list[dict[str, Any]], final_time: float,
                num_intervals: int) -> tuple[OptimalControlProblem, ModePattern, Transcription]:
    """(problem, pattern, guess) on N intervals from a continuous optimum's stick-slip phases.

    Args:
        phases: the mode sequence in time, as ``optimal.phase_collocation`` records it: per
            phase "sliding" (c,) flags, "start" and "end" [s].
        final_time: t_f [s] of the continuous optimum (the problem's for a time task).

    The pattern: ``phases_on_grid`` (a contact slides in an interval whose midpoint a sliding
    phase of it covers; the last interval is the stop at rest). The guess: the shipped
    reference interpolated in t / t_f, its inputs, friction impulses (scaled by the step
    ratio) and slip speeds taken from the interval holding each new interval's midpoint.
    """
    problem = make_problem(name, num_intervals)
    if problem.cost == "time":
        problem = dataclasses.replace(problem, final_time=final_time)
    contacts = len(phases[0]["sliding"])
    sliding = {f"contact {j}": [[phase["start"], phase["end"]] for phase in phases
                                if phase["sliding"][j]] for j in range(contacts)}
    pattern = phases_on_grid(sliding, final_time, num_intervals)
    reference = load_reference(name)
    shipped = reference.tau.shape[0]
    fraction, fine = reference.time / reference.final_time, np.linspace(0.0, 1.0,
                                                                          num_intervals + 1)
    holder = ((np.arange(num_intervals) + 0.5) * shipped / num_intervals).astype(int)
    impulses = regridded_impulses({key: reference.arrays[key] for key in GUESS_IMPULSES},
                                  holder, shipped / num_intervals)
    guess = Transcription(problem, modes=pattern)
    guess.set_guess(*(np.column_stack([np.interp(fine, fraction, c) for c in values.T])
                      for values in (reference.q, reference.u)),
                    reference.tau[holder], final_time, impulses)
    return problem, pattern, guess


def phases_on_grid(phases: dict[str, list[list[float]]], final_time: float,
                   num_intervals: int) -> ModePattern:
    """The pattern of ``phases`` (``ModePattern.phases``, on [0, ``final_time``]) on N intervals.

    An interval is engaged (a brake) or sliding (a contact) when a phase covers its midpoint.
    A phase reaching t_f ends where the last interval starts: that interval is the stop at
    rest (the terminal condition), in which every contact sticks.
    """
    step = final_time / num_intervals
    middle = (np.arange(num_intervals) + 0.5) * step
    rows: dict[str, list[np.ndarray]] = {"brake": [], "contact": []}
    for label in sorted(phases, key=lambda key: (key.split()[0], int(key.split()[1]))):
        covered = np.zeros(num_intervals, dtype=bool)
        for start, end in phases[label]:
            if math.isclose(end, final_time, rel_tol=1e-9):
                end = final_time - step
            covered |= (middle >= start) & (middle <= end)
        rows[label.split()[0]].append(covered)
    return ModePattern(*(np.array(rows[kind]) if rows[kind] else None
                         for kind in ("brake", "contact")))


def _held_inputs(schedule: SwitchingSchedule, problem: Any, grid: np.ndarray) -> np.ndarray:
    """(N, m) the bang-bang inputs averaged over each interval (a switch inside: its mean)."""
    columns = []
    for sign, switches in zip(schedule.initial_signs, schedule.switches, strict=True):
        edges = np.concatenate([[0.0], switches, [schedule.final_time]])
        signs = sign * (-1.0) ** np.arange(edges.size - 1)
        left, right = grid[:-1, None], grid[1:, None]
        overlap = np.clip(np.minimum(right, edges[1:]) - np.maximum(left, edges[:-1]), 0.0, None)
        columns.append(problem.torque_bound * (overlap @ signs) / (right - left)[:, 0])
    return np.column_stack(columns)


def richardson(num_intervals: list[int], costs: list[float]) -> dict[str, float]:
    """The limit c of cost(N) = c + a h^p through three levels N, r N, r^2 N (h ~ 1/N).

    Returns:
        {"value": c, "order": p, "coefficient": a (per unit 1/N^p)}; all NaN when the three
        costs do not change monotonically or the second change is not smaller than the first
        (no fit with p > 0).

    Raises:
        ValueError: not three levels with a constant ratio r > 1.
    """
    if len(num_intervals) != 3 or len(costs) != 3:
        raise ValueError(f"richardson needs three levels, got N = {num_intervals}")
    ratio = num_intervals[1] / num_intervals[0]
    if ratio <= 1.0 or not math.isclose(num_intervals[2] / num_intervals[1], ratio):
        raise ValueError(f"richardson needs N, r N, r^2 N with r > 1, got N = {num_intervals}")
    first, second = costs[0] - costs[1], costs[1] - costs[2]
    if first * second <= 0.0 or abs(second) >= abs(first):
        return {"value": math.nan, "order": math.nan, "coefficient": math.nan}
    order = math.log(first / second) / math.log(ratio)
    value = costs[2] - second / (ratio ** order - 1.0)
    return {"value": value, "order": order,
            "coefficient": (costs[2] - value) * num_intervals[2] ** order}


def continuous_cost(record: dict[str, Any]) -> float:
    """A continuous optimum's cost.

    t_f of a polished schedule; else the extrapolated limit of the collocation levels
    (``optimal.phase_collocation``), else its finest level's cost.
    """
    if "schedule" in record:
        return float(record["final_time"])
    limit = record.get("extrapolation", {}).get("value", math.nan)
    return float(limit) if math.isfinite(limit) else float(record["cost"])


def study_start(name: str, record: dict[str, Any]) -> Start:
    """Where ``name``'s levels start: a polished schedule, or a collocation's phases."""
    if "schedule" in record:
        return partial(schedule_start, name, _schedule(record["schedule"]))
    return partial(phase_start, name, record["phases"], record["final_time"])


def study_table(study: dict[str, Any]) -> list[dict[str, float]]:
    """The refinement table: one row per level, coarsest first.

    Rows: N, the projected pattern's cost, the cost after the mode search and its round limit,
    its change from the previous level, the distance d_N = cost - the study's
    "continuous_cost", d_N / continuous_cost, the observed order, wall time [s].

    The order of a row is log(d_N / d_N') / log(N' / N) with N' the next level (NaN for the
    last row or where the two distances differ in sign or one is zero).
    """
    optimum = study["continuous_cost"]
    levels = sorted(study["levels"].values(), key=lambda level: level["num_intervals"])
    rows = []
    for i, level in enumerate(levels):
        distance = level["cost"] - optimum
        order = math.nan
        if i + 1 < len(levels):
            following = levels[i + 1]["cost"] - optimum
            if distance * following > 0.0:
                order = math.log(distance / following) / math.log(
                    levels[i + 1]["num_intervals"] / level["num_intervals"])
        change = level["cost"] - levels[i - 1]["cost"] if i else math.nan
        rows.append({"num_intervals": level["num_intervals"], "start_cost": level["start_cost"],
                     "change": change,
                     "max_rounds": level.get("max_rounds", 8), "cost": level["cost"],
                     "distance": distance, "relative_distance": distance / optimum,
                     "order": order, "wall_time": level["wall_time"]})
    return rows


def is_chain(study: dict[str, Any]) -> bool:
    """Whether the study's levels are the refinement chain from the reference (``--chain``)."""
    return any(level.get("start") == "reference chain" for level in study["levels"].values())


def plot_study(study: dict[str, Any], path: Path) -> None:
    """Log-log plot of |cost(N) - the continuous optimum| against N, with a first-order line.

    Filled markers: costs above the continuous optimum, open: below.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = study_table(study)
    limit = study["continuous_cost"]
    n = np.array([row["num_intervals"] for row in rows], dtype=float)
    distance = np.array([row["distance"] for row in rows])
    projected = np.array([row["start_cost"] for row in rows]) - limit
    figure, axes = plt.subplots(figsize=(5, 3.6))
    fixed_label = "pattern refined, fixed" if is_chain(study) else "pattern projected, fixed"
    for values, style, color, label in [(projected, "s:", "0.5", fixed_label),
                                        (distance, "o-", "C0", "after the search")]:
        axes.loglog(n, np.abs(values), style, color=color, label=label, markerfacecolor="none")
        above = values > 0
        axes.loglog(n[above], values[above], style[0], color=color)
    axes.loglog(n, abs(distance[-1]) * n[-1] / n, "k--", lw=0.8, label="order 1")
    axes.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes.set_xlabel("N (intervals)")
    axes.set_ylabel("|cost(N) - continuous optimum|")
    axes.set_title(f"{study['name']}: continuous optimum {limit:.6f}", fontsize=9)
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def run_study(name: str, levels: list[int], directory: Path = CONTINUOUS_DIR,
              max_rounds: int = 8, max_iterations: int = FIXED_PATTERN_MAX_ITERATIONS,
              chain: bool = False) -> dict[str, Any]:
    """Solve ``levels`` of ``name``'s study one by one, saving after each.

    The study's target is the continuous optimum ``NAME.json`` in ``directory``
    (``continuous_cost``). By default the levels start from it (``study_start``) and only the
    missing ones are solved, coarsest first; a converged level warm-starts the next one solved
    in the same call when its N divides the next (``solve_level``'s ``warm``). With ``chain``
    the levels are the refinement chain from the shipped reference (``chain_levels``), all
    solved in order, and replace the study's levels.
    """
    polished = directory / f"{name}.json"
    if not polished.exists():
        raise FileNotFoundError(f"{name}: no continuous optimum {polished}; compute it first "
                                "(optimal.convergence --polish, or optimal.phase_collocation)")
    record = json.loads(polished.read_text())
    path = directory / f"{name}_refinement.json"
    study = json.loads(path.read_text()) if path.exists() else {"name": name, "levels": {}}
    study["continuous_cost"] = continuous_cost(record)
    if chain:
        study["levels"] = {}
        solved = chain_levels(name, levels, max_rounds)
    else:
        solved = _independent_levels(study_start(name, record), sorted(
            n for n in levels if str(n) not in study["levels"]), max_rounds, max_iterations)
    for level in solved:
        study["levels"][str(level["num_intervals"])] = level
        path.write_text(json.dumps(study, indent=1) + "\n")
        print(f"N = {level['num_intervals']}: cost {level['cost']:.6f} (start "
              f"{level['start_cost']:.6f}), t_f {level['final_time']:.6f} s, converged "
              f"{level['converged']}, kept pattern {level['kept_pattern']}, "
              f"{len(level['moves'])} moves, {level['wall_time']:.0f} s", flush=True)
    if study["levels"]:
        plot_study(study, directory / f"{name}_refinement.png")
    return study


def _independent_levels(start: Start, levels: list[int], max_rounds: int, max_iterations: int
                        ) -> Iterator[dict[str, Any]]:
    """``solve_level`` for each of ``levels`` (ascending), the previous converged one warm."""
    warm = None
    for n in levels:
        level, *solved = solve_level(start, n, max_rounds,
                                     warm if warm and n % warm[0].num_intervals == 0 else None,
                                     max_iterations)
        warm = tuple(solved) if level["converged"] else None
        yield level


def _schedule(data: dict[str, Any]) -> SwitchingSchedule:
    return SwitchingSchedule(tuple(tuple(r) for r in data["input_switches"]),
                             tuple(data["initial_signs"]),
                             tuple(tuple(tuple(p) for p in r) for r in data["brake_phases"]),
                             data["final_time"])


def main(argv: list[str] | None = None) -> None:
    """``python -m optimal.convergence NAME [--polish] [--levels 30,60,120]``; prints the table."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("name")
    parser.add_argument("--polish", action="store_true",
                        help="(re)compute the continuous-time optimum first")
    parser.add_argument("--levels", default="", help="N of the refinement levels, e.g. 30,60")
    parser.add_argument("--rounds", type=int, default=8, help="mode-search rounds per level")
    parser.add_argument("--iterations", type=int, default=FIXED_PATTERN_MAX_ITERATIONS,
                        help="IPOPT's limit in a level's first fixed-pattern solve")
    parser.add_argument("--chain", action="store_true",
                        help="the levels refined from the shipped reference, each from the one "
                             "before and freed (they replace the study's levels)")
    args = parser.parse_args(argv)
    if args.polish:
        record = polish_reference(args.name)
        print(f"continuous-time optimum {record['final_time']:.6f} s ({record['best_start']}), "
              f"goal error {record['goal_error']:.1e}; h-discrete {record['discrete_cost']:.6f} "
              f"s ({100 * record['relative_difference']:+.3f} %)", flush=True)
    levels = [int(n) for n in args.levels.split(",") if n]
    if levels:
        run_study(args.name, levels, max_rounds=args.rounds, max_iterations=args.iterations,
                  chain=args.chain)
    path = CONTINUOUS_DIR / f"{args.name}_refinement.json"
    study = json.loads(path.read_text()) if path.exists() else {}
    if study.get("levels"):  # the table, as markdown
        print(f"continuous optimum {study['continuous_cost']:.7f}")
        print("| N | cost, pattern fixed | cost after the search (rounds) | change | "
              "distance | distance / optimum | observed order |\n|---|---|---|---|---|---|---|")
        for row in study_table(study):
            print("| {num_intervals} | {start_cost:.6f} | {cost:.6f} ({max_rounds}) | "
                  "{change:.3e} | {distance:.3e} | {relative_distance:.3%} | {order:.2f} |"
                  .format(**row))


if __name__ == "__main__":
    main()
