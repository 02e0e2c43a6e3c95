"""The numerical stress cases of the Moreau-Jean engine and the LCP solvers, with their criteria.

Families (each case's docstring states its criteria and why their limits hold):

1. ``zeno``: balls dropped with restitution eps in {0, 0.3, 0.6, 0.9, 0.99} for 10^6 steps;
2. ``brake_toggle``: the manipulator's ideal brake engaged and released on alternate steps for
   10^5 steps under full motor torque;
3. ``dt_sweep``: dt from 1e-6 to 1e-1 s on every model over a fixed horizon;
4. ``mu_sweep``: friction coefficients 0 ... 2 on the slope and on the robot;
5. ``overdrive``: torques 10x, 100x, 1000x the maneuver bounds on the manipulator and the robot;
6. ``lcp``: degenerate, rank-deficient and ill-conditioned LCPs (and the Siconos peer files)
   given straight to ``solve_lcp`` with every method;
7. ``long_horizon``: energy, momentum and brake-constraint drift over 10^6 manipulator steps
   (and 10^5 robot steps).

A case is a dict ``{family, name, parameters, metrics, criteria, passed}``; a criterion is
``{value, limit, relation, passed}`` (``relation`` ``"<="`` or ``">="``; a NaN or infinite value
never passes). Shared criteria: ``non_finite`` (NaN/inf entries in any recorded q, u or impulse;
limit 0) and ``solver_failures`` (steps whose complementarity solve did not report CONVERGED;
limit 0). Where the manipulator is driven beyond what its dt resolves (overdrive, dt = 0.1 s, the
brake toggled at full torque for 10^5 steps) the stepper must say so: its INACCURATE status (the
under-resolution flag, see ``mdi_envs.stepping._free_motion.RESOLVED_INERTIA_FRACTION``) is then
reported in the metrics, not counted as a failure, and the energy balance must hold up to the
first flagged step (no silent energy gain). Long runs call ``step_batch`` with ``num_substeps`` =
a stride and record every stride-th state (the status is the worst over the substeps, so no
failed solve is missed).

``plan(config)`` lists every case (name, the computation that produces it); ``case(name)`` runs
it, sharing one simulation between the copies of a batch. ``MDI_ENVS_STRESS=quick`` selects the
quick configuration: it compiles two models only (block and manipulator): its Zeno balls are
point masses dropped on the block's slope set flat (``SlidingBlock`` with slope_angle = 0 is the
bouncing ball with radius 0), and it skips the differential-drive robot's cases.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cache
from typing import Any

import numpy as np
from peer_data import PEER_DATA, peer_files

from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER, MANIPULATOR_MANEUVER
from mdi_envs.mechanics.models import BlockableManipulator, BouncingBall, SlidingBlock
from mdi_envs.mechanics.models.diff_drive import DiffDriveRobot
from mdi_envs.solvers.lcp import LCP_METHODS, lcp_residual, solve_lcp
from mdi_envs.solvers.siconos_io import read_lcp
from mdi_envs.solvers.status import SolverStatus
from mdi_envs.stepping import MoreauJeanStepper
from mdi_envs.stepping._kernel import INFO_STATUS
from mdi_envs.stepping._spatial_kernel import INFO_LIFTED_CONTACTS, INFO_MODE

FloatArray = np.ndarray
Criterion = dict[str, Any]

MODELS: dict[str, Any] = {
    "ball": BouncingBall,
    "block": SlidingBlock,
    "manipulator": BlockableManipulator,
    "diff_drive": DiffDriveRobot,
}
"""Model label -> ``ModelDefinition`` class."""

CONSTANT_FORCE_MODELS = (BouncingBall, SlidingBlock)
"""Models whose h is a constant force (gravity): their potential energy is -h . q."""

BALL_TIME_STEP = 1e-3
"""[s] The ball and block environments' physics step (``time_step`` of their envs)."""
MANIPULATOR_TIME_STEP = 0.01
"""[s] The manipulator environment's physics step."""
DIFF_DRIVE_TIME_STEP = 0.01
"""[s] The differential-drive environment's physics step."""

EPS_MACHINE = float(np.finfo(float).eps)
REST_SPEED = 1e-10
"""[m/s] A ball is at rest when every velocity component is at most this."""
BRAKE_VELOCITY_RTOL = 1e-12
"""Largest |beta' - alpha'| / max(1, |u|_inf) after an engaged step (round-off of the solve)."""
SOLVER_TOL = 1e-9
"""Relative accuracy expected of the robot's FC3D solve (its Newton tolerance is 1e-12 in units
of the weight impulse; energy and load errors are a few of these per step)."""
LCP_TOL = 1e-10
"""The LCP methods' default tolerance on the shared residual."""
ANGLE_PER_STEP_CAP = 0.3
"""[rad] Cap on omega dt in the second-order energy allowance (omega dt)^2: the estimate holds
while a step turns the links by a small angle; past 0.3 rad (17 deg) per step no accuracy is
claimed, and an energy gain above 0.09 of the energy scale fails however coarse the step."""


