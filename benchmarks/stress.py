"""``mdi-envs bench stress``: run the stress cases of ``tests/stress`` and write their record.

Runs the ``stress`` pytest cases (``--quick``: ``MDI_ENVS_STRESS=quick``), collects the record
each attaches (parameters, metrics, criteria) into ``stress.json`` with the target that every case
passes, and their margins into ``stress.png``. Exits with 1 if any case fails.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from benchmarks import report
from benchmarks.timing import arguments

TESTS = Path(__file__).resolve().parents[1] / "tests" / "stress"  # The folder of the stress cases.
MARGIN_FLOOR, MARGIN_CEILING = 1e-9, 1e9
"""Margins are drawn within these (a zero count at the floor; a failed count, NaN, inf above)."""


class _Collector:
    """A pytest plug-in that keeps the records the stress cases attach to their reports."""

    def __init__(self) -> None:
        self.cases: list[dict[str, Any]] = []
        self.run: dict[str, Any] = {}

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        """Collect ``stress_case`` and ``stress_run`` properties of each case's call."""
        for key, value in report.user_properties if report.when == "call" else ():
            if key == "stress_case":
                self.cases.append(json.loads(value))
            elif key == "stress_run":
                self.run = json.loads(value)


def run(output: Path, quick: bool) -> dict[str, Any]:
    """Run every stress case, write ``stress.json`` and ``stress.png`` to ``output``."""
    with report.study("stress", output, {"quick": quick}) as (record, _, _):
        collector = _Collector()
        os.environ["MDI_ENVS_STRESS"] = "quick" if quick else "full"
        code = pytest.main([str(TESTS), "-q", "-m", "stress", "-p", "no:cacheprovider"],
                           plugins=[collector])
        cases = collector.cases
        record.update({
            "config": collector.run.get("config") or record["config"],
            "notes": collector.run.get("notes", []), "cases": cases,
            "passed": bool(cases) and all(c["passed"] for c in cases), "num_cases": len(cases),
            "num_failed": sum(not c["passed"] for c in cases),
            "compile_s": collector.run.get("compile_s", {})})
        if code not in (pytest.ExitCode.OK, pytest.ExitCode.TESTS_FAILED):
            record["passed"], record["pytest_exit_code"] = False, int(code)
        record["targets"] = [target(cases)]
        if cases:
            plot_margins(cases, output / "stress.png")
    return record


def margin(criterion: Mapping[str, Any]) -> float:
    """How close a criterion is to failing: < 1 passes, > 1 fails (``value / limit`` for ``<=``)."""
    value, limit = float(criterion["value"]), float(criterion["limit"])
    if not math.isfinite(value):
        return MARGIN_CEILING
    if criterion["relation"] == ">=":
        value, limit = limit, value
    if limit <= 0.0:
        return MARGIN_FLOOR if value <= limit else MARGIN_CEILING
    return float(np.clip(value / limit, MARGIN_FLOOR, MARGIN_CEILING))


def target(cases: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The target check that every case passes its criteria: passed of total, failures named."""
    failed = [case["name"] for case in cases if not case.get("passed")]
    return report.target_row("every stress case passes its criteria", "=", len(cases), "cases",
                             len(cases) - len(failed), ("failed: " + ", ".join(failed)) if failed
                             else "", met=bool(cases) and not failed)


def plot_margins(cases: Sequence[Mapping[str, Any]], path: Path) -> None:
    """One row per case, one dot per criterion at its margin (log x); green passes, red fails."""
    fig, ax = report.plt.subplots(figsize=(10.0, 0.19 * len(cases) + 1.6))
    for row, case in enumerate(cases):
        for criterion in case["criteria"].values():
            ax.plot(margin(criterion), row, "o", ms=4, alpha=0.8,
                    color="tab:green" if criterion["passed"] else "tab:red")
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlim(MARGIN_FLOOR / 3, MARGIN_CEILING * 3)
    ax.set_yticks(range(len(cases)), [c["name"] for c in cases], fontsize=6.5)
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
    report.save_figure(fig, path, dpi=120)


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns 1 if any case fails, else 0."""
    args = arguments(__doc__, argv)
    record = run(args.output, args.quick)
    print(report.summary(record, ("numpy", "numba", "scipy")))
    return 0 if record["passed"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
