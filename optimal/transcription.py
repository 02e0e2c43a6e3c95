"""Problem (34) of Yunt & Glocker transcribed on the engine's midpoint discretization.

With h = t_f / N (t_f a variable when the problem is time-optimal) and per interval k

    q_M = q_k + h/2 u_k
    M(q_M) (u_{k+1} - u_k) = (h(q_M, u_k) + theta J (u_{k+1} - u_k) + B(q_M) tau_k) h
                             + W(q_M)^T P_k,            J = dh/du (q_M, u_k), theta = 1/2
    q_{k+1} = q_M + h/2 u_{k+1},

exactly the step of ``mdi_envs.stepping.MoreauJeanStepper`` (whose linearly implicit theta term
keeps velocity-dependent forces from pumping energy; it vanishes when h does not depend on u).
M, h, B and the contact and brake rows W come from the model's single definition
(``mdi_envs.mechanics.symbolic``). The impulses P_k and the complementarity pairs (a, b >= 0
with a b = 0) are NLP variables; the pairs are enforced by ``optimal.continuation`` (a penalty
rho sum a b whose weight rises and a relaxation a b <= r that falls). The laws, per interval:

* Brake j (the impulsive, set-valued control): engaged means xi_B = W_B u_{k+1} = 0 with P_B
  free, released means P_B = 0. Both are the one law |P_B| |xi_B| = 0, written with
  nonnegative parts P_B = p+ - p-, xi_B = v+ - v- and the pair (p+ + p-, v+ + v-). The brake
  schedule is an output: engaged where the relative velocity after the step is zero.
* Frictionless unilateral contact i with a gap (planar models): the stepper's law -- closed at
  the midpoint (g_i(q_M) <= 0) gives 0 <= P_N _|_ xi_N >= 0 with xi_N = W_N (u_{k+1} + eps u_k),
  open gives P_N = 0 -- as g_i(q_M) = o - c (open and closing parts), a slack v >= 0 that lets
  xi_N be negative while open and s = xi_N + v >= 0, with the pairs (o, c), (P_N, o),
  (P_N, s) and (v, c).
* Spatial Coulomb contact i with load transfer (the robot, set I_NC): P_N = N0 h + K P_T >= 0
  (no contact lifts off), slip xi_T = W_T u_{k+1} (2,), and with the slip speed lam >= 0 and the
  cone slack s = mu^2 P_N^2 - |P_T|^2 >= 0:  mu P_N xi_T + lam P_T = 0 and the pair (lam, s).
  Sliding (lam > 0) puts P_T on the cone boundary against the slip, |xi_T| = lam; sticking
  (lam = 0) gives xi_T = 0. In the last interval, when u_N = 0 is imposed, every slip is zero
  and only the cone is stated; the polish (``Transcription.polished``) fixes the modes.

The NLP is nondimensional: every variable is stored in the problem's units (``time_scale``,
``velocity_scale``, ``impulse_scale``, ``length_scale``; inputs in units of ``torque_bound``)
and every constraint is divided by its unit, and the pairs are compared in these units, so that
a residual is dimensionless. With units that follow the physics' own scaling (the manipulator's
time unit sqrt(1 kg m^2 / tau_max)) the NLP, and so its solution path, is the same for every
torque bound. Planar Coulomb friction at gap contacts
is not transcribed (no shipped problem needs it; ``NotImplementedError``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from mdi_envs._types import FloatArray
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.mechanics.symbolic import symbolic_equations
from optimal.modes import ModePattern

IMPLICIT_THETA = 0.5
"""The stepper's theta for velocity-dependent forces (``mdi_envs.stepping._kernel``)."""


TANGENT_REGULARIZATION = 1e-6
"""Weight of sum |P_T / impulse_scale|^2 / N in the objective of load-transfer models: the rigid
robot leaves the split of the lateral impulse between its two wheels undetermined (their
lateral rows coincide), which leaves a direction of the NLP without curvature; this picks the
least-norm split and changes the cost by less than this weight. (The coinciding rows also make
the two wheels' sticking laws duplicate constraints -- a rank-deficient Jacobian that no
objective term repairs; ``Transcription.polished`` states them once.)"""


BRAKE_SPLIT_REGULARIZATION = 1e-6
"""Weight of sum (p+ + p-) / impulse_scale / N over the engaged intervals of a fixed mode
pattern: there xi_B = 0 and only P_B = p+ - p- enters the dynamics, so (p+, p-) + (d, d) is a
direction without cost that IPOPT's log barrier follows without bound (fixed-pattern solves
then stalled at their iteration limit on the right cost). This term picks the split with
min(p+, p-) = 0 and adds 1e-6 |P_B| (impulse units) to the cost."""

