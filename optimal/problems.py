"""The named optimal-control problems: the paper's three maneuvers and two small checks.

* ``manipulator_time``: the blockable manipulator (paper section 3.1) from alpha = beta = 0 to
  pi, at rest, time-optimally, |tau| <= ``MANIPULATOR_MANEUVER.max_torque``.
* ``diff_drive_time``: the differential-drive robot's maneuver B (section 3.2), time-optimal.
* ``diff_drive_effort``: maneuver A, effort-optimal (integral of tau_L^2 + tau_R^2) at the
  fixed t_f = ``DIFF_DRIVE_MANEUVER.effort_final_time``.
* ``double_integrator``: a unit mass from rest at 0 to rest at d = 1 m with |F| <= 1 N,
  time-optimal; the answer is bang-bang with T = 2 sqrt(d / a) = 2 s.
* ``ball_drop``: the bouncing ball (eps = 0.5) dropped from 0.3 m, one impact, pushed
  horizontally from rest to rest over 0.5 m in 0.4 s (the impact comes at 0.25 s,
  the next one after t_f) with least effort; the vertical motion is
  the simulator's (the horizontal force does not touch it), the horizontal one the minimum-
  effort double integrator's (a force falling linearly in time).

Start, goal and bounds come from ``mdi_envs.maneuvers``; nothing here restates a model formula.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

from mdi_envs.maneuvers import DIFF_DRIVE_MANEUVER, MANIPULATOR_MANEUVER
from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.mechanics.models.blockable_manipulator import BlockableManipulator
from mdi_envs.mechanics.models.bouncing_ball import BouncingBall, BouncingBallParameters
from mdi_envs.mechanics.models.diff_drive import DiffDriveRobot
from optimal.transcription import OptimalControlProblem


class _UnitMassValues(NamedTuple):
    mass: float


@dataclass(frozen=True)
class UnitMassParameters:
    """A 1 kg point on a line (the double integrator's plant).

    Attributes:
        mass: [kg] 1.0.
    """

    mass: float = 1.0

    def values(self) -> _UnitMassValues:
        """The record the equations read."""
        return _UnitMassValues(self.mass)


class UnitMass(ModelDefinition):
    """A point mass on a line driven by a force: M = m, h = 0, B = 1 (test plant only)."""

    NAME = "unit_mass"
    NUM_DOFS = 1
    NUM_INPUTS = 1
    HAS_CONSTANT_MASS = True
    COORDINATE_NAMES = ("x",)
    Parameters = UnitMassParameters

    @staticmethod
    def mass_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """((m,),) [kg]."""
        return ((p.mass,),)

    @staticmethod
    def forces(q: Any, u: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """No force but the input."""
        return (0.0,)

    @staticmethod
    def input_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """The input is the force on x."""
        return ((1.0,),)


BALL_DROP_PARAMETERS = BouncingBallParameters(restitution=0.5)
"""The ball of ``ball_drop``: the defaults with eps = 0.5."""

MANIPULATOR_ENV_ID = "mdi_envs/BlockableManipulator-v0"
DIFF_DRIVE_ENV_ID = "mdi_envs/DiffDriveRobot-v0"


MANIPULATOR_TIME_UNIT_TORQUE = 1.6
"""[N m] The manipulator's units: time t0 = sqrt(1 kg m^2 / tau_max) * sqrt(this / 1 N m)
(1 s at 1.6 N m), velocity 1/t0, impulse
1 kg m^2 / t0. They follow the physics' scaling (t ~ tau_max^(-1/2)), so the nondimensional NLP,
its continuation path and its local optimum do not depend on the torque bound."""

MANIPULATOR_GUESS_TIME = 4.53
"""The naive guess of t_f, in units of t0 (4.53 s at 1.6 N m)."""


def _manipulator_time(num_intervals: int = 120, guess_time: float = MANIPULATOR_GUESS_TIME
                      ) -> OptimalControlProblem:
    maneuver = MANIPULATOR_MANEUVER
    time_unit = math.sqrt(MANIPULATOR_TIME_UNIT_TORQUE / maneuver.max_torque)
    return OptimalControlProblem(
        name="manipulator_time",
        model=BlockableManipulator,
        num_intervals=num_intervals,
        initial_q=maneuver.initial_q,
        initial_u=(0.0, 0.0),
        goal_q=dict(enumerate(maneuver.goal_q)),
        goal_u={0: 0.0, 1: 0.0},
        torque_bound=maneuver.max_torque,
        cost="time",
        final_time=guess_time * time_unit,
        final_time_bounds=(0.5 * time_unit, 20.0 * time_unit),
        guess_final_q=maneuver.goal_q,
        impulse_scale=1.0 / time_unit,
        velocity_scale=1.0 / time_unit,
        time_scale=guess_time * time_unit,
        env_id=MANIPULATOR_ENV_ID,
        description="blockable manipulator, (0, 0) -> (pi, pi) at rest, time-optimal",
    )


ROBOT_GUESS_BEND = (1.5, 1.5, 0.5 * math.pi, 0.0, 0.0)
"""[m, m, rad, rad, rad] The robot's random-start bends: the path through the plane and the
heading on the way; the wheel angles enter no dynamics. From the straight naive guess, a
random stick-slip pattern solved with its modes fixed did not converge (500 iterations)."""


def _diff_drive(cost: str, num_intervals: int = 100) -> OptimalControlProblem:
    maneuver = DIFF_DRIVE_MANEUVER
    parameters = DiffDriveRobot.Parameters()  # type: ignore[attr-defined]
    weight_impulse = (parameters.mass * parameters.gravity * maneuver.effort_final_time
                      / num_intervals)
    start = (*maneuver.initial_pose, 0.0, 0.0)
    end = (*maneuver.goal_pose, 0.0, 0.0)
    effort = cost == "effort"
    return OptimalControlProblem(
        name="diff_drive_effort" if effort else "diff_drive_time",
        model=DiffDriveRobot,
        parameters=parameters,
        num_intervals=num_intervals,
        initial_q=start,
        initial_u=(0.0,) * 5,
        goal_q=dict(enumerate(maneuver.goal_pose)),
        goal_u=dict.fromkeys(range(5), 0.0),
        torque_bound=maneuver.max_wheel_torque,
        cost="effort" if effort else "time",
        final_time=maneuver.effort_final_time,
        final_time_bounds=(0.5, 20.0),
        guess_final_q=end,
        guess_bend_scale=ROBOT_GUESS_BEND,
        impulse_scale=weight_impulse,
        velocity_scale=1.0,
        env_id=DIFF_DRIVE_ENV_ID,
        env_kwargs=(("objective", "effort" if effort else "time"),),
        description=(
            "differential drive, maneuver A: (0, 0, 0) -> (2, 5, -pi/2) at rest, "
            f"effort-optimal at t_f = {maneuver.effort_final_time} s" if effort else
            "differential drive, maneuver B: (0, 0, 0) -> (2, 5, -pi/2) at rest, time-optimal"
        ),
    )


def _double_integrator(num_intervals: int = 40) -> OptimalControlProblem:
    return OptimalControlProblem(
        name="double_integrator",
        model=UnitMass,
        num_intervals=num_intervals,
        initial_q=(0.0,),
        initial_u=(0.0,),
        goal_q={0: 1.0},
        goal_u={0: 0.0},
        torque_bound=1.0,
        cost="time",
        final_time=1.0,
        final_time_bounds=(0.1, 10.0),
        guess_final_q=(1.0,),
        description="unit mass 0 -> 1 m at rest, |F| <= 1 N, time-optimal (T = 2 s)",
    )


def _ball_drop(num_intervals: int = 40) -> OptimalControlProblem:
    radius = BALL_DROP_PARAMETERS.radius
    return OptimalControlProblem(
        name="ball_drop",
        model=BouncingBall,
        parameters=BALL_DROP_PARAMETERS,
        num_intervals=num_intervals,
        initial_q=(0.0, radius + 0.3),
        initial_u=(0.0, 0.0),
        goal_q={0: 0.5},
        goal_u={0: 0.0},
        torque_bound=10.0,
        cost="effort",
        final_time=0.4,
        guess_final_q=(0.5, radius + 0.3),
        impulse_scale=0.1,
        velocity_scale=1.0,
        length_scale=0.1,
        description="ball (eps = 0.5) dropped from 0.3 m, pushed 0.5 m sideways, least effort",
    )


PROBLEMS = {
    "manipulator_time": _manipulator_time,
    "diff_drive_time": lambda num_intervals=100: _diff_drive("time", num_intervals),
    "diff_drive_effort": lambda num_intervals=100: _diff_drive("effort", num_intervals),
    "double_integrator": _double_integrator,
    "ball_drop": _ball_drop,
}
"""Problem factories by name; each takes ``num_intervals`` (N) and returns the problem."""

REFERENCE_NAMES = ("manipulator_time", "diff_drive_time", "diff_drive_effort")
"""The problems whose solutions ship in ``optimal/references``."""


def make_problem(name: str, num_intervals: int | None = None) -> OptimalControlProblem:
    """The problem called ``name`` (N = its default unless ``num_intervals`` is given).

    Raises:
        KeyError: unknown name (the message lists the known ones).
    """
    if name not in PROBLEMS:
        raise KeyError(f"unknown problem {name!r}; known: {', '.join(PROBLEMS)}")
    factory = PROBLEMS[name]
    return factory() if num_intervals is None else factory(num_intervals)


def model_of(problem: OptimalControlProblem) -> tuple[type[ModelDefinition], Any]:
    """(model class, parameters) of ``problem``, defaults filled in."""
    parameters = problem.parameters
    if parameters is None:
        parameters = problem.model.Parameters()  # type: ignore[attr-defined]
    return problem.model, parameters


__all__ = [
    "BALL_DROP_PARAMETERS",
    "PROBLEMS",
    "REFERENCE_NAMES",
    "ROBOT_GUESS_BEND",
    "UnitMass",
    "UnitMassParameters",
    "make_problem",
    "model_of",
]
