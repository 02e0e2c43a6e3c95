"""Reporting shared by every benchmark: tables, target checks, figures, JSON, the headline.

A target check is ``{target, comparison, threshold, unit, measured, met, note}`` (``target_row``);
the headline table holds every benchmark's target checks.
"""

from __future__ import annotations

import contextlib
import json
import math
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the non-interactive backend)
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from benchmarks.timing import VERSIONED_PACKAGES, Log, Progress, finish, machine_info  # noqa: E402


def format_number(value: float | None) -> str:
    """Three significant digits, exponent notation outside [0.01, 1e4); ``–`` if absent."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    if isinstance(value, int) or value == 0.0:
        return str(value if isinstance(value, int) else 0)
    return f"{value:.3g}" if 1e-2 <= abs(value) < 1e4 else f"{value:.2e}"


def flat_table(rows: Iterable[Mapping[str, Any]], columns: Sequence[str] | None = None) -> str:
    """Markdown of records: nested dicts become ``a.b`` columns, list fields are left out."""
    frame = pd.json_normalize(list(rows))
    keep = [c for c in (columns or frame.columns) if c in frame
            and not frame[c].map(lambda v: isinstance(v, list)).any()]
    return frame[keep].to_markdown(index=False, floatfmt=".3g")


def summary(record: Mapping[str, Any], packages: Sequence[str],
            sections: Mapping[str, Any] | None = None) -> str:
    """A run's stdout report: run line, notes, targets, then per title a table of records.

    The full results are in the run's JSON (rendered by the docs' results page). A section is
    records (``flat_table``), a (records, columns) pair, or ready text.
    """
    lines = [run_line(record, packages), *(f"* {note}" for note in record.get("notes") or [])]
    if record.get("targets"):
        lines += ["", "**Targets**", "", targets_table(record["targets"])]
    for title, section in (sections or {}).items():
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


def log_lines(ax: Any, rows: Sequence[Mapping[str, Any]], x: str, y: str, group: str,
              band: tuple[str, str] | None = None, scale: float = 1.0,
              label: Callable[[Any], str] = str, dashed: Callable[[Any], bool] = bool,
              ticks: bool = True) -> None:
    """A log-log panel: ``y * scale`` against ``x``, one line per value of ``group``.

    ``band`` names the low and high keys of a shaded band; ``dashed(group)`` dashes a line;
    ``ticks`` marks every x value.
    """
    for key in dict.fromkeys(r[group] for r in rows):
        chosen = sorted((r for r in rows if r[group] == key), key=lambda r: r[x])
        xs = [r[x] for r in chosen]
        (line,) = ax.plot(xs, [r[y] * scale for r in chosen], "--" if dashed(key) else "-",
                          marker="o", ms=4, label=label(key))
        if band:
            ax.fill_between(xs, [r[band[0]] * scale for r in chosen],
                            [r[band[1]] * scale for r in chosen], color=line.get_color(),
                            alpha=0.15)
    ax.set_xscale("log")
    ax.set_yscale("log")
    if ticks:
        values = sorted({r[x] for r in rows})
        ax.set_xticks(values, [f"{t:g}" for t in values])
        ax.minorticks_off()
    ax.grid(True, which="both", alpha=0.3)


def bars(ax: Any, labels: Sequence[str], series: Mapping[str, Sequence[float | None]],
         xlabel: str, log: bool = True) -> None:
    """Grouped horizontal bars, one group per label (top to bottom), one bar per series."""
    frame = pd.DataFrame(dict(series), index=list(labels), dtype=float)  # None: no bar
    frame.plot.barh(ax=ax, width=0.8, logx=log)
    ax.tick_params(axis="y", labelsize=7 if len(labels) > 20 else 8)
    ax.invert_yaxis()
    ax.set_xlabel(xlabel)
    ax.grid(True, axis="x", which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2, frameon=False)


def target_row(name: str, comparison: str, threshold: float | None, unit: str,
               measured: float | None, note: str = "", met: bool | None = None
               ) -> dict[str, Any]:  # fmt: skip
    """One target check; ``met`` judged from ``comparison`` ("≤", "≥" or "") unless given."""
    if met is None and measured is not None and comparison in ("≤", "≥"):
        met = bool(measured <= threshold) if comparison == "≤" else bool(measured >= threshold)
    return {"target": name, "comparison": comparison, "threshold": threshold, "unit": unit,
            "measured": measured, "met": met, "note": note}


def target_value(value: float | None, unit: str) -> str:
    """A target's value with its unit, ratios as ``12.3×``."""
    if value is None:
        return "–"
    if unit == "×":
        return f"{value:.3g}×"
    return f"{format_number(value)} {unit}".strip()


def targets_table(targets: Sequence[Mapping[str, Any]]) -> str:
    """Markdown: (benchmark,) target, threshold, measured, met (✓, ✗, ``–`` undecided), note."""
    def threshold(t: Mapping[str, Any]) -> str:
        if t["threshold"] is None:
            return "(comparison)"
        unit = t["unit"] if t["unit"] in ("×", "") else f" {t['unit']}"
        return f"{t['comparison']} {t['threshold']:g}{unit}"

    return pd.DataFrame([{
        **({"benchmark": t["benchmark"]} if t.get("benchmark") else {}),
        "target": t["target"], "threshold": threshold(t),
        "measured": target_value(t["measured"], t["unit"]),
        "met": {True: "✓", False: "✗"}.get(t["met"], "–" if t["measured"] is not None
                                            else "not measured"),
        "note": t["note"]} for t in targets]).to_markdown(index=False, disable_numparse=True)