GUESS_IMPULSES = ("tangent_impulse", "slip_speed")
"""The per-interval solution arrays (``read_solution`` names) ``Transcription.set_guess`` takes
besides the trajectory: the friction of load-transfer contacts. A warm start of the robot needs
them (a fixed-pattern solve from its own optimum's trajectory without them: 200+ iterations,
9 % off; with them 14)."""


def regridded_impulses(impulses: dict[str, FloatArray], holder: np.ndarray,
                       step_ratio: float) -> dict[str, FloatArray]:
    """``GUESS_IMPULSES`` arrays moved to another grid of the same maneuver.

    Args:
        impulses: per-interval arrays by name, each (N_old, ·).
        holder: (N_new,) the old interval each new interval takes its values from.
        step_ratio: new interval length / old one. An impulse per interval scales with it,
            a slip speed does not.
    """
    return {key: value[holder] * (1.0 if key == "slip_speed" else step_ratio)
            for key, value in impulses.items()}


@dataclass(frozen=True)
class OptimalControlProblem:
    """A named instance of problem (34): model, boundary conditions, bounds, cost, grid.

    Attributes:
        name: the problem's name (``optimal.problems.PROBLEMS`` key).
        model: the ``ModelDefinition`` subclass. parameters: its parameters (None: defaults).
        num_intervals: N, the number of midpoint steps.
        initial_q: (n,) coordinates at t = 0. initial_u: (n,) velocities at t = 0.
        goal_q: {coordinate index: value} imposed at t_f (other coordinates free).
        goal_u: {coordinate index: value} imposed at t_f.
        torque_bound: |tau_i| <= this, per input [N m or N].
        cost: "time" (minimize t_f) or "effort" (minimize sum_k h |tau_k|^2 [N^2 m^2 s]).
        final_time: t_f [s] when cost is "effort"; the naive initial guess when "time".
        final_time_bounds: (lower, upper) of t_f [s] when cost is "time".
        guess_final_q: (n,) end of the linear interpolation used as the initial guess.
        impulse_scale: [N s or N m s] unit of impulses in complementarity residuals.
        velocity_scale: [m/s or rad/s] unit of velocities in them.
        length_scale: [m] unit of gaps in them and of the coordinates' kinematic equations.
        time_scale: [s] unit of t_f (and of the time-optimal cost).
        env_id: the environment the reference is meant for (metadata).
        env_kwargs: (key, value) pairs for ``gym.make(env_id, ...)`` (metadata), e.g. the
            robot's ``objective="effort"``.
        description: one line for humans.
        goal_q_tolerance: |q_i(t_f) - goal| <= this for the ``goal_q`` entries [rad or m]; 0
            imposes the goal exactly (every reference; the MPC's fallback relaxes it).
        goal_u_tolerance: the same for ``goal_u`` [rad/s or m/s].
        guess_bend_scale: (n,) largest amplitude per coordinate of the half-sine bends the
            global search's random starts add to the naive guess (``set_naive_guess(bump)``);
            () keeps their guesses straight.
    """

    name: str
    model: type[ModelDefinition]
    num_intervals: int
    initial_q: tuple[float, ...]
    initial_u: tuple[float, ...]
    goal_q: dict[int, float]
    goal_u: dict[int, float]
    torque_bound: float
    cost: Literal["time", "effort"]
    final_time: float
    guess_final_q: tuple[float, ...]
    parameters: Any = None
    final_time_bounds: tuple[float, float] = (0.0, np.inf)
    impulse_scale: float = 1.0
    velocity_scale: float = 1.0
    length_scale: float = 1.0
    time_scale: float = 1.0
    env_id: str = ""
    env_kwargs: tuple[tuple[str, Any], ...] = ()
    description: str = ""
    goal_q_tolerance: float = 0.0
    goal_u_tolerance: float = 0.0
    guess_bend_scale: tuple[float, ...] = ()


@dataclass
class Pair:
    """Complementarity pairs of one kind: a, b >= 0 elementwise, a b = 0 wanted.

    Attributes:
        kind: a label ("brake", "gap", ...). a, b: CasADi expressions of equal shape.
        scale: the product's unit (a b / scale is dimensionless).
    """

    kind: str
    a: Any
    b: Any
    scale: float


