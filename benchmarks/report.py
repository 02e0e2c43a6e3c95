"""Reporting: aggregation, Markdown tables, plots and the JSON record of ``benchmarks.solvers``."""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the non-interactive backend)
import numpy as np  # noqa: E402
from matplotlib.ticker import NullFormatter  # noqa: E402

ENTRY_KEYS = ("driver", "kernel", "quantecon")
"""Keys of the three timed entries in each row of the QuantEcon comparison."""

RESIDUAL_FLOOR = 1e-18
"""Residuals of exactly zero are drawn at this value on log axes."""

ENTRY_TITLES = {
    "lemke": "lemke",
    "pgs": "pgs",
    "newton_fb": "newton_fb",
    "enumerative": "enumerative",
    "quantecon": "QuantEcon lcp_lemke",
}


def format_us(seconds: float) -> str:
    """Seconds as microseconds with about three significant digits (``"1,430"``, ``"12.3"``)."""
    us = seconds * 1e6
    if us < 9.995:
        return f"{us:.2f}"
    if us < 99.95:
        return f"{us:.1f}"
    return f"{us:,.0f}"


def format_ratio(ratio: float) -> str:
    """A time ratio with two decimals (or two significant digits when tiny)."""
    return f"{ratio:.2f}" if ratio >= 0.1 else f"{ratio:.2g}"


def format_residual(residual: float, digits: int = 1) -> str:
    """A residual in exponent notation, or ``0`` when exactly zero."""
    return "0" if residual == 0.0 else f"{residual:.{digits}e}"


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
        rows.append(
            {
                "family": family,
                "n": n,
                "entry": entry,
                "time_median_s": _median(times),
                "time_min_s": min(times),
                "time_max_s": max(times),
                "residual_max": max(r["outcome"]["residual"] for r in group),
                "iterations_median": _median(r["outcome"]["iterations"] for r in group),
                "solved": sum(r["outcome"]["success"] for r in group),
                "instances": len(group),
            }
        )
    return rows


def load_average_text(machine: Mapping[str, Any]) -> str:
    """The machine record's load averages at start and end of a run, as one phrase."""
    start = machine.get("load_average_at_start") or []
    end = machine.get("load_average_at_end") or []
    return (f"load average (1/5/15 min) {'/'.join(f'{x:.2f}' for x in start)} at start, "
            f"{'/'.join(f'{x:.2f}' for x in end)} at end")


def machine_speed_text(machine: Mapping[str, Any]) -> str:
    """The machine record's speed probes (``timing.speed_probe``) at start and end, as a phrase."""
    parts = []
    for when in ("start", "end"):
        probe = machine.get(f"speed_probe_at_{when}")
        if probe:
            parts.append(f"{probe['fastest_us']:.2f} µs fastest, {probe['median_us']:.2f} µs "
                         f"median, {probe['slow_fraction']:.0%} of batches slow (> 1.5× the "
                         f"fastest) at {when}")
    return ("machine speed probe (a compiled no-op called from Python): " + "; ".join(parts)
            if parts else "no machine speed probe")


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    """A GitHub Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def _size_cell(row: dict[str, Any] | None) -> str:
    """``time µs · iterations · max residual``, flagged when not every instance was solved."""
    if row is None:
        return "–"
    cell = (
        f"{format_us(row['time_median_s'])} · {row['iterations_median']:g} · "
        f"{format_residual(row['residual_max'], 0)}"
    )
    if row["solved"] < row["instances"]:
        cell += f" **({row['solved']}/{row['instances']} solved)**"
    return cell


def size_tables(aggregates: Sequence[dict[str, Any]], entries: Sequence[str]) -> str:
    """One Markdown table per family: rows n, columns entries, cells from ``_size_cell``."""
    index = {(r["family"], r["n"], r["entry"]): r for r in aggregates}
    families = list(dict.fromkeys(r["family"] for r in aggregates))
    blocks = []
    for family in families:
        sizes = sorted({r["n"] for r in aggregates if r["family"] == family})
        instances = max(r["instances"] for r in aggregates if r["family"] == family)
        header = ["n", *(ENTRY_TITLES.get(e, e) for e in entries)]
        rows = [[str(n), *(_size_cell(index.get((family, n, e))) for e in entries)] for n in sizes]
        title = (
            f"**Work vs size, family `{family}`** (our methods through `solve_lcp`; cells: "
            f"median over {instances} instances of the median time per solve in µs · median "
            "iterations · largest residual)"
        )
        blocks.append(title + "\n\n" + markdown_table(header, rows))
    return "\n\n".join(blocks)


def peer_table(rows: Sequence[dict[str, Any]]) -> str:
    """Per-problem comparison of our Lemke (driver and compiled entry) with QuantEcon's."""
    header = [
        "problem",
        "n",
        "driver µs",
        "lemke_solve µs",
        "QuantEcon µs",
        "driver/QE",
        "lemke_solve/QE",
        "residual ours",
        "residual QE",
        "pivots ours",
        "pivots QE",
        "status ours",
        "status QE",
    ]
    body = [
        [
            row["name"],
            str(row["n"]),
            format_us(row["driver"]["time"]["median_s"]),
            format_us(row["kernel"]["time"]["median_s"]),
            format_us(row["quantecon"]["time"]["median_s"]),
            format_ratio(row["ratio_driver"]),
            format_ratio(row["ratio_kernel"]),
            format_residual(row["kernel"]["outcome"]["residual"]),
            format_residual(row["quantecon"]["outcome"]["residual"]),
            str(row["kernel"]["outcome"]["iterations"]),
            str(row["quantecon"]["outcome"]["iterations"]),
            row["kernel"]["outcome"]["status"],
            row["quantecon"]["outcome"]["status"],
        ]
        for row in rows
    ]
    return markdown_table(header, body)


