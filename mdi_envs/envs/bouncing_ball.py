"""``mdi_envs/BouncingBall-v0``: a validation scene. A ball dropped on rigid ground bounces to
rest in finitely many impacts (Zeno) while a bounded horizontal force carries it to x = 1 m.
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
from mdi_envs.mechanics.models.bouncing_ball import BouncingBall, BouncingBallParameters
from mdi_envs.mechanics.parameters import require_positive

GOAL_X = 1.0  # [m] horizontal goal of the ball's centre
INITIAL_HEIGHT = 1.0  # [m] height of the ball's centre at the start (at rest)
POSITION_TOLERANCE = 0.02  # [m] |x - GOAL_X| at success
SPEED_TOLERANCE = 0.05  # [m/s] |x'| and |y'| at success
GAP_TOLERANCE = 1e-3  # [m] |y - r| at success
VELOCITY_WEIGHT = 0.3  # [s] weight of the horizontal speed in the goal distance


class BouncingBallConstants(NamedTuple):
    """What the compiled scene functions read (``c``).

    Attributes:
        goal_x, radius, gravity: the goal [m], the ball's radius [m], gravity [m/s^2].
        position_tolerance, speed_tolerance, gap_tolerance: the success box [m], [m/s], [m].
        velocity_weight: of the horizontal speed in the distance [s].
    """

    goal_x: float
    radius: float
    gravity: float
    position_tolerance: float
    speed_tolerance: float
    gap_tolerance: float
    velocity_weight: float


class BouncingBallScene(MoreauJeanScene):
    """Batched logic of the bouncing-ball environments (documented on the env class)."""

    MODEL = BouncingBall
    NUM_OBSERVATIONS = 4
    CONSTANTS = BouncingBallConstants
    INFO_KEYS = ("normal_impulse", "friction_impulse", "penetration")

    def __init__(
        self,
        *,
        parameters: BouncingBallParameters | None = None,
        restitution: float | None = None,
        friction_coefficient: float | None = None,
        max_force: float = 1.0,
        time_step: float = 1e-3,
        frame_skip: int = 10,
        reset_noise_scale: float = 0.01,
        **options: Any,
    ) -> None:
        parameters = build_parameters(parameters, BouncingBallParameters,
                                      restitution=restitution,
                                      friction_coefficient=friction_coefficient)  # fmt: skip
        super().__init__(parameters=parameters, time_step=time_step, frame_skip=frame_skip,
                         reset_noise_scale=reset_noise_scale, **options)  # fmt: skip
        self.max_force = require_positive("max_force", max_force)
        if not INITIAL_HEIGHT > self.parameters.radius:
            raise ValueError(f"parameter 'radius' must be < the drop height {INITIAL_HEIGHT} m, "
                             f"got {self.parameters.radius!r}")  # fmt: skip
        # horizontal force [N] = max_force * clip(action, -1, 1)
        self.actions = TorqueBrakeActions("box", 1, False, self.max_force)
        self.single_action_space = self.actions.space()
        high = np.full(self.NUM_OBSERVATIONS, np.inf, np.float32)
        self.single_observation_space = spaces.Box(-high, high, dtype=np.float32)

    START_NOISE_ENTRIES = (0, 2)  # x, x' (the height is exact)

    def nominal_start(self) -> FloatArray:
        """Rest at (0, 1 m)."""
        return np.array([0.0, INITIAL_HEIGHT, 0.0, 0.0])

    def constants(self) -> BouncingBallConstants:
        """The goal, the ball's radius and gravity, the tolerances, the distance weight."""
        p = self.parameters
        return BouncingBallConstants(GOAL_X, p.radius, p.gravity, POSITION_TOLERANCE,
                                     SPEED_TOLERANCE, GAP_TOLERANCE, VELOCITY_WEIGHT)

    @staticmethod
    def observe_one(q: Any, u: Any, brake: Any, time_left: float, c: Any, out: Any) -> None:
        """(x - goal, gap y - r, x', y')."""
        out[0] = q[0] - c.goal_x
        out[1] = q[1] - c.radius
        out[2] = u[0]
        out[3] = u[1]

    @staticmethod
    def distance_one(q: Any, u: Any, c: Any) -> float:
        """sqrt(e_x^2 + (w x')^2 + h^2), w = 0.3 s.

        h = max(gap, 0) + y'^2 / (2 g): the height of the next apex above contact (the vertical
        energy over m g).
        """
        e_x = q[0] - c.goal_x
        h = max(q[1] - c.radius, 0.0)
        w = c.velocity_weight
        if c.gravity > 0.0:
            h += u[1] * u[1] / (2.0 * c.gravity)
        else:
            h += w * abs(u[1])
        return math.sqrt(e_x * e_x + w * w * u[0] * u[0] + h * h)

    @staticmethod
    def success_one(q: Any, u: Any, c: Any) -> bool:
        """|x - goal| <= 0.02 m, |x'| <= 0.05 m/s, |y - r| <= 1e-3 m, |y'| <= 0.05 m/s."""
        return (
            abs(q[0] - c.goal_x) <= c.position_tolerance
            and abs(u[0]) <= c.speed_tolerance
            and abs(q[1] - c.radius) <= c.gap_tolerance
            and abs(u[1]) <= c.speed_tolerance
        )

    @staticmethod
    def info_one(q: Any, u: Any, brake: Any, impulses: Any, physics: Any, c: Any,
                 out: Any) -> None:  # fmt: skip
        """P_N and P_T of the last physics step [N s]; penetration max(0, r - y) [m]."""
        out[0] = impulses[0]
        out[1] = impulses[1]
        out[2] = max(c.radius - q[1], 0.0)


