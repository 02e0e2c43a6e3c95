"""Refinement toward the continuous-time optimum: start variants, levels, the order table."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from optimal.convergence import (
    end_variants,
    extrapolated_limit,
    phases_on_grid,
    richardson,
    study_table,
)
from optimal.polish import SwitchingSchedule
from optimal.references import load_reference


def _levels(cost: Callable[[int], float], sizes: tuple[int, ...]) -> dict[str, dict[str, float]]:
    """A synthetic study's levels: cost(N) after the search and as projected."""
    return {str(n): {"num_intervals": n, "cost": cost(n), "start_cost": cost(n),
                     "wall_time": 0.0} for n in sizes}


def _flat(phases: dict[str, list[Any]]) -> list[float]:
    """The phases' labels in order and their times, one list (for ``pytest.approx``)."""
    return [float(t) for label in sorted(phases) for phase in phases[label] for t in phase] + [
        len(phases[label]) for label in sorted(phases)]


def test_end_variants_replace_the_last_brake_phases() -> None:
    schedule = SwitchingSchedule(((2.0,),), (1.0,), (((1.0, 1.5), (3.0, 3.2), (3.5, 4.0)),), 4.0)
    variants = end_variants(schedule)
    assert variants["as found"] is schedule
    assert variants["lock at t_f"].phases == (((1.0, 1.5), (4.0, 4.0)),)
    assert variants["engaged to t_f"].phases == (((1.0, 1.5), (3.5, 4.0)),)
    no_brake = SwitchingSchedule(((1.0,),), (1.0,), (), 2.0)
    assert list(end_variants(no_brake)) == ["as found"]


def test_study_table_gives_the_observed_order() -> None:
    levels = _levels(lambda n: 2.0 + 0.3 / n ** 2, (10, 20, 40))
    rows = study_table({"continuous_cost": 2.0, "levels": levels})
    assert [row["num_intervals"] for row in rows] == [10, 20, 40]
    assert rows[0]["order"] == pytest.approx(2.0) and rows[1]["order"] == pytest.approx(2.0)
    assert math.isnan(rows[2]["order"])
    assert rows[2]["relative_distance"] == pytest.approx(0.3 / 1600 / 2.0)


@pytest.mark.slow
def test_level_of_the_double_integrator_is_its_exact_time() -> None:
    pytest.importorskip("casadi")
    from optimal.convergence import solve_level

    # The midpoint step is exact for a held force: with the switch on the grid, T = 2 s.
    level, _, _ = solve_level("double_integrator",
                              SwitchingSchedule(((1.0,),), (1.0,), (), 2.0), 10)
    assert level["converged"]
    assert level["cost"] == pytest.approx(2.0, abs=1e-6)


def test_richardson_recovers_limit_and_order_of_a_synthetic_series() -> None:
    levels = _levels(lambda n: 3.5 + 0.8 / n ** 1.3, (25, 50, 100, 200, 400))
    limit = extrapolated_limit({"name": "synthetic", "levels": levels})
    assert limit["value"] == pytest.approx(3.5, abs=1e-12)
    assert limit["order"] == pytest.approx(1.3, abs=1e-9)
    assert limit["coefficient"] == pytest.approx(0.8, rel=1e-9)
    assert limit["levels"] == [100, 200, 400]
    assert limit["uncertainty"] == pytest.approx(0.0, abs=1e-12)
    # A second-order term makes the two fits differ; the finer one is closer to the limit.
    levels = _levels(lambda n: 3.5 + 0.8 / n + 5.0 / n ** 2, (25, 50, 100, 200, 400))
    limit = extrapolated_limit({"name": "synthetic", "levels": levels})
    assert abs(limit["value"] - 3.5) < abs(limit["previous"] - 3.5)
    assert limit["uncertainty"] > abs(limit["value"] - 3.5)
    row_orders = [row["order"] for row in study_table({"levels": levels,
                                                       "extrapolation": limit})]
    assert row_orders[-2] == pytest.approx(limit["order"])


def test_richardson_reports_a_series_that_is_not_monotone() -> None:
    assert all(math.isnan(v) for v in richardson([10, 20, 40], [2.0, 1.9, 1.95]).values())
    # monotone, but the changes grow: no fit with a positive order
    assert all(math.isnan(v) for v in richardson([10, 20, 40], [2.0, 2.1, 2.3]).values())
    with pytest.raises(ValueError, match="r\\^2 N"):
        richardson([10, 20, 50], [2.0, 1.9, 1.85])
    gapped = extrapolated_limit({"name": "gapped",
                                 "levels": _levels(lambda n: 1.0 + 1.0 / n, (25, 200, 400))})
    assert math.isnan(gapped["value"]) and math.isnan(gapped["uncertainty"])


def test_phases_on_grid_repeats_a_pattern_but_keeps_the_terminal_rest_one_interval() -> None:
    level = max(load_reference("diff_drive_time").metadata["refinement"]["levels"],
                key=lambda lv: lv["num_intervals"])
    n, final_time = level["num_intervals"], level["final_time"]
    pattern = phases_on_grid(level["phases"], final_time, n, n)
    assert pattern.engaged is None and pattern.sliding.shape == (3, n)
    phases = pattern.phases(np.linspace(0.0, final_time, n + 1))
    assert _flat(phases) == pytest.approx(_flat(level["phases"]), abs=1e-12)
    # Every contact of this level sticks in the last interval only (the rest at t_f): on a
    # 4x finer grid, still the last interval only; elsewhere each interval repeated.
    assert not pattern.sliding[:, -1].any() and pattern.sliding[:, -2].all()
    finer = phases_on_grid(level["phases"], final_time, 4 * n, n).sliding
    repeated = pattern.refined(4).sliding
    np.testing.assert_array_equal(finer[:, :-4], repeated[:, :-4])
    assert finer[:, -4:-1].all() and not finer[:, -1].any()


def test_robot_level_with_the_pattern_fixed_is_the_shipped_optimum_of_its_grid() -> None:
    pytest.importorskip("casadi")
    from optimal.convergence import solve_level

    # The finest level's stick-slip phases projected on N = 25 are those the shipped N = 25
    # level (freed and mode-searched) found; solved with them fixed, the same optimum.
    shipped = load_reference("diff_drive_effort").metadata["refinement"]["levels"][0]
    assert shipped["num_intervals"] == 25
    level, _, best = solve_level("diff_drive_effort", None, 25, max_rounds=0)
    assert level["converged"]
    assert _flat(level["phases"]) == pytest.approx(_flat(shipped["phases"]), abs=1e-9)
    assert level["cost"] == pytest.approx(shipped["cost"], rel=1e-8)
