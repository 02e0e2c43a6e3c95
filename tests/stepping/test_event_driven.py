"""The event-driven reference integrator (``mdi_envs/stepping/event_driven.py``).

Closed forms for the ball (impact times, apex heights, Zeno stop), conservation laws and the
plastic-impact energy loss for the manipulator, and the O(dt) convergence of the Moreau-Jean
stepper to the event-driven reference under the paper's brake schedule with a bang-bang torque.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from mdi_envs.mechanics.models.blockable_manipulator import (
    BlockableManipulator,
    BlockableManipulatorParameters,
)
from mdi_envs.mechanics.models.bouncing_ball import BouncingBall, BouncingBallParameters
from mdi_envs.stepping import MoreauJeanStepper
from mdi_envs.stepping.event_driven import (
    EVENT_APEX,
    EVENT_BRAKE_ENGAGE,
    EVENT_BRAKE_RELEASE,
    EVENT_IMPACT,
    EVENT_INPUT_SWITCH,
    STATUS_COMPLETED,
    STATUS_ZENO,
    EventDrivenIntegrator,
    PiecewiseConstant,
    Trajectory,
    bang_bang,
    brake_schedule,
    simulate_ball,
    simulate_manipulator,
)

# The paper's schedule (engage 0, release 0.41, engage 1.07, release 1.84, engage 2.39 s) and a
# torque reversal at half the 4.53 s horizon, rounded to multiples of the largest dt = 4 ms so
# that the stepper, which holds each command over a step, sees the same switches.
COARSEST_DT = 4e-3  # [s]
ENGAGE_TIMES = (0.0, 1.072, 2.392)  # [s]
RELEASE_TIMES = (0.412, 1.84)  # [s]
TORQUE_SWITCH = 2.264  # [s]
HORIZON = 4.528  # [s]
MAX_TORQUE = 1.0  # [N m], illustrative (the calibrated tau_max is not needed for convergence)
TIME_STEPS = (4e-3, 2e-3, 1e-3, 5e-4)  # [s]


def _ball_closed_form(p: BouncingBallParameters, drop: float, count: int
                      ) -> tuple[np.ndarray, np.ndarray, float]:
    """Impact times t_k, apex gaps eps^(2k) drop (k = 1..count) and t_inf of a ball at rest."""
    g, eps = p.gravity, p.restitution
    t1 = math.sqrt(2.0 * drop / g)
    flights = 2.0 * t1 * eps ** np.arange(1, count)  # flight after impact k: 2 eps^k v0 / g
    times = t1 + np.concatenate([[0.0], np.cumsum(flights)])
    apexes = drop * eps ** (2.0 * np.arange(1, count + 1))
    return times, apexes, t1 * (1.0 + eps) / (1.0 - eps)


def _kinetic_energy(q: np.ndarray, u: np.ndarray, values: object) -> float:
    return 0.5 * float(u @ np.array(BlockableManipulator.mass_matrix(q, values, math)) @ u)


def test_ball_impacts_and_apexes_match_closed_form_until_zeno_stop() -> None:
    p = BouncingBallParameters()
    drop, min_flight = 1.0, 1e-5
    run = simulate_ball(p, p.radius + drop, 6.0, min_flight_time=min_flight)
    impacts, apexes = run.events_of(EVENT_IMPACT), run.events_of(EVENT_APEX)
    times, heights, t_inf = _ball_closed_form(p, drop, len(impacts))
    np.testing.assert_allclose([e.t for e in impacts], times, rtol=0.0, atol=1e-8)
    np.testing.assert_allclose([e.q[1] - p.radius for e in apexes], heights[: len(apexes)],
                               rtol=0.0, atol=1e-8)
    # Newton's law at each impact: gamma+ = -eps gamma-, P_N = m (1 + eps) |gamma-|.
    for e in impacts:
        assert e.u_plus[1] == pytest.approx(-p.restitution * e.u_minus[1], rel=1e-12)
        assert e.impulses[0] == pytest.approx(-p.mass * (1 + p.restitution) * e.u_minus[1],
                                              rel=1e-12)
    # Clean stop at the first impact after a flight shorter than min_flight_time.
    flights = np.diff(times)
    assert run.status == STATUS_ZENO
    assert flights[-1] < min_flight <= flights[-2]
    assert run.t_end == impacts[-1].t and 0.0 < t_inf - run.t_end < 10 * min_flight
    assert len(impacts) > 45
    assert np.isnan(run.evaluate([run.t_end + 1e-6])[0]).all()


def test_plastic_ball_comes_to_rest_and_stays() -> None:
    p = BouncingBallParameters(restitution=0.0)
    run = simulate_ball(p, p.radius + 0.5, 2.0, sample_times=np.linspace(0.0, 2.0, 41))
    assert run.status == STATUS_COMPLETED
    assert [e.kind for e in run.events[1:]] == [EVENT_IMPACT]
    resting = run.t > run.events[1].t
    np.testing.assert_allclose(run.q[resting, 1], p.radius, rtol=0.0, atol=1e-14)
    np.testing.assert_allclose(run.u[resting], 0.0, atol=1e-14)


def test_manipulator_conservation_and_plastic_engagement_loss() -> None:
    """Zero torque: conserved momentum and energy, the plastic engagement's exact loss.

    (1,1) M u is conserved throughout (the brake is internal), the energy within each phase, and
    each impactive engagement dissipates 1/2 gamma_B-^2 / (W_B M^-1 W_B^T).
    """
    values = BlockableManipulatorParameters().values()
    times = np.linspace(0.0, 1.3, 261)
    run = simulate_manipulator(None, [0.3, 1.1], [1.2, -0.7], PiecewiseConstant.constant([0.0]),
                               brake_schedule([0.25, 0.9], [0.6]), 1.3, sample_times=times)
    assert run.status == STATUS_COMPLETED
    momentum = [float(np.ones(2) @ np.array(BlockableManipulator.mass_matrix(q, values, math))
                      @ u) for q, u in zip(run.q, run.u, strict=True)]
    np.testing.assert_allclose(momentum, momentum[0], rtol=1e-10)

    energy = np.array([_kinetic_energy(q, u, values) for q, u in zip(run.q, run.u, strict=True)])
    switches = [0.0, 0.25, 0.6, 0.9, 1.3]
    for start, end in zip(switches[:-1], switches[1:], strict=True):
        phase = (times > start) & (times <= end)
        np.testing.assert_allclose(energy[phase], energy[phase][0], rtol=1e-10)

    w_brake = np.array(BlockableManipulator.brake_directions(None, values, math)[0])
    engagements = run.events_of(EVENT_BRAKE_ENGAGE)
    assert [e.t for e in engagements] == [0.25, 0.9]
    for e in engagements:
        gamma = float(w_brake @ e.u_minus)
        delassus = float(w_brake @ np.linalg.solve(
            np.array(BlockableManipulator.mass_matrix(e.q, values, math)), w_brake))
        assert abs(gamma) > 0.1  # impactive
        loss = _kinetic_energy(e.q, e.u_minus, values) - _kinetic_energy(e.q, e.u_plus, values)
        assert loss == pytest.approx(0.5 * gamma**2 / delassus, rel=1e-12)
        assert e.impulses[0] == pytest.approx(-gamma / delassus, rel=1e-12)
        assert abs(float(w_brake @ e.u_plus)) < 1e-14
    # Drift-free blocked phases: the relative angle stays constant to round-off.
    for start, end in ((0.25, 0.6), (0.9, 1.3)):
        phase = (times > start) & (times <= end)
        relative = run.q[phase, 1] - run.q[phase, 0]
        assert np.ptp(relative) < 1e-13
        np.testing.assert_allclose(run.u[phase, 1] - run.u[phase, 0], 0.0, atol=1e-13)


@pytest.fixture(scope="module")
def paper_schedule() -> tuple[PiecewiseConstant, PiecewiseConstant]:
    return (bang_bang(MAX_TORQUE, [TORQUE_SWITCH]),
            brake_schedule(ENGAGE_TIMES, RELEASE_TIMES))


@pytest.fixture(scope="module")
def reference(paper_schedule: tuple[PiecewiseConstant, PiecewiseConstant]) -> Trajectory:
    torque, brake = paper_schedule
    return simulate_manipulator(None, [0.0, 0.0], [0.0, 0.0], torque, brake, HORIZON)


def test_reference_schedule_events_and_accuracy(
    paper_schedule: tuple[PiecewiseConstant, PiecewiseConstant], reference: Trajectory
) -> None:
    kinds = [(e.t, e.kind) for e in reference.events[1:]]
    assert kinds == [(0.0, EVENT_BRAKE_ENGAGE), (0.412, EVENT_BRAKE_RELEASE),
                     (1.072, EVENT_BRAKE_ENGAGE), (1.84, EVENT_BRAKE_RELEASE),
                     (2.264, EVENT_INPUT_SWITCH), (2.392, EVENT_BRAKE_ENGAGE)]
    # Two of the three engagements are impactive (gamma_B- != 0), the first is at rest.
    gammas = [e.u_minus[1] - e.u_minus[0] for e in reference.events_of(EVENT_BRAKE_ENGAGE)]
    assert gammas[0] == 0.0 and min(abs(gammas[1]), abs(gammas[2])) > 0.3
    # The reference's own error is far below the stepper errors measured against it.
    torque, brake = paper_schedule
    tighter = simulate_manipulator(None, [0.0, 0.0], [0.0, 0.0], torque, brake, HORIZON,
                                   rtol=1e-12, atol=1e-14)
    radau = simulate_manipulator(None, [0.0, 0.0], [0.0, 0.0], torque, brake, HORIZON,
                                 method="Radau")
    for other in (tighter, radau):
        q_ref, u_ref = reference.final_state
        q_other, u_other = other.final_state
        np.testing.assert_allclose(q_other, q_ref, rtol=0.0, atol=1e-8)
        np.testing.assert_allclose(u_other, u_ref, rtol=0.0, atol=1e-8)


def test_moreau_jean_converges_at_first_order_to_event_driven_reference(
    paper_schedule: tuple[PiecewiseConstant, PiecewiseConstant], reference: Trajectory
) -> None:
    """The paper's brake schedule with bang-bang torque: the stepper's error is O(dt).

    Max state error over the common grid (multiples of 4 ms) and final-state error, for
    dt = 4, 2, 1, 0.5 ms: monotonically decreasing, log-log slope between 0.8 and 1.3.
    """
    torque, brake = paper_schedule
    common = np.arange(round(HORIZON / COARSEST_DT) + 1) * COARSEST_DT
    q_ref, u_ref = reference.evaluate(common)
    max_errors, final_errors, run_times = [], [], []
    for dt in TIME_STEPS:
        stepper = MoreauJeanStepper(BlockableManipulator, None, dt)
        stepper.step([0.0, 0.0], [0.0, 0.0], [0.0], [0.0])  # compile outside the timing
        stride = round(COARSEST_DT / dt)
        q, u = np.zeros(2), np.zeros(2)
        error = 0.0
        start = time.perf_counter()
        for k in range(round(HORIZON / dt)):
            middle = (k + 0.5) * dt  # the command held over [k dt, (k + 1) dt)
            result = stepper.step(q, u, torque(middle), brake(middle))
            q, u = result.q, result.u
            if (k + 1) % stride == 0:
                j = (k + 1) // stride
                error = max(error, np.abs(q - q_ref[j]).max(), np.abs(u - u_ref[j]).max())
        run_times.append(time.perf_counter() - start)
        max_errors.append(error)
        final_errors.append(max(np.abs(q - q_ref[-1]).max(), np.abs(u - u_ref[-1]).max()))
    print("\ndt [s]   max error   final error   stepper time [s]")
    for row in zip(TIME_STEPS, max_errors, final_errors, run_times, strict=True):
        print("{:.1e}  {:.3e}   {:.3e}     {:.3f}".format(*row))
    for errors in (max_errors, final_errors):
        assert all(a > b for a, b in zip(errors[:-1], errors[1:], strict=True))
        order = np.polyfit(np.log(TIME_STEPS), np.log(errors), 1)[0]
        print(f"observed order {order:.3f}")
        assert 0.8 < order < 1.3
    assert max_errors[-1] < 2e-3


def test_schedules_are_right_continuous_and_validated() -> None:
    torque = bang_bang(2.0, [1.0, 2.0])
    assert [float(torque(t)[0]) for t in (0.0, 1.0, 1.5, 2.0, 9.0)] == [2.0, -2.0, -2.0, 2.0,
                                                                         2.0]
    with pytest.raises(ValueError, match="alternate"):
        brake_schedule([0.0, 1.0], [2.0])
    with pytest.raises(ValueError, match="strictly increasing"):
        PiecewiseConstant([1.0, 1.0], [[0.0], [1.0], [2.0]])
    with pytest.raises(ValueError, match="values must have shape"):
        PiecewiseConstant([1.0], [[0.0]])


def test_tresca_bounds_and_penetration_are_rejected() -> None:
    integrator = EventDrivenIntegrator(BlockableManipulator)
    with pytest.raises(ValueError, match="Tresca"):
        integrator.simulate([0.0, 0.0], [0.0, 0.0], 1.0,
                            brake=PiecewiseConstant.constant([3.0]))
    with pytest.raises(ValueError, match="penetration"):
        EventDrivenIntegrator(BouncingBall).simulate([0.0, 0.0], [0.0, 0.0], 1.0)
