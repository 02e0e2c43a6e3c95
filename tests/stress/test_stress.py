"""Every numerical stress case (``cases.plan()``) passes all its criteria.

Each case is one parametrized test, marked ``stress``; its record is attached with
``record_property("stress_case", json)``, which ``mdi-envs bench stress`` collects into
``stress.json``. The copies of one batch share a simulation (run once per process). The models'
kernels are compiled in the module fixture, so a case's call time is its own (but for the located
kernels, compiled by the first case that uses them).
"""

from __future__ import annotations

import json
from dataclasses import asdict
from typing import Any

import pytest
from stress.cases import CONFIG, NOTES, STEPPERS, PlannedCase, plan, run_case

SLOW = frozenset({f"zeno ball eps={eps:g}{located}" for eps in (0.0, 0.3, 0.6, 0.9, 0.99)
                  for located in ("", " located") if located or eps == 0.99})
"""Cases whose call took more than 5 s (6.0-9.9 s; the others at most 4.7 s) in a full run on
the 2-core machine under load (``pytest tests/stress --durations=30``)."""


def _json(value: Any) -> str:
    return json.dumps(value, default=lambda v: v.item())


@pytest.fixture(scope="module")
def compiled() -> None:
    """Compile every model the configuration uses (the located kernels on their first case)."""
    for label in CONFIG.models:
        STEPPERS.get(label, 1e-3)


@pytest.mark.stress
@pytest.mark.parametrize("planned", [
    pytest.param(case, id=case.name, marks=[pytest.mark.slow] if case.name in SLOW else [])
    for case in plan()])  # fmt: skip
def test_stress_case(planned: PlannedCase, compiled: None,
                     record_property: Any) -> None:  # fmt: skip
    case = run_case(planned)
    record_property("stress_case", _json(case))
    record_property("stress_run", _json({"config": asdict(CONFIG), "notes": NOTES,
                                         "compile_s": STEPPERS.compile_s}))
    failing = [f"{name} {c['value']:.3g} (limit {c['relation']} {c['limit']:.3g})"
               for name, c in case["criteria"].items() if not c["passed"]]
    assert case["criteria"] and not failing, f"{case['name']}: " + "; ".join(failing)
    assert case["passed"]
