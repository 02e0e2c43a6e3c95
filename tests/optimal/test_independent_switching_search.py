"""The manipulator's continuous-time optimum against an independent switching-time search.

The check shares nothing with the project's mechanics but the link parameters: the two-link arm
is written here from its Lagrangian in absolute angles (alpha, beta), the brake as what it does
to a rigid body (engaged: the links turn as one body of inertia I(d) = (1, 1) M(d) (1, 1)^T, the
lock an inelastic impact that keeps the angular momentum about the base; released: the free
two-link equations), integrated phase by phase with SciPy's DOP853. The search is SLSQP over the
event times of a mode structure (one torque switch, brake phases, a lock at t_f), minimizing t_f
with the goal (alpha = beta = pi at rest) as equality constraints, from the polish's structure
with its times jittered, from two brake phases at random times and from the paper's brake
structure (which ends in a slower local optimum). The polish
(``optimal/continuous/manipulator_time.json``) must be at most 0.05 % above the best time found
and must reach the goal in this simulator.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize

from mdi_envs.maneuvers import MANIPULATOR_MANEUVER
from mdi_envs.mechanics.models.blockable_manipulator import BlockableManipulatorParameters

POLISH = Path(__file__).parents[2] / "optimal" / "continuous" / "manipulator_time.json"
P = BlockableManipulatorParameters()
I1 = P.link1_mass * P.link1_length**2 / 3 + P.link2_mass * P.link1_length**2
I2 = P.link2_mass * P.link2_length**2 / 3
C = P.link2_mass * P.link1_length * P.link2_length / 2
TORQUE = MANIPULATOR_MANEUVER.max_torque
GOAL = math.pi


def mass_matrix(d: float) -> np.ndarray:
    """M(d) in (alpha, beta), d = beta - alpha."""
    return np.array([[I1, C * math.cos(d)], [C * math.cos(d), I2]])


def free(_t: float, x: np.ndarray, tau: float) -> np.ndarray:
    """The released arm: M (alpha'', beta'') = (tau + C sin d beta'^2, -C sin d alpha'^2)."""
    a, b, wa, wb = x
    d = b - a
    rhs = np.array([tau + C * math.sin(d) * wb**2, -C * math.sin(d) * wa**2])
    return np.concatenate(([wa, wb], np.linalg.solve(mass_matrix(d), rhs)))


def locked(_t: float, x: np.ndarray, tau: float) -> np.ndarray:
    """The engaged arm, one rigid body: I(d) omega' = tau, d constant."""
    d = x[1] - x[0]
    inertia = I1 + 2 * C * math.cos(d) + I2
    return np.array([x[2], x[3], tau / inertia, tau / inertia])


def lock(x: np.ndarray) -> np.ndarray:
    """The inelastic lock: both rates become p / I(d), p the angular momentum about the base."""
    d = x[1] - x[0]
    momentum = np.ones(2) @ mass_matrix(d) @ x[2:]
    omega = momentum / (I1 + 2 * C * math.cos(d) + I2)
    return np.array([x[0], x[1], omega, omega])


def simulate(torque_switches: list[float], brake: list[tuple[float, float]], final_time: float,
             final_lock: bool) -> np.ndarray:  # fmt: skip
    """The state (alpha, beta, alpha', beta') at t_f (after a lock at t_f if ``final_lock``).

    Torque +TORQUE, flipping sign at each switch; the brake engaged on each (engage, release),
    locking at each engage (an instant phase, engage = release, is a lock and a release).
    """
    events = sorted({0.0, final_time, *torque_switches, *(t for phase in brake for t in phase)})
    x = np.zeros(4)
    for start, end in zip(events[:-1], events[1:], strict=True):
        if any(a == start for a, _ in brake):
            x = lock(x)
        middle = 0.5 * (start + end)
        tau = TORQUE * (-1.0) ** sum(s <= middle for s in torque_switches)
        engaged = any(a <= middle <= b for a, b in brake)
        x = solve_ivp(locked if engaged else free, (start, end), x, method="DOP853",
                      args=(tau,), rtol=1e-11, atol=1e-13).y[:, -1]  # fmt: skip
    return lock(x) if final_lock else x


