"""The maneuvers, defined once: start and goal states, control bounds, success tolerances.

The environments, the optimal-control references (``optimal/``) and the baselines all read these
records, so a goal, a torque bound or a tolerance exists in exactly one place. The paper's
published numbers (Yunt & Glocker, HSCC 2007) sit beside each maneuver for comparison only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class ManipulatorManeuver:
    """Blockable manipulator, paper section 3.1: from alpha = beta = 0 to pi, at rest, fastest.

    Attributes:
        initial_q: (alpha, beta) [rad] at t = 0, at rest.
        goal_q: (alpha, beta) [rad] to reach at rest (compared modulo 2 pi).
        max_torque: |tau| bound of the motor on alpha [N m]. Without gravity the optimal time
            scales as max_torque^(-1/2). The value is 0.81378 (4.61066 / 4.53)^2 = 0.84302 N m:
            it scales a 4.61066 s local optimum at 0.81378 N m to the paper's 4.53 s. The best
            optimum found at this bound is faster: the shipped reference takes 4.256 s
            (``optimal.load_reference("manipulator_time")``).
        angle_tolerance: success when both wrapped angle errors are within this [rad].
        velocity_tolerance: ... and both angular speeds are within this [rad/s].
        paper_final_time: the paper's optimal time [s].
        paper_brake_engaged: the paper's brake engagement times [s] (the last two impactive).
        paper_brake_released: the paper's brake release times [s].
    """

    initial_q: tuple[float, float] = (0.0, 0.0)
    goal_q: tuple[float, float] = (math.pi, math.pi)
    max_torque: float = 0.84302
    angle_tolerance: float = 0.05
    velocity_tolerance: float = 0.1
    paper_final_time: float = 4.53
    paper_brake_engaged: tuple[float, ...] = (0.0, 1.07, 2.39)
    paper_brake_released: tuple[float, ...] = (0.41, 1.84)


@dataclass(frozen=True)
class DiffDriveManeuver:
    """Differential-drive robot, paper section 3.2: from rest at the origin to (2, 5, -pi/2).

    Maneuver A minimizes the effort (integral of tau_L^2 + tau_R^2) with the final time fixed;
    maneuver B minimizes the time. Wheel angles are free at the end.

    Attributes:
        initial_pose: (x [m], y [m], phi [rad]) at t = 0, at rest.
        goal_pose: (x, y, phi) to reach at rest.
        max_wheel_torque: |tau_L|, |tau_R| bound [N m]; above the rolling traction limit of the
            default robot (about 2.2 N m per wheel), so that the optimum may slip. Not
            calibrated to the paper's 4.03 s (the paper gives no robot parameters): with the
            default robot the shipped time-optimal reference takes 2.435 s at 3.0 N m
            (``optimal.load_reference("diff_drive_time")``) through stick-slip modes like the
            paper's Fig. 8; 4.03 s would need a bound below the traction limit, where both
            maneuvers roll throughout (2-DOF only) and the stick-slip character of the paper's
            maneuvers is lost.
        effort_final_time: maneuver A's fixed final time [s] (the paper's 4.05 s).
        position_tolerance: success when |(x, y) - goal| is within this [m] ...
        heading_tolerance: ... the wrapped heading error within this [rad] ...
        speed_tolerance: ... the chassis speed |(x', y')| within this [m/s] ...
        yaw_rate_tolerance: ... and |phi'| within this [rad/s].
        paper_time_optimal: the paper's optimal time of maneuver B [s].
    """

    initial_pose: tuple[float, float, float] = (0.0, 0.0, 0.0)
    goal_pose: tuple[float, float, float] = (2.0, 5.0, -math.pi / 2)
    max_wheel_torque: float = 3.0
    effort_final_time: float = 4.05
    position_tolerance: float = 0.05
    heading_tolerance: float = 0.05
    speed_tolerance: float = 0.05
    yaw_rate_tolerance: float = 0.1
    paper_time_optimal: float = 4.03


MANIPULATOR_MANEUVER = ManipulatorManeuver()
DIFF_DRIVE_MANEUVER = DiffDriveManeuver()


__all__ = [
    "DIFF_DRIVE_MANEUVER",
    "MANIPULATOR_MANEUVER",
    "DiffDriveManeuver",
    "ManipulatorManeuver",
]
