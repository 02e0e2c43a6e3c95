"""Moreau-Jean stepping of the blockable manipulator: the brake as an impulsive control.

Without the motor (tau = 0) the brake is internal: W_B = (-1, 1) is orthogonal to (1, 1), so
the brake impulse never changes the total angular momentum L = (1, 1) . M(q) u. An ideal
engagement is a plastic impact at the step's midpoint q_M: with the iteration matrix
M_theta = M(q_M) - dt/2 J(q_M, u) (J = dh/du, the theta = 1/2 scheme), the smooth part of the
step u_free = u + dt M_theta^-1 h(q_M, u) and G = W_B M_theta^-1 W_B^T,

    u+ = u_free - M_theta^-1 W_B^T (W_B u_free) / G,   P_B = -(W_B u_free) / G,

exactly (round-off). In aligned configurations (sin(beta - alpha) = 0) h and J vanish, M_theta
= M(q_M), and the energy identity T_M(u_free) - T_M(u+) = (W_B u_free)^2 / (2 G), T_M(v) =
v^T M(q_M) v / 2, holds to round-off; with gamma_B^- = W_B u_k and T at the grid points it
holds up to O(dt) everywhere. Everything here is computed from the model's plain-Python
equations (``ops = math``) and the closed-form J, independently of the compiled kernel.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mdi_envs.mechanics.models import BlockableManipulator
from mdi_envs.stepping import MoreauJeanStepper

VALUES = BlockableManipulator.Parameters().values()
W_B = np.array([-1.0, 1.0])
ONES = np.ones(2)
Stepper = Callable[..., MoreauJeanStepper]


def mass(q: np.ndarray) -> np.ndarray:
    return np.array(BlockableManipulator.mass_matrix(q, VALUES, math))


def forces(q: np.ndarray, u: np.ndarray) -> np.ndarray:
    return np.array(BlockableManipulator.forces(q, u, VALUES, math))


def kinetic(q: np.ndarray, u: np.ndarray) -> float:
    return float(0.5 * u @ mass(q) @ u)


def momentum(q: np.ndarray, u: np.ndarray) -> float:
    return float(ONES @ mass(q) @ u)


def force_jacobian(q: np.ndarray, u: np.ndarray) -> np.ndarray:
    """J = dh/du in closed form: h = (c s beta'^2, -c s alpha'^2), c s = m2 l1 l2 sin / 2."""
    cs = 0.5 * VALUES.link2_mass * VALUES.link1_length * VALUES.link2_length * math.sin(
        q[1] - q[0])
    return np.array([[0.0, 2.0 * cs * u[1]], [-2.0 * cs * u[0], 0.0]])


def iteration_matrix(q_mid: np.ndarray, u: np.ndarray, dt: float) -> np.ndarray:
    """M_theta = M(q_M) - dt/2 J(q_M, u)."""
    return mass(q_mid) - 0.5 * dt * force_jacobian(q_mid, u)


def midpoint_free(q: np.ndarray, u: np.ndarray, dt: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """q_M, the velocity after the smooth part of the step (no brake impulse, tau = 0), M_theta."""
    q_mid = q + 0.5 * dt * u
    m_theta = iteration_matrix(q_mid, u, dt)
    return q_mid, u + dt * np.linalg.solve(m_theta, forces(q_mid, u)), m_theta


def random_states(seed: int, count: int) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-np.pi, np.pi, 2), rng.normal(0.0, 3.0, 2)) for _ in range(count)]


def aligned_states(seed: int, count: int, dt: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """States whose midpoint is straight or folded (sin(beta - alpha) = 0), random velocities."""
    rng = np.random.default_rng(seed)
    states = []
    for _ in range(count):
        u = rng.normal(0.0, 3.0, 2)
        q_mid = np.full(2, rng.uniform(-np.pi, np.pi))
        q_mid[1] += np.pi * rng.integers(2)
        states.append((q_mid - 0.5 * dt * u, u))
    return states


def run(stepper: MoreauJeanStepper, q: np.ndarray, u: np.ndarray, bounds: np.ndarray
        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """Step with tau = 0 and brake bound bounds[k] in step k; (q, u) at every grid point, P_B."""
    qs, us, impulses = [q], [u], []
    for bound in bounds:
        result = stepper.step(q, u, [0.0], [bound])
        assert result.status.is_success
        q, u = result.q, result.u
        qs.append(q)
        us.append(u)
        impulses.append(result.impulses[0])
    return np.array(qs), np.array(us), np.array(impulses)


def random_schedule(rng: np.random.Generator, num_steps: int, choices: list[float]) -> np.ndarray:
    """Piecewise-constant brake bounds: a new random choice every 20-200 steps."""
    bounds = np.empty(num_steps)
    k = 0
    while k < num_steps:
        length = int(rng.integers(20, 200))
        bounds[k : k + length] = choices[int(rng.integers(len(choices)))]
        k += length
    return bounds


# ------------------------------------------------------------------------------ single steps
@pytest.mark.parametrize("dt", [1e-2, 1e-3])
def test_ideal_engagement_is_the_plastic_impact(make_stepper: Stepper, dt: float) -> None:
    """u+, P_B and the energy loss of an ideal engagement against the closed form (round-off)."""
    stepper = make_stepper(BlockableManipulator, dt)
    for q, u in random_states(1, 40) + aligned_states(1, 20, dt):
        result = stepper.step(q, u, [0.0], [np.inf])
        assert result.num_equalities == 1 and result.lcp_size == 0
        q_mid, u_free, m_theta = midpoint_free(q, u, dt)
        delassus = W_B @ np.linalg.solve(m_theta, W_B)
        gamma = W_B @ u_free
        impulse = -gamma / delassus
        scale = 1.0 + np.abs(u).max()
        np.testing.assert_allclose(result.impulses[0], impulse, rtol=1e-12, atol=1e-14 * scale)
        expected_u = u_free + np.linalg.solve(m_theta, W_B) * impulse
        np.testing.assert_allclose(result.u, expected_u, rtol=0, atol=1e-13 * scale)
        np.testing.assert_allclose(result.q, q_mid + 0.5 * dt * expected_u, rtol=0,
                                   atol=1e-13 * scale)  # fmt: skip
        if abs(math.sin(q_mid[1] - q_mid[0])) < 1e-9:  # aligned: M_theta = M(q_M)
            m_mid = mass(q_mid)
            loss = 0.5 * u_free @ m_mid @ u_free - 0.5 * result.u @ m_mid @ result.u
            assert loss == pytest.approx(0.5 * gamma**2 / delassus, rel=1e-10,
                                         abs=1e-13 * scale**2)  # fmt: skip


def test_engagement_loss_from_pre_step_velocity_is_first_order(make_stepper: Stepper) -> None:
    """Grid energies T(q_k, u_k) - T(q_k+1, u_k+1) vs (W_B u_k)^2 / (2 G(q_M)): O(dt) apart."""
    q, u = np.array([0.3, 1.2]), np.array([1.0, -2.0])
    gaps = []
    for dt in (1e-2, 1e-3, 1e-4):
        result = make_stepper(BlockableManipulator, dt).step(q, u, [0.0], [np.inf])
        q_mid = q + 0.5 * dt * u
        formula = 0.5 * (W_B @ u) ** 2 / (W_B @ np.linalg.solve(mass(q_mid), W_B))
        grid_loss = kinetic(q, u) - kinetic(result.q, result.u)
        gaps.append(abs(grid_loss - formula) / formula)
    # measured: 1.5e-2, 1.5e-3, 1.5e-4
    assert gaps[0] < 0.05
    assert 8.0 < gaps[0] / gaps[1] < 12.0 and 8.0 < gaps[1] / gaps[2] < 12.0, gaps


@pytest.mark.parametrize("bound", [0.0, 0.3, 5.0, 1e3, np.inf])
def test_brake_impulse_does_not_change_momentum(make_stepper: Stepper, bound: float) -> None:
    """(1, 1) . [M_theta (u+ - u) - h(q_M, u) dt] = (1, 1) . W_B P_B = 0, to round-off."""
    dt = 1e-3
    stepper = make_stepper(BlockableManipulator, dt)
    for q, u in random_states(2, 40):
        result = stepper.step(q, u, [0.0], [bound])
        q_mid = q + 0.5 * dt * u
        m_theta = iteration_matrix(q_mid, u, dt)
        residual = ONES @ (m_theta @ (result.u - u) - forces(q_mid, u) * dt)
        assert abs(residual) <= 1e-14 * (1.0 + np.abs(u).max())


@pytest.mark.parametrize("bound", [0.3, 5.0, 1e3, np.inf])
def test_brake_impulse_never_adds_energy(make_stepper: Stepper, bound: float) -> None:
    """T_M(u+) <= T_M(u_free): the brake (ideal or Tresca) only dissipates; Tresca obeys its law.

    Dissipation is exact where M_theta = M(q_M) (aligned configurations); the Tresca law is
    checked everywhere: |P_B| <= a dt; if the relative velocity gamma+ = W_B u+ is not 0
    (sliding), P_B = -a dt sign(gamma+).
    """
    dt = 1e-3
    stepper = make_stepper(BlockableManipulator, dt)
    for q, u in random_states(3, 60) + aligned_states(3, 30, dt):
        result = stepper.step(q, u, [0.0], [bound])
        q_mid, u_free, _ = midpoint_free(q, u, dt)
        m_mid = mass(q_mid)
        scale = 1.0 + np.abs(u).max() ** 2
        if abs(math.sin(q_mid[1] - q_mid[0])) < 1e-9:
            assert result.u @ m_mid @ result.u <= u_free @ m_mid @ u_free + 1e-14 * scale
        impulse, gamma = result.impulses[0], W_B @ result.u
        if np.isfinite(bound):
            assert result.lcp_size == 2 and result.num_equalities == 0
            assert abs(impulse) <= bound * dt * (1.0 + 1e-12) + 1e-15
            if abs(gamma) > 1e-12:
                assert impulse == pytest.approx(-np.sign(gamma) * bound * dt, rel=1e-12)
        else:
            assert abs(gamma) <= 1e-13 * (1.0 + np.abs(u).max())


def test_huge_tresca_bound_matches_the_ideal_brake(make_stepper: Stepper) -> None:
    """A = 1e6 N m (impulse bound 1e3 N m s >> |P_B| ~ 1): the ideal brake's step, to 1e-11."""
    stepper = make_stepper(BlockableManipulator, 1e-3)
    for q, u in random_states(4, 40):
        ideal = stepper.step(q, u, [0.0], [np.inf])
        tresca = stepper.step(q, u, [0.0], [1e6])
        np.testing.assert_allclose(tresca.u, ideal.u, rtol=0, atol=1e-11 * (1 + np.abs(u).max()))
        np.testing.assert_allclose(tresca.impulses, ideal.impulses, rtol=1e-11, atol=1e-13)


