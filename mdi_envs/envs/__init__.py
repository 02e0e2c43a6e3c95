"""The Gymnasium environments (registered as ``mdi_envs/...`` by ``import mdi_envs``)."""

from mdi_envs.envs.base import MoreauJeanEnv, MoreauJeanTask, MoreauJeanVectorEnv
from mdi_envs.envs.blockable_manipulator import (
    BlockableManipulatorEnv,
    BlockableManipulatorVectorEnv,
)
from mdi_envs.envs.diff_drive import DiffDriveRobotEnv, DiffDriveRobotVectorEnv

__all__ = [
    "BlockableManipulatorEnv",
    "BlockableManipulatorVectorEnv",
    "DiffDriveRobotEnv",
    "DiffDriveRobotVectorEnv",
    "MoreauJeanEnv",
    "MoreauJeanTask",
    "MoreauJeanVectorEnv",
]
