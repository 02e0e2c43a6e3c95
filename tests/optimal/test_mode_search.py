"""Mode patterns, fixed-pattern solves, the mode-neighbourhood search and mesh refinement."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from optimal.modes import ModePattern

SHORT_N = 40
"""A manipulator grid coarse enough for CI: its continuation takes ~2 s, a fixed-pattern
solve ~0.3 s."""


def _row(text: str) -> np.ndarray:
    return np.array([c == "1" for c in text], dtype=bool)


def test_neighbours_shift_flip_and_split_each_phase_once() -> None:
    pattern = ModePattern(engaged=_row("0011100")[None, :])
    moves = dict(pattern.neighbours(max_shift=1))
    rows = {label.split(": ", 1)[1]: "".join(str(int(v)) for v in p.engaged[0])
            for label, p in moves.items()}
    assert rows == {
        "switch at 2 shifted by -1": "0111100",
        "switch at 2 shifted by +1": "0001100",
        "switch at 5 shifted by -1": "0011000",
        "switch at 5 shifted by +1": "0011110",
        "phase 0-2 flipped": "1111100",
        "phase 2-5 flipped": "0000000",
        "phase 5-7 flipped": "0011111",
        "phase 2-5 split": "0010100",
    }
    keys = {p.key() for p in moves.values()}
    assert len(keys) == len(moves) and pattern.key() not in keys


def test_refined_pattern_repeats_each_interval_and_keeps_the_phases() -> None:
    pattern = ModePattern(engaged=_row("0110")[None, :], sliding=_row("1001")[None, :])
    fine = pattern.refined(2)
    assert fine.num_intervals == 8
    assert fine.engaged is not None and "".join(map(str, fine.engaged[0].astype(int))) == "00111100"
    time = np.linspace(0.0, 4.0, 5)
    assert pattern.phases(time) == fine.phases(np.linspace(0.0, 4.0, 9))
    with pytest.raises(ValueError, match="same number of intervals"):
        ModePattern(engaged=_row("01")[None, :], sliding=_row("011")[None, :])
    with pytest.raises(ValueError, match="bool"):
        ModePattern(engaged=np.zeros((1, 3)))


casadi = pytest.importorskip("casadi")

from optimal.global_search import Start, make_starts, run_start  # noqa: E402
from optimal.mode_search import improve_modes, solve_with_modes  # noqa: E402
from optimal.problems import make_problem  # noqa: E402
from optimal.references import Reference  # noqa: E402
from optimal.refinement import refine  # noqa: E402
from optimal.replay import replay  # noqa: E402
from optimal.solution import read_solution, values_at  # noqa: E402
from optimal.transcription import Transcription  # noqa: E402


@pytest.fixture(scope="module")
def short_optimum():  # noqa: ANN201
    """The short manipulator's continuation, then mode-searched to a local optimum."""
    problem = make_problem("manipulator_time", SHORT_N)
    result = run_start(problem, Start("naive guess", problem.final_time))
    assert result.continuation_success and result.local is not None
    return problem, result


@pytest.mark.slow  # NLP solves: the short optimum's search and its checks
def test_fixed_pattern_solve_reproduces_the_continuation_and_is_complementary(
        short_optimum) -> None:  # noqa: ANN001
    problem, result = short_optimum
    local = result.local
    # the search started from the continuation's optimum re-solved with its modes fixed
    assert local.start.cost == pytest.approx(result.continuation_cost, rel=1e-8)
    best = local.best
    assert best.success and best.residual <= 1e-8
    assert best.cost <= local.start.cost
    # a local optimum: no neighbour improves it
    for _, pattern in best.modes.neighbours():
        neighbour = solve_with_modes(problem, pattern, initial=best.point)
        assert not neighbour.success or neighbour.cost >= best.cost * (1 - 1e-7)


