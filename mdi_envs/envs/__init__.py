"""The Gymnasium environments (registered as ``mdi_envs/...`` by ``import mdi_envs``)."""

from mdi_envs.envs.base import MoreauJeanEnv, MoreauJeanScene, MoreauJeanVectorEnv
from mdi_envs.envs.blockable_manipulator import (
    BlockableManipulatorEnv,
    BlockableManipulatorVectorEnv,
)
from mdi_envs.envs.bouncing_ball import BouncingBallEnv, BouncingBallVectorEnv
from mdi_envs.envs.diff_drive import DiffDriveRobotEnv, DiffDriveRobotVectorEnv
from mdi_envs.envs.sliding_block import SlidingBlockEnv, SlidingBlockVectorEnv

__all__ = [
    "BlockableManipulatorEnv",
    "BlockableManipulatorVectorEnv",
    "BouncingBallEnv",
    "BouncingBallVectorEnv",
    "DiffDriveRobotEnv",
    "DiffDriveRobotVectorEnv",
    "MoreauJeanEnv",
    "MoreauJeanScene",
    "MoreauJeanVectorEnv",
    "SlidingBlockEnv",
    "SlidingBlockVectorEnv",
]
