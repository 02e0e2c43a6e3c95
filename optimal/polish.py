"""Continuous-time polish: switching times and t_f of a mode sequence, under exact events.

A reference is an optimum of the h-discretized problem; its mode sequence (bang-bang torque
arcs, engaged brake phases) is kept here and the times are made continuous. A
``SwitchingSchedule`` holds, per input, the switch times of a bang-bang command
(+-``torque_bound``) and, per brake, its engaged phases (engage, release) with
engage <= release: a phase may shrink to an instant (engage = release: a plastic lock of the
relative velocity, then released) and may end at t_f (engaged to the end; an instant at t_f is
an impulsive stop). ``simulate_schedule`` runs it through the project's event-driven
integrator (``mdi_envs.stepping.event_driven``: DOP853, the impact law at every engagement);
``polish`` minimizes t_f with SciPy's SLSQP over the gaps between consecutive times (bounds
>= 0 keep the order at every iterate; each brake's and input's gaps sum to the same t_f), the
goal (``problem.goal_q``, ``goal_u`` after the events at t_f) as equality constraints,
gradients by central differences (one-sided at an active bound). A brake engaged at t_f
stays engaged; its velocity goal is then stated in the directions the lock leaves free.

Only time-optimal problems of models the event-driven integrator handles (constant brake and
contact directions, frictionless contacts) with bang-bang inputs: the blockable manipulator and
the double integrator. The robot's stick-slip modes (Coulomb friction with load transfer,
contact directions turning with the heading) are outside it.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from scipy.linalg import null_space
from scipy.optimize import LinearConstraint, NonlinearConstraint, minimize

from mdi_envs._types import FloatArray
from mdi_envs.stepping.event_driven import EventDrivenIntegrator, PiecewiseConstant
from optimal.modes import ModePattern
from optimal.problems import model_of
from optimal.references import Reference
from optimal.transcription import OptimalControlProblem

RTOL, ATOL = 1e-12, 1e-14
"""The event-driven integrator's tolerances in the polish (DOP853)."""

DIFFERENCE_STEP = 1e-6
"""[s] Step of the central differences of the goal residuals in the switching times."""


@dataclass(frozen=True)
class SwitchingSchedule:
    """A mode sequence with its times.

    Attributes:
        switches: per input, its switch times [s] (increasing, in [0, t_f]).
        initial_signs: per input, +1 or -1: the sign of the bang-bang input before its first
            switch.
        phases: per brake, its engaged phases ((engage, release), ...) [s], ordered, each
            engage <= release <= next engage <= t_f.
        final_time: t_f [s].
    """

    switches: tuple[tuple[float, ...], ...]
    initial_signs: tuple[float, ...]
    phases: tuple[tuple[tuple[float, float], ...], ...]
    final_time: float

    def _chains(self) -> list[FloatArray]:
        return ([np.asarray(row, dtype=float) for row in self.switches]
                + [np.asarray(row, dtype=float).reshape(-1) for row in self.phases])

    def gaps(self) -> FloatArray:
        """The times as gaps: per input, then per brake, the differences of 0, its times, t_f."""
        return np.concatenate([np.diff([0.0, *chain, self.final_time])
                               for chain in self._chains()])

    def with_gaps(self, x: FloatArray) -> SwitchingSchedule:
        """The same sequence with the gaps ``x`` (see ``gaps``); t_f from the first chain."""
        sizes = np.cumsum([chain.size + 1 for chain in self._chains()])[:-1]
        times = [np.cumsum(part).tolist() for part in np.split(np.asarray(x, float), sizes)]
        k = len(self.switches)
        return dataclasses.replace(
            self, switches=tuple(tuple(row[:-1]) for row in times[:k]),
            phases=tuple(tuple(zip(row[:-1:2], row[1::2], strict=True)) for row in times[k:]),
            final_time=times[0][-1])

    def chain_totals(self) -> FloatArray:
        """(chains, len(gaps)) rows summing each chain's gaps (each total is t_f)."""
        sizes = [chain.size + 1 for chain in self._chains()]
        edges = np.concatenate([[0], np.cumsum(sizes)])
        rows = np.zeros((len(sizes), edges[-1]))
        for i, (a, b) in enumerate(zip(edges, edges[1:], strict=False)):
            rows[i, a:b] = 1.0
        return rows

    def as_dict(self) -> dict[str, Any]:
        """Plain-JSON form."""
        return {"final_time": self.final_time, "input_switches": [list(r) for r in self.switches],
                "initial_signs": list(self.initial_signs),
                "brake_phases": [[list(p) for p in row] for row in self.phases]}


