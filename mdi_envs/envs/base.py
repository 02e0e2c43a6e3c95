"""The environment base classes: one batched scene behind a single and a vector Gymnasium env.

Everything scene-specific -- spaces, action decoding, observations, goal distance, success --
lives in a ``MoreauJeanScene`` written once for a batch of N copies. ``MoreauJeanEnv`` runs it
with N = 1 and ``MoreauJeanVectorEnv`` with N = ``num_envs``; both advance the physics through
the same compiled ``MoreauJeanStepper.step_batch`` call, so the vector env equals a
``SyncVectorEnv`` of the single env step for step. The reward is assembled here, the same for
every scene:

    reward = reward_objective + reward_shaping + reward_goal
    reward_objective = -dt                       (objective "time")
                     = -effort_weight sum(tau^2) dt   (objective "effort")
    reward_shaping   = gamma Phi(s') - Phi(s),   Phi = -shaping_weight * distance_to_goal,
                       with Phi(s') = 0 when the episode terminates (Ng et al. 1999: the optimal
                       policy of the discounted problem with discount gamma is unchanged)
    reward_goal      = -goal_weight * distance_to_goal, once, when a fixed horizon ends.

The per-copy scene functions (observation, goal distance, success) are plain Python on scalars
and small arrays, compiled with numba into one batched kernel per scene class, so that an
``env.step`` costs one compiled call (action decoding, physics, rewards, observations and info)
with six array arguments: the batch state lives in one flat buffer (``BatchState``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any, ClassVar, NamedTuple

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numba import njit

from mdi_envs._borrowing import borrowing_njit
from mdi_envs._kernel_cache import define, freeze
from mdi_envs._types import BoolArray, FloatArray
from mdi_envs.envs._actions import ARRAY_DTYPE_CHARS, TorqueBrakeActions, decode_levels
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.mechanics.parameters import require_nonnegative, require_positive
from mdi_envs.stepping._kernel import (
    INFO_ACTIVE_CONTACTS,
    INFO_ITERATIONS,
    INFO_STATUS,
    StepShortcuts,
)
from mdi_envs.stepping.moreau_jean import MoreauJeanStepper

BASE_INFO_KEYS = (
    "reward_objective", "reward_shaping", "reward_goal", "distance_to_goal", "is_success",
    "elapsed_time", "effort", "solver_status", "solver_iterations", "num_active_contacts",
)
"""``info`` entries of every scene (units: reward terms -, distance -, elapsed_time s, effort
N^2 m^2 s; solver_status a ``SolverStatus`` code, 0 = converged, the worst over the substeps)."""
_INFO_TYPES: dict[str, Any] = {
    "is_success": bool, "brake_engaged": bool, "solver_status": int, "solver_iterations": int,
    "num_active_contacts": int, "slip_mode": int, "num_lifted_contacts": int,
    "is_sticking": bool,
}


class EnvSettings(NamedTuple):
    """What the compiled env step reads of a scene besides its state, the model's parameter
    record and the scene constants (all three stored as float64 at the end of every
    ``BatchState`` buffer and rebuilt inside the kernels, see ``_reader``).

    Attributes:
        time_step: physics step [s].
        frame_skip: physics steps per env step.
        dt: env step [s] (time_step * frame_skip).
        horizon_steps: env steps of the fixed horizon of the "effort" objective (0: "time").
        effort_weight, goal_weight, shaping_weight, shaping_discount: the reward's weights and
            the shaping discount gamma (see the module docstring).
        action_rule: how the brake level is decoded (``TorqueBrakeActions.rule``).
        max_torque: bound of every input at level 1 [N m or N].
        max_brake_torque: the Tresca bound at brake level 1 of "brake_force" [N m].
    """

    time_step: float
    frame_skip: int
    dt: float
    horizon_steps: int
    effort_weight: float
    goal_weight: float
    shaping_weight: float
    shaping_discount: float
    action_rule: int
    max_torque: float
    max_brake_torque: float


class SceneKernels(NamedTuple):
    """The compiled kernels of one scene class (see ``_compiled``)."""

    advance: Any
    observe_all: Any
    distance_one: Any
    restart: Any


class StateViews(NamedTuple):
    """The named views of a ``BatchState`` buffer, in buffer order (see ``_state_carver``).

    ``workspace_floats``/``workspace_ints``: the stepper's scratch; ``q`` to ``reward``: the
    per-copy arrays of ``state_fields``; ``obs``: the float32 observations; ``settings``: the
    ``EnvSettings``, the parameter record and the scene constants, as float64.
    """

    workspace_floats: Any
    workspace_ints: Any
    q: Any
    u: Any
    tau: Any
    brake: Any
    impulses: Any
    step_impulses: Any
    physics: Any
    info: Any
    elapsed_steps: Any
    effort: Any
    potential: Any
    terminated: Any
    reward: Any
    obs: Any
    settings: Any


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ValueError(message)


def build_parameters(parameters: Any, defaults: type[Any], **overrides: Any) -> Any:
    """``parameters`` (default ``defaults()``) with the non-None ``overrides`` replaced.

    The dataclass validates the result: a bad value raises ValueError naming its field.
    """
    base = defaults() if parameters is None else parameters
    if not isinstance(base, defaults):
        raise ValueError(f"parameters must be a {defaults.__name__}, got {type(base).__name__}")
    changes = {name: value for name, value in overrides.items() if value is not None}
    return dataclasses.replace(base, **changes) if changes else base


class MoreauJeanScene:
    """Scene logic of one environment family, batched over N copies.

    Subclasses set ``MODEL``, ``NUM_OBSERVATIONS``, ``OBJECTIVE_OPTIONS`` and ``CONSTANTS``,
    the action coding ``actions`` with ``single_action_space = actions.space()``, the
    observation space, and implement the compiled ``observe_one``, ``distance_one`` and
    ``success_one`` with the ``constants`` record ``c`` they read, plus ``nominal_start`` with
    ``START_NOISE_ENTRIES`` and ``info_one`` with ``INFO_KEYS``. Arrays are float64 of shape
    (N, ...), observations float32.

    Args:
        parameters: the model's parameter dataclass (default: its defaults).
        time_step: physics step dt [s].
        frame_skip: physics steps per env step (the control is held over them).
        objective: "time" (reach the goal fastest; success terminates) or "effort" (minimize
            the integral of sum(tau^2) over a fixed horizon ``final_time``).
        final_time: the fixed horizon [s] of the "effort" objective (ignored for "time").
        shaping_weight: weight of the distance in the shaping potential Phi (0 disables).
        shaping_discount: gamma of the shaping term; set it to the agent's discount.
        goal_weight: weight of the distance at the end of a fixed horizon.
        effort_weight: weight of sum(tau^2) dt in the "effort" objective.
        reset_noise_scale: half-width of the uniform noise added to the start state.
        shortcuts: the stepper's exact shortcuts (``StepShortcuts``).
        locate_impacts: the stepper's impact location (``MoreauJeanStepper``; contact scenes).
    """

    MODEL: ClassVar[type[ModelDefinition]]
    OBJECTIVE_OPTIONS: ClassVar[tuple[str, ...]] = ("time",)
    single_observation_space: spaces.Space[Any]
    single_action_space: spaces.Space[Any]
    actions: TorqueBrakeActions
    """The action coding (space, scaling, brake rule); set by each scene's ``__init__``."""

    def __init__(
        self,
        *,
        parameters: Any = None,
        time_step: float,
        frame_skip: int,
        objective: str = "time",
        final_time: float | None = None,
        shaping_weight: float = 1.0,
        shaping_discount: float = 0.99,
        goal_weight: float = 10.0,
        effort_weight: float = 1.0,
        reset_noise_scale: float = 0.0,
        shortcuts: StepShortcuts | None = None,
        locate_impacts: bool = False,
    ) -> None:
        self._settings_cache: FloatArray | None = None
        self._constants_cache: Any = None
        self._info_keys = BASE_INFO_KEYS + self.INFO_KEYS
        self._info_of = _info_builder(self._info_keys)
        _require(isinstance(frame_skip, (int, np.integer)) and frame_skip >= 1,
                 f"frame_skip must be a positive integer, got {frame_skip!r}")  # fmt: skip
        _require(objective in self.OBJECTIVE_OPTIONS,
                 f"objective must be one of {self.OBJECTIVE_OPTIONS}, got {objective!r}")
        self.stepper = MoreauJeanStepper(
            self.MODEL, parameters, require_positive("time_step", time_step),
            shortcuts if shortcuts is not None else StepShortcuts(), bool(locate_impacts),
        )
        self.parameters = self.stepper.parameters
        self.frame_skip = int(frame_skip)
        self.dt = self.stepper.time_step * self.frame_skip
        self.objective = objective
        self.num_horizon_steps = 0
        if objective == "effort":
            if final_time is None:
                raise ValueError("objective 'effort' needs a final_time")
            horizon = require_positive("final_time", final_time)
            self.num_horizon_steps = round(horizon / self.dt)
            _require(abs(self.num_horizon_steps * self.dt - horizon) <= 1e-9 * horizon,
                     f"final_time {horizon} s must be a whole number of env steps of "
                     f"{self.dt} s (time_step * frame_skip)")  # fmt: skip
        self.final_time = self.num_horizon_steps * self.dt
        self.shaping_weight = require_nonnegative("shaping_weight", shaping_weight)
        self.shaping_discount = require_positive("shaping_discount", shaping_discount)
        _require(self.shaping_discount <= 1.0,
                 f"shaping_discount must lie in (0, 1], got {shaping_discount!r}")
        self.goal_weight = require_nonnegative("goal_weight", goal_weight)
        self.effort_weight = require_nonnegative("effort_weight", effort_weight)
        self.reset_noise_scale = require_nonnegative("reset_noise_scale", reset_noise_scale)
        self._take_kernels()

    def _take_kernels(self) -> None:
        """Look up (or build) the compiled kernels of this scene (see ``_compiled``)."""
        self._kernels = _compiled(self)
        self._advance_kernel = self._kernels.advance

    def __getstate__(self) -> dict[str, Any]:
        """Pickle without the compiled kernels and the info builder (rebuilt when unpickled)."""
        return {key: value for key, value in self.__dict__.items()
                if key not in ("_kernels", "_advance_kernel", "_info_of")}  # fmt: skip

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._info_of = _info_builder(self._info_keys)
        self._take_kernels()

    @property
    def settings(self) -> EnvSettings:
        """What the compiled step reads of the scene (``EnvSettings``)."""
        coding = self.actions
        return EnvSettings(
            self.stepper.time_step, self.frame_skip, self.dt, self.num_horizon_steps,
            self.effort_weight, self.goal_weight, self.shaping_weight, self.shaping_discount,
            coding.rule, coding.max_torque, coding.max_brake_torque,
        )  # fmt: skip

    @property
    def _settings_array(self) -> FloatArray:
        """``settings``, the model's parameter record and ``constants()``, in one float64 array
        (copied to the end of every ``BatchState`` buffer; read back by ``_reader``).
        """
        if self._settings_cache is None:
            self._settings_cache = np.array(
                [*self.settings, *self.stepper.compiled_step_batch[1], *self._constants],
                np.float64)  # fmt: skip
        return self._settings_cache

    @property
    def _constants(self) -> Any:
        """``constants()``, built once."""
        if self._constants_cache is None:
            self._constants_cache = self.constants()
        return self._constants_cache

    # -- scene-specific, implemented by each scene class ------------------------------------
    # The static methods below are compiled by numba (nopython): plain arithmetic on floats
    # and 1-D float64 arrays, scene constants read by name from the record ``c``
    # (``self.constants()``).
    NUM_OBSERVATIONS: ClassVar[int]

    @staticmethod
    def observe_one(q: Any, u: Any, brake: Any, time_left: float, c: Any, out: Any) -> None:
        """Write one copy's observation into ``out`` (NUM_OBSERVATIONS,) float32."""
        raise NotImplementedError

    @staticmethod
    def distance_one(q: Any, u: Any, c: Any) -> float:
        """One copy's weighted distance from the goal at rest (0 at the goal)."""
        raise NotImplementedError

    @staticmethod
    def success_one(q: Any, u: Any, c: Any) -> bool:
        """Whether one copy is at the goal at rest within the maneuver's tolerances."""
        raise NotImplementedError

    CONSTANTS: ClassVar[type[Any]]
    """The NamedTuple class of ``constants()`` (floats; defined at module level, where the
    kernel cache imports it)."""

    def constants(self) -> Any:
        """The scene constants ``c`` the compiled functions read by name (a ``CONSTANTS``)."""
        raise NotImplementedError

    START_NOISE_ENTRIES: ClassVar[tuple[int, ...]]
    """Entries of the stacked start state (q, u) (2n,) that get the reset noise, in the order
    of their draws."""

    def nominal_start(self) -> FloatArray:
        """The start state (q, u) stacked, (2n,), before the reset noise."""
        raise NotImplementedError

    INFO_KEYS: ClassVar[tuple[str, ...]] = ()

    @staticmethod
    def info_one(q: Any, u: Any, brake: Any, impulses: Any, physics: Any, c: Any,
                 out: Any) -> None:  # fmt: skip
        """Write one copy's scene diagnostics (one value per ``INFO_KEYS`` entry) into ``out``.

        impulses: the impulses summed over the physics steps of the env step (c*d + k,);
        physics: the stepper diagnostics of its last physics step (the ``mdi_envs.stepping``
        INFO_* layout; the status is the worst over the env step).
        """

    # -- shared ----------------------------------------------------------------------------
    @property
    def info_keys(self) -> tuple[str, ...]:
        """Names of the ``info`` entries of a step, in the order of ``state.info`` columns."""
        return self._info_keys

    def advance(self, state: BatchState, actions: Any) -> None:
        """Decode ``actions`` (a batch, see ``actions.levels``) into ``state.tau`` [N m] and
        ``state.brake``, step the physics of every copy, then the rewards, observations and
        info columns (all written into ``state``), in one compiled call.

        A float32/float64 array whose last axis is the action width goes to the compiled call
        as it is (its size and rank are checked there); anything else through
        ``actions.levels``.

        Raises:
            ValueError: a wrong shape or NaN/inf in ``actions`` (``state`` is left unchanged).
            RuntimeError: the physics produced a non-finite state.
        """
        if (type(actions) is np.ndarray and actions.dtype.char in ARRAY_DTYPE_CHARS
                and actions.shape[-1:] == self.actions.array_tail):
            levels = actions
        else:
            levels = self.actions.levels(actions, state.num_copies)
        outcome = self._advance_kernel(levels, state.buffer)
        if outcome != ADVANCE_OK:
            self._raise_for(outcome, state, actions, levels)

    def _raise_for(self, outcome: int, state: BatchState, actions: Any, levels: Any) -> None:
        """The error of a failed ``advance`` (``outcome`` an ``ADVANCE_*`` code)."""
        if outcome == ADVANCE_ACTION_SHAPE:
            self.actions.levels(actions, state.num_copies)  # raises, naming the shape
            raise ValueError(f"action must have shape {self.single_action_space.shape} per "
                             f"copy, got {np.shape(actions)}")  # fmt: skip
        if outcome == ADVANCE_ACTION_NOT_FINITE:
            raise ValueError(f"action contains NaN or inf entries: {np.asarray(levels).tolist()}")
        raise RuntimeError(
            "the physics step produced a non-finite state (solver status codes "
            f"{state.physics[:, INFO_STATUS].tolist()}); please report this with the seed"
        )

    def info_arrays(self, state: BatchState) -> dict[str, Any]:
        """The last step's info as name -> (N,) array (bool and int entries typed)."""
        return {key: state.info[:, k].astype(_INFO_TYPES.get(key, np.float64))
                for k, key in enumerate(self.info_keys)}  # fmt: skip

    def info_dict(self, state: BatchState) -> dict[str, Any]:
        """Copy 0's last-step info as name -> Python scalar (bool and int entries typed)."""
        return self._info_of(state.info[0].tolist())

    def observe(self, state: BatchState) -> Any:
        """Recompute every copy's observation into ``state.obs`` and return it."""
        observe_all = self._kernels.observe_all
        observe_all(state.q, state.u, state.brake, state.elapsed_steps, self.num_horizon_steps,
                    self.dt, self._constants, state.obs)
        return state.obs

    def reset_copies(self, state: BatchState, indices: Any,
                     rngs: Sequence[np.random.Generator]) -> None:  # fmt: skip
        """Put the copies ``indices`` ((K,) int) at fresh start states, the k-th drawn from
        ``rngs[k]``, and write their observations into ``state.obs``.

        A start state is ``nominal_start()`` plus, on ``START_NOISE_ENTRIES``, the draws of
        ``rng.uniform(-reset_noise_scale, reset_noise_scale, len(START_NOISE_ENTRIES))``
        (computed here for all copies at once from one ``rng.random`` call per copy, with
        Generator.uniform's arithmetic, so the values are the same). Torques, brakes and
        impulses (the first step starts its solver cold), elapsed steps, effort and the
        termination flag restart from zero; Phi from the start state.
        """
        indices = np.asarray(indices, np.int64)
        entries = list(self.START_NOISE_ENTRIES)
        if len(rngs) != indices.size:
            raise ValueError(f"{len(rngs)} generators for {indices.size} copies")
        draws = np.array([rng.random(len(entries)) for rng in rngs]).reshape(
            indices.size, len(entries))
        low, high = -self.reset_noise_scale, self.reset_noise_scale
        starts = np.tile(self.nominal_start(), (indices.size, 1))
        starts[:, entries] += low + (high - low) * draws
        n = self.MODEL.NUM_DOFS
        state.q[indices] = starts[:, :n]
        state.u[indices] = starts[:, n:]
        self._kernels.restart(indices, state.buffer)

    def update_potential(self, state: BatchState, index: int) -> None:
        """Phi of copy ``index`` after its state was set from outside the step."""
        distance = self._kernels.distance_one(state.q[index], state.u[index], self._constants)
        state.potential[index] = -self.shaping_weight * distance


