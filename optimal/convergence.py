"""Mesh refinement toward the continuous-time optimum, and the shipped continuous optima.

``polish_reference(name)`` polishes a shipped reference's mode sequence in continuous time
(``optimal.polish``), from its own times and from variants of its end (the last brake phase
as an instant lock at t_f, or engaged up to t_f), and keeps the best; ``optimal/continuous/
NAME.json`` holds it. ``solve_level`` solves the h-discrete problem on N intervals started from
that optimum: its mode sequence on the grid (``pattern_on_grid``, so a lock at t_f is the last
interval engaged) and its trajectory sampled there, then mode-searched. Levels are independent,
so a study is resumable:

    python -m optimal.convergence manipulator_time --levels 30,60,120,240,480

appends each level to ``optimal/continuous/NAME_refinement.json`` when it is done (levels in
the file are skipped) and redraws ``NAME_refinement.png``: N, t_f, the distance to the
continuous-time optimum and the observed order log2(d_N / d_2N).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from mdi_envs.stepping.event_driven import EventDrivenIntegrator
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

CONTINUOUS_DIR = Path(__file__).parent / "continuous"
"""Where the continuous-time optima and the refinement studies are stored."""


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


def solve_level(name: str, schedule: SwitchingSchedule, num_intervals: int,
                max_rounds: int = 8) -> dict[str, Any]:
    """The h-discrete optimum on N intervals, started from the continuous-time ``schedule``.

    The projected pattern is solved with its modes fixed from the sampled trajectory, then
    mode-searched (``improve_modes``, switches +-1, +-2 intervals per move): the h-discrete
    optimum on the continuous optimum's branch. (Freed by the continuation instead, as
    ``optimal.refinement.refine`` does, a coarse grid moves to the branch of an earlier lock.)

    Returns:
        A plain-JSON record: N, cost, t_f, converged, the fixed pattern's cost, the phases [s],
        the moves of the mode search and its round limit (0: the pattern as projected, an
        upper bound of the branch's optimum), wall time [s].
    """
    from optimal.mode_search import improve_modes, solve_with_modes
    from optimal.transcription import Transcription

    clock = time.perf_counter()
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
    fixed = solve_with_modes(problem, pattern, initial=guess.initial_point(), transcription=guess)
    local = improve_modes(problem, fixed, max_rounds=max_rounds)
    best, moves = local.best, [step.move for step in local.steps]
    phases = best.found_modes.phases(np.linspace(0.0, best.final_time, num_intervals + 1))
    return {"num_intervals": num_intervals, "cost": best.cost, "final_time": best.final_time,
            "converged": best.success, "start_cost": fixed.cost, "phases": phases,
            "moves": moves, "max_rounds": max_rounds, "wall_time": time.perf_counter() - clock}


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


def study_table(study: dict[str, Any]) -> list[dict[str, float]]:
    """The refinement table: one row per level, coarsest first.

    Rows: N, the projected pattern's cost, the cost after the mode search and its round limit,
    the distance d_N = cost - continuous optimum, d_N / optimum, the observed order.

    The order of a row is log(d_N / d_N') / log(N' / N) with N' the next level (NaN for the
    last row or where a distance is not positive).
    """
    optimum = study["continuous_cost"]
    levels = sorted(study["levels"].values(), key=lambda level: level["num_intervals"])
    rows = []
    for i, level in enumerate(levels):
        distance = level["cost"] - optimum
        order = math.nan
        if i + 1 < len(levels):
            following = levels[i + 1]["cost"] - optimum
            if distance > 0 and following > 0:
                order = math.log(distance / following) / math.log(
                    levels[i + 1]["num_intervals"] / level["num_intervals"])
        rows.append({"num_intervals": level["num_intervals"], "start_cost": level["start_cost"],
                     "max_rounds": level.get("max_rounds", 8), "cost": level["cost"],
                     "distance": distance, "relative_distance": distance / optimum,
                     "order": order})
    return rows


def plot_study(study: dict[str, Any], path: Path) -> None:
    """Log-log plot of the distance to the continuous-time optimum against N, with slope -1."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = study_table(study)
    n = np.array([row["num_intervals"] for row in rows], dtype=float)
    distance = np.array([row["distance"] for row in rows])
    projected = np.array([row["start_cost"] for row in rows]) - study["continuous_cost"]
    figure, axes = plt.subplots(figsize=(5, 3.6))
    axes.loglog(n, projected, "s:", color="0.5", label="pattern projected, fixed")
    axes.loglog(n, distance, "o-", label="after the mode search")
    axes.loglog(n, distance[-1] * n[-1] / n, "k--", lw=0.8, label="first order (slope -1)")
    axes.set_xlabel("N (intervals)")
    axes.set_ylabel("t_f(N) - continuous optimum [s]")
    axes.set_title(f"{study['name']}: continuous optimum {study['continuous_cost']:.6f} s",
                   fontsize=9)
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def run_study(name: str, levels: list[int], directory: Path = CONTINUOUS_DIR,
              max_rounds: int = 8) -> dict[str, Any]:
    """Solve the missing ``levels`` of ``name``'s study one by one, saving after each."""
    record = json.loads((directory / f"{name}.json").read_text())
    schedule = _schedule(record["schedule"])
    path = directory / f"{name}_refinement.json"
    study = json.loads(path.read_text()) if path.exists() else {
        "name": name, "continuous_cost": record["final_time"], "levels": {}}
    for n in levels:
        if str(n) in study["levels"]:
            continue
        level = solve_level(name, schedule, n, max_rounds)
        study["levels"][str(n)] = level
        path.write_text(json.dumps(study, indent=1) + "\n")
        print(f"N = {n}: t_f {level['final_time']:.6f} s (start {level['start_cost']:.6f}), "
              f"converged {level['converged']}, {len(level['moves'])} moves, "
              f"{level['wall_time']:.0f} s", flush=True)
    if study["levels"]:
        plot_study(study, directory / f"{name}_refinement.png")
    return study


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
    args = parser.parse_args(argv)
    if args.polish or not (CONTINUOUS_DIR / f"{args.name}.json").exists():
        record = polish_reference(args.name)
        print(f"continuous-time optimum {record['final_time']:.6f} s ({record['best_start']}), "
              f"goal error {record['goal_error']:.1e}; h-discrete {record['discrete_cost']:.6f} "
              f"s ({100 * record['relative_difference']:+.3f} %)", flush=True)
    levels = [int(n) for n in args.levels.split(",") if n]
    if levels:
        run_study(args.name, levels, max_rounds=args.rounds)
    path = CONTINUOUS_DIR / f"{args.name}_refinement.json"
    if path.exists():  # the table, as markdown
        print("| N | t_f, pattern projected [s] | t_f after the mode search [s] (rounds) | "
              "distance [s] | distance / optimum | observed order |\n|---|---|---|---|---|---|")
        for row in study_table(json.loads(path.read_text())):
            print("| {num_intervals} | {start_cost:.6f} | {cost:.6f} ({max_rounds}) | "
                  "{distance:.3e} | {relative_distance:.3%} | {order:.2f} |".format(**row))

if __name__ == "__main__":
    main()
