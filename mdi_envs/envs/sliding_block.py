"""``mdi_envs/SlidingBlock-v0``: a validation scene. A block on a slope with Coulomb stick-slip
friction must be pushed 0.5 m up the slope and stopped there.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from gymnasium import spaces

from mdi_envs._types import FloatArray
from mdi_envs.envs._actions import TorqueBrakeActions
from mdi_envs.envs.base import (
    MoreauJeanEnv,
    MoreauJeanScene,
    MoreauJeanVectorEnv,
    build_parameters,
)
from mdi_envs.mechanics.models.sliding_block import SlidingBlock, SlidingBlockParameters
from mdi_envs.mechanics.parameters import require_positive

GOAL_S = -0.5  # [m] goal position along the slope (0.5 m up-slope of the start)
POSITION_TOLERANCE = 0.02  # [m] |s - GOAL_S| at success
SPEED_TOLERANCE = 0.02  # [m/s] |s'| at success
VELOCITY_WEIGHT = 0.3  # [s] weight of the speed in the goal distance
STICK_SPEED = 1e-6  # [m/s] the block counts as sticking below this slip speed, in contact
CONTACT_GAP = 1e-6  # [m] the block counts as in contact below this normal distance


class SlidingBlockConstants(NamedTuple):
    """What the compiled scene functions read (``c``).

    Attributes:
        goal_s: the goal [m].
        position_tolerance, speed_tolerance: the success box [m], [m/s].
        velocity_weight: of the speed in the distance [s].
        stick_speed, contact_gap: below these the block counts as sticking, in contact [m/s],
            [m].
    """

    goal_s: float
    position_tolerance: float
    speed_tolerance: float
    velocity_weight: float
    stick_speed: float
    contact_gap: float


class SlidingBlockScene(MoreauJeanScene):
    """Batched logic of the sliding-block environments (documented on the env class)."""

    MODEL = SlidingBlock
    NUM_OBSERVATIONS = 3
    CONSTANTS = SlidingBlockConstants
    INFO_KEYS = ("normal_impulse", "friction_impulse", "is_sticking")

    def __init__(
        self,
        *,
        parameters: SlidingBlockParameters | None = None,
        slope_angle: float | None = None,
        restitution: float | None = None,
        friction_coefficient: float | None = None,
        max_force: float = 20.0,
        time_step: float = 1e-3,
        frame_skip: int = 10,
        reset_noise_scale: float = 0.01,
        **options: Any,
    ) -> None:
        parameters = build_parameters(parameters, SlidingBlockParameters,
                                      slope_angle=slope_angle, restitution=restitution,
                                      friction_coefficient=friction_coefficient)  # fmt: skip
        super().__init__(parameters=parameters, time_step=time_step, frame_skip=frame_skip,
                         reset_noise_scale=reset_noise_scale, **options)  # fmt: skip
        self.max_force = require_positive("max_force", max_force)
        # force along +s (down-slope) [N] = max_force * clip(action, -1, 1)
        self.actions = TorqueBrakeActions("box", 1, False, self.max_force)
        self.single_action_space = self.actions.space()
        high = np.array([np.inf, np.inf, 1.0], np.float32)
        low = np.array([-np.inf, -np.inf, 0.0], np.float32)
        self.single_observation_space = spaces.Box(low, high, dtype=np.float32)

    START_NOISE_ENTRIES = (0, 2)  # s, s'

    def nominal_start(self) -> FloatArray:
        """Rest at s = 0 on the slope (n = 0)."""
        return np.zeros(4)

    def constants(self) -> SlidingBlockConstants:
        """The goal, the tolerances, the distance weight, the stick and contact thresholds."""
        return SlidingBlockConstants(GOAL_S, POSITION_TOLERANCE, SPEED_TOLERANCE,
                                     VELOCITY_WEIGHT, STICK_SPEED, CONTACT_GAP)

    @staticmethod
    def observe_one(q: Any, u: Any, brake: Any, time_left: float, c: Any, out: Any) -> None:
        """(s - goal, s', 1 if sticking (in contact, |s'| <= 1e-6 m/s) else 0)."""
        out[0] = q[0] - c.goal_s
        out[1] = u[0]
        out[2] = 1.0 if (q[1] <= c.contact_gap and abs(u[0]) <= c.stick_speed) else 0.0

    @staticmethod
    def distance_one(q: Any, u: Any, c: Any) -> float:
        """sqrt((s - goal)^2 + (w s')^2), w = 0.3 s."""
        e = q[0] - c.goal_s
        w = c.velocity_weight
        return math.sqrt(e * e + w * w * u[0] * u[0])

    @staticmethod
    def success_one(q: Any, u: Any, c: Any) -> bool:
        """|s - goal| <= 0.02 m and |s'| <= 0.02 m/s."""
        return abs(q[0] - c.goal_s) <= c.position_tolerance and abs(u[0]) <= c.speed_tolerance

    @staticmethod
    def info_one(q: Any, u: Any, brake: Any, impulses: Any, physics: Any, c: Any,
                 out: Any) -> None:  # fmt: skip
        """P_N, P_T of the last physics step [N s]; sticking (P_N > 0 and |s'| <= 1e-6 m/s)."""
        out[0] = impulses[0]
        out[1] = impulses[1]
        out[2] = 1.0 if (impulses[0] > 0.0 and abs(u[0]) <= c.stick_speed) else 0.0


class SlidingBlockEnv(MoreauJeanEnv):
    """
    ## Description
    A validation scene for Coulomb stick-slip. A block (point mass 1 kg) rests on a slope of
    angle theta (default 0.5 rad) with friction coefficient mu (default 0.5); since
    tan(theta) = 0.546 > mu it slides down unless pushed. The simple control problem: a bounded
    force along the slope must bring the block from s = 0 to s = -0.5 m (0.5 m up-slope) and
    stop it there. Holding it needs a force in the friction cone
    [-m g (sin theta + mu cos theta), -m g (sin theta - mu cos theta)] = [-9.01, -0.40] N;
    moving it up-slope needs more than 9.01 N up-slope.

    ## Action Space
    `Box(-1, 1, (1,), float32)`: force along +s (down-slope) / max_force (no brake).

    | index | meaning                                   | min | max | unit |
    |-------|-------------------------------------------|-----|-----|------|
    | 0     | force along +s (down-slope) / max_force   | -1  | 1   | -    |

    Out-of-range values are clipped; NaN/inf or wrong shapes raise ValueError.

    ## Observation Space
    `Box((3,), float32)`:

    | index | meaning                                              | min  | max | unit |
    |-------|------------------------------------------------------|------|-----|------|
    | 0     | s + 0.5 (offset from the goal, positive down-slope)  | -inf | inf | m    |
    | 1     | s'                                                   | -inf | inf | m/s  |
    | 2     | 1 if sticking (on the slope, |s'| <= 1e-6 m/s) else 0 | 0    | 1   | -    |

    ## Rewards
    Per step `reward = reward_objective + reward_shaping` (every term also in `info`):
    `reward_objective = -dt` (reach the goal fastest); `reward_shaping = gamma Phi(s') -
    Phi(s)` with `Phi = -shaping_weight d`, `d = sqrt((s + 0.5)^2 + (0.3 s)^2 s'^2)`, and
    `Phi = 0` at termination (the optimal policy is unchanged for discount
    `gamma = shaping_discount`).

    ## Starting State
    Rest at s = 0 on the slope (n = 0); s and s' plus uniform noise in [-reset_noise_scale,
    reset_noise_scale] (m, m/s).

    ## Episode End
    1. Termination: success, `info["is_success"]`: |s + 0.5| <= 0.02 m and |s'| <= 0.02 m/s.
    2. Truncation: 500 steps (5 s) via `max_episode_steps`.
    A solve that does not converge is reported in `info["solver_status"]` (0 = converged);
    a non-finite state raises RuntimeError.

    ## Physics
    One planar contact between block and slope (gap n, normal (0, 1), tangent (1, 0)),
    Coulomb friction `mu` = `friction_coefficient`, restitution `eps` = `restitution`
    (default 0: the block stays on the slope), gravity (m g sin theta, -m g cos theta) in
    slope coordinates. Moreau-Jean midpoint stepping (``mdi_envs.stepping``), `time_step`
    1e-3 s, `frame_skip` 10 (env dt 0.01 s), the force held over the substeps; sticking is
    exact (s' = 0 after a step whose force lies in the cone). `info` adds `normal_impulse`
    P_N and `friction_impulse` P_T [N s] summed over the env step and `is_sticking` (1.0 if
    P_N > 0 and |s'| <= 1e-6 m/s, else 0.0), besides `elapsed_time` [s], `effort`
    [N^2 s], `distance_to_goal`, `solver_status`, `solver_iterations`,
    `num_active_contacts`.

    ## Arguments
    | parameter            | type  | default | description                                    |
    |----------------------|-------|---------|------------------------------------------------|
    | max_force            | float | 20.0    | force along +s at action 1 [N]                 |
    | slope_angle          | float | None    | theta in [0, pi/2) [rad] (overrides; 0.5)      |
    | friction_coefficient | float | None    | mu >= 0 (overrides `parameters`; 0.5)          |
    | restitution          | float | None    | eps in [0, 1] (overrides `parameters`; 0)      |
    | parameters           | SlidingBlockParameters | defaults | mass, gravity, theta, eps, mu |
    | time_step            | float | 1e-3    | physics step [s]                               |
    | frame_skip           | int   | 10      | physics steps per env step                     |
    | shaping_weight       | float | 1.0     | weight of the shaping potential (0: off)       |
    | shaping_discount     | float | 0.99    | gamma of the shaping term                      |
    | reset_noise_scale    | float | 0.01    | start noise half-width on s, s' [m, m/s]       |
    | shortcuts            | StepShortcuts | all on | the stepper's exact shortcuts           |
    | locate_impacts       | bool  | False   | split steps at impacts (``MoreauJeanStepper``) |
    | render_mode          | str   | None    | "rgb_array" or "human"                         |

    Invalid physics raise ValueError naming the field (e.g. `friction_coefficient=-0.1`,
    `SlidingBlockParameters(mass=-1)`, `time_step=0`).
    `gym.make("mdi_envs/SlidingBlock-v0", friction_coefficient=0.7, max_force=30.0)`.

    ## Version History
    * v0: initial release.

    ## References
    The closed forms it validates: the block at rest sticks iff the net driving force
    m g sin theta + F lies within the cone |.| <= mu m g cos theta (with F = 0: iff
    tan theta <= mu); sliding down (F = 0) it accelerates at g (sin theta - mu cos theta)
    = 0.399 m/s^2 with the defaults, so s' = g (sin theta - mu cos theta) t exactly; pushed
    up-slope by F < -m g (sin theta + mu cos theta) it accelerates at
    F / m + g (sin theta + mu cos theta). J.J. Moreau, "Unilateral contact and dry friction
    in finite freedom dynamics", CISM 302, 1988; F. Pfeiffer, Ch. Glocker, "Multibody
    Dynamics with Unilateral Contacts", 1996.
    """

    SCENE = SlidingBlockScene
    scene: SlidingBlockScene
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 100}

    def _draw(self) -> Any:
        from mdi_envs.rendering import draw_sliding_block

        return draw_sliding_block(self.state.q[0], self.scene.parameters,
                                  target_position=GOAL_S)  # fmt: skip


class SlidingBlockVectorEnv(MoreauJeanVectorEnv):
    """``num_envs`` copies of ``SlidingBlockEnv`` in one compiled step (same arguments)."""

    SCENE = SlidingBlockScene


__all__ = ["SlidingBlockEnv", "SlidingBlockScene", "SlidingBlockVectorEnv"]
