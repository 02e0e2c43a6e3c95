"""The receding-horizon tracking MPC on the manipulator reference, with a short window."""

from __future__ import annotations

import resource
import warnings
from collections.abc import Callable

import numpy as np
import pytest

casadi = pytest.importorskip("casadi")

from mdi_envs.maneuvers import MANIPULATOR_MANEUVER  # noqa: E402
from mdi_envs.rollout import rollout  # noqa: E402
from optimal.references import load_reference  # noqa: E402
from optimal.replay import env_options  # noqa: E402
from optimal.tracking import TrackingMPC, _shift_indices  # noqa: E402

WINDOW = 8


@pytest.fixture(scope="module")
def controller() -> TrackingMPC:
    return TrackingMPC(load_reference("manipulator_time"), horizon=WINDOW)


@pytest.fixture(scope="module")
def robot_trackers() -> dict[str, TrackingMPC]:
    """A tracker (window 3) per robot reference, built once for the module's tests."""
    return {name: TrackingMPC(load_reference(name), horizon=3)
            for name in ("diff_drive_effort", "diff_drive_time")}


@pytest.fixture()
def robot_tracker(robot_trackers: dict[str, TrackingMPC], monkeypatch: pytest.MonkeyPatch
                  ) -> Callable[[str], TrackingMPC]:
    """The shared tracker of a robot reference, reset; attributes a test sets are restored."""
    def tracker(name: str) -> TrackingMPC:
        controller = robot_trackers[name]
        for attribute in ("index_window", "index_on_less_friction"):
            monkeypatch.setattr(controller, attribute, getattr(controller, attribute))
        controller.reset()
        return controller

    return tracker


def test_on_the_reference_the_plan_is_the_reference(controller: TrackingMPC) -> None:
    """No deviation: the window's optimum is the reference's own controls."""
    reference = controller.reference
    controller.reset()
    tau, brake = controller.control(0, reference.q[0], reference.u[0])
    np.testing.assert_allclose(tau, reference.tau[0], atol=1e-3 * controller.torque_bound)
    np.testing.assert_array_equal(brake, reference.brake_bound[0])
    assert controller.fallbacks == []


@pytest.mark.parametrize("name", ["diff_drive_effort", "diff_drive_time"])
def test_every_window_solved_from_the_references_state_gives_its_multipliers(
        name: str, robot_tracker: Callable[[str], TrackingMPC]) -> None:
    """The stored multipliers (the start of a first or window-changing step) are a solution's.

    On both robot references (the time task's with ``WARM_START_PUSH``: the stored multipliers
    are solved with IPOPT's own pushes). A failed solve would leave zeros; each window has at
    least one nearly active inequality (a torque bound or a contact law), whose multiplier is
    not zero.
    """
    controller = robot_tracker(name)
    lead = controller._lead  # the windows before the reference's first: see the next tests
    for key, multipliers in zip(controller._keys[lead:],
                                controller._reference_multipliers[lead:], strict=True):
        assert multipliers.shape == (controller._windows[key].num_multipliers,)
        assert np.all(np.isfinite(multipliers)) and np.any(multipliers != 0.0)


def test_from_a_perturbed_start_it_reaches_the_goal_in_the_optimal_time(
        controller: TrackingMPC) -> None:
    reference = controller.reference
    options = env_options(reference)
    options.update(reset_noise_scale=0.01, max_episode_steps=2 * len(reference.tau))
    controller.reset()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        info = rollout(reference.metadata["env_id"], controller, seed=3, **options).last_info
    assert info["is_success"]
    assert info["elapsed_time"] <= 1.01 * reference.final_time
    assert len(controller.compute_times) == len(controller.iterations)


def test_on_the_reference_the_next_warm_start_is_the_reference(controller: TrackingMPC) -> None:
    """The plan shifted by one interval, its new last interval from the reference's point.

    On the reference the plan is the reference, so the next window's start (trajectory and
    torques, the first three variables) is that window's reference point, its last interval
    included (the plan's last interval repeated there is 0.09 off in the NLP's units).
    """
    reference = controller.reference
    controller.reset()
    controller.control(0, reference.q[0], reference.u[0])
    last, plan, _, solved_at = controller._previous
    window = controller._windows[controller._keys[1]]
    start = np.concatenate([plan, controller._reference_points[1]])[
        _shift_indices(last.shapes, window.shapes, 1 - solved_at)]
    size = sum(rows * columns for rows, columns in window.shapes[:3])
    np.testing.assert_allclose(start[:size], controller._reference_points[1][:size], atol=1e-2)


