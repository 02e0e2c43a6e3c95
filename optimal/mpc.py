"""Shrinking-horizon model-predictive control on the optimal-control transcription.

At every env step the controller re-solves the remaining optimal-control problem from the
measured state -- the same model definition and midpoint transcription as the references
(``optimal.transcription``), with the mode pattern (brake schedule, stick-slip) of its previous
plan fixed (``optimal.mode_search.solve_with_modes``), warm-started from that plan shifted by
one interval -- and applies the first interval's torque and brake command. Each NLP is built
once per (intervals, pattern, goal relaxed) with the start as a parameter
(``Transcription(parametric_start=True)``) and kept (``NLP_CACHE_SIZE``): building costs more
than a warm-started solve, and episodes from nearby starts revisit the same keys. Where the
fixed-pattern solve fails, the fallbacks are, in order: the neighbouring patterns that differ
within the next ``NEIGHBOUR_WINDOW`` intervals (switches shifted by one interval, phases merged
or split), the goal relaxed to ``GOAL_TOLERANCE_FRACTION``
of the success box, on time-optimal problems arriving 1 to ``MAX_EXTRA_STEPS`` env steps
later (the exact goal, then the relaxed one; ``Plan.delayed``), the pattern freed (the
reference's continuation schedule from the fixed solve's last iterate, then re-solved with
the modes it found), and last the previous plan's next control open loop
(``MPCStep.fallback``).

Horizon: one env step is one interval (the env runs at the reference's h, ``env_options``).
Effort problems have t_f fixed, N - k intervals of h left at step k. Time-optimal problems
plan on one of two grids (``GRIDS``; per reference ``GRID_OF_REFERENCE``):

* ``"env"``: the env's grid, t_f = N h. The control applied is held for exactly as long as
  planned and the plan ends at the end of an env step; a plan of N steps is followed by one of
  N - 1 while the goal stays reachable, and by one 1 to ``MAX_EXTRA_STEPS`` steps longer where
  it does not (it never looks for an arrival earlier than planned).
* ``"free"``: t_f free on N equal intervals; the remaining plan keeps N - 1 intervals while
  they stay within ``REGRID_TOLERANCE`` of h, and is re-gridded to max(round(t_remaining / h),
  ``min_horizon``) intervals beyond that. Each interval of t_f / N is held for h by the env.

``ShrinkingHorizonMPC(reference)`` is a policy: ``controller(observation) -> action`` in the
env's default Box action space (the observation decoded into (q, u) against the plan by
``optimal.observations.decode_observation``), or ``controller.control(q, u)`` on a state.
``controller.steps`` records the compute per control step. Needs CasADi.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER, MANIPULATOR_MANEUVER
from optimal.continuation import SCHEDULES, Schedule, solve_continuation
from optimal.mode_search import ModeSolve, solve_with_modes
from optimal.modes import ModePattern
from optimal.observations import decode_observation
from optimal.problems import make_problem
from optimal.references import Reference
from optimal.solution import SLIP_TOLERANCE, read_modes, read_solution, values_at
from optimal.transcription import GUESS_IMPULSES, Transcription, regridded_impulses

GRIDS = ("env", "free")
"""The grids a time-optimal plan is on (the module docstring)."""

GRID_OF_REFERENCE = {"manipulator_time": "env", "diff_drive_time": "free"}
"""The grid of each time-optimal reference's MPC, chosen by measurement: on the free grid the
manipulator's last planned intervals, 11 ms long but held for a 35.5 ms env step, overshoot the
goal; on the env's grid the robot's fixed-time, fixed-pattern NLPs fail from a perturbed start
and the fallbacks build dozens more."""

MIN_HORIZON = 1
"""Fewest intervals a re-solve on the free grid plans over. The horizon is re-gridded to keep
each planned interval near the env step h (a plan of 4 intervals in 0.5 h, held for h each,
ran past the goal)."""

STEP_MAX_ITERATIONS = 200
"""IPOPT's iteration limit per control step (warm-started solves take 5-40)."""

