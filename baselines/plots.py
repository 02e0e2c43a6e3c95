"""The figures of the baselines: comparison, runs over seeds, robustness, one training run.

- ``plot_comparison``: the nominal trajectories of every controller over the optimum's (black,
  dashed; manipulator alpha(t), beta(t); robot x-y path and heading), the first run's perturbed
  episodes faint; the per-step schedule of each row's first run (brake engaged, or slip mode
  2/3/5 DOF); the IQM with 95 % CI bars of the success rate and the time or effort ratio.
- ``plot_seeds``: rliable performance profiles of the success rate and of the optimality score
  (optimum / the run's mean time or effort over its successes; 0 without success), and the
  training curves (IQM over seeds of the training success rate, log step axis, 95 % band).
- ``plot_brake_use``: the brake's engaged intervals from the nominal start for every run (each
  training seed its own line) against the optimum's, and the engagements per perturbed episode.
- ``plot_robustness``: success against the start perturbation scale, and under each mismatch.
- ``plot_training``: one run's episode return and success rate against environment steps.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the non-interactive backend)
import numpy as np  # noqa: E402

from baselines.records import (  # noqa: E402
    DEFAULT_SCALE,
    OPTIMAL,
    Episode,
    Estimate,
    Row,
    Study,
    Training,
)

MODE_COLOURS = {2: "#4c72b0", 3: "#dd8452", 5: "#c44e52"}
"""Slip mode (DOF) -> colour: 2 rolling, 3 one wheel slipping, 5 both slipping."""

TAUS = np.linspace(0.0, 1.0, 101)
"""Profile thresholds (success rate and optimality score are both in [0, 1])."""


def _colour(index: int, label: str) -> str:
    return "black" if label == OPTIMAL else f"C{index}"


def _save(fig: Any, path: Path, dpi: int = 110) -> Path:
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return Path(path)


def _draw(axes: Any, episode: Episode | None, robot: bool, style: dict[str, Any]) -> None:
    if episode is None or episode.trajectory is None:
        return
    q, t = np.asarray(episode.trajectory.q), np.asarray(episode.trajectory.time)
    axes[0].plot(*((q[:, 0], q[:, 1]) if robot else (t, q[:, 0])), **style)
    axes[1].plot(t, q[:, 2] if robot else q[:, 1], **style)


def _trajectory_panels(axes: Any, study: Study, condition: str) -> None:
    robot = "DiffDrive" in study.env_id
    for index, row in enumerate(study.rows):
        runs = row.at(condition)
        colour, optimal = _colour(index, row.label), row.label == OPTIMAL
        style = {"color": colour, "lw": 2.2 if optimal else 1.4, "ls": "--" if optimal else "-"}
        for episode in runs[0].episodes if runs else []:
            _draw(axes, episode, robot, {"color": colour, "lw": 0.6, "alpha": 0.15})
        label = row.label + (f" ({len(runs)} seeds)" if row.trained else "")
        for number, run in enumerate(runs):
            _draw(axes, run.nominal, robot,
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


def _schedule_panel(ax: Any, study: Study, condition: str) -> None:
    robot = "DiffDrive" in study.env_id
    for level, row in enumerate(study.rows):
        runs = row.at(condition)
        nominal = runs[0].nominal if runs else None
        if nominal is None or nominal.trajectory is None or not nominal.trajectory.schedule:
            continue
        t, schedule = np.asarray(nominal.trajectory.time), np.asarray(nominal.trajectory.schedule)
        for mode, colour in MODE_COLOURS.items() if robot else [(None, None)]:
            on = np.append(schedule == mode if robot else schedule > 0.5, False)
            ax.fill_between(t, level, level + 0.8, where=on, step="post", lw=0,
                            color=colour if robot else _colour(level, row.label),
                            label=f"{mode}-DOF" if robot and level == 0 else None)  # fmt: skip
    labels = [row.label + (f" seed {row.at(condition)[0].seed}" if row.trained else "")
              for row in study.rows]  # fmt: skip
    ax.set_yticks(np.arange(len(study.rows)) + 0.4, labels, fontsize=7)
    ax.set_xlabel("t [s]")
    ax.set_title("slip mode per step (nominal)" if robot else "brake engaged (nominal)")
    if robot:
        ax.legend(fontsize=7, loc="upper right")
    ax.grid(alpha=0.3, axis="x")


def _bars(ax: Any, positions: np.ndarray, estimates: list[Estimate], colour: str,
          label: str) -> None:  # fmt: skip
    """IQM bars with 95 % CI error bars (none for one run)."""
    heights = np.array([e.iqm if e.iqm is not None else 0.0 for e in estimates])
    errors = np.array([[h - e.ci[0], e.ci[1] - h] if e.ci is not None else [0.0, 0.0]
                       for h, e in zip(heights, estimates, strict=True)]).T  # fmt: skip
    ax.bar(positions, heights, 0.4, color=colour, label=label, yerr=errors, capsize=3,
           error_kw={"lw": 0.8})  # fmt: skip


def _score_panel(ax: Any, study: Study, condition: str) -> None:
    rows = [row for row in study.rows if row.aggregate(condition) is not None]
    aggregates = [row.aggregate(condition) for row in rows]
    ratio = "effort" if study.objective == "effort" else "time"
    positions = np.arange(len(rows))
    _bars(ax, positions - 0.2, [a.success_rate for a in aggregates if a], "C2", "success rate")
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("success rate (perturbed starts)")
    twin = ax.twinx()
    _bars(twin, positions + 0.2, [getattr(a, f"{ratio}_ratio") for a in aggregates if a], "C7",
          f"{ratio} / optimal")  # fmt: skip
    twin.axhline(1.0, color="black", lw=0.8, ls=":")
    twin.set_ylabel(f"{ratio} / optimal (successes)")
    labels = [row.label + (f"\n(n={len(row.at(condition))})" if row.trained else "")
              for row in rows]  # fmt: skip
    ax.set_xticks(positions, labels, fontsize=7, rotation=15)
    handles = ax.get_legend_handles_labels()[0] + twin.get_legend_handles_labels()[0]
    ax.legend(handles, [h.get_label() for h in handles], fontsize=7, loc="upper right")
    ax.set_title(f"IQM and 95 % CI over runs, {study.num_starts} perturbed starts each")


def plot_comparison(study: Study, path: Path, condition: str | None = None) -> Path:
    """Write the four-panel comparison figure of ``condition`` (default the first) to ``path``."""
    condition = condition or study.conditions[0].label
    study = dataclasses.replace(study, rows=[row for row in study.rows if row.at(condition)])
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    _trajectory_panels(axes[0], study, condition)
    _schedule_panel(axes[1, 0], study, condition)
    _score_panel(axes[1, 1], study, condition)
    fig.suptitle(f"{study.env_id.split('/')[-1]}, {study.objective}, {condition}: RL vs "
                 f"optimal reference ({study.reference}, {study.optimal_time:.3f} s)")
    return _save(fig, path)


def plot_brake_use(study: Study, path: Path, condition: str | None = None) -> Path:
    """Write the brake-use figure of ``condition`` (default the first) to ``path``.

    Left: per run (seed), the intervals with the brake engaged from the nominal start
    (``baselines.tables.engaged_intervals``), rows grouped by controller, the optimum on top.
    Right: engagements per perturbed episode per controller (points jittered), the optimum's
    as a dotted line.
    """
    from baselines.tables import engaged_intervals

    condition = condition or study.conditions[0].label
    rows = [row for row in study.rows if row.at(condition)]
    num_runs = sum(len(row.at(condition)) for row in rows)
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 2.0 + 0.3 * num_runs),
                                      width_ratios=(2, 1))  # fmt: skip
    labels, level = [], 0
    rng = np.random.default_rng(0)
    for index, row in enumerate(rows):
        colour = _colour(index, row.label)
        for run in row.at(condition):
            for start, end in engaged_intervals(run.nominal):
                left.broken_barh([(start, max(end - start, 1e-3))], (-level - 0.4, 0.8),
                                 color=colour)  # fmt: skip
            labels.append(row.label + (f" seed {run.seed}" if row.trained else ""))
            level += 1
        counts = [e.brake_use.engagements for run in row.at(condition) for e in run.episodes
                  if e.brake_use is not None]  # fmt: skip
        right.scatter(counts, index + rng.uniform(-0.25, 0.25, len(counts)), s=8,
                      color=colour, alpha=0.6)  # fmt: skip
        if row.label == OPTIMAL and counts:
            right.axvline(counts[0], color="black", ls=":", lw=0.8)
    left.set_yticks(-np.arange(level), labels, fontsize=7)
    left.set_ylim(-level + 0.5, 0.5)
    left.set(xlabel="t [s]", title="brake engaged, nominal start (each run)")
    left.grid(alpha=0.3, axis="x")
    right.set_yticks(np.arange(len(rows)), [row.label for row in rows], fontsize=7)
    right.set_ylim(len(rows) - 0.5, -0.5)
    right.set(xlabel="engagements per episode", title=f"{condition}, perturbed starts")
    right.grid(alpha=0.3, axis="x")
    fig.suptitle(f"{study.env_id.split('/')[-1]}: brake use against the optimal reference")
    return _save(fig, path)


def read_curve(training: Training, trained_dir: Path) -> tuple[np.ndarray, np.ndarray] | None:
    """(steps (P,), success rate (P,)) of a run in ``trained_dir``; None without its files.

    From its ``STEM_curve.csv``, else its ``STEM_episodes.csv`` (``baselines.train``).
    """
    import pandas as pd

    from baselines.aggregate import sampled_curve

    curve, episodes = (Path(trained_dir) / f"{training.stem}_{kind}.csv"
                       for kind in ("curve", "episodes"))  # fmt: skip
    if curve.exists():
        frame = pd.read_csv(curve)
        return frame["timesteps"].to_numpy(float), frame["success_rate"].to_numpy(float)
    if not episodes.exists():
        return None
    frame = pd.read_csv(episodes)
    return sampled_curve(frame["timesteps"].to_numpy(float), frame["is_success"].to_numpy(float))


def _profile_panel(ax: Any, scores: dict[str, list[float]], colours: dict[str, str],
                   xlabel: str, title: str, reps: int) -> None:  # fmt: skip
    from rliable import plot_utils

    from baselines.aggregate import performance_profiles

    profiles, intervals = performance_profiles(scores, TAUS, reps=reps)
    plot_utils.plot_performance_profiles(
        profiles, TAUS, performance_profile_cis=intervals, ax=ax,
        colors={label: colours[label] for label in profiles}, xlabel=xlabel,
        ylabel="fraction of runs > tau", labelsize="medium", ticklabelsize="small",
        xticks=[0.0, 0.25, 0.5, 0.75, 1.0])  # fmt: skip
    ax.legend(ax.lines, [f"{label} (n={len(scores[label])})" for label in profiles],
              fontsize=7, loc="lower left")  # fmt: skip
    ax.set_title(title, fontsize=9)


def _curve_panel(ax: Any, rows: Sequence[Row], condition: str, trained_dir: Path,
                 colours: dict[str, str], reps: int) -> None:  # fmt: skip
    from rliable import plot_utils

    from baselines.aggregate import training_curves

    logs, missing = {}, []
    for row in rows:
        if row.trained:
            found = [read_curve(run.training, trained_dir) for run in row.at(condition)
                     if run.training is not None]  # fmt: skip
            logs[row.label] = [log for log in found if log is not None]
            missing += [] if logs[row.label] else [row.label]
    for label, curve in training_curves(logs, reps=reps).items():
        interval = curve.ci if curve.ci is not None else np.stack([curve.iqm] * 2)
        plot_utils.plot_sample_efficiency_curve(
            curve.steps, {label: curve.iqm}, {label: interval}, algorithms=[label],
            colors={label: colours[label]}, ax=ax, xlabel="environment steps (log)",
            ylabel="training success rate (IQM)", labelsize="medium", ticklabelsize="small",
            marker="")  # fmt: skip
        ax.lines[-1].set_label(f"{label} (n={curve.n}" + (", no CI)" if curve.n < 2 else ")"))
    if ax.lines:
        ax.set_xscale("log")
        ax.legend(fontsize=7, loc="lower right")
    note = f"\n(no training curves: {', '.join(missing)})" if missing else ""
    ax.set_title("training curves, 95 % CI over seeds" + note, fontsize=9)
    ax.set_ylim(-0.05, 1.05)


def plot_seeds(study: Study, path: Path, trained_dir: Path, condition: str | None = None,
               reps: int | None = None) -> Path:  # fmt: skip
    """Write the three-panel figure over runs of ``condition`` (default the first) to ``path``.

    ``reps``: bootstrap replications of the bands (default ``aggregate.BOOTSTRAP_REPS``).
    """
    from baselines.aggregate import BOOTSTRAP_REPS, optimality_score

    reps = BOOTSTRAP_REPS if reps is None else reps
    condition = condition or study.conditions[0].label
    rows = [row for row in study.rows if row.at(condition)]
    colours = {row.label: _colour(index, row.label) for index, row in enumerate(rows)}
    ratio = "effort" if study.objective == "effort" else "time"
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    _profile_panel(axes[0], {row.label: [run.scores.success_rate for run in row.at(condition)]
                             for row in rows}, colours, "success rate tau",
                   "performance profile: success rate", reps)  # fmt: skip
    _profile_panel(axes[1], {row.label: [optimality_score(getattr(run.scores, f"{ratio}_ratio"))
                                         for run in row.at(condition)] for row in rows},
                   colours, f"optimal / achieved {ratio} tau",
                   "performance profile: optimality (0 = no success)", reps)  # fmt: skip
    _curve_panel(axes[2], rows, condition, trained_dir, colours, reps)
    fig.suptitle(f"{study.env_id.split('/')[-1]}, {study.objective}, {condition}: runs over "
                 f"training seeds ({study.num_starts} perturbed starts per run)")
    return _save(fig, path)


def plot_robustness(study: Study, path: Path) -> Path:
    """Success against the perturbation scale per controller, and under each mismatch.

    Each mismatch bar is labelled with its success in % ("n/a": that cell was not played).
    """
    scaled = [c for c in study.conditions if c.mismatch is None]
    mismatched = [c for c in study.conditions if c.mismatch is not None]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 5))
    width = 0.8 / max(len(study.rows), 1)
    for k, row in enumerate(study.rows):
        success = {a.condition: 100 * (a.success_rate.mean or 0.0) for a in row.aggregates}
        played = [c for c in scaled if c.label in success]
        runs = max(a.success_rate.n for a in row.aggregates)
        left.plot([c.scale for c in played], [success[c.label] for c in played], "o-",
                  label=f"{row.label} ({runs} run{'s' * (runs > 1)})")
        positions = np.arange(len(mismatched)) + k * width
        heights = [success.get(c.label, np.nan) for c in mismatched]
        right.bar(positions, heights, width, label=row.label)
        for position, height in zip(positions, heights, strict=True):  # a 0 % bar has no height
            right.text(position, 1.0 if np.isnan(height) else height + 1.0,
                       "n/a" if np.isnan(height) else f"{height:.0f}", ha="center",
                       va="bottom", rotation=90, fontsize=6)  # fmt: skip
    left.set(xscale="log", xlabel="start perturbation scale [rad, rad/s, m, m/s]",
             ylabel="success [%]", ylim=(-3, 103),
             title=f"{study.env_id.split('/')[-1]} {study.objective}: perturbed starts")
    left.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=2)
    right.set_xticks(np.arange(len(mismatched)) + width * (len(study.rows) - 1) / 2)
    right.set_xticklabels([c.label for c in mismatched], fontsize=8)
    right.set(ylabel="success [%]", ylim=(0, 115),
              title=f"model mismatch (scale {DEFAULT_SCALE:g})")
    return _save(fig, path, dpi=120)


def plot_training(rows: Sequence[tuple[Any, ...]], path: Path, title: str = "",
                  window: int = 100) -> Path:  # fmt: skip
    """Episode return and success rate vs environment steps (moving mean over ``window``).

    ``rows``: the training episodes (``baselines.train.EPISODE_COLUMNS``).
    """
    fig, (ax_return, ax_success) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    if rows:
        data = np.array([r[:4] for r in rows], dtype=float)
        steps, returns, success = data[:, 0], data[:, 1], data[:, 3]
        kernel = np.ones(min(window, len(rows)))
        counts = np.convolve(np.ones(len(rows)), kernel)[: len(rows)]
        ax_return.plot(steps, returns, ".", ms=2, alpha=0.3, color="C0", label="episode")
        ax_return.plot(steps, np.convolve(returns, kernel)[: len(rows)] / counts, color="C0",
                       label=f"mean of last {len(kernel)}")  # fmt: skip
        ax_success.plot(steps, np.convolve(success, kernel)[: len(rows)] / counts, color="C2")
        ax_return.legend(loc="lower right")
    else:
        ax_return.text(0.5, 0.5, "no finished episode", ha="center", transform=ax_return.transAxes)
    ax_return.set_ylabel("episode return [-]")
    ax_success.set(ylabel="success rate", ylim=(-0.05, 1.05), xlabel="environment steps")
    for ax in (ax_return, ax_success):
        ax.grid(alpha=0.3)
    fig.suptitle(title)
    return _save(fig, path)


__all__ = ["TAUS", "plot_comparison", "plot_robustness", "plot_seeds",
           "plot_training", "read_curve"]
