"""Model-based controllers in real time (``mdi-envs bench control``): compute, success, cost.

Each controller of ``baselines.model_based.EXPERTS`` (a row keyed by its name there) plays every
optimal reference's task (``TASKS``, in the env id of its metadata) from perturbed starts
(``reset(seed=s)`` at each ``SCALES`` half-width) in the env configured like the comparison. The
compute of each control step is CPU time (``time.process_time`` around the policy call), so other
processes on the machine do not inflate it; the real-time factor is that time over the control
period (the env's dt, the reference's h): at most 1 means the controller keeps up. Reported per row:
the real-time factor's median, 95th percentile and worst over all steps of all episodes; the success
rate; the time (time tasks) or effort (effort task) over the reference's, mean over the successes.
The shrinking-horizon MPC takes seconds per step: it plays the first ``SLOW_STEPS`` steps of
``SLOW_STARTS`` starts per scale (compute only); ``--quick`` plays the LQR only. ``--controllers``
plays some rows and keeps the others of an existing ``control.json`` (each record carries its date).
With the tracking MPC, ``memory_growth`` measures the memory over ``MEMORY_STEPS`` steps without a
plan. Writes ``control.json`` and ``control.png``.
"""

from __future__ import annotations

import json
import resource
import sys
import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from baselines.evaluation import REFERENCE_NAMES, Controller, reference_effort
from baselines.model_based import EXPERTS, row_env_options
from benchmarks import report
from benchmarks.timing import VERSIONED_PACKAGES, Progress, arguments, finish, machine_info
from optimal.references import load_reference

TASKS = tuple(dict.fromkeys(REFERENCE_NAMES.values()))
"""The references, each played in the env it was computed for (its metadata's env id)."""

SLOW = ("mpc",)
"""Rows that play ``SLOW_STARTS`` starts."""

QUICK_ROWS = ("lqr",)
"""The rows ``--quick`` plays (the MPCs take 10-60 s to build or seconds per step)."""

SCALES = (0.01, 0.1)
"""Start perturbation half-widths [rad, rad/s, m, m/s]."""

STARTS, SLOW_STARTS, QUICK_STARTS = 20, 1, 2
"""Perturbed starts per scale: fast rows, ``SLOW`` rows, every row under ``--quick``."""

SLOW_STEPS = 12
"""Steps a ``SLOW`` row plays of each episode: its compute only (its success and cost from
perturbed starts are the comparison's and robustness study's, ``baselines/``)."""

MEMORY_STEPS, QUICK_MEMORY_STEPS, MEMORY_WARMUP = 300, 40, 10
"""Steps without a plan of the memory measurement (``memory_growth``), and the first steps
before it starts (the first calls' one-time allocations)."""

TARGET_RTF, TARGET_SUCCESS, TARGET_RATIO, TARGET_GROWTH_MB = 1.0, 0.95, 1.01, 100.0
"""Targets per task and scale: median real-time factor, success rate, cost over the optimum;
and the memory growth over ``MEMORY_STEPS`` steps without a plan [MB]."""


