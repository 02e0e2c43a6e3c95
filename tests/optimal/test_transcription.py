"""The transcription and the continuation on problems with known answers."""

from __future__ import annotations

import numpy as np
import pytest

casadi = pytest.importorskip("casadi")

from mdi_envs.stepping import MoreauJeanStepper  # noqa: E402
from optimal.continuation import Schedule, solve_continuation  # noqa: E402
from optimal.problems import BALL_DROP_PARAMETERS, make_problem  # noqa: E402
from optimal.transcription import Transcription, numeric  # noqa: E402


def test_double_integrator_is_bang_bang_with_the_closed_form_time() -> None:
    transcription = Transcription(make_problem("double_integrator"))
    result = solve_continuation(transcription)
    assert result.success
    final_time = float(result.values(transcription.final_time))
    # unit mass, |F| <= 1 N, 1 m rest to rest: T = 2 sqrt(d / a) = 2 s
    assert final_time == pytest.approx(2.0, abs=1e-6)
    force = numeric(result.values(transcription.tau)).ravel()
    half = force.size // 2
    np.testing.assert_allclose(force[:half], 1.0, atol=1e-6)
    np.testing.assert_allclose(force[half:], -1.0, atol=1e-6)


def test_ball_drop_reaches_complementarity_and_matches_the_simulator() -> None:
    problem = make_problem("ball_drop")
    transcription = Transcription(problem)
    result = solve_continuation(transcription)
    assert result.success
    last = result.history[-1]
    assert last.stage == "polish"
    assert last.residual <= 1e-8
    assert [record.stage for record in result.history[:-1]] == ["penalty"] * (
        len(result.history) - 1)
    penalties = [record.penalty for record in result.history[:-1]]
    relaxations = [record.relaxation for record in result.history[:-1]]
    assert penalties == sorted(penalties) and relaxations == sorted(relaxations, reverse=True)
    # exactly one impact, and the optimizer's trajectory is the simulator's under its force
    normal = numeric(result.values(transcription.outputs["normal_impulse"])).ravel()
    assert int(np.sum(normal > 1e-9)) == 1
    q = numeric(result.values(transcription.q)).reshape(2, -1).T
    u = numeric(result.values(transcription.u)).reshape(2, -1).T
    force = numeric(result.values(transcription.tau)).ravel()
    stepper = MoreauJeanStepper(problem.model, BALL_DROP_PARAMETERS,
                                problem.final_time / problem.num_intervals)
    state = (q[0], u[0])
    for k, f in enumerate(force):
        step = stepper.step(state[0], state[1], [f])
        state = (step.q, step.u)
        np.testing.assert_allclose(step.q, q[k + 1], atol=1e-9)
        np.testing.assert_allclose(step.u, u[k + 1], atol=1e-9)
    # horizontal least effort, rest to rest: m^2 12 d^2 / T^3 (the continuous optimum)
    mass, distance = BALL_DROP_PARAMETERS.mass, 0.5
    expected = mass**2 * 12 * distance**2 / problem.final_time**3
    assert float(result.values(transcription.cost)) == pytest.approx(expected, rel=1e-3)


def test_schedule_validates_its_stages() -> None:
    with pytest.raises(ValueError, match="equal length"):
        Schedule(penalties=(1.0, 2.0), relaxations=(0.1,))


def test_robot_lateral_wheel_rows_are_found_identical() -> None:
    """The polish states the two wheels' shared lateral no-slip row once (else LICQ fails)."""
    from mdi_envs.mechanics.models.diff_drive import DiffDriveRobot
    from optimal.transcription import _identical_tangent_rows

    same = _identical_tangent_rows(DiffDriveRobot, DiffDriveRobot.Parameters().values())
    # tangent rows: (L x, L y, R x, R y, stick x, stick y)
    expected = np.eye(6, dtype=bool)
    expected[1, 3] = expected[3, 1] = True
    np.testing.assert_array_equal(same, expected)


@pytest.mark.parametrize("num_intervals", [6, 1])
def test_robot_polish_nlp_has_the_same_variables(num_intervals: int) -> None:
    """``polished`` rebuilds the NLP with fixed modes but the same variable layout.

    One interval too: CasADi returns its (3, 1) slip speeds as (3,), which once became a
    pattern of 3 intervals (the MPC's freed fallback crashed on a one-interval robot plan).
    """
    transcription = Transcription(make_problem("diff_drive_time", num_intervals))
    transcription.set_naive_guess()
    opti = transcription.opti
    polished = transcription.polished(lambda expression: opti.value(expression, opti.initial()))
    assert polished.opti.nx == transcription.opti.nx
    assert polished.modes is not None
    assert polished.modes.sliding.shape == (3, num_intervals)


def test_a_parametric_friction_factor_is_the_models_friction_scaled() -> None:
    """At any point, the constraints with factor 0.8 are those of the model with 0.8 mu."""
    import dataclasses

    from optimal.problems import model_of
    from optimal.traction import scaled_friction

    problem = make_problem("diff_drive_time", 3)
    parametric = Transcription(problem, parametric_friction=True)
    slippery = Transcription(dataclasses.replace(
        problem, parameters=scaled_friction(model_of(problem)[1], 0.8)))
    point = np.random.default_rng(0).normal(size=parametric.opti.nx)
    values = []
    for transcription, factor in ((parametric, 0.8), (slippery, None), (parametric, 1.0)):
        opti = transcription.opti
        for parameter in (transcription.rho, transcription.relaxation):
            opti.set_value(parameter, 0.0)
        if factor is not None:
            opti.set_value(transcription.friction_factor, factor)
        constraints = casadi.Function("g", [opti.x, opti.p], [opti.g])
        values.append(numeric(constraints(point, opti.value(opti.p))))
    np.testing.assert_allclose(values[0], values[1], rtol=1e-12, atol=1e-12)
    assert np.abs(values[2] - values[1]).max() > 1e-3
