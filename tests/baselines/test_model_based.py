"""``baselines.model_based``: the supervisor of the robot's reference trackers."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest

from baselines.model_based import Recovering, row_env_options
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER
from optimal.references import load_reference


class _Still:
    """A time-indexed tracker that applies no torque."""

    last_step = 0

    def reset(self) -> None:
        self.calls = 0

    def __call__(self, _observation: np.ndarray) -> np.ndarray:
        self.last_step, self.calls = self.calls, self.calls + 1
        return np.zeros(2, np.float32)

    def reference_interval(self, step: int) -> int:
        return step


class _StillAtTheLastNode(_Still):
    """A state-indexed tracker that applies no torque, nearest the reference's last node."""

    def __init__(self, last_node: int) -> None:
        self.last_node = last_node

    def __call__(self, _observation: np.ndarray) -> np.ndarray:
        self.last_step = self.last_node
        return np.zeros(2, np.float32)


@pytest.mark.parametrize("state_indexed", [False, True], ids=["time-indexed", "state-indexed"])
def test_past_the_reference_outside_the_goal_box_it_parks_the_robot(state_indexed: bool) -> None:
    """The tracker until it has acted for the last node, then the parking follower into the goal.

    The tracker applies no torque, so the robot stays at rest 0.3 m before the goal: a
    time-indexed tracker for the reference's N steps, a state-indexed one at its last node for
    one step; the follower reaches the goal box before the episode's 2 N steps end.
    """
    reference = load_reference("diff_drive_time")
    options = {**row_env_options(reference), "reset_noise_scale": 0.0}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make(reference.metadata["env_id"], **options)
    last_node = len(reference.tau) - 1
    tracker = _StillAtTheLastNode(last_node) if state_indexed else _Still()
    handover = 1 if state_indexed else len(reference.tau)
    policy = Recovering(tracker, reference, env)
    policy.reset()
    env.reset(seed=0)
    gx, gy, gphi = DIFF_DRIVE_MANEUVER.goal_pose
    env.unwrapped.set_state(np.array([gx + 0.02, gy + 0.3, gphi, 0.0, 0.0]), np.zeros(5))
    obs, steps, done = env.unwrapped.state.obs[0].copy(), 0, False
    while not done:
        action = policy(obs)
        if steps < handover:
            assert policy.recovery is None and not action.any()
        else:
            assert policy.recovery is not None
        obs, _, terminated, truncated, info = env.step(action)
        steps += 1
        done = terminated or truncated
    assert terminated and info["is_success"]
    assert handover < steps < 2 * len(reference.tau)
