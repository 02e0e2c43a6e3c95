"""The stress criteria fail on broken inputs; ``mdi-envs bench stress`` reports case records.

The criterion evaluators are shown to fail on deliberately broken inputs, so that a passing case
means something; the report (table, JSON, plot) is checked on hand-made records.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from peer_data import peer_files
from stress.cases import (
    FULL,
    QUICK,
    Trace,
    at_least,
    at_most,
    energy_excess_ratio,
    health_criteria,
    lcp_criteria,
    lcp_outcome,
    plan,
)

from benchmarks import stress as bench_stress
from mdi_envs.solvers.status import SolverStatus


def test_plan_covers_every_family_once_per_name() -> None:
    cases = plan()
    names = [c.name for c in cases]
    assert len(names) == len(set(names))
    assert {c.family for c in cases} >= {"zeno", "brake_toggle", "dt_sweep", "mu_sweep",
                                         "overdrive", "lcp", "long_horizon"}
    zeno = [c.args for c in cases if c.family == "zeno"]
    assert zeno == [(eps, located) for eps in (0.0, 0.3, 0.6, 0.9, 0.99)
                    for located in (False, True)]
    dts = {c.args[1] for c in cases if c.family == "dt_sweep"}
    assert min(dts) == 1e-6 and max(dts) == 0.1
    peers = bool(peer_files("lcp"))  # the Siconos files are one case where they are present
    assert (len(plan(FULL)), len(plan(QUICK))) == (80 + peers, 58 + peers)


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
    margin = bench_stress.margin
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


def test_report_of_a_failing_case(tmp_path: Path) -> None:
    cases = [{"family": "lcp", "name": "lcp good", "parameters": {"n": 2, "eps": 0.25},
              "metrics": {}, "criteria": {"dishonest_results": at_most(0, 0)}, "passed": True},
             {"family": "lcp", "name": "lcp bad", "parameters": {"dt": [1e-3, 2e-3]},
              "metrics": {}, "criteria": {"energy": at_most(math.inf, 1.0)}, "passed": False}]
    check = bench_stress.target(cases)
    assert (check["measured"], check["threshold"], check["met"]) == (1, 2, False)
    assert check["note"] == "failed: lcp bad"
    assert bench_stress.target(cases[:1])["met"] and not bench_stress.target([])["met"]
    record = {"cases": cases, "config": {"quick": True}, "run_time_s": 1.0, "notes": ["n1"],
              "machine": {"date": "d", "cpu_model": "c", "cpu_count": 2, "versions": {}},
              "targets": [check]}
    text = bench_stress.report.summary(record, ())
    assert "(--quick)" in text.splitlines()[0] and text.splitlines()[1] == "* n1"
    assert [cell.strip() for cell in text.splitlines()[-1].split("|")[1:-1]] == [
        "every stress case passes its criteria", "= 2 cases", "1 cases", "✗", "failed: lcp bad"]
    assert [bench_stress.margin(c["criteria"][k]) for c, k in
            ((cases[0], "dishonest_results"), (cases[1], "energy"))] == [1e-9, 1e9]
    bench_stress.plot_margins(cases, tmp_path / "stress.png")
    assert (tmp_path / "stress.png").stat().st_size > 5_000
    bench_stress.report.write_json(bench_stress.report.json_safe(record), tmp_path / "s.json")
    assert json.loads((tmp_path / "s.json").read_text())["cases"][1]["criteria"]["energy"][
        "value"] == "inf"
