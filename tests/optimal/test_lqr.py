"""The time-varying LQR: its linearization, its Riccati recursion, and closed-loop tracking."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.linalg import solve_discrete_are

from baselines.evaluation import reference_effort
from mdi_envs.rollout import open_loop_policy, rollout
from mdi_envs.stepping import MoreauJeanStepper
from optimal.lqr import TimeVaryingLQR, linearize, riccati
from optimal.problems import UnitMass
from optimal.references import load_reference
from optimal.replay import env_actions, env_options


def test_the_linearization_of_a_unit_mass_is_its_exact_midpoint_step() -> None:
    """M = 1, h = 0: u' = u + dt F, q' = q + dt (u + u') / 2, linear in (q, u, F)."""
    dt = 0.1
    A, B = linearize(MoreauJeanStepper(UnitMass, time_step=dt), np.array([0.3]),
                     np.array([-0.2]), np.array([0.5]), None)
    np.testing.assert_allclose(A, [[1.0, dt], [0.0, 1.0]], atol=1e-8)
    np.testing.assert_allclose(B, [[dt**2 / 2], [dt]], atol=1e-8)


def test_the_riccati_recursion_converges_to_the_stationary_solution() -> None:
    """Far from the end, the cost-to-go of a time-invariant system solves the DARE."""
    dt = 0.1
    A = np.array([[1.0, dt], [0.0, 1.0]])
    B = np.array([[dt**2 / 2], [dt]])
    Q, R = np.diag([1.0, 0.1]), np.array([[0.01]])
    K, P = riccati(np.repeat(A[None], 400, 0), np.repeat(B[None], 400, 0), Q, R, np.zeros((2, 2)))
    stationary = solve_discrete_are(A, B, Q, R)
    np.testing.assert_allclose(P[0], stationary, rtol=1e-8)
    np.testing.assert_allclose(K[0], np.linalg.solve(R + B.T @ stationary @ B,
                                                     B.T @ stationary @ A), rtol=1e-8)
    assert np.allclose(K[-1], 0.0)  # the last input has nothing left to steer towards


def _play(policy, reference, seed: int, noise: float) -> dict:  # noqa: ANN001
    options = env_options(reference)
    options["reset_noise_scale"] = noise
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rollout(reference.metadata["env_id"], policy, seed=seed, **options).last_info


def test_the_lqr_reaches_the_goal_where_the_open_loop_reference_misses_it() -> None:
    """The robot's effort maneuver from 0.1-perturbed starts, at the optimum's effort +-5 %."""
    reference = load_reference("diff_drive_effort")
    controller = TimeVaryingLQR(reference)
    optimum = reference_effort(reference)
    open_loop = []
    for seed in range(3):
        controller.reset()
        info = _play(controller, reference, seed, 0.1)
        assert info["is_success"]
        assert info["effort"] == pytest.approx(optimum, rel=0.05)
        assert len(controller.compute_times) == len(reference.tau)
        open_loop.append(_play(open_loop_policy(env_actions(reference)), reference, seed,
                               0.1)["is_success"])
    assert not any(open_loop)


def test_from_the_reference_start_the_lqr_replays_the_reference() -> None:
    """No deviation, no correction: the controls are the reference's to its last interval."""
    reference = load_reference("manipulator_time")
    controller = TimeVaryingLQR(reference)
    for k in (0, 57, 119):
        tau, brake = controller.control(k, reference.q[k], reference.u[k])
        np.testing.assert_allclose(tau, reference.tau[k], atol=1e-12)
        np.testing.assert_array_equal(brake, reference.brake_bound[k])


def test_a_state_indexed_lqr_finds_the_reference_node_of_the_state() -> None:
    """The state-indexed step: node k's own state gives k, and the nominal replay its step count.

    Searched from ``first`` on, the index is never behind ``first``.
    """
    reference = load_reference("manipulator_time")
    controller = TimeVaryingLQR(reference)
    controller.index_window = 10
    for k in range(0, len(reference.tau) + 1, 7):
        for first in (max(k - 10, 0), k):
            assert controller.nearest_node(reference.q[k], reference.u[k], first) == k
        assert controller.nearest_node(reference.q[k], reference.u[k], k + 1) > k
    indices = []

    def policy(observation: np.ndarray) -> np.ndarray:
        action = controller(observation)
        indices.append(controller.last_step)
        return action

    info = _play(policy, reference, 0, 0.0)
    assert info["is_success"]  # within the goal's tolerance a few steps before the last node
    assert len(indices) > len(reference.tau) - 5
    np.testing.assert_array_equal(indices, np.arange(len(indices)))
