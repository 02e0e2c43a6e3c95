"""Refinement toward the continuous-time optimum: start variants, levels, the order table."""

from __future__ import annotations

import math

import pytest

from optimal.convergence import end_variants, study_table
from optimal.polish import SwitchingSchedule


def test_end_variants_replace_the_last_brake_phases() -> None:
    schedule = SwitchingSchedule(((2.0,),), (1.0,), (((1.0, 1.5), (3.0, 3.2), (3.5, 4.0)),), 4.0)
    variants = end_variants(schedule)
    assert variants["as found"] is schedule
    assert variants["lock at t_f"].phases == (((1.0, 1.5), (4.0, 4.0)),)
    assert variants["engaged to t_f"].phases == (((1.0, 1.5), (3.5, 4.0)),)
    no_brake = SwitchingSchedule(((1.0,),), (1.0,), (), 2.0)
    assert list(end_variants(no_brake)) == ["as found"]


def test_study_table_gives_the_observed_order() -> None:
    levels = {str(n): {"num_intervals": n, "cost": 2.0 + 0.3 / n ** 2, "start_cost": 2.1}
              for n in (10, 20, 40)}
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
    level = solve_level("double_integrator", SwitchingSchedule(((1.0,),), (1.0,), (), 2.0), 10)
    assert level["converged"]
    assert level["cost"] == pytest.approx(2.0, abs=1e-6)