def state_fields(scene: MoreauJeanScene) -> tuple[tuple[str, int | None], ...]:
    """(name, width) of the per-copy ``BatchState`` arrays inside its buffer, in order.

    Width w makes an (N, w) array, None an (N,) array (one number per copy).
    """
    model, stepper = scene.MODEL, scene.stepper
    return (("q", model.NUM_DOFS), ("u", model.NUM_DOFS), ("tau", model.NUM_INPUTS),
            ("brake", model.NUM_BRAKES), ("impulses", stepper.num_impulses),
            ("step_impulses", stepper.num_impulses), ("physics", stepper.info_size),
            ("info", len(scene.info_keys)),
            ("elapsed_steps", None), ("effort", None), ("potential", None),
            ("terminated", None), ("reward", None))  # fmt: skip


class StateLayout(NamedTuple):
    """The layout of a ``BatchState`` buffer (see ``BatchState``), hashable.

    Attributes:
        fields: the per-copy arrays (``state_fields``).
        workspace_floats, workspace_ints: sizes of the stepper's scratch (``make_workspace``).
        num_observations: entries of one copy's float32 observation.
    """

    fields: tuple[tuple[str, int | None], ...]
    workspace_floats: int
    workspace_ints: int
    num_observations: int

    @classmethod
    def of(cls, scene: MoreauJeanScene) -> StateLayout:
        """The layout of ``scene``'s states."""
        floats, ints = scene.stepper.compiled_step_batch[2]
        return cls(state_fields(scene), floats.size, ints.size, scene.NUM_OBSERVATIONS)

    def size(self, num_copies: int, num_settings: int) -> int:
        """float64 entries of the buffer of ``num_copies`` copies and ``num_settings`` settings."""
        per_copy = sum(1 if width is None else width for _, width in self.fields)
        observation_slots = (num_copies * self.num_observations + 1) // 2
        return (1 + self.workspace_floats + self.workspace_ints + num_copies * per_copy
                + observation_slots + num_settings)  # fmt: skip


