"""Simulation: the Moreau-Jean stepper (single and batched), the event-driven reference."""

from typing import Any

from mdi_envs.stepping._kernel import StepShortcuts
from mdi_envs.stepping.in_place import InPlaceStepper
from mdi_envs.stepping.moreau_jean import MoreauJeanStepper, StepResult

_EVENT_DRIVEN_NAMES = ("EventDrivenIntegrator", "PiecewiseConstant", "Trajectory", "bang_bang",
                       "brake_schedule", "simulate_ball", "simulate_manipulator")


def __getattr__(name: str) -> Any:
    """The event-driven reference's names, imported on first use.

    ``event_driven`` needs scipy.integrate, about 0.3 s to import that a process which only
    steps an environment should not pay.
    """
    if name in _EVENT_DRIVEN_NAMES:
        from mdi_envs.stepping import event_driven

        return getattr(event_driven, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "EventDrivenIntegrator",
    "InPlaceStepper",
    "MoreauJeanStepper",
    "PiecewiseConstant",
    "StepResult",
    "StepShortcuts",
    "Trajectory",
    "bang_bang",
    "brake_schedule",
    "simulate_ball",
    "simulate_manipulator",
]
