"""Reporting of ``benchmarks.engine``: Markdown tables, target checks and plots."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.report import (
    format_us_fine,
    markdown_table,
    plt,
    run_line,
    save_figure,
    targets_table,
)

MODEL_TITLES = {
    "ball": "bouncing ball",
    "block": "sliding block",
    "manipulator": "blockable manipulator",
    "diff_drive": "diff-drive robot",
    "mujoco": "MuJoCo arm (rollout, 1 thread)",
}

SHORTCUT_TITLES = {
    "skip_frictionless_rows": "skip_frictionless_rows",
    "reuse_constant_mass": "reuse_constant_mass",
    "direct_solve_max_size": "direct_solve_max_size 3 vs 0",
    "no_solve": "no closed contact / brake → no solve (no switch: free vs active step)",
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


def compile_table(records: Sequence[dict[str, Any]]) -> str:
    """Markdown: stepper, first step() [s], first step_batch() [s]."""
    return markdown_table([{
        "stepper": r["stepper"],
        "first step() s": "–" if r["step_s"] is None else f"{r['step_s']:.1f}",
        "first step_batch() s (after step)": f"{r['step_batch_s']:.1f}"} for r in records])


def scenes_table(models: Sequence[dict[str, Any]]) -> str:
    """Markdown: model, scene, in the batched mix?, description."""
    return markdown_table([{
        "model": m["label"], "scene": s["name"], "in the batched mix": "yes" if s["name"] in
        m["mix"] else "no", "what": s["description"]} for m in models for s in m["scenes"]])


def single_step_table(single: Sequence[dict[str, Any]], scenes: Sequence[dict[str, Any]]
                      ) -> str:
    """Markdown: per (model, scene) the Python step, the in-place step and the in-kernel cost."""
    index = {(r["model"], r["scene"], r["entry"]): r["median_s"] for r in single}
    kernel = {(r["model"], r["scene"]): r["per_copy_step_s"] for r in scenes}
    copies = scenes[0]["copies"] if scenes else "N"
    return markdown_table([{
        "model": "MuJoCo arm" if model == "mujoco" else MODEL_TITLES.get(model, model),
        "scene": scene,
        "one step from Python µs (step() / MuJoCo mj_step)": format_us_fine(
            index.get((model, scene, "mj_step" if model == "mujoco" else "step"))),
        "InPlaceStepper.step() from Python µs": format_us_fine(
            index.get((model, scene, "in_place"))),
        f"in-kernel µs per step (batched, N = {copies})": format_us_fine(
            kernel.get((model, scene)))}
        for model, scene in dict.fromkeys((r["model"], r["scene"]) for r in single)])


def batched_table(batched: Sequence[dict[str, Any]]) -> str:
    """Markdown: rows N, columns models (and MuJoCo), cells µs per copy-step."""
    models = list(dict.fromkeys(r["model"] for r in batched))
    sizes = sorted({r["copies"] for r in batched})
    index = {(r["model"], r["copies"]): r for r in batched}
    def cell(r: dict[str, Any] | None) -> str:
        return "–" if r is None else f"{format_us_fine(r['per_copy_step_s'])} (×{r['substeps']:,})"

    return markdown_table([{"N": str(n), **{MODEL_TITLES.get(m, m): cell(index.get((m, n)))
                                           for m in models}} for n in sizes])


def substeps_table(substeps: Sequence[dict[str, Any]]) -> str:
    """Markdown: rows models, columns substeps per call, cells µs per copy-step."""
    models = list(dict.fromkeys(r["model"] for r in substeps))
    grid = sorted({r["substeps"] for r in substeps})
    index = {(r["model"], r["substeps"]): r["per_copy_step_s"] for r in substeps}
    rows = [[MODEL_TITLES.get(m, m), *(format_us_fine(index.get((m, k))) for k in grid)]
            for m in models]
    return markdown_table(rows, ["model", *(f"{k} substeps/call" for k in grid)])


def shortcuts_table(shortcuts: Sequence[dict[str, Any]]) -> str:
    """Markdown: shortcut, model/scene, on µs, off µs, speedup, largest state difference."""
    return markdown_table([{
        "shortcut": SHORTCUT_TITLES.get(r["shortcut"], r["shortcut"]),
        "model / scene": f"{r['model']} / {_scene(r)}",
        "on µs": format_us_fine(r["on"]["per_copy_step_s"]),
        "off µs": format_us_fine(r["off"]["per_copy_step_s"]),
        "speedup off/on (medians)": f"{r['speedup']:.2f}",
        "speedup (fastest rounds)": f"{r['speedup_fastest_rounds']:.2f}",
        "largest state difference on vs off": "–" if r["max_state_difference"] is None
        else f"{r['max_state_difference']:.1e}"} for r in shortcuts])


def _scene(row: Mapping[str, Any]) -> str:
    """A shortcut row's scene, or both scenes where on and off ran different ones."""
    same = row["off_scene"] == row["scene"]
    return row["scene"] if same else f"{row['scene']} vs {row['off_scene']}"