def schedule_from_reference(reference: Reference) -> SwitchingSchedule:
    """The mode sequence of an h-discrete reference, with its times as the starting point.

    Inputs: a switch where the sign of tau changes, inside whichever of the two intervals there
    is further from the bound, at the fraction f where the held value is the switch's average
    (tau = (2 f - 1) bound x the old sign). Brakes:
    each run of engaged intervals is one phase from its first interval's start to its last's
    end.

    Raises:
        ValueError: a reference that is not time-optimal.
    """
    if reference.metadata["cost_kind"] != "time":
        raise ValueError(f"{reference.name}: the polish handles time-optimal problems only")
    time, tau = reference.time, reference.tau / reference.metadata["torque_bound"]
    switches, signs = [], []
    for column in tau.T:
        sign = np.where(column >= 0.0, 1.0, -1.0)
        changes = np.flatnonzero(sign[1:] != sign[:-1])
        times = []
        for k in changes:  # the switch lies in interval k or k + 1, where |tau| < 1
            j = k if abs(column[k]) < abs(column[k + 1]) else k + 1
            fraction = (1.0 + sign[k] * column[j]) / 2.0  # held value (2 f - 1) x old sign
            times.append(float(time[j] + fraction * (time[j + 1] - time[j])))
        switches.append(tuple(times))
        signs.append(float(sign[0]))
    phases = []
    engaged = np.isinf(reference.brake_bound) if reference.brake_bound is not None else np.zeros(
        (tau.shape[0], 0), bool)
    for row in engaged.T:
        edges = np.flatnonzero(np.diff(np.concatenate([[0], row.astype(int), [0]])))
        phases.append(tuple((float(time[a]), float(time[b])) for a, b in edges.reshape(-1, 2)))
    return SwitchingSchedule(tuple(switches), tuple(signs), tuple(phases),
                             float(reference.final_time))


class ScheduleRun(NamedTuple):
    """An event-driven run of a schedule: the end state and optional samples.

    Attributes:
        q, u: (n,) q(t_f) and u(t_f+), after the events at t_f.
        q_samples, u_samples: (T, n) at the sample times (u the left limits), or (0, n).
    """

    q: FloatArray
    u: FloatArray
    q_samples: FloatArray
    u_samples: FloatArray


