"""The environment base classes: one batched task behind a single and a vector Gymnasium env.

Everything scene-specific -- spaces, action decoding, observations, goal distance, success --
lives in a ``MoreauJeanTask`` written once for a batch of N copies. ``MoreauJeanEnv`` runs it
with N = 1 and ``MoreauJeanVectorEnv`` with N = ``num_envs``; both advance the physics through
the same compiled ``MoreauJeanStepper.step_batch`` call, so the vector env equals a
``SyncVectorEnv`` of the single env step for step. The reward is assembled here, the same for
every task:

    reward = reward_objective + reward_shaping + reward_goal
    reward_objective = -dt                       (objective "time")
                     = -effort_weight sum(tau^2) dt   (objective "effort")
    reward_shaping   = gamma Phi(s') - Phi(s),   Phi = -shaping_weight * distance_to_goal,
                       with Phi(s') = 0 when the episode terminates (Ng et al. 1999: the optimal
                       policy of the discounted task with discount gamma is unchanged)
    reward_goal      = -goal_weight * distance_to_goal, once, when a fixed horizon ends.

The per-copy scene functions (observation, goal distance, success) are plain Python on scalars
and small arrays, compiled with numba into one batched kernel per task class, so that a single
``env.step`` costs two compiled calls (physics, then rewards and observations).
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numba import njit

from mdi_envs._types import BoolArray, FloatArray
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


class MoreauJeanTask:
    """Scene logic of one environment family, batched over N copies.

    Subclasses set ``MODEL``, ``NUM_OBSERVATIONS`` and ``OBJECTIVE_OPTIONS``, build the two
    single-copy spaces and implement the compiled ``observe_one``, ``distance_one`` and
    ``success_one`` with their ``constants``, plus ``initial_state``, ``decode_actions`` and
    ``info_one`` with ``INFO_KEYS``. Arrays are float64 of shape (N, ...), observations float32.

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
        self._constants_cache: FloatArray | None = None
        self._kernels: tuple[Any, Any, Any] | None = None
        self._info_keys = BASE_INFO_KEYS + self.INFO_KEYS
        self._typed_keys = tuple(
            (key, _INFO_TYPES[key]) for key in self._info_keys if key in _INFO_TYPES)
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
        self._settings = np.array([
            self.stepper.time_step, self.frame_skip, self.dt, self.num_horizon_steps,
            self.effort_weight, self.goal_weight, self.shaping_weight, self.shaping_discount,
            *self.stepper.compiled_step_batch[1],
        ])  # read by the compiled ``advance`` (see ``_compiled``), the model's record last

    def __getstate__(self) -> dict[str, Any]:
        """Pickle without the compiled kernels (rebuilt on first use)."""
        return {**self.__dict__, "_kernels": None}

    @property
    def _constants(self) -> FloatArray:
        if self._constants_cache is None:
            self._constants_cache = np.ascontiguousarray(self.constants(), dtype=np.float64)
        return self._constants_cache

    # -- scene-specific, implemented by each task ------------------------------------------
    # The three static methods below are compiled by numba (nopython): plain arithmetic on
    # floats and 1-D float64 arrays, scene constants read from ``c`` (``self.constants()``).
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
        """Whether one copy is at the goal at rest within the task's tolerances."""
        raise NotImplementedError

    def constants(self) -> FloatArray:
        """The scene constants ``c`` read by the compiled functions, float64 (any length)."""
        raise NotImplementedError

    def initial_state(self, rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
        """One copy's start (q (n,), u (n,)), drawn from ``rng`` only."""
        raise NotImplementedError

    def decode_actions(self, actions: Any, state: BatchState) -> None:
        """Validate a batch of actions and write ``state.tau`` [N m] and ``state.brake``."""
        raise NotImplementedError

    INFO_KEYS: ClassVar[tuple[str, ...]] = ()

    @staticmethod
    def info_one(q: Any, u: Any, brake: Any, impulses: Any, physics: Any, c: Any,
                 out: Any) -> None:  # fmt: skip
        """Write one copy's scene diagnostics (one value per ``INFO_KEYS`` entry) into ``out``.

        impulses: the last physics step's impulses (c*d + k,); physics: its stepper
        diagnostics (the ``mdi_envs.stepping`` INFO_* layout).
        """

    # -- shared ----------------------------------------------------------------------------
    @property
    def info_keys(self) -> tuple[str, ...]:
        """Names of the ``info`` entries of a step, in the order of ``state.info`` columns."""
        return self._info_keys

    def advance(self, state: BatchState) -> None:
        """Step the physics of every copy under ``state.tau`` and ``state.brake``, then the
        rewards, observations and info columns (all written into ``state``).

        Raises:
            RuntimeError: the physics produced a non-finite state.
        """
        if self._kernels is None:
            self._kernels = _compiled(type(self), *self.stepper.compiled_step_batch[:2])
        finite = self._kernels[0](
            state.q, state.u, state.tau, state.brake, state.impulses, state.physics,
            self._settings, self._constants, state.elapsed_steps, state.effort,
            state.potential, state.terminated, state.reward, state.obs, state.info,
            *self.stepper.compiled_step_batch[2],
        )
        if not finite:
            raise RuntimeError(
                "the physics step produced a non-finite state (solver status codes "
                f"{state.physics[:, INFO_STATUS].tolist()}); please report this with the seed"
            )

    def info_arrays(self, state: BatchState) -> dict[str, Any]:
        """The last step's info as name -> (N,) array (bool and int entries typed)."""
        return {key: state.info[:, k].astype(_INFO_TYPES.get(key, np.float64))
                for k, key in enumerate(self.info_keys)}  # fmt: skip

    def info_dict(self, state: BatchState) -> dict[str, Any]:
        """Copy 0's last-step info as name -> Python scalar."""
        info = dict(zip(self._info_keys, state.info[0].tolist(), strict=True))
        for key, kind in self._typed_keys:
            info[key] = kind(info[key])
        return info

    def observe(self, state: BatchState) -> Any:
        """Recompute every copy's observation into ``state.obs`` and return it."""
        observe_all = _compiled(type(self), *self.stepper.compiled_step_batch[:2])[1]
        observe_all(state.q, state.u, state.brake, state.elapsed_steps, self.num_horizon_steps,
                    self.dt, self._constants, state.obs)
        return state.obs

    def reset_copy(self, state: BatchState, index: int, rng: np.random.Generator) -> None:
        """Put copy ``index`` at a fresh start state drawn from ``rng``."""
        q, u = self.initial_state(rng)
        state.q[index] = q
        state.u[index] = u
        state.tau[index] = 0.0
        state.brake[index] = 0.0
        state.impulses[index] = 0.0  # the first step starts its solver cold
        state.elapsed_steps[index] = 0
        state.effort[index] = 0.0
        state.terminated[index] = False
        self.update_potential(state, index)

    def update_potential(self, state: BatchState, index: int) -> None:
        """Phi of copy ``index`` after its state was set from outside the step."""
        distance_one = _compiled(type(self), *self.stepper.compiled_step_batch[:2])[2]
        distance = distance_one(state.q[index], state.u[index], self._constants)
        state.potential[index] = -self.shaping_weight * distance

    def noise(self, rng: np.random.Generator, size: int) -> FloatArray:
        """Uniform start noise in [-reset_noise_scale, reset_noise_scale], (size,)."""
        return rng.uniform(-self.reset_noise_scale, self.reset_noise_scale, size)


class BatchState:
    """The mutable state of N copies: physics arrays advanced in place, episode bookkeeping.

    Attributes:
        q, u: (N, n) coordinates and velocities. tau: (N, m) last torques [N m].
        brake: (N, k) last brake bounds (0 released, inf ideal). elapsed_steps: (N,) env
        steps. effort: (N,) integral of sum(tau^2) [N^2 m^2 s]. potential: (N,) Phi of the
        current state. terminated: (N,) whether the last step ended the episode. reward (N,),
        obs (N, NUM_OBSERVATIONS) float32, info (N, len(info_keys)): the last step's outputs.
        impulses, physics: the stepper's outputs of the last physics step (the impulses also
        warm-start the next step's solver for spatial contacts; zero after a reset).
    """

    def __init__(self, task: MoreauJeanTask, num_copies: int) -> None:
        model = task.MODEL
        self.num_copies = num_copies
        self.q = np.zeros((num_copies, model.NUM_DOFS))
        self.u = np.zeros((num_copies, model.NUM_DOFS))
        self.tau = np.zeros((num_copies, model.NUM_INPUTS))
        self.brake = np.zeros((num_copies, model.NUM_BRAKES))
        self.elapsed_steps = np.zeros(num_copies, np.int64)
        self.effort = np.zeros(num_copies)
        self.potential = np.zeros(num_copies)
        self.terminated = np.zeros(num_copies, np.bool_)
        self.reward = np.zeros(num_copies)
        self.obs = np.zeros((num_copies, task.NUM_OBSERVATIONS), np.float32)
        self.info = np.zeros((num_copies, len(task.info_keys)))
        self.impulses = np.zeros((num_copies, task.stepper.num_impulses))
        self.physics = np.zeros((num_copies, task.stepper.info_size))


class MoreauJeanEnv(gym.Env[Any, Any]):
    """A single Gymnasium environment running one copy of a ``MoreauJeanTask``.

    Subclasses set ``TASK`` and ``metadata`` and implement ``_draw`` (rendering). Like
    Gymnasium's MuJoCo base, it exposes ``dt``, ``set_state(q, u)`` and the model state.
    """

    TASK: ClassVar[type[MoreauJeanTask]]
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 50}

    def __init__(self, render_mode: str | None = None, **options: Any) -> None:
        _require(render_mode is None or render_mode in self.metadata["render_modes"],
                 f"render_mode must be one of {self.metadata['render_modes']} or None, got "
                 f"{render_mode!r}")  # fmt: skip
        self.task = self.TASK(**options)
        self.observation_space = self.task.single_observation_space
        self.action_space = self.task.single_action_space
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": max(1, round(1.0 / self.task.dt))}
        self.state = BatchState(self.task, 1)
        self._viewer: Any = None
        self._has_reset = False

    @property
    def dt(self) -> float:
        """Duration of one env step [s] (time_step * frame_skip)."""
        return self.task.dt

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
        n = self.task.MODEL.NUM_DOFS
        for name, value in (("q", q), ("u", u)):
            array = np.asarray(value, dtype=np.float64)
            _require(array.shape == (n,), f"{name} must have shape ({n},), got {array.shape}")
            _require(bool(np.isfinite(array).all()), f"{name} contains NaN or inf entries")
        self.state.q[0] = q
        self.state.u[0] = u
        self.state.impulses[0] = 0.0  # no warm start from another state
        self.task.update_potential(self.state, 0)
        self.task.observe(self.state)

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Advance by ``dt``; see the class docstring for rewards and ``info``."""
        if not self._has_reset:
            raise gym.error.ResetNeeded("call reset() before step()")
        self.task.decode_actions(action, self.state)
        self.task.advance(self.state)
        if self.render_mode == "human":
            self.render()
        return (self.state.obs[0].copy(), float(self.state.reward[0]),
                bool(self.state.terminated[0]), False, self.task.info_dict(self.state))

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[Any, dict[str, Any]]:  # fmt: skip
        """Start a new episode (start state drawn from ``self.np_random``)."""
        super().reset(seed=seed)
        self.task.reset_copy(self.state, 0, self.np_random)
        self._has_reset = True
        if self.render_mode == "human":
            self.render()
        return self.task.observe(self.state)[0].copy(), {}

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
    """``num_envs`` copies of a ``MoreauJeanTask`` stepped in one compiled call.

    Autoreset: ``AutoresetMode.NEXT_STEP`` (Gymnasium's default): the step after an episode
    ends resets that copy (its action is ignored, reward 0, terminated = truncated = False).
    Each copy draws its start states from its own generator seeded ``seed + i``, as a
    ``SyncVectorEnv`` seeds its sub-environments, so both give the same episodes.
    """

    TASK: ClassVar[type[MoreauJeanTask]]
    metadata: dict[str, Any] = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None,
                 render_mode: str | None = None, **options: Any) -> None:  # fmt: skip
        _require(isinstance(num_envs, (int, np.integer)) and num_envs >= 1,
                 f"num_envs must be a positive integer, got {num_envs!r}")
        _require(render_mode is None, "the vector environments do not render; use gym.make "
                 "for a rendered single environment")  # fmt: skip
        self.task = self.TASK(**options)
        self.num_envs = int(num_envs)
        self.max_episode_steps = max_episode_steps
        self.render_mode = None
        self.single_observation_space = self.task.single_observation_space
        self.single_action_space = self.task.single_action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.state = BatchState(self.task, self.num_envs)
        self._rngs: list[np.random.Generator] = []
        self._autoreset = np.zeros(self.num_envs, np.bool_)
        self._step_mask = np.ones(self.num_envs, np.bool_)

    @property
    def dt(self) -> float:
        """Duration of one env step [s]."""
        return self.task.dt

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
        for i in np.flatnonzero(mask):
            self.task.reset_copy(self.state, int(i), self._rngs[i])
        self._autoreset[mask] = False
        return self.task.observe(self.state).copy(), {}

    def step(self, actions: Any) -> tuple[Any, FloatArray, BoolArray, BoolArray, dict[str, Any]]:
        """Advance every copy by ``dt`` (copies that ended last step are reset instead)."""
        if not self._rngs:
            raise gym.error.ResetNeeded("call reset() before step()")
        self.task.decode_actions(actions, self.state)
        self.task.advance(self.state)
        reward = self.state.reward
        info = self.task.info_arrays(self.state)
        terminated = self.state.terminated.copy()
        if self.max_episode_steps is not None:
            truncated = self.state.elapsed_steps >= self.max_episode_steps
        else:
            truncated = np.zeros(self.num_envs, np.bool_)
        reward = reward.copy()
        resetting = np.flatnonzero(self._autoreset)
        for i in resetting:
            self.task.reset_copy(self.state, int(i), self._rngs[i])
        if resetting.size:
            self.task.observe(self.state)
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


_COMPILED: dict[tuple[type[MoreauJeanTask], Any, type], tuple[Any, Any, Any]] = {}
SETTINGS_SIZE = 8
"""Entries of ``MoreauJeanTask._settings`` before the model's parameter record."""


def _compiled(task: type[MoreauJeanTask], step_batch: Any, record: Any
              ) -> tuple[Any, Any, Any]:  # fmt: skip
    """The batched kernels of ``task`` on the stepper kernel ``step_batch`` whose parameter
    record is like ``record`` (compiled once per task, kernel and record type, per process).

    Returns (advance, observe_all, distance_one). ``advance`` runs the physics substeps and
    then the rewards, observations and info of every copy in one compiled call (one dispatch
    from Python per env step). Its arguments are flat arrays only, the stepper's workspace
    last, unpacked: the record is rebuilt inside from the settings array, since each tuple
    argument costs microseconds of typing per call.
    """
    key = (task, step_batch, type(record))
    if key in _COMPILED:
        return _COMPILED[key]
    fields = ", ".join(f"settings[{SETTINGS_SIZE + i}]" for i in range(len(record)))
    namespace: dict[str, Any] = {"Record": type(record)}
    exec(f"def read_record(settings):\n    return Record({fields})", namespace)  # noqa: S102
    read_record = njit(inline="always")(namespace["read_record"])
    observe_one = njit(task.observe_one)
    distance_one = njit(task.distance_one)
    success_one = njit(task.success_one)
    info_one = njit(task.info_one)

    @njit
    def evaluate(q, u, tau, brake, impulses, physics, c, dt, horizon, effort_weight,  # noqa: ANN001
                 goal_weight, shaping_weight, discount, elapsed, effort, potential, terminated,
                 reward, obs, info):
        finite = True
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
            s = success_one(qi, ui, c)
            if horizon == 0:  # objective "time": success ends the episode
                objective = -dt
                ended = s
                goal = 0.0
            else:  # objective "effort" over a fixed horizon
                objective = -effort_weight * rate * dt
                ended = elapsed[i] >= horizon
                goal = -goal_weight * d if ended else 0.0
            phi = 0.0 if ended else -shaping_weight * d
            shaping = discount * phi - potential[i]
            potential[i] = phi
            reward[i] = objective + shaping + goal
            terminated[i] = ended
            # info: BASE_INFO_KEYS, then the scene's INFO_KEYS
            row[0] = objective
            row[1] = shaping
            row[2] = goal
            row[3] = d
            row[4] = 1.0 if s else 0.0
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
    def advance(q, u, tau, brake, impulses, physics, settings, c, elapsed,  # noqa: ANN001
                effort, potential, terminated, reward, obs, info, *workspace):
        step_batch(q, u, tau, brake, settings[0], read_record(settings), int(settings[1]),
                   impulses, physics, workspace)
        return evaluate(q, u, tau, brake, impulses, physics, c, settings[2], int(settings[3]),
                        settings[4], settings[5], settings[6], settings[7], elapsed, effort,
                        potential, terminated, reward, obs, info)

    @njit
    def observe_all(q, u, brake, elapsed, horizon, dt, c, obs):  # noqa: ANN001
        for i in range(q.shape[0]):
            time_left = (horizon - elapsed[i]) * dt if horizon > 0 else 0.0
            observe_one(q[i], u[i], brake[i], time_left, c, obs[i])

    _COMPILED[key] = (advance, observe_all, distance_one)
    return _COMPILED[key]


__all__ = ["BatchState", "MoreauJeanEnv", "MoreauJeanTask", "MoreauJeanVectorEnv"]
