"""Linear complementarity problems: data, the shared residual, ``solve_lcp`` and its methods."""

from mdi_envs.solvers.lcp import enumerative, lemke, newton_fb, pgs  # noqa: F401  (registration)
from mdi_envs.solvers.lcp.driver import solve_lcp
from mdi_envs.solvers.lcp.problem import LCP, LCPResult, lcp_residual
from mdi_envs.solvers.lcp.registry import LCP_METHODS

__all__ = ["LCP", "LCPResult", "LCP_METHODS", "lcp_residual", "solve_lcp"]
