"""Reporting shared by every benchmark: Markdown tables, target checks, figures, the JSON record.

A target check is ``{target, comparison, threshold, unit, measured, met, note}`` (``target_row``).
"""

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
import pandas as pd  # noqa: E402


def format_us(seconds: float) -> str:
    """Seconds as microseconds with about three significant digits (``"1,430"``, ``"12.3"``)."""
    us = seconds * 1e6
    if us < 9.995:
        return f"{us:.2f}"
    return f"{us:.1f}" if us < 99.95 else f"{us:,.0f}"


def format_us_fine(seconds: float | None) -> str:
    """Seconds as µs, with three significant digits below 1 µs (``"0.0512"``); ``–`` if absent."""
    if seconds is None or not np.isfinite(seconds):
        return "–"
    return f"{seconds * 1e6:.3g}" if seconds < 1e-6 else format_us(seconds)


def format_ratio(ratio: float) -> str:
    """A time ratio with two decimals (or two significant digits when tiny)."""
    return f"{ratio:.2f}" if ratio >= 0.1 else f"{ratio:.2g}"


def format_residual(residual: float, digits: int = 1) -> str:
    """A residual in exponent notation, or ``0`` when exactly zero."""
    return "0" if residual == 0.0 else f"{residual:.{digits}e}"


def format_number(value: float | None) -> str:
    """Three significant digits, exponent notation outside [0.01, 1e4); ``–`` if absent."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    if isinstance(value, int) or value == 0.0:
        return str(value if isinstance(value, int) else 0)
    return f"{value:.3g}" if 1e-2 <= abs(value) < 1e4 else f"{value:.2e}"


def markdown_table(rows: Iterable[Any], columns: Sequence[str] | None = None) -> str:
    """A GitHub Markdown table (pandas ``DataFrame.to_markdown``); cells are written as given.

    Args:
        rows: dicts (column -> cell) or sequences of cells in the order of ``columns``.
        columns: the header (default: the dicts' keys).
    """
    frame = pd.DataFrame(list(rows), columns=list(columns) if columns is not None else None)
    return frame.to_markdown(index=False, disable_numparse=True)


def flat_table(rows: Iterable[Mapping[str, Any]], columns: Sequence[str] | None = None) -> str:
    """Markdown of records: nested dicts become ``a.b`` columns, list fields are left out."""
    frame = pd.json_normalize(list(rows))
    keep = [c for c in (columns or frame.columns) if c in frame
            and not frame[c].map(lambda v: isinstance(v, list)).any()]
    return frame[keep].to_markdown(index=False, floatfmt=".3g")


def summary(record: Mapping[str, Any], packages: Sequence[str],
            sections: Mapping[str, Any]) -> str:
    """A run's stdout report: run line, notes, targets, then per section title its table.

    A section is a list of records (``flat_table``), a (records, columns) pair or ready text.
    """
    lines = [run_line(record, packages), *(f"* {note}" for note in record.get("notes") or [])]
    if record.get("targets"):
        lines += ["", "**Targets**", "", targets_table(record["targets"])]
    for title, section in sections.items():
        rows, columns = section if isinstance(section, tuple) else (section, None)
        if rows:
            text = rows if isinstance(rows, str) else flat_table(rows, columns)
            lines += ["", f"**{title}**", "", text]
    return "\n".join(lines)


def save_figure(fig: Any, path: Path, dpi: int = 130) -> None:
    """Lay out, write and close a figure."""
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def target_row(name: str, comparison: str, threshold: float | None, unit: str,
               measured: float | None, note: str = "", met: bool | None = None
               ) -> dict[str, Any]:  # fmt: skip
    """One target check; ``met`` is judged from ``comparison`` unless given (None: not measured).

    Args:
        name: what is measured. comparison: ``"≤"``, ``"≥"`` or ``""`` (no limit).
        threshold: the limit in ``unit``. measured: the value in ``unit`` (None: not measured).
        note: context. met: an explicit verdict (e.g. None where only a bound was measured).
    """
    if met is None and measured is not None and comparison in ("≤", "≥"):
        met = bool(measured <= threshold) if comparison == "≤" else bool(measured >= threshold)
    return {"target": name, "comparison": comparison, "threshold": threshold, "unit": unit,
            "measured": measured, "met": met, "note": note}


def target_value(value: float | None, unit: str) -> str:
    """A target's value with its unit: µs with ``format_us_fine``, ratios as ``12.3×``."""
    if value is None:
        return "–"
    if unit == "µs":
        return f"{format_us_fine(value * 1e-6)} µs"
    if unit == "×":
        return f"{value:.3g}×"
    return f"{format_number(value)} {unit}".strip()


def targets_table(targets: Sequence[Mapping[str, Any]]) -> str:
    """Markdown: target, threshold, measured, met (✓, ✗, ``–`` undecided, not measured), note."""
    def threshold(t: Mapping[str, Any]) -> str:
        if t["threshold"] is None:
            return "(comparison)"
        unit = t["unit"] if t["unit"] in ("×", "") else f" {t['unit']}"
        return f"{t['comparison']} {t['threshold']:g}{unit}"

    return markdown_table([{
        "target": t["target"], "threshold": threshold(t),
        "measured": target_value(t["measured"], t["unit"]),
        "met": {True: "✓", False: "✗"}.get(t["met"], "–" if t["measured"] is not None
                                            else "not measured"),
        "note": t["note"]} for t in targets])  # fmt: skip


def run_line(record: Mapping[str, Any], packages: Sequence[str]) -> str:
    """One line on the run: date, CPU, package versions, run time, load and speed probes."""
    machine = record["machine"]
    versions = ", ".join(f"{name} {machine['versions'].get(name)}" for name in packages)
    quick = " (--quick)" if record["config"]["quick"] else ""
    return (f"Run {machine['date']} on {machine['cpu_model']} ({machine['cpu_count']} CPUs), "
            f"{versions}; total {record['run_time_s']:.0f} s{quick}; "
            f"{load_average_text(machine)}; {machine_speed_text(machine)}.")


def load_average_text(machine: Mapping[str, Any]) -> str:
    """The machine record's load averages at start and end of a run, as one phrase."""
    start, end = (machine.get(f"load_average_at_{when}") or [] for when in ("start", "end"))
    return (f"load average (1/5/15 min) {'/'.join(f'{x:.2f}' for x in start)} at start, "
            f"{'/'.join(f'{x:.2f}' for x in end)} at end")


def machine_speed_text(machine: Mapping[str, Any]) -> str:
    """The machine record's speed probes (``timing.speed_probe``) at start and end, as a phrase."""
    parts = [f"{probe['fastest_us']:.2f} µs fastest, {probe['median_us']:.2f} µs median, "
             f"{probe['slow_fraction']:.0%} of batches slow (> 1.5× the fastest) at {when}"
             for when in ("start", "end") if (probe := machine.get(f"speed_probe_at_{when}"))]
    return ("machine speed probe (a compiled no-op called from Python): " + "; ".join(parts)
            if parts else "no machine speed probe")


def json_safe(value: Any) -> Any:
    """``value`` as strict JSON: non-finite floats as the strings "inf", "-inf", "nan".

    A diverged measurement thus stays visible; numpy scalars become Python numbers, tuples lists.
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
    """Write the full record (indented; numpy scalars as Python numbers)."""
    path.write_text(json.dumps(record, indent=1, default=lambda v: v.item()) + "\n")


__all__ = ["flat_table", "format_number", "format_ratio", "format_residual", "format_us",
           "format_us_fine", "json_safe", "markdown_table", "plt", "run_line", "save_figure",
           "summary", "target_row", "targets_table", "write_json"]
