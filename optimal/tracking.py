"""Receding-horizon tracking MPC: a short window of the reference re-solved at every env step.

At env step k the controller solves, from the measured state, the transcription
(``optimal.transcription``: the simulator's midpoint step, exact contact and brake laws) over
the next H (``HORIZON``) intervals with the mode pattern of the reference's intervals k ... k+H-1
fixed (brake schedule, stick-slip), and the cost

    sum_{j=1}^{H-1} |x_j - x_{k+j}|_Q^2 + sum_{j=0}^{H-1} |tau_j - tau_{k+j}|_R^2
        + |x_H - x_{k+H}|_{P_{k+H}}^2,

with Q, R and the terminal weight P_{k+H} the time-varying LQR's (``optimal.lqr``: the
cost-to-go of the linearized problem beyond the window). The torque bounds are constraints, so
the plan respects the saturation the LQR clips. It applies the first torque and the reference's
brake command of interval k. Past the reference's end, a brake model's window holds the goal
at rest with zero torque under the last brake command (the LQR's hold weight as P) from step N
on; a contact model's windows shrink to the reference's end and the LQR holds the goal after
it: holding a rest state would stick every contact, whose laws then repeat the rows of u = 0
(a rank-deficient NLP). For the same reason the contact modes of a reference's last interval,
which ends at rest, are its neighbour's.

A brake engaged in a window that reaches past the reference's end locks its joint for good (the
hold keeps it engaged), at the relative angle it has then: a plan that lags the reference there
cannot make up the lag, and engaging on time locks the joint short of the goal. At such a step k
(the reference's interval k engages a brake that interval k - 1 left released) the controller
also solves window k - 1, the reference one step later, from the measured state and applies the
plan of lower objective; taking it delays the rest of the episode by one step (``delays``).

At each interval k at which the reference's torque reverses (time-indexed, references in
``REPLAN``: the manipulator's swing turns from accelerating to braking at interval 60 of 120)
the controller re-solves the whole remaining problem once from the measured state
(``optimal.mpc.ShrinkingHorizonMPC.replan``: the reference's mode pattern on the env's grid,
arriving on time, with the goal relaxed or 1-3 steps later) and tracks that plan instead of the
reference's rest, later by the steps it arrives later (``replans``; a plan of another pattern
is not taken). A window tracks the reference's state: from a start that lags the reference
there it keeps the torque at its bound a few steps past the reversal to catch up, after which
no plan of the pattern arrives within 3 steps and the final brake locks the arm past the goal,
from where it creeps in; the plan re-solved at the reversal brakes at once.

On the robot's references (``REPLAN_AT_START``) the same re-solve, with the goal itself (a plan
to the relaxed goal's edge, tracked a step behind, ends outside the success box), runs at the
first step from the measured start and at the next ones until a plan is taken
(``START_ATTEMPTS``: IPOPT may fail from one start and converge from the next step's). Tracking
the reference's timing from a start that cannot keep it, the windows saturate behind it and the
episode ends on the parking follower, well above the optimal time, where a plan re-solved
from the start arrives one or more steps after the reference (when IPOPT finds none, the
state-indexed windows bring the robot in); on the effort task the plan from a start is that
start's own optimum, which tracking the reference misses by up to 3 % of the effort.
A time-optimal plan that arrives d steps later begins d intervals before the reference's first:
the controller's intervals start with ``MAX_EXTRA_STEPS`` copies of the reference's first one
(as ``Plan.delayed``), used only when such a plan is taken, whose own points and multipliers
then start their windows. The re-solve costs up to 18 s of CPU time at the first step on the
time task, 2.1 s on the effort task (``mdi-envs bench control``).

One NLP per distinct window pattern is built in the constructor with the start, the reference
window and P as parameters, and wrapped once as a CasADi function of (parameters, primal and
dual start) (``Opti.to_function``); a control step is one call. Its primal start is the last
solution shifted by the intervals since it was found, its multipliers that solution's if the
window is the same NLP; the intervals the shifted plan does not cover (the last one, or more
after failed steps), and the whole first step, take the reference's own point of the window (one
per window, computed in the constructor), a consistent point of the fixed modes (repeating the
plan's last interval instead breaks the dynamics there, from where IPOPT converges to local
minima of the window far off the reference). The first step and a step into another window
pattern take the multipliers of that window solved from the reference's state (computed in the
constructor): an interior-point start needs the multipliers of its nearly active inequalities,
which zeros are not. Those multipliers, and the first step, whose start is the reference's
point, are solved with IPOPT's own warm-start pushes (the window's ``change`` function); the
steps after the first, whose start is a shifted plan, with ``WARM_START_PUSH``'s smaller ones
(``solve``). IPOPT runs from a small barrier parameter to a loose tolerance
(``SOLVER_OPTIONS``) and at most ``MAX_ITERATIONS`` iterations; if it fails, the LQR's control
is applied (``fallbacks``) and its last iterate is dropped.

On a model with friction contacts (the robot) the window NLPs take a friction factor as a
parameter (``Transcription(parametric_friction=True)``): every control step first feeds the
last measured step to a ``optimal.traction.FrictionEstimator`` and solves with its estimate, so
a floor with more or less grip than the model is planned for once a contact has slipped on it.
With ``index_on_less_friction`` the controller is time-indexed until the estimate falls below
the model's friction, or until the last of ``START_ATTEMPTS`` re-solves from the start has found
no plan, and state-indexed (``index_window``) from then on: the reference's timing is then out
of reach, and a time-indexed window would chase a reference that runs away from the robot,
while a state-indexed one follows its path at the robot's pace.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from mdi_envs._types import FloatArray
from optimal.continuation import POLISH_RELAXATION
from optimal.lqr import TimeVaryingLQR
from optimal.modes import ModePattern
from optimal.mpc import MAX_EXTRA_STEPS, ShrinkingHorizonMPC, reference_plan
from optimal.observations import StateFeedbackPolicy
from optimal.problems import make_problem, model_of
from optimal.references import Reference
from optimal.traction import FrictionEstimator
from optimal.transcription import GUESS_IMPULSES, Transcription

HORIZON = {"manipulator_time": 30, "diff_drive_effort": 40}
"""Intervals of the window (one env step each) per reference, ``DEFAULT_HORIZON`` for the others.
The manipulator's underactuated swing needs the longer window: at 15 intervals its plans
saturate behind the reference and arrive 1.5x late from 0.1-perturbed starts. The robot's
effort reference ends in a skid whose length grows as the friction falls: on a floor with 20 %
less grip the window must reach from before the skid to the fixed horizon (1.6 s) to slow the
robot in time; at 15 or 30 intervals it ends the skid 0.07-0.2 m past the goal."""

REPLAN = ("manipulator_time",)
"""References whose tracker re-solves the remaining problem at the reference's torque reversals
(see the module docstring)."""

REPLAN_AT_START = ("diff_drive_time", "diff_drive_effort")
"""References whose tracker re-solves the whole problem at the first step, from the measured
start (see the module docstring)."""

START_ATTEMPTS = 3
"""Steps from the first at which ``REPLAN_AT_START``'s re-solve runs until a plan is taken."""

