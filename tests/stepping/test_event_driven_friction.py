"""Event-driven integration of the robot's stick-slip contacts (event_driven_friction.py).

A closed form (a robot sliding straight on locked wheels: spin-up, rolling, rest), the
acceleration-level mode decisions from rest, dissipation, the stick margin against a brute-force
search over the undetermined lateral split, and the O(dt) convergence of the Moreau-Jean stepper
to the event-driven solution through slip onsets and sticks.
"""

from __future__ import annotations

import numpy as np
import pytest

from mdi_envs.mechanics.models.bouncing_ball import BouncingBall
from mdi_envs.mechanics.models.diff_drive import DiffDriveRobot
from mdi_envs.stepping import MoreauJeanStepper
from mdi_envs.stepping.event_driven import PiecewiseConstant
from mdi_envs.stepping.event_driven_friction import (
    EVENT_SLIP,
    EVENT_STICK,
    STATUS_COMPLETED,
    EventDrivenFrictionIntegrator,
)

LEFT, RIGHT, STICK = 0, 1, 2


@pytest.fixture(scope="module")
def integrator() -> EventDrivenFrictionIntegrator:
    return EventDrivenFrictionIntegrator(DiffDriveRobot)


def _modes(trajectory) -> list[tuple[float, str, int]]:  # noqa: ANN001
    return [(e.t, e.kind, e.element) for e in trajectory.events
            if e.kind in (EVENT_STICK, EVENT_SLIP)]


def test_straight_slide_on_locked_wheels_matches_the_closed_form(
        integrator: EventDrivenFrictionIntegrator) -> None:
    """Forward speed v0, wheels not turning, no torque.

    Phase 1, everything slides backwards: sum F_x = X from the load law, the wheels spin up
    until they roll at t1. Phase 2, the wheels roll and the stick slides: constant deceleration
    a2 until rest at t2, where every contact sticks.
    """
    p = integrator._p
    m, J, r, g = p.mass, p.wheel_inertia, p.wheel_radius, p.gravity
    a, c, h = p.axle_offset, p.stick_offset, p.cm_height
    mu_w, mu_s, span, v0 = p.wheel_friction, p.stick_friction, a + c, 1.0
    X = -(mu_w * c + mu_s * a) * m * g / (span + (mu_w - mu_s) * h)
    axle_load = (c * m * g + h * X) / span
    t1 = v0 / (r * r * mu_w * axle_load / (2.0 * J) - X / m)
    v1 = v0 + X / m * t1
    a2 = -mu_s * a * m * g / (span * (m + 2.0 * J / r ** 2) - mu_s * h * m)
    t2 = t1 - v1 / a2
    x2 = v0 * t1 + 0.5 * X / m * t1 ** 2 + v1 * (t2 - t1) + 0.5 * a2 * (t2 - t1) ** 2

    trajectory = integrator.simulate(np.zeros(5), [v0, 0.0, 0.0, 0.0, 0.0], t2 + 0.3)

    assert trajectory.status == STATUS_COMPLETED
    modes = _modes(trajectory)
    assert [(kind, i) for _, kind, i in modes] == [
        (EVENT_SLIP, LEFT), (EVENT_SLIP, RIGHT), (EVENT_SLIP, STICK),
        (EVENT_STICK, LEFT), (EVENT_STICK, RIGHT), (EVENT_STICK, STICK)]
    assert modes[3][0] == pytest.approx(t1, abs=1e-10)
    assert modes[5][0] == pytest.approx(t2, abs=1e-9)
    q, u = trajectory.final_state
    assert q[0] == pytest.approx(x2, abs=1e-10)
    assert np.abs(q[1:3]).max() < 1e-12 and np.abs(u).max() < 1e-12
    assert q[3] == pytest.approx(q[4], abs=1e-12)