GOAL_TOLERANCE_FRACTION = 0.5
"""Where the exact goal is infeasible from the measured state (an underactuated link off its
plan by float32 rounding cannot be steered back within a fixed pattern), the re-solve asks for
the goal within this fraction of the maneuver's success tolerances."""

NLP_CACHE_SIZE = 400
"""Fixed-pattern NLPs a controller keeps (least recently used dropped): about 11 MB each at
the manipulator's 120 intervals, 30 MB for the robot once solved. Building one costs 0.5-0.8 s
at 120 intervals, a warm-started re-solve of a kept one about 0.1 s, and episodes from nearby
starts visit the same (intervals, pattern) keys."""

NEIGHBOUR_WINDOW = 3
"""The neighbouring-pattern fallback tries only the moves that change one of the next this-many
intervals: a measured state off the plan puts the imminent mode in doubt, not a switch seconds
ahead."""

MAX_EXTRA_STEPS = 3
"""On the env's grid, a time-optimal re-plan that cannot reach the goal in the env steps left
tries arriving 1, 2, ... this many steps later (warm-started from ``Plan.delayed``); longer
detours are not taken."""

REGRID_TOLERANCE = 0.25
"""On the free grid, a plan is re-gridded to steps of h when its intervals differ from the env
step h by more than this fraction (``ShrinkingHorizonMPC._horizon_after_step``)."""

MAX_REPLAN_GROWTH = 1.5
"""On the free grid, a re-plan longer than this times the previous remaining time (plus one
step) is a detour through another local optimum, and is not taken."""


@dataclass(frozen=True, eq=False)
class Plan:
    """A trajectory on a grid of N intervals from the current state.

    Attributes:
        q: (N+1, n). u: (N+1, n). tau: (N, m) [N m]. modes: the pattern (N intervals).
        final_time: its duration [s].
        impulses: per-interval impulses and slip speeds by output name (``GUESS_IMPULSES``),
            each (N, ·), the rest of the warm start (``Transcription.set_guess``). The brake
            impulses are not carried: warm-started with them, the nominal N = 40 manipulator
            run left its plan at step 24 and took 7 % longer.
    """

    q: FloatArray
    u: FloatArray
    tau: FloatArray
    modes: ModePattern
    final_time: float
    impulses: dict[str, FloatArray] = dataclasses.field(default_factory=dict)

    @property
    def num_intervals(self) -> int:
        """N."""
        return int(self.tau.shape[0])

    def shifted(self, num_intervals: int | None = None) -> Plan:
        """The plan from its second grid point on.

        Re-gridded to ``num_intervals`` (default: one less, no re-gridding) by ``regridded``.
        A plan of one interval continues as that interval repeated from its end state.
        """
        step = self.final_time / self.num_intervals
        if self.num_intervals == 1:  # past the plan's end: hold its last interval from there
            rest = Plan(self.q[[1, 1]], self.u[[1, 1]], self.tau, self.modes, step,
                        self.impulses)
        else:
            rest = Plan(self.q[1:], self.u[1:], self.tau[1:],
                        self.modes.intervals(slice(1, None)),
                        self.final_time - step,
                        {key: value[1:] for key, value in self.impulses.items()})
        if num_intervals is None or num_intervals == rest.num_intervals:
            return rest
        return rest.regridded(num_intervals)

    def delayed(self, steps: int) -> Plan:
        """The plan with its first interval repeated ``steps`` times in front.

        An arrival ``steps`` intervals later with every later switch as many intervals before
        the goal as in this plan (a start that needs longer is held up at its beginning);
        the repeated grid points are the first one, as a warm start.
        """
        front = np.zeros(steps + 1, dtype=int)
        nodes = np.concatenate([front, np.arange(1, self.num_intervals + 1)])
        intervals = np.concatenate([front[:-1], np.arange(self.num_intervals)])
        step = self.final_time / self.num_intervals
        return Plan(self.q[nodes], self.u[nodes], self.tau[intervals],
                    self.modes.intervals(intervals),
                    self.final_time + steps * step,
                    {key: value[intervals] for key, value in self.impulses.items()})

    def regridded(self, num_intervals: int) -> Plan:
        """The same plan on ``num_intervals`` intervals of equal length.

        Each input, impulse and mode is the one of the old interval holding the new
        interval's midpoint (impulses scaled by the ratio of the interval lengths, slip speeds
        not); q and u interpolate linearly.
        """
        old = np.linspace(0.0, 1.0, self.num_intervals + 1)
        new = np.linspace(0.0, 1.0, num_intervals + 1)
        midpoints = (new[:-1] + new[1:]) / 2
        holder = np.minimum(np.searchsorted(old, midpoints, side="right") - 1,
                            self.num_intervals - 1)

        def interpolated(values: FloatArray) -> FloatArray:
            return np.column_stack([np.interp(new, old, column) for column in values.T])

        impulses = regridded_impulses(self.impulses, holder, self.num_intervals / num_intervals)
        return Plan(interpolated(self.q), interpolated(self.u), self.tau[holder],
                    self.modes.intervals(holder),
                    self.final_time, impulses)


