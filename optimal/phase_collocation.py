"""Continuous-time optima of the robot's maneuvers for a fixed stick-slip mode sequence.

The h-discrete references fix a sequence of contact modes (which contacts slide, phase by
phase). With that sequence fixed, the continuous-time problem is a smooth multi-phase optimal
control problem whose phase durations are free: each phase p has its own sticking set S_p,

    q' = u,   M u' = B tau + W(q)^T F,   N = N0 + K F,
    W_i(q) u = 0,  |F_i| <= mu_i N_i,  N_i >= 0          (i in S_p, sticking),
    F_i = -mu_i N_i e_i,  gamma_i = s_i e_i,  s_i >= 0    (i not in S_p, sliding),

|tau| <= tau_max (at the collocation points), from rest at the start pose to rest at the
goal pose, minimizing t_f or the effort integral of |tau|^2 at fixed t_f. A sliding contact's
direction e_i = (cos a_i, sin a_i) and slip speed s_i are unknowns, so a slip that vanishes at a
phase end (the start from rest, the final stop) is never divided by. It is solved by direct
collocation at the Gauss-Legendre points, ``elements`` elements per phase of equal length
d_p / K, with CasADi and IPOPT. A shared row of two sticking contacts (the wheels' lateral row)
is imposed once; the split of its force stays free within the cones.

The controls are polynomials of degree ``degree - 1`` in each element; ``ElementInputs`` turns
them into inputs tau(t) that ``EventDrivenFrictionIntegrator`` replays with exact events: an
independent check of the result, whose modes the acceleration-level law decides afresh, by its
events and its final state against the goal.
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
from optimal.convergence import CONTINUOUS_DIR, richardson
from optimal.problems import make_problem
from optimal.references import Reference, load_reference
from optimal.replay import goal_errors


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
        points = _gauss_points(self.values.shape[1])
        weights = np.array([math.prod((x - points[s]) / (points[r] - points[s])
                                      for s in range(len(points)) if s != r)
                            for r in range(len(points))])
        return weights @ self.values[k]


@dataclass(frozen=True)
class CollocationResult:
    """A continuous-time optimum for one mode sequence.

    Attributes:
        name: the problem. phases: the mode sequence with the optimal durations.
        cost: t_f [s] (time) or the effort integral [N^2 m^2 s]. final_time: t_f [s].
        elements: elements per phase. degree: collocation points per element.
        inputs: the optimal controls as ``ElementInputs``.
        converged: IPOPT's success flag. iterations: its iteration count.
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