@dataclass
class Transcription:
    """The NLP of one problem, built once; ``continuation`` solves it stage by stage.

    Attributes:
        problem: the problem transcribed. modes: None (the modes are free: complementarity
            pairs), or a ``ModePattern`` whose brake and contact modes the NLP states exactly
            (the polish NLP of ``polished``, the fixed-pattern solves of
            ``optimal.mode_search``).
        parametric_start: the initial state is an NLP parameter (``set_start``), so that one
            built NLP serves every start (the MPC's re-solves); False states the problem's
            ``initial_q``/``initial_u`` as constants.
        parametric_friction: every friction coefficient of load-transfer contacts is the
            model's times ``friction_factor``, an NLP parameter (1 until set), so that one
            built NLP serves a friction estimated on line (the tracking MPC's).
        opti: the ``casadi.Opti`` instance.
        q: (n, N+1) coordinates. u: (n, N+1) velocities. tau: (m, N) inputs.
        final_time: t_f (a variable or a float). step: h = t_f / N.
        rho: penalty weight (parameter). relaxation: bound r on each scaled product (parameter).
        friction_factor: the ``parametric_friction`` parameter (1.0 without it).
        pairs: the complementarity pairs. cost: the problem's cost (expression).
        outputs: named expressions extracted from a solution (impulses, slips, ...).
        solver_settings: what ``optimal.continuation.set_solver`` last set (None: nothing).
    """

    problem: OptimalControlProblem
    modes: ModePattern | None = None
    parametric_start: bool = False
    parametric_friction: bool = False
    opti: Any = field(init=False)
    q: Any = field(init=False)
    u: Any = field(init=False)
    tau: Any = field(init=False)
    final_time: Any = field(init=False)
    step: Any = field(init=False)
    rho: Any = field(init=False)
    relaxation: Any = field(init=False)
    friction_factor: Any = field(init=False, default=1.0)
    cost: Any = field(init=False)
    pairs: list[Pair] = field(init=False, default_factory=list)
    outputs: dict[str, Any] = field(init=False, default_factory=dict)
    solver_settings: Any = field(init=False, default=None)
    _start: tuple[Any, Any] | None = field(init=False, default=None)
    _slack_guesses: list[tuple[Any, Callable[[], Any]]] = field(init=False, default_factory=list)
    _raw: dict[int, tuple[Any, float]] = field(init=False, default_factory=dict)
    _contact: Any = field(init=False, default=None)

    def __post_init__(self) -> None:
        import casadi

        pr = self.problem
        model = pr.model
        parameters = pr.parameters if pr.parameters is not None else model.Parameters()  # type: ignore[attr-defined]
        values = parameters.values()
        eq = symbolic_equations(model, parameters)
        q_sym, u_sym = casadi.SX.sym("q", model.NUM_DOFS), casadi.SX.sym("u", model.NUM_DOFS)
        force_jacobian = casadi.Function(
            "dh_du", [q_sym, u_sym], [casadi.jacobian(eq.forces(q_sym, u_sym), u_sym)]
        )
        n, m, big_n = model.NUM_DOFS, model.NUM_INPUTS, pr.num_intervals
        c, d, k = model.NUM_CONTACTS, model.CONTACT_DIMENSION, model.NUM_BRAKES
        opti = casadi.Opti()
        self.opti = opti
        s_imp, s_vel, s_len = pr.impulse_scale, pr.velocity_scale, pr.length_scale
        self.q = self.variable((n, big_n + 1), s_len)
        self.u = self.variable((n, big_n + 1), s_vel)
        self.tau = self.variable((m, big_n), pr.torque_bound)
        if pr.cost == "time":
            self.final_time = self.variable((1, 1), pr.time_scale)
            low, high = pr.final_time_bounds
            opti.subject_to(opti.bounded(low / pr.time_scale, self.final_time / pr.time_scale,
                                         high / pr.time_scale))
        else:
            self.final_time = pr.final_time
        h = self.final_time / big_n
        self.step = h
        self.rho, self.relaxation = opti.parameter(), opti.parameter()
        if self.parametric_friction:
            self.friction_factor = opti.parameter()
            opti.set_value(self.friction_factor, 1.0)

        modes = self.modes or ModePattern()
        if modes.num_intervals not in (0, big_n):
            raise ValueError(f"the mode pattern has {modes.num_intervals} intervals, the "
                             f"problem {big_n}")
        brake = _BrakeLaw(opti, self.variable, k, big_n, s_imp, s_vel,
                          modes.engaged) if k else None
        gap = contact = None
        if c and model.HAS_LOAD_TRANSFER:
            if d != 3:
                raise NotImplementedError("load-transfer contacts are transcribed in 3-D only")
            contact = _LoadTransferLaw(opti, self.variable, model, values, big_n, s_imp, s_vel,
                                       modes.sliding, self.friction_factor)
        elif c:
            if any(mu > 0.0 for mu in model.friction_coefficients(values)) or d != 2:
                raise NotImplementedError("gap contacts are transcribed without friction only")
            gap = _GapLaw(opti, self.variable, model, values, big_n, s_imp, s_vel, s_len)

        for i in range(big_n):
            qk, uk, u_next = self.q[:, i], self.u[:, i], self.u[:, i + 1]
            qm = qk + h / 2 * uk
            implicit = IMPLICIT_THETA * force_jacobian(qm, uk) @ (u_next - uk)
            generalized = (eq.forces(qm, uk) + implicit + eq.inputs(qm) @ self.tau[:, i]) * h
            if brake is not None:
                generalized += brake.interval(i, eq.brake_rows(qm), u_next)
            if gap is not None:
                generalized += gap.interval(i, eq.gaps(qm), eq.contact_rows(qm), uk, u_next)
            if contact is not None:
                # at rest after the last step every slip is zero: the law reduces to the cone
                at_rest = (i == big_n - 1 and set(pr.goal_u) == set(range(n))
                           and pr.goal_u_tolerance == 0.0)
                generalized += contact.interval(i, h, eq.contact_rows(qm), u_next, at_rest)
            opti.subject_to((eq.mass(qm) @ (u_next - uk) - generalized) / s_imp == 0)
            opti.subject_to((self.q[:, i + 1] - qm - h / 2 * u_next) / s_len == 0)

        start_q: Any = np.asarray(pr.initial_q, dtype=float)
        start_u: Any = np.asarray(pr.initial_u, dtype=float)
        if self.parametric_start:
            self._start = opti.parameter(n), opti.parameter(n)
            start_q, start_u = self._start
            self.set_start(pr.initial_q, pr.initial_u)
        opti.subject_to((self.q[:, 0] - start_q) / s_len == 0)
        opti.subject_to((self.u[:, 0] - start_u) / s_vel == 0)
        for end, goal, tolerance, unit in ((self.q, pr.goal_q, pr.goal_q_tolerance, s_len),
                                           (self.u, pr.goal_u, pr.goal_u_tolerance, s_vel)):
            for index, value in goal.items():
                error = (end[index, big_n] - value) / unit
                if tolerance > 0.0:
                    opti.subject_to(opti.bounded(-tolerance / unit, error, tolerance / unit))
                else:
                    opti.subject_to(error == 0)
        opti.subject_to(opti.bounded(-1.0, casadi.vec(self.tau) / pr.torque_bound, 1.0))

        if brake is not None:
            self.pairs.append(Pair("brake", brake.magnitude, brake.speed, s_imp * s_vel))
            self.outputs.update(brake_impulse=brake.impulse, brake_velocity=brake.velocity)
            self._slack_guesses += brake.guesses
        if gap is not None:
            self.pairs += [
                Pair("gap split", gap.open, gap.closing, s_len**2),
                Pair("no force when open", gap.normal, gap.open, s_imp * s_len),
                Pair("Signorini", gap.normal, gap.signorini, s_imp * s_vel),
                Pair("no approach when closed", gap.approach, gap.closing, s_vel * s_len),
            ]
            self.outputs.update(normal_impulse=gap.normal, midpoint_gap=gap.open - gap.closing)
            self._slack_guesses += gap.guesses
        if contact is not None:
            self.pairs.append(Pair("slip", contact.slip_speed, contact.cone_slack,
                                   s_vel * s_imp**2))
            self.outputs.update(normal_impulse=contact.normal, tangent_impulse=contact.tangent,
                                slip_speed=contact.slip_speed, slip_velocity=contact.slip)
            self._contact = contact
            self._slack_guesses += contact.guesses

        if pr.cost == "time":
            self.cost = self.final_time
            cost_unit = pr.time_scale
        else:
            self.cost = h * casadi.sumsqr(self.tau)
            cost_unit = pr.torque_bound**2 * pr.final_time
        regularization = 0
        if brake is not None and modes.engaged is not None:
            regularization = BRAKE_SPLIT_REGULARIZATION * casadi.sum1(casadi.vec(
                brake.magnitude * np.asarray(modes.engaged, dtype=float))) / s_imp
        if contact is not None:
            regularization += TANGENT_REGULARIZATION * casadi.sumsqr(contact.tangent / s_imp)
        penalty = 0
        for pair in self.pairs:
            products = pair.a * pair.b / pair.scale
            penalty += casadi.sum1(casadi.vec(products))
            opti.subject_to(casadi.vec(products) <= self.relaxation)
        opti.minimize(self.cost / cost_unit + (self.rho * penalty + regularization) / big_n)

    def polished(self, values: Callable[[Any], Any]) -> Transcription:
        """The polish NLP of a load-transfer model at the modes of the point ``values``.

        A contact slides over an interval where its slip speed exceeds the scaled cone slack
        (the larger side of the pair), else sticks. The new NLP has the same variables (so
        ``opti.x`` carries over) and states each mode's law exactly and without repeated rows:
        sticking fixes the slip speed to 0 and the slip W_T u_{k+1} to 0, with the rows that
        repeat a sticking row of another contact (the two wheels' lateral slip) stated once;
        sliding fixes the cone slack to 0 and keeps mu P_N xi_T + lam P_T = 0.
        """
        def rows(expression: Any) -> np.ndarray:  # (contacts, N): CasADi drops unit dimensions
            return np.asarray(values(expression), dtype=float).reshape(expression.shape)

        contact_slip = rows(self.outputs["slip_speed"])
        cone = rows(self._contact.cone_slack)
        pr = self.problem
        sliding = contact_slip / pr.velocity_scale > cone / pr.impulse_scale**2
        return Transcription(pr, modes=ModePattern(sliding=sliding))

    def set_start(self, q: Any, u: Any) -> None:
        """The initial state of a ``parametric_start`` NLP: q (n,), u (n,) [SI units]."""
        if self._start is None:
            raise ValueError("set_start needs a Transcription built with parametric_start=True")
        for parameter, value in zip(self._start, (q, u), strict=True):
            self.opti.set_value(parameter, np.asarray(value, dtype=float))

    def set_naive_guess(self, bump: FloatArray | None = None) -> None:
        """The documented naive initial guess, optionally bent.

        Coordinates interpolate linearly from ``initial_q`` to ``guess_final_q`` over t_f (the
        problem's ``final_time``), velocities are that interpolation's constant rate, inputs
        are zero, brakes released and impulses zero; every slack takes the value its defining
        equation gives at this guess.

        Args:
            bump: (n,) amplitudes of a half sine, bump * sin(pi t / t_f), added to the
                coordinates (and its derivative to the velocities): the same ends, another
                path between them (the global search's random starts). None: straight.
        """
        pr = self.problem
        big_n = pr.num_intervals
        start = np.asarray(pr.initial_q, dtype=float)
        end = np.asarray(pr.guess_final_q, dtype=float)
        weights = np.linspace(0.0, 1.0, big_n + 1)
        q = start[None, :] + (end - start)[None, :] * weights[:, None]
        u = np.repeat(((end - start) / pr.final_time)[None, :], big_n + 1, axis=0)
        if bump is not None:
            amplitude = np.asarray(bump, dtype=float)
            if amplitude.shape != start.shape:
                raise ValueError(f"bump must have shape {start.shape}, got {amplitude.shape}")
            q = q + amplitude[None, :] * np.sin(np.pi * weights)[:, None]
            u = u + amplitude[None, :] * (np.pi / pr.final_time) * np.cos(np.pi * weights)[:, None]
        self.set_guess(q, u, np.zeros((big_n, pr.model.NUM_INPUTS)), pr.final_time)

    def initial_point(self) -> FloatArray:
        """(nx,) the NLP point of the current initial guess (``set_guess``, ``set_naive_guess``)."""
        return np.asarray(self.opti.value(self.opti.x, self.opti.initial()), dtype=float).ravel()

    def set_guess(self, q: FloatArray, u: FloatArray, tau: FloatArray,
                  final_time: float, impulses: dict[str, FloatArray] | None = None) -> None:
        """An initial guess from a trajectory on this grid, impulses zero unless given.

        Args:
            q: (N+1, n) coordinates. u: (N+1, n) velocities. tau: (N, m) inputs.
            final_time: t_f [s] (used when it is a variable).
            impulses: the friction of load-transfer contacts, named as in ``read_solution``:
                "tangent_impulse" (N, 2c) [N s] and "slip_speed" (N, c) [m/s] (None: zero).
                Without them a fixed-pattern robot solve from its own optimum's trajectory
                took 200+ iterations and ended 9 % off; with them, 14.

        Every slack takes the value its defining equation gives at this guess (brakes
        released).
        """
        self._set_initial(self.q, np.asarray(q, dtype=float).T)
        self._set_initial(self.u, np.asarray(u, dtype=float).T)
        self._set_initial(self.tau, np.asarray(tau, dtype=float).T)
        if self.problem.cost == "time":
            self._set_initial(self.final_time, final_time)
        for variable, guess in self._slack_guesses:
            self._set_initial(variable, self.opti.value(guess(), self.opti.initial()))
        given = {key: np.asarray(value, dtype=float).T for key, value in (impulses or {}).items()}
        contact = self._contact
        if contact is not None and "tangent_impulse" in given:
            self._set_initial(contact.tangent, given["tangent_impulse"])
            self._set_initial(contact.slip_speed,
                              given.get("slip_speed", np.zeros(contact.slip_speed.shape)))
            self._set_initial(contact.cone_slack,
                              self.opti.value(contact.cones, self.opti.initial()))

    def variable(self, shape: tuple[int, int], scale: float, nonnegative: bool = False) -> Any:
        """A new NLP variable in units of ``scale``: returns scale * raw (the physical value)."""
        raw = self.opti.variable(*shape)
        if nonnegative:
            import casadi

            self.opti.subject_to(casadi.vec(raw) >= 0)
        expression = scale * raw
        self._raw[id(expression)] = (raw, scale)
        return expression

    def _set_initial(self, expression: Any, value: Any) -> None:
        """Initial value of a variable made by ``variable``, given in physical units."""
        raw, scale = self._raw[id(expression)]
        self.opti.set_initial(raw, np.asarray(value, dtype=float) / scale)

    def residuals(self, values: Callable[[Any], Any]) -> tuple[float, float]:
        """(natural residual max min(a, b), product residual max a b), both scaled.

        Args:
            values: evaluates an expression at a point (e.g. ``solution.value``).
        """
        natural, product = 0.0, 0.0
        for pair in self.pairs:
            root = float(np.sqrt(pair.scale))
            a = np.atleast_1d(np.asarray(values(pair.a), dtype=float)).ravel() / root
            b = np.atleast_1d(np.asarray(values(pair.b), dtype=float)).ravel() / root
            if a.size:
                natural = max(natural, float(np.max(np.abs(np.minimum(a, b)))))
                product = max(product, float(np.max(np.abs(a * b))))
        return natural, product


