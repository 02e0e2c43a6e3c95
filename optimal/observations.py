"""The state (q, u) of a mission env's observation, for the model-based controllers.

Neither observation carries the robot's wheel angles, on which no dynamics depend:
``decode_observation`` takes them, and the branch of every angle, from a predicted q.
``StateFeedbackPolicy`` turns a controller acting on (q, u) into an env policy.
"""

from __future__ import annotations

import math
import time

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.angles import wrap_angle
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER


def decode_observation(observation: FloatArray, predicted_q: FloatArray,
                       has_brake: bool) -> tuple[FloatArray, FloatArray]:
    """(q (n,), u (n,)) from an observation of the manipulator (``has_brake``) or the robot.

    Args:
        observation: the env's observation, (6,) for the manipulator, (9,) for the robot.
        predicted_q: (n,) the q the controller expects [rad, m]: the angles are unwrapped
            against it, the robot's wheel angles copied from it.
        has_brake: True for the manipulator (cos a, sin a, cos b, sin b, a', b'), False for
            the robot (goal offset x, y, cos and sin of the heading error, forward and lateral
            speed, yaw rate, wheel speeds).
    """
    observation = np.asarray(observation, dtype=float)
    if has_brake:
        angles = [math.atan2(observation[2 * i + 1], observation[2 * i]) for i in range(2)]
        q = np.array([p + wrap_angle(a - p) for a, p in zip(angles, predicted_q, strict=True)])
        return q, observation[4:6].copy()
    goal = DIFF_DRIVE_MANEUVER.goal_pose
    heading = goal[2] + math.atan2(observation[3], observation[2])
    heading = predicted_q[2] + wrap_angle(heading - predicted_q[2])
    cos_phi, sin_phi = math.cos(heading), math.sin(heading)
    forward, lateral = observation[4], observation[5]
    q = np.array([observation[0] + goal[0], observation[1] + goal[1], heading,
                  predicted_q[3], predicted_q[4]])
    u = np.array([cos_phi * forward - sin_phi * lateral,
                  sin_phi * forward + cos_phi * lateral, *observation[6:9]])
    return q, u


class StateFeedbackPolicy:
    """An env policy (default Box action space) from a state feedback ``control(step, q, u)``.

    Subclasses set ``has_brake``, ``torque_bound`` [N m], ``compute_times`` (reset per
    episode), ``node_states`` (N + 1, 2n) the reference's states (q, u) and ``node_weight``
    (2n,) a weight per state component, and define ``control`` and ``predicted_q``. A call
    decodes the observation against ``predicted_q`` at the last step, chooses the step, applies
    ``control`` at it, encodes the torques and brake bounds as the Box action and records its
    CPU time [s].

    The step is the number of calls this episode (time-indexed) unless ``is_state_indexed``
    (``index_window`` > 0 by default); then it is ``nearest_node`` of the measured state,
    searched from the last call's step (0 at the first call) over the ``index_window`` nodes
    after it, so it never goes back. A time-indexed policy that lags the reference acts for a
    later phase of it; a state-indexed one acts for the phase it is in, so its action is a
    function of the state and of the last step only. ``last_step`` is the last call's step.
    """

    has_brake: bool
    torque_bound: float
    compute_times: list[float]
    node_states: FloatArray
    node_weight: FloatArray
    index_window: int = 0
    last_step: int = 0

    def predicted_q(self, step: int) -> FloatArray:
        """(n,) the q expected at env step ``step`` (angles unwrapped near it)."""
        raise NotImplementedError

    def control(self, step: int, q: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(torques (m,) [N m], brake bounds (k,)) at env step ``step`` in the state (q, u)."""
        raise NotImplementedError

    def applied(self, action: FloatArray) -> None:
        """Note that ``action`` was played after the last call instead of this policy's own.

        ``action``: the env action played, its first m entries the torques over
        ``torque_bound`` (the brake entries are not read). A policy whose state follows the
        applied torques overrides it (``TrackingMPC``'s friction estimate); here nothing to note.
        """

    def reference_interval(self, step: int) -> int:
        """The reference's interval that the call at ``step`` acts for (``step`` itself here)."""
        return step

    def is_state_indexed(self) -> bool:
        """Whether this call's step is the state's ``nearest_node`` (else the call count)."""
        return bool(self.index_window)

    def nearest_node(self, q: FloatArray, u: FloatArray, first: int) -> int:
        """The node k in ``first`` ... ``first + index_window`` nearest (q, u).

        Distance: sum_i node_weight_i (x_i - node_states[k, i])^2; the first node on a tie.
        """
        stop = min(first + self.index_window + 1, len(self.node_states))
        error = self.node_states[first:stop] - np.concatenate([q, u])
        return first + int(np.argmin(np.square(error) @ self.node_weight))

    def __call__(self, observation: FloatArray) -> FloatArray:
        """The env action for an observation of the reference's env."""
        clock = time.process_time()
        step = len(self.compute_times)
        state_indexed = self.is_state_indexed()
        if state_indexed:
            step = self.last_step if step else 0
        q, u = decode_observation(observation, self.predicted_q(step), self.has_brake)
        if state_indexed:
            step = self.nearest_node(q, u, step)
        self.last_step = step
        tau, brake = self.control(step, q, u)
        action = [tau / self.torque_bound]
        if self.has_brake:
            action.append(np.where(brake > 0.0, 1.0, -1.0))
        self.compute_times.append(time.process_time() - clock)
        return np.concatenate(action).astype(np.float32)


__all__ = ["StateFeedbackPolicy", "decode_observation"]
