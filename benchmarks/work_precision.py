"""Work-precision benchmark: error against wall time per scene, ours, event-driven and MuJoCo.

``python -m benchmarks.work_precision [--output DIR] [--quick]`` writes ``work_precision.json``,
``work_precision_<scene>.png`` and ``work_precision_ball_convergence.png``. Scenes and error
measures: ball apexes against the closed form, slope cases against theirs, the manipulator
against the event-driven reference, the robot against a fine step (docs/guide/benchmarks.md).
"""

from __future__ import annotations

import math
import textwrap
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks import engine_mujoco as mj
from benchmarks import report, timing
from benchmarks.engine_scenes import Copies
from benchmarks.report import format_number, log_lines, plt, save_figure, summary
from benchmarks.timing import Log, TimingPlan
from mdi_envs import stepping
from mdi_envs.mechanics import models
from mdi_envs.mechanics.models.bouncing_ball import BouncingBallParameters
from mdi_envs.mechanics.models.sliding_block import SlidingBlockParameters
from mdi_envs.solvers.status import SolverStatus
from mdi_envs.stepping.event_driven import EVENT_APEX, EVENT_IMPACT, Trajectory

METHODS = {"enumerative": stepping.StepShortcuts(),
           "lemke": stepping.StepShortcuts(direct_solve_max_size=0)}
ATOL_PER_RTOL = 1e-2  # event-driven runs: atol = ATOL_PER_RTOL * rtol
BOUNCES = 3  # ball apexes compared (impacts 2 .. BOUNCES + 1 for the times)
# The manipulator's scenario [s, N m]: the paper's brake schedule and a torque reversal.
ENGAGE_TIMES, RELEASE_TIMES, TORQUE_SWITCH = (0.0, 1.072, 2.392), (0.412, 1.84), 2.264
MANIPULATOR_HORIZON, MAX_TORQUE, SAMPLE_INTERVAL = 4.528, 1.0, 4e-3
REFERENCE_RTOL, REFERENCE_ATOL, CHECK_RTOL, CHECK_ATOL = 1e-12, 1e-14, 1e-11, 1e-13
DIFF_DRIVE_PHASES = ((0.5, (1.0, 0.6)), (0.5, (3.0, -3.0)), (0.5, (-0.5, -0.5)))  # [s], [N m]
SLOPE_STICKING_FRICTION = 0.6  # > tan 0.5
STICK_SLIP = {"slope_angle": 0.3, "friction_coefficient": 0.5, "mass": 2.0, "rate": 8.0}  # N/s
TARGET_APEX_ERROR, TARGET_ORDER, TARGET_RATIO = 1e-3, 0.8, 100.0  # at dt = 1e-3 s; MuJoCo / ours


ERROR_FLOOR = 1e-17  # exactly-zero errors are drawn at or below this on log axes
TIMED_PATHS = {
    "mj_one_call": "one step_batch call (N = 1, check_inputs=False, num_substeps = all steps)",
    "mj_per_phase": "one step_batch call (N = 1, check_inputs=False) per constant-command phase",
    "mj_per_step": "one step_batch call (N = 1, 1 substep) per step from Python (the input "
                   "changes every step)",
    "ed": "EventDrivenIntegrator.simulate (scipy solve_ivp DOP853 with events), sampling included",
    "mujoco_one_call": "one mj_step(model, data, nstep = all steps) call",
    "mujoco_per_phase": "one mj_step(model, data, nstep) call per constant-command phase",
}
"""What each point's wall time covers (``timed_path`` of a point)."""

SERIES_TITLES = {
    "mj_enumerative": "Moreau–Jean (enumerative LCP, default)",
    "mj_lemke": "Moreau–Jean (Lemke)",
    "mj_located": "Moreau–Jean, impacts located (locate_impacts=True)",
    "mj_newton_ac": "Moreau–Jean (semismooth Newton, Alart–Curnier)",
    "event_driven": "event-driven (DOP853)",
    "mujoco_formula": "MuJoCo, dampratio from ε (formula)",
    "mujoco_calibrated": "MuJoCo, dampratio calibrated per dt",
    "mujoco_default": "MuJoCo, brake solref (0.02, 1) (default)",
    "mujoco_stiffest": "MuJoCo, brake solref (2 dt, 1) (stiffest)",
}

SCENE_TITLES = {
    "ball": "Bouncing ball: mean over drops of the largest relative apex error, bounces 1–3 [-]",
    "slope": "Block on a slope: largest |state − closed form| [m, m/s]",
    "manipulator": "Manipulator, bang-bang torque and 3 brake engagements: largest |state − "
                   "event-driven reference| over the 4 ms samples [rad, rad/s]",
    "diff_drive": "Diff-drive robot: |final state − Moreau–Jean at dt_ref| [m, rad, m/s, rad/s]",
}


@dataclass(frozen=True)
class WorkPrecisionConfig:
    """Scenes, methods, dt [s] and rtol grids, and the timing of one run."""

    scenes: tuple[str, ...]
    methods: tuple[str, ...]
    ball_time_steps: tuple[float, ...]
    ball_drops: int
    tolerances: tuple[float, ...]
    manipulator_time_steps: tuple[float, ...]
    mujoco_ball_time_steps: tuple[float, ...]
    mujoco_arm_time_steps: tuple[float, ...]
    timing: TimingPlan
    mujoco_ball_series: tuple[str, ...] = ("formula", "calibrated")
    mujoco_arm_series: tuple[str, ...] = ("default", "stiffest")
    slope_time_steps: tuple[float, ...] = ()
    diff_drive_time_steps: tuple[float, ...] = ()
    diff_drive_reference_step: float = 5e-6


