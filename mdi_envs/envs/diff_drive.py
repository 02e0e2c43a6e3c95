"""``mdi_envs/DiffDriveRobot-v1`` and ``mdi_envs/DiffDriveRobotEffort-v1`` (and
``DiffDriveRobot-v0``): the paper's three-wheeled robot driven by two wheel torques over
stick-slip ground contacts, to a goal pose fastest ("time") or with least effort ("effort").
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from gymnasium import spaces

from mdi_envs._types import FloatArray
from mdi_envs.angles import cos_sin, wrap_angle
from mdi_envs.envs._actions import TorqueBrakeActions
from mdi_envs.envs.base import MoreauJeanEnv, MoreauJeanScene, MoreauJeanVectorEnv
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER
from mdi_envs.mechanics.models.diff_drive import DiffDriveRobot
from mdi_envs.mechanics.parameters import require_positive
from mdi_envs.stepping._spatial_kernel import INFO_LIFTED_CONTACTS, INFO_MODE, INFO_RESIDUAL

HEADING_WEIGHT = 0.5  # [m/rad] weight of the heading error in the goal distance
VELOCITY_WEIGHT = 0.5  # [s] weight of the chassis speed in the goal distance
YAW_RATE_WEIGHT = 0.25  # [m s/rad] weight of the yaw rate in the goal distance
SLIDING_SPEED = 1e-4  # [m/s] a contact is drawn as sliding above this slip speed


class DiffDriveRobotConstants(NamedTuple):
    """What the compiled scene functions read (``c``).

    Attributes:
        goal_x, goal_y, goal_phi: the goal pose [m], [m], [rad].
        position_tolerance, heading_tolerance, speed_tolerance, yaw_rate_tolerance: the
            success box [m], [rad], [m/s], [rad/s].
        heading_weight, velocity_weight, yaw_rate_weight: the weights of the goal distance
            [m/rad], [s], [m s/rad].
    """

    goal_x: float
    goal_y: float
    goal_phi: float
    position_tolerance: float
    heading_tolerance: float
    speed_tolerance: float
    yaw_rate_tolerance: float
    heading_weight: float
    velocity_weight: float
    yaw_rate_weight: float


class DiffDriveRobotScene(MoreauJeanScene):
    """Batched logic of the diff-drive environments (documented on the env class)."""

    MODEL = DiffDriveRobot
    NUM_OBSERVATIONS = 10
    CONSTANTS = DiffDriveRobotConstants
    OBJECTIVE_OPTIONS = ("time", "effort")
    INFO_KEYS = ("slip_mode", "num_lifted_contacts", "solver_residual", "normal_impulse_left",
                 "normal_impulse_right", "normal_impulse_stick")  # fmt: skip

    def __init__(
        self,
        *,
        objective: str = "time",
        max_wheel_torque: float = DIFF_DRIVE_MANEUVER.max_wheel_torque,
        time_step: float = 0.01,
        frame_skip: int = 5,
        reset_noise_scale: float = 0.01,
        **options: Any,
    ) -> None:
        super().__init__(time_step=time_step, frame_skip=frame_skip, objective=objective,
                         final_time=DIFF_DRIVE_MANEUVER.effort_final_time,
                         reset_noise_scale=reset_noise_scale, **options)  # fmt: skip
        self.max_wheel_torque = require_positive("max_wheel_torque", max_wheel_torque)
        # wheel torques tau_L, tau_R [N m] from the normalised Box action
        self.actions = TorqueBrakeActions("box", 2, False, self.max_wheel_torque)
        self.single_action_space = self.actions.space()
        high = np.full(self.NUM_OBSERVATIONS, np.inf, np.float32)
        high[2:4] = 1.0
        low = -high
        low[-1] = 0.0
        high[-1] = max(self.final_time, 1.0)  # time left; always 0 for "time"
        self.single_observation_space = spaces.Box(low, high, dtype=np.float32)

    START_NOISE_ENTRIES = (0, 1, 2, 5, 6, 7)  # x, y, phi, then their rates

    def nominal_start(self) -> FloatArray:
        """Rest at the origin heading +x (wheel angles 0)."""
        return np.concatenate([DIFF_DRIVE_MANEUVER.initial_pose, np.zeros(7)])

    def constants(self) -> DiffDriveRobotConstants:
        """The maneuver's goal pose and four tolerances, the three distance weights."""
        m = DIFF_DRIVE_MANEUVER
        return DiffDriveRobotConstants(*m.goal_pose, m.position_tolerance, m.heading_tolerance,
                                       m.speed_tolerance, m.yaw_rate_tolerance, HEADING_WEIGHT,
                                       VELOCITY_WEIGHT, YAW_RATE_WEIGHT)  # fmt: skip

    @staticmethod
    def observe_one(q: Any, u: Any, brake: Any, time_left: float, c: Any, out: Any) -> None:
        """Goal offset, heading error, body-frame velocity, yaw and wheel rates, time left."""
        heading_error = q[2] - c.goal_phi
        cos_phi, sin_phi = cos_sin(q[2])
        out[0] = q[0] - c.goal_x
        out[1] = q[1] - c.goal_y
        out[2], out[3] = cos_sin(heading_error)
        out[4] = cos_phi * u[0] + sin_phi * u[1]
        out[5] = -sin_phi * u[0] + cos_phi * u[1]
        out[6] = u[2]
        out[7] = u[3]
        out[8] = u[4]
        out[9] = time_left

    @staticmethod
    def distance_one(q: Any, u: Any, c: Any) -> float:
        """sqrt(|dp|^2 + (w_h e_phi)^2 + (w_v |v|)^2 + (w_r phi')^2), e_phi wrapped."""
        dx, dy = q[0] - c.goal_x, q[1] - c.goal_y
        e_phi = wrap_angle(q[2] - c.goal_phi)
        w_v = c.velocity_weight
        return math.sqrt(dx * dx + dy * dy + (c.heading_weight * e_phi) ** 2
                         + w_v * w_v * (u[0] * u[0] + u[1] * u[1])
                         + (c.yaw_rate_weight * u[2]) ** 2)

    @staticmethod
    def success_one(q: Any, u: Any, c: Any) -> bool:
        """Position, heading, speed and yaw rate within the maneuver's tolerances."""
        dx, dy = q[0] - c.goal_x, q[1] - c.goal_y
        e_phi = wrap_angle(q[2] - c.goal_phi)
        return (math.sqrt(dx * dx + dy * dy) <= c.position_tolerance
                and abs(e_phi) <= c.heading_tolerance
                and math.sqrt(u[0] * u[0] + u[1] * u[1]) <= c.speed_tolerance
                and abs(u[2]) <= c.yaw_rate_tolerance)

    @staticmethod
    def info_one(q: Any, u: Any, brake: Any, impulses: Any, physics: Any, c: Any,
                 out: Any) -> None:  # fmt: skip
        """Mode (2, 3, 5 DOF), lifted wheels, FC3D residual, normal impulses [N s] (env step)."""
        out[0] = physics[INFO_MODE]
        out[1] = physics[INFO_LIFTED_CONTACTS]
        out[2] = physics[INFO_RESIDUAL]
        out[3] = impulses[0]
        out[4] = impulses[3]
        out[5] = impulses[6]


