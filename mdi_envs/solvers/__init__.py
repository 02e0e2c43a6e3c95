"""Complementarity solvers: LCP, mixed LCP (engaged brakes), planar and 3-D frictional contact.

This layer knows nothing of bodies, contacts or time: the stepper builds each step's problem and
maps the solution back to impulses.
"""

from mdi_envs.solvers.fc2d import (
    FC2D_METHODS,
    FC2DResult,
    FrictionContact2D,
    fc2d_residual,
    solve_fc2d,
)
from mdi_envs.solvers.fc3d import (
    FC3D_METHODS,
    FC3DResult,
    FrictionContact3D,
    fc3d_residual,
    solve_fc3d,
)
from mdi_envs.solvers.lcp import LCP, LCP_METHODS, LCPResult, lcp_residual, solve_lcp
from mdi_envs.solvers.mlcp import MLCP, MLCP_METHODS, MLCPResult, solve_mlcp
from mdi_envs.solvers.status import SolverStatus

__all__ = [
    "FC2DResult",
    "FC2D_METHODS",
    "FC3DResult",
    "FC3D_METHODS",
    "FrictionContact2D",
    "FrictionContact3D",
    "LCP",
    "LCPResult",
    "LCP_METHODS",
    "MLCP",
    "MLCPResult",
    "MLCP_METHODS",
    "SolverStatus",
    "fc2d_residual",
    "fc3d_residual",
    "lcp_residual",
    "solve_fc2d",
    "solve_fc3d",
    "solve_lcp",
    "solve_mlcp",
]
