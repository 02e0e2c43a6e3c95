"""Block on a slope with Coulomb stick-slip, pushed along the slope.

q = (s, n) [m]: position along the slope (positive down-slope) and normal distance of the
block's contact face from the slope surface; u = (s', n') [m/s]. One planar contact: gap g = n,
normal row (0, 1), tangent row (1, 0). Gravity has components (m g sin(theta), -m g cos(theta)).
The input is a force along +s [N]. Closed forms: the block at rest sticks iff
tan(theta) <= mu; sliding down it accelerates at g (sin(theta) - mu cos(theta)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.mechanics.parameters import require_in_interval, require_nonnegative, require_positive


class SlidingBlockValues(NamedTuple):
    """Parameter record read by the equations (floats, SI units)."""

    mass: float
    gravity: float
    slope_angle: float
    restitution: float
    friction_coefficient: float


@dataclass(frozen=True)
class SlidingBlockParameters:
    """Parameters of the block on a slope, validated on construction.

    Attributes:
        mass: [kg] 1.0, a unit mass so that forces read as accelerations.
        gravity: [m/s^2] 9.81, standard gravity.
        slope_angle: [rad] 0.5 (28.6 deg), in [0, pi/2); steeper than the default friction
            angle atan(0.5) = 26.6 deg, so the free block slides slowly.
        restitution: [-] 0 in [0, 1]: the block lands plastically.
        friction_coefficient: [-] 0.5 (>= 0), wood on wood.
    """

    mass: float = 1.0
    gravity: float = 9.81
    slope_angle: float = 0.5
    restitution: float = 0.0
    friction_coefficient: float = 0.5

    def __post_init__(self) -> None:
        require_positive("mass", self.mass)
        require_nonnegative("gravity", self.gravity)
        require_in_interval("slope_angle", self.slope_angle, 0.0, math.pi / 2 - 1e-9)
        require_in_interval("restitution", self.restitution, 0.0, 1.0)
        require_nonnegative("friction_coefficient", self.friction_coefficient)

    def values(self) -> SlidingBlockValues:
        """The record the equations read."""
        return SlidingBlockValues(
            self.mass, self.gravity, self.slope_angle, self.restitution,
            self.friction_coefficient,
        )


class SlidingBlock(ModelDefinition):
    """Block on an inclined plane (see the module docstring)."""

    NAME = "sliding_block"
    NUM_DOFS = 2
    NUM_INPUTS = 1
    NUM_CONTACTS = 1
    CONTACT_DIMENSION = 2
    HAS_CONSTANT_MASS = True
    HAS_VELOCITY_FORCES = False
    COORDINATE_NAMES = ("s", "n")
    Parameters = SlidingBlockParameters

    @staticmethod
    def mass_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """diag(m, m) [kg]."""
        return ((p.mass, 0.0), (0.0, p.mass))

    @staticmethod
    def forces(q: Any, u: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """Gravity in slope coordinates [N]."""
        weight = p.mass * p.gravity
        return (weight * ops.sin(p.slope_angle), -weight * ops.cos(p.slope_angle))

    @staticmethod
    def input_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """A push along +s."""
        return ((1.0,), (0.0,))

    @staticmethod
    def gaps(q: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """N [m]."""
        return (q[1],)

    @staticmethod
    def contact_directions(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """Normal (0, 1) and tangent (1, 0)."""
        return ((0.0, 1.0), (1.0, 0.0))

    @staticmethod
    def restitutions(p: Any) -> tuple[float, ...]:
        """Eps of the slope contact."""
        return (p.restitution,)

    @staticmethod
    def friction_coefficients(p: Any) -> tuple[float, ...]:
        """Mu of the slope contact."""
        return (p.friction_coefficient,)


__all__ = ["SlidingBlock", "SlidingBlockParameters", "SlidingBlockValues"]