DEFAULT_HORIZON = 15
"""The window of references not in ``HORIZON``."""

MAX_ITERATIONS = 50
"""IPOPT's iteration limit per control step."""

SOLVER_OPTIONS = {"print_level": 0, "sb": "yes", "tol": 1e-4, "acceptable_tol": 1e-2,
                  "acceptable_iter": 1, "mu_init": 1e-4, "warm_start_init_point": "yes"}
"""IPOPT's options besides the iteration limit: a step ends at the first acceptable iterate."""

_PUSHES = tuple(f"warm_start_{name}" for name in ("bound_push", "bound_frac", "slack_bound_push",
                                                 "slack_bound_frac", "mult_bound_push"))

_PLUGIN_OPTIONS = {"expand": True, "print_time": False, "error_on_fail": False}
"""CasADi's options of the IPOPT plugin (an SX expansion; a failed solve is a status)."""

WARM_START_PUSH = {"manipulator_time": 1e-6, "diff_drive_time": 1e-6}
"""IPOPT's warm-start pushes into the interior (``warm_start_bound_push``, ``_bound_frac``,
``_slack_bound_push``, ``_slack_bound_frac``, ``_mult_bound_push``) per reference, IPOPT's own
(1e-3) for the others: a shifted plan stays where it is."""


@dataclasses.dataclass
class _Window:
    """One window pattern's NLP as functions (see the module docstring).

    ``solve`` with ``WARM_START_PUSH``'s pushes, ``change`` with IPOPT's own (``solve`` itself
    for a reference without ``WARM_START_PUSH``).
    """

    transcription: Transcription
    solve: Any
    change: Any
    shapes: list[tuple[int, int]]
    num_multipliers: int


