"""Planar Coulomb friction contact: data, the shared residual, ``solve_fc2d``."""

from mdi_envs.solvers.fc2d import lemke, newton_ac, nsgs  # noqa: F401  (registration)
from mdi_envs.solvers.fc2d.driver import solve_fc2d
from mdi_envs.solvers.fc2d.problem import FC2DResult, FrictionContact2D, fc2d_residual
from mdi_envs.solvers.fc2d.registry import FC2D_METHODS

__all__ = ["FC2DResult", "FC2D_METHODS", "FrictionContact2D", "fc2d_residual", "solve_fc2d"]