FULL = WorkPrecisionConfig(
    scenes=("ball", "slope", "manipulator", "diff_drive"), methods=("enumerative", "lemke"),
    ball_time_steps=(1e-2, 4e-3, 2e-3, 1e-3, 4e-4, 2e-4, 1e-4, 4e-5, 2e-5, 1e-5), ball_drops=8,
    tolerances=(1e-4, 1e-6, 1e-8, 1e-10),
    manipulator_time_steps=(4e-3, 2e-3, 1e-3, 4e-4, 2e-4, 1e-4, 4e-5, 2e-5, 1e-5),
    mujoco_ball_time_steps=(1e-2, 4e-3, 2e-3, 1e-3, 4e-4, 2e-4, 1e-4, 4e-5, 1e-5),
    mujoco_arm_time_steps=(4e-3, 2e-3, 1e-3, 4e-4, 2e-4, 1e-4, 4e-5, 1e-5),
    timing=TimingPlan(budget_s=0.5, min_rounds=3, max_rounds=15),
    slope_time_steps=(1e-2, 4e-3, 2e-3, 1e-3, 4e-4, 2e-4, 1e-4, 4e-5, 1e-5),
    diff_drive_time_steps=(1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4))
QUICK = WorkPrecisionConfig(
    scenes=("ball", "manipulator"), methods=("enumerative",), ball_time_steps=(4e-3, 2e-3, 1e-3),
    ball_drops=8, tolerances=(1e-8,), manipulator_time_steps=(4e-3, 2e-3, 1e-3),
    mujoco_ball_time_steps=(2e-3, 1e-3, 1e-4), mujoco_arm_time_steps=(2e-3, 1e-3),
    timing=TimingPlan(budget_s=0.0, min_rounds=3, max_rounds=3))


