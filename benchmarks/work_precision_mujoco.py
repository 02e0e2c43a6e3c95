"""MuJoCo peers of the work-precision benchmark: the bouncing ball and the braked two-link arm.

Both are run by ``benchmarks.work_precision`` (``python -m benchmarks.work_precision``); this
module only builds the MuJoCo models and runs them. MuJoCo is a benchmark-only dependency: the
caller imports it with ``benchmarks.engine_mujoco.import_mujoco`` and skips these peers when it is
missing.

**Ball.** A sphere (radius, mass and gravity of ``BouncingBallParameters``) on a vertical slide
joint over a ground plane, normal-only contacts (``condim = 1``), the default Euler integrator.
MuJoCo has no impact law: a contact is a soft constraint whose reference acceleration
``a_ref = -b v - k r`` is a damped spring set by ``solref = (timeconst, dampratio)``
(k ~ 1 / (timeconst dampratio)^2, b ~ 2 / timeconst) and blended in by the impedance ``solimp``
(MuJoCo's default (0.9, 0.95, 0.001) here). A bounce with restitution eps therefore needs an
underdamped contact. Two mappings of eps = 0.8 are measured:

* ``formula``: dampratio from the damped-oscillator relation eps = exp(-pi z / sqrt(1 - z^2)),
  z = -ln(eps) / sqrt(pi^2 + ln(eps)^2) = 0.0709;
* ``calibrated``: dampratio tuned per time step (Brent's method) until a separate calibration
  drop from ``CALIBRATION_DROP`` = 0.5 m rebounds to eps^2 of its height (effective restitution
  sqrt(apex / drop) = eps to 1e-6). This is the best MuJoCo can do at that stiffness; the
  benchmark's drops (0.9-1.1 m) are not used to tune it.

``timeconst`` is MuJoCo's default 0.02 s: with z = 0.07 the contact then lasts pi timeconst z
= 4.4 ms and the ball sinks about 6 mm at 4.4 m/s (a tennis ball's contact lasts ~5 ms). A
stiffer contact is not resolved by MuJoCo's time steps (timeconst = 2 dt, the smallest it
accepts, gives z timeconst << dt: the ball gains energy or the simulation goes unstable).

**Arm.** ``benchmarks.engine_mujoco.MJCF``: the blockable manipulator in MuJoCo coordinates
(alpha, beta - alpha), the brake a joint equality switched by ``eq_active`` whose lock angle
(``eq_data[0, 0]``, polycoef r0) is set to the relative angle at each engagement. Two
``solref`` settings: MuJoCo's default (0.02, 1) and the stiffest it accepts, (2 dt, 1).

Every run is one compiled ``mj_step(model, data, nstep)`` call per constant-command phase (the
timed runs), or per sample interval (the replays the errors are measured on); the ball's
replays of several drops use ``mujoco.rollout`` (one thread), which returns every step's state.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import brentq

from benchmarks.engine_mujoco import MJCF as ARM_MJCF
from mdi_envs.mechanics.models.bouncing_ball import BouncingBallParameters

BALL_MJCF = """
<mujoco model="bouncing_ball">
  <option timestep="{dt}" gravity="0 0 {gravity}"/>
  <default><geom condim="1" solref="{timeconst} {dampratio}"/></default>
  <worldbody>
    <geom name="ground" type="plane" size="1 1 0.1"/>
    <body name="ball">
      <joint name="height" type="slide" axis="0 0 1"/>
      <geom name="ball" type="sphere" size="{radius}" mass="{mass}"/>
    </body>
  </worldbody>
