"""Reporting of ``benchmarks.solvers``: aggregation, Markdown tables and plots."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.ticker import NullFormatter

from benchmarks.report import (
    format_ratio,
    format_residual,
    format_us,
    markdown_table,
    plt,
    run_line,
    save_figure,
)

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
    """Combine the instances of each (family, n, entry) of the work-size study.

    Args:
        records: one dict per (family, n, instance, entry) with ``time`` (a ``Timed.summary``)
            and ``outcome`` (an ``Outcome`` as dict).

    Returns:
        One dict per (family, n, entry): the median over instances of the per-instance median
        time, its min and max over instances, the largest residual, the median iteration
        count and how many instances the entry solved.
    """
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


def _size_cell(row: dict[str, Any] | None) -> str:
    """``time µs · iterations · max residual``, flagged when not every instance was solved."""
    if row is None:
        return "–"
    cell = (f"{format_us(row['time_median_s'])} · {row['iterations_median']:g} · "
            f"{format_residual(row['residual_max'], 0)}")
    if row["solved"] < row["instances"]:
        cell += f" **({row['solved']}/{row['instances']} solved)**"
    return cell


def size_tables(aggregates: Sequence[dict[str, Any]], entries: Sequence[str]) -> str:
    """One Markdown table per family: rows n, columns entries, cells from ``_size_cell``."""
    index = {(r["family"], r["n"], r["entry"]): r for r in aggregates}
    blocks = []
    for family in dict.fromkeys(r["family"] for r in aggregates):
        sizes = sorted({r["n"] for r in aggregates if r["family"] == family})
        instances = max(r["instances"] for r in aggregates if r["family"] == family)
        rows = [{"n": str(n), **{ENTRY_TITLES.get(e, e): _size_cell(index.get((family, n, e)))
                                 for e in entries}} for n in sizes]
        blocks.append(f"**Work vs size, family `{family}`** (our methods through `solve_lcp`; "
                      f"cells: median over {instances} instances of the median time per solve "
                      "in µs · median iterations · largest residual)\n\n" + markdown_table(rows))
    return "\n\n".join(blocks)


def peer_table(rows: Sequence[dict[str, Any]]) -> str:
    """Per-problem comparison of our Lemke (driver and compiled entry) with QuantEcon's."""
    return markdown_table([{
        "problem": r["name"], "n": str(r["n"]),
        "driver µs": format_us(r["driver"]["time"]["median_s"]),
        "lemke_solve µs": format_us(r["kernel"]["time"]["median_s"]),
        "QuantEcon µs": format_us(r["quantecon"]["time"]["median_s"]),
        "driver/QE": format_ratio(r["ratio_driver"]),
        "lemke_solve/QE": format_ratio(r["ratio_kernel"]),
        "residual ours": format_residual(r["kernel"]["outcome"]["residual"]),
        "residual QE": format_residual(r["quantecon"]["outcome"]["residual"]),
        "pivots ours": str(r["kernel"]["outcome"]["iterations"]),
        "pivots QE": str(r["quantecon"]["outcome"]["iterations"]),
        "status ours": r["kernel"]["outcome"]["status"],
        "status QE": r["quantecon"]["outcome"]["status"]} for r in rows])  # fmt: skip