@pytest.mark.parametrize("bound", [1e18, 1e20, 1e300])
def test_astronomical_tresca_bound_matches_the_ideal_brake(
    make_stepper: Stepper, bound: float
) -> None:
    """A finite bound far above any needed impulse must still act as the ideal brake.

    FAILS (reported): the Tresca row is posed as P_B = P_R - a dt with P_R >= 0 the LCP
    variable, so P_B is the difference of two numbers of size a dt and loses all precision:
    q = (0.3, 1.2), u = (1, -2), dt = 1e-3: the ideal brake gives P_B = 0.456044 and
    u+ = (0.155692, 0.155692); a = 1e15 gives P_B = 0.456055, a = 1e18 gives P_B = 0.375,
    a = 1e20 and 1e300 give P_B = 0 and u+ = (1.001852, -2.002903), the released brake's
    step, all with status CONVERGED.
    """
    stepper = make_stepper(BlockableManipulator, 1e-3)
    q, u = np.array([0.3, 1.2]), np.array([1.0, -2.0])
    ideal = stepper.step(q, u, [0.0], [np.inf])
    tresca = stepper.step(q, u, [0.0], [bound])
    assert tresca.status.is_success
    np.testing.assert_allclose(tresca.impulses, ideal.impulses, rtol=1e-6)
    np.testing.assert_allclose(tresca.u, ideal.u, rtol=0, atol=1e-6)


