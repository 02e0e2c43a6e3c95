"""``InPlaceStepper``: one state advanced in place by a single compiled call per step.

``MoreauJeanStepper.step`` validates and converts its arguments and returns a new
``StepResult`` each call (about 10 us from Python); this keeps the state, the inputs, the
parameters, the outputs and the solver's scratch in one flat float64 buffer that the compiled
step reads and writes, so that a step from Python costs one dispatch with one array argument
(below 1 us for the manipulator: numba types each array argument on every call). The inputs
are still screened, inside the compiled call, which raises the ValueError itself; ``step`` is
that call bound to the buffer (``functools.partial``), with no Python frame around it. It calls
the kernel's compiled entry point for the buffer's type (``Dispatcher.compile`` returns it),
not the dispatcher: the buffer's type never changes, so the dispatcher's per-call matching of
argument types against its overloads is skipped.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numba
import numpy as np

from mdi_envs._borrowing import borrowing_njit
from mdi_envs._kernel_cache import define, freeze
from mdi_envs._types import FloatArray
from mdi_envs.solvers.status import SolverStatus
from mdi_envs.stepping._kernel import INFO_STATUS
from mdi_envs.stepping._screen import INPUT_PROBLEMS, STATUS_OF_CODE, screen_inputs

if TYPE_CHECKING:  # the stepper builds an InPlaceStepper (MoreauJeanStepper.in_place)
    from mdi_envs.stepping.moreau_jean import MoreauJeanStepper

_KERNELS: dict[tuple[Any, type], Any] = {}


def _buffer_layout(stepper: MoreauJeanStepper) -> list[tuple[str, int]]:
    """(name, size) of the buffer's parts after the parameter record and dt, in order.

    Last the step's float and int scratch (``make_workspace``), the int part read through an
    int64 view of its float64 entries (zero bits: int zeros, as ``make_workspace`` sets them).
    """
    n, m, k = stepper.num_dofs, stepper.num_inputs, stepper.num_brakes
    floats, ints = stepper.compiled_step_batch[2]
    return [("q", n), ("u", n), ("tau", m), ("brake", k), ("q_next", n), ("u_next", n),
            ("impulses", stepper.num_impulses), ("info", stepper.info_size),
            ("float_scratch", floats.size), ("int_scratch", ints.size)]


def _make_kernel(stepper: MoreauJeanStepper) -> Any:
    """Compile ``step_in_place(buffer)`` around ``stepper.compiled_step``.

    It raises ValueError with the message of ``INPUT_PROBLEMS`` before touching the state
    when the screen finds a problem.
    """
    record = stepper.compiled_step_batch[1]
    start = len(record) + 1  # the record, then dt
    lines = ["def step_in_place(buffer):",
             "    p = Record(" + ", ".join(f"buffer[{i}]" for i in range(len(record))) + ")",
             f"    dt = buffer[{len(record)}]"]
    for name, size in _buffer_layout(stepper):
        lines.append(f"    {name} = buffer[{start}:{start + size}]")
        start += size
    lines += [
        "    problem = screen(q, u, tau, brake)",
        *(f"    if problem == {code}:\n        raise ValueError({message!r})"
          for code, message in enumerate(INPUT_PROBLEMS) if code > 0),
        "    step(q, u, tau, brake, dt, p, q_next, u_next, impulses, info,",
        "         (float_scratch, int_scratch.view(np.int64)))",
        f"    for i in range({stepper.num_dofs}):",
        "        q[i] = q_next[i]",
        "        u[i] = u_next[i]",
    ]
    namespace: dict[str, Any] = {"Record": type(record), "step": stepper.compiled_step,
                                 "screen": screen_inputs, "np": np}
    define("\n".join(lines), namespace)
    return borrowing_njit(namespace["step_in_place"])


class InPlaceStepper:
    """One copy of a ``MoreauJeanStepper``'s model, stepped in place.

    Build it with ``MoreauJeanStepper.in_place(q, u)``. Write the inputs into ``tau`` (m,) and
    ``brake_bound`` (k,) (or the state into ``q``, ``u``) as numpy arrays, in place, then call
    ``step()``; read ``q``, ``u`` (n,) and ``impulses`` (c*d + k,) afterwards. All are views
    into one buffer: assign with ``x[:] = ...``, never rebind.

    ``step()`` advances ``q``, ``u`` by one step under ``tau`` and ``brake_bound``, in place,
    and returns None. It raises ValueError (the state kept) for NaN/inf in q, u or tau, or a
    negative/NaN brake bound. It is the compiled kernel's entry point bound to the buffer, an
    attribute set per instance.

    Example:
        >>> from mdi_envs.mechanics import BlockableManipulator
        >>> from mdi_envs.stepping import MoreauJeanStepper
        >>> arm = MoreauJeanStepper(BlockableManipulator, time_step=1e-3).in_place(
        ...     [0.0, 0.0], [0.0, 0.0])
        >>> arm.tau[0] = 1.0
        >>> arm.step()
        >>> round(float(arm.u[0]), 6) > 0.0
        True
    """

    def __init__(self, stepper: MoreauJeanStepper, q: Any, u: Any) -> None:
        record = stepper.compiled_step_batch[1]
        key = (stepper.compiled_step, type(record))
        if key not in _KERNELS:
            _KERNELS[key] = freeze(f"in_place_{stepper.model.__name__}",
                                   {"step_in_place": _make_kernel(stepper)})["step_in_place"]
        layout = _buffer_layout(stepper)
        self._buffer = np.zeros(len(record) + 1 + sum(size for _, size in layout))
        self._buffer[: len(record)] = record
        self._buffer[len(record)] = stepper.time_step
        views = []
        start = len(record) + 1
        for _, size in layout:
            views.append(self._buffer[start:start + size])
            start += size
        self.q, self.u, self.tau, self.brake_bound, _, _, self.impulses, self._info, _, _ = views
        entry_point = _KERNELS[key].compile((numba.typeof(self._buffer),))
        self.step: Callable[[], None] = functools.partial(entry_point, self._buffer)
        for name, value in (("q", q), ("u", u)):
            array = np.asarray(value, dtype=np.float64)
            if array.shape != (stepper.num_dofs,):
                raise ValueError(f"{name} must have shape ({stepper.num_dofs},), "
                                 f"got {array.shape}")
            getattr(self, name)[:] = array

    @property
    def status(self) -> SolverStatus:
        """The last step's solve status (CONVERGED when nothing had to be solved)."""
        return STATUS_OF_CODE[int(self._info[INFO_STATUS])]

    @property
    def diagnostics(self) -> FloatArray:
        """The last step's stepper diagnostics (the ``INFO_*`` layout of ``step_batch``)."""
        return self._info.copy()


__all__ = ["InPlaceStepper"]