@pytest.mark.parametrize(("torque", "expected"), [
    ((0.5, 0.5), [(EVENT_STICK, LEFT), (EVENT_STICK, RIGHT), (EVENT_SLIP, STICK)]),
    ((3.0, -3.0), [(EVENT_SLIP, LEFT), (EVENT_SLIP, RIGHT), (EVENT_SLIP, STICK)]),
    ((0.0, 0.0), [(EVENT_STICK, LEFT), (EVENT_STICK, RIGHT), (EVENT_STICK, STICK)]),
])
def test_modes_from_rest_follow_the_traction_limit(
        integrator: EventDrivenFrictionIntegrator, torque: tuple[float, float],
        expected: list[tuple[str, int]]) -> None:
    """Modes from rest follow the traction limit.

    Small equal torques roll the wheels (the stick slides as the chassis moves); a full
    opposite pair spins them (all slide); no torque keeps the robot at rest.
    """
    trajectory = integrator.simulate(np.zeros(5), np.zeros(5), 0.05,
                                     PiecewiseConstant.constant(torque))
    starting = [(kind, i) for t, kind, i in _modes(trajectory) if t == 0.0]
    assert starting == expected
    slips = integrator.slips(*trajectory.final_state)
    for kind, i in expected:
        assert (np.hypot(*slips[i]) > 1e-4) == (kind == EVENT_SLIP)


class _Ramp:
    """Equal wheel torques rising linearly, 4 N m/s (inputs without switches)."""

    switch_times = np.empty(0)

    def __call__(self, t: float) -> np.ndarray:
        return np.array([4.0 * t, 4.0 * t])


def test_rising_torque_breaks_the_stick_then_the_wheels_loose_on_time(
        integrator: EventDrivenFrictionIntegrator) -> None:
    """A rising torque from rest: the stick breaks loose first, then the wheels.

    Everything sticks until the stick's friction reaches its cone (the torques push the chassis
    against it); the robot then rolls until the wheels' traction limit. Both are grazing onsets
    (a stick margin reaching 0); closed forms from the load law: t1 = mu_s N_s0 r / (2 k) and
    the torque tau* at which the wheel force F = (tau - J a / r) / r reaches mu_w N_w, with a
    the rolling acceleration.
    """
    p = integrator._p
    m, J, r, g = p.mass, p.wheel_inertia, p.wheel_radius, p.gravity
    a, c, h = p.axle_offset, p.stick_offset, p.cm_height
    mu_w, mu_s, span, rate = p.wheel_friction, p.stick_friction, a + c, 4.0
    t1 = mu_s * a * m * g / span * r / 2.0 / rate
    scale = 1.0 + 2.0 * J / (m * r * r) - mu_s * h / span
    x1, x0 = 2.0 / r / scale, -mu_s * a * m * g / span / scale  # sum F_x = x1 tau + x0
    slope = (1.0 - J * x1 / (m * r)) / r - mu_w * h * x1 / (2.0 * span)
    offset = -J * x0 / (m * r * r) - mu_w * (c * m * g + h * x0) / (2.0 * span)
    t_star = -offset / slope / rate

    trajectory = integrator.simulate(np.zeros(5), np.zeros(5), 1.0, _Ramp())

    assert trajectory.status == STATUS_COMPLETED
    modes = _modes(trajectory)
    assert [(kind, i) for _, kind, i in modes] == [
        (EVENT_STICK, LEFT), (EVENT_STICK, RIGHT), (EVENT_STICK, STICK), (EVENT_SLIP, STICK),
        (EVENT_SLIP, LEFT), (EVENT_SLIP, RIGHT)]
    assert modes[3][0] == pytest.approx(t1, abs=1e-12)
    assert modes[4][0] == pytest.approx(t_star, abs=1e-12)
    assert modes[5][0] == modes[4][0]


def test_friction_dissipates_until_rest(integrator: EventDrivenFrictionIntegrator) -> None:
    """A chassis thrown sideways and spinning, wheels still, no torque.

    The kinetic energy never increases and the robot comes to rest with every contact stuck.
    """
    trajectory = integrator.simulate(np.zeros(5), [0.5, 0.8, 2.0, 0.0, 0.0], 2.0,
                                     sample_times=np.linspace(0.0, 2.0, 401))
    mass = np.diag([10.0, 10.0, 0.5, 0.02, 0.02])
    energy = 0.5 * np.einsum("ti,ij,tj->t", trajectory.u, mass, trajectory.u)
    assert (np.diff(energy) <= 1e-12 * energy[0]).all()
    assert energy[-1] < 1e-20
    last_mode = {i: kind for _, kind, i in _modes(trajectory)}
    assert last_mode == {LEFT: EVENT_STICK, RIGHT: EVENT_STICK, STICK: EVENT_STICK}