# ------------------------------------------------------------------------------ trajectories
def test_engaged_brake_holds_to_roundoff(make_stepper: Stepper) -> None:
    """Random velocities and on/off schedules: |beta' - alpha'| <= 1e-12 in every engaged step.

    While engaged the arm is one rigid body: after the engagement step, u, T and L stay
    constant to round-off.
    """
    rng = np.random.default_rng(5)
    stepper = make_stepper(BlockableManipulator, 1e-3)
    for q, u in random_states(5, 6):
        bounds = random_schedule(rng, 2000, [0.0, np.inf])
        qs, us, _ = run(stepper, q, u, bounds)
        engaged = np.isinf(bounds)
        scale = 1.0 + np.abs(us).max()
        assert np.abs(us[1:][engaged] @ W_B).max() <= 1e-12 * scale
        held = np.nonzero(engaged[1:] & engaged[:-1])[0] + 1  # engaged in steps k-1 and k
        np.testing.assert_allclose(us[held + 1], us[held], rtol=0, atol=1e-12 * scale)
        energy = np.array([kinetic(a, b) for a, b in zip(qs, us, strict=True)])
        momenta = np.array([momentum(a, b) for a, b in zip(qs, us, strict=True)])
        np.testing.assert_allclose(energy[held + 1], energy[held], rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(momenta[held + 1], momenta[held], rtol=1e-12, atol=1e-14)


def test_momentum_drift_is_first_order(make_stepper: Stepper) -> None:
    """L = (1, 1) . M(q) u is conserved by the MDI; the step conserves it up to O(dt) drift.

    Not to round-off: M is evaluated at q_M but L at the grid points, so a free step changes
    L by O(dt^2). Schedule: released, engaged from 0.2 s, released at 0.5 s, engaged from
    0.8 s to 1.1 s, over 1.5 s. Measured max |L - L0| / |L0|: 1.5e-3, 7.5e-4, 3.8e-4 at
    dt = 2, 1, 0.5 ms.
    """
    q, u = np.array([0.3, -1.0]), np.array([2.0, -3.0])
    drifts = []
    for dt in (2e-3, 1e-3, 5e-4):
        t = np.arange(int(round(1.5 / dt))) * dt
        engaged = ((t > 0.2 - 1e-9) & (t < 0.5 - 1e-9)) | ((t > 0.8 - 1e-9) & (t < 1.1 - 1e-9))
        qs, us, _ = run(make_stepper(BlockableManipulator, dt), q, u, np.where(engaged, np.inf, 0))
        values = np.array([momentum(a, b) for a, b in zip(qs, us, strict=True)])
        drifts.append(np.abs(values - values[0]).max() / abs(values[0]))
    assert drifts[0] < 2e-2
    ratios = np.array(drifts[:-1]) / np.array(drifts[1:])
    assert np.all((ratios > 1.8) & (ratios < 2.2)), (drifts, ratios)


def reference_with_brake(q0: np.ndarray, u0: np.ndarray, engage: float, release: float,
                         t_end: float) -> np.ndarray:  # fmt: skip
    """Event-driven reference (tau = 0): free, plastic engagement at ``engage``, rigid, free."""

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        return np.concatenate([y[2:], np.linalg.solve(mass(y[:2]), forces(y[:2], y[2:]))])

    def free(y: np.ndarray, t0: float, t1: float) -> np.ndarray:
        return solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-12).y[:, -1]

    y = free(np.concatenate([q0, u0]), 0.0, engage)
    q, u = y[:2], y[2:]
    m_inv_w = np.linalg.solve(mass(q), W_B)
    u = u - m_inv_w * (W_B @ u) / (W_B @ m_inv_w)  # plastic impact: beta' = alpha' after
    q = q + (release - engage) * u  # rigid rotation at constant rate (h is along W_B)
    return free(np.concatenate([q, u]), release, t_end)


