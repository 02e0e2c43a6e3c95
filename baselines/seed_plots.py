"""The figure over training seeds of ``baselines.compare``: performance profiles and curves.

Three panels per env x objective, drawn with ``rliable.plot_utils``: the performance profile of the
success rate (fraction of runs whose success rate over the perturbed starts exceeds tau), the
profile of the optimality score (optimum / the run's mean time or effort over its successes,
1 = optimal; 0 for a run without success), and the training curves: the IQM over seeds of the
training success rate (moving mean over 100 episodes, from each run's ``STEM_curve.csv`` or
``STEM_episodes.csv``, ``run_curve``) with its 95 % stratified-bootstrap band. Bands need two
runs or more; one run is drawn as a line labelled n=1, and a row without a curve is left out
(named in the panel).
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the non-interactive backend)
import numpy as np  # noqa: E402

from baselines.aggregate import performance_profiles, training_curves  # noqa: E402
from baselines.compare import OPTIMAL  # noqa: E402

TAUS = np.linspace(0.0, 1.0, 101)
"""Profile thresholds (success rate and optimality score are both in [0, 1])."""


def optimality_score(run: dict[str, Any], objective: str) -> float:
    """Optimum / the run's mean over its successes (time or effort by ``objective``); 0 if none."""
    ratio = run["summary"]["effort_ratio" if objective == "effort" else "time_ratio"]
    return 0.0 if ratio is None else 1.0 / ratio


def run_curve(config: dict[str, Any], trained_dir: Path) -> tuple[np.ndarray, np.ndarray] | None:
    """(steps (P,), success rate (P,)) of a run in ``trained_dir``, or None.

    From its ``STEM_curve.csv`` (shipped), else from its ``STEM_episodes.csv`` (a fresh
    training folder) through ``baselines.train.training_curve``.
    """
    from baselines.train import read_episodes, run_name, training_curve

    stem = run_name(config["env_id"], config["objective"], config["algo"], int(config["seed"]))
    curve, episodes = (Path(trained_dir) / f"{stem}_{kind}.csv" for kind in ("curve", "episodes"))
    if curve.exists():
        with curve.open() as handle:
            points = [(float(r["timesteps"]), float(r["success_rate"]))
                      for r in csv.DictReader(handle)]
        return np.array([p[0] for p in points]), np.array([p[1] for p in points])
    if episodes.exists():
        return training_curve(read_episodes(episodes))
    return None


def _colours(rows: list[dict[str, Any]]) -> dict[str, Any]:
    return {row["label"]: "black" if row["label"] == OPTIMAL else f"C{index}"
            for index, row in enumerate(rows)}  # fmt: skip


def _profile_panel(ax: Any, scores: dict[str, list[float]], colours: dict[str, Any],
                   xlabel: str) -> None:  # fmt: skip
    from rliable import plot_utils

    profiles, intervals = performance_profiles(scores, TAUS)
    plot_utils.plot_performance_profiles(
        profiles, TAUS, performance_profile_cis=intervals, ax=ax,
        colors={label: colours[label] for label in profiles}, xlabel=xlabel,
        ylabel="fraction of runs > tau", labelsize="medium", ticklabelsize="small",
        xticks=[0.0, 0.25, 0.5, 0.75, 1.0])  # fmt: skip
    ax.legend(ax.lines, [f"{label} (n={len(scores[label])})" for label in profiles],
              fontsize=7, loc="lower left")  # fmt: skip


def _curve_panel(ax: Any, comparison: dict[str, Any], trained_dir: Path,
                 colours: dict[str, Any]) -> None:  # fmt: skip
    from rliable import plot_utils

    logs, missing = {}, []
    for row in comparison["controllers"]:
        if not row["trained"]:
            continue
        found = [run_curve(run["config"], trained_dir) for run in row["runs"]]
        logs[row["label"]] = [log for log in found if log is not None]
        if not logs[row["label"]]:
            missing.append(row["label"])
    for label, curve in training_curves(logs).items():
        interval = curve["ci"] if curve["ci"] is not None else np.stack([curve["iqm"]] * 2)
        plot_utils.plot_sample_efficiency_curve(
            curve["steps"], {label: curve["iqm"]}, {label: interval}, algorithms=[label],
            colors={label: colours[label]}, ax=ax, xlabel="environment steps",
            ylabel="training success rate (IQM)", labelsize="medium", ticklabelsize="small",
            marker="")  # fmt: skip
        ax.lines[-1].set_label(f"{label} (n={curve['n']}" + (", no CI)" if curve["n"] < 2
                                                              else ")"))  # fmt: skip
    if ax.lines:
        ax.legend(fontsize=7, loc="lower right")
    note = f"no training curves: {', '.join(missing)}" if missing else ""
    ax.set_title("training curves, 95 % CI over seeds" + (f"\n({note})" if note else ""),
                 fontsize=9)  # fmt: skip
    ax.set_ylim(-0.05, 1.05)


def plot_seeds(comparison: dict[str, Any], path: Path, trained_dir: Path) -> None:
    """Write the three-panel figure over runs of one env x objective to ``path`` (PNG)."""
    rows = comparison["controllers"]
    colours = _colours(rows)
    objective = comparison["objective"]
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    _profile_panel(axes[0], {row["label"]: [run["summary"]["success_rate"] for run in row["runs"]]
                             for row in rows}, colours, "success rate tau")  # fmt: skip
    axes[0].set_title("performance profile: success rate", fontsize=9)
    _profile_panel(axes[1], {row["label"]: [optimality_score(run, objective) for run in row["runs"]]
                             for row in rows}, colours,
                   f"optimal / achieved {'effort' if objective == 'effort' else 'time'} tau")
    axes[1].set_title("performance profile: optimality (0 = no success)", fontsize=9)
    _curve_panel(axes[2], comparison, trained_dir, colours)
    env = comparison["env_id"].split("/")[-1]
    fig.suptitle(f"{env}, objective {objective}: runs over training seeds "
                 f"({len(comparison['seeds'])} perturbed starts per run)")  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


__all__ = ["TAUS", "optimality_score", "plot_seeds", "run_curve"]