@dataclasses.dataclass
class _Plan:
    """One window's solve from the measured state.

    x and multipliers: the NLP's point (flat); tau (m * H,): the window's torques [N m],
    column-major; objective: the NLP's; iterations: IPOPT's.
    """

    success: bool
    objective: float
    window: _Window
    x: FloatArray
    multipliers: FloatArray
    tau: FloatArray
    iterations: int


class TrackingMPC(StateFeedbackPolicy):
    """The receding-horizon tracking MPC along ``reference`` (see the module docstring).

    Args:
        reference: the reference tracked; its grid step h must be the env's dt.
        horizon: intervals of the window (None: ``HORIZON``). max_iterations: see
            ``MAX_ITERATIONS``. solver_options: IPOPT options over ``SOLVER_OPTIONS`` and
            ``WARM_START_PUSH``.

    Attributes:
        lqr: the ``TimeVaryingLQR`` whose weights, fallback control and ``node_weight``
            (``StateFeedbackPolicy``) it uses.
        compute_times: CPU time [s] of each control step of this episode.
        fallbacks: steps of this episode at which IPOPT failed and the LQR's control was applied.
        iterations: IPOPT's iterations per step of this episode (both windows' at a step that
            solves two).
        traction: the ``FrictionEstimator`` (None: a model without friction contacts).
        friction_factors: its estimate at each step of this episode.
        delays: steps of this episode at which the reference was taken one step later (a brake
            engaged one step later, or a re-plan arriving later, once per step it is later;
            see the module docstring).
        replans: steps of this episode at which the remaining problem was re-solved and its plan
            taken (``REPLAN``, ``REPLAN_AT_START``, see the module docstring).
        index_on_less_friction: state-indexed only from the step at which the friction
            estimate is first below 1 this episode, or no plan from the start was found (see
            the module docstring); False (default): state-indexed whenever ``index_window`` is
            set.
    """

    def __init__(self, reference: Reference, horizon: int | None = None,
                 max_iterations: int = MAX_ITERATIONS,
                 solver_options: dict[str, Any] | None = None) -> None:
        self.reference = reference
        self.horizon = int(horizon or HORIZON.get(reference.name, DEFAULT_HORIZON))
        self.max_iterations = int(max_iterations)
        push = WARM_START_PUSH.get(reference.name)
        self.solver_options = {**SOLVER_OPTIONS, **({} if push is None else {
            name: push for name in _PUSHES}),
                               **(solver_options or {}), "max_iter": self.max_iterations}
        self.lqr = TimeVaryingLQR(reference)
        self.node_weight = self.lqr.node_weight
        self.base = make_problem(reference.name, len(reference.tau))
        self.has_brake = bool(self.base.model.NUM_BRAKES)
        model, parameters = model_of(self.base)
        n = model.NUM_DOFS
        self.traction = None
        if model.HAS_LOAD_TRANSFER and model.NUM_CONTACTS:  # the robot: its chassis velocity
            weight = np.zeros(n)
            weight[:2] = self.node_weight[n:n + 2]
            self.traction = FrictionEstimator(model, parameters, reference.time_step, weight)
        self.torque_bound = float(reference.metadata["torque_bound"])
        n = self.base.model.NUM_DOFS
        extension = self.horizon if self.has_brake else 0
        self._lead = (MAX_EXTRA_STEPS if reference.name in REPLAN_AT_START
                      and self.base.cost == "time" else 0)
        nodes = np.concatenate([np.zeros(self._lead, dtype=int), np.arange(len(reference.q))])
        intervals = nodes[:-1]
        steps = len(intervals)
        rest = np.concatenate([reference.q[-1], np.zeros(n)])
        self._x = np.vstack([np.hstack([reference.q, reference.u])[nodes],
                             np.repeat(rest[None], extension, 0)])
        self._tau = np.vstack([reference.tau[intervals],
                               np.zeros((extension, len(reference.tau[0])))])
        self._impulses = {key: np.asarray(reference.arrays[key], dtype=float)[intervals]
                          for key in GUESS_IMPULSES if key in reference.arrays}
        modes = reference_plan(reference).modes
        self._pattern = modes.intervals(intervals)  # what a re-plan keeps
        engaged, sliding = modes.engaged, modes.sliding
        if sliding is not None:  # the last interval, at rest: its neighbour's contact modes
            sliding = np.hstack([sliding[:, :-1], sliding[:, -2:-1]])
        self._modes = ModePattern(*(
            None if rows is None else
            np.hstack([rows[:, intervals], np.repeat(rows[:, -1:], extension, 1)])
            for rows in (engaged, sliding)))
        self._brake = (np.vstack([reference.brake_bound[intervals],
                                  np.repeat(reference.brake_bound[-1:], extension, 0)])
                       if self.has_brake else None)
        self._terminal = np.concatenate([self.lqr.cost_to_go[nodes],
                                         np.repeat(self.lqr.hold_cost_to_go[None], extension, 0)])
        self._windows: dict[bytes, _Window] = {}
        torque = np.sign(reference.tau)
        self._replan_intervals: set[int] = set()  # the intervals that re-solve the rest
        if reference.name in REPLAN:
            reversals = np.flatnonzero(np.any(torque[1:] * torque[:-1] < 0, axis=1)) + 1
            self._replan_intervals = set(reversals.tolist())
        if reference.name in REPLAN_AT_START:
            self._replan_intervals = set(range(self._lead, self._lead + START_ATTEMPTS))
        self._reference_x, self._reference_tau = self._x, self._tau
        self._full: ShrinkingHorizonMPC | None = None
        self._keys = [self._window(k) for k in range(steps + (1 if extension else 0))]
        self._reference_points = [self._reference_point(k) for k in range(len(self._keys))]
        self._reference_multipliers = [self._reference_multiplier(k)
                                       for k in range(len(self._keys))]
        self._reference_starts = (tuple(self._reference_points),
                                  tuple(self._reference_multipliers))  # what a reset restores
        self.compute_times: list[float] = []
        self.fallbacks: list[int] = []
        self.iterations: list[int] = []
        self.friction_factors: list[float] = []
        self.delays: list[int] = []
        self.replans: list[int] = []
        self._replanned: set[int] = set()
        self._previous: tuple[_Window, FloatArray, FloatArray, int] | None = None
        self._measured: tuple[FloatArray, FloatArray, FloatArray] | None = None
        self.index_on_less_friction = False
        self._off_timing = False
        self._start_delay = 0

    @property
    def node_states(self) -> FloatArray:
        """(N + d + 1, 2n) the states a state-indexed step searches (``StateFeedbackPolicy``).

        The reference's, or the plan re-solved from the start once taken (d: the steps it
        arrives later); node j is the interval a time-indexed env step j acts for.
        """
        first = self._lead - self._start_delay
        return self._x[first:len(self.reference.tau) + self._lead + 1]

    def reset(self) -> None:
        """A new episode: step counter, records, warm starts and friction estimate start again.

        The windows' start points and multipliers are the reference's again: a plan taken at
        the second or third step from the start writes its own into windows the next episode's
        first step starts from.
        """
        self.compute_times, self.fallbacks, self.iterations = [], [], []
        self.friction_factors, self.delays, self.replans = [], [], []
        self._replanned = set()
        self._x, self._tau = self._reference_x, self._reference_tau
        self._reference_points = list(self._reference_starts[0])
        self._reference_multipliers = list(self._reference_starts[1])
        self._previous = self._measured = None
        self._off_timing = False
        self._start_delay = 0
        if self.traction is not None:
            self.traction.reset()

    def predicted_q(self, step: int) -> FloatArray:
        """(n,) the reference's q at env step ``step`` (the goal past the end)."""
        x = self._x[min(max(self._interval(step), 0), len(self._keys) - 1)]
        return x[:x.size // 2]

    def reference_interval(self, step: int) -> int:
        """The reference's interval that env step ``step`` acts for: later by the ``delays``."""
        return step - len(self.delays)

    def _interval(self, step: int) -> int:
        """The controller's interval of env step ``step`` (the reference's, past the lead)."""
        return self.reference_interval(step) + self._lead

    def is_state_indexed(self) -> bool:
        """With ``index_window``: always, or once the reference's timing is out of reach.

        The latter with ``index_on_less_friction``: from the step at which the friction
        estimate fell below 1 or the start's re-solves found no plan, for the rest of the
        episode.
        """
        if self.traction is not None and self.traction.factor < 1.0:
            self._off_timing = True
        return bool(self.index_window) and (self._off_timing or not self.index_on_less_friction)

    def control(self, step: int, q: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(torques (m,) [N m], brake bounds (k,)) at env step ``step`` in the state (q, u).

        Each call is taken as the env step after the last call's (its torques applied).
        """
        tau, brake = self._control(step, q, u)
        self._measured = (q, u, tau)
        return tau, brake

    def applied(self, action: FloatArray) -> None:
        """The friction estimate's next update takes the torques of ``action`` (the base's)."""
        if self._measured is not None:
            q, u, tau = self._measured
            torques = np.clip(np.asarray(action[:tau.size], dtype=float), -1.0, 1.0)
            self._measured = (q, u, torques * self.torque_bound)

    def _control(self, step: int, q: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
        """``control`` without recording the step."""
        extra = []
        if self.traction is not None:
            if self._measured is not None:
                self.traction.update(*self._measured, u)
            self.friction_factors.append(self.traction.factor)
            extra = [self.traction.factor]
        if self._interval(step) >= len(self._keys) and not self.has_brake:
            return self.lqr.control(step, q, u)  # past the reference (a brake's: the hold)
        k = min(self._interval(step), len(self._keys) - 1)
        if k in self._replan_intervals and k not in self._replanned and not self.is_state_indexed():
            self._replanned.add(k)
            self._replan(step, k, q, u)
            if self._replanned >= self._replan_intervals and not self.replans and (
                    self.reference.name in REPLAN_AT_START):  # no plan from the start
                self._off_timing = True
            k = min(self._interval(step), len(self._keys) - 1)
        plan = self._solve(k, q, u, extra)
        iterations = plan.iterations
        if self._engages(k):  # the reference one step later: the brake engaged one step later
            later = self._solve(k - 1, q, u, extra)
            iterations += later.iterations
            if later.success and (not plan.success or later.objective < plan.objective):
                plan, k = later, k - 1
                self.delays.append(step)
        self.iterations.append(iterations)
        brake = self._brake[k] if self._brake is not None else np.zeros(0)
        if not plan.success:  # the next step starts from the last solution, shifted further
            self.fallbacks.append(step)
            return self.lqr.control(step, q, u)[0], brake
        self._previous = (plan.window, plan.x, plan.multipliers, k)
        tau0 = plan.tau.reshape(-1, plan.window.shapes[0][1] - 1)[:, 0]
        return np.clip(tau0, -self.torque_bound, self.torque_bound), brake

    def _replan(self, step: int, k: int, q: FloatArray, u: FloatArray) -> None:
        """The remaining problem re-solved at env step ``step`` (reference interval k), taken.

        Its plan replaces the reference's rest from interval k - d on, d the steps it arrives
        later (see the module docstring), if it has the reference's mode pattern.
        """
        if self._full is None:
            self._full = ShrinkingHorizonMPC(self.reference, grid="env")
        at_start = self.reference.name in REPLAN_AT_START  # the goal itself, not relaxed
        plan = self._full.replan(k - self._lead, q, u, relax_goal=not at_start)
        steps = len(self.reference.tau) + self._lead
        later = 0 if plan is None else plan.num_intervals - (steps - k)
        if plan is None or k - later < 0 or (
                plan.modes.key() != self._pattern.intervals(slice(k - later, None)).key()):
            return
        self._x, self._tau = self._x.copy(), self._tau.copy()
        self._x[k - later:steps + 1] = np.hstack([plan.q, plan.u])
        self._tau[k - later:steps] = plan.tau
        for j in range(k - later, k):  # the lead's windows: their start from the plan
            self._reference_points[j] = self._reference_point(j)
            self._reference_multipliers[j] = self._reference_multiplier(j)
        self.delays += [step] * later
        self.replans.append(step)
        if at_start:  # a plan taken: no more attempts
            self._replanned |= self._replan_intervals
            self._start_delay = later

    def _engages(self, k: int) -> bool:
        """Whether interval k engages a brake released over k - 1, in a window into the hold.

        The window of k reaches the hold past the reference's end (see the module docstring).
        """
        engaged, steps = self._modes.engaged, len(self.reference.tau) + self._lead
        return engaged is not None and steps - self.horizon < k < steps and bool(
            np.any(engaged[:, k] & ~engaged[:, k - 1]))

    def _solve(self, k: int, q: FloatArray, u: FloatArray, extra: list[float]
               ) -> _Plan:
        """Window k from the state (q, u)."""
        window = self._windows[self._keys[k]]
        reference = self._reference_points[k]
        solve = window.change
        if self._previous is None:
            x0, lam0 = reference, self._reference_multipliers[k]
        else:
            last, x_last, lam_last, solved_at = self._previous
            x0 = np.concatenate([x_last, reference])[
                _shift_indices(last.shapes, window.shapes, max(k - solved_at, 0))]
            lam0 = lam_last if last is window else self._reference_multipliers[k]
            solve = window.solve
        end = k + window.shapes[0][1] - 1  # intervals: q has one column per node
        x, lam, tau, objective = solve(q, u, self._x[k:end + 1].T, self._tau[k:end].T,
                                       self._terminal[end], *extra, x0, lam0)
        stats = solve.stats()
        return _Plan(bool(stats.get("success", False)), float(objective), window,
                     np.asarray(x, dtype=float).ravel(), np.asarray(lam, dtype=float).ravel(),
                     np.asarray(tau, dtype=float).ravel(), int(stats.get("iter_count", -1)))

    def _window(self, k: int) -> bytes:
        """The key of window k's NLP (its intervals k ... k + H - 1, as far as there are)."""
        modes = self._modes.intervals(slice(k, k + self.horizon))
        key = modes.key()
        if key not in self._windows:
            self._windows[key] = self._build(modes)
        return key

    def _build(self, modes: ModePattern) -> _Window:
        """The window NLP of ``modes`` as a function (see the module docstring)."""
        import casadi

        big_h, h = modes.num_intervals, self.reference.time_step
        problem = dataclasses.replace(self.base, num_intervals=big_h, cost="effort",
                                      final_time=big_h * h, goal_q={}, goal_u={})
        t = Transcription(problem, modes=modes, parametric_start=True,
                          parametric_friction=self.traction is not None)
        opti = t.opti
        n2, m = 2 * self.base.model.NUM_DOFS, self.base.model.NUM_INPUTS
        x_ref, tau_ref = opti.parameter(n2, big_h + 1), opti.parameter(m, big_h)
        terminal = opti.parameter(n2, n2)
        error = casadi.vertcat(t.q, t.u) - x_ref
        torque = t.tau - tau_ref
        Q, R = self.lqr.state_weight, self.lqr.input_weight
        tracking = sum(casadi.bilin(Q, error[:, j], error[:, j]) for j in range(1, big_h))
        tracking += sum(casadi.bilin(R, torque[:, j], torque[:, j]) for j in range(big_h))
        tracking += casadi.bilin(terminal, error[:, big_h], error[:, big_h])
        effort_unit = problem.torque_bound**2 * problem.final_time
        opti.minimize(opti.f - t.cost / effort_unit + tracking / big_h)
        opti.solver("ipopt", _PLUGIN_OPTIONS,
                    self.solver_options)
        q0, u0 = t._start
        opti.set_value(t.rho, 0.0)
        opti.set_value(t.relaxation, POLISH_RELAXATION)
        friction = [t.friction_factor] if self.traction is not None else []
        inputs = [q0, u0, x_ref, tau_ref, terminal, *friction, opti.x, opti.lam_g]
        outputs = [opti.x, opti.lam_g, t.tau, opti.f]
        solve = change = opti.to_function("window", inputs, outputs)
        own = {name: value for name, value in self.solver_options.items()
               if name not in _PUSHES}
        if own != self.solver_options:
            opti.solver("ipopt", _PLUGIN_OPTIONS,
                        own)
            change = opti.to_function("window_change", inputs, outputs)
        return _Window(t, solve, change, [raw.shape for raw, _ in t._raw.values()], opti.ng)

    def _reference_point(self, k: int) -> FloatArray:
        """The NLP point of window k on the reference (its warm start where no plan is)."""
        window = self._windows[self._keys[k]]
        length, n = window.shapes[0][1] - 1, self.base.model.NUM_DOFS
        span = slice(k, k + length)
        impulses = {key: value[span] for key, value in self._impulses.items()}
        x = self._x[k:k + length + 1]
        window.transcription.set_guess(x[:, :n], x[:, n:], self._tau[span],
                                       length * self.reference.time_step, impulses)
        return window.transcription.initial_point()

    def _reference_multiplier(self, k: int) -> FloatArray:
        """The multipliers of window k's solution from the reference's state k (zeros if none)."""
        window = self._windows[self._keys[k]]
        length = window.shapes[0][1] - 1
        n, end = self.base.model.NUM_DOFS, k + length
        friction = [1.0] if self.traction is not None else []
        _, lam, _, _ = window.change(self._x[k, :n], self._x[k, n:], self._x[k:end + 1].T,
                                 self._tau[k:end].T, self._terminal[end], *friction,
                                 self._reference_points[k], np.zeros(window.num_multipliers))
        if not window.change.stats().get("success", False):
            return np.zeros(window.num_multipliers)
        return np.asarray(lam, dtype=float).ravel()


def _shift_indices(old: list[tuple[int, int]], new: list[tuple[int, int]],
                   by: int) -> np.ndarray:
    """Indices into (old point, fill point) that make a start of another NLP (shapes ``new``).

    Every variable of a ``Transcription`` is a (rows, columns) matrix over the grid's nodes or
    intervals, stored column-major in declaration order: the old point has the shapes ``old``,
    the fill point (appended after it) the shapes ``new``. Each new column j takes the old
    column j + ``by`` (the plan ``by`` intervals on), the fill point's column j where there is
    none.
    """
    indices, offset = [], 0
    filler = sum(rows * columns for rows, columns in old)
    for (rows, columns), (_, new_columns) in zip(old, new, strict=True):
        source = np.arange(new_columns) + by
        block = offset + np.arange(rows * columns).reshape(columns, rows)
        fill = filler + np.arange(rows * new_columns).reshape(new_columns, rows)
        indices.append(np.where((source < columns)[:, None],
                                block[np.minimum(source, columns - 1)], fill).ravel())
        offset += rows * columns
        filler += rows * new_columns
    return np.concatenate(indices)


__all__ = ["DEFAULT_HORIZON", "HORIZON", "MAX_ITERATIONS", "REPLAN", "REPLAN_AT_START",
           "SOLVER_OPTIONS", "START_ATTEMPTS", "WARM_START_PUSH", "TrackingMPC"]