@pytest.mark.slow  # NLP solves: the short optimum's search and its checks
def test_mode_search_recovers_the_optimum_from_a_shifted_pattern(short_optimum) -> None:  # noqa: ANN001
    problem, result = short_optimum
    best = result.local.best
    engaged = best.modes.engaged.copy()
    switch = int(np.flatnonzero(engaged[0, 1:] != engaged[0, :-1])[0]) + 1
    engaged[0, switch - 2:switch] = engaged[0, switch]  # the first switch moved 2 earlier
    shifted = solve_with_modes(problem, ModePattern(engaged=engaged), initial=best.point)
    assert shifted.success and shifted.cost > best.cost * (1 + 1e-4)
    recovered = improve_modes(problem, shifted)
    assert recovered.steps
    assert recovered.best.cost == pytest.approx(best.cost, rel=1e-7)
    np.testing.assert_array_equal(recovered.best.modes.engaged, best.modes.engaged)


@pytest.mark.slow  # NLP solves: the short optimum's search and its checks
def test_searched_solution_replays_to_the_goal_and_refines(short_optimum) -> None:  # noqa: ANN001
    problem, result = short_optimum
    best = result.local.best
    arrays, final_time = read_solution(*values_at(problem, best.modes, best.point))
    assert final_time == pytest.approx(best.final_time)
    reference = Reference("manipulator_time", arrays,
                          {"final_time": final_time, "time_step": final_time / SHORT_N})
    report = replay(reference, 1)[0]
    assert report.reaches_goal and report.state_error <= 1e-6
    # the level's fixed-pattern solve, freed and re-solved; no neighbourhood round at N = 80
    # (18 solves that accept no move here): the rounds are checked on N = 40 above
    refinement = refine(problem, best, (2,), max_rounds=0,
                        make=lambda n: make_problem("manipulator_time", n))
    fine = refinement.levels[-1]
    assert fine.problem.num_intervals == 2 * SHORT_N and fine.solve.success
    # the same maneuver on the finer grid: t_f within 1 % (observed 0.03 %)
    assert abs(refinement.relative_changes()[0]) < 0.01


def test_starts_include_the_naive_guess_the_paper_schedule_and_random_ones() -> None:
    problem = make_problem("manipulator_time")
    starts = make_starts(problem, 5, seed=3)
    assert [s.label for s in starts] == ["naive guess", "paper schedule", "random 0",
                                         "random 1", "random 2"]
    paper = starts[1].modes.engaged[0]
    time = np.linspace(0.0, 4.53, problem.num_intervals + 1)
    phases = starts[1].modes.phases(time)["brake 0"]
    assert [round(a, 1) for a, _ in phases] == [0.0, 1.1, 2.4] and paper[-1]
    again = make_starts(problem, 5, seed=3)
    assert all(np.array_equal(a.modes.engaged, b.modes.engaged)
               for a, b in zip(starts[2:], again[2:], strict=True))
    with pytest.raises(ValueError, match="at least 1"):
        make_starts(problem, 0)
    effort = dataclasses.replace(make_problem("diff_drive_effort"))
    robot_starts = make_starts(effort, 3)
    assert all(s.final_time == effort.final_time for s in robot_starts)
    # the robot's random starts bend the path within its scale; the manipulator's stay straight
    assert robot_starts[0].bump is None and all(s.bump is None for s in starts)
    scale = np.asarray(effort.guess_bend_scale)
    for start in robot_starts[1:]:
        assert np.all(np.abs(start.bump) <= scale) and np.any(np.asarray(start.bump) != 0)


def test_a_bent_guess_keeps_its_ends_and_its_velocities_match_the_path() -> None:
    problem = make_problem("diff_drive_time", 40)
    transcription = Transcription(problem)
    bump = np.array([1.0, -0.5, 0.3, 0.0, 0.0])
    transcription.set_naive_guess(bump)
    opti = transcription.opti
    q = np.asarray(opti.value(transcription.q, opti.initial())).T
    u = np.asarray(opti.value(transcription.u, opti.initial())).T
    np.testing.assert_allclose(q[0], problem.initial_q, atol=1e-12)
    np.testing.assert_allclose(q[-1], problem.guess_final_q, atol=1e-12)
    np.testing.assert_allclose(q[20] - (np.asarray(problem.initial_q)
                                        + np.asarray(problem.guess_final_q)) / 2, bump, atol=1e-12)
    h = problem.final_time / problem.num_intervals  # central differences of q match u
    np.testing.assert_allclose((q[2:] - q[:-2]) / (2 * h), u[1:-1], rtol=0, atol=1e-2)
    with pytest.raises(ValueError, match="bump must have shape"):
        transcription.set_naive_guess(np.zeros(2))