class BouncingBallEnv(MoreauJeanEnv):
    """
    ## Description
    A validation scene for impacts. A ball (point mass 0.1 kg, radius 0.05 m) is dropped from
    rest with its centre at 1 m above rigid ground; Newton's impact law with restitution
    `eps` (default 0.8) makes it bounce with apex heights falling as eps^(2k), and the impacts
    accumulate in finite time (Zeno), after which the ball rests on the ground. The simple
    control problem: a bounded horizontal force must bring the ball to x = 1 m at rest, on the
    ground. With the default frictionless ground the force does not interact with the
    impacts, so the episode cannot end before the bouncing has died out (t_inf = 3.96 s with
    the defaults); with `friction_coefficient > 0` the impacts also brake the horizontal
    motion.

    ## Action Space
    `Box(-1, 1, (1,), float32)`: horizontal force / max_force (no brake).

    | index | meaning                        | min | max | unit |
    |-------|--------------------------------|-----|-----|------|
    | 0     | horizontal force / max_force   | -1  | 1   | -    |

    Out-of-range values are clipped; NaN/inf or wrong shapes raise ValueError.

    ## Observation Space
    `Box((4,), float32)`:

    | index | meaning                                 | min  | max | unit |
    |-------|-----------------------------------------|------|-----|------|
    | 0     | x - 1 (offset from the goal)            | -inf | inf | m    |
    | 1     | gap y - r (height of the lowest point)  | -inf | inf | m    |
    | 2     | x'                                      | -inf | inf | m/s  |
    | 3     | y'                                      | -inf | inf | m/s  |

    ## Rewards
    Per step `reward = reward_objective + reward_shaping` (every term also in `info`):
    `reward_objective = -dt` (reach the goal fastest); `reward_shaping = gamma Phi(s') -
    Phi(s)` with `Phi = -shaping_weight d`, `d = sqrt((x - 1)^2 + (0.3 s)^2 x'^2 + h^2)`,
    `h = max(y - r, 0) + y'^2 / (2 g)` the height of the next apex (vertical energy / m g),
    and `Phi = 0` at termination (the optimal policy is unchanged for discount
    `gamma = shaping_discount`).

    ## Starting State
    Rest at x = 0, y = 1 m; x and x' plus uniform noise in [-reset_noise_scale,
    reset_noise_scale] (m, m/s). The height and y' are exact, so the vertical motion is the
    closed-form one below.

    ## Episode End
    1. Termination: success, `info["is_success"]`: |x - 1| <= 0.02 m, |x'| <= 0.05 m/s,
       |y - r| <= 1e-3 m and |y'| <= 0.05 m/s.
    2. Truncation: 600 steps (6 s) via `max_episode_steps`.
    A solve that does not converge is reported in `info["solver_status"]` (0 = converged);
    a non-finite state raises RuntimeError.

    ## Physics
    One planar ground contact (gap y - r, normal (0, 1), tangent (1, 0)), Newton restitution
    `eps` = `restitution` (default 0.8) and Coulomb friction `mu` = `friction_coefficient`
    (default 0), gravity 9.81 m/s^2. Moreau-Jean midpoint stepping (``mdi_envs.stepping``),
    `time_step` 1e-3 s, `frame_skip` 10 (env dt 0.01 s), the force held over the substeps.
    `info` adds `normal_impulse` P_N and `friction_impulse` P_T [N s] summed over the env step
    (P_N = m g dt at rest, dt = time_step * frame_skip) and `penetration` max(0, r - y) [m], besides
    `elapsed_time` [s], `effort` [N^2 s], `distance_to_goal`, `solver_status`,
    `solver_iterations`, `num_active_contacts`.

    ## Arguments
    | parameter            | type  | default | description                                    |
    |----------------------|-------|---------|------------------------------------------------|
    | max_force            | float | 1.0     | horizontal force at action 1 [N]               |
    | restitution          | float | None    | eps in [0, 1] (overrides `parameters`; 0.8)    |
    | friction_coefficient | float | None    | mu >= 0 (overrides `parameters`; 0)            |
    | parameters           | BouncingBallParameters | defaults | mass, radius, gravity, eps, mu |
    | time_step            | float | 1e-3    | physics step [s]                               |
    | frame_skip           | int   | 10      | physics steps per env step                     |
    | shaping_weight       | float | 1.0     | weight of the shaping potential (0: off)       |
    | shaping_discount     | float | 0.99    | gamma of the shaping term                      |
    | reset_noise_scale    | float | 0.01    | start noise half-width on x, x' [m, m/s]       |
    | shortcuts            | StepShortcuts | all on | the stepper's exact shortcuts           |
    | locate_impacts       | bool  | False   | split steps at impacts (``MoreauJeanStepper``) |
    | render_mode          | str   | None    | "rgb_array" or "human"                         |

    Invalid physics raise ValueError naming the field (e.g. `restitution=1.5`,
    `BouncingBallParameters(mass=-1)`, `time_step=0`).
    `gym.make("mdi_envs/BouncingBall-v0", restitution=0.5, friction_coefficient=0.3)`.

    ## Version History
    * v0: initial release.

    ## References
    The closed forms it validates (h0 = 1 m, r, g, eps): first impact at
    t_1 = sqrt(2 (h0 - r) / g) = 0.440 s; the k-th apex at eps^(2k) (h0 - r) above contact
    (0.608 m for k = 1); the flights shrink geometrically, so the impacts accumulate at
    t_inf = t_1 (1 + eps) / (1 - eps) = 3.96 s (Zeno), after which the ball rests with
    P_N = m g dt per step. J.J. Moreau, "Unilateral contact and dry friction in finite
    freedom dynamics", CISM 302, 1988; C. Glocker, "Set-Valued Force Laws", 2001.
    """

    SCENE = BouncingBallScene
    scene: BouncingBallScene
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 100}

    def _draw(self) -> Any:
        from mdi_envs.rendering import draw_bouncing_ball

        return draw_bouncing_ball(self.state.q[0], self.scene.parameters)


class BouncingBallVectorEnv(MoreauJeanVectorEnv):
    """``num_envs`` copies of ``BouncingBallEnv`` in one compiled step (same arguments)."""

    SCENE = BouncingBallScene


__all__ = ["BouncingBallEnv", "BouncingBallScene", "BouncingBallVectorEnv"]