def run_line(record: Mapping[str, Any], packages: Sequence[str]) -> str:
    """One line on the run: date, CPU, package versions, run time, load and speed probes."""
    machine = record["machine"]
    versions = ", ".join(f"{name} {machine['versions'].get(name)}" for name in packages)
    quick = " (--quick)" if record["config"].get("quick") else ""
    loads = ["/".join(f"{x:.2f}" for x in machine.get(f"load_average_at_{when}") or [])
             for when in ("start", "end")]
    probes = [f"{probe['fastest_us']:.2f} µs fastest, {probe['median_us']:.2f} µs median at {when}"
              for when in ("start", "end") if (probe := machine.get(f"speed_probe_at_{when}"))]
    return (f"Run {machine['date']} on {machine['cpu_model']} ({machine['cpu_count']} CPUs), "
            f"{versions}; total {record['run_time_s']:.0f} s{quick}; load average "
            f"{loads[0]} at start, {loads[1]} at end; speed probe (a compiled no-op): "
            + ("; ".join(probes) or "none") + ".")


def json_safe(value: Any) -> Any:
    """``value`` as strict JSON: non-finite floats as the strings "inf", "-inf", "nan"."""
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


@contextlib.contextmanager
def study(name: str, output: Path, config: dict[str, Any],
          packages: Sequence[str] = VERSIONED_PACKAGES, speed: bool = False,
          log: Log | None = None) -> Iterator[tuple[dict[str, Any], Log, Progress]]:
    """A run's (record, log, clock); at the end: load, ``speed`` probe, time, ``output/NAME.json``.

    The record opens with ``machine`` (``packages``' versions) and ``config`` (``quick``, if any).
    """
    progress = Progress()
    say = log or progress
    output.mkdir(parents=True, exist_ok=True)
    record: dict[str, Any] = {"machine": machine_info(tuple(packages)), "config": config}
    say(f"{name} benchmark ({'quick' if config.get('quick') else 'full'}) -> {output}")
    yield record, say, progress
    finish(record, progress.elapsed, speed)
    write_json(json_safe(record), output / f"{name}.json")
    say(f"done in {progress.elapsed:.0f} s; wrote {name}.json and its plots to {output}")

HEADLINE_SOURCES = (("engine", "engine.json"), ("envs", "envs.json"),
                    ("precision", "work_precision.json"), ("stress", "stress.json"),
                    ("startup", "startup.json"), ("control", "control.json"))  # fmt: skip
"""(benchmark name, result file) whose targets enter the table, in this order."""


def engine_peer_rows(record: dict[str, Any]) -> list[dict[str, Any]]:
    """Ours against MuJoCo's arm in the engine run."""
    rows = []  # each model's row at its largest N (the last of equals)
    batched = sorted(record.get("batched") or [], key=lambda entry: entry["copies"])
    largest = {entry["model"]: entry for entry in batched}
    if "manipulator" in largest and "mujoco" in largest:
        ours, peer = largest["manipulator"]["per_copy_step_s"], largest["mujoco"]["per_copy_step_s"]
        rows.append(target_row(
            "manipulator step vs MuJoCo arm (rollout), batched N = "
            f"{largest['manipulator']['copies']}: MuJoCo time / ours", "", None, "×", peer / ours,
            f"ours {ours * 1e6:.3g} µs, MuJoCo {peer * 1e6:.3g} µs per copy-step", peer > ours))
    stop = record.get("brake_stop") or {}
    if "ours" in stop and "mujoco_default" in stop:
        rows.append(target_row(
            "brake stops relative motion (< 1 %) within one step", "≤", 1, "steps",
            stop["ours"]["steps"], "MuJoCo eq_active, default solref: "
            f"{stop['mujoco_default']['steps']} steps", stop["ours"]["steps"] <= 1))
    return rows


def write_headline(folder: Path) -> str:
    """Write ``headline.json`` and ``headline.md`` (``targets_table`` per row) from ``folder``."""
    folder = Path(folder)
    rows: list[dict[str, Any]] = []
    runs = {}
    for name, filename in HEADLINE_SOURCES:
        if not (folder / filename).exists():
            continue
        record = json.loads((folder / filename).read_text())
        runs[name] = {"file": filename, "machine": record.get("machine"),
                      "run_time_s": record.get("run_time_s"),
                      "quick": (record.get("config") or {}).get("quick")}
        extra = engine_peer_rows(record) if name == "engine" else []
        rows += [{"benchmark": name, **target, "met": bool(target.get("met"))}
                 for target in (record.get("targets") or []) + extra]
    (folder / "headline.json").write_text(json.dumps({"runs": runs, "rows": rows}, indent=1,
                                                     default=str) + "\n")  # fmt: skip
    text = targets_table(rows) if rows else f"no benchmark results with targets in {folder}"
    (folder / "headline.md").write_text(text + "\n")
    return text
