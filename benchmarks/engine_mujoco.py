"""MuJoCo peers: the blockable manipulator as a two-link MJCF arm, and the bouncing ball.

The arm's coordinates are ``(alpha, beta - alpha)`` (mass matrix ``T^T M T``, checked at run
time); its brake is a joint equality switched by ``eq_active`` (soft, ``solref``), its Tresca
brake ``frictionloss``. The ball is a sphere on a slide joint whose restitution comes from the
contact's ``solref`` damping ratio, by the damped-oscillator formula or calibrated per dt.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from benchmarks.engine_scenes import (
    MANIPULATOR_Q,
    MANIPULATOR_U,
    MOTOR_TORQUE,
    TIME_STEP,
    TRESCA_BOUND,
)

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


def import_mujoco() -> tuple[Any, str | None]:
    """(the mujoco module or None, a note when it is missing)."""
    try:
        import mujoco
    except ImportError as error:
        return None, f"MuJoCo skipped: {error} (pip install mujoco)"
    return mujoco, None


@dataclass
class MujocoArm:
    """The MJCF arm, its Python single steps, batched rollouts and the brake-stop test.

    Args:
        mujoco: the imported module.
    """

    mujoco: Any

    def __post_init__(self) -> None:
        mj = self.mujoco
        lock = MANIPULATOR_Q[1] - MANIPULATOR_Q[0]
        self.plain = self._model(frictionloss=0.0, lock=lock)
        self.tresca = self._model(frictionloss=TRESCA_BOUND, lock=lock)
        self.state_spec = mj.mjtState.mjSTATE_FULLPHYSICS.value
        self.control_spec = mj.mjtState.mjSTATE_CTRL.value | mj.mjtState.mjSTATE_EQ_ACTIVE.value
        self._rollout = None

    def _model(self, frictionloss: float, lock: float) -> Any:
        xml = MJCF.format(dt=TIME_STEP, rod=1.0 / 12.0, frictionloss=frictionloss, lock=lock)
        return self.mujoco.MjModel.from_xml_string(xml)

    def _data(self, scene: str) -> tuple[Any, Any]:
        """(model, data) of a scene: the manipulator scenes' state in MuJoCo coordinates."""
        model = self.tresca if scene == "tresca" else self.plain
        data = self.mujoco.MjData(model)
        alpha, beta = MANIPULATOR_Q
        alpha_dot, beta_dot = MANIPULATOR_U
        data.qpos[:] = (alpha, beta - alpha)
        data.qvel[:] = (alpha_dot, beta_dot - alpha_dot)
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
        calls = {}
        for scene in SCENES:
            model, data = self._data(scene)
            calls[scene] = (lambda m=model, d=data: self.mujoco.mj_step(m, d))
        return calls

    def rollout_call(self, num_copies: int, num_steps: int,
                     scenes: tuple[str, ...] = SCENES) -> Any:
        """A zero-argument single-thread ``rollout`` of N copies by ``num_steps`` steps.

        Outputs are preallocated and ``skip_checks=True``. Copy i runs scene
        ``scenes[i % len(scenes)]`` (default: the manipulator's mix); the brake state is the
        ``eq_active`` part of the control (``mjSTATE_CTRL | mjSTATE_EQ_ACTIVE``), the Tresca
        copies use the frictionloss model. Every call starts from the same initial states.
        """
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
        picks = [per_scene[scenes[i % len(scenes)]] for i in range(num_copies)]
        models = [pick[0] for pick in picks]
        states = [pick[1] for pick in picks]
        controls = [pick[2] for pick in picks]
        initial = np.array(states)
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
        """Steps until |q2'| < 1 % of 1 rad/s after the brake engages at q2' = 1 rad/s.

        Link 1 at rest, no torque; the brake locks joint 2 at its current angle 0.

        Args:
            solref: the equality's (timeconst, dampratio), or None for MuJoCo's default.
            max_steps: give up after this many steps.

        Returns:
            steps (None if not reached), the |q2'| trace up to then (at most 200 entries), the
            relative angle when reached and its largest magnitude on the way.
        """
        mj = self.mujoco
        model = self._model(frictionloss=0.0, lock=0.0)
        if solref is not None:
            model.eq_solref[0] = solref
        data = mj.MjData(model)
        data.qvel[:] = (0.0, 1.0)
        data.eq_active[0] = 1
        trace = [1.0]
        largest_angle = 0.0
        steps = None
        for k in range(1, max_steps + 1):
            mj.mj_step(model, data)
            speed = abs(float(data.qvel[1]))
            largest_angle = max(largest_angle, abs(float(data.qpos[1])))
            if len(trace) < 200:
                trace.append(speed)
            if speed < 0.01:
                steps = k
                break
        return {
            "solref": list(model.eq_solref[0]),
            "solimp": list(model.eq_solimp[0]),
            "steps": steps,
            "relative_angle_at_stop": float(data.qpos[1]),
            "largest_relative_angle": largest_angle,
            "relative_speed_trace": trace,
        }

    def close(self) -> None:
        """Shut down the rollout thread pool, if one was made."""
        if self._rollout is not None:
            self._rollout.close()
            self._rollout = None


__all__ = ["MJCF", "SCENES", "MujocoArm", "import_mujoco"]