class BatchState:
    """The mutable state of N copies: physics arrays advanced in place, episode bookkeeping.

    Everything the compiled step reads and writes lives in one flat float64 ``buffer``, so that
    an env step passes it as one argument: N, the stepper's scratch (its int part read through
    an int64 view), the per-copy arrays of ``state_fields`` (C-contiguous float64, array after
    array), the float32 observations (a float32 view of ceil(N * NUM_OBSERVATIONS / 2) float64
    entries) and last a copy of the scene's settings (``MoreauJeanScene._settings_array``). The same
    generated function carves the views here (numpy) and inside the kernels (numba). Assign
    into them (``state.q[i] = ...``), never rebind them.

    Attributes:
        q, u: (N, n) coordinates and velocities.
        tau: (N, m) last torques [N m].
        brake: (N, k) last brake bounds (0 released, inf ideal).
        elapsed_steps: (N,) env steps (whole numbers).
        effort: (N,) integral of sum(tau^2) [N^2 m^2 s].
        potential: (N,) Phi of the current state.
        terminated: (N,) 1.0 if the last step ended the episode else 0.0.
        reward, obs, info: the last step's outputs, (N,), (N, NUM_OBSERVATIONS) float32 and
            (N, len(info_keys)).
        impulses, physics: the stepper's outputs of the last physics step (the impulses also
            warm-start the next step's solver for spatial contacts; zero after a reset),
            except the solver status in physics, the worst over the env step.
        step_impulses: (N, c*d + k) the impulses summed over the physics steps of the last
            env step (what ``info_one`` reports).
    """

    q: FloatArray
    u: FloatArray
    tau: FloatArray
    brake: FloatArray
    impulses: FloatArray
    step_impulses: FloatArray
    physics: FloatArray
    info: FloatArray
    elapsed_steps: FloatArray
    effort: FloatArray
    potential: FloatArray
    terminated: FloatArray
    reward: FloatArray
    obs: np.ndarray

    def __init__(self, scene: MoreauJeanScene, num_copies: int) -> None:
        self.num_copies = num_copies
        self.layout = StateLayout.of(scene)
        settings = scene._settings_array
        self.buffer = np.zeros(self.layout.size(num_copies, settings.size))
        self.buffer[0] = num_copies
        self.buffer[self.buffer.size - settings.size:] = settings
        self._take_views()

    def _take_views(self) -> None:
        names, carve, _ = _state_carver(self.layout)
        for name, view in zip(names, carve(self.buffer), strict=True):
            setattr(self, name, view)

    def __getstate__(self) -> dict[str, Any]:
        """Pickle the buffer, not its views (unpickled views would be copies)."""
        return {key: self.__dict__[key] for key in ("num_copies", "layout", "buffer")}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._take_views()


