"""The headline results (RL vs MPC vs optimal) from the committed comparison JSON.

``python docs/headline.py`` prints the README's results table and writes its plot,
``docs/assets/headline.png``; ``docs/gen_pages.py`` uses the same table on the results page.
The numbers come from ``baselines/comparison/compare_*.json`` (``mdi-envs compare all``).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from baselines.records import Estimate, Row, Study, read_study
from baselines.tables import interval_text

ROOT = Path(__file__).resolve().parent.parent
COMPARISON_DIR = ROOT / "baselines" / "comparison"
PLOT = ROOT / "docs" / "assets" / "headline.png"


def comparisons(folder: Path = COMPARISON_DIR) -> list[Study]:
    """Every committed ``compare_*.json`` (``baselines.records.read_study``): v0 ids first."""
    studies = [read_study(p) for p in sorted(folder.glob("compare_*.json"))]
    return sorted(studies, key=lambda study: study.env_id.rsplit("-", 1)[-1])


def _scores(study: Study, row: Row) -> tuple[Estimate, Estimate]:
    """The row's success rate and its ratio to the optimum (time or effort, the objective's)."""
    aggregate = row.aggregate(study.conditions[0].label)
    if aggregate is None:
        raise ValueError(f"{study.name}: row {row.label!r} has no aggregate")
    return aggregate.success_rate, getattr(aggregate, f"{study.objective}_ratio")


def _text(row: Row, estimate: Estimate, percent: bool = False) -> str:
    """IQM [CI] over a trained row's runs; an untrained controller's one value alone."""
    if row.trained or estimate.iqm is None:
        return interval_text(estimate, percent)
    return f"{100 * estimate.iqm:.0f} %" if percent else f"{estimate.iqm:.2f}"


def headline_frame(studies: list[Study]) -> pd.DataFrame:
    """One row per env x objective x controller: success and ratio to the optimum, IQM [CI]."""
    rows = []
    for study in studies:
        for row in study.rows:
            success, ratio = _scores(study, row)
            rows.append({"env": study.env_id.removeprefix("mdi_envs/"),
                         "objective": study.objective, "controller": row.label,
                         "runs": success.n + success.missing,
                         "success": _text(row, success, percent=True),
                         "time or effort / optimal": _text(row, ratio)})
    return pd.DataFrame(rows)


def headline_plot(studies: list[Study], path: Path = PLOT) -> Path:
    """Success (bars) and ratio to the optimum (dots) per controller; a panel per study, 3 a row."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    columns = min(3, len(studies))
    rows = -(-len(studies) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.4 * rows), squeeze=False)
    for ax in axes.flat[len(studies):]:
        ax.set_visible(False)
    for ax, study in zip(axes.flat, studies, strict=False):
        labels = [_short(row.label) for row in study.rows]
        success, ratio = zip(*(_scores(study, row) for row in study.rows), strict=True)
        x = range(len(labels))
        ax.bar(x, [s.iqm or 0.0 for s in success], color="tab:green", alpha=0.8,
               yerr=_errors(success), capsize=3, label="success (IQM, 95 % CI)")
        ax.set_ylim(0, 1.05)
        ax.set_xticks(list(x), labels, fontsize=7, rotation=35, ha="right")
        ax.set_title(f"{study.env_id.removeprefix('mdi_envs/')}, {study.objective}", fontsize=9)
        twin = ax.twinx()
        shown = [i for i, r in enumerate(ratio) if r.iqm is not None]
        twin.errorbar(shown, [ratio[i].iqm for i in shown],
                      yerr=_errors([ratio[i] for i in shown]), fmt="o", color="black",
                      capsize=3, label="time or effort / optimal")
        twin.axhline(1.0, color="gray", lw=0.8, ls=":")
        twin.set_ylim(0, max([2.2] + [1.1 * ratio[i].iqm for i in shown]))
        if ax is axes[0][0]:
            ax.set_ylabel("success rate")
            ax.legend(loc="lower left", fontsize=7)
        if ax is axes[0][columns - 1]:
            twin.set_ylabel("time or effort / optimal")
            twin.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


SHORT_LABELS = {
    "optimal (open loop)": "optimal, open loop", "LQR (time-varying)": "LQR",
    "MPC (shrinking horizon)": "MPC, shrinking", "MPC (tracking window)": "MPC, tracking",
    "MPC (tracking window), state-indexed": "MPC, tracking by state",
    "rigid-arm bang-bang": "bang-bang floor", "rolling path follower": "rolling floor",
}
"""Row labels as the plot's tick labels."""


def _short(label: str) -> str:
    return SHORT_LABELS.get(label, label)


def _errors(estimates: Sequence[Estimate]) -> list[list[float]]:
    """Asymmetric error bars (2, k) from IQM and CI (zero without a CI)."""
    low, high = [], []
    for e in estimates:
        iqm = e.iqm or 0.0
        ci = e.ci or (iqm, iqm)
        low.append(iqm - ci[0])
        high.append(ci[1] - iqm)
    return [low, high]


def main() -> int:
    """Print the README table and write the plot."""
    studies = comparisons()
    print(headline_frame(studies).to_markdown(index=False))
    print(f"wrote {headline_plot(studies).relative_to(ROOT)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