def test_the_warm_start_shifts_every_variable_by_whole_intervals() -> None:
    """Two variables, (2, 3) and (1, 2), column-major, then the new window's reference point.

    Each new column j takes the old column j + 1; where there is none, the reference point's
    column j (its entries follow the old point's 8).
    """
    old = [(2, 3), (1, 2)]
    np.testing.assert_array_equal(_shift_indices(old, old, 1), [2, 3, 4, 5, 12, 13, 7, 15])
    np.testing.assert_array_equal(_shift_indices(old, [(2, 2), (1, 1)], 1), [2, 3, 4, 5, 7])
    np.testing.assert_array_equal(_shift_indices(old, old, 0), np.arange(8))


def test_steps_without_a_plan_keep_no_memory() -> None:
    """Without a plan at any step, the peak resident memory stays where the first steps left it.

    IPOPT is held to one iteration without an acceptable stop, so every step falls back to the
    LQR; the NLPs are built once, nothing per step.
    """
    import gymnasium as gym

    reference = load_reference("manipulator_time")
    controller = TrackingMPC(reference, horizon=4, max_iterations=1,
                             solver_options={"acceptable_iter": 0})
    options = env_options(reference)
    options.update(reset_noise_scale=0.1, max_episode_steps=2 * len(reference.tau))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make(reference.metadata["env_id"], **options)
    observation, _ = env.reset(seed=0)
    for step in range(60):
        if step == 10:
            start = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        observation, *_ = env.step(controller(observation))
    growth_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - start
    assert controller.fallbacks == list(range(60))
    assert growth_kb < 10 * 1024  # the unbounded growth kept ~100 MB per such step


def test_on_a_floor_with_less_grip_the_robots_tracker_adapts_and_follows_the_path(
        robot_tracker: Callable[[str], TrackingMPC]) -> None:
    """One step of the reference's start (both wheels slip) on a floor with 20 % less friction.

    Before it the tracker plans with the model's friction and is time-indexed; after it, with
    the floor's, and (``index_on_less_friction``) state-indexed.
    """
    from mdi_envs.stepping import MoreauJeanStepper
    from optimal.problems import make_problem, model_of
    from optimal.traction import scaled_friction

    controller = robot_tracker("diff_drive_time")
    reference = controller.reference
    controller.index_window, controller.index_on_less_friction = 10, True
    controller.reset()
    model, parameters = model_of(make_problem(reference.name))
    floor = MoreauJeanStepper(model, scaled_friction(parameters, 0.8), reference.time_step)
    q, u = reference.q[0], reference.u[0]
    assert not controller.is_state_indexed()
    tau, _ = controller.control(0, q, u)
    step = floor.step(q, u, tau)
    controller.control(1, step.q, step.u)
    assert controller.friction_factors[0] == 1.0
    assert controller.friction_factors[1] == pytest.approx(0.8, abs=1e-4)
    assert controller.is_state_indexed()
    controller.reset()
    assert controller.traction.factor == 1.0 and not controller.is_state_indexed()


def test_the_robots_tracker_estimates_friction_from_the_torques_played(
        robot_tracker: Callable[[str], TrackingMPC]) -> None:
    """A step played with other torques than the tracker's (a learner's, in a DAgger mixture).

    Told those torques (``applied``), it finds the floor's 20 % less grip from the step; fed its
    own, no friction factor explains the step and the estimate stays at the model's.
    """
    from mdi_envs.stepping import MoreauJeanStepper
    from optimal.problems import make_problem, model_of
    from optimal.traction import scaled_friction

    controller = robot_tracker("diff_drive_time")
    reference = controller.reference
    model, parameters = model_of(make_problem(reference.name))
    floor = MoreauJeanStepper(model, scaled_friction(parameters, 0.8), reference.time_step)
    q, u = reference.q[0], reference.u[0]
    for told, factor in ((True, 0.8), (False, 1.0)):
        controller.reset()
        tau, _ = controller.control(0, q, u)
        played = 0.5 * tau
        step = floor.step(q, u, played)
        if told:
            controller.applied(played / controller.torque_bound)
        controller.control(1, step.q, step.u)
        assert controller.friction_factors[1] == pytest.approx(factor, abs=1e-6)


