"""Heuristic floors: simple controllers every reader understands, beside the learned ones.

* Manipulator, ``rigid_arm_bang_bang``: the brake held engaged from the first step, so the two
  links turn as one rigid body of inertia I(d) = (1, 1) M (1, 1)^T about the base (d the
  locked relative angle), driven by the time-optimal bang-bang feedback of a double
  integrator with acceleration A = max_torque / I: full torque until the switching curve
  e + w |w| / (2 A) = 0, then full reverse torque (linear within ``band`` of the curve, so that
  the discrete-time control does not chatter). The target angle pi - d / 2 puts both links
  equally close to pi. Free of tuning except the band.
* Robot, ``rolling_path_follower``: a path that never asks for more than the rolling traction:
  a cubic Bezier curve for the driven axle's midpoint from the start pose to the goal pose,
  with the fastest speed profile within an acceleration budget ``max_acceleration`` (the
  tangential and centripetal accelerations inside one circle, an ellipse's worth of the
  friction limit) or, for the effort objective, that profile slowed uniformly to end ``margin``
  before the fixed horizon. A tracking law (Kanayama et al. 1990) turns the pose error into
  speed and yaw-rate commands, a velocity loop with acceleration feedforward into wheel
  torques, clipped to ``max_wheel_torque`` (below the traction limit: no slip when it holds).
  ``path_follower`` is that law along any path; ``parking_follower`` along one segment from the
  robot's pose into the goal, forward or in reverse (``baselines.model_based.Recovering``).

``heuristic_controller(env_id, objective)`` returns the floor of a mission env as a comparison
``Controller``; ``python -m baselines.heuristics`` plays each from the nominal start and from
``NUM_STARTS`` starts perturbed at 0.01 and at 0.1 and writes ``baselines/heuristics.json``:
success rates and, over the successes, the time and effort ratios to the optimal reference.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from mdi_envs.angles import wrap_angle
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER, MANIPULATOR_MANEUVER
from mdi_envs.rollout import Policy

OUTPUT = Path(__file__).parent / "heuristics.json"
"""The committed evaluation of the floors."""

NUM_STARTS = 20
"""Perturbed starts per start-noise scale (reset seeds 0 ... NUM_STARTS - 1)."""

SCALES = (0.01, 0.1)
"""The start-noise scales played (``reset_noise_scale``)."""


# -- manipulator ---------------------------------------------------------------------------
def rigid_arm_bang_bang(env: gym.Env[Any, Any], band: float = 0.01) -> Policy:
    """The rigid-arm bang-bang policy (module docstring) for the manipulator ``env``.

    Args:
        env: a ``BlockableManipulator`` env (its parameters and torque bound are read).
        band: half-width [rad] of the linear zone around the switching curve.
    """
    scene = env.unwrapped.scene
    p = scene.parameters
    base = p.link1_mass * p.link1_length**2 / 3 + p.link2_mass * p.link1_length**2 \
        + p.link2_mass * p.link2_length**2 / 3
    coupling = p.link2_mass * p.link1_length * p.link2_length  # 2 c of the mass matrix
    goal_alpha, goal_beta = MANIPULATOR_MANEUVER.goal_q
    max_torque = scene.max_torque

    def policy(obs: Any) -> Any:
        alpha, beta = math.atan2(obs[1], obs[0]), math.atan2(obs[3], obs[2])
        d = wrap_angle(beta - alpha)
        error = wrap_angle(alpha - (goal_alpha + goal_beta - d) / 2)
        rate = 0.5 * (float(obs[4]) + float(obs[5]))
        acceleration = max_torque / (base + coupling * math.cos(d))
        switching = error + rate * abs(rate) / (2.0 * acceleration)
        return np.array([np.clip(-switching / band, -1.0, 1.0), 1.0], np.float32)

    return policy


# -- robot ---------------------------------------------------------------------------------
def bezier_path(poses: Sequence[Sequence[float]], handles: Sequence[float],
                num_points: int = 1001) -> tuple[np.ndarray, ...]:  # fmt: skip
    """Cubic Bezier segments through ``poses`` (x [m], y [m], heading [rad]), sampled.

    Segment i runs from ``poses[i]`` to ``poses[i + 1]`` with its inner control points
    ``handles[i]`` [m] along the first pose's heading and behind the second's (a semicircle
    of radius R: handles 4 R / 3). Returns (s (P,) arc length [m], xy (P, 2), heading (P,)
    [rad], signed curvature (P,) [1/m]).
    """
    t = np.linspace(0.0, 1.0, num_points)[:, None]
    points, first, second = [], [], []
    for k, handle in enumerate(handles):
        a, b = poses[k], poses[k + 1]
        p0, p3 = np.array(a[:2], float), np.array(b[:2], float)
        p1 = p0 + handle * np.array([math.cos(a[2]), math.sin(a[2])])
        p2 = p3 - handle * np.array([math.cos(b[2]), math.sin(b[2])])
        cut = slice(1 if k else 0, None)  # each joint once
        points.append(((1 - t) ** 3 * p0 + 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t**2 * p2
                       + t**3 * p3)[cut])
        first.append((3 * (1 - t) ** 2 * (p1 - p0) + 6 * (1 - t) * t * (p2 - p1)
                      + 3 * t**2 * (p3 - p2))[cut])
        second.append((6 * (1 - t) * (p2 - 2 * p1 + p0) + 6 * t * (p3 - 2 * p2 + p1))[cut])
    xy, d1, d2 = np.concatenate(points), np.concatenate(first), np.concatenate(second)
    speed = np.hypot(d1[:, 0], d1[:, 1])
    curvature = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed**3
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])
    return s, xy, np.unwrap(np.arctan2(d1[:, 1], d1[:, 0])), curvature


def speed_profile(s: np.ndarray, curvature: np.ndarray, max_acceleration: float,
                  max_speed: float) -> np.ndarray:  # fmt: skip
    """The fastest speeds (P,) [m/s] along the path (arc lengths ``s``), from rest to rest.

    The tangential and centripetal accelerations stay inside the circle of radius
    ``max_acceleration`` [m/s^2]; the speed stays below ``max_speed``.
    """
    k = np.maximum(np.abs(curvature), 1e-9)
    v = np.minimum(max_speed, np.sqrt(max_acceleration / k))
    v[0] = v[-1] = 0.0
    ds = np.diff(s)

    def tangential(i: int, speed: float) -> float:
        return math.sqrt(max(max_acceleration**2 - (speed * speed * k[i]) ** 2, 0.0))

    for i in range(len(s) - 1):  # accelerate forward, then brake backward
        v[i + 1] = min(v[i + 1], math.sqrt(v[i] ** 2 + 2 * tangential(i, v[i]) * ds[i]))
    for i in range(len(s) - 2, -1, -1):
        v[i] = min(v[i], math.sqrt(v[i + 1] ** 2 + 2 * tangential(i + 1, v[i + 1]) * ds[i]))
    return v


def rolling_path_follower(env: gym.Env[Any, Any], final_time: float | None = None,
                          via: tuple[float, float] = (0.9, 2.5), handle: float = 0.8,
                          approach: float = 0.5, **limits: float) -> Policy:  # fmt: skip
    """The rolling path follower (module docstring) for the diff-drive ``env``.

    Args:
        env: a ``DiffDriveRobot`` env (its parameters and ``dt`` are read).
        final_time: the fixed horizon [s] of the effort objective (None: as fast as the profile).
        via: (x, y) [m] where the axle, after the start's left turn, heads straight up (+y)
            to the right half-turn (radius (goal x - via x) / 2) that ends ``approach`` [m]
            above the goal, from where it heads straight down into the goal.
        handle: [m] the first segment's Bezier handles.
        limits: ``path_follower``'s speed, acceleration and torque limits.
    """
    unwrapped = env.unwrapped
    a = unwrapped.scene.parameters.axle_offset
    x0, y0, phi0 = DIFF_DRIVE_MANEUVER.initial_pose
    start = (x0 - a * math.cos(phi0), y0 - a * math.sin(phi0), phi0)
    gx, gy, gphi = DIFF_DRIVE_MANEUVER.goal_pose
    goal = (gx - a * math.cos(gphi), gy - a * math.sin(gphi), gphi)
    radius = (goal[0] - via[0]) / 2
    top = goal[1] + approach  # the half-turn ends this far above the goal, heading down
    poses = [start, (*via, math.pi / 2), (via[0], top, math.pi / 2), (goal[0], top, -math.pi / 2),
             goal]
    return path_follower(unwrapped.scene.parameters, unwrapped.dt, unwrapped.scene.max_wheel_torque,
                         poses, [handle, (top - via[1]) / 3, 4 * radius / 3, approach / 3],
                         final_time, **limits)


PARKING_LIMITS = {"max_acceleration": 1.2, "max_wheel_torque": 1.5, "max_lag": 0.1}
"""``parking_follower``'s acceleration and torque limits [m/s^2, N m], within the rolling
traction of a robot with 20 % less friction than the default (1.76 N m per wheel), and the lag
[m] at which its path's clock stops (``path_follower``)."""


