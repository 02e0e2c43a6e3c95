"""Refinement toward the continuous-time optimum: start variants, levels, the order table."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
import pytest

from optimal.convergence import (
    CONTINUOUS_DIR,
    end_variants,
    phases_on_grid,
    richardson,
    schedule_start,
    study_start,
    study_table,
)
from optimal.polish import SwitchingSchedule


def _levels(cost: Callable[[int], float], sizes: tuple[int, ...]) -> dict[str, dict[str, float]]:
    """A synthetic study's levels: cost(N) after the search and as projected."""
    return {str(n): {"num_intervals": n, "cost": cost(n), "start_cost": cost(n),
                     "wall_time": 0.0} for n in sizes}


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
    schedule = SwitchingSchedule(((1.0,),), (1.0,), (), 2.0)
    level, _, _ = solve_level(partial(schedule_start, "double_integrator", schedule), 10)
    assert level["converged"]
    assert level["cost"] == pytest.approx(2.0, abs=1e-6)


def test_richardson_recovers_limit_and_order_of_a_synthetic_series() -> None:
    fit = richardson([100, 200, 400], [3.5 + 0.8 / n ** 1.3 for n in (100, 200, 400)])
    assert fit["value"] == pytest.approx(3.5, abs=1e-12)
    assert fit["order"] == pytest.approx(1.3, abs=1e-9)
    assert fit["coefficient"] == pytest.approx(0.8, rel=1e-9)
    # A second-order term: the fit through finer levels is closer to the limit.
    def cost(n: int) -> float:
        return 3.5 + 0.8 / n + 5.0 / n ** 2

    coarse = richardson([25, 50, 100], [cost(n) for n in (25, 50, 100)])["value"]
    fine = richardson([100, 200, 400], [cost(n) for n in (100, 200, 400)])["value"]
    assert abs(fine - 3.5) < abs(coarse - 3.5)


def test_richardson_reports_a_series_that_is_not_monotone() -> None:
    assert all(math.isnan(v) for v in richardson([10, 20, 40], [2.0, 1.9, 1.95]).values())
    # monotone, but the changes grow: no fit with a positive order
    assert all(math.isnan(v) for v in richardson([10, 20, 40], [2.0, 2.1, 2.3]).values())
    with pytest.raises(ValueError, match="r\\^2 N"):
        richardson([10, 20, 50], [2.0, 1.9, 1.85])


def _continuous(name: str) -> dict[str, Any]:
    return json.loads((CONTINUOUS_DIR / f"{name}.json").read_text())


def test_phases_on_grid_puts_switches_at_midpoints_and_the_stop_in_the_last_interval() -> None:
    record = _continuous("diff_drive_effort")
    wheels_slide = record["phases"][1]
    assert wheels_slide["sliding"] == [True, True, True]
    n, final_time = 100, record["final_time"]
    middle = (np.arange(n) + 0.5) * final_time / n
    sliding = {f"contact {j}": [[phase["start"], phase["end"]] for phase in record["phases"]
                                if phase["sliding"][j]] for j in range(3)}
    pattern = phases_on_grid(sliding, final_time, n)
    assert pattern.engaged is None and pattern.sliding.shape == (3, n)
    expected = (middle >= wheels_slide["start"]) & (middle <= wheels_slide["end"])
    np.testing.assert_array_equal(pattern.sliding[0], expected)
    np.testing.assert_array_equal(pattern.sliding[1], expected)
    # the caster slides throughout, but every contact sticks in the last interval (the stop)
    assert pattern.sliding[2, :-1].all() and not pattern.sliding[:, -1].any()


def test_robot_level_from_the_continuous_phases_keeps_them_and_lies_above_the_optimum() -> None:
    pytest.importorskip("casadi")
    from optimal.convergence import continuous_cost, solve_level

    record = _continuous("diff_drive_effort")
    level, _, _ = solve_level(study_start("diff_drive_effort", record), 25, max_rounds=0)
    assert level["converged"] and level["kept_pattern"]
    optimum = continuous_cost(record)
    assert optimum < level["cost"] < 1.01 * optimum


def test_reference_solve_reproduces_the_shipped_reference() -> None:
    pytest.importorskip("casadi")
    from optimal.convergence import reference_solve
    from optimal.references import load_reference

    problem, solve = reference_solve("diff_drive_time")
    reference = load_reference("diff_drive_time")
    assert problem.num_intervals == reference.tau.shape[0]
    assert solve.success and solve.found_modes.key() == solve.modes.key()
    assert solve.cost == pytest.approx(reference.cost, rel=1e-7)


@pytest.mark.slow
def test_reference_chain_moves_toward_the_continuous_optimum() -> None:
    pytest.importorskip("casadi")
    from optimal.convergence import chain_levels, continuous_cost

    optimum = continuous_cost(_continuous("diff_drive_time"))
    coarse, fine = chain_levels("diff_drive_time", [100, 200])
    assert coarse["num_intervals"] == 100 and fine["num_intervals"] == 200
    assert fine["converged"] and fine["start_cost"] >= fine["cost"] - 1e-9
    # refined and freed, the grid's optimum comes closer to the continuous one
    assert abs(fine["cost"] - optimum) < 0.75 * abs(coarse["cost"] - optimum)
    with pytest.raises(ValueError, match="not a multiple"):
        list(chain_levels("diff_drive_time", [150]))