def test_stick_margin_finds_the_best_split_of_the_shared_lateral_row(
        integrator: EventDrivenFrictionIntegrator) -> None:
    """Both wheels roll in a turn: their lateral forces are determined only in sum.

    One null direction; the margin max_xi min_i (mu N_i - |F_i + xi z_i|) agrees with a dense
    scan over the split.
    """
    q, u = np.array([0.0, 0.0, 0.3, 0.0, 0.0]), np.array([0.8, 0.25, 1.5, 8.0, 8.0])
    u = u - np.linalg.pinv(integrator.tangent_rows(q, u)[0][:4]) @ (
        integrator.tangent_rows(q, u)[0][:4] @ u)  # both wheels rolling
    sliding = {STICK: integrator.slips(q, u)[STICK] / np.hypot(*integrator.slips(q, u)[STICK])}
    _, forces, null = integrator.accelerations(q, u, np.array([1.2, -0.4]), sliding)
    assert null.shape == (6, 1)
    assert np.abs(null[[0, 2, 4, 5], 0]).max() < 1e-12  # only the lateral split moves
    loads = integrator.n0 + integrator.k @ forces
    scan = np.linspace(-60.0, 60.0, 240_001)
    margins = np.min([integrator.mu[i] * loads[i] - np.hypot(
        forces[2 * i] + scan * null[2 * i, 0], forces[2 * i + 1] + scan * null[2 * i + 1, 0])
        for i in (LEFT, RIGHT)], axis=0)
    found = integrator.stick_margin(forces, null, [LEFT, RIGHT])
    assert found == pytest.approx(margins.max(), abs=1e-6)
    assert found >= margins.max() - 1e-12


def test_moreau_jean_converges_at_first_order_through_slip_and_stick(
        integrator: EventDrivenFrictionIntegrator) -> None:
    """Spin from rest (all slide), then both wheels grip, then the right one breaks loose.

    The stepper's final-state error against the event-driven solution falls as dt (observed
    order 0.9-1.1).
    """
    inputs = PiecewiseConstant([0.2, 0.4], [[3.0, -3.0], [2.5, 1.0], [-1.0, -2.0]])
    horizon = 0.6
    trajectory = integrator.simulate(np.zeros(5), np.zeros(5), horizon, inputs)
    modes = [(kind, i) for _, kind, i in _modes(trajectory)]
    assert modes[3:] == [(EVENT_STICK, LEFT), (EVENT_STICK, RIGHT), (EVENT_SLIP, RIGHT),
                         (EVENT_STICK, RIGHT)]
    q_ref, u_ref = trajectory.final_state
    steps = (0.01, 0.0025, 0.000625)
    errors = []
    for dt in steps:
        stepper = MoreauJeanStepper(DiffDriveRobot, None, dt)
        q, u, impulses = np.zeros(5), np.zeros(5), None
        for k in range(round(horizon / dt)):
            result = stepper.step(q, u, inputs((k + 0.5) * dt), warm_start=impulses)
            q, u, impulses = result.q, result.u, result.impulses
        errors.append(max(np.abs(q - q_ref).max(), np.abs(u - u_ref).max()))
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert errors[0] > errors[1] > errors[2]
    assert 0.9 < order < 1.1


def test_rejects_models_without_load_transfer() -> None:
    with pytest.raises(ValueError, match="load transfer"):
        EventDrivenFrictionIntegrator(BouncingBall)
    with pytest.raises(ValueError, match="slip_tolerance"):
        EventDrivenFrictionIntegrator(DiffDriveRobot, slip_tolerance=0.0)
