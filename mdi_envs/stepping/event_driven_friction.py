"""Event-driven integration of always-closed spatial Coulomb contacts with load transfer.

For models with ``HAS_LOAD_TRANSFER`` (the differential-drive robot): every contact is closed at
all times, its normal force follows the load law N = N0 + K F of the friction forces F (2c,)
(``model.normal_loads``), and each contact i either sticks (slip velocity gamma_i = W_i u = 0,
|F_i| <= mu_i N_i) or slides (F_i = -mu_i N_i gamma_i / |gamma_i|). W_i (2, n) are contact i's
two tangent rows (``model.contact_directions`` without its zero normal row); they depend on q,
and their rate W_i' u is evaluated exactly by forward-mode differentiation of the same rows.

A phase has a fixed set S of sticking contacts; the sliding ones (D) follow the force law with
their current slip direction e_i. Accelerations u' (n,) and forces F solve the linear system

    M u' - W^T F = h + B tau,
    W_i u' = -W_i' u                          for i in S (they stay stuck),
    F_i + mu_i e_i (N0_i + K_i F) = 0         for i in D,

and are integrated by ``solve_ivp`` (DOP853 by default) with event location. u' is unique; the
forces of sticking contacts need not be: contacts whose rows coincide (the robot's two wheels
share their lateral row, the axle) leave the split of their forces undetermined, along the null
space Z of the system (handled when Z is one-dimensional and leaves the loads unchanged, as for
the robot). A phase's *stick margin* is the best split's smallest cone margin,

    m = max_xi min_{i in S} (mu_i N_i - |F_i + Z_i xi|)    [N].

Events ending a phase: a sliding contact's slip speed |gamma_i| falling to ``slip_tolerance``;
the stick margin falling to 0; a switch of the piecewise-constant inputs (the time axis is cut
there). At each event the contacts at zero slip (the sticking ones and the one that stopped)
take their modes from the acceleration-level Coulomb law: each either sticks (gamma_i' = 0, F_i
in its cone, margin >= 0) or starts to slide (F_i = -mu_i N_i d_i with gamma_i' = lambda_i d_i,
lambda_i > 0, |d_i| = 1). That problem is small (at most c contacts) but not a standard one (the
sliding contacts' fixed directions and the load law couple it), so its candidates are
enumerated: the sets T of contacts that start to slide, by increasing size, the directions d_i
found by Newton's method (``scipy.optimize.root``) from the stuck force's opposite and from the
frictionless slip acceleration; the first consistent candidate is taken. After a stick-margin
event the stuck set that ran out of margin is excluded (at least one of its contacts slides).
A contact that starts to stick gets its slip removed exactly (a velocity change of at most
``slip_tolerance``, the smallest in the kinetic metric). A starting slide follows d_i until its
slip speed exceeds ``arm_speed``; from then on, gamma_i / |gamma_i|.

Events are reported as ``Event``s of kind ``stick`` or ``slip`` (element: the contact) and
``input_switch``; the modes at the start are ``stick``/``slip`` events at t_start.
Notation: q (n,) coordinates, u (n,) velocities, tau (m,) inputs, c contacts, F (2c,) friction
forces [N] in the tangent rows' directions, N (c,) normal forces [N].
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar, root

from mdi_envs._types import FloatArray
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.stepping.event_driven import (
    EVENT_INPUT_SWITCH,
    EVENT_START,
    STATUS_COMPLETED,
    STATUS_MAX_EVENTS,
    Event,
    PiecewiseConstant,
    Segment,
    Trajectory,
    assemble_trajectory,
)

EVENT_STICK = "stick"
EVENT_SLIP = "slip"
STATUS_UNDECIDED = "undecided_mode"  # no candidate of the acceleration-level law is consistent
GRAZING_RATE = 1e-9  # [m/s^2] a slip acceleration this small is zero (see ``_onset``)
EDGE_FORCE = 1e-6  # a stuck contact within this x the total static load of its cone's edge
_TOGETHER = 10.0  # at a stop, other slides with |gamma| <= this x slip_tolerance stop as well


class Inputs(Protocol):
    """Inputs tau(t) (m,), smooth between their switch times (``PiecewiseConstant`` is one)."""

    switch_times: FloatArray  # (K,) increasing [s]; the integration restarts at each

    def __call__(self, t: float) -> FloatArray:
        """The inputs (m,) at time t [s], right-continuous at the switch times."""
        ...


class _Dual:
    """A number a + b epsilon (epsilon^2 = 0): value and time derivative along u."""

    __slots__ = ("d", "v")

    def __init__(self, v: float, d: float) -> None:
        self.v, self.d = v, d

    def __add__(self, other: Any) -> _Dual:
        if isinstance(other, _Dual):
            return _Dual(self.v + other.v, self.d + other.d)
        return _Dual(self.v + other, self.d)

    __radd__ = __add__

    def __neg__(self) -> _Dual:
        return _Dual(-self.v, -self.d)

    def __sub__(self, other: Any) -> _Dual:
        return self + (-other)

    def __rsub__(self, other: Any) -> _Dual:
        return (-self) + other

    def __mul__(self, other: Any) -> _Dual:
        if isinstance(other, _Dual):
            return _Dual(self.v * other.v, self.d * other.v + self.v * other.d)
        return _Dual(self.v * other, self.d * other)

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> _Dual:
        if isinstance(other, _Dual):
            return _Dual(self.v / other.v, (self.d * other.v - self.v * other.d) / other.v ** 2)
        return _Dual(self.v / other, self.d / other)


class _DualOps:
    """The ``ops`` namespace of the model equations, for dual numbers (and plain floats)."""

    @staticmethod
    def cos(x: Any) -> Any:
        return _Dual(math.cos(x.v), -math.sin(x.v) * x.d) if isinstance(x, _Dual) else math.cos(x)

    @staticmethod
    def sin(x: Any) -> Any:
        return _Dual(math.sin(x.v), math.cos(x.v) * x.d) if isinstance(x, _Dual) else math.sin(x)



class EventDrivenFrictionIntegrator:
    """High-accuracy event-driven integration of a load-transfer model (module docstring).

    Args:
        model: a ``ModelDefinition`` with ``HAS_LOAD_TRANSFER`` and ``CONTACT_DIMENSION == 3``.
        parameters: its parameter dataclass (default: ``model.Parameters()``).
        method: ``solve_ivp`` method of the smooth phases.
        rtol, atol: ODE tolerances (relative; absolute in the units of q and u).
        slip_tolerance: [m/s] a slip speed at or below this is zero (a slide stops there).
        arm_speed: [m/s] a starting slide keeps its onset direction until its slip speed
            exceeds this (at least twice ``slip_tolerance``): below it the slip direction
            turns at a rate ~ 1/|gamma|, which would make the explicit ODE solver crawl.
        max_events: bound on the number of events (status ``max_events`` beyond it).

    Raises:
        ValueError: a model without load transfer or bad tolerances.
    """

    def __init__(self, model: type[ModelDefinition], parameters: Any = None, *,
                 method: str = "DOP853", rtol: float = 1e-11, atol: float = 1e-12,
                 slip_tolerance: float = 1e-10, arm_speed: float = 1e-6,
                 max_events: int = 10_000) -> None:
        if not model.HAS_LOAD_TRANSFER or model.CONTACT_DIMENSION != 3:
            raise ValueError(f"{model.__name__}: the friction integrator needs always-closed "
                             "spatial contacts with load transfer (HAS_LOAD_TRANSFER)")
        for name, value in (("rtol", rtol), ("atol", atol), ("slip_tolerance", slip_tolerance)):
            if not (np.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        self.model = model
        self.parameters = model.Parameters() if parameters is None else parameters  # type: ignore[attr-defined]
        self.method, self.rtol, self.atol = method, rtol, atol
        self.slip_tolerance = slip_tolerance
        self.arm_speed = max(arm_speed, 2.0 * slip_tolerance)
        self.max_events = int(max_events)
        self._p = self.parameters.values()
        self._n, self._m, self._c = model.NUM_DOFS, model.NUM_INPUTS, model.NUM_CONTACTS
        self.mu = np.array(model.friction_coefficients(self._p), dtype=np.float64)
        n0, k = model.normal_loads(self._p)
        self.n0 = np.array(n0, dtype=np.float64)  # (c,) [N]
        self.k = np.array(k, dtype=np.float64).reshape(self._c, 2 * self._c)
        self.force_tolerance = 1e-9 * float(np.abs(self.n0).sum())  # [N]
        self._tangent = np.delete(np.arange(3 * self._c), np.s_[::3])  # rows without normals

    # ---- equations ---------------------------------------------------------------------

    def tangent_rows(self, q: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(W (2c, n), W' u (2c,)): the contacts' tangent rows and their rate along u."""
        dual_q = [_Dual(float(a), float(b)) for a, b in zip(q, u, strict=True)]
        rows = self.model.contact_directions(dual_q, self._p, _DualOps)
        value = np.array([[x.v if isinstance(x, _Dual) else x for x in row] for row in rows])
        rate = np.array([[x.d if isinstance(x, _Dual) else 0.0 for x in row] for row in rows])
        return value[self._tangent], rate[self._tangent] @ u

    def _mass_and_force(self, q: FloatArray, u: FloatArray, tau: FloatArray
                        ) -> tuple[FloatArray, FloatArray]:
        model, p = self.model, self._p
        mass = np.array(model.mass_matrix(q, p, math), dtype=np.float64)
        smooth = np.array(model.forces(q, u, p, math), dtype=np.float64)
        inputs = np.array(model.input_matrix(q, p, math), dtype=np.float64)
        return mass, smooth + inputs.reshape(self._n, self._m) @ tau

    def accelerations(self, q: FloatArray, u: FloatArray, tau: FloatArray,
                      directions: dict[int, FloatArray]
                      ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Solve the phase's linear system (module docstring).

        Args:
            q, u: (n,) state. tau: (m,) inputs.
            directions: the sliding contacts, each with its unit slip direction e_i (2,); the
                other contacts stick.

        Returns:
            (u' (n,), F (2c,) the minimum-norm forces, Z (2c, k) the forces' null space).
        """
        n, c = self._n, self._c
        mass, force = self._mass_and_force(q, u, tau)
        W, rate = self.tangent_rows(q, u)
        A = np.zeros((n + 2 * c, n + 2 * c))
        b = np.zeros(n + 2 * c)
        A[:n, :n], A[:n, n:], b[:n] = mass, -W.T, force
        for i in range(c):
            rows = slice(n + 2 * i, n + 2 * i + 2)
            if i in directions:
                e = directions[i]
                A[rows, n + 2 * i: n + 2 * i + 2] = np.eye(2)
                A[rows, n:] += self.mu[i] * np.outer(e, self.k[i])
                b[rows] = -self.mu[i] * self.n0[i] * e
            else:
                A[rows, :n], b[rows] = W[2 * i: 2 * i + 2], -rate[2 * i: 2 * i + 2]
        U, s, Vt = np.linalg.svd(A)
        rank = int((s > 1e-12 * s[0]).sum())
        x = Vt[:rank].T @ ((U[:, :rank].T @ b) / s[:rank])
        return x[:n], x[n:], Vt[rank:, n:].T

    def contact_margins(self, forces: FloatArray, null: FloatArray, sticking: list[int]
                        ) -> dict[int, float]:
        """Per sticking contact, mu_i N_i - |F_i| [N] at the split that maximizes the smallest.

        Raises:
            NotImplementedError: a null space of dimension > 1, or one that changes the loads.
        """
        loads = self.n0 + self.k @ forces

        def margins(xi: float) -> dict[int, float]:
            moved = forces + xi * null[:, 0] if null.shape[1] else forces
            return {i: self.mu[i] * loads[i] - math.hypot(*moved[2 * i: 2 * i + 2])
                    for i in sticking}

        if not sticking or null.shape[1] == 0:
            return margins(0.0)
        if null.shape[1] > 1 or np.abs(self.k @ null).max() > 1e-9:
            raise NotImplementedError("stick margin: a force null space of dimension > 1 or one "
                                      "that changes the normal loads")
        z = null[:, 0]
        moving = [np.hypot(*z[2 * i: 2 * i + 2]) for i in sticking]
        if max(moving) < 1e-12:
            return margins(0.0)
        reach = max(np.hypot(*forces[2 * i: 2 * i + 2]) + self.mu[i] * abs(loads[i])
                    for i in sticking) / min(m for m in moving if m >= 1e-12)
        best = minimize_scalar(lambda xi: -min(margins(xi).values()), bounds=(-reach, reach),
                               method="bounded", options={"xatol": 1e-14 * reach,
                                                          "maxiter": 500})
        return max(margins(float(best.x)), margins(0.0), key=lambda m: min(m.values()))

    def stick_margin(self, forces: FloatArray, null: FloatArray, sticking: list[int]) -> float:
        """Stick margin m = max over the free split of min_{i in S} (mu_i N_i - |F_i|) [N]."""
        return min(self.contact_margins(forces, null, sticking).values(), default=math.inf)

    def slip_rates(self, q: FloatArray, u: FloatArray, accelerations: FloatArray) -> FloatArray:
        """Slip accelerations gamma' = W u' + W' u, (c, 2) [m/s^2]."""
        W, rate = self.tangent_rows(q, u)
        return (W @ accelerations + rate).reshape(self._c, 2)

    def slips(self, q: FloatArray, u: FloatArray) -> FloatArray:
        """Slip velocities gamma = W u, (c, 2) [m/s] (the rows in floats: no rate needed)."""
        rows = np.array(self.model.contact_directions(q, self._p, math), dtype=np.float64)
        return (rows[self._tangent] @ u).reshape(self._c, 2)

    # ---- the acceleration-level law at an event ---------------------------------------

    def decide(self, q: FloatArray, u: FloatArray, tau: FloatArray,
               sliding: dict[int, FloatArray], zero_slip: list[int],
               excluded_stuck: frozenset[int] = frozenset(),
               ) -> dict[int, FloatArray] | None:
        """Modes of the contacts at zero slip (module docstring).

        Args:
            q, u, tau: state and inputs at the event.
            sliding: the contacts that keep sliding, with their slip directions.
            zero_slip: the contacts whose mode is decided.
            excluded_stuck: if not empty (after a stick-margin event), candidates in which all
                of these stick are skipped, and those whose starting slides are the contacts at
                their cone's edge are tried first.

        Returns:
            The new sliding contacts with their directions (the kept ones and the starting
            ones), or None when no candidate is consistent.
        """
        candidates = [starting for size in range(len(zero_slip) + 1)
                      for starting in itertools.combinations(zero_slip, size)]
        if excluded_stuck:  # the contacts at their cone's edge first, all of them together
            _, forces, null = self.accelerations(q, u, tau, sliding)
            margins = self.contact_margins(forces, null, sorted(excluded_stuck))
            edge = [i for i, margin in margins.items() if margin <= EDGE_FORCE * self.n0.sum()]
            first = [starting for size in range(len(edge), 0, -1)
                     for starting in itertools.combinations(edge, size)]
            candidates = first + [s for s in candidates if s not in first]
        for starting in candidates:
            stuck = [i for i in zero_slip if i not in starting]
            if excluded_stuck and excluded_stuck.issubset(stuck):
                continue
            found = self._onset(q, u, tau, sliding, list(starting), stuck,
                                grazing=bool(excluded_stuck))
            if found is not None:
                return found
        return None

    def _onset(self, q: FloatArray, u: FloatArray, tau: FloatArray,
               sliding: dict[int, FloatArray], starting: list[int], stuck: list[int],
               grazing: bool = False) -> dict[int, FloatArray] | None:
        """The directions of the starting slides if this candidate is consistent, else None.

        ``grazing``: the event is a stick margin reaching 0, where the force of a contact that
        starts to slide is on its cone's edge and its slip acceleration lambda_i d_i is 0 at
        that instant (the slip grows as t^2); lambda_i = 0 is then accepted, and the first
        direction tried, opposite to the stuck force, is the one it leaves in.
        """
        lowest = -GRAZING_RATE if grazing else GRAZING_RATE
        def modes(angles: FloatArray) -> dict[int, FloatArray]:
            return {**sliding, **{i: np.array([math.cos(a), math.sin(a)])
                                  for i, a in zip(starting, angles, strict=True)}}

        def consistent(angles: FloatArray) -> dict[int, FloatArray] | None:
            chosen = modes(angles)
            accelerations, forces, null = self.accelerations(q, u, tau, chosen)
            rates = self.slip_rates(q, u, accelerations)
            for i in starting:
                along = float(chosen[i] @ rates[i])
                across = abs(chosen[i][0] * rates[i][1] - chosen[i][1] * rates[i][0])
                if along <= lowest or across > 1e-8 * (1.0 + abs(along)):
                    return None
            if self.stick_margin(forces, null, stuck) < -self.force_tolerance:
                return None
            return chosen

        if not starting:
            return consistent(np.empty(0))

        def residual(angles: FloatArray) -> FloatArray:
            chosen = modes(angles)
            rates = self.slip_rates(q, u, self.accelerations(q, u, tau, chosen)[0])
            return np.array([chosen[i][0] * rates[i][1] - chosen[i][1] * rates[i][0]
                             for i in starting])

        for guess in self._direction_guesses(q, u, tau, sliding, starting, stuck):
            # judged by ``consistent`` (the residual), not by ``root``'s flag, which reports
            # slow progress at round-off level as a failure
            found = consistent(root(residual, guess, method="hybr", options={"xtol": 1e-14}).x)
            if found is not None:
                return found
        return None

    def _direction_guesses(self, q: FloatArray, u: FloatArray, tau: FloatArray,
                           sliding: dict[int, FloatArray], starting: list[int],
                           stuck: list[int]) -> list[FloatArray]:
        """Start angles: opposite to the stuck forces, and the frictionless slip accelerations."""
        _, forces, _ = self.accelerations(q, u, tau, sliding)
        opposite = np.array([math.atan2(-forces[2 * i + 1], -forces[2 * i]) for i in starting])
        saved = self.mu.copy()
        try:
            self.mu[starting] = 0.0
            directions = {**sliding, **{i: np.array([1.0, 0.0]) for i in starting}}
            accelerations = self.accelerations(q, u, tau, directions)[0]
        finally:
            self.mu[:] = saved
        rates = self.slip_rates(q, u, accelerations)
        free = np.array([math.atan2(rates[i][1], rates[i][0]) for i in starting])
        turns = [np.full(len(starting), k * math.pi / 2.0) for k in range(4)]
        return [opposite, free] + [opposite + turn for turn in turns[1:]]

    # ---- a run -------------------------------------------------------------------------

    def simulate(self, q0: ArrayLike, u0: ArrayLike, t_final: float,
                 input_schedule: Inputs | None = None,
                 sample_times: ArrayLike | None = None, t_start: float = 0.0) -> Trajectory:
        """Integrate from (q0, u0) at t_start to t_final.

        Args:
            q0, u0: (n,) initial state.
            t_final: final time [s], > t_start.
            input_schedule: inputs tau(t), (m,)-valued (default: zero): piecewise constant or
                any ``Inputs``, smooth between its switch times.
            sample_times: (T,) report times [s] (default: the ODE steps and event times).
            t_start: initial time [s].

        Returns:
            The ``Trajectory`` (status ``completed``, ``max_events`` or ``undecided_mode``).

        Raises:
            ValueError: bad shapes, non-finite states or times.
        """
        q = np.array(q0, dtype=np.float64).reshape(-1)
        u = np.array(u0, dtype=np.float64).reshape(-1)
        if q.shape != (self._n,) or u.shape != (self._n,) or not (
                np.isfinite(q).all() and np.isfinite(u).all()):
            raise ValueError(f"q0 and u0 must be finite with shape ({self._n},)")
        if not (np.isfinite(t_final) and t_final > t_start):
            raise ValueError(f"t_final must be finite and > t_start={t_start}, got {t_final!r}")
        inputs = (PiecewiseConstant.constant(np.zeros(self._m)) if input_schedule is None
                  else input_schedule)
        if np.shape(inputs(t_start)) != (self._m,):
            raise ValueError(f"input_schedule must be ({self._m},)-valued")
        run = _FrictionRun(self, inputs, t_start, q, u)
        cuts = [float(x) for x in inputs.switch_times if t_start < x < t_final]
        for cut in [*cuts, float(t_final)]:
            run.integrate_until(cut)
            if run.status != STATUS_COMPLETED:
                break
            if cut < t_final:
                run.switch(cut)
        return assemble_trajectory(run.events, run.segments, run.t, run.status,
                                   run.num_rhs_evals, sample_times)


class _FrictionRun:
    """The mutable state of one ``simulate`` call."""

    def __init__(self, integrator: EventDrivenFrictionIntegrator, inputs: Inputs,
                 t: float, q: FloatArray, u: FloatArray) -> None:
        self.ig, self.inputs = integrator, inputs
        self.t, self.q, self.u = t, q, u
        self.sliding: dict[int, FloatArray] = {}
        self.armed: set[int] = set()
        self.events: list[Event] = []
        self.segments: list[Segment] = []
        self.status = STATUS_COMPLETED
        self.num_rhs_evals = 0
        self._identity = np.eye(integrator._n)
        self._record(EVENT_START, -1, u)
        slips = integrator.slips(q, u)
        for i in range(integrator._c):
            speed = float(np.hypot(*slips[i]))
            if speed > integrator.slip_tolerance:
                self.sliding[i] = slips[i] / speed
                self.armed.add(i)
                self._record(EVENT_SLIP, i, u)
        self._decide(frozenset(), initial=True)

    def _record(self, kind: str, element: int, u_minus: FloatArray) -> None:
        self.events.append(Event(self.t, kind, element, self.q.copy(), u_minus.copy(),
                                 self.u.copy(), np.zeros(0)))
        if len(self.events) > self.ig.max_events:
            self.status = STATUS_MAX_EVENTS

    def _tau(self) -> FloatArray:
        return self.inputs(self.t)

    def _decide(self, excluded_stuck: frozenset[int], stopped: tuple[int, ...] = (),
                initial: bool = False) -> None:
        """Modes of the contacts at zero slip; a contact that sticks has its slip removed.

        Records a ``slip`` event per starting slide and a ``stick`` event per contact of
        ``stopped`` (slides that just ended) that sticks, or per stuck contact if ``initial``.
        """
        ig = self.ig
        slips = ig.slips(self.q, self.u)
        for i in self.armed & set(self.sliding):  # the slides' current directions
            self.sliding[i] = slips[i] / np.hypot(*slips[i])
        zero_slip = [i for i in range(ig._c) if i not in self.sliding]
        if not zero_slip:
            return
        kept = dict(self.sliding)
        chosen = ig.decide(self.q, self.u, self._tau(), kept, zero_slip, excluded_stuck)
        if chosen is None:
            self.status = STATUS_UNDECIDED
            return
        u_minus = self.u.copy()
        self.sliding = chosen
        stuck = [i for i in range(ig._c) if i not in chosen]
        self._remove_slip(stuck)
        for i in stuck:
            if initial or i in stopped:
                self._record(EVENT_STICK, i, u_minus)
        for i in sorted(set(chosen) - set(kept)):
            self._record(EVENT_SLIP, i, u_minus)

    def _remove_slip(self, stuck: list[int]) -> None:
        """Replace u by the nearest u (kinetic metric) with zero slip at the ``stuck`` contacts."""
        if not stuck:
            return
        ig = self.ig
        W = ig.tangent_rows(self.q, self.u)[0]
        rows = np.concatenate([W[2 * i: 2 * i + 2] for i in stuck])
        mass, _ = ig._mass_and_force(self.q, self.u, self._tau())
        minv_rt = np.linalg.solve(mass, rows.T)
        correction = minv_rt @ np.linalg.lstsq(rows @ minv_rt, rows @ self.u, rcond=1e-12)[0]
        self.u = self.u - correction

    def switch(self, t: float) -> None:
        """An input switch at t: the zero-slip contacts' modes are decided anew."""
        self.t = t
        self._record(EVENT_INPUT_SWITCH, -1, self.u)
        self._decide(frozenset())

    def _phase(self, t_stop: float) -> tuple[Callable[[float, FloatArray], FloatArray],
                                             list[Callable[[float, FloatArray], float]],
                                             list[tuple[str, int]]]:
        """The right-hand side of a phase ending by t_stop, its event functions and labels.

        The inputs are their left limits at t_stop (a switch there acts on the next phase).
        """
        ig, n = self.ig, self.ig._n
        last = float(np.nextafter(t_stop, -np.inf))

        def inputs(t: float) -> FloatArray:
            return self.inputs(min(t, last))

        sliding, armed = dict(self.sliding), set(self.armed)
        stuck = [i for i in range(ig._c) if i not in sliding]

        def directions(q: FloatArray, u: FloatArray) -> dict[int, FloatArray]:
            slips = ig.slips(q, u)
            return {i: (slips[i] / np.hypot(*slips[i]) if i in armed else e)
                    for i, e in sliding.items()}

        def rhs(t: float, y: FloatArray) -> FloatArray:
            q, u = y[:n], y[n:]
            return np.concatenate([u, ig.accelerations(q, u, inputs(t), directions(q, u))[0]])

        def slip_event(i: int, level: float, direction: int
                       ) -> Callable[[float, FloatArray], float]:
            def event(t: float, y: FloatArray) -> float:
                return float(np.hypot(*ig.slips(y[:n], y[n:])[i])) - level
            event.terminal, event.direction = True, direction  # type: ignore[attr-defined]
            return event

        def margin(t: float, y: FloatArray) -> float:
            q, u = y[:n], y[n:]
            _, forces, null = ig.accelerations(q, u, inputs(t), directions(q, u))
            return ig.stick_margin(forces, null, stuck)

        margin.terminal, margin.direction = True, -1  # type: ignore[attr-defined]
        events, labels = [], []
        for i in sliding:  # an armed slide stops at the tolerance; a starting one arms
            stop = i in armed
            events.append(slip_event(i, ig.slip_tolerance if stop else ig.arm_speed,
                                     -1 if stop else 1))
            labels.append(("stop" if stop else "arm", i))
        if stuck:
            events.append(margin)
            labels.append(("margin", -1))
        return rhs, events, labels

    def integrate_until(self, t_stop: float) -> None:
        """Integrate phase after phase up to t_stop, handling the events on the way."""
        ig, n = self.ig, self.ig._n
        while self.t < t_stop and self.status == STATUS_COMPLETED:
            stuck = frozenset(i for i in range(ig._c) if i not in self.sliding)
            rhs, events, labels = self._phase(t_stop)
            solution = solve_ivp(rhs, (self.t, t_stop), np.concatenate([self.q, self.u]),
                                 method=ig.method, rtol=ig.rtol, atol=ig.atol,
                                 dense_output=True, events=events or None)
            if solution.status < 0:
                raise RuntimeError(f"solve_ivp failed at t={solution.t[-1]}: "
                                   f"{solution.message}")
            self.num_rhs_evals += solution.nfev
            t_new = float(solution.t[-1])
            if t_new > self.t:
                self.segments.append(Segment(self.t, t_new, solution.sol, np.zeros(n),
                                             self._identity))
            self.t, self.q, self.u = t_new, solution.y[:n, -1].copy(), solution.y[n:, -1].copy()
            if solution.status == 0:
                continue
            hits = [labels[k] for k, times in enumerate(solution.t_events) if times.size]
            self._handle(hits, stuck)

    def _handle(self, hits: list[tuple[str, int]], stuck: frozenset[int]) -> None:
        stopped = tuple(i for kind, i in hits if kind == "stop")
        if stopped:  # slides ending within a few tolerances of each other end together
            slips = self.ig.slips(self.q, self.u)
            stopped = tuple(sorted({*stopped, *(
                i for i in self.armed
                if np.hypot(*slips[i]) <= _TOGETHER * self.ig.slip_tolerance)}))
        for kind, i in hits:
            if kind == "arm":
                self.armed.add(i)
        for i in stopped:
            del self.sliding[i]
            self.armed.discard(i)
        if any(kind != "arm" for kind, _ in hits):
            excluded = stuck if any(kind == "margin" for kind, _ in hits) else frozenset()
            self._decide(excluded, stopped)