def play(controller: Controller, env_id: str, scale: float, seed: int,
         max_steps: int | None = None) -> dict[str, Any]:
    """One episode from ``reset(seed=seed)``: its end ``info`` and each step's CPU time [s].

    ``max_steps``: stop after this many steps (the end ``info`` is then None).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make(env_id, **{**controller.env_kwargs, "reset_noise_scale": scale})
    policy = controller.make_policy(env)
    observation, _ = env.reset(seed=seed)
    compute: list[float] = []
    while True:
        clock = time.process_time()
        action = policy(observation)
        compute.append(time.process_time() - clock)
        observation, _, terminated, truncated, info = env.step(action)
        if terminated or truncated or len(compute) == max_steps:
            env.close()
            return {"info": None if len(compute) == max_steps and not (terminated or truncated)
                    else info, "compute": compute}


def measure(key: str, env_id: str, objective: str, starts: int, progress: Progress,
            max_steps: int | None = None) -> list[dict[str, Any]]:
    """One record per scale of the row ``key`` on the task (env id, objective).

    ``max_steps``: play only the first steps of each episode (compute only; success and cost
    are then None).
    """
    controller = EXPERTS[key](env_id, objective)
    if controller is None:
        return []
    reference = load_reference(REFERENCE_NAMES[(env_id, objective)])
    optimum = reference.final_time if objective == "time" else reference_effort(reference)
    records = []
    for scale in SCALES:
        episodes = []
        for seed in range(starts):
            episodes.append(play(controller, env_id, scale, seed, max_steps))
            info = episodes[-1]["info"]
            progress(f"{key} {reference.name} scale {scale} seed {seed}: "
                     f"{'cut' if info is None else 'success' if info['is_success'] else 'failure'}")
        steps = np.concatenate([e["compute"] for e in episodes]) / reference.time_step
        played = [e["info"] for e in episodes if e["info"] is not None]
        success = [bool(info["is_success"]) for info in played]
        cost = "elapsed_time" if objective == "time" else "effort"
        ratios = [info[cost] / optimum for info, ok in zip(played, success, strict=True) if ok]
        records.append({
            "controller": key, "label": controller.label, "task": reference.name,
            "scale": scale, "starts": starts, "control_period_s": reference.time_step,
            "rtf_median": float(np.median(steps)), "rtf_p95": float(np.percentile(steps, 95)),
            "rtf_worst": float(np.max(steps)), "steps": int(steps.size),
            "success_rate": float(np.mean(success)) if success else None,
            "ratio": float(np.mean(ratios)) if ratios else None,
            "ratios": [float(r) for r in ratios], "date": time.strftime("%Y-%m-%d %H:%M UTC",
                                                                           time.gmtime())})
    return records


def memory_growth(steps: int, progress: Progress) -> dict[str, Any]:
    """Peak resident memory growth over ``steps`` control steps in which no plan is found.

    The tracking MPC on the manipulator with IPOPT limited to one iteration and no acceptable
    stop, so every step's window solve fails and the LQR's control is applied; episodes from
    0.1-perturbed starts are played until ``steps`` steps have been taken after the first
    episode's first ``MEMORY_WARMUP`` steps (``resource.getrusage``'s peak RSS, before and after).
    """
    from optimal.tracking import TrackingMPC

    reference = load_reference("manipulator_time")
    controller = TrackingMPC(reference, max_iterations=1, solver_options={"acceptable_iter": 0})
    options = {**row_env_options(reference), "reset_noise_scale": 0.1}
    env = gym.make(reference.metadata["env_id"], **options)
    taken, seed, start = 0, 0, None
    while taken < steps + MEMORY_WARMUP:
        controller.reset()
        observation, _ = env.reset(seed=seed)
        done = False
        while not done and taken < steps + MEMORY_WARMUP:
            observation, _, terminated, truncated, _ = env.step(controller(observation))
            done = terminated or truncated
            taken += 1
            if taken == MEMORY_WARMUP:
                start = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        failed = len(controller.fallbacks) == len(controller.compute_times)
        progress(f"memory: episode {seed}, {taken} steps, every step without a plan: {failed}")
        seed += 1
    end = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return {"controller": "tracking", "task": reference.name, "steps": steps,
            "episodes": seed, "peak_rss_start_mb": start / 1024, "peak_rss_end_mb": end / 1024,
            "growth_mb": (end - start) / 1024}


def targets(records: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per fast row, task and scale: real-time factor, success and cost ratio checks."""
    rows = []
    for r in records:
        if r["controller"] in SLOW:
            continue
        name = f"{r['label']}, {r['task']} at {r['scale']:g}"
        rows += [report.target_row(f"{name}: real-time factor, median", "≤", TARGET_RTF, "×",
                                   r["rtf_median"], f"p95 {r['rtf_p95']:.3g}, worst "
                                   f"{r['rtf_worst']:.3g}"),
                 report.target_row(f"{name}: success", "≥", TARGET_SUCCESS, "",
                                   r["success_rate"], f"{r['starts']} starts"),
                 report.target_row(f"{name}: cost / optimum", "≤", TARGET_RATIO, "×",
                                   r["ratio"])]
    return rows