@dataclass(frozen=True)
class StressConfig:
    """Sizes of one run.

    Attributes:
        quick: the quick mode (see the module docstring).
        models: model labels whose kernels are compiled (cases of the others are skipped).
        zeno_restitutions: eps of the Zeno balls. zeno_steps: steps per ball run.
        zeno_heights: drop heights above contact [m] (one batch copy each).
        zeno_chunk: substeps per call once every ball rests.
        toggle_steps: steps of the brake-toggle case.
        dt_grid: time steps of the dt sweep [s]. dt_horizon: its simulated time [s].
        dt_max_calls: most ``step_batch`` calls (recorded states) per dt-sweep run.
        block_mu_grid: friction coefficients on the slope (plus tan(theta) (1 -+ 1e-3)).
        robot_mu_grid: friction coefficients of the robot's wheels and stick.
        overdrive_factors: multiples of the maneuver's torque bound.
        overdrive_horizon: simulated time of the overdrive runs [s].
        long_steps: steps of the manipulator's long run. long_stride: substeps per record.
        robot_long_steps: steps of the robot's long roll.
    """

    quick: bool
    models: tuple[str, ...]
    zeno_restitutions: tuple[float, ...] = (0.0, 0.3, 0.6, 0.9, 0.99)
    zeno_steps: int = 10**6
    zeno_heights: tuple[float, ...] = (0.55, 0.7, 0.85, 1.0)
    zeno_chunk: int = 10**5
    toggle_steps: int = 10**5
    dt_grid: tuple[float, ...] = (1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
    dt_horizon: float = 0.3
    dt_max_calls: int = 20_000
    block_mu_grid: tuple[float, ...] = (0.0, 0.25, 0.5, 1.0, 2.0)
    robot_mu_grid: tuple[float, ...] = (0.0, 0.1, 0.25, 0.6, 1.0, 2.0)
    overdrive_factors: tuple[float, ...] = (10.0, 100.0, 1000.0)
    overdrive_horizon: float = 1.0
    long_steps: int = 10**6
    long_stride: int = 50
    robot_long_steps: int = 10**5


FULL = StressConfig(quick=False, models=("ball", "block", "manipulator", "diff_drive"))
QUICK = StressConfig(quick=True, models=("block", "manipulator"), zeno_steps=10**4,
                     toggle_steps=10**4, dt_horizon=0.15, dt_max_calls=2_000, long_steps=10**4,
                     long_stride=10, robot_long_steps=0)
CONFIG = QUICK if os.environ.get("MDI_ENVS_STRESS") == "quick" else FULL
"""The configuration of this process: ``FULL`` unless ``MDI_ENVS_STRESS=quick``."""
NOTES = [note for condition, note in (
    ("diff_drive" not in CONFIG.models, "quick mode: the differential-drive robot is not "
     "compiled; its dt-sweep, mu-sweep, overdrive and long-roll cases are skipped"),
    ("ball" not in CONFIG.models, "quick mode: the Zeno balls are point masses on the block's "
     "slope set flat (SlidingBlock, slope_angle 0), the ball with radius 0")) if condition]
"""What the configuration leaves out, for the record."""


# --------------------------------------------------------------------------- steppers, traces
@dataclass
class Steppers:
    """Builds steppers, compiling each model's kernels once and timing that first call."""

    compile_s: dict[str, float] = field(default_factory=dict)

    def get(self, label: str, time_step: float, locate_impacts: bool = False,
            **parameters: Any) -> MoreauJeanStepper:
        """A stepper of model ``label`` with ``parameters``, compiled on the kernel's first use.

        ``locate_impacts`` steppers have kernels of their own, timed as ``label + " located"``.
        """
        model = MODELS[label]
        stepper = MoreauJeanStepper(model, model.Parameters(**parameters), time_step,
                                    locate_impacts=locate_impacts)  # fmt: skip
        label = label + (" located" if locate_impacts else "")
        if label not in self.compile_s:
            start = time.perf_counter()
            n, m, k = model.NUM_DOFS, model.NUM_INPUTS, model.NUM_BRAKES
            stepper.step_batch(np.zeros((1, n)), np.zeros((1, n)), np.zeros((1, m)),
                               np.zeros((1, k)))
            self.compile_s[label] = time.perf_counter() - start
        return stepper


@dataclass
class Trace:
    """States recorded by ``simulate`` every ``stride`` steps (C calls, N copies).

    Attributes:
        q, u: (C + 1, N, n) coordinates and velocities, from the initial ones.
        impulses: (C, N, c*d + k) impulses of the last step of each call.
        info: (C, N, info_size) diagnostics of each call (status: the worst over its substeps).
        tau: (C, N, m) inputs held over each call. brake: (C, N, k) brake bounds.
        stride: steps per call. dt: time step [s].
    """

    q: FloatArray
    u: FloatArray
    impulses: FloatArray
    info: FloatArray
    tau: FloatArray
    brake: FloatArray
    stride: int
    dt: float

    @property
    def status(self) -> FloatArray:
        """(C, N) worst solver status code of each call."""
        return self.info[:, :, INFO_STATUS]

    @property
    def time(self) -> FloatArray:
        """(C + 1,) time of each recorded state [s]."""
        return np.arange(self.q.shape[0]) * self.stride * self.dt


def _per_call(value: Any, calls: int, copies: int, size: int) -> FloatArray:
    """(calls, copies, size) float64 from None (zeros), (copies, size) or (calls, copies, size).

    Always a fresh writable C-contiguous array: numba types a read-only view (what
    ``np.broadcast_to`` returns, and ``np.ascontiguousarray`` keeps when it is already
    contiguous) as another argument type and would compile the step kernels again.
    """
    result = np.zeros((calls, copies, size))
    if value is not None:
        result[...] = np.asarray(value, dtype=float)
    return result


def simulate(stepper: MoreauJeanStepper, q0: Any, u0: Any, num_steps: int, tau: Any = None,
             brake: Any = None, stride: int = 1) -> Trace:
    """Advance N copies ``num_steps`` steps, recording every ``stride``-th state.

    Args:
        stepper: the stepper. q0, u0: (N, n) initial states.
        num_steps: steps per copy (a multiple of ``stride``).
        tau: inputs, None (zeros), (N, m) constant or (num_steps / stride, N, m) per call.
        brake: brake bounds, as ``tau`` with (..., k).
        stride: steps per ``step_batch`` call (``num_substeps``).

    Returns:
        The ``Trace``.
    """
    if num_steps % stride:
        raise ValueError(f"num_steps {num_steps} is not a multiple of stride {stride}")
    q = np.array(q0, dtype=float, order="C", ndmin=2)
    u = np.array(u0, dtype=float, order="C", ndmin=2)
    copies, calls = q.shape[0], num_steps // stride
    taus = _per_call(tau, calls, copies, stepper.num_inputs)
    brakes = _per_call(brake, calls, copies, stepper.num_brakes)
    qs = np.empty((calls + 1, copies, stepper.num_dofs))
    us = np.empty_like(qs)
    impulses = np.empty((calls, copies, stepper.num_impulses))
    info = np.empty((calls, copies, stepper.info_size))
    qs[0], us[0] = q, u
    out = (np.empty((copies, stepper.num_impulses)), np.empty((copies, stepper.info_size)))
    for c in range(calls):
        stepper.step_batch(q, u, taus[c], brakes[c], stride, False, out)
        qs[c + 1], us[c + 1], impulses[c], info[c] = q, u, out[0], out[1]
    return Trace(qs, us, impulses, info, taus, brakes, stride, float(stepper.time_step))


# --------------------------------------------------------------------------- model quantities
def _entries(matrix: Any, shape: tuple[int, ...]) -> FloatArray:
    """A model's tuple-of-rows matrix evaluated on arrays, broadcast to (rows, cols, *shape)."""
    return np.array([[np.broadcast_to(np.asarray(v, dtype=float), shape) for v in row]
                     for row in matrix])


def kinetic_energy(stepper: MoreauJeanStepper, q: FloatArray, u: FloatArray) -> FloatArray:
    """T = u^T M(q) u / 2 [J] for states q, u of shape (..., n), from the model's own M."""
    values = stepper.parameters.values()
    mass = _entries(stepper.model.mass_matrix(np.moveaxis(q, -1, 0), values, np), q.shape[:-1])
    return 0.5 * np.einsum("ij...,...i,...j->...", mass, u, u)


def potential_energy(stepper: MoreauJeanStepper, q: FloatArray, q_ref: Sequence[float]
                     ) -> FloatArray:  # fmt: skip
    """V(q) - V(q_ref) = -h . (q - q_ref) [J] for constant-force models, else 0; shape q[..., 0]."""
    if stepper.model not in CONSTANT_FORCE_MODELS:
        return np.zeros(q.shape[:-1])
    force = np.array(stepper.model.forces(None, None, stepper.parameters.values(), np), dtype=float)
    return -(q - np.asarray(q_ref)) @ force


def penetration(stepper: MoreauJeanStepper, q: FloatArray) -> FloatArray:
    """max(0, -min_i g_i(q)) [m] for states (..., n) (0 for models without contacts)."""
    if stepper.model.NUM_CONTACTS == 0 or stepper.model.HAS_LOAD_TRANSFER:
        return np.zeros(q.shape[:-1])
    gaps = np.array([np.broadcast_to(g, q.shape[:-1]) for g in stepper.model.gaps(
        np.moveaxis(q, -1, 0), stepper.parameters.values(), np)])
    return np.maximum(-gaps.min(axis=0), 0.0)


def input_work(stepper: MoreauJeanStepper, trace: Trace) -> FloatArray:
    """(C, N) work tau . B^T (q_next - q) of the inputs over each call [J] (B constant)."""
    values = stepper.parameters.values()
    b = np.array(stepper.model.input_matrix(trace.q[0, 0], values, math), dtype=float)
    return np.einsum("cnm,im,cni->cn", trace.tau, b, np.diff(trace.q, axis=0))


def free_motion_work(stepper: MoreauJeanStepper, trace: Trace) -> FloatArray:
    """(C, N) work of the inputs over each step's smooth part, constant-M models with h = 0.

    With u_free = u + M^-1 B tau dt, T(u_free) - T(u) = dt (B tau) . (u + u_free) / 2 exactly,
    and T(u+) <= T(u_free) because every contact impulse dissipates (P . gamma+ <= 0 for the
    Coulomb laws on xi = gamma+): so T(u_k+1) - T(u_k) <= this work, to round-off. Needs
    ``trace.stride == 1``.
    """
    if trace.stride != 1:
        raise ValueError("free_motion_work needs every step (stride 1)")
    values = stepper.parameters.values()
    q0 = trace.q[0, 0]
    mass = np.array(stepper.model.mass_matrix(q0, values, math), dtype=float)
    b = np.array(stepper.model.input_matrix(q0, values, math), dtype=float)
    force = np.einsum("im,cnm->cni", b, trace.tau)
    u_free = trace.u[:-1] + trace.dt * np.einsum("ij,cnj->cni", np.linalg.inv(mass), force)
    return 0.5 * trace.dt * np.einsum("cni,cni->cn", force, trace.u[:-1] + u_free)


# --------------------------------------------------------------------------- criteria
def at_most(value: float, limit: float) -> Criterion:
    """Criterion ``value <= limit``; fails when ``value`` is NaN or infinite."""
    value = float(value)
    return {"value": value, "limit": float(limit), "relation": "<=",
            "passed": bool(math.isfinite(value) and value <= limit)}


def at_least(value: float, limit: float) -> Criterion:
    """Criterion ``value >= limit``; fails when ``value`` is NaN or infinite."""
    value = float(value)
    return {"value": value, "limit": float(limit), "relation": ">=",
            "passed": bool(math.isfinite(value) and value >= limit)}


def count_non_finite(*arrays: FloatArray) -> int:
    """Number of NaN/inf entries in all ``arrays``."""
    return int(sum(np.size(a) - np.count_nonzero(np.isfinite(a)) for a in arrays))


def health_criteria(trace: Trace, copy: int | slice = slice(None),
                    under_resolved_reported: bool = False) -> dict[str, Criterion]:  # fmt: skip
    """``non_finite`` (entries of q, u, impulses) and ``solver_failures`` (calls not CONVERGED).

    Args:
        trace: the run. copy: which copies (default all).
        under_resolved_reported: for runs that drive the manipulator beyond what its dt
            resolves (about a radian per step), where the stepper is expected to say so: calls
            reporting INACCURATE (the step's under-resolution flag) then do not count as
            failures; every other status still does.
    """
    status = trace.status[:, copy]
    failures = np.count_nonzero(status != SolverStatus.CONVERGED)
    criteria = {
        "non_finite": at_most(count_non_finite(trace.q[:, copy], trace.u[:, copy],
                                               trace.impulses[:, copy]), 0),
        "solver_failures": at_most(failures, 0),
    }
    if under_resolved_reported:
        inaccurate = np.count_nonzero(status == SolverStatus.INACCURATE)
        criteria["solver_failures"] = at_most(failures - inaccurate, 0)
    return criteria


def first_under_resolved_call(trace: Trace, copy: int) -> int | None:
    """Index of the first call of ``copy`` reporting INACCURATE (under-resolved), or None."""
    flagged = np.flatnonzero(trace.status[:, copy] == SolverStatus.INACCURATE)
    return int(flagged[0]) if flagged.size else None


def energy_excess_ratio(energy: FloatArray, supplied: FloatArray, allowance: FloatArray
                        ) -> float:  # fmt: skip
    """max_t (E(t) - E(0) - supplied(t)) / allowance(t): energy gained beyond what was supplied.

    Args:
        energy: (C + 1,) energy at the recorded states [J].
        supplied: (C + 1,) work done on the system up to each state [J] (0 at the start).
        allowance: (C + 1,) the tolerated excess at each state [J] (>= 0; a positive excess
            against a zero allowance gives inf).

    Returns:
        The largest ratio (NaN/inf if the energy is not finite: the criterion then fails).
    """
    excess = energy - energy[0] - supplied
    if not np.all(np.isfinite(excess)):
        return math.inf
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        ratio = np.where(excess <= 0.0, 0.0, excess / allowance)
    return float(ratio.max()) if np.all(np.isfinite(ratio)) else math.inf


def prior_max(values: FloatArray) -> FloatArray:
    """(C + 1,) running maximum over the states strictly before each one (itself for the first).

    Scales for tolerances must come from the trajectory before a step, so that a step that blows
    up cannot widen its own tolerance.
    """
    running = np.maximum.accumulate(values)
    return np.concatenate([running[:1], running[:-1]])


def smallest_mass_eigenvalue(stepper: MoreauJeanStepper, q: FloatArray) -> float:
    """Smallest eigenvalue of M(q) over the states q (..., n) [kg, kg m^2]."""
    values = stepper.parameters.values()
    mass = _entries(stepper.model.mass_matrix(np.moveaxis(q, -1, 0), values, np), q.shape[:-1])
    return float(np.linalg.eigvalsh(np.moveaxis(mass.reshape(*mass.shape[:2], -1), -1, 0)).min())


def second_order_energy_allowance(stepper: MoreauJeanStepper, trace: Trace, energy: FloatArray,
                                  copy: int, work_abs: FloatArray) -> FloatArray:
    """(C + 1,) tolerated energy excess of the manipulator: (omega dt)^2 (T + |W|) + round-off.

    The theta = 1/2 midpoint scheme is second order: over a free spin its relative energy error
    stays below 0.46 (omega dt)^2 (omega the largest angular speed; measured at dt = 1e-3 ...
    0.1 over 200 s, no growth), so (omega dt)^2 T bounds it with a margin of 2; under a torque
    the energy supplied, |W| = sum |tau . Delta alpha|, enters the scale too. Scales come from
    the states *before* each one (``prior_max``), so that a step that blows up cannot widen its
    own tolerance: omega is the largest prior speed plus the most one step of torque can add,
    max |tau| dt / lambda_min(M); omega dt is capped at ``ANGLE_PER_STEP_CAP``. Round-off:
    4 eps per step of T + |W| [J].
    """
    speed = prior_max(np.abs(trace.u[:, copy]).max(axis=1))
    kick = np.abs(trace.tau[:, copy]).max() * trace.dt / smallest_mass_eigenvalue(
        stepper, trace.q[:, copy])
    angle = np.minimum((speed + kick) * trace.dt, ANGLE_PER_STEP_CAP)
    steps = np.arange(trace.q.shape[0]) * trace.stride
    round_off = (4.0 * steps + 4.0) * EPS_MACHINE * (np.abs(energy) + work_abs)
    return angle**2 * (prior_max(energy) + work_abs) + round_off


def case_record(family: str, name: str, parameters: dict[str, Any], metrics: dict[str, Any],
                criteria: dict[str, Criterion], notes: str = "") -> dict[str, Any]:
    """One case of the JSON record; it passes when all its criteria pass."""
    record = {"family": family, "name": name, "parameters": parameters, "metrics": metrics,
              "criteria": criteria, "passed": all(c["passed"] for c in criteria.values())}
    if notes:
        record["notes"] = notes
    return record


def _contact_offset(stepper: MoreauJeanStepper) -> float:
    """Height of the point mass's coordinate at contact (the ball's radius; 0 for the block)."""
    return -float(stepper.model.gaps((0.0, 0.0), stepper.parameters.values(), math)[0])


# --------------------------------------------------------------------------- 1. Zeno balls
def zeno_case(eps: float, located: bool) -> list[dict[str, Any]]:
    """Balls dropped from rest, one batch copy per drop height, for each eps; dt = 1e-3 s.

    Each eps runs with the default midpoint step and with ``locate_impacts=True`` ("located").

    Closed forms (v1 = sqrt(2 g h0)): first impact t1 = sqrt(2 h0 / g), rest at the Zeno time
    t_inf = t1 (1 + eps) / (1 - eps). Criteria:

    * ``energy_above_initial``: max (E - E0) / E0 <= 1e-12. Flight is integrated exactly and
      each impact dissipates, so the energy never exceeds its initial value beyond round-off.
    * ``energy_rise_per_step``: max step-to-step rise / (m g^2 dt^2) <= 1. The midpoint law
      acts on contacts closed at q_M: a ball below ground and already rising is turned around,
      which can gain at most m g^2 dt^2 (``tests/stepping/test_moreau_jean_ball.py``).
    * ``penetration``: max depth / ((v1 + g dt) dt) <= 1: a contact closes once its midpoint gap
      is <= 0, so the ball sinks at most one step at its largest speed (v1 + g dt, the speed a
      step after reaching the ground).
    * ``rest_delay`` (when the horizon covers t_inf): max |t_rest - t_inf| / ((3 K + 2) dt) <= 1,
      t_rest the time from which |u| <= 1e-10. K = ln(g dt / (2 v1)) / ln(eps) counts the
      bounces longer than a step; each shifts the sequence by a few steps (measured 2.1-2.4 steps
      per bounce for eps = 0.3 ... 0.99, one step for eps = 0).
    * ``drift_after_rest``: once every ball rests the remaining steps run in chunks; max |q -
      q_rest| <= 1e-12 m and max |u| <= 1e-10 m/s at every chunk end (the rest state is a fixed
      point of the step).
    * ``energy_decay`` (when the horizon ends before t_inf): E_end / (E0 eps^(2 (n - 1))) <= 1
      with n the closed-form impacts before the end: at least the closed form's dissipation,
      one impact of lag allowed.
    """
    config, steppers = CONFIG, STEPPERS
    label = "ball" if "ball" in config.models else "block"
    heights = np.array(config.zeno_heights)
    if label == "ball":
        st = steppers.get("ball", BALL_TIME_STEP, located, restitution=eps)
    else:
        st = steppers.get("block", BALL_TIME_STEP, located, slope_angle=0.0,
                          restitution=eps, friction_coefficient=0.0)
    p, dt = st.parameters, BALL_TIME_STEP
    g, m = p.gravity, p.mass
    offset = _contact_offset(st)
    copies = len(heights)
    q0 = np.column_stack([np.zeros(copies), offset + heights])
    t1 = np.sqrt(2.0 * heights / g)
    v1 = np.sqrt(2.0 * g * heights)
    t_inf = t1 * (1.0 + eps) / (1.0 - eps)
    bounces = np.log(g * dt / (2.0 * v1)) / np.log(eps) if eps > 0 else np.zeros(copies)
    delay_limit = (3.0 * np.maximum(bounces, 0.0) + 2.0) * dt
    total = config.zeno_steps
    covered = bool(np.all(t_inf + delay_limit < total * dt))
    recorded = min(total, int(np.ceil((1.2 * t_inf.max() + 1.0) / dt))) if covered else total
    trace = simulate(st, q0, np.zeros_like(q0), recorded)
    energy = (kinetic_energy(st, trace.q, trace.u)
              + potential_energy(st, trace.q, (0.0, offset)))
    e0 = energy[0]
    depth = penetration(st, trace.q)
    criteria = health_criteria(trace)
    criteria["energy_above_initial"] = at_most(((energy - e0) / e0).max(), 1e-12)
    criteria["energy_rise_per_step"] = at_most(
        np.diff(energy, axis=0).max() / (m * g * g * dt * dt), 1.0)
    criteria["penetration"] = at_most((depth / ((v1 + g * dt) * dt)).max(), 1.0)
    metrics: dict[str, Any] = {
        "first_impact_s": t1.tolist(), "zeno_time_s": t_inf.tolist(),
        "max_penetration_m": float(depth.max()), "steps_recorded": recorded,
        "steps_total": total}
    if covered:
        moving = np.abs(trace.u).max(axis=2) > REST_SPEED
        last = np.array([np.nonzero(col)[0].max() if col.any() else -1 for col in moving.T])
        t_rest = np.where(last >= recorded, np.inf, (last + 1) * dt)
        criteria["rest_delay"] = at_most((np.abs(t_rest - t_inf) / delay_limit).max(), 1.0)
        metrics["rest_time_s"] = t_rest.tolist()
        metrics["rest_delay_steps"] = ((t_rest - t_inf) / dt).tolist()
        metrics["resolved_bounces_K"] = bounces.tolist()
        q_rest, q, u = trace.q[-1].copy(), trace.q[-1].copy(), trace.u[-1].copy()
        drift, speed, worst, remaining = 0.0, float(np.abs(u).max()), 0.0, total - recorded
        tau, brake = np.zeros((copies, 1)), np.zeros((copies, 0))
        while remaining > 0:
            chunk = min(config.zeno_chunk, remaining)
            _, info = st.step_batch(q, u, tau, brake, chunk)
            drift = max(drift, float(np.abs(q - q_rest).max()))
            speed = max(speed, float(np.abs(u).max()))
            worst = max(worst, float(info[:, INFO_STATUS].max()))
            remaining -= chunk
        criteria["drift_after_rest"] = at_most(drift, 1e-12)
        criteria["speed_after_rest"] = at_most(speed, REST_SPEED)
        criteria["solver_failures_after_rest"] = at_most(
            worst != SolverStatus.CONVERGED or count_non_finite(q, u), 0)
    else:
        t_end = total * dt
        impacts = np.array([_impacts_before(h, eps, g, t_end) for h in heights])
        expected = e0 * eps ** (2.0 * np.maximum(impacts - 1, 0))
        criteria["energy_decay"] = at_most((energy[-1] / expected).max(), 1.0)
        metrics["closed_form_impacts"] = impacts.tolist()
        metrics["final_energy_ratio"] = (energy[-1] / e0).tolist()
    return [case_record(
        "zeno", zeno_name(label, eps, located),
        {"model": label, "eps": eps, "dt": dt, "steps": total, "heights_m": heights.tolist(),
         "locate_impacts": located},
        metrics, criteria,
        "" if label == "ball" else "point mass on the block's slope set flat (quick mode)")]


def zeno_name(label: str, eps: float, located: bool) -> str:
    """The name of a Zeno case."""
    return f"zeno {label} eps={eps:g}" + (" located" if located else "")


def _impacts_before(h0: float, eps: float, g: float, t_end: float) -> int:
    """Closed-form number of impacts of a ball dropped from h0 before t_end (eps < 1)."""
    v1 = math.sqrt(2.0 * g * h0)
    t, k = math.sqrt(2.0 * h0 / g), 0
    while t < t_end and k < 10**6:
        k += 1
        t += 2.0 * eps**k * v1 / g
    return k


# --------------------------------------------------------------------------- 2. brake toggle
def _manipulator_energy_criteria(st: MoreauJeanStepper, trace: Trace, copy: int
                                 ) -> tuple[dict[str, Criterion], dict[str, Any]]:  # fmt: skip
    """``energy_balance`` of one manipulator copy: excess over the motor's work / allowance <= 1.

    The brake impulse is internal and can only dissipate, so T(t) - T(0) <= W(0, t), the work
    tau . (alpha_k+1 - alpha_k) of the motor, within the scheme's second-order energy error
    (``second_order_energy_allowance``). Checked up to the first call the stepper reports as
    under-resolved (INACCURATE): no energy may be gained silently; after that report the
    step's accuracy is not claimed (metrics ``first_under_resolved_step`` and the energies
    over the whole run show what happened).
    """
    energy = kinetic_energy(st, trace.q[:, copy], trace.u[:, copy])
    work_steps = input_work(st, trace)[:, copy]
    work = np.concatenate([[0.0], np.cumsum(work_steps)])
    work_abs = np.concatenate([[0.0], np.cumsum(np.abs(work_steps))])
    allowance = second_order_energy_allowance(st, trace, energy, copy, work_abs)
    flagged = first_under_resolved_call(trace, copy)
    end = len(energy) if flagged is None else flagged + 1  # states before the flagged call
    ratio = energy_excess_ratio(energy[:end], work[:end], allowance[:end])
    excess = energy - energy[0] - work
    speed = float(np.abs(trace.u[:, copy]).max())
    metrics = {"max_speed_rad_s": speed, "max_angle_per_step_rad": speed * trace.dt,
               "max_energy_J": float(energy.max()), "final_energy_J": float(energy[-1]),
               "motor_work_J": float(work[-1]), "max_energy_excess_J": float(excess.max()),
               "first_under_resolved_step": None if flagged is None else flagged * trace.stride}
    if np.isfinite(excess).all() and excess.max() > 0:
        worst = int(excess.argmax())
        metrics["worst_excess_step"] = worst * trace.stride
    return {"energy_balance": at_most(ratio, 1.0)}, metrics


def _engaged_velocity(trace: Trace, copy: int, engaged: FloatArray) -> float:
    """Largest |beta' - alpha'| / max(1, |u|_inf) over the states right after engaged calls."""
    u = trace.u[1:, copy][engaged]
    if u.size == 0:
        return 0.0
    return float((np.abs(u[:, 1] - u[:, 0]) / np.maximum(1.0, np.abs(u).max(axis=1))).max())


def brake_toggle_cases() -> list[dict[str, Any]]:
    """The ideal brake engaged on even steps and released on odd ones, at full motor torque.

    Manipulator from rest at alpha = beta = 0, dt = 0.01 s, |tau| = the maneuver's max_torque. One
    copy per torque pattern: constant +max (spins up for the whole run), bang-bang (sign flips
    every second) and a random sign every step (seeded). Criteria:

    * ``engaged_relative_velocity``: max |beta' - alpha'| / max(1, |u|) <= 1e-12 right after
      every engaged step (an ideal brake holds gamma_B = 0 to round-off);
    * ``energy_balance``: T(t) - T(0) - W_motor(0, t) <= (omega dt)^2 (T + |W|) + round-off,
      scales from before t (the brake only dissipates; the allowance is the scheme's
      second-order energy error, see ``second_order_energy_allowance``).
    """
    st = STEPPERS.get("manipulator", MANIPULATOR_TIME_STEP)
    steps, tau_max = CONFIG.toggle_steps, MANIPULATOR_MANEUVER.max_torque
    k = np.arange(steps)
    patterns = [np.full(steps, tau_max), tau_max * np.where((k // 100) % 2 == 0, 1.0, -1.0),
                tau_max * np.random.default_rng(1).choice([-1.0, 1.0], steps)]
    tau = np.stack(patterns, axis=1)[:, :, None]
    engaged = k % 2 == 0
    brake = np.broadcast_to(np.where(engaged, np.inf, 0.0)[:, None, None], tau.shape)
    copies = len(patterns)
    trace = simulate(st, np.zeros((copies, 2)), np.zeros((copies, 2)), steps, tau, brake)
    cases = []
    for copy, name in enumerate(TOGGLE_PATTERNS):
        criteria = health_criteria(trace, copy, under_resolved_reported=True)
        criteria["engaged_relative_velocity"] = at_most(
            _engaged_velocity(trace, copy, engaged), BRAKE_VELOCITY_RTOL)
        energy_criteria, metrics = _manipulator_energy_criteria(st, trace, copy)
        criteria.update(energy_criteria)
        cases.append(case_record(
            "brake_toggle", f"brake toggle tau={name}",
            {"steps": steps, "dt": MANIPULATOR_TIME_STEP, "max_torque": tau_max,
             "torque": name, "brake": "inf on even steps, 0 on odd"},
            metrics, criteria))
    return cases


TOGGLE_PATTERNS = ("+max", "bang-bang 1 s", "random sign")
"""The torque patterns of ``brake_toggle_cases``, one copy each."""


# --------------------------------------------------------------------------- 3. dt sweep
@dataclass(frozen=True)
class SweepScene:
    """Initial states, inputs and parameters of one model in the dt sweep.

    Attributes:
        label: model label. q0, u0: (N, n). tau: (N, m). brake: (N, k).
        parameters: model parameters. copies: a name per copy.
    """

    label: str
    q0: tuple[tuple[float, ...], ...]
    u0: tuple[tuple[float, ...], ...]
    tau: tuple[tuple[float, ...], ...]
    brake: tuple[tuple[float, ...], ...]
    parameters: dict[str, float]
    copies: tuple[str, ...]


def _sweep_scenes() -> dict[str, SweepScene]:
    radius = BouncingBall.Parameters().radius
    return {
        "ball": SweepScene(
            "ball", ((0.0, radius + 0.1), (0.0, radius), (0.0, radius)),
            ((0.0, 0.0), (0.5, -1.0), (0.0, 0.0)), ((0.0,),) * 3, ((),) * 3, {},
            ("dropped from 0.1 m", "hitting the ground at 1 m/s", "resting")),
        "block": SweepScene(
            "block", ((0.0, 0.0), (0.0, 0.0), (0.0, 0.05)),
            ((0.0, 0.0), (-2.0, 0.0), (0.5, 0.0)), ((0.0,),) * 3, ((),) * 3, {},
            ("from rest (slides)", "thrown up-slope at 2 m/s", "dropped from 0.05 m")),
        "manipulator": SweepScene(
            "manipulator", ((0.0, 0.5),) * 3, ((1.0, -2.0),) * 3, ((0.0,),) * 3,
            ((0.0,), (np.inf,), (0.5,)), {},
            ("released", "ideal brake (plastic impact, then rigid)", "Tresca brake 0.5 N m")),
        "diff_drive": SweepScene(
            "diff_drive", ((0.0,) * 5,) * 3,
            ((0.5, 1.0, 2.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 3.0, 0.0, 0.0)),
            ((0.0, 0.0),) * 3, ((),) * 3, {},
            ("coasting, sideways and yawing", "coasting, wheels locked", "spinning in place")),
    }


def dt_sweep_case(label: str, dt: float) -> list[dict[str, Any]]:
    """Model ``label`` over ``dt_horizon`` s at time step ``dt``, no inputs (``_sweep_scenes``).

    Criteria:

    * ball, block: ``energy_above_initial``: max (E - E0) <= m g^2 dt^2 + 4 eps n max |E terms|
      (round-off over n steps; constant
      gravity is integrated exactly; impacts dissipate; the midpoint contact law can gain at most
      m g^2 dt^2 once, see ``zeno_cases``); ``penetration`` <= v dt + g dt^2 with v the largest
      normal speed at impact (a contact closes within a step; resting contacts sink by g dt^2).
    * manipulator: ``energy_rise``: max (T - T0) / T0 <= (omega0 dt)^2 + 4 eps per step (the
      second-order error, ``second_order_energy_allowance``; the brakes only dissipate);
      ``engaged_relative_velocity`` <= 1e-12 on the ideal-brake copy after its first step.
    * diff-drive (coasting, no torque): ``energy_rise_per_record``: T must never increase
      (Coulomb impulses dissipate and M is constant): max rise <= 1e-9 T0 + round-off;
      ``weight_carried``: max |sum P_N / (m g dt) - 1| <= 1e-9 (the normal loads balance the
      weight while no contact lifts).
    """
    config, scene = CONFIG, _sweep_scenes()[label]
    st = STEPPERS.get(label, dt, **scene.parameters)
    steps = max(1, math.ceil(config.dt_horizon / dt - 1e-9))
    stride = max(1, math.ceil(steps / config.dt_max_calls))
    steps = stride * math.ceil(steps / stride)
    trace = simulate(st, scene.q0, scene.u0, steps, scene.tau, scene.brake, stride)
    criteria = health_criteria(trace, under_resolved_reported=label == "manipulator")
    metrics: dict[str, Any] = {"steps": steps, "stride": stride}
    criteria.update(_sweep_criteria(st, scene, trace, metrics))
    return [case_record(
        "dt_sweep", f"dt sweep {label} dt={dt:g}",
        {"model": label, "dt": dt, "horizon_s": steps * dt, "copies": list(scene.copies)},
        metrics, criteria)]


def _sweep_criteria(st: MoreauJeanStepper, scene: SweepScene, trace: Trace,
                    metrics: dict[str, Any]) -> dict[str, Criterion]:
    """The model-specific criteria of ``dt_sweep_cases``; fills ``metrics``."""
    dt = trace.dt
    p = st.parameters
    criteria: dict[str, Criterion] = {}
    if scene.label in ("ball", "block"):
        offset = _contact_offset(st)
        energy = kinetic_energy(st, trace.q, trace.u) + potential_energy(st, trace.q, (0.0, offset))
        g_normal = p.gravity * (math.cos(p.slope_angle) if scene.label == "block" else 1.0)
        q0, u0 = np.array(scene.q0), np.array(scene.u0)
        heights = np.maximum(q0[:, 1] - offset, 0.0)
        speed = np.sqrt(u0[:, 1] ** 2 + 2.0 * g_normal * heights).max()
        rise = (energy - energy[0]).max()
        steps = trace.stride * (trace.q.shape[0] - 1)
        scale = np.abs(kinetic_energy(st, trace.q, trace.u)).max() + np.abs(
            potential_energy(st, trace.q, (0.0, offset))).max()
        limit = p.mass * p.gravity**2 * dt**2 + (4.0 * steps + 4.0) * EPS_MACHINE * scale
        criteria["energy_above_initial"] = at_most(rise, limit)
        depth = penetration(st, trace.q).max()
        criteria["penetration"] = at_most(depth, speed * dt + g_normal * dt**2)
        metrics.update(max_energy_rise_J=float(rise), max_penetration_m=float(depth),
                       impact_speed_m_s=float(speed))
    elif scene.label == "manipulator":
        energy = kinetic_energy(st, trace.q, trace.u)
        omega0 = np.abs(np.array(scene.u0)).max()
        steps = trace.stride * (trace.q.shape[0] - 1)
        rise = ((energy - energy[0]) / energy[0]).max()
        criteria["energy_rise"] = at_most(rise, (omega0 * dt) ** 2 + 4.0 * steps * EPS_MACHINE)
        engaged = np.array([b[0] == np.inf for b in scene.brake])
        u = trace.u[1:, engaged]
        relative = np.abs(u[..., 1] - u[..., 0]) / np.maximum(1.0, np.abs(u).max(axis=-1))
        criteria["engaged_relative_velocity"] = at_most(relative.max(), BRAKE_VELOCITY_RTOL)
        metrics.update(max_relative_energy_rise=float(rise),
                       relative_energy_error=float(np.abs((energy - energy[0]) / energy[0]).max()))
    else:
        energy = kinetic_energy(st, trace.q, trace.u)
        rise = np.diff(energy, axis=0).max(axis=0) / energy[0]
        criteria["energy_rise_per_record"] = at_most(
            rise.max(), SOLVER_TOL + 4.0 * trace.stride * EPS_MACHINE)
        weight = p.mass * p.gravity * dt
        loads = trace.impulses[:, :, 0::3].sum(axis=2)
        lifted = trace.info[:, :, INFO_LIFTED_CONTACTS] > 0
        error = np.where(lifted, 0.0, np.abs(loads / weight - 1.0))
        criteria["weight_carried"] = at_most(error.max(), SOLVER_TOL)
        metrics.update(max_relative_energy_rise=float(rise.max()),
                       energy_lost_fraction=(1.0 - energy[-1] / energy[0]).tolist())
    return criteria


# --------------------------------------------------------------------------- 4. mu sweep
def block_mu_case(mu: float) -> list[dict[str, Any]]:
    """Block on the default slope (theta = 0.5 rad, tan = 0.546), dt = 1e-3 s, 1 s, no push.

    Copies: from rest, and thrown up-slope at 1 m/s. mu: the grid plus tan(theta) (1 -+ 1e-3).
    Criteria (closed forms of ``tests/stepping/test_moreau_jean_block.py``):

    * ``coulomb_cone``: max (|P_T| - mu P_N) / (m g cos(theta) dt) <= 1e-12 at every step;
    * from rest, if tan(theta) <= mu: ``sticks`` (max |u| <= 1e-12 g dt: at rest up to the
      round-off of one step's impulse balance); else
      ``slide_acceleration``: |s'(T) / (a T) - 1| <= 1e-9, a = g (sin - mu cos);
    * thrown up-slope: ``final_velocity``: |s'(T) - closed form| <= (a_up + |a_down|) dt, the
      closed form decelerating at a_up = g (sin + mu cos), stopping, then sticking (tan <= mu)
      or sliding down at a_down (one step of error where the stop falls inside a step).
    """
    theta = SlidingBlock.Parameters().slope_angle
    threshold = math.tan(theta)
    dt, steps, v_up = BALL_TIME_STEP, 1000, 1.0
    st = STEPPERS.get("block", dt, friction_coefficient=mu)
    p = st.parameters
    g, s, c = p.gravity, math.sin(theta), math.cos(theta)
    trace = simulate(st, np.zeros((2, 2)), [[0.0, 0.0], [-v_up, 0.0]], steps)
    p_n, p_t = trace.impulses[:, :, 0], trace.impulses[:, :, 1]
    unit = p.mass * g * c * dt
    criteria = health_criteria(trace)
    criteria["coulomb_cone"] = at_most(((np.abs(p_t) - mu * p_n) / unit).max(), 1e-12)
    horizon = steps * dt
    if threshold <= mu:
        criteria["sticks"] = at_most(np.abs(trace.u[:, 0]).max(), 1e-12 * g * dt)
    else:
        a = g * (s - mu * c)
        criteria["slide_acceleration"] = at_most(
            abs(trace.u[-1, 0, 0] / (a * horizon) - 1.0), 1e-9)
    a_up, a_down = g * (s + mu * c), g * (s - mu * c)
    t_stop = v_up / a_up
    expected = 0.0 if threshold <= mu else a_down * (horizon - t_stop)
    criteria["final_velocity"] = at_most(abs(trace.u[-1, 1, 0] - expected),
                                         (a_up + abs(a_down)) * dt)
    return [case_record(
        "mu_sweep", f"mu sweep block mu={mu:.4g}",
        {"model": "block", "mu": mu, "slope_angle": theta, "tan_theta": threshold, "dt": dt,
         "steps": steps, "copies": ["from rest", f"thrown up-slope at {v_up} m/s"]},
        {"final_velocities_m_s": trace.u[-1, :, 0].tolist(),
         "max_cone_excess_N_s": float((np.abs(p_t) - mu * p_n).max())},
        criteria)]


def block_mu_grid(config: StressConfig) -> list[float]:
    """The friction coefficients of ``block_mu_case``: the grid and tan(theta) (1 -+ 1e-3)."""
    threshold = math.tan(SlidingBlock.Parameters().slope_angle)
    return sorted({*config.block_mu_grid, threshold * (1 - 1e-3), threshold * (1 + 1e-3)})


def _robot_rolls(p: Any, torque: float) -> bool:
    """Whether equal wheel torques ``torque`` make the robot roll (closed form, from rest).

    Rolling with the stick sliding: A = (2 tau / r - mu_S a m g / (a + c)) / (m + 2 J / r^2 -
    mu_S h m / (a + c)) (``tests/stepping/test_diff_drive.py``), or A = 0 when the stick holds.
    Each wheel then needs F_x = (tau - J A / r) / r within mu N_w, N_w = (c m g + h m A) /
    (2 (a + c)).
    """
    span = p.axle_offset + p.stick_offset
    accel = ((2 * torque / p.wheel_radius
              - p.stick_friction * p.axle_offset * p.mass * p.gravity / span)
             / (p.mass + 2 * p.wheel_inertia / p.wheel_radius**2
                - p.stick_friction * p.cm_height * p.mass / span))
    accel = max(accel, 0.0)
    traction = (torque - p.wheel_inertia * accel / p.wheel_radius) / p.wheel_radius
    load = (p.stick_offset * p.mass * p.gravity + p.cm_height * p.mass * accel) / (2 * span)
    return abs(traction) <= p.wheel_friction * load


def _robot_contact_criteria(st: MoreauJeanStepper, trace: Trace) -> dict[str, Criterion]:
    """Cone, weight and energy-balance criteria of robot runs (stride 1).

    * ``coulomb_cone``: max (|P_T| - mu P_N) / (m g dt) <= 1e-9 at every contact and step;
    * ``weight_carried``: max |sum P_N / (m g dt) - 1| <= 1e-9 while no contact lifts;
    * ``energy_balance``: max (T(t) - T(0) - W_free(0, t)) / (T + sum |W|) <= 1e-9, W_free the
      torques' work over each step's smooth part, an exact bound (``free_motion_work``).
    """
    p = st.parameters
    weight = p.mass * p.gravity * trace.dt
    impulses = trace.impulses.reshape(*trace.impulses.shape[:2], 3, 3)
    mu = np.array([p.wheel_friction, p.wheel_friction, p.stick_friction])
    excess = np.linalg.norm(impulses[..., 1:], axis=-1) - mu * impulses[..., 0]
    lifted = trace.info[:, :, INFO_LIFTED_CONTACTS] > 0
    load_error = np.where(lifted, 0.0, np.abs(impulses[..., 0].sum(axis=-1) / weight - 1.0))
    energy = kinetic_energy(st, trace.q, trace.u)
    work_steps = free_motion_work(st, trace)
    work = np.concatenate([np.zeros((1, work_steps.shape[1])), np.cumsum(work_steps, axis=0)])
    scale = prior_max(energy.max(axis=1)) + np.concatenate(
        [[0.0], np.cumsum(np.abs(work_steps).max(axis=1))])
    balance = ((energy - energy[0] - work).max(axis=1) / np.maximum(scale, 1e-300)).max()
    return {
        "coulomb_cone": at_most(excess.max() / weight, SOLVER_TOL),
        "weight_carried": at_most(load_error.max(), SOLVER_TOL),
        "energy_balance": at_most(balance, SOLVER_TOL),
    }


def robot_mu_case(mu: float) -> list[dict[str, Any]]:
    """Robot with wheel and stick friction mu, dt = 0.01 s, 2 s from rest.

    Copies: torques (1, 1) (straight), (1.5, 0.5) (turning), (-1, 1) (spinning) N m.

    Criteria: ``_robot_contact_criteria``; mu = 0: ``chassis_pushed``: max |x, y, phi| <= 1e-8
    (frictionless wheels cannot push it); mu > 0: ``mode_as_closed_form`` on the straight copy:
    steps whose slip mode differs from the closed form (2 if rolling is feasible, ``_robot_rolls``,
    else 5) <= 0.
    """
    torques = np.array([[1.0, 1.0], [1.5, 0.5], [-1.0, 1.0]])
    steps = 200
    st = STEPPERS.get("diff_drive", DIFF_DRIVE_TIME_STEP, wheel_friction=mu,
                      stick_friction=mu)
    trace = simulate(st, np.zeros((3, 5)), np.zeros((3, 5)), steps, torques)
    criteria = health_criteria(trace)
    criteria.update(_robot_contact_criteria(st, trace))
    modes = trace.info[:, :, INFO_MODE]
    metrics: dict[str, Any] = {"final_pose": trace.q[-1, :, :3].tolist(),
                               "modes_seen": sorted({int(m) for m in modes.ravel()})}
    if mu == 0.0:
        criteria["chassis_pushed"] = at_most(np.abs(trace.q[:, :, :3]).max(), 1e-8)
    else:
        expected = 2 if _robot_rolls(st.parameters, 1.0) else 5
        criteria["mode_as_closed_form"] = at_most(np.count_nonzero(modes[:, 0] != expected), 0)
        metrics["expected_mode_straight"] = expected
    return [case_record(
        "mu_sweep", f"mu sweep diff_drive mu={mu:g}",
        {"model": "diff_drive", "mu_wheels_and_stick": mu, "dt": DIFF_DRIVE_TIME_STEP,
         "steps": steps, "torques_N_m": torques.tolist()},
        metrics, criteria)]


# --------------------------------------------------------------------------- 5. overdrive
def manipulator_overdrive_cases(factor: float) -> list[dict[str, Any]]:
    """Manipulator from rest, tau = factor x max_torque, dt = 0.01 s, for ``overdrive_horizon`` s.

    Copies by brake (``OVERDRIVE_BRAKES``): released, ideal (engaged throughout), toggled every
    step, Tresca at a = max_torque.

    Criteria: health, ``energy_balance`` (as ``brake_toggle_cases``) and, for the ideal and
    toggled brakes, ``engaged_relative_velocity`` <= 1e-12.
    """
    st = STEPPERS.get("manipulator", MANIPULATOR_TIME_STEP)
    steps = round(CONFIG.overdrive_horizon / MANIPULATOR_TIME_STEP)
    tau_max = MANIPULATOR_MANEUVER.max_torque
    k = np.arange(steps)
    brakes = [np.zeros(steps), np.full(steps, np.inf), np.where(k % 2 == 0, np.inf, 0.0),
              np.full(steps, tau_max)]
    brake = np.stack(brakes, axis=1)[:, :, None]
    copies = len(brakes)
    tau = np.full((copies, 1), factor * tau_max)
    trace = simulate(st, np.zeros((copies, 2)), np.zeros((copies, 2)), steps, tau, brake)
    cases = []
    for copy, name in enumerate(OVERDRIVE_BRAKES):
        criteria = health_criteria(trace, copy, under_resolved_reported=True)
        energy_criteria, metrics = _manipulator_energy_criteria(st, trace, copy)
        criteria.update(energy_criteria)
        engaged = np.isinf(brake[:, copy, 0])
        if engaged.any():
            criteria["engaged_relative_velocity"] = at_most(
                _engaged_velocity(trace, copy, engaged), BRAKE_VELOCITY_RTOL)
        cases.append(case_record(
            "overdrive", f"overdrive manipulator {factor:g}x brake={name}",
            {"model": "manipulator", "torque_N_m": factor * tau_max, "factor": factor,
             "brake": name, "dt": MANIPULATOR_TIME_STEP, "steps": steps},
            metrics, criteria))
    return cases


OVERDRIVE_BRAKES = ("released", "ideal", "toggled", "tresca a=max_torque")
"""The brake copies of ``manipulator_overdrive_cases``."""


def robot_overdrive_case(factor: float) -> list[dict[str, Any]]:
    """Robot from rest, wheel torques factor x max_wheel_torque, dt = 0.01 s.

    Copies: both forward, opposite (spin), left only.

    Criteria: health, ``_robot_contact_criteria`` and, for the both-wheel copies, ``both_slip``:
    steps not in mode 5 <= 0, and ``cone_saturated``: max | |P_T| / (mu P_N) - 1 | <= 1e-9 at both
    wheels (sliding contacts carry friction at the cone's boundary).
    """
    st = STEPPERS.get("diff_drive", DIFF_DRIVE_TIME_STEP)
    p = st.parameters
    steps = round(CONFIG.overdrive_horizon / DIFF_DRIVE_TIME_STEP)
    torques = factor * DIFF_DRIVE_MANEUVER.max_wheel_torque * np.array(
        [[1.0, 1.0], [1.0, -1.0], [1.0, 0.0]])
    trace = simulate(st, np.zeros((3, 5)), np.zeros((3, 5)), steps, torques)
    criteria = health_criteria(trace)
    criteria.update(_robot_contact_criteria(st, trace))
    modes = trace.info[:, :2, INFO_MODE]
    criteria["both_slip"] = at_most(np.count_nonzero(modes != 5), 0)
    wheels = trace.impulses[:, :2, :6].reshape(steps, 2, 2, 3)
    ratio = np.linalg.norm(wheels[..., 1:], axis=-1) / (p.wheel_friction * wheels[..., 0])
    criteria["cone_saturated"] = at_most(np.abs(ratio - 1.0).max(), SOLVER_TOL)
    return [case_record(
        "overdrive", f"overdrive diff_drive {factor:g}x",
        {"model": "diff_drive", "factor": factor, "torques_N_m": torques.tolist(),
         "dt": DIFF_DRIVE_TIME_STEP, "steps": steps},
        {"final_speeds": trace.u[-1].tolist(),
         "modes_seen": sorted({int(m) for m in trace.info[:, :, INFO_MODE].ravel()})},
        criteria)]


# --------------------------------------------------------------------------- 6. LCPs
@dataclass(frozen=True)
class StressLCP:
    """A degenerate or ill-conditioned LCP and what an exact method must report on it.

    Attributes:
        name: label. M: (n, n). q: (n,).
        expect: ``"solvable"`` (a solution exists: exact methods must find it), ``"infeasible"``
            (none exists: exact methods must report RAY_TERMINATION or NO_SOLUTION) or
            ``"any"`` (no requirement beyond honesty).
        description: how it was built.
    """

    name: str
    M: FloatArray
    q: FloatArray
    expect: str
    description: str


def _random_orthogonal(rng: np.random.Generator, n: int) -> FloatArray:
    q, r = np.linalg.qr(rng.standard_normal((n, n)))
    return q * np.sign(np.diag(r))


def stress_lcps(seed: int = 7) -> list[StressLCP]:
    """The constructed LCPs of ``lcp_cases`` (deterministic for a seed)."""
    rng = np.random.default_rng(seed)
    problems = []
    # Redundant contacts: a planar body (m = 1 kg, I = 0.1 kg m^2) touching at 4 points, each
    # listed twice. M = J Minv J^T has rank 3 of 8; q = J v for an approaching velocity v. The
    # impact LCP is the optimality system of min |u+ - v|_M^2 / 2 s.t. J u+ >= 0 (u+ = 0 is
    # feasible), so it has a solution although M is singular.
    normals = rng.standard_normal((4, 2))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    arms = rng.uniform(-0.5, 0.5, (4, 2))
    rows = np.column_stack([normals, arms[:, 0] * normals[:, 1] - arms[:, 1] * normals[:, 0]])
    jac = np.vstack([rows, rows])
    inv_mass = np.diag([1.0, 1.0, 10.0])
    v = -jac.sum(axis=0) / 4.0
    v = v if (jac @ v).min() < 0 else -v
    problems.append(StressLCP("redundant contacts (rank 3 of 8)", jac @ inv_mass @ jac.T,
                              jac @ v, "solvable", "4 contacts listed twice on one body"))
    near = jac.copy()
    near[4:] += 1e-9 * rng.standard_normal(near[4:].shape)
    problems.append(StressLCP("near-duplicate contacts (1e-9)", near @ inv_mass @ near.T,
                              near @ v, "solvable", "the duplicates perturbed by 1e-9"))
    # SPD matrices of prescribed condition with a known mixed solution.
    n = 8
    for cond in (1e8, 1e10, 1e12):
        basis = _random_orthogonal(rng, n)
        matrix = (basis * np.logspace(0.0, -math.log10(cond), n)) @ basis.T
        matrix = 0.5 * (matrix + matrix.T)
        z = np.where(np.arange(n) % 2 == 0, rng.uniform(0.5, 1.5, n), 0.0)
        w = np.where(np.arange(n) % 2 == 1, rng.uniform(0.5, 1.5, n), 0.0)
        problems.append(StressLCP(f"SPD cond {cond:.0e}", matrix, w - matrix @ z, "solvable",
                                  "Q diag(logspace) Q^T, solution with half the z active"))
    ill = problems[-1].M
    problems.append(StressLCP("q = 0, SPD cond 1e+12", ill, np.zeros(n), "solvable",
                              "z = 0 is the unique solution"))
    problems.append(StressLCP("q = 0, M = 0", np.zeros((4, 4)), np.zeros(4), "solvable",
                              "every z >= 0 with w = 0 solves it"))
    problems.append(StressLCP("M = 0, q < 0 (no solution)", np.zeros((4, 4)), -np.ones(4),
                              "infeasible", "w = q < 0 for every z"))
    ones = np.ones((4, 4))
    problems.append(StressLCP("rank 1, q in range", ones, -np.ones(4), "solvable",
                              "sum z = 1: a face of solutions"))
    problems.append(StressLCP("rank 1, duplicated rows", np.ones((2, 2)), np.array([-1.0, -2.0]),
                              "solvable", "unique solution z = (0, 2)"))
    problems.append(StressLCP("q = -1e-14, rank 1", ones, np.full(4, -1e-14), "solvable",
                              "a tiny negative q on a singular M"))
    skew = np.array([[0.0, 1.0], [-1.0, 0.0]])
    problems.append(StressLCP("skew M, q = (-1, -1)", skew, -np.ones(2), "infeasible",
                              "w1 = z2 - 1, w2 = -z1 - 1 < 0: infeasible"))
    return problems


def lcp_outcome(M: FloatArray, q: FloatArray, method: str) -> dict[str, Any]:
    """Solve with one method; the status, the residual recomputed by ``lcp_residual``, honesty.

    A result is honest unless it claims CONVERGED with a non-finite z or a residual above the
    tolerance. Methods that refuse the problem (``ValueError``, e.g. enumeration beyond its size)
    are recorded as skipped.
    """
    try:
        result = solve_lcp(M, q, method=method)
    except ValueError as error:
        return {"method": method, "skipped": str(error)}
    finite = bool(np.isfinite(result.z).all())
    residual = float(lcp_residual(M, q, np.ascontiguousarray(result.z))) if finite else math.inf
    converged = result.status is SolverStatus.CONVERGED
    return {"method": method, "status": result.status.name, "iterations": int(result.num_iter),
            "residual": residual, "finite": finite,
            "honest": not (converged and not (finite and residual <= LCP_TOL))}


def lcp_criteria(expect: str, outcomes: Sequence[dict[str, Any]]) -> dict[str, Criterion]:
    """``dishonest_results`` <= 0 and, per ``expect``, what the exact methods must report.

    The exact methods (``lemke`` and, up to its size limit, ``enumerative``) must between them
    solve a ``"solvable"`` problem (``exact_solved`` >= 1) and report RAY_TERMINATION or
    NO_SOLUTION on an ``"infeasible"`` one (``exact_claims_on_infeasible`` <= 0). Iterative
    methods may stop at their iteration limit; only their honesty is required.
    """
    ran = [o for o in outcomes if "skipped" not in o]
    criteria = {"dishonest_results": at_most(sum(not o["honest"] for o in ran), 0)}
    exact = [o for o in ran if o["method"] in ("lemke", "enumerative")]
    if expect == "solvable":
        criteria["exact_solved"] = at_least(sum(o["status"] == "CONVERGED" for o in exact), 1)
    elif expect == "infeasible":
        criteria["exact_claims_on_infeasible"] = at_most(
            sum(o["status"] not in ("RAY_TERMINATION", "NO_SOLUTION") for o in exact), 0)
    return criteria


def lcp_case(index: int) -> list[dict[str, Any]]:
    """LCP ``stress_lcps()[index]`` given to ``solve_lcp`` with every registered method.

    Criteria (``lcp_criteria``): no method reports CONVERGED with a NaN/inf z or a residual
    (``lcp_residual``) above its tolerance 1e-10; an exact method (Lemke or enumeration) solves
    the solvable ones, and neither claims a solution of the infeasible ones.
    """
    problem = stress_lcps()[index]
    outcomes = [lcp_outcome(problem.M, problem.q, m) for m in LCP_METHODS.names()]
    cond = float(np.linalg.cond(problem.M)) if np.any(problem.M) else math.inf
    return [case_record(
        "lcp", f"lcp {problem.name}",
        {"n": int(problem.q.shape[0]), "expect": problem.expect,
         "description": problem.description},
        {"condition_number": cond, "outcomes": outcomes},
        lcp_criteria(problem.expect, outcomes))]


def lcp_peer_case() -> list[dict[str, Any]]:
    """Every Siconos peer LCP file with every method: honesty only (``dishonest_results`` 0)."""
    files = peer_files("lcp")
    outcomes = []
    for path in files:
        M, q = read_lcp(path)
        outcomes += [{"problem": path.stem, **lcp_outcome(np.ascontiguousarray(M), q, m)}
                     for m in LCP_METHODS.names()]
    ran = [o for o in outcomes if "skipped" not in o]
    return [case_record(
        "lcp", "lcp siconos peer files", {"files": len(files), "folder": str(PEER_DATA / "lcp")},
        {"outcomes": outcomes,
         "converged": sum(o["status"] == "CONVERGED" for o in ran), "runs": len(ran)},
        {"dishonest_results": at_most(sum(not o["honest"] for o in ran), 0)})]


# --------------------------------------------------------------------------- 7. long horizons
def manipulator_long_cases() -> list[dict[str, Any]]:
    """Manipulator free spin (tau = 0, dt = 0.01 s) for ``long_steps`` steps.

    Copies (``LONG_BRAKES``): brake released throughout; brake engaged 3 s of every 10 s.
    Criteria (omega0 the largest initial speed, n the steps so far):

    * released: ``energy_drift``: max |T - T0| / T0 <= (omega0 dt)^2 + 4 eps n (second order,
      ``second_order_energy_allowance``); ``energy_drift_growth``: max |error| over the second
      half / over the first half <= 1.5 (bounded oscillation gives 1, secular drift 2);
    * both: ``momentum_drift``: max |L - L0| / allowance <= 1, L = (1, 1) . M u the angular
      momentum about the base, conserved by the internal brake with tau = 0. The scheme keeps
      it to second order over smooth motion, allowance (omega0 dt)^2 |L0| + 4 eps n |L0|, and to
      first order across each engagement (a plastic impact; the midpoint rule evaluates M at
      q_M): plus dt |dM/dq|_max (|u-| + |u+|) |u+ - u-| per engagement (measured 0.2 of it);
    * scheduled: ``energy_rise``: max (T - T0) / T0 <= (omega0 dt)^2 + 4 eps n (engagements only
      dissipate); ``engaged_angle_drift``: max change of beta - alpha after the first step of
      each engaged stretch <= n_engaged (dt 1e-12 max(1, |u|) + 4 eps max |q|) (the brake holds
      gamma_B = 0 to round-off); ``engaged_relative_velocity`` <= 1e-12.
    """
    config, steppers = CONFIG, STEPPERS
    st = steppers.get("manipulator", MANIPULATOR_TIME_STEP)
    dt, stride, steps = MANIPULATOR_TIME_STEP, config.long_stride, config.long_steps
    calls = steps // stride
    period, engaged_steps = 1000, 300
    if period % stride or engaged_steps % stride:
        raise ValueError("long_stride must divide the brake schedule (1000 and 300 steps)")
    step_index = np.arange(calls) * stride
    engaged = (step_index % period) < engaged_steps
    brake = np.zeros((calls, 2, 1))
    brake[:, 1, 0] = np.where(engaged, np.inf, 0.0)
    q0 = np.array([[0.0, 0.5], [0.0, 0.5]])
    u0 = np.array([[1.0, -2.0], [1.0, -2.0]])
    trace = simulate(st, q0, u0, steps, None, brake, stride)
    omega0 = np.abs(u0).max()
    n = np.arange(calls + 1) * stride
    limit = (omega0 * dt) ** 2 + 4.0 * n * EPS_MACHINE
    values = st.parameters.values()
    mass = _entries(st.model.mass_matrix(np.moveaxis(trace.q, -1, 0), values, np),
                    trace.q.shape[:-1])
    momentum = np.einsum("ij...,...j->...", mass, trace.u)
    energy = kinetic_energy(st, trace.q, trace.u)
    slope = _mass_slope(st, trace.q)
    starts = np.nonzero(engaged & ~np.concatenate([[False], engaged[:-1]]))[0]
    cases = []
    for copy, name in enumerate(LONG_BRAKES):
        criteria = health_criteria(trace, copy)
        error = (energy[:, copy] - energy[0, copy]) / energy[0, copy]
        l0 = abs(momentum[0, copy])
        drift_l = np.abs(momentum[:, copy] - momentum[0, copy]) / l0
        impulsive = np.zeros(calls + 1)
        if copy == 1:
            for start in starts:
                before, after = trace.u[start, copy], trace.u[start + 1, copy]
                impulsive[start + 1:] += (dt * slope * (np.abs(before).max() + np.abs(after).max())
                                          * np.abs(after - before).max()) / l0
        criteria["momentum_drift"] = at_most((drift_l / (limit + impulsive)).max(), 1.0)
        metrics: dict[str, Any] = {
            "max_relative_energy_error": float(np.abs(error).max()),
            "final_relative_energy_error": float(error[-1]),
            "max_relative_momentum_drift": float(drift_l.max())}
        if copy == 0:
            criteria["energy_drift"] = at_most((np.abs(error) / limit).max(), 1.0)
            half = calls // 2
            growth = np.abs(error[half:]).max() / max(np.abs(error[1:half + 1]).max(), 1e-300)
            criteria["energy_drift_growth"] = at_most(growth, 1.5)
        else:
            criteria["energy_rise"] = at_most((error / limit).max(), 1.0)
            drift, holds = _engaged_angle_drift(trace, copy, engaged, stride)
            criteria["engaged_angle_drift"] = at_most(drift / holds, 1.0)
            criteria["engaged_relative_velocity"] = at_most(
                _engaged_velocity(trace, copy, engaged), BRAKE_VELOCITY_RTOL)
            metrics["max_engaged_angle_drift_rad"] = drift
        cases.append(case_record(
            "long_horizon", f"long horizon manipulator {name}",
            {"model": "manipulator", "steps": steps, "stride": stride, "dt": dt,
             "q0": q0[copy].tolist(), "u0": u0[copy].tolist(), "brake": name},
            metrics, criteria))
    return cases


LONG_BRAKES = ("released", "engaged 3 s of 10 s")
"""The brake copies of ``manipulator_long_cases``."""


def _mass_slope(stepper: MoreauJeanStepper, q: FloatArray, step: float = 1e-6) -> float:
    """Largest |dM_ij / dq_k| over the states q (..., n), by central differences."""
    values = stepper.parameters.values()
    largest = 0.0
    for k in range(q.shape[-1]):
        shift = np.zeros(q.shape[-1])
        shift[k] = step
        plus, minus = (_entries(stepper.model.mass_matrix(np.moveaxis(q + sign * shift, -1, 0),
                                                          values, np), q.shape[:-1])
                       for sign in (1.0, -1.0))
        largest = max(largest, float(np.abs(plus - minus).max() / (2.0 * step)))
    return largest


def _engaged_angle_drift(trace: Trace, copy: int, engaged: FloatArray, stride: int
                         ) -> tuple[float, float]:  # fmt: skip
    """(largest drift of beta - alpha within an engaged stretch, its allowance) [rad].

    A stretch's reference is the first state recorded after its first engaged step (that step
    moves the angle by dt/2 gamma_B^- before the brake holds it). The allowance of a stretch of
    n steps is n (dt 1e-12 max(1, |u|) + 4 eps max |q|); the worst ratio's pair is returned.
    """
    angle = trace.q[:, copy, 1] - trace.q[:, copy, 0]
    worst_drift, worst_allowance, worst_ratio = 0.0, 1.0, -1.0
    starts = np.nonzero(engaged & ~np.concatenate([[False], engaged[:-1]]))[0]
    for start in starts:
        stop = start
        while stop < len(engaged) and engaged[stop]:
            stop += 1
        # states start+1 ... stop are after engaged calls (state i follows call i - 1)
        segment = slice(start + 1, stop + 1)
        drift = float(np.abs(angle[segment] - angle[start + 1]).max())
        steps = (stop - start) * stride
        speed = max(1.0, float(np.abs(trace.u[segment, copy]).max()))
        size = float(np.abs(trace.q[segment, copy]).max())
        allowance = steps * (trace.dt * 1e-12 * speed + 4.0 * EPS_MACHINE * size)
        if drift / allowance > worst_ratio:
            worst_drift, worst_allowance, worst_ratio = drift, allowance, drift / allowance
    return worst_drift, worst_allowance


def robot_long_case() -> list[dict[str, Any]]:
    """Robot long roll, ``robot_long_steps`` steps of dt = 0.01 s; ``_robot_contact_criteria``.

    Zero-mean sinusoidal wheel torques of 1 N m amplitude (periods 12.6 s and 20.9 s).
    """
    st = STEPPERS.get("diff_drive", DIFF_DRIVE_TIME_STEP)
    steps = CONFIG.robot_long_steps
    t = np.arange(steps) * DIFF_DRIVE_TIME_STEP
    tau = np.stack([np.sin(0.5 * t), np.sin(0.3 * t + 1.0)], axis=1)[:, None, :]
    trace = simulate(st, np.zeros((1, 5)), np.zeros((1, 5)), steps, tau)
    criteria = health_criteria(trace)
    criteria.update(_robot_contact_criteria(st, trace))
    energy = kinetic_energy(st, trace.q, trace.u)
    return [case_record(
        "long_horizon", "long horizon diff_drive roll",
        {"model": "diff_drive", "steps": steps, "dt": DIFF_DRIVE_TIME_STEP,
         "torques": "sin(0.5 t), sin(0.3 t + 1) N m"},
        {"max_energy_J": float(energy.max()), "final_pose": trace.q[-1, 0, :3].tolist(),
         "modes_seen": sorted({int(m) for m in trace.info[:, 0, INFO_MODE]})},
        criteria)]


# --------------------------------------------------------------------------- the plan
STEPPERS = Steppers()
"""The steppers of this process (each model compiled once, its time in ``compile_s``)."""


@dataclass(frozen=True)
class PlannedCase:
    """One stress case: its name and the computation (shared by its batch) that yields it.

    Attributes:
        name: the case's name. family: its family.
        compute: ``compute(*args) -> list of case records``, one per copy of its batch.
        args: the arguments. index: which of the returned records is this case.
    """

    name: str
    family: str
    compute: Callable[..., list[dict[str, Any]]]
    args: tuple[Any, ...] = ()
    index: int = 0


@cache
def _computed(compute: Callable[..., list[dict[str, Any]]], args: tuple[Any, ...]
              ) -> list[dict[str, Any]]:  # fmt: skip
    return compute(*args)


def run_case(planned: PlannedCase) -> dict[str, Any]:
    """The record of one planned case (its batch is simulated once per process)."""
    record = _computed(planned.compute, planned.args)[planned.index]
    if record["name"] != planned.name:
        raise RuntimeError(f"planned {planned.name!r}, computed {record['name']!r}")
    return record


def plan(config: StressConfig = CONFIG) -> list[PlannedCase]:
    """Every case of ``config`` in report order (the peer files only where they are present)."""
    models = config.models
    label = "ball" if "ball" in models else "block"
    cases = [PlannedCase(zeno_name(label, eps, located), "zeno", zeno_case, (eps, located))
             for eps in config.zeno_restitutions for located in (False, True)]
    if "manipulator" in models:
        cases += [PlannedCase(f"brake toggle tau={name}", "brake_toggle", brake_toggle_cases,
                              (), i) for i, name in enumerate(TOGGLE_PATTERNS)]
    cases += [PlannedCase(f"dt sweep {model} dt={dt:g}", "dt_sweep", dt_sweep_case, (model, dt))
              for model in _sweep_scenes() if model in models for dt in config.dt_grid]
    if "block" in models:
        cases += [PlannedCase(f"mu sweep block mu={mu:.4g}", "mu_sweep", block_mu_case, (mu,))
                  for mu in block_mu_grid(config)]
    if "diff_drive" in models:
        cases += [PlannedCase(f"mu sweep diff_drive mu={mu:g}", "mu_sweep", robot_mu_case, (mu,))
                  for mu in config.robot_mu_grid]
    if "manipulator" in models:
        cases += [PlannedCase(f"overdrive manipulator {factor:g}x brake={name}", "overdrive",
                              manipulator_overdrive_cases, (factor,), i)
                  for factor in config.overdrive_factors
                  for i, name in enumerate(OVERDRIVE_BRAKES)]
    if "diff_drive" in models:
        cases += [PlannedCase(f"overdrive diff_drive {factor:g}x", "overdrive",
                              robot_overdrive_case, (factor,))
                  for factor in config.overdrive_factors]
    if "manipulator" in models:
        cases += [PlannedCase(f"long horizon manipulator {name}", "long_horizon",
                              manipulator_long_cases, (), i) for i, name in enumerate(LONG_BRAKES)]
    if "diff_drive" in models and config.robot_long_steps:
        cases.append(PlannedCase("long horizon diff_drive roll", "long_horizon", robot_long_case))
    cases += [PlannedCase(f"lcp {problem.name}", "lcp", lcp_case, (i,))
              for i, problem in enumerate(stress_lcps())]
    if peer_files("lcp"):
        cases.append(PlannedCase("lcp siconos peer files", "lcp", lcp_peer_case))
    return cases
