"""Reporting of ``benchmarks.engine``: Markdown tables, target checks and plots."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.report import bars, format_us, log_lines, plt, save_figure, summary

MODEL_TITLES = {
    "ball": "bouncing ball",
    "block": "sliding block",
    "manipulator": "blockable manipulator",
    "diff_drive": "diff-drive robot",
    "mujoco": "MuJoCo arm (rollout, 1 thread)",
}

def shortcuts_text(shortcuts: Any) -> str:
    """The fields of a ``StepShortcuts`` that differ from the defaults, as ``a=b`` text."""
    defaults = type(shortcuts)()
    changed = [f"{k}={v}" for k, v in shortcuts._asdict().items() if getattr(defaults, k) != v]
    return ", ".join(changed) or "default shortcuts"


def case_record(case: Any) -> dict[str, Any]:
    """A model case (model, scenes, mix) as JSON-ready data."""
    return {
        "label": case.label,
        "model": case.model.__name__,
        "mix": [s.name for s in case.mix_scenes],
        "scenes": [
            {"name": s.name, "description": s.description, "q": s.q, "u": s.u, "tau": s.tau,
             "brake": [float(b) if np.isfinite(b) else "inf" for b in s.brake]}
            for s in case.scenes
        ],
    }


def markdown_report(record: Mapping[str, Any]) -> str:
    """The targets and the result tables of one run (printed on stdout)."""
    per_copy = ["model", "scene", "copies", "substeps", "per_copy_step_s"]
    return summary(record, ("numpy", "numba", "mujoco"), {
        "Compile time [s] (first calls, excluded from every timing)": record["compile"],
        "One step from Python [s] (median)": (record["single_step"],
                                              ["model", "scene", "entry", "median_s", "q1_s",
                                               "q3_s"]),
        "In-kernel step per scene [s]": (record["per_scene"], per_copy),
        "Batched: s per copy-step of step_batch, each model's scene mix": (record["batched"],
                                                                          per_copy),
        "Substeps per call [s per copy-step]": (record["substeps"], per_copy),
        "Shortcuts on vs off [s per copy-step]": (record["shortcuts"], [
            "shortcut", "model", "scene", "off_scene", "on.per_copy_step_s",
            "off.per_copy_step_s", "speedup", "speedup_fastest_rounds",
            "max_state_difference"]),
        "Brake stop (steps until the relative velocity < 1 % of 1 rad/s)": brake_rows(
            record.get("brake_stop")),
    })


def brake_rows(brake: Mapping[str, Any] | None) -> tuple[list[dict[str, Any]], list[str]]:
    """The brake-stop study as table rows (simulator, steps, relative angle, solref)."""
    rows = [{"simulator": key, **value} for key, value in (brake or {}).items()]
    return rows, ["simulator", "steps", "relative_angle_at_stop", "solref",
                  "relative_speed_after_first_step"]


def plot_batched(batched: Sequence[dict[str, Any]], substeps: Sequence[dict[str, Any]],
                 targets_us: Mapping[str, float], path: Path) -> None:
    """µs per copy-step against N (and against substeps per call), one line per model."""
    panels = 2 if substeps else 1
    fig, axes = plt.subplots(1, panels, figsize=(7.5 + 4.5 * (panels - 1), 4.8), sharey=True,
                             gridspec_kw={"width_ratios": [5, 3][:panels]})
    axes = list(np.atleast_1d(axes))
    for ax, rows, x in zip(axes, (batched, substeps), ("copies", "substeps"), strict=False):
        log_lines(ax, rows, x, "per_copy_step_s", "model", ("per_copy_step_q1_s",
                  "per_copy_step_q3_s"), 1e6, lambda m: MODEL_TITLES.get(m, m),
                  lambda m: m == "mujoco")
        ax.set_xlabel(f"{x} per step_batch call")
    for model, key, color in (("manipulator", "manipulator_batched", "tab:green"),
                              ("diff_drive", "diff_drive", "tab:red")):
        if any(r["model"] == model for r in batched):
            axes[0].axhline(targets_us[key], color=color, lw=0.9, ls=":",
                            label=f"{model} target {targets_us[key]:g} µs")
    axes[0].set_title("Batched stepping (single thread), per copy-step")
    axes[0].set_ylabel("µs per copy-step (band: quartiles)")
    axes[0].legend(fontsize=7, loc="best")
    save_figure(fig, path)


def plot_single_step(single: Sequence[dict[str, Any]], scenes: Sequence[dict[str, Any]],
                     targets_us: Mapping[str, float], path: Path) -> None:
    """Horizontal bars per (model, scene): Python step, in-place step, in-kernel step [µs]."""
    index = {(r["model"], r["scene"], r["entry"]): r["median_s"] * 1e6 for r in single}
    index.update({(r["model"], r["scene"], "kernel"): r["per_copy_step_s"] * 1e6 for r in scenes})
    keys = list(dict.fromkeys((r["model"], r["scene"]) for r in single))
    fig, ax = plt.subplots(figsize=(8.5, 0.42 * len(keys) + 1.6))
    ax.axvline(targets_us["manipulator_python"], color="tab:green", lw=0.9, ls=":",
               label=f"manipulator target (Python) {targets_us['manipulator_python']:g} µs")
    bars(ax, [f"{m} / {s}" for m, s in keys], {
        "one step from Python: step() / mj_step": [
            index.get((m, s, "mj_step" if m == "mujoco" else "step")) for m, s in keys],
        "InPlaceStepper.step() from Python": [index.get((m, s, "in_place")) for m, s in keys],
        "in-kernel (batched)": [index.get((m, s, "kernel")) for m, s in keys]}, "µs per step")
    save_figure(fig, path)


def plot_shortcuts(shortcuts: Sequence[dict[str, Any]], path: Path) -> None:
    """Horizontal bars of the speedup off/on per shortcut measurement (log axis)."""
    fig, ax = plt.subplots(figsize=(8.5, 0.4 * max(len(shortcuts), 1) + 1.6))
    if shortcuts:
        labels = []
        for r in shortcuts:
            name = "no solve (free vs active)" if r["shortcut"] == "no_solve" else r["shortcut"]
            scene = r["scene"] + ("" if r["off_scene"] == r["scene"] else f" vs {r['off_scene']}")
            labels.append(f"{name}: {r['model']} / {scene}")
        y = np.arange(len(shortcuts))
        speedups = [r["speedup"] for r in shortcuts]
        colors = ["tab:gray" if r["shortcut"] == "no_solve" else "tab:blue" for r in shortcuts]
        fastest = [r["speedup_fastest_rounds"] for r in shortcuts]
        ax.barh(y, speedups, 0.6, color=colors, label="ratio of medians")
        ax.plot(fastest, y, "kD", ms=4, label="ratio of fastest rounds")
        for yi, r in zip(y, shortcuts, strict=True):
            ax.text(max(r["speedup"], r["speedup_fastest_rounds"]), yi,
                    f"  {format_us(r['on']['per_copy_step_s'])} vs "
                    f"{format_us(r['off']['per_copy_step_s'])} µs", va="center", fontsize=7)
        ax.set_yticks(y, labels, fontsize=8)
        ax.invert_yaxis()
        ax.set_xlim(0.0, 1.25 * max(max(speedups), max(fastest), 1.0))
        ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2,
                  frameon=False)
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_xlabel("time off / time on (> 1: the shortcut saves time)\n"
                  "labels: on vs off, µs per copy-step (medians)")
    ax.grid(True, axis="x", which="both", alpha=0.3)
    save_figure(fig, path)


__all__ = ["MODEL_TITLES", "brake_rows", "case_record", "markdown_report", "plot_batched",
           "plot_shortcuts", "plot_single_step", "shortcuts_text"]
