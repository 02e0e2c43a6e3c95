"""The figure of ``baselines.compare``: RL trajectories over the optimum's, schedules, scores.

Four panels: two trajectory panels (manipulator: alpha(t) and beta(t); robot: the x-y path and
the heading phi(t)), the nominal episode of every run (training seed) of each controller in
colour over the optimum (black, dashed), the first run's perturbed episodes faint; the
per-step schedule of each controller's first run, nominal start (brake engaged, or the robot's
slip mode 2/3/5 DOF); and the scores over runs (IQM with 95 % CI bars of the success rate over
the perturbed starts and of the time or effort ratio to the optimum).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the non-interactive backend)
import numpy as np  # noqa: E402

from baselines.compare import OPTIMAL  # noqa: E402

MODE_COLOURS = {2: "#4c72b0", 3: "#dd8452", 5: "#c44e52"}
"""Slip mode (DOF) -> colour: 2 rolling, 3 one wheel slipping, 5 both slipping."""


def _colour(index: int, label: str) -> str:
    return "black" if label == OPTIMAL else f"C{index}"


def _trajectory_panels(axes: Any, comparison: dict[str, Any]) -> None:
    robot = "DiffDrive" in comparison["env_id"]
    for index, row in enumerate(comparison["controllers"]):
        colour, optimal = _colour(index, row["label"]), row["label"] == OPTIMAL
        style = {"color": colour, "lw": 2.2 if optimal else 1.4, "ls": "--" if optimal else "-"}
        for episode in row["runs"][0]["episodes"]:
            _draw(axes, episode, robot, {"color": colour, "lw": 0.6, "alpha": 0.15})
        runs = len(row["runs"])
        label = row["label"] + (f" ({runs} seeds)" if row["trained"] else "")
        for number, run in enumerate(row["runs"]):
            _draw(axes, run["nominal"], robot,
                  {**style, "label": label} if number == 0 else {**style, "lw": 0.9})
    if robot:
        axes[0].set(xlabel="x [m]", ylabel="y [m]", title="path (nominal start; faint: perturbed)")
        axes[0].set_aspect("equal", adjustable="datalim")
        axes[1].set(xlabel="t [s]", ylabel="heading phi [rad]", title="heading")
    else:
        axes[0].set(xlabel="t [s]", ylabel="alpha [rad]",
                    title="link 1 (nominal; faint: perturbed)")
        axes[1].set(xlabel="t [s]", ylabel="beta [rad]", title="link 2")
    axes[0].legend(fontsize=7, loc="best")
    for ax in axes:
        ax.grid(alpha=0.3)


def _draw(axes: Any, episode: Any, robot: bool, style: dict[str, Any]) -> None:
    q, t = episode.q, episode.time
    if not q.size:  # a row merged from a JSON without its trajectories
        return
    if robot:
        axes[0].plot(q[:, 0], q[:, 1], **style)
        axes[1].plot(t, q[:, 2], **style)
    else:
        axes[0].plot(t, q[:, 0], **style)
        axes[1].plot(t, q[:, 1], **style)


def _schedule_panel(ax: Any, comparison: dict[str, Any]) -> None:
    robot = "DiffDrive" in comparison["env_id"]
    rows = comparison["controllers"]
    for level, row in enumerate(rows):
        episode = row["runs"][0]["nominal"]
        t, schedule = episode.time, episode.schedule
        if not schedule.size:
            continue
        if robot:
            for mode, colour in MODE_COLOURS.items():
                on = np.append(schedule == mode, False)
                ax.fill_between(t, level, level + 0.8, where=on, step="post", color=colour,
                                lw=0, label=f"{mode}-DOF" if level == 0 else None)  # fmt: skip
        else:
            on = np.append(schedule > 0.5, False)
            ax.fill_between(t, level, level + 0.8, where=on, step="post",
                            color=_colour(level, row["label"]), lw=0)  # fmt: skip
    labels = [row["label"] + (f" seed {row['runs'][0]['seed']}" if row["trained"] else "")
              for row in rows]  # fmt: skip
    ax.set_yticks(np.arange(len(rows)) + 0.4, labels, fontsize=7)
    ax.set_xlabel("t [s]")
    ax.set_title("slip mode per step (nominal)" if robot else "brake engaged (nominal)")
    if robot:
        ax.legend(fontsize=7, loc="upper right")
    ax.grid(alpha=0.3, axis="x")


def _bars(ax: Any, positions: np.ndarray, estimates: list[dict[str, Any]], colour: str,
          label: str) -> None:  # fmt: skip
    """IQM bars with 95 % CI error bars (none for one run)."""
    heights = np.array([e["iqm"] if e["iqm"] is not None else 0.0 for e in estimates])
    errors = np.array([[h - e["ci"][0], e["ci"][1] - h] if e["ci"] is not None else [0.0, 0.0]
                       for h, e in zip(heights, estimates, strict=True)]).T  # fmt: skip
    ax.bar(positions, heights, 0.4, color=colour, label=label, yerr=errors, capsize=3,
           error_kw={"lw": 0.8})  # fmt: skip


def _score_panel(ax: Any, comparison: dict[str, Any]) -> None:
    rows = comparison["controllers"]
    ratio_key = "effort_ratio" if comparison["objective"] == "effort" else "time_ratio"
    name = ratio_key.split("_")[0]
    positions = np.arange(len(rows))
    _bars(ax, positions - 0.2, [row["aggregate"]["success_rate"] for row in rows], "C2",
          "success rate")  # fmt: skip
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("success rate (perturbed starts)")
    twin = ax.twinx()
    _bars(twin, positions + 0.2, [row["aggregate"][ratio_key] for row in rows], "C7",
          f"{name} / optimal")  # fmt: skip
    twin.axhline(1.0, color="black", lw=0.8, ls=":")
    twin.set_ylabel(f"{name} / optimal (successes)")
    labels = [row["label"] + (f"\n(n={len(row['runs'])})" if row["trained"] else "")
              for row in rows]  # fmt: skip
    ax.set_xticks(positions, labels, fontsize=7, rotation=15)
    handles = ax.get_legend_handles_labels()[0] + twin.get_legend_handles_labels()[0]
    ax.legend(handles, [h.get_label() for h in handles], fontsize=7, loc="upper right")
    ax.set_title(f"IQM and 95 % CI over runs, {len(comparison['seeds'])} perturbed starts each")


def plot_comparison(comparison: dict[str, Any], path: Path) -> None:
    """Write the four-panel comparison figure of one env x objective to ``path`` (PNG)."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    _trajectory_panels(axes[0], comparison)
    _schedule_panel(axes[1, 0], comparison)
    _score_panel(axes[1, 1], comparison)
    env = comparison["env_id"].split("/")[-1]
    fig.suptitle(f"{env}, objective {comparison['objective']}: RL vs optimal reference "
                 f"({comparison['reference']}, {comparison['optimal_time']:.3f} s)")  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


__all__ = ["plot_comparison"]