def solve_phases(reference: Reference, phases: list[Phase], elements: int = 20,
                 degree: int = 3, max_iterations: int = 3000, print_level: int = 0
                 ) -> CollocationResult:
    """Solve the multi-phase problem of ``reference``'s maneuver for the mode sequence ``phases``.

    Args:
        reference: the h-discrete reference (its problem name, and its trajectory, controls and
            friction impulses as the initial guess).
        phases: the mode sequence with guessed durations (``reference_phases``).
        elements: collocation elements per phase. degree: Gauss-Legendre points per element.
        max_iterations: IPOPT's limit. print_level: IPOPT's output (0 silent, 5 per iteration).

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

    opti = casadi.Opti()
    durations = opti.variable(len(phases))
    for i, phase in enumerate(phases):
        opti.subject_to(durations[i] >= 1e-3)
        opti.set_initial(durations[i], phase.duration)
    if effort:
        opti.subject_to(casadi.sum1(durations) == problem.final_time)

    # guesses from the reference, interpolated in time
    guess_time = reference.time
    guess_x = np.hstack([reference.q, reference.u])
    guess_force = reference.arrays["tangent_impulse"] / reference.time_step
    guess_tau = reference.tau

    def interpolate(table: FloatArray, times: FloatArray, t: float) -> FloatArray:
        return np.array([np.interp(t, times, column) for column in table.T])

    mid_times = guess_time[:-1] + reference.time_step / 2.0
    x = opti.variable(2 * n)
    opti.subject_to(x == np.concatenate([problem.initial_q, problem.initial_u]))
    opti.set_initial(x, guess_x[0])
    cost: Any = 0.0
    control_values: list[Any] = []
    t_guess = 0.0
    for i, phase in enumerate(phases):
        h = durations[i] / elements
        stuck = [j for j in range(c) if not phase.sliding[j]]
        rows = _independent_rows(equations, reference, stuck, tangent)
        if i > 0 and rows:  # a phase of sticking starts with zero slip
            W0 = equations.contact_rows(x[:n])
            opti.subject_to(casadi.vertcat(*[W0[r, :] @ x[n:] for r in rows]) == 0.0)
        for _ in range(elements):
            states = [x]
            element_controls = []
            for j in range(degree):
                t_point = t_guess + points[j] * phase.duration / elements
                state = opti.variable(2 * n)
                opti.set_initial(state, interpolate(guess_x, guess_time, t_point))
                states.append(state)
            end = sum(D[r] * states[r] for r in range(degree + 1))
            for j in range(degree):
                t_point = t_guess + points[j] * phase.duration / elements
                state = states[j + 1]
                q, u = state[:n], state[n:]
                tau = opti.variable(m)
                force = opti.variable(2 * c)
                opti.set_initial(tau, interpolate(guess_tau, mid_times, t_point))
                opti.set_initial(force, interpolate(guess_force, mid_times, t_point))
                opti.subject_to(opti.bounded(-bound, tau, bound))
                element_controls.append(tau)
                slope = sum(C[r, j] * states[r] for r in range(degree + 1))
                W = equations.contact_rows(q)[tangent, :]
                opti.subject_to(slope[:n] == h * u)
                opti.subject_to(mass @ slope[n:] == h * (inputs_matrix @ tau + W.T @ force))
                loads = n0 + K @ force
                guess_state = interpolate(guess_x, guess_time, t_point)
                guess_slip = (np.array(equations.contact_rows(guess_state[:n]))[tangent]
                              @ guess_state[n:]).reshape(c, 2)
                guess_f = interpolate(guess_force, mid_times, t_point).reshape(c, 2)
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
            opti.set_initial(x, interpolate(guess_x, guess_time, t_guess))
            opti.subject_to(x == end)
    for i, value in problem.goal_q.items():
        opti.subject_to(x[i] == value)
    for i, value in problem.goal_u.items():
        opti.subject_to(x[n + i] == value)
    opti.minimize(cost if effort else casadi.sum1(durations))
    opti.solver("ipopt", {"print_time": False}, {"max_iter": max_iterations,
                                                 "print_level": print_level, "tol": 1e-10,
                                                 "acceptable_tol": 1e-8})
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
        converged, int(stats.get("iter_count", -1)))


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


def solve_level(reference: Reference, elements: int, degree: int = 3) -> dict[str, Any]:
    """One collocation level from the reference's mode sequence, replayed event-driven.

    Returns:
        A plain-JSON record: elements, degree, cost, t_f, the phases [s], IPOPT's outcome, the
        wall time [s], the commit, and the replay (status, the time reached, goal errors,
        whether they are within the maneuver's tolerances, its stick and slip events).
    """
    clock = time.perf_counter()
    result = solve_phases(reference, reference_phases(reference), elements, degree)
    wall_time = time.perf_counter() - clock
    q, u, trajectory = replay_result(result, reference)
    errors, ok = goal_errors(reference.name, q, u)
    return {"elements": elements, "degree": degree, "cost": result.cost,
            "final_time": result.final_time, "phases": _phase_record(result),
            "converged": result.converged, "iterations": result.iterations,
            "wall_time": wall_time, "commit": git_commit(),
            "replay": {"status": trajectory.status, "t_end": trajectory.t_end,
                       "goal_errors": errors, "reaches_goal": ok,
                       "events": [[e.t, e.kind, e.element] for e in trajectory.events
                                  if e.kind in (EVENT_SLIP, EVENT_STICK)]}}


def polish_reference(name: str, elements: list[int], degree: int = 3,
                     directory: Path | None = None) -> dict[str, Any]:
    """Solve ``name``'s mode sequence at each number of elements; write ``NAME.json``.

    Resumable: the record is written after each level, and a level already in it (same number
    of elements and degree) is kept. Its cost is the finest level's; with three levels or more
    it carries the Richardson extrapolation of the three finest
    (``optimal.convergence.richardson``) as ``extrapolation``.
    """
    reference = load_reference(name)
    path = (CONTINUOUS_DIR if directory is None else directory) / f"{name}.json"
    done = json.loads(path.read_text())["levels"] if path.exists() else []
    levels = {level["elements"]: level for level in done if level["degree"] == degree}
    record: dict[str, Any] = {}
    for count in sorted(elements):
        if count not in levels:
            levels[count] = solve_level(reference, count, degree)
            level = levels[count]
            print(f"K = {count}: cost {level['cost']:.7f}, converged {level['converged']}, "
                  f"replay {level['replay']['status']}, goal errors "
                  f"{level['replay']['goal_errors']}, {level['wall_time']:.0f} s", flush=True)
        ordered = [levels[k] for k in sorted(levels)]
        finest = ordered[-1]
        record = {
            "name": name, "cost": finest["cost"], "final_time": finest["final_time"],
            "phases": finest["phases"],
            "goal_error": max(finest["replay"]["goal_errors"].values()),
            "integrator": {"method": f"Gauss-Legendre collocation ({degree} points, "
                                     f"{finest['elements']} elements per phase); replayed by "
                                     "DOP853, event-driven", "rtol": 1e-11, "atol": 1e-12},
            "levels": ordered, "discrete_cost": reference.cost,
            "discrete_num_intervals": reference.metadata["num_intervals"],
            "relative_difference": finest["cost"] / reference.cost - 1.0}
        if len(ordered) >= 3:
            last = ordered[-3:]
            try:
                record["extrapolation"] = richardson([lv["elements"] for lv in last],
                                                     [lv["cost"] for lv in last])
            except ValueError:  # the three finest levels are not in a constant ratio
                pass
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(record, indent=1) + "\n")
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
    print(f"continuous-time cost {record['cost']:.7f} (h-discrete {record['discrete_cost']:.7f}, "
          f"{100 * record['relative_difference']:+.3f} %)")


if __name__ == "__main__":
    main()