</mujoco>
"""

BALL_TIMECONST = 0.02
"""[s] The ball contact's solref time constant (MuJoCo's default)."""

CALIBRATION_DROP = 0.5
"""[m] Drop height (gap above contact) of the calibration run of the ``calibrated`` series."""

CALIBRATION_XTOL = 1e-7
"""Absolute tolerance on the calibrated dampratio (about 3e-7 in effective restitution)."""


def formula_dampratio(restitution: float) -> float:
    """Damping ratio z of a linear spring-damper whose half-period bounce has restitution eps.

    eps = exp(-pi z / sqrt(1 - z^2))  <=>  z = -ln(eps) / sqrt(pi^2 + ln(eps)^2).
    """
    log_eps = math.log(restitution)
    return -log_eps / math.sqrt(math.pi**2 + log_eps**2)


@dataclass
class MujocoBall:
    """The MuJoCo ball at one time step and dampratio.

    Args:
        mujoco: the imported module.
        parameters: the ball's parameters (radius [m], mass [kg], gravity [m/s^2]).
        time_step: dt [s].
        dampratio: solref damping ratio [-].
        timeconst: solref time constant [s].
    """

    mujoco: Any
    parameters: BouncingBallParameters
    time_step: float
    dampratio: float
    timeconst: float = BALL_TIMECONST

    def __post_init__(self) -> None:
        p = self.parameters
        xml = BALL_MJCF.format(dt=self.time_step, gravity=-p.gravity, timeconst=self.timeconst,
                               dampratio=self.dampratio, radius=p.radius, mass=p.mass)
        self.model = self.mujoco.MjModel.from_xml_string(xml)
        self.data = self.mujoco.MjData(self.model)
        self._spec = self.mujoco.mjtState.mjSTATE_FULLPHYSICS.value

    @property
    def contact_settings(self) -> dict[str, list[float]]:
        """The ball geom's solref and solimp as compiled (JSON-ready)."""
        return {"solref": [float(x) for x in self.model.geom_solref[1]],
                "solimp": [float(x) for x in self.model.geom_solimp[1]]}

    def _reset(self, gap: float) -> None:
        """Ball at rest with its centre ``gap`` [m] above contact."""
        self.mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[0] = self.parameters.radius + gap

    def run(self, gap: float, num_steps: int) -> tuple[float, float]:
        """Drop from rest at ``gap``, ``num_steps`` steps in one ``mj_step`` call.

        Returns:
            The final (height of the centre [m], vertical velocity [m/s]).
        """
        self._reset(gap)
        self.mujoco.mj_step(self.model, self.data, nstep=num_steps)
        return float(self.data.qpos[0]), float(self.data.qvel[0])

    def trajectories(self, gaps: Sequence[float] | np.ndarray, num_steps: int
                     ) -> tuple[np.ndarray, np.ndarray]:
        """Drops from rest at each gap, every step recorded (one single-thread rollout).

        Returns:
            (heights y (D, K + 1) [m], velocities v (D, K + 1) [m/s]), column 0 the initial
            state, D = len(gaps), K = num_steps.
        """
        from mujoco import rollout

        mj = self.mujoco
        size = mj.mj_stateSize(self.model, self._spec)
        initial = np.empty((len(gaps), size))
        for i, gap in enumerate(gaps):
            self._reset(gap)
            mj.mj_getState(self.model, self.data, initial[i], self._spec)
        state, _ = rollout.rollout(self.model, mj.MjData(self.model), initial_state=initial,
                                   nstep=num_steps)
        # FULLPHYSICS state: time, qpos (1), qvel (1), ...
        y = np.concatenate([initial[:, 1:2], state[:, :, 1]], axis=1)
        v = np.concatenate([initial[:, 2:3], state[:, :, 2]], axis=1)
        return y, v

    def effective_restitution(self, drop: float = CALIBRATION_DROP) -> float:
        """sqrt(first rebound apex / drop) of a drop from rest at gap ``drop`` [m].

        NaN when the ball does not rebound or the simulation diverges.
        """
        g = self.parameters.gravity
        t_apex = math.sqrt(2.0 * drop / g) * 2.0  # rebound apex at t1 (1 + eps) < 2 t1
        y, v = self.trajectories([drop], int(math.ceil((t_apex + 0.05) / self.time_step)))
        rising = np.nonzero(v[0] > 0.0)[0]
        if rising.size == 0 or not np.isfinite(y).all():
            return float("nan")
        apex = float(y[0, rising[0]:].max()) - self.parameters.radius
        return math.sqrt(apex / drop) if apex > 0.0 else float("nan")