def plot(records: Sequence[dict[str, Any]], path: Path) -> None:
    """Real-time factor (median and worst) and success per row, task and scale."""
    labels = [f"{r['task']} {r['scale']:g}" for r in records if r["controller"] == "lqr"]
    fig, axes = report.plt.subplots(1, 2, figsize=(11, 4.5))
    series_rtf: dict[str, list[float | None]] = {}
    series_success: dict[str, list[float | None]] = {}
    for key in dict.fromkeys(r["controller"] for r in records):
        by_case = {f"{r['task']} {r['scale']:g}": r for r in records if r["controller"] == key}
        label = next(r["label"] for r in records if r["controller"] == key)
        for stat in ("median", "worst"):
            series_rtf[f"{label} {stat}"] = [by_case[c][f"rtf_{stat}"] if c in by_case else None
                                             for c in labels]
        series_success[label] = [by_case[c]["success_rate"] if c in by_case else None
                                 for c in labels]
    report.bars(axes[0], labels, series_rtf, "compute per step / control period (CPU time)")
    axes[0].axvline(TARGET_RTF, color="k", lw=0.8)
    report.bars(axes[1], labels, series_success, "success rate", log=False)
    report.save_figure(fig, path)


def run(quick: bool, output: Path, keys: Sequence[str]) -> str:
    """Play the rows ``keys`` on every task, merge into ``control.json``; the summary."""
    progress = Progress()
    record: dict[str, Any] = {"machine": machine_info((*VERSIONED_PACKAGES, "casadi")), "config": {
        "quick": quick, "scales": list(SCALES), "controllers": list(keys)}}
    path = output / "control.json"
    records = []
    for key in keys:
        starts = QUICK_STARTS if quick else (SLOW_STARTS if key in SLOW else STARTS)
        for name in TASKS:
            meta = load_reference(name).metadata
            records += measure(key, meta["env_id"], meta["cost_kind"], starts, progress,
                               SLOW_STEPS if key in SLOW else None)
    # read at the end: a run of other rows may have written meanwhile
    previous = json.loads(path.read_text()) if path.exists() and not quick else {}
    record["records"] = [r for r in previous.get("records", [])
                         if r["controller"] not in keys and r["controller"] in EXPERTS] + records
    record["targets"] = targets(record["records"])
    if "tracking" in keys:
        record["memory"] = memory_growth(QUICK_MEMORY_STEPS if quick else MEMORY_STEPS, progress)
        record["targets"].append(report.target_row(
            f"peak RSS growth over {record['memory']['steps']} steps without a plan",
            "≤", TARGET_GROWTH_MB, "MB", record["memory"]["growth_mb"],
            "tracking MPC, manipulator"))
    elif previous:
        record["memory"] = previous.get("memory")
        record["targets"] += [t for t in previous.get("targets", []) if "RSS" in t["target"]]
    finish(record, progress.elapsed)
    report.write_json(report.json_safe(record), path)
    plot(record["records"], output / "control.png")
    columns = ["label", "task", "scale", "starts", "rtf_median", "rtf_p95", "rtf_worst",
               "success_rate", "ratio"]
    return report.summary(record, ("numpy", "scipy", "casadi", "mdi-envs"),
                          {"Controllers": (record["records"], columns),
                           "Memory without a plan": [record["memory"]] if record.get("memory")
                           else []})


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point."""
    args = arguments(__doc__, argv, ("--controllers", {
        "nargs": "+", "choices": list(EXPERTS), "default": None,
        "help": "rows to play (default: all; --quick: QUICK_ROWS)"}))
    keys = args.controllers or [k for k in EXPERTS if not args.quick or k in QUICK_ROWS]
    args.output.mkdir(parents=True, exist_ok=True)
    print(run(args.quick, args.output, keys))
    return 0


if __name__ == "__main__":
    sys.exit(main())
