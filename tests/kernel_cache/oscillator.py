"""A damped 1-DOF oscillator defined outside the package (the kernel cache tests edit it)."""

from typing import Any, NamedTuple

from mdi_envs.mechanics.models.base import ModelDefinition


class OscillatorValues(NamedTuple):
    """Parameter record."""

    stiffness: float


class OscillatorParameters:
    """Parameters: stiffness [N/m]."""

    def __init__(self, stiffness: float = 4.0) -> None:
        self.stiffness = stiffness

    def values(self) -> OscillatorValues:
        """The record the equations read."""
        return OscillatorValues(self.stiffness)


class Oscillator(ModelDefinition):
    """Unit mass on a spring with unit damping: h = -k q - u."""

    NAME = "oscillator"
    NUM_DOFS = 1
    NUM_INPUTS = 1
    HAS_CONSTANT_MASS = True
    HAS_VELOCITY_FORCES = True
    COORDINATE_NAMES = ("q",)
    Parameters = OscillatorParameters

    @staticmethod
    def mass_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """M = 1 [kg]."""
        return ((1.0,),)

    @staticmethod
    def forces(q: Any, u: Any, p: Any, ops: Any) -> tuple[Any, ...]:
        """Spring and damper [N]."""
        return (-p.stiffness * q[0] - 1.0 * u[0],)

    @staticmethod
    def input_matrix(q: Any, p: Any, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """A force."""
        return ((1.0,),)
