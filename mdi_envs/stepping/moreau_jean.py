"""``MoreauJeanStepper``: the validated Python face of the compiled midpoint step.

One stepper serves one model class and parameter set: ``step`` advances a single state (for
tests, references and tooling), ``step_batch`` advances N independent copies, each with its own
state, inputs and brake commands, in one compiled call (for vector environments).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from mdi_envs._kernel_cache import freeze
from mdi_envs._types import FloatArray
from mdi_envs.mechanics.compiled import compile_equations
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.solvers.status import SolverStatus
from mdi_envs.stepping._kernel import (
    INFO_ACTIVE_CONTACTS,
    INFO_EQUALITIES,
    INFO_ITERATIONS,
    INFO_LCP_SIZE,
    INFO_SIZE,
    INFO_STATUS,
    StepShortcuts,
    make_step_kernels,
    make_workspace,
)
from mdi_envs.stepping._screen import INPUT_PROBLEMS, STATUS_OF_CODE, screen_inputs
from mdi_envs.stepping._spatial_kernel import (
    INFO_LIFTED_CONTACTS,
    INFO_MODE,
    SPATIAL_INFO_SIZE,
    make_spatial_step_kernels,
    make_spatial_workspace,
)
from mdi_envs.stepping.in_place import InPlaceStepper

_KERNELS: dict[tuple[type[ModelDefinition], StepShortcuts, bool], tuple[Any, Any]] = {}


class StepResult(NamedTuple):
    """One step's outcome.

    Attributes:
        q: (n,) coordinates at t + dt. u: (n,) velocities at t + dt.
        impulses: (c*d + k,) per contact P_N then P_T, then per brake P_B, over the step.
        status: the complementarity solve's status (CONVERGED when nothing had to be solved).
        num_iter: pivots or candidate sets of that solve.
        num_active_contacts: contacts closed at the step's midpoint.
        lcp_size: complementarity variables solved for. num_equalities: ideal brake rows.
        mode: the model's slip mode after the step (the robot's Table 1: 2, 3 or 5 DOF);
            0 for models without modes.
        num_lifted_contacts: load-transfer contacts whose load would be negative (P_N = 0, a
            wheel that would lift off); 0 for models without load transfer.
    """

    q: FloatArray
    u: FloatArray
    impulses: FloatArray
    status: SolverStatus
    num_iter: int
    num_active_contacts: int
    lcp_size: int
    num_equalities: int
    mode: int = 0
    num_lifted_contacts: int = 0


@dataclass
class MoreauJeanStepper:
    """Moreau-Jean midpoint time-stepping of one model.

    Args:
        model: the model class (a ``ModelDefinition`` subclass).
        parameters: its parameter dataclass instance (default: ``model.Parameters()``).
        time_step: dt [s], > 0.
        shortcuts: which exact shortcuts to take (default: all; see ``StepShortcuts``).
        locate_impacts: split a step in which a contact closes at the impact time (flight,
            impact law, rest of the step) instead of applying the impact at the step's
            midpoint, an O(|u| dt) error per impact. The impact time is the root of the gap's
            quadratic model over the step: exact for linear gaps under constant forces (the
            ball and the block: grid states equal the closed form to rounding); a contact the
            model leaves open at t* falls back to the midpoint rule. Up to 3 extra solves per
            impact step. Off by default (the midpoint scheme of docs/theory.md); models with
            contacts and without brakes only.

    Example:
        >>> from mdi_envs.mechanics.models.bouncing_ball import BouncingBall
        >>> stepper = MoreauJeanStepper(BouncingBall, time_step=1e-3)
        >>> result = stepper.step([0.0, 1.0], [0.0, 0.0], [0.0])
        >>> round(float(result.u[1]), 5)
        -0.00981
    """

    model: type[ModelDefinition]
    parameters: Any = None
    time_step: float = 1e-3
    shortcuts: StepShortcuts = StepShortcuts()
    locate_impacts: bool = False
    num_dofs: int = field(init=False)
    num_inputs: int = field(init=False)
    num_brakes: int = field(init=False)
    num_impulses: int = field(init=False)
    _values: Any = field(init=False, repr=False)
    _workspace: Any = field(init=False, repr=False)
    _step: Any = field(init=False, repr=False)
    _step_batch: Any = field(init=False, repr=False)
    _info_size: int = field(init=False, repr=False)
    _released: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not (isinstance(self.time_step, numbers.Real) and np.isfinite(self.time_step)
                and self.time_step > 0):
            raise ValueError(f"time_step must be a finite number > 0, got {self.time_step!r}")
        parameters_type = self.model.Parameters  # type: ignore[attr-defined]
        if self.parameters is None:
            self.parameters = parameters_type()
        if not isinstance(self.parameters, parameters_type):
            raise ValueError(
                f"parameters must be a {parameters_type.__name__} for {self.model.__name__}, "
                f"got {type(self.parameters).__name__}"
            )
        self._values = self.parameters.values()
        key = (self.model, self.shortcuts, bool(self.locate_impacts))
        spatial = self.model.CONTACT_DIMENSION == 3 and self.model.NUM_CONTACTS > 0
        if self.locate_impacts and (spatial or self.model.NUM_CONTACTS == 0
                                    or self.model.NUM_BRAKES > 0):
            raise ValueError(
                f"locate_impacts needs a model with planar contacts and without brakes; "
                f"{self.model.__name__} has {self.model.NUM_CONTACTS} contacts of dimension "
                f"{self.model.CONTACT_DIMENSION} and {self.model.NUM_BRAKES} brakes"
            )
        if key not in _KERNELS:
            equations = compile_equations(self.model)
            step, step_batch = (
                make_spatial_step_kernels(self.model, equations, self.shortcuts) if spatial
                else make_step_kernels(self.model, equations, self.shortcuts,
                                       self.locate_impacts)
            )  # fmt: skip
            frozen = freeze(f"step_{self.model.__name__}",
                            {"step": step, "step_batch": step_batch})
            _KERNELS[key] = (frozen["step"], frozen["step_batch"])
        self._step, self._step_batch = _KERNELS[key]
        if spatial:
            self._workspace = make_spatial_workspace(self.model)
            self._info_size = SPATIAL_INFO_SIZE
        else:
            self._workspace = make_workspace(self.model)
            self._info_size = INFO_SIZE
        m = self.model
        self.num_dofs = m.NUM_DOFS
        self.num_inputs = m.NUM_INPUTS
        self.num_brakes = m.NUM_BRAKES
        self._released = np.zeros(self.num_brakes)
        self.num_impulses = m.NUM_CONTACTS * m.CONTACT_DIMENSION + m.NUM_BRAKES

    def __reduce__(self) -> tuple[Any, ...]:
        """Pickle as the constructor's arguments.

        Compiled kernels and scratch arrays are rebuilt on loading.
        """
        return (type(self), (self.model, self.parameters, self.time_step, self.shortcuts,
                             self.locate_impacts))  # fmt: skip

    @property
    def compiled_step_batch(self) -> tuple[Any, Any, Any]:
        """(kernel, parameter record, workspace) for callers fusing the step into their kernels.

        ``kernel(q, u, tau, brake, dt, record, num_substeps, impulses, info, workspace)`` does
        what ``step_batch(..., check_inputs=False)`` does.
        """
        return self._step_batch, self._values, self._workspace

    @property
    def compiled_step(self) -> Any:
        """The single-step kernel behind ``step`` (no input checks).

        ``step(q, u, tau, brake, dt, record, q_out, u_out, impulses, info, workspace)``.
        """
        return self._step

    def in_place(self, q: Any, u: Any) -> InPlaceStepper:
        """An ``InPlaceStepper`` at (q, u): one copy stepped in place.

        One compiled call per step, the fastest single steps from Python (see
        ``mdi_envs.stepping.in_place``).
        """
        return InPlaceStepper(self, q, u)

    @property
    def info_size(self) -> int:
        """Columns of the per-copy diagnostics ``step_batch`` returns."""
        return self._info_size

    def step(
        self, q: Any, u: Any, tau: Any, brake_bound: Any = None, warm_start: Any = None
    ) -> StepResult:
        """Advance one state by one step.

        Args:
            q: (n,) coordinates. u: (n,) velocities. tau: (m,) inputs.
            brake_bound: (k,) brake bounds a >= 0 (0 released, ``np.inf`` ideal; default all
                released).
            warm_start: (c*d + k,) impulses the spatial contact solver starts from, usually
                the previous step's ``impulses`` (default: a cold start). Planar models solve
                exactly and ignore it. Where the rigid model leaves impulses undetermined
                (the robot's two wheels share the lateral load), it also selects the split.

        Raises:
            ValueError: wrong shapes, NaN/inf in q, u, tau, or a negative/NaN brake bound.
        """
        q_arr = self._vector(q, "q", self.num_dofs)
        u_arr = self._vector(u, "u", self.num_dofs)
        tau_arr = self._vector(tau, "tau", self.num_inputs)
        brake = (self._released if brake_bound is None
                 else self._vector(brake_bound, "brake_bound", self.num_brakes))
        problem = screen_inputs(q_arr, u_arr, tau_arr, brake)
        if problem:
            raise ValueError(INPUT_PROBLEMS[problem])
        q_out, u_out = np.empty(self.num_dofs), np.empty(self.num_dofs)
        impulses = (np.zeros(self.num_impulses) if warm_start is None
                    else self._vector(warm_start, "warm_start", self.num_impulses).copy())
        info = np.empty(self._info_size)
        self._step(q_arr, u_arr, tau_arr, brake, float(self.time_step), self._values,
                   q_out, u_out, impulses, info, self._workspace)
        mode, lifted = 0, 0
        if self._info_size == SPATIAL_INFO_SIZE:
            mode, lifted = int(info[INFO_MODE]), int(info[INFO_LIFTED_CONTACTS])
        return StepResult(
            q_out, u_out, impulses, STATUS_OF_CODE[int(info[INFO_STATUS])],
            int(info[INFO_ITERATIONS]), int(info[INFO_ACTIVE_CONTACTS]),
            int(info[INFO_LCP_SIZE]), int(info[INFO_EQUALITIES]), mode, lifted,
        )

    def step_batch(
        self,
        q: FloatArray,
        u: FloatArray,
        tau: Any,
        brake_bound: Any = None,
        num_substeps: int = 1,
        check_inputs: bool = True,
        out: tuple[FloatArray, FloatArray] | None = None,
    ) -> tuple[FloatArray, FloatArray]:
        """Advance N copies in place by ``num_substeps`` steps each, in one compiled call.

        Args:
            q: (N, n) float64 C-contiguous, overwritten. u: (N, n), overwritten.
            tau: (N, m) inputs. brake_bound: (N, k) bounds (default: all released).
            num_substeps: steps per call (>= 1).
            check_inputs: validate every argument (default). ``False`` is for callers that
                own arrays of the right shapes, dtypes and values (the vector environments):
                then tau and brake_bound must be C-contiguous float64 arrays, and nothing is
                checked.
            out: preallocated (impulses, info) arrays to write into, shapes as returned
                (only with ``check_inputs=False``; default: new arrays). Spatial models read
                the impulses first as each copy's warm start (the previous call's impulses;
                zeros: a cold start, as every call without ``out``).

        Returns:
            (impulses (N, c*d + k), info (N, INFO_SIZE)) of each copy's last step; the status
            column holds the worst status over the substeps. Spatial models report
            ``SPATIAL_INFO_SIZE`` columns (the planar ones, then mode, lifted contacts and
            solver residual; see ``mdi_envs.stepping._spatial_kernel``).

        Raises:
            ValueError: wrong shapes or dtypes, NaN/inf inputs, negative brake bounds.
        """
        if not check_inputs:
            if out is None:
                out = (np.zeros((q.shape[0], self.num_impulses)),
                       np.empty((q.shape[0], self._info_size)))  # fmt: skip
            impulses, info = out
            self._step_batch(q, u, tau, brake_bound, float(self.time_step), self._values,
                             int(num_substeps), impulses, info, self._workspace)
            return impulses, info
        for name, array in (("q", q), ("u", u)):
            if not (isinstance(array, np.ndarray) and array.dtype == np.float64
                    and array.flags.c_contiguous and array.ndim == 2
                    and array.shape[1] == self.num_dofs):
                raise ValueError(
                    f"{name} must be a C-contiguous float64 array of shape (N, {self.num_dofs})"
                )
            if not np.isfinite(array).all():
                raise ValueError(f"{name} contains NaN or inf entries")
        num_copies = q.shape[0]
        if u.shape[0] != num_copies:
            raise ValueError(f"u has {u.shape[0]} rows, q has {num_copies}")
        tau_arr = np.ascontiguousarray(tau, dtype=np.float64)
        if tau_arr.shape != (num_copies, self.num_inputs) or not np.isfinite(tau_arr).all():
            raise ValueError(
                f"tau must be finite with shape ({num_copies}, {self.num_inputs}), "
                f"got shape {tau_arr.shape}"
            )
        brake = self._brake(brake_bound, (num_copies, self.num_brakes))
        if int(num_substeps) != num_substeps or num_substeps < 1:
            raise ValueError(f"num_substeps must be a positive integer, got {num_substeps!r}")
        impulses = np.zeros((num_copies, self.num_impulses))  # a cold start
        info = np.empty((num_copies, self._info_size))
        self._step_batch(q, u, tau_arr, brake, float(self.time_step), self._values,
                         int(num_substeps), impulses, info, self._workspace)
        return impulses, info

    @staticmethod
    def _vector(value: Any, name: str, size: int) -> FloatArray:
        if not (type(value) is np.ndarray and value.dtype == np.float64
                and value.flags.c_contiguous):
            value = np.ascontiguousarray(value, dtype=np.float64)
        if value.shape != (size,):
            raise ValueError(f"{name} must have shape ({size},), got {value.shape}")
        return value

    @staticmethod
    def _brake(value: Any, shape: tuple[int, ...]) -> FloatArray:
        if value is None:
            return np.zeros(shape)
        array = np.ascontiguousarray(value, dtype=np.float64)
        if array.shape != shape:
            raise ValueError(f"brake_bound must have shape {shape}, got {array.shape}")
        if np.isnan(array).any() or (array < 0.0).any():
            raise ValueError("brake_bound must be >= 0 (0 released, inf ideal), got NaN or < 0")
        return array


__all__ = ["MoreauJeanStepper", "StepResult"]
