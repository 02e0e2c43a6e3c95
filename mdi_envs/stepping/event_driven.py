"""Event-driven reference integrator: high-order smooth phases, impact laws at events.

Method (docs/theory.md, "Event-driven reference integrator"). Between events the motion is
smooth and integrated by ``scipy.integrate.solve_ivp`` (DOP853 by default, rtol 1e-10, atol
1e-12) with dense output and event location. A phase has a fixed set of active constraints: the
engaged (ideal) brakes and the contacts that stay closed, rows ``W_a`` (r, n), all constant in q
for the models handled here. Its motion is integrated drift-free in the null space of ``W_a``:
``q = q_a + N s``, ``u = N s'`` with ``W_a N = 0``, so a blocked relative angle stays constant to
round-off, and the accelerations and constraint forces come from the saddle-point system

    [[M, -W_a^T], [W_a, 0]] [u'; lambda] = [h + B tau; 0].

Events ending a phase:

* a scheduled switch (input or brake command; the time axis is cut at every switch time);
* an open contact closing: gap g_i(q) crossing zero downward;
* a contact that just separated reaching its maximum gap ("apex": gamma_N,i crossing zero
  downward); only then is its closing event armed, so that a phase starting at g_i ~ 0 cannot
  report a spurious closing or miss a short flight;
* a closed contact lifting off: its force lambda_i crossing zero downward.

At each event the impulse-level law is solved first: for the contacts at g_i <= gap tolerance,
Newton's law 0 <= P_N _|_ xi_N = gamma_N+ + eps gamma_N- >= 0, and for the engaged brakes the
plastic (eps = 0) bilateral law gamma_B+ = 0 with P_B free, from M (u+ - u-) = W_N^T P_N +
W_B^T P_B. The brake rows are eliminated by a Schur complement and the contact rows solved as an
LCP (``solve_lcp``). Then the acceleration-level LCP (the same structure with forces and
accelerations) decides which contacts with gamma_N+ = 0 stay closed (lambda_i > 0). A brake's
release is a mode change without a velocity jump.

Contacts are frictionless here (normal rows only): a model with mu > 0 is accepted as long as no
tangential relative velocity appears at a contact event (checked), as for a ball dropped
vertically. Brake commands are 0 (released) or inf (ideal brake); finite (Tresca) bounds are not
supported. Accumulations of impacts (Zeno) cannot be integrated event by event: the run stops
cleanly when two successive impacts of one contact are closer than ``min_flight_time``.

Notation: q (n,) coordinates, u (n,) velocities, M mass matrix, h forces, B input matrix, tau
(m,) inputs, W rows of contact normals (c, n) and brakes (k, n), eps restitution, P impulses.
Sampled velocities are left limits u(t-) (the state before the events at t), the convention of
the time-stepper, whose state at t_k precedes the impulses of the step starting there.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp
from scipy.linalg import null_space

from mdi_envs._types import FloatArray
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.mechanics.models.blockable_manipulator import BlockableManipulator
from mdi_envs.mechanics.models.bouncing_ball import BouncingBall
from mdi_envs.solvers import SolverStatus, solve_lcp

# Run outcomes (``Trajectory.status``).
STATUS_COMPLETED = "completed"
STATUS_ZENO = "zeno"
STATUS_MAX_EVENTS = "max_events"

# Event kinds (``Event.kind``).
EVENT_START = "start"
EVENT_IMPACT = "impact"
EVENT_APEX = "apex"
EVENT_LIFTOFF = "liftoff"
EVENT_BRAKE_ENGAGE = "brake_engage"
EVENT_BRAKE_RELEASE = "brake_release"
EVENT_INPUT_SWITCH = "input_switch"


@dataclass(frozen=True, init=False)
class PiecewiseConstant:
    """A piecewise-constant, right-continuous command: inputs tau(t) or brake bounds a(t).

    ``value(t) = values[i]`` with ``i`` the number of switch times ``<= t``: ``values[0]`` before
    the first switch, ``values[-1]`` after the last. A switch at t_s therefore acts from t_s on,
    as in the time-stepper, which holds the command of time t_k over the step [t_k, t_k + dt).

    Args:
        switch_times: (K,) strictly increasing finite times [s].
        values: (K + 1, m) values (inputs in their units, brake bounds in N m or N).

    Raises:
        ValueError: non-increasing or non-finite switch times, or a values shape other than
            (K + 1, m).

    Example:
        >>> schedule = PiecewiseConstant([1.0], [[2.0], [-2.0]])
        >>> float(schedule(0.5)[0]), float(schedule(1.0)[0])
        (2.0, -2.0)
    """

    switch_times: FloatArray
    values: FloatArray

    def __init__(self, switch_times: ArrayLike, values: ArrayLike) -> None:
        times = np.asarray(switch_times, dtype=np.float64).reshape(-1)
        values = np.asarray(values, dtype=np.float64)
        if values.ndim == 1:
            values = values[:, None]
        if not np.isfinite(times).all() or (np.diff(times) <= 0.0).any():
            raise ValueError(f"switch_times must be finite and strictly increasing: {times}")
        if values.ndim != 2 or values.shape[0] != times.size + 1:
            raise ValueError(
                f"values must have shape ({times.size + 1}, m) for {times.size} switch times, "
                f"got {values.shape}"
            )
        if np.isnan(values).any():
            raise ValueError("values contains NaN entries")
        object.__setattr__(self, "switch_times", times)
        object.__setattr__(self, "values", values)

    @classmethod
    def constant(cls, value: ArrayLike) -> PiecewiseConstant:
        """A command that never switches: ``value`` (m,) at all times."""
        return cls(np.empty(0), np.atleast_1d(np.asarray(value, dtype=np.float64))[None, :])

    def __call__(self, t: float) -> FloatArray:
        """The (m,) value at time t [s] (a copy)."""
        return self.values[int(np.searchsorted(self.switch_times, t, side="right"))].copy()


def bang_bang(max_torque: float, switch_times: ArrayLike, initial_sign: float = 1.0
              ) -> PiecewiseConstant:
    """A single-input bang-bang command: ``initial_sign * max_torque``, flipping at each switch.

    Args:
        max_torque: tau_max [N m] (or N), > 0.
        switch_times: (K,) increasing switching times [s].
        initial_sign: +1 or -1, the sign before the first switch.

    Returns:
        The (1,)-valued schedule.

    Raises:
        ValueError: max_torque <= 0 or initial_sign not +-1.
    """
    if not (np.isfinite(max_torque) and max_torque > 0.0):
        raise ValueError(f"max_torque must be a finite number > 0, got {max_torque!r}")
    if initial_sign not in (1.0, -1.0):
        raise ValueError(f"initial_sign must be +1 or -1, got {initial_sign!r}")
    times = np.asarray(switch_times, dtype=np.float64).reshape(-1)
    signs = initial_sign * (-1.0) ** np.arange(times.size + 1)
    return PiecewiseConstant(times, np.asarray(max_torque * signs, dtype=np.float64)[:, None])


def brake_schedule(engage_times: ArrayLike, release_times: ArrayLike = ()) -> PiecewiseConstant:
    """The bound a(t) of one ideal brake: inf (engaged) or 0 (released), released initially.

    Args:
        engage_times: times [s] at which the brake engages (an engagement at t = 0 blocks the
            initial state).
        release_times: times [s] at which it releases; the two lists must alternate, starting
            with an engagement.

    Returns:
        A (1,)-valued schedule of brake bounds, usable by both integrators.

    Raises:
        ValueError: the switches do not alternate engage/release.

    Examples:
        >>> schedule = brake_schedule([0.0, 1.0], [0.5])
        >>> [float(schedule(t)[0]) for t in (0.0, 0.7, 1.2)]
        [inf, 0.0, inf]
    """
    engage = np.asarray(engage_times, dtype=np.float64).reshape(-1)
    release = np.asarray(release_times, dtype=np.float64).reshape(-1)
    times = np.concatenate([engage, release])
    is_engage = np.concatenate([np.ones(engage.size, bool), np.zeros(release.size, bool)])
    order = np.argsort(times, kind="stable")
    times, is_engage = times[order], is_engage[order]
    if (is_engage[::2] != True).any() or (is_engage[1::2] != False).any():  # noqa: E712
        raise ValueError(
            f"engage {engage.tolist()} and release {release.tolist()} times must alternate, "
            "starting with an engagement"
        )
    values = np.concatenate([[0.0], np.where(is_engage, np.inf, 0.0)])
    return PiecewiseConstant(times, values[:, None])


class Event(NamedTuple):
    """One event of an event-driven run.

    Attributes:
        t: time [s].
        kind: one of ``start``, ``impact``, ``apex``, ``liftoff``, ``brake_engage``,
            ``brake_release``, ``input_switch``.
        element: the contact (impact, apex, liftoff) or brake (engage, release) concerned; -1
            for ``start`` and ``input_switch``.
        q: (n,) coordinates at t.
        u_minus: (n,) velocities before the event. u_plus: (n,) after it.
        impulses: (c + k,) the normal contact impulses P_N, then the brake impulses P_B, of the
            impact law solved at this event [N s or N m s]; zeros when nothing jumped.
    """

    t: float
    kind: str
    element: int
    q: FloatArray
    u_minus: FloatArray
    u_plus: FloatArray
    impulses: FloatArray


@dataclass(frozen=True)
class Segment:
    """A smooth phase on (t0, t1]: dense output of the reduced state and its map to (q, u)."""

    t0: float
    t1: float
    solution: Any  # scipy OdeSolution of z = (s, s')
    q_a: FloatArray
    N: FloatArray

    def evaluate(self, times: FloatArray) -> tuple[FloatArray, FloatArray]:
        z = np.atleast_2d(self.solution(times).T)
        d = self.N.shape[1]
        return self.q_a + z[:, :d] @ self.N.T, z[:, d:] @ self.N.T


@dataclass(frozen=True)
class Trajectory:
    """The outcome of an event-driven run.

    Attributes:
        t: (T,) sample times [s].
        q: (T, n) coordinates at the sample times (NaN after ``t_end``).
        u: (T, n) velocities, left limits u(t-) (NaN after ``t_end``).
        events: every event in time order, the ``start`` event first.
        t_end: the time reached [s]: t_final, or the time of the impact at which a Zeno
            accumulation was detected.
        status: ``completed``, ``zeno`` (stopped before an accumulation point) or ``max_events``.
        num_rhs_evals: right-hand-side evaluations of the ODE solver over the run.
    """

    t: FloatArray
    q: FloatArray
    u: FloatArray
    events: tuple[Event, ...]
    t_end: float
    status: str
    num_rhs_evals: int
    _segments: tuple[Segment, ...] = field(repr=False)

    def evaluate(self, times: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The state at arbitrary times, from the dense output.

        Args:
            times: (T,) times [s] in [t_start, t_end] (a time past t_end by a few ulps counts as
                t_end); others give NaN rows.

        Returns:
            (q (T, n), u (T, n)), u being the left limits u(t-); at the start time the initial
            state (before any event at t_start).
        """
        return _sample(self.events[0], self._segments, self.t_end, times)

    @property
    def final_state(self) -> tuple[FloatArray, FloatArray]:
        """(q, u) at ``t_end``, u the left limit, each (n,)."""
        q, u = self.evaluate([self.t_end])
        return q[0], u[0]

    def events_of(self, kind: str) -> list[Event]:
        """The events of one kind, in time order."""
        return [event for event in self.events if event.kind == kind]