def parking_follower(parameters: Any, dt: float, action_torque: float, observation: Any,
                     **limits: float) -> Policy:
    """A rolling path from the robot's pose in ``observation`` into the goal pose, at rest.

    One Bezier segment (handles a third of the distance) for the driven axle's midpoint,
    driven forward if the goal lies ahead of the axle, in reverse if behind; followed by
    ``path_follower`` (the model ``parameters``, env step ``dt`` [s], ``action_torque`` [N m]
    the env's action scale, ``limits`` over ``PARKING_LIMITS``) from the call on. For a robot
    at rest near the goal: the recovery of a controller whose plan ended outside the goal box.
    """
    a = parameters.axle_offset
    gx, gy, gphi = DIFF_DRIVE_MANEUVER.goal_pose
    phi = math.atan2(observation[3], observation[2]) + gphi
    x = float(observation[0]) + gx - a * math.cos(phi)
    y = float(observation[1]) + gy - a * math.sin(phi)
    goal = (gx - a * math.cos(gphi), gy - a * math.sin(gphi))
    dx, dy = goal[0] - x, goal[1] - y
    reverse = dx * math.cos(phi) + dy * math.sin(phi) < 0.0
    turn = math.pi if reverse else 0.0  # the driving direction's heading
    poses = [(x, y, phi + turn), (*goal, gphi + turn)]
    handle = max(math.hypot(dx, dy) / 3, 1e-3)
    return path_follower(parameters, dt, action_torque, poses, [handle], reverse=reverse,
                         **{**PARKING_LIMITS, **limits})