Factory = Callable[..., Any]
"""``Transcription.variable``: (shape, scale, nonnegative) -> scale * raw."""


@dataclass
class _BrakeLaw:
    """Variables and constraints of the brakes (see the module docstring)."""

    opti: Any
    new: Factory
    num_brakes: int
    num_intervals: int
    impulse_unit: float
    velocity_unit: float
    engaged: Any = None

    def __post_init__(self) -> None:
        import casadi

        shape = (self.num_brakes, self.num_intervals)
        self.impulse_parts = tuple(self.new(shape, self.impulse_unit, True) for _ in range(2))
        self.velocity_parts = tuple(self.new(shape, self.velocity_unit, True) for _ in range(2))
        self._rows: list[Any] = []
        if self.engaged is not None:  # fixed modes: engaged -> xi_B = 0, released -> P_B = 0
            engaged = np.asarray(self.engaged, dtype=bool).ravel(order="F")
            for parts, unit, where in ((self.velocity_parts, self.velocity_unit, engaged),
                                       (self.impulse_parts, self.impulse_unit, ~engaged)):
                indices = np.flatnonzero(where).tolist()
                if indices:
                    for part in parts:
                        self.opti.subject_to(casadi.vec(part)[indices] / unit == 0)

    def interval(self, i: int, rows: Any, u_next: Any) -> Any:
        """Generalized brake impulse W_B^T P_B of interval i; ties v+ - v- to W_B u_{k+1}."""
        plus, minus = self.velocity_parts
        self.opti.subject_to((rows @ u_next - plus[:, i] + minus[:, i]) / self.velocity_unit
                             == 0)
        self._rows.append(rows @ u_next)
        return rows.T @ (self.impulse_parts[0][:, i] - self.impulse_parts[1][:, i])

    @property
    def impulse(self) -> Any:
        """P_B (k, N) [N m s]."""
        return self.impulse_parts[0] - self.impulse_parts[1]

    @property
    def velocity(self) -> Any:
        """Xi_B = W_B u_{k+1} (k, N) [rad/s]."""
        return self.velocity_parts[0] - self.velocity_parts[1]

    @property
    def magnitude(self) -> Any:
        """p+ + p- (k, N)."""
        return self.impulse_parts[0] + self.impulse_parts[1]

    @property
    def speed(self) -> Any:
        """v+ + v- (k, N)."""
        return self.velocity_parts[0] + self.velocity_parts[1]

    @property
    def guesses(self) -> list[tuple[Any, Callable[[], Any]]]:
        """Slack initial values: the parts of W_B u_{k+1} at the guess (impulses zero)."""
        import casadi

        velocity = casadi.horzcat(*self._rows)
        return [(self.impulse_parts[0], lambda: 0 * velocity),
                (self.impulse_parts[1], lambda: 0 * velocity),
                (self.velocity_parts[0], lambda: casadi.fmax(velocity, 0)),
                (self.velocity_parts[1], lambda: casadi.fmax(-velocity, 0))]