@dataclass
class Context:
    """What every study needs: configuration, progress, MuJoCo, compile records, notes."""

    config: WorkPrecisionConfig
    log: Log
    mujoco: Any
    compile: list[dict[str, Any]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    failed_sections: list[str] = field(default_factory=list)
    references: dict[str, Any] = field(default_factory=dict)
    calibrations: list[dict[str, Any]] = field(default_factory=list)
    reference: Any = None  # the manipulator's reference states (S, 4) at the sample times
    _compiled: set[tuple[str, str]] = field(default_factory=set)

    def timed(self, call: Callable[[], Any]) -> tuple[float, int, Any]:
        """(fastest wall time [s] of ``call()``, timed calls, the untimed warm-up call's result).

        ``timing.time_interleaved`` with the run's plan, one callable.
        """
        t = timing.time_interleaved({"call": call}, self.config.timing)["call"]
        return t.min_s, t.rounds * t.number, t.result

    def stepper(self, model: Any, parameters: Any, dt: float, method: str = "enumerative",
                locate_impacts: bool = False) -> stepping.MoreauJeanStepper:
        """A stepper; the first of each (model, method, location) is compiled and timed here."""
        st = stepping.MoreauJeanStepper(model, parameters, dt, METHODS[method], locate_impacts)
        variant = method + (", locate_impacts" if locate_impacts else "")
        key = (model.__name__, variant)
        if key not in self._compiled:
            self.log(f"compiling {model.__name__} step_batch ({variant}) ...")
            seconds = timing.timed_call(lambda: Copies(st).advance(1))[1]
            self.compile.append({"model": model.__name__, "method": variant,
                                 "first_step_batch_s": seconds})
            self.log(f"  {seconds:.1f} s")
            self._compiled.add(key)
        return st


def point(log: Log, scene: str, series: str, parameter: str, value: float, wall_s: float | None,
          repeats: int, path: str, errors: dict[str, Any], **extra: Any) -> dict[str, Any]:
    """One work-precision point, logged (NaN errors become None and mark the point failed)."""
    clean = {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
             for k, v in errors.items()}
    status = (extra.pop("status", None) or clean.pop("status", None)
              or ("ok" if clean.get("error") is not None else "failed: no error measured"))
    p = {"scene": scene, "series": series, "parameter": parameter, "value": value,
         "wall_time_s": wall_s, "repeats": repeats, "timed_path": path, **clean,
         "status": status, **extra}
    error = "failed" if p.get("error") is None else f"error {p['error']:.3e}"
    log(f"  {scene} {series} {parameter} = {value:g}: {error}, {wall_s} s ({status})")
    return p


def _steps(duration: float, dt: float) -> int:
    """Steps of length dt in ``duration`` [s] (must be a multiple, to 1e-9 relative)."""
    steps = round(duration / dt)
    if abs(steps * dt - duration) > 1e-9 * max(duration, 1.0):
        raise ValueError(f"dt = {dt:g} s does not divide {duration:g} s")
    return steps


def ball_closed_form(p: BouncingBallParameters, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """(apex gaps eps^(2k) h0 [m], k = 1..BOUNCES; impact times [s] of impacts 1..BOUNCES+1)."""
    eps, t1 = p.restitution, math.sqrt(2.0 * gap / p.gravity)
    k = np.arange(1, BOUNCES + 1)
    impacts = t1 * (1.0 + 2.0 * np.concatenate([[0.0], np.cumsum(eps**k)]))
    return gap * eps ** (2.0 * k), impacts


def ball_horizon(p: BouncingBallParameters, gaps: np.ndarray) -> float:
    """[s] 1.25 times the last compared impact of the highest drop (before the Zeno point)."""
    return 1.25 * float(ball_closed_form(p, float(gaps.max()))[1][-1])


def _ball_summary(p: BouncingBallParameters, gaps: np.ndarray,
                  per_drop: list[tuple[np.ndarray, np.ndarray] | str]) -> dict[str, Any]:
    """A point's errors from each drop's (apex gaps [m], landing times [s]) or why it has none."""
    reasons = sorted({d for d in per_drop if isinstance(d, str)})
    if reasons:
        failed = sum(isinstance(d, str) for d in per_drop)
        return {"error": math.nan, "failed_drops": failed,
                "status": f"failed: {failed} of {len(per_drop)} drops: " + "; ".join(reasons)}
    exact = [ball_closed_form(p, float(gap)) for gap in gaps]
    relative = np.array([np.abs(apexes - apex) / apex  # (D, BOUNCES)
                         for (apexes, _), (apex, _) in zip(per_drop, exact, strict=True)])
    landing = [np.abs(landings - impacts[1:]).max()
               for (_, landings), (_, impacts) in zip(per_drop, exact, strict=True)]
    worst = relative.max(axis=1)
    return {"error": float(worst.mean()), "error_max": float(worst.max()),
            "apex_error_by_bounce": [float(x) for x in relative.mean(axis=0)],
            "impact_time_error_s": float(np.mean(landing)), "failed_drops": 0}


def ball_errors(p: BouncingBallParameters, gaps: np.ndarray, y: np.ndarray, v: np.ndarray,
                dt: float) -> dict[str, Any]:
    """Errors of sampled drops: y, v (D, K + 1) heights [m] and velocities [m/s] every dt [s].

    ``error``: the mean over drops of the largest relative apex error over bounces 1-3 (apex: the
    largest sample at a + to - sign change of y'); ``impact_time_error_s`` from the landing times
    of the simulated flights; ``error_max``, ``apex_error_by_bounce``, ``failed_drops``.
    """
    per_drop: list[tuple[np.ndarray, np.ndarray] | str] = []
    g, r = p.gravity, p.radius
    for i in range(len(gaps)):
        if not (np.isfinite(y[i]).all() and np.isfinite(v[i]).all()):
            per_drop.append("the simulation diverged (NaN)")
            continue
        turns = np.nonzero((v[i, :-1] > 0.0) & (v[i, 1:] <= 0.0) & (y[i, :-1] > r))[0]
        if turns.size < BOUNCES:
            per_drop.append(f"fewer than {BOUNCES} apexes within the horizon")
            continue
        j = turns[:BOUNCES] + (y[i, turns[:BOUNCES] + 1] > y[i, turns[:BOUNCES]])
        gap_j, v_j = y[i, j] - r, v[i, j]
        landings = j * dt + (v_j + np.sqrt(v_j**2 + 2.0 * g * np.maximum(gap_j, 0.0))) / g
        per_drop.append((gap_j, landings))
    return _ball_summary(p, gaps, per_drop)


def ball_event_errors(p: BouncingBallParameters, gaps: np.ndarray, runs: list[Trajectory]
                      ) -> dict[str, Any]:
    """``ball_errors`` from event-driven runs: apex events' gaps and impact events' times."""
    per_drop: list[tuple[np.ndarray, np.ndarray] | str] = []
    for run in runs:
        apexes = [e.q[1] - p.radius for e in run.events_of(EVENT_APEX)][:BOUNCES]
        impacts = [e.t for e in run.events_of(EVENT_IMPACT)][1:BOUNCES + 1]
        if len(apexes) < BOUNCES or len(impacts) < BOUNCES:
            per_drop.append(f"fewer than {BOUNCES} apex events (run {run.status})")
            continue
        per_drop.append((np.array(apexes), np.array(impacts)))
    return _ball_summary(p, gaps, per_drop)


def _ball_setup(ctx: Context) -> tuple[BouncingBallParameters, np.ndarray, float]:
    """The ball's parameters, the drops' initial gaps h0 [m] (U(0.9, 1.1), seed 0), horizon [s]."""
    p, gaps = BouncingBallParameters(), np.random.default_rng(0).uniform(0.9, 1.1,
                                                                         ctx.config.ball_drops)
    return p, gaps, ball_horizon(p, gaps)


def ball_moreau_jean(ctx: Context) -> Iterator[dict[str, Any]]:
    """Moreau-Jean ball points: per method and dt, drop 0 timed, D drops replayed step by step."""
    p, gaps, horizon = _ball_setup(ctx)
    variants = [(f"mj_{method}", method, False) for method in ctx.config.methods]
    for series, method, locate_impacts in [*variants, ("mj_located", "enumerative", True)]:
        for dt in ctx.config.ball_time_steps:
            st = ctx.stepper(models.BouncingBall, p, dt, method, locate_impacts)
            num_steps = math.ceil(horizon / dt)
            q0 = np.column_stack([np.zeros(gaps.size), p.radius + gaps])  # at rest
            phases = [(num_steps, (0.0,), ())]
            wall, repeats, final = ctx.timed(partial(Copies(st, q0[:1]).run, phases))
            states = Copies(st, q0).run(phases, stride=1)  # (K + 1, D, 4): x, y, x', y'
            yield point(ctx.log, "ball", series, "dt", dt, wall, repeats, "mj_one_call",
                        ball_errors(p, gaps, states[:, :, 1].T, states[:, :, 3].T, dt),
                        replay_difference=float(np.abs(states[-1, 0] - final).max()))


def ball_event_driven(ctx: Context) -> Iterator[dict[str, Any]]:
    """Event-driven ball points: per rtol, drop 0 timed, every drop's events compared."""
    p, gaps, horizon = _ball_setup(ctx)
    for rtol in ctx.config.tolerances:
        options = {"rtol": rtol, "atol": ATOL_PER_RTOL * rtol}
        wall, repeats, _ = ctx.timed(partial(stepping.simulate_ball, p, p.radius + gaps[0], horizon,
                                             **options))
        runs = [stepping.simulate_ball(p, p.radius + gap, horizon, **options) for gap in gaps]
        yield point(ctx.log, "ball", "event_driven", "rtol", rtol, wall, repeats, "ed",
                    ball_event_errors(p, gaps, runs), atol=options["atol"],
                    rhs_evaluations=runs[0].num_rhs_evals)


def ball_mujoco(ctx: Context) -> Iterator[dict[str, Any]]:
    """MuJoCo ball points per dampratio mapping and dt (the calibrations into ``ctx``)."""
    p, gaps, horizon = _ball_setup(ctx)
    for series in ctx.config.mujoco_ball_series:
        for dt in ctx.config.mujoco_ball_time_steps:
            name = f"mujoco_{series}"
            dampratio, note = ((mj.formula_dampratio(p.restitution), "damped-oscillator formula")
                               if series == "formula" else
                               mj.calibrate_dampratio(ctx.mujoco, p, dt))
            if dampratio is None:
                yield point(ctx.log, "ball", name, "dt", dt, None, 0, "",
                            {"error": math.nan}, status=f"failed: {note}")
                continue
            ball = mj.MujocoBall(ctx.mujoco, p, dt, dampratio)
            restitution = ball.effective_restitution()
            ctx.calibrations.append({"series": name, "dt": dt, "dampratio": dampratio,
                                     "effective_restitution": restitution, "note": note,
                                     **ball.contact_settings})
            num_steps = math.ceil(horizon / dt)
            wall, repeats, final = ctx.timed(partial(ball.run, float(gaps[0]), num_steps))
            y, v = ball.trajectories(gaps, num_steps)
            difference = max(abs(y[0, -1] - final[0]), abs(v[0, -1] - final[1]))
            yield point(
                ctx.log, "ball", name, "dt", dt, wall, repeats, "mujoco_one_call",
                ball_errors(p, gaps, y, v, dt), replay_difference=float(difference),
                dampratio=dampratio, effective_restitution=restitution)


def stick_slip_closed_form(theta: float, mu: float, mass: float, rate: float, gravity: float
                           ) -> tuple[float, float, Callable[[float], float],
                                      Callable[[float], float]]:
    """(t_s [s], final s [m], push(t) [N], s'(t) [m/s]) of the triangular push: stick, slide, stick.

    The push ``rate * t`` rises to 1.5 t_b (t_b: breakaway), then falls at the same rate.
    """
    t_b = mass * gravity * (mu * math.cos(theta) - math.sin(theta)) / rate
    t1 = 1.5 * t_b
    d = t1 - t_b
    w_stop = (1.0 + math.sqrt(2.0)) * d
    t_s = t1 + w_stop

    def push(t: float) -> float:
        return rate * (t if t <= t1 else max(2.0 * t1 - t, 0.0))

    def speed(t: float) -> float:
        if t <= t_b or t >= t_s:
            return 0.0
        if t <= t1:
            return rate * (t - t_b) ** 2 / (2.0 * mass)
        w = t - t1
        return rate * (d**2 / 2.0 + d * w - w**2 / 2.0) / mass

    s1, v1 = rate * d**3 / (6.0 * mass), rate * d**2 / (2.0 * mass)
    s_final = s1 + v1 * w_stop + rate * (d * w_stop**2 / 2.0 - w_stop**3 / 6.0) / mass
    return t_s, s_final, push, speed


def slope_moreau_jean(ctx: Context) -> list[dict[str, Any]]:
    """Slope points: per method, case and dt (see the module docstring)."""
    return [_slope_point(ctx, method, case, dt) for method in ctx.config.methods
            for case in ("sliding", "sticking", "stick_slip") for dt in ctx.config.slope_time_steps]


def _slope_point(ctx: Context, method: str, case: str, dt: float) -> dict[str, Any]:
    series = f"mj_{method}:{case}"
    if case != "stick_slip":
        p = SlidingBlockParameters(friction_coefficient=(
            SlidingBlockParameters().friction_coefficient if case == "sliding"
            else SLOPE_STICKING_FRICTION))
        a = max(p.gravity * (math.sin(p.slope_angle)
                             - p.friction_coefficient * math.cos(p.slope_angle)), 0.0)
        num_steps = _steps(1.0, dt)
        run = Copies(ctx.stepper(models.SlidingBlock, p, dt, method))
        wall, repeats, final = ctx.timed(partial(run.run, [(num_steps, (0.0,), ())]))
        exact = np.array([0.5 * a, 0.0, a, 0.0])  # (s, n, s', n') at T = 1 s
        errors = {"error": float(np.abs(final - exact).max())}
        return point(ctx.log, "slope", series, "dt", dt, wall, repeats, "mj_one_call", errors)
    p = SlidingBlockParameters(**{k: v for k, v in STICK_SLIP.items() if k != "rate"})
    t_s, s_final, push, speed = stick_slip_closed_form(
        p.slope_angle, p.friction_coefficient, p.mass, STICK_SLIP["rate"], p.gravity)
    num_steps = round((t_s + 0.5) / dt)
    pushes = np.array([push((k + 0.5) * dt) for k in range(num_steps)])
    run = Copies(ctx.stepper(models.SlidingBlock, p, dt, method))
    speeds = np.empty(num_steps)

    def per_step() -> np.ndarray:
        run.reset()
        for k in range(num_steps):
            run.tau[0, 0] = pushes[k]
            run.advance(1)
            speeds[k] = run.u[0, 0]
        return run.state()

    wall, repeats, final = ctx.timed(per_step)
    exact_speeds = np.array([speed((k + 1) * dt) for k in range(num_steps)])
    speed_error = float(np.abs(speeds - exact_speeds).max())
    final_error = float(max(abs(final[0] - s_final), np.abs(final[1:]).max()))
    return point(ctx.log, "slope", series, "dt", dt, wall, repeats, "mj_per_step",
                 {"error": max(speed_error, final_error), "final_error": final_error,
                  "speed_error": speed_error})


def manipulator_schedule() -> tuple[Any, Any, list[float]]:
    """(torque tau(t) [N m], brake bound a(t), phase boundaries [s] from 0 to the horizon)."""
    torque = stepping.bang_bang(MAX_TORQUE, [TORQUE_SWITCH])
    brake = stepping.brake_schedule(ENGAGE_TIMES, RELEASE_TIMES)
    bounds = sorted({0.0, *ENGAGE_TIMES, *RELEASE_TIMES, TORQUE_SWITCH, MANIPULATOR_HORIZON})
    return torque, brake, bounds


def manipulator_phases(dt: float) -> list[tuple[int, float, float]]:
    """(steps, torque [N m], brake bound) per constant-command phase at time step dt."""
    torque, brake, bounds = manipulator_schedule()
    return [(_steps(b - a, dt), float(torque(a)[0]), float(brake(a)[0]))
            for a, b in zip(bounds[:-1], bounds[1:], strict=True)]


def manipulator_reference(ctx: Context) -> None:
    """The reference states (S, 4) at the sample times into ``ctx``, with its record."""
    torque, brake, _ = manipulator_schedule()
    grid = SAMPLE_INTERVAL * np.arange(_steps(MANIPULATOR_HORIZON, SAMPLE_INTERVAL) + 1)
    runs = [timing.timed_call(partial(
        stepping.simulate_manipulator, None, [0.0, 0.0], [0.0, 0.0], torque, brake,
        MANIPULATOR_HORIZON, sample_times=grid, rtol=rtol, atol=atol))
        for rtol, atol in ((REFERENCE_RTOL, REFERENCE_ATOL), (CHECK_RTOL, CHECK_ATOL))]
    states = [np.hstack([run.q, run.u]) for run, _ in runs]
    seconds = [elapsed for _, elapsed in runs]
    record = {"rtol": REFERENCE_RTOL, "atol": REFERENCE_ATOL, "wall_time_s": seconds[0],
              "check_rtol": CHECK_RTOL, "check_atol": CHECK_ATOL,
              "self_difference": float(np.abs(states[0] - states[1]).max()),
              "sample_interval_s": SAMPLE_INTERVAL, "samples": int(grid.size)}
    ctx.log(f"manipulator reference: {seconds[0]:.2f} s, |rtol 1e-12 - rtol 1e-11| = "
            f"{record['self_difference']:.1e}")
    ctx.reference, ctx.references["manipulator"] = states[0], record


def _state_errors(samples: np.ndarray, reference: np.ndarray) -> dict[str, float]:
    """``error`` (largest |difference| over samples and components), ``final_error``."""
    difference = np.abs(samples - reference)
    return {"error": float(difference.max()), "final_error": float(difference[-1].max())}


def manipulator_moreau_jean(ctx: Context) -> Iterator[dict[str, Any]]:
    """Moreau-Jean points: one ``step_batch`` call per phase (timed), replayed per sample."""
    for dt in ctx.config.manipulator_time_steps:
        run = Copies(ctx.stepper(models.BlockableManipulator, None, dt))
        phases = [(steps, [torque], [bound]) for steps, torque, bound in manipulator_phases(dt)]
        wall, repeats, final = ctx.timed(partial(run.run, phases))
        samples = run.run(phases, _steps(SAMPLE_INTERVAL, dt))[:, 0]
        yield point(
            ctx.log, "manipulator", "mj_enumerative", "dt", dt, wall, repeats, "mj_per_phase",
            _state_errors(samples, ctx.reference),
            replay_difference=float(np.abs(samples[-1] - final).max()))


def manipulator_event_driven(ctx: Context) -> Iterator[dict[str, Any]]:
    """Event-driven points at each rtol (sampling at the 4 ms grid included in the time)."""
    torque, brake, _ = manipulator_schedule()
    grid = SAMPLE_INTERVAL * np.arange(ctx.reference.shape[0])
    for rtol in ctx.config.tolerances:
        options = {"rtol": rtol, "atol": ATOL_PER_RTOL * rtol}
        wall, repeats, trajectory = ctx.timed(partial(
            stepping.simulate_manipulator, None, [0.0, 0.0], [0.0, 0.0], torque, brake,
            MANIPULATOR_HORIZON, sample_times=grid, **options))
        errors = _state_errors(np.hstack([trajectory.q, trajectory.u]), ctx.reference)
        yield point(ctx.log, "manipulator", "event_driven", "rtol", rtol, wall, repeats, "ed",
                    errors, atol=options["atol"], rhs_evaluations=trajectory.num_rhs_evals)


def manipulator_mujoco(ctx: Context) -> Iterator[dict[str, Any]]:
    """MuJoCo arm points per brake solref setting and dt."""
    for series in ctx.config.mujoco_arm_series:
        for dt in ctx.config.mujoco_arm_time_steps:
            solref = None if series == "default" else (2.0 * dt, 1.0)
            arm = mj.MujocoArmRun(ctx.mujoco, dt, solref)
            phases = [(steps, torque, bool(np.isinf(bound)))
                      for steps, torque, bound in manipulator_phases(dt)]
            wall, repeats, (final, _) = ctx.timed(partial(arm.simulate, phases))
            _, samples = arm.simulate(phases, _steps(SAMPLE_INTERVAL, dt))
            assert samples is not None
            yield point(
                ctx.log, "manipulator", f"mujoco_{series}", "dt", dt, wall, repeats,
                "mujoco_per_phase", _state_errors(samples, ctx.reference),
                replay_difference=float(np.abs(samples[-1] - final).max()), **arm.brake_settings)


def diff_drive_run(ctx: Context, dt: float) -> tuple[Callable[[], np.ndarray], Copies]:
    """A zero-argument run of the robot's phases at dt (one call per phase), and its copies."""
    run = Copies(ctx.stepper(models.DiffDriveRobot, None, dt))
    return partial(run.run, [(_steps(duration, dt), tau, ())
                             for duration, tau in DIFF_DRIVE_PHASES]), run


def diff_drive_moreau_jean(ctx: Context) -> Iterator[dict[str, Any]]:
    """Robot points against the fine-step reference (its record into ``ctx.references``)."""
    dt_ref = ctx.config.diff_drive_reference_step
    reference_run, reference_copies = diff_drive_run(ctx, dt_ref)
    reference, seconds = timing.timed_call(reference_run)
    check = diff_drive_run(ctx, 2.0 * dt_ref)[0]()
    record = {"time_step": dt_ref, "check_time_step": 2.0 * dt_ref, "wall_time_s": seconds,
              "self_difference": float(np.abs(reference - check).max()),
              "worst_status": SolverStatus(reference_copies.worst_status).name,
              "final_state": [float(x) for x in reference]}
    ctx.log(f"diff-drive reference dt = {dt_ref:g}: |x(2 dt_ref) - x(dt_ref)| = "
            f"{record['self_difference']:.1e}")
    for dt in ctx.config.diff_drive_time_steps:
        call, copies = diff_drive_run(ctx, dt)
        wall, repeats, final = ctx.timed(call)
        yield point(ctx.log, "diff_drive", "mj_newton_ac", "dt", dt, wall, repeats,
                    "mj_per_phase", {"error": float(np.abs(final - reference).max())},
                    worst_solver_status=SolverStatus(copies.worst_status).name)
    ctx.references["diff_drive"] = record


def observed_order(points: Sequence[dict[str, Any]]) -> float | None:
    """Least-squares slope of log(error) against log(dt) (None with fewer than 2 points)."""
    usable = [(p["value"], p["error"]) for p in points if p.get("error")]
    if len(usable) < 2:
        return None
    dts, errors = np.array(usable).T
    return float(np.polyfit(np.log(dts), np.log(errors), 1)[0])


STUDIES = {
    "ball": (("ball Moreau-Jean", ball_moreau_jean), ("ball event-driven", ball_event_driven),
             ("ball MuJoCo", ball_mujoco)),
    "slope": (("slope", slope_moreau_jean),),
    "manipulator": (("manipulator Moreau-Jean", manipulator_moreau_jean),
                    ("manipulator event-driven", manipulator_event_driven),
                    ("manipulator MuJoCo", manipulator_mujoco)),
    "diff_drive": (("diff-drive", diff_drive_moreau_jean),),
}
"""Scene -> (name, study) in the order they run (the manipulator's after its reference)."""


def evaluate_targets(points: Sequence[dict[str, Any]]
                     ) -> tuple[list[dict[str, Any]], dict[str, Any] | None]:
    """The targets against the measurements, and the ball's equal-time comparison."""
    ours = [p for p in points if p["scene"] == "ball" and p["series"] == "mj_enumerative"]
    located = [p for p in points if p["scene"] == "ball" and p["series"] == "mj_located"]
    targets = []
    for series, label, default in ((located, "locate_impacts=True", False),
                                   (ours, "the default midpoint step", True)):
        at_1ms = [p for p in series if math.isclose(p["value"], 1e-3)]
        apex = at_1ms[0] if at_1ms and at_1ms[0]["error"] is not None else None
        note = "" if apex is None else f"worst drop {apex['error_max']:.2e}; per bounce " + \
            ", ".join(f"{x:.2e}" for x in apex["apex_error_by_bounce"])
        if default:
            note = ("the impact applied at the step's midpoint, an O(v dt) error, v the impact "
                    "speed") + (f"; {note}" if note else "")
        targets.append(report.target_row(
            f"ball apex error at dt = 1e-3 s (relative, bounces 1-3, mean over drops), {label}",
            "≤", TARGET_APEX_ERROR, "", None if apex is None else apex["error"], note))
    for series, label in ((located, "locate_impacts=True"), (ours, "default")):
        order = observed_order(series)
        targets.append(report.target_row(
            f"ball error converges at least O(dt) (fitted log-log order), {label}",
            "≥", TARGET_ORDER, "", order, "dt " + ", ".join(f"{p['value']:g}" for p in series)))
    mujoco = [p for p in points if p["scene"] == "ball" and p["series"].startswith("mujoco")]
    comparison = equal_time_comparison(ours, mujoco) if mujoco else None
    name = "ball: MuJoCo error / ours at equal wall time (smallest over our dt)"
    if comparison is None or comparison["min_ratio"] is None:
        targets.append(report.target_row(name, "≥", TARGET_RATIO, "×", None,
                                         "MuJoCo not run" if not mujoco else "no comparable point"))
    elif comparison["min_equal_time_ratio"] is not None:
        targets.append(report.target_row(name, "≥", TARGET_RATIO, "×",
                                         comparison["min_equal_time_ratio"], comparison["summary"]))
    else:  # only lower bounds: they can show the target met, not missed
        bound = comparison["min_lower_bound_ratio"]
        targets.append(report.target_row(name, "≥", TARGET_RATIO, "×", bound,
                                         "lower bounds only: " + comparison["summary"]))
        targets[-1]["met"] = True if bound >= TARGET_RATIO else None
    return targets, comparison


def _section(ctx: Context, name: str, study: Callable[[Context], Iterable[dict[str, Any]]]
             ) -> list[dict[str, Any]]:
    """Run one study; on an exception note it (``main`` then exits with 1) and go on."""
    try:
        return list(study(ctx))
    except Exception as error:  # noqa: BLE001 - one failed study must not lose the others
        message = f"{name} failed: {type(error).__name__}: {error}"
        ctx.notes.append(message)
        ctx.failed_sections.append(name)
        ctx.log(message)
        ctx.log(traceback.format_exc())
        return []


def run(output: Path, quick: bool, log: Log | None = None,
        config: WorkPrecisionConfig | None = None) -> dict[str, Any]:
    """Run the benchmark, write the JSON and plots to ``output`` and return the record."""
    config = config or (QUICK if quick else FULL)
    packages = (*timing.VERSIONED_PACKAGES, "mujoco")
    with report.study("work_precision", output, {"quick": quick, **asdict(config)}, packages,
                      log=log) as (record, log, _):
        mujoco, mujoco_note = mj.import_mujoco()
        ctx = Context(config, log, mujoco, notes=[mujoco_note] if mujoco_note else [])
        record["timed_paths"] = TIMED_PATHS
        points: list[dict[str, Any]] = []
        for scene, studies in STUDIES.items():
            if scene not in config.scenes:
                continue
            if scene == "manipulator":
                manipulator_reference(ctx)
            for name, study in studies:
                if "MuJoCo" not in name or mujoco is not None:
                    points += _section(ctx, name, study)
        targets, comparison = evaluate_targets(points)
        record.update({"compile": ctx.compile, "points": points, "references": ctx.references,
                       "mujoco_ball_calibration": ctx.calibrations,
                       "equal_time": comparison, "targets": targets, "notes": ctx.notes,
                       "failed_sections": ctx.failed_sections})
        scenes = [s for s in config.scenes if any(p["scene"] == s for p in points)]
        record["plots"] = plot_all(points, scenes, output)
    return report.json_safe(record)


def series_title(series: str) -> str:
    """Readable series name (slope series are ``method:case``)."""
    method, _, case = series.partition(":")
    title = SERIES_TITLES.get(method, method)
    return f"{title} · {case}" if case else title


def pareto_front(points: Sequence[Mapping[str, Any]]) -> list[tuple[float, float, str]]:
    """(wall time [s], error, label) of the points no other point beats in both, by time."""
    usable = sorted((p["wall_time_s"], p["error"], f"{p['series']} dt={p['value']:g}")
                    for p in points if p.get("error") is not None and p["wall_time_s"] is not None)
    return [entry for i, entry in enumerate(usable)
            if all(entry[1] < earlier[1] for earlier in usable[:i])]


def interpolate_front(front: Sequence[tuple[float, float, str]], seconds: float
                      ) -> tuple[float | None, str]:
    """MuJoCo's error at ``seconds`` on its front (see ``equal_time_comparison``)."""
    times, errors = np.log([f[:2] for f in front]).T
    if seconds <= front[0][0]:
        return front[0][1], "clamped"
    if seconds > front[-1][0]:
        return None, "beyond"
    return math.exp(np.interp(math.log(seconds), times, errors)), "interpolated"


def equal_time_comparison(ours: Sequence[Mapping[str, Any]],
                          mujoco: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """MuJoCo's ball error / ours at our wall times, off MuJoCo's Pareto front.

    Between front points the error is interpolated in (log t, log error) ("interpolated"); where
    ours is faster than the fastest front point that point's error is used ("clamped": a lower
    bound); beyond the slowest nothing is compared ("beyond"). Returns ``rows``, ``front``,
    ``min_ratio``, ``max_ratio``, ``min_equal_time_ratio``, ``min_lower_bound_ratio``,
    ``ratio_at_1ms`` and ``summary``.
    """
    front = pareto_front(mujoco)
    rows = []
    for p in sorted(ours, key=lambda p: -p["value"]):
        if p.get("error") is None or not front:
            continue
        theirs, how = interpolate_front(front, p["wall_time_s"])
        ratio = None if theirs is None or p["error"] == 0.0 else theirs / p["error"]
        rows.append({"dt": p["value"], "wall_time_s": p["wall_time_s"], "error": p["error"],
                     "mujoco_error": theirs, "how": how, "ratio": ratio})
    ratios = [r["ratio"] for r in rows if r["ratio"] is not None]
    equal = [r["ratio"] for r in rows if r["ratio"] is not None and r["how"] == "interpolated"]
    bounds = [r["ratio"] for r in rows if r["ratio"] is not None and r["how"] == "clamped"]
    at_1ms = next((r for r in rows if math.isclose(r["dt"], 1e-3)), None)
    result: dict[str, Any] = {
        "rows": rows, "front": [list(f) for f in front], "min_ratio": min(ratios, default=None),
        "max_ratio": max(ratios, default=None), "min_equal_time_ratio": min(equal, default=None),
        "min_lower_bound_ratio": min(bounds, default=None),
        "ratio_at_1ms": None if at_1ms is None else at_1ms["ratio"]}
    parts = [f"{text} {format_number(min(ratios))}–{format_number(max(ratios))}× over "
             f"{len(ratios)} of our dt" for text, ratios in (
                 ("at equal time (interpolated)", equal),
                 ("where ours is faster than any MuJoCo run (clamped: lower bounds)", bounds))
             if ratios]
    if at_1ms is not None and at_1ms["ratio"] is not None:
        parts.append(f"at dt = 1e-3: {format_number(at_1ms['ratio'])}× ({at_1ms['how']})")
    result["summary"] = "; ".join(parts) or "no comparable point"
    return result


def plot_scene(points: Sequence[Mapping[str, Any]], scene: str, path: Path) -> None:
    """Log-log error against wall time, one line per series, each point labelled by dt/rtol."""
    fig, ax = plt.subplots(figsize=(8.0, 5.4))
    positive = [p["error"] for p in points if p.get("error")]
    floor = min(ERROR_FLOOR, 0.1 * min(positive)) if positive else ERROR_FLOOR
    rows = [{**p, "ms": p["wall_time_s"] * 1e3, "drawn": max(p["error"], floor)}
            for p in points if p.get("error") is not None]
    log_lines(ax, rows, "ms", "drawn", "series", label=series_title,
              dashed=lambda s: "lemke" in s, ticks=False)
    for p in rows:
        ax.annotate(f"{p['value']:g}", (p["ms"], p["drawn"]), textcoords="offset points",
                    xytext=(3, 3), fontsize=6)
    ax.set_ylabel("error")
    ax.set_title(textwrap.fill(SCENE_TITLES.get(scene, scene), 95), fontsize=9)
    ax.legend(fontsize=7)
    ax.set_xlabel("wall time per trajectory [ms]   (point labels: dt [s] or rtol; errors of "
                  f"exactly 0 drawn at {floor:.0e})")
    save_figure(fig, path)


def plot_ball_convergence(points: Sequence[Mapping[str, Any]], path: Path) -> None:
    """Ball error against dt (log-log), with an O(dt) slope and the 1e-3 target marked."""
    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    stepped = [p for p in points if p["parameter"] == "dt" and p.get("error") is not None]
    log_lines(ax, stepped, "value", "error", "series", label=series_title,
              dashed=lambda s: "lemke" in s, ticks=False)
    ours = sorted((p for p in stepped if p["series"] == "mj_enumerative"),
                  key=lambda p: p["value"])
    if ours:
        dts = np.array([p["value"] for p in ours])
        anchor = ours[len(ours) // 2]
        ax.plot(dts, anchor["error"] * dts / anchor["value"], "k:", lw=1.0,
                label="O(dt) reference slope")
    ax.plot([1e-3], [1e-3], marker="*", color="k", ms=10, ls="none",
            label="target: 1e-3 at dt = 1e-3 s")
    ax.set_xlabel("time step dt [s]")
    ax.set_ylabel("mean largest relative apex error, bounces 1–3")
    ax.set_title("Bouncing ball: convergence in dt", fontsize=9)
    ax.legend(fontsize=7)
    save_figure(fig, path)


def plot_all(points: Sequence[Mapping[str, Any]], scenes: Sequence[str], output: Path
             ) -> list[str]:
    """Every plot of the run; returns the file names written."""
    names = []
    for scene in scenes:
        chosen = [p for p in points if p["scene"] == scene]
        plot_scene(chosen, scene, output / f"work_precision_{scene}.png")
        names.append(f"work_precision_{scene}.png")
        if scene == "ball":
            names.append("work_precision_ball_convergence.png")
            plot_ball_convergence(chosen, output / names[-1])
    return names


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point."""
    args = timing.arguments(__doc__, argv)
    record = run(args.output, args.quick)
    print(summary(record, ("numpy", "numba", "scipy", "mujoco")))
    return 1 if record.get("failed_sections") else 0


if __name__ == "__main__":
    raise SystemExit(main())