@dataclass(frozen=True)
class MPCStep:
    """One control step.

    Attributes:
        step: env step index. horizon: intervals planned. cost: the plan's cost (t_f of the
            remaining maneuver [s] or its effort). status: IPOPT's. iterations: IPOPT's.
        compute_time: wall time of the step's NLP build and solves [s].
        fallback: "" (fixed-pattern solve), "pattern shifted" (a neighbouring pattern),
            "goal relaxed", "K step(s) later" (time problems on the env's grid: arriving K env
            steps later), "freed" (pattern freed too), or "open loop" (all failed: the previous
            plan's control).
    """

    step: int
    horizon: int
    cost: float
    status: str
    iterations: int
    compute_time: float
    fallback: str


class ShrinkingHorizonMPC:
    """Shrinking-horizon MPC around a reference (see the module docstring).

    Args:
        reference: the reference whose problem is re-solved (``optimal.references``);
            its grid step h must be the env's dt.
        grid: a time-optimal plan's grid, one of ``GRIDS`` (None: ``GRID_OF_REFERENCE``, else
            "env"); effort problems are always on the env's grid.
        min_horizon: see ``MIN_HORIZON``. max_iterations: see ``STEP_MAX_ITERATIONS``.

    Attributes:
        steps: the ``MPCStep`` records of this episode. nlps_built: NLPs built so far (the
            rest of the fixed-pattern solves reused one, ``NLP_CACHE_SIZE``).
    """

    def __init__(self, reference: Reference, grid: str | None = None,
                 min_horizon: int = MIN_HORIZON,
                 max_iterations: int = STEP_MAX_ITERATIONS) -> None:
        grid = grid if grid is not None else GRID_OF_REFERENCE.get(reference.name, "env")
        if grid not in GRIDS:
            raise ValueError(f"grid must be one of {GRIDS}, got {grid!r}")
        self.reference = reference
        self.base = make_problem(reference.name, len(reference.tau))
        self.grid = grid if self.base.cost == "time" else "env"
        self.time_step = reference.time_step
        self.min_horizon = int(min_horizon)
        self.max_iterations = int(max_iterations)
        self.schedule = SCHEDULES.get(reference.name) or Schedule()
        self.steps: list[MPCStep] = []
        self.nlps_built = 0
        self._plan: Plan | None = None
        self._nlps: OrderedDict[tuple[int, bytes, bool], Transcription] = OrderedDict()

    def reset(self) -> None:
        """Forget the plan and the step records (a new episode); the built NLPs are kept."""
        self.steps = []
        self._plan = None

    def __call__(self, observation: FloatArray) -> FloatArray:
        """The env action (default Box space) for an observation of the reference's env."""
        q, u = self.decode(np.asarray(observation, dtype=float))
        tau, engaged = self.control(q, u)
        action = [tau / self.base.torque_bound]
        if engaged.size:
            action.append(np.where(engaged, 1.0, -1.0))
        return np.concatenate(action).astype(np.float32)

    def control(self, q: FloatArray, u: FloatArray) -> tuple[FloatArray, np.ndarray]:
        """(torques (m,) [N m], brakes engaged (k,) bool) for the state (q, u)."""
        clock = time.perf_counter()
        step = len(self.steps)
        guess = self._next_guess()
        if guess.num_intervals < 1:  # past a fixed horizon: nothing left to plan
            self.steps.append(MPCStep(step, 0, 0.0, "horizon over", 0, 0.0, "open loop"))
            return np.zeros(self.base.model.NUM_INPUTS), np.zeros(self.base.model.NUM_BRAKES,
                                                                   dtype=bool)
        solve, plan, fallback = self._solve(guess, q, u)
        self._plan = plan
        self.steps.append(MPCStep(
            step, plan.num_intervals, float("nan") if solve is None else solve.cost,
            "" if solve is None else solve.status, 0 if solve is None else solve.iterations,
            time.perf_counter() - clock, fallback))
        engaged = (plan.modes.engaged[:, 0] if plan.modes.engaged is not None
                   else np.zeros(0, dtype=bool))
        return plan.tau[0].copy(), engaged.copy()

    def replan(self, step: int, q: FloatArray, u: FloatArray,
               relax_goal: bool = True) -> Plan | None:
        """One re-solve of the problem remaining at env step ``step`` from the state (q, u).

        Warm-started from the reference's rest, with its pattern: the fallbacks of a control
        step that keep it (the goal relaxed unless ``relax_goal`` is False, a later arrival);
        None if none found a plan. The episode's records are left as they are.
        """
        guess = reference_plan(self.reference)
        for _ in range(step):
            guess = guess.shifted()
        solve, plan, _ = self._solve(guess, q, u, other_patterns=False, relax_goal=relax_goal)
        return None if solve is None else plan

    def decode(self, observation: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(q, u) from an observation; angles unwrapped against the plan's prediction."""
        return decode_observation(observation, self._predicted_q(),
                                  bool(self.base.model.NUM_BRAKES))

    def _predicted_q(self) -> FloatArray:
        if self._plan is None:
            return np.asarray(self.reference.q[0], dtype=float)
        return self._plan.q[1]

    def _next_guess(self) -> Plan:
        if self._plan is None:
            return reference_plan(self.reference)
        if self.grid == "env":
            return self._plan.shifted()
        return self._plan.shifted(self._horizon_after_step(self._plan))

    def _horizon_after_step(self, plan: Plan) -> int:
        """Intervals of a free-grid plan's rest: one fewer, or re-gridded to steps of h.

        The rest keeps its N - 1 intervals while their length stays within
        ``REGRID_TOLERANCE`` of the env step h; beyond that it is re-gridded to
        round(remaining / h) intervals (at least ``min_horizon``). Each kept step shortens the
        remaining time by h (the env's step) and the plan by one interval, so the plan's excess
        over N h is carried unchanged and the next switch comes one interval nearer. Re-gridding
        whenever rounding said so kept N at every step once the excess neared half a step, and
        the plan stalled: its next switch stayed as far ahead (a 0.03-perturbed manipulator
        episode planned 3.46 s to go for 27 steps and took 1.39x the optimum).
        """
        remaining = plan.final_time - plan.final_time / plan.num_intervals
        kept = plan.num_intervals - 1
        if kept >= self.min_horizon and abs(remaining / kept / self.time_step - 1.0) \
                <= REGRID_TOLERANCE:
            return kept
        return max(int(round(remaining / self.time_step)), self.min_horizon)

    def _nlp(self, modes: ModePattern, relaxed: bool, q: FloatArray,
             u: FloatArray) -> Transcription:
        """The fixed-pattern NLP of the remaining problem from (q, u), built once per key.

        The key is (intervals, pattern, goal relaxed); the start is the NLP's parameter. t_f is
        the intervals times h (on a time-optimal problem on the env's grid by its bounds: the
        NLP is then a feasibility problem, the cost being the number of intervals), or free
        (from ~0) on the free grid.
        The least recently used NLP is dropped past ``NLP_CACHE_SIZE``.
        """
        key = (modes.num_intervals, modes.key(), relaxed)
        transcription = self._nlps.pop(key, None)
        if transcription is None:
            final_time = modes.num_intervals * self.time_step
            bounds = ((final_time, final_time) if self.grid == "env"
                      else (1e-3 * self.time_step, self.base.final_time_bounds[1]))
            problem = dataclasses.replace(self.base, num_intervals=modes.num_intervals,
                                          final_time=final_time, final_time_bounds=bounds)
            if relaxed:
                q_tolerance, u_tolerance = self._goal_tolerances()
                problem = dataclasses.replace(problem, goal_q_tolerance=q_tolerance,
                                              goal_u_tolerance=u_tolerance)
            transcription = Transcription(problem, modes=modes, parametric_start=True)
            self.nlps_built += 1
        self._nlps[key] = transcription
        if len(self._nlps) > NLP_CACHE_SIZE:
            self._nlps.popitem(last=False)
        transcription.set_start(q, u)
        return transcription

    def _fixed(self, modes: ModePattern, relaxed: bool, q: FloatArray, u: FloatArray,
               initial: FloatArray) -> tuple[ModeSolve, Transcription]:
        """A fixed-pattern solve of the remaining problem from the NLP point ``initial``."""
        transcription = self._nlp(modes, relaxed, q, u)
        solve = solve_with_modes(transcription.problem, modes, initial=initial,
                                 transcription=transcription,
                                 max_iterations=self.max_iterations)
        return solve, transcription

    def _initial_point(self, guess: Plan, q: FloatArray, u: FloatArray) -> FloatArray:
        """The NLP point of ``guess`` (its start replaced by (q, u)) in its fixed-pattern NLP."""
        transcription = self._nlp(guess.modes, False, q, u)
        start_q, start_u = guess.q.copy(), guess.u.copy()
        start_q[0], start_u[0] = q, u
        transcription.set_guess(start_q, start_u, guess.tau, guess.final_time, guess.impulses)
        return transcription.initial_point()

    def _solve(self, guess: Plan, q: FloatArray, u: FloatArray, other_patterns: bool = True,
               relax_goal: bool = True) -> tuple[ModeSolve | None, Plan, str]:
        """The step's plan: fixed pattern, neighbours, goal relaxed, later arrival, freed.

        ``other_patterns`` False: without the neighbours and the freed pattern; ``relax_goal``
        False: without the relaxed goal.
        """
        initial = self._initial_point(guess, q, u)
        solve, transcription = self._fixed(guess.modes, False, q, u, initial)
        if self._acceptable(solve, guess):
            return solve, _plan_of(solve, transcription), ""
        if other_patterns and guess.num_intervals > 1:
            candidates = [self._fixed(pattern, False, q, u, initial)
                          for pattern in _imminent_neighbours(guess.modes)]
            accepted = [pair for pair in candidates if self._acceptable(pair[0], guess)]
            if accepted:
                best = min(accepted, key=lambda pair: pair[0].cost)
                return best[0], _plan_of(*best), "pattern shifted"
        if relax_goal:
            solve, transcription = self._fixed(guess.modes, True, q, u, initial)
            if self._acceptable(solve, guess):
                return solve, _plan_of(solve, transcription), "goal relaxed"
        extra_steps = MAX_EXTRA_STEPS if self.base.cost == "time" and self.grid == "env" else 0
        for extra in range(1, extra_steps + 1):
            longer = guess.delayed(extra)
            longer_initial = self._initial_point(longer, q, u)
            for relaxed_goal in (False, True) if relax_goal else (False,):
                solve, transcription = self._fixed(longer.modes, relaxed_goal, q, u,
                                                   longer_initial)
                if self._acceptable(solve, longer):
                    return solve, _plan_of(solve, transcription), f"{extra} step(s) later"
        if not other_patterns:
            return None, guess, "open loop"
        longest = guess
        if extra_steps:  # freed over the longest horizon allowed
            longest = guess.delayed(extra_steps)
            initial = self._initial_point(longest, q, u)
        relaxed = self._nlp(longest.modes, True, q, u).problem
        free = Transcription(relaxed, parametric_start=True)
        free.set_start(q, u)
        freed = solve_continuation(free, self.schedule, initial=initial)
        if freed.success:
            solved = freed.transcription or free
            point = np.asarray(freed.values(solved.opti.x), dtype=float).ravel()
            again, transcription = self._fixed(read_modes(solved, freed.values), True, q, u,
                                               point)
            if self._acceptable(again, guess):
                return again, _plan_of(again, transcription), "freed"
        return None, guess, "open loop"

    def _acceptable(self, solve: ModeSolve, guess: Plan) -> bool:
        """Whether a re-plan is taken.

        It must have converged and, on the free grid, not be a detour: t_f at most
        ``MAX_REPLAN_GROWTH`` times the guess's plus one step.
        """
        if not solve.success:
            return False
        return self.grid == "env" or solve.final_time <= (
            MAX_REPLAN_GROWTH * guess.final_time + self.time_step)

    def _goal_tolerances(self) -> tuple[float, float]:
        """(q, u) tolerances: ``GOAL_TOLERANCE_FRACTION`` of the maneuver's success box."""
        if self.base.model.NUM_BRAKES:
            maneuver = MANIPULATOR_MANEUVER
            q_tol, u_tol = maneuver.angle_tolerance, maneuver.velocity_tolerance
        else:
            robot = DIFF_DRIVE_MANEUVER
            q_tol = min(robot.position_tolerance / math.sqrt(2.0), robot.heading_tolerance)
            u_tol = min(robot.speed_tolerance / math.sqrt(2.0), robot.yaw_rate_tolerance)
        return GOAL_TOLERANCE_FRACTION * q_tol, GOAL_TOLERANCE_FRACTION * u_tol


def _imminent_neighbours(modes: ModePattern) -> list[ModePattern]:
    """``modes.neighbours(max_shift=1)`` that differ from ``modes`` within ``NEIGHBOUR_WINDOW``."""
    window = slice(0, NEIGHBOUR_WINDOW)
    return [pattern for _, pattern in modes.neighbours(max_shift=1)
            if any(new is not None and old is not None
                   and bool(np.any(new[:, window] != old[:, window]))
                   for new, old in ((pattern.engaged, modes.engaged),
                                    (pattern.sliding, modes.sliding)))]


def _plan_of(solve: ModeSolve, transcription: Transcription) -> Plan:
    arrays, final_time = read_solution(*values_at(transcription.problem, solve.modes,
                                                  solve.point, transcription))
    return Plan(arrays["q"], arrays["u"], arrays["tau"], solve.modes, final_time,
                {key: arrays[key] for key in GUESS_IMPULSES if key in arrays})


def reference_plan(reference: Reference) -> Plan:
    """The reference as a ``Plan``: its trajectory, torques, impulses and mode pattern.

    A brake is engaged where its bound is positive, a contact slides where its slip speed
    exceeds ``SLIP_TOLERANCE`` times the problem's velocity scale.
    """
    engaged = sliding = None
    if reference.brake_bound is not None and reference.brake_bound.shape[1]:
        engaged = np.asarray(reference.brake_bound > 0.0).T
    if "slip_speed" in reference.arrays:
        scale = make_problem(reference.name).velocity_scale
        sliding = np.asarray(reference.arrays["slip_speed"] > SLIP_TOLERANCE * scale).T
    return Plan(np.asarray(reference.q, dtype=float), np.asarray(reference.u, dtype=float),
                np.asarray(reference.tau, dtype=float), ModePattern(engaged, sliding),
                float(reference.final_time),
                {key: np.asarray(reference.arrays[key], dtype=float)
                 for key in GUESS_IMPULSES if key in reference.arrays})


__all__ = [
    "GOAL_TOLERANCE_FRACTION", "GRIDS", "GRID_OF_REFERENCE", "MAX_EXTRA_STEPS",
    "MAX_REPLAN_GROWTH", "MIN_HORIZON", "NEIGHBOUR_WINDOW", "NLP_CACHE_SIZE", "REGRID_TOLERANCE",
    "STEP_MAX_ITERATIONS",
    "MPCStep", "Plan", "ShrinkingHorizonMPC", "reference_plan",
]