@dataclass
class _GapLaw:
    """Variables and constraints of frictionless gap contacts (see the module docstring)."""

    opti: Any
    new: Factory
    model: type[ModelDefinition]
    values: Any
    num_intervals: int
    impulse_unit: float
    velocity_unit: float
    length_unit: float

    def __post_init__(self) -> None:
        shape = (self.model.NUM_CONTACTS, self.num_intervals)
        self.normal = self.new(shape, self.impulse_unit, True)
        self.open = self.new(shape, self.length_unit, True)
        self.closing = self.new(shape, self.length_unit, True)
        self.approach = self.new(shape, self.velocity_unit, True)
        self.signorini = self.new(shape, self.velocity_unit, True)
        self._restitution = np.asarray(self.model.restitutions(self.values), dtype=float)
        self._gaps: list[Any] = []
        self._speeds: list[Any] = []

    def interval(self, i: int, gaps: Any, rows: Any, u_now: Any, u_next: Any) -> Any:
        """Generalized normal impulse W_N^T P_N of interval i, with the gap/velocity slacks."""
        d = self.model.CONTACT_DIMENSION
        normal_rows = rows[::d, :]
        speed = normal_rows @ u_next + self._restitution * (normal_rows @ u_now)
        self.opti.subject_to((gaps - self.open[:, i] + self.closing[:, i]) / self.length_unit
                             == 0)
        self.opti.subject_to(
            (self.signorini[:, i] - speed - self.approach[:, i]) / self.velocity_unit == 0
        )
        self._gaps.append(gaps)
        self._speeds.append(speed)
        return normal_rows.T @ self.normal[:, i]

    @property
    def guesses(self) -> list[tuple[Any, Callable[[], Any]]]:
        """Slack initial values from the gaps and normal speeds at the guess (P_N = 0)."""
        import casadi

        gaps, speeds = casadi.horzcat(*self._gaps), casadi.horzcat(*self._speeds)
        return [(self.normal, lambda: 0 * gaps),
                (self.open, lambda: casadi.fmax(gaps, 0)),
                (self.closing, lambda: casadi.fmax(-gaps, 0)),
                (self.approach, lambda: casadi.fmax(-speeds, 0)),
                (self.signorini, lambda: casadi.fmax(speeds, 0))]