def goal_error(x: np.ndarray) -> np.ndarray:
    """(alpha - pi, beta - pi, alpha', beta'): zero at the goal."""
    return np.array([x[0] - GOAL, x[1] - GOAL, x[2], x[3]])


def search(times: np.ndarray, num_switches: int, final_lock: bool) -> tuple[float, float]:
    """SLSQP from ``times`` = (torque switches..., brake engage/release pairs..., t_f).

    Returns (t_f, max |goal error|) of the converged point (inf if SLSQP failed).
    """

    def unpack(z: np.ndarray) -> tuple[list[float], list[tuple[float, float]], float]:
        pairs = z[num_switches:-1].reshape(-1, 2)
        return list(z[:num_switches]), [(float(a), float(b)) for a, b in pairs], float(z[-1])

    def residual(z: np.ndarray) -> np.ndarray:
        switches, brake, final_time = unpack(z)
        error = goal_error(simulate(switches, brake, final_time, final_lock))
        return error[:3] if final_lock else error  # after a lock alpha' = beta'

    n = len(times)
    order = [{"type": "ineq", "fun": lambda z, i=i: z[i + 1] - z[i]}
             for i in range(num_switches - 1)]  # fmt: skip
    order += [{"type": "ineq", "fun": lambda z, i=i: z[-1] - z[i]} for i in range(n - 1)]
    order += [{"type": "ineq", "fun": lambda z, i=i: z[i + 1] - z[i]}
              for i in range(num_switches, n - 2)]  # brake phases in order  # fmt: skip
    result = minimize(lambda z: z[-1], times, jac=lambda z: np.eye(n)[-1], method="SLSQP",
                      constraints=[{"type": "eq", "fun": residual}, *order],
                      bounds=[(0.0, 8.0)] * n, options={"maxiter": 60, "ftol": 1e-12})  # fmt: skip
    error = float(np.abs(residual(result.x)).max())
    return (float(result.x[-1]) if result.success and error < 1e-7 else math.inf), error


@pytest.fixture(scope="module")
def polished() -> dict:
    return json.loads(POLISH.read_text())


def test_the_polish_reaches_the_goal_in_the_independent_simulator(polished: dict) -> None:
    schedule = polished["schedule"]
    (switches,) = schedule["input_switches"]
    phases = [tuple(phase) for phase in schedule["brake_phases"][0]]
    final_time = schedule["final_time"]
    brake = [(a, b) for a, b in phases if b > a]
    final_lock = any(abs(a - final_time) < 1e-9 for a, _ in phases)
    error = goal_error(simulate(switches, brake, final_time, final_lock))
    assert np.abs(error).max() < 1e-8


@pytest.mark.slow
def test_no_structure_beats_the_polish_by_more_than_five_hundredths_of_a_percent(
        polished: dict) -> None:  # fmt: skip
    schedule = polished["schedule"]
    final_time = schedule["final_time"]
    (switches,) = schedule["input_switches"]
    engage, release = schedule["brake_phases"][0][0]
    rng = np.random.default_rng(0)
    starts = []  # (times, number of torque switches, final lock)
    jitter = 1.0 + rng.uniform(-0.05, 0.05, 4)  # the polish's structure, times jittered <= 5 %
    starts.append((np.array([switches[0], engage, release, final_time]) * jitter, 1, True))
    t = np.sort(rng.uniform(0.3, 0.95, 4)) * 4.4  # two brake phases before t_f, then the lock
    starts.append((np.array([2.2, *t, 4.4]), 1, True))
    maneuver = MANIPULATOR_MANEUVER  # the paper's brake structure, engaged from 2.39 s to t_f
    (e0, e1, e2), (r0, r1) = maneuver.paper_brake_engaged, maneuver.paper_brake_released
    paper = np.array([e0, r0, e1, r1, e2, maneuver.paper_final_time])
    paper *= 4.4 / maneuver.paper_final_time
    starts.append((np.array([2.2, *paper, 4.4]), 1, True))
    found = [search(times, k, lock_at_end)[0] for times, k, lock_at_end in starts]
    assert math.isfinite(found[0]) and math.isfinite(found[1])
    assert final_time <= min(found) * (1.0 + 5e-4), (final_time, found)
