"""The spatial-contact Moreau-Jean step on the differential-drive robot (paper section 3.2).

Closed forms and invariants: rolling straight under equal torques, spinning about the axle
under opposite torques (against the reduced 2-DOF dynamics integrated by an ODE solver),
sliding at the traction limit, load transfer, frictionless wheels, dissipation; then the
batched form, input validation and diagnostics.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters, DiffDriveRobot
from mdi_envs.solvers.status import SolverStatus
from mdi_envs.stepping import MoreauJeanStepper
from mdi_envs.stepping._kernel import INFO_ACTIVE_CONTACTS, INFO_LCP_SIZE, INFO_STATUS
from mdi_envs.stepping._spatial_kernel import INFO_MODE, INFO_RESIDUAL, SPATIAL_INFO_SIZE

DT = 1e-3


@pytest.fixture(scope="module")
def make() -> Callable[..., MoreauJeanStepper]:
    """``make(**parameters)``: a fresh stepper (cold warm start); kernels compiled once."""
    warm = MoreauJeanStepper(DiffDriveRobot, time_step=DT)
    warm.step(np.zeros(5), np.zeros(5), np.zeros(2))
    warm.step_batch(np.zeros((1, 5)), np.zeros((1, 5)), np.zeros((1, 2)))

    def build(**parameters: Any) -> MoreauJeanStepper:
        return MoreauJeanStepper(DiffDriveRobot, DiffDriveParameters(**parameters), DT)

    return build


class Rollout(NamedTuple):
    q: np.ndarray  # (K + 1, 5) states, from the initial one
    u: np.ndarray  # (K + 1, 5)
    impulses: np.ndarray  # (K, 3, 3): per contact (P_N, P_T1, P_T2)
    slip: np.ndarray  # (K, 3, 2): W_T(q_M) u+ per contact (the velocities the laws act on)
    modes: np.ndarray  # (K,)
    statuses: set[SolverStatus]
    iterations: np.ndarray  # (K,)
    lifted: np.ndarray  # (K,)


def _rollout(stepper: MoreauJeanStepper, tau: Any, steps: int,
             q0: Any = None, u0: Any = None) -> Rollout:
    """``tau``: (2,) constant, or a function of the step index."""
    p = stepper.parameters.values()
    q = np.zeros(5) if q0 is None else np.array(q0, dtype=float)
    u = np.zeros(5) if u0 is None else np.array(u0, dtype=float)
    qs, us, imps, slips, modes, statuses, iters, lifted = [q], [u], [], [], [], set(), [], []
    warm_start = None
    for k in range(steps):
        res = stepper.step(q, u, tau(k) if callable(tau) else tau, warm_start=warm_start)
        warm_start = res.impulses
        rows = np.array(DiffDriveRobot.contact_directions(q + 0.5 * DT * u, p, math))
        slips.append((rows @ res.u).reshape(3, 3)[:, 1:])
        q, u = res.q, res.u
        qs.append(q)
        us.append(u)
        imps.append(res.impulses.reshape(3, 3))
        modes.append(res.mode)
        statuses.add(res.status)
        iters.append(res.num_iter)
        lifted.append(res.num_lifted_contacts)
    return Rollout(np.array(qs), np.array(us), np.array(imps), np.array(slips),
                   np.array(modes), statuses, np.array(iters), np.array(lifted))


def _friction(p: DiffDriveParameters) -> np.ndarray:
    return np.array([p.wheel_friction, p.wheel_friction, p.stick_friction])


@pytest.mark.parametrize("stick_friction", [0.0, 0.3])
def test_equal_torques_roll_straight(make: Callable[..., MoreauJeanStepper],
                                     stick_friction: float) -> None:
    """Both wheels roll; x = A t^2 / 2 with the rolling closed form.

    Rolling (r psi' = x'), wheel: J psi'' = tau - r F_x; chassis: m x'' = 2 F_x + F_S with the
    sliding stick F_S = -mu_S N_S and N_S = (a m g - h m x'') / (a + c) (load transfer), so

        A = (2 tau / r - mu_S a m g / (a + c)) / (m + 2 J / r^2 - mu_S h m / (a + c)),

    i.e. 2 tau / (r (m + 2 J / r^2)) for a frictionless stick. The midpoint rule integrates a
    constant acceleration exactly.
    """
    stepper = make(stick_friction=stick_friction)
    p = stepper.parameters
    tau = 1.0
    run = _rollout(stepper, [tau, tau], 1000)
    span = p.axle_offset + p.stick_offset
    accel = ((2 * tau / p.wheel_radius - stick_friction * p.axle_offset * p.mass * p.gravity / span)
             / (p.mass + 2 * p.wheel_inertia / p.wheel_radius**2
                - stick_friction * p.cm_height * p.mass / span))
    t = DT * np.arange(run.q.shape[0])
    assert run.statuses == {SolverStatus.CONVERGED}
    assert (run.modes == 2).all()
    assert np.abs(run.slip[:, :2]).max() < 1e-12  # wheels roll
    np.testing.assert_allclose(run.q[:, 0], 0.5 * accel * t**2, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(run.q[:, 3:], run.q[:, [0, 0]] / p.wheel_radius,
                               rtol=1e-9, atol=1e-15)
    assert np.abs(run.q[:, 1:3]).max() < 1e-12  # straight, heading unchanged
    if stick_friction > 0:  # the stick slides at its friction bound
        stick = run.impulses[:, 2]
        np.testing.assert_allclose(-stick[:, 1], stick_friction * stick[:, 0], rtol=1e-9)


def _reduced_rolling_dynamics(p: DiffDriveParameters, tau_l: float, tau_r: float) -> Callable:
    """RHS of the 2-DOF rolling mode for the state (x, y, phi, V_x, omega).

    Body-frame CM velocity (V_x, V_y) with V_y = a omega (the axle does not slide sideways);
    unknowns (V_x', omega', F_xL, F_xR, F_yL + F_yR); the stick slides (forces -mu_S N_S along
    its velocity (V_x, (a + c) omega), N_S from the pitch balance).
    """
    m, inertia, r, j = p.mass, p.yaw_inertia, p.wheel_radius, p.wheel_inertia
    b, a, c, h, mu = p.half_track, p.axle_offset, p.stick_offset, p.cm_height, p.stick_friction
    n_s0, n_s1 = a * m * p.gravity / (a + c), h * m / (a + c)  # N_S = n_s0 - n_s1 sum F_x / m

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        _, _, phi, vx, w = y
        vy = a * w
        speed = math.hypot(vx, (a + c) * w)
        ex, ey = (vx / speed, (a + c) * w / speed) if speed > 0 else (0.0, 1.0)
        stick0 = n_s0 + n_s1 * w * vy  # N_S = stick0 - n_s1 V_x'
        mat = np.array([
            [m - mu * ex * n_s1, 0.0, -1.0, -1.0, 0.0],  # m (V_x' - w V_y) = sum F_x
            [-mu * ey * n_s1, m * a, 0.0, 0.0, -1.0],  # m (a w' + w V_x) = sum F_y
            [-c * mu * ey * n_s1, inertia, b, -b, a],  # I w' = moments about the CM
            [j / r, -j * b / r, r, 0.0, 0.0],  # J psi_L'' = tau_L - r F_xL, r psi_L' = V_x - b w
            [j / r, j * b / r, 0.0, r, 0.0],
        ])
        rhs_vec = np.array([m * w * vy - mu * ex * stick0, -m * w * vx - mu * ey * stick0,
                            -c * mu * ey * stick0, tau_l, tau_r])
        vx_dot, w_dot = np.linalg.solve(mat, rhs_vec)[:2]
        cp, sp = math.cos(phi), math.sin(phi)
        return [cp * vx - sp * vy, sp * vx + cp * vy, w, vx_dot, w_dot]

    return rhs


def test_opposite_torques_spin_about_the_axle(make: Callable[..., MoreauJeanStepper]) -> None:
    """Both wheels roll and the axle never slides sideways; the CM, ahead of the axle, circles.

    The axle midpoint does not stay exactly put: the centrifugal force on the CM (ahead of the
    axle) pushes it forward, resisted only by the wheels' spin inertia, so it drifts forward by
    m a omega^2 / (m + 2 J / r^2) -- checked against the reduced rolling dynamics (ODE).
    """
    stepper = make()
    p = stepper.parameters
    run = _rollout(stepper, [-1.0, 1.0], 1000)
    assert run.statuses == {SolverStatus.CONVERGED}
    assert (run.modes == 2).all()
    assert np.abs(run.slip[:, :2]).max() < 1e-12  # both wheels roll, no lateral axle slip
    assert np.linalg.norm(run.slip[:, 2], axis=1).min() > 0  # the stick slides
    ref = solve_ivp(_reduced_rolling_dynamics(p, -1.0, 1.0), (0.0, 1.0), np.zeros(5),
                    rtol=1e-11, atol=1e-13).y[:, -1]
    q, u = run.q[-1], run.u[-1]
    np.testing.assert_allclose(q[:3], ref[:3], rtol=0.0, atol=3e-5)  # O(dt): 1.3e-5 measured
    cp, sp = math.cos(q[2]), math.sin(q[2])
    np.testing.assert_allclose([cp * u[0] + sp * u[1], u[2]], ref[3:], rtol=0.0, atol=1e-4)
    # the wheels turn in opposite senses relative to the forward drift (rolling)
    np.testing.assert_allclose(p.wheel_radius * u[3:], ref[3] + np.array([-1, 1])
                               * p.half_track * ref[4], rtol=0.0, atol=1e-4)
    # the axle midpoint: drift small against the CM's travel, and as the ODE predicts
    axle = run.q[:, :2] - p.axle_offset * np.stack([np.cos(run.q[:, 2]), np.sin(run.q[:, 2])], 1)
    axle_ref = ref[:2] - p.axle_offset * np.array([math.cos(ref[2]), math.sin(ref[2])])
    np.testing.assert_allclose(axle[-1], axle_ref, atol=3e-5)
    assert np.linalg.norm(axle[-1] - axle[0]) < 0.15 * p.axle_offset * q[2]


def test_torques_beyond_traction_limit_slide_at_the_cone_boundary(
        make: Callable[..., MoreauJeanStepper]) -> None:
    stepper = make()
    mu = _friction(stepper.parameters)
    run = _rollout(stepper, [10.0, 10.0], 300)
    assert run.statuses == {SolverStatus.CONVERGED}
    assert (run.modes == 5).all()
    ratio = np.linalg.norm(run.impulses[:, :, 1:], axis=2) / (mu * run.impulses[:, :, 0])
    np.testing.assert_allclose(ratio, 1.0, rtol=1e-8)
    # the friction opposes the slip; the wheels spin faster than the chassis moves
    dot = np.einsum("kij,kij->ki", run.impulses[:, :, 1:], run.slip)
    assert (dot < 0).all()
    assert (stepper.parameters.wheel_radius * run.u[1:, 3:] > run.u[1:, [0]]).all()


def test_one_wheel_beyond_its_limit_gives_the_3_dof_mode(
        make: Callable[..., MoreauJeanStepper]) -> None:
    stepper = make()
    mu = _friction(stepper.parameters)
    run = _rollout(stepper, [10.0, 0.5], 100)
    assert run.statuses == {SolverStatus.CONVERGED}
    assert (run.modes == 3).all()
    left = run.impulses[:, 0]
    np.testing.assert_allclose(np.hypot(left[:, 1], left[:, 2]), mu[0] * left[:, 0], rtol=1e-8)
    assert np.linalg.norm(run.slip[:, 0], axis=1).min() > 1e-3  # left slides
    assert np.abs(run.slip[:, 1]).max() < 1e-12  # right rolls


def test_normal_impulses_carry_the_weight_and_shift_with_acceleration(
        make: Callable[..., MoreauJeanStepper]) -> None:
    stepper = make()
    p = stepper.parameters
    n0, k = (np.array(a) for a in DiffDriveRobot.normal_loads(p.values()))
    run = _rollout(stepper, lambda i: [1.0 + 0.5 * math.sin(0.01 * i), 1.6], 1500)
    assert run.statuses == {SolverStatus.CONVERGED} and (run.lifted == 0).all()
    normal = run.impulses[:, :, 0]
    np.testing.assert_allclose(normal.sum(axis=1), p.mass * p.gravity * DT, rtol=1e-12)
    # P_N = N0 dt + K P_T (all loads positive), to the solver's tolerance
    friction = run.impulses[:, :, 1:].reshape(-1, 6)
    np.testing.assert_allclose(normal, n0 * DT + friction @ k.T, rtol=0.0,
                               atol=1e-11 * p.mass * p.gravity * DT)
    # accelerating forward: the axle carries more than its static share
    static_axle = (n0[0] + n0[1]) * DT
    assert (normal[:, 0] + normal[:, 1] > static_axle).all()
    # turning left (tau_R > tau_L): the outer (right) wheel carries more, once moving
    assert run.u[-1, 2] > 0
    assert (normal[100:, 1] > normal[100:, 0]).all()


@pytest.mark.parametrize("mu", [0.0, 1e-9])
def test_frictionless_wheels_cannot_push_the_chassis(make: Callable[..., MoreauJeanStepper],
                                                     mu: float) -> None:
    stepper = make(wheel_friction=mu, stick_friction=mu)
    p = stepper.parameters
    tau = np.array([0.5, -0.3])
    run = _rollout(stepper, tau, 500)
    assert run.statuses == {SolverStatus.CONVERGED}
    assert np.abs(run.q[:, :3]).max() < 1e-8 and np.abs(run.u[:, :3]).max() < 1e-7
    t = DT * np.arange(run.q.shape[0])
    np.testing.assert_allclose(run.u[:, 3:], np.outer(t, tau / p.wheel_inertia), rtol=1e-7)
    assert (run.modes[1:] == 5).all()  # both wheels spin freely (slide)


def test_coasting_dissipates_energy_and_comes_to_rest(
        make: Callable[..., MoreauJeanStepper]) -> None:
    stepper = make()
    p = stepper.parameters
    masses = np.array([p.mass, p.mass, p.yaw_inertia, p.wheel_inertia, p.wheel_inertia])
    # sideways and yaw motion stop within ~0.2 s; then the robot rolls on, slowed by the stick
    run = _rollout(stepper, [0.0, 0.0], 1300, u0=[0.5, 1.0, 2.0, 0.0, 0.0])
    assert run.statuses == {SolverStatus.CONVERGED}
    energy = 0.5 * (run.u**2 * masses).sum(axis=1)
    assert np.diff(energy).max() <= 1e-12 * energy[0]
    assert np.abs(run.u[-1]).max() < 1e-10
    assert set(run.modes[:5]) == {5} and run.modes[-1] == 2  # slides, then rests


def test_step_batch_continues_from_the_impulses_it_is_given(
        make: Callable[..., MoreauJeanStepper]) -> None:
    """Two calls of 40 substeps passing the impulses on (``out``) equal one call of 80.

    Bitwise; a cold restart reaches the same motion to the solver's tolerance.
    """
    torques = np.array([[1.0, 1.0], [0.2, 0.8], [10.0, 0.5]])
    stepper = make()
    q_one, u_one = np.zeros((3, 5)), np.zeros((3, 5))
    impulses_one, _ = stepper.step_batch(q_one, u_one, torques, num_substeps=80)
    q, u = np.zeros((3, 5)), np.zeros((3, 5))
    out = (np.zeros((3, 9)), np.empty((3, SPATIAL_INFO_SIZE)))
    for _ in range(2):
        stepper.step_batch(q, u, torques, np.zeros((3, 0)), 40, check_inputs=False, out=out)
    np.testing.assert_array_equal(q, q_one)
    np.testing.assert_array_equal(u, u_one)
    np.testing.assert_array_equal(out[0], impulses_one)
    assert (out[1][:, INFO_STATUS] == SolverStatus.CONVERGED).all()
    q_cold, u_cold = np.zeros((3, 5)), np.zeros((3, 5))
    stepper.step_batch(q_cold, u_cold, torques, num_substeps=40)
    stepper.step_batch(q_cold, u_cold, torques, num_substeps=40)  # restarts cold
    np.testing.assert_allclose(u_cold, u_one, rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(q_cold, q_one, rtol=0.0, atol=1e-11)


def test_batch_equals_single(make: Callable[..., MoreauJeanStepper]) -> None:
    torques = np.array([[1.0, 1.0], [-1.0, 1.0], [10.0, 0.5], [0.2, 2.0]])
    q = np.zeros((4, 5))
    u = np.zeros((4, 5))
    u[3] = [0.3, -0.2, 1.0, 0.0, 0.0]
    u0 = u.copy()
    batch = make()
    impulses, info = batch.step_batch(q, u, torques, num_substeps=80)
    assert info.shape == (4, SPATIAL_INFO_SIZE)
    for e in range(4):
        single = _rollout(make(), torques[e], 80, u0=u0[e])
        np.testing.assert_allclose(q[e], single.q[-1], rtol=0.0, atol=1e-13)
        np.testing.assert_allclose(u[e], single.u[-1], rtol=0.0, atol=1e-12)
        np.testing.assert_allclose(impulses[e], single.impulses[-1].ravel(), atol=1e-14)
        assert info[e, INFO_MODE] == single.modes[-1]
    np.testing.assert_array_equal(info[:, INFO_MODE], [2, 2, 3, 2])
    np.testing.assert_array_equal(info[:, INFO_STATUS], SolverStatus.CONVERGED)
    np.testing.assert_array_equal(info[:, INFO_ACTIVE_CONTACTS], 3)
    np.testing.assert_array_equal(info[:, INFO_LCP_SIZE], 9)
    assert (info[:, INFO_RESIDUAL] <= 1e-12).all()


def test_a_load_that_would_be_negative_lifts_the_contact(
        make: Callable[..., MoreauJeanStepper]) -> None:
    """A tall robot accelerating hard unloads its stick (a wheelie): P_N = 0, reported."""
    stepper = make(cm_height=1.0)
    run = _rollout(stepper, [3.0, 3.0], 20)
    assert run.statuses == {SolverStatus.CONVERGED}
    assert (run.lifted == 1).all()
    np.testing.assert_array_equal(run.impulses[:, 2], 0.0)
    assert (run.impulses[:, :2, 0] > 0).all()


def test_bad_input_raises(make: Callable[..., MoreauJeanStepper]) -> None:
    stepper = make()
    with pytest.raises(ValueError):
        stepper.step(np.zeros(4), np.zeros(5), [0.0, 0.0])
    with pytest.raises(ValueError):
        stepper.step(np.zeros(5), np.zeros(5), [0.0, 0.0, 0.0])
    with pytest.raises(ValueError):
        stepper.step(np.zeros(5), np.zeros(5), [np.nan, 0.0])
    with pytest.raises(ValueError):
        stepper.step(np.zeros(5), [0.0, np.inf, 0.0, 0.0, 0.0], [0.0, 0.0])
    q, u = np.zeros((2, 5)), np.zeros((2, 5))
    with pytest.raises(ValueError):
        stepper.step_batch(q, u, np.zeros((3, 2)))
    with pytest.raises(ValueError):
        stepper.step_batch(q, u, np.array([[0.0, np.nan], [0.0, 0.0]]))
    with pytest.raises(ValueError):
        stepper.step_batch(np.zeros((2, 4)), u, np.zeros((2, 2)))
    with pytest.raises(ValueError):
        stepper.step_batch(q, u, np.zeros((2, 2)), num_substeps=0)


def test_the_full_fc3d_fallback_steps_as_the_newton_on_friction_impulses() -> None:
    """The full FC3D fallback gives the trajectory of the Newton on friction impulses alone.

    With no Newton step allowed on the friction impulses, every solve that the warm start does
    not already satisfy goes to the full FC3D problem (``newton_ac_core``): the trajectory
    through rolling, turning, wheel spin and braking is the same to the solvers' tolerance,
    and both report the same modes.
    """
    from mdi_envs._kernel_cache import freeze
    from mdi_envs.mechanics.compiled import compile_equations
    from mdi_envs.stepping import _spatial_kernel
    from mdi_envs.stepping._kernel import INFO_ITERATIONS, StepShortcuts

    stepper = MoreauJeanStepper(DiffDriveRobot, time_step=DT)
    _, record, _ = stepper.compiled_step_batch
    default_step = stepper.compiled_step
    fallback, _ = _spatial_kernel.make_spatial_step_kernels(
        DiffDriveRobot, compile_equations(DiffDriveRobot), StepShortcuts(),
        load_transfer_max_iter=0)
    fallback_step = freeze("step_DiffDriveRobot", {"step": fallback})["step"]  # cached on disk
    runs = {}
    for name, step in (("default", default_step), ("fallback", fallback_step)):
        q, u = np.zeros(5), np.zeros(5)
        q_next, u_next = np.empty(5), np.empty(5)
        impulses, info = np.zeros(9), np.zeros(SPATIAL_INFO_SIZE)
        workspace = _spatial_kernel.make_spatial_workspace(DiffDriveRobot)
        states, modes, iterations = [], [], 0
        for k in range(400):
            tau = [(0.5, 0.5), (0.2, 0.8), (5.0, 5.0), (-2.0, -2.0)][k // 100]
            step(q, u, np.array(tau), np.zeros(0), DT, record, q_next, u_next, impulses, info,
                 workspace)
            assert info[INFO_STATUS] == 0.0
            q, u = q_next.copy(), u_next.copy()
            states.append(np.concatenate([q, u]))
            modes.append(info[INFO_MODE])
            iterations += info[INFO_ITERATIONS]
        runs[name] = (np.array(states), modes, iterations)
    np.testing.assert_allclose(runs["fallback"][0], runs["default"][0], rtol=0, atol=1e-9)
    assert not np.array_equal(runs["fallback"][0], runs["default"][0])  # two solvers did run
    assert runs["fallback"][1] == runs["default"][1]
    assert set(runs["default"][1]) >= {2.0, 5.0}  # rolling and spinning wheels both seen
    assert runs["default"][2] > 0 and runs["fallback"][2] > 0