@dataclass
class _LoadTransferLaw:
    """Variables and constraints of spatial Coulomb contacts with N = N0 + K F."""

    opti: Any
    new: Factory
    model: type[ModelDefinition]
    values: Any
    num_intervals: int
    impulse_unit: float
    velocity_unit: float
    sliding: Any = None
    friction_factor: Any = 1.0

    def __post_init__(self) -> None:
        c = self.model.NUM_CONTACTS
        self._same_row = _identical_tangent_rows(self.model, self.values)
        self.tangent = self.new((2 * c, self.num_intervals), self.impulse_unit)
        self.slip_speed = self.new((c, self.num_intervals), self.velocity_unit, True)
        self.cone_slack = self.new((c, self.num_intervals), self.impulse_unit**2, True)
        n0, gain = self.model.normal_loads(self.values)
        self._n0 = np.asarray(n0, dtype=float)
        self._gain = np.asarray(gain, dtype=float)
        self._mu = np.asarray(self.model.friction_coefficients(self.values), dtype=float)
        self._normals: list[Any] = []
        self._slips: list[Any] = []
        self._cones: list[Any] = []

    def interval(self, i: int, h: Any, rows: Any, u_next: Any, at_rest: bool = False) -> Any:
        """Generalized friction impulse W_T^T P_T of interval i, with its laws.

        ``at_rest``: u_{k+1} = 0 is imposed, so every slip is zero and the law reduces to P_T
        in the cone with slip speed 0 (stating it would repeat the rows of u_{k+1} = 0).
        """
        import casadi

        c = self.model.NUM_CONTACTS
        tangent_rows = casadi.vertcat(*[rows[3 * j + 1:3 * j + 3, :] for j in range(c)])
        p_t = self.tangent[:, i]
        p_n = self._n0 * h + self._gain @ p_t
        mu = [self.friction_factor * self._mu[j] for j in range(c)]
        slip = tangent_rows @ u_next
        unit, speed_unit = self.impulse_unit, self.velocity_unit
        self.opti.subject_to(p_n / unit >= 0)
        cones = []
        stated: list[int] = []  # rows of W_T already set to zero in this interval
        for j in range(c):
            pj, sj = p_t[2 * j:2 * j + 2], slip[2 * j:2 * j + 2]
            cones.append((mu[j] * p_n[j]) ** 2 - casadi.sumsqr(pj))
            if at_rest:
                self.opti.subject_to(self.slip_speed[j, i] / speed_unit == 0)
            elif self.sliding is not None and not self.sliding[j, i]:  # sticks
                self.opti.subject_to(self.slip_speed[j, i] / speed_unit == 0)
                for row in (2 * j, 2 * j + 1):
                    if not any(self._same_row[row, other] for other in stated):
                        self.opti.subject_to(slip[row] / speed_unit == 0)
                        stated.append(row)
            else:
                self.opti.subject_to(
                    (mu[j] * p_n[j] * sj + self.slip_speed[j, i] * pj)
                    / (unit * speed_unit) == 0
                )
                if self.sliding is not None:  # slides: on the cone
                    self.opti.subject_to(self.cone_slack[j, i] / unit**2 == 0)
        cone = casadi.vertcat(*cones)
        self.opti.subject_to((self.cone_slack[:, i] - cone) / unit**2 == 0)
        self._normals.append(p_n)
        self._slips.append(slip)
        self._cones.append(cone)
        return tangent_rows.T @ p_t

    @property
    def normal(self) -> Any:
        """P_N (c, N) [N s]."""
        import casadi

        return casadi.horzcat(*self._normals)

    @property
    def cones(self) -> Any:
        """mu^2 P_N^2 - |P_T|^2 (c, N) [N^2 s^2], the cone slacks' defining expressions."""
        import casadi

        return casadi.horzcat(*self._cones)

    @property
    def slip(self) -> Any:
        """Slip velocities W_T u_{k+1} (2c, N) [m/s], body frame (longitudinal, lateral)."""
        import casadi

        return casadi.horzcat(*self._slips)

    @property
    def guesses(self) -> list[tuple[Any, Callable[[], Any]]]:
        """Slack initial values at the guess (P_T = 0, no slip): the full cone, mu^2 P_N^2."""
        cones = self.cones
        return [(self.tangent, lambda: 0 * self.tangent),
                (self.slip_speed, lambda: 0 * self.slip_speed),
                (self.cone_slack, lambda: cones)]