def test_a_step_behind_at_the_last_engagement_it_engages_the_brake_a_step_later(
        controller: TrackingMPC) -> None:
    """At the reference's last released-to-engaged interval k, from the reference's state k - 1.

    Engaging on time would lock the joint one interval short of the goal; the plan of window
    k - 1 (the reference one step later) keeps the brake released, and the controller's
    reference runs one step later from then on. From the reference's state k itself it engages
    on time.
    """
    reference = controller.reference
    engaged = reference.brake_bound[:, 0] > 0.0
    k = int(np.flatnonzero(engaged[1:] & ~engaged[:-1])[-1]) + 1
    controller.reset()
    _, brake = controller.control(k, reference.q[k], reference.u[k])
    assert controller.delays == [] and brake[0] > 0.0
    controller.reset()
    _, brake = controller.control(k, reference.q[k - 1], reference.u[k - 1])
    assert controller.delays == [k] and brake[0] == 0.0
    np.testing.assert_array_equal(controller.predicted_q(k + 1), reference.q[k])


def _reversal(reference) -> int:
    """The reference interval at which the manipulator's torque turns from + to -."""
    torque = np.sign(reference.tau[:, 0])
    return int(np.flatnonzero(torque[1:] * torque[:-1] < 0)[0]) + 1


def test_on_the_reference_at_the_torque_reversal_the_re_solved_rest_is_the_reference(
        controller: TrackingMPC) -> None:
    """The remaining problem re-solved from the reference's own state k arrives on time, along it.

    A reset tracks the reference again; a state-indexed controller does not re-plan.
    """
    reference = controller.reference
    k = _reversal(reference)
    controller.reset()
    controller.control(k, reference.q[k], reference.u[k])
    assert controller.replans == [k] and controller.delays == []
    np.testing.assert_allclose(controller.predicted_q(len(reference.tau)), reference.q[-1],
                               atol=1e-4)
    deviation = max(np.max(np.abs(controller.predicted_q(j) - reference.q[j]))
                    for j in range(k, len(reference.tau) + 1))
    assert deviation < 0.02
    controller.reset()
    assert controller.replans == []
    np.testing.assert_array_equal(controller.predicted_q(k + 1), reference.q[k + 1])
    controller.index_window = 10  # state-indexed: the reference's own nodes, never re-planned
    try:
        controller.control(k, reference.q[k], reference.u[k])
        assert controller.replans == []
    finally:
        controller.index_window = 0
        controller.reset()


def test_a_step_behind_at_the_torque_reversal_it_tracks_the_re_solved_rest(
        controller: TrackingMPC) -> None:
    """From the reference's state k - 1 at step k the plan tracked starts at that state.

    It ends at rest within the goal's tolerances, at most 3 steps after the reference.
    """
    reference = controller.reference
    k = _reversal(reference)
    controller.reset()
    controller.control(k, reference.q[k - 1], reference.u[k - 1])
    later = len(controller.delays)
    assert controller.replans == [k] and later <= 3
    start = controller._x[k - later]
    np.testing.assert_allclose(start, np.concatenate([reference.q[k - 1], reference.u[k - 1]]))
    end = controller._x[len(reference.tau)]
    n = end.size // 2
    assert np.all(np.abs(end[:n] - reference.q[-1]) <= MANIPULATOR_MANEUVER.angle_tolerance)
    assert np.all(np.abs(end[n:]) <= MANIPULATOR_MANEUVER.velocity_tolerance)


def _robot_goal_reached(x: np.ndarray) -> bool:
    """Whether the robot's state (q, u) (5 + 5) is at rest in the goal box."""
    from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER as goal

    q, u = x[:5], x[5:]
    heading = (q[2] - goal.goal_pose[2] + np.pi) % (2 * np.pi) - np.pi
    return bool(np.hypot(*(q[:2] - goal.goal_pose[:2])) <= goal.position_tolerance
                and abs(heading) <= goal.heading_tolerance
                and np.hypot(*u[:2]) <= goal.speed_tolerance
                and abs(u[2]) <= goal.yaw_rate_tolerance)