def brake_stop_table(brake: Mapping[str, Any]) -> str:
    """Markdown: simulator/setting, steps to stop, relative angle at the stop."""
    titles = {
        "ours": "ours (ideal brake, Moreau-Jean)",
        "mujoco_default": "MuJoCo joint equality, default solref/solimp",
        "mujoco_stiffest": "MuJoCo joint equality, solref timeconst = 2 dt (stiffest allowed)",
    }
    rows = []
    for key, value in brake.items():
        setting = ""
        if "solref" in value:
            setting = (f"solref ({value['solref'][0]:g}, {value['solref'][1]:g}), solimp "
                       f"({', '.join(f'{x:g}' for x in value['solimp'][:3])})")
        elif "relative_speed_after_first_step" in value:
            speed = value["relative_speed_after_first_step"]
            setting = f"relative velocity after step 1: {speed:.1e} rad/s"
        rows.append({"simulator": titles.get(key, key), "setting": setting,
                     "steps until relative velocity < 1 % of 1 rad/s": "not reached"
                     if value["steps"] is None else str(value["steps"]),
                     "relative angle then (rad)": f"{value['relative_angle_at_stop']:.2e}"})
    return markdown_table(rows)


def markdown_report(record: Mapping[str, Any]) -> str:
    """All result tables of one run, as printed on stdout and pasted into the README."""
    lines = [run_line(record, ("numpy", "numba", "mujoco"))]
    if record["notes"]:
        lines += ["", *(f"* {note}" for note in record["notes"])]
    lines += ["", "**Targets**", "", targets_table(record["targets"])]
    lines += ["", "**Scenes**", "", scenes_table(record["models"])]
    lines += ["", "**Compile time** (first calls in this process; numba JIT, excluded from "
              "every timing below)", "", compile_table(record["compile"])]
    lines += ["", "**One step** (median µs per step; MuJoCo rows: the same arm in MJCF)", "",
              single_step_table(record["single_step"], record["per_scene"])]
    lines += ["", "**Batched: µs per copy-step of `step_batch(Q, U, TAU, BRAKE, substeps)`** "
              "(each model's scene mix, copy i in scene i mod k; in parentheses the substeps per "
              "call, sized so that one call lasts ≥ "
              f"{record['config']['call_s'] * 1e3:g} ms)", "", batched_table(record["batched"])]
    if record["substeps"]:
        copies = record["substeps"][0]["copies"]
        lines += ["", f"**Substeps per call** (µs per copy-step, each model's mix, N = {copies})",
                  "", substeps_table(record["substeps"])]
    if record["shortcuts"]:
        copies = record["shortcuts"][0]["on"]["copies"]
        lines += ["", f"**Shortcuts** (in-kernel µs per copy-step, batched N = {copies}, the "
                  "same scene on every copy; off/on > 1: the shortcut saves time)", "",
                  shortcuts_table(record["shortcuts"])]
    if record["brake_stop"]:
        lines += ["", "**Brake stop** (relative velocity 1 rad/s, link 1 at rest, no torque; "
                  "then the brake engages)", "", brake_stop_table(record["brake_stop"])]
    if "mujoco_mass_matrix_difference" in record:
        lines += ["", "MuJoCo arm check: largest |M_MuJoCo − Tᵀ M_ours T| at the scene state = "
                  f"{record['mujoco_mass_matrix_difference']:.1e}."]
    return "\n".join(lines)


def plot_batched(batched: Sequence[dict[str, Any]], substeps: Sequence[dict[str, Any]],
                 targets_us: Mapping[str, float], path: Path) -> None:
    """µs per copy-step vs N (log-log), one line per model and MuJoCo, band = quartiles.

    A second panel (if measured) shows it against the substeps per call.
    """
    panels = 2 if substeps else 1
    fig, axes = plt.subplots(1, panels, figsize=(7.5 + 4.5 * (panels - 1), 4.8), sharey=True,
                             gridspec_kw={"width_ratios": [5, 3][:panels]})
    axes = list(np.atleast_1d(axes))
    _batched_panel(axes[0], batched, "copies", "copies N per step_batch call")
    axes[0].set_title("Batched stepping (single thread), per copy-step")
    models = {r["model"] for r in batched}
    axes[0].axhline(targets_us["manipulator_batched"], color="tab:green", lw=0.9, ls=":",
                    label=f"manipulator target {targets_us['manipulator_batched']:g} µs")
    if "diff_drive" in models:
        axes[0].axhline(targets_us["diff_drive"], color="tab:red", lw=0.9, ls=":",
                        label=f"diff-drive target {targets_us['diff_drive']:g} µs")
    axes[0].set_ylabel("µs per copy-step")
    axes[0].legend(fontsize=7, loc="best")
    if substeps:
        _batched_panel(axes[1], substeps, "substeps", "substeps per call")
        axes[1].set_title(f"N = {substeps[0]['copies']}", fontsize=10)
    save_figure(fig, path)