def ratio_summary(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Median time ratios ours/QuantEcon over problem sets, for both of our entry points.

    Sets: the Siconos peer files, all random problems, each random family, and the peer files
    that all three entries solved.
    """
    solved = [r for r in rows if all(r[k]["outcome"]["success"] for k in ENTRY_KEYS)]
    sets = {
        "Siconos peer files": [r for r in rows if r["family"] == "siconos"],
        "random (spd + contact)": [r for r in rows if r["family"] != "siconos"],
        "random spd (the issue-23 target: driver / QE <= 1)": [
            r for r in rows if r["family"] == "spd"
        ],
        "random contact": [r for r in rows if r["family"] == "contact"],
        "Siconos peer files solved by all three": [r for r in solved if r["family"] == "siconos"],
    }
    return [
        {
            "set": name,
            "problems": len(members),
            "median_ratio_driver": _median(r["ratio_driver"] for r in members),
            "median_ratio_kernel": _median(r["ratio_kernel"] for r in members),
        }
        for name, members in sets.items()
        if members
    ]


def ratio_table(summary: Sequence[dict[str, Any]]) -> str:
    """Markdown table of ``ratio_summary``."""
    header = [
        "problem set",
        "problems",
        "median driver / QuantEcon",
        "median lemke_solve / QuantEcon",
    ]
    body = [
        [
            s["set"],
            str(s["problems"]),
            format_ratio(s["median_ratio_driver"]),
            format_ratio(s["median_ratio_kernel"]),
        ]
        for s in summary
    ]
    return markdown_table(header, body)


def fixed_cost_table(rows: Sequence[dict[str, Any]]) -> str:
    """Markdown table of the n = 2 fixed-cost rows: median µs per call of each entry."""
    header = ["problem", "solve_lcp (driver) µs", "lemke_solve µs", "QuantEcon µs", "driver/QE"]
    body = [
        [
            row["name"],
            format_us(row["driver"]["time"]["median_s"]),
            format_us(row["kernel"]["time"]["median_s"]),
            format_us(row["quantecon"]["time"]["median_s"]),
            format_ratio(row["driver"]["time"]["median_s"] / row["quantecon"]["time"]["median_s"]),
        ]
        for row in rows
    ]
    return markdown_table(header, body)


def _family_axes(
    families: Sequence[str], sizes: Sequence[int], ylabel: str
) -> tuple[Any, list[Any]]:
    """One log-log panel per family, sharing the y axis, with the grid's sizes as x ticks."""
    fig, axes = plt.subplots(1, len(families), figsize=(5.5 * len(families), 4.2), sharey=True)
    axes = list(np.atleast_1d(axes))
    for ax, family in zip(axes, families, strict=True):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xticks(sizes, [str(n) for n in sizes])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_title(f"family {family!r}")
        ax.set_xlabel("n")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel(ylabel)
    return fig, axes


def _plot_by_entry(
    aggregates: Sequence[dict[str, Any]],
    entries: Sequence[str],
    ylabel: str,
    path: Path,
    value: str,
    band: tuple[str, str] | None = None,
    hline: float | None = None,
) -> None:
    """Shared body of the two size plots: one line per entry in each family's panel."""
    families = list(dict.fromkeys(r["family"] for r in aggregates))
    sizes = sorted({r["n"] for r in aggregates})
    fig, axes = _family_axes(families, sizes, ylabel)
    for ax, family in zip(axes, families, strict=True):
        for entry in entries:
            rows = sorted(
                (r for r in aggregates if r["family"] == family and r["entry"] == entry),
                key=lambda r: r["n"],
            )
            if not rows:
                continue
            n = [r["n"] for r in rows]
            y = [max(r[value], RESIDUAL_FLOOR) for r in rows]
            style = "k--" if entry == "quantecon" else "-"
            (line,) = ax.plot(n, y, style, marker="o", ms=4, label=ENTRY_TITLES.get(entry, entry))
            if band is not None:
                low = [r[band[0]] for r in rows]
                high = [r[band[1]] for r in rows]
                ax.fill_between(n, low, high, color=line.get_color(), alpha=0.15)
        if hline is not None:
            ax.axhline(hline, color="grey", lw=0.8, ls=":", label="tol 1e-10")
    axes[-1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def plot_time_vs_size(
    aggregates: Sequence[dict[str, Any]], entries: Sequence[str], path: Path
) -> None:
    """Median time per solve vs n (log-log), band = min..max over instances."""
    _plot_by_entry(
        aggregates,
        entries,
        "time per solve (s)",
        path,
        "time_median_s",
        band=("time_min_s", "time_max_s"),
    )


def plot_residual_vs_size(
    aggregates: Sequence[dict[str, Any]], entries: Sequence[str], path: Path
) -> None:
    """Largest residual over instances vs n (log-log; zeros drawn at ``RESIDUAL_FLOOR``)."""
    _plot_by_entry(
        aggregates,
        entries,
        "largest residual (0 drawn at 1e-18)",
        path,
        "residual_max",
        hline=1e-10,
    )


def plot_ratios(rows: Sequence[dict[str, Any]], path: Path) -> None:
    """Horizontal bars of the time ratio ours/QuantEcon per problem, for both entry points."""
    names = [_ratio_label(r) for r in rows]
    y = np.arange(len(rows))
    fig, ax = plt.subplots(figsize=(9.0, 0.22 * len(rows) + 1.8))
    ax.barh(y - 0.2, [r["ratio_driver"] for r in rows], 0.4, label="solve_lcp driver / QE")
    ax.barh(y + 0.2, [r["ratio_kernel"] for r in rows], 0.4, label="lemke_solve / QE")
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_yticks(y, names, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("time ratio ours / QuantEcon lcp_lemke (< 1: ours faster)")
    ax.grid(True, axis="x", which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2, frameon=False)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def _ratio_label(row: dict[str, Any]) -> str:
    """Bar label: the problem, its size, and both statuses when either entry failed."""
    label = f"{row['name']} (n={row['n']})"
    ours, theirs = row["kernel"]["outcome"], row["quantecon"]["outcome"]
    if not (ours["success"] and theirs["success"]):
        label += f" [ours: {_short(ours['status'])}; QE: {_short(theirs['status'])}]"
    return label


def _short(status: str) -> str:
    """``"RAY_TERMINATION"`` -> ``"ray termination"``; ``"1 (iteration limit)"`` -> its words."""
    if "(" in status:
        return status.split("(", 1)[1].rstrip(")")
    return status.lower().replace("_", " ")


def json_safe(value: Any) -> Any:
    """``value`` as strict JSON: non-finite floats as the strings "inf", "-inf", "nan".

    A diverged measurement thus stays visible; numpy scalars become Python numbers, tuples
    lists.
    """
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else str(float(value))
    return value


def write_json(record: dict[str, Any], path: Path) -> None:
    """Write the full record (indented, NaN-free numbers as produced)."""
    path.write_text(json.dumps(record, indent=1, default=_to_builtin) + "\n")


def _to_builtin(value: Any) -> Any:
    """JSON fallback for numpy scalars."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serializable: {type(value).__name__}")


__all__ = [
    "ENTRY_KEYS",
    "aggregate_size_study",
    "format_residual",
    "format_ratio",
    "format_us",
    "json_safe",
    "markdown_table",
    "peer_table",
    "plot_ratios",
    "plot_residual_vs_size",
    "plot_time_vs_size",
    "ratio_summary",
    "ratio_table",
    "size_tables",
    "write_json",
]