class DiffDriveRobotEnv(MoreauJeanEnv):
    """
    ## Description
    A differential-drive robot (10 kg) with two driven rear wheels and a front skid ("stick")
    on the ground, all three with isotropic Coulomb friction whose normal loads shift with
    the friction forces (load transfer: the centre of mass is 0.15 m above the ground). Wheel
    torques beyond the traction limit make a wheel slip: the robot switches between the
    paper's 2-DOF (both wheels roll), 3-DOF (one slips) and 5-DOF (both slip) modes. The maneuver
    (Yunt & Glocker 2007, section 3.2): from rest at the origin, heading +x, to
    (x, y, phi) = (2 m, 5 m, -pi/2) at rest, wheel angles free.
    `objective="time"` is maneuver B (time-optimal; paper 4.03 s), the id
    `mdi_envs/DiffDriveRobot-v1`; `objective="effort"` is maneuver A (minimise the integral of
    tau_L^2 + tau_R^2 with the final time fixed at 4.05 s), the id
    `mdi_envs/DiffDriveRobotEffort-v1`.

    ## Action Space
    `Box(-1, 1, (2,), float32)`: normalised wheel torques (tau_L, tau_R) / max_wheel_torque.
    Out-of-range values are clipped; NaN/inf or wrong shapes raise ValueError.

    ## Observation Space
    `Box((10,), float32)`:

    | index | meaning                                         | min  | max | unit  |
    |-------|-------------------------------------------------|------|-----|-------|
    | 0, 1  | x - 2, y - 5 (offset from the goal position)    | -inf | inf | m     |
    | 2, 3  | cos, sin of phi + pi/2 (heading error)          | -1   | 1   | -     |
    | 4, 5  | chassis velocity, forward and left (body frame) | -inf | inf | m/s   |
    | 6     | yaw rate phi'                                   | -inf | inf | rad/s |
    | 7, 8  | wheel rates psi_L', psi_R' (relative to chassis)| -inf | inf | rad/s |
    | 9     | time left of the fixed horizon (0 for "time")   | 0    | 4.05| s     |

    ## Rewards
    `reward = reward_objective + reward_shaping + reward_goal` (every term also in `info`).
    "time": `reward_objective = -dt`. "effort": `reward_objective = -effort_weight (tau_L^2 +
    tau_R^2) dt` and, at the end of the horizon, `reward_goal = -goal_weight d`. Shaping:
    `gamma Phi(s') - Phi(s)`, `Phi = -shaping_weight d` (0 at termination), with
    `d = sqrt(|p - p_goal|^2 + (0.5 m/rad e_phi)^2 + (0.5 s)^2 |v|^2 + (0.25 m s/rad phi')^2)`.

    ## Starting State
    Rest at the origin heading +x; x, y, phi and their rates plus uniform noise in
    [-reset_noise_scale, reset_noise_scale] (m, rad, m/s, rad/s).

    ## Episode End
    1. Termination: "time": success (`info["is_success"]`: position within 0.05 m, heading
       within 0.05 rad, speed <= 0.05 m/s, yaw rate <= 0.1 rad/s; ``mdi_envs.maneuvers``).
       "effort": when the 4.05 s horizon ends (81 steps); `is_success` then says whether
       the goal was reached.
    2. Truncation: 200 steps (10 s) via `max_episode_steps`.
    The contact solve's status is in `info["solver_status"]` (0 = converged) with its
    residual `info["solver_residual"]`; a non-finite state raises RuntimeError.

    ## Physics
    Moreau-Jean midpoint stepping with spatial Coulomb friction at the three contacts (an
    Alart-Curnier semismooth Newton solve per step, normal impulses from the load-transfer
    balance), time_step 0.01 s, frame_skip 5 (env dt 0.05 s), torques held over the
    substeps. `info`: `slip_mode` (2, 3 or 5), `num_lifted_contacts` (contacts whose load
    would be negative), `normal_impulse_left/right/stick` [N s] summed over the env step,
    `elapsed_time` [s], `effort` [N^2 m^2 s], `distance_to_goal`.

    ## Arguments
    | parameter         | type  | default | description                                      |
    |-------------------|-------|---------|--------------------------------------------------|
    | objective         | str   | "time"  | "time" (maneuver B) or "effort" (maneuver A)     |
    | max_wheel_torque  | float | 3.0     | wheel torque bound [N m] (``mdi_envs.maneuvers``) |
    | time_step         | float | 0.01    | physics step [s]                                 |
    | frame_skip        | int   | 5       | physics steps per env step                       |
    | parameters        | DiffDriveParameters | defaults | mass, geometry, friction       |
    | shaping_weight    | float | 1.0     | weight of the shaping potential (0: off)         |
    | shaping_discount  | float | 0.99    | gamma of the shaping term (v1 ids: 1.0)          |
    | goal_weight       | float | 10.0    | weight of the final distance ("effort")          |
    | effort_weight     | float | 1.0     | weight of sum tau^2 dt ("effort")                |
    | reset_noise_scale | float | 0.01    | start-state noise half-width                     |
    | render_mode       | str   | None    | "rgb_array" or "human"                           |

    The ids set: `DiffDriveRobot-v1` objective "time", shaping_discount 1.0;
    `DiffDriveRobotEffort-v1` objective "effort", goal_weight 1000, shaping_discount 1.0;
    `DiffDriveRobot-v0` the defaults above. `gym.make("mdi_envs/DiffDriveRobotEffort-v1")`;
    `gym.make_vec("mdi_envs/DiffDriveRobot-v1", num_envs=256)`.

    ## Version History
    * v1: one id per objective (`DiffDriveRobot-v1`: "time", `DiffDriveRobotEffort-v1`:
      "effort", goal_weight 1000), `shaping_discount` 1.0: the settings the shipped baselines
      train with, so that `gym.make(id)` is the task their tables report (rl-zoo3 keys its
      settings by id). Dynamics and spaces are those of v0; the `normal_impulse_*` info of
      both versions sums the physics steps of an env step.
    * v0: initial release: one id, the objective the `objective` argument (default "time"),
      goal_weight 10, shaping_discount 0.99.

    ## References
    K. Yunt, Ch. Glocker, "Modeling and Optimal Control of Hybrid Rigidbody Mechanical
    Systems", HSCC 2007, section 3.2, Table 1 and Figs. 7-9.
    """

    SCENE = DiffDriveRobotScene
    scene: DiffDriveRobotScene
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 20}

    def __init__(self, render_mode: str | None = None, **options: Any) -> None:
        super().__init__(render_mode=render_mode, **options)
        self._trail: list[tuple[float, float]] = []

    def _draw(self) -> Any:
        from mdi_envs.rendering import draw_diff_drive

        q = self.state.q[0]
        if not self._trail or self.state.elapsed_steps[0] == 0:
            self._trail = []
        self._trail.append((float(q[0]), float(q[1])))
        rows = np.array(DiffDriveRobot.contact_directions(q, self.scene.parameters.values(),
                                                          math))  # fmt: skip
        slip = (rows @ self.state.u[0]).reshape(3, 3)[:, 1:]
        sliding = np.hypot(slip[:, 0], slip[:, 1]) > SLIDING_SPEED
        impulses = self.state.impulses[0].reshape(3, 3)
        return draw_diff_drive(q, self.scene.parameters, DIFF_DRIVE_MANEUVER.goal_pose,
                               contact_forces=impulses[:, 1:] / self.scene.stepper.time_step,
                               sliding=sliding, trail=self._trail)  # fmt: skip


class DiffDriveRobotVectorEnv(MoreauJeanVectorEnv):
    """``num_envs`` copies of ``DiffDriveRobotEnv`` in one compiled step (same arguments)."""

    SCENE = DiffDriveRobotScene


__all__ = ["DiffDriveRobotEnv", "DiffDriveRobotScene", "DiffDriveRobotVectorEnv"]