def calibrate_dampratio(mujoco: Any, parameters: BouncingBallParameters, time_step: float,
                        timeconst: float = BALL_TIMECONST) -> tuple[float | None, str]:
    """The dampratio whose calibration drop rebounds with eps = ``parameters.restitution``.

    Brent's method on [z / 4, 4 z], z the formula's value, to ``CALIBRATION_XTOL``.

    Returns:
        (dampratio or None, a note: evaluations used, or why it failed).
    """
    target = parameters.restitution
    evaluations = 0

    def mismatch(dampratio: float) -> float:
        nonlocal evaluations
        evaluations += 1
        ball = MujocoBall(mujoco, parameters, time_step, dampratio, timeconst)
        value = ball.effective_restitution()
        return (value if np.isfinite(value) else 2.0) - target  # diverged: far too bouncy

    start = formula_dampratio(target)
    low, high = 0.25 * start, 4.0 * start
    try:
        f_low, f_high = mismatch(low), mismatch(high)
        if f_low * f_high > 0.0:
            return None, f"no sign change of eps_eff - eps on [{low:.3g}, {high:.3g}]"
        value = brentq(mismatch, low, high, xtol=CALIBRATION_XTOL)
    except (RuntimeError, ValueError) as error:
        return None, f"calibration failed: {error}"
    return float(value), f"{evaluations} calibration drops"


@dataclass
class MujocoArmRun:
    """The MuJoCo arm at one time step, driven by constant-command phases.

    Args:
        mujoco: the imported module.
        time_step: dt [s].
        solref: the brake equality's (timeconst [s], dampratio), None for MuJoCo's default.
    """

    mujoco: Any
    time_step: float
    solref: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        xml = ARM_MJCF.format(dt=self.time_step, rod=1.0 / 12.0, frictionloss=0.0, lock=0.0)
        self.model = self.mujoco.MjModel.from_xml_string(xml)
        if self.solref is not None:
            self.model.eq_solref[0] = self.solref
        self.data = self.mujoco.MjData(self.model)

    @property
    def brake_settings(self) -> dict[str, list[float]]:
        """The brake equality's solref and solimp (JSON-ready)."""
        return {"solref": [float(x) for x in self.model.eq_solref[0]],
                "solimp": [float(x) for x in self.model.eq_solimp[0]]}

    def state(self) -> np.ndarray:
        """(alpha, beta, alpha', beta') in our coordinates [rad, rad/s]."""
        q, u = self.data.qpos, self.data.qvel
        return np.array([q[0], q[0] + q[1], u[0], u[0] + u[1]])

    def simulate(self, phases: Sequence[tuple[int, float, bool]], stride: int | None = None
                 ) -> tuple[np.ndarray, np.ndarray | None]:
        """Run from rest at alpha = beta = 0 through ``phases``.

        Args:
            phases: (steps, motor torque [N m], brake engaged) per constant-command phase.
            stride: None for one ``mj_step`` call per phase (the timed run); else record the
                state every ``stride`` steps (each phase's length must be a multiple).

        Returns:
            (final state (4,), the recorded states (S + 1, 4) from the initial one, or None).
        """
        mj, model, data = self.mujoco, self.model, self.data
        mj.mj_resetData(model, data)
        samples = [self.state()] if stride is not None else None
        engaged_before = False
        for steps, torque, engaged in phases:
            data.ctrl[0] = torque
            if engaged and not engaged_before:
                model.eq_data[0, 0] = data.qpos[1]  # lock the relative angle where it is
            data.eq_active[0] = 1 if engaged else 0
            engaged_before = engaged
            if samples is None or stride is None:
                mj.mj_step(model, data, nstep=steps)
                continue
            for _ in range(steps // stride):
                mj.mj_step(model, data, nstep=stride)
                samples.append(self.state())
        return self.state(), None if samples is None else np.array(samples)


__all__ = ["BALL_TIMECONST", "CALIBRATION_DROP", "MujocoArmRun", "MujocoBall",
           "calibrate_dampratio", "formula_dampratio"]
