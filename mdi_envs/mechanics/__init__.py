"""Mechanical models: one definition per system (equations + validated SI parameters)."""

from mdi_envs.mechanics.models import (
    BlockableManipulator,
    BlockableManipulatorParameters,
    BouncingBall,
    BouncingBallParameters,
    DiffDriveParameters,
    DiffDriveRobot,
    SlidingBlock,
    SlidingBlockParameters,
)
from mdi_envs.mechanics.models.base import ModelDefinition

__all__ = [
    "BlockableManipulator",
    "BlockableManipulatorParameters",
    "BouncingBall",
    "BouncingBallParameters",
    "DiffDriveParameters",
    "DiffDriveRobot",
    "ModelDefinition",
    "SlidingBlock",
    "SlidingBlockParameters",
]
