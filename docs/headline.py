"""The headline results (RL vs MPC vs optimal) from the committed comparison JSON.

``python docs/headline.py`` prints the README's results table (the v1 ids) and writes its plot,
``docs/assets/headline.png``; ``docs/gen_pages.py`` uses the same table, with the v0 ids, on
the results page.
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


def current(studies: list[Study]) -> list[Study]:
    """The studies of the current (v1) ids: the README's table and plot."""
    return [study for study in studies if study.env_id.endswith("-v1")]


ROW_ORDER = ("optimal", "MPC", "LQR", "DAgger", "PPO", "HybridPPO", "SAC")
"""Rows by kind: the reference, model-based control, the distilled and RL policies, then the
heuristic floor (any label not listed)."""


def ordered(rows: Sequence[Row]) -> list[Row]:
    """The rows in ``ROW_ORDER`` by the first word of their label (stable within a kind)."""
    def rank(row: Row) -> int:
        kind = row.label.split()[0]
        return ROW_ORDER.index(kind) if kind in ROW_ORDER else len(ROW_ORDER)
    return sorted(rows, key=rank)


NOT_PLAYED = Estimate(n=0, missing=0, mean=None, iqm=None, ci=None, values=[])
"""The scores of a row not played under a condition (shown as "n/a")."""


def _scores(study: Study, row: Row, condition: str) -> tuple[Estimate, Estimate]:
    """The row's success rate and its ratio to the optimum (time or effort, the objective's).

    ``NOT_PLAYED`` twice where the row has no run under ``condition``.
    """
    aggregate = row.aggregate(condition)
    if aggregate is None:
        return NOT_PLAYED, NOT_PLAYED
    return aggregate.success_rate, getattr(aggregate, f"{study.objective}_ratio")


def _text(row: Row, estimate: Estimate, percent: bool = False) -> str:
    """IQM [CI] over a trained row's runs; an untrained controller's one value alone."""
    if estimate is NOT_PLAYED:
        return "n/a"
    if row.trained or estimate.iqm is None:
        return interval_text(estimate, percent)
    return f"{100 * estimate.iqm:.0f} %" if percent else f"{estimate.iqm:.2f}"


def headline_frame(studies: list[Study]) -> pd.DataFrame:
    """One row per env x objective x controller; per start noise, success and ratio IQM [CI].

    The columns name the start-perturbation scale of each study condition (0.01 and 0.1 in the
    committed comparisons); the ratio is time (or effort) over the optimum's on the successes.
    """
    rows = []
    for study in studies:
        for row in ordered(study.rows):
            record = {"env": study.env_id.removeprefix("mdi_envs/"),
                      "objective": study.objective, "controller": row.label,
                      "runs": len(row.at(study.conditions[0].label))}
            scored = [(c.scale, *_scores(study, row, c.label)) for c in study.conditions]
            for scale, success, _ in scored:
                record[f"success, noise {scale:g}"] = _text(row, success, percent=True)
            for scale, _, ratio in scored:
                record[f"ratio, noise {scale:g}"] = _text(row, ratio)
            rows.append(record)
    return pd.DataFrame(rows)


def headline_plot(studies: list[Study], path: Path = PLOT) -> Path:
    """Per study a panel: success (bars) and ratio to the optimum (dots) per controller.

    One bar and one dot per start noise (light: the first condition, dark: the last).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    columns = min(3, len(studies))
    rows = -(-len(studies) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.6 * columns, 3.6 * rows), squeeze=False)
    for ax in axes.flat[len(studies):]:
        ax.set_visible(False)
    for ax, study in zip(axes.flat, studies, strict=False):
        controllers = ordered(study.rows)
        twin = ax.twinx()
        top = 2.2
        width = 0.8 / len(study.conditions)
        for k, condition in enumerate(study.conditions):
            shade = 0.45 + 0.45 * k / max(1, len(study.conditions) - 1)
            offset = (k - (len(study.conditions) - 1) / 2) * width
            success, ratio = zip(*(_scores(study, row, condition.label) for row in controllers),
                                 strict=True)
            x = [i + offset for i in range(len(controllers))]
            ax.bar(x, [s.iqm or 0.0 for s in success], width=width, color="tab:green",
                   alpha=shade, yerr=_errors(success), capsize=2,
                   label=f"success, noise {condition.scale:g}")
            shown = [i for i, r in enumerate(ratio) if r.iqm is not None]
            top = max([top] + [1.1 * ratio[i].iqm for i in shown])
            twin.errorbar([x[i] for i in shown], [ratio[i].iqm for i in shown],
                          yerr=_errors([ratio[i] for i in shown]), fmt="o", markersize=4,
                          color=str(0.6 * (1 - k / max(1, len(study.conditions) - 1))),
                          capsize=2, label=f"ratio, noise {condition.scale:g}")
        ax.set_ylim(0, 1.05)
        ax.set_xticks(range(len(controllers)), [_short(r.label) for r in controllers],
                      fontsize=7, rotation=35, ha="right")
        ax.set_title(f"{study.env_id.removeprefix('mdi_envs/')}, {study.objective}", fontsize=9)
        twin.axhline(1.0, color="gray", lw=0.8, ls=":")
        twin.set_ylim(0, top)
        if ax is axes[0][0]:
            ax.set_ylabel("success rate (IQM, 95 % CI)")
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
    "MPC (tracking window), state-indexed, parking": "MPC, by state, parking",
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
    studies = current(comparisons())
    print(headline_frame(studies).to_markdown(index=False))
    print(f"wrote {headline_plot(studies).relative_to(ROOT)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