def test_global_error_is_first_order_through_engagement(make_stepper: Stepper) -> None:
    """Against an event-driven reference: engaged at 0.3 s (impactive), released at 0.7 s."""
    q0, u0 = np.array([0.3, -1.0]), np.array([2.0, -3.0])
    reference = reference_with_brake(q0, u0, 0.3, 0.7, 1.0)
    errors = []
    for dt in (4e-3, 2e-3, 1e-3):
        t = np.arange(int(round(1.0 / dt))) * dt
        engaged = (t >= 0.3 - 1e-12) & (t < 0.7 - 1e-12)
        qs, us, _ = run(make_stepper(BlockableManipulator, dt), q0, u0,
                        np.where(engaged, np.inf, 0.0))  # fmt: skip
        errors.append(np.abs(np.concatenate([qs[-1], us[-1]]) - reference).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert errors[-1] < 0.05
    assert np.all((ratios > 1.7) & (ratios < 2.3)), (errors, ratios)


def test_free_energy_error_per_step_is_second_order(make_stepper: Stepper) -> None:
    """Released brake: the energy changes O(dt^3) per step and drifts O(dt^2) over 1 s.

    The theta = 1/2 treatment of h makes the free step second-order accurate in energy;
    measured max increase per step 1.2e-7, 1.5e-8, 1.9e-9 J and drift 1.2e-5, 2.9e-6, 7.2e-7 J
    at dt = 2, 1, 0.5 ms.
    """
    q, u = np.array([0.3, 1.2]), np.array([1.9, 0.3])
    increases, drifts = [], []
    for dt in (2e-3, 1e-3, 5e-4):
        qs, us, _ = run(make_stepper(BlockableManipulator, dt), q, u,
                        np.zeros(int(round(1.0 / dt))))  # fmt: skip
        energy = np.array([kinetic(a, b) for a, b in zip(qs, us, strict=True)])
        increases.append(np.diff(energy).max())
        drifts.append(np.abs(energy - energy[0]).max())
    assert increases[0] > 0.0  # it does gain energy at times (see the energy test below)
    increase_ratios = np.array(increases[:-1]) / np.array(increases[1:])
    assert np.all((increase_ratios > 7.0) & (increase_ratios < 9.0)), increases
    drift_ratios = np.array(drifts[:-1]) / np.array(drifts[1:])
    assert np.all((drift_ratios > 3.5) & (drift_ratios < 4.5)), drifts


@pytest.mark.xfail(
    strict=True,
    reason=(
        "the smooth part of the step is not exactly energy-conserving: free phases change the "
        "energy by O(dt^3) per step, either way (bounded by the test above); impacts and brake "
        "engagements never add energy"
    ),
)
def test_design_energy_never_increases(make_stepper: Stepper) -> None:
    """The textbook property "with eps <= 1 and no control the energy never increases".

    FAILS (reported): tau = 0, brake released, dt = 1e-3, q = (0.3, 1.2), u = (1.9, 0.3):
    679 of the first 1000 free steps gain energy, by up to 1.5e-8 J (T = 2.60 J). The
    theta = 1/2 step conserves energy to O(dt^2) over a finite time
    (``test_free_energy_error_per_step_is_second_order``), not exactly; the brake itself
    never adds energy (``test_brake_impulse_never_adds_energy``).
    """
    rng = np.random.default_rng(6)
    stepper = make_stepper(BlockableManipulator, 1e-3)
    cases = [(np.array([0.3, 1.2]), np.array([1.9, 0.3]), np.zeros(1000))]
    cases += [(q, u, random_schedule(rng, 1000, [0.0, np.inf, 0.5, 20.0]))
              for q, u in random_states(6, 4)]  # fmt: skip
    for q, u, bounds in cases:
        qs, us, _ = run(stepper, q, u, bounds)
        energy = np.array([kinetic(a, b) for a, b in zip(qs, us, strict=True)])
        assert np.diff(energy).max() <= 1e-12 * energy[0]


def test_tresca_brake_slows_then_holds(make_stepper: Stepper) -> None:
    """Small Tresca bound a: the relative velocity falls, but not at once, then holds.

    Gamma = beta' - alpha' falls monotonically with |P_B| = a dt per step, reaches 0 at the
    time of the sliding ODE M u' = h - a W_B^T sign(gamma) (within 2 dt), then stays 0.
    """
    a, dt = 2.0, 1e-3
    q0, u0 = np.array([0.3, 1.2]), np.array([1.0, -2.0])
    sign = np.sign(W_B @ u0)

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        q, u = y[:2], y[2:]
        return np.concatenate([u, np.linalg.solve(mass(q), forces(q, u) - a * sign * W_B)])

    def stops(_t: float, y: np.ndarray) -> float:
        return float(W_B @ y[2:])

    stops.terminal = True  # type: ignore[attr-defined]
    reference = solve_ivp(rhs, (0.0, 5.0), np.concatenate([q0, u0]), method="DOP853",
                          rtol=1e-12, atol=1e-12, events=stops)  # fmt: skip
    t_stop = float(reference.t_events[0][0])

    qs, us, impulses = run(make_stepper(BlockableManipulator, dt), q0, u0,
                           np.full(int(round(2 * t_stop / dt)), a))  # fmt: skip
    gamma = us @ W_B
    stopped = np.nonzero(np.abs(gamma) <= 1e-12)[0]
    k_stop = stopped[0]
    assert k_stop > 10  # not instantly
    assert np.all(stopped == np.arange(k_stop, len(gamma)))  # holds once stopped
    assert np.all(np.diff(np.abs(gamma[: k_stop + 1])) < 0.0)
    np.testing.assert_allclose(impulses[: k_stop - 1], -sign * a * dt, rtol=1e-12)
    assert np.all(np.abs(impulses) <= a * dt * (1 + 1e-12))
    assert abs(k_stop * dt - t_stop) <= 2 * dt, (k_stop * dt, t_stop)


def test_free_spin_keeps_energy_and_momentum_over_50_s(make_stepper: Stepper) -> None:
    """At the env's step dt = 0.01 s, tau = 0, brake released, u0 = (3, 6) rad/s, for 50 s.

    Measured: relative energy and momentum drift 3.7e-5 (the explicit h(q_M, u_k) of commit
    4a65047 drifted +89 % in energy and +38 % in momentum on this run).
    """
    stepper = make_stepper(BlockableManipulator, 1e-2)
    q, u = np.zeros(2), np.array([3.0, 6.0])
    energy, moment = kinetic(q, u), momentum(q, u)
    for _ in range(5000):
        result = stepper.step(q, u, [0.0])
        q, u = result.q, result.u
    drifts = (abs(kinetic(q, u) / energy - 1.0), abs(momentum(q, u) / moment - 1.0))
    print("relative energy and momentum drift over 50 s:", drifts)
    assert max(drifts) < 1e-4


@pytest.mark.parametrize("brake", [None, [np.inf]])
def test_under_resolved_step_is_reported(brake: list[float] | None) -> None:
    """An under-resolved step says INACCURATE; a resolved one CONVERGED.

    Joints counter-rotating at 100 rad/s turn 2 rad relative per 0.01 s step: the linearized
    velocity forces then eat more than 10 % of the inertia. At 10 rad/s the step is resolved.
    (The stress benchmark found such a step reporting CONVERGED while multiplying the energy
    by 1e10.)
    """
    from mdi_envs.solvers.status import SolverStatus

    stepper = MoreauJeanStepper(BlockableManipulator, time_step=0.01)
    slow = stepper.step([0.0, 0.0], [10.0, -10.0], [0.0], brake)
    fast = stepper.step([0.0, 0.0], [100.0, -100.0], [0.0], brake)
    assert slow.status is SolverStatus.CONVERGED
    assert fast.status is SolverStatus.INACCURATE
    assert np.isfinite(fast.u).all()


def test_dominates_matches_eigenvalues() -> None:
    """``dominates(A, M, f)`` is the sign of the smallest eigenvalue of sym(A) - f M."""
    from mdi_envs.solvers._linalg import dominates

    rng = np.random.default_rng(0)
    work = np.empty((3, 3))
    for _ in range(200):
        root = rng.normal(size=(3, 3))
        M = root @ root.T + 0.1 * np.eye(3)
        A = M - rng.normal(scale=0.5, size=(3, 3))
        smallest = np.linalg.eigvalsh(0.5 * (A + A.T) - 0.9 * M).min()
        if abs(smallest) > 1e-9:
            assert dominates(A, M, 0.9, work) == (smallest > 0.0)
