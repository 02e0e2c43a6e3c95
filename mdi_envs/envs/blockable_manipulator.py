"""``mdi_envs/BlockableManipulator-v1`` (and ``-v0``): the paper's time-optimal swing of a
two-link arm with a motor on the first joint and an impulsive brake on the second.
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
from mdi_envs.maneuvers import MANIPULATOR_MANEUVER
from mdi_envs.mechanics.models.blockable_manipulator import BlockableManipulator
from mdi_envs.mechanics.parameters import require_positive

VELOCITY_WEIGHT = 0.3  # [s] weight of the speeds in the goal distance (rad/s -> rad)


class BlockableManipulatorConstants(NamedTuple):
    """What the compiled scene functions read (``c``).

    Attributes:
        goal_alpha, goal_beta: goal angles [rad]. angle_tolerance [rad], speed_tolerance
        [rad/s]: the success box. velocity_weight: of the speeds in the distance [s].
        max_brake_torque: the brake bound at level 1 [N m] (scales the observed level).
    """

    goal_alpha: float
    goal_beta: float
    angle_tolerance: float
    speed_tolerance: float
    velocity_weight: float
    max_brake_torque: float


class BlockableManipulatorScene(MoreauJeanScene):
    """Batched logic of the manipulator environments (documented on the env class)."""

    MODEL = BlockableManipulator
    NUM_OBSERVATIONS = 7
    CONSTANTS = BlockableManipulatorConstants

    def __init__(
        self,
        *,
        max_torque: float = MANIPULATOR_MANEUVER.max_torque,
        max_brake_torque: float = 50.0,
        action_mode: str = "box",
        time_step: float = 0.01,
        frame_skip: int = 2,
        reset_noise_scale: float = 0.01,
        **options: Any,
    ) -> None:
        super().__init__(time_step=time_step, frame_skip=frame_skip,
                         reset_noise_scale=reset_noise_scale, **options)  # fmt: skip
        self.max_torque = require_positive("max_torque", max_torque)
        self.max_brake_torque = require_positive("max_brake_torque", max_brake_torque)
        # motor torque [N m] and brake bound (see the env's Action Space)
        self.actions = TorqueBrakeActions(action_mode, 1, True, self.max_torque,
                                          self.max_brake_torque)  # fmt: skip
        self.single_action_space = self.actions.space()
        high = np.array([1, 1, 1, 1, np.inf, np.inf, 1], np.float32)  # see observe_one
        low = -high
        low[-1] = 0.0
        self.single_observation_space = spaces.Box(low, high, dtype=np.float32)

    START_NOISE_ENTRIES = (0, 1, 2, 3)  # alpha, beta, alpha', beta'

    def nominal_start(self) -> FloatArray:
        """Rest at alpha = beta = 0."""
        return np.array([*MANIPULATOR_MANEUVER.initial_q, 0.0, 0.0])

    def constants(self) -> BlockableManipulatorConstants:
        """The maneuver's goal and tolerances, the distance weight, the brake bound."""
        maneuver = MANIPULATOR_MANEUVER
        return BlockableManipulatorConstants(*maneuver.goal_q, maneuver.angle_tolerance,
                                             maneuver.velocity_tolerance, VELOCITY_WEIGHT,
                                             self.max_brake_torque)  # fmt: skip

    @staticmethod
    def observe_one(q: Any, u: Any, brake: Any, time_left: float, c: Any, out: Any) -> None:
        """(cos a, sin a, cos b, sin b, a', b', brake level in [0, 1])."""
        out[0], out[1] = cos_sin(q[0])
        out[2], out[3] = cos_sin(q[1])
        out[4] = u[0]
        out[5] = u[1]
        out[6] = min(brake[0] / c.max_brake_torque, 1.0)

    @staticmethod
    def distance_one(q: Any, u: Any, c: Any) -> float:
        """sqrt(e_a^2 + e_b^2 + w^2 (a'^2 + b'^2)), wrapped angle errors e, w = 0.3 s."""
        e0 = wrap_angle(q[0] - c.goal_alpha)
        e1 = wrap_angle(q[1] - c.goal_beta)
        w = c.velocity_weight
        return math.sqrt(e0 * e0 + e1 * e1 + w * w * (u[0] * u[0] + u[1] * u[1]))

    @staticmethod
    def success_one(q: Any, u: Any, c: Any) -> bool:
        """Both wrapped angle errors <= angle tol and both speeds <= speed tol."""
        e0 = wrap_angle(q[0] - c.goal_alpha)
        e1 = wrap_angle(q[1] - c.goal_beta)
        return (max(abs(e0), abs(e1)) <= c.angle_tolerance
                and max(abs(u[0]), abs(u[1])) <= c.speed_tolerance)

    INFO_KEYS = ("brake_engaged", "brake_impulse")

    @staticmethod
    def info_one(q: Any, u: Any, brake: Any, impulses: Any, physics: Any, c: Any,
                 out: Any) -> None:  # fmt: skip
        """Brake engaged (bound > 0) and its impulse P_B summed over the env step [N m s]."""
        out[0] = 1.0 if brake[0] > 0.0 else 0.0
        out[1] = impulses[0]


