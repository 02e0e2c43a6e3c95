"""Mixed LCPs (equality rows with free variables): data, ``solve_mlcp`` and its methods."""

from mdi_envs.solvers.mlcp import schur  # noqa: F401  (registration)
from mdi_envs.solvers.mlcp.driver import solve_mlcp
from mdi_envs.solvers.mlcp.problem import MLCP, MLCPResult
from mdi_envs.solvers.mlcp.registry import MLCP_METHODS

__all__ = ["MLCP", "MLCPResult", "MLCP_METHODS", "solve_mlcp"]
