"""Reporting of ``benchmarks.work_precision``: equal-time comparison, tables and plots."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.engine_report import brake_rows
from benchmarks.report import format_number as _format
from benchmarks.report import log_lines, plt, save_figure, summary

ERROR_FLOOR = 1e-17  # exactly-zero errors are drawn at or below this on log axes
TIMED_PATHS = {
    "mj_one_call": "one step_batch call (N = 1, check_inputs=False, num_substeps = all steps)",
    "mj_per_phase": "one step_batch call (N = 1, check_inputs=False) per constant-command phase",
    "mj_per_step": "one step_batch call (N = 1, 1 substep) per step from Python (the input "
                   "changes every step)",
    "ed": "EventDrivenIntegrator.simulate (scipy solve_ivp DOP853 with events), sampling included",
    "mujoco_one_call": "one mj_step(model, data, nstep = all steps) call",
    "mujoco_per_phase": "one mj_step(model, data, nstep) call per constant-command phase",
}
"""What each point's wall time covers (``timed_path`` of a point)."""

SERIES_TITLES = {
    "mj_enumerative": "Moreau–Jean (enumerative LCP, default)",
    "mj_lemke": "Moreau–Jean (Lemke)",
    "mj_located": "Moreau–Jean, impacts located (locate_impacts=True)",
    "mj_newton_ac": "Moreau–Jean (semismooth Newton, Alart–Curnier)",
    "event_driven": "event-driven (DOP853)",
    "mujoco_formula": "MuJoCo, dampratio from ε (formula)",
    "mujoco_calibrated": "MuJoCo, dampratio calibrated per dt",
    "mujoco_default": "MuJoCo, brake solref (0.02, 1) (default)",
    "mujoco_stiffest": "MuJoCo, brake solref (2 dt, 1) (stiffest)",
}

SCENE_TITLES = {
    "ball": "Bouncing ball: mean over drops of the largest relative apex error, bounces 1–3 [-]",
    "slope": "Block on a slope: largest |state − closed form| [m, m/s]",
    "manipulator": "Manipulator, bang-bang torque and 3 brake engagements: largest |state − "
                   "event-driven reference| over the 4 ms samples [rad, rad/s]",
    "diff_drive": "Diff-drive robot: |final state − Moreau–Jean at dt_ref| [m, rad, m/s, rad/s]",
}

def series_title(series: str) -> str:
    """Readable series name (slope series are ``method:case``)."""
    method, _, case = series.partition(":")
    title = SERIES_TITLES.get(method, method)
    return f"{title} · {case}" if case else title


def pareto_front(points: Sequence[Mapping[str, Any]]) -> list[tuple[float, float, str]]:
    """(wall time [s], error, label) of the points no other point beats in both, by time."""
    usable = sorted((p["wall_time_s"], p["error"], f"{p['series']} dt={p['value']:g}")
                    for p in points
                    if p.get("error") is not None and p["wall_time_s"] is not None)
    front: list[tuple[float, float, str]] = []
    for seconds, error, label in usable:
        if not front or error < front[-1][1]:
            front.append((seconds, error, label))
    return front


def interpolate_front(front: Sequence[tuple[float, float, str]], seconds: float
                      ) -> tuple[float | None, str]:
    """MuJoCo's error at ``seconds`` on its front (see ``equal_time_comparison``)."""
    times = [f[0] for f in front]
    if seconds <= times[0]:
        return front[0][1], "clamped"
    if seconds > times[-1]:
        return None, "beyond"
    i = int(np.searchsorted(times, seconds))
    (t0, e0, _), (t1, e1, _) = front[i - 1], front[i]
    w = math.log(seconds / t0) / math.log(t1 / t0)
    return math.exp((1.0 - w) * math.log(e0) + w * math.log(e1)), "interpolated"