def path_follower(parameters: Any, dt: float, action_torque: float,
                  poses: Sequence[Sequence[float]], handles: Sequence[float],
                  final_time: float | None = None, reverse: bool = False,
                  max_acceleration: float = 1.5, max_speed: float = 4.0,
                  max_wheel_torque: float = 2.0, margin: float = 0.1,
                  max_lag: float | None = None) -> Policy:  # fmt: skip
    """The tracking law of the module docstring along ``bezier_path(poses, handles)``.

    Args:
        parameters: the robot model's ``DiffDriveParameters`` the torques are computed with.
        dt: env step [s] (the path's clock starts at the policy's first call).
        action_torque: [N m] the env's wheel torque bound (the action's scale).
        poses, handles: the axle midpoint's path (``bezier_path``), headings in the driving
            direction. final_time: the fixed horizon [s] of the effort objective (None: as
            fast as the profile). reverse: driven backwards (headings opposite the chassis').
        max_acceleration: [m/s^2] of the axle point, tangential and centripetal together.
        max_speed: [m/s]. max_wheel_torque: [N m] the clip, below the ~2.2 N m rolling
            traction limit of the default robot. margin: [s] the path ends this long before
            ``final_time`` (if it can; otherwise the profile is kept as it is).
        max_lag: [m] with it, the path's clock slows as the axle falls behind its point along
            the path and stops at this lag (None: the clock is the env's). Under more mass or
            less grip than ``parameters`` the heading then waits for the position, which
            otherwise turns on time while the robot lags and ends the path off to its side.
    """
    p = parameters
    a = p.axle_offset
    gphi = DIFF_DRIVE_MANEUVER.goal_pose[2]
    gx, gy = DIFF_DRIVE_MANEUVER.goal_pose[:2]
    s, xy, heading, curvature = bezier_path(poses, handles)
    v = speed_profile(s, curvature, max_acceleration, max_speed)
    # time along the path: trapezoidal integration of ds / v (v > 0 inside)
    mean_v = np.maximum(0.5 * (v[1:] + v[:-1]), 1e-9)
    t = np.concatenate([[0.0], np.cumsum(np.diff(s) / mean_v)])
    if final_time is not None and t[-1] < final_time - margin:
        scale = (final_time - margin) / t[-1]
        t, v = t * scale, v / scale
    accel = np.gradient(v, t)
    mass = p.mass + 2 * p.wheel_inertia / p.wheel_radius**2  # forward, at the axle point
    inertia = p.yaw_inertia + p.mass * a**2 + 2 * p.wheel_inertia * p.half_track**2 \
        / p.wheel_radius**2  # yaw, about the axle point
    stick_load = p.mass * p.gravity * a / (a + p.stick_offset)
    drag = p.stick_friction * stick_load  # [N] the skid's friction while moving
    direction = -1.0 if reverse else 1.0
    lever = direction * (a + p.stick_offset)  # the skid ahead of the axle, driving frame
    k_x, k_y, k_phi, k_v, k_w = 2.0, 4.0, 4.0, 6.0, 8.0
    clock = [0.0]  # [s] along the path's profile

    def policy(obs: Any) -> Any:
        now = clock[0]
        chassis = math.atan2(obs[3], obs[2]) + gphi
        phi = chassis + (math.pi if reverse else 0.0)
        x = float(obs[0]) + gx - a * math.cos(chassis)
        y = float(obs[1]) + gy - a * math.sin(chassis)
        forward, yaw_rate = direction * float(obs[4]), float(obs[6])
        ref_x, ref_y = np.interp(now, t, xy[:, 0]), np.interp(now, t, xy[:, 1])
        ref_phi = float(np.interp(now, t, heading))
        ref_v = float(np.interp(now, t, v, right=0.0))  # at rest at the goal after the path
        ref_a = float(np.interp(now, t, accel, right=0.0))
        ref_k = float(np.interp(now, t, curvature))
        c, s_ = math.cos(phi), math.sin(phi)
        e_x = c * (ref_x - x) + s_ * (ref_y - y)  # pose error in the driving frame
        e_y = -s_ * (ref_x - x) + c * (ref_y - y)
        e_phi = wrap_angle(ref_phi - phi)
        rate = 1.0 if max_lag is None else min(max(1.0 - e_x / max_lag, 0.0), 1.0)
        clock[0] += rate * dt
        v_cmd = ref_v * math.cos(e_phi) + k_x * e_x
        w_cmd = ref_v * ref_k + ref_v * k_y * e_y + k_phi * math.sin(e_phi)
        # the skid's Coulomb friction, along its commanded sliding velocity (driving frame),
        # compensated: forward force and yaw moment about the axle
        slide_x, slide_y = v_cmd, w_cmd * lever
        norm = math.sqrt(slide_x * slide_x + slide_y * slide_y + 0.05**2)
        force = direction * (mass * (ref_a + k_v * (v_cmd - forward)) + drag * slide_x / norm)
        torque = inertia * (ref_k * ref_a + k_w * (w_cmd - yaw_rate)) \
            + drag * lever * slide_y / norm
        r, b = p.wheel_radius, p.half_track
        wheels = np.array([force * r / 2 - torque * r / (2 * b),
                           force * r / 2 + torque * r / (2 * b)])  # fmt: skip
        peak = np.abs(wheels).max()
        if peak > max_wheel_torque:
            wheels *= max_wheel_torque / peak
        return (wheels / action_torque).astype(np.float32)

    return policy


