"""Reporting of ``benchmarks.solvers``: aggregation, Markdown tables and plots."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.report import bars, log_lines, plt, save_figure, summary

ENTRY_KEYS = ("driver", "kernel", "quantecon")
"""Keys of the three timed entries in each row of the QuantEcon comparison."""
RESIDUAL_FLOOR = 1e-18
"""Residuals of exactly zero are drawn at this value on log axes."""
ENTRY_TITLES = {"quantecon": "QuantEcon lcp_lemke"}


def _median(values: Iterable[float]) -> float:
    """Median of an iterable of floats (NaN when empty)."""
    array = np.fromiter(values, dtype=float)
    return float(np.median(array)) if array.size else float("nan")


def aggregate_size_study(records: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Combine the instances of each (family, n, entry) of the work-size study."""
    groups: dict[tuple[str, int, str], list[dict[str, Any]]] = {}
    for record in records:
        groups.setdefault((record["family"], record["n"], record["entry"]), []).append(record)
    rows = []
    for (family, n, entry), group in groups.items():
        times = [r["time"]["median_s"] for r in group]
        rows.append({
            "family": family, "n": n, "entry": entry, "time_median_s": _median(times),
            "time_min_s": min(times), "time_max_s": max(times),
            "residual_max": max(r["outcome"]["residual"] for r in group),
            "iterations_median": _median(r["outcome"]["iterations"] for r in group),
            "solved": sum(r["outcome"]["success"] for r in group), "instances": len(group)})
    return rows


def ratio_summary(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Median time ratios ours/QuantEcon over problem sets, for both of our entry points."""
    solved = [r for r in rows if all(r[k]["outcome"]["success"] for k in ENTRY_KEYS)]
    sets = {
        "Siconos peer files": [r for r in rows if r["family"] == "siconos"],
        "random (spd + contact)": [r for r in rows if r["family"] != "siconos"],
        "random spd (target: driver / QE <= 1)": [r for r in rows if r["family"] == "spd"],
        "random contact": [r for r in rows if r["family"] == "contact"],
        "Siconos peer files solved by all three": [r for r in solved if r["family"] == "siconos"],
    }
    return [{"set": name, "problems": len(members),
             "median_ratio_driver": _median(r["ratio_driver"] for r in members),
             "median_ratio_kernel": _median(r["ratio_kernel"] for r in members)}
            for name, members in sets.items() if members]


def markdown_report(record: dict[str, Any]) -> str:
    """The result tables of one run (printed on stdout)."""
    first = record["first_call"]
    comparison = record["quantecon_comparison"]
    return summary(record, ("numpy", "numba", "quantecon"), {
        "First call per entry [s] (fresh interpreter)": [
            {"probe": probe, **result.get("first_call_s", result)}
            for probe, result in first.items()],
        "Work vs size (median over instances; our methods through solve_lcp)": (
            record["size_study"]["aggregates"], ["family", "n", "entry", "time_median_s",
                                                 "iterations_median", "residual_max", "solved",
                                                 "instances"]),
        "Lemke vs QuantEcon per problem (median time per solve [s])": (comparison["problems"], [
            "name", "n", "driver.time.median_s", "kernel.time.median_s",
            "quantecon.time.median_s", "ratio_driver", "ratio_kernel",
            "kernel.outcome.residual", "quantecon.outcome.residual",
            "kernel.outcome.iterations", "quantecon.outcome.iterations",
            "kernel.outcome.status", "quantecon.outcome.status"]),
        "Median time ratio ours / QuantEcon (< 1: ours faster)": comparison["median_ratios"],
        "Fixed cost per call at n = 2 [s]": (record["fixed_cost"], [
            "name", "driver.time.median_s", "kernel.time.median_s",
            "quantecon.time.median_s"]),
    })


def plot_by_entry(aggregates: Sequence[dict[str, Any]], path: Path, value: str) -> None:
    """One log-log panel per family, one line per entry, against n.

    ``value`` is ``time_median_s`` (band: min..max over instances) or ``residual_max``.
    """
    families = list(dict.fromkeys(r["family"] for r in aggregates))
    fig, axes = plt.subplots(1, len(families), figsize=(5.5 * len(families), 4.2), sharey=True)
    axes = list(np.atleast_1d(axes))
    floored = [{**r, value: max(r[value], RESIDUAL_FLOOR)} for r in aggregates]
    for ax, family in zip(axes, families, strict=True):
        log_lines(ax, [r for r in floored if r["family"] == family], "n", value, "entry",
                  ("time_min_s", "time_max_s") if value == "time_median_s" else None,
                  label=lambda e: ENTRY_TITLES.get(e, e), dashed=lambda e: e == "quantecon")
        if value == "residual_max":
            ax.axhline(1e-10, color="grey", lw=0.8, ls=":", label="tol 1e-10")
        ax.set_title(f"family {family!r}")
        ax.set_xlabel("n")
    axes[0].set_ylabel("time per solve (s)" if value == "time_median_s"
                       else "largest residual (0 drawn at 1e-18)")
    axes[-1].legend(fontsize=8)
    save_figure(fig, path)


def plot_ratios(rows: Sequence[dict[str, Any]], path: Path) -> None:
    """Horizontal bars of the time ratio ours/QuantEcon per problem, for both entry points."""
    fig, ax = plt.subplots(figsize=(9.0, 0.22 * len(rows) + 1.8))
    ax.axvline(1.0, color="k", lw=0.8)
    bars(ax, [_ratio_label(r) for r in rows], {
        "solve_lcp driver / QE": [r["ratio_driver"] for r in rows],
        "lemke_solve / QE": [r["ratio_kernel"] for r in rows]},
        "time ratio ours / QuantEcon lcp_lemke (< 1: ours faster)")
    save_figure(fig, path)


def _ratio_label(row: dict[str, Any]) -> str:
    """Bar label: the problem, its size, and both statuses when either entry failed."""
    def short(status: str) -> str:  # "RAY_TERMINATION" -> "ray termination"; "1 (x)" -> "x"
        return (status.split("(", 1)[1].rstrip(")") if "(" in status
                else status.lower().replace("_", " "))

    label = f"{row['name']} (n={row['n']})"
    ours, theirs = row["kernel"]["outcome"], row["quantecon"]["outcome"]
    if not (ours["success"] and theirs["success"]):
        label += f" [ours: {short(ours['status'])}; QE: {short(theirs['status'])}]"
    return label


__all__ = ["aggregate_size_study", "markdown_report", "plot_by_entry", "plot_ratios",
           "ratio_summary"]
