"""Speed before and after a change, in one run: the engine and env benchmarks on two trees.

``python -m benchmarks.before_after --before DIR [--rounds 2]`` runs the quick engine and env
benchmarks and ``in_place_probe`` alternately on the package in DIR and on this tree, in fresh
interpreters, and writes the medians and ratios to ``before_after.json`` and ``.png``.
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from benchmarks import report
from benchmarks.timing import ROOT, Progress, arguments, fresh_python, machine_info

BENCHMARKS = (("engine", "engine.json"), ("envs", "envs.json"))
LIMIT = 1.10
"""An 'after' step may be at most this factor slower than 'before' (lower-is-better units)."""


def _targets(record: dict[str, Any]) -> dict[str, tuple[float, str]]:
    """{target: (measured, unit)} of a benchmark record's measured targets."""
    return {t["target"]: (float(t["measured"]), t["unit"]) for t in record.get("targets") or []
            if isinstance(t.get("measured"), (int, float))}


ARGUMENTS = {"engine": ("--quick", "--models", "manipulator,diff_drive"), "envs": ("--quick",)}
"""Each benchmark's arguments: quick budgets; the engine on both mission models."""


def _run_in(tree: Path, scratch: Path, *args: str) -> str:
    """Stdout of ``python -m benchmarks.ARGS`` on ``tree``'s packages and this ``benchmarks``."""
    harness = scratch / f"harness-{abs(hash(str(tree)))}"
    if not harness.exists():
        harness.mkdir()
        for package in ("mdi_envs", "optimal", "baselines"):
            (harness / package).symlink_to(tree / package)
        (harness / "benchmarks").symlink_to(ROOT / "benchmarks")
    process = fresh_python("-m", f"benchmarks.{args[0]}", *args[1:], cwd=harness,
                           PYTHONPATH=str(harness))
    if process.returncode != 0:
        raise RuntimeError(f"benchmarks.{args[0]} on {tree} failed: "
                           f"{process.stderr.strip().splitlines()[-1:]}")
    return process.stdout


def run_once(tree: Path, name: str, folder: Path) -> dict[str, tuple[float, str]]:
    """Run ``benchmarks.<name>`` (``ARGUMENTS``) on the package in ``tree``; its targets."""
    _run_in(tree, folder.parent, name, *ARGUMENTS[name], "--output", str(folder))
    filename = dict(BENCHMARKS)[name]
    record = json.loads((folder / filename).read_text())
    found = _targets(record)
    probe = (record.get("machine") or {}).get("speed_probe_at_start") or {}
    if "median_us" in probe:  # the VM's phase at the run's start (benchmarks.timing)
        found["speed probe at start (compiled no-op call, median)"] = (probe["median_us"], "µs")
    return found


def run(before: Path, rounds: int, output: Path) -> str:
    """Alternate the trees ``rounds`` times, write the JSON and PNG, return the table."""
    log = Progress()
    samples: dict[str, dict[str, list[float]]] = {"before": {}, "after": {}}
    units: dict[str, str] = {}
    with tempfile.TemporaryDirectory(prefix="before-after-") as scratch:
        for round_index in range(rounds):
            for label, tree in (("before", before), ("after", ROOT)):
                for name, _ in BENCHMARKS:
                    log(f"round {round_index + 1}/{rounds}: {name} on {label} ({tree})")
                    folder = Path(scratch) / f"{label}-{name}-{round_index}"
                    for target, (value, unit) in run_once(tree, name, folder).items():
                        samples[label].setdefault(f"{name}: {target}", []).append(value)
                        units[f"{name}: {target}"] = unit
                for model in ("manipulator", "diff_drive"):
                    # (min, median) µs of the in-place probe on the package in ``tree``
                    fastest, median = _run_in(tree, Path(scratch), "in_place_probe", model).split()
                    for statistic, value in (("min", float(fastest)), ("median", float(median))):
                        key = (f"in-place probe: {model} InPlaceStepper.step(), {statistic} "
                               "over 300 batches")
                        samples[label].setdefault(key, []).append(value)
                        units[key] = "µs"
    rows = []
    for target in samples["after"]:
        if target not in samples["before"]:
            continue
        old = statistics.median(samples["before"][target])
        new = statistics.median(samples["after"][target])
        unit = units[target]
        rate = "/s" in unit or "×" in unit or "per s" in unit  # higher is better
        slowdown = old / new if rate else new / old
        rows.append({"target": target, "unit": unit, "before": old, "after": new,
                     "slowdown": slowdown, "ok": slowdown <= LIMIT,
                     "before_runs": samples["before"][target],
                     "after_runs": samples["after"][target]})
    record = {"machine": machine_info(), "before_tree": str(before), "rounds": rounds,
              "limit": LIMIT, "rows": rows}
    output.mkdir(parents=True, exist_ok=True)
    (output / "before_after.json").write_text(json.dumps(record, indent=2))
    _plot(rows, output / "before_after.png")
    return report.flat_table(rows, ["target", "unit", "before", "after", "slowdown", "ok"])


def _plot(rows: list[dict[str, Any]], path: Path) -> None:
    figure, axis = report.plt.subplots(figsize=(9, 0.35 * len(rows) + 1.5))
    labels = [row["target"][:70] for row in rows]
    axis.barh(range(len(rows)), [row["slowdown"] for row in rows],
              color=["tab:green" if row["ok"] else "tab:red" for row in rows])
    axis.axvline(1.0, color="k", linewidth=1)
    axis.axvline(LIMIT, color="tab:red", linestyle="--", linewidth=1, label=f"limit {LIMIT:g}")
    axis.set_yticks(range(len(rows)), labels, fontsize=7)
    axis.set_xlabel("after / before (time; inverse for rates): > 1 is slower")
    axis.legend(fontsize=8)
    report.save_figure(figure, path, dpi=120)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns 1 if a target got slower than the limit."""
    args = arguments(__doc__, argv, ("--before", {"type": Path, "required": True,
                                                  "help": "a checkout of the earlier commit"}),
                     ("--rounds", {"type": int, "default": 2, "help": "alternations"}),
                     quick=False)
    if not (args.before / "mdi_envs" / "__init__.py").exists():
        raise SystemExit(f"--before {args.before}: no mdi_envs package there")
    print(run(args.before.resolve(), args.rounds, args.output))
    record = json.loads((args.output / "before_after.json").read_text())
    return 0 if all(row["ok"] for row in record["rows"]) else 1


if __name__ == "__main__":
    sys.exit(main())
