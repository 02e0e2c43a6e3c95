"""MuJoCo peers: the blockable manipulator as a two-link MJCF arm, and the bouncing ball.

The arm's coordinates are ``(alpha, beta - alpha)`` (mass matrix ``T^T M T``, checked at run
time); its brake is a joint equality switched by ``eq_active`` (soft, ``solref``), its Tresca
brake ``frictionloss``. The ball is a sphere on a slide joint whose restitution comes from the
contact's ``solref`` damping ratio, by the damped-oscillator formula or calibrated per dt.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from scipy.optimize import brentq

from benchmarks import engine_scenes
from benchmarks.engine_scenes import MANIPULATOR_Q, MANIPULATOR_U, MOTOR_TORQUE, TIME_STEP
from mdi_envs.mechanics.models.bouncing_ball import BouncingBallParameters

MJCF = """
<mujoco model="blockable_manipulator">
  <option timestep="{dt}" gravity="0 0 0"><flag contact="disable"/></option>
  <worldbody>
    <body name="link1">
      <joint name="j1" type="hinge" axis="0 0 1"/>
      <inertial pos="0.5 0 0" mass="1" diaginertia="1e-6 {rod} {rod}"/>
      <geom type="capsule" fromto="0 0 0 1 0 0" size="0.02" contype="0" conaffinity="0"/>
      <body name="link2" pos="1 0 0">
        <joint name="j2" type="hinge" axis="0 0 1" frictionloss="{frictionloss}"/>
        <inertial pos="0.5 0 0" mass="1" diaginertia="1e-6 {rod} {rod}"/>
        <geom type="capsule" fromto="0 0 0 1 0 0" size="0.02" contype="0" conaffinity="0"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor name="motor" joint="j1" gear="1"/></actuator>
  <equality><joint name="brake" joint1="j2" polycoef="{lock} 0 0 0 0" active="false"/></equality>
</mujoco>
"""

SCENES = ("engaged", "released", "tresca")
"""MuJoCo scenes, in the order of the manipulator's batched mix."""


def arm_model(mujoco: Any, dt: float, frictionloss: float = 0.0, lock: float = 0.0) -> Any:
    """The MJCF arm at time step dt [s], joint 2's frictionloss [N m] and brake lock [rad]."""
    xml = MJCF.format(dt=dt, rod=1.0 / 12.0, frictionloss=frictionloss, lock=lock)
    return mujoco.MjModel.from_xml_string(xml)


def _settings(solref: Any, solimp: Any) -> dict[str, list[float]]:
    """A constraint's solref and solimp (JSON-ready)."""
    return {"solref": [float(x) for x in solref], "solimp": [float(x) for x in solimp]}


def import_mujoco() -> tuple[Any, str | None]:
    """(the mujoco module or None, a note when it is missing)."""
    try:
        import mujoco
    except ImportError as error:
        return None, f"MuJoCo skipped: {error} (pip install mujoco)"
    return mujoco, None


@dataclass
class MujocoArm:
    """The MJCF arm, its Python single steps, batched rollouts and the brake-stop test."""

    mujoco: Any

    def __post_init__(self) -> None:
        mj = self.mujoco
        lock = MANIPULATOR_Q[1] - MANIPULATOR_Q[0]
        self.plain = arm_model(mj, TIME_STEP, lock=lock)
        self.tresca = arm_model(mj, TIME_STEP, frictionloss=engine_scenes.TRESCA_BOUND, lock=lock)
        self.state_spec = mj.mjtState.mjSTATE_FULLPHYSICS.value
        self.control_spec = mj.mjtState.mjSTATE_CTRL.value | mj.mjtState.mjSTATE_EQ_ACTIVE.value
        self._rollout = None

    def _data(self, scene: str) -> tuple[Any, Any]:
        """(model, data) of a scene: the manipulator scenes' state in MuJoCo coordinates."""
        model = self.tresca if scene == "tresca" else self.plain
        data = self.mujoco.MjData(model)
        (alpha, beta), (alpha_dot, beta_dot) = MANIPULATOR_Q, MANIPULATOR_U
        data.qpos[:], data.qvel[:] = (alpha, beta - alpha), (alpha_dot, beta_dot - alpha_dot)
        data.ctrl[0] = MOTOR_TORQUE
        data.eq_active[0] = 1 if scene == "engaged" else 0
        return model, data

    def mass_matrix_check(self, ours: np.ndarray) -> float:
        """Largest |M_mujoco - T^T M_ours T| at the scene state; ``ours`` is our M(q)."""
        model, data = self._data("released")
        self.mujoco.mj_forward(model, data)
        full = np.zeros((2, 2))
        self.mujoco.mj_fullM(model, data, full)
        transform = np.array([[1.0, 0.0], [1.0, 1.0]])
        return float(np.abs(full - transform.T @ ours @ transform).max())

    def single_step_calls(self) -> dict[str, Any]:
        """Scene -> zero-argument ``mj_step(model, data)`` (the state advances call by call)."""
        return {scene: partial(self.mujoco.mj_step, *self._data(scene)) for scene in SCENES}

    def rollout_call(self, num_copies: int, num_steps: int,
                     scenes: tuple[str, ...] = SCENES) -> Any:
        """A zero-argument single-thread ``rollout`` of N copies by ``num_steps`` steps."""
        from mujoco import rollout

        if self._rollout is None:
            self._rollout = rollout.Rollout(nthread=0)
        mj = self.mujoco
        per_scene = {}
        for scene in dict.fromkeys(scenes):
            model, data = self._data(scene)
            state = np.empty(mj.mj_stateSize(model, self.state_spec))
            mj.mj_getState(model, data, state, self.state_spec)
            per_scene[scene] = (model, state, (MOTOR_TORQUE, 1.0 if scene == "engaged" else 0.0))
        models, states, controls = zip(*(per_scene[scenes[i % len(scenes)]]
                                         for i in range(num_copies)), strict=True)
        models, initial = list(models), np.array(states)
        control = np.repeat(np.array(controls)[:, None, :], num_steps, axis=1)
        out_state = np.empty((num_copies, num_steps, initial.shape[1]))
        out_sensor = np.empty((num_copies, num_steps, 0))
        data = [mj.MjData(self.plain)]
        runner = self._rollout

        def call() -> None:
            runner.rollout(models, data, initial_state=initial, control=control,
                           control_spec=self.control_spec, skip_checks=True, nstep=num_steps,
                           state=out_state, sensordata=out_sensor, initial_warmstart=None,
                           chunk_size=None)

        return call

    def brake_stop(self, solref: tuple[float, float] | None, max_steps: int = 10_000
                   ) -> dict[str, Any]:
        """Steps until |q2'| < 1 % of 1 rad/s after the brake engages at q2' = 1 rad/s."""
        mj, run = self.mujoco, MujocoArmRun(self.mujoco, TIME_STEP, solref)
        model, data = run.model, run.data
        data.qvel[:] = (0.0, 1.0)
        data.eq_active[0] = 1
        trace, largest_angle, steps = [1.0], 0.0, None
        for k in range(1, max_steps + 1):
            mj.mj_step(model, data)
            speed = abs(float(data.qvel[1]))
            largest_angle = max(largest_angle, abs(float(data.qpos[1])))
            if len(trace) < 200:
                trace.append(speed)
            if speed < 0.01:
                steps = k
                break
        return {**run.brake_settings, "steps": steps, "relative_angle_at_stop": float(data.qpos[1]),
                "largest_relative_angle": largest_angle, "relative_speed_trace": trace}

    def close(self) -> None:
        """Shut down the rollout thread pool, if one was made."""
        if self._rollout is not None:
            self._rollout.close()
            self._rollout = None


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

