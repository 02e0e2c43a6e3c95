"""Time-varying LQR along a reference, within its mode pattern: the cheapest model-based row.

The simulator's step x_{k+1} = f(x_k, tau_k; brake_k), x = (q, u), is linearized around the
reference's grid points (x_k, tau_k) with its brake commands held (``linearize``: central
differences of ``MoreauJeanStepper.step``, so the contact modes are the stepper's own around
the reference: the robot's stick-slip pattern is the reference's). A backward Riccati
recursion on the deviations dx_k = x - x_k, dtau_k = tau - tau_k with weights from the
maneuver's success tolerances (Bryson's rule: each state error counts one unit at its
tolerance, each torque at its bound) gives gains K_k, and the control at step k is

    tau = clip(tau_k - K_k dx_k, -tau_max, tau_max),   brake = the reference's command at k.

Past the reference's last interval the controller holds the goal: the gain of the same
recursion run ``HOLD_STEPS`` steps back from the goal at rest with zero torque and the last
brake command. Gains and linearization are computed once per controller (``TimeVaryingLQR``);
a control step is one matrix-vector product.
"""

from __future__ import annotations

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER, MANIPULATOR_MANEUVER
from mdi_envs.stepping import MoreauJeanStepper
from optimal.observations import StateFeedbackPolicy
from optimal.problems import make_problem, model_of
from optimal.references import Reference

DIFFERENCE_STEP = 1e-6
"""Relative step of the central differences of ``linearize`` (times max(1, |x_i|))."""

INPUT_WEIGHT = 1.0
"""R = this / tau_max^2 per input (Bryson's rule at weight 1)."""

TERMINAL_WEIGHT = 100.0
"""The terminal cost: this times the running state weight Q at the reference's last point."""

HOLD_STEPS = 200
"""Steps of the Riccati recursion behind the gain that holds the goal after the reference."""


def linearize(stepper: MoreauJeanStepper, q: FloatArray, u: FloatArray, tau: FloatArray,
              brake: FloatArray | None) -> tuple[FloatArray, FloatArray]:
    """(A (2n, 2n), B (2n, m)): the step's Jacobians at (q, u, tau) with the brakes ``brake``.

    Central differences, step ``DIFFERENCE_STEP`` relative; the spatial contact solver is
    warm-started from the nominal step's impulses so every difference picks the same split.
    """
    n = q.size
    nominal = stepper.step(q, u, tau, brake)
    warm = nominal.impulses

    def state(x: FloatArray, torque: FloatArray) -> FloatArray:
        result = stepper.step(x[:n], x[n:], torque, brake, warm)
        return np.concatenate([result.q, result.u])

    x = np.concatenate([q, u])
    columns = []
    for point, other, is_state in ((x, tau, True), (tau, x, False)):
        jacobian = []
        for i in range(point.size):
            delta = DIFFERENCE_STEP * max(1.0, abs(float(point[i])))
            plus, minus = point.copy(), point.copy()
            plus[i] += delta
            minus[i] -= delta
            if is_state:
                forward, backward = state(plus, other), state(minus, other)
            else:
                forward, backward = state(other, plus), state(other, minus)
            jacobian.append((forward - backward) / (2.0 * delta))
        columns.append(np.array(jacobian).T)
    return columns[0], columns[1]