def assemble_trajectory(events: list[Event], segments: list[Segment], t_end: float,
                        status: str, num_rhs_evals: int, sample_times: ArrayLike | None
                        ) -> Trajectory:
    """The ``Trajectory`` of a run: its events and smooth segments, sampled at ``sample_times``.

    Default sample times: the start and every step of the ODE solver.
    """
    start = events[0].t
    times = (np.unique(np.concatenate([[start]] + [s.solution.ts for s in segments]))
             if sample_times is None
             else np.atleast_1d(np.asarray(sample_times, dtype=np.float64)))
    q, u = _sample(events[0], tuple(segments), t_end, times)
    return Trajectory(times, q, u, tuple(events), t_end, status, num_rhs_evals, tuple(segments))


def _sample(start: Event, segments: tuple[Segment, ...], t_end: float, times: ArrayLike
            ) -> tuple[FloatArray, FloatArray]:
    """(q, u-) at ``times`` from the dense output (see ``Trajectory.evaluate``)."""
    times = np.atleast_1d(np.asarray(times, dtype=np.float64))
    # A time past t_end by round-off only (e.g. k * dt for the final step) means t_end.
    slack = 8.0 * np.finfo(np.float64).eps * max(1.0, abs(t_end))
    times = np.where((times > t_end) & (times <= t_end + slack), t_end, times)
    n = start.q.size
    q = np.full((times.size, n), np.nan)
    u = np.full((times.size, n), np.nan)
    at_start = times == start.t
    q[at_start], u[at_start] = start.q, start.u_minus
    for segment in segments:
        inside = (times > segment.t0) & (times <= segment.t1)
        if inside.any():
            q[inside], u[inside] = segment.evaluate(times[inside])
    return q, u