def simulate_schedule(integrator: EventDrivenIntegrator, problem: OptimalControlProblem,
                      schedule: SwitchingSchedule, sample_times: FloatArray | None = None
                      ) -> ScheduleRun:
    """Run ``schedule`` from the problem's initial state to t_f.

    Each interval between consecutive times runs with its torques and engaged brakes
    (``EventDrivenIntegrator.simulate``, whose start resolves the engagement's impact);
    instant phases are applied as plastic locks (``EventDrivenIntegrator.impact``). Times out
    of order (an optimizer's trial point) are sorted per row and clipped to [0, t_f].

    Args:
        integrator: for ``problem.model``. problem: start state and torque bound.
        schedule: the mode sequence and times. sample_times: (T,) times [s], within [0, t_f].
    """
    t_f = schedule.final_time
    rows = [np.clip(np.maximum.accumulate(np.asarray(row, dtype=float)), 0.0, t_f)
            for row in schedule.switches]
    phases = [np.clip(np.maximum.accumulate(np.asarray(row, dtype=float).reshape(-1)), 0.0, t_f
                      ).reshape(-1, 2) for row in schedule.phases]
    cuts = np.unique(np.concatenate([[0.0, t_f], *rows, *(p.ravel() for p in phases)]))
    q, u = np.array(problem.initial_q, dtype=float), np.array(problem.initial_u, dtype=float)
    times = np.empty(0) if sample_times is None else np.asarray(sample_times, dtype=float)
    q_samples, u_samples = np.tile(q, (times.size, 1)), np.tile(u, (times.size, 1))
    for a, b in zip(cuts, [*cuts[1:], None], strict=True):
        locks = [j for j, p in enumerate(phases) if ((p[:, 0] == a) & (p[:, 1] == a)).any()]
        if locks:
            u = integrator.impact(q, u, locks)[0]
        if b is None:
            break
        tau = [sign * problem.torque_bound * (-1.0) ** np.searchsorted(row, a, side="right")
               for sign, row in zip(schedule.initial_signs, rows, strict=True)]
        engaged = [np.inf if ((p[:, 0] <= a) & (p[:, 1] >= b)).any() else 0.0 for p in phases]
        inside = (times > a) & (times <= b)
        run = integrator.simulate(q, u, b, PiecewiseConstant.constant(tau),
                                  PiecewiseConstant.constant(engaged) if phases else None,
                                  sample_times=times[inside], t_start=a)
        q_samples[inside], u_samples[inside] = run.q, run.u
        q, u = run.final_state
    return ScheduleRun(q, u, q_samples, u_samples)


def pattern_on_grid(schedule: SwitchingSchedule, num_intervals: int) -> ModePattern:
    """The brake modes of ``schedule`` on N equal intervals of [0, t_f].

    An interval is engaged when an engaged phase covers its midpoint; a phase covering no
    midpoint (short, or an instant) engages the interval it starts in (a lock at t_f: the
    last one, whose step ends with the relative velocity zero).
    """
    h = schedule.final_time / num_intervals
    middle = (np.arange(num_intervals) + 0.5) * h
    engaged = np.zeros((len(schedule.phases), num_intervals), dtype=bool)
    for row, phases in zip(engaged, schedule.phases, strict=True):
        for start, end in phases:
            covered = (middle >= start) & (middle <= end)
            row[covered] = True
            if not covered.any():
                row[min(int(start / h), num_intervals - 1)] = True
    return ModePattern(engaged=engaged if schedule.phases else None)


@dataclass(frozen=True)
class PolishResult:
    """The outcome of ``polish``.

    Attributes:
        schedule: the polished schedule. start: the one it started from.
        goal_error: max |goal residual| at the end state [rad, rad/s or m, m/s].
        success: SLSQP converged and goal_error <= ``goal_tolerance``.
        message: SLSQP's. iterations: its iterations. simulations: event-driven runs.
        rtol, atol: the integrator's tolerances.
    """

    schedule: SwitchingSchedule
    start: SwitchingSchedule
    goal_error: float
    success: bool
    message: str
    iterations: int
    simulations: int
    rtol: float
    atol: float

    def as_dict(self) -> dict[str, Any]:
        """Plain-JSON form."""
        return {"final_time": self.schedule.final_time, "schedule": self.schedule.as_dict(),
                "start": self.start.as_dict(), "goal_error": self.goal_error,
                "success": self.success, "message": self.message,
                "iterations": self.iterations, "simulations": self.simulations,
                "integrator": {"method": "DOP853, event-driven", "rtol": self.rtol,
                               "atol": self.atol}}