BALL_TIMECONST = 0.02  # [s] the contact's solref time constant (MuJoCo's default)
CALIBRATION_DROP = 0.5  # [m] drop of the calibration run
CALIBRATION_XTOL = 1e-7  # on the calibrated dampratio


def formula_dampratio(restitution: float) -> float:
    """Damping ratio -ln(eps) / sqrt(pi^2 + ln(eps)^2) of a bounce with restitution eps."""
    log_eps = math.log(restitution)
    return -log_eps / math.sqrt(math.pi**2 + log_eps**2)


@dataclass
class MujocoBall:
    """The MuJoCo ball at time step dt [s] and contact solref (timeconst [s], dampratio)."""

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
        return _settings(self.model.geom_solref[1], self.model.geom_solimp[1])

    def _reset(self, gap: float) -> None:
        self.mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[0] = self.parameters.radius + gap

    def run(self, gap: float, num_steps: int) -> tuple[float, float]:
        """Final (height [m], velocity [m/s]) of a drop from rest at ``gap``, one mj_step call."""
        self._reset(gap)
        self.mujoco.mj_step(self.model, self.data, nstep=num_steps)
        return float(self.data.qpos[0]), float(self.data.qvel[0])

    def trajectories(self, gaps: Sequence[float] | np.ndarray, num_steps: int
                     ) -> tuple[np.ndarray, np.ndarray]:
        """Heights y and velocities v (D, K + 1) of drops from rest at D gaps (one rollout)."""
        from mujoco import rollout

        mj = self.mujoco
        size = mj.mj_stateSize(self.model, self._spec)
        initial = np.empty((len(gaps), size))
        for i, gap in enumerate(gaps):
            self._reset(gap)
            mj.mj_getState(self.model, self.data, initial[i], self._spec)
        state, _ = rollout.rollout(self.model, mj.MjData(self.model), initial_state=initial,
                                   nstep=num_steps)
        y = np.concatenate([initial[:, 1:2], state[:, :, 1]], axis=1)
        v = np.concatenate([initial[:, 2:3], state[:, :, 2]], axis=1)
        return y, v

    def effective_restitution(self, drop: float = CALIBRATION_DROP) -> float:
        """sqrt(first rebound apex / drop) of a drop from gap ``drop`` [m]; NaN if none."""
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
    """(dampratio whose calibration drop rebounds with eps (Brent), or None; a note)."""
    target, evaluations = parameters.restitution, 0

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
    """The MuJoCo arm at dt [s] driven by phases; brake ``solref`` None: MuJoCo's default."""

    mujoco: Any
    time_step: float
    solref: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        self.model = arm_model(self.mujoco, self.time_step)
        if self.solref is not None:
            self.model.eq_solref[0] = self.solref
        self.data = self.mujoco.MjData(self.model)

    @property
    def brake_settings(self) -> dict[str, list[float]]:
        """The brake equality's solref and solimp (JSON-ready)."""
        return _settings(self.model.eq_solref[0], self.model.eq_solimp[0])

    def state(self) -> np.ndarray:
        """(alpha, beta, alpha', beta') in our coordinates [rad, rad/s]."""
        q, u = self.data.qpos, self.data.qvel
        return np.array([q[0], q[0] + q[1], u[0], u[0] + u[1]])

    def simulate(self, phases: Sequence[tuple[int, float, bool]], stride: int | None = None
                 ) -> tuple[np.ndarray, np.ndarray | None]:
        """From rest through (steps, torque [N m], brake engaged) phases, one mj_step each."""
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
