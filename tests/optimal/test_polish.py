"""The continuous-time polish: switching times and t_f under the event-driven integrator."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from mdi_envs.mechanics.models.blockable_manipulator import BlockableManipulator
from mdi_envs.stepping.event_driven import EventDrivenIntegrator
from optimal.polish import (
    SwitchingSchedule,
    pattern_on_grid,
    polish,
    schedule_from_reference,
    simulate_schedule,
)
from optimal.problems import make_problem
from optimal.references import load_reference


def test_polish_recovers_the_double_integrators_bang_bang_minimum_time() -> None:
    # 0 -> 1 m at rest, |F| <= 1 N, unit mass: full thrust to t = 1 s, full brake to T = 2 s.
    start = SwitchingSchedule(((0.7,),), (1.0,), (), 1.5)
    result = polish(make_problem("double_integrator"), start)
    assert result.success, result.message
    assert result.schedule.final_time == pytest.approx(2.0, abs=1e-9)
    assert result.schedule.switches[0][0] == pytest.approx(1.0, abs=1e-9)
    assert result.goal_error <= 1e-10


@pytest.mark.slow
def test_polish_moves_an_early_brake_lock_to_an_impulsive_stop_at_t_f() -> None:
    # The manipulator to (pi/2, pi/2): a schedule reaching the goal with its last brake phase
    # engaged 0.3 s before t_f (the best such schedule, from ``polish(min_gaps=...)``).
    problem = dataclasses.replace(make_problem("manipulator_time"),
                                  goal_q={0: math.pi / 2, 1: math.pi / 2})
    t_f = 3.3969259960918827
    early = SwitchingSchedule(((1.6984629979854453,),), (1.0,),
                              (((1.6298442762218581, 1.6298442762218581), (t_f - 0.3, t_f)),), t_f)
    integrator = EventDrivenIntegrator(BlockableManipulator, rtol=1e-8, atol=1e-10)
    start = simulate_schedule(integrator, problem, early)
    assert np.abs(start.q - math.pi / 2).max() <= 1e-6 and np.abs(start.u).max() <= 1e-6
    result = polish(problem, early, rtol=1e-8, atol=1e-10)
    assert result.success, result.message
    assert result.goal_error <= 1e-8
    assert result.schedule.final_time < 0.98 * t_f  # 3.3097 s
    engage, release = result.schedule.phases[0][-1]
    assert release == pytest.approx(result.schedule.final_time, abs=1e-12)
    assert release - engage <= 1e-6  # shrunk to an instant: the lock at t_f


def test_schedule_from_reference_reads_the_shipped_mode_sequence() -> None:
    reference = load_reference("manipulator_time")
    schedule = schedule_from_reference(reference)
    t_f = reference.final_time
    assert schedule.final_time == t_f and schedule.initial_signs == (1.0,)
    (switch,) = schedule.switches[0]
    assert abs(switch - t_f / 2) <= reference.time_step
    engaged = np.isinf(reference.brake_bound[:, 0])
    assert len(schedule.phases[0]) == np.count_nonzero(np.diff(engaged.astype(int)) == 1)
    assert schedule.phases[0][-1][1] == t_f  # engaged in the last interval
    # The grid pattern of the schedule is the reference's own.
    pattern = pattern_on_grid(schedule, reference.metadata["num_intervals"])
    assert pattern.engaged is not None and (pattern.engaged[0] == engaged).all()
    with pytest.raises(ValueError, match="time-optimal"):
        schedule_from_reference(load_reference("diff_drive_effort"))


def test_pattern_on_grid_puts_an_instant_lock_into_its_interval() -> None:
    schedule = SwitchingSchedule(((),), (1.0,), (((1.0, 2.0), (3.3, 3.3), (4.0, 4.0)),), 4.0)
    row = pattern_on_grid(schedule, 8).engaged[0]
    # midpoints 0.25, 0.75, ...: [1, 2] covers 1.25 and 1.75; 3.3 lies in [3, 3.5); t_f: last.
    assert row.tolist() == [False, False, True, True, False, False, True, True]


def test_gaps_round_trip_and_chain_totals() -> None:
    schedule = SwitchingSchedule(((1.0, 2.5),), (-1.0,), (((0.5, 0.5), (2.0, 3.0)),), 3.0)
    gaps = schedule.gaps()
    assert gaps.tolist() == [1.0, 1.5, 0.5, 0.5, 0.0, 1.5, 1.0, 0.0]
    assert schedule.with_gaps(gaps) == schedule
    assert (schedule.chain_totals() @ gaps == 3.0).all()
    with pytest.raises(ValueError, match="time-optimal"):
        polish(make_problem("diff_drive_effort"), schedule)