@dataclass
class _Phase:
    """Constraint set and inputs of one smooth phase, with its drift-free parametrization."""

    closed: list[int]  # contacts held closed (bilateral while lambda_i > 0)
    engaged: list[int]  # ideal brakes
    armed: list[int]  # open contacts whose closing is watched
    departing: list[int]  # open contacts whose apex is watched
    tau: FloatArray
    q_a: FloatArray
    N: FloatArray  # (n, n - r), W_a N = 0
    N_pinv: FloatArray  # (n - r, n)
    W_a: FloatArray  # (r, n) closed contact normals, then engaged brakes


class EventDrivenIntegrator:
    """High-accuracy event-driven integration of one model (see the module docstring).

    Args:
        model: the model class (a ``ModelDefinition``) with contact normals and brake rows
            constant in q (true for the ball and the manipulator; checked).
        parameters: its parameter dataclass (default: ``model.Parameters()``).
        method: ``solve_ivp`` method for the smooth phases (``"DOP853"`` or ``"Radau"``, ...).
        rtol, atol: ODE tolerances (relative; absolute in the units of q and u).
        min_flight_time: [s] a contact impacting again sooner than this after its previous
            impact stops the run (status ``zeno``).
        gap_tolerance: [m or rad] contacts with g_i <= this enter the impact law.
        velocity_tolerance: [m/s or rad/s] contacts with |gamma_N,i| <= this after an impact
            are candidates for staying closed.
        max_events: safety bound on the number of events (status ``max_events``).

    Raises:
        ValueError: bad tolerances. NotImplementedError: contact or brake rows depending on q.
    """

    def __init__(
        self,
        model: type[ModelDefinition],
        parameters: Any = None,
        *,
        method: str = "DOP853",
        rtol: float = 1e-10,
        atol: float = 1e-12,
        min_flight_time: float = 1e-6,
        gap_tolerance: float = 1e-10,
        velocity_tolerance: float = 1e-9,
        max_events: int = 100_000,
    ) -> None:
        for name, value in (("rtol", rtol), ("atol", atol), ("min_flight_time", min_flight_time),
                            ("gap_tolerance", gap_tolerance),
                            ("velocity_tolerance", velocity_tolerance)):
            if not (np.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        self.model = model
        self.parameters = model.Parameters() if parameters is None else parameters  # type: ignore[attr-defined]
        self.method = method
        self.rtol, self.atol = rtol, atol
        self.min_flight_time = min_flight_time
        self.gap_tolerance = gap_tolerance
        self.velocity_tolerance = velocity_tolerance
        self.max_events = int(max_events)
        self._p = self.parameters.values()
        n = model.NUM_DOFS
        self._n, self._m = n, model.NUM_INPUTS
        self._c, self._d, self._k = model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
        self._eps = np.array(model.restitutions(self._p), dtype=np.float64).reshape(self._c)
        self._mu = np.array(model.friction_coefficients(self._p), dtype=np.float64).reshape(
            self._c)
        # Constant rows, checked at two unrelated configurations.
        rows = [self._rows(np.full(n, value)) for value in (0.0, 0.7316)]
        if not all(np.array_equal(a, b) for a, b in zip(rows[0], rows[1], strict=True)):
            raise NotImplementedError(
                f"{model.__name__}: contact or brake directions depend on q; the event-driven "
                "integrator handles constant directions only"
            )
        self._Wc, self._Wb = rows[0]
        self._Wn = self._Wc[:: self._d] if self._c else np.empty((0, n))
        self._Wt = (np.delete(self._Wc, np.s_[:: self._d], axis=0) if self._c
                    else np.empty((0, n)))

    def _rows(self, q: FloatArray) -> tuple[FloatArray, FloatArray]:
        n = self._n
        Wc = np.array(self.model.contact_directions(q, self._p, math), dtype=np.float64)
        Wb = np.array(self.model.brake_directions(q, self._p, math), dtype=np.float64)
        return Wc.reshape(self._c * self._d, n), Wb.reshape(self._k, n)

    def mass_matrix(self, q: FloatArray) -> FloatArray:
        """M(q), (n, n)."""
        return np.array(self.model.mass_matrix(q, self._p, math), dtype=np.float64)

    def _force(self, q: FloatArray, u: FloatArray, tau: FloatArray) -> FloatArray:
        """h(q, u) + B(q) tau, (n,)."""
        h = np.array(self.model.forces(q, u, self._p, math), dtype=np.float64)
        B = np.array(self.model.input_matrix(q, self._p, math), dtype=np.float64)
        return h + B.reshape(self._n, self._m) @ tau

    def _gaps(self, q: FloatArray) -> FloatArray:
        return np.array(self.model.gaps(q, self._p, math), dtype=np.float64).reshape(self._c)

    def simulate(
        self,
        q0: ArrayLike,
        u0: ArrayLike,
        t_final: float,
        input_schedule: PiecewiseConstant | None = None,
        brake: PiecewiseConstant | None = None,
        sample_times: ArrayLike | None = None,
        t_start: float = 0.0,
    ) -> Trajectory:
        """Integrate from (q0, u0) at t_start to t_final.

        Args:
            q0: (n,) initial coordinates (no penetration: g_i(q0) >= -gap_tolerance).
            u0: (n,) initial velocities (before any event at t_start).
            t_final: final time [s], > t_start.
            input_schedule: inputs tau(t), (m,)-valued (default: zero).
            brake: brake bounds a(t), (k,)-valued, each 0 or inf (default: all released).
            sample_times: (T,) times [s] at which to report the state (default: the ODE
                solver's own steps and the event times).
            t_start: initial time [s].

        Returns:
            The ``Trajectory``.

        Raises:
            ValueError: bad shapes, non-finite states, initial penetration, or a brake bound
                other than 0 or inf. NotImplementedError: a tangential velocity at a frictional
                contact event. RuntimeError: an impact or contact LCP without a solution.
        """
        q = np.array(q0, dtype=np.float64).reshape(-1)
        u = np.array(u0, dtype=np.float64).reshape(-1)
        n = self._n
        if q.shape != (n,) or u.shape != (n,) or not (np.isfinite(q).all()
                                                       and np.isfinite(u).all()):
            raise ValueError(f"q0 and u0 must be finite with shape ({n},)")
        if not (np.isfinite(t_final) and t_final > t_start):
            raise ValueError(f"t_final must be finite and > t_start={t_start}, got {t_final!r}")
        inputs = (PiecewiseConstant.constant(np.zeros(self._m)) if input_schedule is None
                  else input_schedule)
        brakes = PiecewiseConstant.constant(np.zeros(self._k)) if brake is None else brake
        if inputs.values.shape[1] != self._m or brakes.values.shape[1] != self._k:
            raise ValueError(
                f"input_schedule must be ({self._m},)-valued and brake ({self._k},)-valued"
            )
        if not np.isin(brakes.values, (0.0, np.inf)).all():
            raise ValueError("brake bounds must be 0 (released) or inf (ideal brake); finite "
                             "(Tresca) bounds are not supported by the event-driven integrator")
        if (self._gaps(q) < -self.gap_tolerance).any():
            raise ValueError(f"initial penetration: gaps {self._gaps(q)}")

        run = _Run(self, inputs, brakes)
        run.start(t_start, q, u)
        switches = np.union1d(inputs.switch_times, brakes.switch_times)
        cuts = [float(x) for x in switches if t_start < x < t_final] + [float(t_final)]
        for cut in cuts:
            run.integrate_until(cut)
            if run.status != STATUS_COMPLETED:
                break
            if cut < t_final:
                run.switch(cut)
        return assemble_trajectory(run.events, run.segments, run.t, run.status,
                                   run.num_rhs_evals, sample_times)

    def _solve_mixed(self, Minv: NDArray[Any], W_u: NDArray[Any], W_e: NDArray[Any],
                     b_u: NDArray[Any], b_e: NDArray[Any]) -> tuple[FloatArray, FloatArray]:
        """Impulses (or forces) of unilateral rows W_u and bilateral rows W_e.

        Finds P_u >= 0 and P_e free with y = W_u Minv (W_u^T P_u + W_e^T P_e) + b_u >= 0,
        P_u . y = 0, and W_e Minv (W_u^T P_u + W_e^T P_e) + b_e = 0: the bilateral rows are
        eliminated by a Schur complement, the rest is LCP(A, r) solved by ``solve_lcp``.

        Args:
            Minv: (n, n). W_u: (a, n). W_e: (e, n). b_u: (a,). b_e: (e,).

        Returns:
            (P_u (a,), P_e (e,)).

        Raises:
            RuntimeError: the LCP has no solution (``solve_lcp`` did not converge).
        """
        G_uu = W_u @ Minv @ W_u.T
        G_ue = W_u @ Minv @ W_e.T
        G_ee = W_e @ Minv @ W_e.T
        if W_e.shape[0]:
            X = np.linalg.solve(G_ee, np.column_stack([G_ue.T, b_e]))
            A = G_uu - G_ue @ X[:, :-1]
            r = b_u - G_ue @ X[:, -1]
        else:
            X = np.empty((0, W_u.shape[0] + 1))
            A, r = G_uu, b_u
        P_u = np.zeros(W_u.shape[0])
        if W_u.shape[0]:
            result = solve_lcp(A, r)
            if result.status is not SolverStatus.CONVERGED:
                raise RuntimeError(f"contact LCP failed: {result.status.name} "
                                   f"(A={A.tolist()}, r={r.tolist()})")
            P_u = result.z
        P_e = -(X[:, -1] + X[:, :-1] @ P_u) if W_e.shape[0] else np.empty(0)
        return P_u, P_e

    def _check_frictionless(self, contacts: list[int], u: FloatArray, t: float) -> None:
        d = self._d - 1
        for i in contacts:
            if self._mu[i] > 0.0 and d > 0:
                slip = self._Wt[i * d:(i + 1) * d] @ u
                if np.abs(slip).max() > self.velocity_tolerance:
                    raise NotImplementedError(
                        f"contact {i} at t={t}: tangential velocity {slip} with mu="
                        f"{self._mu[i]}; the event-driven integrator is frictionless"
                    )

    def impact(self, q: FloatArray, u_minus: FloatArray, engaged: list[int]
               ) -> tuple[FloatArray, FloatArray]:
        """The impulse-level law at one instant.

        Contacts with g_i(q) <= gap_tolerance obey Newton's law with their eps; engaged brakes
        are plastic bilateral constraints gamma_B+ = 0 (an engagement with gamma_B- != 0 is a
        plastic impact). M (u+ - u-) = W_N^T P_N + W_B^T P_B.

        Args:
            q: (n,) coordinates. u_minus: (n,) velocities before. engaged: engaged brake indices.

        Returns:
            (u_plus (n,), impulses (c + k,): P_N per contact, then P_B per brake).
        """
        near = [i for i in range(self._c) if self._gaps(q)[i] <= self.gap_tolerance]
        impulses = np.zeros(self._c + self._k)
        if not near and not engaged:
            return u_minus.copy(), impulses
        Minv = np.linalg.inv(self.mass_matrix(q))
        W_u, W_e = self._Wn[near], self._Wb[engaged]
        b_u = (1.0 + self._eps[near]) * (W_u @ u_minus)
        P_u, P_e = self._solve_mixed(Minv, W_u, W_e, b_u, W_e @ u_minus)
        impulses[near] = P_u
        impulses[[self._c + j for j in engaged]] = P_e
        u_plus = u_minus + Minv @ (W_u.T @ P_u + W_e.T @ P_e)
        return u_plus, impulses

    def contact_forces(self, q: FloatArray, u: FloatArray, tau: FloatArray, contacts: list[int],
                       engaged: list[int]) -> FloatArray:
        """The acceleration-level LCP: forces lambda_i >= 0 of contacts with gamma_N,i = 0.

        0 <= lambda _|_ W_N u' >= 0 with M u' = h + B tau + W_N^T lambda + W_B^T lambda_B and
        W_B u' = 0 for the engaged brakes (rows constant, so gamma' = W u').

        Args:
            q, u: (n,) state. tau: (m,) inputs. contacts: candidate contacts. engaged: brakes.

        Returns:
            (len(contacts),) normal forces [N]; > 0 where the contact stays closed.
        """
        Minv = np.linalg.inv(self.mass_matrix(q))
        acc = Minv @ self._force(q, u, tau)
        W_u, W_e = self._Wn[contacts], self._Wb[engaged]
        lam, _ = self._solve_mixed(Minv, W_u, W_e, W_u @ acc, W_e @ acc)
        return lam


class _Run:
    """The mutable state of one ``simulate`` call: current time, state, mode, records."""

    def __init__(self, integrator: EventDrivenIntegrator, inputs: PiecewiseConstant,
                 brakes: PiecewiseConstant) -> None:
        self.ig = integrator
        self.inputs, self.brakes = inputs, brakes
        self.events: list[Event] = []
        self.segments: list[Segment] = []
        self.status = STATUS_COMPLETED
        self.num_rhs_evals = 0
        self.last_impact = np.full(integrator._c, -np.inf)
        self.t = 0.0
        self.q = np.empty(0)
        self.u = np.empty(0)
        self.closed: list[int] = []
        self.departing: set[int] = set()
        self.engaged: list[int] = []
        self.tau = np.empty(0)
        self._last_impulses = np.zeros(integrator._c + integrator._k)

    def _record(self, kind: str, element: int, u_minus: FloatArray,
                impulses: FloatArray | None = None) -> None:
        ig = self.ig
        self.events.append(Event(
            self.t, kind, element, self.q.copy(), u_minus.copy(), self.u.copy(),
            np.zeros(ig._c + ig._k) if impulses is None else impulses,
        ))
        if len(self.events) > ig.max_events:
            self.status = STATUS_MAX_EVENTS

    def start(self, t: float, q: FloatArray, u: FloatArray) -> None:
        self.t, self.q, self.u = t, q, u
        self.tau = self.inputs(t)
        self.engaged = [j for j in range(self.ig._k) if np.isinf(self.brakes(t)[j])]
        self._record(EVENT_START, -1, u)
        self._engage(self.engaged)

    def switch(self, t: float) -> None:
        """Apply the scheduled switches at t (inputs first, then brakes)."""
        self.t = t
        tau = self.inputs(t)
        if not np.array_equal(tau, self.tau):
            self.tau = tau
            self._record(EVENT_INPUT_SWITCH, -1, self.u)
        engaged = [j for j in range(self.ig._k) if np.isinf(self.brakes(t)[j])]
        for j in sorted(set(self.engaged) - set(engaged)):
            self._record(EVENT_BRAKE_RELEASE, j, self.u)
        newly = sorted(set(engaged) - set(self.engaged))
        self.engaged = engaged
        self._engage(newly)

    def _engage(self, newly: list[int]) -> None:
        """Resolve the current instant; record an engagement (with its impulse) per brake."""
        u_minus = self.u.copy()
        self._resolve()
        for j in newly:
            self._record(EVENT_BRAKE_ENGAGE, j, u_minus, self._last_impulses)

    def _resolve(self, closing: tuple[int, ...] = ()) -> None:
        """Impact law at the current instant, then the contacts that stay closed.

        Records an ``impact`` event for each contact in ``closing`` (detected closings) or
        receiving a normal impulse (e.g. an initial state already at the surface, moving in).
        """
        ig = self.ig
        u_minus = self.u
        self.u, self._last_impulses = ig.impact(self.q, u_minus, self.engaged)
        gaps = ig._gaps(self.q)
        near = [i for i in range(ig._c) if gaps[i] <= ig.gap_tolerance]
        ig._check_frictionless(near, u_minus, self.t)
        gamma = ig._Wn @ self.u
        candidates = [i for i in near if abs(gamma[i]) <= ig.velocity_tolerance]
        self.closed = []
        if candidates:
            lam = ig.contact_forces(self.q, self.u, self.tau, candidates, self.engaged)
            self.closed = [i for i, value in zip(candidates, lam, strict=True) if value > 0.0]
        # Open contacts at the surface separate: watch their apex before their next closing.
        self.departing = {i for i in near if i not in self.closed}
        # Remove round-off violations of the active constraints from u.
        W_a = np.vstack([ig._Wn[self.closed], ig._Wb[self.engaged]])
        if W_a.shape[0]:
            N = null_space(W_a)
            self.u = N @ (N.T @ self.u)
        for i in range(ig._c):
            if i in closing or self._last_impulses[i] > 0.0:
                self._record(EVENT_IMPACT, i, u_minus, self._last_impulses)

    def _phase(self) -> _Phase:
        ig = self.ig
        n = ig._n
        W_a = np.vstack([ig._Wn[self.closed], ig._Wb[self.engaged]]).reshape(-1, n)
        if W_a.shape[0]:
            N = null_space(W_a)
            N = N / np.abs(N).max(axis=0)  # e.g. (1, 1) exactly for one blocked relative angle
        else:
            N = np.eye(n)
        departing = sorted(self.departing)
        armed = [i for i in range(ig._c) if i not in self.closed and i not in self.departing]
        return _Phase(self.closed, self.engaged, armed, departing, self.tau, self.q.copy(), N,
                      np.linalg.pinv(N), W_a)

    def _dynamics(self, phase: _Phase) -> tuple[Callable[..., Any], Callable[..., Any]]:
        """(rhs(t, z), state(z) -> (q, u', lambda)) of the phase's reduced ODE.

        u' and the constraint forces lambda solve the saddle-point system
        [[M, -W_a^T], [W_a, 0]] [u'; lambda] = [h + B tau; 0]; with a constant mass matrix
        its inverse is formed once per phase.
        """
        ig = self.ig
        d = phase.N.shape[1]
        r = phase.W_a.shape[0]
        n = ig._n

        def saddle(M: FloatArray) -> FloatArray:
            K = np.zeros((n + r, n + r))
            K[:n, :n] = M
            K[:n, n:] = -phase.W_a.T
            K[n:, :n] = phase.W_a
            return K

        K_inv = (np.linalg.inv(saddle(ig.mass_matrix(phase.q_a)))
                 if ig.model.HAS_CONSTANT_MASS else None)
        rhs_tail = np.zeros(n + r)

        def state(z: FloatArray) -> tuple[NDArray[Any], NDArray[Any], NDArray[Any]]:
            q = phase.q_a + phase.N @ z[:d]
            u = phase.N @ z[d:]
            rhs_tail[:n] = ig._force(q, u, phase.tau)
            if K_inv is not None:
                sol = K_inv @ rhs_tail
            else:
                sol = np.linalg.solve(saddle(ig.mass_matrix(q)), rhs_tail)
            return q, sol[:n], sol[n:]

        def rhs(t: float, z: FloatArray) -> FloatArray:
            _, u_dot, _ = state(z)
            return np.concatenate([z[d:], phase.N_pinv @ u_dot])

        return rhs, state

    def _events(self, phase: _Phase, state: Callable[..., Any]
                ) -> tuple[list[Callable[..., float]], list[tuple[str, int]]]:
        """Terminal event functions of the phase (all downward crossings) and their labels."""
        ig = self.ig
        d = phase.N.shape[1]

        def make_event(kind: str, i: int) -> Callable[..., float]:
            if kind == EVENT_IMPACT:
                def event(t: float, z: FloatArray) -> float:
                    return float(ig._gaps(phase.q_a + phase.N @ z[:d])[i])
            elif kind == EVENT_APEX:
                def event(t: float, z: FloatArray) -> float:
                    return float(ig._Wn[i] @ (phase.N @ z[d:]))
            else:
                slot = phase.closed.index(i)

                def event(t: float, z: FloatArray) -> float:
                    return float(state(z)[2][slot])
            event.terminal = True  # type: ignore[attr-defined]
            event.direction = -1.0  # type: ignore[attr-defined]
            return event

        events: list[Callable[..., float]] = []
        labels: list[tuple[str, int]] = []
        for kind, contacts in ((EVENT_IMPACT, phase.armed), (EVENT_APEX, phase.departing),
                               (EVENT_LIFTOFF, phase.closed)):
            for i in contacts:
                events.append(make_event(kind, i))
                labels.append((kind, i))
        return events, labels

    def integrate_until(self, t_stop: float) -> None:
        """Integrate phase after phase up to t_stop, handling the events on the way."""
        ig = self.ig
        while self.t < t_stop and self.status == STATUS_COMPLETED:
            phase = self._phase()
            rhs, state = self._dynamics(phase)
            d = phase.N.shape[1]
            events, labels = self._events(phase, state)
            z0 = np.concatenate([np.zeros(d), phase.N_pinv @ self.u])
            sol = solve_ivp(rhs, (self.t, t_stop), z0, method=ig.method, rtol=ig.rtol,
                            atol=ig.atol, dense_output=True, events=events or None)
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed at t={sol.t[-1]}: {sol.message}")
            self.num_rhs_evals += sol.nfev
            t_new = float(sol.t[-1])
            self.segments.append(Segment(self.t, t_new, sol.sol, phase.q_a, phase.N))
            self.q = phase.q_a + phase.N @ sol.y[:d, -1]
            self.u = phase.N @ sol.y[d:, -1]
            self.t = t_new
            if sol.status == 0:
                continue
            hits = [labels[e] for e, times in enumerate(sol.t_events) if times.size]
            self._handle(hits)

    def _handle(self, hits: list[tuple[str, int]]) -> None:
        ig = self.ig
        impacts = [i for kind, i in hits if kind == EVENT_IMPACT]
        for kind, i in hits:
            if kind in (EVENT_APEX, EVENT_LIFTOFF):
                self._record(kind, i, self.u)
            if kind == EVENT_APEX:
                self.departing.discard(i)
        if impacts:
            self._resolve(tuple(impacts))
            for i in impacts:
                if self.t - self.last_impact[i] < ig.min_flight_time:
                    self.status = STATUS_ZENO
                self.last_impact[i] = self.t
        elif any(kind == EVENT_LIFTOFF for kind, _ in hits):
            self._resolve()


def simulate_manipulator(
    parameters: Any,
    q0: ArrayLike,
    u0: ArrayLike,
    torque_schedule: PiecewiseConstant,
    brake: PiecewiseConstant,
    t_final: float,
    sample_times: ArrayLike | None = None,
    **options: Any,
) -> Trajectory:
    """Event-driven run of the blockable manipulator under scheduled torque and brake.

    Args:
        parameters: ``BlockableManipulatorParameters`` (None for the defaults).
        q0: (2,) initial (alpha, beta) [rad]. u0: (2,) initial rates [rad/s].
        torque_schedule: motor torque tau(t) [N m], e.g. ``bang_bang(tau_max, [t_s])``.
        brake: brake bound a(t), e.g. ``brake_schedule([0.0, 1.072], [0.412])``.
        t_final: final time [s].
        sample_times: (T,) report times [s] (default: the solver's steps).
        **options: ``EventDrivenIntegrator`` options (``rtol``, ``atol``, ``method``, ...).

    Returns:
        The ``Trajectory``; each impactive engagement is a ``brake_engage`` event with its
        impulse P_B [N m s].

    Example:
        >>> trajectory = simulate_manipulator(
        ...     None, [0.0, 0.0], [0.0, 0.0], bang_bang(1.0, [0.5]), brake_schedule([0.2]), 1.0)
        >>> trajectory.status, [event.kind for event in trajectory.events[1:]]
        ('completed', ['brake_engage', 'input_switch'])
    """
    integrator = EventDrivenIntegrator(BlockableManipulator, parameters, **options)
    return integrator.simulate(q0, u0, t_final, torque_schedule, brake, sample_times)


def simulate_ball(
    parameters: Any,
    height: float,
    t_final: float,
    vertical_velocity: float = 0.0,
    sample_times: ArrayLike | None = None,
    **options: Any,
) -> Trajectory:
    """Event-driven run of the bouncing ball dropped vertically (x = 0, x' = 0, no input).

    With eps < 1 the impacts accumulate at t_inf = t_1 (1 + eps) / (1 - eps) after the first
    impact; the run stops at the first impact whose preceding flight was shorter than
    ``min_flight_time`` (status ``zeno``, ``t_end`` that impact's time). With eps = 0 the ball
    rests after its first impact (the contact stays closed to t_final).

    Args:
        parameters: ``BouncingBallParameters`` (None for the defaults).
        height: initial height of the centre y0 [m], >= radius.
        t_final: final time [s].
        vertical_velocity: initial y' [m/s].
        sample_times: (T,) report times [s] (default: the solver's steps).
        **options: ``EventDrivenIntegrator`` options (``min_flight_time``, ``rtol``, ...).

    Returns:
        The ``Trajectory``: ``impact`` events (times, P_N) and ``apex`` events (maximum heights).
    """
    integrator = EventDrivenIntegrator(BouncingBall, parameters, **options)
    return integrator.simulate([0.0, height], [0.0, vertical_velocity], t_final,
                               sample_times=sample_times)


__all__ = [
    "EVENT_APEX",
    "EVENT_BRAKE_ENGAGE",
    "EVENT_BRAKE_RELEASE",
    "EVENT_IMPACT",
    "EVENT_INPUT_SWITCH",
    "EVENT_LIFTOFF",
    "EVENT_START",
    "STATUS_COMPLETED",
    "STATUS_MAX_EVENTS",
    "STATUS_ZENO",
    "Event",
    "EventDrivenIntegrator",
    "PiecewiseConstant",
    "Trajectory",
    "bang_bang",
    "brake_schedule",
    "simulate_ball",
    "simulate_manipulator",
]
