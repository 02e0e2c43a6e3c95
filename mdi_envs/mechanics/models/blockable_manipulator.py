"""The blockable two-link manipulator of Yunt & Glocker (HSCC 2007, section 3.1).

Two uniform rods in a horizontal plane (no gravity). q = (alpha, beta) [rad]: absolute angles
of link 1 (hinged at the base, driven by the motor torque tau) and of link 2 (hinged at the tip
of link 1, passive); u = (alpha', beta') [rad/s]. A brake on the relative angle beta - alpha
(direction W_B = (-1, 1)) blocks it instantly when engaged: an impulsive, set-valued control.

With c = m2 l1 l2 / 2 and s = sin(beta - alpha), the Lagrangian gives

    M = [[m1 l1^2/3 + m2 l1^2,  c cos(beta - alpha)],
         [c cos(beta - alpha),  m2 l2^2/3          ]],   h = (c s beta'^2, -c s alpha'^2).

The total angular momentum about the base is (1, 1) . M u; the brake is internal, so it is
conserved whenever tau = 0.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

from mdi_envs.mechanics.models.base import ModelDefinition
from mdi_envs.mechanics.parameters import require_positive


class BlockableManipulatorValues(NamedTuple):
    """Parameter record read by the equations (floats, SI units)."""

    link1_mass: float
    link1_length: float
    link2_mass: float
    link2_length: float


@dataclass(frozen=True)
class BlockableManipulatorParameters:
    """Parameters of the manipulator, validated on construction.

    Attributes:
        link1_mass: [kg] 1.0, a uniform rod.
        link1_length: [m] 1.0, idem.
        link2_mass: [kg] 1.0, idem.
        link2_length: [m] 1.0, idem.
    """

    link1_mass: float = 1.0
    link1_length: float = 1.0
    link2_mass: float = 1.0
    link2_length: float = 1.0

    def __post_init__(self) -> None:
        for name in ("link1_mass", "link1_length", "link2_mass", "link2_length"):
            require_positive(name, getattr(self, name))

    def values(self) -> BlockableManipulatorValues:
        """The record the equations read."""
        return BlockableManipulatorValues(
            self.link1_mass, self.link1_length, self.link2_mass, self.link2_length
        )


class BlockableManipulator(ModelDefinition):
    """Two links, one motor on alpha, one brake on beta - alpha (see the module docstring)."""

    NAME = "blockable_manipulator"
    NUM_DOFS = 2
    NUM_INPUTS = 1
    NUM_BRAKES = 1
    COORDINATE_NAMES = ("alpha", "beta")
    Parameters = BlockableManipulatorParameters

    @staticmethod
    def mass_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """M(q) [kg m^2]."""
        coupling = 0.5 * p.link2_mass * p.link1_length * p.link2_length * ops.cos(q[1] - q[0])
        m11 = (p.link1_mass / 3.0 + p.link2_mass) * p.link1_length**2
        m22 = p.link2_mass * p.link2_length**2 / 3.0
        return ((m11, coupling), (coupling, m22))

    @staticmethod
    def forces(q: Any, u: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """Centrifugal coupling h(q, u) [N m]."""
        c = 0.5 * p.link2_mass * p.link1_length * p.link2_length * ops.sin(q[1] - q[0])
        return (c * u[1] * u[1], -c * u[0] * u[0])

    @staticmethod
    def input_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """The motor drives alpha."""
        return ((1.0,), (0.0,))

    @staticmethod
    def brake_directions(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """The relative angular velocity beta' - alpha'."""
        return ((-1.0, 1.0),)


__all__ = [
    "BlockableManipulator",
    "BlockableManipulatorParameters",
    "BlockableManipulatorValues",
]