# -- comparison rows -----------------------------------------------------------------------
BANG_BANG = "rigid-arm bang-bang"
FOLLOWER = "rolling path follower"


def heuristic_controller(env_id: str, objective: str) -> Any:
    """The floor of (env id, objective) as a ``baselines.evaluation.Controller``, else None.

    A ``ControllerFactory`` (registered in ``baselines.evaluation.CONTROLLER_FACTORIES``): any
    version of the manipulator and of the robot (the floors read only the dynamics, which the
    versions share); the robot's effort floor aims to end before the fixed horizon.
    """
    from baselines.evaluation import Controller

    name = env_id.split("/")[-1]
    if name.startswith("BlockableManipulator") and objective == "time":
        return Controller(BANG_BANG, rigid_arm_bang_bang)
    if name.startswith("DiffDriveRobot") and objective == "effort":
        horizon = DIFF_DRIVE_MANEUVER.effort_final_time
        return Controller(FOLLOWER, lambda env: rolling_path_follower(env, horizon),
                          {"objective": "effort"})  # fmt: skip
    if name.startswith("DiffDriveRobot"):
        return Controller(FOLLOWER, rolling_path_follower, {"objective": "time"})
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m baselines.heuristics [--output PATH] [--starts N]``: evaluate every floor.

    Plays the floors of every (env id, objective) of ``baselines.evaluation.REFERENCE_NAMES``
    from the nominal start and from ``--starts`` starts perturbed at each of ``SCALES``, and
    writes the studies (``baselines.records``; trajectories of the nominal episodes only) as
    one JSON list.
    """
    from baselines.evaluation import REFERENCE_NAMES, evaluate
    from baselines.records import Condition, to_json

    parser = argparse.ArgumentParser(prog="python -m baselines.heuristics",
                                     description=__doc__.split("\n")[0])  # fmt: skip
    parser.add_argument("--output", type=Path, default=OUTPUT)
    parser.add_argument("--starts", type=int, default=NUM_STARTS)
    args = parser.parse_args(argv)
    studies = []
    for env_id, objective in REFERENCE_NAMES:
        label = heuristic_controller(env_id, objective).label
        study = evaluate(env_id, objective, [Condition(scale) for scale in SCALES], args.starts,
                         only=[label], nominal=True)  # fmt: skip
        record = to_json(study)
        for run in record["rows"][0]["runs"]:  # keep the nominal trajectories only
            for perturbed in run["episodes"]:
                perturbed["trajectory"] = None
        studies.append(record)
        for run in study.rows[0].runs:
            nominal, scores = run.nominal, run.scores
            print(f"{env_id} {objective} {label}, {run.condition.label}: success "
                  f"{scores.success_rate:.2f}, time ratio {scores.time_ratio}, effort ratio "
                  f"{scores.effort_ratio}; nominal: success {nominal.is_success}, "
                  f"{nominal.elapsed_time:.2f} s, effort {nominal.effort:.2f}")
    args.output.write_text(json.dumps(studies, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


__all__ = [
    "BANG_BANG", "FOLLOWER", "PARKING_LIMITS", "bezier_path", "heuristic_controller", "main",
    "parking_follower", "path_follower", "rigid_arm_bang_bang", "rolling_path_follower",
    "speed_profile",
]
