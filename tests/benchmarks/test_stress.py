"""Tests of the numerical stress test (``benchmarks/stress.py``) in its quick mode.

One module-scoped run of ``run(tmp, quick=True)`` (it compiles the block's and the manipulator's
step kernels: 20-50 s in a fresh process) feeds the checks on its outcome and outputs; the
criterion evaluators are then shown to fail on deliberately broken inputs, so that a passing
case means something.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:  # ``benchmarks`` is a folder of the repository, not installed
    sys.path.insert(0, str(ROOT))

from benchmarks.stress import (  # noqa: E402
    Trace,
    at_least,
    at_most,
    energy_excess_ratio,
    health_criteria,
    lcp_criteria,
    lcp_outcome,
    markdown_report,
    run,
)
from benchmarks.stress_report import margin  # noqa: E402
from mdi_envs.solvers.status import SolverStatus  # noqa: E402


@pytest.fixture(scope="module")
def outcome(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], Path]:
    """The quick run's record and its output folder."""
    output = tmp_path_factory.mktemp("stress")
    return run(output, quick=True, log=lambda message: None), output


def test_every_stress_case_passes(outcome: tuple[dict[str, Any], Path]) -> None:
    record, _ = outcome
    failing = [f"{c['name']}: {name} {v['value']:.3g} (limit {v['relation']} {v['limit']:.3g})"
               for c in record["cases"] for name, v in c["criteria"].items() if not v["passed"]]
    assert not failing, "failing stress cases:\n" + "\n".join(failing)
    assert record["passed"] and record["num_failed"] == 0


def test_every_family_is_run(outcome: tuple[dict[str, Any], Path]) -> None:
    record, _ = outcome
    families = {c["family"] for c in record["cases"]}
    assert families == {"zeno", "brake_toggle", "dt_sweep", "mu_sweep", "overdrive", "lcp",
                        "long_horizon"}
    zeno = [c for c in record["cases"] if c["family"] == "zeno"]
    assert [(c["parameters"]["eps"], c["parameters"]["locate_impacts"]) for c in zeno] == [
        (eps, located) for eps in (0.0, 0.3, 0.6, 0.9, 0.99) for located in (False, True)]
    dts = {c["parameters"]["dt"] for c in record["cases"] if c["family"] == "dt_sweep"}
    assert min(dts) == 1e-6 and max(dts) == 0.1


def test_outputs_are_written(outcome: tuple[dict[str, Any], Path]) -> None:
    record, output = outcome
    assert (output / "stress.png").stat().st_size > 10_000
    saved = json.loads((output / "stress.json").read_text())
    assert saved["num_cases"] == len(saved["cases"]) == len(record["cases"])
    assert saved["machine"]["cpu_count"] and saved["run_time_s"] > 0
    for case in saved["cases"]:
        assert case["criteria"], case["name"]
        for criterion in case["criteria"].values():
            assert set(criterion) == {"value", "limit", "relation", "passed"}
        assert case["passed"] == all(c["passed"] for c in case["criteria"].values())


def test_markdown_report_has_one_row_per_case(outcome: tuple[dict[str, Any], Path]) -> None:
    record, _ = outcome
    text = markdown_report(record)
    rows = [line for line in text.splitlines() if line.startswith("| ") and "---" not in line]
    assert len(rows) == len(record["cases"]) + 1  # plus the header
    for case in record["cases"]:
        assert f"| {case['name']} |" in text


def _trace(q: np.ndarray, status: np.ndarray) -> Trace:
    """A hand-made trace of C = len(status) calls, one copy, n = 2."""
    calls = status.shape[0]
    info = np.zeros((calls, 1, 5))
    info[:, 0, 0] = status
    return Trace(q=q, u=np.zeros_like(q), impulses=np.zeros((calls, 1, 1)), info=info,
                 tau=np.zeros((calls, 1, 1)), brake=np.zeros((calls, 1, 1)), stride=1, dt=1e-3)


def test_health_criteria_flag_nan_and_failed_solves() -> None:
    q = np.zeros((4, 1, 2))
    good = health_criteria(_trace(q, np.zeros(3)))
    assert all(c["passed"] for c in good.values())
    q[2, 0, 1] = np.nan
    broken = health_criteria(_trace(q, np.array([0.0, SolverStatus.MAX_ITER, 0.0])))
    assert not broken["non_finite"]["passed"] and broken["non_finite"]["value"] == 1
    assert not broken["solver_failures"]["passed"]


def test_energy_gain_is_flagged() -> None:
    energy = np.array([1.0, 0.9, 0.95, 1.2])  # ends 0.2 J above its start
    allowance = np.full(4, 1e-3)
    assert energy_excess_ratio(energy, np.zeros(4), allowance) == pytest.approx(200.0)
    assert not at_most(energy_excess_ratio(energy, np.zeros(4), allowance), 1.0)["passed"]
    # the same rise is fine when the inputs supplied that work
    supplied = np.array([0.0, 0.0, 0.1, 0.25])
    assert at_most(energy_excess_ratio(energy, supplied, allowance), 1.0)["passed"]
    # a blow-up to inf or NaN never passes
    assert not at_most(energy_excess_ratio(np.array([1.0, np.inf]), np.zeros(2),
                                           np.ones(2)), 1.0)["passed"]
    assert not at_most(energy_excess_ratio(np.array([1.0, np.nan]), np.zeros(2),
                                           np.ones(2)), 1.0)["passed"]


def test_criteria_fail_on_non_finite_values() -> None:
    assert not at_most(math.nan, 1.0)["passed"] and not at_least(math.nan, 1.0)["passed"]
    assert not at_most(math.inf, 1.0)["passed"]
    assert at_least(2, 1)["passed"] and not at_least(0, 1)["passed"]
    assert margin(at_most(0.5, 1.0)) == 0.5 and margin(at_most(math.nan, 1.0)) > 1.0
    assert margin(at_most(0, 0)) < 1.0 < margin(at_most(3, 0))


def test_lcp_criteria_flag_false_claims() -> None:
    # a converged claim with a residual above the tolerance (or a NaN z) is dishonest
    claims = [{"method": "lemke", "status": "CONVERGED", "honest": False},
              {"method": "pgs", "status": "MAX_ITER", "honest": True}]
    criteria = lcp_criteria("solvable", claims)
    assert not criteria["dishonest_results"]["passed"]
    # on an infeasible problem an exact method must not claim a solution
    infeasible = lcp_criteria("infeasible", [{"method": "lemke", "status": "CONVERGED",
                                              "honest": True}])
    assert not infeasible["exact_claims_on_infeasible"]["passed"]
    unsolved = lcp_criteria("solvable", [{"method": "lemke", "status": "MAX_ITER",
                                          "honest": True}])
    assert not unsolved["exact_solved"]["passed"]


def test_lcp_outcome_reports_infeasible_problem_honestly() -> None:
    M, q = np.zeros((3, 3)), -np.ones(3)
    for method in ("lemke", "enumerative", "pgs", "newton_fb"):
        result = lcp_outcome(M, q, method)
        assert result["honest"] and result["status"] != "CONVERGED", result
