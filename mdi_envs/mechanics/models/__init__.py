"""One module per system: parameters (SI, validated) and equations (``ModelDefinition``)."""

from mdi_envs.mechanics.models.blockable_manipulator import (
    BlockableManipulator,
    BlockableManipulatorParameters,
)
from mdi_envs.mechanics.models.bouncing_ball import BouncingBall, BouncingBallParameters
from mdi_envs.mechanics.models.diff_drive import DiffDriveParameters, DiffDriveRobot
from mdi_envs.mechanics.models.sliding_block import SlidingBlock, SlidingBlockParameters

__all__ = [
    "BlockableManipulator",
    "BlockableManipulatorParameters",
    "BouncingBall",
    "BouncingBallParameters",
    "DiffDriveParameters",
    "DiffDriveRobot",
    "SlidingBlock",
    "SlidingBlockParameters",
]