class MoreauJeanEnv(gym.Env[Any, Any]):
    """A single Gymnasium environment running one copy of a ``MoreauJeanScene``.

    Subclasses set ``SCENE`` and ``metadata`` and implement ``_draw`` (rendering). Like
    Gymnasium's MuJoCo base, it exposes ``dt``, ``set_state(q, u)`` and the model state.
    """

    SCENE: ClassVar[type[MoreauJeanScene]]
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 50}

    def __init__(self, render_mode: str | None = None, **options: Any) -> None:
        _require(render_mode is None or render_mode in self.metadata["render_modes"],
                 f"render_mode must be one of {self.metadata['render_modes']} or None, got "
                 f"{render_mode!r}")  # fmt: skip
        self.scene = self.SCENE(**options)
        self.observation_space = self.scene.single_observation_space
        self.action_space = self.scene.single_action_space
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": max(1, round(1.0 / self.scene.dt))}
        self.state = BatchState(self.scene, 1)
        self._viewer: Any = None
        self._has_reset = False

    @property
    def dt(self) -> float:
        """Duration of one env step [s] (time_step * frame_skip)."""
        return self.scene.dt

    @property
    def q(self) -> FloatArray:
        """Coordinates (n,) (a copy)."""
        return self.state.q[0].copy()

    @property
    def u(self) -> FloatArray:
        """Velocities (n,) (a copy)."""
        return self.state.u[0].copy()

    def set_state(self, q: Any, u: Any) -> None:
        """Overwrite the physical state; shapes (n,), finite values."""
        n = self.scene.MODEL.NUM_DOFS
        for name, value in (("q", q), ("u", u)):
            array = np.asarray(value, dtype=np.float64)
            _require(array.shape == (n,), f"{name} must have shape ({n},), got {array.shape}")
            _require(bool(np.isfinite(array).all()), f"{name} contains NaN or inf entries")
        self.state.q[0] = q
        self.state.u[0] = u
        self.state.impulses[0] = 0.0  # no warm start from another state
        self.scene.update_potential(self.state, 0)
        self.scene.observe(self.state)

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Advance by ``dt``; see the class docstring for rewards and ``info``."""
        if not self._has_reset:
            raise gym.error.ResetNeeded("call reset() before step()")
        state = self.state
        self.scene.advance(state, action)
        if self.render_mode == "human":
            self.render()
        return (state.obs[0].copy(), float(state.reward[0]), bool(state.terminated[0]), False,
                self.scene.info_dict(state))

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[Any, dict[str, Any]]:  # fmt: skip
        """Start a new episode (start state drawn from ``self.np_random``)."""
        super().reset(seed=seed)
        self.scene.reset_copies(self.state, _FIRST_COPY, (self.np_random,))
        self._has_reset = True
        if self.render_mode == "human":
            self.render()
        return self.state.obs[0].copy(), {}

    def render(self) -> Any:
        """Draw the scene: an (H, W, 3) uint8 array in "rgb_array" mode, a window in "human"."""
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode= to "
                            "gym.make")  # fmt: skip
            return None
        from mdi_envs.rendering import Viewer

        if self._viewer is None:
            self._viewer = Viewer(self.render_mode, render_fps=self.metadata["render_fps"],
                                  title=type(self).__name__)  # fmt: skip
        return self._viewer.show(self._draw())

    def _draw(self) -> Any:
        raise NotImplementedError

    def close(self) -> None:
        """Close the render window, if any."""
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None


class MoreauJeanVectorEnv(VectorEnv[Any, Any, Any]):
    """``num_envs`` copies of a ``MoreauJeanScene`` stepped in one compiled call.

    Autoreset: ``AutoresetMode.NEXT_STEP`` (Gymnasium's default): the step after an episode
    ends resets that copy (its action is ignored, reward 0, terminated = truncated = False).
    Each copy draws its start states from its own generator seeded ``seed + i``, as a
    ``SyncVectorEnv`` seeds its sub-environments, so both give the same episodes.
    """

    SCENE: ClassVar[type[MoreauJeanScene]]
    metadata: dict[str, Any] = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None,
                 render_mode: str | None = None, **options: Any) -> None:  # fmt: skip
        _require(isinstance(num_envs, (int, np.integer)) and num_envs >= 1,
                 f"num_envs must be a positive integer, got {num_envs!r}")
        _require(render_mode is None, "the vector environments do not render; use gym.make "
                 "for a rendered single environment")  # fmt: skip
        self.scene = self.SCENE(**options)
        self.num_envs = int(num_envs)
        self.max_episode_steps = max_episode_steps
        self.render_mode = None
        self.single_observation_space = self.scene.single_observation_space
        self.single_action_space = self.scene.single_action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.state = BatchState(self.scene, self.num_envs)
        self._rngs: list[np.random.Generator] = []
        self._autoreset = np.zeros(self.num_envs, np.bool_)
        self._step_mask = np.ones(self.num_envs, np.bool_)

    @property
    def dt(self) -> float:
        """Duration of one env step [s]."""
        return self.scene.dt

    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:  # fmt: skip
        """Reset every copy; ``seed`` an int (copy i gets seed + i), a list, or None.

        ``options={"reset_mask": mask}`` ((num_envs,) bool) resets only the masked copies, as
        Gymnasium's vector envs do; the others keep their state. A copy reset without a seed
        continues its own random stream (fresh entropy on the very first reset).
        """
        mask = np.ones(self.num_envs, np.bool_)
        if options is not None and "reset_mask" in options:
            mask = options["reset_mask"]
            _require(isinstance(mask, np.ndarray) and mask.dtype == np.bool_
                     and mask.shape == (self.num_envs,),
                     f"options['reset_mask'] must be a bool array of shape ({self.num_envs},)")
            _require(bool(mask.any()) and (bool(mask.all()) or bool(self._rngs)),
                     "options['reset_mask'] needs a True entry, and a full reset() first")
        if seed is None or isinstance(seed, (int, np.integer)):
            seeds = [None if seed is None else int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            _require(len(seeds) == self.num_envs,
                     f"seed list has {len(seeds)} entries for {self.num_envs} envs")
        if not self._rngs:
            self._rngs = [seeding.np_random(s)[0] for s in seeds]
        else:  # as gymnasium's Env.reset: a seed restarts the copy's stream, None continues it
            for i in np.flatnonzero(mask):
                if seeds[i] is not None:
                    self._rngs[i] = seeding.np_random(seeds[i])[0]
        if seed is not None:
            self._np_random, self._np_random_seed = seeding.np_random(seeds[0])
        indices = np.flatnonzero(mask)
        self.scene.reset_copies(self.state, indices, [self._rngs[i] for i in indices])
        self._autoreset[mask] = False
        return self.state.obs.copy(), {}

    def step(self, actions: Any) -> tuple[Any, FloatArray, BoolArray, BoolArray, dict[str, Any]]:
        """Advance every copy by ``dt`` (copies that ended last step are reset instead)."""
        if not self._rngs:
            raise gym.error.ResetNeeded("call reset() before step()")
        self.scene.advance(self.state, actions)
        reward = self.state.reward
        info = self.scene.info_arrays(self.state)
        terminated = self.state.terminated != 0.0
        if self.max_episode_steps is not None:
            truncated = self.state.elapsed_steps >= self.max_episode_steps
        else:
            truncated = np.zeros(self.num_envs, np.bool_)
        reward = reward.copy()
        resetting = np.flatnonzero(self._autoreset)
        if resetting.size:
            self.scene.reset_copies(self.state, resetting, [self._rngs[i] for i in resetting])
            reward[resetting] = 0.0
            terminated[resetting] = False
            truncated[resetting] = False
        self._autoreset = terminated | truncated
        mask = self._step_mask
        mask[:] = True
        mask[resetting] = False
        infos: dict[str, Any] = {}
        for key, value in info.items():
            infos[key] = value
            infos["_" + key] = mask.copy()
        return self.state.obs.copy(), reward, terminated, truncated, infos


_COMPILED: dict[tuple[Any, ...], SceneKernels] = {}
_FIRST_COPY = np.zeros(1, np.int64)
ADVANCE_OK, ADVANCE_ACTION_NOT_FINITE, ADVANCE_STATE_NOT_FINITE, ADVANCE_ACTION_SHAPE = 0, 1, 2, 3
"""Outcomes of the compiled ``advance``."""


def _state_carver(layout: StateLayout) -> tuple[tuple[str, ...], Any, Any]:
    """(names, carve, compiled carve): ``carve(buffer)`` returns the ``StateViews`` of a
    ``BatchState`` buffer from numpy arrays; the compiled one (inlined) inside the kernels.

    One generated source serves both, so the kernels and ``BatchState`` read the same layout;
    every width is a compile-time constant. Cached per layout.
    """
    if layout not in _CARVERS:
        floats, ints = layout.workspace_floats, layout.workspace_ints
        lines = ["def carve(buffer):",
                 "    N = int(buffer[0])",
                 f"    workspace_floats = buffer[1:{1 + floats}]",
                 f"    workspace_ints = buffer[{1 + floats}:{1 + floats + ints}].view(np.int64)"]
        start = str(1 + floats + ints)
        for name, width in layout.fields:
            end = f"{start} + N * {1 if width is None else width}"
            shape = "" if width is None else f".reshape((N, {width}))"
            lines.append(f"    {name} = buffer[{start}:{end}]{shape}")
            start = end
        k = layout.num_observations
        lines += [f"    obs = buffer[{start}:{start} + (N * {k} + 1) // 2].view(np.float32)"
                  f"[:N * {k}].reshape((N, {k}))",
                  f"    settings = buffer[{start} + (N * {k} + 1) // 2:]"]
        names = ("workspace_floats", "workspace_ints", *(name for name, _ in layout.fields),
                 "obs", "settings")
        if names != StateViews._fields:
            raise ValueError(f"state fields {names} differ from StateViews {StateViews._fields}")
        lines.append(f"    return StateViews({', '.join(names)})")
        namespace: dict[str, Any] = {"np": np, "StateViews": StateViews}
        define("\n".join(lines), namespace)
        carve = namespace["carve"]
        _CARVERS[layout] = (names, carve, njit(inline="always")(carve))
    return _CARVERS[layout]


_CARVERS: dict[StateLayout, tuple[tuple[str, ...], Any, Any]] = {}


def _info_builder(keys: tuple[str, ...]) -> Any:
    """A function from one info row (a list of floats, in ``keys`` order) to the info dict.

    Generated as a single dict display with the bool and int entries converted inline (a
    step's info dict then costs about a microsecond). Cached per ``keys``.
    """
    if keys not in _INFO_BUILDERS:
        entries = []
        for k, key in enumerate(keys):
            kind = _INFO_TYPES.get(key, float)
            value = (f"row[{k}] != 0.0" if kind is bool else f"int(row[{k}])" if kind is int
                     else f"row[{k}]")  # fmt: skip
            entries.append(f"{key!r}: {value}")
        namespace: dict[str, Any] = {}
        exec("def info_of(row):\n    return {" + ", ".join(entries) + "}",  # noqa: S102
             namespace)  # fmt: skip
        _INFO_BUILDERS[keys] = namespace["info_of"]
    return _INFO_BUILDERS[keys]


_INFO_BUILDERS: dict[tuple[str, ...], Any] = {}


def _reader(record_type: type[Any], start: int) -> Any:
    """A compiled, inlined ``read(settings)``: the ``record_type`` (a NamedTuple) rebuilt from
    the float64 entries ``settings[start:start + len(fields)]``, its ``int`` fields converted.

    The kernels read their ``EnvSettings``, parameter record and scene constants by name this
    way, from the end of the ``BatchState`` buffer, at no cost per step (the record is a value
    numba keeps in registers). Cached per (type, start).
    """
    key = (record_type, start)
    if key not in _READERS:
        hints = getattr(record_type, "__annotations__", {})
        entries = ", ".join(
            f"int(settings[{start + k}])" if hints.get(name) in (int, "int")
            else f"settings[{start + k}]"
            for k, name in enumerate(record_type._fields))  # type: ignore[attr-defined]
        namespace: dict[str, Any] = {"Record": record_type}
        define(f"def read(settings):\n    return Record({entries})", namespace)
        _READERS[key] = njit(inline="always")(namespace["read"])
    return _READERS[key]


_READERS: dict[tuple[type[Any], int], Any] = {}


def _compiled(scene: MoreauJeanScene) -> SceneKernels:
    """The batched kernels of ``scene``: compiled once per scene class, stepper kernel,
    parameter record type and state layout, per process.

    ``advance(levels, buffer)`` checks the levels' size and rank, decodes the actions, runs the
    physics substeps and then the rewards, observations and info of every copy in one compiled
    call (one dispatch from Python per env step), and returns an ``ADVANCE_*`` outcome. Its
    arguments are two arrays (each costs about 0.1 us to type per call, a tuple several):
    everything else is carved from the ``BatchState`` buffer inside (``StateViews``), the
    ``EnvSettings``, parameter record and scene constants rebuilt from its settings
    (``_reader``). The loop over the copies after the physics (``evaluate``) takes row views of
    every copy and is compiled without reference counting (``mdi_envs._borrowing``).
    """
    step_batch, record = scene.stepper.compiled_step_batch[:2]
    constants_type = scene.CONSTANTS
    layout = StateLayout.of(scene)
    key = (type(scene), step_batch, type(record), constants_type, layout)
    if key in _COMPILED:
        return _COMPILED[key]
    read_settings = _reader(EnvSettings, 0)
    read_record = _reader(type(record), len(EnvSettings._fields))
    read_constants = _reader(constants_type, len(EnvSettings._fields) + len(record))
    carve_state = _state_carver(layout)[2]
    num_torques = scene.MODEL.NUM_INPUTS
    width = num_torques + scene.MODEL.NUM_BRAKES  # of one copy's levels
    # inlined into ``evaluate``: no call per copy, and one copy's array views stay local
    observe_one = njit(inline="always")(scene.observe_one)
    distance_one = njit(inline="always")(scene.distance_one)
    success_one = njit(inline="always")(scene.success_one)
    info_one = njit(inline="always")(scene.info_one)

    @borrowing_njit
    def evaluate(q, u, tau, brake, impulses, physics, c, s, elapsed, effort, potential,  # noqa: ANN001
                 terminated, reward, obs, info):
        finite = True
        dt, horizon = s.dt, s.horizon_steps
        for i in range(q.shape[0]):
            qi, ui, bi, row = q[i], u[i], brake[i], info[i]
            for j in range(q.shape[1]):
                if not (np.isfinite(qi[j]) and np.isfinite(ui[j])):
                    finite = False
            elapsed[i] += 1
            rate = 0.0
            for j in range(tau.shape[1]):
                rate += tau[i, j] * tau[i, j]
            effort[i] += rate * dt
            d = distance_one(qi, ui, c)
            success = success_one(qi, ui, c)
            if horizon == 0:  # objective "time": success ends the episode
                objective = -dt
                ended = success
                goal = 0.0
            else:  # objective "effort" over a fixed horizon
                objective = -s.effort_weight * rate * dt
                ended = elapsed[i] >= horizon
                goal = -s.goal_weight * d if ended else 0.0
            phi = 0.0 if ended else -s.shaping_weight * d
            shaping = s.shaping_discount * phi - potential[i]
            potential[i] = phi
            reward[i] = objective + shaping + goal
            terminated[i] = 1.0 if ended else 0.0
            # info: BASE_INFO_KEYS, then the scene's INFO_KEYS
            row[0] = objective
            row[1] = shaping
            row[2] = goal
            row[3] = d
            row[4] = 1.0 if success else 0.0
            row[5] = elapsed[i] * dt
            row[6] = effort[i]
            row[7] = physics[i, INFO_STATUS]
            row[8] = physics[i, INFO_ITERATIONS]
            row[9] = physics[i, INFO_ACTIVE_CONTACTS]
            info_one(qi, ui, bi, impulses[i], physics[i], c, row[10:])
            time_left = (horizon - elapsed[i]) * dt if horizon > 0 else 0.0
            observe_one(qi, ui, bi, time_left, c, obs[i])
        return finite

    @njit
    def advance(levels, buffer):  # noqa: ANN001
        v = carve_state(buffer)
        if levels.ndim > 2 or levels.size != width * v.q.shape[0]:
            return ADVANCE_ACTION_SHAPE
        s = read_settings(v.settings)
        if not decode_levels(levels, num_torques, s.action_rule, s.max_torque,
                             s.max_brake_torque, v.tau, v.brake):  # fmt: skip
            return ADVANCE_ACTION_NOT_FINITE
        # one physics step at a time, to sum each copy's impulses over the env step
        record = read_record(v.settings)
        worst = np.zeros(v.q.shape[0])
        step_impulses = v.step_impulses
        step_impulses[:] = 0.0
        for _ in range(s.frame_skip):
            step_batch(v.q, v.u, v.tau, v.brake, s.time_step, record, 1, v.impulses, v.physics,
                       (v.workspace_floats, v.workspace_ints))  # fmt: skip
            step_impulses += v.impulses
            for i in range(v.q.shape[0]):
                worst[i] = max(worst[i], v.physics[i, INFO_STATUS])
        v.physics[:, INFO_STATUS] = worst
        finite = evaluate(v.q, v.u, v.tau, v.brake, step_impulses, v.physics,
                          read_constants(v.settings), s, v.elapsed_steps, v.effort, v.potential,
                          v.terminated, v.reward, v.obs, v.info)  # fmt: skip
        return ADVANCE_OK if finite else ADVANCE_STATE_NOT_FINITE

    @njit
    def observe_all(q, u, brake, elapsed, horizon, dt, c, obs):  # noqa: ANN001
        for i in range(q.shape[0]):
            time_left = (horizon - elapsed[i]) * dt if horizon > 0 else 0.0
            observe_one(q[i], u[i], brake[i], time_left, c, obs[i])

    @njit
    def restart(indices, buffer):  # noqa: ANN001
        """Zero the episode state of the copies ``indices`` (q, u already set), then their
        Phi and observation (see ``MoreauJeanScene.reset_copies``).
        """
        v = carve_state(buffer)
        s = read_settings(v.settings)
        c = read_constants(v.settings)
        for i in indices:
            v.tau[i, :] = 0.0
            v.brake[i, :] = 0.0
            v.impulses[i, :] = 0.0
            v.step_impulses[i, :] = 0.0
            v.elapsed_steps[i] = 0.0
            v.effort[i] = 0.0
            v.terminated[i] = 0.0
            v.potential[i] = -s.shaping_weight * distance_one(v.q[i], v.u[i], c)
            observe_one(v.q[i], v.u[i], v.brake[i], s.horizon_steps * s.dt, c, v.obs[i])

    frozen = freeze(f"scene_{type(scene).__name__}",
                    {"advance": advance, "observe_all": observe_all,
                     "distance_one": distance_one, "restart": restart})
    _COMPILED[key] = SceneKernels(**frozen)
    return _COMPILED[key]


__all__ = [
    "BatchState",
    "EnvSettings",
    "MoreauJeanEnv",
    "MoreauJeanScene",
    "MoreauJeanVectorEnv",
    "SceneKernels",
    "StateViews",
]
