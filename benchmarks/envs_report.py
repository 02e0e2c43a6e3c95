"""Reporting of ``benchmarks.envs``: Markdown tables, target checks and plots."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.report import log_lines, plt, save_figure, summary

SHORT_NAMES = {
    "mdi_envs/BlockableManipulator-v0": "BlockableManipulator",
    "mdi_envs/DiffDriveRobot-v0": "DiffDriveRobot",
}


def short_name(env_id: str) -> str:
    """A short label: ``mdi_envs/BlockableManipulator-v0`` -> ``BlockableManipulator``."""
    if env_id in SHORT_NAMES:
        return SHORT_NAMES[env_id]
    name = env_id.split("/")[-1]
    return name[:-3] if env_id.startswith("mdi_envs/") and name.endswith("-v0") else name


def markdown_report(record: Mapping[str, Any]) -> str:
    """The targets and the result tables of one run (printed on stdout)."""
    return summary(record, ("numpy", "numba", "gymnasium", "mujoco"), {
        "One env, env.step [µs] (gym.make and unwrapped; pre-sampled actions)": (
            record["single_env"] + record["unavailable"],
            ["env_id", "gym.make.median_us", "gym.make.min_us", "unwrapped.median_us",
             "frame_skip", "per_physics_step_us", "first_step_s", "error"]),
        "Vector env throughput": (record["vector_env"], [
            "env_id", "mode", "num_envs", "env_steps_per_s", "physics_steps_per_s"]),
    })


def plot_step(single: Sequence[dict[str, Any]], unavailable: Sequence[dict[str, Any]],
              targets: Mapping[str, float], path: Path) -> None:
    """Bars of ``env.step`` µs per env (gym.make and unwrapped), with the targets as lines."""
    labels = [short_name(r["env_id"]) + ("" if r["ours"] else "\n(peer)") for r in single]
    labels += [short_name(u["env_id"]) + "\n(peer)" for u in unavailable]
    x = np.arange(len(labels))
    fig, ax = plt.subplots(figsize=(max(6.5, 1.6 * len(labels) + 2.0), 4.8))
    width = 0.38
    for offset, entry, color in ((-0.5, "gym.make", "tab:blue"), (0.5, "unwrapped", "tab:gray")):
        med = [r[entry]["median_us"] for r in single]
        err = [[r[entry]["median_us"] - r[entry]["q1_us"] for r in single],
               [r[entry]["q3_us"] - r[entry]["median_us"] for r in single]]
        colors = [color if entry != "gym.make" or r["ours"] else "tab:orange" for r in single]
        bars = ax.bar(x[:len(single)] + offset * width, med, width, yerr=err, capsize=3,
                      color=colors, label=f"env.step, {entry}" if entry == "unwrapped"
                      else "env.step through gym.make (ours blue, peers orange)")
        for bar, value in zip(bars, med, strict=True):
            ax.text(bar.get_x() + bar.get_width() / 2, 0.6, f"{value:.1f}", ha="center",
                    va="bottom", fontsize=7, color="white", fontweight="bold")
    for i, item in enumerate(unavailable):
        ax.text(len(single) + i, 1.0, "not measured:\n" + item["error"][:60].replace(": ", ":\n"),
                ha="center", va="bottom", fontsize=6, color="tab:red")
    ax.axhline(targets["manipulator_step_us"], color="tab:green", ls=":", lw=1.2,
               label=f"target: manipulator ≤ {targets['manipulator_step_us']:g} µs")
    acrobot = [r for r in single if r["env_id"] == "Acrobot-v1"]
    if acrobot:
        bound = acrobot[0]["gym.make"]["median_us"] / targets["speedup_vs_acrobot"]
        ax.axhline(bound, color="tab:red", ls="--", lw=1.0,
                   label=f"target: {targets['speedup_vs_acrobot']:g}× faster than Acrobot-v1 "
                   f"(≤ {bound:.1f} µs)")
    ax.set_yscale("log")
    ax.set_ylim(bottom=0.5)
    ax.set_xticks(x, labels, fontsize=8)
    ax.set_ylabel("µs per env.step (median; bars: quartiles)")
    ax.grid(True, axis="y", which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2, frameon=False,
              title="One environment: env.step time (lower is better)",
              title_fontproperties={"size": 10})
    save_figure(fig, path)


def plot_vector(vector: Sequence[dict[str, Any]], targets: Mapping[str, float], path: Path
                ) -> None:
    """Env-steps/s and physics steps/s against num_envs (log-log), with the target line."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    rows = [{**r, "line": f"{short_name(r['env_id'])} ({r['mode']}, frame_skip "
             f"{r['frame_skip']})"} for r in vector]
    for ax, key in zip(axes, ("env_steps_per_s", "physics_steps_per_s"), strict=True):
        log_lines(ax, rows, "num_envs", key, "line", (f"{key}_q1", f"{key}_q3"),
                  dashed=lambda line: "(sync" in line)
        ax.set_xlabel("num_envs N (one core)")
        ax.set_ylabel(f"{key.replace('_', ' ')} (median; band: quartiles)")
    goal, at = targets["manipulator_physics_steps_per_s"], targets["manipulator_vector_copies"]
    axes[1].axhline(goal, color="k", ls=":", lw=1.2,
                    label=f"target: manipulator ≥ {goal:.0e} physics steps/s at N = {at}")
    axes[0].set_title("Vector env throughput: env-steps/s")
    axes[1].set_title("Vector env throughput: physics steps/s")
    for ax in axes:
        ax.legend(fontsize=7, loc="best")
    save_figure(fig, path)


__all__ = ["markdown_report", "plot_step", "plot_vector", "short_name"]
