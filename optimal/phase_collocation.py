"""Continuous-time optima of the robot's maneuvers for a fixed stick-slip mode sequence.

The h-discrete references fix a sequence of contact modes (which contacts slide, phase by
phase). With that sequence fixed, the continuous-time problem is a smooth multi-phase optimal
control problem whose phase durations are free: each phase p has its own sticking set S_p,

    q' = u,   M u' = B tau + W(q)^T F,   N = N0 + K F,
    W_i(q) u = 0,  |F_i| <= mu_i N_i,  N_i >= 0          (i in S_p, sticking),
    F_i = -mu_i N_i e_i,  gamma_i = s_i e_i,  s_i >= 0    (i not in S_p, sliding),

|tau| <= tau_max, from rest at the start pose to rest at the
goal pose, minimizing t_f or the effort integral of |tau|^2 at fixed t_f. A sliding contact's
direction e_i = (cos a_i, sin a_i) and slip speed s_i are unknowns, so a slip that vanishes at a
phase end (the start from rest, the final stop) is never divided by. It is solved by direct
collocation at the Gauss-Legendre points, ``elements`` elements per phase of equal length
d_p / K, with CasADi and IPOPT. A shared row of two sticking contacts (the wheels' lateral row)
is imposed once; the split of its force stays free within the cones.

The controls are linear in each element, within their bounds at its ends and so throughout;
``ElementInputs`` turns them into inputs tau(t) that ``EventDrivenFrictionIntegrator`` replays
with exact events: an independent check of the result, whose modes the acceleration-level law
decides afresh, by its events and its final state against the goal.
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.mechanics.symbolic import symbolic_equations
from mdi_envs.provenance import git_commit
from mdi_envs.stepping.event_driven_friction import (
    EVENT_SLIP,
    EVENT_STICK,
    EventDrivenFrictionIntegrator,
    Inputs,
)
from optimal.convergence import CONTINUOUS_DIR, continuous_cost, richardson
from optimal.problems import make_problem
from optimal.references import Reference, load_reference
from optimal.replay import goal_errors

WARM_START_OPTIONS = {"mu_init": 1e-4}
"""IPOPT's options from a coarser solution: a small initial barrier parameter keeps the bounded
inputs near the bounds they sit at (from IPOPT's default 0.1 a warm start leaves for another
local optimum)."""


@dataclass(frozen=True)
class Phase:
    """One phase of a mode sequence.

    Attributes:
        sliding: (c,) True where the contact slides throughout the phase.
        duration: [s] its length (the initial guess, or the optimum).
    """

    sliding: tuple[bool, ...]
    duration: float


def reference_phases(reference: Reference, slip_threshold: float = 1e-6) -> list[Phase]:
    """The reference's mode sequence: runs of intervals with equal slide flags.

    A last run in which every contact sticks (the stepper's stop at rest) is merged into the
    run before it: in continuous time the robot comes to rest at t_f.
    """
    flags = reference.arrays["slip_speed"] > slip_threshold
    h = reference.time_step
    phases: list[Phase] = []
    for row in flags:
        key = tuple(bool(x) for x in row)
        if phases and phases[-1].sliding == key:
            phases[-1] = Phase(key, phases[-1].duration + h)
        else:
            phases.append(Phase(key, h))
    if len(phases) > 1 and not any(phases[-1].sliding):
        last = phases.pop()
        phases[-1] = Phase(phases[-1].sliding, phases[-1].duration + last.duration)
    return phases


@functools.cache
def _gauss_points(degree: int) -> FloatArray:
    """The ``degree`` Gauss-Legendre points in (0, 1), increasing."""
    return (np.polynomial.legendre.leggauss(degree)[0] + 1.0) / 2.0


def _legendre_scheme(degree: int) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Gauss-Legendre points tau_j in (0, 1) and the Lagrange matrices of the collocation.

    Returns (points (d,), C (d+1, d): derivative of basis r at point j, D (d+1,): basis r at 1,
    B (d+1,): quadrature weights), the basis over (0, tau_1, ..., tau_d).
    """
    points = _gauss_points(degree)
    nodes = np.concatenate([[0.0], points])
    C = np.zeros((degree + 1, degree))
    D = np.zeros(degree + 1)
    B = np.zeros(degree + 1)
    for r in range(degree + 1):
        basis = np.poly1d([1.0])
        for s in range(degree + 1):
            if s != r:
                basis *= np.poly1d([1.0, -nodes[s]]) / (nodes[r] - nodes[s])
        D[r] = basis(1.0)
        derivative = np.polyder(basis)
        C[r] = [derivative(x) for x in points]
        B[r] = np.polyint(basis)(1.0)
    return points, C, D, B


@dataclass(frozen=True)
class ElementInputs:
    """Inputs tau(t): per element, the polynomial through its values at the collocation points.

    Attributes:
        boundaries: (E + 1,) element boundaries [s], increasing, from 0 to t_f.
        values: (E, d, m) the inputs at the d Gauss-Legendre points of each element.
    """

    boundaries: FloatArray
    values: FloatArray

    @property
    def switch_times(self) -> FloatArray:
        """The inner element boundaries [s] (the integrator restarts there)."""
        return self.boundaries[1:-1]

    def __call__(self, t: float) -> FloatArray:
        """The inputs (m,) at t [s]; an element's polynomial holds on [its start, its end)."""
        k = int(np.clip(np.searchsorted(self.boundaries, t, side="right") - 1, 0,
                        len(self.values) - 1))
        t0, t1 = self.boundaries[k], self.boundaries[k + 1]
        x = (t - t0) / (t1 - t0)
        weights = _lagrange_at(_gauss_points(self.values.shape[1]), np.array([x]))[0]
        return weights @ self.values[k]


@dataclass(frozen=True)
class TrajectoryGuess:
    """A trajectory sampled in time: the initial guess of ``solve_phases``.

    Attributes:
        state_time: (S,) [s] increasing. state: (S, 2n) (q, u) there.
        control_time: (C,) [s] increasing. tau: (C, m) the inputs [N m] there.
        force: (C, 2c) the contacts' tangential forces [N] there.
    """

    state_time: FloatArray
    state: FloatArray
    control_time: FloatArray
    tau: FloatArray
    force: FloatArray

    @classmethod
    def from_reference(cls, reference: Reference) -> TrajectoryGuess:
        """The h-discrete reference: states at its grid, inputs and forces at mid-steps."""
        mid_times = reference.time[:-1] + reference.time_step / 2.0
        return cls(reference.time, np.hstack([reference.q, reference.u]), mid_times,
                   reference.tau, reference.arrays["tangent_impulse"] / reference.time_step)

    def state_at(self, t: float) -> FloatArray:
        """(2n,) the state interpolated at t [s]."""
        return _interpolate(self.state, self.state_time, t)

    def tau_at(self, t: float) -> FloatArray:
        """(m,) the inputs interpolated at t [s]."""
        return _interpolate(self.tau, self.control_time, t)

    def force_at(self, t: float) -> FloatArray:
        """(2c,) the tangential forces interpolated at t [s]."""
        return _interpolate(self.force, self.control_time, t)


def _interpolate(table: FloatArray, times: FloatArray, t: float) -> FloatArray:
    return np.array([np.interp(t, times, column) for column in table.T])


@dataclass(frozen=True)
class CollocationResult:
    """A continuous-time optimum for one mode sequence.

    Attributes:
        name: the problem. phases: the mode sequence with the optimal durations.
        cost: t_f [s] (time) or the effort integral [N^2 m^2 s]. final_time: t_f [s].
        elements: elements per phase. degree: collocation points per element.
        inputs: the optimal controls as ``ElementInputs``.
        converged: IPOPT's success flag. iterations: its iteration count.
        samples: the solution at its collocation points (the guess of a finer solve).
    """

    name: str
    phases: tuple[Phase, ...]
    cost: float
    final_time: float
    elements: int
    degree: int
    inputs: ElementInputs
    converged: bool
    iterations: int
    samples: TrajectoryGuess


def solve_phases(reference: Reference, phases: list[Phase], elements: int = 20,
                 degree: int = 3, max_iterations: int = 3000, print_level: int = 0,
                 guess: TrajectoryGuess | None = None) -> CollocationResult:
    """Solve the multi-phase problem of ``reference``'s maneuver for the mode sequence ``phases``.

    Args:
        reference: the h-discrete reference (its problem name; its trajectory, controls and
            friction impulses are the initial guess unless ``guess`` is given).
        phases: the mode sequence with guessed durations (``reference_phases``, or a coarser
            solution's ``phases``).
        elements: collocation elements per phase. degree: Gauss-Legendre points per element.
        max_iterations: IPOPT's limit. print_level: IPOPT's output (0 silent, 5 per iteration).
        guess: the initial guess in time, e.g. a coarser solution's ``samples`` (its phases
            as ``phases``, so that its switches fall where the guess has them).

    Returns:
        The ``CollocationResult``.
    """
    import casadi

    problem = make_problem(reference.name)
    model, parameters = problem.model, problem.parameters
    equations = symbolic_equations(model, parameters)
    n, m, c = model.NUM_DOFS, model.NUM_INPUTS, model.NUM_CONTACTS
    p = parameters.values()
    mu = np.array(model.friction_coefficients(p))
    n0_list, k_rows = model.normal_loads(p)
    n0, K = np.array(n0_list), np.array(k_rows).reshape(c, 2 * c)
    tangent = [r for r in range(3 * c) if r % 3]
    mass = np.array(casadi.DM(equations.mass(np.zeros(n))))
    inputs_matrix = np.array(casadi.DM(equations.inputs(np.zeros(n))))
    points, C, D, B = _legendre_scheme(degree)
    bound = problem.torque_bound
    effort = problem.cost == "effort"
    warm_start = guess is not None
    guess = TrajectoryGuess.from_reference(reference) if guess is None else guess

    opti = casadi.Opti()
    durations = opti.variable(len(phases))
    for i, phase in enumerate(phases):
        opti.subject_to(durations[i] >= 1e-3)
        opti.set_initial(durations[i], phase.duration)
    if effort:
        opti.subject_to(casadi.sum1(durations) == problem.final_time)

    x = opti.variable(2 * n)
    opti.subject_to(x == np.concatenate([problem.initial_q, problem.initial_u]))
    opti.set_initial(x, guess.state_at(0.0))
    cost: Any = 0.0
    control_values: list[Any] = []
    # (phase, element, position in the element in [0, 1], state, tau or None, force or None)
    sampled: list[tuple[int, int, float, Any, Any, Any]] = []
    t_guess = 0.0
    for i, phase in enumerate(phases):
        h = durations[i] / elements
        stuck = [j for j in range(c) if not phase.sliding[j]]
        rows = _independent_rows(equations, reference, stuck, tangent)
        if i > 0 and rows:  # a phase of sticking starts with zero slip
            W0 = equations.contact_rows(x[:n])
            opti.subject_to(casadi.vertcat(*[W0[r, :] @ x[n:] for r in rows]) == 0.0)
        for e in range(elements):
            states = [x]
            sampled.append((i, e, 0.0, x, None, None))
            element_controls = []
            # the inputs are linear in an element: within the bounds at its ends, everywhere
            ends = opti.variable(m, 2)
            opti.subject_to(opti.bounded(-bound, ends, bound))
            for side in range(2):
                opti.set_initial(ends[:, side], guess.tau_at(
                    t_guess + side * phase.duration / elements))
            for j in range(degree):
                state = opti.variable(2 * n)
                opti.set_initial(state, guess.state_at(
                    t_guess + points[j] * phase.duration / elements))
                states.append(state)
            end = sum(D[r] * states[r] for r in range(degree + 1))
            for j in range(degree):
                t_point = t_guess + points[j] * phase.duration / elements
                state = states[j + 1]
                q, u = state[:n], state[n:]
                tau = (1.0 - points[j]) * ends[:, 0] + points[j] * ends[:, 1]
                force = opti.variable(2 * c)
                sampled.append((i, e, float(points[j]), state, tau, force))
                opti.set_initial(force, guess.force_at(t_point))
                element_controls.append(tau)
                slope = sum(C[r, j] * states[r] for r in range(degree + 1))
                W = equations.contact_rows(q)[tangent, :]
                opti.subject_to(slope[:n] == h * u)
                opti.subject_to(mass @ slope[n:] == h * (inputs_matrix @ tau + W.T @ force))
                loads = n0 + K @ force
                guess_state = guess.state_at(t_point)
                guess_slip = (np.array(equations.contact_rows(guess_state[:n]))[tangent]
                              @ guess_state[n:]).reshape(c, 2)
                guess_f = guess.force_at(t_point).reshape(c, 2)
                for contact in range(c):
                    f = force[2 * contact: 2 * contact + 2]
                    if phase.sliding[contact]:
                        # direction angle and slip speed as unknowns: no division by |gamma|
                        angle, speed = opti.variable(), opti.variable()
                        direction = casadi.vertcat(casadi.cos(angle), casadi.sin(angle))
                        gamma = W[2 * contact: 2 * contact + 2, :] @ u
                        opti.subject_to(f == -mu[contact] * loads[contact] * direction)
                        opti.subject_to(gamma == speed * direction)
                        opti.subject_to(speed >= 0.0)
                        slip = guess_slip[contact]
                        opti.set_initial(speed, float(np.hypot(*slip)))
                        opti.set_initial(angle, math.atan2(slip[1], slip[0])
                                         if np.hypot(*slip) > 1e-6
                                         else math.atan2(-guess_f[contact][1],
                                                         -guess_f[contact][0]))
                    else:
                        opti.subject_to(casadi.sumsqr(f) <= (mu[contact] * loads[contact]) ** 2)
                        opti.subject_to(loads[contact] >= 0.0)
                if rows:
                    Wall = equations.contact_rows(q)
                    opti.subject_to(casadi.vertcat(*[Wall[r, :] @ u for r in rows]) == 0.0)
                if effort:
                    cost = cost + B[j + 1] * h * casadi.sumsqr(tau)
            control_values.append(element_controls)
            x = opti.variable(2 * n)
            t_guess += phase.duration / elements
            opti.set_initial(x, guess.state_at(t_guess))
            opti.subject_to(x == end)
    for i, value in problem.goal_q.items():
        opti.subject_to(x[i] == value)
    for i, value in problem.goal_u.items():
        opti.subject_to(x[n + i] == value)
    opti.minimize(cost if effort else casadi.sum1(durations))
    options = {"max_iter": max_iterations, "print_level": print_level, "tol": 1e-10,
               "acceptable_tol": 1e-6}
    if warm_start:
        options.update(WARM_START_OPTIONS)
    opti.solver("ipopt", {"print_time": False}, options)
    try:
        solution = opti.solve()
        converged = True
    except RuntimeError:
        solution = opti.debug
        converged = False
    optimal_durations = np.atleast_1d(np.array(solution.value(durations), dtype=np.float64))
    boundaries = np.concatenate([[0.0], np.cumsum(np.repeat(optimal_durations / elements,
                                                            elements))])
    values = np.array([[np.atleast_1d(solution.value(tau)) for tau in element]
                       for element in control_values])
    stats = solution.stats()
    return CollocationResult(
        reference.name,
        tuple(Phase(phase.sliding, float(d)) for phase, d in zip(phases, optimal_durations,
                                                                  strict=True)),
        float(solution.value(cost if effort else casadi.sum1(durations))),
        float(boundaries[-1]), elements, degree, ElementInputs(boundaries, values),
        converged, int(stats.get("iter_count", -1)),
        _samples(solution, sampled, boundaries, elements, x))


def _lagrange_at(points: FloatArray, positions: FloatArray) -> FloatArray:
    """(P, d) the Lagrange basis over ``points`` (d,) evaluated at ``positions`` (P,)."""
    return np.array([[math.prod((x - points[s]) / (points[r] - points[s])
                                for s in range(len(points)) if s != r)
                      for r in range(len(points))] for x in positions])


def _samples(solution: Any, sampled: list[tuple[int, int, float, Any, Any, Any]],
             boundaries: FloatArray, elements: int, final_state: Any) -> TrajectoryGuess:
    """The solved states (element starts, collocation points, t_f) and controls in time."""
    def time_of(phase: int, element: int, position: float) -> float:
        k = phase * elements + element
        return float(boundaries[k] + position * (boundaries[k + 1] - boundaries[k]))

    state_time = [time_of(i, e, x) for i, e, x, *_ in sampled] + [float(boundaries[-1])]
    state = [solution.value(s) for *_, s, _, _ in sampled] + [solution.value(final_state)]
    controls = [(time_of(i, e, x), solution.value(tau), solution.value(force))
                for i, e, x, _, tau, force in sampled if tau is not None]
    return TrajectoryGuess(np.array(state_time), np.array(state, dtype=np.float64),
                           np.array([t for t, _, _ in controls]),
                           np.array([np.atleast_1d(v) for _, v, _ in controls]),
                           np.array([np.atleast_1d(f) for _, _, f in controls]))


def _independent_rows(equations: Any, reference: Reference, stuck: list[int],
                      tangent: list[int]) -> list[int]:
    """Contact rows of the stuck contacts, with rows that repeat an earlier one dropped.

    Judged at the reference's middle configuration (the robot's wheels share their lateral row
    at every configuration).
    """
    W = np.array(equations.contact_rows(reference.q[len(reference.q) // 2]))
    kept: list[int] = []
    for contact in stuck:
        for r in (3 * contact + 1, 3 * contact + 2):
            if r not in tangent:
                continue
            candidate = W[[*kept, r]]
            if np.linalg.matrix_rank(candidate, tol=1e-10) == len(kept) + 1:
                kept.append(r)
    return kept


def replay_result(result: CollocationResult, reference: Reference, rtol: float = 1e-11,
                  atol: float = 1e-12) -> tuple[FloatArray, FloatArray, Any]:
    """Replay the optimal controls with the event-driven integrator.

    Returns:
        (q (n,), u (n,)) at t_f and the ``Trajectory`` (its stick and slip events).
    """
    problem = make_problem(reference.name)
    integrator = EventDrivenFrictionIntegrator(problem.model, problem.parameters, rtol=rtol,
                                               atol=atol)
    inputs: Inputs = result.inputs
    trajectory = integrator.simulate(problem.initial_q, problem.initial_u, result.final_time,
                                     inputs)
    q, u = trajectory.final_state
    return q, u, trajectory


def _phase_record(result: CollocationResult) -> list[dict[str, Any]]:
    starts = np.concatenate([[0.0], np.cumsum([phase.duration for phase in result.phases])])
    return [{"sliding": list(phase.sliding), "start": float(a), "end": float(b)}
            for phase, a, b in zip(result.phases, starts[:-1], starts[1:], strict=True)]


def _solve_from(reference: Reference, elements: int, degree: int,
                coarser: CollocationResult | None) -> CollocationResult:
    """``solve_phases`` from the ``coarser`` solution (phases, samples), else the reference."""
    if coarser is None:
        return solve_phases(reference, reference_phases(reference), elements, degree)
    return solve_phases(reference, list(coarser.phases), elements, degree,
                        guess=coarser.samples)


def solve_level(reference: Reference, elements: int, degree: int = 3,
                coarser: CollocationResult | None = None
                ) -> tuple[dict[str, Any], CollocationResult]:
    """One collocation level, replayed event-driven.

    The mode sequence and the initial guess: the ``coarser`` level's solution (its phases and
    ``samples``), else the reference's (``reference_phases``, its trajectory).

    Returns:
        A plain-JSON record: elements, degree, cost, t_f, the phases [s], IPOPT's outcome, the
        wall time [s], the commit, the start (the reference, or the coarser level's elements),
        and the replay (status, the time reached, goal errors, whether they are within the
        maneuver's tolerances, its stick and slip events); then the result.
    """
    clock = time.perf_counter()
    result = _solve_from(reference, elements, degree, coarser)
    wall_time = time.perf_counter() - clock
    q, u, trajectory = replay_result(result, reference)
    errors, ok = goal_errors(reference.name, q, u)
    return {"elements": elements, "degree": degree, "cost": result.cost,
            "final_time": result.final_time, "phases": _phase_record(result),
            "converged": result.converged, "iterations": result.iterations,
            "wall_time": wall_time, "commit": git_commit(),
            "start": "reference" if coarser is None else coarser.elements,
            "replay": {"status": trajectory.status, "t_end": trajectory.t_end,
                       "goal_errors": errors, "reaches_goal": ok,
                       "events": [[e.t, e.kind, e.element] for e in trajectory.events
                                  if e.kind in (EVENT_SLIP, EVENT_STICK)]}}, result


def polish_reference(name: str, elements: list[int], degree: int = 3,
                     directory: Path | None = None) -> dict[str, Any]:
    """Solve ``name``'s mode sequence at each number of elements; write ``NAME.json``.

    The coarsest level starts from the reference, each finer one from the level before it
    (solved again in this call when it was loaded from the record), so that every level stays
    on the coarsest one's branch. Resumable: the record is written after each level, and a
    level already in it (same number of elements and degree) is kept. Its cost is the finest
    level's; with three levels or more it carries the Richardson extrapolation of the three
    finest (``optimal.convergence.richardson``) as ``extrapolation``.
    """
    reference = load_reference(name)
    path = (CONTINUOUS_DIR if directory is None else directory) / f"{name}.json"
    done = json.loads(path.read_text())["levels"] if path.exists() else []
    levels = {level["elements"]: level for level in done if level["degree"] == degree}
    counts = sorted(set(elements) | set(levels))
    coarser: CollocationResult | None = None
    for count in counts:
        if count in levels and all(k in levels for k in counts if k > count):
            continue
        if count in levels:  # solved again, without its replay: the start of a finer level
            coarser = _solve_from(reference, count, degree, coarser)
            continue
        level, coarser = solve_level(reference, count, degree, coarser)
        levels[count] = level
        print(f"K = {count}: cost {level['cost']:.7f}, converged {level['converged']}, "
              f"replay {level['replay']['status']}, goal errors "
              f"{level['replay']['goal_errors']}, {level['wall_time']:.0f} s", flush=True)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(_record(reference, levels, degree), indent=1) + "\n")
    return _record(reference, levels, degree)


def _record(reference: Reference, levels: dict[int, dict[str, Any]], degree: int
            ) -> dict[str, Any]:
    """The continuous optimum's record: the finest level, every level, the extrapolation.

    "relative_difference" compares ``continuous_cost`` (the extrapolated limit, else the
    finest level's cost) with the h-discrete reference's cost.
    """
    ordered = [levels[k] for k in sorted(levels)]
    finest = ordered[-1]
    record = {
        "name": reference.name, "cost": finest["cost"], "final_time": finest["final_time"],
        "phases": finest["phases"],
        "goal_error": max(finest["replay"]["goal_errors"].values()),
        "integrator": {"method": f"Gauss-Legendre collocation ({degree} points, "
                                 f"{finest['elements']} elements per phase); replayed by "
                                 "DOP853, event-driven", "rtol": 1e-11, "atol": 1e-12},
        "levels": ordered, "discrete_cost": reference.cost,
        "discrete_num_intervals": reference.metadata["num_intervals"]}
    if len(ordered) >= 3:
        last = ordered[-3:]
        try:
            record["extrapolation"] = richardson([lv["elements"] for lv in last],
                                                 [lv["cost"] for lv in last])
        except ValueError:  # the three finest levels are not in a constant ratio
            pass
    record["relative_difference"] = continuous_cost(record) / reference.cost - 1.0
    return record


def main(argv: list[str] | None = None) -> None:
    """``python -m optimal.phase_collocation NAME --elements 10 20 40``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("name", choices=["diff_drive_effort", "diff_drive_time"])
    parser.add_argument("--elements", type=int, nargs="+", default=[10, 20, 40],
                        help="collocation elements per phase, one level each")
    parser.add_argument("--degree", type=int, default=3, help="collocation points per element")
    args = parser.parse_args(argv)
    record = polish_reference(args.name, args.elements, args.degree)
    print(f"continuous-time cost {continuous_cost(record):.7f} "
          f"(h-discrete {record['discrete_cost']:.7f}, "
          f"{100 * record['relative_difference']:+.3f} %)")


if __name__ == "__main__":
    main()
