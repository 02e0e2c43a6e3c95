"""The three-wheeled differential-drive robot of Yunt & Glocker (HSCC 2007, section 3.2).

q = (x, y, phi, psi_L, psi_R): planar position [m] of the centre of mass (CM) and heading
[rad] of the chassis, and the angles [rad] of the left and right driven wheels relative to the
chassis; u = q'. The unpowered front wheel is replaced by a sliding point (the "stick").
Wheel and actuator spin inertias are lumped into J, chassis and wheel masses into m and I, so

    M = diag(m, m, I, J, J) (constant),  h = 0,  B = [e_psiL, e_psiR] (motor torques tau_L, tau_R).

Contacts (body frame K: x_K forward, y_K left, origin at the CM, ground at -h_cm):
left wheel (-a, b), right wheel (-a, -b), stick (c, 0). All three are spatial Coulomb contacts
(CONTACT_DIMENSION = 3) whose tangent rows give the slip velocities in the body frame,

    gamma_x = cos(phi) x' + sin(phi) y' - phi' r_y - r psi'   (longitudinal; no psi at the stick)
    gamma_y = -sin(phi) x' + cos(phi) y' + phi' r_x           (lateral),

and whose normal rows are zero: the chassis has no vertical degree of freedom. The normal
forces instead follow from the balance of vertical force and of roll and pitch moments about the
CM, and so depend linearly on the friction forces F = (F_x, F_y) at the contacts (the paper's
set I_NC): with S = N_L + N_R,

    S   = (c m g + h_cm sum F_x) / (a + c),        N_stick = (a m g - h_cm sum F_x) / (a + c),
    N_L = (S - (h_cm / b) sum F_y) / 2,            N_R     = (S + (h_cm / b) sum F_y) / 2,

which ``normal_loads`` returns as N = N0 + K F. (The balance neglects the pitch-axis angular
momentum of the spinning wheels.) Modes (Table 1): 2-DOF when both wheels roll, 3-DOF when one
slips, 5-DOF when both slip.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.mechanics.parameters import require_nonnegative, require_positive


class DiffDriveValues(NamedTuple):
    """Parameter record read by the equations (floats, SI units)."""

    mass: float
    yaw_inertia: float
    wheel_radius: float
    wheel_inertia: float
    half_track: float
    axle_offset: float
    stick_offset: float
    cm_height: float
    gravity: float
    wheel_friction: float
    stick_friction: float


@dataclass(frozen=True)
class DiffDriveParameters:
    """Parameters of the differential-drive robot, validated on construction.

    The paper gives none; these describe a small indoor robot.

    Attributes:
        mass: [kg] 10, chassis, battery and wheels together.
        yaw_inertia: [kg m^2] 0.5, about the vertical axis through the CM (a 0.6 x 0.4 m box
            of 10 kg has 0.43; the wheels add to it).
        wheel_radius: [m] 0.1.
        wheel_inertia: [kg m^2] 0.02, a wheel (0.005) plus the reflected inertia of motor and
            gearbox.
        half_track: [m] 0.2, half the distance between the driven wheels.
        axle_offset: [m] 0.1, the driven axle lies this far behind the CM.
        stick_offset: [m] 0.3, the front stick lies this far ahead of the CM.
        cm_height: [m] 0.15, height of the CM above the ground (drives the load transfer).
        gravity: [m/s^2] 9.81.
        wheel_friction: [-] 0.6, rubber on a floor.
        stick_friction: [-] 0.3, a skid on a floor.
    """

    mass: float = 10.0
    yaw_inertia: float = 0.5
    wheel_radius: float = 0.1
    wheel_inertia: float = 0.02
    half_track: float = 0.2
    axle_offset: float = 0.1
    stick_offset: float = 0.3
    cm_height: float = 0.15
    gravity: float = 9.81
    wheel_friction: float = 0.6
    stick_friction: float = 0.3

    def __post_init__(self) -> None:
        for name in ("mass", "yaw_inertia", "wheel_radius", "wheel_inertia", "half_track",
                     "gravity"):
            require_positive(name, getattr(self, name))
        for name in ("axle_offset", "stick_offset", "cm_height", "wheel_friction",
                     "stick_friction"):
            require_nonnegative(name, getattr(self, name))
        require_positive("axle_offset + stick_offset", self.axle_offset + self.stick_offset)

    def values(self) -> DiffDriveValues:
        """The record the equations read."""
        return DiffDriveValues(
            self.mass, self.yaw_inertia, self.wheel_radius, self.wheel_inertia,
            self.half_track, self.axle_offset, self.stick_offset, self.cm_height,
            self.gravity, self.wheel_friction, self.stick_friction,
        )


class DiffDriveRobot(ModelDefinition):
    """Chassis with two driven wheels and a sliding stick (see the module docstring)."""

    NAME = "diff_drive"
    NUM_DOFS = 5
    NUM_INPUTS = 2
    NUM_CONTACTS = 3
    CONTACT_DIMENSION = 3
    HAS_CONSTANT_MASS = True
    HAS_VELOCITY_FORCES = False
    HAS_LOAD_TRANSFER = True
    COORDINATE_NAMES = ("x", "y", "phi", "psi_L", "psi_R")
    Parameters = DiffDriveParameters

    @staticmethod
    def mass_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """diag(m, m, I, J, J)."""
        m, inertia, j = p.mass, p.yaw_inertia, p.wheel_inertia
        return (
            (m, 0.0, 0.0, 0.0, 0.0),
            (0.0, m, 0.0, 0.0, 0.0),
            (0.0, 0.0, inertia, 0.0, 0.0),
            (0.0, 0.0, 0.0, j, 0.0),
            (0.0, 0.0, 0.0, 0.0, j),
        )

    @staticmethod
    def forces(q: Any, u: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """No smooth forces in the plane (gravity acts through the normal loads)."""
        return (0.0, 0.0, 0.0, 0.0, 0.0)

    @staticmethod
    def input_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """The motors drive the wheel angles."""
        return ((0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0))

    @staticmethod
    def gaps(q: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """Always closed (0): there is no vertical degree of freedom."""
        return (0.0, 0.0, 0.0)

    @staticmethod
    def contact_directions(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """Per contact: a zero normal row, then the longitudinal and lateral slip rows."""
        c, s = ops.cos(q[2]), ops.sin(q[2])
        a, b, f, r = p.axle_offset, p.half_track, p.stick_offset, p.wheel_radius
        zero = (0.0, 0.0, 0.0, 0.0, 0.0)
        return (
            zero,
            (c, s, -b, -r, 0.0),
            (-s, c, -a, 0.0, 0.0),
            zero,
            (c, s, b, 0.0, -r),
            (-s, c, -a, 0.0, 0.0),
            zero,
            (c, s, 0.0, 0.0, 0.0),
            (-s, c, f, 0.0, 0.0),
        )

    @staticmethod
    def normal_loads(p: Any) -> tuple[tuple[float, ...], tuple[tuple[float, ...], ...]]:
        """(N0, K): normal forces N = N0 + K F [N] for friction forces F (6,) [N].

        F lists (F_x, F_y) of the left wheel, right wheel and stick in the body frame.
        """
        weight = p.mass * p.gravity
        span = p.axle_offset + p.stick_offset
        shift_x = p.cm_height / span  # load moved to the axle per unit of sum F_x
        shift_y = p.cm_height / p.half_track  # load moved left -> right per unit of sum F_y
        axle0 = p.stick_offset * weight / span
        # explicit rows (numba compiles this too, and has no tuple repetition)
        lx, ly = 0.5 * shift_x, 0.5 * shift_y
        row_left = (lx, -ly, lx, -ly, lx, -ly)
        row_right = (lx, ly, lx, ly, lx, ly)
        row_stick = (-shift_x, 0.0, -shift_x, 0.0, -shift_x, 0.0)
        n0 = (0.5 * axle0, 0.5 * axle0, p.axle_offset * weight / span)
        return n0, (row_left, row_right, row_stick)

    @staticmethod
    def slip_mode(sliding: Any) -> int:
        """The mode of Table 1 from the slip state of the contacts: 2, 3 or 5 (its DOF count).

        Args:
            sliding: per contact (left wheel, right wheel, stick) 1 if it slides, else 0.

        Returns:
            2 when both wheels roll (the robot moves like a unicycle: forward speed and yaw
            rate), 3 when exactly one wheel slides, 5 when both slide. The stick slides
            whenever the robot moves and does not enter the mode.
        """
        num_sliding = sliding[0] + sliding[1]
        if num_sliding == 0:
            return 2
        if num_sliding == 1:
            return 3
        return 5

    @staticmethod
    def friction_coefficients(p: Any) -> tuple[float, ...]:
        """Friction coefficients mu of the left wheel, right wheel and stick."""
        return (p.wheel_friction, p.wheel_friction, p.stick_friction)

    @staticmethod
    def restitutions(p: Any) -> tuple[float, ...]:
        """No impacts in the normal direction (always closed)."""
        return (0.0, 0.0, 0.0)


__all__ = ["DiffDriveParameters", "DiffDriveRobot", "DiffDriveValues"]
