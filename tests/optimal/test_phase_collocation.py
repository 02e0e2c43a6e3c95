"""Continuous-time optima of the robot's mode sequences (optimal/phase_collocation.py).

The collocation solution, replayed by the event-driven integrator (an independent method with
its own mode decisions), must show the same stick-slip events and reach the goal, closer at
more elements.
"""

from __future__ import annotations

import numpy as np
import pytest

from optimal.phase_collocation import (
    ElementInputs,
    reference_phases,
    solve_level,
    solve_phases,
)
from optimal.problems import make_problem
from optimal.references import load_reference


def test_reference_phases_read_the_effort_references_mode_sequence() -> None:
    phases = reference_phases(load_reference("diff_drive_effort"))
    assert [phase.sliding for phase in phases] == [
        (False, False, True), (True, True, True), (False, False, True)]
    assert sum(phase.duration for phase in phases) == pytest.approx(4.05)


def test_element_inputs_interpolate_their_collocation_values() -> None:
    points = (np.polynomial.legendre.leggauss(3)[0] + 1.0) / 2.0
    boundaries = np.array([0.0, 1.0, 3.0])
    quadratic = [lambda t: 1.0 + 2.0 * t - t * t, lambda t: 4.0 - t]
    values = np.array([[[f(a + x * (b - a)) for f in quadratic] for x in points]
                       for a, b in zip(boundaries[:-1], boundaries[1:], strict=True)])
    inputs = ElementInputs(boundaries, values)
    for t in (0.0, 0.3, 1.0, 2.2, 3.0):
        assert inputs(t) == pytest.approx([f(t) for f in quadratic], abs=1e-12)
    assert list(inputs.switch_times) == [1.0]


@pytest.mark.slow
def test_effort_optimum_replays_with_its_modes_and_reaches_the_goal() -> None:
    reference = load_reference("diff_drive_effort")
    coarse_record, coarse = solve_level(reference, 10)
    fine_record, fine = solve_level(reference, 20, coarser=coarse)
    assert fine_record["start"] == 10
    errors = []
    for record, result in ((coarse_record, coarse), (fine_record, fine)):
        assert record["converged"]
        assert result.final_time == pytest.approx(4.05, abs=1e-9)
        assert record["replay"]["status"] == "completed" and record["replay"]["reaches_goal"]
        switches = np.cumsum([phase.duration for phase in result.phases])[:2]
        events = [(t, kind, i) for t, kind, i in record["replay"]["events"] if t > 0.0]
        assert [(kind, i) for _, kind, i in events] == [("slip", 0), ("slip", 1),
                                                        ("stick", 0), ("stick", 1)]
        assert events[0][0] == pytest.approx(switches[0], abs=1e-6)  # a switch of the inputs
        assert events[2][0] == pytest.approx(switches[1], abs=5e-3)  # the slides stop there
        errors.append(max(record["replay"]["goal_errors"].values()))
        # the continuous optimum of this sequence lies below the h-discrete one, within 1 %
        assert 0.99 * reference.cost < result.cost < reference.cost
    assert errors[1] < errors[0] / 2.0
    assert fine.cost < coarse.cost  # more elements, a larger control space


@pytest.mark.slow
def test_a_solution_warm_starts_its_own_problem() -> None:
    reference = load_reference("diff_drive_effort")
    first = solve_phases(reference, reference_phases(reference), elements=10)
    assert first.converged
    again = solve_phases(reference, list(first.phases), elements=10, guess=first.samples)
    assert again.converged
    assert again.cost == pytest.approx(first.cost, rel=1e-6)  # IPOPT stops at 1e-6
    # the samples hold the solution: its inputs at the collocation points, its final state
    assert first.samples.tau == pytest.approx(first.inputs.values.reshape(-1, 2), abs=1e-12)
    problem = make_problem("diff_drive_effort")
    for i, value in problem.goal_q.items():
        assert first.samples.state[-1, i] == pytest.approx(value, abs=1e-8)