def polish(problem: OptimalControlProblem, start: SwitchingSchedule, rtol: float = RTOL,
           atol: float = ATOL, goal_tolerance: float = 1e-8, max_iterations: int = 200,
           min_gaps: FloatArray | None = None) -> PolishResult:
    """Minimize t_f over the times of ``start``'s mode sequence, goal as equality constraints.

    Args:
        problem: a time-optimal problem (its model, start, goal and torque bound).
        start: the mode sequence and the starting times.
        rtol, atol: of the event-driven integrator. goal_tolerance: for ``success``.
        max_iterations: SLSQP's limit.
        min_gaps: lower bounds of the gaps (``SwitchingSchedule.gaps``) [s]; default 0 (a
            phase may shrink to an instant).

    Raises:
        ValueError: a problem that is not time-optimal.
    """
    if problem.cost != "time":
        raise ValueError(f"{problem.name}: the polish handles time-optimal problems only")
    model, parameters = model_of(problem)
    integrator = EventDrivenIntegrator(model, parameters, rtol=rtol, atol=atol)
    goal_q = np.array(list(problem.goal_q.values()))
    goal_u = np.zeros(model.NUM_DOFS)
    goal_u[list(problem.goal_u)] = list(problem.goal_u.values())
    totals = start.chain_totals()
    x0 = start.gaps()
    lower = np.zeros(x0.size) if min_gaps is None else np.asarray(min_gaps, dtype=float)
    upper = np.full(x0.size, np.inf)
    # A brake engaged at t_f stays so: its last phase is pinned to t_f, and the velocity goal
    # is stated in the directions the locked brakes leave free (the others hold by the lock).
    at_end = [j for j, row in enumerate(start.phases) if row and row[-1][1] >= start.final_time]
    ends = np.cumsum([len(r) + 1 for r in start.switches] + [2 * len(r) + 1 for r in start.phases])
    upper[ends[[len(start.switches) + j for j in at_end]] - 1] = 0.0
    rows = np.array(model.brake_directions(problem.initial_q, parameters.values(), math),
                    dtype=float).reshape(-1, model.NUM_DOFS)[at_end]
    velocity_rows = null_space(rows).T if at_end else np.eye(model.NUM_DOFS)[list(problem.goal_u)]
    count = [0]

    def residual(x: FloatArray) -> FloatArray:
        count[0] += 1
        q, u = simulate_schedule(integrator, problem, start.with_gaps(x))[:2]
        return np.concatenate([q[list(problem.goal_q)] - goal_q, velocity_rows @ (u - goal_u)])

    def jacobian(x: FloatArray) -> FloatArray:
        here, columns = residual(x), []
        for i in range(x.size):  # central differences, one-sided at an active bound
            step = np.zeros(x.size)
            step[i] = DIFFERENCE_STEP
            up = bool(x[i] + DIFFERENCE_STEP <= upper[i])
            down = bool(x[i] - DIFFERENCE_STEP >= lower[i])
            plus = residual(x + step) if up else here
            minus = residual(x - step) if down else here
            columns.append((plus - minus) / (DIFFERENCE_STEP * max(int(up) + int(down), 1)))
        return np.column_stack(columns)

    cost = totals[0] / start.final_time
    constraints = [NonlinearConstraint(residual, 0.0, 0.0, jac=jacobian)]
    if len(totals) > 1:
        constraints.append(LinearConstraint(totals[1:] - totals[0], 0.0, 0.0))
    result = minimize(lambda x: cost @ x, x0, jac=lambda x: cost, method="SLSQP",
                      constraints=constraints, bounds=list(zip(lower, upper, strict=True)),
                      options={"maxiter": max_iterations, "ftol": 1e-14})
    schedule = start.with_gaps(result.x)
    q, u = simulate_schedule(integrator, problem, schedule)[:2]
    error = float(max(np.abs(q[list(problem.goal_q)] - goal_q).max(),
                      np.abs(u - goal_u)[list(problem.goal_u)].max()))
    return PolishResult(schedule, start, error, bool(result.success) and error <= goal_tolerance,
                        str(result.message), int(result.nit), count[0], rtol, atol)


__all__ = ["ATOL", "DIFFERENCE_STEP", "RTOL", "PolishResult", "ScheduleRun", "SwitchingSchedule",
           "pattern_on_grid", "polish", "schedule_from_reference", "simulate_schedule"]