def _identical_tangent_rows(model: type[ModelDefinition], values: Any) -> np.ndarray:
    """(2c, 2c) booleans: which tangent rows of W coincide for every q.

    For the robot: the two wheels' lateral rows. Found by evaluating the rows at three random
    configurations.
    """
    import math

    class _Ops:
        cos, sin = staticmethod(math.cos), staticmethod(math.sin)

    rng = np.random.default_rng(0)
    c, d = model.NUM_CONTACTS, model.CONTACT_DIMENSION
    tangent = [j for j in range(c * d) if j % d]
    samples = [np.asarray(model.contact_directions(rng.normal(size=model.NUM_DOFS), values,
                                                   _Ops), dtype=float)[tangent]
               for _ in range(3)]
    same = np.ones((len(tangent), len(tangent)), dtype=bool)
    for rows in samples:
        same &= np.all(np.isclose(rows[:, None, :], rows[None, :, :], rtol=0.0, atol=1e-12),
                       axis=2)
    return same


def numeric(value: Any) -> FloatArray:
    """A CasADi value as a float array (scalars become shape ())."""
    return np.asarray(value, dtype=float)


__all__ = [
    "BRAKE_SPLIT_REGULARIZATION",
    "GUESS_IMPULSES",
    "IMPLICIT_THETA",
    "TANGENT_REGULARIZATION",
    "OptimalControlProblem",
    "Pair",
    "Transcription",
    "numeric",
    "regridded_impulses",
]