def test_on_the_robots_effort_task_it_tracks_the_optimum_re_solved_from_its_start(
        robot_tracker: Callable[[str], TrackingMPC]) -> None:
    """From a perturbed start the first step re-solves the problem and tracks that plan.

    The plan starts at the measured state and ends at rest in the goal box at the reference's
    final time (a fixed horizon: never later); a reset tracks the reference again.
    """
    controller = robot_tracker("diff_drive_effort")
    reference = controller.reference
    q = reference.q[0] + np.array([-0.074, 0.0, 0.02, 0.0, 0.0])
    u = reference.u[0] + np.array([-0.094, -0.07, 0.086, 0.0, 0.0])
    controller.control(0, q, u)
    assert controller.replans == [0] and controller.delays == []
    np.testing.assert_allclose(controller._x[0], np.concatenate([q, u]), atol=1e-9)
    np.testing.assert_allclose(controller.predicted_q(0), q, atol=1e-9)
    assert _robot_goal_reached(controller._x[len(reference.tau)])
    assert not np.allclose(controller._tau[:len(reference.tau)], reference.tau, atol=1e-3)
    controller.reset()
    assert controller.replans == []
    np.testing.assert_array_equal(controller.predicted_q(1), reference.q[1])


@pytest.mark.slow
def test_from_a_start_that_cannot_keep_the_time_it_tracks_a_plan_arriving_later(
        robot_tracker: Callable[[str], TrackingMPC]) -> None:
    """The robot's time task from a start behind the reference: the re-solved plan, 1-3 steps late.

    It begins at the measured state ``later`` intervals before the reference's first and ends at
    rest in the goal box ``later`` steps after the reference's end; each step acts for the
    reference's interval ``later`` steps before it, and a state-indexed step searches the plan.
    A reset restores the windows' warm starts the plan rewrote.
    """
    controller = robot_tracker("diff_drive_time")
    reference = controller.reference
    starts = ([p.copy() for p in controller._reference_points],
              [m.copy() for m in controller._reference_multipliers])
    q = reference.q[0] + np.array([-0.083, -0.053, 0.06, 0.0, 0.0])
    u = reference.u[0] + np.array([0.016, -0.081, -0.013, 0.0, 0.0])
    controller.control(0, q, u)
    later, steps = len(controller.delays), len(reference.tau)
    assert controller.replans == [0] and 1 <= later <= 3
    np.testing.assert_allclose(controller.predicted_q(0), q, atol=1e-9)
    assert _robot_goal_reached(controller._x[-1])  # the plan's last node
    first = controller._lead - later
    assert np.any(controller._reference_multipliers[first] != 0.0)  # solved from the plan
    assert controller.reference_interval(steps - 1 + later) == steps - 1
    # state-indexed, the nodes are the plan's: its last acts for the reference's last interval
    assert len(controller.node_states) == steps + later + 1
    np.testing.assert_allclose(controller.node_states[0], np.concatenate([q, u]), atol=1e-9)
    controller.reset()  # the windows start from the reference again, as before the episode
    for window, (point, multipliers) in enumerate(zip(*starts, strict=True)):
        np.testing.assert_array_equal(controller._reference_points[window], point)
        np.testing.assert_array_equal(controller._reference_multipliers[window], multipliers)


def test_without_a_plan_from_the_start_the_robots_tracker_follows_the_path_at_its_pace(
        monkeypatch: pytest.MonkeyPatch, robot_tracker: Callable[[str], TrackingMPC]) -> None:
    """No re-solve from the start finds a plan: state-indexed after the last attempt.

    With ``index_on_less_friction`` (the robot's time-optimal row); a reset is time-indexed
    again.
    """
    from optimal.mpc import ShrinkingHorizonMPC
    from optimal.tracking import START_ATTEMPTS

    monkeypatch.setattr(ShrinkingHorizonMPC, "replan", lambda *args, **kwargs: None)
    controller = robot_tracker("diff_drive_time")
    reference = controller.reference
    controller.index_window, controller.index_on_less_friction = 10, True
    controller.reset()
    for step in range(START_ATTEMPTS):
        assert not controller.is_state_indexed()
        controller.control(step, reference.q[step], reference.u[step])
    assert controller.replans == [] and controller.is_state_indexed()
    controller.reset()
    assert not controller.is_state_indexed()
