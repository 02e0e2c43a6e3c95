"""Simulation: the Moreau-Jean stepper (single and batched), the event-driven reference."""

from mdi_envs.stepping._kernel import StepShortcuts
from mdi_envs.stepping.event_driven import (
    EventDrivenIntegrator,
    PiecewiseConstant,
    Trajectory,
    bang_bang,
    brake_schedule,
    simulate_ball,
    simulate_manipulator,
)
from mdi_envs.stepping.in_place import InPlaceStepper
from mdi_envs.stepping.moreau_jean import MoreauJeanStepper, StepResult

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
