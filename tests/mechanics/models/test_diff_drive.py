"""The differential-drive robot's equations against first principles (plain Python, ops = math).

* ``normal_loads``: the ground forces (F_x, F_y, N) at the three contacts, with N = N0 + K F,
  balance the weight and have no roll or pitch moment about the centre of mass, for any F.
* ``contact_directions``: each contact's rows are the velocity of the material point touching
  the ground (the bottom of a wheel's rim, the stick's tip), by central finite differences of
  its 3-D position, in the body frame (normal z, longitudinal x_K, lateral y_K).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mdi_envs.mechanics.models.diff_drive import (
    DiffDriveParameters,
    DiffDriveRobot,
    DiffDriveValues,
)

RNG_SEED = 20070403

PARAMETER_SETS = (
    DiffDriveParameters(),
    DiffDriveParameters(mass=3.0, axle_offset=0.0, stick_offset=0.5, cm_height=0.4,
                        half_track=0.35, wheel_radius=0.07),
    DiffDriveParameters(mass=25.0, axle_offset=0.3, stick_offset=0.05, cm_height=0.02,
                        half_track=0.1, gravity=1.62),
)


def _contact_points(p: DiffDriveValues) -> list[tuple[float, float, bool]]:
    """(x_K, y_K, is_wheel) of the left wheel, right wheel and stick relative to the CM."""
    return [(-p.axle_offset, p.half_track, True), (-p.axle_offset, -p.half_track, True),
            (p.stick_offset, 0.0, False)]


@pytest.mark.parametrize("params", PARAMETER_SETS)
def test_normal_loads_balance_weight_and_roll_pitch_moments(params: DiffDriveParameters) -> None:
    p = params.values()
    n0, k = DiffDriveRobot.normal_loads(p)
    n0, k = np.array(n0), np.array(k)
    assert n0.shape == (3,) and k.shape == (3, 6)
    points = _contact_points(p)
    rng = np.random.default_rng(RNG_SEED)
    weight = p.mass * p.gravity
    for _ in range(50):
        friction = rng.normal(scale=weight, size=6)
        loads = n0 + k @ friction
        force = np.zeros(3)
        moment = np.zeros(3)
        for i, (x, y, _) in enumerate(points):
            f = np.array([friction[2 * i], friction[2 * i + 1], loads[i]])
            force += f
            moment += np.cross([x, y, -p.cm_height], f)  # ground at -h below the CM
        # vertical: the loads carry the weight; roll (x) and pitch (y): no moment about the CM
        assert force[2] == pytest.approx(weight, rel=1e-13)
        np.testing.assert_allclose(moment[:2], 0.0, atol=1e-12 * weight)


def test_load_transfer_directions() -> None:
    """Driving forward loads the axle; a force to the left (a left turn) loads the right wheel."""
    p = DiffDriveParameters().values()
    n0, k = (np.array(a) for a in DiffDriveRobot.normal_loads(p))
    forward = np.array([1.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    left = np.array([0.0, 1.0, 0.0, 1.0, 0.0, 0.0])
    assert (k @ forward)[0] > 0 and (k @ forward)[1] > 0 and (k @ forward)[2] < 0
    assert (k @ left)[1] > 0 > (k @ left)[0] and (k @ left)[2] == 0.0
    span = p.axle_offset + p.stick_offset
    np.testing.assert_allclose(
        n0, [p.stick_offset / span / 2, p.stick_offset / span / 2, p.axle_offset / span]
        * np.array(p.mass * p.gravity), rtol=1e-15,
    )


def _material_point(q: np.ndarray, p: DiffDriveValues, i: int, psi_ref: float) -> np.ndarray:
    """World position of the material point of contact i that touches the ground at psi_ref.

    A wheel's rim point at the bottom (relative to the wheel centre (0, 0, -r)) turns by
    d = psi - psi_ref about the axle y_K: (-r sin d, 0, -r cos d); the stick's tip is fixed.
    """
    x_k, y_k, is_wheel = _contact_points(p)[i]
    z_k = -p.cm_height
    if is_wheel:
        d = q[3 + i] - psi_ref
        x_k = x_k - p.wheel_radius * math.sin(d)
        z_k = z_k + p.wheel_radius * (1.0 - math.cos(d))
    c, s = math.cos(q[2]), math.sin(q[2])
    return np.array([q[0] + c * x_k - s * y_k, q[1] + s * x_k + c * y_k, z_k])


@pytest.mark.parametrize("params", PARAMETER_SETS)
def test_slip_rows_are_contact_point_velocities(params: DiffDriveParameters) -> None:
    p = params.values()
    rng = np.random.default_rng(RNG_SEED + 1)
    for _ in range(20):
        q = rng.uniform(-3.0, 3.0, size=5)
        u = rng.normal(size=5)
        rows = np.array(DiffDriveRobot.contact_directions(q, p, math))
        assert rows.shape == (9, 5)
        c, s = math.cos(q[2]), math.sin(q[2])
        body = np.array([[0.0, 0.0, 1.0], [c, s, 0.0], [-s, c, 0.0]])  # (z, x_K, y_K) axes
        eps = 1e-6
        for i in range(3):
            psi_ref = q[3 + i] if i < 2 else 0.0
            velocity = (_material_point(q + eps * u, p, i, psi_ref)
                        - _material_point(q - eps * u, p, i, psi_ref)) / (2 * eps)
            np.testing.assert_allclose(rows[3 * i: 3 * i + 3] @ u, body @ velocity,
                                       rtol=0.0, atol=1e-8)
        np.testing.assert_array_equal(rows[0::3], 0.0)  # no vertical degree of freedom


def test_slip_mode_follows_table_1() -> None:
    mode = DiffDriveRobot.slip_mode
    assert mode((0, 0, 0)) == 2 and mode((0, 0, 1)) == 2
    assert mode((1, 0, 1)) == 3 and mode((0, 1, 0)) == 3
    assert mode((1, 1, 0)) == 5 and mode((1, 1, 1)) == 5


def test_invalid_parameters_raise() -> None:
    with pytest.raises(ValueError):
        DiffDriveParameters(mass=-1.0)
    with pytest.raises(ValueError):
        DiffDriveParameters(axle_offset=0.0, stick_offset=0.0)