def riccati(A: FloatArray, B: FloatArray, Q: FloatArray, R: FloatArray,
            terminal: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Gains and cost-to-go of the finite-horizon discrete LQR.

    Args:
        A: (N, nx, nx). B: (N, nx, m). Q: (nx, nx) running state weight. R: (m, m).
        terminal: (nx, nx) the weight of the last state.

    Returns:
        (K (N, m, nx), P (N+1, nx, nx)): u_k = -K_k x_k minimizes
        sum_k (x_k' Q x_k + u_k' R u_k) + x_N' terminal x_N; P_k is the cost-to-go at k.
    """
    steps = A.shape[0]
    P = np.empty((steps + 1, *Q.shape))
    K = np.empty((steps, B.shape[2], Q.shape[0]))
    P[steps] = terminal
    for k in range(steps - 1, -1, -1):
        a, b, p = A[k], B[k], P[k + 1]
        K[k] = np.linalg.solve(R + b.T @ p @ b, b.T @ p @ a)
        closed = a - b @ K[k]
        P[k] = Q + K[k].T @ R @ K[k] + closed.T @ p @ closed
        P[k] = 0.5 * (P[k] + P[k].T)
    return K, P


def state_weight(reference: Reference) -> FloatArray:
    """(2n, 2n) diagonal Q: 1 / tolerance^2 per state of the maneuver's success box.

    Manipulator: angles and angular speeds. Robot: x, y (position tolerance), heading, chassis
    velocity (speed tolerance), yaw rate; its wheel angles weigh nothing (no dynamics depend
    on them), its wheel speeds as the chassis speed over the wheel radius.
    """
    problem = make_problem(reference.name)
    _, parameters = model_of(problem)
    if problem.model.NUM_BRAKES:
        maneuver = MANIPULATOR_MANEUVER
        scales = [maneuver.angle_tolerance] * 2 + [maneuver.velocity_tolerance] * 2
        return np.diag(1.0 / np.square(scales))
    robot = DIFF_DRIVE_MANEUVER
    wheel_speed = robot.speed_tolerance / parameters.wheel_radius
    weights = np.array([robot.position_tolerance**-2] * 2 + [robot.heading_tolerance**-2, 0.0, 0.0]
                       + [robot.speed_tolerance**-2] * 2 + [robot.yaw_rate_tolerance**-2]
                       + [wheel_speed**-2] * 2)
    return np.diag(weights)


class TimeVaryingLQR(StateFeedbackPolicy):
    """The time-varying LQR along ``reference`` (see the module docstring).

    Args:
        reference: the reference tracked; its grid step h must be the env's dt.
        input_weight: see ``INPUT_WEIGHT``. terminal_weight: see ``TERMINAL_WEIGHT``.

    Attributes:
        gains: (N, m, 2n) K_k. hold_gain: (m, 2n) the gain past the reference.
        cost_to_go: (N+1, 2n, 2n) P_k. hold_cost_to_go: (2n, 2n) P past the reference.
        state_weight: (2n, 2n) Q. input_weight: (m, m) R.
        node_states: (N+1, 2n) the reference's states; node_weight: (2n,) the diagonal of Q
            (``StateFeedbackPolicy``).
        compute_times: CPU time [s] of each control step of this episode.
    """

    def __init__(self, reference: Reference, input_weight: float = INPUT_WEIGHT,
                 terminal_weight: float = TERMINAL_WEIGHT) -> None:
        problem = make_problem(reference.name)
        model, parameters = model_of(problem)
        self.reference = reference
        self.has_brake = bool(model.NUM_BRAKES)
        self.torque_bound = float(reference.metadata["torque_bound"])
        stepper = MoreauJeanStepper(model, parameters, reference.time_step)
        self._x = np.hstack([reference.q, reference.u]).astype(float)
        self._tau = np.asarray(reference.tau, dtype=float)
        steps = len(self._tau)
        self._brake = (np.asarray(reference.brake_bound, dtype=float) if self.has_brake
                       else np.zeros((steps, 0)))
        brakes = [self._brake[k] if self.has_brake else None for k in range(steps)]
        pairs = [linearize(stepper, reference.q[k], reference.u[k], self._tau[k], brakes[k])
                 for k in range(steps)]
        A, B = np.array([a for a, _ in pairs]), np.array([b for _, b in pairs])
        Q = state_weight(reference)
        R = input_weight / self.torque_bound**2 * np.eye(model.NUM_INPUTS)
        self.gains, self.cost_to_go = riccati(A, B, Q, R, terminal_weight * Q)
        rest = np.zeros(model.NUM_INPUTS)
        a, b = linearize(stepper, reference.q[-1], np.zeros(model.NUM_DOFS), rest, brakes[-1])
        hold, hold_cost = riccati(np.repeat(a[None], HOLD_STEPS, 0),
                                  np.repeat(b[None], HOLD_STEPS, 0), Q, R, terminal_weight * Q)
        self.hold_gain, self.hold_cost_to_go = hold[0], hold_cost[0]
        self.state_weight, self.input_weight = Q, R
        self.node_states, self.node_weight = self._x, np.diag(Q).copy()
        self._goal = np.concatenate([reference.q[-1], np.zeros(model.NUM_DOFS)])
        self.compute_times: list[float] = []

    def reset(self) -> None:
        """A new episode: the step counter and the compute records start again."""
        self.compute_times = []

    def predicted_q(self, step: int) -> FloatArray:
        """(n,) the reference's q at env step ``step`` (its last past the end)."""
        return self.reference.q[min(step, len(self._tau))]

    def control(self, step: int, q: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(torques (m,) [N m], brake bounds (k,)) at env step ``step`` in the state (q, u)."""
        x = np.concatenate([q, u])
        if step < len(self._tau):
            tau = self._tau[step] - self.gains[step] @ (x - self._x[step])
            brake = self._brake[step]
        else:
            tau = -self.hold_gain @ (x - self._goal)
            brake = self._brake[-1]
        return np.clip(tau, -self.torque_bound, self.torque_bound), brake


__all__ = ["DIFFERENCE_STEP", "HOLD_STEPS", "INPUT_WEIGHT", "TERMINAL_WEIGHT", "TimeVaryingLQR",
           "linearize", "riccati", "state_weight"]
