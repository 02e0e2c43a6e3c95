"""Reading a solution's modes and arrays back from the NLP."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

pytest.importorskip("casadi")

from optimal.problems import make_problem  # noqa: E402
from optimal.solution import read_modes, read_solution, values_at  # noqa: E402
from optimal.transcription import Transcription  # noqa: E402


@pytest.mark.parametrize("num_intervals", [1, 3])
def test_robot_modes_keep_one_row_per_contact(num_intervals: int) -> None:
    # one interval left (the MPC's last steps): CasADi returns the (3, 1) slip speeds as (3,)
    problem = dataclasses.replace(make_problem("diff_drive_time", num_intervals),
                                  goal_u_tolerance=0.1)
    transcription = Transcription(problem)
    transcription.set_naive_guess()
    point = np.asarray(transcription.opti.value(transcription.opti.x,
                                                transcription.opti.initial())).ravel()
    solved, values = values_at(problem, None, point, transcription)
    modes = read_modes(solved, values)
    assert modes.sliding is not None and modes.sliding.shape == (3, num_intervals)
    arrays, _ = read_solution(solved, values)
    assert arrays["slip_speed"].shape == (num_intervals, 3)
    assert arrays["mode"].shape == (num_intervals,)