def equal_time_comparison(ours: Sequence[Mapping[str, Any]],
                          mujoco: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """MuJoCo's ball error / ours at our wall times, off MuJoCo's Pareto front.

    Between front points the error is interpolated in (log t, log error) ("interpolated"); where
    ours is faster than the fastest front point that point's error is used ("clamped": a lower
    bound); beyond the slowest nothing is compared ("beyond"). Returns ``rows``, ``front``,
    ``min_ratio``, ``max_ratio``, ``min_equal_time_ratio``, ``min_lower_bound_ratio``,
    ``ratio_at_1ms`` and ``summary``.
    """
    front = pareto_front(mujoco)
    rows = []
    for p in sorted(ours, key=lambda p: -p["value"]):
        if p.get("error") is None or not front:
            continue
        theirs, how = interpolate_front(front, p["wall_time_s"])
        ratio = None if theirs is None or p["error"] == 0.0 else theirs / p["error"]
        rows.append({"dt": p["value"], "wall_time_s": p["wall_time_s"], "error": p["error"],
                     "mujoco_error": theirs, "how": how, "ratio": ratio})
    ratios = [r["ratio"] for r in rows if r["ratio"] is not None]
    equal = [r["ratio"] for r in rows if r["ratio"] is not None and r["how"] == "interpolated"]
    bounds = [r["ratio"] for r in rows if r["ratio"] is not None and r["how"] == "clamped"]
    at_1ms = next((r for r in rows if math.isclose(r["dt"], 1e-3)), None)
    result: dict[str, Any] = {
        "rows": rows, "front": [list(f) for f in front],
        "min_ratio": min(ratios) if ratios else None,
        "max_ratio": max(ratios) if ratios else None,
        "min_equal_time_ratio": min(equal) if equal else None,
        "min_lower_bound_ratio": min(bounds) if bounds else None,
        "ratio_at_1ms": None if at_1ms is None else at_1ms["ratio"],
    }
    parts = []
    if equal:
        parts.append(f"at equal time (interpolated) {_format(min(equal))}–{_format(max(equal))}× "
                     f"over {len(equal)} of our dt")
    if bounds:
        parts.append(f"where ours is faster than any MuJoCo run (clamped: lower bounds) "
                     f"{_format(min(bounds))}–{_format(max(bounds))}× over {len(bounds)} of our dt")
    if at_1ms is not None and at_1ms["ratio"] is not None:
        parts.append(f"at dt = 1e-3: {_format(at_1ms['ratio'])}× ({at_1ms['how']})")
    result["summary"] = "; ".join(parts) or "no comparable point"
    return result


def markdown_report(record: Mapping[str, Any]) -> str:
    """The targets, the equal-time comparison, the compile times and one table per scene."""
    comparison = record.get("equal_time") or {}
    columns = ["series", "parameter", "value", "wall_time_s", "error", "error_max",
               "final_error", "speed_error", "impact_time_error_s", "status"]
    return summary(record, ("numpy", "numba", "scipy", "mujoco"), {
        "Ball: MuJoCo's error / ours at equal wall time (MuJoCo's Pareto front interpolated "
        f"in log-log; clamped: a lower bound). {comparison.get('summary', '')}":
            comparison.get("rows"),
        "Compile time [s] (first step_batch per kernel, excluded from every wall time)":
            record["compile"],
        **{title: ([p for p in record["points"] if p["scene"] == scene], columns)
           for scene, title in SCENE_TITLES.items()},
        "References": [{"scene": k, **v} for k, v in record["references"].items()],
        "MuJoCo ball calibration": record.get("mujoco_ball_calibration"),
        "Brake stop (dt = 1e-3 s)": brake_rows(record.get("brake_stop")),
    })


def plot_scene(points: Sequence[Mapping[str, Any]], scene: str, path: Path) -> None:
    """Log-log error against wall time, one line per series, each point labelled by dt/rtol."""
    fig, ax = plt.subplots(figsize=(8.0, 5.4))
    positive = [p["error"] for p in points if p.get("error")]
    floor = min(ERROR_FLOOR, 0.1 * min(positive)) if positive else ERROR_FLOOR
    rows = [{**p, "ms": p["wall_time_s"] * 1e3, "drawn": max(p["error"], floor)}
            for p in points if p.get("error") is not None]
    log_lines(ax, rows, "ms", "drawn", "series", label=series_title,
              dashed=lambda s: "lemke" in s, ticks=False)
    for p in rows:
        ax.annotate(f"{p['value']:g}", (p["ms"], p["drawn"]), textcoords="offset points",
                    xytext=(3, 3), fontsize=6)
    ax.set_ylabel("error")
    ax.set_title(textwrap.fill(SCENE_TITLES.get(scene, scene), 95), fontsize=9)
    ax.legend(fontsize=7)
    ax.set_xlabel("wall time per trajectory [ms]   (point labels: dt [s] or rtol; errors of "
                  f"exactly 0 drawn at {floor:.0e})")
    save_figure(fig, path)


def plot_ball_convergence(points: Sequence[Mapping[str, Any]], path: Path) -> None:
    """Ball error against dt (log-log), with an O(dt) slope and the 1e-3 target marked."""
    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    stepped = [p for p in points if p["parameter"] == "dt" and p.get("error") is not None]
    log_lines(ax, stepped, "value", "error", "series", label=series_title,
              dashed=lambda s: "lemke" in s, ticks=False)
    ours = sorted((p for p in stepped if p["series"] == "mj_enumerative"),
                  key=lambda p: p["value"])
    if ours:
        dts = np.array([p["value"] for p in ours])
        anchor = ours[len(ours) // 2]
        ax.plot(dts, anchor["error"] * dts / anchor["value"], "k:", lw=1.0,
                label="O(dt) reference slope")
    ax.plot([1e-3], [1e-3], marker="*", color="k", ms=10, ls="none",
            label="target: 1e-3 at dt = 1e-3 s")
    ax.set_xlabel("time step dt [s]")
    ax.set_ylabel("mean largest relative apex error, bounces 1–3")
    ax.set_title("Bouncing ball: convergence in dt", fontsize=9)
    ax.legend(fontsize=7)
    save_figure(fig, path)


def plot_all(points: Sequence[Mapping[str, Any]], scenes: Sequence[str], output: Path
             ) -> list[str]:
    """Every plot of the run; returns the file names written."""
    names = []
    for scene in scenes:
        chosen = [p for p in points if p["scene"] == scene]
        name = f"work_precision_{scene}.png"
        plot_scene(chosen, scene, output / name)
        names.append(name)
        if scene == "ball":
            plot_ball_convergence(chosen, output / "work_precision_ball_convergence.png")
            names.append("work_precision_ball_convergence.png")
    return names


__all__ = ["ERROR_FLOOR", "SCENE_TITLES", "SERIES_TITLES", "TIMED_PATHS", "equal_time_comparison",
           "interpolate_front", "markdown_report", "pareto_front", "plot_all", "series_title"]
