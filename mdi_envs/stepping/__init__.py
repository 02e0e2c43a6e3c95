"""Simulation: the Moreau-Jean midpoint stepper (single and batched)."""

from mdi_envs.stepping._kernel import StepShortcuts
from mdi_envs.stepping.moreau_jean import MoreauJeanStepper, StepResult

__all__ = ["MoreauJeanStepper", "StepResult", "StepShortcuts"]
