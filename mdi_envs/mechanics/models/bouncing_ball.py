"""Bouncing ball: a point mass over rigid ground, Newton restitution and Coulomb friction.

q = (x, y) [m]: horizontal position and height of the ball's centre; u = (x', y') [m/s].
One planar contact with the ground y = 0: gap g = y - r, normal row (0, 1), tangent row
(1, 0). The input is a horizontal force [N]. With eps < 1 the impacts accumulate in finite time
(Zeno): t_inf = t_1 (1 + eps) / (1 - eps) after the first impact at t_1.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.mechanics.parameters import require_in_interval, require_nonnegative, require_positive


class BouncingBallValues(NamedTuple):
    """Parameter record read by the equations (floats, SI units)."""

    mass: float
    radius: float
    gravity: float
    restitution: float
    friction_coefficient: float


@dataclass(frozen=True)
class BouncingBallParameters:
    """Parameters of the bouncing ball, validated on construction.

    Attributes:
        mass: [kg] 0.1, a tennis-ball-sized mass; scales forces, not trajectories.
        radius: [m] 0.05, gap g = y - radius.
        gravity: [m/s^2] 9.81, standard gravity.
        restitution: [-] 0.8 in [0, 1]; apex heights fall as eps^(2k).
        friction_coefficient: [-] 0 (>= 0); frictionless by default, so that only impacts act.
    """

    mass: float = 0.1
    radius: float = 0.05
    gravity: float = 9.81
    restitution: float = 0.8
    friction_coefficient: float = 0.0

    def __post_init__(self) -> None:
        require_positive("mass", self.mass)
        require_positive("radius", self.radius)
        require_nonnegative("gravity", self.gravity)
        require_in_interval("restitution", self.restitution, 0.0, 1.0)
        require_nonnegative("friction_coefficient", self.friction_coefficient)

    def values(self) -> BouncingBallValues:
        """The record the equations read."""
        return BouncingBallValues(
            self.mass, self.radius, self.gravity, self.restitution, self.friction_coefficient
        )


class BouncingBall(ModelDefinition):
    """Point mass over the ground y = 0 (see the module docstring)."""

    NAME = "bouncing_ball"
    NUM_DOFS = 2
    NUM_INPUTS = 1
    NUM_CONTACTS = 1
    CONTACT_DIMENSION = 2
    HAS_CONSTANT_MASS = True
    HAS_VELOCITY_FORCES = False
    COORDINATE_NAMES = ("x", "y")
    Parameters = BouncingBallParameters

    @staticmethod
    def mass_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """diag(m, m) [kg]."""
        return ((p.mass, 0.0), (0.0, p.mass))

    @staticmethod
    def forces(q: Any, u: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """Gravity (0, -m g) [N]."""
        return (0.0, -p.mass * p.gravity)

    @staticmethod
    def input_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """A horizontal force."""
        return ((1.0,), (0.0,))

    @staticmethod
    def gaps(q: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """Y - r [m]."""
        return (q[1] - p.radius,)

    @staticmethod
    def contact_directions(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """Normal (0, 1) and tangent (1, 0)."""
        return ((0.0, 1.0), (1.0, 0.0))

    @staticmethod
    def restitutions(p: Any) -> tuple[float, ...]:
        """Eps of the ground contact."""
        return (p.restitution,)

    @staticmethod
    def friction_coefficients(p: Any) -> tuple[float, ...]:
        """Mu of the ground contact."""
        return (p.friction_coefficient,)


__all__ = ["BouncingBall", "BouncingBallParameters", "BouncingBallValues"]