class BlockableManipulatorEnv(MoreauJeanEnv):
    """
    ## Description
    Two uniform rods (1 m, 1 kg each) move in a horizontal plane (no gravity). A motor drives
    the absolute angle alpha of the first link; the second link (absolute angle beta) is
    passive, but a brake on the relative angle beta - alpha can block it *instantly*: an
    impulsive, set-valued control. The maneuver (Yunt & Glocker 2007, section 3.1) is to swing the
    arm from alpha = beta = 0 at rest to alpha = beta = pi at rest as fast as possible. The
    optimal maneuver uses the brake to store and release the second link's motion; the
    shipped optimal-control reference takes 4.256 s (``optimal.load_reference("manipulator_time")``;
    the paper reports 4.53 s).

    ## Action Space
    `action_mode="box"` (default): `Box(-1, 1, (2,), float32)`, SB3 PPO/SAC train on it as is.

    | index | meaning                                   | min | max | unit  |
    |-------|-------------------------------------------|-----|-----|-------|
    | 0     | motor torque / max_torque                 | -1  | 1   | -     |
    | 1     | brake: engaged (ideal) iff value > 0      | -1  | 1   | -     |

    `action_mode="hybrid"`: the native hybrid space `Tuple(Discrete(2), Box(-1, 1, (1,)))`
    (brake released/engaged, normalised torque). `action_mode="brake_force"`: the Box above
    with index 1 mapped to a finite brake torque bound a = max_brake_torque (value + 1) / 2
    [N m] (a Tresca element: the brake slips when it would need more). Out-of-range values are
    clipped; NaN/inf or wrong shapes raise ValueError.

    ## Observation Space
    `Box((7,), float32)`:

    | index | meaning                                  | min  | max | unit  |
    |-------|------------------------------------------|------|-----|-------|
    | 0, 1  | cos alpha, sin alpha                     | -1   | 1   | -     |
    | 2, 3  | cos beta, sin beta                       | -1   | 1   | -     |
    | 4, 5  | alpha', beta'                            | -inf | inf | rad/s |
    | 6     | brake level of the last step (1 engaged) | 0    | 1   | -     |

    ## Rewards
    Per step `reward = reward_objective + reward_shaping` (every term also in `info`):
    `reward_objective = -dt` (time-optimal); `reward_shaping = gamma Phi(s') - Phi(s)` with
    `Phi = -shaping_weight d`, `d = sqrt(e_alpha^2 + e_beta^2 + (0.3 s)^2 (alpha'^2 +
    beta'^2))` from the wrapped angle errors, and `Phi = 0` at termination, which leaves the
    optimal policy unchanged for discount `gamma = shaping_discount`. With the v1 default
    `shaping_discount = 1` the shaping sums to `Phi(s_T) - Phi(s_0)` over an episode, so the
    undiscounted return ranks policies as the episode time does.

    ## Starting State
    alpha = beta = 0 at rest, each coordinate and speed plus uniform noise in
    [-reset_noise_scale, reset_noise_scale] (rad, rad/s).

    ## Episode End
    1. Termination: success, `info["is_success"]`: both wrapped angle errors <= 0.05 rad and
       both speeds <= 0.1 rad/s (``mdi_envs.maneuvers.MANIPULATOR_MANEUVER``).
    2. Truncation: 500 steps (10 s) via `max_episode_steps`.
    A solve that does not converge is reported in `info["solver_status"]` (a
    ``SolverStatus`` code, 0 = converged); a non-finite state raises RuntimeError.

    ## Physics
    Moreau-Jean midpoint stepping (``mdi_envs.stepping``), dt = `time_step` = 0.01 s,
    `frame_skip` = 2 physics steps per action (env dt 0.02 s), torque and brake held over them.
    The engaged brake is an equality row (ideal: relative velocity exactly 0 after the step,
    an inelastic impact if it was moving); a finite bound is a Tresca element solved by the
    compiled LCP (enumeration up to 3 unknowns, else Lemke). `info` carries `elapsed_time`
    [s], `effort` [N^2 m^2 s], `brake_engaged`, `brake_impulse` [N m s] (summed over the
    `frame_skip` physics steps: the whole impact of an engagement), `solver_status`,
    `solver_iterations`, `num_active_contacts`, `distance_to_goal`.

    ## Arguments
    | parameter         | type  | default | description                                    |
    |-------------------|-------|---------|------------------------------------------------|
    | action_mode       | str   | "box"   | "box", "hybrid" or "brake_force"               |
    | max_torque        | float | 0.84302 | motor torque bound [N m] (``mdi_envs.maneuvers``) |
    | max_brake_torque  | float | 50.0    | brake bound at action 1 in "brake_force" [N m] |
    | time_step         | float | 0.01    | physics step [s]                               |
    | frame_skip        | int   | 2       | physics steps per env step                     |
    | parameters        | BlockableManipulatorParameters | defaults | link masses/lengths |
    | shaping_weight    | float | 1.0     | weight of the shaping potential (0: off)       |
    | shaping_discount  | float | 0.99    | gamma of the shaping term (v1 id: 1.0)         |
    | reset_noise_scale | float | 0.01    | start-state noise half-width [rad, rad/s]      |
    | shortcuts         | StepShortcuts | all on | the stepper's exact shortcuts           |
    | render_mode       | str   | None    | "rgb_array" or "human"                         |

    `gym.make("mdi_envs/BlockableManipulator-v1", action_mode="hybrid")`;
    `gym.make_vec("mdi_envs/BlockableManipulator-v1", num_envs=1024)` steps all copies in one
    compiled call.

    ## Version History
    * v1: `shaping_discount` defaults to 1.0, the setting the shipped baselines train with
      (with 0.99 the shaping pays for standing still). Dynamics, spaces and the
      `info["brake_impulse"]` sum over the physics steps are those of v0.
    * v0: initial release (`shaping_discount` 0.99).

    ## References
    K. Yunt, Ch. Glocker, "Modeling and Optimal Control of Hybrid Rigidbody Mechanical
    Systems", HSCC 2007, section 3.1 and Figs. 3-4.
    """

    SCENE = BlockableManipulatorScene
    scene: BlockableManipulatorScene
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 50}

    def _draw(self) -> Any:
        from mdi_envs.rendering import draw_manipulator

        return draw_manipulator(self.state.q[0], bool(self.state.brake[0, 0] > 0.0),
                                float(self.state.tau[0, 0]) / self.scene.max_torque,
                                self.scene.parameters)  # fmt: skip


class BlockableManipulatorVectorEnv(MoreauJeanVectorEnv):
    """``num_envs`` copies of ``BlockableManipulatorEnv`` in one compiled step (same arguments)."""

    SCENE = BlockableManipulatorScene


__all__ = ["BlockableManipulatorEnv", "BlockableManipulatorScene", "BlockableManipulatorVectorEnv"]
