"""Speed before and after a change, in one run: the engine and env benchmarks on two trees.

``python -m benchmarks.before_after --before DIR [--rounds 2]`` runs the quick engine and env
benchmarks and ``probes.in_place`` alternately on the package in DIR and on this tree, in fresh
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
from benchmarks.timing import ROOT, Log, arguments, fresh_python

LIMIT = 1.10
"""An 'after' step may be at most this factor slower than 'before' (lower-is-better units)."""
ARGUMENTS = {"engine": ("--quick", "--models", "manipulator,diff_drive"), "envs": ("--quick",)}
"""The benchmarks run (each writes NAME.json) with their arguments: quick budgets; the engine on
both mission models."""


def _run_in(tree: Path, scratch: Path, *args: str) -> str:
    """Stdout of ``python -m benchmarks.ARGS`` on ``tree``'s packages and this ``benchmarks``."""
    harness = scratch / f"harness-{abs(hash(str(tree)))}"
    if not harness.exists():
        harness.mkdir()
        for package in ("mdi_envs", "optimal", "baselines"):
            (harness / package).symlink_to(tree / package)
        (harness / "benchmarks").symlink_to(ROOT / "benchmarks")
    process = fresh_python("-m", f"benchmarks.{args[0]}", *args[1:], cwd=harness,
                           PYTHONPATH=harness)
    if process.returncode != 0:
        raise RuntimeError(f"benchmarks.{args[0]} on {tree} failed: "
                           f"{process.stderr.strip().splitlines()[-1:]}")
    return process.stdout


def run_once(tree: Path, scratch: Path, log: Log) -> dict[str, tuple[float, str]]:
    """{target: (value, unit)} of one round on the package in ``tree``.

    Each benchmark's measured targets and its speed probe at the start (the VM's phase), then
    the in-place probes.
    """
    found = {}
    for name, options in ARGUMENTS.items():
        log(f"{name} on {tree}")
        folder = Path(tempfile.mkdtemp(dir=scratch))
        _run_in(tree, scratch, name, *options, "--output", str(folder))
        record = json.loads((folder / f"{name}.json").read_text())
        probe = {"target": "speed probe at start (compiled no-op call, median)", "unit": "µs",
                 "measured": (record["machine"].get("speed_probe_at_start") or {}).get("median_us")}
        found.update({f"{name}: {t['target']}": (float(t["measured"]), t["unit"])
                      for t in [*(record.get("targets") or []), probe]
                      if isinstance(t.get("measured"), (int, float))})
    for model in ("manipulator", "diff_drive"):  # (min, median) µs of the in-place probe
        fastest, median = _run_in(tree, scratch, "probes", "in-place", model).split()
        for statistic, value in (("min", fastest), ("median", median)):
            found[f"in-place probe: {model} InPlaceStepper.step(), {statistic} over 300 "
                  "batches"] = (float(value), "µs")
    return found


def run(before: Path, rounds: int, output: Path) -> dict[str, Any]:
    """Alternate the trees ``rounds`` times, write the JSON and PNG; returns the record."""
    samples: dict[str, dict[str, list[float]]] = {}  # target -> label -> values
    units: dict[str, str] = {}
    config = {"before_tree": str(before), "rounds": rounds, "limit": LIMIT}
    with (report.study("before_after", output, config) as (record, log, _),
          tempfile.TemporaryDirectory(prefix="before-after-") as scratch):
        for round_index in range(rounds):
            for label, tree in (("before", before), ("after", ROOT)):
                log(f"round {round_index + 1}/{rounds}, {label}:")
                for target, (value, unit) in run_once(tree, Path(scratch), log).items():
                    samples.setdefault(target, {"before": [], "after": []})[label].append(value)
                    units[target] = unit
        record["rows"] = []
        for target, runs in samples.items():
            if runs["before"] and runs["after"]:
                old, new = (statistics.median(runs[label]) for label in ("before", "after"))
                rate = any(mark in units[target] for mark in ("/s", "×", "per s"))  # higher: better
                slowdown = old / new if rate else new / old
                record["rows"].append({"target": target, "unit": units[target], "before": old,
                                       "after": new, "slowdown": slowdown, "ok": slowdown <= LIMIT,
                                       "before_runs": runs["before"], "after_runs": runs["after"]})
        _plot(record["rows"], output / "before_after.png")
    return record


def _plot(rows: list[dict[str, Any]], path: Path) -> None:
    """Bars of after / before per target: within the limit, or beyond it."""
    figure, axis = report.plt.subplots(figsize=(9, 0.35 * len(rows) + 1.5))
    axis.axvline(1.0, color="k", linewidth=1)
    axis.axvline(LIMIT, color="tab:red", linestyle="--", linewidth=1, label=f"limit {LIMIT:g}")
    report.bars(axis, [row["target"][:70] for row in rows], {
        "within the limit": [row["slowdown"] if row["ok"] else None for row in rows],
        "slower than the limit": [None if row["ok"] else row["slowdown"] for row in rows]},
        "after / before (time; inverse for rates): > 1 is slower", log=False)
    report.save_figure(figure, path, dpi=120)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns 1 if a target got slower than the limit."""
    args = arguments(__doc__, argv, ("--before", {"type": Path, "required": True,
                                                  "help": "a checkout of the earlier commit"}),
                     ("--rounds", {"type": int, "default": 2, "help": "alternations"}),
                     quick=False)
    if not (args.before / "mdi_envs" / "__init__.py").exists():
        raise SystemExit(f"--before {args.before}: no mdi_envs package there")
    record = run(args.before.resolve(), args.rounds, args.output)
    print(report.flat_table(record["rows"],
                            ["target", "unit", "before", "after", "slowdown", "ok"]))
    return 0 if all(row["ok"] for row in record["rows"]) else 1


if __name__ == "__main__":
    sys.exit(main())