def _batched_panel(ax: Any, rows_in: Sequence[dict[str, Any]], x_key: str, xlabel: str
                   ) -> None:
    """One log-log panel of µs per copy-step against ``x_key``, one line per model."""
    models = list(dict.fromkeys(r["model"] for r in rows_in))
    xs = sorted({r[x_key] for r in rows_in})
    for model in models:
        rows = sorted((r for r in rows_in if r["model"] == model), key=lambda r: r[x_key])
        x = [r[x_key] for r in rows]
        y = [r["per_copy_step_s"] * 1e6 for r in rows]
        style = "k--" if model == "mujoco" else "-"
        (line,) = ax.plot(x, y, style, marker="o", ms=4, label=MODEL_TITLES.get(model, model))
        ax.fill_between(x, [r["per_copy_step_q1_s"] * 1e6 for r in rows],
                        [r["per_copy_step_q3_s"] * 1e6 for r in rows],
                        color=line.get_color(), alpha=0.15)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xticks(xs, [str(x) for x in xs])
    ax.minorticks_off()
    ax.set_xlabel(xlabel)
    ax.grid(True, which="both", alpha=0.3)


def plot_single_step(single: Sequence[dict[str, Any]], scenes: Sequence[dict[str, Any]],
                     targets_us: Mapping[str, float], path: Path) -> None:
    """Horizontal bars per (model, scene): Python step, in-place step, in-kernel step."""
    index = {(r["model"], r["scene"], r["entry"]): r["median_s"] for r in single}
    kernel = {(r["model"], r["scene"]): r["per_copy_step_s"] for r in scenes}
    keys = list(dict.fromkeys((r["model"], r["scene"]) for r in single))
    series = [
        ("one step from Python: step() / mj_step", lambda m, s: index.get(
            (m, s, "mj_step" if m == "mujoco" else "step"))),
        ("InPlaceStepper.step() from Python", lambda m, s: index.get((m, s, "in_place"))),
        ("in-kernel (batched)", lambda m, s: kernel.get((m, s))),
    ]
    y = np.arange(len(keys))
    fig, ax = plt.subplots(figsize=(8.5, 0.42 * len(keys) + 1.6))
    height = 0.27
    for i, (label, get) in enumerate(series):
        values = [get(m, s) for m, s in keys]
        widths = [np.nan if v is None else v * 1e6 for v in values]
        ax.barh(y + (i - 1) * height, widths, height, label=label)
    ax.axvline(targets_us["manipulator_python"], color="tab:green", lw=0.9, ls=":",
               label=f"manipulator target (Python) {targets_us['manipulator_python']:g} µs")
    ax.set_xscale("log")
    ax.set_yticks(y, [f"{'MuJoCo' if m == 'mujoco' else m} / {s}" for m, s in keys],
                  fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("µs per step")
    ax.grid(True, axis="x", which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2, frameon=False)
    save_figure(fig, path)


def plot_shortcuts(shortcuts: Sequence[dict[str, Any]], path: Path) -> None:
    """Horizontal bars of the speedup off/on per shortcut measurement (log axis)."""
    fig, ax = plt.subplots(figsize=(8.5, 0.4 * max(len(shortcuts), 1) + 1.6))
    if shortcuts:
        labels = []
        for r in shortcuts:
            name = "no solve (free vs active)" if r["shortcut"] == "no_solve" else r["shortcut"]
            labels.append(f"{name}: {r['model']} / {_scene(r)}")
        y = np.arange(len(shortcuts))
        speedups = [r["speedup"] for r in shortcuts]
        colors = ["tab:gray" if r["shortcut"] == "no_solve" else "tab:blue" for r in shortcuts]
        fastest = [r["speedup_fastest_rounds"] for r in shortcuts]
        ax.barh(y, speedups, 0.6, color=colors, label="ratio of medians")
        ax.plot(fastest, y, "kD", ms=4, label="ratio of fastest rounds")
        for yi, r in zip(y, shortcuts, strict=True):
            ax.text(max(r["speedup"], r["speedup_fastest_rounds"]), yi,
                    f"  {format_us_fine(r['on']['per_copy_step_s'])} vs "
                    f"{format_us_fine(r['off']['per_copy_step_s'])} µs", va="center", fontsize=7)
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


__all__ = [
    "MODEL_TITLES",
    "brake_stop_table",
    "case_record",
    "markdown_report",
    "plot_batched",
    "plot_shortcuts",
    "plot_single_step",
    "shortcuts_text",
]
