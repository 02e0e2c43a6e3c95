"""3-D (spatial, isotropic) Coulomb friction contact: data, the shared residual, ``solve_fc3d``."""

from mdi_envs.solvers.fc3d import (  # noqa: F401  (registration)
    fixed_point_socp,
    hybrid,
    newton_ac,
    nsgs,
)
from mdi_envs.solvers.fc3d.driver import solve_fc3d
from mdi_envs.solvers.fc3d.problem import FC3DResult, FrictionContact3D, fc3d_residual
from mdi_envs.solvers.fc3d.registry import FC3D_METHODS

__all__ = ["FC3DResult", "FC3D_METHODS", "FrictionContact3D", "fc3d_residual", "solve_fc3d"]
