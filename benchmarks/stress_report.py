"""Reporting of ``benchmarks.stress``: pass/fail criteria, the Markdown table and the summary plot.

A criterion is a dict ``{"value", "limit", "relation", "passed"}``: ``relation`` is ``"<="`` (the
value must not exceed the limit) or ``">="`` (it must reach it). A NaN or infinite value never
passes, so a trajectory that blows up fails every criterion computed from it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.report import markdown_table, plt

Criterion = dict[str, Any]

MARGIN_FLOOR = 1e-9
"""Margins below this (a zero value against a positive limit, or a zero count) are drawn here."""
MARGIN_CEILING = 1e9
"""Margins above this (a positive count against a limit of 0, NaN, inf) are drawn here."""


def at_most(value: float, limit: float) -> Criterion:
    """Criterion ``value <= limit``; fails when ``value`` is NaN or infinite."""
    value = float(value)
    return {"value": value, "limit": float(limit), "relation": "<=",
            "passed": bool(math.isfinite(value) and value <= limit)}


def at_least(value: float, limit: float) -> Criterion:
    """Criterion ``value >= limit``; fails when ``value`` is NaN or infinite."""
    value = float(value)
    return {"value": value, "limit": float(limit), "relation": ">=",
            "passed": bool(math.isfinite(value) and value >= limit)}


def margin(criterion: Criterion) -> float:
    """How close a criterion is to failing: < 1 passes, > 1 fails (``value / limit`` for ``<=``).

    Zero values against a zero limit (e.g. no NaN counted) give ``MARGIN_FLOOR``; positive values
    against a zero limit, and non-finite values, give ``MARGIN_CEILING``.
    """
    value, limit = criterion["value"], criterion["limit"]
    if not math.isfinite(value):
        return MARGIN_CEILING
    if criterion["relation"] == ">=":
        value, limit = limit, value
    if limit <= 0.0:
        return MARGIN_FLOOR if value <= limit else MARGIN_CEILING
    return float(np.clip(value / limit, MARGIN_FLOOR, MARGIN_CEILING))


def format_number(value: float) -> str:
    """A value or limit for the table: integers as such, others with three significant digits."""
    if not math.isfinite(value):
        return str(value)
    if value == int(value) and abs(value) < 1e6:
        return str(int(value))
    return f"{value:.3g}"


def format_parameters(parameters: Mapping[str, Any]) -> str:
    """``key=value`` pairs of a case's parameters, floats with four significant digits."""
    parts = []
    for key, value in parameters.items():
        if isinstance(value, float):
            parts.append(f"{key}={value:.4g}")
        elif isinstance(value, (list, tuple)):
            parts.append(f"{key}=" + ",".join(f"{v:.3g}" if isinstance(v, float) else str(v)
                                              for v in value))
        else:
            parts.append(f"{key}={value}")
    return ", ".join(parts)


def format_criteria(criteria: Mapping[str, Criterion]) -> str:
    """``name value <= limit`` per criterion, failures in bold."""
    parts = []
    for name, c in criteria.items():
        text = f"{name} {format_number(c['value'])} {c['relation']} {format_number(c['limit'])}"
        parts.append(text if c["passed"] else f"**{text} FAIL**")
    return "; ".join(parts)


def markdown_report(record: Mapping[str, Any]) -> str:
    """The Markdown results: a summary line, then one row per case (criteria, PASS/FAIL).

    Args:
        record: the record returned by ``benchmarks.stress.run``.
    """
    cases = record["cases"]
    failed = [c["name"] for c in cases if not c["passed"]]
    header = ["case", "parameters", "criteria (value relation limit)", "result"]
    rows = [[c["name"], format_parameters(c["parameters"]), format_criteria(c["criteria"]),
             "PASS" if c["passed"] else "**FAIL**"] for c in cases]
    mode = "quick" if record["config"]["quick"] else "full"
    lines = [
        f"Stress test ({mode}): {len(cases) - len(failed)} of {len(cases)} cases pass"
        + (f"; failing: {', '.join(failed)}" if failed else "")
        + f". Run time {record['run_time_s']:.0f} s.",
        "",
        markdown_table(header, rows),
    ]
    if record.get("notes"):
        lines += ["", "Notes:", *[f"* {note}" for note in record["notes"]]]
    return "\n".join(lines)


def plot_margins(cases: Sequence[Mapping[str, Any]], path: Path) -> None:
    """One row per case, one dot per criterion at its margin (log x); green passes, red fails.

    The margin is value / limit for ``<=`` criteria (limit / value for ``>=``), so every passing
    dot lies left of the line at 1. Zero counts are drawn at ``MARGIN_FLOOR``, failed counts and
    non-finite values at ``MARGIN_CEILING``.
    """
    names = [c["name"] for c in cases]
    fig, ax = plt.subplots(figsize=(10.0, 0.19 * len(cases) + 1.6))
    for row, case in enumerate(cases):
        for criterion in case["criteria"].values():
            ax.plot(margin(criterion), row, "o", ms=4, alpha=0.8,
                    color="tab:green" if criterion["passed"] else "tab:red")
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlim(MARGIN_FLOOR / 3, MARGIN_CEILING * 3)
    ax.set_yticks(range(len(cases)), names, fontsize=6.5)
    for label, case in zip(ax.get_yticklabels(), cases, strict=True):
        if not case["passed"]:
            label.set_color("tab:red")
    ax.set_ylim(len(cases) - 0.5, -0.5)
    ax.set_xlabel("margin = value / limit (limit / value for >= criteria); pass < 1 < fail; "
                  "zero counts at 1e-9", fontsize=9)
    num_failed = sum(not c["passed"] for c in cases)
    ax.set_title(f"Stress test: {len(cases) - num_failed} of {len(cases)} cases pass "
                 "(green: criterion passed, red: failed)", fontsize=10)
    ax.grid(True, axis="x", which="major", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


__all__ = [
    "Criterion",
    "at_least",
    "at_most",
    "format_criteria",
    "format_number",
    "format_parameters",
    "margin",
    "markdown_report",
    "plot_margins",
]