def ratio_summary(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Median time ratios ours/QuantEcon over problem sets, for both of our entry points.

    Sets: the Siconos peer files, all random problems, each random family, and the peer files
    that all three entries solved.
    """
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


def ratio_table(summary: Sequence[dict[str, Any]]) -> str:
    """Markdown table of ``ratio_summary``."""
    return markdown_table([{
        "problem set": s["set"], "problems": str(s["problems"]),
        "median driver / QuantEcon": format_ratio(s["median_ratio_driver"]),
        "median lemke_solve / QuantEcon": format_ratio(s["median_ratio_kernel"])}
        for s in summary])  # fmt: skip


def fixed_cost_table(rows: Sequence[dict[str, Any]]) -> str:
    """Markdown table of the n = 2 fixed-cost rows: median µs per call of each entry."""
    def us(row: dict[str, Any], key: str) -> float:
        return row[key]["time"]["median_s"]

    return markdown_table([{
        "problem": r["name"], "solve_lcp (driver) µs": format_us(us(r, "driver")),
        "lemke_solve µs": format_us(us(r, "kernel")), "QuantEcon µs": format_us(us(r, "quantecon")),
        "driver/QE": format_ratio(us(r, "driver") / us(r, "quantecon"))} for r in rows])


def first_call_table(first: dict[str, Any]) -> str:
    """Markdown table: entry x probe (warm / cold cache) of first-call milliseconds."""
    probes = [p for p in first if "first_call_s" in first[p]]
    if not probes:
        return "(first-call probe failed: " + str(first) + ")"
    return markdown_table([{
        "entry": name,
        **{f"first call, {p.replace('_', ' ')}": f"{first[p]['first_call_s'][name] * 1e3:.1f}"
           for p in probes},
        "second call": f"{first[probes[0]]['second_call_s'][name] * 1e3:.3f}"}
        for name in first[probes[0]]["first_call_s"]])  # fmt: skip


def markdown_report(record: dict[str, Any], aggregates: list[dict[str, Any]],
                    summary: list[dict[str, Any]], entries: Sequence[str]) -> str:
    """All result tables of the run, as printed to stdout."""
    return "\n\n".join([
        run_line(record, ("numpy", "numba", "quantecon")),
        "**First call per entry** (fresh interpreter; ms):", first_call_table(record["first_call"]),
        size_tables(aggregates, entries),
        "**Lemke vs QuantEcon, per problem** (median time per solve; residuals recomputed with "
        "`lcp_residual`; our pivots/status/residual are those of `lemke_solve`, which the driver "
        "returns unchanged)", peer_table(record["quantecon_comparison"]["problems"]),
        "**Median time ratio ours / QuantEcon** (< 1: ours faster)", ratio_table(summary),
        "**Fixed cost per call at n = 2** (median µs per call, interleaved rounds)",
        fixed_cost_table(record["fixed_cost"])])


def plot_by_entry(aggregates: Sequence[dict[str, Any]], entries: Sequence[str], path: Path,
                  value: str) -> None:
    """One log-log panel per family, one line per entry, against n.

    ``value`` is ``time_median_s`` (band: min..max over instances) or ``residual_max`` (zeros
    drawn at ``RESIDUAL_FLOOR``, the tolerance marked).
    """
    families = list(dict.fromkeys(r["family"] for r in aggregates))
    sizes = sorted({r["n"] for r in aggregates})
    fig, axes = plt.subplots(1, len(families), figsize=(5.5 * len(families), 4.2), sharey=True)
    axes = list(np.atleast_1d(axes))
    for ax, family in zip(axes, families, strict=True):
        for entry in entries:
            rows = sorted((r for r in aggregates if r["family"] == family
                           and r["entry"] == entry), key=lambda r: r["n"])
            if not rows:
                continue
            n = [r["n"] for r in rows]
            (line,) = ax.plot(n, [max(r[value], RESIDUAL_FLOOR) for r in rows],
                              "k--" if entry == "quantecon" else "-", marker="o", ms=4,
                              label=ENTRY_TITLES.get(entry, entry))
            if value == "time_median_s":
                ax.fill_between(n, [r["time_min_s"] for r in rows],
                                [r["time_max_s"] for r in rows], color=line.get_color(),
                                alpha=0.15)
        if value == "residual_max":
            ax.axhline(1e-10, color="grey", lw=0.8, ls=":", label="tol 1e-10")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xticks(sizes, [str(n) for n in sizes])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_title(f"family {family!r}")
        ax.set_xlabel("n")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("time per solve (s)" if value == "time_median_s"
                       else "largest residual (0 drawn at 1e-18)")
    axes[-1].legend(fontsize=8)
    save_figure(fig, path)


def plot_ratios(rows: Sequence[dict[str, Any]], path: Path) -> None:
    """Horizontal bars of the time ratio ours/QuantEcon per problem, for both entry points."""
    y = np.arange(len(rows))
    fig, ax = plt.subplots(figsize=(9.0, 0.22 * len(rows) + 1.8))
    ax.barh(y - 0.2, [r["ratio_driver"] for r in rows], 0.4, label="solve_lcp driver / QE")
    ax.barh(y + 0.2, [r["ratio_kernel"] for r in rows], 0.4, label="lemke_solve / QE")
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_yticks(y, [_ratio_label(r) for r in rows], fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("time ratio ours / QuantEcon lcp_lemke (< 1: ours faster)")
    ax.grid(True, axis="x", which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2, frameon=False)
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


__all__ = [
    "aggregate_size_study",
    "markdown_report",
    "plot_by_entry",
    "plot_ratios",
    "ratio_summary",
]
