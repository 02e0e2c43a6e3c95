"""Verification by replay: a reference's controls run open loop through the simulator.

The inputs tau_k and brake commands of each interval are held (zero-order hold) and fed to
``MoreauJeanStepper`` -- the engine the environments step -- at the reference's own time step h
and again at h/10 (each control held for 10 substeps). Reported: the final-state error against
the reference's last grid point, and whether the replayed end state meets the maneuver's success
tolerances (``mdi_envs.maneuvers``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.angles import wrap_angle
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER, MANIPULATOR_MANEUVER
from mdi_envs.stepping import MoreauJeanStepper
from optimal.problems import make_problem, model_of
from optimal.references import Reference


@dataclass(frozen=True)
class ReplayReport:
    """One open-loop replay.

    Attributes:
        substeps: simulator steps per reference interval (1 or 10).
        time_step: the simulator's dt [s].
        state_error: max |(q, u)_replay(t_f) - (q, u)_reference(t_f)| [rad, m, rad/s, m/s].
        goal_errors: the maneuver's error measures at the replayed end state (see ``goal_errors``).
        reaches_goal: every goal error within the maneuver's tolerance.
    """

    substeps: int
    time_step: float
    state_error: float
    goal_errors: dict[str, float]
    reaches_goal: bool

    def as_dict(self) -> dict[str, object]:
        """Plain-JSON form."""
        return asdict(self)


def goal_errors(name: str, q: FloatArray, u: FloatArray) -> tuple[dict[str, float], bool]:
    """The maneuver's error measures at the end state (q, u), and whether all are in tolerance.

    Manipulator: wrapped angle errors [rad] and angular speeds [rad/s]. Robot: position error
    [m], wrapped heading error [rad], chassis speed [m/s], yaw rate [rad/s]. Other problems:
    the distance to their imposed goal coordinates and velocities, tolerance 1e-6.
    """
    if name.startswith("manipulator"):
        maneuver = MANIPULATOR_MANEUVER
        angle = max(abs(wrap_angle(float(q[i] - maneuver.goal_q[i]))) for i in range(2))
        speed = float(np.max(np.abs(u)))
        errors = {"angle": angle, "angular_speed": speed}
        return errors, angle <= maneuver.angle_tolerance and speed <= maneuver.velocity_tolerance
    if name.startswith("diff_drive"):
        robot = DIFF_DRIVE_MANEUVER
        errors = {
            "position": float(np.hypot(q[0] - robot.goal_pose[0], q[1] - robot.goal_pose[1])),
            "heading": abs(wrap_angle(float(q[2] - robot.goal_pose[2]))),
            "speed": float(np.hypot(u[0], u[1])),
            "yaw_rate": abs(float(u[2])),
        }
        ok = (errors["position"] <= robot.position_tolerance
              and errors["heading"] <= robot.heading_tolerance
              and errors["speed"] <= robot.speed_tolerance
              and errors["yaw_rate"] <= robot.yaw_rate_tolerance)
        return errors, ok
    problem = make_problem(name)
    error = max([abs(float(q[i]) - v) for i, v in problem.goal_q.items()]
                + [abs(float(u[i]) - v) for i, v in problem.goal_u.items()])
    return {"goal": error}, error <= 1e-6


def replay(
    reference: Reference, substeps: int = 1
) -> tuple[ReplayReport, FloatArray, FloatArray, np.ndarray]:
    """Run the reference's controls open loop, ``substeps`` simulator steps per interval.

    Returns:
        (report, q (N*substeps+1, n), u (same), modes (N*substeps,) of the simulator's steps).
    """
    model, parameters = model_of(make_problem(reference.name))
    stepper = MoreauJeanStepper(model, parameters, reference.time_step / substeps)
    tau, brake = reference.tau, reference.brake_bound
    num_intervals = tau.shape[0]
    q, u = reference.q[0].copy(), reference.u[0].copy()
    qs, us, modes = [q], [u], []
    for k in range(num_intervals):
        for _ in range(substeps):
            result = stepper.step(q, u, tau[k], None if brake is None else brake[k])
            q, u = result.q, result.u
            qs.append(q)
            us.append(u)
            modes.append(result.mode)
    error = float(max(np.max(np.abs(q - reference.q[-1])), np.max(np.abs(u - reference.u[-1]))))
    errors, ok = goal_errors(reference.name, q, u)
    report = ReplayReport(substeps, stepper.time_step, error, errors, ok)
    return report, np.array(qs), np.array(us), np.array(modes, dtype=np.int64)


def env_actions(reference: Reference) -> FloatArray:
    """The reference's controls as the env's default normalised Box actions, (N, a).

    Torques are divided by the reference's torque bound; a brake (if the model has one) becomes
    +1 (engaged, ideal) where its bound is positive and -1 (released) elsewhere.
    """
    actions = [reference.tau / reference.metadata["torque_bound"]]
    if reference.brake_bound is not None and reference.brake_bound.shape[1]:
        actions.append(np.where(reference.brake_bound > 0.0, 1.0, -1.0))
    return np.hstack(actions).astype(np.float32)


def env_options(reference: Reference) -> dict[str, Any]:
    """``gym.make`` keyword arguments under which one env step is one reference interval.

    time_step = h, frame_skip = 1, no start noise, the reference's torque bound, an episode
    limit of N steps, plus the metadata's ``env_kwargs`` (e.g. ``objective="effort"``).
    """
    meta = reference.metadata
    has_brake = reference.brake_bound is not None and reference.brake_bound.shape[1]
    bound_name = "max_torque" if has_brake else "max_wheel_torque"
    options: dict[str, Any] = {"time_step": reference.time_step, "frame_skip": 1,
                               "reset_noise_scale": 0.0, bound_name: meta["torque_bound"],
                               "max_episode_steps": len(reference.tau)}
    options.update(meta.get("env_kwargs", {}))
    return options


def replay_in_env(reference: Reference) -> tuple[FloatArray, dict[str, Any]]:
    """Run the controls open loop through ``gym.make(env_id)`` at the reference's time step.

    The env gets ``time_step = h``, ``frame_skip = 1``, no start noise and the reference's
    torque bound, so each env step is one step of the transcription. Returns the final
    coordinates (n,) and the last step's ``info`` (``is_success``, ``elapsed_time``, ...).
    """
    import gymnasium as gym

    import mdi_envs  # noqa: F401 - registers the ids

    env = gym.make(reference.metadata["env_id"], **env_options(reference))
    env.reset(seed=0)
    info: dict[str, Any] = {}
    for action in env_actions(reference):
        _, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break
    model: Any = env.unwrapped  # a MoreauJeanEnv
    return model.q, info


__all__ = ["ReplayReport", "env_actions", "env_options", "goal_errors", "replay", "replay_in_env"]
